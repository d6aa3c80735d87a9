//! The plots' axes as one plotters coordinate: frame on a log2 axis labelled at powers of
//! two, RelMSE on a log10 axis labelled at 1-2-5 steps (decades over a wide range), a
//! ratio, a lag or a frequency on a linear axis at round steps. plotters' own log axis labels arbitrary
//! intermediate values and knows no base 2, so the ticks are chosen here.

use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint, Ranged};
use std::ops::Range;

/// How data values map along an axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Scale {
    /// log2 (frames).
    Log2,
    /// log10 (errors).
    Log10,
    /// Linear (ratios, correlations, lags, frequencies).
    Linear,
}

/// One axis: its range in data units, the labelled ticks and the light grid lines.
#[derive(Clone, Debug)]
pub(super) struct Axis {
    scale: Scale,
    start: f64,
    end: f64,
    ticks: Vec<f64>,
    grid: Vec<f64>,
    /// Decimals of the linear axis' labels.
    decimals: usize,
}

impl Axis {
    /// Frames 1..=`frames` on a log2 axis (at least 1..=2), ticks at powers of two.
    pub fn frames(frames: u32) -> Axis {
        let end = f64::from(frames.max(2));
        let top = end.log2().floor() as i32;
        let step = (top / 10 + 1) as usize;
        let ticks: Vec<f64> = (0..=top).step_by(step).map(|e| 2f64.powi(e)).collect();
        Axis { scale: Scale::Log2, start: 1.0, end, grid: ticks.clone(), ticks, decimals: 0 }
    }

    /// A log10 axis just around `low..high` (both positive), ticks at round linear steps
    /// when the range is within a decade, at 1, 2 and 5 times powers of ten up to three
    /// decades, at decades beyond.
    pub fn log10(low: f64, high: f64) -> Axis {
        let (mut lo, mut hi) = (low.log10(), high.log10());
        if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
            (lo, hi) = (-3.0, 0.0);
        }
        if hi - lo < 0.3 {
            let middle = (hi + lo) / 2.0;
            (lo, hi) = (middle - 0.15, middle + 0.15);
        }
        let pad = (hi - lo) * 0.05;
        let (lo, hi) = (lo - pad, hi + pad);
        let (start, end) = (10f64.powf(lo), 10f64.powf(hi));
        let decades = (lo.floor() as i32)..=(hi.ceil() as i32);
        let span = hi - lo;
        let decade_step = (span / 8.0).ceil().max(1.0) as usize;
        let inside = |v: &f64| *v >= start && *v <= end;
        if span < 1.0 {
            // Within a decade, round linear steps (0.010, 0.012, …) read best.
            let step = nice_step((end - start) / 6.0);
            let ticks = multiples(start, end, step);
            let decimals = (-step.log10().floor()).max(0.0) as usize;
            return Axis { scale: Scale::Log10, start, end, grid: multiples(start, end, step / 2.0), ticks, decimals };
        }
        let (ticks, grid): (Vec<f64>, Vec<f64>) = if span > 3.0 {
            let ticks: Vec<f64> = decades.clone().step_by(decade_step).map(|e| 10f64.powi(e)).filter(inside).collect();
            let grid = if span > 6.0 {
                ticks.clone()
            } else {
                decades.flat_map(|e| (1..10).map(move |m| f64::from(m) * 10f64.powi(e))).filter(inside).collect()
            };
            (ticks, grid)
        } else {
            let grid = decades
                .clone()
                .flat_map(|e| (1..10).map(move |m| f64::from(m) * 10f64.powi(e)))
                .filter(inside)
                .collect();
            let ticks = decades.flat_map(|e| [1.0, 2.0, 5.0].map(|m| m * 10f64.powi(e))).filter(inside).collect();
            (ticks, grid)
        };
        Axis { scale: Scale::Log10, start, end, ticks, grid, decimals: 0 }
    }

    /// A linear axis just around `low..high`, ticks at round steps.
    pub fn linear(low: f64, high: f64) -> Axis {
        Axis::linear_ticked(low, high, 0.0)
    }

    /// [`Axis::linear`] with ticks at least `least` apart (1 for a lag in whole pixels,
    /// which a half-pixel tick would misstate).
    pub fn linear_ticked(low: f64, high: f64, least: f64) -> Axis {
        let (mut lo, mut hi) = (low, high);
        if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
            (lo, hi) = (0.0, 1.0);
        }
        if hi - lo < 1e-6 * hi.abs().max(1.0) {
            (lo, hi) = (lo - 0.05 * lo.abs().max(1.0), hi + 0.05 * hi.abs().max(1.0));
        }
        let pad = (hi - lo) * 0.05;
        let (start, end) = (lo - pad, hi + pad);
        let step = nice_step((end - start) / 6.0).max(least);
        let decimals = (-step.log10().floor()).max(0.0) as usize;
        Axis {
            scale: Scale::Linear,
            start,
            end,
            grid: multiples(start, end, step / 2.0),
            ticks: multiples(start, end, step),
            decimals,
        }
    }

    /// `value` moved into the axis' range (a non-positive value to the start of a log
    /// axis, NaN to the start).
    pub fn clamp(&self, value: f64) -> f64 {
        if value.is_nan() { self.start } else { value.clamp(self.start, self.end) }
    }

    /// The labelled ticks.
    pub fn ticks(&self) -> &[f64] {
        &self.ticks
    }

    /// The axis' range in data units.
    pub fn bounds(&self) -> (f64, f64) {
        (self.start, self.end)
    }

    /// The label of the tick at `value`.
    pub fn label(&self, value: f64) -> String {
        match self.scale {
            Scale::Log2 => format!("{}", value.round()),
            Scale::Log10 if self.decimals > 0 => fixed(value, self.decimals),
            Scale::Log10 => number(value),
            Scale::Linear => format!("{value:.*}", self.decimals),
        }
    }

    /// Where `value` lies along the axis, 0 at the start and 1 at the end.
    fn fraction(&self, value: f64) -> f64 {
        let value = self.clamp(value);
        let t = |v: f64| match self.scale {
            Scale::Log2 => v.log2(),
            Scale::Log10 => v.log10(),
            Scale::Linear => v,
        };
        let span = t(self.end) - t(self.start);
        if span > 0.0 { (t(value) - t(self.start)) / span } else { 0.0 }
    }
}

impl Ranged for Axis {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        limit.0 + (self.fraction(*value) * f64::from(limit.1 - limit.0)).round() as i32
    }

    fn key_points<Hint: KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        if hint.weight().allow_light_points() { self.grid.clone() } else { self.ticks.clone() }
    }

    fn range(&self) -> Range<f64> {
        self.start..self.end
    }
}

/// 1, 2 or 5 times a power of ten, the nearest to `rough` (by ratio).
fn nice_step(rough: f64) -> f64 {
    if !(rough > 0.0 && rough.is_finite()) {
        return 1.0;
    }
    let power = 10f64.powf(rough.log10().floor());
    let distance = |s: f64| (s / rough).ln().abs();
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * power)
        .min_by(|a, b| distance(*a).total_cmp(&distance(*b)))
        .unwrap_or(power)
}

/// The multiples of `step` in `start..=end`.
fn multiples(start: f64, end: f64, step: f64) -> Vec<f64> {
    let (first, last) = ((start / step).ceil() as i64, (end / step).floor() as i64);
    (first..=last).map(|i| i as f64 * step).collect()
}

/// A positive tick `value` on a grid of `decimals` decimals: plain from 0.001 up, else
/// in scientific notation with as many significant digits (`1.2e-5`).
fn fixed(value: f64, decimals: usize) -> String {
    let exponent = value.log10().floor();
    if exponent >= -3.0 {
        format!("{value:.decimals$}")
    } else {
        format!("{value:.*e}", (decimals as f64 + exponent).max(0.0) as usize)
    }
}

/// A positive tick value as short text: plain decimals from 0.0001 to 9999, else `2e-5`.
fn number(value: f64) -> String {
    let exponent = value.log10().floor();
    if (-4.0..4.0).contains(&exponent) {
        format!("{value:.*}", (-exponent).max(0.0) as usize)
    } else {
        let mantissa = value / 10f64.powf(exponent);
        format!("{}e{}", mantissa.round(), exponent)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_are_round_and_inside_the_range() {
        let frames = Axis::frames(32);
        assert_eq!(frames.ticks, [1.0, 2.0, 4.0, 8.0, 16.0, 32.0]);
        assert_eq!(Axis::frames(1).ticks, [1.0, 2.0]);
        let log = Axis::log10(0.011, 0.019);
        assert!(log.ticks.iter().all(|t| *t >= log.start && *t <= log.end) && !log.ticks.is_empty());
        let decade = Axis::log10(0.0085, 0.0195);
        assert_eq!(
            decade.ticks.iter().map(|&t| decade.label(t)).collect::<Vec<_>>(),
            ["0.010", "0.012", "0.014", "0.016", "0.018", "0.020"]
        );
        let tiny = Axis::log10(1.1e-5, 1.9e-5);
        assert_eq!(tiny.label(tiny.ticks[1]), "1.2e-5");
        let three = Axis::log10(0.008, 0.3);
        assert_eq!(
            three.ticks.iter().map(|&t| three.label(t)).collect::<Vec<_>>(),
            ["0.01", "0.02", "0.05", "0.1", "0.2"]
        );
        let wide = Axis::log10(1e-9, 1.0);
        assert!(wide.ticks.len() <= 10, "{:?}", wide.ticks);
        assert_eq!(
            (wide.label(1e-6), wide.label(5e-4), wide.label(0.01)),
            ("1e-6".into(), "0.0005".into(), "0.01".into())
        );
        let linear = Axis::linear(0.8, 1.0);
        assert_eq!(linear.label(0.85), "0.85");
        assert!(linear.ticks.contains(&1.0) || linear.ticks.iter().any(|t| (t - 1.0).abs() < 1e-9));
        // Odd ranges fall back instead of panicking.
        for axis in [Axis::log10(0.0, 1.0), Axis::log10(f64::NAN, 1.0), Axis::linear(f64::INFINITY, 0.0)] {
            assert!(axis.start < axis.end && axis.start.is_finite() && axis.end.is_finite());
            assert_eq!(axis.map(&f64::NAN, (0, 100)), 0);
        }
    }

    #[test]
    fn a_lag_axis_ticks_whole_pixels() {
        // Lags 1..=4 alone would tick every half pixel; at least 1 apart, whole ones.
        assert_eq!(Axis::linear(1.0, 4.0).label(1.5), "1.5");
        let lags = Axis::linear_ticked(1.0, 4.0, 1.0);
        assert_eq!(lags.ticks.iter().map(|&t| lags.label(t)).collect::<Vec<_>>(), ["1", "2", "3", "4"]);
        // A wide range keeps its own round step.
        assert_eq!(Axis::linear_ticked(1.0, 64.0, 1.0).ticks[..2], [0.0, 10.0]);
    }
}
