//! Map encoding (PNG in the formats `material` fixes), the material manifest, and atomic
//! output (single files and whole sets, see `atomic.rs`).
//!
//! Encoding runs in parallel, one map per task: PNG compression of a 2K set is ~0.2 s on
//! one core, the largest single cost after generation.

mod atomic;
pub mod gltf;
mod manifest;
pub mod pack;
pub mod srgb;

pub use atomic::{
    Earlier, FileGroup, Inputs, KeptBecause, KeptFile, SetLock, Staged, begins_as, check_folder, check_folder_writable,
    check_lock_not_an_input, check_lock_place, check_not_an_input, check_png_target, check_replaces_its_own,
    check_target, check_target_named, check_writable, clean_up_before_exit, create_folder, create_folder_noted,
    ends_as_a_folder, folder_of, lies_under, lock_file_name, lock_is_held, remove_empty_made_folders, same_identity,
    same_path, sha256_hex, temporary_target, wait_for_commit, write_file_atomically, write_new_numbered_file,
};
pub(crate) use manifest::verify_set_json;
pub use manifest::{
    Counts, FileIdentity, MANIFEST_SUFFIX, Manifest, ManifestReadError, MapEntry, Source, VerifiedSet, body_counts,
    file_identity, manifest, manifest_file_name, manifest_json, read_set_manifest, set_file_sha256, verify_set,
};
pub use srgb::{linear_to_srgb8, linear_to_srgb8_formula};

use std::io::Cursor;
use std::path::PathBuf;

use image::ExtendedColorType;
use rayon::prelude::*;

use crate::material::{Encoding, FileFormat, MapKind};
use crate::ops::Image;

#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    #[error("cannot write {path}: {source}")]
    Io { path: PathBuf, source: std::io::Error },
    /// A commit that failed, and whose undo failed too: the earlier set's files that could
    /// not go back (`kept`: each temporary and the file it was) wait in hidden temporaries,
    /// which the next run in the folder removes. It said only why the commit failed, and
    /// `verify` then advised the run that removed them (a sweep).
    #[error(
        "{source}; undoing the commit failed too: {} of the earlier set's files are kept in hidden temporaries \
         beside it, those that could not go back and the manifest, kept aside with them ({}): rename them back \
         before another run in this folder, which removes them",
        kept.len(),
        kept_words(kept)
    )]
    NotPutBack { source: Box<ExportError>, kept: Vec<(PathBuf, PathBuf)> },
    /// A file that could not be made in a folder that exists because the folder refused it:
    /// the folder is what the user has to change (it said "cannot write ro/.NAME.lock").
    #[error("cannot write in folder {folder} (making {name} there): {source}")]
    FolderNotWritable { folder: PathBuf, name: String, source: std::io::Error },
    /// A missing output folder that could not be made: the first one missing, in the folder
    /// that refused it (it said "cannot write ro/a/b/c", three levels below `ro`).
    #[error("cannot create folder {path}: {source}")]
    CreateFolder { path: PathBuf, source: std::io::Error },
    #[error("cannot encode the {map} map: {message}")]
    Encode { map: MapKind, message: String },
    /// A manifest longer than its readers take (`manifest::MANIFEST_MAX_BYTES`): the set
    /// would be one that `verify`, a batch and the next run could not read back.
    #[error(
        "the set's manifest would be {bytes} bytes, more than its readers take ({limit} bytes): shorten the preset's \
         species or common name, or the --set overrides, which it records"
    )]
    ManifestTooLarge { bytes: usize, limit: u64 },
    #[error(
        "another snakeskin run is writing the set {name} in {dir} (it holds {dir}/.{name}.lock); run again when it has \
         finished, or write to another folder"
    )]
    Busy { dir: PathBuf, name: String },
    /// Something other than a regular file where a set's lock goes: a FIFO made the run wait
    /// for a reader for ever, a link failed with "Too many levels of symbolic links".
    #[error(
        "{path} is {kind}, not a regular file: snakeskin keeps the lock of this set there (an empty file it makes \
         itself); remove it and run again, or write to another folder"
    )]
    LockNotAFile { path: PathBuf, kind: &'static str },
    /// A file with content where a set's lock goes: not a lock (snakeskin's are empty), so
    /// not the run's to take and remove (a preset named `.NAME.lock` was removed by its own
    /// export).
    #[error(
        "{path} holds {bytes} bytes, so it is not a lock of snakeskin's (an empty file it makes itself, named after \
         the set, and removes when the run ends); move it away and run again, or write to another folder"
    )]
    LockHoldsData { path: PathBuf, bytes: u64 },
    #[error(
        "{path} exists and is not a folder, so nothing can be written into it; give the path of a folder (one that \
         exists, or one to create)"
    )]
    NotAFolder { path: PathBuf },
    /// An output file's path that ends as a folder's does (`out/`, `out/.`): it was written
    /// to after the work and failed with "Not a directory".
    /// `-` as an output file: read as standard output by most tools, it was written as a file
    /// named `-`.
    #[error("-: writing to standard output is not supported; give a file name (./- for a file named -)")]
    Stdout,
    /// `extension`: the example's, one the command writes (`folder_name`).
    #[error("{path} names a folder (it ends in a slash or a dot); give a file name, as in out/snake.{extension}")]
    FolderName { path: PathBuf, extension: &'static str },
    /// An output that names one of the command's inputs (the preset file, the jobs file):
    /// it replaced the input, and the command could not be run again.
    #[error("{output} would be written over this command's input {input} (the same file); move or rename one of them")]
    OverwritesInput { output: PathBuf, input: PathBuf },
    /// The command's input file where the set's (or export's) lock goes: the run would take
    /// it as its lock and remove it as it ends.
    #[error(
        "the input {input} is where this run keeps its lock (.NAME.lock, which it takes and removes as it ends); \
         rename the file"
    )]
    InputAtLock { input: PathBuf },
    /// An output named for another format (`preview --out x.jpg`, `--plot x.png`): it was
    /// written in its own format under that name, without a word.
    #[error("{path}: this output is a .{format} file; give it a name ending in .{format} (it ends in .{extension})")]
    NamedForAnotherFormat { path: PathBuf, format: &'static str, extension: String },
    /// An output named without an extension where a file of another kind stands
    /// (`gallery -o notes` over a text file named `notes`): it was replaced without a word.
    #[error(
        "{path} exists and is not a .{format} file; an output named without an extension replaces only a file of its \
         own format: give a name ending in .{format}, or move the file away"
    )]
    WouldReplaceAnotherKind { path: PathBuf, format: &'static str },
    /// A file the tool names itself (a batch's index, a close-up) where a file of another
    /// kind stands (`check_replaces_its_own`).
    #[error(
        "{path} exists and is not a {format} this tool wrote, which it would replace: move the file away, or give \
         another folder"
    )]
    NotOurs { path: PathBuf, format: &'static str },
    /// `-o .png`: Rust reads it as a hidden file named `.png` with no extension, and it was
    /// written so, out of sight of `ls`.
    #[error("{path}: the file's name is only an extension; give it a name, e.g. snake.{format}")]
    OnlyAnExtension { path: PathBuf, format: &'static str },
    /// A `.gltf` beside another whose name differs only in the extension's case (`x.GLTF`
    /// and `x.gltf`): both name their side files after the stem (`x.bin`, `x.basecolor.png`),
    /// and the second export wrote over the first's, which then read a buffer of another
    /// length and images of another export, without a word (a hostile-input sweep).
    #[error(
        "{path}: {other} beside it is a .gltf file whose name differs only in the extension's case, and a .gltf's \
         side files are named after its stem ({stem}.bin and its images): this export would replace the side files \
         that a document of that name reads; give this export another name, or move {other} and its side files away"
    )]
    SharesSideFiles { path: PathBuf, other: PathBuf, stem: String },
    #[error(
        "{path} is {kind}, not a regular file: snakeskin writes an output whole and renames it over the old one, \
         which would replace it; give the path of a regular file (or of none)"
    )]
    NotAFile { path: PathBuf, kind: &'static str },
    #[error(
        "cannot write {path}: a folder is in the way of this output file; move or rename the folder, or write elsewhere"
    )]
    FolderInTheWay { path: PathBuf },
    #[error(
        "{path} is a symbolic link to nothing (its target is missing, or a loop of links); make its target, remove \
         the link, or write elsewhere"
    )]
    BrokenLink { path: PathBuf },
    #[error(
        "cannot write {path}: its file name is {bytes} bytes long, and file systems take at most {limit}; give a shorter name"
    )]
    NameTooLong { path: PathBuf, bytes: usize, limit: usize },
    /// A folder of an output's path whose name no file system takes (`check_folder`): it
    /// failed as the folder was made, "File name too long (os error 36)", exit 1.
    #[error(
        "cannot make folder {folder}: its name is {bytes} bytes long, and file systems take at most {limit}; give a \
         shorter name"
    )]
    FolderNameTooLong { folder: PathBuf, bytes: usize, limit: usize },
    /// An output's folder path too long for the system to take with a file's name in it
    /// (`check_folder`): it failed naming the first folder it made ("cannot create folder dd:
    /// File name too long").
    #[error(
        "the folder {path:.80}… is {bytes} bytes long, and an output's folder may be at most {limit} (a path is at \
         most 4095 bytes, and a file name in it up to 255 more); give a shorter path"
    )]
    PathTooLong { path: String, bytes: usize, limit: usize },
    /// An output's path that goes up (`..`) out of a folder that does not exist
    /// (`ghost/../x.png`): no system resolves it (`ls ghost/..` fails), and making it resolve
    /// made `ghost`, left empty after the run, and a run that failed there left it too (a
    /// hostile-input sweep).
    #[error(
        "{path}: the path goes up (..) out of {missing}, which does not exist; give the path without it, or make the \
         folder first"
    )]
    ThroughMissingFolder { path: PathBuf, missing: PathBuf },
    #[error(
        "cannot write {path:?}: the path has a control character (a newline, a tab, an escape) or bytes that are \
         not UTF-8, which the lists of files written cannot show as they are (a script reading them would get \
         another path); give a path without them, in its folders' names too"
    )]
    NotListable { path: PathBuf },
    #[error("set {manifest}: {problem}")]
    Verify { manifest: PathBuf, problem: String },
    #[error("cannot encode the packed {texture} texture: {message}")]
    Pack { texture: &'static str, message: String },
    #[error("cannot write the glTF file: {0}")]
    Gltf(String),
}

impl ExportError {
    /// `FolderName` for `path`, its example's extension the path's where it is one of
    /// `accepted` (`snake.glb/` for `--gltf`), else the first: `foo.glb/` said "as in
    /// out/snake.png" to `--gltf`, which refuses that name.
    pub fn folder_name(path: &std::path::Path, accepted: &[&'static str]) -> ExportError {
        let written = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase());
        let extension = accepted.iter().copied().find(|e| written.as_deref() == Some(*e)).unwrap_or(accepted[0]);
        ExportError::FolderName { path: path.into(), extension }
    }
}

/// The extensions of the files the commands write one by one (`check_target`), the first
/// the most common, for `ExportError::folder_name`.
pub const OUTPUT_EXTENSIONS: [&str; 3] = ["png", "svg", "exr"];

impl ExportError {
    /// True when the user's input is at fault: an output folder that is not a folder, an
    /// output file that is something other than a file (a folder in its way included, as a
    /// link there is, and a link to nothing where a folder goes).
    pub fn is_invalid_input(&self) -> bool {
        matches!(
            self,
            ExportError::NotAFolder { .. }
                | ExportError::NotAFile { .. }
                | ExportError::LockNotAFile { .. }
                | ExportError::LockHoldsData { .. }
                | ExportError::FolderInTheWay { .. }
                | ExportError::FolderName { .. }
                | ExportError::Stdout
                | ExportError::NamedForAnotherFormat { .. }
                | ExportError::WouldReplaceAnotherKind { .. }
                | ExportError::NotOurs { .. }
                | ExportError::OnlyAnExtension { .. }
                | ExportError::OverwritesInput { .. }
                | ExportError::SharesSideFiles { .. }
                | ExportError::InputAtLock { .. }
                | ExportError::BrokenLink { .. }
                | ExportError::NameTooLong { .. }
                | ExportError::FolderNameTooLong { .. }
                | ExportError::PathTooLong { .. }
                | ExportError::ThroughMissingFolder { .. }
                | ExportError::NotListable { .. }
                | ExportError::ManifestTooLarge { .. }
        )
    }
}

/// `NotPutBack`'s files in words: each temporary and the name it had.
fn kept_words(kept: &[(PathBuf, PathBuf)]) -> String {
    let name = |path: &PathBuf| path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    kept.iter()
        .map(|(temporary, was)| format!("{} was {}", temporary.display(), name(was)))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Whether `c` changes the order or the lines in which a terminal or an editor shows the text
/// around it: Unicode's bidirectional controls (UAX #9, section 2: the embeddings and
/// overrides U+202A to U+202E, the isolates U+2066 to U+2069, the marks U+200E, U+200F and
/// U+061C), and the line and paragraph separators U+2028 and U+2029 (a line break to an
/// editor, to Python's `splitlines`). In a file name the first make one that ends `.exe`
/// show as ending `.png` ("Trojan Source", CVE-2021-42574), the second split a listing's
/// line; being no control characters (`char::is_control`), they were written raw. Refused in
/// the names a run writes (`unfit_for_file_names`), escaped wherever text from a file or a
/// path is printed (`toml_text::one_line`, the binary's `printable`).
pub fn reshapes_text(c: char) -> bool {
    matches!(
        c,
        '\u{061C}' | '\u{200E}' | '\u{200F}' | '\u{202A}'..='\u{202E}' | '\u{2066}'..='\u{2069}' | '\u{2028}' | '\u{2029}'
    )
}

/// What makes `name` unfit to be carried by a set's file names (its maps and manifest are
/// named after the preset file's stem, a `.gltf`'s side files after the `.gltf`'s), None
/// where it is fit: control characters (a newline in a name broke every listing and script
/// that reads the files), or a backslash (a folder's separator on Windows, where the set may
/// be read: a preset `a\b.toml` made a manifest naming `a\b_color.png`, which `verify`
/// refused, so `batch` never took the set as done and made it at every run), a
/// bidirectional control or a line separator (`reshapes_text`). Asked of a preset file's stem, of a `.gltf`'s,
/// and of the map files a manifest names (`verify`).
pub fn unfit_for_file_names(name: &str) -> Option<&'static str> {
    if name.chars().any(char::is_control) {
        return Some("control characters");
    }
    if name.chars().any(reshapes_text) {
        return Some(
            "bidirectional controls or line separators (they show a name's text in another order or on lines of its \
             own)",
        );
    }
    if name.contains('\\') {
        return Some("a backslash (a folder's separator on Windows)");
    }
    None
}

/// File name of a map for a preset name (PNG).
pub fn map_file_name(preset_name: &str, map: MapKind) -> String {
    map_file_name_in(preset_name, map, FileFormat::Png)
}

/// File name of a map for a preset name in a file format.
pub fn map_file_name_in(preset_name: &str, map: MapKind, format: FileFormat) -> String {
    format!("{preset_name}_{}.{}", map.name(), format.name())
}

/// Every file name a set named `set_name` can have: each map in each format, each pack's
/// textures, and the manifest. A commit removes no file of an earlier set but these, and a
/// run sweeps the stale temporaries of these only: set `a`'s names are never set `a_b`'s.
pub fn every_set_file_name(set_name: &str) -> Vec<String> {
    let mut names: Vec<String> = MapKind::EVERY
        .iter()
        .flat_map(|map| [FileFormat::Png, FileFormat::Exr].map(|format| map_file_name_in(set_name, *map, format)))
        .collect();
    for pack in pack::Pack::ALL {
        for (film, ao) in [(true, true), (false, false)] {
            names.extend(pack.textures(film, ao).iter().map(|spec| pack::texture_file_name(set_name, spec)));
        }
    }
    names.push(manifest_file_name(set_name));
    names.sort();
    names.dedup();
    names
}

/// Every file name a run holding the lock of `name` (`SetLock`) may write: a set's
/// (`every_set_file_name`) and a glTF export's of that stem (`.glb`, or `.gltf` with its
/// buffer and images), which take the same lock. Under it every temporary of these is stale
/// and goes: a `.gltf` export killed mid-run left its buffer's and images' temporaries, and a
/// later `.glb` export of that name, which writes none of them, kept them (an interruption
/// review: 14 MB beside the new `.glb`). A commit still removes only a set's own names.
pub fn every_file_name_under_lock(name: &str) -> Vec<String> {
    let mut names = every_set_file_name(name);
    names.extend(gltf::gltf_side_file_names(name, true));
    names.extend(["glb", "gltf"].map(|extension| format!("{name}.{extension}")));
    names.sort();
    names.dedup();
    names
}

/// OpenEXR's `wrapmodes` attribute of a set's maps (horizontal, then vertical: the standard
/// attribute's keywords, OpenEXR's ImfStandardAttributes.h): a tile repeats both ways; a
/// body atlas repeats around the body and stops at the snout and the tail tip, as the
/// glTF export's samplers say.
pub fn exr_wrap_modes(wraps_v: bool) -> &'static str {
    if wraps_v { "periodic" } else { "periodic,clamp" }
}

/// Encodes one map as OpenEXR (`MapKind::exr_channels`): linear floats in physical units —
/// the colour map's linear values, the normal's xyz in [-1, 1], the film thickness in nm
/// (`thickness_nm` = the manifest's range the map's [0, 1] spans) — with the set's wrap
/// modes (`exr_wrap_modes`) and, on the colour map, the sRGB primaries and white as its
/// `chromaticities`.
pub fn encode_exr(
    map: MapKind,
    image: &Image,
    thickness_nm: (f64, f64),
    wraps_v: bool,
) -> Result<Vec<u8>, ExportError> {
    use exr::prelude::*;
    let (names, sample) = map.exr_channels();
    let (w, h, ch) = (image.width, image.height, image.channels);
    let value = |x: f32| match map {
        MapKind::Iridescence => (thickness_nm.0 + x as f64 * (thickness_nm.1 - thickness_nm.0)) as f32,
        _ => x,
    };
    let channels: SmallVec<[AnyChannel<FlatSamples>; 4]> = names
        .iter()
        .enumerate()
        .map(|(c, name)| {
            let samples = image.data.iter().skip(c.min(ch - 1)).step_by(ch).map(|x| value(*x));
            let data = match sample {
                crate::material::ExrSample::Half => FlatSamples::F16(samples.map(f16::from_f32).collect()),
                crate::material::ExrSample::Float => FlatSamples::F32(samples.collect()),
            };
            AnyChannel::new(*name, data)
        })
        .collect();
    let mut exr_image = exr::image::Image::from_channels((w, h), AnyChannels::sort(channels));
    exr_image.layer_data.attributes.wrap_mode_name = Some(Text::from(exr_wrap_modes(wraps_v)));
    if map == MapKind::Color {
        // Readers that convert colour (OCIO, Nuke, Resolve) read the primaries from here;
        // without them they assume Rec. 709, which is what the values are, but a file
        // should say so. Data maps carry none: their channels are not colours.
        let [r, g, b, white] = crate::optics::spectrum::SRGB_PRIMARIES_XY.map(|[x, y]| Vec2(x as f32, y as f32));
        exr_image.attributes.chromaticities =
            Some(exr::meta::attribute::Chromaticities { red: r, green: g, blue: b, white });
    }
    let mut bytes = Cursor::new(Vec::new());
    exr_image.write().to_buffered(&mut bytes).map_err(|e| ExportError::Encode { map, message: e.to_string() })?;
    Ok(bytes.into_inner())
}

/// A sample on [0, 1] to 8 bits, rounded to nearest (every map and packed channel).
pub(crate) fn unit_to_u8(x: f32) -> u8 {
    (x.clamp(0.0, 1.0) * 255.0 + 0.5) as u8
}

/// A sample on [0, 1] to 16 bits, rounded to nearest.
pub(crate) fn unit_to_u16(x: f32) -> u16 {
    (x.clamp(0.0, 1.0) * 65535.0 + 0.5) as u16
}

/// A map quantised to its file format (DESIGN.md's formats), ready to encode; a quarter
/// to an eighth of the f32 image's memory, so maps are quantised as soon as they are done.
#[derive(Debug, Clone)]
pub struct Quantized {
    pub map: MapKind,
    pub width: usize,
    pub height: usize,
    pub samples: Vec<u8>,
    pub color: ExtendedColorType,
}

/// Quantises a map to its file format (`MapKind::format`: encoding, channels, bit depth);
/// 16-bit samples big-endian, the order PNG stores them in, so the encoder takes the
/// buffer as it is. (`image`'s `PngEncoder` takes native order and swaps into a second
/// buffer of the map's size: 8 MiB at 2048², whose pages the swap read before writing
/// them, and a later buffer at those addresses then paid a copy-on-write fault with a TLB
/// shootdown per page; BENCHMARKS.md, "Copy-on-write faults".)
pub fn quantize(map: MapKind, image: &Image) -> Quantized {
    let row_len = image.width * image.channels;
    let row_bytes = row_len * (map.format().bit_depth as usize / 8);
    // Into one buffer of the final size, its pages first touched by the rows' writes (a
    // fresh allocation of this size is mapped zeroed, not written): collecting the bytes
    // of a `flat_map_iter` grew a vector per rayon task and joined them, and glibc keeps
    // the freed pieces in its worker arenas.
    let mut samples = vec![0u8; image.height * row_bytes];
    samples.par_chunks_mut(row_bytes.max(1)).zip(image.data.par_chunks(row_len.max(1))).for_each(|(out, values)| {
        quantize_row(map, values, out);
    });
    Quantized { map, width: image.width, height: image.height, samples, color: color_type(map) }
}

/// `quantize` of a map given a row at a time by `row` (which writes row y's samples, as
/// many per pixel as the map's format has channels, into its buffer), the same bytes: for
/// a map whose last step only feeds the file (the normal map from the height map,
/// `filters::height_to_normal_rows`), without an image of its f32 samples.
pub fn quantize_rows(map: MapKind, width: usize, height: usize, row: impl Fn(usize, &mut [f32]) + Sync) -> Quantized {
    let format = map.format();
    let row_len = width * format.channels as usize;
    let row_bytes = row_len * (format.bit_depth as usize / 8);
    let mut samples = vec![0u8; row_bytes * height];
    samples.par_chunks_mut(row_bytes.max(1)).enumerate().for_each_init(
        || vec![0.0f32; row_len],
        |values, (y, out)| {
            row(y, values);
            quantize_row(map, values, out);
        },
    );
    Quantized { map, width, height, samples, color: color_type(map) }
}

/// A map's f32 samples to the file's scale, before rounding (`MapKind::format`'s encoding).
fn sample_encoding(map: MapKind) -> impl Fn(f32) -> f32 + Sync {
    let encoding = map.format().encoding;
    move |x: f32| encode(encoding, x)
}

/// The stored value on [0, 1] of a linear sample in `encoding`: the one home of the map
/// files' encodings (a pack's channels take theirs from here too, `pack::Transfer`).
pub(crate) fn encode(encoding: Encoding, x: f32) -> f32 {
    match encoding {
        Encoding::Srgb => linear_to_srgb8(x) as f32 / 255.0,
        Encoding::Linear => x,
        Encoding::SignedUnit => x * 0.5 + 0.5,
    }
}

/// The file's samples of `values` into `out` (8 bits, or 16 bits big-endian: the order PNG
/// stores them in): the one quantisation of every map file.
fn quantize_row(map: MapKind, values: &[f32], out: &mut [u8]) {
    let encode = sample_encoding(map);
    if map.format().bit_depth == 8 && map.format().encoding == Encoding::Srgb {
        // The sRGB code itself: `sample_encoding` scales it to [0, 1] and `unit_to_u8` gives
        // the same code back for every code (`tests`), so the round trip (a division and a
        // multiplication a sample, and the table found a sample at a time) is skipped.
        srgb::linear_to_srgb8_row(values, out);
    } else if map.format().bit_depth == 8 {
        for (o, &x) in out.iter_mut().zip(values) {
            *o = unit_to_u8(encode(x));
        }
    } else {
        for (o, &x) in out.chunks_exact_mut(2).zip(values) {
            o.copy_from_slice(&unit_to_u16(encode(x)).to_be_bytes());
        }
    }
}

fn color_type(map: MapKind) -> ExtendedColorType {
    match (map.format().channels, map.format().bit_depth) {
        (3, 8) => ExtendedColorType::Rgb8,
        (1, 8) => ExtendedColorType::L8,
        (1, 16) => ExtendedColorType::L16,
        other => unreachable!("MapKind::format has no {other:?} layout"),
    }
}

/// `quantize` of a `width` × `height` single-channel map that holds `value` everywhere (a
/// species without a film: its thickness map, `graph::Graph::constant_output`), without
/// the map's f32 image: one pixel quantised and its samples repeated, the same bytes. Zeros
/// are written too: a fresh zeroed buffer that the encoder only read mapped the kernel's
/// shared zero page, and the next buffer the allocator placed there paid a copy-on-write
/// fault and a TLB shootdown per page (BENCHMARKS.md, "Copy-on-write faults"). None
/// for a map of more than one channel.
pub fn quantize_constant(map: MapKind, width: usize, height: usize, value: f32) -> Option<Quantized> {
    if map.format().channels != 1 {
        return None;
    }
    let pixel = quantize(map, &Image { width: 1, height: 1, channels: 1, data: vec![value] });
    Some(Quantized { width, height, samples: pixel.samples.repeat(width * height), ..pixel })
}

/// Encodes a quantised map as PNG bytes.
pub fn encode_quantized(q: &Quantized) -> Result<Vec<u8>, ExportError> {
    // Room for the whole file up front (the samples and a margin for incompressible ones):
    // the pages are resident only as they are written, and a vector grown by doubling
    // leaves its earlier pieces in the encoder thread's allocator arena.
    let mut out = Vec::with_capacity(q.samples.len() + q.samples.len() / 64 + (1 << 16));
    write_whole(png_encoder(&mut out, q.map, q.width, q.height), &q.samples)
        .map_err(|e| ExportError::Encode { map: q.map, message: e.to_string() })?;
    Ok(out)
}

/// Writes a whole image's samples through `encoder`: header, data, end.
fn write_whole<W: std::io::Write>(encoder: png::Encoder<'_, W>, samples: &[u8]) -> Result<(), png::EncodingError> {
    let mut writer = encoder.write_header()?;
    writer.write_image_data(samples)?;
    writer.finish()
}

/// Encodes an 8-bit RGB image for the eye (a render, a sheet, a figure: `rgb`, rows top
/// first) as PNG bytes, tagged sRGB as the colour maps are, so that a reader that honours
/// tags shows every image snakeskin writes alike (the renders were written untagged by
/// the `image` crate). Balanced compression, the `image` crate's default before: these
/// files are kept (docs/), so the smaller file is worth the time.
pub fn encode_srgb_image_png(width: u32, height: u32, rgb: &[u8]) -> Result<Vec<u8>, String> {
    let mut out = Vec::new();
    let mut encoder = png_file_encoder(&mut out, width as usize, height as usize, 3, 8, true);
    encoder.set_compression(png::Compression::Balanced);
    write_whole(encoder, rgb).map_err(|e| e.to_string())?;
    Ok(out)
}

/// Encodes one map as PNG bytes.
pub fn encode_png(map: MapKind, image: &Image) -> Result<Vec<u8>, ExportError> {
    encode_quantized(&quantize(map, image))
}

/// A PNG written a band of rows at a time (a body atlas too long to hold as one image):
/// the same format as `encode_quantized` (`MapKind::format`, fast compression, adaptive
/// filter), into memory.
pub struct RowEncoder {
    pub map: MapKind,
    writer: png::StreamWriter<'static, SharedBuffer>,
    buffer: SharedBuffer,
}

/// The file's bytes, shared with the PNG writer: `StreamWriter::finish` consumes the writer
/// (its drop writes the end chunk), so the bytes are read back through this handle.
#[derive(Clone, Default)]
pub(crate) struct SharedBuffer(pub(crate) std::sync::Arc<std::sync::Mutex<Vec<u8>>>);

impl std::io::Write for SharedBuffer {
    fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
        self.0.lock().expect("PNG buffer").extend_from_slice(bytes);
        Ok(bytes.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// The PNG encoder of every map file (`MapKind::format`'s channels and depth), for whole
/// images (`encode_quantized`) and for bands (`RowEncoder`): one format written one way.
fn png_encoder<W: std::io::Write>(out: W, map: MapKind, width: usize, height: usize) -> png::Encoder<'static, W> {
    let format = map.format();
    png_file_encoder(out, width, height, format.channels as usize, format.bit_depth, format.encoding == Encoding::Srgb)
}

/// The PNG encoder of every map, packed texture and image (`encode_srgb_image_png`:
/// renders, figures, sheets). Colour is tagged sRGB (the `sRGB` chunk), so a reader that
/// honours tags shows it as written; data (height, normal, roughness, thickness, masks)
/// carries no tag, as engines expect of non-colour textures (PNG has no "data" tag: a
/// `gAMA` of 1.0 would make a viewer that honours it brighten a normal map on screen), and
/// the manifest names its colour space. Fast compression (fdeflate), adaptive filter. A
/// 16-bit map's low bytes are noise to deflate, so its file is about its raw size: a whole
/// image is stored uncompressed where fdeflate's is larger (a 512² tile's height map, 1.001
/// of raw), but a stream (`RowEncoder`, a pack's `TextureEncoder`) cannot fall back so, as
/// png's `DeflateCompression::FdeflateUltraFast` says: an `unreal` pack's 256² height came
/// out 1.165 of raw and a 64-wide body atlas's 1.17 (an independent check of the files),
/// 0.93 at 2048² and 0.85 in a 1024-wide body atlas. zlib at level 1 in the streams (it
/// falls back block by block) gave 0.96, 0.83 and 0.77, but cost 0.1–0.4 s more CPU a set
/// (an `unreal` pack at 2048², a 1024-wide body atlas: a sixth of the run) for 4–6 % of the
/// set's bytes: not kept. zlib at level 6 would save about a tenth (a 512-wide body atlas's
/// height map: 5.58 MB against 6.30 MB raw, measured with Python's zlib), not worth a
/// slower encoder on the set's critical path.
pub(crate) fn png_file_encoder<W: std::io::Write>(
    out: W,
    width: usize,
    height: usize,
    channels: usize,
    bit_depth: u32,
    srgb: bool,
) -> png::Encoder<'static, W> {
    let mut encoder = png::Encoder::new(out, width as u32, height as u32);
    encoder.set_color(match channels {
        1 => png::ColorType::Grayscale,
        3 => png::ColorType::Rgb,
        4 => png::ColorType::Rgba,
        n => unreachable!("a PNG of snakeskin's has 1, 3 or 4 channels, not {n}"),
    });
    encoder.set_depth(if bit_depth == 16 { png::BitDepth::Sixteen } else { png::BitDepth::Eight });
    if srgb {
        encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    }
    encoder.set_compression(png::Compression::Fast);
    encoder.set_filter(png::Filter::Adaptive);
    encoder
}

impl RowEncoder {
    pub fn new(map: MapKind, width: usize, height: usize) -> Result<RowEncoder, ExportError> {
        let error = |e: png::EncodingError| ExportError::Encode { map, message: e.to_string() };
        let buffer = SharedBuffer::default();
        let writer = png_encoder(buffer.clone(), map, width, height)
            .write_header()
            .map_err(error)?
            .into_stream_writer()
            .map_err(error)?;
        Ok(RowEncoder { map, writer, buffer })
    }

    /// Appends whole rows of the map (the image's rows `rows`).
    pub fn write_rows(&mut self, image: &Image, rows: std::ops::Range<usize>) -> Result<(), ExportError> {
        let samples = Self::samples(self.map, image, rows);
        self.write_samples(&samples)
    }

    /// The file's samples of the image's rows `rows` (quantised, 16-bit big-endian): the
    /// cheap half of `write_rows`, so a caller can quantise as maps finish and compress on
    /// another thread (`write_samples`).
    pub fn samples(map: MapKind, image: &Image, rows: std::ops::Range<usize>) -> Vec<u8> {
        quantize(map, &image.band(rows)).samples
    }

    /// Appends samples from `samples` (whole rows, in order).
    pub fn write_samples(&mut self, samples: &[u8]) -> Result<(), ExportError> {
        use std::io::Write;
        self.writer.write_all(samples).map_err(|e| ExportError::Encode { map: self.map, message: e.to_string() })
    }

    /// The finished file's bytes (every row must have been written).
    pub fn finish(self) -> Result<Vec<u8>, ExportError> {
        let map = self.map;
        let error = |e: png::EncodingError| ExportError::Encode { map, message: e.to_string() };
        self.writer.finish().map_err(error)?;
        let bytes = std::mem::take(&mut *self.buffer.0.lock().expect("PNG buffer"));
        Ok(bytes)
    }
}

/// Encodes quantised maps in parallel; returns (file name, bytes) in the given order.
pub fn encode_all(preset_name: &str, maps: &[Quantized]) -> Result<Vec<(String, Vec<u8>)>, ExportError> {
    maps.par_iter().map(|q| Ok((map_file_name(preset_name, q.map), encode_quantized(q)?))).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `quantize_row`'s sRGB shortcut writes the code where the general path scales it to
    /// [0, 1] and rounds it back: the same byte for every code. Negative control: a scale of
    /// 1/256 does not give the codes back.
    #[test]
    fn every_srgb_code_comes_back_from_unit() {
        for k in 0..=255u8 {
            assert_eq!(unit_to_u8(k as f32 / 255.0), k);
        }
        assert!((0..=255u8).any(|k| unit_to_u8(k as f32 / 256.0) != k));
    }

    /// The colour map's rows against the general per-sample path, over values inside and
    /// outside [0, 1], the floats next to code boundaries and NaN.
    #[test]
    fn srgb_rows_are_the_per_sample_round_trip() {
        let encode = sample_encoding(MapKind::Color);
        let mut values: Vec<f32> = (0..=20_000).map(|i| i as f32 / 20_000.0 * 1.2 - 0.1).collect();
        values.extend([f32::NAN, f32::INFINITY, f32::NEG_INFINITY, -0.0, f32::MIN_POSITIVE, 0.003_130_8]);
        for k in 1..=255u8 {
            // The smallest float that encodes to k, and its neighbours.
            // (Bisection over the bit patterns, which order non-negative floats.)
            let (mut low, mut high) = (0u32, 1.0f32.to_bits());
            while low < high {
                let mid = low + (high - low) / 2;
                if linear_to_srgb8(f32::from_bits(mid)) >= k { high = mid } else { low = mid + 1 }
            }
            let start = f32::from_bits(low);
            values.extend([
                f32::from_bits(start.to_bits().saturating_sub(1)),
                start,
                f32::from_bits(start.to_bits() + 1),
            ]);
        }
        let mut rows = vec![0u8; values.len()];
        quantize_row(MapKind::Color, &values, &mut rows);
        let each: Vec<u8> = values.iter().map(|&x| unit_to_u8(encode(x))).collect();
        assert_eq!(rows, each);
    }
}
