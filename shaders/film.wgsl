// Film colour F_film(d, cos θ0) as linear sRGB, by the method chosen with the FILM_METHOD
// override constant: the WGSL twins of optics::lut (FILM_LUT), optics::methods rgb3
// (FILM_RGB3), spectral-N (FILM_SPECTRAL_N) and gaussian-fit (FILM_GAUSSIAN_FIT), and the
// plain Fresnel reflectance of n0|n2 for a material without a film (FILM_NONE; its layered
// coupling still reads the coupling texture, brdf.wgsl's coupling_is_baked). A pipeline
// specialised for one method carries only its code (the constant is resolved before the
// driver compiles the shader). The codes, the LUT's thickness axis (FINE_MAX_NM,
// COARSE_MAX_NM), the rgb3 wavelengths and the Belcour–Barla fits come from the generated
// prelude (render::engine::shaders).

override FILM_METHOD: u32 = FILM_LUT;

struct FilmInfo {
    n_cos: u32,
    n_fine: u32,
    n_coarse: u32,
    n_bands: u32,
    // n0, n1, n2 and the spectral-N band width in nm.
    iors_band: vec4<f32>,
    // XYZ (relative to illuminant E) to linear sRGB under D65, rows; for gaussian-fit.
    xyz_to_rgb: array<vec4<f32>, 3>,
}

// The per-material film colour table: x = thickness texel, y = cos texel, RGB, half floats,
// read with the sampler's bilinear filter (clamped to the edge texels).
@group(0) @binding(0) var<uniform> film_info: FilmInfo;
@group(0) @binding(1) var lut_texture: texture_2d<f32>;
@group(0) @binding(3) var lut_sampler: sampler;
// spectral-N: per band (centre nm, then linear-sRGB weights).
@group(0) @binding(2) var<storage, read> bands: array<vec4<f32>>;
// The rough lobe's table (render::engine::film::lobe_table, read by brdf.wgsl's
// parts_on_row and path_delta_in): per (mu, r) entry, row-major by roughness, LOBE_VEC4S
// vec4s of slots: this material's path delta (brdf.wgsl's path_delta_at), the lobe node
// (optics::brdf::energy::node) and this material's rule for light straight back through
// the top (optics::brdf::path).
@group(0) @binding(4) var<storage, read> lobe_table: array<vec4<f32>>;
// The layered model's coupling baked with the table (optics::lut::Lut::coupling): x = cos
// texel (uniform in sqrt(cos), optics::lut::coupling_texel_cos), the reflected share and the
// path delta (as in lobe_table's first slot) in the first n_cos texels and the
// multiple-scatter amplitude in the next n_cos; y = the rough lobe's roughness row
// (E1_ROUGHNESS); z = thickness texel, as the table's columns. Half floats, read with the
// same sampler (brdf.wgsl's coupling_table).
@group(0) @binding(5) var coupling_texture: texture_3d<f32>;

// The table's continuous thickness texel of d (nm), as optics::lut::Lut::column_f32.
fn lut_column(thickness_nm: f32) -> f32 {
    let d = max(thickness_nm, 0.0);
    let n_fine = f32(film_info.n_fine);
    var x: f32;
    if (d <= FINE_MAX_NM) {
        x = d * ((n_fine - 1.0) / FINE_MAX_NM);
    } else {
        x = (n_fine - 1.0) + (d - FINE_MAX_NM) * (f32(film_info.n_coarse) / (COARSE_MAX_NM - FINE_MAX_NM));
    }
    return min(x, n_fine + f32(film_info.n_coarse) - 1.0);
}

// Film colour at thickness d (nm) and incidence cosine c: the table's texel coordinates
// as in optics::lut::Lut::lookup_f32, then one filtered fetch at those coordinates.
fn film_lut(thickness_nm: f32, cos0: f32) -> vec3<f32> {
    let w = f32(film_info.n_fine + film_info.n_coarse);
    let x = lut_column(thickness_nm);
    let h = f32(film_info.n_cos);
    let y = clamp(cos0, 0.0, 1.0) * (h - 1.0);
    return textureSampleLevel(lut_texture, lut_sampler, vec2<f32>((x + 0.5) / w, (y + 0.5) / h), 0.0).rgb;
}

// ---- Complex arithmetic on vec2 (re, im), as optics::fast. ----

fn cmul(a: vec2<f32>, b: vec2<f32>) -> vec2<f32> {
    return vec2<f32>(a.x * b.x - a.y * b.y, a.x * b.y + a.y * b.x);
}

fn cdiv(a: vec2<f32>, b: vec2<f32>) -> vec2<f32> {
    let d = dot(b, b);
    return vec2<f32>((a.x * b.x + a.y * b.y) / d, (a.y * b.x - a.x * b.y) / d);
}

fn csqrt_real(x: f32) -> vec2<f32> {
    if (x >= 0.0) {
        return vec2<f32>(sqrt(x), 0.0);
    }
    return vec2<f32>(0.0, sqrt(-x));
}

fn cln(a: vec2<f32>) -> vec2<f32> {
    return vec2<f32>(0.5 * log(dot(a, a)), atan2(a.y, a.x));
}

// Fourier coefficients of one polarisation (optics::fast::Harmonics32).
struct Harmonics {
    c0: f32,
    d: vec2<f32>,
    q: vec2<f32>,
}

// As optics::fast::Film32: kappa1 = Im cos theta1 (> 0 beyond the critical angle of a film
// less dense than the ambient, where the wave in the film is evanescent), exact (the series is
// not used and band_reflectance reads the exact film: evanescent, or |q|^2 >= MAX_Q2), and
// the Fresnel amplitudes (r01 in xy, r12 in zw) of s and of p, and whether the substrate's
// and the film's indices are the ambient's (film_passes_all).
struct Film {
    s: Harmonics,
    p: Harmonics,
    cos1: f32,
    kappa1: f32,
    exact: bool,
    amplitudes_s: vec4<f32>,
    amplitudes_p: vec4<f32>,
    substrate_is_ambient: bool,
    film_is_ambient: bool,
}

// No interface at all at this thickness: everything passes (optics::film::Stack::passes_all,
// on f32 indices as optics::fast::Film32::passes_all).
fn film_passes_all(f: Film, thickness_nm: f32) -> bool {
    return f.substrate_is_ambient && (f.film_is_ambient || thickness_nm == 0.0);
}

fn harmonics(a: vec2<f32>, b: vec2<f32>) -> Harmonics {
    let q = -cmul(a, b);
    let k = cmul(b, vec2<f32>(1.0, 0.0) - cmul(a, a));
    let k2 = dot(k, k);
    let inv = 1.0 / max(1.0 - dot(q, q), HARMONICS_DENOM_MIN);
    return Harmonics(dot(a, a) + k2 * inv, cmul(k, vec2<f32>(a.x, -a.y)) + q * (k2 * inv), q);
}

// Snell's cos^2 in n of light at cosine cos in n0, below 0 beyond the critical angle of
// n0 > n; (1 - eta^2) + eta^2 cos^2, exact at grazing light where eta = 1
// (optics::film::snell_cos_sq). Every later file of a program reads it.
fn snell_cos_sq(n0: f32, n: f32, cos: f32) -> f32 {
    let eta2 = (n0 / n) * (n0 / n);
    return (1.0 - eta2) + eta2 * cos * cos;
}

fn cos_in(n0: f32, n: f32, cos0: f32) -> vec2<f32> {
    return csqrt_real(snell_cos_sq(n0, n, cos0));
}

fn r_s(ni: f32, ci: vec2<f32>, nj: f32, cj: vec2<f32>) -> vec2<f32> {
    return cdiv(ci * ni - cj * nj, ci * ni + cj * nj);
}

fn r_p(ni: f32, ci: vec2<f32>, nj: f32, cj: vec2<f32>) -> vec2<f32> {
    return cdiv(ci * nj - cj * ni, ci * nj + cj * ni);
}

fn film_coefficients(n0: f32, n1: f32, n2: f32, cos0_in: f32) -> Film {
    let cos0 = clamp(cos0_in, 0.0, 1.0);
    let substrate_is_ambient = n2 == n0;
    let film_is_ambient = n1 == n0;
    if (cos0 * cos0 < F32_MIN_POSITIVE) {
        // Grazing light is all reflected, unless there is no interface (optics::fast::film_f32).
        let none = Harmonics(1.0, vec2<f32>(0.0), vec2<f32>(0.0));
        let reflects_all = vec4<f32>(1.0, 0.0, 0.0, 0.0);
        return Film(none, none, 0.0, 0.0, true, reflects_all, reflects_all, substrate_is_ambient, film_is_ambient);
    }
    let c0 = vec2<f32>(cos0, 0.0);
    // Off exactly 0 at the film's critical angle (optics::fast::film_f32).
    let eta1 = n0 / n1;
    var x1 = snell_cos_sq(n0, n1, cos0);
    if (x1 == 0.0) {
        x1 = F32_EPSILON * abs(1.0 - eta1 * eta1);
    }
    let c1 = csqrt_real(x1);
    let c2 = cos_in(n0, n2, cos0);
    let a_s = r_s(n0, c0, n1, c1);
    let b_s = r_s(n1, c1, n2, c2);
    let a_p = r_p(n0, c0, n1, c1);
    let b_p = r_p(n1, c1, n2, c2);
    let s = harmonics(a_s, b_s);
    let p = harmonics(a_p, b_p);
    var cos1 = 0.0;
    if (c1.y == 0.0) {
        cos1 = c1.x;
    }
    let exact = !(c1.y == 0.0 && dot(s.q, s.q) < MAX_Q2 && dot(p.q, p.q) < MAX_Q2);
    return Film(s, p, cos1, c1.y, exact, vec4<f32>(a_s, b_s), vec4<f32>(a_p, b_p), substrate_is_ambient, film_is_ambient);
}

// One polarisation's exact reflectance |a + b e|^2 / |1 + a b e|^2 (optics::fast::
// airy_reflectance_f32).
fn airy_one(ab: vec4<f32>, e: vec2<f32>) -> f32 {
    let num = ab.xy + cmul(ab.zw, e);
    let den = vec2<f32>(1.0, 0.0) + cmul(cmul(ab.xy, ab.zw), e);
    return dot(num, num) / dot(den, den);
}

// The exact coherent film at one wavelength (optics::fast::airy_reflectance_f32).
fn airy_reflectance(f: Film, n1: f32, thickness_nm: f32, wavelength_nm: f32) -> f32 {
    if (film_passes_all(f, thickness_nm)) {
        return 0.0;
    }
    let k = 4.0 * PI * n1 * thickness_nm / wavelength_nm;
    let e = vec2<f32>(cos(k * f.cos1), sin(k * f.cos1)) * exp(-k * f.kappa1);
    return clamp(0.5 * (airy_one(f.amplitudes_s, e) + airy_one(f.amplitudes_p, e)), 0.0, 1.0);
}

fn sinc(x: f32) -> f32 {
    if (abs(x) < SINC_SMALL) {
        return 1.0;
    }
    return sin(x) / x;
}

// The box-prefiltered series in closed form (optics::fast::series).
fn series(h: Harmonics, phase: f32, box_width: f32) -> f32 {
    let z = vec2<f32>(cos(phase), sin(phase));
    let one = vec2<f32>(1.0, 0.0);
    var mean: vec2<f32>;
    if (box_width < BOX_NARROW_RAD) {
        mean = cdiv(cmul(h.d, z), one - cmul(h.q, z));
    } else if (dot(h.q, h.q) < Q_NEGLIGIBLE) {
        mean = cmul(h.d, z) * sinc(0.5 * box_width);
    } else {
        let half = 0.5 * box_width;
        let upper = cln(one - cmul(h.q, vec2<f32>(cos(phase + half), sin(phase + half))));
        let lower = cln(one - cmul(h.q, vec2<f32>(cos(phase - half), sin(phase - half))));
        mean = cmul(vec2<f32>(0.0, 1.0), cdiv(cmul(h.d, upper - lower), h.q)) * (1.0 / box_width);
    }
    return clamp(h.c0 + 2.0 * mean.x, 0.0, 1.0);
}

// optics::fast::band_reflectance_f32: the prefiltered series, or the exact film where the
// series is not used (f.exact).
fn band_reflectance(f: Film, n1: f32, thickness_nm: f32, wavelength_nm: f32, band_nm: f32) -> f32 {
    if (f.exact) {
        return airy_reflectance(f, n1, thickness_nm, wavelength_nm);
    }
    let phase = 4.0 * PI * n1 * thickness_nm * f.cos1 / wavelength_nm;
    let box_width = phase * band_nm / wavelength_nm;
    return 0.5 * (series(f.s, phase, box_width) + series(f.p, phase, box_width));
}

// rgb3: three wavelengths (RGB3_NM), each prefiltered over RGB3_BAND_NM.
fn film_rgb3(thickness_nm: f32, cos0: f32) -> vec3<f32> {
    let n = film_info.iors_band;
    let f = film_coefficients(n.x, n.y, n.z, cos0);
    return vec3<f32>(
        band_reflectance(f, n.y, thickness_nm, RGB3_NM.x, RGB3_BAND_NM),
        band_reflectance(f, n.y, thickness_nm, RGB3_NM.y, RGB3_BAND_NM),
        band_reflectance(f, n.y, thickness_nm, RGB3_NM.z, RGB3_BAND_NM),
    );
}

fn film_spectral_n(thickness_nm: f32, cos0: f32) -> vec3<f32> {
    let n = film_info.iors_band;
    let f = film_coefficients(n.x, n.y, n.z, cos0);
    var rgb = vec3<f32>(0.0);
    for (var i = 0u; i < film_info.n_bands; i++) {
        let band = bands[i];
        rgb += band_reflectance(f, n.y, thickness_nm, band.x, n.w) * band.yzw;
    }
    return rgb;
}

// Belcour & Barla (2017) Gaussian fits, optics::methods::BB_LOBES as (X, Y, Z, X's second
// lobe): amplitude with its normalisation folded in (BB_AMP), centre, variance.
fn bb_lobes(phase: f32, arg: f32) -> vec4<f32> {
    return BB_AMP * cos(BB_POS * phase + vec4<f32>(arg)) * exp(-BB_VAR * phase * phase);
}

// 16 |D|^2 |q|^(2H) < (GAUSSIAN_FIT_MAX_REST (1 - |q|^2))^2, as optics::methods::gaussian_fit_f32.
fn gaussian_fit_rest_is_small(h: Harmonics) -> bool {
    let q2 = dot(h.q, h.q);
    var q2h = 1.0;
    for (var m = 0u; m < GAUSSIAN_FIT_HARMONICS; m++) {
        q2h *= q2;
    }
    let allowed = GAUSSIAN_FIT_MAX_REST * (1.0 - q2);
    return 16.0 * dot(h.d, h.d) * q2h < allowed * allowed;
}

fn film_gaussian_fit(thickness_nm: f32, cos0: f32) -> vec3<f32> {
    let n = film_info.iors_band;
    let f = film_coefficients(n.x, n.y, n.z, cos0);
    // The harmonics left out, compared squared (optics::methods::GAUSSIAN_FIT_MAX_REST).
    if (f.exact || !(gaussian_fit_rest_is_small(f.s) && gaussian_fit_rest_is_small(f.p))) {
        return vec3<f32>(airy_reflectance(f, n.y, thickness_nm, GAUSSIAN_FIT_EXACT_NM));
    }
    let opd = 2.0 * n.y * thickness_nm * f.cos1;
    var xyz = vec3<f32>(0.5 * (f.s.c0 + f.p.c0));
    for (var pol = 0u; pol < 2u; pol++) {
        var h = f.s;
        if (pol == 1u) {
            h = f.p;
        }
        var c = h.d;
        for (var m = 1u; m <= GAUSSIAN_FIT_HARMONICS; m++) {
            let phase = 2.0 * PI * (f32(m) * opd) * BB_METRES_PER_NM;
            let mag = length(c);
            let arg = atan2(c.y, c.x);
            let lobes = bb_lobes(phase, arg);
            xyz += mag * vec3<f32>(lobes.x + lobes.w, lobes.y, lobes.z);
            c = cmul(c, h.q);
        }
    }
    let m = film_info.xyz_to_rgb;
    return vec3<f32>(dot(m[0].xyz, xyz), dot(m[1].xyz, xyz), dot(m[2].xyz, xyz));
}

// Unpolarised Fresnel reflectance of the n0|n2 interface (no film), grey; none where the
// indices are equal (no interface: grazing light read 0 / 0 there, as in film_passes_all).
fn film_none(cos0: f32) -> vec3<f32> {
    let n = film_info.iors_band;
    if (n.x == n.z) {
        return vec3<f32>(0.0);
    }
    let c0 = vec2<f32>(clamp(cos0, 0.0, 1.0), 0.0);
    let c2 = cos_in(n.x, n.z, c0.x);
    let rs = r_s(n.x, c0, n.z, c2);
    let rp = r_p(n.x, c0, n.z, c2);
    return vec3<f32>(0.5 * (dot(rs, rs) + dot(rp, rp)));
}

fn film_rgb(thickness_nm: f32, cos0: f32) -> vec3<f32> {
    switch FILM_METHOD {
        case FILM_RGB3: {
            return film_rgb3(thickness_nm, cos0);
        }
        case FILM_SPECTRAL_N: {
            return film_spectral_n(thickness_nm, cos0);
        }
        case FILM_GAUSSIAN_FIT: {
            return film_gaussian_fit(thickness_nm, cos0);
        }
        case FILM_NONE: {
            return film_none(cos0);
        }
        default: {
            return film_lut(thickness_nm, cos0);
        }
    }
}
