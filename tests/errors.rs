//! Bad input: a clear message (file, line, key, what is accepted), exit code 2, and no change
//! on disk — no new file, and an earlier output of the same name untouched.

mod common;

use common::*;

/// Runs `generate` with `preset` into a folder that already holds an earlier output named
/// like the preset's; asserts exit 2 and an unchanged folder; returns stderr.
fn refused(preset_name: &str, preset_text: &str, extra: &[&str]) -> String {
    let dir = tempfile::tempdir().unwrap();
    let presets = tempfile::tempdir().unwrap();
    let path = write_preset(presets.path(), preset_name, preset_text);
    let stem = preset_name.trim_end_matches(".toml");
    std::fs::write(dir.path().join(format!("{stem}_color.png")), b"earlier output").unwrap();
    let before = snapshot(dir.path());
    let out_dir = dir.path().to_str().unwrap();
    let mut args = vec!["generate", path.as_str(), "-o", out_dir];
    if !extra.contains(&"--size") {
        args.extend(["--size", "64"]);
    }
    args.extend_from_slice(extra);
    let out = snakeskin(&args);
    assert_eq!(out.status.code(), Some(2), "stderr: {}", stderr(&out));
    assert_eq!(snapshot(dir.path()), before, "the output folder changed");
    stderr(&out)
}

/// Runs `generate` with `preset` (a path or a built-in name) at 16 pixels into a new
/// folder and asserts that it succeeds (the negative controls of the refusals).
fn accepted(preset: &str, extra: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let args = [&["generate", preset, "-o", dir.path().to_str().unwrap(), "--size", "16"][..], extra].concat();
    let out = snakeskin(&args);
    assert!(out.status.success(), "{preset} {extra:?}: {}", stderr(&out));
}

/// A scales, body or belly key that shapes what another draws is refused without it, with its line
/// (they passed silently, where a pattern layer refuses a key its kind does not read).
/// Negative controls: each beside its partner is accepted.
#[test]
fn a_key_without_the_key_it_shapes_is_refused() {
    for (text, says, with) in [
        (
            "[body]\ntail_band_width = 0.3\n",
            "b.toml:2: key `body.tail_band_width` shapes the bands",
            "tail_bands = 4\n",
        ),
        ("[body]\ntail_band_color = \"#ff0000\"\n", "b.toml:2: key `body.tail_band_color` shapes", "tail_bands = 4\n"),
        (
            "[body]\ntail_band_over_belly = true\n",
            "b.toml:2: key `body.tail_band_over_belly` shapes",
            "tail_bands = 4\n",
        ),
        ("[body]\ntip_fraction = 0.3\n", "b.toml:2: key `body.tip_fraction` sizes what", "tip_color = \"#ffffff\"\n"),
        (
            "[body]\ntail_shift_start = 0.3\n",
            "b.toml:2: key `body.tail_shift_start` starts",
            "tail_color = \"#aa2200\"\n",
        ),
        (
            "[body]\nbelly_front_end = 0.3\n",
            "b.toml:2: key `body.belly_front_end` ends what",
            "belly_front_color = \"#d8c068\"\n",
        ),
        (
            "[body]\nbelly_front_color = \"#d8c068\"\n[belly]\nwidth = 0\n",
            "b.toml:2: key `body.belly_front_color` colours the front of the belly",
            "",
        ),
        (
            "[body]\nsubcaudal_color = \"#101010\"\n[belly]\nwidth = 0\n",
            "b.toml:2: key `body.subcaudal_color` colours the underside",
            "",
        ),
        ("[belly]\nup_rows = 2\nplates = false\n", "b.toml:2: key `belly.up_rows` runs the belly", ""),
        ("[scales]\nkeel_height = 0.7\n", "b.toml:2: key `scales.keel_height` shapes the keels", "keeled = true\n"),
        ("[scales]\nkeel_width = 0.2\n", "b.toml:2: key `scales.keel_width` shapes the keels", "keeled = true\n"),
        ("[scales]\nsmooth_rows = 1\n", "b.toml:2: key `scales.smooth_rows` shapes the keels", "keeled = true\n"),
        ("[roughness]\nkeel = 0.4\n[scales]\n", "b.toml:2: key `roughness.keel` shapes the keels", "keeled = true\n"),
    ] {
        let err = refused("b.toml", text, &[]);
        assert!(err.contains(says), "{text}: {err}");
        let dir = tempfile::tempdir().unwrap();
        // Without a partner to add, the text's own partner is turned on.
        let partnered = if with.is_empty() {
            text.replace("plates = false", "plates = true").replace("width = 0\n", "width = 0.2\n")
        } else {
            format!("{text}{with}")
        };
        accepted(&write_preset(dir.path(), "b.toml", &partnered), &[]);
    }
    // An override that turns a built-in's partner off passes over the keys its file wrote
    // for it (they were refused, at a line of a file the user cannot edit); one that writes
    // the key itself without its partner is refused.
    accepted("crotalus-atrox", &["--set", "body.tail_bands=0"]);
    accepted("corallus-caninus", &["--set", "belly.plates=false"]);
    accepted("bitis-arietans", &["--set", "scales.keeled=false"]);
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().to_str().unwrap();
    let out =
        snakeskin(&["generate", "natrix-natrix", "-o", out_dir, "--size", "16", "--set", "body.tip_fraction=0.3"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("(with --set): key `body.tip_fraction` sizes what"), "{}", stderr(&out));
}

/// An absorption list of the wrong length says its length (any longer list said 4).
/// Negative control: three numbers are accepted.
#[test]
fn an_absorption_list_of_the_wrong_length_says_its_length() {
    for (list, length) in [("[1, 2]", 2), ("[1, 2, 3, 4, 5]", 5), ("[1, 2, 3, 4, \"x\"]", 5)] {
        let err = refused("a.toml", &format!("[optics]\nabsorption = {list}\n"), &[]);
        let says = format!("invalid length {length}, expected a number or [r, g, b]");
        assert!(err.contains(&says) && err.contains("optics.absorption"), "{list}: {err}");
    }
    let dir = tempfile::tempdir().unwrap();
    accepted(&write_preset(dir.path(), "a.toml", "[optics]\nabsorption = [1, 2, 3]\n"), &[]);
}

#[test]
fn toml_syntax_error_names_file_and_line() {
    let err = refused("broken.toml", "seed = 1\n\n[scales]\nrows = = 3\n", &[]);
    assert!(err.contains("broken.toml:4:"), "{err}");
}

/// A wrong type names the line, the dotted key and what is accepted in words, not in
/// serde's Rust types (`seed = "x"` said only `invalid type: string "x", expected u64`).
#[test]
fn type_error_names_line_and_key() {
    let err = refused("typed.toml", "seed = 1\n[scales]\nrows = \"many\"\n", &[]);
    assert!(err.contains("typed.toml:3:"), "{err}");
    // With the key's range, as a number with a fraction says it (it said "expected a whole
    // number" alone).
    assert!(
        err.trim_end()
            .ends_with("key `scales.rows`: invalid type: string \"many\", expected a whole number in [4, 128]"),
        "{err}"
    );
    assert!(!err.contains("u32"), "{err}");
    let err = refused("typed.toml", "[scales]\nrows = true\n", &[]);
    assert!(err.trim_end().ends_with("expected a whole number in [4, 128]"), "{err}");
    let err = refused("seed.toml", "seed = \"x\"\n", &[]);
    assert!(err.contains("seed.toml:1:") && err.contains("key `seed`"), "{err}");
    // Inside an array of tables and an array: the layer's index and the item's.
    let text = "[[pattern]]\nkind = \"solid\"\ncolor = \"#102030\"\n[[pattern]]\nkind = \"rings\"\ncolors = [\"#ffffff\", 7]\n";
    let err = refused("nested.toml", text, &[]);
    assert!(err.contains("key `pattern.1.colors.1`") && err.contains("expected a colour \"#rrggbb\""), "{err}");
    // A colour that is a string but not a colour, in a list over several lines: its own line
    // and index (it named the list's opening bracket, without the index; a hostile-input
    // sweep), as a number in `widths` is named.
    let text = "[[pattern]]\nkind = \"rings\"\ncolor = \"#101010\"\ncolors = [\n \"#101010\",\n \"#zz0000\",\n]\n";
    let err = refused("lines.toml", text, &[]);
    assert!(
        err.contains("lines.toml:6:") && err.contains("key `pattern.0.colors.1`: invalid colour \"#zz0000\""),
        "{err}"
    );
    // A single `[pattern]` table is layer 0, as the range checks name it.
    let err = refused("one.toml", "[pattern]\nkind = \"spots\"\ncolor = \"#000000\"\namount = \"x\"\n", &[]);
    assert!(err.contains("key `pattern.0.amount`") && err.contains("expected a number"), "{err}");
    // An integer out of the type's range says the range, not "a whole number" alone, in the
    // range check's words (`whole_number_range`).
    let err = refused("negative.toml", "seed = -1\n", &[]);
    assert!(err.contains("key `seed`: must be an integer in [0, 9007199254740991], got -1"), "{err}");
    // Beyond i64, the same words (toml said "integer `…` as i128").
    let err = refused(
        "huge.toml",
        "seed = 99999999999999999999
",
        &[],
    );
    assert!(err.contains("must be an integer in [0, 9007199254740991], got 99999999999999999999"), "{err}");
    assert!(!err.contains("i128"), "{err}");
    // Not a whole number: the key's range (4 to 128), not the type's (0 to 4294967295).
    let err = refused("rows.toml", "[scales]\nrows = 4.0\n", &[]);
    assert!(
        err.contains("key `scales.rows`") && err.trim_end().ends_with("expected a whole number in [4, 128]"),
        "{err}"
    );
    let err = refused("table.toml", "scales = 5\n", &[]);
    assert!(err.contains("key `scales`") && err.contains("expected a table"), "{err}");
    let err = refused("float.toml", "[optics]\nfilm_ior = true\n", &[]);
    assert!(err.contains("key `optics.film_ior`") && err.contains("expected a number"), "{err}");
    // Of several overrides, the one at fault is named.
    let err =
        refused("ok.toml", "seed = 1\n", &["--set", "scales.size=1.1", "--set", "scales.rows=1.5", "--set", "seed=3"]);
    assert!(err.contains("invalid --set \"scales.rows=1.5\":"), "{err}");
    assert!(err.trim_end().ends_with("expected a whole number in [4, 128]"), "{err}");
}

/// An array where a table belongs is refused with its key and line, not read field by
/// field: serde's derived structs also read a sequence in field order, so `scales =
/// ["diamond", 40]` made diamond scales in 40 rows, `optics = [1.33]` set the first index
/// of refraction and `belly = []` passed as the defaults, all silently; `scales = [19]` was
/// refused as `scales.0`, and `[[scales]]` too, a key no preset has.
#[test]
fn an_array_where_a_table_belongs_is_refused_not_read_in_field_order() {
    for (text, line, key) in [
        ("scales = [\"diamond\", 40]\n", 1, "scales"),
        ("seed = 3\noptics = [1.33]\n", 2, "optics"),
        ("belly = []\n", 1, "belly"),
        ("[[scales]]\nrows = 19\n", 1, "scales"),
        ("pattern = [[\"stripes\", \"#000000\"]]\n", 1, "pattern.0"),
        ("[body]\nhead_mark = [[\"cap\", \"#000000\"]]\n", 2, "body.head_mark.0"),
        // An item that is an array inside an inline array is the item's fault, not its list's.
        ("pattern = [[[\"stripes\"]]]\n", 1, "pattern.0"),
    ] {
        let err = refused("arrays.toml", text, &[]);
        assert!(err.contains(&format!("arrays.toml:{line}:")), "{text:?}: {err}");
        assert!(err.contains(&format!("key `{key}`: invalid type: array, expected a table")), "{text:?}: {err}");
    }
    let err = refused("ok.toml", "seed = 1\n", &["--set", "optics=[1.2, 1.5, 1.8]"]);
    assert!(err.contains("invalid --set \"optics=[1.2, 1.5, 1.8]\": invalid type: array, expected a table"), "{err}");
    // Negative controls: the same keys as tables, arrays of tables where they belong, and
    // the jobs file's `[[job]]` tables (its `job = [[…]]` is refused: `tests/batch.rs`).
    let dir = tempfile::tempdir().unwrap();
    let tables = "scales = { shape = \"diamond\", rows = 41 }\n[optics]\nambient_ior = 1.33\n[belly]\n\
                  [[pattern]]\nkind = \"solid\"\ncolor = \"#102030\"\n[[body.head_mark]]\nkind = \"cap\"\n\
                  color = \"#000000\"\n";
    accepted(&write_preset(dir.path(), "tables.toml", tables), &[]);
    accepted("natrix-natrix", &["--set", "optics={ambient_ior = 1.2}"]);
}

/// A stripe placed twice is refused, not one placement silently dropped: `position` sets the
/// offset (`position = "lateral"` beside `offset = 0.1` drew the lateral stripe, the same
/// bytes as with `offset = 0.24`), and `rows` sets the offset, width and count.
/// Negative controls: each key alone, and `position` with a width and count.
#[test]
fn a_stripe_placed_twice_is_refused() {
    let layer = |extra: &str| format!("[[pattern]]\nkind = \"stripes\"\ncolor = \"#101010\"\n{extra}\n");
    for (extra, key, by) in [
        ("position = \"lateral\"\noffset = 0.1", "offset", "position"),
        ("rows = [9.5, 10]\noffset = 0.1", "offset", "rows"),
        ("rows = [9.5, 10]\nposition = \"vertebral\"", "position", "rows"),
        ("rows = [9.5, 10]\nsize = 0.02", "size", "rows"),
        ("rows = [9.5, 10]\namount = 2", "amount", "rows"),
    ] {
        let err = refused("twice.toml", &layer(extra), &[]);
        let says = format!("twice.toml:5: key `pattern.0.{key}` is replaced by this layer's `{by}`");
        assert!(err.contains(&says), "{extra}: {err}");
    }
    let dir = tempfile::tempdir().unwrap();
    for extra in [
        "position = \"lateral\"",
        "offset = 0.1",
        "rows = [9.5, 10]",
        "position = \"lateral\"\nsize = 0.02\namount = 2",
    ] {
        accepted(&write_preset(dir.path(), "once.toml", &layer(extra)), &[]);
    }
    // The refusal says the way out from the command line, and it works: `--set` gives the
    // file's key its default, which counts as none.
    let err = refused("twice.toml", &layer("rows = [9.5, 10]\nsize = 0.02"), &[]);
    assert!(err.contains("give one of the two (its default, 0.05, counts as none; `rows = []`"), "{err}");
    let twice = write_preset(dir.path(), "twice.toml", &layer("rows = [9.5, 10]\nsize = 0.02"));
    accepted(&twice, &["--set", "pattern.0.size=0.05"]);
    accepted(&twice, &["--set", "pattern.0.rows=[]"]);
    let err = refused("placed.toml", &layer("rows = [9.5, 10]\nposition = \"vertebral\""), &[]);
    assert!(err.contains("give one of the two (`rows = []` counts as no rows)"), "{err}");
}

/// Stripes that reach past the belly's midline wrap round onto the other side's: 16 a side
/// at the default size made the whole body one colour, without a word (a hostile-input
/// sweep). Refused on `amount`'s line with the most that fit; negative controls: that many
/// is accepted, and so are stripes placed by rows (which `amount` does not place).
#[test]
fn stripes_that_wrap_round_the_body_are_refused() {
    let layer = |extra: &str| format!("[[pattern]]\nkind = \"stripes\"\ncolor = \"#101010\"\n{extra}\n");
    // Size 0.05 from the spine: centres 0, ±0.15, ±0.30, ±0.45 (edge 0.475): four fit.
    let err = refused("wrap.toml", &layer("amount = 5"), &[]);
    assert!(err.contains("wrap.toml:4: key `pattern.0.amount` is 5 stripes a side"), "{err}");
    assert!(err.contains("past the belly's midline (0.5)") && err.contains("at most 4 a side"), "{err}");
    let err = refused("wrap.toml", &layer("amount = 2\nposition = \"lateral\"\nsize = 0.1"), &[]);
    assert!(err.contains("at most 1 a side"), "{err}");
    // One stripe only meets its own mirror image at the midline (a review found a single
    // stripe at the documented largest offset, 0.5, refused): accepted.
    let dir = tempfile::tempdir().unwrap();
    for extra in ["amount = 4", "amount = 1\nposition = \"lateral\"\nsize = 0.1", "rows = [1, 2]", "offset = 0.5"] {
        accepted(&write_preset(dir.path(), "fits.toml", &layer(extra)), &[]);
    }
}

/// A ring `size` beside `colors` is refused: the sequence's widths replace it (it gave the
/// same bytes as without it). Negative controls: either alone is accepted.
#[test]
fn a_ring_size_beside_its_colours_is_refused() {
    let layer = |extra: &str| format!("[[pattern]]\nkind = \"rings\"\ncolor = \"#101010\"\n{extra}\n");
    let err = refused("rings.toml", &layer("colors = [\"#101010\", \"#e0c020\"]\nsize = 0.3"), &[]);
    assert!(err.contains("rings.toml:5: key `pattern.0.size` is replaced by this layer's `colors`"), "{err}");
    let dir = tempfile::tempdir().unwrap();
    for extra in ["colors = [\"#101010\", \"#e0c020\"]", "size = 0.3"] {
        accepted(&write_preset(dir.path(), "once.toml", &layer(extra)), &[]);
    }
}

/// One bad value is one problem: a row count out of its range was reported, and then the
/// keys it bounds as well, against a range made from it (`belly.up_rows` "must be an
/// integer in [0, 0]", a key the user had not touched); a body fraction out of its range
/// also failed a check of the fractions' sum, named `body.tail_fraction`. Negative control:
/// with the rows in range, an `up_rows` past half of them is refused.
#[test]
fn one_bad_value_is_one_problem() {
    let err = refused("body.toml", "[body]\nhead_fraction = 0.7\n", &[]);
    assert!(err.contains("key `body.head_fraction`") && !err.contains("body.tail_fraction"), "{err}");
    let err = refused("rows.toml", "[scales]\nrows = 1\n[belly]\nup_rows = 1\n", &[]);
    assert!(err.contains("key `scales.rows` must be an integer in [4, 128], got 1"), "{err}");
    assert!(!err.contains("belly.up_rows"), "{err}");
    let stripe = "[scales]\nrows = 1\n[[pattern]]\nkind = \"stripes\"\ncolor = \"#101010\"\nrows = [9.5, 10]\n";
    let err = refused("rows.toml", stripe, &[]);
    assert!(err.contains("scales.rows") && !err.contains("pattern.0.rows"), "{err}");
    // A value no row count allows is still refused beside it, against the most rows allowed.
    let err = refused("rows.toml", "[scales]\nrows = 1\nsmooth_rows = 5000\n", &[]);
    assert!(err.contains("key `scales.smooth_rows` must be an integer in [0, 64], got 5000"), "{err}");
    let err = refused("rows.toml", "[scales]\nrows = 9\n[belly]\nup_rows = 5\n", &[]);
    assert!(err.contains("key `belly.up_rows` must be an integer in [0, 4], got 5"), "{err}");
}

/// `snakeskin brdf film --batch -` with `input` on its standard input.
fn film_batch(input: &[u8]) -> std::process::Output {
    use std::io::Write;
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_snakeskin"))
        .args(["brdf", "film", "--batch", "-"])
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    child.stdin.take().unwrap().write_all(input).unwrap();
    child.wait_with_output().unwrap()
}

/// A refused number far from its range is printed as written, not in full: `film_ior =
/// 1e300` printed three hundred digits, an angle of -1e-300 (then `--angle-deg`, now a
/// `brdf film --batch` line: the flag is refused by clap as written) a "-0.000…" as long.
#[test]
fn a_number_far_out_of_range_is_printed_short() {
    let text = "seed = 1\n[optics]\nfilm_ior = 1e300\n";
    let err = refused("huge.toml", text, &[]);
    assert!(err.contains("must be a finite number in [1, 3], got 1e300"), "{err}");
    assert!(err.len() < 400, "{err}");
    let out = film_batch(b"{\"thickness_nm\": 400, \"wavelength_nm\": 550, \"angle_deg\": -1e-300}\n");
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("-:1: angle_deg must be in [0, 90], got -1e-300"), "{}", stderr(&out));
    assert!(stderr(&out).len() < 200, "{}", stderr(&out));
    // Negative control: a value near its range is printed plainly.
    assert!(refused("near.toml", "seed = 1\n[optics]\nfilm_ior = 3.5\n", &[]).contains("got 3.5"));
}

/// A number nearer 0 than a 64-bit float holds was read as 0 without a word, where one too
/// large is refused: `between_scales = 1e-400` drew what 0 draws, `size = 2.4e-400` said "got
/// 0", a number never written. It is refused with its line and key in a preset, in `--set`,
/// in a jobs file and on a `brdf --batch` line. Negative controls: 0 written out, and the
/// smallest float.
#[test]
fn a_number_that_underflows_is_refused_not_read_as_zero() {
    let says = "`1e-400` is nearer 0 than a 64-bit float holds";
    let err = refused("tiny.toml", "seed = 1\n[color]\nbetween_scales = 1e-400\n", &[]);
    assert!(
        err.contains("tiny.toml:3:18") && err.contains("key `color.between_scales`") && err.contains(says),
        "{err}"
    );
    let err = refused("list.toml", "[optics]\nabsorption = [0.1, 1e-400, 0.2]\n", &[]);
    assert!(err.contains("list.toml:2:") && err.contains("key `optics.absorption.1`") && err.contains(says), "{err}");
    let err = refused("plain.toml", "seed = 1\n", &["--set", "color.between_scales=1e-400"]);
    assert!(err.contains("invalid --set \"color.between_scales=1e-400\"") && err.contains(says), "{err}");
    let dir = tempfile::tempdir().unwrap();
    let jobs = dir.path().join("jobs.toml");
    std::fs::write(&jobs, "[[job]]\npreset = \"natrix-natrix\"\nset = { \"scales.size\" = 1e-400 }\n").unwrap();
    let out = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", dir.path().join("out").to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("jobs.toml:3:") && stderr(&out).contains(says), "{}", stderr(&out));
    assert!(!dir.path().join("out").exists());
    let lines = b"{\"thickness_nm\": 5e-324, \"wavelength_nm\": 550, \"angle_deg\": 0}\n\
                  {\"thickness_nm\": 1e-400, \"wavelength_nm\": 550, \"angle_deg\": 0}\n";
    let out = film_batch(lines);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("-:2: ") && stderr(&out).contains(says), "{}", stderr(&out));
    assert_eq!(String::from_utf8_lossy(&out.stdout).lines().count(), 1, "the first line's answer");
    // Negative controls: 0 however written, and the smallest float, are numbers.
    accepted("natrix-natrix", &["--set", "color.between_scales=0e-400", "--set", "optics.absorption=5e-324"]);
    let presets = tempfile::tempdir().unwrap();
    let path = write_preset(presets.path(), "zero.toml", "seed = 1\n[color]\nbetween_scales = 0.000e-400\n");
    accepted(&path, &[]);
}

/// A whole number the key's type cannot hold (negative, or past 2³²) is refused with the
/// key's range, the one the range check gives a whole number in the type's (it said "from 0
/// to 4294967295", the type's range). Each key is checked both ways, so the two ranges are
/// the same by test, not only by construction.
#[test]
fn a_whole_number_beyond_its_type_gets_the_keys_range() {
    let range =
        |err: &str| err.split("must be an integer in ").nth(1).map(|r| r.split(']').next().unwrap().to_string());
    for (key, inside_the_type) in [
        ("scales.rows", "200"),
        ("scales.smooth_rows", "100"),
        ("belly.up_rows", "100"),
        ("body.ventrals", "9000"),
        ("body.subcaudals", "9000"),
        ("body.tail_bands", "9000"),
        ("pattern.0.count", "9000"),
    ] {
        let preset = "seed = 1\n\n[[pattern]]\nkind = \"blotches\"\ncolor = \"#202020\"\n";
        let checked = refused("r.toml", preset, &["--set", &format!("{key}={inside_the_type}")]);
        for beyond in ["-3", "5000000000", "99999999999999999999"] {
            let err = refused("r.toml", preset, &["--set", &format!("{key}={beyond}")]);
            assert!(err.contains(&format!("got {beyond}")) && !err.contains("4294967295"), "{key}={beyond}: {err}");
            let (beyond_range, checked_range) = (range(&err), range(&checked));
            assert!(beyond_range.is_some(), "{key}={beyond}: {err}");
            if key.ends_with("_rows") {
                assert_eq!(beyond_range.as_deref(), Some("[0, scales.rows / 2"), "{err}");
            } else {
                assert_eq!(beyond_range, checked_range, "{key}: {err} / {checked}");
            }
        }
    }
    // A quoted number is a string, and said so (not "got 21" for a value in range).
    let err = refused("q.toml", "seed = 1\n", &["--set", "scales.rows=\"21\""]);
    assert!(err.contains("invalid type: string \"21\"") && !err.contains("must be an integer"), "{err}");
    // In a file, with its line; a jobs file's size too.
    let err = refused("w.toml", "seed = 1\n[scales]\nrows = -3\n", &[]);
    assert!(err.contains("w.toml:3:8: key `scales.rows`: must be an integer in [4, 128], got -3"), "{err}");
    let dir = tempfile::tempdir().unwrap();
    let jobs = dir.path().join("jobs.toml");
    std::fs::write(&jobs, "[[job]]\npreset = \"natrix-natrix\"\nsizes = [-64]\n").unwrap();
    let out = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", dir.path().join("out").to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("key `sizes`: size -64: accepted sizes are 16 to 16384 pixels"), "{}", stderr(&out));
    // A seed its type cannot hold, in the seed's range (before: the type's, 0 to 2^64 - 1).
    std::fs::write(&jobs, "[[job]]\npreset = \"natrix-natrix\"\nseeds = [1, -1]\n").unwrap();
    let out = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", dir.path().join("out").to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out)
            .contains("jobs.toml:3:13: [[job]] 1: key `seeds`: seed -1: accepted seeds are 0 to 9007199254740991"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn unknown_key_is_named_with_a_suggestion() {
    let err = refused("typo.toml", "seed = 1\n[optics]\nfilm_iro = 1.4\n", &[]);
    assert!(err.contains("typo.toml:3:"), "{err}");
    assert!(err.contains("`film_iro`"), "{err}");
    assert!(err.contains("did you mean `film_ior`"), "{err}");
    // A look-alike letter (Cyrillic `а`, U+0430) is not a letter TOML's bare keys accept:
    // the message names it (before: "invalid unquoted key" alone, the key looking right).
    let err = refused("lookalike.toml", "[sc\u{430}les]\nrows = 19\n", &[]);
    assert!(err.contains("lookalike.toml:1:4:") && err.contains("`\u{430}` (U+0430) is not ASCII"), "{err}");
}

#[test]
fn unknown_enum_value_lists_what_is_accepted() {
    let err = refused("shape.toml", "[scales]\nshape = \"round\"\n", &[]);
    assert!(err.contains("shape.toml:2:"), "{err}");
    assert!(err.contains("leaf") && err.contains("diamond") && err.contains("hexagon"), "{err}");
    let err = refused("kind.toml", "[[pattern]]\nkind = \"spot\"\ncolor = \"#000000\"\n", &[]);
    assert!(
        err.contains("kind.toml:2:8: key `pattern.0.kind`: unknown value \"spot\"; did you mean \"spots\"?"),
        "{err}"
    );
    // Spots and blotches take different shapes: the one list offered `ring` to a blotches
    // layer, which then refused it.
    let err = refused("blotch.toml", "[[pattern]]\nkind = \"blotches\"\ncolor = \"#000000\"\nshape = \"rnd\"\n", &[]);
    assert!(
        err.contains(
            "(accepted: for spots round, ring; for blotches round, diamond, saddle, chevron, hourglass, zigzag)"
        ),
        "{err}"
    );
}

/// Every layer needs its colour, named at its table when it is missing; but a rings layer
/// with a `colors` sequence draws those and needs no `color` (it was required and unread).
#[test]
fn a_layer_needs_its_colour_but_a_ring_sequence_draws_its_own() {
    let err = refused("spots.toml", "seed = 1\n[[pattern]]\nkind = \"spots\"\n", &[]);
    assert!(
        err.contains("spots.toml:2: key `pattern.0.color` is missing: give the layer's colour as \"#rrggbb\""),
        "{err}"
    );
    let err = refused("rings.toml", "seed = 1\n[[pattern]]\nkind = \"rings\"\n", &[]);
    assert!(err.contains("rings.toml:2: key `pattern.0.color` is missing") && err.contains("in `colors`)"), "{err}");
    // A layer an override made is placed at the override (it said "missing field `color`").
    let err = refused("plain.toml", "seed = 1\n", &["--set", "pattern.0.kind=spots"]);
    assert!(err.contains("plain.toml (with --set): key `pattern.0.color` is missing"), "{err}");
    // A sequence: the same colour map with a `color` beside it or without one, and no
    // warning about a colour that is not drawn (white is past what the stack shows).
    let dir = tempfile::tempdir().unwrap();
    let sequence = "seed = 1\n[[pattern]]\nkind = \"rings\"\ncolors = [\"#101010\", \"#e0c030\"]\n";
    let colour_map = |name: &str, text: &str| {
        let path = write_preset(dir.path(), name, text);
        let out_dir = dir.path().join(name.trim_end_matches(".toml"));
        let args = ["generate", path.as_str(), "-o", out_dir.to_str().unwrap(), "--size", "64", "--maps", "color"];
        let out = snakeskin(&args);
        assert!(out.status.success(), "{name}: {}", stderr(&out));
        (std::fs::read(out_dir.join(name.replace(".toml", "_color.png"))).unwrap(), stderr(&out))
    };
    let (without, said) = colour_map("rings.toml", sequence);
    assert!(!said.contains("warning"), "{said}");
    let (beside, said) = colour_map("rings.toml", &sequence.replace("kind", "color = \"#ffffff\"\nkind"));
    assert!(!said.contains("warning"), "{said}");
    assert_eq!(without, beside);
    // Negative control: the same white drawn by a one-ring layer is warned about.
    let (_, said) = colour_map("ring.toml", "seed = 1\n[[pattern]]\nkind = \"rings\"\ncolor = \"#ffffff\"\n");
    assert!(said.contains("warning: ") && said.contains("pattern.0.color = \"#ffffff\""), "{said}");
}

/// A name is a string: serde's TOML enums also took a table (`[scales.shape.hexagon]` made
/// hexagons; `kind = {spots = {}}` spots) and answered anything else in their own words
/// ("wanted string or table", "invalid type: unit variant, expected string only").
#[test]
fn enum_values_are_names_in_quotes_only() {
    for (text, key) in [
        ("[scales.shape.hexagon]\n", "scales.shape"),
        ("[scales]\nshape = {hexagon = {}}\n", "scales.shape"),
        ("[scales]\nshape = 5\n", "scales.shape"),
        ("[[pattern]]\nkind = {spots = {}}\ncolor = \"#000000\"\n", "pattern.0.kind"),
        ("category = true\n", "category"),
    ] {
        let err = refused("name.toml", text, &[]);
        assert!(err.contains(&format!("key `{key}")) && err.contains("expected a string"), "{text}: {err}");
        assert!(!err.contains("wanted") && !err.contains("variant"), "{text}: {err}");
    }
    for set in ["scales.shape=5", "scales.shape={}", "scales.shape={hexagon={}}"] {
        let err = refused("ok.toml", "seed = 1\n", &["--set", set]);
        assert!(err.contains("expected a string") && !err.contains("variant"), "{set}: {err}");
    }
}

/// A long list is counted, not echoed back whole (100,000 `rows` made one 500 KB line),
/// and a kind is named as a preset writes it (`not Spots` was Rust's name).
#[test]
fn messages_count_long_lists_and_name_kinds_as_written() {
    let rows = vec!["1"; 100_000].join(",");
    let text = format!("[[pattern]]\nkind = \"stripes\"\ncolor = \"#000000\"\nrows = [{rows}]\n");
    let err = refused("rows.toml", &text, &[]);
    assert!(err.contains("rows.toml:4: key `pattern.0.rows`") && err.contains("got 100000 entries"), "{err}");
    assert!(err.len() < 2000, "{} bytes of message", err.len());
    // Negative control: a short list is shown as written.
    let err = refused("rows.toml", "[[pattern]]\nkind = \"stripes\"\ncolor = \"#000000\"\nrows = [3, 1]\n", &[]);
    assert!(err.contains("got [3.0, 1.0]"), "{err}");
    let text = "[[pattern]]\nkind = \"spots\"\ncolor = \"#000000\"\ncount = 3\n";
    let err = refused("count.toml", text, &[]);
    assert!(err.contains("\"blotches\" or \"rings\" only, not \"spots\""), "{err}");
}

/// An index in a `--set` key reaches into a list the preset has: into a missing key it made
/// a table ("invalid type: table, expected an array"), and `pattern = []` with
/// `pattern.0.KEY`, which starts a layer, said "index 0 is out of range".
#[test]
fn set_indices_reach_into_lists_the_preset_has() {
    for (set, says) in [
        (
            "body.head_mark.0.kind=cap",
            "`body.head_mark` is not written in the preset, so `body.head_mark.0` has no list",
        ),
        ("optics.absorption.1=5", "`optics.absorption` is not written in the preset"),
        ("pattern.0.colors.1=#000000", "`pattern.0.colors` is not written in the preset"),
        ("scales.rows.0=3", "`scales.rows` is not written in the preset"),
    ] {
        let err = refused("plain.toml", "seed = 1\n", &["--set", set]);
        assert!(err.contains(says), "{set}: {err}");
        assert!(!err.contains("invalid type: table"), "{set}: {err}");
    }
    let err = refused("one.toml", "[scales]\nrows = 21\n", &["--set", "scales.rows.0=3"]);
    assert!(err.contains("`scales.rows` is one value, not a list, so `scales.rows.0` names nothing"), "{err}");
    let marks = "[body]\nhead_mark = [{kind = \"cap\", color = \"#000000\"}]\n";
    let err = refused("marks.toml", marks, &["--set", "body.head_mark.3.kind=v"]);
    assert!(err.contains("`body.head_mark` has 1 entry: body.head_mark.0; there is no `body.head_mark.3`"), "{err}");
    // An index is written one way: `pattern.00.kind=spots` reached layer 0 but was not read as
    // a change of its kind (the old kind's `colors` were refused), and `.+1` reached item 1.
    for (set, says) in [
        ("pattern.00.kind=spots", "the index `00` is written `0`"),
        ("body.head_mark.+0.kind=v", "the index `+0` is written `0`"),
    ] {
        let err = refused(
            "marks.toml",
            &format!("{marks}[[pattern]]\nkind = \"rings\"\ncolor = \"#ffffff\"\ncolors = [\"#000000\"]\n"),
            &["--set", set],
        );
        assert!(err.contains(says), "{set}: {err}");
    }
    // Negative controls: `pattern.0.KEY` starts a layer under `pattern = []` too, and an
    // index into a list the preset has is set.
    let dir = tempfile::tempdir().unwrap();
    let preset = write_preset(dir.path(), "empty.toml", "pattern = []\n");
    accepted(&preset, &["--set", "pattern.0.kind=stripes", "--set", "pattern.0.color=#000000"]);
    accepted(&write_preset(dir.path(), "marks.toml", marks), &["--set", "body.head_mark.0.kind=v"]);
    accepted("micrurus-diastema", &["--set", "pattern.0.kind=spots"]);
}

/// A key one kind reads, on a layer of another kind, is refused with its line (`colors` and
/// `widths` on spots, `phase` on stripes were silently ignored), unless it holds its default.
#[test]
fn keys_of_another_kind_are_refused_not_ignored() {
    let layer = "[[pattern]]\nkind = \"spots\"\ncolor = \"#000000\"\n";
    for (extra, says) in [
        ("colors = [\"#ffffff\"]", "key `pattern.0.colors` is read by kind \"rings\" only, not \"spots\""),
        ("phase = 0.5", "key `pattern.0.phase` is read by kind \"blotches\" only"),
        ("noise = \"cellular\"", "key `pattern.0.noise` is read by kind \"irregular\" only"),
        ("position = \"lateral\"", "key `pattern.0.position` is read by kind \"stripes\" only"),
        ("offset = 0.1", "key `pattern.0.offset` is read by kind \"stripes\" and \"blotches\" only"),
        ("broken = 0.3", "key `pattern.0.broken` is read by kind \"stripes\" only, not \"spots\""),
    ] {
        let err = refused("kinds.toml", &format!("{layer}{extra}\n"), &[]);
        assert!(err.contains(&format!("kinds.toml:4: {says}")), "{extra}: {err}");
    }
    // On its own kind, `broken` keeps most of the stripe's pieces.
    let err = refused("kinds.toml", &format!("{}broken = 0.95\n", layer.replace("spots", "stripes")), &[]);
    assert!(
        err.contains("kinds.toml:4: key `pattern.0.broken` must be a finite number in [0, 0.6], got 0.95"),
        "{err}"
    );
    // A solid tint has no size and no edges; a stripe has no centre, nor a shape.
    let marked = "\"stripes\", \"rings\", \"spots\", \"blotches\" and \"irregular\"";
    for (kind, extra, says) in [
        ("solid", "size = 0.4", format!("`pattern.0.size` is read by kind {marked} only, not \"solid\"")),
        ("solid", "edge_distortion = 0.9", format!("`pattern.0.edge_distortion` is read by kind {marked} only")),
        (
            "stripes",
            "center_size = 0.2",
            "`pattern.0.center_size` is read by kind \"spots\" and \"blotches\" only".into(),
        ),
        // These two said "must be one of round for kind ..." and "must be [first, last] ...
        // for kind "stripes" only; got [2.0, 3.0]", as if the value were wrong.
        ("stripes", "shape = \"ring\"", "`pattern.0.shape` is read by kind \"spots\" and \"blotches\" only".into()),
        (
            "blotches",
            "rows = [2, 3]",
            "`pattern.0.rows` is read by kind \"stripes\" and \"spots\" only, not \"blotches\"".into(),
        ),
        // A size without the colour that would draw it (the review).
        ("spots", "center_size = 0.3", "`pattern.0.center_size` sizes what `center_color` draws".into()),
        ("stripes", "border_size = 0.02", "`pattern.0.border_size` sizes what `border_color` draws".into()),
        // The spots' `checkered` on blotches was silently `aligned` (the docs walkthrough).
        (
            "blotches",
            "arrangement = \"checkered\"",
            "`pattern.0.arrangement` must be one of aligned, alternating for kind \"blotches\"".into(),
        ),
    ] {
        let err = refused("kinds.toml", &format!("{}{extra}\n", layer.replace("spots", kind)), &[]);
        assert!(err.contains(&format!("kinds.toml:4: key {says}")), "{extra}: {err}");
    }
    // Negative controls: a default value, and the key on its own kind; and a kind changed
    // by `--set` (README's example), where the file's keys for its old kind are passed over
    // (built-ins were refused: bitis-arietans's blotch `length`, `shape` and `count` on spots).
    for species in ["bitis-arietans", "bungarus-fasciatus", "boa-constrictor"] {
        accepted(species, &["--set", "pattern.0.kind=spots"]);
    }
    // ... but such a key written by an override with the new kind is refused.
    let err = refused("kinds.toml", layer, &["--set", "pattern.0.kind=stripes", "--set", "pattern.0.phase=0.5"]);
    assert!(err.contains("key `pattern.0.phase` is read by kind \"blotches\" only, not \"stripes\""), "{err}");
    // A key both kinds read keeps the file's value, so the spots' `checkered` is refused on a
    // layer made blotches (it was drawn as `aligned`: the review); with an arrangement of
    // the blotches' own it is taken.
    let garter =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/presets/thamnophis-sirtalis.toml")).unwrap();
    let err = refused("garter.toml", &garter, &["--set", "pattern.0.kind=blotches"]);
    assert!(err.contains("`pattern.0.arrangement` must be one of aligned, alternating"), "{err}");
    accepted("thamnophis-sirtalis", &["--set", "pattern.0.kind=blotches", "--set", "pattern.0.arrangement=aligned"]);
    let dir = tempfile::tempdir().unwrap();
    for text in [
        format!("{layer}length = 0.6\n"),
        layer.replace("spots", "rings") + "colors = [\"#ffffff\"]\n",
        format!("{layer}arrangement = \"checkered\"\n"),
    ] {
        accepted(&write_preset(dir.path(), "fine.toml", &text), &[]);
    }
}

/// A set's files are named after its preset file: a newline there made `new\nline_color.png`;
/// a backslash `a\b_color.png`, which `verify` refuses in a manifest (a folder's separator on
/// Windows), so `batch` never took the set as done and made it again at every run (a sweep);
/// a bidirectional control. Control: a name with a space and a `#` is taken.
#[cfg(unix)]
#[test]
fn a_preset_file_name_with_control_characters_or_a_backslash_is_refused() {
    let err = refused("new\nline.toml", "seed = 1\n", &[]);
    assert!(err.contains("its file name has control characters") && err.contains("rename the file"), "{err}");
    let err = refused("back\\slash.toml", "seed = 1\n", &[]);
    assert!(err.contains("its file name has a backslash") && err.contains("rename the file"), "{err}");
    // A bidirectional control: `gnp.exe` after U+202E shows as `exe.png` (it was taken, and
    // the name printed raw: "Trojan Source"); the message shows it escaped.
    let err = refused("x\u{202e}gnp.exe.toml", "seed = 1\n", &[]);
    assert!(err.contains("its file name has bidirectional controls") && err.contains("x\\u{202e}gnp"), "{err}");
    assert!(!err.contains('\u{202e}'), "{err}");
    // A line separator, a line break to an editor and to Python's `splitlines`.
    let err = refused("line\u{2028}break.toml", "seed = 1\n", &[]);
    assert!(err.contains("or line separators") && err.contains("line\\u{2028}break"), "{err}");
    let dir = tempfile::tempdir().unwrap();
    accepted(&write_preset(dir.path(), "a b#c.toml", "seed = 1\n"), &[]);
    // Right-to-left letters are no controls: a name in Hebrew is taken.
    accepted(&write_preset(dir.path(), "\u{05e6}\u{05e4}\u{05e2}.toml", "seed = 1\n"), &[]);
}

#[test]
fn out_of_range_value_names_key_and_range() {
    let err = refused("range.toml", "seed = 1\n[optics]\nfilm_ior = 7.5\n", &[]);
    assert!(err.contains("range.toml:3"), "{err}");
    assert!(err.contains("optics.film_ior"), "{err}");
    assert!(err.contains("[1, 3]"), "{err}");
}

/// A pattern's `amount` that counts marks (stripes, rings, spots, blotches) must be whole:
/// a fraction was rounded where they are drawn, silently (2.4 stripes drew 2, 7.5 spots 8: a
/// hostile-input sweep). Controls: a whole count, and an irregular layer's fractional
/// coverage, are accepted.
#[test]
fn a_count_of_marks_must_be_whole() {
    let presets = tempfile::tempdir().unwrap();
    for (kind, amount, said) in [
        ("stripes", "2.4", "must be a whole number of stripes a side in [1, 16], got 2.4"),
        ("spots", "7.5", "must be a whole number of spots around the body in [1, 64], got 7.5"),
        // Out of its range and not whole: one problem in the same words (it said only
        // "a finite number in [1, 16]", and 15.5 was refused next).
        ("stripes", "16.5", "must be a whole number of stripes a side in [1, 16], got 16.5"),
        ("rings", "1.5", "must be a whole number of repeats per tile in [1, 32], got 1.5"),
        ("blotches", "1.49", "must be a whole number of blotches per tile in [1, 32], got 1.49"),
    ] {
        let layer = format!("[[pattern]]\nkind = \"{kind}\"\ncolor = \"#101010\"\namount = {amount}\nsize = 0.02\n");
        let err = refused("count.toml", &layer, &[]);
        assert!(err.contains("count.toml:4: key `pattern.0.amount`") && err.contains(said), "{kind}: {err}");
        // Refused once: the checks that read the count (spots' spacing, stripes past the
        // belly) do not refuse it again as the count it rounds to.
        assert_eq!(err.matches("key `").count(), 1, "{kind}: {err}");
        accepted(&write_preset(presets.path(), "c.toml", &layer.replace(amount, "2")), &[]);
    }
    // Counts that the spacing and wrap checks read as they round: refused once, not again
    // as 41 spots too large at the default size or 3 stripes past the belly (an
    // independent review).
    for extra in ["kind = \"spots\"\namount = 40.5", "kind = \"stripes\"\namount = 2.5\nsize = 0.1\noffset = 0.3"] {
        let err = refused("count.toml", &format!("[[pattern]]\ncolor = \"#101010\"\n{extra}\n"), &[]);
        assert_eq!(err.matches("key `").count(), 1, "{extra}: {err}");
    }
    let irregular = "[[pattern]]\nkind = \"irregular\"\ncolor = \"#101010\"\namount = 0.25\n";
    accepted(&write_preset(presets.path(), "i.toml", irregular), &[]);
}

/// Spots larger than their spacing: each range alone allowed `size = 0.3` with 64 around, a
/// radius of 19 spacings that drew each point hundreds of times over (59.9 s for 16 layers
/// of them on a body atlas 16 pixels wide). Negative controls: the largest size the message
/// prints is accepted, so is a lower amount, and so is the built-in layer that comes closest
/// when turned to spots (acanthophis-antarcticus' rings, 1.75 spacings). A size out of its
/// own range is refused once, by its range.
#[test]
fn spots_larger_than_their_spacing_are_refused() {
    let layer = "[[pattern]]\nkind = \"spots\"\ncolor = \"#101010\"\namount = 64\nsize = 0.3\n";
    let err = refused("big_spots.toml", layer, &[]);
    assert!(err.contains("big_spots.toml:5") && err.contains("pattern.0.size"), "{err}");
    assert!(err.contains("a radius of 19.2 spacings") && err.contains("size ≤ 0.0312 at this spacing"), "{err}");
    let presets = tempfile::tempdir().unwrap();
    let path = write_preset(presets.path(), "big_spots.toml", layer);
    accepted(&path, &["--set", "pattern.0.size=0.0312"]);
    accepted(&path, &["--set", "pattern.0.amount=3"]);
    let err = refused("default_size.toml", &layer.replace("size = 0.3\n", ""), &[]);
    assert!(err.contains("is 0.05 with 64 spots around"), "{err}");
    // A key at its default is named as one, not as an override's (it said "(with --set)"
    // with nothing set), at the line of the key it is checked against (it had none); one an
    // override wrote still is.
    assert!(err.contains("default_size.toml:4: key `pattern.0.size` (not written: its default)"), "{err}");
    let err = refused("default_size.toml", &layer.replace("size = 0.3\n", ""), &["--set", "pattern.0.size=0.2"]);
    assert!(err.contains("default_size.toml (with --set): key `pattern.0.size`"), "{err}");
    accepted("acanthophis-antarcticus", &["--set", "pattern.0.kind=spots"]);
    let err = refused("too_big.toml", &layer.replace("amount = 64", "amount = 2").replace("0.3", "0.9"), &[]);
    assert!(err.contains("must be a finite number in [0.001, 0.5], got 0.9"), "{err}");
    assert_eq!(err.matches("pattern.0.size").count(), 1, "{err}");
    // On a band of `rows` the spots lie the band's width over `amount` apart, along the body
    // too: 64 over the lowest of 19 rows at 0.03 passed the check round the body (0.0312)
    // and took 37 s for a body atlas 64 pixels wide (a review); and at the largest radius
    // their spacing allows, 204,800 spots a circumference took seconds (the next review).
    // Refused on `amount` with the most that keep 64 round the body's count, and on `size`
    // with the largest radius: each printed value accepted (the controls), and the size
    // round the body.
    let banded = layer.replace("size = 0.3", "size = 0.03\nrows = [1, 1]");
    let err = refused("band.toml", &banded, &[]);
    assert!(err.contains("band.toml:4: key `pattern.0.amount` is 64 spots across rows [1, 1] each side"), "{err}");
    let most: u32 = err.split("at most ").nth(1).and_then(|t| t.split(' ').next()).unwrap().parse().unwrap();
    assert!((2..64).contains(&most), "{err}");
    let path = write_preset(presets.path(), "band.toml", &banded);
    let err = refused("band.toml", &banded, &["--set", &format!("pattern.0.amount={most}")]);
    assert!(err.contains(&format!("is 0.03 with {most} spots across rows [1, 1] (`amount`, `rows`),")), "{err}");
    assert!(!err.contains("pattern.0.amount"), "{most} across is accepted: {err}");
    let largest = err.split("size ≤ ").nth(1).and_then(|t| t.split(' ').next()).expect("the largest size");
    assert!(largest.parse::<f64>().unwrap() < 0.03, "{err}");
    accepted(&path, &["--set", &format!("pattern.0.amount={most}"), "--set", &format!("pattern.0.size={largest}")]);
    let err = refused(
        "band.toml",
        &banded,
        &["--set", &format!("pattern.0.amount={}", most + 1), "--set", "pattern.0.size=0.001"],
    );
    assert!(err.contains("pattern.0.amount"), "the control: {} across: {err}", most + 1);
    accepted(&write_preset(presets.path(), "round.toml", &banded.replace("rows = [1, 1]\n", "")), &[]);
}

/// A preset that is not UTF-8 is placed by line and column (std's message gave a byte
/// offset), and a raw control character by its own column with its code (a NUL after a
/// number was "string values must be quoted").
#[test]
fn bytes_a_preset_cannot_hold_are_placed_by_line_and_column() {
    let dir = tempfile::tempdir().unwrap();
    for (name, bytes, says) in [
        ("latin1.toml", &b"seed = 1\n[scales]\n# caf\xe9\n"[..], "line 3, column 6 holds the byte 0xE9"),
        ("nul.toml", b"seed = 1\0\n", "nul.toml:1:9: the control character U+0000 is not allowed in TOML text"),
    ] {
        let path = dir.path().join(name);
        std::fs::write(&path, bytes).unwrap();
        let out = snakeskin(&["generate", path.to_str().unwrap(), "-o", dir.path().join("out").to_str().unwrap()]);
        assert_eq!(out.status.code(), Some(2), "{name}: {}", stderr(&out));
        assert!(stderr(&out).contains(says), "{name}: {}", stderr(&out));
        assert!(!dir.path().join("out").exists(), "{name}: an output folder was made");
    }
}

#[test]
fn non_finite_value_is_refused() {
    let err = refused("nan.toml", "[scales]\nsize = nan\n", &[]);
    assert!(err.contains("scales.size") && err.contains("finite"), "{err}");
}

#[test]
fn out_of_range_override_names_the_set_argument() {
    let err = refused("ok.toml", "seed = 1\n", &["--set", "scales.rows=1000"]);
    assert!(err.contains("scales.rows") && err.contains("--set"), "{err}");
    let err = refused("ok.toml", "seed = 1\n", &["--set", "scales.rwos=20"]);
    assert!(err.contains("did you mean `rows`"), "{err}");
}

#[test]
fn sizes_outside_the_range_are_refused_before_anything_runs() {
    for size in ["0", "15", "1000000", "16385"] {
        let err = refused("fine.toml", "seed = 1\n", &["--size", size]);
        assert!(err.contains("16..=16384") || err.contains("16 to 16384"), "{size}: {err}");
        assert!(!err.contains("one width"), "{size}: {err}");
    }
    // A frame's size, as `preview --size` takes it, is told what a set's size is.
    let err = refused("fine.toml", "seed = 1\n", &["--size", "1024x1024"]);
    assert!(err.contains("a set's --size is one width (the tile is square"), "{err}");
}

#[test]
fn unknown_map_and_preset_are_refused() {
    let err = refused("fine.toml", "seed = 1\n", &["--maps", "colour"]);
    assert!(err.contains("colour") && err.contains("roughness"), "{err}");
    let out = snakeskin(&["generate", "no-such-snake", "-o", "/nonexistent-dir-never-created"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("erythrolamprus-miliaris"), "lists the built-in presets");
    assert!(!std::path::Path::new("/nonexistent-dir-never-created").exists());
}

#[test]
fn unwritable_output_leaves_no_partial_files() {
    // The output folder lies under a file: it cannot be created, nothing else is written.
    // The file is named, and the exit is 2 as for `-o FILE` (it was 1, an I/O error).
    let dir = tempfile::tempdir().unwrap();
    let blocker = dir.path().join("blocked");
    std::fs::write(&blocker, b"a file").unwrap();
    let out = snakeskin(&["generate", PATTERNED, "-o", blocker.join("sub").to_str().unwrap(), "--size", "32"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("blocked exists and is not a folder"), "{}", stderr(&out));
    assert_eq!(snapshot(dir.path()).len(), 1);
}

/// A name one `.toml` away from what is there gets the fix: `my-snake` beside my-snake.toml
/// (as `presets show NAME > my-snake.toml` writes it) listed the built-ins only, and a
/// missing `natrix-natrix.toml` said only "No such file or directory". Negative controls:
/// no such file beside the name, and a missing file named after no built-in, get neither.
#[test]
fn a_name_one_toml_away_from_a_preset_gets_the_fix() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("my-snake.toml"), "seed = 1\n").unwrap();
    let run = |name: &str| {
        let args = ["generate", name, "-o", "out", "--size", "16"];
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_snakeskin"))
            .args(args)
            .current_dir(dir.path())
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(2), "{name}: {}", stderr(&out));
        stderr(&out)
    };
    let err = run("my-snake");
    let says = "unknown preset \"my-snake\": not a .toml file and not a built-in preset; to read the file \
                my-snake.toml, give its name with .toml";
    assert!(err.contains(says), "{err}");
    assert!(!run("your-snake").contains("give its name with .toml"));
    let err = run("natrix-natrix.toml");
    let says = "cannot read preset natrix-natrix.toml: No such file or directory (os error 2); to use the \
                built-in preset natrix-natrix, give its name without a path or .toml";
    assert!(err.contains(says), "{err}");
    assert!(!run("natrix-natrixx.toml").contains("built-in preset"));
    // A path that is no file is the file's error (it was "not a .toml file and not a
    // built-in preset", where the README says `./NAME` reads the file).
    let err = run("./your-snake");
    assert!(err.contains("cannot read preset ./your-snake: No such file or directory"), "{err}");
    let err = run("./natrix-natrix");
    assert!(err.contains("; to use the built-in preset natrix-natrix, give its name without a path"), "{err}");
    // A folder is called one (it was only "not a .toml file and not a built-in preset").
    std::fs::create_dir(dir.path().join("snakes")).unwrap();
    assert!(run("snakes").contains("; snakes is a folder: name a .toml file in it"), "{}", run("snakes"));
    assert!(!dir.path().join("out").exists(), "a folder was made");
}

/// A map name mistyped gets a suggestion: `colour` (the documentation's prose spelling)
/// listed the accepted names only. Negative control: a name near none of them.
#[test]
fn a_mistyped_map_name_gets_a_suggestion() {
    for (maps, says) in [
        ("colour", "unknown map \"colour\"; did you mean color? accepted: color, height"),
        ("height,Normal", "unknown map \"Normal\"; did you mean normal? accepted:"),
        ("iridesence", "did you mean iridescence?"),
        ("sheen", "unknown map \"sheen\"; accepted:"),
        // Not `ao` for any word of two letters, nor for a comma too many, nor for one of
        // three two edits away (every letter of `ao`); one edit still is.
        ("xy", "unknown map \"xy\"; accepted:"),
        ("foo", "unknown map \"foo\"; accepted:"),
        ("aoo", "unknown map \"aoo\"; did you mean ao?"),
        // The same name in capitals, at any length (`AO` had none).
        ("AO", "unknown map \"AO\"; did you mean ao?"),
        // `all`, a word of the list, is suggested and accepted by name too (`ALL` and `al`
        // had neither: a hostile-input sweep); a map's suggestion comes first (`aol`).
        ("ALL", "unknown map \"ALL\"; did you mean all? accepted: color, height"),
        ("color,al", "unknown map \"al\"; did you mean all?"),
        ("sheen", "iridescence, ao, or all (the five of every set)"),
        ("aol", "unknown map \"aol\"; did you mean ao?"),
        ("color,", "an empty name in \"color,\"; name the maps, one comma between two"),
    ] {
        let out = snakeskin(&["graph", "natrix-natrix", "--maps", maps]);
        assert_eq!(out.status.code(), Some(2), "{maps}");
        assert!(stderr(&out).contains(says), "{maps}: {}", stderr(&out));
    }
}

/// A built-in name mistyped gets a suggestion: `natrix_natrix`, `Natrix-Natrix` and the
/// genus alone (`natrix`) had none, only the list of all 34; nor had a common name, an
/// artist's first guess (`grass-snake`, `"Corn snake"`, `macklots-python`: an independent
/// review's find). Negative control: a name near none of them gets no suggestion.
#[test]
fn a_mistyped_built_in_name_gets_a_suggestion() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().to_str().unwrap();
    for (name, suggestion) in [
        ("natrix_natrix", Some("natrix-natrix")),
        ("Natrix-Natrix", Some("natrix-natrix")),
        ("natrix", Some("natrix-natrix")),
        ("vipera-beru", Some("vipera-berus")),
        ("grass-snake", Some("natrix-natrix")),
        ("Corn snake", Some("pantherophis-guttatus")),
        ("macklots-python", Some("liasis-mackloti")),
        ("no-such-snake", None),
    ] {
        let out = snakeskin(&["generate", name, "-o", out_dir, "--size", "16"]);
        assert_eq!(out.status.code(), Some(2), "{name}");
        let err = stderr(&out);
        assert!(err.contains(&format!("unknown preset {name:?}")), "{err}");
        match suggestion {
            Some(s) => assert!(err.contains(&format!("; did you mean {s}? (built-in: ")), "{err}"),
            None => assert!(!err.contains("did you mean"), "{err}"),
        }
    }
}

/// An empty map list is refused (it meant all five: `--maps "$MAPS"` with the variable unset
/// wrote every map without a word), in a jobs file too. Negative control: `all`.
#[test]
fn an_empty_map_list_is_refused() {
    let err = refused("m.toml", "seed = 1\n", &["--maps", ""]);
    assert!(err.contains("an empty list; name the maps"), "{err}");
    accepted("natrix-natrix", &["--maps", "all"]);
    let dir = tempfile::tempdir().unwrap();
    let jobs = dir.path().join("jobs.toml");
    std::fs::write(&jobs, "[[job]]\npreset = \"natrix-natrix\"\nmaps = \" \"\n").unwrap();
    let out = snakeskin(&["batch", jobs.to_str().unwrap(), "-o", dir.path().join("out").to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("jobs.toml:3: [[job]] 1 (natrix-natrix): maps: an empty list"), "{}", stderr(&out));
}

/// A head mark's border is drawn behind a mark round the neck only: on another kind it is
/// refused with its line, as a pattern layer's key of another kind is, and its size without
/// its colour as a pattern layer's `border_size` is. Negative controls: both on crescents and
/// on a collar are accepted, and a kind changed by `--set` passes the file's border over.
#[test]
fn a_head_marks_border_is_read_by_marks_round_the_neck_only() {
    let mark = |kind: &str, extra: &str| format!("[[body.head_mark]]\nkind = \"{kind}\"\ncolor = \"#ffffff\"\n{extra}");
    for (kind, extra, says) in [
        (
            "cap",
            "border_color = \"#000000\"\n",
            "b.toml:4: key `body.head_mark.0.border_color` is read by kind \"collar\" and \"crescents\" only, not \"cap\"",
        ),
        ("lips", "border_size = 0.5\n", "b.toml:4: key `body.head_mark.0.border_size` is read by kind \"collar\""),
        ("crescents", "border_size = 0.5\n", "b.toml:4: key `body.head_mark.0.border_size` sizes what `border_color`"),
        ("collar", "border_size = 2.5\nborder_color = \"#000000\"\n", "must be a finite number in [0.3, 2], got 2.5"),
    ] {
        let err = refused("b.toml", &mark(kind, extra), &[]);
        assert!(err.contains(says), "{kind} {extra}: {err}");
    }
    let dir = tempfile::tempdir().unwrap();
    for kind in ["crescents", "collar"] {
        let text = mark(kind, "border_color = \"#000000\"\nborder_size = 0.5\n");
        accepted(&write_preset(dir.path(), &format!("{kind}.toml"), &text), &["--layout", "body"]);
    }
    accepted("natrix-natrix", &["--set", "body.head_mark.0.kind=cap"]);
    let set = ["--set", "body.head_mark.0.kind=cap", "--set", "body.head_mark.0.border_size=0.5"];
    let err = refused("b.toml", &mark("crescents", "border_color = \"#000000\"\n"), &set);
    assert!(err.contains("key `body.head_mark.0.border_size` is read by kind \"collar\""), "{err}");
}
