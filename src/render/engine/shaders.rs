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
use crate::optics::brdf::energy::{
    E1_MU, E1_ROUGHNESS, LOBE_NODES, MS_NODES, MS_NORM_MIN, PAIR_NODES, PAIR_SLOT, PAIR_WEIGHTS_SLOT, ROW_FILM_READS,
    SHARE_SLOT, ms_rule,
};
use crate::optics::brdf::path::THROUGH_NODES;
use crate::optics::brdf::{ALPHA_MIN, COS_MIN, LENGTH_MIN, Model};
use crate::optics::fast::{BOX_NARROW_RAD, HARMONICS_DENOM_MIN, MAX_Q2_F32, Q_NEGLIGIBLE, SINC_SMALL};
use crate::optics::lut::{COARSE_MAX_NM, FINE_MAX_NM};
use crate::optics::methods::{
    BB_LOBES, BB_METRES_PER_NM, GAUSSIAN_FIT_EXACT_NM, GAUSSIAN_FIT_HARMONICS, GAUSSIAN_FIT_MAX_REST, RGB3_BAND_NM,
    RGB3_NM, bb_amplitude,
};
use crate::render::engine::scene::{BOUNCE_THICKNESSES, SCENE_LIGHTS};

use super::film::GpuFilmMethod;
use super::material::{
    FOOTPRINT_SMALL_EXPONENT, FOOTPRINT_WAVELENGTH_NM, THICKNESS_MOMENT_CENTRE, THICKNESS_SPREAD_MIN,
};
use super::renderer::{GBUFFER_ALBEDO_GEOMETRY, GBUFFER_POSITION_NORMAL, TONE_MAP_CURVE, TONE_MAP_NONE};
use super::scene::{Stage, View};
use crate::render::reference::frame::{PBR_NEUTRAL_DESATURATION, PBR_NEUTRAL_OFFSET, PBR_NEUTRAL_START_COMPRESSION};

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

// `brdf.wgsl`'s `ms_norms_from_row` lists the rule's eight node constants in an array.
const _: () = assert!(MS_NODES == 8, "brdf.wgsl's ms_norms_from_row lists eight nodes");

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
        ("MAX_Q2", "f32", f32_literal(MAX_Q2_F32 as f64)),
        ("F32_EPSILON", "f32", f32_literal(f32::EPSILON as f64)),
        ("F32_MIN_POSITIVE", "f32", f32_literal(f32::MIN_POSITIVE as f64)),
        ("F32_MAX", "f32", f32_literal(f32::MAX as f64)),
        // brdf_eval.wgsl's entry points; the dispatch divides by it (render::reference::brdf_eval).
        ("EVAL_WORKGROUP_SIZE", "u32", format!("{}u", crate::render::reference::brdf_eval::WORKGROUP_SIZE)),
        ("RGB3_NM", "vec3<f32>", vec3_literal(RGB3_NM.map(f64::from))),
        ("RGB3_BAND_NM", "f32", f32_literal(RGB3_BAND_NM as f64)),
        // Belcour–Barla lobes as (X, Y, Z, X's second lobe).
        ("BB_AMP", "vec4<f32>", vec4_literal(BB_LOBES.map(bb_amplitude))),
        ("BB_POS", "vec4<f32>", vec4_literal(BB_LOBES.map(|l| l.1))),
        ("BB_VAR", "vec4<f32>", vec4_literal(BB_LOBES.map(|l| l.2))),
        ("BB_METRES_PER_NM", "f32", f32_literal(BB_METRES_PER_NM)),
        ("MS_NORM_MIN", "f32", f32_literal(MS_NORM_MIN)),
        // The scene's directional lights (render::engine::scene::Lighting::lights).
        ("SCENE_LIGHTS", "u32", format!("{SCENE_LIGHTS}u")),
        ("GAUSSIAN_FIT_HARMONICS", "u32", format!("{GAUSSIAN_FIT_HARMONICS}u")),
        ("GAUSSIAN_FIT_EXACT_NM", "f32", f32_literal(GAUSSIAN_FIT_EXACT_NM)),
        ("GAUSSIAN_FIT_MAX_REST", "f32", f32_literal(GAUSSIAN_FIT_MAX_REST)),
        ("PBR_NEUTRAL_OFFSET", "f32", f32_literal(PBR_NEUTRAL_OFFSET)),
        ("PBR_NEUTRAL_START_COMPRESSION", "f32", f32_literal(PBR_NEUTRAL_START_COMPRESSION)),
        ("PBR_NEUTRAL_DESATURATION", "f32", f32_literal(PBR_NEUTRAL_DESATURATION)),
        ("TONE_MAP_CURVE", "u32", format!("{TONE_MAP_CURVE}u")),
        ("TONE_MAP_NONE", "u32", format!("{TONE_MAP_NONE}u")),
        // The sRGB transfer (export::srgb), which the map viewer undoes (skin.wgsl's
        // `srgb_decode`) so that the sRGB target shows each map as its file stores it.
        ("SRGB_ENCODED_KNEE", "f32", f32_literal(crate::export::srgb::SRGB_ENCODED_KNEE)),
        ("SRGB_SLOPE", "f32", f32_literal(crate::export::srgb::SRGB_SLOPE)),
        ("SRGB_SCALE", "f32", f32_literal(crate::export::srgb::SRGB_SCALE)),
        ("SRGB_OFFSET", "f32", f32_literal(crate::export::srgb::SRGB_OFFSET)),
        ("SRGB_GAMMA", "f32", f32_literal(crate::export::srgb::SRGB_GAMMA)),
        ("GBUFFER_POSITION_NORMAL", "u32", format!("{GBUFFER_POSITION_NORMAL}u")),
        ("GBUFFER_ALBEDO_GEOMETRY", "u32", format!("{GBUFFER_ALBEDO_GEOMETRY}u")),
        // The axes of the rough lobe's table (optics::brdf::energy; the table itself is a
        // storage buffer of the film bind group, render::engine::film).
        ("E1_MU", "u32", format!("{E1_MU}u")),
        ("E1_ROUGHNESS", "u32", format!("{E1_ROUGHNESS}u")),
        // The lobe table's entries (render::engine::film::lobe_table) and the slots of a
        // lobe node (optics::brdf::energy::node).
        ("LOBE_VEC4S", "u32", format!("{}u", super::film::LOBE_VEC4S)),
        ("LOBE_NODE_SLOT", "u32", format!("{}u", super::film::LOBE_NODE_SLOT)),
        ("LOBE_THROUGH_SLOT", "u32", format!("{}u", super::film::LOBE_THROUGH_SLOT)),
        ("LOBE_NODES", "u32", format!("{LOBE_NODES}u")),
        // The lobe table's quantile section, where a material has it (film::lobe_table).
        ("QUANTILES", "u32", format!("{}u", crate::optics::brdf::energy::QUANTILES)),
        ("QUANTILE_VEC4S", "u32", format!("{}u", super::film::QUANTILE_VEC4S)),
        ("LOBE_ENTRIES", "u32", format!("{}u", E1_MU * E1_ROUGHNESS)),
        ("PAIR_NODES", "u32", format!("{PAIR_NODES}u")),
        ("PAIR_SLOT", "u32", format!("{PAIR_SLOT}u")),
        ("PAIR_WEIGHTS_SLOT", "u32", format!("{PAIR_WEIGHTS_SLOT}u")),
        ("SHARE_SLOT", "u32", format!("{SHARE_SLOT}u")),
        ("THROUGH_NODES", "u32", format!("{THROUGH_NODES}u")),
        ("ROW_FILM_READS", "u32", format!("{ROW_FILM_READS}u")),
        ("MS_NODES", "u32", format!("{MS_NODES}u")),
        // K and E's film thicknesses (render::engine::scene::BOUNCE_THICKNESSES) and the
        // scene uniform's table length.
        ("BOUNCE_THICKNESSES", "u32", format!("{BOUNCE_THICKNESSES}u")),
        ("BOUNCE_ENTRIES", "u32", format!("{}u", E1_ROUGHNESS * BOUNCE_THICKNESSES)),
        // The thickness texture's second moment and the spread its rounding leaves
        // (render::engine::material).
        ("THICKNESS_MOMENT_CENTRE", "f32", f32_literal(THICKNESS_MOMENT_CENTRE as f64)),
        ("THICKNESS_SPREAD_MIN", "f32", f32_literal(THICKNESS_SPREAD_MIN as f64)),
        ("FOOTPRINT_WAVELENGTH_NM", "f32", f32_literal(FOOTPRINT_WAVELENGTH_NM)),
        ("FOOTPRINT_SMALL_EXPONENT", "f32", f32_literal(FOOTPRINT_SMALL_EXPONENT)),
    ];
    // The multiple-scatter lobe's normalisation rule (optics::brdf::energy::ms_rule), one
    // constant per node: (μ, 2 w μ).
    const MS_NODE_NAMES: [&str; MS_NODES] =
        ["MS_NODE_0", "MS_NODE_1", "MS_NODE_2", "MS_NODE_3", "MS_NODE_4", "MS_NODE_5", "MS_NODE_6", "MS_NODE_7"];
    for (name, &(mu, weight)) in MS_NODE_NAMES.iter().zip(ms_rule()) {
        c.push((name, "vec2<f32>", format!("vec2<f32>({}, {})", f32_literal(mu), f32_literal(2.0 * weight * mu))));
    }
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
            Model::Layered => "MODEL_LAYERED",
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
            MapKind::Ao => unreachable!("not in MapKind::ALL"),
        };
        c.push((name, "u32", code(View::Map(map).map_code())));
    }
    c
}

/// The generated prelude every program starts with.
pub fn generated_constants() -> String {
    let mut out =
        String::from("// Generated by render::engine::shaders::generated_constants from the Rust constants.\n");
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

    /// The size in bytes WGSL gives struct `name` of `program` (naga's layout rules).
    fn wgsl_struct_size(program_name: &str, name: &str) -> u32 {
        let (module, handle) = wgsl_struct(program_name, name);
        let mut layouter = naga::proc::Layouter::default();
        layouter.update(module.to_ctx()).expect("the program's types lay out");
        layouter[handle].size
    }

    /// `program`'s module, parsed, and its type `name`.
    fn wgsl_struct(program_name: &str, name: &str) -> (naga::Module, naga::Handle<naga::Type>) {
        let module = naga::front::wgsl::parse_str(&program(program_name)).expect("the program parses");
        let handle = module
            .types
            .iter()
            .find(|(_, t)| t.name.as_deref() == Some(name))
            .map(|(handle, _)| handle)
            .unwrap_or_else(|| panic!("{program_name} has no struct {name}"));
        (module, handle)
    }

    /// The structs Rust writes into GPU buffers have the sizes their WGSL twins read, which
    /// are copied by hand (a field added on one side only shifted every later sample or
    /// uniform without an error). Negative control: a struct of another size is told apart.
    #[test]
    fn buffers_have_the_sizes_their_shaders_read() {
        use crate::render::engine::film::FilmInfo;
        use crate::render::engine::scene::SceneUniform;
        use crate::render::reference::brdf_eval::GpuSample;
        for (program_name, name, rust) in [
            ("brdf_eval", "Sample", std::mem::size_of::<GpuSample>()),
            ("brdf_eval", "FilmInfo", std::mem::size_of::<FilmInfo>()),
            ("skin", "Scene", std::mem::size_of::<SceneUniform>()),
        ] {
            assert_eq!(wgsl_struct_size(program_name, name) as usize, rust, "{program_name}'s {name}");
        }
        assert_ne!(wgsl_struct_size("brdf_eval", "Sample") as usize, std::mem::size_of::<FilmInfo>());
    }

    /// Each member of WGSL struct `name` of `program`, by name, at the offset naga lays it
    /// out at.
    fn wgsl_struct_members(program_name: &str, name: &str) -> Vec<(String, u32)> {
        let (module, handle) = wgsl_struct(program_name, name);
        match &module.types[handle].inner {
            naga::TypeInner::Struct { members, .. } => {
                members.iter().map(|m| (m.name.clone().unwrap_or_default(), m.offset)).collect()
            }
            other => panic!("{name} is not a struct: {other:?}"),
        }
    }

    /// A Rust struct's fields, as named, at their offsets.
    macro_rules! rust_members {
        ($ty:ty { $($field:ident),* $(,)? }) => {
            vec![$((stringify!($field).to_string(), std::mem::offset_of!($ty, $field) as u32)),*]
        };
    }

    /// The structs' members lie where their WGSL twins read them, field by field: sizes
    /// alone (`buffers_have_the_sizes_their_shaders_read`) let two fields of one size trade
    /// places on one side (`sky_top` and `sky_bottom`, `n_fine` and `n_coarse`) unseen, a
    /// review found. Each field is named once here, so a field added to a Rust struct and
    /// not listed fails the size test, and one listed in another order than WGSL's fails
    /// this. Seen failing (the size test passing) with `SceneUniform`'s `sky_top` and
    /// `sky_bottom` traded.
    #[test]
    fn buffers_have_their_members_where_their_shaders_read_them() {
        use crate::render::engine::film::FilmInfo;
        use crate::render::engine::scene::SceneUniform;
        use crate::render::reference::brdf_eval::GpuSample;
        for (program_name, name, rust) in [
            (
                "brdf_eval",
                "Sample",
                rust_members!(GpuSample { normal_roughness, wi_thickness, wo_n0, tau_n2, albedo, k, e }),
            ),
            (
                "brdf_eval",
                "FilmInfo",
                rust_members!(FilmInfo { n_cos, n_fine, n_coarse, n_bands, iors_band, xyz_to_rgb }),
            ),
            (
                "skin",
                "Scene",
                rust_members!(SceneUniform {
                    view_proj,
                    camera,
                    light_dir,
                    light_rgb,
                    sky_top,
                    sky_bottom,
                    film,
                    optical_depth,
                    bounce_k,
                    bounce_e,
                }),
            ),
        ] {
            assert_eq!(wgsl_struct_members(program_name, name), rust, "{program_name}'s {name}");
        }
    }

    /// Every numeric literal outside comments, with its line (a token starting with a digit,
    /// or a '.' followed by one, not inside an identifier), parsed as f64 (suffix dropped).
    fn literals(source: &str) -> Vec<(f64, String)> {
        let mut out = vec![];
        for line in source.lines() {
            if line.contains("// not a shared constant") {
                continue;
            }
            let code = line.split("//").next().unwrap_or("");
            let bytes = code.as_bytes();
            let mut i = 0;
            while i < bytes.len() {
                let starts =
                    bytes[i].is_ascii_digit() || (bytes[i] == b'.' && bytes.get(i + 1).is_some_and(u8::is_ascii_digit));
                let inside_word = i > 0 && (bytes[i - 1].is_ascii_alphanumeric() || bytes[i - 1] == b'_');
                if starts && !inside_word {
                    let mut j = i;
                    while j < bytes.len()
                        && (bytes[j].is_ascii_digit()
                            || bytes[j] == b'.'
                            || ((bytes[j] == b'e' || bytes[j] == b'E') && j + 1 < bytes.len())
                            || ((bytes[j] == b'-' || bytes[j] == b'+') && matches!(bytes[j - 1], b'e' | b'E')))
                    {
                        j += 1;
                    }
                    if let Ok(v) = code[i..j].parse::<f64>() {
                        out.push((v, line.trim().to_string()));
                    }
                    i = j;
                } else {
                    i += 1;
                }
            }
        }
        out
    }

    /// The f32 values of the generated constants (vector components included), without the
    /// ordinary numbers any shader uses (0, ±0.5, small integers).
    fn generated_values() -> Vec<(&'static str, f32)> {
        let mut values = vec![];
        for (name, ty, value) in shared_constants() {
            if !ty.contains("f32") {
                continue;
            }
            let inner = match value.find('(') {
                Some(open) => value[open + 1..].trim_end_matches(')'),
                None => value.as_str(),
            };
            for part in inner.split(',') {
                if let Ok(v) = part.trim().parse::<f32>() {
                    let ordinary = v.fract() == 0.0 && v.abs() <= 4.0 || v.abs() == 0.5;
                    if !ordinary {
                        values.push((name, v));
                    }
                }
            }
        }
        values
    }

    fn spelled_out(source: &str) -> Vec<String> {
        let generated = generated_values();
        let mut found = vec![];
        for (v, line) in literals(source) {
            if let Some((name, _)) = generated.iter().find(|(_, g)| *g == v as f32) {
                found.push(format!("{name} in `{line}`"));
            }
        }
        // Switch cases and override comparisons name their codes.
        for line in source.lines().map(|l| l.split("//").next().unwrap_or("").trim()) {
            let code_literal = |rest: &str| rest.trim_start().starts_with(|c: char| c.is_ascii_digit());
            if let Some(rest) = line.strip_prefix("case ")
                && code_literal(rest)
            {
                found.push(format!("a literal case in `{line}`"));
            }
            for name in ["STAGE", "VIEW_MAP", "FILM_METHOD", "BRDF_MODEL"] {
                for op in ["==", "!=", "<=", ">=", "<", ">"] {
                    if let Some(at) = line.find(&format!("{name} {op} "))
                        && code_literal(&line[at + name.len() + op.len() + 2..])
                    {
                        found.push(format!("{name} compared with a literal in `{line}`"));
                    }
                }
            }
        }
        found
    }

    #[test]
    fn no_shader_file_spells_out_a_generated_number() {
        let files = [FILM_WGSL, BRDF_WGSL, BRDF_EVAL_WGSL, SCENE_WGSL, SKIN_WGSL, PLAIN_WGSL, TONEMAP_WGSL];
        for file in files {
            let found = spelled_out(file);
            assert!(found.is_empty(), "name the generated constants instead: {found:?}");
        }
        // Negative controls: the first version's spellings are found (its COS_MIN and PI,
        // an rgb3 wavelength, a Belcour–Barla centre, a literal stage code and case).
        for old in [
            "let c = max(x, 0.000001);",
            "const PI: f32 = 3.14159265358979;",
            "band_reflectance(f, n.y, thickness_nm, 650.0, 100.0),",
            "xyz.y += mag * bb_lobe(4.4201e-13, 1.7953e+06, 9.3046e+09, phase, arg);",
            "if (STAGE <= 1u) {",
            "case 3u: {",
        ] {
            assert!(!spelled_out(old).is_empty(), "not caught: {old}");
        }
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
