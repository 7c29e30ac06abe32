//! Peak memory, estimated before anything is allocated, and the memory the machine has.
//!
//! A texture set at 16384² needs tens of GiB; allocating blindly ends in an abort after
//! tens of seconds. `estimate_generate_bytes` walks the graph's schedule with buffer sizes
//! instead of buffers (`graph::estimate_peak_bytes`) and adds what export holds; `Plan`
//! refuses a set whose estimate exceeds the available memory, and the binary warns when it
//! takes more than half of it.
//!
//! Available memory is the smallest of: `MemAvailable` in /proc/meminfo, the headroom of the
//! process's memory cgroup and of every cgroup above it (limit less usage: `memory.max` and
//! `memory.current` on cgroup v2, `memory.limit_in_bytes` and `memory.usage_in_bytes` on
//! v1, the usage less the inactive file cache the kernel reclaims before it kills, as
//! container runtimes count a working set; a container, a systemd slice, a batch
//! scheduler's job), the headroom under the process's own limits (`ulimit -v`, the address
//! space, less what is mapped already and the malloc arenas its threads may still reserve;
//! `ulimit -d`, the data segment, which since Linux 4.7 counts private writable mappings too;
//! without them a run under `ulimit -v` aborted with "memory allocation of N bytes failed"
//! and a backtrace, exit 134), and
//! `SNAKESKIN_MEMORY_LIMIT_MIB` when set (a cap the user chooses, also how the tests pretend
//! to be a small machine). The refusal and `generate`'s warning name the bound that held,
//! so that "only 1100 MiB are available" on a machine with 20 GiB free says why.

use crate::Error;
use crate::graph::{Graph, estimate_peak_bytes};
use crate::material::MapKind;

/// Bytes in a mebibyte: every MiB the tool reads (`SNAKESKIN_MEMORY_LIMIT_MIB`) or prints.
pub const MIB: u64 = 1 << 20;

/// Allocator slack, thread stacks, the binary and its tables: measured resident size of a
/// 16² run is about 20 MiB; 64 MiB leaves room.
pub const FIXED_OVERHEAD_BYTES: u64 = 64 * MIB;

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
/// one strip's live buffers at their worst (`strip_rows` rows, margins included) and what the
/// allocator keeps of the strip before, as much again, at most 128 MiB (its buffers, freed on
/// the pool's threads, stay in their threads' arenas, and the next strip may ask on another
/// thread: the body atlas of python-regius at 1024 packed for glTF peaked at 274–312 MiB, ten
/// runs, where one strip's 101 MiB and the files counted 280; at 2048, strips of about 400 MiB,
/// the peaks of three species stayed 170–280 MiB under the estimate without it; BENCHMARKS.md,
/// "Export's memory". Half a strip, at most 64 MiB, was counted until a full test run beside
/// it took that `.glb` to 344 MiB against 328 estimated), plus the PNG files growing as rows
/// are encoded (counted at the set's quantised size: a streamed 16-bit map can come out a
/// sixth over its own, `export::png_file_encoder`, which the set's 8-bit maps, compressed to
/// half of theirs or less, make up for; `--maps height` alone, 64 wide, came to 1.185 of
/// it: kilobytes, which the fixed overhead covers), plus the fixed overhead.
pub fn estimate_strips_bytes(graph: &Graph, maps: &[MapKind], width: usize, height: usize, strip_rows: usize) -> u64 {
    let pixels = (width * height) as u64;
    let files: u64 = maps.iter().map(|m| m.format().bytes_per_pixel() as u64 * pixels).sum();
    let strip_pixels = (width * strip_rows) as u64;
    let strip_quantized: u64 = maps.iter().map(|m| m.format().bytes_per_pixel() as u64 * strip_pixels).sum();
    let strip = estimate_peak_bytes(graph, maps, width, strip_rows);
    strip + strip.min(128 * MIB) + 2 * strip_quantized + files + FIXED_OVERHEAD_BYTES
}

/// Hands the memory the allocator keeps from freed blocks back to the system (glibc's
/// `malloc_trim`; nothing elsewhere), between the species of a sheet or the figures drawn in
/// turn: the next one's evaluation may run on other threads' arenas, which cannot reuse it.
pub fn release_freed() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: malloc_trim only returns free pages of the allocator's own arenas to the system.
    unsafe {
        libc::malloc_trim(0);
    }
}

/// An estimate next to the memory available for it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MemoryCheck {
    pub estimate_bytes: u64,
    pub available_bytes: u64,
    /// What bounds `available_bytes`.
    pub bound: MemoryBound,
}

/// What bounds the memory available to this process (`available`): the least of them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MemoryBound {
    /// `MemAvailable` in /proc/meminfo (or nothing read: no bound known).
    Machine,
    /// A memory cgroup's limit less its usage.
    Cgroup,
    /// `ulimit -v` (RLIMIT_AS) less the address space mapped already.
    AddressSpace,
    /// `ulimit -d` (RLIMIT_DATA) less the data mapped already.
    DataSegment,
    /// `SNAKESKIN_MEMORY_LIMIT_MIB`.
    UserLimit,
}

impl MemoryBound {
    /// Where the limit comes from, as "N MiB are available …" goes on (the refusal, and
    /// `generate`'s warning when a set needs more than half the memory available).
    pub fn place(self) -> &'static str {
        match self {
            MemoryBound::Machine => "on this machine now",
            MemoryBound::Cgroup => {
                "under the memory limit of this process's control group (a container, a systemd slice or a job \
                 scheduler's)"
            }
            MemoryBound::AddressSpace => {
                "under this process's address-space limit (ulimit -v) less what it has mapped and may reserve for its \
                 threads' allocators"
            }
            MemoryBound::DataSegment => {
                "under this process's data-size limit (ulimit -d) less the data it holds already"
            }
            MemoryBound::UserLimit => "under SNAKESKIN_MEMORY_LIMIT_MIB",
        }
    }

    /// What to do when a set does not fit, as the refusal ends (`Error::Memory`).
    pub fn remedy(self) -> &'static str {
        match self {
            MemoryBound::Machine => "use a smaller size",
            MemoryBound::Cgroup => "use a smaller size or raise that limit",
            MemoryBound::AddressSpace | MemoryBound::DataSegment => "use a smaller size or raise the limit",
            MemoryBound::UserLimit => "use a smaller size or raise it",
        }
    }
}

impl MemoryCheck {
    pub fn against_available(estimate_bytes: u64) -> MemoryCheck {
        let (available_bytes, bound) = available();
        MemoryCheck { estimate_bytes, available_bytes, bound }
    }

    /// The estimate in whole MiB, rounded up, as the refusal and the warning give it.
    pub fn needed_mib(&self) -> u64 {
        self.estimate_bytes.div_ceil(MIB)
    }

    /// The available memory in whole MiB, rounded down, as the refusal and the warning give it.
    pub fn available_mib(&self) -> u64 {
        self.available_bytes / MIB
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
                needed_mib: self.needed_mib(),
                available_mib: self.available_mib(),
                bound: self.bound,
            });
        }
        Ok(())
    }
}

/// Memory available to this process now, in bytes (see the module documentation).
pub fn available_bytes() -> u64 {
    available().0
}

/// Memory available to this process now, in bytes, and what bounds it: the least of the
/// bounds (the later one where two are equal).
pub fn available() -> (u64, MemoryBound) {
    let (address_space, data) = process_headroom();
    // A malformed value is refused at the command line's start (`limit_from_env`); here it
    // is ignored rather than failing mid-run.
    let user = limit_from_env().ok().flatten().map(|mib| mib.saturating_mul(MIB));
    least_bound(
        meminfo_available(),
        [
            (cgroup_headroom(), MemoryBound::Cgroup),
            (address_space, MemoryBound::AddressSpace),
            (data, MemoryBound::DataSegment),
            (user, MemoryBound::UserLimit),
        ],
    )
}

/// The least of the machine's available memory (`machine`; none read: no bound) and the
/// `bounds` that are set, the later one where two are equal.
fn least_bound(machine: Option<u64>, bounds: [(Option<u64>, MemoryBound); 4]) -> (u64, MemoryBound) {
    let machine = (machine.unwrap_or(u64::MAX), MemoryBound::Machine);
    bounds.into_iter().fold(machine, |least, (bytes, bound)| match bytes {
        Some(bytes) if bytes <= least.0 => (bytes, bound),
        _ => least,
    })
}

/// The address space glibc reserves for each thread's malloc arena (HEAP_MAX_SIZE on 64-bit
/// targets, 64 MiB), mapped as a thread first allocates and counted by RLIMIT_AS though
/// hardly resident. Measured (`generate natrix-natrix`, two cores, VmPeak polled from
/// /proc/PID/status): VmPeak exceeded the estimate by 335 MiB at 4096² and 471 MiB at 8192²
/// while the resident peak stayed below it; with only the mapped size subtracted, runs whose
/// estimate fitted the headroom by 152 and 217 MiB still aborted.
const THREAD_ARENA_BYTES: u64 = 64 * MIB;

/// Arenas a process under an address-space limit keeps (`bound_arenas_under_address_limit`):
/// the main one and one more. Glibc's default, eight per core, reserved 64 MiB of address
/// space per allocating thread: counted for every thread a 64-core host may start, the
/// allowance alone came to 4.4 GiB and refused every set under `ulimit -v 4G`.
const ARENAS_UNDER_ADDRESS_LIMIT: u64 = 2;

/// Caps glibc's malloc arenas at `ARENAS_UNDER_ADDRESS_LIMIT` when this process runs under an
/// address-space limit and the user has not chosen a cap (`MALLOC_ARENA_MAX`); called by the
/// binary before it starts threads. Threads then share arenas, as glibc does anyway once it
/// cannot map another, so the headroom need not allow for an arena per thread.
pub fn bound_arenas_under_address_limit() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    if soft_limits()[0].is_some() && std::env::var_os("MALLOC_ARENA_MAX").is_none() {
        // SAFETY: mallopt only sets an allocator parameter; called before any thread starts.
        if unsafe { libc::mallopt(libc::M_ARENA_MAX, ARENAS_UNDER_ADDRESS_LIMIT as libc::c_int) } == 1 {
            ARENAS_BOUNDED.store(true, std::sync::atomic::Ordering::Relaxed);
        }
    }
}

/// Arenas this process may map beyond those in VmSize already: the cap the user set
/// (`MALLOC_ARENA_MAX`) or the binary's (`bound_arenas_under_address_limit`); else (the library
/// in another program) one per thread that may allocate (the evaluation pool and up to five map
/// encoders), at most glibc's eight per core.
fn arena_threads() -> u64 {
    if let Some(max) = std::env::var("MALLOC_ARENA_MAX").ok().and_then(|v| v.trim().parse::<u64>().ok()) {
        return max;
    }
    if ARENAS_BOUNDED.load(std::sync::atomic::Ordering::Relaxed) {
        return ARENAS_UNDER_ADDRESS_LIMIT;
    }
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get()) as u64;
    (rayon::current_num_threads() as u64 + 5).min(8 * cores)
}

/// Whether `bound_arenas_under_address_limit` capped the arenas.
static ARENAS_BOUNDED: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// The headroom under this process's address-space limit (RLIMIT_AS, against `VmSize` in
/// /proc/self/status, less the arenas its threads may still reserve) and data-size limit
/// (RLIMIT_DATA, against `VmData`; an arena's reserve is not writable, so not data until
/// used); None where a limit is unlimited or unread.
fn process_headroom() -> (Option<u64>, Option<u64>) {
    let [address_space, data] = soft_limits();
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    let arenas = THREAD_ARENA_BYTES * arena_threads();
    (
        headroom_under(address_space, &status, "VmSize:").map(|h| h.saturating_sub(arenas)),
        headroom_under(data, &status, "VmData:"),
    )
}

/// The soft limits RLIMIT_AS and RLIMIT_DATA, None where unlimited.
#[cfg(target_os = "linux")]
fn soft_limits() -> [Option<u64>; 2] {
    let soft = |read: &dyn Fn(&mut libc::rlimit) -> libc::c_int| {
        let mut limit = libc::rlimit { rlim_cur: 0, rlim_max: 0 };
        // rlim_t is 32 bits wide on 32-bit targets.
        #[allow(clippy::unnecessary_cast)]
        (read(&mut limit) == 0 && limit.rlim_cur != libc::RLIM_INFINITY).then_some(limit.rlim_cur as u64)
    };
    // SAFETY: getrlimit only writes the limit into the `rlimit` it is given, which outlives the call.
    [
        soft(&|l| unsafe { libc::getrlimit(libc::RLIMIT_AS, l) }),
        soft(&|l| unsafe { libc::getrlimit(libc::RLIMIT_DATA, l) }),
    ]
}

#[cfg(not(target_os = "linux"))]
fn soft_limits() -> [Option<u64>; 2] {
    [None, None]
}

/// `limit` less the size in /proc/self/status's `key` line (`status`, in kB); None without a
/// limit; the whole limit when the line is not there (a kernel without it).
fn headroom_under(limit: Option<u64>, status: &str, key: &str) -> Option<u64> {
    let used_kib =
        status.lines().find_map(|l| l.strip_prefix(key)?.split_whitespace().next()?.parse::<u64>().ok()).unwrap_or(0);
    Some(limit?.saturating_sub(used_kib.saturating_mul(1024)))
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
    macro_rules! accepted {
        () => {
            "a whole number of MiB, e.g. 4096"
        };
    }
    let invalid = |value: String| Error::Environment { variable, value, accepted: accepted!() };
    match std::env::var(variable) {
        Err(std::env::VarError::NotPresent) => Ok(None),
        Err(std::env::VarError::NotUnicode(v)) => Err(invalid(v.to_string_lossy().into_owned())),
        // A number past u64 said "expected a whole number of MiB", which it is.
        Ok(v) => v.trim().parse::<u64>().map(Some).map_err(|e| match e.kind() {
            std::num::IntErrorKind::PosOverflow => Error::Environment {
                variable,
                value: v,
                // u64::MAX
                accepted: concat!(accepted!(), ", at most 18446744073709551615"),
            },
            _ => invalid(v),
        }),
    }
}

fn meminfo_available() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

fn cgroup_headroom() -> Option<u64> {
    let membership = std::fs::read_to_string("/proc/self/cgroup").unwrap_or_default();
    cgroup_headroom_in(&membership, &|path| std::fs::read_to_string(path).ok())
}

/// One cgroup hierarchy's memory files: its mount, its limit, its usage, and the key of the
/// inactive file cache in its `memory.stat`.
struct Hierarchy {
    mount: &'static str,
    limit: &'static str,
    usage: &'static str,
    cache: &'static str,
}

/// A cgroup v1 limit at or above this is "no limit" (the kernel writes the largest page
/// multiple of i64::MAX, 9223372036854771712).
const CGROUP_V1_UNLIMITED: u64 = 1 << 62;

/// The least headroom (limit less usage) over the process's memory cgroup and every cgroup
/// above it, from `/proc/self/cgroup` (`membership`) and the files `read` returns. It read
/// only the root's v2 files, which hold the limit inside a container's own namespace but not
/// on a v1 host or in a v2 slice (`systemd-run -p MemoryMax=`): a run there was killed by
/// the kernel instead of refused.
fn cgroup_headroom_in(membership: &str, read: &dyn Fn(&std::path::Path) -> Option<String>) -> Option<u64> {
    use std::path::{Path, PathBuf};
    let number = |path: PathBuf| read(&path).and_then(|t| t.trim().parse::<u64>().ok());
    // The page cache counts as usage, but its inactive part is reclaimed before the kernel
    // kills: left in, a run after a large file copy was refused where it fitted.
    let inactive_file = |group: &Path, key: &str| {
        let stat = read(&group.join("memory.stat"))?;
        stat.lines().find_map(|l| l.strip_prefix(key)?.strip_prefix(' ')?.trim().parse::<u64>().ok())
    };
    let v2 =
        Hierarchy { mount: "/sys/fs/cgroup", limit: "memory.max", usage: "memory.current", cache: "inactive_file" };
    let v1 = Hierarchy {
        mount: "/sys/fs/cgroup/memory",
        limit: "memory.limit_in_bytes",
        usage: "memory.usage_in_bytes",
        cache: "total_inactive_file",
    };
    // Each hierarchy with the process's path in it.
    let mut memberships: Vec<(&Hierarchy, &str)> = Vec::new();
    for line in membership.lines() {
        let mut fields = line.splitn(3, ':');
        let (Some(_), Some(controllers), Some(path)) = (fields.next(), fields.next(), fields.next()) else { continue };
        if controllers.is_empty() {
            memberships.push((&v2, path));
        } else if controllers.split(',').any(|c| c == "memory") {
            memberships.push((&v1, path));
        }
    }
    if memberships.is_empty() {
        // No membership read: the root's v2 files, as a container shows them.
        memberships.push((&v2, "/"));
    }
    let mut least: Option<u64> = None;
    for (h, path) in memberships {
        let mut group = Path::new(h.mount).join(path.trim_start_matches('/'));
        loop {
            // "max" (v2) does not parse: no limit at this level.
            if let Some(limit) = number(group.join(h.limit)).filter(|&l| l < CGROUP_V1_UNLIMITED) {
                let usage = number(group.join(h.usage)).unwrap_or(0);
                let usage = usage.saturating_sub(inactive_file(&group, h.cache).unwrap_or(0));
                let headroom = limit.saturating_sub(usage);
                least = Some(least.map_or(headroom, |l| l.min(headroom)));
            }
            if group == Path::new(h.mount) || !group.pop() || !group.starts_with(h.mount) {
                break;
            }
        }
    }
    least
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;
    use std::path::Path;

    fn headroom(membership: &str, files: &[(&str, &str)]) -> Option<u64> {
        let files: HashMap<&Path, &str> = files.iter().map(|(p, t)| (Path::new(*p), *t)).collect();
        cgroup_headroom_in(membership, &|path| files.get(path).map(|t| format!("{t}\n")))
    }

    /// The headroom under a process limit is the limit less the size its status line gives
    /// (in kB), none without a limit, the whole limit without the line, and 0 past it.
    #[test]
    fn the_headroom_under_a_process_limit_is_the_limit_less_what_is_mapped() {
        let status = "Name:\tsnakeskin\nVmPeak:\t  9000 kB\nVmSize:\t    1024 kB\nVmData:\t 512 kB\n";
        assert_eq!(headroom_under(Some(4 * MIB), status, "VmSize:"), Some(3 * MIB));
        assert_eq!(headroom_under(Some(4 * MIB), status, "VmData:"), Some(4 * MIB - 512 * 1024));
        assert_eq!(headroom_under(None, status, "VmSize:"), None);
        assert_eq!(headroom_under(Some(4 * MIB), "Name:\tx\n", "VmSize:"), Some(4 * MIB));
        assert_eq!(headroom_under(Some(MIB / 2), status, "VmSize:"), Some(0));
    }

    /// The least bound is the one named; an unset bound is passed over; where two are equal,
    /// the later (the user's cap over the machine's memory, as the tests set it).
    #[test]
    fn the_least_bound_is_the_one_named() {
        use MemoryBound::*;
        let bounds = |cgroup, address_space, data, user| {
            [(cgroup, Cgroup), (address_space, AddressSpace), (data, DataSegment), (user, UserLimit)]
        };
        assert_eq!(least_bound(Some(100), bounds(None, None, None, None)), (100, Machine));
        assert_eq!(least_bound(None, bounds(None, None, None, None)), (u64::MAX, Machine));
        assert_eq!(least_bound(Some(100), bounds(Some(90), Some(50), Some(70), None)), (50, AddressSpace));
        assert_eq!(least_bound(Some(100), bounds(Some(90), Some(80), Some(40), Some(60))), (40, DataSegment));
        assert_eq!(least_bound(Some(100), bounds(None, None, None, Some(100))), (100, UserLimit));
        assert_eq!(least_bound(Some(100), bounds(Some(30), None, None, Some(200))), (30, Cgroup));
    }

    #[test]
    fn the_cgroup_limit_is_found_where_the_process_lives_and_above_it() {
        // A v2 slice: the limit two levels above the process's own group ("max": none there).
        let slice = [
            ("/sys/fs/cgroup/user.slice/job.scope/memory.max", "max"),
            ("/sys/fs/cgroup/user.slice/job.scope/memory.current", "100"),
            ("/sys/fs/cgroup/user.slice/memory.max", "1000"),
            ("/sys/fs/cgroup/user.slice/memory.current", "300"),
        ];
        assert_eq!(headroom("0::/user.slice/job.scope\n", &slice), Some(700));
        // The least headroom of the levels wins.
        let mut tighter = slice.to_vec();
        tighter[0].1 = "500";
        tighter[1].1 = "450";
        assert_eq!(headroom("0::/user.slice/job.scope\n", &tighter), Some(50));
        // A v1 host: the memory controller's own hierarchy; the root's "unlimited" is no limit.
        let v1 = [
            ("/sys/fs/cgroup/memory/review/memory.limit_in_bytes", "1500"),
            ("/sys/fs/cgroup/memory/review/memory.usage_in_bytes", "500"),
            ("/sys/fs/cgroup/memory/memory.limit_in_bytes", "9223372036854771712"),
            ("/sys/fs/cgroup/memory/memory.usage_in_bytes", "7000"),
        ];
        assert_eq!(headroom("11:cpu,cpuacct:/other\n5:memory:/review\n", &v1), Some(1000));
        // A container's namespace: the root's v2 files, with or without the membership.
        let container = [("/sys/fs/cgroup/memory.max", "2000"), ("/sys/fs/cgroup/memory.current", "500")];
        assert_eq!(headroom("0::/\n", &container), Some(1500));
        assert_eq!(headroom("", &container), Some(1500));
        // The inactive file cache is reclaimable: not counted as used (v2, and v1's
        // hierarchical total; v1's own-group `inactive_file` is not the key).
        let mut cached = container.to_vec();
        cached.push(("/sys/fs/cgroup/memory.stat", "anon 100\nfile 400\nactive_file 100\ninactive_file 300\n"));
        assert_eq!(headroom("0::/\n", &cached), Some(1800));
        let mut cached = v1.to_vec();
        cached.push(("/sys/fs/cgroup/memory/review/memory.stat", "inactive_file 50\ntotal_inactive_file 400\n"));
        assert_eq!(headroom("5:memory:/review\n", &cached), Some(1400));
        // No limit anywhere.
        assert_eq!(headroom("0::/a/b\n", &[("/sys/fs/cgroup/a/memory.max", "max")]), None);
        assert_eq!(headroom("4:memory:/\n", &v1[2..]), None);
    }
}
