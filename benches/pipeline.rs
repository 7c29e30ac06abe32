//! Criterion benchmarks of the texture pipeline: whole sets (generation + PNG encoding, no
//! disk), a single map (to show demand-driven evaluation pays), and the heavy operations.
//!
//! Run: `cargo bench --bench pipeline` (add `-- full_set` etc. to pick groups).

use criterion::{Criterion, criterion_group, criterion_main};
use snakeskin::export::{encode_all, quantize};
use snakeskin::graph::{Op, evaluate_into};
use snakeskin::maps::{BuildOptions, MapKind, build_graph, scale_field};
use snakeskin::ops::filters;
use snakeskin::ops::noise::{FractalNoise, NoiseKind};
use snakeskin::preset::{LoadedPreset, parse, read_source};

const PATTERNED: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/patterned.toml");

fn load() -> LoadedPreset {
    parse(&read_source(PATTERNED).unwrap(), &[]).unwrap()
}

/// Evaluation, quantisation and PNG encoding, as `generate` does them (no disk).
fn set(loaded: &LoadedPreset, maps: &[MapKind], size: usize) -> usize {
    let graph = build_graph(&loaded.preset, BuildOptions::default());
    let mut quantized = Vec::new();
    evaluate_into(&graph, maps, size, size, &|_, _| {}, &mut |map, image| quantized.push(quantize(map, &image)));
    encode_all(&loaded.name, &quantized).unwrap().iter().map(|(_, b)| b.len()).sum()
}

fn sets(c: &mut Criterion) {
    let loaded = load();
    let mut group = c.benchmark_group("set_1024");
    group.sample_size(10);
    group.bench_function("all_maps", |b| b.iter(|| set(&loaded, &MapKind::ALL, 1024)));
    group.bench_function("roughness_only", |b| b.iter(|| set(&loaded, &[MapKind::Roughness], 1024)));
    group.finish();
}

fn operations(c: &mut Criterion) {
    let loaded = load();
    let size = 1024;
    let mut group = c.benchmark_group("ops_1024");
    group.sample_size(10);
    let field = scale_field(&loaded.preset, snakeskin::maps::Layout::Tile);
    // The graph's node (planar); `render` adds a copy to interleaved pixels.
    group.bench_function("scales", |b| b.iter(|| field.render_planar(snakeskin::ops::Frame::whole(size, size))));
    // Coarse noises (sampled on a grid and upsampled), and a grain noise fine enough to be
    // sampled at every pixel: `crotalus-atrox`'s at 2048² (105 × 81 cells, three octaves),
    // as dense in pixels per cell at this size.
    let noises = [
        ("perlin_4oct", NoiseKind::Perlin, (8, 8), 4),
        ("cellular_4oct", NoiseKind::Cellular, (8, 8), 4),
        ("perlin_grain", NoiseKind::Perlin, (52, 40), 3),
    ];
    for (name, kind, (cells_u, cells_v), octaves) in noises {
        let op = Op::Noise(FractalNoise { kind, cells_u, cells_v, octaves, gain: 0.5, seed: 1 });
        group.bench_function(name, |b| b.iter(|| op.eval(None, &[], snakeskin::ops::Frame::whole(size, size))));
    }
    let noise =
        Op::Noise(FractalNoise { kind: NoiseKind::Perlin, cells_u: 8, cells_v: 8, octaves: 1, gain: 0.5, seed: 1 })
            .eval(None, &[], snakeskin::ops::Frame::whole(size, size));
    group.bench_function("blur_sigma_0.005", |b| {
        b.iter(|| filters::blur(std::borrow::Cow::Borrowed(&noise), 0.005, true))
    });
    group.bench_function("height_to_normal", |b| {
        let spec = filters::NormalSpec {
            slope_per_unit_height: 0.05,
            convention: filters::NormalConvention::OpenGl,
            v_extent: 1.0,
            full_height: noise.height,
            wraps_v: true,
        };
        b.iter(|| filters::height_to_normal(&noise, spec))
    });
    group.finish();
}

criterion_group!(benches, sets, operations);
criterion_main!(benches);
