//! Tests of the plots: fixed colours, one line per method, the ratio plot's conditions,
//! the overlay's files, PNGs that decode and show text, odd data that draws anyway.

use super::figure::SIZE;
use super::plots::relmse_figure;
use super::style::{Dash, dash_pieces};
use super::*;
use crate::evaluation::compare::FrameError;
use std::path::{Path, PathBuf};
use strata_render::restir::Method;

/// Rows of `methods` at frames 0..frames and seeds 1..=seeds, RelMSE falling with frame.
fn rows(methods: &[Method], frames: u32, seeds: u32) -> Vec<FrameError> {
    let mut errors = Vec::new();
    for (index, &method) in methods.iter().enumerate() {
        for frame in 0..frames {
            for seed in 1..=seeds {
                errors.push(FrameError {
                    method,
                    frame,
                    seed,
                    relmse: (0.1 + 0.02 * index as f64 + 0.001 * f64::from(seed)) / f64::from(frame + 1),
                    prelmse: 0.0,
                    mse: 0.0,
                    relmse_luminance: None,
                    flip: None,
                    block_edge: None,
                });
            }
        }
    }
    errors
}

/// A new empty folder of a random name for one test's files (the test removes it).
fn folder(name: &str) -> PathBuf {
    strata_files::private_scratch_folder(&format!("strata-plot-{name}-")).unwrap().keep()
}

/// Each `<polyline>` of an SVG: its stroke colour (lower case) and number of points.
fn polylines(svg: &str) -> Vec<(String, usize)> {
    let attribute = |tag: &str, name: &str| -> String {
        let start = tag.find(&format!("{name}=\"")).map(|i| i + name.len() + 2).unwrap_or(0);
        tag[start..].split('"').next().unwrap_or("").to_string()
    };
    svg.split("<polyline")
        .skip(1)
        .map(|rest| {
            let tag = rest.split("/>").next().unwrap_or("");
            (attribute(tag, "stroke").to_lowercase(), attribute(tag, "points").split_whitespace().count())
        })
        .collect()
}

/// The texts of an SVG's `<text>` elements.
fn texts(svg: &str) -> Vec<String> {
    svg.split("<text")
        .skip(1)
        .filter_map(|rest| Some(rest.split_once('>')?.1.split("</text>").next()?.trim().to_string()))
        .collect()
}

/// Whether an SVG has a `<text>` element reading `text` (escaped as in XML).
fn has_text(svg: &str, text: &str) -> bool {
    texts(svg).iter().any(|t| t == text)
}

/// The data lines of an SVG (more points than a legend sample's two), by colour.
fn data_lines(svg: &str) -> Vec<String> {
    polylines(svg).into_iter().filter(|(_, n)| *n > 2).map(|(colour, _)| colour).collect()
}

/// How many pixels of `image` within `rows` are dark (text or lines).
fn dark_pixels(image: &image::RgbImage, rows: std::ops::Range<u32>) -> usize {
    rows.flat_map(|y| (0..image.width()).map(move |x| (x, y)))
        .filter(|&(x, y)| image.get_pixel(x, y).0.iter().all(|&c| c < 100))
        .count()
}

#[test]
fn every_method_has_one_colour_whatever_the_order() {
    let methods = [Method::Strata, Method::Restir, Method::RestirDisc];
    let colours: Vec<&str> = methods.iter().map(|&m| method_colour(m)).collect();
    assert!(colours.iter().all(|c| c.len() == 7 && c.starts_with('#')), "{colours:?}");
    assert!(colours[0] != colours[1] && colours[1] != colours[2] && colours[0] != colours[2]);
    let errors = rows(&methods, 4, 2);
    // Each line's colour is its method's, whatever the order or the subset asked for.
    for asked in [
        &methods[..],
        &[Method::RestirDisc, Method::Restir, Method::Strata],
        &[Method::RestirDisc],
        &[Method::Restir, Method::Strata],
    ] {
        let figure = relmse_figure(&errors, asked, 4, "t");
        assert_eq!(figure.series.len(), asked.len());
        for series in &figure.series {
            let method = methods.iter().find(|m| m.name() == series.label).unwrap();
            assert_eq!(series.colour, method_colour(*method), "{} when asked for {asked:?}", series.label);
        }
        // The SVG draws those colours: one line each.
        let mut drawn = data_lines(&relmse_svg(&errors, asked, 4, "t"));
        let mut expected: Vec<String> = asked.iter().map(|&m| method_colour(m).to_lowercase()).collect();
        drawn.sort();
        expected.sort();
        assert_eq!(drawn, expected);
    }
}

#[test]
fn the_svg_has_a_line_and_a_band_per_method_and_labelled_axes() {
    let errors = rows(&[Method::Strata, Method::Restir], 4, 3);
    let svg = relmse_svg(&errors, &[Method::Strata, Method::Restir], 4, "a < b");
    assert_eq!(data_lines(&svg).len(), 2, "{svg}");
    assert_eq!(svg.matches("<polygon").count(), 2, "one band per method: {svg}");
    for text in ["a &lt; b", "strata", "restir", "frame", "RelMSE (mean, 95 % CI over seeds)"] {
        assert!(has_text(&svg, text), "{text} missing: {:?}", texts(&svg));
    }
    assert!(!svg.contains("NaN") && !svg.contains("inf"));
    // A method asked for without rows is left out, not drawn flat.
    let svg = relmse_svg(&errors, &[Method::Strata, Method::RestirDisc], 4, "t");
    assert_eq!(data_lines(&svg), [method_colour(Method::Strata)]);
    assert!(!has_text(&svg, "restir-disc"));
}

#[test]
fn odd_data_draws_without_panicking() {
    let dir = folder("odd");
    let mut errors = rows(&[Method::Strata, Method::Restir], 3, 1);
    errors[0].relmse = f64::NAN;
    errors[1].relmse = f64::INFINITY;
    errors[3].relmse = 0.0;
    // One seed: lines but no bands; the NaN and infinite frames leave gaps.
    let figure = relmse_figure(&errors, &[Method::Strata, Method::Restir], 3, "one seed");
    assert!(figure.series.iter().all(|s| s.points.iter().all(|p| p.band.is_none() && p.mean > 0.0)));
    let svg = relmse_svg(&errors, &[Method::Strata, Method::Restir], 3, "one seed");
    assert_eq!(svg.matches("<polygon").count(), 0, "{svg}");
    write_relmse_plot(&errors, &[Method::Strata, Method::Restir], 3, "one seed", &dir.join("odd")).unwrap();
    assert!(write_ratio_plot(&errors, 3, "one seed", &dir.join("odd_ratio")).unwrap());
    // One frame; a band whose lower end is negative (two very different seeds); no rows.
    let mut one = rows(&[Method::Strata, Method::Restir], 1, 2);
    one[0].relmse = 1e-6;
    one[1].relmse = 10.0;
    write_relmse_plot(&one, &[Method::Strata, Method::Restir], 1, "one frame", &dir.join("one")).unwrap();
    assert!(write_ratio_plot(&one, 1, "one frame", &dir.join("one_ratio")).unwrap());
    write_relmse_plot(&[], &[Method::Strata], 0, "nothing", &dir.join("none")).unwrap();
    let svg = relmse_svg(&one, &[Method::Strata, Method::Restir], 1, "one frame");
    assert!(!svg.contains("NaN") && !svg.contains("inf") && svg.contains("<circle"), "{svg}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_ratio_plot_needs_strata_and_a_baseline() {
    let dir = folder("ratio");
    let stem = dir.join("ratio");
    let baselines_only = rows(&[Method::Restir, Method::RestirDisc], 4, 2);
    assert!(!write_ratio_plot(&baselines_only, 4, "t", &stem).unwrap());
    assert!(!write_ratio_plot(&rows(&[Method::Strata], 4, 2), 4, "t", &stem).unwrap());
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0, "nothing is written");
    let errors = rows(&[Method::Strata, Method::Restir, Method::RestirDisc], 4, 2);
    assert!(write_ratio_plot(&errors, 4, "t", &stem).unwrap());
    let svg = std::fs::read_to_string(dir.join("ratio.svg")).unwrap();
    // One line per baseline in the baseline's colour, and the dashed line at 1 (in pieces).
    assert_eq!(data_lines(&svg), [method_colour(Method::Restir), method_colour(Method::RestirDisc)]);
    assert!(has_text(&svg, "strata ÷ restir") && has_text(&svg, "strata ÷ restir-disc"));
    assert!(has_text(&svg, "strata ÷ baseline"));
    assert!(dir.join("ratio.png").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_overlay_writes_its_files_and_tells_runs_apart() {
    let dir = folder("overlay");
    let runs = vec![
        ("off".to_string(), rows(&[Method::Strata, Method::Restir], 8, 2)),
        ("on".to_string(), rows(&[Method::Strata, Method::Restir], 8, 2)),
    ];
    let written = write_overlay_plots(&runs, "block shift", &dir.join("shift")).unwrap();
    let names: Vec<&str> = written.iter().map(|p| p.file_name().unwrap().to_str().unwrap()).collect();
    assert_eq!(names, ["shift_relmse.svg", "shift_relmse.png", "shift_ratio.svg", "shift_ratio.png"]);
    assert!(written.iter().all(|p| p.exists()));
    let svg = std::fs::read_to_string(dir.join("shift_relmse.svg")).unwrap();
    for label in ["off: strata", "off: restir", "on: strata", "on: restir"] {
        assert!(has_text(&svg, label), "{label} missing");
    }
    // The first run solid (one polyline per method), the second dashed (many pieces).
    let strata = method_colour(Method::Strata).to_lowercase();
    let pieces = polylines(&svg).iter().filter(|(c, _)| *c == strata).count();
    assert!(pieces > 4, "{pieces}");
    let ratio = std::fs::read_to_string(dir.join("shift_ratio.svg")).unwrap();
    assert!(has_text(&ratio, "off: strata ÷ restir") && has_text(&ratio, "on: strata ÷ restir"));
    // No run with a baseline: only the RelMSE plot.
    let runs = vec![("a".to_string(), rows(&[Method::Strata], 2, 2)), ("b".to_string(), rows(&[Method::Strata], 2, 2))];
    let written = write_overlay_plots(&runs, "t", &dir.join("alone")).unwrap();
    assert_eq!(written, [dir.join("alone_relmse.svg"), dir.join("alone_relmse.png")]);
    assert!(!dir.join("alone_ratio.svg").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn pngs_decode_and_show_their_text() {
    let dir = folder("png");
    let errors = rows(&[Method::Strata, Method::Restir], 4, 3);
    let methods = [Method::Strata, Method::Restir];
    write_relmse_plot(&errors, &methods, 4, "A title in the PNG", &dir.join("titled")).unwrap();
    write_relmse_plot(&errors, &methods, 4, "", &dir.join("untitled")).unwrap();
    let titled = image::open(dir.join("titled.png")).unwrap().to_rgb8();
    let untitled = image::open(dir.join("untitled.png")).unwrap().to_rgb8();
    assert!(titled.width() >= SIZE.0 && titled.height() >= SIZE.1, "{}x{}", titled.width(), titled.height());
    // The title band (above the plot) is dark only where the title's glyphs are.
    let band = 0..titled.height() * 6 / 100;
    assert!(dark_pixels(&titled, band.clone()) > 200, "{}", dark_pixels(&titled, band.clone()));
    assert_eq!(dark_pixels(&untitled, band), 0);
    // Axis labels and tick labels are drawn too: the bottom strip has text.
    let bottom = titled.height() * 90 / 100..titled.height();
    assert!(dark_pixels(&titled, bottom) > 100);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn write_errors_name_the_file() {
    let stem = Path::new("/nonexistent-strata-folder/relmse");
    let error = write_relmse_plot(&rows(&[Method::Strata], 2, 2), &[Method::Strata], 2, "t", stem).unwrap_err();
    let message = format!("{error:#}");
    assert!(message.contains("/nonexistent-strata-folder/relmse.svg: cannot write"), "{message}");
}

#[test]
fn dashes_alternate_and_keep_corners() {
    // A 30 px line with 10 on, 5 off: pieces at 0-10 and 15-25, then 30 starts a dash.
    let pieces = dash_pieces(&[(0.0, 0.0), (30.0, 0.0)], Dash(&[10.0, 5.0]), 1.0);
    assert_eq!(pieces, [vec![(0.0, 0.0), (10.0, 0.0)], vec![(15.0, 0.0), (25.0, 0.0)]]);
    // A dash over a corner keeps the corner.
    let pieces = dash_pieces(&[(0.0, 0.0), (4.0, 0.0), (4.0, 4.0)], Dash(&[6.0, 100.0]), 1.0);
    assert_eq!(pieces, [vec![(0.0, 0.0), (4.0, 0.0), (4.0, 2.0)]]);
    assert_eq!(dash_pieces(&[(0.0, 0.0), (1.0, 1.0)], Dash::SOLID, 2.0), [vec![(0.0, 0.0), (1.0, 1.0)]]);
}

#[test]
fn control_characters_never_reach_the_svg() {
    // XML 1.0 allows tab, line feed and carriage return, and no other C0 character;
    // plotters escapes `<` and `&` but writes control characters as they are.
    let xml_forbids =
        |c: char| (c.is_control() && !matches!(c, '\t' | '\n' | '\r')) || matches!(c, '\u{FFFE}' | '\u{FFFF}');
    let title = "bell\u{7} <tab>\tnul\u{0}\u{FFFF}";
    let errors = rows(&[Method::Strata, Method::Restir], 2, 2);
    let svg = relmse_svg(&errors, &[Method::Strata, Method::Restir], 2, title);
    assert!(!svg.chars().any(xml_forbids), "the SVG holds a character XML forbids: {svg:?}");
    assert!(has_text(&svg, "bell\u{FFFD} &lt;tab&gt;\u{FFFD}nul\u{FFFD}\u{FFFD}"), "{:?}", texts(&svg));
    // A legend label made from a folder name: replaced in the same way.
    let runs = vec![("run\u{1b}[31m".to_string(), errors.clone()), ("b".to_string(), errors)];
    let dir = folder("control");
    let written = write_overlay_plots(&runs, "t", &dir.join("overlay")).unwrap();
    let svg = std::fs::read_to_string(&written[0]).unwrap();
    assert!(!svg.chars().any(xml_forbids), "{svg:?}");
    assert!(texts(&svg).iter().any(|t| t.starts_with("run\u{FFFD}[31m")), "{:?}", texts(&svg));
    let _ = std::fs::remove_dir_all(&dir);
}
