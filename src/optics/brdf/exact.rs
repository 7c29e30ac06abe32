//! The layer stack's transport, exactly, for a smooth top interface (PHYSICS.md, "Layered
//! transport, exactly"): the reference the real-time models are measured against.
//!
//! Light that crosses the film into the pigment layer (index n2) reaches the Lambertian
//! base, and every diffuse bounce meets the film from below: directions outside the escape
//! cone are totally reflected, the rest are reflected or transmitted by the film seen from
//! below (the Airy stack n2 | n1 | n0). Summing the bounces is a geometric series:
//!
//! ```text
//! K = ∫0^1 2μ R_b(μ) exp(−2τ/μ) dμ      sent back to the base per bounce
//! E = ∫0^1 2μ T_b(μ) exp(−τ/μ) dμ       escapes per bounce
//! f_diff = T(μi) T(μo) exp(−τ (1/cos_t(wi) + 1/cos_t(wo))) (n0/n2)² k_d / (π (1 − k_d K))
//! R_d(μi) = T(μi) exp(−τ / cos_t(wi)) k_d E / (1 − k_d K)
//! ```
//!
//! Colour: every spectral quantity enters as its linear sRGB colour under D65, as the film
//! colour does (`film_rgb_reference`): the colour map is linear, so ∫ w(μ) R(λ, μ) dμ has
//! the colour ∫ w(μ) colour(R(·, μ)) dμ, and channel c of K is taken with channel c's τ.
//! The integrals are Gauss–Legendre, split at the critical cosines where R_b has a kink.

use std::f64::consts::PI;

use std::sync::{Arc, Mutex, OnceLock};

use super::energy;
use super::layered::{closed_form_diffuse, closed_form_reflectance};
use super::{BrdfValue, Layers, cos_transmitted, radiance_factor};
use crate::optics::film::Stack;
use crate::optics::film_rgb_reference;
use crate::optics::spectrum::{Observer, xyz_to_linear_srgb};

/// Gauss–Legendre nodes per segment of [0, 1], split at the kinks. The integrands are not
/// smooth at a split: R_b rises like a square root past a critical cosine, which the rule
/// resolves only algebraically, so 24 nodes give K to about 2e-6 on the thesis stack (300
/// nm, τ 0.4) and 1.5e-4 on (1.5, 1.2, 2.0) at 800 nm and 50°, the diffuse albedo to 1e-6
/// and 5e-5 (an independent review's integration of the same form at 300 nodes; ΔE00 far
/// under 0.01). Until then this said ~1e-10, "checked against 48". A thick film less dense
/// than the ambient rings in angle faster than 24 nodes follow: the albedo of (1.5, 1.2,
/// 1.6) at normal light is 4.6e-4 off at 2000 nm, 2.8e-4 at 5000 and 1.1e-4 at 9999 (a later
/// review, 300 nodes; τ 0.6/0.3/0, k_d 0.5/0.8/0.2), where (1, 1.55, 2), (1, 3, 3) and (1.33,
/// 1.56, 1.34) stay within 4e-6. More nodes would change the K and E rows the layered model
/// reads (`cached`), so the renders: not done.
const NODES_PER_SEGMENT: usize = 24;

/// The stack seen from below: light in the pigment layer (n2) meets the film (n1), then
/// the ambient medium (n0).
pub fn reversed(stack: Stack) -> Stack {
    Stack { n0: stack.n2, n1: stack.n1, n2: stack.n0 }
}

/// The linear sRGB colour of the perfect reflector (R = 1 at every wavelength): (1, 1, 1)
/// within 1e-3 (PHYSICS.md).
fn white() -> [f64; 3] {
    xyz_to_linear_srgb(Observer::get().white_xyz())
}

/// The film's reflectance colour for light arriving in `stack.n0` at cosine `cos0`: the
/// 1 nm spectral sum (or the incoherent limit beyond `COHERENT_LIMIT_NM`) relative to the
/// perfect reflector's colour, so that R = 1 is exactly (1, 1, 1) and the transmittance
/// colour is exactly 1 − R (R + T = 1 at every wavelength for the lossless film): energy
/// balances hold to rounding, not to the 1e-3 of the white point. Total internal reflection
/// (no propagating wave in n2) gives R = 1. A saturated film colour can fall outside the
/// sRGB gamut (a channel below 0); it is clamped to [0, 1] per channel, as every model
/// clamps the film, so R and 1 − R stay probabilities and the models and the references
/// read the same film.
pub fn reflectance(stack: Stack, thickness_nm: f64, cos0: f64) -> [f64; 3] {
    let white = white();
    let r = film_rgb_reference(stack, thickness_nm, cos0);
    [0, 1, 2].map(|c| (r[c] / white[c]).clamp(0.0, 1.0))
}

/// Gauss–Legendre nodes and weights on [a, b] (Newton's iteration on P_n).
pub fn gauss_legendre(n: usize, a: f64, b: f64) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 1.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                    p0 = p1;
                    p1 = p2;
                }
                dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let step = p1 / dp;
                x -= step;
                if step.abs() < 1e-15 {
                    break;
                }
            }
            let w = 2.0 / ((1.0 - x * x) * dp * dp);
            (0.5 * (a + b) + 0.5 * (b - a) * x, 0.5 * (b - a) * w)
        })
        .collect()
}

/// Cosines in the pigment layer where the film seen from below changes regime: the critical
/// angles of n2 against n1 and against n0 (when those are lower).
fn kinks(stack: Stack) -> Vec<f64> {
    let mut cuts: Vec<f64> = [stack.n1, stack.n0]
        .into_iter()
        .filter(|n| *n < stack.n2)
        .map(|n| (1.0 - (n / stack.n2) * (n / stack.n2)).sqrt())
        .collect();
    cuts.push(0.0);
    cuts.push(1.0);
    cuts.sort_by(f64::total_cmp);
    cuts.dedup_by(|a, b| (*a - *b).abs() < 1e-12);
    cuts
}

/// The smooth-top stack of one material and film thickness: the film from below tabulated
/// at the quadrature nodes, from which K and E follow for any τ.
#[derive(Debug, Clone)]
pub struct SmoothTop {
    pub stack: Stack,
    pub thickness_nm: f64,
    /// (μ in the pigment layer, quadrature weight, colour of R_b(μ)).
    below: Vec<(f64, f64, [f64; 3])>,
    /// Per node: the cosine outside (in n0) of a direction inside the escape cone, None
    /// beyond it (totally reflected).
    outside: Vec<Option<f64>>,
    /// Where n0 > n2: (cosine in n0, quadrature weight) over the directions beyond the
    /// critical angle, which no direction inside reaches through a smooth top and a rough
    /// top lets light out into (`k_e_row`); empty otherwise.
    beyond_critical: Vec<(f64, f64)>,
    /// Per roughness row, per node: the probability of being sent back down under the
    /// layered model's coupling (`k_e_row`), each row computed when first read
    /// (`coupled_row`): a row costs 18 spectral film sums per node inside the escape cone
    /// (24 × 18 for the thesis stack; the mirror row, none), and a preset's colour limit
    /// reads only the rows its roughness map reaches, `brdf stress` two per sample.
    coupled: Vec<OnceLock<Vec<[f64; 3]>>>,
}

impl SmoothTop {
    pub fn new(stack: Stack, thickness_nm: f64) -> SmoothTop {
        let cuts = kinks(stack);
        let below: Vec<(f64, f64, [f64; 3])> = cuts
            .windows(2)
            .flat_map(|w| gauss_legendre(NODES_PER_SEGMENT, w[0], w[1]))
            .map(|(mu, weight)| (mu, weight, reflectance(reversed(stack), thickness_nm, mu)))
            .collect();
        let (n0, n2) = (stack.n0, stack.n2);
        let outside: Vec<Option<f64>> = below
            .iter()
            .map(|&(mu, _, _)| {
                let sin2_out = (n2 / n0) * (n2 / n0) * (1.0 - mu * mu);
                (sin2_out < 1.0).then(|| (1.0 - sin2_out).sqrt())
            })
            .collect();
        let beyond_critical = if n0 > n2 {
            gauss_legendre(NODES_PER_SEGMENT, 0.0, (1.0 - (n2 / n0) * (n2 / n0)).sqrt())
        } else {
            Vec::new()
        };
        let coupled = (0..energy::E1_ROUGHNESS).map(|_| OnceLock::new()).collect();
        SmoothTop { stack, thickness_nm, below, outside, beyond_critical, coupled }
    }

    /// Row `row` of `coupled` (the nodes of `below`, then those of `beyond_critical`: s
    /// there, 1 on the mirror row), computed on first use (the same values whichever row is
    /// asked for first: each row reads only the film and the material's path table, which
    /// the mirror row does not need). The initialiser must not wait on the rayon pool: a
    /// pool thread blocked on this row's `OnceLock` could not take the work it waits for
    /// (`path::cached` builds on threads of its own).
    fn coupled_row(&self, row: usize) -> &[[f64; 3]] {
        self.coupled[row].get_or_init(|| {
            let (stack, thickness_nm) = (self.stack, self.thickness_nm);
            let path = (row > 0).then(|| super::path::cached(stack.n0, stack.n2));
            let rule = energy::LobeRule::of(stack.n0, stack.n1, stack.n2);
            // What the top reflects on this row (its single scattering and x).
            let film = |c: f64| reflectance(stack, thickness_nm, c);
            let reflected = |mu_out: f64, through: &[_]| {
                let (single, beyond) = energy::parts_on_row(mu_out, row, &film, through, rule);
                [0, 1, 2].map(|c| single[c] + beyond[c])
            };
            let below = self.below.iter().zip(&self.outside).map(|(&(_, _, rb), mu_out)| {
                let Some(mu_out) = *mu_out else {
                    return [1.0; 3];
                };
                match &path {
                    Some(path) => reflected(mu_out, &path.through),
                    // Row 0, a mirror: F(μo) = R_b(μ) by reciprocity of the lossless film.
                    None => rb,
                }
            });
            let beyond_critical = self.beyond_critical.iter().map(|&(mu_out, _)| match &path {
                Some(path) => reflected(mu_out, &path.through),
                // A mirror reflects all of it (no wave propagates in n2 there).
                None => [1.0; 3],
            });
            below.chain(beyond_critical).collect()
        })
    }

    /// K (sent back to the base per bounce) and E (escaping per bounce) per channel for
    /// optical depth τ per channel.
    pub fn k_e(&self, tau: [f64; 3]) -> ([f64; 3], [f64; 3]) {
        self.integrate(tau, |_, rb| rb, |_, mu| mu)
    }

    /// K = ∫ 2μ R(μ) exp(−2τ/μ) dμ and E = ∫ 2μ (1 − R(μ)) exp(−τ/μ_e) dμ over the nodes,
    /// with `sent_back(node, R_b)` the probability a direction at that node is sent back
    /// down and `escape_cos(node, μ)` the cosine μ_e of the escaping light's path (μ itself
    /// under a smooth top).
    fn integrate(
        &self,
        tau: [f64; 3],
        sent_back: impl Fn(usize, [f64; 3]) -> [f64; 3],
        escape_cos: impl Fn(usize, f64) -> f64,
    ) -> ([f64; 3], [f64; 3]) {
        let (mut k, mut e) = ([0.0; 3], [0.0; 3]);
        for (node, &(mu, weight, rb)) in self.below.iter().enumerate() {
            let r = sent_back(node, rb);
            let mu_e = escape_cos(node, mu);
            for c in 0..3 {
                let tau = tau[c].max(0.0);
                k[c] += weight * 2.0 * mu * r[c] * (-2.0 * tau / mu).exp();
                e[c] += weight * 2.0 * mu * (1.0 - r[c]) * (-tau / mu_e).exp();
            }
        }
        (k, e)
    }

    /// K and E per channel as the `layered` model couples them to a rough top at roughness
    /// row `row` of the energy table (r = row / (E1_ROUGHNESS − 1)): a direction inside the
    /// escape cone, at cosine μo outside, leaves with probability 1 − s(μo) (s the light the
    /// rough top reflects, `energy::top`, with this film); outside the cone it
    /// is totally reflected. Row 0 is `k_e`
    /// (F(μo) = R_b(μ) by reciprocity of the lossless film); for τ = 0, K + E = 1 in every
    /// row, so the furnace holds.
    ///
    /// With absorption, light that escapes through the rough top crosses the pigment layer
    /// on the way out as the light the top lets in does on the way in (reciprocity): E takes
    /// exp(−τ / cos_eff(μo, r)) (`path`) where the smooth top has exp(−τ / μ), so that E is
    /// the hemispherical escape of the model's own diffuse lobe. K keeps the smooth path.
    ///
    /// **Beyond the critical angle of n0 > n2.** Every direction inside reaches, by Snell's
    /// law, a direction inside the critical cone outside, so the integral over the nodes
    /// inside leaves out the light a rough top lets out beyond it (the model's diffuse lobe
    /// sends 1 − s there: `layered::entering`). That light is added to E as the lobe's own
    /// escape there, (n0/n2)² ∫ 2μo (1 − s(μo)) exp(−τ / cos_eff(μo, r)) dμo over μo below
    /// the critical cosine (`beyond_critical`), and taken from K with the same weight at
    /// the round trip's exp(−2τ / cos_eff): the light inside that leaves there would
    /// otherwise have been counted as sent back. Without absorption both terms are equal, so
    /// K + E = 1 still. (Before, the lobe sent nothing beyond the critical angle and a
    /// white stack at roughness 1 reflected a quarter of the light just past it.)
    pub fn k_e_row(&self, tau: [f64; 3], row: usize) -> ([f64; 3], [f64; 3]) {
        let coupled = self.coupled_row(row);
        let (inside, beyond) = coupled.split_at(self.below.len());
        let sent_back = |node: usize, _| inside[node];
        let absorbing = tau.iter().any(|t| *t > 0.0);
        let path = (row > 0 && absorbing).then(|| super::path::cached(self.stack.n0, self.stack.n2));
        let r = energy::GridCell::<f64>::row_roughness(row);
        let (mut k, mut e) = match &path {
            None => self.integrate(tau, sent_back, |_, mu| mu),
            Some(path) => self.integrate(tau, sent_back, |node, mu| match self.outside[node] {
                // The direction inside is Snell's cos_t of the one outside.
                Some(mu_out) => path.cos_eff(mu, mu_out, r),
                None => mu,
            }),
        };
        if row == 0 {
            return (k, e);
        }
        let eta2 = radiance_factor(self.stack.n0, self.stack.n2);
        for (&(mu_out, weight), s) in self.beyond_critical.iter().zip(beyond) {
            let cos_eff = path.as_ref().map_or(1.0, |p| p.cos_eff(0.0, mu_out, r));
            for c in 0..3 {
                let tau = tau[c].max(0.0);
                let out = eta2 * weight * 2.0 * mu_out * (1.0 - s[c]);
                e[c] += out * (-tau / cos_eff).exp();
                k[c] -= out * (-2.0 * tau / cos_eff).exp();
            }
        }
        (k.map(|v| v.max(0.0)), e)
    }

    /// `bounce_table(tau).at(roughness)` from the two rows it needs (`Layers::of_stack`, once
    /// per sample in `brdf stress`, would otherwise compute all sixteen).
    pub fn k_e_at(&self, tau: [f64; 3], roughness: f64) -> ([f64; 3], [f64; 3]) {
        let (i, f) = row_of(roughness);
        mix_rows(self.k_e_row(tau, i), self.k_e_row(tau, i + 1), f)
    }

    /// `k_e_row` at every roughness row of the energy table: K, and E without absorption,
    /// are linear in r between rows (E₁ is interpolated linearly in r), so interpolating
    /// these rows is exact for them; with absorption E's exp(−τ / cos_eff) is not linear in
    /// r, and between rows the interpolated E departs slightly from the lobe's own escape
    /// (on the rows they agree: tests/visible.rs). The shader interpolates per pixel
    /// (`Scene.bounce`).
    pub fn bounce_table(&self, tau: [f64; 3]) -> BounceTable {
        BounceTable { rows: (0..energy::E1_ROUGHNESS).map(|row| self.k_e_row(tau, row)).collect() }
    }

    /// The film's transmittance colour from above at cosine `cos0`.
    pub fn transmittance(&self, cos0: f64) -> [f64; 3] {
        let r = reflectance(self.stack, self.thickness_nm, cos0);
        r.map(|v| 1.0 - v)
    }

    /// Light entering the pigment layer from a direction at cosine `cos` and reaching the
    /// base: T(μ) exp(−τ / cos_t), per channel (zero under total internal reflection).
    pub fn entering(&self, layers: &Layers, cos: f64) -> [f64; 3] {
        let Some(cos_t) = cos_transmitted(self.stack.n0, self.stack.n2, cos) else {
            return [0.0; 3];
        };
        let t = self.transmittance(cos);
        [0, 1, 2].map(|c| t[c] * (-layers.optical_depth[c].max(0.0) / cos_t).exp())
    }

    /// The diffuse lobe f_diff(wi, wo) at cosines `cos_i`, `cos_o` about the normal (the
    /// specular part of a smooth top is a mirror: see `albedo`).
    pub fn diffuse(&self, layers: &Layers, cos_i: f64, cos_o: f64) -> [f64; 3] {
        let (k, _) = self.k_e(layers.optical_depth);
        let (a_i, a_o) = (self.entering(layers, cos_i), self.entering(layers, cos_o));
        let eta2 = radiance_factor(self.stack.n0, self.stack.n2);
        [0, 1, 2].map(|c| closed_form_diffuse(eta2, layers.albedo[c], a_i[c], a_o[c], k[c]))
    }

    /// The directional albedo for light from a direction at cosine `cos_i`: the mirror
    /// reflection F(μi) and the diffuse reflectance R_d(μi), as a `BrdfValue` of
    /// reflectances (not per steradian).
    pub fn albedo(&self, layers: &Layers, cos_i: f64) -> BrdfValue {
        let (k, e) = self.k_e(layers.optical_depth);
        let a_i = self.entering(layers, cos_i);
        let diffuse = [0, 1, 2].map(|c| closed_form_reflectance(layers.albedo[c], a_i[c], k[c], e[c]));
        BrdfValue { specular: reflectance(self.stack, self.thickness_nm, cos_i), diffuse }
    }
}

/// K and E per roughness row (`SmoothTop::bounce_table`).
#[derive(Debug, Clone)]
pub struct BounceTable {
    pub rows: Vec<([f64; 3], [f64; 3])>,
}

impl BounceTable {
    /// Zeros in every row: for a model that does not read K and E.
    pub fn unused() -> BounceTable {
        BounceTable { rows: vec![([0.0; 3], [0.0; 3]); energy::E1_ROUGHNESS] }
    }

    /// K and E at perceptual roughness `roughness`, interpolated between rows.
    pub fn at(&self, roughness: f64) -> ([f64; 3], [f64; 3]) {
        let (i, f) = row_of(roughness);
        mix_rows(self.rows[i], self.rows[i + 1], f)
    }
}

/// The roughness row below `roughness` and the weight of the one above (rows uniform in r).
fn row_of(roughness: f64) -> (usize, f64) {
    energy::GridCell::<f64>::row_below(roughness)
}

type KE = ([f64; 3], [f64; 3]);

fn mix_rows(a: KE, b: KE, f: f64) -> KE {
    let mix = |p: [f64; 3], q: [f64; 3]| [0, 1, 2].map(|c| p[c] * (1.0 - f) + q[c] * f);
    (mix(a.0, b.0), mix(a.1, b.1))
}

/// `SmoothTop::new` for a (stack, thickness), kept for reuse: the renderer, the reference
/// frame and the window ask for the same few materials every frame (32 kept).
pub fn cached(stack: Stack, thickness_nm: f64) -> Arc<SmoothTop> {
    static CACHE: Mutex<Vec<Arc<SmoothTop>>> = Mutex::new(Vec::new());
    let same = |t: &SmoothTop| t.stack == stack && t.thickness_nm.to_bits() == thickness_nm.to_bits();
    if let Some(top) = CACHE.lock().expect("transport cache").iter().find(|t| same(t)) {
        return top.clone();
    }
    let top = Arc::new(SmoothTop::new(stack, thickness_nm));
    let mut cache = CACHE.lock().expect("transport cache");
    if cache.len() >= 32 {
        cache.remove(0);
    }
    cache.push(top.clone());
    top
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_integrates_polynomials_exactly() {
        let nodes = gauss_legendre(NODES_PER_SEGMENT, 0.2, 0.9);
        // Degree 2n − 1 is exact; x^7 on [0.2, 0.9].
        let sum: f64 = nodes.iter().map(|(x, w)| w * x.powi(7)).sum();
        let exact = (0.9f64.powi(8) - 0.2f64.powi(8)) / 8.0;
        assert!((sum - exact).abs() < 1e-14, "{sum} {exact}");
    }

    #[test]
    fn lossless_stack_reflects_everything_and_k_plus_e_is_one() {
        // τ = 0: every photon that leaves the base either escapes or comes back (K + E = 1);
        // with k_d = 1 the albedo is F + T = 1 at every angle.
        for stack in [Stack::THESIS, Stack { n0: 1.0, n1: 1.56, n2: 1.33 }, Stack { n0: 1.33, n1: 1.55, n2: 2.0 }] {
            let top = SmoothTop::new(stack, 420.0);
            let (k, e) = top.k_e([0.0; 3]);
            for c in 0..3 {
                assert!((k[c] + e[c] - 1.0).abs() < 1e-9, "{stack:?} K {k:?} E {e:?}");
            }
            let layers = Layers::of_stack(stack, 420.0, 0.0, [0.0; 3], [1.0; 3]);
            for cos_i in [1.0, 0.7, 0.3, 0.05] {
                let a = top.albedo(&layers, cos_i).total();
                assert!(a.iter().all(|v| (v - 1.0).abs() < 1e-9), "{stack:?} cos {cos_i}: {a:?}");
            }
        }
    }

    #[test]
    fn rough_coupling_keeps_k_plus_e_one_and_meets_the_smooth_top_at_zero() {
        let top = SmoothTop::new(Stack::THESIS, 400.0);
        for row in [0, 5, 10, 15] {
            let (k, e) = top.k_e_row([0.0; 3], row);
            assert!((0..3).all(|c| (k[c] + e[c] - 1.0).abs() < 1e-9), "row {row}: {k:?} {e:?}");
        }
        let (k0, e0) = top.k_e_row([0.5, 0.2, 0.0], 0);
        let (k, e) = top.k_e([0.5, 0.2, 0.0]);
        assert!((0..3).all(|c| (k0[c] - k[c]).abs() < 1e-12 && (e0[c] - e[c]).abs() < 1e-12));
        // Rougher tops reflect less by the lobe, so more escapes.
        assert!(top.k_e_row([0.0; 3], 15).1[1] > e[1] - 1e-12);
    }

    #[test]
    fn total_internal_reflection_keeps_three_quarters_for_n2_2() {
        // With no film (n1 = n0) and n2 = 2, directions outside the escape cone are the
        // fraction 1 − (n0/n2)² = 3/4 of a Lambertian distribution (PHYSICS.md): K ≥ 0.75.
        let top = SmoothTop::new(Stack { n0: 1.0, n1: 1.0, n2: 2.0 }, 0.0);
        let (k, _) = top.k_e([0.0; 3]);
        assert!(k.iter().all(|v| *v > 0.75 && *v < 0.85), "{k:?}");
    }
}
