//! Tests of the viewer's figures on synthetic curves: each method's lines in its colour
//! and named in the legend, a lag or bin without a measurement (NaN, none, not positive
//! on the log axis) left out as a gap instead of drawn, a stage without curves written
//! as nothing, and PNGs that decode.

use super::figure::XAxis;
use super::series::segments;
use super::viewer_plots::{correlation_figure, spectrum_figure};
use super::*;
use crate::evaluation::metrics::MeanInterval;
use crate::evaluation::viewer::{Stage, ViewerCurves};
use std::path::PathBuf;
use strata_render::restir::Method;

/// A measurement over 3 seeds.
fn value(mean: f64) -> Option<MeanInterval> {
    Some(MeanInterval { mean, half_width: 0.05, count: 3 })
}

/// Curves of `method` at `stage`: lags 1..=8 (inside a block up to 7, negative and
/// rising to 0; across an edge small and positive) and 8 spectrum bins (power rising
/// from `low` to 1).
fn curves(method: Method, stage: Stage, low: f64) -> ViewerCurves {
    ViewerCurves {
        method,
        stage,
        lags: (1..=8u32)
            .map(|k| {
                let inside = (k < 8).then(|| -0.2 / f64::from(k)).and_then(value);
                (k, inside, value(0.1 / f64::from(k)))
            })
            .collect(),
        spectrum: (0..8)
            .map(|i| ((f64::from(i) + 0.5) / 16.0, value(low + (1.0 - low) * f64::from(i) / 7.0)))
            .collect(),
    }
}

/// A new empty folder of a random name for one test's files (the test removes it).
fn folder(name: &str) -> PathBuf {
    strata_files::private_scratch_folder(&format!("strata-viewer-plot-{name}-")).unwrap().keep()
}

/// The texts of an SVG's `<text>` elements.
fn texts(svg: &str) -> Vec<String> {
    svg.split("<text")
        .skip(1)
        .filter_map(|rest| Some(rest.split_once('>')?.1.split("</text>").next()?.trim().to_string()))
        .collect()
}

/// How many `<polyline>`s of an SVG are drawn in `colour` with more than two points
/// (a data line; a legend sample has two).
fn lines_in(svg: &str, colour: &str) -> usize {
    svg.split("<polyline")
        .skip(1)
        .map(|rest| rest.split("/>").next().unwrap_or(""))
        .filter(|tag| tag.to_lowercase().contains(&format!("stroke=\"{}\"", colour.to_lowercase())))
        .filter(|tag| {
            tag.split("points=\"").nth(1).and_then(|p| p.split('"').next()).unwrap_or("").split_whitespace().count() > 2
        })
        .count()
}

#[test]
fn the_correlation_figure_names_each_method_and_leaves_gaps() {
    let dir = folder("correlation");
    let mut strata = curves(Method::Strata, Stage::Raw, 0.2);
    // Lag 4 measured as NaN inside a block, and not at all across an edge.
    strata.lags[3].1 = value(f64::NAN);
    strata.lags[3].2 = None;
    // restir-disc has nothing at all: left out, not drawn flat.
    let empty = ViewerCurves { method: Method::RestirDisc, stage: Stage::Raw, lags: vec![], spectrum: vec![] };
    let all = [curves(Method::Restir, Stage::Raw, 0.9), strata, empty, curves(Method::Strata, Stage::Denoised, 0.5)];

    let figure = correlation_figure(&all, Stage::Raw, "run").unwrap();
    let labels: Vec<&str> = figure.series.iter().map(|s| s.label.as_str()).collect();
    // The fixed method order, whatever the curves' order.
    assert_eq!(
        labels,
        ["strata, inside a block", "strata, across an edge", "restir, inside a block", "restir, across an edge"]
    );
    let XAxis::Linear { step, .. } = figure.x else { panic!("a lag axis: {:?}", figure.x) };
    let runs = |label: &str| {
        let series = figure.series.iter().find(|s| s.label == label).unwrap();
        assert!(series.points.iter().all(|p| p.mean.is_finite()), "{label}: {:?}", series.points);
        segments(&series.points, step).iter().map(|run| run.len()).collect::<Vec<_>>()
    };
    assert_eq!(runs("strata, inside a block"), [3, 3], "lags 1-3 and 5-7");
    assert_eq!(runs("strata, across an edge"), [3, 4], "lags 1-3 and 5-8");
    assert_eq!(runs("restir, inside a block"), [7]);

    assert!(write_correlation_plot(&all, Stage::Raw, "run", &dir.join("c")).unwrap());
    let svg = std::fs::read_to_string(dir.join("c.svg")).unwrap();
    let shown = texts(&svg);
    for text in labels.iter().copied().chain(["lag (pixels)", "error correlation (mean, 95 % CI over seeds)"]) {
        assert!(shown.iter().any(|t| t == text), "{text} missing: {shown:?}");
    }
    assert!(shown.iter().any(|t| t.starts_with("Error correlation between pixels, raw frames")), "{shown:?}");
    assert!(!shown.iter().any(|t| t.starts_with("restir-disc")), "{shown:?}");
    assert!(!svg.contains("NaN") && !svg.contains("inf"));
    // Each method's lines in its colour (strata's solid one in two pieces, the gap).
    assert!(lines_in(&svg, method_colour(Method::Restir)) >= 1, "{svg}");
    assert!(lines_in(&svg, method_colour(Method::Strata)) >= 2, "{svg}");
    assert_eq!(lines_in(&svg, method_colour(Method::RestirDisc)), 0, "{svg}");
    image::open(dir.join("c.png")).unwrap();
    // The denoised stage has strata alone; a stage without curves writes nothing.
    let denoised = correlation_figure(&all, Stage::Denoised, "").unwrap();
    assert_eq!(denoised.series.len(), 2);
    assert_eq!(denoised.title, "Error correlation between pixels, denoised frames");
    let raw_only = &all[..3];
    assert!(!write_correlation_plot(raw_only, Stage::Denoised, "run", &dir.join("none")).unwrap());
    assert!(!dir.join("none.svg").exists() && !dir.join("none.png").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_gap_is_not_drawn_over() {
    // One method, inside a block only, NaN at lag 4: two solid lines and two bands.
    let mut one = curves(Method::Restir, Stage::Raw, 0.5);
    for lag in &mut one.lags {
        lag.2 = None;
    }
    one.lags[3].1 = value(f64::NAN);
    let dir = folder("gap");
    assert!(write_correlation_plot(&[one], Stage::Raw, "", &dir.join("gap")).unwrap());
    let svg = std::fs::read_to_string(dir.join("gap.svg")).unwrap();
    assert_eq!(lines_in(&svg, method_colour(Method::Restir)), 2, "{svg}");
    assert_eq!(svg.matches("<polygon").count(), 2, "{svg}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_spectrum_figure_names_each_method_and_leaves_gaps() {
    let dir = folder("spectrum");
    let mut strata = curves(Method::Strata, Stage::Raw, 0.1);
    strata.spectrum[3].1 = value(f64::NAN);
    let mut restir = curves(Method::Restir, Stage::Raw, 0.9);
    // Not positive: cannot be drawn on the log axis.
    restir.spectrum[0].1 = value(0.0);
    let ris = ViewerCurves { method: Method::Ris, stage: Stage::Raw, lags: vec![], spectrum: vec![(0.1, None)] };
    let all = [strata, restir, ris];

    let figure = spectrum_figure(&all, Stage::Raw, "run").unwrap();
    let labels: Vec<&str> = figure.series.iter().map(|s| s.label.as_str()).collect();
    assert_eq!(labels, ["strata", "restir"]);
    let XAxis::Linear { step, low, high, .. } = figure.x else { panic!("a frequency axis: {:?}", figure.x) };
    assert_eq!((low, high), (0.0, 0.5));
    assert!((step - 1.0 / 16.0).abs() < 1e-12, "{step}");
    let runs = |index: usize| segments(&figure.series[index].points, step).iter().map(|r| r.len()).collect::<Vec<_>>();
    assert_eq!(runs(0), [3, 4], "bins 0-2 and 4-7");
    assert_eq!(runs(1), [7], "bins 1-7");
    assert_eq!(figure.reference, Some(1.0));

    assert!(write_spectrum_plot(&all, Stage::Raw, "run", &dir.join("s")).unwrap());
    let svg = std::fs::read_to_string(dir.join("s.svg")).unwrap();
    let shown = texts(&svg);
    for text in ["strata", "restir", "radial frequency (cycles per pixel)", "error power ÷ white noise (mean, 95 % CI)"]
    {
        assert!(shown.iter().any(|t| t == text), "{text} missing: {shown:?}");
    }
    assert!(!shown.iter().any(|t| t == "ris"), "{shown:?}");
    assert!(!svg.contains("NaN") && !svg.contains("inf"));
    assert_eq!(lines_in(&svg, method_colour(Method::Strata)), 2, "strata's gap at bin 3");
    assert_eq!(lines_in(&svg, method_colour(Method::Restir)), 1);
    image::open(dir.join("s.png")).unwrap();
    assert!(!write_spectrum_plot(&all, Stage::Denoised, "run", &dir.join("none")).unwrap());
    // Curves whose every bin is unmeasured: a figure that says "no data".
    let nothing = ViewerCurves { method: Method::Strata, stage: Stage::Raw, lags: vec![], spectrum: vec![(0.1, None)] };
    assert!(write_spectrum_plot(&[nothing], Stage::Raw, "", &dir.join("nothing")).unwrap());
    let svg = std::fs::read_to_string(dir.join("nothing.svg")).unwrap();
    assert!(texts(&svg).iter().any(|t| t == "no data"));
    std::fs::remove_dir_all(&dir).unwrap();
}
