//! Graphviz DOT output of the part of a graph that given maps need.

use std::fmt::Write;

use super::Graph;
use crate::maps::MapKind;

/// A DOT digraph with exactly the nodes `evaluate` would run for `maps`: one DOT node per
/// graph node (named by node name, labelled with the operation), one edge per input. Nodes
/// that produce a requested map are drawn bold with the map's name in their label.
pub fn to_dot(graph: &Graph, maps: &[MapKind]) -> String {
    let mut dot = String::from("digraph snakeskin {\n  rankdir=LR;\n  node [shape=box, fontname=\"monospace\"];\n");
    for id in graph.reachable(maps) {
        let node = graph.node(id);
        let produces: Vec<&str> = maps.iter().filter(|m| graph.output(**m) == Some(id)).map(|m| m.name()).collect();
        let (style, suffix) = if produces.is_empty() {
            ("", String::new())
        } else {
            (", style=bold", format!("\\n=> {} map", produces.join(", ")))
        };
        let _ = writeln!(dot, "  \"{}\" [label=\"{}\\n{}{suffix}\"{style}];", node.name, node.name, node.op.label());
        for input in &node.inputs {
            let _ = writeln!(dot, "  \"{}\" -> \"{}\";", graph.node(*input).name, node.name);
        }
    }
    dot.push_str("}\n");
    dot
}
