//! `snakeskin gallery`: every scale shape and pattern kind on one sheet.

use std::path::Path;

use anyhow::Result;

use crate::output::{ensure_parent_folder, path_line};

pub fn run(out: &Path, tile: usize, columns: usize) -> Result<()> {
    ensure_parent_folder(out)?;
    snakeskin::render::figures::gallery::write(out, tile, columns)?;
    println!("{}", path_line(out));
    Ok(())
}
