//! The five maps as GPU textures. The renderer takes the generator's f32 maps directly (no PNG
//! round trip) and packs them into three filterable half-float textures with a full mip
//! chain built on the CPU (2×2 box, colour averaged in linear light), so distant scales
//! average instead of shimmering:
//! `albedo_roughness` (linear colour, perceptual roughness), `normal_height` (tangent-space
//! normal in [-1, 1], height), `thickness_moments` (iridescence map value t in [0, 1] and
//! (t − ½)²).
//!
//! The thickness map's second channel is there for the film seen from afar: a mip texel
//! covers scales of many thicknesses, and the film colour of their mean thickness is far
//! more saturated than the mean of their colours (BENCHMARKS.md, "Iridescence seen from
//! afar"). The filtered pair gives the footprint's mean and variance (`scene.wgsl`'s
//! `sample_material`), and the shader reads the film at two thicknesses either side of the
//! mean and averages the reads (`footprint_offset_nm`; `skin.wgsl`'s `film_offset_nm`). The
//! square is taken about ½, the middle of the map's range, not about 0: the variance is a
//! difference of two filtered values, and half floats round (t − ½)² ≤ ¼ more finely than
//! t² ≤ 1, so a map of one thickness reads a spread of at most 0.0172 of the range instead
//! of 0.0268 (`THICKNESS_SPREAD_MIN` ignores what is left).

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
    /// Per texel (t, (t − `THICKNESS_MOMENT_CENTRE`)²), t the iridescence map value.
    pub thickness_moments: Vec<Vec<[f32; 2]>>,
}

/// The value the thickness texture's second channel squares its distance from: the middle
/// of the iridescence map's [0, 1] (the shader's `THICKNESS_MOMENT_CENTRE`).
pub const THICKNESS_MOMENT_CENTRE: f32 = 0.5;

/// The thickness spread (standard deviation, as a fraction of the map's range) under which
/// the shader reads one thickness: the most that half-float rounding of the texture's two
/// channels puts into a footprint of one thickness is about 0.0175
/// (`half_float_rounding_stays_under_the_spread_threshold`), so a spread below this is not
/// one the map holds.
pub const THICKNESS_SPREAD_MIN: f32 = 0.02;

/// The wavelength whose film colour the footprint's two thicknesses average exactly (in the
/// first harmonic): the green of `rgb3` (`RGB3_NM`), near the 555 nm peak of CIE 1931 ȳ.
pub const FOOTPRINT_WAVELENGTH_NM: f64 = crate::optics::methods::RGB3_NM[1] as f64;

/// How far from the mean thickness the shader's two thicknesses lie (nm), for a footprint
/// whose thicknesses spread with standard deviation `spread_nm`, seen at cosine `cos_o` in
/// the medium n0 above a film of index n1 (`skin.wgsl`'s `footprint_offset_nm` is the
/// twin).
///
/// Why not ± the spread (the two-point Gauss–Hermite rule): the film's reflectance is a
/// Fourier series in the phase p·d, p = 2k = 4π n1 cos θ1 / λ (the Airy sum), and a spread of
/// thicknesses damps its first harmonic by exp(−½ (2kσ)²) for a normal distribution — to
/// nothing once σ is a good part of a period (about 180 nm in green for n1 = 1.55). Two
/// points at ± s damp it by cos(2k s), which at s = σ turns negative beyond 2kσ = π/2: a
/// distant snake took the complementary colour (tried: `benches/far_field.sh` ΔE00 6.94 →
/// 5.63 only, its chroma 9.65 against the supersampled frame's 13.10). Choosing s with
/// cos(2k s) = exp(−½ (2kσ)²) matches the damping of the first harmonic at
/// `FOOTPRINT_WAVELENGTH_NM` exactly, at every spread: s → σ for small spreads, a quarter
/// period (the harmonic cancelled, the film's mean reflectance left) for large ones. What it
/// does not match: the other wavelengths (at a large spread the first harmonic keeps a
/// factor of −0.34 at 450 nm and +0.24 at 650 nm where a normal spread leaves none), the
/// higher harmonics (the second turned over in full: cos 2ps → −1; weak for a film that
/// reflects little), and the directions other than the view's (the shader computes s once a
/// pixel, at the view's cosine, and reads the light's side and the half vector's with it).
/// For ½(pσ)² under 1e-4 it is σ (within 2e-5 relative): there acos(exp(−x)) loses its digits in
/// f32, and the shader's twin returned 0 for a spread of 5 nm just past a film's critical
/// angle (n1 < n0), where p is small.
pub fn footprint_offset_nm(spread_nm: f64, n0: f64, n1: f64, cos_o: f64) -> f64 {
    let cos1 = crate::optics::film::snell_cos_sq(n0, n1, cos_o).max(0.0).sqrt();
    // 2k: the phase per nm of thickness (the round trip through the film).
    let phase_per_nm = 4.0 * std::f64::consts::PI * n1 * cos1 / FOOTPRINT_WAVELENGTH_NM;
    if phase_per_nm <= 0.0 {
        return spread_nm;
    }
    let exponent = 0.5 * (phase_per_nm * spread_nm).powi(2);
    if exponent < FOOTPRINT_SMALL_EXPONENT {
        return spread_nm;
    }
    (-exponent).exp().acos() / phase_per_nm
}

/// Below this ½(pσ)², `footprint_offset_nm` is the spread itself (its expansion: s = σ (1 −
/// x/6 + …), so within 2e-5 relative).
pub const FOOTPRINT_SMALL_EXPONENT: f64 = 1e-4;

/// The spread the shader reads from one texel of the thickness texture, as a fraction of the
/// map's range, before `THICKNESS_SPREAD_MIN`: the texel's half floats, (t − c)² less the
/// square of (t − c) (`scene.wgsl`'s `sample_material`; for tests, which look for the map
/// values whose rounding reads most).
pub fn rounded_texel_spread(texel: [f32; 2]) -> f32 {
    let [t, square] = texel.map(round_to_f16);
    let d = t - THICKNESS_MOMENT_CENTRE;
    (square - d * d).max(0.0).sqrt()
}

/// A texel of the thickness texture: the map value and its square about the centre.
pub fn thickness_moments(value: f32) -> [f32; 2] {
    let d = value - THICKNESS_MOMENT_CENTRE;
    [value, d * d]
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
        let t: Vec<[f32; 2]> = (0..w * h).map(|i| thickness_moments(px(irid, i, 0))).collect();
        Ok(MaterialMaps {
            width: w,
            height: h,
            atlas: None,
            albedo_roughness: mip_chain(ar, w, h),
            normal_height: mip_chain(nh, w, h),
            thickness_moments: mip_chain(t, w, h),
        })
    }

    pub fn levels(&self) -> usize {
        self.thickness_moments.len()
    }
}

/// The three textures' formats, in binding order.
pub const ALBEDO_ROUGHNESS_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
pub const NORMAL_HEIGHT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
pub const THICKNESS_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rg16Float;

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

/// Bytes of `MaterialMaps`' packed f32 chains for `width`×`height` maps (16 + 16 + 8 per
/// texel, every level), for the memory checks before anything is generated.
pub fn packed_bytes(width: usize, height: usize) -> u64 {
    let per_texel = 2 * std::mem::size_of::<[f32; 4]>() + std::mem::size_of::<[f32; 2]>();
    chain_texels(width, height) * per_texel as u64
}

/// Bytes of the three textures `MaterialTextures::new` makes for `width`×`height` maps
/// (8 + 8 + 4 per texel, every level): device memory on a GPU, host memory on lavapipe.
pub fn texture_bytes(width: usize, height: usize) -> u64 {
    let texel = |f: wgpu::TextureFormat| f.block_copy_size(None).expect("colour formats have a size") as u64;
    let per_texel = texel(ALBEDO_ROUGHNESS_FORMAT) + texel(NORMAL_HEIGHT_FORMAT) + texel(THICKNESS_FORMAT);
    chain_texels(width, height) * per_texel
}

/// Anything a 2×2 box filter can average.
pub trait Texel: Copy {
    fn average(a: Self, b: Self, c: Self, d: Self) -> Self;
}

impl Texel for f32 {
    fn average(a: f32, b: f32, c: f32, d: f32) -> f32 {
        0.25 * (a + b + c + d)
    }
}

impl<const N: usize> Texel for [f32; N] {
    fn average(a: Self, b: Self, c: Self, d: Self) -> Self {
        std::array::from_fn(|k| 0.25 * (a[k] + b[k] + c[k] + d[k]))
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
            upload(&th, maps.thickness_moments[level].iter().flat_map(|t| t.map(f32_to_f16)).collect(), 4);
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

    /// A footprint of one thickness reads a spread under `THICKNESS_SPREAD_MIN` after the
    /// texture's half-float rounding, at every map value (every f16 step and between), and a
    /// footprint of many reads its true standard deviation to within the same rounding:
    /// every texel of every level of random maps, against the variance of the level-0
    /// block it averages (f64). Seen failing with the square taken about 0 (t², whose half
    /// floats round four times as coarsely near 1): 0.0271 from one thickness.
    #[test]
    fn half_float_rounding_stays_under_the_spread_threshold() {
        let mut worst_one: f32 = 0.0;
        for k in 0..=200_000 {
            let t = k as f32 / 200_000.0;
            worst_one = worst_one.max(rounded_texel_spread(thickness_moments(t)));
        }
        eprintln!("one thickness: at most {worst_one:.4} of the range");
        assert!(worst_one < THICKNESS_SPREAD_MIN, "one thickness reads a spread of {worst_one}");
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut random = || {
            state = state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        let mut worst_var: f64 = 0.0;
        for _ in 0..20 {
            let (w, h) = (32, 32);
            let level0: Vec<f32> = (0..w * h).map(|_| random()).collect();
            let chain = mip_chain(level0.iter().map(|&t| thickness_moments(t)).collect(), w, h);
            for (level, texels) in chain.iter().enumerate() {
                let (lw, block) = (w >> level, 1usize << level);
                for (i, &texel) in texels.iter().enumerate() {
                    let (x0, y0) = ((i % lw) * block, (i / lw) * block);
                    let values: Vec<f64> = (y0..y0 + block)
                        .flat_map(|y| (x0..x0 + block).map(move |x| (x, y)))
                        .map(|(x, y)| level0[y * w + x] as f64)
                        .collect();
                    let mean = values.iter().sum::<f64>() / values.len() as f64;
                    let var = values.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / values.len() as f64;
                    let read = rounded_texel_spread(texel) as f64;
                    worst_var = worst_var.max((read * read - var).abs());
                }
            }
        }
        eprintln!("random maps: variance read to within {worst_var:.2e}");
        assert!(worst_var < (THICKNESS_SPREAD_MIN * THICKNESS_SPREAD_MIN) as f64, "{worst_var}");
    }

    /// The two thicknesses `footprint_offset_nm` places average the film colour over a
    /// spread of thicknesses better than the mean thickness alone and better than ± the
    /// spread, against the 1 nm spectral film colour averaged over the spread (241 points,
    /// f64), for normal and for uniform spreads of the thesis' film at 15 to 150 nm, across
    /// its colours (means 250 to 650 nm) and two view angles; and the offset is the spread
    /// where the spread is small and a quarter of the green's period where it is large.
    /// Measured: mean / worst ΔE00 2.53 / 8.88 for the offset, 7.45 / 25.05 for ± the
    /// spread, 12.69 / 33.72 for the mean thickness.
    #[test]
    fn the_footprints_two_thicknesses_average_the_film_over_the_spread() {
        use crate::optics::film::Stack;
        use crate::optics::film_rgb_reference;
        use crate::optics::lab::{ciede2000, linear_srgb_to_lab};
        let stack = Stack::THESIS;
        let de = |a: [f64; 3], b: [f64; 3]| ciede2000(linear_srgb_to_lab(a), linear_srgb_to_lab(b));
        let mut worst = [0.0f64; 3];
        let mut total = [0.0f64; 3];
        let mut count = 0;
        for cos_o in [1.0, 0.6] {
            let period_nm = FOOTPRINT_WAVELENGTH_NM
                / (2.0 * stack.n1 * (1.0 - (1.0 - cos_o * cos_o) / (stack.n1 * stack.n1)).sqrt());
            assert!((footprint_offset_nm(1.0, stack.n0, stack.n1, cos_o) - 1.0).abs() < 1e-3);
            assert!((footprint_offset_nm(500.0, stack.n0, stack.n1, cos_o) - period_nm / 4.0).abs() < 1e-6);
            for normal in [true, false] {
                for mean in (250..=650).step_by(50).map(f64::from) {
                    for spread in [15.0, 40.0, 80.0, 150.0] {
                        let film = |d: f64| film_rgb_reference(stack, d.max(0.0), cos_o);
                        // z over ±6 (normal) or ±√3 (uniform), weights by the density.
                        let (reach, density): (f64, fn(f64) -> f64) =
                            if normal { (6.0, |z| (-0.5 * z * z).exp()) } else { (3f64.sqrt(), |_| 1.0) };
                        let zs: Vec<f64> = (0..=240).map(|j| -reach + 2.0 * reach * j as f64 / 240.0).collect();
                        let weights: Vec<f64> = zs.iter().map(|&z| density(z)).collect();
                        let sum: f64 = weights.iter().sum();
                        let mut truth = [0.0; 3];
                        for (z, w) in zs.iter().zip(&weights) {
                            let c = film(mean + spread * z);
                            for k in 0..3 {
                                truth[k] += c[k] * w / sum;
                            }
                        }
                        let pair = |s: f64| {
                            let (a, b) = (film(mean - s), film(mean + s));
                            [0, 1, 2].map(|k| 0.5 * (a[k] + b[k]))
                        };
                        let offset = footprint_offset_nm(spread, stack.n0, stack.n1, cos_o);
                        let errors = [de(pair(offset), truth), de(pair(spread), truth), de(film(mean), truth)];
                        for k in 0..3 {
                            worst[k] = worst[k].max(errors[k]);
                            total[k] += errors[k];
                        }
                        count += 1;
                    }
                }
            }
        }
        let mean_error = total.map(|t| t / count as f64);
        eprintln!(
            "mean / worst ΔE00: the offset {:.2} / {:.2}, ± the spread {:.2} / {:.2}, the mean thickness {:.2} / {:.2}",
            mean_error[0], worst[0], mean_error[1], worst[1], mean_error[2], worst[2]
        );
        assert!(mean_error[0] < mean_error[1] && mean_error[0] < mean_error[2], "{mean_error:?}");
        assert!(mean_error[0] < 4.0, "the offset's mean ΔE00 {}", mean_error[0]);
        assert!(worst[0] < worst[1] && worst[0] < worst[2], "{worst:?}");
    }

    /// The memory checks count a chain's texels without building it: the count is the chain's,
    /// for square, oblong, odd and one-texel sizes (a body atlas is 8192 rows at most).
    #[test]
    fn chain_texels_counts_the_levels_mip_chain_makes() {
        for (w, h) in [(1, 1), (64, 64), (64, 32), (5, 3), (682, 8184), (1, 9), (1024, 1)] {
            let built: usize = mip_chain(vec![0f32; w * h], w, h).iter().map(Vec::len).sum();
            assert_eq!(chain_texels(w, h), built as u64, "{w}×{h}");
        }
        assert_eq!(packed_bytes(2, 2), (4 + 1) * 40);
        assert_eq!(texture_bytes(2, 2), (4 + 1) * 20);
    }
}
