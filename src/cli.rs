//! Command-line definitions only (clap derive); `main.rs` turns them into library calls.

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand, ValueEnum};

#[derive(Debug, Parser)]
#[command(
    name = "snakeskin",
    version,
    about = "Physically based snake-skin texture sets from species presets",
    long_about = "Generates seamless snake-skin texture sets (color, height, normal, roughness and \
                  iridescence-thickness maps, with a JSON manifest) from a TOML species preset.\n\n\
                  Start with `snakeskin presets list`, then `snakeskin generate <name> -o out/`."
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Generate a texture set: <out>/<name>_<map>.png and <out>/<name>.material.json.
    Generate(GenerateArgs),
    /// Print the node graph the requested maps need.
    Graph(GraphArgs),
    /// Query the optics: exact thin-film reflectance and film colour (JSON output).
    Brdf {
        #[command(subcommand)]
        command: BrdfCommand,
    },
    /// Benchmarks: `bench irid` measures every film colour method's error against cost.
    Bench {
        #[command(subcommand)]
        command: BenchCommand,
    },
    /// A gallery PNG of every scale shape and pattern kind (tile order: see README).
    Gallery {
        /// Output PNG file.
        #[arg(short, long)]
        out: PathBuf,
        /// Tile size in pixels.
        #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u64).range(16..=2048))]
        tile: u64,
        /// Tiles per row.
        #[arg(long, default_value_t = 6, value_parser = clap::value_parser!(u64).range(1..=64))]
        columns: u64,
    },
    /// Render a preset on a snake body with the multi-layer BRDF: headless to a PNG (--out)
    /// or in a window with sliders and live reload (--window).
    Preview(PreviewArgs),
    /// Render the documentation figures: layer stages (thesis Fig. 5.12), film thickness
    /// δ0 = 0, 200, 400, 600 nm and 2.4 mm (Figs. 5.5-5.9), absorption σ0 = 0.1 and 0.7
    /// (Figs. 5.10-5.11).
    Figures {
        /// Preset to render (file or built-in name).
        #[arg(default_value = "erythrolamprus-miliaris")]
        preset: String,
        /// Output folder.
        #[arg(short, long, default_value = "docs/figures", value_name = "DIR")]
        out: PathBuf,
        /// Image size WIDTHxHEIGHT.
        #[arg(long, default_value = "640x400")]
        size: String,
        /// Map resolution for the preview (pixels per side).
        #[arg(long, default_value_t = 1024, value_parser = clap::value_parser!(u64).range(64..=4096))]
        map_size: u64,
    },
    /// A contact sheet of the species library: per species its colour map and a preview
    /// render, labelled with scientific name, common name and pattern category.
    Sheet {
        /// Output PNG file.
        #[arg(short, long, value_name = "FILE.png")]
        out: PathBuf,
        /// Tile size in pixels (colour map tile × tile, render 2·tile × tile).
        #[arg(long, default_value_t = 224, value_parser = clap::value_parser!(u32).range(64..=1024))]
        tile: u32,
        /// Cells per row.
        #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u32).range(1..=8))]
        columns: u32,
        /// Map resolution per species (pixels per side).
        #[arg(long, default_value_t = 512, value_parser = clap::value_parser!(u64).range(64..=4096))]
        map_size: u64,
    },
    /// List or show the built-in species presets.
    Presets {
        #[command(subcommand)]
        command: PresetsCommand,
    },
}

/// Which preset, with which edits: shared by every command that reads one.
#[derive(Debug, Args)]
pub struct PresetSource {
    /// A preset: a path to a .toml file, or a built-in name (see `snakeskin presets list`).
    pub preset: String,
    /// Override a preset key by dotted path, e.g. `--set scales.rows=23 --set pattern.0.kind=spots`.
    /// VALUE is parsed as TOML; a bare word that is not valid TOML is taken as a string.
    #[arg(long = "set", value_name = "KEY=VALUE", value_parser = parse_key_value)]
    pub overrides: Vec<(String, String)>,
    /// Override the preset's seed.
    #[arg(long)]
    pub seed: Option<u64>,
}

#[derive(Debug, Args)]
pub struct PresetArgs {
    #[command(flatten)]
    pub source: PresetSource,
    /// Maps to produce, comma-separated: color, height, normal, roughness, iridescence (default: all).
    #[arg(long, default_value = "all", value_name = "LIST")]
    pub maps: String,
}

#[derive(Debug, Args)]
pub struct GenerateArgs {
    #[command(flatten)]
    pub preset: PresetArgs,
    /// Output folder (created if missing).
    #[arg(short, long, default_value = ".", value_name = "DIR")]
    pub out: PathBuf,
    /// Width and height of every map in pixels (16 to 16384).
    #[arg(long, default_value_t = 1024, value_parser = clap::value_parser!(u64).range(16..=16384))]
    pub size: u64,
    /// Normal map convention: opengl (+Y up, glTF/Blender) or directx (+Y down, Unreal).
    #[arg(long, value_enum, default_value_t = Convention::Opengl)]
    pub normal_convention: Convention,
    /// Print per-node evaluations, time and buffer size after the run.
    #[arg(long)]
    pub stats: bool,
}

#[derive(Debug, Args)]
pub struct PreviewArgs {
    #[command(flatten)]
    pub source: PresetSource,
    /// Write the rendered image to this PNG file (headless; no window needed).
    #[arg(short, long, value_name = "FILE.png")]
    pub out: Option<PathBuf>,
    /// Open a window: drag to orbit, wheel to zoom, sliders for the optics; the preset file
    /// is watched and reloaded on save.
    #[arg(long)]
    pub window: bool,
    /// Image or window size WIDTHxHEIGHT.
    #[arg(long, default_value = "1280x720")]
    pub size: String,
    /// What to show: a layer stage (diffuse, normal, film, all; thesis Fig. 5.12) or one map
    /// unlit on the body (map:color, map:height, map:normal, map:roughness, map:iridescence).
    #[arg(long, default_value = "all", value_name = "STAGE")]
    pub layers: String,
    /// Film colour method: lut (default), rgb3, spectral-N (e.g. spectral-16), gaussian-fit.
    #[arg(long, default_value = "lut", value_name = "M")]
    pub method: String,
    /// Map resolution for the preview (pixels per side).
    #[arg(long, default_value_t = 1024, value_parser = clap::value_parser!(u64).range(64..=4096))]
    pub map_size: u64,
    /// With --window: render N frames, print the mean frame time and exit.
    #[arg(long, value_name = "N")]
    pub frames: Option<u32>,
    /// Exposure multiplier before tone mapping (Khronos PBR Neutral).
    #[arg(long, default_value_t = 1.0)]
    pub exposure: f32,
    /// Number of snakes (instanced in a grid).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=400))]
    pub snakes: u32,
    /// Hide the ground plane.
    #[arg(long)]
    pub no_ground: bool,
    /// Frame the mid-body closely instead of the whole snake.
    #[arg(long)]
    pub close_up: bool,
    /// Also shade the frame on the CPU with the f64 spectral reference, print mean and p99
    /// CIEDE2000 against the GPU image, and write the error heat map to this PNG.
    #[arg(long, value_name = "HEATMAP.png")]
    pub reference: Option<PathBuf>,
}

#[derive(Debug, Args)]
pub struct GraphArgs {
    #[command(flatten)]
    pub preset: PresetArgs,
    /// Print Graphviz DOT (render with `dot -Tsvg`); otherwise a plain list of nodes.
    #[arg(long)]
    pub dot: bool,
}

#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum Convention {
    Opengl,
    Directx,
}

#[derive(Debug, Subcommand)]
pub enum PresetsCommand {
    /// One preset per line: name, common name, category.
    List,
    /// Print a preset's TOML.
    Show { name: String },
}

fn parse_key_value(arg: &str) -> Result<(String, String), String> {
    let (key, value) = arg.split_once('=').ok_or_else(|| format!("expected KEY=VALUE, got {arg:?}"))?;
    if key.trim().is_empty() {
        return Err(format!("empty key in {arg:?}"));
    }
    Ok((key.trim().to_string(), value.trim().to_string()))
}

#[derive(Debug, Args)]
pub struct StackArgs {
    /// Refractive index of the ambient medium (thesis n0).
    #[arg(long, default_value_t = 1.0)]
    pub n0: f64,
    /// Refractive index of the iridescent film (thesis n1).
    #[arg(long, default_value_t = 1.55)]
    pub n1: f64,
    /// Refractive index of the pigment layer under the film (thesis n2).
    #[arg(long, default_value_t = 2.0)]
    pub n2: f64,
}

#[derive(Debug, Subcommand)]
pub enum BrdfCommand {
    /// The exact coherent film at one wavelength: {"rs","rp","r","ts","tp","t"}.
    Film {
        #[command(flatten)]
        stack: StackArgs,
        /// Film thickness in nm (thesis δ0).
        #[arg(long, required_unless_present = "batch")]
        thickness_nm: Option<f64>,
        /// Vacuum wavelength in nm.
        #[arg(long, required_unless_present = "batch")]
        wavelength_nm: Option<f64>,
        /// Incidence angle in the ambient medium, degrees (0 = normal).
        #[arg(long, required_unless_present = "batch")]
        angle_deg: Option<f64>,
        /// Read JSON lines {n0, n1, n2, thickness_nm, wavelength_nm, angle_deg} from FILE
        /// (or - for stdin); print one JSON line per query, in order.
        #[arg(long, value_name = "FILE")]
        batch: Option<String>,
    },
    /// The film's reflectance colour in linear sRGB under D65: {"rgb":[r,g,b]}.
    Color {
        #[command(flatten)]
        stack: StackArgs,
        #[arg(long, required_unless_present = "batch")]
        thickness_nm: Option<f64>,
        #[arg(long, required_unless_present = "batch")]
        angle_deg: Option<f64>,
        /// Colour method: spectral (the 1 nm reference of PHYSICS.md), rgb3, spectral-N
        /// (e.g. spectral-16), gaussian-fit, lut.
        #[arg(long, default_value = "spectral")]
        method: String,
        /// JSON lines {n0, n1, n2, thickness_nm, angle_deg, method}.
        #[arg(long, value_name = "FILE")]
        batch: Option<String>,
    },
    /// The full multi-layer BRDF for given directions and layer parameters (JSON).
    Eval(EvalArgs),
    /// A thin-film colour chart PNG: thickness 0..2000 nm across, angle 0..89° down.
    Chart {
        #[command(flatten)]
        stack: StackArgs,
        /// Output PNG file.
        #[arg(short, long)]
        out: PathBuf,
        /// Colour method (spectral = the 1 nm reference).
        #[arg(long, default_value = "spectral")]
        method: String,
        /// Chart width (thickness samples) and height (angle samples) in pixels.
        #[arg(long, default_value_t = 800)]
        width: u32,
        #[arg(long, default_value_t = 300)]
        height: u32,
    },
    /// Random and adversarial inputs: counts NaN and Inf, the range of R and T, the worst
    /// white-furnace albedo and the f32 path's worst deviation from f64 (JSON with --json).
    Stress {
        /// Number of random samples.
        #[arg(long, default_value_t = 100_000)]
        samples: u64,
        /// Seed of the sample generator.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Print one JSON object instead of a table.
        #[arg(long)]
        json: bool,
    },
}

#[derive(Debug, Args)]
pub struct EvalArgs {
    #[command(flatten)]
    pub stack: StackArgs,
    /// Direction towards the light, x,y,z (need not be normalised).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub wi: [f64; 3],
    /// Direction towards the viewer, x,y,z.
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub wo: [f64; 3],
    /// Shading normal, x,y,z (a zero vector falls back to 0,0,1).
    #[arg(long, value_parser = parse_vec3, default_value = "0,0,1", allow_hyphen_values = true)]
    pub normal: [f64; 3],
    /// Film thickness in nm (thesis δ0).
    #[arg(long, default_value_t = 400.0)]
    pub thickness_nm: f64,
    /// Perceptual roughness (GGX α = roughness²).
    #[arg(long, default_value_t = 0.35)]
    pub roughness: f64,
    /// Absorption coefficient σ0 (one value, or r,g,b).
    #[arg(long, value_parser = parse_vec3_or_scalar, default_value = "0.6")]
    pub absorption: [f64; 3],
    /// Pigment layer thickness δ1 (optical depth τ = σ0 δ1).
    #[arg(long, default_value_t = 1.0)]
    pub pigment_thickness: f64,
    /// Base albedo k_d, linear r,g,b (or one value).
    #[arg(long, value_parser = parse_vec3_or_scalar, default_value = "1")]
    pub albedo: [f64; 3],
    /// Film colour method (as for `brdf color`).
    #[arg(long, default_value = "spectral")]
    pub method: String,
}

#[derive(Debug, Subcommand)]
pub enum BenchCommand {
    /// Frame time of the skin shader against a plain PBR shader on the same scene (GPU
    /// timestamps where available), the specialised variants, 20 snakes, and the CPU
    /// reference comparison (mean and p99 CIEDE2000).
    Render {
        /// Preset to render.
        #[arg(default_value = "erythrolamprus-miliaris")]
        preset: String,
        /// Frame size WIDTHxHEIGHT (use 1920x1080 on a real GPU).
        #[arg(long, default_value = "1280x720")]
        size: String,
        /// Timed frames per variant (after 3 warm-up frames); the median is reported.
        #[arg(long, default_value_t = 30, value_parser = clap::value_parser!(u64).range(3..=10_000))]
        frames: u64,
        /// Map resolution (pixels per side).
        #[arg(long, default_value_t = 1024, value_parser = clap::value_parser!(u64).range(64..=4096))]
        map_size: u64,
        /// Frame size of the CPU reference comparison (the CPU shades each pixel spectrally).
        #[arg(long, default_value = "480x300")]
        reference_size: String,
        /// Print one JSON object.
        #[arg(long)]
        json: bool,
    },
    /// The BRDF (LUT film) per million evaluations: WGSL compute shader on the GPU and the
    /// Rust f32 twin on one CPU core, side by side in one run.
    Gpu {
        /// Evaluations per dispatch.
        #[arg(long, default_value_t = 1_000_000, value_parser = clap::value_parser!(u64).range(1000..=16_000_000))]
        samples: u64,
        /// Print one JSON object.
        #[arg(long)]
        json: bool,
    },
    /// Time against error of every film colour method on PHYSICS.md's grid.
    Irid {
        /// Print JSON {"default", "methods": [{"name","mean_de","p95_de","max_de","ns_per_eval"}]}.
        #[arg(long)]
        json: bool,
        /// Write an SVG plot of error against cost, one point per method.
        #[arg(long, value_name = "FILE")]
        plot: Option<PathBuf>,
        /// Thickness step of the grid in nm (PHYSICS.md grid: 0..2000 nm).
        #[arg(long, default_value_t = 10.0)]
        d_step_nm: f64,
        /// Angle step of the grid in degrees (0..89°).
        #[arg(long, default_value_t = 1.0)]
        angle_step_deg: f64,
        /// Also measure other LUT sizes (the table-size trade-off).
        #[arg(long)]
        lut_sweep: bool,
    },
}

fn parse_vec3(text: &str) -> Result<[f64; 3], String> {
    let parts: Vec<f64> = text
        .split(',')
        .map(|p| p.trim().parse::<f64>().map_err(|_| format!("expected x,y,z numbers, got {text:?}")))
        .collect::<Result<_, _>>()?;
    match parts.as_slice() {
        [x, y, z] if parts.iter().all(|v| v.is_finite()) => Ok([*x, *y, *z]),
        _ => Err(format!("expected three finite numbers x,y,z, got {text:?}")),
    }
}

fn parse_vec3_or_scalar(text: &str) -> Result<[f64; 3], String> {
    match text.trim().parse::<f64>() {
        Ok(v) if v.is_finite() => Ok([v; 3]),
        _ => parse_vec3(text),
    }
}
