//! The printed summary of `strata compare`: strata's whole-run ratio to each baseline and
//! the reference-free table of relative variance over seeds (with `variance.csv`).
//! Plain data in, text out; the command line decides what to show.

use super::compare::{FrameError, relmse_ratio_over_frames};
use super::metrics;
use crate::restir::Method;
use crate::rgb_image::RgbImage;
use anyhow::{Context, Result};

/// strata ÷ each baseline over the whole run, one paired ratio per baseline the errors
/// hold ([`relmse_ratio_over_frames`]).
pub fn print_ratio_over_frames(errors: &[FrameError], frames: u32) {
    for baseline in [Method::Restir, Method::RestirDisc] {
        if let Some(r) = relmse_ratio_over_frames(errors, Method::Strata, baseline) {
            println!(
                "strata ÷ {} over frames 1-{frames} (per seed, RelMSE summed over the frames): {:.4} ± {:.4} ({} seeds)",
                baseline.name(),
                r.mean,
                r.half_width,
                r.count
            );
        }
    }
}

/// The reference-free summary ([`super::variance`]), of the images and of their
/// luminance: each method's relative variance over seeds at the shown frames, strata's
/// ratio to each baseline with its jackknife interval, and `variance.csv` (method, frame,
/// relvar, vs_restir / vs_restir_disc ratio ± half-width for strata, relvar_luminance).
pub fn print_variance(
    methods: &[Method],
    shown: &[u32],
    seed_images: &std::collections::HashMap<(Method, u32), Vec<RgbImage>>,
    references: &[RgbImage],
    path: &std::path::Path,
) -> Result<()> {
    use super::variance::{relative_variance, variance_ratio};
    let reference = |frame: u32| references.get(frame as usize).unwrap_or(&references[0]).clone();
    let images = |method: Method, frame: u32| seed_images.get(&(method, frame)).cloned().unwrap_or_default();
    let grey_reference = |frame: u32| metrics::luminance_image(&reference(frame));
    let grey = |method: Method, frame: u32| images(method, frame).iter().map(metrics::luminance_image).collect();
    println!("relative variance over seeds (reference-free RelMSE; ratio ± 95% jackknife interval):");
    print_variance_rows(methods, shown, "", &images, &reference)?;
    println!("the same of luminance (the error without colour noise):");
    print_variance_rows(methods, shown, " luma", &grey, &grey_reference)?;
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
                    ratios += &format!(",{:.4},{:.4}", r.mean, r.half_width);
                } else {
                    ratios += ",,";
                }
            }
            let luminance = relative_variance(&grey(method, f), &grey_reference(f))?;
            csv += &format!("{},{},{value:.6e}{ratios},{luminance:.6e}\n", method.name(), f + 1);
        }
    }
    std::fs::write(path, csv).with_context(|| format!("{}: cannot write", path.display()))?;
    Ok(())
}

/// One table of [`print_variance`]: a row per method, then strata ÷ each baseline; row
/// labels end with `suffix`.
fn print_variance_rows(
    methods: &[Method],
    shown: &[u32],
    suffix: &str,
    images: &dyn Fn(Method, u32) -> Vec<RgbImage>,
    reference: &dyn Fn(u32) -> RgbImage,
) -> Result<()> {
    use super::variance::{relative_variance, variance_ratio};
    for &method in methods {
        print!("{:<18}", format!("{}{suffix}", method.name()));
        for &f in shown {
            let value = relative_variance(&images(method, f), &reference(f))?;
            print!(" | {:>20}", format!("{value:.4e}"));
        }
        println!();
    }
    if methods.contains(&Method::Strata) {
        for baseline in [Method::Restir, Method::RestirDisc] {
            if !methods.contains(&baseline) {
                continue;
            }
            print!("{:<18}", format!("÷ {}{suffix}", baseline.name()));
            for &f in shown {
                let r = variance_ratio(&images(Method::Strata, f), &images(baseline, f), &reference(f))?;
                print!(" | {:>20}", format!("{:.3} ± {:.3}", r.mean, r.half_width));
            }
            println!();
        }
    }
    Ok(())
}
