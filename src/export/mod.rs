//! Map encoding (PNG in the formats DESIGN.md fixes), the material manifest, and atomic
//! output.
//!
//! Encoding runs in parallel, one map per task: PNG compression of a 2K set is ~0.2 s on
//! one core, the largest single cost after generation.

mod atomic;
mod manifest;

pub use atomic::write_all_atomically;
pub use manifest::{Manifest, manifest};

use std::collections::BTreeMap;
use std::io::Cursor;
use std::path::PathBuf;

use image::codecs::png::{CompressionType, FilterType, PngEncoder};
use image::{ExtendedColorType, ImageEncoder};
use rayon::prelude::*;

use crate::maps::MapKind;
use crate::ops::Image;

#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    #[error("cannot write {path}: {source}")]
    Io { path: PathBuf, source: std::io::Error },
    #[error("cannot encode the {map} map: {message}")]
    Encode { map: MapKind, message: String },
}

/// File name of a map for a preset name.
pub fn map_file_name(preset_name: &str, map: MapKind) -> String {
    format!("{preset_name}_{}.png", map.name())
}

/// sRGB encoding of a linear value (IEC 61966-2-1), 8 bits.
pub fn linear_to_srgb8(linear: f32) -> u8 {
    let c = linear.clamp(0.0, 1.0);
    let s = if c <= 0.003_130_8 { c * 12.92 } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 };
    (s * 255.0 + 0.5) as u8
}

fn unit_to_u8(x: f32) -> u8 {
    (x.clamp(0.0, 1.0) * 255.0 + 0.5) as u8
}

fn unit_to_u16(x: f32) -> u16 {
    (x.clamp(0.0, 1.0) * 65535.0 + 0.5) as u16
}

/// Raw samples and PNG colour type of a map, per DESIGN.md's formats.
fn samples(map: MapKind, image: &Image) -> (Vec<u8>, ExtendedColorType) {
    match map {
        MapKind::Color => (image.data.par_iter().map(|&c| linear_to_srgb8(c)).collect(), ExtendedColorType::Rgb8),
        MapKind::Normal => {
            (image.data.par_iter().map(|&n| unit_to_u8(n * 0.5 + 0.5)).collect(), ExtendedColorType::Rgb8)
        }
        MapKind::Roughness => (image.data.par_iter().map(|&r| unit_to_u8(r)).collect(), ExtendedColorType::L8),
        // `ImageEncoder::write_image` takes 16-bit samples in native byte order.
        MapKind::Height | MapKind::Iridescence => {
            (image.data.par_iter().flat_map_iter(|&h| unit_to_u16(h).to_ne_bytes()).collect(), ExtendedColorType::L16)
        }
    }
}

/// Encodes one map as PNG bytes.
pub fn encode_png(map: MapKind, image: &Image) -> Result<Vec<u8>, ExportError> {
    let (data, color) = samples(map, image);
    let mut out = Cursor::new(Vec::new());
    let encoder = PngEncoder::new_with_quality(&mut out, CompressionType::Fast, FilterType::Adaptive);
    encoder
        .write_image(&data, image.width as u32, image.height as u32, color)
        .map_err(|e| ExportError::Encode { map, message: e.to_string() })?;
    Ok(out.into_inner())
}

/// Encodes every map in parallel; returns (file name, bytes) in map order.
pub fn encode_all(preset_name: &str, maps: &BTreeMap<MapKind, Image>) -> Result<Vec<(String, Vec<u8>)>, ExportError> {
    maps.par_iter().map(|(map, image)| Ok((map_file_name(preset_name, *map), encode_png(*map, image)?))).collect()
}
