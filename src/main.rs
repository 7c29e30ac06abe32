//! The `snakeskin` binary: parse the command line, call the library, map errors to exit codes
//! (2 for invalid input, 1 for anything else).

mod brdf;
mod cli;
mod progress;
mod render_cmd;

use std::process::ExitCode;

use anyhow::Result;
use clap::Parser;

use cli::{Cli, Command, Convention, PresetsCommand};
use snakeskin::graph::{EvalStats, to_dot};
use snakeskin::maps::{BuildOptions, build_graph};
use snakeskin::ops::filters::NormalConvention;
use snakeskin::preset::library;
use snakeskin::{Error, GenerateRequest, generate, parse_map_list};

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            eprintln!("error: {err:#}");
            let invalid = err.downcast_ref::<Error>().is_some_and(Error::is_invalid_input);
            ExitCode::from(if invalid { 2 } else { 1 })
        }
    }
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Generate(args) => {
            let convention = match args.normal_convention {
                Convention::Opengl => NormalConvention::OpenGl,
                Convention::Directx => NormalConvention::DirectX,
            };
            let request = GenerateRequest {
                preset: args.preset.source.preset.clone(),
                overrides: args.preset.source.overrides.clone(),
                seed: args.preset.source.seed,
                size: args.size,
                maps: parse_map_list(&args.preset.maps)?,
                out_dir: args.out.clone(),
                options: BuildOptions { normal_convention: convention },
            };
            let bar = progress::Progress::counting("{spinner} generating [{bar:30}] {pos}/{len} nodes {elapsed}");
            let report = generate(&request, &|done, total| bar.update(done, total))?;
            bar.finish();
            for file in &report.files {
                println!("{}", file.display());
            }
            if args.stats {
                print_stats(&report.stats);
                eprintln!(
                    "encode + write: {:.1} ms, total: {:.1} ms",
                    report.encode_time.as_secs_f64() * 1e3,
                    report.total_time.as_secs_f64() * 1e3
                );
            }
            Ok(())
        }
        Command::Graph(args) => {
            let maps = parse_map_list(&args.preset.maps)?;
            let loaded = snakeskin::generate::load(
                &args.preset.source.preset,
                &args.preset.source.overrides,
                args.preset.source.seed,
            )?;
            let graph = build_graph(&loaded.preset, BuildOptions::default());
            if args.dot {
                print!("{}", to_dot(&graph, &maps));
            } else {
                for id in graph.reachable(&maps) {
                    let node = graph.node(id);
                    let inputs: Vec<&str> = node.inputs.iter().map(|i| graph.node(*i).name.as_str()).collect();
                    println!("{:<28} {:<36} <- {}", node.name, node.op.label(), inputs.join(", "));
                }
            }
            Ok(())
        }
        Command::Brdf { command } => brdf::run(command),
        Command::Bench { command } => brdf::bench(command),
        Command::Preview(args) => render_cmd::preview(args),
        Command::Figures { preset, out, size, map_size } => render_cmd::figures(&preset, &out, &size, map_size),
        Command::Gallery { out, tile, columns } => {
            snakeskin::gallery::write(&out, tile as usize, columns as usize)?;
            println!("{}", out.display());
            Ok(())
        }
        Command::Presets { command: PresetsCommand::List } => {
            println!("{:<26} {:<26} {:<32} category", "name", "species", "common name");
            for (name, text) in library::all() {
                let preset: snakeskin::preset::Preset = toml::from_str(text)?;
                println!(
                    "{name:<26} {:<26} {:<32} {}",
                    preset.species.unwrap_or_default(),
                    preset.common_name.unwrap_or_default(),
                    preset.category.map(|c| c.name()).unwrap_or("-")
                );
            }
            Ok(())
        }
        Command::Sheet { out, tile, columns, map_size } => render_cmd::sheet(&out, tile, columns, map_size as usize),
        Command::Presets { command: PresetsCommand::Show { name } } => match library::get(&name) {
            Some(text) => {
                print!("{text}");
                Ok(())
            }
            None => Err(Error::Preset(snakeskin::preset::PresetError::UnknownPreset {
                available: library::names().join(", "),
                name,
            })
            .into()),
        },
    }
}

fn print_stats(stats: &EvalStats) {
    eprintln!("{:<28} {:<36} {:>5} {:>10} {:>10}", "node", "operation", "evals", "ms", "MiB");
    let mut nodes = stats.nodes.clone();
    nodes.sort_by_key(|n| std::cmp::Reverse(n.time));
    for n in &nodes {
        eprintln!(
            "{:<28} {:<36} {:>5} {:>10.2} {:>10.1}",
            n.name,
            n.label,
            n.evaluations,
            n.time.as_secs_f64() * 1e3,
            n.bytes as f64 / (1 << 20) as f64
        );
    }
    eprintln!(
        "{} nodes evaluated, graph wall {:.1} ms, peak buffers {:.1} MiB",
        stats.nodes.len(),
        stats.wall.as_secs_f64() * 1e3,
        stats.peak_bytes as f64 / (1 << 20) as f64
    );
}
