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

    /// Each pixel's error, the mean over its three channels, row-major: or `None` when the
    /// images' sizes differ or they are empty.
    pub fn map(self, image: &RgbImage, reference: &RgbImage) -> Option<Vec<f64>> {
        let same_size = (image.width, image.height) == (reference.width, reference.height);
        if !same_size || image.pixels.is_empty() || image.pixels.len() != reference.pixels.len() {
            return None;
        }
        Some(
            image
                .pixels
                .iter()
                .zip(&reference.pixels)
                .map(|(f, r)| (0..3).map(|c| self.of(f[c], r[c])).sum::<f64>() / 3.0)
                .collect(),
        )
    }

    /// The mean error over every channel of every pixel of `image` against `reference`
    /// (the mean of [`Self::map`]), or `None` when their sizes differ, they are empty, or
    /// a value is not finite (a number that cannot be computed is not a score).
    pub fn mean(self, image: &RgbImage, reference: &RgbImage) -> Option<f64> {
        map_mean(&self.map(image, reference)?)
    }
}

/// The mean of an error map ([`Metric::map`]), or `None` when it is empty or not finite.
pub fn map_mean(map: &[f64]) -> Option<f64> {
    (!map.is_empty()).then(|| map.iter().sum::<f64>() / map.len() as f64).filter(|mean| mean.is_finite())
}

/// The error maps' colours, sRGB: log10 of the error from 1e-4 (black) through blue, red
/// and yellow to 1 and above (white), evenly spaced (the live page's colour bar is a CSS
/// gradient of the same stops).
pub const FALSE_COLOUR_STOPS: [[f32; 3]; 5] =
    [[0.0, 0.0, 0.0], [0.2, 0.1, 0.6], [0.8, 0.15, 0.3], [1.0, 0.8, 0.1], [1.0, 1.0, 1.0]];

/// A false-colour picture of a per-pixel error map (row-major, `width` × `height`), on
/// [`FALSE_COLOUR_STOPS`], as linear RGB whose sRGB encoding at exposure 1 shows that
/// ramp. A zero or negative error is black, NaN white.
pub fn false_colour(map: &[f64], width: u32, height: u32) -> RgbImage {
    const STOPS: [[f32; 3]; 5] = FALSE_COLOUR_STOPS;
    let pixels = map
        .iter()
        .map(|&e| {
            let t = if e > 0.0 || e.is_nan() { ((e.log10() + 4.0) / 4.0).clamp(0.0, 1.0) as f32 } else { 0.0 };
            let t = if t.is_nan() { 1.0 } else { t };
            let position = t * (STOPS.len() - 1) as f32;
            let i = (position as usize).min(STOPS.len() - 2);
            let f = position - i as f32;
            let srgb: [f32; 3] = std::array::from_fn(|c| STOPS[i][c] * (1.0 - f) + STOPS[i + 1][c] * f);
            srgb.map(|c| crate::scene::srgb_to_linear((c * 255.0).round() as u8))
        })
        .collect();
    RgbImage { width, height, pixels }
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
        assert_eq!(Metric::Relmse.map(&image, &reference).unwrap(), [expected * 2.0, 0.0]);
    }

    /// The ramp's ends and a stop: 1e-4 and below black, 1 and above white, 1e-2 (the
    /// middle stop) red; NaN white.
    #[test]
    fn false_colour_puts_the_decades_on_the_stops() {
        let srgb = |e: f64| false_colour(&[e], 1, 1).pixels[0].map(crate::rgb_image::linear_to_srgb8);
        assert_eq!(srgb(0.0), [0, 0, 0]);
        assert_eq!(srgb(1e-5), [0, 0, 0]);
        assert_eq!(srgb(1e-2), [204, 38, 77]);
        assert_eq!(srgb(1.0), [255, 255, 255]);
        assert_eq!(srgb(7.0), [255, 255, 255]);
        assert_eq!(srgb(f64::NAN), [255, 255, 255]);
    }
}
