//! The engine: a headless-first wgpu renderer (as wgpu's examples) that draws the snake
//! with the skin BRDF into textures tests and `preview --out` read back; the window draws
//! the same frame into a surface texture. Pipelines are specialised with WGSL override
//! constants whose codes come from Rust (`shaders`), the film colour tables are bound per
//! material (`film`), and `prepare` turns a preset into a drawable material.

pub mod film;
pub mod gpu;
pub mod material;
pub mod mesh;
pub mod prepare;
pub mod renderer;
pub mod scene;
pub mod shaders;
