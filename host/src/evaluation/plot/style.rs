//! How a line looks: each method's fixed colour (the same in every plot and in the HTML
//! report, so strata is never green in one figure and red in the next) and the dash
//! patterns that tell overlaid runs apart.

use plotters::style::RGBColor;
use strata_render::restir::Method;

/// One colour per method, the same in every plot and in the HTML report (CSS hex, e.g.
/// "#1f77b4"). From the Okabe–Ito palette, which stays distinguishable under the common
/// colour-vision deficiencies: strata vermillion, restir blue, restir-disc bluish green,
/// ris reddish purple.
pub fn method_colour(method: Method) -> &'static str {
    match method {
        Method::Strata => "#d55e00",
        Method::Restir => "#0072b2",
        Method::RestirDisc => "#009e73",
        Method::Ris => "#cc79a7",
    }
}

/// A CSS hex colour (`#rrggbb`) as plotters' colour; anything else is black.
pub(super) fn rgb(hex: &str) -> RGBColor {
    let channel = |i: usize| hex.get(i..i + 2).and_then(|c| u8::from_str_radix(c, 16).ok());
    match (hex.len(), hex.starts_with('#'), channel(1), channel(3), channel(5)) {
        (7, true, Some(r), Some(g), Some(b)) => RGBColor(r, g, b),
        _ => RGBColor(0, 0, 0),
    }
}

/// A line's dash pattern: alternating drawn and skipped lengths in pixels (before the
/// figure's scale), empty for a solid line.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Dash(pub &'static [f64]);

impl Dash {
    /// A solid line.
    pub const SOLID: Dash = Dash(&[]);
    /// Dashes.
    pub const DASHED: Dash = Dash(&[9.0, 5.0]);
}

/// The line styles of overlaid runs, in run order (repeating after the last): solid,
/// dashed, dotted, dash-dot, long dashes, dash-dot-dot.
const RUN_DASHES: [Dash; 6] = [
    Dash::SOLID,
    Dash::DASHED,
    Dash(&[2.0, 4.0]),
    Dash(&[10.0, 4.0, 2.0, 4.0]),
    Dash(&[18.0, 6.0]),
    Dash(&[10.0, 4.0, 2.0, 4.0, 2.0, 4.0]),
];

/// The line style of the `index`-th overlaid run.
pub(super) fn run_dash(index: usize) -> Dash {
    RUN_DASHES[index % RUN_DASHES.len()]
}

/// The pieces of the polyline `points` that a dash pattern draws (the whole line when
/// the pattern is solid); lengths are multiplied by `scale`. Pieces keep the polyline's
/// corners, so a dash bends with the line.
pub(super) fn dash_pieces(points: &[(f64, f64)], dash: Dash, scale: f64) -> Vec<Vec<(f64, f64)>> {
    let pattern: Vec<f64> = dash.0.iter().map(|l| l * scale).collect();
    if pattern.is_empty() || pattern.iter().any(|l| l.is_nan() || *l <= 0.0) {
        return vec![points.to_vec()];
    }
    let mut pieces = Vec::new();
    let (mut index, mut left) = (0, pattern[0]);
    let mut current: Vec<(f64, f64)> = points.first().map(|&p| vec![p]).unwrap_or_default();
    for pair in points.windows(2) {
        let ((x0, y0), (x1, y1)) = (pair[0], pair[1]);
        let length = (x1 - x0).hypot(y1 - y0);
        let mut done = 0.0;
        while length - done > left {
            done += left;
            let t = done / length;
            let at = (x0 + (x1 - x0) * t, y0 + (y1 - y0) * t);
            if index % 2 == 0 {
                current.push(at);
                pieces.push(std::mem::take(&mut current));
            } else {
                current = vec![at];
            }
            index = (index + 1) % pattern.len();
            left = pattern[index];
        }
        left -= length - done;
        if index % 2 == 0 {
            current.push((x1, y1));
        }
    }
    if index % 2 == 0 && current.len() > 1 {
        pieces.push(current);
    }
    pieces
}
