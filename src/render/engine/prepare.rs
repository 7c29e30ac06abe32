//! From a preset to a drawable material: the five maps generated at preview resolution
//! (through a node cache for live reload), the film LUT baked for the layer optics, and the
//! spectral bands a film method needs. The window, the figures, the sheet and the benchmark
//! all start here.

use super::film::GpuFilmMethod;
use super::material::{self, MaterialMaps};
use super::mesh::BodyShape;
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

/// The map sizes (pixels per side) the drawing commands (preview, figures, sheet, bench
/// render) generate their materials at: the maps are made before the first frame, and a
/// 4096² set (1.6 s and under 1 GiB for the built-in species, BENCHMARKS "Speed") still
/// opens a preview in seconds.
pub const MAP_SIZE_RANGE: std::ops::RangeInclusive<u32> = 64..=4096;

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
    // Its callers hold a renderer already, and the commands checked the whole drawing before
    // they made it (`check_preview_memory`): what the maps add is checked here.
    DrawMemory::new(&graph, (width, height), 0).check_added(DRAWN_MAPS)?;
    let evaluation = evaluate(&graph, &MapKind::ALL, width, height, &|_, _| {});
    packed(&evaluation.maps, loaded, layout)
}

/// What a command that draws maps holds, phase by phase, for its memory check before anything
/// is allocated (`estimate_bytes`). The check counted the maps' evaluation (as `generate`'s)
/// and the frame only: on lavapipe, whose textures are host memory, a body sheet with `--tile
/// 1024 --map-size 1024` peaked at 1635 MiB resident where it estimated 580 MiB.
#[derive(Debug, Clone, Copy)]
pub struct DrawMemory {
    /// Width and height of the maps.
    pub maps: (usize, usize),
    /// The maps' evaluation at its worst: the schedule's buffers (`graph::estimate_peak_bytes`)
    /// and the maps handed over, which `evaluate` keeps to its end (a live-reload cache: every
    /// node it keeps).
    pub evaluation_bytes: u64,
    /// Held beside every phase: a contact sheet's canvas, a live-reload cache's entries.
    pub held_bytes: u64,
    /// The frame and what is made from it (`renderer::frame_bytes`; a window's,
    /// `renderer::window_frame_bytes`).
    pub frame_bytes: u64,
    /// Materials uploaded from the maps and kept at once (the render benchmark's variants).
    pub materials: u64,
    /// The largest maps (width, height) drawn before these, when several are drawn in turn (a
    /// sheet's species, the figures): what the previous ones freed is not all reusable at once
    /// (the allocator's other arenas; textures wgpu frees at a later poll), counted as one
    /// more material of that size: packed chains, textures and staging. A second
    /// `natrix-natrix` at 2048² raised a sheet's peak by 108 MiB; in a busy test run, two at
    /// 1024² peaked at 443 MiB where they take 353 alone. Between species the sheet hands
    /// freed memory back (`memory::release_freed`): 332 MiB then.
    pub drawn_after: Option<(usize, usize)>,
}

/// What a drawing process holds at any size: the renderer's and the process's own overheads.
const DRAWING_OVERHEAD_BYTES: u64 = RENDERER_OVERHEAD_BYTES + FIXED_OVERHEAD_BYTES;

impl DrawMemory {
    /// One material from `graph`'s maps at `maps` (width, height), drawn into a frame of
    /// `frame_bytes`.
    pub fn new(graph: &Graph, maps: (usize, usize), frame_bytes: u64) -> DrawMemory {
        let evaluation_bytes = estimate_peak_bytes(graph, &MapKind::ALL, maps.0, maps.1) + maps_bytes(maps.0, maps.1);
        DrawMemory { maps, evaluation_bytes, held_bytes: 0, frame_bytes, materials: 1, drawn_after: None }
    }

    /// Estimated peak bytes of a process that makes its renderer for this drawing:
    /// `estimate_added_bytes` and the renderer's and the process's own overheads.
    pub fn estimate_bytes(&self) -> u64 {
        self.estimate_added_bytes() + DRAWING_OVERHEAD_BYTES
    }

    /// Estimated bytes the drawing adds to what the process holds. The phases follow one
    /// another, so the peak is the largest of them, plus what is held throughout:
    /// - evaluation: the graph's buffers at their worst;
    /// - packing: the generator's f32 maps beside their packed mip chains (`packed_bytes`);
    /// - upload: the chains beside every material's textures (`texture_bytes`), wgpu's staging
    ///   copies of them (host memory until the queue is done) and one level in half floats;
    /// - drawing: the textures and their staging beside the frame, and as much again as the
    ///   packed chains: freed memory that the allocator keeps (a 4096² frame with 1024² maps
    ///   peaked 94 MiB above the same frame with 64² maps, where textures and staging are
    ///   48 MiB).
    pub fn estimate_added_bytes(&self) -> u64 {
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
        let kept_from_before =
            self.drawn_after.map_or(0, |(w, h)| material::packed_bytes(w, h) + 2 * material::texture_bytes(w, h));
        peak.saturating_add(self.held_bytes + kept_from_before)
    }

    /// `Error::Memory` when the estimate exceeds the available memory, before a renderer is
    /// made; `what` names the work.
    pub fn check(&self, what: &str) -> Result<(), Error> {
        // The renderer's part named: no smaller size brings the estimate under it (a limit of
        // 300 MiB refused 16×16 frames of 64² maps, "use a smaller size").
        let fixed_mib = DRAWING_OVERHEAD_BYTES.div_ceil(crate::memory::MIB);
        self.refuse_over(self.estimate_bytes(), what, &format!(", {fixed_mib} MiB of it the renderer's at any size,"))
    }

    /// The same for a process that holds its renderer (and whatever it drew) already: the
    /// available memory leaves those out, so only what this drawing adds is compared with it.
    /// Counted again, a 2048² window's reloads (1312 MiB estimated, 891 resident) would be
    /// refused unless about 2.2 GiB were free.
    pub fn check_added(&self, what: &str) -> Result<(), Error> {
        self.refuse_over(self.estimate_added_bytes(), what, "")
    }

    fn refuse_over(&self, bytes: u64, what: &str, fixed: &str) -> Result<(), Error> {
        let (width, height) = self.maps;
        MemoryCheck::against_available(bytes).refuse_if_over(&format!("{what} ({width}×{height} maps){fixed}"))
    }
}

/// Bytes of the generator's five maps at `width`×`height` (f32 samples).
fn maps_bytes(width: usize, height: usize) -> u64 {
    let channels: u64 = MapKind::ALL.iter().map(|m| m.format().channels as u64).sum();
    channels * std::mem::size_of::<f32>() as u64 * (width * height) as u64
}

/// What the memory check calls a window's maps.
const PREVIEW_MAPS: &str = "the preview's set of maps";

/// What the memory check calls the maps of a drawing after its renderer is made (a
/// preview's, a figure's, a sheet's species': `material_maps_in`). `figures` refused under
/// `ulimit -v` with "the preview's set of maps" (a sweep).
const DRAWN_MAPS: &str = "the set of maps to draw";

/// `material_maps_in`'s memory check alone, for a command to run before it makes its
/// renderer (so that a machine without a GPU hears about the memory first).
/// `frame_bytes` are the frame's own (`renderer::frame_bytes`), which an 8192² frame made
/// 4.9 GB of when only the maps were counted; `drawn_in_turn`: one of several drawn in turn,
/// the same size (`DrawMemory::drawn_after`; the figures).
pub fn check_preview_memory(
    loaded: &LoadedPreset,
    map_size: usize,
    layout: Layout,
    frame_bytes: u64,
    drawn_in_turn: bool,
) -> Result<(), Error> {
    let graph = build_graph(&loaded.preset, BuildOptions { layout, ..BuildOptions::default() });
    let size = map_dimensions(loaded, map_size, layout);
    let memory =
        DrawMemory { drawn_after: drawn_in_turn.then_some(size), ..DrawMemory::new(&graph, size, frame_bytes) };
    memory.check(if drawn_in_turn {
        "drawing the figures' frames with their maps"
    } else {
        "the preview's frame with its maps"
    })
}

/// `material_maps_cached`'s memory check of a window's first maps, alone: the window runs it
/// before it asks for a display, which it asks for before it builds the maps.
pub fn check_window_memory(
    loaded: &LoadedPreset,
    map_size: usize,
    layout: Layout,
    frame_bytes: u64,
) -> Result<(), Error> {
    let graph = build_graph(&loaded.preset, BuildOptions { layout, ..BuildOptions::default() });
    first_maps_memory(&graph, map_dimensions(loaded, map_size, layout), frame_bytes).check(PREVIEW_MAPS)
}

/// What a window's first maps take, with nothing made before them but its frame: the whole
/// process. The cache keeps every node, and hands copies of the maps over.
fn first_maps_memory(graph: &crate::graph::Graph, (width, height): (usize, usize), frame_bytes: u64) -> DrawMemory {
    DrawMemory {
        evaluation_bytes: maps_bytes(width, height),
        held_bytes: estimate_cached_peak_bytes(graph, &MapKind::ALL, width, height),
        ..DrawMemory::new(graph, (width, height), frame_bytes)
    }
}

/// What `snakes` snakes add to a frame's memory over one (`renderer::more_snakes_bytes`),
/// drawn with the body mesh of `layout` (an atlas' has more rings).
pub fn more_snakes_bytes(loaded: &LoadedPreset, layout: Layout, snakes: u32) -> u64 {
    super::renderer::more_snakes_bytes(BodyShape::for_layout(layout, &loaded.preset).triangles(), snakes)
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
/// `frame_bytes`: the window's targets and swap chain (`renderer::window_frame_bytes`), for
/// its first maps (made before its renderer).
pub fn material_maps_cached(
    loaded: &LoadedPreset,
    map_size: usize,
    layout: Layout,
    cache: &mut NodeCache,
    frame_bytes: u64,
) -> Result<(MaterialMaps, crate::graph::CacheStats), Error> {
    let graph = build_graph(&loaded.preset, BuildOptions { layout, ..BuildOptions::default() });
    let (width, height) = map_dimensions(loaded, map_size, layout);
    if cache.bytes() == 0 {
        // The window's first maps, before its renderer (`check_window_memory`).
        first_maps_memory(&graph, (width, height), frame_bytes).check(PREVIEW_MAPS)?;
    } else {
        let kept = estimate_cached_peak_bytes(&graph, &MapKind::ALL, width, height);
        let handed_over = maps_bytes(width, height);
        // A reload, in a window that holds its renderer, targets, cache and textures: what it
        // adds is the nodes that run (at most every one kept), the maps handed over, their
        // chains, and the new textures beside the old.
        let memory = DrawMemory { evaluation_bytes: kept + handed_over, ..DrawMemory::new(&graph, (width, height), 0) };
        memory.check_added(PREVIEW_MAPS)?;
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// 64² maps: 5461 texels in their mip chains (4096 + 1024 + … + 1), packed as 40 bytes
    /// (two RGBA f32 and one RG f32) and uploaded as 20 (two RGBA f16 and one RG f16).
    const CHAIN: u64 = 5461;

    fn drawing() -> DrawMemory {
        DrawMemory {
            maps: (64, 64),
            evaluation_bytes: 0,
            held_bytes: 0,
            frame_bytes: 0,
            materials: 1,
            drawn_after: None,
        }
    }

    /// Each phase wins when it is the largest; what is held throughout, a material drawn
    /// before and the overheads add to it.
    #[test]
    fn the_estimate_is_the_largest_phase_and_what_is_held() {
        let (packed, textures) = (CHAIN * 40, CHAIN * 20);
        let frame = 1 << 30;
        let drawing_phase = packed + 2 * textures + frame;
        assert_eq!(DrawMemory { frame_bytes: frame, ..drawing() }.estimate_added_bytes(), drawing_phase);
        let evaluation = 3 << 30;
        let heavy = DrawMemory { evaluation_bytes: evaluation, frame_bytes: frame, held_bytes: 7, ..drawing() };
        assert_eq!(heavy.estimate_added_bytes(), evaluation + 7);
        // Ten materials: ten textures with their staging in the upload and drawing phases.
        let ten = DrawMemory { materials: 10, ..drawing() };
        assert_eq!(ten.estimate_added_bytes(), packed + 20 * textures + 64 * 64 * 8);
        // A material of 128² maps drawn before: its chains, textures and staging.
        let after = DrawMemory { frame_bytes: frame, drawn_after: Some((128, 128)), ..drawing() };
        let before_chain = 21845;
        assert_eq!(after.estimate_added_bytes(), drawing_phase + before_chain * (40 + 2 * 20));
        assert_eq!(after.estimate_bytes() - after.estimate_added_bytes(), (256 + 64) << 20);
        // Without a frame, the upload phase (chains, textures, staging, one level in half
        // floats) is the largest.
        assert_eq!(drawing().estimate_added_bytes(), packed + 2 * textures + 64 * 64 * 8);
    }
}
