//! `report.html`: one page that shows a `strata compare` run the way the paper's figures
//! do. Top to bottom: strata's whole-run ratio to each baseline; RelMSE and the paired
//! ratio against frame (the plots); the reference beside every method at each written
//! frame, with its error map and each image's RelMSE and relative difference to each
//! baseline; close-ups magnified without smoothing, where the methods differ most or
//! where `--crop` said; the summary tables; and the run's record.
//!
//! The page is self-contained in its folder: the images and plots it shows are files
//! beside it (relative links), styles are inline, no script, nothing from the network.
//! Close-ups are cut out of the frame images by CSS (a clipped, magnified `<img>`), so
//! they add no files.

use super::crops::Crop;
use super::plot::method_colour;
use super::record::RunRecord;
use super::summary::{Table, WholeRunRatio};
use strata_render::restir::Method;

/// Everything the page shows; file names are relative to the page's folder.
pub struct Page<'a> {
    /// The page's heading.
    pub title: String,
    /// The run's record.
    pub record: &'a RunRecord,
    /// Image width and height in pixels.
    pub size: (u32, u32),
    /// The written frames, in order.
    pub frames: Vec<FrameImages>,
    /// The close-ups, in order (the same rectangles at every frame).
    pub crops: Vec<CropShown>,
    /// The frames (0-based) whose close-ups are shown.
    pub crop_frames: Vec<u32>,
    /// strata ÷ each baseline over the whole run, per regime measured (the run's own
    /// first, then the other one with `--both-regimes`).
    pub whole_run: Vec<RegimeRatios>,
    /// Plots: (file, caption).
    pub plots: Vec<(String, String)>,
    /// The summary tables.
    pub tables: Vec<Table>,
    /// Sentences shown after the tables (what the viewer sees: a denoiser hiding the
    /// sampler, what was not measured).
    pub notes: Vec<String>,
    /// The error maps' colour bar (a PNG of [`COLOUR_BAR_DECADES`] decades).
    pub colour_bar: String,
}

/// strata ÷ each baseline over the whole run in one regime.
pub struct RegimeRatios {
    /// The regime, as the page names it (`temporal reuse`, `accumulated frames`).
    pub regime: String,
    /// Its ratios.
    pub ratios: Vec<WholeRunRatio>,
}

/// The decades of RelMSE the error maps' colours span, from 1e-4 (black) to 1 (white).
pub const COLOUR_BAR_DECADES: [&str; 5] = ["≤ 1e-4", "1e-3", "1e-2", "0.1", "≥ 1"];

/// One written frame: the reference and every method's first-seed image.
pub struct FrameImages {
    /// Frame index (0-based).
    pub frame: u32,
    /// The reference's PNG.
    pub reference: String,
    /// Every method's image, in the run's order.
    pub methods: Vec<MethodImage>,
}

/// One method's image at one frame.
pub struct MethodImage {
    /// The method.
    pub method: Method,
    /// Its PNG.
    pub image: String,
    /// Its RelMSE map's false-colour PNG.
    pub error_map: String,
    /// RelMSE of this image (seed 1).
    pub relmse: f64,
    /// RelMSE of this image inside each crop of [`Page::crops`].
    pub crop_relmse: Vec<f64>,
}

/// A close-up and where it came from.
pub struct CropShown {
    /// The rectangle.
    pub crop: Crop,
    /// Chosen where the methods differ most (otherwise given by `--crop`).
    pub automatic: bool,
}

/// Side in CSS pixels that a small image is magnified to (by a whole factor).
const SHOWN_SIDE: u32 = 256;
/// Side in CSS pixels of a close-up.
const CROP_SIDE: u32 = 176;

/// Escapes text for HTML.
fn escape(text: &str) -> String {
    text.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// (value − baseline) ÷ baseline in percent, signed, e.g. "−18.2 %".
fn relative_difference(value: f64, baseline: f64) -> String {
    let percent = (value - baseline) / baseline * 100.0;
    if !percent.is_finite() {
        return "–".to_string();
    }
    let sign = if percent < 0.0 { "−" } else { "+" };
    format!("{sign}{:.1} %", percent.abs())
}

/// A method's name in its colour.
fn method_label(method: Method) -> String {
    format!("<span class=\"method\" style=\"color:{}\">{}</span>", method_colour(method), method.name())
}

/// How a method's number compares with each baseline's: "−18 % vs restir, …" (empty
/// for a baseline itself).
fn versus_baselines(method: Method, value: f64, of: impl Fn(Method) -> Option<f64>) -> String {
    if method != Method::Strata {
        return String::new();
    }
    Method::BASELINES
        .into_iter()
        .filter_map(|b| Some(format!("{} vs {}", relative_difference(value, of(b)?), b.name())))
        .collect::<Vec<_>>()
        .join(", ")
}

impl Page<'_> {
    /// The whole page.
    pub fn to_html(&self) -> String {
        let mut html = String::from("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n");
        html += &format!("<title>{}</title>\n<style>{}</style>\n</head>\n<body>\n", escape(&self.title), STYLE);
        html += &format!("<h1>{}</h1>\n", escape(&self.title));
        let r = self.record;
        html += &format!(
            "<p class=\"lead\">{}×{}, {} frames × {} seeds, {}; reference: {}.<br>{}</p>\n",
            r.width,
            r.height,
            r.frames,
            r.seeds,
            if r.temporal { "temporal reuse" } else { "frames accumulated (no temporal reuse)" },
            escape(&r.reference),
            escape(&r.backend)
        );
        html += &self.headline();
        html += &self.plots();
        html += &self.images();
        html += &self.closeups();
        html += &self.tables();
        html += &self.record_section();
        html += "</body>\n</html>\n";
        html
    }

    fn headline(&self) -> String {
        if self.whole_run.iter().all(|regime| regime.ratios.is_empty()) {
            return String::new();
        }
        let mut html = String::from("<section id=\"headline\">\n<h2>Over the whole run</h2>\n<div class=\"ratios\">\n");
        for regime in &self.whole_run {
            for w in &regime.ratios {
                html += &format!(
                    "<div class=\"ratio\"><div class=\"big\">{}</div>\
                     <div>{} ÷ {} RelMSE, {}, frames 1–{}</div><div class=\"note\">per seed, summed over frames; mean \
                     and 95 % interval over {} seeds (below 1: strata better)</div></div>\n",
                    headline_ratio(&w.ratio),
                    method_label(Method::Strata),
                    method_label(w.baseline),
                    escape(&regime.regime),
                    self.record.frames,
                    w.ratio.count
                );
            }
        }
        html + "</div>\n</section>\n"
    }

    fn plots(&self) -> String {
        let mut html = String::from("<section id=\"plots\">\n<h2>Error against frame</h2>\n<div class=\"row\">\n");
        for (file, caption) in &self.plots {
            html += &format!(
                "<figure class=\"plot\"><img src=\"{0}\" alt=\"{1}\"><figcaption>{1}</figcaption></figure>\n",
                escape(file),
                escape(caption)
            );
        }
        html + "</div>\n</section>\n"
    }

    /// Width and height at which a frame image is shown, and whether it is magnified.
    fn shown_size(&self) -> (u32, u32, bool) {
        let (width, height) = self.size;
        let factor = (SHOWN_SIDE / width.max(1)).max(1);
        (width * factor, height * factor, factor > 1)
    }

    fn image(&self, file: &str, alt: &str) -> String {
        let (w, h, magnified) = self.shown_size();
        format!(
            "<img src=\"{}\" alt=\"{}\" width=\"{w}\" height=\"{h}\"{}>",
            escape(file),
            escape(alt),
            if magnified { " class=\"pixelated\"" } else { "" }
        )
    }

    fn images(&self) -> String {
        let mut html = String::from(
            "<section id=\"images\">\n<h2>Images</h2>\n<p class=\"note\">Seed 1 of each method at the written \
             frames; below each image its RelMSE map (per pixel (f − ref)² / (ref + 1e-4), averaged over channels).</p>\n",
        );
        for (index, frame) in self.frames.iter().enumerate() {
            let open = index == 0 || index + 1 == self.frames.len();
            html += &format!(
                "<details{}><summary>Frame {}</summary>\n<div class=\"grid\">\n",
                if open { " open" } else { "" },
                frame.frame + 1
            );
            html += &format!(
                "<figure>{}<figcaption><b>reference</b></figcaption></figure>\n",
                self.image(&frame.reference, &format!("reference, frame {}", frame.frame + 1))
            );
            let of = |m: Method| frame.methods.iter().find(|i| i.method == m).map(|i| i.relmse);
            for image in &frame.methods {
                let versus = versus_baselines(image.method, image.relmse, of);
                html += &format!(
                    "<figure>{}{}<figcaption>{} RelMSE {:.3e}{}</figcaption></figure>\n",
                    self.image(&image.image, &format!("{}, frame {}", image.method.name(), frame.frame + 1)),
                    self.image(
                        &image.error_map,
                        &format!("RelMSE map of {}, frame {}", image.method.name(), frame.frame + 1)
                    ),
                    method_label(image.method),
                    image.relmse,
                    if versus.is_empty() { String::new() } else { format!("<br>{versus}") }
                );
            }
            html += "</div>\n</details>\n";
        }
        html += &format!(
            "<div class=\"colourbar\"><span>RelMSE map colours:</span><div><img src=\"{}\" alt=\"colour bar of the \
             RelMSE maps\" width=\"320\" height=\"14\"><div class=\"ticks\">{}</div></div></div>\n",
            escape(&self.colour_bar),
            COLOUR_BAR_DECADES.iter().map(|d| format!("<span>{d}</span>")).collect::<String>()
        );
        html + "</section>\n"
    }

    fn closeups(&self) -> String {
        if self.crops.is_empty() || self.frames.is_empty() {
            return String::new();
        }
        let mut html = String::from("<section id=\"closeups\">\n<h2>Close-ups</h2>\n");
        let automatic = self.crops.iter().any(|c| c.automatic);
        html += &format!(
            "<p class=\"note\">{}Each close-up is magnified without smoothing; under it, RelMSE inside the \
             rectangle (seed 1).</p>\n",
            if automatic {
                "Rectangles marked “auto” were chosen where the methods' errors differ most at frame 1. "
            } else {
                ""
            }
        );
        // The reference with every rectangle drawn on it.
        let first = &self.frames[0];
        let (width, height) = self.size;
        html += "<div class=\"row\"><div class=\"boxes\">";
        html += &self.image(&first.reference, "reference with the close-ups marked");
        for (index, shown) in self.crops.iter().enumerate() {
            let c = shown.crop;
            html += &format!(
                "<div class=\"box\" style=\"left:{:.3}%;top:{:.3}%;width:{:.3}%;height:{:.3}%\"><span>{}</span></div>",
                100.0 * f64::from(c.x) / f64::from(width),
                100.0 * f64::from(c.y) / f64::from(height),
                100.0 * f64::from(c.width) / f64::from(width),
                100.0 * f64::from(c.height) / f64::from(height),
                index + 1
            );
        }
        html += "</div></div>\n";
        for &frame_index in &self.crop_frames {
            let Some(frame) = self.frames.iter().find(|f| f.frame == frame_index) else { continue };
            html += &format!(
                "<h3>Frame {}</h3>\n<table class=\"crops\">\n<tr><th></th><th>reference</th>",
                frame.frame + 1
            );
            for image in &frame.methods {
                html += &format!("<th>{}</th>", method_label(image.method));
            }
            html += "</tr>\n";
            for (index, shown) in self.crops.iter().enumerate() {
                let c = shown.crop;
                html += &format!(
                    "<tr><th>{}<br><small>{} {}</small></th><td>{}</td>",
                    index + 1,
                    if shown.automatic { "auto" } else { "--crop" },
                    c,
                    self.crop_image(&frame.reference, c)
                );
                let of = |m: Method| {
                    frame.methods.iter().find(|i| i.method == m).and_then(|i| i.crop_relmse.get(index).copied())
                };
                for image in &frame.methods {
                    let value = image.crop_relmse.get(index).copied().unwrap_or(f64::NAN);
                    let versus = versus_baselines(image.method, value, of);
                    html += &format!(
                        "<td>{}<div class=\"caption\">{:.3e}{}</div></td>",
                        self.crop_image(&image.image, c),
                        value,
                        if versus.is_empty() { String::new() } else { format!("<br>{versus}") }
                    );
                }
                html += "</tr>\n";
            }
            html += "</table>\n";
        }
        for note in &self.notes {
            html += &format!("<p class=\"note\">{}</p>\n", escape(note));
        }
        html + "</section>\n"
    }

    /// A rectangle of `file` magnified by CSS without smoothing.
    fn crop_image(&self, file: &str, crop: Crop) -> String {
        let zoom = f64::from(CROP_SIDE) / f64::from(crop.width.max(crop.height));
        let (width, height) = self.size;
        format!(
            "<div class=\"crop\" style=\"width:{:.0}px;height:{:.0}px\"><img src=\"{}\" alt=\"close-up {}\" \
             style=\"width:{:.1}px;height:{:.1}px;left:{:.1}px;top:{:.1}px\"></div>",
            f64::from(crop.width) * zoom,
            f64::from(crop.height) * zoom,
            escape(file),
            crop,
            f64::from(width) * zoom,
            f64::from(height) * zoom,
            -f64::from(crop.x) * zoom,
            -f64::from(crop.y) * zoom
        )
    }

    fn tables(&self) -> String {
        let mut html = String::from("<section id=\"tables\">\n<h2>Tables</h2>\n");
        for table in &self.tables {
            html += &format!("<table class=\"summary\">\n<caption>{}</caption>\n<tr>", escape(&table.title));
            for column in &table.columns {
                html += &format!("<th>{}</th>", escape(column));
            }
            html += "</tr>\n";
            for row in &table.rows {
                html += &format!(
                    "<tr{}><th>{}</th>",
                    if row.is_ratio { " class=\"ratio-row\"" } else { "" },
                    escape(&row.label)
                );
                for cell in &row.cells {
                    html += &format!("<td>{}</td>", escape(cell));
                }
                html += "</tr>\n";
            }
            html += "</table>\n";
        }
        for note in &self.notes {
            html += &format!("<p class=\"note\">{}</p>\n", escape(note));
        }
        html + "</section>\n"
    }

    fn record_section(&self) -> String {
        let mut html = String::from("<section id=\"record\">\n<h2>This run</h2>\n<dl>\n");
        for (name, value) in self.record.lines() {
            html += &format!("<dt>{}</dt><dd>{}</dd>\n", escape(&name), escape(&value));
        }
        html + "</dl>\n<p class=\"note\">Also in this folder: errors.csv (every frame of every seed), run.json (this \
                record), summary.txt, the EXR images and maps.</p>\n</section>\n"
    }
}

/// The page's styles (inline, so the folder stands alone).
const STYLE: &str = "
body { font: 15px/1.45 system-ui, sans-serif; margin: 2em auto; max-width: 1200px; padding: 0 1em; color: #222; }
h1 { font-size: 1.6em; margin-bottom: 0.2em; } h2 { margin-top: 1.6em; border-bottom: 1px solid #ddd; }
.lead { color: #555; } .note { color: #666; font-size: 0.9em; }
.ratios, .row { display: flex; flex-wrap: wrap; gap: 1.5em; }
.ratio { border: 1px solid #ddd; border-radius: 6px; padding: 0.8em 1.2em; flex: 0 1 24em; }
.ratio .big { font-size: 2em; font-weight: 600; } .ratio small { font-size: 0.5em; color: #666; }
.method { font-weight: 600; }
figure { margin: 0; } figure.plot { flex: 1 1 500px; max-width: 590px; }
figure.plot img { width: 100%; height: auto; border: 1px solid #eee; }
figcaption { font-size: 0.9em; margin-top: 0.2em; }
details { margin: 0.8em 0; } summary { font-weight: 600; cursor: pointer; }
.grid { display: flex; flex-wrap: wrap; gap: 1em; align-items: flex-start; }
.grid img { display: block; max-width: 100%; height: auto; margin-bottom: 2px; }
img.pixelated, .crop img { image-rendering: pixelated; }
.colourbar { display: flex; align-items: center; gap: 0.6em; font-size: 0.85em; flex-wrap: wrap; }
.colourbar img { display: block; } .colourbar .ticks { display: flex; justify-content: space-between; width: 320px; }
.boxes { position: relative; display: inline-block; line-height: 0; }
.box { position: absolute; border: 2px solid #ff0; box-shadow: 0 0 0 1px #000; box-sizing: border-box; }
.box span { position: absolute; top: 2px; left: 3px; color: #ff0; font: bold 12px/1 sans-serif; text-shadow: 0 0 2px #000; }
.crop { position: relative; overflow: hidden; border: 1px solid #ccc; }
.crop img { position: absolute; max-width: none; }
table { border-collapse: collapse; margin: 1em 0; font-size: 0.9em; }
table.summary td, table.summary th { border-bottom: 1px solid #eee; padding: 0.25em 0.7em; text-align: right; }
table.summary th:first-child { text-align: left; } caption { text-align: left; font-weight: 600; padding-bottom: 0.3em; }
tr.ratio-row { background: #f6f8fa; }
table.crops td, table.crops th { padding: 0.3em; vertical-align: top; text-align: center; }
.caption { font-size: 0.85em; }
dl { display: grid; grid-template-columns: max-content 1fr; gap: 0.2em 1em; } dt { font-weight: 600; }
dd { margin: 0; font-family: ui-monospace, monospace; font-size: 0.9em; overflow-wrap: anywhere; }
";

/// The headline's big number: `mean <small>± half-width</small>`, or the mean alone
/// (with why) where no interval exists; never NaN or infinity.
fn headline_ratio(ratio: &crate::evaluation::metrics::MeanInterval) -> String {
    if ratio.count >= 2 && ratio.mean.is_finite() && ratio.half_width.is_finite() {
        format!("{:.3} <small>± {:.3}</small>", ratio.mean, ratio.half_width)
    } else {
        let text = ratio.fixed(3);
        match text.split_once(' ') {
            Some((mean, why)) => format!("{mean} <small>{why}</small>"),
            None => text,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_differences_are_signed_percentages() {
        assert_eq!(relative_difference(0.8, 1.0), "−20.0 %");
        assert_eq!(relative_difference(1.25, 1.0), "+25.0 %");
        assert_eq!(relative_difference(1.0, 0.0), "–");
        assert_eq!(escape("<a & \"b\">"), "&lt;a &amp; &quot;b&quot;&gt;");
    }
}
