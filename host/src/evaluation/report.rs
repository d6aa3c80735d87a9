//! What `strata compare` does once the reference exists: every method and seed rendered
//! ([`super::compare::run_comparison`]), the first seed's images and error maps written,
//! `errors.csv`, `relmse.svg` and (with 3 seeds or more) `variance.csv`, and the summary
//! printed. Driven by [`ReportOptions`], a plain struct: the command line fills it from
//! its arguments, and anything else (a script, a test, a report page) can too.

use super::compare::{
    Comparison, FrameError, errors_csv, luminance_relmse_ratio, relmse_over_seeds, relmse_ratio, run_comparison,
};
use super::metrics::{self, MeanInterval, Metric};
use crate::render::{GpuScene, RenderSettings};
use crate::restir::Method;
use crate::rgb_image::RgbImage;
use anyhow::{Context, Result};
use std::path::PathBuf;
use std::time::Instant;

/// What to run and where to write it.
#[derive(Clone, Debug, PartialEq)]
pub struct ReportOptions {
    /// The methods, in the order their rows are printed.
    pub methods: Vec<Method>,
    /// Frames per seed.
    pub frames: u32,
    /// Independent renders (seeds 1..=N) per method.
    pub seeds: u32,
    /// Output folder (exists).
    pub out: PathBuf,
    /// Exposure of the PNG previews.
    pub exposure: f32,
    /// The scene's name in the plot's title.
    pub scene_name: String,
    /// Frames accumulated rather than temporally reused (said in the plot's title).
    pub accumulate: bool,
}

/// A paired ratio of one error column between two methods at one frame.
type RatioOf = fn(&[FrameError], Method, Method, u32) -> Option<MeanInterval>;

/// Renders every method and seed, writes the files and prints the summary (see the
/// module docs).
/// Runs `comparison`, writes its images, error maps and CSV, prints the summary.
pub fn run_and_report(
    options: &ReportOptions,
    backend: &mut dyn strata_backends::Backend,
    gpu_scene: &GpuScene,
    render: &RenderSettings,
    extent: f32,
    comparison: &Comparison,
    references: &[RgbImage],
) -> Result<()> {
    let total = u64::from(options.frames) * u64::from(options.seeds) * options.methods.len() as u64;
    let bar = indicatif::ProgressBar::new(total);
    let started = Instant::now();
    let mut write_error: Option<anyhow::Error> = None;
    let shown: Vec<u32> =
        (0..options.frames).filter(|f| (f + 1).is_power_of_two() || f + 1 == options.frames).collect();
    // Every seed's image of the shown frames, for the variance over seeds.
    let mut seed_images: std::collections::HashMap<(Method, u32), Vec<RgbImage>> = Default::default();
    let errors =
        run_comparison(backend, gpu_scene, render, extent, comparison, references, |method, seed, frame, image| {
            bar.inc(1);
            if options.seeds >= 3 && shown.contains(&frame) {
                seed_images.entry((method, frame)).or_default().push(image.clone());
            }
            // Images of the first seed: the first frame and every power of two.
            if seed == 1 && ((frame + 1).is_power_of_two() || frame + 1 == options.frames) {
                let stem = options.out.join(format!("{}_frame{:03}", method.name(), frame + 1));
                let result = (|| -> Result<()> {
                    image.write_exr(&stem.with_extension("exr"))?;
                    image.write_png(&stem.with_extension("png"), options.exposure)?;
                    let reference = references.get(frame as usize).unwrap_or(&references[0]);
                    let map = metrics::error_map(image, reference, Metric::Relmse)?;
                    let error_stem = options.out.join(format!("{}_frame{:03}_relmse", method.name(), frame + 1));
                    metrics::false_colour(&map, image.width, image.height)
                        .write_png(&error_stem.with_extension("png"), 1.0)?;
                    RgbImage {
                        width: image.width,
                        height: image.height,
                        pixels: map.iter().map(|&e| [e as f32; 3]).collect(),
                    }
                    .write_exr(&error_stem.with_extension("exr"))?;
                    Ok(())
                })();
                if let Err(error) = result {
                    write_error.get_or_insert(error);
                }
            }
        })?;
    bar.finish_and_clear();
    if let Some(error) = write_error {
        return Err(error);
    }
    let csv = options.out.join("errors.csv");
    std::fs::write(&csv, errors_csv(&errors)).with_context(|| format!("{}: cannot write", csv.display()))?;
    let title = format!(
        "{} {}x{}, {} seeds{}",
        options.scene_name,
        render.camera.width,
        render.camera.height,
        options.seeds,
        if options.accumulate { ", accumulated frames" } else { ", temporal reuse" }
    );
    let plot = options.out.join("relmse.svg");
    std::fs::write(&plot, super::plot::relmse_svg(&errors, &options.methods, options.frames, &title))
        .with_context(|| format!("{}: cannot write", plot.display()))?;
    println!(
        "{} frames x {} seeds x {} methods in {:.1} s; RelMSE (paper's form), mean ± 95% CI over seeds:",
        options.frames,
        options.seeds,
        options.methods.len(),
        started.elapsed().as_secs_f64()
    );
    print!("{:<18}", "method");
    for f in &shown {
        print!(" | {:>20}", format!("frame {}", f + 1));
    }
    println!();
    for &method in &options.methods {
        print!("{:<18}", method.name());
        for &f in &shown {
            print!(" | {:>20}", relmse_over_seeds(&errors, method, f).to_string());
        }
        println!();
    }
    if options.methods.contains(&Method::Strata) {
        for baseline in [Method::Restir, Method::RestirDisc] {
            if !options.methods.contains(&baseline) {
                continue;
            }
            for (suffix, ratio_of) in [("", relmse_ratio as RatioOf), (" luma", luminance_relmse_ratio)] {
                print!("{:<18}", format!("÷ {}{suffix}", baseline.name()));
                for &f in &shown {
                    let ratio = ratio_of(&errors, Method::Strata, baseline, f);
                    let text = ratio.map(|r| format!("{:.3} ± {:.3}", r.mean, r.half_width)).unwrap_or_default();
                    print!(" | {text:>20}");
                }
                println!();
            }
        }
        super::summary::print_ratio_over_frames(&errors, options.frames);
    }
    let mut wrote = format!("{}, {}", csv.display(), plot.display());
    if options.seeds >= 3 {
        let path = options.out.join("variance.csv");
        super::summary::print_variance(&options.methods, &shown, &seed_images, references, &path)?;
        wrote += &format!(", {}", path.display());
    }
    println!("wrote {wrote} and images in {}", options.out.display());
    Ok(())
}
