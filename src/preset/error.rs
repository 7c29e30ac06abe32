//! Errors a user can cause with a preset or an override. Each names where (file, line,
//! column or the `--set` argument), what (the key) and what would be accepted.

use std::fmt;
use std::path::{Path, PathBuf};

/// A preset's path for a message of one line (`toml_text::one_line`): a jobs file names its
/// presets, and a folder name with a newline printed a line of its own (an independent review).
fn one_line(path: &Path) -> String {
    crate::toml_text::one_line(&path.display().to_string())
}

#[derive(Debug, thiserror::Error)]
pub enum PresetError {
    /// `hint`: empty, or "; ..." naming the built-in preset a missing file is named after.
    #[error("cannot read preset {}: {source}{hint}", one_line(.path))]
    Read { path: PathBuf, source: std::io::Error, hint: String },

    #[error("cannot read preset {}: it is {kind}; a preset must be a regular file", one_line(.path))]
    NotAFile { path: PathBuf, kind: &'static str },

    #[error("cannot read preset {}: it is {size}; presets are limited to {limit} bytes", one_line(.path))]
    TooLarge { path: PathBuf, size: crate::text_file::FileSize, limit: u64 },

    /// A preset file whose name the set's files cannot carry.
    #[error("preset {path:?}: its file name has {what}, and a set's files are named after it; rename the file")]
    FileName { path: PathBuf, what: &'static str },
    #[error("unknown preset {name:?}: not a .toml file and not a built-in preset{suggestion} (built-in: {available})")]
    UnknownPreset { name: String, suggestion: String, available: String },

    /// TOML syntax, a wrong type, an unknown key or a bad enum value.
    #[error("{location}: {message}")]
    Parse { location: Location, message: String },

    /// Values out of range, one line each.
    #[error("{}", describe_problems(.file, .problems, SET_FLAG))]
    Invalid { file: String, problems: Vec<LocatedProblem> },

    #[error("invalid --set {argument:?}: {message}")]
    Override { argument: String, message: String },
}

/// Where in a preset something is.
#[derive(Debug, Clone, PartialEq)]
pub struct Location {
    pub file: String,
    pub line: Option<usize>,
    pub column: Option<usize>,
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        let file = crate::toml_text::one_line(&self.file);
        match (self.line, self.column) {
            (Some(l), Some(c)) => write!(f, "{file}:{l}:{c}"),
            (Some(l), None) => write!(f, "{file}:{l}"),
            _ => write!(f, "{file}"),
        }
    }
}

#[derive(Debug, Clone, PartialEq)]
pub struct LocatedProblem {
    pub key: String,
    /// Line in the file, or None when the value came from `--set` or is the key's default.
    pub line: Option<usize>,
    /// Whether `--set` (or a jobs file's `set`) wrote the key, or for a key at its default
    /// the check's other key (`validate::Problem::second_key`).
    pub overridden: bool,
    /// Whether the key is at its default (neither written nor overridden); `line` is then
    /// the line of the check's other key (`validate::Problem::second_key`), if any.
    pub default: bool,
    pub message: String,
}

impl LocatedProblem {
    /// " (not written: its default)" for a key at its default, else nothing.
    pub fn default_note(&self) -> &'static str {
        if self.default { " (not written: its default)" } else { "" }
    }
}

/// One line per problem: the file and line of a key written in the file, the file `(with
/// OVERRIDES)` for one an override wrote (`--set`, or a jobs file's `set`), and a key at its
/// default named as one (a check across keys can name one: `pattern.0.size` against the
/// `amount` written; that said "(with --set)" when nothing was set), at the line of the
/// check's other key where the file writes it.
pub fn describe_problems(file: &str, problems: &[LocatedProblem], overrides: &str) -> String {
    problems
        .iter()
        .map(|p| {
            format!(
                "{}: key `{}`{} {}",
                place(file, p.line, p.overridden, overrides),
                p.key,
                p.default_note(),
                p.message
            )
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// The command line's overrides, as problems and warnings name them (a jobs file's are "its
/// `set` table").
pub const SET_FLAG: &str = "--set";

/// Where a preset's key is, as its problems and warnings say it, on one line: `FILE:LINE`
/// for a key written in the file, `FILE (with OVERRIDES)` for one an override wrote, else
/// `FILE` (a key at its default, or a built-in preset's name).
pub fn place(file: &str, line: Option<usize>, overridden: bool, overrides: &str) -> String {
    let file = crate::toml_text::one_line(file);
    match (line, overridden) {
        (Some(line), _) => format!("{file}:{line}"),
        (None, true) => format!("{file} (with {overrides})"),
        (None, false) => file,
    }
}
