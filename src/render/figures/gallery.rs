//! A gallery of the generator's vocabulary: every scale shape (height maps) and every
//! pattern kind (colour maps), each a small variation of one base preset, tiled into one PNG.
//! `snakeskin gallery -o docs/gallery.png` makes the README's figure; the tile order is
//! `VARIANTS`.

use rayon::prelude::*;

use crate::Error;
use crate::export::{FileGroup, encode_png};
use crate::graph::evaluate;
use crate::maps::{BuildOptions, MapKind, build_graph};
use crate::ops::Image;
use crate::preset::{PresetSource, parse};

/// The base every variant edits: a plain olive snake with a pale belly.
const BASE: &str = "seed = 5\n";
/// Tables the base adds when a variant does not write its own.
const BASE_COLOR: &str = "[color]\nbase = \"#6b7a3a\"\n";
const BASE_BELLY: &str = "[belly]\nwidth = 0.2\ncolor = \"#e8dcb8\"\n";

/// (label, map shown, overrides as TOML appended to `BASE`).
pub const VARIANTS: &[(&str, MapKind, &str)] = &[
    ("leaf scales", MapKind::Height, "[scales]\nshape = \"leaf\"\n"),
    ("diamond scales", MapKind::Height, "[scales]\nshape = \"diamond\"\n"),
    ("hexagon scales", MapKind::Height, "[scales]\nshape = \"hexagon\"\nsize = 0.95\n"),
    ("keeled leaf scales", MapKind::Height, "[scales]\nshape = \"leaf\"\nkeeled = true\n"),
    ("keeled diamond scales", MapKind::Height, "[scales]\nshape = \"diamond\"\nkeeled = true\n"),
    ("solid", MapKind::Color, "[[pattern]]\nkind = \"solid\"\ncolor = \"#3f6a2a\"\namount = 0.8\n"),
    (
        "stripes: vertebral + lateral",
        MapKind::Color,
        "[[pattern]]\nkind = \"stripes\"\ncolor = \"#e8d060\"\nposition = \"vertebral\"\nsize = 0.03\n\
         [[pattern]]\nkind = \"stripes\"\ncolor = \"#202018\"\nposition = \"lateral\"\nsize = 0.05\n",
    ),
    (
        "rings: coral triads",
        MapKind::Color,
        "[[pattern]]\nkind = \"rings\"\ncolor = \"#000000\"\namount = 3\nover_belly = true\n\
         colors = [\"#c8201a\", \"#f0d020\", \"#101010\", \"#f0d020\"]\nwidths = [0.4, 0.1, 0.4, 0.1]\n",
    ),
    (
        "spots: round, alternating",
        MapKind::Color,
        "[[pattern]]\nkind = \"spots\"\ncolor = \"#3a2a18\"\namount = 6\nsize = 0.04\noutline_size = 0.006\n\
         outline_color = \"#f0e8c0\"\n",
    ),
    (
        "spots: rings, checkered",
        MapKind::Color,
        "[[pattern]]\nkind = \"spots\"\ncolor = \"#2a1a10\"\namount = 6\nsize = 0.05\nshape = \"ring\"\n\
         arrangement = \"checkered\"\n",
    ),
    (
        "blotches: diamonds",
        MapKind::Color,
        "[color]\nbase = \"#a08a68\"\n[[pattern]]\nkind = \"blotches\"\nshape = \"diamond\"\ncolor = \"#5a4430\"\n\
         amount = 3\nsize = 0.2\nlength = 1.0\noutline_size = 0.01\noutline_color = \"#f0e8d8\"\n",
    ),
    (
        "blotches: saddles",
        MapKind::Color,
        "[color]\nbase = \"#c87838\"\n[[pattern]]\nkind = \"blotches\"\nshape = \"saddle\"\ncolor = \"#a02818\"\n\
         amount = 4\nsize = 0.28\nlength = 0.5\noutline_size = 0.008\n",
    ),
    (
        "blotches: rounded",
        MapKind::Color,
        "[color]\nbase = \"#d0b890\"\n[[pattern]]\nkind = \"blotches\"\nshape = \"round\"\ncolor = \"#403020\"\n\
         amount = 4\nsize = 0.14\nlength = 0.7\n",
    ),
    (
        "irregular: perlin",
        MapKind::Color,
        "[[pattern]]\nkind = \"irregular\"\ncolor = \"#2a3018\"\namount = 0.4\nsize = 0.12\n",
    ),
    (
        "irregular: cellular",
        MapKind::Color,
        "[[pattern]]\nkind = \"irregular\"\nnoise = \"cellular\"\ncolor = \"#403018\"\namount = 0.5\nsize = 0.15\n",
    ),
    (
        "scale-aligned spots",
        MapKind::Color,
        "[[pattern]]\nkind = \"spots\"\ncolor = \"#201810\"\namount = 8\nsize = 0.03\nscale_aligned = 1.0\n",
    ),
    ("checkered belly", MapKind::Color, "[belly]\nwidth = 0.3\ncolor = \"#e8dcb8\"\npattern = \"checkered\"\n"),
    // The vocabulary of colour that lives in scales, composite marks, belly marks and rows.
    (
        "per-scale tone, dark rims, speckle",
        MapKind::Color,
        "[color]\nbase = \"#8a7a50\"\nscale_tone = 0.15\nedge_tone = -0.6\nspeckle = 0.25\n",
    ),
    (
        "light tips, pale skin between scales",
        MapKind::Color,
        // Skin and belly as pale as this stack shows them under the map's per-scale
        // brightening (`visible::per_scale_gain`, the tips' 0.6 in it;
        // `no_figure_asks_for_a_colour_it_cannot_show`); its `[belly]` replaces `BASE_BELLY`,
        // whose width it repeats.
        "[scales]\nsize = 0.9\n[color]\nbase = \"#4a5a2a\"\ntip_tone = 0.6\nskin = \"#c8c1ac\"\n[belly]\nwidth = 0.2\n\
         color = \"#c8bd9e\"\n",
    ),
    (
        "composite: centre, dark edge, pale border",
        MapKind::Color,
        "[color]\nbase = \"#a89878\"\n[[pattern]]\nkind = \"blotches\"\ncolor = \"#7a5a3a\"\namount = 3\nsize = 0.12\n\
         length = 0.7\noutline_size = 0.008\noutline_color = \"#201810\"\nborder_color = \"#f0e4c8\"\n\
         border_size = 0.01\ncenter_color = \"#d0c098\"\ncenter_size = 0.45\n",
    ),
    (
        "staggered pairs over a flank series",
        MapKind::Color,
        "[color]\nbase = \"#9a8058\"\n[[pattern]]\nkind = \"blotches\"\nshape = \"saddle\"\ncolor = \"#3a2a1c\"\n\
         amount = 4\nsize = 0.07\nlength = 0.5\noffset = 0.09\narrangement = \"alternating\"\noutline_size = 0.006\n\
         outline_color = \"#f0e8d0\"\n[[pattern]]\nkind = \"blotches\"\ncolor = \"#2a1a10\"\namount = 4\nsize = 0.03\n\
         length = 0.3\noffset = 0.27\narrangement = \"aligned\"\nphase = 0.5\n",
    ),
    (
        "chevrons",
        MapKind::Color,
        "[color]\nbase = \"#b8985e\"\n[[pattern]]\nkind = \"blotches\"\nshape = \"chevron\"\ncolor = \"#22180f\"\n\
         amount = 4\nsize = 0.3\nlength = 0.8\nborder_color = \"#e0cc94\"\nborder_size = 0.01\n",
    ),
    (
        "hourglasses",
        MapKind::Color,
        "[color]\nbase = \"#b08a60\"\n[[pattern]]\nkind = \"blotches\"\nshape = \"hourglass\"\ncolor = \"#4a2a18\"\n\
         amount = 4\nsize = 0.28\nlength = 0.7\noutline_size = 0.006\n",
    ),
    (
        "zigzag",
        MapKind::Color,
        "[color]\nbase = \"#8a8478\"\n[[pattern]]\nkind = \"blotches\"\nshape = \"zigzag\"\ncolor = \"#1c1a18\"\n\
         amount = 5\nsize = 0.08\nlength = 0.6\n",
    ),
    (
        "stripes on rows 2–3 and the vertebral row",
        MapKind::Color,
        "[color]\nbase = \"#2a2e24\"\n[[pattern]]\nkind = \"stripes\"\ncolor = \"#d8d070\"\nrows = [9.5, 10]\n\
         [[pattern]]\nkind = \"stripes\"\ncolor = \"#c8c878\"\nrows = [2, 3]\n",
    ),
    (
        "rings in whole scales",
        MapKind::Color,
        "[scales]\nrows = 15\n[[pattern]]\nkind = \"rings\"\ncolor = \"#000000\"\namount = 1\nover_belly = true\n\
         colors = [\"#121110\", \"#e8c828\", \"#c42018\", \"#e8c828\"]\nwidths = [0.3, 0.06, 0.58, 0.06]\n\
         scale_aligned = 1.0\n",
    ),
    (
        "belly: scattered spots",
        MapKind::Color,
        "[belly]\nwidth = 0.3\ncolor = \"#e8dcb8\"\npattern = \"spots\"\npattern_amount = 0.6\n",
    ),
    (
        "belly: half-moons, colour up 2 rows",
        MapKind::Color,
        "[belly]\nwidth = 0.3\ncolor = \"#e89030\"\npattern = \"half_moons\"\npattern_amount = 0.8\nup_rows = 2\n",
    ),
    (
        "belly: median stripe",
        MapKind::Color,
        "[belly]\nwidth = 0.3\ncolor = \"#e8dcb8\"\npattern = \"median_stripe\"\npattern_amount = 0.3\n",
    ),
    (
        "enlarged vertebral row",
        MapKind::Height,
        "[scales]\nshape = \"hexagon\"\nsize = 0.95\nrows = 15\nvertebral_width = 2.2\n",
    ),
    (
        "keels off the lowest 3 rows",
        MapKind::Height,
        "[scales]\nshape = \"diamond\"\nkeeled = true\nkeel_height = 1.0\nsmooth_rows = 3\n",
    ),
];

/// Renders every variant at `tile` pixels and tiles them `columns` wide (at most one row of
/// every variant) into one PNG, after a memory check: a 64-column gallery of 2048-pixel
/// tiles took 4.8 GB and was not checked at all.
pub fn render(tile: usize, columns: usize) -> Result<Image, Error> {
    let columns = fitted_columns(columns);
    check_memory(tile, columns, false)?;
    let tiles: Vec<Image> = VARIANTS
        .par_iter()
        .map(|(label, map, overrides)| {
            let graph = variant_graph(label, overrides)?;
            let mut maps = evaluate(&graph, &[*map], tile, tile, &|_, _| {}).maps;
            let image = maps.remove(map).expect("requested map");
            Ok(if image.channels == 1 { gray_to_display(&image) } else { image })
        })
        .collect::<Result<_, Error>>()?;
    let (w, h) = canvas_size(tile, columns);
    // White background; colour tiles are linear, so white is 1.0.
    let mut sheet = Image { width: w, height: h, channels: 3, data: vec![1.0; w * h * 3] };
    for (i, t) in tiles.iter().enumerate() {
        let (x0, y0) = (GAP + (i % columns) * (tile + GAP), GAP + (i / columns) * (tile + GAP));
        for y in 0..tile {
            let dst = ((y0 + y) * w + x0) * 3;
            sheet.data[dst..dst + tile * 3].copy_from_slice(&t.data[y * tile * 3..(y + 1) * tile * 3]);
        }
    }
    Ok(sheet)
}

/// A variant's graph: `BASE` with the variant's overrides, and the base's colour and belly
/// tables where the variant writes none of its own (the memory check's copy of this
/// wrote both always, so the variants with their own failed to parse and were left out).
fn variant_graph(label: &str, overrides: &str) -> Result<crate::graph::Graph, Error> {
    Ok(build_graph(&parse(&variant_source(label, overrides), &[])?.preset, BuildOptions::default()))
}

/// A variant's preset text (`variant_graph`).
fn variant_source(label: &str, overrides: &str) -> PresetSource {
    PresetSource {
        name: label.replace([' ', ':', ',', '+'], "_"),
        display: format!("gallery variant {label:?}"),
        text: format!(
            "{BASE}{}{}{overrides}",
            if overrides.contains("[color]") { "" } else { BASE_COLOR },
            if overrides.contains("[belly]") { "" } else { BASE_BELLY },
        ),
    }
}

/// No more columns than variants: the rest were empty canvas.
fn fitted_columns(columns: usize) -> usize {
    columns.clamp(1, VARIANTS.len())
}

/// Pixels between the gallery's tiles and round its edge.
const GAP: usize = 4;

/// The gallery's width and height in pixels: `columns` tiles with `GAP`s.
fn canvas_size(tile: usize, columns: usize) -> (usize, usize) {
    let (gap, columns) = (GAP, fitted_columns(columns));
    let rows = VARIANTS.len().div_ceil(columns);
    (columns * tile + (columns + 1) * gap, rows * tile + (rows + 1) * gap)
}

/// The gallery's peak against the available memory: every variant's finished tile (three
/// f32 channels), the canvas (f32, then its 8-bit copy and PNG), and the heaviest variant's
/// graph once per thread evaluating at a time; with `closeups`, the larger of that and the
/// close-ups' (`closeup_pngs`, made after the gallery: its PNG, at most the canvas' 8-bit
/// size, the heaviest close-up's graph at `CLOSEUP_MAP`² once per thread, each with its
/// crop, and the process' fixed overhead once). The close-ups were left out: `gallery
/// --tile 16 --closeups` peaked at 151 MiB against the 129 estimated (an independent
/// sweep). The variants and close-ups were counted as sets (`estimate_generate_bytes`:
/// quantised maps and the process' overhead per thread): the close-ups came to 2–3 times
/// the peak at 4–16 threads, and `--tile 16` alone, 14 MiB at its peak, was estimated at
/// 1985 MiB on 32 threads (two reviews).
pub fn check_memory(tile: usize, columns: usize, closeups: bool) -> Result<(), Error> {
    let (w, h) = canvas_size(tile, columns);
    let tiles = (VARIANTS.len() * tile * tile * 12) as u64;
    let canvas = (w * h * (12 + 3 + 3)) as u64;
    let mut heaviest = 0;
    for (label, map, overrides) in VARIANTS {
        let graph = variant_graph(label, overrides)?;
        heaviest = heaviest.max(crate::graph::estimate_peak_bytes(&graph, &[*map], tile, tile));
    }
    let graphs = heaviest.saturating_mul(rayon::current_num_threads().min(VARIANTS.len()) as u64);
    let mut peak = tiles + canvas + graphs + crate::memory::FIXED_OVERHEAD_BYTES;
    let mut what = format!("a gallery of {w}×{h} pixels ({} tiles of {tile}²)", VARIANTS.len());
    if closeups {
        let maps = [MapKind::Color, MapKind::Normal];
        let mut heaviest = 0;
        for (stem, _, text) in CLOSEUPS {
            let graph = build_graph(&parse(&closeup_source(stem, text), &[])?.preset, BuildOptions::default());
            heaviest = heaviest.max(crate::graph::estimate_peak_bytes(&graph, &maps, CLOSEUP_MAP, CLOSEUP_MAP));
        }
        let crop = (2 * CLOSEUP_CROP * CLOSEUP_CROP * 12) as u64;
        let threads = rayon::current_num_threads().min(CLOSEUPS.len()) as u64;
        let closeups = (heaviest + crop).saturating_mul(threads) + crate::memory::FIXED_OVERHEAD_BYTES;
        peak = peak.max((w * h * 3) as u64 + closeups);
        what = format!("{what} and {} close-ups of {CLOSEUP_MAP}² maps", CLOSEUPS.len());
    }
    crate::memory::MemoryCheck::against_available(peak).refuse_if_over(&what)
}

/// A one-channel map shown as gray: the linear value whose sRGB encoding is the value, so
/// the figure shows each value as its code (a 2.2 power stood in for the transfer function
/// and showed dark values up to 9 codes darker).
fn gray_to_display(image: &Image) -> Image {
    let data = image.data.iter().flat_map(|v| [crate::export::srgb::decode_f32(*v); 3]).collect();
    Image { width: image.width, height: image.height, channels: 3, data }
}

/// One close-up per capability of the skin vocabulary: (file stem, the crop's top-left corner
/// as a fraction of the map, preset text). Generated at `CLOSEUP_MAP` pixels; the crop is
/// `CLOSEUP_CROP` pixels square.
pub const CLOSEUPS: &[(&str, (f32, f32), &str)] = &[
    (
        "per-scale-colour",
        (0.25, 0.0),
        "seed = 4\n[scales]\nsize = 0.95\n[color]\nbase = \"#8a7a50\"\nscale_tone = 0.12\nscale_hue = 0.04\n\
         edge_tone = -0.5\ntip_tone = 0.35\nspeckle = 0.2\nskin = \"#d0c9b2\"\n[belly]\ncolor = \"#d0c7ae\"\n",
    ),
    (
        "composite-marks",
        (0.25, 0.0),
        "seed = 5\n[scales]\nshape = \"diamond\"\nkeeled = true\n[color]\nbase = \"#b08a60\"\n[[pattern]]\n\
         kind = \"blotches\"\nshape = \"hourglass\"\ncolor = \"#3a2418\"\namount = 2\nsize = 0.22\nlength = 0.6\n\
         border_color = \"#e8d090\"\nborder_size = 0.008\n[[pattern]]\nkind = \"blotches\"\ncolor = \"#7a5a3a\"\n\
         amount = 2\nsize = 0.06\nlength = 0.5\noffset = 0.2\narrangement = \"aligned\"\nphase = 0.5\n\
         outline_size = 0.006\noutline_color = \"#201810\"\ncenter_color = \"#e0d0b0\"\ncenter_size = 0.4\n",
    ),
    (
        "rings-in-whole-scales",
        (0.25, 0.0),
        "seed = 6\n[scales]\nrows = 15\n[color]\nbase = \"#c42018\"\n[[pattern]]\nkind = \"rings\"\ncolor = \"#000000\"\n\
         amount = 1\nover_belly = true\ncolors = [\"#121110\", \"#e8c828\", \"#c42018\", \"#e8c828\"]\n\
         widths = [0.3, 0.06, 0.58, 0.06]\nscale_aligned = 1.0\n",
    ),
    (
        "belly-marks",
        (0.75, 0.0),
        "seed = 7\n[color]\nbase = \"#3a4048\"\n[belly]\nwidth = 0.3\ncolor = \"#e89030\"\npattern = \"half_moons\"\n\
         pattern_amount = 0.8\nup_rows = 2\n",
    ),
    (
        "rows",
        (0.25, 0.0),
        "seed = 8\n[scales]\nshape = \"hexagon\"\nsize = 0.95\nrows = 15\nvertebral_width = 2.2\n[color]\n\
         base = \"#202020\"\n[[pattern]]\nkind = \"stripes\"\ncolor = \"#e8d040\"\nrows = [7.5, 8]\n",
    ),
    (
        "imbricate-geometry",
        (0.25, 0.0),
        "seed = 9\n[scales]\nshape = \"leaf\"\nkeeled = true\nkeel_height = 0.8\nsmooth_rows = 2\nimbrication = 0.8\n\
         [color]\nbase = \"#6b7a3a\"\n",
    ),
];

/// The size the close-ups are generated at, and the crop's side.
pub const CLOSEUP_MAP: usize = 1024;
pub const CLOSEUP_CROP: usize = 512;

/// The close-ups' file names, in `CLOSEUPS` order.
pub fn closeup_file_names() -> impl Iterator<Item = String> {
    CLOSEUPS.iter().map(|(stem, _, _)| closeup_file_name(stem))
}

/// A close-up's preset (`closeup_pngs`).
fn closeup_source(stem: &str, text: &str) -> PresetSource {
    PresetSource { name: stem.to_string(), display: format!("close-up {stem:?}"), text: text.to_string() }
}

fn closeup_file_name(stem: &str) -> String {
    format!("{stem}.png")
}

/// Each close-up as (file name, PNG bytes): colour crop left, normal crop right.
fn closeup_pngs() -> Result<Vec<(String, Vec<u8>)>, Error> {
    CLOSEUPS
        .par_iter()
        .map(|(stem, (u0, v0), text)| {
            let loaded = parse(&closeup_source(stem, text), &[])?;
            let graph = build_graph(&loaded.preset, BuildOptions::default());
            let maps = evaluate(&graph, &[MapKind::Color, MapKind::Normal], CLOSEUP_MAP, CLOSEUP_MAP, &|_, _| {}).maps;
            let (n, c) = (CLOSEUP_MAP, CLOSEUP_CROP);
            let (x0, y0) = ((u0 * n as f32) as usize, (v0 * n as f32) as usize);
            let mut out = Image::new(2 * c, c, 3);
            for (k, map) in [MapKind::Color, MapKind::Normal].iter().enumerate() {
                let img = &maps[map];
                for y in 0..c {
                    for x in 0..c {
                        let (sx, sy) = ((x0 + x) % n, (y0 + y) % n);
                        for ch in 0..3 {
                            // The normal map's [-1, 1] shown as its PNG stores it, (n + 1) / 2,
                            // as the linear value that sRGB encoding turns into that code.
                            let v = img.data[(sy * n + sx) * 3 + ch];
                            let v = if *map == MapKind::Normal {
                                crate::export::srgb::decode_f32((v + 1.0) * 0.5)
                            } else {
                                v
                            };
                            out.data[(y * 2 * c + k * c + x) * 3 + ch] = v;
                        }
                    }
                }
            }
            Ok((closeup_file_name(stem), encode_png(MapKind::Color, &out)?))
        })
        .collect()
}

/// Renders the gallery PNG to `path`, and with `closeups` a folder, the close-ups into it;
/// they appear together or not at all (`FileGroup`: a close-up that failed left the gallery
/// and some close-ups written). Returns the paths, the gallery first.
pub fn write(
    path: &std::path::Path,
    tile: usize,
    columns: usize,
    closeups: Option<&std::path::Path>,
) -> Result<Vec<std::path::PathBuf>, Error> {
    if closeups.is_some() {
        check_memory(tile, columns, true)?;
    }
    let mut group = FileGroup::new();
    group.stage(path, encode_png(MapKind::Color, &render(tile, columns)?)?)?;
    if let Some(dir) = closeups {
        for (name, png) in closeup_pngs()? {
            group.stage(&dir.join(name), png)?;
        }
    }
    Ok(group.commit()?)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A one-channel tile shows each value as its own code: v / 255 encodes back to v (a 2.2
    /// power in its place was 9 codes off near black).
    #[test]
    fn a_gray_tile_shows_each_value_as_its_code() {
        let data = (0..=255).map(|v| v as f32 / 255.0).collect();
        let gray = gray_to_display(&Image { width: 256, height: 1, channels: 1, data });
        for (v, rgb) in gray.data.chunks(3).enumerate() {
            assert!(rgb.iter().all(|c| crate::export::linear_to_srgb8(*c) as usize == v), "{v}: {rgb:?}");
        }
    }

    /// The figures show what their presets say: no colour key of a variant or a close-up is
    /// brighter than the stack shows with the map's headroom (`preset::visible`), where it
    /// would be clamped without a word (the figures print no warnings).
    #[test]
    fn no_figure_asks_for_a_colour_it_cannot_show() {
        let sources = VARIANTS.iter().map(|(label, _, overrides)| variant_source(label, overrides));
        let sources = sources.chain(CLOSEUPS.iter().map(|(stem, _, text)| closeup_source(stem, text)));
        let mut clamped = Vec::new();
        for source in sources {
            let loaded = parse(&source, &[]).expect("the figures' presets parse");
            for c in &loaded.clamped_colours {
                clamped.push(format!("{}: {} = {} shown as {}", source.display, c.key, c.requested, c.clamped_to));
            }
        }
        assert!(clamped.is_empty(), "{}", clamped.join("\n"));
    }
}
