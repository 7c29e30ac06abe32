//! From a reflectance spectrum to colour: CIE 1931 2° observer, illuminant D65,
//! 360–780 nm at 1 nm, to XYZ and linear sRGB (PHYSICS.md, "From spectrum to colour").
//!
//! Tables (in `data/`, copied from the CIE's published tables):
//! - `cie1931_2deg_cmf_1nm.csv`: x̄, ȳ, z̄ at 1 nm (CIE 015:2018, Table 1 data).
//! - `cie_d65_spd_5nm.csv`: D65 relative spectral power at 5 nm (CIE S 014-2), linearly
//!   interpolated to 1 nm as PHYSICS.md prescribes.
//!
//! Normalisation k = 1 / Σ S ȳ, so a perfect reflector has Y = 1.

use std::sync::OnceLock;

/// First and last wavelength of the reference sum, nm.
pub const LAMBDA_MIN_NM: u32 = 360;
pub const LAMBDA_MAX_NM: u32 = 780;
pub const SAMPLES: usize = (LAMBDA_MAX_NM - LAMBDA_MIN_NM + 1) as usize;

/// XYZ → linear sRGB (IEC 61966-2-1), the matrix PHYSICS.md fixes.
pub const XYZ_TO_SRGB: [[f64; 3]; 3] =
    [[3.2404542, -1.5371385, -0.4985314], [-0.9692660, 1.8760108, 0.0415560], [0.0556434, -0.2040259, 1.0572252]];

/// The sRGB primaries and white as CIE 1931 xy chromaticities: red, green, blue, then the
/// D65 white (IEC 61966-2-1; the ITU-R BT.709 primaries). `XYZ_TO_SRGB` is the matrix they
/// define (the test `srgb_matrix_is_the_primaries_matrix` derives it from them), and an
/// OpenEXR colour map records them as its `chromaticities`.
pub const SRGB_PRIMARIES_XY: [[f64; 2]; 4] = [[0.64, 0.33], [0.30, 0.60], [0.15, 0.06], [0.3127, 0.3290]];

/// Per-wavelength weights k S(λ) (x̄, ȳ, z̄)(λ) for λ = 360..=780 nm.
pub struct Observer {
    pub weights: Vec<[f64; 3]>,
    /// `xyz` of the perfect reflector, summed once: every reference film colour is divided
    /// by it (`brdf::exact::reflectance`).
    white_xyz: [f64; 3],
}

fn parse_csv(text: &str) -> Vec<Vec<f64>> {
    text.lines()
        .skip(1)
        .filter(|l| !l.trim().is_empty())
        .map(|l| l.split(',').map(|v| v.trim().parse::<f64>().expect("numeric CIE table")).collect())
        .collect()
}

impl Observer {
    fn build() -> Self {
        let cmf = parse_csv(include_str!("../../data/cie1931_2deg_cmf_1nm.csv"));
        let d65 = parse_csv(include_str!("../../data/cie_d65_spd_5nm.csv"));
        let d65_at = |lambda: f64| {
            let i = d65.iter().rposition(|row| row[0] <= lambda).expect("D65 covers 300-780 nm");
            let (a, b) = (&d65[i], d65.get(i + 1).unwrap_or(&d65[i]));
            if b[0] == a[0] { a[1] } else { a[1] + (b[1] - a[1]) * (lambda - a[0]) / (b[0] - a[0]) }
        };
        let mut weights: Vec<[f64; 3]> = (LAMBDA_MIN_NM..=LAMBDA_MAX_NM)
            .map(|l| {
                let row = cmf.iter().find(|r| r[0] == l as f64).expect("CMF covers 360-830 nm");
                let s = d65_at(l as f64);
                [s * row[1], s * row[2], s * row[3]]
            })
            .collect();
        let k = 1.0 / weights.iter().map(|w| w[1]).sum::<f64>();
        weights.iter_mut().for_each(|w| w.iter_mut().for_each(|c| *c *= k));
        let mut observer = Observer { weights, white_xyz: [0.0; 3] };
        observer.white_xyz = observer.xyz(|_| 1.0);
        observer
    }

    /// The shared table (parsed once).
    pub fn get() -> &'static Observer {
        static OBSERVER: OnceLock<Observer> = OnceLock::new();
        OBSERVER.get_or_init(Observer::build)
    }

    /// XYZ of a reflectance spectrum `reflectance(λ_nm)` under D65.
    pub fn xyz(&self, reflectance: impl Fn(f64) -> f64) -> [f64; 3] {
        let mut xyz = [0.0; 3];
        for (i, w) in self.weights.iter().enumerate() {
            let r = reflectance((LAMBDA_MIN_NM as usize + i) as f64);
            for c in 0..3 {
                xyz[c] += r * w[c];
            }
        }
        xyz
    }

    /// XYZ of the perfect reflector (the D65 white with Y = 1).
    pub fn white_xyz(&self) -> [f64; 3] {
        self.white_xyz
    }
}

pub fn mat3_mul(m: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|r| m[r][0] * v[0] + m[r][1] * v[1] + m[r][2] * v[2])
}

pub fn xyz_to_linear_srgb(xyz: [f64; 3]) -> [f64; 3] {
    mat3_mul(&XYZ_TO_SRGB, xyz)
}

/// Inverse of a 3×3 matrix (cofactors), for linear sRGB → XYZ with exactly the inverse of
/// the matrix above, so the two conversions round-trip.
pub fn mat3_inverse(m: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let c = |r0: usize, c0: usize, r1: usize, c1: usize| m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0];
    let cof = [
        [c(1, 1, 2, 2), -c(1, 0, 2, 2), c(1, 0, 2, 1)],
        [-c(0, 1, 2, 2), c(0, 0, 2, 2), -c(0, 0, 2, 1)],
        [c(0, 1, 1, 2), -c(0, 0, 1, 2), c(0, 0, 1, 1)],
    ];
    let det = m[0][0] * cof[0][0] + m[0][1] * cof[0][1] + m[0][2] * cof[0][2];
    [0, 1, 2].map(|r| [0, 1, 2].map(|col| cof[col][r] / det))
}

pub fn linear_srgb_to_xyz(rgb: [f64; 3]) -> [f64; 3] {
    static INVERSE: OnceLock<[[f64; 3]; 3]> = OnceLock::new();
    mat3_mul(INVERSE.get_or_init(|| mat3_inverse(&XYZ_TO_SRGB)), rgb)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn perfect_reflector_is_white() {
        let obs = Observer::get();
        let white = obs.white_xyz();
        assert!((white[1] - 1.0).abs() < 1e-12);
        let rgb = xyz_to_linear_srgb(white);
        for c in rgb {
            assert!((c - 1.0).abs() < 1e-3, "{rgb:?}");
        }
        // The D65 chromaticity (CIE 015: x = 0.31272, y = 0.32903 for the 2° observer).
        let sum = white.iter().sum::<f64>();
        assert!((white[0] / sum - 0.31272).abs() < 2e-4 && (white[1] / sum - 0.32903).abs() < 2e-4, "{white:?}");
    }

    #[test]
    fn srgb_matrix_is_the_primaries_matrix() {
        // RGB → XYZ from the chromaticities alone: the columns are the primaries' xyz
        // scaled so that RGB = (1, 1, 1) is the white with Y = 1 (the standard derivation,
        // e.g. SMPTE RP 177). The matrix above was derived from the white's XYZ to five
        // digits (0.95047, 1, 1.08883), whose xy round to the standard's (0.3127, 0.3290):
        // the two agree to 6e-4, not closer.
        let xyz_of = |[x, y]: [f64; 2]| [x / y, 1.0, (1.0 - x - y) / y];
        let [r, g, b, white] = SRGB_PRIMARIES_XY.map(xyz_of);
        let primaries = [0, 1, 2].map(|row| [r[row], g[row], b[row]]);
        let scale = mat3_mul(&mat3_inverse(&primaries), white);
        let rgb_to_xyz = [0, 1, 2].map(|row| [0, 1, 2].map(|col| primaries[row][col] * scale[col]));
        let derived = mat3_inverse(&rgb_to_xyz);
        for row in 0..3 {
            for col in 0..3 {
                let error = (derived[row][col] - XYZ_TO_SRGB[row][col]).abs();
                assert!(error < 6e-4, "{row},{col}: {derived:?} against {XYZ_TO_SRGB:?}");
            }
        }
    }

    #[test]
    fn inverse_matrix_round_trips() {
        let rgb = [0.2, 0.5, 0.9];
        let back = xyz_to_linear_srgb(linear_srgb_to_xyz(rgb));
        for c in 0..3 {
            assert!((rgb[c] - back[c]).abs() < 1e-12);
        }
    }
}
