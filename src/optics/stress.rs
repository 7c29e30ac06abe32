//! `snakeskin brdf stress`: random and adversarial inputs through the film and the BRDF,
//! f64 and f32, counting anything non-finite and the worst of every bound PHYSICS.md sets.
//!
//! Adversarial on purpose: grazing (cos = 0 and 1e-9) and back-facing directions, d = 0 and
//! 10 mm, n1 = n0, n2 < n1, n0 > n2 (total internal reflection), n2 = n0 (no interface without
//! the film) and n2 a millionth above n0, roughness 0 and 1, τ = 0 and 50, zero-length and
//! back-facing normals. The film goes through f64 (R, T and R + T = 1: every index is real, so
//! nothing is absorbed) and through the f32 kernels the real-time film methods and the shader
//! share (`fast`, `methods`). Samples are generated from (seed, index) alone, so a report is
//! reproducible at any thread count.

use rayon::prelude::*;

use super::brdf::{Layers, Model};
use super::fast;
use super::film::{Stack, airy, incoherent};
use super::lut::Lut;
use super::methods;
use super::spectrum::{LAMBDA_MAX_NM, LAMBDA_MIN_NM};
use crate::ops::hash;

#[derive(Debug, Clone, serde::Serialize)]
pub struct StressReport {
    pub samples: u64,
    pub nan: u64,
    pub inf: u64,
    /// Smallest and largest of R_s, R_p, R, T_s, T_p, T seen (must stay in [0, 1]).
    pub min_r: f64,
    pub max_r: f64,
    /// Largest |R + T − 1| of the f64 film, per polarisation, exact and incoherent: the
    /// stress' indices are real, so the film absorbs nothing.
    pub film_energy_err: f64,
    /// Smallest and largest f32 film reflectance seen: the exact film and the prefiltered
    /// series band (`fast::airy_reflectance_f32`, `fast::band_reflectance_f32`), which must
    /// stay in [0, 1]; the f32 film colours (rgb3, spectral-8, gaussian-fit) are counted for
    /// NaN and Inf only (a saturated film colour lies outside sRGB's [0, 1]).
    pub film_f32_min_r: f64,
    pub film_f32_max_r: f64,
    /// Largest |R_f32 − R_f64| of the exact film at one wavelength, for films up to
    /// `F32_FILM_DEV_MAX_NM` (beyond, f32 cannot hold the phase: 4π n1 d / λ is 10⁶ rad at
    /// 10 mm, where f32's spacing is 0.06 rad).
    pub max_film_f32_dev: f64,
    /// Largest white-furnace albedo (k_d = 1, τ = 0) over the furnace subset, for the
    /// models that must never reflect more than arrives (the thesis model).
    pub max_albedo: f64,
    /// Smallest and largest white-furnace albedo of each model, with K and E of the film
    /// drawn. The layered model holds albedo 1 within its furnace bounds up to 89°; the
    /// stress also views at 89.94° (cos 0.001), where a mirror-smooth top reads 0.79–0.86, and
    /// draws n0 = 1.5 over n2 = 1, where tops of roughness 0.87 and more reflect up to 1.05
    /// (`layered::PigmentBelowAmbient`; before the model followed the light beyond the
    /// critical angle, 0.44 there), and a pigment a millionth denser than the ambient, where
    /// near-mirror tops at 89.94° read up to 2.1 through the film table (0.99 through the
    /// exact film: BENCHMARKS, "Stress").
    pub furnace_by_model: Vec<ModelFurnace>,
    /// Largest |f32 − f64| / (1 + |f64|) of the BRDF.
    pub max_f32_dev: f64,
    pub furnace_evaluations: u64,
    /// The layer models every sample went through (the bounds above are over all of them).
    pub models: Vec<&'static str>,
}

#[derive(Debug, Clone, serde::Serialize)]
pub struct ModelFurnace {
    pub model: &'static str,
    pub min_albedo: f64,
    pub max_albedo: f64,
}

/// The materials the stress draws from: the thesis default and its edge cases.
pub const STRESS_MATERIALS: [Stack; 9] = [
    Stack::THESIS,
    Stack { n0: 1.0, n1: 1.0, n2: 2.0 },
    Stack { n0: 1.0, n1: 1.56, n2: 1.33 },
    Stack { n0: 1.5, n1: 1.55, n2: 1.0 },
    Stack { n0: 1.33, n1: 1.55, n2: 2.0 },
    Stack { n0: 1.0, n1: 3.0, n2: 1.0 },
    Stack { n0: 1.0, n1: 2.0, n2: 2.0 },
    // No interface without the film, and a pigment a millionth denser than the ambient: a film
    // of 0 nm passes everything here, and the f32 films read NaN near grazing until
    // `fast::Film32::passes_all`.
    Stack { n0: 1.33, n1: 1.55, n2: 1.33 },
    Stack { n0: 1.0, n1: 1.55, n2: 1.000001 },
];

/// The thickest film whose f32 reflectance the stress compares with f64 (see
/// `StressReport::max_film_f32_dev`): the thin-film chart's range, about three times the
/// built-in species' thickest films (xenopeltis: 420 nm, spread 260).
pub const F32_FILM_DEV_MAX_NM: f64 = 2000.0;

/// One furnace integration per this many samples (it costs ~2000 BRDF evaluations).
const FURNACE_EVERY: u64 = 2000;

struct Draw {
    seed: u32,
    index: u64,
    stream: u32,
}

impl Draw {
    fn unit(&mut self) -> f64 {
        self.stream += 1;
        let lo = hash::unit(self.index as i32, (self.index >> 31) as i32, self.stream, self.seed) as f64;
        let hi = hash::unit(self.index as i32, (self.index >> 31) as i32, self.stream + 1000, self.seed) as f64;
        (lo + hi / (1u64 << 24) as f64).min(1.0 - 1e-15)
    }
    fn pick<T: Copy>(&mut self, options: &[T]) -> T {
        options[((self.unit() * options.len() as f64) as usize).min(options.len() - 1)]
    }
    fn direction(&mut self) -> [f64; 3] {
        let kind = self.pick(&[0, 0, 0, 1, 2, 3]);
        let phi = self.unit() * std::f64::consts::TAU;
        let cos = match kind {
            0 => self.unit() * 2.0 - 1.0, // anywhere on the sphere, back-facing included
            1 => 0.0,                     // exactly grazing
            2 => 1e-9,                    // almost grazing
            _ => 1.0,
        };
        let sin = (1.0 - cos * cos).max(0.0).sqrt();
        [sin * phi.cos(), sin * phi.sin(), cos]
    }
}

pub fn run(samples: u64, seed: u32) -> StressReport {
    let luts: Vec<Lut> = STRESS_MATERIALS.iter().map(|s| Lut::bake_default(*s)).collect();
    let partials: Vec<StressReport> = (0..samples)
        .into_par_iter()
        .fold(empty, |mut acc, index| {
            sample(&mut acc, &luts, Draw { seed, index, stream: 0 });
            acc
        })
        .collect();
    let mut total = empty();
    for p in partials {
        total.samples += p.samples;
        total.nan += p.nan;
        total.inf += p.inf;
        total.min_r = total.min_r.min(p.min_r);
        total.max_r = total.max_r.max(p.max_r);
        total.film_energy_err = total.film_energy_err.max(p.film_energy_err);
        total.film_f32_min_r = total.film_f32_min_r.min(p.film_f32_min_r);
        total.film_f32_max_r = total.film_f32_max_r.max(p.film_f32_max_r);
        total.max_film_f32_dev = total.max_film_f32_dev.max(p.max_film_f32_dev);
        total.max_albedo = total.max_albedo.max(p.max_albedo);
        for (t, q) in total.furnace_by_model.iter_mut().zip(&p.furnace_by_model) {
            t.min_albedo = t.min_albedo.min(q.min_albedo);
            t.max_albedo = t.max_albedo.max(q.max_albedo);
        }
        total.max_f32_dev = total.max_f32_dev.max(p.max_f32_dev);
        total.furnace_evaluations += p.furnace_evaluations;
    }
    total
}

fn empty() -> StressReport {
    StressReport {
        samples: 0,
        nan: 0,
        inf: 0,
        min_r: f64::INFINITY,
        max_r: f64::NEG_INFINITY,
        film_energy_err: 0.0,
        film_f32_min_r: f64::INFINITY,
        film_f32_max_r: f64::NEG_INFINITY,
        max_film_f32_dev: 0.0,
        max_albedo: 0.0,
        max_f32_dev: 0.0,
        furnace_evaluations: 0,
        models: Model::ALL.iter().map(|m| m.name()).collect(),
        furnace_by_model: Model::ALL
            .iter()
            .map(|m| ModelFurnace { model: m.name(), min_albedo: f64::INFINITY, max_albedo: f64::NEG_INFINITY })
            .collect(),
    }
}

fn count(acc: &mut StressReport, values: &[f64]) {
    for v in values {
        if v.is_nan() {
            acc.nan += 1;
        } else if v.is_infinite() {
            acc.inf += 1;
        }
    }
}

fn sample(acc: &mut StressReport, luts: &[Lut], mut draw: Draw) {
    acc.samples += 1;
    let material = draw.pick(&[0, 1, 2, 3, 4, 5, 6, 7, 8]);
    let stack = STRESS_MATERIALS[material];
    let thickness = match draw.pick(&[0, 1, 2, 3]) {
        0 => 0.0,
        1 => 1.0e7,
        2 => 10f64.powf(draw.unit() * 7.0),
        _ => draw.unit() * 2000.0,
    };
    let roughness = draw.pick(&[0.0, 1.0, -1.0]);
    let roughness = if roughness < 0.0 { draw.unit() } else { roughness };
    let tau = draw.pick(&[0.0, 50.0, -1.0]);
    let tau = if tau < 0.0 { draw.unit() * 5.0 } else { tau };
    let normal = match draw.pick(&[0, 1, 2, 2, 2]) {
        0 => [0.0; 3],
        1 => [0.0, 0.0, -1.0],
        _ => draw.direction(),
    };
    let (wi, wo) = (draw.direction(), draw.direction());

    // Film R and T at a random wavelength and angle.
    let cos0 = draw.pick(&[0.0, 1e-9, 1.0, -1.0]);
    let cos0 = if cos0 < 0.0 { draw.unit() } else { cos0 };
    let wavelength_nm = f64::from(LAMBDA_MIN_NM) + draw.unit() * f64::from(LAMBDA_MAX_NM - LAMBDA_MIN_NM);
    let film = airy(stack, thickness, wavelength_nm, cos0);
    let inc = incoherent(stack, cos0);
    let rt = [film.rs, film.rp, film.r, film.ts, film.tp, film.t, inc.r, inc.t];
    count(acc, &rt);
    for v in rt {
        acc.min_r = acc.min_r.min(v);
        acc.max_r = acc.max_r.max(v);
    }
    for f in [&film, &inc] {
        for (r, t) in [(f.rs, f.ts), (f.rp, f.tp)] {
            acc.film_energy_err = acc.film_energy_err.max((r + t - 1.0).abs());
        }
    }
    film_f32(acc, stack, thickness, wavelength_nm, cos0, film.r);

    let lut = &luts[material];
    // K and E of a 400 nm film for every sample: these look for non-finite and
    // out-of-range values, not energy (the film from below at every sampled thickness would
    // cost 30,000 Airy sums a sample); the furnace below takes the film drawn.
    let layers =
        Layers::of_stack(stack, crate::material::thesis::FILM_THICKNESS_NM, roughness, [tau; 3], [1.0, 0.5, 0.0]);
    let layers32 = layers.to_f32(thickness);
    for model in Model::ALL {
        let value = model.eval(&layers, normal, wi, wo, &|c| lut.lookup_f64(thickness, c)).total();
        let value32 =
            model.eval_f32(&layers32, normal.map(|x| x as f32), wi.map(|x| x as f32), wo.map(|x| x as f32), lut);
        count(acc, &value);
        count(acc, &value32.map(|v| v as f64));
        for c in 0..3 {
            if value[c] < 0.0 || value32[c] < 0.0 {
                // Negative radiance is as wrong as NaN; report it there.
                acc.nan += 1;
            }
            let dev = (value32[c] as f64 - value[c]).abs() / (1.0 + value[c].abs());
            if dev.is_finite() {
                acc.max_f32_dev = acc.max_f32_dev.max(dev);
            }
        }
    }

    if draw.index.is_multiple_of(FURNACE_EVERY) {
        // K and E of the film drawn: with the 400 nm film's above, the furnace measured the
        // mismatch between two films (albedo 0.23 to 1.76), not the model.
        let white = Layers::of_stack(stack, thickness, roughness, [0.0; 3], [1.0; 3]);
        let cos_o = draw.pick(&[1.0, 1e-3, -1.0]);
        let cos_o = if cos_o < 0.0 { draw.unit() } else { cos_o };
        for (m, model) in Model::ALL.into_iter().enumerate() {
            let albedo = model.furnace_albedo(&white, cos_o, &|c| lut.lookup_f64(thickness, c), 32);
            count(acc, &albedo);
            acc.furnace_evaluations += 1;
            if model == Model::Thesis {
                acc.max_albedo = albedo.iter().cloned().fold(acc.max_albedo, f64::max);
            }
            let f = &mut acc.furnace_by_model[m];
            f.min_albedo = albedo.iter().cloned().fold(f.min_albedo, f64::min);
            f.max_albedo = albedo.iter().cloned().fold(f.max_albedo, f64::max);
        }
    }
}

/// The f32 film kernels at the sample's film: the exact film and a series band (range, and
/// the exact film against f64's `r64`), and the three f32 film colours (NaN and Inf).
fn film_f32(acc: &mut StressReport, stack: Stack, thickness_nm: f64, wavelength_nm: f64, cos0: f64, r64: f64) {
    let (n0, n1, n2) = (stack.n0 as f32, stack.n1 as f32, stack.n2 as f32);
    let (d, lambda, cos) = (thickness_nm as f32, wavelength_nm as f32, cos0 as f32);
    let film = fast::film_f32(n0, n1, n2, cos);
    let exact = fast::airy_reflectance_f32(&film, n1, d, lambda);
    let band = fast::band_reflectance_f32(&film, n1, d, lambda, methods::RGB3_BAND_NM);
    count(acc, &[exact as f64, band as f64]);
    for r in [exact, band] {
        acc.film_f32_min_r = acc.film_f32_min_r.min(r as f64);
        acc.film_f32_max_r = acc.film_f32_max_r.max(r as f64);
    }
    if thickness_nm <= F32_FILM_DEV_MAX_NM {
        // A NaN is counted above (`f64::max` passes it over here).
        acc.max_film_f32_dev = acc.max_film_f32_dev.max((exact as f64 - r64).abs());
    }
    let colours = [
        methods::rgb3_f32(n0, n1, n2, d, cos),
        methods::spectral_n_f32(n0, n1, n2, d, cos, 8),
        methods::gaussian_fit_f32(n0, n1, n2, d, cos),
    ];
    for rgb in colours {
        count(acc, &rgb.map(f64::from));
    }
}
