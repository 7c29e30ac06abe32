//! Demand-driven, memoised, parallel, frugal evaluation.
//!
//! - Demand-driven: only nodes reachable from the requested maps run.
//! - Memoised: each reachable node runs exactly once, however many consumers it has.
//! - Parallel: nodes are grouped into levels (1 + the deepest input); the nodes of one level
//!   are independent and run together on rayon, and every kernel is itself row-parallel.
//! - Frugal: each buffer counts its remaining consumers and is dropped after the last one, so
//!   peak memory follows the graph's width, not its size.
//!
//! Results do not depend on scheduling: every node is a pure function of its inputs.

use std::borrow::Cow;
use std::collections::BTreeMap;
use std::sync::Arc;
use std::time::{Duration, Instant};

use rayon::prelude::*;

use super::{Graph, NodeId};
use crate::maps::MapKind;
use crate::ops::Image;

#[derive(Debug, Clone)]
pub struct NodeStats {
    pub name: String,
    pub label: String,
    pub evaluations: u32,
    pub time: Duration,
    pub bytes: usize,
}

#[derive(Debug, Clone, Default)]
pub struct EvalStats {
    /// One entry per evaluated node, in topological order.
    pub nodes: Vec<NodeStats>,
    /// The most bytes of node buffers alive at once.
    pub peak_bytes: usize,
    pub wall: Duration,
}

impl EvalStats {
    pub fn get(&self, name: &str) -> Option<&NodeStats> {
        self.nodes.iter().find(|n| n.name == name)
    }
}

pub struct Evaluation {
    pub maps: BTreeMap<MapKind, Image>,
    pub stats: EvalStats,
}

/// Evaluates the nodes that `maps` need at `width` × `height`. `progress(done, total)` is
/// called after each node.
pub fn evaluate(
    graph: &Graph,
    maps: &[MapKind],
    width: usize,
    height: usize,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Evaluation {
    let start = Instant::now();
    let needed = graph.reachable(maps);
    let total = needed.len();
    let is_needed: Vec<bool> = {
        let mut v = vec![false; graph.nodes().len()];
        needed.iter().for_each(|id| v[id.0] = true);
        v
    };
    let outputs: Vec<NodeId> = maps.iter().filter_map(|m| graph.output(*m)).collect();

    // Remaining consumers of each node among the needed ones; outputs are held to the end.
    let mut consumers = vec![0usize; graph.nodes().len()];
    for id in &needed {
        for input in &graph.node(*id).inputs {
            consumers[input.0] += 1;
        }
    }
    for out in &outputs {
        consumers[out.0] += 1;
    }

    let mut level = vec![0usize; graph.nodes().len()];
    for id in &needed {
        level[id.0] = graph.node(*id).inputs.iter().map(|i| level[i.0] + 1).max().unwrap_or(0);
    }
    let max_level = needed.iter().map(|id| level[id.0]).max().unwrap_or(0);

    let mut store: Vec<Option<Arc<Image>>> = vec![None; graph.nodes().len()];
    let mut stats: BTreeMap<usize, NodeStats> = BTreeMap::new();
    let (mut live_bytes, mut peak_bytes, mut done) = (0usize, 0usize, 0usize);

    for lv in 0..=max_level {
        let batch: Vec<NodeId> = needed.iter().copied().filter(|id| level[id.0] == lv).collect();
        // A node that is the last consumer of its first input may reuse that buffer: take it
        // out of the store now (no other node can still need it), so the kernel runs in
        // place instead of allocating, and page-faulting, a new image.
        let owned: Vec<Option<Image>> = batch
            .iter()
            .map(|&id| {
                let node = graph.node(id);
                let first = *node.inputs.first()?;
                let used_once = node.inputs.iter().filter(|i| **i == first).count() == 1;
                if !(node.op.in_place() && used_once && consumers[first.0] == 1) {
                    return None;
                }
                let image = Arc::try_unwrap(store[first.0].take()?).ok()?;
                live_bytes -= image.bytes();
                Some(image)
            })
            .collect();
        let results: Vec<(NodeId, Image, Duration)> = batch
            .par_iter()
            .zip(owned)
            .map(|(&id, owned)| {
                let node = graph.node(id);
                let first = match owned {
                    Some(image) => node.inputs.first().map(|_| Cow::Owned(image)),
                    None => node.inputs.first().map(|i| Cow::Borrowed(store[i.0].as_deref().expect("input evaluated"))),
                };
                let rest: Vec<&Image> =
                    node.inputs.iter().skip(1).map(|i| store[i.0].as_deref().expect("input evaluated")).collect();
                let t = Instant::now();
                let image = node.op.eval(first, &rest, width, height);
                (id, image, t.elapsed())
            })
            .collect();
        for (id, image, time) in results {
            let node = graph.node(id);
            live_bytes += image.bytes();
            let entry = stats.entry(id.0).or_insert_with(|| NodeStats {
                name: node.name.clone(),
                label: node.op.label(),
                evaluations: 0,
                time: Duration::ZERO,
                bytes: 0,
            });
            entry.evaluations += 1;
            entry.time += time;
            entry.bytes = image.bytes();
            store[id.0] = Some(Arc::new(image));
            done += 1;
            progress(done, total);
        }
        peak_bytes = peak_bytes.max(live_bytes);
        // Release every buffer whose last consumer has now run.
        for id in &batch {
            for input in &graph.node(*id).inputs {
                consumers[input.0] -= 1;
                if consumers[input.0] == 0
                    && let Some(buf) = store[input.0].take()
                {
                    live_bytes -= buf.bytes();
                }
            }
        }
    }
    debug_assert!(needed.iter().all(|id| is_needed[id.0]));

    let mut result = BTreeMap::new();
    for map in maps {
        if let Some(id) = graph.output(*map) {
            let arc = store[id.0].clone().expect("output evaluated");
            result.insert(*map, Arc::unwrap_or_clone(arc));
        }
    }
    drop(store);
    Evaluation {
        maps: result,
        stats: EvalStats { nodes: stats.into_values().collect(), peak_bytes, wall: start.elapsed() },
    }
}
