//! The `layered` model: the real-time form of the stack's transport (PHYSICS.md, "Layered
//! transport, exactly"), with the rough top coupled to it by energy (`energy`).
//!
//! ```text
//! s(μ)   = E₁(μ, r) ⟨F⟩                                  what the rough lobe reflects
//! a(μ)   = (1 − s(μ)) exp(−τ / cos_t(μ))                light that enters and reaches the base
//! f_diff = (n0/n2)² k_d a(μi) a(μo) / (π (1 − k_d K))
//! ambient diffuse (sky along the normal) = a(μo) k_d E / (1 − k_d K)
//! ```
//!
//! with ⟨F⟩ the film read at the lobe's microfacet angles (`energy`; `Model::coupling`
//! passes s in).
//!
//! K and E (per channel, per material, per roughness) come with the layers
//! (`Layers::of_stack`: the film seen from below, `exact::SmoothTop::bounce_table`). At r = 0
//! this is the smooth-top closed form exactly, up to the film colour method. f64, f32 (the
//! shader's twin) and the ambient term read one formula.

use std::f64::consts::PI;

use super::{Layers, Layers32, cos_transmitted};

/// a(μ) per channel: the light from a direction at cosine `cos` that reaches the base,
/// `s` what the rough lobe reflects there.
fn entering(layers: &Layers, cos: f64, s: [f64; 3]) -> [f64; 3] {
    let Some(cos_t) = cos_transmitted(layers.n0, layers.n2, cos) else {
        return [0.0; 3];
    };
    [0, 1, 2].map(|c| (1.0 - s[c]) * (-layers.optical_depth[c].max(0.0) / cos_t.max(super::COS_MIN)).exp())
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

fn entering_f32(layers: &Layers32, cos: f32, s: [f32; 3]) -> [f32; 3] {
    let eta2 = (layers.n0 / layers.n2) * (layers.n0 / layers.n2);
    let k = (1.0 - eta2) + eta2 * cos * cos;
    if k <= 0.0 {
        return [0.0; 3];
    }
    let cos_t = k.sqrt().max(super::COS_MIN as f32);
    [0, 1, 2].map(|c| (1.0 - s[c]) * (-layers.optical_depth[c].max(0.0) / cos_t).exp())
}

/// The f32 diffuse lobe, as `brdf.wgsl`'s `layered_diffuse`.
pub fn diffuse_f32(layers: &Layers32, cos_i: f32, cos_o: f32, f_i: [f32; 3], f_o: [f32; 3]) -> [f32; 3] {
    let (a_i, a_o) = (entering_f32(layers, cos_i, f_i), entering_f32(layers, cos_o, f_o));
    let eta2 = (layers.n0 / layers.n2) * (layers.n0 / layers.n2);
    [0, 1, 2].map(|c| {
        let kd = layers.albedo[c].clamp(0.0, 1.0);
        eta2 * kd * a_i[c] * a_o[c] / (std::f32::consts::PI * (1.0 - kd * layers.k[c]))
    })
}
