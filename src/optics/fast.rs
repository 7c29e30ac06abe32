//! The f32 film kernels the real-time methods share, written as the WGSL twin will be:
//! complex numbers as `[f32; 2]`, no allocation, no branches on data beyond clamps.
//!
//! `harmonics_f32` computes the same Fourier coefficients as `series::FilmSeries` and
//! `reflectance_f32` sums the prefiltered series (see `series.rs` for the derivation).

pub type C32 = [f32; 2];

#[inline]
fn add(a: C32, b: C32) -> C32 {
    [a[0] + b[0], a[1] + b[1]]
}
#[inline]
fn sub(a: C32, b: C32) -> C32 {
    [a[0] - b[0], a[1] - b[1]]
}
#[inline]
fn mul(a: C32, b: C32) -> C32 {
    [a[0] * b[0] - a[1] * b[1], a[0] * b[1] + a[1] * b[0]]
}
#[inline]
fn scale(a: C32, k: f32) -> C32 {
    [a[0] * k, a[1] * k]
}
#[inline]
fn div(a: C32, b: C32) -> C32 {
    let d = b[0] * b[0] + b[1] * b[1];
    [
        (a[0] * b[0] + a[1] * b[1]) / d,
        (a[1] * b[0] - a[0] * b[1]) / d,
    ]
}
#[inline]
fn conj(a: C32) -> C32 {
    [a[0], -a[1]]
}
#[inline]
fn norm_sqr(a: C32) -> f32 {
    a[0] * a[0] + a[1] * a[1]
}
/// sqrt(x) for real x, as a complex number in the upper half-plane.
#[inline]
fn sqrt_real(x: f32) -> C32 {
    if x >= 0.0 {
        [x.sqrt(), 0.0]
    } else {
        [0.0, (-x).sqrt()]
    }
}

/// Fourier coefficients (c0, D, q) of one polarisation, f32.
#[derive(Debug, Clone, Copy)]
pub struct Harmonics32 {
    pub c0: f32,
    pub d: C32,
    pub q: C32,
}

/// Both polarisations and the real film cosine (0 when the film wave is evanescent).
#[derive(Debug, Clone, Copy)]
pub struct Film32 {
    pub s: Harmonics32,
    pub p: Harmonics32,
    pub cos1: f32,
}

#[inline]
fn harmonics(a: C32, b: C32) -> Harmonics32 {
    let q = scale(mul(a, b), -1.0);
    let k = mul(b, sub([1.0, 0.0], mul(a, a)));
    let k2 = norm_sqr(k);
    let inv = 1.0 / (1.0 - norm_sqr(q)).max(1e-6);
    Harmonics32 {
        c0: norm_sqr(a) + k2 * inv,
        d: add(mul(k, conj(a)), scale(q, k2 * inv)),
        q,
    }
}

/// Film coefficients for indices (n0, n1, n2) and the incidence cosine in the ambient medium.
#[inline]
pub fn film_f32(n0: f32, n1: f32, n2: f32, cos0: f32) -> Film32 {
    let cos0 = cos0.clamp(0.0, 1.0);
    let sin2 = 1.0 - cos0 * cos0;
    let c0: C32 = [cos0, 0.0];
    let c1 = sqrt_real(1.0 - (n0 / n1) * (n0 / n1) * sin2);
    let c2 = sqrt_real(1.0 - (n0 / n2) * (n0 / n2) * sin2);
    let r = |ni: f32, ci: C32, nj: f32, cj: C32| {
        let (a, b) = (scale(ci, ni), scale(cj, nj));
        let rs = div(sub(a, b), add(a, b));
        let (c, d) = (scale(ci, nj), scale(cj, ni));
        let rp = div(sub(c, d), add(c, d));
        (rs, rp)
    };
    let (a_s, a_p) = r(n0, c0, n1, c1);
    let (b_s, b_p) = r(n1, c1, n2, c2);
    Film32 {
        s: harmonics(a_s, b_s),
        p: harmonics(a_p, b_p),
        cos1: if c1[1] == 0.0 { c1[0] } else { 0.0 },
    }
}

#[inline]
fn sinc(x: f32) -> f32 {
    if x.abs() < 1e-4 { 1.0 } else { x.sin() / x }
}

/// Harmonics summed in the box-prefiltered series; enough for |q| ≤ 0.6 to 1e-4.
pub const HARMONICS: u32 = 12;

#[inline]
fn series(h: &Harmonics32, phase: f32, box_width: f32) -> f32 {
    let mut total = h.c0;
    let mut coeff = h.d;
    let step = [phase.cos(), phase.sin()];
    let mut z = step;
    for m in 1..=HARMONICS {
        total += 2.0 * mul(coeff, z)[0] * sinc(0.5 * m as f32 * box_width);
        coeff = mul(coeff, h.q);
        z = mul(z, step);
    }
    total.clamp(0.0, 1.0)
}

/// Unpolarised reflectance at phase φ, averaged over a box of phase width `box_width`.
#[inline]
pub fn reflectance_f32(film: &Film32, phase: f32, box_width: f32) -> f32 {
    0.5 * (series(&film.s, phase, box_width) + series(&film.p, phase, box_width))
}

/// The round-trip phase 4π n1 d cos θ1 / λ.
#[inline]
pub fn phase_f32(film: &Film32, n1: f32, thickness_nm: f32, wavelength_nm: f32) -> f32 {
    4.0 * std::f32::consts::PI * n1 * thickness_nm * film.cos1 / wavelength_nm
}
