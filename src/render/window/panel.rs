//! The window's side panel: the optics sliders (over the preset's own range table, the wide
//! ones logarithmic, like the thesis' Unity inspector, Fig. 5.1), the stage, map and film
//! method pickers, the scene controls and the status line.

use crate::maps::MapKind;
use crate::optics::film::Stack;
use crate::render::engine::film::GpuFilmMethod;
use crate::render::engine::renderer::FrameSettings;
use crate::render::engine::scene::{LayerOptics, Light, Stage, View};

/// The most snakes the panel's slider draws (the window's memory check counts as many).
pub const SNAKES_SLIDER_MAX: u32 = 20;

/// Optics as the sliders edit them (σ0 as one number: an RGB σ0 shows its mean, and the
/// slider scales the three channels together).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sliders {
    pub n0: f64,
    pub n1: f64,
    pub n2: f64,
    pub thickness_nm: f64,
    spread_nm: f64,
    pigment_thickness: f64,
    absorption: f64,
    /// σ0's channels over their mean (1, 1, 1 for a grey σ0): the window drew a tinted σ0
    /// as its mean, unlike the headless preview (a window sweep).
    absorption_tint: [f64; 3],
}

impl Sliders {
    pub fn from_preset(preset: &crate::preset::Preset) -> Sliders {
        let o = &preset.optics;
        let mean_absorption = o.absorption.0.iter().sum::<f64>() / 3.0;
        Sliders {
            n0: o.ambient_ior,
            n1: o.film_ior,
            n2: o.pigment_ior,
            thickness_nm: o.film_thickness_nm,
            spread_nm: preset.iridescence.spread_nm,
            pigment_thickness: o.pigment_thickness,
            absorption: mean_absorption,
            absorption_tint: o.absorption.0.map(|a| if mean_absorption > 0.0 { a / mean_absorption } else { 1.0 }),
        }
    }

    /// The preset keys where these sliders differ from `file` (the sliders of the preset as
    /// loaded, its `--set` included), as `--set KEY=VALUE` arguments that carry the tuned
    /// optics to `generate`, `export` or a headless preview; empty where none differs. Values
    /// to six significant digits (a drag gives fifteen), and a key differs where its six
    /// digits do; σ0 as the three channels the shader reads.
    pub fn set_arguments(&self, file: &Sliders) -> Vec<String> {
        let absorption = |s: &Sliders| {
            let channels = s.channels().map(significant);
            if channels.iter().all(|c| *c == channels[0]) {
                channels[0].clone()
            } else {
                format!("[{}]", channels.join(","))
            }
        };
        type Value = fn(&Sliders) -> String;
        let keys: [(&str, Value); 7] = [
            ("optics.ambient_ior", |s| significant(s.n0)),
            ("optics.film_ior", |s| significant(s.n1)),
            ("optics.pigment_ior", |s| significant(s.n2)),
            ("optics.film_thickness_nm", |s| significant(s.thickness_nm)),
            ("iridescence.spread_nm", |s| significant(s.spread_nm)),
            ("optics.pigment_thickness", |s| significant(s.pigment_thickness)),
            ("optics.absorption", absorption),
        ];
        keys.iter()
            .filter_map(|(key, value)| {
                let now = value(self);
                (now != value(file)).then(|| format!("{key}={now}"))
            })
            // Quoted where a shell would read a character: σ0's brackets are a glob.
            .map(
                |argument| {
                    if argument.contains('[') { format!("--set '{argument}'") } else { format!("--set {argument}") }
                },
            )
            .collect()
    }

    /// σ0 per channel, as the shader reads it: the tint times the slider, within the key's
    /// range.
    fn channels(&self) -> [f64; 3] {
        let (lo, hi) = crate::preset::validate::ranges::ABSORPTION;
        self.absorption_tint.map(|tint| (tint * self.absorption).clamp(lo, hi))
    }

    pub fn optics(&self) -> LayerOptics {
        LayerOptics {
            stack: Stack { n0: self.n0, n1: self.n1, n2: self.n2 },
            thickness_range_nm: crate::material::thickness_range_nm(self.thickness_nm, self.spread_nm),
            // Each channel within the key's range: a tinted σ0's largest channel would pass
            // it as the slider nears its end ([0, 0, 100] is a mean of 33 and a tint of 3).
            optical_depth: self.channels().map(|absorption| absorption * self.pigment_thickness),
        }
    }
}

/// The side panel. The status line (a reload's result, why the file is not watched) comes
/// first, and the rest scrolls: last, below the sliders, it was cut off at the README's own
/// 960×540 and out of sight at 320×200 (a window sweep).
pub fn controls(ui: &mut egui::Ui, settings: &mut FrameSettings, s: &mut Sliders, status: &str, frame_ms: f64) {
    egui::Panel::left("controls").default_size(260.0).show(ui, |ui| {
        egui::ScrollArea::vertical().show(ui, |ui| panel_contents(ui, settings, s, status, frame_ms));
    });
}

fn panel_contents(ui: &mut egui::Ui, settings: &mut FrameSettings, s: &mut Sliders, status: &str, frame_ms: f64) {
    {
        ui.heading("snakeskin");
        ui.label(format!("frame {frame_ms:.2} ms ({:.0} fps)", if frame_ms > 0.0 { 1000.0 / frame_ms } else { 0.0 }));
        if !status.is_empty() {
            ui.label(status);
        }
        ui.separator();
        ui.label("View");
        let mut view = settings.view;
        egui::ComboBox::from_label("stage / map").selected_text(view_name(view)).show_ui(ui, |ui| {
            for stage in Stage::ALL {
                ui.selectable_value(&mut view, View::Shaded(stage), view_name(View::Shaded(stage)));
            }
            for map in MapKind::ALL {
                ui.selectable_value(&mut view, View::Map(map), view_name(View::Map(map)));
            }
        });
        settings.view = view;
        let mut method = settings.method;
        egui::ComboBox::from_label("film method").selected_text(method.name()).show_ui(ui, |ui| {
            for m in [
                GpuFilmMethod::Lut,
                GpuFilmMethod::Rgb3,
                GpuFilmMethod::SpectralN(8),
                GpuFilmMethod::SpectralN(32),
                GpuFilmMethod::GaussianFit,
            ] {
                ui.selectable_value(&mut method, m, m.name());
            }
        });
        settings.method = method;
        ui.separator();
        ui.label("Layer optics (thesis Table 5.2)");
        // The preset's own ranges (one table for files, --set and the window); the wide ones
        // (10 mm of film, σ0 and δ1 up to 100) are logarithmic so the usual values stay fine.
        use crate::preset::validate::ranges;
        ui.add(slider(&mut s.n0, ranges::IOR, false, "n0 ambient"));
        ui.add(slider(&mut s.n1, ranges::IOR, false, "n1 film"));
        ui.add(slider(&mut s.n2, ranges::IOR, false, "n2 pigment"));
        ui.add(slider(&mut s.thickness_nm, ranges::FILM_THICKNESS_NM, true, "δ0 film nm"));
        ui.add(slider(&mut s.spread_nm, ranges::SPREAD_NM, false, "δ spread nm"));
        ui.add(slider(&mut s.pigment_thickness, ranges::PIGMENT_THICKNESS, true, "δ1 pigment"));
        ui.add(slider(&mut s.absorption, ranges::ABSORPTION, true, "σ0 absorption"));
        ui.separator();
        ui.label("Scene");
        // Dragged over the usual range; a value given on the command line outside it (the
        // CLI takes 1e-6 to 1000 and up to 400 snakes) stays until the slider is moved: it
        // was clamped to the slider's ends at the first frame (a window sweep).
        let exposure = egui::Slider::new(&mut settings.exposure, 0.1..=4.0).logarithmic(true);
        ui.add(exposure.clamping(egui::SliderClamping::Edits).text("exposure"));
        let mut azimuth = settings.lighting.key.direction.x.atan2(settings.lighting.key.direction.z).to_degrees();
        let mut elevation = settings.lighting.key.direction.y.clamp(-1.0, 1.0).asin().to_degrees();
        let a = ui.add(egui::Slider::new(&mut azimuth, -180.0..=180.0).text("light azimuth"));
        let e = ui.add(egui::Slider::new(&mut elevation, 1.0..=89.0).text("light elevation"));
        if a.changed() || e.changed() {
            let irradiance = settings.lighting.key.irradiance;
            settings.lighting.key = Light::from_angles(azimuth, elevation, irradiance);
        }
        ui.checkbox(&mut settings.lighting.fill.enabled, "fill light");
        ui.checkbox(&mut settings.ground, "ground");
        let snakes = egui::Slider::new(&mut settings.snakes, 1..=SNAKES_SLIDER_MAX);
        ui.add(snakes.clamping(egui::SliderClamping::Edits).text("snakes"));
        ui.separator();
        ui.label("drag: orbit · wheel: zoom\nS: save the view as a PNG\nR: reset the view");
    }
}

/// `value` to six significant digits, without trailing zeros (TOML reads it back).
fn significant(value: f64) -> String {
    if value == 0.0 || !value.is_finite() {
        return format!("{value}");
    }
    let decimals = (5 - value.abs().log10().floor() as i32).max(0) as usize;
    let text = format!("{value:.decimals$}");
    if text.contains('.') { text.trim_end_matches('0').trim_end_matches('.').to_string() } else { text }
}

fn view_name(view: View) -> String {
    match view {
        View::Shaded(Stage::Diffuse) => "(a) diffuse".into(),
        View::Shaded(Stage::DiffuseNormal) => "(b) + normal map".into(),
        View::Shaded(Stage::Film) => "(c) thin film".into(),
        View::Shaded(Stage::All) => "(d) all layers".into(),
        View::Map(map) => format!("map: {map}"),
    }
}

/// A slider over one of the preset's ranges.
fn slider<'a>(value: &'a mut f64, (lo, hi): (f64, f64), logarithmic: bool, text: &str) -> egui::Slider<'a> {
    egui::Slider::new(value, lo..=hi).logarithmic(logarithmic).text(text)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sliders give back the optics the preset has: a tinted σ0 keeps its channels (the
    /// window drew their mean, the headless preview the three).
    #[test]
    fn the_sliders_keep_the_presets_optics() {
        for (name, overrides) in [
            ("erythrolamprus-miliaris", vec![("optics.absorption".to_string(), "[0.1, 0.4, 0.9]".to_string())]),
            ("erythrolamprus-miliaris", vec![("optics.absorption".to_string(), "0".to_string())]),
            ("xenopeltis-unicolor", vec![]),
        ] {
            let loaded = crate::preset::load(name, &overrides, None).unwrap();
            let want = LayerOptics::from_preset(&loaded.preset);
            let got = Sliders::from_preset(&loaded.preset).optics();
            for c in 0..3 {
                let (g, w) = (got.optical_depth[c], want.optical_depth[c]);
                assert!((g - w).abs() <= 1e-12 * w.abs().max(1.0), "{name} {overrides:?}: {got:?} against {want:?}");
            }
            assert_eq!(got.stack, want.stack);
            assert_eq!(got.thickness_range_nm, want.thickness_range_nm);
        }
    }

    /// The sliders' `--set` arguments carry them: loaded with them, the preset's sliders give
    /// none back (to six digits). Untouched sliders give none; each one moved gives its key.
    #[test]
    fn the_sliders_set_arguments_give_their_optics_back() {
        let loaded = crate::preset::load("erythrolamprus-miliaris", &[], None).unwrap();
        let file = Sliders::from_preset(&loaded.preset);
        assert_eq!(file.set_arguments(&file), Vec::<String>::new());
        let moved = Sliders {
            n1: 1.712345678,
            thickness_nm: 512.3456789,
            spread_nm: 33.3,
            absorption: file.absorption * 2.5 + 0.01,
            absorption_tint: [0.5, 1.0, 1.5],
            ..file
        };
        let arguments = moved.set_arguments(&file);
        assert_eq!(arguments.len(), 4, "{arguments:?}");
        assert!(arguments.contains(&"--set optics.film_ior=1.71235".to_string()), "{arguments:?}");
        assert!(arguments.contains(&"--set optics.film_thickness_nm=512.346".to_string()), "{arguments:?}");
        let overrides: Vec<(String, String)> = arguments
            .iter()
            .map(|a| {
                let a = a.trim_start_matches("--set ").trim_matches('\'');
                let (key, value) = a.split_once('=').unwrap();
                (key.to_string(), value.to_string())
            })
            .collect();
        let reloaded = crate::preset::load("erythrolamprus-miliaris", &overrides, None).unwrap();
        let back = Sliders::from_preset(&reloaded.preset);
        assert_eq!(moved.set_arguments(&back), Vec::<String>::new(), "{overrides:?}");
        assert_eq!(back.set_arguments(&file).len(), 4);
    }

    /// Six significant digits, as TOML reads them back.
    #[test]
    fn values_are_written_to_six_significant_digits() {
        for (value, text) in [
            (512.3456789, "512.346"),
            (1.5, "1.5"),
            (2_412_345.6, "2412346"),
            (0.000012345678, "0.0000123457"),
            (0.0, "0"),
            (100.0, "100"),
        ] {
            assert_eq!(significant(value), text);
        }
    }

    /// The status line is in sight in a small window (320×200, the tests' size): it came last,
    /// below the panel's end (a window sweep).
    #[test]
    fn the_status_line_is_in_sight_in_a_small_window() {
        let loaded = crate::preset::load("natrix-natrix", &[], None).unwrap();
        let mut sliders = Sliders::from_preset(&loaded.preset);
        let mut settings = FrameSettings::default();
        let context = egui::Context::default();
        let screen = egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(320.0, 200.0));
        let input = || egui::RawInput { screen_rect: Some(screen), ..Default::default() };
        let status = "reload failed, keeping the last good maps";
        let mut bottom = None;
        for _ in 0..2 {
            let mut output = context.run_ui(input(), |ui| controls(ui, &mut settings, &mut sliders, status, 0.0));
            output.textures_delta.clear();
            bottom = output.shapes.iter().find_map(|clipped| match &clipped.shape {
                egui::Shape::Text(text) if text.galley.text().starts_with("reload failed") => {
                    Some(text.pos.y + text.galley.size().y)
                }
                _ => None,
            });
        }
        let bottom = bottom.expect("the status line is drawn");
        assert!(bottom <= screen.max.y, "the status line ends at {bottom}, below the window's {}", screen.max.y);
    }

    /// A value the command line gave outside a slider's range survives the panel's frames
    /// (it was clamped to the slider's end at the first frame).
    #[test]
    fn the_panel_keeps_command_line_values_outside_its_sliders() {
        let loaded = crate::preset::load("natrix-natrix", &[], None).unwrap();
        let mut sliders = Sliders::from_preset(&loaded.preset);
        let mut settings = FrameSettings { exposure: 10.0, snakes: 100, ..FrameSettings::default() };
        let context = egui::Context::default();
        for _ in 0..2 {
            let mut output =
                context.run_ui(egui::RawInput::default(), |ui| controls(ui, &mut settings, &mut sliders, "", 0.0));
            // No renderer takes the font texture here (epaint's debug build asserts on it).
            output.textures_delta.clear();
        }
        assert_eq!((settings.exposure, settings.snakes), (10.0, 100));
    }
}
