//! GPU side: the preview renderer (snake mesh, multi-layer BRDF, layer stages, map viewer,
//! tone mapping), the CPU reference it is measured against, and the WGSL twin of the BRDF.
//!
//! Headless first (as wgpu's examples): `Renderer` draws into textures that tests and the
//! `preview --out` command read back; the window (`window.rs`) draws the same frame into a
//! surface texture, so the tests exercise the code the artist sees. Shaders are WGSL files in
//! `shaders/`, embedded at build time and concatenated into programs because WGSL has no
//! include: `common` (constants), `film` (film colour by method), `brdf` (the BRDF), `scene`
//! (vertex stage, maps, lights), then the entry points (`skin`, `plain`, `tonemap`).

pub mod bench;
pub mod brdf_eval;
pub mod film;
pub mod gallery;
pub mod gpu;
pub mod material;
pub mod mesh;
pub mod preview;
pub mod reference;
pub mod renderer;
pub mod scene;
pub mod shaders;
pub mod sheet;
#[cfg(feature = "window")]
pub mod window;

pub use gpu::{Gpu, GpuError};
pub use renderer::Renderer;

pub use shaders::{program, shader_programs};
