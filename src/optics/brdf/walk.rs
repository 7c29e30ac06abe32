//! The stochastic reference: photons followed one by one through the stack, with a rough
//! (GGX) or smooth top: position-free layered transport (as Guo, Hašan & Zhao 2018 and
//! pbrt-v4's `LayeredBxDF`), with the rough top walked as a microsurface (below). It shares no formula with `exact.rs` beyond the
//! film's reflectance, so the closed form's geometric series, its escape cone, its (n0/n2)²
//! and its K and E are checked against a simulation of the physics they describe.
//!
//! A photon from direction wi meets the top, a Smith microsurface walked with heights as
//! Heitz, Hanika, d'Eon & Dachsbacher 2016 ("Multiple-scattering microfacet BSDFs with the
//! Smith model") walk a rough dielectric: at each intersection a microfacet normal m is
//! drawn from GGX's distribution of visible normals (Heitz 2018; m = n for a smooth top),
//! the film reflects with probability R(wi·m) (from above, or from below with total
//! internal reflection) or the photon refracts through m by Snell's law, and the next
//! intersection's height follows from Smith's masking, so a reflected photon may meet the
//! surface again (its single scattering is the height-correlated G2 lobe; its multiple
//! scattering conserves energy, as a real interface does). In the pigment layer the photon
//! survives a path at cosine μ with probability exp(−τ/|μ|), at the base with probability
//! k_d, leaving in a cosine-distributed direction; it is followed until it escapes or is
//! absorbed. Analog (0/1) tallies make the noise binomial: σ = √(p(1 − p)/N).
//!
//! (The first version ended the walk at the first upward reflection, without the height
//! that decides whether the microsurface masks it. That overstated single scattering: at
//! roughness 0.9 and normal incidence its specular albedo was 0.070 where the height walk
//! gives 0.048, and the error table measured the models against that bias.)
//!
//! Film colours come from tables over the cosine (2049 entries from above and from below,
//! linear interpolation: bias below 1e-5 next to the square-root kink at a critical angle),
//! each channel walked separately with its own R, τ and k_d.

use super::Layers;
use super::exact::{reflectance, reversed};
use crate::optics::film::Stack;

/// Entries of the film tables over cos ∈ [0, 1].
const TABLE_SIZE: usize = 2049;
/// Interface events after which a photon is counted as absorbed (never reached in practice:
/// with K ≤ 0.9 the chance of 10,000 bounces is below 1e-400).
const MAX_EVENTS: usize = 10_000;

/// The film's reflectance colour from above and from below, tabulated over the cosine.
#[derive(Debug, Clone)]
pub struct FilmTables {
    pub stack: Stack,
    above: Vec<[f64; 3]>,
    below: Vec<[f64; 3]>,
}

impl FilmTables {
    pub fn new(stack: Stack, thickness_nm: f64) -> FilmTables {
        let cos = |i: usize| i as f64 / (TABLE_SIZE - 1) as f64;
        // Colours relative to the white point and in [0, 1] (`exact::reflectance`): R is a
        // probability.
        FilmTables {
            stack,
            above: (0..TABLE_SIZE).map(|i| reflectance(stack, thickness_nm, cos(i))).collect(),
            below: (0..TABLE_SIZE).map(|i| reflectance(reversed(stack), thickness_nm, cos(i))).collect(),
        }
    }

    /// The film's reflectance colour from above at cosine `cos` (interpolated; within 1e-5
    /// of `exact::reflectance`): a film function for the models that agrees with the one K
    /// and E are computed from.
    pub fn above(&self, cos: f64) -> [f64; 3] {
        [0, 1, 2].map(|c| FilmTables::lookup(&self.above, cos, c))
    }

    fn lookup(table: &[[f64; 3]], cos: f64, channel: usize) -> f64 {
        let x = cos.clamp(0.0, 1.0) * (TABLE_SIZE - 1) as f64;
        let i = (x as usize).min(TABLE_SIZE - 2);
        let f = x - i as f64;
        table[i][channel] * (1.0 - f) + table[i + 1][channel] * f
    }
}

/// What the photons did: the fractions reflected by the top alone (specular) and after
/// entering the stack (diffuse), per channel, with their standard errors; and the diffuse
/// photons' outgoing cosines in `bins` equal bins of cos θo.
#[derive(Debug, Clone, serde::Serialize)]
pub struct WalkResult {
    pub photons: u64,
    pub specular: [f64; 3],
    pub diffuse: [f64; 3],
    pub specular_sigma: [f64; 3],
    pub diffuse_sigma: [f64; 3],
    /// Per channel, per bin of cos θo (bin b covers [b/n, (b+1)/n)): fraction of photons.
    pub diffuse_bins: Vec<[f64; 3]>,
}

impl WalkResult {
    pub fn total(&self) -> [f64; 3] {
        [0, 1, 2].map(|c| self.specular[c] + self.diffuse[c])
    }
    /// σ of the total: the two tallies are exclusive outcomes of one trial.
    pub fn total_sigma(&self) -> [f64; 3] {
        let n = self.photons as f64;
        self.total().map(|p| (p * (1.0 - p) / n).max(0.0).sqrt())
    }
}

/// SplitMix64: a small, fast generator whose streams are fixed by the seed.
pub struct Rng(pub u64);

impl Rng {
    /// Uniform in [0, 1) with 53 random bits.
    pub fn unit(&mut self) -> f64 {
        (crate::ops::hash::splitmix64(&mut self.0) >> 11) as f64 / (1u64 << 53) as f64
    }
}

type V3 = [f64; 3];

fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn normalize(v: V3) -> V3 {
    let l = dot(v, v).sqrt();
    v.map(|c| c / l)
}

fn cross(a: V3, b: V3) -> V3 {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// A GGX visible normal for a viewer at `w`, Heitz 2018 ("Sampling the GGX distribution of
/// visible normals", JCGT 7(4), listing 1): density D(m) max(0, w·m) / A(w). It holds for
/// `w` below the horizon too (tested), which the height walk needs.
fn sample_visible_normal(w: V3, alpha: f64, rng: &mut Rng) -> V3 {
    // A mirror draws nothing (the walk's random streams are as they were).
    if alpha <= 0.0 {
        return [0.0, 0.0, 1.0];
    }
    let (u1, u2) = (rng.unit(), rng.unit());
    visible_normal_at(w, alpha, u1, u2)
}

/// `sample_visible_normal` at the uniforms (u1, u2) (for quadratures).
pub fn visible_normal_at(w: V3, alpha: f64, u1: f64, u2: f64) -> V3 {
    if alpha <= 0.0 {
        return [0.0, 0.0, 1.0];
    }
    let vh = normalize([alpha * w[0], alpha * w[1], w[2]]);
    let lensq = vh[0] * vh[0] + vh[1] * vh[1];
    let t1 = if lensq > 0.0 { [-vh[1] / lensq.sqrt(), vh[0] / lensq.sqrt(), 0.0] } else { [1.0, 0.0, 0.0] };
    let t2 = cross(vh, t1);
    let r = u1.sqrt();
    let phi = 2.0 * std::f64::consts::PI * u2;
    let p1 = r * phi.cos();
    let s = 0.5 * (1.0 + vh[2]);
    let p2 = (1.0 - s) * (1.0 - p1 * p1).sqrt() + s * r * phi.sin();
    let p3 = (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt();
    let nh = [0, 1, 2].map(|k| p1 * t1[k] + p2 * t2[k] + p3 * vh[k]);
    normalize([alpha * nh[0], alpha * nh[1], nh[2].max(0.0)])
}

/// Mirror of the travel direction `d` about the normal `m`.
fn reflect(d: V3, m: V3) -> V3 {
    let k = 2.0 * dot(d, m);
    [0, 1, 2].map(|i| d[i] - k * m[i])
}

/// The travel direction after refraction through `m` (facing the incident side, m·d < 0)
/// from index n_i into n_t; None under total internal reflection.
fn refract(d: V3, m: V3, eta: f64) -> Option<V3> {
    let cos_i = -dot(d, m);
    let k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
    (k >= 0.0).then(|| normalize([0, 1, 2].map(|i| eta * d[i] + (eta * cos_i - k.sqrt()) * m[i])))
}

/// The microsurface's heights: uniform on [−1, 1] (Heitz et al. 2016 show the Smith
/// walk's result does not depend on the height distribution; uniform is the simplest).
/// C1 is its cumulative distribution.
fn height_cdf(h: f64) -> f64 {
    (0.5 * (h + 1.0)).clamp(0.0, 1.0)
}

fn height_of_cdf(u: f64) -> f64 {
    (2.0 * u - 1.0).clamp(-1.0, 1.0)
}

/// Smith Λ of a travel direction `w` (Heitz et al. 2016, §3): GGX's Λ for an upward
/// direction, −1 − Λ(−w) for a downward one.
fn lambda(w: V3, alpha: f64) -> f64 {
    let up = super::ggx::smith_lambda(w[2].abs().max(1e-300), alpha);
    if w[2] > 0.0 { up } else { -1.0 - up }
}

/// The height of the next intersection of a ray travelling in `w` from height `h` with the
/// microsurface (above it, seen from above), or None if it leaves: Heitz, Hanika, d'Eon &
/// Dachsbacher 2016, "Multiple-scattering microfacet BSDFs with the Smith model", §4. A ray
/// travelling up leaves with probability G1(w, h) = C1(h)^Λ(w); one travelling down always
/// meets the surface.
fn next_height(w: V3, h: f64, alpha: f64, u: f64) -> Option<f64> {
    // A mirror-smooth top is a plane: whatever leaves it leaves, however grazing (the
    // near-horizontal shortcut below kept a photon reflected at exactly 90° on the plane,
    // reflecting until `MAX_EVENTS`, and `brdf albedo --model stochastic --roughness 0
    // --angle-deg 90` read 0 where the closed form reads 1).
    if w[2] > 0.9999 || (alpha == 0.0 && w[2] > 0.0) {
        return None;
    }
    if w[2] < -0.9999 {
        return Some(height_of_cdf(u * height_cdf(h)));
    }
    if w[2].abs() < 1e-4 {
        return Some(h);
    }
    let lambda = lambda(w, alpha);
    let leave = if w[2] > 0.0 { height_cdf(h).powf(lambda) } else { 0.0 };
    if u > 1.0 - leave {
        return None;
    }
    Some(height_of_cdf(height_cdf(h) / (1.0 - u).powf(1.0 / lambda)))
}

enum Fate {
    /// Reflected without entering the stack, after this many intersections with the
    /// microsurface (1: single scattering; read by the test of the walk's single scattering).
    #[cfg_attr(not(test), allow(dead_code))]
    Specular(usize),
    /// Left after entering the stack, at cos θo, after this many base reflections.
    Diffuse(f64, usize),
    Absorbed,
}

/// Follows one photon of channel `c` arriving from direction `wi` (unit, wi.z > 0).
///
/// The top interface is a Smith microsurface walked with heights (Heitz et al. 2016, the
/// dielectric case): at each intersection a visible normal is drawn, the film reflects with
/// its probability at the microfacet angle (from above, or from below with total internal
/// reflection) or the photon refracts and continues on the other side, where the same
/// surface is walked mirrored. A photon leaves the microsurface upward (it is reflected) or
/// downward into the pigment layer, where it survives a path at cosine μ with probability
/// exp(−τ/|μ|) and the base with probability k_d, leaving the base in a cosine-distributed
/// direction to meet the microsurface again from below. Single scattering on the walk is
/// the height-correlated Smith lobe the models use (G2 = 1 / (1 + Λi + Λo)); the walk adds
/// what that lobe leaves out (light reflected or refracted more than once by the rough
/// surface), which the models must account for.
fn follow(wi: V3, layers: &Layers, film: &FilmTables, alpha: f64, c: usize, rng: &mut Rng) -> Fate {
    let Stack { n0, n2, .. } = film.stack;
    let tau = layers.optical_depth[c].max(0.0);
    let kd = layers.albedo[c].clamp(0.0, 1.0);
    let reflectance =
        |outside: bool, cos: f64| FilmTables::lookup(if outside { &film.above } else { &film.below }, cos, c);
    let mut photon = OnTop::arriving(wi);
    let mut bounces = 0;
    while photon.scatterings < MAX_EVENTS {
        if walk_top(&mut photon, alpha, n0, n2, &reflectance, rng) == Some(Leaves::Up) {
            return if photon.entered {
                Fate::Diffuse(photon.d[2], bounces)
            } else {
                Fate::Specular(photon.scatterings)
            };
        }
        if photon.scatterings >= MAX_EVENTS {
            break;
        }
        // Down through the layer, the base, and up through the layer again: each traversal
        // at its own cosine survives with exp(−τ/|μ|).
        if rng.unit() >= (-tau / photon.d[2].abs()).exp() || rng.unit() >= kd {
            return Fate::Absorbed;
        }
        bounces += 1;
        // Lambertian: cos θ = √u, uniform azimuth.
        let (u1, u2) = (rng.unit(), rng.unit());
        let (cos, phi) = (u1.sqrt(), 2.0 * std::f64::consts::PI * u2);
        let sin = (1.0 - cos * cos).max(0.0).sqrt();
        if rng.unit() >= (-tau / cos.max(1e-300)).exp() {
            return Fate::Absorbed;
        }
        // Back at the microsurface from below: mirrored, it starts from the top.
        (photon.d, photon.h) = ([sin * phi.cos(), sin * phi.sin(), cos], 1.0);
    }
    Fate::Absorbed
}

/// A photon on the rough top: its travel direction, its height (in the frame of the side it
/// is on: inside, the surface is walked mirrored, z → −z), its side, whether it has crossed
/// the top yet, how many microfacets it has met, and the microfacet cosine of its latest
/// reflection from above (negative before the first; `through_cosines` reads it).
struct OnTop {
    d: V3,
    h: f64,
    outside: bool,
    entered: bool,
    scatterings: usize,
    reflected_cos: f64,
}

impl OnTop {
    /// A photon arriving from direction `wi` (unit, wi.z > 0), above the surface.
    fn arriving(wi: V3) -> OnTop {
        OnTop { d: wi.map(|v| -v), h: 1.0, outside: true, entered: false, scatterings: 0, reflected_cos: -1.0 }
    }
}

/// Where a photon leaves the rough top: up into n0, or down into the pigment layer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Leaves {
    Up,
    Down,
}

/// Walks `photon` on the rough top (GGX α between n0 above and n2 below) until it leaves
/// it, or None after `MAX_EVENTS` microfacets: at each intersection a visible normal is
/// drawn, and `reflectance(outside, cos)` is the probability that the microfacet at cosine
/// `cos` reflects it; otherwise it refracts to the other side, where the same surface is
/// walked mirrored (Heitz et al. 2016's dielectric walk). `follow` and
/// `transmitted_cosines` share it.
fn walk_top(
    photon: &mut OnTop,
    alpha: f64,
    n0: f64,
    n2: f64,
    reflectance: &dyn Fn(bool, f64) -> f64,
    rng: &mut Rng,
) -> Option<Leaves> {
    while photon.scatterings < MAX_EVENTS {
        let u = rng.unit();
        let OnTop { d, h, outside, .. } = *photon;
        let next = if outside { next_height(d, h, alpha, u) } else { next_height(d.map(|v| -v), h, alpha, u) };
        match next {
            Some(next) => photon.h = next,
            None => return Some(if outside { Leaves::Up } else { Leaves::Down }),
        }
        photon.scatterings += 1;
        // A microfacet facing the photon, drawn from the normals visible along −d: seen
        // from below, the surface's own normals m visible along d, facing down as −m.
        let m = if outside {
            sample_visible_normal(d.map(|v| -v), alpha, rng)
        } else {
            sample_visible_normal(d, alpha, rng).map(|v| -v)
        };
        let cos = -dot(d, m);
        let r = reflectance(outside, cos);
        let eta = if outside { n0 / n2 } else { n2 / n0 };
        match if rng.unit() < r { None } else { refract(d, m, eta) } {
            None => {
                photon.d = reflect(d, m);
                if outside {
                    photon.reflected_cos = cos;
                }
            }
            Some(t) => {
                photon.d = t;
                photon.outside = !outside;
                photon.entered = true;
                // The other side's frame: heights mirror.
                photon.h = -photon.h;
            }
        }
    }
    None
}

/// The reflectance of a bare interface n0 | n2 (no film) at a microfacet cosine, from above
/// (`outside`) or from below, unpolarised: the top of `transmitted_cosines` and
/// `through_cosines`.
pub fn bare_interface(n0: f64, n2: f64) -> impl Fn(bool, f64) -> f64 {
    move |outside: bool, cos: f64| {
        let (from, to) = if outside { (n0, n2) } else { (n2, n0) };
        let (rs, rp) = crate::optics::film::fresnel(from, to, cos.clamp(0.0, 1.0));
        0.5 * (rs + rp)
    }
}

/// The cosines, in the pigment layer, at which photons arriving from `wi` (unit, wi.z > 0)
/// leave a rough top of GGX α between media n0 (above) and n2 (below) downward: the top
/// walked alone as `follow` walks it (`walk_top`), with the plain Fresnel reflectance of
/// n0 | n2 at each microfacet. Photons reflected away are not listed. `path::PathTable` is
/// built from these.
pub fn transmitted_cosines(wi: V3, alpha: f64, n0: f64, n2: f64, photons: u64, seed: u64) -> Vec<f64> {
    let reflectance = bare_interface(n0, n2);
    let mut rng = Rng(seed);
    let mut cosines = Vec::with_capacity(photons as usize);
    for _ in 0..photons {
        let mut photon = OnTop::arriving(wi);
        if walk_top(&mut photon, alpha, n0, n2, &reflectance, &mut rng) == Some(Leaves::Down) {
            cosines.push(photon.d[2].abs());
        }
    }
    cosines
}

/// Light that crosses the rough top and comes straight back through it: of photons
/// arriving from `wi` (unit, wi.z > 0) at a rough top walked as `transmitted_cosines` walks
/// it (plain Fresnel of n0 | n2), those that refract into the surface and leave it upward
/// without reaching the pigment layer. Nearly all of them enter through one microfacet,
/// leave through another and are reflected by a third from above, near grazing (the
/// sequences walked, at 85° and roughness 0.9 on n0 | n2 = 1 | 1.33: down-up-reflected
/// two thirds, the rest with further reflections). Returns how many photons entered the
/// surface at all, how many of those came straight back, and, for those reflected from
/// above, the microfacet cosine of their latest such reflection (`path::PathTable`'s rule
/// for the film's share of them is built from these).
pub fn through_cosines(wi: V3, alpha: f64, n0: f64, n2: f64, photons: u64, seed: u64) -> (u64, u64, Vec<f64>) {
    let reflectance = bare_interface(n0, n2);
    let mut rng = Rng(seed);
    let (mut entered, mut count, mut cosines) = (0, 0, Vec::new());
    for _ in 0..photons {
        let mut photon = OnTop::arriving(wi);
        let leaves = walk_top(&mut photon, alpha, n0, n2, &reflectance, &mut rng);
        entered += u64::from(photon.entered);
        if leaves == Some(Leaves::Up) && photon.entered {
            count += 1;
            if photon.reflected_cos >= 0.0 {
                cosines.push(photon.reflected_cos);
            }
        }
    }
    (entered, count, cosines)
}

/// A photon that a rough top reflecting everything scatters more than once: the microfacet
/// cosines of its first two reflections and how many reflections it took.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MultipleReflection {
    pub first: f64,
    pub second: f64,
    pub count: usize,
}

/// Every photon arriving from `wi` (unit, wi.z > 0) that meets a rough top more than once,
/// walked until `twice` of them have reflected exactly twice or `photons` have arrived (so
/// that smooth tops, which scatter little more than once, still give enough). The top
/// reflects everything (F = 1 at every microfacet, so no photon enters), walked as `follow`
/// walks it. A film that reflects F(c) at cosine c returns such a path with probability
/// Π F(c_k) over its cosines, and the directions after each reflection do not depend on F,
/// so these paths are the film's multiple scattering exactly; `energy`'s rule for it is
/// built from them.
pub fn multiple_reflections(wi: V3, alpha: f64, twice: usize, photons: u64, seed: u64) -> Vec<MultipleReflection> {
    let (count, first, second) = (std::cell::Cell::new(0usize), std::cell::Cell::new(0.0), std::cell::Cell::new(0.0));
    let mirror = |_: bool, cos: f64| {
        match count.get() {
            0 => first.set(cos),
            1 => second.set(cos),
            _ => {}
        }
        count.set(count.get() + 1);
        1.0
    };
    let mut rng = Rng(seed);
    let (mut paths, mut walked, mut reflected_twice) = (Vec::new(), 0, 0);
    while walked < photons && reflected_twice < twice {
        walked += 1;
        count.set(0);
        let mut photon = OnTop::arriving(wi);
        walk_top(&mut photon, alpha, 1.0, 1.0, &mirror, &mut rng);
        if photon.scatterings > 1 {
            paths.push(MultipleReflection { first: first.get(), second: second.get(), count: count.get() });
            reflected_twice += usize::from(count.get() == 2);
        }
    }
    paths
}

/// GGX α of the walk's top: 0 (a mirror, m = n) for roughness 0, else the models'
/// `ggx_alpha`.
fn walk_alpha(layers: &Layers) -> f64 {
    if layers.roughness <= 0.0 { 0.0 } else { super::ggx_alpha(layers.roughness) }
}

/// Each channel's own stream, fixed by the seed.
fn channel_rng(seed: u64, channel: usize) -> Rng {
    Rng(seed ^ (0x5151_0000 + channel as u64).wrapping_mul(0x2545_f491_4f6c_dd1d))
}

/// Walks `photons` photons per channel from direction `wi` (need not be normalised; the
/// normal is +z) through the stack of `layers` with the film of `film`.
pub fn walk(layers: &Layers, film: &FilmTables, wi: V3, photons: u64, bins: usize, seed: u64) -> WalkResult {
    let (wi, alpha) = (normalize(wi), walk_alpha(layers));
    let mut specular = [0u64; 3];
    let mut diffuse = [0u64; 3];
    let mut binned = vec![[0u64; 3]; bins.max(1)];
    for c in 0..3 {
        let mut rng = channel_rng(seed, c);
        for _ in 0..photons {
            match follow(wi, layers, film, alpha, c, &mut rng) {
                Fate::Specular(_) => specular[c] += 1,
                Fate::Diffuse(cos_o, _) => {
                    diffuse[c] += 1;
                    let b = ((cos_o * binned.len() as f64) as usize).min(binned.len() - 1);
                    binned[b][c] += 1;
                }
                Fate::Absorbed => {}
            }
        }
    }
    let n = photons as f64;
    let p = |k: [u64; 3]| k.map(|v| v as f64 / n);
    let sigma = |p: [f64; 3]| p.map(|v| (v * (1.0 - v) / n).sqrt());
    let (s, d) = (p(specular), p(diffuse));
    WalkResult {
        photons,
        specular: s,
        diffuse: d,
        specular_sigma: sigma(s),
        diffuse_sigma: sigma(d),
        diffuse_bins: binned.into_iter().map(p).collect(),
    }
}

/// Photons of one walk sorted by their fate: the specular ones, and the diffuse ones by how
/// many times the base reflected them. The base's albedo k_d enters only as k_d^n for a
/// photon reflected n times, so one walk with a white base (k_d = 1; absorption in the
/// layer still walked) gives the albedo for every k_d: A(k_d) = (S + Σ_n h_n k_d^n) / N.
#[derive(Debug, Clone)]
pub struct BounceTally {
    pub photons: u64,
    pub specular: [u64; 3],
    /// `escaped_after[n][c]`: channel-c photons that left after n base reflections.
    pub escaped_after: Vec<[u64; 3]>,
}

impl BounceTally {
    /// The directional albedo for base albedo `albedo`, and its standard error.
    pub fn albedo(&self, albedo: [f64; 3]) -> ([f64; 3], [f64; 3]) {
        let n = self.photons as f64;
        let mut mean = [0.0; 3];
        let mut sigma = [0.0; 3];
        for c in 0..3 {
            let kd = albedo[c].clamp(0.0, 1.0);
            let (mut first, mut second) = (self.specular[c] as f64, self.specular[c] as f64);
            for (bounces, counts) in self.escaped_after.iter().enumerate() {
                let x = kd.powi(bounces as i32);
                first += counts[c] as f64 * x;
                second += counts[c] as f64 * x * x;
            }
            mean[c] = first / n;
            sigma[c] = ((second / n - mean[c] * mean[c]).max(0.0) / n).sqrt();
        }
        (mean, sigma)
    }
}

/// Walks `photons` photons per channel with a white base (the `albedo` of `layers` is not
/// used) and tallies them by base reflections (`BounceTally`).
pub fn walk_bounces(layers: &Layers, film: &FilmTables, wi: V3, photons: u64, seed: u64) -> BounceTally {
    let (wi, alpha) = (normalize(wi), walk_alpha(layers));
    let white = Layers { albedo: [1.0; 3], ..*layers };
    let mut tally = BounceTally { photons, specular: [0; 3], escaped_after: Vec::new() };
    for c in 0..3 {
        let mut rng = channel_rng(seed, c);
        for _ in 0..photons {
            match follow(wi, &white, film, alpha, c, &mut rng) {
                Fate::Specular(_) => tally.specular[c] += 1,
                Fate::Diffuse(_, bounces) => {
                    if tally.escaped_after.len() <= bounces {
                        tally.escaped_after.resize(bounces + 1, [0; 3]);
                    }
                    tally.escaped_after[bounces][c] += 1;
                }
                Fate::Absorbed => {}
            }
        }
    }
    tally
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optics::brdf::ggx::ggx_d;

    /// E₁ by the midpoint rule over (θi, φi), 1000 × 1000.
    fn smith_lobe_albedo(cos_o: f64, alpha: f64) -> f64 {
        use crate::optics::brdf::ggx::smith_lambda;
        let wo = [(1.0 - cos_o * cos_o).sqrt(), 0.0, cos_o];
        let n = 1000;
        let (d_theta, d_phi) = (std::f64::consts::FRAC_PI_2 / n as f64, std::f64::consts::TAU / n as f64);
        let mut sum = 0.0;
        for i in 0..n {
            let theta = (i as f64 + 0.5) * d_theta;
            for j in 0..n {
                let phi = (j as f64 + 0.5) * d_phi;
                let wi = [theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()];
                let h = normalize([wi[0] + wo[0], wi[1] + wo[1], wi[2] + wo[2]]);
                let g2 = 1.0 / (1.0 + smith_lambda(wi[2], alpha) + smith_lambda(cos_o, alpha));
                let f = ggx_d(h[2], alpha) * g2 / (4.0 * wi[2] * cos_o);
                sum += f * wi[2] * theta.sin() * d_theta * d_phi;
            }
        }
        sum
    }

    /// With a film that reflects everything, no photon enters: the microsurface walk must
    /// return every one (energy conservation of the multiple-scattering surface), and the
    /// share reflected at the first intersection must be the height-correlated Smith
    /// lobe's albedo E₁(μ) = ∫ D G2 / (4 μi μo) μi dωi, here by quadrature over the
    /// sphere of directions, sharing no code with the walk but D and Λ (Heitz et al. 2016,
    /// §5). (The energy table's stratified half-vector quadrature is within 0.0013 of
    /// this at μ ≥ 0.5, but 0.007–0.009 off at 80–85° and 0.03 at 89°.)
    #[test]
    fn the_walk_scatters_once_as_the_smith_lobe_and_returns_everything_on_a_mirror_film() {
        let stack = crate::optics::film::Stack::THESIS;
        let film = FilmTables { stack, above: vec![[1.0; 3]; TABLE_SIZE], below: vec![[1.0; 3]; TABLE_SIZE] };
        let photons = 200_000;
        for (mu, roughness) in [(1.0, 0.6), (0.5, 0.9), (0.2, 0.6), (0.1, 0.3), (0.7, 1.0)] {
            let layers = Layers { roughness, ..Layers::of_stack(stack, 400.0, roughness, [0.0; 3], [1.0; 3]) };
            let wi = [(1.0f64 - mu * mu).sqrt(), 0.0, mu];
            let alpha = walk_alpha(&layers);
            let mut rng = Rng(5 + (mu * 100.0) as u64);
            let (mut once, mut total) = (0u64, 0u64);
            for _ in 0..photons {
                match follow(wi, &layers, &film, alpha, 0, &mut rng) {
                    Fate::Specular(events) => {
                        total += 1;
                        once += u64::from(events == 1);
                    }
                    _ => panic!("a photon entered a stack whose film reflects everything"),
                }
            }
            assert_eq!(total, photons);
            let p = once as f64 / photons as f64;
            let sigma = (p * (1.0 - p) / photons as f64).sqrt();
            let e1 = smith_lobe_albedo(mu, roughness * roughness);
            assert!((p - e1).abs() <= 4.0 * sigma + 5e-4, "μ={mu} r={roughness}: walk {p:.4} ± {sigma:.4}, E₁ {e1:.4}");
        }
    }

    /// Light along a mirror-smooth top, at exactly 90° (cos 6e-17): it meets the plane and
    /// is reflected back out, every photon (the film here reflects everything).
    #[test]
    fn a_mirror_smooth_top_reflects_light_at_exactly_grazing() {
        let stack = crate::optics::film::Stack::THESIS;
        let film = FilmTables { stack, above: vec![[1.0; 3]; TABLE_SIZE], below: vec![[1.0; 3]; TABLE_SIZE] };
        let layers = Layers { roughness: 0.0, ..Layers::of_stack(stack, 400.0, 0.0, [0.0; 3], [1.0; 3]) };
        let wi = [1.0, 0.0, 90f64.to_radians().cos()];
        let mut rng = Rng(3);
        for _ in 0..1000 {
            assert!(matches!(follow(wi, &layers, &film, walk_alpha(&layers), 0, &mut rng), Fate::Specular(1)));
        }
    }

    /// The multiple-scattering walk meets microfacets from directions below the horizon
    /// (a photon travelling up that hits the surface again): the visible-normal sampler
    /// must draw D(m) max(0, w·m) there too. Its moments against quadrature.
    #[test]
    fn visible_normals_are_right_above_and_below_the_horizon() {
        for (wz, alpha) in [(0.7f64, 0.5), (0.1, 0.8), (-0.3, 0.6), (-0.8, 0.3), (-0.05, 0.9)] {
            let w: V3 = [(1.0 - wz * wz).sqrt(), 0.0, wz];
            // Quadrature of D(m) max(0, w·m) over the upper hemisphere of m.
            let (n_t, n_p) = (400, 400);
            let (mut norm, mut mean) = (0.0, [0.0; 3]);
            for i in 0..n_t {
                let theta = (i as f64 + 0.5) / n_t as f64 * std::f64::consts::FRAC_PI_2;
                for j in 0..n_p {
                    let phi = (j as f64 + 0.5) / n_p as f64 * std::f64::consts::TAU;
                    let m = [theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()];
                    let weight = ggx_d(m[2], alpha) * dot(w, m).max(0.0) * theta.sin();
                    norm += weight;
                    for k in 0..3 {
                        mean[k] += weight * m[k];
                    }
                }
            }
            let expected = mean.map(|v| v / norm);
            let mut rng = Rng(99);
            let samples = 400_000;
            let mut sampled = [0.0; 3];
            for _ in 0..samples {
                let m = sample_visible_normal(w, alpha, &mut rng);
                assert!(dot(w, m) >= -1e-9 && m[2] >= 0.0, "w={w:?}: {m:?} not visible");
                for k in 0..3 {
                    sampled[k] += m[k] / samples as f64;
                }
            }
            for k in 0..3 {
                assert!((sampled[k] - expected[k]).abs() < 3e-3, "w.z={wz} α={alpha}: {sampled:?} vs {expected:?}");
            }
        }
    }
}
