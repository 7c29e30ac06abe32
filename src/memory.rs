//! Peak memory, estimated before anything is allocated, and the memory the machine has.
//!
//! A texture set at 16384² needs tens of GiB; allocating blindly ends in an abort after
//! tens of seconds. `estimate_generate_bytes` walks the graph's schedule with buffer sizes
//! instead of buffers (`graph::estimate_peak_bytes`) and adds what export holds; `Plan`
//! refuses a set whose estimate exceeds the available memory, and the binary warns when it
//! takes more than half of it.
//!
//! Available memory is the smallest of: `MemAvailable` in /proc/meminfo, the cgroup's
//! `memory.max` less its `memory.current` (containers), and `SNAKESKIN_MEMORY_LIMIT_MIB`
//! when set (a cap the user chooses, also how the tests pretend to be a small machine).

use crate::Error;
use crate::graph::{Graph, estimate_peak_bytes};
use crate::material::MapKind;

const MIB: u64 = 1 << 20;

/// Allocator slack, thread stacks, the binary and its tables: measured resident size of a
/// 16² run is about 20 MiB; 64 MiB leaves room.
const FIXED_OVERHEAD_BYTES: u64 = 64 * MIB;

/// Estimated peak bytes of `generate` for `maps` at `size`²: the graph's live buffers at
/// their worst point, plus every quantised map (held until encoding) and its PNG (at most
/// the quantised size with the fast filter; a whole tile's PNG goes to its temporary file
/// when compressed, a strip set's are held to the end: counting every one held is an upper
/// bound), plus a fixed overhead.
pub fn estimate_generate_bytes(graph: &Graph, maps: &[MapKind], width: usize, height: usize) -> u64 {
    let pixels = (width * height) as u64;
    let quantized: u64 = maps.iter().map(|m| m.format().bytes_per_pixel() as u64 * pixels).sum();
    estimate_peak_bytes(graph, maps, width, height) + 2 * quantized + FIXED_OVERHEAD_BYTES
}

/// Estimated peak bytes of a set evaluated in strips (a body atlas, `generate::STRIP_ROWS`):
/// one strip's live buffers at their worst (`strip_rows` rows, margins included), plus the
/// PNG files growing as rows are encoded (at most the quantised size of the whole set with
/// the fast filter), plus the fixed overhead.
pub fn estimate_strips_bytes(graph: &Graph, maps: &[MapKind], width: usize, height: usize, strip_rows: usize) -> u64 {
    let pixels = (width * height) as u64;
    let files: u64 = maps.iter().map(|m| m.format().bytes_per_pixel() as u64 * pixels).sum();
    let strip_pixels = (width * strip_rows) as u64;
    let strip_quantized: u64 = maps.iter().map(|m| m.format().bytes_per_pixel() as u64 * strip_pixels).sum();
    estimate_peak_bytes(graph, maps, width, strip_rows) + 2 * strip_quantized + files + FIXED_OVERHEAD_BYTES
}

/// An estimate next to the memory available for it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MemoryCheck {
    pub estimate_bytes: u64,
    pub available_bytes: u64,
}

impl MemoryCheck {
    pub fn against_available(estimate_bytes: u64) -> MemoryCheck {
        MemoryCheck { estimate_bytes, available_bytes: available_bytes() }
    }

    /// More than half of the available memory: worth a warning.
    pub fn is_tight(&self) -> bool {
        self.estimate_bytes > self.available_bytes / 2
    }

    /// `Error::Memory` when the estimate exceeds what is available.
    pub fn refuse_if_over(&self, what: &str) -> Result<(), Error> {
        if self.estimate_bytes > self.available_bytes {
            return Err(Error::Memory {
                what: what.into(),
                needed_mib: self.estimate_bytes.div_ceil(MIB),
                available_mib: self.available_bytes / MIB,
            });
        }
        Ok(())
    }
}

/// Memory available to this process now, in bytes (see the module documentation).
pub fn available_bytes() -> u64 {
    let mut available = meminfo_available().unwrap_or(u64::MAX);
    if let Some(cgroup) = cgroup_headroom() {
        available = available.min(cgroup);
    }
    // A malformed value is refused at the command line's start (`limit_from_env`); here it
    // is ignored rather than failing mid-run.
    if let Ok(Some(limit)) = limit_from_env() {
        available = available.min(limit.saturating_mul(MIB));
    }
    available
}

/// The environment variable that caps the memory the tool assumes available, in MiB.
pub const LIMIT_VARIABLE: &str = "SNAKESKIN_MEMORY_LIMIT_MIB";

/// The user's cap (`LIMIT_VARIABLE`) in MiB, None when unset; a value that is not a whole
/// number of MiB is an error, not a silently disabled check.
pub fn limit_from_env() -> Result<Option<u64>, Error> {
    mib_from_env(LIMIT_VARIABLE)
}

/// The environment variable that replaces `generate`'s strip budgets, in MiB (how tests
/// send small tiles through strips; `generate::strips_of`).
pub const TILE_BUDGET_VARIABLE: &str = "SNAKESKIN_TILE_BUDGET_MIB";

/// `TILE_BUDGET_VARIABLE` in MiB, None when unset; a malformed value is an error (it was
/// silently ignored, while the memory limit's was refused).
pub fn tile_budget_from_env() -> Result<Option<u64>, Error> {
    mib_from_env(TILE_BUDGET_VARIABLE)
}

fn mib_from_env(variable: &'static str) -> Result<Option<u64>, Error> {
    let invalid = |value: String| Error::Environment { variable, value, accepted: "a whole number of MiB, e.g. 4096" };
    match std::env::var(variable) {
        Err(std::env::VarError::NotPresent) => Ok(None),
        Err(std::env::VarError::NotUnicode(v)) => Err(invalid(v.to_string_lossy().into_owned())),
        Ok(v) => v.trim().parse::<u64>().map(Some).map_err(|_| invalid(v)),
    }
}

fn meminfo_available() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

fn cgroup_headroom() -> Option<u64> {
    let max: u64 = std::fs::read_to_string("/sys/fs/cgroup/memory.max").ok()?.trim().parse().ok()?;
    let current: u64 =
        std::fs::read_to_string("/sys/fs/cgroup/memory.current").ok().and_then(|t| t.trim().parse().ok()).unwrap_or(0);
    Some(max.saturating_sub(current))
}
