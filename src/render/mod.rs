//! GPU side: headless device setup and the WGSL twin of the multi-layer BRDF.
//!
//! Headless first (as wgpu's examples): everything draws or computes into buffers and
//! textures that tests read back, so the CPU/GPU comparison and a future window share one
//! code path. Shaders are WGSL files in `shaders/`, embedded at build time; `brdf.wgsl` is
//! prepended to every program that shades, because WGSL has no include.

pub mod brdf_eval;
pub mod gpu;

pub use gpu::{Gpu, GpuError};

/// The WGSL of the BRDF and its film LUT lookup.
pub const BRDF_WGSL: &str = include_str!("../../shaders/brdf.wgsl");
/// Compute entry point evaluating the BRDF on a buffer of samples.
pub const BRDF_EVAL_WGSL: &str = include_str!("../../shaders/brdf_eval.wgsl");

/// Every shader program as the GPU receives it: (name, WGSL source, shader files it uses).
pub fn shader_programs() -> Vec<(&'static str, String, Vec<&'static str>)> {
    vec![("brdf_eval", format!("{BRDF_WGSL}\n{BRDF_EVAL_WGSL}"), vec!["brdf.wgsl", "brdf_eval.wgsl"])]
}
