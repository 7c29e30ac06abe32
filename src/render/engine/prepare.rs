//! From a preset to a drawable material: the five maps generated at preview resolution
//! (through a node cache for live reload), the film LUT baked for the layer optics, and the
//! spectral bands a film method needs. The window, the figures, the sheet and the benchmark
//! all start here.

use super::film::GpuFilmMethod;
use super::material::{self, MaterialMaps};
use super::renderer::{Material, RENDERER_OVERHEAD_BYTES, Renderer};
use super::scene::LayerOptics;
use crate::Error;
use crate::graph::{Graph, NodeCache, estimate_cached_peak_bytes, estimate_peak_bytes, evaluate};
use crate::maps::{BuildOptions, Layout, MapKind, body_plan, build_graph};
use crate::memory::{FIXED_OVERHEAD_BYTES, MemoryCheck};
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
    DrawMemory::new(&graph, (width, height), 0).check(PREVIEW_MAPS)?;
    let evaluation = evaluate(&graph, &MapKind::ALL, width, height, &|_, _| {});
    packed(&evaluation.maps, loaded, layout)
}

/// What a command that draws maps holds, phase by phase, for its memory check before anything
/// is allocated (`estimate_bytes`). The check counted the maps' evaluation (as `generate`'s)
/// and the frame only: on lavapipe, whose textures are host memory, a body sheet with `--tile
/// 1024 --map-size 1024` peaked at 1632 MiB resident where it estimated 580 MiB.
#[derive(Debug, Clone, Copy)]
pub struct DrawMemory {
    /// Width and height of the maps.
    pub maps: (usize, usize),
    /// The maps' evaluation at its worst (`graph::estimate_peak_bytes`; with a live-reload
    /// cache, the cache's previous entries and the maps handed over besides).
    pub evaluation_bytes: u64,
    /// Held beside every phase: a contact sheet's canvas, a live-reload cache's entries.
    pub held_bytes: u64,
    /// The frame (`renderer::frame_bytes`) and what is made from it.
    pub frame_bytes: u64,
    /// Materials uploaded from the maps and kept at once (the render benchmark's variants).
    pub materials: u64,
    /// One of several sets of maps drawn in turn (a sheet's species, the figures): what the
    /// previous one freed is not all reusable at once (the allocator's other arenas; textures
    /// wgpu frees at a later poll), counted as one more material's packed chains, textures
    /// and staging. A second `natrix-natrix` at 2048² raised a sheet's peak by 108 MiB; in a
    /// busy test run, two at 1024² peaked at 443 MiB where they take 353 alone. Between
    /// species the sheet hands freed memory back (`memory::release_freed`): 332 MiB then.
    pub drawn_in_turn: bool,
}

impl DrawMemory {
    /// One material from `graph`'s maps at `maps` (width, height), drawn into a frame of
    /// `frame_bytes`.
    pub fn new(graph: &Graph, maps: (usize, usize), frame_bytes: u64) -> DrawMemory {
        let evaluation_bytes = estimate_peak_bytes(graph, &MapKind::ALL, maps.0, maps.1);
        DrawMemory { maps, evaluation_bytes, held_bytes: 0, frame_bytes, materials: 1, drawn_in_turn: false }
    }

    /// Estimated peak bytes. The phases follow one another, so the peak is the largest of
    /// them, plus what is held throughout and the fixed overheads:
    /// - evaluation: the graph's buffers at their worst;
    /// - packing: the generator's f32 maps beside their packed mip chains (`packed_bytes`);
    /// - upload: the chains beside every material's textures (`texture_bytes`), wgpu's staging
    ///   copies of them (host memory until the queue is done) and one level in half floats;
    /// - drawing: the textures and their staging beside the frame, and as much again as the
    ///   packed chains: freed memory that the allocator keeps (a 4096² frame with 1024² maps
    ///   peaked 94 MiB above the same frame with 64² maps, where textures and staging are
    ///   48 MiB).
    pub fn estimate_bytes(&self) -> u64 {
        let (width, height) = self.maps;
        let pixels = (width * height) as u64;
        let maps = maps_bytes(width, height);
        let packed = material::packed_bytes(width, height);
        let textures = self.materials.saturating_mul(2 * material::texture_bytes(width, height));
        let half_floats = pixels * std::mem::size_of::<[u16; 4]>() as u64;
        let phases = [
            self.evaluation_bytes,
            maps + packed,
            packed + textures + half_floats,
            (packed + textures).saturating_add(self.frame_bytes),
        ];
        let peak = phases.into_iter().max().unwrap_or(0);
        let one_material = packed + 2 * material::texture_bytes(width, height);
        let kept_from_before = if self.drawn_in_turn { one_material } else { 0 };
        peak.saturating_add(self.held_bytes + kept_from_before) + RENDERER_OVERHEAD_BYTES + FIXED_OVERHEAD_BYTES
    }

    /// `Error::Memory` when the estimate exceeds the available memory; `what` names the work.
    pub fn check(&self, what: &str) -> Result<(), Error> {
        let (width, height) = self.maps;
        MemoryCheck::against_available(self.estimate_bytes()).refuse_if_over(&format!("{what} ({width}×{height} maps)"))
    }
}

/// Bytes of the generator's five maps at `width`×`height` (f32 samples).
fn maps_bytes(width: usize, height: usize) -> u64 {
    let channels: u64 = MapKind::ALL.iter().map(|m| m.format().channels as u64).sum();
    channels * std::mem::size_of::<f32>() as u64 * (width * height) as u64
}

/// What the memory check calls the preview's maps.
const PREVIEW_MAPS: &str = "the preview's set of maps";

/// `material_maps_in`'s memory check alone, for a command to run before it makes its
/// renderer (so that a machine without a GPU hears about the memory first).
/// `frame_bytes` are the frame's own (`renderer::frame_bytes`), which an 8192² frame made
/// 4.9 GB of when only the maps were counted; `drawn_in_turn` as in `DrawMemory` (figures).
pub fn check_preview_memory(
    loaded: &LoadedPreset,
    map_size: usize,
    layout: Layout,
    frame_bytes: u64,
    drawn_in_turn: bool,
) -> Result<(), Error> {
    let graph = build_graph(&loaded.preset, BuildOptions { layout, ..BuildOptions::default() });
    let memory =
        DrawMemory { drawn_in_turn, ..DrawMemory::new(&graph, map_dimensions(loaded, map_size, layout), frame_bytes) };
    memory.check("the preview's frame with its maps")
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
    // The cache keeps every node, beside its previous entries while it evaluates, and hands
    // copies of the maps over.
    let kept = estimate_cached_peak_bytes(&graph, &MapKind::ALL, width, height);
    let handed_over = maps_bytes(width, height);
    let memory = DrawMemory {
        evaluation_bytes: cache.bytes().saturating_add(handed_over),
        held_bytes: kept,
        ..DrawMemory::new(&graph, (width, height), 0)
    };
    memory.check(PREVIEW_MAPS)?;
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
