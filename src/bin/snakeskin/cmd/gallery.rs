//! `snakeskin gallery`: every scale shape and pattern kind on one sheet.

use std::path::Path;

use anyhow::Result;

use crate::output::{ensure_folder, ensure_parent_folder, path_line};

/// Every output is checked before any is drawn: a `--closeups` path that is a file used to
/// fail after the gallery was written, with the OS's "File exists" and no path, and a folder
/// in the way of one close-up after the gallery and some close-ups were. Memory and the
/// names are checked before any folder is made; the files appear together (`gallery::write`).
pub fn run(out: &Path, tile: usize, columns: usize, closeups: Option<&Path>) -> Result<()> {
    snakeskin::render::figures::gallery::check_memory(tile, columns, closeups.is_some())?;
    snakeskin::export::check_png_target(out)?;
    if let Some(dir) = closeups
        && snakeskin::export::same_path(dir, out)
    {
        return Err(snakeskin::Error::Unsupported(format!(
            "-o and --closeups name one path ({}): the gallery is a file, the close-ups a folder",
            path_line(out)
        ))
        .into());
    }
    if let Some(dir) = closeups
        && snakeskin::export::lies_under(dir, out)
    {
        return Err(snakeskin::Error::Unsupported(format!(
            "--closeups {} lies inside -o {}, the gallery's file; give the close-ups a folder of their own",
            path_line(dir),
            path_line(out)
        ))
        .into());
    }
    if let Some(dir) = closeups {
        snakeskin::export::check_folder(dir)?;
        let mut probed = std::collections::HashSet::new();
        for name in snakeskin::render::figures::gallery::closeup_file_names() {
            let closeup = dir.join(&name);
            snakeskin::export::check_target(&closeup)?;
            snakeskin::export::check_replaces_its_own(&closeup, "png")?;
            // A read-only folder was found after the gallery was drawn, seconds and a
            // gigabyte in, as "cannot write DIR" (a hostile-input review).
            snakeskin::export::check_folder_writable(dir, &name, &mut probed)?;
            // `-o sp/rows.png --closeups sp`: the close-up replaced the gallery (the review).
            if snakeskin::export::same_path(&closeup, out) {
                return Err(snakeskin::Error::Unsupported(format!(
                    "-o names the close-up {} that --closeups writes; give the gallery another name",
                    path_line(&closeup)
                ))
                .into());
            }
        }
    }
    ensure_parent_folder(out)?;
    if let Some(dir) = closeups {
        ensure_folder(dir)?;
    }
    for path in snakeskin::render::figures::gallery::write(out, tile, columns, closeups)? {
        println!("{}", path_line(&path));
    }
    Ok(())
}
