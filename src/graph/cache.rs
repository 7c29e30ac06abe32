//! Incremental re-evaluation for live reload: each node's output is cached under a key that
//! hashes its operation (with every parameter), its inputs' keys and the size, so after a
//! preset edit only the nodes whose parameters changed — and the nodes downstream of them —
//! run again. A one-shot `generate` does not need this and uses the frugal scheduler in
//! `eval.rs`, which frees buffers early; the cache keeps every node of the current graph alive
//! instead (fine at preview resolution: a 512² preview holds a few tens of MiB).

use std::collections::hash_map::DefaultHasher;
use std::collections::{BTreeMap, HashMap};
use std::hash::{Hash, Hasher};
use std::sync::Arc;

use super::Graph;
use crate::maps::MapKind;
use crate::ops::Image;

#[derive(Debug, Default)]
pub struct NodeCache {
    entries: HashMap<u64, Arc<Image>>,
}

/// How much of the graph an evaluation had to run.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct CacheStats {
    pub evaluated: usize,
    pub reused: usize,
}

impl NodeCache {
    pub fn new() -> NodeCache {
        NodeCache::default()
    }

    /// Evaluates `maps`, reusing every node whose key is cached; afterwards the cache holds
    /// exactly the nodes of this evaluation.
    pub fn evaluate(
        &mut self,
        graph: &Graph,
        maps: &[MapKind],
        width: usize,
        height: usize,
    ) -> (BTreeMap<MapKind, Image>, CacheStats) {
        let mut keys: HashMap<usize, u64> = HashMap::new();
        let mut fresh: HashMap<u64, Arc<Image>> = HashMap::new();
        let mut stats = CacheStats::default();
        for id in graph.reachable(maps) {
            let node = graph.node(id);
            let mut hasher = DefaultHasher::new();
            format!("{:?}", node.op).hash(&mut hasher);
            (width, height).hash(&mut hasher);
            for input in &node.inputs {
                keys[&input.0].hash(&mut hasher);
            }
            let key = hasher.finish();
            keys.insert(id.0, key);
            if fresh.contains_key(&key) {
                continue;
            }
            if let Some(image) = self.entries.get(&key) {
                fresh.insert(key, image.clone());
                stats.reused += 1;
                continue;
            }
            let inputs: Vec<Arc<Image>> = node.inputs.iter().map(|i| fresh[&keys[&i.0]].clone()).collect();
            let rest: Vec<&Image> = inputs.iter().skip(1).map(|i| i.as_ref()).collect();
            let first = inputs.first().map(|i| std::borrow::Cow::Borrowed(i.as_ref()));
            let image = node.op.eval(first, &rest, width, height);
            fresh.insert(key, Arc::new(image));
            stats.evaluated += 1;
        }
        let outputs =
            maps.iter().filter_map(|m| graph.output(*m).map(|id| (*m, (*fresh[&keys[&id.0]]).clone()))).collect();
        self.entries = fresh;
        (outputs, stats)
    }
}
