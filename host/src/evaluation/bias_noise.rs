//! Bias and residual noise, separately: what a method's error is made of, measured from N
//! images of one frame rendered from independent seeds. After a denoiser every method's
//! RelMSE can look alike, because the denoiser's own bias dominates it (issue 55); the
//! residual noise, the part that changes from seed to seed, is where the sampler still
//! shows.
//!
//! Per pixel and channel, with x₁ … x_N the seeds' values, r the reference, w = 1 / (r + 10⁻⁴)
//! the weight of the paper's RelMSE (`Metric::Relmse`),
//! m = (1/N) Σ xₛ the mean over seeds and s² = Σ (xₛ − m)² / (N − 1) the unbiased sample
//! variance:
//!
//! - **residual noise** s², an unbiased estimate of the variance σ² over seeds;
//! - **squared bias** (m − r)² − s²/N, an unbiased estimate of (E x − r)², since
//!   E[(m − r)²] = bias² + σ²/N: without the −s²/N term a method with no bias at all would
//!   show a bias of σ²/N. Per pixel the estimate can be negative; so can its mean, by
//!   sampling error, where there is no bias.
//!
//! Each is multiplied by w and averaged over pixels and channels. The two add up to the mean
//! over seeds of the seeds' RelMSE, exactly and not only in expectation, by the identity
//!
//! ```text
//! (1/N) Σₛ (xₛ − r)² = (m − r)² + ((N − 1)/N) s²
//!                    = [(m − r)² − s²/N] + s²        (squared bias + residual noise)
//! ```
//!
//! (expand (xₛ − r) = (xₛ − m) + (m − r); the cross term sums to zero). So
//! [`BiasNoise::relative_bias_squared`] + [`BiasNoise::relative_noise`] =
//! [`BiasNoise::relmse`]`.mean` up to rounding ([`BiasNoise::identity_gap`]), and in
//! expectation each seed's RelMSE is bias² + σ². [`BiasNoise::relative_noise`] is the
//! quantity `variance::relative_variance` measures, here from 2 seeds up.
//!
//! [`compare_noise`] says whether two methods' residual noise differ, with a 95 % interval
//! for their ratio from the delete-one-seed jackknife (its documentation says why seeds, and
//! not pixels, are the independent units).

use crate::evaluation::metrics::{MeanInterval, student_t_975};
use strata_render::rgb_image::RgbImage;

/// The ε of the paper's RelMSE, (f − r)² / (r + ε).
const EPSILON: f64 = 1e-4;

/// Why a bias/noise split or a noise comparison cannot be computed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SplitError {
    /// Fewer seeds than the estimate needs.
    #[error("{what} needs at least {needed} seeds, got {got}")]
    TooFewSeeds {
        /// What was asked for.
        what: &'static str,
        /// Seeds it needs.
        needed: usize,
        /// Seeds it got.
        got: usize,
    },
    /// A seed's image is not the size of the reference.
    #[error("seed {seed} is {width}x{height} but the reference is {reference_width}x{reference_height}")]
    Size {
        /// Index of the seed (from 0).
        seed: usize,
        /// Its width.
        width: u32,
        /// Its height.
        height: u32,
        /// The reference's width.
        reference_width: u32,
        /// The reference's height.
        reference_height: u32,
    },
    /// The reference has no pixels.
    #[error("the reference is empty (0 pixels)")]
    Empty,
    /// A value is NaN or infinite.
    #[error("{which} has a non-finite value at pixel ({x}, {y})")]
    NonFinite {
        /// `the reference` or `seed i`.
        which: String,
        /// Column.
        x: u32,
        /// Row.
        y: u32,
    },
    /// The reference is negative, where a relative error's weight 1 / (r + 10⁻⁴) means nothing.
    #[error("the reference is negative at pixel ({x}, {y}): relative errors divide by reference + 1e-4")]
    NegativeReference {
        /// Column.
        x: u32,
        /// Row.
        y: u32,
    },
    /// Two methods' seed counts differ where a seed is left out of both.
    #[error("{0} seeds against {1}: leaving one seed out of both methods needs as many seeds for each")]
    SeedCounts(usize, usize),
    /// A result is not finite. A safeguard: finite f32 values and weights of at most 10⁴
    /// keep every sum far inside f64's range.
    #[error("the {0} is not finite")]
    NonFiniteResult(&'static str),
    /// A method's residual noise is zero (with a seed left out, or at all), so no ratio exists.
    #[error("the {0} method's residual noise is 0 (with one seed left out, or at all): no ratio")]
    ZeroNoise(&'static str),
}

/// A method's error, split into squared bias and residual noise (module documentation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BiasNoise {
    /// Mean over pixels and channels of [(m − r)² − s²/N] / (r + 10⁻⁴): the unbiased
    /// estimate of the relative squared bias. Near 0, and possibly below, without bias.
    pub relative_bias_squared: f64,
    /// Mean over pixels and channels of s² / (r + 10⁻⁴): the relative residual noise.
    pub relative_noise: f64,
    /// Each seed's RelMSE (the paper's), averaged over the seeds, with its 95 % interval.
    pub relmse: MeanInterval,
    /// Number of seeds N.
    pub seeds: usize,
}

impl BiasNoise {
    /// `relmse.mean − (relative_bias_squared + relative_noise)`: zero up to rounding, by the
    /// identity of the module documentation.
    pub fn identity_gap(&self) -> f64 {
        self.relmse.mean - (self.relative_bias_squared + self.relative_noise)
    }

    /// Whether squared bias and residual noise add up to the mean RelMSE within 10⁻⁹ of it
    /// (rounding of f64 sums over pixels and seeds; a wrong estimator misses by far more).
    pub fn adds_up(&self) -> bool {
        self.identity_gap().abs() <= 1e-9 * self.relmse.mean.abs().max(f64::MIN_POSITIVE)
    }

    /// The share of the mean RelMSE that is squared bias (at most 1; negative only by
    /// sampling error where there is no bias). 0 for a zero RelMSE.
    pub fn bias_share(&self) -> f64 {
        if self.relmse.mean > 0.0 { self.relative_bias_squared / self.relmse.mean } else { 0.0 }
    }
}

/// The values of N seeds' images, per pixel and channel (index `3 · pixel + channel`):
/// weight w = 1 / (r + 10⁻⁴), the reference r, the mean m over seeds and the sum of squares
/// Σ (xₛ − m)² (two passes, so that a large mean does not cost the variance its digits).
struct Seeds<'a> {
    images: &'a [RgbImage],
    reference: Vec<f64>,
    weight: Vec<f64>,
    mean: Vec<f64>,
    squares: Vec<f64>,
}

impl<'a> Seeds<'a> {
    fn of(images: &'a [RgbImage], reference: &RgbImage) -> Seeds<'a> {
        let reference: Vec<f64> = reference.pixels.iter().flatten().map(|&r| f64::from(r)).collect();
        let weight = reference.iter().map(|r| 1.0 / (r + EPSILON)).collect();
        let n = images.len() as f64;
        let mut mean = vec![0.0; reference.len()];
        for image in images {
            for (m, &x) in mean.iter_mut().zip(image.pixels.iter().flatten()) {
                *m += f64::from(x);
            }
        }
        mean.iter_mut().for_each(|m| *m /= n);
        let mut squares = vec![0.0; reference.len()];
        for image in images {
            for ((q, &x), m) in squares.iter_mut().zip(image.pixels.iter().flatten()).zip(&mean) {
                let d = f64::from(x) - m;
                *q += d * d;
            }
        }
        Seeds { images, reference, weight, mean, squares }
    }

    fn count(&self) -> usize {
        self.images.len()
    }

    /// Mean of w · s² over pixels and channels.
    fn relative_noise(&self) -> f64 {
        let n = self.count() as f64;
        let total: f64 = self.weight.iter().zip(&self.squares).map(|(w, q)| w * q / (n - 1.0)).sum();
        total / self.weight.len() as f64
    }

    /// [`Seeds::relative_noise`] of the seeds without seed `i` (needs N ≥ 3):
    /// Σ_{s≠i} (xₛ − m₋ᵢ)² = Σ (xₛ − m)² − N/(N − 1) · (xᵢ − m)².
    fn relative_noise_without(&self, i: usize) -> f64 {
        let n = self.count() as f64;
        let total: f64 = self.images[i]
            .pixels
            .iter()
            .flatten()
            .zip(&self.mean)
            .zip(self.weight.iter().zip(&self.squares))
            .map(|((&x, m), (w, q))| {
                let d = f64::from(x) - m;
                w * (q - n / (n - 1.0) * d * d).max(0.0) / (n - 2.0)
            })
            .sum();
        total / self.weight.len() as f64
    }
}

/// Checks `images` (at least `needed` of them, for `what`) against `reference`: sizes,
/// finite values, a non-negative reference.
fn validate(images: &[RgbImage], reference: &RgbImage, needed: usize, what: &'static str) -> Result<(), SplitError> {
    if images.len() < needed {
        return Err(SplitError::TooFewSeeds { what, needed, got: images.len() });
    }
    if reference.pixels.is_empty() {
        return Err(SplitError::Empty);
    }
    let at = |i: usize| ((i % reference.width as usize) as u32, (i / reference.width as usize) as u32);
    if let Some(i) = reference.pixels.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
        let (x, y) = at(i);
        return Err(SplitError::NonFinite { which: "the reference".to_string(), x, y });
    }
    if let Some(i) = reference.pixels.iter().position(|p| p.iter().any(|&c| c < 0.0)) {
        let (x, y) = at(i);
        return Err(SplitError::NegativeReference { x, y });
    }
    for (seed, image) in images.iter().enumerate() {
        if (image.width, image.height) != (reference.width, reference.height)
            || image.pixels.len() != reference.pixels.len()
        {
            return Err(SplitError::Size {
                seed,
                width: image.width,
                height: image.height,
                reference_width: reference.width,
                reference_height: reference.height,
            });
        }
        if let Some(i) = image.pixels.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
            let (x, y) = at(i);
            return Err(SplitError::NonFinite { which: format!("seed {seed}"), x, y });
        }
    }
    Ok(())
}

/// The bias/noise split (module documentation) of `images`, one frame of one method rendered
/// from N ≥ 2 independent seeds, against `reference`. Errors name what is wrong: fewer than 2
/// seeds, a size that differs, a NaN or infinite value, a negative reference, or a result
/// that is not finite.
pub fn bias_noise(images: &[RgbImage], reference: &RgbImage) -> Result<BiasNoise, SplitError> {
    validate(images, reference, 2, "the bias/noise split")?;
    let seeds = Seeds::of(images, reference);
    let n = images.len() as f64;
    let values = seeds.weight.len() as f64;
    let relative_noise = seeds.relative_noise();
    let bias: f64 = (0..seeds.weight.len())
        .map(|k| {
            let d = seeds.mean[k] - seeds.reference[k];
            seeds.weight[k] * (d * d - seeds.squares[k] / (n - 1.0) / n)
        })
        .sum();
    let relative_bias_squared = bias / values;
    let per_seed: Vec<f64> = images
        .iter()
        .map(|image| {
            let total: f64 = image
                .pixels
                .iter()
                .flatten()
                .zip(seeds.reference.iter().zip(&seeds.weight))
                .map(|(&x, (r, w))| {
                    let d = f64::from(x) - r;
                    w * d * d
                })
                .sum();
            total / values
        })
        .collect();
    let relmse = MeanInterval::of(&per_seed);
    for (value, name) in [
        (relative_bias_squared, "relative squared bias"),
        (relative_noise, "relative residual noise"),
        (relmse.mean, "mean RelMSE"),
    ] {
        if !value.is_finite() {
            return Err(SplitError::NonFiniteResult(name));
        }
    }
    Ok(BiasNoise { relative_bias_squared, relative_noise, relmse, seeds: images.len() })
}

/// The ratio of two methods' residual noise with its 95 % interval ([`compare_noise`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NoiseRatio {
    /// relative noise of the first method ÷ that of the second.
    pub ratio: f64,
    /// Lower end of the 95 % interval.
    pub low: f64,
    /// Upper end of the 95 % interval.
    pub high: f64,
    /// Number of seeds of each method.
    pub seeds: usize,
}

impl NoiseRatio {
    /// Whether the methods' residual noise differ at the 95 % level: the interval leaves out 1.
    pub fn differ(&self) -> bool {
        self.low > 1.0 || self.high < 1.0
    }
}

impl std::fmt::Display for NoiseRatio {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{:.3} [{:.3}, {:.3}] ({} seeds)", self.ratio, self.low, self.high, self.seeds)
    }
}

/// Whether method `a`'s residual noise differs from method `b`'s: the ratio
/// [`BiasNoise::relative_noise`]`(a) ÷ (b)` with a 95 % interval, from N ≥ 3 seeds of each
/// (the same N; seed i of `a` and of `b` may share random numbers or not).
///
/// The interval comes from the delete-one-seed jackknife of the log ratio L = ln(A/B):
/// L₋ᵢ is L with seed i left out of both methods, v = (N − 1)/N · Σᵢ (L₋ᵢ − L̄)², and the
/// interval is exp(L ± t₀.₉₇₅(N − 1) · √v). Why this and not a paired test over pixels:
/// the seeds are the only independent units. A pixel's error is correlated with its
/// neighbours' (ReSTIR reuses them, strata's blocks share a sorted run, a denoiser blurs
/// them), so a t-interval over pixels would treat thousands of dependent values as
/// independent and be far too narrow. Over seeds, each relative noise is a mean over pixels
/// of unbiased variances, a U-statistic of the independent seed images whatever the
/// correlation inside an image, and the jackknife's variance of (a smooth function of)
/// U-statistics is consistent. The log makes the ratio's sampling distribution closer to
/// symmetric, so the interval's ends are not symmetric about the ratio. Leaving one seed out
/// leaves N − 1 ≥ 2 for a variance: hence N ≥ 3.
pub fn compare_noise(a: &[RgbImage], b: &[RgbImage], reference: &RgbImage) -> Result<NoiseRatio, SplitError> {
    validate(a, reference, 3, "a noise comparison")?;
    validate(b, reference, 3, "a noise comparison")?;
    if a.len() != b.len() {
        return Err(SplitError::SeedCounts(a.len(), b.len()));
    }
    let (sa, sb) = (Seeds::of(a, reference), Seeds::of(b, reference));
    let log_ratio = |na: f64, nb: f64| -> Result<f64, SplitError> {
        if na <= 0.0 {
            return Err(SplitError::ZeroNoise("first"));
        }
        if nb <= 0.0 {
            return Err(SplitError::ZeroNoise("second"));
        }
        Ok((na / nb).ln())
    };
    let full = log_ratio(sa.relative_noise(), sb.relative_noise())?;
    let n = a.len();
    let left_out = (0..n)
        .map(|i| log_ratio(sa.relative_noise_without(i), sb.relative_noise_without(i)))
        .collect::<Result<Vec<_>, _>>()?;
    let mean = left_out.iter().sum::<f64>() / n as f64;
    let spread = left_out.iter().map(|l| (l - mean) * (l - mean)).sum::<f64>() * (n - 1) as f64 / n as f64;
    let half = student_t_975(n - 1) * spread.sqrt();
    let result = NoiseRatio { ratio: full.exp(), low: (full - half).exp(), high: (full + half).exp(), seeds: n };
    if ![result.ratio, result.low, result.high].iter().all(|v| v.is_finite()) {
        return Err(SplitError::NonFiniteResult("noise ratio"));
    }
    Ok(result)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::evaluation::test_noise::Rng;

    /// A reference of `size` × `size` pixels with channel values between 0.25 and 4.
    fn reference(size: u32) -> RgbImage {
        let pixels = (0..size * size).map(|i| [0.25 + (i % 5) as f32 * 0.5, 1.0 + (i % 3) as f32, 4.0]).collect();
        RgbImage { width: size, height: size, pixels }
    }

    /// `seeds` images: each value r + bias · √r + σ · √r · g with g standard normal, so that
    /// the relative squared bias is bias² · r/(r + 10⁻⁴) ≈ bias² and the relative noise ≈ σ².
    fn method(reference: &RgbImage, bias: f64, sigma: f64, seeds: usize, rng: &mut Rng) -> Vec<RgbImage> {
        (0..seeds)
            .map(|_| RgbImage {
                pixels: reference
                    .pixels
                    .iter()
                    .map(|p| {
                        p.map(|r| {
                            let root = f64::from(r).sqrt();
                            (f64::from(r) + bias * root + sigma * root * rng.normal()) as f32
                        })
                    })
                    .collect(),
                ..reference.clone()
            })
            .collect()
    }

    /// The mean over the reference's values of r/(r + 10⁻⁴): the factor between bias² or
    /// σ² and their relative forms here (just below 1).
    fn shrink(reference: &RgbImage) -> f64 {
        let values: Vec<f64> = reference.pixels.iter().flatten().map(|&r| f64::from(r)).collect();
        values.iter().map(|r| r / (r + EPSILON)).sum::<f64>() / values.len() as f64
    }

    #[test]
    fn a_known_bias_and_noise_are_split_apart_and_add_up_to_the_relmse() {
        let reference = reference(64);
        let k = shrink(&reference);
        let mut rng = Rng::new(1);
        // bias 0.1, σ 0.2 (relative bias² 0.01, noise 0.04), 4 seeds of 64 × 64 × 3 values.
        // Standard errors over 12 288 values: noise 0.04 · √(2/3/12288) ≈ 3e-4; bias²
        // about 2 · 0.1 · 0.1/√12288 ≈ 2e-4. Uncorrected, the bias would be 0.01 + 0.04/4.
        let split = bias_noise(&method(&reference, 0.1, 0.2, 4, &mut rng), &reference).unwrap();
        assert!((split.relative_bias_squared - 0.01 * k).abs() < 1.5e-3, "{split:?}");
        assert!((split.relative_noise - 0.04 * k).abs() < 2e-3, "{split:?}");
        assert!(split.adds_up(), "gap {} in {split:?}", split.identity_gap());
        // In expectation each seed's RelMSE is bias² + σ² = 0.05.
        assert!((split.relmse.mean - 0.05 * k).abs() < 2.5e-3, "{split:?}");
        assert!((split.bias_share() - 0.2).abs() < 0.03, "{split:?}");
        // No bias: the corrected estimate is 0 within sampling error (uncorrected σ²/N = 0.01).
        let unbiased = bias_noise(&method(&reference, 0.0, 0.2, 4, &mut rng), &reference).unwrap();
        assert!(unbiased.relative_bias_squared.abs() < 1e-3, "{unbiased:?}");
        assert!((unbiased.relative_noise - 0.04 * k).abs() < 2e-3, "{unbiased:?}");
        assert!(unbiased.adds_up(), "{unbiased:?}");
    }

    #[test]
    fn two_seeds_suffice_and_the_identity_holds_exactly_for_any_values() {
        let reference = reference(8);
        let mut rng = Rng::new(2);
        for seeds in [2, 3, 7] {
            let images = method(&reference, 0.3, 1.5, seeds, &mut rng);
            let split = bias_noise(&images, &reference).unwrap();
            assert_eq!(split.seeds, seeds);
            assert!(split.adds_up(), "{seeds} seeds: gap {}", split.identity_gap());
            // By hand for the first value, N seeds: (1/N) Σ (x − r)² = (m − r)² + (N−1)/N s².
            let x: Vec<f64> = images.iter().map(|i| f64::from(i.pixels[0][0])).collect();
            let r = f64::from(reference.pixels[0][0]);
            let n = seeds as f64;
            let m = x.iter().sum::<f64>() / n;
            let s2 = x.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / (n - 1.0);
            let lhs = x.iter().map(|v| (v - r) * (v - r)).sum::<f64>() / n;
            assert!((lhs - ((m - r) * (m - r) + (n - 1.0) / n * s2)).abs() < 1e-12 * lhs.max(1.0));
        }
    }

    #[test]
    fn the_noise_is_the_variance_modules_relative_variance() {
        let reference = reference(16);
        let images = method(&reference, 0.2, 0.3, 5, &mut Rng::new(3));
        let split = bias_noise(&images, &reference).unwrap();
        let variance = crate::evaluation::variance::relative_variance(&images, &reference).unwrap();
        assert!((split.relative_noise / variance - 1.0).abs() < 1e-9, "{} vs {variance}", split.relative_noise);
    }

    #[test]
    fn noise_twice_as_large_is_told_apart_and_equal_noise_is_not() {
        // 20 independent experiments, 8 seeds of 32 × 32 each. Method b has twice a's noise
        // variance (σ² 0.02 against 0.01), both with the same bias, so their raw RelMSE also
        // differ about twofold: every experiment must call the ratio 0.5 different from 1.
        // Two methods of equal noise are called different at a 5 % rate (one in 20 expected);
        // more than 3 of 20 would have probability below 2 %.
        let reference = reference(32);
        let mut rng = Rng::new(4);
        let (mut told_apart, mut false_calls) = (0, 0);
        for _ in 0..20 {
            let a = method(&reference, 0.05, 0.1, 8, &mut rng);
            let b = method(&reference, 0.05, 0.1 * 2f64.sqrt(), 8, &mut rng);
            let same = method(&reference, 0.05, 0.1, 8, &mut rng);
            let twofold = compare_noise(&a, &b, &reference).unwrap();
            assert!((twofold.ratio - 0.5).abs() < 0.05, "{twofold}");
            assert!(twofold.low < twofold.ratio && twofold.ratio < twofold.high, "{twofold}");
            told_apart += usize::from(twofold.differ());
            let equal = compare_noise(&a, &same, &reference).unwrap();
            false_calls += usize::from(equal.differ());
        }
        assert_eq!(told_apart, 20, "twofold noise told apart in {told_apart} of 20");
        assert!(false_calls <= 3, "equal noise called different in {false_calls} of 20");
        // The very same images: ratio 1 with an interval of zero width, not a difference.
        let a = method(&reference, 0.05, 0.1, 4, &mut rng);
        let itself = compare_noise(&a, &a, &reference).unwrap();
        assert!((itself.ratio - 1.0).abs() < 1e-12 && !itself.differ(), "{itself}");
    }

    #[test]
    fn what_is_wrong_is_named() {
        let reference = reference(4);
        let mut rng = Rng::new(5);
        let one = method(&reference, 0.0, 0.1, 1, &mut rng);
        let message = bias_noise(&one, &reference).unwrap_err().to_string();
        assert_eq!(message, "the bias/noise split needs at least 2 seeds, got 1");
        let two = method(&reference, 0.0, 0.1, 2, &mut rng);
        let message = compare_noise(&two, &two, &reference).unwrap_err().to_string();
        assert_eq!(message, "a noise comparison needs at least 3 seeds, got 2");
        let mut images = method(&reference, 0.0, 0.1, 3, &mut rng);
        let message = compare_noise(&images, &images[..2], &reference).unwrap_err().to_string();
        assert!(message.contains("got 2"), "{message}");
        let four = method(&reference, 0.0, 0.1, 4, &mut rng);
        assert_eq!(compare_noise(&images, &four, &reference).unwrap_err(), SplitError::SeedCounts(3, 4));
        images[2] = RgbImage::new(3, 4);
        let message = bias_noise(&images, &reference).unwrap_err().to_string();
        assert_eq!(message, "seed 2 is 3x4 but the reference is 4x4");
        images[2] = reference.clone();
        images[1].pixels[6][1] = f32::NAN;
        let message = bias_noise(&images, &reference).unwrap_err().to_string();
        assert_eq!(message, "seed 1 has a non-finite value at pixel (2, 1)");
        images[1] = reference.clone();
        let mut negative = reference.clone();
        negative.pixels[5][2] = -0.5;
        let message = bias_noise(&images, &negative).unwrap_err().to_string();
        assert!(message.starts_with("the reference is negative at pixel (1, 1)"), "{message}");
        // Noiseless methods have no noise ratio.
        let still = vec![reference.clone(); 3];
        let message = compare_noise(&images, &still, &reference).unwrap_err().to_string();
        assert!(message.starts_with("the second method's residual noise is 0"), "{message}");
        assert_eq!(
            bias_noise(&[], &RgbImage::new(0, 0)).unwrap_err().to_string(),
            "the bias/noise split needs at least 2 seeds, got 0"
        );
        assert_eq!(
            bias_noise(&[RgbImage::new(0, 0), RgbImage::new(0, 0)], &RgbImage::new(0, 0)).unwrap_err(),
            SplitError::Empty
        );
    }
}
