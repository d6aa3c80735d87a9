//! Correlation of the error between pixels: whether a method's error is white, clumped
//! (positively correlated neighbours, as ReSTIR's spatial reuse makes it, which a denoiser
//! mistakes for signal) or blue (negatively correlated neighbours, which a spatial filter
//! cancels). The paper leaves this open (§7); stratifying a block's pixels is the candidate
//! for negatively correlated errors (issue 55).
//!
//! The input is an [`ErrorField`], one scalar per pixel. [`ErrorField::relative_luminance`]
//! makes it from an image and its reference: ε = (Y − Y_ref) / √(Y_ref + 10⁻⁴), the Rec. 709
//! luminance error scaled so that ε² is the paper's RelMSE term of luminance (luminance,
//! because a denoiser's edge-stopping weights and a viewer both see luminance).
//! [`ErrorField::seed_residuals`] takes out the per-pixel mean over seeds first, so that a
//! denoiser's bias pattern, the same in every seed, does not pass for correlated noise.
//!
//! **Autocorrelation** ([`autocorrelation`]): with ε̄ the field's mean and
//! σ² = (1/P) Σₚ (εₚ − ε̄)² its variance over its P pixels, the normalised autocorrelation of
//! a set S of pixel pairs is
//!
//! ```text
//! ρ(S) = (1/|S|) Σ_{(a,b)∈S} (ε_a − ε̄)(ε_b − ε̄) / σ²
//! ```
//!
//! for the horizontal pairs (x, y), (x + k, y) and the vertical pairs (x, y), (x, y + k) at
//! each lag k = 1 … B, split into the pairs inside one B × B block and the pairs straddling a
//! block edge (pixel (x, y) lies in block ((x + sx) / B, (y + sy) / B) for the grid's shift
//! (sx, sy), as `BlockGrid::block_of` has it). White noise gives 0; errors shared within
//! blocks give a positive ρ inside and 0 across; complementary strata within a block give a
//! negative ρ inside. Each field gives one value per lag and kind; they are averaged over the
//! fields (the seeds) with a 95 % interval ([`MeanInterval`]).
//!
//! **Radial power spectrum** ([`radial_spectrum`]): E(u, v), the 2-D DFT of ε − ε̄
//! (`super::fft`), gives the normalised power S(u, v) = |E(u, v)|² / (P σ²), which is 1 in
//! expectation at every frequency for white noise (flat), and whose sum over the P − 1
//! frequencies other than 0 is exactly P (Parseval). Frequencies are in cycles per pixel,
//! fu = u/W folded to [−½, ½) (likewise fv), at radius f = √(fu² + fv²); the bins split
//! (0, ½] evenly and each reports the mean S of its frequencies (the corners beyond ½ are in
//! no bin). The one-number summary is the **low/high ratio**: the mean S over 0 < f ≤ ¼
//! divided by the mean S over f > ¼ (corners included): ≈ 1 for white noise, < 1 for blue
//! (high-pass) noise, > 1 for clumped (low-pass) noise.

use crate::evaluation::fft::{Complex, dft_2d};
use crate::evaluation::metrics::MeanInterval;
use strata_render::rgb_image::RgbImage;

/// Why a correlation or spectrum cannot be computed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum CorrelationError {
    /// No error fields, or too few seeds for residuals.
    #[error("{what} needs at least {needed} {of}, got {got}")]
    TooFew {
        /// What was asked for.
        what: &'static str,
        /// How many it needs.
        needed: usize,
        /// Of what: `error fields` or `seeds`.
        of: &'static str,
        /// How many it got.
        got: usize,
    },
    /// An image, reference or field is not the size of the others.
    #[error("{which} is {width}x{height} but {expected} is {expected_width}x{expected_height}")]
    Size {
        /// `image`, `seed i` or `error field i`.
        which: String,
        /// Its width.
        width: u32,
        /// Its height.
        height: u32,
        /// What it is compared with.
        expected: &'static str,
        /// That one's width.
        expected_width: u32,
        /// That one's height.
        expected_height: u32,
    },
    /// An error field's values do not fill its size.
    #[error("error field {field} has {values} values for {width}x{height} pixels")]
    Values {
        /// Field index.
        field: usize,
        /// Values it has.
        values: usize,
        /// Its width.
        width: u32,
        /// Its height.
        height: u32,
    },
    /// A value is NaN or infinite.
    #[error("{which} has a non-finite value at pixel ({x}, {y})")]
    NonFinite {
        /// `the image`, `the reference`, `seed i` or `error field i`.
        which: String,
        /// Column.
        x: u32,
        /// Row.
        y: u32,
    },
    /// The reference is negative, where 1 / √(r + 10⁻⁴) means nothing.
    #[error("the reference is negative at pixel ({x}, {y}): relative errors divide by reference + 1e-4")]
    NegativeReference {
        /// Column.
        x: u32,
        /// Row.
        y: u32,
    },
    /// The block size does not fit the fields.
    #[error("block size {block} needs fields wider and taller than it (and at least 1), got {width}x{height}")]
    BlockSize {
        /// The block size B.
        block: u32,
        /// Field width.
        width: u32,
        /// Field height.
        height: u32,
    },
    /// The fields are too small for a spectrum's two bands, or no bins were asked for.
    #[error("the spectrum needs at least 1 bin and 4x4 pixels, got {bins} bins of {width}x{height}")]
    Spectrum {
        /// Bins asked for.
        bins: usize,
        /// Field width.
        width: u32,
        /// Field height.
        height: u32,
    },
    /// A field is constant: it has no correlation and no normalised spectrum.
    #[error("error field {0} is constant (variance 0): no correlation or spectrum")]
    Constant(usize),
    /// A result is not finite.
    #[error("the {0} is not finite")]
    NonFiniteResult(&'static str),
}

/// One value per pixel, row-major: the error whose correlation is measured.
#[derive(Clone, Debug, PartialEq)]
pub struct ErrorField {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width × height` values, row-major.
    pub values: Vec<f64>,
}

/// Rec. 709 luminance.
fn luminance(p: &[f32; 3]) -> f64 {
    0.2126 * f64::from(p[0]) + 0.7152 * f64::from(p[1]) + 0.0722 * f64::from(p[2])
}

/// Checks a reference: finite and not negative.
fn check_reference(reference: &RgbImage) -> Result<(), CorrelationError> {
    let at = |i: usize| ((i % reference.width.max(1) as usize) as u32, (i / reference.width.max(1) as usize) as u32);
    if let Some(i) = reference.pixels.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
        let (x, y) = at(i);
        return Err(CorrelationError::NonFinite { which: "the reference".to_string(), x, y });
    }
    if let Some(i) = reference.pixels.iter().position(|p| p.iter().any(|&c| c < 0.0)) {
        let (x, y) = at(i);
        return Err(CorrelationError::NegativeReference { x, y });
    }
    Ok(())
}

/// Checks an image (named `which`) against the reference's size, and its values.
fn check_image(image: &RgbImage, reference: &RgbImage, which: String) -> Result<(), CorrelationError> {
    if (image.width, image.height) != (reference.width, reference.height)
        || image.pixels.len() != reference.pixels.len()
    {
        return Err(CorrelationError::Size {
            which,
            width: image.width,
            height: image.height,
            expected: "the reference",
            expected_width: reference.width,
            expected_height: reference.height,
        });
    }
    if let Some(i) = image.pixels.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
        let (x, y) = ((i % image.width as usize) as u32, (i / image.width as usize) as u32);
        return Err(CorrelationError::NonFinite { which, x, y });
    }
    Ok(())
}

impl ErrorField {
    /// The relative luminance error of `image` against `reference`:
    /// (Y − Y_ref) / √(Y_ref + 10⁻⁴) per pixel. An error for sizes that differ, a value that
    /// is not finite, or a negative reference.
    pub fn relative_luminance(image: &RgbImage, reference: &RgbImage) -> Result<ErrorField, CorrelationError> {
        check_reference(reference)?;
        check_image(image, reference, "the image".to_string())?;
        let values = image
            .pixels
            .iter()
            .zip(&reference.pixels)
            .map(|(f, r)| (luminance(f) - luminance(r)) / (luminance(r) + 1e-4).sqrt())
            .collect();
        Ok(ErrorField { width: image.width, height: image.height, values })
    }

    /// The noise of N ≥ 2 seeds' images of one frame without their bias: per seed s,
    /// (Yₛ − Ȳ) / √(Y_ref + 10⁻⁴) with Ȳ the mean luminance over the seeds at that pixel.
    /// What every seed shares (the reference's structure, a denoiser's bias) is gone; the
    /// normalised correlation and spectrum do not depend on the residuals' scale, which is
    /// √((N − 1)/N) of the noise's. The N residual fields sum to zero, so they are not quite
    /// independent (each value's correlation with another seed's is −1/(N − 1)): intervals
    /// over them are approximate, the more so the fewer the seeds.
    pub fn seed_residuals(images: &[RgbImage], reference: &RgbImage) -> Result<Vec<ErrorField>, CorrelationError> {
        if images.len() < 2 {
            return Err(CorrelationError::TooFew { what: "seed residuals", needed: 2, of: "seeds", got: images.len() });
        }
        check_reference(reference)?;
        for (seed, image) in images.iter().enumerate() {
            check_image(image, reference, format!("seed {seed}"))?;
        }
        let n = images.len() as f64;
        let mut mean = vec![0.0; reference.pixels.len()];
        for image in images {
            for (m, p) in mean.iter_mut().zip(&image.pixels) {
                *m += luminance(p) / n;
            }
        }
        let scale: Vec<f64> = reference.pixels.iter().map(|r| 1.0 / (luminance(r) + 1e-4).sqrt()).collect();
        Ok(images
            .iter()
            .map(|image| ErrorField {
                width: image.width,
                height: image.height,
                values: image.pixels.iter().zip(&mean).zip(&scale).map(|((p, m), s)| (luminance(p) - m) * s).collect(),
            })
            .collect())
    }
}

/// Checks `fields`: at least one, all of the first one's size, filled, finite, not constant.
/// Returns each field's mean and variance (1/P Σ (ε − ε̄)²).
fn check_fields(fields: &[ErrorField], what: &'static str) -> Result<Vec<(f64, f64)>, CorrelationError> {
    let Some(first) = fields.first() else {
        return Err(CorrelationError::TooFew { what, needed: 1, of: "error fields", got: 0 });
    };
    fields
        .iter()
        .enumerate()
        .map(|(i, field)| {
            if (field.width, field.height) != (first.width, first.height) {
                return Err(CorrelationError::Size {
                    which: format!("error field {i}"),
                    width: field.width,
                    height: field.height,
                    expected: "error field 0",
                    expected_width: first.width,
                    expected_height: first.height,
                });
            }
            if field.values.len() != field.width as usize * field.height as usize {
                return Err(CorrelationError::Values {
                    field: i,
                    values: field.values.len(),
                    width: field.width,
                    height: field.height,
                });
            }
            if let Some(j) = field.values.iter().position(|v| !v.is_finite()) {
                let (x, y) = ((j % field.width as usize) as u32, (j / field.width as usize) as u32);
                return Err(CorrelationError::NonFinite { which: format!("error field {i}"), x, y });
            }
            let p = field.values.len() as f64;
            let mean = field.values.iter().sum::<f64>() / p;
            let variance = field.values.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / p;
            if variance.is_nan() || variance <= 0.0 {
                return Err(CorrelationError::Constant(i));
            }
            Ok((mean, variance))
        })
        .collect()
}

/// The autocorrelation of one lag ([`autocorrelation`]), averaged over the fields.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LagCorrelation {
    /// The lag k in pixels.
    pub lag: u32,
    /// ρ over every pair at this lag.
    pub all: MeanInterval,
    /// ρ over the pairs inside one block; `None` where there are none (k ≥ B).
    pub inside_block: Option<MeanInterval>,
    /// ρ over the pairs straddling a block edge; `None` where there are none.
    pub across_edge: Option<MeanInterval>,
}

/// The normalised autocorrelation of the error at lags 1 … B ([`autocorrelation`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Autocorrelation {
    /// The block size B.
    pub block_size: u32,
    /// The grid's shift (sx, sy).
    pub shift: (u32, u32),
    /// Lags 1 … B along rows: pairs (x, y), (x + k, y).
    pub horizontal: Vec<LagCorrelation>,
    /// Lags 1 … B along columns: pairs (x, y), (x, y + k).
    pub vertical: Vec<LagCorrelation>,
}

/// Sums of (ε_a − ε̄)(ε_b − ε̄) and pair counts for one lag of one field: all, inside, across.
#[derive(Clone, Copy, Default)]
struct PairSums {
    sums: [f64; 3],
    counts: [usize; 3],
}

/// The normalised autocorrelation (module documentation) of `fields` (one per seed, all of
/// one size) at horizontal and vertical lags 1 … `block_size`, inside blocks and across block
/// edges of the grid of `block_size` × `block_size` blocks shifted by `shift`. An error for no
/// fields, fields that differ in size or are constant or not finite, or a block size of 0 or
/// not smaller than the fields.
pub fn autocorrelation(
    fields: &[ErrorField],
    block_size: u32,
    shift: (u32, u32),
) -> Result<Autocorrelation, CorrelationError> {
    let moments = check_fields(fields, "the autocorrelation")?;
    let (width, height) = (fields[0].width, fields[0].height);
    if block_size == 0 || block_size >= width || block_size >= height {
        return Err(CorrelationError::BlockSize { block: block_size, width, height });
    }
    let (w, h, b) = (width as usize, height as usize, block_size as usize);
    let (sx, sy) = (shift.0 as usize % b, shift.1 as usize % b);
    // [field][lag − 1] for each direction.
    let along = |horizontal: bool| -> Vec<Vec<PairSums>> {
        fields
            .iter()
            .zip(&moments)
            .map(|(field, &(mean, _))| {
                (1..=b)
                    .map(|k| {
                        let mut sums = PairSums::default();
                        let (xs, ys) = if horizontal { (w - k, h) } else { (w, h - k) };
                        for y in 0..ys {
                            for x in 0..xs {
                                let (xb, yb) = if horizontal { (x + k, y) } else { (x, y + k) };
                                let product = (field.values[y * w + x] - mean) * (field.values[yb * w + xb] - mean);
                                let inside = if horizontal {
                                    (x + sx) / b == (xb + sx) / b
                                } else {
                                    (y + sy) / b == (yb + sy) / b
                                };
                                for class in [0, if inside { 1 } else { 2 }] {
                                    sums.sums[class] += product;
                                    sums.counts[class] += 1;
                                }
                            }
                        }
                        sums
                    })
                    .collect()
            })
            .collect()
    };
    let summarise = |sums: Vec<Vec<PairSums>>| -> Result<Vec<LagCorrelation>, CorrelationError> {
        (0..b)
            .map(|lag| {
                let class = |c: usize| -> Result<Option<MeanInterval>, CorrelationError> {
                    let values: Vec<f64> = sums
                        .iter()
                        .zip(&moments)
                        .filter(|(s, _)| s[lag].counts[c] > 0)
                        .map(|(s, &(_, variance))| s[lag].sums[c] / s[lag].counts[c] as f64 / variance)
                        .collect();
                    if values.is_empty() {
                        return Ok(None);
                    }
                    let interval = MeanInterval::of(&values);
                    if !interval.mean.is_finite() {
                        return Err(CorrelationError::NonFiniteResult("autocorrelation"));
                    }
                    Ok(Some(interval))
                };
                Ok(LagCorrelation {
                    lag: lag as u32 + 1,
                    all: class(0)?.ok_or(CorrelationError::NonFiniteResult("autocorrelation"))?,
                    inside_block: class(1)?,
                    across_edge: class(2)?,
                })
            })
            .collect()
    };
    let horizontal = summarise(along(true))?;
    let vertical = summarise(along(false))?;
    Ok(Autocorrelation { block_size, shift, horizontal, vertical })
}

/// One radial bin of the spectrum ([`radial_spectrum`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpectrumBin {
    /// Lower end of the bin's radial frequency, cycles per pixel (inclusive).
    pub low: f64,
    /// Upper end (exclusive, except ½ for the last bin).
    pub high: f64,
    /// Frequencies (u, v) of each field in the bin.
    pub frequencies: usize,
    /// Mean normalised power S over the bin's frequencies, averaged over the fields (1 for
    /// white noise); `None` where the bin holds no frequency (fields too small for the bins).
    pub power: Option<MeanInterval>,
}

/// The error's radial power spectrum and its low/high summary ([`radial_spectrum`]).
#[derive(Clone, Debug, PartialEq)]
pub struct RadialSpectrum {
    /// The bins, from frequency 0 to ½.
    pub bins: Vec<SpectrumBin>,
    /// Mean S at 0 < f ≤ ¼ ÷ mean S at f > ¼, averaged over the fields: ≈ 1 white, < 1 blue,
    /// > 1 clumped.
    pub low_high_ratio: MeanInterval,
}

/// For one field, the normalised power S(u, v) with the radius f of each frequency (index
/// v · W + u), DC excluded.
fn normalised_power(field: &ErrorField, mean: f64, variance: f64) -> Vec<(f64, f64)> {
    let (w, h) = (field.width as usize, field.height as usize);
    let mut spectrum: Vec<Complex> = field.values.iter().map(|v| [v - mean, 0.0]).collect();
    dft_2d(&mut spectrum, w, h);
    let p = (w * h) as f64;
    let folded = |k: usize, n: usize| if 2 * k < n { k as f64 / n as f64 } else { k as f64 / n as f64 - 1.0 };
    spectrum
        .iter()
        .enumerate()
        .skip(1)
        .map(|(i, c)| {
            let (fu, fv) = (folded(i % w, w), folded(i / w, h));
            ((fu * fu + fv * fv).sqrt(), (c[0] * c[0] + c[1] * c[1]) / (p * variance))
        })
        .collect()
}

/// The radial power spectrum (module documentation) of `fields` (one per seed, all of one
/// size, at least 4 × 4) in `bins` bins over (0, ½] cycles per pixel, and its low/high ratio.
/// An error for no fields or bins, fields that differ in size, are too small, constant or not
/// finite.
pub fn radial_spectrum(fields: &[ErrorField], bins: usize) -> Result<RadialSpectrum, CorrelationError> {
    let moments = check_fields(fields, "the spectrum")?;
    let (width, height) = (fields[0].width, fields[0].height);
    if bins == 0 || width < 4 || height < 4 {
        return Err(CorrelationError::Spectrum { bins, width, height });
    }
    let bin_of = |f: f64| -> Option<usize> { (f <= 0.5).then(|| ((f / 0.5 * bins as f64) as usize).min(bins - 1)) };
    let mut per_bin: Vec<Vec<f64>> = vec![Vec::new(); bins];
    let mut counts = vec![0usize; bins];
    let mut ratios = Vec::with_capacity(fields.len());
    for (field, &(mean, variance)) in fields.iter().zip(&moments) {
        let power = normalised_power(field, mean, variance);
        let mut sums = vec![0.0; bins];
        counts.iter_mut().for_each(|c| *c = 0);
        let (mut low, mut high) = ([0.0, 0.0], [0.0, 0.0]);
        for &(f, s) in &power {
            if let Some(bin) = bin_of(f) {
                sums[bin] += s;
                counts[bin] += 1;
            }
            let band = if f <= 0.25 { &mut low } else { &mut high };
            band[0] += s;
            band[1] += 1.0;
        }
        for ((values, sum), &count) in per_bin.iter_mut().zip(&sums).zip(&counts) {
            if count > 0 {
                values.push(sum / count as f64);
            }
        }
        let (low_mean, high_mean) = (low[0] / low[1], high[0] / high[1]);
        if high_mean <= 0.0 {
            return Err(CorrelationError::NonFiniteResult("low/high ratio"));
        }
        ratios.push(low_mean / high_mean);
    }
    let low_high_ratio = MeanInterval::of(&ratios);
    if !low_high_ratio.mean.is_finite() {
        return Err(CorrelationError::NonFiniteResult("low/high ratio"));
    }
    let bins = per_bin
        .iter()
        .zip(&counts)
        .enumerate()
        .map(|(i, (values, &frequencies))| SpectrumBin {
            low: 0.5 * i as f64 / bins as f64,
            high: 0.5 * (i + 1) as f64 / bins as f64,
            frequencies,
            power: (!values.is_empty()).then(|| MeanInterval::of(values)),
        })
        .collect();
    Ok(RadialSpectrum { bins, low_high_ratio })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::evaluation::test_noise::Rng;

    fn field(width: u32, height: u32, value: impl FnMut(usize, usize) -> f64) -> ErrorField {
        let mut value = value;
        let values = (0..(width * height) as usize).map(|i| value(i % width as usize, i / width as usize)).collect();
        ErrorField { width, height, values }
    }

    fn white(size: u32, rng: &mut Rng) -> ErrorField {
        field(size, size, |_, _| rng.normal())
    }

    /// Separable AR(1) noise plus an `offset`: along each row εₓ = ρₕ εₓ₋₁ + √(1 − ρₕ²) g
    /// (stationary from x = 0), then the same along each column with ρᵥ. Its autocorrelation
    /// is ρₕᵏ at horizontal lag k and ρᵥᵏ at vertical lag k.
    fn ar1(size: u32, rho_h: f64, rho_v: f64, offset: f64, rng: &mut Rng) -> ErrorField {
        let n = size as usize;
        let mut rows = white(size, rng).values;
        for y in 0..n {
            for x in 1..n {
                rows[y * n + x] = rho_h * rows[y * n + x - 1] + (1.0 - rho_h * rho_h).sqrt() * rows[y * n + x];
            }
        }
        // The same filter down each column, with the row-filtered values as innovations:
        // rows are independent of each other, so the covariance is ρₕ^|dx| · ρᵥ^|dy|.
        for x in 0..n {
            for y in 1..n {
                rows[y * n + x] = rho_v * rows[(y - 1) * n + x] + (1.0 - rho_v * rho_v).sqrt() * rows[y * n + x];
            }
        }
        ErrorField { width: size, height: size, values: rows.iter().map(|v| v + offset).collect() }
    }

    fn close(interval: Option<MeanInterval>, expected: f64, tolerance: f64, what: &str) {
        let interval = interval.unwrap_or_else(|| panic!("{what}: no value"));
        assert!((interval.mean - expected).abs() < tolerance, "{what}: {interval} against {expected}");
    }

    #[test]
    fn ar1_noise_has_its_known_correlation_at_every_lag() {
        // ρₕ = 0.6, ρᵥ = −0.3, offset 5 (so that a mean left in would read as correlation
        // near 1); 4 fields of 128 × 128: standard error of a lag's ρ ≈ 1/√(4 · 16384) ≈ 0.004.
        let mut rng = Rng::new(31);
        let fields: Vec<ErrorField> = (0..4).map(|_| ar1(128, 0.6, -0.3, 5.0, &mut rng)).collect();
        let measured = autocorrelation(&fields, 4, (0, 0)).unwrap();
        for (k, (h, v)) in measured.horizontal.iter().zip(&measured.vertical).enumerate() {
            let k = k as i32 + 1;
            assert_eq!((h.lag, v.lag), (k as u32, k as u32));
            close(Some(h.all), 0.6f64.powi(k), 0.03, &format!("horizontal lag {k}"));
            close(Some(v.all), (-0.3f64).powi(k), 0.03, &format!("vertical lag {k}"));
            // Stationary noise: the same inside blocks and across their edges.
            close(h.across_edge, 0.6f64.powi(k), 0.04, &format!("horizontal lag {k} across"));
            if k < 4 {
                close(h.inside_block, 0.6f64.powi(k), 0.04, &format!("horizontal lag {k} inside"));
            } else {
                assert_eq!(h.inside_block, None, "lag B has no pair inside a block");
            }
            assert_eq!(h.all.count, 4);
        }
        // White noise: 0 at every lag.
        let white: Vec<ErrorField> = (0..4).map(|_| white(128, &mut rng)).collect();
        for lag in autocorrelation(&white, 8, (0, 0)).unwrap().horizontal {
            close(Some(lag.all), 0.0, 0.02, "white noise");
        }
    }

    #[test]
    fn errors_shared_within_blocks_correlate_inside_and_not_across() {
        // ε = g + c(block), var g = var c = 1: inside a block ρ = ½ at every lag < B, across
        // an edge 0 (blocks independent). On a grid shifted by (3, 5), measured on that grid
        // and on the unshifted one. 4 fields of 17 × 17 blocks: the sample variance of the
        // block offsets, which sets ρ, is within about ± 0.04 of 1.
        let mut rng = Rng::new(32);
        let blocky = |shift: (usize, usize), rng: &mut Rng| {
            let offsets: Vec<f64> = (0..17 * 17).map(|_| rng.normal()).collect();
            field(128, 128, |x, y| rng.normal() + offsets[(y + shift.1) / 8 * 17 + (x + shift.0) / 8])
        };
        let fields: Vec<ErrorField> = (0..4).map(|_| blocky((3, 5), &mut rng)).collect();
        let on_grid = autocorrelation(&fields, 8, (3, 5)).unwrap();
        for lags in [&on_grid.horizontal, &on_grid.vertical] {
            for lag in &lags[..7] {
                close(lag.inside_block, 0.5, 0.06, &format!("lag {} inside", lag.lag));
                close(lag.across_edge, 0.0, 0.06, &format!("lag {} across", lag.lag));
            }
            assert_eq!(lags[7].inside_block, None);
            close(lags[7].across_edge, 0.0, 0.06, "lag B across");
        }
        // On the wrong grid a pair counted as inside may straddle a real edge and the
        // reverse: the two kinds move towards each other.
        let off_grid = autocorrelation(&fields, 8, (0, 0)).unwrap();
        let (inside, across) =
            (off_grid.horizontal[0].inside_block.unwrap().mean, off_grid.horizontal[0].across_edge.unwrap().mean);
        assert!(inside < 0.5 && across > 0.3, "off grid: inside {inside}, across {across}");
    }

    #[test]
    fn complementary_errors_inside_blocks_correlate_negatively() {
        // Blocks of 2: the right pixel of each pair is minus the left one. Inside: ρ = −1
        // exactly (the field's mean is exactly 0); across the edge, and vertically, 0.
        let mut rng = Rng::new(33);
        let fields: Vec<ErrorField> = (0..3)
            .map(|_| {
                let base = white(64, &mut rng);
                field(64, 64, |x, y| if x % 2 == 0 { base.values[y * 64 + x] } else { -base.values[y * 64 + x - 1] })
            })
            .collect();
        let measured = autocorrelation(&fields, 2, (0, 0)).unwrap();
        let inside = measured.horizontal[0].inside_block.unwrap();
        assert!((inside.mean + 1.0).abs() < 1e-12, "{inside}");
        close(measured.horizontal[0].across_edge, 0.0, 0.05, "across");
        close(measured.horizontal[1].across_edge, 0.0, 0.05, "lag 2 across");
        close(measured.vertical[0].inside_block, 0.0, 0.05, "vertical inside");
    }

    #[test]
    fn white_noise_has_a_flat_spectrum_and_a_ratio_of_one() {
        let mut rng = Rng::new(34);
        let fields: Vec<ErrorField> = (0..4).map(|_| white(128, &mut rng)).collect();
        let spectrum = radial_spectrum(&fields, 8).unwrap();
        for bin in &spectrum.bins {
            // Bin 0 holds the fewest frequencies: about 200 per field, 100 of them independent
            // (E(−u, −v) is E(u, v)'s conjugate), each S exponential: ± 0.05 over 4 fields.
            close(bin.power, 1.0, 0.2, &format!("bin {:.3}..{:.3}", bin.low, bin.high));
        }
        close(Some(spectrum.low_high_ratio), 1.0, 0.06, "white ratio");
        assert_eq!(spectrum.low_high_ratio.count, 4);
        // The same noise on a 96 × 80 field (direct DFT, not radix 2): still flat.
        let odd: Vec<ErrorField> = (0..4).map(|_| field(96, 80, |_, _| rng.normal())).collect();
        close(Some(radial_spectrum(&odd, 4).unwrap().low_high_ratio), 1.0, 0.1, "white ratio 96 x 80");
    }

    #[test]
    fn a_cosine_puts_all_its_power_in_one_bin_and_parseval_holds() {
        // ε = cos(2π · 5x/64) + 3 on 64 × 64: all its power at (±5, 0), radius 5/64 ≈ 0.078,
        // bin 2 of 16 (width 1/32). The normalised powers over the P − 1 frequencies sum to P,
        // so the bin's mean is P / (its frequencies) and every other bin is 0.
        let cosine = field(64, 64, |x, _| (std::f64::consts::TAU * 5.0 * x as f64 / 64.0).cos() + 3.0);
        let spectrum = radial_spectrum(std::slice::from_ref(&cosine), 16).unwrap();
        for (i, bin) in spectrum.bins.iter().enumerate() {
            let power = bin.power.unwrap().mean;
            let expected = if i == 2 { 4096.0 / bin.frequencies as f64 } else { 0.0 };
            assert!((power - expected).abs() < 1e-9, "bin {i}: {power} against {expected}");
        }
        // Parseval on noise: Σ over all frequencies but 0 of S = P, bins and corners alike.
        let mut rng = Rng::new(35);
        let noise = ar1(32, 0.5, 0.2, 1.0, &mut rng);
        let (mean, variance) = check_fields(std::slice::from_ref(&noise), "test").unwrap()[0];
        let total: f64 = normalised_power(&noise, mean, variance).iter().map(|(_, s)| s).sum();
        assert!((total - 1024.0).abs() < 1e-8, "{total}");
    }

    #[test]
    fn clumped_noise_has_a_high_ratio_and_blue_noise_a_low_one() {
        let mut rng = Rng::new(36);
        // Constant over 8 × 8 blocks: power below 1/8 cycles per pixel.
        let clumped: Vec<ErrorField> = (0..3)
            .map(|_| {
                let blocks: Vec<f64> = (0..16 * 16).map(|_| rng.normal()).collect();
                field(128, 128, |x, y| blocks[y / 8 * 16 + x / 8])
            })
            .collect();
        let ratio = radial_spectrum(&clumped, 8).unwrap().low_high_ratio;
        assert!(ratio.mean > 10.0, "clumped: {ratio}");
        // AR(1) with ρ = 0.6 both ways: clumped too, less so.
        let smooth: Vec<ErrorField> = (0..3).map(|_| ar1(128, 0.6, 0.6, 0.0, &mut rng)).collect();
        let smooth_ratio = radial_spectrum(&smooth, 8).unwrap().low_high_ratio;
        assert!(smooth_ratio.mean > 2.0 && smooth_ratio.mean < ratio.mean, "AR(1): {smooth_ratio}");
        // Blue: white noise minus the mean of its 4 neighbours (a discrete Laplacian, wrapping
        // at the borders), whose power (1 − (cos ωx + cos ωy)/2)² vanishes at frequency 0.
        let blue: Vec<ErrorField> = (0..3)
            .map(|_| {
                let g = white(128, &mut rng);
                let at = |x: usize, y: usize| g.values[(y % 128) * 128 + x % 128];
                field(128, 128, |x, y| at(x, y) - (at(x + 1, y) + at(x + 127, y) + at(x, y + 1) + at(x, y + 127)) / 4.0)
            })
            .collect();
        let blue_ratio = radial_spectrum(&blue, 8).unwrap().low_high_ratio;
        assert!(blue_ratio.mean < 0.5, "blue: {blue_ratio}");
    }

    #[test]
    fn errors_from_images_and_seed_residuals() {
        let reference = RgbImage { width: 8, height: 8, pixels: vec![[0.25, 0.5, 1.0]; 64] };
        let y_ref = 0.2126 * 0.25 + 0.7152 * 0.5 + 0.0722;
        // A uniform grey offset of 0.1 is a relative luminance error of 0.1/√(Y + 1e-4).
        let image = RgbImage { pixels: vec![[0.35, 0.6, 1.1]; 64], ..reference.clone() };
        let error = ErrorField::relative_luminance(&image, &reference).unwrap();
        assert!(error.values.iter().all(|v| (v - 0.1 / (y_ref + 1e-4f64).sqrt()).abs() < 1e-6));
        // A bias pattern shared by every seed is gone from the residuals; the noise stays.
        let mut rng = Rng::new(37);
        let seeds: Vec<RgbImage> = (0..3)
            .map(|_| RgbImage {
                pixels: (0..64).map(|i| [(0.5 + 0.1 * (i % 8) as f64 + 0.01 * rng.normal()) as f32; 3]).collect(),
                ..reference.clone()
            })
            .collect();
        let residuals = ErrorField::seed_residuals(&seeds, &reference).unwrap();
        assert_eq!(residuals.len(), 3);
        for i in 0..64 {
            let sum: f64 = residuals.iter().map(|r| r.values[i]).sum();
            assert!(sum.abs() < 1e-9, "residuals sum to 0 at {i}: {sum}");
            assert!(residuals[0].values[i].abs() < 0.2, "no bias pattern left at {i}");
        }
    }

    #[test]
    fn what_is_wrong_is_named() {
        let reference = RgbImage { width: 8, height: 8, pixels: vec![[1.0; 3]; 64] };
        let small = RgbImage::new(4, 8);
        let message = ErrorField::relative_luminance(&small, &reference).unwrap_err().to_string();
        assert_eq!(message, "the image is 4x8 but the reference is 8x8");
        let message = ErrorField::seed_residuals(std::slice::from_ref(&reference), &reference).unwrap_err().to_string();
        assert_eq!(message, "seed residuals needs at least 2 seeds, got 1");
        let mut nan = reference.clone();
        nan.pixels[9] = [f32::NAN; 3];
        let message =
            ErrorField::seed_residuals(&[reference.clone(), nan.clone()], &reference).unwrap_err().to_string();
        assert_eq!(message, "seed 1 has a non-finite value at pixel (1, 1)");
        let message = ErrorField::relative_luminance(&reference, &nan).unwrap_err().to_string();
        assert_eq!(message, "the reference has a non-finite value at pixel (1, 1)");
        let mut rng = Rng::new(38);
        let a = white(8, &mut rng);
        assert_eq!(
            autocorrelation(&[], 2, (0, 0)).unwrap_err().to_string(),
            "the autocorrelation needs at least 1 error fields, got 0"
        );
        assert_eq!(
            autocorrelation(std::slice::from_ref(&a), 8, (0, 0)).unwrap_err().to_string(),
            "block size 8 needs fields wider and taller than it (and at least 1), got 8x8"
        );
        assert!(autocorrelation(std::slice::from_ref(&a), 0, (0, 0)).is_err());
        let constant = field(8, 8, |_, _| 2.0);
        assert_eq!(
            radial_spectrum(&[a.clone(), constant], 4).unwrap_err().to_string(),
            "error field 1 is constant (variance 0): no correlation or spectrum"
        );
        let other = white(4, &mut rng);
        assert_eq!(
            autocorrelation(&[a.clone(), other], 2, (0, 0)).unwrap_err().to_string(),
            "error field 1 is 4x4 but error field 0 is 8x8"
        );
        let short = ErrorField { width: 8, height: 8, values: vec![1.0; 10] };
        assert_eq!(radial_spectrum(&[short], 4).unwrap_err().to_string(), "error field 0 has 10 values for 8x8 pixels");
        assert_eq!(
            radial_spectrum(&[white(3, &mut rng)], 4).unwrap_err().to_string(),
            "the spectrum needs at least 1 bin and 4x4 pixels, got 4 bins of 3x3"
        );
        assert!(radial_spectrum(std::slice::from_ref(&a), 0).is_err());
    }
}
