//! What the GPU produced, read back and measured against the CPU: the frame against its f64
//! reference (`frame`), the WGSL BRDF against its Rust twin on a buffer of samples
//! (`brdf_eval`), and the frame-time benchmark of the skin shader (`bench`).

pub mod bench;
pub mod brdf_eval;
pub mod frame;
