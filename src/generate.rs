//! One texture-set generation, planned before it runs: `Plan::new` loads and validates the
//! preset, builds the graph and estimates the peak memory from it (refusing a set that
//! cannot fit); `Plan::run` locks the output set, evaluates the requested maps, encodes them
//! and writes them with the manifest as one set (`export::SetLock`). Nothing touches the
//! output folder until every input has been validated.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use crate::export::pack::{Pack, TextureEncoder, TextureSpec, texture_file_name};
use crate::export::{self, MapEntry, SetLock, sha256_hex};
use crate::graph::{EvalStats, Graph, evaluate_into, evaluate_rows};
use crate::maps::{BuildOptions, Layout, build_graph, has_film};
use crate::material::{FileFormat, MapKind};
use crate::memory::MemoryCheck;
use crate::ops::Frame;
use crate::ops::filters::NormalSpec;
use crate::preset::{self, LoadedPreset, Preset};
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
    /// The strips of a body atlas or of a tile too large to evaluate whole: (strips, rows
    /// per strip, margin rows each side).
    pub strips: Option<(usize, usize, usize)>,
    /// Maps quantised from their constant value, their node's image not read (a species
    /// without a film: its thickness map), with the value.
    pub constant_maps: Vec<(MapKind, f32)>,
    /// The earlier set's files that went with it because this set does not write them.
    pub removed: Vec<PathBuf>,
    /// The files of the set's names that this set does not write and that stayed (changed
    /// since, would not move, or recorded by no manifest that could be read), with why: to
    /// warn of.
    pub kept: Vec<crate::export::KeptFile>,
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

/// How messages name a request's size: `generate`'s and `export`'s option, or a batch job's
/// size (a jobs file's `sizes`).
fn size_option(request: &GenerateRequest) -> &'static str {
    if request.job.is_some() { "size" } else { "--size" }
}

/// The names of the files a request's set writes for its loaded preset: its maps (or its
/// pack's textures), then its manifest.
pub fn set_file_names(loaded: &LoadedPreset, request: &GenerateRequest) -> Vec<String> {
    let name = &loaded.name;
    let mut files: Vec<String> = match request.pack {
        Some(pack) => pack
            .textures(has_film(&loaded.preset), request.ao)
            .iter()
            .map(|spec| texture_file_name(name, spec))
            .collect(),
        None => request.maps.iter().map(|map| export::map_file_name_in(name, *map, request.format)).collect(),
    };
    files.push(export::manifest_file_name(name));
    files
}

/// A set's folder and its files (`set_file_names`) checked before the work
/// (`Plan::check_outputs`), none of them one of `inputs`, the command's inputs besides the
/// set's own preset (a batch's jobs file and its other jobs' preset files: kept among a
/// set's files, the jobs file was replaced by the set's manifest, and the batch could not be
/// run again). None of the files can be the set's own preset file: the set's names are its
/// file stem with a suffix, `NAME_color.png`, `NAME.material.json`; but the set's lock
/// (`.NAME.lock`, `name` the set's), which the run removes as it ends, can be, so it is
/// checked against `inputs` too: `generate ./.preset.lock` removed its own (empty) preset;
/// and for what is there (`check_lock_place`).
pub fn check_set_outputs(
    out_dir: &Path,
    name: &str,
    files: &[String],
    inputs: &export::Inputs,
) -> Result<(), export::ExportError> {
    export::check_folder(out_dir)?;
    for file in files {
        let target = out_dir.join(file);
        export::check_target(&target)?;
        inputs.check(&target)?;
    }
    let lock = out_dir.join(export::lock_file_name(name));
    export::check_lock_not_an_input(&lock, inputs)?;
    export::check_lock_place(&lock)
}

/// What is lost where `ambient_ior` is not air's and the file goes to `reader` (glTF, an
/// engine's pack): none of them has an ambient index, so a viewer or engine lights the
/// material as in air (README, "What glTF cannot carry"). Said before the work, so that a
/// snake under water is not taken for one (an onboarding review: `export` was silent; a
/// later review: packs too). None in air.
pub fn ambient_warning(ambient_ior: f64, reader: &str) -> Option<String> {
    (ambient_ior != 1.0).then(|| {
        format!(
            "optics.ambient_ior is {ambient_ior}, but {reader} has no ambient index: it lights this material as \
             in air (the colour map is still the visible colour under {ambient_ior}; the film's and the base's \
             reflections are not)"
        )
    })
}

/// `Pack::size_problem` for a set `size` wide in `layout`, with the largest size whose
/// textures the engine loads (a body atlas's height is rounded, so it is searched for):
/// "give {give} N or less". None when the textures fit, or without a pack.
pub fn pack_size_warning(pack: Pack, layout: Layout, preset: &Preset, size: usize, give: &str) -> Option<String> {
    let height = layout.height(preset, size);
    let problem = pack.size_problem((size, height))?;
    let (limit, _) = pack.longest_side_loaded();
    // At most the width in proportion, from which the rounding moves it by a texel or so.
    let start = (limit * size / height).saturating_add(1).min(size).min(limit);
    let fitting = (1..=start).rev().find(|&width| width.max(layout.height(preset, width)) <= limit).unwrap_or(1);
    let body = if height == size { "" } else { " (a body atlas is body.length widths tall)" };
    Some(format!("{problem}: give {give} {fitting} or less{body}"))
}

impl Plan {
    /// The preset as loaded (overrides applied, colours clamped to what the stack shows).
    pub fn loaded(&self) -> &LoadedPreset {
        &self.loaded
    }

    /// The names of the files the set writes: its maps (or its pack's textures), then its
    /// manifest (`run` checks them before the work; tests/hostile.rs checks that they are
    /// the files written).
    pub fn file_names(&self) -> Vec<String> {
        set_file_names(&self.loaded, &self.request)
    }

    /// Validates the request and estimates its peak memory; refuses a set whose estimate
    /// exceeds the memory available (`Error::Memory`, before any allocation).
    pub fn new(request: &GenerateRequest) -> Result<Plan, Error> {
        let plan = Plan::within_checked_budget(request)?;
        plan.memory.refuse_if_over(&plan.size_words())?;
        Ok(plan)
    }

    /// The request's size as a memory refusal names it: `--size 1024`, or `--size 1024
    /// (1024 x 12288)` for a body atlas.
    pub fn size_words(&self) -> String {
        let size_option = size_option(&self.request);
        if self.height == self.size {
            format!("{size_option} {}", self.size)
        } else {
            format!("{size_option} {} ({} x {})", self.size, self.size, self.height)
        }
    }

    /// The pack's encoded textures, at most (`pack_textures`' result; 0 without a pack): their
    /// samples, PNG's filter byte a row, 1/256 for the stream writer's chunks (12 bytes in each
    /// 4 KiB IDAT) and 4 KiB. A bound for maps as these are, as the set's estimate assumes
    /// (`memory::estimate_generate_bytes`): the fast compressor takes them to a third or less
    /// (python-regius's body atlas at 1024: 47 MB for 126 MB of samples); its fixed codes could
    /// make incompressible noise up to 1.5× its samples, which neither counts.
    pub fn texture_bytes_bound(&self) -> u64 {
        let Some(pack) = self.request.pack else { return 0 };
        let (width, height) = (self.size as u64, self.height as u64);
        pack.textures(has_film(&self.loaded.preset), self.request.ao)
            .iter()
            .map(|spec| {
                let samples = width * height * spec.channels.len() as u64 * u64::from(spec.bit_depth / 8);
                samples + height + samples / 256 + 4096
            })
            .sum()
    }

    /// `new` without refusing a set whose estimate exceeds the memory available now: for a
    /// batch, which checked its jobs against the available memory before any ran, and whose
    /// other running jobs hold part of it when a later one starts.
    pub fn within_checked_budget(request: &GenerateRequest) -> Result<Plan, Error> {
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
            // The widest that fits, named (a body atlas's height is rounded, so it is searched
            // for down from the width in proportion).
            let layout = request.options.layout;
            let start = (MAX_HEIGHT * size / height).saturating_add(1).min(size);
            let fits = (1..=start).rev().find(|&w| layout.height(&loaded.preset, w) <= MAX_HEIGHT).unwrap_or(1);
            let size_option = size_option(request);
            return Err(Error::Height { width: size, height, max: MAX_HEIGHT, size_option, fits });
        }
        let maps = match request.pack {
            Some(pack) => pack.maps(has_film(&loaded.preset), request.ao),
            None => request.maps.clone(),
        };
        let graph = build_graph(&loaded.preset, request.options).for_maps(&maps).fused(&maps, size, height);
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
        Ok(Plan { request: request.clone(), size, height, loaded, graph, maps, memory, start })
    }

    pub fn memory(&self) -> MemoryCheck {
        self.memory
    }

    /// The pack's warning when its textures are longer than the engine loads
    /// (`pack_size_warning`), "warning: " first; None when they fit, or without a pack.
    pub fn size_warning(&self) -> Option<String> {
        let (layout, preset) = (self.request.options.layout, &self.loaded.preset);
        let give = size_option(&self.request);
        pack_size_warning(self.request.pack?, layout, preset, self.size, give).map(|w| format!("warning: {w}"))
    }

    /// `ambient_warning` for a pack, "warning: " first; None in air, or without a pack.
    pub fn ambient_warning(&self) -> Option<String> {
        let reader = self.request.pack?.material_reader();
        ambient_warning(self.loaded.preset.optics.ambient_ior, reader).map(|w| format!("warning: {w}"))
    }

    /// The layout the maps are drawn in.
    pub fn layout(&self) -> Layout {
        self.request.options.layout
    }

    /// Width and height of the maps.
    pub fn dimensions(&self) -> (usize, usize) {
        (self.size, self.height)
    }

    /// The set's folder and every file of it, checked before the work, not only when the
    /// set is committed: a folder or a link where the last map goes failed after the whole
    /// set had been evaluated and encoded (the commit checks again: the folder may change).
    /// `run` calls it, and a batch for every job before the first runs.
    pub fn check_outputs(&self) -> Result<(), export::ExportError> {
        let preset = crate::preset::input_file(&self.request.preset);
        check_set_outputs(&self.request.out_dir, &self.loaded.name, &self.file_names(), &export::Inputs::new(preset))
    }

    /// Runs the plan: `lock_set`, then `run_locked`. `progress(done, total)` reports node
    /// evaluations.
    pub fn run(self, progress: &(dyn Fn(usize, usize) + Sync)) -> Result<GenerateReport, Error> {
        let lock = self.lock_set()?;
        self.run_locked(lock, progress)
    }

    /// The set's folder and files checked (`check_outputs`), then its lock taken
    /// (`SetLock::acquire`: a set another run is writing is `ExportError::Busy`).
    pub fn lock_set(&self) -> Result<SetLock, Error> {
        self.check_outputs()?;
        Ok(SetLock::acquire(&self.request.out_dir, &self.loaded.name)?)
    }

    /// `lock_set`, waiting for a set another run is writing (`SetLock::acquire_waiting`):
    /// a batch's job, which then looks under the lock whether that run made the set.
    pub fn lock_set_waiting(&self, waiting: &mut dyn FnMut(), give_up: &dyn Fn() -> bool) -> Result<SetLock, Error> {
        self.check_outputs()?;
        Ok(SetLock::acquire_waiting(&self.request.out_dir, &self.loaded.name, waiting, give_up)?)
    }

    /// Runs the plan under `lock`, the set's (`lock_set`, `lock_set_waiting`): evaluates,
    /// encodes and commits the set. Panics if `lock` is another set's.
    pub fn run_locked(self, lock: SetLock, progress: &(dyn Fn(usize, usize) + Sync)) -> Result<GenerateReport, Error> {
        assert!(lock.is_for(&self.request.out_dir, &self.loaded.name), "run_locked under another set's lock");
        if let Some(pack) = self.request.pack {
            return self.run_pack(pack, lock, progress);
        }
        let Plan { request, size, height, loaded, graph, start, .. } = self;
        let strip_layout = strips_of(&graph, &request.maps, size, height);
        let mut constant_maps = Vec::new();
        let (kinds, files, stats, encode_time) = if request.format == FileFormat::Exr {
            // The maps as f32, whole: a square evaluated at once, a body atlas strip by strip
            // with each strip's rows copied into place (the OpenEXR writer takes whole
            // images; the graph's buffers stay a strip's).
            let mut finished: Vec<(MapKind, crate::ops::Image)> = Vec::new();
            let stats =
                for_each_band(&graph, &request.maps, size, height, strip_layout, progress, &mut |band, rows| {
                    for (map, image) in band {
                        let stride = image.width * image.channels;
                        let band_rows = image.rows(rows.clone());
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
            let range = crate::maps::map_thickness_range_nm(&loaded.preset);
            use rayon::prelude::*;
            let files = finished
                .par_iter()
                .map(|(map, image)| {
                    Ok((
                        export::map_file_name_in(&loaded.name, *map, FileFormat::Exr),
                        export::encode_exr(*map, image, range, graph.wraps_v())?,
                    ))
                })
                .collect::<Result<Vec<_>, export::ExportError>>()?;
            (finished.iter().map(|(m, _)| *m).collect(), Files::Bytes(files), stats, encode_start.elapsed())
        } else if let Some(layout) = strip_layout.filter(|_| graph.wraps_v()) {
            // A tile too large to evaluate whole: strip by strip, each map's rows quantised
            // into the whole map's samples as they come, each map compressed as it completes
            // (the same PNG bytes as a tile evaluated whole).
            let (kinds, files, stats, time) = tile_strips(&graph, &request.maps, &loaded.name, size, layout, progress)?;
            (kinds, Files::Bytes(files), stats, time)
        } else if let Some(layout) = strip_layout {
            // A body atlas: strip by strip, each encoded as it is done (memory bounded by a
            // strip, not the body's length).
            let (kinds, files, stats, time) =
                strips(&graph, &request.maps, &loaded.name, size, height, layout, progress)?;
            (kinds, Files::Bytes(files), stats, time)
        } else {
            // Each map is quantised to its file format the moment it is finished, freeing its
            // f32 buffer, and compressed on a thread of its own while the graph goes on: the
            // quantised samples are freed as soon as their PNG is done (at 4096² they were
            // 200 MB held to the end), and compression fills the moments the graph leaves a
            // core idle. Each PNG goes to its temporary file as soon as it is compressed
            // (`SetLock::stage`), so the compressed maps are not held to the end either:
            // `liasis-mackloti` at 4096² peaked at 1035 MiB with its 86 MB of PNGs held, 951
            // without.
            let name = loaded.name.as_str();
            let lock = &lock;
            // A constant map (a species without a film: its thickness map) is quantised from
            // its value, not read back from its image (`export::quantize_constant`): the
            // constant node's zeros are never touched. Its node still runs, in its place in
            // the schedule: evaluating the graph without it let the next chains start sooner
            // and raised `crotalus-atrox`'s buffers at 4096² from 768 to 832 MiB (1.0–1.06 GB
            // resident against 0.92–0.95).
            // The normal map is quantised from the height map where it can be
            // (`whole_tile_maps`).
            let (evaluated, normal_direct) = whole_tile_maps(&graph, &request.maps, size, height);
            let mut normal_time = None;
            let (mut stats, mut encoded) = std::thread::scope(|scope| {
                let mut encoders = Vec::new();
                let mut encode = |map: MapKind, quantized: export::Quantized| {
                    encoders.push(scope.spawn(move || {
                        let t = Instant::now();
                        let staged = export::encode_quantized(&quantized)
                            .map_err(Error::from)
                            .and_then(|bytes| Ok(lock.stage(&export::map_file_name(name, map), &bytes)?));
                        (map, staged, t.elapsed())
                    }));
                };
                let stats = evaluate_into(&graph, &evaluated, size, height, progress, &mut |map, image| {
                    if let (MapKind::Height, Some(spec)) = (map, normal_direct) {
                        let t = Instant::now();
                        let rows = crate::ops::filters::height_to_normal_rows(&image, spec);
                        let normal = export::quantize_rows(MapKind::Normal, image.width, image.height, rows);
                        normal_time = Some((t.elapsed(), normal.samples.len()));
                        encode(MapKind::Normal, normal);
                    }
                    let constant = graph
                        .constant_output(map)
                        .and_then(|v| Some((v, export::quantize_constant(map, image.width, image.height, v)?)));
                    let quantized = match constant {
                        Some((value, quantized)) => {
                            constant_maps.push((map, value));
                            quantized
                        }
                        None => export::quantize(map, &image),
                    };
                    drop(image);
                    encode(map, quantized);
                });
                let encoded: Vec<_> =
                    encoders.into_iter().map(|h| h.join().expect("a PNG encoder thread panicked")).collect();
                (stats, encoded)
            });
            if let (Some((time, bytes)), Some(node), Some(height_node)) =
                (normal_time, graph.output(MapKind::Normal), graph.output(MapKind::Height))
            {
                // `--stats` lists the normal map's step as the node it stands for, after the
                // height map's (the nodes are in topological order), with its time
                // (quantising included) and its output: the file's samples.
                let node = graph.node(node);
                let after = stats.nodes.iter().position(|n| n.name == graph.node(height_node).name);
                let entry = crate::graph::NodeStats {
                    name: node.name.clone(),
                    label: format!("{} {NORMAL_FROM_HEIGHT}", node.op.label()),
                    evaluations: 1,
                    time,
                    bytes,
                };
                stats.nodes.insert(after.map_or(stats.nodes.len(), |i| i + 1), entry);
            }
            encoded.sort_by_key(|(map, _, _)| *map);
            let encode_time = encoded.iter().map(|(_, _, t)| *t).sum();
            let kinds: Vec<MapKind> = encoded.iter().map(|(map, _, _)| *map).collect();
            let staged = encoded.into_iter().map(|(_, file, _)| file).collect::<Result<Vec<_>, _>>()?;
            (kinds, Files::Staged(staged), stats, encode_time)
        };
        let encode_start = Instant::now();
        let staged = match files {
            Files::Bytes(files) => {
                files.iter().map(|(name, bytes)| lock.stage(name, bytes)).collect::<Result<Vec<_>, _>>()?
            }
            Files::Staged(staged) => staged,
        };
        let convention = request.options.normal_convention;
        let entries: Vec<MapEntry> = kinds
            .iter()
            .zip(&staged)
            .map(|(m, file)| MapEntry::for_map(*m, &file.name, file.sha256.clone(), request.format, convention))
            .collect();
        let mut manifest =
            export::manifest(&loaded, (size, height), entries, request.options, request.format.name(), None);
        manifest.job = request.job.clone();
        let json = export::manifest_json(&manifest)?;
        let manifest_name = export::manifest_file_name(&loaded.name);
        let encode_time = encode_time + encode_start.elapsed();

        let written = lock.commit(staged, (&manifest_name, &json))?;
        Ok(GenerateReport {
            files: written,
            stats,
            encode_time,
            total_time: start.elapsed(),
            created_folder: lock.created_folder,
            strips: strip_layout.map(|s| (s.count, s.rows, s.margin)),
            constant_maps,
            removed: lock.removed(),
            kept: lock.kept(),
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
    fn run_pack(
        self,
        pack: Pack,
        lock: SetLock,
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> Result<GenerateReport, Error> {
        let (textures, stats, encode_time) = self.pack_textures(pack, progress)?;
        let name = &self.loaded.name;
        let names: Vec<String> = textures.iter().map(|(spec, _)| texture_file_name(name, spec)).collect();
        let entries: Vec<MapEntry> = textures
            .iter()
            .zip(&names)
            .map(|((spec, bytes), file)| MapEntry::for_texture(spec, file, sha256_hex(bytes)))
            .collect();
        // Moved, not copied: the encoded textures were held twice while they were written.
        let files: Vec<(String, Vec<u8>)> =
            names.into_iter().zip(textures).map(|(file, (_, bytes))| (file, bytes)).collect();
        let options = self.request.options;
        let mut manifest =
            export::manifest(&self.loaded, (self.size, self.height), entries, options, "png", Some(pack));
        manifest.job = self.request.job.clone();
        let json = export::manifest_json(&manifest)?;
        let written = lock.write(&files, (&export::manifest_file_name(name), &json))?;
        let strips = strips_of(&self.graph, &self.maps, self.size, self.height);
        Ok(GenerateReport {
            files: written,
            stats,
            encode_time,
            total_time: self.start.elapsed(),
            created_folder: lock.created_folder,
            strips: strips.map(|s| (s.count, s.rows, s.margin)),
            constant_maps: Vec::new(),
            removed: lock.removed(),
            kept: lock.kept(),
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
    let frames = strip_frames(width, height, graph.wraps_v(), strips);
    let mut stats = EvalStats::default();
    for (k, (frame, kept)) in frames.iter().enumerate() {
        let nodes = &|done: usize, total: usize| progress(k * total + done, frames.len() * total);
        let mut band: Vec<(MapKind, crate::ops::Image)> = Vec::new();
        let strip_stats = evaluate_rows(graph, maps, *frame, nodes, &mut |map, image| band.push((map, image)));
        stats.merge(strip_stats);
        band.sort_by_key(|(m, _)| *m);
        sink(&band, kept.clone())?;
    }
    Ok(stats)
}

/// Like `for_each_band`, but hands each map of a strip to `sink` the moment it is finished
/// (with the rows of it that belong to the texture), so a strip's finished maps are not
/// held as f32 until its last one is done: at 4096² that was 335 MB of a 2048-row strip's
/// five maps.
fn for_each_strip_map(
    graph: &Graph,
    maps: &[MapKind],
    width: usize,
    height: usize,
    strips: Option<Strips>,
    progress: &(dyn Fn(usize, usize) + Sync),
    sink: &mut dyn FnMut(MapKind, crate::ops::Image, std::ops::Range<usize>) -> Result<(), Error>,
) -> Result<EvalStats, Error> {
    let frames = strip_frames(width, height, graph.wraps_v(), strips);
    let mut stats = EvalStats::default();
    for (k, (frame, kept)) in frames.iter().enumerate() {
        let nodes = &|done: usize, total: usize| progress(k * total + done, frames.len() * total);
        let mut failed = None;
        let strip_stats = evaluate_rows(graph, maps, *frame, nodes, &mut |map, image| {
            if failed.is_none() {
                failed = sink(map, image, kept.clone()).err();
            }
        });
        if let Some(error) = failed {
            return Err(error);
        }
        stats.merge(strip_stats);
    }
    Ok(stats)
}

/// The frame of each strip (its rows plus its margins) and the rows of it that belong to the
/// texture. The tile repeats along v, so its strips' margins run round the seam (the first
/// strip's margin above is the texture's last rows); a body atlas's stop at its ends.
fn strip_frames(
    width: usize,
    height: usize,
    wraps: bool,
    strips: Option<Strips>,
) -> Vec<(Frame, std::ops::Range<usize>)> {
    let Some(Strips { count, rows: step, margin }) = strips else {
        return vec![(Frame::whole(width, height), 0..height)];
    };
    (0..count)
        .map(|k| {
            let (start, end) = (k * step, ((k + 1) * step).min(height));
            if wraps {
                let row0 = (start + height - margin) % height;
                let frame = Frame { width, height: end - start + 2 * margin, full_height: height, row0, wraps_v: true };
                (frame, margin..margin + end - start)
            } else {
                let row0 = start.saturating_sub(margin);
                let frame = Frame {
                    width,
                    height: (end + margin).min(height) - row0,
                    full_height: height,
                    row0,
                    wraps_v: false,
                };
                (frame, start - row0..end - row0)
            }
        })
        .collect()
}

/// Rows of texture per strip of a long texture, as a multiple of its width: two widths hold
/// about what a square tile of 1.4× the width would, and the margins (`Graph::row_reach`,
/// typically a tenth of a width each side for patterned species) then cost about a tenth.
pub const STRIP_WIDTHS: usize = 2;

/// A set's map files before they are committed: compressed bytes, or already written to
/// their temporaries (`SetLock::stage`).
enum Files {
    Bytes(Vec<(String, Vec<u8>)>),
    Staged(Vec<export::Staged>),
}

/// How a texture taller than wide is cut: `count` strips of `rows` rows, each evaluated
/// with `margin` more rows each side (`Graph::row_reach`).
#[derive(Debug, Clone, Copy)]
struct Strips {
    count: usize,
    rows: usize,
    margin: usize,
}

/// The node buffers a square tile may hold at once and still be evaluated whole: the speed
/// issue's memory target (peak resident ≤ 1 GiB at 4096² for every species) less what else
/// is resident then (the quantised maps waiting for their encoders, the program). At 2048²
/// every built-in species fits whole, so the common sizes pay no margins. Measured at 4096²:
/// Erythrolamprus' 768 MiB of buffers peaked at 847 MB resident; with the box blur in place
/// and 64 MiB buffers kept out of the pool, the species whose buffers reach 832 MiB peaked
/// at 885–978 MiB resident, and evaluated whole instead of in two or three strips took
/// 0.55–0.65 of the time (`crotalus-atrox` 3.85 → 2.39 s). 840: the box blur's rows of
/// scratch (`Op::scratch_rows`), counted since, add up to 8 MiB to the same runs (its row
/// sweeps, counted later still, under 1 MiB a blur on two threads). Since then 64 MiB
/// buffers do wait in the pool, but only in the room the schedule's planned peak leaves
/// (`ops::pool::set_large_budget`): the species' 4K peaks stayed at 939–950 MiB.
pub const TILE_BUFFER_BUDGET_BYTES: u64 = 840 << 20;

/// The node buffers of one strip of a tile too large to evaluate whole: less than the whole
/// tile's budget, because a strip's set also holds every map of the whole tile quantised
/// until its last strip is in (168 MB at 4096²) and the buffer pool (`ops::pool`). Measured
/// at 4096²: the largest peak over the built-in species, Elaphe climacophora in three
/// strips, 906 MiB resident.
pub const STRIP_BUFFER_BUDGET_BYTES: u64 = 640 << 20;

/// The strips of a `width` × `height` texture, or None to evaluate it whole. A long texture
/// (the body atlas) is cut every `STRIP_WIDTHS` widths. A square tile is whole unless its
/// buffers would exceed `TILE_BUFFER_BUDGET_BYTES`; then it is cut into the fewest strips
/// (2 to 16) whose buffers, margins included, fit `STRIP_BUFFER_BUDGET_BYTES` (the margins
/// are recomputed rows, so fewer strips cost less time: measured at 4096², three strips
/// instead of four took Natrix natrix from 5.5–5.7 s to 5.0 s); if none fits, the most
/// strips whose margins still leave each shorter than the texture (None if even two
/// cannot). `SNAKESKIN_TILE_BUDGET_MIB` replaces both budgets (how the tests send small
/// tiles through strips).
fn strips_of(graph: &Graph, maps: &[MapKind], width: usize, height: usize) -> Option<Strips> {
    let margin = graph.row_reach(maps, width);
    if !graph.wraps_v() {
        let rows = STRIP_WIDTHS * width;
        return Some(Strips { count: height.div_ceil(rows), rows, margin });
    }
    // A malformed value is refused at the command line's start.
    // In bytes, saturating: shifted, 2^44 MiB and more wrapped to a small budget (or 0),
    // and a budget meant as unlimited cut the tile into the most strips (a hostile-input sweep).
    let set_budget =
        crate::memory::tile_budget_from_env().ok().flatten().map(|mib| mib.saturating_mul(crate::memory::MIB));
    let buffers = |rows: usize| crate::graph::estimate_peak_bytes(graph, maps, width, rows);
    // With the normal node, though a tile evaluated whole goes without it (`whole_tile_maps`):
    // the budget was measured with it, and without it the presets in strips at 4096² would
    // still not fit (the two measured then, without it: over 1000 and 920–960 MiB).
    if buffers(height) <= set_budget.unwrap_or(TILE_BUFFER_BUDGET_BYTES) {
        return None;
    }
    let fits = |rows: usize| buffers(rows) <= set_budget.unwrap_or(STRIP_BUFFER_BUDGET_BYTES);
    let mut best = None;
    for count in 2..=16 {
        let rows = height.div_ceil(count);
        // A strip with its margins must stay shorter than the texture.
        if rows + 2 * margin >= height {
            break;
        }
        // Every strip must hold rows: with `rows` per strip, `count` strips must not start
        // one past the end (height 100 in 14 strips of 8 would put the last at row 104).
        if rows * (count - 1) >= height {
            continue;
        }
        best = Some(Strips { count, rows, margin });
        if fits(rows + 2 * margin) {
            break;
        }
    }
    best
}

/// How `--stats` labels the normal map's step where it is quantised from the height map's
/// rows (after the node's own label, "height to normal"): its output is the file's samples.
pub const NORMAL_FROM_HEIGHT: &str = "rows → file";

/// The maps a tile evaluated whole runs its graph for, and how it makes its normal map:
/// `maps` less the normal map where that is the height map's normals and nothing else reads
/// it (`Graph::normal_from`, whose spec comes second), for `generate` quantises it
/// straight from the height map a row at a time, without the node: its f32 image, three
/// samples a pixel (192 MiB at 4096²), was written, read once by `quantize` and freed.
/// Strips and body atlases evaluate the node.
fn whole_tile_maps(graph: &Graph, maps: &[MapKind], width: usize, height: usize) -> (Vec<MapKind>, Option<NormalSpec>) {
    let direct = graph
        .normal_from(MapKind::Height, graph.frame(Frame::whole(width, height)))
        .filter(|_| maps.contains(&MapKind::Normal) && maps.contains(&MapKind::Height));
    (maps.iter().copied().filter(|m| direct.is_none() || *m != MapKind::Normal).collect(), direct)
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
    let encoders = kinds.iter().map(|m| export::RowEncoder::new(*m, width, height)).collect::<Result<Vec<_>, _>>()?;
    let mut encode_time = Duration::ZERO;
    // Each map's rows are quantised the moment the map is finished in a strip (its f32
    // buffer then freed) and compressed by the map's own thread, in order, while the graph
    // goes on. The hand-over waits for the encoder to take the rows (a rendezvous channel):
    // one strip's samples being compressed and the next one's waiting is what the estimate
    // counts (`memory::estimate_strips_bytes`). Through an unbounded channel, an encoder that
    // fell behind (other work holding the cores) let strips of samples pile up beyond it.
    let (stats, encoders) = std::thread::scope(|scope| {
        let mut senders = Vec::new();
        let mut threads = Vec::new();
        for mut encoder in encoders {
            let (send, receive) = std::sync::mpsc::sync_channel::<Vec<u8>>(0);
            senders.push((encoder.map, send));
            threads.push(scope.spawn(move || {
                let mut time = Duration::ZERO;
                for samples in receive {
                    let t = Instant::now();
                    encoder.write_samples(&samples)?;
                    time += t.elapsed();
                }
                Ok::<_, export::ExportError>((encoder, time))
            }));
        }
        let stats = for_each_strip_map(graph, maps, width, height, Some(layout), progress, &mut |map, image, rows| {
            let t = Instant::now();
            let samples = export::RowEncoder::samples(map, &image, rows);
            drop(image);
            encode_time += t.elapsed();
            let (_, send) = senders.iter().find(|(m, _)| *m == map).expect("an encoder per map");
            // A closed channel means the encoder failed: its error comes from the join below.
            let _ = send.send(samples);
            Ok(())
        });
        drop(senders);
        let mut encoders = Vec::new();
        for thread in threads {
            let (encoder, time) = thread.join().expect("a PNG encoder thread panicked")?;
            encode_time += time;
            encoders.push(encoder);
        }
        stats.map(|s| (s, encoders))
    })?;
    let t = Instant::now();
    let files = encoders
        .into_par_iter()
        .map(|e| Ok((export::map_file_name(name, e.map), e.finish()?)))
        .collect::<Result<Vec<_>, export::ExportError>>()?;
    Ok((kinds, files, stats, encode_time + t.elapsed()))
}

/// `strips` for a square tile: (maps, their files' names and bytes, merged stats, encode
/// time). Each map's rows go into its quantised samples as the strips finish it (an f32
/// strip is freed at once; the quantised tile is a quarter to an eighth of its f32 size)
/// and each map is compressed on its own thread as soon as its last strip is in, by the
/// encoder of a tile evaluated whole, so the files are byte for byte the same.
#[allow(clippy::type_complexity)]
fn tile_strips(
    graph: &Graph,
    maps: &[MapKind],
    name: &str,
    size: usize,
    layout: Strips,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<(Vec<MapKind>, Vec<(String, Vec<u8>)>, EvalStats, Duration), Error> {
    let mut kinds: Vec<MapKind> = maps.iter().copied().filter(|m| graph.output(*m).is_some()).collect();
    kinds.sort();
    kinds.dedup();
    let mut tiles: Vec<export::Quantized> = Vec::new();
    let mut rows_in = vec![0usize; kinds.len()];
    let mut quantise_time = Duration::ZERO;
    let (stats, mut encoded) = std::thread::scope(|scope| {
        let mut encoders = Vec::new();
        let stats = for_each_strip_map(graph, maps, size, size, Some(layout), progress, &mut |map, image, rows| {
            let t = Instant::now();
            let band = image.band(rows.clone());
            drop(image);
            let quantized = export::quantize(map, &band);
            let index = kinds.iter().position(|k| *k == map).expect("a requested map");
            match tiles.iter_mut().find(|q| q.map == map) {
                Some(tile) => tile.samples.extend_from_slice(&quantized.samples),
                None => {
                    let mut tile = export::Quantized { height: size, ..quantized };
                    tile.samples.reserve_exact(tile.samples.len() / rows.len() * (size - rows.len()));
                    tiles.push(tile);
                }
            }
            rows_in[index] += rows.len();
            if rows_in[index] == size {
                let position = tiles.iter().position(|q| q.map == map).expect("just filled");
                let tile = tiles.swap_remove(position);
                encoders.push(scope.spawn(move || {
                    let t = Instant::now();
                    let png = export::encode_quantized(&tile);
                    (map, png.map(|bytes| (export::map_file_name(name, map), bytes)), t.elapsed())
                }));
            }
            quantise_time += t.elapsed();
            Ok(())
        });
        let encoded: Vec<_> = encoders.into_iter().map(|h| h.join().expect("a PNG encoder thread panicked")).collect();
        (stats, encoded)
    });
    let stats = stats?;
    encoded.sort_by_key(|(map, _, _)| *map);
    let encode_time = quantise_time + encoded.iter().map(|(_, _, t)| *t).sum::<Duration>();
    let kinds: Vec<MapKind> = encoded.iter().map(|(map, _, _)| *map).collect();
    let files = encoded.into_iter().map(|(_, file, _)| file).collect::<Result<Vec<_>, _>>()?;
    Ok((kinds, files, stats, encode_time))
}

/// Plans and runs a whole generation.
pub fn generate(request: &GenerateRequest, progress: &(dyn Fn(usize, usize) + Sync)) -> Result<GenerateReport, Error> {
    Plan::new(request)?.run(progress)
}
