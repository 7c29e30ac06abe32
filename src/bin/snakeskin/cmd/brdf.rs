//! `snakeskin brdf ...`: machine-readable optics queries, so anyone can check the physics
//! against their own implementation. One JSON object per query; `--batch` reads JSON lines.

use std::io::{BufRead, BufReader, Read, Write};

use anyhow::Result;
use serde::Deserialize;

use crate::cli::{AlbedoArgs, AlbedoModel, BrdfCommand, EvalArgs, LayerArgs, StackArgs};
use crate::output::{ensure_parent_folder, path_line, printable};
use snakeskin::Error;
use snakeskin::optics::brdf::exact::SmoothTop;
use snakeskin::optics::brdf::layered::{FilmBelowAmbient, PigmentBelowAmbient, PigmentNearAmbient};
use snakeskin::optics::brdf::walk::{FilmTables, walk};
use snakeskin::optics::brdf::{BrdfValue, Layers, Model};
use snakeskin::optics::film::{Stack, airy};
use snakeskin::optics::methods::Method;
use snakeskin::optics::query::{chart, check, film_colour};

/// The thesis' layer indices (Table 5.2), the defaults of a query that leaves them out.
const THESIS: Stack = Stack::THESIS;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct FilmQuery {
    #[serde(default = "n0_default")]
    n0: f64,
    #[serde(default = "n1_default")]
    n1: f64,
    #[serde(default = "n2_default")]
    n2: f64,
    thickness_nm: f64,
    wavelength_nm: f64,
    angle_deg: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ColorQuery {
    #[serde(default = "n0_default")]
    n0: f64,
    #[serde(default = "n1_default")]
    n1: f64,
    #[serde(default = "n2_default")]
    n2: f64,
    thickness_nm: f64,
    angle_deg: f64,
    #[serde(default = "spectral")]
    method: String,
}

fn n0_default() -> f64 {
    THESIS.n0
}
fn n1_default() -> f64 {
    THESIS.n1
}
fn n2_default() -> f64 {
    THESIS.n2
}
fn spectral() -> String {
    "spectral".into()
}

fn stack_of(s: &StackArgs) -> Stack {
    Stack { n0: s.n0, n1: s.n1, n2: s.n2 }
}

fn film_json(q: &FilmQuery) -> Result<String> {
    let stack = Stack { n0: q.n0, n1: q.n1, n2: q.n2 };
    check(stack, q.thickness_nm, q.angle_deg, Some(q.wavelength_nm))?;
    let rt = airy(stack, q.thickness_nm, q.wavelength_nm, q.angle_deg.to_radians().cos());
    Ok(serde_json::to_string(&rt)?)
}

fn color_json(q: &ColorQuery) -> Result<String> {
    let method = Method::parse(&q.method)
        .ok_or_else(|| Error::Query(format!("unknown method {:?}; accepted: {}", q.method, Method::ACCEPTED)))?;
    color_json_with(Stack { n0: q.n0, n1: q.n1, n2: q.n2 }, q.thickness_nm, q.angle_deg, method)
}

fn color_json_with(stack: Stack, thickness_nm: f64, angle_deg: f64, method: Method) -> Result<String> {
    check(stack, thickness_nm, angle_deg, None)?;
    let rgb = film_colour(method, stack, thickness_nm, angle_deg.to_radians().cos());
    Ok(serde_json::json!({ "rgb": rgb }).to_string())
}

/// The layered model's known limits (`PigmentBelowAmbient`, `PigmentNearAmbient`, `FilmBelowAmbient`, which a
/// preset's check warns of too) for a film `thickness_nm` thick under a top `roughness`
/// rough, each said once, on stderr.
fn warn_of_model_limit(model: Model, stack: Stack, thickness_nm: f64, roughness: f64) {
    if model != Model::Layered {
        return;
    }
    let walk = "`brdf albedo --model stochastic` walks the stack itself";
    if let Some(limit) = PigmentBelowAmbient::of(stack, (thickness_nm, thickness_nm), (roughness, roughness)) {
        eprintln!("warning: --n0 {} is above --n2 {}: {limit} ({walk})", stack.n0, stack.n2);
    }
    if let Some(limit) = PigmentNearAmbient::of(stack, thickness_nm, roughness) {
        eprintln!("warning: --n2 {} is near --n0 {}: {limit} ({walk})", stack.n2, stack.n0);
    }
    if let Some(limit) = FilmBelowAmbient::of(stack.n0, stack.n1, thickness_nm, (roughness, roughness)) {
        eprintln!("warning: --n1 {} is below --n0 {}: {limit} ({walk})", stack.n1, stack.n0);
    }
}

fn eval_json(args: &EvalArgs) -> Result<String> {
    let stack = stack_of(&args.stack);
    let (layers, l) = (layers_of(&args.stack, &args.layer)?, &args.layer);
    warn_of_model_limit(args.model, stack, l.thickness_nm, l.roughness);
    let film = |c: f64| film_colour(args.method, stack, l.thickness_nm, c);
    let value = args.model.eval(&layers, args.normal, args.wi, args.wo, &film);
    let json = serde_json::json!({
        "model": args.model.name(),
        "f": value.total(),
        "specular": value.specular,
        "diffuse": value.diffuse,
    });
    Ok(json.to_string())
}

/// The layers of `brdf eval` and `brdf albedo`, checked.
fn layers_of(stack: &StackArgs, l: &LayerArgs) -> Result<Layers> {
    let stack = stack_of(stack);
    check(stack, l.thickness_nm, 0.0, None)?;
    let optical_depth = l.absorption.map(|a| a * l.pigment_thickness);
    Ok(Layers::of_stack(stack, l.thickness_nm, l.roughness, optical_depth, l.albedo))
}

/// Photons per channel of `brdf albedo --model stochastic` unless told (`--photons`).
const DEFAULT_PHOTONS: u64 = 200_000;

fn albedo_json(args: &AlbedoArgs) -> Result<String> {
    if args.photons.is_some() && args.model != AlbedoModel::Stochastic {
        // It was silently ignored.
        let reason = "photons are counted by --model stochastic only; leave --photons out, or use that model".into();
        return Err(Error::InvalidOption { option: "--photons", reason }.into());
    }
    if args.method.is_some() && !matches!(args.model, AlbedoModel::Model(_)) {
        // It was silently ignored: the references read the exact 1 nm film.
        let reason = "the references read the exact film; --method chooses the film of --model thesis or layered \
                      only"
            .into();
        return Err(Error::InvalidOption { option: "--method", reason }.into());
    }
    let stack = stack_of(&args.stack);
    let (layers, l) = (layers_of(&args.stack, &args.layer)?, &args.layer);
    let cos = args.angle_deg.to_radians().cos();
    let (name, value, sigma) = match args.model {
        AlbedoModel::Model(model) => {
            warn_of_model_limit(model, stack, l.thickness_nm, l.roughness);
            let method = args.method.unwrap_or(Method::Lut);
            let film = |c: f64| film_colour(method, stack, l.thickness_nm, c);
            let total = model.furnace_albedo(&layers, cos, &film, 64);
            let specular = model.furnace_albedo(&Layers { albedo: [0.0; 3], ..layers }, cos, &film, 64);
            let diffuse = [0, 1, 2].map(|c| total[c] - specular[c]);
            (model.name(), BrdfValue { specular, diffuse }, None)
        }
        AlbedoModel::Reference => ("reference", SmoothTop::new(stack, l.thickness_nm).albedo(&layers, cos), None),
        AlbedoModel::Stochastic => {
            let tables = FilmTables::new(stack, l.thickness_nm);
            let wi = [(1.0 - cos * cos).max(0.0).sqrt(), 0.0, cos];
            let walked = walk(&layers, &tables, wi, args.photons.unwrap_or(DEFAULT_PHOTONS), 1, 1);
            let value = BrdfValue { specular: walked.specular, diffuse: walked.diffuse };
            ("stochastic", value, Some(walked.total_sigma()))
        }
    };
    let mut json = serde_json::json!({
        "model": name,
        "albedo": value.total(),
        "specular": value.specular,
        "diffuse": value.diffuse,
    });
    if let Some(sigma) = sigma {
        json["sigma"] = serde_json::json!(sigma);
    }
    Ok(json.to_string())
}

/// The longest `--batch` line accepted (a query is under 200 bytes).
const MAX_LINE_BYTES: u64 = 64 * 1024;

/// Runs `per_line` on every non-empty JSON line; errors name the file and the line.
fn run_batch<Q: for<'de> Deserialize<'de>>(path: &str, per_line: impl Fn(&Q) -> Result<String>) -> Result<()> {
    let shown = printable(path);
    let reader: Box<dyn BufRead> = if path == "-" {
        Box::new(BufReader::new(std::io::stdin()))
    } else {
        let file = std::fs::File::open(path).map_err(|e| Error::Query(format!("cannot read --batch {shown}: {e}")))?;
        Box::new(BufReader::new(file))
    };
    let mut reader = reader;
    let mut out = std::io::stdout().lock();
    for i in 0.. {
        // One query is a short JSON object: a line is read with a bound (--batch /dev/zero
        // must not grow a line until memory runs out).
        let mut bytes = Vec::new();
        (&mut reader)
            .take(MAX_LINE_BYTES + 1)
            .read_until(b'\n', &mut bytes)
            .map_err(|e| Error::Query(format!("cannot read --batch {shown}: {e}")))?;
        if bytes.is_empty() {
            break;
        }
        if bytes.len() as u64 > MAX_LINE_BYTES {
            return Err(Error::Query(format!("{shown}:{}: line longer than {MAX_LINE_BYTES} bytes", i + 1)).into());
        }
        let line = String::from_utf8(bytes).map_err(|_| Error::Query(format!("{shown}:{}: not UTF-8", i + 1)))?;
        // A byte-order mark (an editor's UTF-8 file) is not part of the first query.
        let line = if i == 0 { line.trim_start_matches('\u{feff}') } else { &line };
        if line.trim().is_empty() {
            continue;
        }
        let at = |message: String| Error::Query(format!("{shown}:{}: {message}", i + 1));
        // One object per line: serde would also take an array of the fields in order (with
        // a Rust type in its message when the count is wrong), and a comment got "expected
        // value at line 1 column 1".
        if !line.trim_start().starts_with('{') {
            return Err(
                at("expected a JSON object, one query per line, e.g. {\"thickness_nm\": 400, ...}".into()).into()
            );
        }
        let query: Q = serde_json::from_str(line).map_err(|e| {
            // The line is its own document: serde's "at line 1 column N" is the column.
            let message = e.to_string();
            let message =
                message.strip_suffix(&format!(" at line {} column {}", e.line(), e.column())).unwrap_or(&message);
            at(format!("{message} (column {})", e.column()))
        })?;
        // serde_json reads a number nearer 0 than a float holds as 0, without a word.
        if let Some(tiny) = underflowing_json_number(line) {
            return Err(at(snakeskin::toml_text::underflow_message(tiny, "a number the field accepts")).into());
        }
        // The query's own refusal is already `Error::Query`: the line is added, not a second
        // "invalid query:".
        let json = per_line(&query).map_err(|e| match e.downcast::<Error>() {
            Ok(Error::Query(message)) => at(message).into(),
            Ok(other) => anyhow::Error::from(other).context(format!("{shown}:{}", i + 1)),
            Err(other) => other.context(format!("{shown}:{}", i + 1)),
        })?;
        // Said as a failed `println!` is (`output::stdout_failure_is_an_error`): the OS's
        // words alone ("No space left on device") did not say which output failed.
        writeln!(out, "{json}").map_err(|e| anyhow::anyhow!("cannot write to standard output: {e}"))?;
    }
    Ok(())
}

/// The first number outside the strings of a JSON line that underflows to 0
/// (`toml_text::underflows`).
fn underflowing_json_number(line: &str) -> Option<&str> {
    let (mut in_string, mut escaped, mut start) = (false, false, None);
    for (i, c) in line.char_indices().chain(std::iter::once((line.len(), ' '))) {
        if in_string {
            (escaped, in_string) = (!escaped && c == '\\', escaped || c != '"');
            continue;
        }
        let numeric = c.is_ascii_digit() || matches!(c, '-' | '+' | '.' | 'e' | 'E');
        match (start, numeric) {
            (None, true) => start = Some(i),
            (Some(s), false) => {
                if snakeskin::toml_text::underflows(&line[s..i]) {
                    return Some(&line[s..i]);
                }
                start = None;
            }
            _ => {}
        }
        in_string = c == '"';
    }
    None
}

pub fn run(command: BrdfCommand) -> Result<()> {
    match command {
        BrdfCommand::Film { batch: Some(path), .. } => run_batch(&path, film_json),
        BrdfCommand::Film { stack, thickness_nm, wavelength_nm, angle_deg, batch: None } => {
            let Stack { n0, n1, n2 } = stack_of(&stack);
            let query = FilmQuery {
                n0,
                n1,
                n2,
                thickness_nm: thickness_nm.unwrap_or_default(),
                wavelength_nm: wavelength_nm.unwrap_or_default(),
                angle_deg: angle_deg.unwrap_or_default(),
            };
            println!("{}", film_json(&query)?);
            Ok(())
        }
        BrdfCommand::Color { batch: Some(path), .. } => run_batch(&path, color_json),
        BrdfCommand::Color { stack, thickness_nm, angle_deg, method, batch: None } => {
            let json = color_json_with(
                stack_of(&stack),
                thickness_nm.unwrap_or_default(),
                angle_deg.unwrap_or_default(),
                method,
            )?;
            println!("{json}");
            Ok(())
        }
        BrdfCommand::Chart { stack, out, method, width, height } => {
            let stack = stack_of(&stack);
            check(stack, 0.0, 0.0, None)?;
            snakeskin::export::check_png_target(&out)?;
            let bytes = snakeskin::optics::query::chart_bytes(width as usize, height as usize);
            snakeskin::memory::MemoryCheck::against_available(bytes)
                .refuse_if_over(&format!("a film colour chart of {width}×{height} pixels"))?;
            ensure_parent_folder(&out)?;
            let bar = crate::progress::Progress::counting("{spinner} chart [{bar:30}] {pos}/{len} rows {elapsed}");
            let (image, exposure) =
                chart(stack, method, width as usize, height as usize, &|done, total| bar.update(done, total));
            bar.finish();
            let png = snakeskin::export::encode_png(snakeskin::material::MapKind::Color, &image)?;
            snakeskin::export::write_file_atomically(&out, png)?;
            // The path on stdout, as `gallery`, `sheet` and `figures` print what they wrote
            // (it was on stderr: `$(snakeskin brdf chart …)` caught nothing, a sweep); how the
            // chart was scaled is a note.
            if image.data.iter().all(|v| *v == 0.0) {
                // Matched indices: nothing to scale, so no scale to report.
                eprintln!("note: the chart is black: this stack reflects nothing at any thickness and angle");
            } else {
                eprintln!("note: the chart's linear reflectance is scaled by {exposure:.3} before sRGB encoding");
            }
            println!("{}", path_line(&out));
            Ok(())
        }
        BrdfCommand::Eval(args) => {
            println!("{}", eval_json(&args)?);
            Ok(())
        }
        BrdfCommand::Albedo(args) => {
            println!("{}", albedo_json(&args)?);
            Ok(())
        }
        BrdfCommand::Stress { samples, seed, json } => {
            let report = snakeskin::optics::stress::run(samples, seed);
            if json {
                println!("{}", serde_json::to_string(&report)?);
            } else {
                print!("{}", stress_table(&report));
            }
            Ok(())
        }
    }
}

/// `brdf stress`'s report as text: one line per bound it checks.
fn stress_table(r: &snakeskin::optics::stress::StressReport) -> String {
    let mut text = format!("samples: {} (layer models: {})\n", r.samples, r.models.join(", "));
    text += &format!("NaN: {}, Inf: {}\n", r.nan, r.inf);
    text += &format!("R and T of the film: {:.6} to {:.6} (must lie in [0, 1])\n", r.min_r, r.max_r);
    text += &format!("|R + T - 1| of the film (nothing absorbed): at most {:.3e}\n", r.film_energy_err);
    text += &format!(
        "f32 film reflectance: {:.6} to {:.6} (must lie in [0, 1]); against f64 up to {} nm: at most {:.3e}\n",
        r.film_f32_min_r,
        r.film_f32_max_r,
        snakeskin::optics::stress::F32_FILM_DEV_MAX_NM,
        r.max_film_f32_dev
    );
    text += &format!("white furnace (k_d = 1, tau = 0), {} evaluations:\n", r.furnace_evaluations);
    for m in &r.furnace_by_model {
        if r.furnace_evaluations == 0 {
            text += &format!("  {:<8} none (too few samples)\n", m.model);
        } else {
            text += &format!("  {:<8} albedo {:.6} to {:.6}\n", m.model, m.min_albedo, m.max_albedo);
        }
    }
    text += &format!("f32 against f64, largest |difference| / (1 + |f64|): {:.3e}\n", r.max_f32_dev);
    text
}
