//! The pigment layer's path for light that a rough top lets in: an effective cosine per
//! material, so the layered model attenuates the light that crosses a rough top as it is.
//!
//! A smooth top refracts light from a direction at cosine μ to the one cosine cos_t(μ) of
//! Snell's law, and the pigment layer lets exp(−τ / cos_t) of it through. A rough top
//! refracts it through tilted microfacets (at grazing light and high roughness, through more
//! than one), so the light crosses the layer at a spread of cosines, more obliquely on
//! average, and less of it survives: with cos_t the layered model was too bright at
//! roughness ≥ 0.6 with absorption (`bench layered`, 40,000 photons: mean / p95 / max ΔE00
//! 0.80 / 2.36 / 5.15 with cos_t, 0.61 / 1.38 / 3.73 with this table).
//!
//! The table holds, per (μ, r) on the rough lobe's grid (`energy::E1_MU` × `E1_ROUGHNESS`),
//! the cosine cos_eff with exp(−τ_ref / cos_eff) = ⟨exp(−τ_ref / μt)⟩ over the cosines μt at
//! which the top lets light in, walked photon by photon through the rough top alone
//! (`walk::transmitted_cosines`: the microsurface with heights, every microfacet reflection
//! and refraction followed, the plain Fresnel reflectance of n0 | n2). One τ_ref serves
//! every τ: matched at τ_ref = 0.5, the same grid (τ = 0.4 and 1) measured 0.61 / 1.38 /
//! 3.73 against 0.60 / 1.33 / 3.66 with the exact mean at each τ. Row r = 0 is Snell's
//! cos_t exactly. The table depends on n0 and n2 only, and is kept per material
//! (`cached`); the renderer sends it to the shader in the rough lobe table's spare slot.

use std::sync::{Arc, Mutex};

use rayon::prelude::*;

use super::energy::{E1_MU, E1_ROUGHNESS};
use super::{ALPHA_MIN, COS_MIN, cos_transmitted};

/// The optical depth the effective cosine is matched at (see the module's measurements).
const TAU_REF: f64 = 0.5;
/// Photons per table entry: ⟨exp(−τ_ref / μt)⟩ to about 0.5 % (1σ), cos_eff to about 1 %.
const PHOTONS: u64 = 4096;
/// The most grazing light walked (μ = 0 itself never meets the top).
const MU_MIN: f64 = 1e-3;

/// cos_eff over (μ, r) for one pair of indices, row-major by roughness as the lobe table.
#[derive(Debug, Clone, PartialEq)]
pub struct PathTable {
    pub n0: f64,
    pub n2: f64,
    pub cos_eff: Vec<f64>,
}

impl PathTable {
    pub fn new(n0: f64, n2: f64) -> PathTable {
        let cos_eff = (0..E1_ROUGHNESS * E1_MU)
            .into_par_iter()
            .map(|k| {
                let (i_mu, i_r) = (k % E1_MU, k / E1_MU);
                let mu = (i_mu as f64 / (E1_MU - 1) as f64).max(MU_MIN);
                let smooth = cos_transmitted(n0, n2, mu).unwrap_or(COS_MIN);
                if i_r == 0 {
                    return smooth;
                }
                let r = i_r as f64 / (E1_ROUGHNESS - 1) as f64;
                let alpha = (r * r).max(ALPHA_MIN);
                let wi = [(1.0 - mu * mu).sqrt(), 0.0, mu];
                let cosines = super::walk::transmitted_cosines(wi, alpha, n0, n2, PHOTONS, seed_of(k));
                if cosines.is_empty() {
                    return smooth;
                }
                let mean =
                    cosines.iter().map(|c| (-TAU_REF / c.max(COS_MIN)).exp()).sum::<f64>() / cosines.len() as f64;
                if mean > 0.0 { (-TAU_REF / mean.ln()).clamp(COS_MIN, 1.0) } else { COS_MIN }
            })
            .collect();
        PathTable { n0, n2, cos_eff }
    }

    /// cos_eff at (μ, r), bilinear (as `brdf.wgsl` reads the lobe table's fourth slot).
    pub fn at(&self, cos: f64, roughness: f64) -> f64 {
        let x = cos.clamp(0.0, 1.0) * (E1_MU - 1) as f64;
        let y = roughness.clamp(0.0, 1.0) * (E1_ROUGHNESS - 1) as f64;
        let (i, j) = ((x as usize).min(E1_MU - 2), (y as usize).min(E1_ROUGHNESS - 2));
        let (fx, fy) = (x - i as f64, y - j as f64);
        let at = |a: usize, b: usize| self.cos_eff[b * E1_MU + a];
        let lower = at(i, j) * (1.0 - fx) + at(i + 1, j) * fx;
        let upper = at(i, j + 1) * (1.0 - fx) + at(i + 1, j + 1) * fx;
        lower * (1.0 - fy) + upper * fy
    }

    /// The f32 twin of `at`, over the table rounded to f32 (what the shader holds).
    pub fn at_f32(&self, cos: f32, roughness: f32) -> f32 {
        let x = cos.clamp(0.0, 1.0) * (E1_MU - 1) as f32;
        let y = roughness.clamp(0.0, 1.0) * (E1_ROUGHNESS - 1) as f32;
        let (i, j) = ((x as usize).min(E1_MU - 2), (y as usize).min(E1_ROUGHNESS - 2));
        let (fx, fy) = (x - i as f32, y - j as f32);
        let at = |a: usize, b: usize| self.cos_eff[b * E1_MU + a] as f32;
        let lower = at(i, j) * (1.0 - fx) + at(i + 1, j) * fx;
        let upper = at(i, j + 1) * (1.0 - fx) + at(i + 1, j + 1) * fx;
        lower * (1.0 - fy) + upper * fy
    }
}

/// A fixed seed per table entry.
fn seed_of(k: usize) -> u64 {
    0x9e37_79b9_7f4a_7c15 ^ (k as u64).wrapping_mul(0xbf58_476d_1ce4_e5b9)
}

/// The table for indices (n0, n2), built once and kept (16 materials). Keyed by the indices
/// as f32, so the f32 path (which carries them as f32) finds the same table.
pub fn cached(n0: f64, n2: f64) -> Arc<PathTable> {
    static CACHE: Mutex<Vec<Arc<PathTable>>> = Mutex::new(Vec::new());
    let same = |t: &PathTable| key(t.n0, t.n2) == key(n0, n2);
    if let Some(table) = CACHE.lock().expect("path cache").iter().find(|t| same(t)) {
        return table.clone();
    }
    let table = Arc::new(PathTable::new(n0, n2));
    let mut cache = CACHE.lock().expect("path cache");
    if cache.len() >= 16 {
        cache.remove(0);
    }
    cache.push(table.clone());
    table
}

fn key(n0: f64, n2: f64) -> (u32, u32) {
    ((n0 as f32).to_bits(), (n2 as f32).to_bits())
}

/// `f` of the table for (n0, n2): the layered model reads it twice per evaluation, so the
/// last table each thread used is kept at hand (no lock, no reference count).
pub fn with<R>(n0: f64, n2: f64, f: impl FnOnce(&PathTable) -> R) -> R {
    thread_local! {
        static LAST: std::cell::RefCell<Option<Arc<PathTable>>> = const { std::cell::RefCell::new(None) };
    }
    LAST.with(|last| {
        let mut last = last.borrow_mut();
        if last.as_ref().is_none_or(|t| key(t.n0, t.n2) != key(n0, n2)) {
            *last = Some(cached(n0, n2));
        }
        f(last.as_ref().expect("just set"))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optics::brdf::ggx::smith_lambda;

    /// A second method: ⟨exp(−τ/μt)⟩ over the single-scatter transmission lobe (Walter et
    /// al. 2007: visible normals for the incoming light, refraction through each, weighted
    /// by the Fresnel transmittance and the transmitted light's masking G1), by a
    /// deterministic midpoint quadrature over the visible-normal sampler's two uniforms.
    /// Where single scattering carries nearly all the light (moderate roughness, light not
    /// grazing) it must agree with the walked table.
    fn single_scatter_mean(n0: f64, n2: f64, mu: f64, alpha: f64, tau: f64) -> f64 {
        let w = [(1.0 - mu * mu).sqrt(), 0.0, mu];
        let eta = n0 / n2;
        let strata = 64;
        let (mut total, mut weighted) = (0.0, 0.0);
        for a in 0..strata {
            for b in 0..strata {
                let (u1, u2) = ((a as f64 + 0.5) / strata as f64, (b as f64 + 0.5) / strata as f64);
                let m = crate::optics::brdf::walk::visible_normal_at(w, alpha, u1, u2);
                let c = (w[0] * m[0] + w[1] * m[1] + w[2] * m[2]).max(0.0);
                let k = 1.0 - eta * eta * (1.0 - c * c);
                if k < 0.0 {
                    continue;
                }
                // The refracted travel direction's downward cosine.
                let t = [0, 1, 2].map(|i| -eta * w[i] + (eta * c - k.sqrt()) * m[i]);
                let mu_t = -t[2] / (t[0] * t[0] + t[1] * t[1] + t[2] * t[2]).sqrt();
                if mu_t <= 1e-9 {
                    continue;
                }
                let (rs, rp) = crate::optics::film::fresnel(n0, n2, c);
                let weight = (1.0 - 0.5 * (rs + rp)) / (1.0 + smith_lambda(mu_t, alpha));
                total += weight;
                weighted += weight * (-tau / mu_t).exp();
            }
        }
        weighted / total
    }

    #[test]
    fn the_walked_path_meets_snell_at_r_0_and_single_scattering_where_it_dominates() {
        for (n0, n2) in [(1.0, 2.0), (1.0, 1.33), (1.33, 2.0)] {
            let table = PathTable::new(n0, n2);
            // Row 0 is Snell's law exactly.
            for i in 0..E1_MU {
                let mu = (i as f64 / (E1_MU - 1) as f64).max(MU_MIN);
                assert_eq!(table.cos_eff[i], cos_transmitted(n0, n2, mu).unwrap());
            }
            // Rough rows at light within 60° of the normal: the walked mean against the
            // single-scatter quadrature at τ_ref (to 1 %: the walk's noise and the little
            // multiple scattering there), and at τ = 1.5 through the one cos_eff (to 3 %: the
            // price of one τ_ref for every τ).
            for row in [2, 5] {
                let r = row as f64 / (E1_ROUGHNESS - 1) as f64;
                for i in [16, 24, 31] {
                    let mu = i as f64 / (E1_MU - 1) as f64;
                    let cos_eff = table.cos_eff[row * E1_MU + i];
                    for (tau, tolerance) in [(TAU_REF, 0.01), (1.5, 0.03)] {
                        let walked = (-tau / cos_eff).exp();
                        let quadrature = single_scatter_mean(n0, n2, mu, (r * r).max(ALPHA_MIN), tau);
                        assert!(
                            (walked - quadrature).abs() < tolerance * quadrature,
                            "n0 {n0} n2 {n2} r {r:.2} μ {mu:.2} τ {tau}: walked {walked:.4}, quadrature {quadrature:.4}"
                        );
                    }
                }
            }
            // Rougher tops send the light in more obliquely: at r = 0.8 and 45° the path is
            // longer than Snell's by more than the walk's noise.
            let (i, row) = (22, 12);
            assert!(table.cos_eff[row * E1_MU + i] < 0.97 * table.cos_eff[i], "{n0} {n2}");
        }
    }
}
