//! The colour map's graph (thesis §4.2.1): a base colour with fractal variation, pattern
//! layers composed in order (each a coverage mask, optionally edge-distorted and outlined),
//! the belly, and darker skin between the scales.

use super::Shared;
use crate::graph::{GraphBuilder, NodeId, Op};
use crate::ops::filters::BlendMode;
use crate::ops::hash::derive_seed;
use crate::ops::noise::{FractalNoise, NoiseKind};
use crate::ops::shapes::SpotGrid;
use crate::preset::Preset;
use crate::preset::schema::{NoiseChoice, PatternKind, PatternLayer};

pub(super) fn build(g: &mut GraphBuilder, preset: &Preset, s: &Shared) -> NodeId {
    let base = preset.color.base.to_linear();
    let var = preset.color.variation as f32;
    let noise = g.add(
        "color.variation_noise",
        perlin(4, 4, 5, 0.55, derive_seed(preset.seed, "color")),
        &[],
    );
    let mut color = g.add(
        "color.base",
        Op::Colorize {
            low: base.map(|c| c * (1.0 - var)),
            high: base.map(|c| c * (1.0 + var)),
        },
        &[noise],
    );

    for (i, layer) in preset.pattern.iter().enumerate() {
        color = pattern_layer(g, preset, i, layer, color);
    }

    if preset.belly.width > 0.0 {
        let b = &preset.belly;
        let mask = g.add(
            "belly.mask",
            Op::Bands {
                centres: vec![0.0],
                half_width: b.width as f32 * 0.5,
                softness: b.blend as f32,
            },
            &[],
        );
        color = g.add(
            "belly.tint",
            Op::Tint {
                color: b.color.to_linear(),
                opacity: 1.0,
            },
            &[color, mask],
        );
    }

    let k = preset.color.between_scales as f32;
    let shade = g.add(
        "color.scale_shade",
        Op::Levels {
            in_low: 0.0,
            in_high: 1.0,
            out_low: 1.0,
            out_high: 1.0 - k,
        },
        &[s.crevice],
    );
    g.add(
        "color.out",
        Op::Blend {
            mode: BlendMode::Multiply,
            opacity: 1.0,
        },
        &[color, shade],
    )
}

fn perlin(cells_u: u32, cells_v: u32, octaves: u32, gain: f32, seed: u32) -> Op {
    Op::Noise(FractalNoise {
        kind: NoiseKind::Perlin,
        cells_u,
        cells_v,
        octaves,
        gain,
        seed,
    })
}

/// Adds one pattern layer over `below`; returns the new colour node.
fn pattern_layer(
    g: &mut GraphBuilder,
    preset: &Preset,
    i: usize,
    layer: &PatternLayer,
    below: NodeId,
) -> NodeId {
    let name = |part: &str| format!("pattern{i}.{part}");
    let seed = derive_seed(preset.seed, &name("seed"));
    let size = layer.size as f32;

    let shape = match layer.kind {
        PatternKind::Solid => {
            // Full coverage, modulated by broad noise so the tint is not flat.
            let n = g.add(name("noise"), perlin(3, 3, 4, 0.5, seed), &[]);
            let amount = layer.amount as f32;
            let mask = g_levels(g, &name("mask"), n, amount * 0.6, amount);
            return tint(g, &name("tint"), layer, below, mask);
        }
        PatternKind::Stripes => {
            // `amount` stripes each side of the dorsal midline (u = 0.5), centre to centre
            // three stripe widths apart; offset 0 puts the first on the spine.
            let half_width = size * 0.5;
            let mut centres = Vec::new();
            for k in 0..layer.amount.round() as usize {
                let d = layer.offset as f32 + k as f32 * size * 3.0;
                centres.push(0.5 + d);
                if d > 0.0 {
                    centres.push(0.5 - d);
                }
            }
            g.add(
                name("shape"),
                Op::Bands {
                    centres,
                    half_width,
                    softness: 0.002,
                },
                &[],
            )
        }
        PatternKind::Spots => {
            let across = layer.amount.round().max(1.0) as u32;
            let grid = SpotGrid {
                across,
                along: across,
                radius: size,
                jitter: 0.35,
                alternate: true,
                seed,
            };
            g.add(name("shape"), Op::Spots(grid), &[])
        }
        PatternKind::Irregular => {
            let kind = match layer.noise {
                NoiseChoice::Perlin => NoiseKind::Perlin,
                NoiseChoice::Cellular => NoiseKind::Cellular,
            };
            let cells = (1.0 / size).round().clamp(1.0, 256.0) as u32;
            let n = g.add(
                name("noise"),
                Op::Noise(FractalNoise {
                    kind,
                    cells_u: cells,
                    cells_v: cells,
                    octaves: 3,
                    gain: 0.45,
                    seed,
                }),
                &[],
            );
            // Higher amount, lower threshold, more coverage; fBm sits mostly in [0.3, 0.7].
            let level = 0.7 - 0.4 * layer.amount as f32;
            let binary = g.add(
                name("threshold"),
                Op::Threshold {
                    level,
                    softness: 0.01,
                },
                &[n],
            );
            g.add(name("shape"), Op::Blur { sigma: size * 0.04 }, &[binary])
        }
    };

    let mask = if layer.edge_distortion > 0.0 {
        // Thesis §4.2.1.2: blend with noise, then threshold, for ragged edges. The shape is
        // softened first so that adding noise moves its edges instead of leaving them.
        let d = layer.edge_distortion as f32;
        let soft = g.add(
            name("soften"),
            Op::Blur {
                sigma: 0.002 + 0.01 * d,
            },
            &[shape],
        );
        let n = g.add(
            name("distortion_noise"),
            perlin(24, 24, 3, 0.5, seed ^ 0x5eed),
            &[],
        );
        let offset = g_levels(g, &name("distortion"), n, -d * 0.5, d * 0.5);
        let moved = g.add(
            name("distorted"),
            Op::Blend {
                mode: BlendMode::Add,
                opacity: 1.0,
            },
            &[soft, offset],
        );
        g.add(
            name("mask"),
            Op::Threshold {
                level: 0.5,
                softness: 0.04,
            },
            &[moved],
        )
    } else {
        shape
    };

    let color = tint(g, &name("tint"), layer, below, mask);
    if layer.outline_size <= 0.0 {
        return color;
    }
    // Thesis §4.2.1.6: edge detection, blur and binarise, then colour the outline.
    let sigma = layer.outline_size as f32 * 0.5;
    let soft = g.add(name("outline_blur"), Op::Blur { sigma }, &[mask]);
    let edges = g.add(
        name("outline_edges"),
        Op::Sobel { edge_sigma: sigma },
        &[soft],
    );
    let outline = g.add(
        name("outline"),
        Op::Threshold {
            level: 0.35,
            softness: 0.1,
        },
        &[edges],
    );
    g.add(
        name("outline_tint"),
        Op::Tint {
            color: layer.outline_color.to_linear(),
            opacity: layer.opacity as f32,
        },
        &[color, outline],
    )
}

fn g_levels(g: &mut GraphBuilder, name: &str, input: NodeId, lo: f32, hi: f32) -> NodeId {
    g.add(
        name,
        Op::Levels {
            in_low: 0.0,
            in_high: 1.0,
            out_low: lo,
            out_high: hi,
        },
        &[input],
    )
}

fn tint(
    g: &mut GraphBuilder,
    name: &str,
    layer: &PatternLayer,
    below: NodeId,
    mask: NodeId,
) -> NodeId {
    g.add(
        name,
        Op::Tint {
            color: layer.color.to_linear(),
            opacity: layer.opacity as f32,
        },
        &[below, mask],
    )
}
