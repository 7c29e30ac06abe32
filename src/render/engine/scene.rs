//! What a frame shows besides the maps: the orbit camera, the lights and sky, the layer stage
//! or map being viewed, the film method, and the uniform block `shaders/scene.wgsl` reads.
//! The CPU reference reads the same structs, so GPU and CPU shade under identical light.

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3};

use crate::optics::brdf::Model;
use crate::optics::brdf::energy::E1_ROUGHNESS;
use crate::optics::film::Stack;
use crate::preset::Preset;
use crate::render::engine::film::GpuFilmMethod;

/// An orbit camera around a target: drag changes yaw and pitch, the wheel the distance.
#[derive(Debug, Clone, Copy)]
pub struct Camera {
    pub target: Vec3,
    pub yaw_deg: f32,
    pub pitch_deg: f32,
    pub distance: f32,
    pub fov_y_deg: f32,
}

impl Default for Camera {
    fn default() -> Self {
        Camera { target: Vec3::new(0.0, 0.05, 0.0), yaw_deg: 20.0, pitch_deg: 38.0, distance: 2.9, fov_y_deg: 35.0 }
    }
}

impl Camera {
    pub fn position(&self) -> Vec3 {
        let (yaw, pitch) = (self.yaw_deg.to_radians(), self.pitch_deg.clamp(-89.0, 89.0).to_radians());
        self.target + self.distance * Vec3::new(pitch.cos() * yaw.sin(), pitch.sin(), pitch.cos() * yaw.cos())
    }

    pub fn view_proj(&self, aspect: f32) -> Mat4 {
        let view = Mat4::look_at_rh(self.position(), self.target, Vec3::Y);
        let near = (self.distance * 0.02).max(1e-3);
        let proj = Mat4::perspective_rh(self.fov_y_deg.to_radians(), aspect, near, self.distance * 20.0 + 10.0);
        proj * view
    }

    /// The default view for one snake; for several, a view of the whole grid
    /// (`renderer::snake_grid`), so that a many-snake frame really draws every snake.
    pub fn framing(snakes: u32) -> Camera {
        if snakes <= 1 {
            return Camera::default();
        }
        let (columns, spacing_x, spacing_z) = crate::render::engine::renderer::grid_layout(snakes);
        let rows = snakes.div_ceil(columns);
        let width = (columns - 1) as f32 * spacing_x + 2.6;
        let depth = (rows - 1) as f32 * spacing_z + 1.0;
        let (centre_x, centre_z) = crate::render::engine::renderer::grid_centre(snakes);
        let target = Vec3::new(centre_x, 0.05, centre_z);
        // Fit the grid's width into the horizontal field of view of a 16:9 frame, and its
        // depth (foreshortened by the 40° pitch, about ×1.8 on screen) into the vertical one.
        let tan_v = (35.0f32.to_radians() * 0.5).tan();
        let distance = 1.15 * (width / (2.0 * tan_v * 16.0 / 9.0)).max(depth * 1.8 / (2.0 * tan_v));
        Camera { target, yaw_deg: 0.0, pitch_deg: 40.0, distance, fov_y_deg: 35.0 }
    }

    /// A close-up of the mid-body (for figures where the scales must be visible).
    pub fn close_up() -> Camera {
        Camera { target: Vec3::new(-0.24, 0.08, 0.0), yaw_deg: 0.0, pitch_deg: 40.0, distance: 0.62, fov_y_deg: 35.0 }
    }
}

/// A directional light: unit direction towards the light and irradiance (linear RGB).
#[derive(Debug, Clone, Copy)]
pub struct Light {
    pub direction: Vec3,
    pub irradiance: [f32; 3],
    pub enabled: bool,
}

impl Light {
    pub fn from_angles(azimuth_deg: f32, elevation_deg: f32, irradiance: [f32; 3]) -> Light {
        let (az, el) = (azimuth_deg.to_radians(), elevation_deg.to_radians());
        Light { direction: Vec3::new(el.cos() * az.sin(), el.sin(), el.cos() * az.cos()), irradiance, enabled: true }
    }
}

/// How many directional lights a scene has: the key and the fill (`Lighting::lights`); the
/// scene uniform's light arrays and the shaders' light loops (`SCENE_LIGHTS` in WGSL) hold
/// this many.
pub const SCENE_LIGHTS: usize = 2;

#[derive(Debug, Clone, Copy)]
pub struct Lighting {
    pub key: Light,
    pub fill: Light,
    pub sky_top: [f32; 3],
    pub sky_bottom: [f32; 3],
}

impl Default for Lighting {
    fn default() -> Self {
        Lighting {
            // A warm key light from the upper front-left and a weak cool fill from the right.
            key: Light::from_angles(-35.0, 40.0, [3.0, 2.85, 2.6]),
            fill: Light::from_angles(110.0, 25.0, [0.35, 0.4, 0.5]),
            sky_top: [0.30, 0.36, 0.45],
            sky_bottom: [0.08, 0.07, 0.06],
        }
    }
}

impl Lighting {
    /// The directional lights in the order the GPU's scene uniform holds them.
    pub fn lights(&self) -> [&Light; SCENE_LIGHTS] {
        [&self.key, &self.fill]
    }
}

/// Layer stages of the thesis' Fig. 5.12.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Stage {
    Diffuse,
    DiffuseNormal,
    Film,
    All,
}

impl Stage {
    pub const ALL: [Stage; 4] = [Stage::Diffuse, Stage::DiffuseNormal, Stage::Film, Stage::All];
    pub const ACCEPTED: &'static str = "diffuse, normal, film, all";

    pub fn name(self) -> &'static str {
        match self {
            Stage::Diffuse => "diffuse",
            Stage::DiffuseNormal => "normal",
            Stage::Film => "film",
            Stage::All => "all",
        }
    }

    pub fn parse(name: &str) -> Option<Stage> {
        Stage::ALL.into_iter().find(|s| s.name() == name)
    }

    /// The value of `skin.wgsl`'s `STAGE` (`STAGE_DIFFUSE`, ... in the generated prelude).
    pub fn code(self) -> u32 {
        match self {
            Stage::Diffuse => 0,
            Stage::DiffuseNormal => 1,
            Stage::Film => 2,
            Stage::All => 3,
        }
    }
}

/// What the skin pass outputs: a shaded stage or one map shown unlit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum View {
    Shaded(Stage),
    Map(crate::maps::MapKind),
}

impl View {
    /// Parses `--layers`: a stage name or `map:NAME`.
    pub fn parse(name: &str) -> Option<View> {
        if let Some(map) = name.strip_prefix("map:") {
            // The five maps the renderer binds; ambient occlusion is not one of them.
            return crate::maps::MapKind::ALL.into_iter().find(|m| m.name() == map).map(View::Map);
        }
        Stage::parse(name).map(View::Shaded)
    }

    pub const ACCEPTED: &'static str =
        "diffuse, normal, film, all, or map:color|map:height|map:normal|map:roughness|map:iridescence";

    /// The pipeline's (`STAGE`, `VIEW_MAP`) pair: a map view is drawn by the full-stage
    /// pipeline with the map shown unlit.
    pub fn codes(self) -> (u32, u32) {
        match self {
            View::Shaded(stage) => (stage.code(), self.map_code()),
            View::Map(_) => (Stage::All.code(), self.map_code()),
        }
    }

    /// The value of `skin.wgsl`'s `VIEW_MAP`: 0 to shade, else the map shown unlit
    /// (`VIEW_COLOR`, ... in the generated prelude).
    pub fn map_code(self) -> u32 {
        match self {
            View::Shaded(_) => 0,
            View::Map(crate::maps::MapKind::Color) => 1,
            View::Map(crate::maps::MapKind::Height) => 2,
            View::Map(crate::maps::MapKind::Normal) => 3,
            View::Map(crate::maps::MapKind::Roughness) => 4,
            View::Map(crate::maps::MapKind::Iridescence) => 5,
            View::Map(crate::maps::MapKind::Ao) => unreachable!("View::parse offers only MapKind::ALL"),
        }
    }
}

/// The material's layer optics as the shader needs them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LayerOptics {
    pub stack: Stack,
    /// Film thickness at iridescence-map values 0 and 1.
    pub thickness_range_nm: (f64, f64),
    pub optical_depth: [f64; 3],
}

impl LayerOptics {
    pub fn from_preset(preset: &Preset) -> LayerOptics {
        let o = &preset.optics;
        LayerOptics {
            stack: Stack { n0: o.ambient_ior, n1: o.film_ior, n2: o.pigment_ior },
            thickness_range_nm: crate::maps::thickness_range_nm(preset),
            optical_depth: o.absorption.0.map(|s| s * o.pigment_thickness),
        }
    }

    /// True when the film changes nothing: zero thickness everywhere or n1 equal to n0.
    pub fn film_is_inert(&self) -> bool {
        crate::material::film_is_inert(self.thickness_range_nm, self.stack.n0, self.stack.n1)
    }

    /// The film thicknesses K and E (the stack's bounce terms) are computed at:
    /// `BOUNCE_THICKNESSES` evenly over the map's range.
    pub fn bounce_thicknesses_nm(&self) -> [f64; BOUNCE_THICKNESSES] {
        let (lo, hi) = self.thickness_range_nm;
        std::array::from_fn(|i| lo + (hi - lo) * i as f64 / (BOUNCE_THICKNESSES - 1) as f64)
    }

    /// K and E per film thickness and roughness row, as the shader interpolates them; zeros
    /// for a model that does not read them (so the thesis model's frames, and the window's
    /// thickness slider under it, never compute the film seen from below).
    pub fn bounce_grid(&self, model: Model) -> BounceGrid {
        use rayon::prelude::*;
        if !model.reads_bounce() {
            return BounceGrid {
                range_nm: self.thickness_range_nm,
                tables: vec![crate::optics::brdf::exact::BounceTable::unused(); BOUNCE_THICKNESSES],
            };
        }
        let tables = self
            .bounce_thicknesses_nm()
            .par_iter()
            .map(|&d| crate::optics::brdf::exact::cached(self.stack, d).bounce_table(self.optical_depth))
            .collect();
        BounceGrid { range_nm: self.thickness_range_nm, tables }
    }

    /// The per-pixel layers of this material with its `bounce_grid` at the pixel's film
    /// thickness and roughness, the base albedo recovered from the colour map's `colour` as
    /// `model` reads it (`Model::base_albedo`): the CPU reference's twin of the shader's
    /// `layers_of`.
    pub fn layers(
        &self,
        model: Model,
        bounce: &BounceGrid,
        thickness_nm: f64,
        roughness: f64,
        colour: [f64; 3],
    ) -> crate::optics::brdf::Layers {
        let (k, e) = bounce.at(thickness_nm, roughness);
        let Stack { n0, n1, n2 } = self.stack;
        let optical_depth = self.optical_depth;
        let layers = crate::optics::brdf::Layers { n0, n1, n2, roughness, optical_depth, albedo: colour, k, e };
        crate::optics::brdf::Layers { albedo: model.base_albedo(colour, &layers), ..layers }
    }

    pub fn has_absorption(&self) -> bool {
        self.optical_depth.iter().any(|t| *t > 0.0)
    }

    /// The film method a pipeline needs: `chosen`, or none when the film is inert. (With no
    /// film the reflectance is the n0|n2 Fresnel term; n1 = n0 makes the film vanish, so the
    /// same holds.)
    pub fn specialised_method(&self, chosen: GpuFilmMethod) -> GpuFilmMethod {
        if self.film_is_inert() { GpuFilmMethod::None } else { chosen }
    }
}

/// Film thicknesses K and E are tabulated at over a material's thickness range. K depends
/// on the film: with K and E of the middle thickness alone, the white furnace of the
/// thesis stack was off by up to 0.115 over a 200 nm range (150–350 nm; 0.097 over
/// 0–200 nm, 0.076 over 300–500 nm). Eight points, 29 nm apart over the default range,
/// keep the interpolated K within the furnace's tolerance (tests/render.rs,
/// `the_renderer_keeps_the_furnace_across_the_thickness_range`); 8 × 16 rows is also an
/// array size the uniform's Pod layout takes.
pub const BOUNCE_THICKNESSES: usize = 8;

/// K and E of a material per film thickness (`BOUNCE_THICKNESSES` evenly over `range_nm`)
/// and roughness row: `LayerOptics::bounce_grid`, read by the shader's `layers_of` and the
/// CPU reference alike.
#[derive(Debug, Clone)]
pub struct BounceGrid {
    pub range_nm: (f64, f64),
    pub tables: Vec<crate::optics::brdf::exact::BounceTable>,
}

impl BounceGrid {
    /// K and E at a film thickness and roughness: linear in roughness between rows, then in
    /// thickness between tables (as `skin.wgsl`'s `layers_of`).
    pub fn at(&self, thickness_nm: f64, roughness: f64) -> ([f64; 3], [f64; 3]) {
        let (lo, hi) = self.range_nm;
        let x = if hi > lo { ((thickness_nm - lo) / (hi - lo)).clamp(0.0, 1.0) } else { 0.0 };
        let x = x * (BOUNCE_THICKNESSES - 1) as f64;
        let i = (x as usize).min(BOUNCE_THICKNESSES - 2);
        let f = x - i as f64;
        let (a, b) = (self.tables[i].at(roughness), self.tables[i + 1].at(roughness));
        let mix = |p: [f64; 3], q: [f64; 3]| [0, 1, 2].map(|c| p[c] * (1.0 - f) + q[c] * f);
        (mix(a.0, b.0), mix(a.1, b.1))
    }

    /// Every (K, E) row of every thickness.
    pub fn rows(&self) -> impl Iterator<Item = &([f64; 3], [f64; 3])> {
        self.tables.iter().flat_map(|t| t.rows.iter())
    }
}

#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct SceneUniform {
    pub view_proj: [[f32; 4]; 4],
    pub camera: [f32; 4],
    pub light_dir: [[f32; 4]; SCENE_LIGHTS],
    pub light_rgb: [[f32; 4]; SCENE_LIGHTS],
    pub sky_top: [f32; 4],
    pub sky_bottom: [f32; 4],
    pub film: [f32; 4],
    pub optical_depth: [f32; 4],
    /// K and E (rgb) per film thickness and roughness row (`LayerOptics::bounce_grid`),
    /// entry `thickness * E1_ROUGHNESS + row`.
    pub bounce_k: [[f32; 4]; E1_ROUGHNESS * BOUNCE_THICKNESSES],
    pub bounce_e: [[f32; 4]; E1_ROUGHNESS * BOUNCE_THICKNESSES],
}

impl SceneUniform {
    /// The uniform for a frame of a material with `optics` and its `bounce` grid for the
    /// frame's model (`LayerOptics::bounce_grid`).
    pub fn new(
        camera: &Camera,
        aspect: f32,
        lighting: &Lighting,
        optics: &LayerOptics,
        bounce: &BounceGrid,
    ) -> SceneUniform {
        let light = |l: &Light| {
            let d = l.direction.normalize();
            (
                [d.x, d.y, d.z, if l.enabled { 1.0 } else { 0.0 }],
                [l.irradiance[0], l.irradiance[1], l.irradiance[2], 0.0],
            )
        };
        let lights = lighting.lights().map(light);
        let p = camera.position();
        let rgb4 = |c: [f32; 3]| [c[0], c[1], c[2], 0.0];
        let tau = optics.optical_depth.map(|t| t as f32);
        let rows: Vec<&([f64; 3], [f64; 3])> = bounce.rows().collect();
        SceneUniform {
            view_proj: camera.view_proj(aspect).to_cols_array_2d(),
            camera: [p.x, p.y, p.z, 0.0],
            light_dir: lights.map(|l| l.0),
            light_rgb: lights.map(|l| l.1),
            sky_top: rgb4(lighting.sky_top),
            sky_bottom: rgb4(lighting.sky_bottom),
            film: [
                optics.thickness_range_nm.0 as f32,
                optics.thickness_range_nm.1 as f32,
                optics.stack.n0 as f32,
                optics.stack.n2 as f32,
            ],
            optical_depth: [tau[0], tau[1], tau[2], 0.0],
            bounce_k: std::array::from_fn(|i| rgb4(rows[i].0.map(|v| v as f32))),
            bounce_e: std::array::from_fn(|i| rgb4(rows[i].1.map(|v| v as f32))),
        }
    }
}
