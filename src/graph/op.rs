//! The operations a node can perform, and the one `match` that dispatches them to the pixel
//! kernels in `ops`.

use crate::ops::{Frame, Image};
use std::borrow::Cow;

use crate::ops::body::{AlongProfile, HeadMark};
use crate::ops::filters::{self, BlendMode, NormalConvention};
use crate::ops::noise::{FractalNoise, NoiseKind};
use crate::ops::scale_colour::{ScaleChannels, ScaleColour};
use crate::ops::scales::ScaleField;
use crate::ops::shapes::{self, Axis, BellyMarks, Blotches, SpotGrid};

use super::fuse::FusedChain;

#[derive(Debug, Clone, PartialEq)]
pub enum Op {
    /// Tileable fractal noise in [0, 1]. No inputs.
    Noise(FractalNoise),
    /// The same value everywhere (a map the preset makes meaningless, such as the film
    /// thickness of a species without a film). No inputs.
    Constant { value: f32 },
    /// The multi-channel scale field (`ops::scales::channel`). No inputs.
    Scales(ScaleField),
    /// One channel of the input, which is the scale field and so planar (`Image::plane`;
    /// a one-channel image is the same either way).
    Channel { index: usize },
    /// Smooth bands along one axis (stripes, rings, the belly). No inputs.
    Bands { axis: Axis, centres: Vec<f32>, half_width: f32, softness: f32 },
    /// A dorsal series of blotches (tiny-skia coverage). No inputs.
    Blotches(Blotches),
    /// Marks on the ventral plates. No inputs.
    BellyMarks(BellyMarks),
    /// Inputs: a mask and the scale field; replaces each pixel's mask value by the value at
    /// its scale's centre, by `amount` (colour that follows scale boundaries).
    /// `reach`: how far (texture widths) a pixel may lie from its scale's centre along the
    /// body, for the margin of a strip (`row_reach`).
    SnapToScales { amount: f32, centre_u: usize, centre_v: usize, reach: f32, whole: bool },
    /// A jittered grid of round spots (tiny-skia coverage). No inputs.
    Spots(SpotGrid),
    /// Linear remap of the input range to the output range.
    Levels { in_low: f32, in_high: f32, out_low: f32, out_high: f32 },
    /// Soft binarisation of the input.
    Threshold { level: f32, softness: f32 },
    /// Wrap-around Gaussian blur, sigma in texture widths.
    Blur { sigma: f32 },
    /// Sobel edge magnitude, normalised for edges blurred by `edge_sigma`.
    Sobel { edge_sigma: f32 },
    /// Inputs: base, layer and an optional mask.
    Blend { mode: BlendMode, opacity: f32 },
    /// Gray input to linear RGB between two colours.
    Colorize { low: [f32; 3], high: [f32; 3] },
    /// Inputs: RGB base and a mask; mixes a constant colour in where the mask is set.
    Tint { color: [f32; 3], opacity: f32 },
    /// Inputs: RGB colour and the scale field; colour per scale (`ops::scale_colour`).
    ScaleColour(ScaleColour),
    /// Height to a tangent-space normal.
    /// `v_extent`: the image's height in texture widths (1 tile, the body's length).
    HeightToNormal { slope: f32, convention: NormalConvention, v_extent: f32 },
    /// A mask varying along the body only (`ops::body::AlongProfile`). No inputs.
    Along(AlongProfile),
    /// A mark on the head or neck of a body atlas (`ops::body::HeadMark`). No inputs.
    HeadMark(HeadMark),
    /// Height to ambient occlusion (`ops::occlusion`): `slope` as `HeightToNormal`'s, the
    /// horizon searched `radius` texture widths out; `v_extent` as `HeightToNormal`'s.
    Occlusion { slope: f32, radius: f32, v_extent: f32 },
    /// A chain of per-pixel operations run a band of rows at a time (`Graph::fused`).
    /// Inputs: those the chain reads from outside it.
    Fused(FusedChain),
}

impl Op {
    /// How many inputs the operation takes (checked when a node is added).
    pub fn arity(&self) -> std::ops::RangeInclusive<usize> {
        match self {
            Op::Noise(_)
            | Op::Constant { .. }
            | Op::Scales(_)
            | Op::Bands { .. }
            | Op::Blotches(_)
            | Op::BellyMarks(_)
            | Op::Spots(_)
            | Op::Along(_)
            | Op::HeadMark(_) => 0..=0,
            Op::Channel { .. }
            | Op::Levels { .. }
            | Op::Threshold { .. }
            | Op::Blur { .. }
            | Op::Sobel { .. }
            | Op::Colorize { .. }
            | Op::HeightToNormal { .. }
            | Op::Occlusion { .. } => 1..=1,
            Op::SnapToScales { .. } | Op::Tint { .. } | Op::ScaleColour(_) => 2..=2,
            Op::Blend { .. } => 2..=3,
            Op::Fused(_) => 1..=usize::MAX,
        }
    }

    /// The channel indices this node reads from its input `input` by position (a
    /// multi-channel scale field), for `Graph::for_maps` to renumber when the field outputs
    /// fewer channels: Some(list) for the ops that address a field's channels, None for an
    /// op that would read the input whole (none reads the field so: it is planar, and only
    /// these ops read it by plane).
    pub fn channel_reads_mut(&mut self, input: usize) -> Option<Vec<&mut usize>> {
        match (self, input) {
            (Op::Channel { index }, 0) => Some(vec![index]),
            (Op::SnapToScales { centre_u, centre_v, .. }, 1) => Some(vec![centre_u, centre_v]),
            (Op::ScaleColour(op), 1) => {
                let c = &mut op.channels;
                let optional =
                    [&mut c.random, &mut c.inside, &mut c.along, &mut c.row].into_iter().flat_map(Option::as_mut);
                Some(std::iter::once(&mut c.crevice).chain(optional).collect())
            }
            _ => None,
        }
    }

    /// Channels of the output, from the channels of the inputs (the memory estimate walks
    /// the graph with these instead of images; a test holds them to what `eval` returns).
    pub fn output_channels(&self, inputs: &[usize]) -> usize {
        match self {
            Op::Scales(field) => field.outputs.len(),
            Op::Fused(chain) => chain.output_channels(inputs),
            Op::Colorize { .. } | Op::HeightToNormal { .. } => 3,
            Op::Levels { .. }
            | Op::Threshold { .. }
            | Op::Blur { .. }
            | Op::Blend { .. }
            | Op::Tint { .. }
            | Op::ScaleColour(_) => inputs.first().copied().unwrap_or(1),
            Op::Noise(_)
            | Op::Constant { .. }
            | Op::Channel { .. }
            | Op::Bands { .. }
            | Op::Blotches(_)
            | Op::BellyMarks(_)
            | Op::SnapToScales { .. }
            | Op::Spots(_)
            | Op::Along(_)
            | Op::HeadMark(_)
            | Op::Occlusion { .. }
            | Op::Sobel { .. } => 1,
        }
    }

    /// Temporary buffers a kernel allocates besides its output, in output-sized images, at
    /// `width` pixels wide: the small blur's horizontal pass, and its input, which it still
    /// holds while it writes a new output (`filters::gaussian_blur`; the estimate has
    /// counted that input as handed over).
    pub fn scratch_images(&self, width: usize) -> usize {
        match self {
            Op::Blur { sigma } if filters::blur_is_gaussian(*sigma, width) => 2,
            _ => 0,
        }
    }

    /// Bytes of the coverage mask a shape kernel draws into besides its output, for an
    /// output `height` rows of a texture `width` wide (`shapes::coverage_mask_bytes`: the
    /// whole tile for any strip of a tile).
    pub fn mask_bytes(&self, width: usize, height: usize, wraps_v: bool) -> u64 {
        match self {
            Op::Blotches(_) | Op::Spots(_) => shapes::coverage_mask_bytes(width, height, wraps_v),
            _ => 0,
        }
    }

    /// Temporary memory besides the output and `scratch_images`, in output rows: the box
    /// blur's ring, tail, tiles and each thread's row sweeps (`filters::blur_scratch_rows`:
    /// about 270 rows at σ = 0.006 and 4096² on two threads, 7 % of the image; more for wide
    /// blurs and with more threads).
    pub fn scratch_rows(&self, width: usize) -> usize {
        match self {
            Op::Blur { sigma } => filters::blur_scratch_rows(*sigma, width),
            _ => 0,
        }
    }

    /// True for operations that can write their result into their first input's buffer.
    pub fn in_place(&self) -> bool {
        matches!(
            self,
            Op::Levels { .. }
                | Op::Threshold { .. }
                | Op::Blend { .. }
                | Op::Tint { .. }
                | Op::ScaleColour(_)
                | Op::Blur { .. }
        ) || matches!(self, Op::Fused(chain) if chain.in_place)
    }

    /// True for operations whose output pixel depends only on the inputs' pixels at the same
    /// place, which `Graph::fused` may run a band of rows at a time in one chain.
    pub fn per_pixel(&self) -> bool {
        matches!(
            self,
            Op::Channel { .. }
                | Op::Levels { .. }
                | Op::Threshold { .. }
                | Op::Blend { .. }
                | Op::Colorize { .. }
                | Op::Tint { .. }
        )
    }

    /// How many rows above and below a pixel the operation reads: what a strip of a long
    /// texture must carry as margin so that its kept rows equal the whole texture's
    /// (`Graph::row_reach` sums them along the graph).
    pub fn row_reach(&self, width: usize) -> usize {
        match self {
            Op::Blur { sigma } => crate::ops::filters::blur_row_reach(*sigma, width),
            Op::Sobel { .. } | Op::HeightToNormal { .. } => 1,
            Op::SnapToScales { reach, .. } => (reach * width as f32).ceil() as usize + 2,
            // Pixels are square: a texture width is `width` rows.
            Op::Occlusion { radius, .. } => crate::ops::occlusion::row_reach(*radius, width as f32),
            _ => 0,
        }
    }

    /// Evaluates the operation over the rows of `frame`. `first` is the first input (owned
    /// when the evaluator could hand its buffer over, see `in_place`), `rest` the others in
    /// input order.
    pub fn eval(&self, first: Option<Cow<'_, Image>>, rest: &[&Image], frame: Frame) -> Image {
        if self.is_generator() && frame.crosses_seam() {
            // Generators place pixels by texture row: the rows before the seam and those
            // after it, each evaluated as any strip, are exactly the texture's.
            let (before, after) = frame.split_at_seam();
            let (top, bottom) = (self.eval(None, &[], before), self.eval(None, &[], after));
            let mut image = Image::new(frame.width, frame.height, top.channels);
            // Each part is the top's rows, then the bottom's: the whole buffer for interleaved
            // pixels, each plane for the scale field, which is planar (`Image::plane`).
            let parts = if let Op::Scales(_) = self { top.channels } else { 1 };
            let (whole, upper_len) = (image.data.len() / parts, top.data.len() / parts);
            for (p, part) in image.data.chunks_exact_mut(whole.max(1)).enumerate() {
                let (upper, lower) = part.split_at_mut(upper_len);
                upper.copy_from_slice(&top.data[p * upper_len..(p + 1) * upper_len]);
                lower.copy_from_slice(&bottom.data[p * (whole - upper_len)..(p + 1) * (whole - upper_len)]);
            }
            return image;
        }
        let input = || first.as_deref().expect("operation has an input");
        match self {
            Op::Noise(noise) => crate::ops::noise::render(noise, frame),
            Op::Constant { value } => filters::constant(frame.width, frame.height, *value),
            Op::Scales(field) => field.render_planar(frame),
            Op::Channel { index } => filters::extract_channel(input(), *index),
            Op::Bands { axis, centres, half_width, softness } => {
                shapes::bands(frame, *axis, centres, *half_width, *softness)
            }
            Op::Blotches(b) => shapes::blotches(frame, b),
            Op::BellyMarks(marks) => shapes::belly_marks(frame, marks),
            Op::SnapToScales { amount, centre_u, centre_v, whole, .. } => {
                filters::snap_to_scales(input(), rest[0], *amount, *centre_u, *centre_v, *whole, frame)
            }
            Op::Spots(grid) => shapes::spots(frame, grid),
            Op::Blur { sigma } => filters::blur(first.expect("operation has an input"), *sigma, frame.wraps_v),
            Op::Sobel { edge_sigma } => filters::sobel(input(), *edge_sigma, frame.wraps_v),
            Op::Colorize { low, high } => filters::colorize(input(), *low, *high),
            Op::HeightToNormal { slope, convention, v_extent } => {
                filters::height_to_normal(input(), filters::NormalSpec::in_frame(*slope, *convention, *v_extent, frame))
            }
            Op::Along(profile) => profile.render(frame),
            Op::HeadMark(mark) => crate::ops::body::head_mark(frame, mark),
            Op::Occlusion { slope, radius, v_extent } => {
                let rows_per_width = frame.full_height as f32 / v_extent;
                crate::ops::occlusion::horizon_occlusion(input(), *slope, *radius, rows_per_width, frame.wraps_v)
            }
            Op::Levels { in_low, in_high, out_low, out_high } => {
                filters::levels(owned(first), *in_low, *in_high, *out_low, *out_high)
            }
            Op::Threshold { level, softness } => filters::threshold(owned(first), *level, *softness),
            Op::Blend { mode, opacity } => filters::blend(owned(first), rest[0], rest.get(1).copied(), *mode, *opacity),
            Op::Tint { color, opacity } => tint(owned(first), rest[0], *color, *opacity),
            Op::ScaleColour(colour) => colour.apply(owned(first), rest[0], frame),
            Op::Fused(chain) => chain.eval(first, rest, frame),
        }
    }

    /// Operations without inputs, which compute their pixels from the frame's texture rows
    /// (`arity`'s list, not a second one a new generator could be left out of).
    fn is_generator(&self) -> bool {
        self.arity() == (0..=0)
    }

    /// A short description for stats and DOT labels.
    pub fn label(&self) -> String {
        match self {
            Op::Noise(n) => {
                let kind = match n.kind {
                    NoiseKind::Perlin => "perlin",
                    NoiseKind::Cellular => "cellular",
                };
                format!("noise {kind} {}x{} octaves={}", n.cells_u, n.cells_v, n.octaves)
            }
            Op::Constant { value } => format!("constant {value}"),
            Op::Scales(s) => format!("scales {:?} rows={}", s.shape, s.rows).to_lowercase(),
            Op::Channel { index } => format!("channel {index}"),
            Op::Bands { axis, centres, .. } => format!("bands {axis:?} n={}", centres.len()).to_lowercase(),
            Op::Blotches(b) => format!("blotches {:?} n={}", b.shape, b.count).to_lowercase(),
            Op::BellyMarks(m) => format!("belly {:?}", m.kind).to_lowercase(),
            Op::SnapToScales { amount, .. } => format!("snap to scales {amount:.2}"),
            Op::Spots(g) => format!("spots {}x{}", g.across, g.along),
            Op::Levels { .. } => "levels".into(),
            Op::Threshold { level, .. } => format!("threshold {level:.2}"),
            Op::Blur { sigma } => format!("blur sigma={sigma:.4}"),
            Op::Sobel { .. } => "sobel".into(),
            Op::Blend { mode, .. } => format!("blend {mode:?}").to_lowercase(),
            Op::Colorize { .. } => "colorize".into(),
            Op::Tint { .. } => "tint".into(),
            Op::HeightToNormal { .. } => "height to normal".into(),
            Op::Occlusion { radius, .. } => format!("ambient occlusion radius={radius:.4}"),
            Op::Along(p) => format!("along the body, {} knots", p.knots.len()),
            Op::HeadMark(m) => format!("head mark {:?}", m.shape).to_lowercase(),
            Op::ScaleColour(c) => format!("colour per scale tone={:.2} speckle={:.2}", c.tone, c.speckle),
            Op::Fused(chain) => {
                let labels: Vec<String> = chain.steps.iter().map(|step| step.op.label()).collect();
                format!("fused {}: {}", labels.len(), labels.join(" + "))
            }
        }
    }
}

/// The first input as an owned buffer (a copy only when the evaluator could not hand it over).
fn owned(first: Option<Cow<'_, Image>>) -> Image {
    first.expect("operation has an input").into_owned()
}

fn tint(base: Image, mask: &Image, color: [f32; 3], opacity: f32) -> Image {
    use rayon::prelude::*;
    let mut out = base;
    let (ch, width) = (out.channels, out.width);
    if ch == 3 && mask.channels == 1 {
        // RGB under a one-channel mask, the colour chain's case: fixed-size pixels, no loop
        // over channels (the same expression per sample, so the same bits; 8 → 6 ms at
        // 2048², one thread).
        out.data.par_chunks_mut(3 * width).zip(mask.data.par_chunks(width)).for_each(|(row, mask_row)| {
            for (px, m) in row.chunks_exact_mut(3).zip(mask_row) {
                let w = m * opacity;
                px[0] += (color[0] - px[0]) * w;
                px[1] += (color[1] - px[1]) * w;
                px[2] += (color[2] - px[2]) * w;
            }
        });
        return out;
    }
    // Rows in parallel, as every other per-pixel kernel (this one ran on one thread).
    out.data.par_chunks_mut(ch * width).zip(mask.data.par_chunks(mask.channels * width)).for_each(|(row, mask_row)| {
        for (px, m) in row.chunks_exact_mut(ch).zip(mask_row.chunks_exact(mask.channels)) {
            let w = m[0] * opacity;
            for c in 0..ch.min(3) {
                px[c] += (color[c] - px[c]) * w;
            }
        }
    });
    out
}

/// Feeds an operation and every parameter into a hasher: the node cache's key. Each struct
/// is destructured in full, so a parameter added later fails to compile here instead of
/// silently sharing a cache entry with different output; floats hash by their bits (so
/// 0.0 and -0.0 differ, which can only cost a needless re-evaluation, never a wrong reuse).
pub fn hash_op<H: std::hash::Hasher>(op: &Op, h: &mut H) {
    use std::hash::Hash;
    let float = |h: &mut H, x: f32| x.to_bits().hash(h);
    std::mem::discriminant(op).hash(h);
    match op {
        Op::Noise(FractalNoise { kind, cells_u, cells_v, octaves, gain, seed }) => {
            (kind, cells_u, cells_v, octaves, seed).hash(h);
            float(h, *gain);
        }
        Op::Scales(ScaleField {
            shape,
            rows,
            aspect,
            size,
            keel_height,
            keel_width,
            jitter,
            imbrication,
            edge_softness,
            belly_width,
            vertebral_width,
            lowest_row_width,
            smooth_rows,
            seed,
            length,
            body,
            outputs,
        }) => {
            (shape, rows, smooth_rows, seed, outputs).hash(h);
            float(h, *length);
            if let Some(b) = body {
                b.hash_into(h);
            }
            for x in [
                aspect,
                size,
                keel_height,
                keel_width,
                jitter,
                imbrication,
                edge_softness,
                belly_width,
                vertebral_width,
                lowest_row_width,
            ] {
                float(h, *x);
            }
        }
        Op::Channel { index } => index.hash(h),
        Op::Constant { value } => float(h, *value),
        Op::Bands { axis, centres, half_width, softness } => {
            axis.hash(h);
            centres.len().hash(h);
            for x in centres.iter().chain([half_width, softness]) {
                float(h, *x);
            }
        }
        Op::Blotches(Blotches {
            shape,
            count,
            half_width,
            length,
            jitter,
            offset,
            staggered,
            phase,
            scale,
            span,
            widen,
            seed,
        }) => {
            (shape, count, staggered, seed).hash(h);
            for x in [half_width, length, jitter, offset, phase, scale, &span.0, &span.1, widen] {
                float(h, *x);
            }
        }
        Op::BellyMarks(BellyMarks { kind, rows_v, body, belly_width, amount, softness, seed }) => {
            (kind, rows_v, seed).hash(h);
            if let Some(b) = body {
                b.hash_into(h);
            }
            for x in [belly_width, amount, softness] {
                float(h, *x);
            }
        }
        Op::SnapToScales { amount, centre_u, centre_v, reach, whole } => {
            (centre_u, centre_v, whole).hash(h);
            float(h, *amount);
            float(h, *reach);
        }
        Op::Spots(SpotGrid { across, along, radius, jitter, alternate, checkered, hole, seed, band, span }) => {
            (across, along, alternate, checkered, seed).hash(h);
            for x in [radius, jitter, hole, &span.0, &span.1] {
                float(h, *x);
            }
            band.is_some().hash(h);
            if let Some((u0, u1)) = band {
                float(h, *u0);
                float(h, *u1);
            }
        }
        Op::Levels { in_low, in_high, out_low, out_high } => {
            for x in [in_low, in_high, out_low, out_high] {
                float(h, *x);
            }
        }
        Op::Threshold { level, softness } => {
            float(h, *level);
            float(h, *softness);
        }
        Op::Blur { sigma } => float(h, *sigma),
        Op::Sobel { edge_sigma } => float(h, *edge_sigma),
        Op::Blend { mode, opacity } => {
            mode.hash(h);
            float(h, *opacity);
        }
        Op::Colorize { low, high } => {
            for x in low.iter().chain(high) {
                float(h, *x);
            }
        }
        Op::Tint { color, opacity } => {
            for x in color.iter().chain([opacity]) {
                float(h, *x);
            }
        }
        Op::HeightToNormal { slope, convention, v_extent } => {
            convention.hash(h);
            float(h, *slope);
            float(h, *v_extent);
        }
        Op::Occlusion { slope, radius, v_extent } => {
            for x in [slope, radius, v_extent] {
                float(h, *x);
            }
        }
        Op::Along(profile) => profile.hash_into(h),
        Op::HeadMark(mark) => mark.hash_into(h),
        Op::ScaleColour(ScaleColour {
            tone,
            hue,
            edge,
            belly_edge,
            tip,
            speckle,
            speckle_color,
            skin,
            speckle_cells,
            speckle_cells_v,
            seed,
            channels: ScaleChannels { crevice, random, inside, along, row },
        }) => {
            (speckle_cells, speckle_cells_v, seed, crevice, random, inside, along, row, skin.is_some()).hash(h);
            let floats = [tone, hue, edge, belly_edge, tip, speckle].into_iter();
            for x in floats.chain(speckle_color).chain(skin.iter().flatten()) {
                float(h, *x);
            }
        }
        Op::Fused(chain) => {
            for step in &chain.steps {
                hash_op(&step.op, h);
                step.inputs.hash(h);
            }
        }
    }
}
