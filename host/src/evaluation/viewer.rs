//! "What the viewer sees" (issue 55): the measurements of `strata compare` that see the
//! sampler behind a denoiser and over time, for raw and denoised frames alike, gathered
//! frame by frame as the comparison runs ([`ViewerCollector::add`]) and turned into the
//! summary's tables and `viewer.csv` at the end ([`ViewerCollector::finish`]):
//!
//! - the last frame's RelMSE split into squared bias and residual noise over the seeds
//!   ([`super::bias_noise`]): a denoiser's own bias is the same whatever the sampler, so
//!   the residual noise is what is left of the sampler after it; strata's residual noise ÷
//!   each baseline's with a jackknife interval over seeds, and a sentence where a denoiser
//!   leaves two methods indistinguishable whose raw noise differs;
//! - temporal flicker for a still camera (per pixel, the standard deviation of luminance
//!   over the frames after the first quarter ÷ its mean; [`super::flicker`]) and, for every
//!   camera, the relative change of the error from frame to frame along the motion vectors
//!   (a still camera's are zero);
//! - the correlation of the error between pixels at the last frame: the normalised
//!   autocorrelation at lag 1 inside a selection block and across a block edge, and the
//!   radial power spectrum's low ÷ high frequency energy (white noise 1, blue below,
//!   clumped above; [`super::correlation`]), on each seed's residual from the mean over
//!   seeds, so that a bias pattern every seed shares is left out;
//! - equal time: strata's RelMSE × frame time ÷ each baseline's, from the frame times of
//!   the same run (the first frame of each seed, which builds the pipelines, left out).
//!
//! Memory: each seed's frames after the first quarter (flicker), and the last frame of
//! every seed; the rest is reduced as it arrives.

use super::bias_noise::{BiasNoise, NoiseRatio, bias_noise, compare_noise};
use super::compare::SeenFrame;
use super::correlation::{CorrelationError, ErrorField, LagCorrelation, autocorrelation, radial_spectrum};
use super::flicker::{PreviousPixels, flicker, temporal_error_change};
use super::metrics::MeanInterval;
use super::summary::{Row, Table};
use anyhow::{Context, Result, anyhow};
use std::collections::BTreeMap;
use std::time::Duration;
use strata_render::restir::Method;
use strata_render::rgb_image::RgbImage;

/// Which image of a frame a measurement is of.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Stage {
    /// As rendered (accumulated without temporal reuse).
    Raw,
    /// After the run's denoiser.
    Denoised,
}

impl Stage {
    /// The stage as the tables and the CSV name it.
    pub fn name(self) -> &'static str {
        match self {
            Stage::Raw => "raw",
            Stage::Denoised => "denoised",
        }
    }
}

/// Per method and stage, what the run's seeds gave.
#[derive(Clone, Debug, Default)]
struct Gathered {
    /// The last frame of each seed.
    last: Vec<RgbImage>,
    /// Flicker of each seed (still camera only).
    flicker: Vec<f64>,
    /// Error change along motion of each seed.
    change: Vec<f64>,
}

/// The frames of the seed being rendered, from the first frame measured on.
#[derive(Clone, Debug, Default)]
struct Window {
    frames: BTreeMap<Stage, Vec<RgbImage>>,
    /// Maps frame t + 1 of the window to frame t.
    previous: Vec<PreviousPixels>,
}

/// Gathers the viewer's measurements as frames arrive (see the module documentation).
#[derive(Debug)]
pub struct ViewerCollector {
    frames: u32,
    skip: u32,
    block_size: u32,
    moving: bool,
    gathered: BTreeMap<(Method, Stage), Gathered>,
    window: Window,
    /// Per method: summed frame time and frames, the first frame of each seed left out.
    times: BTreeMap<Method, (Duration, u32)>,
    /// The first measurement that failed, said at the end.
    failure: Option<anyhow::Error>,
}

/// The first frame (0-based) the temporal measurements use: after the first quarter of
/// the run, where the history is still building up (frame 1 with 4 frames, 8 with 32).
pub fn first_measured_frame(frames: u32) -> u32 {
    (frames / 4).max(1)
}

impl ViewerCollector {
    /// A collector for a run of `frames` frames per seed on blocks of `block_size`;
    /// `moving`: the camera moves (no still-camera flicker, the error change follows the
    /// motion vectors).
    pub fn new(frames: u32, block_size: u32, moving: bool) -> ViewerCollector {
        ViewerCollector {
            frames,
            skip: first_measured_frame(frames),
            block_size,
            moving,
            gathered: BTreeMap::new(),
            window: Window::default(),
            times: BTreeMap::new(),
            failure: None,
        }
    }

    /// Takes one frame; `references[frame]` (or `references[0]`) is its reference.
    /// Frames of one method and seed arrive in order, a seed's after the previous one's.
    pub fn add(&mut self, seen: SeenFrame<'_>, references: &[RgbImage]) {
        if seen.frame > 0 {
            let time = self.times.entry(seen.method).or_default();
            time.0 += seen.took;
            time.1 += 1;
        }
        if seen.frame == 0 {
            self.window = Window::default();
        }
        if seen.frame >= self.skip {
            if seen.frame > self.skip {
                let (width, height) = (seen.image.width, seen.image.height);
                let previous = match seen.motion {
                    // Motion is previous minus current; the map takes current minus previous.
                    Some(motion) => {
                        let forward: Vec<[f32; 2]> = motion.iter().map(|m| [-m[0], -m[1]]).collect();
                        PreviousPixels::from_motion_vectors(width, height, &forward)
                    }
                    None => PreviousPixels::still(width, height),
                };
                self.window.previous.push(previous);
            }
            self.window.frames.entry(Stage::Raw).or_default().push(seen.image.clone());
            if let Some(denoised) = seen.denoised {
                self.window.frames.entry(Stage::Denoised).or_default().push(denoised.clone());
            }
        }
        if seen.frame + 1 == self.frames
            && let Err(error) = self.end_seed(seen, references)
        {
            self.failure.get_or_insert(error);
        }
    }

    /// The seed's temporal measurements, and its last frame kept.
    fn end_seed(&mut self, seen: SeenFrame<'_>, references: &[RgbImage]) -> Result<()> {
        let window = std::mem::take(&mut self.window);
        let what = |stage: Stage| format!("{} seed {}, {} frames", seen.method.name(), seen.seed, stage.name());
        for (stage, frames) in &window.frames {
            let gathered = self.gathered.entry((seen.method, *stage)).or_default();
            if frames.len() >= 2 && frames.len() == window.previous.len() + 1 {
                if !self.moving {
                    let measured = flicker(frames, 0).with_context(|| what(*stage))?;
                    gathered.flicker.push(measured.mean);
                }
                let first = self.skip as usize;
                let refs: Vec<RgbImage> = (first..first + frames.len())
                    .map(|f| references.get(f).unwrap_or(&references[0]).clone())
                    .collect();
                let change = temporal_error_change(frames, &refs, &window.previous, 0).with_context(|| what(*stage))?;
                gathered.change.push(change.mean);
            }
        }
        for (stage, image) in [(Stage::Raw, Some(seen.image)), (Stage::Denoised, seen.denoised)] {
            if let Some(image) = image {
                self.gathered.entry((seen.method, stage)).or_default().last.push(image.clone());
            }
        }
        Ok(())
    }

    /// The tables and CSV of the run (`methods` in the order of their rows; `reference`
    /// the last frame's), or the first measurement that failed, named.
    pub fn finish(self, methods: &[Method], reference: &RgbImage) -> Result<ViewerReport> {
        if let Some(failure) = self.failure {
            return Err(failure.context("what the viewer sees"));
        }
        let mut report = ViewerReport::default();
        if let Some(((method, stage), g)) = self.gathered.iter().find(|(_, g)| g.last.len() < 2) {
            report.notes.push(format!(
                "what the viewer sees is not measured: the bias/noise split needs 2 seeds at least ({} {} frames \
                 have {})",
                method.name(),
                stage.name(),
                g.last.len()
            ));
            return Ok(report);
        }
        let stages: Vec<Stage> =
            [Stage::Raw, Stage::Denoised].into_iter().filter(|s| self.gathered.keys().any(|k| k.1 == *s)).collect();
        let frame_ms = |m: Method| {
            self.times.get(&m).filter(|t| t.1 > 0).map(|(time, count)| time.as_secs_f64() * 1e3 / f64::from(*count))
        };
        let noise = noise_ratios(&self.gathered, reference)?;
        for stage in stages {
            let mut measured: BTreeMap<Method, MethodViewer> = BTreeMap::new();
            for &method in methods {
                let Some(gathered) = self.gathered.get(&(method, stage)) else { continue };
                let m = measure(method, stage, gathered, reference, self.block_size, &mut report.notes)?;
                measured.insert(method, m);
            }
            let table = stage_table(stage, methods, &measured, &self.gathered, &noise, frame_ms, self.moving);
            report.notes.extend(table.1);
            report.tables.push(table.0);
            for &method in methods {
                if let Some(m) = measured.get(&method) {
                    report.csv += &m.csv_line(stage, frame_ms(method));
                    report.curves.push(m.curves.clone());
                }
            }
        }
        report.notes.extend(hidden_by_denoiser(methods, &noise));
        report.notes.push(
            "bias² is measured against the reference, whose own noise counts as bias alike for every method; after a \
             denoiser it is mostly the filter's own bias; it is an unbiased estimate (the seeds' spread divided by \
             their number taken off), so near 0 it can be slightly negative"
                .to_string(),
        );
        Ok(report)
    }
}

/// The viewer's tables, notes and CSV.
#[derive(Clone, Debug, Default)]
pub struct ViewerReport {
    /// One table per stage: each method's measurements, then strata's ratios.
    pub tables: Vec<Table>,
    /// Sentences the tables need (a denoiser hiding a difference; what was not measured).
    pub notes: Vec<String>,
    /// `viewer.csv`'s rows after its header ([`VIEWER_CSV_HEADER`]).
    pub csv: String,
    /// Every method's correlation and spectrum curves, per stage.
    pub curves: Vec<ViewerCurves>,
}

/// The header of `viewer.csv`.
pub const VIEWER_CSV_HEADER: &str = "method,stage,seeds,relmse,relative_bias_squared,relative_noise,flicker,\
                                     error_change,lag1_inside_block,lag1_across_edge,spectrum_low_high,frame_ms\n";

impl ViewerReport {
    /// `viewer.csv`: one row per method and stage (an empty field where not measured).
    pub fn csv_text(&self) -> String {
        format!("{VIEWER_CSV_HEADER}{}", self.csv)
    }

    /// The tables and notes as the printed summary shows them.
    pub fn to_text(&self) -> String {
        let mut text: String = self.tables.iter().map(Table::to_text).collect();
        for note in &self.notes {
            text += &format!("{note}\n");
        }
        text
    }
}

/// Radial bins of the error's power spectrum, from frequency 0 to ½ cycle per pixel.
const SPECTRUM_BINS: usize = 8;

/// One method's error correlation by lag and its radial power spectrum at one stage, for
/// the report's figures.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewerCurves {
    /// The method.
    pub method: Method,
    /// The stage.
    pub stage: Stage,
    /// Per lag 1..=B (pixels): the normalised autocorrelation of the error between pixels
    /// of one block and across a block edge (horizontal and vertical pooled), mean and 95 %
    /// interval over seeds; `None` where no pair of that kind exists.
    pub lags: Vec<(u32, Option<MeanInterval>, Option<MeanInterval>)>,
    /// Per radial bin: its centre frequency (cycles per pixel) and the normalised power
    /// (1 for white noise).
    pub spectrum: Vec<(f64, Option<MeanInterval>)>,
}

/// One method's measurements at one stage.
#[derive(Clone, Debug)]
struct MethodViewer {
    method: Method,
    curves: ViewerCurves,
    split: BiasNoise,
    flicker: Option<MeanInterval>,
    change: Option<MeanInterval>,
    inside: Option<MeanInterval>,
    across: Option<MeanInterval>,
    spectrum: Option<MeanInterval>,
}

impl MethodViewer {
    fn csv_line(&self, stage: Stage, frame_ms: Option<f64>) -> String {
        let value = |v: Option<f64>| v.map(|v| format!("{v:.6e}")).unwrap_or_default();
        let mean = |m: Option<MeanInterval>| value(m.map(|m| m.mean));
        format!(
            "{},{},{},{:.6e},{:.6e},{:.6e},{},{},{},{},{},{}\n",
            self.method.name(),
            stage.name(),
            self.split.seeds,
            self.split.relmse.mean,
            self.split.relative_bias_squared,
            self.split.relative_noise,
            mean(self.flicker),
            mean(self.change),
            mean(self.inside),
            mean(self.across),
            mean(self.spectrum),
            value(frame_ms)
        )
    }
}

/// The measurements of one method at one stage from what its seeds gave.
fn measure(
    method: Method,
    stage: Stage,
    gathered: &Gathered,
    reference: &RgbImage,
    block_size: u32,
    unmeasured: &mut Vec<String>,
) -> Result<MethodViewer> {
    let what = format!("{} {} frames", method.name(), stage.name());
    let split = bias_noise(&gathered.last, reference).map_err(|e| anyhow!("{what}: {e}"))?;
    let residuals = ErrorField::seed_residuals(&gathered.last, reference).map_err(|e| anyhow!("{what}: {e}"))?;
    let correlation = measurable(autocorrelation(&residuals, block_size, (0, 0)), &what, unmeasured)?;
    let spectrum = measurable(radial_spectrum(&residuals, SPECTRUM_BINS), &what, unmeasured)?;
    // Lag 1 in both directions, pooled as the mean of the two.
    let lag_one = |pick: fn(&LagCorrelation) -> Option<MeanInterval>| {
        let correlation = correlation.as_ref()?;
        pool(correlation.horizontal.first().and_then(pick), correlation.vertical.first().and_then(pick))
    };
    let interval = |values: &[f64]| (!values.is_empty()).then(|| MeanInterval::of(values));
    let curves = ViewerCurves {
        method,
        stage,
        lags: correlation
            .iter()
            .flat_map(|c| c.horizontal.iter().zip(&c.vertical))
            .map(|(h, v)| (h.lag, pool(h.inside_block, v.inside_block), pool(h.across_edge, v.across_edge)))
            .collect(),
        spectrum: spectrum.iter().flat_map(|s| &s.bins).map(|b| (0.5 * (b.low + b.high), b.power)).collect(),
    };
    Ok(MethodViewer {
        method,
        curves,
        split,
        flicker: interval(&gathered.flicker),
        change: interval(&gathered.change),
        inside: lag_one(|l| l.inside_block),
        across: lag_one(|l| l.across_edge),
        spectrum: spectrum.map(|s| s.low_high_ratio),
    })
}

/// A correlation measurement, or `None` where the images cannot have one: no larger than a
/// block, too small for the spectrum's bands, or a constant residual. The columns then
/// stay empty and `notes` says why, rather than the whole run failing.
fn measurable<T>(result: Result<T, CorrelationError>, what: &str, notes: &mut Vec<String>) -> Result<Option<T>> {
    match result {
        Ok(value) => Ok(Some(value)),
        Err(
            why @ (CorrelationError::BlockSize { .. }
            | CorrelationError::Spectrum { .. }
            | CorrelationError::Constant(_)),
        ) => {
            notes.push(format!("{what}: no correlation or spectrum ({why})"));
            Ok(None)
        }
        Err(error) => Err(anyhow!("{what}: {error}")),
    }
}

/// The horizontal and vertical values of one lag pooled as their mean (a mean of two
/// correlated estimates: the half-widths are averaged, not combined as if independent).
fn pool(a: Option<MeanInterval>, b: Option<MeanInterval>) -> Option<MeanInterval> {
    let (a, b) = (a?, b?);
    Some(MeanInterval {
        mean: 0.5 * (a.mean + b.mean),
        half_width: 0.5 * (a.half_width + b.half_width),
        count: a.count.min(b.count),
    })
}

/// Per-seed ratios `a[i] / b[i]` of paired seeds, as a mean and interval.
fn paired_ratio(a: &[f64], b: &[f64]) -> Option<MeanInterval> {
    if a.len() != b.len() || a.is_empty() {
        return None;
    }
    let ratios: Vec<f64> = a.iter().zip(b).filter(|(_, b)| **b > 0.0).map(|(a, b)| a / b).collect();
    (ratios.len() == a.len()).then(|| MeanInterval::of(&ratios))
}

/// One stage's table (each method's row, then strata ÷ each baseline) and its notes.
fn stage_table(
    stage: Stage,
    methods: &[Method],
    measured: &BTreeMap<Method, MethodViewer>,
    gathered: &BTreeMap<(Method, Stage), Gathered>,
    noise: &BTreeMap<(Stage, Method), NoiseRatio>,
    frame_ms: impl Fn(Method) -> Option<f64>,
    moving: bool,
) -> (Table, Vec<String>) {
    let seeds = measured.values().map(|m| m.split.seeds).max().unwrap_or(0);
    let title = format!(
        "What the viewer sees, {} frames (the last frame over {seeds} seeds; RelMSE = bias² + residual noise, \
         relative like RelMSE; flicker {}; error change along motion, relative; lag-1 correlation of the error \
         inside a block and across a block edge; spectrum low ÷ high, white noise 1; frame time):",
        stage.name(),
        if moving { "not measured: the camera moves" } else { "= std ÷ mean of luminance over frames" },
    );
    let columns = [
        "method",
        "RelMSE",
        "bias²",
        "residual noise",
        "flicker",
        "error change",
        "corr. inside",
        "corr. across",
        "spectrum lo/hi",
        "frame ms",
    ];
    let cell = |m: Option<MeanInterval>, decimals: usize| m.map(|m| m.fixed(decimals)).unwrap_or_default();
    let mut rows = Vec::new();
    for &method in methods {
        let Some(m) = measured.get(&method) else { continue };
        rows.push(Row {
            label: method.name().to_string(),
            cells: vec![
                format!("{:.4e}", m.split.relmse.mean),
                format!("{:.4e}", m.split.relative_bias_squared),
                format!("{:.4e}", m.split.relative_noise),
                cell(m.flicker, 4),
                cell(m.change, 4),
                cell(m.inside, 3),
                cell(m.across, 3),
                cell(m.spectrum, 2),
                frame_ms(method).map(|t| format!("{t:.1}")).unwrap_or_default(),
            ],
            is_ratio: false,
        });
    }
    let mut notes = Vec::new();
    if let Some(strata) = measured.get(&Method::Strata) {
        for baseline in Method::BASELINES {
            let Some(base) = measured.get(&baseline) else { continue };
            let (Some(ours), Some(theirs)) = (gathered.get(&(Method::Strata, stage)), gathered.get(&(baseline, stage)))
            else {
                continue;
            };
            let noise = noise.get(&(stage, baseline)).map_or_else(|| "needs 3 seeds".to_string(), |r| r.to_string());
            let relmse_ratio = strata.split.relmse.mean / base.split.relmse.mean;
            let equal_time = match (frame_ms(Method::Strata), frame_ms(baseline)) {
                (Some(ts), Some(tb)) if tb > 0.0 && base.split.relmse.mean > 0.0 => {
                    format!("{:.3}", relmse_ratio * ts / tb)
                }
                _ => String::new(),
            };
            rows.push(Row {
                label: format!("÷ {}", baseline.name()),
                cells: vec![
                    format!("{relmse_ratio:.3}"),
                    String::new(),
                    noise,
                    cell(paired_ratio(&ours.flicker, &theirs.flicker), 3),
                    cell(paired_ratio(&ours.change, &theirs.change), 3),
                    String::new(),
                    String::new(),
                    String::new(),
                    equal_time,
                ],
                is_ratio: true,
            });
        }
        if measured.len() > 1 {
            notes.push(format!(
                "{}: ÷ rows give strata ÷ baseline: RelMSE of the means, residual noise with a jackknife 95 % \
                 interval over seeds, flicker and error change paired per seed, and in the last column RelMSE × \
                 frame time (equal time: below 1 strata is better per unit of time)",
                stage.name()
            ));
        }
    }
    let table = Table { title, columns: columns.iter().map(|c| c.to_string()).collect(), rows };
    (table, notes)
}

/// strata's residual noise ÷ each baseline's per stage ([`compare_noise`]), computed once
/// for the tables and [`hidden_by_denoiser`]; left out with fewer than 3 seeds.
fn noise_ratios(
    gathered: &BTreeMap<(Method, Stage), Gathered>,
    reference: &RgbImage,
) -> Result<BTreeMap<(Stage, Method), NoiseRatio>> {
    let mut ratios = BTreeMap::new();
    for stage in [Stage::Raw, Stage::Denoised] {
        let Some(ours) = gathered.get(&(Method::Strata, stage)).filter(|g| g.last.len() >= 3) else { continue };
        for baseline in Method::BASELINES {
            let Some(theirs) = gathered.get(&(baseline, stage)) else { continue };
            let ratio = compare_noise(&ours.last, &theirs.last, reference)
                .map_err(|e| anyhow!("strata ÷ {} residual noise, {} frames: {e}", baseline.name(), stage.name()))?;
            ratios.insert((stage, baseline), ratio);
        }
    }
    Ok(ratios)
}

/// Where the raw residual noise of strata and a baseline differs but the denoised does
/// not (the denoiser hides the sampler), or the order reverses, said in a sentence.
fn hidden_by_denoiser(methods: &[Method], noise: &BTreeMap<(Stage, Method), NoiseRatio>) -> Vec<String> {
    let mut notes = Vec::new();
    for baseline in Method::BASELINES.into_iter().filter(|b| methods.contains(b)) {
        let (Some(raw), Some(denoised)) = (noise.get(&(Stage::Raw, baseline)), noise.get(&(Stage::Denoised, baseline)))
        else {
            continue;
        };
        if raw.differ() && !denoised.differ() {
            notes.push(format!(
                "the denoiser hides the sampler: strata ÷ {} residual noise is {raw} raw but {denoised} after it \
                 (no longer told apart)",
                baseline.name()
            ));
        } else if raw.differ() && denoised.differ() && (raw.ratio < 1.0) != (denoised.ratio < 1.0) {
            notes.push(format!(
                "the denoiser reverses the sampler's order: strata ÷ {} residual noise is {raw} raw but {denoised} \
                 after it",
                baseline.name()
            ));
        } else if raw.differ() && denoised.differ() {
            notes.push(format!(
                "strata ÷ {} residual noise stays distinguishable after the denoiser: {raw} raw, {denoised} after it",
                baseline.name()
            ));
        }
    }
    notes
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(width: u32, height: u32, value: impl Fn(u32, u32) -> f32) -> RgbImage {
        let pixels = (0..height).flat_map(|y| (0..width).map(move |x| (x, y))).map(|(x, y)| [value(x, y); 3]).collect();
        RgbImage { width, height, pixels }
    }

    /// Two synthetic methods whose per-pixel noise differs twofold in variance: the
    /// collector's residual-noise ratio finds 0.5 and tells them apart, the still camera's
    /// flicker ratio is about √0.5, and a constant offset shows as bias, not noise.
    #[test]
    fn the_collector_tells_apart_two_methods_whose_noise_differs_twofold() {
        let (width, height, frames, seeds) = (32, 32, 8, 6);
        let reference = image(width, height, |_, _| 1.0);
        let mut collector = ViewerCollector::new(frames, 8, false);
        let mut rng = crate::evaluation::test_noise::Rng::new(0x1234_5678);
        for (method, sigma, offset) in [(Method::Restir, 0.2_f64, 0.0_f32), (Method::Strata, 0.2 / 2f64.sqrt(), 0.05)] {
            for seed in 1..=seeds {
                for frame in 0..frames {
                    let noise: Vec<f32> =
                        (0..width * height).map(|_| (1.0 + sigma * rng.normal()) as f32 + offset).collect();
                    let shown = image(width, height, |x, y| noise[(y * width + x) as usize]);
                    let seen = SeenFrame {
                        method,
                        seed,
                        frame,
                        image: &shown,
                        denoised: None,
                        took: Duration::from_millis(10),
                        motion: None,
                    };
                    collector.add(seen, std::slice::from_ref(&reference));
                }
            }
        }
        let report = collector.finish(&[Method::Restir, Method::Strata], &reference).unwrap();
        let table = &report.tables[0];
        let ratio_row = table.rows.iter().find(|r| r.label == "÷ restir").unwrap();
        let noise: f64 = ratio_row.cells[2].split_whitespace().next().unwrap().parse().unwrap();
        assert!((noise - 0.5).abs() < 0.12, "residual noise ratio {noise}, want 0.5: {}", report.to_text());
        assert!(ratio_row.cells[2].contains('['), "an interval: {}", ratio_row.cells[2]);
        let flicker: f64 = ratio_row.cells[3].split_whitespace().next().unwrap().parse().unwrap();
        // strata's mean is 1.05, so its std ÷ mean is √0.5 / 1.05 of restir's.
        let want = 0.5f64.sqrt() / 1.05;
        assert!((flicker - want).abs() < 0.05, "flicker ratio {flicker}, want {want:.3}");
        let bias =
            |label: &str| -> f64 { table.rows.iter().find(|r| r.label == label).unwrap().cells[1].parse().unwrap() };
        // bias² of a 0.05 offset on a reference of 1: 0.0025 / (1 + 1e-4).
        assert!((bias("strata") - 0.0025).abs() < 5e-4, "strata bias² {}", bias("strata"));
        assert!(bias("restir").abs() < 5e-4, "restir bias² {}", bias("restir"));
        assert!(report.csv_text().lines().count() == 3, "{}", report.csv_text());
    }

    /// A single seed gives no split and no invented number: a note says why.
    #[test]
    fn a_single_seed_gives_a_note_not_a_number() {
        let reference = image(8, 8, |_, _| 1.0);
        let mut collector = ViewerCollector::new(1, 8, false);
        let shown = image(8, 8, |x, _| 1.0 + x as f32 * 0.01);
        let seen = SeenFrame {
            method: Method::Strata,
            seed: 1,
            frame: 0,
            image: &shown,
            denoised: None,
            took: Duration::ZERO,
            motion: None,
        };
        collector.add(seen, std::slice::from_ref(&reference));
        let report = collector.finish(&[Method::Strata], &reference).unwrap();
        assert!(report.tables.is_empty());
        assert!(report.to_text().contains("needs 2 seeds at least (strata raw frames have 1)"), "{}", report.to_text());
    }

    /// An image no larger than a block has no correlation: the run is measured without it
    /// and a note names why (the golden runs are 16x16 with blocks of 16).
    #[test]
    fn an_image_no_larger_than_a_block_leaves_the_correlation_out() {
        let reference = image(8, 8, |_, _| 1.0);
        let mut collector = ViewerCollector::new(2, 8, false);
        for seed in 1..=3 {
            for frame in 0..2 {
                let shown = image(8, 8, |x, y| 1.0 + ((x * 7 + y * 3 + seed * 5 + frame) % 11) as f32 * 0.01);
                let seen = SeenFrame {
                    method: Method::Strata,
                    seed,
                    frame,
                    image: &shown,
                    denoised: None,
                    took: Duration::ZERO,
                    motion: None,
                };
                collector.add(seen, std::slice::from_ref(&reference));
            }
        }
        let report = collector.finish(&[Method::Strata], &reference).unwrap();
        let row = &report.tables[0].rows[0];
        assert!(row.cells[5].is_empty() && row.cells[6].is_empty(), "{:?}", row.cells);
        assert!(report.to_text().contains("no correlation or spectrum (block size 8"), "{}", report.to_text());
    }
}
