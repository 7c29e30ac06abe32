//! The layer stack's transport against an independent simulation: the smooth-top closed
//! form (`optics::brdf::exact`) against photons followed one by one (`optics::brdf::walk`),
//! over random stacks, optical depths, base albedos and angles. The two share only the
//! film's reflectance; the geometric series, the escape cone, (n0/n2)², K and E are the
//! closed form's alone.

use snakeskin::optics::brdf::exact::{SmoothTop, gauss_legendre};
use snakeskin::optics::brdf::walk::{FilmTables, Rng, walk};
use snakeskin::optics::brdf::{Layers, Model};
use snakeskin::optics::film::Stack;

const PHOTONS: u64 = 100_000;
const BINS: usize = 6;
/// Bias allowed on top of 3σ: the walk's film tables interpolate linearly (< 1e-5).
const TABLE_BIAS: f64 = 2e-5;

/// ∫ over the bin [lo, hi) of cos θo of f_diff(μi, μo) cos θo dωo = 2π ∫ f μo dμo.
fn closed_form_bin(top: &SmoothTop, layers: &Layers, cos_i: f64, lo: f64, hi: f64) -> [f64; 3] {
    let mut sum = [0.0; 3];
    for (mu, w) in gauss_legendre(12, lo, hi) {
        let f = top.diffuse(layers, cos_i, mu);
        for c in 0..3 {
            sum[c] += w * 2.0 * std::f64::consts::PI * f[c] * mu;
        }
    }
    sum
}

#[test]
fn smooth_top_closed_form_matches_the_random_walk() {
    let mut rng = Rng(2024);
    let stacks = [
        Stack::THESIS,
        Stack { n0: 1.0, n1: 1.56, n2: 1.33 },
        Stack { n0: 1.33, n1: 1.55, n2: 2.0 },
        Stack { n0: 1.0, n1: 1.33, n2: 1.56 },
    ];
    let mut worst_sigmas: f64 = 0.0;
    let (mut z2_sum, mut z2_count) = (0.0, 0);
    let mut thesis_worst_sigmas: f64 = 0.0;
    for case in 0..8 {
        let stack = stacks[case % stacks.len()];
        let thickness_nm = 2000.0 * rng.unit();
        let tau = [0.0, 0.4, 1.0, 2.0 * rng.unit()];
        let optical_depth = [tau[case % 4], tau[(case + 1) % 4], 0.3 * rng.unit()];
        let albedo = [0.05 + 0.9 * rng.unit(), 0.05 + 0.9 * rng.unit(), 1.0];
        let layers = Layers::of_stack(stack, thickness_nm, 0.0, optical_depth, albedo);
        let cos_i = 0.05 + 0.95 * rng.unit();
        let wi = [(1.0 - cos_i * cos_i).sqrt(), 0.0, cos_i];
        let top = SmoothTop::new(stack, thickness_nm);
        let tables = FilmTables::new(stack, thickness_nm);
        let walked = walk(&layers, &tables, wi, PHOTONS, BINS, 7 + case as u64);
        let exact = top.albedo(&layers, cos_i);
        let label = format!(
            "{stack:?} d={thickness_nm:.0} τ={:?} k_d={:?} cos={cos_i:.3}",
            layers.optical_depth, layers.albedo
        );
        // Totals within 3σ; the 144 bins within 4σ (with that many draws a 3σ excursion
        // is expected once in three seeds), and the mean z² near 1 (a bias shows there).
        let mut check = |name: &str, walked: f64, sigma: f64, exact: f64, bound: f64| {
            let off = (walked - exact).abs() / (sigma + TABLE_BIAS / 3.0);
            worst_sigmas = worst_sigmas.max(off);
            z2_sum += off * off;
            z2_count += 1;
            assert!(off <= bound, "{label}: {name} walk {walked:.5} ± {sigma:.5}, closed form {exact:.5} ({off:.1}σ)");
        };
        for c in 0..3 {
            check("specular", walked.specular[c], walked.specular_sigma[c], exact.specular[c], 3.0);
            check("diffuse", walked.diffuse[c], walked.diffuse_sigma[c], exact.diffuse[c], 3.0);
            for b in 0..BINS {
                let (lo, hi) = (b as f64 / BINS as f64, (b + 1) as f64 / BINS as f64);
                let p = walked.diffuse_bins[b][c];
                let sigma = (p * (1.0 - p) / PHOTONS as f64).sqrt();
                check(
                    &format!("diffuse in cos θo ∈ [{lo:.2}, {hi:.2})"),
                    p,
                    sigma,
                    closed_form_bin(&top, &layers, cos_i, lo, hi)[c],
                    4.0,
                );
            }
        }
        // Negative control: the thesis model's diffuse albedo (no (n0/n2)², no light sent
        // back down) is far outside the walk's noise on the same stack.
        let film = |cos: f64| snakeskin::optics::brdf::exact::reflectance(stack, thickness_nm, cos);
        let thesis = Model::Thesis.furnace_albedo(&Layers { roughness: 0.0, ..layers }, cos_i, &film, 32);
        let walked_total = walked.total();
        let sigma_total = walked.total_sigma();
        let off = (0..3).map(|c| (thesis[c] - walked_total[c]).abs() / sigma_total[c]).fold(0.0, f64::max);
        thesis_worst_sigmas = thesis_worst_sigmas.max(off);
    }
    let mean_z2 = z2_sum / z2_count as f64;
    eprintln!(
        "closed form vs walk: worst {worst_sigmas:.2}σ, mean z² {mean_z2:.2} over {z2_count}; thesis model vs walk: worst {thesis_worst_sigmas:.0}σ"
    );
    // For unbiased estimates E[z²] = 1; its standard error over ~190 draws is ~0.1.
    assert!(mean_z2 < 1.5, "mean z² {mean_z2}: the walk and the closed form disagree on average");
    assert!(thesis_worst_sigmas > 20.0, "the walk cannot tell the thesis model from the exact transport");
}

#[test]
fn rough_walk_conserves_energy_in_the_white_furnace() {
    // k_d = 1, τ = 0: nothing is absorbed, so every photon comes back out, however rough.
    let stack = Stack::THESIS;
    let tables = FilmTables::new(stack, 400.0);
    for roughness in [0.3, 0.7, 1.0] {
        let layers = Layers::of_stack(stack, 400.0, roughness, [0.0; 3], [1.0; 3]);
        for cos_i in [1.0f64, 0.5, 0.1] {
            let wi = [(1.0 - cos_i * cos_i).sqrt(), 0.0, cos_i];
            let walked = walk(&layers, &tables, wi, 20_000, 1, 3);
            let total = walked.total();
            assert!(total.iter().all(|v| *v == 1.0), "r={roughness} cos={cos_i}: {total:?}");
        }
    }
    // Negative control: with absorption photons are lost.
    let layers = Layers::of_stack(stack, 400.0, 0.5, [0.5; 3], [1.0; 3]);
    let walked = walk(&layers, &tables, [0.0, 0.0, 1.0], 20_000, 1, 3);
    assert!(walked.total().iter().all(|v| *v < 0.9), "{:?}", walked.total());
}
