//! The snake-skin BRDF: one rough top interface (GGX, `ggx`) over a layer model that says
//! what happens beneath it. Every model is reached through [`Model`] — f64 (the reference
//! side), f32 (the CPU twin of the shader, film colour from the LUT), the ambient term of the
//! reference renderer — and `shaders/brdf.wgsl` selects the same model by its `BRDF_MODEL`
//! override constant, whose values come from [`Model::code`]. The references, the stress
//! and furnace tests and `snakeskin brdf eval` all take a `Model`, so a new model is added
//! in one place: a file beside `thesis.rs`, one arm per match here, in `brdf.wgsl`'s
//! `coupling`, `diffuse_lobe` and `ambient_diffuse`, and its `MODEL_*` name in
//! `render::engine::shaders`.
//!
//! ```text
//! f = D(h) G2(wi, wo) F(|wo·h|, d) / (4 |n·wi| |n·wo|) + f_diff(model)
//! ```
//!
//! D: GGX; G2: Smith height-correlated (Heitz 2014, eq. 99); F: the film's RGB reflectance,
//! clamped to [0, 1] per channel (a saturated film colour can fall outside the sRGB gamut,
//! and 1 − F must stay a valid transmittance).
//!
//! Stability rules (PHYSICS.md): GGX α = roughness² within [ALPHA_MIN, 1] (`ggx_alpha`) so
//! roughness 0 stays finite; a zero-length or non-finite normal falls back to the tangent-space up vector;
//! directions below the shading horizon give 0; cosines are floored at COS_MIN after that
//! test so grazing angles give finite values. These numbers reach the WGSL from here
//! (`render::engine::shaders::generated_constants`), never by copy.

pub mod accuracy;
mod baked;
pub mod energy;
pub mod exact;
pub mod ggx;
pub mod layered;
pub mod path;
pub mod thesis;
pub mod walk;

pub use ggx::{ggx_d, ggx_d_sin, smith_g2, smith_lambda};

use super::lut::Lut;

/// Smallest GGX α: roughness 0 would make D a Dirac delta. 1e-3 keeps D's peak
/// 1 / (π α²) ≈ 3.2e5, finite in f32, and is a mirror to the eye.
pub const ALPHA_MIN: f64 = 1e-3;

/// GGX α of a roughness: roughness² (the perceptual mapping of Burley 2012, as glTF reads
/// its roughness), within [ALPHA_MIN, 1]. Every lobe, table and walk reads it; `brdf.wgsl`'s
/// `ggx_alpha` is the same expression. (`plain.wgsl`, the baseline shader `bench gpu` times
/// the skin against, is a program of its own without brdf.wgsl and keeps its own. A NaN
/// roughness stays NaN, as `clamp` passes it: presets and the command line refuse one.)
pub fn ggx_alpha(roughness: f64) -> f64 {
    (roughness * roughness).clamp(ALPHA_MIN, 1.0)
}

/// `ggx_alpha` in f32.
pub fn ggx_alpha_f32(roughness: f32) -> f32 {
    (roughness * roughness).clamp(ALPHA_MIN as f32, 1.0)
}
/// Floor on cosines after the hemisphere test.
pub const COS_MIN: f64 = 1e-6;
/// A direction shorter than this is treated as no direction (zero normal, zero wi or wo).
pub const LENGTH_MIN: f64 = 1e-12;

/// A layer model: what the light that crosses the top interface does beneath it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Model {
    /// The thesis' eq. 4.21 (Weidlich & Wilkie 2007 single scatter): kept for comparison.
    Thesis,
    /// The stack's transport: (n0/n2)², the internal-reflection series 1 / (1 − k_d K) and
    /// the rough top's energy coupling (`layered.rs`). The default: within ΔE00 1 of the
    /// rough reference on average where the thesis model is off by 4–23 (`bench layered`).
    #[default]
    Layered,
}

impl Model {
    pub const ALL: [Model; 2] = [Model::Thesis, Model::Layered];
    /// The names, for error messages (a test ties it to `ALL`).
    pub const ACCEPTED: &'static str = "thesis, layered";

    pub fn name(self) -> &'static str {
        match self {
            Model::Thesis => "thesis",
            Model::Layered => "layered",
        }
    }

    pub fn parse(name: &str) -> Option<Model> {
        Model::ALL.into_iter().find(|m| m.name() == name)
    }

    /// The value of `brdf.wgsl`'s `BRDF_MODEL` override constant (`MODEL_THESIS`, ...).
    pub fn code(self) -> u32 {
        match self {
            Model::Thesis => 0,
            Model::Layered => 1,
        }
    }

    /// Whether the model reads the stack's bounce terms K and E (`Layers::k`, `e`): callers
    /// skip computing them (the film seen from below, ~10⁶ Airy sums per new film thickness)
    /// for models that do not.
    pub fn reads_bounce(self) -> bool {
        match self {
            Model::Thesis => false,
            Model::Layered => true,
        }
    }

    /// The diffuse lobe (f64) at floored cosines with the model's `coupling` there.
    fn diffuse(self, layers: &Layers, cos_i: f64, cos_o: f64, f_i: [f64; 3], f_o: [f64; 3]) -> [f64; 3] {
        match self {
            Model::Thesis => thesis::diffuse(layers, cos_i, cos_o, f_i, f_o),
            Model::Layered => layered::diffuse(layers, cos_i, cos_o, f_i, f_o),
        }
    }

    /// The f32 diffuse lobe at the two directions' cosines, with what the top reflects
    /// there and the path deltas the coupling table brings (the thesis model reads no delta).
    fn diffuse_f32(self, layers: &Layers32, cos: [f32; 2], reflected: [[f32; 3]; 2], path_delta: [f32; 2]) -> [f32; 3] {
        match self {
            Model::Thesis => thesis::diffuse_f32(layers, cos[0], cos[1], reflected[0], reflected[1]),
            Model::Layered => layered::diffuse_f32(layers, cos, reflected, path_delta),
        }
    }

    /// What the top does by itself for light from a direction at cosine `cos`, per channel
    /// (`energy::Top`): the share it reflects (the diffuse lobe lets 1 minus this into the
    /// stack, and the ambient term's mirror part is the sky times this) and the amplitude
    /// of its multiple-scatter lobe. The thesis: the film F(cos) (`film` clamped to [0, 1]),
    /// no multiple scattering; the layered model: the rough lobe's albedo with the film read
    /// at its microfacet angles plus its multiple scattering and the light that comes
    /// straight back through it (`energy::top`, with the material's rule for that:
    /// `path::PathTable::through`). `layers` gives the roughness and the material's indices.
    /// `brdf.wgsl`'s `coupling`.
    pub fn coupling(self, cos: f64, layers: &Layers, film: &dyn Fn(f64) -> [f64; 3]) -> energy::Top<f64> {
        match self {
            Model::Thesis => energy::Top { reflected: film(cos), ms_amplitude: [0.0; 3] },
            Model::Layered => path::with(layers.n0, layers.n2, |p| {
                energy::top(cos, layers.roughness, film, &p.through, layers.lobe_rule())
            }),
        }
    }

    /// `coupling` at several cosines (an evaluation's light and view, or one of them), which
    /// share the rough lobe's normalisation (`energy::tops`; `norms` from `ms_norms` where
    /// the caller has it). `film` as the coupling reads it (`coupling_film`).
    fn couplings<const N: usize>(
        self,
        cos: [f64; N],
        layers: &Layers,
        film: &dyn Fn(f64) -> [f64; 3],
        norms: Option<energy::MsNorms>,
    ) -> [energy::Top<f64>; N] {
        match self {
            Model::Thesis => cos.map(|c| self.coupling(c, layers, film)),
            Model::Layered => path::with(layers.n0, layers.n2, |p| {
                energy::tops(cos, layers.roughness, film, &p.through, layers.lobe_rule(), norms)
            }),
        }
    }

    /// The rough top's multiple-scatter normalisation X̄ on the two roughness rows around
    /// `layers.roughness`, `film` as the coupling reads it (`coupling_film`): the same
    /// for every pair of directions, so an integral over directions computes it once
    /// (`furnace_albedo`: it was four fifths of each evaluation's rule there). None for the
    /// thesis model, which has no such lobe.
    fn ms_norms(self, layers: &Layers, film: &dyn Fn(f64) -> [f64; 3]) -> Option<energy::MsNorms> {
        match self {
            Model::Thesis => None,
            Model::Layered => Some(path::with(layers.n0, layers.n2, |p| {
                energy::ms_norms(layers.roughness, film, &p.through, layers.lobe_rule())
            })),
        }
    }

    /// The f32 twin of `coupling` for the light's and the view's cosines, with the film from
    /// `lut`, and the path delta there, in two halves: this one starts it,
    /// `finish_coupling_f32` finishes it. The layered model reads the LUT's coupling table
    /// (the rule on the lobe's roughness rows per cos texel and thickness column,
    /// interpolated between rows as the rule does: `Lut::coupling_pair_f32`, one search for
    /// the pixel's thickness and roughness), as the shader does for the LUT film method, and
    /// asks for its texels here so they load while the caller evaluates the specular lobe
    /// (`Lut::coupling_pair_start`); the thesis model reads the film table, small enough to
    /// stay cached.
    #[inline(always)]
    fn start_coupling_f32(self, cos: [f32; 2], layers: &Layers32, lut: &Lut) -> PendingCoupling {
        match self {
            Model::Thesis => PendingCoupling::Film(cos),
            Model::Layered => {
                PendingCoupling::Table(lut.coupling_pair_start(layers.thickness_nm, cos, layers.roughness))
            }
        }
    }

    /// The second half of `start_coupling_f32`: the light's and the view's coupling.
    #[inline(always)]
    fn finish_coupling_f32(pending: PendingCoupling, layers: &Layers32, lut: &Lut) -> [(energy::Top<f32>, f32); 2] {
        match pending {
            PendingCoupling::Film(cos) => cos.map(|cos| {
                let reflected = lut.lookup_f32(layers.thickness_nm, cos.clamp(0.0, 1.0)).map(|v| v.clamp(0.0, 1.0));
                (energy::Top { reflected, ms_amplitude: [0.0; 3] }, 0.0)
            }),
            PendingCoupling::Table(fetch) => lut.coupling_pair_read(&fetch),
        }
    }

    /// The base albedo k_d behind a colour-map value `colour` (linear) for a pixel whose
    /// layers are `layers` (their `albedo` is not read): the thesis reads the map as k_d
    /// itself; the layered model reads it as the visible diffuse colour
    /// (`layered::visible_colour`) and inverts the stack in closed form, at most 1. The
    /// renderer, the CPU reference frame and `brdf.wgsl`'s `base_albedo` all go through this.
    pub fn base_albedo(self, colour: [f64; 3], layers: &Layers) -> [f64; 3] {
        match self {
            Model::Thesis => colour,
            Model::Layered => {
                let t1 = layered::normal_transmittance(layers.n0, layers.n2, layers.roughness, layers.optical_depth);
                [0, 1, 2].map(|c| layered::base_albedo(colour[c], t1[c], layers.k[c], layers.e[c]))
            }
        }
    }

    /// The ambient term's diffuse part towards a view at cosine `cos_o`, with `s_o` the
    /// model's `coupling` there: multiplies the sky radiance along the normal (the reference
    /// renderer's twin of `brdf.wgsl`'s `ambient_diffuse`).
    pub fn ambient_diffuse(self, layers: &Layers, cos_o: f64, s_o: [f64; 3]) -> [f64; 3] {
        match self {
            Model::Thesis => thesis::ambient_diffuse(layers, cos_o, s_o),
            Model::Layered => layered::ambient_diffuse(layers, cos_o, s_o),
        }
    }
}

/// A coupling read that `Model::start_coupling_f32` started: the thesis model's two cosines
/// (it reads the film there), or the layered model's texels in the coupling table.
#[derive(Clone, Copy)]
enum PendingCoupling {
    Film([f32; 2]),
    Table(super::lut::CouplingFetch),
}

/// Per-pixel layer parameters (linear RGB where RGB).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Layers {
    pub n0: f64,
    /// The film's index: where it (or n2) is below n0 the coupling reads the film by the
    /// quantile rule (`energy::LobeRule::of`).
    pub n1: f64,
    pub n2: f64,
    /// Perceptual roughness r (α = r²).
    pub roughness: f64,
    /// Optical depth τ = σ0 δ1 of the pigment layer, per channel.
    pub optical_depth: [f64; 3],
    /// Albedo k_d of the Lambertian base.
    pub albedo: [f64; 3],
    /// K: the fraction of the base's diffuse light the top sends back down per bounce, per
    /// channel (the `layered` model; `of_stack` computes it).
    pub k: [f64; 3],
    /// E: the fraction that escapes per bounce.
    pub e: [f64; 3],
}

impl Layers {
    /// The layers of a material: its stack, film thickness (for K and E: the film seen from
    /// below), roughness, optical depth and base albedo.
    pub fn of_stack(
        stack: super::film::Stack,
        thickness_nm: f64,
        roughness: f64,
        optical_depth: [f64; 3],
        albedo: [f64; 3],
    ) -> Layers {
        let (k, e) = exact::cached(stack, thickness_nm).k_e_at(optical_depth, roughness);
        Layers { n0: stack.n0, n1: stack.n1, n2: stack.n2, roughness, optical_depth, albedo, k, e }
    }

    /// How the rough top's coupling reads this material's film (`energy::LobeRule::of`).
    pub fn lobe_rule(&self) -> energy::LobeRule {
        energy::LobeRule::of(self.n0, self.n1, self.n2)
    }

    /// The f32 form, with the film thickness the LUT is read at.
    pub fn to_f32(&self, thickness_nm: f64) -> Layers32 {
        Layers32 {
            n0: self.n0 as f32,
            n2: self.n2 as f32,
            roughness: self.roughness as f32,
            optical_depth: self.optical_depth.map(|v| v as f32),
            albedo: self.albedo.map(|v| v as f32),
            thickness_nm: thickness_nm as f32,
            k: self.k.map(|v| v as f32),
            e: self.e.map(|v| v as f32),
        }
    }
}

/// The BRDF's lobes: the single-scatter specular lobe, the top's multiple scattering and
/// the diffuse lobe (each RGB, per steradian).
struct Lobes {
    single: [f64; 3],
    multiple: [f64; 3],
    diffuse: [f64; 3],
}

/// The BRDF split into its two lobes (each RGB, per steradian): what the top reflects
/// (single and multiple scattering) and what comes from under it.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct BrdfValue {
    pub specular: [f64; 3],
    pub diffuse: [f64; 3],
}

impl BrdfValue {
    pub fn total(&self) -> [f64; 3] {
        [0, 1, 2].map(|c| self.specular[c] + self.diffuse[c])
    }
    const ZERO: BrdfValue = BrdfValue { specular: [0.0; 3], diffuse: [0.0; 3] };
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn normalize(v: [f64; 3]) -> Option<[f64; 3]> {
    let len = dot(v, v).sqrt();
    (len.is_finite() && len > LENGTH_MIN).then(|| v.map(|c| c / len))
}

/// Cosine of the direction refracted into the pigment layer (Snell's law n0 sin θ =
/// n2 sin θ_t; the film's parallel faces do not change it); None under total internal
/// reflection (no light enters). Every model reads it.
pub fn cos_transmitted(n0: f64, n2: f64, cos: f64) -> Option<f64> {
    let k = snell_cos_sq(n0, n2, cos);
    (k > 0.0).then(|| k.sqrt())
}

pub use crate::optics::film::{snell_cos_sq, snell_cos_sq_f32};

/// (n0/n2)²: the radiance factor of light leaving the pigment layer (index n2) into the
/// ambient (n0), radiance going as n² across an interface (PHYSICS.md, "Layered transport,
/// exactly"). Every diffuse lobe and escape term multiplies by it; `brdf.wgsl`'s
/// `radiance_factor` is the same expression.
pub fn radiance_factor(n0: f64, n2: f64) -> f64 {
    (n0 / n2) * (n0 / n2)
}

/// `radiance_factor` in f32.
pub fn radiance_factor_f32(n0: f32, n2: f32) -> f32 {
    (n0 / n2) * (n0 / n2)
}

/// The film as the f64 coupling reads it: at the cosine clamped to [0, 1], its colour
/// clamped to [0, 1] (`film_clamped`).
fn coupling_film(film: &dyn Fn(f64) -> [f64; 3]) -> impl Fn(f64) -> [f64; 3] + '_ {
    move |c| film_clamped(film(c.clamp(0.0, 1.0)))
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

impl Model {
    /// Evaluates the BRDF. `film(cos)` returns the film's RGB reflectance at incidence cosine
    /// `cos` (the caller binds the material, thickness and method). The specular part is
    /// the single-scatter lobe plus the top's multiple scattering.
    pub fn eval(
        self,
        layers: &Layers,
        normal: [f64; 3],
        wi: [f64; 3],
        wo: [f64; 3],
        film: &dyn Fn(f64) -> [f64; 3],
    ) -> BrdfValue {
        let Some(lobes) = self.eval_lobes(layers, normal, wi, wo, film, None) else {
            return BrdfValue::ZERO;
        };
        let specular = [0, 1, 2].map(|c| lobes.single[c] + lobes.multiple[c]);
        BrdfValue { specular, diffuse: lobes.diffuse }
    }

    /// The BRDF's three lobes, or None where it is zero (below the horizon, no direction);
    /// `norms`: the model's `ms_norms` for this film, where the caller has computed it.
    fn eval_lobes(
        self,
        layers: &Layers,
        normal: [f64; 3],
        wi: [f64; 3],
        wo: [f64; 3],
        film: &dyn Fn(f64) -> [f64; 3],
        norms: Option<energy::MsNorms>,
    ) -> Option<Lobes> {
        let (single, cos_i, cos_o) = single_lobe(layers, normal, wi, wo, film)?;
        let [top_i, top_o] = self.couplings([cos_i, cos_o], layers, &coupling_film(film), norms);
        let (multiple, diffuse) = self.under_lobes(layers, [cos_i, cos_o], [&top_i, &top_o]);
        Some(Lobes { single, multiple, diffuse })
    }

    /// The multiple-scatter and diffuse lobes at the light's and the view's floored
    /// cosines, from the top's coupling there.
    fn under_lobes(self, layers: &Layers, cos: [f64; 2], top: [&energy::Top<f64>; 2]) -> ([f64; 3], [f64; 3]) {
        let [top_i, top_o] = top;
        (
            [0, 1, 2].map(|c| top_i.ms_amplitude[c] * top_o.ms_amplitude[c]),
            self.diffuse(layers, cos[0], cos[1], top_i.reflected, top_o.reflected),
        )
    }

    /// The f32 fast path, film colour from the material's LUT: the CPU twin of the shader.
    pub fn eval_f32(self, layers: &Layers32, normal: [f32; 3], wi: [f32; 3], wo: [f32; 3], lut: &Lut) -> [f32; 3] {
        match self {
            Model::Thesis => Model::Thesis.eval_f32_of(layers, normal, wi, wo, lut),
            Model::Layered => Model::Layered.eval_f32_of(layers, normal, wi, wo, lut),
        }
    }

    /// `eval_f32` for the model `self`, inlined into a copy per model so that neither pays
    /// for the other's branches and code: with one copy, the thesis model measured 108–117
    /// ns a call once the layered model's coupling was started early, against 105–110.
    #[inline(always)]
    fn eval_f32_of(self, layers: &Layers32, normal: [f32; 3], wi: [f32; 3], wo: [f32; 3], lut: &Lut) -> [f32; 3] {
        let n = normalize32(normal).unwrap_or([0.0, 0.0, 1.0]);
        let (Some(wi), Some(wo)) = (normalize32(wi), normalize32(wo)) else {
            return [0.0; 3];
        };
        let (cos_i, cos_o) = (dot32(n, wi), dot32(n, wo));
        if !(cos_i > 0.0 && cos_o > 0.0) {
            return [0.0; 3];
        }
        let cos_min = COS_MIN as f32;
        let (cos_i, cos_o) = (cos_i.max(cos_min), cos_o.max(cos_min));
        let coupling = self.start_coupling_f32([cos_i, cos_o], layers, lut);
        let Some(h) = normalize32([wi[0] + wo[0], wi[1] + wo[1], wi[2] + wo[2]]) else {
            return [0.0; 3];
        };
        let alpha = ggx_alpha_f32(layers.roughness);
        let film = |c: f32| lut.lookup_f32(layers.thickness_nm, c.clamp(0.0, 1.0)).map(|v| v.clamp(0.0, 1.0));

        let cos_h = dot32(n, h).clamp(0.0, 1.0);
        let nxh = [n[1] * h[2] - n[2] * h[1], n[2] * h[0] - n[0] * h[2], n[0] * h[1] - n[1] * h[0]];
        let spec = ggx::specular_scale_f32(cos_h, dot32(nxh, nxh), cos_i, cos_o, alpha * alpha);
        let f_h = film(dot32(wo, h).abs());
        let [(top_i, delta_i), (top_o, delta_o)] = Model::finish_coupling_f32(coupling, layers, lut);
        let diffuse = self.diffuse_f32(layers, [cos_i, cos_o], [top_i.reflected, top_o.reflected], [delta_i, delta_o]);
        [0, 1, 2].map(|c| f_h[c] * spec + top_i.ms_amplitude[c] * top_o.ms_amplitude[c] + diffuse[c])
    }

    /// White-furnace albedo ∫ f(wi, wo) cos θi dωi for view cosine `cos_o`, with k_d = 1 and
    /// τ = 0 passed in `layers`. The single-scatter lobe is integrated in half-vector space
    /// with stratified GGX sampling (exact for any α, however peaked); the multiple-scatter
    /// and diffuse lobes, which depend on θi only, by the midpoint rule in cos θi. `n`
    /// strata per axis.
    pub fn furnace_albedo(self, layers: &Layers, cos_o: f64, film: &dyn Fn(f64) -> [f64; 3], n: usize) -> [f64; 3] {
        let cos_o = cos_o.clamp(COS_MIN, 1.0);
        let wo = [(1.0 - cos_o * cos_o).sqrt(), 0.0, cos_o];
        let alpha = ggx_alpha(layers.roughness);
        let mut spec = [0.0; 3];
        for hv in ggx::stratified_half_vectors(wo, alpha, n) {
            // f cos θi / pdf(wi).
            let Some((single, _, _)) = single_lobe(layers, NORMAL, hv.wi, wo, film) else {
                continue;
            };
            for (s, v) in spec.iter_mut().zip(single) {
                *s += v * hv.wi[2] / hv.pdf_wi;
            }
        }
        let spec = spec.map(|s| s / (n * n) as f64);
        // The lobes under the specular one, as `eval_lobes` gives them, with what does not
        // depend on wi computed once: the rough lobe's normalisation and the view's coupling.
        let mut diffuse = [0.0; 3];
        if let Some(cos_o) = normalize(wo).and_then(|wo| floored_cos(NORMAL, wo)) {
            let film = coupling_film(film);
            let norms = self.ms_norms(layers, &film);
            let [top_o] = self.couplings([cos_o], layers, &film, norms);
            for a in 0..n * n {
                // ∫ over the hemisphere of g(θi) cos θi dω = 2π ∫ g(μ) μ dμ.
                let mu = (a as f64 + 0.5) / (n * n) as f64;
                let Some(cos_i) = normalize([(1.0 - mu * mu).sqrt(), 0.0, mu]).and_then(|wi| floored_cos(NORMAL, wi))
                else {
                    continue;
                };
                let [top_i] = self.couplings([cos_i], layers, &film, norms);
                let (multiple, under) = self.under_lobes(layers, [cos_i, cos_o], [&top_i, &top_o]);
                for (c, d) in diffuse.iter_mut().enumerate() {
                    *d += (multiple[c] + under[c]) * mu * 2.0 * std::f64::consts::PI / (n * n) as f64;
                }
            }
        }
        [0, 1, 2].map(|c| spec[c] + diffuse[c])
    }
}

/// The normal of the integrals' frame, and the one taken where a normal given has no direction.
const NORMAL: [f64; 3] = [0.0, 0.0, 1.0];

/// The cosine between the unit normal `n` and the unit direction `w`, floored at `COS_MIN`
/// as every lobe reads it; None at or below the horizon (where the BRDF is zero).
fn floored_cos(n: [f64; 3], w: [f64; 3]) -> Option<f64> {
    let cos = dot(n, w);
    (cos > 0.0).then(|| cos.max(COS_MIN))
}

/// The single-scatter specular lobe every model shares, with the floored cosines of wi
/// and wo; None where the BRDF is zero (below the horizon, no direction).
fn single_lobe(
    layers: &Layers,
    normal: [f64; 3],
    wi: [f64; 3],
    wo: [f64; 3],
    film: &dyn Fn(f64) -> [f64; 3],
) -> Option<([f64; 3], f64, f64)> {
    let n = normalize(normal).unwrap_or(NORMAL);
    let (wi, wo) = (normalize(wi)?, normalize(wo)?);
    let (cos_i, cos_o) = (floored_cos(n, wi)?, floored_cos(n, wo)?);
    let h = normalize([wi[0] + wo[0], wi[1] + wo[1], wi[2] + wo[2]])?;
    let alpha = ggx_alpha(layers.roughness);
    let nxh = cross(n, h);
    let d = ggx_d_sin(dot(n, h).clamp(0.0, 1.0), dot(nxh, nxh), alpha);
    let g2 = smith_g2(cos_i, cos_o, alpha);
    let f_h = film_clamped(film(dot(wo, h).abs().clamp(0.0, 1.0)));
    let spec_scale = d * g2 / (4.0 * cos_i * cos_o);
    Some((f_h.map(|f| f * spec_scale), cos_i, cos_o))
}

/// f32 layer parameters for the fast path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Layers32 {
    pub n0: f32,
    pub n2: f32,
    pub roughness: f32,
    pub optical_depth: [f32; 3],
    pub albedo: [f32; 3],
    pub thickness_nm: f32,
    pub k: [f32; 3],
    pub e: [f32; 3],
}

fn dot32(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn normalize32(v: [f32; 3]) -> Option<[f32; 3]> {
    let len = dot32(v, v).sqrt();
    (len.is_finite() && len > LENGTH_MIN as f32).then(|| v.map(|c| c / len))
}

/// The film's reflectance made a valid reflectance: clamped to [0, 1] per channel, 1 where
/// not finite (so 1 − F is a valid transmittance).
fn film_clamped(rgb: [f64; 3]) -> [f64; 3] {
    rgb.map(|v| if v.is_finite() { v.clamp(0.0, 1.0) } else { 1.0 })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_model_has_one_name_and_code_and_accepted_lists_them() {
        let names: Vec<&str> = Model::ALL.iter().map(|m| m.name()).collect();
        assert_eq!(Model::ACCEPTED, names.join(", "));
        for m in Model::ALL {
            assert_eq!(Model::parse(m.name()), Some(m));
            assert_eq!(Model::ALL.iter().filter(|o| o.code() == m.code()).count(), 1);
        }
        assert_eq!(Model::parse("lambert"), None);
    }

    /// `furnace_albedo` computes the lobe's normalisation and the view's coupling once per
    /// integral; it is still the sum, by its rules, of the lobes each evaluation gives.
    #[test]
    fn the_furnace_integral_sums_the_lobes_each_evaluation_gives() {
        let film = |c: f64| [0.04 + 0.5 * (1.0 - c).powi(5), 0.08 * c, 0.3 - 0.2 * c];
        let n = 5;
        let cases: [(f64, f64, f64, f64); 4] =
            [(0.07, 0.97, 1.0, 1.55), (0.45, 0.5, 1.33, 1.33), (0.9, 0.08, 1.0, 2.0), (0.3, 0.0, 1.0, 1.5)];
        for model in Model::ALL {
            for (roughness, cos_o, n0, n2) in cases {
                let layers = Layers {
                    n0,
                    n1: n2,
                    n2,
                    roughness,
                    optical_depth: [0.0; 3],
                    albedo: [1.0, 0.6, 0.2],
                    k: [0.3, 0.35, 0.45],
                    e: [0.6, 0.5, 0.4],
                };
                let c = cos_o.max(COS_MIN);
                let wo = [(1.0 - c * c).sqrt(), 0.0, c];
                let alpha = ggx_alpha(roughness);
                let mut sum = [0.0; 3];
                for hv in ggx::stratified_half_vectors(wo, alpha, n) {
                    let (single, _, _) = single_lobe(&layers, NORMAL, hv.wi, wo, &film).unwrap_or_default();
                    (0..3).for_each(|k| sum[k] += single[k] * hv.wi[2] / hv.pdf_wi / (n * n) as f64);
                }
                for a in 0..n * n {
                    let mu = (a as f64 + 0.5) / (n * n) as f64;
                    let wi = [(1.0 - mu * mu).sqrt(), 0.0, mu];
                    // Each evaluation on its own: its own normalisation and both couplings.
                    let lobes = model.eval_lobes(&layers, NORMAL, wi, wo, &film, None).expect("above the horizon");
                    let weight = mu * 2.0 * std::f64::consts::PI / (n * n) as f64;
                    (0..3).for_each(|k| sum[k] += (lobes.multiple[k] + lobes.diffuse[k]) * weight);
                }
                let integral = model.furnace_albedo(&layers, cos_o, &film, n);
                let case = format!("{model:?} roughness {roughness} cos_o {cos_o} n0 {n0} n2 {n2}");
                assert!((0..3).all(|k| (integral[k] - sum[k]).abs() <= 1e-12), "{case}: {integral:?} {sum:?}");
                assert!(sum.iter().all(|v| *v > 0.01), "{case}: {sum:?}");
            }
        }
    }
}
