//! Demand-driven, memoised, parallel, frugal evaluation.
//!
//! - Demand-driven: only nodes reachable from the requested maps run.
//! - Memoised: each reachable node runs exactly once, however many consumers it has.
//! - Parallel: nodes run in topological (builder) order, up to one per thread at a time: the
//!   next node and any ready node a few places further on; every kernel is row-parallel.
//! - Frugal: each buffer counts its remaining consumers and is dropped after the last one;
//!   a node that is its input's last consumer may overwrite that buffer in place; a finished
//!   map is handed to the caller's sink as soon as nothing else needs it. Following the
//!   builder's order (one map's chain after another) rather than running whole graph levels
//!   at once keeps few buffers alive: measured at 4096² for a four-layer preset, level
//!   scheduling peaked at 2.2 GB resident.
//! - Fused, where the caller asks (`Graph::fused`, as `generate` does): a chain of per-pixel
//!   nodes is one node that runs a band of rows at a time, with no images in between.
//!
//! Results do not depend on scheduling: every node is a pure function of its inputs.

use std::borrow::Cow;
use std::collections::BTreeMap;
use std::sync::Arc;
use std::time::{Duration, Instant};

use rayon::prelude::*;

use super::cache::{CacheStats, NodeCache};
use super::op::hash_op;
use super::{Graph, NodeId};
use crate::material::MapKind;
use crate::ops::{Frame, Image};

/// How many nodes past the next one in builder order the scheduler may start early.
const LOOKAHEAD: usize = 6;

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
    /// The most bytes of node buffers alive at once (maps handed to the sink excluded).
    pub peak_bytes: usize,
    pub wall: Duration,
}

impl EvalStats {
    /// Adds another evaluation's figures (strips of one texture): node times and
    /// evaluations summed by node, the larger peak, the walls summed.
    pub fn merge(&mut self, other: EvalStats) {
        for node in other.nodes {
            match self.nodes.iter_mut().find(|n| n.name == node.name) {
                Some(n) => {
                    n.evaluations += node.evaluations;
                    n.time += node.time;
                    n.bytes = n.bytes.max(node.bytes);
                }
                None => self.nodes.push(node),
            }
        }
        self.peak_bytes = self.peak_bytes.max(other.peak_bytes);
        self.wall += other.wall;
    }

    pub fn get(&self, name: &str) -> Option<&NodeStats> {
        self.nodes.iter().find(|n| n.name == name)
    }
}

pub struct Evaluation {
    pub maps: BTreeMap<MapKind, Image>,
    pub stats: EvalStats,
}

/// Evaluates the nodes that `maps` need at `width` × `height` and returns the maps.
/// `progress(done, total)` is called after each node.
pub fn evaluate(
    graph: &Graph,
    maps: &[MapKind],
    width: usize,
    height: usize,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Evaluation {
    let mut collected = BTreeMap::new();
    let stats = evaluate_into(graph, maps, width, height, progress, &mut |map, image| {
        collected.insert(map, image);
    });
    Evaluation { maps: collected, stats }
}

/// Like `evaluate`, but hands each finished map to `sink` as soon as no other node needs it,
/// so the caller can encode it and free the f32 buffer early.
pub fn evaluate_into(
    graph: &Graph,
    maps: &[MapKind],
    width: usize,
    height: usize,
    progress: &(dyn Fn(usize, usize) + Sync),
    sink: &mut dyn FnMut(MapKind, Image),
) -> EvalStats {
    evaluate_with(graph, maps, Frame::whole(width, height), progress, sink, CachePolicy::None).0
}

/// `evaluate_into` over the rows of `frame` only: a strip of a texture too long to hold at
/// once (`generate`'s body atlas). The maps' rows match the whole texture's except within
/// `Graph::row_reach` of a strip edge inside the texture, which the caller crops.
pub fn evaluate_rows(
    graph: &Graph,
    maps: &[MapKind],
    frame: Frame,
    progress: &(dyn Fn(usize, usize) + Sync),
    sink: &mut dyn FnMut(MapKind, Image),
) -> EvalStats {
    evaluate_with(graph, maps, frame, progress, sink, CachePolicy::None).0
}

/// What the evaluator keeps between evaluations: the one difference between a one-shot
/// `generate` and live reload.
pub enum CachePolicy<'a> {
    /// Nothing: every buffer is freed after its last consumer, or overwritten in place by it.
    None,
    /// Nodes whose key (operation, parameters, input keys, size) is in the cache are not run,
    /// nor anything only they need; afterwards the cache holds every node this evaluation
    /// ran or used. Buffers are kept, so nothing is overwritten in place.
    Keep(&'a mut NodeCache),
}

/// The one evaluator: `evaluate_into` with a cache policy. Returns the stats and, for
/// `CachePolicy::Keep`, how many nodes ran and how many reachable nodes did not have to.
pub fn evaluate_with(
    graph: &Graph,
    maps: &[MapKind],
    frame: Frame,
    progress: &(dyn Fn(usize, usize) + Sync),
    sink: &mut dyn FnMut(MapKind, Image),
    mut policy: CachePolicy,
) -> (EvalStats, CacheStats) {
    let start = Instant::now();
    let frame = graph.frame(frame);
    let reachable = graph.reachable(maps);
    let keys: Vec<u64> = match policy {
        CachePolicy::None => Vec::new(),
        CachePolicy::Keep(_) => node_keys(graph, &reachable, frame),
    };
    let cached = |id: NodeId| match &policy {
        CachePolicy::None => None,
        CachePolicy::Keep(cache) => cache.get(keys[id.0]),
    };

    // Nodes to run: those the maps reach without passing through a cached node; the cached
    // nodes where the walk stops go straight into the store.
    let mut store: Vec<Option<Arc<Image>>> = vec![None; graph.nodes().len()];
    let mut computed = vec![false; graph.nodes().len()];
    let needed = graph.reachable_until(maps, |id| {
        let image = cached(id);
        computed[id.0] = image.is_some();
        store[id.0] = image;
        computed[id.0]
    });
    let mut run = vec![false; graph.nodes().len()];
    for id in &needed {
        run[id.0] = true;
    }
    let total = needed.len();
    let in_place = matches!(policy, CachePolicy::None);

    let (mut consumers, produces) = consumers_and_products(graph, &needed, maps);

    // The pool keeps buffers larger than a 2048² RGB image (a channel at 4096²) only under
    // the schedule's planned peak (`ops::pool::set_large_budget`): reused instead of
    // page-faulted afresh, without raising the peak.
    let planned_peak = (frame.width * frame.height * 4 > crate::ops::pool::MAX_BUFFER_BYTES)
        .then(|| estimate_peak_bytes(graph, maps, frame.width, frame.height));
    let mut kept: Vec<(u64, Arc<Image>)> = Vec::new();
    let mut stats: BTreeMap<usize, NodeStats> = BTreeMap::new();
    let (mut live_bytes, mut peak_bytes, mut done) = (0usize, 0usize, 0usize);
    let threads = rayon::current_num_threads().max(1);

    // Cached nodes nothing here consumes are finished already (a cached map).
    let mut finished: Vec<usize> = (0..graph.nodes().len()).filter(|&i| computed[i] && consumers[i] == 0).collect();
    let mut remaining: Vec<NodeId> = needed;
    loop {
        // Release every buffer whose last consumer has run; hand finished maps over.
        for index in finished.drain(..) {
            let Some(buffer) = store[index].take() else { continue };
            if run[index] {
                live_bytes -= buffer.bytes();
            }
            if !keys.is_empty() {
                kept.push((keys[index], buffer.clone()));
            }
            if let Some((last, others)) = produces.get(&index).and_then(|kinds| kinds.split_last()) {
                for map in others {
                    sink(*map, (*buffer).clone());
                }
                sink(*last, Arc::try_unwrap(buffer).unwrap_or_else(|shared| (*shared).clone()));
            }
        }
        if remaining.is_empty() {
            break;
        }
        let batch = next_batch(graph, &remaining, &computed, threads);
        remaining.retain(|id| !batch.contains(id));
        // A node that is the last consumer of its first input may reuse that buffer
        // (`reusable_input`): decided once, for the pool's room and for the hand-over below.
        let reused: Vec<Option<NodeId>> =
            batch.iter().map(|&id| reusable_input(graph, id, &consumers, &produces).filter(|_| in_place)).collect();
        if let Some(planned) = planned_peak {
            // Large buffers wait in the pool only in the room the planned peak leaves now.
            let allocated: u64 = batch
                .iter()
                .zip(&reused)
                .map(|(&id, reused)| {
                    let inputs: Vec<usize> = graph.node(id).inputs.iter().map(|i| channels_of(&store, *i)).collect();
                    let (bytes, scratch) = node_bytes(graph, id, &inputs, frame.width, frame.height);
                    // A node that overwrites its input allocates no result buffer.
                    if reused.is_some() { scratch } else { bytes + scratch }
                })
                .sum();
            let room = planned.saturating_sub(live_bytes as u64 + allocated);
            crate::ops::pool::set_large_budget(usize::try_from(room).unwrap_or(usize::MAX));
        }

        // A reused buffer leaves the store now (no other node can still need it), so the
        // kernel runs in place instead of allocating, and page-faulting, a new image.
        let owned: Vec<Option<Image>> = reused
            .iter()
            .map(|first| {
                let first = (*first)?;
                let image = Arc::try_unwrap(store[first.0].take()?).ok()?;
                live_bytes -= image.bytes();
                Some(image)
            })
            .collect();
        // Inside the thread pool: rayon runs a batch of one node on the calling thread,
        // which is no worker of the pool, and each parallel loop of the node's kernel was
        // then sent to the pool and waited for, a sleep and a wake-up per loop. A blur's box
        // passes make about 300: `natrix-natrix`'s at 2048² took 55–57 ms on one thread,
        // 25 ms in the pool (`--stats` with RAYON_NUM_THREADS=1).
        let results: Vec<(NodeId, Image, Duration)> = rayon::scope(|_| {
            batch
                .par_iter()
                .zip(owned)
                .map(|(&id, owned)| {
                    let node = graph.node(id);
                    let input = |i: &NodeId| store[i.0].as_deref().expect("inputs are computed before their consumers");
                    let first = match owned {
                        Some(image) => Some(Cow::Owned(image)),
                        None => node.inputs.first().map(|i| Cow::Borrowed(input(i))),
                    };
                    let rest: Vec<&Image> = node.inputs.iter().skip(1).map(input).collect();
                    let t = Instant::now();
                    let image = node.op.eval(first, &rest, frame);
                    (id, image, t.elapsed())
                })
                .collect()
        });

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
            computed[id.0] = true;
            done += 1;
            progress(done, total);
        }
        peak_bytes = peak_bytes.max(live_bytes);

        finished.extend(batch.iter().map(|id| id.0).filter(|i| consumers[*i] == 0));
        for id in &batch {
            for input in &graph.node(*id).inputs {
                consumers[input.0] -= 1;
                if consumers[input.0] == 0 {
                    finished.push(input.0);
                }
            }
        }
    }

    if let CachePolicy::Keep(cache) = &mut policy {
        cache.replace(kept);
    }
    crate::ops::pool::clear();
    let cache_stats = CacheStats { evaluated: total, reused: reachable.len() - total };
    (EvalStats { nodes: stats.into_values().collect(), peak_bytes, wall: start.elapsed() }, cache_stats)
}

/// Cache keys of the reachable nodes (in topological order, so inputs come first): the
/// operation with every parameter (`hash_op`), the size and the inputs' keys.
fn node_keys(graph: &Graph, reachable: &[NodeId], frame: Frame) -> Vec<u64> {
    use std::hash::{Hash, Hasher};
    let mut keys = vec![0u64; graph.nodes().len()];
    for &id in reachable {
        let node = graph.node(id);
        let mut hasher = std::collections::hash_map::DefaultHasher::new();
        hash_op(&node.op, &mut hasher);
        frame.hash(&mut hasher);
        for input in &node.inputs {
            keys[input.0].hash(&mut hasher);
        }
        keys[id.0] = hasher.finish();
    }
    keys
}

/// Remaining consumers of each buffer among the `needed` nodes, and the maps each node
/// produces.
fn consumers_and_products(
    graph: &Graph,
    needed: &[NodeId],
    maps: &[MapKind],
) -> (Vec<usize>, BTreeMap<usize, Vec<MapKind>>) {
    let mut consumers = vec![0usize; graph.nodes().len()];
    for id in needed {
        for input in &graph.node(*id).inputs {
            consumers[input.0] += 1;
        }
    }
    let mut produces: BTreeMap<usize, Vec<MapKind>> = BTreeMap::new();
    for map in maps {
        if let Some(id) = graph.output(*map) {
            produces.entry(id.0).or_default().push(*map);
        }
    }
    (consumers, produces)
}

/// Channels of a computed node's buffer.
fn channels_of(store: &[Option<Arc<Image>>], id: NodeId) -> usize {
    store[id.0].as_ref().map_or(1, |image| image.channels)
}

/// The first ready node in builder order, plus ready nodes a short way ahead, at most one
/// per thread: branch parallelism without running far ahead (memory).
fn next_batch(graph: &Graph, remaining: &[NodeId], computed: &[bool], threads: usize) -> Vec<NodeId> {
    let mut batch = Vec::new();
    for id in remaining.iter().take(LOOKAHEAD) {
        if batch.len() == threads {
            break;
        }
        if graph.node(*id).inputs.iter().all(|i| computed[i.0]) {
            batch.push(*id);
        }
    }
    batch
}

/// The input whose buffer node `id` may overwrite: its first input, when it is an in-place
/// operation and the last consumer of that buffer, and the buffer is no requested map.
fn reusable_input(
    graph: &Graph,
    id: NodeId,
    consumers: &[usize],
    produces: &BTreeMap<usize, Vec<MapKind>>,
) -> Option<NodeId> {
    let node = graph.node(id);
    let first = *node.inputs.first()?;
    let used_once = node.inputs.iter().filter(|i| **i == first).count() == 1;
    let needed_later = consumers[first.0] != 1 || produces.contains_key(&first.0);
    (node.op.in_place() && used_once && !needed_later).then_some(first)
}

/// Bytes node `id` allocates when its inputs have `inputs` channels at `width` × `height`:
/// its result's buffer and the scratch its kernel holds while it runs.
fn node_bytes(graph: &Graph, id: NodeId, inputs: &[usize], width: usize, height: usize) -> (u64, u64) {
    let op = &graph.node(id).op;
    let channels = op.output_channels(inputs) as u64;
    let bytes = channels * (width as u64) * (height as u64) * 4;
    let mut scratch = op.scratch_images(width) as u64 * bytes + op.mask_bytes(width, height, graph.wraps_v());
    scratch += op.scratch_rows(width) as u64 * channels * width as u64 * 4;
    if let super::Op::Fused(chain) = op {
        scratch += chain.scratch_bytes(width, height, inputs);
    }
    (bytes, scratch)
}

/// The most bytes of node buffers alive at once when `maps` are evaluated at `width` ×
/// `height`, found by running the evaluator's schedule on buffer sizes instead of buffers
/// (same batches, same in-place reuse, same releases), plus the scratch buffers of the
/// kernels running together. Maps are counted until they are handed over.
pub fn estimate_peak_bytes(graph: &Graph, maps: &[MapKind], width: usize, height: usize) -> u64 {
    schedule_peak_bytes(graph, maps, width, height, CacheKind::None)
}

/// `estimate_peak_bytes` for a first evaluation into a `NodeCache` (`CachePolicy::Keep`):
/// nothing is freed or overwritten in place, so every node's buffer is alive at the end.
/// The window's check used the one-shot peak: 312 MiB estimated, 890 MiB peak at 2048².
pub fn estimate_cached_peak_bytes(graph: &Graph, maps: &[MapKind], width: usize, height: usize) -> u64 {
    schedule_peak_bytes(graph, maps, width, height, CacheKind::Keep)
}

/// The two cache policies' effect on the schedule's buffers, without a cache.
#[derive(Clone, Copy, PartialEq, Eq)]
enum CacheKind {
    None,
    Keep,
}

fn schedule_peak_bytes(graph: &Graph, maps: &[MapKind], width: usize, height: usize, cache: CacheKind) -> u64 {
    let keep = cache == CacheKind::Keep;
    let needed = graph.reachable(maps);
    let (mut consumers, produces) = consumers_and_products(graph, &needed, maps);
    let mut channels = vec![0usize; graph.nodes().len()];
    let mut live = vec![0u64; graph.nodes().len()];
    let mut computed = vec![false; graph.nodes().len()];
    let (mut live_bytes, mut peak_bytes) = (0u64, 0u64);
    let threads = rayon::current_num_threads().max(1);
    let mut remaining = needed;
    while !remaining.is_empty() {
        let batch = next_batch(graph, &remaining, &computed, threads);
        remaining.retain(|id| !batch.contains(id));
        let mut scratch = 0;
        for &id in &batch {
            let node = graph.node(id);
            if let Some(first) = reusable_input(graph, id, &consumers, &produces).filter(|_| !keep) {
                live_bytes -= std::mem::take(&mut live[first.0]);
            }
            let inputs: Vec<usize> = node.inputs.iter().map(|i| channels[i.0]).collect();
            channels[id.0] = node.op.output_channels(&inputs);
            let (bytes, node_scratch) = node_bytes(graph, id, &inputs, width, height);
            scratch += node_scratch;
            live[id.0] = bytes;
            live_bytes += bytes;
            computed[id.0] = true;
        }
        peak_bytes = peak_bytes.max(live_bytes + scratch);
        let mut finished: Vec<usize> = batch.iter().map(|id| id.0).filter(|i| consumers[*i] == 0).collect();
        for id in &batch {
            for input in &graph.node(*id).inputs {
                consumers[input.0] -= 1;
                if consumers[input.0] == 0 {
                    finished.push(input.0);
                }
            }
        }
        if !keep {
            for index in finished {
                live_bytes -= std::mem::take(&mut live[index]);
            }
        }
    }
    peak_bytes
}
