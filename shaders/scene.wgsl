// The scene every shading program draws: the snake body (instanced for many snakes), its
// material maps, the camera, up to two directional lights and a sky-gradient ambient term.
// Groups: 0 = film (film.wgsl, skin only), 1 = scene uniforms, 2 = material maps.

struct Scene {
    view_proj: mat4x4<f32>,
    // xyz: camera position; w: unused.
    camera: vec4<f32>,
    // xyz: unit direction towards the light; w: 1 if the light is on.
    light_dir: array<vec4<f32>, SCENE_LIGHTS>,
    // Irradiance on a surface facing the light, linear RGB.
    light_rgb: array<vec4<f32>, SCENE_LIGHTS>,
    // Sky radiance straight up and straight down (the gradient's ends).
    sky_top: vec4<f32>,
    sky_bottom: vec4<f32>,
    // x, y: film thickness in nm at iridescence-map values 0 and 1; z: n0; w: n2.
    film: vec4<f32>,
    // rgb: pigment optical depth tau = sigma0 * delta1.
    optical_depth: vec4<f32>,
    // The stack's K and E (rgb) per film thickness (BOUNCE_THICKNESSES evenly over film.xy)
    // and roughness row, entry thickness * E1_ROUGHNESS + row (LayerOptics::bounce_grid).
    bounce_k: array<vec4<f32>, BOUNCE_ENTRIES>,
    bounce_e: array<vec4<f32>, BOUNCE_ENTRIES>,
}

@group(1) @binding(0) var<uniform> scene: Scene;
// rgb: linear albedo (color map), a: perceptual roughness.
@group(2) @binding(0) var albedo_roughness: texture_2d<f32>;
// rgb: tangent-space normal (OpenGL, +Y up the image), a: height.
@group(2) @binding(1) var normal_height: texture_2d<f32>;
// r: iridescence map value t in [0, 1]; g: (t - THICKNESS_MOMENT_CENTRE)^2, so that the
// filtered pair gives the footprint's variance (render::engine::material).
@group(2) @binding(2) var thickness_map: texture_2d<f32>;
@group(2) @binding(3) var map_sampler: sampler;

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) tangent: vec4<f32>,
    @location(3) uv: vec2<f32>,
    // Per instance: x, z offset on the ground, yaw in radians.
    @location(4) placement: vec4<f32>,
}

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) tangent: vec4<f32>,
    @location(3) uv: vec2<f32>,
}

fn yaw(v: vec3<f32>, angle: f32) -> vec3<f32> {
    let c = cos(angle);
    let s = sin(angle);
    return vec3<f32>(c * v.x + s * v.z, v.y, -s * v.x + c * v.z);
}

@vertex
fn vs_main(v: VertexIn) -> VertexOut {
    var out: VertexOut;
    let world = yaw(v.position, v.placement.z) + vec3<f32>(v.placement.x, 0.0, v.placement.y);
    out.clip = scene.view_proj * vec4<f32>(world, 1.0);
    out.world = world;
    out.normal = yaw(v.normal, v.placement.z);
    out.tangent = vec4<f32>(yaw(v.tangent.xyz, v.placement.z), v.tangent.w);
    out.uv = v.uv;
    return out;
}

// The material at a fragment: what the G-buffer stores and the shading reads.
struct Material {
    albedo: vec3<f32>,
    roughness: f32,
    // Shading normal after normal mapping, and the interpolated geometric normal.
    normal: vec3<f32>,
    geometric: vec3<f32>,
    thickness_nm: f32,
    // The standard deviation of the film thickness over the pixel's footprint (nm; 0 where
    // it is under THICKNESS_SPREAD_MIN of the map's range, half-float rounding).
    thickness_spread_nm: f32,
    height: f32,
    map_normal: vec3<f32>,
    map_value: f32,
}

fn sample_material(in: VertexOut) -> Material {
    var m: Material;
    let ar = textureSample(albedo_roughness, map_sampler, in.uv);
    let nh = textureSample(normal_height, map_sampler, in.uv);
    let moments = textureSample(thickness_map, map_sampler, in.uv).rg;
    let t = moments.r;
    m.albedo = ar.rgb;
    m.roughness = ar.a;
    m.height = nh.a;
    m.map_value = t;
    m.map_normal = nh.xyz;
    let n = normalize(in.normal);
    // Gram-Schmidt: the interpolated tangent is not quite orthogonal to the normal.
    let t_axis = normalize(in.tangent.xyz - n * dot(n, in.tangent.xyz));
    let b_axis = in.tangent.w * cross(n, t_axis);
    // Mip averaging shortens the stored normals; renormalise.
    let tn = normalize(nh.xyz);
    m.normal = normalize(t_axis * tn.x + b_axis * tn.y + n * tn.z);
    m.geometric = n;
    m.thickness_nm = mix(scene.film.x, scene.film.y, clamp(t, 0.0, 1.0));
    let spread = sqrt(max(moments.g - (t - THICKNESS_MOMENT_CENTRE) * (t - THICKNESS_MOMENT_CENTRE), 0.0));
    m.thickness_spread_nm = select(0.0, spread * abs(scene.film.y - scene.film.x), spread > THICKNESS_SPREAD_MIN);
    return m;
}

fn sky(direction: vec3<f32>) -> vec3<f32> {
    return mix(scene.sky_bottom.rgb, scene.sky_top.rgb, clamp(0.5 + 0.5 * direction.y, 0.0, 1.0));
}
