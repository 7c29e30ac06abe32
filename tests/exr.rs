//! `generate --format exr`: OpenEXR maps in physical units, read back with the `exr` crate
//! and compared against the graph's own f32 maps (the reference OpenEXR library read the
//! same files in a manual check: see BENCHMARKS' note on formats).

mod common;

use snakeskin::graph::evaluate;
use snakeskin::maps::{BuildOptions, Layout, MapKind, build_graph, thickness_range_nm};
use snakeskin::preset::load;

/// A file's first layer: its channels as (name, OpenEXR sample type, f32 samples in
/// row-major order), its `wrapmodes` attribute, and the file's `chromaticities` (red, green,
/// blue, white as xy).
struct ExrFile {
    channels: Vec<(String, &'static str, Vec<f32>)>,
    wrap_modes: Option<String>,
    chromaticities: Option<[[f32; 2]; 4]>,
}

fn read_exr(path: &std::path::Path) -> ExrFile {
    use exr::prelude::*;
    let image = read_all_flat_layers_from_file(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let layer = &image.layer_data[0];
    let channels = layer
        .channel_data
        .list
        .iter()
        .map(|c| {
            let (sample_type, samples): (&str, Vec<f32>) = match &c.sample_data {
                FlatSamples::F16(v) => ("half", v.iter().map(|x| x.to_f32()).collect()),
                FlatSamples::F32(v) => ("float", v.clone()),
                FlatSamples::U32(v) => ("uint", v.iter().map(|x| *x as f32).collect()),
            };
            (c.name.to_string(), sample_type, samples)
        })
        .collect();
    let chromaticities = image.attributes.chromaticities.map(|c| [c.red, c.green, c.blue, c.white].map(|v| [v.0, v.1]));
    ExrFile { channels, wrap_modes: layer.attributes.wrap_mode_name.as_ref().map(|t| t.to_string()), chromaticities }
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
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join(format!("{name}.material.json"))).unwrap())
            .unwrap();
    // OpenEXR's standard `wrapmodes` (horizontal, vertical): a tile repeats both ways; a
    // body atlas repeats around the body only, as the glTF samplers of `tests/gltf.rs` say.
    let wrap_modes = match layout {
        Layout::Tile => "periodic",
        Layout::Body => "periodic,clamp",
    };
    for (map, image) in &maps {
        let file = dir.path().join(format!("{name}_{}.exr", map.name()));
        let exr = read_exr(&file);
        assert_eq!(exr.wrap_modes.as_deref(), Some(wrap_modes), "{map}");
        // The colour map names its primaries: sRGB's, IEC 61966-2-1 (OpenEXR's own default
        // `Chromaticities()`, ImfChromaticities.h); the data maps have no colour to name.
        let srgb = [[0.64, 0.33], [0.30, 0.60], [0.15, 0.06], [0.3127, 0.3290]];
        assert_eq!(exr.chromaticities, (*map == MapKind::Color).then_some(srgb), "{map}");
        let entry = manifest["maps"].as_array().unwrap().iter().find(|m| m["map"] == map.name()).unwrap();
        for (channel, sample_type, _) in &exr.channels {
            assert_eq!(entry["sample_type"], *sample_type, "{map} {channel}: the manifest says the file's type");
            assert_eq!(entry["bit_depth"], if *sample_type == "half" { 16 } else { 32 }, "{map} {channel}");
        }
        let channels: Vec<(String, Vec<f32>)> = exr.channels.into_iter().map(|(n, _, s)| (n, s)).collect();
        let (names, sample) = map.exr_channels();
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
                let tolerance = if sample.bits() == 16 { want.abs() * 1e-3 + 1e-4 } else { 0.0 };
                assert!(
                    (got - want).abs() <= tolerance,
                    "{map} {channel} sample {i}: {got} in the file, {want} computed"
                );
            }
        }
    }
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
        let samples = read_exr(&dir.path().join("xenopeltis-unicolor_iridescence.exr")).channels.remove(0).2;
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
