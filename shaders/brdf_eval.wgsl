// Compute entry points that evaluate skin_brdf (brdf.wgsl, prepended), or the film colour
// alone (film.wgsl's film_rgb, by the pipeline's FILM_METHOD), on a buffer of samples: the
// GPU side of the CPU/GPU comparisons in tests/gpu.rs.

struct Sample {
    normal_roughness: vec4<f32>,
    wi_thickness: vec4<f32>,
    wo_n0: vec4<f32>,
    tau_n2: vec4<f32>,
    albedo: vec4<f32>,
    k: vec4<f32>,
    e: vec4<f32>,
}

@group(1) @binding(0) var<storage, read> samples: array<Sample>;
@group(1) @binding(1) var<storage, read_write> results: array<vec4<f32>>;

@compute @workgroup_size(EVAL_WORKGROUP_SIZE)
fn eval_samples(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if (i >= arrayLength(&samples)) {
        return;
    }
    let s = samples[i];
    let layers = with_ms_norms(Layers(
        s.wo_n0.w,
        s.tau_n2.w,
        s.normal_roughness.w,
        s.wi_thickness.w,
        0.0,
        s.tau_n2.xyz,
        s.albedo.xyz,
        s.k.xyz,
        s.e.xyz,
        vec3<f32>(0.0),
        vec3<f32>(0.0),
    ));
    results[i] = vec4<f32>(skin_brdf(layers, s.normal_roughness.xyz, s.wi_thickness.xyz, s.wo_n0.xyz), 1.0);
}

// The film colour of each sample's thickness (wi_thickness.w) at the cosine wi_thickness.z
// (the light's direction against a normal along z), by the pipeline's FILM_METHOD.
@compute @workgroup_size(EVAL_WORKGROUP_SIZE)
fn film_samples(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if (i >= arrayLength(&samples)) {
        return;
    }
    let s = samples[i];
    results[i] = vec4<f32>(film_rgb(s.wi_thickness.w, s.wi_thickness.z), 1.0);
}
