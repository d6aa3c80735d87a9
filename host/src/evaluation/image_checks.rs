//! What an image must be before it is scored, in one place: a reference (read from a
//! file or path-traced) and every rendered frame pass these checks before any error
//! metric is computed from them, so that a number in `errors.csv`, the summary or the
//! report is never computed from an image that cannot mean anything.
//!
//! - A reference is finite, non-negative (radiance; a negative pixel makes the paper's
//!   RelMSE, (f − ref)² / (ref + 1e-4), negative or huge) and not black everywhere (a
//!   camera that sees no light: every error would be 0 and every ratio 0 / 0).
//! - A frame is finite. A frame black everywhere where its reference is not is scored
//!   but said ([`black_against`]: at a few pixels and one sample per frame it can
//!   happen; a renderer that lost every sample to overflow flags those samples as
//!   invalid, which the comparison refuses, so black alone is not an error).

use strata_render::rgb_image::{RgbImage, linear_to_srgb8};

/// Why an image cannot be scored; the message names the image and the pixel.
#[derive(Debug, thiserror::Error)]
pub enum ImageCheckError {
    /// A NaN or infinite channel.
    #[error("{name}: pixel ({x}, {y}) is {value:?}: an image with non-finite values cannot be measured")]
    NonFinite {
        /// The image, in words ("the reference", "strata frame 3, seed 1").
        name: String,
        /// Column.
        x: u32,
        /// Row.
        y: u32,
        /// The pixel.
        value: [f32; 3],
    },
    /// A negative channel in a reference.
    #[error("{name}: pixel ({x}, {y}) is {value:?}: a reference is radiance, never negative")]
    Negative {
        /// The image.
        name: String,
        /// Column.
        x: u32,
        /// Row.
        y: u32,
        /// The pixel.
        value: [f32; 3],
    },
    /// A reference that is 0 everywhere.
    #[error(
        "{name} is black everywhere ({width}x{height} pixels of 0): the camera sees no light (is it inside a closed \
         object, pointed away from the scene, or is the scene unlit?), so there is no error to measure"
    )]
    BlackReference {
        /// The image.
        name: String,
        /// Width.
        width: u32,
        /// Height.
        height: u32,
    },
}

/// The first pixel with a channel that fails `bad`, as (x, y, pixel).
fn first_pixel(image: &RgbImage, bad: impl Fn(f32) -> bool) -> Option<(u32, u32, [f32; 3])> {
    let index = image.pixels.iter().position(|p| p.iter().any(|&c| bad(c)))?;
    let width = image.width.max(1) as usize;
    Some(((index % width) as u32, (index / width) as u32, image.pixels[index]))
}

/// Whether every channel of every pixel is exactly 0.
pub fn is_black(image: &RgbImage) -> bool {
    image.pixels.iter().all(|p| p.iter().all(|&c| c == 0.0))
}

/// Refuses a reference that is not finite, has a negative pixel or is black everywhere;
/// `name` says which image it is in the message ("the reference", a file name).
pub fn check_reference(image: &RgbImage, name: &str) -> Result<(), ImageCheckError> {
    if let Some((x, y, value)) = first_pixel(image, |c| !c.is_finite()) {
        return Err(ImageCheckError::NonFinite { name: name.into(), x, y, value });
    }
    if let Some((x, y, value)) = first_pixel(image, |c| c < 0.0) {
        return Err(ImageCheckError::Negative { name: name.into(), x, y, value });
    }
    if is_black(image) {
        return Err(ImageCheckError::BlackReference { name: name.into(), width: image.width, height: image.height });
    }
    Ok(())
}

/// Refuses a rendered frame that is not finite.
pub fn check_frame(image: &RgbImage, name: &str) -> Result<(), ImageCheckError> {
    match first_pixel(image, |c| !c.is_finite()) {
        Some((x, y, value)) => Err(ImageCheckError::NonFinite { name: name.into(), x, y, value }),
        None => Ok(()),
    }
}

/// Whether `image` is black everywhere while `reference` is not (worth a warning).
pub fn black_against(image: &RgbImage, reference: &RgbImage) -> bool {
    is_black(image) && !is_black(reference)
}

/// A warning when `image` has light but its 8-bit preview at `exposure` is black
/// everywhere (an `--exposure` so small that the brightest pixel maps below one step):
/// the PNG would look like a failed render while the EXR holds the image.
pub fn black_preview(image: &RgbImage, exposure: f32) -> Option<String> {
    if is_black(image) {
        return None;
    }
    let brightest = image.pixels.iter().flat_map(|p| p.iter().copied()).fold(0.0f32, f32::max);
    let all_zero = image.pixels.iter().all(|p| p.iter().all(|&c| linear_to_srgb8(c * exposure) == 0));
    all_zero.then(|| {
        format!(
            "--exposure {exposure:e}: the PNG previews are black (the brightest pixel, {brightest:e}, maps below one \
             8-bit step); the EXR images hold the render: raise --exposure"
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_preview_black_at_its_exposure_is_warned_about() {
        let image = RgbImage { width: 2, height: 1, pixels: vec![[0.0; 3], [0.5, 0.25, 1.0]] };
        assert!(black_preview(&image, 1.0).is_none());
        let warning = black_preview(&image, 1e-6).expect("a black preview");
        assert!(warning.contains("--exposure 1e-6") && warning.contains("1e0"), "{warning}");
        assert!(black_preview(&RgbImage { pixels: vec![[0.0; 3]; 2], ..image }, 1e-6).is_none(), "black is black");
    }

    fn image(pixels: Vec<[f32; 3]>) -> RgbImage {
        RgbImage { width: 2, height: (pixels.len() / 2) as u32, pixels }
    }

    #[test]
    fn references_must_be_finite_non_negative_and_lit() {
        let lit = image(vec![[0.0; 3], [0.5; 3], [0.0; 3], [0.0; 3]]);
        assert!(check_reference(&lit, "r").is_ok());
        let negative = image(vec![[0.0; 3], [0.5; 3], [0.0, -1e-3, 0.0], [0.0; 3]]);
        let message = check_reference(&negative, "ref.exr").unwrap_err().to_string();
        assert!(message.starts_with("ref.exr: pixel (0, 1)") && message.contains("never negative"), "{message}");
        let nan = image(vec![[0.0; 3], [f32::NAN, 0.0, 0.0], [0.0; 3], [0.0; 3]]);
        assert!(check_reference(&nan, "r").unwrap_err().to_string().contains("pixel (1, 0)"));
        let black = image(vec![[0.0; 3]; 4]);
        assert!(check_reference(&black, "the reference").unwrap_err().to_string().contains("black everywhere"));
    }

    #[test]
    fn frames_must_be_finite_and_black_ones_are_told_apart() {
        let lit = image(vec![[0.0; 3], [0.5; 3], [0.0; 3], [0.0; 3]]);
        let black = image(vec![[0.0; 3]; 4]);
        assert!(check_frame(&lit, "f").is_ok() && check_frame(&black, "f").is_ok());
        assert!(black_against(&black, &lit) && !black_against(&black, &black) && !black_against(&lit, &lit));
        let infinite = image(vec![[0.0; 3], [0.5; 3], [0.0; 3], [0.0, 0.0, f32::INFINITY]]);
        assert!(matches!(check_frame(&infinite, "f"), Err(ImageCheckError::NonFinite { x: 1, y: 1, .. })));
    }
}
