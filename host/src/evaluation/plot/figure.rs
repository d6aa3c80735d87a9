//! One figure drawn on any plotters backend (the SVG and the PNG come from this same
//! code): title, the x axis (frames on log2 for the error-against-frame plots, or a
//! linear one for the viewer's lags and frequencies: one drawing code, so every figure of
//! the report looks alike), the y axis, light grid, each line's 95 % band under its line,
//! an optional dashed reference line, and the legend in a column right of the plot so
//! that it never hides a line.

use super::axis::Axis;
use super::series::{Point, Series, band_segments, segments};
use super::style::{Dash, dash_pieces, rgb};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// The size of a figure at scale 1, in pixels.
pub(super) const SIZE: (u32, u32) = (960, 540);

/// How the y axis maps values.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum YScale {
    /// log10 (RelMSE, power spectra).
    Log,
    /// Linear over values that cannot be negative (ratios): a band never stretches the
    /// axis below 0.
    Linear,
    /// Linear over values of either sign (correlations).
    LinearSigned,
}

/// What the x axis shows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum XAxis {
    /// Frames 1..=N on a log2 axis, described "frame"; a line joins consecutive frames.
    Frames(u32),
    /// `low..=high` on a linear axis described `desc`, ticks at least `least_tick` apart;
    /// a line joins points `step` apart (a lag in whole pixels, a frequency bin).
    Linear {
        /// The axis' description.
        desc: &'static str,
        /// The smallest value shown.
        low: f64,
        /// The largest value shown.
        high: f64,
        /// The distance of neighbouring points.
        step: f64,
        /// The least distance of two ticks (0: any round step).
        least_tick: f64,
    },
}

impl XAxis {
    /// The axis as plotters' coordinate.
    fn axis(&self) -> Axis {
        match *self {
            XAxis::Frames(frames) => Axis::frames(frames),
            XAxis::Linear { low, high, least_tick, .. } => Axis::linear_ticked(low, high, least_tick),
        }
    }

    /// The axis' description.
    fn desc(&self) -> &'static str {
        match *self {
            XAxis::Frames(_) => "frame",
            XAxis::Linear { desc, .. } => desc,
        }
    }

    /// The distance of neighbouring points (one frame on the frame axis).
    fn step(&self) -> f64 {
        match *self {
            XAxis::Frames(_) => 1.0,
            XAxis::Linear { step, .. } => step,
        }
    }
}

/// What one plot shows.
#[derive(Clone, Debug)]
pub(super) struct Figure {
    /// The title above the plot.
    pub title: String,
    /// The y axis' description.
    pub y_desc: &'static str,
    /// The y axis' scale.
    pub y_scale: YScale,
    /// The x axis.
    pub x: XAxis,
    /// The lines, drawn in order (the legend lists them in the same order).
    pub series: Vec<Series>,
    /// A horizontal dashed grey line at this value (1 for a ratio).
    pub reference: Option<f64>,
}

/// How far a band may stretch the axis beyond its mean: a factor on a log axis, a
/// distance on a linear one. A wider band (two seeds give very wide ones) is cut at the
/// plot's edge instead of squeezing every line into a corner.
const LOG_BAND_REACH: f64 = 4.0;
const LINEAR_BAND_REACH: f64 = 0.5;

impl Figure {
    /// The y axis that holds every mean, the reference line and the bands (within reach).
    pub fn y_axis(&self) -> Axis {
        let points = || self.series.iter().flat_map(|s| &s.points);
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        let mut take = |v: f64| {
            if v.is_finite() {
                lo = lo.min(v);
                hi = hi.max(v);
            }
        };
        for p in points() {
            take(p.mean);
            if let Some((low, high)) = p.band {
                match self.y_scale {
                    YScale::Log => {
                        take(low.max(p.mean / LOG_BAND_REACH));
                        take(high.min(p.mean * LOG_BAND_REACH));
                    }
                    YScale::Linear => {
                        take(low.max(p.mean - LINEAR_BAND_REACH).max(0.0));
                        take(high.min(p.mean + LINEAR_BAND_REACH));
                    }
                    YScale::LinearSigned => {
                        take(low.max(p.mean - LINEAR_BAND_REACH));
                        take(high.min(p.mean + LINEAR_BAND_REACH));
                    }
                }
            }
        }
        if let Some(value) = self.reference {
            take(value);
        }
        match self.y_scale {
            YScale::Log => Axis::log10(lo, hi),
            YScale::Linear | YScale::LinearSigned => Axis::linear(lo, hi),
        }
    }
}

/// `text` as a figure may draw it: every control character (C0, DEL, C1: line breaks
/// and tabs included) and every character XML forbids (U+FFFE, U+FFFF) replaced by
/// U+FFFD. plotters escapes `<`, `&` and quotes in an SVG, but writes control characters
/// as they are, and most of them make the document invalid XML. The command line refuses
/// such characters in the text it is given (`--title`, `--label`); this covers text
/// made from other input (a label from a folder name).
pub(super) fn drawable(text: &str) -> std::borrow::Cow<'_, str> {
    let refused = |c: char| c.is_control() || matches!(c, '\u{FFFE}' | '\u{FFFF}');
    if text.chars().any(refused) {
        text.chars().map(|c| if refused(c) { char::REPLACEMENT_CHARACTER } else { c }).collect::<String>().into()
    } else {
        text.into()
    }
}

/// Draws `figure` on `root` (the whole canvas), every length multiplied by `scale`.
pub(super) fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    figure: &Figure,
    scale: f64,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let px = |v: f64| (v * scale).round() as i32;
    let font = |size: f64| ("sans-serif", size * scale).into_font().color(&BLACK);
    root.fill(&WHITE)?;
    let (width, _) = root.dim_in_pixel();
    let title = font(22.0).pos(Pos::new(HPos::Center, VPos::Top));
    root.draw_text(&drawable(&figure.title), &title, (width as i32 / 2, px(12.0)))?;

    // The legend's column: as wide as its longest entry.
    let entry = font(15.0).pos(Pos::new(HPos::Left, VPos::Center));
    let shown: Vec<&Series> = figure.series.iter().filter(|s| !s.points.is_empty()).collect();
    let mut text_width = 0;
    for series in &shown {
        text_width = text_width.max(root.estimate_text_size(&drawable(&series.label), &entry)?.0 as i32);
    }
    // At most 45 % of the width: a longer label runs off the canvas, the plot stays.
    let legend_width = if shown.is_empty() { px(16.0) } else { (text_width + px(72.0)).min(width as i32 * 45 / 100) };
    let (plot_area, _) = root.split_horizontally(width as i32 - legend_width);

    let x_axis = figure.x.axis();
    let step = figure.x.step();
    let y_axis = figure.y_axis();
    // The y label area: the widest tick label, the tick, and the rotated description.
    let tick_label = font(14.0);
    let mut widest = 0;
    for tick in y_axis.ticks() {
        widest = widest.max(root.estimate_text_size(&y_axis.label(*tick), &tick_label)?.0 as i32);
    }
    let y_label_area = widest + px(10.0 + 20.0 + 8.0);
    let mut chart = ChartBuilder::on(&plot_area)
        .margin_top(px(52.0))
        .margin_left(px(12.0))
        .margin_right(px(8.0))
        .margin_bottom(px(10.0))
        .x_label_area_size(px(52.0))
        .y_label_area_size(y_label_area)
        .build_cartesian_2d(x_axis.clone(), y_axis.clone())?;
    let x_label = |v: &f64| x_axis.label(*v);
    let y_label = |v: &f64| y_axis.label(*v);
    chart
        .configure_mesh()
        .x_desc(figure.x.desc())
        .y_desc(figure.y_desc)
        .x_label_formatter(&x_label)
        .y_label_formatter(&y_label)
        .label_style(tick_label.clone())
        .axis_desc_style(font(16.0))
        .bold_line_style(BLACK.mix(0.14).stroke_width(px(1.0).max(1) as u32))
        .light_line_style(BLACK.mix(0.06).stroke_width(px(1.0).max(1) as u32))
        .axis_style(BLACK.mix(0.8).stroke_width(px(1.0).max(1) as u32))
        .set_all_tick_mark_size(px(5.0))
        .draw()?;

    let at = |x: f64, value: f64| -> (f64, f64) {
        let (x, y) = chart.backend_coord(&(x, y_axis.clamp(value)));
        (f64::from(x), f64::from(y))
    };
    let line_style = |colour: &str, width: f64| rgb(colour).stroke_width(px(width).max(1) as u32);
    let stroke = |points: &[(f64, f64)], dash: Dash, style: ShapeStyle| -> Result<(), DrawingAreaErrorKind<_>> {
        for piece in dash_pieces(points, dash, scale) {
            let piece: Vec<(i32, i32)> = piece.iter().map(|&(x, y)| (x.round() as i32, y.round() as i32)).collect();
            root.draw(&PathElement::new(piece, style))?;
        }
        Ok(())
    };

    // Bands first, then the reference and the lines over them.
    for series in &shown {
        let fill = rgb(series.colour).mix(0.16).filled();
        for run in band_segments(&series.points, step) {
            let band = |p: &Point| p.band.unwrap_or((p.mean, p.mean));
            let mut outline: Vec<(i32, i32)> = Vec::new();
            let points = run.iter().map(|p| at(p.x, band(p).1)).chain(run.iter().rev().map(|p| at(p.x, band(p).0)));
            outline.extend(points.map(|(x, y)| (x.round() as i32, y.round() as i32)));
            if run.len() == 1 {
                // One point: its interval as an error bar.
                let (x, _) = outline[0];
                root.draw(&PathElement::new(
                    vec![(x, outline[0].1), (x, outline[1].1)],
                    fill.stroke_width(px(6.0) as u32),
                ))?;
            } else {
                root.draw(&Polygon::new(outline, fill))?;
            }
        }
    }
    if let Some(value) = figure.reference {
        let (low, high) = x_axis.bounds();
        let ends = [at(low, value), at(high, value)];
        stroke(&ends, Dash::DASHED, BLACK.mix(0.55).stroke_width(px(1.5).max(1) as u32))?;
    }
    for series in &shown {
        for segment in segments(&series.points, step) {
            let points: Vec<(f64, f64)> = segment.iter().map(|p| at(p.x, p.mean)).collect();
            if let [(x, y)] = points[..] {
                root.draw(&Circle::new((x.round() as i32, y.round() as i32), px(3.5), rgb(series.colour).filled()))?;
            } else {
                stroke(&points, series.dash, line_style(series.colour, 2.0))?;
            }
        }
    }
    if shown.is_empty() {
        let (x, y) = chart.plotting_area().get_pixel_range();
        let centre = ((x.start + x.end) / 2, (y.start + y.end) / 2);
        root.draw_text("no data", &font(18.0).pos(Pos::new(HPos::Center, VPos::Center)), centre)?;
    }

    // The legend: a band swatch, a line sample in the series' style, the label.
    let left = f64::from(width as i32 - legend_width + px(12.0));
    for (index, series) in shown.iter().enumerate() {
        let y = f64::from(px(52.0 + 12.0 + 26.0 * index as f64));
        let (x0, x1) = (left, left + 40.0 * scale);
        if series.points.iter().any(|p| p.band.is_some()) {
            let corner = |x: f64, dy: f64| (x.round() as i32, (y + dy * scale).round() as i32);
            root.draw(&Rectangle::new([corner(x0, -7.0), corner(x1, 7.0)], rgb(series.colour).mix(0.16).filled()))?;
        }
        stroke(&[(x0, y), (x1, y)], series.dash, line_style(series.colour, 2.0))?;
        root.draw_text(&drawable(&series.label), &entry, ((x1 + 8.0 * scale).round() as i32, y.round() as i32))?;
    }
    Ok(())
}
