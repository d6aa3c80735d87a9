//! A self-contained SVG plot of RelMSE against frame count, one line per method with
//! its 95 % confidence band over seeds (`strata compare` writes it as `relmse.svg`).

use crate::evaluation::compare::{FrameError, relmse_over_seeds};
use crate::restir::Method;

const WIDTH: f64 = 640.0;
const HEIGHT: f64 = 400.0;
const MARGIN: f64 = 60.0;
const COLOURS: [&str; 3] = ["#d62728", "#1f77b4", "#2ca02c"];

/// Per frame: (frame number, mean RelMSE, half-width of its 95 % interval).
type Series = Vec<(f64, f64, f64)>;

/// The SVG document: x = frame (log2 axis), y = RelMSE (log10 axis).
pub fn relmse_svg(errors: &[FrameError], methods: &[Method], frames: u32, title: &str) -> String {
    let series: Vec<(Method, Series)> = methods
        .iter()
        .map(|&m| {
            let points = (0..frames)
                .map(|f| {
                    let interval = relmse_over_seeds(errors, m, f);
                    let half = if interval.half_width.is_finite() { interval.half_width } else { 0.0 };
                    (f64::from(f + 1), interval.mean, half)
                })
                .collect();
            (m, points)
        })
        .collect();
    let values: Vec<f64> = series
        .iter()
        .flat_map(|(_, p)| p.iter().flat_map(|&(_, m, h)| [m + h, (m - h).max(m * 0.5)]))
        .filter(|v| *v > 0.0 && v.is_finite())
        .collect();
    let (low, high) = values.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &v| (lo.min(v), hi.max(v)));
    let (y0, y1) = if low.is_finite() && high > 0.0 { (low.log10().floor(), high.log10().ceil()) } else { (-3.0, 0.0) };
    let y1 = if y1 <= y0 { y0 + 1.0 } else { y1 };
    let x1 = f64::from(frames.max(2)).log2();
    let px = |frame: f64| MARGIN + frame.log2() / x1 * (WIDTH - 2.0 * MARGIN);
    let py = |value: f64| HEIGHT - MARGIN - (value.max(1e-30).log10() - y0) / (y1 - y0) * (HEIGHT - 2.0 * MARGIN);
    let mut svg = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{WIDTH}\" height=\"{HEIGHT}\" font-family=\"sans-serif\" \
         font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n<text x=\"{}\" y=\"20\" \
         text-anchor=\"middle\" font-size=\"14\">{}</text>\n",
        WIDTH / 2.0,
        escape(title)
    );
    // Axes, decades and powers of two.
    svg += &format!(
        "<line x1=\"{MARGIN}\" y1=\"{0}\" x2=\"{1}\" y2=\"{0}\" stroke=\"black\"/>\n<line x1=\"{MARGIN}\" y1=\"{MARGIN}\" \
         x2=\"{MARGIN}\" y2=\"{0}\" stroke=\"black\"/>\n",
        HEIGHT - MARGIN,
        WIDTH - MARGIN
    );
    let mut decade = y0;
    while decade <= y1 {
        let y = py(10f64.powf(decade));
        svg += &format!(
            "<line x1=\"{MARGIN}\" y1=\"{y:.1}\" x2=\"{:.1}\" y2=\"{y:.1}\" stroke=\"#ddd\"/>\n<text x=\"{:.1}\" \
             y=\"{:.1}\" text-anchor=\"end\">1e{decade}</text>\n",
            WIDTH - MARGIN,
            MARGIN - 6.0,
            y + 4.0
        );
        decade += 1.0;
    }
    let mut frame = 1u32;
    while frame <= frames.max(1) {
        let x = px(f64::from(frame));
        svg +=
            &format!("<text x=\"{x:.1}\" y=\"{:.1}\" text-anchor=\"middle\">{frame}</text>\n", HEIGHT - MARGIN + 16.0);
        frame *= 2;
    }
    svg += &format!(
        "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">frame</text>\n<text x=\"14\" y=\"{}\" \
         transform=\"rotate(-90 14 {})\" text-anchor=\"middle\">RelMSE (mean, 95% CI over seeds)</text>\n",
        WIDTH / 2.0,
        HEIGHT - 16.0,
        HEIGHT / 2.0,
        HEIGHT / 2.0
    );
    for (index, (method, points)) in series.iter().enumerate() {
        let colour = COLOURS[index % COLOURS.len()];
        let upper: Vec<String> = points.iter().map(|&(f, m, h)| format!("{:.1},{:.1}", px(f), py(m + h))).collect();
        let lower: Vec<String> =
            points.iter().rev().map(|&(f, m, h)| format!("{:.1},{:.1}", px(f), py((m - h).max(m * 0.5)))).collect();
        svg += &format!(
            "<polygon points=\"{} {}\" fill=\"{colour}\" fill-opacity=\"0.15\" stroke=\"none\"/>\n",
            upper.join(" "),
            lower.join(" ")
        );
        let line: Vec<String> = points.iter().map(|&(f, m, _)| format!("{:.1},{:.1}", px(f), py(m))).collect();
        svg += &format!(
            "<polyline points=\"{}\" fill=\"none\" stroke=\"{colour}\" stroke-width=\"2\"/>\n<text x=\"{:.1}\" \
             y=\"{:.1}\" fill=\"{colour}\">{}</text>\n",
            line.join(" "),
            WIDTH - MARGIN - 90.0,
            MARGIN + 16.0 * index as f64,
            method.name()
        );
    }
    svg + "</svg>\n"
}

fn escape(text: &str) -> String {
    text.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plot_has_a_line_per_method_and_escapes_the_title() {
        let errors: Vec<FrameError> = [Method::Strata, Method::Restir]
            .iter()
            .flat_map(|&method| {
                (0..4).flat_map(move |frame| {
                    (1..3).map(move |seed| FrameError {
                        method,
                        frame,
                        seed,
                        relmse: 0.1 / f64::from(frame + seed),
                        prelmse: 0.0,
                        mse: 0.0,
                        relmse_luminance: None,
                    })
                })
            })
            .collect();
        let svg = relmse_svg(&errors, &[Method::Strata, Method::Restir], 4, "a < b");
        assert_eq!(svg.matches("<polyline").count(), 2);
        assert!(svg.contains("a &lt; b") && svg.contains(">strata<") && svg.contains(">restir<"));
        assert!(!svg.contains("NaN") && !svg.contains("inf"));
    }
}
