//! The film's GPU resources: one bind group (group 0 of every shading program) holding the
//! material's indices, its baked colour LUT (with its sampler), the spectral-N band table,
//! the rough lobe's table and the layered model's coupling texture, so that every film
//! method in `shaders/film.wgsl` reads the same inputs and a method switch is only a pipeline
//! switch. The LUT is a half-float texture read with one hardware-filtered fetch at the texel
//! coordinates `Lut::lookup_f32` computes (its piecewise thickness axis is mapped in the
//! shader). Measured on lavapipe, this is ~5 % faster per frame than four storage-buffer loads
//! with a manual bilinear blend, and half precision changes the film colour by at most 5e-4
//! relative (`bench render`'s reference ΔE is unchanged at 0.21).
use bytemuck::{Pod, Zeroable};
use wgpu::util::DeviceExt;

use super::gpu::{sampler_entry, storage_entry, texture_entry, uniform_entry};
use crate::optics::brdf::energy::NODE_LEN;
use crate::optics::brdf::path::THROUGH_LEN;
use crate::optics::film::Stack;
use crate::optics::lut::Lut;
use crate::optics::methods::{Bands, Method, gaussian_fit_xyz_to_rgb};

/// How `film.wgsl` computes the film colour (its `FILM_METHOD` override constant).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum GpuFilmMethod {
    Lut,
    Rgb3,
    SpectralN(usize),
    GaussianFit,
    /// No film: the Fresnel reflectance of the n0|n2 interface.
    None,
}

impl GpuFilmMethod {
    /// The GPU form of an optics method; the 1 nm reference becomes 421 one-nanometre bands.
    pub fn from_method(method: Method) -> GpuFilmMethod {
        match method {
            Method::Lut => GpuFilmMethod::Lut,
            Method::Rgb3 => GpuFilmMethod::Rgb3,
            Method::SpectralN(n) => GpuFilmMethod::SpectralN(n),
            Method::Spectral => GpuFilmMethod::SpectralN(crate::optics::spectrum::SAMPLES),
            Method::GaussianFit => GpuFilmMethod::GaussianFit,
        }
    }

    /// The value of `film.wgsl`'s `FILM_METHOD` (`FILM_LUT`, ... in the generated prelude).
    pub fn code(self) -> u32 {
        match self {
            GpuFilmMethod::Lut => 0,
            GpuFilmMethod::Rgb3 => 1,
            GpuFilmMethod::SpectralN(_) => 2,
            GpuFilmMethod::GaussianFit => 3,
            GpuFilmMethod::None => 4,
        }
    }

    pub fn name(self) -> String {
        match self {
            // The optics method's own name (`Method::name`); only "no film" is the GPU's.
            GpuFilmMethod::Lut => Method::Lut.name(),
            GpuFilmMethod::Rgb3 => Method::Rgb3.name(),
            GpuFilmMethod::SpectralN(n) => Method::SpectralN(n).name(),
            GpuFilmMethod::GaussianFit => Method::GaussianFit.name(),
            GpuFilmMethod::None => "none".into(),
        }
    }
}

#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub(crate) struct FilmInfo {
    // Visible to the crate for the layout test (`shaders::tests`), which reads each field's
    // offset.
    pub(crate) n_cos: u32,
    pub(crate) n_fine: u32,
    pub(crate) n_coarse: u32,
    pub(crate) n_bands: u32,
    pub(crate) iors_band: [f32; 4],
    pub(crate) xyz_to_rgb: [[f32; 4]; 3],
}

/// Slots per entry of the lobe table (`lobe_table`), in order: the path delta
/// (cos_eff − cos_t), the lobe node (`energy::node`, `NODE_LEN` slots from
/// `LOBE_NODE_SLOT`) and the rule for light straight back through the top
/// (`path::PathTable::through`, `THROUGH_LEN` slots from `LOBE_THROUGH_SLOT`).
const LOBE_SLOTS: usize = LOBE_THROUGH_SLOT + THROUGH_LEN;
/// The entry's slot where the lobe node begins (the shader's `LOBE_NODE_SLOT`).
pub const LOBE_NODE_SLOT: usize = 1;
/// The entry's slot where the rule for light straight back begins (`LOBE_THROUGH_SLOT`).
pub const LOBE_THROUGH_SLOT: usize = LOBE_NODE_SLOT + NODE_LEN;
/// vec4s per entry of the lobe table (the shader's `LOBE_VEC4S`): its slots, in order,
/// padded with zeros.
pub const LOBE_VEC4S: usize = LOBE_SLOTS.div_ceil(4);

/// The rough lobe's table (`optics::brdf::energy`) as `film.wgsl`'s `lobe_table`: per (μ, r)
/// entry, row-major by roughness, `LOBE_VEC4S` vec4s holding `LOBE_SLOTS` slots in order:
/// from the material's path table (`optics::brdf::path`, the same grid) the path delta, then
/// the lobe's albedo, its five-point rule and the multiple scattering's rule (`energy::node`),
/// then the rule for light that comes straight back through the top. Filled for every
/// material, absorbing or not: the window changes the absorption without a new film binding.
/// For a material whose coupling reads the quantile rule (`energy::LobeRule::of`: a film
/// less dense than the medium above), the quantile nodes of every entry follow, in the same
/// order, `QUANTILE_VEC4S` vec4s each; the shader reads the rule the table holds
/// (`brdf.wgsl`'s `parts_on_row`), so the choice has one home.
fn lobe_table(stack: Stack) -> Vec<[f32; 4]> {
    use crate::optics::brdf::energy::{E1_MU, E1_ROUGHNESS, LobeRule, node, quantile_table};
    let path = crate::optics::brdf::path::cached(stack.n0, stack.n2);
    let entries = (0..E1_MU * E1_ROUGHNESS).flat_map(|k| {
        let mut slots = [0.0f32; 4 * LOBE_VEC4S];
        slots[0] = path.delta_f32[k];
        slots[LOBE_NODE_SLOT..LOBE_THROUGH_SLOT].copy_from_slice(&node(k % E1_MU, k / E1_MU));
        slots[LOBE_THROUGH_SLOT..LOBE_SLOTS].copy_from_slice(&path.through_f32[k]);
        let entry: [[f32; 4]; LOBE_VEC4S] = std::array::from_fn(|v| std::array::from_fn(|c| slots[4 * v + c]));
        entry
    });
    let quantiles =
        (LobeRule::of(stack.n0, stack.n1, stack.n2) == LobeRule::Quantiles).then(quantile_table).unwrap_or(&[]);
    let quantiles = quantiles.iter().flat_map(|nodes| {
        let entry: [[f32; 4]; QUANTILE_VEC4S] =
            std::array::from_fn(|v| std::array::from_fn(|c| nodes[4 * v + c] as f32));
        entry
    });
    entries.chain(quantiles).collect()
}

/// vec4s per entry of the lobe table's quantile section (the shader's `QUANTILE_VEC4S`).
pub const QUANTILE_VEC4S: usize = crate::optics::brdf::energy::QUANTILES / 4;
// The shader reads the quantile nodes four to a vec4: a remainder would be lost.
const _: () = assert!(crate::optics::brdf::energy::QUANTILES.is_multiple_of(4));

/// The LUT's coupling table (`Lut::coupling`) as `film.wgsl`'s `coupling_texture`: a 3-D
/// half-float texture of 2 n_cos × E1_ROUGHNESS × the table's thickness columns, the
/// reflected share and the path delta in the first n_cos texels of a row and the
/// multiple-scatter amplitude in the next (one texture, one binding; the shader's
/// coordinates never filter across the two halves, since cos is clamped to the texel
/// centres of its half).
fn coupling_texture(device: &wgpu::Device, queue: &wgpu::Queue, lut: &Lut) -> wgpu::Texture {
    use crate::optics::brdf::energy::E1_ROUGHNESS;
    let table = lut.coupling();
    let mut texels: Vec<u16> = Vec::with_capacity(table.len() * 8);
    for row in table.chunks(lut.n_cos) {
        for half in 0..2 {
            for entry in row {
                texels.extend(entry[4 * half..4 * half + 4].iter().map(|v| super::material::f32_to_f16(*v)));
            }
        }
    }
    let size = wgpu::Extent3d {
        width: 2 * lut.n_cos as u32,
        height: E1_ROUGHNESS as u32,
        depth_or_array_layers: lut.width() as u32,
    };
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("film coupling"),
        size,
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D3,
        format: wgpu::TextureFormat::Rgba16Float,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    queue.write_texture(
        texture.as_image_copy(),
        bytemuck::cast_slice(&texels),
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(size.width * 8),
            rows_per_image: Some(size.height),
        },
        size,
    );
    texture
}

/// The bind group layout of `film.wgsl`'s group 0.
pub fn bind_group_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let visibility = wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE;
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("film"),
        entries: &[
            uniform_entry(0, visibility),
            texture_entry(1, visibility, true),
            storage_entry(2, visibility, true),
            sampler_entry(3, visibility),
            storage_entry(4, visibility, true),
            super::gpu::texture_entry_of(5, visibility, true, wgpu::TextureViewDimension::D3),
        ],
    })
}

/// A material's film on the GPU: its bind group and what it was made from.
pub struct FilmBinding {
    pub stack: Stack,
    pub n_bands: usize,
    pub bind_group: wgpu::BindGroup,
}

impl FilmBinding {
    /// Uploads `lut` (baked for `stack`) and the band table for `n_bands` (1 if unused).
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        layout: &wgpu::BindGroupLayout,
        stack: Stack,
        lut: &Lut,
        n_bands: usize,
    ) -> FilmBinding {
        let bands = Bands::cached(n_bands.max(1));
        let xyz_to_rgb = gaussian_fit_xyz_to_rgb().map(|row| [row[0], row[1], row[2], 0.0].map(|v| v as f32));
        let info = FilmInfo {
            n_cos: lut.n_cos as u32,
            n_fine: lut.n_fine as u32,
            n_coarse: lut.n_coarse as u32,
            n_bands: bands.centres_nm.len() as u32,
            iors_band: [stack.n0 as f32, stack.n1 as f32, stack.n2 as f32, bands.width_nm as f32],
            xyz_to_rgb,
        };
        let texels: Vec<u16> =
            lut.texels.iter().flat_map(|t| [t[0], t[1], t[2], 0.0].map(super::material::f32_to_f16)).collect();
        let band_table: Vec<[f32; 4]> = bands
            .centres_nm
            .iter()
            .zip(&bands.rgb_weights)
            .map(|(c, w)| [*c as f32, w[0] as f32, w[1] as f32, w[2] as f32])
            .collect();
        let buffer = |label, contents: &[u8], usage| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: Some(label), contents, usage })
        };
        let info_buffer = buffer("film info", bytemuck::bytes_of(&info), wgpu::BufferUsages::UNIFORM);
        let size = wgpu::Extent3d { width: lut.width() as u32, height: lut.n_cos as u32, depth_or_array_layers: 1 };
        let lut_texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("film lut"),
            size,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba16Float,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        queue.write_texture(
            lut_texture.as_image_copy(),
            bytemuck::cast_slice(&texels),
            wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(size.width * 8), rows_per_image: None },
            size,
        );
        let lut_view = lut_texture.create_view(&wgpu::TextureViewDescriptor::default());
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("film lut"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        let coupling_view = coupling_texture(device, queue, lut).create_view(&wgpu::TextureViewDescriptor::default());
        let band_buffer = buffer("film bands", bytemuck::cast_slice(&band_table), wgpu::BufferUsages::STORAGE);
        let lobe_buffer = buffer("rough lobe", bytemuck::cast_slice(&lobe_table(stack)), wgpu::BufferUsages::STORAGE);
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("film"),
            layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: info_buffer.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(&lut_view) },
                wgpu::BindGroupEntry { binding: 2, resource: band_buffer.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 3, resource: wgpu::BindingResource::Sampler(&sampler) },
                wgpu::BindGroupEntry { binding: 4, resource: lobe_buffer.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 5, resource: wgpu::BindingResource::TextureView(&coupling_view) },
            ],
        });
        FilmBinding { stack, n_bands: bands.centres_nm.len(), bind_group }
    }
}
