//! How much light the rough top reflects by itself, so that the rest can enter the stack:
//! the energy coupling of the `layered` model.
//!
//! The single-scatter GGX lobe reflects, from a direction at cosine μ,
//! E_spec(μ) = ∫ F(|wo·h|) D G2 / (4 μ cos θi) cos θi dωi: the film read at the microfacet
//! angles, weighted by the lobe. Written as E₁(μ, r) ⟨F(c)⟩, with E₁ the lobe's albedo for
//! F = 1 and ⟨F(c)⟩ the lobe-weighted mean of F over the microfacet cosines c = |wo·h|, the
//! mean is taken by a three-point Gauss rule for that weight: ⟨F⟩ ≈ Σ w_k F(c_k), exact for
//! F of degree 5 in c. (Measured on the white furnace, worst stack and angle: one point at
//! the mean cosine under-reads the convex Fresnel curve, Jensen's inequality, and the
//! furnace exceeded 1 by 2–4 % at grazing views; one point at a Schlick-matched cosine
//! missed a film's colours by 2 %; two points left 2.3 % at 70° and 6.9 % at 89° on a film
//! of 900 nm under water, whose colour changes several times across the lobe.)
//!
//! **Multiple scattering.** What the single-scatter lobe misses, 1 − E₁(μ) for F = 1
//! (Kulla & Conty 2017; it grows with roughness), is light reflected by one microfacet and
//! masked by another: it meets a second microfacet, where the film reflects it again or lets
//! it into the stack. Its reflected share is taken as g(μ) = ⟨F⟩ F₂ with F₂ the film at the
//! lobe's most grazing node c₁ (the masked ray meets the next facet at a grazing angle). Of
//! four choices for F₂, measured against the microsurface walk (`walk.rs`) on the
//! `bench layered` grid at 20,000 photons, mean / max ΔE00: none 1.01 / 6.33, ⟨F⟩ 0.95 /
//! 6.23, Kulla & Conty's hemispherical average F_avg 0.96 / 6.15, the film at c₁ 0.92 /
//! 5.83 — the best, and free: c₁ is read for ⟨F⟩ anyway. The lobe has Kulla & Conty's
//! shape, f_ms = (1 − E₁(μi))(1 − E₁(μo)) √(g(μi) g(μo)) / (π (1 − E_avg)), with E_avg the
//! hemispherical mean of E₁: separable, reciprocal, and of albedo (1 − E₁(μo)) g(μo) where g
//! is constant. (`Top`.)
//!
//! The light the top does not reflect, 1 − E₁⟨F⟩ − (1 − E₁) g, enters the stack, and the
//! white furnace holds at every roughness to about 2 %: the lobe's albedo is
//! (1 − E₁(μo)) √g(μo) times a mean of √g over the hemisphere, which equals the
//! (1 − E₁(μo)) g(μo) the coupling takes out only where g is the same in every direction
//! (measured: `bench layered`'s furnace rows, 0.0209 at most, 0.0057 up to 70°; 0.0195 and
//! 0.0064 before the coupling interpolated rows' results, below; without the lobe 0.0138
//! and 0.0064). At r = 0, E₁ = 1, c₁ = c₂ = μ and the coupling
//! is the smooth film's transmittance 1 − F(μ) exactly.
//!
//! The tables (E₁, c₁, c₂, c₃, w₁, w₂ and the multiple-scatter scale (1 − E₁) /
//! √(π (1 − E_avg)) over μ and r) are computed once, deterministically (stratified
//! half-vector quadrature, as `Model::furnace_albedo`), and reach the shader in a storage
//! buffer, so the CPU and the GPU read the same numbers.

use std::sync::OnceLock;

use super::ggx::{ggx_d_sin, smith_g2, stratified_half_vectors};
use super::{ALPHA_MIN, COS_MIN};

/// Table entries over μ ∈ [0, 1] and over r ∈ [0, 1] (uniform in both).
pub const E1_MU: usize = 32;
pub const E1_ROUGHNESS: usize = 16;
/// Quadrature strata per axis of the half-vector integral: E₁ to ~1e-4.
const STRATA: usize = 64;

/// The lobe at one (μ, r): its albedo for F = 1 and the Gauss rule for ⟨F(c)⟩: nodes
/// `cos` with weights `weight` (the third weight is 1 minus the other two).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lobe {
    pub albedo: f64,
    pub cos: [f64; 3],
    pub weight: [f64; 2],
}

impl Lobe {
    fn point(albedo: f64, cos: f64) -> Lobe {
        Lobe { albedo, cos: [cos; 3], weight: [1.0, 0.0] }
    }

    /// ⟨g⟩ by the rule.
    pub fn mean(&self, g: impl Fn(f64) -> f64) -> f64 {
        let w = [self.weight[0], self.weight[1], 1.0 - self.weight[0] - self.weight[1]];
        (0..3).map(|k| w[k] * g(self.cos[k])).sum()
    }
}

/// E₁(μ, r) = ∫ D G2 / (4 μ cos θi) cos θi dωi with F = 1 (stratified GGX sampling of h).
pub fn single_scatter_albedo(cos_o: f64, roughness: f64) -> f64 {
    lobe(cos_o, roughness).albedo
}

/// The lobe's albedo and the three-point Gauss rule for its distribution of c = |wo·h|:
/// the nodes are the roots of the degree-3 orthogonal polynomial of that weight (from its
/// moments up to the fifth), the weights match the moments 0–2. Where the distribution is
/// too narrow for three distinct nodes (r → 0) the rule falls back to two, then one.
pub fn lobe(cos_o: f64, roughness: f64) -> Lobe {
    let cos_o = cos_o.clamp(COS_MIN, 1.0);
    let wo = [(1.0 - cos_o * cos_o).sqrt(), 0.0, cos_o];
    let alpha = (roughness * roughness).clamp(ALPHA_MIN, 1.0);
    let (mut sum, mut moments) = (0.0, [0.0; 5]);
    for hv in stratified_half_vectors(wo, alpha, STRATA) {
        // f cos θi / pdf(wi) with F = 1.
        let cos_i = hv.wi[2];
        let f = ggx_d_sin(hv.cos_h, hv.sin_h * hv.sin_h, alpha) * smith_g2(cos_i.max(COS_MIN), cos_o, alpha)
            / (4.0 * cos_i.max(COS_MIN) * cos_o);
        let value = f * cos_i / hv.pdf_wi;
        sum += value;
        for (k, m) in moments.iter_mut().enumerate() {
            *m += value * hv.wo_h.powi(k as i32 + 1);
        }
    }
    let albedo = (sum / (STRATA * STRATA) as f64).min(1.0);
    if sum <= 0.0 {
        return Lobe::point(albedo, cos_o);
    }
    let m = [1.0, moments[0] / sum, moments[1] / sum, moments[2] / sum, moments[3] / sum, moments[4] / sum];
    gauss_rule(albedo, &m)
}

/// The Gauss rule of up to three points for the moments `m` (m[0] = 1).
fn gauss_rule(albedo: f64, m: &[f64; 6]) -> Lobe {
    let variance = m[2] - m[1] * m[1];
    if variance <= 1e-10 {
        return Lobe::point(albedo, m[1]);
    }
    // Degree 3: p(x) = x³ + c2 x² + c1 x + c0 with ∫ p x^k = 0 for k = 0, 1, 2.
    let h = [[m[0], m[1], m[2]], [m[1], m[2], m[3]], [m[2], m[3], m[4]]];
    let rhs = [-m[3], -m[4], -m[5]];
    if let Some([c0, c1, c2]) = solve3(h, rhs)
        && let Some(nodes) = cubic_roots(c2, c1, c0)
        && let Some([w0, w1, _]) = solve3([[1.0; 3], nodes, nodes.map(|x| x * x)], [m[0], m[1], m[2]])
        && nodes.iter().all(|x| (-1e-9..=1.0 + 1e-9).contains(x))
        && [w0, w1].iter().all(|w| (0.0..=1.0).contains(w))
    {
        return Lobe { albedo, cos: nodes.map(|x| x.clamp(0.0, 1.0)), weight: [w0, w1] };
    }
    // Degree 2: p(x) = x² + a x + b orthogonal to 1 and x.
    let a = (m[1] * m[2] - m[3]) / variance;
    let b = -m[2] - a * m[1];
    let root = (a * a - 4.0 * b).max(0.0).sqrt();
    let (x1, x2) = (0.5 * (-a - root), 0.5 * (-a + root));
    let w = if x2 > x1 { ((x2 - m[1]) / (x2 - x1)).clamp(0.0, 1.0) } else { 1.0 };
    Lobe { albedo, cos: [x1.clamp(0.0, 1.0), x2.clamp(0.0, 1.0), x2.clamp(0.0, 1.0)], weight: [w, 1.0 - w] }
}

/// Solves a 3×3 system by Cramer's rule; None when it is (nearly) singular.
fn solve3(a: [[f64; 3]; 3], b: [f64; 3]) -> Option<[f64; 3]> {
    let det = |m: [[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(a);
    let scale = a.iter().flatten().map(|v| v.abs()).fold(0.0, f64::max).powi(3);
    if d.abs().partial_cmp(&(1e-14 * scale)) != Some(std::cmp::Ordering::Greater) {
        return None;
    }
    Some([0, 1, 2].map(|col| {
        let mut m = a;
        for row in 0..3 {
            m[row][col] = b[row];
        }
        det(m) / d
    }))
}

/// The three real roots of x³ + a x² + b x + c, ascending (trigonometric method); None
/// unless all three are real and distinct.
fn cubic_roots(a: f64, b: f64, c: f64) -> Option<[f64; 3]> {
    let p = b - a * a / 3.0;
    let q = 2.0 * a * a * a / 27.0 - a * b / 3.0 + c;
    if p.partial_cmp(&0.0) != Some(std::cmp::Ordering::Less) {
        return None;
    }
    let r = 2.0 * (-p / 3.0).sqrt();
    let arg = (3.0 * q / (p * r)).clamp(-1.0, 1.0);
    let phi = arg.acos() / 3.0;
    let mut roots = [0, 1, 2].map(|k| r * (phi - 2.0 * std::f64::consts::PI * k as f64 / 3.0).cos() - a / 3.0);
    roots.sort_by(f64::total_cmp);
    (roots[1] - roots[0] > 1e-9 && roots[2] - roots[1] > 1e-9).then_some(roots)
}

/// The tables, each row-major by roughness (`t[i_r * E1_MU + i_mu]`): E₁, the three
/// nodes, the first two weights, and the multiple-scatter scale.
pub struct Tables {
    pub albedo: Vec<f32>,
    pub cos: [Vec<f32>; 3],
    pub weight: [Vec<f32>; 2],
    /// (1 − E₁(μ, r)) / √(π (1 − E_avg(r))): f_ms = scale(μi) scale(μo) √(g(μi) g(μo)).
    pub ms_scale: Vec<f32>,
}

/// E_avg(r) = 2 ∫ E₁(μ, r) μ dμ over one roughness row of E₁ (trapezoid rule in μ).
fn average_albedo(row: &[f64]) -> f64 {
    let h = 1.0 / (row.len() - 1) as f64;
    let end = |i: usize| if i == 0 || i == row.len() - 1 { 0.5 } else { 1.0 };
    row.iter().enumerate().map(|(i, e1)| end(i) * h * 2.0 * (i as f64 * h) * e1).sum()
}

/// 1 − E_avg below which a row has no multiple scattering to speak of (r → 0: a mirror).
const MS_MIN_DEFICIT: f64 = 1e-6;

pub fn tables() -> &'static Tables {
    static TABLES: OnceLock<Tables> = OnceLock::new();
    TABLES.get_or_init(|| {
        let mut t = Tables { albedo: vec![], cos: Default::default(), weight: Default::default(), ms_scale: vec![] };
        for i_r in 0..E1_ROUGHNESS {
            let r = i_r as f64 / (E1_ROUGHNESS - 1) as f64;
            // r = 0 is a mirror: everything the film reflects leaves by the lobe, at μ.
            let row: Vec<Lobe> = (0..E1_MU)
                .map(|i_mu| {
                    let mu = i_mu as f64 / (E1_MU - 1) as f64;
                    if i_r == 0 { Lobe::point(1.0, mu) } else { lobe(mu, r) }
                })
                .collect();
            let deficit = 1.0 - average_albedo(&row.iter().map(|l| l.albedo).collect::<Vec<_>>());
            for l in &row {
                t.albedo.push(l.albedo as f32);
                for k in 0..3 {
                    t.cos[k].push(l.cos[k] as f32);
                }
                for k in 0..2 {
                    t.weight[k].push(l.weight[k] as f32);
                }
                let scale = if deficit > MS_MIN_DEFICIT {
                    (1.0 - l.albedo) / (std::f64::consts::PI * deficit).sqrt()
                } else {
                    0.0
                };
                t.ms_scale.push(scale as f32);
            }
        }
        t
    })
}

/// A cell of the (μ, r) grid that the lobe tables and the path table (`path::PathTable`)
/// share, entries row-major by roughness (index r_row × E1_MU + μ_node): the lower corner
/// and the bilinear weights, as `brdf.wgsl`'s `lobe_cell`.
#[derive(Debug, Clone, Copy)]
pub struct GridCell<T> {
    pub i: usize,
    pub j: usize,
    pub fx: T,
    pub fy: T,
}

/// `GridCell::at` and `bilinear` for f64 (the reference side) and f32 (the shader's twin,
/// in f32 arithmetic as the WGSL), written once.
macro_rules! grid_cell_impl {
    ($t:ty) => {
        impl GridCell<$t> {
            pub fn at(cos: $t, roughness: $t) -> GridCell<$t> {
                let x = cos.clamp(0.0, 1.0) * (E1_MU - 1) as $t;
                let y = roughness.clamp(0.0, 1.0) * (E1_ROUGHNESS - 1) as $t;
                let (i, j) = ((x as usize).min(E1_MU - 2), (y as usize).min(E1_ROUGHNESS - 2));
                GridCell { i, j, fx: x - i as $t, fy: y - j as $t }
            }

            /// Bilinear interpolation of a table of the grid.
            pub fn bilinear(&self, table: &[$t]) -> $t {
                let at = |a: usize, b: usize| table[b * E1_MU + a];
                let lower = at(self.i, self.j) * (1.0 - self.fx) + at(self.i + 1, self.j) * self.fx;
                let upper = at(self.i, self.j + 1) * (1.0 - self.fx) + at(self.i + 1, self.j + 1) * self.fx;
                lower * (1.0 - self.fy) + upper * self.fy
            }
        }
    };
}

grid_cell_impl!(f64);
grid_cell_impl!(f32);

/// The lobe at node (i_mu, i_r) of the tables: [E₁, c₁, c₂, c₃, w₁, w₂, multiple-scatter
/// scale] (two vec4s of `brdf.wgsl`'s `lobe_table`).
pub fn node(i_mu: usize, i_r: usize) -> [f32; 7] {
    let t = tables();
    let k = i_r * E1_MU + i_mu;
    [t.albedo[k], t.cos[0][k], t.cos[1][k], t.cos[2][k], t.weight[0][k], t.weight[1][k], t.ms_scale[k]]
}

/// What the rough top does by itself for light from a direction (per channel): the share
/// it reflects, single plus multiple scattering (the diffuse lobe lets 1 minus this in),
/// and the direction's amplitude of the multiple-scatter lobe, f_ms = ms_i ms_o.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Top<T> {
    pub reflected: [T; 3],
    pub ms_amplitude: [T; 3],
}

/// The coupling on one roughness row and between rows, in f64 and f32 (the shader's twin),
/// written once.
///
/// On a row the lobe's nodes and weights are interpolated in μ and the rule evaluated with
/// them: on the mirror row that is the film at μ itself, whose curvature near grazing a
/// linear interpolation of results would miss (the smooth furnace at 89° then loses 0.8 %).
/// Between rows the rule's *results* are interpolated, not its nodes and weights: the rows
/// differ in kind (the mirror row has one node of weight 1 at μ, the next two outer nodes
/// of weight 0.03 and a centre one), and a rule with interpolated weights puts half its
/// weight on an outer node and reads the grazing film 0.01–0.02 too dark. Interpolated
/// results also tabulate: the film table's coupling texture holds the rows' results on its
/// cos nodes and its filter does this interpolation (`optics::lut::Lut::coupling_f32`).
macro_rules! top_impl {
    ($t:ty, $on_row:ident, $top:ident) => {
        /// The rule on roughness row `i_r` at cosine `cos`: E₁ times the film averaged
        /// over the lobe's microfacet angles (three-point Gauss rule) plus the multiple
        /// scattering (1 − E₁) ⟨F⟩ F(c₁), the lobe interpolated linearly in μ.
        pub fn $on_row(cos: $t, i_r: usize, film: &dyn Fn($t) -> [$t; 3]) -> Top<$t> {
            let cell = GridCell::<$t>::at(cos, 0.0);
            let (lo, hi) = (node(cell.i, i_r), node(cell.i + 1, i_r));
            let [e1, c1, c2, c3, w1, w2, ms_scale] =
                [0, 1, 2, 3, 4, 5, 6].map(|k| lo[k] as $t * (1.0 - cell.fx) + hi[k] as $t * cell.fx);
            let (f1, f2, f3) = (film(c1), film(c2), film(c3));
            let mean = [0, 1, 2].map(|c| w1 * f1[c] + w2 * f2[c] + (1.0 - w1 - w2) * f3[c]);
            let g = [0, 1, 2].map(|c| mean[c] * f1[c]);
            Top {
                reflected: [0, 1, 2].map(|c| e1 * mean[c] + (1.0 - e1) * g[c]),
                ms_amplitude: g.map(|g| ms_scale * g.sqrt()),
            }
        }

        /// `Top` of the rough lobe at cosine `cos` and roughness `roughness` with the film
        /// `film` (its reflectance, clamped to [0, 1], as a function of the cosine): the
        /// rule on the two roughness rows around `roughness`, interpolated linearly.
        pub fn $top(cos: $t, roughness: $t, film: &dyn Fn($t) -> [$t; 3]) -> Top<$t> {
            let cell = GridCell::<$t>::at(cos, roughness);
            let (lower, upper) = ($on_row(cos, cell.j, film), $on_row(cos, cell.j + 1, film));
            let mix = |a: $t, b: $t| a * (1.0 - cell.fy) + b * cell.fy;
            Top {
                reflected: [0, 1, 2].map(|k| mix(lower.reflected[k], upper.reflected[k])),
                ms_amplitude: [0, 1, 2].map(|k| mix(lower.ms_amplitude[k], upper.ms_amplitude[k])),
            }
        }
    };
}

top_impl!(f64, top_on_row, top);
top_impl!(f32, top_on_row_f32, top_f32);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn smooth_is_one_and_roughness_loses_energy() {
        assert!((single_scatter_albedo(0.8, 0.0) - 1.0).abs() < 1e-3);
        // The deficit Kulla & Conty describe; PHYSICS.md quotes ≈ 0.70 at normal incidence
        // for roughness 0.7.
        let e = single_scatter_albedo(1.0, 0.7);
        assert!((e - 0.70).abs() < 0.01, "{e}");
        // More roughness, more loss (at α = 1 the microfacet normals are cosine-distributed:
        // half of them send normal light below the horizon).
        let r: Vec<f64> = [0.2, 0.4, 0.6, 0.8, 1.0].iter().map(|r| single_scatter_albedo(1.0, *r)).collect();
        assert!(r.windows(2).all(|w| w[1] < w[0]), "{r:?}");
        assert!(node(E1_MU - 1, 0)[0] == 1.0 && (node(E1_MU - 1, E1_ROUGHNESS - 1)[0] as f64 - r[4]).abs() < 1e-6);
    }

    #[test]
    fn the_gauss_rule_integrates_quintics_in_the_microfacet_cosine() {
        // ⟨g⟩ by the rule equals the lobe-weighted mean of g computed by brute force (the
        // same quadrature as `lobe`, independent of the rule's algebra) for g of degree 5.
        for (mu, r) in [(0.9, 0.3), (0.35, 0.6), (0.1, 1.0)] {
            let l = lobe(mu, r);
            assert!(l.cos[0] < l.cos[1] && l.cos[1] < l.cos[2], "three nodes: {l:?}");
            let quintic = |c: f64| 0.3 - c + 2.0 * c * c * c - 0.7 * c.powi(5);
            let (by_rule, by_sum) = (l.mean(quintic), brute_mean(mu, r, quintic));
            assert!((by_rule - by_sum).abs() < 1e-8, "μ={mu} r={r}: {by_rule} {by_sum}");
            // Negative control: degree 6 is not integrated exactly.
            let sextic = |c: f64| c.powi(6);
            let off = l.mean(sextic) - brute_mean(mu, r, sextic);
            assert!(off.abs() > 1e-9, "μ={mu} r={r}: {off}");
        }
    }

    #[test]
    fn a_mirror_has_no_multiple_scattering_and_reflects_the_film() {
        let film = |c: f64| [0.04 + 0.3 * (1.0 - c).powi(5), 0.1, 0.5 * c];
        for mu in [0.05, 0.4, 1.0] {
            let t = top(mu, 0.0, &film);
            assert_eq!(t.ms_amplitude, [0.0; 3], "μ={mu}");
            let f = film(mu);
            assert!((0..3).all(|c| (t.reflected[c] - f[c]).abs() < 2e-3), "μ={mu}: {:?} vs {f:?}", t.reflected);
        }
    }

    #[test]
    fn the_multiple_scatter_lobe_returns_what_the_top_takes_for_a_constant_film() {
        // With a film of the same reflectance at every angle, g is the same in every
        // direction and the lobe's albedo ∫ ms(μi) ms(μo) cos θi dωi equals the
        // (1 − E₁(μo)) g the coupling takes out of the light entering the stack.
        let f = 0.3;
        let film = |_: f64| [f; 3];
        for r in [0.3, 0.6, 1.0] {
            for mu_o in [0.2, 0.7, 1.0] {
                let t_o = top(mu_o, r, &film);
                let n = 2000;
                let albedo: f64 = (0..n)
                    .map(|k| {
                        let mu = (k as f64 + 0.5) / n as f64;
                        2.0 * std::f64::consts::PI * mu * top(mu, r, &film).ms_amplitude[0] * t_o.ms_amplitude[0]
                            / n as f64
                    })
                    .sum();
                // With a constant film the rule is E₁ f + (1 − E₁) f², bilinear in E₁.
                let e1 = (t_o.reflected[0] - f * f) / (f - f * f);
                let taken = t_o.reflected[0] - e1 * f;
                assert!((albedo - taken).abs() < 2e-3 * f, "r={r} μ={mu_o}: lobe {albedo}, coupling {taken}");
                assert!(taken > 0.0);
            }
        }
        // Negative control: with no lobe scale the lobe returns nothing of it.
        assert!(top(0.7, 0.6, &film).ms_amplitude[0] > 0.0);
    }

    fn brute_mean(cos_o: f64, roughness: f64, g: impl Fn(f64) -> f64) -> f64 {
        let wo = [(1.0 - cos_o * cos_o).sqrt(), 0.0, cos_o];
        let alpha = roughness * roughness;
        let (mut sum, mut acc) = (0.0, 0.0);
        for a in 0..STRATA {
            for b in 0..STRATA {
                let (u1, u2) = ((a as f64 + 0.5) / STRATA as f64, (b as f64 + 0.5) / STRATA as f64);
                let cos_h = (1.0 / (1.0 + alpha * alpha * u1 / (1.0 - u1))).sqrt();
                let sin_h = (1.0 - cos_h * cos_h).sqrt();
                let phi = 2.0 * std::f64::consts::PI * u2;
                let wo_h = wo[0] * sin_h * phi.cos() + wo[2] * cos_h;
                let cos_i = 2.0 * wo_h * cos_h - wo[2];
                if wo_h <= 0.0 || cos_i <= 0.0 {
                    continue;
                }
                let value = smith_g2(cos_i, cos_o, alpha) * wo_h / (cos_o * cos_h);
                sum += value;
                acc += value * g(wo_h);
            }
        }
        acc / sum
    }
}
