//! The three plots `strata compare`, `strata plot` and the report page draw: RelMSE per
//! method, strata ÷ each baseline, and several runs overlaid.

use super::figure::{Figure, XAxis, YScale};
use super::output::{self, with_suffix};
use super::series::{Series, all_methods, baselines, frame_count, ratio_points, relmse_points};
use super::style::{Dash, method_colour, run_dash};
use crate::evaluation::compare::FrameError;
use anyhow::Result;
use std::path::{Path, PathBuf};
use strata_render::restir::Method;

/// The y axis of the RelMSE plots.
const RELMSE_AXIS: &str = "RelMSE (mean, 95 % CI over seeds)";
/// The y axis of the ratio plots.
const RATIO_AXIS: &str = "strata ÷ baseline";

/// The RelMSE figure of `methods` (in the fixed method order, each once; a method with
/// nothing to draw is left out).
pub(super) fn relmse_figure(errors: &[FrameError], methods: &[Method], frames: u32, title: &str) -> Figure {
    let series = all_methods()
        .iter()
        .filter(|m| methods.contains(m))
        .map(|&method| Series {
            label: method.name().to_string(),
            colour: method_colour(method),
            dash: Dash::SOLID,
            points: relmse_points(errors, method, frames),
        })
        .filter(|s| !s.points.is_empty())
        .collect();
    Figure {
        title: title.to_string(),
        y_desc: RELMSE_AXIS,
        y_scale: YScale::Log,
        x: XAxis::Frames(frames),
        series,
        reference: None,
    }
}

/// strata ÷ each baseline the errors pair with it, labelled `{prefix}strata ÷ {baseline}`.
fn ratio_series(errors: &[FrameError], frames: u32, prefix: &str, dash: Dash) -> Vec<Series> {
    baselines()
        .map(|baseline| Series {
            label: format!("{prefix}strata ÷ {}", baseline.name()),
            colour: method_colour(baseline),
            dash,
            points: ratio_points(errors, baseline, frames),
        })
        .filter(|s| !s.points.is_empty())
        .collect()
}

/// The ratio figure of `series`.
fn ratio_figure(series: Vec<Series>, frames: u32, title: &str) -> Figure {
    Figure {
        title: title.to_string(),
        y_desc: RATIO_AXIS,
        y_scale: YScale::Linear,
        x: XAxis::Frames(frames),
        series,
        reference: Some(1.0),
    }
}

/// RelMSE against frame (log-log axes: frame on log2, RelMSE on log10), one line per
/// method with its 95 % CI band over seeds ([`relmse_over_seeds`]); writes `{stem}.svg`
/// and `{stem}.png`. Methods keep their [`method_colour`] and a fixed legend order; a
/// method without rows is left out, a frame whose mean is not a positive number leaves a
/// gap, a frame with one seed has no band.
///
/// [`relmse_over_seeds`]: crate::evaluation::compare::relmse_over_seeds
pub fn write_relmse_plot(
    errors: &[FrameError],
    methods: &[Method],
    frames: u32,
    title: &str,
    stem: &Path,
) -> Result<()> {
    output::write(&relmse_figure(errors, methods, frames, title), stem).map(drop)
}

/// strata ÷ each baseline present (restir, restir-disc) against frame, per-seed paired
/// ratio mean with its 95 % CI band ([`relmse_ratio`]), a dashed line at 1, each line in
/// its baseline's colour; writes `{stem}.svg` and `{stem}.png`. `Ok(false)` and nothing
/// written when the errors hold no strata + baseline pair (or no finite ratio).
///
/// [`relmse_ratio`]: crate::evaluation::compare::relmse_ratio
pub fn write_ratio_plot(errors: &[FrameError], frames: u32, title: &str, stem: &Path) -> Result<bool> {
    let series = ratio_series(errors, frames, "", Dash::SOLID);
    if series.is_empty() {
        return Ok(false);
    }
    output::write(&ratio_figure(series, frames, title), stem)?;
    Ok(true)
}

/// Several runs (each a label and its parsed errors.csv) overlaid: methods keep their
/// colours, runs are told apart by line style (solid, dashed, dotted, dash-dot …) and
/// named in the legend as "label: method"; writes `{stem}_relmse.{svg,png}` and, when any
/// run has strata + a baseline, `{stem}_ratio.{svg,png}` (legend "label: strata ÷
/// baseline"). Returns the paths written. The frame axis covers the longest run.
pub fn write_overlay_plots(runs: &[(String, Vec<FrameError>)], title: &str, stem: &Path) -> Result<Vec<PathBuf>> {
    let frames = runs.iter().map(|(_, errors)| frame_count(errors)).max().unwrap_or(0);
    let mut relmse = Vec::new();
    let mut ratios = Vec::new();
    for (index, (label, errors)) in runs.iter().enumerate() {
        let dash = run_dash(index);
        let figure = relmse_figure(errors, all_methods(), frames, "");
        relmse.extend(figure.series.into_iter().map(|s| Series { label: format!("{label}: {}", s.label), dash, ..s }));
        ratios.extend(ratio_series(errors, frames, &format!("{label}: "), dash));
    }
    let figure = Figure { series: relmse, ..relmse_figure(&[], &[], frames, title) };
    let mut files = output::encode(&figure, &with_suffix(stem, "_relmse"))?;
    if !ratios.is_empty() {
        files.extend(output::encode(&ratio_figure(ratios, frames, title), &with_suffix(stem, "_ratio"))?);
    }
    output::write_files(&files)
}

/// [`write_relmse_plot`] at `stem` and [`write_ratio_plot`] at `ratio_stem`, written as
/// one set: all four files or none (a full disk or a refused name on the last leaves no
/// plot half-made). Returns the paths written.
pub fn write_relmse_and_ratio_plots(
    errors: &[FrameError],
    methods: &[Method],
    frames: u32,
    title: &str,
    stem: &Path,
    ratio_stem: &Path,
) -> Result<Vec<PathBuf>> {
    let mut files = output::encode(&relmse_figure(errors, methods, frames, title), stem)?;
    let series = ratio_series(errors, frames, "", Dash::SOLID);
    if !series.is_empty() {
        files.extend(output::encode(&ratio_figure(series, frames, title), ratio_stem)?);
    }
    output::write_files(&files)
}

/// The RelMSE plot of [`write_relmse_plot`] as an SVG document, for callers that write
/// the file themselves (`report.rs` until it calls [`write_relmse_plot`]). A drawing
/// error (only a font that does not load) gives an SVG that says so.
pub fn relmse_svg(errors: &[FrameError], methods: &[Method], frames: u32, title: &str) -> String {
    output::svg(&relmse_figure(errors, methods, frames, title)).unwrap_or_else(|e| {
        let message = e.to_string().replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;");
        format!("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"640\" height=\"80\"><text x=\"10\" y=\"40\">{message}</text></svg>\n")
    })
}
