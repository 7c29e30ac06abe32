//! `snakeskin figures`: the documentation figures (layer stages, thickness, absorption).

use std::path::Path;

use anyhow::Result;

use crate::cli::ImageSize;
use crate::output::{ensure_folder, path_line, report_warnings};
use crate::progress::Progress;
use snakeskin::maps::Layout;
use snakeskin::render::Renderer;
use snakeskin::render::figures::write_figures;

/// Names, then memory (the maps and one frame: figures are rendered one at a time, drawn
/// in turn, each PNG staged before the next), then the GPU, then the folder: a refused run
/// makes none (the folder was made before the GPU was asked for, and a run without an
/// adapter said "created folder" of one it then removed: a hostile-input review).
/// (The memory check was the maps' alone, after the folder and the renderer were made: an
/// 8192-wide run reached 4.9 GB under a 300 MiB limit.)
/// The preset's warnings are printed as `preview` prints them, then those only a figure's
/// overrides bring, once each with the figures they concern (the figures drew clamped
/// colours without a word: the same review).
pub fn run(preset: &str, out: &Path, size: ImageSize, map_size: u64) -> Result<()> {
    // Read once: the memory check and every figure parse this text (`write_figures`).
    let source = snakeskin::preset::read_source(preset)?;
    let loaded = snakeskin::preset::parse(&source, &[])?;
    report_warnings(preset, &loaded);
    report_figure_warnings(preset, &loaded, &snakeskin::render::figures::figure_variants(&source)?);
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
    let renderer = Renderer::headless()?;
    ensure_folder(out)?;
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

/// The warnings a figure's variant of the preset has that the preset itself has not, each
/// once, with the figures whose overrides bring it.
fn report_figure_warnings(
    preset: &str,
    loaded: &snakeskin::preset::LoadedPreset,
    variants: &[snakeskin::preset::LoadedPreset],
) {
    let own = loaded.warnings(preset);
    let mut extra: Vec<(String, Vec<&str>)> = Vec::new();
    for (figure, variant) in snakeskin::render::figures::figure_list().iter().zip(variants) {
        for warning in variant.warnings(preset).into_iter().filter(|w| !own.contains(w)) {
            match extra.iter_mut().find(|(w, _)| *w == warning) {
                Some((_, files)) => files.push(figure.file),
                None => extra.push((warning, vec![figure.file])),
            }
        }
    }
    for (warning, files) in extra {
        eprintln!("{warning} (in {}, with its overrides)", files.join(", "));
    }
}
