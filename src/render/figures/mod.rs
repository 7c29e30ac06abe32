//! Pictures for people: the documentation figures (the thesis' Figs. 5.5–5.12 redone), the
//! species contact sheet and the pattern gallery, and the PNG writing they share. Each
//! renders through the engine (`render::engine`) exactly as the window does.

pub mod gallery;
pub mod sheet;

use std::path::{Path, PathBuf};

use super::engine::film::GpuFilmMethod;
use super::engine::prepare::upload_material;
use super::engine::renderer::{FrameSettings, Renderer};
use super::engine::scene::{Camera, Stage, View};
use crate::Error;
use crate::export::{FileGroup, write_file_atomically};

/// A rendered image as PNG bytes, as RGB converted without a copy of the RGBA image
/// (`renderer::frame_bytes` counts the RGB image and the PNG bytes).
pub fn rendered_png_bytes(image: &image::RgbaImage) -> Result<Vec<u8>, Error> {
    use image::buffer::ConvertBuffer;
    let rgb: image::RgbImage = image.convert();
    png_bytes(&rgb)
}

/// Encodes and writes an RGB image (atomically).
pub fn write_rgb_png(path: &Path, image: &image::RgbImage) -> Result<PathBuf, Error> {
    Ok(write_file_atomically(path, png_bytes(image)?)?)
}

/// An RGB image as PNG bytes, tagged sRGB (`export::encode_srgb_image_png`). An encoder
/// failure is ours, not the user's.
pub fn png_bytes(image: &image::RgbImage) -> Result<Vec<u8>, Error> {
    crate::export::encode_srgb_image_png(image.width(), image.height(), image.as_raw())
        .map_err(|e| Error::Internal(format!("PNG encoding failed: {e}")))
}

/// One documentation figure: its file name, what it shows, and the overrides it needs.
pub struct Figure {
    pub file: &'static str,
    pub caption: &'static str,
    pub overrides: Vec<(&'static str, &'static str)>,
    pub view: View,
}

/// The thesis' Figs. 5.5–5.12, redone: layer stages, film thickness δ0 and absorption σ0.
pub fn figure_list() -> Vec<Figure> {
    // Fig. 5.12's material: film IOR 1.56, δ0 = 900 nm, absorption 0.4 (thesis, caption).
    let fig_5_12 = vec![("optics.film_ior", "1.56"), ("optics.film_thickness_nm", "900"), ("optics.absorption", "0.4")];
    let mut figures: Vec<Figure> = Stage::ALL
        .iter()
        .zip(["stage_a_diffuse.png", "stage_b_normal.png", "stage_c_film.png", "stage_d_all.png"])
        .zip([
            "(a) diffuse base only",
            "(b) diffuse + normal map",
            "(c) thin film alone",
            "(d) all layers (film, pigment, base)",
        ])
        .map(|((stage, file), caption)| Figure {
            file,
            caption,
            overrides: fig_5_12.clone(),
            view: View::Shaded(*stage),
        })
        .collect();
    for (file, caption, d) in [
        ("thickness_0nm.png", "δ0 = 0 nm: plain Fresnel, no interference (Fig. 5.8)", "0"),
        ("thickness_200nm.png", "δ0 = 200 nm (Fig. 5.5)", "200"),
        ("thickness_400nm.png", "δ0 = 400 nm (Fig. 5.6)", "400"),
        ("thickness_600nm.png", "δ0 = 600 nm (Fig. 5.7)", "600"),
        ("thickness_2.4mm.png", "δ0 = 2.4 mm: the incoherent limit, no moiré (Fig. 5.9)", "2400000"),
    ] {
        figures.push(Figure {
            file,
            caption,
            // δ0 = 0 means no film anywhere: the thickness map's spread goes too.
            overrides: if d == "0" {
                vec![("optics.film_thickness_nm", d), ("iridescence.spread_nm", "0"), ("optics.absorption", "0.6")]
            } else {
                vec![("optics.film_thickness_nm", d), ("optics.absorption", "0.6")]
            },
            view: View::Shaded(Stage::All),
        });
    }
    for (file, caption, s) in
        [("absorption_0.1.png", "σ0 = 0.1 (Fig. 5.10)", "0.1"), ("absorption_0.7.png", "σ0 = 0.7 (Fig. 5.11)", "0.7")]
    {
        figures.push(Figure {
            file,
            caption,
            overrides: vec![("optics.absorption", s), ("optics.film_thickness_nm", "400")],
            view: View::Shaded(Stage::All),
        });
    }
    figures
}

/// Checks every figure's file in `out_dir` (`check_target`, `export::check_replaces_its_own`), and that none is the file
/// `preset` reads (a preset saved as `stage_a_diffuse.png` in the figures' folder was
/// replaced by that figure), before any is rendered.
pub fn check_figure_files(out_dir: &Path, preset: &str) -> Result<(), Error> {
    let input = crate::export::Inputs::new(crate::preset::input_file(preset));
    let mut probed = std::collections::HashSet::new();
    for figure in figure_list() {
        let target = out_dir.join(figure.file);
        crate::export::check_target(&target)?;
        input.check(&target)?;
        crate::export::check_replaces_its_own(&target, "png")?;
        // The folder takes files (or can be made): a read-only one was found after the
        // figures' maps and first frame, seconds in (an independent review's find).
        crate::export::check_folder_writable(out_dir, figure.file, &mut probed)?;
    }
    Ok(())
}

/// The preset as each figure of `figure_list` draws it (its overrides applied), in the list's
/// order, parsed from `source`: `write_figures` renders these, and the command prints their
/// warnings first (the figures' own overrides can clamp a preset's colours: absorption 0.7
/// darkens the stack below a bright base colour).
pub fn figure_variants(source: &crate::preset::PresetSource) -> Result<Vec<crate::preset::LoadedPreset>, Error> {
    figure_list()
        .iter()
        .map(|figure| {
            let overrides: Vec<(String, String)> =
                figure.overrides.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect();
            Ok(crate::preset::parse(source, &overrides)?)
        })
        .collect()
}

/// Renders every figure of `figure_list` for `preset` into `out_dir`, and puts them in place
/// together (`FileGroup`: an interrupted or failed run leaves the earlier figures as they
/// were, not some new ones among them); returns the files. `variants` are the figures'
/// presets (`figure_variants`), parsed from the preset's text as the command read it once
/// (`preset::read_source`) before any is rendered (each figure read the file again: one
/// saved during a run made a set of two presets' figures, and an error in it came after the
/// others' rendering).
pub fn write_figures(
    renderer: &Renderer,
    preset: &str,
    variants: &[crate::preset::LoadedPreset],
    out_dir: &Path,
    size: (u32, u32),
    map_size: usize,
    progress: &dyn Fn(usize, usize),
) -> Result<Vec<PathBuf>, Error> {
    check_figure_files(out_dir, preset)?;
    let figures = figure_list();
    if variants.len() != figures.len() {
        return Err(Error::Internal(format!("{} variants for {} figures", variants.len(), figures.len())));
    }
    let mut group = FileGroup::new();
    for (i, (figure, loaded)) in figures.iter().zip(variants).enumerate() {
        progress(i, figures.len());
        crate::memory::release_freed();
        let material = upload_material(renderer, loaded, map_size, GpuFilmMethod::Lut)?;
        let settings = FrameSettings { view: figure.view, camera: Camera::close_up(), ..FrameSettings::default() };
        let image = renderer.render_image(&settings, &material, size.0, size.1)?;
        let rgb = image::DynamicImage::ImageRgba8(image).into_rgb8();
        group.stage(&out_dir.join(figure.file), png_bytes(&rgb)?)?;
    }
    let written = group.commit()?;
    progress(figures.len(), figures.len());
    Ok(written)
}

#[cfg(test)]
mod tests {
    /// Renders, figures and sheets are tagged sRGB like the colour maps (they were untagged),
    /// and read back as the pixels written.
    #[test]
    fn an_image_for_the_eye_is_a_tagged_srgb_png_of_its_pixels() {
        let image = image::RgbImage::from_fn(5, 3, |x, y| image::Rgb([x as u8 * 50, y as u8 * 80, 7]));
        let bytes = super::png_bytes(&image).unwrap();
        let decoder = png::Decoder::new(std::io::Cursor::new(&bytes));
        let reader = decoder.read_info().unwrap();
        assert!(reader.info().srgb.is_some(), "no sRGB chunk");
        let back = image::load_from_memory(&bytes).unwrap().into_rgb8();
        assert_eq!(back, image);
    }
}
