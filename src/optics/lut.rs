//! The `lut` method: a per-material table of film colour over (cos θ, thickness), baked
//! from the spectral sum and prefiltered in thickness, read with one bilinear lookup.
//!
//! Thickness axis: `n_fine` texels uniform over [0, `FINE_MAX_NM`] (the range presets
//! use), then `n_coarse` texels up to `COARSE_MAX_NM`, the last of which is exactly the
//! incoherent limit; thicker films clamp to it. Each texel is the box average of the colour
//! over its thickness cell (exact, through the Fourier series in `series.rs`), so texels of
//! thick films already hold the washed-out colour and a lookup can never alias: no moiré at
//! 2.4 mm (the thesis' Fig. 5.9) or any other thickness. Cos θ axis: `n_cos` texels uniform
//! over [0, 1].

use rayon::prelude::*;

use super::film::{Stack, airy};
use super::series::FilmSeries;
use super::spectrum::{Observer, xyz_to_linear_srgb};

pub const FINE_MAX_NM: f64 = 2000.0;
pub const COARSE_MAX_NM: f64 = 20_000.0;

#[derive(Debug, Clone)]
pub struct Lut {
    pub n_cos: usize,
    pub n_fine: usize,
    pub n_coarse: usize,
    /// Row-major: `texels[i_cos * width + i_d]`, linear sRGB reflectance.
    pub texels: Vec<[f32; 3]>,
}

/// Table size chosen from the error/size trade-off measured by `snakeskin bench irid`
/// (see BENCHMARKS.md): 64 angles × (256 + 64) thicknesses, 240 KiB as RGB f32.
pub const DEFAULT_SIZE: (usize, usize, usize) = (64, 256, 64);

impl Lut {
    pub fn width(&self) -> usize {
        self.n_fine + self.n_coarse
    }

    fn fine_step(&self) -> f64 {
        FINE_MAX_NM / (self.n_fine - 1) as f64
    }

    fn coarse_step(&self) -> f64 {
        (COARSE_MAX_NM - FINE_MAX_NM) / self.n_coarse as f64
    }

    /// Thickness at texel column j and the width of the cell it stands for.
    pub fn texel_thickness(&self, j: usize) -> (f64, f64) {
        if j < self.n_fine {
            (j as f64 * self.fine_step(), if j == 0 { 0.0 } else { self.fine_step() })
        } else {
            (FINE_MAX_NM + (j + 1 - self.n_fine) as f64 * self.coarse_step(), self.coarse_step())
        }
    }

    /// Bakes the table for one material (parallel over angles).
    pub fn bake(stack: Stack, n_cos: usize, n_fine: usize, n_coarse: usize) -> Lut {
        let mut lut = Lut { n_cos: n_cos.max(2), n_fine: n_fine.max(2), n_coarse: n_coarse.max(1), texels: Vec::new() };
        let width = lut.width();
        let rows: Vec<Vec<[f32; 3]>> = (0..lut.n_cos)
            .into_par_iter()
            .map(|i| {
                let cos0 = i as f64 / (lut.n_cos - 1) as f64;
                let film = FilmSeries::new(stack, cos0);
                (0..width)
                    .map(|j| {
                        let rgb = if j + 1 == width {
                            let r = super::film::incoherent(stack, cos0).r;
                            [r; 3]
                        } else {
                            let (d, w) = lut.texel_thickness(j);
                            box_colour(stack, &film, d, w, cos0)
                        };
                        rgb.map(|c| c as f32)
                    })
                    .collect()
            })
            .collect();
        lut.texels = rows.into_iter().flatten().collect();
        lut
    }

    pub fn bake_default(stack: Stack) -> Lut {
        let (a, b, c) = DEFAULT_SIZE;
        Lut::bake(stack, a, b, c)
    }

    /// Continuous texel coordinates (x along thickness, y along cos θ).
    #[inline]
    fn coords(&self, thickness_nm: f64, cos0: f64) -> (f64, f64) {
        let d = thickness_nm.max(0.0);
        let x = if d <= FINE_MAX_NM {
            d / self.fine_step()
        } else {
            (self.n_fine - 1) as f64 + (d - FINE_MAX_NM) / self.coarse_step()
        };
        let x = x.min((self.width() - 1) as f64);
        let y = cos0.clamp(0.0, 1.0) * (self.n_cos - 1) as f64;
        (x, y)
    }

    /// f32 bilinear lookup (the shader's texture fetch).
    #[inline]
    pub fn lookup_f32(&self, thickness_nm: f32, cos0: f32) -> [f32; 3] {
        let d = thickness_nm.max(0.0);
        let fine_step = (FINE_MAX_NM / (self.n_fine - 1) as f64) as f32;
        let coarse_step = ((COARSE_MAX_NM - FINE_MAX_NM) / self.n_coarse as f64) as f32;
        let x = if d <= FINE_MAX_NM as f32 {
            d / fine_step
        } else {
            (self.n_fine - 1) as f32 + (d - FINE_MAX_NM as f32) / coarse_step
        };
        let w = self.width();
        let x = x.min((w - 1) as f32);
        let y = cos0.clamp(0.0, 1.0) * (self.n_cos - 1) as f32;
        let (x0, y0) = (x as usize, y as usize);
        let (x1, y1) = ((x0 + 1).min(w - 1), (y0 + 1).min(self.n_cos - 1));
        let (fx, fy) = (x - x0 as f32, y - y0 as f32);
        let t = |i: usize, j: usize| self.texels[i * w + j];
        let (a, b, c, e) = (t(y0, x0), t(y0, x1), t(y1, x0), t(y1, x1));
        [0, 1, 2].map(|k| {
            let top = a[k] + (b[k] - a[k]) * fx;
            let bottom = c[k] + (e[k] - c[k]) * fx;
            top + (bottom - top) * fy
        })
    }

    /// The same lookup in f64 arithmetic (the method's f64 form).
    pub fn lookup_f64(&self, thickness_nm: f64, cos0: f64) -> [f64; 3] {
        let (x, y) = self.coords(thickness_nm, cos0);
        let w = self.width();
        let (x0, y0) = (x as usize, y as usize);
        let (x1, y1) = ((x0 + 1).min(w - 1), (y0 + 1).min(self.n_cos - 1));
        let (fx, fy) = (x - x0 as f64, y - y0 as f64);
        let t = |i: usize, j: usize| self.texels[i * w + j].map(|v| v as f64);
        let (a, b, c, e) = (t(y0, x0), t(y0, x1), t(y1, x0), t(y1, x1));
        [0, 1, 2].map(|k| {
            let top = a[k] + (b[k] - a[k]) * fx;
            let bottom = c[k] + (e[k] - c[k]) * fx;
            top + (bottom - top) * fy
        })
    }
}

/// The spectral colour averaged over thicknesses [d − w/2, d + w/2] (w = 0: at d).
pub fn box_colour(stack: Stack, film: &FilmSeries, d: f64, w: f64, cos0: f64) -> [f64; 3] {
    let obs = Observer::get();
    let usable = film.usable();
    let cos1 = film.cos1.unwrap_or(0.0);
    let xyz = obs.xyz(|lambda| {
        if !usable {
            return airy(stack, d, lambda, cos0).r;
        }
        let k = 4.0 * std::f64::consts::PI * stack.n1 * cos1 / lambda;
        film.reflectance(k * d, k * w)
    });
    xyz_to_linear_srgb(xyz)
}
