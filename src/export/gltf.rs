//! glTF 2.0 export: one mesh with the set's packed textures (`Pack::Gltf`) as a metallic-
//! roughness material, the film as `KHR_materials_iridescence` and the pigment layer's index
//! as `KHR_materials_ior`, written as one binary `.glb` or as a `.gltf` with its buffer and
//! images beside it.
//!
//! What glTF can carry of the layer stack: the film (index n1, thickness range in nm, the
//! thickness texture) over a dielectric base of index n2, with the base colour as the
//! visible diffuse colour (`COLOR_MEANS`: the stack's diffuse reflectance per unit of light
//! the top lets in, which is what glTF's base colour under a dielectric top is). What it
//! cannot: the absorbing pigment layer's thickness and σ (folded into the visible colour),
//! an ambient index n0 other than air, and the internal-reflection series' angle dependence.
//! Every extension value is written explicitly: the spec's defaults (film index 1.3,
//! 100–400 nm, base index 1.5) are not ours.
//!
//! Spec: https://registry.khronos.org/glTF/specs/2.0/glTF-2.0.html and the extensions'
//! READMEs in KhronosGroup/glTF (KHR_materials_iridescence, KHR_materials_ior).

use serde_json::{Value, json};

use super::{ExportError, KeptBecause, Source};
use crate::render::engine::mesh::Mesh;

/// glTF's numeric constants (glTF 2.0 spec, 5.1 accessors, 5.11 buffer views, 5.26 samplers).
mod gl {
    pub const FLOAT: u32 = 5126;
    pub const UNSIGNED_INT: u32 = 5125;
    pub const ARRAY_BUFFER: u32 = 34962;
    pub const ELEMENT_ARRAY_BUFFER: u32 = 34963;
    pub const LINEAR: u32 = 9729;
    pub const LINEAR_MIPMAP_LINEAR: u32 = 9987;
    pub const REPEAT: u32 = 10497;
    pub const CLAMP_TO_EDGE: u32 = 33071;
    pub const TRIANGLES: u32 = 4;
}

/// The material's numbers (the preset's optics and the manifest's thickness range).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GltfMaterial {
    /// n2: the index of the base under the film (KHR_materials_ior).
    pub base_ior: f64,
    /// The film, if the preset has one: (n1, minimum nm, maximum nm).
    pub film: Option<(f64, f64, f64)>,
    /// Whether the texture repeats along v (a tile) or spans it once (a body atlas).
    pub repeat_v: bool,
}

/// The textures a glTF material reads, as PNG bytes (`Pack::Gltf`'s files).
#[derive(Debug, Clone)]
pub struct GltfTextures {
    pub base_color: Vec<u8>,
    pub normal: Vec<u8>,
    /// Occlusion (R, 1 without an AO map), roughness (G), metallic (B).
    pub orm: Vec<u8>,
    /// Film thickness in G (grey), when there is a film.
    pub thickness: Option<Vec<u8>>,
    /// Whether `orm`'s R channel holds a real ambient occlusion map.
    pub occlusion: bool,
}

impl GltfTextures {
    /// The images by role, in the order the material's texture indices count them (0 base
    /// colour, 1 normal, 2 ORM, 3 thickness when there is one).
    fn images(&self) -> Vec<(&'static str, &[u8])> {
        let images = [Some(&self.base_color), Some(&self.normal), Some(&self.orm), self.thickness.as_ref()];
        IMAGE_ROLES.into_iter().zip(images).filter_map(|(role, image)| Some((role, image?.as_slice()))).collect()
    }

    /// `images`, moved out (a `.gltf`'s image files take them without a copy).
    fn into_images(self) -> Vec<(&'static str, Vec<u8>)> {
        let images = [Some(self.base_color), Some(self.normal), Some(self.orm), self.thickness];
        IMAGE_ROLES.into_iter().zip(images).filter_map(|(role, image)| Some((role, image?))).collect()
    }
}

/// The roles of a glTF material's images, in its texture indices' order; the last only
/// with a film.
const IMAGE_ROLES: [&str; 4] = ["basecolor", "normal", "orm", "thickness"];

/// The files a `.gltf` export named `name` writes beside the `.gltf` (its buffer and its
/// images; `film`: with the thickness image), for checking them before the work
/// (`gltf_files` writes them).
pub fn gltf_side_file_names(name: &str, film: bool) -> Vec<String> {
    let roles = &IMAGE_ROLES[..if film { 4 } else { 3 }];
    std::iter::once(format!("{name}.bin")).chain(roles.iter().map(|role| gltf_image_file_name(name, role))).collect()
}

/// A glTF document before it is written: the JSON and the binary buffer's mesh data;
/// images are in the buffer (GLB, at `image_offsets`, after the mesh data, `length` bytes in
/// all) or in their own files (`.gltf`).
struct Document {
    json: Value,
    mesh_bin: Vec<u8>,
    image_offsets: Vec<usize>,
    length: usize,
}

/// The binary buffer being filled, with its buffer views and accessors. The mesh's bytes are
/// copied in; a GLB's images are only given their places (`place`), and `glb` writes them from
/// the textures straight into the file's bytes: with the images copied into the buffer and the
/// buffer into the file, every image was held three times (a body atlas of python-regius at
/// 1024: the encoded textures 47 MB, the buffer and the file 53 MB each).
#[derive(Default)]
struct Buffer {
    bin: Vec<u8>,
    /// The buffer's length with the placed images, which follow the mesh data.
    length: usize,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Buffer {
    /// A buffer view of `length` bytes at the next 4-byte-aligned offset (accessors of floats
    /// must be aligned): (the view's index, its offset).
    fn next_view(&mut self, length: usize, target: Option<u32>) -> (usize, usize) {
        let offset = self.length.next_multiple_of(4);
        let mut view = json!({ "buffer": 0, "byteOffset": offset, "byteLength": length });
        if let Some(t) = target {
            view["target"] = json!(t);
        }
        self.length = offset + length;
        self.views.push(view);
        (self.views.len() - 1, offset)
    }

    /// Appends `bytes` as a buffer view; returns the view's index. Mesh data only, before any
    /// `place`d image.
    fn view(&mut self, bytes: &[u8], target: Option<u32>) -> usize {
        assert_eq!(self.length, self.bin.len(), "mesh data after a placed image");
        let (index, offset) = self.next_view(bytes.len(), target);
        self.bin.resize(offset, 0);
        self.bin.extend_from_slice(bytes);
        index
    }

    /// A view of `length` bytes whose bytes the GLB writer fills in: (its index, its offset).
    fn place(&mut self, length: usize) -> (usize, usize) {
        self.next_view(length, None)
    }

    /// A vertex attribute of `components` floats per vertex; returns the accessor's index.
    /// `bounds`: write its min and max (POSITION must, glTF 2.0 §3.7.2.1).
    fn attribute(&mut self, values: &[f32], components: usize, kind: &str, bounds: bool) -> usize {
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.view(&bytes, Some(gl::ARRAY_BUFFER));
        let mut accessor =
            json!({ "bufferView": view, "componentType": gl::FLOAT, "count": values.len() / components, "type": kind });
        if bounds {
            let mut lo = vec![f32::MAX; components];
            let mut hi = vec![f32::MIN; components];
            for chunk in values.chunks_exact(components) {
                for (k, v) in chunk.iter().enumerate() {
                    lo[k] = lo[k].min(*v);
                    hi[k] = hi[k].max(*v);
                }
            }
            accessor["min"] = json!(lo);
            accessor["max"] = json!(hi);
        }
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }

    /// Triangle indices as u32; returns the accessor's index.
    fn indices(&mut self, indices: &[u32]) -> usize {
        let bytes: Vec<u8> = indices.iter().flat_map(|i| i.to_le_bytes()).collect();
        let view = self.view(&bytes, Some(gl::ELEMENT_ARRAY_BUFFER));
        self.accessors.push(json!({
            "bufferView": view,
            "componentType": gl::UNSIGNED_INT,
            "count": indices.len(),
            "type": "SCALAR",
            "min": [indices.iter().min().copied().unwrap_or(0)],
            "max": [indices.iter().max().copied().unwrap_or(0)],
        }));
        self.accessors.len() - 1
    }
}

/// Where the images go: into the buffer (GLB) or beside the file under these names.
enum Images<'a> {
    Embedded,
    Files(&'a [String]),
}

/// What made an exported file, written as its asset's `extras`: the set manifest's keys for
/// what made it (`Source`), and the export's own options, so that the file can be made
/// again (the mesh and `--ao` were left out: a sweep).
#[derive(Debug, Clone, serde::Serialize)]
pub struct ExportSource {
    #[serde(flatten)]
    pub set: Source,
    /// `--mesh` (`gltf_export::MeshKind::name`).
    pub mesh: &'static str,
    /// `--ao`.
    pub ambient_occlusion: bool,
}

/// `source`: what made the file (`ExportSource`), written as the asset's `extras`; None: no
/// `extras`.
fn document(
    name: &str,
    mesh: &Mesh,
    material: GltfMaterial,
    textures: &GltfTextures,
    images: Images,
    source: Option<&ExportSource>,
) -> Document {
    let mut buffer = Buffer::default();
    let v = &mesh.vertices;
    let position = buffer.attribute(&v.iter().flat_map(|v| v.position).collect::<Vec<_>>(), 3, "VEC3", true);
    let normal = buffer.attribute(&v.iter().flat_map(|v| v.normal).collect::<Vec<_>>(), 3, "VEC3", false);
    let tangent = buffer.attribute(&v.iter().flat_map(|v| v.tangent).collect::<Vec<_>>(), 4, "VEC4", false);
    let uv = buffer.attribute(&v.iter().flat_map(|v| v.uv).collect::<Vec<_>>(), 2, "VEC2", false);
    let indices = buffer.indices(&mesh.indices);

    let pngs = textures.images();
    let mut image_offsets = Vec::new();
    let image_list: Vec<Value> = pngs
        .iter()
        .enumerate()
        .map(|(k, (role, bytes))| match &images {
            Images::Embedded => {
                let (index, offset) = buffer.place(bytes.len());
                image_offsets.push(offset);
                json!({ "name": format!("{name}_{role}"), "bufferView": index, "mimeType": "image/png" })
            }
            // Each file's SHA-256, so that a later export can tell the image it wrote from one
            // edited since (`earlier_image`), as a set's manifest does for its maps.
            Images::Files(names) => json!({
                "name": format!("{name}_{role}"),
                "uri": uri_reference(&names[k]),
                "extras": { "sha256": super::sha256_hex(bytes) },
            }),
        })
        .collect();
    let texture_list: Vec<Value> = (0..pngs.len()).map(|k| json!({ "sampler": 0, "source": k })).collect();

    let pbr = json!({
        "baseColorTexture": { "index": 0, "texCoord": 0 },
        "baseColorFactor": [1.0, 1.0, 1.0, 1.0],
        "metallicRoughnessTexture": { "index": 2, "texCoord": 0 },
        // The texture's B is 0 (a dielectric) and G the roughness itself.
        "metallicFactor": 1.0,
        "roughnessFactor": 1.0,
    });
    let mut mat = json!({
        "name": name,
        "normalTexture": { "index": 1, "texCoord": 0, "scale": 1.0 },
        "doubleSided": false,
        "alphaMode": "OPAQUE",
    });
    if textures.occlusion {
        mat["occlusionTexture"] = json!({ "index": 2, "texCoord": 0, "strength": 1.0 });
    }
    let mut extensions = serde_json::Map::new();
    let mut used = vec!["KHR_materials_ior"];
    extensions.insert("KHR_materials_ior".into(), json!({ "ior": material.base_ior }));
    if let Some((film_ior, min_nm, max_nm)) = material.film {
        used.push("KHR_materials_iridescence");
        let mut film = json!({
            "iridescenceFactor": 1.0,
            "iridescenceIor": film_ior,
            "iridescenceThicknessMaximum": max_nm,
        });
        // Without a texture the thickness is the maximum, and a minimum says nothing (the
        // validator's KHR_MATERIALS_IRIDESCENCE_THICKNESS_RANGE_WITHOUT_TEXTURE).
        if textures.thickness.is_some() {
            film["iridescenceThicknessMinimum"] = json!(min_nm);
            film["iridescenceThicknessTexture"] = json!({ "index": 3, "texCoord": 0 });
        }
        extensions.insert("KHR_materials_iridescence".into(), film);
    }
    mat["extensions"] = Value::Object(extensions);
    mat["pbrMetallicRoughness"] = pbr;
    used.sort();

    let Buffer { bin, length, views, accessors } = buffer;
    let buffer = match &images {
        Images::Embedded => json!({ "byteLength": length }),
        Images::Files(_) => json!({ "byteLength": length, "uri": uri_reference(&format!("{name}.bin")) }),
    };
    let mut json = json!({
        "asset": { "version": "2.0", "generator": format!("snakeskin {}", env!("CARGO_PKG_VERSION")) },
        "extensionsUsed": used,
        "scene": 0,
        "scenes": [{ "name": name, "nodes": [0] }],
        "nodes": [{ "name": name, "mesh": 0 }],
        "meshes": [{
            "name": name,
            "primitives": [{
                "attributes": { "POSITION": position, "NORMAL": normal, "TANGENT": tangent, "TEXCOORD_0": uv },
                "indices": indices,
                "material": 0,
                "mode": gl::TRIANGLES,
            }],
        }],
        "materials": [mat],
        "textures": texture_list,
        "images": image_list,
        "samplers": [{
            "magFilter": gl::LINEAR,
            "minFilter": gl::LINEAR_MIPMAP_LINEAR,
            // u wraps round the body; v repeats on a tile, spans a body atlas once.
            "wrapS": gl::REPEAT,
            "wrapT": if material.repeat_v { gl::REPEAT } else { gl::CLAMP_TO_EDGE },
        }],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [buffer],
    });
    if let Some(source) = source {
        json["asset"]["extras"] = serde_json::to_value(source).expect("an ExportSource is plain data");
    }
    Document { json, mesh_bin: bin, image_offsets, length }
}

/// GLB chunk types (glTF 2.0, 4.4.3): "JSON" and "BIN\0" as little-endian u32.
const GLB_MAGIC: u32 = 0x4654_6C67;
const CHUNK_JSON: u32 = 0x4E4F_534A;
const CHUNK_BIN: u32 = 0x004E_4942;

/// A binary glTF (.glb): header, JSON chunk (padded with spaces), BIN chunk (padded with
/// zeros), every chunk 4-byte aligned; at most 4 GiB in all (the header's u32 length).
pub fn glb(
    name: &str,
    mesh: &Mesh,
    material: GltfMaterial,
    textures: &GltfTextures,
    source: Option<&ExportSource>,
) -> Result<Vec<u8>, ExportError> {
    let Document { json, mesh_bin, image_offsets, length } =
        document(name, mesh, material, textures, Images::Embedded, source);
    let mut text = serde_json::to_vec(&json).map_err(|e| ExportError::Gltf(e.to_string()))?;
    while !text.len().is_multiple_of(4) {
        text.push(b' ');
    }
    let bin_length = length.next_multiple_of(4);
    let total = 12 + 8 + text.len() + 8 + bin_length;
    let total32 = u32::try_from(total)
        .map_err(|_| ExportError::Gltf(format!("{total} bytes is over GLB's 4 GiB; use a smaller --size")))?;
    let mut out = Vec::with_capacity(total);
    for word in [GLB_MAGIC, 2, total32, text.len() as u32, CHUNK_JSON] {
        out.extend_from_slice(&word.to_le_bytes());
    }
    out.extend_from_slice(&text);
    for word in [bin_length as u32, CHUNK_BIN] {
        out.extend_from_slice(&word.to_le_bytes());
    }
    let bin_start = out.len();
    out.extend_from_slice(&mesh_bin);
    let images = textures.images();
    assert_eq!(image_offsets.len(), images.len(), "a place for every image");
    for (offset, (_, bytes)) in image_offsets.into_iter().zip(images) {
        out.resize(bin_start + offset, 0);
        out.extend_from_slice(bytes);
    }
    out.resize(total, 0);
    Ok(out)
}

/// A `.gltf` with its buffer (`NAME.bin`) and images beside it: (file name, bytes), the
/// `.gltf` last (it names the others, so it is the set's commit record).
pub fn gltf_files(
    name: &str,
    mesh: &Mesh,
    material: GltfMaterial,
    textures: GltfTextures,
    source: Option<&ExportSource>,
) -> Result<Vec<(String, Vec<u8>)>, ExportError> {
    let names: Vec<String> = textures.images().iter().map(|(role, _)| gltf_image_file_name(name, role)).collect();
    let Document { json, mesh_bin, .. } = document(name, mesh, material, &textures, Images::Files(&names), source);
    let text = serde_json::to_vec_pretty(&json).map_err(|e| ExportError::Gltf(e.to_string()))?;
    let mut files = vec![(format!("{name}.bin"), mesh_bin)];
    for (file, (_, bytes)) in names.into_iter().zip(textures.into_images()) {
        files.push((file, bytes));
    }
    files.push((format!("{name}.gltf"), text));
    Ok(files)
}

/// The file name of a `.gltf`'s image beside it: `NAME.ROLE.png`. A dot, not the `_` of a
/// texture set's files (`NAME_normal.png`, `NAME_basecolor.png` of `--pack gltf`), so that a
/// `.gltf` exported into a set's folder under the set's name overwrites none of its files.
pub fn gltf_image_file_name(name: &str, role: &str) -> String {
    format!("{name}.{role}.png")
}

/// The most bytes of an earlier `.gltf` read to see which images it names (`earlier_image`;
/// one this tool writes is a few KB): a link to /dev/zero or a huge file is not read.
const EARLIER_GLTF_MAX_BYTES: u64 = 16 << 20;

/// What an earlier `.gltf` says of an image file beside it (`earlier_image`).
#[derive(Debug, Clone, PartialEq)]
pub enum EarlierImage {
    /// One of its images, with the SHA-256 it recorded (None: written before images carried
    /// one).
    Named { sha256: Option<String> },
    /// Not shown to be one: the `.gltf` does not name it (someone else's file), is not there
    /// (a killed commit can leave its images without it) or could not be read. Why, to say
    /// of a file that stays (as `generate` says of a map no manifest records).
    NotShown(KeptBecause),
}

/// What the `.gltf` at `gltf` says of `image_file` (a file beside it): named as one of its
/// images where it is a regular file (no link followed) of at most `EARLIER_GLTF_MAX_BYTES`,
/// JSON with an `images[].uri` that is `image_file`'s URI reference, with the image's
/// `extras.sha256` where it has one. Never named otherwise, so that a file is taken for an
/// earlier export's only where that export's `.gltf` says it is.
pub fn earlier_image(gltf: &std::path::Path, image_file: &str) -> EarlierImage {
    use crate::text_file::{BoundedReadError, Links, read_bounded_bytes};
    let gltf_name = gltf.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let unreadable =
        |error: String| EarlierImage::NotShown(KeptBecause::RecordUnreadable { record: gltf_name.clone(), error });
    let bytes = match read_bounded_bytes(gltf, EARLIER_GLTF_MAX_BYTES, Links::Refuse) {
        Ok(bytes) => bytes,
        Err(BoundedReadError::Io(e)) if e.kind() == std::io::ErrorKind::NotFound => {
            return EarlierImage::NotShown(KeptBecause::NoRecord(gltf_name));
        }
        Err(e) => return unreadable(e.to_string()),
    };
    let json = match serde_json::from_slice::<Value>(&bytes) {
        Ok(json) => json,
        Err(e) => return unreadable(format!("not JSON: {e}")),
    };
    let uri = uri_reference(image_file);
    match json["images"].as_array().into_iter().flatten().find(|image| image["uri"].as_str() == Some(&uri)) {
        Some(image) => EarlierImage::Named { sha256: image["extras"]["sha256"].as_str().map(String::from) },
        None => EarlierImage::NotShown(KeptBecause::NotRecorded { record: gltf_name }),
    }
}

/// A file name as a relative URI reference (RFC 3986 §2): every byte but the unreserved
/// characters percent-encoded, so that a name with a space, `#`, `%` or `?` still names
/// its file (glTF 2.0 §3.3: `uri` is a URI reference, relative to the `.gltf`).
fn uri_reference(file_name: &str) -> String {
    let mut out = String::with_capacity(file_name.len());
    for byte in file_name.bytes() {
        if byte.is_ascii_alphanumeric() || b"-._~".contains(&byte) {
            out.push(byte as char);
        } else {
            out.push_str(&format!("%{byte:02X}"));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::engine::mesh::Mesh;

    fn parse_glb(bytes: &[u8]) -> (Value, Vec<u8>) {
        let word = |k: usize| u32::from_le_bytes(bytes[k..k + 4].try_into().unwrap()) as usize;
        assert_eq!(word(0) as u32, GLB_MAGIC);
        assert_eq!(word(4), 2);
        assert_eq!(word(8), bytes.len());
        let json_len = word(12);
        assert_eq!(word(16) as u32, CHUNK_JSON);
        assert_eq!(json_len % 4, 0);
        let json: Value = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
        let bin_start = 20 + json_len;
        let bin_len = word(bin_start);
        assert_eq!(word(bin_start + 4) as u32, CHUNK_BIN);
        (json, bytes[bin_start + 8..bin_start + 8 + bin_len].to_vec())
    }

    /// A film of one thickness has no texture and no minimum: glTF reads the maximum then
    /// (the validator's note on a minimum without a texture). Negative control: with the
    /// texture, both.
    #[test]
    fn a_film_without_a_thickness_texture_has_no_minimum() {
        let mesh = Mesh::plane(1.0, 1.0);
        let material = GltfMaterial { base_ior: 1.56, film: Some((1.33, 420.0, 420.0)), repeat_v: true };
        for thickness in [None, Some(vec![7, 8])] {
            let textures = GltfTextures {
                base_color: vec![1],
                normal: vec![2],
                orm: vec![3],
                thickness: thickness.clone(),
                occlusion: false,
            };
            let (json, _) = parse_glb(&glb("snake", &mesh, material, &textures, None).unwrap());
            let film = &json["materials"][0]["extensions"]["KHR_materials_iridescence"];
            assert_eq!(film["iridescenceThicknessMaximum"], 420.0);
            assert_eq!(film.get("iridescenceThicknessMinimum").is_some(), thickness.is_some(), "{film}");
        }
    }

    /// Four textures of a few bytes each, the thickness the fourth (the tests below).
    fn four_textures() -> GltfTextures {
        GltfTextures {
            base_color: vec![1, 2, 3],
            normal: vec![4, 5],
            orm: vec![6],
            thickness: Some(vec![7, 8, 9, 10, 11]),
            occlusion: false,
        }
    }

    /// A material with a film of 250–450 nm (the tests below).
    const FILM_MATERIAL: GltfMaterial =
        GltfMaterial { base_ior: 1.56, film: Some((1.33, 250.0, 450.0)), repeat_v: true };

    #[test]
    fn glb_round_trips_the_mesh_and_writes_every_film_value() {
        let mesh = Mesh::plane(1.0, 1.0);
        let (json, bin) = parse_glb(&glb("snake", &mesh, FILM_MATERIAL, &four_textures(), None).unwrap());
        let film = &json["materials"][0]["extensions"]["KHR_materials_iridescence"];
        assert_eq!(film["iridescenceIor"], 1.33);
        assert_eq!(film["iridescenceThicknessMinimum"], 250.0);
        assert_eq!(film["iridescenceThicknessMaximum"], 450.0);
        assert_eq!(film["iridescenceFactor"], 1.0);
        assert_eq!(json["materials"][0]["extensions"]["KHR_materials_ior"]["ior"], 1.56);
        // The positions read back from the buffer are the mesh's.
        let accessor =
            &json["accessors"][json["meshes"][0]["primitives"][0]["attributes"]["POSITION"].as_u64().unwrap() as usize];
        let view = &json["bufferViews"][accessor["bufferView"].as_u64().unwrap() as usize];
        let offset = view["byteOffset"].as_u64().unwrap() as usize;
        assert_eq!(offset % 4, 0);
        let first: Vec<f32> =
            (0..3).map(|k| f32::from_le_bytes(bin[offset + 4 * k..offset + 4 * k + 4].try_into().unwrap())).collect();
        assert_eq!(first, mesh.vertices[0].position.to_vec());
        // Every image's bytes are in the buffer where its view says (the thickness image the
        // fourth), each at a 4-byte-aligned offset after the mesh data, and the BIN chunk is
        // the buffer's length padded to 4 bytes.
        let images: [&[u8]; 4] = [&[1, 2, 3], &[4, 5], &[6], &[7, 8, 9, 10, 11]];
        for (k, expected) in images.into_iter().enumerate() {
            let view = &json["bufferViews"][json["images"][k]["bufferView"].as_u64().unwrap() as usize];
            let (o, n) = (view["byteOffset"].as_u64().unwrap() as usize, view["byteLength"].as_u64().unwrap() as usize);
            assert_eq!((o % 4, &bin[o..o + n]), (0, expected), "image {k}");
        }
        let length = json["buffers"][0]["byteLength"].as_u64().unwrap() as usize;
        assert_eq!(bin.len(), length.next_multiple_of(4));
    }

    /// A `.gltf`'s buffer file is the mesh data alone, exactly `byteLength` long, and its
    /// images are the textures' bytes under the names the document gives them.
    #[test]
    fn a_gltf_buffer_file_is_as_long_as_its_buffer_and_its_images_are_the_textures() {
        let mesh = Mesh::plane(1.0, 1.0);
        let files = gltf_files("s", &mesh, FILM_MATERIAL, four_textures(), None).unwrap();
        let json: Value = serde_json::from_slice(&files.last().unwrap().1).unwrap();
        let file = |name: &str| &files.iter().find(|(n, _)| n == name).unwrap_or_else(|| panic!("no {name}")).1;
        let bin = file(json["buffers"][0]["uri"].as_str().unwrap());
        assert_eq!(bin.len() as u64, json["buffers"][0]["byteLength"].as_u64().unwrap());
        let expected = four_textures();
        for (k, (role, bytes)) in expected.images().into_iter().enumerate() {
            assert_eq!(json["images"][k]["uri"], format!("s.{role}.png"));
            assert_eq!(file(&format!("s.{role}.png")).as_slice(), bytes, "{role}");
        }
    }

    #[test]
    fn no_film_writes_no_iridescence_extension() {
        let mesh = Mesh::plane(1.0, 1.0);
        let textures =
            GltfTextures { base_color: vec![1], normal: vec![2], orm: vec![3], thickness: None, occlusion: false };
        let material = GltfMaterial { base_ior: 2.0, film: None, repeat_v: false };
        let (json, _) = parse_glb(&glb("s", &mesh, material, &textures, None).unwrap());
        assert_eq!(json["extensionsUsed"], json!(["KHR_materials_ior"]));
        assert!(json["materials"][0]["extensions"].get("KHR_materials_iridescence").is_none());
        assert_eq!(json["samplers"][0]["wrapT"], gl::CLAMP_TO_EDGE);
    }
}
