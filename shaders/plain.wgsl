// A plain metal-roughness PBR shader (GGX + Smith + Schlick, Lambert; metallic = 0, F0 = 0.04)
// on the same mesh, maps and lights: the baseline `snakeskin bench render` compares the skin
// shader against.

// The baseline's Schlick F0 for a dielectric (n = 1.5), its own number.
const PLAIN_F0: f32 = 0.04; // not a shared constant

// Schlick's approximation of the Fresnel reflectance at `cos_theta`, for the lights' half
// vectors and the sky's view direction alike.
fn plain_schlick(cos_theta: f32) -> f32 {
    return PLAIN_F0 + (1.0 - PLAIN_F0) * pow(1.0 - max(cos_theta, 0.0), 5.0);
}

fn plain_brdf(albedo: vec3<f32>, roughness: f32, n: vec3<f32>, wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    let cos_i = dot(n, wi);
    let cos_o = dot(n, wo);
    if (cos_i <= 0.0 || cos_o <= 0.0) {
        return vec3<f32>(0.0);
    }
    let h = normalize(wi + wo);
    let alpha = max(roughness * roughness, ALPHA_MIN);
    let a2 = alpha * alpha;
    let cos_h = max(dot(n, h), 0.0);
    let t = cos_h * cos_h * (a2 - 1.0) + 1.0;
    let d = a2 / (PI * t * t);
    let vis = 0.5 / (cos_i * sqrt(cos_o * cos_o * (1.0 - a2) + a2) + cos_o * sqrt(cos_i * cos_i * (1.0 - a2) + a2));
    let f = plain_schlick(dot(wo, h));
    return vec3<f32>(d * vis * f) + (1.0 - f) * albedo / PI;
}

@fragment
fn fs_plain(in: VertexOut) -> @location(0) vec4<f32> {
    let m = sample_material(in);
    let wo = normalize(scene.camera.xyz - in.world);
    var radiance = vec3<f32>(0.0);
    for (var i = 0u; i < SCENE_LIGHTS; i++) {
        let wi = scene.light_dir[i].xyz;
        radiance += scene.light_dir[i].w * scene.light_rgb[i].rgb * plain_brdf(m.albedo, m.roughness, m.normal, wi, wo)
            * max(dot(m.normal, wi), 0.0);
    }
    let f = plain_schlick(dot(m.normal, wo));
    radiance += sky(m.normal) * m.albedo * (1.0 - f) + sky(reflect(-wo, m.normal)) * f;
    return vec4<f32>(radiance, 1.0);
}
