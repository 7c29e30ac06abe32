//! A minimal complex number for the thin-film amplitudes: the Airy sum needs complex Fresnel
//! coefficients past total internal reflection (PHYSICS.md, thesis mistake 2), and a small
//! explicit type keeps the f64 reference readable next to its WGSL twin.

use std::ops::{Add, Div, Mul, Neg, Sub};

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct C64 {
    pub re: f64,
    pub im: f64,
}

impl C64 {
    pub const ZERO: C64 = C64 { re: 0.0, im: 0.0 };
    pub const ONE: C64 = C64 { re: 1.0, im: 0.0 };

    pub const fn new(re: f64, im: f64) -> Self {
        C64 { re, im }
    }

    pub const fn real(re: f64) -> Self {
        C64 { re, im: 0.0 }
    }

    pub fn conj(self) -> Self {
        C64::new(self.re, -self.im)
    }

    pub fn norm_sqr(self) -> f64 {
        self.re * self.re + self.im * self.im
    }

    /// e^{i φ} for real φ.
    pub fn cis(phase: f64) -> Self {
        C64::new(phase.cos(), phase.sin())
    }

    /// e^{i z} for complex z: e^{-Im z} (cos Re z + i sin Re z).
    pub fn exp_i(z: C64) -> Self {
        C64::cis(z.re) * (-z.im).exp()
    }

    /// Principal natural logarithm: ln|z| + i arg z.
    pub fn ln(self) -> Self {
        C64::new(0.5 * self.norm_sqr().ln(), self.im.atan2(self.re))
    }

    /// The square root with a non-negative imaginary part (for a real negative argument,
    /// +i sqrt|x|): the branch that makes an evanescent wave decay into the medium.
    pub fn sqrt_upper(self) -> Self {
        let r = self.norm_sqr().sqrt();
        let re = ((r + self.re) * 0.5).max(0.0).sqrt();
        let im = ((r - self.re) * 0.5).max(0.0).sqrt();
        // sign(im of result) follows sign(self.im); then flip into the upper half-plane.
        let root = if self.im < 0.0 { C64::new(re, -im) } else { C64::new(re, im) };
        if root.im < 0.0 { -root } else { root }
    }
}

impl Add for C64 {
    type Output = C64;
    fn add(self, o: C64) -> C64 {
        C64::new(self.re + o.re, self.im + o.im)
    }
}

impl Sub for C64 {
    type Output = C64;
    fn sub(self, o: C64) -> C64 {
        C64::new(self.re - o.re, self.im - o.im)
    }
}

impl Mul for C64 {
    type Output = C64;
    fn mul(self, o: C64) -> C64 {
        C64::new(self.re * o.re - self.im * o.im, self.re * o.im + self.im * o.re)
    }
}

impl Mul<f64> for C64 {
    type Output = C64;
    fn mul(self, k: f64) -> C64 {
        C64::new(self.re * k, self.im * k)
    }
}

impl Div for C64 {
    type Output = C64;
    fn div(self, o: C64) -> C64 {
        let d = o.norm_sqr();
        C64::new((self.re * o.re + self.im * o.im) / d, (self.im * o.re - self.re * o.im) / d)
    }
}

impl Neg for C64 {
    type Output = C64;
    fn neg(self) -> C64 {
        C64::new(-self.re, -self.im)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sqrt_upper_squares_back_and_stays_in_the_upper_half_plane() {
        for &(re, im) in &[(4.0, 0.0), (-4.0, 0.0), (-4.0, -0.0), (3.0, -4.0), (-3.0, 4.0), (0.0, 0.0)] {
            let z = C64::new(re, im);
            let s = z.sqrt_upper();
            assert!(s.im >= 0.0, "{z:?} -> {s:?}");
            let back = s * s;
            assert!((back.re - re).abs() < 1e-12 && (back.im - im).abs() < 1e-12, "{z:?}");
        }
        assert_eq!(C64::new(-4.0, -0.0).sqrt_upper(), C64::new(0.0, 2.0));
    }
}
