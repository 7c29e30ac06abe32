//! `<name>.material.json`: what each file is, so a renderer or pipeline can use the set
//! without guessing (colour space, bit depth, meaning, the film thickness range the
//! iridescence map spans as glTF's KHR_materials_iridescence does, the layer optics), and
//! the SHA-256 of every map: the manifest is the set's commit record (`atomic.rs`), and
//! `verify_set` is how a reader checks that the files are the ones it describes.

use std::path::{Path, PathBuf};

use serde::Serialize;

use super::ExportError;
use super::pack::TextureSpec;
use crate::maps::{BuildOptions, Layout, body_plan};
use crate::material::{FileFormat, MapKind, NormalConvention, Optics};
use crate::preset::LoadedPreset;
use crate::text_file::Links;

#[derive(Debug, Serialize)]
pub struct Manifest {
    /// What made the set (written in place, the manifest's first keys).
    #[serde(flatten)]
    pub source: Source,
    /// `png` or `exr` (the maps' file format; each entry gives its samples).
    pub format: String,
    /// The engine the textures are packed for (`generate --pack`), if any: `maps` then
    /// lists the packed textures, each with what its channels hold.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pack: Option<String>,
    /// Body layout: the counts the atlas was drawn with.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub counts: Option<Counts>,
    /// Body layout: the v range (0 snout .. 1 tail tip) of each region.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub regions: Option<Regions>,
    /// How the maps lie on the snake (`TILE_TEXTURE_SPACE`, `BODY_TEXTURE_SPACE`): what an
    /// artist needs to map them onto a mesh, which the keys alone did not say (where the
    /// belly is, which image row is the snout, which edges wrap: a sweep).
    pub texture_space: String,
    pub maps: Vec<MapEntry>,
    pub iridescence: IridescenceRange,
    /// The height map's physical scale (not `height`, the image's rows, beside `width`).
    pub displacement: HeightScale,
    /// The normal map's convention (`NormalConvention::name`): `opengl`, +Y up (glTF,
    /// Blender, Unity), or `directx`, +Y down (Unreal).
    pub normal_convention: String,
    pub optics: Optics,
    /// What the colour map's values are (`COLOR_MEANS`).
    pub color_means: String,
    /// Preset colours the stack cannot show, clamped to its limit (`preset::visible`).
    pub clamped_colors: Vec<crate::preset::visible::ClampedColour>,
    /// The batch job that wrote the set (`batch::Job::key`), if any.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub job: Option<String>,
}

/// What made a set or a model: the manifest's first keys, and a glTF asset's `extras`
/// (`gltf_export`), so a file is traced to its preset, its content and its seed the same
/// way wherever it went.
#[derive(Debug, Clone, Serialize)]
pub struct Source {
    pub generator: String,
    pub generator_version: String,
    pub preset: String,
    pub preset_hash: String,
    /// The `--set` overrides (and a jobs file's `set`) as given, `KEY=VALUE` in order; absent
    /// where there were none.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub overrides: Vec<String>,
    pub species: Option<String>,
    pub seed: u64,
    pub width: usize,
    pub height: usize,
    /// `tile` (a square that tiles both ways) or `body` (the whole snake, snout at v = 0).
    pub layout: String,
}

impl Source {
    pub fn of(loaded: &LoadedPreset, (width, height): (usize, usize), layout: Layout) -> Source {
        Source {
            generator: "snakeskin".into(),
            generator_version: env!("CARGO_PKG_VERSION").into(),
            preset: loaded.name.clone(),
            preset_hash: loaded.content_hash.clone(),
            overrides: loaded.overrides.iter().map(|(key, value)| format!("{key}={value}")).collect(),
            species: loaded.preset.species.clone(),
            seed: loaded.preset.seed,
            width,
            height,
            layout: layout.name().into(),
        }
    }
}

/// The colour map's convention, for the manifest: the visible colour, which the renderer
/// inverts through the stack (`optics::brdf::layered::visible_colour`).
pub const COLOR_MEANS: &str = "visible diffuse colour: the stack's diffuse reflectance at normal incidence per \
     unit of light the top lets in, c = t1 k_d E / (1 - k_d K), per linear channel, with k_d the base's Lambertian \
     albedo, K and E the shares of the base's diffuse light that the top sends back down and lets out per bounce \
     (the film seen from below), tau = optics.absorption * optics.pigment_thickness the pigment layer's optical \
     depth (only the product matters: the two are in reciprocal relative units), and t1 = exp(-tau / \
     cos_eff(1, roughness)) the pigment layer's transmittance along the path of light the rough top lets in at \
     normal incidence, cos_eff being that path's effective cosine (1 under a smooth top: t1 = exp(-tau)) (a glTF \
     baseColor under a dielectric top); the layered model recovers the base albedo k_d = c / (t1 E + \
     c K) per pixel, the thesis model reads the map as k_d itself; see docs/presets.md";

#[derive(Debug, Serialize)]
pub struct Counts {
    /// Ventral and subcaudal plates, where the belly draws plates (`belly.plates`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ventrals: Option<u32>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub subcaudals: Option<u32>,
    /// Marks of the first counted pattern layer (`pattern.N.count`) on the trunk, neck to
    /// vent, if any (without tail bands the series runs on down the tail at its spacing),
    /// whatever the layer draws: dorsal blotches, a series each side (per side), repeats of a
    /// ring sequence. The name is the format's; the body sheet says which.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub dorsal_marks: Option<u32>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tail_bands: Option<u32>,
}

/// The counts a body atlas of `preset` is drawn with (`plan`, its `body_plan`): the
/// manifest's `counts` and the body contact sheet's labels, which named ventrals and
/// subcaudals for the species without plates.
pub fn body_counts(preset: &crate::preset::Preset, plan: &crate::ops::body::BodyPlan) -> Counts {
    let plates = preset.belly.plates && preset.belly.width > 0.0;
    Counts {
        ventrals: plates.then_some(plan.ventrals),
        subcaudals: plates.then_some(plan.subcaudals),
        dorsal_marks: preset.pattern.iter().find_map(|l| l.series_count()),
        tail_bands: (preset.body.tail_bands > 0).then_some(preset.body.tail_bands),
    }
}

/// [start, end] in v of each region of a body atlas.
#[derive(Debug, Serialize)]
pub struct Regions {
    pub head: [f32; 2],
    pub neck: [f32; 2],
    pub trunk: [f32; 2],
    /// The vent: the last ventral plate's length either side of it.
    pub vent: [f32; 2],
    pub tail: [f32; 2],
}

/// `MapEntry::sample_type` of a PNG (every packed texture is one).
const PNG_SAMPLES: &str = "uint";

#[derive(Debug, Serialize)]
pub struct MapEntry {
    pub map: String,
    pub file: String,
    pub color_space: String,
    pub channels: u32,
    pub bit_depth: u32,
    /// How a sample is stored: `uint` (PNG's unsigned integers of `bit_depth` bits, 0 to
    /// the largest value meaning 0 to 1), or OpenEXR's `half` or `float`.
    pub sample_type: String,
    pub meaning: String,
    /// SHA-256 of the file's bytes, 64 hex digits.
    pub sha256: String,
}

impl MapEntry {
    /// The entry of one of the set's maps in a file format.
    pub fn for_map(map: MapKind, file: &str, sha256: String, format: FileFormat, convention: NormalConvention) -> Self {
        let (color_space, channels, bit_depth, sample_type, meaning) = match format {
            FileFormat::Png => {
                let f = map.format();
                (f.color_space(), f.channels, f.bit_depth, PNG_SAMPLES, map.meaning(convention))
            }
            FileFormat::Exr => {
                let (names, sample) = map.exr_channels();
                ("linear", names.len() as u32, sample.bits(), sample.name(), map.exr_meaning(convention))
            }
        };
        MapEntry {
            map: map.name().into(),
            file: file.into(),
            color_space: color_space.into(),
            channels,
            bit_depth,
            sample_type: sample_type.into(),
            meaning,
            sha256,
        }
    }

    /// The entry of a packed texture (`export::pack`).
    pub fn for_texture(spec: &TextureSpec, file: &str, sha256: String) -> Self {
        MapEntry {
            map: spec.suffix.into(),
            file: file.into(),
            color_space: if spec.srgb { "srgb" } else { "linear" }.into(),
            channels: spec.channels.len() as u32,
            bit_depth: spec.bit_depth,
            sample_type: PNG_SAMPLES.into(),
            meaning: spec.meaning.clone(),
            sha256,
        }
    }
}

#[derive(Debug, Serialize)]
pub struct IridescenceRange {
    /// Whether the preset's film shows at all (`maps::has_film`). Without one the
    /// iridescence map is constant 0 and its range means nothing.
    pub film: bool,
    /// Thickness at sample value 0 and at the maximum sample value.
    pub min_nm: f64,
    pub max_nm: f64,
}

/// The physical scale of the height map.
#[derive(Debug, Serialize)]
pub struct HeightScale {
    /// How far above a sample of 0 a sample of 1 stands, in texture widths, as the normal
    /// map was made (`maps::height_rise_texture_widths`): a displacement's scale is this
    /// times the texture's width in the scene's units (the body's circumference for the
    /// body atlas).
    pub rise_texture_widths: f64,
}

/// The manifest's file name for a set name.
pub fn manifest_file_name(set_name: &str) -> String {
    format!("{set_name}{MANIFEST_SUFFIX}")
}

/// How u lies in every layout (DESIGN.md's texture space): the start of each `texture_space`.
macro_rules! u_round_the_body {
    () => {
        "u (image x, left to right) runs round the body, the belly's midline at u = 0 and 1, the spine at u = 0.5; "
    };
}

/// `texture_space` of the tile layout (DESIGN.md's texture space).
pub const TILE_TEXTURE_SPACE: &str = concat!(
    u_round_the_body!(),
    "v (image rows, top to bottom) runs along it, head to tail; the tile repeats in u and in v"
);

/// `texture_space` of the body layout (`--layout body`).
pub const BODY_TEXTURE_SPACE: &str = concat!(
    u_round_the_body!(),
    "v (image rows, top to bottom) runs along it from the snout (v = 0, the first row) to the tail tip (v = 1, the \
     last row), as glTF's v does (a mesh whose v points up reads 1 - v); the atlas wraps in u, not in v, and is \
     height / width circumferences long (the preset's body.length); `regions` are ranges of v"
);

/// What a set's name is followed by in its manifest's file name.
pub const MANIFEST_SUFFIX: &str = ".material.json";

/// The manifest of a set: `entries` its files, `format` their file format's name, `pack`
/// the engine they are packed for (whose normal convention is its own, whatever the
/// graph's).
pub fn manifest(
    loaded: &LoadedPreset,
    dimensions: (usize, usize),
    entries: Vec<MapEntry>,
    options: BuildOptions,
    format: &str,
    pack: Option<super::pack::Pack>,
) -> Manifest {
    let p = &loaded.preset;
    let body = (options.layout == Layout::Body).then(|| body_plan(p));
    let counts = body.as_ref().map(|b| body_counts(p, b));
    let regions = body.map(|b| {
        let plate = b.plate_length_v(false);
        Regions {
            head: [0.0, b.head_end],
            neck: [b.head_end, b.neck_end],
            trunk: [b.neck_end, b.vent],
            vent: [b.vent - plate, b.vent + plate],
            tail: [b.vent, 1.0],
        }
    });
    let (min_nm, max_nm) = crate::maps::map_thickness_range_nm(p);
    Manifest {
        source: Source::of(loaded, dimensions, options.layout),
        format: format.into(),
        pack: pack.map(|pack| pack.name().into()),
        counts,
        regions,
        texture_space: if options.layout == Layout::Body { BODY_TEXTURE_SPACE } else { TILE_TEXTURE_SPACE }.into(),
        maps: entries,
        iridescence: IridescenceRange { film: crate::maps::has_film(p), min_nm, max_nm },
        displacement: HeightScale { rise_texture_widths: crate::maps::height_rise_texture_widths(p) as f64 },
        normal_convention: pack.map_or(options.normal_convention, |pack| pack.normal_convention()).name().into(),
        optics: p.optics.clone(),
        color_means: COLOR_MEANS.into(),
        clamped_colors: loaded.clamped_colours.clone(),
        job: None,
    }
}

/// The most bytes a manifest of an earlier set is read to (a built-in species' body manifest
/// is under 10 KB): a link to /dev/zero or a huge file in its place is refused unread. Above
/// what any run can write: the strings it records from the user are the species (at most a
/// preset's 1 MiB), the `--set` overrides (Linux passes at most 2 MiB of arguments) or a jobs
/// file's `set` and the job's key (at most its 1 MiB each), and JSON at most doubles a string
/// (a `"` or `\\` becomes two bytes; TOML's own escapes are no shorter than JSON's): about 8.5
/// MiB with the rest. At 1 MiB, a preset whose species was 600,000 quotes wrote a manifest of
/// 1.2 MB that `verify` refused (a hostile-input sweep). `manifest_json` refuses to write one
/// over it all the same.
pub const MANIFEST_MAX_BYTES: u64 = 16 << 20;

/// A set's manifest as written (pretty JSON), refused where it is longer than its readers
/// take (`MANIFEST_MAX_BYTES`), so that no run leaves a set that cannot be read back.
pub fn manifest_json(manifest: &Manifest) -> Result<Vec<u8>, super::ExportError> {
    let json = serde_json::to_vec_pretty(manifest).expect("a manifest serialises: strings, numbers and lists");
    if json.len() as u64 > MANIFEST_MAX_BYTES {
        return Err(super::ExportError::ManifestTooLarge { bytes: json.len(), limit: MANIFEST_MAX_BYTES });
    }
    Ok(json)
}

/// An earlier set's manifest, read back and parsed (`verify_set`, `batch`, a commit's
/// clean-up): a regular file of at most `MANIFEST_MAX_BYTES`. `links`: whether a link is
/// followed (a reader's check may meet a set kept as links, as git-annex keeps files; what a
/// run may remove or replace is never reached through one: the set wrote none).
pub fn read_set_manifest(path: &Path, links: Links) -> Result<serde_json::Value, ManifestReadError> {
    let text =
        crate::text_file::read_bounded_bytes(path, MANIFEST_MAX_BYTES, links).map_err(ManifestReadError::Read)?;
    serde_json::from_slice(&text).map_err(ManifestReadError::NotJson)
}

/// Why an earlier set's manifest could not be read back (`read_set_manifest`).
#[derive(Debug)]
pub enum ManifestReadError {
    /// Missing, not a regular file, too large, or the read failed.
    Read(crate::text_file::BoundedReadError),
    NotJson(serde_json::Error),
}

/// The most bytes one file of the set a manifest describes can hold: every map of its
/// `width` × `height` pixels at 16 bytes a pixel (RGBA f32, the widest any format writes),
/// twice over for a container's overhead (a glTF's base64, a stored PNG), and a MiB for
/// headers. A file larger than that is not the set's; without the size, or with a size no
/// run writes (wider than `SIZE_RANGE`, taller than `generate::MAX_HEIGHT`: a forged
/// manifest's 2³² × 2³² made the bound wrap to nothing), nothing is.
pub fn set_file_max_bytes(json: &serde_json::Value) -> u64 {
    set_size(json).map_or(0, file_max_bytes)
}

/// `set_file_max_bytes` of a size `set_size` accepted.
fn file_max_bytes((width, height): (u64, u64)) -> u64 {
    let maps = MapKind::ALL.len() as u64;
    width * height * 16 * maps * 2 + (1 << 20)
}

/// The set's `width` and `height` as a run writes them, or why they are not (the key and
/// what is accepted: `verify` blamed every map for being "more than such a file can be"
/// where the manifest's size was missing or forged, a hostile-input review).
fn set_size(json: &serde_json::Value) -> Result<(u64, u64), String> {
    // A set is at least the smallest `--size` each way (a body atlas is taller, never
    // narrower), at most `SIZE_RANGE`'s end wide and `MAX_HEIGHT` tall.
    let least = u64::from(*crate::SIZE_RANGE.start());
    let (max_width, max_height) = (u64::from(*crate::SIZE_RANGE.end()), crate::generate::MAX_HEIGHT as u64);
    // Any integer JSON holds, so that `-1` is said to be outside, not "not an integer".
    let integer = |value: &serde_json::Value| value.as_u64().map(i128::from).or(value.as_i64().map(i128::from));
    let (width, height) = (integer(&json["width"]), integer(&json["height"]));
    let outside = |key: &str, value: i128, most: u64| {
        format!("the manifest's {key} {value} is outside what a set can be ({least} to {most} pixels)")
    };
    let within = |value: i128, most: u64| (i128::from(least)..=i128::from(most)).contains(&value);
    match (width, height) {
        (Some(width), _) if !within(width, max_width) => Err(outside("width", width, max_width)),
        (_, Some(height)) if !within(height, max_height) => Err(outside("height", height, max_height)),
        (Some(width), Some(height)) => Ok((width as u64, height as u64)),
        _ => Err("the manifest's width and height are not both integers (pixels, as a run writes them: 1024)".into()),
    }
}

/// The SHA-256 of an earlier set's file (or an earlier export's image), streamed (the file is
/// not held in memory): a regular file of at most `limit` bytes (`set_file_max_bytes`);
/// `links` as for `read_set_manifest`.
pub fn set_file_sha256(path: &Path, limit: u64, links: Links) -> Result<String, crate::text_file::BoundedReadError> {
    use crate::text_file::{BoundedReadError, check_read_length, open_bounded};
    use sha2::Digest;
    use std::io::Read;
    let file = open_bounded(path, limit, links)?;
    let mut hasher = sha2::Sha256::new();
    let read = std::io::copy(&mut (&file).take(limit.saturating_add(1)), &mut hasher).map_err(BoundedReadError::Io)?;
    check_read_length(&file, read, limit)?;
    Ok(super::atomic::hex(&hasher.finalize()))
}

/// A set whose files match its manifest.
#[derive(Debug, Clone)]
pub struct VerifiedSet {
    pub manifest: PathBuf,
    /// How many times it was checked: more than once where it was replaced while checked.
    pub tries: usize,
    /// (map name, file path) in manifest order.
    pub files: Vec<(String, PathBuf)>,
}

/// Which file `path` is (device, inode) and its length and modification time, if it is
/// there; `links` followed or not: a commit renames a new file into place, so a set made
/// meanwhile is another file even within one tick of a coarse clock.
pub type FileIdentity = (u64, u64, u64, Option<std::time::SystemTime>);

/// `FileIdentity` of `path`, None where it is not there.
pub fn file_identity(path: &Path, links: Links) -> Option<FileIdentity> {
    let m = match links {
        Links::Follow => std::fs::metadata(path),
        Links::Refuse => std::fs::symlink_metadata(path),
    }
    .ok()?;
    #[cfg(unix)]
    let (device, inode) = { (std::os::unix::fs::MetadataExt::dev(&m), std::os::unix::fs::MetadataExt::ino(&m)) };
    #[cfg(not(unix))]
    let (device, inode) = (0, 0);
    Some((device, inode, m.len(), m.modified().ok()))
}

/// How often `verify_set` checks a set again whose manifest was replaced while it checked.
const VERIFY_TRIES: usize = 3;

/// Checks a set through its manifest: every map it lists exists beside it with the SHA-256
/// it records. A set whose manifest is missing is incomplete (a run failed or was killed
/// while writing it); one whose hashes differ is mixed or altered. A set replaced while it
/// was checked (its manifest another file after its maps were read: a run committed a new
/// set meanwhile) is checked again, up to `VERIFY_TRIES` times: the new maps read against
/// the old manifest failed as "mixed or altered", 1 check in 835 beside a run making the
/// set again and again (a sweep).
pub fn verify_set(manifest_path: &Path) -> Result<VerifiedSet, ExportError> {
    let mut tries = 1;
    loop {
        let before = file_identity(manifest_path, Links::Follow);
        let result = verify_set_once(manifest_path, tries).map(|set| VerifiedSet { tries, ..set });
        if result.is_ok() || tries == VERIFY_TRIES || file_identity(manifest_path, Links::Follow) == before {
            return result;
        }
        tries += 1;
    }
}

/// `verify_set`, once (its try `try_number`).
fn verify_set_once(manifest_path: &Path, try_number: usize) -> Result<VerifiedSet, ExportError> {
    let problem = |problem: String| ExportError::Verify { manifest: manifest_path.into(), problem };
    let json = read_set_manifest(manifest_path, Links::Follow).map_err(|e| {
        problem(match e {
            ManifestReadError::Read(crate::text_file::BoundedReadError::Io(e))
                if e.kind() == std::io::ErrorKind::NotFound && manifest_path.is_symlink() =>
            {
                let target = std::fs::read_link(manifest_path).unwrap_or_default();
                format!("the manifest is a link to {}, which does not exist", target.display())
            }
            ManifestReadError::Read(crate::text_file::BoundedReadError::Io(e))
                if e.kind() == std::io::ErrorKind::NotFound =>
            {
                "no manifest: the set is incomplete (a run failed or was killed while writing it)".into()
            }
            ManifestReadError::Read(e) => format!("cannot read the manifest: {e}"),
            ManifestReadError::NotJson(e) => format!("the manifest is not valid JSON: {e}"),
        })
    })?;
    super::atomic::pause_hook(|| format!("verify-{try_number}"));
    verify_set_json(manifest_path, &json)
}

/// `verify_set` for a manifest already read (`json`, from `manifest_path`): `batch` reads it
/// once for its job key and the files it lists.
pub(crate) fn verify_set_json(manifest_path: &Path, json: &serde_json::Value) -> Result<VerifiedSet, ExportError> {
    let problem = |problem: String| ExportError::Verify { manifest: manifest_path.into(), problem };
    let dir = manifest_path.parent().unwrap_or(Path::new("."));
    let file_limit = set_size(json).map(file_max_bytes).map_err(problem)?;
    let maps = json["maps"]
        .as_array()
        .filter(|m| !m.is_empty())
        .ok_or_else(|| problem("the manifest lists no maps".into()))?;
    // No set has more files than a set can be named (`every_set_file_name`, its manifest
    // aside): a forged manifest of 330,000 entries within the read limit took the duplicate
    // check below an hour (80,000 entries: 309 s; a hostile-input sweep).
    let most = super::every_set_file_name("").len() - 1;
    if maps.len() > most {
        return Err(problem(format!("the manifest lists {} maps; a set has at most {most} files", maps.len())));
    }
    // The set's own file names, where the manifest is named as a set's (`NAME.material.json`):
    // another set's manifest copied or renamed over this one listed that set's files, and
    // `verify` said `ok` of a set whose own maps it never looked at (a sweep). A link's name
    // is its target's: `latest.material.json` linking to `boa.material.json` is boa's set
    // (the review).
    let named = std::fs::canonicalize(manifest_path).unwrap_or_else(|_| manifest_path.to_path_buf());
    let set_name = named.file_name().and_then(|n| n.to_str()).and_then(|n| n.strip_suffix(MANIFEST_SUFFIX));
    let own_files = set_name.map(super::every_set_file_name);
    let mut foreign = Vec::new();
    let mut files = Vec::new();
    // Every map's problem, not the first only: a set with a missing map and an altered one
    // took two runs of `verify` to learn both (an onboarding review).
    let mut problems = Vec::new();
    for (index, entry) in maps.iter().enumerate() {
        let text = |key: &'static str| entry[key].as_str().ok_or(key);
        let (map, file, expected) = match (text("map"), text("file"), text("sha256")) {
            (Ok(map), Ok(file), Ok(expected)) => (map, file, expected),
            (map, file, expected) => {
                let keys: Vec<&str> = [map, file, expected].into_iter().filter_map(Result::err).collect();
                let (keys, are) = (keys.join(", "), if keys.len() == 1 { "is" } else { "are" });
                problems.push(format!("map entry {}: {keys} {are} missing or not text", index + 1));
                continue;
            }
        };
        // What a run records (`atomic::hex`): an empty or upper-case hash is a forged or
        // edited manifest, not an altered file (it was reported as "the set is mixed").
        if expected.len() != 64 || !expected.bytes().all(|b| b.is_ascii_digit() || (b'a'..=b'f').contains(&b)) {
            problems.push(format!("the {map} map's sha256 {expected:?} is not a SHA-256 (64 lower-case hex digits)"));
            continue;
        }
        // An empty name too: it joined to the set's folder, "it is a folder, not a regular
        // file" (a hostile-input sweep).
        if file.is_empty() || file.contains('/') || file.starts_with('.') {
            problems.push(format!("map file {file:?} is not a plain file name"));
            continue;
        }
        // A name no run writes (`super::unfit_for_file_names`).
        if let Some(what) = super::unfit_for_file_names(file) {
            problems.push(format!("map file {file:?} has {what}, which no set's file name carries"));
            continue;
        }
        if own_files.as_ref().is_some_and(|own| !own.iter().any(|name| name == file)) {
            foreign.push(file);
            continue;
        }
        if files.iter().any(|(m, p): &(String, PathBuf)| m == map || p.ends_with(file)) {
            problems.push(format!("the {map} map or its file {file:?} is listed twice"));
            continue;
        }
        let path = dir.join(file);
        match set_file_sha256(&path, file_limit, Links::Follow) {
            Err(e) => problems.push(format!("{map} map {}: {e}", path.display())),
            Ok(actual) if actual != expected => problems.push(format!(
                "{map} map {} has SHA-256 {actual}, the manifest records {expected}: the set is mixed or altered",
                path.display()
            )),
            Ok(_) => {}
        }
        files.push((map.to_string(), path));
    }
    if let (Some(first), Some(set_name)) = (foreign.first(), set_name) {
        let count = if foreign.len() == 1 { "a file".to_string() } else { format!("{} files", foreign.len()) };
        problems.insert(
            0,
            format!(
                "it lists {count} not of set {set_name:?} (the first {first:?}; a set's files are named after it, \
                 as {set_name}_color.png): the manifest is another set's, copied or renamed"
            ),
        );
    }
    if !problems.is_empty() {
        return Err(problem(problems.join("; ")));
    }
    Ok(VerifiedSet { manifest: manifest_path.into(), tries: 1, files })
}
