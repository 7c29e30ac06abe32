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
//! 5.83 — the best, and free: c₁ is read for ⟨F⟩ anyway.
//!
//! **Light straight back through the top.** A rough top also sends some of the light it
//! lets in straight back out (in through one microfacet, out through another, up off a
//! third), q(μ): the material's rule for it comes from a walk of the bare interface
//! (`path::PathTable::through`), reweighted by the film (`parts_on_row`).
//!
//! **The lobe.** The top reflects E₁⟨F⟩ + x with x = (1 − E₁) g + q, what it reflects beyond
//! single scattering, and returns x through a separable lobe, f_ms = x(μi) x(μo) / (π X̄),
//! X̄ = 2 ∫ x(μ) μ dμ (`ms_norm_on_row`): reciprocal, and of albedo x(μo) in every direction,
//! for any film. (Kulla & Conty's shape, (1 − E₁(μi))(1 − E₁(μo)) √(g(μi) g(μo)) /
//! (π (1 − E_avg)), which this replaced, returned (1 − E₁) g only where g was the same in
//! every direction, and did not return q at grazing light: `bench layered`'s max ΔE00 2.64
//! with it against 2.39 with this lobe, the same rule for q.) The light the top does not
//! reflect, 1 − E₁⟨F⟩ − x, enters the stack; the white furnace holds at every roughness to
//! 1.5 % (`bench layered`'s furnace rows: 0.0144 at most, 0.0058 up to 70°; 0.0209 and
//! 0.0057 with Kulla & Conty's shape). At r = 0, E₁ = 1, c₁ = c₂ = μ, q = 0 and the coupling
//! is the smooth film's transmittance 1 − F(μ) exactly.
//!
//! The tables (E₁, c₁, c₂, c₃, w₁, w₂ over μ and r) are computed once, deterministically
//! (stratified half-vector quadrature, as `Model::furnace_albedo`), and reach the shader in
//! a storage buffer, so the CPU and the GPU read the same numbers.

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
    let [x1, x2, w] = two_point_rule(m[1], m[2], m[3]);
    Lobe { albedo, cos: [x1, x2, x2], weight: [w, 1.0 - w] }
}

/// The two-point Gauss rule of a distribution on [0, 1] with moments m1, m2, m3 (m0 = 1):
/// nodes x1 ≤ x2 in [0, 1] and the weight of x1; one node (weight 1) where it is too narrow.
/// (`gauss_rule` where three nodes fail; `path::PathTable`'s rule for light that comes
/// straight back through the top.)
pub(super) fn two_point_rule(m1: f64, m2: f64, m3: f64) -> [f64; 3] {
    let variance = m2 - m1 * m1;
    if variance <= 1e-10 {
        return [m1.clamp(0.0, 1.0), m1.clamp(0.0, 1.0), 1.0];
    }
    // Degree 2: p(x) = x² + a x + b orthogonal to 1 and x.
    let a = (m1 * m2 - m3) / variance;
    let b = -m2 - a * m1;
    let root = (a * a - 4.0 * b).max(0.0).sqrt();
    let (x1, x2) = (0.5 * (-a - root), 0.5 * (-a + root));
    let w = if x2 > x1 { ((x2 - m1) / (x2 - x1)).clamp(0.0, 1.0) } else { 1.0 };
    [x1.clamp(0.0, 1.0), x2.clamp(0.0, 1.0), w]
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
/// nodes and the first two weights.
pub struct Tables {
    pub albedo: Vec<f32>,
    pub cos: [Vec<f32>; 3],
    pub weight: [Vec<f32>; 2],
}

/// Nodes of the rule for the multiple-scatter lobe's normalisation (`ms_norm_on_row`).
pub const MS_NODES: usize = 8;

/// The (μ, weight) pairs of that rule: four Gauss–Legendre nodes on [0, 1/4] and four on
/// [1/4, 1].
pub fn ms_rule() -> &'static [(f64, f64); MS_NODES] {
    static RULE: OnceLock<[(f64, f64); MS_NODES]> = OnceLock::new();
    RULE.get_or_init(|| {
        let nodes: Vec<(f64, f64)> = [(0.0, 0.25), (0.25, 1.0)]
            .into_iter()
            .flat_map(|(a, b)| super::exact::gauss_legendre(MS_NODES / 2, a, b))
            .collect();
        std::array::from_fn(|k| nodes[k])
    })
}

pub fn tables() -> &'static Tables {
    static TABLES: OnceLock<Tables> = OnceLock::new();
    TABLES.get_or_init(|| {
        let mut t = Tables { albedo: vec![], cos: Default::default(), weight: Default::default() };
        for i_r in 0..E1_ROUGHNESS {
            let r = i_r as f64 / (E1_ROUGHNESS - 1) as f64;
            // r = 0 is a mirror: everything the film reflects leaves by the lobe, at μ.
            let row: Vec<Lobe> = (0..E1_MU)
                .map(|i_mu| {
                    let mu = i_mu as f64 / (E1_MU - 1) as f64;
                    if i_r == 0 { Lobe::point(1.0, mu) } else { lobe(mu, r) }
                })
                .collect();
            for l in &row {
                t.albedo.push(l.albedo as f32);
                for k in 0..3 {
                    t.cos[k].push(l.cos[k] as f32);
                }
                for k in 0..2 {
                    t.weight[k].push(l.weight[k] as f32);
                }
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

/// The lobe at node (i_mu, i_r) of the tables: [E₁, c₁, c₂, c₃, w₁, w₂] (the first six
/// slots of `brdf.wgsl`'s `lobe_table` entry).
pub fn node(i_mu: usize, i_r: usize) -> [f32; 6] {
    let t = tables();
    let k = i_r * E1_MU + i_mu;
    [t.albedo[k], t.cos[0][k], t.cos[1][k], t.cos[2][k], t.weight[0][k], t.weight[1][k]]
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
    ($t:ty, $parts:ident, $norm:ident, $norms:ident, $on_row_with:ident, $top_with:ident, $top:ident) => {
        /// The rule's two parts on roughness row `i_r` at cosine `cos`, per channel: the
        /// single scattering E₁ ⟨F⟩ (the film averaged over the lobe's microfacet angles by
        /// the three-point Gauss rule) and what the top reflects beyond it,
        /// x = (1 − E₁) ⟨F⟩ F(c₁) + q: the multiple scattering and the light that comes
        /// straight back through the top, q = (1 − ⟨F⟩) W (w_a F(c_a) + (1 − w_a) F(c_b))
        /// with the material's rule `through` (`path::PathTable::through`; empty: none).
        /// The lobe and the rule interpolated linearly in μ.
        pub fn $parts(cos: $t, i_r: usize, film: &dyn Fn($t) -> [$t; 3], through: &[[$t; 4]]) -> ([$t; 3], [$t; 3]) {
            let cell = GridCell::<$t>::at(cos, 0.0);
            let (lo, hi) = (node(cell.i, i_r), node(cell.i + 1, i_r));
            let [e1, c1, c2, c3, w1, w2] =
                [0, 1, 2, 3, 4, 5].map(|k| lo[k] as $t * (1.0 - cell.fx) + hi[k] as $t * cell.fx);
            let (f1, f2, f3) = (film(c1), film(c2), film(c3));
            let mean = [0, 1, 2].map(|c| w1 * f1[c] + w2 * f2[c] + (1.0 - w1 - w2) * f3[c]);
            let q = match through {
                [] => [0.0; 3],
                _ => {
                    let (lo, hi) = (through[i_r * E1_MU + cell.i], through[i_r * E1_MU + cell.i + 1]);
                    let [w, c_a, c_b, w_a] = [0, 1, 2, 3].map(|k| lo[k] * (1.0 - cell.fx) + hi[k] * cell.fx);
                    let (f_a, f_b) = (film(c_a), film(c_b));
                    [0, 1, 2].map(|c| (1.0 - mean[c]) * w * (w_a * f_a[c] + (1.0 - w_a) * f_b[c]))
                }
            };
            // x never more than the light the single scattering leaves (q's reweighting is
            // an estimate).
            let single = [0, 1, 2].map(|c| e1 * mean[c]);
            (single, [0, 1, 2].map(|c| ((1.0 - e1) * mean[c] * f1[c] + q[c]).min(1.0 - single[c])))
        }

        /// X̄ = 2 ∫ x(μ) μ dμ on roughness row `i_r`, the multiple-scatter lobe's
        /// normalisation, by `ms_rule` (x rises towards grazing light, so half the nodes lie
        /// below μ = 1/4). Against 2,000 midpoints (the test of the lobe's albedo, a 650 nm
        /// film) the lobe returns x to within 1.0 %; Simpson's rule on every cell of the
        /// lobe's grid (63 evaluations) did no better on `bench layered`.
        pub fn $norm(i_r: usize, film: &dyn Fn($t) -> [$t; 3], through: &[[$t; 4]]) -> [$t; 3] {
            let mut norm = [0.0; 3];
            for &(mu, weight) in ms_rule() {
                let (_, x) = $parts(mu as $t, i_r, film, through);
                for c in 0..3 {
                    norm[c] += (2.0 * weight * mu) as $t * x[c];
                }
            }
            norm
        }

        /// The rule on roughness row `i_r` at cosine `cos` (`$parts`) with the row's X̄
        /// `norm` (`$norm`; the film table bakes it once per column and row): the top
        /// reflects E₁ ⟨F⟩ + x, and its multiple-scatter lobe f_ms = x(μi) x(μo) / (π X̄)
        /// returns the x it takes, in every direction (amplitude x / √(π X̄)).
        pub fn $on_row_with(
            cos: $t,
            i_r: usize,
            film: &dyn Fn($t) -> [$t; 3],
            through: &[[$t; 4]],
            norm: [$t; 3],
        ) -> Top<$t> {
            let (single, x) = $parts(cos, i_r, film, through);
            Top {
                reflected: [0, 1, 2].map(|c| single[c] + x[c]),
                ms_amplitude: [0, 1, 2]
                    .map(|c| if norm[c] > 1e-9 { x[c] / (std::f64::consts::PI as $t * norm[c]).sqrt() } else { 0.0 }),
            }
        }

        /// `Top` of the rough lobe at cosine `cos` and roughness `roughness` with the film
        /// `film` (its reflectance, clamped to [0, 1], as a function of the cosine) and the
        /// material's rule for light that comes straight back (`through`, as `$parts`): the
        /// rule on the two roughness rows around `roughness`, interpolated linearly.
        pub fn $top(cos: $t, roughness: $t, film: &dyn Fn($t) -> [$t; 3], through: &[[$t; 4]]) -> Top<$t> {
            $top_with(cos, roughness, film, through, $norms(roughness, film, through))
        }

        /// X̄ (`$norm`) on the two roughness rows around `roughness`, which every cosine's
        /// rule at that roughness reads.
        pub fn $norms(roughness: $t, film: &dyn Fn($t) -> [$t; 3], through: &[[$t; 4]]) -> [[$t; 3]; 2] {
            let j = GridCell::<$t>::at(0.0, roughness).j;
            [$norm(j, film, through), $norm(j + 1, film, through)]
        }

        /// `$top` with the two rows' X̄ given.
        fn $top_with(
            cos: $t,
            roughness: $t,
            film: &dyn Fn($t) -> [$t; 3],
            through: &[[$t; 4]],
            norms: [[$t; 3]; 2],
        ) -> Top<$t> {
            let cell = GridCell::<$t>::at(cos, roughness);
            let lower = $on_row_with(cos, cell.j, film, through, norms[0]);
            let upper = $on_row_with(cos, cell.j + 1, film, through, norms[1]);
            let mix = |a: $t, b: $t| a * (1.0 - cell.fy) + b * cell.fy;
            Top {
                reflected: [0, 1, 2].map(|k| mix(lower.reflected[k], upper.reflected[k])),
                ms_amplitude: [0, 1, 2].map(|k| mix(lower.ms_amplitude[k], upper.ms_amplitude[k])),
            }
        }
    };
}

top_impl!(f64, parts_on_row, ms_norm_on_row, ms_norms, top_on_row_with, top_with, top);
top_impl!(f32, parts_on_row_f32, ms_norm_on_row_f32, ms_norms_f32, top_on_row_with_f32, top_with_f32, top_f32);

/// `top` for the two directions of one evaluation (the f64 model's), which share the rows'
/// X̄: computed once, not once per direction.
pub fn top_pair(cos: [f64; 2], roughness: f64, film: &dyn Fn(f64) -> [f64; 3], through: &[[f64; 4]]) -> [Top<f64>; 2] {
    let norms = ms_norms(roughness, film, through);
    cos.map(|c| top_with(c, roughness, film, through, norms))
}

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
            let t = top(mu, 0.0, &film, &[]);
            assert_eq!(t.ms_amplitude, [0.0; 3], "μ={mu}");
            let f = film(mu);
            assert!((0..3).all(|c| (t.reflected[c] - f[c]).abs() < 2e-3), "μ={mu}: {:?} vs {f:?}", t.reflected);
        }
    }

    /// The multiple-scatter lobe's albedo ∫ ms(μi) ms(μo) cos θi dωi (here by 2,000
    /// midpoints) in direction μo is the x(μo) the top takes there (`parts_on_row`): for a
    /// film whose colour changes with the angle and with the light that comes straight back
    /// through the top, on whole roughness rows. (The earlier lobe, (1 − E₁) √g in each
    /// direction, returned it only where g was the same in every direction.)
    #[test]
    fn the_multiple_scatter_lobe_returns_what_the_top_takes_in_every_direction() {
        // The film of `bench layered`'s worst material, 650 nm: its colour changes with the
        // angle.
        let stack = crate::optics::film::Stack { n0: 1.0, n1: 1.56, n2: 1.33 };
        let tables = crate::optics::brdf::walk::FilmTables::new(stack, 650.0);
        let film = |c: f64| tables.above(c).map(|v| v.clamp(0.0, 1.0));
        let through = &crate::optics::brdf::path::cached(stack.n0, stack.n2).through;
        let lobe_albedo = |mu_o: f64, i_r: usize, scale: f64| {
            let norm = ms_norm_on_row(i_r, &film, through).map(|v| v * scale);
            let t_o = top_on_row_with(mu_o, i_r, &film, through, norm);
            let n = 2000;
            let mut albedo = [0.0; 3];
            for k in 0..n {
                let mu = (k as f64 + 0.5) / n as f64;
                let t_i = top_on_row_with(mu, i_r, &film, through, norm);
                for (a, (i, o)) in albedo.iter_mut().zip(t_i.ms_amplitude.iter().zip(t_o.ms_amplitude)) {
                    *a += 2.0 * std::f64::consts::PI * mu * i * o / n as f64;
                }
            }
            albedo
        };
        for i_r in [4, 9, 15] {
            for mu_o in [0.08, 0.4, 0.9] {
                let (_, taken) = parts_on_row(mu_o, i_r, &film, through);
                let albedo = lobe_albedo(mu_o, i_r, 1.0);
                for c in 0..3 {
                    assert!(taken[c] > 0.0);
                    assert!(
                        (albedo[c] - taken[c]).abs() < 1.5e-2 * taken[c],
                        "row {i_r} μ={mu_o} channel {c}: lobe {}, taken {}",
                        albedo[c],
                        taken[c]
                    );
                }
                // Negative control: a normalisation 5 % off is seen.
                let off = lobe_albedo(mu_o, i_r, 1.05);
                assert!((0..3).all(|c| (off[c] - taken[c]).abs() > 3e-2 * taken[c]));
            }
        }
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
