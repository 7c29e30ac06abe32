//! snakeskin: physically based snake-skin texture sets from species presets.
//!
//! The pipeline is "parse first, then run": a preset is read and validated (`preset`), turned
//! into a node graph (`maps`), evaluated on demand (`graph`) with pure pixel kernels (`ops`),
//! and written atomically (`export`). `material` is the one home of what a set means (map
//! formats, layer optics, thesis defaults); `generate` plans and runs one set, `gltf_export` puts one on a mesh as glTF, `batch` runs many; `render` is
//! the wgpu preview. The library neither parses command lines nor prints: the `snakeskin`
//! binary (`src/bin/snakeskin/`) does both.

pub mod batch;
pub mod export;
pub mod generate;
pub mod gltf_export;
pub mod graph;
pub mod maps;
pub mod material;
pub mod memory;
pub mod ops;
pub mod optics;
pub mod preset;
pub mod render;
pub mod text_file;
pub mod toml_text;

pub use generate::{GenerateReport, GenerateRequest, Plan, generate};
pub use material::parse_map_list;

/// Smallest and largest accepted `--size` (pixels per side). Whether a size fits is decided
/// by the memory estimate (`memory`), not by this bound: 16384² needs about 17 GiB.
pub const SIZE_RANGE: std::ops::RangeInclusive<u32> = 16..=16384;

/// The size of a set whose size is not given (`--size`, a jobs file's `sizes`).
pub const DEFAULT_SIZE: u64 = 1024;

#[derive(Debug, thiserror::Error)]
pub enum Error {
    #[error(transparent)]
    Preset(#[from] preset::PresetError),
    #[error(transparent)]
    Export(#[from] export::ExportError),
    #[error(transparent)]
    Batch(#[from] batch::BatchError),
    #[error("invalid --size {size}: accepted sizes are {lo} to {hi} pixels", lo = SIZE_RANGE.start(), hi = SIZE_RANGE.end())]
    Size { size: u64 },
    #[error(
        "a body atlas {width} wide is {height} tall (body.length widths), over the {max} rows a map may have; give \
         {size_option} {fits} or less, or a shorter body.length"
    )]
    Height { width: usize, height: usize, max: usize, size_option: &'static str, fits: usize },
    /// A combination of options the tool does not support (yet).
    #[error("{0}")]
    Unsupported(String),
    /// An optics query outside what the physics covers (`snakeskin brdf`).
    #[error("invalid query: {0}")]
    Query(String),
    #[error(transparent)]
    Gpu(#[from] render::GpuError),
    /// A command-line option's value that the command does not accept (`sheet --species`).
    #[error("invalid {option}: {reason}")]
    InvalidOption { option: &'static str, reason: String },
    /// A preview option outside what the renderer accepts (`snakeskin preview`).
    #[error("invalid preview option: {0}")]
    Preview(String),
    /// The work would need more memory than the machine has available.
    #[error("{what} needs about {needed_mib} MiB at its peak, but only {available_mib} MiB are available {}; {}", .bound.place(), .bound.remedy())]
    Memory { what: String, needed_mib: u64, available_mib: u64, bound: memory::MemoryBound },
    /// An environment variable the tool reads holds a value it does not accept.
    #[error("invalid {variable}={value:?}: expected {accepted}")]
    Environment { variable: &'static str, value: String, accepted: &'static str },
    /// A failure that is not the user's: a bug or a library refusing valid data.
    #[error("internal error: {0}")]
    Internal(String),
}

impl Error {
    /// True when the user's input is at fault (exit code 2), false for the environment
    /// (I/O, GPU, a concurrent run) and internal failures (exit code 1).
    pub fn is_invalid_input(&self) -> bool {
        match self {
            Error::Export(e) => e.is_invalid_input(),
            Error::Batch(
                batch::BatchError::Planned { source, .. }
                | batch::BatchError::Failed { source, .. }
                | batch::BatchError::Stopped { source, .. },
            ) => source.is_invalid_input(),
            Error::Batch(
                batch::BatchError::Changed { .. }
                | batch::BatchError::Busy { .. }
                | batch::BatchError::MadeMeanwhile { .. },
            ) => false,
            Error::Gpu(_) | Error::Internal(_) => false,
            _ => true,
        }
    }
}
