//! All-or-nothing output: every file of a set is written to a temporary name in the target
//! folder first, and only when all of them are complete are they renamed into place. A
//! failed or interrupted run leaves no truncated file and never damages an earlier output.

use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};

use super::ExportError;

/// Writes `files` (name, bytes) into `dir`, creating it if needed.
pub fn write_all_atomically(dir: &Path, files: &[(String, Vec<u8>)]) -> Result<Vec<PathBuf>, ExportError> {
    fs::create_dir_all(dir).map_err(|source| ExportError::Io { path: dir.into(), source })?;
    let mut staged: Vec<(PathBuf, PathBuf)> = Vec::new();
    let cleanup = |staged: &[(PathBuf, PathBuf)]| {
        for (tmp, _) in staged {
            let _ = fs::remove_file(tmp);
        }
    };
    for (name, bytes) in files {
        let target = dir.join(name);
        let tmp = dir.join(format!(".{name}.tmp-{}", std::process::id()));
        let written = fs::File::create(&tmp).and_then(|mut f| {
            f.write_all(bytes)?;
            f.sync_all()
        });
        if let Err(source) = written {
            let _ = fs::remove_file(&tmp);
            cleanup(&staged);
            return Err(ExportError::Io { path: tmp, source });
        }
        staged.push((tmp, target));
    }
    for (tmp, target) in &staged {
        if let Err(source) = fs::rename(tmp, target) {
            cleanup(&staged);
            return Err(ExportError::Io { path: target.clone(), source });
        }
    }
    Ok(staged.into_iter().map(|(_, target)| target).collect())
}

/// Writes one file atomically (temporary name, then rename) to `path`.
pub fn write_file_atomically(path: &Path, bytes: Vec<u8>) -> Result<PathBuf, ExportError> {
    let dir = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let name = path.file_name().ok_or_else(|| ExportError::Io {
        path: path.into(),
        source: std::io::Error::new(std::io::ErrorKind::InvalidInput, "the path does not name a file"),
    })?;
    let written = write_all_atomically(dir, &[(name.to_string_lossy().into_owned(), bytes)])?;
    Ok(written.into_iter().next().unwrap_or_else(|| path.into()))
}
