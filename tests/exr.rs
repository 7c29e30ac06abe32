//! `generate --format exr`: OpenEXR maps in physical units, read back with the `exr` crate
//! and compared against the graph's own f32 maps (the reference OpenEXR library read the
//! same files in a manual check: see BENCHMARKS' note on formats).

mod common;

use snakeskin::graph::evaluate;
use snakeskin::maps::{BuildOptions, Layout, MapKind, build_graph, thickness_range_nm};
use snakeskin::preset::load;

/// Channels of the first layer as (name, f32 samples in row-major order).
fn read_channels(path: &std::path::Path) -> Vec<(String, Vec<f32>)> {
    use exr::prelude::*;
    let image = read_all_flat_layers_from_file(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let layer = &image.layer_data[0];
    layer
        .channel_data
        .list
        .iter()
        .map(|c| {
            let samples: Vec<f32> = match &c.sample_data {
                FlatSamples::F16(v) => v.iter().map(|x| x.to_f32()).collect(),
                FlatSamples::F32(v) => v.clone(),
                FlatSamples::U32(v) => v.iter().map(|x| *x as f32).collect(),
            };
            (c.name.to_string(), samples)
        })
        .collect()
}

#[test]
fn exr_maps_hold_the_graphs_values_in_physical_units() {
    check_exr("xenopeltis-unicolor", Layout::Tile);
}

#[test]
fn a_body_atlas_in_exr_holds_the_whole_atlas_values() {
    // Evaluated in strips and gathered: every sample as the atlas evaluated at once.
    check_exr("liasis-mackloti", Layout::Body);
}

fn check_exr(name: &str, layout: Layout) {
    let dir = tempfile::tempdir().unwrap();
    let out = common::snakeskin(&[
        "generate",
        name,
        "-o",
        dir.path().to_str().unwrap(),
        "--size",
        "64",
        "--format",
        "exr",
        "--layout",
        layout.name(),
    ]);
    assert!(out.status.success(), "{}", common::stderr(&out));
    let preset = load(name, &[], None).unwrap().preset;
    let (lo, hi) = thickness_range_nm(&preset);
    assert!(hi > lo, "a species with a film: the thickness map spans a range");
    let graph = build_graph(&preset, BuildOptions { layout, ..BuildOptions::default() });
    let height = layout.height(&preset, 64);
    let maps = evaluate(&graph, &MapKind::ALL, 64, height, &|_, _| {}).maps;
    for (map, image) in &maps {
        let file = dir.path().join(format!("{name}_{}.exr", map.name()));
        let channels = read_channels(&file);
        let (names, bits) = map.exr_channels();
        let mut found: Vec<&str> = channels.iter().map(|(n, _)| n.as_str()).collect();
        found.sort();
        let mut wanted = names.to_vec();
        wanted.sort();
        assert_eq!(found, wanted, "{map}");
        for (k, channel) in names.iter().enumerate() {
            let samples = &channels.iter().find(|(n, _)| n == channel).unwrap().1;
            assert_eq!(samples.len(), 64 * height);
            for (i, got) in samples.iter().enumerate() {
                let x = image.data[i * image.channels + k.min(image.channels - 1)];
                let want = if *map == MapKind::Iridescence { (lo + x as f64 * (hi - lo)) as f32 } else { x };
                // Half floats keep 11 significant bits; floats are exact.
                let tolerance = if bits == 16 { want.abs() * 1e-3 + 1e-4 } else { 0.0 };
                assert!(
                    (got - want).abs() <= tolerance,
                    "{map} {channel} sample {i}: {got} in the file, {want} computed"
                );
            }
        }
    }
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join(format!("{name}.material.json"))).unwrap())
            .unwrap();
    assert_eq!(manifest["format"], "exr");
    let irid = manifest["maps"].as_array().unwrap().iter().find(|m| m["map"] == "iridescence").unwrap();
    assert_eq!(irid["meaning"], "film thickness in nm");
    assert_eq!(irid["bit_depth"], 32);
    assert!(snakeskin::export::verify_set(&dir.path().join(format!("{name}.material.json"))).is_ok());
}

/// A film switched off by an index equal to the ambient's has no thickness: its map is the
/// constant 0, and the manifest's range and the OpenEXR map say 0 nm (they said 290–550 nm
/// and 290 nm, the range of a film that does not show). Negative control: the film on.
#[test]
fn a_film_that_does_not_show_has_no_thickness_in_the_files() {
    let generate = |overrides: &[&str]| {
        let dir = tempfile::tempdir().unwrap();
        let args = ["generate", "xenopeltis-unicolor", "-o", dir.path().to_str().unwrap(), "--size", "32"];
        let rest = ["--format", "exr", "--maps", "iridescence"];
        let out = common::snakeskin(&[&args[..], &rest, overrides].concat());
        assert!(out.status.success(), "{}", common::stderr(&out));
        let manifest: serde_json::Value =
            serde_json::from_slice(&std::fs::read(dir.path().join("xenopeltis-unicolor.material.json")).unwrap())
                .unwrap();
        let samples = read_channels(&dir.path().join("xenopeltis-unicolor_iridescence.exr")).remove(0).1;
        (manifest["iridescence"].clone(), samples.iter().cloned().fold(f32::MIN, f32::max))
    };
    let (range, thickest) = generate(&["--set", "optics.film_ior=1.0"]);
    assert_eq!(
        (range["film"].as_bool(), range["min_nm"].as_f64(), range["max_nm"].as_f64()),
        (Some(false), Some(0.0), Some(0.0))
    );
    assert_eq!(thickest, 0.0);
    let (range, thickest) = generate(&[]);
    assert_eq!(range["film"].as_bool(), Some(true));
    assert!(range["min_nm"].as_f64().unwrap() > 0.0 && thickest > 0.0, "{range} {thickest}");
}
