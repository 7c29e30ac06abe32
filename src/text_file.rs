//! Files read with a bound: the small text inputs a user names on the command line (presets,
//! jobs files), and the files of an earlier set that a run reads back to see whether it is
//! complete (its manifest and maps, `batch` and the commit's clean-up). A device such as
//! /dev/zero, a FIFO with no writer or a huge file is refused without reading it, so a
//! mistaken path, or a planted one, costs neither memory nor a hang. One reader, so every
//! input refuses them alike; each caller turns the refusal into its own typed error.

use std::io::Read;
use std::path::Path;

/// Why a bounded text file was not read.
#[derive(Debug)]
pub enum BoundedReadError {
    /// Opening or reading failed, or the bytes are not UTF-8.
    Io(std::io::Error),
    /// Not a regular file: what it is ("a FIFO", "a device", "a folder" ...).
    NotAFile(&'static str),
    /// Larger than the limit: its size (its size now, if it grew while it was read).
    TooLarge(FileSize),
}

/// A file's size as far as it is known: its bytes, or only that it holds more than the
/// limit (a file that reports no size, as /proc's do, read to the limit and a byte more: it
/// was said to be that many bytes, "1048577", whatever it held).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FileSize {
    Bytes(u64),
    MoreThan(u64),
}

impl std::fmt::Display for FileSize {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            FileSize::Bytes(bytes) => write!(f, "{bytes} bytes"),
            FileSize::MoreThan(limit) => write!(f, "more than {limit} bytes"),
        }
    }
}

/// Whether opening a path follows a symbolic link at its end: a user's input may be a link,
/// and so may a set a reader checks (kept as links, as git-annex keeps files); what a run
/// may remove or replace is never reached through one (the set wrote none).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Links {
    Follow,
    Refuse,
}

impl std::fmt::Display for BoundedReadError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            BoundedReadError::Io(e) => write!(f, "{e}"),
            BoundedReadError::NotAFile(kind) => write!(f, "it is {kind}, not a regular file"),
            BoundedReadError::TooLarge(size @ FileSize::Bytes(_)) => {
                write!(f, "it is {size}, more than such a file can be")
            }
            BoundedReadError::TooLarge(size) => write!(f, "it is {size}, larger than such a file can be"),
        }
    }
}

/// Opens `path` for reading, without blocking (a FIFO would otherwise wait forever for a
/// writer), and checks through the open handle that it is a regular file of at most `limit`
/// bytes. The caller reads it with `take(limit.saturating_add(1))`, so a file growing after
/// the check is not read past the bound either (`check_read_length`).
pub fn open_bounded(path: &Path, limit: u64, links: Links) -> Result<std::fs::File, BoundedReadError> {
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        let no_follow = if links == Links::Refuse { libc::O_NOFOLLOW } else { 0 };
        std::os::unix::fs::OpenOptionsExt::custom_flags(&mut options, libc::O_NONBLOCK | no_follow);
    }
    let file = options.open(path).map_err(|e| {
        // O_NOFOLLOW's refusal of a link is ELOOP: said as what the path is.
        #[cfg(unix)]
        if links == Links::Refuse && e.raw_os_error() == Some(libc::ELOOP) {
            return BoundedReadError::NotAFile("a symbolic link");
        }
        BoundedReadError::Io(e)
    })?;
    let meta = file.metadata().map_err(BoundedReadError::Io)?;
    if !meta.is_file() {
        return Err(BoundedReadError::NotAFile(file_kind(&meta.file_type())));
    }
    if meta.len() > limit {
        return Err(BoundedReadError::TooLarge(FileSize::Bytes(meta.len())));
    }
    Ok(file)
}

/// After reading `read` bytes of `file` with `take(limit + 1)`: refuses a file that grew past
/// `limit` after `open_bounded` checked it, with its size now.
pub fn check_read_length(file: &std::fs::File, read: u64, limit: u64) -> Result<(), BoundedReadError> {
    if read > limit {
        let now = file.metadata().map_or(0, |m| m.len());
        let size = if now > limit { FileSize::Bytes(now) } else { FileSize::MoreThan(limit) };
        return Err(BoundedReadError::TooLarge(size));
    }
    Ok(())
}

/// Reads `path`, a regular file of at most `limit` bytes (`open_bounded`).
pub fn read_bounded_bytes(path: &Path, limit: u64, links: Links) -> Result<Vec<u8>, BoundedReadError> {
    let file = open_bounded(path, limit, links)?;
    let mut bytes = Vec::new();
    (&file).take(limit.saturating_add(1)).read_to_end(&mut bytes).map_err(BoundedReadError::Io)?;
    check_read_length(&file, bytes.len() as u64, limit)?;
    Ok(bytes)
}

/// Reads `path` as UTF-8 text of at most `limit` bytes (`open_bounded`; a link is followed).
pub fn read_bounded(path: &Path, limit: u64) -> Result<String, BoundedReadError> {
    let bytes = read_bounded_bytes(path, limit, Links::Follow)?;
    String::from_utf8(bytes).map_err(|e| {
        let message = not_utf8(e.as_bytes(), &e.utf8_error());
        BoundedReadError::Io(std::io::Error::new(std::io::ErrorKind::InvalidData, message))
    })
}

/// Where `bytes` stop being UTF-8, in the words of the TOML errors: the line and column
/// (counted as `toml_text::line_column` counts them) and the byte, so a stray Latin-1 `é`
/// can be found in an editor. std's own message gave a byte offset ("invalid utf-8 sequence
/// of 1 bytes from index 23"). A UTF-16 file (Windows' "Unicode") is named as such: every
/// other byte of it is zero, and its first line would be all the message could point at.
fn not_utf8(bytes: &[u8], error: &std::str::Utf8Error) -> String {
    if bytes.starts_with(&[0xFF, 0xFE]) || bytes.starts_with(&[0xFE, 0xFF]) {
        return "not UTF-8 text: it begins with a UTF-16 byte-order mark (save it as UTF-8)".into();
    }
    let valid = error.valid_up_to();
    let before = std::str::from_utf8(&bytes[..valid]).unwrap_or_default();
    let (line, column) = crate::toml_text::line_column(before, valid);
    match error.error_len() {
        Some(_) => format!(
            "not UTF-8 text: line {line}, column {column} holds the byte 0x{:02X}, which UTF-8 does not allow there \
             (save the file as UTF-8)",
            bytes[valid]
        ),
        None => format!("not UTF-8 text: it ends inside a character at line {line}, column {column} (cut short?)"),
    }
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

#[cfg(test)]
mod tests {
    use super::{check_read_length, not_utf8};

    /// A file read past its limit whose size says less than was read (a /proc file reports
    /// 0) is "more than the limit", not the bytes read ("1048577"); one that reports more
    /// is its size.
    #[test]
    fn a_file_past_its_limit_is_its_size_or_more_than_the_limit() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("f");
        std::fs::write(&path, [b'x'; 100]).unwrap();
        let file = std::fs::File::open(&path).unwrap();
        let said = |file: &std::fs::File| check_read_length(file, 11, 10).unwrap_err().to_string();
        assert_eq!(said(&file), "it is 100 bytes, more than such a file can be");
        std::fs::write(&path, b"12345").unwrap();
        assert_eq!(said(&file), "it is more than 10 bytes, larger than such a file can be");
        assert!(check_read_length(&file, 10, 10).is_ok());
    }

    fn message(bytes: &[u8]) -> String {
        not_utf8(bytes, &std::str::from_utf8(bytes).expect_err("the test's bytes are not UTF-8"))
    }

    /// Line and column of the first byte that is not UTF-8, counted in characters (the `é`
    /// before it is one column, as in an editor).
    #[test]
    fn the_first_byte_that_is_not_utf8_is_placed_by_line_and_column() {
        assert_eq!(
            message(b"seed = 1\nname = \"\xC3\xA9t\xE9\"\n"),
            "not UTF-8 text: line 2, column 11 holds the byte 0xE9, which UTF-8 does not allow there (save the \
             file as UTF-8)"
        );
        assert!(message(b"\xFF").contains("line 1, column 1 holds the byte 0xFF"), "{}", message(b"\xFF"));
        assert_eq!(message(b"a\nb\xC3"), "not UTF-8 text: it ends inside a character at line 2, column 2 (cut short?)");
        assert_eq!(
            message(b"\xFF\xFEs\0e\0"),
            "not UTF-8 text: it begins with a UTF-16 byte-order mark (save it as UTF-8)"
        );
    }
}
