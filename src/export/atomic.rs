//! Output that is never half-written, never mixed, and never follows a planted link.
//!
//! **Single files** (`write_file_atomically`: charts, plots, sheets) are written
//! to a fresh temporary in the target folder — created exclusively (`O_EXCL`), with an
//! unpredictable name, so a symlink planted at a guessable name cannot redirect the write —
//! then renamed over the target. A reader sees the old file or the new one, never a part.
//!
//! **Groups of files** (`FileGroup`: the documentation figures, a gallery with its close-ups,
//! a preview with its heat map) are staged the same way, each as soon as it is made, and
//! renamed into place together at the end, the old files moved aside first and put back if a
//! rename fails: an interrupt or a failure while they are made leaves the earlier files as
//! they were, never some new. A group (or commit) of one file is one rename over the old.
//!
//! **Texture sets** (`SetLock`: `stage` each map, then `commit`; `write` does both) are
//! several files, and a rename is atomic only per file, so the set's manifest is its commit
//! record:
//!
//! 1. `SetLock::acquire` takes an exclusive advisory lock (`flock`) on `DIR/.NAME.lock`
//!    before any pixel is computed; a second run on the same set fails at once with a
//!    clear error instead of interleaving its files with ours. The kernel releases the
//!    lock when a process dies, so a killed run never blocks the next one. The lock file is
//!    removed when the run ends (a killed run leaves an empty one, reused by the next);
//!    whoever locks checks that the path still names the file it locked, so removal never
//!    lets two runs hold the set at once.
//! 2. Under the lock, every file is written to a new temporary (`stage`, as soon as its
//!    bytes exist, so they need not be held), after the temporaries a killed run left for
//!    that file name are removed (their names end in `.snakeskin-tmp`). A set stages each
//!    file name once: a second stage of a name would remove the first's temporary.
//! 3. Before any rename, every target is checked: a folder where a file must go is an
//!    error, and nothing has changed yet.
//! 4. The old files are moved aside to temporaries, the old manifest first, and with them
//!    the old set's maps that the new one does not write (`left_over_files`); then the maps
//!    are renamed into place, and the new manifest, which records the SHA-256 of every map,
//!    is renamed in last; then the old files are removed.
//!
//! A glTF export takes the same lock and commit, its `.glb` or `.gltf` the record file (the
//! `.gltf`'s side files staged before it); the manifest's guarantee below is a set's.
//!
//! The guarantee: **whenever `NAME.material.json` exists, the maps it names are exactly the
//! ones it was written with** — `verify_set` checks the hashes. An earlier set survives every
//! failure: before step 4 nothing has changed, and a rename that fails in step 4 (a file
//! that may not be replaced, a full disk) undoes the commit — the new files go and the old
//! ones are renamed back, the manifest last. If a rename of the undo fails too, the old
//! files that could not go back stay in their temporaries and the old manifest stays aside
//! with them. A kill during step 4 or its undo leaves no manifest (some maps or none, the
//! old files in temporaries the next run removes): an incomplete set that no reader
//! accepts, never maps under a manifest that did not name them.
//!
//! **An interrupted run** (Ctrl-C, SIGTERM, SIGHUP: the binary's handler calls
//! `clean_up_before_exit`) waits for a commit in progress and its undo to end, then removes
//! its temporaries of new files, and no new temporary or commit starts after that. Without
//! it, a Ctrl-C left hidden temporaries (up to a set's size) until the next run in that
//! folder. The old files a commit moved aside are the commit's to put back or remove, never
//! the handler's. Its set lock files and the empty folders it made go too (a batch left a
//! lock in every set folder it had begun): the commit and temporaries' locks stay held
//! until the exit, so another run that takes a set meanwhile meets no write of this one's
//! but an export's removal of a thickness image its just-committed set no longer writes.
//! The locks are taken in one order: `COMMIT`, `LIVE`, `HELD_LOCKS`, `MADE_FOLDERS`.

use std::fs::{self, File};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Mutex, MutexGuard};

use sha2::{Digest, Sha256};

use super::ExportError;

/// The suffix of every temporary this module creates.
const TMP_SUFFIX: &str = ".snakeskin-tmp";

/// Random characters in a temporary's name (between `.FILE.` and the suffix).
const RANDOM_CHARS: usize = 6;

/// The longest file name, in bytes, that Linux's file systems take (ext4, XFS, Btrfs, tmpfs:
/// `NAME_MAX`, limits.h) and macOS's APFS (255 UTF-8 bytes).
const NAME_MAX_BYTES: usize = 255;

/// The part of a file's name its temporaries carry: `.STEM.RANDOM.snakeskin-tmp` must itself
/// be a legal name, so a name near the limit is cut (at a character boundary) and ends in
/// `~` and eight hex digits of its SHA-256, so that two names cut alike keep stems of their
/// own: the sweep of one name's stale temporaries (`remove_stale_temporaries`) matches its
/// stem exactly, and a set's maps share their first 233 bytes when the set's name is long
/// (the first cut, without the digits, swept a set's other staged maps: "No such file or
/// directory" after the work). Without any cut, a legal 234-byte output name failed after the
/// work with "cannot write .: File name too long".
fn temporary_stem(target_name: &str) -> std::borrow::Cow<'_, str> {
    cut_to(target_name, NAME_MAX_BYTES - 2 - RANDOM_CHARS - TMP_SUFFIX.len())
}

/// `name` if it has at most `room` bytes, else its first bytes, `~` and eight hex digits of
/// its SHA-256 in `room` bytes (`temporary_stem`, `lock_file_name`).
fn cut_to(name: &str, room: usize) -> std::borrow::Cow<'_, str> {
    if name.len() <= room {
        return name.into();
    }
    let mut end = room - 9;
    while !name.is_char_boundary(end) {
        end -= 1;
    }
    format!("{}~{}", &name[..end], &sha256_hex(name.as_bytes())[..8]).into()
}

/// The lock file of the set (or export) `name`: `.NAME.lock`, the name cut as a temporary's
/// is where that would pass `NAME_MAX_BYTES` (a legal 255-byte `NAME.glb` failed for its
/// lock's name, "File name too long").
pub fn lock_file_name(name: &str) -> String {
    format!(".{}.lock", cut_to(name, NAME_MAX_BYTES - ".".len() - ".lock".len()))
}

/// This process's temporaries of new files (staged, not yet renamed into place): what
/// `clean_up_before_exit` removes.
static LIVE: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// This process's set lock files (`SetLock`), for `clean_up_before_exit` to remove: a batch
/// interrupted by Ctrl-C left `.NAME.lock` in its sets' folders (a folder of a lock alone,
/// where the job had not begun writing), until a later run took the lock again.
static HELD_LOCKS: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Held by a commit from its first rename to its last (the undo's included), and by
/// `clean_up_before_exit` from when it begins until the process exits. Taken before `LIVE`.
static COMMIT: Mutex<()> = Mutex::new(());

/// Whether a commit's renames (or its undo) are under way (`swap_in`), for a second signal
/// that must not end the run in the middle of them (`wait_for_commit`).
static COMMITTING: AtomicBool = AtomicBool::new(false);

/// Sets `COMMITTING` for as long as it lives (a failed rename's early return included).
struct Committing;

impl Committing {
    fn start() -> Committing {
        COMMITTING.store(true, Ordering::SeqCst);
        Committing
    }
}

impl Drop for Committing {
    fn drop(&mut self) {
        COMMITTING.store(false, Ordering::SeqCst);
    }
}

/// Waits while a commit's renames are under way, at most `limit`; whether none is (any
/// more). A second signal waits so (`output::clean_up_on_interrupt` in the binary): it
/// exited at once, and a Ctrl-C pressed twice during the few milliseconds of a commit left
/// new maps and old ones under the set's names, no manifest, and the earlier set only in
/// temporaries, which the next run removed (an interruption review). The limit keeps the
/// way out of a rename that hangs (a stalled network drive).
pub fn wait_for_commit(limit: std::time::Duration) -> bool {
    let start = std::time::Instant::now();
    while COMMITTING.load(Ordering::SeqCst) {
        if start.elapsed() >= limit {
            return false;
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    true
}

/// A poisoned lock still guards valid data here (lists of paths), so it is used as it is.
fn locked<T>(mutex: &'static Mutex<T>) -> MutexGuard<'static, T> {
    mutex.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// For a process that is about to exit on a signal: waits for a commit in progress (and its
/// undo) to end, then removes this process's temporaries of new files, its set lock files
/// (the locks themselves go with the process) and the folders it made that are empty then.
/// Returns how many temporaries it removed. The commit and temporaries' locks stay held, so
/// no temporary or commit starts before the exit (a thread that tries waits until then); a
/// second call returns the first one's count.
pub fn clean_up_before_exit() -> usize {
    static REMOVED: std::sync::OnceLock<usize> = std::sync::OnceLock::new();
    *REMOVED.get_or_init(|| {
        std::mem::forget(locked(&COMMIT));
        let live = locked(&LIVE);
        let removed = live.iter().filter(|path| fs::remove_file(path).is_ok()).count();
        std::mem::forget(live);
        // Taken in `SetLock::acquire`'s order and kept: no lock file or folder is made after
        // these are removed (a batch's next job made its folder in between).
        let held = locked(&HELD_LOCKS);
        for lock in held.iter() {
            let _ = fs::remove_file(lock);
        }
        let mut made = locked(&MADE_FOLDERS);
        remove_empty(&mut made);
        std::mem::forget((held, made));
        removed
    })
}

/// `path` is not (or no longer) a temporary of a new file: renamed into place, or the name
/// of a new temporary that holds an old file moved aside (a name a dropped one had).
fn forget_temporary(path: &Path) {
    locked(&LIVE).retain(|p| p != path);
}

/// The error of an operation on `path`: the folder's, when it refused to make a file that is
/// not there (`folder_refused`).
fn io_error(path: &Path) -> impl FnOnce(std::io::Error) -> ExportError + '_ {
    move |source| {
        if path.file_name().is_some() && fs::symlink_metadata(path).is_err() {
            folder_refused(path, source)
        } else {
            ExportError::Io { path: path.into(), source }
        }
    }
}

/// The error of making the new file `path`: `ExportError::FolderNotWritable` where its folder
/// (one that exists) refused it — no permission, or a read-only file system (which said
/// "cannot write ro/.NAME.lock": the hostile-input review) — the file's otherwise.
fn folder_refused(path: &Path, source: std::io::Error) -> ExportError {
    use std::io::ErrorKind::{PermissionDenied, ReadOnlyFilesystem};
    let folder = folder_of(path);
    if matches!(source.kind(), PermissionDenied | ReadOnlyFilesystem) && folder.is_dir() {
        ExportError::FolderNotWritable { folder: folder.into(), name: file_name(path), source }
    } else {
        ExportError::Io { path: path.into(), source }
    }
}

/// SHA-256 of `bytes` as 64 hex digits (the manifest's `sha256` per map).
pub fn sha256_hex(bytes: &[u8]) -> String {
    hex(&Sha256::digest(bytes))
}

/// A digest as the manifest writes it: lowercase hex.
pub(crate) fn hex(digest: &[u8]) -> String {
    digest.iter().map(|b| format!("{b:02x}")).collect()
}

/// Every temporary of a name, whatever its age (under the set's lock).
const ZERO_AGE: std::time::Duration = std::time::Duration::ZERO;

/// Removes temporaries that a killed run left for `file_names` in `dir`
/// (`.FILE.*.snakeskin-tmp`) and that are at least `min_age` old.
fn remove_stale_temporaries(dir: &Path, file_names: &[&str], min_age: std::time::Duration) {
    let Ok(entries) = fs::read_dir(dir) else { return };
    for entry in entries.flatten() {
        let name = entry.file_name();
        let name = name.to_string_lossy();
        // Exactly `.FILE.` + tempfile's random part + the suffix.
        let ours = file_names.iter().any(|f| {
            let random = name
                .strip_prefix('.')
                .and_then(|r| r.strip_prefix(temporary_stem(f).as_ref()))
                .and_then(|r| r.strip_prefix('.'))
                .and_then(|r| r.strip_suffix(TMP_SUFFIX));
            random.is_some_and(|r| r.len() == RANDOM_CHARS && r.chars().all(|c| c.is_ascii_alphanumeric()))
        });
        let old_enough = || {
            min_age.is_zero()
                || entry
                    .metadata()
                    .and_then(|m| m.modified())
                    .is_ok_and(|t| t.elapsed().is_ok_and(|age| age >= min_age))
        };
        if ours && entry.file_type().is_ok_and(|t| t.is_file()) && old_enough() {
            let _ = fs::remove_file(entry.path());
        }
    }
}

/// Writes `bytes` to a new exclusive temporary beside `target` and returns it (deleted on
/// drop unless persisted).
fn stage(dir: &Path, target_name: &str, bytes: &[u8]) -> Result<tempfile::NamedTempFile, ExportError> {
    let mut tmp = listed_temporary(dir, target_name).map_err(io_error(dir))?;
    // Named as the file it will become (the temporary is hidden from the user), a full disk
    // said "cannot write /out/.x.png.JWK6WF.snakeskin-tmp: No space left on device (os
    // error 28) at path "/out/.x.png.JWK6WF.snakeskin-tmp"".
    // A file named without a folder is named so (`folder_of` reads it as in `.`: a full
    // disk said "cannot write ./s.png" of `-o s.png`: a sweep).
    let shown = if dir == Path::new(".") { PathBuf::from(target_name) } else { dir.join(target_name) };
    tmp.write_all(bytes)
        .and_then(|_| tmp.as_file().sync_all())
        .map_err(|e| io_error(&shown)(without_temporary_path(e)))?;
    Ok(tmp)
}

/// `temporary`, listed in `LIVE` for an interrupt's clean-up: created and listed under one
/// lock, so that once `clean_up_before_exit` has begun none is created that it would not
/// remove.
fn listed_temporary(dir: &Path, target_name: &str) -> std::io::Result<tempfile::NamedTempFile> {
    let mut live = locked(&LIVE);
    let tmp = temporary(dir, target_name)?;
    live.push(tmp.path().to_path_buf());
    Ok(tmp)
}

/// Whether a run holds the lock of set (or export) `name` in `dir` now (`SetLock`), one try:
/// what `verify` asks before it calls a set found only in temporaries interrupted (a set
/// being written was FAILED, a review found), and what `SetLock::acquire_waiting` polls. No
/// lock file, one nobody holds, or something there that does not open as a lock: false.
/// A shared lock's try, on a descriptor opened for reading (on NFS `flock` is a byte-range
/// lock: a shared one needs read access, an exclusive one write access, which a lock
/// another user made may refuse).
pub fn lock_is_held(dir: &Path, name: &str) -> bool {
    let Ok(file) = lock_open_options(false).open(dir.join(lock_file_name(name))) else { return false };
    matches!(file.try_lock_shared(), Err(fs::TryLockError::WouldBlock))
}

/// How a set's lock file is opened, by the acquire (`write`, creating it) and by a look at
/// whether it is held: not through a link, and without waiting (a plain open of a FIFO there
/// waited for the other end for ever: `verify` opened it plainly). Opened so, a FIFO fails
/// to open for writing (ENXIO), and opens for reading at once and reads as not held.
fn lock_open_options(write: bool) -> fs::OpenOptions {
    let mut options = fs::OpenOptions::new();
    match write {
        true => options.create(true).truncate(false).write(true),
        false => options.read(true),
    };
    #[cfg(unix)]
    std::os::unix::fs::OpenOptionsExt::custom_flags(&mut options, libc::O_NOFOLLOW | libc::O_NONBLOCK);
    options
}

/// The file name a temporary in a folder listing stands for (`.NAME.RANDOM.snakeskin-tmp`:
/// `NAME`), None for any other name; a name cut to fit (`temporary_stem`) comes back cut.
/// `verify` finds by it the sets a run left only in temporaries (killed while renaming).
pub fn temporary_target(file_name: &str) -> Option<&str> {
    let inner = file_name.strip_prefix('.')?.strip_suffix(TMP_SUFFIX)?;
    let (target, random) = inner.rsplit_once('.')?;
    (random.len() == RANDOM_CHARS && !target.is_empty()).then_some(target)
}

/// A new, empty temporary for `target_name` in `dir` (`.NAME.RANDOM.snakeskin-tmp`, created
/// exclusively): a map being staged, or the place an old file is moved aside to.
fn temporary(dir: &Path, target_name: &str) -> std::io::Result<tempfile::NamedTempFile> {
    let prefix = format!(".{}.", temporary_stem(target_name));
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix).suffix(TMP_SUFFIX).rand_bytes(RANDOM_CHARS);
    // tempfile creates 0600 files; outputs are ordinary files (0666 less the umask, as
    // `File::create` makes them), readable by whoever reads the user's other files. One that
    // replaces a file keeps that file's bits, as `sed -i` and editors keep them (a read-only
    // file too, which the run replaces by renaming, as they do; the owner is the run's): a
    // `chmod 600` map came back 0644 after the next run (a sweep). It is created with them,
    // so never more open than they are (set only after, a `chmod 600` map's replacement
    // could be opened by others first: a review), and then given them exactly (creation
    // takes the umask off).
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let kept = permission_bits(&dir.join(target_name));
        builder.permissions(fs::Permissions::from_mode(kept.unwrap_or(0o666)));
        let tmp = builder.tempfile_in(dir).map_err(without_temporary_path)?;
        if let Some(bits) = kept {
            // Where they cannot be set, the temporary keeps the ones it was made with.
            let _ = tmp.as_file().set_permissions(fs::Permissions::from_mode(bits));
        }
        Ok(tmp)
    }
    #[cfg(not(unix))]
    builder.tempfile_in(dir).map_err(without_temporary_path)
}

/// The permission bits of a plain file at `path` (not through a link), if there is one.
#[cfg(unix)]
fn permission_bits(path: &Path) -> Option<u32> {
    use std::os::unix::fs::PermissionsExt;
    let meta = fs::symlink_metadata(path).ok().filter(|m| m.is_file())?;
    Some(meta.permissions().mode() & 0o777)
}

/// tempfile's errors name the hidden temporary (`... at path "/out/.t.png.RZ4prK.
/// snakeskin-tmp"`), a file the user never sees; the caller names the folder or the target.
/// Its error type is private and exposes no source, so the OS's words are its message's part
/// before " at path " (tempfile 3's `PathError` display).
fn without_temporary_path(e: std::io::Error) -> std::io::Error {
    match e.to_string().split_once(" at path ") {
        Some((reason, _)) => std::io::Error::new(e.kind(), reason.to_string()),
        None => e,
    }
}

/// Refuses a target that is a folder (a rename over it would fail half-way through a set),
/// and one that is anything else but a regular file: the rename would replace a symbolic
/// link, a device (`brdf chart --out /dev/full` run as root made `/dev/full` a PNG), a FIFO
/// or a socket with the output, where the user meant to write through it
/// (`ExportError::NotAFile`).
/// Public so that a command can check an output file before the work that makes it.
pub fn check_target(target: &Path) -> Result<(), ExportError> {
    if target.as_os_str() == "-" {
        return Err(ExportError::Stdout);
    }
    refuse_unlistable(target)?;
    if ends_as_a_folder(target) {
        return Err(ExportError::folder_name(target, &super::OUTPUT_EXTENSIONS));
    }
    if let Some(folder) = target.parent() {
        check_name_lengths(folder)?;
    }
    let name_bytes = target.file_name().map_or(0, |n| n.len());
    if name_bytes > NAME_MAX_BYTES {
        return Err(ExportError::NameTooLong { path: target.into(), bytes: name_bytes, limit: NAME_MAX_BYTES });
    }
    let Ok(meta) = fs::symlink_metadata(target) else {
        return Ok(());
    };
    let file_type = meta.file_type();
    if file_type.is_dir() {
        return Err(ExportError::FolderInTheWay { path: target.into() });
    }
    if file_type.is_file() {
        return Ok(());
    }
    Err(ExportError::NotAFile { path: target.into(), kind: crate::text_file::file_kind(&file_type) })
}

/// Refuses an output path that a list of the files written cannot show as it is: a
/// control character anywhere in it (a newline printed a listed file as `nl\nout/…`, a path
/// that does not exist; the preset names the files are named after are refused alike:
/// `PresetError::FileName`), or bytes that are not UTF-8 (listed with U+FFFD in their place).
fn refuse_unlistable(path: &Path) -> Result<(), ExportError> {
    match path.to_str() {
        Some(text) if !text.chars().any(char::is_control) => Ok(()),
        _ => Err(ExportError::NotListable { path: path.into() }),
    }
}

/// `check_target` for an output written in one format, `format` its extension (`png` for a
/// render, a sheet, a gallery, a chart; `svg` for a plot): a name with another extension
/// (`.jpg`, `.exr`) is refused (it was written in `format` under that name, without a
/// word), and so is the extension alone (`.png`, a hidden file); one without an extension is
/// taken as it is, but replaces only a file of `format` (an earlier run's output), not a
/// file of another kind that stands there (a text file named `notes`).
pub fn check_target_named(target: &Path, format: &'static str) -> Result<(), ExportError> {
    // Its example named with the format asked for (`chart.v2/` said "as in out/snake.v2").
    if ends_as_a_folder(target) {
        return Err(ExportError::folder_name(target, &[format]));
    }
    check_target(target)?;
    // `.png`, and another image format's extension alone (`.jpg`: no extension to compare,
    // so it was written as a hidden PNG).
    const IMAGE_EXTENSIONS: [&str; 11] =
        ["png", "jpg", "jpeg", "exr", "webp", "tif", "tiff", "svg", "gif", "bmp", "tga"];
    let name = target.file_name().map(|n| n.to_string_lossy());
    let only_an_extension = |rest: &str| rest == format || IMAGE_EXTENSIONS.contains(&rest);
    if name.is_some_and(|n| n.strip_prefix('.').is_some_and(|rest| only_an_extension(&rest.to_ascii_lowercase()))) {
        return Err(ExportError::OnlyAnExtension { path: target.into(), format });
    }
    match target.extension().map(|e| e.to_string_lossy()) {
        Some(extension) if !extension.eq_ignore_ascii_case(format) => {
            Err(ExportError::NamedForAnotherFormat { path: target.into(), format, extension: extension.into_owned() })
        }
        None if fs::metadata(target).is_ok_and(|m| m.is_file()) && !holds_format(target, format) => {
            Err(ExportError::WouldReplaceAnotherKind { path: target.into(), format })
        }
        _ => Ok(()),
    }
}

/// Whether the file at `path` begins as a file of `format` does (`png`: its 8-byte
/// signature, PNG spec §5.2; `svg`: `<svg` after any white space, or an XML declaration
/// with an `<svg` element within its first KiB: any other XML file, a settings file, is not
/// an SVG, as an independent review found it taken for one; `batch index`: a JSON object
/// with snakeskin's `generator` first). An empty file counts as any
/// format's (nothing is lost replacing it).
fn holds_format(path: &Path, format: &str) -> bool {
    use std::io::Read;
    let mut head = Vec::with_capacity(1024);
    let Ok(file) = fs::File::open(path) else { return false };
    if file.take(1024).read_to_end(&mut head).is_err() {
        return false;
    }
    begins_as(&head, format)
}

/// `holds_format` for a file's first bytes (its first KiB is enough; `batch` reads an index
/// whole and asks of it as of a file).
pub fn begins_as(head: &[u8], format: &str) -> bool {
    if head.is_empty() {
        return true;
    }
    match format {
        "png" => head.starts_with(b"\x89PNG\r\n\x1a\n"),
        // A batch's index: a JSON object whose first key is `generator`, snakeskin's
        // (`batch::BatchIndex`).
        "batch index" => {
            // Token by token, white space and a UTF-8 byte-order mark passed over: a re-saved
            // index (`"generator":"snakeskin"`, compact) is one still (a review).
            let mut rest = head.strip_prefix(b"\xef\xbb\xbf").unwrap_or(head);
            ["{", "\"generator\"", ":", "\"snakeskin\""].iter().all(|token| {
                rest = rest.trim_ascii_start();
                let found = rest.starts_with(token.as_bytes());
                rest = &rest[token.len().min(rest.len())..];
                found
            })
        }
        "svg" => {
            let text = head.trim_ascii_start();
            text.starts_with(b"<svg") || (text.starts_with(b"<?xml") && text.windows(4).any(|w| w == b"<svg"))
        }
        _ => false,
    }
}

/// For a file the tool names itself in a folder the user gave (a batch's index, a gallery's
/// close-ups, the figures), after `check_target` and the check against the command's inputs
/// (whose messages say more): `format` what it holds; a file of that name is replaced only
/// where it holds `format` (or is empty), as an output named without an extension is. A web
/// page named `index.json` in a batch's folder, a text file named `rows.png` among the
/// close-ups were replaced without a word (a hostile-input sweep).
pub fn check_replaces_its_own(target: &Path, format: &'static str) -> Result<(), ExportError> {
    if fs::metadata(target).is_ok_and(|m| m.is_file()) && !holds_format(target, format) {
        return Err(ExportError::NotOurs { path: target.into(), format });
    }
    Ok(())
}

/// `check_target_named` for a PNG image.
pub fn check_png_target(target: &Path) -> Result<(), ExportError> {
    check_target_named(target, "png")
}

/// Whether a path's text ends as only a folder's can: in a separator, `.` or `..` (or is
/// empty). `Path` drops a trailing separator and `.` (`out/` and `out/.` have the file name
/// `out`), so this reads the text.
pub fn ends_as_a_folder(path: &Path) -> bool {
    let text = path.as_os_str().as_encoded_bytes();
    let last = text.rsplit(|&b| std::path::is_separator(b as char)).next().unwrap_or(b"");
    matches!(last, b"" | b"." | b"..")
}

/// Whether two output paths name one file: through links and `..` (the longest existing
/// part of each resolved, the rest read lexically), so `sub/../a.png` is `a.png` whether or
/// not `sub` exists. A path that cannot be made absolute names no file here. (Comparing
/// `std::path::absolute`s missed `..` and links: a heat map replaced the render.)
pub fn same_path(a: &Path, b: &Path) -> bool {
    matches!((resolved(a), resolved(b)), (Some(a), Some(b)) if a == b)
}

/// Whether `path` lies inside `outer` (below it, not `outer` itself), by `same_path`'s rule:
/// one output inside another that is a file (`gallery -o g.png --closeups g.png/sub`) made
/// the file's path a folder, ran the whole work, and failed with "a folder is in the way of
/// this output file" (a sweep).
pub fn lies_under(path: &Path, outer: &Path) -> bool {
    matches!((resolved(path), resolved(outer)), (Some(p), Some(o)) if p != o && p.starts_with(&o))
}

/// Refuses a lock path (`lock_file_name` in its folder) that names one of `inputs`
/// (`ExportError::InputAtLock`): `generate ./.preset.lock` took its own (empty) preset as its
/// lock and removed it.
pub fn check_lock_not_an_input(lock: &Path, inputs: &Inputs) -> Result<(), ExportError> {
    inputs.check(lock).map_err(|e| match e {
        ExportError::OverwritesInput { input, .. } => ExportError::InputAtLock { input },
        other => other,
    })
}

/// Refuses an output that names the command's input file (`same_path`, links and `..`
/// resolved): `preview snake -o snake`, `export ./x.glb --gltf x.glb` and a batch whose jobs
/// file is its index replaced their input, and could not be run again.
pub fn check_not_an_input(output: &Path, input: Option<&Path>) -> Result<(), ExportError> {
    Inputs::new(input).check(output)
}

/// A command's input files, each resolved once (`same_path`'s rule), for refusing the
/// outputs that would be written over one of them: a batch checks every job's files against
/// its jobs file and every job's preset file (a job's preset saved as `DIR/index.json` was
/// replaced by the batch's index), and resolving both paths per file and input made a
/// table of 100,000 jobs pay for it on every one.
/// Each input by its resolved path, the path as given beside it: a check is one lookup (a
/// scan over 2,000 jobs' preset files made `batch --list` of 20,000 jobs take 16 s).
#[derive(Debug, Default)]
pub struct Inputs(std::collections::HashMap<PathBuf, PathBuf>);

impl Inputs {
    /// `paths` as given (the error names them so) and resolved; one entry per file, the first
    /// spelling of it.
    pub fn new<'a>(paths: impl IntoIterator<Item = &'a Path>) -> Inputs {
        let mut inputs = std::collections::HashMap::new();
        for path in paths {
            if let Some(real) = resolved(path) {
                inputs.entry(real).or_insert_with(|| path.to_path_buf());
            }
        }
        Inputs(inputs)
    }

    /// Refuses `output` where it names one of the inputs (`ExportError::OverwritesInput`).
    pub fn check(&self, output: &Path) -> Result<(), ExportError> {
        if self.0.is_empty() {
            return Ok(());
        }
        match resolved(output).and_then(|out| self.0.get(&out)) {
            Some(input) => Err(ExportError::OverwritesInput { output: output.into(), input: input.clone() }),
            None => Ok(()),
        }
    }
}

fn resolved(path: &Path) -> Option<PathBuf> {
    let absolute = std::path::absolute(path).ok()?;
    let existing = absolute.ancestors().find(|p| p.exists())?;
    let mut out = existing.canonicalize().ok()?;
    for part in absolute.strip_prefix(existing).ok()?.components() {
        match part {
            std::path::Component::ParentDir => {
                out.pop();
            }
            std::path::Component::CurDir => {}
            other => out.push(other),
        }
    }
    Some(out)
}

/// The folders this process made for its outputs (`create_folder_noted`): the output folders
/// and their missing parents, for `remove_empty_made_folders`. One list for the process,
/// since a batch's jobs may share a parent that one of them made.
static MADE_FOLDERS: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// `create_folder`, noting each folder it made so that a run that fails can take them away
/// again (`remove_empty_made_folders`): the parts of the path below its deepest existing
/// folder, up to the first `..` or `.` (a `..` out of a missing folder is refused before,
/// by `check_folder`).
pub fn create_folder_noted(dir: &Path) -> Result<bool, ExportError> {
    // Held while the folder is made: once `clean_up_before_exit` holds it, none is.
    let mut made = locked(&MADE_FOLDERS);
    let existing = dir.ancestors().find(|p| p.as_os_str().is_empty() || fs::symlink_metadata(p).is_ok());
    let mut missing = Vec::new();
    if let Some(existing) = existing
        && let Ok(below) = dir.strip_prefix(existing)
    {
        let mut folder = existing.to_path_buf();
        for part in below.components() {
            let std::path::Component::Normal(name) = part else { break };
            folder.push(name);
            missing.push(folder.clone());
        }
    }
    let created = create_folder(dir)?;
    if created {
        made.extend(missing);
    }
    Ok(created)
}

/// Removes every folder `create_folder_noted` made that is empty now, deepest first, so a
/// run that failed before its commit leaves no empty folders behind (its lock's drop calls
/// this, and so does `main` for a run that failed). `remove_dir` removes only an empty folder: a
/// set's folder, or one another job is writing into (its lock file is there), stays.
pub fn remove_empty_made_folders() {
    remove_empty(&mut locked(&MADE_FOLDERS));
}

/// `remove_empty_made_folders` on the list it holds.
fn remove_empty(made: &mut Vec<PathBuf>) {
    made.sort_by_key(|folder| std::cmp::Reverse(folder.components().count()));
    made.retain(|folder| fs::remove_dir(folder).is_err());
}

/// Creates an output folder if needed (true when it was created); a path that exists and is
/// not a folder is `ExportError::NotAFolder`. Every output path goes through here.
pub fn create_folder(dir: &Path) -> Result<bool, ExportError> {
    check_folder(dir)?;
    if dir.is_dir() {
        return Ok(false);
    }
    // Without its `.` components: std's `create_dir_all("x/.")` failed with "No such file or
    // directory" for a missing `x`, where `mkdir -p x/.` succeeds (a hostile-input sweep).
    let without_dots: PathBuf = dir.components().filter(|c| *c != std::path::Component::CurDir).collect();
    let dir = if without_dots.as_os_str().is_empty() { Path::new(".") } else { without_dots.as_path() };
    fs::create_dir_all(dir)
        .map(|_| true)
        .map_err(|source| ExportError::CreateFolder { path: first_missing_folder(dir).into(), source })
}

/// The first folder of `dir` that is missing (the one a failed `create_dir_all` could not
/// make, in one that exists); `dir` itself when none is.
fn first_missing_folder(dir: &Path) -> &Path {
    let missing = dir.ancestors().take_while(|p| !p.as_os_str().is_empty() && fs::symlink_metadata(p).is_err());
    missing.last().unwrap_or(dir)
}

/// An output folder's path, checked without creating anything: a path that exists and is
/// not a folder is `ExportError::NotAFolder`, and so is a missing folder under a file
/// (`-o a-file/sub` names `a-file`); a link to nothing on the way is
/// `ExportError::BrokenLink` (creating the folder would fail with "File exists"); a `..` out
/// of a missing folder is `ExportError::ThroughMissingFolder`; a missing one under folders
/// is fine.
pub fn check_folder(dir: &Path) -> Result<(), ExportError> {
    refuse_unlistable(dir)?;
    check_name_lengths(dir)?;
    check_no_way_up_from_missing(dir)?;
    for path in dir.ancestors().filter(|p| !p.as_os_str().is_empty()) {
        match fs::metadata(path) {
            Ok(meta) if meta.is_dir() => return Ok(()),
            Ok(_) => return Err(ExportError::NotAFolder { path: path.into() }),
            Err(e) if e.kind() == std::io::ErrorKind::PermissionDenied => continue,
            // Missing when followed: a link to nothing, or missing until a moment ago (a
            // folder another job of a batch made meanwhile was "a symbolic link to
            // nothing"), or missing still.
            Err(_) => match fs::symlink_metadata(path) {
                Ok(meta) if meta.file_type().is_symlink() => {
                    return Err(ExportError::BrokenLink { path: path.into() });
                }
                Ok(meta) if meta.is_dir() => return Ok(()),
                Ok(_) => return Err(ExportError::NotAFolder { path: path.into() }),
                Err(_) => continue,
            },
        }
    }
    Ok(())
}

/// Refuses a `..` that follows a folder that does not exist (`ExportError::ThroughMissingFolder`),
/// naming that folder. Before a `..`, the path up to it must be there: the system resolves
/// `a/..` only where `a` is.
fn check_no_way_up_from_missing(dir: &Path) -> Result<(), ExportError> {
    let mut before = PathBuf::new();
    for component in dir.components() {
        if component == std::path::Component::ParentDir
            && !before.as_os_str().is_empty()
            && fs::symlink_metadata(&before).is_err_and(|e| e.kind() == std::io::ErrorKind::NotFound)
        {
            let missing = first_missing_folder(&before).to_path_buf();
            return Err(ExportError::ThroughMissingFolder { path: dir.into(), missing });
        }
        before.push(component);
    }
    Ok(())
}

/// The longest path Linux takes in one call (`PATH_MAX`, 4096 with its closing NUL).
const PATH_MAX_BYTES: usize = 4095;

/// The longest folder path an output goes in: `PATH_MAX_BYTES` less a separator and a file
/// name of up to `NAME_MAX_BYTES`, which the lock and the temporaries can reach (they are cut
/// to it). A folder within 4095 bytes, but not with its files' names, was made and then
/// failed at its lock, "File name too long", exit 1 (the review).
const FOLDER_PATH_MAX_BYTES: usize = PATH_MAX_BYTES - 1 - NAME_MAX_BYTES;

/// Refuses a folder path no file system takes: a folder's name over `NAME_MAX_BYTES`, or the
/// whole path over `FOLDER_PATH_MAX_BYTES` (both failed as the folder was made, exit 1, the
/// second naming the first folder made: a sweep).
fn check_name_lengths(dir: &Path) -> Result<(), ExportError> {
    let bytes = dir.as_os_str().len();
    if bytes > FOLDER_PATH_MAX_BYTES {
        let path = dir.to_string_lossy().into_owned();
        return Err(ExportError::PathTooLong { path, bytes, limit: FOLDER_PATH_MAX_BYTES });
    }
    let mut folder = PathBuf::new();
    for component in dir.components() {
        folder.push(component);
        if let std::path::Component::Normal(name) = component
            && name.len() > NAME_MAX_BYTES
        {
            return Err(ExportError::FolderNameTooLong { folder, bytes: name.len(), limit: NAME_MAX_BYTES });
        }
    }
    Ok(())
}

/// How often, and how long apart, `SetLock::acquire` tries a lock another process holds
/// before it calls the set busy: a second in all.
const BUSY_RETRIES: usize = 20;
const BUSY_RETRY_WAIT: std::time::Duration = std::time::Duration::from_millis(50);

/// How often `SetLock::acquire_waiting` looks whether another run has let go of the lock: a
/// set takes 0.1 s (256) to seconds (4K), so a quarter second adds little to a wait and
/// costs nothing while it lasts.
const LOCK_WAIT_POLL: std::time::Duration = std::time::Duration::from_millis(250);

/// An exclusive lock on one output set (`DIR/.NAME.lock`), held until dropped.
#[derive(Debug)]
pub struct SetLock {
    dir: PathBuf,
    path: PathBuf,
    /// The locked file; the lock goes with it.
    _file: File,
    /// Whether acquiring created the output folder.
    pub created_folder: bool,
    /// The earlier set's files a commit removed (`left_over_files`), for the caller to say.
    removed: Mutex<Vec<PathBuf>>,
    /// The files of the set's names that the new set does not write and that stayed, with
    /// why: for the caller to warn of (they lie beside the new set under no manifest).
    kept: Mutex<Vec<KeptFile>>,
}

/// A file of the set's names (an earlier set's, or one no readable manifest claims) that stays
/// beside the new set although the new set does not write it (`SetLock::kept`); or an
/// export's image its new `.gltf` does not reference (`gltf_export`).
#[derive(Debug, Clone, PartialEq)]
pub struct KeptFile {
    pub path: PathBuf,
    pub why: KeptBecause,
    /// What would have written it: the earlier set or export.
    pub by: Earlier,
}

/// What writes the files a run may find of an earlier run: a texture set (its manifest
/// records its maps) or a glTF export (its `.gltf` names its images).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Earlier {
    Set,
    Export,
}

impl Earlier {
    pub fn word(self) -> &'static str {
        match self {
            Earlier::Set => "set",
            Earlier::Export => "export",
        }
    }
}

impl KeptFile {
    /// Why it stayed, for a warning that names the file (escaped as the caller prints paths).
    pub fn reason(&self) -> String {
        self.why.words(self.by)
    }
}

#[derive(Debug, Clone, PartialEq)]
pub enum KeptBecause {
    /// Its bytes are no longer what the earlier manifest recorded (edited by hand: no longer
    /// the set's to remove).
    ChangedSince,
    /// It could not be read to compare with the record: the error.
    Unreadable(String),
    /// It would not move aside (immutable, or its folder refuses): the error.
    WouldNotMove(String),
    /// Not a regular file where the record names one (a link, a device).
    NotAFile,
    /// No record (the manifest, the `.gltf`: its file name) was there to say whose it is.
    NoRecord(String),
    /// The record there could not be used to say whose it is: what it is ("manifest", the
    /// `.gltf`'s file name) and the error.
    RecordUnreadable { record: String, error: String },
    /// The record there ("manifest", the `.gltf`'s file name) does not name it.
    NotRecorded { record: String },
}

impl KeptBecause {
    /// Why a file stayed, the earlier run `by` named: one sentence for sets and exports.
    pub fn words(&self, by: Earlier) -> String {
        let by = by.word();
        match self {
            KeptBecause::ChangedSince => {
                format!("it changed since the earlier {by} wrote it, so it is not that {by}'s to remove")
            }
            KeptBecause::Unreadable(error) => {
                format!("it could not be read to compare with the earlier {by}'s record ({error})")
            }
            KeptBecause::WouldNotMove(error) => format!("it is the earlier {by}'s and could not be removed ({error})"),
            KeptBecause::NotAFile => format!("it is not a regular file, so it is not the earlier {by}'s to remove"),
            KeptBecause::NoRecord(record) => format!("no {record} is there to say it is an earlier {by}'s to remove"),
            KeptBecause::RecordUnreadable { record, error } => format!(
                "the {record} there could not be used ({error}), so nothing says it is the earlier {by}'s to remove"
            ),
            KeptBecause::NotRecorded { record } => {
                format!("the {record} there does not record it, so it is not the earlier {by}'s to remove")
            }
        }
    }
}

/// Refuses what is at a set's lock path unless it is nothing or an empty regular file
/// (snakeskin's locks are empty): `SetLock::acquire` as it opens the lock, and a batch for
/// every job before any runs (a FIFO at a later job's lock stopped the run after the earlier
/// jobs' sets were written, and `--list` said "to do").
pub fn check_lock_place(path: &Path) -> Result<(), ExportError> {
    let Ok(meta) = fs::symlink_metadata(path) else {
        return Ok(());
    };
    let file_type = meta.file_type();
    match file_type.is_file() {
        true if meta.len() > 0 => Err(ExportError::LockHoldsData { path: path.into(), bytes: meta.len() }),
        true => Ok(()),
        false => Err(ExportError::LockNotAFile { path: path.into(), kind: crate::text_file::file_kind(&file_type) }),
    }
}

impl SetLock {
    /// Locks the set `name` in `dir`, creating the folder if it is missing.
    pub fn acquire(dir: &Path, name: &str) -> Result<SetLock, ExportError> {
        // Held from the lock file's making to its listing: once `clean_up_before_exit` holds
        // it, no lock file is made that it would not remove.
        let mut held = locked(&HELD_LOCKS);
        let created_folder = create_folder_noted(dir)?;
        let path = dir.join(lock_file_name(name));
        let options = lock_open_options(true);
        // The lock file is the run's to make, empty: anything else there is named as such,
        // before the open and again if the open fails or opens it.
        let not_a_lock = || check_lock_place(&path).err();
        if let Some(refused) = not_a_lock() {
            return Err(refused);
        }
        // A run that ends removes the lock file; if that happened between our open and our
        // lock, we hold a lock on a file nobody else will open: open again.
        let mut folder_went = None;
        for _ in 0..8 {
            let file = match options.open(&path) {
                Ok(file) => file,
                // A failed job of this batch removed the empty folder between our making it
                // and opening the lock (`remove_empty_made_folders`): make it again.
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                    folder_went = Some(e);
                    match create_folder_noted(dir) {
                        Err(ExportError::CreateFolder { source, .. } | ExportError::Io { source, .. })
                            if source.kind() == std::io::ErrorKind::NotFound => {}
                        other => drop(other?),
                    }
                    continue;
                }
                Err(e) => return Err(not_a_lock().unwrap_or_else(|| io_error(&path)(e))),
            };
            // The file opened, by its own metadata (the path may have changed since).
            match file.metadata() {
                Ok(m) if m.is_file() && m.len() > 0 => {
                    return Err(ExportError::LockHoldsData { path: path.clone(), bytes: m.len() });
                }
                Ok(m) if m.is_file() => {}
                _ => {
                    return Err(not_a_lock()
                        .unwrap_or_else(|| ExportError::LockNotAFile { path: path.clone(), kind: "something else" }));
                }
            }
            // A run killed a moment ago holds its lock until the kernel has torn it down
            // (0.3 s after a 4K run's SIGKILL, an independent review measured: a run started
            // at once was told another run was writing); a lock held a second on is a run's.
            // The table is let go of while it waits: another process holds this lock file, so
            // it is not this run's to remove, and the other sets' acquires, their drops and
            // the exit's clean-up go on (held through the second, every busy set stopped the
            // batch's other jobs for it: the review). A clean-up that takes the table meanwhile
            // keeps it until the process exits.
            let mut attempt = file.try_lock();
            for _ in 0..BUSY_RETRIES {
                if !matches!(attempt, Err(fs::TryLockError::WouldBlock)) {
                    break;
                }
                drop(held);
                std::thread::sleep(BUSY_RETRY_WAIT);
                held = locked(&HELD_LOCKS);
                attempt = file.try_lock();
            }
            match attempt {
                Ok(()) if same_file(&file, &path) => {
                    // Under the lock every temporary of the set's names is stale: a run killed
                    // while it committed left the earlier set's files it moved aside, of names
                    // the next run may not write (`--maps color` after a full set), and a
                    // killed `.gltf` export's, which a `.glb` export does not write.
                    let names = super::every_file_name_under_lock(name);
                    remove_stale_temporaries(dir, &names.iter().map(String::as_str).collect::<Vec<_>>(), ZERO_AGE);
                    held.push(path.clone());
                    return Ok(SetLock {
                        dir: dir.into(),
                        path,
                        _file: file,
                        created_folder,
                        removed: Mutex::new(Vec::new()),
                        kept: Mutex::new(Vec::new()),
                    });
                }
                Ok(()) => continue,
                Err(fs::TryLockError::WouldBlock) => {
                    return Err(ExportError::Busy { dir: dir.into(), name: name.into() });
                }
                Err(fs::TryLockError::Error(source)) => return Err(ExportError::Io { path, source }),
            }
        }
        // Eight tries, each lost to a run that ended or to a folder that went: say which. A
        // folder that is there still takes no new files (`-o /proc/self` said "cannot write
        // /proc/self/.NAME.lock: No such file or directory"): the folder is to change.
        Err(match folder_went {
            Some(source) if dir.is_dir() => {
                ExportError::FolderNotWritable { folder: dir.into(), name: file_name(&path), source }
            }
            Some(source) => ExportError::Io { path, source },
            None => ExportError::Busy { dir: dir.into(), name: name.into() },
        })
    }

    /// `acquire`, waiting for a set another run is writing rather than calling it busy: a
    /// batch's job (of two batches over the same sets, the second stopped at its first busy
    /// set and made none). `waiting` is called once, as the wait begins; `give_up` at every
    /// look, and where it says so the wait ends in `ExportError::Busy`. The wait holds no
    /// lock and not the process's table of held locks: it looks whether the lock is held
    /// (`lock_is_held`) every `LOCK_WAIT_POLL`, and takes it with `acquire` once free (taken
    /// again with the second of tries each time, the jobs beside it waited on the table: a
    /// review measured 3.8–6.3 s for 1.3 s). It sleeps before each look: a lock held shared
    /// (a `verify`'s look) reads as free, and the acquire that then found it busy was tried
    /// again at once, its twenty tries a second for as long as the lock was held (a review).
    pub fn acquire_waiting(
        dir: &Path,
        name: &str,
        waiting: &mut dyn FnMut(),
        give_up: &dyn Fn() -> bool,
    ) -> Result<SetLock, ExportError> {
        let mut said = false;
        loop {
            let busy = match SetLock::acquire(dir, name) {
                Err(busy @ ExportError::Busy { .. }) => busy,
                other => return other,
            };
            if give_up() {
                return Err(busy);
            }
            if !said {
                waiting();
                said = true;
            }
            loop {
                std::thread::sleep(LOCK_WAIT_POLL);
                if give_up() {
                    return Err(busy);
                }
                if !lock_is_held(dir, name) {
                    break;
                }
            }
        }
    }

    /// Whether this is the lock of set `name` in `dir`.
    pub fn is_for(&self, dir: &Path, name: &str) -> bool {
        self.dir == dir && self.path == dir.join(lock_file_name(name))
    }

    /// Writes the set: `maps` (file name, bytes) first, then `manifest` (file name, bytes)
    /// as the commit record. See the module documentation for the guarantee.
    pub fn write(&self, maps: &[(String, Vec<u8>)], manifest: (&str, &[u8])) -> Result<Vec<PathBuf>, ExportError> {
        let staged = maps.iter().map(|(name, bytes)| self.stage(name, bytes)).collect::<Result<Vec<_>, _>>()?;
        self.commit(staged, manifest)
    }

    /// The earlier set's files that commits removed because the new set does not write them
    /// (`--maps color` after a full set).
    pub fn removed(&self) -> Vec<PathBuf> {
        self.removed.lock().unwrap_or_else(|e| e.into_inner()).clone()
    }

    /// The files of the set's names that commits left in place although the new set does not
    /// write them (changed since, would not move, or recorded by no readable manifest), with
    /// why.
    pub fn kept(&self) -> Vec<KeptFile> {
        self.kept.lock().unwrap_or_else(|e| e.into_inner()).clone()
    }

    /// Writes one map of the set to its temporary now (step 2), so its bytes need not be
    /// held until the whole set is done: at 4096² the compressed maps of a set are up to
    /// 90 MB. Nothing is visible until `commit`; a dropped `Staged` deletes its temporary.
    /// May run on several threads at once, one file name each; each name once per set (the
    /// removal of stale temporaries before it takes every temporary of that name).
    pub fn stage(&self, name: &str, bytes: &[u8]) -> Result<Staged, ExportError> {
        // Under the lock no other run can be writing this set: every temporary of it is stale.
        remove_stale_temporaries(&self.dir, &[name], ZERO_AGE);
        Ok(Staged { file: stage(&self.dir, name, bytes)?, name: name.into(), sha256: sha256_hex(bytes) })
    }

    /// Commits staged maps with `manifest` (file name, bytes) as the commit record (steps 3
    /// and 4). See the module documentation for the guarantee.
    pub fn commit(&self, maps: Vec<Staged>, manifest: (&str, &[u8])) -> Result<Vec<PathBuf>, ExportError> {
        let dir = &self.dir;
        let manifest_target = dir.join(manifest.0);
        let mut staged: Vec<(tempfile::NamedTempFile, PathBuf)> =
            maps.into_iter().map(|m| (m.file, dir.join(&m.name))).collect();
        staged.push((self.stage(manifest.0, manifest.1)?.file, manifest_target.clone()));
        for (_, target) in &staged {
            check_target(target)?;
        }
        pause_hook(|| "commit".into());
        let targets: Vec<&PathBuf> = staged.iter().map(|(_, t)| t).collect();
        let (left_over, changed) = left_over_files(&manifest_target, &targets);
        // The old manifest first (so that from here on no old manifest names a map that may
        // change), then the old maps, then the earlier set's files the new one does not write.
        let old_first: Vec<PathBuf> = std::iter::once(&manifest_target)
            .chain(targets.iter().copied().filter(|t| **t != manifest_target))
            .chain(&left_over)
            .cloned()
            .collect();
        let Swapped { written, removed, stayed } = swap_in(staged, &old_first, &left_over, Some(&manifest_target))?;
        self.removed.lock().unwrap_or_else(|e| e.into_inner()).extend(removed);
        self.kept.lock().unwrap_or_else(|e| e.into_inner()).extend(changed.into_iter().chain(stayed));
        Ok(written)
    }
}

/// Step 4 of a commit, for a set and for a `FileGroup`: under the commit lock (an interrupt
/// waits for it), moves the existing files of `old` aside, in that order, then renames each
/// staged file into place, in its order; then removes what it moved aside. A rename that
/// fails undoes what was done (`put_back`): the new files go, the old ones return. Files of
/// `may_stay` that will not move aside are left where they are (their place is not needed);
/// `manifest` is the commit record that goes back only over its own files.
fn swap_in(
    staged: Vec<(tempfile::NamedTempFile, PathBuf)>,
    old: &[PathBuf],
    may_stay: &[PathBuf],
    manifest: Option<&Path>,
) -> Result<Swapped, ExportError> {
    let _commit = locked(&COMMIT);
    let _committing = Committing::start();
    let mut renames = 0;
    // One file over (at most) its own old one: a single rename replaces it atomically, and
    // one that fails leaves it. Moved aside first, a reader found no file in between, and a
    // kill there left the old one only in a temporary, which the next run removed.
    if let [(_, target)] = staged.as_slice()
        && old.iter().all(|o| o == target)
        && may_stay.is_empty()
    {
        let target = target.clone();
        let (tmp, _) = staged.into_iter().next().expect("one staged file");
        let temporary = tmp.path().to_path_buf();
        before_rename(&mut renames)
            .and_then(|()| tmp.persist(&target).map(drop).map_err(|e| e.error))
            .map_err(io_error(&target))?;
        forget_temporary(&temporary);
        sync_folder(folder_of(&target));
        return Ok(Swapped { written: vec![target], removed: Vec::new(), stayed: Vec::new() });
    }
    let mut aside: Vec<(tempfile::TempPath, PathBuf)> = Vec::new();
    let mut stayed = Vec::new();
    for target in old {
        if fs::symlink_metadata(target).is_err() {
            continue;
        }
        let dir = folder_of(target);
        let moved = temporary(dir, &file_name(target)).map_err(io_error(dir)).and_then(|backup| {
            let backup = backup.into_temp_path();
            forget_temporary(&backup);
            before_rename(&mut renames).and_then(|()| fs::rename(target, &backup)).map_err(io_error(target))?;
            Ok(backup)
        });
        match moved {
            Ok(backup) => aside.push((backup, target.clone())),
            // An earlier set's map that the new set does not write stays if it will not move
            // (`left_over_files`): the new set does not need its place.
            Err(e) if may_stay.contains(target) => {
                let error = match e {
                    ExportError::Io { source, .. } => source.to_string(),
                    other => other.to_string(),
                };
                stayed.push(KeptFile { path: target.clone(), why: KeptBecause::WouldNotMove(error), by: Earlier::Set });
            }
            Err(e) => return Err(not_put_back(e, put_back(aside, &[], manifest, &mut renames))),
        }
    }
    let mut written = Vec::new();
    for (tmp, target) in staged {
        let temporary = tmp.path().to_path_buf();
        if let Err(e) = before_rename(&mut renames).and_then(|()| tmp.persist(&target).map(drop).map_err(|e| e.error)) {
            let kept = put_back(aside, &written, manifest, &mut renames);
            return Err(not_put_back(ExportError::Io { path: target, source: e }, kept));
        }
        forget_temporary(&temporary);
        written.push(target);
    }
    let mut folders: Vec<&Path> = written.iter().map(|t| folder_of(t)).collect();
    folders.dedup();
    for dir in folders {
        sync_folder(dir);
    }
    // The old files go (each `TempPath` removes its file when dropped).
    let removed: Vec<PathBuf> =
        aside.iter().map(|(_, target)| target.clone()).filter(|t| may_stay.contains(t)).collect();
    drop(aside);
    Ok(Swapped { written, removed, stayed })
}

/// What a commit did (`swap_in`): the files written, the files of `may_stay` removed, and
/// those of `may_stay` that stayed (with the error).
struct Swapped {
    written: Vec<PathBuf>,
    removed: Vec<PathBuf>,
    stayed: Vec<KeptFile>,
}

/// The folder a file is in (`.` for a bare file name).
pub fn folder_of(path: &Path) -> &Path {
    path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."))
}

/// Files that appear together or not at all, without a manifest: the documentation figures,
/// a gallery and its close-ups, a preview and its heat map. Each is staged when its bytes
/// exist (`stage`: the folder is made, the target checked, the bytes kept), so nothing is
/// visible while the work goes on and an interrupt leaves the earlier files as they were;
/// `commit` writes them to temporaries and puts them all in place at once (`swap_in`: the
/// old ones aside first, all back if a rename fails). Unlike a set there is no lock: two
/// runs on one folder each write a whole group, the last one's stays.
///
/// The bytes wait in memory, not in temporaries: without a lock, another run takes a
/// temporary older than ten minutes for a killed run's (`remove_stale_temporaries`), and a
/// `preview --reference` staged its frame, then spent longer than that on the reference:
/// another preview to the same name removed the temporary, and the first failed at its end
/// with its work lost (a hostile-input sweep). A group's files are a few images.
#[derive(Debug, Default)]
pub struct FileGroup {
    staged: Vec<(Vec<u8>, PathBuf)>,
}

impl FileGroup {
    pub fn new() -> FileGroup {
        FileGroup::default()
    }

    /// Keeps `bytes` for `target` (creating its folder if needed, and checking the target).
    pub fn stage(&mut self, target: &Path, bytes: Vec<u8>) -> Result<(), ExportError> {
        let (dir, name) = (folder_of(target), file_name(target));
        if name.is_empty() || ends_as_a_folder(target) {
            return Err(ExportError::folder_name(target, &super::OUTPUT_EXTENSIONS));
        }
        create_folder(dir)?;
        check_target(target)?;
        self.staged.push((bytes, target.into()));
        Ok(())
    }

    /// Writes every staged file to a temporary beside its target and puts them all in place,
    /// or none (see `swap_in`); returns their paths.
    pub fn commit(self) -> Result<Vec<PathBuf>, ExportError> {
        let mut staged = Vec::with_capacity(self.staged.len());
        for (bytes, target) in self.staged {
            check_target(&target)?;
            let (dir, name) = (folder_of(&target), file_name(&target));
            // Without a lock, a temporary is only taken as stale once it is older than any
            // write; these live for the commit only.
            remove_stale_temporaries(dir, &[&name], std::time::Duration::from_secs(600));
            staged.push((stage(dir, &name, &bytes)?, target));
        }
        pause_hook(|| "commit".into());
        let old: Vec<PathBuf> = staged.iter().map(|(_, t)| t.clone()).collect();
        Ok(swap_in(staged, &old, &[], None)?.written)
    }
}

/// The files the old manifest at `manifest` lists that the new set does not write (`targets`)
/// and that are still what the old set wrote (their SHA-256 as recorded): they go with the
/// old set's other files, or a set written over another with fewer maps, a pack or another
/// format (`--maps color` after a full set, `--pack unreal` after PNGs) left the old set's
/// other maps beside the new ones, of another size or seed, under no manifest. A file
/// changed since (by hand: no longer the set's) is left where it is, as is anything the
/// manifest names that is not one of the set's own file names (`every_set_file_name`, in
/// its folder): an edited manifest cannot make a commit remove another set's files or
/// anything else. Best effort: a file that will not move aside (immutable, held open
/// elsewhere) stays, as before such files went at all. Returns the files to remove and the
/// files of the set's names that stay beside the new set although it does not write them,
/// with why (to be said): changed since, unreadable, or recorded by no manifest that could
/// be read (a manifest deleted or damaged: the files left were silent before).
fn left_over_files(manifest: &Path, targets: &[&PathBuf]) -> (Vec<PathBuf>, Vec<KeptFile>) {
    let Some(set_name) = file_name(manifest).strip_suffix(super::manifest::MANIFEST_SUFFIX).map(String::from) else {
        return (Vec::new(), Vec::new());
    };
    let dir = manifest.parent().unwrap_or(Path::new("."));
    let set_files = super::every_set_file_name(&set_name);
    let (files, mut kept, unrecorded_because) = recorded_left_overs(manifest, dir, &set_files, targets);
    // Every other file of the set's names that the new set does not write stays where it is
    // (nothing says it is a set's to remove) and is said: it lies beside the new set under no
    // manifest.
    for name in &set_files {
        let path = dir.join(name);
        let accounted = path == manifest
            || targets.contains(&&path)
            || files.contains(&path)
            || kept.iter().any(|k| k.path == path);
        if !accounted && fs::symlink_metadata(&path).is_ok() {
            kept.push(KeptFile { path, why: unrecorded_because.clone(), by: Earlier::Set });
        }
    }
    (files, kept)
}

/// `left_over_files`' reading of the old manifest: the files it records that are still as
/// recorded (to remove), those it records that changed or cannot be read (to keep), and why
/// any other file of the set's names is kept (no manifest, a manifest that could not be
/// read, or one that does not record it).
fn recorded_left_overs(
    manifest: &Path,
    dir: &Path,
    set_files: &[String],
    targets: &[&PathBuf],
) -> (Vec<PathBuf>, Vec<KeptFile>, KeptBecause) {
    let record = || "manifest".to_string();
    let unreadable =
        |error: String| (Vec::new(), Vec::new(), KeptBecause::RecordUnreadable { record: record(), error });
    if fs::symlink_metadata(manifest).is_err() {
        return (Vec::new(), Vec::new(), KeptBecause::NoRecord(file_name(manifest)));
    }
    let json = match super::manifest::read_set_manifest(manifest, crate::text_file::Links::Refuse) {
        Ok(json) => json,
        Err(super::manifest::ManifestReadError::Read(e)) => return unreadable(e.to_string()),
        Err(super::manifest::ManifestReadError::NotJson(e)) => return unreadable(format!("not JSON: {e}")),
    };
    let Some(entries) = json["maps"].as_array() else {
        return unreadable("it has no \"maps\" list".into());
    };
    let file_limit = super::manifest::set_file_max_bytes(&json);
    let (mut files, mut changed): (Vec<PathBuf>, Vec<KeptFile>) = (Vec::new(), Vec::new());
    for entry in entries {
        let Some(file) = entry["file"].as_str() else { continue };
        let path = dir.join(file);
        let seen = files.contains(&path) || changed.iter().any(|k| k.path == path);
        if !set_files.iter().any(|name| name == file) || targets.contains(&&path) || seen {
            continue;
        }
        let Ok(meta) = fs::symlink_metadata(&path) else { continue };
        // A regular file as its record's digest says goes. A link (never followed), a folder,
        // or a record without its digest is no longer what the set wrote.
        let why = match entry["sha256"].as_str() {
            Some(recorded) if meta.is_file() => {
                match super::manifest::set_file_sha256(&path, file_limit, crate::text_file::Links::Refuse) {
                    Ok(actual) if actual == recorded => {
                        files.push(path);
                        continue;
                    }
                    Ok(_) => KeptBecause::ChangedSince,
                    Err(e) => KeptBecause::Unreadable(e.to_string()),
                }
            }
            _ => KeptBecause::ChangedSince,
        };
        changed.push(KeptFile { path, why, by: Earlier::Set });
    }
    (files, changed, KeptBecause::NotRecorded { record: record() })
}

/// Undoes a commit that failed: removes the new files already in place and renames the old
/// ones back, the maps before the manifest (`aside` holds the manifest first), so that the
/// old manifest returns only over its own maps. An old file that cannot go back stays in
/// its temporary (never deleted), and then the old manifest stays aside too: the set is
/// incomplete, not mixed. `renames` counts on from the commit's (`before_rename`). Returns
/// the old files kept so: each temporary and the file it was.
fn put_back(
    aside: Vec<(tempfile::TempPath, PathBuf)>,
    written: &[PathBuf],
    manifest: Option<&Path>,
    renames: &mut usize,
) -> Vec<(PathBuf, PathBuf)> {
    let mut whole = true;
    for target in written {
        whole &= fs::remove_file(target).is_ok();
    }
    let mut kept = Vec::new();
    for (backup, target) in aside.into_iter().rev() {
        let back = if Some(target.as_path()) == manifest && !whole {
            Err(backup)
        } else {
            match before_rename(renames) {
                Ok(()) => backup.persist(&target).map_err(|e| e.path),
                Err(_) => Err(backup),
            }
        };
        if let Err(backup) = back {
            whole = false;
            if let Ok(temporary) = backup.keep() {
                kept.push((temporary, target));
            }
        }
    }
    // In the set's order, the manifest first, as they were moved aside.
    kept.reverse();
    kept
}

/// A commit's `error`, with the earlier files its undo could not put back (`put_back`).
fn not_put_back(error: ExportError, kept: Vec<(PathBuf, PathBuf)>) -> ExportError {
    if kept.is_empty() { error } else { ExportError::NotPutBack { source: Box::new(error), kept } }
}

/// The file name of a path in the set's folder.
fn file_name(path: &Path) -> String {
    path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default()
}

/// Counts the commit's renames in `renames`: moving the old files aside, putting the new
/// ones in, and an undo's renames back, in that order from 0. Test hooks (debug builds
/// only), so the commit and its undo can be tested at every step:
/// `SNAKESKIN_TEST_FAIL_AT_RENAME=N[,M...]` makes the renames listed fail with an I/O error,
/// as a file that may not be replaced would; `SNAKESKIN_TEST_KILL_AT_RENAME=N` ends the
/// process before rename N with no cleanup at all (`_exit`, as a SIGKILL would: no
/// destructor runs, temporaries and the lock file stay).
fn before_rename(renames: &mut usize) -> std::io::Result<()> {
    let this = *renames;
    *renames += 1;
    pause_hook(|| format!("rename-{this}"));
    #[cfg(debug_assertions)]
    {
        let listed = |name: &str| {
            std::env::var(name).is_ok_and(|v| v.split(',').any(|n| n.trim().parse::<usize>().ok() == Some(this)))
        };
        #[cfg(unix)]
        if listed("SNAKESKIN_TEST_KILL_AT_RENAME") {
            // SAFETY: `_exit` ends the process at once; nothing after it runs.
            unsafe { libc::_exit(137) };
        }
        if listed("SNAKESKIN_TEST_FAIL_AT_RENAME") {
            return Err(std::io::Error::new(std::io::ErrorKind::PermissionDenied, "injected failure (test hook)"));
        }
    }
    #[cfg(not(debug_assertions))]
    let _ = this;
    Ok(())
}

/// Test hook (debug builds only): `SNAKESKIN_TEST_PAUSE_AT=POINT` stops the run for three
/// seconds at POINT, `commit` (every file staged, before the commit lock and the first
/// rename), `rename-N` (before rename N, see `before_rename`, the lock held) or `verify-N`
/// (`verify_set`'s try N, its manifest read, its maps not), so that a test can interrupt the
/// run there or change its files.
pub(crate) fn pause_hook(point: impl Fn() -> String) {
    #[cfg(debug_assertions)]
    if std::env::var("SNAKESKIN_TEST_PAUSE_AT").is_ok_and(|at| at == point()) {
        std::thread::sleep(std::time::Duration::from_secs(3));
    }
    #[cfg(not(debug_assertions))]
    let _ = point;
}

/// A map of a set written to its temporary (`SetLock::stage`), waiting for `commit`.
#[derive(Debug)]
pub struct Staged {
    file: tempfile::NamedTempFile,
    /// The file name it takes in the set's folder.
    pub name: String,
    /// SHA-256 of its bytes (the manifest's `sha256`).
    pub sha256: String,
}

impl Drop for SetLock {
    /// Removes the lock file while still holding the lock (see `acquire`), then the folders
    /// this process made that are empty now (the run failed before its commit).
    fn drop(&mut self) {
        let mut held = locked(&HELD_LOCKS);
        if let Some(i) = held.iter().position(|p| *p == self.path) {
            held.swap_remove(i);
        }
        let _ = fs::remove_file(&self.path);
        drop(held);
        remove_empty_made_folders();
    }
}

/// True when `path` still names the open `file` (same device and inode).
fn same_file(file: &File, path: &Path) -> bool {
    match (file.metadata(), fs::symlink_metadata(path)) {
        (Ok(a), Ok(b)) => same_identity(&a, &b),
        _ => false,
    }
}

/// Whether two files' metadata are of one file: device and inode on Unix; elsewhere taken
/// as one.
pub fn same_identity(a: &fs::Metadata, b: &fs::Metadata) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        a.dev() == b.dev() && a.ino() == b.ino()
    }
    #[cfg(not(unix))]
    {
        let _ = (a, b);
        true
    }
}

/// Makes the renames durable where the platform allows (a folder fsync on Unix).
fn sync_folder(dir: &Path) {
    #[cfg(unix)]
    if let Ok(folder) = File::open(dir) {
        let _ = folder.sync_all();
    }
}

/// Checks, before the work, that a new file can be made where `target` goes (its folder must
/// exist): a temporary for it is made and removed (an empty one, that a watcher of the
/// folder may see). `preview --out ro/x.png` rendered for seconds (minutes with its CPU
/// reference) and only then said "cannot write ro: Permission denied"; now it says so at
/// once, naming the file.
pub fn check_writable(target: &Path) -> Result<(), ExportError> {
    // Empty, so neither written nor synced (a batch probes a folder per set). The probe is
    // always a new file: a refusal is the folder's, whatever stands at the target (an earlier
    // set's writable manifest was named as the culprit).
    let probe = listed_temporary(folder_of(target), &file_name(target)).map_err(|e| folder_refused(target, e))?;
    let path = probe.path().to_path_buf();
    drop(probe);
    forget_temporary(&path);
    Ok(())
}

/// Checks, before the work, that a run can write `file` in `dir`, or where `dir` is missing,
/// make its first missing folder (a probe of that name in the folder that exists:
/// `check_writable`). Each folder once: `probed` holds those probed. A batch whose job's
/// preset folder was read-only found it when that job ran, after the jobs before it.
pub fn check_folder_writable(
    dir: &Path,
    file: &str,
    probed: &mut std::collections::HashSet<PathBuf>,
) -> Result<(), ExportError> {
    let target = probe_target(dir, file);
    if !probed.insert(folder_of(&target).to_path_buf()) {
        return Ok(());
    }
    check_writable(&target)
}

/// What `check_folder_writable` makes a probe of: `file` in `dir`, or `dir`'s first missing
/// folder (in the folder that exists).
fn probe_target(dir: &Path, file: &str) -> PathBuf {
    if fs::symlink_metadata(dir).is_ok() { dir.join(file) } else { first_missing_folder(dir).into() }
}

/// Writes one file atomically (exclusive temporary, then rename) to `path`. The folder must
/// exist (the binary creates missing folders and says so).
pub fn write_file_atomically(path: &Path, bytes: Vec<u8>) -> Result<PathBuf, ExportError> {
    let dir = folder_of(path);
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).ok_or_else(|| ExportError::Io {
        path: path.into(),
        source: std::io::Error::new(std::io::ErrorKind::InvalidInput, "the path does not name a file"),
    })?;
    create_folder(dir)?;
    check_target(path)?;
    // Without a lock, a temporary is only taken as stale once it is older than any write.
    remove_stale_temporaries(dir, &[&name], std::time::Duration::from_secs(600));
    let tmp = stage(dir, &name, &bytes)?;
    let temporary = tmp.path().to_path_buf();
    tmp.persist(path).map_err(|e| ExportError::Io { path: path.into(), source: e.error })?;
    forget_temporary(&temporary);
    Ok(path.into())
}

/// The most numbered names `write_new_numbered_file` tries in one folder.
pub const NUMBERED_NAMES_MAX: u32 = 9999;

/// Writes `bytes` as `dir/STEM_N.EXTENSION` for the first N from 1 whose file is not there,
/// atomically (exclusive temporary, then a link that refuses to replace), so that a
/// picture saved twice, or by two windows into one folder at once, keeps every earlier one.
/// The folder is made if missing.
pub fn write_new_numbered_file(dir: &Path, stem: &str, extension: &str, bytes: &[u8]) -> Result<PathBuf, ExportError> {
    let name = |n: u32| format!("{stem}_{n}.{extension}");
    create_folder(dir)?;
    let mut tmp = stage(dir, &name(1), bytes)?;
    let temporary = tmp.path().to_path_buf();
    let written = (|| {
        for n in 1..=NUMBERED_NAMES_MAX {
            let target = dir.join(name(n));
            match tmp.persist_noclobber(&target) {
                Ok(_) => return Ok(target),
                Err(e) if e.error.kind() == std::io::ErrorKind::AlreadyExists => tmp = e.file,
                Err(e) => return Err(io_error(&target)(e.error)),
            }
        }
        Err(ExportError::Io {
            path: dir.join(name(NUMBERED_NAMES_MAX)),
            source: std::io::Error::new(
                std::io::ErrorKind::AlreadyExists,
                format!("{} files named {stem}_N.{extension} are there already; move some away", NUMBERED_NAMES_MAX),
            ),
        })
    })();
    forget_temporary(&temporary);
    written
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Numbered files never replace one another: the third save beside 1 and 3 (2 removed)
    /// is 2, and 1 and 3 keep their bytes; no temporary is left. Negative control: a folder
    /// that is a file is refused, and nothing is written.
    #[test]
    fn numbered_files_take_the_first_free_number_and_replace_none() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let first = write_new_numbered_file(d, "boa", "png", b"one").unwrap();
        let second = write_new_numbered_file(d, "boa", "png", b"two").unwrap();
        let third = write_new_numbered_file(d, "boa", "png", b"three").unwrap();
        assert_eq!(
            [&first, &second, &third].map(|p| p.file_name().unwrap().to_owned()),
            ["boa_1.png", "boa_2.png", "boa_3.png"].map(std::ffi::OsString::from)
        );
        fs::remove_file(&second).unwrap();
        let again = write_new_numbered_file(d, "boa", "png", b"again").unwrap();
        assert_eq!(again, second);
        for (path, bytes) in [(&first, &b"one"[..]), (&second, b"again"), (&third, b"three")] {
            assert_eq!(fs::read(path).unwrap(), bytes);
        }
        let names: Vec<String> =
            fs::read_dir(d).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
        assert_eq!(names.len(), 3, "{names:?}");
        let file = d.join("boa_1.png");
        assert!(write_new_numbered_file(&file, "boa", "png", b"x").is_err());
        assert_eq!(fs::read_dir(d).unwrap().count(), 3);
    }

    /// A group's staged files leave no temporary while the work goes on, so another run's
    /// sweep of stale temporaries (here everything of the name, at any age) takes nothing
    /// from it and its commit writes every file. A `preview --reference` staged its frame,
    /// then spent longer than the sweep's ten minutes on the reference; another preview to
    /// the same name removed the temporary, and the first failed at its end. Negative
    /// control: the commit's own temporaries, swept before the renames, fail it.
    #[test]
    fn a_groups_staged_files_survive_another_runs_sweep() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a.png"), dir.path().join("b.png"));
        let mut group = FileGroup::new();
        group.stage(&a, b"first".to_vec()).unwrap();
        group.stage(&b, b"second".to_vec()).unwrap();
        remove_stale_temporaries(dir.path(), &["a.png", "b.png"], std::time::Duration::ZERO);
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 0, "a temporary while the work goes on");
        group.commit().unwrap();
        assert_eq!((fs::read(&a).unwrap(), fs::read(&b).unwrap()), (b"first".to_vec(), b"second".to_vec()));
        // The control: a temporary swept before its rename.
        let swept = stage(dir.path(), "a.png", b"third").unwrap();
        remove_stale_temporaries(dir.path(), &["a.png"], std::time::Duration::ZERO);
        assert!(swept.persist(&a).is_err(), "the sweep took nothing");
    }

    /// A lock released a moment after the run starts (a killed run's, while the kernel
    /// tears it down) is taken, not called busy; one held on is busy. Held here by a second
    /// open of the lock file (`flock` locks conflict between open files, in one process too).
    /// Negative control: without the retries the first acquire is `Busy`.
    #[test]
    fn a_lock_released_a_moment_later_is_taken() {
        let dir = tempfile::tempdir().unwrap();
        let holder = fs::File::create(dir.path().join(lock_file_name("n"))).unwrap();
        holder.lock().unwrap();
        let release = std::thread::spawn(move || {
            std::thread::sleep(std::time::Duration::from_millis(300));
            drop(holder);
        });
        let lock = SetLock::acquire(dir.path(), "n");
        release.join().unwrap();
        assert!(lock.is_ok(), "{:?}", lock.err());
        drop(lock);
        let mut options = fs::OpenOptions::new();
        options.create(true).truncate(false).write(true);
        let holder = options.open(dir.path().join(lock_file_name("n"))).unwrap();
        holder.lock().unwrap();
        assert!(matches!(SetLock::acquire(dir.path(), "n"), Err(ExportError::Busy { .. })));
    }

    /// A file a folder refused names the folder (it said "cannot write ro/.NAME.lock"); a
    /// folder that could not be made is the first one missing (it named the deepest, three
    /// levels below the one that refused). Tests run as root, where no folder refuses: the
    /// refusal is the error itself.
    #[test]
    fn a_refusal_names_the_folder_that_refused() {
        let dir = tempfile::tempdir().unwrap();
        let denied = || std::io::Error::from(std::io::ErrorKind::PermissionDenied);
        let lock = dir.path().join(".x.lock");
        match io_error(&lock)(denied()) {
            ExportError::FolderNotWritable { folder, name, .. } => {
                assert_eq!((folder.as_path(), name.as_str()), (dir.path(), ".x.lock"));
            }
            other => panic!("{other}"),
        }
        // In the working folder, named as `.`.
        let here = Path::new(".snakeskin-no-such-file.lock");
        assert!(
            matches!(io_error(here)(denied()), ExportError::FolderNotWritable { folder, .. } if folder == Path::new("."))
        );
        // A read-only file system.
        let read_only = io_error(&lock)(std::io::Error::from(std::io::ErrorKind::ReadOnlyFilesystem));
        assert!(matches!(read_only, ExportError::FolderNotWritable { .. }), "{read_only}");
        // Negative controls: a file that is there (it may refuse itself), another error.
        fs::write(&lock, b"").unwrap();
        assert!(matches!(io_error(&lock)(denied()), ExportError::Io { .. }));
        let missing = dir.path().join("y");
        let full = std::io::Error::from(std::io::ErrorKind::StorageFull);
        assert!(matches!(io_error(&missing)(full), ExportError::Io { .. }));
        assert_eq!(first_missing_folder(&dir.path().join("a/b/c")), dir.path().join("a"));
        assert_eq!(first_missing_folder(&dir.path().join("a/..")), dir.path().join("a"));
        assert_eq!(first_missing_folder(dir.path()), dir.path());
    }

    /// A batch's folders are probed before any job runs where its sets go: a file in a folder
    /// that exists, else the first folder missing in the one that does; each folder once.
    #[test]
    fn a_folder_is_probed_where_the_set_goes_and_once() {
        let dir = tempfile::tempdir().unwrap();
        let set = dir.path().join("natrix/tile-16-seed1-png");
        assert_eq!(probe_target(&set, "n.material.json"), dir.path().join("natrix"));
        fs::create_dir_all(&set).unwrap();
        assert_eq!(probe_target(&set, "n.material.json"), set.join("n.material.json"));
        let mut probed = std::collections::HashSet::new();
        check_folder_writable(&set, "n.material.json", &mut probed).unwrap();
        check_folder_writable(&set, "m.material.json", &mut probed).unwrap();
        check_folder_writable(&dir.path().join("natrix/other"), "n.material.json", &mut probed).unwrap();
        assert_eq!(probed, [set.clone(), dir.path().join("natrix")].into_iter().collect());
        // The probe leaves nothing.
        assert_eq!(fs::read_dir(&set).unwrap().count(), 0);
    }

    /// One file named two ways: through `..` (its folder missing or not) and a link.
    /// Negative controls: two different files, and a file beside its folder's name.
    #[cfg(unix)]
    #[test]
    fn two_names_of_one_file_are_the_same_path() {
        let dir = tempfile::tempdir().unwrap();
        let at = |p: &str| dir.path().join(p);
        fs::create_dir(at("real")).unwrap();
        std::os::unix::fs::symlink(at("real"), at("link")).unwrap();
        assert!(same_path(&at("sub/../a.png"), &at("a.png")));
        assert!(same_path(&at("real/../a.png"), &at("./a.png")));
        assert!(same_path(&at("link/h.png"), &at("real/h.png")));
        assert!(!same_path(&at("a.png"), &at("b.png")));
        assert!(!same_path(&at("real/a.png"), &at("a.png")));
    }

    /// A folder another thread or process makes while one is checked is a folder, not "a
    /// symbolic link to nothing": the check read the path missing, then present (CI: two
    /// jobs of one batch in one new folder, `a_killed_batch_resumes_...`). The race is
    /// provoked many times over; negative control: a real dangling link is still one.
    #[cfg(unix)]
    #[test]
    fn a_folder_made_meanwhile_is_not_a_broken_link() {
        let dir = tempfile::tempdir().unwrap();
        for i in 0..3000 {
            let path = dir.path().join(format!("f{i}"));
            let maker = {
                let path = path.clone();
                std::thread::spawn(move || fs::create_dir_all(&path).unwrap())
            };
            while !path.is_dir() {
                check_folder(&path).unwrap();
            }
            check_folder(&path).unwrap();
            maker.join().unwrap();
        }
        let link = dir.path().join("dangling");
        std::os::unix::fs::symlink(dir.path().join("nowhere"), &link).unwrap();
        assert!(matches!(check_folder(&link), Err(ExportError::BrokenLink { .. })));
    }

    /// A folder no file can be made in (sysfs refuses new files, root or not): the error
    /// named tempfile's hidden temporary (`at path "/sys/.x.png.RZ4prK.snakeskin-tmp"`).
    #[cfg(target_os = "linux")]
    #[test]
    fn a_temporary_that_cannot_be_made_is_not_named() {
        let error = temporary(Path::new("/sys"), "x.png").unwrap_err().to_string();
        assert!(!error.contains(TMP_SUFFIX) && !error.contains("at path"), "{error}");
        assert!(error.contains("(os error"), "the OS's reason is kept: {error}");
    }

    /// Folders a failed run made go when its lock goes: a parent another lock made too (a
    /// batch's jobs share `out/PRESET/`) once the last of them goes, and through a `..` what
    /// lies after it (`there/../c/d`: `there` was there before). A `..` out of a missing folder
    /// makes nothing (`check_folder`). A folder that holds a file stays. Negative controls:
    /// the folders that were there stay.
    #[test]
    fn empty_folders_a_run_made_go_with_its_lock() {
        let dir = tempfile::tempdir().unwrap();
        let at = |p: &str| dir.path().join(p);
        fs::create_dir(at("there")).unwrap();
        let refused = SetLock::acquire(&at("c/../there/d"), "boa");
        assert!(matches!(refused, Err(ExportError::ThroughMissingFolder { .. })), "{refused:?}");
        assert!(!at("c").exists() && !at("there/d").exists());
        let through = SetLock::acquire(&at("there/../c/d"), "boa").unwrap();
        assert!(at("c/d").is_dir());
        drop(through);
        assert!(!at("c").exists() && at("there").is_dir(), "c goes, the folder that was there stays");
        let first = SetLock::acquire(&at("out/boa/seed1"), "boa").unwrap();
        let second = SetLock::acquire(&at("out/boa/seed2"), "boa").unwrap();
        let written = SetLock::acquire(&at("written"), "boa").unwrap();
        fs::write(at("written/boa.material.json"), b"{}").unwrap();
        drop(first);
        assert!(!at("out/boa/seed1").exists() && at("out/boa/seed2").is_dir(), "the other job's folder stays");
        drop(second);
        assert!(!at("out").exists(), "the parent the first lock made goes with the last lock in it");
        drop(written);
        assert!(at("written/boa.material.json").is_file());
        assert!(dir.path().is_dir());
    }
}
