//! Fusing chains of per-pixel nodes into one pass.
//!
//! Why: a graph evaluated one buffer per node makes every one-line operation (a levels, a
//! blend, a channel copy) a pass over whole images in memory, into a new buffer that the
//! kernel page-faults in. At 2048² such nodes took about a third of a set's node time
//! (`--stats`: a channel copy 18–23 ms, a levels 14 ms on a fresh buffer, 2–3 ms in place;
//! figures from before the scale field was planar, which made channel copies cheaper).
//! A per-pixel node whose only reader is another per-pixel node needs no image of its own:
//! [`Graph::fused`] folds it into that reader, and the reader (the chain's root, whose
//! result some other node or a map needs) becomes one [`Op::Fused`] node that runs the
//! chain a band of rows at a time ([`FusedChain::eval`]), its intermediates a few rows
//! each, in cache.
//!
//! The kernels are the nodes' own (`Op::eval` on a band of rows), so the results are the
//! same bits (`tests/pipeline.rs` compares every preset fused and unfused). Fusion comes
//! last (after `Graph::for_maps`), and the memory estimate walks the fused graph, so it
//! sees the buffers that are really allocated; a fold that would raise the estimated peak
//! is not made (`Graph::fused`).
//!
//! Measured (`--stats`, `natrix-natrix` at 2048², two cores, three runs): the roughness
//! map's nine nodes 77 → 43–45 ms (two chains and one channel copy, whose fold the memory
//! guard undid), the height map's four 37 → 21–23 ms, the colour's last three 20 → 14 ms,
//! graph wall 525 → 491–508 ms; over every species, 2K 0.54 → 0.51 s and 4K 2.17 → 2.07 s
//! at the median (BENCHMARKS.md, "Fused per-pixel chains").

use std::borrow::Cow;
use std::ops::Range;

use rayon::prelude::*;

use super::{Graph, Node, NodeId, estimate_peak_bytes};
use crate::material::MapKind;
use crate::ops::filters;
use crate::ops::{Frame, Image};

use super::Op;

/// Rows per band: a band's intermediates (one- to three-channel rows of the image's width)
/// stay in a core's cache: 16 rows of a 2048-wide RGB image are 384 KiB. Measured on
/// `natrix-natrix` at 2048² (four runs, the four fused chains' node times): 8 rows as fast
/// as 16, 32 rows 5–15 % slower.
const BAND_ROWS: usize = 16;

/// A chain of per-pixel operations run as one node (`Op::Fused`).
#[derive(Debug, Clone, PartialEq)]
pub struct FusedChain {
    /// The operations in topological order; the last is the chain's root, whose result the
    /// node returns.
    pub steps: Vec<FusedStep>,
    /// The result has the first input's channels, so it can be written into that input's
    /// buffer when the evaluator hands it over (`Op::in_place`).
    pub in_place: bool,
}

/// One operation of a fused chain, with the node name it had.
#[derive(Debug, Clone, PartialEq)]
pub struct FusedStep {
    pub name: String,
    pub op: Op,
    pub inputs: Vec<FusedInput>,
}

/// Where a step's input comes from: the fused node's input `k`, or an earlier step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FusedInput {
    External(usize),
    Step(usize),
}

impl FusedChain {
    /// Channels of the chain's result, from the channels of the node's inputs.
    pub fn output_channels(&self, external: &[usize]) -> usize {
        self.step_channels(external).last().copied().unwrap_or(1)
    }

    /// Channels of every step's result.
    fn step_channels(&self, external: &[usize]) -> Vec<usize> {
        let mut channels: Vec<usize> = Vec::with_capacity(self.steps.len());
        for step in &self.steps {
            let inputs: Vec<usize> = step
                .inputs
                .iter()
                .map(|input| match *input {
                    FusedInput::External(k) => external[k],
                    FusedInput::Step(s) => channels[s],
                })
                .collect();
            channels.push(step.op.output_channels(&inputs));
        }
        channels
    }

    /// Bytes of scratch while the chain runs at `width` × `height` with inputs of
    /// `external` channels: per band in flight (one per thread, at most one per band), a band
    /// of every input it copies (`copied_inputs`, and the first input, which the in-place
    /// path always copies) and of every step (an upper bound: a step's band is dropped when
    /// its reader has run).
    pub fn scratch_bytes(&self, width: usize, height: usize, external: &[usize]) -> u64 {
        let mut copied = self.copied_inputs(external.len());
        copied[0] |= self.in_place;
        let inputs: usize = external.iter().zip(&copied).filter(|(_, c)| **c).map(|(k, _)| k).sum();
        let band_channels = inputs + self.step_channels(external).iter().sum::<usize>();
        let in_flight = rayon::current_num_threads().clamp(1, height.div_ceil(BAND_ROWS).max(1));
        (BAND_ROWS.min(height) * width * band_channels * 4 * in_flight) as u64
    }

    /// Which of the node's `count` inputs a band copies: those a step other than a channel
    /// copy reads (a channel copy reads its band straight from the whole image; the
    /// multi-channel scale field, read only so, is never copied).
    fn copied_inputs(&self, count: usize) -> Vec<bool> {
        let mut copied = vec![false; count];
        for step in &self.steps {
            for input in &step.inputs {
                if let FusedInput::External(k) = *input {
                    copied[k] |= !matches!(step.op, Op::Channel { .. });
                }
            }
        }
        copied
    }

    /// Runs the chain over the rows of `frame`, a band at a time, each band's result
    /// written into the output as it is done. `first` is the node's first input, owned when
    /// the evaluator could hand its buffer over (`in_place`): the result then goes into it
    /// (a band's rows are copied out of it before the band's result is written back, and
    /// every step reads only its band's rows).
    pub fn eval(&self, first: Option<Cow<'_, Image>>, rest: &[&Image], frame: Frame) -> Image {
        let first = first.expect("a fused chain has an input");
        let external: Vec<usize> = std::iter::once(first.channels).chain(rest.iter().map(|i| i.channels)).collect();
        let channels = self.output_channels(&external);
        let (width, height) = (first.width, first.height);
        let band_frame = |rows: &Range<usize>| Frame { height: rows.len(), row0: frame.row0 + rows.start, ..frame };
        let row_len = width * channels;
        let band_rows = |band: usize, target: &[f32]| band * BAND_ROWS..band * BAND_ROWS + target.len() / row_len;
        match first {
            Cow::Owned(mut image) if self.in_place && image.channels == channels => {
                image.data.par_chunks_mut(BAND_ROWS * row_len).enumerate().for_each(|(band, target)| {
                    let rows = band_rows(band, target);
                    let own = Image { width, height: rows.len(), channels, data: crate::ops::pool::take_copy(target) };
                    let inputs = std::iter::once(Band::Own(own)).chain(rest.iter().map(|i| Band::Rows(i))).collect();
                    target.copy_from_slice(&self.eval_band(inputs, rows.clone(), band_frame(&rows)).data);
                });
                image
            }
            first => {
                let mut out = Image::new(width, height, channels);
                out.data.par_chunks_mut(BAND_ROWS * row_len).enumerate().for_each(|(band, target)| {
                    let rows = band_rows(band, target);
                    let all = std::iter::once(first.as_ref()).chain(rest.iter().copied());
                    let inputs = all.map(Band::Rows).collect();
                    target.copy_from_slice(&self.eval_band(inputs, rows.clone(), band_frame(&rows)).data);
                });
                out
            }
        }
    }

    /// The chain's result for the band `rows`, from the node's inputs. An input that only
    /// channel copies read is read from the whole image; the others are copied into bands
    /// of their own first. Each step's result has one reader in the chain (`Graph::fused`),
    /// which takes it over; an input's band is handed over to the step that reads it last,
    /// as its first input.
    fn eval_band(&self, inputs: Vec<Band<'_>>, rows: Range<usize>, frame: Frame) -> Image {
        let mut last_use = vec![usize::MAX; inputs.len()];
        for (j, step) in self.steps.iter().enumerate() {
            for input in &step.inputs {
                if let FusedInput::External(k) = *input {
                    last_use[k] = j;
                }
            }
        }
        let copied = self.copied_inputs(inputs.len());
        let whole: Vec<Option<&Image>> =
            inputs.iter().map(|input| if let Band::Rows(image) = input { Some(*image) } else { None }).collect();
        let mut inputs: Vec<Option<Image>> = inputs
            .into_iter()
            .zip(&copied)
            .map(|(input, copy)| match input {
                Band::Own(image) => Some(image),
                Band::Rows(image) if *copy => Some(image.band(rows.clone())),
                Band::Rows(_) => None,
            })
            .collect();
        let mut results: Vec<Option<Image>> = (0..self.steps.len()).map(|_| None).collect();
        for (j, step) in self.steps.iter().enumerate() {
            if let (Op::Channel { index }, [FusedInput::External(k)]) = (&step.op, step.inputs.as_slice())
                && let (None, Some(image)) = (&inputs[*k], whole[*k])
            {
                results[j] = Some(filters::extract_channel_rows(image, rows.clone(), *index));
                continue;
            }
            // The first operand by value where nothing else reads it; then the others by
            // reference.
            let owned = match step.inputs.first() {
                Some(FusedInput::Step(s)) => results[*s].take(),
                Some(&FusedInput::External(k))
                    if last_use[k] == j
                        && step.inputs.iter().filter(|i| **i == FusedInput::External(k)).count() == 1 =>
                {
                    inputs[k].take()
                }
                _ => None,
            };
            let operand = |input: &FusedInput| -> &Image {
                match *input {
                    FusedInput::External(k) => inputs[k].as_ref(),
                    FusedInput::Step(s) => results[s].as_ref(),
                }
                .expect("a fused step's input is ready and read once")
            };
            let first = match owned {
                Some(image) => Some(Cow::Owned(image)),
                None => step.inputs.first().map(|i| Cow::Borrowed(operand(i))),
            };
            let rest: Vec<&Image> = step.inputs.iter().skip(1).map(operand).collect();
            let result = step.op.eval(first, &rest, frame);
            drop(rest);
            for input in step.inputs.iter().skip(1) {
                if let FusedInput::Step(s) = *input {
                    results[s] = None;
                }
            }
            results[j] = Some(result);
        }
        results.pop().flatten().expect("a fused chain has steps")
    }
}

/// A fused node's input for one band: the whole image, whose band is read from it, or the
/// band already copied out (the input whose buffer the result overwrites).
enum Band<'a> {
    Rows(&'a Image),
    Own(Image),
}

impl Graph {
    /// The graph with every chain of per-pixel nodes folded into one `Op::Fused` node (see
    /// the module): a per-pixel node that is read once, by another per-pixel node, and is
    /// no requested map joins its reader's chain. Only the nodes `maps` reach are kept;
    /// the fused node takes its root's name, and inputs from outside the chain become its
    /// inputs: first the one reached through first inputs from the root (whose buffer the
    /// result may overwrite, as the root's own first input could be), then the others in
    /// the order the chain first reads them. A node that is its chain alone stays as it
    /// was. `width` × `height`: the size it will be evaluated at, at which the fused graph's
    /// estimated peak memory (`estimate_peak_bytes`) stays within the plain graph's.
    pub fn fused(&self, maps: &[MapKind], width: usize, height: usize) -> Graph {
        let reachable = self.reachable(maps);
        let count = self.nodes.len();
        let mut consumers = vec![0usize; count];
        let mut reader = vec![None; count];
        let mut channels = vec![0usize; count];
        for &id in &reachable {
            let node = &self.nodes[id.0];
            for input in &node.inputs {
                consumers[input.0] += 1;
                reader[input.0] = Some(id);
            }
            let inputs: Vec<usize> = node.inputs.iter().map(|i| channels[i.0]).collect();
            channels[id.0] = node.op.output_channels(&inputs);
        }
        let outputs: Vec<NodeId> = maps.iter().filter_map(|m| self.output(*m)).collect();
        let mut folded: Vec<bool> = (0..count)
            .map(|i| {
                self.nodes[i].op.per_pixel()
                    && consumers[i] == 1
                    && !outputs.contains(&NodeId(i))
                    && reader[i].is_some_and(|r: NodeId| self.nodes[r.0].op.per_pixel())
            })
            .collect();
        // A fold delays a node to its reader's turn, and the inputs it reads from outside
        // the chain stay alive until then: a chain of tints across pattern layers would hold
        // every layer's mask at once (measured: `bitis-gabonica` at 4096², 835 → 1109 MiB
        // estimated). Fusion must never raise the peak: while it does, the fold that
        // reaches furthest in builder order is undone.
        //
        // That undoes folds that did not raise it too (the reach is a guess at the culprit):
        // `natrix-natrix` lost the folds of its height and crevice channel copies, each a
        // 16 MiB copy at 2048² (64 MiB, page-faulted, at 4096²). So each undone fold is then
        // tried again, in builder order, and kept where the estimated peak stays at what the
        // undoing reached: `natrix-natrix` gets five back (the two channel copies, a keel
        // blend, the colour's base and the belly's outside); at 4096², three runs each
        // interleaved, 1.33–1.36 → 1.27–1.29 s, peak resident 855–875 → 904 MiB (the
        // evaluated peak varies with the schedule by a 64 MiB channel either way).
        let plain_peak = estimate_peak_bytes(self, maps, width, height);
        let wanted = folded.clone();
        let (mut graph, peak) = loop {
            let graph = self.fold(maps, &reachable, &channels, &folded);
            let peak = estimate_peak_bytes(&graph, maps, width, height);
            if peak <= plain_peak {
                break (graph, peak);
            }
            let furthest = (0..count)
                .filter(|&i| folded[i])
                .max_by_key(|&i| reader[i].map_or(0, |r: NodeId| r.0 - i))
                .expect("with nothing folded the graph is the plain one");
            folded[furthest] = false;
        };
        for i in 0..count {
            if wanted[i] && !folded[i] {
                folded[i] = true;
                let refolded = self.fold(maps, &reachable, &channels, &folded);
                if estimate_peak_bytes(&refolded, maps, width, height) <= peak {
                    graph = refolded;
                } else {
                    folded[i] = false;
                }
            }
        }
        graph
    }

    /// The graph with each node for which `folded` is true folded into its one reader's
    /// chain (`fused`); `channels`: each reachable node's output channels.
    fn fold(&self, maps: &[MapKind], reachable: &[NodeId], channels: &[usize], folded: &[bool]) -> Graph {
        let count = self.nodes.len();
        let mut new_id: Vec<Option<NodeId>> = vec![None; count];
        let mut nodes: Vec<Node> = Vec::new();
        for &id in reachable {
            if folded[id.0] {
                continue;
            }
            let node = &self.nodes[id.0];
            let renumber = |i: &NodeId| new_id[i.0].expect("inputs come first");
            let mut members = vec![id];
            let mut stack = vec![id];
            while let Some(member) = stack.pop() {
                for input in &self.nodes[member.0].inputs {
                    if folded[input.0] && !members.contains(input) {
                        members.push(*input);
                        stack.push(*input);
                    }
                }
            }
            members.sort_unstable();
            let fused = if members.len() == 1 {
                Node {
                    name: node.name.clone(),
                    op: node.op.clone(),
                    inputs: node.inputs.iter().map(renumber).collect(),
                }
            } else {
                // The first input along the chain of first inputs comes first: the buffer the
                // evaluator may hand over, as it would to the unfused root.
                let mut spine = id;
                while folded[self.nodes[spine.0].inputs[0].0] {
                    spine = self.nodes[spine.0].inputs[0];
                }
                let mut external: Vec<NodeId> = vec![self.nodes[spine.0].inputs[0]];
                let steps = members
                    .iter()
                    .map(|m| {
                        let member = &self.nodes[m.0];
                        let inputs = member
                            .inputs
                            .iter()
                            .map(|i| match members.binary_search(i) {
                                Ok(s) if folded[i.0] => FusedInput::Step(s),
                                _ => FusedInput::External(external.iter().position(|e| e == i).unwrap_or_else(|| {
                                    external.push(*i);
                                    external.len() - 1
                                })),
                            })
                            .collect();
                        FusedStep { name: member.name.clone(), op: member.op.clone(), inputs }
                    })
                    .collect();
                // Into the scale field's buffer only where it has one channel: it is planar
                // (`Image::plane`), and a band of a planar image of several channels is not a
                // band of rows.
                let planar = matches!(self.nodes[external[0].0].op, Op::Scales(_)) && channels[external[0].0] > 1;
                let in_place = channels[external[0].0] == channels[id.0] && !planar;
                Node {
                    name: node.name.clone(),
                    op: Op::Fused(FusedChain { steps, in_place }),
                    inputs: external.iter().map(renumber).collect(),
                }
            };
            nodes.push(fused);
            new_id[id.0] = Some(NodeId(nodes.len() - 1));
        }
        let outputs = self
            .outputs
            .iter()
            .filter(|(map, _)| maps.contains(map))
            .map(|(map, id)| (*map, new_id[id.0].expect("a map's node is reachable")))
            .collect();
        Graph { nodes, outputs, open_v: self.open_v }
    }
}
