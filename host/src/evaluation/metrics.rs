//! Image error metrics against a reference, as the paper and the literature print them.
//!
//! Every metric is computed per RGB channel and pixel, then averaged over both:
//! - [`mse`]: (f − ref)²;
//! - [`relmse`]: the paper's form, (f − ref)² / (ref + 1e-4) (its Table 2 numbers);
//! - [`relmse_common`]: the form most renderers print, (f − ref)² / (ref² + 1e-2);
//! - [`prelmse`]: [`relmse`] after blurring both images with a Gaussian of σ = 1 px
//!   (perceptual RelMSE: blue-noise error distributions score lower than white noise);
//! - [`relmse_luminance`]: the paper's form on Rec. 709 luminance instead of per channel.
//!   It leaves out colour noise (errors that keep luminance), which ReSTIR's target p̂ =
//!   luminance cannot resample away, so it shows how much of [`relmse`] the selection
//!   of candidates can act on.
//!
//! [`error_map`] gives the per-pixel value of a metric (channel-averaged) for error
//! images. [`MeanInterval`] reports a mean with its 95 % confidence interval over
//! independent seeds.

use strata_render::rgb_image::RgbImage;

pub use strata_render::error_metric::Metric;

/// Why two images cannot be compared.
#[derive(Debug, thiserror::Error)]
pub enum MetricError {
    /// The sizes differ.
    #[error("image is {0}x{1} but the reference is {2}x{3}")]
    Size(u32, u32, u32, u32),
    /// An image is empty.
    #[error("the images are empty (0 pixels)")]
    Empty,
    /// A pixel is NaN or infinite.
    #[error("the {which} has a non-finite value at pixel ({x}, {y})")]
    NonFinite {
        /// `image` or `reference`.
        which: &'static str,
        /// Column.
        x: u32,
        /// Row.
        y: u32,
    },
    /// A variance over seeds needs at least three of them.
    #[error("a variance over seeds needs at least 3 seeds, got {0}")]
    TooFewSeeds(usize),
    /// Two methods' seed counts differ.
    #[error("{0} seeds against {1}: the methods must run from the same seeds")]
    SeedCounts(usize, usize),
    /// The exposure of a tone-mapped metric (FLIP) is not finite and positive.
    #[error("exposure {0}: must be finite and positive")]
    Exposure(f32),
}

/// Both images have the same, non-zero size and only finite values.
pub(crate) fn check(image: &RgbImage, reference: &RgbImage) -> Result<(), MetricError> {
    if (image.width, image.height) != (reference.width, reference.height) {
        return Err(MetricError::Size(image.width, image.height, reference.width, reference.height));
    }
    if image.pixels.is_empty() {
        return Err(MetricError::Empty);
    }
    for (which, img) in [("image", image), ("reference", reference)] {
        if let Some(i) = img.pixels.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
            let (x, y) = ((i % img.width as usize) as u32, (i / img.width as usize) as u32);
            return Err(MetricError::NonFinite { which, x, y });
        }
    }
    Ok(())
}

/// The per-pixel error of `image` against `reference` (mean over R, G, B), row-major.
pub fn error_map(image: &RgbImage, reference: &RgbImage, metric: Metric) -> Result<Vec<f64>, MetricError> {
    check(image, reference)?;
    metric.map(image, reference).ok_or(MetricError::Empty)
}

/// The mean of [`error_map`] ([`Metric::mean`], once the images' sizes and values have
/// been checked: the error names what is wrong with them).
pub fn mean_error(image: &RgbImage, reference: &RgbImage, metric: Metric) -> Result<f64, MetricError> {
    check(image, reference)?;
    metric.mean(image, reference).ok_or(MetricError::Empty)
}

/// Mean squared error.
pub fn mse(image: &RgbImage, reference: &RgbImage) -> Result<f64, MetricError> {
    mean_error(image, reference, Metric::Mse)
}

/// The paper's RelMSE: mean of (f − ref)² / (ref + 1e-4).
pub fn relmse(image: &RgbImage, reference: &RgbImage) -> Result<f64, MetricError> {
    mean_error(image, reference, Metric::Relmse)
}

/// The common RelMSE: mean of (f − ref)² / (ref² + 1e-2).
pub fn relmse_common(image: &RgbImage, reference: &RgbImage) -> Result<f64, MetricError> {
    mean_error(image, reference, Metric::RelmseCommon)
}

/// The paper's RelMSE of luminance: mean of (Y_f − Y_ref)² / (Y_ref + 1e-4), with Y the
/// Rec. 709 luminance of each pixel.
pub fn relmse_luminance(image: &RgbImage, reference: &RgbImage) -> Result<f64, MetricError> {
    check(image, reference)?;
    relmse(&luminance_image(image), &luminance_image(reference))
}

/// The grey image (Y, Y, Y) of each pixel's Rec. 709 luminance Y: any per-channel
/// metric of it is that metric of luminance.
pub fn luminance_image(image: &RgbImage) -> RgbImage {
    let grey = |c: &[f32; 3]| [0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; 3];
    RgbImage { pixels: image.pixels.iter().map(grey).collect(), ..*image }
}

/// Perceptual RelMSE: [`relmse`] of both images blurred by a Gaussian of σ = 1 px.
pub fn prelmse(image: &RgbImage, reference: &RgbImage) -> Result<f64, MetricError> {
    check(image, reference)?;
    relmse(&gaussian_blur(image, 1.0), &gaussian_blur(reference, 1.0))
}

/// `image` convolved with a normalised Gaussian of standard deviation `sigma` pixels,
/// truncated at 3σ, with clamp-to-edge borders (separable).
pub fn gaussian_blur(image: &RgbImage, sigma: f32) -> RgbImage {
    let radius = (3.0 * sigma).ceil() as i64;
    let weights: Vec<f32> = (-radius..=radius).map(|i| (-(i * i) as f32 / (2.0 * sigma * sigma)).exp()).collect();
    let total: f32 = weights.iter().sum();
    let weights: Vec<f32> = weights.iter().map(|w| w / total).collect();
    let (w, h) = (image.width as i64, image.height as i64);
    let pass = |source: &[[f32; 3]], horizontal: bool| -> Vec<[f32; 3]> {
        let mut out = vec![[0.0f32; 3]; source.len()];
        for y in 0..h {
            for x in 0..w {
                let mut sum = [0.0f32; 3];
                for (k, weight) in weights.iter().enumerate() {
                    let offset = k as i64 - radius;
                    let (sx, sy) =
                        if horizontal { ((x + offset).clamp(0, w - 1), y) } else { (x, (y + offset).clamp(0, h - 1)) };
                    let p = source[(sy * w + sx) as usize];
                    for c in 0..3 {
                        sum[c] += weight * p[c];
                    }
                }
                out[(y * w + x) as usize] = sum;
            }
        }
        out
    };
    let horizontal = pass(&image.pixels, true);
    RgbImage { width: image.width, height: image.height, pixels: pass(&horizontal, false) }
}

pub use strata_render::error_metric::false_colour;

/// A mean over independent samples with its 95 % confidence half-width (Student t).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeanInterval {
    /// Sample mean.
    pub mean: f64,
    /// Half-width of the 95 % confidence interval (infinite for fewer than 2 samples).
    pub half_width: f64,
    /// Number of samples.
    pub count: usize,
}

impl MeanInterval {
    /// The mean and 95 % interval of `values`.
    pub fn of(values: &[f64]) -> MeanInterval {
        let count = values.len();
        let mean = values.iter().sum::<f64>() / count.max(1) as f64;
        if count < 2 {
            return MeanInterval { mean, half_width: f64::INFINITY, count };
        }
        let variance = values.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / (count - 1) as f64;
        let half_width = student_t_975(count - 1) * (variance / count as f64).sqrt();
        MeanInterval { mean, half_width, count }
    }
}

impl MeanInterval {
    /// `mean ± half-width` with `decimals` decimals; with fewer than two samples, where
    /// no interval exists, `mean (1 seed: no interval)`; and `n/a` for a mean that could
    /// not be computed. Printed summaries never show NaN or infinity. A value of a million
    /// or more is written in scientific notation (`5.0000e299`, not 300 digits).
    pub fn fixed(&self, decimals: usize) -> String {
        self.text(|v| if v.abs() >= 1e6 { format!("{v:.decimals$e}") } else { format!("{v:.decimals$}") })
    }

    /// The text of the interval with `number` formatting each value ([`MeanInterval::fixed`]).
    fn text(&self, number: impl Fn(f64) -> String) -> String {
        if self.count == 0 || !self.mean.is_finite() {
            return "n/a".to_string();
        }
        if !self.half_width.is_finite() {
            let seeds = if self.count == 1 { "1 seed" } else { "seeds" };
            return format!("{} ({seeds}: no interval)", number(self.mean));
        }
        format!("{} ± {}", number(self.mean), number(self.half_width))
    }
}

impl std::fmt::Display for MeanInterval {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.half_width.is_finite() && self.mean.is_finite() && self.count > 0 {
            write!(f, "{:.4e} ± {:.1e}", self.mean, self.half_width)
        } else {
            write!(f, "{}", self.text(|v| format!("{v:.4e}")))
        }
    }
}

/// The 97.5 % quantile of Student's t distribution with `dof` degrees of freedom
/// (table to 30, then the normal approximation with the first Cornish–Fisher term).
pub fn student_t_975(dof: usize) -> f64 {
    const TABLE: [f64; 30] = [
        12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228, 2.201, 2.179, 2.160, 2.145, 2.131,
        2.120, 2.110, 2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064, 2.060, 2.056, 2.052, 2.048, 2.045, 2.042,
    ];
    match dof {
        0 => f64::INFINITY,
        1..=30 => TABLE[dof - 1],
        _ => {
            let z = 1.959964;
            z + (z * z * z + z) / (4.0 * dof as f64)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(width: u32, height: u32, f: impl Fn(u32, u32) -> [f32; 3]) -> RgbImage {
        let pixels = (0..height).flat_map(|y| (0..width).map(move |x| (x, y))).map(|(x, y)| f(x, y)).collect();
        RgbImage { width, height, pixels }
    }

    #[test]
    fn metrics_of_a_known_difference() {
        let reference = image(4, 2, |_, _| [1.0, 0.5, 0.0]);
        let f = image(4, 2, |_, _| [1.5, 0.5, 0.1]);
        let mse_expected = (0.25 + 0.0 + 0.01) / 3.0;
        assert!((mse(&f, &reference).unwrap() - mse_expected).abs() < 1e-7);
        let rel = (0.25 / (1.0 + 1e-4) + 0.01 / 1e-4) / 3.0;
        assert!((relmse(&f, &reference).unwrap() - rel).abs() < 1e-6);
        let common = (0.25 / 1.01 + 0.01 / 1e-2) / 3.0;
        assert!((relmse_common(&f, &reference).unwrap() - common).abs() < 1e-6);
        assert_eq!(relmse(&reference, &reference).unwrap(), 0.0);
    }

    #[test]
    fn luminance_relmse_ignores_colour_shifts_of_equal_luminance() {
        let reference = image(3, 2, |_, _| [0.5, 0.5, 0.5]);
        // Red up, green down by the amount that keeps 0.2126 r + 0.7152 g + 0.0722 b.
        let shifted = image(3, 2, |_, _| [0.5 + 0.7152 * 0.1, 0.5 - 0.2126 * 0.1, 0.5]);
        assert!(relmse_luminance(&shifted, &reference).unwrap() < 1e-12);
        assert!(relmse(&shifted, &reference).unwrap() > 1e-3);
        // A uniform grey error is the same per channel and in luminance.
        let brighter = image(3, 2, |_, _| [0.75, 0.75, 0.75]);
        let expected = 0.0625 / (0.5 + 1e-4);
        assert!((relmse_luminance(&brighter, &reference).unwrap() - expected).abs() < 1e-6);
        assert!((relmse(&brighter, &reference).unwrap() - expected).abs() < 1e-6);
        let nan = image(3, 2, |x, _| if x == 2 { [f32::NAN; 3] } else { [0.5; 3] });
        assert!(matches!(relmse_luminance(&nan, &reference), Err(MetricError::NonFinite { x: 2, .. })));
    }

    #[test]
    fn blur_keeps_constants_and_the_mean_and_lowers_white_noise() {
        let constant = image(9, 7, |_, _| [2.0, 3.0, 4.0]);
        for (a, b) in gaussian_blur(&constant, 1.0).pixels.iter().zip(&constant.pixels) {
            for c in 0..3 {
                assert!((a[c] - b[c]).abs() < 1e-5);
            }
        }
        let noise = image(32, 32, |x, y| {
            let v = if (x * 7 + y * 13) % 3 == 0 { 1.5 } else { 0.75 };
            [v; 3]
        });
        let reference = image(32, 32, |_, _| [1.0; 3]);
        let plain = relmse(&noise, &reference).unwrap();
        let perceptual = prelmse(&noise, &reference).unwrap();
        assert!(perceptual < plain * 0.5, "pRelMSE {perceptual} vs RelMSE {plain}");
    }

    #[test]
    fn bad_inputs_are_errors() {
        let a = image(2, 2, |_, _| [1.0; 3]);
        let b = image(3, 2, |_, _| [1.0; 3]);
        assert!(matches!(mse(&a, &b), Err(MetricError::Size(2, 2, 3, 2))));
        let nan = image(2, 2, |x, y| if (x, y) == (1, 1) { [f32::NAN; 3] } else { [1.0; 3] });
        let message = mse(&nan, &a).unwrap_err().to_string();
        assert!(message.contains("(1, 1)") && message.contains("image"), "{message}");
        let empty = image(0, 0, |_, _| [0.0; 3]);
        assert!(matches!(mse(&empty, &empty), Err(MetricError::Empty)));
    }

    #[test]
    fn interval_of_known_values() {
        let interval = MeanInterval::of(&[1.0, 2.0, 3.0, 4.0]);
        assert_eq!(interval.mean, 2.5);
        let sd = (5.0f64 / 3.0).sqrt();
        assert!((interval.half_width - 3.182 * sd / 2.0).abs() < 1e-9);
        assert!(MeanInterval::of(&[1.0]).half_width.is_infinite());
        // What is printed never says NaN or inf.
        assert_eq!(MeanInterval::of(&[0.5]).fixed(3), "0.500 (1 seed: no interval)");
        assert_eq!(MeanInterval::of(&[0.5]).to_string(), "5.0000e-1 (1 seed: no interval)");
        assert_eq!(MeanInterval::of(&[]).fixed(3), "n/a");
        assert_eq!(MeanInterval::of(&[1.0, 3.0]).fixed(1), "2.0 ± 12.7");
        assert_eq!(MeanInterval::of(&[5e299]).fixed(4), "5.0000e299 (1 seed: no interval)");
    }
}
