//! What a preset's colours mean: each colour key is the **visible diffuse colour** of the
//! skin (`optics::brdf::layered::visible_colour`: the stack's diffuse reflectance at normal
//! incidence, per unit of light the top lets in), not the base albedo behind the film and
//! the pigment layer; the renderer recovers the base albedo per pixel. A stack with
//! absorption cannot show every colour: with k_d = 1 it shows exp(−τ) E / (1 − K) at most
//! (0.07 for the thesis' τ = 0.6 over n2 = 2). Colours beyond that are clamped to it when
//! the preset is loaded, and reported with the key, the line and the limit — never
//! silently — so the maps, the renderer and any tool that reads the colour map agree.
//!
//! The limit is taken at the preset's scale roughness (`roughness.base`) and at the
//! middle of its film thickness range, where the renderer takes K and E.

use super::schema::{Preset, Srgb8};
use crate::optics::brdf::{Model, layered};
use crate::render::engine::scene::LayerOptics;

/// A colour key the stack cannot show, and what it was clamped to.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ClampedColour {
    /// The dotted key (`belly.color`, `pattern.0.colors.2`).
    pub key: String,
    /// The key's line in the preset file, where it is written there (not for `--set`).
    pub line: Option<usize>,
    pub requested: String,
    /// The brightest colour of that hue the stack shows, per channel (what the maps use).
    pub clamped_to: String,
    /// The stack's limit per channel, linear.
    pub limit_linear: [f64; 3],
}

/// The brightest visible colour per channel (linear) of the preset's stack, or None when
/// it is lossless (τ = 0 in every channel: every colour can be shown).
pub fn visible_limit(preset: &Preset) -> Option<[f64; 3]> {
    let optics = LayerOptics::from_preset(preset);
    if !optics.has_absorption() {
        return None;
    }
    let (k, e) = optics.bounce_table(Model::Layered).at(preset.roughness.base);
    Some([0, 1, 2].map(|c| layered::visible_limit(optics.optical_depth[c], k[c], e[c])))
}

/// Every colour key of a preset with its value, mutable.
fn colour_keys(preset: &mut Preset) -> Vec<(String, &mut Srgb8)> {
    let mut keys: Vec<(String, &mut Srgb8)> = vec![
        ("color.base".into(), &mut preset.color.base),
        ("belly.color".into(), &mut preset.belly.color),
        ("belly.pattern_color".into(), &mut preset.belly.pattern_color),
    ];
    for (i, layer) in preset.pattern.iter_mut().enumerate() {
        keys.push((format!("pattern.{i}.color"), &mut layer.color));
        keys.push((format!("pattern.{i}.outline_color"), &mut layer.outline_color));
        for (j, colour) in layer.colors.iter_mut().enumerate() {
            keys.push((format!("pattern.{i}.colors.{j}"), colour));
        }
    }
    keys
}

/// Clamps every colour key beyond the stack's limit to it (per channel, rounded down so
/// the 8-bit colour stays within it) and returns what was clamped.
pub fn clamp_to_visible(preset: &mut Preset) -> Vec<ClampedColour> {
    let Some(limit) = visible_limit(preset) else {
        return Vec::new();
    };
    let mut clamped = Vec::new();
    for (key, colour) in colour_keys(preset) {
        let linear = colour.to_linear();
        if (0..3).all(|c| linear[c] as f64 <= limit[c]) {
            continue;
        }
        let shown = Srgb8(
            [0, 1, 2].map(|c| if linear[c] as f64 <= limit[c] { colour.0[c] } else { Srgb8::encode_floor(limit[c]) }),
        );
        clamped.push(ClampedColour {
            key,
            line: None,
            requested: colour.to_string(),
            clamped_to: shown.to_string(),
            limit_linear: limit,
        });
        *colour = shown;
    }
    clamped
}
