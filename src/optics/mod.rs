//! Optics: the exact thin film (complex Airy summation), spectral colour (CIE 1931 2°, D65),
//! CIELAB and CIEDE2000. This is the f64 reference every faster method is measured against
//! (PHYSICS.md).

pub mod accuracy;
pub mod brdf;
pub mod complex;
pub mod fast;
pub mod film;
pub mod lab;
pub mod lut;
pub mod methods;
pub mod plot;
pub mod query;
pub mod series;
pub mod spectrum;
pub mod stress;

use film::{FilmAtAngle, Stack, incoherent};
use spectrum::{Observer, xyz_to_linear_srgb};

/// Above this thickness the 1 nm spectral sum aliases (2β changes by more than ~1 rad per nm
/// at 400 nm), so the reference is the incoherent limit (PHYSICS.md).
pub const COHERENT_LIMIT_NM: f64 = 10_000.0;

/// The reference film colour: linear sRGB reflectance under D65 (a perfect reflector gives
/// (1, 1, 1)), from the exact coherent film summed at 1 nm, or the incoherent limit for
/// films thicker than `COHERENT_LIMIT_NM`.
pub fn film_rgb_reference(stack: Stack, thickness_nm: f64, cos0: f64) -> [f64; 3] {
    let obs = Observer::get();
    let xyz = if thickness_nm > COHERENT_LIMIT_NM {
        let r = incoherent(stack, cos0).r;
        obs.xyz(|_| r)
    } else {
        let film = FilmAtAngle::new(stack, thickness_nm, cos0);
        obs.xyz(|lambda| film.reflectance(lambda))
    };
    xyz_to_linear_srgb(xyz)
}
