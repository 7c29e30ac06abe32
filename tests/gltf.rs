//! glTF export checked in the tools that open it: the Khronos glTF-Validator (0 errors and
//! 0 warnings on snakes, spheres and planes of several species, binary and JSON, tile and
//! body layout) and three.js's GLTFLoader in headless Chromium (the material parses as
//! iridescent with the preset's film index and thickness range, the frame is not blank, and
//! turning the film off changes it clearly). Both run Node from `tests/interop` (its
//! packages pinned in package-lock.json: `npm ci --prefix tests/interop`); without Node,
//! the packages or Chromium the tests skip, unless SNAKESKIN_REQUIRE_BROWSER=1 (set in
//! .ci/run), which makes a missing tool a failure.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::{snakeskin, stderr};
use serde_json::Value;

fn interop() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/interop")
}

fn browser_required() -> bool {
    std::env::var("SNAKESKIN_REQUIRE_BROWSER").is_ok_and(|v| v == "1")
}

fn chromium() -> PathBuf {
    std::env::var_os("CHROMIUM").map(PathBuf::from).unwrap_or_else(|| PathBuf::from("/usr/bin/chromium"))
}

/// Whether the tools are there (`needs_browser`: Chromium too); prints why not and returns
/// false when the test may skip, panics when SNAKESKIN_REQUIRE_BROWSER=1.
fn tools_or_skip(test: &str, needs_browser: bool) -> bool {
    let mut missing = Vec::new();
    if Command::new("node").arg("--version").output().map(|o| !o.status.success()).unwrap_or(true) {
        missing.push("node (Debian package nodejs)".to_string());
    }
    for package in ["gltf-validator", "three", "puppeteer-core"] {
        if !interop().join("node_modules").join(package).is_dir() {
            missing.push(format!("tests/interop/node_modules/{package} (run `npm ci --prefix tests/interop`)"));
        }
    }
    if needs_browser && !chromium().is_file() {
        missing.push(format!("{} (Debian package chromium, or set CHROMIUM)", chromium().display()));
    }
    if missing.is_empty() {
        return true;
    }
    let why = format!("missing {}", missing.join(", "));
    assert!(!browser_required(), "{test}: SNAKESKIN_REQUIRE_BROWSER=1 but {why}");
    eprintln!("{test}: SKIPPED: {why}");
    false
}

/// Runs a script in tests/interop; one JSON value per output line.
fn node(script: &str, args: &[&Path]) -> Vec<Value> {
    let out = Command::new("node").arg(interop().join(script)).args(args).output().expect("run node");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "node {script} failed:\n{text}\n{}", String::from_utf8_lossy(&out.stderr));
    text.lines().map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("{e}: {l}"))).collect()
}

fn export(dir: &Path, preset: &str, file: &str, extra: &[&str]) -> PathBuf {
    let path = dir.join(file);
    let mut args = vec!["export", preset, "--gltf", path.to_str().unwrap(), "--size", "128"];
    args.extend_from_slice(extra);
    let out = snakeskin(&args);
    assert!(out.status.success(), "export {preset} {extra:?}: {}", stderr(&out));
    path
}

#[test]
fn the_khronos_validator_finds_no_error_and_no_warning() {
    if !tools_or_skip("validator", false) {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let gltf_dir = dir.path().join("json");
    // (file, species): an iridescent species, a banded one, one without a film, each as a
    // snake and a sphere; a plane; a body atlas; a .gltf with its files beside it.
    let mut files: Vec<(PathBuf, &str)> = Vec::new();
    for species in ["xenopeltis-unicolor", "bungarus-fasciatus", "crotalus-atrox"] {
        files.push((export(dir.path(), species, &format!("{species}-snake.glb"), &[]), species));
        files.push((export(dir.path(), species, &format!("{species}-sphere.glb"), &["--mesh", "sphere"]), species));
    }
    files.push((
        export(dir.path(), "loxocemus-bicolor", "plane.glb", &["--mesh", "plane", "--ao"]),
        "loxocemus-bicolor",
    ));
    let body = export(dir.path(), "lampropeltis-triangulum", "body.glb", &["--layout", "body"]);
    files.push((body, "lampropeltis-triangulum"));
    // A name with a space and a `#`: the file's URIs must be percent-encoded to name their files.
    files.push((export(&gltf_dir, "liasis-mackloti", "liasis #1.gltf", &["--mesh", "sphere"]), "liasis-mackloti"));
    // A film of one thickness: its texture was embedded though unused (an info of the
    // validator's, KHR_MATERIALS_IRIDESCENCE_THICKNESS_TEXTURE_UNUSED).
    let one_thickness = ["--mesh", "plane", "--set", "iridescence.spread_nm=0"];
    files.push((export(dir.path(), "xenopeltis-unicolor", "one-thickness.glb", &one_thickness), "xenopeltis-unicolor"));

    let paths: Vec<&Path> = files.iter().map(|(p, _)| p.as_path()).collect();
    let reports = node("validate.mjs", &paths);
    assert_eq!(reports.len(), files.len());
    for (report, (_, species)) in reports.iter().zip(&files) {
        eprintln!(
            "{}: {} errors, {} warnings, {} infos",
            report["file"], report["errors"], report["warnings"], report["infos"]
        );
        assert_eq!(report["errors"], 0, "{report:#}");
        assert_eq!(report["warnings"], 0, "{report:#}");
        let messages = report["messages"].as_array().unwrap();
        assert!(!messages.iter().any(|m| m.as_str().unwrap().contains("_UNUSED")), "{report:#}");
        // Nor a minimum without its texture (KHR_MATERIALS_IRIDESCENCE_THICKNESS_RANGE_WITHOUT_TEXTURE).
        assert!(!messages.iter().any(|m| m.as_str().unwrap().contains("_WITHOUT_TEXTURE")), "{report:#}");
        // The iridescence extension is declared exactly where the preset has a film.
        let declared = report["extensions"].as_array().unwrap().iter().any(|e| e == "KHR_materials_iridescence");
        // From the presets' own words (a film of 380–420 nm in the iridescent species, 0 nm
        // and "iridescence not found" in the others), not from the exporter's rule.
        let film = matches!(*species, "xenopeltis-unicolor" | "loxocemus-bicolor" | "liasis-mackloti");
        assert_eq!(declared, film, "{species}: {report:#}");
    }
    assert!(reports.iter().any(|r| r["file"].as_str().unwrap().contains("crotalus")));
    // --ao references the ORM texture as the occlusion texture too; without it, no
    // occlusion texture (occlusion 1 is glTF's default).
    let material = |path: &Path| {
        let bytes = std::fs::read(path).unwrap();
        let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
        let json: Value = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
        json["materials"][0].clone()
    };
    let with_ao = material(&dir.path().join("plane.glb"));
    assert_eq!(
        with_ao["occlusionTexture"]["index"],
        with_ao["pbrMetallicRoughness"]["metallicRoughnessTexture"]["index"]
    );
    assert!(material(&dir.path().join("crotalus-atrox-snake.glb")).get("occlusionTexture").is_none());

    // Negative control: the same validator on a file with one wrong number (the POSITION
    // accessor's max no longer bounds its data) reports an error.
    let gltf_path = gltf_dir.join("liasis #1.gltf");
    let mut json: Value = serde_json::from_slice(&std::fs::read(&gltf_path).unwrap()).unwrap();
    let position = json["meshes"][0]["primitives"][0]["attributes"]["POSITION"].as_u64().unwrap() as usize;
    json["accessors"][position]["max"][0] = serde_json::json!(-10.0);
    let broken = gltf_dir.join("broken.gltf");
    std::fs::write(&broken, serde_json::to_vec(&json).unwrap()).unwrap();
    let report = &node("validate.mjs", &[&broken])[0];
    assert!(report["errors"].as_u64().unwrap() > 0, "the validator missed a wrong POSITION max: {report:#}");
}

/// CIEDE2000 of one just-noticeable difference is about 1; a film that a viewer shows moves
/// the snake's colours by far more than that. Mean over the snake's pixels.
const FILM_VISIBLE_DELTA_E00: f64 = 3.0;

/// A film of one thickness (`iridescence.spread_nm = 0`) is written as glTF reads it without
/// a texture: its maximum alone, no minimum (the validator noted that it had no effect), no
/// thickness texture or image (glTF then takes the maximum).
/// Negative control: the same preset with its spread has the texture and its image.
#[test]
fn a_film_of_one_thickness_is_written_without_a_thickness_texture() {
    let dir = tempfile::tempdir().unwrap();
    for (spread, texture) in [("0", false), ("260", true)] {
        let name = format!("spread{spread}.gltf");
        let set = ["--mesh", "plane", "--set", &format!("iridescence.spread_nm={spread}")];
        let gltf = export(dir.path(), "xenopeltis-unicolor", &name, &set);
        let json: Value = serde_json::from_slice(&std::fs::read(&gltf).unwrap()).unwrap();
        let film = &json["materials"][0]["extensions"]["KHR_materials_iridescence"];
        let (min, max) = (film["iridescenceThicknessMinimum"].as_f64(), film["iridescenceThicknessMaximum"].as_f64());
        assert!(max.is_some(), "{spread}: {film}");
        assert_eq!(min.is_some(), texture, "{spread}: {film}");
        assert!(min < max || !texture, "{spread}: {film}");
        assert_eq!(film.get("iridescenceThicknessTexture").is_some(), texture, "{spread}: {film}");
        assert_eq!(json["images"].as_array().unwrap().len(), if texture { 4 } else { 3 }, "{spread}");
        assert_eq!(dir.path().join(format!("spread{spread}.thickness.png")).is_file(), texture, "{spread}");
    }
}

/// An export of a snake under water (`optics.ambient_ior` other than 1) says before the work
/// that glTF viewers light it as in air; control: the default ambient says nothing of it.
#[test]
fn an_export_under_water_says_viewers_light_it_as_in_air() {
    let dir = tempfile::tempdir().unwrap();
    for (ambient, warned) in [("1.33", true), ("1.0", false)] {
        let out = dir.path().join(format!("a{ambient}.glb"));
        let args =
            ["export", "xenopeltis-unicolor", "--gltf", out.to_str().unwrap(), "--size", "16", "--mesh", "plane"];
        let run = snakeskin(&[&args[..], &["--set", &format!("optics.ambient_ior={ambient}")]].concat());
        assert!(run.status.success(), "{}", stderr(&run));
        // Any such warning counts for the control (its text at 1.0 would name 1, not 1.33).
        let said = stderr(&run).contains("glTF has no ambient index");
        assert_eq!(said, warned, "{ambient}: {}", stderr(&run));
        if warned {
            assert!(stderr(&run).contains("warning: optics.ambient_ior is 1.33,"), "{}", stderr(&run));
        }
    }
}

/// A `.gltf` exported into a texture set's folder under the set's own name writes its
/// images beside the set's maps without overwriting one (the set still verifies), and a
/// later export without a film leaves no thickness image of the earlier one.
#[test]
fn a_gltf_beside_a_set_of_the_same_name_leaves_the_set_whole() {
    let dir = tempfile::tempdir().unwrap();
    for args in [
        vec!["generate", "liasis-mackloti", "--size", "64", "-o"],
        vec!["generate", "liasis-mackloti", "--size", "64", "--pack", "gltf", "-o"],
    ] {
        let folder = dir.path().join(args.len().to_string());
        let mut args = args.clone();
        args.push(folder.to_str().unwrap());
        let out = snakeskin(&args);
        assert!(out.status.success(), "{}", stderr(&out));
        let gltf = export(&folder, "liasis-mackloti", "liasis-mackloti.gltf", &["--mesh", "plane"]);
        let set = folder.join(snakeskin::export::manifest_file_name("liasis-mackloti"));
        snakeskin::export::verify_set(&set).unwrap_or_else(|e| panic!("{args:?}: {e}"));
        assert!(folder.join("liasis-mackloti.thickness.png").is_file());
        // The same file again for a preset without a film: its thickness image goes too.
        let out = snakeskin(&[
            "export",
            "liasis-mackloti",
            "--set",
            "optics.film_thickness_nm=0",
            "--set",
            "iridescence.spread_nm=0",
            "--gltf",
            gltf.to_str().unwrap(),
            "--size",
            "64",
        ]);
        assert!(out.status.success(), "{}", stderr(&out));
        assert!(!folder.join("liasis-mackloti.thickness.png").exists(), "a stale thickness image was left");
        // And says so, as `generate` says the earlier set's files it removes (it was silent).
        let note =
            format!("note: removed {}, which this export", folder.join("liasis-mackloti.thickness.png").display());
        assert!(stderr(&out).contains(&note), "{}", stderr(&out));
        snakeskin::export::verify_set(&set).unwrap();
    }
}

/// A `.gltf` of the other spelling made while an export waits for the name's lock (two
/// exports, `a.gltf` and `a.GLTF`, started together) is refused under the lock: both passed
/// the look made before it, and the second wrote its images over the first's, both saying
/// they had succeeded (a sweep: 5 tries of 5). Here the other export is the test, holding
/// the lock while it writes `RACE.GLTF`.
#[cfg(target_os = "linux")]
#[test]
fn a_gltf_of_the_other_spelling_made_while_waiting_for_the_lock_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let lock = std::fs::File::create(dir.path().join(".RACE.lock")).unwrap();
    lock.try_lock().unwrap();
    let target = dir.path().join("RACE.gltf");
    let run = Command::new(env!("CARGO_BIN_EXE_snakeskin"))
        .args(["export", "xenopeltis-unicolor", "--mesh", "plane", "--size", "16", "--gltf", target.to_str().unwrap()])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // Within the lock's second of tries: the export holds the lock file open while it tries
    // (past its plan's look), which its descriptors in /proc show.
    common::wait_until_open(run.id(), &dir.path().canonicalize().unwrap().join(".RACE.lock"));
    std::fs::write(dir.path().join("RACE.GLTF"), "{}").unwrap();
    drop(lock);
    let out = run.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("RACE.GLTF beside it is a .gltf file whose name differs only"), "{}", stderr(&out));
    let mut left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
    left.sort();
    // (The lock file, let go, the export removes as it does its own.)
    assert_eq!(left, ["RACE.GLTF"].map(std::ffi::OsString::from), "nothing written");
}

/// A `.gltf` whose name holds a backslash is refused before any work: its side files are
/// named after it (`x\\y.bin`), which Windows reads as a folder (a sweep). Control: a `.glb`,
/// whose name is only inside it, is written.
#[cfg(unix)]
#[test]
fn a_gltf_named_with_a_backslash_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = snakeskin(&[
        "export",
        "xenopeltis-unicolor",
        "--size",
        "16",
        "--gltf",
        dir.path().join("x\\y.gltf").to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("the file name has a backslash"), "{}", stderr(&out));
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0, "nothing written");
    export(dir.path(), "xenopeltis-unicolor", "x\\y.glb", &["--mesh", "plane"]);
}

/// `--gltf NAME.GLTF` writes the file named, its extension's case kept, as `.GLB` did (it
/// wrote NAME.gltf, a file other than the one named and checked).
#[test]
fn an_upper_case_extension_names_the_file_written() {
    let dir = tempfile::tempdir().unwrap();
    for (name, lower) in [("UP.GLTF", "UP.gltf"), ("Up.Glb", "Up.glb")] {
        let written = export(dir.path(), "xenopeltis-unicolor", name, &["--mesh", "plane"]);
        assert!(written.is_file(), "{name}");
        assert!(!dir.path().join(lower).exists(), "{name}");
    }
    assert!(dir.path().join("UP.bin").is_file());
    // A `.gltf` whose name differs from one beside it only in the extension's case shares
    // its side files (`UP.bin`, `UP.basecolor.png`): refused, the earlier export left whole
    // (it was written over, and the first `.gltf` read a buffer of another length). Controls:
    // the same name again, and another name, are exported.
    let before = common::snapshot(dir.path());
    let out = snakeskin(&["export", "xenopeltis-unicolor", "--gltf", dir.path().join("UP.gltf").to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("UP.GLTF beside it is a .gltf file whose name differs only"), "{}", stderr(&out));
    assert_eq!(common::snapshot(dir.path()), before);
    export(dir.path(), "xenopeltis-unicolor", "UP.GLTF", &["--mesh", "plane"]);
    export(dir.path(), "xenopeltis-unicolor", "Up.gltf", &["--mesh", "plane"]);
    // A hard link is another name that the export's rename would leave reading the old
    // document beside the new side files: refused too (an independent review). Controls: a
    // symbolic link reads the new file, and a folder of that name is no document.
    std::fs::hard_link(dir.path().join("Up.gltf"), dir.path().join("Up.GLTF")).unwrap();
    let out = snakeskin(&["export", "xenopeltis-unicolor", "--gltf", dir.path().join("Up.gltf").to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    std::fs::remove_file(dir.path().join("Up.GLTF")).unwrap();
    std::os::unix::fs::symlink("Up.gltf", dir.path().join("Up.GLTF")).unwrap();
    std::fs::create_dir(dir.path().join("Up.glTF")).unwrap();
    export(dir.path(), "xenopeltis-unicolor", "Up.gltf", &["--mesh", "plane"]);
    // A symbolic link to a hard link of the export is the old document after it: refused
    // (it was let through as the same file: a second review).
    std::fs::create_dir(dir.path().join("keep")).unwrap();
    std::fs::hard_link(dir.path().join("Up.gltf"), dir.path().join("keep/Up.gltf")).unwrap();
    std::fs::remove_file(dir.path().join("Up.GLTF")).unwrap();
    std::os::unix::fs::symlink("keep/Up.gltf", dir.path().join("Up.GLTF")).unwrap();
    let out = snakeskin(&["export", "xenopeltis-unicolor", "--gltf", dir.path().join("Up.gltf").to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    // A name that ends as a folder's is refused with an example of its own kind (it said
    // "as in out/snake.png", a name `--gltf` refuses).
    for (given, example) in [
        ("x.glb/", "as in out/snake.glb"),
        ("x.gltf/.", "as in out/snake.gltf"),
        ("x/", "as in out/snake.glb"),
        ("x.png/", "as in out/snake.glb"),
    ] {
        let out = snakeskin(&["export", "xenopeltis-unicolor", "--gltf", &format!("{}/{given}", dir.path().display())]);
        assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
        assert!(stderr(&out).contains(example), "{given}: {}", stderr(&out));
    }
}

/// An earlier export's thickness image edited since stays when a re-export no longer writes
/// it, and is said, as `generate` keeps a map changed since: each image of a `.gltf` carries
/// its file's SHA-256 in its `extras`. It was removed, edits and all. Negative control: left
/// as written, it goes (`a_gltf_beside_a_set_of_the_same_name_leaves_the_set_whole`).
#[test]
fn an_export_keeps_a_thickness_image_edited_since() {
    let dir = tempfile::tempdir().unwrap();
    let gltf = export(dir.path(), "liasis-mackloti", "x.gltf", &["--mesh", "plane"]);
    let json: Value = serde_json::from_slice(&std::fs::read(&gltf).unwrap()).unwrap();
    for image in json["images"].as_array().unwrap() {
        let bytes = std::fs::read(dir.path().join(image["uri"].as_str().unwrap())).unwrap();
        assert_eq!(image["extras"]["sha256"].as_str(), Some(snakeskin::export::sha256_hex(&bytes).as_str()));
    }
    let thickness = dir.path().join("x.thickness.png");
    let mut edited = std::fs::read(&thickness).unwrap();
    edited.extend_from_slice(b"an edit");
    std::fs::write(&thickness, &edited).unwrap();
    let no_film = ["--mesh", "plane", "--set", "optics.film_thickness_nm=0", "--set", "iridescence.spread_nm=0"];
    let out = snakeskin(
        &[&["export", "liasis-mackloti", "--gltf", gltf.to_str().unwrap(), "--size", "64"][..], &no_film].concat(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(std::fs::read(&thickness).unwrap(), edited, "{}", stderr(&out));
    let warning = "which this export does not reference: it changed since the earlier export wrote it";
    assert!(stderr(&out).contains(warning), "{}", stderr(&out));

    // A `.gltf` written before images carried their hash is taken at its word: its image goes.
    let gltf = export(dir.path(), "liasis-mackloti", "y.gltf", &["--mesh", "plane"]);
    let mut json: Value = serde_json::from_slice(&std::fs::read(&gltf).unwrap()).unwrap();
    for image in json["images"].as_array_mut().unwrap() {
        image.as_object_mut().unwrap().remove("extras");
    }
    std::fs::write(&gltf, serde_json::to_vec(&json).unwrap()).unwrap();
    let out = snakeskin(
        &[&["export", "liasis-mackloti", "--gltf", gltf.to_str().unwrap(), "--size", "64"][..], &no_film].concat(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(!dir.path().join("y.thickness.png").exists(), "{}", stderr(&out));
}

/// A `NAME.thickness.png` beside a `.gltf` that does not name it is not the earlier export's,
/// and an export without a film leaves it as it was (it was removed as stale whoever's it was),
/// and says so; so it does where no `.gltf` is there to say whose it is (a killed commit's
/// images without their `.gltf`, which stayed without a word), or one that cannot be read.
#[test]
fn an_export_without_a_film_keeps_a_thickness_image_it_did_not_write() {
    let dir = tempfile::tempdir().unwrap();
    let no_film = ["--mesh", "plane", "--set", "optics.film_thickness_nm=0", "--set", "iridescence.spread_nm=0"];
    let gltf = export(dir.path(), "liasis-mackloti", "x.gltf", &no_film);
    let mine = dir.path().join("x.thickness.png");
    std::fs::write(&mine, b"someone else's").unwrap();
    let out = snakeskin(
        &[&["export", "liasis-mackloti", "--gltf", gltf.to_str().unwrap(), "--size", "64"][..], &no_film].concat(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(std::fs::read(&mine).unwrap(), b"someone else's", "{}", stderr(&out));
    assert!(!stderr(&out).contains("removed"), "{}", stderr(&out));
    let kept = format!("warning: kept {}, which this export does not reference: ", mine.display());
    assert!(stderr(&out).contains(&format!("{kept}the x.gltf there does not record it")), "{}", stderr(&out));

    // An export with a film, then its `.gltf` gone or broken: its image stays, said.
    for (broken, why) in
        [(None, "no x.gltf is there to say"), (Some(&b"{broken"[..]), "the x.gltf there could not be used (not JSON")]
    {
        let gltf = export(dir.path(), "liasis-mackloti", "x.gltf", &["--mesh", "plane"]);
        let image = std::fs::read(&mine).unwrap();
        match broken {
            None => std::fs::remove_file(&gltf).unwrap(),
            Some(bytes) => std::fs::write(&gltf, bytes).unwrap(),
        }
        let out = snakeskin(
            &[&["export", "liasis-mackloti", "--gltf", gltf.to_str().unwrap(), "--size", "64"][..], &no_film].concat(),
        );
        assert!(out.status.success(), "{}", stderr(&out));
        assert_eq!(std::fs::read(&mine).unwrap(), image, "{why}: {}", stderr(&out));
        assert!(stderr(&out).contains(&format!("{kept}{why}")), "{why}: {}", stderr(&out));
    }
    // Negative control: beside the `.gltf` that named it, it goes without a warning.
    let gltf = export(dir.path(), "liasis-mackloti", "x.gltf", &["--mesh", "plane"]);
    let out = snakeskin(
        &[&["export", "liasis-mackloti", "--gltf", gltf.to_str().unwrap(), "--size", "64"][..], &no_film].concat(),
    );
    assert!(out.status.success() && !mine.exists() && !stderr(&out).contains("warning"), "{}", stderr(&out));
}

#[test]
fn three_js_reads_the_film_and_renders_it() {
    if !tools_or_skip("three.js", true) {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let glb = export(dir.path(), "xenopeltis-unicolor", "xeno.glb", &[]);
    let result = &node("render.mjs", &[&glb])[0];
    eprintln!("three.js: {result:#}");
    assert!(result.get("error").is_none(), "{result:#}");
    let preset = snakeskin::preset::load("xenopeltis-unicolor", &[], None).unwrap().preset;
    let (min_nm, max_nm) = snakeskin::maps::thickness_range_nm(&preset);
    let m = &result["material"];
    assert_eq!(m["type"], "MeshPhysicalMaterial");
    assert_eq!(m["iridescence"], 1.0);
    let close = |v: &Value, want: f64| (v.as_f64().unwrap() - want).abs() < 1e-6;
    assert!(close(&m["iridescenceIOR"], preset.optics.film_ior), "{m}");
    assert!(close(&m["iridescenceThicknessMinimum"], min_nm), "{m}");
    assert!(close(&m["iridescenceThicknessMaximum"], max_nm), "{m}");
    assert!(close(&m["ior"], preset.optics.pigment_ior), "{m}");
    for map in ["hasThicknessMap", "hasMap", "hasNormalMap", "hasRoughnessMap"] {
        assert_eq!(m[map], true, "{map}: {m}");
    }
    // Not blank: the snake covers part of the frame and is not one flat colour.
    assert!(result["coverage"].as_f64().unwrap() > 0.02, "{result:#}");
    assert!(result["luma_std"].as_f64().unwrap() > 5.0, "{result:#}");
    let delta = result["delta_e00_mean"].as_f64().unwrap();
    assert!(delta > FILM_VISIBLE_DELTA_E00, "turning the film off changed the frame by only ΔE00 {delta}");

    // Control of the measurement, not of the exporter: a species without a film loads with
    // iridescence 0, so its two frames are drawn alike, and any ΔE here would be the
    // renderer's own frame-to-frame noise, which the film's ΔE above must stand clear of.
    let plain = export(dir.path(), "crotalus-atrox", "crotalus.glb", &[]);
    let result = &node("render.mjs", &[&plain])[0];
    assert_eq!(result["material"]["iridescence"], 0.0, "{result:#}");
    let delta = result["delta_e00_mean"].as_f64().unwrap();
    assert!(delta < 0.5, "a snake without a film changed by ΔE00 {delta}");
}

/// An exported file says what made it, as a texture set's manifest does: the asset's
/// `extras` hold the manifest's generator, preset, preset_hash, species, seed, layout and size
/// (it held only the generator, so a file could not be traced to its preset or made again). Checked
/// against the manifest of `generate` with the same preset, overrides and seed, for a
/// `.glb` and a `.gltf`: every key of `extras` is the manifest's, with the same value, but for
/// the export's own `mesh` and `ambient_occlusion`, which a set's manifest lacks.
#[test]
fn an_export_records_the_preset_and_seed_it_was_made_from() {
    let dir = tempfile::tempdir().unwrap();
    let set = ["--set", "scales.rows=21", "--seed", "7", "--size", "128"];
    let out =
        snakeskin(&[&["generate", "natrix-natrix", "-o", dir.path().join("set").to_str().unwrap()][..], &set].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    let manifest: Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("set/natrix-natrix.material.json")).unwrap()).unwrap();
    for file in ["n.glb", "n.gltf"] {
        let path = export(dir.path(), "natrix-natrix", file, &set[..4]);
        let bytes = std::fs::read(&path).unwrap();
        let json: Value = if file.ends_with(".glb") {
            let length = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
            serde_json::from_slice(&bytes[20..20 + length]).unwrap()
        } else {
            serde_json::from_slice(&bytes).unwrap()
        };
        let extras = &json["asset"]["extras"];
        for key in ["preset", "preset_hash", "species", "seed", "layout", "width", "height"] {
            assert!(extras.get(key).is_some(), "{file}: no {key}: {extras}");
        }
        // The export's own options besides, so that it can be made again (they were left out).
        assert_eq!(extras["mesh"], "snake", "{file}");
        assert_eq!(extras["ambient_occlusion"], false, "{file}");
        for (key, value) in extras.as_object().unwrap() {
            if !["mesh", "ambient_occlusion"].contains(&key.as_str()) {
                assert_eq!(value, &manifest[key], "{file}: {key}: {extras}");
            }
        }
        assert_eq!(extras["seed"], 7, "{file}");
    }
}
