//! The built-in preset library and the `presets` and `--set` commands.

mod common;

use common::*;
use snakeskin::preset::{library, parse, read_source};

#[test]
fn every_builtin_preset_parses_and_validates() {
    for name in library::names() {
        let loaded = parse(&read_source(name).unwrap(), &[]).unwrap_or_else(|e| panic!("{name}: {e}"));
        let preset = &loaded.preset;
        let species = preset.species.as_deref().unwrap_or_else(|| panic!("{name} names its species"));
        assert_eq!(species.to_lowercase().replace(' ', "-"), name, "file name follows the species");
        assert!(preset.common_name.is_some(), "{name} has a common name");
        assert!(preset.category.is_some(), "{name} has a category");
        assert!(!preset.sources.is_empty(), "{name} cites a source");
        // A citation says where: a URL, or a publication with its year.
        for source in &preset.sources {
            let has_year = source.chars().collect::<Vec<_>>().windows(4).any(|w| w.iter().all(|c| c.is_ascii_digit()));
            assert!(source.contains("http") || has_year, "{name}: vague source {source:?}");
        }
    }
}

#[test]
fn every_file_in_presets_is_built_in() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/presets");
    let mut files: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|f| f.ends_with(".toml"))
        .map(|f| f.trim_end_matches(".toml").to_string())
        .collect();
    files.sort();
    assert_eq!(files, library::names());
    for name in library::names() {
        let on_disk = std::fs::read_to_string(format!("{dir}/{name}.toml")).unwrap();
        assert_eq!(library::get(name), Some(on_disk.as_str()), "{name}: the embedded copy is current");
    }
}

#[test]
fn the_library_covers_the_thesis_species_every_category_and_scale_type() {
    use snakeskin::preset::schema::{Category, ScaleShape};
    let required = [
        "Erythrolamprus miliaris",
        "Lampropeltis triangulum",
        "Philodryas olfersii",
        "Philodryas aestiva",
        "Phalotris lemniscatus",
        "Micrurus diastema",
        "Ptychophis flavovirgatus",
        "Bothrops alternatus",
        "Python regius",
        "Leiopython albertisii",
        "Xenopeltis unicolor",
        "Epicrates cenchria",
    ];
    let presets: Vec<_> =
        library::names().into_iter().map(|n| parse(&read_source(n).unwrap(), &[]).unwrap().preset).collect();
    assert!(presets.len() >= 20, "{} presets", presets.len());
    for species in required {
        assert!(presets.iter().any(|p| p.species.as_deref() == Some(species)), "{species} is missing");
    }
    for category in [
        Category::Solid,
        Category::VerticalStripe,
        Category::HorizontalStripe,
        Category::Spot,
        Category::Simple,
        Category::Complex,
    ] {
        assert!(presets.iter().any(|p| p.category == Some(category)), "no {category:?} preset");
    }
    for shape in [ScaleShape::Leaf, ScaleShape::Diamond, ScaleShape::Hexagon] {
        assert!(presets.iter().any(|p| p.scales.shape == shape), "no {shape:?} preset");
    }
    assert!(presets.iter().any(|p| p.scales.keeled) && presets.iter().any(|p| !p.scales.keeled));
    // The iridescent species have a film; most others do not.
    for species in ["Xenopeltis unicolor", "Epicrates cenchria", "Leiopython albertisii"] {
        let p = presets.iter().find(|p| p.species.as_deref() == Some(species)).unwrap();
        assert!(p.optics.film_thickness_nm > 0.0 && p.iridescence.spread_nm > 0.0, "{species} has no film");
    }
}

#[test]
fn every_preset_generates_and_no_two_look_alike() {
    use snakeskin::graph::evaluate;
    use snakeskin::maps::{BuildOptions, MapKind, build_graph};
    use snakeskin::optics::lab::linear_srgb_to_lab;
    let size = 48;
    let mut labs: Vec<(&str, Vec<[f64; 3]>)> = Vec::new();
    for name in library::names() {
        let preset = parse(&read_source(name).unwrap(), &[]).unwrap().preset;
        let maps = evaluate(&build_graph(&preset, BuildOptions::default()), &MapKind::ALL, size, size, &|_, _| {}).maps;
        assert_eq!(maps.len(), 5, "{name}");
        for image in maps.values() {
            assert!(image.data.iter().all(|v| v.is_finite()), "{name}: non-finite map value");
        }
        let color = &maps[&MapKind::Color];
        let lab =
            color.data.chunks_exact(3).map(|c| linear_srgb_to_lab([c[0] as f64, c[1] as f64, c[2] as f64])).collect();
        labs.push((name, lab));
    }
    // Mean per-pixel CIE76 difference of the colour maps: near-identical presets would be
    // close to 0; distinct species differ by tens of units.
    let mut closest = (f64::MAX, "", "");
    for (i, (a, la)) in labs.iter().enumerate() {
        for (b, lb) in &labs[i + 1..] {
            let d = la
                .iter()
                .zip(lb)
                .map(|(p, q)| ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt())
                .sum::<f64>()
                / la.len() as f64;
            if d < closest.0 {
                closest = (d, a, b);
            }
        }
    }
    eprintln!("closest pair: {} and {}, mean ΔE76 {:.1}", closest.1, closest.2, closest.0);
    assert!(closest.0 > 10.0, "{} and {} look alike (mean ΔE76 {:.1})", closest.1, closest.2, closest.0);
}

#[test]
fn presets_list_prints_names_first_and_show_prints_toml() {
    let out = snakeskin(&["presets", "list"]);
    assert!(out.status.success());
    let text = stdout(&out);
    let listed: Vec<String> = text.lines().skip(1).map(|l| l.split_whitespace().next().unwrap().to_string()).collect();
    assert_eq!(listed, library::names());
    // The library: at least 32 species, each with its own scientific name.
    let species: std::collections::BTreeSet<&str> = text.lines().skip(1).filter_map(|l| l.get(27..52)).collect();
    assert!(listed.len() >= 32 && species.len() == listed.len(), "{} presets, {} species", listed.len(), species.len());
    // Each line shows the common name and the category.
    let line = text.lines().find(|l| l.starts_with("crotalus-atrox")).unwrap();
    assert!(line.contains("Crotalus atrox") && line.contains("Western diamondback rattlesnake"), "{line}");
    assert!(line.trim_end().ends_with("simple"), "{line}");
    assert!(text.lines().any(|l| l.starts_with("micrurus-diastema") && l.trim_end().ends_with("horizontal_stripe")));
    let shown = snakeskin(&["presets", "show", "erythrolamprus-miliaris"]);
    assert!(shown.status.success());
    let text = stdout(&shown);
    let parsed: toml::Table = toml::from_str(&text).unwrap();
    assert_eq!(parsed["species"].as_str(), Some("Erythrolamprus miliaris"));
    assert_eq!(snakeskin(&["presets", "show", "nope"]).status.code(), Some(2));
}

#[test]
fn set_overrides_change_the_output_like_editing_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let edited = write_preset(dir.path(), "edited.toml", "seed = 3\n[scales]\nrows = 27\nshape = \"hexagon\"\n");
    let base = write_preset(dir.path(), "base.toml", "seed = 3\n");
    let a = dir.path().join("a");
    let b = dir.path().join("b");
    let run_a = snakeskin(&["generate", &edited, "-o", a.to_str().unwrap(), "--size", "64", "--maps", "height"]);
    let run_b = snakeskin(&[
        "generate",
        &base,
        "-o",
        b.to_str().unwrap(),
        "--size",
        "64",
        "--maps",
        "height",
        "--set",
        "scales.rows=27",
        "--set",
        "scales.shape=hexagon",
    ]);
    assert!(run_a.status.success() && run_b.status.success(), "{}{}", stderr(&run_a), stderr(&run_b));
    assert_eq!(std::fs::read(a.join("edited_height.png")).unwrap(), std::fs::read(b.join("base_height.png")).unwrap());
    // The control (a review: both ignoring the keys would pass the above): the base preset
    // without the overrides makes another height map.
    let c = dir.path().join("c");
    let run_c = snakeskin(&["generate", &base, "-o", c.to_str().unwrap(), "--size", "64", "--maps", "height"]);
    assert!(run_c.status.success(), "{}", stderr(&run_c));
    assert_ne!(std::fs::read(c.join("base_height.png")).unwrap(), std::fs::read(b.join("base_height.png")).unwrap());
}

/// A set says what made it beyond its preset: the manifest lists the `--set` overrides as
/// given (a set without any has no such key), and a key given twice is warned of, the last
/// value used. Before, neither: two sets with different overrides had manifests differing
/// only in `preset_hash`, and `--set a=1 --set a=2` said nothing.
/// `natrix-natrix`'s colour map generated into `dir/out` with `args` after the command's
/// own: its manifest and what it printed on stderr.
fn natrix_colour_set(dir: &std::path::Path, out: &str, args: &[&str]) -> (serde_json::Value, String) {
    let folder = dir.join(out);
    let mut all = vec!["generate", "natrix-natrix", "-o", folder.to_str().unwrap(), "--size", "32", "--maps", "color"];
    all.extend(args);
    let run = snakeskin(&all);
    assert!(run.status.success(), "{}", stderr(&run));
    let manifest = std::fs::read_to_string(folder.join("natrix-natrix.material.json")).unwrap();
    (serde_json::from_str::<serde_json::Value>(&manifest).unwrap(), stderr(&run))
}

#[test]
fn the_manifest_records_the_overrides_and_a_repeated_key_is_warned_of() {
    let dir = tempfile::tempdir().unwrap();
    let generate = |out: &str, sets: &[&str]| {
        let args: Vec<&str> = sets.iter().flat_map(|s| ["--set", s]).collect();
        natrix_colour_set(dir.path(), out, &args)
    };
    let (twice, err) = generate("twice", &["scales.rows=10", "scales.rows=20"]);
    let (once, quiet) = generate("once", &["scales.rows=20"]);
    let (none, _) = generate("none", &[]);
    assert_eq!(twice["overrides"], serde_json::json!(["scales.rows=10", "scales.rows=20"]));
    assert_eq!(once["overrides"], serde_json::json!(["scales.rows=20"]));
    assert!(none.get("overrides").is_none(), "{none}");
    assert_eq!(twice["preset_hash"], once["preset_hash"]);
    assert!(err.contains("warning: --set scales.rows is given 2 times: the last, scales.rows=20, is used"), "{err}");
    assert!(!quiet.contains("given"), "{quiet}");
    // Another key that writes the same one (an inline table, a list replacing a key inside
    // it; silent before: a hostile-input sweep, a review), either way round, said once.
    for (sets, key) in [
        (&["scales.rows=20", "scales={rows=30}"][..], "scales.rows"),
        (&["scales={rows=30}", "scales.rows=20"], "scales.rows"),
        (&["pattern.0.opacity=0.3", "pattern=[{kind=\"spots\",color=\"#000000\"}]"], "pattern.0.opacity"),
        // A table over the list replaces it whole too (a second review).
        (&["pattern.0.opacity=0.3", "pattern={kind=\"spots\",color=\"#000000\"}"], "pattern.0.opacity"),
    ] {
        let (_, err) = generate("table", sets);
        let said =
            format!("warning: --set {} is not used for `{key}`: the later --set {} sets it again", sets[0], sets[1]);
        assert!(err.contains(&said), "{sets:?}: {err}");
        assert_eq!(err.matches("warning: --set").count(), 1, "{sets:?}: {err}");
    }
    // Three of one key: one warning, naming the last; an empty list replaced by a list; a
    // repeated key then a table: one line; the seed, where --seed does not override it (it
    // was said to be used and not used: a second review).
    for (sets, said) in [
        (
            &["scales.rows=20", "scales.rows=25", "scales.rows=30"][..],
            "--set scales.rows is given 3 times: the last, scales.rows=30, is used",
        ),
        (
            &["pattern=[]", "pattern=[{kind=\"spots\",color=\"#000000\"}]"],
            "--set pattern is given 2 times: the last, pattern=[{kind=\"spots\",color=\"#000000\"}], is used",
        ),
        (
            &["scales.rows=20", "scales.rows=20", "scales={rows=30}"],
            "--set scales.rows=20 is not used for `scales.rows`: the later --set scales={rows=30} sets it again",
        ),
        (&["seed=1", "seed=2"], "--set seed is given 2 times: the last, seed=2, is used"),
    ] {
        let (_, err) = generate("three", sets);
        assert!(err.contains(&format!("warning: {said}")), "{sets:?}: {err}");
        assert_eq!(err.matches("warning: --set").count(), 1, "{sets:?}: {err}");
    }
    let (_, err) = natrix_colour_set(dir.path(), "seeded", &["--seed", "5", "--set", "seed=1", "--set", "seed=2"]);
    assert!(err.contains("warning: --set seed=2 is not used: --seed 5 overrides it"), "{err}");
    assert_eq!(err.matches("warning: --set").count(), 1, "{err}");
    // The controls, nothing said: tables of one key merge; a key inside a list after the list
    // changes it.
    for sets in [
        &["scales.rows=20", "scales={keeled=true}"][..],
        &["scales={rows=30}", "scales={keeled=true}"],
        &["pattern=[{kind=\"spots\",color=\"#000000\"}]", "pattern.0.opacity=0.3"],
    ] {
        let (_, err) = generate("apart", sets);
        assert!(!err.contains("warning: --set"), "{sets:?}: {err}");
    }
}

/// `--seed` wins over `--set seed=`, and says so where they differ (`--seed 5 --set seed=6`
/// ran silently with seed 5, the manifest listing `seed=6` beside it: a hostile-input sweep).
/// Controls: the same seed both ways, and the override alone, say nothing.
#[test]
fn a_seed_override_that_seed_overrides_is_warned_of() {
    let dir = tempfile::tempdir().unwrap();
    let generate = |name: &str, args: &[&str]| {
        let (manifest, err) = natrix_colour_set(dir.path(), name, args);
        (manifest["seed"].clone(), err)
    };
    let (seed, err) = generate("both", &["--seed", "5", "--set", "seed=6"]);
    assert_eq!(seed, 5);
    assert!(err.contains("warning: --set seed=6 is not used: --seed 5 overrides it"), "{err}");
    for (name, args) in [("same", &["--seed", "6", "--set", "seed=6"][..]), ("set", &["--set", "seed=6"][..])] {
        let (seed, err) = generate(name, args);
        assert_eq!(seed, 6);
        assert!(!err.contains("seed"), "{name}: {err}");
    }
}

#[test]
fn docs_presets_md_documents_every_key() {
    // Every key of a fully populated preset must appear in the docs, as `key`.
    let docs = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/presets.md")).unwrap();
    let preset: snakeskin::preset::Preset = toml::from_str(&std::fs::read_to_string(PATTERNED).unwrap()).unwrap();
    let mut full = toml::Table::try_from(&preset).unwrap();
    full.insert("species".into(), "x".into());
    full.insert("common_name".into(), "x".into());
    full.insert("category".into(), "solid".into());
    fn keys(table: &toml::Table, out: &mut Vec<String>) {
        for (k, v) in table {
            out.push(k.clone());
            match v {
                toml::Value::Table(t) => keys(t, out),
                toml::Value::Array(items) => items.iter().filter_map(|i| i.as_table()).for_each(|t| keys(t, out)),
                _ => {}
            }
        }
    }
    let mut all = Vec::new();
    keys(&full, &mut all);
    assert!(all.len() > 40, "walked the schema: {all:?}");
    for key in all {
        assert!(
            docs.contains(&format!("`{key}`"))
                || docs.contains(&format!("[{key}]"))
                || docs.contains(&format!("[[{key}]]")),
            "docs/presets.md lacks `{key}`"
        );
    }
}
