//! The `thesis` model: the diffuse lobe of the thesis' eq. 4.21 (Weidlich & Wilkie 2007,
//! single scatter), with the refracted cosine from Snell's law into n2 (the thesis mixes θ2
//! and θ3, PHYSICS.md mistake 5):
//!
//! ```text
//! f_diff = (1 − F(n·wi)) (1 − F(n·wo)) exp(−τ (1/cos_t(wi) + 1/cos_t(wo))) k_d / π
//! ```
//!
//! PHYSICS.md keeps it only for comparison: it lacks the radiance factor (n0/n2)² and all
//! light the top interface sends back down. f64 here, f32 below (the shader's twin), and the
//! ambient term's diffuse part, so the three stay one formula read three ways.

use std::f64::consts::PI;

use super::{COS_MIN, Layers, Layers32, cos_transmitted, snell_cos_sq, snell_cos_sq_f32};

/// The diffuse lobe at cosines `cos_i`, `cos_o` (already floored at COS_MIN) with the film's
/// reflectance `f_i`, `f_o` at those cosines (clamped to [0, 1]).
pub fn diffuse(layers: &Layers, cos_i: f64, cos_o: f64, f_i: [f64; 3], f_o: [f64; 3]) -> [f64; 3] {
    let (Some(ti), Some(to)) =
        (cos_transmitted(layers.n0, layers.n2, cos_i), cos_transmitted(layers.n0, layers.n2, cos_o))
    else {
        return [0.0; 3];
    };
    let path = 1.0 / ti.max(COS_MIN) + 1.0 / to.max(COS_MIN);
    [0, 1, 2].map(|c| {
        let attenuation = (-layers.optical_depth[c].max(0.0) * path).exp();
        (1.0 - f_i[c]) * (1.0 - f_o[c]) * attenuation * layers.albedo[c].max(0.0) / PI
    })
}

/// The f32 diffuse lobe, as `brdf.wgsl`'s `thesis_diffuse`.
pub fn diffuse_f32(layers: &Layers32, cos_i: f32, cos_o: f32, f_i: [f32; 3], f_o: [f32; 3]) -> [f32; 3] {
    let cos_min = COS_MIN as f32;
    let (ki, ko) = (snell_cos_sq_f32(layers.n0, layers.n2, cos_i), snell_cos_sq_f32(layers.n0, layers.n2, cos_o));
    if !(ki > 0.0 && ko > 0.0) {
        return [0.0; 3];
    }
    let path = 1.0 / ki.sqrt().max(cos_min) + 1.0 / ko.sqrt().max(cos_min);
    [0, 1, 2].map(|c| {
        (1.0 - f_i[c]) * (1.0 - f_o[c]) * (-layers.optical_depth[c].max(0.0) * path).exp() * layers.albedo[c].max(0.0)
            / std::f32::consts::PI
    })
}

/// The ambient term's diffuse part, as `brdf.wgsl`'s `thesis_ambient_diffuse`: the sky seen
/// along the normal enters the pigment layer through the film (1 − F at the view cosine)
/// and is attenuated along the view path plus one layer thickness. Multiplies the sky
/// radiance along the normal.
pub fn ambient_diffuse(layers: &Layers, cos_o: f64, f_o: [f64; 3]) -> [f64; 3] {
    let k = snell_cos_sq(layers.n0, layers.n2, cos_o);
    let path = 1.0 / k.max(0.0).sqrt().max(COS_MIN) + 1.0;
    // k_d clamped at 0 as the direct lobe's (`diffuse`): a negative albedo (the library's
    // callers can pass one) gave a negative ambient term beside a zero direct one (a review).
    [0, 1, 2].map(|c| (1.0 - f_o[c]) * layers.albedo[c].max(0.0) * (-layers.optical_depth[c].max(0.0) * path).exp())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A negative albedo (possible through the library's API, not from a colour map) is read
    /// as 0 by the ambient term as by the direct lobe: the ambient term went negative beside
    /// a zero direct one (a review). Control: a positive albedo lights both.
    #[test]
    fn the_ambient_term_reads_the_albedo_as_the_direct_lobe_does() {
        let stack = crate::optics::film::Stack { n0: 1.0, n1: 1.55, n2: 2.0 };
        let layers = |albedo| Layers::of_stack(stack, 300.0, 0.3, [0.2; 3], albedo);
        let negative = layers([-0.5, 0.2, 0.0]);
        let (direct, ambient) =
            (diffuse(&negative, 0.8, 0.7, [0.05; 3], [0.05; 3]), ambient_diffuse(&negative, 0.7, [0.05; 3]));
        assert_eq!((direct[0], ambient[0]), (0.0, 0.0), "{direct:?} {ambient:?}");
        assert!(direct[1] > 0.0 && ambient[1] > 0.0, "the control: {direct:?} {ambient:?}");
    }
}
