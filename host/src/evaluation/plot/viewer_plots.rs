//! The figures of "what the viewer sees" (issue 55). The viewer's table gives one number
//! per kind of correlation (lag 1) and one for the spectrum (low ÷ high), but a spatial
//! filter acts over its whole footprint and a block grid shows at every lag, so the page
//! shows the curves those numbers come from, one figure of each per stage (raw frames,
//! and denoised ones when the run has a denoiser):
//!
//! * [`write_correlation_plot`]: per method, the correlation of the error between pixels
//!   k apart inside one selection block (solid) and across a block edge (dashed) against
//!   k, with a line at 0. Below 0 inside a block: negatively correlated errors, which a
//!   spatial filter averages away; the two lines apart: the block grid shows.
//! * [`write_spectrum_plot`]: per method, the error's power against radial frequency ÷
//!   white noise's, on log10 (a blue spectrum's low end lies decades below 1), with a
//!   line at 1. Below 1 at low frequencies: blue-noise-like error, which a blur removes.
//!
//! Methods keep their colour and the fixed legend order of the other plots; a lag or a
//! bin without a measurement (no pair of pixels of that kind, NaN) is left out and its
//! line has a gap there.

use super::figure::{Figure, XAxis, YScale};
use super::output;
use super::series::{Point, Series, all_methods, point};
use super::style::{Dash, method_colour};
use crate::evaluation::metrics::MeanInterval;
use crate::evaluation::viewer::{Stage, ViewerCurves};
use anyhow::Result;
use std::path::Path;

/// The y axis of the correlation figure.
const CORRELATION_AXIS: &str = "error correlation (mean, 95 % CI over seeds)";
/// The x axis of the correlation figure.
const LAG_AXIS: &str = "lag (pixels)";
/// The y axis of the spectrum figure.
const SPECTRUM_AXIS: &str = "error power ÷ white noise (mean, 95 % CI)";
/// The x axis of the spectrum figure.
const FREQUENCY_AXIS: &str = "radial frequency (cycles per pixel)";
/// The highest radial frequency of a pixel grid (Nyquist), cycles per pixel.
const NYQUIST: f64 = 0.5;

/// The curves of `stage`, in the fixed method order, each method once.
fn of_stage(curves: &[ViewerCurves], stage: Stage) -> Vec<&ViewerCurves> {
    all_methods().iter().filter_map(|&m| curves.iter().find(|c| c.method == m && c.stage == stage)).collect()
}

/// The drawable points of (x, measurement) pairs, in x order as given; a pair without a
/// measurement, or with a NaN or infinite x or mean, is left out (a gap).
fn points(values: impl Iterator<Item = (f64, Option<MeanInterval>)>) -> Vec<Point> {
    values.filter(|(x, _)| x.is_finite()).filter_map(|(x, value)| point(x, value?)).collect()
}

/// `what` of `stage`'s frames, then the run's `title` if there is one.
fn titled(what: &str, stage: Stage, title: &str) -> String {
    let head = format!("{what}, {} frames", stage.name());
    if title.is_empty() { head } else { format!("{head}: {title}") }
}

/// The correlation figure of `stage` (see the module documentation); `None` when no
/// method has curves of that stage.
pub(super) fn correlation_figure(curves: &[ViewerCurves], stage: Stage, title: &str) -> Option<Figure> {
    let chosen = of_stage(curves, stage);
    if chosen.is_empty() {
        return None;
    }
    let mut series = Vec::new();
    for curve in &chosen {
        let name = curve.method.name();
        let inside = points(curve.lags.iter().map(|&(lag, inside, _)| (f64::from(lag), inside)));
        let across = points(curve.lags.iter().map(|&(lag, _, across)| (f64::from(lag), across)));
        for (kind, dash, points) in [("inside a block", Dash::SOLID, inside), ("across an edge", Dash::DASHED, across)]
        {
            let colour = method_colour(curve.method);
            series.push(Series { label: format!("{name}, {kind}"), colour, dash, points });
        }
    }
    series.retain(|s| !s.points.is_empty());
    let longest = chosen.iter().flat_map(|c| &c.lags).map(|l| l.0).max().unwrap_or(1);
    Some(Figure {
        title: titled("Error correlation between pixels", stage, title),
        y_desc: CORRELATION_AXIS,
        y_scale: YScale::LinearSigned,
        x: XAxis::Linear { desc: LAG_AXIS, low: 1.0, high: f64::from(longest.max(2)), step: 1.0, least_tick: 1.0 },
        series,
        reference: Some(0.0),
    })
}

/// The spectrum figure of `stage` (see the module documentation); `None` when no method
/// has curves of that stage.
pub(super) fn spectrum_figure(curves: &[ViewerCurves], stage: Stage, title: &str) -> Option<Figure> {
    let chosen = of_stage(curves, stage);
    if chosen.is_empty() {
        return None;
    }
    let series = chosen
        .iter()
        .map(|curve| Series {
            label: curve.method.name().to_string(),
            colour: method_colour(curve.method),
            dash: Dash::SOLID,
            // Only positive powers on the log axis.
            points: points(curve.spectrum.iter().copied()).into_iter().filter(|p| p.mean > 0.0).collect(),
        })
        .filter(|s| !s.points.is_empty())
        .collect();
    // Neighbouring bins are a bin width apart: the smallest spacing of two centres.
    let step = chosen
        .iter()
        .flat_map(|c| c.spectrum.windows(2).map(|pair| pair[1].0 - pair[0].0))
        .filter(|d| d.is_finite() && *d > 0.0)
        .min_by(f64::total_cmp)
        .unwrap_or(NYQUIST);
    Some(Figure {
        title: titled("Error power spectrum", stage, title),
        y_desc: SPECTRUM_AXIS,
        y_scale: YScale::Log,
        x: XAxis::Linear { desc: FREQUENCY_AXIS, low: 0.0, high: NYQUIST, step, least_tick: 0.0 },
        series,
        reference: Some(1.0),
    })
}

/// The correlation of the error between pixels against the lag in pixels, for `stage`'s
/// frames: per method (in its [`method_colour`]) inside one selection block (solid) and
/// across a block edge (dashed), mean and 95 % band over seeds, a dashed line at 0;
/// writes `{stem}.svg` and `{stem}.png`, both or neither. `Ok(false)` and nothing written
/// when `curves` hold no method at that stage. A lag without a measurement leaves a gap.
pub fn write_correlation_plot(curves: &[ViewerCurves], stage: Stage, title: &str, stem: &Path) -> Result<bool> {
    let Some(figure) = correlation_figure(curves, stage, title) else { return Ok(false) };
    output::write(&figure, stem)?;
    Ok(true)
}

/// The error's radial power spectrum ÷ white noise's (log10) against frequency (0 to ½
/// cycle per pixel, linear), for `stage`'s frames: one line per method in its
/// [`method_colour`], mean and 95 % band over seeds, a dashed line at 1 (white noise);
/// writes `{stem}.svg` and `{stem}.png`, both or neither. `Ok(false)` and nothing written
/// when `curves` hold no method at that stage. A bin without a positive measurement
/// leaves a gap.
pub fn write_spectrum_plot(curves: &[ViewerCurves], stage: Stage, title: &str, stem: &Path) -> Result<bool> {
    let Some(figure) = spectrum_figure(curves, stage, title) else { return Ok(false) };
    output::write(&figure, stem)?;
    Ok(true)
}
