//! The `lut` method: a per-material table of film colour over (cos θ, thickness), baked
//! from the spectral sum and prefiltered in thickness, read with one bilinear lookup.
//!
//! Thickness axis: `n_fine` texels uniform over [0, `FINE_MAX_NM`] (the range presets
//! use), then `n_coarse` texels up to `COARSE_MAX_NM`, the last of which is exactly the
//! incoherent limit; thicker films clamp to it. Each texel is the box average of the colour
//! over its thickness cell (exact, through the Fourier series in `series.rs`), so texels of
//! thick films already hold the washed-out colour and a lookup can never alias: no moiré at
//! 2.4 mm (the thesis' Fig. 5.9) or any other thickness. Cos θ axis: `n_cos` texels uniform
//! over [0, 1], row 0 fitted over the first interval rather than sampled at cos 0 ("Row 0,
//! fitted", below).
//!
//! **The rough top's coupling, tabulated.** The layered model reads, per direction, what the
//! rough top reflects (`brdf::energy::top`): the rule on the two roughness rows of the lobe
//! around the roughness, each eighteen film lookups (`energy::ROW_FILM_READS`), and the
//! multiple-scatter lobe's normalisation on both rows, eight more evaluations of the rule
//! each, where the thesis model makes one lookup.
//! Baked with the table on as many cos texels (uniform in √cos, `coupling_texel_cos`), the
//! same rows and its thickness columns, it is one trilinear lookup (`coupling_f32`; in the
//! shader two filtered 3-D texture fetches, one per RGBA half) that interpolates between rows as the rule does; between cos texels and
//! thickness columns it interpolates the results where the rule interpolates the lobe and
//! the film (`tests/brdf.rs` bounds the difference). The f32 twin and the shader read it;
//! the f64 model evaluates the rule.

use rayon::prelude::*;

use std::sync::OnceLock;

use crate::optics::brdf::energy::{self, E1_ROUGHNESS, GridCell};
use crate::optics::brdf::path;

use super::film::{FilmAtAngle, Stack};
use super::series::FilmSeries;
use super::spectrum::{Observer, xyz_to_linear_srgb};

/// The end of the fine thickness columns, uniform over [0, FINE_MAX_NM] (the module's
/// thickness axis; shared with the shader's prelude).
pub const FINE_MAX_NM: f64 = 2000.0;

/// The last coarse column, exactly the incoherent limit: thicker films clamp to it.
pub const COARSE_MAX_NM: f64 = 20_000.0;

/// The cosine of the coupling table's cos texel `i` of `n`: uniform in √cos, as the rough
/// lobe's own nodes (`energy::node_mu`), where a low-roughness lobe changes within a few α
/// of grazing light. Why: once the rule resolved that boundary layer, texels uniform in cos
/// (the film's, 0.016 apart) read its multiple-scatter amplitude up to 4.6 off below
/// cos 0.1 and its reflected share 0.0053 off (`coupling_table_is_the_rule_it_tabulates`).
pub fn coupling_texel_cos(i: usize, n: usize) -> f32 {
    energy::GridCell::<f32>::axis_cos(i, n)
}

/// The texels one evaluation reads from the coupling table for its two directions
/// (`Lut::coupling_pair_start`): the four (thickness column, roughness row) corners, each
/// corner's first entry and its weight, and per direction the cos texel below its cosine
/// and the weight of the next.
#[derive(Debug, Clone, Copy)]
pub(crate) struct CouplingFetch {
    corners: [(usize, f32); 4],
    texels: [(usize, f32); 2],
}

#[derive(Debug, Clone)]
pub struct Lut {
    /// The material the table was baked for.
    pub stack: Stack,
    pub n_cos: usize,
    pub n_fine: usize,
    pub n_coarse: usize,
    /// Row-major: `texels[i_cos * width + i_d]`, linear sRGB reflectance.
    pub texels: Vec<[f32; 3]>,
    /// The rough top's coupling at `n_cos` cos nodes (`coupling_texel_cos`), the rough lobe's
    /// roughness rows and the texels' thickness columns (`bake_coupling`): per entry the
    /// reflected share (RGB), the pigment layer's path delta (cos_eff − cos_t,
    /// `brdf::path`), the multiple-scatter amplitude (RGB) and 0 — the two RGBA texels of
    /// the shader's `coupling_texture` — index `(i_d * E1_ROUGHNESS + i_r) * n_cos + i_cos`.
    /// Baked on first use (`coupling`): it needs the material's path table, a photon walk
    /// that a film-colour query or a thesis-model render should not pay for.
    coupling: OnceLock<Vec<[f32; 8]>>,
}

/// Table size chosen from the error/size trade-off measured by `snakeskin bench irid`
/// (see BENCHMARKS.md): 64 angles × (256 + 64) thicknesses, 240 KiB as RGB f32.
pub const DEFAULT_SIZE: (usize, usize, usize) = (64, 256, 64);

/// Thickness columns of a default-size LUT (`Lut::width`): the width of the renderer's film
/// texture and the depth of its 3-D coupling texture, which a GPU must be able to hold.
pub const DEFAULT_WIDTH: usize = DEFAULT_SIZE.1 + DEFAULT_SIZE.2;

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

    /// The table's shape, without texels.
    fn shape(stack: Stack, n_cos: usize, n_fine: usize, n_coarse: usize) -> Lut {
        Lut {
            stack,
            n_cos: n_cos.max(2),
            n_fine: n_fine.max(2),
            n_coarse: n_coarse.max(1),
            texels: Vec::new(),
            coupling: OnceLock::new(),
        }
    }

    /// The cosine of texel row `i` (row 0's texels are fitted over the first interval
    /// instead: `grazing_texel`).
    fn row_cos(&self, i: usize) -> f64 {
        i as f64 / (self.n_cos - 1) as f64
    }

    /// The colour of texel column `j` for the film `film` at `cos0`: the box average over
    /// its thickness cell; the last column, the incoherent limit.
    fn colour(&self, film: &FilmSeries, cos0: f64, j: usize) -> [f64; 3] {
        if j + 1 == self.width() {
            [super::film::incoherent(self.stack, cos0).r; 3]
        } else {
            let (d, w) = self.texel_thickness(j);
            box_colour(self.stack, film, d, w, cos0)
        }
    }

    /// The texel of column `j` on the row whose film is `film` (at `row_cos`, rows 1 on).
    fn texel(&self, film: &FilmSeries, cos0: f64, j: usize) -> [f32; 3] {
        self.colour(film, cos0, j).map(|c| c as f32)
    }

    /// The films row 0's fit reads (`GrazingFit`).
    fn grazing_fit(&self) -> GrazingFit {
        let h = self.row_cos(1);
        let nodes = crate::optics::brdf::exact::gauss_legendre(GRAZING_FIT_NODES, 0.0, 1.0)
            .into_iter()
            .map(|(t, weight)| (t, weight, FilmSeries::new(self.stack, t * h)))
            .collect();
        GrazingFit { nodes, limit: FilmSeries::new(self.stack, GRAZING_LIMIT_COS) }
    }

    /// Row 0's texel at column `j`, `above` being row 1's: the value r0 that makes the
    /// first interval's linear interpolation, r0 (1 − t) + above t with t = cos / cos₁, closest
    /// to the film over it (least squares: r0 = 3 ∫₀¹ (R(t) − above t)(1 − t) dt), kept
    /// within the values the film takes there (its limit just above grazing light, the
    /// nodes', row 1's).
    fn grazing_texel(&self, fit: &GrazingFit, j: usize, above: [f32; 3]) -> [f32; 3] {
        let h = self.row_cos(1);
        let above = above.map(f64::from);
        let limit = self.colour(&fit.limit, GRAZING_LIMIT_COS, j);
        let (mut sum, mut low, mut high) = ([0.0; 3], limit, limit);
        for c in 0..3 {
            low[c] = low[c].min(above[c]);
            high[c] = high[c].max(above[c]);
        }
        for (t, weight, film) in &fit.nodes {
            let r = self.colour(film, t * h, j);
            for c in 0..3 {
                sum[c] += weight * (r[c] - above[c] * t) * (1.0 - t);
                low[c] = low[c].min(r[c]);
                high[c] = high[c].max(r[c]);
            }
        }
        [0, 1, 2].map(|c| (3.0 * sum[c]).clamp(low[c], high[c]) as f32)
    }

    /// Bakes the table for one material (parallel over angles; row 0 fitted once row 1 is
    /// known, parallel over columns).
    pub fn bake(stack: Stack, n_cos: usize, n_fine: usize, n_coarse: usize) -> Lut {
        let mut lut = Lut::shape(stack, n_cos, n_fine, n_coarse);
        let mut rows: Vec<Vec<[f32; 3]>> = (0..lut.n_cos)
            .into_par_iter()
            .map(|i| {
                if i == 0 {
                    return Vec::new();
                }
                let cos0 = lut.row_cos(i);
                let film = FilmSeries::new(stack, cos0);
                (0..lut.width()).map(|j| lut.texel(&film, cos0, j)).collect()
            })
            .collect();
        let fit = lut.grazing_fit();
        rows[0] = (0..lut.width()).into_par_iter().map(|j| lut.grazing_texel(&fit, j, rows[1][j])).collect();
        lut.texels = rows.into_iter().flatten().collect();
        lut
    }

    /// The coupling table from the texels: at each cos texel, roughness row of the rough
    /// lobe and thickness column, `energy::top_on_row_with_f32` with the film read along
    /// that column (linear in cos, as the texture filter reads it) and the row's
    /// normalisation X̄ for that column (`energy::ms_norm_on_row_f32`, once per column and
    /// row), and the material's path delta there (the same in every column). Parallel over
    /// columns.
    fn bake_coupling(&self) -> Vec<[f32; 8]> {
        let (w, n_cos) = (self.width(), self.n_cos);
        let path = path::cached(self.stack.n0, self.stack.n2);
        let rule = energy::LobeRule::of(self.stack.n0, self.stack.n1, self.stack.n2);
        let columns: Vec<Vec<[f32; 8]>> = (0..w)
            .into_par_iter()
            .map(|j| {
                let film = |c: f32| {
                    let (y0, fy) = self.cos_texel(c);
                    let (a, b) = (self.texels[y0 * w + j], self.texels[(y0 + 1) * w + j]);
                    [0, 1, 2].map(|k| (a[k] + (b[k] - a[k]) * fy).clamp(0.0, 1.0))
                };
                let mut column = Vec::with_capacity(E1_ROUGHNESS * n_cos);
                for i_r in 0..E1_ROUGHNESS {
                    let norm = energy::ms_norm_on_row_f32(i_r, &film, &path.through_f32, rule);
                    for i_cos in 0..n_cos {
                        let cos = coupling_texel_cos(i_cos, n_cos);
                        let top = energy::top_on_row_with_f32(cos, i_r, &film, &path.through_f32, rule, norm);
                        let (s, m) = (top.reflected, top.ms_amplitude);
                        let r = GridCell::<f32>::row_roughness(i_r);
                        let delta = energy::GridCell::<f32>::at(cos, r).bilinear(&path.delta_f32);
                        column.push([s[0], s[1], s[2], delta, m[0], m[1], m[2], 0.0]);
                    }
                }
                column
            })
            .collect();
        columns.into_iter().flatten().collect()
    }

    /// The thickness coordinate x (continuous texel column) of `thickness_nm`, in f32 as the
    /// shader computes it.
    #[inline]
    fn column_f32(&self, thickness_nm: f32) -> f32 {
        let d = thickness_nm.max(0.0);
        let fine_step = (FINE_MAX_NM / (self.n_fine - 1) as f64) as f32;
        let coarse_step = ((COARSE_MAX_NM - FINE_MAX_NM) / self.n_coarse as f64) as f32;
        let x = if d <= FINE_MAX_NM as f32 {
            d / fine_step
        } else {
            (self.n_fine - 1) as f32 + (d - FINE_MAX_NM as f32) / coarse_step
        };
        x.min((self.width() - 1) as f32)
    }

    /// The coupling table (see the field), baked on first use.
    pub fn coupling(&self) -> &[[f32; 8]] {
        self.coupling.get_or_init(|| self.bake_coupling())
    }

    /// The same table with its entries replaced (tests: the values the GPU holds, rounded
    /// to half floats; a broken table for a negative control). `table` must have the
    /// table's length.
    pub fn with_coupling(mut self, table: Vec<[f32; 8]>) -> Lut {
        assert_eq!(table.len(), self.width() * E1_ROUGHNESS * self.n_cos, "coupling table length");
        self.coupling = OnceLock::from(table);
        self
    }

    /// What the rough top reflects at cosine `cos` and roughness `roughness` through the
    /// film at `thickness_nm` (`energy::Top`), and the path delta there: the coupling table,
    /// linear in √cos between its texels (`coupling_texel`), in roughness between the rows as
    /// `energy::top_f32` interpolates them, and between thickness columns (one trilinear
    /// fetch: `brdf.wgsl`'s `coupling_table`).
    pub fn coupling_f32(&self, thickness_nm: f32, cos: f32, roughness: f32) -> (energy::Top<f32>, f32) {
        self.coupling_at(self.coupling(), &self.coupling_corners(thickness_nm, roughness), self.coupling_texel(cos))
    }

    /// `coupling_f32` for the two directions of one evaluation (light and view), which share
    /// the pixel's thickness and roughness: the four (thickness, roughness) corners and their
    /// weights are found once. The same values as two `coupling_f32` calls, bit for bit
    /// (`tests/brdf.rs`). Measured with `bench layered`'s cost loop (`accuracy::ns_per_eval`,
    /// one core, the thesis model 110 ns throughout), the layered model's CPU evaluation went
    /// from 150 to 124 ns with inputs in thickness order and from 218 to 187 ns at random
    /// thicknesses: finding the corners once, each corner's two cos texels read as one
    /// slice with their weights premultiplied, and this function inlined into the pair (which
    /// lets the two directions' loads overlap; without it 128 / 175 ns). In two halves
    /// (`coupling_pair_start`, `coupling_pair_read`) for a caller with work to do between them.
    pub fn coupling_pair_f32(&self, thickness_nm: f32, cos: [f32; 2], roughness: f32) -> [(energy::Top<f32>, f32); 2] {
        self.coupling_pair_read(&self.coupling_pair_start(thickness_nm, cos, roughness))
    }

    /// The first half of `coupling_pair_f32`: finds the texels it reads and asks the memory
    /// system for their cache lines, and returns at once. The CPU f32 twin starts it as soon
    /// as it knows the two cosines, so the lines arrive while it evaluates the specular lobe.
    /// Why: at random thicknesses each evaluation reads eight texel pairs somewhere new in a
    /// 10 MiB table, past a core's L2, and waited for them there. Asked for early, the
    /// layered model's cost went from 189–204 to 155–159 ns a call, against the thesis
    /// model's 104–115 (1.65–1.88× → 1.36–1.52×; `bench layered`'s cost loop, one core,
    /// BENCHMARKS.md "The coupling's lines asked for early"). Asking only for each pair's
    /// first line measured 176–186 ns: a pair of 32-byte texels usually spans two lines;
    /// `prefetchnta` 329–367. A hint only: x86-64's `prefetcht0`, nothing elsewhere.
    #[inline(always)]
    pub(crate) fn coupling_pair_start(&self, thickness_nm: f32, cos: [f32; 2], roughness: f32) -> CouplingFetch {
        let fetch = CouplingFetch {
            corners: self.coupling_corners(thickness_nm, roughness),
            texels: cos.map(|c| self.coupling_texel(c)),
        };
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
            let table = self.coupling();
            for (y0, _) in fetch.texels {
                for (first, _) in fetch.corners {
                    let pair: &[[f32; 8]; 2] = table[first + y0..first + y0 + 2].try_into().expect("two texels");
                    let (start, end) = (pair.as_ptr() as *const i8, pair[1][7..].as_ptr() as *const i8);
                    // SAFETY: `prefetcht0` is part of x86-64's baseline SSE, and a prefetch is a
                    // hint that never faults (both addresses lie in `table` anyway).
                    unsafe {
                        _mm_prefetch::<_MM_HINT_T0>(start);
                        _mm_prefetch::<_MM_HINT_T0>(end);
                    }
                }
            }
        }
        fetch
    }

    /// The second half of `coupling_pair_f32`: the light's and the view's coupling.
    #[inline(always)]
    pub(crate) fn coupling_pair_read(&self, fetch: &CouplingFetch) -> [(energy::Top<f32>, f32); 2] {
        let table = self.coupling();
        fetch.texels.map(|texel| self.coupling_at(table, &fetch.corners, texel))
    }

    /// The film's cos texel below `cos` and the weight of the one above it (linear
    /// filtering; the film's texels are uniform in cos).
    #[inline(always)]
    fn cos_texel(&self, cos: f32) -> (usize, f32) {
        self.texel_below(cos.clamp(0.0, 1.0) * (self.n_cos - 1) as f32)
    }

    /// The coupling table's cos texel below `cos` and the weight of the one above it: its
    /// texels are uniform in √cos (`coupling_texel_cos`), so the coordinate is √cos
    /// (n_cos − 1), as `brdf.wgsl`'s `coupling_table` computes it.
    #[inline(always)]
    fn coupling_texel(&self, cos: f32) -> (usize, f32) {
        self.texel_below(energy::GridCell::<f32>::axis_coordinate(cos, self.n_cos))
    }

    /// The cos texel below the continuous coordinate `y` and the weight of the next.
    #[inline(always)]
    fn texel_below(&self, y: f32) -> (usize, f32) {
        let y0 = (y as usize).min(self.n_cos - 2);
        (y0, y - y0 as f32)
    }

    /// The four (thickness column, roughness row) corners of a trilinear coupling fetch:
    /// each corner's first entry (at cos texel 0) and its weight.
    #[inline]
    fn coupling_corners(&self, thickness_nm: f32, roughness: f32) -> [(usize, f32); 4] {
        let x = self.column_f32(thickness_nm);
        let x0 = x as usize;
        let (x1, fx) = ((x0 + 1).min(self.width() - 1), x - x0 as f32);
        let (z0, fz) = GridCell::<f32>::row_below(roughness);
        let corner = |i_d: usize, wx: f32, i_r: usize, wz: f32| ((i_d * E1_ROUGHNESS + i_r) * self.n_cos, wx * wz);
        [
            corner(x0, 1.0 - fx, z0, 1.0 - fz),
            corner(x0, 1.0 - fx, z0 + 1, fz),
            corner(x1, fx, z0, 1.0 - fz),
            corner(x1, fx, z0 + 1, fz),
        ]
    }

    /// The coupling at the cos texel `y0` and the weight `fy` of the next (`coupling_texel`) from
    /// `table` (`coupling`), linear between the two texels, summed over `corners`.
    #[inline(always)]
    fn coupling_at(
        &self,
        table: &[[f32; 8]],
        corners: &[(usize, f32); 4],
        (y0, fy): (usize, f32),
    ) -> (energy::Top<f32>, f32) {
        let mut v = [0.0f32; 8];
        for &(first, weight) in corners {
            let [a, b]: &[[f32; 8]; 2] = table[first + y0..first + y0 + 2].try_into().expect("two texels");
            let (weight_a, weight_b) = (weight * (1.0 - fy), weight * fy);
            for c in 0..8 {
                v[c] += weight_a * a[c] + weight_b * b[c];
            }
        }
        (energy::Top { reflected: [v[0], v[1], v[2]], ms_amplitude: [v[4], v[5], v[6]] }, v[3])
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
        let w = self.width();
        let x = self.column_f32(thickness_nm);
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
        let w = self.width();
        self.bilinear_f64(thickness_nm, cos0, |i, j| self.texels[i * w + j])
    }

    /// The f64 bilinear lookup with texel (row `i`, column `j`) read by `texel`.
    fn bilinear_f64(&self, thickness_nm: f64, cos0: f64, texel: impl Fn(usize, usize) -> [f32; 3]) -> [f64; 3] {
        let (x, y) = self.coords(thickness_nm, cos0);
        let w = self.width();
        let (x0, y0) = (x as usize, y as usize);
        let (x1, y1) = ((x0 + 1).min(w - 1), (y0 + 1).min(self.n_cos - 1));
        let (fx, fy) = (x - x0 as f64, y - y0 as f64);
        let t = |i: usize, j: usize| texel(i, j).map(|v| v as f64);
        let (a, b, c, e) = (t(y0, x0), t(y0, x1), t(y1, x0), t(y1, x1));
        [0, 1, 2].map(|k| {
            let top = a[k] + (b[k] - a[k]) * fx;
            let bottom = c[k] + (e[k] - c[k]) * fx;
            top + (bottom - top) * fy
        })
    }
}

/// **Row 0, fitted.** Exactly grazing light reflects everything (`film::FilmAtAngle`), the
/// limit of a stack with an interface, but how near grazing the film gets there varies: an
/// ordinary stack's reflectance falls about linearly from 1 over the first row interval
/// (89.1–90°), one without an interface (n0 = n1 = n2, or n0 = n2 under a film of no
/// thickness) reflects nothing at every angle above grazing, and one with a faint interface
/// (n1 = 1.0000003 between indices of 1) or a film of a few nanometres between equal indices
/// falls from 1 to near 0 within a small part of the interval. Baked at cos 0, row 0 held 1
/// for all of them, and the lookups blended toward it from 89.1° on (a physics review: a
/// lossless white stack of index 1 reflected 1.056 at 89.5°, the spectral film 1.000); baked
/// at the limit just above 0 it held 0 for exactly equal indices only, 1 for n1 = 1.0000003,
/// and 0 under a 1 nm film between equal indices where the film reflects 0.99 at 89.99° (an
/// independent review of that fix). So each texel of row 0 is the least-squares fit of the
/// interval (`Lut::grazing_texel`): for a reflectance linear in cos it is the film at cos 0,
/// and where the film drops within the interval, what its average says. Red at 89.5° / 89.9°
/// / 89.99°, lookup against the spectral film (`brdf color --method lut` and `spectral`):
/// (1, 1.55, 2) at 400 nm 0.949 / 0.989 / 0.998 against 0.949 / 0.990 / 0.999 (as before);
/// (1, 1, 1) and (1, 1.0000003, 1) 0 / 0 / 0, as the film (0.450 / 0.890 / 0.989 before);
/// (1, 1.001, 1) 0.341 / 0.620 / 0.683 against 0.163 / 0.833 / 0.998 (0.481 / 0.896 /
/// 0.990 before: the fit spreads the error over the interval). Not mended: a film thinner
/// than the first thickness column (7.8 nm) between equal indices is read between column 0,
/// no film at all (reflecting nothing), and column 1, so near grazing light (1, 2, 1) at 1 nm
/// reads 0.117 / 0.125 / 0.127 against 0.443 / 0.901 / 0.999: the thickness axis cannot
/// hold a reflectance that jumps at a thickness of 0 (row 0 holding 1 had put it right there
/// by accident, and every stack without an interface wrong). The fit's price, from a second
/// review's sweep (indices 1–3, 0–2000 nm, 88–89.99°, 129,024 lookups against 76a80a9's
/// table: 1,852 closer to the spectral film by more than 0.05, 1,039 further, the RMS over
/// 89–90° lower for every stack): where the film falls steeply within the interval from its
/// limit of 1, exactly grazing light now reads the fit, below 1 and tinted — a film index
/// close to the ambient's ((1.5, 1.52, 3) at 600 nm reads [0.74, 0.87, 1.0] at 90° against
/// 1.0, but 0.40 against 0.30 at 89.5°, where the table read 0.52) or a critical angle just
/// short of 90° ((1.0000003, 1, 1) reads 0.15 at 89.99° against 1.0). No built-in material
/// is among them (a film index of 1.55 over air or water).
const GRAZING_FIT_NODES: usize = 8;

/// The cosine whose film stands for grazing light's limit in row 0's fit (its clamp).
const GRAZING_LIMIT_COS: f64 = 1e-9;

/// The films row 0's fit reads: at the Gauss–Legendre nodes t of the first row interval
/// (cos = t cos₁, with their weights), and at the limit just above grazing light.
struct GrazingFit {
    nodes: Vec<(f64, f64, FilmSeries)>,
    limit: FilmSeries,
}

/// The default table (`Lut::bake_default`) with each texel computed on first read, for
/// queries: one film colour reads 4 of its 20,480 texels (below the first row's cosine, 89.1°,
/// row 0's fit reads nine more films and row 1: 4.7 times the time of a query elsewhere, a
/// review measured), where baking the whole table for
/// it took 2.6 s of CPU here (`brdf color --method lut`); the queries of a batch share
/// what earlier ones computed, so while the table is kept (`query`'s cache) a batch never
/// computes more than the bake. Its values are the baked table's, bit for bit (the test
/// below).
pub struct LazyLut {
    shape: Lut,
    /// Each row's film series, made on the row's first read.
    rows: Vec<OnceLock<FilmSeries>>,
    /// Row 0's fit, made on its first read.
    grazing: OnceLock<GrazingFit>,
    texels: Vec<OnceLock<[f32; 3]>>,
}

impl LazyLut {
    pub fn new(stack: Stack) -> LazyLut {
        let (a, b, c) = DEFAULT_SIZE;
        let shape = Lut::shape(stack, a, b, c);
        let rows = (0..shape.n_cos).map(|_| OnceLock::new()).collect();
        let texels = (0..shape.n_cos * shape.width()).map(|_| OnceLock::new()).collect();
        LazyLut { shape, rows, grazing: OnceLock::new(), texels }
    }

    /// `Lut::lookup_f64` of the baked table.
    pub fn lookup_f64(&self, thickness_nm: f64, cos0: f64) -> [f64; 3] {
        self.shape.bilinear_f64(thickness_nm, cos0, |i, j| self.texel(i, j))
    }

    /// The texel (row `i`, column `j`), computed on its first read as `Lut::bake` does.
    fn texel(&self, i: usize, j: usize) -> [f32; 3] {
        let shape = &self.shape;
        *self.texels[i * shape.width() + j].get_or_init(|| {
            if i == 0 {
                let fit = self.grazing.get_or_init(|| shape.grazing_fit());
                return shape.grazing_texel(fit, j, self.texel(1, j));
            }
            let cos0 = shape.row_cos(i);
            let film = self.rows[i].get_or_init(|| FilmSeries::new(shape.stack, cos0));
            shape.texel(film, cos0, j)
        })
    }

    /// How many texels have been computed.
    #[cfg(test)]
    fn computed(&self) -> usize {
        self.texels.iter().filter(|t| t.get().is_some()).count()
    }
}

/// The spectral colour averaged over thicknesses [d − w/2, d + w/2] (w = 0: at d).
pub fn box_colour(stack: Stack, film: &FilmSeries, d: f64, w: f64, cos0: f64) -> [f64; 3] {
    let obs = Observer::get();
    // Where the series does not converge (an evanescent film, near grazing light), the
    // exact film at this angle, its wavelength-free parts computed once.
    let exact = (!film.usable()).then(|| FilmAtAngle::new(stack, d, cos0));
    let cos1 = film.cos1.unwrap_or(0.0);
    let xyz = obs.xyz(|lambda| {
        if let Some(exact) = &exact {
            return exact.reflectance(lambda);
        }
        let k = 4.0 * std::f64::consts::PI * stack.n1 * cos1 / lambda;
        film.reflectance(k * d, k * w)
    });
    xyz_to_linear_srgb(xyz)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A stack without an interface, or with one too faint to reflect above grazing light,
    /// reflects nothing near grazing light in the table, as the spectral film says; the row
    /// at grazing held the film at cos 0, which reflects everything, and lookups at 89.5°
    /// read 0.45 (seen failing), and held at the limit just above it, 1 for n1 = 1.0000003
    /// (seen failing). Control: a stack with an interface reads the spectral film's
    /// near-total reflection within 0.002 there.
    #[test]
    fn a_stack_without_an_interface_reflects_nothing_near_grazing_light() {
        use crate::optics::film::Stack;
        let matched = [
            (Stack { n0: 1.0, n1: 1.0, n2: 1.0 }, 400.0),
            (Stack { n0: 1.0, n1: 1.000_000_3, n2: 1.0 }, 400.0),
            (Stack { n0: 1.5, n1: 2.0, n2: 1.5 }, 0.0),
        ];
        for (stack, d) in matched {
            let lut = LazyLut::new(stack);
            for cos in [0.0, 0.001, 0.0087, 0.02] {
                let r = lut.lookup_f64(d, cos);
                assert!(r.iter().all(|c| c.abs() < 1e-3), "{stack:?} d {d} cos {cos}: {r:?}");
            }
        }
        let lut = LazyLut::new(Stack::THESIS);
        for cos in [0.0017, 0.0087] {
            let (r, exact) = (lut.lookup_f64(400.0, cos), crate::optics::film_rgb_reference(Stack::THESIS, 400.0, cos));
            assert!((0..3).all(|c| (r[c] - exact[c]).abs() < 0.002), "{cos}: {r:?} vs {exact:?}");
        }
    }

    /// The lazy table reads the baked table's values, bit for bit, and computes only the
    /// texels its lookups read (four for one lookup inside the table; one at a corner).
    #[test]
    fn a_lazy_lut_reads_the_baked_values_and_computes_only_what_it_reads() {
        let stack = Stack { n0: 1.0, n1: 1.4, n2: 1.8 };
        let baked = Lut::bake_default(stack);
        let lazy = LazyLut::new(stack);
        assert_eq!(lazy.lookup_f64(350.0, 0.61), baked.lookup_f64(350.0, 0.61));
        assert_eq!(lazy.computed(), 4);
        let mut rng = 0x2545_f491_4f6c_dd1d_u64;
        let mut uniform = || {
            rng ^= rng << 13;
            rng ^= rng >> 7;
            rng ^= rng << 17;
            (rng >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..200 {
            let (thickness_nm, cos0) = (uniform() * 25_000.0, uniform());
            assert_eq!(
                lazy.lookup_f64(thickness_nm, cos0),
                baked.lookup_f64(thickness_nm, cos0),
                "{thickness_nm} {cos0}"
            );
        }
        for (thickness_nm, cos0) in [(0.0, 0.0), (0.0, 1.0), (1e7, 1.0), (FINE_MAX_NM, 0.5)] {
            assert_eq!(
                lazy.lookup_f64(thickness_nm, cos0),
                baked.lookup_f64(thickness_nm, cos0),
                "{thickness_nm} {cos0}"
            );
        }
        assert!(lazy.computed() < 1000, "{} texels computed", lazy.computed());
    }

    /// `DEFAULT_WIDTH`, which the renderer checks a GPU against, is what a default bake makes.
    #[test]
    fn a_default_lut_has_default_width_thickness_columns() {
        assert_eq!(Lut::bake_default(Stack::THESIS).width(), DEFAULT_WIDTH);
    }
}
