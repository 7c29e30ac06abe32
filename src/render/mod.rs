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
pub mod sheet;
#[cfg(feature = "window")]
pub mod window;

pub use gpu::{Gpu, GpuError};
pub use renderer::Renderer;

pub const COMMON_WGSL: &str = include_str!("../../shaders/common.wgsl");
/// Film colour by method (LUT lookup and the analytic methods).
pub const FILM_WGSL: &str = include_str!("../../shaders/film.wgsl");
/// The WGSL of the BRDF.
pub const BRDF_WGSL: &str = include_str!("../../shaders/brdf.wgsl");
/// Compute entry point evaluating the BRDF on a buffer of samples.
pub const BRDF_EVAL_WGSL: &str = include_str!("../../shaders/brdf_eval.wgsl");
pub const SCENE_WGSL: &str = include_str!("../../shaders/scene.wgsl");
pub const SKIN_WGSL: &str = include_str!("../../shaders/skin.wgsl");
pub const PLAIN_WGSL: &str = include_str!("../../shaders/plain.wgsl");
pub const TONEMAP_WGSL: &str = include_str!("../../shaders/tonemap.wgsl");

/// Every shader program as the GPU receives it: (name, WGSL source, shader files it uses).
pub fn shader_programs() -> Vec<(&'static str, String, Vec<&'static str>)> {
    let program = |parts: &[(&'static str, &str)]| {
        let source = parts.iter().map(|(_, s)| *s).collect::<Vec<_>>().join("\n");
        (source, parts.iter().map(|(name, _)| *name).collect())
    };
    let common = ("common.wgsl", COMMON_WGSL);
    let film = ("film.wgsl", FILM_WGSL);
    let brdf = ("brdf.wgsl", BRDF_WGSL);
    let scene = ("scene.wgsl", SCENE_WGSL);
    let mut all = Vec::new();
    for (name, parts) in [
        ("brdf_eval", vec![common, film, brdf, ("brdf_eval.wgsl", BRDF_EVAL_WGSL)]),
        ("skin", vec![common, film, brdf, scene, ("skin.wgsl", SKIN_WGSL)]),
        ("plain", vec![common, scene, ("plain.wgsl", PLAIN_WGSL)]),
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
