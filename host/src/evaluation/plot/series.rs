//! The data of a plot: lines of (x, mean, 95 % band) made from `errors.csv` rows, one
//! per method (RelMSE over seeds) or per baseline (strata's paired ratio to it), or from
//! the viewer's curves (x a lag or a frequency). Points that cannot be drawn (no rows, a
//! mean that is NaN or infinite, or not positive on a log axis) are left out, and the
//! line has a gap there: lines join only points one step of the x axis apart.

use super::style::Dash;
use crate::evaluation::compare::{FrameError, by_frame, relmse_over_seeds, relmse_ratio};
use crate::evaluation::metrics::MeanInterval;
use strata_render::restir::Method;

/// One point of a line.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Point {
    /// Where along the x axis: the frame counted from 1, a lag in pixels, a frequency.
    pub x: f64,
    /// The mean over seeds.
    pub mean: f64,
    /// The 95 % interval (low, high); `None` with fewer than two seeds.
    pub band: Option<(f64, f64)>,
}

/// One line of a plot with its legend entry.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Series {
    /// The legend's text.
    pub label: String,
    /// CSS hex colour.
    pub colour: &'static str,
    /// Line style.
    pub dash: Dash,
    /// The drawable points, by x.
    pub points: Vec<Point>,
}

/// The methods in their fixed order (legend and drawing order never depend on the order
/// of the rows or of a method list).
pub(super) fn all_methods() -> &'static [Method] {
    <Method as clap::ValueEnum>::value_variants()
}

/// The baselines strata is compared with: every other method.
pub(super) fn baselines() -> impl Iterator<Item = Method> {
    all_methods().iter().copied().filter(|&m| m != Method::Strata)
}

/// Frames 1..=N that `errors` hold (N the largest frame; 0 for no rows).
pub(super) fn frame_count(errors: &[FrameError]) -> u32 {
    errors.iter().map(|e| e.frame.saturating_add(1)).max().unwrap_or(0)
}

/// `method`'s RelMSE over seeds at frames 1..=`frames`; only positive finite means.
/// Plots walk the frames the rows hold, each over its own rows ([`by_frame`]): the work
/// follows the rows, whatever the frame numbers.
pub(super) fn relmse_points(errors: &[FrameError], method: Method, frames: u32) -> Vec<Point> {
    by_frame(errors)
        .range(..frames)
        .filter_map(|(&f, rows)| point(frame_x(f), relmse_over_seeds(rows, method, f)).filter(|p| p.mean > 0.0))
        .collect()
}

/// strata ÷ `baseline`, paired per seed, at frames 1..=`frames`; only finite means.
pub(super) fn ratio_points(errors: &[FrameError], baseline: Method, frames: u32) -> Vec<Point> {
    by_frame(errors)
        .range(..frames)
        .filter_map(|(&f, rows)| point(frame_x(f), relmse_ratio(rows, Method::Strata, baseline, f)?))
        .collect()
}

/// Where 0-based `frame` lies on the frame axis (frames are counted from 1 there).
fn frame_x(frame: u32) -> f64 {
    f64::from(frame) + 1.0
}

/// The point at `x`, if its mean can be drawn; its band if the half-width is finite.
pub(super) fn point(x: f64, interval: MeanInterval) -> Option<Point> {
    (interval.count > 0 && interval.mean.is_finite()).then(|| Point {
        x,
        mean: interval.mean,
        band: interval
            .half_width
            .is_finite()
            .then_some((interval.mean - interval.half_width, interval.mean + interval.half_width)),
    })
}

/// The runs of consecutive points in `points`, neighbours `step` apart on the x axis (a
/// missing point, further on, splits the line; half a step of slack for rounding).
pub(super) fn segments(points: &[Point], step: f64) -> Vec<&[Point]> {
    points.chunk_by(|a, b| b.x - a.x <= 1.5 * step).collect()
}

/// The runs of consecutive points that all have a band.
pub(super) fn band_segments(points: &[Point], step: f64) -> Vec<&[Point]> {
    segments(points, step)
        .into_iter()
        .flat_map(|segment| segment.split(|p| p.band.is_none()))
        .filter(|run| !run.is_empty())
        .collect()
}
