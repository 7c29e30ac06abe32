//! Recycled pixel buffers: an image's buffer, when the image is dropped, waits here for the
//! next image of the same size instead of going back to the operating system.
//!
//! Why: a 2048² channel is 16 MiB, which the allocator maps fresh from the kernel and unmaps
//! on free, so every new buffer page-faults 4096 pages that the kernel zeroes one by one.
//! Measured with `perf` on a 2K set, 18 % of the run was kernel time, almost all of it those
//! faults. Zeroing a recycled buffer in place costs a fraction of that. The pool holds at
//! most `MAX_BYTES` of buffers up to `MAX_BUFFER_BYTES`, all it can add to the peak resident
//! memory; larger buffers (a channel or an RGB image at 4096²) only within the room the
//! evaluator's schedule leaves under its planned peak (`set_large_budget`), so they add
//! nothing to it. `clear` empties it (the evaluator does, when it finishes).
//!
//! Contents never leak from one image to the next: `take_zeroed` zeroes what it returns and
//! `take_copy` overwrites all of it.
//!
//! The pool is one for the process: evaluations running at once (a batch runs two jobs)
//! share it, each setting the large budget from its own schedule before each of its
//! batches, and the first to finish empties it. Buffers only wait here after an image let
//! them go, so the pool holds at most the latest budget of memory that was resident a
//! moment before; with two evaluations it is a cap, not a per-evaluation guarantee.

use std::sync::Mutex;

/// Bytes of buffers up to `MAX_BUFFER_BYTES` kept for reuse at most, the pool's whole
/// addition to the evaluator's planned peak: six single-channel buffers at 2048² (larger
/// ones wait only within that plan, `set_large_budget`).
const MAX_BYTES: usize = 96 << 20;

/// The largest buffer kept unconditionally: an RGB image at 2048² (48 MiB) and anything
/// smaller, not a 4096² channel (64 MiB). At 4096² the 1 GiB memory target weighs more:
/// measured on `liasis-mackloti` evaluated whole at 4096², a 64 MiB buffer kept regardless
/// added 41 MiB to the peak resident memory and saved 3 % of the time; larger buffers are
/// kept only within `set_large_budget`'s room.
pub const MAX_BUFFER_BYTES: usize = 48 << 20;

/// Buffers smaller than this are left to the allocator, which serves them from its heap
/// without page faults anyway (glibc maps allocations above 128 KiB to 32 MiB).
const MIN_LEN: usize = 1 << 16;

static POOL: Mutex<Pool> = Mutex::new(Pool::new());

/// The buffers waiting, oldest first, and the room for large ones.
struct Pool {
    buffers: Vec<Vec<f32>>,
    /// Bytes of buffers over `MAX_BUFFER_BYTES` that may wait here (`set_large_budget`).
    large_budget: usize,
}

fn bytes(buffer: &[f32]) -> usize {
    std::mem::size_of_val(buffer)
}

fn is_large(buffer: &[f32]) -> bool {
    bytes(buffer) > MAX_BUFFER_BYTES
}

impl Pool {
    const fn new() -> Pool {
        Pool { buffers: Vec::new(), large_budget: 0 }
    }

    /// A waiting buffer of exactly `len` samples.
    fn take(&mut self, len: usize) -> Option<Vec<f32>> {
        self.buffers.iter().position(|b| b.len() == len).map(|i| self.buffers.remove(i))
    }

    /// Keeps `buffer` if it may wait (see `give`).
    fn give(&mut self, buffer: Vec<f32>) {
        if buffer.len() < MIN_LEN {
            return;
        }
        let (large, size) = (is_large(&buffer), bytes(&buffer));
        let limit = if large { self.large_budget } else { MAX_BYTES };
        if size > limit {
            return;
        }
        self.trim(large, limit - size);
        self.buffers.push(buffer);
    }

    fn set_large_budget(&mut self, budget: usize) {
        self.large_budget = budget;
        self.trim(true, budget);
    }

    fn bytes(&self, large: bool) -> usize {
        self.buffers.iter().filter(|b| is_large(b) == large).map(|b| bytes(b)).sum()
    }

    /// Drops the oldest buffers of the kind (`large` or not) until `limit` bytes are left.
    fn trim(&mut self, large: bool, limit: usize) {
        while self.bytes(large) > limit {
            let oldest = self.buffers.iter().position(|b| is_large(b) == large).expect("over a limit: not empty");
            self.buffers.remove(oldest);
        }
    }
}

fn pool() -> std::sync::MutexGuard<'static, Pool> {
    POOL.lock().unwrap_or_else(|p| p.into_inner())
}

/// A buffer of `len` zeros: a recycled one of exactly that length if the pool has one.
pub fn take_zeroed(len: usize) -> Vec<f32> {
    if len >= MIN_LEN {
        let recycled = pool().take(len);
        if let Some(mut buffer) = recycled {
            buffer.fill(0.0);
            return buffer;
        }
    }
    vec![0.0; len]
}

/// A copy of `source`, in a recycled buffer if the pool has one of its length.
pub fn take_copy(source: &[f32]) -> Vec<f32> {
    if source.len() >= MIN_LEN {
        let recycled = pool().take(source.len());
        if let Some(mut buffer) = recycled {
            buffer.copy_from_slice(source);
            return buffer;
        }
    }
    source.to_vec()
}

/// Offers a buffer for reuse; dropped if it is small or its kind's room is full (the
/// oldest buffer of its kind makes way: recent sizes are the likeliest to be asked for
/// next). Up to `MAX_BUFFER_BYTES` the room is `MAX_BYTES`; above, the large budget.
pub fn give(buffer: Vec<f32>) {
    pool().give(buffer);
}

/// Sets the bytes of large buffers (over `MAX_BUFFER_BYTES`) the pool may hold, dropping the
/// oldest to fit. The evaluator sets it before each batch of nodes to the room its planned
/// peak leaves: the peak less the buffers alive and those the batch may allocate.
pub fn set_large_budget(budget: usize) {
    pool().set_large_budget(budget);
}

/// Frees every pooled buffer and closes the pool to large ones (after an evaluation:
/// nothing should outlive it).
pub fn clear() {
    let drained = {
        let mut pool = pool();
        pool.large_budget = 0;
        std::mem::take(&mut pool.buffers)
    };
    drop(drained);
}

#[cfg(test)]
mod tests {
    use super::*;

    const SMALL: usize = MIN_LEN; // 256 KiB
    const LARGE: usize = MAX_BUFFER_BYTES / 4 + 1; // just over the limit

    #[test]
    fn small_buffers_wait_up_to_max_bytes_oldest_out_first() {
        let mut pool = Pool::new();
        pool.give(vec![0.0; MIN_LEN - 1]);
        assert!(pool.buffers.is_empty(), "too small to keep");
        let count = MAX_BYTES / (SMALL * 4);
        for i in 0..count + 2 {
            pool.give(vec![i as f32; SMALL]);
        }
        assert_eq!(pool.bytes(false), MAX_BYTES);
        assert_eq!(pool.buffers[0][0], 2.0, "the two oldest made way");
        assert_eq!(pool.take(SMALL).map(|b| b.len()), Some(SMALL));
        assert!(pool.take(SMALL + 1).is_none(), "only exact lengths");
    }

    #[test]
    fn taking_keeps_the_others_oldest_first_and_the_limit_is_inclusive() {
        let mut pool = Pool::new();
        for extra in 0..3 {
            pool.give(vec![extra as f32; SMALL + extra]);
        }
        assert_eq!(pool.take(SMALL).map(|b| b[0]), Some(0.0));
        assert_eq!(pool.buffers.iter().map(|b| b[0]).collect::<Vec<_>>(), [1.0, 2.0], "order kept");
        // A buffer of exactly MAX_BUFFER_BYTES is small: kept without a large budget.
        pool.give(vec![3.0; MAX_BUFFER_BYTES / 4]);
        assert_eq!(pool.bytes(true), 0);
        assert_eq!(pool.buffers.last().map(|b| b[0]), Some(3.0));
    }

    #[test]
    fn large_buffers_wait_only_within_the_budget() {
        let mut pool = Pool::new();
        pool.give(vec![0.0; LARGE]);
        assert!(pool.buffers.is_empty(), "no budget, no large buffer");
        pool.set_large_budget(2 * LARGE * 4);
        pool.give(vec![1.0; LARGE]);
        pool.give(vec![2.0; LARGE]);
        pool.give(vec![3.0; LARGE]);
        assert_eq!(pool.bytes(true), 2 * LARGE * 4, "the budget holds two");
        assert_eq!(pool.buffers[0][0], 2.0, "the oldest made way");
        pool.give(vec![4.0; SMALL]);
        pool.set_large_budget(LARGE * 4 + 3);
        assert_eq!(pool.bytes(true), LARGE * 4, "a smaller budget drops the oldest");
        assert_eq!(pool.buffers.iter().map(|b| b[0]).collect::<Vec<_>>(), [3.0, 4.0], "small ones stay");
        pool.set_large_budget(0);
        assert_eq!(pool.bytes(true), 0);
        pool.give(vec![5.0; 2 * LARGE]);
        assert_eq!(pool.bytes(true), 0, "a buffer over the budget is not kept");
    }
}
