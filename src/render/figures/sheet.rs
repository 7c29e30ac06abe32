//! `snakeskin sheet`: the species library at a glance. One cell per built-in preset: its
//! colour map beside a preview render, under a label with the scientific name, common name
//! and pattern category. Labels use the public-domain 8×8 bitmap font of the `font8x8` crate,
//! drawn at 2×, so the sheet needs no system fonts.

use std::path::{Path, PathBuf};

use font8x8::UnicodeFonts;
use image::{Rgb, RgbImage, imageops};

use crate::Error;
use crate::graph::evaluate;
use crate::maps::{BuildOptions, Layout, MapKind, body_plan, build_graph};
use crate::optics::lut::Lut;
use crate::preset::{LoadedPreset, library};
use crate::render::engine::film::GpuFilmMethod;
use crate::render::engine::material::MaterialMaps;
use crate::render::engine::prepare::DrawMemory;
use crate::render::engine::renderer::{FrameSettings, Renderer, frame_bytes};
use crate::render::engine::scene::{Camera, LayerOptics};

const LABEL_SCALE: u32 = 2;
/// From one label line's top to the next's (its 16 pixels of glyphs and 4 between).
const LINE_PITCH: u32 = 8 * LABEL_SCALE + 4;
const BACKGROUND: Rgb<u8> = Rgb([24, 24, 26]);
const INK: Rgb<u8> = Rgb([235, 235, 230]);
const MUTED: Rgb<u8> = Rgb([170, 170, 160]);

/// Sheet layout: tile size (the colour map is tile × tile, the render 2·tile × tile),
/// cells per row, and the resolution the maps are generated at.
#[derive(Debug, Clone, Copy)]
pub struct SheetOptions {
    pub tile: u32,
    pub columns: u32,
    pub map_size: usize,
    /// Body sheet: also a close-up render of each species' head and of its tail.
    pub closeups: bool,
}

/// A sheet checked and laid out before anything is rendered (`plan_sheet`): its species,
/// loaded, and where everything goes, on a canvas the memory available can hold. Parse,
/// then run: a wrong species name or a sheet too large is refused before a renderer is
/// made (without a GPU, the GPU's error came first).
pub struct SheetPlan {
    options: SheetOptions,
    layout: Layout,
    species: Vec<(&'static str, LoadedPreset)>,
    columns: u32,
    /// One species' cell, and the whole canvas.
    cell: (u32, u32),
    canvas: (u32, u32),
    /// The label's height (the most lines a species' label wraps to); the body layout's
    /// longest strip and its renders' size.
    label_h: u32,
    strip_w: u32,
    render: (u32, u32),
}

/// Checks a sheet's options and lays it out (`SheetPlan`): the species named in `species`
/// (all when empty) must be built in, `closeups` needs the body layout, and the canvas
/// with the heaviest species' maps must fit in the memory available.
pub fn plan_sheet(options: SheetOptions, layout: Layout, species: &[String]) -> Result<SheetPlan, Error> {
    if options.closeups && layout != Layout::Body {
        return Err(Error::InvalidOption {
            option: "--closeups",
            reason: "it draws each body's head and tail, so it needs --layout body".into(),
        });
    }
    let species: Vec<(&'static str, LoadedPreset)> = chosen_species(species)?
        .into_iter()
        .map(|(name, _)| Ok((name, crate::preset::load(name, &[], None)?)))
        .collect::<Result<_, Error>>()?;
    // No more columns than species: the rest were empty cells of canvas.
    let columns = options.columns.clamp(1, (species.len() as u32).max(1));
    let rows = (species.len() as u32).div_ceil(columns);
    let tile = options.tile;
    let cell_w = |strip_w: u32, render_w: u32, closeups_w: u32| match layout {
        Layout::Tile => 3 * tile,
        Layout::Body => strip_w + render_w + closeups_w + 12,
    };
    // Every label as many lines high as the longest wraps to in its cell (they were cut
    // to one line each: "Philodrya.." for both Philodryas, no category, at --tile 64).
    let lines = |cell_w: u32| {
        species.iter().map(|(name, loaded)| label_lines(name, loaded, layout, cell_w).len() as u32).max().unwrap_or(0)
    };
    let (cell, label_h, strip_w, render) = match layout {
        Layout::Tile => {
            let label_h = LINE_PITCH * lines(cell_w(0, 0, 0)) + 6;
            ((3 * tile, tile + label_h), label_h, 0, (2 * tile, tile))
        }
        Layout::Body => {
            // `tile` is the strip's height, one circumference; the longest body sets the
            // strips' length, all at one scale.
            let strip_w = species.iter().map(|(_, l)| Layout::Body.height(&l.preset, tile as usize)).max().unwrap_or(0);
            let strip_w = strip_w.max(tile as usize) as u32;
            let (render_w, render_h) = (4 * tile, 2 * tile);
            let closeups_w = if options.closeups { 2 * (render_h + 6) } else { 0 };
            let width = cell_w(strip_w, render_w, closeups_w);
            let label_h = LINE_PITCH * lines(width) + 8;
            ((width, label_h + render_h + 8), label_h, strip_w, (render_w, render_h))
        }
    };
    let canvas = (cell.0 * columns, cell.1 * rows);
    let plan = SheetPlan { options, layout, species, columns, cell, canvas, label_h, strip_w, render };
    check_sheet_memory(&plan)?;
    Ok(plan)
}

impl SheetPlan {
    /// The map size of one species' maps: square in the tile layout, its atlas' in the body's.
    fn map_size(&self, loaded: &LoadedPreset) -> (usize, usize) {
        match self.layout {
            Layout::Tile => (self.options.map_size, self.options.map_size),
            Layout::Body => crate::render::engine::prepare::map_dimensions(loaded, self.options.map_size, Layout::Body),
        }
    }
}

/// Close-up cameras on a body atlas's snake (`BodyShape::for_atlas`): the head seen from
/// above and the side, and the last part of the tail.
pub fn head_and_tail_cameras(plan: &crate::ops::body::BodyPlan) -> [Camera; 2] {
    let shape = crate::render::engine::mesh::BodyShape::for_atlas(plan);
    let lift = glam::Vec3::Y * shape.radius * shape.flatten;
    let head = shape.centre(0.5 * plan.head_end.max(0.01)) + lift;
    let tail = shape.centre(1.0 - 0.5 * (1.0 - plan.vent)) + lift;
    let distance = 16.0 * shape.radius;
    [
        Camera { target: head, yaw_deg: -60.0, pitch_deg: 45.0, distance, fov_y_deg: 35.0 },
        Camera { target: tail, yaw_deg: 30.0, pitch_deg: 45.0, distance: 2.2 * distance, fov_y_deg: 35.0 },
    ]
}

/// The camera for sheet renders: the mid-body, close enough to read the pattern.
pub fn sheet_camera() -> Camera {
    Camera { target: glam::Vec3::new(-0.3, 0.08, 0.15), yaw_deg: 5.0, pitch_deg: 38.0, distance: 1.25, fov_y_deg: 35.0 }
}

/// A species' label as the lines a cell `cell_w` wide draws: the scientific name (in ink),
/// the common name and category, and for a body the counts its atlas was drawn with, each
/// wrapped at its spaces (`wrapped`).
fn label_lines(name: &str, loaded: &LoadedPreset, layout: Layout, cell_w: u32) -> Vec<(String, Rgb<u8>)> {
    let preset = &loaded.preset;
    let category = preset.category.map(|c| format!(" ({})", c.name())).unwrap_or_default();
    let mut texts = vec![
        (preset.species.clone().unwrap_or_else(|| name.to_string()), INK),
        (format!("{}{}", preset.common_name.as_deref().unwrap_or(""), category), MUTED),
    ];
    if layout == Layout::Body {
        let counts = counts_line(name, preset, &crate::export::body_counts(preset, &body_plan(preset)));
        texts.push((counts, MUTED));
    }
    texts
        .into_iter()
        .flat_map(|(text, colour)| wrapped(&text, cell_w).into_iter().map(move |line| (line, colour)))
        .collect()
}

/// `text` in lines a cell `cell_w` wide holds, broken at spaces; a word longer than a line
/// is `clipped`. An empty text is one empty line (the label keeps its place).
fn wrapped(text: &str, cell_w: u32) -> Vec<String> {
    let fits = line_chars(cell_w);
    let mut lines: Vec<String> = Vec::new();
    let mut line = String::new();
    for word in text.split_whitespace() {
        let word = clipped(word, cell_w);
        if !line.is_empty() && line.chars().count() + 1 + word.chars().count() > fits {
            lines.push(std::mem::take(&mut line));
        }
        if !line.is_empty() {
            line.push(' ');
        }
        line.push_str(&word);
    }
    lines.push(line);
    lines
}

/// How many characters a label line of a cell `cell_w` wide holds (6 pixels each side).
fn line_chars(cell_w: u32) -> usize {
    (cell_w as usize).saturating_sub(12) / (8 * LABEL_SCALE as usize)
}

/// `text` as a label line of a cell `cell_w` wide holds it: whole, or cut with ".." where
/// it was cut mid-word without a sign ("Crotalus at", "Western dia" at `--tile 64`).
fn clipped(text: &str, cell_w: u32) -> String {
    let fits = line_chars(cell_w);
    if text.chars().count() <= fits || fits < 3 {
        return text.chars().take(fits).collect();
    }
    let kept: String = text.chars().take(fits.saturating_sub(2)).collect();
    format!("{}..", kept.trim_end())
}

/// Draws a label's lines from the cell's top-left corner `(x0, y0)`, one `LINE_PITCH` apart.
fn draw_label(sheet: &mut RgbImage, (x0, y0): (u32, u32), lines: &[(String, Rgb<u8>)]) {
    for (k, (line, colour)) in lines.iter().enumerate() {
        draw_text(sheet, x0 + 6, y0 + 4 + k as u32 * LINE_PITCH, line, *colour);
    }
}

/// Draws `text` with its top-left corner at (x, y); characters outside the font are skipped.
pub fn draw_text(image: &mut RgbImage, x: u32, y: u32, text: &str, color: Rgb<u8>) {
    let mut pen = x;
    for ch in text.chars() {
        let glyph = font8x8::BASIC_FONTS.get(ch).or_else(|| font8x8::LATIN_FONTS.get(ch));
        if let Some(rows) = glyph {
            for (row, bits) in rows.iter().enumerate() {
                for col in 0..8 {
                    if bits & (1 << col) == 0 {
                        continue;
                    }
                    for dy in 0..LABEL_SCALE {
                        for dx in 0..LABEL_SCALE {
                            let (px, py) = (pen + col * LABEL_SCALE + dx, y + row as u32 * LABEL_SCALE + dy);
                            if px < image.width() && py < image.height() {
                                image.put_pixel(px, py, color);
                            }
                        }
                    }
                }
            }
        }
        pen += 8 * LABEL_SCALE;
    }
}

/// The linear colour map as an sRGB image, resized to `tile` × `tile` (a triangle filter on
/// the sRGB codes).
fn colour_tile(maps: &std::collections::BTreeMap<MapKind, crate::ops::Image>, tile: u32) -> RgbImage {
    imageops::resize(&colour_image(maps), tile, tile, imageops::FilterType::Triangle)
}

/// The film LUT for `optics`, baked once per distinct stack (most species share the thesis'
/// indices).
fn lut_for(luts: &mut Vec<(crate::optics::film::Stack, Lut)>, optics: LayerOptics) -> &Lut {
    let index = match luts.iter().position(|(s, _)| *s == optics.stack) {
        Some(k) => k,
        None => {
            luts.push((optics.stack, Lut::bake_default(optics.stack)));
            luts.len() - 1
        }
    };
    &luts[index].1
}

/// Renders the contact sheet `plan` lays out (the tile's, or the whole bodies'); `progress(done,
/// total)` after each species.
pub fn render_sheet(renderer: &Renderer, plan: &SheetPlan, progress: &dyn Fn(usize, usize)) -> Result<RgbImage, Error> {
    match plan.layout {
        Layout::Tile => render_tile_sheet(renderer, plan, progress),
        Layout::Body => render_body_sheet(renderer, plan, progress),
    }
}

/// Per species its colour map tile beside a render of the mid-body, under its label.
fn render_tile_sheet(
    renderer: &Renderer,
    plan: &SheetPlan,
    progress: &dyn Fn(usize, usize),
) -> Result<RgbImage, Error> {
    let (options, tile, columns) = (plan.options, plan.options.tile, plan.columns);
    let (cell_w, cell_h) = plan.cell;
    let presets = &plan.species;
    let mut sheet = RgbImage::from_pixel(plan.canvas.0, plan.canvas.1, BACKGROUND);
    let mut luts: Vec<(crate::optics::film::Stack, Lut)> = Vec::new();
    for (i, (name, loaded)) in presets.iter().enumerate() {
        progress(i, presets.len());
        crate::memory::release_freed();
        let graph = build_graph(&loaded.preset, BuildOptions::default());
        let evaluation = evaluate(&graph, &MapKind::ALL, options.map_size, options.map_size, &|_, _| {});
        let maps =
            MaterialMaps::from_maps(&evaluation.maps).map_err(|e| Error::Internal(format!("the sheet's maps: {e}")))?;
        // Only the colour tile is needed from the f32 maps: not held through the upload.
        let colour = colour_tile(&evaluation.maps, tile);
        drop(evaluation);
        let optics = LayerOptics::from_preset(&loaded.preset);
        let material = renderer.material(&maps, optics, lut_for(&mut luts, optics), 1)?;
        drop(maps);
        let settings = FrameSettings {
            camera: sheet_camera(),
            method: GpuFilmMethod::Lut,
            ground: false,
            ..FrameSettings::default()
        };
        let render = renderer.render_image(&settings, &material, plan.render.0, plan.render.1)?;
        let render = image::DynamicImage::ImageRgba8(render).into_rgb8();

        let (x0, y0) = ((i as u32 % columns) * cell_w, (i as u32 / columns) * cell_h);
        draw_label(&mut sheet, (x0, y0), &label_lines(name, loaded, Layout::Tile, cell_w));
        imageops::replace(&mut sheet, &colour, (x0) as i64, (y0 + plan.label_h) as i64);
        imageops::replace(&mut sheet, &render, (x0 + tile) as i64, (y0 + plan.label_h) as i64);
    }
    progress(presets.len(), presets.len());
    Ok(sheet)
}

/// The body sheet's line of counts for the built-in `name`: its plates, a count its preset
/// does not give called the default (the sheet labelled `crotalus-atrox`, whose sources then gave
/// no count, "200 ventrals, 60 subcaudals", as if they were the species': a walkthrough),
/// its counted marks and its tail bands.
fn counts_line(name: &str, preset: &crate::preset::Preset, counts: &crate::export::Counts) -> String {
    let lines = library::get(name).map(crate::toml_text::KeyLines::new);
    let default = |key: &str| lines.as_ref().is_some_and(|l| l.line(key).is_none());
    let plates = match (counts.ventrals, counts.subcaudals) {
        (Some(ventrals), Some(subcaudals)) => match (default("body.ventrals"), default("body.subcaudals")) {
            (true, true) => format!("{ventrals} ventrals, {subcaudals} subcaudals (defaults)"),
            (v, s) => {
                let said = |d: bool| if d { " (default)" } else { "" };
                format!("{ventrals} ventrals{}, {subcaudals} subcaudals{}", said(v), said(s))
            }
        },
        _ => "no ventral plates".into(),
    };
    let series = preset.pattern.iter().find(|l| l.series_count().is_some()).map_or("dorsal marks", series_words);
    let marks = counts.dorsal_marks.map(|n| format!(", {n} {series}")).unwrap_or_default();
    let bands = counts.tail_bands.map(|n| format!(", {n} tail bands")).unwrap_or_default();
    format!("{plates}{marks}{bands}")
}

/// What a counted series' marks are, for the sheet's counts: the manifest's `dorsal_marks`
/// counts the first counted layer whatever it draws, and the sheet called a green tree
/// python's white spots along each flank and a coral snake's rings "dorsal marks".
fn series_words(layer: &crate::preset::schema::PatternLayer) -> &'static str {
    use crate::preset::schema::PatternKind;
    match layer.kind {
        PatternKind::Rings if layer.colors.is_empty() => "rings",
        PatternKind::Rings => "repeats of its rings",
        // Above 0, two mirrored series, each counted (docs/presets.md, `offset`).
        _ if layer.offset > 0.0 => "marks a side",
        _ => "dorsal marks",
    }
}

/// The body sheet (`sheet --layout body`): per species its whole body atlas laid on its
/// side — snout at the left, tail tip at the right, the spine along the middle of the strip
/// and the belly at its edges — beside a render of the whole snake, under the label and a
/// line with the counts the atlas was drawn with. `options.tile` is the strip's height for
/// a body 12 circumferences long (longer bodies get longer strips, all at one scale);
/// `options.map_size` the atlas' width (its circumference) in pixels.
fn render_body_sheet(
    renderer: &Renderer,
    plan: &SheetPlan,
    progress: &dyn Fn(usize, usize),
) -> Result<RgbImage, Error> {
    let (options, columns, circumference) = (plan.options, plan.columns, plan.options.tile);
    let (cell_w, cell_h) = plan.cell;
    let (strip_w, label_h, (render_w, render_h)) = (plan.strip_w, plan.label_h, plan.render);
    let presets = &plan.species;
    let mut sheet = RgbImage::from_pixel(plan.canvas.0, plan.canvas.1, BACKGROUND);
    let mut luts: Vec<(crate::optics::film::Stack, Lut)> = Vec::new();
    let options_body = BuildOptions { layout: Layout::Body, ..BuildOptions::default() };
    for (i, (name, loaded)) in presets.iter().enumerate() {
        progress(i, presets.len());
        crate::memory::release_freed();
        let preset = &loaded.preset;
        let graph = build_graph(preset, options_body);
        let (width, height) = plan.map_size(loaded);
        let evaluation = evaluate(&graph, &MapKind::ALL, width, height, &|_, _| {});
        let mut maps =
            MaterialMaps::from_maps(&evaluation.maps).map_err(|e| Error::Internal(format!("the sheet's maps: {e}")))?;
        let body = body_plan(preset);
        maps.atlas = Some(body);
        let optics = LayerOptics::from_preset(preset);
        // The atlas on its side: rotate so v (snout → tail) runs left to right, scaled to
        // `circumference` pixels round the body and the body's length along. Made before the
        // upload, so that the f32 maps are not held through it nor beside the frame.
        let atlas = colour_image(&evaluation.maps);
        drop(evaluation);
        let strip = imageops::rotate270(&atlas);
        drop(atlas);
        let length_px = Layout::Body.height(preset, circumference as usize) as u32;
        let strip = imageops::resize(&strip, length_px, circumference, imageops::FilterType::Triangle);
        let material = renderer.material(&maps, optics, lut_for(&mut luts, optics), 1)?;
        drop(maps);
        let settings = FrameSettings {
            camera: Camera::framing(1),
            method: GpuFilmMethod::Lut,
            ground: false,
            ..FrameSettings::default()
        };
        let render = renderer.render_image(&settings, &material, render_w, render_h)?;
        let render = image::DynamicImage::ImageRgba8(render).into_rgb8();

        let (x0, y0) = ((i as u32 % columns) * cell_w, (i as u32 / columns) * cell_h);
        draw_label(&mut sheet, (x0, y0), &label_lines(name, loaded, Layout::Body, cell_w));
        let strip_y = y0 + label_h + (render_h - circumference) / 2;
        imageops::replace(&mut sheet, &strip, (x0 + 6) as i64, strip_y as i64);
        imageops::replace(&mut sheet, &render, (x0 + strip_w + 12) as i64, (y0 + label_h) as i64);
        if options.closeups {
            for (k, camera) in head_and_tail_cameras(&body).into_iter().enumerate() {
                let settings = FrameSettings { camera, ..settings };
                let close = renderer.render_image(&settings, &material, render_h, render_h)?;
                let close = image::DynamicImage::ImageRgba8(close).into_rgb8();
                let x = x0 + strip_w + 12 + render_w + 6 + k as u32 * (render_h + 6);
                imageops::replace(&mut sheet, &close, x as i64, (y0 + label_h) as i64);
            }
        }
    }
    progress(presets.len(), presets.len());
    Ok(sheet)
}

/// Refuses a sheet whose canvas (RGB bytes) and heaviest species (the largest estimate over
/// the sheet's presets, each graph weighed, not only its size: its maps, textures, colour
/// strip and frame, `prepare::DrawMemory`) would together need more memory than is
/// available, before a renderer or the canvas is made.
fn check_sheet_memory(plan: &SheetPlan) -> Result<(), Error> {
    let canvas = plan.canvas;
    // The canvas, and its PNG bytes at the end (at most its size).
    let canvas_bytes = canvas.0 as u64 * canvas.1 as u64 * 3 * 2;
    let layout = plan.layout;
    // The frame and its RGB copy (the close-ups' frames are smaller, and drawn after it).
    let frame_bytes = frame_bytes(plan.render.0, plan.render.1);
    // The largest maps of the sheet, which may have been drawn before any species.
    let largest = plan.species.iter().map(|(_, l)| plan.map_size(l)).max_by_key(|(w, h)| w * h).unwrap_or((0, 0));
    let heaviest = plan
        .species
        .iter()
        .map(|(_, l)| {
            let graph = build_graph(&l.preset, BuildOptions { layout, ..BuildOptions::default() });
            let (width, height) = plan.map_size(l);
            // The colour image (RGB), rotated, and scaled to its strip (the tile's square):
            // the resize's f32 RGBA pass is the source's width by the new height.
            let tile = plan.options.tile as u64;
            let (strip, source_width) = match layout {
                Layout::Tile => (tile * tile, width as u64),
                Layout::Body => (Layout::Body.height(&l.preset, tile as usize) as u64 * tile, height as u64),
            };
            let colour_bytes = (width * height) as u64 * 3 * 2 + source_width * tile * 16 + strip * 3;
            let memory = DrawMemory {
                held_bytes: canvas_bytes + colour_bytes,
                drawn_after: (plan.species.len() > 1).then_some(largest),
                ..DrawMemory::new(&graph, (width, height), frame_bytes)
            };
            (memory.estimate_bytes(), memory)
        })
        .max_by_key(|(bytes, _)| *bytes);
    let Some((_, memory)) = heaviest else {
        return Ok(());
    };
    memory.check(&format!("a contact sheet of {}×{} pixels, with the maps of its heaviest species", canvas.0, canvas.1))
}

/// The linear colour map as an sRGB image at full size.
fn colour_image(maps: &std::collections::BTreeMap<MapKind, crate::ops::Image>) -> RgbImage {
    let color = &maps[&MapKind::Color];
    RgbImage::from_fn(color.width as u32, color.height as u32, |x, y| {
        let i = (y as usize * color.width + x as usize) * color.channels;
        Rgb([0, 1, 2].map(|c| crate::export::linear_to_srgb8(color.data[i + c])))
    })
}

/// The built-in presets named in `species` (all of them when it is empty), in its order; a
/// name that is not built in is an error naming it, and the nearest built-in name.
fn chosen_species(species: &[String]) -> Result<Vec<(&'static str, &'static str)>, Error> {
    if species.is_empty() {
        return Ok(library::all().to_vec());
    }
    let chosen: Vec<(&'static str, &'static str)> = species
        .iter()
        .map(|name| {
            // `a, b` is two names: the space is the list's, not the name's.
            let name = name.trim();
            if name.is_empty() {
                return Err(Error::InvalidOption {
                    option: "--species",
                    reason: "an empty name in the list (a comma too many?)".into(),
                });
            }
            library::all().iter().find(|(n, _)| *n == name).copied().ok_or_else(|| {
                let hint = library::suggest(name).map(|n| format!("did you mean {n}? ")).unwrap_or_default();
                Error::InvalidOption {
                    option: "--species",
                    reason: format!("no built-in species {name:?}; {hint}`snakeskin presets list` shows them all"),
                }
            })
        })
        .collect::<Result<_, _>>()?;
    // A name twice drew two identical cells without a word: likely a slip for another name.
    for (k, (name, _)) in chosen.iter().enumerate() {
        if chosen[..k].iter().any(|(earlier, _)| earlier == name) {
            return Err(Error::InvalidOption {
                option: "--species",
                reason: format!("{name} is listed twice (a sheet shows each species once)"),
            });
        }
    }
    Ok(chosen)
}

/// Renders the sheet `plan` lays out and writes it as a PNG (atomically).
pub fn write_sheet(
    renderer: &Renderer,
    path: &Path,
    plan: &SheetPlan,
    progress: &dyn Fn(usize, usize),
) -> Result<PathBuf, Error> {
    super::write_rgb_png(path, &render_sheet(renderer, plan, progress)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A preset that gives its plate counts is labelled with them; one whose sources give
    /// none (`pantherophis-guttatus`: one text's counts, doubtful for the species and not
    /// used) is labelled with the defaults, called so.
    #[test]
    fn the_body_sheet_calls_default_counts_defaults() {
        let counts = |ventrals, subcaudals| crate::export::Counts {
            ventrals: Some(ventrals),
            subcaudals: Some(subcaudals),
            dorsal_marks: None,
            tail_bands: None,
        };
        let preset = |name: &str| crate::preset::load(name, &[], None).unwrap().preset;
        let line = |name: &str, counts| counts_line(name, &preset(name), &counts);
        assert_eq!(line("pantherophis-guttatus", counts(200, 60)), "200 ventrals, 60 subcaudals (defaults)");
        assert_eq!(line("boa-constrictor", counts(232, 48)), "232 ventrals, 48 subcaudals");
    }

    /// The counted series is named for what it draws: dorsal blotches, a series a side, rings
    /// (the sheet called a green tree python's flank spots and a coral snake's rings dorsal
    /// marks). The control: a dorsal series is still dorsal marks.
    #[test]
    fn the_body_sheet_names_a_series_for_what_it_draws() {
        for (name, words) in [
            ("crotalus-atrox", "dorsal marks"),
            ("morelia-viridis", "marks a side"),
            ("bungarus-fasciatus", "repeats of its rings"),
        ] {
            let preset = crate::preset::load(name, &[], None).unwrap().preset;
            let plan = crate::maps::body_plan(&preset);
            let line = counts_line(name, &preset, &crate::export::body_counts(&preset, &plan));
            assert!(line.contains(&format!(" {words}")), "{name}: {line}");
        }
    }

    /// At `--tile 64` (a cell 192 pixels wide, 11 characters a line) every label is whole,
    /// wrapped at its spaces within the cell (a word longer than a line cut, with ".."), and
    /// the cells as tall as the longest label:
    /// the two Philodryas were both "Philodrya..", with no category, a sweep. Negative
    /// control: at `--tile 256` every label is its two lines, as high as before.
    #[test]
    fn labels_wrap_whole_in_small_cells() {
        let species = ["philodryas-aestiva", "philodryas-olfersii", "crotalus-atrox"].map(String::from);
        let options = |tile| SheetOptions { tile, columns: 3, map_size: 64, closeups: false };
        let plan = plan_sheet(options(64), Layout::Tile, &species).unwrap();
        let mut most = 0;
        for (name, loaded) in &plan.species {
            let lines = label_lines(name, loaded, Layout::Tile, plan.cell.0);
            let text: Vec<&str> = lines.iter().map(|(line, _)| line.as_str()).collect();
            assert!(text.iter().all(|l| l.chars().count() <= 11), "{name}: {text:?}");
            let p = &loaded.preset;
            let whole = format!(
                "{} {} ({})",
                p.species.as_deref().unwrap(),
                p.common_name.as_deref().unwrap(),
                p.category.unwrap().name()
            );
            // Every word whole but one longer than a line ("Lichtenstein's"), cut with "..".
            let words: Vec<String> = whole.split_whitespace().map(|w| clipped(w, 192)).collect();
            assert_eq!(text.join(" "), words.join(" "));
            assert!(words.iter().filter(|w| w.ends_with("..")).all(|w| w.starts_with("Lichtenst")), "{words:?}");
            most = most.max(lines.len() as u32);
        }
        assert!(most > 2);
        assert_eq!(plan.label_h, LINE_PITCH * most + 6);
        assert_eq!(plan.cell.1, 64 + plan.label_h);
        let wide = plan_sheet(options(256), Layout::Tile, &species).unwrap();
        assert_eq!(wide.label_h, 2 * 8 * LABEL_SCALE + 14, "two lines, as high as before");
        for (name, loaded) in &wide.species {
            assert_eq!(label_lines(name, loaded, Layout::Tile, wide.cell.0).len(), 2);
        }
    }

    /// A label that does not fit its cell ends in "..", within the cell; one that fits is
    /// whole. A tile of 64 (a cell 192 wide) holds 11 characters of 16 pixels.
    #[test]
    fn a_label_too_long_for_its_cell_says_it_was_cut() {
        assert_eq!(clipped("Crotalus atrox", 192), "Crotalus..");
        assert_eq!(clipped("Natrix", 192), "Natrix");
        assert_eq!(clipped("Natrix natri", 192), "Natrix na..");
        assert_eq!(clipped("Boa", 12 + 2 * 16), "Bo");
        for text in ["Crotalus atrox", "Western diamond-backed rattlesnake (complex)"] {
            assert!(clipped(text, 192).chars().count() <= 11, "{text}");
        }
    }

    #[test]
    fn text_is_drawn_where_asked_and_clipped_at_the_edge() {
        let mut image = RgbImage::from_pixel(40, 20, BACKGROUND);
        draw_text(&mut image, 2, 2, "Ab", INK);
        let inked = image.pixels().filter(|p| **p == INK).count();
        assert!(inked > 20, "{inked} pixels inked");
        // Nothing left of x = 2 or above y = 2.
        for y in 0..20 {
            assert_ne!(*image.get_pixel(0, y), INK);
            assert_ne!(*image.get_pixel(1, y), INK);
        }
        // A label longer than the image is clipped, not a panic.
        draw_text(&mut image, 30, 10, "overflowing", INK);
    }

    /// `--species "a, b"` kept the space in the second name, and `a,` or `,` asked for a
    /// species named "".
    #[test]
    fn species_names_are_trimmed_and_an_empty_one_is_named() {
        let names = |list: &[&str]| chosen_species(&list.iter().map(|s| s.to_string()).collect::<Vec<_>>());
        let chosen = names(&["natrix-natrix", " vipera-berus"]).unwrap();
        assert_eq!(chosen.iter().map(|(n, _)| *n).collect::<Vec<_>>(), ["natrix-natrix", "vipera-berus"]);
        let error = names(&["natrix-natrix", ""]).unwrap_err().to_string();
        assert!(error.contains("an empty name in the list"), "{error}");
        let error = names(&["natrix"]).unwrap_err().to_string();
        assert!(error.contains("did you mean natrix-natrix?"), "{error}");
        let error = names(&["natrix-natrix", "vipera-berus", " natrix-natrix"]).unwrap_err().to_string();
        assert!(error.contains("natrix-natrix is listed twice"), "{error}");
    }

    /// One species on eight columns made a canvas of eight cells, seven empty.
    #[test]
    fn a_sheet_has_no_more_columns_than_species() {
        let options = SheetOptions { tile: 64, columns: 8, map_size: 64, closeups: false };
        for (species, columns) in [(vec!["natrix-natrix".to_string()], 1), (vec![], 8)] {
            let plan = plan_sheet(options, Layout::Tile, &species).unwrap();
            assert_eq!(plan.canvas.0, columns * plan.cell.0, "{species:?}");
        }
    }
}
