//! `snakeskin verify PATH...`: checks sets against their manifests, for pipelines that take
//! a set from a shared folder, a cache or an archive and need to know it is whole. A run
//! killed while renaming leaves an incomplete set, and a file replaced by hand a mixed one;
//! both fail here. The check is the library's (`export::verify_set`: every map the manifest
//! lists exists beside it with the SHA-256 it records), so `batch`, which skips finished
//! jobs by it, and this command agree on what a finished set is.

use std::path::{Path, PathBuf};

use anyhow::Result;

use crate::output::path_line;
use snakeskin::export::MANIFEST_SUFFIX;

/// The most manifests one folder argument is searched for: a set folder holds one, a batch
/// folder one per job; a folder with more is not a set folder (`verify /`), and is refused
/// before any file is hashed.
const MAX_MANIFESTS: usize = 100_000;

/// How far below a folder argument manifests are looked for: a batch writes each set two
/// folders down (`OUT/PRESET/tile-1024-seed1-png/`).
const SUBFOLDER_LEVELS: usize = 2;

pub fn run(paths: &[PathBuf]) -> Result<()> {
    let mut manifests = Vec::new();
    for path in paths {
        manifests.extend(manifests_at(path)?);
    }
    let mut failed = 0;
    for manifest in &manifests {
        match snakeskin::export::verify_set(manifest) {
            Ok(set) => println!("ok {} ({} files)", path_line(manifest), set.files.len()),
            Err(e) => {
                failed += 1;
                // The error names the manifest (`set PATH: problem`).
                println!("FAILED {}", crate::output::printable(&e.to_string()).replace('\n', "\\n"));
            }
        }
    }
    if failed > 0 {
        anyhow::bail!("{failed} of {} sets failed: incomplete or altered (listed above)", manifests.len());
    }
    Ok(())
}

/// The manifests `path` names: itself, where it is a file; in a folder, those in it and in
/// its subfolders down to `SUBFOLDER_LEVELS` (a batch's output), hidden entries and links
/// passed over. A manifest missing
/// from its folder is an incomplete set; a path that is missing otherwise, one that is no
/// manifest, or a folder without a manifest, is the user's mistake.
fn manifests_at(path: &Path) -> Result<Vec<PathBuf>> {
    let invalid = |reason: String| snakeskin::Error::InvalidOption { option: "verify PATH", reason };
    let names_a_manifest = path.to_string_lossy().ends_with(MANIFEST_SUFFIX);
    let metadata = match std::fs::metadata(path) {
        Ok(metadata) => metadata,
        // A manifest missing from a folder that exists is a set that is incomplete (a run
        // killed while renaming), which `verify_set` says.
        Err(e)
            if e.kind() == std::io::ErrorKind::NotFound
                && names_a_manifest
                && path.parent().is_some_and(|p| p.as_os_str().is_empty() || p.is_dir()) =>
        {
            return Ok(vec![path.to_path_buf()]);
        }
        Err(e) => return Err(invalid(format!("{}: {e}", path_line(path))).into()),
    };
    if !metadata.is_dir() {
        if !names_a_manifest {
            let gltf =
                path.extension().is_some_and(|e| e.eq_ignore_ascii_case("glb") || e.eq_ignore_ascii_case("gltf"));
            let reason = format!(
                "{} is not a set's manifest (NAME{MANIFEST_SUFFIX}) or a folder of sets{}",
                path_line(path),
                if gltf { " (a glTF export carries no manifest)" } else { "" }
            );
            return Err(invalid(reason).into());
        }
        return Ok(vec![path.to_path_buf()]);
    }
    let mut found = Vec::new();
    // Depth first, in name order, so the lines come out in the order `ls -R` lists them.
    let mut folders = vec![(path.to_path_buf(), 0)];
    while let Some((folder, depth)) = folders.pop() {
        let mut below = Vec::new();
        for entry in read_sorted(&folder)? {
            let name = entry.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
            if name.starts_with('.') || entry.is_symlink() {
                continue;
            }
            if entry.is_dir() {
                if depth < SUBFOLDER_LEVELS {
                    below.push((entry, depth + 1));
                }
            } else if name.ends_with(MANIFEST_SUFFIX) && entry.is_file() {
                found.push(entry);
                if found.len() > MAX_MANIFESTS {
                    let reason =
                        format!("{} holds more than {MAX_MANIFESTS} manifests: name a set's folder", path_line(path));
                    return Err(invalid(reason).into());
                }
            }
        }
        folders.extend(below.into_iter().rev());
    }
    if found.is_empty() {
        let reason = format!(
            "{} holds no set's manifest (NAME{MANIFEST_SUFFIX}), nor do its subfolders: nothing to verify",
            path_line(path)
        );
        return Err(invalid(reason).into());
    }
    Ok(found)
}

/// The entries of `folder`, sorted by path (the listing's order is the file system's).
fn read_sorted(folder: &Path) -> Result<Vec<PathBuf>> {
    let entries = std::fs::read_dir(folder)
        .map_err(|e| anyhow::anyhow!("cannot list {}: {e}", path_line(folder)))?
        .map(|entry| entry.map(|e| e.path()))
        .collect::<std::io::Result<Vec<_>>>()
        .map_err(|e| anyhow::anyhow!("cannot list {}: {e}", path_line(folder)))?;
    let mut entries = entries;
    entries.sort();
    Ok(entries)
}
