//! Time against error: every real-time method's f32 function on PHYSICS.md's grid, scored by
//! CIEDE2000 against the f64 spectral reference, and timed per evaluation.
//!
//! Grid: d ∈ [0, 2000] nm, θ ∈ [0°, 89°], and the four materials of PHYSICS.md. Both colours
//! are linear sRGB reflectances converted to CIELAB with the D65 white (Y = 1).

use std::hint::black_box;
use std::time::Instant;

use rayon::prelude::*;

use super::film::Stack;
use super::film_rgb_reference;
use super::lab::{ciede2000, linear_srgb_to_lab};
use super::lut::Lut;
use super::methods::{Method, gaussian_fit_f32, rgb3_f32, spectral_n_f32};

/// (n0, n1, n2) of PHYSICS.md's error grid: the thesis' default, a water-like film on a
/// keratin-like base, the same inverted, and the default under water.
pub const GRID_MATERIALS: [Stack; 4] = [
    Stack::THESIS,
    Stack { n0: 1.00, n1: 1.33, n2: 1.56 },
    Stack { n0: 1.00, n1: 1.56, n2: 1.33 },
    Stack { n0: 1.33, n1: 1.55, n2: 2.00 },
];

#[derive(Debug, Clone, serde::Serialize)]
pub struct MethodReport {
    pub name: String,
    pub mean_de: f64,
    pub p95_de: f64,
    pub max_de: f64,
    pub ns_per_eval: f64,
}

/// One grid point.
#[derive(Debug, Clone, Copy)]
pub struct Sample {
    pub material: usize,
    pub thickness_nm: f64,
    pub cos0: f64,
}

/// The most grid points `bench irid` accepts: each needs a 421-wavelength reference sum
/// (the default 10 nm × 1° grid has 72,360; 400,000 take a few minutes on two cores).
pub const MAX_GRID_POINTS: usize = 400_000;

/// The error grid's largest angle of incidence: 89°, short of grazing, where the film's
/// colour is degenerate (cos θ = 0, every stack reflects everything). Its thicknesses run
/// over the presets' range, the LUT's fine columns (`lut::FINE_MAX_NM`).
pub const GRID_ANGLE_MAX_DEG: f64 = 89.0;

/// How many points `grid` makes for these steps, computed without building it.
pub fn grid_points(d_step_nm: f64, angle_step_deg: f64) -> usize {
    let count = |span: f64, step: f64| (span / step + 1e-9).floor() as usize + 1;
    GRID_MATERIALS.len() * count(GRID_ANGLE_MAX_DEG, angle_step_deg) * count(super::lut::FINE_MAX_NM, d_step_nm)
}

/// The grid with `d_step_nm` and `angle_step_deg` spacing.
pub fn grid(d_step_nm: f64, angle_step_deg: f64) -> Vec<Sample> {
    let mut samples = Vec::new();
    for material in 0..GRID_MATERIALS.len() {
        let mut angle = 0.0;
        while angle <= GRID_ANGLE_MAX_DEG + 1e-9 {
            let mut d = 0.0;
            while d <= super::lut::FINE_MAX_NM + 1e-9 {
                samples.push(Sample { material, thickness_nm: d, cos0: f64::to_radians(angle).cos() });
                d += d_step_nm;
            }
            angle += angle_step_deg;
        }
    }
    samples
}

/// A method ready to run on the grid (LUTs baked per material).
pub struct Prepared {
    pub method: Method,
    pub luts: Vec<Lut>,
}

impl Prepared {
    pub fn new(method: Method) -> Self {
        Self::with_lut_size(method, super::lut::DEFAULT_SIZE)
    }

    pub fn with_lut_size(method: Method, size: (usize, usize, usize)) -> Self {
        let luts = if method == Method::Lut {
            GRID_MATERIALS.iter().map(|s| Lut::bake(*s, size.0, size.1, size.2)).collect()
        } else {
            Vec::new()
        };
        Prepared { method, luts }
    }

    /// The method's f32 function at one grid point.
    #[inline]
    pub fn eval_f32(&self, s: &Sample) -> [f32; 3] {
        let m = &GRID_MATERIALS[s.material];
        let (n0, n1, n2, d, c) = (m.n0 as f32, m.n1 as f32, m.n2 as f32, s.thickness_nm as f32, s.cos0 as f32);
        match self.method {
            Method::Rgb3 => rgb3_f32(n0, n1, n2, d, c),
            Method::SpectralN(n) => spectral_n_f32(n0, n1, n2, d, c, n),
            Method::GaussianFit => gaussian_fit_f32(n0, n1, n2, d, c),
            Method::Lut => self.luts[s.material].lookup_f32(d, c),
            Method::Spectral => film_rgb_reference(*m, s.thickness_nm, s.cos0).map(|v| v as f32),
        }
    }
}

pub fn reference_colours(samples: &[Sample]) -> Vec<[f64; 3]> {
    samples.par_iter().map(|s| film_rgb_reference(GRID_MATERIALS[s.material], s.thickness_nm, s.cos0)).collect()
}

/// ΔE2000 statistics and cost of one method.
pub fn measure(prepared: &Prepared, samples: &[Sample], reference_lab: &[[f64; 3]]) -> MethodReport {
    let mut errors: Vec<f64> = samples
        .par_iter()
        .zip(reference_lab)
        .map(|(s, lab_ref)| {
            let rgb = prepared.eval_f32(s).map(|v| v as f64);
            ciede2000(linear_srgb_to_lab(rgb), *lab_ref)
        })
        .collect();
    errors.sort_by(f64::total_cmp);
    let mean = errors.iter().sum::<f64>() / errors.len() as f64;
    let p95 = errors[((errors.len() as f64 * 0.95) as usize).min(errors.len() - 1)];
    let max = *errors.last().unwrap_or(&0.0);

    // Cost: single-threaded passes over the grid; the median of five.
    let mut per_eval: Vec<f64> = (0..5)
        .map(|_| {
            let start = Instant::now();
            let mut acc = 0.0f32;
            for s in samples {
                let rgb = prepared.eval_f32(black_box(s));
                acc += rgb[0] + rgb[1] + rgb[2];
            }
            black_box(acc);
            start.elapsed().as_secs_f64() * 1e9 / samples.len() as f64
        })
        .collect();
    per_eval.sort_by(f64::total_cmp);
    MethodReport { name: prepared.method.name(), mean_de: mean, p95_de: p95, max_de: max, ns_per_eval: per_eval[2] }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The finest grids `bench irid --d-step-nm`'s help names: about 1.8 nm at 1° angle
    /// steps, 0.1 nm over 22.25° (it said 2 nm and 25°, which were not the limits).
    #[test]
    fn the_finest_grids_the_help_names_are_the_limits() {
        let fits = |d: f64, a: f64| grid_points(d, a) <= MAX_GRID_POINTS;
        assert!(fits(1.802, 1.0) && !fits(1.80, 1.0));
        assert!(fits(0.1, 22.26) && !fits(0.1, 22.25));
    }

    #[test]
    fn grid_points_counts_the_grid_without_building_it() {
        for (d, a) in [(10.0, 1.0), (50.0, 11.0), (7.0, 3.0), (0.5, 89.0), (2000.0, 0.7), (3.3, 2.9)] {
            assert_eq!(grid_points(d, a), grid(d, a).len(), "steps {d} nm, {a}°");
        }
    }
}
