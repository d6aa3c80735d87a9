//! Reference-free error: the variance of a method's frame across independent seeds, in
//! the form of the paper's RelMSE.
//!
//! For an unbiased method the expected RelMSE against a reference r is
//! `mean over pixels of (Var f + (E f − r)²) / (r + 1e-4)`: the method's variance plus
//! the reference's own error, which is the same for every method. Where the reference
//! is grainy that shared term can dominate and pull every RelMSE ratio towards 1 (on
//! veach-ajar it turned out not to: its RelMSE is the methods' own variance). The
//! relative variance measured
//! across seeds, `mean of s² / (r + 1e-4)` with `s²` the unbiased sample variance of
//! the seeds' images per pixel and channel, leaves it out; the reference only scales
//! each pixel, exactly as in RelMSE.

use crate::evaluation::metrics::{MeanInterval, MetricError, student_t_975};
use strata_render::rgb_image::RgbImage;

/// Per pixel and channel: the sum and the sum of squares of the seeds' values.
struct Moments {
    sum: Vec<f64>,
    squares: Vec<f64>,
    count: usize,
}

impl Moments {
    fn of(images: &[RgbImage]) -> Moments {
        let len = images.first().map_or(0, |i| i.pixels.len() * 3);
        let mut moments = Moments { sum: vec![0.0; len], squares: vec![0.0; len], count: images.len() };
        for image in images {
            for (i, &v) in image.pixels.iter().flatten().enumerate() {
                let v = f64::from(v);
                moments.sum[i] += v;
                moments.squares[i] += v * v;
            }
        }
        moments
    }

    /// Relative variance of these moments less the image `left_out` (if any).
    fn relative_variance(&self, reference: &RgbImage, left_out: Option<&RgbImage>) -> f64 {
        let n = (self.count - usize::from(left_out.is_some())) as f64;
        let out: Vec<f64> =
            left_out.map_or_else(Vec::new, |i| i.pixels.iter().flatten().map(|&v| f64::from(v)).collect());
        let total: f64 = reference
            .pixels
            .iter()
            .flatten()
            .enumerate()
            .map(|(i, &r)| {
                let x = out.get(i).copied().unwrap_or(0.0);
                let (sum, squares) = (self.sum[i] - x, self.squares[i] - x * x);
                let variance = ((squares - sum * sum / n) / (n - 1.0)).max(0.0);
                variance / (f64::from(r) + 1e-4)
            })
            .sum();
        total / self.sum.len() as f64
    }
}

fn check(images: &[RgbImage], reference: &RgbImage) -> Result<(), MetricError> {
    if images.len() < 3 {
        return Err(MetricError::TooFewSeeds(images.len()));
    }
    images.iter().try_for_each(|image| crate::evaluation::metrics::check(image, reference))
}

/// Mean over pixels and channels of the seeds' sample variance ÷ (reference + 1e-4);
/// `images` are one frame of one method from independent seeds (at least 3).
pub fn relative_variance(images: &[RgbImage], reference: &RgbImage) -> Result<f64, MetricError> {
    check(images, reference)?;
    Ok(Moments::of(images).relative_variance(reference, None))
}

/// `relative_variance(a) ÷ relative_variance(b)` with a 95 % interval from the
/// delete-one-seed jackknife (seed i left out of both, as the methods ran from the same
/// seeds): half-width t₀.₉₇₅(n − 1) · √((n − 1)/n · Σ (θ₋ᵢ − θ̄)²).
pub fn variance_ratio(a: &[RgbImage], b: &[RgbImage], reference: &RgbImage) -> Result<MeanInterval, MetricError> {
    check(a, reference)?;
    check(b, reference)?;
    if a.len() != b.len() {
        return Err(MetricError::SeedCounts(a.len(), b.len()));
    }
    let (ma, mb) = (Moments::of(a), Moments::of(b));
    let ratio = ma.relative_variance(reference, None) / mb.relative_variance(reference, None);
    let n = a.len();
    let leave_out: Vec<f64> = (0..n)
        .map(|i| ma.relative_variance(reference, Some(&a[i])) / mb.relative_variance(reference, Some(&b[i])))
        .collect();
    let mean = leave_out.iter().sum::<f64>() / n as f64;
    let spread = leave_out.iter().map(|t| (t - mean) * (t - mean)).sum::<f64>() * (n - 1) as f64 / n as f64;
    Ok(MeanInterval { mean: ratio, half_width: student_t_975(n - 1) * spread.sqrt(), count: n })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `seeds` images of 64 × 64 pixels, each value reference · (1 + σ·noise) with
    /// noise of unit variance (a xorshift uniform scaled by √12).
    fn noisy(reference: &RgbImage, sigma: f64, seeds: usize, salt: u32) -> Vec<RgbImage> {
        let mut state = 0x1234_5678u32 ^ salt;
        (0..seeds)
            .map(|_| RgbImage {
                pixels: reference
                    .pixels
                    .iter()
                    .map(|p| {
                        p.map(|r| {
                            state ^= state << 13;
                            state ^= state >> 17;
                            state ^= state << 5;
                            let u = f64::from(state) / f64::from(u32::MAX) - 0.5;
                            (f64::from(r) * (1.0 + sigma * u * 12f64.sqrt())) as f32
                        })
                    })
                    .collect(),
                ..reference.clone()
            })
            .collect()
    }

    fn reference() -> RgbImage {
        RgbImage { width: 64, height: 64, pixels: (0..64 * 64).map(|i| [0.5 + (i % 7) as f32 * 0.1; 3]).collect() }
    }

    #[test]
    fn relative_variance_measures_the_seeds_spread_without_the_reference_error() {
        let reference = reference();
        let images = noisy(&reference, 0.2, 8, 1);
        // Var = (0.2 r)², divided by r: 0.04 · mean(r²/(r + 1e-4)) ≈ 0.04 · mean(r).
        let mean_r: f64 = reference.pixels.iter().map(|p| f64::from(p[0])).sum::<f64>() / 4096.0;
        let measured = relative_variance(&images, &reference).unwrap();
        assert!((measured / (0.04 * mean_r) - 1.0).abs() < 0.05, "{measured} vs {}", 0.04 * mean_r);
        // A reference off by 20 % everywhere changes RelMSE a lot, the variance barely.
        let wrong = RgbImage { pixels: reference.pixels.iter().map(|p| p.map(|r| r * 1.2)).collect(), ..reference };
        let against_wrong = relative_variance(&images, &wrong).unwrap();
        assert!((against_wrong / measured - 1.0 / 1.2).abs() < 0.01, "{against_wrong} vs {measured}");
    }

    #[test]
    fn the_ratio_and_its_interval_find_half_the_variance() {
        let reference = reference();
        let a = noisy(&reference, 0.1, 8, 2);
        let b = noisy(&reference, 0.1 * 2f64.sqrt(), 8, 3);
        let ratio = variance_ratio(&a, &b, &reference).unwrap();
        assert!((ratio.mean - 0.5).abs() < 0.03, "{ratio}");
        assert!(ratio.half_width > 0.0 && ratio.half_width < 0.1, "{ratio}");
        assert!((ratio.mean - 0.5).abs() < ratio.half_width * 2.0, "{ratio}");
    }

    #[test]
    fn too_few_seeds_and_mismatched_sizes_are_named() {
        let reference = reference();
        let error = relative_variance(&noisy(&reference, 0.1, 2, 4), &reference).unwrap_err().to_string();
        assert!(error.contains("at least 3 seeds, got 2"), "{error}");
        let small = RgbImage { width: 2, height: 2, pixels: vec![[1.0; 3]; 4] };
        let error = relative_variance(&noisy(&small, 0.1, 3, 5), &reference).unwrap_err().to_string();
        assert!(error.contains("2x2 but the reference is 64x64"), "{error}");
    }
}
