//! GPU tests: every shader validates (naga), and the WGSL BRDF matches its Rust f32 twin.
//! They run for real on Mesa's software Vulkan (lavapipe) in CI. Without an adapter they
//! skip with a printed reason, unless SNAKESKIN_REQUIRE_GPU=1 (set in .ci/run), which makes
//! a missing adapter a failure.

use snakeskin::optics::brdf::{Layers, Model};
use snakeskin::optics::film::Stack;
use snakeskin::optics::lut::Lut;
use snakeskin::render::engine::material::round_to_f16;
use snakeskin::render::reference::brdf_eval::{GpuSample, eval_on_gpu};
use snakeskin::render::shader_programs;

mod common;
use common::gpu_or_skip;

#[test]
fn every_wgsl_file_parses_and_validates() {
    let programs = shader_programs();
    for (name, source, _) in &programs {
        let module =
            naga::front::wgsl::parse_str(source).unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(source)));
        naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::default())
            .validate(&module)
            .unwrap_or_else(|e| panic!("{name}: {e:?}"));
    }
    // Every file in shaders/ is part of some program (so none escapes validation).
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/shaders");
    for entry in std::fs::read_dir(dir).unwrap() {
        let file = entry.unwrap().file_name().to_string_lossy().into_owned();
        if file.ends_with(".wgsl") {
            assert!(programs.iter().any(|(_, _, files)| files.contains(&file.as_str())), "{file} is in no program");
        }
    }
}

/// SplitMix64, so the inputs are the same on every run.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f32 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
    }
    fn direction(&mut self, upper: bool) -> [f32; 3] {
        let cos = if upper { self.next() } else { self.next() * 2.0 - 1.0 };
        let phi = self.next() * std::f32::consts::TAU;
        let sin = (1.0 - cos * cos).max(0.0).sqrt();
        [sin * phi.cos(), sin * phi.sin(), cos]
    }
}

#[test]
fn wgsl_brdf_matches_the_rust_twin_on_10000_inputs() {
    let Some(gpu) = gpu_or_skip("wgsl_brdf_matches_the_rust_twin") else { return };
    let stack = Stack::THESIS;
    let lut = Lut::bake(stack, 32, 128, 32);
    let mut rng = Rng(42);
    let mut layers = Vec::new();
    let mut samples = Vec::new();
    for i in 0..10_000 {
        // Every 10th sample is a mirror (roughness 0) or fully rough, the extremes.
        let roughness = match i % 10 {
            0 => 0.0,
            1 => 1.0,
            _ => 0.02 + 0.98 * rng.next(),
        };
        let tau = [rng.next() * 3.0, rng.next() * 3.0, rng.next() * 3.0].map(f64::from);
        let albedo = [rng.next(), rng.next(), rng.next()].map(f64::from);
        let thickness_nm = match i % 7 {
            0 => 0.0,
            1 => 1.0e7,
            _ => rng.next() * 3000.0,
        };
        // K and E from the film at 400 nm (as the renderer: one thickness per material).
        let l = Layers::of_stack(stack, 400.0, roughness as f64, tau, albedo).to_f32(thickness_nm as f64);
        // Mostly upper hemisphere (where the BRDF is non-zero), some anywhere.
        let upper = i % 5 != 0;
        let normal = if i % 50 == 0 {
            [0.0, 0.0, 0.0]
        } else {
            let d = rng.direction(true);
            [d[0] * 0.3, d[1] * 0.3, 1.0]
        };
        let (wi, wo) = (rng.direction(upper), rng.direction(upper));
        samples.push(GpuSample::new(&l, normal, wi, wo));
        layers.push((l, normal, wi, wo));
    }
    // The GPU holds the table as a half-float texture: its CPU twin reads the same values.
    let mut lut_f16 = lut.clone().with_coupling(lut.coupling().iter().map(|t| t.map(round_to_f16)).collect());
    lut_f16.texels = lut.texels.iter().map(|t| t.map(round_to_f16)).collect();
    for model in Model::ALL {
        let gpu_values = eval_on_gpu(&gpu, model, &lut, &samples).expect("gpu evaluation");
        assert_eq!(gpu_values.len(), samples.len());
        let mut worst: f32 = 0.0;
        let mut non_zero = 0;
        for ((l, n, wi, wo), g) in layers.iter().zip(&gpu_values) {
            let cpu = model.eval_f32(l, *n, *wi, *wo, &lut_f16);
            if cpu.iter().any(|v| *v > 0.0) {
                non_zero += 1;
            }
            for c in 0..3 {
                assert!(g[c].is_finite(), "{model:?}: GPU value not finite for {l:?}");
                // Relative to 1 + f: the GPU's sqrt, exp and division may round differently
                // from the CPU's, and GGX's peak (up to ~3e5 at roughness 0) amplifies that.
                worst = worst.max((g[c] - cpu[c]).abs() / (1.0 + cpu[c].abs()));
            }
        }
        eprintln!(
            "{model:?}: max |gpu - cpu| / (1 + cpu) = {worst:e} over {} samples ({non_zero} non-zero)",
            samples.len()
        );
        assert!(non_zero > 5000, "the inputs exercise the BRDF: {non_zero}");
        // Measured 4.2e-7 on lavapipe (llvmpipe, Vulkan), whose texture filter interpolates in
        // f32; 1e-4 leaves room for GPUs with faster, less exact sqrt and exp. (GPUs that
        // quantise bilinear weights to 8 bits may need more: up to 1/512 of a texel step.)
        assert!(worst < 1e-4, "{model:?}: GPU and CPU BRDF differ by {worst}");
    }
}

#[test]
fn bench_gpu_reports_both_costs() {
    let Some(_gpu) = gpu_or_skip("bench_gpu_reports_both_costs") else { return };
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_snakeskin"))
        .args(["bench", "gpu", "--samples", "20000", "--json"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["samples"], 20000);
    assert!(v["adapter"].as_str().is_some_and(|a| !a.is_empty()));
    // Both costs are measured, not clamped: a difference of timings that is not positive is
    // an error of `bench gpu`, so zero here would mean the measurement is broken.
    for key in ["gpu_ms_per_million", "cpu_f32_ms_per_million"] {
        let ms = v[key].as_f64().unwrap();
        assert!(ms.is_finite() && ms > 0.0, "{key} = {ms}");
    }
}

#[test]
fn every_gpu_film_method_matches_its_cpu_f32_twin() {
    use snakeskin::optics::methods::{gaussian_fit_f32, rgb3_f32, spectral_n_f32};
    use snakeskin::render::engine::film::GpuFilmMethod;
    use snakeskin::render::reference::brdf_eval::eval_timed;
    let Some(gpu) = gpu_or_skip("every_gpu_film_method_matches_its_cpu_f32_twin") else { return };
    let stack = Stack::THESIS;
    let lut = Lut::bake(stack, 16, 32, 8);
    let mut rng = Rng(7);
    let mut inputs = Vec::new();
    let mut samples = Vec::new();
    for i in 0..4000 {
        let roughness = 0.05 + 0.95 * rng.next() as f64;
        let tau = [rng.next(), rng.next(), rng.next()].map(f64::from);
        let albedo = [rng.next(), rng.next(), rng.next()].map(f64::from);
        let thickness_nm = if i % 9 == 0 { 2.4e6 } else { rng.next() as f64 * 2500.0 };
        let l = Layers::of_stack(stack, 400.0, roughness, tau, albedo).to_f32(thickness_nm);
        let (wi, wo) = (rng.direction(true), rng.direction(true));
        samples.push(GpuSample::new(&l, [0.0, 0.0, 1.0], wi, wo));
        inputs.push((l, wi, wo));
    }
    type Film = fn(f32, f32) -> [f32; 3];
    let methods: [(GpuFilmMethod, Film); 4] = [
        (GpuFilmMethod::Rgb3, |d, c| rgb3_f32(1.0, 1.55, 2.0, d, c)),
        (GpuFilmMethod::SpectralN(8), |d, c| spectral_n_f32(1.0, 1.55, 2.0, d, c, 8)),
        (GpuFilmMethod::SpectralN(32), |d, c| spectral_n_f32(1.0, 1.55, 2.0, d, c, 32)),
        (GpuFilmMethod::GaussianFit, |d, c| gaussian_fit_f32(1.0, 1.55, 2.0, d, c)),
    ];
    for (model, (method, film)) in Model::ALL.into_iter().flat_map(|m| methods.map(|f| (m, f))) {
        let (gpu_values, _) = eval_timed(&gpu, model, stack, &lut, method, &samples, 1).expect("gpu evaluation");
        let mut worst = 0.0f64;
        for ((l, wi, wo), g) in inputs.iter().zip(&gpu_values) {
            let layers = Layers {
                n0: l.n0 as f64,
                n2: l.n2 as f64,
                roughness: l.roughness as f64,
                optical_depth: l.optical_depth.map(|v| v as f64),
                albedo: l.albedo.map(|v| v as f64),
                k: l.k.map(|v| v as f64),
                e: l.e.map(|v| v as f64),
            };
            let d = l.thickness_nm;
            let cpu = model
                .eval(&layers, [0.0, 0.0, 1.0], wi.map(|v| v as f64), wo.map(|v| v as f64), &|c| {
                    film(d, c as f32).map(|v| v as f64)
                })
                .total();
            for c in 0..3 {
                assert!(g[c].is_finite(), "{model:?} {}: not finite", method.name());
                worst = worst.max((g[c] as f64 - cpu[c]).abs() / (1.0 + cpu[c].abs()));
            }
        }
        eprintln!("{model:?} {}: max |gpu - cpu| / (1 + cpu) = {worst:e}", method.name());
        // The CPU side here is the f64 BRDF around the f32 film method; the f32 BRDF itself
        // deviates from f64 by up to 2.1e-3 (`brdf stress`), so 5e-3 bounds the film twins.
        assert!(worst < 5e-3, "{model:?} {}: GPU and CPU differ by {worst}", method.name());
    }
}
