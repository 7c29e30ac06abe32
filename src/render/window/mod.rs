//! The interactive preview: a winit window drawing the same frame as the headless path into
//! its surface, with an egui side panel (optics sliders like the thesis' Unity inspector,
//! Fig. 5.1; stage, map and method pickers; frame time) and live reload.
//!
//! Nothing slow runs on the render thread: `reload` owns the workers (maps through a node
//! cache, film tables), `panel` the side panel. Thickness, absorption and light sliders
//! change only uniforms and apply at once.

mod panel;
mod reload;

use std::sync::Arc;
use std::sync::mpsc::{Receiver, Sender};
use std::time::{Duration, Instant};

use winit::application::ApplicationHandler;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::Key;
use winit::window::{Window, WindowId};

use self::panel::{Sliders, controls};
use super::engine::material::MaterialMaps;
use super::engine::prepare::{bands_for, material_maps_cached};
use super::engine::renderer::{FrameOutput, FrameSettings, Material, Renderer, Targets, WINDOW_FRAME_LATENCY};
use super::engine::scene::{Camera, LayerOptics};
use super::{Gpu, GpuError};
use crate::Error;
use crate::graph::NodeCache;
use crate::optics::film::Stack;
use crate::optics::lut::Lut;

pub struct WindowOptions {
    pub preset: String,
    pub overrides: Vec<(String, String)>,
    pub seed: Option<u64>,
    pub map_size: usize,
    /// The tile repeated along the body, or a body atlas on its whole snake.
    pub layout: crate::maps::Layout,
    pub size: (u32, u32),
    /// Render this many frames, then exit (tests, benchmarks).
    pub frames: Option<u32>,
    pub settings: FrameSettings,
    /// The folder the S key saves the view into (`export::write_new_numbered_file`: made if
    /// missing, never replacing a file).
    pub shots: std::path::PathBuf,
    /// Receives status lines (first frame, each reload or failed reload) for the user: the
    /// window may be behind others, and tests read them. The library itself prints nothing.
    pub report: Box<dyn Fn(&str)>,
}

#[derive(Debug, Clone)]
pub struct WindowReport {
    pub frames: u32,
    pub mean_frame_ms: f64,
    pub adapter: String,
}

struct Gfx {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    renderer: Renderer,
    targets: Targets,
    material: Material,
    egui_state: egui_winit::State,
    egui_renderer: egui_wgpu::Renderer,
    /// Why the window is not drawn at its size now (`App::resize`), or None while it is.
    not_drawn: Option<NotDrawn>,
}

/// Why a window's frames are not drawn (`App::resize`).
#[derive(Debug)]
enum NotDrawn {
    /// Minimised (no pixels): nothing to say.
    Minimised,
    /// Larger than the GPU or the memory can draw: said once, until it is smaller again.
    TooLarge(String),
}

/// How long the window goes on drawing after something changed (input, a slider, a reload,
/// a resize): long enough for the panel's frame time to be measured over several frames
/// even on a software GPU (lavapipe draws a 960×540 frame in about 0.2 s), short enough that
/// an idle window is idle. It drew without end before: an untouched 320×200 window took
/// 1.1 to 1.8 cores of two on lavapipe (a window sweep).
const DRAWN_ON_AFTER_A_CHANGE: Duration = Duration::from_millis(500);

/// How often an idle window looks whether the background workers finished (a reload, film
/// tables): a look is a channel's `try_recv`, so the idle window costs nothing measurable.
const IDLE_LOOK_INTERVAL: Duration = Duration::from_millis(100);

struct App {
    options: WindowOptions,
    settings: FrameSettings,
    sliders: Sliders,
    /// The sliders as the preset file gives them (its `--set` included), at the start and
    /// at each reload: what the saved view's `--set` arguments differ from.
    file_sliders: Sliders,
    /// The view the window opened with (the R key goes back to it).
    start_camera: Camera,
    /// The preset's output name (a saved view is `NAME_view_N.png`).
    name: String,
    baked_stack: Stack,
    baked_bands: usize,
    initial_maps: Option<(MaterialMaps, LayerOptics)>,
    lut: Option<Lut>,
    gfx: Option<Gfx>,
    error: Option<Error>,
    egui: egui::Context,
    drag: Option<(f64, f64)>,
    cursor: (f64, f64),
    last_frame: Option<Instant>,
    frame_ms: Vec<f64>,
    frames_done: u32,
    lut_jobs: Sender<(Stack, usize)>,
    lut_results: Receiver<(Stack, usize, Lut)>,
    map_worker: reload::MapWorker,
    status: String,
    /// Frames are drawn one after another until then (`DRAWN_ON_AFTER_A_CHANGE`).
    drawing_until: Option<Instant>,
    /// When egui asked for its next frame (an animation, a tooltip's delay).
    egui_repaint_at: Option<Instant>,
    /// The window is wholly covered or iconified, as the window system says: not drawn.
    occluded: bool,
    /// The window was destroyed from outside (not closed through the window manager):
    /// nothing may ask it anything (winit's size query panicked, "BadDrawable": a sweep).
    destroyed: bool,
}

/// Opens the window and runs until it is closed (or `frames` frames were drawn).
pub fn run(options: WindowOptions) -> Result<WindowReport, Error> {
    // Watched before it is read: a save while the first maps were made (seconds) was never
    // reloaded (a window sweep: saved 0.7 s after the start, shown stale for good).
    let watch = reload::watch_preset(&options.preset);
    let loaded = crate::preset::load(&options.preset, &options.overrides, options.seed)?;
    let sliders = Sliders::from_preset(&loaded.preset);
    let mut cache = NodeCache::new();
    // The snakes' triangles too: `--snakes`, or as many as the panel's slider draws.
    let snakes = options.settings.snakes.max(panel::SNAKES_SLIDER_MAX);
    let frame_bytes = super::engine::renderer::window_frame_bytes(options.size.0, options.size.1)
        + super::engine::prepare::more_snakes_bytes(&loaded, options.layout, snakes);
    // The memory, then the window system, then the work: without a display the maps
    // (seconds, and 5 GB at --map-size 4096) were built and thrown away (a hostile-input
    // review).
    super::engine::prepare::check_window_memory(&loaded, options.map_size, options.layout, frame_bytes)?;
    let event_loop = EventLoop::new().map_err(|e| {
        Error::Gpu(GpuError::Window(format!(
            "cannot open a window: {} (no display? run under `xvfb-run -a`, or use --out)",
            without_source_location(&e.to_string())
        )))
    })?;
    let (maps, _) = material_maps_cached(&loaded, options.map_size, options.layout, &mut cache, frame_bytes)?;
    let optics = LayerOptics::from_preset(&loaded.preset);
    let lut = Lut::bake_default(optics.stack);

    let (lut_jobs, lut_results) = reload::spawn_lut_worker();
    let status = match &watch {
        Ok(_) => "watching the preset file".to_string(),
        Err(why) => format!("not reloaded: {why}"),
    };
    let map_worker = reload::spawn_map_worker(&options, cache, watch);

    event_loop.set_control_flow(ControlFlow::Poll);
    let mut app = App {
        settings: options.settings,
        file_sliders: sliders,
        start_camera: options.settings.camera,
        name: loaded.name.clone(),
        baked_stack: optics.stack,
        baked_bands: bands_for(options.settings.method),
        sliders,
        initial_maps: Some((maps, optics)),
        lut: Some(lut),
        gfx: None,
        error: None,
        egui: egui::Context::default(),
        drag: None,
        cursor: (0.0, 0.0),
        last_frame: None,
        frame_ms: Vec::new(),
        frames_done: 0,
        lut_jobs,
        lut_results,
        status,
        map_worker,
        options,
        drawing_until: None,
        egui_repaint_at: None,
        occluded: false,
        destroyed: false,
    };
    event_loop.run_app(&mut app).map_err(|e| Error::Gpu(GpuError::Window(format!("window event loop failed: {e}"))))?;
    if let Some(error) = app.error {
        return Err(error);
    }
    // The first frames include pipeline compilation; report the steady state when possible.
    let steady: Vec<f64> = if app.frame_ms.len() > 4 { app.frame_ms[2..].to_vec() } else { app.frame_ms.clone() };
    let mean = if steady.is_empty() { f64::NAN } else { steady.iter().sum::<f64>() / steady.len() as f64 };
    let adapter = app.gfx.as_ref().map(|g| g.renderer.gpu.describe()).unwrap_or_default();
    Ok(WindowReport { frames: app.frames_done, mean_frame_ms: mean, adapter })
}

impl App {
    fn init(&mut self, event_loop: &ActiveEventLoop) -> Result<(), Error> {
        let (w, h) = self.options.size;
        let attributes = Window::default_attributes()
            .with_title(format!("snakeskin — {}", self.options.preset))
            .with_inner_size(winit::dpi::PhysicalSize::new(w, h));
        let window = Arc::new(
            event_loop
                .create_window(attributes)
                .map_err(|e| Error::Gpu(GpuError::Window(format!("cannot open a window: {e}"))))?,
        );
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_with_display_handle_from_env(Box::new(
            event_loop.owned_display_handle(),
        )));
        let surface = instance
            .create_surface(window.clone())
            .map_err(|e| Error::Gpu(GpuError::Window(format!("cannot draw into the window: {e}"))))?;
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            compatible_surface: Some(&surface),
            ..Default::default()
        }))
        .map_err(|e| Error::Gpu(GpuError::NoAdapter(e.to_string())))?;
        let gpu = Gpu::open(&adapter)?;
        let caps = surface.get_capabilities(&adapter);
        // The tone mapper writes linear values and relies on an sRGB target to encode them:
        // a surface that offers none would show the picture darker than it is.
        let (Some(format), Some(&alpha_mode)) =
            (caps.formats.iter().copied().find(|f| f.is_srgb()), caps.alpha_modes.first())
        else {
            return Err(Error::Gpu(GpuError::Window(format!(
                "the window's surface on {} offers no sRGB format (it offers {:?}), which the preview's tone mapping \
                 writes to; use the headless preview (preview --out FILE.png)",
                adapter.get_info().name,
                caps.formats
            ))));
        };
        let size = window.inner_size();
        let config = wgpu::SurfaceConfiguration {
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            format,
            color_space: wgpu::SurfaceColorSpace::Auto,
            width: size.width.max(1),
            height: size.height.max(1),
            present_mode: wgpu::PresentMode::AutoNoVsync,
            desired_maximum_frame_latency: WINDOW_FRAME_LATENCY,
            alpha_mode,
            view_formats: vec![],
        };
        surface.configure(&gpu.device, &config);
        let max_texture_side = gpu.device.limits().max_texture_dimension_2d as usize;
        let egui_renderer = egui_wgpu::Renderer::new(&gpu.device, format, egui_wgpu::RendererOptions::default());
        let egui_state = egui_winit::State::new(
            self.egui.clone(),
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            None,
            Some(max_texture_side),
        );
        let renderer = Renderer::new(gpu);
        let (maps, optics) = self.initial_maps.take().expect("initial maps");
        let lut = self.lut.take().expect("initial LUT");
        let material = renderer.material(&maps, optics, &lut, self.baked_bands)?;
        let targets = renderer.targets(config.width, config.height, self.settings.samples);
        self.gfx = Some(Gfx {
            window,
            surface,
            config,
            renderer,
            targets,
            material,
            egui_state,
            egui_renderer,
            not_drawn: None,
        });
        Ok(())
    }

    /// Remakes the surface and the frame's targets for the window's new size, or stops
    /// drawing while it cannot be drawn: minimised (wgpu asks that a surface of no pixels
    /// not be configured; 1×1 frames were drawn as fast as the loop ran), wider or taller
    /// than the GPU's largest texture (wgpu panicked in `Surface::configure`: 16400×64 on
    /// lavapipe, a window sweep), with frames larger than the memory available (an
    /// 8192×4096 window took 2.2 GB, unchecked: only `--size` was), or with frames the
    /// driver will not make (at 9000×9000 the 4× multisampled target alone is one 2.6 GB
    /// allocation, over lavapipe's largest: wgpu panicked "Out of Memory", a review). Said
    /// once on stderr; drawn again, and said so, when the window is made smaller.
    fn resize(&mut self, width: u32, height: u32) {
        let samples = self.settings.samples;
        let Some(gfx) = self.gfx.as_mut() else { return };
        let limit = gfx.renderer.gpu.device.limits().max_texture_dimension_2d;
        let mut not_drawn = if width == 0 || height == 0 {
            Some(NotDrawn::Minimised)
        } else if width > limit || height > limit {
            Some(NotDrawn::TooLarge(format!(
                "the window is {width}×{height}; the GPU draws at most {limit} pixels a side"
            )))
        } else {
            // Its frames beside the old ones: a remake holds both for a moment.
            let bytes = super::engine::renderer::window_frame_bytes(width, height);
            let check = crate::memory::MemoryCheck::against_available(bytes);
            check.refuse_if_over(&format!("a {width}×{height} window")).err().map(|e| NotDrawn::TooLarge(e.to_string()))
        };
        // X11 reports the first size even when it is the one configured: nothing to remake
        // then (a remake holds the old targets beside the new for a moment).
        if not_drawn.is_none() && (width, height) != (gfx.config.width, gfx.config.height) {
            let config = wgpu::SurfaceConfiguration { width, height, ..gfx.config.clone() };
            let made = gfx.renderer.gpu.checked(&format!("making a {width}×{height} window's frames"), || {
                gfx.surface.configure(&gfx.renderer.gpu.device, &config);
                Ok(gfx.renderer.targets(width, height, samples))
            });
            match made {
                Ok(targets) => (gfx.config, gfx.targets) = (config, targets),
                Err(error) => {
                    // The surface may be left at the refused size: no size a frame can use
                    // is recorded, so the next one that fits configures it again.
                    gfx.config.width = 0;
                    not_drawn = Some(NotDrawn::TooLarge(error.to_string()));
                }
            }
        }
        // Once as it stops (not at every step of a drag). On stderr only: the panel is
        // not drawn meanwhile, and keeps its own line (what the file watch is doing).
        let was_too_large = matches!(gfx.not_drawn, Some(NotDrawn::TooLarge(_)));
        match &not_drawn {
            Some(NotDrawn::TooLarge(why)) if !was_too_large => {
                (self.options.report)(&format!("not drawn until the window is made smaller: {why}"))
            }
            None if was_too_large => (self.options.report)(&format!("drawn again at {width}×{height}")),
            _ => {}
        }
        if not_drawn.is_some() {
            // The time not drawn is no frame's.
            self.last_frame = None;
        }
        gfx.not_drawn = not_drawn;
    }

    /// Swaps in finished background work and pushes slider changes to the GPU; true where
    /// some work had finished (the window has something new to show).
    fn apply_updates(&mut self) -> bool {
        let Some(gfx) = self.gfx.as_mut() else { return false };
        let mut arrived = false;
        while let Ok(result) = self.map_worker.reloads.try_recv() {
            arrived = true;
            // A reload fails in the generator or in the upload alike: the last good maps stay.
            let uploaded = result.map_err(|e| e.to_string()).and_then(|reloaded| {
                gfx.renderer.retexture(&mut gfx.material, &reloaded.maps).map(|()| reloaded).map_err(|e| e.to_string())
            });
            match uploaded {
                Ok(reloaded) => {
                    for warning in &reloaded.warnings {
                        (self.options.report)(warning);
                    }
                    let warned = match reloaded.warnings.len() {
                        0 => String::new(),
                        1 => format!("; {}", reloaded.warnings[0]),
                        n => format!("; {n} warnings (on the terminal)"),
                    };
                    // An edit of a key `--set` gives changed nothing, without a word (a window
                    // sweep): the keys it holds are named at every reload.
                    let mut held: Vec<&str> = self.options.overrides.iter().map(|(key, _)| key.as_str()).collect();
                    held.sort();
                    held.dedup();
                    let held = if held.is_empty() {
                        String::new()
                    } else {
                        format!("; --set holds {} over the file", held.join(", "))
                    };
                    self.status = format!(
                        "reloaded in {:.0} ms: {} nodes re-evaluated, {} reused{warned}{held}",
                        reloaded.took.as_secs_f64() * 1e3,
                        reloaded.stats.evaluated,
                        reloaded.stats.reused
                    );
                    // The file is the source of truth for the optics too.
                    self.sliders = reloaded.sliders;
                    self.file_sliders = reloaded.sliders;
                }
                Err(error) => self.status = format!("reload failed, keeping the last good maps: {error}"),
            }
            // Also to the caller: the window may be behind others, and tests read it.
            (self.options.report)(&self.status);
        }
        while let Ok((stack, bands, lut)) = self.lut_results.try_recv() {
            arrived = true;
            let optics = LayerOptics { stack, ..gfx.material.optics };
            if let Err(error) = gfx.renderer.refilm(&mut gfx.material, optics, &lut, bands) {
                self.status = format!("the film tables were not uploaded, keeping the last: {error}");
                (self.options.report)(&self.status);
                continue;
            }
            self.baked_stack = stack;
            self.baked_bands = bands;
        }
        let wanted = self.sliders.optics();
        let wanted_bands = bands_for(self.settings.method);
        if wanted.stack != self.baked_stack || wanted_bands != self.baked_bands {
            // Ask once per change; the worker keeps only the newest request.
            let _ = self.lut_jobs.send((wanted.stack, wanted_bands));
            self.baked_stack = wanted.stack;
            self.baked_bands = wanted_bands;
        }
        // Uniform-only parameters apply immediately; indices wait for their LUT.
        gfx.material.optics = LayerOptics { stack: gfx.material.optics.stack, ..wanted };
        arrived
    }

    /// Saves the view (the frame without the panel, at the window's size, as the headless
    /// preview renders it) as `NAME_view_N.png` in `--shots`, and says where, with the
    /// `--set` arguments that carry the sliders' optics where they differ from the file.
    fn save_view(&mut self) {
        let Some(gfx) = &self.gfx else { return };
        let (width, height) = (gfx.config.width, gfx.config.height);
        let saved = match &gfx.not_drawn {
            Some(_) => Err("the window is not drawn at its size".to_string()),
            None => {
                // Its own frame's targets and read-back beside the window's.
                let bytes = super::engine::renderer::frame_bytes(width, height);
                crate::memory::MemoryCheck::against_available(bytes)
                    .refuse_if_over(&format!("a {width}×{height} view"))
                    .and_then(|()| Ok(gfx.renderer.render_image(&self.settings, &gfx.material, width, height)?))
                    .and_then(|image| super::figures::rendered_png_bytes(&image))
                    .and_then(|png| {
                        let stem = format!("{}_view", self.name);
                        Ok(crate::export::write_new_numbered_file(&self.options.shots, &stem, "png", &png)?)
                    })
                    .map_err(|e| e.to_string())
            }
        };
        self.status = match saved {
            Ok(path) => {
                let set = self.sliders.set_arguments(&self.file_sliders);
                let set = if set.is_empty() {
                    String::new()
                } else {
                    format!("; the sliders differ from the preset: {}", set.join(" "))
                };
                format!("saved the view as {} ({width}×{height}){set}", path.display())
            }
            Err(why) => format!("the view was not saved: {why}"),
        };
        (self.options.report)(&self.status);
    }

    /// Something changed: frames are drawn until `DRAWN_ON_AFTER_A_CHANGE` from now.
    fn wake(&mut self) {
        self.drawing_until = Some(Instant::now() + DRAWN_ON_AFTER_A_CHANGE);
    }

    /// Whether frames are left undrawn now: the window destroyed, too large or minimised
    /// (`resize`), or covered (not for `--frames`, which draws its frames whatever: a covered
    /// window's count stalled, a review).
    fn undrawn(&self) -> bool {
        self.destroyed
            || (self.occluded && self.options.frames.is_none())
            || self.gfx.as_ref().is_some_and(|gfx| gfx.not_drawn.is_some())
    }

    fn draw(&mut self, event_loop: &ActiveEventLoop) {
        if self.undrawn() {
            return;
        }
        self.apply_updates();
        let now = Instant::now();
        if let Some(last) = self.last_frame {
            self.frame_ms.push((now - last).as_secs_f64() * 1e3);
        }
        self.last_frame = Some(now);
        let mean_ms = {
            let recent = &self.frame_ms[self.frame_ms.len().saturating_sub(60)..];
            if recent.is_empty() { 0.0 } else { recent.iter().sum::<f64>() / recent.len() as f64 }
        };
        let Some(gfx) = self.gfx.as_mut() else { return };
        let raw = gfx.egui_state.take_egui_input(&gfx.window);
        let (settings, sliders, status) = (&mut self.settings, &mut self.sliders, &self.status);
        let full = self.egui.run_ui(raw, |ui| controls(ui, settings, sliders, status, mean_ms));
        // egui's next frame, if it asked for one (zero: at once; never: `Duration::MAX`).
        let egui_delay = full.viewport_output.get(&egui::ViewportId::ROOT).map(|v| v.repaint_delay);
        self.egui_repaint_at = egui_delay.and_then(|delay| now.checked_add(delay));
        gfx.egui_state.handle_platform_output(&gfx.window, full.platform_output);
        let jobs = self.egui.tessellate(full.shapes, full.pixels_per_point);
        let device = &gfx.renderer.gpu.device;
        let queue = &gfx.renderer.gpu.queue;
        let mut textures = full.textures_delta;
        for (id, deltas) in &textures.set {
            for delta in deltas {
                gfx.egui_renderer.update_texture(device, queue, *id, delta);
            }
        }
        // Freed textures are released after this frame's painting; on an early return they
        // are released now (egui never paints them again).
        let freed = std::mem::take(&mut textures.free);
        textures.clear();
        let frame = match gfx.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(frame) | wgpu::CurrentSurfaceTexture::Suboptimal(frame) => frame,
            other => {
                for id in &freed {
                    gfx.egui_renderer.free_texture(id);
                }
                if !matches!(other, wgpu::CurrentSurfaceTexture::Timeout | wgpu::CurrentSurfaceTexture::Occluded) {
                    gfx.surface.configure(device, &gfx.config);
                }
                return;
            }
        };
        let view = frame.texture.create_view(&wgpu::TextureViewDescriptor::default());
        let mut encoder = device.create_command_encoder(&Default::default());
        gfx.renderer.encode_frame(
            &mut encoder,
            &gfx.targets,
            &self.settings,
            &gfx.material,
            FrameOutput { view: &view, format: gfx.config.format },
            None,
        );
        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [gfx.config.width, gfx.config.height],
            pixels_per_point: full.pixels_per_point,
        };
        let extra = gfx.egui_renderer.update_buffers(device, queue, &mut encoder, &jobs, &screen);
        {
            let pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("egui"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            gfx.egui_renderer.render(&mut pass.forget_lifetime(), &jobs, &screen);
        }
        queue.submit(extra.into_iter().chain([encoder.finish()]));
        gfx.window.pre_present_notify();
        queue.present(frame);
        for id in &freed {
            gfx.egui_renderer.free_texture(id);
        }
        self.frames_done += 1;
        if self.frames_done == 1 {
            (self.options.report)("first frame presented");
        }
        if self.options.frames.is_some_and(|n| self.frames_done >= n) {
            // Wait for the last frame so the reported times cover finished work.
            let _ = device.poll(wgpu::PollType::wait_indefinitely());
            event_loop.exit();
        }
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.gfx.is_none() {
            match self.init(event_loop) {
                Ok(()) => self.wake(),
                Err(error) => {
                    self.error = Some(error);
                    event_loop.exit();
                }
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        if self.destroyed {
            return;
        }
        if matches!(event, WindowEvent::Destroyed) {
            self.destroyed = true;
            event_loop.exit();
            return;
        }
        let Some(gfx) = self.gfx.as_mut() else { return };
        let response = gfx.egui_state.on_window_event(&gfx.window, &event);
        let consumed = response.consumed;
        // Input, a resize, the window shown again: drawn until a while after (the drag and
        // the wheel below change the camera; egui says what changes its panel, and asks a
        // repaint of every redraw too, which would draw without end).
        let changes = (response.repaint && !matches!(event, WindowEvent::RedrawRequested))
            || matches!(
                event,
                WindowEvent::Resized(_)
                    | WindowEvent::MouseInput { .. }
                    | WindowEvent::CursorMoved { .. }
                    | WindowEvent::MouseWheel { .. }
                    | WindowEvent::KeyboardInput { .. }
                    | WindowEvent::Occluded(false)
                    | WindowEvent::ScaleFactorChanged { .. }
            );
        if changes {
            self.wake();
        }
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => self.resize(size.width, size.height),
            WindowEvent::Occluded(occluded) => {
                self.occluded = occluded;
                // The time covered is no frame's.
                self.last_frame = None;
            }
            WindowEvent::RedrawRequested => self.draw(event_loop),
            WindowEvent::MouseInput { state, button: MouseButton::Left, .. } => {
                self.drag = (state == ElementState::Pressed && !consumed).then_some(self.cursor);
            }
            WindowEvent::CursorMoved { position, .. } => {
                self.cursor = (position.x, position.y);
                if let Some((x, y)) = self.drag {
                    let camera = &mut self.settings.camera;
                    camera.yaw_deg -= (position.x - x) as f32 * 0.3;
                    camera.pitch_deg = (camera.pitch_deg + (position.y - y) as f32 * 0.3).clamp(-5.0, 89.0);
                    self.drag = Some(self.cursor);
                }
            }
            // Keys the panel does not take (a slider's value being typed takes them).
            WindowEvent::KeyboardInput { event, .. }
                if !consumed && event.state == ElementState::Pressed && !event.repeat =>
            {
                match event.logical_key.as_ref() {
                    Key::Character(c) if c.eq_ignore_ascii_case("s") => self.save_view(),
                    Key::Character(c) if c.eq_ignore_ascii_case("r") => self.settings.camera = self.start_camera,
                    _ => {}
                }
            }
            WindowEvent::MouseWheel { delta, .. } if !consumed => {
                let lines = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
                };
                let camera = &mut self.settings.camera;
                camera.distance = (camera.distance * 0.9f32.powf(lines)).clamp(0.15, 20.0);
            }
            _ => {}
        }
    }

    /// Draws frame after frame while something changes (`wake`), for `--frames`, and where
    /// egui asks; otherwise waits for the next event, looking at the background workers every
    /// `IDLE_LOOK_INTERVAL`. A window not drawn (minimised, too large, covered) only looks at
    /// the workers, whose reloads it still applies and reports (the window may be behind
    /// others: a covered window said nothing of a save until it was shown, a review).
    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        if self.gfx.is_none() || self.destroyed {
            return;
        }
        if self.apply_updates() {
            self.wake();
        }
        let now = Instant::now();
        if self.undrawn() {
            self.last_frame = None;
            event_loop.set_control_flow(ControlFlow::WaitUntil(now + IDLE_LOOK_INTERVAL));
            return;
        }
        let egui_due = self.egui_repaint_at.is_some_and(|at| at <= now);
        let drawing = self.options.frames.is_some() || self.drawing_until.is_some_and(|until| now < until);
        let Some(gfx) = &self.gfx else { return };
        if drawing || egui_due {
            event_loop.set_control_flow(ControlFlow::Poll);
            gfx.window.request_redraw();
        } else {
            // The time idle is no frame's.
            self.last_frame = None;
            let look = now + IDLE_LOOK_INTERVAL;
            let until = self.egui_repaint_at.map_or(look, |at| at.min(look));
            event_loop.set_control_flow(ControlFlow::WaitUntil(until));
        }
    }
}

/// winit's error without the source location it opens with ("os error at /root/.cargo/
/// registry/src/.../winit-0.30.13/src/platform_impl/linux/mod.rs:765: neither WAYLAND_DISPLAY
/// nor ..."): a path of the machine that built the binary, of no use to its user.
fn without_source_location(message: &str) -> &str {
    message.strip_prefix("os error at ").and_then(|rest| rest.split_once(": ")).map_or(message, |(_, words)| words)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// winit's location goes; a message without one is kept whole (the negative control).
    #[test]
    fn a_window_error_loses_the_build_machine_path() {
        let said = "os error at /root/.cargo/registry/src/index.crates.io-1949cf8c6b5b557f/winit-0.30.13/src/\
                    platform_impl/linux/mod.rs:765: neither WAYLAND_DISPLAY nor WAYLAND_SOCKET nor DISPLAY is set.";
        assert_eq!(without_source_location(said), "neither WAYLAND_DISPLAY nor WAYLAND_SOCKET nor DISPLAY is set.");
        assert_eq!(without_source_location("the event loop can't be re-created"), "the event loop can't be re-created");
    }
}
