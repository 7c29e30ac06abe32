//! The procedural snake body: a tube swept along a smooth S-curve on the ground, tapering to
//! a rounded head and a pointed tail, closed at both ends, with UVs in the texture-space
//! convention of DESIGN.md (u around the body, seam on the belly; v along it, head to tail).
//!
//! Design rule: the texture repeats along the body at the aspect it was generated for: one
//! texture width is the circumference where it lies, and one texture height is the same
//! length along the body, so scales stay as round as the generator drew them and shrink with
//! the girth towards the tail and the snout. Below a quarter of the full girth (the last
//! tenth of the body, the snout's tip) they stop shrinking along the body, or v would run
//! without bound into the point. Normals and tangents come from the same parametric surface
//! (finite differences of the grid), so normal mapping follows `∂P/∂u` and `-∂P/∂v`
//! (OpenGL's +Y points up the image).

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use crate::ops::body::BodyPlan;

#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct Vertex {
    pub position: [f32; 3],
    pub normal: [f32; 3],
    /// Unit ∂P/∂u, and in `w` the sign that makes `w · cross(normal, tangent)` point up the
    /// image (towards −v).
    pub tangent: [f32; 4],
    pub uv: [f32; 2],
}

#[derive(Debug, Clone)]
pub struct Mesh {
    pub vertices: Vec<Vertex>,
    pub indices: Vec<u32>,
}

/// The body's shape in world units (metres, but only ratios matter for a preview).
#[derive(Debug, Clone, Copy)]
pub struct BodyShape {
    pub length: f32,
    /// Radius at the thickest point.
    pub radius: f32,
    /// Sideways amplitude and number of half-waves of the S-curve.
    pub wave_amplitude: f32,
    pub half_waves: f32,
    /// Height over width of the cross-section (snakes are flatter below).
    pub flatten: f32,
    /// Rings along the body and vertices around it.
    pub rings: usize,
    pub segments: usize,
    /// A body atlas (the whole snake in one texture, `generate --layout body`): v runs once
    /// from the snout (0) to the tail tip (1) and the head, neck and tail take the atlas'
    /// proportions; None repeats a tile every circumference.
    pub atlas: Option<BodyPlan>,
}

impl Default for BodyShape {
    fn default() -> Self {
        BodyShape {
            length: 3.0,
            radius: 0.09,
            wave_amplitude: 0.35,
            half_waves: 2.5,
            flatten: 0.85,
            rings: 480,
            segments: 64,
            atlas: None,
        }
    }
}

impl BodyShape {
    /// The snake a layout's maps go on: the default body with the tile repeated along it, or
    /// a body atlas once over `for_atlas` of the preset's plan: the preview's memory check
    /// and the glTF export take it from here (the renderer makes both meshes from the maps
    /// it is given).
    pub fn for_layout(layout: crate::maps::Layout, preset: &crate::preset::Preset) -> BodyShape {
        match layout {
            crate::maps::Layout::Tile => BodyShape::default(),
            crate::maps::Layout::Body => BodyShape::for_atlas(&crate::maps::body_plan(preset)),
        }
    }

    /// The body for a body atlas: the centre line of the default, a radius that makes the
    /// body `plan.length` circumferences long (so a texel covers the same skin both ways),
    /// and the atlas' head, neck and tail. More rings than the default, so that the short
    /// head still has several.
    pub fn for_atlas(plan: &BodyPlan) -> BodyShape {
        let base = BodyShape { rings: 1200, atlas: Some(*plan), ..BodyShape::default() };
        let arc = *base.arc_table(2000).last().expect("arc table");
        // The cross-section is an ellipse of semi-axes r and flatten · r: its perimeter
        // (Ramanujan's approximation) is the circumference one texture width spans.
        BodyShape { radius: arc / (ellipse_perimeter(base.flatten) * plan.length.max(1.0)), ..base }
    }

    /// Arc length of the centre line from the snout to s = i / n, i = 0 ..= n.
    fn arc_table(&self, n: usize) -> Vec<f32> {
        let mut arc = vec![0.0f32; n + 1];
        for i in 1..=n {
            let (a, b) = (i as f32 - 1.0, i as f32);
            arc[i] = arc[i - 1] + (self.centre(b / n as f32) - self.centre(a / n as f32)).length();
        }
        arc
    }

    /// Centre line at s ∈ [0, 1] (0 = snout), lying on the ground plane y = radius.
    pub fn centre(&self, s: f32) -> Vec3 {
        let x = (s - 0.5) * self.length * 0.8;
        let z = self.wave_amplitude * (std::f32::consts::PI * self.half_waves * s).sin();
        Vec3::new(x, 0.0, z)
    }

    /// Body radius at s: an elliptical head cap, a slight neck, full body, and a long taper
    /// over the last 30 % to a point.
    pub fn radius_at(&self, s: f32) -> f32 {
        // The tile's body: a head cap over the first 3.5 %, the neck to 8 %, the taper from
        // 70 %; an atlas puts them where its regions are.
        let (head, neck, tail_start) = match &self.atlas {
            Some(p) => (p.head_end, p.neck_end.max(p.head_end + 1e-3), p.vent),
            None => (0.035, 0.08, 0.7),
        };
        let s = s.clamp(0.0, 1.0);
        let profile = if s < head {
            let x = 1.0 - s / head;
            (1.0 - x * x).max(0.0).sqrt() * 0.9
        } else if s < neck {
            // Head (0.9) narrowing to the neck (0.75), then widening to the body.
            let t = (s - head) / (neck - head);
            0.9 - 0.15 * (std::f32::consts::PI * t).sin()
        } else if s < tail_start {
            let t = ((s - neck) / 0.2).min(1.0);
            0.9 + 0.1 * (t * std::f32::consts::FRAC_PI_2).sin()
        } else {
            let t = (s - tail_start) / (1.0 - tail_start);
            (1.0 - t).powf(1.3)
        };
        self.radius * profile
    }

    /// World-space length of one tile repeat along the body at s (`radius_at`'s parameter):
    /// the circumference there, at least `SMALLEST_TILE_GIRTH` of the full one (module doc).
    pub fn tile_length_at(&self, s: f32) -> f32 {
        ellipse_perimeter(self.flatten) * self.radius_at(s).max(SMALLEST_TILE_GIRTH * self.radius)
    }

    /// A point on the surface at body parameter s and around-angle u (0 = belly, 0.5 = back).
    /// `along`: the body's shape at s (`radius_at`'s parameter): s itself for the tile's
    /// body, the arc-length fraction for an atlas (whose regions are placed by length).
    fn surface(&self, s: f32, u: f32, along: &dyn Fn(f32) -> f32) -> (Vec3, Vec3) {
        let c = self.centre(s);
        let ahead = (self.centre((s + 1e-3).min(1.0)) - self.centre((s - 1e-3).max(0.0))).normalize();
        let right = ahead.cross(Vec3::Y).normalize();
        let up = right.cross(ahead);
        let r = self.radius_at(along(s));
        let phi = 2.0 * std::f32::consts::PI * u;
        let lift = Vec3::Y * self.radius * self.flatten;
        let offset = up * (-phi.cos() * r * self.flatten) + right * (phi.sin() * r);
        (c + lift + offset, c + lift)
    }

    /// Rings and segments as the mesh is made: at least 4 and 3.
    fn rings_segments(&self) -> (usize, usize) {
        (self.rings.max(4), self.segments.max(3))
    }

    /// Triangles of `mesh`: two a quad, `segments` quads round each of `rings` bands.
    pub fn triangles(&self) -> u64 {
        let (rings, segments) = self.rings_segments();
        2 * rings as u64 * segments as u64
    }

    /// The closed tube with UVs and tangents.
    pub fn mesh(&self) -> Mesh {
        let (rings, segments) = self.rings_segments();
        // Arc length along the centre line at each ring gives v.
        let arc = self.arc_table(rings);
        // An atlas places its regions by length along the body (its v), so the body's shape
        // is taken at the arc fraction too, not at the curve parameter (on the S-curve they
        // differ by up to a fifth of the head's length).
        let fine = if self.atlas.is_some() { self.arc_table(4 * rings) } else { Vec::new() };
        let along = |s: f32| -> f32 {
            if fine.is_empty() {
                return s;
            }
            let x = s.clamp(0.0, 1.0) * (fine.len() - 1) as f32;
            let i = (x as usize).min(fine.len() - 2);
            let t = x - i as f32;
            (fine[i] + (fine[i + 1] - fine[i]) * t) / fine[fine.len() - 1]
        };
        // An atlas spans the whole length once; the tile repeats every circumference, summed
        // ring by ring (the midpoint rule: 480 rings put v within 1.2e-3 of 19,200 rings).
        let v: Vec<f32> = match self.atlas {
            Some(_) => arc.iter().map(|a| a / arc[rings]).collect(),
            None => std::iter::once(0.0)
                .chain((1..=rings).scan(0.0, |v, i| {
                    let middle = (i as f32 - 0.5) / rings as f32;
                    *v += (arc[i] - arc[i - 1]) / self.tile_length_at(middle);
                    Some(*v)
                }))
                .collect(),
        };
        let mut vertices = Vec::with_capacity((rings + 1) * (segments + 1));
        let (du, ds) = (1e-3f32, 1e-3f32);
        for (i, v_i) in v.iter().enumerate() {
            let s = i as f32 / rings as f32;
            for j in 0..=segments {
                let u = j as f32 / segments as f32;
                let (p, centre) = self.surface(s, u, &along);
                let dpdu = self.surface(s, u + du, &along).0 - self.surface(s, u - du, &along).0;
                let (s0, s1) = ((s - ds).max(0.0), (s + ds).min(1.0));
                let dpds = self.surface(s1, u, &along).0 - self.surface(s0, u, &along).0;
                let outward = p - centre;
                let mut normal = dpdu.cross(dpds).normalize_or_zero();
                if normal == Vec3::ZERO {
                    // The closed ends: the ring has collapsed to a point on the centre line.
                    let ahead = (self.centre(s1) - self.centre(s0)).normalize();
                    normal = if s < 0.5 { -ahead } else { ahead };
                } else if normal.dot(outward) < 0.0 {
                    normal = -normal;
                }
                // At a closed end the ring is one point and ∂P/∂u vanishes: the frame takes
                // the direction round the body from the next ring inwards, so the end's
                // tangents and their handedness agree with their neighbours'.
                let round = if dpdu.length() > 1e-9 {
                    dpdu
                } else {
                    let inward = if s < 0.5 { s + 1.0 / rings as f32 } else { s - 1.0 / rings as f32 };
                    self.surface(inward, u + du, &along).0 - self.surface(inward, u - du, &along).0
                };
                let tangent = (round - normal * round.dot(normal)).normalize_or(normal.any_orthonormal_vector());
                // "Up the image" is −v, i.e. towards the head.
                vertices.push(Vertex::new(p, normal, tangent, -dpds, [u, *v_i]));
            }
        }
        let mut mesh = Mesh { vertices, indices: grid_indices(rings, segments) };
        mesh.orient_outward();
        mesh
    }
}

/// The share of the full girth below which the tile stops shrinking along the body (module
/// doc): a quarter, reached 90 % of the way to the tail's point (`radius_at`'s taper).
const SMALLEST_TILE_GIRTH: f32 = 0.25;

/// The perimeter of the cross-section, an ellipse of semi-axes 1 and `flatten`
/// (Ramanujan's first approximation, within 1e-4 relative for these shapes).
fn ellipse_perimeter(flatten: f32) -> f32 {
    let (a, b) = (1.0, flatten);
    std::f32::consts::PI * (3.0 * (a + b) - ((3.0 * a + b) * (a + 3.0 * b)).sqrt())
}

impl Vertex {
    /// A vertex whose tangent's `w` makes `w · cross(normal, tangent)` point `up_image`
    /// (towards −v: OpenGL's and glTF's bitangent).
    fn new(position: Vec3, normal: Vec3, tangent: Vec3, up_image: Vec3, uv: [f32; 2]) -> Vertex {
        let sign = if normal.cross(tangent).dot(up_image) >= 0.0 { 1.0 } else { -1.0 };
        Vertex {
            position: position.to_array(),
            normal: normal.to_array(),
            tangent: [tangent.x, tangent.y, tangent.z, sign],
            uv,
        }
    }
}

/// Two triangles per quad of a grid of `rings + 1` rows of `segments + 1` vertices (row-major),
/// counter-clockwise when row index and column index grow like v and u; `orient_outward`
/// fixes the winding of surfaces parametrised the other way.
fn grid_indices(rings: usize, segments: usize) -> Vec<u32> {
    let stride = (segments + 1) as u32;
    let mut indices = Vec::with_capacity(rings * segments * 6);
    for i in 0..rings as u32 {
        for j in 0..segments as u32 {
            let a = i * stride + j;
            let b = a + stride;
            indices.extend_from_slice(&[a, a + 1, b, b, a + 1, b + 1]);
        }
    }
    indices
}

impl Mesh {
    /// Flips every triangle whose geometric normal disagrees with its vertex normals, so that
    /// front faces are counter-clockwise from outside whatever the parametrisation's handedness.
    fn orient_outward(&mut self) {
        for tri in self.indices.chunks_exact_mut(3) {
            let p = |k: usize| Vec3::from(self.vertices[tri[k] as usize].position);
            let n = |k: usize| Vec3::from(self.vertices[tri[k] as usize].normal);
            let face = (p(1) - p(0)).cross(p(2) - p(0));
            if face.dot(n(0) + n(1) + n(2)) < 0.0 {
                tri.swap(1, 2);
            }
        }
    }

    /// A square ground plane at y = 0, `half_size` from the origin, UVs in world units.
    pub fn ground(half_size: f32) -> Mesh {
        let corners = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]];
        let vertices = corners
            .iter()
            .map(|[x, z]| Vertex {
                position: [x * half_size, 0.0, z * half_size],
                normal: [0.0, 1.0, 0.0],
                tangent: [1.0, 0.0, 0.0, 1.0],
                uv: [x * half_size, z * half_size],
            })
            .collect();
        // Counter-clockwise seen from above (+y).
        Mesh { vertices, indices: vec![0, 2, 1, 0, 3, 2] }
    }

    /// A flat `width` × `height` rectangle in the xy plane facing +z, centred on the origin,
    /// the texture once over it (u left to right, v top to bottom as in the image).
    pub fn plane(width: f32, height: f32) -> Mesh {
        let corners = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let vertices = corners
            .iter()
            .map(|&[u, v]| Vertex {
                position: [(u - 0.5) * width, (0.5 - v) * height, 0.0],
                normal: [0.0, 0.0, 1.0],
                // +x is +u; cross(+z, +x) = +y is up the image (−v): w = +1.
                tangent: [1.0, 0.0, 0.0, 1.0],
                uv: [u, v],
            })
            .collect();
        // Counter-clockwise seen from +z.
        Mesh { vertices, indices: vec![0, 3, 1, 1, 3, 2] }
    }

    /// A sphere of `radius` about the origin, +y up, the texture `repeats` times around the
    /// equator (u) and `repeats / 2` times from pole to pole (v, top to bottom), so texels
    /// stay square at the equator. The poles' zero-area triangles are left out.
    pub fn sphere(radius: f32, repeats: f32, rings: usize, segments: usize) -> Mesh {
        let (rings, segments) = (rings.max(3), segments.max(4));
        let mut vertices = Vec::with_capacity((rings + 1) * (segments + 1));
        for i in 0..=rings {
            let v = i as f32 / rings as f32;
            let theta = std::f32::consts::PI * v;
            // The poles exactly (sin π is 8.7e-8 in f32), so that their rings are one point
            // and their triangles are dropped as zero-area below.
            let (sin_theta, cos_theta) = match i {
                0 => (0.0, 1.0),
                _ if i == rings => (0.0, -1.0),
                _ => theta.sin_cos(),
            };
            for j in 0..=segments {
                let u = j as f32 / segments as f32;
                let phi = 2.0 * std::f32::consts::PI * u;
                let normal = Vec3::new(sin_theta * phi.cos(), cos_theta, -sin_theta * phi.sin());
                // ∂P/∂u (its direction does not depend on θ, so it is defined at the poles).
                let tangent = Vec3::new(-phi.sin(), 0.0, -phi.cos());
                // Up the image (−v) is towards the north pole: −∂P/∂θ.
                let up_image = -Vec3::new(cos_theta * phi.cos(), -sin_theta, -cos_theta * phi.sin());
                let uv = [u * repeats, v * repeats * 0.5];
                vertices.push(Vertex::new(normal * radius, normal, tangent, up_image, uv));
            }
        }
        let mut mesh = Mesh { vertices, indices: grid_indices(rings, segments) };
        mesh.orient_outward();
        mesh.without_degenerate_triangles()
    }

    /// The mesh without zero-area triangles (a tube's closed ends, where a ring collapses to
    /// a point) and without the vertices no triangle then uses: nothing a renderer would
    /// draw, but validators and tangent generators trip on them.
    pub fn without_degenerate_triangles(self) -> Mesh {
        let vertices = &self.vertices;
        let area = |t: &[u32]| {
            let p = |k: usize| Vec3::from(vertices[t[k] as usize].position);
            (p(1) - p(0)).cross(p(2) - p(0)).length()
        };
        let kept: Vec<u32> = self.indices.chunks_exact(3).filter(|t| area(t) > 1e-12).flatten().copied().collect();
        // Renumber the used vertices in their old order.
        let mut new_index = vec![u32::MAX; vertices.len()];
        for &i in &kept {
            new_index[i as usize] = 0;
        }
        let mut used = Vec::with_capacity(vertices.len());
        for (i, vertex) in vertices.iter().enumerate() {
            if new_index[i] == 0 {
                new_index[i] = used.len() as u32;
                used.push(*vertex);
            }
        }
        Mesh { vertices: used, indices: kept.iter().map(|&i| new_index[i as usize]).collect() }
    }

    /// Axis-aligned bounds (min, max).
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.vertices.iter().fold((Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)), |(lo, hi), v| {
            let p = Vec3::from(v.position);
            (lo.min(p), hi.max(p))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn small() -> Mesh {
        BodyShape { rings: 120, segments: 24, ..BodyShape::default() }.mesh()
    }

    #[test]
    fn normals_and_tangents_are_unit_and_orthogonal() {
        for v in &small().vertices {
            let n = Vec3::from(v.normal);
            let t = Vec3::new(v.tangent[0], v.tangent[1], v.tangent[2]);
            assert!((n.length() - 1.0).abs() < 1e-4, "{v:?}");
            assert!((t.length() - 1.0).abs() < 1e-4, "{v:?}");
            assert!(v.tangent[3].abs() == 1.0);
            assert!(n.dot(t).abs() < 0.05, "{v:?}");
        }
    }

    #[test]
    fn belly_at_u_zero_back_at_u_half() {
        let shape = BodyShape { rings: 100, segments: 20, ..BodyShape::default() };
        let mesh = shape.mesh();
        let ring = 50 * 21;
        let belly = Vec3::from(mesh.vertices[ring].position);
        let back = Vec3::from(mesh.vertices[ring + 10].position);
        assert!(back.y > belly.y + shape.radius, "back {back} belly {belly}");
        assert_eq!(mesh.vertices[ring].uv[0], 0.0);
        assert_eq!(mesh.vertices[ring + 20].uv[0], 1.0);
        // The belly rests on the ground.
        assert!(belly.y >= -1e-4 && belly.y < 0.2 * shape.radius, "{belly}");
    }

    #[test]
    fn triangles_face_outward_and_the_tube_is_closed() {
        let mesh = small();
        // A closed, outward-oriented surface encloses a positive volume (divergence theorem).
        let volume: f32 = mesh
            .indices
            .chunks_exact(3)
            .map(|t| {
                let p = |k: usize| Vec3::from(mesh.vertices[t[k] as usize].position);
                p(0).dot(p(1).cross(p(2))) / 6.0
            })
            .sum();
        let shape = BodyShape::default();
        let tube = std::f32::consts::PI * shape.radius.powi(2) * shape.flatten * shape.length * 0.8;
        assert!(volume > 0.3 * tube && volume < 1.2 * tube, "volume {volume} vs tube {tube}");
        // Closed ends: the first and last rings collapse to points.
        let first = &mesh.vertices[0..25];
        assert!(first.iter().all(|v| (Vec3::from(v.position) - Vec3::from(first[0].position)).length() < 1e-5));
    }

    /// Where a tube's end collapses to a point, each vertex's tangent frame continues the
    /// next ring's: the same handedness and nearly the same direction round the body.
    /// Negative control: the frame a vanishing ∂P/∂u would give (any vector orthogonal to
    /// the normal) has one handedness for the whole ring, which the neighbours do not share.
    #[test]
    fn the_closed_ends_frames_continue_the_next_rings() {
        let shape = BodyShape { rings: 120, segments: 24, ..BodyShape::default() };
        let mesh = shape.mesh();
        let stride = 25;
        let tangent = |v: &Vertex| Vec3::new(v.tangent[0], v.tangent[1], v.tangent[2]);
        for (end, next) in [(0, stride), (120 * stride, 119 * stride)] {
            for j in 0..stride {
                let (a, b) = (&mesh.vertices[end + j], &mesh.vertices[next + j]);
                assert_eq!(a.tangent[3], b.tangent[3], "ring {end} vertex {j}: {a:?} against {b:?}");
                assert!(tangent(a).dot(tangent(b)) > 0.5, "ring {end} vertex {j}: {a:?} against {b:?}");
            }
        }
    }

    /// The meshes `export --gltf` writes keep no zero-area triangle and no vertex that no
    /// triangle uses (a sphere's poles, a tube's closed ends), and the triangles kept are
    /// the tube's own (the same corner positions, in order).
    #[test]
    fn exported_meshes_keep_no_zero_area_triangles_or_unused_vertices() {
        let tube = BodyShape { rings: 60, segments: 12, ..BodyShape::default() }.mesh();
        for (name, mesh) in [("sphere", Mesh::sphere(0.5, 2.0, 16, 32)), ("tube", tube.clone())] {
            let clean = mesh.clone().without_degenerate_triangles();
            let position = |m: &Mesh, i: u32| Vec3::from(m.vertices[i as usize].position);
            let mut used = vec![false; clean.vertices.len()];
            for t in clean.indices.chunks_exact(3) {
                let area = (position(&clean, t[1]) - position(&clean, t[0]))
                    .cross(position(&clean, t[2]) - position(&clean, t[0]))
                    .length();
                assert!(area > 1e-9, "{name}: a zero-area triangle {t:?} ({area})");
                t.iter().for_each(|&i| used[i as usize] = true);
            }
            assert!(used.iter().all(|&u| u), "{name}: {} unused vertices", used.iter().filter(|&&u| !u).count());
            let corners = |m: &Mesh| -> Vec<Vec3> { m.indices.iter().map(|&i| position(m, i)).collect() };
            let kept: Vec<Vec3> = mesh
                .indices
                .chunks_exact(3)
                .filter(|t| {
                    (position(&mesh, t[1]) - position(&mesh, t[0]))
                        .cross(position(&mesh, t[2]) - position(&mesh, t[0]))
                        .length()
                        > 1e-9
                })
                .flatten()
                .map(|&i| position(&mesh, i))
                .collect();
            assert_eq!(corners(&clean), kept, "{name}");
            // `Mesh::sphere` drops its poles' triangles itself.
            if name == "tube" {
                assert!(clean.vertices.len() < mesh.vertices.len(), "{name}: nothing dropped");
            }
        }
    }

    #[test]
    fn the_triangle_count_is_the_meshes() {
        for shape in [BodyShape::default(), BodyShape { rings: 3, segments: 2, ..BodyShape::default() }] {
            assert_eq!(shape.triangles(), shape.mesh().indices.len() as u64 / 3);
        }
    }

    /// The tile stays square on the body: for every ring behind the snout's dome and wider
    /// than a third of the full girth, the ring's length round the body (one texture width) against the length along
    /// the centre line that one texture height spans there, measured on the mesh's own
    /// positions and v. Negative control: a repeat of one full-girth circumference (the
    /// earlier rule) is off by the girth's ratio, ten times the tolerance at a third.
    #[test]
    fn the_tile_stays_square_as_the_girth_changes() {
        let shape = BodyShape { rings: 480, segments: 64, ..BodyShape::default() };
        let mesh = shape.mesh();
        let stride = 65;
        let position = |i: usize, j: usize| Vec3::from(mesh.vertices[i * stride + j].position);
        let mut checked = 0;
        for i in 1..480 {
            let s = i as f32 / 480.0;
            // Past the snout's dome (its first 3.5 %), where the girth grows by a fifth or more
            // from one ring to the next and the ring-by-ring sum lags the centre's slope.
            if s < 0.035 || shape.radius_at(s) < shape.radius / 3.0 {
                continue;
            }
            let round: f32 = (0..64).map(|j| (position(i, j + 1) - position(i, j)).length()).sum();
            let (next, previous) = (shape.centre((i + 1) as f32 / 480.0), shape.centre((i - 1) as f32 / 480.0));
            let dv = mesh.vertices[(i + 1) * stride].uv[1] - mesh.vertices[(i - 1) * stride].uv[1];
            let along_per_texture = (next - previous).length() / dv;
            let aspect = round / along_per_texture;
            assert!((aspect - 1.0).abs() < 0.02, "ring {i}: width / height of a texel {aspect}");
            checked += 1;
        }
        assert!(checked > 400, "{checked} rings checked");
        // Below the smallest girth the tile's length stops shrinking: v at the tail's point
        // is finite and the tile repeats about twice as often as on the chord at full girth.
        let last = mesh.vertices.last().unwrap().uv[1];
        let chord_repeats = shape.length * 0.8 / (ellipse_perimeter(shape.flatten) * shape.radius);
        assert!(last.is_finite() && last > chord_repeats && last < 3.0 * chord_repeats, "{last}");
    }
}
