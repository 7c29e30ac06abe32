//! `snakeskin brdf ...`: machine-readable optics queries, so anyone can check the physics
//! against their own implementation. One JSON object per query; `--batch` reads JSON lines.

use std::io::{BufRead, BufReader, Write};

use anyhow::{Context, Result, bail};
use serde::Deserialize;

use crate::cli::{BrdfCommand, StackArgs};
use snakeskin::optics::film::{Stack, airy};
use snakeskin::optics::film_rgb_reference;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct FilmQuery {
    #[serde(default = "one")]
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
    #[serde(default = "one")]
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

fn one() -> f64 {
    1.0
}
fn n1_default() -> f64 {
    1.55
}
fn n2_default() -> f64 {
    2.0
}
fn spectral() -> String {
    "spectral".into()
}

/// Refuses what the physics does not cover, naming the parameter and the accepted range.
fn check(
    stack: Stack,
    thickness_nm: f64,
    angle_deg: f64,
    wavelength_nm: Option<f64>,
) -> Result<()> {
    for (name, n) in [("n0", stack.n0), ("n1", stack.n1), ("n2", stack.n2)] {
        if !(n.is_finite() && n >= 1.0) {
            bail!(snakeskin::Error::Query(format!(
                "{name} must be a finite refractive index >= 1, got {n}"
            )));
        }
    }
    if !(thickness_nm.is_finite() && thickness_nm >= 0.0) {
        bail!(snakeskin::Error::Query(format!(
            "thickness_nm must be finite and >= 0, got {thickness_nm}"
        )));
    }
    if !(angle_deg.is_finite() && (0.0..=90.0).contains(&angle_deg)) {
        bail!(snakeskin::Error::Query(format!(
            "angle_deg must be in [0, 90], got {angle_deg}"
        )));
    }
    if let Some(l) = wavelength_nm
        && !(l.is_finite() && l > 0.0)
    {
        bail!(snakeskin::Error::Query(format!(
            "wavelength_nm must be finite and > 0, got {l}"
        )));
    }
    Ok(())
}

fn film_json(q: &FilmQuery) -> Result<String> {
    let stack = Stack {
        n0: q.n0,
        n1: q.n1,
        n2: q.n2,
    };
    check(stack, q.thickness_nm, q.angle_deg, Some(q.wavelength_nm))?;
    let rt = airy(
        stack,
        q.thickness_nm,
        q.wavelength_nm,
        q.angle_deg.to_radians().cos(),
    );
    Ok(serde_json::to_string(&rt)?)
}

fn color_json(q: &ColorQuery) -> Result<String> {
    let stack = Stack {
        n0: q.n0,
        n1: q.n1,
        n2: q.n2,
    };
    check(stack, q.thickness_nm, q.angle_deg, None)?;
    let rgb = match q.method.as_str() {
        "spectral" => film_rgb_reference(stack, q.thickness_nm, q.angle_deg.to_radians().cos()),
        other => bail!(snakeskin::Error::Query(format!(
            "unknown method {other:?}; accepted: spectral"
        ))),
    };
    Ok(serde_json::json!({ "rgb": rgb }).to_string())
}

fn batch_lines(path: &str) -> Result<Box<dyn BufRead>> {
    Ok(if path == "-" {
        Box::new(BufReader::new(std::io::stdin()))
    } else {
        Box::new(BufReader::new(
            std::fs::File::open(path).with_context(|| format!("cannot read {path}"))?,
        ))
    })
}

/// Runs `per_line` on every non-empty JSON line; errors name the line number.
fn run_batch<Q: for<'de> Deserialize<'de>>(
    path: &str,
    per_line: impl Fn(&Q) -> Result<String>,
) -> Result<()> {
    let mut out = std::io::stdout().lock();
    for (i, line) in batch_lines(path)?.lines().enumerate() {
        let line = line?;
        if line.trim().is_empty() {
            continue;
        }
        let query: Q = serde_json::from_str(&line)
            .map_err(|e| snakeskin::Error::Query(format!("{path}:{}: {e}", i + 1)))?;
        let json = per_line(&query).with_context(|| format!("{path}:{}", i + 1))?;
        writeln!(out, "{json}")?;
    }
    Ok(())
}

fn stack_of(s: &StackArgs) -> (f64, f64, f64) {
    (s.n0, s.n1, s.n2)
}

pub fn run(command: BrdfCommand) -> Result<()> {
    match command {
        BrdfCommand::Film {
            batch: Some(path), ..
        } => run_batch(&path, film_json),
        BrdfCommand::Film {
            stack,
            thickness_nm,
            wavelength_nm,
            angle_deg,
            batch: None,
        } => {
            let (n0, n1, n2) = stack_of(&stack);
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
        BrdfCommand::Color {
            batch: Some(path), ..
        } => run_batch(&path, color_json),
        BrdfCommand::Color {
            stack,
            thickness_nm,
            angle_deg,
            method,
            batch: None,
        } => {
            let (n0, n1, n2) = stack_of(&stack);
            let query = ColorQuery {
                n0,
                n1,
                n2,
                thickness_nm: thickness_nm.unwrap_or_default(),
                angle_deg: angle_deg.unwrap_or_default(),
                method,
            };
            println!("{}", color_json(&query)?);
            Ok(())
        }
    }
}
