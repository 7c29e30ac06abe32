//! `snakeskin bench ...`: film-method error against cost, the WGSL BRDF against its CPU
//! twin, and the renderer's frame time against a plain PBR shader.

use anyhow::Result;

use crate::cli::BenchCommand;
use crate::output::{ensure_parent_folder, path_line};
use crate::progress::Progress;
use snakeskin::Error;
use snakeskin::optics::accuracy::{MAX_GRID_POINTS, Prepared, grid, grid_points, measure, reference_colours};
use snakeskin::optics::lab::linear_srgb_to_lab;
use snakeskin::optics::methods::Method;
use snakeskin::render::Renderer;
use snakeskin::render::reference::bench::{BenchOptions, bench_render};

pub fn run(command: BenchCommand) -> Result<()> {
    match command {
        BenchCommand::Gpu { samples, model, json } => gpu(samples as usize, model, json),
        BenchCommand::Render { preset, size, frames, map_size, reference_size, lut_only, json } => {
            let options = BenchOptions {
                width: size.width,
                height: size.height,
                frames: frames as usize,
                map_size: map_size as usize,
                reference_size: (reference_size.width, reference_size.height),
                lut_only,
            };
            render(&preset, &options, json)
        }
        BenchCommand::Irid { json, plot, d_step_nm, angle_step_deg, lut_sweep } => {
            irid(json, plot.as_deref(), d_step_nm, angle_step_deg, lut_sweep)
        }
        BenchCommand::Layered { json, photons, plot } => layered(json, photons, plot.as_deref()),
    }
}

/// The base colours of every built-in species (back and belly), linear sRGB, each once.
fn species_colours() -> Result<Vec<[f64; 3]>> {
    let mut colours: Vec<[f64; 3]> = Vec::new();
    for (name, _) in snakeskin::preset::library::all() {
        let preset = snakeskin::preset::load(name, &[], None)?.preset;
        for c in [preset.color.base, preset.belly.color] {
            let linear = c.to_linear().map(f64::from);
            if !colours.contains(&linear) {
                colours.push(linear);
            }
        }
    }
    Ok(colours)
}

fn layered(json: bool, photons: u64, plot: Option<&std::path::Path>) -> Result<()> {
    if let Some(path) = plot {
        snakeskin::export::check_target_named(path, "svg")?;
        ensure_parent_folder(path)?;
    }
    let colours = species_colours()?;
    let progress = Progress::spinner("walking photons through the stack");
    let report = snakeskin::optics::brdf::accuracy::run(&colours, photons);
    progress.finish();
    if let Some(path) = plot {
        // The same plot as `bench irid`'s, one point per model.
        let points: Vec<snakeskin::optics::accuracy::MethodReport> = report
            .models
            .iter()
            .map(|m| snakeskin::optics::accuracy::MethodReport {
                name: m.name.to_string(),
                mean_de: m.mean_de,
                p95_de: m.p95_de,
                max_de: m.max_de,
                ns_per_eval: m.ns_per_eval,
            })
            .collect();
        let svg = snakeskin::optics::plot::error_vs_cost_svg(
            &points,
            snakeskin::optics::brdf::Model::default().name(),
            "the photon walk",
        );
        snakeskin::export::write_file_atomically(path, svg.into_bytes())?;
        // On stderr, as `brdf chart` says its file: stdout may be the JSON.
        eprintln!("wrote {}", path_line(path));
    }
    if json {
        println!("{}", serde_json::to_string(&report)?);
        return Ok(());
    }
    println!(
        "{} points ({} colours), {} photons per channel per walk; reference noise: mean ΔE00 {:.3}, max {:.3}",
        report.points,
        colours.len(),
        report.photons_per_channel,
        report.reference_noise_mean_de,
        report.reference_noise_max_de
    );
    // Half a ΔE00: the colour differences the targets are set in (mean 0.5, max 1.5)
    // are then not the reference's noise.
    if report.reference_noise_max_de > 0.5 {
        println!(
            "  (the reference's own noise moves a colour by up to {:.2} ΔE00: errors of that size may be \
             its noise; more --photons lower it as 1/√N)",
            report.reference_noise_max_de
        );
    }
    println!(
        "{:<10} {:>8} {:>8} {:>8} {:>12} {:>12} {:>10} {:>14}",
        "model", "mean ΔE", "p95 ΔE", "max ΔE", "furnace≤70°", "furnace all", "ns/eval", "ns/eval coh."
    );
    for m in &report.models {
        println!(
            "{:<10} {:>8.3} {:>8.3} {:>8.3} {:>12.4} {:>12.4} {:>10.1} {:>14.1}",
            m.name,
            m.mean_de,
            m.p95_de,
            m.max_de,
            m.max_furnace_err_to_70,
            m.max_furnace_err,
            m.ns_per_eval,
            m.ns_per_eval_coherent
        );
    }
    println!("\nwhere the error lies (mean / max ΔE00 over materials, τ, films and colours):");
    println!("{:<10} {:>9} {:>9} {:>8} {:>8}", "model", "roughness", "angle°", "mean", "max");
    for (name, roughness, angle, mean, max) in &report.error_by_roughness_angle {
        println!("{name:<10} {roughness:>9.2} {angle:>9.0} {mean:>8.3} {max:>8.3}");
    }
    println!("{:<10} {:>9} {:>8} {:>8}", "model", "τ", "mean", "max");
    for (name, tau, mean, max) in &report.error_by_optical_depth {
        println!("{name:<10} {tau:>9.2} {mean:>8.3} {max:>8.3}");
    }
    Ok(())
}

fn irid(json: bool, plot: Option<&std::path::Path>, d_step_nm: f64, angle_step_deg: f64, sweep: bool) -> Result<()> {
    let points = grid_points(d_step_nm, angle_step_deg);
    if points > MAX_GRID_POINTS {
        // An option pair, not a query: it said "invalid query".
        let reason = format!(
            "{d_step_nm} with --angle-step-deg {angle_step_deg} makes {points} grid points; at most \
             {MAX_GRID_POINTS} are accepted (each needs a {SAMPLES}-wavelength reference sum): use larger steps",
            SAMPLES = snakeskin::optics::spectrum::SAMPLES
        );
        return Err(Error::InvalidOption { option: "--d-step-nm", reason }.into());
    }
    if let Some(path) = plot {
        snakeskin::export::check_target_named(path, "svg")?;
        ensure_parent_folder(path)?;
    }
    let samples = grid(d_step_nm, angle_step_deg);
    eprintln!("reference: {} grid points, 1 nm spectral sum", samples.len());
    let reference_lab: Vec<[f64; 3]> = reference_colours(&samples).into_iter().map(linear_srgb_to_lab).collect();
    let mut reports = Vec::new();
    for method in Method::all_realtime() {
        eprintln!("measuring {}", method.name());
        reports.push(measure(&Prepared::new(method), &samples, &reference_lab));
    }
    if sweep {
        for size in [(16, 64, 16), (32, 128, 32), (128, 512, 128)] {
            let mut report = measure(&Prepared::with_lut_size(Method::Lut, size), &samples, &reference_lab);
            report.name = format!("lut-{}x{}+{}", size.0, size.1, size.2);
            reports.push(report);
        }
    }
    let default = Method::Lut.name();
    // The plot is written before the results are printed, as `layered`'s: a plot that could
    // not be written printed the whole JSON and then exited 1 (a hostile-input sweep, on a
    // full disk), so a script had complete results and a failure.
    if let Some(path) = plot {
        let svg = snakeskin::optics::plot::error_vs_cost_svg(&reports, &default, "the spectral reference");
        snakeskin::export::write_file_atomically(path, svg.into_bytes())?;
        eprintln!("wrote {}", path_line(path));
    }
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
    Ok(())
}

/// GPU compute against the CPU twin, per million BRDF evaluations, on the same inputs.
fn gpu(count: usize, model: snakeskin::optics::brdf::Model, json: bool) -> Result<()> {
    let gpu = snakeskin::render::Gpu::headless()?;
    let result = snakeskin::render::reference::brdf_eval::bench_per_million(&gpu, model, count)?;
    if json {
        println!("{}", serde_json::to_string(&result)?);
    } else {
        println!("adapter: {}, model: {}", result.adapter, result.model);
        println!(
            "WGSL BRDF (compute):  {:.3} ms per million evaluations ({} extra dispatches timed)",
            result.gpu_ms_per_million, result.gpu_extra_dispatches
        );
        println!("Rust f32 twin (1 core): {:.3} ms per million evaluations", result.cpu_f32_ms_per_million);
    }
    Ok(())
}

fn render(preset: &str, options: &BenchOptions, json: bool) -> Result<()> {
    let loaded = snakeskin::preset::load(preset, &[], None)?;
    crate::output::report_warnings(preset, &loaded);
    snakeskin::render::reference::bench::check_memory(&loaded, options)?;
    let renderer = Renderer::headless()?;
    let bar = Progress::spinner("bench render");
    let result = bench_render(&renderer, &loaded, options, &|what| bar.message(what))?;
    bar.finish();
    if json {
        println!("{}", serde_json::to_string(&result)?);
        return Ok(());
    }
    println!("adapter: {} (timing: {})", result.adapter, result.timing);
    println!("frame {}x{}, median of {} frames, scene pass only", result.width, result.height, result.frames);
    println!("{:<22} {:>7} {:>10} {:>10} {:>10}", "variant", "snakes", "median ms", "p10 ms", "p90 ms");
    for v in &result.variants {
        println!("{:<22} {:>7} {:>10.3} {:>10.3} {:>10.3}", v.name, v.snakes, v.median_ms, v.p10_ms, v.p90_ms);
    }
    println!(
        "skin / plain: {:.3} (layered model, the default), {:.3} (thesis model), {:.3} (the film at each pixel's \
         mean thickness: preview --film-footprint mean)",
        result.ratio, result.thesis_ratio, result.mean_thickness_ratio
    );
    println!(
        "reference ({}x{}, {} px): CIEDE2000 mean {:.3}, p99 {:.3}, max {:.3}",
        result.reference_width,
        result.reference_height,
        result.reference_pixels,
        result.reference_mean_de,
        result.reference_p99_de,
        result.reference_max_de
    );
    Ok(())
}
