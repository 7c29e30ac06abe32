//! Geometry that reads as imbricate scales: each scale's free edge stands above the scale it
//! overlaps (a rounded lip and an overlap step, not a groove down to the skin), ventral plates
//! overlap front to back the same way, and keels fade towards the scale's attached base.
//! Measured on the scale field's own channels along the body.

mod common;

use snakeskin::ops::Image;
use snakeskin::ops::scales::channel;

/// Fine enough that the next scale's own rise over one pixel (its dome near its tip) stays
/// well under the step.
const SIZE: usize = 1024;

fn field(text: &str) -> Image {
    common::full_scale_field(text, SIZE)
}

fn get(f: &Image, x: usize, y: usize, c: usize) -> f32 {
    f.data[((y % SIZE) * SIZE + x) * f.channels + c]
}

/// Height drops where one scale (or plate) hands over to the next going tailwards along
/// column `x`: (height on the last pixel of the front one, height on the first pixel of the
/// next).
fn handovers(f: &Image, x: usize) -> Vec<(f32, f32)> {
    (0..SIZE)
        .filter(|&y| get(f, x, y, channel::CENTRE_V) != get(f, x, y + 1, channel::CENTRE_V))
        .filter(|&y| get(f, x, y, channel::CREVICE) < 1.0 && get(f, x, y + 1, channel::CREVICE) < 1.0)
        .map(|y| (get(f, x, y, channel::HEIGHT), get(f, x, y + 1, channel::HEIGHT)))
        .collect()
}

fn steps(text: &str, x: usize) -> Vec<f32> {
    handovers(&field(text), x).iter().map(|(before, after)| before - after).collect()
}

#[test]
fn a_free_edge_stands_a_step_above_the_scale_it_overlaps() {
    let preset = |imbrication: f64| format!("[scales]\nshape = \"leaf\"\njitter = 0\nimbrication = {imbrication}\n");
    // Along the spine (the vertebral row's centre) and along the belly's midline.
    for (x, part) in [(SIZE / 2, "dorsal scales"), (0, "ventral plates")] {
        let lipped = steps(&preset(0.6), x);
        assert!(lipped.len() >= 8, "{part}: only {} edges crossed", lipped.len());
        // LIP_STEP × imbrication = 0.048 of the height range; the rounded lip keeps it.
        for s in &lipped {
            assert!(*s > 0.03, "{part}: a free edge drops only {s} onto the next scale: {lipped:?}");
        }
        // Negative control: without imbrication there is no overlap step.
        let flat = steps(&preset(0.0), x);
        assert!(flat.len() >= 8, "{part}: the control crossed only {} edges", flat.len());
        assert!(flat.iter().all(|s| *s < 0.01), "{part}: steps without imbrication: {flat:?}");
    }
}

#[test]
fn keels_fade_towards_the_base_of_the_scale() {
    let f = field("[scales]\nshape = \"leaf\"\njitter = 0\nkeeled = true\nkeel_height = 1\n");
    let (mut base, mut tip) = (Vec::new(), Vec::new());
    for y in 0..SIZE {
        let p = |c| get(&f, SIZE / 2, y, c);
        if p(channel::CREVICE) > 0.0 {
            continue;
        }
        // The first fifth of a scale lies hidden under the scale in front.
        if p(channel::ALONG) < 0.3 {
            base.push(p(channel::KEEL));
        } else if p(channel::ALONG) > 0.7 {
            tip.push(p(channel::KEEL));
        }
    }
    let mean = |v: &[f32]| v.iter().sum::<f32>() / v.len().max(1) as f32;
    assert!(!base.is_empty() && !tip.is_empty());
    assert!(mean(&base) < 0.5 * mean(&tip), "keel at the base {} vs the free end {}", mean(&base), mean(&tip));
}
