//! `snakeskin bench layered`: each layer model against the stochastic reference with a
//! rough top (`walk`), on a documented grid, in colour difference, white-furnace energy and
//! cost.
//!
//! What is compared is the **reflected colour**: the directional albedo (specular plus
//! diffuse) for light from one direction, as linear sRGB → CIELAB (D65, Y of the perfect
//! reflector 1) → CIEDE2000. The model's albedo is the integral of its BRDF
//! (`Model::furnace_albedo`, 32² + 32² evaluations); the reference's is the walk's, one
//! walk per (material, τ, thickness, angle, roughness) for every base colour at once
//! (`BounceTally`). Both read the same exact film (tabulated over the cosine), so the
//! table measures the transport model, not a film method (`bench irid` measures those).
//! The report says what the reference's own noise does to the colour (`noise_de`, mean and
//! largest over the points), so that an error the noise could make is seen as such: at
//! 100,000 photons it moves dark colours by up to about 1 ΔE00, at 1,600,000 by 0.25.
//!
//! The grid: the four materials of PHYSICS.md; τ ∈ {0, 0.4, 1}; film 250 and 650 nm; light
//! at 0°, 30°, 60° and 85°; roughness 0.05, 0.3, 0.6 and 0.9; the base colours of every
//! built-in species (back and belly, as linear sRGB).

use rayon::prelude::*;

use super::walk::{FilmTables, walk_bounces};
use super::{Layers, Layers32, Model};
use crate::optics::accuracy::GRID_MATERIALS;
use crate::optics::film::Stack;
use crate::optics::lab::{ciede2000, linear_srgb_to_lab};
use crate::optics::lut::Lut;

pub const TAUS: [f64; 3] = [0.0, 0.4, 1.0];
pub const THICKNESSES_NM: [f64; 2] = [250.0, 650.0];
pub const ANGLES_DEG: [f64; 4] = [0.0, 30.0, 60.0, 85.0];
pub const ROUGHNESSES: [f64; 4] = [0.05, 0.3, 0.6, 0.9];
/// Strata per axis of the model's albedo integral.
const STRATA: usize = 32;

#[derive(Debug, Clone, serde::Serialize)]
pub struct ModelReport {
    pub name: &'static str,
    pub mean_de: f64,
    pub p95_de: f64,
    pub max_de: f64,
    /// Largest |albedo − 1| over the lossless points (τ = 0, k_d = 1), every angle.
    pub max_furnace_err: f64,
    /// The same up to 70° (the tighter bound).
    pub max_furnace_err_to_70: f64,
    /// CPU f32 cost of one BRDF evaluation (LUT film), median of five passes, each input
    /// at its own random film thickness (the table read at random: the worst case).
    pub ns_per_eval: f64,
    /// The same inputs in order of thickness, as a frame reads the tables (neighbouring
    /// pixels, neighbouring thicknesses).
    pub ns_per_eval_coherent: f64,
}

#[derive(Debug, Clone, serde::Serialize)]
pub struct LayeredBench {
    pub models: Vec<ModelReport>,
    pub points: usize,
    pub photons_per_channel: u64,
    /// Mean and largest ΔE00 that the reference's own noise makes at the points (`noise_de`:
    /// the worst corner of each point's ±1σ box).
    pub reference_noise_mean_de: f64,
    pub reference_noise_max_de: f64,
    /// Furnace error of each model per (roughness, angle): rows of
    /// (model, roughness, angle_deg, max |albedo − 1| over materials and films).
    pub furnace: Vec<(&'static str, f64, f64, f64)>,
    /// Where each model's error lies: rows of (model, roughness, angle_deg, mean ΔE00, max
    /// ΔE00) over materials, τ, films and colours.
    pub error_by_roughness_angle: Vec<(&'static str, f64, f64, f64, f64)>,
    /// The same by optical depth: (model, τ, mean ΔE00, max ΔE00).
    pub error_by_optical_depth: Vec<(&'static str, f64, f64, f64)>,
}

struct Point {
    stack: Stack,
    tau: f64,
    thickness_nm: f64,
    angle_deg: f64,
    roughness: f64,
}

fn grid() -> Vec<Point> {
    let mut points = Vec::new();
    for stack in GRID_MATERIALS {
        for tau in TAUS {
            for thickness_nm in THICKNESSES_NM {
                for angle_deg in ANGLES_DEG {
                    for roughness in ROUGHNESSES {
                        points.push(Point { stack, tau, thickness_nm, angle_deg, roughness });
                    }
                }
            }
        }
    }
    points
}

/// The most ΔE00 the reference's own noise makes at a point: its colour `r` against `r`
/// moved by one standard deviation `sigma` per channel, in whichever of the eight
/// directions (±σ per channel, a corner of the 1σ box) moves it most. Moving every channel
/// up at once (the estimate before) changes mostly lightness, where ΔE00 is lenient; the
/// channels' noise is independent (`walk`'s per-channel random streams), and against each
/// other they shift hue and chroma, which for dark colours counts several times more
/// (BENCHMARKS.md: at 100,000 photons the largest went from 0.23 to 1.06). A bound, not an
/// expectation: the root mean square over the corners would be the 1σ figure.
fn noise_de(r: [f64; 3], sigma: [f64; 3]) -> f64 {
    let lab_r = linear_srgb_to_lab(r);
    (0..8)
        .map(|signs: usize| {
            let shifted = [0, 1, 2].map(|c| (r[c] + if (signs >> c) & 1 == 1 { sigma[c] } else { -sigma[c] }).max(0.0));
            ciede2000(linear_srgb_to_lab(shifted), lab_r)
        })
        .fold(0.0, f64::max)
}

/// Runs the comparison with `photons` per channel per walk, over `colours` (linear sRGB).
pub fn run(colours: &[[f64; 3]], photons: u64) -> LayeredBench {
    let points = grid();
    // Film tables per (material, thickness): the walk's and the models' film.
    let films: Vec<((Stack, u64), FilmTables)> = GRID_MATERIALS
        .iter()
        .flat_map(|s| THICKNESSES_NM.map(|d| (*s, d)))
        .collect::<Vec<_>>()
        .into_par_iter()
        .map(|(s, d)| ((s, d.to_bits()), FilmTables::new(s, d)))
        .collect();
    let film_of = |s: Stack, d: f64| &films.iter().find(|(k, _)| *k == (s, d.to_bits())).expect("film").1;

    // Per point: the reference for every colour, each model's albedo for every colour.
    type PointResult = (Vec<([f64; 3], [f64; 3])>, Vec<Vec<[f64; 3]>>, Vec<[f64; 3]>);
    let results: Vec<PointResult> = points
        .par_iter()
        .enumerate()
        .map(|(i, p)| {
            let film = film_of(p.stack, p.thickness_nm);
            let cos = p.angle_deg.to_radians().cos();
            let wi = [(1.0 - cos * cos).max(0.0).sqrt(), 0.0, cos];
            let layers = Layers::of_stack(p.stack, p.thickness_nm, p.roughness, [p.tau; 3], [1.0; 3]);
            let tally = walk_bounces(&layers, film, wi, photons, 1000 + i as u64);
            let reference = colours.iter().map(|c| tally.albedo(*c)).collect();
            let film_fn = |c: f64| film.above(c);
            let per_model = Model::ALL
                .iter()
                .map(|m| {
                    colours
                        .iter()
                        .map(|c| m.furnace_albedo(&Layers { albedo: *c, ..layers }, cos, &film_fn, STRATA))
                        .collect()
                })
                .collect();
            // The lossless stack for the furnace: τ = 0, k_d = 1 (only at τ = 0 points).
            let furnace = if p.tau == 0.0 {
                Model::ALL.iter().map(|m| m.furnace_albedo(&layers, cos, &film_fn, STRATA)).collect()
            } else {
                vec![]
            };
            (reference, per_model, furnace)
        })
        .collect();

    let mut noise = Vec::new();
    let mut models = Vec::new();
    let mut furnace_rows = Vec::new();
    let mut error_rows = Vec::new();
    let mut depth_rows = Vec::new();
    for (m, model) in Model::ALL.iter().enumerate() {
        let mut de = Vec::new();
        let mut de_at: Vec<((f64, f64), f64)> = Vec::new();
        let mut de_by_tau: Vec<(f64, f64)> = Vec::new();
        let (mut furnace_max, mut furnace_70) = (0.0f64, 0.0f64);
        for (p, (reference, per_model, furnace)) in points.iter().zip(&results) {
            for (k, (r, sigma)) in reference.iter().enumerate() {
                let lab_r = linear_srgb_to_lab(*r);
                let e = ciede2000(linear_srgb_to_lab(per_model[m][k]), lab_r);
                de.push(e);
                de_at.push(((p.roughness, p.angle_deg), e));
                de_by_tau.push((p.tau, e));
                if m == 0 {
                    noise.push(noise_de(*r, *sigma));
                }
            }
            if let Some(a) = furnace.get(m) {
                let err = a.iter().map(|v| (v - 1.0).abs()).fold(0.0, f64::max);
                furnace_max = furnace_max.max(err);
                if p.angle_deg <= 70.0 {
                    furnace_70 = furnace_70.max(err);
                }
            }
        }
        for roughness in ROUGHNESSES {
            for angle in ANGLES_DEG {
                let worst = points
                    .iter()
                    .zip(&results)
                    .filter(|(p, (_, _, f))| p.roughness == roughness && p.angle_deg == angle && !f.is_empty())
                    .map(|(_, (_, _, f))| f[m].iter().map(|v| (v - 1.0).abs()).fold(0.0, f64::max))
                    .fold(0.0, f64::max);
                furnace_rows.push((model.name(), roughness, angle, worst));
                let here: Vec<f64> = de_at.iter().filter(|(k, _)| *k == (roughness, angle)).map(|(_, e)| *e).collect();
                let mean = here.iter().sum::<f64>() / here.len().max(1) as f64;
                error_rows.push((model.name(), roughness, angle, mean, here.iter().cloned().fold(0.0, f64::max)));
            }
        }
        for tau in TAUS {
            let here: Vec<f64> = de_by_tau.iter().filter(|(t, _)| *t == tau).map(|(_, e)| *e).collect();
            let mean = here.iter().sum::<f64>() / here.len().max(1) as f64;
            depth_rows.push((model.name(), tau, mean, here.iter().cloned().fold(0.0, f64::max)));
        }
        de.sort_by(f64::total_cmp);
        let mean = de.iter().sum::<f64>() / de.len() as f64;
        let p95 = de[((de.len() as f64 * 0.95) as usize).min(de.len() - 1)];
        models.push(ModelReport {
            name: model.name(),
            mean_de: mean,
            p95_de: p95,
            max_de: *de.last().unwrap_or(&f64::NAN),
            max_furnace_err: furnace_max,
            max_furnace_err_to_70: furnace_70,
            ns_per_eval: ns_per_eval(*model, false),
            ns_per_eval_coherent: ns_per_eval(*model, true),
        });
    }
    LayeredBench {
        models,
        points: points.len() * colours.len(),
        photons_per_channel: photons,
        reference_noise_mean_de: noise.iter().sum::<f64>() / noise.len().max(1) as f64,
        reference_noise_max_de: noise.iter().cloned().fold(0.0, f64::max),
        furnace: furnace_rows,
        error_by_roughness_angle: error_rows,
        error_by_optical_depth: depth_rows,
    }
}

/// CPU f32 cost of `Model::eval_f32` with the default LUT, median of five passes over
/// 200,000 deterministic inputs on one core; `coherent`: the inputs sorted by thickness.
pub fn ns_per_eval(model: Model, coherent: bool) -> f64 {
    let lut = Lut::bake_default(Stack::THESIS);
    let layers = Layers::of_stack(
        Stack::THESIS,
        crate::material::thesis::FILM_THICKNESS_NM,
        0.35,
        [0.6, 0.4, 0.2],
        [0.5, 0.4, 0.3],
    );
    let count = 200_000;
    let mut inputs: Vec<_> = (0..count)
        .map(|i| {
            let u = |k: u32| crate::ops::hash::unit(i, 0, k, 11);
            let dir = |a: f32, b: f32| {
                let phi = b * std::f32::consts::TAU;
                let sin = (1.0 - a * a).sqrt();
                [sin * phi.cos(), sin * phi.sin(), a]
            };
            let mut l = layers.to_f32(crate::optics::lut::FINE_MAX_NM * u(0) as f64);
            l.roughness = 0.05 + 0.9 * u(1);
            (l, dir(u(2), u(3)), dir(u(4), u(5)))
        })
        .collect();
    if coherent {
        inputs.sort_by(|a: &(Layers32, _, _), b| a.0.thickness_nm.total_cmp(&b.0.thickness_nm));
    }
    median_ns_per_eval(model, &inputs, &lut)
}

/// One core's cost of `Model::eval_f32` over `inputs` (layers, wi, wo; normal +z), ns per
/// evaluation, median of five passes (`bench layered` and `bench gpu` time the CPU here).
pub fn median_ns_per_eval(model: Model, inputs: &[(Layers32, [f32; 3], [f32; 3])], lut: &Lut) -> f64 {
    use std::hint::black_box;
    let mut times: Vec<f64> = (0..5)
        .map(|_| {
            let start = std::time::Instant::now();
            let mut acc = 0.0f32;
            for (l, wi, wo) in inputs {
                acc += model.eval_f32(black_box(l), [0.0, 0.0, 1.0], *wi, *wo, lut)[1];
            }
            black_box(acc);
            start.elapsed().as_secs_f64() * 1e9 / inputs.len().max(1) as f64
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[2]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The noise estimate takes the worst of the eight ±σ directions: never less than moving
    /// every channel up, and for a dark colour several times more (the channels moving
    /// against each other shift hue). Negative control: the all-up shift alone.
    #[test]
    fn the_noise_estimate_takes_the_channels_moving_apart() {
        let (r, sigma) = ([0.004, 0.006, 0.005], [0.0005; 3]);
        let all_up = ciede2000(linear_srgb_to_lab(r.map(|v| v + 0.0005)), linear_srgb_to_lab(r));
        let worst = noise_de(r, sigma);
        eprintln!("noise ΔE00: worst direction {worst:.3}, all channels up {all_up:.3}");
        assert!(worst.is_finite() && worst >= all_up);
        assert!(worst > 2.0 * all_up, "worst {worst}, all channels up {all_up}");
        // No noise, no difference.
        assert_eq!(noise_de(r, [0.0; 3]), 0.0);
    }
}
