//! The body layout's own colour nodes (`generate --layout body`): the ground shifting to
//! the tail's colour, the belly's colours along it, bands round the tail, a coloured tail tip
//! and the head's marks.
//! Everything else — scales, counted plates, the pattern layers — comes from the same
//! builders as the tile, with counts along the body (`Shared::along_count`, `series`).

use super::Shared;
use crate::graph::{GraphBuilder, NodeId, Op};
use crate::ops::body::{AlongProfile, BodyPlan, HeadMark, HeadMarkShape};
use crate::preset::Preset;
use crate::preset::schema::{HeadMark as HeadMarkSchema, HeadMarkKind};

/// About two pixels of a 1024-wide atlas twelve widths long, in v: the soft edge of region
/// boundaries (an edge that is not anti-aliased reads as a seam).
const EDGE_V: f32 = 1.6e-4;

/// Where a pattern layer lies along the body: a counted series from the end of the neck
/// (to the vent when the tail has bands of its own, `ends_at_vent`), any other layer from
/// the end of the head to the tip.
pub(super) fn layer_region(plan: &BodyPlan, counted: bool, ends_at_vent: bool) -> AlongProfile {
    if counted && !ends_at_vent {
        AlongProfile { knots: vec![(plan.neck_end - EDGE_V, 0.0), (plan.neck_end, 1.0)] }
    } else if counted {
        AlongProfile {
            knots: vec![
                (plan.neck_end - EDGE_V, 0.0),
                (plan.neck_end, 1.0),
                (plan.vent, 1.0),
                (plan.vent + EDGE_V, 0.0),
            ],
        }
    } else {
        AlongProfile { knots: vec![(plan.head_end, 0.0), (plan.head_end + EDGE_V, 1.0)] }
    }
}

/// The ground colour shifting to `body.tail_color` from `tail_shift_start` of the trunk to
/// the vent, and that colour over the whole tail (before the belly and the pattern layers,
/// which keep their own colours).
pub(super) fn tail_shift(g: &mut GraphBuilder, preset: &Preset, plan: &BodyPlan, color: NodeId) -> NodeId {
    let Some(tail) = preset.body.tail_color else { return color };
    let start = plan.neck_end + (plan.vent - plan.neck_end) * preset.body.tail_shift_start as f32;
    let knots = if start >= plan.vent {
        vec![(plan.vent, 0.0), (plan.vent + EDGE_V, 1.0)]
    } else {
        vec![(start, 0.0), (plan.vent, 1.0)]
    };
    let ramp = g.add("body.tail_shift", Op::Along(AlongProfile { knots }), &[]);
    g.add("body.tail_color", Op::Tint { color: tail.to_linear(), opacity: 1.0 }, &[color, ramp])
}

/// The share of the ventral plates' span over which the belly's front colour fades into
/// `belly.color`, centred on `belly_front_end` and kept within the span (half of it at the
/// span's ends). The sources that give a front colour (liasis-mackloti: "Anterior third of
/// the venter is yellow, the rest of the venter is greyish white") do not say how sharp the
/// change is, so it is soft: a tenth of the span (about one circumference long on a snake of
/// the default proportions).
const BELLY_FRONT_FADE: f32 = 0.1;

/// The belly's colour along the body where `[body]` changes it (none where it does not): the
/// belly colour, the front colour (`body.belly_front_color`) from the snout to
/// `belly_front_end` of the ventral plates' span, fading into it over `BELLY_FRONT_FADE` of
/// that span, and the subcaudals' colour (`body.subcaudal_color`) from the vent to the tip.
/// The belly band mixes this in where a constant would be tinted: each colour tinted over
/// the band in turn left a thin line of the colour below along the band's soft edges.
pub(super) fn belly_colour(g: &mut GraphBuilder, preset: &Preset, plan: &BodyPlan) -> Option<NodeId> {
    let b = &preset.body;
    if b.belly_front_color.is_none() && b.subcaudal_color.is_none() {
        return None;
    }
    let zero = g.add("body.belly_colour_ground", Op::Constant { value: 0.0 }, &[]);
    let belly = preset.belly.color.to_linear();
    let mut colour = g.add("body.belly_colour", Op::Colorize { low: belly, high: belly }, &[zero]);
    let mut tint = |g: &mut GraphBuilder, name: &str, tint: crate::preset::schema::Srgb8, knots| {
        let along = g.add(format!("body.{name}"), Op::Along(AlongProfile { knots }), &[]);
        colour =
            g.add(format!("body.{name}_tint"), Op::Tint { color: tint.to_linear(), opacity: 1.0 }, &[colour, along]);
    };
    if let Some(front) = b.belly_front_color {
        let span = plan.vent - plan.head_end;
        let end = plan.head_end + span * b.belly_front_end as f32;
        let half = 0.5 * BELLY_FRONT_FADE * span;
        // The fade kept to the ventral plates: centred on an end at the head or the vent, it
        // left the chin half the front colour or ran onto the tail's underside (a review).
        let (from, to) = ((end - half).max(plan.head_end), (end + half).min(plan.vent));
        tint(g, "belly_front", front, vec![(from, 1.0), (to, 0.0)]);
    }
    if let Some(under_tail) = b.subcaudal_color {
        tint(g, "subcaudals", under_tail, vec![(plan.vent, 0.0), (plan.vent + EDGE_V, 1.0)]);
    }
    Some(colour)
}

/// Tail bands, the tail tip and head marks over the pattern layers.
pub(super) fn marks(
    g: &mut GraphBuilder,
    preset: &Preset,
    s: &Shared,
    plan: &BodyPlan,
    outside_belly: Option<NodeId>,
    mut color: NodeId,
) -> NodeId {
    let b = &preset.body;
    let snap = preset.pattern.iter().map(|l| l.scale_aligned).fold(0.0f64, f64::max);
    if b.tail_bands > 0 {
        // `tail_bands` dark bands spread evenly from the vent to the tip, each
        // `tail_band_width` of its repeat, centred in it, off the subcaudals unless
        // `tail_band_over_belly`.
        let n = b.tail_bands as f32;
        let repeat = (1.0 - plan.vent) / n;
        let half = 0.5 * b.tail_band_width as f32 * repeat;
        // The edge within a quarter of the band and of the gap, so the knots stay in order.
        let edge = EDGE_V.min(0.25 * half).min(0.25 * (0.5 * repeat - half));
        let mut knots = Vec::new();
        for i in 0..b.tail_bands {
            let centre = plan.vent + (i as f32 + 0.5) * repeat;
            knots.extend([
                (centre - half - edge, 0.0),
                (centre - half, 1.0),
                (centre + half, 1.0),
                (centre + half + edge, 0.0),
            ]);
        }
        let mut mask = g.add("body.tail_bands", Op::Along(AlongProfile { knots }), &[]);
        if snap > 0.0 {
            mask = s.snap(g, "body.tail_bands_aligned".into(), mask, snap as f32, true);
        }
        if !b.tail_band_over_belly {
            mask = super::masked(g, "body.tail_bands_off_belly".into(), mask, outside_belly);
        }
        color = g.add(
            "body.tail_bands_tint",
            Op::Tint { color: b.tail_band_color.to_linear(), opacity: 1.0 },
            &[color, mask],
        );
    }
    if let Some(tip) = b.tip_color.filter(|_| b.tip_fraction > 0.0) {
        let start = 1.0 - (1.0 - plan.vent) * b.tip_fraction as f32;
        let mask = g.add("body.tip", Op::Along(AlongProfile { knots: vec![(start - EDGE_V, 0.0), (start, 1.0)] }), &[]);
        color = g.add("body.tip_tint", Op::Tint { color: tip.to_linear(), opacity: 1.0 }, &[color, mask]);
    }
    for (i, m) in b.head_mark.iter().enumerate() {
        let shape = match m.kind {
            HeadMarkKind::Cap => HeadMarkShape::Cap,
            HeadMarkKind::Snout => HeadMarkShape::Snout,
            HeadMarkKind::V => HeadMarkShape::V,
            HeadMarkKind::X => HeadMarkShape::X,
            HeadMarkKind::Spearhead => HeadMarkShape::Spearhead,
            HeadMarkKind::SpearStripes => HeadMarkShape::SpearStripes,
            HeadMarkKind::EyeBand => HeadMarkShape::EyeBand,
            HeadMarkKind::CrownBand => HeadMarkShape::CrownBand,
            HeadMarkKind::PreocularStripe => HeadMarkShape::PreocularStripe,
            HeadMarkKind::PostocularStripe => HeadMarkShape::PostocularStripe,
            HeadMarkKind::PostocularSpot => HeadMarkShape::PostocularSpot,
            HeadMarkKind::Collar => HeadMarkShape::Collar,
            HeadMarkKind::Crescents => HeadMarkShape::Crescents,
            HeadMarkKind::Lips => HeadMarkShape::Lips,
        };
        // The border first, as the mark lengthened backward, and the mark over it: the two
        // meet without a seam of the ground between them.
        // Only a mark round the neck draws one (a file's border passed over where `--set`
        // changed the kind was drawn under a lip stripe: a review).
        let border = m.border_color.filter(|_| HeadMarkSchema::takes_border(m.kind));
        let border = border.map(|c| ("_border", c, m.border_size as f32));
        for (part, tint, behind) in border.into_iter().chain([("", m.color, 0.0)]) {
            let mark = HeadMark { shape, size: m.size as f32, plan: *plan, behind };
            let mask = g.add(format!("body.head_mark{i}{part}"), Op::HeadMark(mark), &[]);
            // Off the belly plates (a collar round the neck stops at them).
            let mask = super::masked(g, format!("body.head_mark{i}{part}_off_belly"), mask, outside_belly);
            color = g.add(
                format!("body.head_mark{i}{part}_tint"),
                Op::Tint { color: tint.to_linear(), opacity: 1.0 },
                &[color, mask],
            );
        }
    }
    color
}
