//! The `layered` model: the real-time form of the stack's transport (PHYSICS.md, "Layered
//! transport, exactly"), with the rough top coupled to it by energy (`energy`).
//!
//! ```text
//! s(μ)   = E₁ ⟨F⟩ + (1 − E₁) g + q                     what the rough top reflects
//! f_ms   = ms(μi) ms(μo)                                 its multiple scattering
//! a(μ)   = (1 − s(μ)) exp(−τ / cos_eff(μ, r))           light that enters and reaches the base
//! f_diff = (n0/n2)² k_d a(μi) a(μo) / (π (1 − k_d K))
//! ambient diffuse (sky along the normal) = a(μo) k_d E / (1 − k_d K)
//! ```
//!
//! with ⟨F⟩ the film read at the lobe's microfacet angles, g the share of the light it
//! scatters more than once that the film reflects (`energy::Multiple`), q the light straight back
//! through the top (`energy::top`; `Model::coupling` passes s in), and cos_eff the cosine at which
//! the light the rough top lets in crosses the pigment layer (`path`: Snell's cos_t at
//! r = 0, more oblique as the top roughens).
//!
//! K and E (per channel, per material, per roughness, per film thickness) come with the
//! layers (`Layers::of_stack`: the film seen from below, `exact::SmoothTop::bounce_table`;
//! the renderer interpolates them over thickness, `render::engine::scene::BounceGrid`). At r = 0
//! this is the smooth-top closed form exactly, up to the film colour method. f64, f32 (the
//! shader's twin) and the ambient term read one formula.

use std::f64::consts::PI;

use super::{COS_MIN, Layers, Layers32, cos_transmitted};

/// A known limit of the layered model, where the medium above is denser than the pigment
/// layer (n0 > n2): light the rough top sends beyond the critical angle asin(n2 / n0) has
/// nowhere to go in the model (the physics reflects it back up), so a white stack without
/// absorption reflects as little as a quarter of the light there, dropping at that angle
/// (`brdf albedo --model layered --absorption 0 --albedo 1 --thickness-nm 400 --n0 1.5 --n1
/// 1.55 --n2 1.33 --roughness 1`: 0.995 at 62°, 0.238 at 63°, the critical angle 62.5°;
/// 0.267 on (1.2, 1.3, 1.0); the walk gives 1; an independent review measured 0.392 at 70°,
/// past the 0.4 this said). `None` where n0 ≤ n2.
///
/// Letting the lobe send light beyond the critical angle (1 − s there, E taking the light it
/// sends out there and K giving it up) was tried and is not enough (a later session;
/// BENCHMARKS, "A pigment layer less dense than the ambient: the top reflects too little"):
/// the rough top's own s is too small there. On the bare interface 1.5 | 1.33 with k_d = 0
/// (`brdf albedo --model layered` against `--model stochastic`, `--albedo 0 --thickness-nm
/// 0 --n0 1.5 --n1 1.4 --n2 1.33 --absorption 0`), roughness 1: 0.38 against the walk's
/// 0.57 at 70°, 0.62 against 0.94 at 80°; roughness 0.6: 0.54 against 0.61 at 70°;
/// roughness 0.3 within 0.011. The walk's difference is light that enters the microsurface
/// and comes straight back (its never-entering share is 0.08 at 70°, roughness 1); the
/// model's straight-back term q counts it only for light entering through the lobe's first
/// microfacet. With n0 < n2 the two agree within 0.001 (1 | 1.33, roughness 1, 0°–85°). Summed
/// over the hemisphere that s lets in (n0/n2)² ⟨1 − s⟩ ≈ 1.10 of a Lambertian's light at
/// roughness 1, where the walk's top keeps the balance n0² ⟨T↓⟩ = n2² ⟨T↑⟩ (1.762 both ways,
/// α = 1), so E would pass 1 − K and the furnace 1.07. One home
/// for the condition and its wording: a preset's check (`validate`) and `brdf eval`/`albedo`
/// warn with it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModelLimit {
    pub critical_angle_deg: f64,
}

impl ModelLimit {
    pub fn of(n0: f64, n2: f64) -> Option<ModelLimit> {
        (n0 > n2).then(|| ModelLimit { critical_angle_deg: (n2 / n0).asin().to_degrees() })
    }
}

impl std::fmt::Display for ModelLimit {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "the layered model loses light beyond the critical angle ({:.0}° from the normal), where the rough \
             top's reflection has nowhere to go (a white stack without absorption reflects as little as a quarter of \
             the light, dropping there), so its values are darker than the physics there; and from roughness 0.6 \
             its top reflects too little of oblique light (0.38 where the physics gives 0.57 at 70° under roughness 1)",
            self.critical_angle_deg
        )
    }
}

/// A second known limit of the layered model, where the film's index is below the medium
/// above it (n1 < n0), what is left of it. Such a film totally reflects beyond its critical
/// angle asin(n1 / n0) and, thick, rings with fringes just inside it; the lobe's five-point
/// Gauss rule read it as 0.89 to 1.19 of the light around that angle, and the coupling now
/// reads such films by the quantile rule (`energy::LobeRule`): from roughness
/// `FILM_BELOW_AMBIENT_ROUGH` up within 0.02 of the furnace to 70° and 0.05 beyond, the
/// issue's bounds (`tests/brdf.rs`, films of 250–2400 nm, 0°–80°: 0.017 at most). Left: under smoother tops, within a few degrees of the critical
/// angle, in bands about a degree wide, up to 0.04 (0.0375: 2400 nm, roughness 0.1, 62.5°,
/// the exact film; `brdf albedo --n0 1.5 --n1 1.35 --n2 2 --roughness 0.05 --thickness-nm
/// 1500 --absorption 0 --angle-deg 62.5`: 0.970 / 0.993 / 1.017), where the lobe is narrower
/// than the fringes, the tables' roughness rows are interpolated and the bounce terms K and E
/// integrate the film's corner over fixed nodes (a mirror: 0.018). Films of at most
/// `FILM_BELOW_AMBIENT_THIN_NM` let the light tunnel through and keep within 0.02.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FilmBelowAmbient {
    pub critical_angle_deg: f64,
}

/// Films at most this thick are within 0.02 of the furnace with n1 < n0 (`FilmBelowAmbient`).
pub const FILM_BELOW_AMBIENT_THIN_NM: f64 = 250.0;
/// Tops at least this rough are within 0.02 of the furnace with n1 < n0 (`FilmBelowAmbient`).
pub const FILM_BELOW_AMBIENT_ROUGH: f64 = 0.3;

impl FilmBelowAmbient {
    /// The limit for a film of index `n1` under an ambient `n0`, at most `thickest_nm`
    /// thick, under tops whose roughness spans `roughness` (smoothest, roughest): `None`
    /// where n1 ≥ n0, or the film or the tops stay where the model was measured within 0.02.
    pub fn of(n0: f64, n1: f64, thickest_nm: f64, roughness: (f64, f64)) -> Option<FilmBelowAmbient> {
        let smoothest = roughness.0.min(roughness.1);
        let off = n1 < n0 && thickest_nm > FILM_BELOW_AMBIENT_THIN_NM && smoothest < FILM_BELOW_AMBIENT_ROUGH;
        off.then(|| FilmBelowAmbient { critical_angle_deg: (n1 / n0).asin().to_degrees() })
    }
}

impl std::fmt::Display for FilmBelowAmbient {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "within a few degrees of the film's critical angle ({:.0}° from the normal) the layered model's energy is \
             off for films thicker than {FILM_BELOW_AMBIENT_THIN_NM} nm under a top smoother than \
             {FILM_BELOW_AMBIENT_ROUGH}: a white stack without absorption reflects from 0.96 to 1.04 of the light in \
             bands about a degree wide there (measured), where the physics reflects all of it; rougher tops keep \
             within 0.02",
            self.critical_angle_deg
        )
    }
}

/// a(μ) per channel: the light from a direction at cosine `cos` that reaches the base,
/// `s` what the rough lobe reflects there.
fn entering(layers: &Layers, cos: f64, s: [f64; 3]) -> [f64; 3] {
    let Some(cos_t) = cos_transmitted(layers.n0, layers.n2, cos) else {
        return [0.0; 3];
    };
    let t = path_transmittance(layers.n0, layers.n2, layers.roughness, layers.optical_depth, cos_t, cos);
    [0, 1, 2].map(|c| (1.0 - s[c]) * t[c])
}

/// exp(−τ / cos_eff(μ, r)) per channel: what the pigment layer lets through of the light the
/// top lets in from a direction at cosine `cos` above, `cos_t` its Snell cosine below (1
/// without absorption, where the path table is not read).
fn path_transmittance(n0: f64, n2: f64, roughness: f64, optical_depth: [f64; 3], cos_t: f64, cos: f64) -> [f64; 3] {
    if optical_depth.iter().all(|t| *t <= 0.0) {
        return [1.0; 3];
    }
    let path_cos = super::path::with(n0, n2, |p| p.cos_eff(cos_t, cos, roughness));
    optical_depth.map(|t| (-t.max(0.0) / path_cos).exp())
}

/// `path_transmittance` at normal incidence, t₁ = exp(−τ / cos_eff(1, r)) per channel
/// (`visible_colour`'s factor).
pub fn normal_transmittance(n0: f64, n2: f64, roughness: f64, optical_depth: [f64; 3]) -> [f64; 3] {
    path_transmittance(n0, n2, roughness, optical_depth, 1.0, 1.0)
}

pub fn diffuse(layers: &Layers, cos_i: f64, cos_o: f64, f_i: [f64; 3], f_o: [f64; 3]) -> [f64; 3] {
    let (a_i, a_o) = (entering(layers, cos_i, f_i), entering(layers, cos_o, f_o));
    let eta2 = (layers.n0 / layers.n2) * (layers.n0 / layers.n2);
    [0, 1, 2].map(|c| {
        let kd = layers.albedo[c].clamp(0.0, 1.0);
        eta2 * kd * a_i[c] * a_o[c] / (PI * (1.0 - kd * layers.k[c]))
    })
}

pub fn ambient_diffuse(layers: &Layers, cos_o: f64, f_o: [f64; 3]) -> [f64; 3] {
    let a_o = entering(layers, cos_o, f_o);
    [0, 1, 2].map(|c| {
        let kd = layers.albedo[c].clamp(0.0, 1.0);
        a_o[c] * kd * layers.e[c] / (1.0 - kd * layers.k[c])
    })
}

/// The f32 diffuse lobe, as `brdf.wgsl`'s `layered_diffuse`: the two directions' paths
/// through the pigment layer attenuate in one exponential, exp(−τ (1/cos_eff,i + 1/cos_eff,o))
/// (= a(μi) a(μo) / ((1 − s_i)(1 − s_o)), three exponentials instead of six), with the path
/// deltas cos_eff − cos_t that the coupling table brings for each direction
/// (`lut::Lut::coupling_f32`).
pub fn diffuse_f32(layers: &Layers32, cos: [f32; 2], reflected: [[f32; 3]; 2], path_delta: [f32; 2]) -> [f32; 3] {
    let ([cos_i, cos_o], [f_i, f_o]) = (cos, reflected);
    let eta2 = (layers.n0 / layers.n2) * (layers.n0 / layers.n2);
    let (k_i, k_o) = ((1.0 - eta2) + eta2 * cos_i * cos_i, (1.0 - eta2) + eta2 * cos_o * cos_o);
    if !(k_i > 0.0 && k_o > 0.0) {
        return [0.0; 3];
    }
    let absorbing = layers.optical_depth.iter().any(|t| *t > 0.0);
    let inverse_path = if absorbing {
        let cos_min = COS_MIN as f32;
        1.0 / (k_i.sqrt() + path_delta[0]).max(cos_min) + 1.0 / (k_o.sqrt() + path_delta[1]).max(cos_min)
    } else {
        0.0
    };
    [0, 1, 2].map(|c| {
        let kd = layers.albedo[c].clamp(0.0, 1.0);
        let attenuation = if absorbing { (-layers.optical_depth[c].max(0.0) * inverse_path).exp() } else { 1.0 };
        eta2 * kd * (1.0 - f_i[c]) * (1.0 - f_o[c]) * attenuation / (std::f32::consts::PI * (1.0 - kd * layers.k[c]))
    })
}

/// What the colour map means under the `layered` model: the **visible diffuse colour**, the
/// stack's diffuse reflectance at normal incidence per unit of light the top lets in,
///
/// ```text
/// c = R_d(μ = 1) / (1 − s(1)) = t₁ k_d E / (1 − k_d K),   t₁ = exp(−τ / cos_eff(1, r))
/// ```
///
/// (`R_d` of `exact::SmoothTop::albedo`, where t₁ = exp(−τ); t₁ the pigment layer's
/// transmittance along the path of the light the top lets in at normal incidence,
/// `normal_transmittance`; K and E the material's bounce terms at the pixel's roughness).
/// It is what glTF's `baseColor` means under a dielectric top (the base weighted by what the
/// top transmits), so a colour map is a base colour other tools read right. `base_albedo`
/// inverts it per pixel.
pub fn visible_colour(albedo: f64, normal_transmittance: f64, k: f64, e: f64) -> f64 {
    let kd = albedo.clamp(0.0, 1.0);
    normal_transmittance * kd * e / (1.0 - kd * k)
}

/// The brightest visible colour the stack can show (k_d = 1): t₁ E / (1 − K). For a
/// lossless stack (τ = 0) t₁ = 1, E = 1 − K and the limit is 1; absorption lowers it fast
/// (the thesis stack under a smooth top, τ = 0.6: 0.07).
pub fn visible_limit(normal_transmittance: f64, k: f64, e: f64) -> f64 {
    visible_colour(1.0, normal_transmittance, k, e)
}

/// The base albedo k_d that shows the visible colour `colour`:
/// k_d = c / (t₁ E + c K), the closed-form inverse of `visible_colour`; colours beyond
/// `visible_limit` give k_d = 1 (the limit); a stack that shows nothing (E = 0) gives 1 for
/// any colour but black (its limit is 0), and black gives 0.
pub fn base_albedo(colour: f64, normal_transmittance: f64, k: f64, e: f64) -> f64 {
    let c = colour.max(0.0);
    let denominator = normal_transmittance * e + c * k;
    if denominator > 0.0 { (c / denominator).min(1.0) } else { 0.0 }
}
