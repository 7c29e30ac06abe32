//! `snakeskin figures`: the documentation figures (layer stages, thickness, absorption).

use std::path::Path;

use anyhow::Result;

use crate::cli::ImageSize;
use crate::output::{ensure_folder, path_line};
use crate::progress::Progress;
use snakeskin::maps::Layout;
use snakeskin::render::Renderer;
use snakeskin::render::figures::write_figures;

/// Names, then memory (the maps and one frame: figures are rendered one at a time, drawn
/// in turn, each PNG staged before the next), then the GPU, then the folder: a refused run
/// makes none.
/// (The memory check was the maps' alone, after the folder and the renderer were made: an
/// 8192-wide run reached 4.9 GB under a 300 MiB limit.)
pub fn run(preset: &str, out: &Path, size: ImageSize, map_size: u64) -> Result<()> {
    // Read once: the memory check and every figure parse this text (`write_figures`).
    let source = snakeskin::preset::read_source(preset)?;
    let loaded = snakeskin::preset::parse(&source, &[])?;
    snakeskin::export::check_folder(out)?;
    snakeskin::render::figures::check_figure_files(out, preset)?;
    let frame_bytes = snakeskin::render::engine::renderer::frame_bytes(size.width, size.height);
    snakeskin::render::engine::prepare::check_preview_memory(
        &loaded,
        map_size as usize,
        Layout::Tile,
        frame_bytes,
        true,
    )?;
    ensure_folder(out)?;
    let renderer = Renderer::headless()?;
    let bar = Progress::counting("{spinner} figures [{bar:30}] {pos}/{len} {elapsed}");
    let files = write_figures(
        &renderer,
        preset,
        &source,
        out,
        (size.width, size.height),
        map_size as usize,
        &|done, total| bar.update(done, total),
    )?;
    bar.finish();
    for f in files {
        println!("{}", path_line(&f));
    }
    Ok(())
}
