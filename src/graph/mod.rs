//! The node graph: operations with parameters and inputs, built once from a preset and
//! evaluated on demand.
//!
//! Design rule (resvg's filter graph): a node is data — an `Op` and the ids of its inputs —
//! and evaluation dispatches with one `match` in `op.rs`. Builders in `maps` add nodes
//! through `GraphBuilder`, which returns ids, so a graph cannot hold a dangling reference:
//! an input id always names an earlier node, which also makes the node order topological.

mod cache;
mod dot;
mod eval;
mod fuse;
mod op;

pub use cache::{CacheStats, NodeCache};
pub use dot::to_dot;
pub use eval::{
    EvalStats, Evaluation, NodeStats, estimate_cached_peak_bytes, estimate_peak_bytes, evaluate, evaluate_into,
    evaluate_rows,
};
pub use fuse::{FusedChain, FusedInput, FusedStep};
pub use op::Op;

use std::collections::BTreeMap;

use crate::material::MapKind;

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct NodeId(pub usize);

#[derive(Debug, Clone)]
pub struct Node {
    /// Unique, human-readable name, grouped by a dotted prefix (`pattern0.mask`).
    pub name: String,
    pub op: Op,
    pub inputs: Vec<NodeId>,
}

#[derive(Debug, Clone, Default)]
pub struct Graph {
    nodes: Vec<Node>,
    outputs: BTreeMap<MapKind, NodeId>,
    /// The texture does not repeat along v (a body atlas): filters clamp at its ends.
    open_v: bool,
}

impl Graph {
    pub fn nodes(&self) -> &[Node] {
        &self.nodes
    }

    pub fn node(&self, id: NodeId) -> &Node {
        &self.nodes[id.0]
    }

    pub fn output(&self, map: MapKind) -> Option<NodeId> {
        self.outputs.get(&map).copied()
    }

    pub fn outputs(&self) -> &BTreeMap<MapKind, NodeId> {
        &self.outputs
    }

    /// The value of `map` where its node is a constant (a species without a film: its
    /// thickness map): its samples need not be read from its image (`export::quantize_constant`).
    pub fn constant_output(&self, map: MapKind) -> Option<f32> {
        match self.output(map).map(|id| &self.node(id).op) {
            Some(Op::Constant { value }) => Some(*value),
            _ => None,
        }
    }

    /// The normal map's step over `frame` where it is `HeightToNormal` of the output of
    /// `from` and no node reads it. Then a caller that only files the normal map can compute
    /// it from `from`'s image a row at a time (`generate`, through
    /// `filters::height_to_normal_rows`), without the node.
    pub fn normal_from(&self, from: MapKind, frame: crate::ops::Frame) -> Option<crate::ops::filters::NormalSpec> {
        let normal = self.output(MapKind::Normal)?;
        let Op::HeightToNormal { slope, convention, v_extent } = self.node(normal).op else { return None };
        let read = self.nodes.iter().any(|n| n.inputs.contains(&normal));
        let spec = crate::ops::filters::NormalSpec::in_frame(slope, convention, v_extent, frame);
        (self.node(normal).inputs == [self.output(from)?] && !read).then_some(spec)
    }

    /// Whether the texture repeats along v (the tile) or not (a body atlas).
    pub fn wraps_v(&self) -> bool {
        !self.open_v
    }

    /// `frame` as this graph's nodes see it: wrapping along v where the texture repeats
    /// (`wraps_v`), the one place the evaluator and `generate`'s direct normal map get it.
    pub fn frame(&self, frame: crate::ops::Frame) -> crate::ops::Frame {
        crate::ops::Frame { wraps_v: self.wraps_v(), ..frame }
    }

    /// The rows above and below a pixel that the maps' values there depend on at `width`:
    /// the longest chain of neighbourhood reads (`Op::row_reach`) through the graph. A strip
    /// of a long texture evaluated with this margin each side keeps its inner rows exact.
    pub fn row_reach(&self, maps: &[MapKind], width: usize) -> usize {
        // Nodes are in topological order: a node's reach is its own plus its inputs' largest.
        let mut reach = vec![0usize; self.nodes.len()];
        for id in self.reachable(maps) {
            let node = &self.nodes[id.0];
            let inputs = node.inputs.iter().map(|i| reach[i.0]).max().unwrap_or(0);
            reach[id.0] = inputs + node.op.row_reach(width);
        }
        maps.iter().filter_map(|m| self.output(*m)).map(|id| reach[id.0]).max().unwrap_or(0)
    }

    /// The graph for writing `maps` only: the other maps' outputs are dropped, and each
    /// scale field computes and stores only the channels the remaining nodes read (a field
    /// of ten channels at 2048² is 160 MiB; `--maps roughness` reads three), its readers
    /// renumbered. Every channel is computed per pixel alone, so the maps' values are
    /// exactly those of the whole graph. A field that some node reads whole is left as it is.
    pub fn for_maps(&self, maps: &[MapKind]) -> Graph {
        let mut graph = self.clone();
        graph.outputs.retain(|map, _| maps.contains(map));
        let live = graph.reachable(maps);
        let fields: Vec<NodeId> =
            live.iter().copied().filter(|id| matches!(graph.nodes[id.0].op, Op::Scales(_))).collect();
        for field_id in fields {
            // (reader, which of its inputs) for every live node that reads the field.
            let readers: Vec<(usize, usize)> = live
                .iter()
                .flat_map(|id| {
                    let inputs = &graph.nodes[id.0].inputs;
                    inputs.iter().enumerate().filter(|(_, i)| **i == field_id).map(move |(k, _)| (id.0, k))
                })
                .collect();
            let mut read = Vec::new();
            let mut whole = false;
            for &(reader, input) in &readers {
                match graph.nodes[reader].op.channel_reads_mut(input) {
                    Some(indices) => read.extend(indices.into_iter().map(|i| *i)),
                    None => whole = true,
                }
            }
            let Op::Scales(field) = &mut graph.nodes[field_id.0].op else { unreachable!() };
            read.sort_unstable();
            read.dedup();
            if whole || read.len() == field.outputs.len() {
                continue;
            }
            field.outputs = read.iter().map(|&i| field.outputs[i]).collect();
            for &(reader, input) in &readers {
                for index in graph.nodes[reader].op.channel_reads_mut(input).into_iter().flatten() {
                    *index = read.binary_search(index).expect("every read channel is kept");
                }
            }
        }
        graph
    }

    /// Every node that the given maps depend on, in topological (id) order.
    pub fn reachable(&self, maps: &[MapKind]) -> Vec<NodeId> {
        self.reachable_until(maps, |_| false)
    }

    /// The nodes the maps reach without passing through a node for which `stop` is true
    /// (asked once per such node; it is left out, and so is what only it needs), in
    /// topological order. The cached evaluator stops at nodes it already has.
    pub fn reachable_until(&self, maps: &[MapKind], mut stop: impl FnMut(NodeId) -> bool) -> Vec<NodeId> {
        let mut seen = vec![false; self.nodes.len()];
        let mut needed = vec![false; self.nodes.len()];
        let mut stack: Vec<NodeId> = maps.iter().filter_map(|m| self.output(*m)).collect();
        while let Some(id) = stack.pop() {
            if !std::mem::replace(&mut seen[id.0], true) && !stop(id) {
                needed[id.0] = true;
                stack.extend(&self.nodes[id.0].inputs);
            }
        }
        (0..self.nodes.len()).filter(|&i| needed[i]).map(NodeId).collect()
    }
}

/// Adds nodes in topological order; the only way to make a `Graph`.
#[derive(Debug, Default)]
pub struct GraphBuilder {
    graph: Graph,
}

impl GraphBuilder {
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a node. Names must be unique: they key stats and DOT output. A wrong number of
    /// inputs is a bug in a graph builder, caught here rather than during evaluation.
    pub fn add(&mut self, name: impl Into<String>, op: Op, inputs: &[NodeId]) -> NodeId {
        let name = name.into();
        assert!(
            op.arity().contains(&inputs.len()),
            "node {name}: {} takes {:?} inputs, got {}",
            op.label(),
            op.arity(),
            inputs.len()
        );
        debug_assert!(self.graph.nodes.iter().all(|n| n.name != name), "duplicate node name {name}");
        debug_assert!(inputs.iter().all(|i| i.0 < self.graph.nodes.len()));
        self.graph.nodes.push(Node { name, op, inputs: inputs.to_vec() });
        NodeId(self.graph.nodes.len() - 1)
    }

    pub fn set_output(&mut self, map: MapKind, id: NodeId) {
        self.graph.outputs.insert(map, id);
    }

    /// Marks the texture as not repeating along v (a body atlas).
    pub fn set_open_v(&mut self) {
        self.graph.open_v = true;
    }

    pub fn finish(self) -> Graph {
        self.graph
    }
}
