//! `snakeskin brdf ...`: machine-readable optics queries, so anyone can check the physics
//! against their own implementation. One JSON object per query; `--batch` reads JSON lines.

use std::io::{BufRead, BufReader, Write};

use anyhow::{Context, Result, bail};
use serde::Deserialize;

use std::collections::HashMap;
use std::sync::Mutex;

use crate::cli::{BenchCommand, BrdfCommand, EvalArgs, StackArgs};
use snakeskin::optics::brdf::{Layers, eval};
use snakeskin::optics::film::{Stack, airy};
use snakeskin::optics::film_rgb_reference;
use snakeskin::optics::lut::Lut;
use snakeskin::optics::methods::{Method, gaussian_fit_f64, rgb3_f64, spectral_n_f64};

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct FilmQuery {
    #[serde(default = "one")]
    n0: f64,
    #[serde(default = "n1_default")]
    n1: f64,
    #[serde(default = "n2_default")]
    n2: f64,
    thickness_nm: f64,
    wavelength_nm: f64,
    angle_deg: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ColorQuery {
    #[serde(default = "one")]
    n0: f64,
    #[serde(default = "n1_default")]
    n1: f64,
    #[serde(default = "n2_default")]
    n2: f64,
    thickness_nm: f64,
    angle_deg: f64,
    #[serde(default = "spectral")]
    method: String,
}

fn one() -> f64 {
    1.0
}
fn n1_default() -> f64 {
    1.55
}
fn n2_default() -> f64 {
    2.0
}
fn spectral() -> String {
    "spectral".into()
}

/// Refuses what the physics does not cover, naming the parameter and the accepted range.
fn check(stack: Stack, thickness_nm: f64, angle_deg: f64, wavelength_nm: Option<f64>) -> Result<()> {
    for (name, n) in [("n0", stack.n0), ("n1", stack.n1), ("n2", stack.n2)] {
        if !(n.is_finite() && n >= 1.0) {
            bail!(snakeskin::Error::Query(format!("{name} must be a finite refractive index >= 1, got {n}")));
        }
    }
    if !(thickness_nm.is_finite() && thickness_nm >= 0.0) {
        bail!(snakeskin::Error::Query(format!("thickness_nm must be finite and >= 0, got {thickness_nm}")));
    }
    if !(angle_deg.is_finite() && (0.0..=90.0).contains(&angle_deg)) {
        bail!(snakeskin::Error::Query(format!("angle_deg must be in [0, 90], got {angle_deg}")));
    }
    if let Some(l) = wavelength_nm
        && !(l.is_finite() && l > 0.0)
    {
        bail!(snakeskin::Error::Query(format!("wavelength_nm must be finite and > 0, got {l}")));
    }
    Ok(())
}

fn film_json(q: &FilmQuery) -> Result<String> {
    let stack = Stack { n0: q.n0, n1: q.n1, n2: q.n2 };
    check(stack, q.thickness_nm, q.angle_deg, Some(q.wavelength_nm))?;
    let rt = airy(stack, q.thickness_nm, q.wavelength_nm, q.angle_deg.to_radians().cos());
    Ok(serde_json::to_string(&rt)?)
}

fn color_json(q: &ColorQuery) -> Result<String> {
    let stack = Stack { n0: q.n0, n1: q.n1, n2: q.n2 };
    check(stack, q.thickness_nm, q.angle_deg, None)?;
    let method = parse_method(&q.method)?;
    let rgb = film_colour(method, stack, q.thickness_nm, q.angle_deg.to_radians().cos());
    Ok(serde_json::json!({ "rgb": rgb }).to_string())
}

fn parse_method(name: &str) -> Result<Method> {
    Method::parse(name).ok_or_else(|| {
        snakeskin::Error::Query(format!("unknown method {name:?}; accepted: {}", Method::ACCEPTED)).into()
    })
}

/// LUTs baked so far, per material (a batch of queries on one material bakes once).
fn lut_for(stack: Stack) -> std::sync::Arc<Lut> {
    static CACHE: Mutex<Option<HashMap<[u64; 3], std::sync::Arc<Lut>>>> = Mutex::new(None);
    let key = [stack.n0.to_bits(), stack.n1.to_bits(), stack.n2.to_bits()];
    let mut cache = CACHE.lock().expect("lut cache");
    cache
        .get_or_insert_with(HashMap::new)
        .entry(key)
        .or_insert_with(|| std::sync::Arc::new(Lut::bake_default(stack)))
        .clone()
}

/// A method's film colour in f64 (the LUT read in f64 arithmetic).
fn film_colour(method: Method, stack: Stack, thickness_nm: f64, cos0: f64) -> [f64; 3] {
    match method {
        Method::Spectral => film_rgb_reference(stack, thickness_nm, cos0),
        Method::Rgb3 => rgb3_f64(stack, thickness_nm, cos0),
        Method::SpectralN(n) => spectral_n_f64(stack, thickness_nm, cos0, n),
        Method::GaussianFit => gaussian_fit_f64(stack, thickness_nm, cos0),
        Method::Lut => lut_for(stack).lookup_f64(thickness_nm, cos0),
    }
}

fn eval_json(args: &EvalArgs) -> Result<String> {
    let stack = Stack { n0: args.stack.n0, n1: args.stack.n1, n2: args.stack.n2 };
    check(stack, args.thickness_nm, 0.0, None)?;
    if !(args.roughness.is_finite() && (0.0..=1.0).contains(&args.roughness)) {
        bail!(snakeskin::Error::Query(format!("roughness must be in [0, 1], got {}", args.roughness)));
    }
    let method = parse_method(&args.method)?;
    let layers = Layers {
        n0: stack.n0,
        n2: stack.n2,
        roughness: args.roughness,
        optical_depth: args.absorption.map(|a| a * args.pigment_thickness),
        albedo: args.albedo,
    };
    let value = eval(&layers, args.normal, args.wi, args.wo, &|c| film_colour(method, stack, args.thickness_nm, c));
    Ok(serde_json::json!({ "f": value.total(), "specular": value.specular, "diffuse": value.diffuse }).to_string())
}

fn batch_lines(path: &str) -> Result<Box<dyn BufRead>> {
    Ok(if path == "-" {
        Box::new(BufReader::new(std::io::stdin()))
    } else {
        Box::new(BufReader::new(std::fs::File::open(path).with_context(|| format!("cannot read {path}"))?))
    })
}

/// Runs `per_line` on every non-empty JSON line; errors name the line number.
fn run_batch<Q: for<'de> Deserialize<'de>>(path: &str, per_line: impl Fn(&Q) -> Result<String>) -> Result<()> {
    let mut out = std::io::stdout().lock();
    for (i, line) in batch_lines(path)?.lines().enumerate() {
        let line = line?;
        if line.trim().is_empty() {
            continue;
        }
        let query: Q =
            serde_json::from_str(&line).map_err(|e| snakeskin::Error::Query(format!("{path}:{}: {e}", i + 1)))?;
        let json = per_line(&query).with_context(|| format!("{path}:{}", i + 1))?;
        writeln!(out, "{json}")?;
    }
    Ok(())
}

fn stack_of(s: &StackArgs) -> (f64, f64, f64) {
    (s.n0, s.n1, s.n2)
}

pub fn run(command: BrdfCommand) -> Result<()> {
    match command {
        BrdfCommand::Film { batch: Some(path), .. } => run_batch(&path, film_json),
        BrdfCommand::Film { stack, thickness_nm, wavelength_nm, angle_deg, batch: None } => {
            let (n0, n1, n2) = stack_of(&stack);
            let query = FilmQuery {
                n0,
                n1,
                n2,
                thickness_nm: thickness_nm.unwrap_or_default(),
                wavelength_nm: wavelength_nm.unwrap_or_default(),
                angle_deg: angle_deg.unwrap_or_default(),
            };
            println!("{}", film_json(&query)?);
            Ok(())
        }
        BrdfCommand::Chart { stack, out, method, width, height } => {
            let stack = Stack { n0: stack.n0, n1: stack.n1, n2: stack.n2 };
            check(stack, 0.0, 0.0, None)?;
            let method = parse_method(&method)?;
            if !(2..=4096).contains(&width) || !(2..=4096).contains(&height) {
                bail!(snakeskin::Error::Query("chart width and height must be 2..=4096 pixels".into()));
            }
            let exposure = chart(stack, method, width as usize, height as usize, &out)?;
            eprintln!("wrote {} (linear reflectance scaled by {exposure:.3} before sRGB encoding)", out.display());
            Ok(())
        }
        BrdfCommand::Eval(args) => {
            println!("{}", eval_json(&args)?);
            Ok(())
        }
        BrdfCommand::Stress { samples, seed, json } => {
            let report = snakeskin::optics::stress::run(samples, seed);
            if json {
                println!("{}", serde_json::to_string(&report)?);
            } else {
                println!("{report:#?}");
            }
            Ok(())
        }
        BrdfCommand::Color { batch: Some(path), .. } => run_batch(&path, color_json),
        BrdfCommand::Color { stack, thickness_nm, angle_deg, method, batch: None } => {
            let (n0, n1, n2) = stack_of(&stack);
            let query = ColorQuery {
                n0,
                n1,
                n2,
                thickness_nm: thickness_nm.unwrap_or_default(),
                angle_deg: angle_deg.unwrap_or_default(),
                method,
            };
            println!("{}", color_json(&query)?);
            Ok(())
        }
    }
}

pub fn bench(command: BenchCommand) -> Result<()> {
    match command {
        BenchCommand::Gpu { samples, json } => bench_gpu(samples as usize, json),
        BenchCommand::Render { preset, size, frames, map_size, reference_size, json } => {
            crate::render_cmd::bench(&preset, &size, frames, map_size, &reference_size, json)
        }
        BenchCommand::Irid { json, plot, d_step_nm, angle_step_deg, lut_sweep } => {
            use snakeskin::optics::accuracy::{Prepared, grid, measure, reference_colours};
            use snakeskin::optics::lab::linear_srgb_to_lab;
            if !(d_step_nm > 0.0 && angle_step_deg > 0.0) {
                bail!(snakeskin::Error::Query("grid steps must be positive".into()));
            }
            let samples = grid(d_step_nm, angle_step_deg);
            eprintln!("reference: {} grid points, 1 nm spectral sum", samples.len());
            let reference_lab: Vec<[f64; 3]> =
                reference_colours(&samples).into_iter().map(linear_srgb_to_lab).collect();
            let mut reports = Vec::new();
            for method in Method::all_realtime() {
                eprintln!("measuring {}", method.name());
                reports.push(measure(&Prepared::new(method), &samples, &reference_lab));
            }
            if lut_sweep {
                for size in [(16, 64, 16), (32, 128, 32), (128, 512, 128)] {
                    let mut report = measure(&Prepared::with_lut_size(Method::Lut, size), &samples, &reference_lab);
                    report.name = format!("lut-{}x{}+{}", size.0, size.1, size.2);
                    reports.push(report);
                }
            }
            let default = Method::Lut.name();
            if json {
                println!("{}", serde_json::json!({ "default": default, "methods": reports }));
            } else {
                println!("{:<18} {:>9} {:>9} {:>9} {:>12}", "method", "mean ΔE", "p95 ΔE", "max ΔE", "ns/eval");
                for r in &reports {
                    let mark = if r.name == default { " (default)" } else { "" };
                    println!(
                        "{:<18} {:>9.3} {:>9.3} {:>9.3} {:>12.1}{mark}",
                        r.name, r.mean_de, r.p95_de, r.max_de, r.ns_per_eval
                    );
                }
            }
            if let Some(path) = plot {
                let svg = snakeskin::optics::plot::error_vs_cost_svg(&reports, &default);
                snakeskin::export::write_file_atomically(&path, svg.into_bytes())?;
            }
            Ok(())
        }
    }
}

/// Renders the chart; returns the exposure (1 / brightest channel) applied so the colours
/// use the whole range (film reflectances are a few percent to a few tens of percent).
fn chart(stack: Stack, method: Method, width: usize, height: usize, out: &std::path::Path) -> Result<f64> {
    use rayon::prelude::*;
    let rows: Vec<Vec<[f64; 3]>> = (0..height)
        .into_par_iter()
        .map(|y| {
            let angle_deg = 89.0 * y as f64 / (height - 1) as f64;
            (0..width)
                .map(|x| {
                    film_colour(method, stack, 2000.0 * x as f64 / (width - 1) as f64, angle_deg.to_radians().cos())
                })
                .collect()
        })
        .collect();
    let brightest = rows.iter().flatten().flat_map(|p| p.iter().copied()).fold(1e-6, f64::max);
    let exposure = 1.0 / brightest;
    let image = snakeskin::ops::Image {
        width,
        height,
        channels: 3,
        data: rows.into_iter().flatten().flat_map(|p| p.map(|c| (c * exposure) as f32)).collect(),
    };
    let png = snakeskin::export::encode_png(snakeskin::maps::MapKind::Color, &image)?;
    snakeskin::export::write_file_atomically(out, png)?;
    Ok(exposure)
}

/// GPU compute against the CPU twin, per million BRDF evaluations, on the same inputs.
fn bench_gpu(count: usize, json: bool) -> Result<()> {
    use snakeskin::optics::brdf::{Layers32, eval_f32};
    use snakeskin::render::Gpu;
    use snakeskin::render::brdf_eval::{GpuSample, eval_timed};
    use snakeskin::render::film::GpuFilmMethod;
    use std::hint::black_box;

    let gpu = Gpu::headless()?;
    let lut = Lut::bake_default(Stack::THESIS);
    // Deterministic inputs over the upper hemisphere, a spread of roughness and thickness.
    let unit = |i: usize, k: u32| snakeskin::ops::hash::unit(i as i32, (i >> 31) as i32, k, 7);
    let inputs: Vec<(Layers32, [f32; 3], [f32; 3])> = (0..count)
        .map(|i| {
            let layers = Layers32 {
                n0: 1.0,
                n2: 2.0,
                roughness: 0.05 + 0.9 * unit(i, 0),
                optical_depth: [0.6, 0.4, 0.2],
                albedo: [0.5, 0.4, 0.3],
                thickness_nm: 2000.0 * unit(i, 1),
            };
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

    // Fixed costs (submit, readback) cancel in the difference of 11 and 1 dispatches; the
    // median of five such pairs.
    let mut per_million: Vec<f64> = (0..5)
        .map(|_| -> Result<f64> {
            let (_, one) = eval_timed(&gpu, Stack::THESIS, &lut, GpuFilmMethod::Lut, &samples, 1)?;
            let (_, eleven) = eval_timed(&gpu, Stack::THESIS, &lut, GpuFilmMethod::Lut, &samples, 11)?;
            Ok((eleven.as_secs_f64() - one.as_secs_f64()).max(0.0) / 10.0 * 1e3 * 1e6 / count as f64)
        })
        .collect::<Result<_>>()?;
    per_million.sort_by(f64::total_cmp);
    let gpu_ms = per_million[2];

    let mut cpu: Vec<f64> = (0..5)
        .map(|_| {
            let start = std::time::Instant::now();
            let mut acc = 0.0f32;
            for (l, wi, wo) in &inputs {
                acc += eval_f32(black_box(l), [0.0, 0.0, 1.0], *wi, *wo, &lut)[1];
            }
            black_box(acc);
            start.elapsed().as_secs_f64() * 1e3 * 1e6 / count as f64
        })
        .collect();
    cpu.sort_by(f64::total_cmp);
    let cpu_ms = cpu[2];
    let report = serde_json::json!({
        "adapter": gpu.describe(),
        "samples": count,
        "gpu_ms_per_million": gpu_ms,
        "cpu_f32_ms_per_million": cpu_ms,
        "cpu_threads": 1,
    });
    if json {
        println!("{report}");
    } else {
        println!("adapter: {}", gpu.describe());
        println!("WGSL BRDF (compute):  {gpu_ms:.3} ms per million evaluations");
        println!("Rust f32 twin (1 core): {cpu_ms:.3} ms per million evaluations");
    }
    Ok(())
}
