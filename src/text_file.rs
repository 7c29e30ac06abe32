//! Small text inputs a user names on the command line (presets, jobs files), read with a
//! bound: a device such as /dev/zero, a FIFO with no writer or a huge file is refused without
//! reading it, so a mistaken path costs neither memory nor a hang. One reader, so every input
//! refuses them alike; each caller turns the refusal into its own typed error.

use std::io::Read;
use std::path::Path;

/// Why a bounded text file was not read.
#[derive(Debug)]
pub enum BoundedReadError {
    /// Opening or reading failed, or the bytes are not UTF-8.
    Io(std::io::Error),
    /// Not a regular file: what it is ("a FIFO", "a device", "a folder" ...).
    NotAFile(&'static str),
    /// Larger than the limit: its size in bytes (its size now, if it grew while it was read).
    TooLarge(u64),
}

/// Reads `path` as UTF-8 text of at most `limit` bytes. The file is opened without blocking
/// (a FIFO would otherwise wait forever for a writer) and checked through the open handle,
/// then read with a bound, so neither a device nor a file growing after the check is read
/// past `limit`.
pub fn read_bounded(path: &Path, limit: u64) -> Result<String, BoundedReadError> {
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    std::os::unix::fs::OpenOptionsExt::custom_flags(&mut options, libc::O_NONBLOCK);
    let file = options.open(path).map_err(BoundedReadError::Io)?;
    let meta = file.metadata().map_err(BoundedReadError::Io)?;
    if !meta.is_file() {
        return Err(BoundedReadError::NotAFile(file_kind(&meta.file_type())));
    }
    if meta.len() > limit {
        return Err(BoundedReadError::TooLarge(meta.len()));
    }
    let mut bytes = Vec::new();
    (&file).take(limit + 1).read_to_end(&mut bytes).map_err(BoundedReadError::Io)?;
    if bytes.len() as u64 > limit {
        // It grew after the check: its size now, not the limit + 1 bytes that were read.
        let now = file.metadata().map_or(0, |m| m.len());
        return Err(BoundedReadError::TooLarge(now.max(bytes.len() as u64)));
    }
    String::from_utf8(bytes).map_err(|e| {
        BoundedReadError::Io(std::io::Error::new(std::io::ErrorKind::InvalidData, format!("not UTF-8 text ({e})")))
    })
}

/// What a file that is not a regular file is, in words ("a FIFO", "a device", "a folder",
/// "a symbolic link" ...): the one wording for input files (here) and output targets
/// (`export::check_target`).
pub(crate) fn file_kind(t: &std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "a FIFO";
        }
        if t.is_char_device() || t.is_block_device() {
            return "a device";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    if t.is_dir() {
        "a folder"
    } else if t.is_symlink() {
        "a symbolic link"
    } else {
        "not a regular file"
    }
}
