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
/// overrides bring, once a key with the figures they concern (the figures drew clamped
/// colours without a word: the same review).
pub fn run(preset: &str, out: &Path, size: ImageSize, map_size: u64) -> Result<()> {
    // Read once: the memory check and every figure's variant are parsed from this text.
    let source = snakeskin::preset::read_source(preset)?;
    let loaded = snakeskin::preset::parse(&source, &[])?;
    report_warnings(preset, &loaded);
    let variants = snakeskin::render::figures::figure_variants(&source)?;
    report_figure_warnings(preset, &loaded, &variants);
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
        &variants,
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

/// A warning's key, its line in the preset file, and what it says.
type KeyedWarning = (String, Option<usize>, String);

/// What a figure's variant of the preset warns of that the preset itself does not, one line
/// per key (its line in the file) with the figures whose overrides bring it: clamped
/// colours and the keys warned of. Matched by key, not by text: each figure's absorption
/// gives its own limit, and the text once per figure made 6 to 58 lines a built-in preset
/// (an independent review of the first cut).
fn report_figure_warnings(
    preset: &str,
    loaded: &snakeskin::preset::LoadedPreset,
    variants: &[snakeskin::preset::LoadedPreset],
) {
    let keys = |l: &snakeskin::preset::LoadedPreset| -> Vec<KeyedWarning> {
        let clamped = l.clamped_colours.iter().map(|c| {
            let what = format!("{} = \"{}\" is drawn clamped to what the figure's stack can show", c.key, c.requested);
            (c.key.clone(), c.line, what)
        });
        let warned = l.warned.iter().map(|p| (p.key.clone(), p.line, format!("{} = {}", p.key, p.message)));
        clamped.chain(warned).collect()
    };
    let own: Vec<String> = keys(loaded).into_iter().map(|(key, _, _)| key).collect();
    let mut extra: Vec<(KeyedWarning, Vec<&str>)> = Vec::new();
    for (figure, variant) in snakeskin::render::figures::figure_list().iter().zip(variants) {
        for item in keys(variant).into_iter().filter(|(key, _, _)| !own.contains(key)) {
            match extra.iter_mut().find(|((key, _, _), _)| *key == item.0) {
                Some((_, files)) => files.push(figure.file),
                None => extra.push((item, vec![figure.file])),
            }
        }
    }
    for ((_, line, what), files) in extra {
        let line = line.map(|l| format!(":{l}")).unwrap_or_default();
        eprintln!(
            "warning: {preset}{line}: {what} in {} (the figures' own optics, not the preset's)",
            files.join(", ")
        );
    }
}
