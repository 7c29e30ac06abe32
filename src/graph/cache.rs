//! The node cache for live reload: node outputs kept under a key that hashes the operation
//! (with every parameter, `op::hash_op`), its inputs' keys and the size, so after a preset
//! edit only the nodes whose parameters changed — and the nodes downstream of them — run
//! again. Evaluation itself is the one evaluator in `eval.rs` with `CachePolicy::Keep`; a
//! one-shot `generate` uses `CachePolicy::None`, which frees buffers early, where the cache
//! keeps every node alive (fine at preview resolution: a 512² preview holds tens of MiB).

use std::collections::{BTreeMap, HashMap};
use std::sync::Arc;

use super::Graph;
use super::eval::{CachePolicy, evaluate_with};
use crate::material::MapKind;
use crate::ops::Image;

#[derive(Debug, Default)]
pub struct NodeCache {
    entries: HashMap<u64, Arc<Image>>,
}

/// How much of the graph an evaluation had to run.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct CacheStats {
    /// Nodes that ran.
    pub evaluated: usize,
    /// Nodes the maps reach whose results were not recomputed (cached, or needed only by
    /// cached nodes).
    pub reused: usize,
}

impl NodeCache {
    pub fn new() -> NodeCache {
        NodeCache::default()
    }

    /// Bytes of the images the cache holds (for the memory check before it evaluates again).
    pub fn bytes(&self) -> u64 {
        self.entries.values().map(|image| image.bytes() as u64).sum()
    }

    pub(crate) fn get(&self, key: u64) -> Option<Arc<Image>> {
        self.entries.get(&key).cloned()
    }

    pub(crate) fn replace(&mut self, entries: Vec<(u64, Arc<Image>)>) {
        self.entries = entries.into_iter().collect();
    }

    /// Evaluates `maps`, reusing every node whose key is cached; afterwards the cache holds
    /// the nodes this evaluation ran or used.
    pub fn evaluate(
        &mut self,
        graph: &Graph,
        maps: &[MapKind],
        width: usize,
        height: usize,
    ) -> (BTreeMap<MapKind, Image>, CacheStats) {
        let mut outputs = BTreeMap::new();
        let (_, stats) = evaluate_with(
            graph,
            maps,
            crate::ops::Frame::whole(width, height),
            &|_, _| {},
            &mut |map, image| {
                outputs.insert(map, image);
            },
            CachePolicy::Keep(self),
        );
        (outputs, stats)
    }
}
