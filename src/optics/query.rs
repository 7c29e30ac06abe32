//! Optics queries by method: the film colour of any method in f64 (the 1 nm reference, the
//! real-time methods, the LUT read in f64 arithmetic), the range checks a query must pass,
//! and the thickness × angle colour chart. `snakeskin brdf` and its batch mode call these;
//! the checks name the parameter and what is accepted, so a bad query is an error, never a
//! silently clamped answer.

use std::sync::{Arc, Mutex};

use rayon::prelude::*;

use super::film::Stack;
use super::film_rgb_reference;
use super::lut::LazyLut;
use super::methods::{Method, gaussian_fit_f64, rgb3_f64, spectral_n_f64};
use crate::Error;
use crate::ops::Image;
use crate::preset::validate::{ranges, shown};

/// Refuses what the physics does not cover, naming the parameter and the accepted range
/// (the preset's range table: indices, film thickness).
pub fn check(stack: Stack, thickness_nm: f64, angle_deg: f64, wavelength_nm: Option<f64>) -> Result<(), Error> {
    let (lo, hi) = ranges::IOR;
    for (name, n) in [("n0", stack.n0), ("n1", stack.n1), ("n2", stack.n2)] {
        if !(n.is_finite() && (lo..=hi).contains(&n)) {
            return Err(Error::Query(format!("{name} must be a refractive index in [{lo}, {hi}], got {}", shown(n))));
        }
    }
    let (lo, hi) = ranges::FILM_THICKNESS_NM;
    if !(thickness_nm.is_finite() && (lo..=hi).contains(&thickness_nm)) {
        return Err(Error::Query(format!(
            "thickness_nm must be a finite number in [{lo}, {hi}], got {}",
            shown(thickness_nm)
        )));
    }
    let (lo, hi) = ranges::ANGLE_DEG;
    if !(angle_deg.is_finite() && (lo..=hi).contains(&angle_deg)) {
        return Err(Error::Query(format!("angle_deg must be in [{lo}, {hi}], got {}", shown(angle_deg))));
    }
    let (lo, hi) = ranges::QUERY_WAVELENGTH_NM;
    if let Some(l) = wavelength_nm
        && !(l.is_finite() && (lo..=hi).contains(&l))
    {
        return Err(Error::Query(format!("wavelength_nm must be a finite number in [{lo}, {hi}], got {}", shown(l))));
    }
    Ok(())
}

/// Tables kept at once by `film_colour`'s LUT cache.
const MAX_CACHED_LUTS: usize = 8;

/// LUTs read so far, per material (the queries of a batch on one material share its texels).
fn lut_for(stack: Stack) -> Arc<LazyLut> {
    static CACHE: Mutex<TableCache<[u64; 3], LazyLut>> = Mutex::new(TableCache::new(MAX_CACHED_LUTS));
    let key = [stack.n0.to_bits(), stack.n1.to_bits(), stack.n2.to_bits()];
    let mut cache = CACHE.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    cache.get_or_make(key, || LazyLut::new(stack))
}

/// A few values by key, each made once while it is kept. A table holds about 0.3 MiB (its
/// 20,480 texel cells), and each line of a batch may name its own material, so a batch
/// keeps a few. When the cache is full, a value chosen at random makes room. Emptying the
/// whole cache (as before) or dropping the least recently used value misses on every query
/// of a batch that cycles through more materials than the cache holds (9 materials in turn:
/// every query's texels computed again, 2 s each when a query baked its whole table);
/// always replacing the value made last misses on every query of two new materials taken in
/// turn. A random choice keeps most of either: the test below counts the makings of both.
/// (The choice changes only what is made again, never a value.)
struct TableCache<K, V> {
    entries: Vec<(K, Arc<V>)>,
    max: usize,
    /// xorshift64 state for the choice of the value that makes room.
    state: u64,
}

impl<K: PartialEq, V> TableCache<K, V> {
    const fn new(max: usize) -> Self {
        TableCache { entries: Vec::new(), max, state: 0x9e37_79b9_7f4a_7c15 }
    }

    fn get_or_make(&mut self, key: K, make: impl FnOnce() -> V) -> Arc<V> {
        if let Some((_, value)) = self.entries.iter().find(|(k, _)| *k == key) {
            return value.clone();
        }
        if self.entries.len() >= self.max {
            self.state ^= self.state << 13;
            self.state ^= self.state >> 7;
            self.state ^= self.state << 17;
            self.entries.swap_remove((self.state % self.entries.len() as u64) as usize);
        }
        let value = Arc::new(make());
        self.entries.push((key, value.clone()));
        value
    }
}

/// A method's film colour in f64 (the LUT read in f64 arithmetic): linear sRGB under D65.
pub fn film_colour(method: Method, stack: Stack, thickness_nm: f64, cos0: f64) -> [f64; 3] {
    match method {
        Method::Spectral => film_rgb_reference(stack, thickness_nm, cos0),
        Method::Rgb3 => rgb3_f64(stack, thickness_nm, cos0),
        Method::SpectralN(n) => spectral_n_f64(stack, thickness_nm, cos0, n),
        Method::GaussianFit => gaussian_fit_f64(stack, thickness_nm, cos0),
        Method::Lut => lut_for(stack).lookup_f64(thickness_nm, cos0),
    }
}

/// Peak bytes of `chart` and its PNG: the rows in f64 (24 bytes a pixel) and the f32 image
/// made from them (12) live together, then the 8-bit pixels and the compressed file (at most
/// about 3 each). A 4096² chart peaked at about 500 MB (maxrss) with no check at all.
pub fn chart_bytes(width: usize, height: usize) -> u64 {
    width as u64 * height as u64 * (24 + 12 + 3 + 3)
}

/// The film colour chart: thickness 0..2000 nm across, angle 0..89° down, scaled so the
/// brightest channel is 1. Returns the linear image and the exposure applied (film
/// reflectances are a few percent to a few tens of percent). `progress(done, total)` counts
/// rows (the spectral reference takes about half a minute at 1024² on two cores, minutes at
/// the largest: it ran without a word, a sweep).
pub fn chart(
    stack: Stack,
    method: Method,
    width: usize,
    height: usize,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> (Image, f64) {
    // The table taken once, not through the cache's lock per pixel (16 million at 4096²).
    let lut = matches!(method, Method::Lut).then(|| lut_for(stack));
    let colour = |thickness_nm: f64, cos0: f64| match &lut {
        Some(lut) => lut.lookup_f64(thickness_nm, cos0),
        None => film_colour(method, stack, thickness_nm, cos0),
    };
    let done = std::sync::atomic::AtomicUsize::new(0);
    let rows: Vec<Vec<[f64; 3]>> = (0..height)
        .into_par_iter()
        .map(|y| {
            let cos0 = (super::accuracy::GRID_ANGLE_MAX_DEG * y as f64 / (height - 1) as f64).to_radians().cos();
            let row =
                (0..width).map(|x| colour(super::lut::FINE_MAX_NM * x as f64 / (width - 1) as f64, cos0)).collect();
            progress(done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1, height);
            row
        })
        .collect();
    // Floored only against a division by zero: a floor of 1e-6 drew a stack of n2 = n1 +
    // 1e-7 (reflecting about 1e-15) at a fifth of full scale, where the help promises the
    // brightest channel at 1 (a hostile-input review).
    let brightest = rows.iter().flatten().flat_map(|p| p.iter().copied()).fold(f64::MIN_POSITIVE, f64::max);
    let exposure = 1.0 / brightest;
    let image = Image {
        width,
        height,
        channels: 3,
        data: rows.into_iter().flatten().flat_map(|p| p.map(|c| (c * exposure) as f32)).collect(),
    };
    (image, exposure)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The chart's brightest channel is 1, however faintly the stack reflects (a floor of
    /// 1e-6 drew n2 = n1 + 1e-7 at a billionth of full scale: a hostile-input review); a stack
    /// that reflects nothing is black, its exposure finite.
    #[test]
    fn a_faint_stacks_chart_is_scaled_to_one_and_a_blank_one_is_black() {
        let brightest = |image: &Image| image.data.iter().copied().fold(0.0f32, f32::max);
        let faint = Stack { n0: 1.0, n1: 1.0, n2: 1.0000001 };
        let (image, exposure) = chart(faint, Method::Rgb3, 8, 8, &|_, _| {});
        assert!((brightest(&image) - 1.0).abs() < 1e-6, "brightest {} at exposure {exposure}", brightest(&image));
        let (image, exposure) = chart(Stack { n0: 1.0, n1: 1.0, n2: 1.0 }, Method::Rgb3, 8, 8, &|_, _| {});
        assert!(exposure.is_finite() && brightest(&image) == 0.0, "{exposure} {}", brightest(&image));
    }

    /// Queries of materials in the two orders that defeat the simpler rules: cycling
    /// through one more material than the cache holds (every query made again when a full cache
    /// was emptied, or with least-recently-used), and, once it is full, two new materials in
    /// turn (every query made again when the value made last made room). Negative control:
    /// within its size, each material is made once.
    #[test]
    fn a_full_cache_keeps_most_of_a_cycle_and_of_two_materials_in_turn() {
        let makings = |queries: &[u32]| {
            let mut cache = TableCache::new(MAX_CACHED_LUTS);
            let mut makings = 0;
            for &k in queries {
                cache.get_or_make(k, || {
                    makings += 1;
                    k
                });
            }
            makings
        };
        let n = MAX_CACHED_LUTS as u32;
        let cycles = |materials: u32| (0..10).flat_map(|_| 0..materials).collect::<Vec<u32>>();
        assert_eq!(makings(&cycles(n)), n);
        let cycle = makings(&cycles(n + 1));
        assert!(cycle <= 45, "{cycle} makings of 90 queries cycling {} materials", n + 1);
        let in_turn: Vec<u32> = (0..n).chain((0..90).map(|q| n + q % 2)).collect();
        let two = makings(&in_turn);
        assert!(two <= n + 20, "{two} makings of {} queries, two new materials in turn", in_turn.len());
    }
}
