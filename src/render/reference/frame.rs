//! The CPU reference for a rendered frame: shade every pixel the snake covers from the GPU's
//! own G-buffer (the sampled material: position, shading normal, albedo, roughness, film
//! thickness and its spread over the pixel) with the f64 BRDF and the 1 nm spectral film
//! colour, under the same lights, ambient term, exposure and tone mapping, and compare with
//! the GPU image in CIEDE2000.
//!
//! Because both sides start from the same material samples, the difference isolates shading:
//! the film method (LUT or another), f32 arithmetic, how a spread of thicknesses is read
//! (`shade_pixel`), and the 8-bit output. This file is the
//! CPU twin of `shaders/skin.wgsl`'s `shade` (stage "all") and `shaders/tonemap.wgsl`.

use rayon::prelude::*;

use crate::Error;
use crate::export::srgb;
use crate::optics::brdf::COS_MIN;
use crate::optics::film_rgb_reference;
use crate::optics::lab::{ciede2000, linear_srgb_to_lab};
use crate::render::engine::material::footprint_offset_nm;
use crate::render::engine::renderer::{FrameSettings, GBuffer, Material, Renderer};
use crate::render::engine::scene::BounceGrid;
use crate::render::engine::scene::{LayerOptics, Lighting, Stage, View};

/// The GPU frame at one sample per pixel against the CPU reference (stage "all").
pub fn reference_check(
    renderer: &Renderer,
    material: &Material,
    settings: &FrameSettings,
    width: u32,
    height: u32,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<(ReferenceReport, image::RgbaImage), Error> {
    let settings = FrameSettings { samples: 1, ground: false, view: View::Shaded(Stage::All), ..*settings };
    let image = renderer.render_image(&settings, material, width, height)?;
    let gbuffer = renderer.render_gbuffer(&settings, material, width, height)?;
    let report = compare(&image, &gbuffer, &settings, &material.optics, progress);
    // No pixel compared is no check: it printed "0 pixels, CIEDE2000 mean NaN" and passed (a
    // hostile-input review: a frame 16 wide with 400 snakes).
    if report.pixels == 0 {
        return Err(Error::Unsupported(format!(
            "the {width}×{height} frame shows no pixel of a snake, so nothing was compared with the CPU \
             reference: give a larger size or fewer snakes"
        )));
    }
    Ok((report, image))
}

/// Mean, 99th percentile and max CIEDE2000 over covered pixels, and the heat map.
#[derive(Debug, Clone)]
pub struct ReferenceReport {
    pub mean_de: f64,
    pub p99_de: f64,
    pub max_de: f64,
    pub pixels: usize,
    /// ΔE per pixel (`None` where the snake does not cover it).
    pub de: Vec<Option<f64>>,
    pub width: u32,
    pub height: u32,
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn normalize(v: [f64; 3]) -> [f64; 3] {
    let len = dot(v, v).sqrt();
    v.map(|c| c / len)
}

fn sky(lighting: &Lighting, d: [f64; 3]) -> [f64; 3] {
    let t = (0.5 + 0.5 * d[1]).clamp(0.0, 1.0);
    [0, 1, 2].map(|c| lighting.sky_bottom[c] as f64 + (lighting.sky_top[c] as f64 - lighting.sky_bottom[c] as f64) * t)
}

/// Khronos PBR Neutral (KHR PBR Neutral Tone Mapper, 2024): the toe offset F90 = 0.04, the
/// compression start 0.8 − F90 and the desaturation 0.15. `tonemap.wgsl` reads them from
/// the generated prelude.
pub const PBR_NEUTRAL_OFFSET: f64 = 0.04;
pub const PBR_NEUTRAL_START_COMPRESSION: f64 = 0.8 - PBR_NEUTRAL_OFFSET;
pub const PBR_NEUTRAL_DESATURATION: f64 = 0.15;

/// Khronos PBR Neutral tone mapping (the twin of `tonemap.wgsl`'s `pbr_neutral`).
pub fn pbr_neutral(color: [f64; 3]) -> [f64; 3] {
    const START_COMPRESSION: f64 = PBR_NEUTRAL_START_COMPRESSION;
    const DESATURATION: f64 = PBR_NEUTRAL_DESATURATION;
    let x = color[0].min(color[1]).min(color[2]);
    // The toe: x − x² / (4 F90) below 2 F90 (= x − 6.25 x² for F90 = 0.04).
    let offset = if x < 2.0 * PBR_NEUTRAL_OFFSET { x - x * x / (4.0 * PBR_NEUTRAL_OFFSET) } else { PBR_NEUTRAL_OFFSET };
    let mut c = color.map(|v| v - offset);
    let peak = c[0].max(c[1]).max(c[2]);
    if peak < START_COMPRESSION {
        return c;
    }
    let d = 1.0 - START_COMPRESSION;
    let new_peak = 1.0 - d * d / (peak + d - START_COMPRESSION);
    c = c.map(|v| v * new_peak / peak);
    let g = 1.0 - 1.0 / (DESATURATION * (peak - new_peak) + 1.0);
    c.map(|v| v + (new_peak - v) * g)
}

/// Linear radiance of one covered pixel (stage "all"), the twin of `skin.wgsl`'s `shade`.
/// Where the G-buffer holds a thickness spread over the pixel's footprint, the mean of the
/// radiance shaded at two thicknesses either side of the mean (`footprint_offset_nm`): the
/// two-point rule applied to what the pixel shows. The shader applies it to each film read
/// instead (the film colour, the top's coupling: `brdf.wgsl`'s `film_clamped` and
/// `coupling_table`) and reads K, E and the base albedo at the mean, so the comparison
/// measures that too (for a material without a film, whose shader reads one thickness,
/// the two shadings are the same).
pub fn shade_pixel(
    gbuffer: &GBuffer,
    i: usize,
    settings: &FrameSettings,
    optics: &LayerOptics,
    bounce: &BounceGrid,
) -> [f64; 3] {
    let pt = gbuffer.position_thickness[i].map(|v| v as f64);
    let nr = gbuffer.normal_roughness[i].map(|v| v as f64);
    let camera = settings.camera.position().to_array().map(|v| v as f64);
    let n = normalize([nr[0], nr[1], nr[2]]);
    let wo = normalize([camera[0] - pt[0], camera[1] - pt[1], camera[2] - pt[2]]);
    let (thickness, spread) = (pt[3], gbuffer.albedo_spread[i][3] as f64);
    let shade = |thickness| shade_at(gbuffer, i, thickness, (n, wo), settings, optics, bounce);
    if spread <= 0.0 {
        return shade(thickness);
    }
    let stack = optics.stack;
    let offset = footprint_offset_nm(spread, stack.n0, stack.n1, dot(n, wo).max(COS_MIN));
    let (thin, thick) = (shade((thickness - offset).max(0.0)), shade(thickness + offset));
    [0, 1, 2].map(|c| 0.5 * (thin[c] + thick[c]))
}

/// Linear radiance of one covered pixel with the film at `thickness` (nm), its shading
/// normal `n` seen along `wo` (`shade_pixel` computes them once for both thicknesses).
fn shade_at(
    gbuffer: &GBuffer,
    i: usize,
    thickness: f64,
    (n, wo): ([f64; 3], [f64; 3]),
    settings: &FrameSettings,
    optics: &LayerOptics,
    bounce: &BounceGrid,
) -> [f64; 3] {
    let roughness = gbuffer.normal_roughness[i][3] as f64;
    let albedo = gbuffer.albedo_spread[i].map(|v| v as f64);
    // Each light asks for the film at the same view cosine (421 Airy evaluations each): keep
    // every colour computed for this pixel, keyed by the exact cosine.
    let computed: std::cell::RefCell<Vec<(u64, [f64; 3])>> = Default::default();
    let film = |cos: f64| {
        if let Some((_, rgb)) = computed.borrow().iter().find(|(bits, _)| *bits == cos.to_bits()) {
            return *rgb;
        }
        let rgb = film_rgb_reference(optics.stack, thickness, cos);
        computed.borrow_mut().push((cos.to_bits(), rgb));
        rgb
    };
    let layers = optics.layers(settings.model, bounce, thickness, roughness, [albedo[0], albedo[1], albedo[2]]);
    let lighting = &settings.lighting;
    let mut radiance = [0.0; 3];
    for light in lighting.lights() {
        if !light.enabled {
            continue;
        }
        let wi = light.direction.normalize().to_array().map(|v| v as f64);
        let cos_i = dot(n, wi).max(0.0);
        let f = settings.model.eval(&layers, n, wi, wo, &film).total();
        for c in 0..3 {
            radiance[c] += light.irradiance[c] as f64 * f[c] * cos_i;
        }
    }
    // Ambient, as skin.wgsl's `ambient`: the sky along the mirror direction reflected by the
    // film, the sky along the normal through the layer model.
    let cos_o = dot(n, wo).max(COS_MIN);
    let film_clamped = |c: f64| film(c).map(|v| v.clamp(0.0, 1.0));
    let s_o = settings.model.coupling(cos_o, &layers, &film_clamped).reflected;
    let mirror = [0, 1, 2].map(|c| -wo[c] + 2.0 * dot(n, wo) * n[c]);
    let sky_mirror = sky(lighting, mirror);
    let sky_normal = sky(lighting, n);
    let diffuse = settings.model.ambient_diffuse(&layers, cos_o, s_o);
    for c in 0..3 {
        radiance[c] += sky_mirror[c] * s_o[c] + sky_normal[c] * diffuse[c];
    }
    radiance
}

/// Display value in [0, 1] (sRGB-encoded) after exposure and tone mapping.
pub fn display(radiance: [f64; 3], exposure: f64) -> [f64; 3] {
    pbr_neutral(radiance.map(|v| v.max(0.0) * exposure)).map(srgb::encode)
}

/// Shades every covered pixel on the CPU and compares with the GPU's 8-bit image.
pub fn compare(
    gpu_image: &image::RgbaImage,
    gbuffer: &GBuffer,
    settings: &FrameSettings,
    optics: &LayerOptics,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> ReferenceReport {
    // K and E per roughness row, once for the frame (the shader's `Scene.bounce`).
    let bounce = optics.bounce_grid(settings.model);
    let exposure = settings.exposure as f64;
    // The spectral shading costs milliseconds a pixel: progress in covered pixels, every
    // 256 of them.
    let total = (0..(gbuffer.width * gbuffer.height) as usize).filter(|&i| gbuffer.covered(i)).count();
    let done = std::sync::atomic::AtomicUsize::new(0);
    let de: Vec<Option<f64>> = (0..(gbuffer.width * gbuffer.height) as usize)
        .into_par_iter()
        .map(|i| {
            if !gbuffer.covered(i) {
                return None;
            }
            let cpu = display(shade_pixel(gbuffer, i, settings, optics, &bounce), exposure).map(srgb::decode);
            let shaded = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
            if shaded.is_multiple_of(256) {
                progress(shaded, total);
            }
            let px = gpu_image.as_raw()[4 * i..4 * i + 3].iter().map(|v| srgb::decode(*v as f64 / 255.0));
            let gpu: Vec<f64> = px.collect();
            Some(ciede2000(linear_srgb_to_lab(cpu), linear_srgb_to_lab([gpu[0], gpu[1], gpu[2]])))
        })
        .collect();
    progress(total, total);
    let mut values: Vec<f64> = de.iter().flatten().copied().collect();
    values.sort_by(f64::total_cmp);
    let pixels = values.len();
    let mean_de = if pixels == 0 { f64::NAN } else { values.iter().sum::<f64>() / pixels as f64 };
    let p99_de =
        values.get(((pixels as f64 * 0.99) as usize).min(pixels.saturating_sub(1))).copied().unwrap_or(f64::NAN);
    ReferenceReport {
        mean_de,
        p99_de,
        max_de: values.last().copied().unwrap_or(f64::NAN),
        pixels,
        de,
        width: gbuffer.width,
        height: gbuffer.height,
    }
}

impl ReferenceReport {
    /// ΔE as a heat map: black 0, through purple and orange, to yellow at `full_scale` and
    /// above; pixels outside the snake dark grey.
    pub fn heat_map(&self, full_scale: f64) -> image::RgbImage {
        const STOPS: [[f64; 3]; 4] = [[0.0, 0.0, 0.0], [0.45, 0.1, 0.55], [0.95, 0.45, 0.1], [1.0, 1.0, 0.3]];
        image::RgbImage::from_fn(self.width, self.height, |x, y| match self.de[(y * self.width + x) as usize] {
            None => image::Rgb([40, 40, 40]),
            Some(de) => {
                let t = (de / full_scale).clamp(0.0, 1.0) * 3.0;
                let k = (t as usize).min(2);
                let f = t - k as f64;
                let c = [0, 1, 2].map(|c| STOPS[k][c] + (STOPS[k + 1][c] - STOPS[k][c]) * f);
                image::Rgb(c.map(|v| (v * 255.0).round() as u8))
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pbr_neutral_leaves_dark_colours_and_compresses_bright_ones() {
        // Below the compression start only the small toe offset applies.
        let c = pbr_neutral([0.5, 0.3, 0.2]);
        assert!((c[0] - 0.46).abs() < 1e-9 && (c[2] - 0.16).abs() < 1e-9, "{c:?}");
        // Bright white approaches but never reaches 1.
        let w = pbr_neutral([100.0; 3]);
        assert!(w[0] < 1.0 && w[0] > 0.99, "{w:?}");
    }
}
