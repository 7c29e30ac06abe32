//! The f32 film kernels the real-time methods share, written as the WGSL twin will be:
//! complex numbers as `[f32; 2]`, no allocation, few branches on data (the series' three
//! regimes, and the exact film where the series is not used).
//!
//! `harmonics_f32` computes the same Fourier coefficients as `series::FilmSeries` and
//! `reflectance_f32` sums the prefiltered series (see `series.rs` for the derivation).

use super::film::snell_cos_sq_f32;
use super::series::MAX_Q;

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
    [(a[0] * b[0] + a[1] * b[1]) / d, (a[1] * b[0] - a[0] * b[1]) / d]
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
    if x >= 0.0 { [x.sqrt(), 0.0] } else { [0.0, (-x).sqrt()] }
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
    /// Im cos θ1: 0 while the film's wave travels, positive beyond the critical angle of a film
    /// less dense than the ambient (n1 < n0), where the wave in the film is evanescent: the
    /// round-trip phase is imaginary and the series in it does not exist. The exact film there
    /// climbs from the bare n0|n2 interface's reflectance at zero thickness towards 1 (total
    /// reflection) over a few decay lengths λ / (4π n1 κ): the further beyond the critical
    /// angle, the thinner the film that reflects everything.
    pub kappa1: f32,
    /// True where the series is not used and `band_reflectance_f32` reads the exact film: the
    /// f64 rule (`series::FilmSeries::usable`), an evanescent film or |q| ≥ `MAX_Q` (the
    /// film's own critical angle, where |q| → 1, and exactly at it q = 1).
    pub exact: bool,
    /// The Fresnel amplitudes [r01, r12] of s and of p (the exact film's, `airy_reflectance_f32`).
    pub amplitudes_s: [C32; 2],
    pub amplitudes_p: [C32; 2],
    /// The substrate's index is the ambient's (n2 = n0), and `film_is_ambient`: the film's is
    /// too (n1 = n0). Where both hold, or the first with a film of no thickness, there is no
    /// interface at all and everything passes at every angle (`passes_all`:
    /// `film::Stack::passes_all` on f32 indices). The Airy sum cannot say so in f32 near grazing: below cos0 ≈
    /// 3e-8, r01 and r12 round to ∓1 and a film of 0 nm read 0 / 0 (NaN) in every method
    /// (found by `brdf stress` once it drew n2 = n0 and the f32 films), and grazing light
    /// read 1.
    pub substrate_is_ambient: bool,
    pub film_is_ambient: bool,
}

impl Film32 {
    /// True where there is no interface at all at this thickness (see `substrate_is_ambient`).
    #[inline]
    pub fn passes_all(&self, thickness_nm: f32) -> bool {
        self.substrate_is_ambient && (self.film_is_ambient || thickness_nm == 0.0)
    }
}

/// Floor on 1 − |q|² in the harmonics' normalisation: |q| < 1 for any physical interface
/// pair, and 1e-6 keeps f32 finite as |q| → 1 at grazing. (`film.wgsl` reads it, and the
/// three thresholds below, from the generated prelude.)
pub const HARMONICS_DENOM_MIN: f32 = 1e-6;
/// Below this |x|, sinc(x) = 1 in f32 (the next term, x²/6, is under 2e-9).
pub const SINC_SMALL: f32 = 1e-4;
/// Below this box width (rad) the prefiltered series' log difference cancels in f32 and the
/// unfiltered closed form is used (its error there is O(Δ²) < 1e-6).
pub const BOX_NARROW_RAD: f32 = 1e-3;
/// |q|² below this: the series is a single term (no multiple reflections to sum).
pub const Q_NEGLIGIBLE: f32 = 1e-12;
/// |q|² at or above this: the series is not used (`Film32::exact`), `series::MAX_Q` squared.
pub const MAX_Q2_F32: f32 = (MAX_Q * MAX_Q) as f32;

#[inline]
fn harmonics(a: C32, b: C32) -> Harmonics32 {
    let q = scale(mul(a, b), -1.0);
    let k = mul(b, sub([1.0, 0.0], mul(a, a)));
    let k2 = norm_sqr(k);
    let inv = 1.0 / (1.0 - norm_sqr(q)).max(HARMONICS_DENOM_MIN);
    Harmonics32 { c0: norm_sqr(a) + k2 * inv, d: add(mul(k, conj(a)), scale(q, k2 * inv)), q }
}

/// Film coefficients for indices (n0, n1, n2) and the incidence cosine in the ambient medium.
#[inline]
pub fn film_f32(n0: f32, n1: f32, n2: f32, cos0: f32) -> Film32 {
    let cos0 = cos0.clamp(0.0, 1.0);
    let (substrate_is_ambient, film_is_ambient) = (n2 == n0, n1 == n0);
    if cos0 * cos0 < f32::MIN_POSITIVE {
        // Grazing light carries no flux and is all reflected, as `film::FilmAtAngle` takes it
        // (r01 was 0 / 0 where n1 = n0): the exact film with r01 = 1 and no second face,
        // unless there is no interface at all (`Film32::passes_all`). So is light whose cosine
        // squares to less than a normal f32 (below 1.1e-19, where the exact film reflects 1
        // to f32's precision): the cosines' squares and the amplitudes' denominators
        // underflowed there (NaN where n1 = n0).
        let none = Harmonics32 { c0: 1.0, d: [0.0; 2], q: [0.0; 2] };
        let reflects_all = [[1.0, 0.0], [0.0; 2]];
        let amplitudes_s = reflects_all;
        return Film32 {
            s: none,
            p: none,
            cos1: 0.0,
            kappa1: 0.0,
            exact: true,
            amplitudes_s,
            amplitudes_p: amplitudes_s,
            substrate_is_ambient,
            film_is_ambient,
        };
    }
    let c0: C32 = [cos0, 0.0];
    // Where the film's cancels to exactly 0 (light at its critical angle), the size of the
    // sum's rounding, as `film::film_cos_in` (never 0 where n1 = n0: cos0² is normal here).
    let x1 = snell_cos_sq_f32(n0, n1, cos0);
    let eta1 = n0 / n1;
    let c1 = sqrt_real(if x1 == 0.0 { f32::EPSILON * (1.0 - eta1 * eta1).abs() } else { x1 });
    let c2 = sqrt_real(snell_cos_sq_f32(n0, n2, cos0));
    let r = |ni: f32, ci: C32, nj: f32, cj: C32| {
        let (a, b) = (scale(ci, ni), scale(cj, nj));
        let rs = div(sub(a, b), add(a, b));
        let (c, d) = (scale(ci, nj), scale(cj, ni));
        let rp = div(sub(c, d), add(c, d));
        (rs, rp)
    };
    let (a_s, a_p) = r(n0, c0, n1, c1);
    let (b_s, b_p) = r(n1, c1, n2, c2);
    let (s, p) = (harmonics(a_s, b_s), harmonics(a_p, b_p));
    Film32 {
        s,
        p,
        cos1: if c1[1] == 0.0 { c1[0] } else { 0.0 },
        kappa1: c1[1],
        exact: !(c1[1] == 0.0 && norm_sqr(s.q) < MAX_Q2_F32 && norm_sqr(p.q) < MAX_Q2_F32),
        amplitudes_s: [a_s, b_s],
        amplitudes_p: [a_p, b_p],
        substrate_is_ambient,
        film_is_ambient,
    }
}

#[inline]
fn sinc(x: f32) -> f32 {
    if x.abs() < SINC_SMALL { 1.0 } else { x.sin() / x }
}

#[inline]
fn ln(a: C32) -> C32 {
    [0.5 * norm_sqr(a).ln(), a[1].atan2(a[0])]
}

/// Box-prefiltered series in closed form (see `series.rs`): the mean of D z / (1 − q z)
/// over φ ± Δ/2 is (i D / q) [ln(1 − q z₊) − ln(1 − q z₋)] / Δ. Below BOX_NARROW_RAD the
/// unfiltered closed form is used.
#[inline]
fn series(h: &Harmonics32, phase: f32, box_width: f32) -> f32 {
    let z = [phase.cos(), phase.sin()];
    let one: C32 = [1.0, 0.0];
    let mean = if box_width < BOX_NARROW_RAD {
        div(mul(h.d, z), sub(one, mul(h.q, z)))
    } else if norm_sqr(h.q) < Q_NEGLIGIBLE {
        scale(mul(h.d, z), sinc(0.5 * box_width))
    } else {
        let half = 0.5 * box_width;
        let upper = ln(sub(one, mul(h.q, [(phase + half).cos(), (phase + half).sin()])));
        let lower = ln(sub(one, mul(h.q, [(phase - half).cos(), (phase - half).sin()])));
        scale(mul([0.0, 1.0], div(mul(h.d, sub(upper, lower)), h.q)), 1.0 / box_width)
    };
    (h.c0 + 2.0 * mean[0]).clamp(0.0, 1.0)
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

/// The exact coherent film at one wavelength (Airy, as `film::airy`'s reflectance), unpolarised:
/// r = (r01 + r12 e) / (1 + r01 r12 e) per polarisation, e = exp(2iβ), β = 2π n1 d cos θ1 / λ,
/// which for an evanescent film (cos θ1 = i κ) is the real decay exp(−4π n1 d κ / λ).
/// 1 + r01 r12 e ≠ 0: it would need |r01| = |r12| = |e| = 1, a travelling wave with both faces
/// reflecting totally, which only cos θ1 = 0 gives, and `film_f32` keeps cos θ1 off 0 (or,
/// for grazing light, holds no second face); in f32 it also vanishes where r01 and r12 round
/// to ∓1, which `Film32::passes_all` takes first.
#[inline]
pub fn airy_reflectance_f32(film: &Film32, n1: f32, thickness_nm: f32, wavelength_nm: f32) -> f32 {
    if film.passes_all(thickness_nm) {
        return 0.0;
    }
    let k = 4.0 * std::f32::consts::PI * n1 * thickness_nm / wavelength_nm;
    let e = scale([(k * film.cos1).cos(), (k * film.cos1).sin()], (-k * film.kappa1).exp());
    let r = |[a, b]: [C32; 2]| norm_sqr(add(a, mul(b, e))) / norm_sqr(add([1.0, 0.0], mul(mul(a, b), e)));
    (0.5 * (r(film.amplitudes_s) + r(film.amplitudes_p))).clamp(0.0, 1.0)
}

/// The film's reflectance over a band of `band_nm` around `wavelength_nm`: the prefiltered
/// series, or where it is not used (`Film32::exact`) the exact film at the band's centre, as
/// the twin `methods::band_reflectance_f64` does.
#[inline]
pub fn band_reflectance_f32(film: &Film32, n1: f32, thickness_nm: f32, wavelength_nm: f32, band_nm: f32) -> f32 {
    if film.exact {
        return airy_reflectance_f32(film, n1, thickness_nm, wavelength_nm);
    }
    let phase = phase_f32(film, n1, thickness_nm, wavelength_nm);
    reflectance_f32(film, phase, phase * band_nm / wavelength_nm)
}
