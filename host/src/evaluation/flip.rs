//! FLIP (Andersson et al., "FLIP: A Difference Evaluator for Alternating Images", HPG
//! 2020), the perceptual difference real-time rendering papers report beside RelMSE,
//! computed by NVIDIA's own implementation through the `nv-flip` crate (the binding
//! wgpu's image tests use).
//!
//! strata's frames are linear radiance; FLIP here is LDR-FLIP of what a person is shown:
//! both images tone-mapped exactly as the PNG previews are (radiance × exposure, clamped,
//! sRGB-encoded to 8 bits: [`RgbImage::png_bytes`]), compared at FLIP's default 67 pixels
//! per degree (a 0.7 m wide 4K screen seen from 0.7 m). The number is the mean of FLIP's
//! per-pixel error map, in [0, 1]; lower is better. Built with the `flip` feature (on by
//! default); without it every FLIP is `None` and says so.

use crate::evaluation::metrics::MetricError;
use strata_render::rgb_image::{RgbImage, linear_to_srgb8};

/// Whether this build computes FLIP (the `flip` feature).
pub const AVAILABLE: bool = cfg!(feature = "flip");

/// `image`'s 8-bit sRGB preview at `exposure`, as the PNG previews have it.
fn preview(image: &RgbImage, exposure: f32) -> Vec<u8> {
    image.pixels.iter().flat_map(|p| p.map(|c| linear_to_srgb8(c * exposure))).collect()
}

/// Mean LDR-FLIP of `image` against `reference`, both tone-mapped at `exposure`; `None`
/// in a build without the `flip` feature.
pub fn mean_flip(image: &RgbImage, reference: &RgbImage, exposure: f32) -> Result<Option<f64>, MetricError> {
    crate::evaluation::metrics::check(image, reference)?;
    if !(exposure.is_finite() && exposure > 0.0) {
        return Err(MetricError::Exposure(exposure));
    }
    Ok(flip_of_previews(image.width, image.height, &preview(image, exposure), &preview(reference, exposure)))
}

#[cfg(feature = "flip")]
fn flip_of_previews(width: u32, height: u32, image: &[u8], reference: &[u8]) -> Option<f64> {
    let reference = nv_flip::FlipImageRgb8::with_data(width, height, reference);
    let image = nv_flip::FlipImageRgb8::with_data(width, height, image);
    let map = nv_flip::flip(reference, image, nv_flip::DEFAULT_PIXELS_PER_DEGREE);
    let values = map.to_vec();
    Some(values.iter().map(|&v| f64::from(v)).sum::<f64>() / values.len().max(1) as f64)
}

#[cfg(not(feature = "flip"))]
fn flip_of_previews(_width: u32, _height: u32, _image: &[u8], _reference: &[u8]) -> Option<f64> {
    None
}

#[cfg(all(test, feature = "flip"))]
mod tests {
    use super::*;

    fn image(value: impl Fn(u32, u32) -> [f32; 3]) -> RgbImage {
        let (width, height) = (32, 24);
        RgbImage { width, height, pixels: (0..width * height).map(|i| value(i % width, i / width)).collect() }
    }

    #[test]
    fn flip_is_zero_for_equal_images_and_grows_with_the_difference() {
        let reference = image(|x, y| [0.2 + 0.02 * x as f32, 0.3, 0.1 + 0.02 * y as f32]);
        assert_eq!(mean_flip(&reference, &reference, 1.0).unwrap(), Some(0.0));
        let noisy = |amount: f32| {
            image(|x, y| {
                let sign = if (x * 7 + y * 13) % 2 == 0 { 1.0 } else { -1.0 };
                reference.pixels[(y * 32 + x) as usize].map(|c| (c + sign * amount).max(0.0))
            })
        };
        let small = mean_flip(&noisy(0.02), &reference, 1.0).unwrap().unwrap();
        let large = mean_flip(&noisy(0.2), &reference, 1.0).unwrap().unwrap();
        assert!(0.0 < small && small < large && large <= 1.0, "small {small}, large {large}");
    }

    #[test]
    fn mismatched_sizes_and_bad_exposures_are_errors() {
        let a = image(|_, _| [0.5; 3]);
        let b = RgbImage { width: 8, height: 8, pixels: vec![[0.5; 3]; 64] };
        assert!(mean_flip(&a, &b, 1.0).is_err());
        assert!(mean_flip(&a, &a, f32::NAN).is_err());
    }
}
