//! The five maps as GPU textures. The renderer takes the generator's f32 maps directly (no PNG
//! round trip) and packs them into three filterable half-float textures with a full mip
//! chain built on the CPU (2×2 box, colour averaged in linear light), so distant scales
//! average instead of shimmering:
//! `albedo_roughness` (linear colour, perceptual roughness), `normal_height` (tangent-space
//! normal in [-1, 1], height), `thickness` (iridescence map value in [0, 1]).

use std::collections::BTreeMap;

use super::gpu::{sampler_entry, texture_entry};
use crate::maps::MapKind;
use crate::ops::Image;

/// The maps a preview needs, as packed RGBA f32 levels (level 0 first).
#[derive(Debug, Clone)]
pub struct MaterialMaps {
    pub width: usize,
    pub height: usize,
    /// The body plan of a body atlas (v clamps at the snout and tail tip instead of
    /// repeating, and the renderer draws the atlas' own body); None for the tile.
    pub atlas: Option<crate::ops::body::BodyPlan>,
    pub albedo_roughness: Vec<Vec<[f32; 4]>>,
    pub normal_height: Vec<Vec<[f32; 4]>>,
    pub thickness: Vec<Vec<f32>>,
}

#[derive(Debug, thiserror::Error)]
#[error("the preview needs the {0} map")]
pub struct MissingMap(pub MapKind);

impl MaterialMaps {
    /// Packs generator output (all five maps, the same size).
    pub fn from_maps(maps: &BTreeMap<MapKind, Image>) -> Result<MaterialMaps, MissingMap> {
        let get = |kind| maps.get(&kind).ok_or(MissingMap(kind));
        let (color, height, normal, rough, irid) = (
            get(MapKind::Color)?,
            get(MapKind::Height)?,
            get(MapKind::Normal)?,
            get(MapKind::Roughness)?,
            get(MapKind::Iridescence)?,
        );
        let (w, h) = (color.width, color.height);
        let px = |img: &Image, i: usize, c: usize| img.data[i * img.channels + c];
        let ar: Vec<[f32; 4]> =
            (0..w * h).map(|i| [px(color, i, 0), px(color, i, 1), px(color, i, 2), px(rough, i, 0)]).collect();
        let nh: Vec<[f32; 4]> =
            (0..w * h).map(|i| [px(normal, i, 0), px(normal, i, 1), px(normal, i, 2), px(height, i, 0)]).collect();
        let t: Vec<f32> = (0..w * h).map(|i| px(irid, i, 0)).collect();
        Ok(MaterialMaps {
            width: w,
            height: h,
            atlas: None,
            albedo_roughness: mip_chain(ar, w, h),
            normal_height: mip_chain(nh, w, h),
            thickness: mip_chain(t, w, h),
        })
    }

    pub fn levels(&self) -> usize {
        self.thickness.len()
    }
}

/// The three textures' formats, in binding order.
pub const ALBEDO_ROUGHNESS_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
pub const NORMAL_HEIGHT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
pub const THICKNESS_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R16Float;

/// Width and height of every level of a mip chain, level 0 first: each halves the last
/// (at least 1) down to 1×1. The one home of the rule that `mip_chain`, the upload and the
/// memory checks share.
pub fn mip_levels(width: usize, height: usize) -> impl Iterator<Item = (usize, usize)> {
    std::iter::successors(Some((width, height)), |&(w, h)| (w > 1 || h > 1).then(|| ((w / 2).max(1), (h / 2).max(1))))
}

/// Texels in `mip_chain`'s levels for a `width`×`height` level 0 (about 4/3 of level 0).
pub fn chain_texels(width: usize, height: usize) -> u64 {
    mip_levels(width, height).map(|(w, h)| (w * h) as u64).sum()
}

/// Bytes of `MaterialMaps`' packed f32 chains for `width`×`height` maps (16 + 16 + 4 per
/// texel, every level), for the memory checks before anything is generated.
pub fn packed_bytes(width: usize, height: usize) -> u64 {
    let per_texel = 2 * std::mem::size_of::<[f32; 4]>() + std::mem::size_of::<f32>();
    chain_texels(width, height) * per_texel as u64
}

/// Bytes of the three textures `MaterialTextures::new` makes for `width`×`height` maps
/// (8 + 8 + 2 per texel, every level): device memory on a GPU, host memory on lavapipe.
pub fn texture_bytes(width: usize, height: usize) -> u64 {
    let texel = |f: wgpu::TextureFormat| f.block_copy_size(None).expect("colour formats have a size") as u64;
    let per_texel = texel(ALBEDO_ROUGHNESS_FORMAT) + texel(NORMAL_HEIGHT_FORMAT) + texel(THICKNESS_FORMAT);
    chain_texels(width, height) * per_texel
}

/// Anything a 2×2 box filter can average.
pub trait Texel: Copy + Default {
    fn average(a: Self, b: Self, c: Self, d: Self) -> Self;
}

impl Texel for f32 {
    fn average(a: f32, b: f32, c: f32, d: f32) -> f32 {
        0.25 * (a + b + c + d)
    }
}

impl Texel for [f32; 4] {
    fn average(a: Self, b: Self, c: Self, d: Self) -> Self {
        [0, 1, 2, 3].map(|k| 0.25 * (a[k] + b[k] + c[k] + d[k]))
    }
}

/// Level 0 and every halving down to 1×1; odd sizes drop their last row or column.
pub fn mip_chain<T: Texel>(level0: Vec<T>, width: usize, height: usize) -> Vec<Vec<T>> {
    let mut levels = vec![level0];
    let sizes: Vec<(usize, usize)> = mip_levels(width, height).collect();
    for pair in sizes.windows(2) {
        let ((w, h), (nw, nh)) = (pair[0], pair[1]);
        let src = levels.last().expect("level 0");
        let at = |x: usize, y: usize| src[y.min(h - 1) * w + x.min(w - 1)];
        let mut next = Vec::with_capacity(nw * nh);
        for y in 0..nh {
            for x in 0..nw {
                next.push(T::average(
                    at(2 * x, 2 * y),
                    at(2 * x + 1, 2 * y),
                    at(2 * x, 2 * y + 1),
                    at(2 * x + 1, 2 * y + 1),
                ));
            }
        }
        levels.push(next);
    }
    levels
}

/// IEEE 754 binary16 from f32, round to nearest even, overflow to infinity (maps never get
/// near 65504): the `half` crate's, which the EXR export's halves are too. (A hand-written
/// conversion here until a later session rounded some subnormals down: it dropped the bits
/// it shifted out before deciding the tie, so 2^-25 plus a little became 0 for 2^-24.)
pub fn f32_to_f16(value: f32) -> u16 {
    half::f16::from_f32(value).to_bits()
}

/// f32 from IEEE 754 binary16 (exact: every half is an f32).
pub fn f16_to_f32(bits: u16) -> f32 {
    half::f16::from_bits(bits).to_f32()
}

/// The value a half-float texture stores for `value`.
pub fn round_to_f16(value: f32) -> f32 {
    f16_to_f32(f32_to_f16(value))
}

/// The material's textures and the bind group (group 2 of the scene programs).
pub struct MaterialTextures {
    pub bind_group: wgpu::BindGroup,
    _textures: [wgpu::Texture; 3],
}

pub fn bind_group_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let fragment = wgpu::ShaderStages::FRAGMENT;
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("material"),
        entries: &[
            texture_entry(0, fragment, true),
            texture_entry(1, fragment, true),
            texture_entry(2, fragment, true),
            sampler_entry(3, fragment),
        ],
    })
}

impl MaterialTextures {
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        layout: &wgpu::BindGroupLayout,
        maps: &MaterialMaps,
    ) -> MaterialTextures {
        let levels = maps.levels() as u32;
        let make = |label, format| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d { width: maps.width as u32, height: maps.height as u32, depth_or_array_layers: 1 },
                mip_level_count: levels,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
                view_formats: &[],
            })
        };
        let ar = make("albedo_roughness", ALBEDO_ROUGHNESS_FORMAT);
        let nh = make("normal_height", NORMAL_HEIGHT_FORMAT);
        let th = make("thickness", THICKNESS_FORMAT);
        for (level, (w, h)) in mip_levels(maps.width, maps.height).take(levels as usize).enumerate() {
            let upload = |texture: &wgpu::Texture, data: Vec<u16>, texel_bytes: usize| {
                queue.write_texture(
                    wgpu::TexelCopyTextureInfo {
                        texture,
                        mip_level: level as u32,
                        origin: wgpu::Origin3d::ZERO,
                        aspect: wgpu::TextureAspect::All,
                    },
                    bytemuck::cast_slice(&data),
                    wgpu::TexelCopyBufferLayout {
                        offset: 0,
                        bytes_per_row: Some((w * texel_bytes) as u32),
                        rows_per_image: Some(h as u32),
                    },
                    wgpu::Extent3d { width: w as u32, height: h as u32, depth_or_array_layers: 1 },
                );
            };
            upload(&ar, maps.albedo_roughness[level].iter().flat_map(|t| t.map(f32_to_f16)).collect(), 8);
            upload(&nh, maps.normal_height[level].iter().flat_map(|t| t.map(f32_to_f16)).collect(), 8);
            upload(&th, maps.thickness[level].iter().map(|t| f32_to_f16(*t)).collect(), 2);
        }
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("maps"),
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: if maps.atlas.is_some() {
                wgpu::AddressMode::ClampToEdge
            } else {
                wgpu::AddressMode::Repeat
            },
            address_mode_w: wgpu::AddressMode::Repeat,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            anisotropy_clamp: 8,
            ..Default::default()
        });
        let view = |t: &wgpu::Texture| t.create_view(&wgpu::TextureViewDescriptor::default());
        let (v0, v1, v2) = (view(&ar), view(&nh), view(&th));
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("material"),
            layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(&v0) },
                wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(&v1) },
                wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(&v2) },
                wgpu::BindGroupEntry { binding: 3, resource: wgpu::BindingResource::Sampler(&sampler) },
            ],
        });
        MaterialTextures { bind_group, _textures: [ar, nh, th] }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn half_floats_round_trip_known_values() {
        // Reference bit patterns from IEEE 754 binary16.
        assert_eq!(f32_to_f16(0.0), 0x0000);
        assert_eq!(f32_to_f16(1.0), 0x3c00);
        assert_eq!(f32_to_f16(-2.0), 0xc000);
        assert_eq!(f32_to_f16(0.5), 0x3800);
        assert_eq!(f32_to_f16(65504.0), 0x7bff);
        assert_eq!(f32_to_f16(1e6), 0x7c00);
        // Smallest subnormal 2^-24.
        assert_eq!(f32_to_f16(5.960_464_5e-8), 0x0001);
        // Subnormals round to nearest on all the bits shifted out: just above half the
        // smallest subnormal (f32 bits 0x3300_0743) is the smallest, not 0, and just above
        // 2.5 of it (0x3420_013f) is 3, not 2 (both missed by the conversion before `half`).
        assert_eq!(f32_to_f16(f32::from_bits(0x3300_0743)), 0x0001);
        assert_eq!(f32_to_f16(f32::from_bits(0x3420_013f)), 0x0003);
        assert_eq!(f32_to_f16(f32::from_bits(0x3300_0000)), 0x0000, "a tie to even");
        // 1/3 rounds to 0x3555.
        assert_eq!(f32_to_f16(1.0 / 3.0), 0x3555);
        // And back: 0x3555 is 0.333251953125, the nearest half to 1/3.
        assert_eq!(f16_to_f32(0x3555), 0.333_251_95);
        for v in [0.0f32, 1.0, -2.0, 0.5, 65504.0, 5.960_464_5e-8, 0.1] {
            let r = round_to_f16(v);
            assert!((r - v).abs() <= v.abs() * 4.9e-4 + 6e-8, "{v} -> {r}");
            assert_eq!(round_to_f16(r), r, "rounding is idempotent");
        }
    }

    #[test]
    fn mip_chain_preserves_the_mean() {
        let level0: Vec<f32> = (0..64 * 32).map(|i| (i % 7) as f32).collect();
        let mean0 = level0.iter().sum::<f32>() / level0.len() as f32;
        let chain = mip_chain(level0, 64, 32);
        assert_eq!(chain.len(), 7);
        assert_eq!(chain.last().unwrap().len(), 1);
        assert!((chain.last().unwrap()[0] - mean0).abs() < 1e-4);
    }

    /// The memory checks count a chain's texels without building it: the count is the chain's,
    /// for square, oblong, odd and one-texel sizes (a body atlas is 8192 rows at most).
    #[test]
    fn chain_texels_counts_the_levels_mip_chain_makes() {
        for (w, h) in [(1, 1), (64, 64), (64, 32), (5, 3), (682, 8184), (1, 9), (1024, 1)] {
            let built: usize = mip_chain(vec![0f32; w * h], w, h).iter().map(Vec::len).sum();
            assert_eq!(chain_texels(w, h), built as u64, "{w}×{h}");
        }
        assert_eq!(packed_bytes(2, 2), (4 + 1) * 36);
        assert_eq!(texture_bytes(2, 2), (4 + 1) * 18);
    }
}
