// The skin pass: the multi-layer BRDF (brdf.wgsl) under the scene's lights, a layer stage or
// a single map on the body, and the G-buffer the CPU reference shades
// (src/render/reference/frame.rs is this file's CPU twin: keep the two in step).

// Layer stages of the thesis' Fig. 5.12: STAGE_DIFFUSE, STAGE_DIFFUSE_NORMAL (+ normal
// map), STAGE_FILM (the thin film alone), STAGE_ALL (codes from the generated prelude).
override STAGE: u32 = STAGE_ALL;
// VIEW_SHADED = shade; VIEW_COLOR ... VIEW_IRIDESCENCE = show that map unlit.
override VIEW_MAP: u32 = VIEW_SHADED;
// Which half of the G-buffer fs_gbuffer writes (two passes keep each under 32 bytes/pixel).
override GBUFFER_PART: u32 = GBUFFER_POSITION_NORMAL;
// Whether `shade` averages the film over the footprint's thickness spread (FilmFootprint::
// Spread) or shades the mean thickness alone (FilmFootprint::Mean: the G-buffer then holds
// no spread either, so the CPU reference shades as the frame did).
override FOOTPRINT_SPREAD: bool = true;

// The pixel's layers; K and E interpolated between the roughness rows (exact: they are
// linear in r between rows) and then between the film thicknesses (BounceGrid::at), the
// base albedo recovered from the colour map as the model reads it (base_albedo;
// LayerOptics::layers is the CPU twin).
fn layers_of(m: Material, thickness_offset_nm: f32) -> Layers {
    let j = lobe_row(m.roughness);
    let f = roughness_coordinate(m.roughness) - f32(j);
    var x = 0.0;
    if (scene.film.y > scene.film.x) {
        x = clamp((m.thickness_nm - scene.film.x) / (scene.film.y - scene.film.x), 0.0, 1.0);
    }
    x *= f32(BOUNCE_THICKNESSES - 1u);
    let t = min(u32(x), BOUNCE_THICKNESSES - 2u);
    let ft = x - f32(t);
    let a = t * E1_ROUGHNESS + j;
    let b = a + E1_ROUGHNESS;
    let k = mix(
        mix(scene.bounce_k[a].rgb, scene.bounce_k[a + 1u].rgb, f),
        mix(scene.bounce_k[b].rgb, scene.bounce_k[b + 1u].rgb, f),
        ft,
    );
    let e = mix(
        mix(scene.bounce_e[a].rgb, scene.bounce_e[a + 1u].rgb, f),
        mix(scene.bounce_e[b].rgb, scene.bounce_e[b + 1u].rgb, f),
        ft,
    );
    let tau = scene.optical_depth.rgb;
    let kd = base_albedo(m.albedo, tau, m.roughness, k, e);
    return with_ms_norms(
        Layers(scene.film.z, scene.film.w, m.roughness, m.thickness_nm, thickness_offset_nm, tau, kd, k, e, vec3<f32>(0.0), vec3<f32>(0.0)),
    );
}

// Ambient light from the sky gradient, as reference::shade_pixel: the sky seen along the
// mirror direction is reflected by the top (the model's coupling: the film for the thesis,
// the rough top's reflected share for the layered model, its multiple scattering taken
// along the mirror too); the sky seen along the normal goes through
// the layer model (brdf.wgsl's ambient_diffuse).
fn ambient(layers: Layers, n: vec3<f32>, wo: vec3<f32>, top_o: Top, with_diffuse: bool) -> vec3<f32> {
    var result = sky(reflect(-wo, n)) * top_o.reflected;
    if (with_diffuse) {
        result += sky(n) * ambient_diffuse(layers, max(dot(n, wo), COS_MIN), top_o);
    }
    return result;
}

// How far from the mean thickness the film is read either side (nm) where the pixel's
// footprint covers a spread of thicknesses: the twin of render::engine::material::
// footprint_offset_nm, which says why (two thicknesses whose average damps the film's first
// harmonic at FOOTPRINT_WAVELENGTH_NM as the spread does).
fn footprint_offset_nm(spread_nm: f32, cos_o: f32) -> f32 {
    let n = film_info.iors_band;
    let cos1 = sqrt(max(snell_cos_sq(n.x, n.y, cos_o), 0.0));
    let phase_per_nm = 4.0 * PI * n.y * cos1 / FOOTPRINT_WAVELENGTH_NM;
    if (phase_per_nm <= 0.0) {
        return spread_nm;
    }
    let exponent = 0.5 * (phase_per_nm * spread_nm) * (phase_per_nm * spread_nm);
    if (exponent < FOOTPRINT_SMALL_EXPONENT) {
        return spread_nm;
    }
    return acos(exp(-exponent)) / phase_per_nm;
}

// Where the pixel's footprint covers a spread of film thicknesses (a distant snake, whose
// mip texels average many scales; a scale's edge up close), the film is read at two
// thicknesses either side of the mean and averaged (brdf.wgsl's film_clamped and
// coupling_table read Layers::thickness_offset_nm), instead of at the mean thickness, whose
// film colour is far more saturated than the footprint's mean colour (BENCHMARKS.md,
// "Iridescence seen from afar"). 0 where the film does not show: the diffuse stages read
// none (shade returns before it asks), and a material without one (FILM_NONE) is the same
// at every thickness.
fn film_offset_nm(m: Material, cos_o: f32) -> f32 {
    if (!FOOTPRINT_SPREAD || FILM_METHOD == FILM_NONE || m.thickness_spread_nm <= 0.0) {
        return 0.0;
    }
    return footprint_offset_nm(m.thickness_spread_nm, cos_o);
}

// A Lambertian surface of `albedo` at normal n under the scene's lights and sky: the diffuse
// stages and the ground.
fn lambertian(albedo: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    var radiance = vec3<f32>(0.0);
    for (var i = 0u; i < SCENE_LIGHTS; i++) {
        let wi = scene.light_dir[i].xyz;
        radiance += scene.light_dir[i].w * scene.light_rgb[i].rgb * albedo / PI * max(dot(n, wi), 0.0);
    }
    return radiance + sky(n) * albedo;
}

fn shade(m: Material, world: vec3<f32>) -> vec3<f32> {
    let wo = normalize(scene.camera.xyz - world);
    var radiance = vec3<f32>(0.0);
    if (STAGE == STAGE_DIFFUSE || STAGE == STAGE_DIFFUSE_NORMAL) {
        var n = m.normal;
        if (STAGE == STAGE_DIFFUSE) {
            n = m.geometric;
        }
        return lambertian(m.albedo, n);
    }
    let cos_o = max(dot(m.normal, wo), COS_MIN);
    let layers = layers_of(m, film_offset_nm(m, cos_o));
    // What the top does towards the viewer, shared by both lights and the ambient term.
    let top_o = coupling(layers, cos_o);
    for (var i = 0u; i < SCENE_LIGHTS; i++) {
        let wi = scene.light_dir[i].xyz;
        let cos_i = max(dot(m.normal, wi), 0.0);
        if (scene.light_dir[i].w > 0.0 && cos_i > 0.0) {
            let f = skin_brdf_seen(layers, m.normal, wi, wo, top_o, STAGE == STAGE_ALL);
            radiance += scene.light_dir[i].w * scene.light_rgb[i].rgb * f * cos_i;
        }
    }
    return radiance + ambient(layers, m.normal, wo, top_o, STAGE == STAGE_ALL);
}

// An sRGB encoding to linear light (export::srgb's `decode`, its twin).
fn srgb_decode(encoded: vec3<f32>) -> vec3<f32> {
    let e = clamp(encoded, vec3<f32>(0.0), vec3<f32>(1.0));
    let curve = pow((e + vec3<f32>(SRGB_OFFSET)) / SRGB_SCALE, vec3<f32>(SRGB_GAMMA));
    return select(curve, e / SRGB_SLOPE, e <= vec3<f32>(SRGB_ENCODED_KNEE));
}

// One map as its file stores it. The frame's sRGB target encodes what is written: the
// colour map is linear colour (its file sRGB), the others are values whose files hold them
// linearly, so they are decoded first and the target gives back their codes (the map
// viewer showed a flat normal as (187, 189, 255) for the file's (128, 131, 255), a sweep).
fn map_view(m: Material) -> vec3<f32> {
    switch VIEW_MAP {
        case VIEW_COLOR: {
            return m.albedo;
        }
        case VIEW_HEIGHT: {
            return srgb_decode(vec3<f32>(m.height));
        }
        case VIEW_NORMAL: {
            return srgb_decode(m.map_normal * 0.5 + vec3<f32>(0.5));
        }
        case VIEW_ROUGHNESS: {
            return srgb_decode(vec3<f32>(m.roughness));
        }
        default: {
            return srgb_decode(vec3<f32>(m.map_value));
        }
    }
}

@fragment
fn fs_skin(in: VertexOut) -> @location(0) vec4<f32> {
    let m = sample_material(in);
    if (VIEW_MAP != VIEW_SHADED) {
        return vec4<f32>(map_view(m), 1.0);
    }
    return vec4<f32>(shade(m, in.world), 1.0);
}

struct GBuffer {
    @location(0) first: vec4<f32>,
    @location(1) second: vec4<f32>,
}

// Part 0: (world position, thickness nm), (shading normal, roughness).
// Part 1: (albedo, thickness spread nm), (geometric normal, height map value); a covered
// pixel has a unit geometric normal, an uncovered one the cleared zero vector.
@fragment
fn fs_gbuffer(in: VertexOut) -> GBuffer {
    let m = sample_material(in);
    var out: GBuffer;
    if (GBUFFER_PART == GBUFFER_POSITION_NORMAL) {
        out.first = vec4<f32>(in.world, m.thickness_nm);
        out.second = vec4<f32>(m.normal, m.roughness);
    } else {
        out.first = vec4<f32>(m.albedo, select(0.0, m.thickness_spread_nm, FOOTPRINT_SPREAD));
        out.second = vec4<f32>(m.geometric, m.height);
    }
    return out;
}

// The ground: a grey Lambertian floor under the same lights and sky.
@fragment
fn fs_ground(in: VertexOut) -> @location(0) vec4<f32> {
    let n = vec3<f32>(0.0, 1.0, 0.0);
    // A box-filtered checker (the analytic integral over the pixel footprint), so the far
    // ground fades to grey instead of aliasing.
    let p = in.uv * 2.0;
    let w = fwidth(p) + vec2<f32>(1e-4); // not a shared constant: keeps w > 0 on flat ground
    let i = 2.0 * (abs(fract((p - 0.5 * w) * 0.5) - 0.5) - abs(fract((p + 0.5 * w) * 0.5) - 0.5)) / w;
    let checker = mix(0.07, 0.09, 0.5 - 0.5 * i.x * i.y);
    return vec4<f32>(lambertian(vec3<f32>(checker), n), 1.0);
}
