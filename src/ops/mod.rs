//! Pure pixel kernels, kept apart from graph bookkeeping (as noise-rs keeps `noise_fns/` and
//! resvg keeps `filter/`): each function takes images and parameters and returns an image.
//! Everything is defined in normalised coordinates and wraps around u, and v on the tile, so
//! tiles tile and a body atlas wraps round the body only (`image::Frame::wraps_v`).

pub mod body;
pub mod filters;
pub mod hash;
pub mod image;
pub mod noise;
pub mod occlusion;
pub mod pool;
pub mod scale_colour;
pub mod scales;
pub mod shapes;

pub use image::{Frame, Image};
