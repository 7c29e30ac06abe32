//! The memory check of the drawing commands (and of `export`) against their measured peaks,
//! in a test binary of its own: cargo runs test binaries one after another, so nothing else runs
//! beside the measured children. In tests/render.rs, beside its other GPU tests, the same
//! 2048×1024 preview peaked at 481 MiB against 323 MiB alone (lavapipe queues more of its
//! rasteriser's work when the cores are busy), past its estimate of 474 (a CI run of
//! 69a99b0); what the estimate bounds is the command's own peak. The binary's two tests
//! measure one at a time (`MEASURING`): cargo runs a binary's tests on threads of their own.

mod common;

use common::{gpu_or_skip, gpu_required, on_x11};

const PLAIN_PRESET: &str = "erythrolamprus-miliaris";

/// The peak resident memory (KiB, from `wait4`'s `ru_maxrss`, KiB on Linux) of `snakeskin
/// args`, which must succeed; this child's own, whatever else the tests run at the same time.
/// Under a `wrapper` (e.g. `xvfb-run`) it is the largest peak among the wrapper and the
/// children it reaps: `xvfb-run` waits for the binary (not for Xvfb, which it kills).
#[cfg(target_os = "linux")]
fn peak_resident_kib(wrapper: &[&str], args: &[&str]) -> u64 {
    let run = measured(wrapper, args, |c| c);
    assert!(run.succeeded, "{wrapper:?} {args:?} failed: {}\n{}", run.status, run.stderr);
    run.peak_kib
}

/// A measured run: whether it exited 0, its wait status, its stderr and its peak resident
/// memory (KiB).
#[cfg(target_os = "linux")]
struct Measured {
    succeeded: bool,
    status: i32,
    stderr: String,
    peak_kib: u64,
}

/// Runs `snakeskin args` (under `wrapper`, as `peak_resident_kib` says), its command set up
/// further by `setup` (an environment), and measures it, whether it succeeds or not.
#[cfg(target_os = "linux")]
#[allow(clippy::zombie_processes, reason = "the child is reaped by wait4, which Child::wait cannot give")]
fn measured(
    wrapper: &[&str],
    args: &[&str],
    setup: impl FnOnce(&mut std::process::Command) -> &mut std::process::Command,
) -> Measured {
    use std::io::{Read, Seek};
    use std::process::{Command, Stdio};
    let binary = env!("CARGO_BIN_EXE_snakeskin");
    let (program, first) = wrapper.split_first().map_or((binary, &[][..]), |(p, rest)| (*p, rest));
    let mut errors = tempfile::tempfile().unwrap();
    let mut command = Command::new(program);
    let child = setup(on_x11(&mut command))
        .args(first)
        .args((!wrapper.is_empty()).then_some(binary))
        .args(args)
        .stdout(Stdio::null())
        .stderr(errors.try_clone().unwrap())
        .spawn()
        .expect("run snakeskin");
    let pid = child.id() as libc::pid_t;
    let (mut status, mut usage) = (0, unsafe { std::mem::zeroed::<libc::rusage>() });
    assert_eq!(unsafe { libc::wait4(pid, &mut status, 0, &mut usage) }, pid, "wait4");
    let mut stderr = String::new();
    errors.rewind().and_then(|_| errors.read_to_string(&mut stderr)).unwrap();
    Measured {
        succeeded: libc::WIFEXITED(status) && libc::WEXITSTATUS(status) == 0,
        status,
        stderr,
        peak_kib: usage.ru_maxrss as u64,
    }
}

/// A window without a display is refused before its maps are made: `preview --window
/// --map-size 4096` built its maps (3.7 GB, seconds) and then said "cannot open a window" (a
/// hostile-input review). Measured by its peak at 2048 (an estimate of 1517 MiB, which the
/// check must let through: 4096's 4.6 GB would not on a smaller runner; the maps took the
/// peak to 241 MiB even at 1024, and the refusal now takes about 10 MiB);
/// the memory check still comes first (a 1 MiB limit refuses it, as
/// `the_memory_estimate_of_a_drawing_is_above_its_peak` reads it). No GPU is needed.
#[cfg(all(target_os = "linux", feature = "window"))]
#[test]
fn a_window_without_a_display_is_refused_before_its_maps_are_made() {
    let _alone = MEASURING.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    let args = ["preview", PLAIN_PRESET, "--window", "--map-size", "2048", "--frames", "3"];
    let run = measured(&[], &args, |c| c.env_remove("DISPLAY"));
    assert!(!run.succeeded, "it opened a window without a display");
    assert!(run.stderr.contains("cannot open a window"), "{}", run.stderr);
    assert!(run.peak_kib < 100 * 1024, "peaked at {} MiB before refusing", run.peak_kib / 1024);
    let limited = common::snakeskin_env(&args, &[("SNAKESKIN_MEMORY_LIMIT_MIB", "1")]);
    assert!(common::stderr(&limited).contains("needs about"), "{}", common::stderr(&limited));
}

/// Held by each test while it measures, so that no test's children run beside another's.
static MEASURING: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// A command's memory estimate, as the refusal under a 1 MiB limit prints it.
fn estimate_mib(args: &[&str]) -> u64 {
    let refused = common::snakeskin_env(args, &[("SNAKESKIN_MEMORY_LIMIT_MIB", "1")]);
    let text = common::stderr(&refused);
    text.split("needs about ")
        .nth(1)
        .and_then(|rest| rest.split(' ').next()?.parse().ok())
        .unwrap_or_else(|| panic!("{args:?}: no estimate in {text}"))
}

/// `export`'s estimate bounds its peak, the file's making included: it counted the textures'
/// evaluation alone, 280 MiB for python-regius's body atlas at 1024, whose `.glb` peaked at
/// 344 MiB (the encoded textures, copied into the buffer and the buffer into the file, on top
/// of the evaluation's freed memory the allocator kept). A packed set (`generate --pack`)
/// held its textures twice as it wrote them. No GPU: the CPU's maps alone.
#[cfg(target_os = "linux")]
#[test]
fn the_memory_estimate_of_an_export_is_above_its_peak() {
    let _alone = MEASURING.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    let dir = tempfile::tempdir().unwrap();
    let (glb, gltf, set) = (dir.path().join("s.glb"), dir.path().join("s.gltf"), dir.path().join("set"));
    let body = ["python-regius", "--layout", "body", "--size", "1024"];
    let cases: [Vec<&str>; 3] = [
        [&["export", "--gltf", glb.to_str().unwrap()][..], &body].concat(),
        [&["export", "--gltf", gltf.to_str().unwrap()][..], &body].concat(),
        [&["generate", "--pack", "gltf", "-o", set.to_str().unwrap()][..], &body].concat(),
    ];
    for args in cases {
        let (estimate_mib, peak_mib) = (estimate_mib(&args), peak_resident_kib(&[], &args) / 1024);
        eprintln!("{args:?}: estimate {estimate_mib} MiB, peak {peak_mib} MiB");
        assert!(estimate_mib >= peak_mib, "{args:?}: estimated {estimate_mib} MiB, peaked at {peak_mib} MiB");
        assert!(estimate_mib <= 2 * peak_mib, "{args:?}: estimated {estimate_mib} MiB for a peak of {peak_mib} MiB");
    }
}

/// The memory check of the commands that draw maps is an upper bound of what they take,
/// measured (peak resident), and on a software adapter, whose textures and frames are host
/// memory as the estimate counts them, not a wild one (on a GPU they are not resident here).
/// It counted the maps' evaluation and the frame alone: 325 MiB for a body sheet with `--tile
/// 512 --map-size 512` that peaks at 631 MiB, 313 for a preview of 2048² maps (497), 204 for
/// a 2048×1024 frame (324); a sheet's frame was not counted at all, nor anywhere the
/// textures, their mip chains and staging, or the renderer. The single-species sheet of
/// large maps holds its maps while they are uploaded (the review: f32 maps beside the upload).
/// A window is measured under Xvfb (its swap chain counted; a window has no readback or PNG).
/// A grid of snakes is measured too: lavapipe holds every triangle drawn.
#[cfg(target_os = "linux")]
#[test]
fn the_memory_estimate_of_a_drawing_is_above_its_peak() {
    let Some(gpu) = gpu_or_skip("the_memory_estimate_of_a_drawing_is_above_its_peak") else { return };
    let _alone = MEASURING.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    let software = gpu.describe().contains("Cpu");
    let dir = tempfile::tempdir().unwrap();
    let (sheet, image) = (dir.path().join("s.png"), dir.path().join("p.png"));
    let (sheet, image) = (sheet.to_str().unwrap(), image.to_str().unwrap());
    let body = ["--layout", "body", "--tile", "512", "--map-size", "512", "--species", "crotalus-atrox"];
    let has_xvfb = std::process::Command::new("xvfb-run").arg("--help").output().is_ok();
    assert!(has_xvfb || !gpu_required(), "SNAKESKIN_REQUIRE_GPU=1 but xvfb-run is missing (apt-get install xvfb)");
    let xvfb = ["xvfb-run", "-a", "-s", "-screen 0 2100x1100x24"];
    let cases: [Vec<&str>; 7] = [
        [&["sheet", "-o", sheet][..], &body].concat(),
        vec!["sheet", "-o", sheet, "--tile", "256", "--map-size", "1024", "--species", "natrix-natrix,vipera-berus"],
        vec!["sheet", "-o", sheet, "--tile", "64", "--map-size", "2048", "--species", "natrix-natrix"],
        vec!["preview", PLAIN_PRESET, "--out", image, "--map-size", "2048", "--size", "16x16"],
        vec!["preview", PLAIN_PRESET, "--out", image, "--map-size", "256", "--size", "2048x1024"],
        // Each snake is drawn whole: the estimate counted one (327 MiB where 100 peak at 711).
        vec!["preview", PLAIN_PRESET, "--out", image, "--map-size", "64", "--size", "320x200", "--snakes", "100"],
        vec!["preview", PLAIN_PRESET, "--window", "--frames", "3", "--map-size", "256", "--size", "2048x1024"],
    ];
    for args in cases {
        let window = args.contains(&"--window");
        if window && !cfg!(feature = "window") {
            continue; // a headless build (`--no-default-features`) has no window to measure
        }
        if window && !has_xvfb {
            eprintln!("the_memory_estimate_of_a_drawing_is_above_its_peak: window case SKIPPED: no xvfb-run");
            continue;
        }
        // The estimate, as the refusal under a 1 MiB limit prints it.
        let estimate_mib = estimate_mib(&args);
        let peak_mib = peak_resident_kib(if window { &xvfb } else { &[] }, &args) / 1024;
        eprintln!("{args:?}: estimate {estimate_mib} MiB, peak {peak_mib} MiB");
        assert!(estimate_mib >= peak_mib, "{args:?}: estimated {estimate_mib} MiB, peaked at {peak_mib} MiB");
        if software {
            assert!(
                estimate_mib <= 2 * peak_mib,
                "{args:?}: estimated {estimate_mib} MiB for a peak of {peak_mib} MiB"
            );
        }
    }
}
