//! End-to-end tests of the texture pipeline: the files and formats `generate` writes, what
//! the graph evaluates, and that bad input changes nothing on disk.

mod common;

use std::collections::BTreeSet;

use common::*;
use image::{ColorType, ImageReader};
use snakeskin::graph::evaluate;
use snakeskin::maps::{BuildOptions, MapKind, build_graph};
use snakeskin::preset::{parse, read_source};

fn patterned_graph() -> snakeskin::graph::Graph {
    let loaded = parse(&read_source(PATTERNED).unwrap(), &[]).unwrap();
    build_graph(&loaded.preset, BuildOptions::default())
}

fn is_color_only(name: &str) -> bool {
    name.starts_with("color.") || name.starts_with("pattern") || name.starts_with("belly.")
}

#[test]
fn generate_writes_five_maps_in_their_formats_and_a_manifest() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let run = snakeskin(&["generate", "erythrolamprus-miliaris", "-o", out, "--size", "256"]);
    assert!(run.status.success(), "{}", stderr(&run));

    let expected = [
        ("color", ColorType::Rgb8),
        ("height", ColorType::L16),
        ("normal", ColorType::Rgb8),
        ("roughness", ColorType::L8),
        ("iridescence", ColorType::L16),
    ];
    for (map, color_type) in expected {
        let path = dir.path().join(format!("erythrolamprus-miliaris_{map}.png"));
        let image = ImageReader::open(&path).unwrap().decode().unwrap();
        assert_eq!(image.color(), color_type, "{map}");
        assert_eq!((image.width(), image.height()), (256, 256), "{map}");
        // Colour is tagged sRGB (the colour map was untagged while the packs' base colour
        // was tagged); data maps carry no colour-space chunk.
        let chunks = png_chunk_types(&std::fs::read(&path).unwrap());
        assert_eq!(chunks.iter().any(|c| c == "sRGB"), map == "color", "{map}: {chunks:?}");
        assert!(!chunks.iter().any(|c| ["gAMA", "iCCP", "cICP", "cHRM"].contains(&c.as_str())), "{map}: {chunks:?}");
    }
    let files = snapshot(dir.path());
    assert_eq!(files.len(), 6, "five maps and a manifest: {:?}", files.keys());

    let manifest: serde_json::Value =
        serde_json::from_slice(&files[&dir.path().join("erythrolamprus-miliaris.material.json")]).unwrap();
    assert_eq!(manifest["preset"], "erythrolamprus-miliaris");
    assert_eq!(manifest["width"], 256);
    assert_eq!(manifest["seed"], 1);
    assert_eq!(manifest["preset_hash"].as_str().unwrap().len(), 16);
    assert_eq!(manifest["maps"].as_array().unwrap().len(), 5);
    let depth = |m: &str| {
        manifest["maps"].as_array().unwrap().iter().find(|e| e["map"] == m).unwrap()["bit_depth"].as_u64().unwrap()
    };
    assert_eq!((depth("color"), depth("height"), depth("iridescence")), (8, 16, 16));
    let (min_nm, max_nm) =
        (manifest["iridescence"]["min_nm"].as_f64().unwrap(), manifest["iridescence"]["max_nm"].as_f64().unwrap());
    // No source reports iridescence for this species: no film, an empty range.
    assert_eq!((min_nm, max_nm), (0.0, 0.0));
    assert_eq!(manifest["optics"]["film_ior"], 1.55);
}

/// The chunk types of a PNG file in order, read from its bytes (length, type, data, CRC).
fn png_chunk_types(bytes: &[u8]) -> Vec<String> {
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "a PNG signature");
    let mut types = Vec::new();
    let mut at = 8;
    while at + 8 <= bytes.len() {
        let length = u32::from_be_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
        types.push(String::from_utf8_lossy(&bytes[at + 4..at + 8]).into_owned());
        at += 12 + length;
    }
    types
}

#[test]
fn normal_map_decodes_to_unit_vectors_facing_out() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let run = snakeskin(&["generate", PATTERNED, "-o", out, "--size", "128", "--maps", "normal"]);
    assert!(run.status.success(), "{}", stderr(&run));
    let normal = ImageReader::open(dir.path().join("patterned_normal.png")).unwrap().decode().unwrap().to_rgb8();
    for p in normal.pixels() {
        let v = p.0.map(|c| c as f32 / 255.0 * 2.0 - 1.0);
        let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        // 8-bit quantisation moves each component by at most 1/255.
        assert!((len - 1.0).abs() < 0.02, "length {len}");
        assert!(v[2] > 0.0);
    }
}

#[test]
fn roughness_alone_writes_one_map_and_runs_no_colour_node() {
    let graph = patterned_graph();
    let only = evaluate(&graph, &[MapKind::Roughness], 64, 64, &|_, _| {});
    assert!(!only.stats.nodes.is_empty());
    let colour_nodes: Vec<&str> =
        only.stats.nodes.iter().map(|n| n.name.as_str()).filter(|n| is_color_only(n)).collect();
    assert!(colour_nodes.is_empty(), "roughness ran colour nodes: {colour_nodes:?}");
    // The full set does run them, so the check above can fail.
    let full = evaluate(&graph, &MapKind::ALL, 64, 64, &|_, _| {});
    assert!(full.stats.nodes.iter().any(|n| n.name.starts_with("pattern")));

    let dir = tempfile::tempdir().unwrap();
    let run = snakeskin(&[
        "generate",
        PATTERNED,
        "-o",
        dir.path().to_str().unwrap(),
        "--size",
        "64",
        "--maps",
        "roughness",
        "--stats",
    ]);
    assert!(run.status.success(), "{}", stderr(&run));
    let files: Vec<String> =
        snapshot(dir.path()).keys().map(|p| p.file_name().unwrap().to_string_lossy().into_owned()).collect();
    assert_eq!(files, ["patterned.material.json", "patterned_roughness.png"]);
    let stats = stderr(&run);
    assert!(stats.contains("roughness.out"), "{stats}");
    assert!(!stats.lines().any(|l| is_color_only(l.split_whitespace().next().unwrap_or(""))), "{stats}");
}

#[test]
fn a_node_shared_by_two_maps_runs_once() {
    let graph = patterned_graph();
    let both = evaluate(&graph, &[MapKind::Height, MapKind::Roughness], 64, 64, &|_, _| {});
    // `scales` feeds height (through scales.height) and roughness (through scales.crevice).
    assert_eq!(both.stats.get("scales").unwrap().evaluations, 1);
    assert_eq!(both.stats.get("noise.grain").unwrap().evaluations, 1);
    let all = evaluate(&graph, &MapKind::ALL, 64, 64, &|_, _| {});
    assert!(all.stats.nodes.iter().all(|n| n.evaluations == 1));
    // Each evaluated node appears once: as many entries as distinct names.
    let names: BTreeSet<&str> = all.stats.nodes.iter().map(|n| n.name.as_str()).collect();
    assert_eq!(names.len(), all.stats.nodes.len());
    assert_eq!(all.stats.nodes.len(), graph.reachable(&MapKind::ALL).len());
}

/// Node names declared in a DOT digraph (lines of the form `"name" [label=...]`).
fn dot_nodes(dot: &str) -> BTreeSet<String> {
    dot.lines()
        .map(str::trim)
        .filter(|l| l.starts_with('"') && l.contains("[label="))
        .map(|l| l[1..].split('"').next().unwrap().to_string())
        .collect()
}

/// `graph --layout body` lists the body atlas's graph, exactly the nodes its evaluation
/// runs, and they include the body's own (`body.`: plates, head, tail) that the tile's graph
/// has none of (control: without `--layout` no body node is listed).
#[test]
fn graph_lists_the_body_atlas_with_layout_body() {
    let loaded = parse(&read_source(PATTERNED).unwrap(), &[]).unwrap();
    let options = BuildOptions { layout: snakeskin::maps::Layout::Body, ..BuildOptions::default() };
    let graph = build_graph(&loaded.preset, options);
    let maps = snakeskin::parse_map_list("all").unwrap();
    let evaluated: BTreeSet<String> =
        evaluate(&graph, &maps, 32, 384, &|_, _| {}).stats.nodes.into_iter().map(|n| n.name).collect();
    let listed = |extra: &[&str]| {
        let run = snakeskin(&[&["graph", PATTERNED, "--dot"][..], extra].concat());
        assert!(run.status.success(), "{}", stderr(&run));
        dot_nodes(&stdout(&run))
    };
    let body = listed(&["--layout", "body"]);
    assert_eq!(body, evaluated);
    assert!(body.iter().any(|n| n.starts_with("body.")), "{body:?}");
    assert!(!listed(&[]).iter().any(|n| n.starts_with("body.")));
}

#[test]
fn graph_dot_lists_exactly_the_evaluated_nodes() {
    let graph = patterned_graph();
    for maps in ["roughness", "color", "height,normal", "iridescence", "all"] {
        let run = snakeskin(&["graph", PATTERNED, "--maps", maps, "--dot"]);
        assert!(run.status.success(), "{}", stderr(&run));
        let dot = stdout(&run);
        assert!(dot.starts_with("digraph"), "{dot}");
        let requested = snakeskin::parse_map_list(maps).unwrap();
        let evaluated: BTreeSet<String> =
            evaluate(&graph, &requested, 32, 32, &|_, _| {}).stats.nodes.into_iter().map(|n| n.name).collect();
        assert_eq!(dot_nodes(&dot), evaluated, "maps {maps}");
        // Every edge joins two declared nodes.
        for line in dot.lines().filter(|l| l.contains("->")) {
            let ends: Vec<&str> =
                line.split('"').filter(|s| !s.trim().is_empty() && !s.contains("->") && !s.contains(';')).collect();
            assert!(ends.iter().all(|e| evaluated.contains(*e)), "{line}");
        }
    }
}

#[test]
fn same_bytes_for_any_thread_count_and_across_runs() {
    let run = |threads: &str| {
        let dir = tempfile::tempdir().unwrap();
        let out = snakeskin_env(
            &["generate", PATTERNED, "-o", dir.path().to_str().unwrap(), "--size", "192"],
            &[("RAYON_NUM_THREADS", threads)],
        );
        assert!(out.status.success(), "{}", stderr(&out));
        snapshot(dir.path()).into_iter().map(|(p, b)| (p.file_name().unwrap().to_owned(), b)).collect::<Vec<_>>()
    };
    let one = run("1");
    assert_eq!(one.len(), 6);
    assert_eq!(one, run("2"));
    assert_eq!(one, run("2"));
}

#[test]
fn seed_changes_the_skin() {
    let a = tempfile::tempdir().unwrap();
    let b = tempfile::tempdir().unwrap();
    for (dir, seed) in [(&a, "1"), (&b, "2")] {
        let out = snakeskin(&[
            "generate",
            PATTERNED,
            "-o",
            dir.path().to_str().unwrap(),
            "--size",
            "64",
            "--maps",
            "height",
            "--seed",
            seed,
        ]);
        assert!(out.status.success(), "{}", stderr(&out));
    }
    let read = |d: &tempfile::TempDir| std::fs::read(d.path().join("patterned_height.png")).unwrap();
    assert_ne!(read(&a), read(&b));
}

#[test]
fn buffers_are_freed_after_their_last_consumer() {
    let graph = patterned_graph();
    let eval = evaluate(&graph, &MapKind::ALL, 64, 64, &|_, _| {});
    let total: usize = eval.stats.nodes.iter().map(|n| n.bytes).sum();
    // Holding every buffer to the end would need `total`; the graph is far narrower.
    assert!(eval.stats.peak_bytes * 2 < total, "peak {} of total {}", eval.stats.peak_bytes, total);
    // The five outputs are alive at the end, so the peak is at least their size.
    let outputs: usize = eval.maps.values().map(|m| m.bytes()).sum();
    assert!(eval.stats.peak_bytes >= outputs);
}

#[test]
fn a_species_without_a_film_evaluates_no_film_nodes() {
    // Decided from the preset before evaluation: without a film (crotalus-atrox: 0 nm, no
    // spread) the thickness map is one constant node; with one (the control) the gradient
    // and noise nodes run. Counted from the evaluator's own statistics, not timed.
    for (name, film) in [("crotalus-atrox", false), ("xenopeltis-unicolor", true)] {
        let preset = snakeskin::preset::load(name, &[], None).unwrap().preset;
        assert_eq!(snakeskin::maps::has_film(&preset), film, "{name}");
        let graph = build_graph(&preset, BuildOptions::default());
        let eval = evaluate(&graph, &[MapKind::Iridescence], 64, 64, &|_, _| {});
        let names: Vec<&str> = eval.stats.nodes.iter().map(|n| n.name.as_str()).collect();
        assert_eq!(names.contains(&"iridescence.noise"), film, "{name}: {names:?}");
        if !film {
            assert_eq!(names, ["iridescence.out"], "{name}");
            assert!(eval.maps[&MapKind::Iridescence].data.iter().all(|&x| x == 0.0));
        }
        // `graph` shows the same.
        let dot = stdout(&snakeskin(&["graph", name, "--maps", "iridescence", "--dot"]));
        assert_eq!(dot.contains("iridescence.noise"), film, "{name}: {dot}");
    }
}

#[test]
fn a_constant_map_is_quantised_from_its_value_and_is_the_evaluated_map_byte_for_byte() {
    // crotalus-atrox has no film: its thickness map is one constant node, whose samples
    // `generate` quantises from the value (`Graph::constant_output`) instead of reading its
    // image. The file must be the bytes of the map quantised from its image as any other;
    // `--stats` says so. The control, xenopeltis-unicolor (a film), quantises its image.
    use snakeskin::export::{encode_quantized, quantize, quantize_constant};
    for (name, film) in [("crotalus-atrox", false), ("xenopeltis-unicolor", true)] {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().to_str().unwrap();
        let run = snakeskin(&["generate", name, "-o", out, "--size", "96", "--stats"]);
        assert!(run.status.success(), "{}", stderr(&run));
        let stats = stderr(&run);
        assert_eq!(stats.contains("iridescence map quantised as the constant 0"), !film, "{name}: {stats}");
        let written = std::fs::read(dir.path().join(format!("{name}_iridescence.png"))).unwrap();
        let preset = snakeskin::preset::load(name, &[], None).unwrap().preset;
        let graph = build_graph(&preset, BuildOptions::default());
        assert_eq!(graph.constant_output(MapKind::Iridescence).is_some(), !film, "{name}");
        let eval = evaluate(&graph, &[MapKind::Iridescence], 96, 96, &|_, _| {});
        let evaluated = encode_quantized(&quantize(MapKind::Iridescence, &eval.maps[&MapKind::Iridescence])).unwrap();
        assert!(written == evaluated, "{name}: the written thickness map differs from the evaluated one");
    }
    // Any constant, in every single-channel format, is the quantised image's samples; a
    // map of three channels is not taken.
    for map in [MapKind::Iridescence, MapKind::Roughness, MapKind::Height] {
        for value in [0.0f32, 1e-7, 0.37, 1.0, 1.5, -0.2] {
            let image = snakeskin::ops::Image { width: 5, height: 3, channels: 1, data: vec![value; 15] };
            let q = quantize_constant(map, 5, 3, value).unwrap();
            assert_eq!(q.samples, quantize(map, &image).samples, "{map:?} {value}");
        }
    }
    assert!(quantize_constant(MapKind::Color, 5, 3, 0.5).is_none());
}

#[test]
fn zero_film_noise_runs_no_noise_node_and_changes_nothing() {
    // iridescence.noise = 0: the noise and its blend are not built. The map equals that of a
    // noise too weak to move any sample (1e-30, which keeps both nodes): skipping them is
    // pure speed. The control: the tiny-noise graph does run the noise node.
    let map = |noise: &str| {
        let preset =
            snakeskin::preset::load("xenopeltis-unicolor", &[("iridescence.noise".into(), noise.into())], None)
                .unwrap()
                .preset;
        let eval =
            evaluate(&build_graph(&preset, BuildOptions::default()), &[MapKind::Iridescence], 64, 64, &|_, _| {});
        let ran_noise = eval.stats.nodes.iter().any(|n| n.name == "iridescence.noise");
        (eval.maps[&MapKind::Iridescence].data.clone(), ran_noise)
    };
    let (skipped, ran_skipped) = map("0");
    let (tiny, ran_tiny) = map("1e-30");
    assert!(!ran_skipped && ran_tiny);
    let worst = skipped.iter().zip(&tiny).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
    assert!(worst < 1e-20, "skipping the zero noise changed the map by {worst}");
}

#[test]
fn zero_amplitudes_and_invisible_layers_run_none_of_their_nodes_and_change_nothing() {
    // Decided from the preset before evaluation: no colour variation (its noise), no height
    // grain and no roughness variation (the grain noise, when both are 0), a pattern layer
    // at opacity 0 (all its nodes). Each against a value too small to move any sample
    // (1e-30, which keeps the nodes): the maps are identical, so the skip is pure speed.
    // The controls: the tiny values do run the nodes.
    let run = |overrides: &[(&str, &str)]| {
        let overrides: Vec<(String, String)> = overrides.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect();
        let preset = snakeskin::preset::load("crotalus-atrox", &overrides, None).unwrap().preset;
        let eval = evaluate(&build_graph(&preset, BuildOptions::default()), &MapKind::ALL, 96, 96, &|_, _| {});
        let names: Vec<String> = eval.stats.nodes.iter().map(|n| n.name.clone()).collect();
        (eval.maps, names)
    };
    type Overrides<'a> = &'a [(&'a str, &'a str)];
    let cases: [(Overrides, Overrides, &[&str]); 3] = [
        (&[("color.variation", "0")], &[("color.variation", "1e-30")], &["color.variation_noise"]),
        (
            &[("height.grain", "0"), ("roughness.variation", "0")],
            &[("height.grain", "1e-30"), ("roughness.variation", "1e-30")],
            &["noise.grain", "height.grain", "height.sum", "roughness.noise"],
        ),
        (&[("pattern.0.opacity", "0")], &[("pattern.0.opacity", "1e-30")], &["pattern0.shape", "pattern0.tint"]),
    ];
    for (zero, tiny, skipped) in cases {
        let (zero_maps, zero_names) = run(zero);
        let (tiny_maps, tiny_names) = run(tiny);
        for node in skipped {
            assert!(!zero_names.iter().any(|n| n == node), "{zero:?}: {node} ran: {zero_names:?}");
            assert!(tiny_names.iter().any(|n| n == node), "{tiny:?}: {node} did not run (the control)");
        }
        for (map, image) in &zero_maps {
            assert!(image.data == tiny_maps[map].data, "{zero:?}: the {map} map changed");
        }
    }
}

#[test]
fn the_normal_map_quantised_from_the_height_map_is_the_evaluated_map_byte_for_byte() {
    // A set with the height map quantises its normal map from the height map's image a row
    // at a time (`Graph::normal_from`), without the normal node; `--maps normal` alone
    // evaluates the node as before. Both files must be the bytes of the evaluated map
    // quantised as any other; `--stats` says which way each went.
    use snakeskin::export::{encode_quantized, quantize};
    for name in ["natrix-natrix", PATTERNED] {
        let loaded = parse(&read_source(name).unwrap(), &[]).unwrap();
        let graph = build_graph(&loaded.preset, BuildOptions::default());
        let eval = evaluate(&graph, &[MapKind::Normal], 96, 96, &|_, _| {});
        let evaluated = encode_quantized(&quantize(MapKind::Normal, &eval.maps[&MapKind::Normal])).unwrap();
        for (maps, direct) in [(None, true), (Some("normal"), false), (Some("height,normal"), true)] {
            let dir = tempfile::tempdir().unwrap();
            let out = dir.path().to_str().unwrap();
            let mut args = vec!["generate", name, "-o", out, "--size", "96", "--stats"];
            args.extend(maps.iter().flat_map(|m| ["--maps", *m]));
            let run = snakeskin(&args);
            assert!(run.status.success(), "{}", stderr(&run));
            let stats = stderr(&run);
            let label = format!("height to normal {}", snakeskin::generate::NORMAL_FROM_HEIGHT);
            assert_eq!(stats.contains(&label), direct, "{name} {maps:?}: {stats}");
            let written = std::fs::read(dir.path().join(format!("{}_normal.png", loaded.name))).unwrap();
            assert!(written == evaluated, "{name} {maps:?}: the written normal map differs from the evaluated one");
        }
    }
    // `quantize_rows` of the rows against `quantize` of the image, off the tile too: a strip
    // of a body atlas (no wrap along v, a texture four widths long), either convention.
    use snakeskin::material::NormalConvention;
    use snakeskin::ops::filters::{NormalSpec, height_to_normal, height_to_normal_rows};
    let (width, height) = (23, 37);
    let data = (0..width * height).map(|i| ((i * 7919) % 1000) as f32 / 999.0).collect();
    let heights = snakeskin::ops::Image { width, height, channels: 1, data };
    for convention in [NormalConvention::OpenGl, NormalConvention::DirectX] {
        for (v_extent, full_height, wraps_v) in [(1.0, height, true), (4.0, 92, false)] {
            let spec = NormalSpec { slope_per_unit_height: 0.7, convention, v_extent, full_height, wraps_v };
            let image = height_to_normal(&heights, spec);
            let rows = height_to_normal_rows(&heights, spec);
            let by_rows = snakeskin::export::quantize_rows(MapKind::Normal, width, height, rows);
            assert_eq!(by_rows.samples, quantize(MapKind::Normal, &image).samples, "{convention:?} {wraps_v}");
        }
    }
}

#[test]
fn a_map_written_alone_computes_only_its_scale_channels_and_the_same_samples() {
    // `Graph::for_maps`, as `generate --maps` and every pack use it: the scale field of a
    // graph for some maps stores only the channels their nodes read, its readers
    // renumbered. Every map written alone must equal that map of the whole set, sample for
    // sample (a wrong renumbering reads another channel and fails this).
    use snakeskin::graph::{Graph, Op};
    use snakeskin::ops::scales::channel;
    let field = |g: &Graph| {
        g.nodes()
            .iter()
            .find_map(|n| match &n.op {
                Op::Scales(f) => Some(f.outputs.clone()),
                _ => None,
            })
            .unwrap()
    };
    // The last: a per-scale colour of speckles alone, which reads no optional channel
    // (`ScaleChannels`: a stand-in index had kept the height plane for `--maps color`).
    let speckles_alone = [("color.scale_tone", "0"), ("color.speckle", "0.3")].map(|(k, v)| (k.into(), v.into()));
    let cases = [
        ("crotalus-atrox", &[][..]),
        ("xenopeltis-unicolor", &[]),
        ("bitis-gabonica", &[]),
        (PATTERNED, &[]),
        ("xenopeltis-unicolor", &speckles_alone[..]),
    ];
    for (name, overrides) in cases {
        let loaded = parse(&read_source(name).unwrap(), overrides).unwrap();
        let whole = build_graph(&loaded.preset, BuildOptions::default());
        let all = evaluate(&whole, &MapKind::ALL, 96, 96, &|_, _| {}).maps;
        assert_eq!(field(&whole.for_maps(&MapKind::ALL)), field(&whole), "{name}: the whole set lost a channel");
        for map in MapKind::ALL {
            let alone = evaluate(&whole.for_maps(&[map]), &[map], 96, 96, &|_, _| {}).maps;
            assert!(alone[&map].data == all[&map].data, "{name}: the {map} map alone differs from the set's");
        }
        // The roughness map reads the crevices, and the keels and the per-scale random value
        // where the preset roughens keels and varies roughness by scale (`maps::build_roughness`).
        let r = &loaded.preset.roughness;
        let mut wanted = vec![channel::CREVICE];
        if loaded.preset.scales.keeled && r.keel > 0.0 {
            wanted.push(channel::KEEL);
        }
        if r.per_scale > 0.0 {
            wanted.push(channel::CELL_RANDOM);
        }
        let mut got = field(&whole.for_maps(&[MapKind::Roughness]));
        got.sort_unstable();
        assert_eq!(got, wanted, "{name}: the roughness map's scale field");
        assert!(field(&whole).len() > wanted.len(), "{name}: the control: the whole set reads more");
        // The colour map reads the crevices, the channels of the per-scale colour's keys that
        // are on (`ops::scale_colour`) and the scale centres of patterns snapped to scales.
        let c = &loaded.preset.color;
        let mut wanted = vec![channel::CREVICE];
        if c.scale_tone > 0.0 || c.scale_hue > 0.0 {
            wanted.push(channel::CELL_RANDOM);
        }
        if c.tip_tone != 0.0 {
            wanted.push(channel::ALONG);
        }
        let belly_edge = loaded.preset.belly.edge_tone;
        if c.edge_tone != 0.0 || belly_edge != 0.0 {
            wanted.push(channel::INSIDE);
        }
        if c.edge_tone != belly_edge {
            wanted.push(channel::ROW);
        }
        if loaded.preset.pattern.iter().any(|p| p.scale_aligned > 0.0) {
            wanted.extend([channel::CENTRE_U, channel::CENTRE_V]);
        }
        wanted.sort_unstable();
        let mut got = field(&whole.for_maps(&[MapKind::Color]));
        got.sort_unstable();
        assert_eq!(got, wanted, "{name} {overrides:?}: the colour map's scale field");
    }
}

#[test]
fn fusion_never_raises_the_estimated_peak_and_keeps_the_folds_that_do_not() {
    // `Graph::fused` undoes folds while the estimated peak is above the unfused graph's,
    // the furthest-reaching first, then tries each undone fold again and keeps those under
    // the peak that reached. Every preset at 2048² and 4096²: never above the unfused peak.
    // `natrix-natrix` at 4096²: undoing by reach had unfolded its height and crevice
    // channel copies too (64 MiB each), which raise nothing; they are folded again.
    rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap().install(|| {
        use snakeskin::graph::estimate_peak_bytes;
        for name in snakeskin::preset::library::all().iter().map(|(name, _)| *name).chain([PATTERNED]) {
            let loaded = parse(&read_source(name).unwrap(), &[]).unwrap();
            let plain = build_graph(&loaded.preset, BuildOptions::default()).for_maps(&MapKind::ALL);
            for size in [2048, 4096] {
                let fused = plain.fused(&MapKind::ALL, size, size);
                let (f, p) = (
                    estimate_peak_bytes(&fused, &MapKind::ALL, size, size),
                    estimate_peak_bytes(&plain, &MapKind::ALL, size, size),
                );
                assert!(f <= p, "{name} at {size}: fused peak {f} above the unfused {p}");
            }
        }
        let loaded = parse(&read_source("natrix-natrix").unwrap(), &[]).unwrap();
        let fused = build_graph(&loaded.preset, BuildOptions::default()).fused(&MapKind::ALL, 4096, 4096);
        let names: Vec<&str> = fused.nodes().iter().map(|n| n.name.as_str()).collect();
        for copy in ["scales.height", "scales.crevice"] {
            assert!(!names.contains(&copy), "{copy} is a node of its own: {names:?}");
        }
    });
}

#[test]
fn fused_chains_give_the_same_bits_as_the_nodes_one_by_one() {
    // `Graph::fused` (what `generate` evaluates) runs chains of per-pixel nodes a band of
    // rows at a time with the nodes' own kernels: every map of every preset, tile and body,
    // must be the unfused graph's bit for bit, at a size that is no multiple of the band
    // (a short last band), and the `--maps` subsets fuse differently (what is a map ends a
    // chain). The body is evaluated as a strip from inside the atlas, as `generate` runs a
    // long texture (`evaluate_rows`: the frame's rows are not the texture's first).
    // Two threads, as on the CI machine: how much fuses depends on the bands in flight
    // (`FusedChain::scratch_bytes`), one per thread.
    rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap().install(fused_chains_on_two_threads);
}

fn fused_chains_on_two_threads() {
    use snakeskin::graph::{Graph, Op, evaluate_rows};
    use snakeskin::maps::Layout;
    use snakeskin::ops::Frame;
    let rows = |graph: &Graph, maps: &[MapKind], frame: Frame| {
        let mut out = std::collections::BTreeMap::new();
        evaluate_rows(graph, maps, frame, &|_, _| {}, &mut |map, image| {
            out.insert(map, image.data.iter().map(|v| v.to_bits()).collect::<Vec<u32>>());
        });
        out
    };
    let bits =
        |graph: &Graph, maps: &[MapKind], width: usize, height: usize| rows(graph, maps, Frame::whole(width, height));
    let mut fused_nodes = 0;
    for name in snakeskin::preset::library::all().iter().map(|(name, _)| *name).chain([PATTERNED]) {
        let loaded = parse(&read_source(name).unwrap(), &[]).unwrap();
        for layout in [Layout::Tile, Layout::Body] {
            let graph = build_graph(&loaded.preset, BuildOptions { layout, ..BuildOptions::default() });
            let (width, height) = (72, layout.height(&loaded.preset, 72));
            let frame = match layout {
                Layout::Tile => Frame::whole(width, height),
                Layout::Body => Frame { width, height: 90, full_height: height, row0: height / 2, wraps_v: false },
            };
            for maps in [&MapKind::ALL[..], &[MapKind::Roughness], &[MapKind::Color, MapKind::Height]] {
                let plain = graph.for_maps(maps);
                let fused = plain.fused(maps, width, height);
                fused_nodes += fused.nodes().iter().filter(|n| matches!(n.op, Op::Fused(_))).count();
                assert!(
                    rows(&fused, maps, frame) == rows(&plain, maps, frame),
                    "{name} {layout:?} {maps:?}: fused maps differ"
                );
            }
        }
    }
    assert!(fused_nodes > 100, "fusion hardly happened: {fused_nodes} fused nodes");

    // Negative control: the comparison sees a change inside a chain (the per-scale
    // roughness is a levels step of the roughness chain).
    let fused_roughness = |per_scale: &str| {
        let loaded =
            parse(&read_source(PATTERNED).unwrap(), &[("roughness.per_scale".into(), per_scale.into())]).unwrap();
        let graph = build_graph(&loaded.preset, BuildOptions::default()).fused(&MapKind::ALL, 64, 64);
        let chain = graph.nodes().iter().find(|n| n.name == "roughness.out").map(|n| n.op.label());
        assert!(chain.is_some_and(|label| label.starts_with("fused")), "the roughness chain is fused");
        bits(&graph, &[MapKind::Roughness], 64, 64)
    };
    assert!(fused_roughness("0.05") != fused_roughness("0.06"), "a changed step went unseen");
}

#[test]
fn the_height_maps_range_holds_every_surface_the_field_draws() {
    // README: the height map's 0 is the floor of the deepest groove between scales and its 1
    // the tallest surface, so no scale's top clips and no groove does: the field's heights
    // (before the grain, which widens both ends by its amplitude) must lie at or below the
    // range's top everywhere, and above its floor but where skin shows, for every shape,
    // flat and fully imbricate, keeled or not, on the tile and on the body layout (plates,
    // head shields). The range assumed the leaf's profile for every shape: hexagons reached
    // 0.7 over a top of 0.6, and a third of a hexagon preset's height map clipped at 1.
    use snakeskin::maps::{Layout, height_range, scale_field};
    use snakeskin::ops::scales::channel;
    for shape in ["leaf", "diamond", "hexagon"] {
        for imbrication in [0.0, 0.5, 1.0] {
            for keeled in [false, true] {
                // The tallest keel where there are keels (a keel height without them is refused).
                let keel = if keeled { "keel_height = 1.0\n" } else { "" };
                let text = format!(
                    "seed = 3\n[scales]\nshape = \"{shape}\"\nimbrication = {imbrication}\nkeeled = {keeled}\n\
                     {keel}[height]\ngrain = 0.05\n"
                );
                let preset = preset_from(&text);
                let (low, high) = height_range(&preset);
                let grain = preset.height.grain as f32;
                let (floor, top) = (low + grain, high - grain);
                let mut highest_drawn = 0.0f32;
                for (layout, width, height) in [(Layout::Tile, 96, 96), (Layout::Body, 48, 48 * 12)] {
                    let mut field = scale_field(&preset, layout);
                    field.outputs = vec![channel::HEIGHT];
                    let heights = field.render(width, height);
                    let hi = heights.data.iter().cloned().fold(f32::MIN, f32::max);
                    // (`top` is the range's end less the grain: within a float's rounding.)
                    assert!(hi <= top + 1e-6, "{layout:?} {text}: heights up to {hi} over the top {top}");
                    highest_drawn = highest_drawn.max(hi);
                    // Below the floor only where skin shows: on the tile, where leaves that
                    // barely overlap (imbrication 0) leave gaps, 1.6 % (a hexagon's floor is
                    // the skin itself: none).
                    if layout == Layout::Tile {
                        let below = heights.data.iter().filter(|&&h| h < floor - 1e-6).count();
                        let share = below as f32 / heights.data.len() as f32;
                        assert!(share < 0.03, "{text}: {share} of the tile below the groove floor {floor}");
                    }
                }
                // And the range is no wider than it needs: the tallest surface drawn reaches
                // near its top, so the 16 bits are spent on the skin's heights.
                assert!(highest_drawn > 0.9 * top, "{text}: tallest {highest_drawn} of a range to {top}");
            }
        }
    }
}

/// A live-reload cache keeps every node's buffer: its memory check counts them all
/// (`estimate_cached_peak_bytes`), not the one-shot schedule's peak, which frees buffers
/// after their last consumer and is below what the cache holds (the window's check used it:
/// 312 MiB estimated, 890 MiB peak at 2048²). Over the built-in presets at 64², the cached
/// estimate covers the bytes the cache holds afterwards; the one-shot one does not.
#[test]
fn a_cached_evaluation_is_estimated_with_every_node_kept() {
    use snakeskin::graph::{NodeCache, estimate_cached_peak_bytes, estimate_peak_bytes};
    for (name, _) in snakeskin::preset::library::all() {
        let loaded = snakeskin::preset::load(name, &[], None).unwrap();
        let graph = build_graph(&loaded.preset, BuildOptions::default());
        let mut cache = NodeCache::new();
        cache.evaluate(&graph, &MapKind::ALL, 64, 64);
        let held = cache.bytes();
        let cached = estimate_cached_peak_bytes(&graph, &MapKind::ALL, 64, 64);
        let one_shot = estimate_peak_bytes(&graph, &MapKind::ALL, 64, 64);
        assert!(cached >= held, "{name}: cached estimate {cached} for {held} bytes held");
        assert!(one_shot < held, "{name}: the one-shot estimate {one_shot} already covers {held}");
    }
}

/// `graph`'s list keeps its columns for every built-in species: each row's inputs start
/// where every other row's do (a label longer than a fixed width, `colour per scale tone=…
/// speckle=…`, pushed its row's inputs out of line).
#[test]
fn the_graph_list_keeps_its_columns() {
    for name in snakeskin::preset::library::names() {
        let out = snakeskin(&["graph", name]);
        assert!(out.status.success(), "{name}: {}", stderr(&out));
        let text = stdout(&out);
        let columns: BTreeSet<usize> = text.lines().map(|line| line.find(" <- ").expect("an arrow a row")).collect();
        assert_eq!(columns.len(), 1, "{name}: the arrows stand in columns {columns:?}\n{text}");
    }
}

/// `graph` shows the operations `generate` runs: every node `generate --stats` lists that
/// it did not fuse has the same label in `graph`'s list (a scale field trimmed to the maps
/// numbers its channels anew: `graph --maps roughness` showed `channel 2` and `channel 1`
/// where the run read channels 1 and 0, a review).
#[test]
fn the_graph_shows_the_operations_generate_runs() {
    let dir = tempfile::tempdir().unwrap();
    let columns = |line: &str| -> Vec<String> {
        line.split("  ").map(str::trim).filter(|s| !s.is_empty()).map(str::to_string).collect()
    };
    for maps in ["roughness", "color", "height,normal", "all"] {
        let species = "erythrolamprus-miliaris";
        let run = snakeskin(&[
            "generate",
            species,
            "--maps",
            maps,
            "--stats",
            "--size",
            "32",
            "-o",
            dir.path().to_str().unwrap(),
        ]);
        assert!(run.status.success(), "{}", stderr(&run));
        let err = stderr(&run);
        let ran: Vec<(String, String)> = err
            .lines()
            .skip_while(|line| !line.starts_with("node "))
            .skip(1)
            .take_while(|line| !line.contains("nodes evaluated"))
            .map(|line| {
                let c = columns(line);
                (c[0].clone(), c[1].clone())
            })
            .filter(|(_, label)| !label.starts_with("fused"))
            // A map streamed to its file is said so in the run's statistics only.
            .map(|(name, label)| (name, label.trim_end_matches(" rows → file").to_string()))
            .collect();
        assert!(ran.iter().any(|(_, label)| label.starts_with("channel")), "{maps}: a scale channel is run\n{err}");
        let listed = snakeskin(&["graph", species, "--maps", maps]);
        assert!(listed.status.success(), "{}", stderr(&listed));
        let listed: Vec<(String, String)> = stdout(&listed)
            .lines()
            .map(|line| {
                let c = columns(line.split(" <- ").next().unwrap());
                (c[0].clone(), c[1].clone())
            })
            .collect();
        for (name, label) in &ran {
            let shown = listed.iter().find(|(n, _)| n == name).map(|(_, l)| l);
            assert_eq!(shown, Some(label), "{maps}: node {name}");
        }
    }
}

#[test]
fn the_manifest_gives_the_height_maps_rise_and_the_normal_maps_convention_as_the_maps_are() {
    // `displacement.rise_texture_widths` and `normal_convention`, read back from the written maps
    // alone: the normal's tilt over the height's slope (both by finite differences of the
    // PNGs) is the rise, and the sign of its green against the height's slope down the image
    // is the convention (+Y up: green grows where the height falls towards the bottom). For
    // a plain set either way and for each pack with a normal texture and a height map or not.
    let dir = tempfile::tempdir().unwrap();
    let size = 256;
    let cases: [(&str, &[&str]); 4] = [
        ("opengl", &[]),
        ("directx", &["--normal-convention", "directx"]),
        ("unreal", &["--pack", "unreal"]),
        ("unity", &["--pack", "unity-hdrp"]),
    ];
    let mut rise_seen = None;
    for (name, extra) in cases {
        let out = dir.path().join(name);
        let mut args = vec!["generate", "crotalus-atrox", "-o", out.to_str().unwrap(), "--size", "256"];
        args.extend(extra);
        let run = snakeskin(&args);
        assert!(run.status.success(), "{}", stderr(&run));
        let manifest: serde_json::Value =
            serde_json::from_slice(&std::fs::read(out.join("crotalus-atrox.material.json")).unwrap()).unwrap();
        let rise = manifest["displacement"]["rise_texture_widths"].as_f64().unwrap();
        let normal = image::open(out.join("crotalus-atrox_normal.png")).unwrap().into_rgb8();
        // The height of the plain sets (the packs' is the same surface: the rise must agree).
        let height_file = dir.path().join("opengl/crotalus-atrox_height.png");
        let height = image::open(height_file).unwrap().into_luma16();
        let h = |x: u32, y: u32| height.get_pixel(x % size, y % size)[0] as f64 / 65535.0;
        let n = |x: u32, y: u32, c: usize| normal.get_pixel(x, y)[c] as f64 / 255.0 * 2.0 - 1.0;
        // Least squares of tilt = rise × slope (slopes per texture width), over every pixel.
        let (mut sx, mut xx, mut sy, mut yy) = (0.0, 0.0, 0.0, 0.0);
        for y in 0..size {
            for x in 0..size {
                let dh_du = (h(x + 1, y) - h(x + size - 1, y)) * size as f64 / 2.0;
                let dh_dv = (h(x, y + 1) - h(x, y + size - 1)) * size as f64 / 2.0;
                let (nx, ny, nz) = (n(x, y, 0), n(x, y, 1), n(x, y, 2));
                sx += -nx / nz * dh_du;
                xx += dh_du * dh_du;
                sy += ny / nz * dh_dv;
                yy += dh_dv * dh_dv;
            }
        }
        let (fitted_u, fitted_v) = (sx / xx, sy / yy);
        assert!((fitted_u / rise - 1.0).abs() < 0.05, "{name}: rise {rise}, the maps' {fitted_u}");
        // +Y up: the green is the slope down the image times the rise, +; +Y down: −.
        let convention = if fitted_v > 0.0 { "opengl" } else { "directx" };
        assert!((fitted_v.abs() / rise - 1.0).abs() < 0.05, "{name}: rise {rise}, the maps' along v {fitted_v}");
        assert_eq!(manifest["normal_convention"], convention, "{name}");
        assert_eq!(*rise_seen.get_or_insert(rise), rise, "{name}: the packs' rise is the set's");
    }
}
