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
