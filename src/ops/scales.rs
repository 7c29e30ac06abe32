//! The scale field: one pass over a periodic, staggered lattice of scales that yields every
//! per-pixel quantity the maps need (height, crevice, position on the scale, keel, identity).
//!
//! Why one multi-channel node instead of one per map? Finding the visible scale means testing
//! the pixel against the neighbouring scales (up to nine; `Sweep` tests the one or two whose
//! outline reaches it); height, roughness, iridescence and colour all need the answer, so the
//! graph computes it once and the maps read channels of it.
//!
//! Geometry (texture space per DESIGN.md: u around the body, v head to tail):
//! - `rows` columns of scales around the body (the dorsal scale rows), `cells_v` along it.
//!   Column c is shifted along v by `c * k / rows` cells with `k ≈ rows / 2`, which staggers
//!   neighbouring columns by about half a scale (interleaved rows, thesis §4.2.2 "Tiling")
//!   while keeping the lattice exactly periodic for odd row counts too.
//! - Leaf (two intersecting circles, thesis Fig. 4.8) and diamond scales overlap like roof
//!   tiles: each scale's height rises towards its free posterior edge, and the visible surface
//!   is the highest candidate, so a scale's posterior edge lies over the anterior part of the
//!   scale behind it. Hexagons tile without overlap (the Voronoi cells of the lattice).
//! - In the belly band (centred on u = 0 ≡ 1) one wide ventral plate spans each row.
//!
//! Per-cell jitter (position, size, rotation) is drawn once per cell into a table, so the
//! per-pixel loop does lookups, not hashing.

use super::body::{BodyPlan, HEAD_TOP_HALF_U, Plate};
use super::hash;
use rayon::prelude::*;

use super::image::{Image, floor_i32, smoothstep};

/// Channel layout of the scale field.
pub mod channel {
    /// Surface height in [0, 1], 0 the skin between scales.
    pub const HEIGHT: usize = 0;
    /// 1 in the crevices between scales, 0 on a scale's body.
    pub const CREVICE: usize = 1;
    /// Position along the visible scale, 0 at its anterior tip, 1 at its posterior edge.
    pub const ALONG: usize = 2;
    /// Normalised distance from the visible scale's centre, 0 centre .. 1 rim.
    pub const RADIAL: usize = 3;
    /// Keel ridge strength in [0, 1].
    pub const KEEL: usize = 4;
    /// A uniform random number per scale (the same over the whole scale).
    pub const CELL_RANDOM: usize = 5;
    /// Texture coordinates of the visible scale's centre (for colour that follows scales).
    pub const CENTRE_U: usize = 6;
    pub const CENTRE_V: usize = 7;
    /// Distance inside the visible scale's outline, in scale-cell widths (0 off every
    /// scale): how far a pixel lies from its scale's edge, for lighter or darker rims.
    pub const INSIDE: usize = 8;
    /// Dorsal scale row of the visible scale, 1 the lowest (next to the ventral plates),
    /// (rows + 1) / 2 the vertebral row; 0 on the ventral plates and between scales.
    pub const ROW: usize = 9;
    pub const COUNT: usize = 10;
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ScaleShape {
    Leaf,
    Diamond,
    Hexagon,
}

#[derive(Debug, Clone, PartialEq)]
pub struct ScaleField {
    pub shape: ScaleShape,
    /// Scale columns around the body (dorsal scale rows).
    pub rows: u32,
    /// Cell length along the body over cell width around it.
    pub aspect: f32,
    /// Scale size relative to its cell; above 1 neighbours overlap.
    pub size: f32,
    pub keel_height: f32,
    /// Keel half-width as a fraction of the scale width.
    pub keel_width: f32,
    /// Random offset, size and rotation per scale, 0..0.5.
    pub jitter: f32,
    /// How far the posterior edge is raised over the anterior tip, 0..1.
    pub imbrication: f32,
    /// Width of the rounded rim of each scale, in scale widths.
    pub edge_softness: f32,
    /// Width of the ventral band as a fraction of the circumference; 0 disables plates.
    /// The band is rounded to whole scale columns (`Lattice`), so exactly `rows` dorsal rows
    /// lie between its edges.
    pub belly_width: f32,
    /// Width of the vertebral row (the row on the spine) relative to the others, ≥ 1.
    pub vertebral_width: f32,
    /// Width of the lowest dorsal row (next to the ventral plates) relative to the others.
    pub lowest_row_width: f32,
    /// The lowest this many dorsal rows carry no keel.
    pub smooth_rows: u32,
    pub seed: u32,
    /// The texture's extent along the body in circumferences (its height over its width):
    /// 1 for the tile, the body's length for the body layout.
    pub length: f32,
    /// The body layout's regions and plate counts (None: the tile, plates one per lattice row).
    pub body: Option<BodyPlan>,
    /// Which `channel`s the node outputs, in order (memory: 4 bytes per pixel each, so the
    /// graph asks only for those its maps read).
    pub outputs: Vec<usize>,
}

/// The lattice's layout derived from the parameters.
///
/// Columns run around the body: the ventral band (centred on u = 0, an even number
/// `belly_cols` of columns, one plate per row across them) and exactly `rows` dorsal columns
/// between its edges, so `rows` means what a herpetologist counts: the dorsal scale rows
/// from one side's ventrals to the other's. With an odd row count the vertebral row is
/// centred on the spine (u = 0.5). Columns may differ in width (an enlarged vertebral row, a
/// wider lowest row): `bounds` holds each column's left edge in u, and lattice x is u warped
/// piecewise linearly through them, so a wider column holds wider scales.
#[derive(Debug, Clone)]
pub struct Lattice {
    pub cols: i32,
    pub rows_v: i32,
    /// Column c is shifted by c * stagger / cols cells along v.
    pub stagger: i32,
    /// Actual cell length / width after rounding `rows_v` to an integer.
    pub aspect: f32,
    /// Columns of the ventral band (even; 0 without plates).
    pub belly_cols: i32,
    /// u of every column edge, cols + 1 entries from 0 to 1.
    pub bounds: Vec<f32>,
    uniform: bool,
}

impl Lattice {
    /// The v of the centre of row r of column 0 (the tile's ventral plate r), unjittered:
    /// v · rows_v = r + 0.5 + `ROW_PHASE`. About it (and every v half a row from it) the
    /// ventral plates, one per row across the belly band, are mirror-symmetric; the dorsal
    /// columns are symmetric under the mirror in v combined with the one about the belly's
    /// midline (u ↦ −u, a half turn): column c's centres lie at v · rows_v =
    /// r + 0.5 + ROW_PHASE + c · stagger / cols (`ScaleField::centre`), and the mirror in v
    /// maps them onto column −c's. So a band and its mirror image cover as many plates, and
    /// as many dorsal scales in all (not column by column). The scales' jitter is not mirrored.
    pub fn row_centre_v(&self, r: i32) -> f32 {
        v_of_row_y(r as f32 + 0.5, self.rows_v as f32)
    }

    /// Lattice y of texture v: row r (the tile's plate r) spans y ∈ [r, r + 1).
    #[inline]
    pub fn row_y(&self, v: f32) -> f32 {
        row_y(v, self.rows_v as f32)
    }

    /// The ventral band's width, fraction of the circumference (whole columns).
    pub fn belly_width(&self) -> f32 {
        2.0 * self.bounds[(self.belly_cols / 2) as usize]
    }

    /// Dorsal row of column `c` (any integer; wrapped): 1 the lowest, 0 in the ventral band.
    #[inline]
    pub fn row_of(&self, c: i32) -> i32 {
        // The callers pass columns at most one period out: a branch, not a division.
        let c = if (0..self.cols).contains(&c) { c } else { c.rem_euclid(self.cols) };
        let half = self.belly_cols / 2;
        if c < half || c >= self.cols - half {
            return 0;
        }
        (c - half).min(self.cols - half - 1 - c) + 1
    }

    /// Lattice x (columns) of texture u in [0, 1).
    #[inline]
    pub fn x_of(&self, u: f32) -> f32 {
        if self.uniform {
            return u * self.cols as f32;
        }
        let c = (self.bounds.partition_point(|b| *b <= u).max(1) - 1).min(self.cols as usize - 1);
        let (a, b) = (self.bounds[c], self.bounds[c + 1]);
        c as f32 + (u - a) / (b - a)
    }

    /// Texture u of lattice x (any real; wrapped into [0, 1)).
    #[inline]
    pub fn u_of(&self, x: f32) -> f32 {
        let n = self.cols as f32;
        // Per pixel, x lies at most one period out: wrap by a branch (`rem_euclid` on f32 is
        // a libm call).
        let x = if x < 0.0 {
            x + n
        } else if x >= n {
            x - n
        } else {
            x
        };
        let x = if (0.0..n).contains(&x) { x } else { x.rem_euclid(n) };
        if self.uniform {
            return (x / n).min(1.0 - f32::EPSILON);
        }
        let c = (x as usize).min(self.cols as usize - 1);
        let (a, b) = (self.bounds[c], self.bounds[c + 1]);
        (a + (x - c as f32) * (b - a)).min(1.0 - f32::EPSILON)
    }

    /// The u range, on the side u > 0.5, from the start of dorsal row `first` to the end of
    /// row `last` (1 the lowest; fractions reach into a row, 0.5 its middle); mirrored, the
    /// same rows on the other side span 1 − that range.
    pub fn row_span_u(&self, first: f32, last: f32) -> (f32, f32) {
        // Row k on the far side is column cols − half − k (its left edge).
        let half = (self.belly_cols / 2) as f32;
        let x_of_row_edge = |k: f32| self.cols as f32 - half - k + 1.0;
        let (x0, x1) = (x_of_row_edge(last + 1.0), x_of_row_edge(first));
        let u = |x: f32| if x >= self.cols as f32 { 1.0 } else { self.u_of(x) };
        (u(x0), u(x1))
    }
}

/// Guards of a field built without the loader (tests, the gallery), each wider than its
/// preset key's range (`preset::validate::ranges`, which asserts it, so a range widened past a
/// guard fails to compile rather than being cut silently): the narrowest row a vertebral or
/// lowest row can be (`ROW_WIDTH`), the widest belly (`BELLY_WIDTH`; 1 leaves no dorsal
/// rows), the softest-edge floor (`EDGE_SOFTNESS`; 0 divides by zero), and `JITTER_MAX`.
pub(crate) const ROW_WIDTH_FLOOR: f32 = 0.1;
pub(crate) const BELLY_WIDTH_CEILING: f32 = 0.9;
pub(crate) const EDGE_SOFTNESS_FLOOR: f32 = 1e-4;

impl ScaleField {
    /// `edge_softness`, kept off zero (`EDGE_SOFTNESS_FLOOR`).
    fn softness(&self) -> f32 {
        self.edge_softness.max(EDGE_SOFTNESS_FLOOR)
    }

    pub fn lattice(&self) -> Lattice {
        let rows = self.rows.max(1) as i32;
        // Relative width of each dorsal row, 1 the lowest.
        let vertebral = (rows % 2 == 1).then_some((rows + 1) / 2);
        let width_of_row = |k: i32| {
            if Some(k) == vertebral {
                self.vertebral_width.max(ROW_WIDTH_FLOOR)
            } else if k == 1 {
                self.lowest_row_width.max(ROW_WIDTH_FLOOR)
            } else {
                1.0
            }
        };
        let dorsal: f32 = (1..=rows).map(|k| width_of_row(k.min(rows + 1 - k))).sum();
        let belly_cols = if self.belly_width > 0.0 {
            // Even, at least 2: an equal number of plate columns each side of u = 0.
            let bw = self.belly_width.min(BELLY_WIDTH_CEILING);
            2 * ((dorsal * bw / (2.0 * (1.0 - bw))).round() as i32).max(1)
        } else {
            0
        };
        let cols = rows + belly_cols;
        let half = belly_cols / 2;
        let widths: Vec<f32> =
            (0..cols)
                .map(|c| {
                    if c < half || c >= cols - half {
                        1.0
                    } else {
                        width_of_row((c - half).min(cols - half - 1 - c) + 1)
                    }
                })
                .collect();
        let uniform = widths.iter().all(|w| *w == 1.0);
        let total: f32 = widths.iter().sum();
        let mut bounds = Vec::with_capacity(cols as usize + 1);
        let mut acc = 0.0f32;
        for w in &widths {
            bounds.push(if uniform { bounds.len() as f32 / cols as f32 } else { acc / total });
            acc += w;
        }
        bounds.push(1.0);
        // The cell aspect is that of an ordinary (width 1) column, 1 / total of u wide; the
        // texture is `length` circumferences long.
        let rows_v = ((total / self.aspect * self.length).round() as i32).max(1);
        let stagger = cols / 2;
        Lattice { cols, rows_v, stagger, aspect: total * self.length / rows_v as f32, belly_cols, bounds, uniform }
    }
}

#[derive(Clone, Copy)]
struct CellJitter {
    dx: f32,
    dy: f32,
    cos: f32,
    sin: f32,
    inv_size: f32,
    random: f32,
}

struct CellTable {
    cells: Vec<CellJitter>,
    cols: i32,
}

/// What `jitter` (at most `JITTER_MAX`) moves per unit: a cell's centre up to ±`JITTER_OFFSET`
/// cells each way, its outline's angle up to ±`JITTER_ANGLE_RAD`, its size up to
/// ±`JITTER_SIZE` of itself (`CellTable`; `longest_reach_cells` bounds what they reach).
pub(crate) const JITTER_MAX: f32 = 0.5;
const JITTER_OFFSET: f32 = 0.5;
const JITTER_ANGLE_RAD: f32 = 0.6;
const JITTER_SIZE: f32 = 0.4;

impl CellTable {
    fn new(field: &ScaleField, lattice: &Lattice) -> Self {
        let j = field.jitter.clamp(0.0, JITTER_MAX);
        let mut cells = Vec::with_capacity((lattice.cols * lattice.rows_v) as usize);
        for r in 0..lattice.rows_v {
            for c in 0..lattice.cols {
                let s = field.seed;
                let angle = hash::signed(c, r, 2, s) * j * JITTER_ANGLE_RAD;
                let size = field.size * (1.0 + hash::signed(c, r, 3, s) * j * JITTER_SIZE);
                cells.push(CellJitter {
                    dx: hash::signed(c, r, 0, s) * j * JITTER_OFFSET,
                    dy: hash::signed(c, r, 1, s) * j * JITTER_OFFSET,
                    cos: angle.cos(),
                    sin: angle.sin(),
                    inv_size: 1.0 / size.max(0.05),
                    random: hash::unit(c, r, 4, s),
                });
            }
        }
        CellTable { cells, cols: lattice.cols }
    }
}

/// One candidate scale evaluated at a pixel, in the scale's own frame (units: scale widths).
struct Candidate {
    /// Distance inside the outline (negative outside).
    inside: f32,
    /// Local position: across (x) and along the body (y, towards the tail), unit = size.
    x: f32,
    y: f32,
    half_len: f32,
    random: f32,
    /// Texture coordinates of the scale's centre, wrapped into [0, 1).
    centre_u: f32,
    centre_v: f32,
    /// Dorsal row (`Lattice::row_of`), 0 for a ventral plate.
    row: i32,
}

/// The lattice is shifted by a quarter row along v so that no row of scale edges lies
/// exactly on the texture's v seam (a crevice there would be real but would read as a seam).
pub const ROW_PHASE: f32 = 0.25;

/// Lattice y of texture v on a tile of `rows_v` rows: row r spans y ∈ [r, r + 1), so its
/// edges lie a quarter row off the v seam (`ROW_PHASE`). The one place the phase is applied;
/// `v_of_row_y` is its inverse.
#[inline]
pub fn row_y(v: f32, rows_v: f32) -> f32 {
    v * rows_v - ROW_PHASE
}

/// Texture v of lattice y on a tile of `rows_v` rows (unwrapped), the inverse of `row_y`.
#[inline]
pub fn v_of_row_y(y: f32, rows_v: f32) -> f32 {
    (y + ROW_PHASE) / rows_v
}

/// Where a scale's rim meets the scale underneath, the surface falls to this fraction of the
/// lower scale's height: a groove, not a hole.
const CREVICE_FLOOR: f32 = 0.8;

/// How far a scale's free edge stands above the scale it overlaps, over the height range at
/// full imbrication: the visible overlap step of imbricate scales (the edge's thickness).
const LIP_STEP: f32 = 0.08;

/// The height of a scale near its outline, `t` = distance inside / rim width: the surface
/// rounds over a quarter circle (a rounded lip, not a linear bevel) down to the lip's foot,
/// which stands `LIP_STEP` × imbrication above the scale underneath (an overlap step: the
/// first version let the rim fall into a groove below it) — or down to the skin where
/// nothing lies underneath.
#[inline]
fn free_edge(profile: f32, t: f32, under_height: f32, imbrication: f32) -> f32 {
    let t = t.clamp(0.0, 1.0);
    // Past the rim (t = 1, most of a scale) the quarter circle is 1, the square root of 1
    // exactly: skipped there (`perf annotate` put the lattice's most samples on it;
    // `natrix-natrix --maps height` at 2048², one thread, the field's median of seven
    // 106.2 → 103.1 ms).
    let round = if t < 1.0 { (1.0 - (1.0 - t) * (1.0 - t)).sqrt() } else { 1.0 };
    // Where a scale lies underneath, the top scale's edge rests on it: never lower than the
    // scale underneath plus the step (its thickness), even where its own dome has fallen.
    let foot = if under_height > 0.0 { under_height + LIP_STEP * imbrication } else { 0.0 };
    (foot + round * (profile - foot).max(0.0)).max(CREVICE_FLOOR * under_height)
}

/// A surface's height over a scale, plate or shield: `base` at its rim's top, `dome` more
/// towards its middle, `rise` × imbrication more towards its free posterior edge. Written
/// once here for the field's pixels and for the height map's range (`height_top`).
#[derive(Debug, Clone, Copy)]
struct Profile {
    base: f32,
    dome: f32,
    rise: f32,
}

impl Profile {
    /// `dome` and `along` in [0, 1].
    #[inline]
    fn at(&self, dome: f32, imbrication: f32, along: f32) -> f32 {
        self.base + self.dome * dome + self.rise * imbrication * along
    }

    fn top(&self, imbrication: f32) -> f32 {
        self.at(1.0, imbrication, 1.0)
    }
}

/// Overlapping dorsal scales (leaf, diamond), domed and rising towards the free edge.
const SCALE_PROFILE: Profile = Profile { base: 0.45, dome: 0.15, rise: 0.3 };
/// Hexagons: they do not overlap, so they rise less towards the posterior edge.
const HEXAGON_PROFILE: Profile = Profile { base: 0.5, dome: 0.2, rise: 0.15 };
/// Ventral plates: a little above the scales, gently convex across the belly (`dome` at
/// the midline).
const PLATE_PROFILE: Profile = Profile { base: 0.55, dome: 0.06, rise: 0.3 };
/// The body layout's head shields: large domed plates, no overlap.
const SHIELD_PROFILE: Profile = Profile { base: 0.55, dome: 0.15, rise: 0.0 };
/// A keel's ridge over the scale, × `keel_height`.
const KEEL_RISE: f32 = 0.2;

/// The floor of the deepest groove between a shape's scales: where an overlapping scale's
/// free edge meets the scale underneath (`CREVICE_FLOOR` × the lowest profile, 0.36), or 0
/// for hexagons, whose rims meet at the skin. Skin showing between scales that do not
/// overlap, or round a head shield, lies below it (the height map reads 0 there).
pub fn groove_floor(shape: ScaleShape) -> f32 {
    match shape {
        ScaleShape::Hexagon => 0.0,
        ScaleShape::Leaf | ScaleShape::Diamond => CREVICE_FLOOR * SCALE_PROFILE.base,
    }
}

/// The highest surface a field of this shape can write in either layout (a keel's ridge on
/// the top of a dorsal scale's profile, or a free edge resting `LIP_STEP` above the top of
/// the scale underneath); `plates` when the belly has plates, `shields` when the body layout
/// draws head shields. Every surface falls to 0 where nothing lies underneath (a hexagon's
/// border, a shield's rim, skin between scales), so the field's heights lie in [0, this].
/// The top of the height map's range (`maps::height_range`): it clipped a third of a
/// hexagon preset's height map at 1 when it assumed the leaf's profile for every shape.
pub fn height_top(shape: ScaleShape, imbrication: f32, keel_height: f32, plates: bool, shields: bool) -> f32 {
    let lip = LIP_STEP * imbrication;
    // Keels ride on the dorsal scales only (plates and shields have none).
    let scales = KEEL_RISE * keel_height
        + match shape {
            ScaleShape::Hexagon => HEXAGON_PROFILE.top(imbrication),
            ScaleShape::Leaf | ScaleShape::Diamond => SCALE_PROFILE.top(imbrication) + lip,
        };
    let plates = if plates { PLATE_PROFILE.top(imbrication) + lip } else { 0.0 };
    let shields = if shields { SHIELD_PROFILE.top(imbrication) } else { 0.0 };
    scales.max(plates).max(shields).min(1.0)
}

/// Half-width of a diamond in cell widths (see `inside_distance`).
const DIAMOND_HALF_WIDTH: f32 = 1.0;

/// Half-width of a leaf in cell widths: wider than half a cell, so that with the staggered
/// columns neighbouring leaves overlap sideways as well as lengthwise and no skin shows
/// between them at the default size.
const LEAF_HALF_WIDTH: f32 = 0.7;

/// Half-width of a shape's bounding box in cell widths.
fn half_width(shape: ScaleShape) -> f32 {
    match shape {
        ScaleShape::Diamond => DIAMOND_HALF_WIDTH,
        ScaleShape::Leaf => LEAF_HALF_WIDTH,
        ScaleShape::Hexagon => 0.5,
    }
}

/// Shape constants that depend only on the field, computed once per render.
#[derive(Clone, Copy)]
struct Geometry {
    shape: ScaleShape,
    /// Half-length of the shape (isotropic units, cell widths).
    b: f32,
    half_width: f32,
    /// Leaf: circle radius and centre offset, and whether the lens lies across (b < a).
    leaf_r: f32,
    leaf_d: f32,
    leaf_across: bool,
    /// Diamond: distance scale of the edge-line equation.
    diamond_k: f32,
}

impl Geometry {
    fn new(shape: ScaleShape, b: f32) -> Self {
        let a = LEAF_HALF_WIDTH;
        let (la, lb) = if b >= a { (a, b) } else { (b, a) };
        let leaf_r = 0.5 * (la + lb * lb / la);
        let da = DIAMOND_HALF_WIDTH;
        Geometry {
            shape,
            b,
            half_width: half_width(shape),
            leaf_r,
            leaf_d: leaf_r - la,
            leaf_across: b < a,
            diamond_k: da * b / (da * da + b * b).sqrt(),
        }
    }

    /// Distance inside the outline (negative outside), for local (x, y) in cell widths.
    #[inline]
    fn inside(&self, x: f32, y: f32) -> f32 {
        match self.shape {
            ScaleShape::Leaf => {
                // Lens from two circles (thesis Fig. 4.8): radius R centred at (±d, 0) gives
                // half-width R − d = a and tips at y = ±sqrt(R² − d²) = ±b.
                let (x, y) = if self.leaf_across { (y, x) } else { (x, y) };
                let (d, r) = (self.leaf_d, self.leaf_r);
                // Inside both circles: the farther centre decides, the one on the other side
                // of x = 0 (d ≥ 0). |x| + d is |x ∓ d| for that centre, rounded the same, so
                // this is the larger of the two circle distances bit for bit, with one square
                // root instead of two.
                let far = x.abs() + d;
                -((far * far + y * y).sqrt() - r)
            }
            // Rhombus with half-diagonals a = 1 cell width and b = half a cell length: with
            // columns staggered by half a row, neighbouring rhombi share edges at size 1
            // (and overlap, imbricated, above). Exact distance to the nearer edge line.
            ScaleShape::Diamond => -(x.abs() / DIAMOND_HALF_WIDTH + y.abs() / self.b - 1.0) * self.diamond_k,
            ScaleShape::Hexagon => unreachable!("hexagons are Voronoi cells, see hexagon_pixel"),
        }
    }
}

impl ScaleField {
    /// The longest reach of any one scale along the body, in cell lengths: the outline's
    /// full extent along v at the largest size and rotation the jitter gives (`CellTable`:
    /// size × (1 ± `JITTER_SIZE` j), angle ± `JITTER_ANGLE_RAD` j), at least one cell.
    /// Scales whose centres lie further apart along the body than this plus the centres'
    /// jitter (`apart_cells`) cannot touch: what keeps a ring drawn in whole scales from
    /// letting its neighbours meet.
    pub fn longest_reach_cells(&self, lattice: &Lattice) -> f32 {
        let j = self.jitter.clamp(0.0, JITTER_MAX);
        let size = self.size * (1.0 + JITTER_SIZE * j);
        let reach = match self.shape {
            // Voronoi cells: one cell along the body, however they are jittered.
            ScaleShape::Hexagon => 1.0,
            ScaleShape::Leaf | ScaleShape::Diamond => {
                // Half-length 0.5 cell lengths, half-width in cell widths = 1 / aspect cell
                // lengths; rotated by θ the outline reaches b cos θ + a sin θ along v.
                let (b, a) = (0.5 * size, half_width(self.shape) * size / lattice.aspect);
                let theta = JITTER_ANGLE_RAD * j;
                2.0 * (b * theta.cos() + a * theta.sin())
            }
        };
        reach.max(1.0)
    }

    /// How far apart along the body two scales' centres must lie not to touch, in cell
    /// lengths: `longest_reach_cells` plus both centres' jitter (±`JITTER_OFFSET` j each).
    pub fn apart_cells(&self, lattice: &Lattice) -> f32 {
        self.longest_reach_cells(lattice) + 2.0 * JITTER_OFFSET * self.jitter.clamp(0.0, JITTER_MAX)
    }

    /// A scale centre's v: wrapped into [0, 1) on the tile; left as it is on a body atlas,
    /// whose snout and tail tip are not neighbours (a centre just beyond an end stays there).
    #[inline]
    fn wrap_v(&self, v: f32) -> f32 {
        if self.body.is_some() { v } else { v.rem_euclid(1.0) }
    }

    /// Position of `channel` among the outputs.
    pub fn output_index(&self, channel: usize) -> Option<usize> {
        self.outputs.iter().position(|c| *c == channel)
    }

    /// Evaluates the scale field at every pixel: one image channel per entry of `outputs`,
    /// interleaved as in any image (tests and tools; the graph holds the field planar).
    pub fn render(&self, width: usize, height: usize) -> Image {
        let planar = self.render_planar(super::image::Frame::whole(width, height));
        let mut image = Image::new(width, height, planar.channels);
        for c in 0..planar.channels {
            for (pixel, value) in image.data.chunks_exact_mut(planar.channels).zip(planar.plane(c)) {
                pixel[c] = *value;
            }
        }
        image
    }

    /// The field over the rows of `frame` (a strip of a long texture), **planar**: entry k of
    /// `outputs` is `Image::plane(k)`. Why planar: every reader takes one to four of
    /// the channels (a channel copy one, the snap two, the per-scale colour four), and from
    /// interleaved pixels each such read streams the whole field through the cache (at
    /// 2048², six channels: 96 MiB read to copy one 16 MiB channel, 15–17 ms; as a plane,
    /// a 16 MiB copy).
    pub fn render_planar(&self, frame: super::image::Frame) -> Image {
        let lattice = self.lattice();
        let table = CellTable::new(self, &lattice);
        let geo = Geometry::new(self.shape, 0.5 * lattice.aspect);
        let belly_half = 0.5 * lattice.belly_width();
        let shields = match &self.body {
            Some(b) if b.head_shields => b.shields(),
            _ => Vec::new(),
        };
        let imbricate = matches!(self.shape, ScaleShape::Leaf | ScaleShape::Diamond);
        let heights = self.outputs.contains(&channel::HEIGHT);
        // Lattice x of every pixel column (`Lattice::x_of` is a binary search over the
        // column edges when rows differ in width).
        let inv_w = 1.0 / frame.width as f32;
        let columns: Vec<(f32, f32)> = (0..frame.width)
            .map(|i| {
                let u = (i as f32 + 0.5) * inv_w;
                (u, lattice.x_of(u))
            })
            .collect();
        let channels = self.outputs.len();
        let mut image = Image::new(frame.width, frame.height, channels);
        // Row y of every plane, as one work item: (y, the planes' rows).
        let mut rows: Vec<Vec<&mut [f32]>> = (0..frame.height).map(|_| Vec::with_capacity(channels)).collect();
        for plane in image.data.chunks_mut((frame.width * frame.height).max(1)) {
            for (row, plane_row) in rows.iter_mut().zip(plane.chunks_mut(frame.width)) {
                row.push(plane_row);
            }
        }
        rows.into_par_iter().enumerate().for_each(|(row_index, mut planes)| {
            let v = frame.v(row_index);
            let y = lattice.row_y(v);
            let candidates = if imbricate { self.row_candidates(&lattice, &table, &geo, y) } else { Vec::new() };
            let hexagons =
                if self.shape == ScaleShape::Hexagon { self.row_hexagons(&lattice, &table, y) } else { Vec::new() };
            let mut cell = HexagonCell::default();
            let mut sweep = Sweep::new(&candidates);
            // The plates this row of pixels may see (None on the head, or without plates).
            let plates = if belly_half > 0.0 { self.plate_row(&lattice, v) } else { None };
            for (i, &(u, x)) in columns.iter().enumerate() {
                let mut all = [0.0f32; channel::COUNT];
                let dist_belly = u.min(1.0 - u);
                if !shields.is_empty() && self.shield_pixel(&lattice, &shields, u, v, &mut all) {
                    // A head shield.
                } else if let Some(plates) = plates.as_ref().filter(|_| dist_belly < belly_half) {
                    // Paired subcaudals: the pixel's side of the midline.
                    self.plate_pixel(&lattice, plates, dist_belly, if u < 0.5 { 0 } else { 1 }, &mut all);
                } else if self.shape == ScaleShape::Hexagon {
                    self.hexagon_pixel(&lattice, &hexagons, &mut cell, x, y, &mut all);
                } else {
                    self.imbricate_pixel(&geo, &candidates, &mut sweep, heights, x, &mut all);
                }
                for (plane, c) in planes.iter_mut().zip(&self.outputs) {
                    plane[i] = all[*c];
                }
            }
        });
        image
    }

    /// The candidate scales of one row of pixels (lattice row coordinate `y`): for every
    /// column from −1 to `cols` (a pixel's column and its neighbours), the three cells
    /// around `y`, in the order `imbricate_pixel` visits them. What depends only on the row
    /// is computed here once instead of at every pixel, and each candidate gets the range of
    /// lattice x outside which its outline cannot hold the pixel (`outline_x_range`), which
    /// `Sweep` walks.
    fn row_candidates(&self, lattice: &Lattice, table: &CellTable, geo: &Geometry, y: f32) -> Vec<RowCandidate> {
        self.row_cells(lattice, table, y)
            .map(|(c, cx, cy, cell)| {
                let py = (y - cy) * lattice.aspect;
                let (x_min, x_max) = outline_x_range(geo, cell, py);
                RowCandidate {
                    cx,
                    cy,
                    py,
                    cos: cell.cos,
                    sin: cell.sin,
                    inv_size: cell.inv_size,
                    random: cell.random,
                    centre_u: lattice.u_of(cx),
                    centre_v: self.wrap_v(v_of_row_y(cy, lattice.rows_v as f32)),
                    row: lattice.row_of(c),
                    x_min: cx as f64 + x_min,
                    x_max: cx as f64 + x_max,
                }
            })
            .collect()
    }

    /// The cells a row of pixels (lattice row coordinate `y`) may see, in the order the
    /// per-pixel kernels visit them: for every column c from −1 to `cols`, the three cells
    /// around `y` (rows r0 − 1 ..= r0 + 1 of the staggered column), each as (c, jittered
    /// centre x, y, jitter).
    fn row_cells<'t>(
        &'t self,
        lattice: &'t Lattice,
        table: &'t CellTable,
        y: f32,
    ) -> impl Iterator<Item = (i32, f32, f32, &'t CellJitter)> + 't {
        (-1..=lattice.cols).flat_map(move |c| {
            let shift = c as f32 * lattice.stagger as f32 / lattice.cols as f32;
            let r0 = floor_i32(y - shift);
            (-1..=1).map(move |dr| {
                let (cx, cy, cell) = self.centre(lattice, table, c, r0 + dr);
                (c, cx, cy, cell)
            })
        })
    }

    /// Lattice position of the jittered centre of cell (c, r), c unwrapped by at most one
    /// period (the callers look one column either side of a pixel's column).
    #[inline]
    fn centre<'t>(&self, lattice: &Lattice, table: &'t CellTable, c: i32, r: i32) -> (f32, f32, &'t CellJitter) {
        let shift = c as f32 * lattice.stagger as f32 / lattice.cols as f32;
        // The same physical cell in the wrapped column: column -1 is column cols - 1 shifted
        // by one stagger, column cols is column 0 shifted back (no integer division: this
        // runs for every candidate of every row).
        let (wc, wr) = if c < 0 {
            (c + lattice.cols, r - lattice.stagger)
        } else if c >= lattice.cols {
            (c - lattice.cols, r + lattice.stagger)
        } else {
            (c, r)
        };
        let mut wr = wr;
        while wr < 0 {
            wr += lattice.rows_v;
        }
        while wr >= lattice.rows_v {
            wr -= lattice.rows_v;
        }
        let cell = &table.cells[(wr * table.cols + wc) as usize];
        (c as f32 + 0.5 + cell.dx, r as f32 + 0.5 + shift + cell.dy, cell)
    }

    /// `x`: the pixel's lattice x; `candidates`: its row's (`row_candidates`), of which
    /// `sweep` holds those whose range reaches x (the pixels of a row come in order of x).
    /// `heights`: whether the maps read the height channel (the only one that needs the
    /// scale underneath).
    fn imbricate_pixel(
        &self,
        geo: &Geometry,
        candidates: &[RowCandidate],
        sweep: &mut Sweep,
        heights: bool,
        x: f32,
        out: &mut [f32],
    ) {
        // Roof tiles: of the scales covering a pixel, the most anterior (smallest centre v)
        // lies on top, its free posterior edge over the scale behind. Its rim falls towards
        // the scale underneath, which leaves a groove along every free edge: the visible
        // crevice between scales.
        let soft = self.softness();
        let profile = |inside: f32, y: f32| {
            let along = (y / geo.b * 0.5 + 0.5).clamp(0.0, 1.0);
            SCALE_PROFILE.at(smoothstep(0.0, 0.35, inside), self.imbrication, along)
        };
        let c0 = floor_i32(x);
        // The nine neighbouring cells, columns c0 − 1 ..= c0 + 1 (entries from column −1).
        let first = (3 * c0).clamp(0, candidates.len() as i32 - 9) as usize;
        let x_f64 = x as f64;
        // (inside, lx, ly, candidate) of the top scale so far.
        let mut top: Option<(f32, f32, f32, &RowCandidate)> = None;
        let mut under_height = 0.0f32;
        sweep.advance(candidates, x_f64);
        for &k in &sweep.active {
            let k = k as usize;
            // Only the nine cells of the pixel's column and its neighbours, as always: a
            // large scale two columns away can reach the pixel (a diamond of size 2 spans
            // about ±2 columns) but has never been looked at, and must not start to be.
            if !(first..first + 9).contains(&k) {
                continue;
            }
            let cand = &candidates[k];
            let Some((inside, lx, ly)) = cand.covers(geo, x) else { continue };
            // The scale underneath only shapes the height: when the maps read no height
            // (`--maps roughness`), its profile is not computed (`erythrolamprus-miliaris`
            // `--maps roughness` at 2048², the field 79.6 → 67.8 ms, medians of seven).
            match top {
                Some(t) if cand.cy >= t.3.cy => {
                    if heights {
                        under_height = under_height.max(profile(inside, ly));
                    }
                }
                _ => {
                    if let Some(t) = top
                        && heights
                    {
                        under_height = under_height.max(profile(t.0, t.2));
                    }
                    top = Some((inside, lx, ly, cand));
                }
            }
        }
        let Some((inside, lx, ly, cand)) = top else {
            return self.write_scale(None, 0.0, self.keel_height, out);
        };
        let height =
            if heights { free_edge(profile(inside, ly), inside / soft, under_height, self.imbrication) } else { 0.0 };
        let top = Candidate {
            inside,
            x: lx,
            y: ly,
            half_len: geo.b,
            random: cand.random,
            centre_u: cand.centre_u,
            centre_v: cand.centre_v,
            row: cand.row,
        };
        self.write_scale(Some(top), height, self.keel_height, out);
    }

    /// The nine centres around every column of one row of pixels (lattice row coordinate
    /// `y`), in isotropic units, for `hexagon_pixel`: for every column from −1 to `cols`, the
    /// three cells around `y`. The centres, their texture coordinates and rows depend only on
    /// the row, so they are computed once per row instead of nine times per pixel.
    fn row_hexagons(&self, lattice: &Lattice, table: &CellTable, y: f32) -> Vec<HexagonCentre> {
        self.row_cells(lattice, table, y)
            .map(|(c, cx, cy, cell)| {
                // Isotropic coordinates: along-body distances scaled by the cell aspect.
                let cy_iso = cy * lattice.aspect;
                HexagonCentre {
                    x: cx,
                    y: cy_iso,
                    random: cell.random,
                    centre_u: lattice.u_of(cx),
                    centre_v: self.wrap_v(v_of_row_y(cy_iso / lattice.aspect, lattice.rows_v as f32)),
                    row: lattice.row_of(c),
                }
            })
            .collect()
    }

    /// `x`, `y`: the pixel's lattice coordinates; `centres`: its row's (`row_hexagons`);
    /// `cell`: the Voronoi cell of the previous pixel of the row, whose bisectors are reused
    /// while the nearest centre stays the same (a hexagon spans tens of pixels).
    fn hexagon_pixel(
        &self,
        lattice: &Lattice,
        centres: &[HexagonCentre],
        cell: &mut HexagonCell,
        x: f32,
        y: f32,
        out: &mut [f32],
    ) {
        // Voronoi cell of the jittered lattice: nearest centre, then the distance to the
        // nearest bisector with any other centre is the distance to the cell's edge.
        let c0 = floor_i32(x);
        debug_assert!((0..lattice.cols).contains(&c0), "lattice x {x} outside the columns");
        // The nine neighbouring cells, columns c0 − 1 ..= c0 + 1 (entries from column −1).
        let first = (3 * c0).clamp(0, centres.len() as i32 - 9) as usize;
        let near = &centres[first..first + 9];
        let p = (x, y * lattice.aspect);
        let d2: [f32; 9] = std::array::from_fn(|i| (near[i].x - p.0).powi(2) + (near[i].y - p.1).powi(2));
        let nearest = (0..9).min_by(|&i, &j| d2[i].total_cmp(&d2[j])).unwrap_or(0);
        if cell.key != Some((first, nearest)) {
            *cell = HexagonCell::new(near, first, nearest);
        }
        let c1 = &near[nearest];
        let mut edge = f32::MAX;
        for b in &cell.bisectors {
            edge = edge.min(((b.mid.0 - p.0) * b.dx + (b.mid.1 - p.1) * b.dy) / b.len);
        }
        // `size` below 1 opens a gap of skin between the plates.
        let inside = edge - (1.0 - self.size.min(1.0)) * 0.5;
        let half_len = 0.5 * lattice.aspect;
        let cand = Candidate {
            inside,
            x: p.0 - c1.x,
            y: p.1 - c1.y,
            half_len,
            random: c1.random,
            centre_u: c1.centre_u,
            centre_v: c1.centre_v,
            row: c1.row,
        };
        let soft = self.softness();
        let along = (cand.y / half_len * 0.5 + 0.5).clamp(0.0, 1.0);
        let rim = smoothstep(0.0, soft, inside);
        let dome = smoothstep(0.0, 0.35, inside);
        let h = rim * HEXAGON_PROFILE.at(dome, self.imbrication, along);
        let visible = if inside > 0.0 { Some(cand) } else { None };
        self.write_scale(visible, h, self.keel_height, out);
    }

    fn write_scale(&self, best: Option<Candidate>, height: f32, keel_height: f32, out: &mut [f32]) {
        let soft = self.softness();
        match best {
            None => {
                out[channel::HEIGHT] = 0.0;
                out[channel::CREVICE] = 1.0;
                out[channel::ALONG] = 0.0;
                out[channel::RADIAL] = 1.0;
                out[channel::KEEL] = 0.0;
                out[channel::CELL_RANDOM] = 0.0;
                out[channel::CENTRE_U] = -1.0;
                out[channel::CENTRE_V] = -1.0;
                out[channel::INSIDE] = 0.0;
                out[channel::ROW] = 0.0;
            }
            Some(c) => {
                // The lowest `smooth_rows` dorsal rows carry no keel.
                let keel_height = if c.row > 0 && c.row as u32 <= self.smooth_rows { 0.0 } else { keel_height };
                let along = (c.y / c.half_len * 0.5 + 0.5).clamp(0.0, 1.0);
                let hw = half_width(self.shape);
                let radial = ((c.x / hw).powi(2) + (c.y / c.half_len).powi(2)).sqrt().min(1.0);
                let keel = if keel_height > 0.0 {
                    // A ridge along the long axis, fading out towards the anterior tip.
                    (1.0 - smoothstep(0.0, self.keel_width.max(1e-3), c.x.abs()))
                        * smoothstep(0.0, 0.6, along)
                        * smoothstep(0.0, soft, c.inside)
                } else {
                    0.0
                };
                out[channel::HEIGHT] = (height + KEEL_RISE * keel_height * keel).clamp(0.0, 1.0);
                out[channel::CREVICE] = 1.0 - smoothstep(0.0, soft * 1.5, c.inside);
                out[channel::ALONG] = along;
                out[channel::RADIAL] = radial;
                out[channel::KEEL] = keel;
                out[channel::CELL_RANDOM] = c.random;
                out[channel::CENTRE_U] = c.centre_u;
                out[channel::CENTRE_V] = c.centre_v;
                out[channel::INSIDE] = c.inside.max(0.0);
                out[channel::ROW] = c.row as f32;
            }
        }
    }

    /// The plates a row of pixels at texture v may see (`PlateRow`), or None where the belly
    /// band holds none (the body's head). The tile: one wide plate per lattice row; the body
    /// layout: the ventrals and subcaudals, counted (`BodyPlan::plate_at`), subcaudals
    /// divided at the midline where the preset says so (most snakes). What depends on the
    /// row alone is computed here once, not at every pixel of the band.
    fn plate_row(&self, lattice: &Lattice, v: f32) -> Option<PlateRow> {
        let Some(body) = &self.body else {
            let rows = PlateRows {
                plate: &|_| Some((lattice.aspect, false)),
                centre_v: &|r| lattice.row_centre_v(r).rem_euclid(1.0),
                identity: &|r| r.rem_euclid(lattice.rows_v),
            };
            return Some(self.plate_row_at(lattice.row_y(v), &rows));
        };
        let y = body.plate_coordinate(v)?.0;
        let total = (body.ventrals + body.subcaudals) as i32;
        let plate = |r: i32| {
            if !(0..total).contains(&r) {
                return None;
            }
            let subcaudal = r >= body.ventrals as i32;
            // Plate length over an ordinary column's width (both in circumferences).
            let aspect = body.plate_length_v(subcaudal) * body.length / lattice.bounds[1];
            Some((aspect, subcaudal && body.divided_subcaudals))
        };
        let rows = PlateRows { plate: &plate, centre_v: &|r| body.plate_centre_v(r), identity: &|r| r };
        Some(self.plate_row_at(y, &rows))
    }

    /// `plate_row` at plate coordinate `y` (plate r spans [r, r + 1)).
    fn plate_row_at(&self, y: f32, rows: &PlateRows) -> PlateRow {
        let r0 = floor_i32(y);
        let half_len = 0.5 * self.size.max(0.5);
        let near = [r0 - 1, r0, r0 + 1].map(|r| {
            // Each plate with its own length and division (a ventral overhanging the vent
            // stays a ventral); none before the first or after the last.
            let (aspect, divided) = (rows.plate)(r)?;
            let along = ((y - (r as f32 + 0.5)) / half_len * 0.5 + 0.5).clamp(0.0, 1.0);
            let id = (rows.identity)(r);
            Some(NearPlate {
                aspect,
                divided,
                to_end: (half_len - (y - (r as f32 + 0.5)).abs()) * aspect,
                along,
                random: [hash::unit(-2, id, 4, self.seed), hash::unit(-3, id, 4, self.seed)],
                random_undivided: hash::unit(-1, id, 4, self.seed),
                ly: (y - (r as f32 + 0.5)) / half_len * 0.5 * aspect,
                centre_v: (rows.centre_v)(r),
            })
        });
        PlateRow { near }
    }

    /// One wide plate per row across the belly band (`plates`: the pixel row's), overlapping
    /// like the dorsal scales (the thesis stretches normal scales "from the middle",
    /// §4.2.2); `side` the pixel's side of the midline (0 for u < 1/2), for divided plates.
    fn plate_pixel(&self, lattice: &Lattice, plates: &PlateRow, dist_belly: f32, side: usize, out: &mut [f32]) {
        let soft = self.softness();
        let half_band = lattice.belly_width() * 0.5;
        // Distances in dorsal scale widths, the unit of `edge_softness` (a plate column is
        // one ordinary column wide).
        let to_side = (half_band - dist_belly) / lattice.bounds[1];
        // Paired plates meet at the midline (u = 0).
        let to_side_divided = to_side.min(dist_belly / lattice.bounds[1]);
        // The most anterior plate covering the pixel lies on top (its free posterior edge over
        // the next plate, as the dorsal scales); the others are the surface underneath.
        let mut top: Option<(&NearPlate, f32, f32)> = None; // (plate, inside, profile)
        let mut under_height = 0.0f32;
        // Plates are gently convex across the belly.
        let across = (dist_belly / half_band).min(1.0);
        let dome = 1.0 - across * across;
        for plate in plates.near.iter().flatten() {
            let inside = if plate.divided { to_side_divided } else { to_side }.min(plate.to_end);
            if inside <= 0.0 {
                continue;
            }
            let profile = PLATE_PROFILE.at(dome, self.imbrication, plate.along);
            match top {
                Some(_) => under_height = under_height.max(profile),
                None => top = Some((plate, inside, profile)),
            }
        }
        let Some((plate, inside, profile)) = top else {
            return self.write_scale(None, 0.0, 0.0, out);
        };
        let h = free_edge(profile, inside / soft, under_height, self.imbrication);
        let cand = Candidate {
            inside,
            x: dist_belly / half_band * 0.5,
            y: plate.ly,
            half_len: 0.5 * plate.aspect,
            random: if plate.divided { plate.random[side] } else { plate.random_undivided },
            centre_u: 0.0,
            centre_v: plate.centre_v,
            row: 0,
        };
        // Ventral plates carry no keel.
        self.write_scale(Some(cand), h, 0.0, out);
    }

    /// A head shield of the body layout (`BodyPlan::shields`), if (u, v) lies on one:
    /// large plates with a rounded rim, domed, without keels. Elsewhere on the head the
    /// lattice's small scales continue. Returns false off every shield.
    fn shield_pixel(&self, lattice: &Lattice, shields: &[Plate], u: f32, v: f32, out: &mut [f32]) -> bool {
        let Some(body) = &self.body else { return false };
        if v > body.head_end * 1.02 || (u - 0.5).abs() > HEAD_TOP_HALF_U {
            return false;
        }
        let (x, y) = (u, v * body.length);
        let best = shields
            .iter()
            .filter(|p| v >= p.v_range.0 - 0.001 && v <= p.v_range.1 + 0.001)
            .map(|p| (p.inside(x, y), p))
            .max_by(|a, b| a.0.total_cmp(&b.0));
        let Some((inside_circ, plate)) = best.filter(|(d, _)| *d > 0.0) else { return false };
        // In ordinary column widths, the unit of `edge_softness`.
        let cell = lattice.bounds[1];
        let inside = inside_circ / cell;
        let soft = self.softness();
        let half_len = 0.5 * (plate.v_range.1 - plate.v_range.0) * body.length / cell;
        let cand = Candidate {
            inside,
            x: (u - plate.centre_uv.0) / cell,
            y: (v - plate.centre_uv.1) * body.length / cell,
            half_len: half_len.max(1e-3),
            random: hash::unit(-3, plate.id, 4, self.seed),
            centre_u: plate.centre_uv.0,
            centre_v: plate.centre_uv.1,
            row: 0,
        };
        let h = smoothstep(0.0, soft, inside) * SHIELD_PROFILE.at(smoothstep(0.0, 1.0, inside), self.imbrication, 0.0);
        self.write_scale(Some(cand), h, 0.0, out);
        true
    }
}

/// The candidates of a row of pixels whose x range (`RowCandidate::x_min` ..= `x_max`)
/// holds the current pixel, found by sweeping the row left to right: each candidate enters
/// once when the pixels reach its range and leaves once behind it, instead of nine range
/// tests per pixel.
struct Sweep {
    /// Candidate indices with a non-empty range, by where the range starts.
    order: Vec<u32>,
    /// Entries of `order` that have entered so far.
    entered: usize,
    /// The candidates holding the current x, in index order: the order in which
    /// `imbricate_pixel` visits them (the first of equal centres stays on top).
    active: Vec<u32>,
    /// The previous pixel's x (the sweep needs x never to decrease).
    last_x: f64,
    /// The smallest range end among `active` (infinite when none): until x passes it, no
    /// candidate leaves, and the per-pixel `retain` over `active` is skipped.
    next_exit: f64,
}

impl Sweep {
    fn new(candidates: &[RowCandidate]) -> Sweep {
        let count = u32::try_from(candidates.len()).expect("a row has fewer than 2³² candidates");
        let mut order: Vec<u32> =
            (0..count).filter(|&k| candidates[k as usize].x_min <= candidates[k as usize].x_max).collect();
        order.sort_by(|a, b| candidates[*a as usize].x_min.total_cmp(&candidates[*b as usize].x_min));
        Sweep { order, entered: 0, active: Vec::new(), last_x: f64::NEG_INFINITY, next_exit: f64::INFINITY }
    }

    /// Moves on to the pixel at `x`, which is not left of the previous one.
    #[inline]
    fn advance(&mut self, candidates: &[RowCandidate], x: f64) {
        debug_assert!(x >= self.last_x, "the sweep went back from x {} to {x}", self.last_x);
        self.last_x = x;
        while let Some(&k) = self.order.get(self.entered) {
            if candidates[k as usize].x_min > x {
                break;
            }
            let at = self.active.partition_point(|a| *a < k);
            self.active.insert(at, k);
            self.next_exit = self.next_exit.min(candidates[k as usize].x_max);
            self.entered += 1;
        }
        if x > self.next_exit {
            self.active.retain(|&k| candidates[k as usize].x_max >= x);
            self.next_exit = self.active.iter().map(|&k| candidates[k as usize].x_max).fold(f64::INFINITY, f64::min);
        }
    }
}

/// A sequence of plates along the belly: the tile's lattice rows or the body's counted
/// ventrals and subcaudals.
struct PlateRows<'a> {
    /// Plate r's length over an ordinary column's width, and whether it is divided at the
    /// midline (subcaudals); None where there is no plate r.
    plate: &'a dyn Fn(i32) -> Option<(f32, bool)>,
    /// v of plate r's centre, for the scale field's CENTRE_V.
    centre_v: &'a dyn Fn(i32) -> f32,
    /// Plate r's identity for its random number.
    identity: &'a dyn Fn(i32) -> i32,
}

/// The plates around one row of pixels (`ScaleField::plate_row`): rows r0 − 1 ..= r0 + 1
/// of the plate coordinate, None where there is no plate, in the order `plate_pixel` visits
/// them.
struct PlateRow {
    near: [Option<NearPlate>; 3],
}

/// What a plate is at one row of pixels, for every pixel of the belly band there.
struct NearPlate {
    /// Length over an ordinary column's width, and divided at the midline.
    aspect: f32,
    divided: bool,
    /// Distance from the row to the plate's nearer end, in dorsal scale widths.
    to_end: f32,
    /// The row's position along the plate, 0 at its anterior end to 1 at its free posterior
    /// edge (`PLATE_PROFILE` rises along it).
    along: f32,
    /// The random number of each half of a divided plate (u < 1/2, u ≥ 1/2) and of the
    /// whole.
    random: [f32; 2],
    random_undivided: f32,
    /// The row's position along the plate (the scale field's local y).
    ly: f32,
    centre_v: f32,
}

/// One hexagon centre of a row of pixels (`ScaleField::row_hexagons`).
struct HexagonCentre {
    /// The jittered centre in isotropic lattice units (x in columns, y in cell widths).
    x: f32,
    y: f32,
    random: f32,
    /// Its texture coordinates and dorsal row, as `Candidate` carries them.
    centre_u: f32,
    centre_v: f32,
    row: i32,
}

/// The bisector between a Voronoi cell's centre and one of its neighbours: the pixel lies
/// ((mid − p) · (dx, dy)) / len inside it.
#[derive(Clone, Copy, Default)]
struct Bisector {
    mid: (f32, f32),
    dx: f32,
    dy: f32,
    len: f32,
}

/// The Voronoi cell a row of pixels is in: its key (the first of the nine centres, the
/// nearest among them) and its eight bisectors, which depend only on the centres.
#[derive(Default)]
struct HexagonCell {
    key: Option<(usize, usize)>,
    bisectors: [Bisector; 8],
}

impl HexagonCell {
    fn new(near: &[HexagonCentre], first: usize, nearest: usize) -> Self {
        let c1 = &near[nearest];
        let mut bisectors = [Bisector::default(); 8];
        for (b, c2) in bisectors.iter_mut().zip(near.iter().enumerate().filter(|(i, _)| *i != nearest).map(|(_, c)| c))
        {
            let (dx, dy) = (c2.x - c1.x, c2.y - c1.y);
            let len = (dx * dx + dy * dy).sqrt().max(1e-6);
            *b = Bisector { mid: ((c1.x + c2.x) * 0.5, (c1.y + c2.y) * 0.5), dx, dy, len };
        }
        HexagonCell { key: Some((first, nearest)), bisectors }
    }
}

/// One candidate scale of a row of pixels (`ScaleField::row_candidates`).
struct RowCandidate {
    /// The cell's jittered centre in lattice units.
    cx: f32,
    cy: f32,
    /// The row's offset from the centre along the body, isotropic units: (y − cy) × aspect.
    py: f32,
    cos: f32,
    sin: f32,
    inv_size: f32,
    random: f32,
    /// What `Candidate` carries of the scale, computed once per row instead of per pixel:
    /// its centre in texture space and its dorsal row.
    centre_u: f32,
    centre_v: f32,
    row: i32,
    /// Lattice x outside which the scale's outline misses the row (conservative,
    /// `outline_x_range`).
    x_min: f64,
    x_max: f64,
}

impl RowCandidate {
    /// Whether the scale covers the pixel at lattice x on this row: (distance inside the
    /// outline, local x, local y) where it does.
    #[inline]
    fn covers(&self, geo: &Geometry, x: f32) -> Option<(f32, f32, f32)> {
        // To isotropic units (cell widths), rotate by the jitter angle, scale by size.
        let px = x - self.cx;
        let py = self.py;
        let lx = (px * self.cos + py * self.sin) * self.inv_size;
        let ly = (-px * self.sin + py * self.cos) * self.inv_size;
        // Every shape lies inside its |x| < half-width, |y| < b box: skip the rest.
        if lx.abs() >= geo.half_width || ly.abs() >= geo.b {
            return None;
        }
        let inside = geo.inside(lx, ly) / self.inv_size;
        (inside > 0.0).then_some((inside, lx, ly))
    }
}

/// How far the culling ranges reach beyond the exact ones, in the scale's own units (cell
/// widths at size 1): f32 rounding moves the per-pixel test (`RowCandidate::covers`) by
/// under 1e-5 there, so a range grown by this never culls a pixel the test accepts.
const CULL_MARGIN: f64 = 1e-4;

/// The range of px = x − cx (lattice units) where a cell's rotated bounding box,
/// |lx| < half-width and |ly| < b with lx = (px cos + py sin) / size and
/// ly = (−px sin + py cos) / size, can hold a pixel at row offset `py`. The box is widened
/// by `CULL_MARGIN` and the range by as much again, so culling by this range never rejects a
/// pixel the per-pixel test accepts.
/// Empty (min > max) where the box misses the row.
fn box_x_range(geo: &Geometry, cell: &CellJitter, py: f32) -> (f64, f64) {
    let (cos, sin, size) = (cell.cos as f64, cell.sin as f64, 1.0 / cell.inv_size as f64);
    let py = py as f64;
    let (hw, b) = ((geo.half_width as f64 + CULL_MARGIN) * size, (geo.b as f64 + CULL_MARGIN) * size);
    if cos <= 0.0 {
        return (f64::NEG_INFINITY, f64::INFINITY);
    }
    // |px cos + py sin| < hw.
    let (mut lo, mut hi) = ((-hw - py * sin) / cos, (hw - py * sin) / cos);
    // |−px sin + py cos| < b.
    if sin.abs() > 1e-9 {
        let (a, z) = ((py * cos - b) / sin, (py * cos + b) / sin);
        lo = lo.max(a.min(z));
        hi = hi.min(a.max(z));
    } else if (py * cos).abs() >= b {
        return (1.0, -1.0);
    }
    (lo - CULL_MARGIN, hi + CULL_MARGIN)
}

/// The range of px = x − cx (lattice units) where the cell's outline itself (not only its
/// bounding box) can hold a pixel at row offset `py`: the outline is convex, so a row crosses
/// it in one interval. Found in f64 for the outline grown by `CULL_MARGIN` (the leaf's
/// circles by that radius; the diamond's |lx| / a + |ly| / b < 1 by that on its left side,
/// a distance of `CULL_MARGIN` × `diamond_k`, 0.14–0.7 of it), then widened by `CULL_MARGIN`
/// in the scale's units, so it never rejects a pixel the per-pixel f32 test accepts;
/// intersected with the box's range.
///
/// Why: with the box alone, half the candidates that reached the per-pixel test failed it
/// (a diamond fills half its box). Counted at 1024², candidates tested per dorsal pixel:
/// `natrix-natrix` (diamonds) 2.88 → 1.44, of which 1.44 cover it; `ahaetulla-nasuta`
/// (leaves) 2.01 → 1.56, 1.55 cover it. With `Sweep`, the field's time at 2048² (two
/// cores, medians of seven): `bitis-gabonica` 95 → 74 ms, `natrix-natrix` 91 → 80 ms,
/// `ahaetulla-nasuta` 72 → 66 ms.
fn outline_x_range(geo: &Geometry, cell: &CellJitter, py: f32) -> (f64, f64) {
    outline_x_range_grown(geo, cell, py, CULL_MARGIN)
}

/// `outline_x_range` with the outline grown by `margin` (the tests' negative control: 0).
fn outline_x_range_grown(geo: &Geometry, cell: &CellJitter, py: f32, margin: f64) -> (f64, f64) {
    let (lo, hi) = box_x_range(geo, cell, py);
    if lo > hi {
        return (lo, hi);
    }
    let (cos, sin, k) = (cell.cos as f64, cell.sin as f64, cell.inv_size as f64);
    let py = py as f64;
    // Local coordinates along the row: lx = ax px + bx, ly = ay px + by.
    let (ax, bx) = (cos * k, py * sin * k);
    let (ay, by) = (-sin * k, py * cos * k);
    let (mut lo_s, mut hi_s) = (f64::NEG_INFINITY, f64::INFINITY);
    match geo.shape {
        ScaleShape::Diamond => {
            // |lx| / a + |ly| / b < 1 is the intersection of the four half-planes
            // ±lx / a ± ly / b < 1, each linear in px.
            let (a, b) = (DIAMOND_HALF_WIDTH as f64, geo.b as f64);
            for (sx, sy) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
                let slope = sx * ax / a + sy * ay / b;
                let offset = sx * bx / a + sy * by / b;
                let limit = 1.0 + margin - offset;
                if slope > 0.0 {
                    hi_s = hi_s.min(limit / slope);
                } else if slope < 0.0 {
                    lo_s = lo_s.max(limit / slope);
                } else if limit <= 0.0 {
                    return (1.0, -1.0);
                }
            }
        }
        ScaleShape::Leaf => {
            // Inside both circles of radius R centred at (±d, 0) (across: the lens' x is ly).
            let ((ax, bx), (ay, by)) = if geo.leaf_across { ((ay, by), (ax, bx)) } else { ((ax, bx), (ay, by)) };
            let (d, r) = (geo.leaf_d as f64, geo.leaf_r as f64 + margin);
            for centre in [d, -d] {
                // (ax px + bx − centre)² + (ay px + by)² < r²: a quadratic in px.
                let qa = ax * ax + ay * ay;
                let qb = ax * (bx - centre) + ay * by;
                let qc = (bx - centre) * (bx - centre) + by * by - r * r;
                let disc = qb * qb - qa * qc;
                if disc <= 0.0 {
                    return (1.0, -1.0);
                }
                let root = disc.sqrt();
                lo_s = lo_s.max((-qb - root) / qa);
                hi_s = hi_s.min((-qb + root) / qa);
            }
        }
        ScaleShape::Hexagon => return (lo, hi),
    }
    let widen = margin / k;
    (lo.max(lo_s - widen), hi.min(hi_s + widen))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Pixels that a row's candidate covers (`RowCandidate::covers`, the per-pixel test)
    /// outside the x range `range` gives it, over rows and x steps across every candidate and
    /// the floats next to each end of its range: the culling's contract is that there are
    /// none. `shrink` (lattice columns) narrows every range.
    fn uncovered(field: &ScaleField, margin: f64, shrink: f64) -> usize {
        let lattice = field.lattice();
        let table = CellTable::new(field, &lattice);
        let geo = Geometry::new(field.shape, 0.5 * lattice.aspect);
        let mut misses = 0;
        for row in 0..23 {
            let y = lattice.row_y((row as f32 + 0.37) / 23.0);
            let candidates = field.row_candidates(&lattice, &table, &geo, y);
            for (cand, (_, cx, _, cell)) in candidates.iter().zip(field.row_cells(&lattice, &table, y)) {
                let (lo, hi) = outline_x_range_grown(&geo, cell, cand.py, margin);
                let (lo, hi) = (cx as f64 + lo + shrink, cx as f64 + hi - shrink);
                let mut check = |x: f32| {
                    if cand.covers(&geo, x).is_some() && !(lo <= x as f64 && x as f64 <= hi) {
                        misses += 1;
                    }
                };
                for step in -3 * 512..=3 * 512 {
                    check(cand.cx + step as f32 / 512.0);
                }
                for end in [lo, hi].into_iter().filter(|e| e.is_finite()) {
                    let mut x = end as f32;
                    for _ in 0..64 {
                        x = x.next_down();
                    }
                    for _ in 0..128 {
                        check(x);
                        x = x.next_up();
                    }
                }
            }
        }
        misses
    }

    /// Fields over the shapes and the preset range table's extremes of aspect (0.3, 4.0;
    /// 0.8: a leaf across), jitter and size (`preset::validate`).
    fn fields() -> Vec<ScaleField> {
        let source = crate::preset::read_source("natrix-natrix").expect("a built-in preset");
        let preset = crate::preset::parse(&source, &[]).expect("it parses").preset;
        let base = crate::maps::scale_field(&preset, crate::maps::Layout::Tile);
        let mut fields = Vec::new();
        for shape in [ScaleShape::Leaf, ScaleShape::Diamond] {
            for aspect in [0.3, 0.8, 2.0, 4.0] {
                for jitter in [0.0, 0.5] {
                    for size in [0.5, 1.0, 2.0] {
                        fields.push(ScaleField { shape, aspect, jitter, size, ..base.clone() });
                    }
                }
            }
        }
        fields
    }

    /// The leaf's distance inside both circles, written out as the larger of the two circle
    /// distances (thesis Fig. 4.8's construction).
    fn two_circles(geo: &Geometry, x: f32, y: f32) -> f32 {
        let (x, y) = if geo.leaf_across { (y, x) } else { (x, y) };
        let (d, r) = (geo.leaf_d, geo.leaf_r);
        let d1 = ((x - d) * (x - d) + y * y).sqrt() - r;
        let d2 = ((x + d) * (x + d) + y * y).sqrt() - r;
        -d1.max(d2)
    }

    /// Points of a grid over the leaf and beyond (both signs, the axes, signed zeros) where
    /// `inside` differs from `two_circles` in any bit.
    fn mismatches(geo: &Geometry, inside: impl Fn(f32, f32) -> f32) -> usize {
        let mut points: Vec<(f32, f32)> = Vec::new();
        for i in -200..=200 {
            for j in -200..=200 {
                points.push((i as f32 * 0.0071, j as f32 * 0.0113));
            }
        }
        points.extend([(0.0, 0.0), (-0.0, 0.3), (0.2, -0.0), (-0.25, 0.0)]);
        points.iter().filter(|&&(x, y)| inside(x, y).to_bits() != two_circles(geo, x, y).to_bits()).count()
    }

    #[test]
    fn the_leaf_with_one_square_root_is_both_circles_bit_for_bit() {
        // b below and above the leaf's half-width: across and lengthwise.
        for b in [0.15, 0.4, 0.7, 1.0, 2.0] {
            let geo = Geometry::new(ScaleShape::Leaf, b);
            assert_eq!(mismatches(&geo, |x, y| geo.inside(x, y)), 0, "b {b}");
            // The negative control: the farther centre taken without |x| (right only for
            // x ≥ 0) is found.
            let signed = |x: f32, y: f32| {
                let (x, y) = if geo.leaf_across { (y, x) } else { (x, y) };
                let far = x + geo.leaf_d;
                -((far * far + y * y).sqrt() - geo.leaf_r)
            };
            // (At b = the half-width the lens is a circle, d = 0, and the two agree.)
            assert!(geo.leaf_d == 0.0 || mismatches(&geo, signed) > 0, "b {b}");
        }
    }

    #[test]
    fn the_sweep_visits_the_candidates_whose_range_holds_the_pixel_in_order() {
        for field in fields() {
            let lattice = field.lattice();
            let table = CellTable::new(&field, &lattice);
            let geo = Geometry::new(field.shape, 0.5 * lattice.aspect);
            for row in 0..23 {
                let y = lattice.row_y((row as f32 + 0.37) / 23.0);
                let candidates = field.row_candidates(&lattice, &table, &geo, y);
                let mut sweep = Sweep::new(&candidates);
                for i in 0..997 {
                    let x = lattice.x_of((i as f32 + 0.5) / 997.0) as f64;
                    sweep.advance(&candidates, x);
                    let swept: Vec<usize> = sweep.active.iter().map(|k| *k as usize).collect();
                    let tested: Vec<usize> = (0..candidates.len())
                        .filter(|k| (candidates[*k].x_min..=candidates[*k].x_max).contains(&x))
                        .collect();
                    assert_eq!(swept, tested, "row {row}, x {x}");
                }
            }
        }
    }

    #[test]
    fn the_sweep_never_culls_a_scale_that_covers_the_pixel() {
        for field in fields() {
            let what = format!("{:?} aspect {} jitter {} size {}", field.shape, field.aspect, field.jitter, field.size);
            assert_eq!(uncovered(&field, CULL_MARGIN, 0.0), 0, "{what}");
        }
    }

    #[test]
    fn ranges_without_the_margin_or_narrowed_cull_covered_pixels() {
        // The negative controls: the check above can fail. Without the margin the exact
        // outline's range misses pixels that f32 rounding puts inside (found at the floats
        // next to the ends); narrowed by a hundredth of a column, every field misses some.
        let fields = fields();
        assert!(fields.iter().map(|f| uncovered(f, 0.0, 0.0)).sum::<usize>() > 0);
        for field in &fields {
            assert!(
                uncovered(field, CULL_MARGIN, 0.01) > 0,
                "{:?} aspect {} size {}",
                field.shape,
                field.aspect,
                field.size
            );
        }
    }
}
