//! One texture-set generation, planned before it runs: `Plan::new` loads and validates the
//! preset, builds the graph and estimates the peak memory from it (refusing a set that
//! cannot fit); `Plan::run` locks the output set, evaluates the requested maps, encodes them
//! and writes them with the manifest as one set (`export::SetLock`). Nothing touches the
//! output folder until every input has been validated.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use crate::export::pack::{Pack, TextureEncoder, TextureSpec, texture_file_name};
use crate::export::{self, MapEntry, Quantized, SetLock, sha256_hex};
use crate::graph::{EvalStats, Graph, evaluate_into, evaluate_rows};
use crate::maps::{BuildOptions, build_graph, has_film};
use crate::material::{FileFormat, MapKind};
use crate::memory::MemoryCheck;
use crate::ops::Frame;
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
    /// PNG (the default) or OpenEXR.
    pub format: FileFormat,
    /// Write an engine's packed textures (`export::pack`) instead of the maps; `maps` is
    /// then ignored (the pack says which maps it reads).
    pub pack: Option<Pack>,
    /// With a pack: fill its occlusion channel from the ambient occlusion map (otherwise 1).
    pub ao: bool,
    /// A batch job's key (`batch::Job::key`), recorded in the manifest so a resumed batch
    /// knows the set is this job's.
    pub job: Option<String>,
}

#[derive(Debug)]
pub struct GenerateReport {
    pub files: Vec<PathBuf>,
    pub stats: EvalStats,
    pub encode_time: Duration,
    pub total_time: Duration,
    /// True when the output folder did not exist and was created.
    pub created_folder: bool,
    /// A body atlas's strips: (strips, rows per strip, margin rows each side).
    pub strips: Option<(usize, usize, usize)>,
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
    /// The maps evaluated: the request's, or those its pack reads.
    maps: Vec<MapKind>,
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
        if request.pack.is_some() && request.format == FileFormat::Exr {
            return Err(Error::Unsupported(
                "--pack with --format exr: packed textures are 8- and 16-bit PNG, as the engines import them; leave \
                 out --format exr, or --pack for OpenEXR maps"
                    .into(),
            ));
        }
        if height > MAX_HEIGHT {
            return Err(Error::Height { width: size, height, max: MAX_HEIGHT });
        }
        let graph = build_graph(&loaded.preset, request.options);
        let maps = match request.pack {
            Some(pack) => pack.maps(has_film(&loaded.preset), request.ao),
            None => request.maps.clone(),
        };
        let strips = strips_of(&graph, &maps, size, height);
        // The finished maps kept as f32 until encoded or packed, and their files (each at
        // most their size).
        let floats: u64 = maps.iter().map(|m| 4 * m.exr_channels().0.len() as u64).sum();
        let held = 2 * floats * (size * height) as u64;
        let estimate = if request.format == FileFormat::Exr
            && let Some(strips) = strips
        {
            // OpenEXR of a body atlas: evaluated in strips, the rows gathered into whole maps.
            let rows = (strips.rows + 2 * strips.margin).min(height);
            crate::memory::estimate_strips_bytes(&graph, &maps, size, height, rows) + held
        } else if request.format == FileFormat::Exr || (request.pack.is_some() && strips.is_none()) {
            crate::memory::estimate_generate_bytes(&graph, &maps, size, height) + held
        } else if let Some(strips) = strips {
            let rows = (strips.rows + 2 * strips.margin).min(height);
            crate::memory::estimate_strips_bytes(&graph, &maps, size, height, rows)
        } else {
            crate::memory::estimate_generate_bytes(&graph, &maps, size, height)
        };
        let memory = MemoryCheck::against_available(estimate);
        let what = if height == size { format!("--size {size}") } else { format!("--size {size} ({size} x {height})") };
        memory.refuse_if_over(&what)?;
        Ok(Plan { request: request.clone(), size, height, loaded, graph, maps, memory, start })
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
        if let Some(pack) = self.request.pack {
            return self.run_pack(pack, progress);
        }
        let Plan { request, size, height, loaded, graph, start, .. } = self;
        let lock = SetLock::acquire(&request.out_dir, &loaded.name)?;
        let strip_layout = strips_of(&graph, &request.maps, size, height);
        let (kinds, files, stats, encode_time) = if request.format == FileFormat::Exr {
            // The maps as f32, whole: a square evaluated at once, a body atlas strip by strip
            // with each strip's rows copied into place (the OpenEXR writer takes whole
            // images; the graph's buffers stay a strip's).
            let mut finished: Vec<(MapKind, crate::ops::Image)> = Vec::new();
            let stats =
                for_each_band(&graph, &request.maps, size, height, strip_layout, progress, &mut |band, rows| {
                    for (map, image) in band {
                        let stride = image.width * image.channels;
                        let band_rows = &image.data[rows.start * stride..rows.end * stride];
                        match finished.iter_mut().find(|(m, _)| m == map) {
                            Some((_, whole)) => whole.data.extend_from_slice(band_rows),
                            None => {
                                let mut whole = crate::ops::Image::new(size, 0, image.channels);
                                whole.data.reserve_exact(stride * height);
                                whole.data.extend_from_slice(band_rows);
                                finished.push((*map, whole));
                            }
                        }
                    }
                    Ok(())
                })?;
            for (_, image) in &mut finished {
                image.height = height;
            }
            finished.sort_by_key(|(m, _)| *m);
            let encode_start = Instant::now();
            let range = crate::maps::thickness_range_nm(&loaded.preset);
            use rayon::prelude::*;
            let files = finished
                .par_iter()
                .map(|(map, image)| {
                    Ok((
                        export::map_file_name_in(&loaded.name, *map, FileFormat::Exr),
                        export::encode_exr(*map, image, range)?,
                    ))
                })
                .collect::<Result<Vec<_>, export::ExportError>>()?;
            (finished.iter().map(|(m, _)| *m).collect(), files, stats, encode_start.elapsed())
        } else if let Some(layout) = strip_layout {
            // A body atlas: strip by strip, each encoded as it is done (memory bounded by a
            // strip, not the body's length).
            strips(&graph, &request.maps, &loaded.name, size, height, layout, progress)?
        } else {
            // Each map is quantised to its file format the moment it is finished, freeing its
            // f32 buffer; PNG compression then runs for all maps in parallel.
            let mut quantized: Vec<Quantized> = Vec::new();
            let stats = evaluate_into(&graph, &request.maps, size, height, progress, &mut |map, image| {
                quantized.push(export::quantize(map, &image));
            });
            quantized.sort_by_key(|q| q.map);
            let kinds: Vec<MapKind> = quantized.iter().map(|q| q.map).collect();
            let encode_start = Instant::now();
            let files = export::encode_all(&loaded.name, &quantized)?;
            (kinds, files, stats, encode_start.elapsed())
        };
        let encode_start = Instant::now();
        let convention = request.options.normal_convention;
        let entries: Vec<MapEntry> = kinds
            .iter()
            .zip(&files)
            .map(|(m, (name, bytes))| MapEntry::for_map(*m, name, sha256_hex(bytes), request.format, convention))
            .collect();
        let mut manifest =
            export::manifest(&loaded, (size, height), entries, request.options, request.format.name(), None);
        manifest.job = request.job.clone();
        let json = serde_json::to_vec_pretty(&manifest).map_err(|e| Error::Internal(format!("manifest: {e}")))?;
        let manifest_name = export::manifest_file_name(&loaded.name);
        let encode_time = encode_time + encode_start.elapsed();

        let written = lock.write(&files, (&manifest_name, &json))?;
        Ok(GenerateReport {
            files: written,
            stats,
            encode_time,
            total_time: start.elapsed(),
            created_folder: lock.created_folder,
            strips: strip_layout.map(|s| (s.count, s.rows, s.margin)),
        })
    }
}

impl Plan {
    /// Evaluates the maps the plan's pack reads and packs them (`export::pack`), a band of
    /// rows at a time (a strip of a body atlas, or the whole tile): (each texture with its
    /// PNG bytes, merged stats, encode time). Nothing is written.
    #[allow(clippy::type_complexity)]
    pub fn pack_textures(
        &self,
        pack: Pack,
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> Result<(Vec<(TextureSpec, Vec<u8>)>, EvalStats, Duration), Error> {
        use rayon::prelude::*;
        let (width, height) = (self.size, self.height);
        let specs = pack.textures(has_film(&self.loaded.preset), self.request.ao);
        let mut encoders =
            specs.into_iter().map(|s| TextureEncoder::new(s, width, height)).collect::<Result<Vec<_>, _>>()?;
        let mut encode_time = Duration::ZERO;
        let strips = strips_of(&self.graph, &self.maps, width, height);
        let stats = for_each_band(&self.graph, &self.maps, width, height, strips, progress, &mut |band, rows| {
            let t = Instant::now();
            encoders.par_iter_mut().try_for_each(|e| e.write_rows(band, rows.clone()))?;
            encode_time += t.elapsed();
            Ok(())
        })?;
        let t = Instant::now();
        let textures = encoders
            .into_par_iter()
            .map(|e| {
                let spec = e.spec.clone();
                Ok((spec, e.finish()?))
            })
            .collect::<Result<Vec<_>, export::ExportError>>()?;
        Ok((textures, stats, encode_time + t.elapsed()))
    }

    /// `run` for a pack: the packed textures and a manifest naming them.
    fn run_pack(self, pack: Pack, progress: &(dyn Fn(usize, usize) + Sync)) -> Result<GenerateReport, Error> {
        let lock = SetLock::acquire(&self.request.out_dir, &self.loaded.name)?;
        let (textures, stats, encode_time) = self.pack_textures(pack, progress)?;
        let name = &self.loaded.name;
        let files: Vec<(String, Vec<u8>)> =
            textures.iter().map(|(spec, bytes)| (texture_file_name(name, spec), bytes.clone())).collect();
        let entries: Vec<MapEntry> = textures
            .iter()
            .zip(&files)
            .map(|((spec, _), (file, bytes))| MapEntry::for_texture(spec, file, sha256_hex(bytes)))
            .collect();
        let options = self.request.options;
        let mut manifest =
            export::manifest(&self.loaded, (self.size, self.height), entries, options, "png", Some(pack.name()));
        manifest.job = self.request.job.clone();
        let json = serde_json::to_vec_pretty(&manifest).map_err(|e| Error::Internal(format!("manifest: {e}")))?;
        let written = lock.write(&files, (&export::manifest_file_name(name), &json))?;
        let strips = strips_of(&self.graph, &self.maps, self.size, self.height);
        Ok(GenerateReport {
            files: written,
            stats,
            encode_time,
            total_time: self.start.elapsed(),
            created_folder: lock.created_folder,
            strips: strips.map(|s| (s.count, s.rows, s.margin)),
        })
    }
}

/// Takes a band of evaluated maps and the rows of it that belong to the texture.
type BandSink<'a> = dyn FnMut(&[(MapKind, crate::ops::Image)], std::ops::Range<usize>) -> Result<(), Error> + 'a;

/// Evaluates `maps` a band of rows at a time and hands each band to `sink` with the rows of
/// it that belong to the texture (the rest is margin): the whole texture at once when it is
/// square (`strips` None), else strip by strip, each over its rows plus `Graph::row_reach`
/// rows each side, so its kept rows are exactly the whole texture's.
fn for_each_band(
    graph: &Graph,
    maps: &[MapKind],
    width: usize,
    height: usize,
    strips: Option<Strips>,
    progress: &(dyn Fn(usize, usize) + Sync),
    sink: &mut BandSink,
) -> Result<EvalStats, Error> {
    let Strips { count, rows: step, margin } = strips.unwrap_or(Strips { count: 1, rows: height, margin: 0 });
    let mut stats = EvalStats::default();
    for k in 0..count {
        let (start, end) = (k * step, ((k + 1) * step).min(height));
        let row0 = start.saturating_sub(margin);
        let frame = Frame {
            width,
            height: (end + margin).min(height) - row0,
            full_height: height,
            row0,
            wraps_v: strips.is_none(),
        };
        let nodes = &|done: usize, total: usize| progress(k * total + done, count * total);
        let mut band: Vec<(MapKind, crate::ops::Image)> = Vec::new();
        let strip_stats = evaluate_rows(graph, maps, frame, nodes, &mut |map, image| band.push((map, image)));
        stats.merge(strip_stats);
        band.sort_by_key(|(m, _)| *m);
        sink(&band, start - row0..end - row0)?;
    }
    Ok(stats)
}

/// Rows of texture per strip of a long texture, as a multiple of its width: two widths hold
/// about what a square tile of 1.4× the width would, and the margins (`Graph::row_reach`,
/// typically a tenth of a width each side for patterned species) then cost about a tenth.
pub const STRIP_WIDTHS: usize = 2;

/// How a texture taller than wide is cut: `count` strips of `rows` rows, each evaluated
/// with `margin` more rows each side (`Graph::row_reach`).
#[derive(Debug, Clone, Copy)]
struct Strips {
    count: usize,
    rows: usize,
    margin: usize,
}

/// The strips of a `width` × `height` texture, or None for a square (evaluated whole).
fn strips_of(graph: &Graph, maps: &[MapKind], width: usize, height: usize) -> Option<Strips> {
    let rows = STRIP_WIDTHS * width;
    (height > width).then(|| Strips { count: height.div_ceil(rows), rows, margin: graph.row_reach(maps, width) })
}

/// (maps, their files' names and bytes, merged stats, encode time) of a long texture
/// evaluated in strips: each strip over its rows plus `Graph::row_reach` rows each side
/// (so its kept rows are exactly the whole texture's), its margins cropped, its rows
/// appended to each map's PNG stream.
#[allow(clippy::type_complexity)]
fn strips(
    graph: &Graph,
    maps: &[MapKind],
    name: &str,
    width: usize,
    height: usize,
    layout: Strips,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<(Vec<MapKind>, Vec<(String, Vec<u8>)>, EvalStats, Duration), Error> {
    use rayon::prelude::*;
    let mut kinds: Vec<MapKind> = maps.iter().copied().filter(|m| graph.output(*m).is_some()).collect();
    kinds.sort();
    kinds.dedup();
    let mut encoders =
        kinds.iter().map(|m| export::RowEncoder::new(*m, width, height)).collect::<Result<Vec<_>, _>>()?;
    let mut encode_time = Duration::ZERO;
    let stats = for_each_band(graph, maps, width, height, Some(layout), progress, &mut |band, rows| {
        let t = Instant::now();
        encoders
            .par_iter_mut()
            .zip(band)
            .try_for_each(|(encoder, (_, image))| encoder.write_rows(image, rows.clone()))?;
        encode_time += t.elapsed();
        Ok(())
    })?;
    let t = Instant::now();
    let files = encoders
        .into_par_iter()
        .map(|e| Ok((export::map_file_name(name, e.map), e.finish()?)))
        .collect::<Result<Vec<_>, export::ExportError>>()?;
    Ok((kinds, files, stats, encode_time + t.elapsed()))
}

/// Plans and runs a whole generation.
pub fn generate(request: &GenerateRequest, progress: &(dyn Fn(usize, usize) + Sync)) -> Result<GenerateReport, Error> {
    Plan::new(request)?.run(progress)
}
