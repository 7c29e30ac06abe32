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
    /// List or show the built-in species presets.
    Presets {
        #[command(subcommand)]
        command: PresetsCommand,
    },
}

#[derive(Debug, Args)]
pub struct PresetArgs {
    /// A preset: a path to a .toml file, or a built-in name (see `snakeskin presets list`).
    pub preset: String,
    /// Override a preset key by dotted path, e.g. `--set scales.rows=23 --set pattern.0.kind=spots`.
    /// VALUE is parsed as TOML; a bare word that is not valid TOML is taken as a string.
    #[arg(long = "set", value_name = "KEY=VALUE", value_parser = parse_key_value)]
    pub overrides: Vec<(String, String)>,
    /// Override the preset's seed.
    #[arg(long)]
    pub seed: Option<u64>,
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
    let (key, value) = arg
        .split_once('=')
        .ok_or_else(|| format!("expected KEY=VALUE, got {arg:?}"))?;
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
        /// Colour method; `spectral` is the 1 nm reference of PHYSICS.md.
        #[arg(long, default_value = "spectral")]
        method: String,
        /// JSON lines {n0, n1, n2, thickness_nm, angle_deg, method}.
        #[arg(long, value_name = "FILE")]
        batch: Option<String>,
    },
}
