//! `snakeskin bench render`: GPU time of the skin shader against a plain metal-roughness PBR
//! shader on the same mesh, maps and view, in one run, plus the specialised variants (no
//! film, no absorption, the film read at each pixel's mean thickness), the other film
//! methods, twenty snakes, and the CPU reference check.
//!
//! Timing: GPU timestamps around the scene pass where the adapter offers them (lavapipe does),
//! otherwise wall time around submit + wait. Variants are interleaved frame by frame and each
//! reports the median over many frames after warm-up: shared machines drift by tens of percent
//! between minutes, and interleaving keeps that drift out of the ratios. The tone-mapping pass
//! is the same for every variant and is not in the scene-pass time.

use std::time::Instant;

use serde::Serialize;

use super::frame::reference_check;
use crate::Error;
use crate::optics::brdf::Model;
use crate::optics::lut::Lut;
use crate::preset::LoadedPreset;
use crate::render::engine::film::GpuFilmMethod;
use crate::render::engine::gpu::GpuError;
use crate::render::engine::prepare::{bands_for, material_maps};
use crate::render::engine::renderer::{FilmFootprint, FrameOutput, FrameSettings, Material, OUTPUT_FORMAT, Renderer};
use crate::render::engine::scene::LayerOptics;

#[derive(Debug, Clone, Serialize)]
pub struct VariantTiming {
    pub name: String,
    pub snakes: u32,
    pub median_ms: f64,
    pub p10_ms: f64,
    pub p90_ms: f64,
}

#[derive(Debug, Clone, Serialize)]
pub struct RenderBench {
    pub adapter: String,
    pub timing: &'static str,
    pub width: u32,
    pub height: u32,
    pub frames: usize,
    pub skin_ms: f64,
    pub plain_ms: f64,
    pub ratio: f64,
    /// skin-thesis / plain-pbr, one snake (the thesis model, LUT film).
    pub thesis_ratio: f64,
    /// skin-mean-thickness / plain-pbr, one snake (the film read once a pixel, at its mean
    /// thickness: `FilmFootprint::Mean`, `preview --film-footprint mean`).
    pub mean_thickness_ratio: f64,
    pub skin_20_ms: f64,
    pub plain_20_ms: f64,
    pub variants: Vec<VariantTiming>,
    pub reference_width: u32,
    pub reference_height: u32,
    pub reference_mean_de: f64,
    pub reference_p99_de: f64,
    pub reference_max_de: f64,
    pub reference_pixels: usize,
}

pub struct BenchOptions {
    pub width: u32,
    pub height: u32,
    pub frames: usize,
    pub map_size: usize,
    pub reference_size: (u32, u32),
    /// Time only the variants that read the LUT film (`DIRECT_FILM_VARIANTS` skipped).
    pub lut_only: bool,
}

fn percentile(sorted: &[f64], p: f64) -> f64 {
    sorted[((sorted.len() - 1) as f64 * p).round() as usize]
}

/// Times one frame's scene pass at a time, for any variant, with shared targets.
struct FrameTimer<'a> {
    renderer: &'a Renderer,
    targets: crate::render::engine::renderer::Targets,
    view: wgpu::TextureView,
    query_set: Option<wgpu::QuerySet>,
    resolve: wgpu::Buffer,
    readback: wgpu::Buffer,
    period_ns: f64,
}

impl<'a> FrameTimer<'a> {
    fn new(renderer: &'a Renderer, options: &BenchOptions, samples: u32) -> FrameTimer<'a> {
        let device = &renderer.gpu.device;
        let timestamps = device.features().contains(wgpu::Features::TIMESTAMP_QUERY);
        let output = renderer.output_texture(options.width, options.height);
        let buffer = |label, usage| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: 16,
                usage,
                mapped_at_creation: false,
            })
        };
        FrameTimer {
            renderer,
            targets: renderer.targets(options.width, options.height, samples),
            view: output.create_view(&wgpu::TextureViewDescriptor::default()),
            query_set: timestamps.then(|| {
                device.create_query_set(&wgpu::QuerySetDescriptor {
                    label: Some("frame"),
                    ty: wgpu::QueryType::Timestamp,
                    count: 2,
                })
            }),
            resolve: buffer("timestamps", wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC),
            readback: buffer("timestamps readback", wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST),
            period_ns: renderer.gpu.queue.get_timestamp_period() as f64,
        }
    }

    fn kind(&self) -> &'static str {
        if self.query_set.is_some() { "gpu-timestamp" } else { "wall" }
    }

    /// Renders one frame and returns its scene-pass time in ms.
    fn frame(&self, settings: &FrameSettings, material: &Material) -> Result<f64, Error> {
        let device = &self.renderer.gpu.device;
        let mut encoder = device.create_command_encoder(&Default::default());
        self.renderer.encode_frame(
            &mut encoder,
            &self.targets,
            settings,
            material,
            FrameOutput { view: &self.view, format: OUTPUT_FORMAT },
            self.query_set.as_ref().map(|q| (q, 0)),
        );
        if let Some(q) = &self.query_set {
            encoder.resolve_query_set(q, 0..2, &self.resolve, 0);
            encoder.copy_buffer_to_buffer(&self.resolve, 0, &self.readback, 0, 16);
        }
        let start = Instant::now();
        self.renderer.gpu.queue.submit([encoder.finish()]);
        if self.query_set.is_some() {
            let data = crate::render::engine::gpu::map_read(device, &self.readback)?;
            let ticks: &[u64] = bytemuck::cast_slice(&data);
            return Ok(ticks[1].saturating_sub(ticks[0]) as f64 * self.period_ns * 1e-6);
        }
        device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| Error::Gpu(crate::render::GpuError::Readback(e.to_string())))?;
        Ok(start.elapsed().as_secs_f64() * 1e3)
    }
}

/// Materials the benchmark keeps at once: its nine variants with one snake, and two of them
/// with twenty (`bench_render`'s runs).
const TIMED_RUNS: usize = 11;

/// The variants that evaluate the layered rule with their own film at every pixel instead
/// of reading the coupling texture (README, "The preview renderer"): on an NVIDIA H200 at
/// 1920×1080 they took 1.10 s of each 1.12 s round (258, 609 and 229 ms against 3 ms for the
/// LUT's skin), and seconds a frame on lavapipe. `--lut-only` leaves them out.
const DIRECT_FILM_VARIANTS: [&str; 3] = ["skin-rgb3", "skin-spectral-8", "skin-gaussian-fit"];

/// How every variant but `skin-mean-thickness` reads a pixel's spread of film thicknesses.
const SPREAD: FilmFootprint = FilmFootprint::Spread;

/// The runs `bench_render` times under `options`.
fn timed_runs(options: &BenchOptions) -> usize {
    TIMED_RUNS - if options.lut_only { DIRECT_FILM_VARIANTS.len() } else { 0 }
}

/// What the benchmark's renderer holds beyond one preview's (`RENDERER_OVERHEAD_BYTES`): the
/// pipelines of its variants (eight when this was measured), twenty snakes' draws and the timing queries. Measured on
/// lavapipe (Mesa 22.3.6, two cores), peak resident with 64² maps and a 16² reference:
/// 505 MiB at a 64² frame, 628 MiB at 640×360, 684 MiB at 1280×720 (a preview with such maps
/// and frame: under 260 MiB), and up to 90 MiB more on a busy machine as for a preview.
const VARIANTS_OVERHEAD_BYTES: u64 = 448 << 20;

/// Refuses a benchmark whose maps, materials and frames (the timed frame, the reference
/// check's frame and G-buffer) would need more memory than is available, before a renderer
/// is made. It checked one material's maps after the renderer was made: 126 MiB estimated
/// for a 1237 MiB peak (`--frames 3 --reference-size 64x64`, lavapipe).
pub fn check_memory(loaded: &LoadedPreset, options: &BenchOptions) -> Result<(), Error> {
    use crate::render::engine::prepare::DrawMemory;
    use crate::render::engine::renderer::{frame_bytes, gbuffer_bytes};
    let (w, h) = options.reference_size;
    let frames = frame_bytes(options.width, options.height) + frame_bytes(w, h) + gbuffer_bytes(w, h);
    let graph = crate::maps::build_graph(&loaded.preset, crate::maps::BuildOptions::default());
    let size = (options.map_size, options.map_size);
    // The packed maps, held from the first upload to the last, are in the upload and drawing
    // phases already.
    let memory = DrawMemory {
        held_bytes: VARIANTS_OVERHEAD_BYTES,
        materials: timed_runs(options) as u64,
        ..DrawMemory::new(&graph, size, frames)
    };
    memory.check("the render benchmark (its materials and frames)")
}

/// Runs the whole benchmark for one preset.
pub fn bench_render(
    renderer: &Renderer,
    loaded: &LoadedPreset,
    options: &BenchOptions,
    progress: &dyn Fn(&str),
) -> Result<RenderBench, Error> {
    // The reference check at the end reads its G-buffer back in one buffer: refused now,
    // not after every timing run.
    // The size named: the refusal spoke of "the preview" (a hostile-input review).
    let (w, h) = options.reference_size;
    renderer.check_readback(w, h, 16).map_err(|e| match e {
        GpuError::Limits(why) => GpuError::Limits(format!("{why} (--reference-size {w}x{h})")),
        e => e,
    })?;
    let maps = material_maps(loaded, options.map_size)?;
    let optics = LayerOptics::from_preset(&loaded.preset);
    let lut = Lut::bake_default(optics.stack);
    let base = FrameSettings { ground: false, ..FrameSettings::default() };
    let no_film = LayerOptics { thickness_range_nm: (0.0, 0.0), ..optics };
    // The other side of the absorption switch from the preset's (built-in presets have
    // none: τ = 0.3 then shows what the attenuation costs).
    let switched = if optics.has_absorption() { [0.0; 3] } else { [0.3; 3] };
    let absorption_switched = LayerOptics { optical_depth: switched, ..optics };
    let switched_name = if optics.has_absorption() { "skin-no-absorption" } else { "skin-absorption" };
    // Every skin variant shades with the default model but `skin-thesis`, and reads the film
    // over each pixel's spread of thicknesses but `skin-mean-thickness` (`FilmFootprint`:
    // what the spread costs, in the same rounds).
    let (default, thesis) = (Model::default(), Model::Thesis);
    let variants: Vec<(String, LayerOptics, GpuFilmMethod, bool, Model, FilmFootprint)> = vec![
        ("plain-pbr".into(), optics, GpuFilmMethod::Lut, true, default, SPREAD),
        ("skin-lut".into(), optics, GpuFilmMethod::Lut, false, default, SPREAD),
        ("skin-mean-thickness".into(), optics, GpuFilmMethod::Lut, false, default, FilmFootprint::Mean),
        ("skin-thesis".into(), optics, GpuFilmMethod::Lut, false, thesis, SPREAD),
        ("skin-no-film".into(), no_film, GpuFilmMethod::Lut, false, default, SPREAD),
        (switched_name.into(), absorption_switched, GpuFilmMethod::Lut, false, default, SPREAD),
        ("skin-rgb3".into(), optics, GpuFilmMethod::Rgb3, false, default, SPREAD),
        ("skin-spectral-8".into(), optics, GpuFilmMethod::SpectralN(8), false, default, SPREAD),
        ("skin-gaussian-fit".into(), optics, GpuFilmMethod::GaussianFit, false, default, SPREAD),
    ];
    // All variants are timed round-robin, one frame each per round, so that a shared
    // machine's drift (other jobs, clock changes) affects every variant alike; the first
    // three rounds are warm-up (pipeline compilation, caches).
    let mut runs = Vec::new();
    for snakes in [1u32, 20] {
        for (name, variant_optics, method, plain, model, footprint) in &variants {
            if snakes == 20 && !matches!(name.as_str(), "plain-pbr" | "skin-lut") {
                continue;
            }
            if options.lut_only && DIRECT_FILM_VARIANTS.contains(&name.as_str()) {
                continue;
            }
            let material = renderer.material(&maps, *variant_optics, &lut, bands_for(*method))?;
            let camera = crate::render::engine::scene::Camera::framing(snakes);
            let (method, plain, model, footprint) = (*method, *plain, *model, *footprint);
            let settings = FrameSettings { method, plain, model, snakes, camera, footprint, ..base };
            runs.push((name.clone(), snakes, material, settings, Vec::with_capacity(options.frames)));
        }
    }
    debug_assert_eq!(runs.len(), timed_runs(options), "check_memory counts the runs' materials");
    let timer = FrameTimer::new(renderer, options, base.samples);
    for round in 0..options.frames + 3 {
        progress(&format!("round {} of {}", round + 1, options.frames + 3));
        for (_, _, material, settings, samples) in runs.iter_mut() {
            let ms = timer.frame(settings, material)?;
            if round >= 3 {
                samples.push(ms);
            }
        }
    }
    let timing_kind = timer.kind();
    let timings: Vec<VariantTiming> = runs
        .into_iter()
        .map(|(name, snakes, _, _, mut samples)| {
            samples.sort_by(f64::total_cmp);
            VariantTiming {
                name,
                snakes,
                median_ms: percentile(&samples, 0.5),
                p10_ms: percentile(&samples, 0.1),
                p90_ms: percentile(&samples, 0.9),
            }
        })
        .collect();
    let find = |name: &str, snakes: u32| {
        timings.iter().find(|t| t.name == name && t.snakes == snakes).map(|t| t.median_ms).unwrap_or(f64::NAN)
    };
    progress("reference comparison");
    let material = renderer.material(&maps, optics, &lut, 1)?;
    let (w, h) = options.reference_size;
    let (report, _) = reference_check(renderer, &material, &base, w, h, &|_, _| {})?;
    Ok(RenderBench {
        adapter: renderer.gpu.describe(),
        timing: timing_kind,
        width: options.width,
        height: options.height,
        frames: options.frames,
        skin_ms: find("skin-lut", 1),
        plain_ms: find("plain-pbr", 1),
        ratio: find("skin-lut", 1) / find("plain-pbr", 1),
        thesis_ratio: find("skin-thesis", 1) / find("plain-pbr", 1),
        mean_thickness_ratio: find("skin-mean-thickness", 1) / find("plain-pbr", 1),
        skin_20_ms: find("skin-lut", 20),
        plain_20_ms: find("plain-pbr", 20),
        variants: timings,
        reference_width: w,
        reference_height: h,
        reference_mean_de: report.mean_de,
        reference_p99_de: report.p99_de,
        reference_max_de: report.max_de,
        reference_pixels: report.pixels,
    })
}
