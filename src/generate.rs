//! One texture-set generation, planned before it runs: `Plan::new` loads and validates the
//! preset, builds the graph and estimates the peak memory from it (refusing a set that
//! cannot fit); `Plan::run` locks the output set, evaluates the requested maps, encodes them
//! and writes them with the manifest as one set (`export::SetLock`). Nothing touches the
//! output folder until every input has been validated.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use crate::export::{self, Quantized, SetLock, sha256_hex};
use crate::graph::{EvalStats, Graph, evaluate_into};
use crate::maps::{BuildOptions, build_graph};
use crate::material::MapKind;
use crate::memory::MemoryCheck;
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
    /// True when the output folder did not exist and was created.
    pub created_folder: bool,
}

/// The tallest map written (a body atlas is `body.length` widths tall): PNG readers and GPU
/// uploads commonly stop at 65535 rows, and the memory check refuses most sets before that.
pub const MAX_HEIGHT: usize = 65_535;

pub fn check_size(size: u64) -> Result<usize, Error> {
    if size < *SIZE_RANGE.start() as u64 || size > *SIZE_RANGE.end() as u64 {
        return Err(Error::Size { size });
    }
    Ok(size as usize)
}

/// A validated generation whose memory has been checked; nothing computed or written yet.
#[derive(Debug)]
pub struct Plan {
    request: GenerateRequest,
    size: usize,
    /// Image height: `size` for the tile, `size` × `body.length` for the body layout.
    height: usize,
    loaded: LoadedPreset,
    graph: Graph,
    memory: MemoryCheck,
    start: Instant,
}

impl Plan {
    /// The preset as loaded (overrides applied, colours clamped to what the stack shows).
    pub fn loaded(&self) -> &LoadedPreset {
        &self.loaded
    }

    /// Validates the request and estimates its peak memory; refuses a set whose estimate
    /// exceeds the memory available (`Error::Memory`, before any allocation).
    pub fn new(request: &GenerateRequest) -> Result<Plan, Error> {
        let start = Instant::now();
        let size = check_size(request.size)?;
        let loaded = preset::load(&request.preset, &request.overrides, request.seed)?;
        let height = request.options.layout.height(&loaded.preset, size);
        if height > MAX_HEIGHT {
            return Err(Error::Height { width: size, height, max: MAX_HEIGHT });
        }
        let graph = build_graph(&loaded.preset, request.options);
        let estimate = crate::memory::estimate_generate_bytes(&graph, &request.maps, size, height);
        let memory = MemoryCheck::against_available(estimate);
        let what = if height == size { format!("--size {size}") } else { format!("--size {size} ({size} x {height})") };
        memory.refuse_if_over(&what)?;
        Ok(Plan { request: request.clone(), size, height, loaded, graph, memory, start })
    }

    pub fn memory(&self) -> MemoryCheck {
        self.memory
    }

    /// Width and height of the maps.
    pub fn dimensions(&self) -> (usize, usize) {
        (self.size, self.height)
    }

    /// Runs the plan. `progress(done, total)` reports node evaluations.
    pub fn run(self, progress: &(dyn Fn(usize, usize) + Sync)) -> Result<GenerateReport, Error> {
        let Plan { request, size, height, loaded, graph, start, .. } = self;
        let lock = SetLock::acquire(&request.out_dir, &loaded.name)?;
        // Each map is quantised to its file format the moment it is finished, freeing its f32
        // buffer; PNG compression then runs for all maps in parallel.
        let mut quantized: Vec<Quantized> = Vec::new();
        let stats = evaluate_into(&graph, &request.maps, size, height, progress, &mut |map, image| {
            quantized.push(export::quantize(map, &image));
        });
        quantized.sort_by_key(|q| q.map);
        let kinds: Vec<MapKind> = quantized.iter().map(|q| q.map).collect();

        let encode_start = Instant::now();
        let files = export::encode_all(&loaded.name, &quantized)?;
        drop(quantized);
        let entries: Vec<(MapKind, String, String)> =
            kinds.iter().zip(&files).map(|(m, (name, bytes))| (*m, name.clone(), sha256_hex(bytes))).collect();
        let manifest = export::manifest(&loaded, (size, height), &entries, request.options);
        let json = serde_json::to_vec_pretty(&manifest).map_err(|e| Error::Internal(format!("manifest: {e}")))?;
        let manifest_name = export::manifest_file_name(&loaded.name);
        let encode_time = encode_start.elapsed();

        let written = lock.write(&files, (&manifest_name, &json))?;
        Ok(GenerateReport {
            files: written,
            stats,
            encode_time,
            total_time: start.elapsed(),
            created_folder: lock.created_folder,
        })
    }
}

/// Plans and runs a whole generation.
pub fn generate(request: &GenerateRequest, progress: &(dyn Fn(usize, usize) + Sync)) -> Result<GenerateReport, Error> {
    Plan::new(request)?.run(progress)
}
