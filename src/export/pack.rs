//! Packed textures: the files an engine or a glTF material reads, each channel taken from one
//! of the set's maps (or a constant) with its own transfer — glTF's occlusion-roughness-
//! metallic, Unreal's DirectX-convention normal, Unity HDRP's mask map with smoothness in
//! alpha. One table (`Pack::textures`) says what every packed file holds; the encoder, the
//! manifest, the glTF writer and the README's packing table all follow it.
//!
//! Packed files are written a band of rows at a time (`TextureEncoder`), like a body atlas's
//! maps, so a pack costs no more memory than the set it is packed from.

use std::io::Write;
use std::ops::Range;

use crate::material::{Encoding, MapKind};
use crate::ops::Image;

use super::{ExportError, SharedBuffer, encode, png_file_encoder, unit_to_u8, unit_to_u16};

/// How one channel of a packed texture is made from a map's linear sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Transfer {
    /// sRGB transfer function (IEC 61966-2-1), for colour textures.
    Srgb,
    /// The value as is, on [0, 1].
    Unit,
    /// A signed value on [-1, 1] stored as x · 0.5 + 0.5 (a normal's x, y, z).
    SignedUnit,
    /// −x, then as `SignedUnit`: the green channel of a DirectX-convention normal from the
    /// graph's OpenGL-convention normal.
    NegatedSignedUnit,
    /// 1 − x: smoothness from perceptual roughness (Unity).
    Complement,
}

/// One channel of a packed texture.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Channel {
    /// Channel `channel` of `map`, through `transfer`.
    Map { map: MapKind, channel: usize, transfer: Transfer },
    /// The same value everywhere, on [0, 1] (metallic 0, occlusion 1 without an AO map).
    Constant(u8),
}

impl Channel {
    const fn map(map: MapKind, channel: usize, transfer: Transfer) -> Channel {
        Channel::Map { map, channel, transfer }
    }
}

/// One packed file: its name in the set, channels, bit depth and what it means.
#[derive(Debug, Clone, PartialEq)]
pub struct TextureSpec {
    /// File name suffix: `<set>_<suffix>.png`.
    pub suffix: &'static str,
    pub channels: Vec<Channel>,
    /// 8, or 16 for a single-channel map that keeps the set's 16-bit precision (height).
    pub bit_depth: u32,
    /// True for colour (sRGB) textures; data textures are linear.
    pub srgb: bool,
    /// What each channel holds, in the engine's own words (the manifest and the README).
    pub meaning: String,
}

/// The engines a set can be packed for (`generate --pack`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Pack {
    /// glTF 2.0's core textures and KHR_materials_iridescence's thickness (`export --gltf`
    /// embeds exactly these).
    Gltf,
    /// Unreal Engine: ORM, DirectX-convention normal.
    Unreal,
    /// Unity's High Definition Render Pipeline (Lit shader).
    UnityHdrp,
}

const RGB_SRGB: [Channel; 3] = [
    Channel::map(MapKind::Color, 0, Transfer::Srgb),
    Channel::map(MapKind::Color, 1, Transfer::Srgb),
    Channel::map(MapKind::Color, 2, Transfer::Srgb),
];
const NORMAL_OPENGL: [Channel; 3] = [
    Channel::map(MapKind::Normal, 0, Transfer::SignedUnit),
    Channel::map(MapKind::Normal, 1, Transfer::SignedUnit),
    Channel::map(MapKind::Normal, 2, Transfer::SignedUnit),
];
const NORMAL_DIRECTX: [Channel; 3] = [
    Channel::map(MapKind::Normal, 0, Transfer::SignedUnit),
    Channel::map(MapKind::Normal, 1, Transfer::NegatedSignedUnit),
    Channel::map(MapKind::Normal, 2, Transfer::SignedUnit),
];
/// No ambient occlusion map: fully unoccluded.
const NO_OCCLUSION: Channel = Channel::Constant(255);
const OCCLUSION: Channel = Channel::map(MapKind::Ao, 0, Transfer::Unit);
const NOT_METALLIC: Channel = Channel::Constant(0);
/// HDRP's detail mask (the mask map's B) at 1: a detail map the artist adds applies
/// everywhere, as it does without a mask map (HDRP's `LitDataIndividualLayer.hlsl` sets
/// `detailMask = 1.0` and reads the mask map's `.b` only where one is given; `Lit.shader`'s
/// `_MaskMap` defaults to "white"). At 0 it masked any detail map out.
const DETAIL_EVERYWHERE: Channel = Channel::Constant(255);
const ROUGHNESS: Channel = Channel::map(MapKind::Roughness, 0, Transfer::Unit);
const THICKNESS: Channel = Channel::map(MapKind::Iridescence, 0, Transfer::Unit);
const HEIGHT: Channel = Channel::map(MapKind::Height, 0, Transfer::Unit);

impl Pack {
    pub const ALL: [Pack; 3] = [Pack::Gltf, Pack::Unreal, Pack::UnityHdrp];

    /// The normal map's convention the engine expects: glTF's and Unity's +Y up (OpenGL),
    /// Unreal's +Y down (DirectX).
    pub fn normal_convention(self) -> crate::material::NormalConvention {
        use crate::material::NormalConvention;
        match self {
            Pack::Gltf | Pack::UnityHdrp => NormalConvention::OpenGl,
            Pack::Unreal => NormalConvention::DirectX,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Pack::Gltf => "gltf",
            Pack::Unreal => "unreal",
            Pack::UnityHdrp => "unity-hdrp",
        }
    }

    /// What reads the pack's material, in words (`generate::ambient_warning` names it).
    pub fn material_reader(self) -> &'static str {
        match self {
            Pack::Gltf => "glTF",
            Pack::Unreal => "Unreal's material",
            Pack::UnityHdrp => "HDRP's Lit material",
        }
    }

    /// The longest texture side the engine is documented to load, and where that is said: past
    /// it an engine scales the texture down on import or refuses it, so a pack (or a glTF
    /// file) with a longer side is warned of (`size_problem`). A body atlas is `body.length`
    /// widths tall, so this is what it meets first.
    pub fn longest_side_loaded(self) -> (usize, &'static str) {
        match self {
            // WebGL's MAX_TEXTURE_SIZE on desktop GPUs is commonly 16384 (many mobile GPUs
            // stop at 4096 or 8192); glTF viewers in browsers are bound by it.
            Pack::Gltf => (16384, "that browsers' WebGL commonly loads"),
            // "Unreal Engine supports texture resolutions from 1x1 up to 8192x8192 with some
            // slight modifications to .INI files." (Texture Format Support and Settings, UE
            // 5.0: docs.unrealengine.com/5.0/en-US/texture-format-support-and-settings-in-unreal-engine/;
            // the page's text is UE4's, and later versions may import more: a warning, not
            // a refusal.)
            Pack::Unreal => (8192, "that Unreal Engine's documentation supports (with .ini changes)"),
            // Unity's importing-textures manual: "Maximum 2D and Cubemap texture dimension
            // size" 16384 for "DX11 Shader Model 5 / GL4 (PC GPUs since 2008)"
            // (docs.unity3d.com/2018.1/Documentation/Manual/ImportingTextures.html).
            Pack::UnityHdrp => (16384, "that Unity's manual lists for DX11 / GL4 GPUs"),
        }
    }

    /// What is wrong with a texture of `width` x `height` longer than the engine loads
    /// (`longest_side_loaded`), in words without a remedy; None when it fits.
    pub fn size_problem(self, (width, height): (usize, usize)) -> Option<String> {
        let (limit, documented) = self.longest_side_loaded();
        (width.max(height) > limit).then(|| {
            format!(
                "the {} textures are {width} x {height}, longer than the {limit} texels a side {documented}; a longer \
                 texture may be scaled down or refused",
                self.name()
            )
        })
    }

    /// The packed files, in order. `film`: whether the preset has a film (a thickness
    /// texture is written only then); `ao`: whether the occlusion channel holds the
    /// ambient occlusion map (`ops::occlusion`) or 1 everywhere.
    pub fn textures(self, film: bool, ao: bool) -> Vec<TextureSpec> {
        let occlusion = if ao { OCCLUSION } else { NO_OCCLUSION };
        // Whether the occlusion channel was computed, so that an importer knows whether to
        // wire it (the two manifests differed only in a hash).
        let occlusion_words = if ao {
            "ambient occlusion from the height map (1 = open)"
        } else {
            "occlusion, 1 everywhere (not computed: no --ao)"
        };
        let base_color = TextureSpec {
            suffix: "basecolor",
            channels: RGB_SRGB.to_vec(),
            bit_depth: 8,
            srgb: true,
            meaning: "RGB: visible diffuse colour (the manifest's color_means), sRGB".into(),
        };
        // The thickness as a [0, 1] value over the manifest's range in nm: glTF remaps it
        // the same way (iridescenceThicknessMinimum/Maximum, read from G; a grey image has
        // it in every channel); Unreal's Substrate thin film (1.0 = 10 µm) and HDRP (R, an
        // optical path, not a thickness) take it differently, as the README's engine
        // sections say.
        let thickness = TextureSpec {
            suffix: "thickness",
            channels: vec![THICKNESS],
            bit_depth: 8,
            srgb: false,
            meaning: "grey: film thickness in nm, min_nm + (sample / 255) * (max_nm - min_nm) (the manifest's iridescence range)"
                .into(),
        };
        let height = TextureSpec {
            suffix: "height",
            channels: vec![HEIGHT],
            bit_depth: 16,
            srgb: false,
            meaning: "grey: relative surface height on the preset's fixed scale, as the height map (displacement or parallax)"
                .into(),
        };
        // The engine's normal convention, its channels and words, with why it is that one.
        let (normal_channels, convention) = match self.normal_convention() {
            crate::material::NormalConvention::OpenGl => (NORMAL_OPENGL, "OpenGL convention (+Y up)"),
            crate::material::NormalConvention::DirectX => {
                (NORMAL_DIRECTX, "DirectX convention (+Y down, green flipped)")
            }
        };
        let why = match self {
            Pack::Gltf => ", as glTF requires",
            Pack::Unreal => "",
            Pack::UnityHdrp => ", as Unity expects",
        };
        let normal = TextureSpec {
            suffix: "normal",
            channels: normal_channels.to_vec(),
            bit_depth: 8,
            srgb: false,
            meaning: format!("RGB: tangent-space normal xyz * 0.5 + 0.5, {convention}{why}"),
        };
        let mut textures = match self {
            Pack::Gltf => vec![
                base_color,
                normal,
                TextureSpec {
                    suffix: "orm",
                    channels: vec![occlusion, ROUGHNESS, NOT_METALLIC],
                    bit_depth: 8,
                    srgb: false,
                    meaning: format!("R: {occlusion_words}, G: perceptual roughness, B: metallic (0)"),
                },
            ],
            Pack::Unreal => vec![
                base_color,
                normal,
                TextureSpec {
                    suffix: "orm",
                    channels: vec![occlusion, ROUGHNESS, NOT_METALLIC],
                    bit_depth: 8,
                    srgb: false,
                    meaning: format!("R: {occlusion_words}, G: roughness, B: metallic (0)"),
                },
                height,
            ],
            Pack::UnityHdrp => vec![
                base_color,
                normal,
                TextureSpec {
                    suffix: "mask",
                    channels: vec![
                        NOT_METALLIC,
                        occlusion,
                        DETAIL_EVERYWHERE,
                        Channel::map(MapKind::Roughness, 0, Transfer::Complement),
                    ],
                    bit_depth: 8,
                    srgb: false,
                    meaning: format!(
                        "R: metallic (0), G: {occlusion_words}, B: detail mask (1: a detail map applies everywhere), A: smoothness = 1 - roughness"
                    ),
                },
                height,
            ],
        };
        if film {
            textures.push(thickness);
        }
        textures
    }

    /// The maps a pack's textures read, in `MapKind` order.
    pub fn maps(self, film: bool, ao: bool) -> Vec<MapKind> {
        let mut maps: Vec<MapKind> = self
            .textures(film, ao)
            .iter()
            .flat_map(|t| t.channels.iter())
            .filter_map(|c| match c {
                Channel::Map { map, .. } => Some(*map),
                Channel::Constant(_) => None,
            })
            .collect();
        maps.sort();
        maps.dedup();
        maps
    }
}

impl std::str::FromStr for Pack {
    type Err = String;
    fn from_str(s: &str) -> Result<Pack, String> {
        Pack::ALL
            .into_iter()
            .find(|p| p.name() == s)
            .ok_or_else(|| format!("unknown pack {s:?}; accepted: gltf, unreal, unity-hdrp"))
    }
}

/// File name of a packed texture.
pub fn texture_file_name(set_name: &str, spec: &TextureSpec) -> String {
    format!("{set_name}_{}.png", spec.suffix)
}

impl Transfer {
    /// The stored value on [0, 1] of a linear sample.
    fn apply(self, x: f32) -> f32 {
        match self {
            Transfer::Srgb => encode(Encoding::Srgb, x),
            Transfer::Unit => encode(Encoding::Linear, x),
            Transfer::SignedUnit => encode(Encoding::SignedUnit, x),
            Transfer::NegatedSignedUnit => encode(Encoding::SignedUnit, -x),
            Transfer::Complement => 1.0 - x,
        }
    }
}

/// A packed PNG written a band of rows at a time.
pub struct TextureEncoder {
    pub spec: TextureSpec,
    writer: png::StreamWriter<'static, SharedBuffer>,
    buffer: SharedBuffer,
}

impl TextureEncoder {
    pub fn new(spec: TextureSpec, width: usize, height: usize) -> Result<TextureEncoder, ExportError> {
        let error = |e: png::EncodingError| ExportError::Pack { texture: spec.suffix, message: e.to_string() };
        let buffer = SharedBuffer::default();
        let encoder = png_file_encoder(buffer.clone(), width, height, spec.channels.len(), spec.bit_depth, spec.srgb);
        let writer = encoder.write_header().map_err(error)?.into_stream_writer().map_err(error)?;
        Ok(TextureEncoder { spec, writer, buffer })
    }

    /// Appends the rows `rows` of a band of maps (each map the set's f32 image of the band).
    pub fn write_rows(&mut self, band: &[(MapKind, Image)], rows: Range<usize>) -> Result<(), ExportError> {
        let texture = self.spec.suffix;
        let sources: Vec<(Option<&Image>, Channel)> = self
            .spec
            .channels
            .iter()
            .map(|c| match c {
                Channel::Map { map, .. } => {
                    let image = band.iter().find(|(m, _)| m == map).map(|(_, i)| i);
                    image.map(|i| (Some(i), *c)).ok_or_else(|| ExportError::Pack {
                        texture,
                        message: format!("the {map} map was not evaluated"),
                    })
                }
                Channel::Constant(_) => Ok((None, *c)),
            })
            .collect::<Result<_, _>>()?;
        let width = band.first().map_or(0, |(_, i)| i.width);
        let bytes_per_sample = (self.spec.bit_depth / 8) as usize;
        let mut samples = Vec::with_capacity(rows.len() * width * sources.len() * bytes_per_sample);
        for y in rows {
            for x in 0..width {
                for (image, channel) in &sources {
                    let value = match (image, channel) {
                        (Some(image), Channel::Map { channel, transfer, .. }) => {
                            transfer.apply(image.data[(y * image.width + x) * image.channels + channel])
                        }
                        (_, Channel::Constant(v)) => *v as f32 / 255.0,
                        (None, Channel::Map { .. }) => unreachable!("sources resolved above"),
                    };
                    if bytes_per_sample == 2 {
                        samples.extend_from_slice(&unit_to_u16(value).to_be_bytes());
                    } else {
                        samples.push(unit_to_u8(value));
                    }
                }
            }
        }
        self.writer.write_all(&samples).map_err(|e| ExportError::Pack { texture, message: e.to_string() })
    }

    /// The finished file's bytes (every row must have been written).
    pub fn finish(self) -> Result<Vec<u8>, ExportError> {
        let texture = self.spec.suffix;
        self.writer.finish().map_err(|e| ExportError::Pack { texture, message: e.to_string() })?;
        Ok(std::mem::take(&mut *self.buffer.0.lock().expect("PNG buffer")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_pack_reads_colour_normal_and_roughness_and_the_film_only_when_there_is_one() {
        for pack in Pack::ALL {
            let with = pack.maps(true, true);
            let without = pack.maps(false, false);
            for m in [MapKind::Color, MapKind::Normal, MapKind::Roughness] {
                assert!(with.contains(&m) && without.contains(&m), "{pack:?} lacks {m}");
            }
            assert!(with.contains(&MapKind::Iridescence) && !without.contains(&MapKind::Iridescence));
            assert!(with.contains(&MapKind::Ao) && !without.contains(&MapKind::Ao));
            let names: Vec<_> = pack.textures(true, true).iter().map(|t| t.suffix).collect();
            let mut unique = names.clone();
            unique.sort_unstable();
            unique.dedup();
            unique.sort_by_key(|u| names.iter().position(|n| n == u));
            assert_eq!(names, unique, "{pack:?} has two textures of one name");
        }
    }

    #[test]
    fn transfers_match_the_engines_conventions() {
        // DirectX green is the OpenGL green mirrored about 0.5; smoothness is 1 - roughness.
        assert_eq!(Transfer::NegatedSignedUnit.apply(0.6), 1.0 - Transfer::SignedUnit.apply(0.6));
        assert_eq!(Transfer::Complement.apply(0.25), 0.75);
        // Linear 0.5 is sRGB 1.055 · 0.5^(1/2.4) − 0.055 = 0.7354 (IEC 61966-2-1), 8-bit 188
        // (the test compared the transfer with the function it calls).
        assert_eq!(Transfer::Srgb.apply(0.5), 188.0 / 255.0);
    }
}
