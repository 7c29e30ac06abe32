//! Real-time film colour methods, each an f32 function shaped for a direct WGSL twin, with
//! an f64 form of the same method for the agreement test, all compared against the f64
//! spectral reference (PHYSICS.md, "Real-time methods").
//!
//! - `rgb3`: the film at three wavelengths taken as R, G, B (what many engines and the thesis
//!   do), each prefiltered over a 100 nm band so thick films fade instead of aliasing.
//! - `spectral-N`: N box bands over 360–780 nm with CMF·D65 weights converted to linear sRGB,
//!   each band's reflectance prefiltered over the band (exact for the Fourier series).
//! - `gaussian-fit`: Belcour & Barla (2017): the Airy sum as a Fourier series whose spectral
//!   integral is taken analytically with Gaussian fits of the XYZ sensitivities (their
//!   published fit, normalised to illuminant E; here scaled to D65 white by a von Kries
//!   scaling in XYZ), three harmonics.
//! - `lut`: a per-material table over (cos θ, thickness) baked from the spectral sum, each
//!   texel box-averaged over its thickness cell, so bilinear lookups never alias; see `lut.rs`.

use std::sync::OnceLock;

use super::fast::{airy_reflectance_f32, band_reflectance_f32, film_f32};
use super::film::Stack;
use super::series::FilmSeries;
use super::spectrum::{LAMBDA_MIN_NM, Observer, SAMPLES, XYZ_TO_SRGB, mat3_mul};

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Method {
    /// The 1 nm spectral reference (f64 only).
    Spectral,
    Rgb3,
    SpectralN(usize),
    GaussianFit,
    Lut,
}

impl Method {
    pub fn parse(name: &str) -> Option<Method> {
        Some(match name {
            "spectral" => Method::Spectral,
            "rgb3" => Method::Rgb3,
            "gaussian-fit" => Method::GaussianFit,
            "lut" => Method::Lut,
            other => {
                // Digits only: `spectral-+5` was read as spectral-5.
                let digits = other.strip_prefix("spectral-").filter(|d| d.bytes().all(|b| b.is_ascii_digit()))?;
                Method::SpectralN(digits.parse().ok().filter(|n| (1..=SAMPLES).contains(n))?)
            }
        })
    }

    pub fn name(&self) -> String {
        match self {
            Method::Spectral => "spectral".into(),
            Method::Rgb3 => "rgb3".into(),
            Method::SpectralN(n) => format!("spectral-{n}"),
            Method::GaussianFit => "gaussian-fit".into(),
            Method::Lut => "lut".into(),
        }
    }

    /// The methods the benchmark compares, cheapest idea first.
    pub fn all_realtime() -> Vec<Method> {
        vec![
            Method::Rgb3,
            Method::SpectralN(4),
            Method::SpectralN(8),
            Method::SpectralN(16),
            Method::SpectralN(32),
            Method::GaussianFit,
            Method::Lut,
        ]
    }

    pub const ACCEPTED: &'static str = "spectral, rgb3, spectral-N (N = 1..421, e.g. spectral-8), gaussian-fit, lut";
}

/// rgb3 wavelengths in nm for R, G, B (the usual 650 / 550 / 450 choice) and the band each
/// stands for when prefiltering.
pub const RGB3_NM: [f32; 3] = [650.0, 550.0, 450.0];
pub const RGB3_BAND_NM: f32 = 100.0;

/// Band centres, widths and linear-sRGB weights of `spectral-N`.
#[derive(Debug, Clone)]
pub struct Bands {
    pub centres_nm: Vec<f64>,
    pub width_nm: f64,
    pub rgb_weights: Vec<[f64; 3]>,
}

impl Bands {
    pub fn new(n: usize) -> Bands {
        let obs = Observer::get();
        let span = SAMPLES as f64;
        let width = span / n as f64;
        let mut xyz = vec![[0.0f64; 3]; n];
        for (i, w) in obs.weights.iter().enumerate() {
            // 1 nm sample i covers [λ - 0.5, λ + 0.5]; assign it to the band of its centre.
            let band = (((i as f64 + 0.5) / width) as usize).min(n - 1);
            for c in 0..3 {
                xyz[band][c] += w[c];
            }
        }
        Bands {
            centres_nm: (0..n).map(|i| LAMBDA_MIN_NM as f64 - 0.5 + (i as f64 + 0.5) * width).collect(),
            width_nm: width,
            rgb_weights: xyz.into_iter().map(|v| mat3_mul(&XYZ_TO_SRGB, v)).collect(),
        }
    }

    /// The band table for N (1..=421), built once on first use.
    pub fn cached(n: usize) -> &'static Bands {
        const MAX_BANDS: usize = SAMPLES;
        static CACHE: OnceLock<Vec<OnceLock<Bands>>> = OnceLock::new();
        let n = n.clamp(1, MAX_BANDS);
        let all = CACHE.get_or_init(|| (0..MAX_BANDS).map(|_| OnceLock::new()).collect());
        all[n - 1].get_or_init(|| Bands::new(n))
    }
}

/// f64 form: spectral-N with band prefiltering.
pub fn spectral_n_f64(stack: Stack, thickness_nm: f64, cos0: f64, n: usize) -> [f64; 3] {
    let bands = Bands::cached(n);
    let film = FilmSeries::new(stack, cos0);
    let mut rgb = [0.0; 3];
    for (lambda, w) in bands.centres_nm.iter().zip(&bands.rgb_weights) {
        let r = band_reflectance_f64(&film, stack, thickness_nm, *lambda, bands.width_nm, cos0);
        for c in 0..3 {
            rgb[c] += r * w[c];
        }
    }
    rgb
}

fn band_reflectance_f64(film: &FilmSeries, stack: Stack, d: f64, lambda: f64, band_nm: f64, cos0: f64) -> f64 {
    if !film.usable() {
        return super::film::airy(stack, d, lambda, cos0).r;
    }
    let phase = film.phase(stack.n1, d, lambda);
    film.reflectance(phase, phase * band_nm / lambda)
}

/// f32 form: spectral-N with band prefiltering.
pub fn spectral_n_f32(n0: f32, n1: f32, n2: f32, thickness_nm: f32, cos0: f32, n: usize) -> [f32; 3] {
    let bands = Bands::cached(n);
    let film = film_f32(n0, n1, n2, cos0);
    let width = bands.width_nm as f32;
    let mut rgb = [0.0f32; 3];
    for (lambda, w) in bands.centres_nm.iter().zip(&bands.rgb_weights) {
        let r = band_reflectance_f32(&film, n1, thickness_nm, *lambda as f32, width);
        for c in 0..3 {
            rgb[c] += r * w[c] as f32;
        }
    }
    rgb
}

pub fn rgb3_f64(stack: Stack, thickness_nm: f64, cos0: f64) -> [f64; 3] {
    let film = FilmSeries::new(stack, cos0);
    RGB3_NM.map(|l| band_reflectance_f64(&film, stack, thickness_nm, l as f64, RGB3_BAND_NM as f64, cos0))
}

pub fn rgb3_f32(n0: f32, n1: f32, n2: f32, thickness_nm: f32, cos0: f32) -> [f32; 3] {
    let film = film_f32(n0, n1, n2, cos0);
    RGB3_NM.map(|lambda| band_reflectance_f32(&film, n1, thickness_nm, lambda, RGB3_BAND_NM))
}

/// Belcour & Barla (2017) Gaussian fits of the XYZ sensitivity in Fourier space
/// (supplemental material; the same constants as the glTF KHR_materials_iridescence sample
/// code): per channel amplitude, centre and variance, plus a second lobe for X, normalised
/// by 1.0685e-7 so that S(0) is illuminant E's white, XYZ = (1, 1, 1).
/// (amplitude, centre, variance) per lobe: X, Y, Z, then X's second lobe. `film.wgsl` reads
/// them from `render::engine::shaders::generated_constants` (as `BB_AMP`, `BB_POS`, `BB_VAR`).
pub const BB_LOBES: [(f64, f64, f64); 4] = [
    (5.4856e-13, 1.6810e+06, 4.3278e+09),
    (4.4201e-13, 1.7953e+06, 9.3046e+09),
    (5.2481e-13, 2.2084e+06, 6.6121e+09),
    (9.7470e-14, 2.2399e+06, 4.5282e+09),
];
pub const BB_NORM: f64 = 1.0685e-7;
/// The lobes' centres and variances are in radians per metre of optical path (Belcour &
/// Barla's Fourier variable), and our path differences in nanometres.
pub const BB_METRES_PER_NM: f64 = 1e-9;

/// A lobe's amplitude with its normalisation folded in, val √(2π var) / BB_NORM: what the
/// f32 paths (Rust and WGSL) multiply by.
pub fn bb_amplitude((val, _, var): (f64, f64, f64)) -> f64 {
    val * (2.0 * std::f64::consts::PI * var).sqrt() / BB_NORM
}
/// Harmonics Belcour & Barla's method sums (they use 2; 3 costs little more).
pub const GAUSSIAN_FIT_HARMONICS: usize = 3;

/// Re(C · S(opd)) per XYZ channel, C a harmonic coefficient, `opd_nm` the path difference.
fn bb_sensitivity(c_re: f64, c_im: f64, opd_nm: f64) -> [f64; 3] {
    let phase = 2.0 * std::f64::consts::PI * opd_nm * BB_METRES_PER_NM;
    let (mag, arg) = ((c_re * c_re + c_im * c_im).sqrt(), c_im.atan2(c_re));
    let lobe = |l: (f64, f64, f64)| bb_amplitude(l) * (l.1 * phase + arg).cos() * (-l.2 * phase * phase).exp();
    let mut xyz = [0, 1, 2].map(|i| lobe(BB_LOBES[i]));
    xyz[0] += lobe(BB_LOBES[3]);
    xyz.map(|v| mag * v)
}

/// The gaussian-fit's XYZ (under illuminant E: the fits are of the bare CMFs) to linear
/// sRGB under D65: the von Kries scaling by D65's white (`d65_white`), then `XYZ_TO_SRGB`,
/// in one matrix. The f64 and f32 paths and the shader's `FilmInfo` take it from here.
pub fn gaussian_fit_xyz_to_rgb() -> [[f64; 3]; 3] {
    let white = d65_white();
    XYZ_TO_SRGB.map(|row| [row[0] * white[0], row[1] * white[1], row[2] * white[2]])
}

/// D65 white XYZ relative to illuminant E's (1, 1, 1), for the von Kries scaling.
pub fn d65_white() -> [f64; 3] {
    Observer::get().white_xyz()
}

/// The wavelength (nm) at which the Gaussian fit reads the exact film, grey, where its series is
/// not used: beyond the film's critical angle, where the series does not exist
/// (`FilmSeries::usable`), and where the harmonics it leaves out may reach
/// `GAUSSIAN_FIT_MAX_REST`. 550 nm: the middle of the visible range and near the peak of the
/// CIE ȳ function (555 nm).
pub const GAUSSIAN_FIT_EXACT_NM: f64 = 550.0;
/// The most the harmonics the Gaussian fit leaves out may add to a polarisation's reflectance,
/// for it to sum its series: it sums GAUSSIAN_FIT_HARMONICS = H harmonics, D q^(m−1), and the
/// rest is at most 2 |D| |q|^H / (1 − |q|) ≤ 4 |D| |q|^H / (1 − |q|²), the bound compared (squared:
/// no root, no division). On the four materials of `bench irid` the bound stays under 0.0052
/// at every angle, so they keep the series; near the critical angle of a film less dense than
/// the ambient |q| → 1 and the bound grows past 0.7: there the f32 form read a bare film on
/// (1.5, 1.35, 2) as 0.98 where it reflects 0.08. Below 0.01 its reading of a bare film is
/// within 0.004 on the three stacks of `tests/brdf.rs` (0.0052 on (1.5, 1.45, 1.5), a review found) (both measured over 0–90° in steps of 0.01°, in Python, for
/// this change).
pub const GAUSSIAN_FIT_MAX_REST: f64 = 0.01;

pub fn gaussian_fit_f64(stack: Stack, thickness_nm: f64, cos0: f64) -> [f64; 3] {
    let film = FilmSeries::new(stack, cos0);
    // The harmonics the fit leaves out (GAUSSIAN_FIT_MAX_REST), compared squared.
    let small_rest = |h: &super::series::Harmonics| {
        let q2 = h.q.norm_sqr();
        16.0 * h.d.norm_sqr() * q2.powi(GAUSSIAN_FIT_HARMONICS as i32) < (GAUSSIAN_FIT_MAX_REST * (1.0 - q2)).powi(2)
    };
    let (true, Some(cos1)) = (film.usable() && small_rest(&film.s) && small_rest(&film.p), film.cos1) else {
        let r = super::film::airy(stack, thickness_nm, GAUSSIAN_FIT_EXACT_NM, cos0).r;
        return [r; 3];
    };
    let opd = 2.0 * stack.n1 * thickness_nm * cos1;
    let mut xyz = [film.incoherent(); 3];
    for h in [&film.s, &film.p] {
        let mut c = h.d;
        for m in 1..=GAUSSIAN_FIT_HARMONICS {
            let s = bb_sensitivity(c.re, c.im, m as f64 * opd);
            for k in 0..3 {
                // 2 Re(...) per polarisation, averaged over s and p.
                xyz[k] += s[k];
            }
            c = c * h.q;
        }
    }
    mat3_mul(&gaussian_fit_xyz_to_rgb(), xyz)
}

pub fn gaussian_fit_f32(n0: f32, n1: f32, n2: f32, thickness_nm: f32, cos0: f32) -> [f32; 3] {
    use super::fast::C32;
    let film = film_f32(n0, n1, n2, cos0);
    // As gaussian_fit_f64: the harmonics left out, compared squared.
    let small_rest = |h: &super::fast::Harmonics32| {
        let q2 = h.q[0] * h.q[0] + h.q[1] * h.q[1];
        16.0 * (h.d[0] * h.d[0] + h.d[1] * h.d[1]) * q2.powi(GAUSSIAN_FIT_HARMONICS as i32)
            < (GAUSSIAN_FIT_MAX_REST as f32 * (1.0 - q2)).powi(2)
    };
    if film.exact || !(small_rest(&film.s) && small_rest(&film.p)) {
        // As gaussian_fit_f64: where the series is not used, the exact film at the fit's
        // centre wavelength instead (grey).
        return [airy_reflectance_f32(&film, n1, thickness_nm, GAUSSIAN_FIT_EXACT_NM as f32); 3];
    }
    let opd = 2.0 * n1 * thickness_nm * film.cos1;
    let mut xyz = [0.5 * (film.s.c0 + film.p.c0); 3];
    let mul = |a: C32, b: C32| [a[0] * b[0] - a[1] * b[1], a[0] * b[1] + a[1] * b[0]];
    for h in [&film.s, &film.p] {
        let mut c = h.d;
        for m in 1..=GAUSSIAN_FIT_HARMONICS {
            let phase = 2.0 * std::f32::consts::PI * (m as f32 * opd) * BB_METRES_PER_NM as f32;
            let (mag, arg) = ((c[0] * c[0] + c[1] * c[1]).sqrt(), c[1].atan2(c[0]));
            let lobe = |l: (f64, f64, f64)| {
                bb_amplitude(l) as f32 * (l.1 as f32 * phase + arg).cos() * (-(l.2 as f32) * phase * phase).exp()
            };
            xyz[0] += mag * (lobe(BB_LOBES[0]) + lobe(BB_LOBES[3]));
            xyz[1] += mag * lobe(BB_LOBES[1]);
            xyz[2] += mag * lobe(BB_LOBES[2]);
            c = mul(c, h.q);
        }
    }
    mat3_mul(&gaussian_fit_xyz_to_rgb(), xyz.map(f64::from)).map(|x| x as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `spectral-N` takes N in digits from 1 to 421 (`spectral-+5` was read as spectral-5).
    #[test]
    fn spectral_n_is_digits_in_range() {
        assert_eq!(Method::parse("spectral-8"), Some(Method::SpectralN(8)));
        assert_eq!(Method::parse("spectral-421"), Some(Method::SpectralN(421)));
        for refused in ["spectral-+5", "spectral-0", "spectral-422", "spectral- 5", "spectral-", "spectral-5.0"] {
            assert_eq!(Method::parse(refused), None, "{refused}");
        }
    }

    /// The f32 "no interface" rule (`fast::Film32::passes_all`) is the f64 one
    /// (`film::Stack::passes_all`) on indices that f32 holds exactly, at every cosine
    /// (the grazing branch of `film_f32` carries it too). Control: 1 + 1e-9 rounds to 1 in
    /// f32, so there the f32 rule passes everything where f64 sees an interface, as it must
    /// (an f32 Airy sum of equal indices reads NaN near grazing).
    #[test]
    fn the_f32_no_interface_rule_is_the_f64_one() {
        let indices = [1.0, 1.25, 1.5, 2.0];
        let mut passing = 0;
        for n0 in indices {
            for n1 in indices {
                for n2 in indices {
                    for d in [0.0, 1e-3, 400.0] {
                        let stack = Stack { n0, n1, n2 };
                        for cos0 in [0.0f32, 1e-30, 0.5, 1.0] {
                            let f32_rule = film_f32(n0 as f32, n1 as f32, n2 as f32, cos0).passes_all(d as f32);
                            assert_eq!(f32_rule, stack.passes_all(d), "{stack:?} {d} nm at cos {cos0}");
                        }
                        passing += stack.passes_all(d) as usize;
                    }
                }
            }
        }
        // n2 = n0 (16 stacks) at 0 nm, and n1 = n0 too (4 stacks) at the other two thicknesses.
        assert_eq!(passing, 16 + 2 * 4);
        let near = Stack { n0: 1.0, n1: 1.0, n2: 1.0 + 1e-9 };
        assert!(!near.passes_all(400.0));
        assert!(film_f32(1.0, 1.0, near.n2 as f32, 0.5).passes_all(400.0));
    }

    /// Where there is no interface at all (the substrate's index the ambient's, with a film
    /// of no thickness or of their index), every f32 film method reads 0 at every cosine,
    /// grazing included, as the f64 film does (`film::Stack::passes_all`). Before
    /// `fast::Film32::passes_all` they read NaN from cos 1e-12 to 3e-8 (r01 and r12 round
    /// to ∓1: 0 / 0) and 1 at grazing. Controls: a film 1 nm thick, and a substrate a
    /// millionth denser than the ambient, reflect nearly everything near grazing in f32 as
    /// the f64 film does; their colours stay finite too.
    #[test]
    fn no_interface_passes_everything_in_every_f32_method_at_every_angle() {
        use super::super::film::{Stack, airy};
        type F32Method = fn(f32, f32, f32, f32, f32) -> [f32; 3];
        let methods: [(&str, F32Method, f32); 3] = [
            ("rgb3", rgb3_f32, 1e-5),
            ("spectral-8", |a, b, c, d, e| spectral_n_f32(a, b, c, d, e, 8), 1e-5),
            // The fit's own error on a bare interface at ordinary angles (1.1e-3 at cos 0.5).
            ("gaussian-fit", gaussian_fit_f32, 2e-3),
        ];
        let cosines = [0.0f32, 1e-30, 1e-20, 1e-12, 1e-9, 3e-8, 1e-7, 1e-5, 0.5, 1.0];
        let f32s = |s: Stack| (s.n0 as f32, s.n1 as f32, s.n2 as f32);
        let passes = [
            (Stack { n0: 1.33, n1: 1.55, n2: 1.33 }, 0.0),
            (Stack { n0: 1.0, n1: 1.55, n2: 1.0 }, 0.0),
            (Stack { n0: 1.33, n1: 1.33, n2: 1.33 }, 300.0),
            (Stack { n0: 1.0, n1: 1.0, n2: 1.0 }, 0.0),
        ];
        for (stack, d) in passes {
            let (n0, n1, n2) = f32s(stack);
            for c in cosines {
                assert_eq!(airy(stack, d, 550.0, f64::from(c)).r, 0.0, "the f64 film, {stack:?} {d} nm, cos {c}");
                for (name, method, tolerance) in methods {
                    let rgb = method(n0, n1, n2, d as f32, c);
                    assert!(rgb.iter().all(|v| v.abs() <= tolerance), "{name} on {stack:?}, {d} nm, cos {c}: {rgb:?}");
                }
            }
        }
        let reflect = [(Stack { n0: 1.33, n1: 1.55, n2: 1.33 }, 1.0), (Stack { n0: 1.0, n1: 1.55, n2: 1.000001 }, 0.0)];
        for (stack, d) in reflect {
            let (n0, n1, n2) = f32s(stack);
            for c in cosines {
                for (name, method, _) in methods {
                    let rgb = method(n0, n1, n2, d as f32, c);
                    assert!(rgb.iter().all(|v| v.is_finite()), "{name} on {stack:?}, {d} nm, cos {c}: {rgb:?}");
                }
            }
            for c in [0.0f32, 1e-20, 1e-9] {
                assert!(airy(stack, d, 550.0, f64::from(c)).r > 0.999, "the f64 film, {stack:?} {d} nm, cos {c}");
                for (name, method, _) in methods {
                    let rgb = method(n0, n1, n2, d as f32, c);
                    assert!(rgb.iter().all(|v| *v > 0.99), "{name} on {stack:?}, {d} nm, cos {c}: {rgb:?}");
                }
            }
        }
    }
}
