//! The summary of `strata compare` as data: tables of RelMSE over seeds with strata's
//! paired ratios, strata's whole-run ratio to each baseline, and the reference-free
//! tables of relative variance over seeds (with `variance.csv`). Plain data in, tables
//! out; [`Table::to_text`] prints them (stdout, `summary.txt`) and the report page
//! writes the same tables as HTML, so the two never disagree.

use super::compare::{
    FrameError, flip_over_seeds, flip_ratio, luminance_relmse_ratio, relmse_over_seeds, relmse_ratio,
    relmse_ratio_over_frames,
};
use super::metrics::{self, MeanInterval};
use anyhow::Result;
use strata_render::restir::Method;
use strata_render::rgb_image::RgbImage;

/// A table with a label column and one column per shown frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Table {
    /// What the table shows, one sentence.
    pub title: String,
    /// Header of the label column, then of each value column.
    pub columns: Vec<String>,
    /// The rows.
    pub rows: Vec<Row>,
}

/// One row of a [`Table`].
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// The row's label (a method, or "÷ baseline" for strata's ratio to it).
    pub label: String,
    /// One cell per value column (empty where there is nothing to show).
    pub cells: Vec<String>,
    /// A ratio row (strata ÷ a baseline) rather than a method's own values.
    pub is_ratio: bool,
}

impl Table {
    /// The table as fixed-width text: the title, then rows of `label | cell | …`.
    pub fn to_text(&self) -> String {
        let mut text = format!("{}\n", self.title);
        let line = |label: &str, cells: &[String]| {
            let mut line = format!("{label:<18}");
            for cell in cells {
                line += &format!(" | {cell:>20}");
            }
            line + "\n"
        };
        if let Some((label, cells)) = self.columns.split_first() {
            text += &line(label, cells);
        }
        for row in &self.rows {
            text += &line(&row.label, &row.cells);
        }
        text
    }
}

/// A paired ratio of one error column between two methods at one frame.
type RatioOf = fn(&[FrameError], Method, Method, u32) -> Option<MeanInterval>;

/// `mean ± half-width` to 3 decimals, or empty.
fn ratio_cell(ratio: Option<MeanInterval>) -> String {
    ratio.map(|r| r.fixed(3)).unwrap_or_default()
}

/// The baselines among `methods` that strata can be compared with.
fn baselines(methods: &[Method]) -> Vec<Method> {
    if !methods.contains(&Method::Strata) {
        return Vec::new();
    }
    Method::BASELINES.into_iter().filter(|b| methods.contains(b)).collect()
}

/// The frame columns' headers, "frame N" (1-based).
fn frame_columns(first: &str, shown: &[u32]) -> Vec<String> {
    std::iter::once(first.to_string()).chain(shown.iter().map(|f| format!("frame {}", f + 1))).collect()
}

/// RelMSE of each method at the shown frames (mean ± 95 % CI over seeds), then strata ÷
/// each baseline, paired per seed, of RelMSE and of luminance RelMSE.
pub fn relmse_table(errors: &[FrameError], methods: &[Method], shown: &[u32], title: &str) -> Table {
    let mut rows: Vec<Row> = methods
        .iter()
        .map(|&m| Row {
            label: m.name().to_string(),
            cells: shown.iter().map(|&f| relmse_over_seeds(errors, m, f).to_string()).collect(),
            is_ratio: false,
        })
        .collect();
    for baseline in baselines(methods) {
        for (suffix, ratio_of) in [("", relmse_ratio as RatioOf), (" luma", luminance_relmse_ratio)] {
            rows.push(Row {
                label: format!("÷ {}{suffix}", baseline.name()),
                cells: shown.iter().map(|&f| ratio_cell(ratio_of(errors, Method::Strata, baseline, f))).collect(),
                is_ratio: true,
            });
        }
    }
    Table { title: title.to_string(), columns: frame_columns("method", shown), rows }
}

/// FLIP of each method at the shown frames (mean ± 95 % CI over seeds), then strata ÷
/// each baseline, paired per seed; `None` when the errors hold no FLIP (a CSV written
/// before it, a build without it).
pub fn flip_table(errors: &[FrameError], methods: &[Method], shown: &[u32]) -> Option<Table> {
    if !errors.iter().any(|e| e.flip.is_some()) {
        return None;
    }
    let mut rows: Vec<Row> = methods
        .iter()
        .map(|&m| Row {
            label: m.name().to_string(),
            cells: shown
                .iter()
                .map(|&f| flip_over_seeds(errors, m, f).map(|v| v.fixed(4)).unwrap_or_default())
                .collect(),
            is_ratio: false,
        })
        .collect();
    for baseline in baselines(methods) {
        rows.push(Row {
            label: format!("÷ {}", baseline.name()),
            cells: shown.iter().map(|&f| ratio_cell(flip_ratio(errors, Method::Strata, baseline, f))).collect(),
            is_ratio: true,
        });
    }
    let title = "FLIP of the previews (LDR-FLIP at the report's exposure, 67 pixels per degree; 0 = identical, lower \
                 is better), mean ± 95% CI over seeds:";
    Some(Table { title: title.to_string(), columns: frame_columns("method", shown), rows })
}

/// The block-edge contrast of each method's error at the shown frames (mean ± 95 % CI
/// over seeds; [`super::block_structure`]): 0 without block structure, positive where the
/// error jumps at the edges of the `block_size` grid. `None` when no row has one.
pub fn block_edge_table(errors: &[FrameError], methods: &[Method], shown: &[u32], block_size: u32) -> Option<Table> {
    if !errors.iter().any(|e| e.block_edge.is_some()) {
        return None;
    }
    let rows = methods
        .iter()
        .map(|&m| Row {
            label: m.name().to_string(),
            cells: shown
                .iter()
                .map(|&f| {
                    let values: Vec<f64> =
                        errors.iter().filter(|e| e.method == m && e.frame == f).filter_map(|e| e.block_edge).collect();
                    if values.is_empty() { String::new() } else { MeanInterval::of(&values).fixed(3) }
                })
                .collect(),
            is_ratio: false,
        })
        .collect();
    let title = format!(
        "block-edge contrast of the error on the {block_size}x{block_size} grid (0: no block structure; 0.5: the \
         error jumps at block edges half again as much as inside a block), mean ± 95% CI over seeds:"
    );
    Some(Table { title, columns: frame_columns("method", shown), rows })
}

/// strata ÷ one baseline over a whole run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WholeRunRatio {
    /// The baseline.
    pub baseline: Method,
    /// Mean and 95 % interval over seeds of the per-seed ratio of summed RelMSE.
    pub ratio: MeanInterval,
}

/// strata ÷ each baseline the errors hold, over the whole run ([`relmse_ratio_over_frames`]).
pub fn whole_run_ratios(errors: &[FrameError]) -> Vec<WholeRunRatio> {
    Method::BASELINES
        .into_iter()
        .filter_map(|baseline| {
            Some(WholeRunRatio { baseline, ratio: relmse_ratio_over_frames(errors, Method::Strata, baseline)? })
        })
        .collect()
}

/// The sentence `strata compare` and `strata plot` print for each baseline the errors
/// hold beside strata: its [`WholeRunRatio`], or why it cannot be computed (the
/// baseline's RelMSE is 0 in every seed: its images equal the reference).
pub fn whole_run_lines(errors: &[FrameError], frames: u32) -> Vec<String> {
    let has = |m: Method| errors.iter().any(|e| e.method == m);
    let ratios = whole_run_ratios(errors);
    Method::BASELINES
        .into_iter()
        .filter(|&baseline| has(Method::Strata) && has(baseline))
        .map(|baseline| {
            let head = format!(
                "strata ÷ {} over frames 1-{frames} (per seed, RelMSE summed over the frames)",
                baseline.name()
            );
            match ratios.iter().find(|w| w.baseline == baseline) {
                Some(w) if w.ratio.count >= 2 => format!("{head}: {} ({} seeds)", w.ratio.fixed(4), w.ratio.count),
                Some(w) => format!("{head}: {}", w.ratio.fixed(4)),
                None => format!(
                    "{head}: cannot be computed ({}'s RelMSE is 0 in every seed: its images equal the reference)",
                    baseline.name()
                ),
            }
        })
        .collect()
}

/// Prints [`whole_run_lines`].
pub fn print_ratio_over_frames(errors: &[FrameError], frames: u32) {
    for line in whole_run_lines(errors, frames) {
        println!("{line}");
    }
}

/// Every seed's image of each (method, shown frame), for the variance over seeds.
pub type SeedImages = std::collections::HashMap<(Method, u32), Vec<RgbImage>>;

/// The reference-free summary ([`super::variance`]) of the images and of their
/// luminance: each method's relative variance over seeds at the shown frames and
/// strata's ratio to each baseline with its jackknife interval; and the text of
/// `variance.csv` (method, frame, relvar, vs_restir / vs_restir_disc ratio ± half-width
/// for strata, relvar_luminance).
pub fn variance_tables(
    methods: &[Method],
    shown: &[u32],
    seed_images: &SeedImages,
    references: &[RgbImage],
) -> Result<(Vec<Table>, String)> {
    use super::variance::{relative_variance, variance_ratio};
    let reference = |frame: u32| references.get(frame as usize).unwrap_or(&references[0]).clone();
    let images = |method: Method, frame: u32| seed_images.get(&(method, frame)).cloned().unwrap_or_default();
    let grey_reference = |frame: u32| metrics::luminance_image(&reference(frame));
    let grey = |method: Method, frame: u32| images(method, frame).iter().map(metrics::luminance_image).collect();
    let tables = vec![
        variance_table(
            "relative variance over seeds (reference-free RelMSE; ratio ± 95% jackknife interval):",
            methods,
            shown,
            "",
            &images,
            &reference,
        )?,
        variance_table(
            "the same of luminance (the error without colour noise):",
            methods,
            shown,
            " luma",
            &grey,
            &grey_reference,
        )?,
    ];
    let mut csv = String::from(
        "method,frame,relvar,vs_restir,vs_restir_half_width,vs_restir_disc,vs_restir_disc_half_width,relvar_luminance\n",
    );
    for &method in methods {
        for &f in shown {
            let value = relative_variance(&images(method, f), &reference(f))?;
            let mut ratios = String::new();
            for baseline in [Method::Restir, Method::RestirDisc] {
                if method == Method::Strata && methods.contains(&baseline) {
                    let r = variance_ratio(&images(method, f), &images(baseline, f), &reference(f))?;
                    // A ratio that cannot be computed (a baseline without variance) is
                    // an empty field, never NaN.
                    let field = |v: f64| if v.is_finite() { format!("{v:.4}") } else { String::new() };
                    ratios += &format!(",{},{}", field(r.mean), field(r.half_width));
                } else {
                    ratios += ",,";
                }
            }
            let luminance = relative_variance(&grey(method, f), &grey_reference(f))?;
            csv += &format!("{},{},{value:.6e}{ratios},{luminance:.6e}\n", method.name(), f + 1);
        }
    }
    Ok((tables, csv))
}

/// One table of [`variance_tables`]: a row per method, then strata ÷ each baseline; row
/// labels end with `suffix`.
fn variance_table(
    title: &str,
    methods: &[Method],
    shown: &[u32],
    suffix: &str,
    images: &dyn Fn(Method, u32) -> Vec<RgbImage>,
    reference: &dyn Fn(u32) -> RgbImage,
) -> Result<Table> {
    use super::variance::{relative_variance, variance_ratio};
    let mut rows = Vec::new();
    for &method in methods {
        let cells = shown
            .iter()
            .map(|&f| Ok(format!("{:.4e}", relative_variance(&images(method, f), &reference(f))?)))
            .collect::<Result<Vec<String>>>()?;
        rows.push(Row { label: format!("{}{suffix}", method.name()), cells, is_ratio: false });
    }
    for baseline in baselines(methods) {
        let cells = shown
            .iter()
            .map(|&f| {
                let r = variance_ratio(&images(Method::Strata, f), &images(baseline, f), &reference(f))?;
                Ok(r.fixed(3))
            })
            .collect::<Result<Vec<String>>>()?;
        rows.push(Row { label: format!("÷ {}{suffix}", baseline.name()), cells, is_ratio: true });
    }
    Ok(Table { title: title.to_string(), columns: frame_columns("method", shown), rows })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn errors() -> Vec<FrameError> {
        let mut errors = Vec::new();
        for seed in 1..=3 {
            for frame in 0..2 {
                for (method, relmse) in [(Method::Restir, 2.0), (Method::Strata, 1.0 + f64::from(seed) * 0.01)] {
                    errors.push(FrameError {
                        method,
                        frame,
                        seed,
                        relmse,
                        prelmse: relmse,
                        mse: relmse,
                        relmse_luminance: Some(relmse),
                        flip: None,
                        block_edge: None,
                    });
                }
            }
        }
        errors
    }

    #[test]
    fn the_relmse_table_has_a_row_per_method_and_ratio_and_prints_them() {
        let table = relmse_table(&errors(), &[Method::Restir, Method::Strata], &[0, 1], "RelMSE:");
        let labels: Vec<&str> = table.rows.iter().map(|r| r.label.as_str()).collect();
        assert_eq!(labels, ["restir", "strata", "÷ restir", "÷ restir luma"]);
        assert_eq!(table.columns, ["method", "frame 1", "frame 2"]);
        assert!(table.rows[2].cells[0].starts_with("0.510 ± 0.01"), "{:?}", table.rows[2]);
        let text = table.to_text();
        assert!(text.starts_with("RelMSE:\nmethod             |              frame 1 |"), "{text}");
        assert_eq!(text.lines().count(), 6);
        // No strata, no ratio rows.
        assert_eq!(relmse_table(&errors(), &[Method::Restir], &[0], "").rows.len(), 1);
    }

    #[test]
    fn whole_run_ratios_name_their_baseline() {
        let lines = whole_run_lines(&errors(), 2);
        assert_eq!(lines.len(), 1);
        assert!(lines[0].starts_with("strata ÷ restir over frames 1-2") && lines[0].contains("(3 seeds)"), "{lines:?}");
    }
}
