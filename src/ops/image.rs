//! The one pixel buffer every node produces: a square-or-rectangular grid of f32 channels.
//!
//! Channels are interleaved (`data[(y * width + x) * channels + c]`) so a pixel's channels sit
//! in one cache line; rows are the unit of parallel work. One image is planar instead: the
//! multi-channel scale field, whose readers each take one to four of its channels
//! (`Image::plane`, `ScaleField::render_planar`). Everything is f32 in linear units:
//! quantisation happens only in `export`, so no intermediate step loses precision.

use rayon::prelude::*;

/// The rows of the texture an image holds: all of them (the tile, a preview) or a strip of a
/// long body atlas evaluated a piece at a time (`generate::strips`). Generators place their
/// pixels by the texture's full height, so a strip holds exactly the rows the whole texture
/// would; filters that look at neighbours see only the strip, which is why strips are
/// evaluated with a margin (`Graph::row_reach`) and cropped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Frame {
    pub width: usize,
    /// Rows in this image.
    pub height: usize,
    /// Rows in the whole texture.
    pub full_height: usize,
    /// The texture row of this image's first row.
    pub row0: usize,
    /// The texture repeats along v (the tile); a body atlas does not (its first and last
    /// rows are the snout and the tail tip), and filters then clamp at its ends.
    pub wraps_v: bool,
}

impl Frame {
    /// The whole texture.
    pub fn whole(width: usize, height: usize) -> Frame {
        Frame { width, height, full_height: height, row0: 0, wraps_v: true }
    }

    /// Texture v of the centre of this image's row `y`.
    #[inline]
    pub fn v(&self, y: usize) -> f32 {
        (self.texture_row(y) as f32 + 0.5) * (1.0 / self.full_height as f32)
    }

    /// The texture row of this image's row `y`. A strip of a repeating texture may run over
    /// the last row into the first: the tile evaluated in strips (`generate`), whose first
    /// strip's margin above row 0 is the texture's last rows.
    #[inline]
    pub fn texture_row(&self, y: usize) -> usize {
        let row = self.row0 + y;
        if row >= self.full_height && self.wraps_v { row - self.full_height } else { row }
    }

    /// The rows run over the texture's last row into its first.
    pub fn crosses_seam(&self) -> bool {
        self.wraps_v && self.row0 + self.height > self.full_height
    }

    /// The rows up to the texture's last and those from its first: two frames that do not
    /// cross the seam, which a generator evaluates as it would any strip (`Op::eval`).
    pub fn split_at_seam(&self) -> (Frame, Frame) {
        let above = self.full_height - self.row0;
        (Frame { height: above, ..*self }, Frame { row0: 0, height: self.height - above, ..*self })
    }
}

#[derive(Debug, PartialEq)]
pub struct Image {
    pub width: usize,
    pub height: usize,
    pub channels: usize,
    pub data: Vec<f32>,
}

/// Buffers go back to the pool (`super::pool`) rather than to the allocator.
impl Drop for Image {
    fn drop(&mut self) {
        super::pool::give(std::mem::take(&mut self.data));
    }
}

impl Clone for Image {
    fn clone(&self) -> Self {
        let data = super::pool::take_copy(&self.data);
        Image { width: self.width, height: self.height, channels: self.channels, data }
    }
}

impl Image {
    pub fn new(width: usize, height: usize, channels: usize) -> Self {
        Image { width, height, channels, data: super::pool::take_zeroed(width * height * channels) }
    }

    /// Fills a new image row by row in parallel; `pixel(u, v, out)` receives the pixel centre
    /// in normalised texture coordinates (u, v in [0, 1)) and writes `channels` values.
    pub fn from_fn<F>(width: usize, height: usize, channels: usize, pixel: F) -> Self
    where
        F: Fn(f32, f32, &mut [f32]) + Sync,
    {
        let mut image = Image::new(width, height, channels);
        let (inv_w, inv_h) = (1.0 / width as f32, 1.0 / height as f32);
        image.data.par_chunks_mut(width * channels).enumerate().for_each(|(y, row)| {
            let v = (y as f32 + 0.5) * inv_h;
            for (x, out) in row.chunks_exact_mut(channels).enumerate() {
                pixel((x as f32 + 0.5) * inv_w, v, out);
            }
        });
        image
    }

    /// `from_fn` over the rows of `frame`: v is the texture's, not the image's.
    pub fn from_fn_in<F>(frame: Frame, channels: usize, pixel: F) -> Self
    where
        F: Fn(f32, f32, &mut [f32]) + Sync,
    {
        let (width, height) = (frame.width, frame.height);
        let mut image = Image::new(width, height, channels);
        let (inv_w, inv_h) = (1.0 / width as f32, 1.0 / frame.full_height as f32);
        image.data.par_chunks_mut(width * channels).enumerate().for_each(|(y, row)| {
            let v = (frame.texture_row(y) as f32 + 0.5) * inv_h;
            for (x, out) in row.chunks_exact_mut(channels).enumerate() {
                pixel((x as f32 + 0.5) * inv_w, v, out);
            }
        });
        image
    }

    /// A single-channel `from_fn_in`.
    pub fn gray_from_fn_in<F>(frame: Frame, value: F) -> Self
    where
        F: Fn(f32, f32) -> f32 + Sync,
    {
        Image::from_fn_in(frame, 1, |u, v, out| out[0] = value(u, v))
    }

    /// A single-channel image from `value(u, v)` at pixel centres.
    pub fn gray_from_fn<F>(width: usize, height: usize, value: F) -> Self
    where
        F: Fn(f32, f32) -> f32 + Sync,
    {
        Image::from_fn(width, height, 1, |u, v, out| out[0] = value(u, v))
    }

    pub fn pixel_count(&self) -> usize {
        self.width * self.height
    }

    pub fn bytes(&self) -> usize {
        self.data.len() * std::mem::size_of::<f32>()
    }

    /// Value at (x, y, c) with wrap-around addressing: the texture is a torus.
    #[inline]
    pub fn at_wrapped(&self, x: isize, y: isize, c: usize) -> f32 {
        let xw = x.rem_euclid(self.width as isize) as usize;
        let yw = y.rem_euclid(self.height as isize) as usize;
        self.data[(yw * self.width + xw) * self.channels + c]
    }

    /// One row of pixels (all channels).
    #[inline]
    pub fn row(&self, y: usize) -> &[f32] {
        self.rows(y..y + 1)
    }

    /// The rows `rows` of pixels (all channels), one after another.
    #[inline]
    pub fn rows(&self, rows: std::ops::Range<usize>) -> &[f32] {
        let stride = self.width * self.channels;
        &self.data[rows.start * stride..rows.end * stride]
    }

    /// The rows `rows` as an image of their own (a copy).
    pub fn band(&self, rows: std::ops::Range<usize>) -> Image {
        let data = super::pool::take_copy(self.rows(rows.clone()));
        Image { width: self.width, height: rows.len(), channels: self.channels, data }
    }

    /// Channel `c` of a **planar** image, whose channels lie one after another, each a
    /// whole row-major plane (the scale field as the graph holds it,
    /// `ScaleField::render_planar`); for one channel the same as `data`.
    #[inline]
    pub fn plane(&self, c: usize) -> &[f32] {
        let n = self.width * self.height;
        &self.data[c * n..(c + 1) * n]
    }

    /// The rows `rows` of channel `c` of a planar image (`plane`).
    #[inline]
    pub fn plane_rows(&self, c: usize, rows: std::ops::Range<usize>) -> &[f32] {
        &self.plane(c)[rows.start * self.width..rows.end * self.width]
    }
}

/// Hermite smoothstep: 0 below `e0`, 1 above `e1`, 3t² − 2t³ between.
#[inline]
pub fn smoothstep(e0: f32, e1: f32, x: f32) -> f32 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// `x.floor() as i32` without a libm call: x86-64's baseline has no SSE4.1 `roundss`, so
/// `f32::floor` is a function call, and the lattice kernels floor several times per pixel.
/// Exact for |x| < 2³¹.
#[inline(always)]
pub fn floor_i32(x: f32) -> i32 {
    let i = x as i32;
    if (i as f32) > x { i - 1 } else { i }
}

/// The runs of consecutive indices `0..len` with equal `key`, as (first, end, key): the
/// pixels of a row that share a lattice cell or a pair of coarse columns, so a kernel looks
/// up what they share once per run (`noise::RowRuns`, `filters::resample_bilinear_rows`).
pub fn runs_by<K: PartialEq>(len: usize, key: impl Fn(usize) -> K) -> Vec<(usize, usize, K)> {
    let mut runs: Vec<(usize, usize, K)> = Vec::new();
    for i in 0..len {
        let k = key(i);
        match runs.last_mut() {
            Some(run) if run.2 == k => run.1 = i + 1,
            _ => runs.push((i, i + 1, k)),
        }
    }
    runs
}
