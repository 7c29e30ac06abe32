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

    /// True where there is no interface at all: the substrate has the ambient's index and
    /// the film either has it too or no thickness. Everything passes then, at every angle,
    /// grazing included, where the Airy sum is 0 / 0. The one rule of the f64 films
    /// (`FilmAtAngle::new`; `incoherent`, a film of some thickness). Its f32 and WGSL twins
    /// (`fast::Film32::passes_all`, `film.wgsl`'s `film_passes_all`) apply it to their own
    /// f32 indices, which they must: indices that differ in f64 can round equal in f32
    /// (1 + 1e-9), and an f32 Airy sum of equal indices reads NaN near grazing.
    pub fn passes_all(&self, thickness_nm: f64) -> bool {
        self.n0 == self.n2 && (self.n1 == self.n0 || thickness_nm == 0.0)
    }
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

/// Snell's cos² of the direction refracted into a medium of index `n` from a direction at
/// cosine `cos` in `n0`, below 0 beyond the critical angle of n0 > n. Written as
/// (1 − η²) + η² cos² rather than 1 − η² sin²: at grazing light with η = 1 the latter
/// cancels to 0 and the film equations divide 0 by 0. Every refraction of the models reads
/// it (the film's cosines here and in `fast`, `brdf::cos_transmitted`, the renderer's
/// `footprint_offset_nm`); `film.wgsl`'s `snell_cos_sq` is the same expression. (The random
/// walk's `refract` keeps its own: the reference is written apart from what it checks.)
pub fn snell_cos_sq(n0: f64, n: f64, cos: f64) -> f64 {
    let eta2 = (n0 / n) * (n0 / n);
    (1.0 - eta2) + eta2 * cos * cos
}

/// `snell_cos_sq` in f32.
pub fn snell_cos_sq_f32(n0: f32, n: f32, cos: f32) -> f32 {
    let eta2 = (n0 / n) * (n0 / n);
    (1.0 - eta2) + eta2 * cos * cos
}

/// Complex cosine of the angle in a medium of index `n` for incidence `cos0` in `n0`:
/// sqrt(1 − (n0/n)² sin²θ0) (`snell_cos_sq`), imaginary (evanescent) beyond total internal
/// reflection.
pub fn cos_in(n0: f64, n: f64, cos0: f64) -> C64 {
    C64::real(snell_cos_sq(n0, n, cos0)).sqrt_upper()
}

/// cos θ1 in a film of index `n1` under an ambient of index `n0` (`cos_in`), except where
/// that cancels to exactly 0 with light still arriving (cos0 > 0): light at the film's
/// critical angle (n1 < n0), where r01 = 1, r12 = −1 and the Airy sum divides 0 by 0. The
/// film's reflectance is smooth through that angle (its limit depends on the thickness:
/// 0.485 for 300 nm of (1.5, 1.3, 1.4) at 550 nm, not 1, which the 0 / 0 was read as), so
/// the cosine takes the size of the sum's rounding instead, √(ε |1 − (n0/n1)²|), which its
/// neighbours' cosines have too (an independent review's find, measured with 50-digit
/// arithmetic). Where n1 = n0 the cosine is cos0 itself, and 0 only where cos0² underflowed
/// (cos0 below about 2e-162): it is cos0 there.
pub fn film_cos_in(n0: f64, n1: f64, cos0: f64) -> C64 {
    let c1 = cos_in(n0, n1, cos0);
    if c1 == C64::ZERO && cos0 > 0.0 {
        let rounding = (f64::EPSILON * (1.0 - (n0 / n1) * (n0 / n1)).abs()).sqrt();
        C64::real(if rounding > 0.0 { rounding } else { cos0 })
    } else {
        c1
    }
}

/// Fresnel amplitude coefficients (r_s, r_p, t_s, t_p) from medium i into medium j.
pub(crate) fn fresnel_amplitudes(ni: f64, ci: C64, nj: f64, cj: C64) -> (C64, C64, C64, C64) {
    let s_den = ci * ni + cj * nj;
    let p_den = ci * nj + cj * ni;
    let rs = (ci * ni - cj * nj) / s_den;
    let rp = (ci * nj - cj * ni) / p_den;
    let ts = (ci * (2.0 * ni)) / s_den;
    let tp = (ci * (2.0 * ni)) / p_den;
    (rs, rp, ts, tp)
}

/// Fresnel intensity reflectance (R_s, R_p) of a single interface n0 | n; none where the
/// indices are equal (no interface: at cos 0 the amplitudes were 0 / 0, NaN, which the
/// walk's bare interface could read, an independent review's find; below cos 1e-154, whose
/// square underflows, they read 1).
pub fn fresnel(n0: f64, n: f64, cos0: f64) -> (f64, f64) {
    if n0 == n {
        return (0.0, 0.0);
    }
    let c0 = C64::real(cos0);
    let c1 = cos_in(n0, n, cos0);
    let (rs, rp, _, _) = fresnel_amplitudes(n0, c0, n, c1);
    (rs.norm_sqr(), rp.norm_sqr())
}

/// The exact coherent film at one vacuum wavelength: `cos0` is the cosine of the incidence
/// angle in the ambient medium (clamped to [0, 1]).
pub fn airy(stack: Stack, thickness_nm: f64, wavelength_nm: f64, cos0: f64) -> FilmRT {
    FilmAtAngle::new(stack, thickness_nm, cos0).at(wavelength_nm)
}

/// The exact coherent film at one angle of incidence, with what does not depend on the
/// wavelength (the cosines in each medium, the two interfaces' Fresnel amplitudes, the flux
/// ratios) computed once: a spectral sum evaluates 421 wavelengths (360–780 nm) at one
/// angle, and per wavelength only the phase changes. `reflectance` is `at(λ).r` bit for bit
/// without the transmitted wave (one complex exponential instead of two): the reference
/// film colour (`optics::film_rgb_reference`) costs about a third of what it did through
/// `airy`.
#[derive(Debug, Clone, Copy)]
pub struct FilmAtAngle {
    /// cos θ1, complex when the film is evanescent (frustrated TIR).
    c1: C64,
    /// 2π n1 d: the phase β = c1 · (this / λ).
    phase_nm: f64,
    /// Amplitudes (s, p) at the 0|1 and 1|2 interfaces.
    r01: [C64; 2],
    r12: [C64; 2],
    t01: [C64; 2],
    t12: [C64; 2],
    /// The ratio of normal energy flux behind and in front of the film: Re(n cos) for s and
    /// Re(n conj(cos)) for p (PHYSICS.md); zero when the substrate wave is evanescent.
    flux: [f64; 2],
    /// True where the film reflects everything at every wavelength: exactly grazing light
    /// (cos0 = 0: it carries no flux) and a flux ratio that overflows (cos0 below about
    /// 1e-308: the transmittance would be inf · 0, a non-finite value, which is taken as the
    /// grazing limit).
    reflects_all: bool,
    /// True where there is no interface at all: equal ambient and substrate with a film of
    /// their index or of no thickness. Everything passes at every angle, grazing included,
    /// where the Airy sum is 0 / 0 (r01 = −1, r12 = 1 in f64 at cos0 ≈ 1e-16: `brdf film
    /// --n0 1 --n1 1.55 --n2 1 --thickness-nm 0 --angle-deg 90` read R = 1, and with n0 =
    /// n2 = 1.33, T = 0.52 with R = 0: an independent review).
    passes_all: bool,
}

impl FilmAtAngle {
    /// The film of `stack`, `thickness_nm` thick, lit at cosine `cos0` in the ambient
    /// medium (clamped to [0, 1]).
    pub fn new(stack: Stack, thickness_nm: f64, cos0: f64) -> FilmAtAngle {
        let cos0 = cos0.clamp(0.0, 1.0);
        let Stack { n0, n1, n2 } = stack;
        let passes_all = stack.passes_all(thickness_nm);
        let c0 = C64::real(cos0);
        let c1 = film_cos_in(n0, n1, cos0);
        let c2 = cos_in(n0, n2, cos0);
        let (r01s, r01p, t01s, t01p) = fresnel_amplitudes(n0, c0, n1, c1);
        let (r12s, r12p, t12s, t12p) = fresnel_amplitudes(n1, c1, n2, c2);
        let flux = [(c2 * n2).re / (c0 * n0).re, (c2.conj() * n2).re / (c0.conj() * n0).re];
        FilmAtAngle {
            c1,
            phase_nm: 2.0 * std::f64::consts::PI * n1 * thickness_nm,
            r01: [r01s, r01p],
            r12: [r12s, r12p],
            t01: [t01s, t01p],
            t12: [t12s, t12p],
            flux,
            reflects_all: !(passes_all || (cos0 > 0.0 && flux.iter().all(|f| f.is_finite()))),
            passes_all,
        }
    }

    /// The phase β = 2π n1 d cos θ1 / λ across the film; complex when the film is
    /// evanescent (frustrated TIR).
    fn beta(&self, wavelength_nm: f64) -> C64 {
        self.c1 * (self.phase_nm / wavelength_nm)
    }

    /// The Airy reflection amplitude of polarisation `pol` (0: s, 1: p) with the round
    /// trip's phase factor `e2` = e^{2iβ}.
    fn airy_r(&self, pol: usize, e2: C64) -> C64 {
        (self.r01[pol] + self.r12[pol] * e2) / (C64::ONE + self.r01[pol] * self.r12[pol] * e2)
    }

    /// Reflectance and transmittance at one vacuum wavelength.
    pub fn at(&self, wavelength_nm: f64) -> FilmRT {
        if self.reflects_all {
            return FilmRT::from_sp(1.0, 1.0, 0.0, 0.0);
        }
        if self.passes_all {
            return FilmRT::from_sp(0.0, 0.0, 1.0, 1.0);
        }
        let beta = self.beta(wavelength_nm);
        let (e1, e2) = (C64::exp_i(beta), C64::exp_i(beta * 2.0));
        let airy_t =
            |pol: usize| (self.t01[pol] * self.t12[pol] * e1) / (C64::ONE + self.r01[pol] * self.r12[pol] * e2);
        let rs = self.airy_r(0, e2).norm_sqr();
        let rp = self.airy_r(1, e2).norm_sqr();
        let (ts, tp) = (self.flux[0] * airy_t(0).norm_sqr(), self.flux[1] * airy_t(1).norm_sqr());
        if ![rs, rp, ts, tp].iter().all(|v| v.is_finite()) {
            // Only |r01 r12| = 1 makes the Airy denominator vanish: the grazing limit, R = 1.
            return FilmRT::from_sp(1.0, 1.0, 0.0, 0.0);
        }
        FilmRT::from_sp(rs.clamp(0.0, 1.0), rp.clamp(0.0, 1.0), ts.clamp(0.0, 1.0), tp.clamp(0.0, 1.0))
    }

    /// `at(wavelength_nm).r`, bit for bit. `at` takes R = 1 where any of R_s, R_p, T_s, T_p
    /// is not finite; past `reflects_all` the flux ratios are finite, and T is then
    /// non-finite only where its Airy fraction is: the reflected one's denominator vanishes
    /// (R is not finite either) or e^{iβ} overflows (e^{2iβ} has overflowed first, and R
    /// is inf / inf).
    pub fn reflectance(&self, wavelength_nm: f64) -> f64 {
        if self.reflects_all {
            return 1.0;
        }
        if self.passes_all {
            return 0.0;
        }
        let e2 = C64::exp_i(self.beta(wavelength_nm) * 2.0);
        let (rs, rp) = (self.airy_r(0, e2).norm_sqr(), self.airy_r(1, e2).norm_sqr());
        if !(rs.is_finite() && rp.is_finite()) {
            return 1.0;
        }
        0.5 * (rs.clamp(0.0, 1.0) + rp.clamp(0.0, 1.0))
    }
}

/// The incoherent (thick-film) limit: intensities add, phases average out.
/// R = R01 + T01² R12 / (1 − R01 R12), per polarisation (PHYSICS.md, mistake 6).
pub fn incoherent(stack: Stack, cos0: f64) -> FilmRT {
    let cos0 = cos0.clamp(0.0, 1.0);
    let Stack { n0, n1, n2 } = stack;
    // The incoherent limit is a thick film: no interface only where all three indices agree.
    if stack.passes_all(f64::INFINITY) {
        // Everything passes, grazing light too (as `airy`).
        return FilmRT::from_sp(0.0, 0.0, 1.0, 1.0);
    }
    if cos0 <= 0.0 {
        return FilmRT::from_sp(1.0, 1.0, 0.0, 0.0);
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// No interface at all (equal ambient and substrate, the film of their index or of no
    /// thickness) passes everything at every angle, grazing included: `--angle-deg 90` is
    /// cos 6.1e-17, where the Airy sum of a 0 nm film is 0 / 0 and read R = 1, or R = 0 with
    /// T = 0.52 (an independent review). Controls: a film 400 nm thick between equal media,
    /// and a 0 nm film over another substrate, reflect all of grazing light, as interfaces do.
    #[test]
    fn no_interface_passes_everything_at_every_angle() {
        let grazing = std::f64::consts::FRAC_PI_2.cos();
        for (stack, d) in [
            (Stack { n0: 1.0, n1: 1.55, n2: 1.0 }, 0.0),
            (Stack { n0: 1.33, n1: 1.56, n2: 1.33 }, 0.0),
            (Stack { n0: 1.5, n1: 1.5, n2: 1.5 }, 400.0),
        ] {
            for cos0 in [0.0, grazing, 1e-12, 1e-9, 0.5, 1.0] {
                let rt = airy(stack, d, 550.0, cos0);
                assert!(rt.r == 0.0 && rt.t == 1.0, "{stack:?} {d} nm at cos {cos0}: {rt:?}");
                assert_eq!(FilmAtAngle::new(stack, d, cos0).reflectance(550.0), 0.0);
            }
        }
        let interface = |stack: Stack, d: f64| airy(stack, d, 550.0, grazing).r;
        assert!(interface(Stack { n0: 1.0, n1: 1.55, n2: 1.0 }, 400.0) > 0.999);
        assert!(interface(Stack { n0: 1.0, n1: 1.55, n2: 2.0 }, 0.0) > 0.999);
        // The bare interface and the incoherent film, likewise: equal indices reflected NaN
        // at cos 0 (0 / 0) and 1 below cos 1e-154, and the incoherent film of one index
        // read 1 at both. Controls: an interface, and a thick film between equal media,
        // reflect all of grazing light.
        for cos0 in [0.0, 1e-320, 1e-200, grazing, 0.5, 1.0] {
            assert_eq!(fresnel(1.33, 1.33, cos0), (0.0, 0.0), "cos {cos0}");
            let rt = incoherent(Stack { n0: 1.5, n1: 1.5, n2: 1.5 }, cos0);
            assert!(rt.r == 0.0 && rt.t == 1.0, "cos {cos0}: {rt:?}");
        }
        assert_eq!(fresnel(1.0, 1.33, 0.0), (1.0, 1.0));
        assert_eq!(incoherent(Stack { n0: 1.0, n1: 1.55, n2: 1.0 }, 0.0).r, 1.0);
    }

    /// `FilmAtAngle::reflectance` (what the spectral sums call) is `at(λ).r` bit for bit:
    /// over films that vanish (n1 = n0), stacks with total internal reflection in the film
    /// and in the substrate (n1 or n2 below n0), zero, thick and NaN films, and cosines at
    /// 0, 1, out of range, NaN, below 1e-308 (where the flux ratios overflow) and at and
    /// beside the critical angles.
    #[test]
    fn the_reflectance_alone_is_the_full_films_bit_for_bit() {
        let flag = |cos0: f64| FilmAtAngle::new(Stack::THESIS, 400.0, cos0).reflects_all;
        assert!(flag(0.0) && flag(1e-310) && flag(f64::NAN) && !flag(1e-300) && !flag(1.0));
        let stacks = [
            Stack::THESIS,
            Stack { n0: 1.0, n1: 1.0, n2: 1.5 },
            Stack { n0: 1.33, n1: 1.56, n2: 1.33 },
            Stack { n0: 2.0, n1: 1.55, n2: 1.0 },
            Stack { n0: 1.5, n1: 1.2, n2: 1.5 },
        ];
        for stack in stacks {
            let critical = [stack.n1, stack.n2]
                .map(|n| if n < stack.n0 { (1.0 - (n / stack.n0) * (n / stack.n0)).sqrt() } else { 0.5 });
            // Below 1e-308 the flux ratios overflow (`reflects_all`; there r01 rounds to ±1
            // too, so R = 1 either way: these cosines guard the flag's reasoning, not a
            // difference seen); NaN is grazing to both.
            let mut cosines =
                vec![0.0, 5e-324, 1e-310, f64::MIN_POSITIVE, 1e-12, 1e-3, 0.3, 0.77, 1.0, -0.5, 1.5, f64::NAN];
            for c in critical {
                cosines.extend([c, c - 1e-9, c + 1e-9, f64::from_bits(c.to_bits() + 1)]);
            }
            for thickness_nm in [0.0, 1.0, 250.0, 812.5, 9000.0, f64::NAN] {
                for &cos0 in &cosines {
                    let film = FilmAtAngle::new(stack, thickness_nm, cos0);
                    for lambda in (360..=830).step_by(7) {
                        let lambda = lambda as f64 + 0.25;
                        let (alone, full) = (film.reflectance(lambda), film.at(lambda).r);
                        assert_eq!(
                            alone.to_bits(),
                            full.to_bits(),
                            "{stack:?} {thickness_nm} nm cos {cos0} λ {lambda}"
                        );
                    }
                }
            }
        }
    }
}
