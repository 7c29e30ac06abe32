//! `snakeskin generate`: one texture set, planned (validated, memory estimated) before any
//! pixel is computed, then evaluated and written as a whole.

use anyhow::Result;

use crate::cli::{Convention, GenerateArgs};
use crate::output::path_line;
use crate::progress::Progress;
use snakeskin::generate::{GenerateRequest, Plan};
use snakeskin::graph::EvalStats;
use snakeskin::maps::BuildOptions;
use snakeskin::ops::filters::NormalConvention;

const MIB: f64 = snakeskin::memory::MIB as f64;

pub fn run(args: GenerateArgs) -> Result<()> {
    let convention = match args.normal_convention {
        Convention::Opengl => NormalConvention::OpenGl,
        Convention::Directx => NormalConvention::DirectX,
    };
    let source = &args.preset.source;
    let request = GenerateRequest {
        preset: source.preset.clone(),
        overrides: source.overrides.clone(),
        seed: source.seed,
        size: args.size,
        maps: args.preset.maps.0.clone(),
        out_dir: args.out.clone(),
        options: BuildOptions { normal_convention: convention, layout: args.layout.layout() },
        format: args.format.format(),
        pack: args.pack.map(|p| p.pack()),
        ao: args.ao,
        job: None,
    };
    let plan = Plan::new(&request)?;
    crate::output::report_warnings(&source.preset, plan.loaded());
    for warning in plan.size_warning().into_iter().chain(plan.ambient_warning()) {
        eprintln!("{warning}");
    }
    let memory = plan.memory();
    crate::output::report_tight_memory(&memory, "this set");
    let bar = Progress::counting("{spinner} generating [{bar:30}] {pos}/{len} nodes {elapsed}");
    let report = plan.run(&|done, total| bar.update(done, total))?;
    bar.finish();
    if report.created_folder {
        eprintln!("note: created folder {}", path_line(&args.out));
    }
    for file in &report.removed {
        eprintln!("note: removed {}, the earlier set's (this set does not write it)", path_line(file));
    }
    for kept in &report.kept {
        eprintln!("warning: {}", crate::output::kept_words(kept));
    }
    for file in &report.files {
        println!("{}", path_line(file));
    }
    if args.stats {
        print_stats(&report.stats);
        for (map, value) in &report.constant_maps {
            eprintln!("{} map quantised as the constant {value} (its image not read)", map.name());
        }
        eprintln!(
            "memory estimate before the run: {:.1} MiB (available: {:.0} MiB)",
            memory.estimate_bytes as f64 / MIB,
            memory.available_bytes as f64 / MIB
        );
        if let Some((count, rows, margin)) = report.strips {
            eprintln!("evaluated in {count} strips of {rows} rows, each with {margin} rows of margin each side");
        }
        eprintln!(
            "encode + write: {:.1} ms (each map's time summed; PNG compression overlaps the graph), total: {:.1} ms",
            report.encode_time.as_secs_f64() * 1e3,
            report.total_time.as_secs_f64() * 1e3
        );
    }
    Ok(())
}

fn print_stats(stats: &EvalStats) {
    // Columns as wide as their longest entry (a long operation label pushed its row's
    // numbers out of line).
    let name_width = stats.nodes.iter().map(|n| n.name.chars().count()).fold(28, usize::max);
    let label_width = stats.nodes.iter().map(|n| n.label.chars().count()).fold(36, usize::max);
    eprintln!("{:<name_width$} {:<label_width$} {:>5} {:>10} {:>10}", "node", "operation", "evals", "ms", "MiB");
    let mut nodes = stats.nodes.clone();
    nodes.sort_by_key(|n| std::cmp::Reverse(n.time));
    for n in &nodes {
        eprintln!(
            "{:<name_width$} {:<label_width$} {:>5} {:>10.2} {:>10.1}",
            n.name,
            n.label,
            n.evaluations,
            n.time.as_secs_f64() * 1e3,
            n.bytes as f64 / MIB
        );
    }
    eprintln!(
        "{} nodes evaluated, graph wall {:.1} ms, peak buffers {:.1} MiB",
        stats.nodes.len(),
        stats.wall.as_secs_f64() * 1e3,
        stats.peak_bytes as f64 / MIB
    );
}
