//! Thin-film reflectance and transmittance by the Airy summation with complex amplitudes
//! (PHYSICS.md, "Thin-film reflectance, exactly"), s and p polarisation, and the thick-film
//! incoherent limit.
//!
//! Why complex amplitudes throughout: the thesis (eqs. 4.6–4.9) tracks phase as a magnitude
//! with 0/π jumps, which is only right while the Fresnel coefficients are real. Past total
//! internal reflection the refracted cosine is imaginary and so are the coefficients; the
//! Airy formula with complex numbers is right everywhere. Snell's law is n0 sin θ0 =
//! n_j sin θ_j (the thesis' eq. 4.15 inverts the ratio), and R_s, R_p are averaged as
//! intensities, never as amplitudes.

use super::complex::C64;

/// Refractive indices of the three media: ambient (n0), film (n1), substrate (n2, the
/// pigment layer). Real: the layers are lossless dielectrics.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stack {
    pub n0: f64,
    pub n1: f64,
    pub n2: f64,
}

impl Stack {
    /// The thesis' defaults (Table 5.2): air, film 1.55, pigment 2.00.
    pub const THESIS: Stack = Stack {
        n0: crate::material::thesis::AMBIENT_IOR,
        n1: crate::material::thesis::FILM_IOR,
        n2: crate::material::thesis::PIGMENT_IOR,
    };
}

/// Reflectance and transmittance per polarisation and unpolarised (the mean of s and p).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct FilmRT {
    pub rs: f64,
    pub rp: f64,
    pub r: f64,
    pub ts: f64,
    pub tp: f64,
    pub t: f64,
}

impl FilmRT {
    fn from_sp(rs: f64, rp: f64, ts: f64, tp: f64) -> Self {
        FilmRT { rs, rp, r: 0.5 * (rs + rp), ts, tp, t: 0.5 * (ts + tp) }
    }
}

/// Complex cosine of the angle in a medium of index `n` for incidence `cos0` in `n0`:
/// sqrt(1 − (n0/n)² sin²θ0), imaginary (evanescent) beyond total internal reflection.
pub fn cos_in(n0: f64, n: f64, cos0: f64) -> C64 {
    // Written as (1 − η²) + η² cos²θ0 rather than 1 − η² sin²θ0: at grazing incidence with
    // η = 1 the latter cancels to 0 and the film equations divide 0 by 0.
    let eta2 = (n0 / n) * (n0 / n);
    C64::real((1.0 - eta2) + eta2 * cos0 * cos0).sqrt_upper()
}

/// Fresnel amplitude coefficients (r_s, r_p, t_s, t_p) from medium i into medium j.
fn fresnel_amplitudes(ni: f64, ci: C64, nj: f64, cj: C64) -> (C64, C64, C64, C64) {
    let s_den = ci * ni + cj * nj;
    let p_den = ci * nj + cj * ni;
    let rs = (ci * ni - cj * nj) / s_den;
    let rp = (ci * nj - cj * ni) / p_den;
    let ts = (ci * (2.0 * ni)) / s_den;
    let tp = (ci * (2.0 * ni)) / p_den;
    (rs, rp, ts, tp)
}

/// Fresnel intensity reflectance (R_s, R_p) of a single interface n0 | n.
pub fn fresnel(n0: f64, n: f64, cos0: f64) -> (f64, f64) {
    let c0 = C64::real(cos0);
    let c1 = cos_in(n0, n, cos0);
    let (rs, rp, _, _) = fresnel_amplitudes(n0, c0, n, c1);
    (rs.norm_sqr(), rp.norm_sqr())
}

/// The exact coherent film at one vacuum wavelength: `cos0` is the cosine of the incidence
/// angle in the ambient medium (clamped to [0, 1]).
pub fn airy(stack: Stack, thickness_nm: f64, wavelength_nm: f64, cos0: f64) -> FilmRT {
    let cos0 = cos0.clamp(0.0, 1.0);
    let Stack { n0, n1, n2 } = stack;
    let c0 = C64::real(cos0);
    let c1 = cos_in(n0, n1, cos0);
    let c2 = cos_in(n0, n2, cos0);
    let (r01s, r01p, t01s, t01p) = fresnel_amplitudes(n0, c0, n1, c1);
    let (r12s, r12p, t12s, t12p) = fresnel_amplitudes(n1, c1, n2, c2);

    // β = 2π n1 d cos θ1 / λ; complex when the film is evanescent (frustrated TIR).
    let beta = c1 * (2.0 * std::f64::consts::PI * n1 * thickness_nm / wavelength_nm);
    let e1 = C64::exp_i(beta);
    let e2 = C64::exp_i(beta * 2.0);
    let airy_r = |r01: C64, r12: C64| (r01 + r12 * e2) / (C64::ONE + r01 * r12 * e2);
    let airy_t = |r01: C64, r12: C64, t01: C64, t12: C64| (t01 * t12 * e1) / (C64::ONE + r01 * r12 * e2);

    let rs = airy_r(r01s, r12s).norm_sqr();
    let rp = airy_r(r01p, r12p).norm_sqr();
    // Power transmittance: the ratio of normal energy flux, Re(n cos) for s and
    // Re(n conj(cos)) for p (PHYSICS.md); zero when the substrate wave is evanescent.
    let flux_s = (c2 * n2).re / (c0 * n0).re;
    let flux_p = (c2.conj() * n2).re / (c0.conj() * n0).re;
    let (ts, tp) = if cos0 > 0.0 {
        (flux_s * airy_t(r01s, r12s, t01s, t12s).norm_sqr(), flux_p * airy_t(r01p, r12p, t01p, t12p).norm_sqr())
    } else {
        // Exactly grazing incidence carries no flux: everything is reflected.
        (0.0, 0.0)
    };
    let (rs, rp) = if cos0 > 0.0 { (rs, rp) } else { (1.0, 1.0) };
    if ![rs, rp, ts, tp].iter().all(|v| v.is_finite()) {
        // Only |r01 r12| = 1 makes the Airy denominator vanish: the grazing limit, R = 1.
        return FilmRT::from_sp(1.0, 1.0, 0.0, 0.0);
    }
    FilmRT::from_sp(rs.clamp(0.0, 1.0), rp.clamp(0.0, 1.0), ts.clamp(0.0, 1.0), tp.clamp(0.0, 1.0))
}

/// The incoherent (thick-film) limit: intensities add, phases average out.
/// R = R01 + T01² R12 / (1 − R01 R12), per polarisation (PHYSICS.md, mistake 6).
pub fn incoherent(stack: Stack, cos0: f64) -> FilmRT {
    let cos0 = cos0.clamp(0.0, 1.0);
    if cos0 <= 0.0 {
        return FilmRT::from_sp(1.0, 1.0, 0.0, 0.0);
    }
    let Stack { n0, n1, n2 } = stack;
    let (r01s, r01p) = fresnel(n0, n1, cos0);
    let c1 = cos_in(n0, n1, cos0);
    // Internal incidence on the 1|2 interface: cos θ1 real unless TIR at 0|1 (then R01 = 1).
    let (r12s, r12p) = if c1.im == 0.0 && c1.re > 0.0 { fresnel(n1, n2, c1.re) } else { (1.0, 1.0) };
    let sum = |r01: f64, r12: f64| {
        let t01 = 1.0 - r01;
        let denom = 1.0 - r01 * r12;
        if denom <= 1e-300 { 1.0 } else { (r01 + t01 * t01 * r12 / denom).clamp(0.0, 1.0) }
    };
    let (rs, rp) = (sum(r01s, r12s), sum(r01p, r12p));
    FilmRT::from_sp(rs, rp, 1.0 - rs, 1.0 - rp)
}
