//! Graph builders: a validated preset becomes one node graph with a named output per map.
//!
//! Node names are grouped by a dotted prefix: `scales*` and `noise.grain` are shared by
//! several maps; `color.*`, `pattern<i>.*` and `belly.*` feed only the colour map; `height.*`,
//! `normal.*`, `roughness.*` and `iridescence.*` their own map. Which maps share which nodes is
//! what makes `--maps roughness` cheap: it never reaches a colour or pattern node.

mod body;
mod color;

use crate::graph::{Graph, GraphBuilder, NodeId, Op};
use crate::ops::body::BodyPlan;
use crate::ops::filters::{BlendMode, NormalConvention};
use crate::ops::hash::derive_seed;
use crate::ops::noise::{FractalNoise, NoiseKind};
use crate::ops::scales::{Lattice, ScaleField, ScaleShape, channel};
use crate::preset::Preset;
use crate::preset::schema::{self, IridescenceGradient};

pub use crate::material::MapKind;
pub use color::{
    WholeScaleRingRows, ring_layers_that_do_not_fit, rings_of_whole_scales, spot_spacing, stripe_distances,
};

/// What one texture set covers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Layout {
    /// A square that tiles both ways: one circumference around, one along (the default).
    #[default]
    Tile,
    /// The whole snake, snout (top) to tail tip (bottom): `body.length` widths long.
    Body,
}

impl Layout {
    pub fn name(self) -> &'static str {
        match self {
            Layout::Tile => "tile",
            Layout::Body => "body",
        }
    }

    /// Image height for a width: the tile is square; the body is `body.length` widths long
    /// (so a pixel covers the same length of skin both ways).
    pub fn height(self, preset: &Preset, width: usize) -> usize {
        match self {
            Layout::Tile => width,
            Layout::Body => ((width as f64 * preset.body.length).round() as usize).max(1),
        }
    }
}

/// Choices that are not part of the preset (they do not change the skin, only its encoding
/// and extent).
#[derive(Debug, Clone, Copy, Default)]
pub struct BuildOptions {
    pub normal_convention: NormalConvention,
    pub layout: Layout,
}

/// The body layout's regions and counts from the preset (`[body]`).
pub fn body_plan(preset: &Preset) -> BodyPlan {
    let b = &preset.body;
    let head_end = b.head_fraction as f32;
    BodyPlan {
        length: b.length as f32,
        head_end,
        neck_end: head_end + b.neck_fraction as f32,
        vent: 1.0 - b.tail_fraction as f32,
        ventrals: b.ventrals,
        subcaudals: b.subcaudals,
        head_shields: b.head_scales == schema::HeadScales::Shields,
        divided_subcaudals: b.divided_subcaudals,
    }
}

/// The film thickness range the iridescence map spans, from the preset.
pub fn thickness_range_nm(preset: &Preset) -> (f64, f64) {
    crate::material::thickness_range_nm(preset.optics.film_thickness_nm, preset.iridescence.spread_nm)
}

/// The thickness range the iridescence map's values stand for in the files (the manifest's
/// `iridescence` range, the OpenEXR map's nanometres): the film's, or 0 to 0 nm where the
/// film does not show (its map is the constant 0). A film switched off by `film_ior` equal
/// to `ambient_ior` kept its range: the manifest said 290–550 nm and the OpenEXR map 290 nm.
pub fn map_thickness_range_nm(preset: &Preset) -> (f64, f64) {
    if has_film(preset) { thickness_range_nm(preset) } else { (0.0, 0.0) }
}

/// Whether the preset's film shows at all (`material::film_is_inert`).
pub fn has_film(preset: &Preset) -> bool {
    let o = &preset.optics;
    !crate::material::film_is_inert(thickness_range_nm(preset), o.ambient_ior, o.film_ior)
}

pub fn scale_field(preset: &Preset, layout: Layout) -> ScaleField {
    let s = &preset.scales;
    let body = (layout == Layout::Body).then(|| body_plan(preset));
    ScaleField {
        shape: match s.shape {
            schema::ScaleShape::Leaf => ScaleShape::Leaf,
            schema::ScaleShape::Diamond => ScaleShape::Diamond,
            schema::ScaleShape::Hexagon => ScaleShape::Hexagon,
        },
        rows: s.rows,
        aspect: s.aspect as f32,
        size: s.size as f32,
        keel_height: if s.keeled { s.keel_height as f32 } else { 0.0 },
        keel_width: s.keel_width as f32,
        jitter: s.jitter as f32,
        imbrication: s.imbrication as f32,
        edge_softness: s.edge_softness as f32,
        belly_width: if preset.belly.plates { preset.belly.width as f32 } else { 0.0 },
        vertebral_width: s.vertebral_width as f32,
        lowest_row_width: s.lowest_row_width as f32,
        smooth_rows: s.smooth_rows,
        seed: derive_seed(preset.seed, "scales"),
        length: body.map_or(1.0, |b| b.length),
        body,
        outputs: scale_outputs(preset),
    }
}

/// The scale-field channels this preset's maps read (each costs 4 bytes per pixel).
fn scale_outputs(preset: &Preset) -> Vec<usize> {
    let mut outputs = vec![channel::HEIGHT, channel::CREVICE];
    // The film's gradient, only where a film shows (`build_iridescence` reads it then only).
    if has_film(preset) {
        outputs.push(match preset.iridescence.gradient {
            IridescenceGradient::Vertical => channel::ALONG,
            IridescenceGradient::Radial => channel::RADIAL,
        });
    }
    if preset.scales.keeled && preset.roughness.keel > 0.0 {
        outputs.push(channel::KEEL);
    }
    if preset.roughness.per_scale > 0.0 {
        outputs.push(channel::CELL_RANDOM);
    }
    if preset.pattern.iter().any(|p| p.scale_aligned > 0.0) {
        outputs.extend([channel::CENTRE_U, channel::CENTRE_V]);
    }
    for c in color::per_scale_channels(preset) {
        if !outputs.contains(&c) {
            outputs.push(c);
        }
    }
    outputs
}

/// The product of two masks (a mask kept to where another is set), or `mask` itself.
pub(crate) fn masked(g: &mut GraphBuilder, name: String, mask: NodeId, by: Option<NodeId>) -> NodeId {
    match by {
        Some(by) => g.add(name, Op::Blend { mode: BlendMode::Multiply, opacity: 1.0 }, &[mask, by]),
        None => mask,
    }
}

/// A count per circumference over a body `length` circumferences long, rounded (at least
/// one): what `Shared::along_count` draws, and what the loader's ring warning counts with
/// (in f64 there, it named an amount the body drew one more repeat of: a review).
pub fn along_repeats(per_circumference: u32, length: f32) -> u32 {
    ((per_circumference as f32 * length).round() as u32).max(1)
}

/// Nodes that several maps read.
pub(crate) struct Shared {
    pub scales: NodeId,
    pub field: ScaleField,
    /// `field.lattice()`, computed once.
    pub lattice: Lattice,
    pub crevice: NodeId,
    pub scale_height: NodeId,
    pub grain: NodeId,
    /// Bands on the tail (`body.tail_bands`): a counted series then ends at the vent.
    pub tail_bands: u32,
}

impl Shared {
    /// Index of a scale-field channel in the `scales` node's output.
    pub fn channel_index(&self, channel: usize) -> usize {
        self.field.output_index(channel).expect("scale_outputs requests every channel the maps read")
    }

    /// Adds a node extracting one scale-field channel.
    pub fn channel(&self, g: &mut GraphBuilder, name: &str, channel: usize) -> NodeId {
        g.add(name, Op::Channel { index: self.channel_index(channel) }, &[self.scales])
    }

    /// How far (texture widths) a pixel can lie from its scale's centre along the body:
    /// the scale's longest reach plus its centre jitter, in cell lengths, times a cell's
    /// length (`SnapToScales::reach`).
    pub fn snap_reach(&self) -> f32 {
        let cells = self.field.apart_cells(&self.lattice);
        cells * self.field.length / self.lattice.rows_v as f32
    }

    /// The body layout's plan (None for the tile): the scale field's.
    pub fn body(&self) -> Option<BodyPlan> {
        self.field.body
    }

    /// Moves a mask to its value at each pixel's scale centre, by `amount`
    /// (`Op::SnapToScales`: colour that follows scale boundaries); `whole` for a coverage
    /// mask, whose scales are the pattern's or not (`filters::snap_to_scales`).
    pub fn snap(&self, g: &mut GraphBuilder, name: String, mask: NodeId, amount: f32, whole: bool) -> NodeId {
        let op = Op::SnapToScales {
            amount,
            whole,
            centre_u: self.channel_index(channel::CENTRE_U),
            centre_v: self.channel_index(channel::CENTRE_V),
            reach: self.snap_reach(),
        };
        g.add(name, op, &[mask, self.scales])
    }

    /// A count per circumference along the body (noise cells, rings, spots) over the whole
    /// texture: unchanged for the tile, times the body's length (rounded) for the body.
    pub fn along_count(&self, per_circumference: u32) -> u32 {
        if self.field.body.is_none() {
            return per_circumference;
        }
        along_repeats(per_circumference, self.field.length)
    }

    /// On a body atlas, marks at `per_circumference` from the end of the head (where an
    /// uncounted layer's region starts, `body::layer_region`) to the tail's tip: how many,
    /// and that stretch of v. None on the tile.
    pub fn behind_head_count(&self, per_circumference: u32) -> Option<(u32, (f32, f32))> {
        let plan = self.body()?;
        let marks = ((self.along_count(per_circumference) as f32 * (1.0 - plan.head_end)).round() as u32).max(1);
        Some((marks, (plan.head_end, 1.0)))
    }

    /// The scale field and what every map reads from it, added to `g` for `layout`.
    pub fn new(g: &mut GraphBuilder, preset: &Preset, layout: Layout) -> Shared {
        let field = scale_field(preset, layout);
        let lattice = field.lattice();
        let scales = g.add("scales", Op::Scales(field.clone()), &[]);
        let index = |channel: usize| field.output_index(channel).expect("height and crevice are always output");
        let crevice = g.add("scales.crevice", Op::Channel { index: index(channel::CREVICE) }, &[scales]);
        let scale_height = g.add("scales.height", Op::Channel { index: index(channel::HEIGHT) }, &[scales]);
        // Fine grain, a few features per scale, shared by height and roughness.
        let grain = g.add(
            "noise.grain",
            Op::Noise(FractalNoise {
                kind: NoiseKind::Perlin,
                cells_u: lattice.cols as u32 * 3,
                cells_v: lattice.rows_v as u32 * 3,
                octaves: 3,
                gain: 0.5,
                seed: derive_seed(preset.seed, "grain"),
            }),
            &[],
        );
        Shared { scales, field, lattice, crevice, scale_height, grain, tail_bands: preset.body.tail_bands }
    }
}

/// Builds the whole graph for a preset; evaluation later picks the part it needs.
pub fn build_graph(preset: &Preset, options: BuildOptions) -> Graph {
    let mut g = GraphBuilder::new();
    if options.layout == Layout::Body {
        g.set_open_v();
    }
    let shared = Shared::new(&mut g, preset, options.layout);
    let along = shared.field.length;

    let height = build_height(&mut g, preset, &shared);
    g.set_output(MapKind::Height, height);

    // The normal follows the physical surface: undo the height map's stretch.
    let slope = height_rise_texture_widths(preset);
    let normal = g.add(
        "normal.out",
        Op::HeightToNormal { slope, convention: options.normal_convention, v_extent: along },
        &[height],
    );
    g.set_output(MapKind::Normal, normal);

    // Occlusion of the same surface the normal map shades, its horizon searched one scale
    // width out (the overlap steps and keels that shade a scale lie within it).
    let ao_radius = 1.0 / shared.lattice.cols as f32;
    let ao = g.add("ao.out", Op::Occlusion { slope, radius: ao_radius, v_extent: along }, &[height]);
    g.set_output(MapKind::Ao, ao);

    let roughness = build_roughness(&mut g, preset, &shared);
    g.set_output(MapKind::Roughness, roughness);

    let iridescence = build_iridescence(&mut g, preset, &shared, shared.lattice.cols as u32);
    g.set_output(MapKind::Iridescence, iridescence);

    // The colour last: the evaluator follows this order, and the surface maps above are
    // what consume the grain noise and the height channel, so those buffers are freed before
    // the colour's many layers are alive (measured at 4096² for Bitis gabonica: the
    // peak of node buffers fell from 1088 MiB, colour first, to 960 MiB).
    let color = color::build(&mut g, preset, &shared);
    g.set_output(MapKind::Color, color);
    g.finish()
}

fn build_height(g: &mut GraphBuilder, preset: &Preset, s: &Shared) -> NodeId {
    let amp = preset.height.grain as f32;
    // Without grain the sum would add 0 to every height: the grain is not read.
    let sum = if amp == 0.0 {
        s.scale_height
    } else {
        let grain =
            g.add("height.grain", Op::Levels { in_low: 0.0, in_high: 1.0, out_low: -amp, out_high: amp }, &[s.grain]);
        g.add("height.sum", Op::Blend { mode: BlendMode::Add, opacity: 1.0 }, &[s.scale_height, grain])
    };
    let (low, high) = height_range(preset);
    g.add("height.out", Op::Levels { in_low: low, in_high: high, out_low: 0.0, out_high: 1.0 }, &[sum])
}

/// The heights the height map stretches over [0, 1]: from the floor of the deepest groove
/// between the preset's scales (`scales::groove_floor`: 0 for hexagons, whose rims meet at
/// the skin) to the tallest surface its scales, plates and head shields can make
/// (`scales::height_top`), each widened by the grain. No scale's top clips, and no groove
/// between scales; skin showing where leaves or diamonds do not overlap, or round their
/// head shields, reads 0 (the 16 bits go to the scales). The same for the tile and the body
/// layout (the head's shields count in both): one scale per preset, as README says. (It
/// assumed the leaf's profile for every shape, 0.3 to 0.6 + 0.3 imbrication: a third of a
/// hexagon preset's height map clipped at 1 and a tenth at 0, its normal map flat there.)
pub fn height_range(preset: &Preset) -> (f32, f32) {
    use crate::ops::scales::{groove_floor, height_top};
    let field = scale_field(preset, Layout::Tile);
    let shields = preset.body.head_scales == schema::HeadScales::Shields;
    let top = height_top(field.shape, field.imbrication, field.keel_height, preset.belly.plates, shields);
    let grain = preset.height.grain as f32;
    (groove_floor(field.shape) - grain, top + grain)
}

/// How far above a height sample of 0 one of 1 stands, in texture widths: the surface the
/// normal map shades, where a unit of the scale field's height rises `height.normal_strength`
/// scale widths (a scale column is 1 / columns of the texture's width), so the height map's
/// full range (`height_range`, high − low of the field's units) rises that many times over. The same for the
/// tile and the body atlas; the manifest's `displacement.rise_texture_widths`, for a
/// displacement that agrees with the normal map.
pub fn height_rise_texture_widths(preset: &Preset) -> f32 {
    let (low, high) = height_range(preset);
    let columns = scale_field(preset, Layout::Tile).lattice().cols;
    preset.height.normal_strength as f32 / columns as f32 * (high - low)
}

/// The range the roughness map can take (`build_roughness`): the base less its variation and
/// per-scale offset, up to the base plus every addition at its largest (the crevice and keel
/// masks reach 1), within [0, 1] as the map is clamped.
pub fn roughness_range(preset: &Preset) -> (f64, f64) {
    let r = &preset.roughness;
    let keel = if preset.scales.keeled { r.keel } else { 0.0 };
    let lo = r.base - r.variation - r.per_scale;
    let hi = r.base + r.variation + r.between_scales + keel + r.per_scale;
    (lo.clamp(0.0, 1.0), hi.clamp(0.0, 1.0))
}

fn build_roughness(g: &mut GraphBuilder, preset: &Preset, s: &Shared) -> NodeId {
    let r = &preset.roughness;
    let (lo, hi) = ((r.base - r.variation) as f32, (r.base + r.variation) as f32);
    let base = if r.variation == 0.0 {
        // No variation: the levels would map any grain to `lo` exactly; the grain is not read.
        g.add("roughness.base", Op::Constant { value: lo }, &[])
    } else {
        g.add("roughness.noise", Op::Levels { in_low: 0.0, in_high: 1.0, out_low: lo, out_high: hi }, &[s.grain])
    };
    let gaps = g.add(
        "roughness.between_scales",
        Op::Blend { mode: BlendMode::Add, opacity: r.between_scales as f32 },
        &[base, s.crevice],
    );
    let keeled = if preset.scales.keeled && r.keel > 0.0 {
        let keel = s.channel(g, "roughness.keel_mask", channel::KEEL);
        g.add("roughness.keel", Op::Blend { mode: BlendMode::Add, opacity: r.keel as f32 }, &[gaps, keel])
    } else {
        gaps
    };
    let last = if r.per_scale > 0.0 {
        // Each scale a little smoother or rougher than its neighbours.
        let random = s.channel(g, "roughness.scale_random", channel::CELL_RANDOM);
        let k = r.per_scale as f32;
        let offset =
            g.add("roughness.per_scale", Op::Levels { in_low: 0.0, in_high: 1.0, out_low: -k, out_high: k }, &[random]);
        g.add("roughness.varied", Op::Blend { mode: BlendMode::Add, opacity: 1.0 }, &[keeled, offset])
    } else {
        keeled
    };
    g.add("roughness.out", Op::Levels { in_low: 0.0, in_high: 1.0, out_low: 0.0, out_high: 1.0 }, &[last])
}

fn build_iridescence(g: &mut GraphBuilder, preset: &Preset, s: &Shared, cols: u32) -> NodeId {
    if !has_film(preset) {
        // No film shows (`has_film`): any thickness means the same, so the map is a
        // constant 0 and none of the gradient and noise nodes below is built or evaluated.
        // A film of one thickness (no spread) keeps them: its map reads as that thickness
        // everywhere, and the window's spread slider spreads it along the same gradient.
        return g.add("iridescence.out", Op::Constant { value: 0.0 }, &[]);
    }
    let p = &preset.iridescence;
    let gradient = match p.gradient {
        IridescenceGradient::Vertical => s.channel(g, "iridescence.gradient", channel::ALONG),
        IridescenceGradient::Radial => {
            let radial = s.channel(g, "iridescence.radial", channel::RADIAL);
            // Thickest at the scale's centre (thesis Fig. 4.14a).
            g.add(
                "iridescence.gradient",
                Op::Levels { in_low: 0.0, in_high: 1.0, out_low: 1.0, out_high: 0.0 },
                &[radial],
            )
        }
    };
    // Blend with the scale shape so the film thins into the crevices (thesis §4.2.5). The
    // film's own copy of the height channel, extracted here rather than shared with the
    // height map (`Shared::scale_height`), which would keep it alive from the height map
    // to here (as `color.crevice`).
    let scale_height = s.channel(g, "iridescence.scale_height", channel::HEIGHT);
    let shaped =
        g.add("iridescence.shaped", Op::Blend { mode: BlendMode::Multiply, opacity: 0.5 }, &[gradient, scale_height]);
    // Without noise the blend would give its base back exactly (b + (l − b) · 0 = b), so
    // neither the noise nor the blend is built.
    let mixed = if p.noise == 0.0 {
        shaped
    } else {
        let noise = g.add(
            "iridescence.noise",
            Op::Noise(FractalNoise {
                kind: NoiseKind::Perlin,
                cells_u: (cols / 2).max(1),
                cells_v: s.along_count((cols / 2).max(1)),
                octaves: 4,
                gain: 0.55,
                seed: derive_seed(preset.seed, "iridescence"),
            }),
            &[],
        );
        g.add("iridescence.mixed", Op::Blend { mode: BlendMode::Mix, opacity: p.noise as f32 }, &[shaped, noise])
    };
    g.add("iridescence.out", Op::Levels { in_low: 0.0, in_high: 1.0, out_low: 0.0, out_high: 1.0 }, &[mixed])
}
