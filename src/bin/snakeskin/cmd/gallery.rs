//! `snakeskin gallery`: every scale shape and pattern kind on one sheet.

use std::path::Path;

use anyhow::Result;

use crate::output::{ensure_folder, ensure_parent_folder, path_line};

/// Both outputs are checked before either is drawn: a `--closeups` path that is a file used
/// to fail after the gallery was written, with the OS's "File exists" and no path. Memory
/// and the two names are checked before any folder is made.
pub fn run(out: &Path, tile: usize, columns: usize, closeups: Option<&Path>) -> Result<()> {
    snakeskin::render::figures::gallery::check_memory(tile, columns)?;
    snakeskin::export::check_target(out)?;
    if let Some(dir) = closeups
        && snakeskin::export::same_path(dir, out)
    {
        return Err(snakeskin::Error::Unsupported(format!(
            "-o and --closeups name one path ({}): the gallery is a file, the close-ups a folder",
            path_line(out)
        ))
        .into());
    }
    ensure_parent_folder(out)?;
    if let Some(dir) = closeups {
        ensure_folder(dir)?;
    }
    snakeskin::render::figures::gallery::write(out, tile, columns)?;
    println!("{}", path_line(out));
    if let Some(dir) = closeups {
        for path in snakeskin::render::figures::gallery::write_closeups(dir)? {
            println!("{}", path_line(&path));
        }
    }
    Ok(())
}
