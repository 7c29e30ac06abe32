//! Range checks on a parsed preset, all before any pixel is computed ("parse first, then
//! run"). Each problem names the dotted key and the accepted range; `load` adds the line.

use super::schema::{Arrangement, PatternKind, PatternLayer, PatternShape, Preset, spelled};

/// One value outside what the generator accepts.
#[derive(Debug, Clone, PartialEq)]
pub struct Problem {
    /// Dotted key path, e.g. `optics.film_ior` or `pattern.1.size`.
    pub key: String,
    pub message: String,
    /// The other key of a check across two keys (`pattern.0.amount` for spots too large
    /// for their spacing; `optics.ambient_ior` for a pigment near the ambient; a ring
    /// sequence's `colors`): where `key` is not written in the file (its default), the problem
    /// is placed at this key's line, or said to come from the override that wrote this key.
    /// A preset that set only `ambient_ior` was warned of `optics.pigment_ior` with no line.
    pub second_key: Option<String>,
}

/// How a problem with a required key that is absent begins: such a key has no line of its
/// own, so the message is placed at its table's.
pub const MISSING: &str = "is missing";

/// The accepted ranges, one place, so docs/presets.md and the checks agree.
pub mod ranges {
    /// 2^53 − 1: the manifest and the batch index record the seed as a JSON
    /// number, and JSON readers that hold numbers as doubles (JavaScript, whose
    /// `Number.MAX_SAFE_INTEGER` it is) keep whole numbers exactly only up to there. RFC 7493
    /// (I-JSON) §2.2 asks the same of integers meant to interoperate. 18446744073709551615
    /// came back from `JSON.parse` as 18446744073709552000.
    pub const SEED_MAX: u64 = (1 << 53) - 1;
    pub const ROWS: (u32, u32) = (4, 128);
    pub const SCALE_SIZE: (f64, f64) = (0.5, 2.0);
    pub const SCALE_ASPECT: (f64, f64) = (0.3, 4.0);
    pub const UNIT: (f64, f64) = (0.0, 1.0);
    pub const KEEL_WIDTH: (f64, f64) = (0.01, 0.5);
    pub const JITTER: (f64, f64) = (0.0, 0.5);
    pub const EDGE_SOFTNESS: (f64, f64) = (0.005, 0.5);
    /// Relative row widths: a krait's vertebral row is about twice the others.
    pub const ROW_WIDTH: (f64, f64) = (0.5, 3.0);
    pub const STRIPES_PER_SIDE: (f64, f64) = (1.0, 16.0);
    pub const SPOTS_AROUND: (f64, f64) = (1.0, 64.0);
    pub const RINGS_PER_TILE: (f64, f64) = (1.0, 32.0);
    pub const BLOTCHES_PER_TILE: (f64, f64) = (1.0, 32.0);
    pub const RING_WIDTH: (f64, f64) = (0.0, 1.0);
    /// Down to 0.01 of the spacing: a sparse series of one-scale spots on a fine-scaled
    /// snake (morelia-viridis: ten a side along the body, 53 rows: 0.02) needs a length
    /// share under the 0.05 this once was, which drew them three scales long.
    pub const BLOTCH_LENGTH: (f64, f64) = (0.01, 1.0);
    /// A stripe's share left out: at most 0.6, so that the pieces kept are 1.2 scale lengths
    /// long on average (a gap every three: `maps::color`), and a stripe snapped to scales
    /// keeps most of them (a piece with no scale centre in it is not drawn; at 0.9 whole
    /// stripes went).
    pub const STRIPE_BROKEN: (f64, f64) = (0.0, 0.6);
    pub const PATTERN_SIZE: (f64, f64) = (0.001, 0.5);
    /// A spot's radius in spacings between spots around the body (`size` × the rounded
    /// `amount`). From about 1.2 the jittered round spots cover every point; ring spots still
    /// leave gaps up to about 2 (a mesh of rings). Past it only the time grows, with the
    /// overlap: 16 layers of round spots of radius 19 spacings took 59.9 s for a body atlas
    /// 16 pixels wide; 16 layers of ring spots at 2 spacings 16.6 s (BENCHMARKS.md, "Spots
    /// that cover each point many times over"). The built-in species' spots reach 0.22; a
    /// layer of another kind turned to spots with `--set pattern.N.kind=spots` reaches 1.75
    /// (acanthophis-antarcticus' rings), 1.5 (bitis-arietans' blotches).
    pub const SPOT_RADIUS_SPACINGS: f64 = 2.0;
    pub const PATTERN_OFFSET: (f64, f64) = (0.0, 0.5);
    pub const OUTLINE_SIZE: (f64, f64) = (0.0, 0.1);
    /// A composite mark's centre, as a fraction of the mark.
    pub const CENTER_SIZE: (f64, f64) = (0.05, 0.95);
    pub const BELLY_WIDTH: (f64, f64) = (0.0, 0.6);
    pub const BELLY_BLEND: (f64, f64) = (0.0, 0.2);
    pub const NORMAL_STRENGTH: (f64, f64) = (0.0, 10.0);
    pub const GRAIN: (f64, f64) = (0.0, 0.2);
    pub const ROUGHNESS_VARIATION: (f64, f64) = (0.0, 0.5);
    /// Per-scale tone and hue jitter: ± half the colour at most.
    pub const SCALE_JITTER: (f64, f64) = (0.0, 0.5);
    /// Rim and tip tone: −1 black .. +1 twice as bright.
    pub const SIGNED_UNIT: (f64, f64) = (-1.0, 1.0);
    pub const SPREAD_NM: (f64, f64) = (0.0, 2000.0);
    /// Refractive indices of real dielectrics; 1 is vacuum.
    pub const IOR: (f64, f64) = (1.0, 3.0);
    /// Up to 10 mm, the stress-test bound of PHYSICS.md.
    pub const FILM_THICKNESS_NM: (f64, f64) = (0.0, 1.0e7);
    pub const PIGMENT_THICKNESS: (f64, f64) = (0.0, 100.0);
    /// Angles from the normal of `brdf` queries, degrees.
    pub const ANGLE_DEG: (f64, f64) = (0.0, 90.0);
    /// Vacuum wavelengths a `brdf film` query takes: 1 nm to 1 mm, far past the visible, so
    /// the film can be checked at any wavelength a reference implementation uses.
    pub const QUERY_WAVELENGTH_NM: (f64, f64) = (1.0, 1.0e6);
    pub const ABSORPTION: (f64, f64) = (0.0, 100.0);
    /// Pattern layers per preset: every built-in species needs at most 3; each layer adds
    /// a few full-size buffers and their time.
    pub const MAX_PATTERN_LAYERS: usize = 16;
    /// Colours (and widths) of one layer's ring sequence: a coral-snake triad needs 4.
    pub const MAX_LAYER_COLORS: usize = 32;
    /// Total length over circumference: stout vipers about 6, whipsnakes above 30.
    pub const BODY_LENGTH: (f64, f64) = (4.0, 40.0);
    pub const HEAD_FRACTION: (f64, f64) = (0.01, 0.15);
    pub const NECK_FRACTION: (f64, f64) = (0.0, 0.15);
    pub const TAIL_FRACTION: (f64, f64) = (0.02, 0.5);
    /// What the head, neck and tail ranges leave the trunk at least (the body layout's
    /// regions need one): checked when compiling, so no preset needs a check of the sum.
    pub const TRUNK_FRACTION_AT_LEAST: f64 = 0.2;
    const _: () = assert!(HEAD_FRACTION.1 + NECK_FRACTION.1 + TAIL_FRACTION.1 <= 1.0 - TRUNK_FRACTION_AT_LEAST);
    /// Ventral counts in snakes run from about 100 to over 400.
    pub const VENTRALS: (u32, u32) = (60, 500);
    pub const SUBCAUDALS: (u32, u32) = (5, 250);
    // The scale field's own guards lie outside these ranges (`ops::scales`).
    const _: () = assert!(JITTER.1 as f32 <= crate::ops::scales::JITTER_MAX);
    const _: () = assert!(ROW_WIDTH.0 as f32 >= crate::ops::scales::ROW_WIDTH_FLOOR);
    const _: () = assert!(BELLY_WIDTH.1 as f32 <= crate::ops::scales::BELLY_WIDTH_CEILING);
    const _: () = assert!(EDGE_SOFTNESS.0 as f32 >= crate::ops::scales::EDGE_SOFTNESS_FLOOR);
    pub const TAIL_BANDS: (u32, u32) = (0, 60);
    /// A tail band's share of its repeat: below 1, so bands and the gaps between them both
    /// have a length (`maps::body::marks` keeps its knots in order by it).
    pub const TAIL_BAND_WIDTH: (f64, f64) = (0.05, 0.95);
    /// Marks counted along the trunk.
    pub const MARK_COUNT: (u32, u32) = (1, 200);
    pub const HEAD_MARK_SIZE: (f64, f64) = (0.3, 2.0);
    pub const MAX_HEAD_MARKS: usize = 16;
    /// A counted series' last blotch over its first: a saddle of half-width 0.1 becomes a
    /// band round the body at 5.
    pub const WIDEN_TO_TAIL: (f64, f64) = (0.25, 6.0);
}

#[derive(Default)]
struct Checker {
    problems: Vec<Problem>,
}

impl Checker {
    /// A value of a key that kinds take different sets of (`shape`, `arrangement`), refused
    /// with the layer kind's own list; `note` is added to the message.
    fn one_of<T: PartialEq + serde::Serialize>(
        &mut self,
        key: String,
        kind: PatternKind,
        value: &T,
        accepted: &[T],
        note: &str,
    ) {
        if !accepted.contains(value) {
            let names: Vec<String> = accepted.iter().map(spelled).collect();
            self.problems.push(Problem {
                key,
                message: format!("must be one of {} for kind \"{}\"{note}", names.join(", "), spelled(&kind)),
                second_key: None,
            });
        }
    }

    fn range(&mut self, key: impl Into<String>, value: f64, (lo, hi): (f64, f64)) {
        if !(value.is_finite() && (lo..=hi).contains(&value)) {
            self.problems.push(Problem {
                key: key.into(),
                message: format!("must be a finite number in [{lo}, {hi}], got {}", shown(value)),
                second_key: None,
            });
        }
    }

    /// A count written as a number (a pattern layer's `amount` for the kinds that count
    /// marks): in its range and whole. A fraction was rounded where the marks are drawn,
    /// without a word (`amount = 2.4` stripes drew 2, 7.5 spots 8: a hostile-input sweep),
    /// as `rows = 19.5` is refused. Out of its range or not whole is one problem, in the same
    /// words (16.5 stripes had only the range's, and 15.5 was refused next).
    fn whole_count(&mut self, key: impl Into<String>, value: f64, range: (f64, f64), counted: &str) {
        if !is_whole_in(value, range) {
            self.problems.push(Problem {
                key: key.into(),
                message: format!(
                    "must be a whole number of {counted} in [{}, {}], got {}",
                    range.0,
                    range.1,
                    shown(value)
                ),
                second_key: None,
            });
        }
    }

    /// A whole-number key against its range (`whole_number_range`; `rows`: the preset's
    /// `scales.rows`, which bounds the keys counted in half its rows).
    fn whole_number(&mut self, key: &str, value: u32, rows: u32) {
        let range = match whole_number_range(key) {
            Some(WholeRange::Fixed(range)) => range,
            // With `rows = 1`, a file's `belly.up_rows = 1` was refused too, against [0, 0].
            Some(WholeRange::HalfTheRows) => (0, rows_bounding(rows) / 2),
            Some(WholeRange::Seed) | None => unreachable!("{key} is not a u32 key of whole_number_range's table"),
        };
        self.int_range(key, value, range);
    }

    fn int_range(&mut self, key: &str, value: u32, (lo, hi): (u32, u32)) {
        if !(lo..=hi).contains(&value) {
            self.problems.push(Problem {
                key: key.into(),
                message: format!("must be an integer in [{lo}, {hi}], got {value}"),
                second_key: None,
            });
        }
    }
}

/// Whether a count written as a number is whole and within `(lo, hi)` (`Checker::whole_count`;
/// the checks that read the count run only then, so that a refused count is not refused
/// again as the count it rounds to).
fn is_whole_in(value: f64, (lo, hi): (f64, f64)) -> bool {
    value.is_finite() && (lo..=hi).contains(&value) && value.fract() == 0.0
}

/// The row count the keys `scales.rows` bounds (`WholeRange::HalfTheRows`, a stripe's
/// `rows`) are checked against: the preset's, or the most rows allowed where its count is
/// out of range (then that is the one problem, not every key it bounds).
fn rows_bounding(rows: u32) -> u32 {
    if (ranges::ROWS.0..=ranges::ROWS.1).contains(&rows) { rows } else { ranges::ROWS.1 }
}

/// What a preset that loads does not do as its keys seem to say, one warning each: the
/// model's limits (`pigment_below_ambient`, `pigment_near_ambient`, `film_below_ambient`) and a film centred too
/// thin for its spread (`film_floor`).
pub fn warnings(preset: &Preset) -> Vec<Problem> {
    pigment_below_ambient(preset)
        .into_iter()
        .chain(pigment_near_ambient(preset))
        .chain(film_below_ambient(preset))
        .chain(film_floor(preset))
        .chain(rings_not_kept_apart(preset))
        .collect()
}

/// Rings drawn in whole scales are sure to stay closed round the body and apart only when
/// each band (and the gap) is a few scale rows long (`maps::color::rings_of_whole_scales`);
/// with more repeats than the rows allow every band takes an equal share, and past about one
/// more repeat red met black, without a word (a coral snake's `amount = 4`, `count = 60`;
/// found by a hostile-input sweep). A warning, not a refusal: the rows asked for are a
/// worst case (the largest jittered scale at its worst angle), and one or two repeats past
/// them often still hold (measured: `tests/rings.rs`).
fn rings_not_kept_apart(preset: &Preset) -> Vec<Problem> {
    crate::maps::ring_layers_that_do_not_fit(preset)
        .into_iter()
        .map(|(i, layout, rows)| {
            let layer = &preset.pattern[i];
            let most = rows.most_repeats();
            let (key, value, keep) = match (layout, layer.count) {
                (crate::maps::Layout::Tile, _) => {
                    ("amount", shown(layer.amount), (most >= 1).then(|| format!("at most {most} per tile keep them")))
                }
                (crate::maps::Layout::Body, Some(count)) => (
                    "count",
                    count.to_string(),
                    (most >= 1).then(|| format!("at most {most} along the trunk keep them")),
                ),
                // The body repeats an uncounted layer round(amount) × length times, rounded
                // (`Shared::along_count`): the largest whole amount whose repeats are at most
                // `most`.
                (crate::maps::Layout::Body, None) => {
                    let length = preset.body.length;
                    let repeats = |a: u32| crate::maps::along_repeats(a, length as f32);
                    let largest = (1..=ranges::RINGS_PER_TILE.1 as u32).take_while(|a| repeats(*a) <= most).last();
                    let keep = largest.map(|a| {
                        format!(
                            "`amount` {a} or less keeps them ({} repeats along the body atlas at `body.length` {})",
                            repeats(a),
                            shown(length)
                        )
                    });
                    ("amount", format!("{} on the body atlas", shown(layer.amount)), keep)
                }
            };
            let keep = keep.unwrap_or_else(|| {
                "not one repeat keeps them: fewer colours, or larger scales (fewer `scales.rows`)".into()
            });
            let gap = if rows.gap { " and the gap between repeats" } else { "" };
            Problem {
                key: format!("pattern.{i}.{key}"),
                message: format!(
                    "{value} leaves {} scale rows to each repeat of this ring sequence drawn in whole scales \
                     (`scale_aligned = 1`), whose {} bands (its colours{gap}) need {} rows each to be sure to stay \
                     closed round the body and apart ({} in all): they are drawn at equal widths, and rings may \
                     break or touch; {keep}, or draw it free of the scales (`scale_aligned` below 1)",
                    shown((rows.per_repeat as f64 * 100.0).floor() / 100.0),
                    rows.bands,
                    shown((rows.per_band as f64 * 100.0).ceil() / 100.0),
                    shown((rows.bands as f64 * rows.per_band as f64 * 100.0).ceil() / 100.0),
                ),
                // The ring sequence's colours, which the bands are (an `amount` at its default
                // had no line: an independent review).
                second_key: Some(format!("pattern.{i}.colors")),
            }
        })
        .collect()
}

/// An ambient so much denser than the pigment layer that the layered model lets out more
/// light than arrives (`PigmentBelowAmbient`), over the thickness map's films and the
/// roughness map's range. A warning: the physics is fine (an oil film over a lighter layer).
fn pigment_below_ambient(preset: &Preset) -> Option<Problem> {
    let o = &preset.optics;
    let stack = crate::optics::film::Stack { n0: o.ambient_ior, n1: o.film_ior, n2: o.pigment_ior };
    let thickness = crate::maps::map_thickness_range_nm(preset);
    let roughness = crate::maps::roughness_range(preset);
    let limit = crate::optics::brdf::layered::PigmentBelowAmbient::of(stack, thickness, roughness)?;
    Some(Problem {
        key: "optics.ambient_ior".into(),
        message: format!(
            "{} is above optics.pigment_ior = {}: {limit}. Keep ambient_ior at most pigment_ior, or from about \
             1.03 to 1.35 times it, for an energy-conserving render.",
            o.ambient_ior, o.pigment_ior
        ),
        // The ambient's index is always written here: above the pigment's, whose least (1)
        // is the ambient's default.
        second_key: None,
    })
}

/// A pigment layer as dense as the ambient or just denser, under a film and a rough top:
/// the layered model misreads the light the top sends straight back (`PigmentNearAmbient`),
/// for the thickness map's thickest film and the roughness map's roughest top. A warning:
/// the physics is fine (a snake's skin under water of about its index).
fn pigment_near_ambient(preset: &Preset) -> Option<Problem> {
    let o = &preset.optics;
    if !crate::maps::has_film(preset) {
        return None;
    }
    let stack = crate::optics::film::Stack { n0: o.ambient_ior, n1: o.film_ior, n2: o.pigment_ior };
    let thickest_nm = crate::maps::map_thickness_range_nm(preset).1;
    let roughest = crate::maps::roughness_range(preset).1;
    let limit = crate::optics::brdf::layered::PigmentNearAmbient::of(stack, thickest_nm, roughest)?;
    Some(Problem {
        key: "optics.pigment_ior".into(),
        message: format!(
            "{} is near optics.ambient_ior = {}: {limit}. Keep pigment_ior at least {} times ambient_ior (or \
             ambient_ior over {} times pigment_ior) for an accurate render of a rough film.",
            o.pigment_ior,
            o.ambient_ior,
            crate::optics::brdf::layered::PIGMENT_NEAR_AMBIENT,
            crate::optics::brdf::layered::PIGMENT_NEAR_AMBIENT_BELOW
        ),
        second_key: Some("optics.ambient_ior".into()),
    })
}

/// A film whose index is below the ambient's, where it shows: the layered model's energy is
/// off near the film's critical angle (`FilmBelowAmbient`), for the thickest film of the
/// thickness map's range under a nearly smooth top within the roughness map's range. A
/// warning: the physics is fine.
fn film_below_ambient(preset: &Preset) -> Option<Problem> {
    let o = &preset.optics;
    if !crate::maps::has_film(preset) {
        return None;
    }
    let thickest_nm = crate::maps::map_thickness_range_nm(preset).1;
    let roughness = crate::maps::roughness_range(preset);
    let limit = crate::optics::brdf::layered::FilmBelowAmbient::of(o.ambient_ior, o.film_ior, thickest_nm, roughness)?;
    Some(Problem {
        key: "optics.film_ior".into(),
        message: format!(
            "{} is below optics.ambient_ior = {}: {limit}. Keep film_ior at least ambient_ior for an \
             energy-conserving render.",
            o.film_ior, o.ambient_ior
        ),
        second_key: Some("optics.ambient_ior".into()),
    })
}

/// A film thickness below half the spread: the range cannot reach below 0 nm, so it starts
/// at 0 (`material::thickness_range_nm`) and every δ0 up to spread / 2 gives the same maps
/// (a user sweeping δ0 from 0 saw nothing change, and no word of why).
fn film_floor(preset: &Preset) -> Option<Problem> {
    let (thickness, spread) = (preset.optics.film_thickness_nm, preset.iridescence.spread_nm);
    let (min_nm, max_nm) = crate::material::thickness_range_nm(thickness, spread);
    (thickness < spread * 0.5).then(|| Problem {
        key: "optics.film_thickness_nm".into(),
        message: format!(
            "{} is below half of iridescence.spread_nm ({} / 2 = {}): a film cannot be thinner than 0 nm, so its \
             range is {}-{} nm, the same for any film_thickness_nm up to {}",
            // `shown`: 1e-320 printed as 330 digits (a hostile-input sweep).
            shown(thickness),
            shown(spread),
            shown(spread * 0.5),
            shown(min_nm),
            shown(max_nm),
            shown(spread * 0.5)
        ),
        second_key: Some("iridescence.spread_nm".into()),
    })
}

/// The range of a whole-number key.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum WholeRange {
    Fixed((u32, u32)),
    /// 0 to half of `scales.rows` (rows that change, counted from the spine or the belly).
    HalfTheRows,
    /// 0 to `ranges::SEED_MAX` (`seed`, a u64).
    Seed,
}

/// The range of every whole-number key, one table for the range checks and for a value the
/// key's type cannot hold (`-3`, `5000000000`), which the reader refuses before any check:
/// it said "expected a whole number from 0 to 4294967295", the type's range, not the key's.
pub fn whole_number_range(key: &str) -> Option<WholeRange> {
    use ranges::*;
    Some(match key {
        "seed" => WholeRange::Seed,
        "scales.rows" => WholeRange::Fixed(ROWS),
        "scales.smooth_rows" | "belly.up_rows" => WholeRange::HalfTheRows,
        "body.ventrals" => WholeRange::Fixed(VENTRALS),
        "body.subcaudals" => WholeRange::Fixed(SUBCAUDALS),
        "body.tail_bands" => WholeRange::Fixed(TAIL_BANDS),
        layer if layer.starts_with("pattern.") && layer.ends_with(".count") => WholeRange::Fixed(MARK_COUNT),
        _ => return None,
    })
}

/// The range check's words for a whole number the key's type cannot hold (`value`: as
/// written), or None for a key that is not a whole number's.
pub fn whole_number_problem(key: &str, value: &str) -> Option<String> {
    Some(format!("must be an integer in {}, got {value}", whole_number_range_words(key)?))
}

/// A whole-number key's range as messages write it (`[4, 128]`), or None for another key.
pub fn whole_number_range_words(key: &str) -> Option<String> {
    Some(match whole_number_range(key)? {
        WholeRange::Fixed((lo, hi)) => format!("[{lo}, {hi}]"),
        WholeRange::HalfTheRows => "[0, scales.rows / 2]".to_string(),
        WholeRange::Seed => seed_range_words(),
    })
}

/// The seed's range as messages write it: `[0, 9007199254740991]`.
pub fn seed_range_words() -> String {
    format!("[0, {}]", ranges::SEED_MAX)
}

/// Every out-of-range value in the preset (empty when it is valid). `overridden(key)`:
/// whether an override (`--set`, a jobs file's `set`) wrote the dotted key. A key the file
/// wrote for what an override then changed is passed over rather than refused: layer i's
/// key while its kind came from `--set` (`--set pattern.0.kind=spots` on a preset of blotches
/// keeps their `length`, `shape` and `count`, which spots do not read), a body key while the
/// key it shapes was overridden (`--set body.tail_bands=0` on a preset with banded tails);
/// the same key written by an override is refused.
pub fn validate(preset: &Preset, overridden: &dyn Fn(&str) -> bool) -> Vec<Problem> {
    use ranges::*;
    // Whether `key` is the file's while `partner`, which it belongs to, was overridden.
    let from_file_for_overridden = |key: &str, partner: &str| overridden(partner) && !overridden(key);
    let from_file_for_old_kind =
        |i: usize, key: &str| from_file_for_overridden(&format!("pattern.{i}.{key}"), &format!("pattern.{i}.kind"));
    let mut c = Checker::default();
    if preset.seed > SEED_MAX {
        c.problems.push(Problem {
            key: "seed".into(),
            message: format!(
                "must be an integer in {}, got {} (2^53 - 1: the files record the seed as a JSON number, which \
                 JavaScript and other readers hold exactly only up to there)",
                seed_range_words(),
                preset.seed
            ),
            second_key: None,
        });
    }
    let s = &preset.scales;
    c.whole_number("scales.rows", s.rows, s.rows);
    c.range("scales.size", s.size, SCALE_SIZE);
    c.range("scales.aspect", s.aspect, SCALE_ASPECT);
    c.range("scales.keel_height", s.keel_height, UNIT);
    c.range("scales.keel_width", s.keel_width, KEEL_WIDTH);
    c.range("scales.jitter", s.jitter, JITTER);
    c.range("scales.imbrication", s.imbrication, UNIT);
    c.range("scales.edge_softness", s.edge_softness, EDGE_SOFTNESS);
    c.range("scales.vertebral_width", s.vertebral_width, ROW_WIDTH);
    c.range("scales.lowest_row_width", s.lowest_row_width, ROW_WIDTH);
    // At most half the rows each side: the rows from one side's plates to the spine.
    c.whole_number("scales.smooth_rows", s.smooth_rows, s.rows);

    if preset.pattern.len() > MAX_PATTERN_LAYERS {
        c.problems.push(Problem {
            key: "pattern".into(),
            message: format!("has {} layers; at most {MAX_PATTERN_LAYERS} are accepted", preset.pattern.len()),
            second_key: None,
        });
        // Checking ten thousand layers one by one only buries this message.
        return c.problems;
    }
    for (i, p) in preset.pattern.iter().enumerate() {
        let key = |field: &str| format!("pattern.{i}.{field}");
        for (field, count) in [("colors", p.colors.len()), ("widths", p.widths.len())] {
            if count > MAX_LAYER_COLORS {
                c.problems.push(Problem {
                    key: key(field),
                    message: format!("has {count} entries; at most {MAX_LAYER_COLORS} are accepted"),
                    second_key: None,
                });
            }
        }
        if p.colors.len() > MAX_LAYER_COLORS || p.widths.len() > MAX_LAYER_COLORS {
            continue;
        }
        match p.kind {
            PatternKind::Stripes => c.whole_count(key("amount"), p.amount, STRIPES_PER_SIDE, "stripes a side"),
            PatternKind::Spots => {
                let counted = if p.rows.is_empty() { "spots around the body" } else { "columns of spots a side" };
                c.whole_count(key("amount"), p.amount, SPOTS_AROUND, counted)
            }
            PatternKind::Rings => c.whole_count(key("amount"), p.amount, RINGS_PER_TILE, "repeats per tile"),
            PatternKind::Blotches => {
                let counted = if p.shape == PatternShape::Zigzag { "zigzags per tile" } else { "blotches per tile" };
                c.whole_count(key("amount"), p.amount, BLOTCHES_PER_TILE, counted)
            }
            PatternKind::Irregular | PatternKind::Solid => c.range(key("amount"), p.amount, UNIT),
        }
        let shapes: &[PatternShape] = match p.kind {
            PatternKind::Spots => PatternShape::FOR_SPOTS,
            PatternKind::Blotches => PatternShape::FOR_BLOTCHES,
            // Another kind reads no shape: `kinds_only` below says so.
            _ => &[],
        };
        if !shapes.is_empty() && !from_file_for_old_kind(i, "shape") {
            c.one_of(key("shape"), p.kind, &p.shape, shapes, "");
        }
        // Blotches take the two series' `aligned` and `alternating`; `checkered` (every other
        // cell of a grid) is the spots' own, and on blotches it was silently `aligned`. Both
        // kinds read the key, so a file's `checkered` for spots is refused on a layer `--set`
        // made blotches too (passing it over would have drawn it as `aligned` all the same).
        if p.kind == PatternKind::Blotches {
            let note =
                " (checkered is the spots' arrangement; with --set pattern.N.kind=blotches, set its arrangement too)";
            c.one_of(
                key("arrangement"),
                p.kind,
                &p.arrangement,
                &[Arrangement::Aligned, Arrangement::Alternating],
                note,
            );
        }
        // A stripe placed twice: `rows` places it and sets its width and count, and
        // `position` sets its offset, so the keys they replace were silently ignored beside
        // them (`position = "lateral"` with `offset = 0.1` drew the lateral stripe).
        if p.kind == Stripes {
            // (key, set away from its default, the key that replaces it, its default)
            let by_rows = !p.rows.is_empty();
            // The default, where the key has one, counts as unset, and `rows = []` as no rows:
            // `--set` cannot take a file's key away, but can give it these (an onboarding
            // review found no way from the command line; a later one, `rows = []`).
            let away = |value: f64, default: f64| (value != default, Some(default));
            let replaced = [
                ("offset", away(p.offset, 0.0), if by_rows { Some("rows") } else { p.position.map(|_| "position") }),
                ("position", (p.position.is_some(), None), by_rows.then_some("rows")),
                ("size", away(p.size, PatternLayer::default_size()), by_rows.then_some("rows")),
                ("amount", away(p.amount, PatternLayer::default_amount()), by_rows.then_some("rows")),
            ];
            for (field, (set, default), by) in replaced {
                // No pass for a file's key under a kind `--set` changed (as `kinds_only` gives):
                // stripes read every one of these keys, so it would be dropped silently (the
                // blotches' `arrangement` is refused the same way, above).
                if let Some(by) = by.filter(|_| set) {
                    let what = if by == "rows" {
                        "places the stripe and sets its width and count"
                    } else {
                        "places the stripe at a named offset"
                    };
                    let mut ways: Vec<String> =
                        default.map(|d| format!("its default, {d}, counts as none")).into_iter().collect();
                    if by == "rows" {
                        ways.push("`rows = []` counts as no rows".into());
                    }
                    let unset = if ways.is_empty() { String::new() } else { format!(" ({})", ways.join("; ")) };
                    c.problems.push(Problem {
                        key: key(field),
                        message: format!(
                            "is replaced by this layer's `{by}`, which {what}; give one of the two{unset}"
                        ),
                        second_key: None,
                    });
                }
            }
        }
        // Every layer draws its `color` but a rings layer with `colors`, which need not name
        // one it would not draw.
        if p.reads_color() && p.color.is_none() {
            let or_rings = if p.kind == PatternKind::Rings { " (or a sequence of rings in `colors`)" } else { "" };
            c.problems.push(Problem {
                key: key("color"),
                message: format!("{MISSING}: give the layer's colour as \"#rrggbb\"{or_rings}"),
                second_key: None,
            });
        }
        // A ring sequence's widths are its colours' (`widths`, or equal parts), so a ring
        // `size` beside `colors` was silently ignored (the same bytes as without it).
        if p.kind == PatternKind::Rings && !p.colors.is_empty() && p.size != PatternLayer::default_size() {
            c.problems.push(Problem {
                key: key("size"),
                message: format!(
                    "is replaced by this layer's `colors`, whose rings take the repeat in `widths` (or in equal \
                     parts); give one of the two (a size of {}, the default, counts as none)",
                    PatternLayer::default_size()
                ),
                second_key: None,
            });
        }
        // Keys some kinds read, set away from their defaults on a kind that ignores them
        // (`colors` on spots, `phase` on stripes, `size` on solid, `center_size` on stripes
        // were silently dropped; `shape`, `count` and `rows` were refused already). A
        // default value changes nothing.
        let k = p.kind;
        use PatternKind::{Blotches, Irregular, Rings, Spots, Stripes};
        let marked = &[Stripes, Rings, Spots, Blotches, Irregular][..];
        let kinds_only: [(&str, bool, &[PatternKind]); 16] = [
            ("shape", p.shape != PatternLayer::default_shape(), &[Spots, Blotches]),
            ("rows", !p.rows.is_empty(), &[Stripes, Spots]),
            ("size", p.size != PatternLayer::default_size(), marked),
            ("edge_distortion", p.edge_distortion != PatternLayer::default_edge_distortion(), marked),
            ("center_size", p.center_size != PatternLayer::default_center_size(), &[Spots, Blotches]),
            ("colors", !p.colors.is_empty(), &[Rings]),
            ("widths", !p.widths.is_empty(), &[Rings]),
            ("noise", p.noise != PatternLayer::default_noise(), &[Irregular]),
            ("position", p.position.is_some(), &[Stripes]),
            ("offset", p.offset != 0.0, &[Stripes, Blotches]),
            ("arrangement", p.arrangement != PatternLayer::default_arrangement(), &[Spots, Blotches]),
            ("phase", p.phase != 0.0, &[Blotches]),
            ("length", p.length != PatternLayer::default_length(), &[Blotches]),
            ("center_color", p.center_color.is_some(), &[Spots, Blotches]),
            ("widen_to_tail", p.widen_to_tail != PatternLayer::default_widen_to_tail(), &[Blotches]),
            ("broken", p.broken != 0.0, &[Stripes]),
        ];
        for (field, set, kinds) in kinds_only {
            if set && !kinds.contains(&k) && !from_file_for_old_kind(i, field) {
                let names: Vec<String> = kinds.iter().map(|k| format!("\"{}\"", spelled(k))).collect();
                let (last, rest) = names.split_last().expect("a key some kind reads");
                let names = if rest.is_empty() { last.clone() } else { format!("{} and {last}", rest.join(", ")) };
                c.problems.push(Problem {
                    key: key(field),
                    message: format!(
                        "is read by kind {names} only, not \"{}\"; leave it out of this layer",
                        spelled(&k)
                    ),
                    second_key: None,
                });
            }
        }
        // A size of something only its colour draws, without the colour (the review found
        // `center_size` alone silently ignored); on a kind that draws no centre the kind's
        // problem above says enough.
        let draws_centre = matches!(k, Spots | Blotches);
        for (field, set, colour, coloured) in [
            (
                "center_size",
                draws_centre && p.center_size != PatternLayer::default_center_size(),
                "center_color",
                p.center_color.is_some(),
            ),
            (
                "border_size",
                p.border_size != PatternLayer::default_border_size(),
                "border_color",
                p.border_color.is_some(),
            ),
        ] {
            if set && !coloured && !from_file_for_old_kind(i, field) {
                c.problems.push(Problem {
                    key: key(field),
                    message: format!(
                        "sizes what `{colour}` draws, which this layer does not set; set it, or leave this out"
                    ),
                    second_key: None,
                });
            }
        }
        for (j, w) in p.widths.iter().enumerate() {
            c.range(format!("pattern.{i}.widths.{j}"), *w, RING_WIDTH);
        }
        if !p.widths.is_empty() && p.widths.len() != p.colors.len() {
            c.problems.push(Problem {
                key: key("widths"),
                message: format!(
                    "must list one width per colour of `colors` ({} colours, {} widths)",
                    p.colors.len(),
                    p.widths.len()
                ),
                second_key: None,
            });
        }
        // The sum of widths each in range (one out of it is its own problem, not the sum's).
        let widths_in_range = p.widths.iter().all(|w| (RING_WIDTH.0..=RING_WIDTH.1).contains(w));
        if widths_in_range && p.widths.iter().sum::<f64>() > 1.0 + 1e-9 {
            c.problems.push(Problem {
                key: key("widths"),
                message: "must sum to at most 1 (one repeat)".into(),
                second_key: None,
            });
        }
        c.range(key("scale_aligned"), p.scale_aligned, UNIT);
        c.range(key("broken"), p.broken, STRIPE_BROKEN);
        c.range(key("phase"), p.phase, UNIT);
        c.range(key("center_size"), p.center_size, CENTER_SIZE);
        c.range(key("border_size"), p.border_size, OUTLINE_SIZE);
        let rows = rows_bounding(preset.scales.rows);
        let top = (rows as f64 + 1.0) / 2.0;
        let rows_ok = p.rows.len() == 2
            && p.rows.iter().all(|r| r.is_finite())
            && 0.5 <= p.rows[0]
            && p.rows[0] <= p.rows[1]
            && p.rows[1] <= top;
        if !p.rows.is_empty() && matches!(p.kind, PatternKind::Stripes | PatternKind::Spots) && !rows_ok {
            c.problems.push(Problem {
                key: key("rows"),
                message: format!(
                    "must be [first, last] dorsal rows with 0.5 ≤ first ≤ last ≤ {top} (the vertebral row of {} \
                     rows); got {}",
                    rows,
                    // A long list is counted, not echoed back whole.
                    if p.rows.len() <= 4 { format!("{:?}", p.rows) } else { format!("{} entries", p.rows.len()) }
                ),
                second_key: None,
            });
        }
        c.range(key("length"), p.length, BLOTCH_LENGTH);
        c.range(key("size"), p.size, PATTERN_SIZE);
        // Spots' radius against their spacing: what the two ranges above allow together
        // (0.5 with 64 around) covers each point thousands of times. Checked only where both
        // are in their ranges (a size already refused is not refused twice). On a band of
        // `rows` the spots lie as far apart as the band's width over `amount`, along the body
        // too (`maps::spot_spacing`): 64 over the lowest row of 19 (0.04 of the
        // circumference) at size 0.03 put 48 spacings in a radius, and a body atlas 64 pixels
        // wide took 37 s (a review found the check counting `amount` round the body).
        let around = p.amount;
        let in_ranges = is_whole_in(around, SPOTS_AROUND) && (PATTERN_SIZE.0..=PATTERN_SIZE.1).contains(&p.size);
        let scale_rows_in_range = (ROWS.0..=ROWS.1).contains(&preset.scales.rows);
        if p.kind == PatternKind::Spots && in_ranges && (p.rows.is_empty() || (rows_ok && scale_rows_in_range)) {
            let lattice = crate::maps::scale_field(preset, crate::maps::Layout::Tile).lattice();
            let (across, band, per_circumference) = crate::maps::spot_spacing(&lattice, p);
            // On a band the spots are as dense along the body as across it: 64 over the
            // lowest of 19 rows made 1,600 rows of them a circumference, 204,800 spots (both
            // sides) in a stretch one circumference long where 64 round the body make 4,096,
            // and a body atlas 16 px wide took 5.7 s at the largest radius the check below
            // allows (a review). At most that many.
            let most_spots = SPOTS_AROUND.1 * SPOTS_AROUND.1;
            let density = |across: u32, per_circumference: u32| 2.0 * f64::from(across) * f64::from(per_circumference);
            if band.is_some() && density(across, per_circumference) > most_spots {
                let fewer = (1..across).rev().find(|&n| {
                    let fewer = PatternLayer { amount: f64::from(n), ..p.clone() };
                    let (n, _, along) = crate::maps::spot_spacing(&lattice, &fewer);
                    density(n, along) <= most_spots
                });
                c.problems.push(Problem {
                    key: key("amount"),
                    message: format!(
                        "is {around} spots across rows [{}, {}] each side, {per_circumference} rows of them a \
                         circumference along the body (spots lie as far apart along it as across the band): {} spots in \
                         a stretch one circumference long, more than the {most_spots} that {} round the body make; at \
                         most {} across these rows",
                        shown(p.rows[0]),
                        shown(p.rows[1]),
                        density(across, per_circumference),
                        SPOTS_AROUND.1,
                        fewer.unwrap_or(1),
                    ),
                    second_key: None,
                });
            }
            let per_circumference = f64::from(per_circumference);
            let most = SPOT_RADIUS_SPACINGS / per_circumference;
            if p.size > most {
                let spacing = match band {
                    Some(_) => format!(
                        "{around} spots across rows [{}, {}] (`amount`, `rows`), {per_circumference} per circumference",
                        shown(p.rows[0]),
                        shown(p.rows[1])
                    ),
                    None => format!("{around} spots around (`amount`)"),
                };
                c.problems.push(Problem {
                    key: key("size"),
                    message: format!(
                        "is {} with {spacing}, a radius of {} spacings between spots; at most \
                         {SPOT_RADIUS_SPACINGS} spacings are accepted (size ≤ {} at this spacing): larger spots \
                         overlap each point more than a dozen deep (for a layer that covers the skin, use kind \
                         \"solid\")",
                        shown(p.size),
                        // Rounded up, so a radius just past the limit does not print as the limit.
                        shown((p.size * per_circumference * 1e3).ceil() / 1e3),
                        // Rounded down, so the number printed is itself accepted.
                        shown((most * 1e4).floor() / 1e4)
                    ),
                    second_key: Some(key("amount")),
                });
            }
        }
        // Stripes are three widths apart from `offset` out (`maps::stripe_distances`): one
        // whose edge passes the belly's midline (half the circumference from the spine)
        // wraps round onto the other side's stripes (16 a side at the default size covered
        // the whole body, without a word; found by a hostile-input sweep). A single stripe
        // there only meets its own mirror image (under the belly, by default): not refused.
        // Checked only where the keys are in their ranges, and not for stripes placed by
        // `rows`.
        let per_side = p.amount.round();
        let offset = p.position.map_or(p.offset, |q| q.offset());
        let stripes_in_ranges = is_whole_in(p.amount, STRIPES_PER_SIDE)
            && (PATTERN_SIZE.0..=PATTERN_SIZE.1).contains(&p.size)
            && (PATTERN_OFFSET.0..=PATTERN_OFFSET.1).contains(&offset);
        if p.kind == PatternKind::Stripes && p.rows.is_empty() && stripes_in_ranges && per_side >= 2.0 {
            let edges: Vec<f32> = crate::maps::stripe_distances(p).map(|d| d + 0.5 * p.size as f32).collect();
            let outer_edge = edges.last().copied().unwrap_or(0.0);
            if outer_edge > 0.5 + 1e-6 {
                let most = edges.iter().filter(|edge| **edge <= 0.5 + 1e-6).count().max(1);
                c.problems.push(Problem {
                    key: key("amount"),
                    message: format!(
                        "is {per_side} stripes a side, three widths ({}) apart from {} off the spine: the outermost \
                         reaches {} of the circumference from the spine, past the belly's midline (0.5), where it \
                         meets the other side's; at most {most} a side fit at this size and offset (for a layer \
                         that covers the skin, use kind \"solid\")",
                        shown((3.0 * p.size * 1e4).round() / 1e4),
                        shown(offset),
                        shown((f64::from(outer_edge) * 1e3).ceil() / 1e3),
                    ),
                    // `amount` is always written here (two stripes or more; its default is 1).
                    second_key: None,
                });
            }
        }
        c.range(key("offset"), p.offset, PATTERN_OFFSET);
        c.range(key("outline_size"), p.outline_size, OUTLINE_SIZE);
        c.range(key("edge_distortion"), p.edge_distortion, UNIT);
        c.range(key("opacity"), p.opacity, UNIT);
        c.range(key("widen_to_tail"), p.widen_to_tail, WIDEN_TO_TAIL);
        if let Some(count) = p.count {
            c.whole_number(&key("count"), count, s.rows);
            if p.series_count().is_none() && !from_file_for_old_kind(i, "count") {
                c.problems.push(Problem {
                    key: key("count"),
                    message: format!(
                        "counts marks of kind \"blotches\" or \"rings\" only, not \"{}\"",
                        spelled(&p.kind)
                    ),
                    second_key: None,
                });
            }
        }
    }

    c.range("belly.width", preset.belly.width, BELLY_WIDTH);
    c.range("belly.blend", preset.belly.blend, BELLY_BLEND);
    c.range("belly.edge_tone", preset.belly.edge_tone, SIGNED_UNIT);
    c.range("belly.pattern_amount", preset.belly.pattern_amount, UNIT);
    c.whole_number("belly.up_rows", preset.belly.up_rows, s.rows);
    c.range("color.variation", preset.color.variation, UNIT);
    c.range("color.between_scales", preset.color.between_scales, UNIT);
    c.range("color.scale_tone", preset.color.scale_tone, SCALE_JITTER);
    c.range("color.scale_hue", preset.color.scale_hue, SCALE_JITTER);
    c.range("color.edge_tone", preset.color.edge_tone, SIGNED_UNIT);
    c.range("color.tip_tone", preset.color.tip_tone, SIGNED_UNIT);
    c.range("color.speckle", preset.color.speckle, UNIT);
    c.range("height.normal_strength", preset.height.normal_strength, NORMAL_STRENGTH);
    c.range("height.grain", preset.height.grain, GRAIN);
    let r = &preset.roughness;
    c.range("roughness.base", r.base, UNIT);
    c.range("roughness.variation", r.variation, ROUGHNESS_VARIATION);
    c.range("roughness.between_scales", r.between_scales, UNIT);
    c.range("roughness.keel", r.keel, UNIT);
    c.range("roughness.per_scale", r.per_scale, ROUGHNESS_VARIATION);
    c.range("iridescence.spread_nm", preset.iridescence.spread_nm, SPREAD_NM);
    c.range("iridescence.noise", preset.iridescence.noise, UNIT);

    let b = &preset.body;
    c.range("body.length", b.length, BODY_LENGTH);
    c.range("body.head_fraction", b.head_fraction, HEAD_FRACTION);
    c.range("body.neck_fraction", b.neck_fraction, NECK_FRACTION);
    c.range("body.tail_fraction", b.tail_fraction, TAIL_FRACTION);
    // The ranges leave the trunk at least 0.2 of the length (`TRUNK_FRACTION_AT_LEAST`). A
    // check of the sum here fired only beside a fraction out of its range, and named
    // `body.tail_fraction` when the user had set `head_fraction`.
    c.whole_number("body.ventrals", b.ventrals, s.rows);
    c.whole_number("body.subcaudals", b.subcaudals, s.rows);
    c.range("body.tail_shift_start", b.tail_shift_start, UNIT);
    c.whole_number("body.tail_bands", b.tail_bands, s.rows);
    c.range("body.tail_band_width", b.tail_band_width, TAIL_BAND_WIDTH);
    c.range("body.tip_fraction", b.tip_fraction, UNIT);
    c.range("body.belly_front_end", b.belly_front_end, UNIT);
    // A key that shapes what another draws, without that other (the review found
    // `tail_band_width` without `tail_bands`, `tip_fraction` without `tip_color` and
    // `up_rows` without `plates` passing silently, where a pattern layer refuses a key its
    // kind does not read). A key at its default is not told apart from one left out; one the
    // file wrote is passed over where an override turned its partner off (`--set
    // body.tail_bands=0` on a preset with banded tails, `--set belly.plates=false`).
    let (body, belly) = (crate::preset::schema::Body::default(), crate::preset::schema::Belly::default());
    let (scales, roughness) =
        (crate::preset::schema::Scales::default(), crate::preset::schema::RoughnessParams::default());
    let no_bands = "shapes the bands `body.tail_bands` draws, which is 0 here; set it, or leave this out";
    let no_keels = "shapes the keels `scales.keeled` draws, which is false here; set it, or leave this out";
    for (key, set, partner, unread, message) in [
        ("scales.keel_height", s.keel_height != scales.keel_height, "scales.keeled", !s.keeled, no_keels),
        ("scales.keel_width", s.keel_width != scales.keel_width, "scales.keeled", !s.keeled, no_keels),
        ("scales.smooth_rows", s.smooth_rows != scales.smooth_rows, "scales.keeled", !s.keeled, no_keels),
        // 0, no keel roughness, asks for nothing a smooth scale lacks (a preset that zeroes
        // every roughness addition need not know which apply).
        (
            "roughness.keel",
            preset.roughness.keel != roughness.keel && preset.roughness.keel != 0.0,
            "scales.keeled",
            !s.keeled,
            no_keels,
        ),
        (
            "body.tail_shift_start",
            b.tail_shift_start != body.tail_shift_start,
            "body.tail_color",
            b.tail_color.is_none(),
            "starts the shift to `body.tail_color`, which this preset does not set; set it, or leave this out",
        ),
        (
            "body.tail_band_width",
            b.tail_band_width != body.tail_band_width,
            "body.tail_bands",
            b.tail_bands == 0,
            no_bands,
        ),
        (
            "body.tail_band_color",
            b.tail_band_color != body.tail_band_color,
            "body.tail_bands",
            b.tail_bands == 0,
            no_bands,
        ),
        (
            "body.tail_band_over_belly",
            b.tail_band_over_belly != body.tail_band_over_belly,
            "body.tail_bands",
            b.tail_bands == 0,
            no_bands,
        ),
        (
            "body.tip_fraction",
            b.tip_fraction != body.tip_fraction,
            "body.tip_color",
            b.tip_color.is_none(),
            "sizes what `body.tip_color` draws, which this preset does not set; set it, or leave this out",
        ),
        (
            "body.belly_front_end",
            b.belly_front_end != body.belly_front_end,
            "body.belly_front_color",
            b.belly_front_color.is_none(),
            "ends what `body.belly_front_color` draws, which this preset does not set; set it, or leave this out",
        ),
        (
            "body.belly_front_color",
            b.belly_front_color.is_some(),
            "belly.width",
            preset.belly.width == 0.0,
            "colours the front of the belly, which `belly.width = 0` leaves out; leave this out",
        ),
        (
            "body.subcaudal_color",
            b.subcaudal_color.is_some(),
            "belly.width",
            preset.belly.width == 0.0,
            "colours the underside of the tail, which `belly.width = 0` leaves out; leave this out",
        ),
        (
            "belly.up_rows",
            preset.belly.up_rows != belly.up_rows,
            "belly.plates",
            !preset.belly.plates,
            "runs the belly colour up beside the plates, which `belly.plates = false` leaves out; leave this out",
        ),
    ] {
        if set && unread && !from_file_for_overridden(key, partner) {
            c.problems.push(Problem { key: key.into(), message: message.into(), second_key: None });
        }
    }
    if b.head_mark.len() > MAX_HEAD_MARKS {
        c.problems.push(Problem {
            key: "body.head_mark".into(),
            message: format!("may list at most {MAX_HEAD_MARKS} head marks, got {}", b.head_mark.len()),
            second_key: None,
        });
    } else {
        // Not one by one past the limit: thousands of marks buried the message (and took
        // minutes to locate, one line each).
        use crate::preset::schema::HeadMark;
        for (i, m) in b.head_mark.iter().enumerate() {
            let key = |field: &str| format!("body.head_mark.{i}.{field}");
            c.range(key("size"), m.size, HEAD_MARK_SIZE);
            c.range(key("border_size"), m.border_size, HEAD_MARK_SIZE);
            // A border only a mark round the neck draws, as a pattern layer refuses a key its
            // kind does not read (passed over where `--set` changed the file's kind).
            let sized = !HeadMark::is_default_size(&m.border_size);
            for (field, set) in [("border_color", m.border_color.is_some()), ("border_size", sized)] {
                if set && !HeadMark::takes_border(m.kind) && !from_file_for_overridden(&key(field), &key("kind")) {
                    c.problems.push(Problem {
                        key: key(field),
                        message: format!(
                            "is read by kind \"collar\" and \"crescents\" only, not \"{}\"; leave it out of this mark",
                            spelled(&m.kind)
                        ),
                        second_key: None,
                    });
                }
            }
            if sized && HeadMark::takes_border(m.kind) && m.border_color.is_none() {
                c.problems.push(Problem {
                    key: key("border_size"),
                    message: "sizes what `border_color` draws, which this mark does not set; set it, or leave this out"
                        .into(),
                    second_key: None,
                });
            }
        }
    }

    let o = &preset.optics;
    c.range("optics.ambient_ior", o.ambient_ior, IOR);
    c.range("optics.film_ior", o.film_ior, IOR);
    c.range("optics.pigment_ior", o.pigment_ior, IOR);
    c.range("optics.film_thickness_nm", o.film_thickness_nm, FILM_THICKNESS_NM);
    c.range("optics.pigment_thickness", o.pigment_thickness, PIGMENT_THICKNESS);
    for (i, a) in o.absorption.0.iter().enumerate() {
        let key = if o.absorption.0.iter().all(|x| x == a) {
            "optics.absorption".to_string()
        } else {
            format!("optics.absorption.{i}")
        };
        c.range(key, *a, ABSORPTION);
    }
    c.problems.dedup();
    c.problems
}

/// A number refused in an error message, as a reader takes it in: plain where it is
/// between 1e-4 and 1e15 in size (or 0), in exponent form beyond (`film_ior = 1e300`
/// printed three hundred digits, `--angle-deg=-1e-300` a "-0.000…" as long).
pub fn shown(value: f64) -> String {
    let size = value.abs();
    if value == 0.0 || !value.is_finite() || (1e-4..1e15).contains(&size) {
        format!("{value}")
    } else {
        format!("{value:e}")
    }
}
