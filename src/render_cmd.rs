//! The binary's rendering commands: `preview`, `figures` and `bench render`.

use anyhow::Result;

use crate::cli::PreviewArgs;
use crate::progress::Progress;
use snakeskin::Error;
use snakeskin::render::Renderer;
use snakeskin::render::bench::{BenchOptions, bench_render};
use snakeskin::render::preview::{
    parse_image_size, parse_method, reference_check, upload_material, write_figures, write_png,
};
use snakeskin::render::renderer::FrameSettings;
use snakeskin::render::scene::{Camera, View};

fn parse_view(text: &str) -> Result<View, Error> {
    View::parse(text).ok_or_else(|| Error::Preview(format!("unknown --layers {text:?}; accepted: {}", View::ACCEPTED)))
}

pub fn preview(args: PreviewArgs) -> Result<()> {
    // Validate everything before touching the GPU or any file.
    let size = parse_image_size(&args.size)?;
    let view = parse_view(&args.layers)?;
    let method = parse_method(&args.method)?;
    let loaded = snakeskin::generate::load(&args.source.preset, &args.source.overrides, args.source.seed)?;
    if !(args.exposure.is_finite() && args.exposure > 0.0) {
        return Err(Error::Preview(format!("--exposure must be a positive number, got {}", args.exposure)).into());
    }
    if args.out.is_none() && !args.window {
        return Err(Error::Preview("nothing to do: give --out FILE.png (headless) or --window".into()).into());
    }
    let settings = FrameSettings {
        view,
        method,
        exposure: args.exposure,
        ground: !args.no_ground,
        snakes: args.snakes,
        camera: if args.close_up { Camera::close_up() } else { Camera::framing(args.snakes) },
        ..FrameSettings::default()
    };
    if args.window {
        let options = snakeskin::render::window::WindowOptions {
            preset: args.source.preset.clone(),
            overrides: args.source.overrides.clone(),
            seed: args.source.seed,
            map_size: args.map_size as usize,
            size,
            frames: args.frames,
            settings,
        };
        let report = snakeskin::render::window::run(options)?;
        if let Some(frames) = args.frames {
            println!(
                "{frames} frames, mean frame time {:.2} ms ({:.1} fps), adapter {}",
                report.mean_frame_ms,
                1000.0 / report.mean_frame_ms,
                report.adapter
            );
        }
        return Ok(());
    }
    let bar = Progress::spinner("generating maps and baking the film LUT");
    let renderer = Renderer::headless()?;
    let material = upload_material(&renderer, &loaded, args.map_size as usize, method)?;
    bar.message("rendering");
    let image = renderer.render_image(&settings, &material, size.0, size.1)?;
    let out = args.out.expect("checked above");
    let written = write_png(&out, &image)?;
    if let Some(heat_path) = &args.reference {
        bar.message("shading the CPU reference");
        let (report, _) = reference_check(&renderer, &material, &settings, size.0, size.1)?;
        let bytes = {
            let mut b = Vec::new();
            report
                .heat_map(5.0)
                .write_to(&mut std::io::Cursor::new(&mut b), image::ImageFormat::Png)
                .map_err(|e| Error::Preview(e.to_string()))?;
            b
        };
        snakeskin::export::write_file_atomically(heat_path, bytes)?;
        eprintln!(
            "reference: {} pixels, CIEDE2000 mean {:.3}, p99 {:.3}, max {:.3} (heat map: black 0 .. yellow >= 5)",
            report.pixels, report.mean_de, report.p99_de, report.max_de
        );
    }
    bar.finish();
    println!("{}", written.display());
    Ok(())
}

pub fn figures(preset: &str, out: &std::path::Path, size: &str, map_size: u64) -> Result<()> {
    let size = parse_image_size(size)?;
    snakeskin::generate::load(preset, &[], None)?;
    let renderer = Renderer::headless()?;
    let bar = Progress::counting("{spinner} figures [{bar:30}] {pos}/{len} {elapsed}");
    let files = write_figures(&renderer, preset, out, size, map_size as usize, &|done, total| bar.update(done, total))?;
    bar.finish();
    for f in files {
        println!("{}", f.display());
    }
    Ok(())
}

pub fn bench(preset: &str, size: &str, frames: u64, map_size: u64, reference_size: &str, json: bool) -> Result<()> {
    let (width, height) = parse_image_size(size)?;
    let reference_size = parse_image_size(reference_size)?;
    let loaded = snakeskin::generate::load(preset, &[], None)?;
    let renderer = Renderer::headless()?;
    let options = BenchOptions { width, height, frames: frames as usize, map_size: map_size as usize, reference_size };
    let bar = Progress::spinner("bench render");
    let result = bench_render(&renderer, &loaded, &options, &|what| bar.message(what))?;
    bar.finish();
    if json {
        println!("{}", serde_json::to_string_pretty(&result)?);
        return Ok(());
    }
    println!("adapter: {} (timing: {})", result.adapter, result.timing);
    println!("frame {}x{}, median of {} frames, scene pass only", result.width, result.height, result.frames);
    println!("{:<22} {:>7} {:>10} {:>10} {:>10}", "variant", "snakes", "median ms", "p10 ms", "p90 ms");
    for v in &result.variants {
        println!("{:<22} {:>7} {:>10.3} {:>10.3} {:>10.3}", v.name, v.snakes, v.median_ms, v.p10_ms, v.p90_ms);
    }
    println!("skin / plain: {:.3}", result.ratio);
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

pub fn sheet(out: &std::path::Path, tile: u32, columns: u32, map_size: usize) -> Result<()> {
    use snakeskin::render::sheet::{SheetOptions, write_sheet};
    let renderer = Renderer::headless()?;
    let bar = Progress::counting("{spinner} sheet [{bar:30}] {pos}/{len} species {elapsed}");
    let written =
        write_sheet(&renderer, out, SheetOptions { tile, columns, map_size }, &|done, total| bar.update(done, total))?;
    bar.finish();
    println!("{}", written.display());
    Ok(())
}
