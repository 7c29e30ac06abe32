//! Tileable fractal noise: gradient (Perlin) noise and cellular (Worley) noise on a periodic
//! lattice.
//!
//! Why not sample the `noise` crate's 4D Perlin on a torus, the usual way to tile? Measured
//! here it costs ~67 ns a sample against ~34 ns for 2D, and a 2K texture set affords only a
//! handful of samples per pixel. A lattice whose cell coordinates wrap modulo an integer
//! period tiles exactly at the cost of plain 2D noise. The gradients still come from the
//! `noise` crate's seeded permutation table, as in its own Perlin. Its `set_is_seamless`
//! is avoided: it blends four samples (4x cost) and loses contrast mid-tile.
//!
//! Every octave has integer periods in u and v, so each octave — and so the sum — tiles.

use std::f32::consts::FRAC_1_SQRT_2;

use noise::permutationtable::{NoiseHasher, PermutationTable};

use super::hash;

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum NoiseKind {
    /// Gradient noise, smooth blobs.
    Perlin,
    /// Distance to the nearest jittered feature point (Worley F1), cells.
    Cellular,
}

/// A fractal (fBm) noise field over the unit torus.
#[derive(Debug, Clone, PartialEq)]
pub struct FractalNoise {
    pub kind: NoiseKind,
    /// Lattice cells per tile of the first octave, around (u) and along (v). At least 1.
    pub cells_u: u32,
    pub cells_v: u32,
    pub octaves: u32,
    /// Amplitude ratio between successive octaves (persistence).
    pub gain: f32,
    pub seed: u32,
}

/// Sixteen unit gradients evenly spaced on the circle (16 gives visibly isotropic noise).
const GRADIENTS: [[f32; 2]; 16] = {
    let mut g = [[0.0f32; 2]; 16];
    // cos/sin of k * 22.5 degrees, written out because const fn trig is unavailable.
    let c = [
        1.0,
        0.923_879_5,
        FRAC_1_SQRT_2,
        0.382_683_4,
        0.0,
        -0.382_683_4,
        -FRAC_1_SQRT_2,
        -0.923_879_5,
        -1.0,
        -0.923_879_5,
        -FRAC_1_SQRT_2,
        -0.382_683_4,
        0.0,
        0.382_683_4,
        FRAC_1_SQRT_2,
        0.923_879_5,
    ];
    let mut k = 0;
    while k < 16 {
        g[k] = [c[k], c[(k + 12) % 16]];
        k += 1;
    }
    g
};

#[inline]
fn quintic(t: f32) -> f32 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

/// Periodic 2D gradient noise in about [-1, 1]; (x, y) in lattice units, periods in cells.
#[inline]
pub fn perlin_periodic(
    table: &PermutationTable,
    x: f32,
    y: f32,
    period_x: i32,
    period_y: i32,
) -> f32 {
    let (xf, yf) = (x.floor(), y.floor());
    let (ix, iy) = (xf as i32, yf as i32);
    let (fx, fy) = (x - xf, y - yf);
    let x0 = ix.rem_euclid(period_x) as isize;
    let y0 = iy.rem_euclid(period_y) as isize;
    let x1 = (ix + 1).rem_euclid(period_x) as isize;
    let y1 = (iy + 1).rem_euclid(period_y) as isize;
    let dot = |cx: isize, cy: isize, dx: f32, dy: f32| {
        let g = GRADIENTS[table.hash(&[cx, cy]) & 15];
        g[0] * dx + g[1] * dy
    };
    let n00 = dot(x0, y0, fx, fy);
    let n10 = dot(x1, y0, fx - 1.0, fy);
    let n01 = dot(x0, y1, fx, fy - 1.0);
    let n11 = dot(x1, y1, fx - 1.0, fy - 1.0);
    let (sx, sy) = (quintic(fx), quintic(fy));
    let nx0 = n00 + sx * (n10 - n00);
    let nx1 = n01 + sx * (n11 - n01);
    // 2D gradient noise with unit gradients peaks at sqrt(2)/2; scale to about [-1, 1].
    (nx0 + sy * (nx1 - nx0)) * std::f32::consts::SQRT_2
}

/// Periodic Worley F1 distance in lattice units (0 at a feature point, about 0..1).
#[inline]
pub fn cellular_periodic(seed: u32, x: f32, y: f32, period_x: i32, period_y: i32) -> f32 {
    let (ix, iy) = (x.floor() as i32, y.floor() as i32);
    let mut best = f32::MAX;
    for dy in -1..=1 {
        for dx in -1..=1 {
            let (cx, cy) = (ix + dx, iy + dy);
            let (wx, wy) = (cx.rem_euclid(period_x), cy.rem_euclid(period_y));
            let px = cx as f32 + hash::unit(wx, wy, 0, seed);
            let py = cy as f32 + hash::unit(wx, wy, 1, seed);
            let d2 = (px - x) * (px - x) + (py - y) * (py - y);
            best = best.min(d2);
        }
    }
    best.sqrt()
}

/// Precomputed per-octave state; build once per node evaluation.
pub struct NoiseSampler {
    noise: FractalNoise,
    tables: Vec<PermutationTable>,
    norm: f32,
}

impl NoiseSampler {
    pub fn new(noise: &FractalNoise) -> Self {
        let octaves = noise.octaves.max(1);
        let tables = (0..octaves)
            .map(|o| PermutationTable::new(noise.seed.wrapping_add(o * 0x9e37)))
            .collect();
        let norm = (0..octaves)
            .map(|o| noise.gain.powi(o as i32))
            .sum::<f32>()
            .max(1e-6);
        NoiseSampler {
            noise: noise.clone(),
            tables,
            norm,
        }
    }

    /// Fractal noise at texture coordinate (u, v), in [0, 1].
    #[inline]
    pub fn sample(&self, u: f32, v: f32) -> f32 {
        let n = &self.noise;
        let mut total = 0.0;
        let mut amplitude = 1.0;
        for (o, table) in self.tables.iter().enumerate() {
            let (pu, pv) = (
                (n.cells_u.max(1) << o) as i32,
                (n.cells_v.max(1) << o) as i32,
            );
            let value = match n.kind {
                NoiseKind::Perlin => {
                    perlin_periodic(table, u * pu as f32, v * pv as f32, pu, pv) * 0.5 + 0.5
                }
                NoiseKind::Cellular => cellular_periodic(
                    n.seed.wrapping_add(o as u32),
                    u * pu as f32,
                    v * pv as f32,
                    pu,
                    pv,
                ),
            };
            total += value * amplitude;
            amplitude *= n.gain;
        }
        (total / self.norm).clamp(0.0, 1.0)
    }
}
