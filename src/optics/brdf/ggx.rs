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

/// One stratified sample of the half vector for a view `wo` (normal +z): `h` drawn with pdf
/// D(h) cos θh, and the mirror direction `wi` it gives (only samples with wo·h > 0 and
/// wi above the horizon are kept). `pdf_wi` = D cos θh / (4 wo·h) turns an integrand over wi
/// into a sum: ∫ g(wi) dωi ≈ Σ g(wi) / pdf_wi / n².
pub struct HalfVector {
    pub h: [f64; 3],
    pub cos_h: f64,
    pub sin_h: f64,
    pub wo_h: f64,
    pub wi: [f64; 3],
    pub pdf_wi: f64,
}

/// The n × n stratified half vectors (midpoints of the strata; tan² θh = α² u / (1 − u)),
/// exact in distribution for any α, however peaked: the furnace and the lobe tables
/// integrate over them.
pub fn stratified_half_vectors(wo: [f64; 3], alpha: f64, n: usize) -> impl Iterator<Item = HalfVector> {
    (0..n * n).filter_map(move |k| {
        let (a, b) = (k / n, k % n);
        let (u1, u2) = ((a as f64 + 0.5) / n as f64, (b as f64 + 0.5) / n as f64);
        let cos_h = (1.0 / (1.0 + alpha * alpha * u1 / (1.0 - u1))).sqrt();
        let sin_h = (1.0 - cos_h * cos_h).max(0.0).sqrt();
        let phi = 2.0 * PI * u2;
        let h = [sin_h * phi.cos(), sin_h * phi.sin(), cos_h];
        let wo_h = wo[0] * h[0] + wo[1] * h[1] + wo[2] * h[2];
        if wo_h <= 0.0 {
            return None;
        }
        let wi = [0, 1, 2].map(|i| 2.0 * wo_h * h[i] - wo[i]);
        if wi[2] <= 0.0 {
            return None;
        }
        let pdf_wi = ggx_d_sin(cos_h, sin_h * sin_h, alpha) * cos_h / (4.0 * wo_h);
        Some(HalfVector { h, cos_h, sin_h, wo_h, wi, pdf_wi })
    })
}
