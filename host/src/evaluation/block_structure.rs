//! Whether a frame's error has the block grid's structure. strata's pixels of one block
//! draw their candidates from one sorted run (paper §4), a correlation of its own that a
//! viewer, or a denoiser, could see as blocks; the paper's limitations section says so
//! and proposes block shifting.
//!
//! The statistic, the *block-edge contrast*: with e the relative luminance error of each
//! pixel, (Y − Y_ref) / (Y_ref + 10⁻²), the mean of (e_a − e_b)² over pairs of
//! neighbouring pixels (left-right and above-below) on either side of a boundary of the
//! B × B grid, divided by the same mean over neighbouring pairs within a block, minus 1.
//! An error without block structure gives 0 up to noise (the grid does not depend on the
//! scene, so both kinds of pair see the same edges and the same noise); errors shared
//! within blocks and changing between them give a positive number (0.5: the error jumps
//! at block edges half again as much as inside a block). The grid is the unshifted one,
//! so block shifting, which moves the grid every frame, spreads what is left over every
//! offset and shows as 0.

use crate::rgb_image::RgbImage;

/// The relative luminance error of each pixel of `image` against `reference`.
fn relative_luminance_errors(image: &RgbImage, reference: &RgbImage) -> Vec<f64> {
    let luminance = |c: &[f32; 3]| 0.2126 * f64::from(c[0]) + 0.7152 * f64::from(c[1]) + 0.0722 * f64::from(c[2]);
    image
        .pixels
        .iter()
        .zip(&reference.pixels)
        .map(|(f, r)| (luminance(f) - luminance(r)) / (luminance(r) + 1e-2))
        .collect()
}

/// The block-edge contrast (module documentation) of `image` against `reference` on the
/// grid of `block_size` × `block_size` blocks. `None` where it cannot be computed: images
/// of different sizes, no block boundary inside the image, or no difference at all
/// between neighbours within blocks.
pub fn block_edge_contrast(image: &RgbImage, reference: &RgbImage, block_size: u32) -> Option<f64> {
    if (image.width, image.height) != (reference.width, reference.height) || block_size < 2 {
        return None;
    }
    let errors = relative_luminance_errors(image, reference);
    let (width, height) = (image.width as usize, image.height as usize);
    let block = block_size as usize;
    // (sum of squared differences, pairs) within blocks and across their edges.
    let (mut within, mut across) = ((0.0f64, 0usize), (0.0f64, 0usize));
    let mut add = |a: usize, b: usize, crosses: bool| {
        let d = errors[a] - errors[b];
        let sum = if crosses { &mut across } else { &mut within };
        sum.0 += d * d;
        sum.1 += 1;
    };
    for y in 0..height {
        for x in 0..width {
            let here = y * width + x;
            if x + 1 < width {
                add(here, here + 1, (x + 1) % block == 0);
            }
            if y + 1 < height {
                add(here, here + width, (y + 1) % block == 0);
            }
        }
    }
    if across.1 == 0 || within.1 == 0 || within.0 == 0.0 {
        return None;
    }
    let contrast = (across.0 / across.1 as f64) / (within.0 / within.1 as f64) - 1.0;
    contrast.is_finite().then_some(contrast)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A `size` × `size` grey image from `value(x, y)`.
    fn image(size: u32, value: impl Fn(u32, u32) -> f32) -> RgbImage {
        RgbImage {
            width: size,
            height: size,
            pixels: (0..size * size).map(|i| [value(i % size, i / size); 3]).collect(),
        }
    }

    /// A hash of (x, y, salt) in [-1, 1): noise with no structure.
    fn noise(x: u32, y: u32, salt: u32) -> f32 {
        let mut h = x.wrapping_mul(0x9e37_79b9) ^ y.wrapping_mul(0x85eb_ca6b) ^ salt.wrapping_mul(0xc2b2_ae35);
        h ^= h >> 16;
        h = h.wrapping_mul(0x7feb_352d);
        h ^= h >> 15;
        (h as f32 / u32::MAX as f32) * 2.0 - 1.0
    }

    #[test]
    fn noise_without_blocks_gives_zero_and_errors_shared_within_blocks_do_not() {
        let reference = image(256, |_, _| 1.0);
        let white = image(256, |x, y| 1.0 + 0.1 * noise(x, y, 1));
        let contrast = block_edge_contrast(&white, &reference, 16).unwrap();
        assert!(contrast.abs() < 0.05, "independent noise: {contrast}");
        // The same noise plus an offset shared by each 16 x 16 block: the error jumps at
        // block edges.
        let blocky = image(256, |x, y| 1.0 + 0.1 * noise(x, y, 1) + 0.1 * noise(x / 16, y / 16, 2));
        let contrast = block_edge_contrast(&blocky, &reference, 16).unwrap();
        assert!(contrast > 0.5, "block offsets: {contrast}");
        // Seen on a grid of another size, the same blocks mostly fall inside its blocks'
        // pairs or across them alike (8 divides 16: every 16-edge is an 8-edge, half the
        // 8-edges are not): weaker, still positive.
        let on_8 = block_edge_contrast(&blocky, &reference, 8).unwrap();
        assert!(0.0 < on_8 && on_8 < contrast, "on the 8 grid: {on_8}");
    }

    #[test]
    fn what_cannot_be_computed_is_none() {
        let reference = image(16, |_, _| 1.0);
        assert_eq!(block_edge_contrast(&reference, &reference, 4), None, "no difference at all");
        let noisy = image(16, |x, y| 1.0 + noise(x, y, 3));
        assert_eq!(block_edge_contrast(&noisy, &reference, 16), None, "no edge inside a 16 x 16 image");
        assert_eq!(block_edge_contrast(&noisy, &image(8, |_, _| 1.0), 4), None, "sizes differ");
    }
}
