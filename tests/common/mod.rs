//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

pub const PATTERNED: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/patterned.toml");

/// Runs the `snakeskin` binary with `args`, stderr not a terminal (so no progress bar).
pub fn snakeskin(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_snakeskin")).args(args).output().expect("run snakeskin")
}

pub fn snakeskin_env(args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_snakeskin"));
    cmd.args(args);
    for (k, v) in env {
        cmd.env(k, v);
    }
    cmd.output().expect("run snakeskin")
}

/// The test hooks (`SNAKESKIN_TEST_PAUSE_AT`, `_FAIL_AT_RENAME`, `_KILL_AT_RENAME`) exist in
/// debug builds only (`cargo test`, the README's command); under `--release` the tests that
/// need them say so and pass.
pub fn test_hooks_exist() -> bool {
    if !cfg!(debug_assertions) {
        eprintln!("SKIPPED: the test hooks exist in debug builds only (cargo test without --release)");
    }
    cfg!(debug_assertions)
}

/// Returns once process `pid` holds `path` open, as its descriptors in /proc show (a run
/// trying a lock another holds keeps the lock file open while it tries); panics after a
/// minute. `path` as /proc names it: canonical, through any link in the temporary folder's.
#[cfg(target_os = "linux")]
pub fn wait_until_open(pid: u32, path: &Path) {
    let holds_it = || {
        let fds = std::fs::read_dir(format!("/proc/{pid}/fd")).into_iter().flatten().flatten();
        fds.filter_map(|fd| std::fs::read_link(fd.path()).ok()).any(|target| target == path)
    };
    let start = std::time::Instant::now();
    while !holds_it() {
        assert!(start.elapsed().as_secs() < 60, "process {pid} never opened {path:?}");
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
}

/// Starts `snakeskin args` paused at its commit (`SNAKESKIN_TEST_PAUSE_AT=commit`, three
/// seconds: debug builds) and returns once it has staged a file in `folder` (a temporary
/// there with bytes: `check_writable`'s probe is an empty one, made before the work), so
/// that the test can act while the run waits; output piped. A run that never gets there is
/// killed before the test fails.
pub fn spawn_paused_at_commit(args: &[&str], folder: &Path) -> std::process::Child {
    let child = Command::new(env!("CARGO_BIN_EXE_snakeskin"))
        .args(args)
        .env("SNAKESKIN_TEST_PAUSE_AT", "commit")
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("run snakeskin");
    let staged = || {
        std::fs::read_dir(folder).is_ok_and(|e| {
            e.flatten().any(|f| {
                f.file_name().to_string_lossy().ends_with(".snakeskin-tmp") && f.metadata().is_ok_and(|m| m.len() > 0)
            })
        })
    };
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(120);
    while !staged() {
        if std::time::Instant::now() > deadline {
            let mut child = child;
            let _ = child.kill();
            let _ = child.wait();
            panic!("{args:?} never staged a file in {folder:?}");
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    child
}

pub fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

pub fn stdout(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Every file in a folder with its bytes.
pub fn snapshot(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut files = BTreeMap::new();
    if let Ok(entries) = std::fs::read_dir(dir) {
        for entry in entries.flatten() {
            files.insert(entry.path(), std::fs::read(entry.path()).unwrap());
        }
    }
    files
}

/// Writes a preset file into `dir` and returns its path as a string.
pub fn write_preset(dir: &Path, name: &str, text: &str) -> String {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path.to_string_lossy().into_owned()
}

/// The GPU, or None (after printing why) when the test may skip. With
/// SNAKESKIN_REQUIRE_GPU=1 (set in .ci/run) a missing adapter fails the test instead.
pub fn gpu_or_skip(test: &str) -> Option<snakeskin::render::Gpu> {
    match snakeskin::render::Gpu::headless() {
        Ok(gpu) => {
            eprintln!("{test}: running on {}", gpu.describe());
            Some(gpu)
        }
        Err(e) if gpu_required() => panic!("{test}: SNAKESKIN_REQUIRE_GPU=1 but {e}"),
        Err(e) => {
            eprintln!("{test}: SKIPPED: {e}");
            None
        }
    }
}

pub fn gpu_required() -> bool {
    std::env::var("SNAKESKIN_REQUIRE_GPU").is_ok_and(|v| v == "1")
}

/// Relative luminance Y of a linear sRGB colour, from the library's own sRGB matrix
/// (`optics::spectrum`), so that no test writes the weights again.
pub fn luminance(rgb: &[f32]) -> f32 {
    snakeskin::optics::spectrum::linear_srgb_to_xyz([rgb[0], rgb[1], rgb[2]].map(f64::from))[1] as f32
}

/// A preset parsed from TOML text (panics with the error and the text).
pub fn preset_from(text: &str) -> snakeskin::preset::Preset {
    let source = snakeskin::preset::PresetSource { name: "t".into(), display: "test preset".into(), text: text.into() };
    snakeskin::preset::parse(&source, &[]).unwrap_or_else(|e| panic!("{e}\n{text}")).preset
}

/// The colour map of a preset's TOML text at `size` × `size` (linear, f32).
pub fn colour_map(text: &str, size: usize) -> snakeskin::ops::Image {
    use snakeskin::maps::{BuildOptions, MapKind, build_graph};
    let graph = build_graph(&preset_from(text), BuildOptions::default());
    snakeskin::graph::evaluate(&graph, &[MapKind::Color], size, size, &|_, _| {}).maps.remove(&MapKind::Color).unwrap()
}

/// The scale field of a preset's TOML text with every channel, in `ops::scales::channel`
/// order (the maps' own field asks only for the channels they read).
pub fn full_scale_field(text: &str, size: usize) -> snakeskin::ops::Image {
    let mut field = snakeskin::maps::scale_field(&preset_from(text), snakeskin::maps::Layout::Tile);
    field.outputs = (0..snakeskin::ops::scales::channel::COUNT).collect();
    field.render(size, size)
}

/// Mean absolute difference between rows `a` and `b` (all channels).
pub fn row_jump(img: &snakeskin::ops::Image, a: usize, b: usize) -> f64 {
    let (ra, rb) = (img.row(a), img.row(b));
    ra.iter().zip(rb).map(|(x, y)| (x - y).abs() as f64).sum::<f64>() / ra.len() as f64
}

pub fn transpose(img: &snakeskin::ops::Image) -> snakeskin::ops::Image {
    let mut t = snakeskin::ops::Image::new(img.height, img.width, img.channels);
    for y in 0..img.height {
        for x in 0..img.width {
            for c in 0..img.channels {
                t.data[(x * img.height + y) * img.channels + c] = img.data[(y * img.width + x) * img.channels + c];
            }
        }
    }
    t
}

/// Asserts the seam (last row → first row) jumps no more than 1.5× the larger of the jumps
/// just beside it and the mean jump between neighbouring rows. "Beside" is the largest of
/// the four jumps on each side: fine random texture (melanophore speckle on a pale belly)
/// makes any one pair of rows jump by chance, while a real seam jumps more than all of them.
pub fn assert_rows_seamless(img: &snakeskin::ops::Image, what: &str) {
    let n = img.height;
    let seam = row_jump(img, n - 1, 0);
    let beside = (0..4).map(|k| row_jump(img, k, k + 1).max(row_jump(img, n - 2 - k, n - 1 - k))).fold(0.0, f64::max);
    let mean = (0..n - 1).map(|y| row_jump(img, y, y + 1)).sum::<f64>() / (n - 1) as f64;
    let limit = 1.5 * beside.max(mean);
    assert!(seam <= limit, "{what}: seam jump {seam:.5} > 1.5 × max(beside {beside:.5}, mean {mean:.5})");
}

/// `command` without the desktop's Wayland variables, so that a window opens on the Xvfb
/// that `xvfb-run` starts, not on the desktop's compositor (which winit prefers).
#[cfg(any(target_os = "linux", feature = "window"))]
pub fn on_x11(command: &mut std::process::Command) -> &mut std::process::Command {
    command.env_remove("WAYLAND_DISPLAY").env_remove("WAYLAND_SOCKET")
}
