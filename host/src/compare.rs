//! `strata compare`: the ReSTIR methods rendered from the same seeds, each frame
//! measured against a reference, with a CSV of every measurement and a summary of
//! mean ± 95 % confidence interval over seeds.

use crate::histogram_pass::PassError;
use crate::metrics::{self, MeanInterval};
use crate::render::{GpuScene, RenderSettings};
use crate::restir::{Method, RestirRenderer, RestirSettings};
use crate::rgb_image::RgbImage;
use crate::scene::Camera;
use strata_backends::Backend;

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
    /// Settings shared by every method (its `method` field is replaced).
    pub restir: RestirSettings,
    /// Average the frames instead of showing each (the accumulation mode): frame f's
    /// image is then the mean of frames 0..=f.
    pub accumulate: bool,
    /// The camera of each frame (empty: the render settings' camera throughout).
    pub cameras: Vec<Camera>,
}

/// Renders every method × seed × frame of `comparison` and measures each frame against
/// its reference (`references[frame]`, or `references[0]` for every frame); `on_frame`
/// sees every image (method, seed, frame, image).
pub fn run_comparison(
    backend: &mut dyn Backend,
    scene: &GpuScene,
    render: &RenderSettings,
    scene_extent: f32,
    comparison: &Comparison,
    references: &[RgbImage],
    mut on_frame: impl FnMut(Method, u32, u32, &RgbImage),
) -> Result<Vec<FrameError>, PassError> {
    let mut errors = Vec::new();
    for &method in &comparison.methods {
        for &seed in &comparison.seeds {
            let settings = RestirSettings { method, ..comparison.restir };
            let render = RenderSettings { seed, ..render.clone() };
            let mut renderer = RestirRenderer::new(backend, scene, &render, settings, scene_extent)?;
            let mut sum: Option<RgbImage> = None;
            let result = (|| {
                for frame in 0..comparison.frames {
                    let camera = comparison.cameras.get(frame as usize);
                    let (image, stats) = renderer.render_frame(backend, camera)?;
                    let reference = references.get(frame as usize).unwrap_or(&references[0]);
                    if stats.invalid_pixels > 0 {
                        return Err(PassError::Input(format!(
                            "{}: frame {frame}, seed {seed}: {} pixels had invalid samples",
                            method.name(),
                            stats.invalid_pixels
                        )));
                    }
                    let shown = if comparison.accumulate {
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
                    let measure = |e: Result<f64, metrics::MetricError>| e.map_err(|e| PassError::Input(e.to_string()));
                    errors.push(FrameError {
                        method,
                        frame,
                        seed,
                        relmse: measure(metrics::relmse(&shown, reference))?,
                        prelmse: measure(metrics::prelmse(&shown, reference))?,
                        mse: measure(metrics::mse(&shown, reference))?,
                    });
                    on_frame(method, seed, frame, &shown);
                }
                Ok(())
            })();
            renderer.destroy(backend)?;
            result?;
        }
    }
    Ok(errors)
}

/// The CSV of `errors`: method, frame, seed, relmse, prelmse, mse (frames 1-based).
pub fn errors_csv(errors: &[FrameError]) -> String {
    let mut csv = String::from("method,frame,seed,relmse,prelmse,mse\n");
    for e in errors {
        csv.push_str(&format!(
            "{},{},{},{:.6e},{:.6e},{:.6e}\n",
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
    let of = |m: Method| -> Vec<(u32, f64)> {
        errors.iter().filter(|e| e.method == m && e.frame == frame).map(|e| (e.seed, e.relmse)).collect()
    };
    let (ours, theirs) = (of(method), of(baseline));
    let ratios: Vec<f64> =
        ours.iter().filter_map(|(seed, a)| theirs.iter().find(|(s, _)| s == seed).map(|(_, b)| a / b)).collect();
    (!ratios.is_empty()).then(|| MeanInterval::of(&ratios))
}

/// Reads the CSV [`errors_csv`] writes; an error names the line and what is wrong.
pub fn parse_errors_csv(text: &str) -> Result<Vec<FrameError>, String> {
    let mut lines = text.lines();
    if lines.next().map(str::trim) != Some("method,frame,seed,relmse,prelmse,mse") {
        return Err("line 1: expected the header `method,frame,seed,relmse,prelmse,mse`".into());
    }
    let mut errors = Vec::new();
    for (index, line) in lines.enumerate().filter(|(_, l)| !l.trim().is_empty()) {
        let number = index + 2;
        let fields: Vec<&str> = line.split(',').collect();
        if fields.len() != 6 {
            return Err(format!("line {number}: expected 6 fields, found {}", fields.len()));
        }
        let method = <Method as clap::ValueEnum>::from_str(fields[0], false)
            .map_err(|_| format!("line {number}: unknown method `{}`", fields[0]))?;
        let int = |i: usize| fields[i].parse::<u32>().map_err(|e| format!("line {number}, field {}: {e}", i + 1));
        let float = |i: usize| fields[i].parse::<f64>().map_err(|e| format!("line {number}, field {}: {e}", i + 1));
        let frame = int(1)?;
        if frame == 0 {
            return Err(format!("line {number}: frames are counted from 1"));
        }
        errors.push(FrameError {
            method,
            frame: frame - 1,
            seed: int(2)?,
            relmse: float(3)?,
            prelmse: float(4)?,
            mse: float(5)?,
        });
    }
    Ok(errors)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_csv_reads_back_and_bad_lines_are_named() {
        let errors =
            vec![FrameError { method: Method::RestirDisc, frame: 2, seed: 7, relmse: 0.5, prelmse: 0.25, mse: 1e-3 }];
        assert_eq!(parse_errors_csv(&errors_csv(&errors)).unwrap(), errors);
        let bad = "method,frame,seed,relmse,prelmse,mse\nstrata,1,1,0.1,0.1\n";
        assert!(parse_errors_csv(bad).unwrap_err().contains("line 2"));
        let unknown = "method,frame,seed,relmse,prelmse,mse\nfoo,1,1,0.1,0.1,0.1\n";
        assert!(parse_errors_csv(unknown).unwrap_err().contains("`foo`"));
    }
}
