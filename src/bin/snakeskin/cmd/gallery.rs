//! `snakeskin gallery`: every scale shape and pattern kind on one sheet.

use std::path::Path;

use anyhow::Result;

use crate::output::{ensure_parent_folder, path_line};

pub fn run(out: &Path, tile: usize, columns: usize, closeups: Option<&Path>) -> Result<()> {
    ensure_parent_folder(out)?;
    snakeskin::render::figures::gallery::write(out, tile, columns)?;
    println!("{}", path_line(out));
    if let Some(dir) = closeups {
        std::fs::create_dir_all(dir)?;
        for path in snakeskin::render::figures::gallery::write_closeups(dir)? {
            println!("{}", path_line(&path));
        }
    }
    Ok(())
}
