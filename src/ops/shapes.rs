//! Pattern shapes as coverage masks: bands (stripes, the belly) analytically, round spots
//! rasterised with tiny-skia.
//!
//! Colour masks only need 8-bit anti-aliased coverage, which tiny-skia's rasteriser gives
//! exactly and fast; heights need more precision and come from f32 distances in `scales`.
//! Wrap-around: a spot that crosses an edge is drawn again shifted by the image size, so
//! the mask tiles; on a body atlas only round the body (u), never from the tail tip to the
//! snout (`copies_v`).

use tiny_skia::{FillRule, Mask, PathBuilder, Transform};

use super::hash;
use super::image::{Frame, Image};

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Axis {
    /// Bands of constant u: stripes running along the body.
    U,
    /// Bands of constant v: rings around the body.
    V,
}

/// A smooth band profile over samples `range` of `n`: coverage of bands centred on
/// `centres` (fractions of the `n` samples) with half-width `half_width` and edge width
/// `softness`. `periodic`: the samples wrap round (u, and v on a tile), so a band near one end
/// reaches past the other; a body atlas' v does not (a ring at the tail tip drew on the snout).
fn band_profile(
    n: usize,
    range: std::ops::Range<usize>,
    centres: &[f32],
    half_width: f32,
    softness: f32,
    periodic: bool,
) -> Vec<f32> {
    let soft = softness.max(0.5 / n as f32);
    range
        .map(|i| {
            let t = (i as f32 + 0.5) / n as f32;
            centres.iter().fold(0.0f32, |acc, &c| {
                let d = if periodic {
                    let d = (t - c).rem_euclid(1.0);
                    d.min(1.0 - d)
                } else {
                    (t - c).abs()
                };
                let k = ((half_width + soft * 0.5 - d) / soft).clamp(0.0, 1.0);
                acc.max(k * k * (3.0 - 2.0 * k))
            })
        })
        .collect()
}

/// Coverage of bands along one axis with smooth edges; `centres`, `half_width` and
/// `softness` are fractions of the image along that axis.
pub fn bands(frame: Frame, axis: Axis, centres: &[f32], half_width: f32, softness: f32) -> Image {
    let (width, height) = (frame.width, frame.height);
    let mut image = Image::new(width, height, 1);
    match axis {
        Axis::U => {
            let profile = band_profile(width, 0..width, centres, half_width, softness, true);
            for row in image.data.chunks_exact_mut(width) {
                row.copy_from_slice(&profile);
            }
        }
        Axis::V => {
            let rows = frame.row0..frame.row0 + height;
            let profile = band_profile(frame.full_height, rows, centres, half_width, softness, frame.wraps_v);
            for (row, value) in image.data.chunks_exact_mut(width).zip(profile) {
                row.fill(value);
            }
        }
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
    /// Draw only every other cell (a checkerboard).
    pub checkered: bool,
    /// Ring spots: the hole's radius as a fraction of the spot's (0 = solid spots).
    pub hole: f32,
    pub seed: u32,
}

/// Rasterises the spot grid into an anti-aliased coverage mask in [0, 1].
pub fn spots(frame: Frame, grid: &SpotGrid) -> Image {
    let drawn = drawn_rows(frame);
    let (w, h) = (frame.width as f32, frame.full_height as f32);
    let (top, bottom) = (drawn.row0 as f32, (drawn.row0 + drawn.height) as f32);
    let mut pb = PathBuilder::new();
    let (across, along) = (grid.across.max(1), grid.along.max(1));
    for row in 0..along as i32 {
        for col in 0..across as i32 {
            if grid.checkered && (row + col) % 2 == 1 {
                continue;
            }
            let shift = if grid.alternate && row % 2 == 1 { 0.5 } else { 0.0 };
            let jx = hash::signed(col, row, 0, grid.seed) * grid.jitter * 0.5;
            let jy = hash::signed(col, row, 1, grid.seed) * grid.jitter * 0.5;
            let jr = 1.0 + hash::signed(col, row, 2, grid.seed) * grid.jitter * 0.5;
            let cu = (col as f32 + 0.5 + shift + jx) / across as f32;
            let cv = (row as f32 + 0.5 + jy) / along as f32;
            let r_px = grid.radius * jr * w;
            // Draw every periodic copy that can touch the tile.
            for &oy in copies_v(frame) {
                for ox in [-1.0f32, 0.0, 1.0] {
                    let (x, y) = ((cu + ox) * w, (cv + oy) * h);
                    if x + r_px >= 0.0 && x - r_px <= w && y + r_px >= top && y - r_px <= bottom {
                        pb.push_circle(x, y, r_px.max(0.1));
                        if grid.hole > 0.0 {
                            push_hole(&mut pb, x, y, (r_px * grid.hole).max(0.05));
                        }
                    }
                }
            }
        }
    }
    // Non-zero: overlapping spots are their union. Even-odd (before) cut the overlap of two
    // spots out of both, a lens-shaped hole wherever jitter or size made spots touch.
    rasterise(frame, drawn, pb, FillRule::Winding)
}

/// Adds the hole of a ring spot: the circle `push_circle` would add, traced the other way
/// round (its own points, in reverse order), so under the non-zero rule it cancels its spot
/// and nothing else. A spot that overlaps the hole still covers it, and coverage where no
/// spots overlap is the even-odd fill's, to the byte.
fn push_hole(pb: &mut PathBuilder, x: f32, y: f32, r: f32) {
    let Some(circle) = PathBuilder::from_circle(x, y, r) else {
        return;
    };
    // tiny-skia traces a circle as a move and quadratic segments (its conics become quads),
    // then a close: points p0, c1, p1, ..., cn, pn, with pn = p0.
    let points = circle.points();
    use tiny_skia::PathSegment::{Close, MoveTo, QuadTo};
    debug_assert!(circle.segments().all(|s| matches!(s, MoveTo(_) | QuadTo(..) | Close)));
    let last = points.len() - 1;
    pb.move_to(points[last].x, points[last].y);
    for end in (0..last).step_by(2).rev() {
        pb.quad_to(points[end + 1].x, points[end + 1].y, points[end].x, points[end].y);
    }
    pb.close();
}

/// The copies of a shape along v, in textures: a tile repeats, so a shape near one end is
/// drawn again past the other; a body atlas does not (its ends are the snout and the tail
/// tip), and a copy of a spot at the tail tip drew on the snout's first rows.
fn copies_v(frame: Frame) -> &'static [f32] {
    if frame.wraps_v { &[-1.0, 0.0, 1.0] } else { &[0.0] }
}

/// The rows a shape node draws for `frame`: the whole tile when `frame` is a strip of it,
/// else `frame`'s own. tiny-skia's anti-aliased coverage of a pixel can depend on the
/// mask's extent and on the other copies in the path (measured: one 8-bit step at one pixel
/// on the seam of a strip of Crotalus at 256²), so a strip of the tile takes its rows from
/// a mask of the whole tile (one byte per pixel). A body atlas is drawn strip by strip: it
/// is not periodic, and its strips are checked against the whole atlas (`tests/body.rs`).
fn drawn_rows(frame: Frame) -> Frame {
    if frame.wraps_v && frame.height < frame.full_height { Frame::whole(frame.width, frame.full_height) } else { frame }
}

/// Fills the path (in texture pixels) into an anti-aliased coverage mask in [0, 1] over the
/// rows of `frame`, drawing the rows of `drawn` (which hold `frame`'s; all zero if there is
/// nothing to fill or the size is unusable).
fn rasterise(frame: Frame, drawn: Frame, pb: PathBuilder, rule: FillRule) -> Image {
    let (width, height) = (frame.width, frame.height);
    let mut out = Image::new(width, height, 1);
    let (Some(mut mask), Some(path)) = (Mask::new(width as u32, drawn.height as u32), pb.finish()) else {
        return out;
    };
    // Written before tiny-skia reads it: the blitter loads a row's coverage before it stores
    // it, and a fresh page first read maps the shared zero page, so its store then paid a
    // copy-on-write fault with a TLB shootdown (BENCHMARKS.md, "Copy-on-write faults").
    mask.data_mut().fill(0);
    let transform =
        if drawn.row0 == 0 { Transform::identity() } else { Transform::from_translate(0.0, -(drawn.row0 as f32)) };
    mask.fill_path(&path, rule, true, transform);
    let first = (frame.row0 - drawn.row0) * width;
    for (o, &m) in out.data.iter_mut().zip(&mask.data()[first..first + width * height]) {
        *o = m as f32 / 255.0;
    }
    out
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum BlotchShape {
    Round,
    Diamond,
    /// A band over the back reaching down the flanks, with rounded corners.
    Saddle,
    /// A V across the back, its apex on the series' centre line pointing towards the tail
    /// and its arms reaching forward down the sides (a puff adder's "backwardly-directed"
    /// chevrons); the arms are a third of the mark's length thick.
    Chevron,
    /// Narrow at the centre line, wide at its sides: a crossband whose length along the body
    /// at the centre is a third of that at its ends (a copperhead's or a Bitis' hourglass).
    Hourglass,
    /// One continuous band zigzagging along the body about the centre line, `half_width`
    /// to either side; each blotch is one zig and one zag (an adder's dorsal zigzag).
    Zigzag,
}

/// A series of blotches along the body: on the spine (u = 0.5), or two series mirrored
/// at 0.5 ± `offset`, side by side or staggered by half a spacing.
#[derive(Debug, Clone, PartialEq)]
pub struct Blotches {
    pub shape: BlotchShape,
    /// Blotches per tile along the body (per series).
    pub count: u32,
    /// Half-width around the body, fraction of the circumference.
    pub half_width: f32,
    /// Length along the body as a fraction of the spacing between blotches.
    pub length: f32,
    /// Random offset and size change, 0..1.
    pub jitter: f32,
    /// Distance of the series' centre line from the spine, fraction of the circumference;
    /// above 0, two mirrored series.
    pub offset: f32,
    /// The mirrored series shifted by half a spacing (staggered, not paired).
    pub staggered: bool,
    /// Shift of the whole series along the body, in spacings.
    pub phase: f32,
    /// Every blotch scaled about its centre (1 as drawn; a composite mark's centre < 1).
    pub scale: f32,
    /// The stretch of v the `count` blotches are spread over, fractions of the image: (0, 1)
    /// for the tile; the trunk for a counted series of the body layout.
    pub span: (f32, f32),
    /// Half-width of the last blotch of the span over the first's, growing linearly along it
    /// (1: all alike; saddles that widen into bands toward the tail above 1).
    pub widen: f32,
    pub seed: u32,
}

/// Rasterises blotches into an anti-aliased coverage mask (tiny-skia), wrapping along v
/// and around u.
pub fn blotches(frame: Frame, b: &Blotches) -> Image {
    let drawn = drawn_rows(frame);
    let (w, h) = (frame.width as f32, frame.full_height as f32);
    let (top, bottom) = (drawn.row0 as f32, (drawn.row0 + drawn.height) as f32);
    let count = b.count.max(1);
    let spacing = (b.span.1 - b.span.0) * h / count as f32;
    let origin = b.span.0 * h;
    let mut pb = PathBuilder::new();
    let sides: &[(f32, f32)] =
        if b.offset > 0.0 { &[(1.0, 0.0), (-1.0, if b.staggered { 0.5 } else { 0.0 })] } else { &[(0.0, 0.0)] };
    if b.shape == BlotchShape::Zigzag {
        for &(side, shift) in sides {
            zigzag(&mut pb, b, (0.5 + side * b.offset) * w, origin + (b.phase + shift) * spacing, spacing, w, h);
        }
        return rasterise(frame, drawn, pb, FillRule::Winding);
    }
    for i in 0..count as i32 {
        let jx = hash::signed(i, 0, 0, b.seed) * b.jitter * 0.05;
        let jy = hash::signed(i, 0, 1, b.seed) * b.jitter * 0.2;
        let js = (1.0 + hash::signed(i, 0, 2, b.seed) * b.jitter * 0.3) * b.scale;
        let mut hw = b.half_width * js * w;
        if b.widen != 1.0 {
            let t = ((i as f32 + 0.5) / count as f32).clamp(0.0, 1.0);
            hw *= 1.0 + (b.widen - 1.0) * t;
        }
        let hl = 0.5 * b.length * js * spacing;
        for &(side, shift) in sides {
            // The mirrored series mirrors the jitter too, so a pair is symmetric.
            let cx = (0.5 + side * b.offset + if side < 0.0 { -jx } else { jx }) * w;
            for &copy_v in copies_v(frame) {
                let cy = origin + (i as f32 + 0.5 + jy + b.phase + shift) * spacing + copy_v * h;
                for copy_u in [-1.0f32, 0.0, 1.0] {
                    let cx = cx + copy_u * w;
                    if cy + hl < top || cy - hl > bottom || cx + hw < 0.0 || cx - hw > w {
                        continue;
                    }
                    push_blotch(&mut pb, b.shape, cx, cy, hw, hl);
                }
            }
        }
    }
    rasterise(frame, drawn, pb, FillRule::Winding)
}

/// One blotch centred at (cx, cy) pixels with half-width `hw` and half-length `hl`.
fn push_blotch(pb: &mut PathBuilder, shape: BlotchShape, cx: f32, cy: f32, hw: f32, hl: f32) {
    match shape {
        BlotchShape::Round => {
            if let Some(rect) = tiny_skia::Rect::from_xywh(cx - hw, cy - hl, 2.0 * hw, 2.0 * hl) {
                pb.push_oval(rect);
            }
        }
        BlotchShape::Diamond => {
            pb.move_to(cx, cy - hl);
            pb.line_to(cx + hw, cy);
            pb.line_to(cx, cy + hl);
            pb.line_to(cx - hw, cy);
            pb.close();
        }
        BlotchShape::Saddle => {
            // A rounded rectangle: corners of radius min(hw, hl) / 2 as quadratics.
            let r = 0.5 * hw.min(hl);
            let (x0, x1, y0, y1) = (cx - hw, cx + hw, cy - hl, cy + hl);
            pb.move_to(x0 + r, y0);
            pb.line_to(x1 - r, y0);
            pb.quad_to(x1, y0, x1, y0 + r);
            pb.line_to(x1, y1 - r);
            pb.quad_to(x1, y1, x1 - r, y1);
            pb.line_to(x0 + r, y1);
            pb.quad_to(x0, y1, x0, y1 - r);
            pb.line_to(x0, y0 + r);
            pb.quad_to(x0, y0, x0 + r, y0);
            pb.close();
        }
        BlotchShape::Chevron => {
            // Centre line from the arms' front ends (cy − rise) to the apex (cy + rise),
            // thickened by ±t along the body.
            let t = hl / 3.0;
            let rise = hl - t;
            pb.move_to(cx - hw, cy - rise - t);
            pb.line_to(cx, cy + rise - t);
            pb.line_to(cx + hw, cy - rise - t);
            pb.line_to(cx + hw, cy - rise + t);
            pb.line_to(cx, cy + rise + t);
            pb.line_to(cx - hw, cy - rise + t);
            pb.close();
        }
        BlotchShape::Hourglass => {
            let waist = hl / 3.0;
            pb.move_to(cx - hw, cy - hl);
            pb.line_to(cx, cy - waist);
            pb.line_to(cx + hw, cy - hl);
            pb.line_to(cx + hw, cy + hl);
            pb.line_to(cx, cy + waist);
            pb.line_to(cx - hw, cy + hl);
            pb.close();
        }
        BlotchShape::Zigzag => unreachable!("a zigzag is one band, see `zigzag`"),
    }
}

/// A continuous zigzag band about x = `cx`: vertices alternate ±`half_width` every half
/// spacing; the band is `length` spacings thick along the body. Drawn over the
/// tile plus one spacing each end so it wraps along v without a seam.
fn zigzag(pb: &mut PathBuilder, b: &Blotches, cx: f32, start: f32, spacing: f32, w: f32, h: f32) {
    let start = start.rem_euclid(spacing);
    let amplitude = b.half_width * b.scale * w;
    let thick = 0.5 * b.length.clamp(0.05, 1.0) * spacing * b.scale;
    let count = (h / spacing).round() as i32;
    for copy_u in [-1.0f32, 0.0, 1.0] {
        let x0 = cx + copy_u * w;
        if x0 + amplitude + thick < 0.0 || x0 - amplitude - thick > w {
            continue;
        }
        // Each segment a quadrilateral between successive vertices, thickened along v.
        for k in -2..=2 * count + 1 {
            let (ya, yb) = (start + k as f32 * 0.5 * spacing, start + (k + 1) as f32 * 0.5 * spacing);
            let xa = x0 + if k.rem_euclid(2) == 0 { -amplitude } else { amplitude };
            let xb = x0 + if k.rem_euclid(2) == 0 { amplitude } else { -amplitude };
            // Every quadrilateral traced the same way round (clockwise on screen), so that
            // under the nonzero rule the overlaps at the vertices add instead of cancelling
            // (traced alternately, the band broke at every vertex).
            let (xa, ya, xb, yb) = if xb >= xa { (xa, ya, xb, yb) } else { (xb, yb, xa, ya) };
            pb.move_to(xa, ya - thick);
            pb.line_to(xb, yb - thick);
            pb.line_to(xb, yb + thick);
            pb.line_to(xa, ya + thick);
            pb.close();
        }
    }
}

/// What the ventral plates carry (`BellyMarks`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum BellyMarkKind {
    /// A square on the left outer third of every other plate and on the right outer third
    /// of the plates between (corn snakes).
    Checkered,
    /// Scattered dark marks: on each plate, with probability `amount`, one oval at a random
    /// place across it (ball pythons' "scattered black markings").
    Spots,
    /// Half-moons on the plates' free posterior edges, alternating sides, present on each
    /// plate with probability `amount`.
    HalfMoons,
    /// A stripe along the ventral midline, `amount` of the band wide.
    MedianStripe,
}

/// Marks on the ventral plates, aligned with the scale field's plates (the same rows and
/// row phase, `ops::scales::ROW_PHASE`), inside the belly band centred on u = 0.
#[derive(Debug, Clone, PartialEq)]
pub struct BellyMarks {
    pub kind: BellyMarkKind,
    /// Plates per tile (the scale lattice's rows along v).
    pub rows_v: u32,
    /// The body layout's counted plates (then `rows_v` is unused).
    pub body: Option<super::body::BodyPlan>,
    /// The band's width, fraction of the circumference.
    pub belly_width: f32,
    /// Probability per plate (spots, half-moons) or stripe width over the band's (stripe).
    pub amount: f32,
    /// Edge softness, fraction of the circumference.
    pub softness: f32,
    pub seed: u32,
}

pub fn belly_marks(frame: Frame, marks: &BellyMarks) -> Image {
    let (width, height) = (frame.width, frame.full_height);
    let half = marks.belly_width * 0.5;
    let rows = marks.rows_v.max(1) as f32;
    let soft = marks.softness.max(0.5 / width.min(height) as f32);
    // Plate r spans y = v · rows − ROW_PHASE ∈ [r, r + 1); `along` runs 0 → 1 head to tail.
    let phase = super::scales::ROW_PHASE;
    let ramp = |distance_inside: f32| ((distance_inside - 0.3 * soft) / soft).clamp(0.0, 1.0);
    Image::gray_from_fn_in(frame, |u, v| {
        let (side, d) = if u < 0.5 { (0, u) } else { (1, 1.0 - u) };
        if d > half {
            return 0.0;
        }
        // (plate, position along it, its length in circumferences: None on the tile, whose
        // plates are 1 / rows long, written as a division as it always was)
        let (plate, along, plate_len) = match &marks.body {
            None => {
                let y = v * rows - phase;
                let r = super::image::floor_i32(y);
                (r.rem_euclid(marks.rows_v.max(1) as i32), y - r as f32, None)
            }
            Some(body) => match body.plate_at(v) {
                Some(p) => (p.index, p.along, Some(p.length_v * body.length)),
                None => return 0.0,
            },
        };
        // A length in plates, in circumferences.
        let plates = |x: f32| match plate_len {
            None => x / rows,
            Some(len) => x * len,
        };
        // Signed position across the band, −1 (one side's edge) .. 1 (the other's).
        let across = if side == 0 { d / half } else { -d / half };
        let to_ends = plates(along.min(1.0 - along));
        match marks.kind {
            BellyMarkKind::Checkered => {
                // By the wrapped plate index, so the plate across the v seam is one plate
                // (with an odd plate count, the two plates either side of the seam carry
                // their square on the same side).
                if (plate + side).rem_euclid(2) == 1 || d < half / 3.0 {
                    return 0.0;
                }
                ramp(to_ends.min(half - d).min(d - half / 3.0))
            }
            BellyMarkKind::Spots => {
                if super::hash::unit(plate, 0, 0, marks.seed) >= marks.amount {
                    return 0.0;
                }
                // An oval half a plate long, a sixth of the band wide, kept off the seam
                // (u = 0) and the band's edges.
                let centre = 0.2 + 0.65 * super::hash::unit(plate, 0, 1, marks.seed);
                let centre = if super::hash::unit(plate, 0, 2, marks.seed) < 0.5 { centre } else { -centre };
                let (rx, ry) = (half / 6.0, plates(0.25));
                let dx = (across - centre) * half / rx;
                let dy = plates(along - 0.5) / ry;
                let r_norm = (dx * dx + dy * dy).sqrt();
                ramp((1.0 - r_norm) * rx.min(ry))
            }
            BellyMarkKind::HalfMoons => {
                if super::hash::unit(plate, 0, 0, marks.seed) >= marks.amount {
                    return 0.0;
                }
                // A half-disc resting on the plate's posterior edge, on alternate sides.
                let centre = if plate % 2 == 0 { 0.5 } else { -0.5 };
                let radius = plates(0.45).min(half * 0.3);
                let dx = (across - centre) * half;
                let dy = plates(1.0 - along);
                ramp(radius - (dx * dx + dy * dy).sqrt())
            }
            BellyMarkKind::MedianStripe => ramp(marks.amount * half - d),
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(radius: f32, hole: f32) -> SpotGrid {
        SpotGrid { across: 4, along: 4, radius, jitter: 0.0, alternate: false, checkered: false, hole, seed: 7 }
    }

    /// Spots 0.4 of the circumference across, 0.25 apart, cover the whole 64² tile (the
    /// farthest point from every centre, a cell's corner, is 11.3 px from four of them and
    /// the radius is 12.8 px). The even-odd fill left their overlaps empty: a lens where
    /// two met, nothing where four did.
    #[test]
    fn overlapping_spots_are_their_union() {
        let mask = spots(Frame::whole(64, 64), &grid(0.2, 0.0));
        let uncovered = mask.data.iter().filter(|&&c| c < 1.0).count();
        assert_eq!(uncovered, 0, "{uncovered} of 4096 pixels not fully covered");
        // A ring's hole is covered by the rings that overlap it: the first spot's centre
        // (8, 8) lies 16 px from four neighbours (two of them copies across the edges),
        // inside their rings (radius 19.2 px, hole 10.6 px); even-odd counted it six times.
        let rings = spots(Frame::whole(64, 64), &grid(0.3, 0.55));
        assert_eq!(rings.data[8 * 64 + 8], 1.0);
    }

    /// Ring spots that do not overlap are the even-odd fill of a circle and its inner circle,
    /// to the byte: the hole is the same circle traced the other way round.
    #[test]
    fn ring_spots_apart_are_the_even_odd_fill_of_their_circles() {
        let (width, radius, hole) = (64usize, 0.1f32, 0.55f32);
        let mask = spots(Frame::whole(width, width), &grid(radius, hole));
        let mut pb = PathBuilder::new();
        for row in 0..4 {
            for col in 0..4 {
                let (x, y) = ((col as f32 + 0.5) * 16.0, (row as f32 + 0.5) * 16.0);
                pb.push_circle(x, y, radius * width as f32);
                pb.push_circle(x, y, radius * hole * width as f32);
            }
        }
        let frame = Frame::whole(width, width);
        let even_odd = rasterise(frame, frame, pb, FillRule::EvenOdd);
        let differ = mask.data.iter().zip(&even_odd.data).filter(|(a, b)| a != b).count();
        assert_eq!(differ, 0, "{differ} of {} pixels differ from the even-odd fill", width * width);
        // The hole is there: the centre of the first spot (8, 8) is empty, its ring full.
        assert_eq!((mask.data[8 * width + 8], mask.data[8 * width + 13]), (0.0, 1.0));
    }

    /// A body atlas of `width` × `height` (its v does not wrap: snout to tail tip), and the
    /// tile of that size, which does.
    fn body_and_tile(width: usize, height: usize) -> [Frame; 2] {
        [Frame { width, height, full_height: height, row0: 0, wraps_v: false }, Frame::whole(width, height)]
    }

    /// Coverage of the top-left `n` × `n` pixels.
    fn corner(mask: &Image, n: usize) -> f32 {
        (0..n).flat_map(|y| (0..n).map(move |x| (x, y))).map(|(x, y)| mask.data[y * mask.width + x]).sum()
    }

    /// A shape at a body atlas' tail tip stays there: its copy one atlas up drew on the
    /// snout's first rows. Each case has a shape that crosses the last row and nothing else
    /// near the first rows' corner; the tile's copy of it covers that corner (the negative
    /// control: the tile still wraps).
    #[test]
    fn shapes_at_the_tail_tip_do_not_reach_the_snout() {
        // Two alternating rows of spots of radius 38.4 px: the second row's spot centred at
        // (0, 96) reaches 134.4, past the last row; its copy at (0, -32) covered rows 0-6.
        let spots_grid = SpotGrid { across: 1, along: 2, alternate: true, ..grid(0.3, 0.0) };
        // Two blotches centred at rows 64 and 128, 32 rows long each way: the second's copy
        // covered rows 0-31 about the spine.
        let blotch = Blotches {
            shape: BlotchShape::Round,
            count: 2,
            half_width: 0.2,
            length: 1.0,
            jitter: 0.0,
            offset: 0.0,
            staggered: false,
            phase: 0.5,
            scale: 1.0,
            span: (0.0, 1.0),
            widen: 1.0,
            seed: 3,
        };
        // A ring centred at 0.98 of the length, 0.05 wide each way: it wrapped to v < 0.03.
        for (i, frame) in body_and_tile(128, 128).into_iter().enumerate() {
            let spots_corner = corner(&spots(frame, &spots_grid), 4);
            let blotch_top = (0..8).map(|y| blotches(frame, &blotch).data[y * 128 + 64]).sum::<f32>();
            let ring_top = bands(frame, Axis::V, &[0.98], 0.05, 0.01).data[0];
            if i == 0 {
                assert_eq!((spots_corner, blotch_top, ring_top), (0.0, 0.0, 0.0), "the tail tip drew on the snout");
            } else {
                assert!(
                    spots_corner > 8.0 && blotch_top > 4.0 && ring_top > 0.5,
                    "{spots_corner} {blotch_top} {ring_top}"
                );
            }
        }
    }
}
