//! `snakeskin graph`: the nodes the requested maps need, as a list or Graphviz DOT.

use anyhow::Result;

use crate::cli::GraphArgs;
use snakeskin::graph::to_dot;
use snakeskin::maps::{BuildOptions, build_graph};

pub fn run(args: GraphArgs) -> Result<()> {
    let maps = &args.preset.maps.0;
    let source = &args.preset.source;
    let loaded = snakeskin::preset::load(&source.preset, &source.overrides, source.seed)?;
    crate::output::report_warnings(&source.preset, &loaded);
    // The body atlas's graph too (an onboarding review found no way to see it but
    // `generate --stats`); trimmed to the maps as `generate` trims it, so that a scale
    // field's channels are numbered as the run numbers them (`--maps roughness` showed
    // channels 2 and 1 where the run reads 1 and 0).
    let options = BuildOptions { layout: args.layout.layout(), ..BuildOptions::default() };
    let graph = build_graph(&loaded.preset, options).for_maps(maps);
    if args.dot {
        print!("{}", to_dot(&graph, maps));
    } else {
        let rows: Vec<[String; 3]> = graph
            .reachable(maps)
            .into_iter()
            .map(|id| {
                let node = graph.node(id);
                let inputs: Vec<&str> = node.inputs.iter().map(|i| graph.node(*i).name.as_str()).collect();
                [node.name.clone(), node.op.label(), inputs.join(", ")]
            })
            .collect();
        // Columns as wide as their longest entry: a label longer than a fixed width pushed
        // its row's inputs out of line.
        let width = |k: usize| rows.iter().map(|row| row[k].chars().count()).max().unwrap_or(0);
        let (name_width, label_width) = (width(0), width(1));
        for [name, label, inputs] in &rows {
            println!("{name:<name_width$}  {label:<label_width$}  <- {inputs}");
        }
    }
    Ok(())
}
