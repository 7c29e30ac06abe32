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
    let graph = build_graph(&loaded.preset, BuildOptions::default());
    if args.dot {
        print!("{}", to_dot(&graph, maps));
    } else {
        for id in graph.reachable(maps) {
            let node = graph.node(id);
            let inputs: Vec<&str> = node.inputs.iter().map(|i| graph.node(*i).name.as_str()).collect();
            println!("{:<28} {:<36} <- {}", node.name, node.op.label(), inputs.join(", "));
        }
    }
    Ok(())
}
