//! From a preset argument (a path or a built-in name) and `--set` overrides to a validated
//! `Preset`, with errors that point at the file, line and key.
//!
//! Order: read → parse the file alone (so syntax, type and unknown-key errors carry the
//! file's line and column) → apply overrides to the TOML tree and parse again (errors name
//! the `--set` argument) → range-check (errors name the key, with its line when it came
//! from the file).

use std::path::{Path, PathBuf};

use serde::Deserialize;

use super::error::{LocatedProblem, Location, PresetError};
use super::library;
use super::schema::Preset;
use super::validate::validate;
use crate::toml_text;

/// Preset text and where it came from.
#[derive(Debug, Clone)]
pub struct PresetSource {
    /// Output file stem: the file stem or the built-in name.
    pub name: String,
    /// What error messages call the file.
    pub display: String,
    pub text: String,
}

/// A validated preset with its provenance.
#[derive(Debug, Clone)]
pub struct LoadedPreset {
    pub name: String,
    pub preset: Preset,
    /// FNV-1a 64 of the resolved preset (after overrides), as 16 hex digits.
    pub content_hash: String,
    /// Colour keys the stack cannot show, clamped to its limit (`visible`): callers report
    /// them, the manifest lists them.
    pub clamped_colours: Vec<super::visible::ClampedColour>,
    /// Keys that load but do not do what they seem (`validate::warnings`: where the layered
    /// model is off from the physics of the stack, a film centred below half its spread),
    /// each with the key's line.
    pub warned: Vec<LocatedProblem>,
    /// The file sets no key (empty, comments or empty tables only) and no `--set` gave one:
    /// every key takes its default, the same green snake whatever the
    /// file was meant to say, which a user who saved the wrong file, or one the editor had
    /// not yet written, should hear of.
    pub sets_no_key: bool,
    /// The overrides as given (`--set`, a jobs file's `set`; `(KEY, VALUE)`, in order): the
    /// manifest records them, so a set says what made it beyond its preset.
    pub overrides: Vec<(String, String)>,
    /// The warnings of overrides whose values later ones replaced (`lost_overrides`).
    lost_overrides: Vec<String>,
}

impl LoadedPreset {
    /// The warnings every command prints for the preset (`preset`: its file or name, as
    /// given), one line each: colours clamped to what the stack can show, and the keys
    /// `warned` of, each placed as a problem is (`preset::place`; `overrides` names the
    /// overrides: `preset::SET_FLAG`, or a jobs file's `set`).
    pub fn warnings(&self, preset: &str, overrides: &str) -> Vec<String> {
        let clamped = self.clamped_colours.iter().map(|c| c.message(preset, overrides));
        let warned = self.warned.iter().map(|p| {
            let place = super::place(preset, p.line, p.overridden, overrides);
            format!("warning: {place}: {}{} = {}", p.key, p.default_note(), p.message)
        });
        // On one line: a jobs file names its presets (a folder name with a newline).
        let preset = &crate::toml_text::one_line(preset);
        let empty = self.sets_no_key.then(|| {
            format!(
                "warning: {preset}: the file sets no key: every key takes its default (`snakeskin presets show NAME` \
                 prints a whole preset to start from)"
            )
        });
        empty
            .into_iter()
            .chain(clamped)
            .chain(warned)
            .chain(self.lost_overrides.iter().cloned())
            .chain(self.seed_not_used())
            .collect()
    }

    /// A `--set seed=` that `--seed` overrode (`parse_with_seed`), said as a repeated key is:
    /// `--seed 5 --set seed=6` ran silently with seed 5, its manifest listing the override
    /// beside it (a hostile-input sweep).
    fn seed_not_used(&self) -> Option<String> {
        let (_, value) = self.overrides.iter().rev().find(|(key, _)| key == "seed")?;
        let seed = self.preset.seed;
        (seed_override(value).ok()? != seed)
            .then(|| format!("warning: --set seed={value} is not used: --seed {seed} overrides it"))
    }
}

/// One warning for each override (`--set`) whose value, somewhere, a later one replaced:
/// `replaced[i]` is where override i put values whole (`merge`, in the order applied), so a
/// key i wrote (`toml_text::written_keys` of what it put there; the place itself where that
/// is an empty table or list) at or inside a place a later one put a value whole is lost.
/// Counted on the merge's own places, a table over a list replacing it whole and a list a
/// key inside it was set in (both silent before: a hostile-input sweep, two reviews). The
/// later override named is the last to replace that key, the one used. One key given more
/// than once as a plain value says so once (`--set a=1 --set a=2`); the seed, which does not
/// go into the table, is counted apart, where `--seed` does not override it
/// (`seed_not_used`). A batch job's `set` refuses such pairs (`batch::set_twice`).
fn lost_overrides(
    given: &[(String, String)],
    applied: &[(String, String)],
    replaced: &[Vec<String>],
    seed_flag_wins: bool,
) -> Vec<String> {
    let mut warnings: Vec<String> = Vec::new();
    let seeds: Vec<&String> = given.iter().filter(|(k, _)| k == "seed").map(|(_, v)| v).collect();
    if let (false, [_, .., last]) = (seed_flag_wins, seeds.as_slice()) {
        warnings.push(format!("warning: --set seed is given {} times: the last, seed={last}, is used", seeds.len()));
    }
    // Each value parsed once (it was, to be applied: a value that does not parse was refused).
    let parsed: Vec<Option<toml::Value>> = applied.iter().map(|(_, value)| override_value(value).ok()).collect();
    // What each override wrote: the keys of the values it put at each of its places.
    let wrote: Vec<Vec<String>> = applied
        .iter()
        .zip(replaced)
        .zip(&parsed)
        .map(|(((key, _), places), value)| {
            places
                .iter()
                .flat_map(|place| {
                    let inside = place.strip_prefix(key.as_str()).unwrap_or("").split('.').filter(|s| !s.is_empty());
                    let put = inside.fold(value.as_ref(), |v, k| v.and_then(|v| v.get(k)));
                    let keys = put.map(|v| toml_text::written_keys(place, v)).unwrap_or_default();
                    if keys.is_empty() { vec![place.clone()] } else { keys }
                })
                .collect()
        })
        .collect();
    let plain = |i: usize| !matches!(parsed[i], Some(toml::Value::Table(_)));
    for (i, (a, value)) in applied.iter().enumerate() {
        // Each key of it a later override replaced, under the last to replace it, in order.
        let mut lost: Vec<(usize, Vec<&String>)> = Vec::new();
        for x in &wrote[i] {
            let last = (i + 1..applied.len()).rev().find(|&j| replaced[j].iter().any(|r| toml_text::key_within(x, r)));
            match (last, lost.iter_mut().find(|(j, _)| Some(*j) == last)) {
                (Some(_), Some((_, keys))) => keys.push(x),
                (Some(j), None) => lost.push((j, vec![x])),
                (None, _) => {}
            }
        }
        for (j, keys) in lost {
            let (b, used) = &applied[j];
            let warning = if a == b && plain(i) && plain(j) {
                let times = applied.iter().enumerate().filter(|(k, (other, _))| other == a && plain(*k)).count();
                format!("warning: --set {a} is given {times} times: the last, {b}={used}, is used")
            } else {
                let (names, it) = (keys.iter().map(|k| format!("`{k}`")).collect::<Vec<_>>(), ["it", "them"]);
                let it = it[(names.len() > 1) as usize];
                format!(
                    "warning: --set {a}={value} is not used for {}: the later --set {b}={used} sets {it} again",
                    names.join(", ")
                )
            };
            if !warnings.contains(&warning) {
                warnings.push(warning);
            }
        }
    }
    warnings
}

/// The largest preset file accepted, in bytes. Built-in presets are 1–8 KiB; a megabyte is
/// far beyond any real preset and bounds what `generate /dev/zero`-like input can cost.
pub const MAX_PRESET_BYTES: u64 = 1 << 20;

/// Whether a preset argument, as `written`, names the file at `path` (the argument itself,
/// or a jobs file's entry joined to its folder) rather than a built-in preset: a name ending
/// in `.toml`, anything but a folder that exists there, or a path with a `/` that is no
/// folder (no built-in's name has one: `./my-snake` missing said "not a .toml file and not a
/// built-in preset", where the file's error was meant) — but never a built-in preset's
/// exact name, which is the built-in wherever it is written (`./NAME` names a file of that
/// name). A folder never is: a set's folder is named after its preset, so `generate
/// natrix-natrix -o natrix-natrix` run twice (and a batch whose jobs file lies in its
/// output folder) read the folder as the preset; and a file named like a built-in (a
/// gallery written as `-o natrix-natrix`) was read, silently, instead of the built-in.
pub fn names_a_file(written: &str, path: &Path) -> bool {
    library::get(written).is_none()
        && (path.to_string_lossy().ends_with(".toml")
            || std::fs::metadata(path).is_ok_and(|m| !m.is_dir())
            || (written.contains('/') && !path.is_dir()))
}

/// The file a PRESET argument reads (`read_source`), or None for a built-in preset: what no
/// output of the command may be written over (`export::check_not_an_input`).
pub fn input_file(spec: &str) -> Option<&Path> {
    let path = Path::new(spec);
    names_a_file(spec, path).then_some(path)
}

/// Resolves a PRESET argument: a file (`names_a_file`), or else a built-in preset name.
pub fn read_source(spec: &str) -> Result<PresetSource, PresetError> {
    read_source_beside(spec, Path::new(""))
}

/// `read_source` for a name written in a file in `folder` (a jobs file's entries, resolved
/// against its folder): an unknown name's `NAME.toml` is looked for there.
pub fn read_source_beside(spec: &str, folder: &Path) -> Result<PresetSource, PresetError> {
    let path = Path::new(spec);
    if names_a_file(spec, path) {
        // The set's files are named after it (`--set` refuses control characters too).
        let stem = path.file_stem().map(|s| s.to_string_lossy()).unwrap_or_default();
        if let Some(what) = crate::export::unfit_for_file_names(&stem) {
            return Err(PresetError::FileName { path: path.into(), what });
        }
        let text = read_bounded(path)?;
        // The set's files are named after it: a hidden name (`.toml`) would hide them.
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .filter(|s| !s.is_empty() && !s.starts_with('.'))
            .unwrap_or_else(|| "preset".into());
        return Ok(PresetSource { name, display: spec.to_string(), text });
    }
    match library::get(spec) {
        Some(text) => {
            Ok(PresetSource { name: spec.into(), display: format!("built-in preset {spec}"), text: text.into() })
        }
        None => {
            // `my-snake` beside my-snake.toml (as `presets show NAME > my-snake.toml` writes
            // it): a file is read only by a name that says so.
            // A name with a `/` is a path resolved already (a jobs file's entries are joined
            // to its folder: `batch::load_jobs`); a bare name is looked for in `folder`.
            let beside = |name: &str| if spec.contains('/') { PathBuf::from(name) } else { folder.join(name) };
            let file = format!("{spec}.toml");
            let suggestion = if !spec.is_empty() && beside(&file).is_file() {
                format!("; to read the file {file}, give its name with .toml")
            } else if !spec.is_empty() && beside(spec).is_dir() {
                // `graph /tmp` said only that it was no preset, where `graph d.toml` (a
                // folder) said it was a folder.
                format!("; {spec} is a folder: name a .toml file in it")
            } else {
                library::suggest(spec).map(|n| format!("; did you mean {n}?")).unwrap_or_default()
            };
            Err(PresetError::UnknownPreset { name: spec.into(), suggestion, available: library::names().join(", ") })
        }
    }
}

/// Reads a preset file: a regular file of at most `MAX_PRESET_BYTES`, in UTF-8
/// (`text_file::read_bounded`: neither a device like /dev/zero nor a file that grows while
/// it is read can exhaust memory).
fn read_bounded(path: &Path) -> Result<String, PresetError> {
    use crate::text_file::{BoundedReadError, read_bounded};
    read_bounded(path, MAX_PRESET_BYTES).map_err(|e| match e {
        BoundedReadError::Io(source) => {
            // `natrix-natrix.toml` where no such file is: the built-in preset was likely meant
            // (a built-in's name is written without `.toml`).
            let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
            let hint = if source.kind() == std::io::ErrorKind::NotFound && library::get(&stem).is_some() {
                format!("; to use the built-in preset {stem}, give its name without a path or .toml")
            } else {
                String::new()
            };
            PresetError::Read { path: path.into(), source, hint }
        }
        BoundedReadError::NotAFile(kind) => PresetError::NotAFile { path: path.into(), kind },
        BoundedReadError::TooLarge(size) => PresetError::TooLarge { path: path.into(), size, limit: MAX_PRESET_BYTES },
    })
}

/// Loads a preset argument (a path or a built-in name) with `--set` overrides and an optional
/// seed: read, parse, validate.
pub fn load(spec: &str, overrides: &[(String, String)], seed: Option<u64>) -> Result<LoadedPreset, PresetError> {
    parse_with_seed(&read_source(spec)?, overrides, seed)
}

/// `load` of a name written in a file in `folder` (`read_source_beside`).
pub fn load_beside(
    spec: &str,
    folder: &Path,
    overrides: &[(String, String)],
    seed: Option<u64>,
) -> Result<LoadedPreset, PresetError> {
    parse_with_seed(&read_source_beside(spec, folder)?, overrides, seed)
}

/// Parses and validates; `overrides` are `(dotted.key, toml value text)` pairs.
pub fn parse(source: &PresetSource, overrides: &[(String, String)]) -> Result<LoadedPreset, PresetError> {
    parse_with_seed(source, overrides, None)
}

/// `parse`, then the seed replaced by `seed` when given. The seed is set on the parsed
/// preset, not written into the TOML, and read as a u64 wherever it is written, so that a
/// seed beyond TOML's integers (2^63 - 1) or the range (`ranges::SEED_MAX`) is refused by
/// the range check with the key's range, not by the reader in its own words. So a `seed`
/// override is read here (`seed_override`; `seed` wins over it, as `--seed` over `--set
/// seed=`), and the file's seed stays out of the table the other overrides go into: a file's
/// seed above 2^63 - 1 parses alone, and with an override made the table's parse fail ("u64
/// value was too large").
pub fn parse_with_seed(
    source: &PresetSource,
    overrides: &[(String, String)],
    seed: Option<u64>,
) -> Result<LoadedPreset, PresetError> {
    let file_preset: Preset = toml::from_str(&source.text).map_err(|e| parse_error(source, &e))?;
    if let Some(underflow) = toml_text::underflowing_float(&source.text) {
        return Err(located_error(source, underflow));
    }
    let file_seed = file_preset.seed;
    let overrides_given = overrides;
    let (seed_overrides, overrides): (Vec<_>, Vec<_>) = overrides.iter().cloned().partition(|(key, _)| key == "seed");
    let overridden_seed = match seed_overrides.last() {
        Some((_, value)) => Some(seed_override(value)?),
        None => None,
    };
    let seed = seed.or(overridden_seed);
    let overrides = overrides.as_slice();
    // Each override's places, where it put a value whole (`merge`; `lost_overrides`).
    let mut replaced: Vec<Vec<String>> = Vec::new();
    let preset = if overrides.is_empty() {
        file_preset
    } else {
        let file_table = toml::from_str::<WithoutSeed>(&source.text).map_err(|e| parse_error(source, &e))?.rest;
        let mut table = file_table.clone();
        for (key, value) in overrides {
            let mut places = Vec::new();
            apply_override(&mut table, key, value, &mut places)?;
            replaced.push(places);
        }
        Preset::deserialize(toml::Value::Table(table)).map_err(|e| {
            // Name the one override that makes this error on its own, where one does (a
            // wrong type); otherwise (a new layer missing a key) all of them.
            let alone = |(key, value): &&(String, String)| {
                let mut table = file_table.clone();
                apply_override(&mut table, key, value, &mut Vec::new()).is_ok()
                    && Preset::deserialize(toml::Value::Table(table)).is_err_and(|a| a.message() == e.message())
            };
            let named: Vec<&(String, String)> = match overrides.iter().find(alone) {
                Some(culprit) => vec![culprit],
                None => overrides.iter().collect(),
            };
            let message = toml_text::in_plain_words(e.message());
            let message = match named.as_slice() {
                [(key, _)] => in_key_range(key, &message, true).unwrap_or(message),
                _ => message,
            };
            let hint = named.iter().find_map(|(key, _)| override_required_key_hint(key, &message));
            let message = format!("{message}{}", hint.unwrap_or_default());
            PresetError::Override {
                argument: named.iter().map(|(k, v)| format!("{k}={v}")).collect::<Vec<_>>().join(" "),
                message,
            }
        })?
    };

    let mut preset = preset;
    preset.seed = seed.unwrap_or(file_seed);
    // A key an override wrote, or one inside a value it put whole (an inline table in place
    // of the file's layers), has no line in the file; the file is parsed for lines once, not
    // once per problem (thousands of them took minutes).
    let under_written = |key: &str| replaced.iter().flatten().any(|k| toml_text::key_within(key, k));
    // The seed's overrides are not among `overrides` (above): a seed given by `--seed` or
    // `--set seed=` has no line either.
    let seed_given = seed.is_some();
    let overridden = |key: &str| {
        (seed_given && key == "seed")
            || under_written(key)
            // Layer 0 may be written as a single `[pattern]` table, which `--set pattern.kind=`
            // and `--set 'pattern={..}'` write: problems name its keys `pattern.0.KEY`.
            || key.strip_prefix("pattern.0.").is_some_and(|rest| under_written(&format!("pattern.{rest}")))
    };
    let problems = validate(&preset, &overridden);
    let key_lines = std::cell::LazyCell::new(|| toml_text::KeyLines::new(&source.text));
    // A key's line in the file: none for a key an override wrote (or one not in the file).
    let line_of = |key: &str| if overridden(key) { None } else { key_lines.line(key) };
    let locate = |p: super::validate::Problem| {
        if p.message.starts_with(super::validate::MISSING) {
            // An absent key is placed at its table (`[[pattern]]`), or at the override that
            // made the table (`--set pattern.0.kind=spots` on a preset without layers).
            let table = p.key.rsplit_once('.').map_or("", |(table, _)| table);
            let line = line_of(table);
            return LocatedProblem { line, overridden: line.is_none(), default: false, key: p.key, message: p.message };
        }
        let (line, written_by_override) = (line_of(&p.key), overridden(&p.key));
        let default = line.is_none() && !written_by_override;
        // A key at its default has no line; a check across two keys is placed at the other's,
        // or is the override's where an override wrote the other (a jobs file's `set`
        // naming `amount` for spots at their default size: an independent review).
        let (line, overridden) = match p.second_key.as_deref() {
            Some(second) if default => (line_of(second), overridden(second)),
            _ => (line, written_by_override),
        };
        LocatedProblem { line, overridden, default, key: p.key, message: p.message }
    };
    if !problems.is_empty() {
        let located = problems.into_iter().map(locate).collect();
        return Err(PresetError::Invalid { file: source.display.clone(), problems: located });
    }
    let mut clamped_colours = super::visible::clamp_to_visible(&mut preset);
    for c in &mut clamped_colours {
        c.line = line_of(&c.key);
        c.overridden = overridden(&c.key);
        c.default = c.line.is_none() && !c.overridden;
    }
    let warned = super::validate::warnings(&preset).into_iter().map(locate).collect();
    let canonical = canonical_text(&preset);
    // Tables without keys (`[scales]` alone) set nothing either; a seed (`--seed`, a jobs
    // file's `seeds`) still draws the default snake.
    fn sets_nothing(table: &toml::Table) -> bool {
        table.values().all(|v| v.as_table().is_some_and(sets_nothing))
    }
    let sets_no_key =
        overrides.is_empty() && toml::from_str::<toml::Table>(&source.text).is_ok_and(|table| sets_nothing(&table));
    Ok(LoadedPreset {
        name: source.name.clone(),
        preset,
        content_hash: format!("{:016x}", crate::ops::hash::fnv1a64(canonical.as_bytes())),
        clamped_colours,
        warned,
        sets_no_key,
        overrides: overrides_given.to_vec(),
        lost_overrides: lost_overrides(
            overrides_given,
            overrides,
            &replaced,
            // `--seed` given, other than the overrides' last (`seed_not_used` says so).
            seed.is_some() && overridden_seed != seed,
        ),
    })
}

/// A preset file's table without its `seed`, which may lie beyond TOML's integers (and so
/// beyond `toml::Value`'s); `parse_with_seed` sets the seed on the parsed preset.
#[derive(Deserialize)]
struct WithoutSeed {
    #[serde(default, rename = "seed")]
    _seed: Option<serde::de::IgnoredAny>,
    #[serde(flatten)]
    rest: toml::Table,
}

/// A seed as written on the command line, by `--seed` or `--set seed=`, which take the same
/// spellings: decimal digits (leading zeros and numbers beyond TOML's 2^63 − 1 included, up
/// to 2^64 − 1) or one TOML integer (`0x10`, `0o20`, `0b10000`, `1_000`, `+16`). `None` for
/// anything else; the caller checks the seed's range. (`--seed` took decimal digits only and
/// `--set seed=` TOML only: `0x10` was refused by one and `0016` by the other.)
pub fn parse_seed_text(text: &str) -> Option<u64> {
    let word = text.trim();
    if !word.is_empty() && word.bytes().all(|b| b.is_ascii_digit()) {
        return word.parse::<u64>().ok();
    }
    match toml::from_str::<toml::Table>(&format!("v = {word}")) {
        Ok(table) if table.len() == 1 => match table.get("v") {
            Some(toml::Value::Integer(i)) => u64::try_from(*i).ok(),
            _ => None,
        },
        _ => None,
    }
}

/// The value of `--set seed=VALUE` (`parse_seed_text`); the range check then refuses what lies
/// beyond the seed's range.
fn seed_override(value: &str) -> Result<u64, PresetError> {
    if value.trim().is_empty() {
        return Err(PresetError::Override {
            argument: format!("seed={value}"),
            message: format!("the value is empty: write a whole number in {}", super::validate::seed_range_words()),
        });
    }
    parse_seed_text(value).ok_or_else(|| PresetError::Override {
        argument: format!("seed={value}"),
        // With the value: a whole number past the range was called "not a whole number".
        message: format!(
            "the seed must be a whole number in {}, got {}",
            super::validate::seed_range_words(),
            value.trim()
        ),
    })
}

/// The resolved preset as TOML, what `content_hash` hashes. Only a validated preset is
/// hashed, and its seed (at most 2^53 - 1) is a TOML integer.
fn canonical_text(preset: &Preset) -> String {
    toml::to_string(preset).expect("a validated preset is TOML: its seed is within TOML's integers")
}

fn parse_error(source: &PresetSource, error: &toml::de::Error) -> PresetError {
    located_error(source, toml_text::describe(&source.text, error))
}

/// An error in a preset file's text, at its line and column, under the key the range checks
/// would name.
fn located_error(source: &PresetSource, mut described: toml_text::Described) -> PresetError {
    // A single `[pattern]` table is layer 0, as the range checks name it: `pattern.0.amount`.
    if let Some(rest) = described.key.as_deref().and_then(|k| k.strip_prefix("pattern."))
        && rest.split('.').next().is_none_or(|s| s.parse::<usize>().is_err())
    {
        described.key = Some(format!("pattern.0.{rest}"));
    }
    if let Some(in_range_words) = described.key.as_deref().and_then(|key| in_key_range(key, &described.message, false))
    {
        described.message = in_range_words;
    }
    if let Some(hint) = described.key.as_deref().and_then(|key| required_key_hint(key, &described.message)) {
        described.message = format!("{}{hint}", described.message);
    }
    PresetError::Parse {
        location: Location {
            file: source.display.clone(),
            line: described.line_column.map(|(line, _)| line),
            column: described.line_column.map(|(_, column)| column),
        },
        message: described.keyed_message(),
    }
}

/// A whole number its key's type cannot hold (`-3`, `5000000000`: the reader's "invalid
/// value: integer `-3`, expected a whole number from 0 to 4294967295", in plain words) in
/// the range check's words, with the key's range (`validate::whole_number_problem`).
/// `from_set`: a `--set` value, where a whole number past TOML's integers is read as a word
/// ("invalid type: string \"99999999999999999999\"") and is a whole number too; a quoted
/// number (`"21"`, in a file or `--set`) is a string, and said so.
fn in_key_range(key: &str, message: &str, from_set: bool) -> Option<String> {
    let value = match toml_text::integer_out_of_type(message) {
        Some(value) => Some(value),
        None if from_set => message.strip_prefix("invalid type: string \"").and_then(|rest| {
            let word = rest.split('"').next()?;
            let past_toml = word.parse::<i64>().is_err();
            (past_toml && is_whole_number_word(word)).then_some(word)
        }),
        None => None,
    };
    if let Some(value) = value {
        return super::validate::whole_number_problem(key, value);
    }
    // Any other type where a whole number goes — a number with a fraction or exponent,
    // `nan`, `inf` (`rows = 20.0`), a string (`rows = "many"`), a boolean — the reader's
    // words, with the key's range they lacked (a string said "expected a whole number" where
    // 19.5 said "expected a whole number in [4, 128]").
    if message.starts_with("invalid type: ") && message.ends_with("expected a whole number") {
        return Some(format!("{message} in {}", super::validate::whole_number_range_words(key)?));
    }
    None
}

/// What a table missing a required key needs (`[[pattern]]` without `kind`: the reader said
/// only "missing field `kind`"), or None.
fn required_key_hint(key: &str, message: &str) -> Option<String> {
    use super::schema::{HeadMarkKind, PatternKind};
    let field = message.strip_prefix("missing field `")?.strip_suffix('`')?;
    let table = key.trim_end_matches(|c: char| c.is_ascii_digit()).trim_end_matches('.');
    Some(match (table, field) {
        ("pattern", "kind") => format!(": every layer needs its kind, one of {}", PatternKind::accepted_names()),
        ("body.head_mark", "kind") => {
            format!(": every head mark needs its kind, one of {}", HeadMarkKind::accepted_names())
        }
        (_, "color") => ": give its colour as \"#rrggbb\"".into(),
        _ => return None,
    })
}

/// `required_key_hint` for a table an override made, with the key to add:
/// `--set pattern.0.kind=spots` on a preset without layers said only "missing field
/// `color`".
fn override_required_key_hint(key: &str, message: &str) -> Option<String> {
    let segments: Vec<&str> = key.split('.').collect();
    let index = segments.iter().position(|s| s.parse::<usize>().is_ok())?;
    let table = segments[..=index].join(".");
    let hint = required_key_hint(&table, message)?;
    // Worded for `--set` and a jobs file's `set` table alike (both write dotted keys).
    let add = match message.strip_prefix("missing field `")?.strip_suffix('`')? {
        "color" => format!("{table}.color = \"#rrggbb\""),
        field => format!("{table}.{field}"),
    };
    Some(format!("{hint} (set {add} as well)"))
}

/// Sets `dotted.key` to `value` (parsed as TOML; a bare word that is not TOML is a string).
/// `written`: where the override put values whole (`merge`), added to.
fn apply_override(
    root: &mut toml::Table,
    key: &str,
    value: &str,
    written: &mut Vec<String>,
) -> Result<(), PresetError> {
    let refuse = |message: String| PresetError::Override { argument: format!("{key}={value}"), message };
    if key.chars().chain(value.chars()).any(char::is_control) {
        return Err(refuse("the key and value must be one line without control characters".into()));
    }
    let parsed = override_value(value).map_err(refuse)?;
    let segments: Vec<&str> = key.split('.').collect();
    let result = if segments.iter().any(|s| s.is_empty()) {
        Err("the key must be a dotted path like scales.rows or pattern.0.kind".to_string())
    } else if segments.len() > toml_text::TOML_NESTING_LIMIT {
        // Each part is a level of `set_path`'s recursion and of the reader's when the
        // preset is read back: 50,000 parts overflowed the stack (an abort, exit 134).
        Err(format!(
            "the key has {} dotted parts; keys nest at most {} deep (a preset's keys have a few, like \
             body.head_mark.0.color)",
            segments.len(),
            toml_text::TOML_NESTING_LIMIT
        ))
    } else if let Some((segment, index)) = non_canonical_index(&segments) {
        // `pattern.00.kind` reached layer 0 as `pattern.0.kind` does, but the rules that read
        // the key's words (a kind changed by `--set` passes over the old kind's keys) did not
        // see it as that key.
        Err(format!("the index `{segment}` is written `{index}` (a whole number, no sign or leading zeros)"))
    } else if let Err(message) = check_indices(root, &segments) {
        Err(message)
    } else {
        let mut tree = toml::Value::Table(std::mem::take(root));
        let result = set_path(&mut tree, &segments, parsed, key, written);
        if let toml::Value::Table(t) = tree {
            *root = t;
        }
        result
    };
    result.map_err(|message| PresetError::Override { argument: format!("{key}={value}"), message })
}

/// The first part of a `--set` key that reads as an index but is not written the one way an
/// index is (`00`, `+1`), with that index.
fn non_canonical_index<'a>(segments: &[&'a str]) -> Option<(&'a str, usize)> {
    segments.iter().find_map(|s| s.parse::<usize>().ok().filter(|n| n.to_string() != *s).map(|n| (*s, n)))
}

/// An index in a `--set` key must reach into a list the preset has. `pattern.N` must name
/// an existing layer (or layer 0 of a preset without layers, which `--set` creates), and the
/// message says how many there are. Any other list must be written in the file (or whole,
/// by `--set`): an index into a missing key made a table where the schema wants a list
/// (`body.head_mark.0.kind=cap`: "invalid type: table, expected an array"), and one into
/// a single value (`optics.absorption.1=5`) the same.
fn check_indices(root: &toml::Table, segments: &[&str]) -> Result<(), String> {
    check_indices_in(root, segments, "")
}

/// `check_indices` in `root`, the table at `prefix` (empty at the preset's root).
fn check_indices_in(root: &toml::Table, segments: &[&str], prefix: &str) -> Result<(), String> {
    // A table the file does not have reads as an empty one: what lies below it is missing.
    let missing = toml::Value::Table(toml::Table::new());
    let mut here: Option<&toml::Value> = None;
    for (i, segment) in segments.iter().enumerate() {
        let path = format!("{prefix}{}", segments[..=i].join("."));
        let value = step(here, root, segment);
        // An index no list has (`pattern.-1`, one past usize), at a list (one the preset has,
        // or one of the schema's): it was taken as a key into the list, and the message said
        // to write `pattern.N.-1.kind`. Below a table or a value it is an unknown key, as
        // `scales.x1` is.
        if let Some(next) = segments.get(i + 1).filter(|s| is_whole_number_word(s) && s.parse::<usize>().is_err()) {
            let have = match value {
                Some(toml::Value::Array(items)) => Some(format!(" (`{path}` has {})", entries(items.len(), &path))),
                None if path == "pattern" || schema_lists().contains(&path) => Some(String::new()),
                _ => None,
            };
            if let Some(have) = have {
                return Err(format!("there is no `{path}.{next}`: a list's entries are numbered from 0{have}"));
            }
        }
        let Some(index) = segments.get(i + 1).and_then(|s| s.parse::<usize>().ok()) else {
            if i + 1 < segments.len() {
                match value {
                    // A key into a list without its index (`pattern.amount` on `[[pattern]]`
                    // said "`amount` must be an array index"): the list and its entries. A
                    // word where the index goes (`pattern.x.kind` was told to write
                    // `pattern.N.x.kind`) is replaced by N; a list of values (`sources`)
                    // has no keys below its entries.
                    Some(toml::Value::Array(items)) => {
                        let rest = &segments[i + 1..];
                        let write = if !items.iter().all(toml::Value::is_table) {
                            format!("{path}.N")
                        } else if rest.len() > 1 {
                            format!("{path}.N.{} (N in place of `{}`)", rest[1..].join("."), rest[0])
                        } else {
                            format!("{path}.N.{}", rest[0])
                        };
                        return Err(format!("`{path}` is a list ({}): write {write}", entries(items.len(), &path)));
                    }
                    // A key below a list the preset does not have (`body.head_mark.color`
                    // without head marks) made a table where the schema wants a list:
                    // "invalid type: table, expected an array". A single `[pattern]` table is
                    // layer 0, so `pattern.KEY` may start one.
                    None if path != "pattern" && schema_lists().contains(&path) => {
                        return Err(format!(
                            "`{path}` is a list, and the preset has none, so `{prefix}{}` has nothing to reach into \
                             (set the list whole: --set '{path}=[...]', or write it in the preset file)",
                            segments.join(".")
                        ));
                    }
                    _ => {}
                }
            }
            here = Some(value.unwrap_or(&missing));
            continue;
        };
        if path == "pattern" {
            check_layer_index(value, index)?;
            // The layer's own keys: the array's item, or a single `[pattern]` table.
            let layer = match value {
                Some(toml::Value::Array(items)) => items.get(index),
                table => table,
            };
            return check_indices_below(layer, &segments[i + 2..], &format!("pattern.{index}."));
        }
        let len = match value {
            None => {
                return Err(format!(
                    "`{path}` is not written in the preset, so `{path}.{index}` has no list to reach into (a key that \
                     takes a list is set whole: --set '{path}=[...]', or written in the preset file)"
                ));
            }
            Some(toml::Value::Array(items)) => items.len(),
            Some(toml::Value::Table(_)) => return Ok(()),
            Some(_) => {
                return Err(format!(
                    "`{path}` is one value, not a list, so `{path}.{index}` names nothing (a key that takes a list is \
                     set whole: --set '{path}=[...]')"
                ));
            }
        };
        if index >= len {
            return Err(format!("`{path}` has {}; there is no `{path}.{index}`", entries(len, &path)));
        }
        let item = value.and_then(|v| v.as_array()).and_then(|items| items.get(index));
        return check_indices_below(item, &segments[i + 2..], &format!("{path}.{index}."));
    }
    Ok(())
}

/// The dotted keys the schema holds as lists (`pattern`, `body.head_mark`, `sources`): the
/// lists of a preset with nothing written but its seed, as the schema writes them. Lists in
/// tables only: not those inside a list's items (a layer's `colors`), which such a preset
/// has none of.
fn schema_lists() -> &'static [String] {
    static LISTS: std::sync::LazyLock<Vec<String>> = std::sync::LazyLock::new(|| {
        let preset: Preset = toml::from_str("seed = 0").expect("a seed alone is a preset");
        let value = toml::Value::try_from(&preset).expect("a preset is TOML");
        let mut lists = Vec::new();
        let mut tables = vec![(String::new(), value)];
        while let Some((path, value)) = tables.pop() {
            let toml::Value::Table(table) = value else { continue };
            for (key, value) in table {
                let key = if path.is_empty() { key } else { format!("{path}.{key}") };
                match value {
                    toml::Value::Array(_) => lists.push(key),
                    value @ toml::Value::Table(_) => tables.push((key, value)),
                    _ => {}
                }
            }
        }
        lists
    });
    &LISTS
}

/// `check_indices` below a list's item at `prefix` (a layer's `colors.N`).
fn check_indices_below(item: Option<&toml::Value>, rest: &[&str], prefix: &str) -> Result<(), String> {
    match item {
        Some(toml::Value::Table(t)) if !rest.is_empty() => check_indices_in(t, rest, prefix),
        // A layer `--set` starts: nothing below it is written yet.
        None if !rest.is_empty() => check_indices_in(&toml::Table::new(), rest, prefix),
        _ => Ok(()),
    }
}

/// One key down from `here` (the root table when None).
fn step<'a>(here: Option<&'a toml::Value>, root: &'a toml::Table, key: &str) -> Option<&'a toml::Value> {
    match here {
        None => root.get(key),
        Some(toml::Value::Table(t)) => t.get(key),
        Some(_) => None,
    }
}

/// "1 entry: a.0", "3 entries: a.0 to a.2".
fn entries(len: usize, path: &str) -> String {
    match len {
        0 => "no entries".to_string(),
        1 => format!("1 entry: {path}.0"),
        n => format!("{n} entries: {path}.0 to {path}.{}", n - 1),
    }
}

/// `pattern.N`: an existing layer, or layer 0 of a preset without layers (`--set` starts it).
fn check_layer_index(pattern: Option<&toml::Value>, index: usize) -> Result<(), String> {
    let layers = match pattern {
        None => 0,
        Some(toml::Value::Array(items)) => items.len(),
        Some(_) => 1,
    };
    if index < layers || (layers == 0 && index == 0) {
        return Ok(());
    }
    let have = match layers {
        0 => "the preset has no pattern layers: `pattern.0.KEY` starts one".to_string(),
        1 => "the preset has 1 pattern layer: pattern.0".to_string(),
        n => format!("the preset has {n} pattern layers: pattern.0 to pattern.{}", n - 1),
    };
    Err(format!("there is no pattern layer {index}; {have} (add layers in the preset file)"))
}

/// Puts `value` at `segments` below `target` (`merge`, which records in `written` under the
/// override's `key` as written).
fn set_path(
    target: &mut toml::Value,
    segments: &[&str],
    value: toml::Value,
    key: &str,
    written: &mut Vec<String>,
) -> Result<(), String> {
    let Some((first, rest)) = segments.split_first() else {
        merge(target, value, key, written);
        return Ok(());
    };
    match target {
        // `pattern.0` addresses a single `[pattern]` table as layer 0.
        toml::Value::Table(t) if *first == "0" && !t.contains_key("0") => set_path(target, rest, value, key, written),
        toml::Value::Table(t) => {
            let child = t.entry(first.to_string()).or_insert_with(|| toml::Value::Table(Default::default()));
            set_path(child, rest, value, key, written)
        }
        toml::Value::Array(items) => {
            let len = items.len();
            // `check_indices` has refused a key into a list without its index.
            let index: usize = first.parse().map_err(|_| format!("`{first}` must be an array index"))?;
            // `pattern = []` and `pattern.0.KEY`: the first layer starts (`check_indices`
            // lets only that index past the end through).
            if index == 0 && len == 0 {
                items.push(toml::Value::Table(Default::default()));
            }
            let item = items.get_mut(index).ok_or_else(|| format!("there is no entry {index}: the list has {len}"))?;
            set_path(item, rest, value, key, written)
        }
        _ => Err(format!("`{first}` is inside a value that is not a table")),
    }
}

/// Puts `value` where `target` is: a table into a table key by key (`--set
/// 'scales={rows=23}'` changes `rows` and keeps the other scale keys, as `--set
/// scales.rows=23` does), anything else in place of what was there (`--set
/// 'pattern={kind="spots"}'` in place of the file's layers). `path`: the key `target` is
/// at, as the override wrote it; each key where a value went whole is added to `written`
/// (what lies under it is the override's, not the file's).
fn merge(target: &mut toml::Value, value: toml::Value, path: &str, written: &mut Vec<String>) {
    match (target, value) {
        (toml::Value::Table(existing), toml::Value::Table(new)) => {
            for (key, v) in new {
                // A key not there yet starts as an empty table, which `v` then replaces or fills.
                let child = existing.entry(key.clone()).or_insert_with(|| toml::Value::Table(Default::default()));
                merge(child, v, &format!("{path}.{key}"), written);
            }
        }
        (target, value) => {
            *target = value;
            written.push(path.to_string());
        }
    }
}

/// Whether `word` is a whole number in digits, signed or not (`-3`, `+99999999999999999999`):
/// one past TOML's integers stays a word in an override (`override_value`), and the key's
/// range check names it (`in_key_range`).
fn is_whole_number_word(word: &str) -> bool {
    let digits = word.strip_prefix(['-', '+']).unwrap_or(word);
    !digits.is_empty() && digits.chars().all(|c| c.is_ascii_digit())
}

/// An override's value: one TOML value, or a bare word that is not TOML as a string. A
/// value written as TOML that does not parse is refused with TOML's reason: one that opens
/// an array, a table or a quoted string, or starts as a number does (`[1, 2`, `"#fff`,
/// `1e400`), as do `True` and `False` (TOML's are lower case). They were taken as strings,
/// and the key then said "invalid type: string \"[1, 2\", expected an array".
fn override_value(value: &str) -> Result<toml::Value, String> {
    if value.trim().is_empty() {
        // It was the text "" for every key: "invalid type: string \"\", expected a whole number".
        return Err("the value is empty: write one after `=` (empty text is written 'KEY=\"\"')".into());
    }
    // One TOML value, nothing else: the table must hold exactly the key `v`.
    let as_toml = format!("v = {value}");
    match toml::from_str::<toml::Table>(&as_toml) {
        Ok(_) if let Some(underflow) = crate::toml_text::underflowing_float(&as_toml) => Err(underflow.message),
        Ok(mut t) if t.len() == 1 => Ok(t.remove("v").unwrap_or(toml::Value::String(value.into()))),
        Ok(_) => Err("the value must be a single TOML value".into()),
        Err(e) => {
            let word = value.trim();
            let mut chars = word.chars();
            let first = chars.next();
            let numeric = |c: Option<char>| c.is_some_and(|c| c.is_ascii_digit());
            // A whole number past TOML's integers stays a word: the key's range check names
            // it (`in_key_range`). One TOML refuses otherwise (`023`: leading zeros) is a
            // number, refused with TOML's reason: it was taken as text ("invalid type:
            // string").
            let whole = is_whole_number_word(word) && word.parse::<i64>().is_err();
            let second = chars.next();
            let signed_number = matches!(first, Some('+' | '-')) && (numeric(second) || second == Some('.'));
            let number = !whole && (numeric(first) || signed_number || (first == Some('.') && numeric(second)));
            let reason = || e.message().trim().replace('\n', "; ");
            if word.eq_ignore_ascii_case("true") || word.eq_ignore_ascii_case("false") {
                // The key may want the word itself (a name, a species): say how to write either.
                Err(format!(
                    "{word} is not a TOML boolean: write {}, or 'KEY=\"{word}\"' for the text",
                    word.to_ascii_lowercase()
                ))
            } else if matches!(first, Some('[' | '{' | '"' | '\'')) {
                Err(format!("not a TOML value ({})", reason()))
            } else if number {
                Err(format!(
                    "not a TOML value ({}); write a TOML number (0.5, 1e3), or a string that starts like a \
                     number in quotes, as in 'KEY=\"{word}\"'",
                    reason()
                ))
            } else {
                Ok(toml::Value::String(value.into()))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn source(text: &str) -> PresetSource {
        PresetSource { name: "t".into(), display: "t.toml".into(), text: text.into() }
    }

    /// The belly's colours along the body stay out of the canonical text (`preset_hash`)
    /// where a preset leaves them unset, so its hash and its batch jobs' keys are those from
    /// before the keys existed (every built-in's hash had changed: a review). The control: a
    /// preset that sets them has them in its text.
    #[test]
    fn unset_belly_colours_along_the_body_leave_the_hash_as_it_was() {
        let keys = ["belly_front_color", "belly_front_end", "subcaudal_color"];
        let text = |name: &str| canonical_text(&load(name, &[], None).unwrap().preset);
        let unset = crate::preset::library::all().iter().filter(|(name, _)| {
            let body = load(name, &[], None).unwrap().preset.body;
            body.belly_front_color.is_none() && body.subcaudal_color.is_none()
        });
        let mut count = 0;
        for (name, _) in unset {
            assert!(keys.iter().all(|k| !text(name).contains(k)), "{name}");
            count += 1;
        }
        assert!(count > 25, "most built-ins leave them unset: {count}");
        let (liasis, pseudechis) = (text("liasis-mackloti"), text("pseudechis-porphyriacus"));
        assert!(liasis.contains("belly_front_color") && liasis.contains("belly_front_end"), "the control");
        assert!(pseudechis.contains("subcaudal_color"), "the control");
    }

    /// A file that sets no key is warned of (it loaded silently as the default snake), a
    /// seed given or not. Negative controls: one key, a `--set`, and a built-in preset.
    #[test]
    fn a_file_that_sets_no_key_is_warned_of() {
        let says = |loaded: &LoadedPreset| {
            loaded.warnings("t.toml", crate::preset::SET_FLAG).iter().any(|w| w.contains("sets no key"))
        };
        for text in ["", "\n  \n", "# a comment only\n", "[scales]\n[body]\n", "scales = {}"] {
            let loaded = parse(&source(text), &[]).unwrap();
            assert!(says(&loaded), "{text:?}: {:?}", loaded.warnings("t.toml", crate::preset::SET_FLAG));
        }
        assert!(!says(&parse(&source("seed = 1"), &[]).unwrap()));
        assert!(!says(&parse(&source(""), &[("scales.rows".into(), "21".into())]).unwrap()));
        // A seed alone still draws the default snake.
        assert!(says(&parse_with_seed(&source(""), &[], Some(3)).unwrap()));
        assert!(!says(&load("natrix-natrix", &[], None).unwrap()));
    }

    /// A value written as TOML that does not parse is refused with TOML's reason (it was
    /// taken as a string, and the key said "invalid type: string"); a bare word still is a
    /// string. Negative control: the same values written right parse.
    #[test]
    fn a_malformed_toml_value_is_refused_with_its_reason() {
        for (value, reason) in [
            ("[\"a\",", "not a TOML value (unclosed array"),
            ("\"#ffffff", "not a TOML value (invalid basic string"),
            ("{rows = 3", "not a TOML value ("),
            ("1e400", "not a TOML value (floating-point number overflowed); write a TOML number"),
            ("-.5", "not a TOML value ("),
            ("True", "True is not a TOML boolean: write true, or 'KEY=\"True\"' for the text"),
            ("FALSE", "FALSE is not a TOML boolean: write false, or 'KEY=\"FALSE\"' for the text"),
        ] {
            let err = override_value(value).unwrap_err();
            assert!(err.starts_with(reason), "{value}: {err}");
        }
        for (value, parsed) in [
            ("[\"a\"]", toml::Value::Array(vec!["a".into()])),
            ("\"#ffffff\"", "#ffffff".into()),
            ("1e300", 1e300.into()),
            ("true", true.into()),
            ("#ffffff", "#ffffff".into()),
            ("Vipera berus", "Vipera berus".into()),
            ("-x", "-x".into()),
            ("99999999999999999999", "99999999999999999999".into()),
            ("+99999999999999999999", "+99999999999999999999".into()),
        ] {
            assert_eq!(override_value(value), Ok(parsed), "{value}");
        }
    }

    /// An inline table given to `--set` merges into the table it names, key by key, as the
    /// dotted keys would; a value that is not a table replaces what was there. Negative
    /// control: the merged preset differs from the original only where the table said.
    #[test]
    fn an_inline_table_merges_into_the_table_it_names() {
        let text = "[scales]\nshape = \"hexagon\"\nrows = 19\nsize = 1.5\n";
        let original = parse(&source(text), &[]).unwrap().preset;
        let set = |k: &str, v: &str| parse(&source(text), &[(k.into(), v.into())]).unwrap().preset;
        let merged = set("scales", "{rows = 23}");
        assert_eq!(merged.scales.rows, 23);
        assert_eq!(merged.scales.shape, original.scales.shape);
        assert_eq!(merged.scales.size, original.scales.size);
        assert_eq!(merged, set("scales.rows", "23"));
        assert_ne!(merged, original);
    }

    #[test]
    fn suggestion_names_the_nearest_key() {
        let err = parse(&source("[scales]\nrwos = 3\n"), &[]).unwrap_err().to_string();
        assert!(err.contains("t.toml:2:1"), "{err}");
        assert!(err.contains("did you mean `rows`"), "{err}");
        let err = parse(&source("[scales]\nROWS = 3\n"), &[]).unwrap_err().to_string();
        assert!(err.contains("unknown key `ROWS`; did you mean `rows`"), "{err}");
    }

    #[test]
    fn range_error_has_line_and_key() {
        let err = parse(&source("seed = 1\n\n[optics]\nfilm_ior = 9.0\n"), &[]).unwrap_err().to_string();
        assert!(err.contains("t.toml:4: key `optics.film_ior`"), "{err}");
        assert!(err.contains("[1, 3]"), "{err}");
    }

    #[test]
    fn overrides_set_nested_keys_and_strings() {
        let overrides = vec![
            ("scales.rows".to_string(), "25".to_string()),
            ("scales.shape".to_string(), "diamond".to_string()),
            ("pattern.0.kind".to_string(), "spots".to_string()),
            ("pattern.0.color".to_string(), "#102030".to_string()),
        ];
        let loaded = parse(&source("seed = 1\n"), &overrides).unwrap();
        assert_eq!(loaded.preset.scales.rows, 25);
        assert_eq!(loaded.preset.scales.shape, super::super::schema::ScaleShape::Diamond);
        assert_eq!(loaded.preset.pattern.len(), 1);
    }

    #[test]
    fn range_errors_in_a_single_pattern_table_have_their_line() {
        let text = "seed = 1\n[pattern]\nkind = \"spots\"\ncolor = \"#102030\"\nsize = 9.0\n";
        let err = parse(&source(text), &[]).unwrap_err().to_string();
        assert!(err.contains("t.toml:5: key `pattern.0.size`"), "{err}");
        let layers = "[[pattern]]\nkind = \"solid\"\ncolor = \"#000000\"\n[[pattern]]\nkind = \"spots\"\ncolor = \"#102030\"\nsize = 9.0\n";
        let err = parse(&source(layers), &[]).unwrap_err().to_string();
        assert!(err.contains("t.toml:7: key `pattern.1.size`"), "{err}");
    }

    /// Seeds run to 2^53 − 1 (`ranges::SEED_MAX`), TOML's integers to 2^63 − 1, a u64 to
    /// 2^64 − 1. A seed beyond the range is refused by the range check wherever it is written:
    /// in the file (alone, or with an override, whose table's parse refused a seed beyond
    /// TOML's integers in its own words), by `--set seed=` or by `--seed`. Negative controls:
    /// the largest seed is taken everywhere, and a seed given by `--seed` replaces a file's
    /// seed beyond the range.
    #[test]
    fn seeds_are_range_checked_wherever_they_are_written() {
        use crate::preset::validate::ranges::SEED_MAX;
        // The file's line where the file's seed is refused, none where a given one is.
        let refused = |result: Result<LoadedPreset, PresetError>, line: &str| {
            let err = result.unwrap_err().to_string();
            assert!(err.contains(&format!("{line}key `seed` must be an integer in [0, 9007199254740991]")), "{err}");
        };
        let rows = [("scales.rows".to_string(), "23".to_string())];
        let file = |seed: u64| format!("seed = {seed}\n[scales]\nrows = 19\n");
        let set_seed = |value: &str| parse(&source("seed = 1\n"), &[("seed".into(), value.into())]);
        for beyond in [SEED_MAX + 1, 1 << 63, u64::MAX] {
            refused(parse(&source(&file(beyond)), &[]), "t.toml:1: ");
            refused(parse(&source(&file(beyond)), &rows), "t.toml:1: ");
            refused(set_seed(&beyond.to_string()), "t.toml (with --set): ");
            refused(parse_with_seed(&source("seed = 1\n"), &[], Some(beyond)), "t.toml (with --set): ");
        }
        let loaded = parse(&source(&file(SEED_MAX)), &rows).unwrap();
        assert_eq!((loaded.preset.seed, loaded.preset.scales.rows), (SEED_MAX, 23));
        assert_eq!(set_seed("9007199254740991").unwrap().preset.seed, SEED_MAX);
        assert_eq!(set_seed("9_000").unwrap().preset.seed, 9000);
        assert_eq!(set_seed("0x10").unwrap().preset.seed, 16);
        // Leading zeros, as `--seed` takes them (`parse_seed_text`), though TOML does not.
        assert_eq!(set_seed("007").unwrap().preset.seed, 7);
        for bad in ["18446744073709551616", "-1", "1.5", "\"7\"", "seven", "", "1\nscales.rows = 5"] {
            let err = set_seed(bad).unwrap_err().to_string();
            assert!(
                err.contains(&format!("{:?}", format!("seed={bad}"))) && err.contains("in [0, 9007199254740991]"),
                "{err}"
            );
        }
        // The file's seed, not TOML's default, when an override leaves the seed alone.
        assert_eq!(parse(&source("seed = 7\n"), &rows).unwrap().preset.seed, 7);
        let both = parse_with_seed(&source(&file(u64::MAX)), &[("seed".into(), "5".into())], Some(6)).unwrap();
        assert_eq!(both.preset.seed, 6);
    }

    /// A problem in a value an override put whole (an inline table in place of the file's
    /// layers, or a single `[pattern]` table's key set as `pattern.KEY`) is the override's:
    /// it was placed at the file's old line for that key or its layer's table, or called
    /// the key's default. Negative controls: keys the override merged around keep the
    /// file's lines, and an indexed key was already the override's.
    #[test]
    fn a_problem_in_what_an_override_wrote_whole_is_the_overrides() {
        let two_layers = "seed = 1\n[[pattern]]\nkind = \"spots\"\ncolor = \"#101010\"\namount = 3\n\
                          [[pattern]]\nkind = \"spots\"\ncolor = \"#202020\"\namount = 4\n";
        let single = "seed = 1\n[pattern]\nkind = \"rings\"\ncolors = [\"#101010\", \"#202020\"]\n";
        let problem = |text: &str, set: (&str, &str)| match parse(&source(text), &[(set.0.into(), set.1.into())]) {
            Err(PresetError::Invalid { problems, .. }) => problems.into_iter().next().expect("one problem"),
            other => panic!("{set:?}: not refused as invalid: {:?}", other.map(|l| l.name)),
        };
        let by_override = |text: &str, set: (&str, &str), key: &str| {
            let p = problem(text, set);
            assert_eq!((p.key.as_str(), p.line, p.overridden), (key, None, true), "{set:?}: {p:?}");
        };
        by_override(two_layers, ("pattern", "{kind = \"irregular\"}"), "pattern.0.color");
        by_override(
            two_layers,
            ("pattern", "{kind = \"spots\", color = \"#101010\", amount = 99}"),
            "pattern.0.amount",
        );
        by_override(single, ("pattern.amount", "99"), "pattern.0.amount");
        by_override(
            "seed = 1\n",
            ("pattern", "{kind = \"spots\", color = \"#101010\", amount = 99}"),
            "pattern.0.amount",
        );
        by_override(two_layers, ("pattern.1.amount", "99"), "pattern.1.amount");
        // The file's own: a value the override merged around, in the file's line.
        let p = problem(&two_layers.replace("amount = 4", "amount = 99"), ("pattern.0", "{amount = 5}"));
        assert_eq!((p.key.as_str(), p.line, p.overridden), ("pattern.1.amount", Some(9), false), "{p:?}");
        let p = problem(&single.replace("seed = 1\n", "seed = 1\n[scales]\nrows = 999\n"), ("pattern.amount", "2"));
        assert_eq!((p.key.as_str(), p.line, p.overridden), ("scales.rows", Some(3), false), "{p:?}");
    }

    /// An index no list can have (`pattern.-1`, one past usize) is said to be one; it was
    /// taken as a key into the list ("write pattern.N.-1.kind").
    #[test]
    fn an_index_no_list_has_is_named() {
        let one_layer = "seed = 1\n[[pattern]]\nkind = \"spots\"\ncolor = \"#101010\"\n";
        for index in ["-1", "99999999999999999999", "-0"] {
            let set = [(format!("pattern.{index}.kind"), "spots".to_string())];
            let err = parse(&source(one_layer), &set).unwrap_err().to_string();
            let says = format!(
                "there is no `pattern.{index}`: a list's entries are numbered from 0 (`pattern` has 1 entry: pattern.0)"
            );
            assert!(err.contains(&says), "{err}");
        }
        let set = [("sources.-2".to_string(), "x".to_string())];
        let err = parse(&source("seed = 1\nsources = [\"a\"]\n"), &set).unwrap_err().to_string();
        assert!(
            err.contains("there is no `sources.-2`: a list's entries are numbered from 0 (`sources` has 1"),
            "{err}"
        );
        // Without layers there are no entries to name.
        let err = parse(&source("seed = 1\n"), &[("pattern.-1.kind".into(), "spots".into())]).unwrap_err();
        assert!(err.to_string().ends_with("there is no `pattern.-1`: a list's entries are numbered from 0"), "{err}");
        // Negative controls: an index the list has; a number below a table is an unknown key.
        assert_eq!(
            parse(&source(one_layer), &[("pattern.0.amount".into(), "3".into())]).unwrap().preset.pattern[0].amount,
            3.0
        );
        let err = parse(&source("seed = 1\n"), &[("scales.-1".into(), "5".into())]).unwrap_err().to_string();
        assert!(!err.contains("a list's entries") && err.contains("-1"), "{err}");
    }

    /// A value that starts as a number TOML refuses (`023`) gets TOML's reason; it was text,
    /// and the key said "invalid type: string". An empty value is said to be empty.
    #[test]
    fn a_number_toml_refuses_and_an_empty_value_are_said() {
        for (value, says) in [
            ("023", "not a TOML value (unexpected leading zero"),
            ("", "the value is empty"),
            (" ", "the value is empty"),
        ] {
            let err = parse(&source("seed = 1\n"), &[("scales.rows".into(), value.into())]).unwrap_err().to_string();
            assert!(err.contains(says) && !err.contains("invalid type"), "{value:?}: {err}");
        }
        // A whole number past TOML's integers is still the key's range problem.
        let err = parse(&source("seed = 1\n"), &[("scales.rows".into(), "99999999999999999999".into())]).unwrap_err();
        assert!(
            !err.to_string().contains("not a TOML value") && err.to_string().contains("99999999999999999999"),
            "{err}"
        );
        // Negative controls: TOML's number and empty text.
        assert_eq!(
            parse(&source("seed = 1\n"), &[("scales.rows".into(), "23".into())]).unwrap().preset.scales.rows,
            23
        );
        assert!(parse(&source("seed = 1\n"), &[("sources".into(), "[\"\"]".into())]).is_ok());
    }

    /// A key into a list without its index names the list and its entries (it said "`amount`
    /// must be an array index"); a single `[pattern]` table takes the key as layer 0's.
    #[test]
    fn a_key_into_a_list_without_an_index_names_the_list() {
        let two_layers = "seed = 1\n[[pattern]]\nkind = \"spots\"\ncolor = \"#101010\"\n\
                          [[pattern]]\nkind = \"spots\"\ncolor = \"#202020\"\n";
        let err = parse(&source(two_layers), &[("pattern.amount".into(), "3".into())]).unwrap_err().to_string();
        let says = "`pattern` is a list (2 entries: pattern.0 to pattern.1): write pattern.N.amount";
        assert!(err.contains(says), "{err}");
        let marks = "seed = 1\n[[body.head_mark]]\nkind = \"collar\"\ncolor = \"#101010\"\n";
        let err = parse(&source(marks), &[("body.head_mark.color".into(), "\"#fff\"".into())]).unwrap_err();
        let says = "`body.head_mark` is a list (1 entry: body.head_mark.0): write body.head_mark.N.color";
        assert!(err.to_string().contains(says), "{err}");
        // A word where the index goes, and a key below a list of values (the hints were
        // `pattern.N.x.kind` and `sources.N.x`, both still wrong).
        let err = parse(&source(two_layers), &[("pattern.x.kind".into(), "\"spots\"".into())]).unwrap_err();
        assert!(err.to_string().contains("write pattern.N.kind (N in place of `x`)"), "{err}");
        let sources = "seed = 1\nsources = [\"a\", \"b\"]\n";
        let err = parse(&source(sources), &[("sources.x".into(), "\"c\"".into())]).unwrap_err();
        assert!(
            err.to_string().contains("`sources` is a list (2 entries: sources.0 to sources.1): write sources.N"),
            "{err}"
        );
        assert!(!err.to_string().contains("sources.N."), "{err}");
        let single = "seed = 1\n[pattern]\nkind = \"spots\"\ncolor = \"#101010\"\n";
        assert_eq!(
            parse(&source(single), &[("pattern.amount".into(), "3".into())]).unwrap().preset.pattern[0].amount,
            3.0
        );
        // A preset without head marks: the list, not the reader's "invalid type: table".
        let err = parse(&source("seed = 1\n"), &[("body.head_mark.color".into(), "\"#fff\"".into())]).unwrap_err();
        let says = "`body.head_mark` is a list, and the preset has none, so `body.head_mark.color` has nothing \
                    to reach into (set the list whole: --set 'body.head_mark=[...]'";
        assert!(err.to_string().contains(says), "{err}");
        // Negative control: set whole, the list is accepted.
        let whole = [("body.head_mark".into(), "[{kind=\"collar\", color=\"#ffffff\"}]".into())];
        assert_eq!(parse(&source("seed = 1\n"), &whole).unwrap().preset.body.head_mark.len(), 1);
        // And a preset without layers still takes `pattern.KEY` as layer 0's.
        let layer = [("pattern.kind".into(), "spots".into()), ("pattern.color".into(), "\"#101010\"".into())];
        assert_eq!(parse(&source("seed = 1\n"), &layer).unwrap().preset.pattern.len(), 1);
    }

    #[test]
    fn the_schema_lists_are_the_lists_a_preset_can_hold() {
        let lists = schema_lists();
        for list in ["pattern", "body.head_mark", "sources"] {
            assert!(lists.iter().any(|l| l == list), "{list} in {lists:?}");
        }
        assert!(!lists.iter().any(|l| l == "body" || l == "optics.absorption"), "{lists:?}");
    }

    #[test]
    fn non_finite_values_are_refused() {
        let err = parse(&source("[optics]\nfilm_thickness_nm = nan\n"), &[]).unwrap_err().to_string();
        assert!(err.contains("optics.film_thickness_nm"), "{err}");
    }
}
