//! 8-bit sRGB encoding (IEC 61966-2-1) by table: the codes of the formula, bit for bit, for
//! a fraction of its cost.
//!
//! The formula takes a `powf` per sample, 12.6 million of them for a 2K colour map: about
//! 35 ms of the 2K set's CPU time here (3–4 %, `perf` on `natrix-natrix`). The code it gives
//! never decreases as the linear value grows, so each code k starts at one float, the
//! smallest that encodes to k (found by bisection over the floats' bit patterns, which
//! order non-negative floats as their values), and a value's code is the number of starts
//! at or below it. A coarse index (4,096 buckets over [0, 1]) gives the code at the
//! bucket's lower edge; no bucket spans more than one code, so one comparison with the next
//! code's start finishes it, without a branch. 7.0 → 2.9 ns a sample (one core, 12.6
//! million samples in random order, release build). Checked against the
//! formula at every f32 in [0, 1] by the test below (1,065,353,217 values, 2.5 s a pass in the
//! test build on two cores).

use std::sync::OnceLock;

/// The sRGB transfer's constants (IEC 61966-2-1), here for the shaders' prelude too
/// (`render::engine::shaders`; the map viewer's decode in `skin.wgsl`): encoded 12.92 c up
/// to linear 0.0031308, 1.055 c^(1/2.4) − 0.055 above; decoded e / 12.92 up to 0.04045,
/// ((e + 0.055) / 1.055)^2.4 above.
pub const SRGB_LINEAR_KNEE: f64 = 0.003_130_8;
pub const SRGB_ENCODED_KNEE: f64 = 0.040_45;
pub const SRGB_SLOPE: f64 = 12.92;
pub const SRGB_SCALE: f64 = 1.055;
pub const SRGB_OFFSET: f64 = 0.055;
pub const SRGB_GAMMA: f64 = 2.4;

/// The sRGB transfer function and its inverse (the constants above), both clamping to
/// [0, 1], written once for each float width: each caller keeps the precision its bytes were
/// made with (the f64 formula rounds 219 f32 inputs to another 8-bit code and decodes 214 of
/// the 256 codes to another f32).
macro_rules! transfer {
    ($float:ty, $encode:ident, $decode:ident) => {
        /// Linear light to its sRGB encoding, both in [0, 1].
        pub fn $encode(linear: $float) -> $float {
            let c = linear.clamp(0.0, 1.0);
            if c <= SRGB_LINEAR_KNEE as $float {
                c * SRGB_SLOPE as $float
            } else {
                SRGB_SCALE as $float * c.powf(1.0 / SRGB_GAMMA as $float) - SRGB_OFFSET as $float
            }
        }

        /// An sRGB encoding to linear light, both in [0, 1].
        pub fn $decode(encoded: $float) -> $float {
            let e = encoded.clamp(0.0, 1.0);
            if e <= SRGB_ENCODED_KNEE as $float {
                e / SRGB_SLOPE as $float
            } else {
                ((e + SRGB_OFFSET as $float) / SRGB_SCALE as $float).powf(SRGB_GAMMA as $float)
            }
        }
    };
}
transfer!(f32, encode_f32, decode_f32);
transfer!(f64, encode, decode);

/// The formula rounded to 8 bits: the reference the table is built from.
pub fn linear_to_srgb8_formula(linear: f32) -> u8 {
    super::unit_to_u8(encode_f32(linear))
}

/// Buckets of the coarse index over [0, 1]: a power of two, so `c · BUCKETS` is exact and a
/// bucket's lower edge is never above the value. At the steepest part of the curve (the
/// linear segment, 12.92 · 255 codes per unit) a bucket spans under one code (checked when
/// the table is built: the codes at successive edges differ by at most one).
const BUCKETS: usize = 4096;

#[derive(Clone)]
struct Table {
    /// `start[k]`: the smallest float in [0, 1] that encodes to k or more (`start[0]` = 0,
    /// `start[256]` = ∞: no value reaches a code past 255).
    start: [f32; 257],
    /// The code at each bucket's lower edge, i / BUCKETS (the last entry: 1.0).
    code_at: Vec<u8>,
}

fn table() -> &'static Table {
    static TABLE: OnceLock<Table> = OnceLock::new();
    TABLE.get_or_init(|| {
        let mut start = [f32::INFINITY; 257];
        start[0] = 0.0;
        for (k, s) in start.iter_mut().enumerate().take(256).skip(1) {
            // The smallest bit pattern in [0, 1.0] whose float encodes to k or more; 1.0
            // encodes to 255, so one exists.
            let (mut lo, mut hi) = (0u32, 1.0f32.to_bits());
            while lo < hi {
                let mid = lo + (hi - lo) / 2;
                if linear_to_srgb8_formula(f32::from_bits(mid)) as usize >= k {
                    hi = mid;
                } else {
                    lo = mid + 1;
                }
            }
            *s = f32::from_bits(lo);
        }
        let code_at: Vec<u8> = (0..=BUCKETS).map(|i| linear_to_srgb8_formula(i as f32 / BUCKETS as f32)).collect();
        assert!(code_at.windows(2).all(|w| w[1] - w[0] <= 1), "a bucket spans more than one sRGB code");
        Table { start, code_at }
    })
}

/// sRGB encoding of a linear value, 8 bits: `linear_to_srgb8_formula`, by table. NaN
/// encodes to 0, as the formula's does.
#[inline]
pub fn linear_to_srgb8(linear: f32) -> u8 {
    encode_linear(table(), linear)
}

/// `linear_to_srgb8` of every sample of `linear` into `out`, the table found once (the
/// colour map's quantisation, `export::quantize_row`).
pub fn linear_to_srgb8_row(linear: &[f32], out: &mut [u8]) {
    let table = table();
    for (code, &x) in out.iter_mut().zip(linear) {
        *code = encode_linear(table, x);
    }
}

/// The code of any linear value: clamped to [0, 1], NaN to 0.
#[inline]
fn encode_linear(table: &Table, linear: f32) -> u8 {
    let c = linear.clamp(0.0, 1.0);
    if c.is_nan() {
        return 0;
    }
    code_of(table, c)
}

/// The code of `c` (in [0, 1]) from `table`.
#[inline]
fn code_of(table: &Table, c: f32) -> u8 {
    let code = table.code_at[(c * BUCKETS as f32) as usize];
    code + (c >= table.start[code as usize + 1]) as u8
}

#[cfg(test)]
mod tests {
    use super::*;
    use rayon::prelude::*;

    #[test]
    fn the_transfer_function_round_trips_and_meets_its_table_values() {
        for v in [0.0, 0.001, 0.003_130_8, 0.2, 0.5, 1.0] {
            assert!((decode(encode(v)) - v).abs() < 1e-12, "{v}");
            assert!((decode_f32(encode_f32(v as f32)) - v as f32).abs() < 1e-6, "{v}");
        }
        // The formula computed apart (Python, doubles): linear 0.18 encodes to 0.4613561295,
        // 0.5 decodes to 0.2140411405; the segments meet at 0.0031308 → 0.0404499 (the
        // standard's rounded 0.04045).
        assert!((encode(0.18) - 0.461_356_1).abs() < 1e-7, "{}", encode(0.18));
        assert!((decode(0.5) - 0.214_041_1).abs() < 1e-7, "{}", decode(0.5));
        assert!((encode(0.003_130_8) - 0.040_45).abs() < 1e-6);
        assert_eq!((encode(-1.0), decode(-1.0), decode(2.0)), (0.0, 0.0, 1.0));
        assert!((encode(2.0) - 1.0).abs() < 1e-15, "{}", encode(2.0));
    }

    /// The table against the formula at every float of [0, 1], and at values outside it and
    /// NaN. Negative control: the same comparison finds the one float a table with one
    /// code's start moved by one float gets wrong.
    #[test]
    fn the_table_encodes_as_the_formula() {
        let one = 1.0f32.to_bits();
        let differ = (0..=one).into_par_iter().filter(|b| {
            let x = f32::from_bits(*b);
            linear_to_srgb8(x) != linear_to_srgb8_formula(x)
        });
        assert_eq!(differ.count(), 0, "floats of [0, 1] that differ");
        for x in [-1.0, -0.0, 1.5, f32::INFINITY, f32::NEG_INFINITY, f32::NAN, f32::MIN_POSITIVE, 1e-40] {
            assert_eq!(linear_to_srgb8(x), linear_to_srgb8_formula(x), "{x:e}");
        }
        // Negative control: a start one float late.
        let mut broken = table().clone();
        broken.start[128] = f32::from_bits(broken.start[128].to_bits() + 1);
        let wrong = (0..=one)
            .into_par_iter()
            .filter(|b| {
                let x = f32::from_bits(*b);
                code_of(&broken, x) != linear_to_srgb8_formula(x)
            })
            .collect::<Vec<u32>>();
        assert_eq!(wrong, vec![table().start[128].to_bits()], "the broken table's wrong floats");
    }
}
