//! `snakeskin verify PATH...`: checks sets against their manifests, for pipelines that take
//! a set from a shared folder, a cache or an archive and need to know it is whole. A run
//! killed or failed while writing a set leaves an incomplete one (maps without their
//! manifest), and a file replaced by hand a mixed one; both fail here. The check of a manifest is the library's
//! (`export::verify_set`: every map it lists exists beside it with the SHA-256 it records),
//! so `batch`, which skips finished jobs by it, and this command agree on what a finished
//! set is; a set's files are known by `export::every_set_file_name`, as a commit knows them.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::Result;

use crate::output::path_line;
use snakeskin::export::MANIFEST_SUFFIX;

/// The most sets one folder argument is searched for: a set folder holds one, a batch
/// folder one per job; a folder with more is not a set folder (`verify /`), and is refused
/// before any file is hashed.
const MAX_SETS: usize = 100_000;

/// How far below a folder argument sets are looked for: a batch writes each set two
/// folders down (`OUT/PRESET/tile-1024-seed1-png/`).
const SUBFOLDER_LEVELS: usize = 2;

/// What one line of the report checks.
enum Check {
    /// A set's manifest (which may be missing, or no regular file: `verify_set` says so).
    Manifest(PathBuf),
    /// Files of a set named `name` in `folder` with no manifest beside them.
    Orphans { folder: PathBuf, name: String, files: usize },
    /// A set named `name` in `folder` with neither its manifest nor any of its files, only
    /// temporaries of them (`.FILE.RANDOM.snakeskin-tmp`): a run killed or failed while
    /// writing, after it moved the old set aside and before it moved the new one in (or
    /// before any rename, where there was no old set). Hidden, they were
    /// passed over, and the folder's other sets said `ok`. Where a run holds the set's lock
    /// it is being written: said so, not failed (`export::lock_is_held`).
    Interrupted { folder: PathBuf, name: String, temporaries: usize },
    /// A subfolder that could not be listed: the sets in it are not checked.
    Unlistable { folder: PathBuf, error: String },
}

pub fn run(paths: &[PathBuf]) -> Result<()> {
    let mut checks = Vec::new();
    // The paths that hold no set to check (the user's mistake, exit 2), each with why. They
    // do not keep the others from being checked: `verify a typo c` checked nothing, and a
    // pipeline learnt of a and c only from a second run (a sweep's note).
    let mut unusable = Vec::new();
    for path in paths {
        match checks_at(path) {
            Ok(found) => checks.extend(found),
            Err(reason) => unusable.push(reason),
        }
    }
    // Each set once, however often it is named (a manifest and its folder, `./x` and `x`, a
    // folder reached again through a link to it).
    let mut seen = std::collections::HashSet::new();
    checks.retain(|check| seen.insert(identity(check)));
    let mut failed = 0;
    for check in &checks {
        let failure = match check {
            Check::Manifest(manifest) => match snakeskin::export::verify_set(manifest) {
                Ok(set) => {
                    let count = set.files.len();
                    // A set a run replaced while it was checked was checked again, whole.
                    let again = if set.tries > 1 { "; replaced while checked, checked again" } else { "" };
                    println!("ok {} ({count} file{}{again})", path_line(manifest), if count == 1 { "" } else { "s" });
                    continue;
                }
                Err(_) if being_written(manifest) => continue,
                // The error names the manifest (`set PATH: problem`).
                Err(e) => e.to_string(),
            },
            Check::Orphans { folder, name, .. } if said_being_written(folder, name) => continue,
            Check::Orphans { folder, name, files } => format!(
                "set {}: {files} of its files but no manifest ({name}{MANIFEST_SUFFIX}): the set is incomplete (a \
                 run failed or was killed while writing it), or the files are not a set's",
                path_line(&folder.join(name))
            ),
            Check::Interrupted { folder, name, .. } if said_being_written(folder, name) => continue,
            Check::Interrupted { folder, name, temporaries } => format!(
                "set {}: no manifest and none of its files, only {temporaries} hidden temporar{} a run left while \
                 writing it (.FILE.RANDOM.snakeskin-tmp): the run was killed or failed before the set was whole. They \
                 may hold the earlier set's files (a commit that failed and could not be undone keeps them so, and \
                 says so): look before running again, which removes them",
                path_line(&folder.join(name)),
                if *temporaries == 1 { "y" } else { "ies" },
            ),
            Check::Unlistable { folder, error } => {
                format!("cannot list {}: {error}: the sets in it are not checked", path_line(folder))
            }
        };
        failed += 1;
        println!("FAILED {}", crate::output::printable(&failure).replace('\n', "\\n"));
    }
    if !unusable.is_empty() {
        // The paths' own reasons first, as a single bad path's error has always read; what
        // the others' checks found after them, where there were any.
        let mut reason = unusable.join("; ");
        if !checks.is_empty() {
            let outcome = if failed > 0 { format!("{failed} failed (listed above)") } else { "none failed".into() };
            reason += &format!(" (the other paths' {} checks: {outcome})", checks.len());
        }
        return Err(snakeskin::Error::InvalidOption { option: "verify PATH", reason }.into());
    }
    if failed > 0 {
        anyhow::bail!("{failed} of {} checks failed: sets incomplete, altered or unread (listed above)", checks.len());
    }
    Ok(())
}

/// Whether the set `name` in `folder` is being written now (a run holds its lock:
/// `export::lock_is_held`), said so where it is: not a broken set, and not one to check. A
/// set read while a run replaced it was FAILED, "mixed or altered" (the old manifest, the
/// new maps) or "no manifest" (a sweep: 24 of 1663 checks beside a run writing the set).
fn said_being_written(folder: &Path, name: &str) -> bool {
    let held = snakeskin::export::lock_is_held(folder, name);
    if held {
        println!("writing {}: a run holds its lock now; not checked", path_line(&folder.join(name)));
    }
    held
}

/// `said_being_written` of the set whose manifest is `manifest`.
fn being_written(manifest: &Path) -> bool {
    let folder = snakeskin::export::folder_of(manifest);
    let name = manifest.file_name().and_then(|n| n.to_str()).and_then(|n| n.strip_suffix(MANIFEST_SUFFIX));
    name.is_some_and(|name| said_being_written(folder, name))
}

/// Which set a check is of, the same however it was reached: the kind of check, and the
/// set's folder with links resolved joined with its name. A manifest is known by the folder
/// it lies in, not by the file a link to it points to: its maps are looked for beside the
/// link, so two folders whose manifests link to one file are two sets (one was passed over,
/// and an altered copy said `ok`; a review).
fn identity(check: &Check) -> (u8, PathBuf) {
    let real = |folder: &Path| std::fs::canonicalize(folder).unwrap_or_else(|_| folder.to_path_buf());
    match check {
        Check::Manifest(path) => {
            let folder = snakeskin::export::folder_of(path);
            let name = path.file_name().unwrap_or_default();
            // A manifest named but missing is the set its folder's files make: the same
            // line as its folder's (`verify c/x.material.json c` said it twice, a review).
            let set = name_text(name);
            match set.strip_suffix(MANIFEST_SUFFIX) {
                Some(set) if path.symlink_metadata().is_err() => (1, real(folder).join(set)),
                _ => (0, real(folder).join(name)),
            }
        }
        Check::Orphans { folder, name, .. } => (1, real(folder).join(name)),
        Check::Interrupted { folder, name, .. } => (2, real(folder).join(name)),
        Check::Unlistable { folder, .. } => (3, real(folder)),
    }
}

/// What `path` names: a manifest, where it is one (or names one in a folder that holds the
/// set's files: an incomplete set); in a folder, the sets in it and in its subfolders down
/// to `SUBFOLDER_LEVELS` (a batch's output), links followed, hidden entries passed over but
/// for a run's temporaries of a set that is missing (`Check::Interrupted`). A
/// path that is missing, one that is no manifest, or a folder without a set, is the user's
/// mistake: the error is why.
fn checks_at(path: &Path) -> Result<Vec<Check>, String> {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let set_name = name.strip_suffix(MANIFEST_SUFFIX).filter(|s| !s.is_empty());
    let metadata = std::fs::metadata(path);
    if let Some(set_name) = set_name {
        // A manifest that is there is checked (a folder of that name too: `verify_set` says
        // it is no file, as when its folder is named); a missing one is an incomplete set
        // where the set's files lie beside it, and a wrong path otherwise (a typo).
        let folder = snakeskin::export::folder_of(path);
        let present = metadata.is_ok() || path.is_symlink();
        if present || set_files_in(folder, set_name) > 0 {
            return Ok(vec![Check::Manifest(path.to_path_buf())]);
        }
        let reason = format!("{}: no such manifest, and no file of set {set_name:?} beside it", path_line(path));
        return Err(reason);
    }
    let metadata = metadata.map_err(|e| format!("{}: {e}", path_line(path)))?;
    if !metadata.is_dir() {
        let gltf = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("glb") || e.eq_ignore_ascii_case("gltf"));
        let reason = format!(
            "{} is not a set's manifest (NAME{MANIFEST_SUFFIX}) or a folder of sets{}",
            path_line(path),
            if gltf { " (a glTF export carries no manifest)" } else { "" }
        );
        return Err(reason);
    }
    let suffixes: Vec<String> =
        snakeskin::export::every_set_file_name("").into_iter().filter(|n| n != MANIFEST_SUFFIX).collect();
    let mut checks = Vec::new();
    // Folders deeper than `SUBFOLDER_LEVELS`: said on stderr, so that an `ok` for a folder
    // holding several batch outputs does not read as every set in it checked (it did).
    let mut not_searched: (usize, Option<PathBuf>) = (0, None);
    // Each folder listed once at its shallowest depth reached so far (file identity: device
    // and inode), however many links lead to it: 200 links to `.` in one folder were
    // listed 40,000 times at the second level, and 8,000,000 folders kept as not searched
    // (29 s and 573 MB; 300 links 100 s and 1.9 GB: a sweep).
    let mut listed: std::collections::HashMap<(u64, u64), usize> = std::collections::HashMap::new();
    // Depth first, in name order, so the lines come out in the order `ls -R` lists them.
    let mut folders = vec![(path.to_path_buf(), 0)];
    while let Some((folder, depth)) = folders.pop() {
        if let Some(identity) = folder_identity(&folder) {
            if listed.get(&identity).is_some_and(|at| *at <= depth) {
                continue;
            }
            listed.insert(identity, depth);
        }
        let entries = match read_sorted(&folder) {
            Ok(entries) => entries,
            Err(e) if depth == 0 => return Err(format!("cannot list {}: {e}", path_line(&folder))),
            Err(e) => {
                checks.push(Check::Unlistable { folder, error: e.to_string() });
                continue;
            }
        };
        let mut below = Vec::new();
        // Set name → its files here; which of them have a manifest.
        let mut sets: BTreeMap<String, usize> = BTreeMap::new();
        let mut manifests = Vec::new();
        // Set name → the temporaries of its files here (hidden, so otherwise passed over).
        let mut temporaries: BTreeMap<String, usize> = BTreeMap::new();
        for entry in entries {
            let name = entry.file_name().map(name_text).unwrap_or_default();
            if name.starts_with('.') {
                let target = snakeskin::export::temporary_target(&name);
                let set = target.and_then(|t| {
                    t.strip_suffix(MANIFEST_SUFFIX)
                        .filter(|s| !s.is_empty())
                        .map(str::to_string)
                        .or_else(|| set_of(t, &suffixes))
                });
                if let Some(set) = set {
                    *temporaries.entry(set).or_default() += 1;
                }
                continue;
            }
            if let Some(set) = name.strip_suffix(MANIFEST_SUFFIX).filter(|s| !s.is_empty()) {
                // Whatever it is (a file, a link, a FIFO, a folder): `verify_set` says.
                manifests.push(set.to_string());
                checks.push(Check::Manifest(entry));
            } else if entry.is_dir() {
                if depth < SUBFOLDER_LEVELS {
                    below.push((entry, depth + 1));
                } else if !folder_identity(&entry).is_some_and(|identity| listed.contains_key(&identity)) {
                    // Not a folder searched already (a link back up: the review).
                    not_searched.0 += 1;
                    not_searched.1.get_or_insert(entry);
                }
            } else if let Some(set) = set_of(&name, &suffixes) {
                *sets.entry(set).or_default() += 1;
            }
            if checks.len() > MAX_SETS {
                let reason = format!("{} holds more than {MAX_SETS} sets: name a set's folder", path_line(path));
                return Err(reason);
            }
        }
        for (name, count) in temporaries {
            if !manifests.contains(&name) && !sets.contains_key(&name) {
                checks.push(Check::Interrupted { folder: folder.clone(), name, temporaries: count });
            }
        }
        for (name, files) in sets {
            if !manifests.contains(&name) {
                checks.push(Check::Orphans { folder: folder.clone(), name, files });
            }
        }
        folders.extend(below.into_iter().rev());
    }
    if let (count, Some(first)) = not_searched {
        eprintln!(
            "note: sets are looked for {SUBFOLDER_LEVELS} folders below {} (a batch's depth); {count} folder{} deeper \
             not searched, the first {}: name such a folder to verify the sets in it",
            path_line(path),
            if count == 1 { "" } else { "s" },
            path_line(&first)
        );
    }
    if checks.is_empty() {
        let reason = format!(
            "{} holds no set (NAME{MANIFEST_SUFFIX} or a set's files), nor do its subfolders: nothing to verify",
            path_line(path)
        );
        return Err(reason);
    }
    Ok(checks)
}

/// A file name as text that keeps every name apart: its bytes that are not UTF-8 written as
/// `\xNN`, and a backslash as two (so that a name spelt `a\xff` is not the byte's). Read
/// lossily, `a\xff_color.png` and `a\xfe_color.png` were one set `a�` (a sweep of `verify`:
/// two incomplete sets reported as one, or one hidden beside a whole set `a\xff`).
fn name_text(name: &std::ffi::OsStr) -> String {
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStrExt;
        let mut text = String::new();
        for chunk in name.as_bytes().utf8_chunks() {
            text.push_str(&chunk.valid().replace('\\', "\\\\"));
            for byte in chunk.invalid() {
                text.push_str(&format!("\\x{byte:02x}"));
            }
        }
        text
    }
    #[cfg(not(unix))]
    {
        name.to_string_lossy().into_owned()
    }
}

/// The set whose file `file_name` is (`NAME_color.png`, `NAME_orm.png`, …), if it ends in one
/// of the suffixes every set's file names have (`suffixes`: `every_set_file_name` of the
/// empty name, its manifest's left out).
fn set_of(file_name: &str, suffixes: &[String]) -> Option<String> {
    // The longest suffix that fits: a set name may end as a shorter suffix begins.
    suffixes
        .iter()
        .filter(|suffix| file_name.len() > suffix.len() && file_name.ends_with(suffix.as_str()))
        .max_by_key(|suffix| suffix.len())
        .map(|suffix| file_name[..file_name.len() - suffix.len()].to_string())
}

/// How many files of set `set_name` lie in `folder` (its manifest aside).
fn set_files_in(folder: &Path, set_name: &str) -> usize {
    let manifest = snakeskin::export::manifest_file_name(set_name);
    snakeskin::export::every_set_file_name(set_name)
        .iter()
        .filter(|name| **name != manifest && folder.join(name).symlink_metadata().is_ok())
        .count()
}

/// A folder's file identity (device, inode), links followed; None where it cannot be read
/// (listing it then says why) or off Unix.
fn folder_identity(folder: &Path) -> Option<(u64, u64)> {
    if cfg!(not(unix)) {
        return None;
    }
    let (device, inode, ..) = snakeskin::export::file_identity(folder, snakeskin::text_file::Links::Follow)?;
    Some((device, inode))
}

/// The entries of `folder`, sorted by path (the listing's order is the file system's).
fn read_sorted(folder: &Path) -> std::io::Result<Vec<PathBuf>> {
    let mut entries =
        std::fs::read_dir(folder)?.map(|entry| entry.map(|e| e.path())).collect::<std::io::Result<Vec<_>>>()?;
    entries.sort();
    Ok(entries)
}
