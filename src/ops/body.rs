//! The whole snake in one texture (the `body` layout): where the head, neck, trunk and tail
//! lie along v, how the ventral and subcaudal plates are counted over them, the head's
//! shields and marks in a head-local frame, and masks that vary along the body.
//!
//! Why a separate module? The scale field (plates, shields), the belly marks (plates) and
//! the colour graph (regions, head marks) must agree on one geometry; it is written here
//! once. The texture stays isotropic: one texture width is one circumference, and the body
//! is `length` widths long, so every kernel keeps its pixel units; what changes is that v
//! runs from the snout (0) to the tail tip (1) instead of repeating.

use super::image::{Frame, Image, floor_i32};

/// The regions and counts of a body atlas, as fractions of the total length (v).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyPlan {
    /// Image height over width: the body's length in circumferences.
    pub length: f32,
    /// End of the head (start of the neck).
    pub head_end: f32,
    /// End of the neck (start of the trunk, where counted dorsal marks begin).
    pub neck_end: f32,
    /// The vent (end of the ventral plates, start of the tail).
    pub vent: f32,
    pub ventrals: u32,
    pub subcaudals: u32,
    /// Large head shields (else small head scales: the body's lattice continues).
    pub head_shields: bool,
    /// Subcaudals in pairs, divided at the midline (most snakes), or single.
    pub divided_subcaudals: bool,
}

/// Where a pixel lies on the belly's plate sequence (`BodyPlan::plate_at`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlatePosition {
    /// Plate index (0 the first ventral; subcaudals continue after the last ventral).
    pub index: i32,
    /// Position along the plate, 0 its anterior end .. 1 its posterior end.
    pub along: f32,
    /// The plate's length in v.
    pub length_v: f32,
    /// A subcaudal (divided at the midline) rather than a ventral.
    pub subcaudal: bool,
}

impl BodyPlan {
    /// Plate coordinate at v: `ventrals` plates from the end of the head to the vent,
    /// `subcaudals` from the vent to the tip; None on the head (chin and throat scales).
    pub fn plate_coordinate(&self, v: f32) -> Option<(f32, f32, bool)> {
        if v < self.head_end {
            None
        } else if v < self.vent {
            let len = self.plate_length_v(false);
            Some(((v - self.head_end) / len, len, false))
        } else {
            let len = self.plate_length_v(true);
            Some((self.ventrals as f32 + (v - self.vent) / len, len, true))
        }
    }

    /// The length in v of a ventral plate (`subcaudal` false) or of a subcaudal.
    #[inline]
    pub fn plate_length_v(&self, subcaudal: bool) -> f32 {
        if subcaudal {
            (1.0 - self.vent) / self.subcaudals.max(1) as f32
        } else {
            (self.vent - self.head_end) / self.ventrals.max(1) as f32
        }
    }

    pub fn plate_at(&self, v: f32) -> Option<PlatePosition> {
        let (y, length_v, subcaudal) = self.plate_coordinate(v)?;
        let index = floor_i32(y);
        Some(PlatePosition { index, along: y - index as f32, length_v, subcaudal })
    }

    /// The v of the centre of plate `index`.
    pub fn plate_centre_v(&self, index: i32) -> f32 {
        let n = self.ventrals as i32;
        if index < n {
            self.head_end + (index as f32 + 0.5) * self.plate_length_v(false)
        } else {
            self.vent + ((index - n) as f32 + 0.5) * self.plate_length_v(true)
        }
    }

    /// One head-local unit in circumferences (the texture's isotropic unit): x across the
    /// top of the head (−1 .. 1 spans the shields, `HEAD_TOP_HALF_U` of the circumference
    /// each side of the spine) and s from the snout tip (0) to the back of the head (1).
    pub fn head_units(&self) -> (f32, f32) {
        (HEAD_TOP_HALF_U, self.head_end * self.length)
    }

    pub fn hash_into<H: std::hash::Hasher>(&self, h: &mut H) {
        use std::hash::Hash;
        (self.ventrals, self.subcaudals, self.head_shields, self.divided_subcaudals).hash(h);
        for x in [self.length, self.head_end, self.neck_end, self.vent] {
            x.to_bits().hash(h);
        }
    }
}

/// Half the width of the head's top (where the shields lie), fraction of the circumference:
/// the top of a snake's head spans roughly the upper 40 % of its girth, the rest being the
/// sides (labials) and the chin.
pub const HEAD_TOP_HALF_U: f32 = 0.2;

/// A head shield: its name, whether it is paired (mirrored about the spine), and its outline.
pub type Shield = (&'static str, bool, &'static [(f32, f32)]);

/// The head shields of a colubrid or elapid head, stylised, as convex polygons in head-local
/// coordinates (x across, −1 .. 1; s from the snout, 0 .. 1), right-hand side only for the
/// paired plates (mirrored). From the snout: rostral, internasals, prefrontals, frontal with
/// the supraoculars beside it, parietals. Neighbouring plates share edges, so the crevice
/// between them is where their outlines meet.
pub const SHIELDS: [Shield; 6] = [
    ("rostral", false, &[(-0.30, 0.0), (0.30, 0.0), (0.36, 0.07), (0.0, 0.12), (-0.36, 0.07)]),
    ("internasal", true, &[(0.0, 0.12), (0.36, 0.07), (0.50, 0.12), (0.46, 0.24), (0.0, 0.24)]),
    ("prefrontal", true, &[(0.0, 0.24), (0.46, 0.24), (0.58, 0.30), (0.50, 0.40), (0.0, 0.40)]),
    ("frontal", false, &[(-0.28, 0.40), (0.28, 0.40), (0.24, 0.60), (0.0, 0.72), (-0.24, 0.60)]),
    ("supraocular", true, &[(0.28, 0.40), (0.50, 0.40), (0.64, 0.44), (0.64, 0.58), (0.24, 0.60)]),
    ("parietal", true, &[(0.0, 0.72), (0.24, 0.60), (0.64, 0.58), (0.66, 0.80), (0.40, 1.0), (0.0, 1.0)]),
];

/// A convex polygon in the texture's isotropic units (circumferences, v scaled by the
/// body's length), with its centre, for the shields' per-pixel distance.
#[derive(Debug, Clone)]
pub struct Plate {
    /// Edge lines as (unit inward normal, offset): inside distance = min(n · p − c).
    edges: Vec<([f32; 2], f32)>,
    /// Centre in texture coordinates (u, v).
    pub centre_uv: (f32, f32),
    /// Extent along v (texture fraction), for a position along the plate.
    pub v_range: (f32, f32),
    pub id: i32,
}

impl Plate {
    /// Distance inside the plate (negative outside), in circumferences, of the point
    /// (x, y) in isotropic units (u, v × length).
    #[inline]
    pub fn inside(&self, x: f32, y: f32) -> f32 {
        self.edges.iter().fold(f32::MAX, |d, (n, c)| d.min(n[0] * x + n[1] * y - c))
    }
}

impl BodyPlan {
    /// Every head shield as a plate in isotropic texture units (mirrored pairs included).
    pub fn shields(&self) -> Vec<Plate> {
        let (ux, us) = self.head_units();
        let mut plates = Vec::new();
        for (id, (_, paired, points)) in SHIELDS.iter().enumerate() {
            let sides: &[f32] = if *paired { &[1.0, -1.0] } else { &[1.0] };
            for (k, side) in sides.iter().enumerate() {
                // To isotropic units: x · ux around the body from the spine, s · us along it.
                let pts: Vec<[f32; 2]> = points.iter().map(|(x, s)| [0.5 + side * x * ux, s * us]).collect();
                let n = pts.len() as f32;
                let centre = pts.iter().fold([0.0, 0.0], |a, p| [a[0] + p[0] / n, a[1] + p[1] / n]);
                let mut edges = Vec::new();
                for i in 0..pts.len() {
                    let (a, b) = (pts[i], pts[(i + 1) % pts.len()]);
                    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
                    let len = (dx * dx + dy * dy).sqrt().max(1e-9);
                    let mut normal = [-dy / len, dx / len];
                    // Point the normal at the centre (mirroring reverses the winding).
                    if normal[0] * (centre[0] - a[0]) + normal[1] * (centre[1] - a[1]) < 0.0 {
                        normal = [-normal[0], -normal[1]];
                    }
                    edges.push((normal, normal[0] * a[0] + normal[1] * a[1]));
                }
                let (lo, hi) = pts.iter().fold((f32::MAX, f32::MIN), |(lo, hi), p| (lo.min(p[1]), hi.max(p[1])));
                let to_v = |y: f32| y / self.length;
                plates.push(Plate {
                    edges,
                    centre_uv: (centre[0], to_v(centre[1])),
                    v_range: (to_v(lo), to_v(hi)),
                    id: (id * 2 + k) as i32,
                });
            }
        }
        plates
    }
}

/// A mark on the head or neck (`body.head_mark`), drawn in head-local coordinates.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum HeadMarkShape {
    Cap,
    Snout,
    V,
    X,
    Spearhead,
    SpearStripes,
    EyeBand,
    CrownBand,
    PreocularStripe,
    PostocularStripe,
    PostocularSpot,
    Collar,
    Crescents,
    Lips,
}

#[derive(Debug, Clone, PartialEq)]
pub struct HeadMark {
    pub shape: HeadMarkShape,
    pub size: f32,
    pub plan: BodyPlan,
    /// The mark lengthened backward by this many of its own widths: a collar's or the
    /// crescents' border (`head_mark.N.border_color`), drawn under the mark itself (0).
    /// Other shapes have no border and ignore it.
    pub behind: f32,
}

/// Half-width of the head's sides down to the lips, fraction of the circumference from the
/// spine: the cap covers this much, the lips lie just below it.
const HEAD_SIDE_HALF_U: f32 = 0.32;

/// The postocular stripe, from behind the eye (at the supraocular's outer edge, `SHIELDS`)
/// to the angle of the jaw, in head-local units (x in shield half-widths across,
/// s in head lengths along); a postocular spot lies on it near the eye.
const POSTOCULAR: ((f32, f32), (f32, f32)) = ((0.62, 0.45), (1.45, 1.0));

/// The half-width of the head's stripes (postocular, preocular, the eye band) at size 1, in
/// shield half-widths: 0.2 across, half the supraocular's width (0.24 to 0.64, `SHIELDS`).
const STRIPE_HALF_WIDTH: f32 = 0.10;

/// Where the eye band crosses the spine: between the eyes, level with them (`POSTOCULAR.0`,
/// where the postocular stripe starts at each eye), so the band runs straight across the
/// frontal between the supraoculars that lie over the eyes (`SHIELDS`). Its halves first met
/// on the prefrontals, in front of the eyes, as the corn snake's source says, but the milk
/// snake's and the puff adder's say "between the eyes", and the chevron joined to the
/// postocular stripes read as a V (a review).
const EYE_BAND_AT_SPINE: (f32, f32) = (0.0, POSTOCULAR.0.1);

/// Where a spearhead's point lies, and the spear stripes meet, in head lengths from the
/// snout: on the prefrontals, in front of the eyes (`SHIELDS`).
const SPEAR_POINT_S: f32 = 0.3;

/// The spear stripes' ends across, in shield half-widths: half a dorsal blotch of a corn
/// snake's preset wide (`size` 0.12 of the circumference) is 0.6, so ends at 0.5 lie inside
/// the first blotch's front where the stripes reach it.
const SPEAR_STRIPES_END_X: f32 = 0.5;

/// Where the crown band crosses the head, in head-local units (as `POSTOCULAR`): across the
/// middle of the parietals (0.60 to 1.0 head lengths back, `SHIELDS`), from the spine to
/// their outer edge there (0.66 across at 0.80), behind the eyes and the eye band. The source
/// names the crown, not where on it; the middle of the top of the head behind the eyes.
const CROWN_BAND: ((f32, f32), (f32, f32)) = ((0.0, 0.80), (0.66, 0.80));

/// Where the preocular stripe starts: the snout, at the rostral's outer corner (`SHIELDS`);
/// it runs to the eye, where the postocular stripe starts (`POSTOCULAR.0`).
const PREOCULAR_START: (f32, f32) = (0.36, 0.07);

/// How far down the postocular stripe a postocular spot is centred: behind the eye, clear of
/// the supraocular shield, which ends 0.60 head lengths back (`SHIELDS`): at size 1 the spot
/// starts 0.64 head lengths back on the test's plan (0.61 at 0.4; at 0.2 it lay beside the
/// supraocular, over the eye, an independent review found).
const POSTOCULAR_SPOT_AT: f32 = 0.45;

/// The postocular spot's centre in head-local units (as `POSTOCULAR`).
fn postocular_spot_centre() -> (f32, f32) {
    let ((ax, a_along), (bx, b_along)) = POSTOCULAR;
    (ax + POSTOCULAR_SPOT_AT * (bx - ax), a_along + POSTOCULAR_SPOT_AT * (b_along - a_along))
}

/// Half the gap at the spine between a grass snake's two crescents (and their border), in
/// circumferences: about one dorsal scale's width at 19 rows (1/19 = 0.053). The sources
/// say "two crescent-shaped spots" and "two black blotches" (presets/natrix-natrix.toml),
/// not how far apart; one scale keeps them two at every map size from 64 px across.
const CRESCENT_HALF_GAP_U: f32 = 0.026;

/// How far down the sides a collar or the crescents reach, from the spine, in
/// circumferences: to the belly's edge, which the belly mask then keeps them off.
const COLLAR_HALF_U: f32 = 0.42;

/// Distance from p to the segment a–b.
fn segment_distance(p: (f32, f32), a: (f32, f32), b: (f32, f32)) -> f32 {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let t = (((p.0 - a.0) * dx + (p.1 - a.1) * dy) / (dx * dx + dy * dy).max(1e-12)).clamp(0.0, 1.0);
    ((p.0 - a.0 - t * dx).powi(2) + (p.1 - a.1 - t * dy).powi(2)).sqrt()
}

impl HeadMark {
    /// The furthest v any shape of this size reaches: only the head and neck can carry a
    /// mark, and rows beyond stay 0 (a spearhead's base, a collar's end, a cap of size k, the
    /// V's arms). A test holds it to `inside` for every shape and size on the built-ins' plans.
    pub fn reach_v(&self) -> f32 {
        let (p, k) = (&self.plan, self.size);
        // A collar reaches 0.7 and the crescents 0.75 of the neck at size 1 (`inside`).
        let neck_marks = p.head_end + 0.75 * k * (1.0 + self.behind) * self.neck_v();
        let head_marks = (p.head_end * (1.3 + 0.6 * k).max(k)).max(neck_marks);
        match self.shape {
            // The stripes' ends and their round caps (twice the cap's radius: at one, f32
            // rounding left the cap's edge a hair inside).
            HeadMarkShape::SpearStripes => {
                head_marks.max(self.spear_stripes_end_v() + 2.0 * STRIPE_HALF_WIDTH * HEAD_TOP_HALF_U / p.length)
            }
            _ => head_marks,
        }
    }

    /// The neck's length in v (at least 0.005: a preset may have none).
    fn neck_v(&self) -> f32 {
        (self.plan.neck_end - self.plan.head_end).max(0.005)
    }

    /// Where the spear stripes end along the body, in v: `size` necks behind the head.
    fn spear_stripes_end_v(&self) -> f32 {
        self.plan.head_end + self.size * self.neck_v()
    }

    /// Signed distance inside the mark at (u, v), in circumferences (positive inside).
    pub fn inside(&self, u: f32, v: f32) -> f32 {
        let p = &self.plan;
        let (ux, us) = p.head_units();
        let k = self.size;
        let du = (u - 0.5).abs();
        // Isotropic head-local point: x and s in circumferences.
        let (x, s) = ((u - 0.5), v * p.length);
        let head = us; // head length in circumferences
        let band = |lo: f32, hi: f32, value: f32| (value - lo).min(hi - value);
        // Segments in head-local units (x in shield half-widths, s in head lengths),
        // mirrored about the spine.
        let arm = |a: (f32, f32), b: (f32, f32), half_width: f32| {
            let q = (du, s);
            let (a, b) = ((a.0 * ux, a.1 * head), (b.0 * ux, b.1 * head));
            half_width * ux - segment_distance(q, a, b)
        };
        match self.shape {
            HeadMarkShape::Cap => band(-1.0, k * head, s).min(HEAD_SIDE_HALF_U - du),
            HeadMarkShape::Snout => band(-1.0, 0.35 * k * head, s).min(HEAD_SIDE_HALF_U - du),
            // Apex forward between the eyes, arms back to the angles of the jaw.
            HeadMarkShape::V => arm((0.0, 0.38), (0.75, 1.1), 0.12 * k),
            HeadMarkShape::X => {
                let d = (x, s);
                let (a, b) = ((-0.55 * ux, 0.35 * head), (0.55 * ux, 1.05 * head));
                let one = segment_distance(d, a, b);
                let two = segment_distance(d, (-a.0, a.1), (-b.0, b.1));
                0.12 * k * ux - one.min(two)
            }
            HeadMarkShape::Spearhead => {
                // A triangle, apex forward between the eyes, base on the neck.
                let apex = SPEAR_POINT_S * head;
                let base = (1.0 + 0.6 * k) * head;
                let half = 0.55 * k * ux;
                let t = ((s - apex) / (base - apex)).clamp(0.0, 1.0);
                (half * t - du).min(s - apex).min(base - s)
            }
            // From the spearhead's apex back to the stripes' ends, mirrored: a point forward.
            HeadMarkShape::SpearStripes => {
                let end = (SPEAR_STRIPES_END_X, self.spear_stripes_end_v() / p.head_end);
                arm((0.0, SPEAR_POINT_S), end, STRIPE_HALF_WIDTH)
            }
            HeadMarkShape::EyeBand => arm(EYE_BAND_AT_SPINE, POSTOCULAR.0, STRIPE_HALF_WIDTH * k),
            HeadMarkShape::CrownBand => arm(CROWN_BAND.0, CROWN_BAND.1, STRIPE_HALF_WIDTH * k),
            HeadMarkShape::PreocularStripe => arm(PREOCULAR_START, POSTOCULAR.0, STRIPE_HALF_WIDTH * k),
            HeadMarkShape::PostocularStripe => arm(POSTOCULAR.0, POSTOCULAR.1, STRIPE_HALF_WIDTH * k),
            // A disc 0.3 shield half-widths across at size 1 (the stripe is 0.2 wide).
            HeadMarkShape::PostocularSpot => {
                let centre = postocular_spot_centre();
                arm(centre, centre, 0.15 * k)
            }
            HeadMarkShape::Collar => {
                let neck = self.neck_v() * p.length;
                band(head, head + 0.7 * k * neck * (1.0 + self.behind), s).min(COLLAR_HALF_U - du)
            }
            // Each side a crescent between the spine's gap and the belly: t runs −1 (at the
            // gap) to 1 (at the belly); its middle lies half its width back from the head
            // and is its thickest (its width), its horns reach forward to the head and thin to
            // 0.4 of it. Distances along s are divided by the edge's slope so the edge is
            // anti-aliased over one pixel where it slants.
            HeadMarkShape::Crescents => {
                let neck = self.neck_v() * p.length;
                let width = 0.5 * k * neck;
                let (mid, half) =
                    (0.5 * (CRESCENT_HALF_GAP_U + COLLAR_HALF_U), 0.5 * (COLLAR_HALF_U - CRESCENT_HALF_GAP_U));
                let t = ((du - mid) / half).clamp(-1.0, 1.0);
                let front = head + 0.5 * width * (1.0 - t * t);
                let back = front + width * (1.0 - 0.6 * t * t) * (1.0 + self.behind);
                // d(front)/d(du) and d(back)/d(du).
                let front_slope = -width * t / half;
                let back_slope = front_slope - width * (1.0 + self.behind) * 1.2 * t / half;
                let along = ((s - front) / (1.0 + front_slope * front_slope).sqrt())
                    .min((back - s) / (1.0 + back_slope * back_slope).sqrt());
                along.min(du - CRESCENT_HALF_GAP_U).min(COLLAR_HALF_U - du)
            }
            HeadMarkShape::Lips => {
                band(0.05 * head, 0.95 * head, s).min(band(HEAD_SIDE_HALF_U - 0.02, HEAD_SIDE_HALF_U + 0.08 * k, du))
            }
        }
    }

    pub fn hash_into<H: std::hash::Hasher>(&self, h: &mut H) {
        use std::hash::Hash;
        self.shape.hash(h);
        self.size.to_bits().hash(h);
        self.plan.hash_into(h);
        self.behind.to_bits().hash(h);
    }
}

/// Coverage of a head mark over the rows of `frame`, anti-aliased over one pixel.
pub fn head_mark(frame: Frame, mark: &HeadMark) -> Image {
    let (width, height) = (frame.width, frame.height);
    // One pixel in circumferences (the texture is isotropic: width = one circumference).
    let pixel = 1.0 / width as f32;
    let last_row = (mark.reach_v() * frame.full_height as f32).ceil() as usize + 2;
    let last = last_row.saturating_sub(frame.row0).min(height);
    let mut image = Image::new(width, height, 1);
    use rayon::prelude::*;
    image.data[..last * width].par_chunks_mut(width).enumerate().for_each(|(y, row)| {
        let v = frame.v(y);
        for (x, out) in row.iter_mut().enumerate() {
            let u = (x as f32 + 0.5) / width as f32;
            *out = (mark.inside(u, v) / pixel + 0.5).clamp(0.0, 1.0);
        }
    });
    image
}

/// A mask that varies along the body only: piecewise linear through `knots` (v, value),
/// constant beyond the first and last (region masks, colour ramps, tail bands).
#[derive(Debug, Clone, PartialEq)]
pub struct AlongProfile {
    pub knots: Vec<(f32, f32)>,
}

impl AlongProfile {
    pub fn value(&self, v: f32) -> f32 {
        let k = &self.knots;
        let Some(first) = k.first() else { return 0.0 };
        if v <= first.0 {
            return first.1;
        }
        let i = k.partition_point(|(kv, _)| *kv <= v);
        if i >= k.len() {
            return k[k.len() - 1].1;
        }
        let ((v0, a), (v1, b)) = (k[i - 1], k[i]);
        if v1 <= v0 { b } else { a + (b - a) * (v - v0) / (v1 - v0) }
    }

    pub fn render(&self, frame: Frame) -> Image {
        let mut image = Image::new(frame.width, frame.height, 1);
        for (y, row) in image.data.chunks_exact_mut(frame.width).enumerate() {
            row.fill(self.value(frame.v(y)));
        }
        image
    }

    pub fn hash_into<H: std::hash::Hasher>(&self, h: &mut H) {
        use std::hash::Hash;
        self.knots.len().hash(h);
        for (v, x) in &self.knots {
            v.to_bits().hash(h);
            x.to_bits().hash(h);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plan() -> BodyPlan {
        BodyPlan {
            length: 12.0,
            head_end: 0.04,
            neck_end: 0.07,
            vent: 0.82,
            ventrals: 200,
            subcaudals: 60,
            head_shields: true,
            divided_subcaudals: true,
        }
    }

    #[test]
    fn shields_are_convex_and_do_not_overlap() {
        // Convex: every vertex of a plate lies inside (or on) every edge line of it.
        for (name, _, pts) in SHIELDS {
            let n = pts.len();
            let mut sign = 0.0f32;
            for i in 0..n {
                let (a, b, c) = (pts[i], pts[(i + 1) % n], pts[(i + 2) % n]);
                let cross = (b.0 - a.0) * (c.1 - b.1) - (b.1 - a.1) * (c.0 - b.0);
                assert!(cross * sign >= 0.0, "{name} is not convex at vertex {}", i + 1);
                if cross != 0.0 {
                    sign = cross.signum();
                }
            }
        }
        // No point lies well inside two plates.
        let plates = plan().shields();
        for i in 0..200 {
            for j in 0..200 {
                let (x, y) = (0.3 + 0.4 * i as f32 / 200.0, 0.48 * j as f32 / 200.0);
                let inside = plates.iter().filter(|p| p.inside(x, y) > 1e-4).count();
                assert!(inside <= 1, "({x}, {y}) lies in {inside} plates");
            }
        }
    }

    #[test]
    fn plates_are_counted_from_the_head_to_the_tip() {
        let p = plan();
        assert_eq!(p.plate_at(0.01), None);
        assert_eq!(p.plate_at(0.0401).unwrap().index, 0);
        assert_eq!(p.plate_at(0.8199).unwrap().index, 199);
        let first_sub = p.plate_at(0.8201).unwrap();
        assert_eq!((first_sub.index, first_sub.subcaudal), (200, true));
        assert_eq!(p.plate_at(0.99999).unwrap().index, 259);
        assert!((p.plate_centre_v(0) - (0.04 + 0.5 * 0.78 / 200.0)).abs() < 1e-6);
    }

    /// No shape reaches past `reach_v`, beyond which `head_mark` draws nothing: every shape
    /// at the smallest, default and largest sizes, on every built-in's plan and at the
    /// shortest and longest head and body, sampled every 1/200 of the circumference over the
    /// fifth of the body's length past `reach_v` (every 1/2000 of it). Negative control: a
    /// reach a tenth shorter is passed by some shape.
    #[test]
    fn no_head_mark_reaches_past_its_reach() {
        use crate::preset::validate::ranges::{BODY_LENGTH, HEAD_FRACTION, HEAD_MARK_SIZE};
        let mut plans: Vec<BodyPlan> = crate::preset::library::all()
            .iter()
            .map(|(name, _)| crate::maps::body_plan(&crate::preset::load(name, &[], None).unwrap().preset))
            .collect();
        for (head, length) in [(HEAD_FRACTION.0, BODY_LENGTH.0), (HEAD_FRACTION.1, BODY_LENGTH.1)] {
            let set =
                [("body.head_fraction".to_string(), head.to_string()), ("body.length".into(), length.to_string())];
            plans.push(crate::maps::body_plan(&crate::preset::load("natrix-natrix", &set, None).unwrap().preset));
        }
        let shapes = [
            HeadMarkShape::Cap,
            HeadMarkShape::Snout,
            HeadMarkShape::V,
            HeadMarkShape::X,
            HeadMarkShape::Spearhead,
            HeadMarkShape::SpearStripes,
            HeadMarkShape::EyeBand,
            HeadMarkShape::CrownBand,
            HeadMarkShape::PreocularStripe,
            HeadMarkShape::PostocularStripe,
            HeadMarkShape::PostocularSpot,
            HeadMarkShape::Collar,
            HeadMarkShape::Crescents,
            HeadMarkShape::Lips,
        ];
        let reached = |scale: f32| {
            let mut reached = 0;
            for plan in &plans {
                for shape in shapes {
                    for (size, behind) in [HEAD_MARK_SIZE.0, 1.0, HEAD_MARK_SIZE.1]
                        .into_iter()
                        .flat_map(|size| [(size, 0.0), (size, HEAD_MARK_SIZE.1)])
                    {
                        let (size, behind) = (size as f32, behind as f32);
                        let mark = HeadMark { shape, size, plan: *plan, behind };
                        let from = mark.reach_v() * scale;
                        let beyond = (0..400).map(|j| (from + 0.2 * j as f32 / 400.0).min(1.0));
                        reached += beyond
                            .flat_map(|v| (0..200).map(move |i| (i as f32 / 200.0, v)))
                            .any(|(u, v)| mark.inside(u, v) > 0.0) as usize;
                    }
                }
            }
            reached
        };
        assert_eq!(reached(1.0), 0, "a shape reaches past reach_v");
        assert!(reached(0.9) > 0, "the control: a tenth less is passed");
    }

    /// Pixels of a head mark on `plan()`'s head, 512 across: each side's count, each side's
    /// extent across (u) and along (v · length), in circumferences, and its first v.
    fn mark_sides(shape: HeadMarkShape) -> [(usize, f32, f32, f32); 2] {
        let mark = HeadMark { shape, size: 1.0, plan: plan(), behind: 0.0 };
        let n = 512;
        let rows = (mark.reach_v() * n as f32 * mark.plan.length).ceil() as usize;
        [false, true].map(|right| {
            let (mut count, mut u_range, mut v_range) = (0, (f32::MAX, f32::MIN), (f32::MAX, f32::MIN));
            for y in 0..rows {
                let v = (y as f32 + 0.5) / (n as f32 * mark.plan.length);
                for x in 0..n {
                    let u = (x as f32 + 0.5) / n as f32;
                    if (u > 0.5) == right && mark.inside(u, v) > 0.0 {
                        count += 1;
                        u_range = (u_range.0.min(u), u_range.1.max(u));
                        v_range = (v_range.0.min(v), v_range.1.max(v));
                    }
                }
            }
            (count, u_range.1 - u_range.0, (v_range.1 - v_range.0) * mark.plan.length, v_range.0)
        })
    }

    #[test]
    fn a_postocular_spot_is_round_and_sits_on_the_stripe_on_each_side() {
        let spot = mark_sides(HeadMarkShape::PostocularSpot);
        let [(left, across, along, first_v), (right, ..)] = spot;
        assert!(left > 20 && left == right, "one spot a side, mirrored: {left} and {right} px");
        assert!((across / along - 1.0).abs() < 0.1, "round: {across} across, {along} along");
        // On the stripe's line and much smaller than it.
        let stripe = HeadMark { shape: HeadMarkShape::PostocularStripe, size: 1.0, plan: plan(), behind: 0.0 };
        let spot_mark = HeadMark { shape: HeadMarkShape::PostocularSpot, size: 1.0, plan: plan(), behind: 0.0 };
        let (ux, head) = plan().head_units();
        let (spot_x, spot_along) = postocular_spot_centre();
        let centre = (0.5 + spot_x * ux, spot_along * head / plan().length);
        assert!(spot_mark.inside(centre.0, centre.1) > 0.0 && stripe.inside(centre.0, centre.1) > 0.0);
        // Behind the eye: no part of it beside the supraocular shield, over the eye.
        let (_, _, supraocular) = SHIELDS.iter().find(|(name, ..)| *name == "supraocular").unwrap();
        let supraocular_back = supraocular.iter().map(|p| p.1).fold(0.0, f32::max);
        let first = first_v * plan().length / head;
        assert!(
            first > supraocular_back,
            "the spot starts {first} head lengths back, the supraocular ends at {supraocular_back}"
        );
        let [(stripe_px, stripe_across, stripe_along, _), _] = mark_sides(HeadMarkShape::PostocularStripe);
        assert!(left * 3 < stripe_px, "a spot, not a stripe: {left} px against the stripe's {stripe_px}");
        // The control: the stripe itself is not round.
        assert!((stripe_across / stripe_along - 1.0).abs() > 0.1, "{stripe_across} across, {stripe_along} along");
    }

    /// The pixels of a head mark on `plan`'s head at `size`, 512 across, as head-local points
    /// (x in shield half-widths, signed; s in head lengths).
    fn mark_points(shape: HeadMarkShape, plan: BodyPlan, size: f32) -> Vec<(f32, f32)> {
        let mark = HeadMark { shape, size, plan, behind: 0.0 };
        let (ux, head) = mark.plan.head_units();
        let n = 512;
        let rows = (mark.reach_v() * n as f32 * mark.plan.length).ceil() as usize;
        let mut points = Vec::new();
        for y in 0..rows {
            let v = (y as f32 + 0.5) / (n as f32 * mark.plan.length);
            for x in 0..n {
                let u = (x as f32 + 0.5) / n as f32;
                if mark.inside(u, v) > 0.0 {
                    points.push(((u - 0.5) / ux, v * mark.plan.length / head));
                }
            }
        }
        points
    }

    /// The eye band crosses the spine between the eyes (its crossing centred within the
    /// supraoculars' length, the shields over the eyes) and the preocular stripe starts on
    /// the snout (within the rostral's length); each shares pixels with the postocular
    /// stripe on both sides, so that drawn together they are one line through the eye. On
    /// every built-in species' plan, at the smallest, default and largest sizes. Negative
    /// controls: the postocular stripe alone has no pixel on the spine and none on the snout;
    /// the spot behind the eye, a mark of the same line, does not meet the preocular stripe.
    #[test]
    fn the_eye_band_and_the_preocular_stripe_meet_the_postocular_stripe_at_the_eye() {
        use crate::preset::validate::ranges::HEAD_MARK_SIZE;
        let extent = |name: &str| {
            let (_, _, points) = SHIELDS.iter().find(|(n, ..)| *n == name).unwrap();
            points.iter().fold((f32::MAX, f32::MIN), |(lo, hi), p| (lo.min(p.1), hi.max(p.1)))
        };
        let (supraocular, rostral) = (extent("supraocular"), extent("rostral"));
        // The two columns beside the spine (512 across; x in shield half-widths).
        let on_spine = |points: &[(f32, f32)]| -> Vec<f32> {
            points.iter().filter(|p| p.0.abs() < 1.0 / 512.0 / HEAD_TOP_HALF_U).map(|p| p.1).collect()
        };
        let shared = |a: &[(f32, f32)], b: &[(f32, f32)], right: bool| {
            a.iter().filter(|p| (p.0 > 0.0) == right && b.contains(p)).count()
        };
        let plans = crate::preset::library::all()
            .iter()
            .map(|(name, _)| crate::maps::body_plan(&crate::preset::load(name, &[], None).unwrap().preset));
        for plan in plans {
            for size in [HEAD_MARK_SIZE.0 as f32, 1.0, HEAD_MARK_SIZE.1 as f32] {
                let band = mark_points(HeadMarkShape::EyeBand, plan, size);
                let spine = on_spine(&band);
                let (lo, hi) = spine.iter().fold((f32::MAX, f32::MIN), |(lo, hi), &s| (lo.min(s), hi.max(s)));
                let centre = 0.5 * (lo + hi);
                assert!(
                    !spine.is_empty() && centre > supraocular.0 && centre < supraocular.1,
                    "size {size}, head {}: the band crosses the spine at {lo}..{hi}, the supraoculars span {supraocular:?}",
                    plan.head_end * plan.length
                );
                let pre = mark_points(HeadMarkShape::PreocularStripe, plan, size);
                let front = pre.iter().map(|p| p.1).fold(f32::MAX, f32::min);
                assert!(front < rostral.1, "size {size}: the preocular stripe starts {front} head lengths back");
                let post = mark_points(HeadMarkShape::PostocularStripe, plan, size);
                for right in [false, true] {
                    assert!(shared(&band, &post, right) > 0, "size {size}: the band meets the stripe ({right})");
                    assert!(shared(&pre, &post, right) > 0, "size {size}: the preocular meets the stripe ({right})");
                }
                // The controls.
                assert!(on_spine(&post).is_empty());
                assert!(post.iter().all(|p| p.1 > rostral.1));
                let spot = mark_points(HeadMarkShape::PostocularSpot, plan, size);
                assert_eq!(shared(&spot, &pre, true) + shared(&spot, &pre, false), 0);
            }
        }
    }

    #[test]
    fn along_profile_interpolates_and_holds_its_ends() {
        let p = AlongProfile { knots: vec![(0.2, 0.0), (0.4, 1.0), (0.4, 0.0)] };
        assert_eq!(p.value(0.0), 0.0);
        assert!((p.value(0.3) - 0.5).abs() < 1e-6);
        assert_eq!(p.value(0.5), 0.0);
    }
}
