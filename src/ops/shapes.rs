//! Pattern shapes as coverage masks: bands (stripes, the belly) analytically, round spots
//! rasterised with tiny-skia.
//!
//! Colour masks only need 8-bit anti-aliased coverage, which tiny-skia's rasteriser gives
//! exactly and fast; heights need more precision and come from f32 distances in `scales`.
//! Wrap-around: a spot that crosses an edge is drawn again shifted by the image size, so
//! the mask tiles.

use tiny_skia::{FillRule, Mask, PathBuilder, Transform};

use super::hash;
use super::image::Image;

/// Coverage of bands of constant u (running along the body) with smooth edges.
/// `centres` and `half_width` are fractions of the circumference; `softness` likewise.
pub fn bands_u(
    width: usize,
    height: usize,
    centres: &[f32],
    half_width: f32,
    softness: f32,
) -> Image {
    let soft = softness.max(0.5 / width as f32);
    let mut profile = vec![0.0f32; width];
    for (x, value) in profile.iter_mut().enumerate() {
        let u = (x as f32 + 0.5) / width as f32;
        for &c in centres {
            let d = (u - c).rem_euclid(1.0);
            let d = d.min(1.0 - d);
            let t = ((half_width + soft * 0.5 - d) / soft).clamp(0.0, 1.0);
            *value = value.max(t * t * (3.0 - 2.0 * t));
        }
    }
    // Constant along v: every row is the same profile.
    let mut image = Image::new(width, height, 1);
    for row in image.data.chunks_exact_mut(width) {
        row.copy_from_slice(&profile);
    }
    image
}

/// Parameters of a jittered grid of round spots.
#[derive(Debug, Clone, PartialEq)]
pub struct SpotGrid {
    /// Spots around the body per row.
    pub across: u32,
    /// Rows of spots along the body per tile.
    pub along: u32,
    /// Spot radius as a fraction of the circumference.
    pub radius: f32,
    /// Random offset as a fraction of the grid spacing, and random radius change, 0..1.
    pub jitter: f32,
    /// Shift every other row by half a spacing (alternating rather than aligned spots).
    pub alternate: bool,
    pub seed: u32,
}

/// Rasterises the spot grid into an anti-aliased coverage mask in [0, 1].
pub fn spots(width: usize, height: usize, grid: &SpotGrid) -> Image {
    let mut out = Image::new(width, height, 1);
    let Some(mut mask) = Mask::new(width as u32, height as u32) else {
        return out;
    };
    let (w, h) = (width as f32, height as f32);
    let mut pb = PathBuilder::new();
    let (across, along) = (grid.across.max(1), grid.along.max(1));
    for row in 0..along as i32 {
        for col in 0..across as i32 {
            let shift = if grid.alternate && row % 2 == 1 {
                0.5
            } else {
                0.0
            };
            let jx = hash::signed(col, row, 0, grid.seed) * grid.jitter * 0.5;
            let jy = hash::signed(col, row, 1, grid.seed) * grid.jitter * 0.5;
            let jr = 1.0 + hash::signed(col, row, 2, grid.seed) * grid.jitter * 0.5;
            let cu = (col as f32 + 0.5 + shift + jx) / across as f32;
            let cv = (row as f32 + 0.5 + jy) / along as f32;
            let r_px = grid.radius * jr * w;
            // Draw every periodic copy that can touch the tile.
            for oy in [-1.0f32, 0.0, 1.0] {
                for ox in [-1.0f32, 0.0, 1.0] {
                    let (x, y) = ((cu + ox) * w, (cv + oy) * h);
                    if x + r_px >= 0.0 && x - r_px <= w && y + r_px >= 0.0 && y - r_px <= h {
                        pb.push_circle(x, y, r_px.max(0.1));
                    }
                }
            }
        }
    }
    if let Some(path) = pb.finish() {
        mask.fill_path(&path, FillRule::Winding, true, Transform::identity());
    }
    for (o, &m) in out.data.iter_mut().zip(mask.data()) {
        *o = m as f32 / 255.0;
    }
    out
}
