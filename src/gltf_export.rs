//! `snakeskin export`: a preset as a glTF 2.0 file that opens right in a viewer or an
//! engine. The maps are evaluated and packed as glTF reads them (`Pack::Gltf`, a band of
//! rows at a time, like `generate`), then put on a mesh — the preview's snake (the tile
//! repeated along it, or a body atlas once over it), or a sphere or plane to look at the
//! material alone — and written atomically: one `.glb`, or a `.gltf` with its buffer and
//! images (`NAME.ROLE.png`, named apart from a texture set's `NAME_MAP.png`) beside it, the
//! `.gltf` renamed last.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use crate::export::gltf::{
    EarlierImage, GltfMaterial, GltfTextures, earlier_image, glb, gltf_files, gltf_image_file_name,
    gltf_side_file_names,
};
use crate::export::pack::Pack;
use crate::export::{Earlier, KeptBecause, KeptFile, SetLock};
use crate::generate::{GenerateRequest, Plan};
use crate::graph::EvalStats;
use crate::maps::{Layout, has_film, thickness_range_nm};
use crate::material::{FileFormat, MapKind};
use crate::memory::MemoryCheck;
use crate::render::engine::mesh::{BodyShape, Mesh};
use crate::{Error, maps::BuildOptions};

/// The mesh the material is put on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MeshKind {
    /// The preview's snake: a tile repeated every circumference, or a body atlas once.
    Snake,
    /// A unit sphere, the tile twice round the equator (the material alone).
    Sphere,
    /// A 1 m square (a tile once), or a 1 m wide strip `body.length` long (a body atlas).
    Plane,
}

impl MeshKind {
    /// As `export --mesh` names it.
    pub fn name(self) -> &'static str {
        match self {
            MeshKind::Snake => "snake",
            MeshKind::Sphere => "sphere",
            MeshKind::Plane => "plane",
        }
    }
}

#[derive(Debug, Clone)]
pub struct ExportRequest {
    pub preset: String,
    pub overrides: Vec<(String, String)>,
    pub seed: Option<u64>,
    /// Texture width in pixels.
    pub size: u64,
    pub layout: Layout,
    pub mesh: MeshKind,
    /// The file to write: `.glb` (one file) or `.gltf` (with `.bin` and PNGs beside it).
    pub out: PathBuf,
    /// Compute the ambient occlusion map into the ORM texture's R (`occlusionTexture`).
    pub ao: bool,
}

#[derive(Debug)]
pub struct ExportReport {
    pub files: Vec<PathBuf>,
    /// The textures' width and height in pixels.
    pub dimensions: (usize, usize),
    pub stats: EvalStats,
    pub encode_time: Duration,
    pub total_time: Duration,
    /// Whether the export created the file's folder.
    pub created_folder: bool,
    /// Files of an earlier export of this name that this one removed (a `.gltf`'s thickness
    /// image, which a film of one thickness no longer references), for the caller to say.
    pub removed: Vec<PathBuf>,
    /// Such files that stay, with why (changed since the earlier export wrote them, no
    /// readable `.gltf` there says whose they are, or they would not go), for the caller to
    /// say: the export stands, and the file beside it is no longer referenced.
    pub kept: Vec<KeptFile>,
}

/// The most bytes of an earlier export's image hashed to compare with its record: a PNG of
/// the largest texture an export writes (the widest size by the tallest atlas, 8 bytes a
/// texel, stored uncompressed) and 1 MiB for its filter bytes and headers. The hash is
/// streamed; the bound stops a file that grows without end.
const EARLIER_IMAGE_MAX_BYTES: u64 =
    *crate::SIZE_RANGE.end() as u64 * crate::generate::MAX_HEIGHT as u64 * 8 + (1 << 20);

/// Removes an earlier export's image that this one no longer references, unless it changed
/// since that export wrote it (`recorded`: its SHA-256 there, None where none was recorded;
/// `regular`: a regular file, which an export writes, where anything else is not opened).
/// None when it went; else why it stays.
fn stale_image_stays(path: &Path, regular: bool, recorded: Option<&str>) -> Option<KeptBecause> {
    if let Some(recorded) = recorded {
        if !regular {
            return Some(KeptBecause::NotAFile);
        }
        let links = crate::text_file::Links::Refuse;
        match crate::export::set_file_sha256(path, EARLIER_IMAGE_MAX_BYTES, links) {
            Ok(now) if now == recorded => {}
            Ok(_) => return Some(KeptBecause::ChangedSince),
            Err(e) => return Some(KeptBecause::Unreadable(e.to_string())),
        }
    }
    std::fs::remove_file(path).err().map(|e| KeptBecause::WouldNotMove(e.to_string()))
}

/// Another `.gltf` file in `dir` named `name` with the extension in other case (`x.GLTF`
/// beside `x.gltf`, `out`), which names its side files as `out` does
/// (`gltf_side_file_names` reads the stem), and which the export would leave reading the
/// old document beside new side files. Not `out` under another spelling where the file
/// system ignores case, nor a symbolic link to `out` (it reads the new document). A hard
/// link to `out` is another (the export's rename leaves it the old document), and so is a
/// symbolic link to anything else, or a name the folder cannot be listed to tell apart
/// (independent reviews).
fn gltf_sharing_side_files(out: &Path, dir: &Path, name: &str) -> Option<std::path::PathBuf> {
    let spelled = out.extension()?.to_str()?;
    let shares = |other: &Path| {
        let (Ok(link), Ok(theirs)) = (std::fs::symlink_metadata(other), std::fs::metadata(other)) else {
            return false;
        };
        if !theirs.is_file() {
            return false;
        }
        if link.is_symlink() {
            // Resolved once each (it was three resolutions of two paths).
            let target = std::fs::canonicalize(other).ok();
            return target.is_none() || target != std::fs::canonicalize(out).ok();
        }
        match std::fs::metadata(out) {
            Ok(ours) if crate::export::same_identity(&ours, &theirs) => !listed_as_one(dir, out, other),
            _ => true,
        }
    };
    (0..16u8)
        .map(|case| {
            let letters = "gltf".chars().enumerate();
            letters.map(|(i, c)| if case & (1 << i) != 0 { c.to_ascii_uppercase() } else { c }).collect::<String>()
        })
        .filter(|extension| extension != spelled)
        .map(|extension| dir.join(format!("{name}.{extension}")))
        .find(|other| shares(other))
}

/// Whether `dir` lists one entry for `a`'s and `b`'s file names (one file read under either
/// spelling), not both; false where it cannot be listed.
fn listed_as_one(dir: &Path, a: &Path, b: &Path) -> bool {
    let (Some(a), Some(b)) = (a.file_name(), b.file_name()) else { return false };
    let Ok(entries) = std::fs::read_dir(dir) else { return false };
    let names: Vec<std::ffi::OsString> = entries.filter_map(|e| e.ok().map(|e| e.file_name())).collect();
    !(names.iter().any(|n| n == a) && names.iter().any(|n| n == b))
}

/// Whether the file is binary glTF (`.glb`) or JSON (`.gltf`), from its extension.
fn is_binary(path: &Path) -> Result<bool, Error> {
    let text = path.to_string_lossy();
    if crate::export::ends_as_a_folder(path) {
        // The one message every output file gets (`export::check_target`).
        return Err(crate::export::ExportError::folder_name(path, &["glb", "gltf"]).into());
    }
    // `.glb` alone: a name that is all extension (`Path::extension` sees none); `..gltf`, a
    // name of dots, wrote the hidden `..bin` and `._basecolor.png` beside it (a hostile-input
    // sweep).
    let name = path.file_name().map(|n| n.to_string_lossy().to_ascii_lowercase()).unwrap_or_default();
    if let Some((stem, extension)) = name.rsplit_once('.')
        && (extension == "glb" || extension == "gltf")
        && stem.chars().all(|c| c == '.')
    {
        return Err(Error::Unsupported(format!(
            "--gltf {text}: give a name before .{extension}, as in snake.{extension}"
        )));
    }
    match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
        Some("glb") => Ok(true),
        Some("gltf") => Ok(false),
        _ => Err(Error::Unsupported(format!(
            "--gltf {}: the file name must end in .glb (one binary file) or .gltf (JSON with its buffer and images \
             beside it)",
            path.display()
        ))),
    }
}

/// The mesh for a request (the snake's mesh without its closed ends' zero-area triangles).
pub fn mesh_for(kind: MeshKind, layout: Layout, preset: &crate::preset::Preset) -> Mesh {
    match (kind, layout) {
        (MeshKind::Snake, _) => BodyShape::for_layout(layout, preset).mesh(),
        (MeshKind::Sphere, _) => Mesh::sphere(0.5, 2.0, 64, 128),
        (MeshKind::Plane, Layout::Tile) => Mesh::plane(1.0, 1.0),
        (MeshKind::Plane, Layout::Body) => Mesh::plane(1.0, preset.body.length as f32),
    }
    .without_degenerate_triangles()
}

/// Plans, evaluates and writes one glTF export (`ExportPlan::new`, then `ExportPlan::run`).
pub fn export(request: &ExportRequest, progress: &(dyn Fn(usize, usize) + Sync)) -> Result<ExportReport, Error> {
    ExportPlan::new(request)?.run(progress)
}

/// An export checked before any pixel is computed: the preset loaded and validated, the
/// files it will write checked, its warnings and memory known, so that a caller can say them
/// before the work (the pack's size warning came after the textures were made).
pub struct ExportPlan {
    start: Instant,
    out: PathBuf,
    binary: bool,
    name: String,
    dir: PathBuf,
    plan: Plan,
    material: GltfMaterial,
    mesh: Mesh,
    mesh_kind: MeshKind,
    thickness_varies: bool,
    ao: bool,
    memory: MemoryCheck,
    warnings: Vec<String>,
}

/// The most memory the file's making holds once the textures are encoded (`ExportPlan::run`),
/// from `textures` (their bound, `Plan::texture_bytes_bound`): the textures; a `.glb`'s bytes,
/// which hold them again with the mesh's buffer; the mesh and its buffer; the fixed overhead.
/// A `.gltf`'s images are the textures moved, and its buffer is the mesh's alone.
fn file_bytes_estimate(textures: u64, mesh: &Mesh, binary: bool) -> u64 {
    // The vertices and indices, in the mesh and again in its buffer (the same floats).
    let mesh_bytes = std::mem::size_of_val(mesh.vertices.as_slice()) + std::mem::size_of_val(mesh.indices.as_slice());
    let mesh_bytes = mesh_bytes as u64;
    let file = if binary { textures + mesh_bytes } else { 0 };
    crate::memory::FIXED_OVERHEAD_BYTES + textures + 2 * mesh_bytes + file
}

impl ExportPlan {
    /// The preset's warnings (`LoadedPreset::warnings`), then the textures' size
    /// (`Plan::size_warning`).
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// The export's peak memory, estimated: the textures' evaluation (`Plan::memory`) or the
    /// file's making after it (`file_bytes_estimate`), whichever is more.
    pub fn memory(&self) -> MemoryCheck {
        self.memory
    }

    pub fn new(request: &ExportRequest) -> Result<ExportPlan, Error> {
        let start = Instant::now();
        let binary = is_binary(&request.out)?;
        if request.mesh == MeshKind::Sphere && request.layout == Layout::Body {
            return Err(Error::Unsupported(
                "--mesh sphere with --layout body: a body atlas spans a whole snake; put it on --mesh snake or plane"
                    .into(),
            ));
        }
        let dir = request.out.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new(".")).to_path_buf();
        let name = request
            .out
            .file_stem()
            .filter(|s| !s.is_empty())
            .ok_or_else(|| Error::Unsupported(format!("--gltf {}: no file name", request.out.display())))?;
        // The name is written into the file (the mesh's, the material's, a `.gltf`'s URIs of
        // its side files): one that is not UTF-8 came out as U+FFFD there and in the side
        // files' names, which then were not the names asked for.
        let name = name.to_str().map(String::from).ok_or_else(|| {
            Error::Unsupported(format!(
                "--gltf {}: the file name is not UTF-8 text; glTF names its mesh, material and side files with it",
                request.out.display()
            ))
        })?;
        // A `.gltf`'s side files are named after it (as a set's after its preset file); a
        // `.glb` carries its name inside only.
        if let Some(what) = crate::export::unfit_for_file_names(&name).filter(|_| !binary) {
            return Err(Error::Unsupported(format!(
                "--gltf {}: the file name has {what}, and the .gltf's side files are named after it; rename it",
                request.out.display()
            )));
        }
        let plan = Plan::within_checked_budget(&GenerateRequest {
            preset: request.preset.clone(),
            overrides: request.overrides.clone(),
            seed: request.seed,
            size: request.size,
            maps: vec![MapKind::Color, MapKind::Normal, MapKind::Roughness, MapKind::Iridescence],
            out_dir: dir.clone(),
            options: BuildOptions { layout: request.layout, ..BuildOptions::default() },
            format: FileFormat::Png,
            pack: Some(Pack::Gltf),
            ao: request.ao,
            job: None,
        })?;
        let preset = &plan.loaded().preset;
        let film = has_film(preset).then(|| {
            let (min_nm, max_nm) = thickness_range_nm(preset);
            (preset.optics.film_ior, min_nm, max_nm)
        });
        let material =
            GltfMaterial { base_ior: preset.optics.pigment_ior, film, repeat_v: request.layout == Layout::Tile };
        let mesh = mesh_for(request.mesh, request.layout, preset);
        let file_bytes = file_bytes_estimate(plan.texture_bytes_bound(), &mesh, binary);
        let memory = MemoryCheck::against_available(plan.memory().estimate_bytes.max(file_bytes));
        memory.refuse_if_over(&plan.size_words())?;
        // The files it will write, checked before the work (a folder or a link where one goes
        // was found only when they were written): the `.glb`, or the `.gltf` and its side files.
        // A film of one thickness (no spread) needs no texture: glTF reads the thickness as
        // the maximum then, which is the minimum (the validator's THICKNESS_TEXTURE_UNUSED).
        let thickness_varies = film.is_some_and(|(_, min_nm, max_nm)| max_nm > min_nm);
        let side_files = if binary { Vec::new() } else { gltf_side_file_names(&name, thickness_varies) };
        crate::export::check_folder(&dir)?;
        let input = crate::preset::input_file(&request.preset);
        crate::export::check_target(&request.out)?;
        crate::export::check_not_an_input(&request.out, input)?;
        // The lock the export takes and removes (`.NAME.lock`): a preset file of that name,
        // an empty one (a valid preset) not refused as a lock with content, was removed.
        let lock = dir.join(crate::export::lock_file_name(&name));
        crate::export::check_lock_not_an_input(&lock, &crate::export::Inputs::new(input))?;
        if !binary && let Some(other) = gltf_sharing_side_files(&request.out, &dir, &name) {
            return Err(
                crate::export::ExportError::SharesSideFiles { path: request.out.clone(), other, stem: name }.into()
            );
        }
        for file in side_files {
            let target = dir.join(file);
            crate::export::check_target(&target)?;
            crate::export::check_not_an_input(&target, input)?;
        }
        let warnings = plan
            .loaded()
            .warnings(&request.preset, crate::preset::SET_FLAG)
            .into_iter()
            // The plan's pack is glTF's: its warnings are the export's.
            .chain(plan.size_warning())
            .chain(plan.ambient_warning())
            .collect();
        Ok(ExportPlan {
            start,
            out: request.out.clone(),
            binary,
            name,
            dir,
            plan,
            material,
            mesh,
            mesh_kind: request.mesh,
            thickness_varies,
            ao: request.ao,
            memory,
            warnings,
        })
    }

    /// Evaluates the textures and writes the file (and, for `.gltf`, its side files).
    pub fn run(self, progress: &(dyn Fn(usize, usize) + Sync)) -> Result<ExportReport, Error> {
        let ExportPlan { start, out, binary, name, dir, plan, material, mesh, mesh_kind, thickness_varies, ao, .. } =
            self;
        // Before the work, as `generate` does: a second export of this name into this folder
        // stops at once (it did all its work, then a `.gltf` was refused at its commit and a
        // `.glb` replaced the other's), and under the lock the temporaries a killed export
        // left (a `.glb`'s whole file) are stale whatever their age. Its drop takes away the
        // folder it made if the export fails.
        let lock = SetLock::acquire(&dir, &name)?;
        // Looked for again under the lock: an export to the other spelling (`a.GLTF` beside
        // `a.gltf`) started at the same moment passed the plan's look before either had
        // written, then waited for the lock and wrote its images over the first's; both said
        // they succeeded, one document reading the other's skin (5 tries of 5, a sweep).
        // Under the lock the other has finished or waits.
        if !binary && let Some(other) = gltf_sharing_side_files(&out, &dir, &name) {
            return Err(crate::export::ExportError::SharesSideFiles { path: out, other, stem: name }.into());
        }
        let (mut textures, stats, encode_time) = plan.pack_textures(Pack::Gltf, progress)?;
        // The evaluation's buffers, freed on the pool's threads, go back before the file is
        // made (python-regius's body atlas at 1024 kept 225 MB resident for 47 MB of textures).
        crate::memory::release_freed();
        let dimensions = plan.dimensions();
        // Moved out, not copied: the encoded textures were held twice until the file was made.
        let mut texture = |suffix: &str| {
            let at = textures.iter().position(|(s, _)| s.suffix == suffix)?;
            Some(textures.swap_remove(at).1)
        };
        let missing = |suffix: &str| Error::Internal(format!("the glTF pack has no {suffix} texture"));
        let textures = GltfTextures {
            base_color: texture("basecolor").ok_or_else(|| missing("basecolor"))?,
            normal: texture("normal").ok_or_else(|| missing("normal"))?,
            orm: texture("orm").ok_or_else(|| missing("orm"))?,
            thickness: texture("thickness").filter(|_| thickness_varies),
            occlusion: ao,
        };
        // The asset's `extras`: the manifest's keys for what made it (`gltf::document`), and
        // the export's own options, so that it can be made again (the mesh and `--ao` were
        // left out: a sweep).
        let source = crate::export::gltf::ExportSource {
            set: crate::export::Source::of(plan.loaded(), dimensions, plan.layout()),
            mesh: mesh_kind.name(),
            ambient_occlusion: ao,
        };
        let created_folder = lock.created_folder;
        let mut removed = Vec::new();
        let mut kept = Vec::new();
        // The file under the name given, its extension's case kept (`--gltf FOO.GLTF` wrote
        // FOO.gltf, a file other than the one named and checked).
        let out_name = out.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        let files = if binary {
            let bytes = glb(&name, &mesh, material, &textures, Some(&source))?;
            // Staged under the lock, which sweeps the name's stale temporaries first.
            lock.write(&[], (&out_name, &bytes))?
        } else {
            let has_thickness = textures.thickness.is_some();
            let mut files = gltf_files(&name, &mesh, material, textures, Some(&source))?;
            let (_, gltf_bytes) = files.pop().expect("gltf_files ends with the .gltf");
            let gltf_name = out_name;
            // The lock swept every stale temporary of this name's files when it was taken,
            // the thickness image's too, which this export may not write
            // (`export::every_file_name_under_lock`).
            let thickness_file = gltf_image_file_name(&name, "thickness");
            // An earlier export of this name with a film left its thickness image, which no
            // file references once this one is committed: it goes, under the lock, after the
            // commit, where the `.gltf` it replaces named it and it is as that export wrote
            // it (the SHA-256 in the image's `extras`; an export from before they were
            // recorded is taken at its word). A file of that name that the earlier `.gltf`
            // did not name, or with no readable `.gltf` there (a killed commit's), may be
            // someone else's, and stays; one edited since stays. Each is said, as `generate`
            // says of the maps it keeps. Whatever stands there is harmless once the commit is
            // done, so an export that succeeded does not fail for it (a folder of that name
            // stays, and so does a file that may not go).
            let earlier = (!has_thickness).then(|| earlier_image(&dir.join(&gltf_name), &thickness_file));
            let written = lock.write(&files, (&gltf_name, &gltf_bytes))?;
            let stale = dir.join(&thickness_file);
            if let Some(earlier) = earlier
                && let Ok(meta) = std::fs::symlink_metadata(&stale)
                && !meta.is_dir()
            {
                let stays = match earlier {
                    EarlierImage::Named { sha256 } => stale_image_stays(&stale, meta.is_file(), sha256.as_deref()),
                    EarlierImage::NotShown(why) => Some(why),
                };
                match stays {
                    Some(why) => kept.push(KeptFile { path: stale, why, by: Earlier::Export }),
                    None => removed.push(stale),
                }
            }
            written
        };
        let total_time = start.elapsed();
        Ok(ExportReport { files, dimensions, stats, encode_time, total_time, created_folder, removed, kept })
    }
}
