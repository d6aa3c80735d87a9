//! `strata compare`: the ReSTIR methods rendered from the same seeds, each frame
//! measured against a reference, with a CSV of every measurement and a summary of
//! mean ± 95 % confidence interval over seeds.

use crate::evaluation::metrics::{self, MeanInterval};
use strata_backends::Backend;
use strata_backends::backend::download;
use strata_kernels::block_grid::frame_shift;
use strata_kernels::denoise_types::DenoiseGuide;
use strata_render::denoise::{Denoiser, OidnDenoiser, OidnError, OidnLibrary, SvgfDenoiser};
use strata_render::histogram_pass::PassError;
use strata_render::render::{GpuScene, RenderSettings};
use strata_render::restir::{Method, RestirRenderer, RestirSettings};
use strata_render::rgb_image::RgbImage;
use strata_render::scene::Camera;

/// One frame's errors against the reference.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameError {
    /// The method.
    pub method: Method,
    /// Frame index (0-based).
    pub frame: u32,
    /// Render seed.
    pub seed: u32,
    /// The paper's RelMSE.
    pub relmse: f64,
    /// RelMSE after a σ = 1 px Gaussian.
    pub prelmse: f64,
    /// Mean squared error.
    pub mse: f64,
    /// The paper's RelMSE of luminance ([`metrics::relmse_luminance`]): the part of the
    /// error that is not colour noise. `None` when read from a CSV written before it.
    pub relmse_luminance: Option<f64>,
    /// Mean LDR-FLIP of the frame's preview against the reference's ([`super::flip`]).
    /// `None` when read from a CSV written before it or computed by a build without FLIP.
    pub flip: Option<f64>,
    /// The block-edge contrast of the frame's error on the selection's block grid
    /// ([`super::block_structure`]): 0 without block structure. `None` when it cannot be
    /// computed (no block edge inside the image) or was not measured.
    pub block_edge: Option<f64>,
}

/// One rendered frame as [`run_comparison`] hands it to its caller.
#[derive(Clone, Copy, Debug)]
pub struct SeenFrame<'a> {
    /// The method that rendered it.
    pub method: Method,
    /// The render seed.
    pub seed: u32,
    /// The frame index (0-based).
    pub frame: u32,
    /// The frame as shown (accumulated without temporal reuse).
    pub image: &'a RgbImage,
    /// The frame after the denoiser, with one.
    pub denoised: Option<&'a RgbImage>,
    /// Wall time of rendering it.
    pub took: std::time::Duration,
    /// With a moving camera, per pixel the previous frame's image position minus this
    /// frame's, in pixels (the denoiser guides' motion vectors); `None` for a still camera.
    pub motion: Option<&'a [[f32; 2]]>,
}

/// What to compare.
#[derive(Clone, Debug)]
pub struct Comparison {
    /// Methods, in order.
    pub methods: Vec<Method>,
    /// Frames per seed.
    pub frames: u32,
    /// Seeds (independent renders per method).
    pub seeds: Vec<u32>,
    /// Settings shared by every method (its `method` field is replaced). Without
    /// temporal reuse (`temporal` false) the frames are accumulated: frame f's image is
    /// the mean of frames 0..=f (Fig. 5 / 10).
    pub restir: RestirSettings,
    /// The camera of each frame (empty: the render settings' camera throughout).
    pub cameras: Vec<Camera>,
    /// The exposure of the previews, at which FLIP compares what a person sees.
    pub exposure: f32,
    /// The denoiser whose output is measured too (`--denoise`); `None`: raw frames only.
    pub denoise: Option<Denoiser>,
}

/// Every frame's errors: as rendered (shown: accumulated without temporal reuse) and,
/// with a denoiser, after it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ComparisonErrors {
    /// The frames as rendered (`errors.csv`).
    pub raw: Vec<FrameError>,
    /// The same frames denoised (`errors_denoised.csv`); empty without a denoiser.
    pub denoised: Vec<FrameError>,
}

/// One frame's [`FrameError`] against `reference`.
fn measure(
    method: Method,
    frame: u32,
    seed: u32,
    image: &RgbImage,
    reference: &RgbImage,
    comparison: &Comparison,
) -> Result<FrameError, PassError> {
    let selection = comparison.restir.selection;
    let measure = |e: Result<f64, metrics::MetricError>| e.map_err(|e| PassError::Input(e.to_string()));
    Ok(FrameError {
        method,
        frame,
        seed,
        relmse: measure(metrics::relmse(image, reference))?,
        prelmse: measure(metrics::prelmse(image, reference))?,
        mse: measure(metrics::mse(image, reference))?,
        relmse_luminance: Some(measure(metrics::relmse_luminance(image, reference))?),
        flip: super::flip::mean_flip(image, reference, comparison.exposure)
            .map_err(|e| PassError::Input(e.to_string()))?,
        block_edge: super::block_structure::block_edge_contrast(
            image,
            reference,
            selection.block_size,
            if selection.block_shift && method.uses_histogram() {
                frame_shift(selection.block_size, frame, seed)
            } else {
                (0, 0)
            },
        ),
    })
}

/// The denoiser of one method and seed's frames.
enum FrameDenoiser {
    /// SVGF's kernels on the run's backend, its history carried from frame to frame.
    Svgf(SvgfDenoiser),
    /// OIDN on the CPU: each frame's colour and guides downloaded and filtered alone.
    Oidn(OidnDenoiser),
}

/// `error` as the one line the command prints: `--denoise oidn: ...`.
pub fn oidn_error(error: OidnError) -> PassError {
    PassError::Input(format!("--denoise oidn: {error}"))
}

/// Renders every method × seed × frame of `comparison` and measures each frame against
/// its reference (`references[frame]`, or `references[0]` for every frame); `on_frame`
/// sees every frame ([`SeenFrame`]). The denoiser filters each frame as rendered (also
/// without temporal reuse, where the raw image scored is the mean of the frames so far):
/// SVGF with its history carried from frame to frame, OIDN each frame alone.
pub fn run_comparison(
    backend: &mut dyn Backend,
    scene: &GpuScene,
    render: &RenderSettings,
    scene_extent: f32,
    comparison: &Comparison,
    references: &[RgbImage],
    mut on_frame: impl FnMut(SeenFrame<'_>),
) -> Result<ComparisonErrors, PassError> {
    let mut errors = ComparisonErrors::default();
    // OIDN's library, found once for the whole run.
    let oidn = match comparison.denoise {
        Some(Denoiser::Oidn) => Some(OidnLibrary::find().map_err(oidn_error)?),
        _ => None,
    };
    for &method in &comparison.methods {
        for &seed in &comparison.seeds {
            let settings = RestirSettings { method, ..comparison.restir };
            let render = RenderSettings { seed, ..render.clone() };
            let mut renderer = RestirRenderer::new(backend, scene, &render, settings, scene_extent)?;
            let mut denoiser = None;
            let mut sum: Option<RgbImage> = None;
            let result = (|| {
                // A moving camera's guides give the motion vectors the viewer's error
                // change follows (super::viewer).
                let moving = !comparison.cameras.is_empty();
                if moving {
                    renderer.enable_guides(backend)?;
                }
                if let Some(chosen) = comparison.denoise {
                    renderer.enable_guides(backend)?;
                    let (width, height) = (render.camera.width, render.camera.height);
                    denoiser = Some(match chosen.svgf_settings() {
                        Some(settings) => FrameDenoiser::Svgf(SvgfDenoiser::new(backend, width, height, settings)?),
                        None => {
                            let library = match oidn {
                                Some(library) => library,
                                None => OidnLibrary::find().map_err(oidn_error)?,
                            };
                            FrameDenoiser::Oidn(OidnDenoiser::new(library, width, height).map_err(oidn_error)?)
                        }
                    });
                }
                for frame in 0..comparison.frames {
                    let camera = comparison.cameras.get(frame as usize);
                    let started = std::time::Instant::now();
                    let (image, stats) = renderer.render_frame(backend, camera)?;
                    let render_time = started.elapsed();
                    let reference = references.get(frame as usize).unwrap_or(&references[0]);
                    let name = format!("{} frame {}, seed {seed}", method.name(), frame + 1);
                    super::image_checks::check_frame(&image, &name).map_err(|e| PassError::Input(e.to_string()))?;
                    if stats.invalid_pixels > 0 {
                        return Err(PassError::Input(format!(
                            "{name}: {} pixels had invalid samples (a radiance that overflows, or a traversal \
                             stack overflow); not scored",
                            stats.invalid_pixels
                        )));
                    }
                    let denoised = match (&mut denoiser, renderer.denoiser_inputs()) {
                        (Some(denoiser), Some(inputs)) => {
                            let denoised = match denoiser {
                                FrameDenoiser::Svgf(svgf) => {
                                    let output =
                                        svgf.denoise(backend, inputs.colour, inputs.guides, inputs.previous_guides)?;
                                    let pixels: Vec<[f32; 4]> = download(backend, output)?;
                                    RgbImage::from_rgba(image.width, image.height, &pixels)
                                }
                                FrameDenoiser::Oidn(oidn) => {
                                    let colour: Vec<[f32; 4]> = download(backend, inputs.colour)?;
                                    let guides: Vec<DenoiseGuide> = download(backend, inputs.guides)?;
                                    oidn.denoise_frame(&colour, &guides).map_err(oidn_error)?
                                }
                            };
                            super::image_checks::check_frame(&denoised, &format!("{name}, denoised"))
                                .map_err(|e| PassError::Input(e.to_string()))?;
                            errors.denoised.push(measure(method, frame, seed, &denoised, reference, comparison)?);
                            Some(denoised)
                        }
                        _ => None,
                    };
                    let shown = if !comparison.restir.temporal {
                        let total = match sum.take() {
                            None => image,
                            Some(mut total) => {
                                for (t, p) in total.pixels.iter_mut().zip(&image.pixels) {
                                    for c in 0..3 {
                                        t[c] += p[c];
                                    }
                                }
                                total
                            }
                        };
                        let scale = 1.0 / (frame + 1) as f32;
                        let mean = RgbImage {
                            pixels: total.pixels.iter().map(|p| p.map(|c| c * scale)).collect(),
                            ..total.clone()
                        };
                        sum = Some(total);
                        mean
                    } else {
                        image
                    };
                    errors.raw.push(measure(method, frame, seed, &shown, reference, comparison)?);
                    let motion: Option<Vec<[f32; 2]>> = match renderer.denoiser_inputs() {
                        Some(inputs) if moving => {
                            let guides: Vec<DenoiseGuide> = download(backend, inputs.guides)?;
                            Some(guides.iter().map(|g| g.motion).collect())
                        }
                        _ => None,
                    };
                    on_frame(SeenFrame {
                        method,
                        seed,
                        frame,
                        image: &shown,
                        denoised: denoised.as_ref(),
                        took: render_time,
                        motion: motion.as_deref(),
                    });
                }
                Ok(())
            })();
            if let Some(FrameDenoiser::Svgf(svgf)) = denoiser {
                svgf.destroy(backend)?;
            }
            renderer.destroy(backend)?;
            result?;
        }
    }
    Ok(errors)
}

/// The CSV header [`errors_csv`] writes.
const CSV_HEADER: &str = "method,frame,seed,relmse,prelmse,mse,relmse_luminance,flip,block_edge";
/// How many of [`CSV_HEADER`]'s columns CSVs written before the later ones have (still
/// read): without the block-edge contrast, without FLIP, without the luminance RelMSE.
const EARLIER_COLUMNS: [usize; 3] = [8, 7, 6];

/// The CSV of `errors`: method, frame, seed, relmse, prelmse, mse, relmse_luminance,
/// flip, block_edge (frames 1-based; an unknown value is an empty field).
pub fn errors_csv(errors: &[FrameError]) -> String {
    let mut csv = format!("{CSV_HEADER}\n");
    for e in errors {
        let optional = |value: Option<f64>| value.map(|v| format!("{v:.6e}")).unwrap_or_default();
        let (luminance, flip, block_edge) = (optional(e.relmse_luminance), optional(e.flip), optional(e.block_edge));
        csv.push_str(&format!(
            "{},{},{},{:.6e},{:.6e},{:.6e},{luminance},{flip},{block_edge}\n",
            e.method.name(),
            e.frame + 1,
            e.seed,
            e.relmse,
            e.prelmse,
            e.mse
        ));
    }
    csv
}

/// RelMSE of `method` at `frame` (0-based) over seeds.
pub fn relmse_over_seeds(errors: &[FrameError], method: Method, frame: u32) -> MeanInterval {
    let values: Vec<f64> = errors.iter().filter(|e| e.method == method && e.frame == frame).map(|e| e.relmse).collect();
    MeanInterval::of(&values)
}

/// Per seed, the ratio of `method`'s RelMSE to `baseline`'s at `frame`, with its mean and
/// interval over seeds (paired: both rendered from the same seed).
pub fn relmse_ratio(errors: &[FrameError], method: Method, baseline: Method, frame: u32) -> Option<MeanInterval> {
    ratio_of(errors, method, baseline, frame, |e| Some(e.relmse))
}

/// [`relmse_ratio`] of the luminance RelMSE; `None` also when a frame lacks it.
pub fn luminance_relmse_ratio(
    errors: &[FrameError],
    method: Method,
    baseline: Method,
    frame: u32,
) -> Option<MeanInterval> {
    ratio_of(errors, method, baseline, frame, |e| e.relmse_luminance)
}

/// FLIP of `method` at `frame` over seeds; `None` when no row has one.
pub fn flip_over_seeds(errors: &[FrameError], method: Method, frame: u32) -> Option<MeanInterval> {
    let values: Vec<f64> =
        errors.iter().filter(|e| e.method == method && e.frame == frame).filter_map(|e| e.flip).collect();
    (!values.is_empty()).then(|| MeanInterval::of(&values))
}

/// Per seed, the ratio of `method`'s FLIP to `baseline`'s at `frame` (paired, as
/// [`relmse_ratio`]).
pub fn flip_ratio(errors: &[FrameError], method: Method, baseline: Method, frame: u32) -> Option<MeanInterval> {
    ratio_of(errors, method, baseline, frame, |e| e.flip)
}

/// Per seed, `value(method) / value(baseline)` at `frame`, with mean and interval.
fn ratio_of(
    errors: &[FrameError],
    method: Method,
    baseline: Method,
    frame: u32,
    value: impl Fn(&FrameError) -> Option<f64>,
) -> Option<MeanInterval> {
    let ours: Vec<(u32, f64)> = errors
        .iter()
        .filter(|e| e.method == method && e.frame == frame)
        .filter_map(|e| Some((e.seed, value(e)?)))
        .collect();
    let theirs: std::collections::HashMap<u32, f64> = errors
        .iter()
        .filter(|e| e.method == baseline && e.frame == frame)
        .filter_map(|e| Some((e.seed, value(e)?)))
        .collect();
    // A pair whose baseline error is 0 has no ratio (only an image equal to its
    // reference scores 0): it is left out rather than averaged as infinity.
    let ratios: Vec<f64> =
        ours.iter().filter_map(|(seed, a)| theirs.get(seed).filter(|&&b| b > 0.0).map(|b| a / b)).collect();
    (!ratios.is_empty()).then(|| MeanInterval::of(&ratios))
}

/// Per seed, `method`'s RelMSE summed over every frame divided by `baseline`'s, with its
/// mean and interval over seeds: one paired ratio for a whole run. The frames of one seed
/// are correlated (a reservoir lives on), so frames are pooled within a seed, never
/// counted as independent samples. The frames are those either method has; a seed that
/// lacks one of them, or has one twice, for either method is left out. The ratio of sums
/// is the per-frame ratios weighted by the baseline's error at each frame.
pub fn relmse_ratio_over_frames(errors: &[FrameError], method: Method, baseline: Method) -> Option<MeanInterval> {
    use std::collections::{BTreeMap, BTreeSet};
    let frames: BTreeSet<u32> =
        errors.iter().filter(|e| e.method == method || e.method == baseline).map(|e| e.frame).collect();
    // Each run's (frame, RelMSE) pairs, grouped in one pass over the rows.
    let mut runs: BTreeMap<(Method, u32), Vec<(u32, f64)>> = BTreeMap::new();
    for e in errors.iter().filter(|e| e.method == method || e.method == baseline) {
        runs.entry((e.method, e.seed)).or_default().push((e.frame, e.relmse));
    }
    // One run's RelMSE summed over the frames, if it has each of them exactly once.
    let summed = |m: Method, seed: u32| -> Option<f64> {
        let mut run = runs.get(&(m, seed))?.clone();
        run.sort_by_key(|&(frame, _)| frame);
        run.iter().map(|&(frame, _)| frame).eq(frames.iter().copied()).then(|| run.iter().map(|&(_, v)| v).sum())
    };
    let seeds: BTreeSet<u32> = runs.keys().map(|&(_, seed)| seed).collect();
    let ratios: Vec<f64> = seeds
        .iter()
        .filter_map(|&seed| Some(summed(method, seed)? / summed(baseline, seed).filter(|&b| b > 0.0)?))
        .collect();
    (!ratios.is_empty()).then(|| MeanInterval::of(&ratios))
}

/// The rows grouped by frame, in frame order (one pass; what per-frame statistics over
/// many frames walk, instead of every row per frame).
pub fn by_frame(errors: &[FrameError]) -> std::collections::BTreeMap<u32, Vec<FrameError>> {
    let mut frames: std::collections::BTreeMap<u32, Vec<FrameError>> = std::collections::BTreeMap::new();
    for e in errors {
        frames.entry(e.frame).or_default().push(*e);
    }
    frames
}

/// Reads the CSV [`errors_csv`] writes; an error names the line and what is wrong.
/// Besides each line's own fields, the rows together must be what a comparison writes:
/// at least one row, each (method, frame, seed) once, every method measured at the same
/// (frame, seed) pairs, and errors finite and 0 or more.
pub fn parse_errors_csv(text: &str) -> Result<Vec<FrameError>, String> {
    let rows = parse_rows(text)?;
    check_rows(&rows)?;
    Ok(rows.into_iter().map(|(_, error)| error).collect())
}

/// The rows as a whole: [`parse_errors_csv`]'s rules across lines.
fn check_rows(rows: &[(usize, FrameError)]) -> Result<(), String> {
    use std::collections::{BTreeMap, BTreeSet};
    if rows.is_empty() {
        return Err("no measurements: the file has its header and no rows".into());
    }
    let mut lines: BTreeMap<(Method, u32, u32), usize> = BTreeMap::new();
    for &(line, e) in rows {
        if let Some(first) = lines.insert((e.method, e.frame, e.seed), line) {
            return Err(format!(
                "line {line}: {} frame {}, seed {} is measured again (first on line {first})",
                e.method.name(),
                e.frame + 1,
                e.seed
            ));
        }
    }
    let methods: BTreeSet<Method> = rows.iter().map(|(_, e)| e.method).collect();
    for &(line, e) in rows {
        for &other in &methods {
            if !lines.contains_key(&(other, e.frame, e.seed)) {
                return Err(format!(
                    "{} has no row for frame {}, seed {} (line {line} has {}'s): every method must be measured at the \
                     same frames and seeds",
                    other.name(),
                    e.frame + 1,
                    e.seed,
                    e.method.name()
                ));
            }
        }
    }
    Ok(())
}

/// Each line's fields, with its line number.
fn parse_rows(text: &str) -> Result<Vec<(usize, FrameError)>, String> {
    let mut lines = text.lines();
    let header = lines.next().map(str::trim).unwrap_or_default();
    let all: Vec<&str> = CSV_HEADER.split(',').collect();
    let columns = match std::iter::once(all.len()).chain(EARLIER_COLUMNS).find(|&n| header == all[..n].join(",")) {
        Some(columns) => columns,
        None => return Err(format!("line 1: expected the header `{CSV_HEADER}`")),
    };
    let mut errors = Vec::new();
    for (index, line) in lines.enumerate().filter(|(_, l)| !l.trim().is_empty()) {
        let number = index + 2;
        let fields: Vec<&str> = line.split(',').collect();
        if fields.len() != columns {
            return Err(format!("line {number}: expected {columns} fields, found {}", fields.len()));
        }
        let method = <Method as clap::ValueEnum>::from_str(fields[0], false)
            .map_err(|_| format!("line {number}: unknown method `{}`", fields[0]))?;
        let int = |i: usize| fields[i].parse::<u32>().map_err(|e| format!("line {number}, field {}: {e}", i + 1));
        // Errors are finite and non-negative: anything else is a damaged file, not a
        // measurement to average. (0 is an image equal to its reference: no ratio to
        // it exists, and the summaries say so.)
        // A subnormal error (below 2.2e-308) is no RelMSE strata writes either: its
        // reciprocal overflows, so no ratio or log axis could show it.
        let float = |i: usize| match fields[i].parse::<f64>() {
            Ok(v) if v == 0.0 || (v.is_normal() && v > 0.0) => Ok(v),
            Ok(v) if v.is_finite() && v > 0.0 => Err(format!(
                "line {number}, field {}: `{}` is below the smallest normal number ({:e}): not an error strata writes",
                i + 1,
                fields[i],
                f64::MIN_POSITIVE
            )),
            Ok(_) => {
                Err(format!("line {number}, field {}: `{}` is not an error (finite, 0 or more)", i + 1, fields[i]))
            }
            Err(e) => Err(format!("line {number}, field {}: `{}`: {e}", i + 1, fields[i])),
        };
        let frame = int(1)?;
        if frame == 0 {
            return Err(format!("line {number}: frames are counted from 1"));
        }
        errors.push((
            number,
            FrameError {
                method,
                frame: frame - 1,
                seed: int(2)?,
                relmse: float(3)?,
                prelmse: float(4)?,
                mse: float(5)?,
                relmse_luminance: match fields.get(6) {
                    None | Some(&"") => None,
                    Some(_) => Some(float(6)?),
                },
                flip: match fields.get(7) {
                    None | Some(&"") => None,
                    Some(_) => Some(float(7)?),
                },
                block_edge: match fields.get(8) {
                    None | Some(&"") => None,
                    Some(text) => Some(text.parse::<f64>().ok().filter(|v| v.is_finite()).ok_or_else(|| {
                        format!("line {number}, field 9: `{text}` is not a block-edge contrast (a finite number)")
                    })?),
                },
            },
        ));
    }
    Ok(errors)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_csv_reads_back_and_bad_lines_are_named() {
        let error = |seed, relmse_luminance| FrameError {
            method: Method::RestirDisc,
            frame: 2,
            seed,
            relmse: 0.5,
            prelmse: 0.25,
            mse: 1e-3,
            relmse_luminance,
            flip: None,
            block_edge: None,
        };
        let errors = vec![
            error(7, Some(0.125)),
            error(8, None),
            FrameError { flip: Some(0.0625), block_edge: Some(-0.25), ..error(9, None) },
        ];
        assert_eq!(parse_errors_csv(&errors_csv(&errors)).unwrap(), errors);
        // CSVs written before the FLIP column still read.
        let without_flip = "method,frame,seed,relmse,prelmse,mse,relmse_luminance\nrestir-disc,3,8,0.5,0.25,1e-3,\n";
        assert_eq!(parse_errors_csv(without_flip).unwrap(), vec![error(8, None)]);
        // CSVs written before the luminance column still read.
        let old = "method,frame,seed,relmse,prelmse,mse\nrestir-disc,3,8,0.5,0.25,1e-3\n";
        assert_eq!(parse_errors_csv(old).unwrap(), vec![error(8, None)]);
        let bad_luminance = "method,frame,seed,relmse,prelmse,mse,relmse_luminance\nstrata,1,1,0.1,0.1,0.1,x\n";
        assert!(parse_errors_csv(bad_luminance).unwrap_err().contains("field 7"));
        let bad = "method,frame,seed,relmse,prelmse,mse\nstrata,1,1,0.1,0.1\n";
        assert!(parse_errors_csv(bad).unwrap_err().contains("line 2"));
        let unknown = "method,frame,seed,relmse,prelmse,mse\nfoo,1,1,0.1,0.1,0.1\n";
        assert!(parse_errors_csv(unknown).unwrap_err().contains("`foo`"));
        for value in ["NaN", "inf", "-0.5"] {
            let bad = format!("method,frame,seed,relmse,prelmse,mse\nstrata,1,1,{value},0.1,0.1\n");
            assert!(parse_errors_csv(&bad).unwrap_err().contains("field 4"), "{value}");
        }
    }

    #[test]
    fn the_ratio_over_frames_pools_frames_within_a_seed() {
        let error = |method, frame, seed, relmse| FrameError {
            method,
            frame,
            seed,
            relmse,
            prelmse: relmse,
            mse: relmse,
            relmse_luminance: None,
            flip: None,
            block_edge: None,
        };
        // Seed s: restir has RelMSE 3 and 1 at frames 0 and 1; strata 1 and 1, so the
        // pooled ratio is 2/4 for every seed, while the per-frame ratios are 1/3 and 1.
        let mut errors = Vec::new();
        for seed in 1..=3 {
            errors.extend([error(Method::Restir, 0, seed, 3.0), error(Method::Restir, 1, seed, 1.0)]);
            errors.extend([error(Method::Strata, 0, seed, 1.0), error(Method::Strata, 1, seed, 1.0)]);
        }
        let pooled = relmse_ratio_over_frames(&errors, Method::Strata, Method::Restir).unwrap();
        assert!((pooled.mean - 0.5).abs() < 1e-12 && pooled.half_width < 1e-12 && pooled.count == 3, "{pooled:?}");
        // A seed that lacks a frame is left out, not pooled over fewer frames.
        errors.push(error(Method::Strata, 0, 4, 100.0));
        errors.push(error(Method::Restir, 0, 4, 1.0));
        errors.push(error(Method::Restir, 1, 4, 1.0));
        let pooled = relmse_ratio_over_frames(&errors, Method::Strata, Method::Restir).unwrap();
        assert_eq!(pooled.count, 3);
        // So is a seed with a frame measured twice, even when the count of rows is right.
        errors.push(error(Method::Strata, 0, 4, 1.0));
        let pooled = relmse_ratio_over_frames(&errors, Method::Strata, Method::Restir).unwrap();
        assert_eq!(pooled.count, 3);
        // A third method with more frames does not change the pair's frames.
        errors.push(error(Method::RestirDisc, 7, 1, 1.0));
        assert_eq!(relmse_ratio_over_frames(&errors, Method::Strata, Method::Restir).unwrap().count, 3);
        assert!(relmse_ratio_over_frames(&errors, Method::Strata, Method::RestirDisc).is_none());
    }
}
