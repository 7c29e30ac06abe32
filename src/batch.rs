//! `snakeskin batch JOBS.toml -o DIR`: many sets in one command, resumable and shardable.
//!
//! A jobs file lists `[[job]]` tables; each expands to one job per combination of its
//! `seeds` and `sizes`. Every job has a key (`Job::key`: SHA-256 of the loaded preset's
//! content hash, the overrides and every option that changes the output bytes) that its set's
//! manifest records as `"job"`. A job whose folder holds a manifest with its key, whose files
//! match their recorded SHA-256, is done and skipped, so a run that was killed is resumed by
//! running the same command again: sets are written atomically (`export::SetLock`), so a
//! killed job left either its complete old set or no manifest (maps without one, which no
//! reader accepts), and only unfinished jobs run. Every job has its own folder: jobs that
//! differ only in their `set` overrides get the overrides' hash in the folder name, a job
//! listed twice runs once (the later one is a `duplicate`), and two different jobs that would
//! still share a folder (two preset files with the same name) are refused before anything
//! runs, in every shard alike.
//! `--shard K/N` runs the jobs whose index is K modulo N (K from 0), the same split on every
//! machine, for array jobs (Slurm, Kubernetes Indexed Jobs). An index of the run's jobs,
//! their folders, manifests and status is written next to them as the run starts (the jobs as
//! planned) and again as it ends, a run a job stopped too (which jobs failed, which never ran).

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::export::pack::Pack;
use crate::export::{sha256_hex, verify_set_json, write_file_atomically};
use crate::generate::{GenerateRequest, Plan, check_set_outputs, pack_size_warning, set_file_names};
use crate::maps::{BuildOptions, Layout};
use crate::material::{FileFormat, MapKind, parse_map_list};
use crate::preset::validate::ranges::SEED_MAX;
use crate::{Error, SIZE_RANGE};

/// Whether two entries of a `set` table reach the same key (`"scales.rows" = 23` and
/// `scales = { rows = 25 }`, or `scales = 5` beside `"scales.rows" = 3`), and which: the
/// entries are applied in the table's key order, so one of the two values was silently lost.
fn set_twice(set: &std::collections::BTreeMap<String, toml::Value>) -> Option<String> {
    let written: Vec<(&String, Vec<String>)> =
        set.iter().map(|(key, value)| (key, crate::toml_text::written_keys(key, value))).collect();
    for (i, (a, a_keys)) in written.iter().enumerate() {
        for (b, b_keys) in &written[i + 1..] {
            if let Some(key) = crate::toml_text::key_written_by_both(a_keys, b_keys) {
                return Some(format!("`{key}` is set by two entries, `{a}` and `{b}`; give it once"));
            }
        }
    }
    None
}

/// At most this many jobs per file (after expansion): a typo such as `sizes = [..]` with a
/// thousand entries is refused before anything runs.
pub const MAX_JOBS: usize = 100_000;

/// A job's overrides, as its problems and warnings name them (`preset::place`).
const SET_TABLE: &str = "its `set` table";
/// Jobs files are small; anything larger is refused unread.
pub const MAX_FILE_BYTES: u64 = 1 << 20;

#[derive(Debug, thiserror::Error)]
pub enum BatchError {
    #[error("cannot read jobs file {path}: {source}")]
    Read { path: PathBuf, source: std::io::Error },
    #[error("cannot read jobs file {path}: it is {kind}; a jobs file must be a regular file")]
    NotAFile { path: PathBuf, kind: &'static str },
    #[error("jobs file {path} is {size}; jobs files are limited to {limit} bytes")]
    TooLarge { path: PathBuf, size: crate::text_file::FileSize, limit: u64 },
    /// TOML syntax, an unknown key or a wrong type, at a line and column.
    #[error("{path}:{line}:{column}: {message}")]
    Parse { path: PathBuf, line: usize, column: usize, message: String },
    /// A value outside what a job accepts; the place's line: where the key is written.
    #[error("{place}: {message}")]
    Invalid { place: JobPlace, message: String },
    /// The job's preset refused (the preset's own message), at the job's `preset` key.
    #[error("{place}: {source}")]
    Preset { place: JobPlace, source: Box<crate::preset::PresetError> },
    /// The job's `set` table refused, at its `set` key: its entries as `key=value`, and why.
    #[error("{place}: set `{entries}`: {message}")]
    Set { place: JobPlace, entries: String, message: String },
    #[error("{path}: no [[job]] tables; a jobs file lists jobs as [[job]] tables with at least a preset key")]
    Empty { path: PathBuf },
    #[error("{path}: {count} jobs after expanding seeds and sizes; at most {max} per file")]
    TooMany { path: PathBuf, count: usize, max: usize },
    #[error("invalid --shard {0:?}: expected K/N with 0 <= K < N, e.g. 0/4 (K is the array index)")]
    Shard(String),
    /// An index file in the output folder (this run's, or another run's or shard's, which
    /// tell what sets other jobs files made there) that cannot be read as one: a FIFO, a
    /// device, a link, a file larger than an index can be, or not an index.
    #[error(
        "{path} cannot be read as a batch index: {reason}. The indexes in an output folder record which jobs file \
         made each set there; remove it (or write to another folder) and run again"
    )]
    Index { path: PathBuf, reason: String },
    /// Another batch run held this index's lock through a second of tries (it holds it only
    /// while it reads and writes the index: a run stopped there, or a file system that does
    /// not release it).
    #[error(
        "another snakeskin batch is writing the index in {out} (it holds {lock}); run again when it has finished, or \
         write to another folder"
    )]
    Busy { out: PathBuf, lock: PathBuf },
    /// The job refused when the run was planned, before any job ran: its size (a body atlas
    /// too tall, more memory than the machine has) or its output (a folder, file or link
    /// in the way); the place's line: the job's `sizes` key, else its `preset` key; with the
    /// seed and size, as a job's messages at run time (a table of several seeds was named
    /// without them, and only its folder's path told which one was refused).
    #[error("{job}: {source}")]
    Planned { job: RunningJob, source: Box<Error> },
    /// The job failed while it ran (a full disk, a file that may not be replaced): its set
    /// was not written.
    #[error("{job}: {source}")]
    Failed { job: RunningJob, source: Box<Error> },
    /// The job's preset (its file, or a file it reads) changed after the run was planned:
    /// the set would not be what the job's key records, so it is not written.
    #[error(
        "{job}: the preset changed while the batch ran; its set was not written (the sets written before it are as \
         their jobs asked). Run the batch again"
    )]
    Changed { job: RunningJob },
    /// Another run made the job's set while the job waited for it (`run_one`), from other
    /// input: this job's set would replace it.
    #[error(
        "{job}: another snakeskin run made {} while this one waited for it, from other input (another jobs file's \
         preset of the same name, or other options); this job's set would replace it: write each jobs file into a -o folder of its own",
        .manifest.display()
    )]
    MadeMeanwhile { job: RunningJob, manifest: PathBuf },
    /// A job failed (`Failed`, `Changed`) and the run stopped: `source` is the earliest
    /// failed job's error (its words are this error's), `index` the run's index, every job
    /// `done`, `skipped`, `duplicate`, `failed` or `not run`, for the caller's summary, and
    /// `index_error` why it could not be written, if it could not (the file holds the index
    /// the run started with).
    #[error("{source}")]
    Stopped { index: Box<BatchIndex>, index_error: Option<Box<Error>>, source: Box<Error> },
}

/// A job's table as every message about it begins: `jobs.toml:LINE: [[job]] N (PRESET)`,
/// N counting the file's `[[job]]` tables from 1 (not the job's index in `--list` and the
/// index, which counts the jobs the tables' seeds and sizes expand to, from 0), LINE that of
/// the key the message is about, where it is written (`Job::place`).
#[derive(Debug, Clone)]
pub struct JobPlace {
    pub path: PathBuf,
    pub line: Option<usize>,
    pub table: usize,
    pub preset: String,
}

impl JobPlace {
    /// The place with `detail` after the preset, inside its parentheses.
    fn fmt_with(&self, f: &mut std::fmt::Formatter<'_>, detail: std::fmt::Arguments<'_>) -> std::fmt::Result {
        let JobPlace { path, line, table, preset } = self;
        // On one line: a newline in a jobs file's preset string printed a line of its own,
        // which could pass for the tool's (`"x\nok: all 40 jobs done"`, a hostile-input
        // sweep); the message's printer escapes the other control characters, not newlines.
        let preset = crate::toml_text::one_line(preset);
        let path = crate::toml_text::one_line(&path.display().to_string());
        write!(f, "{path}{}: [[job]] {table} ({preset}{detail})", at_line(*line))
    }
}

impl std::fmt::Display for JobPlace {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.fmt_with(f, format_args!(""))
    }
}

/// A job as its messages at run time name it: its place at its `preset` key, with the seed
/// and size it runs at: `jobs.toml:LINE: [[job]] N (PRESET, seed S, size Z)`.
#[derive(Debug, Clone)]
pub struct RunningJob {
    pub place: JobPlace,
    pub seed: u64,
    pub size: u64,
}

impl std::fmt::Display for RunningJob {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.place.fmt_with(f, format_args!(", seed {}, size {}", self.seed, self.size))
    }
}

/// One `[[job]]` table as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct JobTable {
    preset: String,
    seeds: Option<Vec<u64>>,
    sizes: Option<Vec<u64>>,
    maps: Option<String>,
    format: Option<String>,
    pack: Option<String>,
    /// With `pack`: the ambient occlusion map in the pack's occlusion channel (`--ao`).
    ao: Option<bool>,
    layout: Option<String>,
    /// The normal map's convention (`generate --normal-convention`): `opengl` or `directx`.
    normal_convention: Option<String>,
    /// `--set` overrides: dotted key to TOML value.
    #[serde(default)]
    set: std::collections::BTreeMap<String, toml::Value>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct JobsFile {
    #[serde(default, deserialize_with = "crate::preset::schema::tables")]
    job: Vec<JobTable>,
}

/// One set to make.
#[derive(Debug, Clone, PartialEq)]
pub struct Job {
    /// Position in the expanded list (what `--shard` splits on).
    pub index: usize,
    /// The `[[job]]` table it came from, counted from 1 (for messages).
    pub table: usize,
    /// Where its keys are written (for messages).
    pub lines: JobLines,
    /// The preset as given (a built-in name, or a path resolved against the jobs file).
    pub preset: String,
    pub overrides: Vec<(String, String)>,
    /// None: the preset's own seed.
    pub seed: Option<u64>,
    pub size: u64,
    pub maps: Vec<MapKind>,
    pub format: FileFormat,
    pub pack: Option<Pack>,
    /// With a pack: its occlusion channel holds the ambient occlusion map (`generate --ao`).
    pub ao: bool,
    pub layout: Layout,
    /// The normal map's convention (OpenGL with a pack, which writes its engine's own).
    pub normal_convention: NormalConvention,
}

pub use crate::DEFAULT_SIZE;
use crate::material::NormalConvention;

impl Job {
    /// Where the job's table is written, at `line` (a key's), for a message about it.
    fn place(&self, jobs_file: &Path, line: Option<usize>) -> JobPlace {
        JobPlace { path: jobs_file.into(), line, table: self.table, preset: self.preset.clone() }
    }

    /// The job's folder under the output folder:
    /// `<preset>/<layout>-<size>-seed<seed>-<format or pack>[-directx][-<maps>][-set<hash>]`, where
    /// `<hash>` is the first 8 hex digits of the overrides' SHA-256 (jobs that differ only in
    /// their overrides must not share a folder).
    pub fn folder(&self, preset_name: &str, seed: u64) -> PathBuf {
        let what = match self.pack {
            Some(p) if self.ao => format!("pack-{}-ao", p.name()),
            Some(p) => format!("pack-{}", p.name()),
            None => self.format.name().to_string(),
        };
        let convention = match self.normal_convention {
            NormalConvention::OpenGl => String::new(),
            other => format!("-{}", other.name()),
        };
        let maps = if self.pack.is_none() && self.maps != MapKind::ALL {
            format!("-{}", self.maps.iter().map(|m| m.name()).collect::<Vec<_>>().join("+"))
        } else {
            String::new()
        };
        let keyed = self.keyed_overrides();
        let overrides = if keyed.is_empty() {
            String::new()
        } else {
            format!("-set{}", &sha256_hex(serde_json::json!(keyed).to_string().as_bytes())[..8])
        };
        Path::new(preset_name).join(format!(
            "{}-{}-seed{seed}-{what}{convention}{maps}{overrides}",
            self.layout.name(),
            self.size
        ))
    }

    /// The overrides as the job's folder and key know them: a table's keys as dotted keys, in
    /// key order, so that the spellings of one override are one job. `set = { scales = {
    /// rows = 19 } }` and `set = { "scales.rows" = 19 }`, which the README says are the same
    /// (an override merges a table key by key), were two jobs making the same bytes in two
    /// folders (a sweep); an empty table writes nothing, the job of no override. Overrides of
    /// single values, the common case, keep their folders and keys (the same list, in the
    /// same order). A list is a value, kept whole.
    fn keyed_overrides(&self) -> Vec<(String, String)> {
        fn leaves(key: String, value: toml::Value, into: &mut Vec<(String, String)>) {
            match value {
                // An empty table writes no key (`scales = {}` is no override).
                toml::Value::Table(table) => {
                    for (k, v) in table {
                        leaves(format!("{key}.{k}"), v, into);
                    }
                }
                other => into.push((key, other.to_string())),
            }
        }
        let mut keyed = Vec::new();
        for (key, text) in &self.overrides {
            // The value as `load_jobs` wrote it (`toml::Value`'s text), read back.
            match format!("v = {text}").parse::<toml::Table>().ok().and_then(|mut t| t.remove("v")) {
                Some(value) => leaves(key.clone(), value, &mut keyed),
                None => keyed.push((key.clone(), text.clone())),
            }
        }
        keyed.sort();
        keyed
    }

    /// The job's key: what its output bytes depend on (the preset's content and seed, the
    /// overrides, the options and the generator's version).
    pub fn key(&self, preset_hash: &str, seed: u64) -> String {
        let mut description = serde_json::json!({
            "generator_version": env!("CARGO_PKG_VERSION"),
            "preset_hash": preset_hash,
            "overrides": self.keyed_overrides(),
            "seed": seed,
            "size": self.size,
            "maps": self.maps.iter().map(|m| m.name()).collect::<Vec<_>>(),
            "format": self.format.name(),
            "pack": self.pack.map(|p| p.name()),
            "layout": self.layout.name(),
        });
        // Only when asked for: the keys of jobs written before `ao` and `normal_convention`
        // existed stay theirs.
        if self.ao {
            description["ao"] = true.into();
        }
        if self.normal_convention != NormalConvention::OpenGl {
            description["normal_convention"] = self.normal_convention.name().into();
        }
        sha256_hex(description.to_string().as_bytes())
    }
}

/// A job's size outside `SIZE_RANGE`, in words.
fn size_refused(size: impl std::fmt::Display) -> String {
    format!("size {size}: accepted sizes are {} to {} pixels", SIZE_RANGE.start(), SIZE_RANGE.end())
}

/// A seed beyond the preset key's range (`ranges::SEED_MAX`), refused before any job runs:
/// the batch index and each set's manifest record it as a JSON number.
fn seed_refused(seed: impl std::fmt::Display) -> String {
    format!("seed {seed}: accepted seeds are 0 to {SEED_MAX} (2^53 - 1, the largest JSON readers keep exactly)")
}

/// `:LINE` after a jobs file's path, where the line is known.
fn at_line(line: Option<usize>) -> String {
    line.map(|l| format!(":{l}")).unwrap_or_default()
}

/// Where a job's keys are written in its jobs file (1-based lines), for its messages.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct JobLines {
    pub preset: Option<usize>,
    pub set: Option<usize>,
    pub sizes: Option<usize>,
}

/// A jobs file's error in its reader's words (`toml_text::describe`), its key counted as the
/// other messages count jobs and items (from 1).
fn jobs_file_error(path: &Path, described: crate::toml_text::Described) -> BatchError {
    let (line, column) = described.line_column.unwrap_or((1, 1));
    // `job.0.sizes` is the first [[job]] table's `sizes`: "[[job]] 1", as the other
    // messages count the tables.
    // A job's own key (`job.2`: a missing field) is the table itself, and an item of a
    // list (`sizes.0`) is counted from 1 as well.
    let in_job =
        described.key.as_deref().and_then(|k| k.strip_prefix("job.")).map(|k| k.split_once('.').unwrap_or((k, "")));
    let message = match in_job.and_then(|(index, key)| Some((index.parse::<usize>().ok()? + 1, key))) {
        // A size the type cannot hold (`-64`) said "a whole number from 0 to
        // 18446744073709551615": the size's own range, as for a size in the type's.
        Some((job, key))
            if let Some(value) = crate::toml_text::integer_out_of_type(&described.message)
                && key.starts_with("sizes.") =>
        {
            format!("[[job]] {job}: key `sizes`: {}", size_refused(value))
        }
        Some((job, key))
            if let Some(value) = crate::toml_text::integer_out_of_type(&described.message)
                && key.starts_with("seeds.") =>
        {
            format!("[[job]] {job}: key `seeds`: {}", seed_refused(value))
        }
        Some((job, "")) if described.message == "missing field `preset`" => {
            format!("[[job]] {job}: {}: every job names its preset, built-in or a .toml file", described.message)
        }
        Some((job, "")) => format!("[[job]] {job}: {}", described.message),
        Some((job, key)) => {
            match key.split_once('.').and_then(|(list, item)| Some((list, item.parse::<usize>().ok()?))) {
                Some((list, item)) => format!("[[job]] {job}: key `{list}`, item {}: {}", item + 1, described.message),
                None => format!("[[job]] {job}: key `{key}`: {}", described.message),
            }
        }
        // `[job]`: one table where the file needs an array of them.
        None if described.key.as_deref() == Some("job") && described.message.starts_with("invalid type: table") => {
            "write each job as a [[job]] table (double brackets: a list of jobs); [job] is a single table".into()
        }
        None => described.keyed_message(),
    };
    BatchError::Parse { path: path.into(), line, column, message }
}

/// Reads and expands a jobs file; every value is checked before any job runs.
pub fn load_jobs(path: &Path) -> Result<Vec<Job>, BatchError> {
    use crate::text_file::BoundedReadError;
    let text = crate::text_file::read_bounded(path, MAX_FILE_BYTES).map_err(|e| match e {
        BoundedReadError::Io(source) => BatchError::Read { path: path.into(), source },
        BoundedReadError::NotAFile(kind) => BatchError::NotAFile { path: path.into(), kind },
        BoundedReadError::TooLarge(size) => BatchError::TooLarge { path: path.into(), size, limit: MAX_FILE_BYTES },
    })?;
    let file: JobsFile =
        toml::from_str(&text).map_err(|e| jobs_file_error(path, crate::toml_text::describe(&text, &e)))?;
    if let Some(underflow) = crate::toml_text::underflowing_float(&text) {
        return Err(jobs_file_error(path, underflow));
    }
    if file.job.is_empty() {
        return Err(BatchError::Empty { path: path.into() });
    }
    let base = jobs_folder(path);
    let base = base.as_path();
    let listed = |list: &Option<Vec<u64>>| list.as_ref().map_or(1, Vec::len);
    let count: usize = file.job.iter().map(|t| listed(&t.seeds).saturating_mul(listed(&t.sizes))).sum();
    if count > MAX_JOBS {
        return Err(BatchError::TooMany { path: path.into(), count, max: MAX_JOBS });
    }
    let mut jobs = Vec::with_capacity(count);
    let key_lines = crate::toml_text::KeyLines::new(&text);
    for (k, table) in file.job.iter().enumerate() {
        let line = |key: &str| key_lines.line(&format!("job.{k}.{key}"));
        let invalid = |key: &str, message: String| BatchError::Invalid {
            place: JobPlace { path: path.into(), line: line(key), table: k + 1, preset: table.preset.clone() },
            message,
        };
        let lines = JobLines { preset: line("preset"), set: line("set"), sizes: line("sizes") };
        // A preset path is relative to the jobs file, by the rule `generate` applies to its
        // argument relative to the working folder (`preset::names_a_file`); anything else
        // is a built-in preset. An entry with a `/` is a path even where it names a folder
        // there (refused as one): left as written, it was looked for in the working folder.
        // Joined without `.` inside (`J/./sub` named in messages read as a path to write).
        // And kept a path where the join drops the `/` (`NAME/` beside a jobs file named
        // without a folder read as `NAME`, the built-in, where `./jobs.toml` refused it).
        let relative = Path::new(&table.preset).is_relative().then(|| {
            let joined = base.join(&table.preset).components().collect::<std::path::PathBuf>();
            // A file name alone, no folder: `NAME/` joined to an empty folder (not `./`, which
            // is the folder `.`, and read `./.`).
            let name_alone = matches!(joined.components().next_back(), Some(std::path::Component::Normal(_)))
                && joined.parent().is_some_and(|p| p.as_os_str().is_empty());
            if table.preset.contains('/') && name_alone { Path::new(".").join(joined) } else { joined }
        });
        let preset = match relative {
            Some(path) if crate::preset::names_a_file(&table.preset, &path) || table.preset.contains('/') => {
                // Presets are named by their paths as text: joined to a folder whose path is
                // not UTF-8, the path read lossily named no file ("cannot read preset n�/…",
                // a review).
                path.to_str().map(String::from).ok_or_else(|| {
                    invalid(
                        "preset",
                        format!(
                            "preset: its path {} is not UTF-8 text (the jobs file's folder's is not), and presets \
                             are named by their paths as text: run the batch from inside that folder, or move the \
                             jobs file and its presets to a folder whose path is UTF-8",
                            path.to_string_lossy()
                        ),
                    )
                })?
            }
            _ => table.preset.clone(),
        };
        let maps = match &table.maps {
            Some(list) => parse_map_list(list).map_err(|e| invalid("maps", format!("maps: {e}")))?,
            None => MapKind::ALL.to_vec(),
        };
        let format = match table.format.as_deref() {
            None | Some("png") => FileFormat::Png,
            Some("exr") => FileFormat::Exr,
            Some(other) => return Err(invalid("format", format!("format {other:?}: accepted: png, exr"))),
        };
        let pack = table
            .pack
            .as_deref()
            .map(str::parse::<Pack>)
            .transpose()
            .map_err(|e| invalid("pack", format!("pack: {e}")))?;
        // A pack decides its own maps and format (the folder name leaves them out too).
        if pack.is_some() && (table.maps.is_some() || table.format.is_some()) {
            return Err(invalid(
                "pack",
                "pack: a pack writes its own textures as PNG; leave out maps and format, or pack".into(),
            ));
        }
        // `--ao` means the pack's occlusion channel; without a pack the map is named.
        let ao = table.ao.unwrap_or(false);
        if ao && pack.is_none() {
            return Err(invalid(
                "ao",
                "ao: the occlusion channel of a pack (with pack = ...); without a pack, name the map: maps = \"all,ao\""
                    .into(),
            ));
        }
        // A pack writes its engine's own (`Pack::normal_convention`: DirectX for Unreal) from
        // the maps' OpenGL normals, as `generate --pack`, which refuses the flag.
        let normal_convention = match (table.normal_convention.as_deref(), pack) {
            (None, _) => NormalConvention::OpenGl,
            (Some(_), Some(pack)) => {
                return Err(invalid(
                    "normal_convention",
                    format!(
                        "normal_convention: pack {:?} writes its normal map in its engine's convention ({}); leave out \
                         normal_convention, or pack",
                        pack.name(),
                        pack.normal_convention().name()
                    ),
                ));
            }
            (Some(name), None) => NormalConvention::from_name(name).ok_or_else(|| {
                let accepted: Vec<&str> = NormalConvention::ALL.iter().map(|c| c.name()).collect();
                invalid("normal_convention", format!("normal_convention {name:?}: accepted: {}", accepted.join(", ")))
            })?,
        };
        // Without a normal map the convention changes no file: not a set of its own (a
        // `maps = "color"` job asking for DirectX ran again, in a folder of its own, for the
        // same bytes: a review).
        let normal_convention =
            if maps.contains(&MapKind::Normal) { normal_convention } else { NormalConvention::OpenGl };
        let layout = match table.layout.as_deref() {
            None | Some("tile") => Layout::Tile,
            Some("body") => Layout::Body,
            Some(other) => return Err(invalid("layout", format!("layout {other:?}: accepted: tile, body"))),
        };
        for (key, list) in [("seeds", &table.seeds), ("sizes", &table.sizes)] {
            if list.as_ref().is_some_and(Vec::is_empty) {
                return Err(invalid(key, format!("{key} = []: list at least one, or leave {key} out for the default")));
            }
        }
        let (lo, hi) = (*SIZE_RANGE.start() as u64, *SIZE_RANGE.end() as u64);
        if let Some(bad) = table.sizes.iter().flatten().find(|s| !(lo..=hi).contains(*s)) {
            return Err(invalid("sizes", size_refused(bad)));
        }
        if let Some(bad) = table.seeds.iter().flatten().find(|&&seed| seed > SEED_MAX) {
            return Err(invalid("seeds", seed_refused(bad)));
        }
        if let Some(message) = set_twice(&table.set) {
            return Err(invalid("set", message));
        }
        // The job's seed replaces a `set` one (as `--seed` replaces `--set seed=`): beside
        // `seeds` it was lost without a word, in a folder of its own (`-set<hash>`).
        if table.seeds.is_some() && table.set.contains_key("seed") {
            return Err(invalid(
                "set",
                "set = { seed = .. } beside seeds, which replace it: list the seed in seeds".into(),
            ));
        }
        let overrides: Vec<(String, String)> = table.set.iter().map(|(k, v)| (k.clone(), v.to_string())).collect();
        let seeds: Vec<Option<u64>> = match &table.seeds {
            Some(seeds) => seeds.iter().copied().map(Some).collect(),
            None => vec![None],
        };
        let sizes = table.sizes.clone().unwrap_or_else(|| vec![DEFAULT_SIZE]);
        for &seed in &seeds {
            for &size in &sizes {
                jobs.push(Job {
                    index: jobs.len(),
                    table: k + 1,
                    lines,
                    preset: preset.clone(),
                    overrides: overrides.clone(),
                    seed,
                    size,
                    maps: maps.clone(),
                    format,
                    pack,
                    ao,
                    layout,
                    normal_convention,
                });
            }
        }
    }
    Ok(jobs)
}

/// `--shard K/N`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
}

/// `K/N`, as `--shard` takes it and the index records it.
impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl std::str::FromStr for Shard {
    type Err = BatchError;
    fn from_str(s: &str) -> Result<Shard, BatchError> {
        let bad = || BatchError::Shard(s.into());
        let (k, n) = s.split_once('/').ok_or_else(bad)?;
        let (index, count): (usize, usize) =
            (k.trim().parse().map_err(|_| bad())?, n.trim().parse().map_err(|_| bad())?);
        if count == 0 || index >= count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }
}

impl Shard {
    pub const ALL: Shard = Shard { index: 0, count: 1 };

    pub fn contains(&self, job: &Job) -> bool {
        job.index % self.count == self.index
    }
}

/// Where one job stands: the word the index, `--list`, the job lines and the summary use.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JobStatus {
    /// Planned, not yet run: in `list`, and in the index a run writes as it starts.
    ToDo,
    /// Run now; from `list`, already complete with this key.
    Done,
    /// Already complete with this key: not run again.
    Skipped,
    /// The same job as `duplicate_of`, which makes its set.
    Duplicate,
    /// In a run that stopped: its set was not written.
    Failed,
    /// In a run that stopped: never started.
    NotRun,
}

impl JobStatus {
    pub fn word(self) -> &'static str {
        match self {
            JobStatus::ToDo => "to do",
            JobStatus::Done => "done",
            JobStatus::Skipped => "skipped",
            JobStatus::Duplicate => "duplicate",
            JobStatus::Failed => "failed",
            JobStatus::NotRun => "not run",
        }
    }
}

/// The index holds the word (`"status": "to do"`).
impl Serialize for JobStatus {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(self.word())
    }
}

impl std::fmt::Display for JobStatus {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        // `pad`, not `write_str`: `--list` aligns the words in a column (`{:<9}`).
        f.pad(self.word())
    }
}

/// What happened to one job.
#[derive(Debug, Clone, Serialize)]
pub struct JobOutcome {
    pub index: usize,
    pub preset: String,
    pub seed: u64,
    pub size: u64,
    /// The set's folder, relative to the output folder.
    pub folder: PathBuf,
    pub manifest: PathBuf,
    pub key: String,
    pub status: JobStatus,
    /// The index of the earlier identical job, for a `duplicate`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub duplicate_of: Option<usize>,
    /// The files of the set's names that stayed beside the job's new set (`GenerateReport::kept`):
    /// for the caller to warn of, as `generate` does (not in the index).
    #[serde(skip)]
    pub kept: Vec<crate::export::KeptFile>,
}

#[derive(Debug, Serialize)]
pub struct BatchIndex {
    pub generator: String,
    pub generator_version: String,
    /// `recorded_jobs_file`.
    pub jobs_file: String,
    /// `K/N`.
    pub shard: String,
    pub jobs: Vec<JobOutcome>,
    /// The sets earlier runs made in the folder that this run's jobs do not write (other
    /// jobs files', and this file's dropped jobs), as the index this one replaced listed them
    /// (its jobs, and the sets it carried so): whose each set is outlives the index that said
    /// so (`OtherSets`, `other_sets_to_carry`). One no longer standing with its key is
    /// dropped. Not written where there are none.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub other_sets: Vec<OtherSet>,
    /// How many jobs ran at once (`fitting_concurrency`); not written to the index, whose
    /// bytes do not depend on it.
    #[serde(skip)]
    pub concurrency: usize,
}

/// The index file's name for a shard (`index.json` for an unsharded run).
pub fn index_file_name(shard: Shard) -> String {
    if shard == Shard::ALL {
        "index.json".into()
    } else {
        format!("index.shard-{}-of-{}.json", shard.index, shard.count)
    }
}

/// Whether `name` is the name of an index file of some shard: its numbers, put back into
/// `index_file_name` (the one place that spells the name), give `name` again.
fn is_index_file_name(name: &str) -> bool {
    let numbers: Vec<usize> = name
        .split(|c: char| !c.is_ascii_digit())
        .filter(|digits| !digits.is_empty())
        .map_while(|n| n.parse().ok())
        .collect();
    let shard = match numbers[..] {
        [] => Shard::ALL,
        [index, count] => Shard { index, count },
        _ => return false,
    };
    name == index_file_name(shard)
}

/// True when `manifest` records `key` and its set is complete: every file it lists has the
/// SHA-256 it records, and it lists exactly the files the job writes (`expected`, which
/// holds the manifest's own name too). A manifest that lost a map's entry along with the map
/// passed as done, and the job was never run again.
fn is_done(manifest: &Path, key: &str, expected: &[String]) -> bool {
    let Ok(json) = crate::export::read_set_manifest(manifest, crate::text_file::Links::Refuse) else { return false };
    if json["job"].as_str() != Some(key) {
        return false;
    }
    let Ok(set) = verify_set_json(manifest, &json) else { return false };
    let name = |path: &Path| path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let mut listed: Vec<String> = set.files.iter().map(|(_, path)| name(path)).collect();
    listed.push(name(manifest));
    listed.sort();
    let mut expected = expected.to_vec();
    expected.sort();
    listed == expected
}

/// A job resolved against its preset and the output folder.
struct Resolved {
    outcome: JobOutcome,
    /// Whether its set is complete with its key.
    done: bool,
    /// The preset's warnings (`LoadedPreset::warnings`: clamped colours, the model's limit).
    warnings: Vec<String>,
    /// The files its set writes (`generate::set_file_names`).
    files: Vec<String>,
    /// The preset's `content_hash`, as its set's manifest records it (`preset_hash`).
    preset_hash: String,
    /// The manifest there as the run was planned (`manifest_identity`; None where there was
    /// none, or the job is another shard's): a job compares it under the set's lock, so that
    /// a set another run made since is never taken for the one it planned to replace.
    found: Option<ManifestIdentity>,
}

/// `check`: whether to look for its finished set (reading and hashing its files).
fn resolve(jobs_file: &Path, job: &Job, out: &Path, check: bool) -> Result<Resolved, Error> {
    let folder = jobs_folder(jobs_file);
    let loaded =
        crate::preset::load_beside(&job.preset, &folder, &job.overrides, job.seed).map_err(|source| match source {
            // The preset's message says `--set`, which a jobs file's reader did not write.
            crate::preset::PresetError::Override { argument, message } => {
                // Its entries on one line: a key with a newline printed a made-up `1/1 done` line.
                let entries = crate::toml_text::one_line(&argument);
                BatchError::Set { place: job.place(jobs_file, job.lines.set), entries, message }
            }
            // At the `set` line where the table wrote a refused key; problems all in the file
            // are the file's, at the `preset` line (they were placed at `set` whenever the job
            // had one).
            crate::preset::PresetError::Invalid { file, problems } if problems.iter().any(|p| p.overridden) => {
                BatchError::Invalid {
                    place: job.place(jobs_file, job.lines.set),
                    message: crate::preset::describe_problems(&file, &problems, SET_TABLE),
                }
            }
            source => BatchError::Preset { place: job.place(jobs_file, job.lines.preset), source: Box::new(source) },
        })?;
    // A warning of a key the job's `set` wrote names that job: "its `set` table", as its
    // errors say after the job's place, named no job here, and jobs of one preset with
    // different tables could not be told apart (a review).
    let set_table = format!(
        "the `set` of [[job]] {} at {}{}",
        job.table,
        crate::toml_text::one_line(&jobs_file.display().to_string()),
        at_line(job.lines.set)
    );
    let mut warnings = loaded.warnings(&job.preset, &set_table);
    // A pack longer than its engine loads, at the job's `sizes` line (`Pack::size_problem`).
    if let Some(pack) = job.pack
        && let Some(problem) = pack_size_warning(pack, job.layout, &loaded.preset, job.size as usize, "a size of")
    {
        warnings.push(format!("warning: {}: {problem}", job.place(jobs_file, job.lines.sizes.or(job.lines.preset))));
    }
    if let Some(pack) = job.pack
        && let Some(lost) = crate::generate::ambient_warning(loaded.preset.optics.ambient_ior, pack.material_reader())
    {
        warnings.push(format!("warning: {}: {lost}", job.place(jobs_file, job.lines.preset)));
    }
    let seed = loaded.preset.seed;
    let key = job.key(&loaded.content_hash, seed);
    let folder = job.folder(&loaded.name, seed);
    let manifest = folder.join(crate::export::manifest_file_name(&loaded.name));
    let mut outcome = JobOutcome {
        index: job.index,
        preset: loaded.name.clone(),
        seed,
        size: job.size,
        folder,
        manifest,
        key,
        status: JobStatus::ToDo,
        duplicate_of: None,
        kept: Vec::new(),
    };
    let files = set_file_names(&loaded, &request(job, out, &outcome));
    // Taken before the look at the set: a set committed between the two is another file.
    let found = if check { manifest_identity(&out.join(&outcome.manifest)) } else { None };
    let done = check && is_done(&out.join(&outcome.manifest), &outcome.key, &files);
    if done {
        outcome.status = JobStatus::Skipped;
    }
    Ok(Resolved { outcome, done, warnings, files, preset_hash: loaded.content_hash.clone(), found })
}

/// Resolves every job of the file (not only the shard's, so that every shard finds the same
/// duplicates and refuses the same clashes; only the shard's sets are checked on disk): a
/// job identical to an earlier one is marked its `duplicate`; two different jobs bound for
/// one folder are an error.
fn resolve_all(jobs_file: &Path, jobs: &[Job], out: &Path, shard: Shard) -> Result<Vec<Resolved>, Error> {
    let mut first_in: std::collections::HashMap<PathBuf, usize> = std::collections::HashMap::new();
    let mut resolved: Vec<Resolved> = Vec::with_capacity(jobs.len());
    for job in jobs {
        let mut r = resolve(jobs_file, job, out, shard.contains(job))?;
        // The job's folder refused, at its `preset` line, the preset as the job writes it (a
        // clash of `x.toml` with `sub/x.toml` named both jobs `(x)`).
        let refuse = |message: String| -> Error {
            BatchError::Invalid { place: job.place(jobs_file, job.lines.preset), message }.into()
        };
        // A preset named like an index (`index.json.toml`) would put its sets in the folder
        // the run's index is written to: found before any job runs, not after all of them.
        let top = r.outcome.folder.components().next().map(|c| c.as_os_str().to_string_lossy().into_owned());
        if let Some(top) = top.filter(|top| is_index_file_name(top)) {
            let message = format!(
                "its sets would go in the folder {top}, a name the batch keeps for its index (index.json, \
                 index.shard-K-of-N.json); rename the preset file"
            );
            return Err(refuse(message));
        }
        if let Some(&earlier) = first_in.get(&r.outcome.folder) {
            let first = &resolved[earlier].outcome;
            if first.key != r.outcome.key {
                // Two different jobs whose sets would overwrite each other: named with both
                // jobs' `preset` lines (this job's where the message starts).
                let first_line = jobs[earlier].lines.preset.map(|l| format!("line {l}, ")).unwrap_or_default();
                let message = format!(
                    "would write {}, which [[job]] {} ({first_line}{}) writes with different output; rename one of the \
                     preset files (a preset's name is its file name without `.toml`; a built-in preset's, its own)",
                    r.outcome.folder.display(),
                    jobs[earlier].table,
                    jobs[earlier].preset,
                );
                return Err(refuse(message));
            }
            r.outcome.status = JobStatus::Duplicate;
            r.outcome.duplicate_of = Some(first.index);
        } else {
            first_in.insert(r.outcome.folder.clone(), resolved.len());
        }
        resolved.push(r);
    }
    Ok(resolved)
}

/// The shard's jobs with their folders and whether each is already done (`done` or
/// `to do`), after the checks `run` makes before it writes anything but the memory (a batch
/// that `run` would refuse for its input is refused here with the same error, not listed
/// "to do"); nothing is run or written.
pub fn list(jobs_file: &Path, jobs: &[Job], out: &Path, shard: Shard) -> Result<Vec<JobOutcome>, Error> {
    Ok(plan(jobs_file, jobs, out, shard, false)?
        .resolved
        .into_iter()
        .map(|Resolved { mut outcome, done, .. }| {
            if outcome.duplicate_of.is_none() {
                outcome.status = if done { JobStatus::Done } else { JobStatus::ToDo };
            }
            outcome
        })
        .collect())
}

/// The generation a job asks for, with its key for the manifest.
fn request(job: &Job, out: &Path, outcome: &JobOutcome) -> GenerateRequest {
    GenerateRequest {
        preset: job.preset.clone(),
        overrides: job.overrides.clone(),
        seed: job.seed,
        size: job.size,
        maps: job.maps.clone(),
        out_dir: out.join(&outcome.folder),
        options: BuildOptions { layout: job.layout, normal_convention: job.normal_convention },
        format: job.format,
        pack: job.pack,
        ao: job.ao,
        job: Some(outcome.key.clone()),
    }
}

/// How many jobs `run` runs at once unless told: two, or one on a one-core machine. One
/// job keeps both cores busy through its graph, but not through its start (preset, lattice
/// set-up) and its end (the last PNG's compression, the manifest's hashes): two jobs fill
/// each other's gaps (measured in BENCHMARKS.md, "Batch throughput").
pub fn default_concurrency() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get()).min(2)
}

/// At most this many jobs at once (`--concurrent`).
pub const MAX_CONCURRENCY: usize = 16;

/// The most jobs that may run at once: at most `requested`, and only as many as the largest
/// estimates (`Plan`'s peak memory) fit in the available memory together; at least one (a
/// job that does not fit alone was refused when it was planned).
pub fn fitting_concurrency(requested: usize, mut estimates: Vec<u64>, available_bytes: u64) -> usize {
    estimates.sort_unstable_by(|a, b| b.cmp(a));
    let mut total = 0u64;
    let mut fit = 0;
    for e in estimates.iter().take(requested.max(1)) {
        total = total.saturating_add(*e);
        if total > available_bytes {
            break;
        }
        fit += 1;
    }
    fit.max(1)
}

/// What `run` tells its caller while it works, on the caller's thread: a batch said nothing
/// on a terminal until its first job ended (an 8K set: 85 s of a blank screen; a sweep).
#[derive(Debug)]
pub enum BatchProgress<'a> {
    /// Every job of the shard planned: `total` of them, the first event.
    Planned { total: usize },
    /// A job began to make its set (not a job whose set is there already, or a duplicate).
    Started { outcome: &'a JobOutcome },
    /// A job ended, `done` of `total` so far, in the order they end.
    Ended { done: usize, total: usize, outcome: &'a JobOutcome },
    /// A job that started ended without its set: it failed (the run stops), or the run
    /// stopped while it waited for another run's lock on the set.
    Left { outcome: &'a JobOutcome },
}

/// Runs the shard's jobs, up to `concurrency` at once (each job's graph still uses every
/// core; bounded by memory: `fitting_concurrency`); `progress` as the jobs are planned, as
/// each starts and as each ends (`BatchProgress`). Every job of the shard is planned first (preset
/// loaded and validated, memory checked), so a bad job stops the run before any set is
/// written, not in the middle of it. A job that fails at run time stops the run: no new job
/// starts, the running ones finish (each set is written atomically), the index is written
/// with the failed jobs and those never started, and `BatchError::Stopped` returned with it
/// and the earliest failed job's error. The index lists the jobs in their order, whatever
/// order they finished in, and the files are the same at any concurrency (every set's bytes
/// are).
pub fn run(
    jobs_file: &Path,
    jobs: &[Job],
    out: &Path,
    shard: Shard,
    concurrency: usize,
    warn: &mut dyn FnMut(&str),
    progress: &mut dyn FnMut(BatchProgress),
) -> Result<BatchIndex, Error> {
    let Planned { mine, resolved, estimates } = plan(jobs_file, jobs, out, shard, true)?;
    progress(BatchProgress::Planned { total: mine.len() });
    let requested = concurrency.clamp(1, MAX_CONCURRENCY);
    // With nothing to run, the summary says what was asked (one, from an empty list, read as
    // if memory had limited it).
    let concurrency = if estimates.is_empty() {
        requested
    } else {
        fitting_concurrency(requested, estimates, crate::memory::available_bytes())
    };
    let total = mine.len();
    let next = std::sync::atomic::AtomicUsize::new(0);
    let stop = std::sync::atomic::AtomicBool::new(false);
    // The shard's presets' warnings, each once, before any job runs (a preset's clamped
    // colours are listed in its sets' manifests too).
    let mut warned: Vec<&String> = Vec::new();
    for warning in resolved.iter().flat_map(|r| &r.warnings) {
        if !warned.contains(&warning) {
            warn(warning);
            warned.push(warning);
        }
    }
    let work: Vec<(&Job, Resolved)> = mine.into_iter().zip(resolved).collect();
    // The index as the run starts, every job as planned (`to do`, `skipped`, `duplicate`):
    // an index left from another jobs file (a run stopped by a signal writes none at its
    // end) described sets this run is not about.
    let planned = work.iter().map(|(_, r)| r.outcome.clone()).collect();
    // The sets this run makes: a job skipped (its set there already) or a duplicate makes none.
    let planned_sets: std::collections::HashSet<&PathBuf> = work
        .iter()
        .filter(|(_, r)| !r.done && r.outcome.duplicate_of.is_none())
        .map(|(_, r)| &r.outcome.manifest)
        .collect();
    // Written over the index this run replaces, carrying the sets it records (`write_merged`;
    // a set of theirs that a job here would replace was refused in `plan`), and saying whose
    // jobs it listed (a second jobs file into one folder replaced the first's index without
    // a word).
    let mut started = BatchIndex::new(jobs_file, shard, planned, Vec::new(), concurrency);
    let earlier_jobs_file = started.write_merged(out, shard, &planned_sets)?;
    // (An index re-saved without its jobs file names none: no note.)
    let named = |earlier: &String| !earlier.is_empty() && !is_this_jobs_file(earlier, jobs_file);
    if let Some(earlier) = earlier_jobs_file.filter(named) {
        warn(&format!(
            "note: {} listed the jobs of {}; it lists this run's now (their sets stay where they are)",
            out.join(index_file_name(shard)).display(),
            earlier
        ));
    }
    let other_sets = started.other_sets;
    let mut finished: Vec<Option<JobOutcome>> = vec![None; total];
    let mut failures: Vec<(usize, Error)> = Vec::new();
    std::thread::scope(|scope| {
        // A job's end, or a note while it runs (said by the caller's `warn`, on this thread).
        enum Event {
            Started(usize),
            Ended(usize, Result<JobOutcome, Error>),
            Left(usize),
            Note(String),
        }
        let (sender, receiver) = std::sync::mpsc::channel::<Event>();
        for _ in 0..concurrency.min(total) {
            let sender = sender.clone();
            let (work, next, stop) = (&work, &next, &stop);
            scope.spawn(move || {
                // A job that panics stops the queue too (the panic reaches the caller when
                // the scope ends).
                let _stop_on_panic = StopOnPanic(stop);
                let notes = sender.clone();
                let note = move |text: &str| drop(notes.send(Event::Note(text.into())));
                while !stop.load(std::sync::atomic::Ordering::SeqCst) {
                    let k = next.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
                    let Some((job, resolved)) = work.get(k) else { break };
                    if !resolved.done && resolved.outcome.duplicate_of.is_none() {
                        let _ = sender.send(Event::Started(k));
                    }
                    let stopped = || stop.load(std::sync::atomic::Ordering::SeqCst);
                    let result = match run_one(jobs_file, job, resolved, out, &note, &stopped) {
                        Ok(Some(outcome)) => Ok(outcome),
                        // The queue stopped while it waited: not run.
                        Ok(None) => {
                            let _ = sender.send(Event::Left(k));
                            break;
                        }
                        Err(e) => Err(e),
                    };
                    if result.is_err() {
                        stop.store(true, std::sync::atomic::Ordering::SeqCst);
                    }
                    if sender.send(Event::Ended(k, result)).is_err() {
                        break;
                    }
                }
            });
        }
        drop(sender);
        let mut done = 0;
        for event in receiver {
            match event {
                Event::Started(k) => progress(BatchProgress::Started { outcome: &work[k].1.outcome }),
                Event::Ended(k, Ok(outcome)) => {
                    done += 1;
                    progress(BatchProgress::Ended { done, total, outcome: &outcome });
                    finished[k] = Some(outcome);
                }
                Event::Ended(k, Err(e)) => {
                    progress(BatchProgress::Left { outcome: &work[k].1.outcome });
                    failures.push((k, e));
                }
                Event::Left(k) => progress(BatchProgress::Left { outcome: &work[k].1.outcome }),
                Event::Note(text) => warn(&text),
            }
        }
    });
    // Every job as it ended; one that never ended failed (its error is in `failures`),
    // never started, or was not the run's to make (skipped, a duplicate).
    let outcomes: Vec<JobOutcome> = finished
        .into_iter()
        .zip(&work)
        .enumerate()
        .map(|(k, (outcome, (_, resolved)))| {
            outcome.unwrap_or_else(|| {
                let mut outcome = resolved.outcome.clone();
                // A set already done (`skipped`) or another job's (`duplicate`) stays as
                // planned: it was marked `not run` though it was there.
                if failures.iter().any(|(j, _)| *j == k) {
                    outcome.status = JobStatus::Failed;
                } else if outcome.status == JobStatus::ToDo {
                    outcome.status = JobStatus::NotRun;
                }
                outcome
            })
        })
        .collect();
    let mut index = BatchIndex::new(jobs_file, shard, outcomes, other_sets, concurrency);
    // The sets it made, at its end: a set another run finished meanwhile (this run's job
    // skipped it) stays its maker's, whose entry an index written meanwhile may hold.
    let made =
        index.jobs.iter().filter(|j| j.status == JobStatus::Done).map(|j| j.manifest.clone()).collect::<Vec<_>>();
    let written = index.write_merged(out, shard, &made.iter().collect());
    // The earliest job's error, whichever failed first; the index's own failure with it.
    if let Some((_, e)) = failures.into_iter().min_by_key(|(k, _)| *k) {
        let index_error = written.err().map(Box::new);
        return Err(BatchError::Stopped { index: Box::new(index), index_error, source: Box::new(e) }.into());
    }
    written?;
    Ok(index)
}

/// A set a batch run made in the output folder: its jobs file (as recorded), the set's
/// manifest (relative to the folder) and the key it was made with.
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct OtherSet {
    pub jobs_file: String,
    pub manifest: PathBuf,
    pub key: String,
}

/// The largest index file a run reads back. An index lists at most `MAX_JOBS` jobs of a few
/// hundred bytes each (two relative paths, a 64-digit key: about 400 bytes for a built-in
/// preset's, so 40 MB for the most a run can hold) and the sets it carried from earlier
/// runs'; 256 MiB leaves room for long paths while a device, a FIFO or a planted huge file
/// is refused before anything is read (`text_file`): the read was unbounded, a FIFO hung the
/// run and /dev/zero took memory until the read failed and the index was skipped unseen.
const INDEX_MAX_BYTES: u64 = 256 << 20;

/// An index file's jobs file (as recorded) and every set it records: its jobs, under that
/// file, and the sets it carried from the index it replaced (`BatchIndex::other_sets`), under
/// theirs; None where there is none, or where the file is of another kind (a web page named
/// `index.json`: not a record; a run refuses to replace its own, `check_replaces_its_own`).
/// A FIFO, a device, a link, a file over `INDEX_MAX_BYTES`, or an index of ours that does
/// not parse (cut short, altered) is an error: each was skipped without a word, and with it
/// the record that keeps another jobs file's sets from being replaced.
fn read_index_file(path: &Path) -> Result<Option<(String, Vec<OtherSet>)>, BatchError> {
    use crate::text_file::{BoundedReadError, Links, read_bounded_bytes};
    #[derive(serde::Deserialize)]
    struct Listed {
        // A re-saved index may have lost it (`check_replaces_its_own` takes such a file for
        // an index still): its jobs are then no jobs file's.
        #[serde(default)]
        jobs_file: String,
        #[serde(default)]
        jobs: Vec<ListedJob>,
        #[serde(default)]
        other_sets: Vec<OtherSet>,
    }
    #[derive(serde::Deserialize)]
    struct ListedJob {
        manifest: PathBuf,
        key: String,
        #[serde(default)]
        status: String,
    }
    let refused = |reason: String| BatchError::Index { path: path.into(), reason };
    let text = match read_bounded_bytes(path, INDEX_MAX_BYTES, Links::Refuse) {
        Ok(text) => text,
        Err(BoundedReadError::Io(e)) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(refused(e.to_string())),
    };
    if text.trim_ascii().is_empty() || !crate::export::begins_as(&text, "batch index") {
        return Ok(None);
    }
    let json = text.strip_prefix(b"\xef\xbb\xbf").unwrap_or(&text);
    let Listed { jobs_file, jobs, other_sets } = serde_json::from_slice::<Listed>(json)
        .map_err(|e| refused(format!("it begins as one but does not parse: cut short or altered? ({e})")))?;
    // A job the run skipped (its set was there, made by whichever run made it) or left to
    // another job (a duplicate) does not make the set its file's: a run that skipped another
    // file's identical set took it over, and that file's own run was then refused (a
    // review). The run carries the maker's entry instead (`other_sets_to_carry`).
    let made =
        |job: &ListedJob| ![JobStatus::Skipped.word(), JobStatus::Duplicate.word()].contains(&job.status.as_str());
    let own = jobs.into_iter().filter(made).map(|job| OtherSet {
        jobs_file: jobs_file.clone(),
        manifest: job.manifest,
        key: job.key,
    });
    let sets = own.chain(other_sets).collect();
    Ok(Some((jobs_file, sets)))
}

/// Of the sets the index this run replaces records (`sets`, `read_index_file`), those for
/// this run's index to carry: without them, a third jobs file's run into the folder replaced the index, and a
/// later run of a fourth replaced the first's set from another preset of its name without
/// the refusal (a hostile-input sweep). Kept: a set still standing with its key (`job` in its
/// manifest) that none of this run's jobs makes (a job of this run that would replace another
/// file's set from another preset was refused in `plan`; one from the same preset makes it
/// this run's set; one that skips it leaves it its maker's), this jobs file's own earlier
/// sets too, where its jobs no longer name them (dropped, they were no one's, and another
/// preset of the name replaced them: a review).
/// `mine`: the sets this run makes (`run`'s `planned_sets`, as it starts) or made (its jobs
/// `done`, at its end).
fn other_sets_to_carry(out: &Path, sets: Vec<OtherSet>, mine: &std::collections::HashSet<&PathBuf>) -> Vec<OtherSet> {
    let mut carried: Vec<OtherSet> = Vec::new();
    for set in sets {
        if mine.contains(&set.manifest) || carried.iter().any(|c| c.manifest == set.manifest) {
            continue;
        }
        let standing = crate::export::read_set_manifest(&out.join(&set.manifest), crate::text_file::Links::Refuse);
        if standing.is_ok_and(|json| json["job"].as_str() == Some(set.key.as_str())) {
            carried.push(set);
        }
    }
    carried
}

/// Whether an index's recorded jobs file is `jobs_file` (`recorded_jobs_file`'s text, or
/// the same file).
fn is_this_jobs_file(recorded: &str, jobs_file: &Path) -> bool {
    recorded == recorded_jobs_file(jobs_file) || crate::export::same_path(Path::new(recorded), jobs_file)
}

/// The sets other jobs files' runs made in the output folder, as their indexes list them:
/// every index there (`index.json` and each shard's: a sharded run of a second jobs file
/// wrote over the first's set unseen, a review found), each set's manifest with every jobs
/// file and key an index lists it under (an older shard's index beside a newer run's: the
/// first read hid the entry of the set standing, and the set was replaced, a review).
struct OtherSets(std::collections::HashMap<PathBuf, Vec<(String, String)>>);

impl OtherSets {
    fn in_folder(out: &Path, jobs_file: &Path) -> Result<OtherSets, BatchError> {
        let mut sets = std::collections::HashMap::new();
        let names = std::fs::read_dir(out).into_iter().flatten().flatten().map(|e| e.file_name());
        for name in names.filter(|n| n.to_str().is_some_and(is_index_file_name)) {
            let Some((_, listed)) = read_index_file(&out.join(name))? else { continue };
            for set in listed.into_iter().filter(|set| !is_this_jobs_file(&set.jobs_file, jobs_file)) {
                sets.entry(set.manifest).or_insert_with(Vec::new).push((set.jobs_file, set.key));
            }
        }
        Ok(OtherSets(sets))
    }

    /// Refuses a job that would replace a set another jobs file's run made from another
    /// preset of the same name: an index lists the job's manifest, the set there is still
    /// the one that run made (its manifest's `job`), and its `preset_hash` is not this job's.
    /// A second jobs file naming another preset `vipera-berus` wrote over the first's set in
    /// the same folder, and the note said their sets stayed (a hostile-input sweep); within
    /// one jobs file such a clash is refused (`resolve_all`). The hash is all the check has:
    /// the same preset made by another version of the tool is replaced where its
    /// `preset_hash` is the same, and refused as another preset where the version's resolved
    /// presets hash differently.
    fn check(&self, out: &Path, r: &Resolved, place: JobPlace) -> Result<(), Error> {
        let manifest = &r.outcome.manifest;
        let Some(listed) = self.0.get(manifest) else { return Ok(()) };
        if r.done || r.outcome.duplicate_of.is_some() {
            return Ok(());
        }
        let Ok(standing) = crate::export::read_set_manifest(&out.join(manifest), crate::text_file::Links::Refuse)
        else {
            return Ok(());
        };
        // The run that made the set standing: the entry with its key.
        let made_by = listed.iter().find(|(_, key)| standing["job"].as_str() == Some(key.as_str()));
        let Some((jobs_file, _)) = made_by else { return Ok(()) };
        let their_hash = standing["preset_hash"].as_str().unwrap_or_default();
        if their_hash == r.preset_hash {
            return Ok(());
        }
        let message = format!(
            "would replace the set in {}, which a run of {jobs_file} made from another preset of that name \
             (its preset_hash {their_hash}, this job's {}; the folder's index records that run's sets): write this \
             batch into another folder, or remove that set's folder first",
            out.join(&r.outcome.folder).display(),
            r.preset_hash,
        );
        Err(BatchError::Invalid { place, message }.into())
    }
}

/// The jobs file as an index records it: its canonical path (as given where that fails), so
/// that a later run started from another folder finds it the same file. JSON holds text: a
/// path that is not UTF-8 has each byte outside UTF-8 written `\xNN` (a batch run in such a
/// folder failed with "internal error: index: path contains invalid UTF-8 characters", a
/// hostile-input sweep), and `run`'s note compares the same text.
fn recorded_jobs_file(jobs_file: &Path) -> String {
    let path = std::fs::canonicalize(jobs_file).unwrap_or_else(|_| jobs_file.into());
    let mut text = String::new();
    for chunk in path.as_os_str().as_encoded_bytes().utf8_chunks() {
        text.push_str(chunk.valid());
        for byte in chunk.invalid() {
            text.push_str(&format!("\\x{byte:02x}"));
        }
    }
    text
}

impl BatchIndex {
    fn new(
        jobs_file: &Path,
        shard: Shard,
        jobs: Vec<JobOutcome>,
        other_sets: Vec<OtherSet>,
        concurrency: usize,
    ) -> BatchIndex {
        BatchIndex {
            generator: "snakeskin".into(),
            generator_version: env!("CARGO_PKG_VERSION").into(),
            // The file itself, wherever a later run is started from (as given, it was relative
            // to this run's working folder, and a later run's note mistook it for another).
            jobs_file: recorded_jobs_file(jobs_file),
            shard: shard.to_string(),
            jobs,
            other_sets,
            concurrency,
        }
    }

    /// Writes the index as `write` does, under the lock of its name (`SetLock`), after
    /// carrying the sets that the index there now records and this one does not
    /// (`other_sets_to_carry`): two runs into one folder at once (which stays possible: the
    /// later skips the sets the earlier finishes) each wrote the whole index from what they
    /// read as they began, and the later dropped the other's record; the set so forgotten was
    /// then replaced by a third jobs file's preset of the same name (a hostile-input review).
    /// The lock is held for the read and the write alone; a run still writing after a second
    /// of tries is `BatchError::Busy`. Where no other run wrote meanwhile, nothing is added:
    /// the bytes are a lone run's. Returns the jobs file the replaced index recorded.
    fn write_merged(
        &mut self,
        out: &Path,
        shard: Shard,
        mine: &std::collections::HashSet<&PathBuf>,
    ) -> Result<Option<String>, Error> {
        let name = index_file_name(shard);
        let _lock = crate::export::SetLock::acquire(out, &name).map_err(|e| match e {
            crate::export::ExportError::Busy { .. } => {
                Error::from(BatchError::Busy { out: out.into(), lock: out.join(crate::export::lock_file_name(&name)) })
            }
            e => e.into(),
        })?;
        let (earlier_jobs_file, sets) = read_index_file(&out.join(&name))?.unzip();
        if let Some(sets) = sets {
            let listed: std::collections::HashSet<PathBuf> =
                self.other_sets.iter().map(|s| s.manifest.clone()).collect();
            let new = sets.into_iter().filter(|s| !listed.contains(&s.manifest)).collect();
            self.other_sets.extend(other_sets_to_carry(out, new, mine));
        }
        self.write(out, shard)?;
        Ok(earlier_jobs_file)
    }

    /// Writes the index to `out` (created if missing), replacing the one there.
    fn write(&self, out: &Path, shard: Shard) -> Result<(), Error> {
        let mut json = serde_json::to_vec_pretty(self).map_err(|e| Error::Internal(format!("index: {e}")))?;
        json.push(b'\n');
        // Noted, so a run that fails before anything is in it takes the folder away again
        // (a full disk failed the index's first write and left the new folder empty).
        crate::export::create_folder_noted(out)?;
        write_file_atomically(&out.join(index_file_name(shard)), json)?;
        Ok(())
    }
}

/// The shard's jobs, resolved and planned: what `run` runs and `list` shows.
struct Planned<'a> {
    mine: Vec<&'a Job>,
    resolved: Vec<Resolved>,
    /// The memory estimate of each job that will generate a set.
    estimates: Vec<u64>,
}

/// Every check a run makes before it writes anything: the output folder, the index's place,
/// every job's preset, size and output files, and (with `for_run`) its memory against
/// what this machine has available and its folder's writing (a probe file made and removed):
/// not for `list`, which writes nothing, and which a login node runs for a cluster's jobs (a
/// job too large for it was refused there).
fn plan<'a>(jobs_file: &Path, jobs: &'a [Job], out: &Path, shard: Shard, for_run: bool) -> Result<Planned<'a>, Error> {
    // The output folder (a file there is the user's mistake, as for `generate -o`) and the
    // index's place, before any job runs (a folder in the index's way would otherwise fail
    // the run after every job), and nothing created yet: a refused batch leaves no folder.
    crate::export::check_folder(out)?;
    crate::export::check_target(&out.join(index_file_name(shard)))?;
    // The files the run reads: its jobs file and every job's preset file (every shard's:
    // another shard's job may read a file this one would write), none of them an output.
    let mut seen = std::collections::HashSet::new();
    let preset_files =
        jobs.iter().filter(|j| seen.insert(j.preset.as_str())).filter_map(|j| crate::preset::input_file(&j.preset));
    let inputs = crate::export::Inputs::new(std::iter::once(jobs_file).chain(preset_files));
    inputs.check(&out.join(index_file_name(shard)))?;
    // A run replaces the index; `--list` writes nothing, and lists beside any file.
    if for_run {
        crate::export::check_replaces_its_own(&out.join(index_file_name(shard)), "batch index")?;
    }
    let (mine, resolved): (Vec<&'a Job>, Vec<Resolved>) =
        jobs.iter().zip(resolve_all(jobs_file, jobs, out, shard)?).filter(|(j, _)| shard.contains(j)).unzip();
    // `--list` too: it shows what a run would do.
    let others = OtherSets::in_folder(out, jobs_file)?;
    for (job, r) in mine.iter().zip(&resolved) {
        others.check(out, r, job.place(jobs_file, job.lines.preset))?;
    }
    let mut estimates = Vec::new();
    // A plan (the preset's graph, its memory estimate) is the same for every seed: jobs that
    // differ only in their seed share one (`Job::key` at seed 0 names the rest). Planned one
    // by one, a table of 100,000 seeds took minutes before anything ran or was listed,
    // most of it in the allocator.
    let mut planned_for: std::collections::HashMap<String, u64> = std::collections::HashMap::new();
    let mut probed = std::collections::HashSet::new();
    for (job, r) in mine.iter().zip(&resolved) {
        if !r.done && r.outcome.duplicate_of.is_none() {
            // A size refused (too tall, too large for memory) at the job's `sizes`; its output
            // at the job (the folder's name comes from all its keys).
            let planned = |line: Option<usize>, source: Error| BatchError::Planned {
                job: RunningJob {
                    place: job.place(jobs_file, line.or(job.lines.preset)),
                    seed: r.outcome.seed,
                    size: job.size,
                },
                source: Box::new(source),
            };
            let request = request(job, out, &r.outcome);
            let shape = job.key(&job.preset, 0);
            let estimate = match planned_for.get(&shape) {
                Some(estimate) => *estimate,
                None => {
                    let plan = if for_run { Plan::new(&request) } else { Plan::within_checked_budget(&request) }
                        .map_err(|e| planned(job.lines.sizes, e))?;
                    planned_for.insert(shape, plan.memory().estimate_bytes);
                    plan.memory().estimate_bytes
                }
            };
            // Its folder and files, as `Plan::run` checks them, but before any job has
            // written its set: a folder in a later job's way stopped the run after the
            // earlier jobs' sets were written. Nor any of them the jobs file or a preset.
            check_set_outputs(&request.out_dir, &r.outcome.preset, &r.files, &inputs)
                .map_err(|e| planned(job.lines.preset, e.into()))?;
            // And that its folder can be written (or made), each folder once: a read-only one
            // stopped the run when its job came, after the jobs before it.
            if for_run && let Some(file) = r.files.last() {
                crate::export::check_folder_writable(&request.out_dir, file, &mut probed)
                    .map_err(|e| planned(job.lines.preset, e.into()))?;
            }
            estimates.push(estimate);
        }
    }
    Ok(Planned { mine, resolved, estimates })
}

/// Sets the flag when the thread unwinds (`run`'s workers).
struct StopOnPanic<'a>(&'a std::sync::atomic::AtomicBool);

impl Drop for StopOnPanic<'_> {
    fn drop(&mut self) {
        if std::thread::panicking() {
            self.0.store(true, std::sync::atomic::Ordering::SeqCst);
        }
    }
}

/// The folder a jobs file's preset paths are relative to: the file's own, through any
/// symbolic links to it (a link `link.toml -> sub/jobs.toml` looked for `my.toml` beside the
/// link, not in `sub/`, while the run's index took both names for one jobs file: a sweep).
/// The path as given where it is no link, so messages keep the paths as the user wrote them.
fn jobs_folder(path: &Path) -> PathBuf {
    let mut file = path.to_path_buf();
    // As many links as the kernel follows (ELOOP past 40).
    for _ in 0..40 {
        match std::fs::read_link(&file) {
            Ok(target) => file = file.parent().unwrap_or(Path::new("")).join(target),
            Err(_) => break,
        }
    }
    file.parent().map_or_else(|| PathBuf::from("."), Path::to_path_buf)
}

/// One job: a duplicate's set is the earlier job's, a done job is left as it is, any other
/// is generated (after waiting for another run that is making it, and skipped if that run
/// did). None where the queue stopped (`stopped`) while it waited.
fn run_one(
    jobs_file: &Path,
    job: &Job,
    resolved: &Resolved,
    out: &Path,
    waiting: &dyn Fn(&str),
    stopped: &dyn Fn() -> bool,
) -> Result<Option<JobOutcome>, Error> {
    let mut outcome = resolved.outcome.clone();
    // Another run into the same folder may have finished the set since this one was planned:
    // looked for again (of two batches over the same jobs, the second generated again every
    // set the first finished after the second was planned; the QA review), and under the
    // set's lock below where the manifest changes meanwhile.
    let done = resolved.done
        || (outcome.duplicate_of.is_none() && is_done(&out.join(&outcome.manifest), &outcome.key, &resolved.files));
    if outcome.duplicate_of.is_some() {
        // Its set is the earlier job's (in this shard or another).
        return Ok(Some(outcome));
    }
    if done {
        outcome.status = JobStatus::Skipped;
        let_go_of_a_left_lock(&out.join(&outcome.folder), &outcome.preset);
        return Ok(Some(outcome));
    }
    let running = RunningJob { place: job.place(jobs_file, job.lines.preset), seed: outcome.seed, size: job.size };
    let failed = |source: Error| BatchError::Failed { job: running.clone(), source: Box::new(source) };
    let manifest = out.join(&outcome.manifest);
    // Checked against the available memory with the other jobs when the run was planned
    // (`fitting_concurrency`); the jobs running beside this one hold part of it now.
    let plan = Plan::within_checked_budget(&request(job, out, &outcome)).map_err(failed)?;
    // The preset is read again here: an edit since the plan would write a set of the edited
    // preset under the planned key, which a later run, the edit undone, took as done.
    let loaded = plan.loaded();
    if job.key(&loaded.content_hash, loaded.preset.seed) != outcome.key {
        return Err(BatchError::Changed { job: running.clone() }.into());
    }
    // Another run into the folder (a shard beside a whole run, a second jobs file sharing
    // sets) that holds the set's lock is making it: waited for, said once. (Failed, the job
    // stopped the whole queue: of two batches over the same 3K sets started together, the
    // second made none.)
    let folder = out.join(&outcome.folder);
    let mut say = || {
        let lock = folder.join(crate::export::lock_file_name(&outcome.preset));
        waiting(&format!(
            "note: {running}: another snakeskin run is writing {} (it holds {}); waiting for it",
            folder.display(),
            lock.display()
        ))
    };
    let lock = match plan.lock_set_waiting(&mut say, stopped) {
        Ok(lock) => lock,
        Err(Error::Export(crate::export::ExportError::Busy { .. })) if stopped() => return Ok(None),
        Err(e) => return Err(failed(e).into()),
    };
    // Under the lock, what another run did since the plan (`Resolved::found`), whether this
    // job waited for it, took the lock the moment it let go, or started after it had gone:
    // a set it made for this job is skipped; another preset's set there is refused, not
    // written over. (Compared with the manifest as the job started, a set made while the
    // jobs before it ran was taken for the old one: the review.)
    let now = manifest_identity(&manifest);
    if now != resolved.found {
        if is_done(&manifest, &outcome.key, &resolved.files) {
            outcome.status = JobStatus::Skipped;
            return Ok(Some(outcome));
        }
        if now.is_some() {
            return Err(BatchError::MadeMeanwhile { job: running.clone(), manifest }.into());
        }
    }
    let report = plan.run_locked(lock, &|_, _| {}).map_err(failed)?;
    outcome.kept = report.kept;
    outcome.status = JobStatus::Done;
    Ok(Some(outcome))
}

/// A run killed after committing a set but before removing its lock file left an empty
/// `.NAME.lock` behind: taking the lock and letting it go removes it (and leaves the set
/// alone; a set some other run holds is left as it is).
fn let_go_of_a_left_lock(folder: &Path, name: &str) {
    let _ = crate::export::SetLock::acquire(folder, name);
}

/// A manifest's identity (`export::file_identity`).
type ManifestIdentity = crate::export::FileIdentity;

/// `export::file_identity` of the manifest itself (a run never writes a link).
fn manifest_identity(path: &Path) -> Option<ManifestIdentity> {
    crate::export::file_identity(path, crate::text_file::Links::Refuse)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn jobs(text: &str) -> Result<Vec<Job>, BatchError> {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("jobs.toml");
        std::fs::write(&path, text).unwrap();
        load_jobs(&path)
    }

    #[test]
    fn jobs_run_at_once_only_as_far_as_the_largest_fit_in_memory_together() {
        // Estimates 5, 4, 3, 1 (any order): 2 at once need 9, 3 need 12.
        let estimates = vec![3, 5, 1, 4];
        assert_eq!(fitting_concurrency(2, estimates.clone(), 100), 2);
        assert_eq!(fitting_concurrency(8, estimates.clone(), 100), 4);
        assert_eq!(fitting_concurrency(3, estimates.clone(), 11), 2);
        assert_eq!(fitting_concurrency(3, estimates.clone(), 9), 2);
        assert_eq!(fitting_concurrency(3, estimates.clone(), 8), 1);
        // A job that does not fit alone was refused when planned; the run still takes one.
        assert_eq!(fitting_concurrency(2, estimates, 2), 1);
        assert_eq!(fitting_concurrency(2, vec![], 0), 1);
        assert_eq!(fitting_concurrency(0, vec![1, 1], 10), 1);
    }

    #[test]
    fn every_combination_of_seeds_and_sizes_is_one_job() {
        let list = jobs("[[job]]\npreset = \"natrix-natrix\"\nseeds = [1, 2, 3]\nsizes = [64, 128]\n\n[[job]]\npreset = \"boa-constrictor\"\npack = \"unreal\"\n").unwrap();
        assert_eq!(list.len(), 7);
        assert_eq!(list.iter().map(|j| j.index).collect::<Vec<_>>(), (0..7).collect::<Vec<_>>());
        assert_eq!(list[6].pack, Some(Pack::Unreal));
        assert_eq!(list[6].size, DEFAULT_SIZE);
        // Shards partition the jobs.
        let shards: Vec<Shard> = (0..3).map(|k| Shard { index: k, count: 3 }).collect();
        for job in &list {
            assert_eq!(shards.iter().filter(|s| s.contains(job)).count(), 1);
        }
    }

    /// A preset path is read from the jobs file's folder by `generate`'s rule: `boa.TOML`
    /// (not `.toml`) beside the jobs file was looked for in the working folder instead.
    #[test]
    fn preset_paths_are_relative_to_the_jobs_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("jobs.toml");
        std::fs::write(dir.path().join("boa.TOML"), "").unwrap();
        std::fs::write(dir.path().join("plain"), "").unwrap();
        let presets = ["boa.TOML", "plain", "sub/x.toml", "natrix-natrix", "missing"];
        let text: String = presets.iter().map(|p| format!("[[job]]\npreset = {p:?}\n")).collect();
        std::fs::write(&path, text).unwrap();
        let found: Vec<String> = load_jobs(&path).unwrap().into_iter().map(|j| j.preset).collect();
        let beside = |name: &str| dir.path().join(name).to_string_lossy().into_owned();
        assert_eq!(
            found,
            [beside("boa.TOML"), beside("plain"), beside("sub/x.toml"), "natrix-natrix".into(), "missing".into()]
        );
    }

    #[test]
    fn bad_jobs_files_name_the_line_or_the_job() {
        let e = jobs("[[job]]\npreset = \"natrix-natrix\"\nsize = [64]\n").unwrap_err().to_string();
        assert!(e.contains(":3:") && e.contains("size"), "{e}");
        let e = jobs("[[job]]\npreset = \"natrix-natrix\"\nsizes = [8]\n").unwrap_err().to_string();
        assert!(e.contains("jobs.toml:3: [[job]] 1") && e.contains("size 8"), "{e}");
        let e = jobs("[[job]]\npreset = \"a\"\npack = \"godot\"\n").unwrap_err().to_string();
        assert!(e.contains("unreal"), "{e}");
        let e = jobs("[[job]]\npreset = \"a\"\npack = \"unreal\"\nformat = \"exr\"\n").unwrap_err().to_string();
        assert!(e.contains("leave out maps and format"), "{e}");
        assert!(matches!(jobs("").unwrap_err(), BatchError::Empty { .. }));
        let many = format!(
            "[[job]]\npreset = \"a\"\nseeds = [{}]\nsizes = [64, 128]\n",
            (0..60_000).map(|s| s.to_string()).collect::<Vec<_>>().join(",")
        );
        assert!(matches!(jobs(&many).unwrap_err(), BatchError::TooMany { .. }));
        for bad in ["4/4", "1", "a/2", "0/0"] {
            assert!(bad.parse::<Shard>().is_err(), "{bad}");
        }
        assert_eq!("3/4".parse::<Shard>().unwrap(), Shard { index: 3, count: 4 });
    }

    /// Two entries of a `set` table that reach one key are refused, naming both; one of the
    /// two values was lost without a word (the QA review). Negative controls: entries that
    /// write different keys of one table.
    #[test]
    fn a_key_set_twice_in_a_set_table_is_refused() {
        let job = |set: &str| jobs(&format!("[[job]]\npreset = \"a\"\nseeds = [1]\nset = {set}\n"));
        for (set, says) in [
            (
                r#"{ "scales.rows" = 23, scales = { rows = 25 } }"#,
                "`scales.rows` is set by two entries, `scales` and `scales.rows`",
            ),
            (r#"{ scales = 5, "scales.rows" = 3 }"#, "`scales.rows` is set by two entries, `scales` and `scales.rows`"),
            (r#"{ "pattern.0" = { kind = "spots" }, "pattern.0.kind" = "bands" }"#, "`pattern.0.kind` is set by two"),
            (r#"{ pattern = [{ kind = "spots" }], "pattern.0.kind" = "bands" }"#, "`pattern.0.kind` is set by two"),
            (r#"{ sources = ["a", "b"], "sources.1" = "c" }"#, "`sources.1` is set by two"),
        ] {
            let e = job(set).unwrap_err().to_string();
            assert!(e.contains("jobs.toml:4: [[job]] 1 (a): ") && e.contains(says), "{set}: {e}");
        }
        for set in [
            r#"{ "scales.rows" = 23, scales = { keel = 0.5 } }"#,
            r#"{ "pattern.0.kind" = "spots", "pattern.1.kind" = "bands", "pattern.10.kind" = "x" }"#,
            r##"{ pattern = [{ color = "#101010" }], "pattern.0.kind" = "spots" }"##,
            r#"{ scales = {}, "scales.rows" = 3 }"#,
        ] {
            assert!(job(set).is_ok(), "{set}: {:?}", job(set).err());
        }
    }

    /// A `set` seed beside `seeds` is refused: the seeds replace it, and it was lost without
    /// a word. Alone it is the job's seed (negative control).
    #[test]
    fn a_set_seed_beside_seeds_is_refused() {
        let e = jobs("[[job]]\npreset = \"a\"\nseeds = [1]\nset = { seed = 5 }\n").unwrap_err().to_string();
        assert!(e.contains("jobs.toml:4: [[job]] 1 (a): ") && e.contains("beside seeds"), "{e}");
        let alone = jobs("[[job]]\npreset = \"a\"\nset = { seed = 5 }\n").unwrap();
        assert_eq!(alone[0].overrides, [("seed".to_string(), "5".to_string())]);
    }

    #[test]
    fn index_file_names_are_the_names_index_file_name_writes() {
        for shard in [Shard::ALL, Shard { index: 0, count: 2 }, Shard { index: 11, count: 12 }] {
            assert!(is_index_file_name(&index_file_name(shard)), "{shard:?}");
        }
        let not_written =
            ["index.json.toml", "index.shard-1-of-2.json.toml", "index.shard-01-of-2.json", "index2.json"];
        for name in not_written.into_iter().chain(["index.shard-0-of-1.json", "index.shard-1-2-of-3.json", "x.json"]) {
            assert!(!is_index_file_name(name), "{name}");
        }
    }
}
