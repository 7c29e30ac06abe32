//! Quality properties of the maps themselves: seamless tiling and value ranges.

mod common;

use common::{PATTERNED, assert_rows_seamless, transpose};
use snakeskin::graph::evaluate;
use snakeskin::maps::{BuildOptions, MapKind, build_graph};
use snakeskin::ops::Image;
use snakeskin::preset::{library, parse, read_source};

#[test]
fn every_preset_and_map_tiles_seamlessly() {
    let mut specs: Vec<String> = library::names().iter().map(|s| s.to_string()).collect();
    // The gallery variants cover every scale shape and pattern kind.
    let variants: Vec<String> =
        snakeskin::render::figures::gallery::VARIANTS.iter().map(|(_, _, o)| format!("seed = 5\n{o}")).collect();
    specs.push(PATTERNED.to_string());
    let sources =
        specs.iter().map(|spec| read_source(spec).unwrap()).chain(variants.into_iter().enumerate().map(|(i, text)| {
            snakeskin::preset::PresetSource {
                name: format!("variant{i}"),
                display: format!("gallery variant {i}"),
                text,
            }
        }));
    for source in sources {
        let spec = source.display.clone();
        let loaded = parse(&source, &[]).unwrap();
        let graph = build_graph(&loaded.preset, BuildOptions::default());
        let eval = evaluate(&graph, &MapKind::ALL, 256, 256, &|_, _| {});
        for (map, img) in &eval.maps {
            assert_rows_seamless(img, &format!("{spec} {map} rows"));
            assert_rows_seamless(&transpose(img), &format!("{spec} {map} columns"));
        }
    }
}

#[test]
fn a_shifted_copy_shows_the_seam_check_would_fail() {
    // A texture cut out of a larger non-periodic pattern has a visible seam.
    let img = Image::gray_from_fn(64, 64, |u, v| (u * 3.3).sin() * 0.5 + v * 0.9);
    let result = std::panic::catch_unwind(|| assert_rows_seamless(&img, "gradient"));
    assert!(result.is_err(), "a v-gradient must fail the seam check");
}

#[test]
fn map_values_stay_in_range() {
    let loaded = parse(&read_source(PATTERNED).unwrap(), &[]).unwrap();
    let graph = build_graph(&loaded.preset, BuildOptions::default());
    let eval = evaluate(&graph, &MapKind::ALL, 128, 128, &|_, _| {});
    for (map, img) in &eval.maps {
        let (lo, hi) = if *map == MapKind::Normal { (-1.0, 1.0) } else { (0.0, 1.0) };
        assert!(img.data.iter().all(|v| v.is_finite() && (lo..=hi).contains(v)), "{map} out of [{lo}, {hi}]");
    }
    let height = &eval.maps[&MapKind::Height];
    let spread =
        height.data.iter().cloned().fold(f32::MIN, f32::max) - height.data.iter().cloned().fold(f32::MAX, f32::min);
    assert!(spread > 0.5, "height uses its range: {spread}");
}
