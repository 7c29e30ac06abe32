//! `snakeskin figures`: the documentation figures (layer stages, thickness, absorption).

use std::path::Path;

use anyhow::Result;

use crate::cli::ImageSize;
use crate::output::{ensure_folder, path_line};
use crate::progress::Progress;
use snakeskin::render::Renderer;
use snakeskin::render::figures::write_figures;

pub fn run(preset: &str, out: &Path, size: ImageSize, map_size: u64) -> Result<()> {
    snakeskin::preset::load(preset, &[], None)?;
    ensure_folder(out)?;
    let renderer = Renderer::headless()?;
    let bar = Progress::counting("{spinner} figures [{bar:30}] {pos}/{len} {elapsed}");
    let files = write_figures(&renderer, preset, out, (size.width, size.height), map_size as usize, &|done, total| {
        bar.update(done, total)
    })?;
    bar.finish();
    for f in files {
        println!("{}", path_line(&f));
    }
    Ok(())
}
