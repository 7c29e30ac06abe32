//! The pigment layer's path for light that a rough top lets in: an effective cosine per
//! material, so the layered model attenuates the light that crosses a rough top as it is.
//!
//! A smooth top refracts light from a direction at cosine μ to the one cosine cos_t(μ) of
//! Snell's law, and the pigment layer lets exp(−τ / cos_t) of it through. A rough top
//! refracts it through tilted microfacets (at grazing light and high roughness, through more
//! than one), so the light crosses the layer at a spread of cosines, more obliquely on
//! average, and less of it survives: with cos_t the layered model was too bright at
//! roughness ≥ 0.6 with absorption (`bench layered`, 40,000 photons: mean / p95 / max ΔE00
//! 0.80 / 2.36 / 5.15 with cos_t, 0.61 / 1.38 / 3.73 with this table).
//!
//! The table holds, per (μ, r) on the rough lobe's grid (`energy::E1_MU` × `E1_ROUGHNESS`),
//! the cosine cos_eff with exp(−τ_ref / cos_eff) = ⟨exp(−τ_ref / μt)⟩ over the cosines μt at
//! which the top lets light in, walked photon by photon through the rough top alone
//! (`walk::transmitted_cosines`: the microsurface with heights, every microfacet reflection
//! and refraction followed, the plain Fresnel reflectance of n0 | n2). One τ_ref serves
//! every τ: matched at τ_ref = 0.5, the same grid (τ = 0.4 and 1) measured 0.61 / 1.38 /
//! 3.73 against 0.60 / 1.33 / 3.66 with the exact mean at each τ. Row r = 0 is Snell's
//! cos_t exactly. The table depends on n0 and n2 only, and is kept per material (`cached`;
//! the thesis' indices, every built-in species', ship built: `baked`); the renderer sends it
//! to the shader in the rough lobe table's spare slot.
//!
//! **Light that comes straight back through the top.** The table also holds, per entry, a
//! rule for the light that a rough top lets in and sends straight back out without it
//! reaching the pigment layer (`walk::through_cosines`: in through one microfacet, out
//! through a second, reflected up by a third). The walk of the whole stack finds it, and
//! without it the layered model reflected up to 0.02 too little at grazing light and
//! roughness 0.9 (`bench layered`'s largest errors, on (1, 1.56, 1.33)). It depends on the
//! film at the microfacets it meets, which the table cannot know, so it is written as what
//! the bare interface n0 | n2 does, reweighted by the film:
//!
//! ```text
//! q(μ, r) = (1 − E₁⟨F⟩ − (1 − E₁) g) W (u₁ F(t₁) + u₂ F(t₂) + (1 − u₁ − u₂) F(t₃))
//! ```
//!
//! with 1 − E₁⟨F⟩ − (1 − E₁) g the light the top lets in before any comes straight back
//! (⟨F⟩ the film averaged over the rough lobe's microfacet angles, g its multiple
//! scattering's share: `energy::parts_on_row` has them), W the share of the light that entered the bare surface
//! which came straight back (times the mean of 1 / F_bare below), and a three-point Gauss
//! rule (nodes t, weights u) for the microfacet cosines of the last reflection from
//! above, weighted by 1 / F_bare (so that a film reweights each photon's reflection by
//! F / F_bare; two points until the lobe's rule grew to five: `through_rule`). Where
//! n0 > n2, last reflections beyond the critical angle are total whatever the film: they
//! take a node of their own at grazing (c = 0, where every film reflects all), the rest a
//! two-point rule, and W reads the bare interface exactly (`through_rule`). The form
//! was chosen against walks of the stack with its film, 96 cases
//! (two film indices, n2 1.33 and 1.55, films of 150, 250 and 650 nm, 60–85°, roughness
//! 0.6–0.9, two channels; each case's own walk giving W and the rule): off by 0.0005 on
//! average and 0.0065 at most, where q itself averages 0.0075 and reaches 0.046; the film
//! at the mean cosines alone was off by twice as much on average. The table as built (a
//! rule per entry where its walk brought enough photons back, else its roughness row's; W a
//! share of what entered: `through_rule`) is checked by `tests/brdf.rs`'s walk at 85° and
//! by `bench layered` (BENCHMARKS.md).

use std::sync::{Arc, Mutex};

use super::energy::{E1_MU, E1_ROUGHNESS, GridCell, node_mu};
use super::{COS_MIN, cos_transmitted, ggx_alpha};

/// The optical depth the effective cosine is matched at (see the module's measurements).
const TAU_REF: f64 = 0.5;
/// Photons per table entry: the mean of 4,096 values in [0, 1] has σ ≤ 0.5 / 64 ≈ 0.008.
const PHOTONS: u64 = 4096;
/// Photons per entry of the rule for light that comes straight back (`through_walk`): it is
/// about 1 % of the light where it matters, so 16,384 photons give ~160 of them (σ ≈ 8 %
/// of q, ≤ 0.0015 in reflectance).
const THROUGH_PHOTONS: u64 = 16_384;
/// Fewer walked photons than this come straight back on a whole roughness row: the row's
/// rule is 0.
const THROUGH_MIN: usize = 16;
/// Nodes of the rule for the last reflection's cosine of light straight back.
pub const THROUGH_NODES: usize = 3;
/// Fewest photons straight back from which an entry has its own rule (`through_rule`).
const THROUGH_ENTRY_MIN: usize = 64;
/// Slots of an entry of that rule (`PathTable::through`): [W, t₁, t₂, t₃, u₁, u₂] (the third
/// weight is 1 minus the others).
pub const THROUGH_LEN: usize = 2 * THROUGH_NODES;
/// The most grazing light walked (μ = 0 itself never meets the top).
pub(super) const MU_MIN: f64 = 1e-3;

/// cos_eff − cos_t over (μ, r) on the lobe grid (row-major by roughness): the rough path's
/// departure from Snell's, which is 0 in row r = 0, so a smooth top is Snell's law exactly
/// at every μ (interpolating cos_eff itself would bend cos_t between the nodes, and across
/// the critical angle where n0 > n2). Beyond that critical angle, where Snell's law lets no
/// light in and a rough top does, cos_t is 0 (`snell_cos`) and the delta is cos_eff.
#[derive(Debug, Clone, PartialEq)]
pub struct PathTable {
    pub n0: f64,
    pub n2: f64,
    pub delta: Vec<f64>,
    /// `delta` in f32, as the shader holds it (the first slot of each lobe table entry,
    /// `render::engine::film::lobe_table`, and the film table's coupling texture:
    /// `lut::Lut::coupling`).
    pub delta_f32: Vec<f32>,
    /// Per entry (the same grid), the rule for light that comes straight back through the
    /// top (the module's q): [W, t₁, t₂, t₃, u₁, u₂] (`THROUGH_LEN`). W = 0 on row r = 0.
    pub through: Vec<[f64; THROUGH_LEN]>,
    /// `through` in f32, as the shader holds it (each lobe table entry's slots from
    /// `render::engine::film::LOBE_THROUGH_SLOT`).
    pub through_f32: Vec<[f32; THROUGH_LEN]>,
}

impl PathTable {
    /// The table for indices (n0, n2): the baked one for the thesis' indices (`baked`), else
    /// `walked`.
    pub fn new(n0: f64, n2: f64) -> PathTable {
        super::baked::path_table(n0, n2).unwrap_or_else(|| PathTable::walked(n0, n2))
    }

    /// The table for indices (n0, n2), walked entry by entry (about 10⁷ photon walks: 2·10⁶
    /// for the path, 8·10⁶ for light straight back; 1.4 s on this machine's two cores), the
    /// entries split over the machine's cores by plain threads (`energy::split_over_threads`:
    /// not the rayon pool, since `cached` builds under a lock that callers on the pool wait
    /// for). Each entry has its own seed, so the table is the same on any number of threads.
    pub fn walked(n0: f64, n2: f64) -> PathTable {
        if n0 == n2 {
            return PathTable::index_matched(n0);
        }
        let walked =
            super::energy::split_over_threads(E1_ROUGHNESS * E1_MU, |k| (entry(n0, n2, k), through_walk(n0, n2, k)));
        let (delta, walks): (Vec<f64>, Vec<ThroughWalk>) = walked.into_iter().unzip();
        let through = through_rule(n0, n2, &walks);
        PathTable::from_parts(n0, n2, delta, through)
    }

    /// The table of these entries, with their f32 copies.
    pub fn from_parts(n0: f64, n2: f64, delta: Vec<f64>, through: Vec<[f64; THROUGH_LEN]>) -> PathTable {
        let delta_f32 = delta.iter().map(|d| *d as f32).collect();
        let through_f32 = through.iter().map(|t| t.map(|v| v as f32)).collect();
        PathTable { n0, n2, delta, delta_f32, through, through_f32 }
    }

    /// The table of a top between equal indices, whose bare interface is no interface at
    /// all: light goes straight through, at cosine μ = cos_t (every δ 0), and the bare
    /// interface reflects none, so none comes straight back (every W 0; a film between
    /// them is the film's own, which the rule's reweighting cannot add to W = 0). Its walk
    /// finds exactly that (`tests`), photon by photon, but slowly: index-matched, each photon crosses the microsurface back and
    /// forth many times before it leaves (27 s for the table, against 1.4 s for n2 = 1.2 and
    /// 4.9 s for 1.001; `brdf albedo --n0 1 --n2 1` took 74 s).
    fn index_matched(n: f64) -> PathTable {
        let entries = E1_ROUGHNESS * E1_MU;
        PathTable::from_parts(n, n, vec![0.0; entries], vec![NO_THROUGH_RULE; entries])
    }

    /// cos_eff at (μ, r) for light whose Snell cosine in the pigment layer is `cos_t`
    /// (`snell_cos`: 0 beyond the critical angle).
    pub fn cos_eff(&self, cos_t: f64, cos: f64, roughness: f64) -> f64 {
        (cos_t + GridCell::<f64>::at(cos, roughness).bilinear(&self.delta)).max(COS_MIN)
    }
}

/// Snell's cosine in the pigment layer of light from a direction at cosine `cos` above, 0
/// beyond the critical angle of n0 > n2 (where Snell's law lets none in, and a rough top's
/// tilted microfacets still do): the cosine the path table's deltas are taken from.
pub fn snell_cos(n0: f64, n2: f64, cos: f64) -> f64 {
    cos_transmitted(n0, n2, cos).unwrap_or(0.0)
}

/// Entry k of the table for (n0, n2): cos_eff − cos_t, walked (see `PathTable`).
fn entry(n0: f64, n2: f64, k: usize) -> f64 {
    let (i_mu, i_r) = (k % E1_MU, k / E1_MU);
    if i_r == 0 {
        return 0.0;
    }
    let mu = node_mu(i_mu).max(MU_MIN);
    // Beyond the critical angle of n0 > n2 a rough top still lets light in, through tilted
    // microfacets; Snell's cosine is taken as 0 there (`snell_cos`), so the delta is the
    // effective cosine itself, and meets the one inside the critical angle at it.
    let cos_t = snell_cos(n0, n2, mu);
    let r = GridCell::<f64>::row_roughness(i_r);
    let alpha = ggx_alpha(r);
    let wi = [(1.0 - mu * mu).sqrt(), 0.0, mu];
    let cosines = super::walk::transmitted_cosines(wi, alpha, n0, n2, PHOTONS, seed_of(k));
    if cosines.is_empty() {
        return 0.0;
    }
    let mean = cosines.iter().map(|c| (-TAU_REF / c.max(COS_MIN)).exp()).sum::<f64>() / cosines.len() as f64;
    let cos_eff = if mean > 0.0 { (-TAU_REF / mean.ln()).clamp(COS_MIN, 1.0) } else { COS_MIN };
    cos_eff - cos_t
}

/// What `through_walk` found at one entry: photons that entered, photons that came straight
/// back, the cosines of their last reflection from above.
type ThroughWalk = (u64, u64, Vec<f64>);

/// Entry k's walk for the rule for light that comes straight back through the top (the
/// module's q): of `THROUGH_PHOTONS`, how many entered the surface and how many of those
/// came straight back, and the cosines of their last reflection from above
/// (`walk::through_cosines`); none on row r = 0.
fn through_walk(n0: f64, n2: f64, k: usize) -> ThroughWalk {
    let (i_mu, i_r) = (k % E1_MU, k / E1_MU);
    if i_r == 0 {
        return (0, 0, Vec::new());
    }
    let mu = node_mu(i_mu).max(MU_MIN);
    let r = GridCell::<f64>::row_roughness(i_r);
    let alpha = ggx_alpha(r);
    let wi = [(1.0 - mu * mu).sqrt(), 0.0, mu];
    let seed = seed_of(k) ^ 0x7468_726f_7567_6821;
    super::walk::through_cosines(wi, alpha, n0, n2, THROUGH_PHOTONS, seed)
}

/// The rule [W, t₁, t₂, t₃, u₁, u₂] per entry from the entries' walks (`through_walk`): W
/// and the three-point Gauss rule for the last reflection's cosines, weighted by 1 / F_bare
/// (`energy::Rule::gauss`). An entry whose walk brought at least `THROUGH_ENTRY_MIN` such
/// photons back has its own rule; the others (normal and near-normal light, where q is
/// small) take the rule of all their roughness row's cosines. (Until the film's rule grew
/// to five points, this was a two-point rule per row, whose nodes moved by a few hundredths
/// with μ: 0.47–0.55 and 0.87–0.93 on the roughest row of n0 | n2 = 1 | 1.56. But a 650 nm
/// film's colour turns within that spread, and the row's rule read it off at the grazing
/// entries where q is largest: with the walk's own q and its exact reweighting at k_d = 0,
/// roughness 0.9 and 85° on (1.33, 1.55, 2.0), the top was 0.5 ΔE00 off the walk, and 2.8
/// with the row's two-point rule; 1.9 with a three-point rule per row, 1.6 per entry.) W carries each entry's own share: of
/// the photons that entered the surface, the fraction that came straight back (at most 1;
/// the film's way in, 1 − E₁⟨F⟩ − (1 − E₁) g, scales it in the rule; until a later session
/// 1 − ⟨F⟩, the way in through the lobe's first microfacet alone, which left out most of
/// the light a pigment layer less dense than the ambient sends straight back). Over the bare interface's way in as
/// the lobe reads it, 1 − ⟨F_bare⟩, the fraction measured 2.39 for `bench layered`'s max
/// against 2.72 with the share (both at 100,000 photons), but beyond the critical angle of
/// n0 > n2, where the bare interface lets almost nothing in, it multiplied a few walked
/// photons without bound (the stress test's grazing views: the f32 table 15 % off the f64
/// rule, capped at 1 or not).
/// A row with fewer than `THROUGH_MIN` such photons in all has none (W = 0).
fn through_rule(n0: f64, n2: f64, walks: &[ThroughWalk]) -> Vec<[f64; THROUGH_LEN]> {
    let bare = super::walk::bare_interface(n0, n2);
    // Where n0 > n2, last reflections beyond the critical angle (microfacet cosine below
    // this) are total for every film: F = F_bare = 1.
    let total_below = if n0 > n2 { (1.0 - (n2 / n0) * (n2 / n0)).sqrt() } else { 0.0 };
    let mut rule = vec![NO_THROUGH_RULE; walks.len()];
    for (i_r, row) in walks.chunks(E1_MU).enumerate().skip(1) {
        let cosines: Vec<f64> = row.iter().flat_map(|(_, _, c)| c.iter().copied()).collect();
        if cosines.len() < THROUGH_MIN {
            continue;
        }
        // The rule and the mean of 1 / F_bare of a set of last reflections' cosines, each
        // weighted by 1 / F_bare there.
        let rule_of = |cosines: &[f64]| {
            let (total_reflections, partial): (Vec<f64>, Vec<f64>) = cosines.iter().partition(|c| **c < total_below);
            if total_reflections.is_empty() {
                let (rule, weight) = weighted_rule::<THROUGH_NODES>(cosines, &bare);
                return (rule, weight / cosines.len() as f64);
            }
            // Total reflections (weight 1 each, F = 1 for every film) on a node at grazing,
            // where every film reflects all; a Gauss rule of the other nodes for the rest,
            // and the mean of 1 / F_bare taken as the inverse of the rule's reading of the
            // bare interface, so that it gives the bare interface the walk's share exactly
            // (the rule reweights by the film's F over the bare's at its nodes). One rule
            // over both misread the corner: on 1.5 | 1.33 at roughness 1 and 70° it read
            // the bare F as 0.170 where the photons' weighted mean is 0.258, and q two
            // thirds of the walk's; the split rule alone read 0.518 of the walk's 0.543.
            let (rest, partial_weight) = weighted_rule::<{ THROUGH_NODES - 1 }>(&partial, &bare);
            let total_share = total_reflections.len() as f64 / (total_reflections.len() as f64 + partial_weight);
            let mut cos = [0.0; THROUGH_NODES];
            let mut weight = [0.0; THROUGH_NODES];
            weight[0] = total_share;
            for k in 1..THROUGH_NODES {
                cos[k] = rest.cos[k - 1];
                weight[k] = (1.0 - total_share) * rest.weight[k - 1];
            }
            let split = super::energy::Rule { cos, weight };
            (split, 1.0 / split.mean(|c| bare(true, c)))
        };
        let row_rule = rule_of(&cosines);
        for (i_mu, (entered, count, own)) in row.iter().enumerate() {
            let share = if *entered > 0 { *count as f64 / *entered as f64 } else { 0.0 };
            let (last, mean_inverse) = if own.len() >= THROUGH_ENTRY_MIN { rule_of(own) } else { row_rule };
            let mut entry = [share * mean_inverse; THROUGH_LEN];
            for (slot, value) in entry[1..].iter_mut().zip(last.slots()) {
                *slot = value;
            }
            rule[i_r * E1_MU + i_mu] = entry;
        }
    }
    rule
}

/// The Gauss rule of N points of last reflections' cosines, each weighted by 1 / F_bare
/// there (`through_rule`), and the weights' sum; a point at 1 and a sum of 0 where there
/// are none (the caller then gives the rule no weight).
fn weighted_rule<const N: usize>(cosines: &[f64], bare: &impl Fn(bool, f64) -> f64) -> (super::energy::Rule<N>, f64) {
    if cosines.is_empty() {
        return (super::energy::Rule::point(1.0), 0.0);
    }
    let weights: Vec<f64> = cosines.iter().map(|c| 1.0 / bare(true, *c).max(1e-9)).collect();
    let total: f64 = weights.iter().sum();
    let moment = |p: i32| cosines.iter().zip(&weights).map(|(c, w)| w * c.powi(p)).sum::<f64>() / total;
    let moments: Vec<f64> = (0..2 * N).map(|p| moment(p as i32)).collect();
    (super::energy::Rule::gauss(&moments), total)
}

/// The rule of an entry from which no light comes straight back: W = 0 (its nodes and
/// weights a valid rule that weighs nothing).
const NO_THROUGH_RULE: [f64; THROUGH_LEN] = [0.0, 0.5, 0.5, 0.5, 1.0, 0.0];

/// A fixed seed per table entry.
fn seed_of(k: usize) -> u64 {
    0x9e37_79b9_7f4a_7c15 ^ (k as u64).wrapping_mul(0xbf58_476d_1ce4_e5b9)
}

/// The indices as f32: the key of a table and what it is built from, so the f64 and the
/// f32 paths (which carry the indices as f32) read one table whoever asks first.
fn key(n0: f64, n2: f64) -> (u32, u32) {
    ((n0 as f32).to_bits(), (n2 as f32).to_bits())
}

/// The table for indices (n0, n2), built once and kept (16 materials). Builds run one at a
/// time, each on the calling thread: a caller that finds its table being built waits for
/// it instead of walking the same photons again (the renderer asks from eight threads at
/// once), and no build waits on the thread pool, whose workers may be the waiting callers.
pub fn cached(n0: f64, n2: f64) -> Arc<PathTable> {
    static CACHE: Mutex<Vec<Arc<PathTable>>> = Mutex::new(Vec::new());
    static BUILDING: Mutex<()> = Mutex::new(());
    let find = || CACHE.lock().expect("path cache").iter().find(|t| key(t.n0, t.n2) == key(n0, n2)).cloned();
    if let Some(table) = find() {
        return table;
    }
    let _building = BUILDING.lock().expect("path build");
    if let Some(table) = find() {
        return table;
    }
    let table = Arc::new(PathTable::new(n0 as f32 as f64, n2 as f32 as f64));
    let mut cache = CACHE.lock().expect("path cache");
    if cache.len() >= 16 {
        cache.remove(0);
    }
    cache.push(table.clone());
    table
}

/// `f` of the table for (n0, n2): the layered model reads it twice per evaluation, so the
/// last table each thread used is kept at hand (no lock, no reference count).
pub fn with<R>(n0: f64, n2: f64, f: impl FnOnce(&PathTable) -> R) -> R {
    thread_local! {
        static LAST: std::cell::RefCell<Option<Arc<PathTable>>> = const { std::cell::RefCell::new(None) };
    }
    let mut f = Some(f);
    let held = LAST.with(|last| {
        let last = last.borrow();
        last.as_ref().filter(|t| key(t.n0, t.n2) == key(n0, n2)).map(|t| f.take().expect("once")(t))
    });
    if let Some(result) = held {
        return result;
    }
    // Not borrowed while the table is looked up or built.
    let table = cached(n0, n2);
    LAST.with(|last| *last.borrow_mut() = Some(table.clone()));
    f.take().expect("once")(&table)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optics::brdf::ggx::smith_lambda;

    /// A second method: ⟨exp(−τ/μt)⟩ over the single-scatter transmission lobe (Walter et
    /// al. 2007: visible normals for the incoming light, refraction through each, weighted
    /// by the Fresnel transmittance and the transmitted light's masking G1), by a
    /// deterministic midpoint quadrature over the visible-normal sampler's two uniforms.
    /// Where single scattering carries nearly all the light (moderate roughness, light not
    /// grazing) it must agree with the walked table.
    fn single_scatter_mean(n0: f64, n2: f64, mu: f64, alpha: f64, tau: f64) -> f64 {
        let w = [(1.0 - mu * mu).sqrt(), 0.0, mu];
        let eta = n0 / n2;
        let strata = 64;
        let (mut total, mut weighted) = (0.0, 0.0);
        for a in 0..strata {
            for b in 0..strata {
                let (u1, u2) = ((a as f64 + 0.5) / strata as f64, (b as f64 + 0.5) / strata as f64);
                let m = crate::optics::brdf::walk::visible_normal_at(w, alpha, u1, u2);
                let c = (w[0] * m[0] + w[1] * m[1] + w[2] * m[2]).max(0.0);
                let k = 1.0 - eta * eta * (1.0 - c * c);
                if k < 0.0 {
                    continue;
                }
                // The refracted travel direction's downward cosine.
                let t = [0, 1, 2].map(|i| -eta * w[i] + (eta * c - k.sqrt()) * m[i]);
                let mu_t = -t[2] / (t[0] * t[0] + t[1] * t[1] + t[2] * t[2]).sqrt();
                if mu_t <= 1e-9 {
                    continue;
                }
                let (rs, rp) = crate::optics::film::fresnel(n0, n2, c);
                let weight = (1.0 - 0.5 * (rs + rp)) / (1.0 + smith_lambda(mu_t, alpha));
                total += weight;
                weighted += weight * (-tau / mu_t).exp();
            }
        }
        weighted / total
    }

    /// The index-matched table (`PathTable::index_matched`) is what the walk finds: every
    /// photon goes straight through at its own cosine and none comes back, at every
    /// roughness and angle (a few hundred photons per entry on a coarse grid of entries).
    /// Negative control: indices 1 and 1.2 bend the light and send some back.
    #[test]
    fn an_index_matched_top_is_no_interface_as_walked() {
        let table = PathTable::new(1.4, 1.4);
        assert!(table.delta.iter().all(|d| *d == 0.0) && table.through.iter().all(|t| t[0] == 0.0));
        let walked = |n2: f64, k: usize| {
            let (i_mu, i_r) = (k % E1_MU, k / E1_MU);
            let mu = node_mu(i_mu).max(MU_MIN);
            let alpha = ggx_alpha(GridCell::<f64>::row_roughness(i_r));
            let wi = [(1.0 - mu * mu).sqrt(), 0.0, mu];
            let down = super::super::walk::transmitted_cosines(wi, alpha, 1.4, n2, 256, seed_of(k));
            let (entered, back, _) = super::super::walk::through_cosines(wi, alpha, 1.4, n2, 256, seed_of(k));
            (mu, down, entered, back)
        };
        for k in (E1_MU..E1_ROUGHNESS * E1_MU).step_by(37) {
            let (mu, down, entered, back) = walked(1.4, k);
            assert_eq!(down.len(), 256, "entry {k}: every photon goes through");
            assert!(down.iter().all(|c| (c - mu).abs() < 1e-9), "entry {k}: at its own cosine {mu}");
            assert_eq!((entered, back), (256, 0), "entry {k}");
        }
        let k = E1_ROUGHNESS * E1_MU - 3;
        let (mu, down, _, back) = walked(1.2, k);
        assert!(down.iter().any(|c| (c - mu).abs() > 1e-3) && back > 0, "entry {k}");
    }

    /// Tables of indices equal, far apart and either way round: every entry finite, the
    /// rule for light that comes straight back a valid one (W ≥ 0, nodes and weight in
    /// [0, 1]), none on the mirror row, and some where the top is rough.
    #[test]
    fn tables_of_any_indices_are_valid() {
        for (n0, n2) in [(1.0, 1.0), (1.9, 1.1), (1.0, 2.9), (1.5, 1.45), (2.0, 3.0), (1.2, 1.8)] {
            let table = PathTable::new(n0, n2);
            assert!(table.delta.iter().all(|d| d.is_finite()), "{n0} {n2}");
            for (k, entry) in table.through.iter().enumerate() {
                let w = entry[0];
                assert!(w.is_finite() && w >= 0.0, "{n0} {n2} entry {k}: W {w}");
                assert!(entry[1..].iter().all(|v| (0.0..=1.0).contains(v)), "{n0} {n2} entry {k}");
                assert!(entry[4] + entry[5] <= 1.0 + 1e-12, "{n0} {n2} entry {k}: weights {entry:?}");
                assert!(k >= E1_MU || w == 0.0, "{n0} {n2}: the mirror row has none");
            }
            if n0 != n2 {
                assert!(table.through.iter().any(|t| t[0] > 0.01), "{n0} {n2}: none came straight back");
            }
        }
    }

    #[test]
    fn the_table_is_the_same_walked_on_threads_as_entry_by_entry() {
        let table = PathTable::new(1.0, 1.55);
        let one_by_one: Vec<f64> = (0..E1_ROUGHNESS * E1_MU).map(|k| entry(1.0, 1.55, k)).collect();
        assert!(table.delta == one_by_one);
        assert!(table.delta.iter().any(|d| *d < -0.01), "a rough row departs from Snell's");
    }

    #[test]
    fn the_walked_path_meets_snell_at_r_0_and_single_scattering_where_it_dominates() {
        for (n0, n2) in [(1.0, 2.0), (1.0, 1.33), (1.33, 2.0)] {
            let table = PathTable::walked(n0, n2);
            // Row 0 is Snell's law exactly, between the nodes too.
            for i in 0..=100 {
                let mu = 0.005 + 0.99 * i as f64 / 100.0;
                let cos_t = cos_transmitted(n0, n2, mu).unwrap();
                assert_eq!(table.cos_eff(cos_t, mu, 0.0), cos_t);
            }
            let cos_eff = |i: usize, row: usize| {
                let mu = node_mu(i);
                let r = GridCell::<f64>::row_roughness(row);
                table.cos_eff(cos_transmitted(n0, n2, mu).unwrap(), mu, r)
            };
            // Rough rows at light within 60° of the normal: the walked mean against the
            // single-scatter quadrature at τ_ref (to 1 %: the walk's noise and the little
            // multiple scattering there), and at τ = 1.5 through the one cos_eff (to 3 %: the
            // price of one τ_ref for every τ).
            for row in [2, 5] {
                let r = GridCell::<f64>::row_roughness(row);
                for i in [22, 27, 31] {
                    let mu = node_mu(i);
                    let cos_eff = cos_eff(i, row);
                    for (tau, tolerance) in [(TAU_REF, 0.01), (1.5, 0.03)] {
                        let walked = (-tau / cos_eff).exp();
                        let quadrature = single_scatter_mean(n0, n2, mu, ggx_alpha(r), tau);
                        assert!(
                            (walked - quadrature).abs() < tolerance * quadrature,
                            "n0 {n0} n2 {n2} r {r:.2} μ {mu:.2} τ {tau}: walked {walked:.4}, quadrature {quadrature:.4}"
                        );
                    }
                }
            }
            // At r = 0.6 and normal incidence single scattering still carries most of the
            // light: the walked table is at least twice as close to the quadrature as Snell's
            // path is (measured: 0.0031 against 0.0117 for n2 = 2, 0.0012 against 0.0033
            // for n2 = 1.33), so a table left at Snell's fails here.
            let (row, i) = (9, 31);
            let walked = (-TAU_REF / cos_eff(i, row)).exp();
            let quadrature = single_scatter_mean(n0, n2, 1.0, 0.36, TAU_REF);
            let snell = (-TAU_REF / cos_eff(i, 0)).exp();
            assert!(
                (walked - quadrature).abs() < 0.5 * (snell - quadrature).abs(),
                "n0 {n0} n2 {n2}: walked {walked:.4}, quadrature {quadrature:.4}, Snell {snell:.4}"
            );
            // Rougher tops send the light in more obliquely: at r = 0.8 and 45° the path is
            // longer than Snell's by more than the walk's noise.
            assert!(cos_eff(22, 12) < 0.97 * cos_eff(22, 0), "{n0} {n2}");
        }
    }
}
