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
//!
//! **A pigment layer less dense than the ambient (n0 > n2).** A smooth top lets no light in
//! beyond the critical angle asin(n2 / n0); a rough one does, through tilted microfacets,
//! and a(μ) takes 1 − s(μ) there too (`entering`), E the light the lobe sends out there and
//! K gives it up (`exact::SmoothTop::k_e_row`), and much of that light comes straight back
//! through the top (`path::through_rule`'s node for total reflections). Until a later
//! session the lobe sent nothing beyond that angle and a white lossless stack reflected a
//! quarter of the light just past it (`brdf albedo --model layered --absorption 0 --albedo
//! 1 --thickness-nm 400 --n0 1.5 --n1 1.55 --n2 1.33 --roughness 1`: 0.995 at 62°, 0.238 at
//! 63°; now within 0.013 of 1 at 0°–85°), and presets with `ambient_ior` above `pigment_ior` were
//! warned of (BENCHMARKS, "A pigment layer less dense than the ambient").

use std::f64::consts::PI;

use super::{COS_MIN, Layers, Layers32};

/// What is left of the layered model's limit where the medium above is denser than the
/// pigment layer (n0 > n2): the rough top's reflection there is still short of the walk's by
/// up to 0.04 (light straight back that the multiple scattering's pair rule misses across
/// the critical angle's corner: `tests/brdf.rs`), and past a contrast of about 1.35 the
/// shortfall summed over the hemisphere lets out more light than arrives: the lossless E
/// passes 1, K is held at 0, and a white stack without absorption reflects more than
/// arrives (`brdf stress`'s 1.5 over 1: 1.05 at roughness 0.97; E at roughness 1 and 0 / 400
/// nm films: 1.0007 at n0 / n2 = 1.35, 1.028 at 1.4, 1.074 at 1.5; up to 1.35, within
/// 0.0056). E bounds the albedo only loosely at high contrast: at n0 / n2 = 3, E 1.424 and the
/// albedo at most about 1.08 (0°–89°, roughness 1: a hostile-input review), so the warning
/// names E as E, not as the albedo.
/// Found from the material's own K and E (`exact::SmoothTop::k_e_row`) on the roughness rows
/// a preset's roughness spans, at the thinnest and thickest films; warned of where E passes
/// 1 by more than `PIGMENT_BELOW_AMBIENT_EXCESS`.
///
/// At low contrast, too: where n0 < `PIGMENT_BELOW_AMBIENT_LOW_CONTRAST` n2 the critical angle
/// lies within about 14° of grazing, the light straight back makes a step in what the rough
/// top reflects there, and the multiple-scatter lobe's normalisation X̄ (`energy::ms_rule`'s
/// fixed nodes) misses it: grazing light under rough tops is reflected more than arrives (an
/// independent review's find; white furnace at 85°, n2 = 1.33, roughness 1 / 0.6: n0 = 1.335
/// 1.63 / 1.17, 1.34 1.21 / 1.12, 1.36 1.06 / 1.04, 1.38 1.03 / 1.01; the model before the
/// change read 1.52 at 1.335). Warned of at any roughness.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PigmentBelowAmbient {
    /// n0 / n2 below `PIGMENT_BELOW_AMBIENT_LOW_CONTRAST`: the critical angle, in degrees.
    LowContrast { critical_angle_deg: f64 },
    /// The lossless E passes 1: from the smallest roughness where it passes the limit (the
    /// first row of the energy table that does, or the smoothest top asked about where that
    /// lies above the row), by at most `excess`.
    Escapes { roughness_from: f64, excess: f64 },
}

/// How far the lossless E may pass 1 before `PigmentBelowAmbient` warns: the furnace bound
/// of the layered-transport issue.
pub const PIGMENT_BELOW_AMBIENT_EXCESS: f64 = 0.02;
/// Contrasts n0 / n2 above 1 and below this are warned of (`PigmentBelowAmbient::LowContrast`):
/// 1.36 / 1.33 = 1.023 read 1.06 at 85°, 1.38 / 1.33 = 1.038 within 0.03.
pub const PIGMENT_BELOW_AMBIENT_LOW_CONTRAST: f64 = 1.03;

impl PigmentBelowAmbient {
    /// The limit for `stack` with films `thickness_nm` (thinnest, thickest) under tops whose
    /// roughness spans `roughness` (smoothest, roughest): `None` where n0 ≤ n2 or the model
    /// stays within the limits.
    pub fn of(stack: crate::optics::film::Stack, thickness_nm: (f64, f64), roughness: (f64, f64)) -> Option<Self> {
        if stack.n0 <= stack.n2 {
            return None;
        }
        if stack.n0 < PIGMENT_BELOW_AMBIENT_LOW_CONTRAST * stack.n2 {
            let critical_angle_deg = (stack.n2 / stack.n0).asin().to_degrees();
            return Some(PigmentBelowAmbient::LowContrast { critical_angle_deg });
        }
        let row = super::energy::GridCell::<f64>::row_coordinate;
        let (smoothest, roughest) = (roughness.0.min(roughness.1), roughness.0.max(roughness.1));
        let rows = row(smoothest).floor() as usize..=row(roughest).ceil() as usize;
        let mut found: Option<(f64, f64)> = None;
        for row in rows {
            for film_nm in [thickness_nm.0, thickness_nm.1] {
                let (k, e) = super::exact::cached(stack, film_nm).k_e_row([0.0; 3], row);
                let excess = (0..3).map(|c| k[c] + e[c] - 1.0).fold(0.0, f64::max);
                if excess > PIGMENT_BELOW_AMBIENT_EXCESS {
                    found = Some(
                        found.map_or((super::energy::GridCell::<f64>::row_roughness(row), excess), |(from, worst)| {
                            (from, worst.max(excess))
                        }),
                    );
                }
            }
        }
        // A row below the preset's smoothest top is read only to interpolate towards it: the
        // warning names the preset's own roughness there, not the row's.
        found.map(|(row_from, excess)| PigmentBelowAmbient::Escapes {
            roughness_from: row_from.max(smoothest.clamp(0.0, 1.0)),
            excess,
        })
    }
}

impl std::fmt::Display for PigmentBelowAmbient {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            PigmentBelowAmbient::LowContrast { critical_angle_deg } => write!(
                f,
                "the critical angle ({critical_angle_deg:.0}° from the normal) lies near grazing, where the layered \
                 model's rough top reflects more light than arrives (a white stack under a rough top, up to 1.6 of \
                 it at 85° for 1.335 over 1.33)"
            ),
            PigmentBelowAmbient::Escapes { roughness_from, excess } => write!(
                f,
                "from roughness {roughness_from:.2} the layered model's rough top lets out more light than arrives \
                 (it reflects too little of the light a rough top sends straight back at this contrast): the share \
                 of the base's light it lets out reaches {:.3}, so a white stack without absorption reflects more \
                 than all the light (how much at one angle: `snakeskin brdf albedo --albedo 1 --absorption 0`)",
                1.0 + excess
            ),
        }
    }
}

/// A known limit of the layered model, where the pigment layer's index is near the medium's
/// above it (n0 / `PIGMENT_NEAR_AMBIENT_BELOW` < n2 < `PIGMENT_NEAR_AMBIENT` n0) and a film
/// lies between them, under a rough top. The light a rough top lets in and sends straight
/// back out (`path`'s q) is walked through the bare interface n0 | n2 and reweighted by the
/// film's reflectance over the bare one at the last reflection; near index matching the
/// bare interface reflects little, so few walked photons carry the rule (and at n0 = n2
/// none: W = 0), while the film's own reflections from below send much light straight
/// back. What the top reflects is then off the photon walk (`brdf albedo --model
/// stochastic`, 100,000 photons; film 1.55 of 400 nm, black base; an independent review's
/// find, and a second review's for n2 below n0). At roughness 1 and 85°, n0 1: by 0.32 at n2
/// = 1, 0.13 at 1.01, 0.04 at 1.05, 0.019 at 1.1, 0.010 at 1.15, 0.006 at 1.2; n2 1: by 0.32
/// at n0 = 1.03, 0.135 at 1.1, 0.061 at 1.2, 0.035 at 1.35, 0.009 at 1.5 (at 60°: 0.106 at
/// 1.1, 0.017–0.019 at 1.5 and 2). Under a top of roughness 0.2, at most 0.018 (n2 = n0 and
/// n0 = 1.03 n2); at 0.1, within 0.005. Films of 1.33 and 2.0 at n2 = 1.05: 0.011 and 0.017
/// (80°, roughness 0.8). Beyond a contrast of 1.35 `PigmentBelowAmbient::Escapes` warns.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PigmentNearAmbient {
    /// n2 / n0.
    pub ratio: f64,
}

/// Contrasts n2 / n0 from 1 to below this are warned of (`PigmentNearAmbient`): 1.15 read
/// within 0.010 of the walk at 85° and roughness 1, 1.1 by 0.019.
pub const PIGMENT_NEAR_AMBIENT: f64 = 1.15;
/// Contrasts n0 / n2 above 1 and below this are warned of too (`PigmentNearAmbient`): 1.35
/// read 0.035 off at 85°, 1.5 0.009; past 1.35 `PigmentBelowAmbient::Escapes` takes over.
pub const PIGMENT_NEAR_AMBIENT_BELOW: f64 = 1.35;
/// From this roughness up (`PigmentNearAmbient`): 0.2 read 0.018 off at n2 = n0.
pub const PIGMENT_NEAR_AMBIENT_ROUGH: f64 = 0.2;

impl PigmentNearAmbient {
    /// The limit for `stack` with its thickest film `thickest_nm` under its roughest top
    /// `roughest`; `None` outside it (no film that reflects, or a smoother top, or a
    /// contrast that is not near 1).
    pub fn of(stack: crate::optics::film::Stack, thickest_nm: f64, roughest: f64) -> Option<Self> {
        let ratio = stack.n2 / stack.n0;
        let near = ratio < PIGMENT_NEAR_AMBIENT && ratio * PIGMENT_NEAR_AMBIENT_BELOW > 1.0;
        let film = thickest_nm > 0.0 && stack.n1 != stack.n0;
        (near && film && roughest >= PIGMENT_NEAR_AMBIENT_ROUGH).then_some(PigmentNearAmbient { ratio })
    }
}

impl std::fmt::Display for PigmentNearAmbient {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "at {:.3} times the ambient index the bare interface reflects little, and the layered model misreads \
             the light a rough top's film sends straight back: what the top reflects is off the photon walk by up \
             to 0.3 of the light near equal indices, 0.04 at 1.05 times, 0.01 at {PIGMENT_NEAR_AMBIENT}, and 0.035 \
             at 1 / {PIGMENT_NEAR_AMBIENT_BELOW} (85°, roughness 1; within 0.02 under tops smoother than \
             {PIGMENT_NEAR_AMBIENT_ROUGH})",
            self.ratio
        )
    }
}

/// A known limit of the layered model, where the film's index is below the medium above it
/// (n1 < n0), what is left of it. Such a film totally reflects beyond its critical
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
/// Beyond the critical angle of n0 > n2 the rough top still lets 1 − s in (none under a
/// smooth top, where s = 1), along its path table's cosine there (`path::snell_cos`).
fn entering(layers: &Layers, cos: f64, s: [f64; 3]) -> [f64; 3] {
    let cos_t = super::path::snell_cos(layers.n0, layers.n2, cos);
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

/// The closed form of PHYSICS.md ("Layered transport, exactly") for one channel, written
/// once for every lobe that reads it: the model's (`diffuse`, `ambient_diffuse`,
/// `diffuse_f32`, `visible_colour`) and the smooth-top reference's (`exact::SmoothTop`);
/// `brdf.wgsl`'s `layered_diffuse` and `layered_ambient_diffuse` are the shader's forms.
///
/// - `closed_form_diffuse`: the diffuse lobe (n0/n2)² k_d a_i a_o / (π (1 − k_d K)), a_i and
///   a_o the light let in along each direction and carried through the pigment layer, the
///   base's bounces 1 / (1 − k_d K) with K what the top sends back down;
/// - `closed_form_reflectance`: the directional diffuse reflectance a k_d E / (1 − k_d K),
///   E the share of the base's light that escapes.
///
/// k_d is read within [0, 1] (`albedo.clamp`): above 1 the base would give back more than
/// reaches it and the bounce series can diverge. (The smooth-top reference read max(0)
/// alone until the two were one function; the random walk clamps as here.)
macro_rules! closed_form_diffuse {
    ($name:ident, $float:ty, $pi:expr) => {
        /// The closed form's diffuse lobe for one channel, (n0/n2)² k_d a_i a_o / (π (1 − k_d K))
        /// (the comment above `closed_form_diffuse!`).
        pub fn $name(radiance_factor: $float, albedo: $float, a_i: $float, a_o: $float, k: $float) -> $float {
            let kd = albedo.clamp(0.0, 1.0);
            radiance_factor * kd * a_i * a_o / ($pi * (1.0 - kd * k))
        }
    };
}
closed_form_diffuse!(closed_form_diffuse, f64, PI);
closed_form_diffuse!(closed_form_diffuse_f32, f32, std::f32::consts::PI);

/// The closed form's directional diffuse reflectance for one channel, a k_d E / (1 − k_d K)
/// (the comment above `closed_form_diffuse!`).
pub fn closed_form_reflectance(albedo: f64, a: f64, k: f64, e: f64) -> f64 {
    let kd = albedo.clamp(0.0, 1.0);
    a * kd * e / (1.0 - kd * k)
}

pub fn diffuse(layers: &Layers, cos_i: f64, cos_o: f64, f_i: [f64; 3], f_o: [f64; 3]) -> [f64; 3] {
    let (a_i, a_o) = (entering(layers, cos_i, f_i), entering(layers, cos_o, f_o));
    let eta2 = super::radiance_factor(layers.n0, layers.n2);
    [0, 1, 2].map(|c| closed_form_diffuse(eta2, layers.albedo[c], a_i[c], a_o[c], layers.k[c]))
}

pub fn ambient_diffuse(layers: &Layers, cos_o: f64, f_o: [f64; 3]) -> [f64; 3] {
    let a_o = entering(layers, cos_o, f_o);
    [0, 1, 2].map(|c| closed_form_reflectance(layers.albedo[c], a_o[c], layers.k[c], layers.e[c]))
}

/// The f32 diffuse lobe, as `brdf.wgsl`'s `layered_diffuse`: the two directions' paths
/// through the pigment layer attenuate in one exponential, exp(−τ (1/cos_eff,i + 1/cos_eff,o))
/// (= a(μi) a(μo) / ((1 − s_i)(1 − s_o)), three exponentials instead of six), with the path
/// deltas cos_eff − cos_t that the coupling table brings for each direction
/// (`lut::Lut::coupling_f32`).
pub fn diffuse_f32(layers: &Layers32, cos: [f32; 2], reflected: [[f32; 3]; 2], path_delta: [f32; 2]) -> [f32; 3] {
    let ([cos_i, cos_o], [f_i, f_o]) = (cos, reflected);
    let eta2 = super::radiance_factor_f32(layers.n0, layers.n2);
    // Snell's cos_t², below 0 beyond the critical angle of n0 > n2, where cos_t is taken as 0
    // (`path::snell_cos`).
    let (k_i, k_o) =
        (super::snell_cos_sq_f32(layers.n0, layers.n2, cos_i), super::snell_cos_sq_f32(layers.n0, layers.n2, cos_o));
    let absorbing = layers.optical_depth.iter().any(|t| *t > 0.0);
    let inverse_path = if absorbing {
        let cos_min = COS_MIN as f32;
        let (cos_t_i, cos_t_o) = (k_i.max(0.0).sqrt(), k_o.max(0.0).sqrt());
        1.0 / (cos_t_i + path_delta[0]).max(cos_min) + 1.0 / (cos_t_o + path_delta[1]).max(cos_min)
    } else {
        0.0
    };
    [0, 1, 2].map(|c| {
        let attenuation = if absorbing { (-layers.optical_depth[c].max(0.0) * inverse_path).exp() } else { 1.0 };
        let (a_i, a_o) = ((1.0 - f_i[c]) * attenuation, 1.0 - f_o[c]);
        closed_form_diffuse_f32(eta2, layers.albedo[c], a_i, a_o, layers.k[c])
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
    closed_form_reflectance(albedo, normal_transmittance, k, e)
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
