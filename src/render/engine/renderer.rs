//! The frame: the snake (instanced), optionally the ground, shaded into a 4× MSAA HDR target,
//! resolved, tone mapped into any 8-bit sRGB view (an offscreen texture or the window's
//! surface). Pipelines are specialised with WGSL override constants — layer stage, map view,
//! film method (or none for an inert film), absorption on/off — and built once per
//! combination on first use, so a material pays only for the layers it has.

use std::collections::HashMap;
use std::sync::Mutex;

use wgpu::util::DeviceExt;

use super::film::{self, FilmBinding, GpuFilmMethod};
use super::gpu::{Gpu, GpuError};
use super::gpu::{map_read_with, texture_entry, uniform_entry};
use super::material::{self, MaterialMaps, MaterialTextures};
use super::mesh::{BodyShape, Mesh, Vertex};
use super::scene::{BounceGrid, Camera, LayerOptics, Lighting, SceneUniform, Stage, View};
use super::shaders::program;
use crate::optics::brdf::Model;
use crate::optics::lut::Lut;

pub const HDR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
pub const OUTPUT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;
const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
const GBUFFER_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
pub const MSAA_SAMPLES: u32 = 4;

/// Bytes a pixel of the render targets (`Targets`): the multisampled HDR target and depth
/// (`MSAA_SAMPLES` texels of 8 and 4 bytes) and the resolved HDR target (8).
const TARGET_BYTES_PER_PIXEL: u64 = MSAA_SAMPLES as u64 * (8 + 4) + 8;

/// Bytes a headless frame of `width`×`height` holds at once, for the memory check before it
/// is rendered: the render targets (`TARGET_BYTES_PER_PIXEL`), the 8-bit output, its readback
/// and the image read back (4 each), and the RGB image and PNG bytes written from it (at
/// most 3 each). wgpu frees the targets at its next poll, so they are still there while the
/// image is written. On a software adapter (lavapipe) all of it is host memory: a 4096×2048
/// preview with 64² maps peaked 72.6 bytes a pixel above a 16×16 one's.
pub fn frame_bytes(width: u32, height: u32) -> u64 {
    let per_pixel = TARGET_BYTES_PER_PIXEL + 3 * 4 + 2 * 3;
    width as u64 * height as u64 * per_pixel
}

/// Bytes a software rasteriser (lavapipe) holds for each triangle it draws in a frame: it
/// bins every triangle with its vertices' outputs before it shades. Each snake of `--snakes`
/// draws the whole body mesh again: 400 tile-layout snakes (61,440 triangles each) at
/// 320×200 peaked at 2.5 GB where one peaked at 0.19 GB, and the check counted one. From
/// `preview erythrolamprus-miliaris --map-size 64 --snakes N` (peak resident, `time -f
/// %M`): 5.4–6.0 MB a further tile snake (1 to 100 snakes, 320×200 and 1280×800: 88–98
/// bytes a triangle), 4.7 MB at 200; a body atlas' snake (153,600 triangles) 11.4 MB at
/// 50 snakes, 6.8 at 200 (74 and 44 bytes a triangle): fewer pixels a snake as the grid
/// grows. 100 bytes a triangle bounds them all.
pub const BINNED_BYTES_PER_TRIANGLE: u64 = 100;

/// Bytes `snakes` snakes of `triangles` each add to a frame's over one snake's (counted in
/// the renderer's own overhead): `BINNED_BYTES_PER_TRIANGLE` each.
pub fn more_snakes_bytes(triangles: u64, snakes: u32) -> u64 {
    u64::from(snakes.saturating_sub(1)) * triangles * BINNED_BYTES_PER_TRIANGLE
}

/// Frames a window's swap chain may queue ahead of the one shown (its
/// `SurfaceConfiguration::desired_maximum_frame_latency`).
pub const WINDOW_FRAME_LATENCY: u32 = 2;

/// The most 8-bit images a window's swap chain holds: wgpu asks for one more than
/// `WINDOW_FRAME_LATENCY` (wgpu-hal 30's Vulkan swap chain), raised to the surface's least
/// image count, which Mesa's window systems put at 3, 4 or 5 on X11 (by present mode; 5
/// under Xwayland) and 2 or 4 on Wayland.
const SWAP_CHAIN_IMAGES_AT_MOST: u64 = 5;

/// Bytes a window of `width`×`height` holds for its frames: the render targets
/// (`TARGET_BYTES_PER_PIXEL`) and the swap chain's images (at most
/// `SWAP_CHAIN_IMAGES_AT_MOST` of 4 bytes); a window has no readback or PNG. 76 bytes a
/// pixel: a 4096×2048 window (lavapipe under Xvfb, whose swap chain has 3 images; 64² maps,
/// five frames) peaked 60.7 bytes a pixel above a 16×16 one's. For the window's size when it
/// opens (`--size`), and again at each resize (`window::App::resize`).
pub fn window_frame_bytes(width: u32, height: u32) -> u64 {
    let per_pixel = TARGET_BYTES_PER_PIXEL + SWAP_CHAIN_IMAGES_AT_MOST * 4;
    width as u64 * height as u64 * per_pixel
}

/// Host memory a renderer holds beyond the process's fixed overhead
/// (`memory::FIXED_OVERHEAD_BYTES`), whatever it draws: the device, its pipelines and their
/// compiled shaders, a body's mesh. Measured on lavapipe (Mesa 22.3.6, two cores) with 64²
/// maps and 16² frames, peak resident: `preview` 189 MiB, `figures` 235 MiB, `sheet --tile
/// 64 --layout body --closeups --species natrix-natrix` 247 MiB, 183 MiB above the fixed
/// overhead. On a busy machine (the test suite running beside it) peaks were up to 90 MiB
/// higher than alone (a 2048×1024 preview of 256² maps: 397 MiB, 324 alone; the allocator
/// makes more arenas when its threads contend): 256 MiB. A GPU driver's own allocations are
/// of the same order.
pub const RENDERER_OVERHEAD_BYTES: u64 = 256 << 20;

/// Bytes the CPU reference check adds to a frame (`render_gbuffer`): two passes of two
/// 16-byte targets, each read back into a buffer and copied into a vector.
pub fn gbuffer_bytes(width: u32, height: u32) -> u64 {
    width as u64 * height as u64 * 4 * 16 * 3
}
/// A readback row's bytes: a texture's row padded to the copy alignment wgpu requires.
fn padded_row_bytes(width: u32, texel_bytes: u32) -> u32 {
    (width * texel_bytes).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
}

/// `tonemap.wgsl`'s modes: the PBR Neutral curve, or none (the map viewer shows values).
pub const TONE_MAP_CURVE: u32 = 0;
pub const TONE_MAP_NONE: u32 = 1;
/// `skin.wgsl`'s `GBUFFER_PART`s: (position, thickness) + (normal, roughness), then
/// (albedo, thickness spread) + (geometric normal, height).
pub const GBUFFER_POSITION_NORMAL: u32 = 0;
pub const GBUFFER_ALBEDO_GEOMETRY: u32 = 1;

/// Where a frame's tone-mapped result goes: any 8-bit sRGB view.
#[derive(Clone, Copy)]
pub struct FrameOutput<'a> {
    pub view: &'a wgpu::TextureView,
    pub format: wgpu::TextureFormat,
}

/// Everything about a frame that is not the material.
#[derive(Debug, Clone, Copy)]
pub struct FrameSettings {
    pub view: View,
    pub method: GpuFilmMethod,
    /// The layer model the skin is shaded with (`brdf.wgsl`'s `BRDF_MODEL`).
    pub model: Model,
    pub camera: Camera,
    pub lighting: Lighting,
    pub exposure: f32,
    pub ground: bool,
    /// Number of snakes (instanced, in a grid).
    pub snakes: u32,
    /// 4 for the preview (MSAA), 1 where pixels must match the G-buffer exactly.
    pub samples: u32,
    /// The plain PBR shader instead of the skin (the benchmark's baseline).
    pub plain: bool,
    pub background: [f64; 3],
    /// How a pixel whose footprint covers several film thicknesses is shaded (`skin.wgsl`'s
    /// `FOOTPRINT_SPREAD`).
    pub footprint: FilmFootprint,
}

/// How the skin shader reads the film where a pixel's footprint covers scales of several
/// thicknesses (a distant snake, whose mip texels average many scales).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum FilmFootprint {
    /// Every film read (the film colour, the top's coupling) the mean of two reads at
    /// thicknesses either side of the footprint's mean, placed from its spread (the
    /// thickness texture's two moments; `material::footprint_offset_nm`): the film colour
    /// averaged over the footprint.
    #[default]
    Spread,
    /// Every film read once, at the footprint's mean thickness (the shading before the
    /// spread was read; 16 % less frame time on lavapipe, `bench render`'s
    /// `skin-mean-thickness`), but a distant film far more saturated than the scales it
    /// averages (BENCHMARKS.md, "Iridescence seen from afar").
    Mean,
}

impl Default for FrameSettings {
    fn default() -> Self {
        FrameSettings {
            view: View::Shaded(Stage::All),
            method: GpuFilmMethod::Lut,
            model: Model::default(),
            camera: Camera::default(),
            lighting: Lighting::default(),
            exposure: 1.0,
            ground: true,
            snakes: 1,
            samples: MSAA_SAMPLES,
            plain: false,
            background: [0.05, 0.055, 0.06],
            footprint: FilmFootprint::default(),
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum Program {
    Skin,
    Plain,
    Ground,
    GBuffer(u32),
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
struct PipelineKey {
    program: Program,
    stage: u32,
    view_map: u32,
    method: u32,
    model: u32,
    absorption: bool,
    footprint: FilmFootprint,
    samples: u32,
}

/// The material currently shown: optics, film tables and map textures.
pub struct Material {
    pub optics: LayerOptics,
    film: FilmBinding,
    textures: MaterialTextures,
    /// The body this material is drawn on, when it is not the tile's (a body atlas).
    mesh: Option<GpuMesh>,
}

/// Render targets for one size and sample count.
pub struct Targets {
    pub width: u32,
    pub height: u32,
    samples: u32,
    msaa: Option<wgpu::TextureView>,
    depth: wgpu::TextureView,
    resolve: wgpu::TextureView,
    tonemap_group: wgpu::BindGroup,
    tonemap_uniform: wgpu::Buffer,
}

pub struct Renderer {
    pub gpu: Gpu,
    film_layout: wgpu::BindGroupLayout,
    material_layout: wgpu::BindGroupLayout,
    tonemap_layout: wgpu::BindGroupLayout,
    pipeline_layout: wgpu::PipelineLayout,
    skin_module: wgpu::ShaderModule,
    plain_module: wgpu::ShaderModule,
    tonemap_module: wgpu::ShaderModule,
    pipelines: Mutex<HashMap<PipelineKey, wgpu::RenderPipeline>>,
    tonemap_pipelines: Mutex<HashMap<wgpu::TextureFormat, wgpu::RenderPipeline>>,
    scene_buffer: wgpu::Buffer,
    scene_group: wgpu::BindGroup,
    body: GpuMesh,
    ground: GpuMesh,
    instances: Mutex<(u32, wgpu::Buffer)>,
    /// The last material's K and E (`LayerOptics::bounce_grid`), kept while its optics and
    /// model stay the same: every frame writes them to the scene uniform, and rebuilding
    /// them is eight tables of film-from-below integrals.
    bounce: Mutex<Option<(LayerOptics, Model, std::sync::Arc<BounceGrid>)>>,
}

struct GpuMesh {
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    count: u32,
}

impl GpuMesh {
    fn new(device: &wgpu::Device, mesh: &Mesh) -> GpuMesh {
        GpuMesh {
            vertices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("vertices"),
                contents: bytemuck::cast_slice(&mesh.vertices),
                usage: wgpu::BufferUsages::VERTEX,
            }),
            indices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("indices"),
                contents: bytemuck::cast_slice(&mesh.indices),
                usage: wgpu::BufferUsages::INDEX,
            }),
            count: mesh.indices.len() as u32,
        }
    }
}

/// Placements (x, z, yaw) of `n` snakes in a grid, the first at the origin.
pub fn snake_grid(n: u32) -> Vec<[f32; 4]> {
    let (columns, spacing_x, spacing_z) = grid_layout(n);
    (0..n)
        .map(|i| {
            let (col, row) = ((i % columns) as f32, (i / columns) as f32);
            [col * spacing_x, -row * spacing_z, 0.0, 0.0]
        })
        .collect()
}

/// The ground reaches this far either side of its centre (scene units; a body is 2.4 long).
const GROUND_HALF_SIZE: f32 = 30.0;

/// The instances a frame draws: `snake_grid(n)`, then the ground's placement at the grid's
/// centre. At the origin, the ground left the far columns of a grid of more than about 100
/// snakes over the bare background.
fn placements(n: u32) -> Vec<[f32; 4]> {
    let (x, z) = grid_centre(n);
    snake_grid(n).into_iter().chain(std::iter::once([x, z, 0.0, 0.0])).collect()
}

/// The centre (x, z) of the grid of `n` snakes' placements (`snake_grid`): where the ground
/// lies and the camera of a many-snake frame looks.
pub fn grid_centre(n: u32) -> (f32, f32) {
    let (columns, spacing_x, spacing_z) = grid_layout(n);
    let rows = n.div_ceil(columns);
    ((columns - 1) as f32 * spacing_x * 0.5, -((rows - 1) as f32) * spacing_z * 0.5)
}

/// Columns of the snake grid and the spacing along x and z (a body is 2.4 long and
/// ±0.35 wide, see `BodyShape`).
pub fn grid_layout(n: u32) -> (u32, f32, f32) {
    ((n as f32).sqrt().ceil().max(1.0) as u32, 2.8, 1.1)
}

impl Renderer {
    pub fn new(gpu: Gpu) -> Renderer {
        let device = &gpu.device;
        let film_layout = film::bind_group_layout(device);
        let material_layout = material::bind_group_layout(device);
        let scene_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("scene"),
            entries: &[uniform_entry(0, wgpu::ShaderStages::VERTEX_FRAGMENT)],
        });
        let tonemap_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("tonemap"),
            entries: &[
                texture_entry(0, wgpu::ShaderStages::FRAGMENT, false),
                uniform_entry(1, wgpu::ShaderStages::FRAGMENT),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("scene"),
            bind_group_layouts: &[Some(&film_layout), Some(&scene_layout), Some(&material_layout)],
            immediate_size: 0,
        });
        let module = |name: &str| {
            device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(name),
                source: wgpu::ShaderSource::Wgsl(program(name).into()),
            })
        };
        let scene_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("scene"),
            size: std::mem::size_of::<SceneUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let scene_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("scene"),
            layout: &scene_layout,
            entries: &[wgpu::BindGroupEntry { binding: 0, resource: scene_buffer.as_entire_binding() }],
        });
        let body = GpuMesh::new(device, &BodyShape::default().mesh());
        let ground = GpuMesh::new(device, &Mesh::ground(GROUND_HALF_SIZE));
        let instance_buffer = |placements: &[[f32; 4]]| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("instances"),
                contents: bytemuck::cast_slice(placements),
                usage: wgpu::BufferUsages::VERTEX,
            })
        };
        let instances = Mutex::new((1, instance_buffer(&placements(1))));
        Renderer {
            skin_module: module("skin"),
            plain_module: module("plain"),
            tonemap_module: module("tonemap"),
            film_layout,

            material_layout,
            tonemap_layout,
            pipeline_layout,
            pipelines: Mutex::new(HashMap::new()),
            tonemap_pipelines: Mutex::new(HashMap::new()),
            scene_buffer,
            scene_group,
            body,
            ground,
            instances,
            bounce: Mutex::new(None),
            gpu,
        }
    }

    pub fn headless() -> Result<Renderer, GpuError> {
        Ok(Renderer::new(Gpu::headless()?))
    }

    /// Uploads a material: maps, optics and the film LUT baked for its indices.
    /// The upload runs in `Gpu::checked`: 8192² maps are five textures of 256 MiB and more,
    /// which a device short of memory refuses (a panic of wgpu's default handler otherwise).
    pub fn material(
        &self,
        maps: &MaterialMaps,
        optics: LayerOptics,
        lut: &Lut,
        n_bands: usize,
    ) -> Result<Material, GpuError> {
        let (textures, mesh) = self.upload_maps(maps)?;
        Ok(Material { optics, film: self.upload_film(optics, lut, n_bands)?, textures, mesh })
    }

    /// The maps as textures, and a body atlas's own body (`Gpu::checked`).
    fn upload_maps(&self, maps: &MaterialMaps) -> Result<(MaterialTextures, Option<GpuMesh>), GpuError> {
        let device = &self.gpu.device;
        self.gpu.checked(&format!("uploading {}×{} maps", maps.width, maps.height), || {
            Ok((
                MaterialTextures::new(device, &self.gpu.queue, &self.material_layout, maps),
                maps.atlas.map(|plan| GpuMesh::new(device, &BodyShape::for_atlas(&plan).mesh())),
            ))
        })
    }

    /// The film tables for `optics`' stack (`Gpu::checked`).
    fn upload_film(&self, optics: LayerOptics, lut: &Lut, n_bands: usize) -> Result<FilmBinding, GpuError> {
        self.gpu.checked("uploading the film tables", || {
            Ok(FilmBinding::new(&self.gpu.device, &self.gpu.queue, &self.film_layout, optics.stack, lut, n_bands))
        })
    }

    /// Replaces the film tables of a material (after its indices or band count changed).
    pub fn refilm(
        &self,
        material: &mut Material,
        optics: LayerOptics,
        lut: &Lut,
        n_bands: usize,
    ) -> Result<(), GpuError> {
        material.film = self.upload_film(optics, lut, n_bands)?;
        material.optics = optics;
        Ok(())
    }

    /// Replaces the maps of a material (live reload).
    pub fn retexture(&self, material: &mut Material, maps: &MaterialMaps) -> Result<(), GpuError> {
        (material.textures, material.mesh) = self.upload_maps(maps)?;
        Ok(())
    }

    /// Refuses a readback of `width`×`height` texels of `texel_bytes` that the device
    /// cannot hold in one buffer (a 4112×4096 G-buffer of 16-byte texels is over the 256
    /// MiB it is opened with): a validation error panicked inside wgpu.
    pub fn check_readback(&self, width: u32, height: u32, texel_bytes: u32) -> Result<(), GpuError> {
        let padded = padded_row_bytes(width, texel_bytes) as u64;
        let largest = self.gpu.device.limits().max_buffer_size;
        if padded * height as u64 > largest {
            return Err(GpuError::Limits(format!(
                "reading back {width}×{height} texels of {texel_bytes} bytes needs {} MiB in one buffer, over the \
                 device's {} MiB; use a smaller size",
                (padded * height as u64) >> 20,
                largest >> 20
            )));
        }
        Ok(())
    }

    pub fn targets(&self, width: u32, height: u32, samples: u32) -> Targets {
        let device = &self.gpu.device;
        let size = wgpu::Extent3d { width, height, depth_or_array_layers: 1 };
        let texture = |label, format, samples, usage| {
            device
                .create_texture(&wgpu::TextureDescriptor {
                    label: Some(label),
                    size,
                    mip_level_count: 1,
                    sample_count: samples,
                    dimension: wgpu::TextureDimension::D2,
                    format,
                    usage,
                    view_formats: &[],
                })
                .create_view(&wgpu::TextureViewDescriptor::default())
        };
        let attach = wgpu::TextureUsages::RENDER_ATTACHMENT;
        let msaa = (samples > 1).then(|| texture("hdr msaa", HDR_FORMAT, samples, attach));
        let depth = texture("depth", DEPTH_FORMAT, samples, attach);
        let resolve = texture("hdr", HDR_FORMAT, 1, attach | wgpu::TextureUsages::TEXTURE_BINDING);
        let tonemap_uniform = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("tonemap"),
            size: 16,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let tonemap_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("tonemap"),
            layout: &self.tonemap_layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(&resolve) },
                wgpu::BindGroupEntry { binding: 1, resource: tonemap_uniform.as_entire_binding() },
            ],
        });
        Targets { width, height, samples, msaa, depth, resolve, tonemap_group, tonemap_uniform }
    }

    fn pipeline(&self, key: PipelineKey) -> wgpu::RenderPipeline {
        let mut cache = self.pipelines.lock().expect("pipeline cache");
        cache.entry(key).or_insert_with(|| self.build_pipeline(key)).clone()
    }

    fn build_pipeline(&self, key: PipelineKey) -> wgpu::RenderPipeline {
        let (module, entry) = match key.program {
            Program::Skin => (&self.skin_module, "fs_skin"),
            Program::GBuffer(_) => (&self.skin_module, "fs_gbuffer"),
            Program::Ground => (&self.skin_module, "fs_ground"),
            Program::Plain => (&self.plain_module, "fs_plain"),
        };
        let mut constants: Vec<(&str, f64)> = Vec::new();
        if module_is_skin(key.program) {
            constants.extend([
                ("STAGE", key.stage as f64),
                ("VIEW_MAP", key.view_map as f64),
                ("FILM_METHOD", key.method as f64),
                ("BRDF_MODEL", key.model as f64),
                ("HAS_ABSORPTION", if key.absorption { 1.0 } else { 0.0 }),
                ("FOOTPRINT_SPREAD", if key.footprint == FilmFootprint::Spread { 1.0 } else { 0.0 }),
            ]);
            if let Program::GBuffer(part) = key.program {
                constants.push(("GBUFFER_PART", part as f64));
            }
        }
        let hdr_target =
            Some(wgpu::ColorTargetState { format: HDR_FORMAT, blend: None, write_mask: wgpu::ColorWrites::ALL });
        let gbuffer_target =
            Some(wgpu::ColorTargetState { format: GBUFFER_FORMAT, blend: None, write_mask: wgpu::ColorWrites::ALL });
        let targets: Vec<Option<wgpu::ColorTargetState>> = match key.program {
            Program::GBuffer(_) => vec![gbuffer_target.clone(), gbuffer_target],
            _ => vec![hdr_target],
        };
        let vertex_layouts = [
            Some(wgpu::VertexBufferLayout {
                array_stride: std::mem::size_of::<Vertex>() as u64,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x4, 3 => Float32x2],
            }),
            Some(wgpu::VertexBufferLayout {
                array_stride: 16,
                step_mode: wgpu::VertexStepMode::Instance,
                attributes: &wgpu::vertex_attr_array![4 => Float32x4],
            }),
        ];
        self.gpu.device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(&format!("{key:?}")),
            layout: Some(&self.pipeline_layout),
            vertex: wgpu::VertexState {
                module,
                entry_point: Some("vs_main"),
                compilation_options: wgpu::PipelineCompilationOptions { constants: &constants, ..Default::default() },
                buffers: &vertex_layouts,
            },
            primitive: wgpu::PrimitiveState { cull_mode: Some(wgpu::Face::Back), ..Default::default() },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Less),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: wgpu::MultisampleState { count: key.samples, ..Default::default() },
            fragment: Some(wgpu::FragmentState {
                module,
                entry_point: Some(entry),
                compilation_options: wgpu::PipelineCompilationOptions { constants: &constants, ..Default::default() },
                targets: &targets,
            }),
            multiview_mask: None,
            cache: None,
        })
    }

    fn tonemap_pipeline(&self, format: wgpu::TextureFormat) -> wgpu::RenderPipeline {
        let mut cache = self.tonemap_pipelines.lock().expect("tonemap cache");
        cache
            .entry(format)
            .or_insert_with(|| {
                let layout = self.gpu.device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                    label: Some("tonemap"),
                    bind_group_layouts: &[Some(&self.tonemap_layout)],
                    immediate_size: 0,
                });
                self.gpu.device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                    label: Some("tonemap"),
                    layout: Some(&layout),
                    vertex: wgpu::VertexState {
                        module: &self.tonemap_module,
                        entry_point: Some("vs_fullscreen"),
                        compilation_options: Default::default(),
                        buffers: &[],
                    },
                    primitive: Default::default(),
                    depth_stencil: None,
                    multisample: Default::default(),
                    fragment: Some(wgpu::FragmentState {
                        module: &self.tonemap_module,
                        entry_point: Some("fs_tonemap"),
                        compilation_options: Default::default(),
                        targets: &[Some(wgpu::ColorTargetState {
                            format,
                            blend: None,
                            write_mask: wgpu::ColorWrites::ALL,
                        })],
                    }),
                    multiview_mask: None,
                    cache: None,
                })
            })
            .clone()
    }

    fn key(&self, program: Program, settings: &FrameSettings, material: &Material, samples: u32) -> PipelineKey {
        let (stage, view_map) = settings.view.codes();
        // Specialisation: an inert film needs no film code (its specular term is the plain
        // interface; the layered coupling reads the coupling texture), no absorption no
        // exponential.
        let method = material.optics.specialised_method(settings.method).code();
        let model = settings.model.code();
        let absorption = material.optics.has_absorption();
        PipelineKey { program, stage, view_map, method, model, absorption, footprint: settings.footprint, samples }
    }

    fn write_scene(&self, settings: &FrameSettings, material: &Material, aspect: f32) {
        let bounce = {
            let mut last = self.bounce.lock().expect("bounce grid");
            match &*last {
                Some((optics, model, grid)) if *optics == material.optics && *model == settings.model => grid.clone(),
                _ => {
                    let grid = std::sync::Arc::new(material.optics.bounce_grid(settings.model));
                    *last = Some((material.optics, settings.model, grid.clone()));
                    grid
                }
            }
        };
        let uniform = SceneUniform::new(&settings.camera, aspect, &settings.lighting, &material.optics, &bounce);
        self.gpu.queue.write_buffer(&self.scene_buffer, 0, bytemuck::bytes_of(&uniform));
    }

    fn instance_buffer(&self, snakes: u32) -> wgpu::Buffer {
        let mut current = self.instances.lock().expect("instances");
        if current.0 != snakes {
            let buffer = self.gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("instances"),
                contents: bytemuck::cast_slice(&placements(snakes.max(1))),
                usage: wgpu::BufferUsages::VERTEX,
            });
            *current = (snakes, buffer);
        }
        current.1.clone()
    }

    /// Binds the material and scene and draws `snakes` instances of the body with `pipeline`.
    fn draw_snakes(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        pipeline: &wgpu::RenderPipeline,
        material: &Material,
        instances: &wgpu::Buffer,
        snakes: u32,
    ) {
        pass.set_bind_group(0, &material.film.bind_group, &[]);
        pass.set_bind_group(1, &self.scene_group, &[]);
        pass.set_bind_group(2, &material.textures.bind_group, &[]);
        pass.set_pipeline(pipeline);
        let body = material.mesh.as_ref().unwrap_or(&self.body);
        pass.set_vertex_buffer(0, body.vertices.slice(..));
        pass.set_vertex_buffer(1, instances.slice(..));
        pass.set_index_buffer(body.indices.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(0..body.count, 0, 0..snakes.max(1));
    }

    /// Records a whole frame: the scene pass (timestamps around it if given) and the tone
    /// mapping pass into `output` (any 8-bit sRGB format).
    pub fn encode_frame(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        targets: &Targets,
        settings: &FrameSettings,
        material: &Material,
        output: FrameOutput<'_>,
        timestamps: Option<(&wgpu::QuerySet, u32)>,
    ) {
        self.write_scene(settings, material, targets.width as f32 / targets.height as f32);
        let mode: u32 = if matches!(settings.view, View::Map(_)) { TONE_MAP_NONE } else { TONE_MAP_CURVE };
        let tone: [u32; 4] = [settings.exposure.to_bits(), mode, 0, 0];
        self.gpu.queue.write_buffer(&targets.tonemap_uniform, 0, bytemuck::cast_slice(&tone));
        let program = if settings.plain { Program::Plain } else { Program::Skin };
        let body = self.pipeline(self.key(program, settings, material, targets.samples));
        let ground =
            settings.ground.then(|| self.pipeline(self.key(Program::Ground, settings, material, targets.samples)));
        let instances = self.instance_buffer(settings.snakes);
        let [r, g, b] = settings.background;
        {
            let (view, resolve) = match &targets.msaa {
                Some(msaa) => (msaa, Some(&targets.resolve)),
                None => (&targets.resolve, None),
            };
            let timestamp_writes = timestamps.map(|(query_set, first)| wgpu::RenderPassTimestampWrites {
                query_set,
                beginning_of_pass_write_index: Some(first),
                end_of_pass_write_index: Some(first + 1),
            });
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("scene"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view,
                    depth_slice: None,
                    resolve_target: resolve,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color { r, g, b, a: 1.0 }),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: Some(depth_attachment(&targets.depth)),
                timestamp_writes,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            self.draw_snakes(&mut pass, &body, material, &instances, settings.snakes);
            if let Some(ground) = ground {
                pass.set_pipeline(&ground);
                pass.set_vertex_buffer(0, self.ground.vertices.slice(..));
                pass.set_vertex_buffer(1, instances.slice(..));
                pass.set_index_buffer(self.ground.indices.slice(..), wgpu::IndexFormat::Uint32);
                let ground_instance = settings.snakes.max(1);
                pass.draw_indexed(0..self.ground.count, 0, ground_instance..ground_instance + 1);
            }
        }
        let tonemap = self.tonemap_pipeline(output.format);
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("tonemap"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: output.view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load: wgpu::LoadOp::Clear(wgpu::Color::BLACK), store: wgpu::StoreOp::Store },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&tonemap);
        pass.set_bind_group(0, &targets.tonemap_group, &[]);
        pass.draw(0..3, 0..1);
    }

    /// Renders one frame offscreen and reads it back as 8-bit sRGB RGBA.
    pub fn render_image(
        &self,
        settings: &FrameSettings,
        material: &Material,
        width: u32,
        height: u32,
    ) -> Result<image::RgbaImage, GpuError> {
        let bytes = self.gpu.checked(&format!("rendering a {width}×{height} frame"), || {
            let targets = self.targets(width, height, settings.samples);
            let output = self.output_texture(width, height);
            let view = output.create_view(&wgpu::TextureViewDescriptor::default());
            let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
            self.encode_frame(
                &mut encoder,
                &targets,
                settings,
                material,
                FrameOutput { view: &view, format: OUTPUT_FORMAT },
                None,
            );
            self.read_texture(encoder, &output, width, height, 4)
        })?;
        image::RgbaImage::from_raw(width, height, bytes).ok_or_else(|| GpuError::Readback("image size".into()))
    }

    /// An 8-bit sRGB texture frames can be drawn into and read back from.
    pub fn output_texture(&self, width: u32, height: u32) -> wgpu::Texture {
        self.readable_target("output", OUTPUT_FORMAT, width, height)
    }

    /// A single-sample render target that can be copied to a buffer.
    fn readable_target(&self, label: &str, format: wgpu::TextureFormat, width: u32, height: u32) -> wgpu::Texture {
        self.gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        })
    }

    /// The G-buffer of the snake (no ground) at one sample per pixel: per pixel the world
    /// position, film thickness, shading and geometric normals, roughness and albedo, and
    /// whether the snake covers it.
    pub fn render_gbuffer(
        &self,
        settings: &FrameSettings,
        material: &Material,
        width: u32,
        height: u32,
    ) -> Result<GBuffer, GpuError> {
        self.gpu.checked(&format!("rendering a {width}×{height} G-buffer"), || {
            self.render_gbuffer_unchecked(settings, material, width, height)
        })
    }

    fn render_gbuffer_unchecked(
        &self,
        settings: &FrameSettings,
        material: &Material,
        width: u32,
        height: u32,
    ) -> Result<GBuffer, GpuError> {
        let device = &self.gpu.device;
        self.write_scene(settings, material, width as f32 / height as f32);
        let instances = self.instance_buffer(settings.snakes);
        // Depth only: the colour targets of `Targets` are not used here.
        let depth = self.targets(width, height, 1).depth;
        let mut parts = Vec::new();
        for part in [GBUFFER_POSITION_NORMAL, GBUFFER_ALBEDO_GEOMETRY] {
            let make = || self.readable_target("gbuffer", GBUFFER_FORMAT, width, height);
            let (first, second) = (make(), make());
            let pipeline = self.pipeline(self.key(Program::GBuffer(part), settings, material, 1));
            let mut encoder = device.create_command_encoder(&Default::default());
            {
                let views = [&first, &second].map(|t| t.create_view(&wgpu::TextureViewDescriptor::default()));
                let attachments: Vec<Option<wgpu::RenderPassColorAttachment>> = views
                    .iter()
                    .map(|view| {
                        Some(wgpu::RenderPassColorAttachment {
                            view,
                            depth_slice: None,
                            resolve_target: None,
                            ops: wgpu::Operations {
                                load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                                store: wgpu::StoreOp::Store,
                            },
                        })
                    })
                    .collect();
                let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("gbuffer"),
                    color_attachments: &attachments,
                    depth_stencil_attachment: Some(depth_attachment(&depth)),
                    timestamp_writes: None,
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                self.draw_snakes(&mut pass, &pipeline, material, &instances, settings.snakes);
            }
            let a = self.read_texture(encoder, &first, width, height, 16)?;
            let b =
                self.read_texture(device.create_command_encoder(&Default::default()), &second, width, height, 16)?;
            parts.push((
                bytemuck::cast_slice::<u8, [f32; 4]>(&a).to_vec(),
                bytemuck::cast_slice::<u8, [f32; 4]>(&b).to_vec(),
            ));
        }
        let (position_thickness, normal_roughness) = parts.remove(0);
        let (albedo_spread, geometric) = parts.remove(0);
        Ok(GBuffer { width, height, position_thickness, normal_roughness, albedo_spread, geometric })
    }

    /// Submits `encoder` with a copy of `texture` and returns its rows, tightly packed.
    pub fn read_texture(
        &self,
        mut encoder: wgpu::CommandEncoder,
        texture: &wgpu::Texture,
        width: u32,
        height: u32,
        texel_bytes: u32,
    ) -> Result<Vec<u8>, GpuError> {
        self.check_readback(width, height, texel_bytes)?;
        let device = &self.gpu.device;
        let row = width * texel_bytes;
        let padded = padded_row_bytes(width, texel_bytes);
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size: (padded * height) as u64,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(padded),
                    rows_per_image: Some(height),
                },
            },
            wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
        );
        self.gpu.queue.submit([encoder.finish()]);
        map_read_with(device, &buffer, |data| {
            let mut out = Vec::with_capacity((row * height) as usize);
            for y in 0..height as usize {
                let start = y * padded as usize;
                out.extend_from_slice(&data[start..start + row as usize]);
            }
            out
        })
    }
}

fn module_is_skin(program: Program) -> bool {
    !matches!(program, Program::Plain)
}

fn depth_attachment(view: &wgpu::TextureView) -> wgpu::RenderPassDepthStencilAttachment<'_> {
    wgpu::RenderPassDepthStencilAttachment {
        view,
        depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store: wgpu::StoreOp::Discard }),
        stencil_ops: None,
    }
}

/// The G-buffer read back from the GPU (row-major, `width × height`).
#[derive(Debug, Clone)]
pub struct GBuffer {
    pub width: u32,
    pub height: u32,
    pub position_thickness: Vec<[f32; 4]>,
    pub normal_roughness: Vec<[f32; 4]>,
    /// Albedo and, in `w`, the film thickness' standard deviation over the pixel's footprint
    /// in nm (0 where the shader reads one thickness: `skin.wgsl`'s `shade`).
    pub albedo_spread: Vec<[f32; 4]>,
    /// Interpolated geometric normal (unit length where the snake covers the pixel, the
    /// cleared zero vector elsewhere; a degenerate triangle's NaN reads as uncovered) and, in
    /// `w`, the height map value.
    pub geometric: Vec<[f32; 4]>,
}

impl GBuffer {
    pub fn covered(&self, i: usize) -> bool {
        let [x, y, z, _] = self.geometric[i];
        x * x + y * y + z * z > 0.25
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The ground lies under every snake of every grid `--snakes` draws (1 to 400): each body
    /// (2.4 long, ±0.35 wide, `grid_layout`) within its reach. Seen failing with the ground at
    /// the origin, from 122 snakes on.
    #[test]
    fn the_ground_lies_under_every_snake_of_the_grid() {
        for n in 1..=400 {
            let placed = placements(n);
            let (snakes, ground) = (&placed[..n as usize], placed[n as usize]);
            for [x, z, ..] in snakes {
                let (dx, dz) = ((x - ground[0]).abs() + 1.2, (z - ground[1]).abs() + 0.35);
                assert!(dx <= GROUND_HALF_SIZE && dz <= GROUND_HALF_SIZE, "{n} snakes: one at ({x}, {z})");
            }
        }
    }
}
