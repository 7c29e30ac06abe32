//! The rough top interface every model shares: the GGX (Trowbridge–Reitz) microfacet
//! distribution and Smith's height-correlated masking-shadowing (Heitz 2014), in f64 and in
//! the f32 form the shader mirrors. A model changes what happens under the top interface,
//! not the interface itself, so these live apart from any one model.

use std::f64::consts::PI;

/// GGX normal distribution D(h) for cos θ_h and α.
pub fn ggx_d(cos_h: f64, alpha: f64) -> f64 {
    ggx_d_sin(cos_h, (1.0 - cos_h * cos_h).max(0.0), alpha)
}

/// GGX D from cos² and sin² of θ_h computed separately: the usual cos²(α² − 1) + 1 cancels
/// catastrophically near the peak when α is small (1 − 1e-6 in f32 keeps one digit).
pub fn ggx_d_sin(cos_h: f64, sin2_h: f64, alpha: f64) -> f64 {
    let a2 = alpha * alpha;
    let t = sin2_h + cos_h * cos_h * a2;
    a2 / (PI * t * t)
}

/// Smith Λ for GGX (Heitz 2014, eq. 72).
pub fn smith_lambda(cos: f64, alpha: f64) -> f64 {
    let c2 = cos * cos;
    let tan2 = (1.0 - c2).max(0.0) / c2;
    0.5 * ((1.0 + alpha * alpha * tan2).sqrt() - 1.0)
}

/// Height-correlated masking-shadowing G2 = 1 / (1 + Λ(wi) + Λ(wo)) (Heitz 2014, eq. 99).
pub fn smith_g2(cos_i: f64, cos_o: f64, alpha: f64) -> f64 {
    1.0 / (1.0 + smith_lambda(cos_i, alpha) + smith_lambda(cos_o, alpha))
}

/// The specular lobe's scalar factor D G2 / (4 cos_i cos_o) in f32, as `brdf.wgsl`'s
/// `specular_scale`: `sin2_h` from the cross product n × h, `a2` = α².
pub fn specular_scale_f32(cos_h: f32, sin2_h: f32, cos_i: f32, cos_o: f32, a2: f32) -> f32 {
    let t = sin2_h + cos_h * cos_h * a2;
    let d = a2 / (std::f32::consts::PI * t * t);
    let lambda = |c: f32| 0.5 * ((1.0 + a2 * (1.0 - c * c).max(0.0) / (c * c)).sqrt() - 1.0);
    let g2 = 1.0 / (1.0 + lambda(cos_i) + lambda(cos_o));
    d * g2 / (4.0 * cos_i * cos_o)
}
