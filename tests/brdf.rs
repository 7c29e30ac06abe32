//! The multi-layer BRDF: energy (white furnace), the whole input domain (proptest), the f32
//! path against f64, and each real-time method's f32 function against its own f64 form.
//! Every test that evaluates the BRDF runs over every layer model (`Model::ALL`).

use proptest::prelude::*;
use snakeskin::optics::accuracy::{GRID_MATERIALS, Sample, grid};
use snakeskin::optics::brdf::walk::FilmTables;
use snakeskin::optics::brdf::{ALPHA_MIN, Layers, Model};
use snakeskin::optics::film::{Stack, airy, incoherent};
use snakeskin::optics::lab::{ciede2000, linear_srgb_to_lab};
use snakeskin::optics::lut::Lut;
use snakeskin::optics::methods::{
    gaussian_fit_f32, gaussian_fit_f64, rgb3_f32, rgb3_f64, spectral_n_f32, spectral_n_f64,
};

/// k_d = 1, τ = 0, with the stack's K and E for the film at `thickness_nm`.
fn white_layers(stack: Stack, thickness_nm: f64, roughness: f64) -> Layers {
    Layers::of_stack(stack, thickness_nm, roughness, [0.0; 3], [1.0; 3])
}

#[test]
fn furnace_machinery_integrates_known_cases() {
    // No film reflection: all light reaches the white Lambertian base, albedo exactly 1.
    // (The thesis model has no (n0/n2)² factor: with no film at all its diffuse lobe is the
    // bare Lambertian base, which the integrator must return as 1.)
    let layers = white_layers(Stack::THESIS, 400.0, 0.5);
    let a = Model::Thesis.furnace_albedo(&layers, 0.7, &|_| [0.0; 3], 64);
    assert!(a.iter().all(|v| (v - 1.0).abs() < 2e-3), "{a:?}");
    // A perfect mirror film on a smooth surface at normal view reflects everything.
    let mirror = white_layers(Stack::THESIS, 400.0, 0.0);
    for model in Model::ALL {
        let a = model.furnace_albedo(&mirror, 1.0, &|_| [1.0; 3], 64);
        assert!(a.iter().all(|v| (v - 1.0).abs() < 2e-3), "{model:?} {a:?}");
    }
}

#[test]
fn white_furnace_never_exceeds_one() {
    // Every model, the film from a small LUT: never more than 1 (2e-3: the stratified
    // quadrature's error, measured on the known cases above). The thesis model loses 6–14 %
    // (PHYSICS.md) and the layered model's energy is held to its own bounds below; this is
    // the stability check over the film's extremes.
    let mut worst: f64 = 0.0;
    let stacks =
        [GRID_MATERIALS.to_vec(), vec![Stack { n0: 1.0, n1: 1.0, n2: 1.5 }, Stack { n0: 1.0, n1: 2.5, n2: 1.2 }]]
            .concat();
    for stack in stacks {
        let lut = Lut::bake(stack, 16, 64, 8);
        for thickness in [0.0, 250.0, 400.0, 900.0, 2400.0, 1e7] {
            let film = |c: f64| lut.lookup_f64(thickness, c);
            for roughness in [0.0, 0.05, 0.2, 0.5, 1.0] {
                for cos_o in [1.0, 0.7, 0.3, 0.1, 0.02] {
                    let a = Model::Thesis.furnace_albedo(&white_layers(stack, thickness, roughness), cos_o, &film, 48);
                    worst = a.iter().cloned().fold(worst, f64::max);
                    assert!(
                        a.iter().all(|v| *v <= 1.0 + 2e-3),
                        "{stack:?} d={thickness} r={roughness} cos={cos_o}: {a:?}"
                    );
                }
            }
        }
    }
    assert!(worst > 0.5, "the furnace integrates real energy: {worst}");
}

#[test]
fn layered_model_keeps_the_white_furnace() {
    // The stack reflects everything (k_d = 1, τ = 0), so the albedo must be 1: smooth top
    // (r = 0) within 0.005 at every angle, rough within 0.02 up to 70° and 0.05 beyond
    // (the targets). The film is the exact one (tabulated over the cosine), the one
    // K and E are computed from, so what is measured is the model, not a film method.
    let stacks = [GRID_MATERIALS.to_vec(), vec![Stack { n0: 1.0, n1: 2.5, n2: 1.2 }]].concat();
    let mut worst = [0.0f64; 3];
    for stack in stacks {
        for thickness in [0.0, 250.0, 900.0, 2400.0] {
            let tables = FilmTables::new(stack, thickness);
            let film = |c: f64| tables.above(c);
            for roughness in [0.0, 0.05, 0.2, 0.5, 0.8, 1.0] {
                for cos_o in [1.0, 0.7, 0.35, 0.1, 0.02] {
                    let a = Model::Layered.furnace_albedo(&white_layers(stack, thickness, roughness), cos_o, &film, 64);
                    let err = a.iter().map(|v| (v - 1.0).abs()).fold(0.0, f64::max);
                    let (regime, bound) = if roughness == 0.0 {
                        (0, 0.005)
                    } else if cos_o >= 70f64.to_radians().cos() {
                        (1, 0.02)
                    } else {
                        (2, 0.05)
                    };
                    worst[regime] = worst[regime].max(err);
                    assert!(err <= bound, "{stack:?} d={thickness} r={roughness} cos={cos_o}: {a:?}");
                }
            }
        }
    }
    eprintln!(
        "layered furnace: max |albedo − 1| {:.4} smooth, {:.4} rough θ ≤ 70°, {:.4} rough beyond",
        worst[0], worst[1], worst[2]
    );
}

/// A film less dense than the medium above (n1 < n0) totally reflects beyond its critical
/// angle and, thick, rings with fringes just inside it: F is not smooth in the microfacet
/// cosine, and the lobe's five-point Gauss rule read it as 0.89–1.19 of the light around that
/// angle. The coupling reads such films by the quantile rule (`energy::LobeRule`); the
/// furnace holds to the bounds over thickness, roughness and angles through the
/// critical one from roughness `FILM_BELOW_AMBIENT_ROUGH` up; smoother tops within 0.05
/// (`layered::FilmBelowAmbient`, warned of). Negative control: the same stacks read by the
/// Gauss rule fail.
#[test]
fn a_film_less_dense_than_the_ambient_keeps_the_white_furnace() {
    use snakeskin::optics::brdf::energy::LobeRule;
    let stacks = [Stack { n0: 1.5, n1: 1.35, n2: 2.0 }, Stack { n0: 1.33, n1: 1.18, n2: 2.5 }];
    use snakeskin::optics::brdf::layered::FILM_BELOW_AMBIENT_ROUGH;
    let (mut worst, mut gauss_worst) = ([0.0f64; 3], 0.0f64);
    for stack in stacks {
        for thickness in [250.0, 1500.0, 2400.0] {
            let tables = FilmTables::new(stack, thickness);
            let film = |c: f64| tables.above(c);
            for roughness in [0.0, 0.1, 0.2, 0.35, 0.6, 1.0] {
                let layers = white_layers(stack, thickness, roughness);
                assert_eq!(layers.lobe_rule(), LobeRule::Quantiles);
                for angle_deg in [0.0f64, 30.0, 50.0, 55.0, 60.0, 62.5, 65.0, 70.0, 80.0] {
                    let cos_o = f64::cos(angle_deg.to_radians());
                    let a = Model::Layered.furnace_albedo(&layers, cos_o, &film, 64);
                    let err = a.iter().map(|v| (v - 1.0).abs()).fold(0.0, f64::max);
                    // Tops smoother than `FILM_BELOW_AMBIENT_ROUGH` (warned of): 0.0375 at most
                    // (2400 nm, roughness 0.1, 62.5°); rougher, the bounds.
                    let (regime, bound) = if roughness < FILM_BELOW_AMBIENT_ROUGH {
                        (2, 0.05)
                    } else if angle_deg <= 70.0 {
                        (0, 0.02)
                    } else {
                        (1, 0.05)
                    };
                    worst[regime] = worst[regime].max(err);
                    assert!(err <= bound, "{stack:?} d={thickness} r={roughness} {angle_deg}°: {a:?}");
                    if (thickness, roughness, angle_deg) == (1500.0, 0.35, 60.0) {
                        // As before the quantile rule: a film denser than the ambient gets the
                        // Gauss rule (`LobeRule::of`), so this is that reading.
                        let gauss = Layers { n1: stack.n0, ..layers };
                        let g = Model::Layered.furnace_albedo(&gauss, cos_o, &film, 64);
                        gauss_worst = gauss_worst.max(g.iter().map(|v| (v - 1.0).abs()).fold(0.0, f64::max));
                    }
                }
            }
        }
    }
    eprintln!(
        "film below the ambient: max |albedo − 1| {:.4} up to 70°, {:.4} beyond, {:.4} under tops smoother than {}",
        worst[0], worst[1], worst[2], FILM_BELOW_AMBIENT_ROUGH
    );
    assert!(gauss_worst > 0.1, "the Gauss rule's reading is off: {gauss_worst}");
}

/// A pigment layer less dense than the medium above (n2 < n0) totally reflects at the
/// film's lower face beyond asin(n2 / n0), 53.1° on (1.5, 1.55, 1.2): F has a corner there,
/// and the Gauss rule read the white stack as 0.948 at 45° and 1.082 at 53° (roughness 0.35,
/// `brdf albedo`, an independent review's find); it is read by the quantile rule
/// (`energy::LobeRule::of` takes n2 too). Beyond that angle a rough top still lets light
/// in, through tilted microfacets, and out (`layered::entering`, `exact::SmoothTop::k_e_row`),
/// and much of it straight back (`path::through_rule`'s node for total reflections): the
/// furnace holds to the bounds at every angle. Seen failing with the lobe sending
/// nothing beyond the critical angle (0.238 at 63° on (1.5, 1.55, 1.33), roughness 1), and
/// with one Gauss rule over all of light straight back's last reflections (the top then
/// reflects too little and the lossless E passes 1: 1.07 at 0°).
#[test]
fn a_pigment_less_dense_than_the_ambient_keeps_the_furnace_at_every_angle() {
    use snakeskin::optics::brdf::energy::LobeRule;
    let stacks = [Stack { n0: 1.5, n1: 1.55, n2: 1.2 }, Stack { n0: 1.5, n1: 1.55, n2: 1.33 }];
    let mut worst = [0.0f64; 2];
    for stack in stacks {
        for thickness in [0.0, 400.0, 1500.0] {
            let tables = FilmTables::new(stack, thickness);
            let film = |c: f64| tables.above(c);
            for roughness in [0.05, 0.2, 0.35, 0.6, 1.0] {
                let layers = white_layers(stack, thickness, roughness);
                assert_eq!(layers.lobe_rule(), LobeRule::Quantiles);
                for angle_deg in [0.0f64, 30.0, 45.0, 50.0, 53.0, 55.0, 60.0, 63.0, 70.0, 80.0, 85.0] {
                    let a = Model::Layered.furnace_albedo(&layers, angle_deg.to_radians().cos(), &film, 64);
                    let err = a.iter().map(|v| (v - 1.0).abs()).fold(0.0, f64::max);
                    let (regime, bound) = if angle_deg <= 70.0 { (0, 0.02) } else { (1, 0.05) };
                    worst[regime] = worst[regime].max(err);
                    assert!(err <= bound, "{stack:?} d={thickness} r={roughness} {angle_deg}°: {a:?}");
                }
            }
        }
    }
    eprintln!("pigment below the ambient: max |albedo − 1| {:.4} up to 70°, {:.4} beyond", worst[0], worst[1]);
}

#[test]
fn a_nearly_smooth_top_keeps_the_furnace_at_grazing_light() {
    // Between 86° and 89.3° a low-roughness lobe changes within a few α of grazing
    // (`energy::node_mu`): with the lobe's nodes uniform in μ its rule was read across that
    // whole boundary layer, and the lossless stack reflected up to 3.3 % more than arrives
    // here (0.0331; 0.0199 with nodes uniform in √μ; the negative control, nodes uniform in
    // μ, fails this bound). What is left is the rows' interpolation in roughness, whose
    // single-scatter albedo bends at grazing light (BENCHMARKS.md, "Beyond the grid's 85°").
    let mut worst: f64 = 0.0;
    for stack in GRID_MATERIALS {
        for thickness in [0.0, 250.0] {
            let tables = FilmTables::new(stack, thickness);
            let film = |c: f64| tables.above(c);
            for roughness in [0.05, 0.08, 0.1, 0.15] {
                for angle_deg in [86.0f64, 87.0, 88.0, 89.0, 89.3] {
                    let layers = white_layers(stack, thickness, roughness);
                    let a = Model::Layered.furnace_albedo(&layers, angle_deg.to_radians().cos(), &film, 64);
                    let err = a.iter().map(|v| (v - 1.0).abs()).fold(0.0, f64::max);
                    worst = worst.max(err);
                    assert!(err <= 0.025, "{stack:?} d={thickness} r={roughness} {angle_deg}°: {a:?}");
                }
            }
        }
    }
    eprintln!("layered furnace at 86–89.3°, roughness 0.05–0.15: max |albedo − 1| {worst:.4}");
}

#[test]
fn furnace_with_the_exact_spectral_film() {
    let stack = Stack::THESIS;
    let film = |c: f64| snakeskin::optics::film_rgb_reference(stack, 400.0, c);
    for model in Model::ALL {
        for (roughness, cos_o) in [(0.3, 0.9), (0.8, 0.2)] {
            let a = model.furnace_albedo(&white_layers(stack, 400.0, roughness), cos_o, &film, 16);
            // The thesis model: never above 1; the layered model: within its rough bound.
            let ok = match model {
                Model::Thesis => a.iter().all(|v| *v <= 1.0 + 5e-3 && *v > 0.3),
                Model::Layered => a.iter().all(|v| (v - 1.0).abs() <= 0.02),
            };
            assert!(ok, "{model:?} {a:?}");
        }
    }
}

fn unit(theta: f64, phi: f64) -> [f64; 3] {
    [theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn brdf_is_finite_and_non_negative_everywhere(
        ti in 0.0f64..std::f64::consts::PI, pi in 0.0f64..6.3,
        to in 0.0f64..std::f64::consts::PI, po in 0.0f64..6.3,
        nx in -1.0f64..1.0, ny in -1.0f64..1.0, nz in -1.0f64..1.0, zero_normal in any::<bool>(),
        // Indices from a set (equal, below and above each other, the extremes): each material
        // walks its path table (about a second), which 2,000 random materials would repeat
        // 2,000 times; `path`'s tests walk tables of random indices.
        n0 in proptest::sample::select(vec![1.0, 1.33, 1.7, 2.0]),
        n2 in proptest::sample::select(vec![1.0, 1.2, 1.55, 2.9]),
        roughness in 0.0f64..1.0,
        tau in prop_oneof![Just(0.0), 0.0f64..60.0], albedo in 0.0f64..1.0,
        film_r in prop_oneof![Just(0.0), Just(1.0), -0.1f64..1.1],
        model in proptest::sample::select(Model::ALL.to_vec()),
        k in prop_oneof![Just(0.0), Just(0.999), 0.0f64..1.0], e in 0.0f64..1.0,
    ) {
        let (optical_depth, albedo, k, e) = ([tau; 3], [albedo; 3], [k; 3], [e; 3]);
        let layers = Layers { n0, n1: n2, n2, roughness, optical_depth, albedo, k, e };
        let normal = if zero_normal { [0.0; 3] } else { [nx, ny, nz] };
        let value = model.eval(&layers, normal, unit(ti, pi), unit(to, po), &|_| [film_r; 3]);
        for v in value.total() {
            prop_assert!(v.is_finite() && v >= 0.0, "{value:?}");
        }
    }

    #[test]
    fn film_r_and_t_stay_in_unit_range(
        n0 in 1.0f64..3.0, n1 in 1.0f64..3.0, n2 in 1.0f64..3.0,
        d in prop_oneof![Just(0.0), Just(1e7), 0.0f64..1e5], lambda in 360.0f64..780.0, cos0 in 0.0f64..1.0,
    ) {
        let f = airy(Stack { n0, n1, n2 }, d, lambda, cos0);
        for v in [f.rs, f.rp, f.r, f.ts, f.tp, f.t] {
            prop_assert!(v.is_finite() && (0.0..=1.0).contains(&v));
        }
        let inc = incoherent(Stack { n0, n1, n2 }, cos0);
        prop_assert!((0.0..=1.0).contains(&inc.r) && (0.0..=1.0).contains(&inc.t));
    }
}

#[test]
fn f32_brdf_follows_the_f64_brdf() {
    let stack = Stack::THESIS;
    let lut = Lut::bake(stack, 32, 128, 16);
    let mut worst: f64 = 0.0;
    for (i, roughness, model) in
        [0.05, 0.3, 0.9].into_iter().enumerate().flat_map(|(i, r)| Model::ALL.map(|m| (i, r, m)))
    {
        for t in 0..20 {
            let thickness = 100.0 * t as f64;
            let layers = Layers::of_stack(stack, 400.0, roughness, [0.6, 0.3, 0.1], [0.5, 0.4, 0.2]);
            let layers32 = layers.to_f32(thickness);
            let (wi, wo) = (unit(0.3 + 0.1 * i as f64, 0.5), unit(0.2 + 0.07 * t as f64, 2.0));
            let n = [0.1, -0.05, 1.0];
            let f64v = model.eval(&layers, n, wi, wo, &|c| lut.lookup_f64(thickness, c)).total();
            let f32v = model.eval_f32(&layers32, n.map(|x| x as f32), wi.map(|x| x as f32), wo.map(|x| x as f32), &lut);
            for c in 0..3 {
                // Relative to 1 + f: f32 carries ~7 digits, the peak of D amplifies rounding.
                let dev = (f32v[c] as f64 - f64v[c]).abs() / (1.0 + f64v[c]);
                worst = worst.max(dev);
            }
        }
    }
    assert!(worst < 1e-4, "max relative f32 deviation {worst}");
}

#[test]
fn each_method_f32_agrees_with_its_f64_form() {
    let samples: Vec<Sample> = grid(50.0, 7.0);
    for s in &samples {
        let stack = GRID_MATERIALS[s.material];
        let (n0, n1, n2, d, c) =
            (stack.n0 as f32, stack.n1 as f32, stack.n2 as f32, s.thickness_nm as f32, s.cos0 as f32);
        let pairs: [(&str, [f32; 3], [f64; 3]); 4] = [
            ("rgb3", rgb3_f32(n0, n1, n2, d, c), rgb3_f64(stack, s.thickness_nm, s.cos0)),
            ("spectral-8", spectral_n_f32(n0, n1, n2, d, c, 8), spectral_n_f64(stack, s.thickness_nm, s.cos0, 8)),
            ("spectral-32", spectral_n_f32(n0, n1, n2, d, c, 32), spectral_n_f64(stack, s.thickness_nm, s.cos0, 32)),
            ("gaussian-fit", gaussian_fit_f32(n0, n1, n2, d, c), gaussian_fit_f64(stack, s.thickness_nm, s.cos0)),
        ];
        for (name, a, b) in pairs {
            let de = ciede2000(linear_srgb_to_lab(a.map(|v| v as f64)), linear_srgb_to_lab(b));
            // 0.05 ΔE00 is a twentieth of a just-noticeable difference.
            assert!(de < 0.05, "{name} at {s:?}: f32 {a:?} vs f64 {b:?} (ΔE {de})");
        }
    }
    let lut = Lut::bake(Stack::THESIS, 16, 64, 8);
    for s in samples.iter().filter(|s| s.material == 0) {
        let a = lut.lookup_f32(s.thickness_nm as f32, s.cos0 as f32);
        let b = lut.lookup_f64(s.thickness_nm, s.cos0);
        assert!((0..3).all(|k| (a[k] as f64 - b[k]).abs() < 1e-5), "lut {a:?} {b:?}");
    }
}

/// Beyond the critical angle of a film less dense than the ambient (n1 < n0) the wave in the
/// film is evanescent and the film has no Fourier series in a real phase. Its reflectance then
/// runs from the bare n0|n2 interface's at zero thickness (Fresnel, computed here) to 1 once
/// the film is a few decay lengths thick (total internal reflection); every f32 method keeps
/// both limits and agrees with its f64 form, which reads the exact film (`airy`) there, and
/// so it does cosine by cosine through the critical angle.
#[test]
fn every_f32_method_reads_an_evanescent_film_exactly() {
    let fresnel = |n0: f64, n2: f64, cos0: f64| {
        let eta2 = (n0 / n2) * (n0 / n2);
        let c2 = snakeskin::optics::complex::C64::real((1.0 - eta2) + eta2 * cos0 * cos0).sqrt_upper();
        let c0 = snakeskin::optics::complex::C64::real(cos0);
        let rs = (c0 * n0 - c2 * n2) / (c0 * n0 + c2 * n2);
        let rp = (c0 * n2 - c2 * n0) / (c0 * n2 + c2 * n0);
        0.5 * (rs.norm_sqr() + rp.norm_sqr())
    };
    let stacks = [
        Stack { n0: 1.5, n1: 1.35, n2: 2.0 },
        Stack { n0: 1.33, n1: 1.2, n2: 1.55 },
        Stack { n0: 1.5, n1: 1.3, n2: 1.4 },
    ];
    let mut evanescent_points = 0;
    for stack in stacks {
        let critical = (stack.n1 / stack.n0).asin();
        let (n0, n1, n2) = (stack.n0 as f32, stack.n1 as f32, stack.n2 as f32);
        for step in 0..=24 {
            // From 10° inside the critical angle to 89.5°.
            let theta = critical - 10f64.to_radians()
                + step as f64 / 24.0 * (89.5f64.to_radians() - critical + 10f64.to_radians());
            let cos0 = theta.cos();
            let beyond = theta > critical + 1e-3;
            for d in [0.0, 5.0, 20.0, 60.0, 150.0, 400.0, 1000.0, 2000.0] {
                let (df, c) = (d as f32, cos0 as f32);
                let pairs: [(&str, [f32; 3], [f64; 3]); 4] = [
                    ("rgb3", rgb3_f32(n0, n1, n2, df, c), rgb3_f64(stack, d, cos0)),
                    ("spectral-8", spectral_n_f32(n0, n1, n2, df, c, 8), spectral_n_f64(stack, d, cos0, 8)),
                    ("spectral-32", spectral_n_f32(n0, n1, n2, df, c, 32), spectral_n_f64(stack, d, cos0, 32)),
                    ("gaussian-fit", gaussian_fit_f32(n0, n1, n2, df, c), gaussian_fit_f64(stack, d, cos0)),
                ];
                for (name, a, b) in pairs {
                    let de = ciede2000(linear_srgb_to_lab(a.map(|v| v as f64)), linear_srgb_to_lab(b));
                    assert!(
                        de < 0.05,
                        "{name} {stack:?} θ {:.2}° d {d}: f32 {a:?} vs f64 {b:?} (ΔE {de})",
                        theta.to_degrees()
                    );
                    // A film of no thickness is the bare interface, at every angle (inside
                    // the critical angle too, where |q| → 1 as it nears: the Gaussian fit's
                    // three harmonics read 0.98 for 0.08 there before it took the exact film;
                    // below GAUSSIAN_FIT_MAX_REST their truncation is within 0.01).
                    let bare = fresnel(stack.n0, stack.n2, cos0);
                    let within = if name == "gaussian-fit" { 0.01 } else { 2e-3 };
                    if d == 0.0 {
                        for v in a {
                            assert!((v as f64 - bare).abs() < within, "{name} {stack:?} θ {theta}: bare {bare}, {a:?}");
                        }
                    }
                    if !beyond {
                        continue;
                    }
                    evanescent_points += 1;
                    // The film's decay length λ / (4π n1 κ) at the end of the visible range
                    // (780 nm; spectral-32's last band is centred at 773 nm).
                    let kappa = ((stack.n0 / stack.n1 * theta.sin()).powi(2) - 1.0).sqrt();
                    let decay_nm = 780.0 / (4.0 * std::f64::consts::PI * stack.n1 * kappa);
                    for k in 0..3 {
                        let v = a[k] as f64;
                        if d > 8.0 * decay_nm {
                            assert!(v > 0.995, "{name} {stack:?} θ {theta} d {d}: not total reflection, {a:?}");
                        }
                    }
                }
            }
        }
    }
    assert!(evanescent_points > 500, "{evanescent_points} points beyond the critical angle");
    // Through the critical angle cosine by cosine: the film's reflectance is continuous there
    // (its limit depends on the thickness), with a square-root corner (cos θ1 grows as the
    // root of the cosine's distance from the critical one), so one f32 step of the cosine
    // moves it by up to about 1e-3. Every method follows it, finite, within 0.02 of the
    // cosine before and within ΔE00 0.5 of its f64 form; at the one f32 cosine where cos θ1
    // cancels to exactly 0 on (1.5, 1.3, 1.4) rgb3 gave NaN, then (read as a film without
    // phase) 0.023 for 300 nm where the film reflects 0.485.
    for stack in stacks {
        let (n0, n1, n2) = (stack.n0 as f32, stack.n1 as f32, stack.n2 as f32);
        let critical_cos = (1.0 - (stack.n1 / stack.n0).powi(2)).sqrt() as f32;
        for d in [0.0f32, 300.0, 1500.0] {
            let mut before: Option<[[f32; 3]; 3]> = None;
            for ulps in -300i32..=300 {
                let c = f32::from_bits((critical_cos.to_bits() as i32 + ulps) as u32);
                let (d64, c64) = (d as f64, c as f64);
                let methods = [
                    ("rgb3", rgb3_f32(n0, n1, n2, d, c), rgb3_f64(stack, d64, c64)),
                    ("spectral-8", spectral_n_f32(n0, n1, n2, d, c, 8), spectral_n_f64(stack, d64, c64, 8)),
                    ("gaussian-fit", gaussian_fit_f32(n0, n1, n2, d, c), gaussian_fit_f64(stack, d64, c64)),
                ];
                for (i, (name, a, b)) in methods.iter().enumerate() {
                    assert!(a.iter().all(|v| v.is_finite()), "{name} {stack:?} cos {c} d {d}: {a:?}");
                    let step = before.map_or(0.0, |p| (0..3).map(|k| (a[k] - p[i][k]).abs()).fold(0.0, f32::max));
                    assert!(
                        step < 0.02,
                        "{name} {stack:?} cos {c} d {d}: {a:?}, a step of {step} from the cosine before"
                    );
                    // f32's cos θ1 there is the root of a sum that cancels to its last bits,
                    // so on the corner it reads up to about 1e-3 off: ΔE00 0.064 at most seen.
                    let de = ciede2000(linear_srgb_to_lab(a.map(|v| v as f64)), linear_srgb_to_lab(*b));
                    assert!(de < 0.5, "{name} {stack:?} cos {c} d {d}: f32 {a:?} vs f64 {b:?} (ΔE {de})");
                }
                before = Some(methods.map(|(_, a, _)| a));
            }
        }
    }
}

/// The exact film (f64) through the critical angle of a film less dense than the ambient,
/// cosine by cosine: where cos θ1 cancels to exactly 0 (r01 = 1, r12 = −1: Airy divides 0 by
/// 0) it read 1 at every thickness, where the film is smooth through that angle: a bare film
/// reflects as the n0|n2 interface, 0.0073 on (1.33, 1, 1.5) (an independent review's find,
/// with 50-digit arithmetic). Every f64 cosine within 2000 of the critical one, for 0, 300 and
/// 1500 nm films: within 1e-4 of the cosine before; the sweep passes an exact 0.
#[test]
fn the_exact_film_is_smooth_through_the_films_critical_angle() {
    for stack in [Stack { n0: 1.33, n1: 1.0, n2: 1.5 }, Stack { n0: 1.5, n1: 1.3, n2: 1.4 }] {
        let eta2 = (stack.n0 / stack.n1).powi(2);
        let critical_cos = (1.0 - (stack.n1 / stack.n0).powi(2)).sqrt();
        let mut exact_zeros = 0;
        for d in [0.0, 300.0, 1500.0] {
            let mut before: Option<f64> = None;
            for ulps in -2000i64..=2000 {
                let c = f64::from_bits((critical_cos.to_bits() as i64 + ulps) as u64);
                exact_zeros += usize::from(d == 0.0 && (1.0 - eta2) + eta2 * c * c == 0.0);
                let r = airy(stack, d, 550.0, c).r;
                let step = before.map_or(0.0, |p| (r - p).abs());
                assert!(step < 1e-4, "{stack:?} cos {c} d {d}: {r}, a step of {step} from the cosine before");
                before = Some(r);
            }
        }
        if stack.n1 == 1.0 {
            assert!(exact_zeros > 0, "no cosine of {stack:?} where cos θ1 is exactly 0");
        }
    }
}

/// Light so near grazing that cos0² underflows (f64 below 1e-154, f32 below 1e-19) on a film
/// as dense as its ambient (n1 = n0, where cos θ1 is cos θ0): cos θ1 read 0 there, r01 = 1
/// and r12 = −1 divided 0 by 0 (NaN). It is grazing light, all but all reflected: every
/// method, f64 and f32, reads within 1e-3 of 1, as at cos0 = 0 itself.
#[test]
fn light_at_an_underflowing_grazing_cosine_is_reflected() {
    let stack = Stack { n0: 1.5, n1: 1.5, n2: 1.3 };
    for c in [0.0, 1e-170, 1e-300] {
        for d in [0.0, 300.0] {
            let r = airy(stack, d, 550.0, c).r;
            assert!((r - 1.0).abs() < 1e-3, "airy {stack:?} cos {c} d {d}: {r}");
        }
    }
    for c in [0.0f32, 1e-25, 1e-40] {
        for d in [0.0f32, 300.0] {
            let methods = [
                ("rgb3", rgb3_f32(1.5, 1.5, 1.3, d, c)),
                ("spectral-8", spectral_n_f32(1.5, 1.5, 1.3, d, c, 8)),
                ("gaussian-fit", gaussian_fit_f32(1.5, 1.5, 1.3, d, c)),
            ];
            for (name, a) in methods {
                assert!(a.iter().all(|v| (v - 1.0).abs() < 1e-3), "{name} cos {c} d {d}: {a:?}");
            }
        }
    }
}

#[test]
fn thick_films_converge_to_the_incoherent_limit() {
    // From 20 µm to 10 mm every method's colour stays within ΔE00 1.0 (a just-noticeable
    // difference) of the incoherent limit, so no thickness shows moiré or colour noise.
    for stack in GRID_MATERIALS {
        let lut = Lut::bake(stack, 16, 64, 16);
        for cos0 in [1.0, 0.5, 0.1] {
            let inc = incoherent(stack, cos0).r;
            let lab_inc = linear_srgb_to_lab([inc; 3]);
            for d in [2.0e4, 3.3e4, 5.0e4, 1.0e5, 2.4e6, 1.0e7] {
                let (n0, n1, n2) = (stack.n0 as f32, stack.n1 as f32, stack.n2 as f32);
                let colours: [(&str, [f64; 3]); 5] = [
                    ("rgb3", rgb3_f32(n0, n1, n2, d as f32, cos0 as f32).map(|v| v as f64)),
                    ("spectral-8", spectral_n_f32(n0, n1, n2, d as f32, cos0 as f32, 8).map(|v| v as f64)),
                    ("spectral-32", spectral_n_f64(stack, d, cos0, 32)),
                    ("gaussian-fit", gaussian_fit_f64(stack, d, cos0)),
                    ("lut", lut.lookup_f64(d, cos0)),
                ];
                for (name, rgb) in colours {
                    let de = ciede2000(linear_srgb_to_lab(rgb), lab_inc);
                    assert!(de < 1.0, "{name} {stack:?} d={d} cos={cos0}: ΔE {de}");
                }
            }
        }
    }
}

#[test]
fn roughness_zero_uses_the_documented_floor() {
    let layers = Layers::of_stack(Stack::THESIS, 400.0, 0.0, [0.0; 3], [0.0; 3]);
    // At the mirror direction D = 1 / (π α²) with α = ALPHA_MIN and G2 = 1: f = D / 4.
    let expected = 1.0 / (std::f64::consts::PI * ALPHA_MIN * ALPHA_MIN) / 4.0;
    for model in Model::ALL {
        let v = model.eval(&layers, [0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [0.0, 0.0, 1.0], &|_| [1.0; 3]);
        assert!((v.specular[0] - expected).abs() / expected < 1e-9, "{model:?} {v:?}");
    }
}

/// The renderer takes K and E per film thickness (`BounceGrid`): the white furnace holds
/// across a material's whole thickness range, not only at its middle.
#[test]
fn the_renderer_keeps_the_furnace_across_the_thickness_range() {
    use snakeskin::render::engine::scene::{BOUNCE_THICKNESSES, BounceGrid, LayerOptics};
    let worst = |optics: &LayerOptics, grid: &BounceGrid| {
        let lut = snakeskin::optics::lut::Lut::bake_default(optics.stack);
        let (lo, hi) = optics.thickness_range_nm;
        let (mut to_70, mut beyond): (f64, f64) = (0.0, 0.0);
        for k in 0..=20 {
            // Nodes and the points halfway between them.
            let d = lo + (hi - lo) * k as f64 / 20.0;
            for roughness in [0.0, 0.3, 0.6, 1.0] {
                for cos in [1.0, 0.5, 0.2] {
                    let layers = optics.layers(Model::Layered, grid, d, roughness, [1.0; 3]);
                    let a = Model::Layered.furnace_albedo(&layers, cos, &|c| lut.lookup_f64(d, c), 24);
                    let err = a.iter().map(|v| (v - 1.0).abs()).fold(0.0, f64::max);
                    if cos >= 70f64.to_radians().cos() { to_70 = to_70.max(err) } else { beyond = beyond.max(err) }
                }
            }
        }
        (to_70, beyond)
    };
    for (stack, range) in [
        (Stack::THESIS, (150.0, 350.0)),
        (Stack::THESIS, (0.0, 200.0)),
        (Stack { n0: 1.0, n1: 1.56, n2: 1.33 }, (0.0, 200.0)),
    ] {
        let optics = LayerOptics { stack, thickness_range_nm: range, optical_depth: [0.0; 3] };
        let grid = optics.bounce_grid(Model::Layered);
        assert_eq!(grid.tables.len(), BOUNCE_THICKNESSES);
        let (to_70, beyond) = worst(&optics, &grid);
        assert!(to_70 <= 0.02 && beyond <= 0.05, "{stack:?} {range:?}: {to_70} up to 70°, {beyond} beyond");
        // Negative control: K and E of the middle thickness everywhere, as the first version.
        let middle = grid.tables[BOUNCE_THICKNESSES / 2].clone();
        let flat = BounceGrid { tables: vec![middle; BOUNCE_THICKNESSES], ..grid };
        let (flat_70, _) = worst(&optics, &flat);
        eprintln!("{stack:?} {range:?}: grid {to_70:.4} / {beyond:.4}; middle thickness alone {flat_70:.4} up to 70°");
        assert!(flat_70 > 0.03, "{stack:?} {range:?}: the middle thickness alone gave {flat_70}");
    }
}

/// The worst difference between the LUT's coupling table and the rule it tabulates
/// (`energy::top_f32` with the film read from the same LUT), over `count` deterministic
/// points (cosine, roughness, and a thickness from `thickness_nm`), in the reflected share
/// and in the multiple-scatter amplitude.
fn coupling_table_deviation(
    lut: &Lut,
    count: i32,
    thickness_nm: impl Fn(f32) -> f32,
    cos: impl Fn(f32) -> f32,
) -> (f32, f32) {
    let (mut reflected, mut amplitude) = (0.0f32, 0.0f32);
    for i in 0..count {
        let u = |k: u32| snakeskin::ops::hash::unit(i, 0, k, 23);
        let (d, cos, r) = (thickness_nm(u(0)), cos(u(1)), u(2));
        let film = |c: f32| lut.lookup_f32(d, c.clamp(0.0, 1.0)).map(|v| v.clamp(0.0, 1.0));
        let through = &snakeskin::optics::brdf::path::cached(lut.stack.n0, lut.stack.n2).through_f32;
        let lobe_rule = snakeskin::optics::brdf::energy::LobeRule::of(lut.stack.n0, lut.stack.n1, lut.stack.n2);
        let rule = snakeskin::optics::brdf::energy::top_f32(cos, r, &film, through, lobe_rule);
        let (table, _) = lut.coupling_f32(d, cos, r);
        for c in 0..3 {
            reflected = reflected.max((table.reflected[c] - rule.reflected[c]).abs());
            amplitude = amplitude.max((table.ms_amplitude[c] - rule.ms_amplitude[c]).abs());
        }
    }
    (reflected, amplitude)
}

#[test]
fn coupling_table_is_the_rule_it_tabulates() {
    // On a cos texel of a thickness column the table holds the rule's result and
    // interpolates between roughness rows as the rule does: the same up to f32 rounding, at
    // any roughness. Between texels and columns it interpolates the results where the rule
    // interpolates the lobe and the film (the rule is linear in neither): the reflected
    // share within 0.005 everywhere (measured ≤ 0.0026 on the four materials, 20,000 points
    // each), the multiple-scatter amplitude x / √(π X̄) within 0.008 for cos ≥ 0.1 and 0.2
    // below, where it rises steeply towards grazing (measured ≤ 0.0069 and ≤ 0.150, nearly
    // all of it between cos texels: between thickness columns ≤ 0.0014). The cos texels are
    // uniform in √cos (`lut::coupling_texel_cos`), as the lobe's nodes; with both uniform in
    // cos the amplitude was ≤ 0.090 below 0.1, but the rule itself then missed the boundary
    // layer of a low-roughness lobe at grazing light, where its amplitude rises several times
    // higher than it read (texels uniform in cos under nodes uniform in √μ: 4.6 off). With
    // the earlier amplitude (1 − E₁) √g, ≤ 0.0045 and ≤ 0.02.
    for stack in GRID_MATERIALS {
        let lut = Lut::bake(stack, 64, 256, 64);
        let fine_step = 2000.0 / 255.0;
        let on_column = |u: f32| (u * 255.0).floor() * fine_step;
        let on_texel = |u: f32| snakeskin::optics::lut::coupling_texel_cos((u * 63.0).floor() as usize, 64);
        let (reflected, amplitude) = coupling_table_deviation(&lut, 5_000, on_column, on_texel);
        assert!(reflected < 2e-6 && amplitude < 2e-6, "{stack:?} on texels: {reflected} {amplitude}");
        let (r1, a1) = coupling_table_deviation(&lut, 20_000, |u| 3000.0 * u, |u| 0.1 + 0.9 * u);
        assert!(r1 < 0.005 && a1 < 0.008, "{stack:?}, cos ≥ 0.1: {r1} {a1}");
        let (reflected, amplitude) = coupling_table_deviation(&lut, 20_000, |u| 3000.0 * u, |u| 0.1 * u);
        eprintln!("{stack:?}: between texels, cos ≥ 0.1: {r1:.4} {a1:.4}; cos < 0.1: {reflected:.4} {amplitude:.4}");
        assert!(reflected < 0.005 && amplitude < 0.2, "{stack:?}, cos < 0.1: {reflected} {amplitude}");
    }
    // Negative control: a table whose roughness rows are shifted by one is caught.
    let lut = Lut::bake(Stack::THESIS, 64, 256, 64);
    let mut shifted = lut.coupling().to_vec();
    shifted.rotate_left(lut.n_cos);
    let lut = lut.with_coupling(shifted);
    let (reflected, _) = coupling_table_deviation(&lut, 5_000, |u| 3000.0 * u, |u| u);
    assert!(reflected > 0.01, "shifted rows not caught: {reflected}");
}

#[test]
fn one_coupling_fetch_for_both_directions_is_two_fetches_bit_for_bit() {
    // `eval_f32` reads the light's and the view's coupling in one call that finds the
    // (thickness, roughness) corners once; it must be the two single fetches exactly, over
    // both thickness ranges and beyond, and at the ends of the cos and roughness axes.
    let lut = Lut::bake(Stack::THESIS, 64, 256, 64);
    let ends = |u: f32| {
        if u < 0.1 {
            0.0
        } else if u > 0.9 {
            1.0
        } else {
            u
        }
    };
    for i in 0..20_000 {
        let u = |k: u32| snakeskin::ops::hash::unit(i, 0, k, 29);
        let (d, r, cos) = (25_000.0 * u(0) * u(0), ends(u(1)), [ends(u(2)), ends(u(3))]);
        let pair = lut.coupling_pair_f32(d, cos, r);
        for (k, (top, delta)) in pair.iter().enumerate() {
            let (single, single_delta) = lut.coupling_f32(d, cos[k], r);
            let bits = |t: &snakeskin::optics::brdf::energy::Top<f32>, delta: f32| {
                [t.reflected, t.ms_amplitude].concat().into_iter().chain([delta]).map(f32::to_bits).collect::<Vec<_>>()
            };
            assert_eq!(bits(top, *delta), bits(&single, single_delta), "d {d} r {r} cos {cos:?} direction {k}");
        }
    }
}

/// Light that crosses the rough top and comes straight back through it (in through one
/// microfacet, out through another, up off a third: `path::PathTable::through`) against
/// the photon walk of the whole stack, with a black base so that nothing comes back from
/// it: at 85° and roughness 0.9 on (1, 1.56, 1.33) under a 650 nm film, what the model's
/// top reflects (its `coupling`) and what the walk returns. Measured: within 0.006 with the
/// term, 0.011–0.017 too little without it (the negative control).
#[test]
fn light_straight_back_through_the_rough_top_meets_the_walk() {
    use snakeskin::optics::brdf::{energy, path, walk};
    let stack = Stack { n0: 1.0, n1: 1.56, n2: 1.33 };
    let film = FilmTables::new(stack, 650.0);
    let film_fn = |c: f64| film.above(c).map(|v| v.clamp(0.0, 1.0));
    let mu = 85f64.to_radians().cos();
    let layers = Layers::of_stack(stack, 650.0, 0.9, [0.0; 3], [0.0; 3]);
    let walked = walk::walk(&layers, &film, [(1.0 - mu * mu).sqrt(), 0.0, mu], 200_000, 1, 17);
    let rule = energy::LobeRule::of(stack.n0, stack.n1, stack.n2);
    let with = energy::top(mu, 0.9, &film_fn, &path::cached(stack.n0, stack.n2).through, rule);
    let without = energy::top(mu, 0.9, &film_fn, &[], rule);
    for c in 0..3 {
        let reference = walked.total()[c];
        assert!(walked.diffuse[c] > 0.01, "the walk finds the light that comes straight back: {:?}", walked.diffuse);
        assert!(
            (with.reflected[c] - reference).abs() < 0.007,
            "channel {c}: model {}, walk {reference}",
            with.reflected[c]
        );
        assert!(reference - without.reflected[c] > 0.009, "channel {c}: without the term {}", without.reflected[c]);
    }
}

/// Under a pigment layer less dense than the ambient (n0 > n2) most of the light a rough top
/// lets in at oblique angles comes straight back: in through one microfacet, out through
/// another (at roughness 1 and 70° on 1.5 | 1.33, 0.49 of the light, against 0.08 that never
/// enters). Its last reflections from above are total beyond the critical angle, for any
/// film, and `path::through_rule` gives them a node of their own; the top's reflection then
/// meets the walk's, with a black base so that nothing comes back from it. Seen failing with
/// one Gauss rule over all last reflections (off by 0.32; 0.383 against 0.574 at 70° on the
/// bare interface, roughness 1, with the term below as it was too) and with light straight
/// back a share of the light in through the lobe's first microfacet only, 1 − ⟨F⟩ (0.066).
/// Left: up to 0.041 too little at roughness 0.6 (a 400 nm film, 70°; the bare
/// interface at 50°, 0.133 against 0.157), light the multiple scattering's pair rule
/// (`energy::Multiple`, read at fixed cosines) misses across the same corner.
#[test]
fn light_straight_back_under_a_pigment_less_dense_than_the_ambient_meets_the_walk() {
    use snakeskin::optics::brdf::{energy, path, walk};
    let stack = Stack { n0: 1.5, n1: 1.4, n2: 1.33 };
    let mut worst = 0.0f64;
    for thickness in [0.0, 400.0] {
        let film = FilmTables::new(stack, thickness);
        let film_fn = |c: f64| film.above(c).map(|v| v.clamp(0.0, 1.0));
        for roughness in [0.6, 1.0] {
            let layers = Layers::of_stack(stack, thickness, roughness, [0.0; 3], [0.0; 3]);
            for angle_deg in [0.0f64, 50.0, 70.0, 80.0] {
                let mu = angle_deg.to_radians().cos();
                let walked = walk::walk(&layers, &film, [(1.0 - mu * mu).sqrt(), 0.0, mu], 100_000, 1, 29);
                let rule = energy::LobeRule::of(stack.n0, stack.n1, stack.n2);
                let top = energy::top(mu, roughness, &film_fn, &path::cached(stack.n0, stack.n2).through, rule);
                for c in 0..3 {
                    let (model, reference) = (top.reflected[c], walked.total()[c]);
                    worst = worst.max((model - reference).abs());
                }
            }
        }
    }
    eprintln!("pigment below the ambient: the top's reflection off the walk's by {worst:.4} at most");
    assert!(worst < 0.05, "{worst}");
}
