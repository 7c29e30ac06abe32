//! Per-pixel and neighbourhood filters: levels, threshold, blend, colourise, Gaussian blur,
//! Sobel edges and height → normal.
//!
//! All neighbourhood filters address pixels modulo the image width, and modulo its height on
//! the tile, so a tileable input stays tileable; on a body atlas (`Frame::wraps_v` false)
//! rows beyond the snout and the tail tip repeat the end rows. Radii are given in normalised
//! texture units and converted to pixels here, which keeps `--size 512` and `--size 4096`
//! of one preset the same picture at different detail.

use std::borrow::Cow;

use rayon::prelude::*;

use super::image::{Frame, Image};

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum BlendMode {
    /// `base + (layer - base) * opacity * mask`
    Mix,
    Multiply,
    Add,
    Screen,
    Max,
    Min,
}

/// Blends `layer` over `base`. A single-channel layer or mask broadcasts over the base's
/// channels; the result has the base's channel count.
pub fn blend(base: Image, layer: &Image, mask: Option<&Image>, mode: BlendMode, opacity: f32) -> Image {
    // The mode is matched once, not at every sample (measured at 2048², one thread: a
    // one-channel blend took 12 ms deciding mode, mask and broadcast per sample, 2–3 ms as a
    // flat loop; the same expression per sample, so the same bits).
    match mode {
        BlendMode::Mix => blend_with(base, layer, mask, opacity, |_, l| l),
        BlendMode::Multiply => blend_with(base, layer, mask, opacity, |b, l| b * l),
        BlendMode::Add => blend_with(base, layer, mask, opacity, |b, l| b + l),
        BlendMode::Screen => blend_with(base, layer, mask, opacity, |b, l| 1.0 - (1.0 - b) * (1.0 - l)),
        BlendMode::Max => blend_with(base, layer, mask, opacity, |b, l| b.max(l)),
        BlendMode::Min => blend_with(base, layer, mask, opacity, |b, l| b.min(l)),
    }
}

/// `blend` with the mode's `mix(base, layer)`: every sample becomes
/// `b + (mix(b, l) − b) × opacity × m`, m the mask's first channel (1 without a mask), l the
/// layer's channel or its only one.
fn blend_with(
    base: Image,
    layer: &Image,
    mask: Option<&Image>,
    opacity: f32,
    mix: impl Fn(f32, f32) -> f32 + Sync + Copy,
) -> Image {
    if base.channels == 1 && layer.channels == 1 && mask.is_none_or(|m| m.channels == 1) {
        return blend_flat(base, layer, mask, opacity, mix);
    }
    let (channels, layer_channels, width) = (base.channels, layer.channels, base.width);
    let mut out = base;
    let blend_row = |row: &mut [f32], layer_row: &[f32], weights: &mut dyn FnMut() -> f32| {
        for (px, l) in row.chunks_exact_mut(channels).zip(layer_row.chunks_exact(layer_channels)) {
            let weight = weights();
            for (c, b) in px.iter_mut().enumerate() {
                let l = l[c.min(layer_channels - 1)];
                *b += (mix(*b, l) - *b) * weight;
            }
        }
    };
    out.data.par_chunks_mut(channels * width).enumerate().for_each(|(y, row)| match mask {
        Some(m) => {
            let mut samples = m.row(y).chunks_exact(m.channels).map(|p| opacity * p[0]);
            blend_row(row, layer.row(y), &mut || samples.next().unwrap_or(0.0))
        }
        None => blend_row(row, layer.row(y), &mut || opacity),
    });
    out
}

/// Samples per parallel task of the flat per-sample kernels (`levels`, `threshold`, the
/// one-channel `blend`): 64 KiB of f32, many tasks per image, each long enough to vectorise.
const FLAT_CHUNK: usize = 16 * 1024;

/// `blend` of one-channel images: the same expression per sample as the general loop
/// (`b + (mixed − b) × opacity × mask`), so the same bits.
fn blend_flat(
    base: Image,
    layer: &Image,
    mask: Option<&Image>,
    opacity: f32,
    mix: impl Fn(f32, f32) -> f32 + Sync,
) -> Image {
    let mut out = base;
    let chunks = out.data.par_chunks_mut(FLAT_CHUNK).zip(layer.data.par_chunks(FLAT_CHUNK));
    match mask {
        None => chunks.for_each(|(out, layer)| {
            for (b, &l) in out.iter_mut().zip(layer) {
                *b += (mix(*b, l) - *b) * opacity;
            }
        }),
        Some(mask) => chunks.zip(mask.data.par_chunks(FLAT_CHUNK)).for_each(|((out, layer), mask)| {
            for ((b, &l), &m) in out.iter_mut().zip(layer).zip(mask) {
                *b += (mix(*b, l) - *b) * (opacity * m);
            }
        }),
    }
    out
}

/// Linear remap of `[in_low, in_high]` to `[out_low, out_high]`, clamped to the output range.
pub fn levels(input: Image, in_low: f32, in_high: f32, out_low: f32, out_high: f32) -> Image {
    let scale = (out_high - out_low) / (in_high - in_low).max(1e-6);
    let (lo, hi) = (out_low.min(out_high), out_low.max(out_high));
    // Every channel alike: one flat pass over the samples.
    let mut out = input;
    out.data.par_chunks_mut(FLAT_CHUNK).for_each(|chunk| {
        for value in chunk {
            *value = (out_low + (*value - in_low) * scale).clamp(lo, hi);
        }
    });
    out
}

/// Soft binarisation: 0 below `level - softness`, 1 above `level + softness`, smooth between.
pub fn threshold(input: Image, level: f32, softness: f32) -> Image {
    let s = softness.max(1e-5);
    let mut out = input;
    out.data.par_chunks_mut(FLAT_CHUNK).for_each(|chunk| {
        for value in chunk {
            let t = ((*value - (level - s)) / (2.0 * s)).clamp(0.0, 1.0);
            *value = t * t * (3.0 - 2.0 * t);
        }
    });
    out
}

/// Maps a single-channel image to colour: `low` at 0, `high` at 1 (linear RGB).
pub fn colorize(input: &Image, low: [f32; 3], high: [f32; 3]) -> Image {
    let mut out = Image::new(input.width, input.height, 3);
    out.data.par_chunks_mut(3 * input.width).enumerate().for_each(|(y, row)| {
        let src = input.row(y);
        for (x, px) in row.chunks_exact_mut(3).enumerate() {
            let t = src[x * input.channels];
            for c in 0..3 {
                px[c] = (low[c] + (high[c] - low[c]) * t).max(0.0);
            }
        }
    });
    out
}

/// Copies one channel out of a planar multi-channel image (the scale field, `Image::plane`).
pub fn extract_channel(input: &Image, channel: usize) -> Image {
    extract_channel_rows(input, 0..input.height, channel)
}

/// Copies one channel of rows `rows` out of a planar multi-channel image (a fused chain's
/// band, `graph::FusedChain`, read straight from the whole field).
pub fn extract_channel_rows(input: &Image, rows: std::ops::Range<usize>, channel: usize) -> Image {
    let source = input.plane_rows(channel, rows.clone());
    let mut out = Image::new(input.width, rows.len(), 1);
    out.data.par_chunks_mut(FLAT_CHUNK).zip(source.par_chunks(FLAT_CHUNK)).for_each(|(o, s)| o.copy_from_slice(s));
    out
}

/// An image of one channel holding `value` everywhere, filled in parallel: the first touch
/// of a fresh buffer's pages costs more than the stores (a serial fill of 16 MiB at 2048²
/// took 8–11 ms).
pub fn constant(width: usize, height: usize, value: f32) -> Image {
    let mut image = Image::new(width, height, 1);
    // `Image::new` is zeros already (+0.0); a fresh buffer's pages are then never written
    // here, so they cost no page faults until read (a species without a film: its
    // thickness map is 0 everywhere; `crotalus-atrox` at 2048², 3.3–3.7 → 1.5–1.6 ms).
    if value.to_bits() != 0 {
        image.data.par_chunks_mut(FLAT_CHUNK).for_each(|chunk| chunk.fill(value));
    }
    image
}

/// Below this σ in pixels `blur` is the identity (a third of a pixel: the kernel's outer
/// taps would weigh under 1e-2).
const IDENTITY_BELOW_PX: f32 = 0.33;

/// Up to this σ in pixels `blur` samples the Gaussian; beyond, three box passes (Kovesi).
const GAUSSIAN_UP_TO_PX: f32 = 2.0;

/// The sampled Gaussian's radius in pixels: 3 σ, at least one.
fn gaussian_radius(sigma_px: f32) -> usize {
    (sigma_px * 3.0).ceil().max(1.0) as usize
}

/// How many rows above and below a pixel `blur` reads: the sampled Gaussian's radius, or
/// the three box passes' half-widths summed (each pass reads what the one before wrote),
/// 0 for the identity. What a strip of a long texture carries as margin for it.
pub fn blur_row_reach(sigma: f32, width: usize) -> usize {
    let sigma_px = sigma * width as f32;
    if sigma_px < IDENTITY_BELOW_PX {
        0
    } else if blur_is_gaussian(sigma, width) {
        gaussian_radius(sigma_px)
    } else {
        box_widths(sigma_px).iter().map(|w| w / 2).sum()
    }
}

fn gaussian_kernel(sigma_px: f32) -> Vec<f32> {
    let radius = gaussian_radius(sigma_px) as isize;
    let mut kernel: Vec<f32> =
        (-radius..=radius).map(|i| (-(i * i) as f32 / (2.0 * sigma_px * sigma_px)).exp()).collect();
    let sum: f32 = kernel.iter().sum();
    kernel.iter_mut().for_each(|k| *k /= sum);
    kernel
}

/// Separable Gaussian blur, wrapping round u (and v on the tile: `wraps_v`). `sigma` is in
/// normalised units (fraction of the image width); below a third of a pixel it is the
/// identity. Up to 2 px the kernel is
/// sampled exactly; beyond, three successive box filters of Kovesi's widths (P. Kovesi,
/// "Fast almost-Gaussian filtering", DICTA 2010) match the Gaussian's variance at a cost
/// independent of sigma (running sums), which is what keeps large blurs cheap at 4K.
/// `wraps_v`: rows wrap round (the tile) or the first and last rows repeat outward (a body
/// atlas, whose snout and tail tip are not neighbours).
pub fn blur(input: Cow<'_, Image>, sigma: f32, wraps_v: bool) -> Image {
    let sigma_px = sigma * input.width as f32;
    if sigma_px < IDENTITY_BELOW_PX {
        return input.into_owned();
    }
    if blur_is_gaussian(sigma, input.width) {
        return gaussian_blur(&input, sigma_px, wraps_v);
    }
    // The three box passes run in place, each a horizontal and a vertical sweep fused
    // (`box_pass`): an input the evaluator hands over is blurred in its own buffer, a
    // borrowed one in one copy.
    let mut out = input.into_owned();
    for width in box_widths(sigma_px) {
        box_pass(&mut out, width / 2, wraps_v);
    }
    out
}

/// Whether `blur` at `width` pixels samples the Gaussian (a new image and a temporary beside
/// its input) rather than running box passes in place: from a third of a pixel up to 2 px.
pub fn blur_is_gaussian(sigma: f32, width: usize) -> bool {
    let sigma_px = sigma * width as f32;
    (IDENTITY_BELOW_PX..=GAUSSIAN_UP_TO_PX).contains(&sigma_px)
}

/// The scratch of `blur`'s box passes in image rows of its size (`box_pass`: the ring of a
/// band plus the window, the tail, a band of tiles, the f64 sums, two rows' worth, and the
/// row sweeps in flight, a `SweepScratch` each), at the widest of the three passes; 0
/// where the blur samples the Gaussian or is the identity. The sweeps' scratch does not
/// grow with the channels (one channel is swept at a time) but is counted in one-channel
/// rows, which the caller counts once per channel: an overestimate for a colour blur.
pub fn blur_scratch_rows(sigma: f32, width: usize) -> usize {
    let sigma_px = sigma * width as f32;
    if sigma_px < IDENTITY_BELOW_PX || blur_is_gaussian(sigma, width) {
        return 0;
    }
    let r = box_widths(sigma_px).into_iter().max().unwrap_or(1) / 2;
    // The sweeps in flight: one per thread, at most one per group of rows of the largest
    // fill (the ring).
    let in_flight = rayon::current_num_threads().min(box_ring_rows(r) / BOX_ROWS).max(1);
    let sweeps = (SweepScratch::f32s(width, r) * in_flight).div_ceil(width);
    box_ring_rows(r) + (r + 1) + BOX_BAND + 2 + sweeps
}

/// Odd box widths whose three-fold convolution has variance sigma² (Kovesi 2010, eq. 4-5).
fn box_widths(sigma: f32) -> [usize; 3] {
    let n = 3.0f32;
    let ideal = (12.0 * sigma * sigma / n + 1.0).sqrt();
    let mut lower = ideal.floor() as i32;
    if lower % 2 == 0 {
        lower -= 1;
    }
    let lower_f = lower as f32;
    let m = ((12.0 * sigma * sigma - n * lower_f * lower_f - 4.0 * n * lower_f - 3.0 * n) / (-4.0 * lower_f - 4.0))
        .round() as i32;
    [0, 1, 2].map(|i| if i < m { lower.max(1) as usize } else { (lower + 2).max(1) as usize })
}

/// Rows the horizontal box sweep runs side by side: each row's running sum is a chain of
/// dependent f64 additions (about 4 cycles each), so the rows' chains advance together,
/// their samples interleaved (`box_rows_horizontal`: the rows' values at one x are
/// contiguous, and the step at each x is one loop over the rows without index arithmetic
/// or bounds checks). Each row's sums are exactly those of a row swept alone. A 2048²
/// one-channel blur of σ = 10 px (three box passes, one thread in the pool): four rows
/// with a slice each 28.7 ms, eight interleaved 23.5 ms.
const BOX_ROWS: usize = 8;

/// The scratch of one `box_rows_horizontal` call at `width` pixels and radius `r`, rows
/// interleaved: `BOX_ROWS` rows padded with their wrap-around (f64) and their results.
struct SweepScratch {
    padded: Vec<f64>,
    swept: Vec<f32>,
}

impl SweepScratch {
    fn new(width: usize, r: usize) -> SweepScratch {
        SweepScratch { padded: vec![0.0; Self::padded_len(width, r)], swept: vec![0.0; BOX_ROWS * width] }
    }

    fn padded_len(width: usize, r: usize) -> usize {
        BOX_ROWS * (width + 2 * r + 1)
    }

    /// Its size in f32s (`blur_scratch_rows`).
    fn f32s(width: usize, r: usize) -> usize {
        2 * Self::padded_len(width, r) + BOX_ROWS * width
    }
}

/// The horizontal box sweep of `count` ≤ `BOX_ROWS` rows: the mean over x − r ..= x + r of
/// each row of `sources` into the matching row of `out`, wrap-around, by a running sum (f64
/// accumulators so long rows do not drift). `sources` has `BOX_ROWS` rows, those past
/// `count` repeats of a real one (swept, not written). The rows are interleaved, sample i
/// of row k at i · BOX_ROWS + k, so the rows' values at one x are contiguous: in
/// `scratch.padded` (the rows padded with their wrap-around, f64) and `scratch.swept`
/// (their results).
fn box_rows_horizontal(
    sources: &[&[f32]; BOX_ROWS],
    count: usize,
    channels: usize,
    r: usize,
    scratch: &mut SweepScratch,
    out: &mut [f32],
) {
    let ch = channels;
    let w = out.len() / count / ch;
    let norm = 1.0 / (2 * r + 1) as f64;
    let padded = &mut scratch.padded[..SweepScratch::padded_len(w, r)];
    let swept = &mut scratch.swept[..w * BOX_ROWS];
    for c in 0..ch {
        // Padded sample i is the row's sample (i − r) mod w: no modulo in the sweep.
        let mut x = (w - r % w) % w;
        for lane in padded.as_chunks_mut::<BOX_ROWS>().0 {
            for (p, src) in lane.iter_mut().zip(sources) {
                *p = src[x * ch + c] as f64;
            }
            x += 1;
            if x == w {
                x = 0;
            }
        }
        // Each row's first window summed in order, as a row swept alone.
        let mut sums: [f64; BOX_ROWS] =
            std::array::from_fn(|k| (0..2 * r + 1).map(|i| &padded[i * BOX_ROWS + k]).sum::<f64>());
        let (lanes, _) = padded.as_chunks::<BOX_ROWS>();
        let (swept_lanes, _) = swept.as_chunks_mut::<BOX_ROWS>();
        for ((values, add), sub) in swept_lanes.iter_mut().zip(&lanes[2 * r + 1..]).zip(lanes) {
            for k in 0..BOX_ROWS {
                values[k] = (sums[k] * norm) as f32;
                sums[k] += add[k] - sub[k];
            }
        }
        for (k, row) in out.chunks_exact_mut(w * ch).enumerate().take(count) {
            for (pixel, values) in row.chunks_exact_mut(ch).zip(swept_lanes.iter()) {
                pixel[c] = values[k];
            }
        }
    }
}

/// Output rows per step of `box_pass`' vertical sweep.
const BOX_BAND: usize = 64;

/// Rows of `box_pass`' ring at radius `r`: a band plus the window (2r + 1), plus a group
/// of BOX_ROWS that a fill may make past the band's last, rounded to whole groups.
fn box_ring_rows(r: usize) -> usize {
    (BOX_BAND + 2 * r + 1 + BOX_ROWS).next_multiple_of(BOX_ROWS)
}
/// Columns (samples of a row) per block of `box_pass`' vertical sweep.
const BOX_BLOCK: usize = 256;

/// One box pass in place: the mean over x − r ..= x + r along rows (wrap-around), then over
/// y − r ..= y + r along columns (wrapped round or clamped, `wraps_v`).
///
/// Why fused: the horizontal sweep's rows are made a band at a time into a ring of rows just
/// large enough for the vertical sweep's window (a band plus 2r + 1 rows), so the horizontal
/// result never goes through memory as a whole image: the first version wrote and read a
/// second full image per pass (six full sweeps of memory and a page-faulting buffer per
/// blur). The arithmetic is the separate passes', term for term, in the same order: each row
/// swept left to right from x = 0 (`box_rows_horizontal`), each column top to bottom from
/// y = 0 with its running sum started over rows −r ..= r, so the values are the same bits.
///
/// In place: the vertical sweep reads only the ring; the image rows the horizontal sweep
/// reads into the ring lie below the rows already written (each band's rows are swept before
/// the band above them is written back), the rows before the first (y < 0: the last rows,
/// wrapped, or the first, clamped) are swept by the first fill before anything is written,
/// and the rows past the end (y ≥ h: the first rows again, wrapped, or the last row,
/// clamped) are swept before anything else and kept aside (`tail`).
///
/// Scratch besides the image (`blur_scratch_rows`): the ring, the tail, one band of each
/// block's values, the blocks' f64 sums and each running sweep's padded and swept rows,
/// counted in image rows.
fn box_pass(image: &mut Image, r: usize, wraps_v: bool) {
    let (w, h, ch) = (image.width, image.height, image.channels);
    let stride = w * ch;
    let norm = 1.0 / (2 * r + 1) as f64;
    let source_of = |y: isize| edge_row(y, h, wraps_v);
    // Horizontal sweeps of the rows y = start .. start + count (unwrapped, y ≥ −r) into
    // `out`, `count` rows, in groups of BOX_ROWS in parallel.
    let sweep = |data: &[f32], start: isize, out: &mut [f32]| {
        out.par_chunks_mut(BOX_ROWS * stride).enumerate().for_each_init(
            || SweepScratch::new(w, r),
            |scratch, (group, rows)| {
                let first = start + (group * BOX_ROWS) as isize;
                let count = rows.len() / stride;
                let sources: [&[f32]; BOX_ROWS] = std::array::from_fn(|k| {
                    let y = first + k.min(count - 1) as isize;
                    &data[source_of(y) * stride..][..stride]
                });
                box_rows_horizontal(&sources, count, ch, r, scratch, rows);
            },
        );
    };
    // The rows past the end, y = h ..= h + r, swept before any row is overwritten.
    let mut tail = vec![0.0f32; (r + 1) * stride];
    sweep(&image.data, h as isize, &mut tail);
    // The ring holds the swept rows y (slot (y + r) mod ring_rows), made in groups of
    // BOX_ROWS starting at y = −r, so a group's slots are contiguous.
    let ring_rows = box_ring_rows(r);
    let mut ring = vec![0.0f32; ring_rows * stride];
    let slot = |y: isize| (y + r as isize) as usize % ring_rows;
    // Swept rows made so far: y < made.
    let mut made = -(r as isize);
    let last = (h + r) as isize;
    let fill = |data: &[f32], ring: &mut [f32], made: &mut isize, upto: isize| {
        while *made <= upto.min(last) {
            let start = *made;
            // As many whole groups as the ring's end and the rows before the tail allow.
            let room = ring_rows - slot(start);
            let count = (upto.min(last) - start + 1).max(1) as usize;
            let count = count.next_multiple_of(BOX_ROWS).min(room);
            let before_tail = (h as isize - start).max(0) as usize;
            let computed = count.min(before_tail);
            let s = slot(start);
            if computed > 0 {
                sweep(data, start, &mut ring[s * stride..(s + computed) * stride]);
            }
            for k in computed..count {
                let y = start + k as isize;
                if y <= last {
                    let t = (y - h as isize) as usize;
                    ring[(s + k) * stride..(s + k + 1) * stride].copy_from_slice(&tail[t * stride..(t + 1) * stride]);
                }
            }
            *made = start + count as isize;
        }
    };
    struct Block {
        start: usize,
        sum: Vec<f64>,
        /// The block's values for the current band of rows, row-major.
        tile: Vec<f32>,
    }
    let mut blocks: Vec<Block> = (0..stride)
        .step_by(BOX_BLOCK)
        .map(|start| Block { start, sum: vec![0.0; BOX_BLOCK.min(stride - start)], tile: Vec::new() })
        .collect();
    fill(&image.data, &mut ring, &mut made, r as isize);
    {
        let ring = &ring;
        let row_at = |y: isize, start: usize, len: usize| &ring[slot(y) * stride + start..][..len];
        blocks.par_iter_mut().for_each(|b| {
            let len = b.sum.len();
            for y in -(r as isize)..=r as isize {
                for (s, v) in b.sum.iter_mut().zip(row_at(y, b.start, len)) {
                    *s += *v as f64;
                }
            }
            b.tile = vec![0.0; len * BOX_BAND];
        });
    }
    for band in (0..h).step_by(BOX_BAND) {
        let rows = BOX_BAND.min(h - band);
        // The band's window: rows band − r ..= band + rows + r.
        fill(&image.data, &mut ring, &mut made, (band + rows + r) as isize);
        {
            let ring = &ring;
            let row_at = |y: isize, start: usize, len: usize| &ring[slot(y) * stride + start..][..len];
            blocks.par_iter_mut().for_each(|b| {
                let len = b.sum.len();
                for i in 0..rows {
                    let y = (band + i) as isize;
                    for (o, s) in b.tile[i * len..(i + 1) * len].iter_mut().zip(&b.sum) {
                        *o = (*s * norm) as f32;
                    }
                    let (add, sub) = (row_at(y + r as isize + 1, b.start, len), row_at(y - r as isize, b.start, len));
                    for ((s, a), d) in b.sum.iter_mut().zip(add).zip(sub) {
                        *s += *a as f64 - *d as f64;
                    }
                }
            });
        }
        image.data[band * stride..(band + rows) * stride].par_chunks_mut(stride).enumerate().for_each(|(i, row)| {
            for b in &blocks {
                let len = b.sum.len();
                row[b.start..b.start + len].copy_from_slice(&b.tile[i * len..(i + 1) * len]);
            }
        });
    }
}

fn gaussian_blur(input: &Image, sigma_px: f32, wraps_v: bool) -> Image {
    let kernel = gaussian_kernel(sigma_px);
    let radius = (kernel.len() / 2) as isize;
    let (w, h, ch) = (input.width, input.height, input.channels);
    // Horizontal pass over a row padded with its own wrap-around, so the inner loop is a
    // plain dot product over contiguous memory.
    let mut tmp = Image::new(w, h, ch);
    tmp.data.par_chunks_mut(w * ch).enumerate().for_each(|(y, row)| {
        let src = input.row(y);
        let r = radius as usize;
        let padded: Vec<f32> = (0..(w + 2 * r) * ch)
            .map(|i| src[((i / ch) as isize - radius).rem_euclid(w as isize) as usize * ch + i % ch])
            .collect();
        for x in 0..w {
            for c in 0..ch {
                let mut acc = 0.0;
                for (k, weight) in kernel.iter().enumerate() {
                    acc += weight * padded[(x + k) * ch + c];
                }
                row[x * ch + c] = acc;
            }
        }
    });
    // Vertical pass: accumulate whole rows so memory is read sequentially.
    let mut out = Image::new(w, h, ch);
    out.data.par_chunks_mut(w * ch).enumerate().for_each(|(y, row)| {
        for (k, weight) in kernel.iter().enumerate() {
            let sy = edge_row(y as isize + k as isize - radius, h, wraps_v);
            for (o, s) in row.iter_mut().zip(tmp.row(sy)) {
                *o += weight * s;
            }
        }
    });
    out
}

/// Moves a mask towards its value at each pixel's scale centre (channels `centre_u`,
/// `centre_v` of the planar scale field; negative where no scale covers the pixel, which
/// keeps the mask's own value). With `whole` (a coverage mask: a pattern's marks) a scale
/// is the pattern's or not, 1 where the mask is half or more at its centre and 0 where less:
/// the centre's value itself, read where an edge's antialiasing or a distorted edge's soft
/// band crossed the centre, tinted whole scales part-way (`loxocemus-bicolor`'s grey "white
/// scales", a half-tinted scale of `corallus-caninus` showing past its outline). Without it
/// (a solid tint's broad noise) each scale takes the value at its centre.
/// In a strip (`frame`), a centre outside the strip's rows reads its nearest row: the strip's
/// margin (`Op::row_reach`) keeps that out of the rows that are kept.
pub fn snap_to_scales(
    mask: &Image,
    scales: &Image,
    amount: f32,
    centre_u: usize,
    centre_v: usize,
    whole: bool,
    frame: Frame,
) -> Image {
    let full = frame.full_height;
    let (w, h) = (mask.width, mask.height);
    // The mask's own value at a centre's pixel. The centres computed below always lie
    // inside the image (clamped); the fallback keeps `Image::at_wrapped`'s meaning, which
    // the first version read at every pixel, should one ever not.
    let at = |cx: isize, cy: isize| {
        if (0..w as isize).contains(&cx) && (0..h as isize).contains(&cy) {
            mask.data[(cy as usize * w + cx as usize) * mask.channels]
        } else {
            mask.at_wrapped(cx, cy, 0)
        }
    };
    let mut snapped = Image::new(w, h, 1);
    // The field is planar (`Image::plane`).
    let (plane_u, plane_v) = (scales.plane(centre_u), scales.plane(centre_v));
    snapped.data.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (x, out) in row.iter_mut().enumerate() {
            let i = y * w + x;
            let own = mask.data[i * mask.channels];
            let (cu, cv) = (plane_u[i], plane_v[i]);
            *out = if cu < 0.0 {
                own
            } else {
                let cx = ((cu * w as f32) as isize).min(w as isize - 1);
                let cy = if frame.wraps_v {
                    ((cv * full as f32) as isize).min(full as isize - 1)
                } else {
                    // A body atlas: a centre beyond the snout or the tail tip reads the end row.
                    ((cv * full as f32).floor() as isize).clamp(0, full as isize - 1)
                };
                let cy = if frame.height == full {
                    cy
                } else {
                    // Relative to the strip; in a strip over the tile's seam a centre in the
                    // texture's first rows lies below the strip's first (last-texture) rows.
                    let relative = cy - frame.row0 as isize;
                    let relative = if frame.wraps_v && relative < 0 { relative + full as isize } else { relative };
                    relative.clamp(0, frame.height as isize - 1)
                };
                let centre = match at(cx, cy) {
                    v if !whole => v,
                    v if v >= 0.5 => 1.0,
                    _ => 0.0,
                };
                own + (centre - own) * amount
            };
        }
    });
    snapped
}

/// Bilinear resampling of a periodic grid whose sample (i, j) sits at (i / w, j / h), over
/// the rows of `frame` (width `width`): `src` holds the coarse rows `first`, `first + 1`, ...
/// of a grid `coarse_height` rows tall (row k of `src` is coarse row `first + k`, wrapped),
/// as many as the frame's rows interpolate between.
pub fn resample_bilinear_rows(src: &Image, width: usize, frame: Frame, coarse_height: usize, first: usize) -> Image {
    let (sw, ch) = (src.width, src.channels);
    let columns: Vec<(usize, usize, f32)> = (0..width)
        .map(|x| {
            let fx = (x as f32 + 0.5) / width as f32 * sw as f32;
            let x0 = fx.floor();
            let i0 = (x0 as isize).rem_euclid(sw as isize) as usize;
            (i0, (i0 + 1) % sw, fx - x0)
        })
        .collect();
    // The pixels between one pair of coarse columns, (first pixel, end, i0): along such a
    // run both rows' endpoints and differences are the same, so one channel's run is a loop
    // over contiguous weights that the compiler vectorises (the same operations per pixel as
    // the general loop below, so the same values). The variation noise at 2048² (`natrix-
    // natrix`, 512² samples): 21–27 → 9 ms (three runs each).
    let runs = super::image::runs_by(width, |x| columns[x].0);
    let weights: Vec<f32> = columns.iter().map(|c| c.2).collect();
    let mut out = Image::new(width, frame.height, ch);
    out.data.par_chunks_mut(width * ch).enumerate().for_each(|(y, row)| {
        let fy = ((frame.row0 + y) as f32 + 0.5) / frame.full_height as f32 * coarse_height as f32;
        let y0 = fy.floor();
        let k = y0 as usize - first;
        let (r0, r1, ty) = (src.row(k), src.row(k + 1), fy - y0);
        if ch == 1 {
            for &(start, end, i0) in &runs {
                let i1 = columns[start].1;
                let (a0, da) = (r0[i0], r0[i1] - r0[i0]);
                let (b0, db) = (r1[i0], r1[i1] - r1[i0]);
                for (o, &tx) in row[start..end].iter_mut().zip(&weights[start..end]) {
                    let a = a0 + da * tx;
                    let b = b0 + db * tx;
                    *o = a + (b - a) * ty;
                }
            }
            return;
        }
        for (x, &(i0, i1, tx)) in columns.iter().enumerate() {
            for c in 0..ch {
                let a = r0[i0 * ch + c] + (r0[i1 * ch + c] - r0[i0 * ch + c]) * tx;
                let b = r1[i0 * ch + c] + (r1[i1 * ch + c] - r1[i0 * ch + c]) * tx;
                row[x * ch + c] = a + (b - a) * ty;
            }
        }
    });
    out
}

/// Row `y` of an image `h` rows tall, wrapped round (`wraps_v`) or clamped to the nearest
/// row. For `y` within one image of the range, wrapping matches `rem_euclid`.
#[inline]
fn edge_row(y: isize, h: usize, wraps_v: bool) -> usize {
    if wraps_v { y.rem_euclid(h as isize) as usize } else { y.clamp(0, h as isize - 1) as usize }
}

/// Calls `f(centre, left, right, up, here, down, out)` for every pixel: sample offsets of the
/// pixel and its wrapped left and right neighbours within a row (channel 0), the rows above,
/// at and below it (`edge_row`), and the pixel's output (no modulo per sample).
fn neighbourhood<F>(input: &Image, channels_out: usize, wraps_v: bool, f: F) -> Image
where
    F: Fn(usize, usize, usize, &[f32], &[f32], &[f32], &mut [f32]) + Sync,
{
    image_from_rows(input.width, input.height, channels_out, |y, row| {
        neighbourhood_row(input, y, wraps_v, channels_out, &f, row)
    })
}

/// An image whose rows `row` writes (row y into its `width` × `channels` samples), in
/// parallel.
fn image_from_rows(width: usize, height: usize, channels: usize, row: impl Fn(usize, &mut [f32]) + Sync) -> Image {
    let mut out = Image::new(width, height, channels);
    out.data.par_chunks_mut(width * channels).enumerate().for_each(|(y, samples)| row(y, samples));
    out
}

/// Row `y` of `neighbourhood`'s output (`channels_out` samples per pixel) into `row`.
fn neighbourhood_row<F>(input: &Image, y: usize, wraps_v: bool, channels_out: usize, f: &F, row: &mut [f32])
where
    F: Fn(usize, usize, usize, &[f32], &[f32], &[f32], &mut [f32]),
{
    let (w, h, ch) = (input.width, input.height, input.channels);
    let up = input.row(edge_row(y as isize - 1, h, wraps_v));
    let here = input.row(y);
    let down = input.row(edge_row(y as isize + 1, h, wraps_v));
    for (x, px) in row.chunks_exact_mut(channels_out).enumerate() {
        // The columns either side, wrapping round, by comparison: two integer divisions
        // per pixel cost, one thread at 2048² (`epicrates-cenchria`), 19–21 → 14 ms of
        // a Sobel and 33–38 → 31 ms of `height to normal`.
        let left = if x == 0 { w - 1 } else { x - 1 };
        let right = if x + 1 == w { 0 } else { x + 1 };
        f(x * ch, left * ch, right * ch, up, here, down, px);
    }
}

/// Sobel gradient magnitude of channel 0, wrap-around. The result is normalised so that a
/// step edge blurred by a Gaussian of `edge_sigma` (normalised units) peaks at 1: the peak
/// slope of such an edge is 1 / (sqrt(2π) σ) per pixel and Sobel's x kernel weighs the
/// central difference by 4 (so 8 × slope per pixel).
pub fn sobel(input: &Image, edge_sigma: f32, wraps_v: bool) -> Image {
    let sigma_px = (edge_sigma * input.width as f32).max(0.5);
    let norm = (2.0 * std::f32::consts::PI).sqrt() * sigma_px / 8.0;
    neighbourhood(input, 1, wraps_v, |c, l, r, up, here, down, out| {
        let gx = (up[r] + 2.0 * here[r] + down[r]) - (up[l] + 2.0 * here[l] + down[l]);
        let gy = (down[l] + 2.0 * down[c] + down[r]) - (up[l] + 2.0 * up[c] + up[r]);
        out[0] = ((gx * gx + gy * gy).sqrt() * norm).min(1.0);
    })
}

pub use crate::material::NormalConvention;

/// How `height_to_normal` turns heights into normals.
#[derive(Debug, Clone, Copy)]
pub struct NormalSpec {
    /// The surface rise, in texture widths, of the full height range (so the result does
    /// not change with resolution).
    pub slope_per_unit_height: f32,
    pub convention: NormalConvention,
    /// The texture's height in texture widths (1 for the square tile, the body's length for
    /// the body layout); with `full_height`, its rows (a strip's texture's), both axes are
    /// differentiated in the same unit.
    pub v_extent: f32,
    pub full_height: usize,
    /// Whether rows wrap round at the top and bottom (the tile) or repeat their edge.
    pub wraps_v: bool,
}

impl NormalSpec {
    /// The normals of `Op::HeightToNormal { slope, convention, v_extent }` over `frame`.
    pub fn in_frame(slope_per_unit_height: f32, convention: NormalConvention, v_extent: f32, frame: Frame) -> Self {
        NormalSpec {
            slope_per_unit_height,
            convention,
            v_extent,
            full_height: frame.full_height,
            wraps_v: frame.wraps_v,
        }
    }
}

/// Tangent-space normal (unit XYZ in [-1, 1]) from a height map by central differences.
pub fn height_to_normal(height: &Image, spec: NormalSpec) -> Image {
    image_from_rows(height.width, height.height, 3, height_to_normal_rows(height, spec))
}

/// `height_to_normal` a row at a time: a function writing row y of the normal map (three
/// samples per pixel) into its buffer, so a caller that only quantises the normals
/// (`export::quantize_rows`) needs no image of them (at 4096², 192 MiB of f32 written, read
/// back and freed). `height_to_normal` is these rows.
pub fn height_to_normal_rows(height: &Image, spec: NormalSpec) -> impl Fn(usize, &mut [f32]) + Sync + '_ {
    let kernel = NormalKernel::new(height, spec);
    move |y, row| {
        // At the first and last rows of a texture that does not wrap (the body's snout and
        // tail tip) the row beyond is the row itself (`edge_row`): the difference spans one
        // row, not two, and halved it gave half the slope there. (A strip's edge rows inside
        // the texture are its margin, cropped.)
        let ends = !spec.wraps_v && (y == 0 || y + 1 == height.height);
        let along_scale = if ends { 2.0 } else { 1.0 };
        let at = |c, l, r, up: &[f32], here: &[f32], down: &[f32], out: &mut [f32]| {
            kernel.at(here[r] - here[l], (down[c] - up[c]) * along_scale, out)
        };
        neighbourhood_row(height, y, spec.wraps_v, 3, &at, row)
    }
}

/// The per-pixel normal of `height_to_normal`: central differences of the height, scaled
/// to texture widths on both axes.
struct NormalKernel {
    /// Pixels per texture width across (u) and along (v).
    per_width_u: f32,
    per_width_v: f32,
    slope_per_unit_height: f32,
    convention: NormalConvention,
}

impl NormalKernel {
    fn new(height: &Image, spec: NormalSpec) -> Self {
        NormalKernel {
            per_width_u: height.width as f32,
            per_width_v: spec.full_height as f32 / spec.v_extent,
            slope_per_unit_height: spec.slope_per_unit_height,
            convention: spec.convention,
        }
    }

    /// The normal from the height differences across (right − left) and along (down − up)
    /// a pixel.
    #[inline]
    fn at(&self, across: f32, along: f32, out: &mut [f32]) {
        let (w, h, slope) = (self.per_width_u, self.per_width_v, self.slope_per_unit_height);
        // dh/du with u in texture widths: (h[x+1] - h[x-1]) / (2 / w).
        let dhdx = across * 0.5 * w;
        let dhdy = along * 0.5 * h;
        let sx = -dhdx * slope;
        // Image y runs down; OpenGL's +Y (bitangent) points up the image.
        let sy = match self.convention {
            NormalConvention::OpenGl => dhdy * slope,
            NormalConvention::DirectX => -dhdy * slope,
        };
        let len = (sx * sx + sy * sy + 1.0).sqrt();
        out[0] = sx / len;
        out[1] = sy / len;
        out[2] = 1.0 / len;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `resample_bilinear_rows` against bilinear interpolation written out per pixel and
    /// channel (the formula of its general loop), bit for bit: one and three channels,
    /// widths that do and do not divide the coarse grid's, wider and narrower than it, the
    /// whole texture and a strip of it. A run path that read a run's neighbour column or
    /// the wrong weight fails it.
    #[test]
    fn upsampling_by_runs_is_bilinear_per_pixel_bit_for_bit() {
        for (sw, ch) in [(7usize, 1usize), (16, 1), (5, 3), (64, 1)] {
            let coarse_height = 6;
            let src = Image::from_fn(sw, coarse_height + 1, ch, |u, v, out| {
                for (c, o) in out.iter_mut().enumerate() {
                    *o = (u * 13.7 + v * 5.3 + c as f32).sin();
                }
            });
            for width in [3usize, 37, 64, 100] {
                let full_height = 48;
                for (row0, height) in [(0usize, 48usize), (9, 17)] {
                    let frame = Frame { width, height, full_height, row0, wraps_v: true };
                    let first = ((row0 as f32 + 0.5) / full_height as f32 * coarse_height as f32).floor() as usize;
                    let out = resample_bilinear_rows(&src, width, frame, coarse_height, first);
                    for y in 0..height {
                        let fy = ((row0 + y) as f32 + 0.5) / full_height as f32 * coarse_height as f32;
                        let y0 = fy.floor();
                        let (r0, r1, ty) = (src.row(y0 as usize - first), src.row(y0 as usize - first + 1), fy - y0);
                        for x in 0..width {
                            let fx = (x as f32 + 0.5) / width as f32 * sw as f32;
                            let x0 = fx.floor();
                            let i0 = (x0 as isize).rem_euclid(sw as isize) as usize;
                            let (i1, tx) = ((i0 + 1) % sw, fx - x0);
                            for c in 0..ch {
                                let a = r0[i0 * ch + c] + (r0[i1 * ch + c] - r0[i0 * ch + c]) * tx;
                                let b = r1[i0 * ch + c] + (r1[i1 * ch + c] - r1[i0 * ch + c]) * tx;
                                let expected = a + (b - a) * ty;
                                let got = out.data[(y * width + x) * ch + c];
                                assert_eq!(
                                    got.to_bits(),
                                    expected.to_bits(),
                                    "sw {sw} ch {ch} width {width} row0 {row0}: ({x}, {y}, {c})"
                                );
                            }
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn blur_preserves_mean_and_wraps() {
        let img = Image::gray_from_fn(64, 32, |u, _| if u < 0.1 { 1.0 } else { 0.0 });
        let mean = |i: &Image| i.data.iter().sum::<f32>() / i.data.len() as f32;
        let blurred = blur(Cow::Borrowed(&img), 0.05, true);
        assert!((mean(&img) - mean(&blurred)).abs() < 1e-4);
        // The bright band at the left edge bleeds across the seam to the right edge.
        assert!(blurred.data[63] > 0.05);
    }

    #[test]
    fn box_blur_matches_the_gaussian() {
        // A wrapped impulse: the three-box approximation must have the Gaussian's variance
        // and stay close to its shape.
        let mut impulse = Image::new(256, 4, 1);
        for y in 0..4 {
            impulse.data[y * 256] = 1.0;
        }
        for sigma_px in [2.5f32, 6.0, 17.0] {
            let approx = blur(Cow::Borrowed(&impulse), sigma_px / 256.0, true);
            let exact = gaussian_blur(&impulse, sigma_px, true);
            let row = |img: &Image| img.row(2).to_vec();
            let (a, e) = (row(&approx), row(&exact));
            let variance = |r: &[f32]| {
                r.iter()
                    .enumerate()
                    .map(|(x, v)| {
                        let d = if x < 128 { x as f32 } else { x as f32 - 256.0 };
                        d * d * v
                    })
                    .sum::<f32>()
            };
            assert!((variance(&a) / variance(&e) - 1.0).abs() < 0.1, "sigma {sigma_px}");
            let peak = e.iter().cloned().fold(0.0, f32::max);
            let worst = a.iter().zip(&e).map(|(x, y)| (x - y).abs()).fold(0.0, f32::max);
            assert!(worst < 0.12 * peak, "sigma {sigma_px}: {worst} vs peak {peak}");
            assert!((a.iter().sum::<f32>() - 1.0).abs() < 1e-4);
        }
    }

    /// The two sweeps of one box pass written the plain way, as separate passes over whole
    /// images: every row from x = 0, every column from y = 0 with its sum started over rows
    /// −r ..= r (the arithmetic `box_pass` must repeat bit for bit).
    fn box_pass_reference(input: &Image, r: usize, wraps_v: bool) -> Image {
        let (w, h, ch) = (input.width, input.height, input.channels);
        let norm = 1.0 / (2 * r + 1) as f64;
        let at_x = |x: isize| x.rem_euclid(w as isize) as usize;
        let mut across = Image::new(w, h, ch);
        for y in 0..h {
            for c in 0..ch {
                let sample = |x: isize| input.data[(y * w + at_x(x)) * ch + c] as f64;
                let mut sum: f64 = (-(r as isize)..=r as isize).map(sample).sum();
                for x in 0..w {
                    across.data[(y * w + x) * ch + c] = (sum * norm) as f32;
                    sum += sample(x as isize + r as isize + 1) - sample(x as isize - r as isize);
                }
            }
        }
        let mut out = Image::new(w, h, ch);
        for i in 0..w * ch {
            let sample = |y: isize| across.data[edge_row(y, h, wraps_v) * w * ch + i] as f64;
            let mut sum = 0.0f64;
            for y in -(r as isize)..=r as isize {
                sum += sample(y);
            }
            for y in 0..h {
                out.data[y * w * ch + i] = (sum * norm) as f32;
                sum += sample(y as isize + r as isize + 1) - sample(y as isize - r as isize);
            }
        }
        out
    }

    #[test]
    fn fused_box_pass_is_the_two_sweeps_bit_for_bit() {
        // Sizes around the band (64 rows) and block (256 samples) and radii up to more than
        // the height (the rows past the end read again); wrapped and clamped; one and three
        // channels; values of mixed magnitudes (1 and 1e-12, 40 bits apart, so that the f64
        // sums round: at 1e-6 they were exact and a change of order went unseen).
        let mut seed = 1u32;
        let mut next = || {
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (seed >> 8) as f32 / (1u32 << 24) as f32
        };
        for (w, h, ch) in [(300usize, 130usize, 1usize), (40, 7, 3), (257, 64, 1), (16, 200, 3)] {
            let mut image = Image::new(w, h, ch);
            for v in image.data.iter_mut() {
                let x = next();
                *v = if x < 0.3 { x * 1e-12 } else { x };
            }
            for r in [0usize, 1, 5, 20, 70] {
                for wraps_v in [true, false] {
                    let mut fused = image.clone();
                    box_pass(&mut fused, r, wraps_v);
                    let reference = box_pass_reference(&image, r, wraps_v);
                    let same = fused.data.iter().zip(&reference.data).all(|(a, b)| a.to_bits() == b.to_bits());
                    assert!(same, "{w}x{h}x{ch}, r {r}, wraps {wraps_v}");
                }
            }
        }
    }

    #[test]
    fn sobel_of_blurred_step_peaks_near_one() {
        let step = Image::gray_from_fn(256, 8, |u, _| if (0.25..0.75).contains(&u) { 1.0 } else { 0.0 });
        let sigma = 0.02;
        let edges = sobel(&blur(Cow::Borrowed(&step), sigma, true), sigma, true);
        let peak = edges.data.iter().cloned().fold(0.0, f32::max);
        assert!((peak - 1.0).abs() < 0.1, "peak {peak}");
    }

    /// A tile's normals: the slope and convention given, one texture tall, wrapping.
    fn spec(slope_per_unit_height: f32, convention: NormalConvention, full_height: usize) -> NormalSpec {
        NormalSpec { slope_per_unit_height, convention, v_extent: 1.0, full_height, wraps_v: true }
    }

    #[test]
    fn normals_are_unit_and_flat_height_points_up() {
        let flat = Image::new(16, 16, 1);
        let n = height_to_normal(&flat, spec(1.0, NormalConvention::OpenGl, flat.height));
        assert!(n.data.chunks(3).all(|p| p == [0.0, 0.0, 1.0]));
        let ramp = Image::gray_from_fn(32, 32, |u, v| (u * std::f32::consts::TAU).sin() * 0.1 + v * 0.0);
        let n = height_to_normal(&ramp, spec(1.0, NormalConvention::OpenGl, ramp.height));
        for p in n.data.chunks(3) {
            assert!(((p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt() - 1.0).abs() < 1e-5);
        }
    }

    #[test]
    fn a_body_atlas_ends_keep_the_slope_of_a_ramp_along_it() {
        // A linear ramp along v has one slope everywhere; at the ends of a texture that does
        // not wrap (snout and tail tip) the difference is one-sided, and must give it too.
        let ramp = Image::gray_from_fn(8, 16, |_, v| 0.5 * v);
        let along = NormalSpec { wraps_v: false, ..spec(1.0, NormalConvention::OpenGl, ramp.height) };
        let n = height_to_normal(&ramp, along);
        let green = |y: usize| n.data[(y * 8 + 3) * 3 + 1];
        for y in [0, 1, 8, 15] {
            assert!((green(y) - green(7)).abs() < 1e-5, "row {y}: {} against {}", green(y), green(7));
        }
        assert!(green(7) > 0.4, "the ramp is steep: {}", green(7));
    }

    #[test]
    fn opengl_green_points_up_the_image_on_a_slope_rising_down() {
        // Height grows with image y (downwards): the surface faces up the image, +Y in OpenGL.
        let ramp = Image::gray_from_fn(16, 16, |_, v| (v * std::f32::consts::TAU).sin());
        let gl = height_to_normal(&ramp, spec(0.1, NormalConvention::OpenGl, ramp.height));
        let dx = height_to_normal(&ramp, spec(0.1, NormalConvention::DirectX, ramp.height));
        let i = (16 + 3) * 3; // pixel (3, 1): near v = 0 the slope is positive
        assert!(gl.data[i + 1] > 0.0 && dx.data[i + 1] < 0.0);
    }
}
