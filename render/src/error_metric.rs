//! The per-pixel error metrics every comparison is scored with, declared once: the
//! evaluation's metrics and maps (`strata::evaluation::metrics`) and the live comparison
//! page (`strata-web`) both use these.

use crate::rgb_image::RgbImage;

/// Which per-pixel error a map or a mean is made of.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Metric {
    /// Squared error.
    Mse,
    /// (f − ref)² / (ref + 1e-4): the paper's RelMSE.
    Relmse,
    /// (f − ref)² / (ref² + 1e-2): the common RelMSE.
    RelmseCommon,
}

impl Metric {
    /// The error of one channel value `f` against the reference value `reference`.
    pub fn of(self, f: f32, reference: f32) -> f64 {
        let (f, r) = (f64::from(f), f64::from(reference));
        let squared = (f - r) * (f - r);
        match self {
            Metric::Mse => squared,
            Metric::Relmse => squared / (r + 1e-4),
            Metric::RelmseCommon => squared / (r * r + 1e-2),
        }
    }

    /// The mean error over every channel of every pixel of `image` against `reference`,
    /// or `None` when their sizes differ, they are empty, or a value is not finite (a
    /// number that cannot be computed is not a score).
    pub fn mean(self, image: &RgbImage, reference: &RgbImage) -> Option<f64> {
        let same_size = (image.width, image.height) == (reference.width, reference.height);
        if !same_size || image.pixels.is_empty() || image.pixels.len() != reference.pixels.len() {
            return None;
        }
        let sum: f64 = image
            .pixels
            .iter()
            .zip(&reference.pixels)
            .map(|(f, r)| (0..3).map(|c| self.of(f[c], r[c])).sum::<f64>() / 3.0)
            .sum();
        Some(sum / image.pixels.len() as f64).filter(|mean| mean.is_finite())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_paper_relmse_of_a_known_pair() {
        let reference = RgbImage { width: 2, height: 1, pixels: vec![[1.0; 3], [0.0; 3]] };
        let image = RgbImage { width: 2, height: 1, pixels: vec![[2.0; 3], [0.0; 3]] };
        // Pixel 1: (2 - 1)² / (1 + 1e-4); pixel 2: 0.
        let expected = 0.5 / (1.0 + 1e-4);
        assert!((Metric::Relmse.mean(&image, &reference).unwrap() - expected).abs() < 1e-12);
        let mut broken = image.clone();
        broken.pixels[1][2] = f32::NAN;
        assert_eq!(Metric::Relmse.mean(&broken, &reference), None);
        assert_eq!(Metric::Relmse.mean(&RgbImage::new(1, 1), &reference), None);
    }
}
