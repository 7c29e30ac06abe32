//! Command-line definitions (clap derive). Every value is parsed into its type here, once —
//! map lists, image sizes, views, film methods, vectors and bounded numbers — so a command
//! in `cmd/` receives checked values and a bad argument is a clap error naming the flag
//! (exit 2) before anything runs.

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand, ValueEnum};

use snakeskin::material::{MapKind, thesis};
use snakeskin::optics::brdf::Model;
use snakeskin::optics::methods::Method;
use snakeskin::preset::validate::ranges;
use snakeskin::render::engine::film::GpuFilmMethod;
use snakeskin::render::engine::scene::View;

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
    /// Generate a texture set: <out>/<name>_<map>.png (.exr with --format exr; an engine's
    /// textures with --pack) and <out>/<name>.material.json.
    Generate(GenerateArgs),
    /// Export a preset as glTF 2.0 (.glb, or .gltf with its images beside it): the snake (or
    /// a sphere or plane) with the maps as a metallic-roughness material, the film as
    /// KHR_materials_iridescence and the base's index as KHR_materials_ior.
    Export(ExportArgs),
    /// Run many sets from a jobs file (resumable: done jobs are skipped; --shard K/N for
    /// array jobs). See the README's "Batch runs".
    Batch(BatchArgs),
    /// Print the node graph the requested maps need.
    Graph(GraphArgs),
    /// Query the optics: the exact thin film, film colour, the BRDF and its albedo (JSON), a
    /// film colour chart (PNG) and a numerical stress test.
    Brdf {
        #[command(subcommand)]
        command: BrdfCommand,
    },
    /// Benchmarks of run time against error: `irid` (the film colour methods), `layered` (the
    /// layer models against the photon walk), `render` (frame times on the GPU), `gpu` (the
    /// WGSL BRDF per million evaluations).
    Bench {
        #[command(subcommand)]
        command: BenchCommand,
    },
    /// A gallery PNG of every scale shape and pattern kind (tile order: see README).
    Gallery {
        /// Output PNG file.
        #[arg(short, long)]
        out: PathBuf,
        /// Tile size in pixels, 16 to 2048.
        #[arg(long, default_value_t = 256, value_parser = ranged_u64(16, 2048))]
        tile: u64,
        /// Tiles per row, 1 to 64 (a row holds at most every tile: more columns than tiles
        /// give one row).
        #[arg(long, default_value_t = 6, value_parser = ranged_u64(1, 64))]
        columns: u64,
        /// Also write one close-up per capability of the skin vocabulary into this folder: a
        /// 512 × 512 crop of the colour map beside the same crop of the normal map, both
        /// generated at 1024 × 1024 (per-scale colour, composite marks, rings in whole
        /// scales, belly marks, rows, imbricate geometry).
        #[arg(long, value_name = "DIR")]
        closeups: Option<PathBuf>,
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
        /// Image size WIDTHxHEIGHT (or one number for a square), each 16 to 8192 pixels.
        #[arg(long, default_value = "640x400", value_parser = parse_image_size)]
        size: ImageSize,
        /// Resolution of the maps each figure is drawn with (pixels per side), 64 to 4096.
        #[arg(long, default_value_t = 1024, value_parser = map_size())]
        map_size: u64,
    },
    /// A contact sheet of the species library: per species its colour map and a preview
    /// render, labelled with scientific name, common name and pattern category.
    Sheet {
        /// Output PNG file.
        #[arg(short, long, value_name = "FILE.png")]
        out: PathBuf,
        /// Tile size in pixels (colour map tile × tile, render 2·tile × tile; with --layout
        /// body: the strip's height, one circumference, the strip length·tile long, the
        /// render 4·tile × 2·tile), 64 to 1024.
        #[arg(long, default_value_t = 224, value_parser = ranged_u32(64, 1024))]
        tile: u32,
        /// Cells per row, 1 to 8 (at most one per species drawn: more give one row).
        #[arg(long, default_value_t = 2, value_parser = ranged_u32(1, 8))]
        columns: u32,
        /// Map resolution per species (pixels per side; a body atlas's width, narrowed for a
        /// species whose atlas would be more than 8192 rows long), 64 to 4096.
        #[arg(long, default_value_t = 512, value_parser = map_size())]
        map_size: u64,
        /// tile: each species' tile and a render; body: each species' whole body atlas on
        /// its side (snout left) with its counts, and a render of the whole snake (--tile
        /// is then the strip's height, one circumference).
        #[arg(long, value_enum, default_value_t = LayoutArg::Tile)]
        layout: LayoutArg,
        /// Only these species, in this order (comma-separated built-in names; default: all).
        #[arg(long, value_delimiter = ',', value_name = "NAMES")]
        species: Vec<String>,
        /// Also a close-up of each species' head and tail (needs --layout body).
        #[arg(long)]
        closeups: bool,
    },
    /// List or show the built-in species presets.
    Presets {
        #[command(subcommand)]
        command: PresetsCommand,
    },
    /// Check sets against their manifests: every file a NAME.material.json lists must lie
    /// beside it with the SHA-256 it records. One line per set on stdout, `ok` or `FAILED`
    /// with why (a missing manifest: a run was killed or failed while writing the set; a file
    /// that differs: the set was altered or mixed); exit 0 when every set is whole, 1 when one is not, 2 for a
    /// path that is no manifest or folder of sets. glTF exports carry no manifest.
    Verify {
        /// A set's manifest (NAME.material.json), or a folder: every manifest in it and in its
        /// subfolders two levels down (a batch's output folder). A path that holds no set is
        /// the user's mistake (exit 2), said after the other paths are checked.
        #[arg(required = true, value_name = "PATH")]
        paths: Vec<PathBuf>,
    },
}

/// A refusal of the command line in clap's format, with the usage of the subcommand the
/// words named (`names`: `brdf`, `eval`), as clap's own errors show it.
fn refusal(
    command: &mut clap::Command,
    names: &[String],
    kind: clap::error::ErrorKind,
    message: String,
) -> clap::Error {
    let mut chosen = command;
    for name in names {
        chosen = chosen.find_subcommand_mut(name).expect("a subcommand the words named");
    }
    clap::Error::raw(kind, message).format(chosen)
}

impl Cli {
    /// The command line parsed, or clap's error (exit code 2), with two rules of ours.
    /// A flag whose value may start with `-` (`--wi -1,0,1`) takes the next word whatever it
    /// is, so `--absorption --wo 0,0,1` read `--wo` as the absorption and then called
    /// `0,0,1` an unexpected argument: one of the command's flags right after such a flag is
    /// refused as its missing value. And every flag that takes a value takes a negative
    /// number as one, to refuse it with its range: `--size -16` said "unexpected argument
    /// '-1'" with the tip `-- -1`, which did not help either (and clap knows `-1e-3`,
    /// `-.5` and `-inf` as no numbers: `negative_values_attached`).
    pub fn try_parse_checked_from(args: Vec<std::ffi::OsString>) -> Result<Cli, clap::Error> {
        use clap::{CommandFactory, FromArgMatches};
        let mut command = negative_numbers_as_values(Cli::command());
        command.build();
        // The checks below read the words as given (a flag's value attached by
        // `negative_values_attached` would show in their messages as `--wo=-1,0,1`); clap
        // reads them attached.
        let words: Vec<&str> = args.iter().map(|a| a.to_str().unwrap_or("")).collect();
        // The subcommands the words name (`brdf`, `eval`): their flags are the ones that
        // count, and the error shows the last one's usage.
        let mut path = vec![&command];
        for word in words.iter().skip(1) {
            if let Some(sub) = path.last().and_then(|c| c.find_subcommand(word)) {
                path.push(sub);
            }
        }
        let attached = negative_values_attached(&args, &path);
        let long_flags = |c: &clap::Command| {
            c.get_arguments()
                .filter_map(|a| a.get_long().map(|l| (format!("--{l}"), a.is_allow_hyphen_values_set())))
                .collect::<Vec<_>>()
        };
        let flags: Vec<(String, bool)> = path.iter().flat_map(|c| long_flags(c)).collect();
        let names: Vec<String> = path.iter().skip(1).map(|c| c.get_name().to_string()).collect();
        for pair in words.windows(2) {
            let next_flag = pair[1].split('=').next().unwrap_or("");
            let takes_hyphen_values = flags.iter().any(|(f, hyphen)| f == pair[0] && *hyphen);
            if takes_hyphen_values && flags.iter().any(|(f, _)| f == next_flag) {
                let message = format!("`{}` needs a value, and the next word is the flag `{}`", pair[0], pair[1]);
                return Err(refusal(&mut command, &names, clap::error::ErrorKind::InvalidValue, message));
            }
        }
        // A long flag written with one dash (`-out`, `-size 64`) is clap's short flag with its
        // value attached (`-o ut`): `generate NAME -out` wrote the set into `./ut/`, and
        // `-size 64` said "unexpected argument '64'". A word that is one of the command's
        // long flags (or their aliases) but for its second dash, alone or followed by what
        // cannot continue a flag's name (`-out/`, `-out.glb`, `-size=16`), is refused with the
        // flag it names. `-help` and `-version` are left to clap (which shows the help).
        let last = path.last().expect("the command itself at least");
        let long_names: Vec<&str> = last
            .get_arguments()
            .flat_map(|a| a.get_long().into_iter().chain(a.get_all_aliases().unwrap_or_default()))
            .filter(|l| *l != "help" && *l != "version")
            .collect();
        for word in words.iter().skip(1).take_while(|w| **w != "--") {
            let Some(rest) = word.strip_prefix('-').filter(|r| r.len() > 1 && !r.starts_with('-')) else {
                continue;
            };
            let ends_a_name =
                |after: &str| after.chars().next().is_none_or(|c| !(c.is_alphanumeric() || c == '-' || c == '_'));
            let named =
                long_names.iter().filter(|l| rest.strip_prefix(**l).is_some_and(ends_a_name)).max_by_key(|l| l.len());
            if let Some(named) = named {
                let first = rest.chars().next().unwrap_or('-');
                let short_takes_a_value =
                    last.get_arguments().any(|a| a.get_short() == Some(first) && a.get_action().takes_values());
                let read_as = if short_takes_a_value {
                    format!(
                        " (with one, it is read as the short flag `-{first}` with the value `{}`)",
                        &rest[first.len_utf8()..]
                    )
                } else {
                    String::new()
                };
                let message = format!("`{word}` has one dash: write `--{named}`; long flags take two{read_as}");
                return Err(refusal(&mut command, &names, clap::error::ErrorKind::UnknownArgument, message));
            }
        }
        let mut matches = command.try_get_matches_from_mut(attached)?;
        let cli = Cli::from_arg_matches_mut(&mut matches).map_err(|e| e.format(&mut command))?;
        // `--ao` without `--pack`: clap's `requires` said only that `--pack <ENGINE>` was
        // missing, and its conflict with `--maps` only that the two cannot be used together,
        // where the user may have meant the map (`--help` says so): the hint adds `ao` to
        // the maps they asked for.
        if let Command::Generate(generate) = &cli.command
            && generate.ao
            && generate.pack.is_none()
        {
            let engines: Vec<String> = PackArg::value_variants()
                .iter()
                .filter_map(|engine| engine.to_possible_value().map(|v| v.get_name().to_string()))
                .collect();
            // The maps asked for, as `--maps` takes them (`all` for the five).
            let asked = &generate.preset.maps.0;
            let maps = if asked[..] == MapKind::ALL[..] {
                "all".to_string()
            } else {
                asked.iter().map(|m| m.name()).collect::<Vec<_>>().join(",")
            };
            let instead = if asked.contains(&MapKind::Ao) {
                format!("drop --ao: --maps {maps} names the map already")
            } else {
                format!("name the map instead: --maps {maps},ao")
            };
            let message = format!(
                "--ao puts ambient occlusion into a pack's occlusion channel: add --pack ENGINE ({}), or, without a \
                 pack, {instead}",
                engines.join(", ")
            );
            let generate = command.find_subcommand_mut("generate").expect("the generate subcommand");
            return Err(clap::Error::raw(clap::error::ErrorKind::MissingRequiredArgument, message).format(generate));
        }
        Ok(cli)
    }
}

/// A whole number in `lo..=hi`, refused with its range whatever it is: negative, or past
/// u64 (`--samples 18446744073709551616` and `--size -16` were "number too large to fit in
/// target type" and "invalid digit found in string" under clap's parsers).
fn ranged_u64(lo: u64, hi: u64) -> impl Fn(&str) -> Result<u64, String> + Clone + Send + Sync + 'static {
    move |text| match text.trim().parse::<i128>() {
        Ok(n) if (i128::from(lo)..=i128::from(hi)).contains(&n) => Ok(n as u64),
        Ok(n) => Err(format!("{n} is not in {lo}..={hi}")),
        Err(_) => Err(format!("not a whole number; accepted: {lo}..={hi}")),
    }
}

/// A set's `--size`: `snakeskin::SIZE_RANGE`.
fn set_size() -> impl Fn(&str) -> Result<u64, String> + Clone + Send + Sync + 'static {
    let parse = ranged_u64((*snakeskin::SIZE_RANGE.start()).into(), (*snakeskin::SIZE_RANGE.end()).into());
    move |text| {
        parse(text).map_err(|e| {
            // `preview --size` takes WIDTHxHEIGHT, a frame's; a set's maps have one width.
            let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
            let frame = text.split_once(['x', 'X']).is_some_and(|(w, h)| digits(w) && w != "0" && digits(h));
            if frame {
                format!(
                    "{e}; a set's --size is one width (the tile is square; a body atlas is body.length widths tall)"
                )
            } else {
                e
            }
        })
    }
}

/// A drawing command's `--map-size`: `render::engine::prepare::MAP_SIZE_RANGE`.
fn map_size() -> impl Fn(&str) -> Result<u64, String> + Clone + Send + Sync + 'static {
    let range = snakeskin::render::engine::prepare::MAP_SIZE_RANGE;
    ranged_u64((*range.start()).into(), (*range.end()).into())
}

/// `ranged_u64` for a flag that holds a u32 (`clap::value_parser!(u32).range` said "number
/// too large to fit in target type" and "invalid digit found in string" for `--tile 1e30`
/// and `--tile 1.5`).
fn ranged_u32(lo: u32, hi: u32) -> impl Fn(&str) -> Result<u32, String> + Clone + Send + Sync + 'static {
    let parse = ranged_u64(lo.into(), hi.into());
    move |text| parse(text).map(|n| n as u32)
}

/// The command line with a value that starts with `-` and then a digit, a point or `inf` /
/// `nan` written onto the long flag before it that takes a value (`--angle-deg=-1e-3`):
/// clap's negative numbers (`negative_numbers_as_values`) are digits and one point only,
/// so `--angle-deg -1e-3` said "unexpected argument '-1'", and `-.5`, `-inf` and `-nan`
/// the same (a hostile-input sweep), where `--angle-deg -1` gives the flag's range. `path`
/// is the commands the words name, whose flags count. Nothing after `--` is touched, nor a
/// flag that takes a path or text: `--out -1dir` stays refused, as `-o -1dir` and
/// `--out -weird` are (a review).
fn negative_values_attached(args: &[std::ffi::OsString], path: &[&clap::Command]) -> Vec<std::ffi::OsString> {
    use clap::builder::ValueParser;
    let words = [ValueParser::path_buf(), ValueParser::os_string(), ValueParser::string()].map(|p| p.type_id());
    let takes_value = |word: &str| {
        path.iter().flat_map(|c| c.get_arguments()).any(|a| {
            a.get_action().takes_values()
                && !words.contains(&a.get_value_parser().type_id())
                && a.get_long().is_some_and(|l| word.strip_prefix("--") == Some(l))
        })
    };
    let looks_negative = |word: &str| {
        word.strip_prefix('-').is_some_and(|rest| {
            rest.starts_with(|c: char| c.is_ascii_digit() || c == '.')
                || ["inf", "infinity", "nan"].contains(&rest.to_ascii_lowercase().as_str())
        })
    };
    let mut out = Vec::with_capacity(args.len());
    let mut i = 0;
    while i < args.len() {
        let (word, next) = (args[i].to_str(), args.get(i + 1).and_then(|a| a.to_str()));
        if word == Some("--") {
            out.extend_from_slice(&args[i..]);
            break;
        }
        if let (Some(flag), Some(value)) = (word, next)
            && i > 0
            && takes_value(flag)
            && looks_negative(value)
        {
            out.push(format!("{flag}={value}").into());
            i += 2;
            continue;
        }
        out.push(args[i].clone());
        i += 1;
    }
    out
}

/// `command` and its subcommands with every flag that takes a value taking a negative
/// number as one (`Cli::try_parse_checked_from`).
fn negative_numbers_as_values(command: clap::Command) -> clap::Command {
    command
        .mut_args(|arg| {
            if !arg.is_positional() && arg.get_action().takes_values() { arg.allow_negative_numbers(true) } else { arg }
        })
        .mut_subcommands(negative_numbers_as_values)
}

/// Which preset, with which edits: shared by every command that reads one.
#[derive(Debug, Args)]
pub struct PresetSource {
    /// A preset: a path to a .toml file, or a built-in name (see `snakeskin presets list`; a
    /// built-in name is the built-in even beside a file of that name: `./NAME` reads the file).
    pub preset: String,
    /// Override a preset key by dotted path, e.g. `--set scales.rows=23 --set color.base=#6c6e5c`
    /// (a preset without pattern layers takes one with its kind and colour: `--set
    /// pattern.0.kind=spots --set pattern.0.color=#101010`). VALUE is parsed as TOML; a bare word that is not valid TOML is taken as a string, but
    /// one that starts as an array, table, quoted string or number must parse.
    #[arg(long = "set", value_name = "KEY=VALUE", value_parser = parse_key_value)]
    pub overrides: Vec<(String, String)>,
    /// Override the preset's seed: a whole number from 0 to 9007199254740991 (2^53 - 1, the
    /// largest that the JSON files recording it keep exactly in every reader).
    #[arg(long, value_parser = parse_seed)]
    pub seed: Option<u64>,
}

/// `--seed`: the spellings `--set seed=` takes (`preset::parse_seed_text`), inside
/// `ranges::SEED_MAX`, refused as `ranged_u64` refuses a number (a negative one with itself).
fn parse_seed(text: &str) -> Result<u64, String> {
    let decimal = ranged_u64(0, ranges::SEED_MAX)(text);
    if decimal.is_ok() || text.trim().parse::<i128>().is_ok() {
        return decimal;
    }
    match snakeskin::preset::parse_seed_text(text) {
        Some(seed) if seed <= ranges::SEED_MAX => Ok(seed),
        Some(seed) => Err(format!("{seed} is not in 0..={}", ranges::SEED_MAX)),
        None => Err(format!(
            "not a whole number; accepted: 0..={} (decimal, or a TOML integer: 0x10, 0o20, 0b10000, 1_000)",
            ranges::SEED_MAX
        )),
    }
}

#[derive(Debug, Args)]
pub struct PresetArgs {
    #[command(flatten)]
    pub source: PresetSource,
    /// Maps to produce, comma-separated: color, height, normal, roughness, iridescence, and ao
    /// (ambient occlusion, only when named); "all" is the first five ("all,ao" adds it).
    /// `generate` writes them as a whole set: in a folder that holds a set of the same name,
    /// that set's other maps are removed (see `generate --help`, -o); give each partial set
    /// its own folder.
    #[arg(long, default_value = "all", value_name = "LIST", value_parser = parse_maps)]
    pub maps: MapList,
}

#[derive(Debug, Args)]
pub struct GenerateArgs {
    #[command(flatten)]
    pub preset: PresetArgs,
    /// Output folder (created if missing). A set written over an earlier one of the same
    /// name replaces all of it: the earlier set's maps this run does not write (not in
    /// --maps) are removed, unless changed since, and each one removed is named.
    #[arg(short, long, default_value = ".", value_name = "DIR")]
    pub out: PathBuf,
    /// Width of every map in pixels (16 to 16384); the tile is square, a body atlas is
    /// `body.length` widths tall (at most 65535 rows: 5461 wide at the default length 12).
    #[arg(long, default_value_t = snakeskin::DEFAULT_SIZE, value_parser = set_size())]
    pub size: u64,
    /// Normal map convention: opengl (+Y up, glTF/Blender) or directx (+Y down, Unreal).
    #[arg(long, value_enum, default_value_t = Convention::Opengl)]
    pub normal_convention: Convention,
    /// What the set covers: tile (a square that repeats both ways) or body (the whole
    /// snake, snout at the top, tail tip at the bottom, with the preset's [body] counts,
    /// head shields and marks, and tail; u still wraps round the body, v does not).
    /// A body atlas is evaluated a strip at a time, so its evaluation's memory does not grow
    /// with its length; its compressed PNGs are held until written (about the maps' raw
    /// size at most, a few bytes a pixel), an EXR's float maps whole (see --format).
    #[arg(long, value_enum, default_value_t = LayoutArg::Tile)]
    pub layout: LayoutArg,
    /// File format: png (8/16-bit, the default) or exr (OpenEXR floats in physical units:
    /// linear half colour and roughness, float height, normal xyz in [-1, 1] and film
    /// thickness in nm; a body atlas's float maps are held whole until written).
    #[arg(long, value_enum, default_value_t = FormatArg::Png)]
    pub format: FormatArg,
    /// Write the textures an engine reads instead of the maps: every pack has the base colour
    /// and (for a species with a film) the film thickness, and besides them gltf an OpenGL
    /// normal and
    /// occlusion-roughness-metallic, unreal ORM, a DirectX normal and the height, unity-hdrp
    /// the mask map (smoothness in alpha), an OpenGL normal and the height; see the README's
    /// packing table. Sets the normal convention the engine expects.
    #[arg(long, value_enum, value_name = "ENGINE", conflicts_with_all = ["normal_convention", "format", "maps"])]
    pub pack: Option<PackArg>,
    /// With --pack: compute the ambient occlusion map (horizon-based, from the height map)
    /// into the pack's occlusion channel instead of 1 everywhere. Without a pack, name the
    /// map instead: --maps all,ao.
    // The conflicts are --pack's own: clap's `requires = "pack"` was not checked when an
    // argument that conflicts with --pack came with it, so `--ao --format png` was silently
    // a set without occlusion. A missing --pack is refused after parsing, with a hint
    // (`Cli::try_parse_checked_from`); so is `--maps` without one, where the hint names the
    // maps given with `ao` added (with --pack, --pack's own conflict refuses it).
    #[arg(long, conflicts_with_all = ["normal_convention", "format"])]
    pub ao: bool,
    /// Print per-node evaluations, time and buffer size after the run.
    #[arg(long)]
    pub stats: bool,
}

#[derive(Debug, Args)]
pub struct ExportArgs {
    #[command(flatten)]
    pub source: PresetSource,
    /// The file to write: NAME.glb (everything in one binary file) or NAME.gltf (JSON, with
    /// NAME.bin and NAME.basecolor.png, NAME.normal.png, NAME.orm.png and,
    /// with a film of more than one thickness, NAME.thickness.png beside it). `-o FILE`, as
    /// the other commands write their output, is the same flag, and so is `--out FILE`.
    #[arg(short = 'o', long, visible_alias = "out", value_name = "FILE")]
    pub gltf: PathBuf,
    /// Texture width in pixels, 16 to 16384 (a body atlas is `body.length` widths tall, at
    /// most 65535 rows: 5461 wide at the default length 12; WebGL viewers commonly load
    /// textures up to 16384 texels a side).
    #[arg(long, default_value_t = snakeskin::DEFAULT_SIZE, value_parser = set_size())]
    pub size: u64,
    /// snake (the preview's body), sphere (the material alone, tile layout) or plane.
    #[arg(long, value_enum, default_value_t = MeshArg::Snake)]
    pub mesh: MeshArg,
    /// tile (the tile repeated along the body) or body (a body atlas once over the whole
    /// snake: head, neck, tail).
    #[arg(long, value_enum, default_value_t = LayoutArg::Tile)]
    pub layout: LayoutArg,
    /// Compute the ambient occlusion map into the ORM texture's R and reference it as the
    /// material's occlusionTexture (otherwise occlusion is 1 and not referenced).
    #[arg(long)]
    pub ao: bool,
}

#[derive(Debug, Args)]
pub struct BatchArgs {
    /// The jobs file: [[job]] tables with `preset` (a built-in name or a .toml path relative
    /// to the jobs file) and optional `seeds = [..]`, `sizes = [..]`, `maps = "color,normal"`,
    /// `format = "png"|"exr"`, `pack = "gltf"|"unreal"|"unity-hdrp"` (with `ao = true`: the
    /// pack's occlusion channel computed, as --ao), `layout = "tile"|"body"`,
    /// `normal_convention = "opengl"|"directx"` (without a pack) and `set = { "scales.rows" = 23 }`. Every combination of seeds and sizes is one job.
    #[arg(value_name = "JOBS.toml")]
    pub jobs: PathBuf,
    /// Output folder: each job writes
    /// DIR/<preset>/<layout>-<size>-seed<seed>-<format or pack-ENGINE[-ao]>[-directx][-<maps>][-set<hash>]/
    /// (the maps joined by + when not all five, the overrides' hash when the job has `set`),
    /// and the run an index of its jobs (DIR/index.json, or index.shard-K-of-N.json).
    #[arg(short, long, value_name = "DIR")]
    pub out: PathBuf,
    /// Run only the jobs whose index is K modulo N (K from 0): one array task's share, the
    /// same split on every machine (Slurm: $SLURM_ARRAY_TASK_ID/N; Kubernetes Indexed Job:
    /// $JOB_COMPLETION_INDEX/N).
    #[arg(long, value_name = "K/N", value_parser = parse_shard)]
    pub shard: Option<snakeskin::batch::Shard>,
    /// List the shard's jobs and whether each is done, without running any.
    #[arg(long)]
    pub list: bool,
    /// How many jobs run at once, 1 to 16 (default: 2, or 1 on a one-core machine). Each job
    /// still uses every core; running two fills the gaps at each job's start and end. Peak
    /// memory is the sum of the running jobs' (fewer run at once if the largest jobs would
    /// not fit in the available memory together). Files are the same at any value.
    #[arg(long, value_name = "N", value_parser = ranged_u32(1, snakeskin::batch::MAX_CONCURRENCY as u32))]
    pub concurrent: Option<u32>,
}

fn parse_shard(s: &str) -> Result<snakeskin::batch::Shard, String> {
    s.parse().map_err(|e: snakeskin::batch::BatchError| e.to_string())
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum MeshArg {
    Snake,
    Sphere,
    Plane,
}

impl MeshArg {
    pub fn kind(self) -> snakeskin::gltf_export::MeshKind {
        match self {
            MeshArg::Snake => snakeskin::gltf_export::MeshKind::Snake,
            MeshArg::Sphere => snakeskin::gltf_export::MeshKind::Sphere,
            MeshArg::Plane => snakeskin::gltf_export::MeshKind::Plane,
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum PackArg {
    Gltf,
    Unreal,
    UnityHdrp,
}

impl PackArg {
    pub fn pack(self) -> snakeskin::export::pack::Pack {
        use snakeskin::export::pack::Pack;
        match self {
            PackArg::Gltf => Pack::Gltf,
            PackArg::Unreal => Pack::Unreal,
            PackArg::UnityHdrp => Pack::UnityHdrp,
        }
    }
}

#[derive(Debug, Args)]
pub struct PreviewArgs {
    #[command(flatten)]
    pub source: PresetSource,
    /// Write the rendered image to this PNG file (headless; no window needed).
    #[arg(short, long, value_name = "FILE.png")]
    pub out: Option<PathBuf>,
    /// Open a window: drag to orbit, wheel to zoom, sliders for the optics, S to save the
    /// view as a PNG (see --shots), R to reset the view; the preset file is watched and
    /// reloaded on save.
    // Not with --out or --reference: the window wrote neither, silently.
    #[arg(long, conflicts_with_all = ["out", "reference"])]
    pub window: bool,
    /// Image or window size WIDTHxHEIGHT (or one number for a square), each 16 to 8192 pixels.
    #[arg(long, default_value = "1280x720", value_parser = parse_image_size)]
    pub size: ImageSize,
    /// What to show: a layer stage (diffuse, normal, film, all; thesis Fig. 5.12) or one map
    /// unlit on the body (map:color, map:height, map:normal, map:roughness, map:iridescence).
    #[arg(long, default_value = "all", value_name = "STAGE", value_parser = parse_view)]
    pub layers: View,
    /// Film colour method: lut (default), rgb3, spectral-N (N = 1 to 421, e.g. spectral-16),
    /// gaussian-fit, or spectral (the 1 nm reference sum in the shader, spectral-421: slow,
    /// for checks).
    #[arg(long, default_value = "lut", value_name = "M", value_parser = parse_gpu_method)]
    pub method: GpuFilmMethod,
    /// Layer model: layered (default; the stack's transport: (n0/n2)², internal
    /// reflection, the rough top's energy coupling; the colour map is the visible colour
    /// and the base albedo is recovered from it) or thesis (the thesis' eq. 4.21, which
    /// reads the colour map as the base albedo k_d), for comparison.
    #[arg(long, default_value = "layered", value_parser = parse_model)]
    pub model: Model,
    /// Map resolution for the preview (pixels per side; a body atlas's width, narrowed
    /// if it would be more than 8192 rows long), 64 to 4096.
    #[arg(long, default_value_t = 1024, value_parser = map_size())]
    pub map_size: u64,
    /// tile (the default: the tile repeated along the body) or body (a body atlas on the
    /// whole snake: head marks on the head, the tail's pattern on the tail).
    #[arg(long, value_enum, default_value_t = LayoutArg::Tile)]
    pub layout: LayoutArg,
    /// With --window: render N frames (1 to 1,000,000), print the mean frame time and exit.
    // (`requires = "window"` is met by a bool flag's default: refused with the headless
    // outputs instead, the one way to run without a window.)
    #[arg(
        long,
        value_name = "N",
        conflicts_with_all = ["out", "reference"],
        value_parser = ranged_u32(1, 1_000_000)
    )]
    pub frames: Option<u32>,
    /// With --window: the folder the S key saves the view into (made if missing), as
    /// NAME_view_N.png for the first N free: the frame without the panel, at the window's
    /// size, as --out would render it with the same camera. The line that names the file
    /// gives the sliders' changes as --set arguments for generate or export.
    #[arg(long, value_name = "DIR", default_value = ".", conflicts_with_all = ["out", "reference"])]
    pub shots: PathBuf,
    /// Exposure multiplier before tone mapping (Khronos PBR Neutral), 1e-6 to 1000 (not for
    /// the map: views, which show each map as its file stores it).
    #[arg(long, default_value_t = 1.0, value_parser = parse_exposure)]
    pub exposure: f32,
    /// Number of snakes (instanced in a grid), 1 to 400.
    #[arg(long, default_value_t = 1, value_parser = ranged_u32(1, 400))]
    pub snakes: u32,
    /// Hide the ground plane.
    #[arg(long)]
    pub no_ground: bool,
    /// How a pixel that covers scales of several film thicknesses (a distant snake) shades
    /// the film: spread (the default) reads the film at two thicknesses either side of the
    /// footprint's mean, placed from its spread (read from the thickness map's mips), and
    /// averages the reads, so the far film is about as colourful as its scales' average;
    /// mean reads the mean thickness once (half the film reads where the thickness varies,
    /// but the far film too saturated: BENCHMARKS.md, "Iridescence seen from afar").
    #[arg(long, value_enum, default_value_t = FootprintArg::Spread, value_name = "HOW")]
    pub film_footprint: FootprintArg,
    /// Frame the mid-body closely instead of the whole snake (of one snake: not with --snakes
    /// above 1).
    #[arg(long)]
    pub close_up: bool,
    /// Also shade the frame on the CPU with the f64 spectral reference, print mean and p99
    /// CIEDE2000 against the GPU image, and write the error heat map to this PNG. The check
    /// renders a frame of its own with the same preset, size, camera, method and model, but
    /// always the whole stack (--layers all), one sample per pixel and no ground, so its
    /// figures are the shading model's, not the PNG's anti-aliasing. The reference costs
    /// about 3 ms per covered pixel on two cores: 3.5 minutes at --size 480x300 with
    /// --close-up, 20 minutes or more at the default size.
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
    /// tile (the default) or body: the graph `generate --layout body` evaluates for a body
    /// atlas (head marks, plates along the body, tail), strip by strip.
    #[arg(long, value_enum, default_value_t = LayoutArg::Tile)]
    pub layout: LayoutArg,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum FootprintArg {
    Spread,
    Mean,
}

impl FootprintArg {
    pub fn footprint(self) -> snakeskin::render::engine::renderer::FilmFootprint {
        use snakeskin::render::engine::renderer::FilmFootprint;
        match self {
            FootprintArg::Spread => FilmFootprint::Spread,
            FootprintArg::Mean => FilmFootprint::Mean,
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum FormatArg {
    Png,
    Exr,
}

impl FormatArg {
    pub fn format(self) -> snakeskin::material::FileFormat {
        match self {
            FormatArg::Png => snakeskin::material::FileFormat::Png,
            FormatArg::Exr => snakeskin::material::FileFormat::Exr,
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum LayoutArg {
    Tile,
    Body,
}

impl LayoutArg {
    pub fn layout(self) -> snakeskin::maps::Layout {
        match self {
            LayoutArg::Tile => snakeskin::maps::Layout::Tile,
            LayoutArg::Body => snakeskin::maps::Layout::Body,
        }
    }
}

#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum Convention {
    Opengl,
    Directx,
}

#[derive(Debug, Subcommand)]
pub enum PresetsCommand {
    /// One preset per line under a header: name, species (scientific name), common name, category.
    List,
    /// Print a built-in preset's TOML (a start for one of your own).
    Show {
        /// A built-in preset's name (`presets list`).
        name: String,
    },
}

fn parse_key_value(arg: &str) -> Result<(String, String), String> {
    if arg.chars().any(char::is_control) {
        return Err(
            "KEY=VALUE must be one line without control characters (a newline would add TOML of its own)".into()
        );
    }
    let (key, value) = arg.split_once('=').ok_or_else(|| format!("expected KEY=VALUE, got {arg:?}"))?;
    if key.trim().is_empty() {
        return Err(format!("empty key in {arg:?}"));
    }
    Ok((key.trim().to_string(), value.trim().to_string()))
}

#[derive(Debug, Args)]
pub struct StackArgs {
    /// Refractive index of the ambient medium (thesis n0), 1 to 3.
    #[arg(long, default_value_t = thesis::AMBIENT_IOR, value_parser = parse_ior)]
    pub n0: f64,
    /// Refractive index of the iridescent film (thesis n1), 1 to 3.
    #[arg(long, default_value_t = thesis::FILM_IOR, value_parser = parse_ior)]
    pub n1: f64,
    /// Refractive index of the pigment layer under the film (thesis n2), 1 to 3.
    #[arg(long, default_value_t = thesis::PIGMENT_IOR, value_parser = parse_ior)]
    pub n2: f64,
}

#[derive(Debug, Subcommand)]
pub enum BrdfCommand {
    /// The exact coherent film at one wavelength: {"rs","rp","r","ts","tp","t"}.
    Film {
        #[command(flatten)]
        stack: StackArgs,
        /// Film thickness in nm (thesis δ0), 0 to 10,000,000 (10 mm).
        #[arg(long, required_unless_present = "batch", value_parser = parse_thickness_nm)]
        thickness_nm: Option<f64>,
        /// Vacuum wavelength in nm, 1 to 1,000,000 (1 mm).
        #[arg(long, required_unless_present = "batch", value_parser = parse_wavelength_nm)]
        wavelength_nm: Option<f64>,
        /// Incidence angle in the ambient medium, degrees from the normal, 0 to 90.
        #[arg(long, required_unless_present = "batch", value_parser = parse_angle_deg)]
        angle_deg: Option<f64>,
        /// Read JSON objects {n0, n1, n2, thickness_nm, wavelength_nm, angle_deg}, one per
        /// line, from FILE (or - for stdin); print one JSON line per query, in order, as each
        /// is answered (blank lines are skipped). Each line carries its own values (n0, n1
        /// and n2 default to the thesis'), so the flags above are refused. A bad line stops
        /// the run with its line number (exit 2), after the answers to the lines before it.
        #[arg(long, value_name = "FILE", conflicts_with_all = ["n0", "n1", "n2", "thickness_nm", "wavelength_nm", "angle_deg"])]
        batch: Option<String>,
    },
    /// The film's reflectance colour in linear sRGB under D65: {"rgb":[r,g,b]}.
    Color {
        #[command(flatten)]
        stack: StackArgs,
        /// Film thickness in nm (thesis δ0), 0 to 10,000,000 (10 mm).
        #[arg(long, required_unless_present = "batch", value_parser = parse_thickness_nm)]
        thickness_nm: Option<f64>,
        /// Angle of light and view from the normal in the ambient medium, degrees, 0 to 90.
        #[arg(long, required_unless_present = "batch", value_parser = parse_angle_deg)]
        angle_deg: Option<f64>,
        /// Colour method: spectral (the reference: the exact film summed at 1 nm over CIE
        /// 1931 2° under D65), rgb3, spectral-N (N = 1 to 421, e.g. spectral-16), gaussian-fit,
        /// lut.
        #[arg(long, default_value = "spectral", value_parser = parse_method)]
        method: Method,
        /// Read JSON objects {n0, n1, n2, thickness_nm, angle_deg, method}, one per line, from
        /// FILE (or - for stdin); print one JSON line per query, in order, as each is answered
        /// (blank lines are skipped). Each line carries its own values (n0, n1 and n2 default
        /// to the thesis', method to spectral), so the flags above are refused. A bad line
        /// stops the run with its line number (exit 2), after the answers to the lines before
        /// it.
        #[arg(long, value_name = "FILE", conflicts_with_all = ["n0", "n1", "n2", "thickness_nm", "angle_deg", "method"])]
        batch: Option<String>,
    },
    /// The full multi-layer BRDF for given directions and layer parameters, as JSON:
    /// {"model","f":[r,g,b],"specular":[r,g,b],"diffuse":[r,g,b]}, each per steradian and
    /// without the cosine factor; "f" is the BRDF, the sum of the top's reflection
    /// ("specular": single and multiple scattering) and what comes back from under it
    /// ("diffuse").
    Eval(EvalArgs),
    /// The directional albedo for light from one angle, by numerical integration of a
    /// model or by a reference: {"model","albedo":[r,g,b],"specular":[r,g,b],"diffuse":[r,g,b]}
    /// (and "sigma" for the stochastic reference). With --albedo 1 and no absorption the
    /// stack loses nothing: the answer should be 1 (see --model; with --n1 below --n0, a film
    /// over 250 nm and roughness under 0.3 the layered model is off by up to 0.04 within a few
    /// degrees of the film's critical angle; with --n0 over about 1.35 times --n2 under rough
    /// tops it reflects up to about 1.07, and with --n0 above --n2 by less than about 3 % up to
    /// 1.6 of grazing light: it says so).
    Albedo(AlbedoArgs),
    /// A thin-film colour chart PNG: thickness 0..2000 nm across, angle 0..89° down, its
    /// brightest channel scaled to 1 (the scale is printed: a dim film's chart is as
    /// readable as a bright one's; a stack that reflects nothing, n0 = n1 = n2, is black).
    Chart {
        #[command(flatten)]
        stack: StackArgs,
        /// Output PNG file.
        #[arg(short, long)]
        out: PathBuf,
        /// Colour method: spectral (the 1 nm reference), rgb3, spectral-N (N = 1 to 421),
        /// gaussian-fit, lut.
        #[arg(long, default_value = "spectral", value_parser = parse_method)]
        method: Method,
        /// Chart width in pixels (thickness samples), 2 to 4096.
        #[arg(long, default_value_t = 800, value_parser = ranged_u32(2, 4096))]
        width: u32,
        /// Chart height in pixels (angle samples), 2 to 4096.
        #[arg(long, default_value_t = 300, value_parser = ranged_u32(2, 4096))]
        height: u32,
    },
    /// Random and adversarial inputs: counts NaN and Inf (`nan`, `inf`), the range of R and T
    /// (`min_r`, `max_r`) and how far R + T strays from 1 (`film_energy_err`: the stress'
    /// films absorb nothing), the f32 film kernels' range (`film_f32_min_r`,
    /// `film_f32_max_r`) and worst deviation from f64 (`max_film_f32_dev`, films up to 2000
    /// nm), the worst white-furnace albedo of the thesis model, which must never pass 1 but by
    /// the quadrature's rounding in the last bits (`max_albedo`), every model's furnace range
    /// (`furnace_by_model`: the layered model's is about 1, off at the grazing, n0 > n2 and
    /// near-matched draws) and the f32 BRDF's worst deviation from f64 (`max_f32_dev`; JSON
    /// with --json).
    Stress {
        /// Number of random samples, 1 to 10,000,000 (the default takes about 40 seconds on
        /// two cores, nearly all of them baking tables whatever the count: 12 the nine stacks'
        /// film tables, about 30 more the layered model's coupling tables, which a thousand
        /// samples already reach; 1,000,000 take about 95).
        #[arg(long, default_value_t = 100_000, value_parser = ranged_u64(1, 10_000_000))]
        samples: u64,
        /// Seed of the sample generator, 0 to 4294967295 (its hash takes 32 bits: a larger
        /// seed was folded onto a smaller one's samples).
        #[arg(long, default_value_t = 1, value_parser = ranged_u32(0, u32::MAX))]
        seed: u32,
        /// Print one JSON object instead of a table.
        #[arg(long)]
        json: bool,
    },
}

#[derive(Debug, Args)]
pub struct EvalArgs {
    #[command(flatten)]
    pub stack: StackArgs,
    /// Direction towards the light, x,y,z (need not be normalised; at least 1e-6 long, each
    /// number at most 1e6 in size).
    #[arg(long, value_parser = parse_direction, allow_hyphen_values = true)]
    pub wi: [f64; 3],
    /// Direction towards the viewer, x,y,z (as --wi).
    #[arg(long, value_parser = parse_direction, allow_hyphen_values = true)]
    pub wo: [f64; 3],
    /// Shading normal, x,y,z (as --wi; 0,0,0 falls back to 0,0,1, as a blank normal map does).
    #[arg(long, value_parser = parse_normal, default_value = "0,0,1", allow_hyphen_values = true)]
    pub normal: [f64; 3],
    #[command(flatten)]
    pub layer: LayerArgs,
    /// Layer model under the top interface: layered (default; the stack's transport) or
    /// thesis (the thesis' eq. 4.21 diffuse lobe; README, "Which layer model"). The
    /// layered model's tables ship built for the default indices (--n0 1, --n2 2): a query
    /// takes well under a second; other indices walk their path table first, once per run
    /// (1.5 s on two cores for --n2 1.5; longer as --n2 nears --n0, where light crosses a
    /// rough top back and forth before it leaves: 9 s of processor time for --n2 1.001, 48 s
    /// for 1.000001; the evaluation itself well under a microsecond).
    #[arg(long, default_value = "layered", value_parser = parse_model)]
    pub model: Model,
    /// Film colour method (as for `brdf color`; spectral = the exact 1 nm sum).
    #[arg(long, default_value = "spectral", value_parser = parse_method)]
    pub method: Method,
}

/// The layer parameters `brdf eval` and `brdf albedo` share.
#[derive(Debug, Args)]
pub struct LayerArgs {
    /// Film thickness in nm (thesis δ0), 0 to 10,000,000 (10 mm).
    #[arg(long, default_value_t = thesis::FILM_THICKNESS_NM, value_parser = parse_thickness_nm)]
    pub thickness_nm: f64,
    /// Perceptual roughness (GGX α = roughness², floored at α 0.001: below about 0.032 all read
    /// as 0.032, a mirror to the eye), 0 to 1.
    #[arg(long, default_value_t = 0.35, value_parser = parse_unit)]
    pub roughness: f64,
    /// Absorption coefficient σ0 (one value, or r,g,b), each 0 to 100. The default is the
    /// thesis' 0.6, as every default here is the thesis' value; a preset's
    /// `optics.absorption` defaults to 0 (give --absorption 0 to match it).
    // The default is thesis::ABSORPTION written out (clap needs text for an array); the
    // test `brdf_eval_defaults_are_the_thesis_values` ties the two.
    #[arg(long, value_parser = parse_absorption, default_value = "0.6", allow_hyphen_values = true)]
    pub absorption: [f64; 3],
    /// Pigment layer thickness δ1 (optical depth τ = σ0 δ1), 0 to 100.
    #[arg(long, default_value_t = thesis::PIGMENT_THICKNESS, value_parser = parse_pigment_thickness)]
    pub pigment_thickness: f64,
    /// Base albedo k_d, linear r,g,b (or one value), each 0 to 1: the Lambertian base
    /// itself, not the visible colour a colour map holds.
    #[arg(long, value_parser = parse_albedo, default_value = "1", allow_hyphen_values = true)]
    pub albedo: [f64; 3],
}

#[derive(Debug, Args)]
pub struct AlbedoArgs {
    #[command(flatten)]
    pub stack: StackArgs,
    /// Angle of the light from the normal in degrees, 0 to 90 (by reciprocity also the
    /// view angle of the albedo seen under a uniform sky).
    #[arg(long, value_parser = parse_angle_deg)]
    pub angle_deg: f64,
    #[command(flatten)]
    pub layer: LayerArgs,
    /// Film colour method for --model thesis | layered (as for `brdf color`; refused with
    /// the references, which read the exact film). lut, the default here, is the
    /// renderer's table: the integration reads the film thousands of times: at the defaults
    /// and 45°, 0.05 s with lut (computing only the texels it reads) and 4 s with spectral
    /// (the exact 1 nm sum) on two cores, agreeing within 2e-4, under the integration's own
    /// 2e-3.
    #[arg(long, value_parser = parse_method)]
    pub method: Option<Method>,
    /// thesis | layered: the model's BRDF integrated over the hemisphere (64 × 64
    /// stratified half vectors for the specular lobe, 4096 midpoints in cos θ for the
    /// diffuse lobe; within 2e-3 of the exact albedo on known cases to 88.5°: closer to
    /// grazing a mirror-smooth top's lobe is narrower than the stratification, and at
    /// roughness 0 the layered model reads 0.903 against the closed form's 0.906 at 89°, 0.878
    /// against 0.990 at 89.9°). reference: the
    /// smooth-top stack in closed form (roughness ignored; Gauss–Legendre, within 5e-5 on
    /// the stacks measured, but up to 5e-4 with a thick film less dense than --n0).
    /// stochastic: photons through the stack with a rough GGX top; adds "sigma", the
    /// standard error per channel. The references read the exact 1 nm film (--method is
    /// for the models), as RGB colours clamped to [0, 1] per channel as the models read
    /// them: where the film's colour lies outside sRGB that moves them from the spectral
    /// physics by up to ΔE00 4 (README, "two references"). layered walks its path table first where `brdf eval --model` does.
    #[arg(long, default_value = "layered", value_parser = parse_albedo_model)]
    pub model: AlbedoModel,
    /// Photons per channel for --model stochastic (only), 1000 to 100,000,000 (σ ∝ 1/√N);
    /// default 200,000. On one thread: about 10 s of processor time per 10,000,000.
    #[arg(long, value_parser = ranged_u64(1000, 100_000_000))]
    pub photons: Option<u64>,
}

/// What `brdf albedo` integrates: a real-time model or one of the references.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AlbedoModel {
    Model(Model),
    Reference,
    Stochastic,
}

fn parse_albedo_model(text: &str) -> Result<AlbedoModel, String> {
    match text {
        "reference" => Ok(AlbedoModel::Reference),
        "stochastic" => Ok(AlbedoModel::Stochastic),
        _ => Model::parse(text)
            .map(AlbedoModel::Model)
            .ok_or_else(|| format!("accepted: {}, reference, stochastic", Model::ACCEPTED)),
    }
}

fn parse_angle_deg(text: &str) -> Result<f64, String> {
    bounded(text, ranges::ANGLE_DEG)
}

#[derive(Debug, Subcommand)]
pub enum BenchCommand {
    /// Frame time of the skin shader against a plain PBR shader on the same scene (GPU
    /// timestamps where available), the specialised variants (no film, the other side of the
    /// absorption switch, the film read at each pixel's mean thickness), 20 snakes, and the
    /// CPU reference comparison (mean and p99 CIEDE2000).
    Render {
        /// Preset to render.
        #[arg(default_value = "xenopeltis-unicolor")]
        preset: String,
        /// Frame size WIDTHxHEIGHT (or one number for a square), each 16 to 8192 pixels (use
        /// 1920x1080 on a real GPU).
        #[arg(long, default_value = "1280x720", value_parser = parse_image_size)]
        size: ImageSize,
        /// Timed frames per variant, 3 to 10,000 (after 3 warm-up frames); the median is reported.
        #[arg(long, default_value_t = 30, value_parser = ranged_u64(3, 10_000))]
        frames: u64,
        /// Map resolution (pixels per side), 64 to 4096.
        #[arg(long, default_value_t = 1024, value_parser = map_size())]
        map_size: u64,
        /// Frame size of the CPU reference comparison (the CPU shades each pixel spectrally,
        /// about 3 ms per covered pixel on two cores: minutes at the default, hours at a
        /// full-HD frame); WIDTHxHEIGHT, each 16 to 8192 pixels.
        #[arg(long, default_value = "480x300", value_parser = parse_image_size)]
        reference_size: ImageSize,
        /// Time only the variants that read the film table (plain, skin, skin at the mean
        /// thickness, thesis, no film, absorption, twenty snakes): skip skin-rgb3, skin-spectral-8 and skin-gaussian-fit,
        /// which evaluate the film at every pixel and take most of a run (on a hardware GPU
        /// about 1 s a round of the 1.1 s, on lavapipe seconds a frame).
        #[arg(long)]
        lut_only: bool,
        /// Print one JSON object.
        #[arg(long)]
        json: bool,
    },
    /// The BRDF (LUT film) per million evaluations: WGSL compute shader on the GPU and the
    /// Rust f32 twin on one CPU core, side by side in one run. The GPU time is the difference
    /// between one dispatch and 1 + N in one submission (N = 10, or tenfold more until the
    /// difference spans 20 ms: a fast GPU is timed over more work), median of five.
    Gpu {
        /// Evaluations per dispatch, 1000 to 1,000,000.
        // The bound is the GPU's, not the bench's: the samples (112 bytes each) are one
        // storage binding, at most 128 MiB under the limits the device is opened with
        // (1,198,372 samples); above it wgpu panicked with a validation error.
        #[arg(long, default_value_t = 1_000_000, value_parser = ranged_u64(1000, 1_000_000))]
        samples: u64,
        /// Layer model to evaluate: layered (default) or thesis.
        #[arg(long, default_value = "layered", value_parser = parse_model)]
        model: Model,
        /// Print one JSON object.
        #[arg(long)]
        json: bool,
    },
    /// Time against error of every film colour method on a grid of film thickness × angle
    /// over four materials, (n0, n1, n2) = (1, 1.55, 2), (1, 1.33, 1.56), (1, 1.56, 1.33)
    /// and (1.33, 1.55, 2), against the 1 nm spectral reference.
    Irid {
        /// Print JSON {"default", "methods": [{"name","mean_de","p95_de","max_de","ns_per_eval"}]}.
        #[arg(long)]
        json: bool,
        /// Write an SVG plot of the mean error (ΔE00 against the spectral reference) against CPU
        /// cost, one point per method.
        #[arg(long, value_name = "FILE")]
        plot: Option<PathBuf>,
        /// Thickness step of the grid in nm (the grid spans 0..2000 nm), 0.1 to 2000; the grid
        /// takes at most 400,000 points over its four materials, so with 1° angle steps the
        /// finest is 1.81 nm (0.1 nm needs angle steps over 22.25°).
        #[arg(long, default_value_t = 10.0, value_parser = parse_d_step_nm)]
        d_step_nm: f64,
        /// Angle step of the grid in degrees (0..89°), 0.1 to 89.
        #[arg(long, default_value_t = 1.0, value_parser = parse_angle_step_deg)]
        angle_step_deg: f64,
        /// Also measure other LUT sizes (the table-size trade-off).
        #[arg(long)]
        lut_sweep: bool,
    },
    /// Every layer model against the stochastic reference (photons through the stack with a
    /// rough GGX top) on a fixed grid: the four materials of `bench irid`, τ ∈ {0, 0.4, 1}, films
    /// of 250 and 650 nm, light at 0–85°, roughness 0.05–0.9, every species' base colours.
    /// Reports the reflected colour's ΔE00 (mean, p95, max), the white-furnace error and the
    /// CPU cost per evaluation (inputs at random thicknesses, and the same sorted by
    /// thickness as a frame reads them). Takes under a minute on two cores at the default
    /// photon count (45 s measured, 87 s of CPU); the models' own albedo integration, which
    /// fewer photons do not shorten, is most of it (34 s at 1000 photons).
    Layered {
        /// Print JSON {"models": [{"name","mean_de","p95_de","max_de","max_furnace_err",
        /// "max_furnace_err_to_70","ns_per_eval","ns_per_eval_coherent"}], "points",
        /// "photons_per_channel", "reference_noise_mean_de", "reference_noise_max_de",
        /// "furnace": [[model, roughness, angle_deg, max |albedo − 1|]],
        /// "error_by_roughness_angle": [[model, roughness, angle_deg, mean ΔE00, max ΔE00]],
        /// "error_by_optical_depth": [[model, τ, mean ΔE00, max ΔE00]]}.
        #[arg(long)]
        json: bool,
        /// Photons per channel per reference walk, 1000 to 10,000,000 (noise ∝ 1/√N; the
        /// report says what it makes in ΔE: up to about 1.7 ΔE00 at the default, 1 at
        /// 100,000, 0.25 at 1,600,000, which BENCHMARKS.md uses and which takes about eight
        /// minutes on two cores).
        #[arg(long, default_value_t = 40_000, value_parser = ranged_u64(1000, 10_000_000))]
        photons: u64,
        /// Write an SVG plot of the mean error (ΔE00 against the photon walk) against CPU
        /// cost, one point per model (the JSON has p95 and max).
        #[arg(long, value_name = "FILE")]
        plot: Option<PathBuf>,
    },
}

/// `--maps`: the maps to produce, in `MapKind` order, each once.
#[derive(Debug, Clone)]
pub struct MapList(pub Vec<MapKind>);

fn parse_maps(list: &str) -> Result<MapList, String> {
    snakeskin::material::parse_map_list(list).map(MapList)
}

/// An image size in pixels, WIDTHxHEIGHT (or one number for a square).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ImageSize {
    pub width: u32,
    pub height: u32,
}

fn parse_image_size(text: &str) -> Result<ImageSize, String> {
    let range = snakeskin::render::engine::prepare::IMAGE_RANGE;
    let bad = || {
        format!(
            "expected WIDTHxHEIGHT (e.g. 1280x720) or one number for a square, each {} to {} pixels",
            range.start(),
            range.end()
        )
    };
    let (w, h, square) = match text.split_once(['x', 'X']) {
        Some((w, h)) => (w.trim().parse().map_err(|_| bad())?, h.trim().parse().map_err(|_| bad())?, false),
        None => {
            let s: u32 = text.trim().parse().map_err(|_| bad())?;
            (s, s, true)
        }
    };
    // The side out of range named, as a number outside the range cannot be seen from the
    // range alone in a long `--size 10240x720`.
    let side = |name: &str, pixels: u32| -> Result<u32, String> {
        match range.contains(&pixels) {
            true => Ok(pixels),
            false => Err(format!(
                "the {name} {pixels} is out of range: each side {} to {} pixels",
                range.start(),
                range.end()
            )),
        }
    };
    let (width, height) = match square {
        true => (side("size", w)?, h),
        false => (side("width", w)?, side("height", h)?),
    };
    Ok(ImageSize { width, height })
}

fn parse_view(text: &str) -> Result<View, String> {
    View::parse(text).ok_or_else(|| format!("accepted: {}", View::ACCEPTED))
}

fn parse_method(text: &str) -> Result<Method, String> {
    Method::parse(text).ok_or_else(|| format!("accepted: {}", Method::ACCEPTED))
}

fn parse_model(text: &str) -> Result<Model, String> {
    Model::parse(text).ok_or_else(|| format!("accepted: {}", Model::ACCEPTED))
}

fn parse_gpu_method(text: &str) -> Result<GpuFilmMethod, String> {
    parse_method(text).map(GpuFilmMethod::from_method)
}

/// A finite number inside `lo..=hi`, for the flags that take one; `-0` is read as 0 (an
/// answer computed from it printed `-0.0`).
fn bounded(text: &str, (lo, hi): (f64, f64)) -> Result<f64, String> {
    if snakeskin::toml_text::underflows(text) {
        return Err(snakeskin::toml_text::underflow_message(text, &format!("a number in [{lo}, {hi}]")));
    }
    match text.trim().parse::<f64>() {
        // Adding 0 turns -0 into +0 and leaves every other number as it is (IEEE 754).
        Ok(v) if v.is_finite() && (lo..=hi).contains(&v) => Ok(v + 0.0),
        _ => Err(format!("must be a finite number in [{lo}, {hi}]")),
    }
}

fn parse_thickness_nm(text: &str) -> Result<f64, String> {
    bounded(text, ranges::FILM_THICKNESS_NM)
}

fn parse_ior(text: &str) -> Result<f64, String> {
    bounded(text, ranges::IOR)
}

fn parse_wavelength_nm(text: &str) -> Result<f64, String> {
    bounded(text, ranges::QUERY_WAVELENGTH_NM)
}

fn parse_unit(text: &str) -> Result<f64, String> {
    bounded(text, ranges::UNIT)
}

fn parse_pigment_thickness(text: &str) -> Result<f64, String> {
    bounded(text, ranges::PIGMENT_THICKNESS)
}

/// Above 0 in f32 too: 1e-50 passed a check of "> 0" and became 0 (a black frame).
fn parse_exposure(text: &str) -> Result<f32, String> {
    bounded(text, (1e-6, 1000.0)).map(|v| v as f32).map_err(|_| "must be a finite number from 1e-6 to 1000".into())
}

fn parse_d_step_nm(text: &str) -> Result<f64, String> {
    // Finer than 0.1 nm only repeats the 1 nm spectral reference's own resolution; the grid's
    // size is bounded with both steps together (`accuracy::MAX_GRID_POINTS`).
    bounded(text, (0.1, snakeskin::optics::lut::FINE_MAX_NM))
}

fn parse_angle_step_deg(text: &str) -> Result<f64, String> {
    bounded(text, (0.1, snakeskin::optics::accuracy::GRID_ANGLE_MAX_DEG))
}

/// One value for all three channels, or r,g,b; each inside `range`.
fn vec3_or_scalar(text: &str, range: (f64, f64)) -> Result<[f64; 3], String> {
    // A number nearer 0 than a float holds is told so, as for one number (`bounded`): the
    // list's words alone said only "a finite number in [0, 100]" of `1e-400`.
    if let Some(tiny) = text.split(',').find(|p| snakeskin::toml_text::underflows(p)) {
        return Err(snakeskin::toml_text::underflow_message(tiny, &format!("a number in [{}, {}]", range.0, range.1)));
    }
    let parts: Vec<&str> = text.split(',').collect();
    let values: Vec<f64> = parts
        .iter()
        .map(|p| bounded(p, range))
        .collect::<Result<_, _>>()
        .map_err(|_| format!("expected one number or r,g,b, each a finite number in [{}, {}]", range.0, range.1))?;
    match values.as_slice() {
        [v] => Ok([*v; 3]),
        [r, g, b] => Ok([*r, *g, *b]),
        _ => Err(format!("expected one number or r,g,b, each a finite number in [{}, {}]", range.0, range.1)),
    }
}

fn parse_absorption(text: &str) -> Result<[f64; 3], String> {
    vec3_or_scalar(text, ranges::ABSORPTION)
}

fn parse_albedo(text: &str) -> Result<[f64; 3], String> {
    vec3_or_scalar(text, ranges::UNIT)
}

fn parse_vec3(text: &str) -> Result<[f64; 3], String> {
    if let Some(tiny) = text.split(',').find(|p| snakeskin::toml_text::underflows(p)) {
        return Err(snakeskin::toml_text::underflow_message(tiny, "0 or a larger number"));
    }
    let parts: Vec<f64> = text
        .split(',')
        .map(|p| p.trim().parse::<f64>().map_err(|_| format!("expected x,y,z numbers, got {text:?}")))
        .collect::<Result<_, _>>()?;
    match parts.as_slice() {
        [x, y, z] if parts.iter().all(|v| v.is_finite() && v.abs() <= 1e6) => Ok([*x, *y, *z]),
        _ => Err("expected three finite numbers x,y,z (each at most 1e6 in size)".into()),
    }
}

/// A direction: three finite numbers, not all zero (it is normalised before use).
fn parse_direction(text: &str) -> Result<[f64; 3], String> {
    direction(parse_vec3(text)?)
}

/// `v` where it is at least 1e-6 long. The length by `hypot`, which does not underflow: the
/// sum of squares said "got length 0e0" of 1e-300,0,0 (a sweep).
fn direction(v: [f64; 3]) -> Result<[f64; 3], String> {
    let length = v[0].hypot(v[1]).hypot(v[2]);
    if length < 1e-6 {
        return Err(format!("a direction must be at least 1e-6 long (it is normalised), got length {length:e}"));
    }
    Ok(v)
}

/// A shading normal: a direction, or exactly 0,0,0 (the BRDF's fallback to 0,0,1). A normal
/// of 1e-9,0,0 was normalised to +x and one of 1e-300,0,0 fell back to +z (its squared length
/// underflows), while --wi refused both.
fn parse_normal(text: &str) -> Result<[f64; 3], String> {
    match parse_vec3(text)? {
        [0.0, 0.0, 0.0] => Ok([0.0; 3]),
        v => direction(v).map_err(|e| format!("{e}; or 0,0,0 for the fallback to 0,0,1")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `snakeskin ARGS...` parsed as the binary parses it: Ok, or clap's message.
    fn parse(args: &[&str]) -> Result<(), String> {
        let words = ["snakeskin"].iter().chain(args).map(|w| w.into()).collect();
        Cli::try_parse_checked_from(words).map(|_| ()).map_err(|e| e.to_string())
    }
    use clap::Parser;

    #[test]
    fn brdf_eval_defaults_are_the_thesis_values() {
        let cli = Cli::try_parse_from(["snakeskin", "brdf", "eval", "--wi", "0,0,1", "--wo", "0,0,1"]).unwrap();
        let Command::Brdf { command: BrdfCommand::Eval(args) } = cli.command else { panic!("parsed as brdf eval") };
        let stack = (args.stack.n0, args.stack.n1, args.stack.n2);
        assert_eq!(stack, (thesis::AMBIENT_IOR, thesis::FILM_IOR, thesis::PIGMENT_IOR));
        assert_eq!(args.layer.absorption, [thesis::ABSORPTION; 3]);
        assert_eq!(args.layer.pigment_thickness, thesis::PIGMENT_THICKNESS);
        assert_eq!(args.layer.thickness_nm, thesis::FILM_THICKNESS_NM);
        // The model's text default is the library's default model.
        assert_eq!(args.model, Model::default());
        // Negative control: a value given on the command line is not the default.
        let cli =
            Cli::try_parse_from(["snakeskin", "brdf", "eval", "--wi", "0,0,1", "--wo", "0,0,1", "--absorption", "0.5"]);
        let Command::Brdf { command: BrdfCommand::Eval(args) } = cli.unwrap().command else { panic!() };
        assert_ne!(args.layer.absorption, [thesis::ABSORPTION; 3]);
    }

    /// Preview flags that did nothing were accepted: --frames without --window, --out and
    /// --reference with it; --exposure -1 got clap's tip `-- -1` (which makes it the
    /// preset) and 1e-50 became 0 in f32. Negative control: each flag where it acts.
    #[test]
    fn preview_flags_that_would_do_nothing_are_refused() {
        let preview = |args: &[&str]| parse(&[&["preview", "natrix-natrix"][..], args].concat());
        for (args, says) in [
            (&["--out", "a.png", "--frames", "5"][..], "cannot be used with"),
            (&["--window", "--out", "a.png"], "cannot be used with"),
            (&["--window", "--reference", "h.png"], "cannot be used with"),
            (&["--out", "a.png", "--exposure", "-1"], "from 1e-6 to 1000"),
            (&["--out", "a.png", "--exposure", "1e-50"], "from 1e-6 to 1000"),
            // No frame drawn, or none counted: "0 frames, mean frame time NaN ms".
            (&["--window", "--frames", "0"], "0 is not in 1..=1000000"),
        ] {
            let error = preview(args).expect_err(&format!("{args:?} was accepted"));
            assert!(error.contains(says), "{args:?}: {error}");
        }
        for args in [&["--window", "--frames", "5"][..], &["--out", "a.png", "--exposure", "1e-6"]] {
            preview(args).unwrap();
        }
    }

    /// `--seed` and `--set seed=` take the same spellings (README: `--set seed=` is `--seed`):
    /// `0x10` was refused by the flag and `0016` by the override. Negative controls: what is
    /// not a whole number, or lies beyond the seed's range, is refused by both.
    #[test]
    fn the_seed_flag_and_the_seed_override_take_the_same_spellings() {
        let source = snakeskin::preset::read_source("natrix-natrix").unwrap();
        let by_override = |text: &str| {
            snakeskin::preset::parse(&source, &[("seed".into(), text.into())]).map(|loaded| loaded.preset.seed)
        };
        for text in ["16", "0016", "0x10", "0o20", "0b10000", "+16", "1_6", " 16 "] {
            assert_eq!(parse_seed(text), Ok(16), "--seed {text}");
            assert_eq!(by_override(text).ok(), Some(16), "--set seed={text}");
        }
        for text in ["1.6", "0x", "sixteen", "", "-16", "-0x10", "1e3", "9007199254740992", "0x20000000000000"] {
            assert!(parse_seed(text).is_err(), "--seed {text} was accepted");
            assert!(by_override(text).is_err(), "--set seed={text} was accepted");
        }
        // The value said: a whole number past the range was called "not a whole number".
        let error = by_override("99999999999999999999999").unwrap_err().to_string();
        assert!(error.contains("in [0, 9007199254740991], got 99999999999999999999999"), "{error}");
    }

    /// A number nearer 0 than a float holds was read as 0 by every flag that takes a number
    /// (`--thickness-nm 1e-400`: a bare interface, without a word). Negative controls: 0 and the
    /// smallest float are numbers.
    #[test]
    fn a_flags_number_that_underflows_is_refused() {
        let film = ["brdf", "film", "--wavelength-nm", "550", "--angle-deg", "0", "--thickness-nm"];
        for tiny in ["1e-400", "2.5E-330", "0.1e-330"] {
            let error = parse(&[&film[..], &[tiny]].concat()).expect_err(tiny);
            assert!(error.contains("is nearer 0 than a 64-bit float holds"), "{error}");
            let eval = ["brdf", "eval", "--wi", "0,0,1", "--wo"];
            let error = parse(&[&eval[..], &[&format!("1,0,-{tiny}")]].concat()).expect_err(tiny);
            assert!(error.contains("is nearer 0 than a 64-bit float holds"), "{error}");
            // A flag of one number or r,g,b (it said only "a finite number in [0, 100]").
            for list in [tiny.to_string(), format!("0.5,{tiny},0.5")] {
                let error = parse(&["brdf", "albedo", "--angle-deg", "0", "--absorption", &list]).expect_err(tiny);
                assert!(error.contains("is nearer 0 than a 64-bit float holds"), "{error}");
            }
        }
        for fine in ["0", "0.0", "-0", "0e-400", "5e-324"] {
            parse(&[&film[..], &[fine]].concat()).unwrap_or_else(|e| panic!("{fine}: {e}"));
        }
    }

    /// A negative number is a flag's value, refused with the flag's range: `--size -16` said
    /// "unexpected argument '-1'" with clap's tip `-- -1`, which made it another error, and
    /// so did the ones clap does not read as numbers (`-1e-3`, `-.5`, `-inf`: a sweep).
    /// Negative controls: a value in range, a flag after a flag is still a missing value,
    /// and a word after `--` is no flag's.
    #[test]
    fn a_negative_number_is_refused_with_the_flags_range() {
        for (args, says) in [
            (&["generate", "natrix-natrix", "--size", "-16"][..], "-16 is not in 16..=16384"),
            (&["generate", "natrix-natrix", "--seed", "-1"], "-1 is not in 0..=9007199254740991"),
            (
                &["generate", "natrix-natrix", "--seed", "9007199254740992"],
                "9007199254740992 is not in 0..=9007199254740991",
            ),
            (&["brdf", "stress", "--samples", "18446744073709551616"], "18446744073709551616 is not in 1..=10000000"),
            (&["export", "natrix-natrix", "--gltf", "a.glb", "--size", "-1"], "-1 is not in 16..=16384"),
            (&["preview", "natrix-natrix", "--out", "a.png", "--snakes", "-3"], "-3 is not in 1..=400"),
            (&["bench", "render", "--frames", "-5"], "-5 is not in 3..=10000"),
            (&["generate", "natrix-natrix", "--size", "--maps", "color"], "a value is required for '--size"),
            (&["brdf", "albedo", "--angle-deg", "-1e-3"], "'-1e-3' for '--angle-deg <ANGLE_DEG>': must be a finite"),
            (&["brdf", "albedo", "--thickness-nm", "-.5"], "'-.5' for '--thickness-nm <THICKNESS_NM>': must be"),
            (&["brdf", "albedo", "--n0", "-inf"], "'-inf' for '--n0 <N0>': must be a finite number in [1, 3]"),
            (&["brdf", "albedo", "--angle-deg", "-NaN"], "'-NaN' for '--angle-deg <ANGLE_DEG>': must be"),
            (&["bench", "render", "--size", "-1x-1"], "'-1x-1' for '--size <SIZE>': expected WIDTHxHEIGHT"),
            (&["generate", "natrix-natrix", "--size", "-1e3"], "'-1e3' for '--size <SIZE>': not a whole number"),
            (&["brdf", "albedo", "--angle-deg", "30", "--", "-1e-3"], "unexpected argument '-1e-3'"),
            // A path is no number: refused as `-o -1dir` is (it wrote `-1dir/`).
            (&["generate", "natrix-natrix", "--out", "-1dir"], "unexpected argument '-1'"),
            // A missing value is named as the words were given (it said `--wo=-1,0,1`).
            (&["brdf", "eval", "--wi", "--wo", "-1,0,1"], "the next word is the flag `--wo`"),
        ] {
            let error = parse(args).expect_err(&format!("{args:?} was accepted"));
            assert!(error.contains(says), "{args:?}: {error}");
        }
        parse(&["generate", "natrix-natrix", "--size", "16"]).unwrap();
    }

    /// A long flag with one dash is refused with the flag it names: `generate NAME -out`
    /// wrote into `./ut/` (clap's `-o ut`) and `-size 64` called 64 an unexpected argument.
    /// Negative controls: the short flag with its value attached where no long flag is
    /// spelled so (`-oout`), a negative number as a value, and words after `--`.
    #[test]
    fn a_long_flag_with_one_dash_is_refused() {
        for (args, says) in [
            (
                &["generate", "natrix-natrix", "-out"][..],
                "write `--out`; long flags take two (with one, it is read as the short flag `-o` with the value `ut`)",
            ),
            (
                &["export", "natrix-natrix", "-gltf", "a.glb"],
                "`-gltf` has one dash: write `--gltf`; long flags take two",
            ),
            (&["generate", "natrix-natrix", "-size", "64"], "write `--size`"),
            (&["generate", "natrix-natrix", "-maps=color"], "write `--maps`"),
            (&["generate", "natrix-natrix", "-out/"], "write `--out`"),
            (&["generate", "natrix-natrix", "-out.d"], "write `--out`"),
            (&["export", "natrix-natrix", "-out.glb"], "write `--out`"),
            (&["brdf", "eval", "-roughness", "0.3"], "write `--roughness`"),
        ] {
            let error = parse(args).expect_err(&format!("{args:?} was accepted"));
            assert!(error.contains(says), "{args:?}: {error}");
        }
        // No short flag `-g` in `export`: no "read as" clause.
        let error = parse(&["export", "natrix-natrix", "-gltf", "a.glb"]).unwrap_err();
        assert!(!error.contains("read as"), "{error}");
        parse(&["generate", "natrix-natrix", "-oout"]).unwrap();
        parse(&["generate", "natrix-natrix", "-outility"]).unwrap();
        parse(&["export", "natrix-natrix", "--out", "a.glb"]).unwrap();
        // `-help` is clap's (it shows the help), not refused as `--help`.
        let error = parse(&["generate", "natrix-natrix", "-help"]).unwrap_err();
        assert!(!error.contains("one dash"), "{error}");
        parse(&["brdf", "eval", "--wi", "-0.3,0,1", "--wo", "0,0,1"]).unwrap();
        let error = parse(&["generate", "natrix-natrix", "--", "-size"]).expect_err("a second preset");
        assert!(!error.contains("long flags take two dashes"), "{error}");
    }

    /// Every whole-number flag says its range, whatever the word: clap's u32 and u16 range
    /// parsers said "invalid digit found in string" (`--tile 1.5`, `--seed -1`) and "number
    /// too large to fit in target type" (`--snakes 99999999999999999999`). Negative control:
    /// each flag's largest value is taken.
    #[test]
    fn every_whole_number_flag_says_its_range() {
        let huge = "99999999999999999999";
        for (args, says, largest) in [
            (&["sheet", "-o", "s.png", "--tile"][..], "is not in 64..=1024", "1024"),
            (&["sheet", "-o", "s.png", "--columns"], "is not in 1..=8", "8"),
            (&["brdf", "chart", "-o", "c.png", "--height"], "is not in 2..=4096", "4096"),
            (&["brdf", "chart", "-o", "c.png", "--width"], "is not in 2..=4096", "4096"),
            (&["preview", "natrix-natrix", "--out", "a.png", "--snakes"], "is not in 1..=400", "400"),
            (&["preview", "natrix-natrix", "--window", "--frames"], "is not in 1..=1000000", "1000000"),
            (&["batch", "jobs.toml", "-o", "out", "--concurrent"], "is not in 1..=16", "16"),
            (&["brdf", "stress", "--seed"], "is not in 0..=4294967295", "4294967295"),
            (&["generate", "natrix-natrix", "--seed"], "is not in 0..=9007199254740991", "9007199254740991"),
        ] {
            for word in ["1.5", "-1", huge] {
                let error = parse(&[args, &[word]].concat()).expect_err(&format!("{args:?} {word} was accepted"));
                let expected = if word == "1.5" { "not a whole number" } else { says };
                assert!(error.contains(expected), "{args:?} {word}: {error}");
            }
            parse(&[args, &[largest]].concat()).unwrap();
        }
        let error = parse(&["sheet", "-o", "s.png", "--tile", "1.5"]).unwrap_err();
        assert!(error.contains("accepted: 64..=1024"), "{error}");
    }

    /// A flag with a missing value took the next flag for it: `--absorption --wo 0,0,1` was
    /// "unexpected argument '0,0,1'". Negative control: a vector that starts with `-`.
    #[test]
    fn a_flag_is_not_taken_for_a_missing_value() {
        let eval = |args: &[&str]| {
            let words = ["snakeskin", "brdf", "eval"].iter().chain(args).map(|w| w.into()).collect();
            Cli::try_parse_checked_from(words)
        };
        for (args, flag) in [
            (&["--wi", "0,0,1", "--absorption", "--wo", "0,0,1"][..], "--wo"),
            (&["--wo", "0,0,1", "--wi", "--albedo", "0.5"][..], "--albedo"),
            (&["--wi", "0,0,1", "--wo", "0,0,1", "--normal", "--model", "thesis"][..], "--model"),
        ] {
            let message = eval(args).unwrap_err().to_string();
            assert!(message.contains(&format!("needs a value, and the next word is the flag `{flag}`")), "{message}");
            assert!(message.contains("Usage: snakeskin brdf eval"), "the command's own usage: {message}");
        }
        let cli = eval(&["--wi", "-0.5,0,1", "--wo", "0,-1,1", "--normal", "-0,0,1"]).unwrap();
        let Command::Brdf { command: BrdfCommand::Eval(args) } = cli.command else { panic!("parsed as brdf eval") };
        assert_eq!((args.wi, args.wo), ([-0.5, 0.0, 1.0], [0.0, -1.0, 1.0]));
    }

    /// Whether `parser` takes `value` (on a lone flag, so that the real flag's requirements
    /// and conflicts do not matter).
    fn takes(parser: &clap::builder::ValueParser, value: &str) -> bool {
        let arg = clap::Arg::new("x").long("x").value_parser(parser.clone()).allow_negative_numbers(true);
        clap::Command::new("t").arg(arg).try_get_matches_from(["t", "--x", value]).is_ok()
    }

    /// The `LO to HI` pairs a help text names (`16 to 16384`, `1 to 10,000`, `0.5 to 3`).
    fn named_ranges(help: &str) -> Vec<(f64, f64)> {
        let number =
            |w: &str| w.trim_matches(|c: char| !c.is_ascii_digit()).replace([',', '_'], "").parse::<f64>().ok();
        let words: Vec<&str> = help.split_whitespace().collect();
        words.windows(3).filter(|w| w[1] == "to").filter_map(|w| Some((number(w[0])?, number(w[2])?))).collect()
    }

    /// Every flag whose values are bounded numbers says its bounds in `--help`, and they are
    /// the ones its parser keeps: a user should not learn a range from an error. (Before,
    /// `sheet --tile`, `gallery --columns`, `preview --snakes`, `bench render --frames` and
    /// others kept ranges that their help did not name.)
    #[test]
    fn every_bounded_number_flag_names_its_range_in_help() {
        fn check(command: &clap::Command, path: &str, problems: &mut Vec<String>) {
            for arg in command.get_arguments().filter(|a| a.get_long().is_some() && a.get_action().takes_values()) {
                let parser = arg.get_value_parser();
                let numeric = ["0", "1", "2", "3", "16", "64", "1000"].iter().any(|v| takes(parser, v));
                if !numeric || takes(parser, &u64::MAX.to_string()) {
                    continue;
                }
                let help = format!(
                    "{} {}",
                    arg.get_help().map(|h| h.to_string()).unwrap_or_default(),
                    arg.get_long_help().map(|h| h.to_string()).unwrap_or_default()
                );
                let kept = |(lo, hi): (f64, f64)| {
                    let text = |x: f64| x.to_string();
                    takes(parser, &text(lo))
                        && takes(parser, &text(hi))
                        && !takes(parser, &text(hi + 1.0))
                        && (lo <= 0.0 || !takes(parser, &text(lo - 1.0)))
                };
                if !named_ranges(&help).into_iter().any(kept) {
                    problems.push(format!("{path} --{}: {help:?}", arg.get_long().unwrap()));
                }
            }
            for sub in command.get_subcommands() {
                check(sub, &format!("{path} {}", sub.get_name()), problems);
            }
        }
        let mut problems = Vec::new();
        check(&<Cli as clap::CommandFactory>::command(), "snakeskin", &mut problems);
        assert!(problems.is_empty(), "flags whose help does not name the range they keep:\n{}", problems.join("\n"));
        // The check itself: a range its parser does not keep is not taken as named.
        let tile = clap::builder::ValueParser::new(ranged_u64(16, 2048));
        assert!(takes(&tile, "2048") && !takes(&tile, "2049") && !takes(&tile, "15"));
        assert_eq!(named_ranges("Tile size in pixels (16 to 2048)."), [(16.0, 2048.0)]);
    }

    /// The atlas's longest side that `sheet --map-size` and `preview --map-size` name is the
    /// one they keep (`MAX_TEXTURE_SIDE`): a help text cannot take the constant, so this test
    /// holds them together. Negative control: a help text with another number of rows.
    #[test]
    fn the_atlas_rows_named_in_help_are_the_kept_ones() {
        use snakeskin::render::engine::prepare::MAX_TEXTURE_SIDE;
        let rows_named = |help: &str| -> Vec<usize> {
            let words: Vec<&str> = help.split_whitespace().collect();
            words.windows(2).filter(|w| w[1].starts_with("rows")).filter_map(|w| w[0].parse().ok()).collect()
        };
        let command = <Cli as clap::CommandFactory>::command();
        for name in ["sheet", "preview"] {
            let sub = command.find_subcommand(name).unwrap();
            let arg = sub.get_arguments().find(|a| a.get_long() == Some("map-size")).unwrap();
            let help = arg.get_long_help().or(arg.get_help()).map(|h| h.to_string()).unwrap_or_default();
            assert_eq!(rows_named(&help), [MAX_TEXTURE_SIDE], "{name} --map-size: {help:?}");
        }
        assert_ne!(rows_named("more than 4096 rows long"), [MAX_TEXTURE_SIDE]);
    }

    /// The roughness floor `brdf eval --help` names is `brdf::ALPHA_MIN`'s (a help text
    /// cannot take the constant). Negative control: another α.
    #[test]
    fn the_roughness_floor_named_in_help_is_alpha_min() {
        let command = <Cli as clap::CommandFactory>::command();
        let eval = command.find_subcommand("brdf").unwrap().find_subcommand("eval").unwrap();
        let help = eval.get_arguments().find(|a| a.get_id() == "roughness").unwrap().get_help().unwrap().to_string();
        let names = |alpha: f64| help.contains(&format!("α {alpha}")) && help.contains(&format!("{:.3}", alpha.sqrt()));
        assert!(names(snakeskin::optics::brdf::ALPHA_MIN), "{help}");
        assert!(!names(2e-3), "{help}");
    }

    /// The largest N that a help text gives `spectral-N` (and `Method::ACCEPTED`, which
    /// errors quote) is the number of 1 nm samples of the reference, `spectrum::SAMPLES`: a
    /// help text cannot take the constant. Negative control: a text naming 420.
    #[test]
    fn the_spectral_band_limit_named_in_help_is_the_sample_count() {
        use snakeskin::optics::spectrum::SAMPLES;
        fn limits(text: &str) -> Vec<usize> {
            ["N = 1 to ", "N = 1.."]
                .iter()
                .flat_map(|p| text.match_indices(p).map(move |(i, _)| &text[i + p.len()..]))
                .filter_map(|rest| rest.split(|c: char| !c.is_ascii_digit()).next()?.parse().ok())
                .collect()
        }
        fn helps(command: &clap::Command, out: &mut Vec<String>) {
            for arg in command.get_arguments() {
                out.extend([arg.get_help(), arg.get_long_help()].into_iter().flatten().map(|h| h.to_string()));
            }
            for sub in command.get_subcommands() {
                helps(sub, out);
            }
        }
        let mut texts = vec![snakeskin::optics::methods::Method::ACCEPTED.to_string()];
        helps(&<Cli as clap::CommandFactory>::command(), &mut texts);
        let named: Vec<usize> = texts.iter().flat_map(|t| limits(t)).collect();
        assert!(named.len() >= 4 && named.iter().all(|n| *n == SAMPLES), "{named:?}");
        assert_eq!(limits("spectral-N (N = 1 to 420, e.g. spectral-16)"), [420]);
    }

    #[test]
    fn a_normal_is_a_direction_or_zero() {
        assert_eq!(parse_normal("0,0,0"), Ok([0.0; 3]));
        assert_eq!(parse_normal("-0,0,0"), Ok([0.0; 3]));
        assert_eq!(parse_normal("0,2,0"), Ok([0.0, 2.0, 0.0]));
        // Each with its own length (1e-300's squared length underflows: it said 0e0).
        for (tiny, length) in
            [("1e-9,0,0", "got length 1e-9;"), ("0,1e-300,1e-300", "got length 1.414213562373095e-300;")]
        {
            let said = parse_normal(tiny).unwrap_err();
            assert!(said.contains("at least 1e-6 long") && said.contains("or 0,0,0"), "{tiny}: {said}");
            assert!(said.contains(length), "{tiny}: {said}");
        }
    }

    #[test]
    fn an_image_size_out_of_range_names_its_side() {
        assert_eq!(parse_image_size("640x400"), Ok(ImageSize { width: 640, height: 400 }));
        assert_eq!(parse_image_size("16"), Ok(ImageSize { width: 16, height: 16 }));
        let said = |text: &str| parse_image_size(text).unwrap_err();
        assert!(said("100000x300").starts_with("the width 100000 is out of range: "), "{}", said("100000x300"));
        assert!(said("300x0").starts_with("the height 0 is out of range: "), "{}", said("300x0"));
        assert!(said("9000").starts_with("the size 9000 is out of range: "), "{}", said("9000"));
        assert!(said("300xten").starts_with("expected WIDTHxHEIGHT"), "{}", said("300xten"));
    }
}
