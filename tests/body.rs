//! The body layout counts what the preset says: ventral plates along the belly, subcaudals
//! on the tail, dorsal marks along the spine and bands on the tail, each counted on the
//! generated maps (the height map's plate edges, the colour map's marks) within ±1 of the
//! preset; u still wraps round the body.
//!
//! The counters know nothing of the generator: plates are the sharp drops of the height
//! profile at each plate's free edge, marks are runs of rows where most pixels near the
//! spine are nearer the mark's colour than any other colour the preset uses. Each is also
//! run on a changed preset (a negative control: a counter that echoed the preset's number,
//! or found a fixed one, would fail there).

mod common;

use common::{assert_rows_seamless, transpose};
use snakeskin::graph::evaluate;
use snakeskin::maps::{BuildOptions, Layout, MapKind, body_plan, build_graph};
use snakeskin::ops::Image;
use snakeskin::preset::schema::Srgb8;
use snakeskin::preset::{Preset, load};

/// Atlas width: a plate of the longest-bodied species here (Liasis, 287 ventrals over
/// 0.78 of 12 widths) is about 8 pixels long.
const WIDTH: usize = 256;

fn preset(name: &str, overrides: &[(&str, &str)]) -> Preset {
    let overrides: Vec<(String, String)> = overrides.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect();
    load(name, &overrides, None).unwrap_or_else(|e| panic!("{name}: {e}")).preset
}

fn body_map(preset: &Preset, map: MapKind) -> Image {
    let graph = build_graph(preset, BuildOptions { layout: Layout::Body, ..BuildOptions::default() });
    let height = Layout::Body.height(preset, WIDTH);
    evaluate(&graph, &[map], WIDTH, height, &|_, _| {}).maps.remove(&map).unwrap()
}

/// The rows of an image `height` tall between v0 and v1.
fn rows_of(height: usize, v0: f32, v1: f32) -> std::ops::Range<usize> {
    (v0 * height as f32).ceil() as usize..(v1 * height as f32).floor() as usize
}

/// Plate edges in rows `rows` of the height map's column at u = 0.06 (on the ventral band,
/// off the subcaudals' midline seam): drops of more than 0.12 of the height range over two
/// rows (a free edge falls by about 0.2, over one row or, when it straddles a pixel
/// boundary, two), drops within three rows counted once.
fn plate_edges(preset: &Preset, height: &Image, rows: std::ops::Range<usize>) -> usize {
    let x = (0.06 * height.width as f32) as usize;
    // In the scale field's heights, whatever the map's stretch (`maps::height_range`): a
    // plate's free edge falls about 0.12 onto the next plate; half of that is an edge.
    let (low, high) = snakeskin::maps::height_range(preset);
    let h = |y: usize| low + height.data[y * height.width + x] * (high - low);
    let mut count = 0;
    let mut last = None;
    for y in rows.start..rows.end - 2 {
        if h(y + 2) - h(y) < -0.06 {
            if last.is_none_or(|l| y > l + 3) {
                count += 1;
            }
            last = Some(y);
        }
    }
    count
}

fn linear(c: Srgb8) -> [f32; 3] {
    c.to_linear()
}

fn distance(a: &[f32], b: [f32; 3]) -> f32 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f32>().sqrt()
}

/// Marks of `mark`'s colour crossing the spine (±2 % of the circumference) in `rows`
/// (`mark_runs`, `whole_marks`).
fn marks_along_spine(colour: &Image, rows: std::ops::Range<usize>, mark: [f32; 3], others: &[[f32; 3]]) -> usize {
    let w = colour.width as f32;
    let spine = (0.48 * w) as usize..(0.52 * w) as usize;
    whole_marks(mark_runs(colour, (rows, spine), mark, others)).len()
}

/// `runs` less the slivers where a narrow tip of a mark crosses the columns: a run counts
/// when it is at least a quarter of the median run's length (and three rows).
fn whole_marks(runs: Vec<(usize, usize)>) -> Vec<(usize, usize)> {
    let mut lengths: Vec<usize> = runs.iter().map(|(a, b)| b - a).collect();
    lengths.sort_unstable();
    let median = lengths.get(lengths.len() / 2).copied().unwrap_or(0);
    runs.into_iter().filter(|(a, b)| b - a >= 3 && 4 * (b - a) >= median).collect()
}

/// Every colour the preset's pattern layers and ground use, except `mark`.
fn other_colours(p: &Preset, mark: Srgb8) -> Vec<[f32; 3]> {
    let mut all = vec![p.color.base];
    for l in &p.pattern {
        all.extend(l.color);
        all.push(l.outline_color);
        all.extend(l.center_color);
        all.extend(l.border_color);
        all.extend(l.colors.iter().copied());
    }
    all.into_iter().filter(|c| *c != mark).map(linear).collect()
}

fn assert_within_one(what: &str, found: usize, expected: u32) {
    assert!(
        (found as i64 - expected as i64).abs() <= 1,
        "{what}: counted {found} on the maps, the preset says {expected}"
    );
}

fn check_plates(name: &str, overrides: &[(&str, &str)]) {
    let p = preset(name, overrides);
    let plan = body_plan(&p);
    let height = body_map(&p, MapKind::Height);
    let h = height.height;
    let ventrals = plate_edges(&p, &height, rows_of(h, plan.head_end, plan.vent));
    let subcaudals = plate_edges(&p, &height, rows_of(h, plan.vent, 1.0));
    assert_within_one(&format!("{name} {overrides:?} ventrals"), ventrals, plan.ventrals);
    assert_within_one(&format!("{name} {overrides:?} subcaudals"), subcaudals, plan.subcaudals);
}

#[test]
fn ventral_and_subcaudal_plates_are_counted_as_the_preset_says() {
    for name in ["natrix-natrix", "liasis-mackloti", "bitis-arietans", "bungarus-fasciatus"] {
        check_plates(name, &[]);
    }
    // Negative control: other counts are found as such.
    check_plates("natrix-natrix", &[("body.ventrals", "120"), ("body.subcaudals", "30")]);
}

fn check_marks(name: &str, overrides: &[(&str, &str)]) {
    let p = preset(name, overrides);
    let plan = body_plan(&p);
    let layer = p.pattern.iter().find(|l| l.count.is_some()).expect("a counted layer");
    let mark = layer.colors.first().copied().unwrap_or(layer.color());
    let colour = body_map(&p, MapKind::Color);
    let trunk = rows_of(colour.height, plan.neck_end, plan.vent);
    let found = marks_along_spine(&colour, trunk, linear(mark), &other_colours(&p, mark));
    assert_within_one(&format!("{name} {overrides:?} dorsal marks"), found, layer.count.unwrap());
}

#[test]
fn dorsal_marks_along_the_spine_are_counted_as_the_preset_says() {
    // Diamonds, saddles, a ring sequence and chevrons.
    for name in ["crotalus-atrox", "lampropeltis-triangulum", "bungarus-fasciatus", "bitis-arietans"] {
        check_marks(name, &[]);
    }
    check_marks("crotalus-atrox", &[("pattern.0.count", "15")]);
}

fn check_tail_bands(name: &str, overrides: &[(&str, &str)]) {
    // The speckle set aside: its dots (the boa's grey speckle) split a band's rows on the
    // spine's few columns into runs the count took for bands (10 for 5); the bands' count
    // does not depend on it.
    let overrides = [overrides, &[("color.speckle", "0")]].concat();
    let p = preset(name, &overrides);
    let plan = body_plan(&p);
    let colour = body_map(&p, MapKind::Color);
    let band = p.body.tail_band_color;
    let mut others = other_colours(&p, band);
    others.extend(p.body.tail_color.map(linear));
    let found = marks_along_spine(&colour, rows_of(colour.height, plan.vent, 1.0), linear(band), &others);
    assert_within_one(&format!("{name} {overrides:?} tail bands"), found, p.body.tail_bands);
}

#[test]
fn tail_bands_are_counted_as_the_preset_says() {
    for name in ["crotalus-atrox", "bitis-arietans", "boa-constrictor"] {
        check_tail_bands(name, &[]);
    }
    check_tail_bands("crotalus-atrox", &[("body.tail_bands", "8")]);
}

#[test]
fn a_body_atlas_still_wraps_round_the_body() {
    for name in ["pantherophis-guttatus", "vipera-berus"] {
        let p = preset(name, &[]);
        let graph = build_graph(&p, BuildOptions { layout: Layout::Body, ..BuildOptions::default() });
        let height = Layout::Body.height(&p, 128);
        assert_eq!(height, (128.0 * p.body.length).round() as usize);
        let eval = evaluate(&graph, &MapKind::ALL, 128, height, &|_, _| {});
        for (map, img) in &eval.maps {
            assert_rows_seamless(&transpose(img), &format!("{name} body {map} columns"));
        }
    }
}

/// A preset of one blotch series of `shape` on a body without plates, `count` marks widened
/// `widen` times toward the vent (the tail's light bands of its own end the series there),
/// written to `dir`.
fn widened_series(dir: &std::path::Path, shape: &str, size: f32, count: u32, widen: f32, offset: f32) -> Preset {
    let file = dir.join(format!("{shape}-{widen}.toml"));
    let text = format!(
        "seed = 3\n[belly]\nwidth = 0\n[color]\nvariation = 0\n\
         [body]\ntail_bands = 3\ntail_band_color = \"#e0e0e0\"\n[[pattern]]\nkind = \"blotches\"\n\
         shape = \"{shape}\"\ncolor = \"#101010\"\nsize = {size}\ncount = {count}\nwiden_to_tail = {widen}\n\
         offset = {offset}\nedge_distortion = 0\n"
    );
    std::fs::write(&file, text).unwrap();
    preset(file.to_str().unwrap(), &[])
}

#[test]
fn marks_widened_past_the_circumference_still_wrap_round_the_body() {
    // Chevrons and hourglasses half the circumference wide, widened six times toward the
    // tail: the last marks span about three circumferences, and every copy of them that
    // reaches the texture must be drawn (one copy either side left a straight seam at u = 0).
    let dir = tempfile::tempdir().unwrap();
    for shape in ["chevron", "hourglass"] {
        let p = widened_series(dir.path(), shape, 0.5, 8, 6.0, 0.2);
        let colour = body_map(&p, MapKind::Color);
        assert_rows_seamless(&transpose(&colour), &format!("{shape} widened 6 times, columns"));
    }
}

/// The most dark pixels (the marks' colour, #101010, 0.005 linear) across each mark of a
/// series, in rows order: a mark is a run of rows with a dark pixel on the spine. (The
/// ground's grooves are darker than 0.1 but not than 0.02.)
fn mark_widths(colour: &Image) -> Vec<usize> {
    let w = colour.width;
    let dark = |y: usize, x: usize| colour.data[(y * w + x) * 3..(y * w + x) * 3 + 3].iter().all(|c| *c < 0.02);
    let mut widths = Vec::new();
    let mut current: Option<usize> = None;
    for y in 0..colour.height {
        let across = (0..w).filter(|&x| dark(y, x)).count();
        match (dark(y, w / 2), current) {
            (true, Some(widest)) => current = Some(widest.max(across)),
            (true, None) => current = Some(across),
            (false, Some(widest)) => {
                widths.push(widest);
                current = None;
            }
            (false, None) => {}
        }
    }
    widths.extend(current);
    widths
}

#[test]
fn widen_to_tail_is_the_last_marks_width_over_the_firsts() {
    // docs/presets.md: "the half-width of its last mark ... over the first's". Five saddles
    // of 0.05 a side (0.1 of the circumference across); the pattern layers' own jitter
    // changes a mark's size by up to 9 %, so the ratio is within 20 %. (Widened at the
    // marks' midpoints, the ratio was 3.7 for 6.)
    let dir = tempfile::tempdir().unwrap();
    for widen in [1.0, 6.0] {
        let p = widened_series(dir.path(), "saddle", 0.05, 5, widen, 0.0);
        let widths = mark_widths(&body_map(&p, MapKind::Color));
        assert_eq!(widths.len(), 5, "widen {widen}: marks {widths:?}");
        let first = widths[0] as f32 / WIDTH as f32;
        let ratio = widths[4] as f32 / widths[0] as f32;
        assert!((first - 0.1).abs() < 0.02, "widen {widen}: the first mark is {first} of the circumference, not 0.1");
        assert!((ratio / widen - 1.0).abs() < 0.2, "widen {widen}: last over first {ratio} ({widths:?})");
    }
}

#[test]
fn the_head_differs_from_the_trunk() {
    // Head shields: the head's height map has far fewer plate edges per row than the
    // trunk's small dorsal scales; head marks: a black cap colours the head only.
    let p = preset("leiopython-albertisii", &[]);
    let plan = body_plan(&p);
    let colour = body_map(&p, MapKind::Color);
    let cap = p.body.head_mark.iter().find(|m| m.kind == snakeskin::preset::schema::HeadMarkKind::Cap).unwrap();
    let cap_colour = linear(cap.color);
    let w = colour.width;
    let near_cap = |y: usize| {
        let px = &colour.data[(y * w + w / 2) * 3..(y * w + w / 2) * 3 + 3];
        distance(px, cap_colour) < 0.05
    };
    let h = colour.height as f32;
    assert!(near_cap((0.5 * plan.head_end * h) as usize), "the cap is on the head");
    assert!(!near_cap((0.5 * h) as usize), "and not on the trunk");
}

#[test]
fn a_body_atlas_written_in_strips_equals_the_whole_atlas() {
    // `generate` evaluates a body atlas a strip at a time (margins cropped) and encodes rows
    // as they come; every sample must equal the atlas evaluated at once and quantised.
    for name in ["pantherophis-guttatus", "crotalus-atrox", "micrurus-diastema"] {
        let dir = tempfile::tempdir().unwrap();
        let out = common::snakeskin(&[
            "generate",
            name,
            "-o",
            dir.path().to_str().unwrap(),
            "--size",
            "128",
            "--layout",
            "body",
            "--maps",
            "all,ao",
        ]);
        assert!(out.status.success(), "{}", common::stderr(&out));
        let p = preset(name, &[]);
        let graph = build_graph(&p, BuildOptions { layout: Layout::Body, ..BuildOptions::default() });
        let height = Layout::Body.height(&p, 128);
        assert!(height > 2 * snakeskin::generate::STRIP_WIDTHS * 128, "several strips");
        // Ambient occlusion too: it reads a scale width up and down the body.
        let whole = evaluate(&graph, &MapKind::EVERY, 128, height, &|_, _| {});
        assert_eq!(whole.maps.len(), 6);
        for (map, image) in &whole.maps {
            let expected = snakeskin::export::quantize(*map, image);
            let file = dir.path().join(snakeskin::export::map_file_name(name, *map));
            let decoded = image::open(&file).unwrap();
            let samples: Vec<u8> = match expected.color {
                image::ExtendedColorType::L16 => {
                    // Big-endian, as `quantize` and PNG store them.
                    decoded.into_luma16().into_raw().iter().flat_map(|v| v.to_be_bytes()).collect()
                }
                image::ExtendedColorType::Rgb8 => decoded.into_rgb8().into_raw(),
                _ => decoded.into_luma8().into_raw(),
            };
            let row_bytes = samples.len() / height;
            let rows: Vec<usize> = (0..height)
                .filter(|y| {
                    samples[y * row_bytes..(y + 1) * row_bytes] != expected.samples[y * row_bytes..(y + 1) * row_bytes]
                })
                .collect();
            assert!(rows.is_empty(), "{name} {map}: rows {rows:?} differ between strips and the whole atlas");
        }
    }
}

/// Pixels nearer `mark` than any of `others`, in each row of `rows`, over `columns`.
fn mark_pixels_per_row(
    colour: &Image,
    (rows, columns): (std::ops::Range<usize>, std::ops::Range<usize>),
    mark: [f32; 3],
    others: &[[f32; 3]],
) -> Vec<usize> {
    let w = colour.width;
    rows.map(|y| {
        columns
            .clone()
            .filter(|x| {
                let px = &colour.data[(y * w + x) * 3..(y * w + x) * 3 + 3];
                let own = distance(px, mark);
                others.iter().all(|o| own < distance(px, *o))
            })
            .count()
    })
    .collect()
}

/// Pixels nearer `mark` than any of `others` in the rows of `rows`, all columns.
fn mark_pixels(colour: &Image, rows: std::ops::Range<usize>, mark: [f32; 3], others: &[[f32; 3]]) -> usize {
    mark_pixels_per_row(colour, (rows, 0..colour.width), mark, others).iter().sum()
}

#[test]
fn a_series_can_widen_toward_the_tail() {
    // The last fifth of the trunk against the first: saddles drawn 3 × as wide at the vent
    // cover far more; the same series without widening (the control) about the same.
    let ratio = |widen: &str| {
        let p = preset("boa-constrictor", &[("pattern.0.widen_to_tail", widen), ("body.tail_color", "\"#9a8a72\"")]);
        let plan = body_plan(&p);
        let colour = body_map(&p, MapKind::Color);
        let layer = &p.pattern[0];
        let others = other_colours(&p, layer.color());
        let h = colour.height;
        let trunk = plan.vent - plan.neck_end;
        let first = rows_of(h, plan.neck_end, plan.neck_end + 0.2 * trunk);
        let last = rows_of(h, plan.vent - 0.2 * trunk, plan.vent);
        let (a, b) = (
            mark_pixels(&colour, first, linear(layer.color()), &others),
            mark_pixels(&colour, last, linear(layer.color()), &others),
        );
        b as f64 / a.max(1) as f64
    };
    let (plain, widened) = (ratio("1"), ratio("3"));
    eprintln!("last fifth over first fifth of the trunk: {plain:.2} plain, {widened:.2} widened 3 ×");
    assert!((0.7..1.4).contains(&plain), "without widening the ends match: {plain:.2}");
    assert!(widened > 1.8, "widened 3 ×, the last fifth carries {widened:.2} × the first's mark");
}

#[test]
fn the_manifest_records_the_layout_counts_and_regions() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path().to_str().unwrap();
    let out = common::snakeskin(&["generate", "crotalus-atrox", "-o", d, "--size", "64", "--layout", "body"]);
    assert!(out.status.success(), "{}", common::stderr(&out));
    let text = std::fs::read_to_string(dir.path().join("crotalus-atrox.material.json")).unwrap();
    let m: serde_json::Value = serde_json::from_str(&text).unwrap();
    let p = preset("crotalus-atrox", &[]);
    assert_eq!(m["layout"], "body");
    assert_eq!(m["width"], 64);
    assert_eq!(m["height"], (64.0 * p.body.length).round() as u64);
    assert_eq!(m["counts"]["ventrals"], p.body.ventrals);
    assert_eq!(m["counts"]["subcaudals"], p.body.subcaudals);
    assert_eq!(m["counts"]["dorsal_marks"], 25);
    assert_eq!(m["counts"]["tail_bands"], p.body.tail_bands);
    // The regions tile v from the snout (0) to the tail tip (1), in order.
    let range = |name: &str| [m["regions"][name][0].as_f64().unwrap(), m["regions"][name][1].as_f64().unwrap()];
    let (head, neck, trunk, tail) = (range("head"), range("neck"), range("trunk"), range("tail"));
    assert_eq!(head[0], 0.0);
    assert_eq!(tail[1], 1.0);
    for (a, b) in [(head, neck), (neck, trunk), (trunk, tail)] {
        assert!((a[1] - b[0]).abs() < 1e-6 && a[0] < a[1], "{a:?} then {b:?}");
    }
    let vent = range("vent");
    assert!(vent[0] < trunk[1] && trunk[1] < vent[1]);
    // Where the maps lie: the snout at the first row, the belly at the edges, v not wrapping.
    let space = m["texture_space"].as_str().unwrap();
    for says in ["the belly's midline at u = 0 and 1", "from the snout (v = 0, the first row)", "wraps in u, not in v"]
    {
        assert!(space.contains(says), "{space}");
    }
    // The tile's manifest says so and has neither.
    let out = common::snakeskin(&["generate", "crotalus-atrox", "-o", d, "--size", "64"]);
    assert!(out.status.success(), "{}", common::stderr(&out));
    let text = std::fs::read_to_string(dir.path().join("crotalus-atrox.material.json")).unwrap();
    let m: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(m["layout"], "tile");
    assert!(m.get("counts").is_none() && m.get("regions").is_none());
    assert!(m["texture_space"].as_str().unwrap().contains("the tile repeats in u and in v"), "{m}");
}

#[test]
fn a_body_atlas_too_long_or_a_bad_body_key_is_refused_with_its_key() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path().join("out");
    let d = d.to_str().unwrap();
    // 16384 wide × 12 = 196608 rows: over the rows a map may have.
    let out = common::snakeskin(&["generate", "crotalus-atrox", "-o", d, "--size", "16384", "--layout", "body"]);
    assert_eq!(out.status.code(), Some(2), "{}", common::stderr(&out));
    assert!(common::stderr(&out).contains("body.length"), "{}", common::stderr(&out));
    // The widest that fits, named: its atlas is at most 65535 rows, one pixel wider's more.
    let fits: usize = common::stderr(&out)
        .split("give --size ")
        .nth(1)
        .and_then(|r| r.split(' ').next()?.parse().ok())
        .unwrap_or_else(|| panic!("no width named: {}", common::stderr(&out)));
    let preset = snakeskin::preset::load("crotalus-atrox", &[], None).unwrap().preset;
    let layout = snakeskin::maps::Layout::Body;
    assert!(layout.height(&preset, fits) <= 65535 && layout.height(&preset, fits + 1) > 65535, "{fits}");
    for (key, value) in [("body.ventrals", "10"), ("body.tail_fraction", "0.9"), ("pattern.0.widen_to_tail", "9")] {
        let set = format!("{key}={value}");
        let out = common::snakeskin(&["generate", "crotalus-atrox", "-o", d, "--layout", "body", "--set", &set]);
        assert_eq!(out.status.code(), Some(2), "{set}: {}", common::stderr(&out));
        assert!(common::stderr(&out).contains(key), "{set}: {}", common::stderr(&out));
    }
    assert!(!std::path::Path::new(d).exists(), "nothing may be written");
}

#[test]
fn every_generator_draws_a_strip_of_the_body_as_the_whole_atlas_does() {
    // A body atlas is evaluated strip by strip (`generate`), and each node's strip is its
    // rows of the whole atlas only if every generator draws any rows exactly as it draws
    // them in the whole: a filter's reach covers only what it reads (`Op::row_reach`).
    // tiny-skia's shapes did not (chevrons of `bitis-arietans` a sixteenth off at pixels
    // deep inside a strip; `ops::shapes::Canvas`), hidden in the maps while a blur's margin
    // ran a few rows wider than its kernel. Each generator alone, strips of 40 rows every
    // 41 rows from the snout to the tail tip (seen failing with the old drawing, and with
    // the edges not cut at fixed rows: `Canvas`), every built-in, and ring spots and one
    // blotch as long as the trunk (it crosses every cut row and the texture's side).
    use snakeskin::graph::{GraphBuilder, Op, evaluate_rows};
    use snakeskin::ops::image::Frame;
    let texts = [
        "seed = 3\n[[pattern]]\nkind = \"spots\"\ncolor = \"#202020\"\nshape = \"ring\"\namount = 5\nsize = 0.09\n",
        "seed = 4\n[[pattern]]\nkind = \"blotches\"\ncolor = \"#202020\"\nshape = \"saddle\"\namount = 1\nlength = 1\nsize = 0.45\n",
    ];
    let presets = snakeskin::preset::library::all()
        .iter()
        .map(|(name, _)| (name.to_string(), preset(name, &[])))
        .chain([("patterned".to_string(), preset(common::PATTERNED, &[]))])
        .chain(texts.iter().map(|t| (t.to_string(), common::preset_from(t))));
    let width = 64;
    let mut shapes = 0;
    for (name, p) in presets {
        let graph = build_graph(&p, BuildOptions { layout: Layout::Body, ..BuildOptions::default() });
        let height = Layout::Body.height(&p, width);
        // The scale field is planar and left out: it computes every pixel alone (`ops::scales`).
        for node in graph.nodes().iter().filter(|n| n.op.arity() == (0..=0) && !matches!(n.op, Op::Scales(_))) {
            shapes += matches!(node.op, Op::Blotches(_) | Op::Spots(_)) as usize;
            let mut builder = GraphBuilder::new();
            builder.set_open_v();
            let id = builder.add(node.name.clone(), node.op.clone(), &[]);
            builder.set_output(MapKind::Height, id);
            let alone = builder.finish();
            let whole = evaluate(&alone, &[MapKind::Height], width, height, &|_, _| {}).maps.remove(&MapKind::Height);
            let whole = whole.unwrap();
            let row = whole.channels * width;
            for (row0, rows) in (0..height - 40).step_by(41).map(|r| (r, 40)) {
                let frame = Frame { width, height: rows, full_height: height, row0, wraps_v: false };
                let mut strip = None;
                evaluate_rows(&alone, &[MapKind::Height], frame, &|_, _| {}, &mut |_, image| strip = Some(image));
                let strip = strip.unwrap();
                let differ: Vec<usize> = (0..rows)
                    .filter(|y| {
                        strip.data[y * row..(y + 1) * row] != whole.data[(row0 + y) * row..(row0 + y + 1) * row]
                    })
                    .map(|y| row0 + y)
                    .collect();
                assert!(differ.is_empty(), "{name} {}: rows {differ:?} of a strip from {row0} differ", node.name);
            }
        }
    }
    assert!(shapes > 20, "the shapes were checked: {shapes}");
}

#[test]
fn a_tile_written_in_strips_equals_the_whole_tile() {
    // A tile over its buffer budget is evaluated in strips whose margins run round the seam
    // (the first strip's margin above is the tile's last rows). Forced here at 256² with a
    // tiny budget; every sample must equal the tile evaluated at once. Crotalus' outlined,
    // blurred, snapped diamonds have the widest margins of the built-in species; Acanthophis'
    // speckles are placed by texture row in the per-scale colour, which is no generator.
    for name in ["crotalus-atrox", "bitis-gabonica", "xenopeltis-unicolor", "acanthophis-antarcticus"] {
        let dir = tempfile::tempdir().unwrap();
        let out = common::snakeskin_env(
            &["generate", name, "-o", dir.path().to_str().unwrap(), "--size", "256", "--maps", "all,ao", "--stats"],
            &[("SNAKESKIN_TILE_BUDGET_MIB", "1")],
        );
        assert!(out.status.success(), "{}", common::stderr(&out));
        assert!(common::stderr(&out).contains("evaluated in "), "the tile went in strips: {}", common::stderr(&out));
        let p = preset(name, &[]);
        let graph = build_graph(&p, BuildOptions::default());
        let whole = evaluate(&graph, &MapKind::EVERY, 256, 256, &|_, _| {});
        for (map, image) in &whole.maps {
            let expected = snakeskin::export::quantize(*map, image);
            let decoded = image::open(dir.path().join(snakeskin::export::map_file_name(name, *map))).unwrap();
            let samples: Vec<u8> = match expected.color {
                image::ExtendedColorType::L16 => {
                    // Big-endian, as `quantize` and PNG store them.
                    decoded.into_luma16().into_raw().iter().flat_map(|v| v.to_be_bytes()).collect()
                }
                image::ExtendedColorType::Rgb8 => decoded.into_rgb8().into_raw(),
                _ => decoded.into_luma8().into_raw(),
            };
            let row_bytes = samples.len() / 256;
            let rows: Vec<usize> = (0..256)
                .filter(|y| {
                    samples[y * row_bytes..(y + 1) * row_bytes] != expected.samples[y * row_bytes..(y + 1) * row_bytes]
                })
                .collect();
            assert!(rows.is_empty(), "{name} {map}: rows {rows:?} differ between strips and the whole tile");
        }
    }
}

/// A `count` that the layer's kind does not read (the file's blotches turned to spots by
/// `--set`, which passes the blotches' keys over) does not count, clip or go into the
/// manifest: it cut the spots to the counted series' stretch of the body (from the end of
/// the neck, not the head). Negative control: the same spots without the count are the
/// same map, and the blotches with it are not.
#[test]
fn a_count_the_layer_does_not_read_changes_nothing() {
    let spots = preset("crotalus-atrox", &[("pattern.0.kind", "spots")]);
    assert_eq!(spots.pattern[0].count, Some(25), "the file's count is kept, passed over");
    let mut uncounted = spots.clone();
    uncounted.pattern[0].count = None;
    let map = |p: &Preset| body_map(p, MapKind::Color).data.clone();
    assert!(map(&spots) == map(&uncounted), "a passed-over count changed the spots");
    let blotches = preset("crotalus-atrox", &[]);
    let mut blotches_uncounted = blotches.clone();
    blotches_uncounted.pattern[0].count = None;
    assert!(map(&blotches) != map(&blotches_uncounted), "the blotches' count counts");

    let dir = tempfile::tempdir().unwrap();
    let out = common::snakeskin(&[
        "generate",
        "crotalus-atrox",
        "--set",
        "pattern.0.kind=spots",
        "--layout",
        "body",
        "--size",
        "32",
        "--maps",
        "color",
        "-o",
        dir.path().to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", common::stderr(&out));
    let manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("crotalus-atrox.material.json")).unwrap()).unwrap();
    assert!(manifest["counts"].get("dorsal_marks").is_none(), "{}", manifest["counts"]);
}

/// Pixels of `mark`'s colour (nearer it than every other colour of the preset) in each of
/// `rows`, on the back (the middle half of the width: the belly band is centred on u = 0).
fn back_pixels_per_row(
    colour: &Image,
    rows: std::ops::Range<usize>,
    mark: [f32; 3],
    others: &[[f32; 3]],
) -> Vec<usize> {
    let w = colour.width;
    mark_pixels_per_row(colour, (rows, w / 4..3 * w / 4), mark, others)
}

#[test]
fn irregular_patches_close_behind_the_head() {
    // An irregular layer starts where the head ends (the head has its own marks). The
    // minority's patches must end there with their own edges, not be cut flat across the
    // neck: none within a third of a noise cell behind the head, where the region's edge
    // alone left as much of them as two to six cells further on. The minority: the layer's
    // patches, or the ground's holes in a layer covering most of the body.
    // python-regius' blotches in blue, which no pixel of the irregular layer is nearer to.
    let cases: [(&str, &[(&str, &str)]); 4] = [
        ("morelia-spilota", &[]),
        ("morelia-spilota", &[("pattern.0.amount", "0.3")]),
        ("morelia-spilota", &[("pattern.0.amount", "0.9")]),
        ("python-regius", &[("pattern.1.color", "#2040f0")]),
    ];
    for (name, overrides) in cases {
        let p = preset(name, overrides);
        let layer = p.pattern.iter().find(|l| l.kind == snakeskin::preset::schema::PatternKind::Irregular).unwrap();
        let minority = if layer.amount > 0.5 { p.color.base } else { layer.color.unwrap() };
        let colour = body_map(&p, MapKind::Color);
        let plan = body_plan(&p);
        let row = |v: f32| (v * colour.height as f32).ceil() as usize;
        let cell_v = layer.size as f32 / plan.length;
        let count = |rows| back_pixels_per_row(&colour, rows, linear(minority), &other_colours(&p, minority));
        let first = count(row(plan.head_end)..row(plan.head_end + cell_v / 3.0));
        let later = count(row(plan.head_end + 2.0 * cell_v)..row(plan.head_end + 6.0 * cell_v));
        let later_mean = later.iter().sum::<usize>() as f32 / later.len() as f32;
        let what = format!("{name}, amount {}", layer.amount);
        assert!(later_mean > 0.03 * (WIDTH / 2) as f32, "{what}: the control, {later_mean} px a row further on");
        assert!(first.iter().all(|n| *n == 0), "{what}: {first:?} px in the first rows behind the head");
    }
}

/// Rows (within `rows`) whose pixels at `columns` are mostly nearer `mark` than any of
/// `others`, as runs (start, end) of the image's rows; gaps of two rows or less join runs.
fn mark_runs(
    colour: &Image,
    (rows, columns): (std::ops::Range<usize>, std::ops::Range<usize>),
    mark: [f32; 3],
    others: &[[f32; 3]],
) -> Vec<(usize, usize)> {
    let span = columns.len();
    let per_row = mark_pixels_per_row(colour, (rows.clone(), columns), mark, others);
    runs_of(rows, &per_row, |near| 2 * near > span)
}

/// Runs (start, end) of the rows of `rows` whose count in `per_row` is `kept`; gaps of two
/// rows or less join runs.
fn runs_of(rows: std::ops::Range<usize>, per_row: &[usize], kept: impl Fn(usize) -> bool) -> Vec<(usize, usize)> {
    let mut runs: Vec<(usize, usize)> = Vec::new();
    for (y, near) in rows.zip(per_row) {
        if !kept(*near) {
            continue;
        }
        match runs.last_mut() {
            Some(last) if y - last.1 <= 2 => last.1 = y + 1,
            _ => runs.push((y, y + 1)),
        }
    }
    runs
}

#[test]
fn the_milk_snakes_side_blotches_alternate_with_its_saddles() {
    // 'large brown saddles ... alternate with 1 or 2 rows of smaller dark blotches running
    // down each side' (the preset's source): every side blotch lies between two saddles,
    // not beside one. An uncounted side series (the tile's spacing) drifted against the
    // counted saddles, half its blotches beside a saddle (the control).
    let check = |overrides: &[(&str, &str)]| {
        let p = preset("lampropeltis-triangulum", overrides);
        let plan = body_plan(&p);
        let colour = body_map(&p, MapKind::Color);
        let (saddle, side) = (&p.pattern[0], &p.pattern[1]);
        let trunk = rows_of(colour.height, plan.neck_end, plan.vent);
        let w = colour.width as f32;
        let column = |u: f32| (u * w) as usize - 1..(u * w) as usize + 2;
        let centres =
            |runs: Vec<(usize, usize)>| whole_marks(runs).iter().map(|(a, b)| 0.5 * (a + b) as f32).collect::<Vec<_>>();
        let saddles = centres(mark_runs(
            &colour,
            (trunk.clone(), column(0.5)),
            linear(saddle.color()),
            &other_colours(&p, saddle.color()),
        ));
        let sides = centres(mark_runs(
            &colour,
            (trunk, column(0.5 - side.offset as f32)),
            linear(side.color()),
            &other_colours(&p, side.color()),
        ));
        // Each side blotch's place between the saddles either side of it, 0 and 1 at them.
        let places: Vec<f32> = sides
            .iter()
            .filter_map(|&c| {
                let next = saddles.iter().position(|&s| s > c)?;
                let before = *saddles.get(next.checked_sub(1)?)?;
                Some((c - before) / (saddles[next] - before))
            })
            .collect();
        let beside = places.iter().filter(|t| !(0.25..=0.75).contains(*t)).count();
        (places.len(), beside)
    };
    let (between, beside) = check(&[]);
    assert!(between >= 30 && beside == 0, "{beside} of {between} side blotches beside a saddle");
    let (between, beside) = check(&[("pattern.1.count", "33")]);
    assert!(beside * 4 > between, "the control: {beside} of {between} beside a saddle");
}

#[test]
fn the_banded_kraits_first_ring_is_the_broadest_and_starts_at_the_head() {
    // Günther (in the preset): 'the first is the broadest, and produced into a triangular
    // process, the point of which rests on the vertical shield': the head's black runs on
    // into the first ring, with no yellow across the neck. Along the spine: black from the
    // end of the head through the neck, and that black longer than any ring behind it; and
    // round the back and flanks (u 0.12-0.88, off the belly), no yellow from behind the V's
    // arms (which reach 1.1 head lengths) to the first ring's middle: where the collar met
    // the ring end to end, scales astride the join showed yellow crescents (an independent
    // review; seeds 1, 2, 3, 7, up to 118 pixels a row at 512 wide, none on the spine).
    let check = |overrides: &[(&str, &str)]| {
        let p = preset("bungarus-fasciatus", overrides);
        let plan = body_plan(&p);
        let colour = body_map(&p, MapKind::Color);
        let black = p.pattern[0].colors[0];
        let h = colour.height;
        let w = colour.width;
        let runs = mark_runs(
            &colour,
            (rows_of(h, plan.head_end, plan.vent), (0.48 * w as f32) as usize..(0.52 * w as f32) as usize),
            linear(black),
            &other_colours(&p, black),
        );
        let first = runs.first().copied().unwrap_or((0, 0));
        let from_head =
            first.0 <= rows_of(h, plan.head_end, 1.0).start + 1 && first.1 > (plan.neck_end * h as f32) as usize;
        let broadest = runs[1..runs.len() - 1].iter().all(|(a, b)| (first.1 - first.0) as f32 > 1.3 * (b - a) as f32);
        let yellow = linear(p.color.base);
        let neck_end = (plan.neck_end * h as f32) as usize;
        let neck = (1.15 * plan.head_end * h as f32) as usize..(neck_end + first.1.max(neck_end)) / 2;
        let back = (0.12 * w as f32) as usize..(0.88 * w as f32) as usize;
        let yellow_on_back = mark_pixels_per_row(&colour, (neck, back), yellow, &[linear(black)]).iter().sum::<usize>();
        (from_head, broadest, yellow_on_back)
    };
    for seed in ["1", "2", "3", "7"] {
        assert_eq!(check(&[("seed", seed)]), (true, true, 0), "seed {seed}");
    }
    // The controls: without the black over the neck, yellow there; the collar ending at the
    // ring's start (size 1.5, the first version), yellow crescents at the join (54-124
    // pixels for these seeds; none from 1.6 up).
    assert!(!check(&[("body.head_mark.1.size", "0.3")]).0);
    for seed in ["1", "3"] {
        assert!(check(&[("seed", seed), ("body.head_mark.1.size", "1.5")]).2 > 0, "seed {seed}: the control");
    }
}

#[test]
fn a_rattlesnakes_tail_rings_go_round_the_tail() {
    // 'Tail encircled by broad black and white rings' (crotalus-atrox's source): the bands
    // cross the subcaudals (`body.tail_band_over_belly`), as many on the belly's midline
    // (off its seam at u = 0, where the pairs of subcaudals meet) as on the spine. Without
    // the key (the control) none reach the belly.
    let check = |overrides: &[(&str, &str)]| {
        let p = preset("crotalus-atrox", overrides);
        let plan = body_plan(&p);
        let colour = body_map(&p, MapKind::Color);
        let band = p.body.tail_band_color;
        let mut others = other_colours(&p, band);
        others.extend(p.body.tail_color.map(linear));
        others.push(linear(p.belly.color));
        let w = colour.width as f32;
        let tail = rows_of(colour.height, plan.vent, 1.0);
        let runs =
            |u: f32| mark_runs(&colour, (tail.clone(), (u * w) as usize..(u * w) as usize + 3), linear(band), &others);
        (runs(0.5).len(), runs(0.03).len())
    };
    let (spine, belly) = check(&[]);
    assert!(spine == 5 && belly == 5, "{spine} bands on the spine, {belly} on the belly");
    let (spine, belly) = check(&[("body.tail_band_over_belly", "false")]);
    assert!(spine == 5 && belly == 0, "the control: {spine} on the spine, {belly} on the belly");
}

#[test]
fn the_grass_snakes_collar_is_two_crescents_bordered_behind_with_black() {
    // anabis (in the preset): 'a white, yellow, or orange collar on the nape, … bordered
    // behind by two black blotches'; roadkill.at: 'two yellow to orange crescent-shaped
    // spots'. Over the head's end to a neck's length behind the neck: no yellow on the spine
    // (two spots, not a band), and on each side (u 0.3 and 0.7) a yellow run with a black
    // run straight behind it at least half as long (the blotches, not a pattern spot).
    let black = preset("natrix-natrix", &[]).body.head_mark[0].border_color.expect("the preset's black border");
    let check = |overrides: &[(&str, &str)]| {
        let p = preset("natrix-natrix", overrides);
        let plan = body_plan(&p);
        let colour = body_map(&p, MapKind::Color);
        let (h, w) = (colour.height, colour.width as f32);
        let collar = p.body.head_mark[0].color;
        let mut others = other_colours(&p, collar);
        others.push(linear(black));
        let nape = rows_of(h, plan.head_end, plan.neck_end + (plan.neck_end - plan.head_end));
        let on_spine = mark_pixels_per_row(
            &colour,
            (nape.clone(), (0.49 * w) as usize..(0.51 * w) as usize),
            linear(collar),
            &others,
        );
        let bordered = [0.3, 0.7].map(|u| {
            let columns = (u * w) as usize..(u * w) as usize + 3;
            let yellow = mark_runs(&colour, (nape.clone(), columns.clone()), linear(collar), &others);
            let dark =
                mark_runs(&colour, (nape.clone(), columns), linear(black), &[linear(collar), linear(p.color.base)]);
            let &[(start, end)] = yellow.as_slice() else { return false };
            dark.iter().any(|&(a, b)| a.abs_diff(end) <= 2 && 2 * (b - a) >= end - start)
        });
        (on_spine.iter().sum::<usize>(), bordered)
    };
    assert_eq!(check(&[]), (0, [true, true]));
    // The controls: a collar round the neck is yellow on the spine; a border of the ground's
    // colour leaves no black behind the crescents.
    assert!(check(&[("body.head_mark.0.kind", "\"collar\"")]).0 > 0);
    let ground = format!("\"{}\"", preset("natrix-natrix", &[]).color.base);
    assert_eq!(check(&[("body.head_mark.0.border_color", &ground)]).1, [false, false]);
}

#[test]
fn the_boas_brick_red_is_the_tails() {
    // 'a ruddy brown ground color, becoming a rich brick red on the tail' (boa-constrictor's
    // source): the back and flanks at 0.7 of the length, ahead of the vent (0.89), keep the
    // trunk's colour, nearer the front's (0.3) than the tail's. The shift from halfway down
    // the trunk (the default 0.5: the control) reddened the trunk's rear half (an audit).
    let check = |overrides: &[(&str, &str)]| {
        let p = preset("boa-constrictor", overrides);
        let colour = body_map(&p, MapKind::Color);
        let (h, w) = (colour.height, colour.width);
        let median_at = |v: f32| {
            let rows = rows_of(h, v - 0.01, v + 0.01);
            let mut channels = [Vec::new(), Vec::new(), Vec::new()];
            for y in rows {
                for x in (0.15 * w as f32) as usize..(0.85 * w as f32) as usize {
                    for (k, c) in channels.iter_mut().enumerate() {
                        c.push(colour.data[(y * w + x) * 3 + k]);
                    }
                }
            }
            channels.map(|mut c| {
                c.sort_by(f32::total_cmp);
                c[c.len() / 2]
            })
        };
        let (front, rear) = (median_at(0.3), median_at(0.7));
        let tail = linear(p.body.tail_color.unwrap());
        distance(&rear[..], front) < distance(&rear[..], tail)
    };
    assert!(check(&[]));
    assert!(!check(&[("body.tail_shift_start", "0.5")]), "the control");
}

#[test]
fn the_green_pythons_white_spots_are_a_few() {
    // 'a few scattered white spots on sides' (morelia-viridis' source): along each flank's
    // series (0.24 of the circumference off the spine, ±0.04) from the neck to the vent, the
    // layer's count (10, a reading of 'a few'), ±1, each spot at most two scales long ('one
    // scale each', the preset: one, or two neighbours where its centre falls between them);
    // at 30 (the control) more than 20; at the tile's length share, streaks. Uncounted, the
    // tile's 3 a circumference ran on down the body, 27 and 28 a side (an audit); counted at
    // the tile's length share, the spots were streaks of 3-5 scales (a review).
    let check = |overrides: &[(&str, &str)]| {
        let p = preset("morelia-viridis", overrides);
        let plan = body_plan(&p);
        let colour = body_map(&p, MapKind::Color);
        let white = p.pattern[0].color.unwrap();
        let w = colour.width as f32;
        let trunk = rows_of(colour.height, plan.neck_end, plan.vent);
        let scale_rows = colour.height as f32 / snakeskin::maps::scale_field(&p, Layout::Body).lattice().rows_v as f32;
        [0.26, 0.74].map(|u| {
            let columns = ((u - 0.04) * w) as usize..((u + 0.04) * w) as usize;
            // Against the green ground only: the vertebral stripe's cream (#e8e8c8) is near the
            // spots' white, and the scales' tone jitter split a spot's rows between the two.
            let per_row =
                mark_pixels_per_row(&colour, (trunk.clone(), columns), linear(white), &[linear(p.color.base)]);
            // Runs of rows with any of a spot's pixels.
            let runs = runs_of(trunk.clone(), &per_row, |n| n > 0);
            let longest = runs.iter().map(|(a, b)| (b - a) as f32).fold(0.0, f32::max);
            (runs.len(), longest <= 2.0 * scale_rows)
        })
    };
    let count = preset("morelia-viridis", &[]).pattern[0].count.unwrap();
    for (side, (found, one_scale)) in check(&[]).into_iter().enumerate() {
        assert_within_one(&format!("side {side}"), found, count);
        assert!(one_scale, "side {side}: a spot longer than two scales");
    }
    // At 30 a side (a spot's length share 0.16: three or four scales long), more than 20 a
    // side are found; and at our 10 a side, that length makes streaks.
    let thirty = [("pattern.0.count", "30"), ("pattern.0.length", "0.16")];
    assert!(check(&thirty).iter().all(|(n, _)| *n > 20), "the control: 30 a side");
    assert!(check(&[("pattern.0.length", "0.16")]).iter().all(|(_, one)| !one), "the control: streaks");
}

#[test]
fn a_border_the_new_kind_does_not_read_draws_nothing() {
    // `--set body.head_mark.0.kind=lips` on the grass snake passes the file's border over (a
    // kind the border does not belong to), and it was still drawn, in black under the lip
    // stripe's anti-aliased edge (a review: 1,666 pixels changed). The map equals the
    // preset's without the border line; the control: crescents, which draw it, differ.
    let text = snakeskin::preset::library::get("natrix-natrix").unwrap();
    let border_line = text.lines().find(|l| l.starts_with("border_color")).expect("natrix's border");
    let without = text.replace(&format!("{border_line}\n"), "");
    let map = |text: &str, kind: &str| {
        let source = snakeskin::preset::PresetSource { name: "t".into(), display: "t.toml".into(), text: text.into() };
        let set = [("body.head_mark.0.kind".to_string(), format!("\"{kind}\""))];
        body_map(&snakeskin::preset::parse(&source, &set).unwrap().preset, MapKind::Color).data.clone()
    };
    assert!(map(text, "lips") == map(&without, "lips"), "a border drawn under the lips");
    assert!(map(text, "crescents") != map(&without, "crescents"), "the control");
}

/// A species' body atlas colour map seen as its head: one head mark's colour against every
/// other colour its head can show (the ground, the pattern's and the other marks' colours).
struct HeadView {
    colour: Image,
    plan: snakeskin::ops::body::BodyPlan,
    mark: [f32; 3],
    others: Vec<[f32; 3]>,
}

impl HeadView {
    /// `name` with `overrides`, looking for the colour of its head mark `index`.
    fn of(name: &str, overrides: &[(&str, &str)], index: usize) -> HeadView {
        let p = preset(name, overrides);
        let mark = p.body.head_mark[index].color;
        let mut others = other_colours(&p, mark);
        others.extend(p.body.head_mark.iter().map(|m| m.color).filter(|c| *c != mark).map(linear));
        HeadView { colour: body_map(&p, MapKind::Color), plan: body_plan(&p), mark: linear(mark), others }
    }

    /// The pixel of the head-local point (x in shield half-widths across, s in head lengths
    /// from the snout; `ops::body::BodyPlan::head_units`).
    fn pixel(&self, (x, s): (f32, f32)) -> (usize, usize) {
        let u = 0.5 + x * snakeskin::ops::body::HEAD_TOP_HALF_U;
        let v = s * self.plan.head_end;
        ((u * self.colour.width as f32) as usize, (v * self.colour.height as f32) as usize)
    }

    /// Whether the pixel at (x, y) is nearer the mark's colour than any other.
    fn is_mark(&self, (x, y): (usize, usize)) -> bool {
        let k = (y * self.colour.width + x) * 3;
        let own = distance(&self.colour.data[k..k + 3], self.mark);
        self.others.iter().all(|o| own < distance(&self.colour.data[k..k + 3], *o))
    }
}

/// The index of `name`'s first head mark of `kind`.
fn head_mark_index(name: &str, kind: snakeskin::preset::schema::HeadMarkKind) -> usize {
    let marks = preset(name, &[]).body.head_mark;
    marks.iter().position(|m| m.kind == kind).unwrap_or_else(|| panic!("{name} draws no {kind:?}"))
}

#[test]
fn a_band_between_the_eyes_crosses_the_head() {
    // pantherophis-guttatus: 'Additional stripes run along the sides of the head, through the
    // eyes and meet on top of the head in front of the eyes'; lampropeltis-triangulum: 'dark
    // transverse band between the eyes'; bitis-arietans: 'two well-marked dark bands: one on
    // the crown and the other between the eyes' (each preset's sources). Every column from
    // the spine to the eyes (0.6 shield half-widths out, each side) holds the band's colour
    // somewhere between the front and the back of the eyes (0.3 to 0.6 head lengths from the
    // snout, the supraoculars over the eyes spanning 0.4 to 0.6): a band across, unbroken. The control: the band's mark turned into a spot behind
    // each eye, and the top of the head in front of the eyes is open (the corn snake's
    // spearhead of the same colour, the milk snake's white V, there only near the spine).
    for name in ["pantherophis-guttatus", "lampropeltis-triangulum", "bitis-arietans"] {
        let index = head_mark_index(name, snakeskin::preset::schema::HeadMarkKind::EyeBand);
        let across = |overrides: &[(&str, &str)]| {
            let head = HeadView::of(name, overrides, index);
            let ((left, first), (right, last)) = (head.pixel((-0.6, 0.3)), head.pixel((0.6, 0.6)));
            (left..=right).filter(|&x| !(first..=last).any(|y| head.is_mark((x, y)))).count()
        };
        assert_eq!(across(&[]), 0, "{name}: columns without the band");
        let key = format!("body.head_mark.{index}.kind");
        assert!(across(&[(&key, "\"postocular_spot\"")]) > 10, "{name}: the control");
    }
}

#[test]
fn the_puff_adders_second_band_crosses_the_crown() {
    // 'The head has two well-marked dark bands: one on the crown and the other between the
    // eyes' (bitis-arietans' source). Every column from the spine to the eyes' line (0.6
    // shield half-widths out, each side) holds the crown band's colour somewhere behind the
    // eyes (0.7 to 0.9 head lengths from the snout), and on the spine the two bands are two:
    // ground between them (0.62 to 0.72). The control: the crown band turned into a spot
    // behind each eye, and the crown is open (the puff adder's crown carried no band before, an
    // audit found).
    let name = "bitis-arietans";
    let index = head_mark_index(name, snakeskin::preset::schema::HeadMarkKind::CrownBand);
    let check = |overrides: &[(&str, &str)]| {
        let head = HeadView::of(name, overrides, index);
        let ((left, first), (right, last)) = (head.pixel((-0.6, 0.7)), head.pixel((0.6, 0.9)));
        let open = (left..=right).filter(|&x| !(first..=last).any(|y| head.is_mark((x, y)))).count();
        let ((spine, gap_first), (_, gap_last)) = (head.pixel((0.0, 0.62)), head.pixel((0.0, 0.72)));
        let parted = (gap_first..=gap_last).any(|y| !head.is_mark((spine, y)));
        (open, parted)
    };
    assert_eq!(check(&[]), (0, true), "columns without the band; ground between the bands");
    let key = format!("body.head_mark.{index}.kind");
    assert!(check(&[(&key, "\"postocular_spot\"")]).0 > 10, "the control");
}

#[test]
fn the_corn_snakes_spearpoint_is_two_stripes_from_the_first_blotch() {
    // 'The first blotch on the back of the neck splits to form two stripes that run on top of
    // the head and meet to form the characteristic spearpoint' (pantherophis-guttatus'
    // source). Every row from just behind the point (0.35 head lengths) to the neck's end,
    // where the first blotch begins, holds the mark's colour on each side of the spine (0.05
    // to 0.8 shield half-widths out): the stripes run unbroken into the blotch, which has the
    // same colour. On the spine 1.2 head lengths from the snout, between the stripes, the
    // ground shows: two stripes, not a wedge. The control: the solid spearhead
    // the preset drew before, which ended 0.02 of the length short of the first blotch (an
    // audit) and is solid on the spine.
    let name = "pantherophis-guttatus";
    let index = head_mark_index(name, snakeskin::preset::schema::HeadMarkKind::SpearStripes);
    let check = |overrides: &[(&str, &str)]| {
        let head = HeadView::of(name, overrides, index);
        let neck_end = head.plan.neck_end / head.plan.head_end;
        let ((_, first), (_, last)) = (head.pixel((0.0, 0.35)), head.pixel((0.0, neck_end)));
        let sides = [(-0.8, -0.05), (0.05, 0.8)].map(|(a, b)| head.pixel((a, 0.0)).0..=head.pixel((b, 0.0)).0);
        let broken =
            (first..=last).filter(|&y| !sides.iter().all(|side| side.clone().any(|x| head.is_mark((x, y))))).count();
        let between = head.pixel((0.0, 1.2));
        (broken, !head.is_mark(between))
    };
    assert_eq!(check(&[]), (0, true), "rows where a stripe breaks; the ground between the stripes");
    let key = format!("body.head_mark.{index}.kind");
    let (broken, open) = check(&[(&key, "\"spearhead\""), (&format!("body.head_mark.{index}.size"), "1")]);
    assert!(broken > 5 && !open, "the control: {broken} rows, open {open}");
}

#[test]
fn the_boas_line_runs_from_the_snout_through_the_eye_to_the_neck() {
    // 'ses yeux ... sont eux aussi parcourus d'une ligne latérale présente du museau à
    // l'embase du cou' (boa-constrictor's source: a line through the eyes from the snout to
    // the neck). In every row from the snout's first tenth to the back of the head, each
    // side holds the line's colour away from the spine (0.25 to 1.6 shield half-widths out,
    // clear of the thin spearhead of the same colour on the midline). The control: the
    // preocular stripe turned into a spot behind the eye, and the rows in front of the eye
    // lack it (the line began behind the eye, an audit found).
    let index = head_mark_index("boa-constrictor", snakeskin::preset::schema::HeadMarkKind::PreocularStripe);
    let rows_without = |overrides: &[(&str, &str)]| {
        let head = HeadView::of("boa-constrictor", overrides, index);
        let ((_, first), (_, last)) = (head.pixel((0.0, 0.1)), head.pixel((0.0, 0.95)));
        let sides = [(-1.6, -0.25), (0.25, 1.6)].map(|(a, b)| head.pixel((a, 0.0)).0..=head.pixel((b, 0.0)).0);
        (first..=last).filter(|&y| !sides.iter().all(|side| side.clone().any(|x| head.is_mark((x, y))))).count()
    };
    assert_eq!(rows_without(&[]), 0, "rows without the line");
    let key = format!("body.head_mark.{index}.kind");
    assert!(rows_without(&[(&key, "\"postocular_spot\"")]) > 5, "the control");
}

/// The median linear colour of the belly's midline (u within 0.03 of 0, where the plates
/// lie) over the rows within 0.01 of v.
fn belly_median_at(colour: &Image, v: f32) -> [f32; 3] {
    let (h, w) = (colour.height, colour.width);
    let reach = (0.03 * w as f32) as usize;
    let mut channels = [Vec::new(), Vec::new(), Vec::new()];
    for y in rows_of(h, v - 0.01, v + 0.01) {
        for x in (0..reach).chain(w - reach..w) {
            for (k, c) in channels.iter_mut().enumerate() {
                c.push(colour.data[(y * w + x) * 3 + k]);
            }
        }
    }
    channels.map(|mut c| {
        c.sort_by(f32::total_cmp);
        c[c.len() / 2]
    })
}

#[test]
fn the_belly_changes_colour_along_the_body_where_the_sources_say() {
    // 'Anterior third of the venter is yellow, the rest of the venter is greyish white'
    // (liasis-mackloti's source): a sixth of the way along the ventral plates the belly is
    // nearer the yellow than the greyish white, at three fifths the other way round. With the
    // yellow's end moved to the head (the control), the sixth is greyish white.
    let front = |overrides: &[(&str, &str)]| {
        let p = preset("liasis-mackloti", overrides);
        let plan = body_plan(&p);
        let colour = body_map(&p, MapKind::Color);
        let (yellow, grey) = (linear(p.body.belly_front_color.unwrap()), linear(p.belly.color));
        let at = |share: f32| belly_median_at(&colour, plan.head_end + share * (plan.vent - plan.head_end));
        let nearer_yellow = |c: [f32; 3]| distance(&c, yellow) < distance(&c, grey);
        (nearer_yellow(at(1.0 / 6.0)), nearer_yellow(at(0.6)))
    };
    assert_eq!(front(&[]), (true, false));
    assert_eq!(front(&[("body.belly_front_end", "0")]), (false, false), "the control");
    // The fade stays on the ventral plates: with the end at the vent the tail's underside
    // just behind it is the rest of the belly's colour (as far down the tail), and with the end
    // at the head the chin is the whole front colour (as a sixth of the way along at the
    // default). Centred on the end, the fade ran half onto the tail and left the chin half
    // yellow (a review; under the tail 0.46 of the way between the two colours, seen).
    let p = preset("liasis-mackloti", &[]);
    let (plan, colour) = (body_plan(&p), body_map(&p, MapKind::Color));
    let (yellow, grey) = (linear(p.body.belly_front_color.unwrap()), linear(p.belly.color));
    let apart = distance(&yellow, grey);
    let front_yellow = belly_median_at(&colour, plan.head_end + (plan.vent - plan.head_end) / 6.0);
    let at_end = |end: &str, v: f32| {
        belly_median_at(&body_map(&preset("liasis-mackloti", &[("body.belly_front_end", end)]), MapKind::Color), v)
    };
    let tail = |end: &str| {
        let p = preset("liasis-mackloti", &[("body.belly_front_end", end)]);
        let colour = body_map(&p, MapKind::Color);
        distance(&belly_median_at(&colour, plan.vent + 0.005), belly_median_at(&colour, plan.vent + 0.1)) / apart
    };
    assert!(tail("1") < 0.15, "under the tail at end 1: {} of the way", tail("1"));
    let chin = distance(&at_end("0", plan.head_end - 0.01), front_yellow) / apart;
    assert!(chin < 0.15, "the chin at end 0: {chin} of the way");

    // 'the scales under the tail, past the cloaca ... are black' (pseudechis-porphyriacus'
    // source): halfway down the tail the belly is black, just ahead of the vent red. Over the
    // whole tail no pixel is red, the band's soft edges included: tinting the black over the
    // band after the red left a thin red line along each edge (a fifth of the red at most).
    // The control: a red under the tail.
    let tail = |overrides: &[(&str, &str)]| {
        let p = preset("pseudechis-porphyriacus", overrides);
        let plan = body_plan(&p);
        let colour = body_map(&p, MapKind::Color);
        let (black, red) = (linear(p.body.subcaudal_color.unwrap()), linear(p.belly.color));
        let nearer_black = |c: [f32; 3]| distance(&c, black) < distance(&c, red);
        let under = nearer_black(belly_median_at(&colour, plan.vent + 0.5 * (1.0 - plan.vent)));
        let ahead = nearer_black(belly_median_at(&colour, plan.vent - 0.02));
        let redness = rows_of(colour.height, plan.vent + 0.01, 1.0)
            .flat_map(|y| (0..colour.width).map(move |x| y * colour.width + x))
            .map(|i| colour.data[i * 3] - colour.data[i * 3 + 1])
            .fold(0.0f32, f32::max);
        (under, ahead, redness < 0.02)
    };
    assert_eq!(tail(&[]), (true, false, true));
    let red = format!("\"{}\"", preset("pseudechis-porphyriacus", &[]).belly.color);
    assert_eq!(tail(&[("body.subcaudal_color", &red)]), (false, false, false), "the control");
}
