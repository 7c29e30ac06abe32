//! Belly marks (`belly.pattern`): each kind marks the ventral plates and nothing else, in
//! the place its name says, judged by the scale field (which pixels are plates, where each
//! plate is).

mod common;

use snakeskin::maps::{Layout, scale_field};
use snakeskin::ops::Image;
use snakeskin::ops::scales::channel;
use snakeskin::preset::Preset;

const SIZE: usize = 384;

fn preset(text: &str) -> Preset {
    common::preset_from(text)
}

fn colour(text: &str) -> Image {
    common::colour_map(text, SIZE)
}

fn text(pattern: &str) -> String {
    format!(
        "seed = 4\n[scales]\nrows = 41\njitter = 0\n[color]\nbase = \"#808080\"\n[belly]\nwidth = 0.3\n\
         color = \"#e0e0e0\"\npattern = \"{pattern}\"\npattern_color = \"#000000\"\npattern_amount = 0.5\n"
    )
}

/// Pixels (x, y) whose colour the belly pattern changed, and the plate field.
fn marked(pattern: &str) -> (Vec<(usize, usize)>, Image) {
    let (plain, marks) = (colour(&text("none")), colour(&text(pattern)));
    let mut f = scale_field(&preset(&text(pattern)), Layout::Tile);
    f.outputs = (0..channel::COUNT).collect();
    let field = f.render(SIZE, SIZE);
    let changed = (0..SIZE * SIZE)
        .filter(|i| (0..3).any(|c| plain.data[i * 3 + c] != marks.data[i * 3 + c]))
        .map(|i| (i % SIZE, i / SIZE))
        .collect();
    (changed, field)
}

/// Half the plate band's width in pixels, from the field (pixels of row 0 that are plates).
fn band_half_px(field: &Image) -> usize {
    (0..SIZE / 2).take_while(|x| field.data[(SIZE / 2 * SIZE + x) * field.channels + channel::ROW] == 0.0).count()
}

fn u_distance_px(x: usize) -> usize {
    x.min(SIZE - x)
}

#[test]
fn every_belly_mark_stays_on_the_plates() {
    for pattern in ["checkered", "spots", "half_moons", "median_stripe"] {
        let (changed, field) = marked(pattern);
        let half = band_half_px(&field);
        assert!(changed.len() > 200, "{pattern}: only {} pixels marked", changed.len());
        for (x, y) in &changed {
            assert!(u_distance_px(*x) <= half, "{pattern}: mark at x {x} (y {y}) off the plate band of ±{half} px");
        }
    }
}

#[test]
fn the_median_stripe_is_centred_and_as_wide_as_asked() {
    let (changed, field) = marked("median_stripe");
    let half = band_half_px(&field) as f64;
    let widest = changed.iter().map(|(x, _)| u_distance_px(*x)).max().unwrap() as f64;
    // pattern_amount 0.5: the stripe reaches half way to the band's edge.
    assert!((widest / half - 0.5).abs() < 0.06, "stripe half-width {widest} px of a ±{half} px band");
}

#[test]
fn spots_and_half_moons_mark_about_the_share_of_plates_asked() {
    for pattern in ["spots", "half_moons"] {
        let (changed, _) = marked(pattern);
        let rows_v = scale_field(&preset(&text(pattern)), Layout::Tile).lattice().rows_v as usize;
        // The plate of a pixel: the same phase as the scale field's plates.
        let plate = |y: usize| {
            (((y as f32 + 0.5) / SIZE as f32 * rows_v as f32 - snakeskin::ops::scales::ROW_PHASE).floor() as i64)
                .rem_euclid(rows_v as i64)
        };
        let plates: std::collections::BTreeSet<i64> = changed.iter().map(|(_, y)| plate(*y)).collect();
        let share = plates.len() as f64 / rows_v as f64;
        assert!((0.25..=0.75).contains(&share), "{pattern}: {} of {rows_v} plates marked", plates.len());
    }
}

#[test]
fn half_moons_rest_on_the_posterior_edge() {
    let (changed, _) = marked("half_moons");
    let rows_v = scale_field(&preset(&text("half_moons")), Layout::Tile).lattice().rows_v as f32;
    for (_, y) in changed {
        let along = ((y as f32 + 0.5) / SIZE as f32 * rows_v - snakeskin::ops::scales::ROW_PHASE).rem_euclid(1.0);
        assert!(along > 0.45, "a half-moon pixel at {along:.2} of its plate, not at the posterior edge");
    }
}

#[test]
fn a_checkered_plate_carries_its_square_on_one_side_only_across_the_seam() {
    let (changed, _) = marked("checkered");
    let rows_v = scale_field(&preset(&text("checkered")), Layout::Tile).lattice().rows_v as usize;
    let plate = |y: usize| {
        (((y as f32 + 0.5) / SIZE as f32 * rows_v as f32 - snakeskin::ops::scales::ROW_PHASE).floor() as i64)
            .rem_euclid(rows_v as i64)
    };
    let mut sides: std::collections::BTreeMap<i64, std::collections::BTreeSet<bool>> = Default::default();
    for (x, y) in changed {
        sides.entry(plate(y)).or_default().insert(x < SIZE / 2);
    }
    // Including the plate the texture's v seam cuts in two (its rows at the top and bottom).
    for (p, s) in &sides {
        assert_eq!(s.len(), 1, "plate {p} is marked on both sides");
    }
    assert!(sides.len() >= rows_v * 3 / 4, "only {} of {rows_v} plates marked", sides.len());
}
