//! The built-in preset library and the `presets` and `--set` commands.

mod common;

use common::*;
use snakeskin::preset::{library, parse, read_source};

#[test]
fn every_builtin_preset_parses_and_validates() {
    for name in library::names() {
        let loaded = parse(&read_source(name).unwrap(), &[]).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(loaded.preset.species.is_some(), "{name} names its species");
        assert!(!loaded.preset.sources.is_empty(), "{name} cites a source");
    }
}

#[test]
fn presets_list_prints_names_first_and_show_prints_toml() {
    let out = snakeskin(&["presets", "list"]);
    assert!(out.status.success());
    let listed: Vec<String> = stdout(&out).lines().map(|l| l.split_whitespace().next().unwrap().to_string()).collect();
    assert_eq!(listed, library::names());
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
