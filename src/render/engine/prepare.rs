//! From a preset to a drawable material: the five maps generated at preview resolution
//! (through a node cache for live reload), the film LUT baked for the layer optics, and the
//! spectral bands a film method needs. The window, the figures, the sheet and the benchmark
//! all start here.

use super::film::GpuFilmMethod;
use super::material::MaterialMaps;
use super::renderer::{Material, Renderer};
use super::scene::LayerOptics;
use crate::Error;
use crate::graph::{NodeCache, evaluate};
use crate::maps::{BuildOptions, MapKind, build_graph};
use crate::optics::lut::Lut;
use crate::preset::LoadedPreset;

/// Preview image size limits (pixels per side): lavapipe handles 8K, a window rarely more.
pub const IMAGE_RANGE: std::ops::RangeInclusive<u32> = 16..=8192;

/// Generates the five maps of `preset` at `map_size`² for rendering.
pub fn material_maps(loaded: &LoadedPreset, map_size: usize) -> Result<MaterialMaps, Error> {
    let graph = build_graph(&loaded.preset, BuildOptions::default());
    let evaluation = evaluate(&graph, &MapKind::ALL, map_size, map_size, &|_, _| {});
    MaterialMaps::from_maps(&evaluation.maps).map_err(|e| Error::Preview(e.to_string()))
}

/// The same through a node cache: after an edit only changed nodes run (live reload).
pub fn material_maps_cached(
    loaded: &LoadedPreset,
    map_size: usize,
    cache: &mut NodeCache,
) -> Result<(MaterialMaps, crate::graph::CacheStats), Error> {
    let graph = build_graph(&loaded.preset, BuildOptions::default());
    let (maps, stats) = cache.evaluate(&graph, &MapKind::ALL, map_size, map_size);
    Ok((MaterialMaps::from_maps(&maps).map_err(|e| Error::Preview(e.to_string()))?, stats))
}

/// A material ready to draw: maps, optics and film tables for `method`.
pub fn upload_material(
    renderer: &Renderer,
    loaded: &LoadedPreset,
    map_size: usize,
    method: GpuFilmMethod,
) -> Result<Material, Error> {
    let maps = material_maps(loaded, map_size)?;
    let optics = LayerOptics::from_preset(&loaded.preset);
    let lut = Lut::bake_default(optics.stack);
    Ok(renderer.material(&maps, optics, &lut, bands_for(method)))
}

pub fn bands_for(method: GpuFilmMethod) -> usize {
    match method {
        GpuFilmMethod::SpectralN(n) => n,
        _ => 1,
    }
}
