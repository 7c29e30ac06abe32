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
/// Warnings: `report_figure_warnings`.
pub fn run(preset: &str, out: &Path, size: ImageSize, map_size: u64) -> Result<()> {
    // Read once: the memory check and every figure's variant are parsed from this text.
    let source = snakeskin::preset::read_source(preset)?;
    let loaded = snakeskin::preset::parse(&source, &[])?;
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

/// What a clamped colour's warning says of it, in the preset and in a figure alike.
fn clamped_what(c: &snakeskin::preset::visible::ClampedColour) -> String {
    format!("{} = \"{}\" is drawn clamped to what the figure's stack can show", c.key, c.requested)
}

/// What a warned key's warning says of it.
fn warned_what(p: &snakeskin::preset::LocatedProblem) -> String {
    format!("{} = {}", p.key, p.message)
}

/// The warnings of a preset or of a figure's variant of it, keyed: clamped colours and the
/// keys warned of.
fn keyed_warnings(l: &snakeskin::preset::LoadedPreset) -> Vec<KeyedWarning> {
    let clamped = l.clamped_colours.iter().map(|c| (c.key.clone(), c.line, clamped_what(c)));
    let warned = l.warned.iter().map(|p| (p.key.clone(), p.line, warned_what(p)));
    clamped.chain(warned).collect()
}

/// The preset's own warnings that some figure draws, as `preview` prints them; then what
/// only a figure's overrides bring, one line per key and text with the figures it concerns
/// (the figures drew clamped colours without a word: a hostile-input review). A warning no
/// figure draws is left out: every figure sets its own film thickness, so the preset's
/// thickness was warned of though no figure showed it. Matched by key and text: by key
/// alone, a line quoted the first figure's value for figures that drew others (900 nm for
/// the 200, 400 and 600 nm figures: a sweep); each clamped colour's text is the same in
/// every figure, so a built-in preset's 6 to 58 lines (each figure's own limit, an
/// independent review of the first cut) stay one a key.
fn report_figure_warnings(
    preset: &str,
    loaded: &snakeskin::preset::LoadedPreset,
    variants: &[snakeskin::preset::LoadedPreset],
) {
    let drawn: Vec<Vec<KeyedWarning>> = variants.iter().map(keyed_warnings).collect();
    let in_a_figure = |key: &str, what: &str| drawn.iter().flatten().any(|(k, _, w)| k == key && w == what);
    let mut shown = loaded.clone();
    shown.clamped_colours.retain(|c| in_a_figure(&c.key, &clamped_what(c)));
    shown.warned.retain(|p| in_a_figure(&p.key, &warned_what(p)));
    report_warnings(preset, &shown);
    let own = keyed_warnings(&shown);
    let mut extra: Vec<(KeyedWarning, Vec<&str>)> = Vec::new();
    for (figure, warnings) in snakeskin::render::figures::figure_list().iter().zip(drawn) {
        let not_own = |(key, _, what): &KeyedWarning| !own.iter().any(|(k, _, w)| k == key && w == what);
        for item in warnings.into_iter().filter(not_own) {
            match extra.iter_mut().find(|((key, _, what), _)| *key == item.0 && *what == item.2) {
                Some((_, files)) => files.push(figure.file),
                None => extra.push((item, vec![figure.file])),
            }
        }
    }
    for ((_, line, what), files) in extra {
        // Placed and on one line as the preset's own warnings are (`preset::place`): a
        // control character in the path was sent raw to the terminal (a sweep).
        let place = snakeskin::preset::place(preset, line, false, snakeskin::preset::SET_FLAG);
        let what = snakeskin::toml_text::one_line(&what);
        eprintln!("warning: {place}: {what} in {} (the figures' own optics, not the preset's)", files.join(", "));
    }
}
