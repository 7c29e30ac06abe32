//! The generator's vocabulary: every scale shape and pattern kind generates something
//! distinct and seamless, and a preset shows the same skin at any resolution.

mod common;

use common::PATTERNED;
use snakeskin::graph::evaluate;
use snakeskin::maps::{BuildOptions, MapKind, build_graph};
use snakeskin::ops::{Image, filters};
use snakeskin::preset::{PresetSource, parse, read_source};
use snakeskin::render::figures::gallery::VARIANTS;

fn maps_of(text: &str, maps: &[MapKind], size: usize) -> std::collections::BTreeMap<MapKind, Image> {
    let source = PresetSource { name: "t".into(), display: "test preset".into(), text: text.into() };
    let loaded = parse(&source, &[]).unwrap_or_else(|e| panic!("{e}\n{text}"));
    let graph = build_graph(&loaded.preset, BuildOptions::default());
    evaluate(&graph, maps, size, size, &|_, _| {}).maps
}

fn mean_abs_diff(a: &Image, b: &Image) -> f64 {
    a.data.iter().zip(&b.data).map(|(x, y)| (x - y).abs() as f64).sum::<f64>() / a.data.len() as f64
}

fn box_down(img: &Image, factor: usize) -> Image {
    let (w, h, ch) = (img.width / factor, img.height / factor, img.channels);
    let mut out = Image::new(w, h, ch);
    for y in 0..h {
        for x in 0..w {
            for c in 0..ch {
                let mut sum = 0.0;
                for dy in 0..factor {
                    for dx in 0..factor {
                        sum += img.data[((y * factor + dy) * img.width + x * factor + dx) * ch + c];
                    }
                }
                out.data[(y * w + x) * ch + c] = sum / (factor * factor) as f32;
            }
        }
    }
    out
}

#[test]
fn every_scale_shape_makes_a_clearly_different_height_map() {
    // No jitter and one seed, so the shape is the only difference.
    let height = |shape: &str| {
        let text = format!("seed = 3\n[scales]\nshape = \"{shape}\"\njitter = 0.0\n");
        maps_of(&text, &[MapKind::Height], 192).remove(&MapKind::Height).unwrap()
    };
    let shapes = ["leaf", "diamond", "hexagon"];
    let maps: Vec<Image> = shapes.iter().map(|s| height(s)).collect();
    for i in 0..3 {
        for j in i + 1..3 {
            let d = mean_abs_diff(&maps[i], &maps[j]);
            // 0.03 of the height range is ~2000 16-bit levels on average over the image.
            assert!(d > 0.03, "{} and {} height maps differ by only {d}", shapes[i], shapes[j]);
        }
    }
    // Keels change the surface too.
    let keeled = maps_of("seed = 3\n[scales]\njitter = 0.0\nkeeled = true\n", &[MapKind::Height], 192);
    assert!(mean_abs_diff(&keeled[&MapKind::Height], &maps[0]) > 0.005);
}

#[test]
fn every_pattern_kind_generates_and_tiles() {
    let base = maps_of("seed = 5\n", &[MapKind::Color], 128).remove(&MapKind::Color).unwrap();
    let mut kinds_seen = std::collections::BTreeSet::new();
    for (label, map, overrides) in VARIANTS {
        let text = format!("seed = 5\n{overrides}");
        let maps = maps_of(&text, &MapKind::ALL, 128);
        for (m, img) in &maps {
            assert!(img.data.iter().all(|v| v.is_finite()), "{label} {m}");
        }
        if *map == MapKind::Color {
            // At least 1 % of the pixels visibly changed (by over 0.05 in some channel).
            let changed = maps[&MapKind::Color]
                .data
                .chunks(3)
                .zip(base.data.chunks(3))
                .filter(|(a, b)| a.iter().zip(*b).any(|(x, y)| (x - y).abs() > 0.05))
                .count();
            let fraction = changed as f64 / base.pixel_count() as f64;
            assert!(fraction > 0.01, "{label}: only {fraction} of the colour map changed");
            for line in overrides.lines().filter(|l| l.starts_with("kind = ")) {
                kinds_seen.insert(line.to_string());
            }
        }
    }
    for kind in ["solid", "stripes", "rings", "spots", "blotches", "irregular"] {
        assert!(kinds_seen.contains(&format!("kind = \"{kind}\"")), "the gallery lacks {kind}");
    }
}

#[test]
fn a_preset_shows_the_same_skin_at_any_resolution() {
    // 256² against 1024² box-downsampled to 256², both blurred by 1.5 px (which removes the
    // detail only the larger map can hold). Tolerances: 0.01 of the range (2.5 8-bit levels)
    // for maps in [0, 1]; 0.02 for the normal map, whose range is [-1, 1] and whose
    // downsampled normals average slopes that the 256² map never resolved.
    let blur = |img: &Image| filters::blur(std::borrow::Cow::Borrowed(img), 1.5 / 256.0, true);
    for spec in ["erythrolamprus-miliaris", PATTERNED] {
        let loaded = parse(&read_source(spec).unwrap(), &[]).unwrap();
        if spec == PATTERNED {
            assert!(snakeskin::maps::has_film(&loaded.preset), "the film's seed control needs a film");
        }
        let graph = build_graph(&loaded.preset, BuildOptions::default());
        let small = evaluate(&graph, &MapKind::ALL, 256, 256, &|_, _| {}).maps;
        let large = evaluate(&graph, &MapKind::ALL, 1024, 1024, &|_, _| {}).maps;
        let reseeded = parse(&read_source(spec).unwrap(), &[("seed".into(), "99".into())]).unwrap();
        let other =
            evaluate(&build_graph(&reseeded.preset, BuildOptions::default()), &MapKind::ALL, 256, 256, &|_, _| {}).maps;
        for map in MapKind::ALL {
            let d = mean_abs_diff(&blur(&small[&map]), &blur(&box_down(&large[&map], 4)));
            let tolerance = if map == MapKind::Normal { 0.02 } else { 0.01 };
            assert!(d <= tolerance, "{spec} {map}: 256² and 1024²↓ differ by {d}");
            // Without a film the thickness map is constant 0 at any seed (`maps::has_film`).
            let seeded = match map {
                MapKind::Height | MapKind::Roughness => true,
                MapKind::Iridescence => snakeskin::maps::has_film(&loaded.preset),
                _ => false,
            };
            if seeded {
                // The comparison can fail: another seed's skin is further away than the tolerance.
                let other_d = mean_abs_diff(&blur(&small[&map]), &blur(&other[&map]));
                assert!(other_d > tolerance, "{spec} {map}: a different seed differs by only {other_d}");
            }
        }
    }
}
