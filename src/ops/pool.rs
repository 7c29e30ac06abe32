//! Recycled pixel buffers: an image's buffer, when the image is dropped, waits here for the
//! next image of the same size instead of going back to the operating system.
//!
//! Why: a 2048² channel is 16 MiB, which the allocator maps fresh from the kernel and unmaps
//! on free, so every new buffer page-faults 4096 pages that the kernel zeroes one by one.
//! Measured with `perf` on a 2K set, 18 % of the run was kernel time, almost all of it those
//! faults. Zeroing a recycled buffer in place costs a fraction of that. The pool holds at
//! most `MAX_BYTES`, all it can add to the peak resident memory; `clear` empties it (the evaluator does, when it finishes).
//!
//! Contents never leak from one image to the next: `take_zeroed` zeroes what it returns and
//! `take_copy` overwrites all of it.

use std::sync::Mutex;

/// Bytes kept for reuse at most, the pool's whole addition to the peak resident memory: six
/// single-channel buffers at 2048², no image of 4096² (`MAX_BUFFER_BYTES`).
const MAX_BYTES: usize = 96 << 20;

/// The largest buffer kept: an RGB image at 2048² (48 MiB) and anything smaller, not a
/// 4096² channel (64 MiB). At 4096² page faults weigh less against the work per buffer and
/// the 1 GiB memory target weighs more: measured on `liasis-mackloti` evaluated whole at
/// 4096², a pooled 64 MiB buffer added 41 MiB to the peak resident memory and saved 3 % of
/// the time.
const MAX_BUFFER_BYTES: usize = 48 << 20;

/// Buffers smaller than this are left to the allocator, which serves them from its heap
/// without page faults anyway (glibc maps allocations above 128 KiB to 32 MiB).
const MIN_LEN: usize = 1 << 16;

static POOL: Mutex<Vec<Vec<f32>>> = Mutex::new(Vec::new());

/// A buffer of `len` zeros: a recycled one of exactly that length if the pool has one.
pub fn take_zeroed(len: usize) -> Vec<f32> {
    if len >= MIN_LEN {
        let recycled = {
            let mut pool = POOL.lock().unwrap_or_else(|p| p.into_inner());
            pool.iter().position(|b| b.len() == len).map(|i| pool.swap_remove(i))
        };
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
        let recycled = {
            let mut pool = POOL.lock().unwrap_or_else(|p| p.into_inner());
            pool.iter().position(|b| b.len() == source.len()).map(|i| pool.swap_remove(i))
        };
        if let Some(mut buffer) = recycled {
            buffer.copy_from_slice(source);
            return buffer;
        }
    }
    source.to_vec()
}

/// Offers a buffer for reuse; dropped if it is small or the pool is full (the oldest buffer
/// makes way: recent sizes are the likeliest to be asked for next).
pub fn give(buffer: Vec<f32>) {
    if buffer.len() < MIN_LEN {
        return;
    }
    let bytes = |b: &Vec<f32>| b.len() * std::mem::size_of::<f32>();
    if bytes(&buffer) > MAX_BUFFER_BYTES {
        return;
    }
    let mut pool = POOL.lock().unwrap_or_else(|p| p.into_inner());
    while pool.iter().map(bytes).sum::<usize>() + bytes(&buffer) > MAX_BYTES {
        pool.remove(0);
    }
    pool.push(buffer);
}

/// Frees every pooled buffer (after an evaluation: nothing should outlive it).
pub fn clear() {
    let drained = std::mem::take(&mut *POOL.lock().unwrap_or_else(|p| p.into_inner()));
    drop(drained);
}
