//! The film's reflectance as a Fourier series in the round-trip phase φ = 4π n1 d cos θ1 / λ,
//! which makes prefiltering exact and cheap.
//!
//! With a = r01, b = r12 and z = e^{iφ}, the Airy amplitude r = (a + b z) / (1 + a b z)
//! expands as r = a + Σ_{k≥1} K q^{k−1} z^k with q = −ab and K = b (1 − a²). Its intensity is
//!
//! ```text
//! R(φ) = c0 + 2 Re Σ_{m≥1} D q^{m−1} e^{imφ}
//! c0 = |a|² + |K|² / (1 − |q|²)            (exactly the incoherent sum R01 + T01² R12 / (1 − R01 R12))
//! D  = K ā + |K|² q / (1 − |q|²)
//! ```
//!
//! Averaging R over a box of phases of width Δ (a band of wavelengths, or a range of
//! thicknesses) multiplies harmonic m by sinc(mΔ/2). As Δ grows every harmonic dies and R
//! fades smoothly to the incoherent c0: no moiré at any thickness (PHYSICS.md, mistake 6),
//! the same idea as Belcour & Barla (2017) applied to the exact coefficients.

use super::complex::C64;
use super::film::{Stack, cos_in, film_cos_in};

/// Fourier coefficients of one polarisation's reflectance.
#[derive(Debug, Clone, Copy)]
pub struct Harmonics {
    pub c0: f64,
    pub d: C64,
    pub q: C64,
}

/// Both polarisations at one incidence, plus the real film cosine (None when the wave in the
/// film is evanescent: then R does not oscillate with thickness and the series is not used).
#[derive(Debug, Clone, Copy)]
pub struct FilmSeries {
    pub s: Harmonics,
    pub p: Harmonics,
    pub cos1: Option<f64>,
}

fn harmonics(a: C64, b: C64) -> Harmonics {
    let q = -(a * b);
    let k = b * (C64::ONE - a * a);
    // |q| = |ab| reaches 1 only where both interfaces reflect everything (grazing light and
    // total internal reflection at once); there `usable` is false and the series unused. The
    // floor only keeps the constructor finite.
    let denom = (1.0 - q.norm_sqr()).max(1e-300);
    let k2 = k.norm_sqr();
    Harmonics { c0: a.norm_sqr() + k2 / denom, d: k * a.conj() + q * (k2 / denom), q }
}

/// `|q|` at or above this makes the series converge too slowly; callers use Airy directly.
pub const MAX_Q: f64 = 0.995;

impl FilmSeries {
    pub fn new(stack: Stack, cos0: f64) -> Self {
        let cos0 = cos0.clamp(0.0, 1.0);
        let Stack { n0, n1, n2 } = stack;
        let (c0, c1, c2) = (C64::real(cos0), film_cos_in(n0, n1, cos0), cos_in(n0, n2, cos0));
        let r = |ni: f64, ci: C64, nj: f64, cj: C64| {
            let (rs, rp, _, _) = super::film::fresnel_amplitudes(ni, ci, nj, cj);
            (rs, rp)
        };
        let (a_s, a_p) = r(n0, c0, n1, c1);
        let (b_s, b_p) = r(n1, c1, n2, c2);
        let cos1 = if c1.im == 0.0 { Some(c1.re) } else { None };
        FilmSeries { s: harmonics(a_s, b_s), p: harmonics(a_p, b_p), cos1 }
    }

    /// True when the series is usable (real film angle, |q| < MAX_Q, not grazing).
    pub fn usable(&self) -> bool {
        self.cos1.is_some() && self.s.q.norm_sqr() < MAX_Q * MAX_Q && self.p.q.norm_sqr() < MAX_Q * MAX_Q
    }

    /// The round-trip phase φ = 4π n1 d cos θ1 / λ.
    pub fn phase(&self, n1: f64, thickness_nm: f64, wavelength_nm: f64) -> f64 {
        4.0 * std::f64::consts::PI * n1 * thickness_nm * self.cos1.unwrap_or(0.0) / wavelength_nm
    }

    /// Unpolarised reflectance at phase φ averaged over a box of phase width `box_width`.
    pub fn reflectance(&self, phase: f64, box_width: f64) -> f64 {
        0.5 * (series(&self.s, phase, box_width) + series(&self.p, phase, box_width))
    }

    /// The incoherent (fully averaged) reflectance.
    pub fn incoherent(&self) -> f64 {
        0.5 * (self.s.c0 + self.p.c0)
    }
}

fn sinc(x: f64) -> f64 {
    // sin x / x = 1 − x²/6 + …: below |x| = 1e-8 the x² term (< 2e-17) is under f64's
    // epsilon, so 1 is exact to the last bit and the division by a tiny x is avoided.
    if x.abs() < 1e-8 { 1.0 } else { x.sin() / x }
}

fn series(h: &Harmonics, phase: f64, box_width: f64) -> f64 {
    let z = C64::cis(phase);
    if box_width <= 1e-6 {
        // Closed form of the undamped series: Σ D q^{m−1} z^m = D z / (1 − q z). (A box
        // this narrow changes R by O(box²) < 1e-12.)
        return (h.c0 + 2.0 * (h.d * z / (C64::ONE - h.q * z)).re).clamp(0.0, 1.0);
    }
    let q_abs2 = h.q.norm_sqr();
    if q_abs2 < 1e-20 {
        // Only the first harmonic is left: D e^{iφ} sinc(Δ/2). (|q| < 1e-10: the harmonics
        // m ≥ 2 are at most 1e-10 of it, and the log form below would divide by q.)
        return (h.c0 + 2.0 * (h.d * z).re * sinc(0.5 * box_width)).clamp(0.0, 1.0);
    }
    // Exact box average of D z / (1 − q z) over φ ± Δ/2, since
    // d/dφ [ (i D / q) ln(1 − q e^{iφ}) ] = D e^{iφ} / (1 − q e^{iφ});
    // |q| < 1 keeps 1 − q e^{iφ} in the right half-plane, so the principal log is continuous.
    let upper = (C64::ONE - h.q * C64::cis(phase + 0.5 * box_width)).ln();
    let lower = (C64::ONE - h.q * C64::cis(phase - 0.5 * box_width)).ln();
    let mean = C64::new(0.0, 1.0) * h.d / h.q * (upper - lower) * (1.0 / box_width);
    (h.c0 + 2.0 * mean.re).clamp(0.0, 1.0)
}
