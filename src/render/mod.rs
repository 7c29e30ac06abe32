//! GPU side, split by role: `engine` (device, pipelines, targets, frames and their readback
//! into images and G-buffers, the WGSL programs and their generated constants), `reference`
//! (what is measured on what the engine reads back: the CPU reference a frame is compared
//! with, the BRDF twin evaluation, the frame benchmark), `window` (the
//! interactive preview: app, panel, live reload; behind the default-on `window` feature, so a
//! headless build skips winit and egui) and `figures` (documentation figures, the species
//! sheet, the pattern gallery).

pub mod engine;
pub mod figures;
pub mod reference;
#[cfg(feature = "window")]
pub mod window;

pub use engine::gpu::{Gpu, GpuError};
pub use engine::renderer::Renderer;
pub use engine::shaders::{program, shader_programs};
