//! `snakeskin preview`: a preset on a snake body, headless to a PNG or in a window.

use anyhow::Result;

use crate::cli::PreviewArgs;
use crate::output::{ensure_parent_folder, path_line};
use crate::progress::Progress;
use snakeskin::Error;
use snakeskin::export::FileGroup;
use snakeskin::render::Renderer;
use snakeskin::render::engine::gpu::GpuError;
use snakeskin::render::engine::prepare::upload_material_in;
use snakeskin::render::engine::renderer::{FrameSettings, frame_bytes, gbuffer_bytes};
use snakeskin::render::engine::scene::{Camera, View};
use snakeskin::render::figures::{png_bytes, rendered_png_bytes};
use snakeskin::render::reference::frame::reference_check;

pub fn run(args: PreviewArgs) -> Result<()> {
    // Validate everything before touching the GPU or any file.
    let source = &args.source;
    let loaded = snakeskin::preset::load(&source.preset, &source.overrides, source.seed)?;
    crate::output::report_warnings(&source.preset, &loaded);
    if args.out.is_none() && !args.window {
        // `--frames` alone said "nothing to do", as if it were not there.
        let what = if args.frames.is_some() {
            "--frames N renders N frames in a window and prints their mean time: add --window"
        } else {
            "nothing to do: give --out FILE.png (headless) or --window"
        };
        return Err(Error::Preview(what.into()).into());
    }
    // Here, not as clap's conflict: that refused `--snakes 1`, the default, too.
    if args.close_up && args.snakes > 1 {
        let what = format!("--close-up frames one snake, not --snakes {}: leave one of them out", args.snakes);
        return Err(Error::Preview(what).into());
    }
    let settings = FrameSettings {
        view: args.layers,
        method: args.method,
        model: args.model,
        exposure: args.exposure,
        ground: !args.no_ground,
        footprint: args.film_footprint.footprint(),
        snakes: args.snakes,
        camera: if args.close_up { Camera::close_up() } else { Camera::framing(args.snakes) },
        ..FrameSettings::default()
    };
    narrowed_note(&loaded, args.map_size as usize, args.layout.layout());
    if matches!(args.layers, View::Map(_)) && args.exposure != 1.0 {
        // It was dropped without a word (a sweep): a map view shows values, not light.
        eprintln!(
            "note: --exposure {} does nothing here: a map view shows each map as its file stores it, unlit and \
             unexposed",
            args.exposure
        );
    }
    if args.window {
        return window(&args, settings);
    }
    let out = args.out.as_deref().expect("checked above");
    let (width, height) = (args.size.width, args.size.height);
    if let Some(heat_path) = &args.reference
        && snakeskin::export::same_path(heat_path, out)
    {
        // The heat map replaced the render, which was printed as written.
        return Err(Error::Preview(format!(
            "--out and --reference name one file ({}); give the heat map a name of its own",
            path_line(out)
        ))
        .into());
    }
    if let Some(heat_path) = &args.reference {
        for (inner, flag, outer, outer_flag) in
            [(heat_path.as_path(), "--reference", out, "--out"), (out, "--out", heat_path.as_path(), "--reference")]
        {
            if snakeskin::export::lies_under(inner, outer) {
                return Err(Error::Preview(format!(
                    "{flag} {} lies inside {outer_flag} {}, a file this run writes; give each its own place",
                    path_line(inner),
                    path_line(outer)
                ))
                .into());
            }
        }
    }
    // Names, then memory, then the GPU's limits, then folders: a refused run makes none
    // (`ensure_parent_folder` checks the names again, where other commands rely on it).
    for file in std::iter::once(out).chain(args.reference.as_deref()) {
        snakeskin::export::check_png_target(file)?;
        snakeskin::export::check_not_an_input(file, snakeskin::preset::input_file(&source.preset))?;
    }
    let layout = args.layout.layout();
    let frame_bytes = frame_bytes(width, height)
        + args.reference.as_ref().map_or(0, |_| gbuffer_bytes(width, height))
        + snakeskin::render::engine::prepare::more_snakes_bytes(&loaded, layout, args.snakes);
    snakeskin::render::engine::prepare::check_preview_memory(
        &loaded,
        args.map_size as usize,
        layout,
        frame_bytes,
        false,
    )?;
    let bar = Progress::spinner("generating maps and baking the film LUT");
    let renderer = Renderer::headless()?;
    if args.reference.is_some() {
        // Before the render is written: the check's G-buffer is read back in one buffer.
        renderer.check_readback(width, height, 16).map_err(|e| match e {
            GpuError::Limits(why) => GpuError::Limits(format!("{why} (--size {width}x{height} with --reference)")),
            e => e,
        })?;
    }
    // Before the work: a folder that takes no new file is said at once, naming the file.
    for file in std::iter::once(out).chain(args.reference.as_deref()) {
        ensure_parent_folder(file)?;
    }
    let material = upload_material_in(&renderer, &loaded, args.map_size as usize, args.method, layout)?;
    bar.message("rendering");
    let image = renderer.render_image(&settings, &material, width, height)?;
    // The render and its heat map appear together or not at all: a reference check that
    // failed (or was interrupted) had already replaced the earlier render.
    let mut files = FileGroup::new();
    files.stage(out, rendered_png_bytes(&image)?)?;
    drop(image);
    bar.finish();
    if let Some(heat_path) = &args.reference {
        let bar = Progress::counting("{spinner} CPU reference [{bar:30}] {pos}/{len} pixels {elapsed} (ETA {eta})");
        let (report, _) =
            reference_check(&renderer, &material, &settings, width, height, &|done, total| bar.update(done, total))?;
        bar.finish();
        files.stage(heat_path, png_bytes(&report.heat_map(5.0))?)?;
        eprintln!(
            "reference: {} pixels, CIEDE2000 mean {:.3}, p99 {:.3}, max {:.3} (heat map: black 0 .. yellow >= 5)",
            report.pixels, report.mean_de, report.p99_de, report.max_de
        );
    }
    // Every written path is printed: the render, then the heat map.
    for written in files.commit()? {
        println!("{}", path_line(&written));
    }
    Ok(())
}

#[cfg(feature = "window")]
fn window(args: &PreviewArgs, settings: FrameSettings) -> Result<()> {
    // A file where the views would go is said now, not at the first S.
    snakeskin::export::check_folder(&args.shots)?;
    let options = snakeskin::render::window::WindowOptions {
        preset: args.source.preset.clone(),
        overrides: args.source.overrides.clone(),
        seed: args.source.seed,
        map_size: args.map_size as usize,
        layout: args.layout.layout(),
        size: (args.size.width, args.size.height),
        frames: args.frames,
        settings,
        shots: args.shots.clone(),
        report: Box::new(|status| eprintln!("preview: {}", crate::output::printable(status))),
    };
    let report = snakeskin::render::window::run(options)?;
    if args.frames.is_some() {
        // The frames drawn (a closed window ends the run early); a frame time needs two.
        let timing = if report.mean_frame_ms.is_finite() {
            format!("mean frame time {:.2} ms ({} fps)", report.mean_frame_ms, fps_text(report.mean_frame_ms))
        } else {
            "no frame time (it needs two frames)".to_string()
        };
        let frames = if report.frames == 1 { "1 frame".to_string() } else { format!("{} frames", report.frames) };
        println!("{frames}, {timing}, adapter {}", report.adapter);
    }
    Ok(())
}

#[cfg(not(feature = "window"))]
fn window(_: &PreviewArgs, _: FrameSettings) -> Result<()> {
    Err(Error::Preview("this build has no window (built without the `window` feature); use --out FILE.png".into())
        .into())
}

/// A body atlas `--map-size` wide that would pass the preview's tallest texture is drawn
/// narrower (`prepare::map_dimensions`): say so, where the refusal of a run too large for
/// memory was the only place that named the maps' size.
fn narrowed_note(loaded: &snakeskin::preset::LoadedPreset, map_size: usize, layout: snakeskin::maps::Layout) {
    use snakeskin::render::engine::prepare::{MAX_TEXTURE_SIDE, map_dimensions};
    let (width, height) = map_dimensions(loaded, map_size, layout);
    if width < map_size {
        eprintln!(
            "note: the body atlas is {width}x{height}: --map-size {map_size} would make it longer than {MAX_TEXTURE_SIDE} \
             rows ({} widths)",
            loaded.preset.body.length
        );
    }
}

/// Frames a second from a mean frame time: one decimal, or below 10 fps two significant
/// figures (a 25 s frame read "0.0 fps").
fn fps_text(mean_frame_ms: f64) -> String {
    let fps = 1000.0 / mean_frame_ms;
    let decimals = if fps >= 10.0 { 1 } else { (1.0 - fps.log10().floor()).clamp(1.0, 6.0) as usize };
    format!("{fps:.decimals$}")
}

#[cfg(test)]
mod tests {
    use super::fps_text;

    #[test]
    fn slow_frames_keep_two_figures_of_their_rate() {
        for (ms, says) in [(25_000.0, "0.040"), (1000.0, "1.0"), (200.0, "5.0"), (16.667, "60.0"), (2000.0, "0.50")] {
            assert_eq!(fps_text(ms), says, "{ms} ms");
        }
    }
}
