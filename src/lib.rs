//! snakeskin: physically based snake-skin texture sets from species presets.
//!
//! The pipeline is "parse first, then run": a preset is read and validated (`preset`), turned
//! into a node graph (`maps`), evaluated on demand (`graph`) with pure pixel kernels (`ops`),
//! and written atomically (`export`). `generate` ties the steps together for the CLI and
//! for tests.

pub mod export;
pub mod gallery;
pub mod generate;
pub mod graph;
pub mod maps;
pub mod ops;
pub mod optics;
pub mod preset;
pub mod render;

pub use generate::{GenerateReport, GenerateRequest, generate};

/// Smallest and largest accepted `--size` (pixels per side). 16384² RGB f32 is 3 GiB per
/// colour buffer, the most a 24 GiB machine can evaluate with the graph's peak widths.
pub const SIZE_RANGE: std::ops::RangeInclusive<u32> = 16..=16384;

#[derive(Debug, thiserror::Error)]
pub enum Error {
    #[error(transparent)]
    Preset(#[from] preset::PresetError),
    #[error(transparent)]
    Export(#[from] export::ExportError),
    #[error("invalid --size {size}: accepted sizes are {lo} to {hi} pixels", lo = SIZE_RANGE.start(), hi = SIZE_RANGE.end())]
    Size { size: u64 },
    #[error("invalid --maps: {0}")]
    Maps(String),
    /// An optics query outside what the physics covers (`snakeskin brdf`).
    #[error("invalid query: {0}")]
    Query(String),
    #[error(transparent)]
    Gpu(#[from] render::GpuError),
    /// A preview option outside what the renderer accepts (`snakeskin preview`).
    #[error("invalid preview option: {0}")]
    Preview(String),
}

impl Error {
    /// True when the user's input is at fault (exit code 2), false for I/O trouble.
    pub fn is_invalid_input(&self) -> bool {
        !matches!(self, Error::Export(_) | Error::Gpu(_))
    }
}

/// Parses a comma-separated map list ("color,height"); "all" or empty means all five.
pub fn parse_map_list(list: &str) -> Result<Vec<maps::MapKind>, Error> {
    if list.trim().is_empty() || list.trim() == "all" {
        return Ok(maps::MapKind::ALL.to_vec());
    }
    let mut out = Vec::new();
    for item in list.split(',').map(str::trim) {
        let map: maps::MapKind = item.parse().map_err(Error::Maps)?;
        if !out.contains(&map) {
            out.push(map);
        }
    }
    out.sort();
    Ok(out)
}
