//! The preset schema: what a snake preset file may say, with defaults.
//!
//! Every struct rejects unknown keys. Names follow the thesis' generator and shading
//! parameters (Bie & Jiang 2024, Tables 5.1 and 5.2); the thesis symbol is noted on each
//! field. Ranges live in `validate.rs`; docs/presets.md documents every key.

use serde::{Deserialize, Deserializer, Serialize, de};

/// Preset enums are read from their names alone, `shape = "leaf"`. serde's derive reads an
/// enum the TOML way, a name or a table (`[scales.shape.hexagon]` was taken for "hexagon"),
/// and its messages for anything else were its own ("wanted string or table", "invalid
/// type: unit variant"): `try_from = "String"` reads a string, and `by_name` finds the
/// variant whose serialised name it is, or names the nearest and lists them all. The
/// macro's `match` makes leaving a variant out of the list a compile error.
/// `accepted:` words the message's list where not every value goes everywhere (called only
/// for a message).
macro_rules! named_enum {
    ($t:ident { $($v:ident),+ $(,)? }) => {
        named_enum!($t { $($v),+ } accepted: None);
    };
    ($t:ident { $($v:ident),+ $(,)? } accepted: $accepted:expr) => {
        impl TryFrom<String> for $t {
            type Error = String;
            fn try_from(name: String) -> Result<Self, String> {
                // Every variant is in the list: this match is exhaustive.
                const _: fn($t) = |x| match x {
                    $($t::$v)|+ => {}
                };
                by_name(&[$($t::$v),+], &name, $accepted)
            }
        }

        impl $t {
            /// Every value as a preset writes it, comma-separated (for messages).
            pub fn accepted_names() -> String {
                [$($t::$v),+].iter().map(spelled).collect::<Vec<_>>().join(", ")
            }
        }
    };
}

/// A preset enum's value as a preset writes it (`"half_moons"`): its serialised name.
pub fn spelled<T: Serialize>(value: &T) -> String {
    serde_json::to_value(value).ok().and_then(|j| j.as_str().map(str::to_string)).unwrap_or_default()
}

/// The variant of `all` serialised as `name` (the preset's spelling), or a message that
/// lists them (or says what `accepted` words, where given).
fn by_name<T: Serialize + Copy>(all: &[T], name: &str, accepted: Option<fn() -> String>) -> Result<T, String> {
    let names: Vec<String> = all.iter().map(spelled).collect();
    match names.iter().position(|n| n == name) {
        Some(i) => Ok(all[i]),
        None => {
            let hint = crate::toml_text::nearest(name, names.iter().map(String::as_str))
                .map(|n| format!("; did you mean \"{n}\"?"))
                .unwrap_or_default();
            let accepted = accepted.map_or_else(|| names.join(", "), |words| words());
            Err(format!("unknown value {name:?}{hint} (accepted: {accepted})"))
        }
    }
}

named_enum!(Category { Solid, VerticalStripe, HorizontalStripe, Spot, Simple, Complex });
named_enum!(ScaleShape { Leaf, Diamond, Hexagon });
named_enum!(PatternKind { Solid, Stripes, Rings, Spots, Blotches, Irregular });
named_enum!(StripePosition { Vertebral, Dorsolateral, Lateral });
// Spots and blotches take different shapes (`validate.rs` checks which): the plain list put
// `ring` before a blotches layer, which then refused it.
named_enum!(PatternShape { Round, Ring, Diamond, Saddle, Chevron, Hourglass, Zigzag }
    accepted: Some(PatternShape::accepted_by_kind));
named_enum!(Arrangement { Aligned, Alternating, Checkered });
named_enum!(NoiseChoice { Perlin, Cellular });
named_enum!(BellyPattern { None, Checkered, Spots, HalfMoons, MedianStripe });
named_enum!(IridescenceGradient { Vertical, Radial });
named_enum!(HeadScales { Shields, Small });
named_enum!(HeadMarkKind {
    Cap,
    Snout,
    V,
    X,
    Spearhead,
    SpearStripes,
    EyeBand,
    CrownBand,
    PreocularStripe,
    PostocularStripe,
    PostocularSpot,
    Collar,
    Crescents,
    Lips
});

/// A colour written as `"#rrggbb"` (sRGB, 8 bits per channel).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Srgb8(pub [u8; 3]);

impl Srgb8 {
    /// Linear RGB by the sRGB transfer function (IEC 61966-2-1).
    pub fn to_linear(self) -> [f32; 3] {
        self.0.map(|c| crate::export::srgb::decode_f32(c as f32 / 255.0))
    }

    pub fn parse(text: &str) -> Option<Self> {
        let hex = text.strip_prefix('#')?;
        if hex.len() != 6 || !hex.bytes().all(|b| b.is_ascii_hexdigit()) {
            return None;
        }
        let byte = |i: usize| u8::from_str_radix(&hex[i..i + 2], 16).ok();
        Some(Srgb8([byte(0)?, byte(2)?, byte(4)?]))
    }
}

impl<'de> Deserialize<'de> for Srgb8 {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        // Parsed inside the visitor, so that a bad colour's error carries the string's own
        // place: parsed after `String::deserialize` returned, one in a list spread over lines
        // was placed at the list's opening bracket, without its index.
        struct Colour;
        impl de::Visitor<'_> for Colour {
            type Value = Srgb8;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a colour \"#rrggbb\" (sRGB hex)")
            }
            fn visit_str<E: de::Error>(self, text: &str) -> Result<Srgb8, E> {
                Srgb8::parse(text)
                    .ok_or_else(|| E::custom(format!("invalid colour {text:?}: expected \"#rrggbb\" (sRGB hex)")))
            }
        }
        deserializer.deserialize_str(Colour)
    }
}

impl Serialize for Srgb8 {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(&self.to_string())
    }
}

impl std::fmt::Display for Srgb8 {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let [r, g, b] = self.0;
        write!(f, "#{r:02x}{g:02x}{b:02x}")
    }
}

impl Srgb8 {
    /// The largest 8-bit sRGB code whose linear value (`to_linear`) is at most `linear`.
    pub fn encode_floor(linear: f64) -> u8 {
        (0..=255u8).rev().find(|&code| Srgb8([code; 3]).to_linear()[0] as f64 <= linear).unwrap_or(0)
    }
}

/// Pinheiro & Walter's pattern categories, used to group the species library.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case", try_from = "String")]
pub enum Category {
    Solid,
    VerticalStripe,
    HorizontalStripe,
    Spot,
    Simple,
    Complex,
}

impl Category {
    /// The name as written in presets.
    pub fn name(self) -> &'static str {
        match self {
            Category::Solid => "solid",
            Category::VerticalStripe => "vertical_stripe",
            Category::HorizontalStripe => "horizontal_stripe",
            Category::Spot => "spot",
            Category::Simple => "simple",
            Category::Complex => "complex",
        }
    }
}

#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Preset {
    /// Scientific name.
    #[serde(default)]
    pub species: Option<String>,
    #[serde(default)]
    pub common_name: Option<String>,
    #[serde(default)]
    pub category: Option<Category>,
    /// Where the facts in this preset come from.
    #[serde(default)]
    pub sources: Vec<String>,
    /// Thesis "Seed": fixes every random choice.
    #[serde(default)]
    pub seed: u64,
    #[serde(default, deserialize_with = "table")]
    pub scales: Scales,
    /// A `[pattern]` table or `[[pattern]]` layers, composed in order.
    #[serde(default, deserialize_with = "one_or_many")]
    pub pattern: Vec<PatternLayer>,
    #[serde(default, deserialize_with = "table")]
    pub belly: Belly,
    #[serde(default, deserialize_with = "table")]
    pub color: ColorParams,
    #[serde(default, deserialize_with = "table")]
    pub height: HeightParams,
    #[serde(default, deserialize_with = "table")]
    pub roughness: RoughnessParams,
    #[serde(default, deserialize_with = "table")]
    pub iridescence: IridescenceParams,
    #[serde(default, deserialize_with = "table")]
    pub optics: Optics,
    /// The whole animal (`generate --layout body`): proportions, counts, head and tail.
    #[serde(default, deserialize_with = "table")]
    pub body: Body,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case", try_from = "String")]
pub enum ScaleShape {
    Leaf,
    Diamond,
    Hexagon,
}

#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct Scales {
    /// Thesis "ScaleType".
    pub shape: ScaleShape,
    /// Thesis "ScaleAmount": dorsal scale rows around the body.
    pub rows: u32,
    /// Thesis "ScaleSize": scale size relative to its lattice cell (above 1 they overlap).
    pub size: f64,
    /// Scale length along the body over its width around it.
    pub aspect: f64,
    /// Thesis "ScaleKeeled".
    pub keeled: bool,
    pub keel_height: f64,
    /// Keel half-width as a fraction of the scale width.
    pub keel_width: f64,
    /// Random offset, size and rotation per scale.
    pub jitter: f64,
    /// How far the free posterior edge is raised over the tucked anterior edge.
    pub imbrication: f64,
    /// Width of a scale's rounded rim, in scale widths.
    pub edge_softness: f64,
    /// Width of the vertebral row relative to the other rows (kraits: enlarged).
    pub vertebral_width: f64,
    /// Width of the lowest dorsal row, next to the ventral plates, relative to the others.
    pub lowest_row_width: f64,
    /// The lowest this many dorsal rows are smooth when the scales are keeled.
    pub smooth_rows: u32,
}

impl Default for Scales {
    fn default() -> Self {
        Scales {
            shape: ScaleShape::Leaf,
            rows: 19,
            size: 1.2,
            aspect: 1.3,
            keeled: false,
            keel_height: 0.5,
            keel_width: 0.08,
            jitter: 0.1,
            imbrication: 0.6,
            edge_softness: 0.06,
            vertebral_width: 1.0,
            lowest_row_width: 1.0,
            smooth_rows: 0,
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case", try_from = "String")]
pub enum PatternKind {
    /// A uniform colour over the whole body, with fractal variation (P&W "solid").
    Solid,
    /// Stripes along the body (P&W "vertical stripe").
    Stripes,
    /// Rings across the body, optionally a colour sequence (P&W "horizontal stripe").
    Rings,
    /// Round or ring spots on a jittered grid (P&W "spot").
    Spots,
    /// A dorsal series of saddles, diamonds or rounded blotches (P&W "other simple").
    Blotches,
    /// Thresholded noise blobs (P&W "complex").
    Irregular,
}

/// Named stripe positions, measured from the dorsal midline.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case", try_from = "String")]
pub enum StripePosition {
    /// On the spine.
    Vertebral,
    /// Between the spine and the flank.
    Dorsolateral,
    /// On the flanks.
    Lateral,
}

impl StripePosition {
    /// Distance of the stripe centre from the dorsal midline, fraction of the circumference.
    pub fn offset(self) -> f64 {
        match self {
            StripePosition::Vertebral => 0.0,
            StripePosition::Dorsolateral => 0.12,
            StripePosition::Lateral => 0.24,
        }
    }
}

/// Shape of spots (`round`, `ring`) or blotches (`round`, `diamond`, `saddle`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case", try_from = "String")]
pub enum PatternShape {
    Round,
    Ring,
    Diamond,
    Saddle,
    Chevron,
    Hourglass,
    Zigzag,
}

impl PatternShape {
    /// The shapes a spots layer draws.
    pub const FOR_SPOTS: &[PatternShape] = &[PatternShape::Round, PatternShape::Ring];
    /// The shapes a blotches layer draws.
    pub const FOR_BLOTCHES: &[PatternShape] = &[
        PatternShape::Round,
        PatternShape::Diamond,
        PatternShape::Saddle,
        PatternShape::Chevron,
        PatternShape::Hourglass,
        PatternShape::Zigzag,
    ];

    /// The shapes by the kind that takes them, for messages.
    fn accepted_by_kind() -> String {
        let names = |shapes: &[PatternShape]| shapes.iter().map(spelled).collect::<Vec<_>>().join(", ");
        format!("for spots {}; for blotches {}", names(Self::FOR_SPOTS), names(Self::FOR_BLOTCHES))
    }
}

/// How spots are laid out in rows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case", try_from = "String")]
pub enum Arrangement {
    /// Rows one above the other.
    Aligned,
    /// Every other row shifted by half a spacing.
    Alternating,
    /// Only every other cell of an aligned grid (a checkerboard).
    Checkered,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case", try_from = "String")]
pub enum NoiseChoice {
    Perlin,
    Cellular,
}

#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct PatternLayer {
    /// Thesis "PatternType".
    pub kind: PatternKind,
    /// The layer's colour: required of every layer but a rings layer with `colors`, which
    /// draws its sequence instead (`validate.rs`); `PatternLayer::color` reads it.
    #[serde(default)]
    pub color: Option<Srgb8>,
    /// Thesis "PatternAmount": stripes per side, spots around the body, or blob coverage.
    #[serde(default = "PatternLayer::default_amount")]
    pub amount: f64,
    /// Thesis "PatternSize": stripe width or spot radius (fraction of the circumference),
    /// or blob feature size.
    #[serde(default = "PatternLayer::default_size")]
    pub size: f64,
    /// Stripes: distance of the innermost stripe from the dorsal midline (fraction of the
    /// circumference); 0 puts a stripe on the spine.
    #[serde(default)]
    pub offset: f64,
    /// Thesis "PatternOutlineSize" (fraction of the circumference; 0 = no outline).
    #[serde(default)]
    pub outline_size: f64,
    #[serde(default = "PatternLayer::default_outline_color")]
    pub outline_color: Srgb8,
    /// Thesis "EdgeDistortion": noise displacement of the pattern's edges.
    #[serde(default = "PatternLayer::default_edge_distortion")]
    pub edge_distortion: f64,
    #[serde(default = "PatternLayer::default_opacity")]
    pub opacity: f64,
    /// Irregular: the noise that shapes the blobs.
    #[serde(default = "PatternLayer::default_noise")]
    pub noise: NoiseChoice,
    /// Stripes: a named position (overrides `offset`).
    #[serde(default)]
    pub position: Option<StripePosition>,
    /// Spots: one of `PatternShape::FOR_SPOTS`; blotches: one of `FOR_BLOTCHES`.
    #[serde(default = "PatternLayer::default_shape")]
    pub shape: PatternShape,
    /// Spots: `aligned`, `alternating` or `checkered`.
    #[serde(default = "PatternLayer::default_arrangement")]
    pub arrangement: Arrangement,
    /// Rings: a colour sequence repeated `amount` times along the body (e.g. a coral
    /// snake's red, yellow, black, yellow); empty means one ring of `color`.
    #[serde(default)]
    pub colors: Vec<Srgb8>,
    /// Rings: the width of each colour of `colors` as a fraction of one repeat (default:
    /// equal widths filling the repeat).
    #[serde(default)]
    pub widths: Vec<f64>,
    /// Blotches: length along the body as a fraction of the spacing between blotches.
    #[serde(default = "PatternLayer::default_length")]
    pub length: f64,
    /// Paint over the belly band too (by default the belly keeps its own colour).
    #[serde(default)]
    pub over_belly: bool,
    /// 0..1: snap the pattern to whole scales (in real snakes colour follows scale
    /// boundaries); 0 leaves it free, 1 colours each scale by the pattern at its centre.
    #[serde(default)]
    pub scale_aligned: f64,
    /// Stripes: the fraction of each stripe's length left out, in gaps along the body (0:
    /// unbroken; a green tree python's "broken vertebral stripe").
    #[serde(default)]
    pub broken: f64,
    /// Stripes: the dorsal scale rows the stripe covers, `[first, last]`, counted from the
    /// lowest row (1, next to the ventral plates) to the vertebral row; fractions reach into
    /// a row (9.5 = from the middle of row 9). Mirrored on both sides; overrides `offset`,
    /// `position`, `size` and `amount`.
    #[serde(default)]
    pub rows: Vec<f64>,
    /// Blotches: shift of the series along the body, in spacings (0.5 puts a flank series
    /// between the blotches of a dorsal one).
    #[serde(default)]
    pub phase: f64,
    /// Blotches and spots: a composite mark's centre, in this colour (none: no centre).
    #[serde(default)]
    pub center_color: Option<Srgb8>,
    /// Blotches and spots: the centre's size as a fraction of the mark's.
    #[serde(default = "PatternLayer::default_center_size")]
    pub center_size: f64,
    /// A border outside the mark (and outside its outline), in this colour (none: none).
    #[serde(default)]
    pub border_color: Option<Srgb8>,
    /// The border's width, fraction of the circumference.
    #[serde(default = "PatternLayer::default_border_size")]
    pub border_size: f64,
    /// Body layout only: the number of marks (blotches, or repeats of a ring sequence)
    /// along the trunk, from the neck to the vent, as counted in the literature; unset, the
    /// tile's `amount` per circumference continues over the whole body.
    #[serde(default)]
    pub count: Option<u32>,
    /// Body layout, a counted blotch series: the last mark's half-width over the first's,
    /// growing linearly along the body (saddles that widen into bands toward the tail).
    #[serde(default = "PatternLayer::default_widen_to_tail")]
    pub widen_to_tail: f64,
}

impl PatternLayer {
    /// Whether the layer draws `color`: every kind does, but rings with a `colors` sequence.
    pub fn reads_color(&self) -> bool {
        self.kind != PatternKind::Rings || self.colors.is_empty()
    }

    /// The layer's colour. Validation requires it wherever `reads_color` says it is drawn, so
    /// the fallback (the first colour of `colors`, else black) is never drawn.
    pub fn color(&self) -> Srgb8 {
        self.color.or(self.colors.first().copied()).unwrap_or(Srgb8([0; 3]))
    }

    /// The layer's `count` where its kind reads one (blotches and rings): a `count` the file
    /// wrote for blotches, passed over after `--set pattern.N.kind=spots`, still cut the spots
    /// to the counted series' stretch of the body and went into the manifest.
    pub fn series_count(&self) -> Option<u32> {
        matches!(self.kind, PatternKind::Blotches | PatternKind::Rings).then_some(self.count).flatten()
    }

    pub(crate) fn default_amount() -> f64 {
        1.0
    }
    pub(crate) fn default_size() -> f64 {
        0.05
    }
    fn default_outline_color() -> Srgb8 {
        Srgb8([0x14, 0x12, 0x10])
    }
    pub(crate) fn default_edge_distortion() -> f64 {
        0.2
    }
    fn default_opacity() -> f64 {
        1.0
    }
    pub(crate) fn default_noise() -> NoiseChoice {
        NoiseChoice::Perlin
    }
    pub(crate) fn default_center_size() -> f64 {
        0.5
    }
    pub(crate) fn default_border_size() -> f64 {
        0.01
    }
    pub(crate) fn default_widen_to_tail() -> f64 {
        1.0
    }
    pub(crate) fn default_length() -> f64 {
        0.6
    }
    pub(crate) fn default_shape() -> PatternShape {
        PatternShape::Round
    }
    pub(crate) fn default_arrangement() -> Arrangement {
        Arrangement::Alternating
    }
}

/// A struct read from a TOML table only. Why: serde's derived structs also read a
/// sequence, field by field in order, so `scales = ["diamond", 40]` was read as `shape =
/// "diamond"` and `rows = 40`, `optics = [1.33]` set the first index of refraction, and
/// `belly = []` passed as the defaults, silently; and `scales = [19]` was refused as
/// `scales.0`, a key no preset has. An array where a table belongs is refused with the key
/// and its line: "invalid type: array, expected a table".
pub(crate) fn table<'de, D: Deserializer<'de>, T: Deserialize<'de>>(deserializer: D) -> Result<T, D::Error> {
    struct Table<T>(std::marker::PhantomData<T>);
    impl<'de, T: Deserialize<'de>> de::Visitor<'de> for Table<T> {
        type Value = T;
        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            f.write_str("a table")
        }
        fn visit_map<A: de::MapAccess<'de>>(self, map: A) -> Result<T, A::Error> {
            T::deserialize(de::value::MapAccessDeserializer::new(map))
        }
    }
    deserializer.deserialize_map(Table(std::marker::PhantomData))
}

/// An array of tables (`[[body.head_mark]]`, `[[pattern]]`), each read by `table`.
pub(crate) fn tables<'de, D: Deserializer<'de>, T: Deserialize<'de>>(deserializer: D) -> Result<Vec<T>, D::Error> {
    struct Each<T>(T);
    impl<'de, T: Deserialize<'de>> Deserialize<'de> for Each<T> {
        fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
            table(deserializer).map(Each)
        }
    }
    Ok(Vec::<Each<T>>::deserialize(deserializer)?.into_iter().map(|each| each.0).collect())
}

/// Accepts `[pattern]` (one table) or `[[pattern]]` (an array of tables).
fn one_or_many<'de, D: Deserializer<'de>>(deserializer: D) -> Result<Vec<PatternLayer>, D::Error> {
    struct Visitor;
    impl<'de> de::Visitor<'de> for Visitor {
        type Value = Vec<PatternLayer>;
        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            f.write_str("a [pattern] table or [[pattern]] layers")
        }
        fn visit_map<A: de::MapAccess<'de>>(self, map: A) -> Result<Self::Value, A::Error> {
            Ok(vec![PatternLayer::deserialize(de::value::MapAccessDeserializer::new(map))?])
        }
        fn visit_seq<A: de::SeqAccess<'de>>(self, seq: A) -> Result<Self::Value, A::Error> {
            tables(de::value::SeqAccessDeserializer::new(seq))
        }
    }
    deserializer.deserialize_any(Visitor)
}

#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct Belly {
    /// Thesis "BellySize": width of the ventral band, fraction of the circumference.
    pub width: f64,
    pub color: Srgb8,
    /// Draw ventral plates (one wide plate per row) in the band.
    pub plates: bool,
    /// Softness of the colour boundary between back and belly (fraction of circumference).
    pub blend: f64,
    /// A pattern on the ventral plates: `none` or `checkered` (alternate halves of each
    /// plate in `pattern_color`, as in corn snakes).
    pub pattern: BellyPattern,
    pub pattern_color: Srgb8,
    /// Spots and half-moons: the share of plates that carry one; median stripe: its width
    /// over the band's.
    pub pattern_amount: f64,
    /// The belly colour runs up onto this many of the lowest dorsal rows each side.
    pub up_rows: u32,
    /// The plates' rims (and every scale's of the ventral band) lighter (> 0) or darker
    /// (< 0), as `color.edge_tone` is for the dorsal scales.
    pub edge_tone: f64,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case", try_from = "String")]
pub enum BellyPattern {
    None,
    Checkered,
    Spots,
    HalfMoons,
    MedianStripe,
}

impl Default for Belly {
    fn default() -> Self {
        Belly {
            width: 0.22,
            color: Srgb8([0xe6, 0xdc, 0xc0]),
            plates: true,
            blend: 0.03,
            pattern: BellyPattern::None,
            pattern_color: Srgb8([0x18, 0x16, 0x14]),
            pattern_amount: 0.5,
            up_rows: 0,
            edge_tone: 0.0,
        }
    }
}

#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct ColorParams {
    /// Base colour of the back (thesis §4.2.1.1).
    pub base: Srgb8,
    /// Strength of the fractal colour variation, 0..1.
    pub variation: f64,
    /// Darkening of the skin between scales, 0..1.
    pub between_scales: f64,
    /// Per-scale brightness jitter (± this fraction, one value per scale).
    pub scale_tone: f64,
    /// Per-scale warm/cool jitter (± this fraction on red against blue, one per scale).
    pub scale_hue: f64,
    /// Scale rims lighter (> 0) or darker (< 0), −1..1.
    pub edge_tone: f64,
    /// Free posterior tips lighter (> 0) or darker (< 0), −1..1.
    pub tip_tone: f64,
    /// Melanophore speckle inside scales: the fraction of fine dot sites that carry a dot.
    pub speckle: f64,
    pub speckle_color: Srgb8,
    /// The colour of the skin between scales where they part; unset keeps the colour
    /// underneath (darkened by `between_scales`).
    pub skin: Option<Srgb8>,
}

impl Default for ColorParams {
    fn default() -> Self {
        ColorParams {
            base: Srgb8([0x5a, 0x6b, 0x3c]),
            variation: 0.15,
            between_scales: 0.35,
            // A few per cent per scale: photographs of any snake show neighbouring scales of
            // one colour differing slightly in tone; 0 gives the flat look of vector art.
            scale_tone: 0.06,
            scale_hue: 0.02,
            edge_tone: 0.0,
            tip_tone: 0.0,
            speckle: 0.0,
            speckle_color: Srgb8([0x16, 0x14, 0x12]),
            skin: None,
        }
    }
}

#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct HeightParams {
    /// Slope of the normal map: surface rise of the full height range, in scale widths.
    pub normal_strength: f64,
    /// Amplitude of fine surface grain added to the height, 0..0.2.
    pub grain: f64,
}

impl Default for HeightParams {
    fn default() -> Self {
        HeightParams { normal_strength: 0.25, grain: 0.02 }
    }
}

#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct RoughnessParams {
    /// Perceptual roughness of a scale's surface (alpha = roughness², as glTF).
    pub base: f64,
    /// Amplitude of fine noise (thesis §4.2.4).
    pub variation: f64,
    /// Extra roughness of the skin between scales.
    pub between_scales: f64,
    /// Extra roughness on keels.
    pub keel: f64,
    /// Random roughness offset per scale (± this much).
    pub per_scale: f64,
}

impl Default for RoughnessParams {
    fn default() -> Self {
        RoughnessParams { base: 0.35, variation: 0.08, between_scales: 0.35, keel: 0.15, per_scale: 0.05 }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case", try_from = "String")]
pub enum IridescenceGradient {
    /// Thicker towards each scale's posterior edge (thesis Fig. 5.4a).
    Vertical,
    /// Thicker towards each scale's centre (thesis Fig. 4.14a, 5.4b).
    Radial,
}

#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct IridescenceParams {
    pub gradient: IridescenceGradient,
    /// Width of the thickness range around `optics.film_thickness_nm`, in nm.
    pub spread_nm: f64,
    /// Strength of the fractal noise (thesis Fig. 5.4c), 0..1.
    pub noise: f64,
}

impl Default for IridescenceParams {
    fn default() -> Self {
        IridescenceParams { gradient: IridescenceGradient::Radial, spread_nm: 200.0, noise: 0.25 }
    }
}

pub use crate::material::{Absorption, Optics};

/// Small head scales or large head shields (`body.head_scales`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case", try_from = "String")]
pub enum HeadScales {
    /// Large symmetrical plates on top of the head (rostral, internasals, prefrontals,
    /// frontal, supraoculars, parietals): most colubrids and elapids.
    Shields,
    /// Small head scales continuing the body's lattice: most vipers, boas and pythons.
    Small,
}

/// A mark on the head or neck (`[[body.head_mark]]`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case", try_from = "String")]
pub enum HeadMarkKind {
    /// The whole top and sides of the head, down to the lips.
    Cap,
    /// The front of the head, to just before the eyes.
    Snout,
    /// A V on top of the head, its apex forward between the eyes (vipers).
    V,
    /// A V with a second, backward V: an X on the crown (Vipera berus).
    X,
    /// A forward-pointing arrowhead between the eyes running onto the neck, solid (a boa's
    /// "thin, dark wedge on the head").
    Spearhead,
    /// Two stripes that meet in a point in front of the eyes and run back over the neck, `size`
    /// neck lengths behind the head (1: to the neck's end, where counted series begin): a corn
    /// snake's "first blotch on the back of the neck splits to form two stripes that run on top
    /// of the head and meet to form the characteristic spearpoint".
    SpearStripes,
    /// A band straight across the top of the head between the eyes, its ends at the eyes
    /// where the postocular stripes start (a milk snake's "transverse band between the
    /// eyes"; with the stripes, a corn snake's stripes through the eyes meeting on top).
    EyeBand,
    /// A band straight across the crown behind the eyes, over the parietals, as wide as the
    /// eye band (a puff adder's "two well-marked dark bands: one on the crown and the other
    /// between the eyes").
    CrownBand,
    /// A stripe from the snout to the eye, each side, ending where the postocular stripe
    /// starts (with it, a line from the snout through the eye to the neck: boas).
    PreocularStripe,
    /// A stripe from behind the eye to the angle of the jaw, each side.
    PostocularStripe,
    /// A round spot just behind the eye, each side, on the postocular stripe's line.
    PostocularSpot,
    /// A band round the neck just behind the head.
    Collar,
    /// Two crescents on the nape, one each side, their horns forward round the back of the
    /// head, parted at the spine (a grass snake's collar).
    Crescents,
    /// The lip scales along both jaws.
    Lips,
}

#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct HeadMark {
    pub kind: HeadMarkKind,
    pub color: Srgb8,
    /// Relative size of the mark (1 the stylised default).
    #[serde(default = "HeadMark::default_size")]
    pub size: f64,
    /// A band just behind the mark in this colour (collars and crescents only: a grass
    /// snake's collar "bordered behind by two black blotches").
    /// Left out of the canonical text (`preset_hash`) where unset, as `border_size` at its
    /// default: a preset without a border keeps the hash, and a batch's job keys, it had
    /// before the keys existed (a review: 23 built-ins' hashes changed, and their batch jobs
    /// ran again).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub border_color: Option<Srgb8>,
    /// The border's width over the mark's own.
    #[serde(default = "HeadMark::default_size", skip_serializing_if = "HeadMark::is_default_size")]
    pub border_size: f64,
}

impl HeadMark {
    pub(crate) fn default_size() -> f64 {
        1.0
    }

    pub(crate) fn is_default_size(size: &f64) -> bool {
        *size == Self::default_size()
    }

    /// Whether this kind draws a `border_color` (a band behind a mark round the neck).
    pub fn takes_border(kind: HeadMarkKind) -> bool {
        matches!(kind, HeadMarkKind::Collar | HeadMarkKind::Crescents)
    }
}

/// The whole snake, snout to tail tip (`[body]`): used by the body layout only; the tile
/// layout ignores it. Lengths are fractions of the total length.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct Body {
    /// Total length over the midbody circumference: the atlas is this many widths long.
    pub length: f64,
    /// Head length over total length.
    pub head_fraction: f64,
    /// Neck (between the head and the trunk) over total length.
    pub neck_fraction: f64,
    /// Tail (vent to tip) over total length.
    pub tail_fraction: f64,
    /// Ventral plates from the end of the head to the vent.
    pub ventrals: u32,
    /// Subcaudal plates (pairs, where divided) from the vent to the tip.
    pub subcaudals: u32,
    /// Subcaudals in pairs, divided at the midline (most snakes), or single (kraits, boas).
    pub divided_subcaudals: bool,
    pub head_scales: HeadScales,
    /// The colour the back shifts to toward the tail (none: no shift).
    pub tail_color: Option<Srgb8>,
    /// Where along the trunk (0 neck .. 1 vent) the shift to `tail_color` starts.
    pub tail_shift_start: f64,
    /// Dark bands round the tail.
    pub tail_bands: u32,
    pub tail_band_color: Srgb8,
    /// Each band's share of its repeat.
    pub tail_band_width: f64,
    /// The bands cross the subcaudals too, round the whole tail (a rattlesnake's "tail
    /// encircled by broad black and white rings"); by default they stop at the belly.
    pub tail_band_over_belly: bool,
    /// The belly's colour over the front of the body, from the snout to `belly_front_end`
    /// (none: the belly is `belly.color` from chin to tail).
    /// This key, `belly_front_end` at its default and `subcaudal_color` are left out of the
    /// canonical text (`preset_hash`) where unset, as a head mark's `border_color` is: a
    /// preset without them keeps the hash, and a batch's job keys, it had before they existed
    /// (every built-in's hash changed, and an identical second jobs file into a folder of
    /// the earlier version's sets was refused: a review).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub belly_front_color: Option<Srgb8>,
    /// Where the front colour gives way to `belly.color`, along the ventral plates (0 the
    /// end of the head, 1 the vent).
    #[serde(skip_serializing_if = "Body::is_default_belly_front_end")]
    pub belly_front_end: f64,
    /// The colour under the tail, the subcaudals from the vent to the tip (none: the
    /// belly's colour).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub subcaudal_color: Option<Srgb8>,
    /// A solid colour over the tail's tip (none: no tip colour).
    pub tip_color: Option<Srgb8>,
    /// The tip colour's share of the tail's length.
    pub tip_fraction: f64,
    #[serde(deserialize_with = "tables")]
    pub head_mark: Vec<HeadMark>,
}

impl Body {
    /// `belly_front_end`'s default.
    const BELLY_FRONT_END: f64 = 0.5;

    fn is_default_belly_front_end(end: &f64) -> bool {
        *end == Self::BELLY_FRONT_END
    }
}

impl Default for Body {
    fn default() -> Self {
        Body {
            length: 12.0,
            head_fraction: 0.04,
            neck_fraction: 0.03,
            tail_fraction: 0.18,
            ventrals: 200,
            subcaudals: 60,
            divided_subcaudals: true,
            head_scales: HeadScales::Shields,
            tail_color: None,
            tail_shift_start: 0.5,
            tail_bands: 0,
            tail_band_color: Srgb8([0x14, 0x12, 0x10]),
            tail_band_width: 0.5,
            tail_band_over_belly: false,
            belly_front_color: None,
            belly_front_end: Self::BELLY_FRONT_END,
            subcaudal_color: None,
            tip_color: None,
            tip_fraction: 0.1,
            head_mark: Vec::new(),
        }
    }
}
