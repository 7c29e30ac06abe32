//! The colour map's graph (thesis §4.2.1): a base colour with fractal variation, the belly
//! (its colour and an optional checkered plate pattern), pattern layers composed in order —
//! each one or more coverage masks, optionally edge-distorted, snapped to whole scales and
//! outlined — and darker skin between the scales.

use super::Shared;
use crate::graph::{GraphBuilder, NodeId, Op};
use crate::ops::body::AlongProfile;
use crate::ops::filters::BlendMode;
use crate::ops::hash::derive_seed;
use crate::ops::noise::{FractalNoise, NoiseKind};
use crate::ops::scale_colour::{SPECKLES_PER_SCALE, ScaleChannels, ScaleColour};
use crate::ops::scales::{Lattice, channel};
use crate::ops::shapes::{Axis, BellyMarkKind, BellyMarks, BlotchShape, Blotches, SpotGrid};
use crate::preset::Preset;
use crate::preset::schema::{Arrangement, BellyPattern, NoiseChoice, PatternKind, PatternLayer, PatternShape, Srgb8};

pub(super) fn build(g: &mut GraphBuilder, preset: &Preset, s: &Shared) -> NodeId {
    let base = preset.color.base.to_linear();
    let var = preset.color.variation as f32;
    // Without variation both ends of the colour ramp are the base colour, whatever the noise
    // (low + (high − low)·t is low exactly), so the noise is not evaluated.
    let noise = if var == 0.0 {
        g.add("color.no_variation", Op::Constant { value: 0.0 }, &[])
    } else {
        g.add("color.variation_noise", perlin(4, s.along_count(4), 5, 0.55, derive_seed(preset.seed, "color")), &[])
    };
    let mut color = g.add(
        "color.base",
        Op::Colorize { low: base.map(|c| c * (1.0 - var)), high: base.map(|c| c * (1.0 + var)) },
        &[noise],
    );
    if let Some(plan) = &s.body() {
        color = super::body::tail_shift(g, preset, plan, color);
    }

    let b = &preset.belly;
    let mut outside_belly = None;
    if b.width > 0.0 {
        let mask = g.add(
            "belly.mask",
            Op::Bands {
                axis: Axis::U,
                centres: vec![0.0],
                half_width: belly_colour_half_width(preset, s),
                softness: b.blend as f32,
            },
            &[],
        );
        color = match s.body().and_then(|plan| super::body::belly_colour(g, preset, &plan)) {
            Some(along) => g.add("belly.tint", Op::Blend { mode: BlendMode::Mix, opacity: 1.0 }, &[color, along, mask]),
            None => g.add("belly.tint", Op::Tint { color: b.color.to_linear(), opacity: 1.0 }, &[color, mask]),
        };
        let kind = match b.pattern {
            BellyPattern::None => None,
            BellyPattern::Checkered => Some(BellyMarkKind::Checkered),
            BellyPattern::Spots => Some(BellyMarkKind::Spots),
            BellyPattern::HalfMoons => Some(BellyMarkKind::HalfMoons),
            BellyPattern::MedianStripe => Some(BellyMarkKind::MedianStripe),
        };
        if let Some(kind) = kind {
            let marks = BellyMarks {
                kind,
                rows_v: s.lattice.rows_v as u32,
                body: s.body(),
                belly_width: plate_band_width(preset, s),
                amount: b.pattern_amount as f32,
                softness: 0.004,
                seed: derive_seed(preset.seed, "belly"),
            };
            let mask = g.add("belly.marks", Op::BellyMarks(marks), &[]);
            color = g.add(
                "belly.marks_tint",
                Op::Tint { color: b.pattern_color.to_linear(), opacity: 1.0 },
                &[color, mask],
            );
        }
        outside_belly = Some(g.add(
            "belly.outside",
            Op::Levels { in_low: 0.0, in_high: 1.0, out_low: 1.0, out_high: 0.0 },
            &[mask],
        ));
    }

    // One distortion noise for every layer (shared, so it is evaluated once).
    let distorted =
        preset.pattern.iter().any(|l| l.edge_distortion > 0.0 && l.kind != PatternKind::Solid && l.opacity > 0.0);
    let distortion_noise = distorted.then(|| {
        g.add(
            "pattern.distortion_noise",
            perlin(24, s.along_count(24), 3, 0.5, derive_seed(preset.seed, "distortion")),
            &[],
        )
    });
    let context = LayerContext { seed: preset.seed, outside_belly, distortion_noise };
    for (i, layer) in preset.pattern.iter().enumerate() {
        // A layer at opacity 0 leaves every colour as it is (each of its tints adds
        // (colour − below) × 0): none of its nodes is built.
        if layer.opacity > 0.0 {
            color = pattern_layer(g, s, &context, i, layer, color);
        }
    }
    if let Some(plan) = &s.body() {
        color = super::body::marks(g, preset, s, plan, outside_belly, color);
    }

    let per_scale = per_scale(preset, s);
    let reads_field_last = per_scale.is_some();
    if let Some(op) = per_scale {
        color = g.add("color.per_scale", Op::ScaleColour(op), &[color, s.scales]);
    }

    let k = preset.color.between_scales as f32;
    // Where the per-scale colour keeps the scale field alive to the end of the colour chain
    // (every built-in species), the colour extracts its own copy of the crevice channel
    // here rather than share the height and roughness's (`Shared::crevice`), which would
    // stay alive through every colour layer: one more 16 MiB extraction at 2048² takes
    // 64 MiB off the peak at 4096² of most patterned species, enough to evaluate many of
    // them whole instead of in strips. Without it, a late extraction would keep the whole
    // field alive instead.
    let crevice = if reads_field_last { s.channel(g, "color.crevice", channel::CREVICE) } else { s.crevice };
    let shade = g.add(
        "color.scale_shade",
        Op::Levels { in_low: 0.0, in_high: 1.0, out_low: 1.0, out_high: 1.0 - k },
        &[crevice],
    );
    g.add("color.out", Op::Blend { mode: BlendMode::Multiply, opacity: 1.0 }, &[color, shade])
}

/// The ventral band's width: the plates' whole columns (`ops::scales::Lattice`) when the
/// preset draws plates, else `belly.width` as written.
fn plate_band_width(preset: &Preset, s: &Shared) -> f32 {
    if preset.belly.plates { s.lattice.belly_width() } else { preset.belly.width as f32 }
}

/// Half the width of the belly colour's band: the plates, and `belly.up_rows` dorsal rows
/// each side where the belly colour runs up onto the lowest rows.
fn belly_colour_half_width(preset: &Preset, s: &Shared) -> f32 {
    let up = preset.belly.up_rows;
    if !preset.belly.plates || up == 0 {
        return 0.5 * plate_band_width(preset, s);
    }
    let edge = (s.lattice.belly_cols / 2) as usize + up as usize;
    s.lattice.bounds[edge.min(s.lattice.bounds.len() / 2)]
}

/// The per-scale colour of the preset (`ops::scale_colour`), or None when every one of its
/// keys is off (the node is then not in the graph).
fn per_scale(preset: &Preset, s: &Shared) -> Option<ScaleColour> {
    let c = &preset.color;
    // A plane it reads (`per_scale_reads`), or speckle or skin, which read only the crevice.
    let any = per_scale_reads(preset).iter().any(|(_, read)| *read) || c.speckle > 0.0 || c.skin.is_some();
    any.then(|| ScaleColour {
        tone: c.scale_tone as f32,
        hue: c.scale_hue as f32,
        edge: c.edge_tone as f32,
        belly_edge: preset.belly.edge_tone as f32,
        tip: c.tip_tone as f32,
        speckle: c.speckle as f32,
        speckle_color: c.speckle_color.to_linear(),
        skin: c.skin.map(Srgb8::to_linear),
        speckle_cells: s.lattice.cols as u32 * SPECKLES_PER_SCALE,
        speckle_cells_v: s.along_count(s.lattice.cols as u32 * SPECKLES_PER_SCALE),
        seed: derive_seed(preset.seed, "per_scale"),
        channels: {
            let [random, inside, along, row] =
                per_scale_reads(preset).map(|(ch, read)| read.then(|| s.channel_index(ch)));
            ScaleChannels { crevice: s.channel_index(channel::CREVICE), random, inside, along, row }
        },
    })
}

/// The scale-field channels the per-scale colour reads besides the crevice, each with
/// whether its keys are on: the cell's random number (`scale_tone`, `scale_hue`), the
/// distance inside the outline (`edge_tone`, `belly.edge_tone`), the position along the
/// scale (`tip_tone`) and the dorsal row (where the back's and the belly's rims differ), in
/// `ScaleChannels`' order.
fn per_scale_reads(preset: &Preset) -> [(usize, bool); 4] {
    let c = &preset.color;
    let [tone, hue, edge, belly_edge, tip] =
        [c.scale_tone, c.scale_hue, c.edge_tone, preset.belly.edge_tone, c.tip_tone].map(|k| k as f32);
    let [random, inside, along, row] = ScaleColour::reads(tone, hue, edge, belly_edge, tip);
    [(channel::CELL_RANDOM, random), (channel::INSIDE, inside), (channel::ALONG, along), (channel::ROW, row)]
}

/// The scale-field channels the per-scale colour reads, for `scale_outputs`.
pub(super) fn per_scale_channels(preset: &Preset) -> Vec<usize> {
    per_scale_reads(preset).into_iter().filter_map(|(ch, read)| read.then_some(ch)).collect()
}

fn perlin(cells_u: u32, cells_v: u32, octaves: u32, gain: f32, seed: u32) -> Op {
    Op::Noise(FractalNoise { kind: NoiseKind::Perlin, cells_u, cells_v, octaves, gain, seed })
}

fn levels(g: &mut GraphBuilder, name: &str, input: NodeId, lo: f32, hi: f32) -> NodeId {
    g.add(name, Op::Levels { in_low: 0.0, in_high: 1.0, out_low: lo, out_high: hi }, &[input])
}

/// The soft edge of a band (stripes across, rings and a stripe's gaps along), a fraction of
/// the circumference: 2 pixels of a 1024-wide map, so an edge is anti-aliased at the usual
/// sizes and stays a line at 4K (`ops::shapes::bands` widens it to half a pixel where a map
/// is smaller). Along a body atlas, divided by its length (the texture's v is the body's).
const BAND_SOFTNESS: f32 = 0.002;

/// The raw coverage shapes of a layer, each with its colour.
fn shapes(
    g: &mut GraphBuilder,
    s: &Shared,
    layer: &PatternLayer,
    name: &dyn Fn(&str) -> String,
    seed: u32,
) -> Vec<(NodeId, Srgb8)> {
    let size = layer.size as f32;
    match layer.kind {
        PatternKind::Solid => {
            // Full coverage, modulated by broad noise so the tint is not flat.
            let n = g.add(name("noise"), perlin(3, s.along_count(3), 4, 0.5, seed), &[]);
            let amount = layer.amount as f32;
            vec![(levels(g, &name("shape"), n, amount * 0.6, amount), layer.color())]
        }
        PatternKind::Stripes if layer.rows.len() == 2 => {
            // On named scale rows (`Lattice::row_span_u`), mirrored about the spine.
            let (u0, u1) = s.lattice.row_span_u(layer.rows[0] as f32, layer.rows[1] as f32);
            let half_width = 0.5 * (u1 - u0);
            let centres = vec![0.5 * (u0 + u1), 1.0 - 0.5 * (u0 + u1)];
            let op = Op::Bands { axis: Axis::U, centres, half_width, softness: BAND_SOFTNESS };
            vec![(g.add(name("shape"), op, &[]), layer.color())]
        }
        PatternKind::Stripes => {
            // `amount` stripes each side of the dorsal midline (u = 0.5), centre to centre
            // three stripe widths apart; the innermost at `offset` (or a named position).
            let mut centres = Vec::new();
            for d in stripe_distances(layer) {
                centres.push(0.5 + d);
                if d > 0.0 {
                    centres.push(0.5 - d);
                }
            }
            let op = Op::Bands { axis: Axis::U, centres, half_width: size * 0.5, softness: BAND_SOFTNESS };
            vec![(g.add(name("shape"), op, &[]), layer.color())]
        }
        PatternKind::Rings => {
            // A colour sequence repeated `amount` times along the body; widths are
            // fractions of one repeat (default: one ring of `size`, or equal parts).
            let (repeats, span) = series(s, layer);
            let repeats = repeats as f32;
            let span_len = span.1 - span.0;
            let (colors, mut widths) = ring_sequence(layer);
            if let Some(rows) = whole_scale_ring_rows(s, layer) {
                widths = rings_of_whole_scales(&widths, rows.per_repeat, rows.per_band);
            }
            // Start half way into the first colour, so the texture's v seam falls inside a
            // ring rather than on the boundary between two (a counted series starts at the
            // start of the trunk; in whole scales, a quarter row before it, below).
            let mut start = if span == (0.0, 1.0) { -0.5 * widths.first().copied().unwrap_or(0.0) } else { 0.0 };
            if fully_snapped(layer) && s.body().is_none() {
                // In whole scales on the tile, the first colour centred on the row of scales a
                // quarter row before v = 0 (`Lattice::row_centre_v`, about which the lattice
                // is symmetric), so that a sequence symmetric about its colours' centres
                // covers as many plates on both sides, and as many dorsal scales in all (about
                // the centre half a repeat on too, where a repeat is a whole number of rows):
                // a coral snake's two yellow rings, the first colour centred at v = 0 (a
                // quarter row off), covered one plate and two. (Centred between two rows,
                // also symmetric, they covered two plates each where 1.2 rows were asked.)
                // Not on a body atlas, whose plates are counted along the body, off the lattice.
                start += s.lattice.row_centre_v(-1) * repeats;
            }
            let mut out = Vec::new();
            for (k, (color, width)) in colors.into_iter().zip(widths).enumerate() {
                let centres = (0..repeats as usize)
                    .map(|r| span.0 + (r as f32 + start + width * 0.5) / repeats * span_len)
                    .collect();
                let half_width = width * 0.5 / repeats * span_len;
                let op = Op::Bands { axis: Axis::V, centres, half_width, softness: BAND_SOFTNESS / s.field.length };
                out.push((g.add(name(&format!("ring{k}")), op, &[]), color));
                start += width;
            }
            out
        }
        PatternKind::Spots => vec![(g.add(name("shape"), Op::Spots(spot_grid(s, layer, seed)), &[]), layer.color())],
        PatternKind::Blotches => {
            vec![(g.add(name("shape"), Op::Blotches(blotches(s, layer, seed, 1.0)), &[]), layer.color())]
        }
        PatternKind::Irregular => {
            let kind = match layer.noise {
                NoiseChoice::Perlin => NoiseKind::Perlin,
                NoiseChoice::Cellular => NoiseKind::Cellular,
            };
            let cells = (1.0 / size).round().clamp(1.0, 256.0) as u32;
            let noise =
                FractalNoise { kind, cells_u: cells, cells_v: s.along_count(cells), octaves: 3, gain: 0.45, seed };
            let mut n = g.add(name("noise"), Op::Noise(noise), &[]);
            if let Some(plan) = s.body() {
                // On a body atlas the layer starts at the end of the head (`body::layer_region`):
                // the noise faded over one of its cells behind it, to 0 (no patch) or, for a
                // layer covering more than half, to 1 (no hole), closes the minority's patches
                // there with their own edges and outlines, where the region's edge cut them
                // flat across the neck (faded to 0, a layer covering most of the body left a
                // collar of the ground behind the head).
                let cell_v = 1.0 / cells as f32 / s.field.length;
                let covers_most = layer.amount > 0.5;
                let head = if covers_most { 1.0 } else { 0.0 };
                let knots = vec![(plan.head_end, head), (plan.head_end + cell_v, 1.0 - head)];
                let fade = g.add(name("head_fade"), Op::Along(AlongProfile { knots }), &[]);
                n = if covers_most {
                    // 1 − (1 − n)(1 − fade): 1 at the head, n from a cell behind it.
                    g.add(name("faded"), Op::Blend { mode: BlendMode::Screen, opacity: 1.0 }, &[n, fade])
                } else {
                    super::masked(g, name("faded"), n, Some(fade))
                };
            }
            // Higher amount, lower threshold, more coverage; fBm sits mostly in [0.3, 0.7].
            let level = 0.7 - 0.4 * layer.amount as f32;
            let binary = g.add(name("threshold"), Op::Threshold { level, softness: 0.01 }, &[n]);
            vec![(g.add(name("shape"), Op::Blur { sigma: size * 0.04 }, &[binary]), layer.color())]
        }
    }
}

/// Scale lengths along the body from one gap of a broken stripe to the next, on average (a
/// visual choice: no source found gives how often a broken stripe breaks).
const STRIPE_GAP_EVERY_SCALES: f32 = 3.0;

/// A stripe layer's mask with `broken` of its length left out: one gap about every
/// `STRIPE_GAP_EVERY_SCALES` scale lengths, each `broken` of the spacing long, the same gaps
/// in every stripe of the layer (both sides of a pair of stripes break together).
fn broken_stripes(
    g: &mut GraphBuilder,
    s: &Shared,
    layer: &PatternLayer,
    name: &dyn Fn(&str) -> String,
    seed: u32,
    stripes: NodeId,
) -> NodeId {
    let count = ((s.lattice.rows_v as f32 / STRIPE_GAP_EVERY_SCALES).round() as i32).max(1);
    // Moved by up to a quarter of the stretch between gaps, two neighbours never overlap
    // (they stay 1 − (1 − broken) / 2 of a spacing apart, more than a gap's length), so
    // exactly `broken` of the length is left out.
    let jitter = 0.25 * (1.0 - layer.broken as f32);
    let centres = (0..count)
        .map(|k| (k as f32 + 0.5 + jitter * crate::ops::hash::signed(k, 0, 0, seed)) / count as f32)
        .collect();
    let half_width = 0.5 * layer.broken as f32 / count as f32;
    let op = Op::Bands { axis: Axis::V, centres, half_width, softness: BAND_SOFTNESS / s.field.length };
    let gaps = g.add(name("gaps"), op, &[]);
    let kept = levels(g, &name("between_gaps"), gaps, 1.0, 0.0);
    super::masked(g, name("broken"), stripes, Some(kept))
}

/// The blotch series of a `blotches` layer, every blotch scaled by `scale` (a composite
/// mark's centre is the same series drawn smaller).
fn blotches(s: &Shared, layer: &PatternLayer, seed: u32, scale: f32) -> Blotches {
    let shape = match layer.shape {
        PatternShape::Diamond => BlotchShape::Diamond,
        PatternShape::Saddle => BlotchShape::Saddle,
        PatternShape::Chevron => BlotchShape::Chevron,
        PatternShape::Hourglass => BlotchShape::Hourglass,
        PatternShape::Zigzag => BlotchShape::Zigzag,
        PatternShape::Round | PatternShape::Ring => BlotchShape::Round,
    };
    let (count, span) = series(s, layer);
    // Widening along a counted body series only: the tile has no tail to widen toward.
    let widen = if s.body().is_some() && layer.series_count().is_some() { layer.widen_to_tail as f32 } else { 1.0 };
    Blotches {
        shape,
        count,
        span,
        widen,
        half_width: layer.size as f32,
        length: layer.length as f32,
        jitter: 0.3,
        offset: layer.offset as f32,
        staggered: layer.arrangement == Arrangement::Alternating,
        phase: layer.phase as f32,
        scale,
        seed,
    }
}

/// A `spots` layer's columns on each side or round the body (`amount`), the band of scale
/// rows they lie on (`rows`, `Lattice::row_span_u`, as a stripe's; none: round the body), and
/// its spots per circumference along the body: rows of spots lie as far apart as the columns
/// across, `across` over the band's width (at most 4096). The loader bounds the spots'
/// radius by this spacing (`validate`), so the two cannot disagree.
pub fn spot_spacing(lattice: &Lattice, layer: &PatternLayer) -> (u32, Option<(f32, f32)>, u32) {
    let across = layer.amount.round().max(1.0) as u32;
    let band = (layer.rows.len() == 2).then(|| lattice.row_span_u(layer.rows[0] as f32, layer.rows[1] as f32));
    let per_circumference = match band {
        Some((u0, u1)) => ((across as f32 / (u1 - u0).max(1e-3)).round() as u32).clamp(1, 4096),
        None => across,
    };
    (across, band, per_circumference)
}

/// The spot grid of a `spots` layer.
fn spot_grid(s: &Shared, layer: &PatternLayer, seed: u32) -> SpotGrid {
    let (across, band, per_circumference) = spot_spacing(&s.lattice, layer);
    // On a body atlas, rows from the end of the head, where the layer's region starts
    // (`body::layer_region`), so that the first row's spots are whole, as a blotch series'
    // first blotch (`series`; spread over the whole length, the head's edge cut the first
    // row of `epicrates-cenchria`'s ocelli in half, an independent review found).
    let (along, span) =
        s.behind_head_count(per_circumference).unwrap_or_else(|| (s.along_count(per_circumference), (0.0, 1.0)));
    SpotGrid {
        across,
        along,
        radius: layer.size as f32,
        jitter: 0.35,
        alternate: layer.arrangement == Arrangement::Alternating,
        checkered: layer.arrangement == Arrangement::Checkered,
        hole: if layer.shape == PatternShape::Ring { 0.55 } else { 0.0 },
        seed,
        band,
        span,
    }
}

/// The centre of a composite mark: the layer's blotches or spots drawn at `center_size`
/// of their size about their own centres (None for other kinds or without `center_color`).
fn centre_shape(s: &Shared, layer: &PatternLayer, seed: u32) -> Option<Op> {
    layer.center_color?;
    let k = layer.center_size as f32;
    match layer.kind {
        PatternKind::Blotches => Some(Op::Blotches(blotches(s, layer, seed, k))),
        PatternKind::Spots => {
            let grid = spot_grid(s, layer, seed);
            Some(Op::Spots(SpotGrid { radius: grid.radius * k, ..grid }))
        }
        _ => None,
    }
}

/// How many marks (blotches, or repeats of a ring sequence) a layer draws over the
/// texture, and the stretch of v (fractions) they are spread over: `amount` per tile over
/// the tile; on the body, `count` over the trunk (neck to vent) where the preset counts
/// them — continued down the tail at the same spacing unless the tail has bands of its own
/// (`body.tail_bands`) — else `amount` per circumference: blotches from the end of the head,
/// where the layer's region starts (`body::layer_region`), to the tail's tip, so that the
/// first is whole (spread over the whole length, the series was cut by the head's edge: a
/// half blotch with a flat, unoutlined end behind the head of `python-regius`, an independent
/// review found); rings over the whole length, a band the head's edge cuts being still a
/// band (started at the head's end, a coral snake's first black ring met its red head).
fn series(s: &Shared, layer: &PatternLayer) -> (u32, (f32, f32)) {
    let amount = layer.amount.round().max(1.0) as u32;
    match (s.body(), layer.series_count()) {
        (Some(plan), Some(count)) => {
            let count = count.max(1);
            if s.tail_bands > 0 {
                // A tail with bands of its own: the series ends at the vent.
                return (count, (plan.neck_end, plan.vent));
            }
            // Otherwise the series runs on down the tail at the trunk's spacing.
            let spacing = (plan.vent - plan.neck_end) / count as f32;
            let on_tail = ((1.0 - plan.vent) / spacing).floor() as u32;
            (count + on_tail, (plan.neck_end, plan.neck_end + (count + on_tail) as f32 * spacing))
        }
        (_, None) if layer.kind == PatternKind::Blotches => {
            s.behind_head_count(amount).unwrap_or_else(|| (s.along_count(amount), (0.0, 1.0)))
        }
        _ => (s.along_count(amount), (0.0, 1.0)),
    }
}

/// How far each stripe of a stripes layer (not placed by `rows`) lies from the spine, one
/// side, fractions of the circumference: `amount` (rounded) stripes three widths (`size`)
/// apart from `offset` (or its named `position`) out. What the generator draws and
/// validation checks (a stripe past the belly's midline wraps onto the other side's:
/// `preset::validate`), from the layer's keys, so the two read them alike.
pub fn stripe_distances(layer: &PatternLayer) -> impl Iterator<Item = f32> {
    let offset = layer.position.map_or(layer.offset, |p| p.offset()) as f32;
    let size = layer.size as f32;
    (0..layer.amount.round() as u32).map(move |k| offset + k as f32 * size * 3.0)
}

/// A layer snapped fully to whole scales (each scale takes the pattern at its centre).
fn fully_snapped(layer: &PatternLayer) -> bool {
    layer.scale_aligned >= 1.0
}

/// A ring layer's colour sequence and each colour's width, fractions of one repeat (one ring
/// of `size` without `colors`; equal parts without `widths`).
fn ring_sequence(layer: &PatternLayer) -> (Vec<Srgb8>, Vec<f32>) {
    if layer.colors.is_empty() {
        (vec![layer.color()], vec![(layer.size as f32).min(1.0)])
    } else if layer.widths.is_empty() {
        let n = layer.colors.len();
        (layer.colors.clone(), vec![1.0 / n as f32; n])
    } else {
        (layer.colors.clone(), layer.widths.iter().map(|w| *w as f32).collect())
    }
}

/// A ring sequence drawn in whole scales, in scale rows along the body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WholeScaleRingRows {
    /// Rows in one repeat of the sequence.
    pub per_repeat: f32,
    /// Rows every band needs at least (`rings_of_whole_scales`: `ScaleField::apart_cells`).
    pub per_band: f32,
    /// Its bands: the colours, and the gap the sequence leaves in its repeat, if any.
    pub bands: usize,
    /// Whether one of `bands` is that gap.
    pub gap: bool,
    /// Rows of the stretch its repeats share: the whole texture, or a counted series' trunk.
    pub stretch: f32,
}

impl WholeScaleRingRows {
    /// Whether every band can be as long as it needs (else the bands keep equal shares and
    /// the rings neither stay closed nor keep apart: `rings_of_whole_scales`).
    pub fn fits(&self) -> bool {
        bands_fit(self.bands, self.per_repeat, self.per_band)
    }

    /// The most repeats over `stretch` at which every band fits (`bands_fit`, so a count
    /// the warning names is one it does not warn of).
    pub fn most_repeats(&self) -> u32 {
        let fit = |n: u32| n == 0 || bands_fit(self.bands, self.stretch / n as f32, self.per_band);
        let mut n = (self.stretch / (self.bands as f32 * self.per_band)).floor().max(0.0) as u32;
        while !fit(n) {
            n -= 1;
        }
        while fit(n + 1) {
            n += 1;
        }
        n
    }
}

/// For a ring layer drawn in whole scales (`scale_aligned` 1), its rows (None for any other
/// layer): what `rings_of_whole_scales` is given, and what the loader's warning checks
/// (`ring_layers_that_do_not_fit`).
fn whole_scale_ring_rows(s: &Shared, layer: &PatternLayer) -> Option<WholeScaleRingRows> {
    if layer.kind != PatternKind::Rings || !fully_snapped(layer) {
        return None;
    }
    let (repeats, span) = series(s, layer);
    let rows = s.lattice.rows_v as f32;
    let widths = ring_sequence(layer).1;
    let gap = gap_band(widths.iter().sum()).is_some();
    // A counted series: its count over the trunk (it runs on down the tail at that spacing).
    let stretch = match (s.body(), layer.series_count()) {
        (Some(plan), Some(_)) => rows * (plan.vent - plan.neck_end),
        _ => rows * (span.1 - span.0),
    };
    Some(WholeScaleRingRows {
        per_repeat: rows * (span.1 - span.0) / repeats as f32,
        per_band: s.field.apart_cells(&s.lattice),
        bands: widths.len() + usize::from(gap),
        gap,
        stretch,
    })
}

/// The ring layers of `preset` drawn in whole scales whose bands do not fit their repeat
/// (`WholeScaleRingRows::fits`): on the tile, by `amount`; on the body atlas, by `count`, or
/// by `amount` where the layer has no count (checked for every preset, as the body's keys
/// are range-checked on the tile too). An uncounted layer repeats `amount` times a
/// circumference on both, but the body rounds its repeats and its scale rows over the whole
/// length each on its own (`Shared::along_count`), so a layer that fits the tile can be a few
/// rows short on the body (a review); warned of once, on the tile, where both fall short.
/// Each with its layer's index and the layout.
pub fn ring_layers_that_do_not_fit(preset: &Preset) -> Vec<(usize, super::Layout, WholeScaleRingRows)> {
    let mut found: Vec<(usize, super::Layout, WholeScaleRingRows)> = Vec::new();
    let rings_in_whole_scales = preset.pattern.iter().any(|l| l.kind == PatternKind::Rings && fully_snapped(l));
    if !rings_in_whole_scales {
        return found;
    }
    for layout in [super::Layout::Tile, super::Layout::Body] {
        let s = Shared::new(&mut GraphBuilder::new(), preset, layout);
        for (i, layer) in preset.pattern.iter().enumerate() {
            let uncounted_and_warned = layer.series_count().is_none() && found.iter().any(|(j, ..)| *j == i);
            if uncounted_and_warned {
                continue;
            }
            if let Some(rows) = whole_scale_ring_rows(&s, layer).filter(|rows| !rows.fits()) {
                found.push((i, layout, rows));
            }
        }
    }
    found
}

/// Whether `bands` bands of at least `floor_cells` scale rows each fit a repeat of
/// `cells_per_repeat` rows (a ten-thousandth over is taken as fitting: rounding). The one
/// test of it: `rings_of_whole_scales` keeps equal shares where it fails, and the loader
/// warns (`WholeScaleRingRows::fits`).
fn bands_fit(bands: usize, cells_per_repeat: f32, floor_cells: f32) -> bool {
    bands as f32 * floor_cells <= cells_per_repeat.max(1e-3) * (1.0 + 1e-4)
}

/// The uncoloured rest of a ring sequence's repeat, whose colours take `drawn` of it: a band
/// too, which separates repeats (none where the colours fill the repeat, to a millionth).
fn gap_band(drawn: f32) -> Option<f32> {
    let gap = (1.0 - drawn).max(0.0);
    (gap > 1e-6).then_some(gap)
}

/// Ring widths (fractions of one repeat) for a ring sequence drawn in whole scales, so that
/// its topology survives the snapping (each scale takes the colour at its centre). Every
/// band — and the gap the sequence leaves in its repeat, if any — is made at least
/// `reach + j` cells long, with j the scale jitter (a centre moves by at most j / 2 of a
/// cell along the body, `ops::scales::CellTable`) and `reach` the longest a scale reaches
/// along the body (`ScaleField::longest_reach_cells`, at least one cell):
/// - at least 1 + j: the centres of each scale column are one cell apart, so the band holds
///   a centre in every column, and a one-scale ring stays closed round the body (in zigzag,
///   the columns being staggered by half a cell);
/// - at least reach + j: the scales either side of the band have centres further apart
///   along the body than two outlines reach, so they never touch.
///
/// The wider bands give up the difference in proportion, as long as they stay above the
/// floor themselves (a band the giving takes below it is held there too, and the rest give
/// again: one pass left a band of 0.3 at 0.21 beside one of 0.0001); a sequence too tight
/// for it keeps equal shares (and the loader warns of it: `ring_layers_that_do_not_fit`).
/// `cells_per_repeat` = scale rows along the body per repeat. (Measured: with the
/// outline's length alone, no rotation, red met black at 2048² with jitter 0.3.)
pub fn rings_of_whole_scales(widths: &[f32], cells_per_repeat: f32, floor_cells: f32) -> Vec<f32> {
    let floor = floor_cells / cells_per_repeat.max(1e-3);
    let mut all = widths.to_vec();
    all.extend(gap_band(widths.iter().sum()));
    // The bands held at the floor, first those narrower than it; then any the others'
    // giving takes below it, until none is (at most once per band).
    let mut held: Vec<bool> = all.iter().map(|w| *w < floor).collect();
    if !held.contains(&true) {
        return widths.to_vec();
    }
    if !bands_fit(all.len(), cells_per_repeat, floor_cells) {
        return vec![1.0 / all.len() as f32; widths.len()];
    }
    loop {
        // Summed as it always was (one floor per band), so widths that one pass settles
        // keep their bytes.
        let narrow: f32 = held.iter().filter(|h| **h).map(|_| floor).sum();
        let wide: f32 = all.iter().zip(&held).filter(|(_, h)| !**h).map(|(w, _)| w).sum();
        if narrow >= 1.0 || wide <= 0.0 {
            return vec![1.0 / all.len() as f32; widths.len()];
        }
        let scale = (1.0 - narrow) / wide;
        let below: Vec<usize> = (0..all.len()).filter(|&k| !held[k] && all[k] * scale < floor).collect();
        if below.is_empty() {
            let widened = all.iter().zip(&held).map(|(w, h)| if *h { floor } else { w * scale });
            return widened.take(widths.len()).collect();
        }
        for k in below {
            held[k] = true;
        }
    }
}

/// What every pattern layer shares.
#[derive(Clone, Copy)]
struct LayerContext {
    /// The preset's seed.
    seed: u64,
    /// 1 off the belly band (None without a belly).
    outside_belly: Option<NodeId>,
    /// The shared edge-distortion noise (None when no layer distorts).
    distortion_noise: Option<NodeId>,
}

/// Adds one pattern layer over `below`; returns the new colour node.
fn pattern_layer(
    g: &mut GraphBuilder,
    s: &Shared,
    context: &LayerContext,
    i: usize,
    layer: &PatternLayer,
    below: NodeId,
) -> NodeId {
    let LayerContext { distortion_noise, .. } = *context;
    let prefix = format!("pattern{i}");
    let seed = derive_seed(context.seed, &prefix);
    let mut color = below;
    let parts = shapes(g, s, layer, &|part: &str| format!("{prefix}.{part}"), seed);
    let many = parts.len() > 1;
    let mut last_mask = None;
    // On a body atlas, where along the body the layer lies: a counted series from the end of
    // the neck, every other layer from the end of the head (the head has its own marks). The
    // region clips what is painted — the mark, its border, outline and centre — not the
    // shapes they are derived from, so a mark cut by a region edge gets no outline along it.
    let region = s.body().map(|plan| {
        let profile = super::body::layer_region(&plan, layer.series_count().is_some(), s.tail_bands > 0);
        g.add(format!("{prefix}.region"), Op::Along(profile), &[])
    });
    let clip = |g: &mut GraphBuilder, name: String, mask: NodeId| super::masked(g, name, mask, region);
    for (k, (shape, tint)) in parts.into_iter().enumerate() {
        let name = |part: &str| if many { format!("{prefix}.{k}.{part}") } else { format!("{prefix}.{part}") };
        let mut mask = shape;
        // A ring sequence in whole scales keeps its topology (`rings_of_whole_scales`) only
        // with straight band edges: no distortion there.
        let distort = layer.edge_distortion > 0.0
            && layer.kind != PatternKind::Solid
            && !(layer.kind == PatternKind::Rings && fully_snapped(layer));
        if let (true, Some(n)) = (distort, distortion_noise) {
            // Thesis §4.2.1.2: blend with noise, then threshold, for ragged edges. The shape is
            // softened first so that adding noise moves its edges instead of leaving them.
            let d = layer.edge_distortion as f32;
            let soft = g.add(name("soften"), Op::Blur { sigma: 0.002 + 0.01 * d }, &[mask]);
            let offset = levels(g, &name("distortion"), n, -d * 0.5, d * 0.5);
            let moved = g.add(name("distorted"), Op::Blend { mode: BlendMode::Add, opacity: 1.0 }, &[soft, offset]);
            mask = g.add(name("mask"), Op::Threshold { level: 0.5, softness: 0.04 }, &[moved]);
        }
        if layer.kind == PatternKind::Stripes && layer.broken > 0.0 {
            // After the edges' distortion, which ate short pieces whole, and before the
            // snapping, so that the gaps end on scale edges too.
            mask = broken_stripes(g, s, layer, &name, seed, mask);
        }
        // Snapped part-way (0 < scale_aligned < 1), a scale astride the mark's own edge is
        // tinted part-way on both sides of it: by `scale_aligned` outside the mark where the
        // scale's centre lies inside, by 1 − `scale_aligned` inside where it lies outside. An
        // outline traced on that mask ran through the half-tinted scales, which showed
        // beyond it (`lampropeltis-triangulum`'s saddles); one traced round every tinted
        // scale merged marks that nearly touch (`crotalus-atrox`'s diamonds, tip to tip). So
        // the outline traces the mark's own shape, and the tint is kept within the outline's
        // outer edge: the shape blurred as the outline's is and thresholded where a blurred
        // edge falls to 0.1, 1.28 σ outside it, under the outline (`tests/marks.rs` checks
        // that no tint shows past it).
        let outline_sigma = layer.outline_size as f32 * 0.5;
        let part_way = layer.scale_aligned > 0.0 && layer.scale_aligned < 1.0;
        let own_outline_blur = (layer.outline_size > 0.0 && part_way).then(|| {
            let own = off_belly(g, context, layer, name("own_off_belly"), mask);
            g.add(name("outline_blur"), Op::Blur { sigma: outline_sigma }, &[own])
        });
        mask = snapped_and_off_belly(g, s, context, layer, &name, mask);
        if let Some(soft) = own_outline_blur {
            let within = g.add(name("within_outline"), Op::Threshold { level: 0.1, softness: 0.05 }, &[soft]);
            mask = super::masked(g, name("tint_within_outline"), mask, Some(within));
        }
        if let Some(border_color) = layer.border_color.filter(|_| layer.border_size > 0.0) {
            // A pale border round the mark and its outline: the mask dilated by blurring
            // and a low threshold (a blurred edge falls to 0.1 at 1.28 σ outside it).
            let reach = (layer.border_size + 0.5 * layer.outline_size) as f32;
            let soft = g.add(name("border_blur"), Op::Blur { sigma: reach / 1.28 }, &[mask]);
            let mut border = g.add(name("border"), Op::Threshold { level: 0.1, softness: 0.05 }, &[soft]);
            border = snapped_and_off_belly(g, s, context, layer, &|p| name(&format!("border_{p}")), border);
            border = clip(g, name("border_in_region"), border);
            color = g.add(
                name("border_tint"),
                Op::Tint { color: border_color.to_linear(), opacity: layer.opacity as f32 },
                &[color, border],
            );
        }
        let painted = clip(g, name("in_region"), mask);
        color =
            g.add(name("tint"), Op::Tint { color: tint.to_linear(), opacity: layer.opacity as f32 }, &[color, painted]);
        last_mask = Some(mask);
        if layer.outline_size > 0.0 {
            // Thesis §4.2.1.6: edge detection, blur and binarise, then colour the outline.
            let soft = own_outline_blur
                .unwrap_or_else(|| g.add(name("outline_blur"), Op::Blur { sigma: outline_sigma }, &[mask]));
            let edges = g.add(name("outline_edges"), Op::Sobel { edge_sigma: outline_sigma }, &[soft]);
            let mut outline = g.add(name("outline"), Op::Threshold { level: 0.35, softness: 0.1 }, &[edges]);
            outline = clip(g, name("outline_in_region"), outline);
            color = g.add(
                name("outline_tint"),
                Op::Tint { color: layer.outline_color.to_linear(), opacity: layer.opacity as f32 },
                &[color, outline],
            );
        }
    }
    if let (Some(centre_color), Some(op), Some(mark)) = (layer.center_color, centre_shape(s, layer, seed), last_mask) {
        // The composite mark's centre, over the mark and its outline, and never outside the
        // mark (a chevron or zigzag scaled about its centre moves its arms sideways).
        let mut centre = g.add(format!("{prefix}.centre"), op, &[]);
        centre = snapped_and_off_belly(g, s, context, layer, &|p| format!("{prefix}.centre_{p}"), centre);
        centre = g.add(
            format!("{prefix}.centre_in_mark"),
            Op::Blend { mode: BlendMode::Multiply, opacity: 1.0 },
            &[centre, mark],
        );
        centre = clip(g, format!("{prefix}.centre_in_region"), centre);
        color = g.add(
            format!("{prefix}.centre_tint"),
            Op::Tint { color: centre_color.to_linear(), opacity: layer.opacity as f32 },
            &[color, centre],
        );
    }
    color
}

/// A mask of the layer (the mark's own, or a composite mark's centre or border) snapped to
/// whole scales as far as `scale_aligned` says, and kept off the belly unless `over_belly`;
/// `name(part)` names the nodes.
fn snapped_and_off_belly(
    g: &mut GraphBuilder,
    s: &Shared,
    context: &LayerContext,
    layer: &PatternLayer,
    name: &dyn Fn(&str) -> String,
    mut mask: NodeId,
) -> NodeId {
    if layer.scale_aligned > 0.0 {
        // A solid tint's mask is broad noise, not a coverage: each scale takes its value.
        let whole = layer.kind != PatternKind::Solid;
        mask = s.snap(g, name("scale_aligned"), mask, layer.scale_aligned as f32, whole);
    }
    off_belly(g, context, layer, name("off_belly"), mask)
}

/// `mask` kept off the belly unless the layer lies `over_belly`.
fn off_belly(g: &mut GraphBuilder, context: &LayerContext, layer: &PatternLayer, name: String, mask: NodeId) -> NodeId {
    let outside = context.outside_belly.filter(|_| !layer.over_belly);
    super::masked(g, name, mask, outside)
}
