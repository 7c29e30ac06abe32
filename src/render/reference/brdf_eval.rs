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
        dispatch(gpu, model, (stack, lut, method), samples, repeats)
    })
}

/// `eval_timed`'s work, inside its error scope (the film as one argument: the material's
/// stack, its LUT and the colour method).
fn dispatch(
    gpu: &Gpu,
    model: Model,
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
    let constants = [("FILM_METHOD", method.code() as f64), ("BRDF_MODEL", model.code() as f64)];
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("brdf_eval"),
        layout: Some(&layout),
        module: &module,
        entry_point: Some("eval_samples"),
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
            pass.dispatch_workgroups((samples.len() as u32).div_ceil(64), 1, 1);
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
    pub cpu_f32_ms_per_million: f64,
    pub cpu_threads: usize,
}

/// Measures `GpuBench` over `count` deterministic inputs (upper hemisphere, a spread of
/// roughness and thickness). GPU: fixed costs (submit, readback) cancel in the difference of
/// 11 and 1 dispatches, median of five pairs; a difference that is not positive means the
/// timing is meaningless and is an error, not a zero. CPU: median of five passes.
pub fn bench_per_million(gpu: &Gpu, model: Model, count: usize) -> Result<GpuBench, GpuError> {
    let lut = Lut::bake_default(Stack::THESIS);
    let tau = [0.6, 0.4, 0.2];
    let bounce = crate::optics::brdf::exact::cached(Stack::THESIS, 1000.0).bounce_table(tau);
    let unit = |i: usize, k: u32| crate::ops::hash::unit(i as i32, (i >> 31) as i32, k, 7);
    let inputs: Vec<(Layers32, [f32; 3], [f32; 3])> = (0..count)
        .map(|i| {
            let roughness = 0.05 + 0.9 * unit(i, 0) as f64;
            let (k, e) = bounce.at(roughness);
            let layers = Layers { n0: 1.0, n2: 2.0, roughness, optical_depth: tau, albedo: [0.5, 0.4, 0.3], k, e };
            let layers = layers.to_f32(2000.0 * unit(i, 1) as f64);
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

    let mut per_million = Vec::new();
    for _ in 0..5 {
        let (_, one) = eval_timed(gpu, model, Stack::THESIS, &lut, GpuFilmMethod::Lut, &samples, 1)?;
        let (_, eleven) = eval_timed(gpu, model, Stack::THESIS, &lut, GpuFilmMethod::Lut, &samples, 11)?;
        per_million.push((eleven.as_secs_f64() - one.as_secs_f64()) / 10.0 * 1e3 * 1e6 / count as f64);
    }
    per_million.sort_by(f64::total_cmp);
    let gpu_ms = per_million[2];
    if !(gpu_ms.is_finite() && gpu_ms > 0.0) {
        return Err(GpuError::Timing(format!(
            "10 extra dispatches took {gpu_ms:.4} ms per million evaluations (median of 5): the timing is \
             dominated by noise; run it again on a quieter machine"
        )));
    }

    // ns per evaluation is ms per million evaluations.
    let cpu_ms = crate::optics::brdf::accuracy::median_ns_per_eval(model, &inputs, &lut);
    Ok(GpuBench {
        adapter: gpu.describe(),
        model: model.name(),
        samples: count,
        gpu_ms_per_million: gpu_ms,
        cpu_f32_ms_per_million: cpu_ms,
        cpu_threads: 1,
    })
}
