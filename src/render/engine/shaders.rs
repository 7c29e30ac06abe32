//! The WGSL programs as the GPU receives them, and the numbers they share with Rust.
//!
//! WGSL has no include, so each program is its files concatenated, after a prelude that
//! this module generates from the Rust constants themselves: the GGX α and cosine floors,
//! the LUT's thickness axis, the rgb3 wavelengths, the Belcour–Barla fits, and the codes of
//! every override constant (film method, layer model, stage, map view). A number shared by
//! the CPU and the GPU is written once, in Rust; the shaders name it. Redeclaring a
//! generated name in a `.wgsl` file fails validation (`tests/gpu.rs`), and a test below
//! checks that no file spells a generated value out.

use crate::maps::MapKind;
use crate::optics::brdf::{ALPHA_MIN, COS_MIN, LENGTH_MIN, Model};
use crate::optics::fast::{BOX_NARROW_RAD, HARMONICS_DENOM_MIN, Q_NEGLIGIBLE, SINC_SMALL};
use crate::optics::lut::{COARSE_MAX_NM, FINE_MAX_NM};
use crate::optics::methods::{BB_LOBES, GAUSSIAN_FIT_HARMONICS, RGB3_BAND_NM, RGB3_NM, bb_amplitude};

use super::film::GpuFilmMethod;
use super::scene::{Stage, View};

/// Film colour by method (LUT lookup and the analytic methods).
pub const FILM_WGSL: &str = include_str!("../../../shaders/film.wgsl");
/// The WGSL of the BRDF.
pub const BRDF_WGSL: &str = include_str!("../../../shaders/brdf.wgsl");
/// Compute entry point evaluating the BRDF on a buffer of samples.
pub const BRDF_EVAL_WGSL: &str = include_str!("../../../shaders/brdf_eval.wgsl");
pub const SCENE_WGSL: &str = include_str!("../../../shaders/scene.wgsl");
pub const SKIN_WGSL: &str = include_str!("../../../shaders/skin.wgsl");
pub const PLAIN_WGSL: &str = include_str!("../../../shaders/plain.wgsl");
pub const TONEMAP_WGSL: &str = include_str!("../../../shaders/tonemap.wgsl");

/// The name the generated prelude goes by in a program's file list.
pub const GENERATED: &str = "generated constants";

/// A WGSL f32 literal for `v`: Rust's shortest round-trip form of the f32, which WGSL reads
/// back to the same f32.
fn f32_literal(v: f64) -> String {
    format!("{:?}", v as f32)
}

fn vec3_literal(v: [f64; 3]) -> String {
    format!("vec3<f32>({}, {}, {})", f32_literal(v[0]), f32_literal(v[1]), f32_literal(v[2]))
}

fn vec4_literal(v: [f64; 4]) -> String {
    format!("vec4<f32>({}, {}, {}, {})", f32_literal(v[0]), f32_literal(v[1]), f32_literal(v[2]), f32_literal(v[3]))
}

/// The shared numbers as WGSL `const` declarations: (name, WGSL type, value).
pub fn shared_constants() -> Vec<(&'static str, &'static str, String)> {
    let mut c: Vec<(&'static str, &'static str, String)> = vec![
        ("PI", "f32", f32_literal(std::f64::consts::PI)),
        ("ALPHA_MIN", "f32", f32_literal(ALPHA_MIN)),
        ("COS_MIN", "f32", f32_literal(COS_MIN)),
        ("LENGTH_MIN", "f32", f32_literal(LENGTH_MIN)),
        ("FINE_MAX_NM", "f32", f32_literal(FINE_MAX_NM)),
        ("COARSE_MAX_NM", "f32", f32_literal(COARSE_MAX_NM)),
        ("HARMONICS_DENOM_MIN", "f32", f32_literal(HARMONICS_DENOM_MIN as f64)),
        ("SINC_SMALL", "f32", f32_literal(SINC_SMALL as f64)),
        ("BOX_NARROW_RAD", "f32", f32_literal(BOX_NARROW_RAD as f64)),
        ("Q_NEGLIGIBLE", "f32", f32_literal(Q_NEGLIGIBLE as f64)),
        ("RGB3_NM", "vec3<f32>", vec3_literal(RGB3_NM.map(f64::from))),
        ("RGB3_BAND_NM", "f32", f32_literal(RGB3_BAND_NM as f64)),
        // Belcour–Barla lobes as (X, Y, Z, X's second lobe).
        ("BB_AMP", "vec4<f32>", vec4_literal(BB_LOBES.map(bb_amplitude))),
        ("BB_POS", "vec4<f32>", vec4_literal(BB_LOBES.map(|l| l.1))),
        ("BB_VAR", "vec4<f32>", vec4_literal(BB_LOBES.map(|l| l.2))),
        ("GAUSSIAN_FIT_HARMONICS", "u32", format!("{GAUSSIAN_FIT_HARMONICS}u")),
    ];
    let code = |v: u32| format!("{v}u");
    for (name, method) in [
        ("FILM_LUT", GpuFilmMethod::Lut),
        ("FILM_RGB3", GpuFilmMethod::Rgb3),
        ("FILM_SPECTRAL_N", GpuFilmMethod::SpectralN(1)),
        ("FILM_GAUSSIAN_FIT", GpuFilmMethod::GaussianFit),
        ("FILM_NONE", GpuFilmMethod::None),
    ] {
        c.push((name, "u32", code(method.code())));
    }
    for model in Model::ALL {
        let name = match model {
            Model::Thesis => "MODEL_THESIS",
        };
        c.push((name, "u32", code(model.code())));
    }
    for stage in Stage::ALL {
        let name = match stage {
            Stage::Diffuse => "STAGE_DIFFUSE",
            Stage::DiffuseNormal => "STAGE_DIFFUSE_NORMAL",
            Stage::Film => "STAGE_FILM",
            Stage::All => "STAGE_ALL",
        };
        c.push((name, "u32", code(stage.code())));
    }
    c.push(("VIEW_SHADED", "u32", code(View::Shaded(Stage::All).map_code())));
    for map in MapKind::ALL {
        let name = match map {
            MapKind::Color => "VIEW_COLOR",
            MapKind::Height => "VIEW_HEIGHT",
            MapKind::Normal => "VIEW_NORMAL",
            MapKind::Roughness => "VIEW_ROUGHNESS",
            MapKind::Iridescence => "VIEW_IRIDESCENCE",
        };
        c.push((name, "u32", code(View::Map(map).map_code())));
    }
    c
}

/// The generated prelude every program starts with.
pub fn generated_constants() -> String {
    let mut out = String::from("// Generated by render::shaders::generated_constants from the Rust constants.\n");
    for (name, ty, value) in shared_constants() {
        out.push_str(&format!("const {name}: {ty} = {value};\n"));
    }
    out
}

/// Every shader program as the GPU receives it: (name, WGSL source, shader files it uses).
pub fn shader_programs() -> Vec<(&'static str, String, Vec<&'static str>)> {
    let prelude = generated_constants();
    let program = |parts: &[(&'static str, &str)]| {
        let mut source = prelude.clone();
        for (_, part) in parts {
            source.push('\n');
            source.push_str(part);
        }
        (source, std::iter::once(GENERATED).chain(parts.iter().map(|(name, _)| *name)).collect())
    };
    let film = ("film.wgsl", FILM_WGSL);
    let brdf = ("brdf.wgsl", BRDF_WGSL);
    let scene = ("scene.wgsl", SCENE_WGSL);
    let mut all = Vec::new();
    for (name, parts) in [
        ("brdf_eval", vec![film, brdf, ("brdf_eval.wgsl", BRDF_EVAL_WGSL)]),
        ("skin", vec![film, brdf, scene, ("skin.wgsl", SKIN_WGSL)]),
        ("plain", vec![scene, ("plain.wgsl", PLAIN_WGSL)]),
        ("tonemap", vec![("tonemap.wgsl", TONEMAP_WGSL)]),
    ] {
        let (source, files) = program(&parts);
        all.push((name, source, files));
    }
    all
}

/// The WGSL source of one program.
pub fn program(name: &str) -> String {
    shader_programs().into_iter().find(|(n, _, _)| *n == name).map(|(_, s, _)| s).expect("known shader program")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The literal spellings a `.wgsl` file would use for a generated value.
    fn spellings(value: &str) -> Vec<String> {
        let mut out = vec![];
        if let Ok(v) = value.parse::<f32>() {
            out.push(format!("{v:?}"));
            out.push(format!("{v:e}"));
        }
        out
    }

    #[test]
    fn no_shader_file_spells_out_a_generated_number() {
        let files = [FILM_WGSL, BRDF_WGSL, BRDF_EVAL_WGSL, SCENE_WGSL, SKIN_WGSL, PLAIN_WGSL, TONEMAP_WGSL];
        // Every scalar f32 (the codes 0..5 also occur as ordinary numbers and are not searched).
        for (name, _, value) in shared_constants().into_iter().filter(|(_, ty, _)| *ty == "f32") {
            for spelling in spellings(&value) {
                for file in files {
                    // A line may say why its number is its own ("not a shared constant").
                    let lines = file.lines().filter(|l| !l.trim_start().starts_with("//"));
                    let found = lines.filter(|l| !l.contains("// not a shared constant")).any(|l| {
                        l.match_indices(&spelling).any(|(i, _)| {
                            let before = l[..i].chars().last().is_none_or(|c| !c.is_ascii_alphanumeric() && c != '.');
                            let after = l[i + spelling.len()..].chars().next().is_none_or(|c| !c.is_ascii_digit());
                            before && after
                        })
                    });
                    assert!(!found, "a shader file spells out {name} = {spelling}: name the constant instead");
                }
            }
        }
        // Negative control: the search does find a spelled-out value.
        assert!(spellings(&f32_literal(COS_MIN)).iter().any(|s| "let c = max(x, 1e-6);".contains(s.as_str())));
    }

    #[test]
    fn the_prelude_declares_each_name_once_with_the_rust_value() {
        let names: Vec<&str> = shared_constants().iter().map(|(n, _, _)| *n).collect();
        let mut unique = names.clone();
        unique.sort();
        unique.dedup();
        assert_eq!(unique.len(), names.len(), "{names:?}");
        let prelude = generated_constants();
        assert!(prelude.contains("const COS_MIN: f32 = 1e-6;"), "{prelude}");
        assert!(prelude.contains(&format!("const MODEL_THESIS: u32 = {}u;", Model::Thesis.code())), "{prelude}");
    }
}
