//! Evaluates the WGSL BRDF on the GPU for a batch of inputs (one compute invocation per
//! sample) and reads the results back: the GPU half of the CPU/GPU twin test, and the way to
//! measure the shader's cost per million evaluations.

use bytemuck::{Pod, Zeroable};
use wgpu::util::DeviceExt;

use crate::optics::brdf::{Layers, Layers32, Model};
use crate::optics::film::Stack;
use crate::optics::lut::Lut;
use crate::render::engine::film::{self, FilmBinding, GpuFilmMethod};
use crate::render::engine::gpu::{StorageOutput, storage_entry};
use crate::render::engine::shaders::shader_programs;
use crate::render::{Gpu, GpuError};

/// Invocations per workgroup of `brdf_eval.wgsl`'s entry points (the shader's
/// `EVAL_WORKGROUP_SIZE`, from the generated prelude): 64, a multiple of every GPU's SIMD
/// width (32 on NVIDIA, 64 on AMD's GCN).
pub const WORKGROUP_SIZE: u32 = 64;

/// One BRDF query, laid out as the shader's `Sample` (seven vec4s).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct GpuSample {
    pub normal_roughness: [f32; 4],
    pub wi_thickness: [f32; 4],
    pub wo_n0: [f32; 4],
    pub tau_n2: [f32; 4],
    pub albedo: [f32; 4],
    pub k: [f32; 4],
    pub e: [f32; 4],
}

impl GpuSample {
    pub fn new(layers: &Layers32, normal: [f32; 3], wi: [f32; 3], wo: [f32; 3]) -> Self {
        let [a, b, c] = layers.optical_depth;
        let [r, g, bl] = layers.albedo;
        GpuSample {
            normal_roughness: [normal[0], normal[1], normal[2], layers.roughness],
            wi_thickness: [wi[0], wi[1], wi[2], layers.thickness_nm],
            wo_n0: [wo[0], wo[1], wo[2], layers.n0],
            tau_n2: [a, b, c, layers.n2],
            albedo: [r, g, bl, 0.0],
            k: [layers.k[0], layers.k[1], layers.k[2], 0.0],
            e: [layers.e[0], layers.e[1], layers.e[2], 0.0],
        }
    }
}

/// Evaluates the BRDF of `model` for every sample with film colours from `lut`; returns
/// linear RGB.
pub fn eval_on_gpu(gpu: &Gpu, model: Model, lut: &Lut, samples: &[GpuSample]) -> Result<Vec<[f32; 3]>, GpuError> {
    Ok(eval_timed(gpu, model, Stack::THESIS, lut, GpuFilmMethod::Lut, samples, 1)?.0)
}

/// The film colour by `method` for the material `stack` (whose LUT is `lut`) of each
/// (thickness in nm, cosine) pair, as the shader's `film_rgb` computes it: the GPU half of
/// the test of every film method against its Rust f32 twin (`optics::methods`).
pub fn film_on_gpu(
    gpu: &Gpu,
    stack: Stack,
    lut: &Lut,
    method: GpuFilmMethod,
    points: &[(f32, f32)],
) -> Result<Vec<[f32; 3]>, GpuError> {
    let samples: Vec<GpuSample> = points
        .iter()
        .map(|&(thickness_nm, cos)| {
            let mut sample = GpuSample::zeroed();
            sample.wi_thickness = [(1.0 - cos * cos).max(0.0).sqrt(), 0.0, cos, thickness_nm];
            sample
        })
        .collect();
    gpu.checked(&format!("evaluating the film at {} points", samples.len()), || {
        Ok(dispatch(gpu, ("film_samples", None), (stack, lut, method), &samples, 1)?.0)
    })
}

/// Evaluates the BRDF of `model` for every sample, dispatching the evaluation `repeats` times in one
/// submission (same inputs and outputs), with film colour by `method` for the material
/// `stack` (whose LUT is `lut`); also returns the wall time from submit to results on the
/// CPU. Two calls with different `repeats` isolate the cost of the evaluations from the
/// fixed costs of submission and readback.
pub fn eval_timed(
    gpu: &Gpu,
    model: Model,
    stack: Stack,
    lut: &Lut,
    method: GpuFilmMethod,
    samples: &[GpuSample],
    repeats: u32,
) -> Result<(Vec<[f32; 3]>, std::time::Duration), GpuError> {
    gpu.checked(&format!("evaluating {} samples", samples.len()), || {
        dispatch(gpu, ("eval_samples", Some(model)), (stack, lut, method), samples, repeats)
    })
}

/// `eval_timed`'s and `film_on_gpu`'s work, inside their error scope: the compute entry
/// point (`eval_samples`, the BRDF of the model; `film_samples`, the film alone), the film
/// as one argument (the material's stack, its LUT and the colour method).
fn dispatch(
    gpu: &Gpu,
    (entry_point, model): (&str, Option<Model>),
    (stack, lut, method): (Stack, &Lut, GpuFilmMethod),
    samples: &[GpuSample],
    repeats: u32,
) -> Result<(Vec<[f32; 3]>, std::time::Duration), GpuError> {
    let device = &gpu.device;
    let (_, source, _) = shader_programs().into_iter().find(|(name, _, _)| *name == "brdf_eval").expect("program");
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("brdf_eval"),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    let film_layout = film::bind_group_layout(device);
    let io_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("samples"),
        entries: &[
            storage_entry(0, wgpu::ShaderStages::COMPUTE, true),
            storage_entry(1, wgpu::ShaderStages::COMPUTE, false),
        ],
    });
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("brdf_eval"),
        bind_group_layouts: &[Some(&film_layout), Some(&io_layout)],
        immediate_size: 0,
    });
    // The film's entry point reads no BRDF model: then the override keeps its default.
    let mut constants = vec![("FILM_METHOD", method.code() as f64)];
    if let Some(model) = model {
        constants.push(("BRDF_MODEL", model.code() as f64));
    }
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("brdf_eval"),
        layout: Some(&layout),
        module: &module,
        entry_point: Some(entry_point),
        compilation_options: wgpu::PipelineCompilationOptions { constants: &constants, ..Default::default() },
        cache: None,
    });
    let n_bands = match method {
        GpuFilmMethod::SpectralN(n) => n,
        _ => 1,
    };
    let film = FilmBinding::new(device, &gpu.queue, &film_layout, stack, lut, n_bands);
    let sample_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("samples"),
        contents: bytemuck::cast_slice(samples),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let results = StorageOutput::new(device, "results", (samples.len() * 16) as u64);
    let io_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("samples"),
        layout: &io_layout,
        entries: &[
            wgpu::BindGroupEntry { binding: 0, resource: sample_buffer.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 1, resource: results.buffer.as_entire_binding() },
        ],
    });

    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("brdf_eval") });
    {
        let mut pass = encoder
            .begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("brdf_eval"), timestamp_writes: None });
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &film.bind_group, &[]);
        pass.set_bind_group(1, &io_group, &[]);
        for _ in 0..repeats.max(1) {
            pass.dispatch_workgroups((samples.len() as u32).div_ceil(WORKGROUP_SIZE), 1, 1);
        }
    }
    results.copy_out(&mut encoder);
    let start = std::time::Instant::now();
    gpu.queue.submit([encoder.finish()]);

    let data = results.read(device)?;
    let elapsed = start.elapsed();
    let values: &[[f32; 4]] = bytemuck::cast_slice(&data);
    Ok((values.iter().map(|v| [v[0], v[1], v[2]]).collect(), elapsed))
}

/// `snakeskin bench gpu`: the WGSL BRDF (LUT film) per million evaluations on the GPU and
/// the Rust f32 twin on one CPU core, on the same inputs, in one run.
#[derive(Debug, Clone, serde::Serialize)]
pub struct GpuBench {
    pub adapter: String,
    pub model: &'static str,
    pub samples: usize,
    pub gpu_ms_per_million: f64,
    /// Dispatches beyond the first that the GPU time was measured over
    /// (`seconds_per_dispatch`): 10 where they take 20 ms or more, tenfold steps beyond.
    pub gpu_extra_dispatches: u32,
    pub cpu_f32_ms_per_million: f64,
    pub cpu_threads: usize,
}

/// The shortest span of extra dispatches the GPU timing trusts. Submitting and reading back
/// jitter by up to a millisecond; on an NVIDIA H200 ten extra dispatches of the thesis
/// model (one million evaluations each, 0.04 ms) once read as -0.015 ms per million, and
/// the benchmark gave up.
const MIN_EXTRA_SPAN_S: f64 = 0.020;

/// The most extra dispatches in one submission: each step is tenfold, taken only after the
/// last spanned under `MIN_EXTRA_SPAN_S`, so a step's submissions span under 0.2 s each.
const MAX_EXTRA_DISPATCHES: u32 = 100_000;

/// Seconds per dispatch, and the extra dispatches that measured it, from `time(n)`: the wall
/// time of n dispatches in one submission. Fixed costs (submit, read-back) cancel in the
/// difference of 1 + extra and 1 dispatches, median of five pairs; extra starts at 10 and
/// grows tenfold until that median spans `MIN_EXTRA_SPAN_S`, so a fast GPU is timed over
/// enough work to rise above the jitter. Never reaching it is an error, not a zero.
pub fn seconds_per_dispatch(
    mut time: impl FnMut(u32) -> Result<std::time::Duration, GpuError>,
) -> Result<(f64, u32), GpuError> {
    let mut extra = 10;
    loop {
        let mut spans = Vec::with_capacity(5);
        for _ in 0..5 {
            let one = time(1)?.as_secs_f64();
            spans.push(time(1 + extra)?.as_secs_f64() - one);
        }
        spans.sort_by(f64::total_cmp);
        let span = spans[2];
        if span >= MIN_EXTRA_SPAN_S {
            return Ok((span / f64::from(extra), extra));
        }
        if extra >= MAX_EXTRA_DISPATCHES {
            return Err(GpuError::Timing(format!(
                "{extra} extra dispatches took {:.4} ms (median of 5), under the {} ms the timing needs to \
                 rise above its noise; run it again on a quieter machine, or with more --samples",
                span * 1e3,
                MIN_EXTRA_SPAN_S * 1e3
            )));
        }
        extra *= 10;
    }
}

/// Measures `GpuBench` over `count` deterministic inputs (upper hemisphere, a spread of
/// roughness and thickness). GPU: `seconds_per_dispatch`. CPU: median of five passes.
pub fn bench_per_million(gpu: &Gpu, model: Model, count: usize) -> Result<GpuBench, GpuError> {
    let lut = Lut::bake_default(Stack::THESIS);
    let tau = [0.6, 0.4, 0.2];
    let bounce = crate::optics::brdf::exact::cached(Stack::THESIS, 1000.0).bounce_table(tau);
    let unit = |i: usize, k: u32| crate::ops::hash::unit(i as i32, (i >> 31) as i32, k, 7);
    let inputs: Vec<(Layers32, [f32; 3], [f32; 3])> = (0..count)
        .map(|i| {
            let roughness = 0.05 + 0.9 * unit(i, 0) as f64;
            let (k, e) = bounce.at(roughness);
            let layers = Layers {
                n0: 1.0,
                n1: Stack::THESIS.n1,
                n2: 2.0,
                roughness,
                optical_depth: tau,
                albedo: [0.5, 0.4, 0.3],
                k,
                e,
            };
            let layers = layers.to_f32(crate::optics::lut::FINE_MAX_NM * unit(i, 1) as f64);
            let dir = |a: f32, b: f32| {
                let phi = b * std::f32::consts::TAU;
                let sin = (1.0 - a * a).sqrt();
                [sin * phi.cos(), sin * phi.sin(), a]
            };
            (layers, dir(unit(i, 2), unit(i, 3)), dir(unit(i, 4), unit(i, 5)))
        })
        .collect();
    let samples: Vec<GpuSample> =
        inputs.iter().map(|(l, wi, wo)| GpuSample::new(l, [0.0, 0.0, 1.0], *wi, *wo)).collect();

    let (seconds, extra_dispatches) = seconds_per_dispatch(|repeats| {
        eval_timed(gpu, model, Stack::THESIS, &lut, GpuFilmMethod::Lut, &samples, repeats).map(|(_, t)| t)
    })?;
    let gpu_ms = seconds * 1e3 * 1e6 / count as f64;

    // ns per evaluation is ms per million evaluations.
    let cpu_ms = crate::optics::brdf::accuracy::median_ns_per_eval(model, &inputs, &lut);
    Ok(GpuBench {
        adapter: gpu.describe(),
        model: model.name(),
        samples: count,
        gpu_ms_per_million: gpu_ms,
        gpu_extra_dispatches: extra_dispatches,
        cpu_f32_ms_per_million: cpu_ms,
        cpu_threads: 1,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    /// A clock for `seconds_per_dispatch`: `fixed_s` per submission, `per_dispatch_s` per
    /// dispatch, and up to ±0.5 ms of deterministic jitter per call.
    fn clock(fixed_s: f64, per_dispatch_s: f64) -> impl FnMut(u32) -> Result<Duration, GpuError> {
        let mut call = 0u32;
        move |n| {
            call += 1;
            let jitter_s = (f64::from(crate::ops::hash::unit(call as i32, 0, 3, 11)) - 0.5) * 1e-3;
            Ok(Duration::from_secs_f64(fixed_s + f64::from(n) * per_dispatch_s + jitter_s))
        }
    }

    #[test]
    fn a_fast_gpu_is_timed_over_more_dispatches() {
        // 4 µs a dispatch: ten extra span 40 µs, under the jitter (ten such, read as a
        // difference of two noisy calls, gave the H200's negative time).
        let (seconds, extra) = seconds_per_dispatch(clock(0.005, 4e-6)).unwrap();
        assert_eq!(extra, 10_000, "the first tenfold step whose span reaches 20 ms");
        assert!((seconds / 4e-6 - 1.0).abs() < 0.05, "{seconds} s a dispatch against 4e-6");
    }

    #[test]
    fn a_slow_gpu_keeps_ten_extra_dispatches() {
        let (seconds, extra) = seconds_per_dispatch(clock(0.005, 0.01)).unwrap();
        assert_eq!(extra, 10);
        assert!((seconds / 0.01 - 1.0).abs() < 0.02, "{seconds}");
    }

    #[test]
    fn work_that_never_rises_above_the_jitter_is_an_error() {
        let error = seconds_per_dispatch(clock(0.005, 0.0)).unwrap_err().to_string();
        assert!(error.contains("100000 extra dispatches took") && error.contains("quieter machine"), "{error}");
    }
}
