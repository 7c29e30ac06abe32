// Resolve of the HDR image to the display: exposure, then the Khronos PBR Neutral tone
// mapper (Khronos 3D Commerce, 2024: hue-preserving, leaves colours below 0.76 nearly
// untouched, so base colours stay recognisable), then sRGB encoding by the Rgba8UnormSrgb
// target. `render::reference::frame::display` (with `pbr_neutral`) is its CPU twin; the
// curve's constants and the modes come from the generated prelude. TONE_MAP_NONE (the map
// viewer) skips the curve.

struct ToneMap {
    exposure: f32,
    mode: u32,
    _pad0: u32,
    _pad1: u32,
}

@group(0) @binding(0) var hdr: texture_2d<f32>;
@group(0) @binding(1) var<uniform> tone: ToneMap;

@vertex
fn vs_fullscreen(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let x = f32(i32(i & 1u) * 4 - 1);
    let y = f32(i32(i >> 1u) * 4 - 1);
    return vec4<f32>(x, y, 0.0, 1.0);
}

fn pbr_neutral(color_in: vec3<f32>) -> vec3<f32> {
    let start_compression = PBR_NEUTRAL_START_COMPRESSION;
    let desaturation = PBR_NEUTRAL_DESATURATION;
    var color = color_in;
    let x = min(color.r, min(color.g, color.b));
    var offset = PBR_NEUTRAL_OFFSET;
    if (x < 2.0 * PBR_NEUTRAL_OFFSET) {
        offset = x - x * x / (4.0 * PBR_NEUTRAL_OFFSET);
    }
    color -= vec3<f32>(offset);
    let peak = max(color.r, max(color.g, color.b));
    if (peak < start_compression) {
        return color;
    }
    let d = 1.0 - start_compression;
    let new_peak = 1.0 - d * d / (peak + d - start_compression);
    color *= new_peak / peak;
    let g = 1.0 - 1.0 / (desaturation * (peak - new_peak) + 1.0);
    return mix(color, vec3<f32>(new_peak), g);
}

@fragment
fn fs_tonemap(@builtin(position) position: vec4<f32>) -> @location(0) vec4<f32> {
    let c = max(textureLoad(hdr, vec2<i32>(position.xy), 0).rgb, vec3<f32>(0.0));
    if (tone.mode == TONE_MAP_NONE) {
        return vec4<f32>(clamp(c, vec3<f32>(0.0), vec3<f32>(1.0)), 1.0);
    }
    return vec4<f32>(clamp(pbr_neutral(c * tone.exposure), vec3<f32>(0.0), vec3<f32>(1.0)), 1.0);
}
