//! The material model, one home for what a texture set *means*: the map kinds and their
//! file formats (colour space, channels, bit depth, meaning), the layer optics with the
//! thesis defaults, and the film thickness range the iridescence map spans.
//!
//! Every part that reads or writes a set — the graph builders, PNG export, the manifest,
//! the renderer, the window, the CLI — takes these facts from here, so a format or a
//! default cannot drift between the file and its description. It depends on nothing else
//! in the crate.

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Deserializer, Serialize, de};

/// The thesis' layer defaults (Bie & Jiang 2024, Table 5.2): air, a film of index 1.55,
/// a pigment layer of index 2.00, a 400 nm film, σ0 = 0.6 over δ1 = 1.
pub mod thesis {
    pub const AMBIENT_IOR: f64 = 1.0;
    pub const FILM_IOR: f64 = 1.55;
    pub const PIGMENT_IOR: f64 = 2.0;
    pub const FILM_THICKNESS_NM: f64 = 400.0;
    pub const PIGMENT_THICKNESS: f64 = 1.0;
    pub const ABSORPTION: f64 = 0.6;
}

/// The preset default of σ0: a clear pigment layer. The thesis' 0.6 (`thesis::ABSORPTION`)
/// read the colour map as the base albedo; now that colours mean the visible colour
/// (`preset::visible`), τ = 0.6 over n2 = 2 caps every visible colour at 0.07 linear
/// (sRGB #4c4c4c): no built-in species' colours could be shown. Absorption stays a preset
/// key for stacks whose colours it can reach.
pub const DEFAULT_ABSORPTION: f64 = 0.0;

/// The maps a set can have: the five of every set, and ambient occlusion on request.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum MapKind {
    Color,
    Height,
    Normal,
    Roughness,
    Iridescence,
    /// Ambient occlusion from the height map (`ops::occlusion`): only when asked for by
    /// name or filled into a pack's occlusion channel (`--ao`), never part of "all".
    Ao,
}

impl MapKind {
    pub const ALL: [MapKind; 5] =
        [MapKind::Color, MapKind::Height, MapKind::Normal, MapKind::Roughness, MapKind::Iridescence];

    /// Every map there is, `ALL` and the maps made only on request.
    pub const EVERY: [MapKind; 6] =
        [MapKind::Color, MapKind::Height, MapKind::Normal, MapKind::Roughness, MapKind::Iridescence, MapKind::Ao];

    pub fn name(self) -> &'static str {
        match self {
            MapKind::Color => "color",
            MapKind::Height => "height",
            MapKind::Normal => "normal",
            MapKind::Roughness => "roughness",
            MapKind::Iridescence => "iridescence",
            MapKind::Ao => "ao",
        }
    }

    /// The map's file format (DESIGN.md, "Maps").
    pub fn format(self) -> MapFormat {
        match self {
            MapKind::Color => MapFormat { encoding: Encoding::Srgb, channels: 3, bit_depth: 8 },
            MapKind::Height => MapFormat { encoding: Encoding::Linear, channels: 1, bit_depth: 16 },
            MapKind::Normal => MapFormat { encoding: Encoding::SignedUnit, channels: 3, bit_depth: 8 },
            MapKind::Roughness => MapFormat { encoding: Encoding::Linear, channels: 1, bit_depth: 8 },
            MapKind::Iridescence => MapFormat { encoding: Encoding::Linear, channels: 1, bit_depth: 16 },
            MapKind::Ao => MapFormat { encoding: Encoding::Linear, channels: 1, bit_depth: 8 },
        }
    }

    /// What a sample of the map means, for the manifest.
    pub fn meaning(self, convention: NormalConvention) -> String {
        match self {
            MapKind::Color => "visible diffuse colour (the manifest's color_means)".into(),
            MapKind::Height => {
                "relative surface height on the preset's fixed scale: 0 = the floor of the deepest groove between \
                 its scales (for hexagons the skin) less the grain, 1 = the tallest surface it can draw plus the \
                 grain (not stretched to the map's own range)"
                    .into()
            }
            MapKind::Normal => {
                let y = match convention {
                    NormalConvention::OpenGl => "OpenGL convention, +Y up",
                    NormalConvention::DirectX => "DirectX convention, +Y down",
                };
                format!("tangent-space normal, rgb = xyz * 0.5 + 0.5, {y}")
            }
            MapKind::Roughness => "perceptual roughness r; GGX alpha = r^2 (glTF)".into(),
            MapKind::Iridescence => {
                "film thickness: min_nm + value / 65535 * (max_nm - min_nm); all 0 where the preset has no film \
                 (the manifest's iridescence.film false)"
                    .into()
            }
            MapKind::Ao => "ambient occlusion: the cosine-weighted share of the sky a point sees, 1 = open".into(),
        }
    }
}

/// The file format a set's maps are written in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum FileFormat {
    /// 8- and 16-bit PNG, in the formats of `MapKind::format` (the default).
    #[default]
    Png,
    /// OpenEXR with float samples in physical units (`MapKind::exr_channels`).
    Exr,
}

impl FileFormat {
    pub fn name(self) -> &'static str {
        match self {
            FileFormat::Png => "png",
            FileFormat::Exr => "exr",
        }
    }
}

/// An OpenEXR map's sample type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExrSample {
    /// 16-bit half float: 11 significant bits.
    Half,
    /// 32-bit float.
    Float,
}

impl ExrSample {
    pub fn bits(self) -> u32 {
        match self {
            ExrSample::Half => 16,
            ExrSample::Float => 32,
        }
    }

    /// The manifest's `sample_type` (OpenEXR's own names for the pixel types).
    pub fn name(self) -> &'static str {
        match self {
            ExrSample::Half => "half",
            ExrSample::Float => "float",
        }
    }
}

impl MapKind {
    /// OpenEXR layout: channel names and sample type. Colour and roughness in half (11
    /// significant bits, finer than the PNG's 8); height, the normal and the film thickness
    /// (in nm, up to 10 mm: PHYSICS.md's bound) need float. One-channel maps are `Y`, the
    /// name OpenEXR's readers take for a grey image (they are data, not luminance: the
    /// manifest's `meaning` says what).
    pub fn exr_channels(self) -> (&'static [&'static str], ExrSample) {
        match self {
            MapKind::Color => (&["R", "G", "B"], ExrSample::Half),
            MapKind::Height => (&["Y"], ExrSample::Float),
            MapKind::Normal => (&["R", "G", "B"], ExrSample::Float),
            MapKind::Roughness => (&["Y"], ExrSample::Half),
            MapKind::Iridescence => (&["Y"], ExrSample::Float),
            MapKind::Ao => (&["Y"], ExrSample::Half),
        }
    }

    /// What a sample means in an OpenEXR file (linear floats, no encoding to undo).
    pub fn exr_meaning(self, convention: NormalConvention) -> String {
        match self {
            MapKind::Normal => {
                let y = match convention {
                    NormalConvention::OpenGl => "OpenGL convention, +Y up",
                    NormalConvention::DirectX => "DirectX convention, +Y down",
                };
                format!("tangent-space unit normal, rgb = xyz in [-1, 1], {y}")
            }
            MapKind::Iridescence => "film thickness in nm".into(),
            MapKind::Color => "visible diffuse colour (the manifest's color_means), linear".into(),
            other => other.meaning(convention),
        }
    }
}

impl fmt::Display for MapKind {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for MapKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        MapKind::EVERY.into_iter().find(|m| m.name() == s).ok_or_else(|| unknown_map(s, false))
    }
}

/// The error for a name that is no map, with the nearest name as "did you mean" and the
/// accepted names; in a map list (`in_list`) `all` is one of them.
fn unknown_map(s: &str, in_list: bool) -> String {
    let names = MapKind::EVERY.map(MapKind::name);
    // `colour`, as the documentation's prose spells it, is one letter from the name.
    // (Not for a name of one or two letters: any is within two edits of `ao`.)
    // The same name in another case is suggested at any length (`AO`).
    let same = names.into_iter().find(|n| n.eq_ignore_ascii_case(s));
    let near = same.or_else(|| (s.len() > 2).then(|| crate::toml_text::nearest(s, names)).flatten());
    // `all` is a word of the list, not a map's name, and a map's name is the likelier meaning
    // (`aol` is one edit from both `ao` and `all`). `ALL` and `al` got no suggestion, and the
    // accepted names left `all` out: a hostile-input sweep.
    let near_all = in_list && crate::toml_text::edit_distance(&s.to_ascii_lowercase(), "all") <= 1;
    let near = near.or(near_all.then_some("all"));
    let suggestion = near.map(|n| format!("did you mean {n}? ")).unwrap_or_default();
    let or_all = if in_list { ", or all (the five of every set)" } else { "" };
    format!("unknown map {s:?}; {suggestion}accepted: {}{or_all}", names.join(", "))
}

/// Parses a comma-separated map list ("color,height"); "all" means the five of every set
/// (`MapKind::ALL`), and "all,ao" adds ambient occlusion. The result is in `MapKind` order,
/// each map once. An empty list is refused: it had meant all five, so `--maps "$MAPS"`
/// with the variable unset wrote every map without a word.
pub fn parse_map_list(list: &str) -> Result<Vec<MapKind>, String> {
    if list.trim().is_empty() {
        return Err(format!(
            "an empty list; name the maps ({}), or all (leave the list out for all five)",
            MapKind::EVERY.map(MapKind::name).join(", ")
        ));
    }
    let mut out = Vec::new();
    for item in list.split(',').map(str::trim) {
        if item.is_empty() {
            return Err(format!("an empty name in {list:?}; name the maps, one comma between two"));
        }
        let maps = if item == "all" {
            MapKind::ALL.to_vec()
        } else {
            let map = MapKind::EVERY.into_iter().find(|m| m.name() == item);
            vec![map.ok_or_else(|| unknown_map(item, true))?]
        };
        for map in maps {
            if !out.contains(&map) {
                out.push(map);
            }
        }
    }
    out.sort();
    Ok(out)
}

/// How a map's linear f32 samples become file samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Encoding {
    /// sRGB transfer function (IEC 61966-2-1) on [0, 1].
    Srgb,
    /// Linear on [0, 1].
    Linear,
    /// Linear on [-1, 1] stored as x * 0.5 + 0.5 (normals).
    SignedUnit,
}

/// A map's file format.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MapFormat {
    pub encoding: Encoding,
    pub channels: u32,
    pub bit_depth: u32,
}

impl MapFormat {
    /// The colour space as the manifest names it.
    pub fn color_space(self) -> &'static str {
        match self.encoding {
            Encoding::Srgb => "srgb",
            Encoding::Linear | Encoding::SignedUnit => "linear",
        }
    }

    /// Bytes per pixel in the file's sample layout.
    pub fn bytes_per_pixel(self) -> usize {
        (self.channels * self.bit_depth / 8) as usize
    }
}

/// Normal map convention: OpenGL (+Y up, glTF, Blender) or DirectX (+Y down, Unreal).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum NormalConvention {
    #[default]
    OpenGl,
    DirectX,
}

impl NormalConvention {
    /// The name the manifest records and `--normal-convention` takes.
    pub fn name(self) -> &'static str {
        match self {
            NormalConvention::OpenGl => "opengl",
            NormalConvention::DirectX => "directx",
        }
    }

    pub const ALL: [NormalConvention; 2] = [NormalConvention::OpenGl, NormalConvention::DirectX];

    /// The convention of that `name` (a jobs file's `normal_convention`).
    pub fn from_name(name: &str) -> Option<NormalConvention> {
        Self::ALL.into_iter().find(|c| c.name() == name)
    }
}

/// The layer stack's optics (thesis Table 5.2 names in comments; defaults in `thesis`).
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct Optics {
    /// n0: refractive index of the environment.
    pub ambient_ior: f64,
    /// n1: refractive index of the iridescent film.
    pub film_ior: f64,
    /// n2: refractive index of the pigment (absorption) layer.
    pub pigment_ior: f64,
    /// δ0: film thickness in nm.
    pub film_thickness_nm: f64,
    /// δ1: pigment layer thickness (relative units; optical depth = σ0 δ1).
    pub pigment_thickness: f64,
    /// σ0: absorption coefficient of the pigment layer, one value or linear [r, g, b].
    pub absorption: Absorption,
}

impl Default for Optics {
    fn default() -> Self {
        Optics {
            ambient_ior: thesis::AMBIENT_IOR,
            film_ior: thesis::FILM_IOR,
            pigment_ior: thesis::PIGMENT_IOR,
            film_thickness_nm: thesis::FILM_THICKNESS_NM,
            pigment_thickness: thesis::PIGMENT_THICKNESS,
            absorption: Absorption([DEFAULT_ABSORPTION; 3]),
        }
    }
}

impl Optics {
    /// Optical depth τ = σ0 δ1 per channel.
    pub fn optical_depth(&self) -> [f64; 3] {
        self.absorption.0.map(|a| a * self.pigment_thickness)
    }
}

/// The film thickness range the iridescence map spans: `spread_nm` wide, centred on the
/// film thickness δ0, never below 0 (values 0 and 1 of the map are its ends).
pub fn thickness_range_nm(film_thickness_nm: f64, spread_nm: f64) -> (f64, f64) {
    let min = (film_thickness_nm - spread_nm * 0.5).max(0.0);
    (min, min + spread_nm)
}

/// True when the film changes nothing: no thickness anywhere in its range, or the film's
/// index equal to the ambient medium's. The renderer then skips it, and exports leave it out
/// (no thickness texture, no glTF iridescence).
pub fn film_is_inert(thickness_range_nm: (f64, f64), ambient_ior: f64, film_ior: f64) -> bool {
    thickness_range_nm.1 <= 0.0 || film_ior == ambient_ior
}

/// σ0, written as one number or `[r, g, b]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Absorption(pub [f64; 3]);

impl<'de> Deserialize<'de> for Absorption {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct Visitor;
        impl<'de> de::Visitor<'de> for Visitor {
            type Value = Absorption;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a number or [r, g, b]")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Absorption, E> {
                Ok(Absorption([v; 3]))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Absorption, E> {
                Ok(Absorption([v as f64; 3]))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Absorption, E> {
                Ok(Absorption([v as f64; 3]))
            }
            fn visit_seq<A: de::SeqAccess<'de>>(self, mut seq: A) -> Result<Absorption, A::Error> {
                let mut rgb = [0.0; 3];
                for (i, slot) in rgb.iter_mut().enumerate() {
                    *slot = seq.next_element()?.ok_or_else(|| de::Error::invalid_length(i, &self))?;
                }
                // The length said is the list's (it said 4 for any longer list).
                let mut length = 3;
                while seq.next_element::<de::IgnoredAny>()?.is_some() {
                    length += 1;
                }
                if length > 3 {
                    return Err(de::Error::invalid_length(length, &self));
                }
                Ok(Absorption(rgb))
            }
        }
        deserializer.deserialize_any(Visitor)
    }
}

impl Serialize for Absorption {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let [r, g, b] = self.0;
        if r == g && g == b { serializer.serialize_f64(r) } else { self.0.serialize(serializer) }
    }
}
