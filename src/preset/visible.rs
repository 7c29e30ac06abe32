//! What a preset's colours mean: each colour key is the **visible diffuse colour** of the
//! skin (`optics::brdf::layered::visible_colour`: the stack's diffuse reflectance at normal
//! incidence, per unit of light the top lets in), not the base albedo behind the film and
//! the pigment layer; the renderer recovers the base albedo per pixel. A stack with
//! absorption cannot show every colour: with k_d = 1 it shows t₁ E / (1 − K) at most
//! (`layered::normal_transmittance`; 0.07 for the thesis' τ = 0.6 over n2 = 2 and a smooth
//! top). Colours beyond that are clamped to it when the preset is loaded, and reported with
//! the key, the line and the limit — never silently — so the maps, the renderer and any tool
//! that reads the colour map agree. A lossless stack's limit is 1: a key that the map's
//! per-scale tone and colour variation would brighten past a reflectance of 1 is clamped
//! and reported too.
//!
//! The limit is the smallest over the film thicknesses and roughnesses the renderer takes K
//! and E at (both maps vary per pixel). The colour
//! map, the renderer's per-pixel inversion (which holds k_d at 1) and any tool that reads
//! the map then agree.

use super::schema::{Preset, Srgb8};
use crate::optics::brdf::energy::{E1_ROUGHNESS, GridCell};
use crate::optics::brdf::{exact, layered};
use crate::render::engine::scene::LayerOptics;
use rayon::prelude::*;

/// A colour key the stack cannot show, and what it was clamped to.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ClampedColour {
    /// The dotted key (`belly.color`, `pattern.0.colors.2`).
    pub key: String,
    /// The key's line in the preset file, where it is written there (not for `--set`).
    pub line: Option<usize>,
    pub requested: String,
    /// The brightest colour of that hue the stack shows (what the maps use).
    pub clamped_to: String,
    /// The stack's limit per channel for this key, linear.
    pub limit_linear: [f64; 3],
    /// Whether the stack's absorption set the limit (in the channel that set the clamp);
    /// else the map's brightening would have carried the key past a reflectance of 1. For
    /// the warning's words only: the manifest records the limit, which says the same.
    #[serde(skip)]
    pub absorbing: bool,
    /// Whether the key is at its default: neither the file nor an override writes it. The
    /// warning says so (a two-line preset warned of `belly.color = "#e6dcc0"`, a colour its
    /// writer never wrote, without a line: a walkthrough).
    #[serde(skip)]
    pub default: bool,
    /// Whether an override (`--set`, a jobs file's `set`) wrote the key: the warning is then
    /// placed at the override, as a problem is (`preset::place`).
    #[serde(skip)]
    pub overridden: bool,
}

impl ClampedColour {
    /// The warning for `preset` (its file or name), as every command prints it; `overrides`
    /// names the overrides where one wrote the key (`preset::place`).
    pub fn message(&self, preset: &str, overrides: &str) -> String {
        let place = super::place(preset, self.line, self.overridden, overrides);
        let [r, g, b] = self.limit_linear;
        let (key, requested, shown) = (&self.key, &self.requested, &self.clamped_to);
        let requested = if self.default {
            format!("\"{requested}\" (its default: the file does not set it)")
        } else {
            format!("\"{requested}\"")
        };
        if self.absorbing {
            return format!(
                "warning: {place}: {key} = {requested} is brighter than this layer stack can show (colours \
                 mean the visible colour; with its absorption, and any headroom this key keeps for the map's per-scale \
                 tone and colour variation, it may be at most linear [{r:.3}, {g:.3}, {b:.3}]); clamped to \"{shown}\". \
                 Lower optics.absorption or the colour to keep it."
            );
        }
        let variation = if key == "color.base" { ", color.variation" } else { "" };
        format!(
            "warning: {place}: {key} = {requested} would be brightened past a reflectance of 1 by the map's \
             per-scale tone and colour variation (colours mean the visible colour; with that headroom it may be at \
             most linear [{r:.3}, {g:.3}, {b:.3}]); clamped to \"{shown}\". Lower color.scale_tone, scale_hue, \
             edge_tone, tip_tone{variation} or the colour to keep it."
        )
    }
}

/// The brightest visible colour per channel (linear) of the preset's stack, or None when
/// it is lossless (τ = 0 in every channel: every colour can be shown). The smallest over
/// every film thickness and the roughnesses the roughness map can take
/// (`maps::roughness_range`), since both maps vary per pixel; 1 in a channel without
/// absorption (its K + E = 1: exactly 1, not 1 up to rounding).
pub fn visible_limit(preset: &Preset) -> Option<[f64; 3]> {
    let optics = LayerOptics::from_preset(preset);
    if !optics.has_absorption() {
        return None;
    }
    // Row j of every thickness's table is at roughness j / (E1_ROUGHNESS − 1); the rows that
    // bracket the roughness map's range are the ones a pixel's values come from (a rougher
    // top shows less: its light crosses the pigment layer more obliquely, so the rows of
    // roughness the map never reaches would clamp too hard).
    let (lo, hi) = crate::maps::roughness_range(preset);
    let row = GridCell::<f64>::row_coordinate;
    let rows = row(lo).floor() as usize..=(row(hi).ceil() as usize).min(E1_ROUGHNESS - 1);
    let t1: Vec<(usize, [f64; 3])> = rows
        .map(|j| {
            let roughness = GridCell::<f64>::row_roughness(j);
            (j, layered::normal_transmittance(optics.stack.n0, optics.stack.n2, roughness, optics.optical_depth))
        })
        .collect();
    // The K and E rows of `bounce_grid(Model::Layered)` that those roughnesses read, and
    // only those: a row of one thickness is a few hundred spectral film sums (432 for the
    // thesis stack), and the whole grid took about 1 s of a preset's load.
    let limits: Vec<[f64; 3]> = optics
        .bounce_thicknesses_nm()
        .par_iter()
        .flat_map_iter(|&d| {
            let top = exact::cached(optics.stack, d);
            let limit = move |&(j, t1): &(usize, [f64; 3])| {
                let (k, e) = top.k_e_row(optics.optical_depth, j);
                [0, 1, 2].map(|c| {
                    if optics.optical_depth[c] <= 0.0 { 1.0 } else { layered::visible_limit(t1[c], k[c], e[c]) }
                })
            };
            t1.iter().map(limit)
        })
        .collect();
    Some([0, 1, 2].map(|c| limits.iter().map(|l| l[c]).fold(1.0, f64::min)))
}

/// The most the per-scale colour brightens a pixel (`ops::scale_colour`): tone and hue
/// (red by up to (1 + tone)(1 + hue)), rim and tip where they lighten (the rim's the
/// lighter of the back's and the belly's, one bound for every colour).
pub fn per_scale_gain(preset: &Preset) -> f64 {
    let c = &preset.color;
    (1.0 + c.scale_tone.max(0.0))
        * (1.0 + c.scale_hue.max(0.0))
        * (1.0 + c.edge_tone.max(preset.belly.edge_tone).max(0.0))
        * (1.0 + c.tip_tone.max(0.0))
}

/// The names of every colour key of the preset (`colour_keys`), e.g. `pattern.1.colors.0`.
pub fn colour_key_names(preset: &Preset) -> Vec<String> {
    colour_keys(&mut preset.clone()).into_iter().map(|(key, _)| key).collect()
}

/// Every colour key of a preset with its value, mutable.
fn colour_keys(preset: &mut Preset) -> Vec<(String, &mut Srgb8)> {
    let mut keys: Vec<(String, &mut Srgb8)> = vec![
        ("color.base".into(), &mut preset.color.base),
        ("belly.color".into(), &mut preset.belly.color),
        ("belly.pattern_color".into(), &mut preset.belly.pattern_color),
        ("color.speckle_color".into(), &mut preset.color.speckle_color),
    ];
    if let Some(skin) = preset.color.skin.as_mut() {
        keys.push(("color.skin".into(), skin));
    }
    for (i, layer) in preset.pattern.iter_mut().enumerate() {
        // A rings layer with `colors` does not draw `color`: no warning for it.
        let reads_color = layer.reads_color();
        if let Some(colour) = layer.color.as_mut().filter(|_| reads_color) {
            keys.push((format!("pattern.{i}.color"), colour));
        }
        keys.push((format!("pattern.{i}.outline_color"), &mut layer.outline_color));
        if let Some(centre) = layer.center_color.as_mut() {
            keys.push((format!("pattern.{i}.center_color"), centre));
        }
        if let Some(border) = layer.border_color.as_mut() {
            keys.push((format!("pattern.{i}.border_color"), border));
        }
        for (j, colour) in layer.colors.iter_mut().enumerate() {
            keys.push((format!("pattern.{i}.colors.{j}"), colour));
        }
    }
    let body = &mut preset.body;
    keys.push(("body.tail_band_color".into(), &mut body.tail_band_color));
    if let Some(tail) = body.tail_color.as_mut() {
        keys.push(("body.tail_color".into(), tail));
    }
    if let Some(front) = body.belly_front_color.as_mut() {
        keys.push(("body.belly_front_color".into(), front));
    }
    if let Some(under_tail) = body.subcaudal_color.as_mut() {
        keys.push(("body.subcaudal_color".into(), under_tail));
    }
    if let Some(tip) = body.tip_color.as_mut() {
        keys.push(("body.tip_color".into(), tip));
    }
    for (i, mark) in body.head_mark.iter_mut().enumerate() {
        keys.push((format!("body.head_mark.{i}.color"), &mut mark.color));
        if let Some(border) = mark.border_color.as_mut() {
            keys.push((format!("body.head_mark.{i}.border_color"), border));
        }
    }
    keys
}

/// Clamps every colour key the stack cannot show and returns what was clamped. A colour
/// keeps its hue and saturation: all three channels are scaled by the one factor that
/// brings the brightest-over-its-limit channel to the limit (rounded down to 8 bits). The
/// map brightens colours beyond their keys in two places, and the keys keep headroom for
/// both: the per-scale colour (`ops::scale_colour`: tone, warm hue, lighter rims and tips)
/// by up to `per_scale_gain` on every key, and the back's colour variation `color.base` by
/// up to (1 + `color.variation`) more (`maps::color`).
pub fn clamp_to_visible(preset: &mut Preset) -> Vec<ClampedColour> {
    // A lossless stack shows every colour up to a reflectance of 1 (`layered::visible_limit`),
    // and the map's brightening must not carry a key past that either: a colour map above 1
    // is no reflectance, its PNG clips where its EXR does not, and the renderer's inversion
    // holds k_d at 1 there.
    let stack_limit = visible_limit(preset).unwrap_or([1.0; 3]);
    let per_scale = per_scale_gain(preset);
    let variation = 1.0 + preset.color.variation.max(0.0);
    let mut clamped = Vec::new();
    for (key, colour) in colour_keys(preset) {
        // Speckle is mixed in after the brightening: it shows as written. (Skin is mixed in
        // before it, and brightened where scales only partly part, as every other key.)
        let headroom = match key.as_str() {
            "color.base" => variation * per_scale,
            "color.speckle_color" => 1.0,
            _ => per_scale,
        };
        let allowed = stack_limit.map(|l| l / headroom);
        let linear = colour.to_linear().map(f64::from);
        // The channel furthest over its limit sets the factor (and says whether absorption did).
        let over = (0..3).filter(|&c| linear[c] > allowed[c]).map(|c| (allowed[c] / linear[c], c));
        let Some((factor, channel)) = over.min_by(|a, b| a.0.total_cmp(&b.0)) else {
            continue;
        };
        let shown = Srgb8([0, 1, 2].map(|c| Srgb8::encode_floor(linear[c] * factor)));
        clamped.push(ClampedColour {
            key,
            line: None,
            requested: colour.to_string(),
            clamped_to: shown.to_string(),
            limit_linear: allowed,
            absorbing: stack_limit[channel] < 1.0,
            default: false,
            overridden: false,
        });
        *colour = shown;
    }
    clamped
}
