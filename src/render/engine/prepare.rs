//! From a preset to a drawable material: the five maps generated at preview resolution
//! (through a node cache for live reload), the film LUT baked for the layer optics, and the
//! spectral bands a film method needs. The window, the figures, the sheet and the benchmark
//! all start here.

use super::film::GpuFilmMethod;
use super::material::MaterialMaps;
use super::renderer::{Material, Renderer};
use super::scene::LayerOptics;
use crate::Error;
use crate::graph::{Graph, NodeCache, evaluate};
use crate::maps::{BuildOptions, Layout, MapKind, body_plan, build_graph};
use crate::memory::{MemoryCheck, estimate_generate_bytes};
use crate::optics::lut::Lut;
use crate::preset::LoadedPreset;

/// Preview image size limits (pixels per side): lavapipe handles 8K, a window rarely more.
pub const IMAGE_RANGE: std::ops::RangeInclusive<u32> = 16..=8192;

/// Generates the five maps of `preset` at `map_size`² for rendering.
pub fn material_maps(loaded: &LoadedPreset, map_size: usize) -> Result<MaterialMaps, Error> {
    material_maps_in(loaded, map_size, Layout::Tile)
}

/// The tallest texture the preview uploads: wgpu's default limit for 2-D textures.
pub const MAX_TEXTURE_SIDE: usize = 8192;

/// The maps in a layout: the tile at `map_size`², or a body atlas `map_size` wide — narrower
/// if its length would pass `MAX_TEXTURE_SIDE` rows.
pub fn material_maps_in(loaded: &LoadedPreset, map_size: usize, layout: Layout) -> Result<MaterialMaps, Error> {
    let graph = build_graph(&loaded.preset, BuildOptions { layout, ..BuildOptions::default() });
    let (width, height) = map_dimensions(loaded, map_size, layout);
    check_memory(&graph, (width, height), 0, PREVIEW_MAPS)?;
    let evaluation = evaluate(&graph, &MapKind::ALL, width, height, &|_, _| {});
    packed(&evaluation.maps, loaded, layout)
}

/// Refuses maps of `graph` at `size` (width, height), with `extra_bytes` that the caller
/// holds beside them (a contact sheet's canvas), when their estimated peak exceeds the
/// available memory, as `generate` refuses a set (`memory::estimate_generate_bytes`, an
/// upper bound here: the preview quantises nothing). `what` names the work in the message.
/// Before, `preview` and `sheet` allocated blindly: a body sheet with `--tile 1024` asked
/// for a 4.2 GB canvas and `SNAKESKIN_MEMORY_LIMIT_MIB` was not consulted.
pub fn check_memory(graph: &Graph, size: (usize, usize), extra_bytes: u64, what: &str) -> Result<(), Error> {
    let (width, height) = size;
    let estimate = estimate_generate_bytes(graph, &MapKind::ALL, width, height).saturating_add(extra_bytes);
    MemoryCheck::against_available(estimate).refuse_if_over(&format!("{what} ({width}×{height} maps)"))
}

/// What `check_memory` calls the preview's maps.
const PREVIEW_MAPS: &str = "the preview's set of maps";

/// `material_maps_in`'s memory check alone, for a command to run before it makes its
/// renderer (so that a machine without a GPU hears about the memory first).
/// `frame_bytes` are the frame's own (`renderer::frame_bytes`), which an 8192² frame made
/// 4.9 GB of when only the maps were counted.
pub fn check_preview_memory(
    loaded: &LoadedPreset,
    map_size: usize,
    layout: Layout,
    frame_bytes: u64,
) -> Result<(), Error> {
    let graph = build_graph(&loaded.preset, BuildOptions { layout, ..BuildOptions::default() });
    check_memory(&graph, map_dimensions(loaded, map_size, layout), frame_bytes, "the preview's frame with its maps")
}

/// Width and height of the preview's maps (`material_maps_in`): `map_size` wide, or the
/// widest that keeps a body atlas within `MAX_TEXTURE_SIDE` rows.
pub fn map_dimensions(loaded: &LoadedPreset, map_size: usize, layout: Layout) -> (usize, usize) {
    let mut width = map_size;
    if layout.height(&loaded.preset, width) > MAX_TEXTURE_SIDE {
        width = ((MAX_TEXTURE_SIDE as f64 / loaded.preset.body.length).floor() as usize).max(16);
        while layout.height(&loaded.preset, width) > MAX_TEXTURE_SIDE && width > 16 {
            width -= 1;
        }
    }
    (width, layout.height(&loaded.preset, width))
}

fn packed(
    maps: &std::collections::BTreeMap<MapKind, crate::ops::Image>,
    loaded: &LoadedPreset,
    layout: Layout,
) -> Result<MaterialMaps, Error> {
    let mut packed = MaterialMaps::from_maps(maps).map_err(|e| Error::Internal(e.to_string()))?;
    packed.atlas = (layout == Layout::Body).then(|| body_plan(&loaded.preset));
    Ok(packed)
}

/// The same through a node cache: after an edit only changed nodes run (live reload).
pub fn material_maps_cached(
    loaded: &LoadedPreset,
    map_size: usize,
    layout: Layout,
    cache: &mut NodeCache,
) -> Result<(MaterialMaps, crate::graph::CacheStats), Error> {
    let graph = build_graph(&loaded.preset, BuildOptions { layout, ..BuildOptions::default() });
    let (width, height) = map_dimensions(loaded, map_size, layout);
    check_memory(&graph, (width, height), 0, PREVIEW_MAPS)?;
    let (maps, stats) = cache.evaluate(&graph, &MapKind::ALL, width, height);
    Ok((packed(&maps, loaded, layout)?, stats))
}

/// A material ready to draw: maps, optics and film tables for `method`.
pub fn upload_material(
    renderer: &Renderer,
    loaded: &LoadedPreset,
    map_size: usize,
    method: GpuFilmMethod,
) -> Result<Material, Error> {
    upload_material_in(renderer, loaded, map_size, method, Layout::Tile)
}

/// `upload_material` in a layout (a body atlas is drawn on its own whole-snake body).
pub fn upload_material_in(
    renderer: &Renderer,
    loaded: &LoadedPreset,
    map_size: usize,
    method: GpuFilmMethod,
    layout: Layout,
) -> Result<Material, Error> {
    let maps = material_maps_in(loaded, map_size, layout)?;
    let optics = LayerOptics::from_preset(&loaded.preset);
    let lut = Lut::bake_default(optics.stack);
    Ok(renderer.material(&maps, optics, &lut, bands_for(method))?)
}

pub fn bands_for(method: GpuFilmMethod) -> usize {
    match method {
        GpuFilmMethod::SpectralN(n) => n,
        _ => 1,
    }
}
