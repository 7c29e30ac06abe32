//! Criterion benchmarks of the film colour methods (one f32 evaluation each) and the BRDF.
//! Run: `cargo bench --bench optics`. `snakeskin bench irid` measures the same costs next to
//! each method's error.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use snakeskin::optics::brdf::{Layers, Model};
use snakeskin::optics::film::Stack;
use snakeskin::optics::lut::Lut;
use snakeskin::optics::methods::{gaussian_fit_f32, rgb3_f32, spectral_n_f32};

fn methods(c: &mut Criterion) {
    let lut = Lut::bake_default(Stack::THESIS);
    let mut group = c.benchmark_group("film_colour_f32");
    let (n0, n1, n2, d, cos0) = (1.0f32, 1.55f32, 2.0f32, 437.0f32, 0.81f32);
    group.bench_function("rgb3", |b| b.iter(|| rgb3_f32(black_box(n0), n1, n2, black_box(d), black_box(cos0))));
    for n in [4usize, 8, 16, 32] {
        group.bench_function(format!("spectral-{n}"), |b| {
            b.iter(|| spectral_n_f32(black_box(n0), n1, n2, black_box(d), black_box(cos0), n))
        });
    }
    group.bench_function("gaussian-fit", |b| {
        b.iter(|| gaussian_fit_f32(black_box(n0), n1, n2, black_box(d), black_box(cos0)))
    });
    group.bench_function("lut", |b| b.iter(|| lut.lookup_f32(black_box(d), black_box(cos0))));
    group.finish();

    let layers = Layers::of_stack(Stack::THESIS, 400.0, 0.35, [0.6; 3], [0.4, 0.3, 0.2]).to_f32(400.0);
    for model in Model::ALL {
        c.bench_function(&format!("brdf_f32_lut_{}", model.name()), |b| {
            b.iter(|| {
                let (n, wi, wo) = (black_box([0.1, 0.0, 1.0]), black_box([0.3, 0.1, 0.9]), black_box([-0.2, 0.0, 1.0]));
                model.eval_f32(&layers, n, wi, wo, &lut)
            })
        });
    }
    c.bench_function("lut_bake_default", |b| b.iter(|| Lut::bake_default(black_box(Stack::THESIS))));
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = methods
}
criterion_main!(benches);
