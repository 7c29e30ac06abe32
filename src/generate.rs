//! One texture-set generation: load and validate, build the graph, evaluate the requested
//! maps, encode and write them with the manifest. Nothing touches the output folder until
//! every input has been validated and every map encoded.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use crate::export::Quantized;
use crate::export::{self, write_all_atomically};
use crate::graph::{EvalStats, evaluate_into};
use crate::maps::{BuildOptions, MapKind, build_graph};
use crate::preset::{self, LoadedPreset};
use crate::{Error, SIZE_RANGE};

#[derive(Debug, Clone)]
pub struct GenerateRequest {
    /// A `.toml` path or a built-in preset name.
    pub preset: String,
    /// `--set` overrides as (dotted key, TOML value).
    pub overrides: Vec<(String, String)>,
    pub seed: Option<u64>,
    pub size: u64,
    pub maps: Vec<MapKind>,
    pub out_dir: PathBuf,
    pub options: BuildOptions,
}

#[derive(Debug)]
pub struct GenerateReport {
    pub files: Vec<PathBuf>,
    pub stats: EvalStats,
    pub encode_time: Duration,
    pub total_time: Duration,
}

/// Loads and validates a preset with overrides and an optional seed.
pub fn load(spec: &str, overrides: &[(String, String)], seed: Option<u64>) -> Result<LoadedPreset, Error> {
    let source = preset::read_source(spec)?;
    let mut all = overrides.to_vec();
    if let Some(seed) = seed {
        all.push(("seed".into(), seed.to_string()));
    }
    Ok(preset::parse(&source, &all)?)
}

pub fn check_size(size: u64) -> Result<usize, Error> {
    if size < *SIZE_RANGE.start() as u64 || size > *SIZE_RANGE.end() as u64 {
        return Err(Error::Size { size });
    }
    Ok(size as usize)
}

/// Runs a whole generation. `progress(done, total)` reports node evaluations.
pub fn generate(request: &GenerateRequest, progress: &(dyn Fn(usize, usize) + Sync)) -> Result<GenerateReport, Error> {
    let start = Instant::now();
    let size = check_size(request.size)?;
    let loaded = load(&request.preset, &request.overrides, request.seed)?;
    let graph = build_graph(&loaded.preset, request.options);
    // Each map is quantised to its file format the moment it is finished, freeing its f32
    // buffer; PNG compression then runs for all maps in parallel.
    let mut quantized: Vec<Quantized> = Vec::new();
    let stats = evaluate_into(&graph, &request.maps, size, size, progress, &mut |map, image| {
        quantized.push(export::quantize(map, &image));
    });
    quantized.sort_by_key(|q| q.map);

    let encode_start = Instant::now();
    let mut files = export::encode_all(&loaded.name, &quantized)?;
    drop(quantized);
    let names: Vec<(MapKind, String)> =
        request.maps.iter().map(|m| (*m, export::map_file_name(&loaded.name, *m))).collect();
    let manifest = export::manifest(&loaded, size, &names, request.options.normal_convention);
    let json = serde_json::to_vec_pretty(&manifest).expect("manifest serialises");
    files.push((format!("{}.material.json", loaded.name), json));
    let encode_time = encode_start.elapsed();

    let written = write_all_atomically(&request.out_dir, &files)?;
    Ok(GenerateReport { files: written, stats, encode_time, total_time: start.elapsed() })
}
