//! `generate --pack`: every packed texture's channels read back against the plain maps of
//! the same preset and seed (written by the ordinary map writer), under each engine's
//! convention — glTF's occlusion-roughness-metallic, Unreal's DirectX green, Unity HDRP's
//! smoothness = 1 − roughness in the mask map's alpha — for a tile and a body atlas.

mod common;

use std::path::Path;

use common::{snakeskin, stderr};
use image::DynamicImage;

fn generate(dir: &Path, preset: &str, extra: &[&str]) {
    generate_at(dir, preset, "64", extra)
}

fn generate_at(dir: &Path, preset: &str, size: &str, extra: &[&str]) {
    let mut args = vec!["generate", preset, "-o", dir.to_str().unwrap(), "--size", size];
    args.extend_from_slice(extra);
    let out = snakeskin(&args);
    assert!(out.status.success(), "generate {extra:?}: {}", stderr(&out));
}

fn read(dir: &Path, file: &str) -> DynamicImage {
    image::open(dir.join(file)).unwrap_or_else(|e| panic!("{file}: {e}"))
}

/// Largest difference between two channel sequences (after `f` on the second).
fn worst(a: impl Iterator<Item = i32>, b: impl Iterator<Item = i32>, f: impl Fn(i32) -> i32) -> i32 {
    a.zip(b).map(|(x, y)| (x - f(y)).abs()).max().unwrap()
}

fn channel(img: &DynamicImage, c: usize) -> Vec<i32> {
    let rgba = img.to_rgba8();
    rgba.pixels().map(|p| p.0[c] as i32).collect()
}

fn check_packs(preset: &str, layout: &str) {
    let dir = tempfile::tempdir().unwrap();
    let plain = dir.path().join("plain");
    generate(&plain, preset, &["--layout", layout]);
    let name = preset;
    let colour = read(&plain, &format!("{name}_color.png"));
    let normal = read(&plain, &format!("{name}_normal.png"));
    let rough = channel(&read(&plain, &format!("{name}_roughness.png")), 0);
    let height16 = read(&plain, &format!("{name}_height.png")).to_luma16();
    let thickness16 = read(&plain, &format!("{name}_iridescence.png")).to_luma16();
    let film = snakeskin::maps::has_film(&snakeskin::preset::load(preset, &[], None).unwrap().preset);

    for pack in ["gltf", "unreal", "unity-hdrp"] {
        let out = dir.path().join(pack);
        generate(&out, preset, &["--layout", layout, "--pack", pack]);
        let manifest: serde_json::Value =
            serde_json::from_slice(&std::fs::read(out.join(format!("{name}.material.json"))).unwrap()).unwrap();
        assert_eq!(manifest["pack"], pack);
        let files: Vec<&str> =
            manifest["maps"].as_array().unwrap().iter().map(|m| m["map"].as_str().unwrap()).collect();

        // The base colour is the colour map, byte for byte.
        let base = read(&out, &format!("{name}_basecolor.png"));
        assert_eq!(base.to_rgb8().as_raw(), colour.to_rgb8().as_raw(), "{pack} base colour");

        // The normal: OpenGL as written, or DirectX (green mirrored) for Unreal.
        let packed_normal = read(&out, &format!("{name}_normal.png"));
        for c in [0, 2] {
            assert_eq!(channel(&packed_normal, c), channel(&normal, c), "{pack} normal channel {c}");
        }
        let green = (channel(&packed_normal, 1), channel(&normal, 1));
        if pack == "unreal" {
            assert!(worst(green.0.into_iter(), green.1.into_iter(), |g| 255 - g) <= 1, "unreal green is not flipped");
        } else {
            assert_eq!(green.0, green.1, "{pack} green");
        }

        // Roughness (and occlusion, metallic) where each engine reads them.
        if pack == "unity-hdrp" {
            let mask = read(&out, &format!("{name}_mask.png"));
            assert!(channel(&mask, 0).iter().all(|&v| v == 0), "metallic");
            assert!(channel(&mask, 1).iter().all(|&v| v == 255), "occlusion");
            // HDRP's detail mask at 1, as without a mask map (at 0 it hid any detail map).
            assert!(channel(&mask, 2).iter().all(|&v| v == 255), "detail mask");
            let smooth = channel(&mask, 3);
            assert!(worst(smooth.into_iter(), rough.clone().into_iter(), |r| 255 - r) <= 1, "smoothness");
        } else {
            let orm = read(&out, &format!("{name}_orm.png"));
            assert!(channel(&orm, 0).iter().all(|&v| v == 255), "{pack} occlusion");
            assert_eq!(channel(&orm, 1), rough, "{pack} roughness in G");
            assert!(channel(&orm, 2).iter().all(|&v| v == 0), "{pack} metallic in B");
        }

        // Height (16-bit, as the set's) for the engines that displace.
        if pack != "gltf" {
            let h = read(&out, &format!("{name}_height.png")).to_luma16();
            assert_eq!(h.as_raw(), height16.as_raw(), "{pack} height");
        }

        // The film's thickness, 8-bit, where there is a film; none where there is not.
        assert_eq!(files.contains(&"thickness"), film, "{pack}: {files:?}");
        if film {
            let t = read(&out, &format!("{name}_thickness.png")).to_luma8();
            let eight = thickness16.as_raw().iter().map(|&v| (v as f64 / 65535.0 * 255.0).round() as i32);
            assert!(worst(t.as_raw().iter().map(|&v| v as i32), eight, |v| v) <= 1, "{pack} thickness");
        }
    }
}

#[test]
fn packed_channels_are_the_maps_under_each_engines_convention() {
    check_packs("xenopeltis-unicolor", "tile");
    check_packs("crotalus-atrox", "tile");
}

#[test]
fn a_body_atlas_packs_strip_by_strip_like_its_maps() {
    check_packs("liasis-mackloti", "body");
}

#[test]
fn ao_fills_the_occlusion_channel_and_only_when_asked() {
    let dir = tempfile::tempdir().unwrap();
    let name = "crotalus-atrox";
    // 256 wide: the scales' relief spans pixels enough to occlude (at 64 it hardly does).
    generate_at(dir.path(), name, "256", &["--maps", "ao"]);
    let ao = channel(&read(dir.path(), &format!("{name}_ao.png")), 0);
    // The skin's overlaps and keels occlude, a little (the relief is the normal map's, a
    // fraction of a scale's width): at 256 wide, about 2 % of the pixels below 250/255.
    let occluded = ao.iter().filter(|&&v| v < 250).count() as f64 / ao.len() as f64;
    assert!(occluded > 0.005, "hardly any occlusion: {occluded}");
    // The manifest says which the channel holds (before, the two manifests differed in a
    // hash only, and both said "1 everywhere without --ao").
    let occlusion_meaning = |set: &Path, file: &str| -> String {
        let manifest: serde_json::Value =
            serde_json::from_slice(&std::fs::read(set.join(format!("{name}.material.json"))).unwrap()).unwrap();
        let entry = manifest["maps"].as_array().unwrap().iter().find(|m| m["map"] == file).unwrap();
        entry["meaning"].as_str().unwrap().to_string()
    };
    for (pack, file, c) in [("gltf", "orm", 0), ("unreal", "orm", 0), ("unity-hdrp", "mask", 1)] {
        let out = dir.path().join(pack);
        generate_at(&out, name, "256", &["--pack", pack, "--ao"]);
        assert_eq!(channel(&read(&out, &format!("{name}_{file}.png")), c), ao, "{pack} occlusion");
        assert!(occlusion_meaning(&out, file).contains("ambient occlusion from the height map"), "{pack}");
        let without = dir.path().join(format!("{pack}-without"));
        generate_at(&without, name, "64", &["--pack", pack]);
        assert!(occlusion_meaning(&without, file).contains("occlusion, 1 everywhere (not computed"), "{pack}");
    }
    // "all" is the five maps of every set: no ambient occlusion unless named.
    let all = dir.path().join("all");
    generate(&all, name, &[]);
    assert!(!all.join(format!("{name}_ao.png")).exists());
    let out = snakeskin(&["generate", name, "-o", all.to_str().unwrap(), "--ao"]);
    assert_eq!(out.status.code(), Some(2), "--ao without --pack: {}", stderr(&out));
}

#[test]
fn pack_refuses_options_that_contradict_it() {
    let dir = tempfile::tempdir().unwrap();
    for extra in [["--format", "exr"], ["--normal-convention", "directx"], ["--maps", "color"]] {
        let mut args = vec!["generate", "xenopeltis-unicolor", "-o", dir.path().to_str().unwrap(), "--pack", "unreal"];
        args.extend_from_slice(&extra);
        let out = snakeskin(&args);
        assert_eq!(out.status.code(), Some(2), "{extra:?}: {}", stderr(&out));
        assert!(stderr(&out).contains("--pack"), "{}", stderr(&out));
    }
    assert!(std::fs::read_dir(dir.path()).unwrap().next().is_none(), "a refused run wrote files");
}

/// A pack longer than its engine loads is warned of, with the largest size that fits: a body
/// atlas is `body.length` widths tall, so `--size 1024` made a 12288-row Unreal texture
/// without a word (its documentation gives 8192). The size named is checked against the
/// layout's own height, one texel either side.
#[test]
fn a_pack_longer_than_its_engine_loads_is_warned_of_with_a_size_that_fits() {
    use snakeskin::export::pack::Pack;
    use snakeskin::generate::pack_size_warning;
    use snakeskin::maps::Layout;
    let preset = snakeskin::preset::load("natrix-natrix", &[], None).unwrap().preset;
    for pack in Pack::ALL {
        let (limit, _) = pack.longest_side_loaded();
        // Negative control: a tile at the limit and a body atlas just under it fit.
        assert_eq!(pack_size_warning(pack, Layout::Tile, &preset, limit, "--size"), None, "{pack:?}");
        let rows = |width: usize| Layout::Body.height(&preset, width);
        let under = (1..=limit).rev().find(|&w| rows(w) <= limit).unwrap();
        assert_eq!(pack_size_warning(pack, Layout::Body, &preset, under, "--size"), None, "{pack:?}");
        // Past it, both ways.
        let tile = pack_size_warning(pack, Layout::Tile, &preset, limit + 1, "--size").expect("a tile too wide");
        assert!(tile.contains(&format!("are {} x {}", limit + 1, limit + 1)), "{tile}");
        assert!(tile.ends_with(&format!("give --size {limit} or less")), "{tile}");
        let body = pack_size_warning(pack, Layout::Body, &preset, under + 1, "--size").expect("a body atlas too tall");
        assert!(
            body.contains(&format!("{} x {}, longer than the {limit} texels", under + 1, rows(under + 1))),
            "{body}"
        );
        assert!(body.contains(&format!("give --size {under} or less (a body atlas")), "{body}");
        assert!(body.starts_with(&format!("the {} textures", pack.name())), "{body}");
    }
    // The commands print it: a body 40 widths long, 208 wide, is 8320 tall, past Unreal's
    // 8192 (204 fits: 8160); `export`'s glTF at 410 wide, 16400, past 16384 (409 fits).
    let dir = tempfile::tempdir().unwrap();
    let long = ["--layout", "body", "--set", "body.length=40", "-o"];
    for (size, warned) in [("208", true), ("204", false)] {
        let out_dir = dir.path().join(size);
        let args = [&["generate", "natrix-natrix", "--pack", "unreal", "--size", size][..], &long[..]].concat();
        let out = snakeskin(&[&args[..], &[out_dir.to_str().unwrap()]].concat());
        assert!(out.status.success(), "{}", stderr(&out));
        let says = "the unreal textures are 208 x 8320, longer than the 8192 texels a side";
        assert_eq!(stderr(&out).contains(says), warned, "{size}: {}", stderr(&out));
        assert_eq!(stderr(&out).contains("give --size 204 or less (a body atlas"), warned, "{}", stderr(&out));
    }
    let glb = dir.path().join("long.glb");
    let args = ["export", "natrix-natrix", "--layout", "body", "--set", "body.length=40", "--size", "410", "--gltf"];
    let out = snakeskin(&[&args[..], &[glb.to_str().unwrap()]].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stderr(&out).contains("the gltf textures are 410 x 16400"), "{}", stderr(&out));
    assert!(stderr(&out).contains("give --size 409 or less"), "{}", stderr(&out));
    // The export knows it before the work (it was said after the textures were made): the
    // plan has it, and no texel is computed until it runs.
    use snakeskin::gltf_export::{ExportPlan, ExportRequest, MeshKind};
    let request = |size: u64| ExportRequest {
        preset: "natrix-natrix".into(),
        overrides: vec![("body.length".into(), "40".into())],
        seed: None,
        size,
        layout: Layout::Body,
        mesh: MeshKind::Snake,
        out: dir.path().join("planned.glb"),
        ao: false,
    };
    let warned = |size| ExportPlan::new(&request(size)).unwrap().warnings().iter().any(|w| w.contains("16384 texels"));
    assert!(warned(410) && !warned(409));
}

/// A pack of a snake under water (`optics.ambient_ior` other than 1) says before the work
/// that its engine lights it as in air, naming the engine, as `export` does for glTF (a
/// review: packs were silent); control: in air nothing is said of it.
#[test]
fn a_pack_under_water_says_its_engine_lights_it_as_in_air() {
    let dir = tempfile::tempdir().unwrap();
    for (pack, ambient, said) in [
        ("unreal", "1.33", Some("Unreal's material has no ambient index")),
        ("unity-hdrp", "1.33", Some("HDRP's Lit material has no ambient index")),
        ("gltf", "1.33", Some("glTF has no ambient index")),
        ("unreal", "1.0", None),
    ] {
        let out = dir.path().join(format!("{pack}-{ambient}"));
        let set = format!("optics.ambient_ior={ambient}");
        let args =
            ["generate", "natrix-natrix", "-o", out.to_str().unwrap(), "--size", "16", "--pack", pack, "--set", &set];
        let run = snakeskin(&args);
        assert!(run.status.success(), "{}", stderr(&run));
        match said {
            Some(words) => assert!(
                stderr(&run).contains(&format!("warning: optics.ambient_ior is 1.33, but {words}")),
                "{pack}: {}",
                stderr(&run)
            ),
            None => assert!(!stderr(&run).contains("has no ambient index"), "{pack}: {}", stderr(&run)),
        }
    }
}
