// The snake-skin BRDF in WGSL: the twin of optics::brdf (Model::eval_f32; keep the two in
// step: tests/gpu.rs compares them on 10,000 random inputs per model, with the CPU reading
// the LUT at the half precision the GPU texture holds). One GGX top interface over the layer
// model chosen by the BRDF_MODEL override constant (codes MODEL_* from the generated
// prelude, as optics::brdf::Model::code):
//   f = D G2 F(|wo.h|) / (4 |n.wi| |n.wo|) + f_diff(model)
// ALPHA_MIN and COS_MIN (the GGX alpha floor and the cosine floor) come from the prelude.

// Film colour comes from film_rgb (film.wgsl, prepended before this file).
override BRDF_MODEL: u32 = MODEL_LAYERED;
// False for a pipeline specialised to a material with no absorption (tau = 0): the
// attenuation and the refracted path length are skipped.
override HAS_ABSORPTION: bool = true;

struct Layers {
    n0: f32,
    n2: f32,
    roughness: f32,
    thickness_nm: f32,
    // Where the pixel's footprint spreads over several thicknesses, the film is read this
    // far either side of thickness_nm and averaged (skin.wgsl's film_offset_nm); 0: read
    // at thickness_nm.
    thickness_offset_nm: f32,
    optical_depth: vec3<f32>,
    albedo: vec3<f32>,
    // The stack's bounce terms (layered model): K sent back to the base, E escaping.
    k: vec3<f32>,
    e: vec3<f32>,
    // X = 2 int x(mu) mu dmu on the two roughness rows around the roughness, the layered
    // model's multiple-scatter normalisation (energy::ms_norm_on_row), for the direct film
    // methods: with_ms_norms computes it once per pixel (every light's coupling and the
    // ambient one read it); the LUT and no-film pipelines read it baked into the coupling
    // texture (coupling_is_baked).
    ms_norm_lower: vec3<f32>,
    ms_norm_upper: vec3<f32>,
}

fn safe_normalize(v: vec3<f32>, fallback: vec3<f32>) -> vec3<f32> {
    let len = length(v);
    // Finite and not too short (Rust's is_finite: NaN fails both tests, infinity the second).
    if (len > LENGTH_MIN && len <= F32_MAX) {
        return v / len;
    }
    return fallback;
}

// How many thicknesses a film read averages: two where the pixel's footprint spreads
// (Layers::thickness_offset_nm), else one; and the k-th of them (the mean itself, which is
// never below 0, where there is no offset).
fn footprint_reads(layers: Layers) -> u32 {
    return select(1u, 2u, layers.thickness_offset_nm > 0.0);
}

fn footprint_thickness(layers: Layers, k: u32) -> f32 {
    return max(layers.thickness_nm + select(-1.0, 1.0, k == 1u) * layers.thickness_offset_nm, 0.0);
}

// The film colour the layers read (the mean of two thicknesses where the footprint spreads).
// The table's two fetches are written out; the other methods loop over the thicknesses
// through one call of film_rgb: a second call written out was inlined with every film
// method's code, and lavapipe's compiler held 136 MiB more for the same pipelines (a
// preview's peak 209 -> 345 MiB, 0.4 s more to start). Written out, the second fetch only
// where there are two: the LUT pipeline's whole-snake frame on lavapipe took 106 ms, against
// 114 averaging two fetches always and 133 through the loop.
fn film_clamped(layers: Layers, c: f32) -> vec3<f32> {
    let cos0 = clamp(c, 0.0, 1.0);
    let reads = footprint_reads(layers);
    var film = vec3<f32>(0.0);
    if (FILM_METHOD == FILM_LUT) {
        film = film_lut(footprint_thickness(layers, 0u), cos0);
        if (reads == 2u) {
            film += film_lut(footprint_thickness(layers, 1u), cos0);
        }
    } else {
        for (var k = 0u; k < reads; k++) {
            film += film_rgb(footprint_thickness(layers, k), cos0);
        }
    }
    return clamp(film / f32(reads), vec3<f32>(0.0), vec3<f32>(1.0));
}

// Smith Lambda for GGX at cosine c, a2 = alpha^2 (Heitz 2014, eq. 72; optics::brdf::ggx).
fn smith_lambda(c: f32, a2: f32) -> f32 {
    return 0.5 * (sqrt(1.0 + a2 * max(1.0 - c * c, 0.0) / (c * c)) - 1.0);
}

// D G2 / (4 cos_i cos_o) for GGX with Smith height-correlated G2 (optics::brdf::ggx).
fn specular_scale(cos_h: f32, sin2_h: f32, cos_i: f32, cos_o: f32, a2: f32) -> f32 {
    let t = sin2_h + cos_h * cos_h * a2;
    let d = a2 / (PI * t * t);
    let g2 = 1.0 / (1.0 + smith_lambda(cos_i, a2) + smith_lambda(cos_o, a2));
    return d * g2 / (4.0 * cos_i * cos_o);
}

// GGX alpha of a roughness: roughness^2 within [ALPHA_MIN, 1] (optics::brdf::ggx_alpha).
fn ggx_alpha(roughness: f32) -> f32 {
    return clamp(roughness * roughness, ALPHA_MIN, 1.0);
}

// (n0/n2)^2, the radiance factor of light leaving the pigment layer into the ambient
// (optics::brdf::radiance_factor).
fn radiance_factor(n0: f32, n2: f32) -> f32 {
    return (n0 / n2) * (n0 / n2);
}

// ---- The thesis model (optics::brdf::thesis). ----

// (1 - F(n.wi)) (1 - F(n.wo)) exp(-tau (1/cos_t(wi) + 1/cos_t(wo))) k_d / pi.
fn thesis_diffuse(layers: Layers, cos_i: f32, cos_o: f32, f_i: vec3<f32>, f_o: vec3<f32>) -> vec3<f32> {
    let ki = snell_cos_sq(layers.n0, layers.n2, cos_i);
    let ko = snell_cos_sq(layers.n0, layers.n2, cos_o);
    if (!(ki > 0.0 && ko > 0.0)) {
        return vec3<f32>(0.0);
    }
    var diffuse = (vec3<f32>(1.0) - f_i) * (vec3<f32>(1.0) - f_o) * max(layers.albedo, vec3<f32>(0.0)) / PI;
    if (HAS_ABSORPTION) {
        let path = 1.0 / max(sqrt(ki), COS_MIN) + 1.0 / max(sqrt(ko), COS_MIN);
        diffuse *= exp(-max(layers.optical_depth, vec3<f32>(0.0)) * path);
    }
    return diffuse;
}

// The sky along the normal enters through the film (1 - F at the view cosine) and is
// attenuated along the view path plus one layer thickness.
fn thesis_ambient_diffuse(layers: Layers, cos_o: f32, f_o: vec3<f32>) -> vec3<f32> {
    var base = (vec3<f32>(1.0) - f_o) * max(layers.albedo, vec3<f32>(0.0));
    if (HAS_ABSORPTION) {
        let k = snell_cos_sq(layers.n0, layers.n2, cos_o);
        let path = 1.0 / max(sqrt(max(k, 0.0)), COS_MIN) + 1.0;
        base *= exp(-max(layers.optical_depth, vec3<f32>(0.0)) * path);
    }
    return base;
}

// ---- The layered model (optics::brdf::layered). ----

// What the top does by itself for light from a direction (energy::Top): the share it
// reflects (the diffuse lobe lets 1 minus this in, the ambient mirror term is the sky times
// this), the amplitude of its multiple-scatter lobe, f_ms = ms_i ms_o, and how much more
// obliquely than Snell's law the light it lets in crosses the pigment layer (cos_eff -
// cos_t, path_delta_at; 0 for the thesis model, which reads cos_t).
struct Top {
    reflected: vec3<f32>,
    ms: vec3<f32>,
    path_delta: f32,
}

// The rough lobe's table (the film bind group's lobe_table, render::engine::film::
// lobe_table): per (mu, r) entry LOBE_VEC4S vec4s holding its slots in order: the pigment
// layer's path delta (path_delta_at), the lobe node from LOBE_NODE_SLOT
// (optics::brdf::energy::node: its albedo E1 for F = 1, the five-point Gauss rule over its
// microfacet cosines, the last weight 1 minus the others, and the rule for light it
// scatters more than once, energy::Multiple: nodes a and b, the weights M of the film's
// products, the share s reflected exactly twice) and from LOBE_THROUGH_SLOT the rule for
// light that comes straight back through the top (W and a three-point rule:
// optics::brdf::path::PathTable::through).

// The lobe table's cell at (mu, r): the indices of its lower corners (LOBE_VEC4S vec4s per
// entry) and the bilinear weights.
struct LobeCell {
    k00: u32,
    k01: u32,
    fx: f32,
    fy: f32,
}

// The continuous row coordinate of `roughness` in every table with a roughness axis, rows
// uniform in r (optics::brdf::energy::GridCell::row_coordinate).
fn roughness_coordinate(roughness: f32) -> f32 {
    return clamp(roughness, 0.0, 1.0) * f32(E1_ROUGHNESS - 1u);
}

// The lobe table's roughness row below `roughness` (GridCell::at's j).
fn lobe_row(roughness: f32) -> u32 {
    return min(u32(roughness_coordinate(roughness)), E1_ROUGHNESS - 2u);
}

fn lobe_cell(cos: f32, roughness: f32) -> LobeCell {
    // sqrt: the nodes are uniform in sqrt(mu) (optics::brdf::energy::node_mu).
    let x = sqrt(clamp(cos, 0.0, 1.0)) * f32(E1_MU - 1u);
    let y = roughness_coordinate(roughness);
    let i = min(u32(x), E1_MU - 2u);
    let j = lobe_row(roughness);
    return LobeCell(LOBE_VEC4S * (j * E1_MU + i), LOBE_VEC4S * ((j + 1u) * E1_MU + i), x - f32(i), y - f32(j));
}

// cos_eff(mu, r) - cos_t(mu): how much more obliquely than Snell's law the light the rough
// top lets in crosses the pigment layer, bilinear in the first slot of the lobe table's
// entries (this material's optics::brdf::path table; PathTable::cos_eff), in the lobe
// table's cell c.
fn path_delta_in(c: LobeCell) -> f32 {
    let lower = mix(lobe_table[c.k00].x, lobe_table[c.k00 + LOBE_VEC4S].x, c.fx);
    let upper = mix(lobe_table[c.k01].x, lobe_table[c.k01 + LOBE_VEC4S].x, c.fx);
    return mix(lower, upper, c.fy);
}

fn path_delta_at(cos: f32, roughness: f32) -> f32 {
    return path_delta_in(lobe_cell(cos, roughness));
}

// a(mu) = (1 - s(mu)) exp(-tau / cos_eff(mu, r)): the light that reaches the base, s what
// the rough lobe reflects and cos_eff - cos_t its path delta (the top at mu: coupling).
fn layered_entering(layers: Layers, cos: f32, top: Top) -> vec3<f32> {
    // Below 0 beyond the critical angle of n0 > n2, where a rough top still lets 1 - s in
    // and cos_t is taken as 0 (optics::brdf::path::snell_cos).
    let k = snell_cos_sq(layers.n0, layers.n2, cos);
    var a = vec3<f32>(1.0) - top.reflected;
    if (HAS_ABSORPTION) {
        let path_cos = max(sqrt(max(k, 0.0)) + top.path_delta, COS_MIN);
        a *= exp(-max(layers.optical_depth, vec3<f32>(0.0)) / path_cos);
    }
    return a;
}

// t1 = exp(-tau / cos_eff(1, r)): what the pigment layer lets through of the light the top
// lets in at normal incidence (optics::brdf::layered::normal_transmittance).
fn normal_transmittance(optical_depth: vec3<f32>, roughness: f32) -> vec3<f32> {
    if (!HAS_ABSORPTION) {
        return vec3<f32>(1.0);
    }
    return exp(-max(optical_depth, vec3<f32>(0.0)) / max(1.0 + path_delta_at(1.0, roughness), COS_MIN));
}

// (n0/n2)^2 k_d a(mu_i) a(mu_o) / (pi (1 - k_d K)), the two paths through the pigment layer
// in one exponential (layered::diffuse_f32), with the tops at mu_i and mu_o (coupling).
fn layered_diffuse(layers: Layers, cos_i: f32, cos_o: f32, top_i: Top, top_o: Top) -> vec3<f32> {
    let eta2 = radiance_factor(layers.n0, layers.n2);
    let k_i = snell_cos_sq(layers.n0, layers.n2, cos_i);
    let k_o = snell_cos_sq(layers.n0, layers.n2, cos_o);
    let kd = clamp(layers.albedo, vec3<f32>(0.0), vec3<f32>(1.0));
    var a = (vec3<f32>(1.0) - top_i.reflected) * (vec3<f32>(1.0) - top_o.reflected);
    if (HAS_ABSORPTION) {
        // cos_t 0 beyond the critical angle of n0 > n2 (layered_entering).
        let inverse_path = 1.0 / max(sqrt(max(k_i, 0.0)) + top_i.path_delta, COS_MIN)
            + 1.0 / max(sqrt(max(k_o, 0.0)) + top_o.path_delta, COS_MIN);
        a *= exp(-max(layers.optical_depth, vec3<f32>(0.0)) * inverse_path);
    }
    return eta2 * kd * a / (PI * (vec3<f32>(1.0) - kd * layers.k));
}

// a(mu_o) k_d E / (1 - k_d K): the directional diffuse reflectance, by reciprocity the
// response to a uniform sky.
fn layered_ambient_diffuse(layers: Layers, cos_o: f32, top_o: Top) -> vec3<f32> {
    let kd = clamp(layers.albedo, vec3<f32>(0.0), vec3<f32>(1.0));
    return layered_entering(layers, cos_o, top_o) * kd * layers.e / (vec3<f32>(1.0) - kd * layers.k);
}

// k_d = c / (t1 E + c K), at most 1: the base albedo that shows the visible diffuse colour c
// (optics::brdf::layered::base_albedo; t1 normal_transmittance).
fn layered_base_albedo(colour: vec3<f32>, t1: vec3<f32>, k: vec3<f32>, e: vec3<f32>) -> vec3<f32> {
    let c = max(colour, vec3<f32>(0.0));
    let denominator = t1 * e + c * k;
    return select(vec3<f32>(0.0), min(c / denominator, vec3<f32>(1.0)), denominator > vec3<f32>(0.0));
}

// ---- The model seam (optics::brdf::Model). ----

// The base albedo k_d behind a colour-map value (Model::base_albedo): the thesis reads the
// map as k_d; the layered model as the visible diffuse colour, inverted through the stack.
fn base_albedo(colour: vec3<f32>, optical_depth: vec3<f32>, roughness: f32, k: vec3<f32>, e: vec3<f32>) -> vec3<f32> {
    switch BRDF_MODEL {
        case MODEL_LAYERED: {
            return layered_base_albedo(colour, normal_transmittance(optical_depth, roughness), k, e);
        }
        case MODEL_THESIS: {
            return colour;
        }
        default: {
            return colour;
        }
    }
}

// The rule's two parts on one roughness row (energy::parts_on_row): the lobe's entries k
// and k + LOBE_VEC4S mixed by fx; the single scattering E1 <F> (the film over the lobe's
// microfacet angles, five-point Gauss rule, or the quantile rule where the table holds it)
// and what the top reflects beyond it, x: the
// multiple scattering (1 - E1) g, g = s sum_ij M_ij F(a_i) F(b_j) + (1 - s) <F>_a <F>_b^2
// (energy::Multiple), plus the light that comes straight back through the top,
// q = (1 - E1 <F> - (1 - E1) g) W <F>_back (its three-point rule): a share W of all the
// light the top lets in, as energy::parts_on_row computes it.
struct RowParts {
    single: vec3<f32>,
    beyond: vec3<f32>,
}

fn parts_on_row(layers: Layers, k: u32, fx: f32) -> RowParts {
    var v: array<vec4<f32>, LOBE_VEC4S>;
    for (var i = 0u; i < LOBE_VEC4S; i++) {
        v[i] = mix(lobe_table[k + i], lobe_table[k + LOBE_VEC4S + i], fx);
    }
    // The film at every cosine the rule reads, in one loop: the lobe's nodes, the multiple
    // scattering's (a, then b) and light straight back's. (One call site: the direct film
    // methods' film is long, and Mesa inlines every call; written out, the rule's eighteen
    // reads at X's sixteen nodes and six couplings made lavapipe compile the rgb3 pipeline
    // for over ten minutes.)
    // A material whose film is less dense than the medium above reads the lobe by the
    // quantile rule (energy::LobeRule): the table then holds its nodes after the entries
    // (render::engine::film::lobe_table), read here in the same loop.
    let quantile_base = LOBE_ENTRIES * LOBE_VEC4S;
    let quantiles = arrayLength(&lobe_table) > quantile_base;
    let quantile_entry = quantile_base + (k / LOBE_VEC4S) * QUANTILE_VEC4S;
    let reads = ROW_FILM_READS + select(0u, QUANTILES, quantiles);
    var f: array<vec3<f32>, ROW_FILM_READS>;
    var quantile_mean = vec3<f32>(0.0);
    for (var n = 0u; n < reads; n++) {
        var c: f32;
        if (n >= ROW_FILM_READS) {
            let i = n - ROW_FILM_READS;
            let a = lobe_table[quantile_entry + i / 4u][i % 4u];
            let b = lobe_table[quantile_entry + QUANTILE_VEC4S + i / 4u][i % 4u];
            c = mix(a, b, fx);
        } else {
            var s = LOBE_THROUGH_SLOT + 1u + n - LOBE_NODES - 2u * PAIR_NODES;
            if (n < LOBE_NODES) {
                s = LOBE_NODE_SLOT + 1u + n;
            } else if (n < LOBE_NODES + 2u * PAIR_NODES) {
                s = LOBE_NODE_SLOT + PAIR_SLOT + n - LOBE_NODES;
            }
            c = lobe_slot(&v, s);
        }
        let film = film_clamped(layers, c);
        if (n >= ROW_FILM_READS) {
            quantile_mean += film / f32(QUANTILES);
        } else {
            f[n] = film;
        }
    }
    let e1 = lobe_slot(&v, LOBE_NODE_SLOT);
    var mean = by_rule(&v, &f, LOBE_NODE_SLOT + 1u, 0u, LOBE_NODES);
    if (quantiles) {
        mean = quantile_mean;
    }
    // The multiple scattering (energy::Multiple::reflected).
    var both = vec3<f32>(0.0);
    var first = vec3<f32>(0.0);
    var second = vec3<f32>(0.0);
    for (var n = 0u; n < PAIR_NODES * PAIR_NODES; n++) {
        let m = lobe_slot(&v, LOBE_NODE_SLOT + PAIR_WEIGHTS_SLOT + n);
        let fa = f[LOBE_NODES + n / PAIR_NODES];
        let fb = f[LOBE_NODES + PAIR_NODES + n % PAIR_NODES];
        both += m * fa * fb;
        first += m * fa;
        second += m * fb;
    }
    let twice = lobe_slot(&v, LOBE_NODE_SLOT + SHARE_SLOT);
    let multiple = twice * both + (1.0 - twice) * first * second * second;
    let back = by_rule(&v, &f, LOBE_THROUGH_SLOT + 1u, LOBE_NODES + 2u * PAIR_NODES, THROUGH_NODES);
    // Light straight back: a share of all the light the top lets in (energy::parts_on_row).
    let q = (1.0 - e1 * mean - (1.0 - e1) * multiple) * lobe_slot(&v, LOBE_THROUGH_SLOT) * back;
    // x never more than the light the single scattering leaves (q's reweighting is an
    // estimate).
    let single = e1 * mean;
    return RowParts(single, clamp((1.0 - e1) * multiple + q, vec3<f32>(0.0), vec3<f32>(1.0) - single));
}

// Slot s of a lobe table entry (its vec4s in order).
fn lobe_slot(v: ptr<function, array<vec4<f32>, LOBE_VEC4S>>, s: u32) -> f32 {
    return (*v)[s / 4u][s % 4u];
}

// A rule of n nodes from slot s of a lobe table entry, then all but the last weight (the
// last is 1 minus the others: energy::Rule::slots), over the film read at its nodes, f[r..].
fn by_rule(
    v: ptr<function, array<vec4<f32>, LOBE_VEC4S>>,
    f: ptr<function, array<vec3<f32>, ROW_FILM_READS>>,
    s: u32,
    r: u32,
    n: u32,
) -> vec3<f32> {
    var sum = vec3<f32>(0.0);
    var last = 1.0;
    for (var i = 0u; i + 1u < n; i++) {
        let w = lobe_slot(v, s + n + i);
        sum += w * (*f)[r + i];
        last -= w;
    }
    return sum + last * (*f)[r + n - 1u];
}

// X = 2 int x(mu) mu dmu on rows j and j + 1, the multiple-scatter lobe's normalisation
// (energy::ms_norm_on_row, its rule's eight nodes (mu, 2 w mu) generated), in one loop (one
// call site of parts_on_row, for the reason given there). The LUT and no-film pipelines
// read it baked into the coupling texture (coupling_is_baked); the direct methods pay these
// sixteen evaluations once per pixel (with_ms_norms).
fn ms_norms_from_row(layers: Layers, j: u32) -> array<vec3<f32>, 2> {
    var nodes = array<vec2<f32>, MS_NODES>(MS_NODE_0, MS_NODE_1, MS_NODE_2, MS_NODE_3, MS_NODE_4, MS_NODE_5, MS_NODE_6, MS_NODE_7);
    var norms = array<vec3<f32>, 2>(vec3<f32>(0.0), vec3<f32>(0.0));
    for (var n = 0u; n < 2u * MS_NODES; n++) {
        let node = nodes[n % MS_NODES];
        let row = n / MS_NODES;
        let x = sqrt(node.x) * f32(E1_MU - 1u);
        let i = min(u32(x), E1_MU - 2u);
        norms[row] += node.y * parts_on_row(layers, LOBE_VEC4S * ((j + row) * E1_MU + i), x - f32(i)).beyond;
    }
    return norms;
}

// `layers` with X on the two roughness rows around its roughness filled in, where the
// coupling evaluates the rule (the layered model's direct film methods): X depends on the
// film and the roughness only, so a pixel computes it once for every direction it shades
// (a pixel with two lights and the sky shaded three couplings, each computing both rows').
fn with_ms_norms(layers: Layers) -> Layers {
    var result = layers;
    if (BRDF_MODEL == MODEL_LAYERED && !coupling_is_baked()) {
        let j = lobe_row(layers.roughness);
        let norms = ms_norms_from_row(layers, j);
        result.ms_norm_lower = norms[0];
        result.ms_norm_upper = norms[1];
    }
    return result;
}

// The rule on one roughness row (energy::top_on_row_with) at the entry k mixed by fx, with
// the row's X `norm`: the top reflects E1 <F> + x, and its multiple-scatter lobe
// x(mu_i) x(mu_o) / (pi X) returns the x it takes in every direction.
fn top_on_row(layers: Layers, k: u32, fx: f32, norm: vec3<f32>) -> Top {
    let parts = parts_on_row(layers, k, fx);
    let amplitude = select(vec3<f32>(0.0), parts.beyond / sqrt(PI * norm), norm > vec3<f32>(MS_NORM_MIN));
    return Top(parts.single + parts.beyond, amplitude, 0.0);
}

// The layered coupling from the film table's coupling texture (optics::lut::Lut::
// coupling_f32): the rule on the lobe's roughness rows at the table's cos texels and
// thickness columns, two filtered fetches at the texel coordinates (cos, roughness,
// thickness); where the footprint spreads (Layers::thickness_offset_nm), the mean of the
// table at the two thicknesses, as film_clamped.
fn coupling_table(layers: Layers, cos: f32) -> Top {
    let n_cos = f32(film_info.n_cos);
    // sqrt: the table's cos texels are uniform in sqrt(cos) (optics::lut::coupling_texel_cos).
    let x = sqrt(clamp(cos, 0.0, 1.0)) * (n_cos - 1.0);
    let rows = f32(E1_ROUGHNESS);
    let v = (roughness_coordinate(layers.roughness) + 0.5) / rows;
    let reads = footprint_reads(layers);
    var t = coupling_texels(x, v, footprint_thickness(layers, 0u));
    if (reads == 2u) {
        let second = coupling_texels(x, v, footprint_thickness(layers, 1u));
        t = Top(t.reflected + second.reflected, t.ms + second.ms, t.path_delta + second.path_delta);
    }
    let mean = 1.0 / f32(reads);
    return Top(t.reflected * mean, t.ms * mean, t.path_delta * mean);
}

// The coupling texture's two fetches at the table's cos texel x, roughness coordinate v and
// a thickness: the reflected share and the path delta, and the multiple-scatter amplitude.
fn coupling_texels(x: f32, v: f32, thickness_nm: f32) -> Top {
    let n_cos = f32(film_info.n_cos);
    let w = (lut_column(thickness_nm) + 0.5) / f32(film_info.n_fine + film_info.n_coarse);
    let s = textureSampleLevel(coupling_texture, lut_sampler, vec3<f32>((x + 0.5) / (2.0 * n_cos), v, w), 0.0);
    let ms = textureSampleLevel(coupling_texture, lut_sampler, vec3<f32>((x + 0.5 + n_cos) / (2.0 * n_cos), v, w), 0.0);
    return Top(s.rgb, ms.rgb, s.a);
}

// Whether the coupling comes from the coupling texture: for the LUT film method, and for a
// material without a film (FILM_NONE), whose table holds the plain n0|n2 interface where
// its thickness is zero (column 0 is the film at d = 0, optics::lut::Lut::texel_thickness)
// and at every thickness where n1 = n0, as the LUT pipeline holds any film (in the film
// table's white balance and half floats, linear between cos texels). Evaluating the rule
// instead cost that pipeline X on two rows per pixel and, when this was measured, ten
// Fresnel terms per direction (five on each row; ROW_FILM_READS on each row now) where
// the table costs two fetches (on lavapipe, xenopeltis-unicolor
// without its film 267 ms a frame against 111 ms for the LUT pipeline with it).
fn coupling_is_baked() -> bool {
    return FILM_METHOD == FILM_LUT || FILM_METHOD == FILM_NONE;
}

// The top at cosine `cos` (Model::coupling). The thesis: the film F(cos), no multiple
// scattering; the layered model: the rule on the two roughness rows around the roughness,
// mixed (energy::top), baked with the table for the LUT film method and a material without
// a film (coupling_table, coupling_is_baked), evaluated here for the direct methods (with X
// from `layers`: with_ms_norms).
fn coupling(layers: Layers, cos: f32) -> Top {
    switch BRDF_MODEL {
        case MODEL_LAYERED: {
            if (coupling_is_baked()) {
                return coupling_table(layers, cos);
            }
            let c = lobe_cell(cos, layers.roughness);
            let lower = top_on_row(layers, c.k00, c.fx, layers.ms_norm_lower);
            let upper = top_on_row(layers, c.k01, c.fx, layers.ms_norm_upper);
            return Top(mix(lower.reflected, upper.reflected, c.fy), mix(lower.ms, upper.ms, c.fy), path_delta_in(c));
        }
        case MODEL_THESIS: {
            return Top(film_clamped(layers, cos), vec3<f32>(0.0), 0.0);
        }
        default: {
            return Top(film_clamped(layers, cos), vec3<f32>(0.0), 0.0);
        }
    }
}

fn diffuse_lobe(layers: Layers, cos_i: f32, cos_o: f32, top_i: Top, top_o: Top) -> vec3<f32> {
    switch BRDF_MODEL {
        case MODEL_LAYERED: {
            return layered_diffuse(layers, cos_i, cos_o, top_i, top_o);
        }
        case MODEL_THESIS: {
            return thesis_diffuse(layers, cos_i, cos_o, top_i.reflected, top_o.reflected);
        }
        default: {
            return thesis_diffuse(layers, cos_i, cos_o, top_i.reflected, top_o.reflected);
        }
    }
}

// The ambient term's diffuse part towards a view at cosine cos_o, top_o = coupling there
// (Model::ambient_diffuse): multiplies the sky radiance along the normal.
fn ambient_diffuse(layers: Layers, cos_o: f32, top_o: Top) -> vec3<f32> {
    switch BRDF_MODEL {
        case MODEL_LAYERED: {
            return layered_ambient_diffuse(layers, cos_o, top_o);
        }
        case MODEL_THESIS: {
            return thesis_ambient_diffuse(layers, cos_o, top_o.reflected);
        }
        default: {
            return thesis_ambient_diffuse(layers, cos_o, top_o.reflected);
        }
    }
}

fn skin_brdf(layers: Layers, normal: vec3<f32>, wi_in: vec3<f32>, wo_in: vec3<f32>) -> vec3<f32> {
    let n = safe_normalize(normal, vec3<f32>(0.0, 0.0, 1.0));
    let cos_o = max(dot(n, safe_normalize(wo_in, vec3<f32>(0.0))), COS_MIN);
    return skin_brdf_seen(layers, normal, wi_in, wo_in, coupling(layers, cos_o), true);
}

// The BRDF with the model's top towards the viewer, top_o = coupling(max(n.wo, COS_MIN)),
// computed by the caller: a pixel lit by several lights (and the ambient term) looks it up
// once instead of once per light. `with_diffuse` = false gives the specular lobe alone.
fn skin_brdf_seen(
    layers: Layers,
    normal: vec3<f32>,
    wi_in: vec3<f32>,
    wo_in: vec3<f32>,
    top_o: Top,
    with_diffuse: bool,
) -> vec3<f32> {
    let n = safe_normalize(normal, vec3<f32>(0.0, 0.0, 1.0));
    let wi = safe_normalize(wi_in, vec3<f32>(0.0));
    let wo = safe_normalize(wo_in, vec3<f32>(0.0));
    let raw_i = dot(n, wi);
    let raw_o = dot(n, wo);
    if (!(raw_i > 0.0 && raw_o > 0.0)) {
        return vec3<f32>(0.0);
    }
    let cos_i = max(raw_i, COS_MIN);
    let cos_o = max(raw_o, COS_MIN);
    let h = safe_normalize(wi + wo, vec3<f32>(0.0));
    if (dot(h, h) == 0.0) {
        return vec3<f32>(0.0);
    }
    let alpha = ggx_alpha(layers.roughness);
    let cos_h = clamp(dot(n, h), 0.0, 1.0);
    // sin^2 from the cross product: cos^2 (a^2 - 1) + 1 cancels near the peak in f32.
    let nxh = cross(n, h);
    let spec = specular_scale(cos_h, dot(nxh, nxh), cos_i, cos_o, alpha * alpha);
    let f_h = film_clamped(layers, abs(dot(wo, h)));
    // The top at the light's cosine: for the diffuse lobe, and the multiple scattering
    // (which only the layered model has: the thesis' specular stage reads no more film).
    var result = f_h * spec;
    if (with_diffuse || BRDF_MODEL == MODEL_LAYERED) {
        let top_i = coupling(layers, cos_i);
        result += top_i.ms * top_o.ms;
        if (with_diffuse) {
            result += diffuse_lobe(layers, cos_i, cos_o, top_i, top_o);
        }
    }
    return result;
}
