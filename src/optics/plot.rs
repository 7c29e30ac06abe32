//! The time-against-error plot of `bench irid` and `bench layered`: an SVG scatter (log
//! cost, log mean error), one labelled point per method. SVG because the plot needs text
//! labels and no font stack.

use std::fmt::Write;

use super::accuracy::MethodReport;

/// `reference`: what the errors were measured against, for the error axis' title. A point
/// off the axes' range (ΔE 0.01 to 100, 1 ns to 10 µs) is drawn at the edge and its label
/// gives its values (`bench irid`'s `lut` at 0.0056 sat on the 0.01 line unsaid: a
/// hostile-input review).
pub fn error_vs_cost_svg(reports: &[MethodReport], default: &str, reference: &str) -> String {
    let (w, h, left, bottom, top, right) = (720.0, 440.0, 70.0, 50.0, 20.0, 150.0);
    let (pw, ph) = (w - left - right, h - top - bottom);
    let log = |v: f64| v.max(1e-6).log10();
    let (x_min, x_max) = (0.0, 4.0); // 1 ns .. 10 µs
    let (y_min, y_max) = (-2.0, 2.0); // ΔE 0.01 .. 100
    let px = |ns: f64| left + (log(ns).clamp(x_min, x_max) - x_min) / (x_max - x_min) * pw;
    let py = |de: f64| top + ph - (log(de).clamp(y_min, y_max) - y_min) / (y_max - y_min) * ph;
    let mut svg = String::new();
    let _ = writeln!(
        svg,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" font-family="sans-serif" font-size="12">"#
    );
    let _ = writeln!(svg, r#"<rect width="{w}" height="{h}" fill="white"/>"#);
    for e in 0..=4 {
        let x = left + e as f64 / 4.0 * pw;
        let _ = writeln!(
            svg,
            r##"<line x1="{x}" y1="{top}" x2="{x}" y2="{}" stroke="#ddd"/><text x="{x}" y="{}" text-anchor="middle">{}</text>"##,
            top + ph,
            top + ph + 16.0,
            ["1", "10", "100", "1k", "10k"][e]
        );
    }
    for e in 0..=4 {
        let y = top + ph - e as f64 / 4.0 * ph;
        let _ = writeln!(
            svg,
            r##"<line x1="{left}" y1="{y}" x2="{}" y2="{y}" stroke="#ddd"/><text x="{}" y="{}" text-anchor="end">{}</text>"##,
            left + pw,
            left - 6.0,
            y + 4.0,
            ["0.01", "0.1", "1", "10", "100"][e]
        );
    }
    let _ = writeln!(
        svg,
        r#"<text x="{}" y="{}" text-anchor="middle">ns per evaluation (CPU, f32, one core)</text>"#,
        left + pw / 2.0,
        h - 10.0
    );
    let _ = writeln!(
        svg,
        r#"<text transform="translate(16 {}) rotate(-90)" text-anchor="middle">mean CIEDE2000 vs {reference}</text>"#,
        top + ph / 2.0
    );
    let on_axes = |v: f64, (lo, hi): (f64, f64)| (lo..=hi).contains(&log(v));
    for r in reports {
        let (x, y) = (px(r.ns_per_eval), py(r.mean_de));
        let colour = if r.name == default { "#c0392b" } else { "#2c3e50" };
        let label = if on_axes(r.mean_de, (y_min, y_max)) && on_axes(r.ns_per_eval, (x_min, x_max)) {
            r.name.clone()
        } else {
            format!("{} (off the axes: ΔE {:.3}, {:.1} ns)", r.name, r.mean_de, r.ns_per_eval)
        };
        let _ = writeln!(
            svg,
            r#"<circle cx="{x:.1}" cy="{y:.1}" r="5" fill="{colour}"/><text x="{:.1}" y="{:.1}">{label}</text>"#,
            x + 8.0,
            y + 4.0,
        );
    }
    svg.push_str("</svg>\n");
    svg
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(name: &str, mean_de: f64, ns_per_eval: f64) -> MethodReport {
        MethodReport { name: name.into(), mean_de, p95_de: mean_de, max_de: mean_de, ns_per_eval }
    }

    /// The error axis names what the errors were measured against (`bench layered`'s said
    /// "spectral reference" of its photon walk), and a point off the axes gives its values
    /// in its label (one at ΔE 0.0056 sat on the 0.01 line unsaid: a hostile-input review);
    /// one on them is labelled by its name alone (the control).
    #[test]
    fn the_plot_names_its_reference_and_the_values_of_points_off_its_axes() {
        let svg = error_vs_cost_svg(&[point("lut", 0.0056, 12.0), point("rgb3", 0.5, 40.0)], "lut", "the photon walk");
        assert!(svg.contains(">mean CIEDE2000 vs the photon walk</text>"), "{svg}");
        assert!(svg.contains(">lut (off the axes: ΔE 0.006, 12.0 ns)</text>"), "{svg}");
        assert!(svg.contains(">rgb3</text>"), "{svg}");
        let slow = error_vs_cost_svg(&[point("walk", 1.0, 2e4)], "lut", "x");
        assert!(slow.contains(">walk (off the axes: ΔE 1.000, 20000.0 ns)</text>"), "{slow}");
    }
}
