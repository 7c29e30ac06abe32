//! `<name>.material.json`: what each file is, so a renderer or pipeline can use the set
//! without guessing (colour space, bit depth, meaning, and the film thickness range the
//! iridescence map spans, as glTF's KHR_materials_iridescence does).

use serde::Serialize;

use crate::maps::{MapKind, thickness_range_nm};
use crate::ops::filters::NormalConvention;
use crate::preset::LoadedPreset;

#[derive(Debug, Serialize)]
pub struct Manifest {
    pub generator: String,
    pub generator_version: String,
    pub preset: String,
    pub preset_hash: String,
    pub species: Option<String>,
    pub seed: u64,
    pub width: usize,
    pub height: usize,
    pub maps: Vec<MapEntry>,
    pub iridescence: IridescenceRange,
    pub optics: OpticsEntry,
}

#[derive(Debug, Serialize)]
pub struct MapEntry {
    pub map: String,
    pub file: String,
    pub color_space: String,
    pub channels: u32,
    pub bit_depth: u32,
    pub meaning: String,
}

#[derive(Debug, Serialize)]
pub struct IridescenceRange {
    /// Thickness at sample value 0 and at the maximum sample value.
    pub min_nm: f64,
    pub max_nm: f64,
}

#[derive(Debug, Serialize)]
pub struct OpticsEntry {
    pub ambient_ior: f64,
    pub film_ior: f64,
    pub pigment_ior: f64,
    pub film_thickness_nm: f64,
    pub pigment_thickness: f64,
    pub absorption: [f64; 3],
}

fn entry(map: MapKind, file: String, convention: NormalConvention) -> MapEntry {
    let (color_space, channels, bit_depth, meaning) = match map {
        MapKind::Color => ("srgb", 3, 8, "base colour (albedo k_d of the Lambertian base layer)".to_string()),
        MapKind::Height => ("linear", 1, 16, "relative surface height, 0 = lowest".to_string()),
        MapKind::Normal => {
            let y = match convention {
                NormalConvention::OpenGl => "OpenGL convention, +Y up",
                NormalConvention::DirectX => "DirectX convention, +Y down",
            };
            ("linear", 3, 8, format!("tangent-space normal, rgb = xyz * 0.5 + 0.5, {y}"))
        }
        MapKind::Roughness => ("linear", 1, 8, "perceptual roughness r; GGX alpha = r^2 (glTF)".to_string()),
        MapKind::Iridescence => {
            ("linear", 1, 16, "film thickness: min_nm + value / 65535 * (max_nm - min_nm)".to_string())
        }
    };
    MapEntry { map: map.name().into(), file, color_space: color_space.into(), channels, bit_depth, meaning }
}

pub fn manifest(
    loaded: &LoadedPreset,
    size: usize,
    files: &[(MapKind, String)],
    convention: NormalConvention,
) -> Manifest {
    let p = &loaded.preset;
    let (min_nm, max_nm) = thickness_range_nm(p);
    Manifest {
        generator: "snakeskin".into(),
        generator_version: env!("CARGO_PKG_VERSION").into(),
        preset: loaded.name.clone(),
        preset_hash: loaded.content_hash.clone(),
        species: p.species.clone(),
        seed: p.seed,
        width: size,
        height: size,
        maps: files.iter().map(|(m, f)| entry(*m, f.clone(), convention)).collect(),
        iridescence: IridescenceRange { min_nm, max_nm },
        optics: OpticsEntry {
            ambient_ior: p.optics.ambient_ior,
            film_ior: p.optics.film_ior,
            pigment_ior: p.optics.pigment_ior,
            film_thickness_nm: p.optics.film_thickness_nm,
            pigment_thickness: p.optics.pigment_thickness,
            absorption: p.optics.absorption.0,
        },
    }
}
