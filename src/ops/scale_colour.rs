//! Colour that lives in scales: each scale of a real snake is one field of pigment cells,
//! so it carries its own tone, its rim and its free tip are often lighter or darker than
//! its middle, melanophores sit in it as fine dark specks, and where scales part the skin
//! between them shows its own colour. One pass over the colour map and the scale field
//! does all of it, keyed by scale identity (`channel::CELL_RANDOM`, the same over a whole
//! scale), so a scale's tone never changes inside it and never leaks into its neighbour.
//!
//! Per pixel, in this order (w_s = 1 − crevice, the weight of the scale's own surface):
//!
//! ```text
//! skin     c ← mix(c, skin, crevice)                        where scales part
//! tone     c ← c (1 + tone (2ρ₁ − 1) w_s)                    ρ₁ the scale's random number
//! hue      R ← R (1 + hue (2ρ₂ − 1) w_s), B ← B (1 − …)      warmer or cooler, ρ₂ = hash(ρ₁)
//! rim      c ← c (1 + edge (1 − smoothstep(0, RIM_WIDTH, inside)) w_r)   w_r: below
//! tip      c ← c (1 + tip smoothstep(TIP_START, 1, along) w_s)
//! speckle  c ← mix(c, speckle colour, dot coverage · w_s)
//! ```
//!
//! The rim is the scale's own margin, and the crevice lies over its outer part: a scale's
//! edge falls there to the scale underneath (at the default `edge_softness` the crevice
//! reaches 0.09 of a cell inward, the rim 0.12). Weighted by w_s like the rest, the rim
//! darkened little: at `edge_tone` −1 the darkest pixel kept 0.62 of its colour, and a
//! species whose "scales are edged with black" showed olive edges. So a dark rim counts in
//! full into the crevice, w_r = min(1, w_s / `DARK_RIM_FADE`): only the crevice's last
//! quarter, where the scale meets the gap between scales (w_s = 0, which nothing changes),
//! fades it out, so the outline has no step. A light rim keeps w_r = w_s (in full it undid
//! the groove's shade, `between_scales`), and so does any rim where a `skin` colour is set:
//! the crevice shows that skin. The ventral band (dorsal row 0: the plates) takes its own
//! tone, `belly_edge`, so that a back and a belly are edged apart.
//!
//! Every change is a factor or a mix, so black stays black and a key at 0 leaves the
//! pixel's bytes as they were. The speckle dots lie on a fixed grid of `SPECKLES_PER_SCALE`
//! cells per scale width in both directions (texture space is isotropic), one dot at most
//! per cell, present with probability `speckle`: the same dots at every resolution, and the
//! grid is a whole number of cells per texture, so the map still tiles (a body atlas's rows
//! do not wrap: its two ends take no dots from each other).

use super::hash;
use super::image::{Image, floor_i32, smoothstep};

/// Rim band, in scale-cell widths from the outline inward: about an eighth of a scale's
/// width, the margin that reads as "edged" in photographs of e.g. Natrix or Philodryas.
pub const RIM_WIDTH: f32 = 0.12;
/// A dark rim's weight in the crevice, w_s / this at most 1: in full until the crevice is
/// three quarters deep, then fading to 0 where scales part. (At 1, w_s alone, the rim was
/// lost in the crevice; in full to the end it stepped from black to the gap's colour in one
/// pixel: `a_black_rim_is_black_at_the_outline_and_fades_into_the_gap`.)
pub const DARK_RIM_FADE: f32 = 0.25;
/// The free tip starts this far along the scale (0 anterior, 1 posterior edge).
pub const TIP_START: f32 = 0.7;
/// Speckle grid cells per scale width: melanophore clusters a fraction of a scale across.
pub const SPECKLES_PER_SCALE: u32 = 6;
/// Dot radius in speckle cells.
const DOT_RADIUS: f32 = 0.28;

/// Scale-field channel positions the kernel reads (indices into the scales image). A
/// channel only some keys read is None where they are off, so that `Graph::for_maps` keeps
/// only the field's planes some node reads (a stand-in index 0 kept the height plane, 16 MiB
/// at 2048², for a `--maps color` run that never read it).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct ScaleChannels {
    pub crevice: usize,
    /// Read by `tone` and `hue`.
    pub random: Option<usize>,
    /// Read by `edge` and `belly_edge`.
    pub inside: Option<usize>,
    /// Read by `tip`.
    pub along: Option<usize>,
    /// The dorsal row (0 on the ventral band), read where `edge` and `belly_edge` differ.
    pub row: Option<usize>,
}

#[derive(Debug, Clone, PartialEq)]
pub struct ScaleColour {
    /// Per-scale brightness jitter, ± this fraction.
    pub tone: f32,
    /// Per-scale warm/cool jitter, ± this fraction on red against blue.
    pub hue: f32,
    /// Rim brightening (> 0) or darkening (< 0), −1..1, of the dorsal scales.
    pub edge: f32,
    /// The same for the ventral band's plates and scales (row 0): a species' back and belly
    /// are edged apart ("each smooth dorsal scale edged with black", a "uniformly yellow"
    /// belly; "ventrals red, edged with black").
    pub belly_edge: f32,
    /// Free-tip brightening (> 0) or darkening (< 0), −1..1.
    pub tip: f32,
    /// Fraction of speckle cells that carry a dot, 0..1.
    pub speckle: f32,
    pub speckle_color: [f32; 3],
    /// The skin between scales, where they part; None keeps the colour underneath.
    pub skin: Option<[f32; 3]>,
    /// Speckle grid cells around the texture (= along it): scale columns × SPECKLES_PER_SCALE.
    pub speckle_cells: u32,
    /// Speckle grid cells along the texture (= `speckle_cells` for the square tile).
    pub speckle_cells_v: u32,
    pub seed: u32,
    pub channels: ScaleChannels,
}

impl ScaleColour {
    /// Which scale-field planes the per-scale colour reads besides the crevice, in
    /// `ScaleChannels`' order (random, inside, along, row): the cell's random numbers for
    /// tone and hue, the distance inside the outline for either rim, the position along the
    /// scale for tips, the dorsal row where the back's and the belly's rims differ. The graph
    /// asks here which planes to make (`maps::color`), and `apply` which to read, so a plane
    /// left out is never read (the two once wrote the conditions apart, `> 0` and `!= 0`).
    pub fn reads(tone: f32, hue: f32, edge: f32, belly_edge: f32, tip: f32) -> [bool; 4] {
        [tone != 0.0 || hue != 0.0, edge != 0.0 || belly_edge != 0.0, tip != 0.0, edge != belly_edge]
    }

    /// Applies the per-scale colour to `colour` (linear RGB) with the scale field `scales`.
    /// `frame`: the rows of the texture the images hold.
    pub fn apply(&self, colour: Image, scales: &Image, frame: super::image::Frame) -> Image {
        let (width, height) = (colour.width, frame.full_height);
        let ch = colour.channels;
        let k = self.channels;
        let cells = self.speckle_cells.max(1) as f32;
        let cells_v = self.speckle_cells_v.max(1) as f32;
        // Anti-aliasing band of a dot's edge: one pixel, in speckle cells.
        let aa = cells / width.min(height).max(1) as f32;
        let mut out = colour;
        use rayon::prelude::*;
        out.data.par_chunks_mut(width * ch).enumerate().for_each(|(y, row)| {
            let v = (frame.texture_row(y) as f32 + 0.5) / height as f32;
            // The field is planar (`Image::plane`): this row of the four channels read.
            let field_row = |c: usize| scales.plane_rows(c, y..y + 1);
            // A plane whose keys are off is not read (an empty row: its keys never index it).
            let read = |on: bool, c: Option<usize>| match on {
                true => field_row(c.expect("the per-scale colour's channels include what its keys read")),
                false => &[][..],
            };
            let crevices = field_row(k.crevice);
            let [random, rims, along, dorsal] = Self::reads(self.tone, self.hue, self.edge, self.belly_edge, self.tip);
            let randoms = read(random, k.random);
            let insides = read(rims, k.inside);
            let dorsal_rows = read(dorsal, k.row);
            let alongs = read(along, k.along);
            // The scale's second random number, hashed once per run of pixels of one scale
            // (a scale spans many pixels of a row), not once per pixel.
            let mut second_of: (u32, f32) = (u32::MAX, 0.0);
            for x in 0..width {
                let px = &mut row[x * ch..x * ch + ch.min(3)];
                let crevice = crevices[x].clamp(0.0, 1.0);
                let own = 1.0 - crevice;
                if let Some(skin) = self.skin {
                    for (c, s) in px.iter_mut().zip(skin) {
                        *c += (s - *c) * crevice;
                    }
                }
                if own <= 0.0 {
                    continue;
                }
                let mut gain = [1.0f32; 3];
                if self.tone != 0.0 {
                    let t = 1.0 + self.tone * (2.0 * randoms[x] - 1.0) * own;
                    gain = gain.map(|g| g * t);
                }
                if self.hue != 0.0 {
                    let random = randoms[x];
                    if second_of.0 != random.to_bits() {
                        second_of = (random.to_bits(), hash::unit(random.to_bits() as i32, 0, 7, self.seed));
                    }
                    let second = second_of.1;
                    let warm = self.hue * (2.0 * second - 1.0) * own;
                    gain[0] *= 1.0 + warm;
                    gain[2] *= 1.0 - warm;
                }
                let edge = match dorsal_rows.get(x) {
                    Some(row) if *row == 0.0 => self.belly_edge,
                    _ => self.edge,
                };
                if edge != 0.0 {
                    let rim = 1.0 - smoothstep(0.0, RIM_WIDTH, insides[x]);
                    let dark = edge < 0.0 && self.skin.is_none();
                    let weight = if dark { (own / DARK_RIM_FADE).min(1.0) } else { own };
                    gain = gain.map(|g| g * (1.0 + edge * rim * weight));
                }
                if self.tip != 0.0 {
                    let tip = smoothstep(TIP_START, 1.0, alongs[x]);
                    gain = gain.map(|g| g * (1.0 + self.tip * tip * own));
                }
                for (c, g) in px.iter_mut().zip(gain) {
                    *c *= g;
                }
                if self.speckle > 0.0 {
                    let u = (x as f32 + 0.5) / width as f32;
                    let dot = self.dot(u * cells, v * cells_v, aa, frame.wraps_v) * own;
                    for (c, s) in px.iter_mut().zip(self.speckle_color) {
                        *c += (s - *c) * dot;
                    }
                }
            }
        });
        out
    }

    /// Coverage of the speckle dot near (gx, gy), in grid-cell units. `wraps_v`: the grid's
    /// rows wrap round (the tile); on a body atlas there is no cell above the snout or below
    /// the tail tip, so neither end takes dots from the other.
    fn dot(&self, gx: f32, gy: f32, aa: f32, wraps_v: bool) -> f32 {
        let (n, n_v) = (self.speckle_cells.max(1) as i32, self.speckle_cells_v.max(1) as i32);
        let (cx, cy) = (floor_i32(gx), floor_i32(gy));
        let mut coverage = 0.0f32;
        // A dot is jittered by at most a quarter cell, so it reaches only the 3 × 3 cells.
        for dy in -1..=1 {
            for dx in -1..=1 {
                let (i, j) = (cx + dx, cy + dy);
                if !wraps_v && !(0..n_v).contains(&j) {
                    continue;
                }
                let (wi, wj) = (i.rem_euclid(n), j.rem_euclid(n_v));
                if hash::unit(wi, wj, 0, self.seed) >= self.speckle {
                    continue;
                }
                let ox = i as f32 + 0.5 + 0.25 * hash::signed(wi, wj, 1, self.seed);
                let oy = j as f32 + 0.5 + 0.25 * hash::signed(wi, wj, 2, self.seed);
                let d = ((gx - ox).powi(2) + (gy - oy).powi(2)).sqrt();
                coverage = coverage.max(1.0 - smoothstep(DOT_RADIUS - aa * 0.5, DOT_RADIUS + aa * 0.5, d));
            }
        }
        coverage
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ops::image::Frame;

    /// A white map under a dot in every speckle cell (64 × 64 cells: eight pixels each at
    /// 512²), on a field that is all scale surface.
    fn speckled(frame: Frame) -> Image {
        let (w, h) = (frame.width, frame.height);
        let n = w * h;
        let mut field = vec![0.0f32; 4 * n];
        field[n..2 * n].fill(0.5);
        field[2 * n..].fill(1.0);
        let scales = Image { width: w, height: h, channels: 4, data: field };
        let colour = Image { width: w, height: h, channels: 3, data: vec![1.0; 3 * n] };
        let kernel = ScaleColour {
            tone: 0.0,
            hue: 0.0,
            edge: 0.0,
            belly_edge: 0.0,
            tip: 0.0,
            speckle: 1.0,
            speckle_color: [0.0; 3],
            skin: None,
            speckle_cells: 64,
            speckle_cells_v: 64,
            seed: 7,
            channels: ScaleChannels { crevice: 0, random: Some(1), inside: Some(2), along: Some(3), row: None },
        };
        kernel.apply(colour, &scales, frame)
    }

    #[test]
    fn a_body_atlas_ends_take_no_dots_from_each_other() {
        let size = 512;
        let tile = speckled(Frame::whole(size, size));
        let body = speckled(Frame { wraps_v: false, ..Frame::whole(size, size) });
        // Past the first and last cell rows the two hold the same dots.
        for y in 8..size - 8 {
            assert_eq!(tile.row(y), body.row(y), "row {y}");
        }
        // In the end rows the body lacks the dots of the other end's cells: nowhere darker
        // than the tile, and lighter where a dot reached over the tile's seam. Each end is
        // counted apart, so a fix at one end alone fails it.
        for (end, rows) in [("snout", 0..8), ("tail tip", size - 8..size)] {
            let mut lighter = 0;
            for y in rows {
                for (b, t) in body.row(y).iter().zip(tile.row(y)) {
                    assert!(b >= t, "row {y}: a dot the tile lacks");
                    lighter += usize::from(b > t);
                }
            }
            assert!(lighter > 0, "the body's {end} rows are the tile's: the other end's dots drew on them");
        }
    }
}
