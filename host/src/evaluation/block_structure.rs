//! Whether a frame's error has the block grid's structure. strata's pixels of one block
//! draw their candidates from one sorted run (paper §4), a correlation of its own that a
//! viewer, or a denoiser, could see as blocks; the paper's limitations section says so
//! and proposes block shifting.
//!
//! The statistic, the *block-edge contrast*: with e the relative luminance error of each
//! pixel, (Y − Y_ref) / (Y_ref + 10⁻²), the median of |e_a − e_b| over pairs of
//! neighbouring pixels (left-right and above-below) on either side of a boundary of the
//! B × B grid, divided by the same median over neighbouring pairs within a block, minus 1.
//! Medians, because a path tracer's error is heavy-tailed: with means, one firefly near
//! an edge decided the number (at 128 × 128, 4 seeds gave ± 0.1 to ± 0.4). An error
//! without block structure gives 0 up to noise (the grid does not depend on the scene,
//! so both kinds of pair see the same edges and the same noise); errors shared within
//! blocks and changing between them give a positive number (0.5: the error jumps at
//! block edges half again as much as inside a block). The grid is the one the frame was
//! selected on: shifted by that frame's offset under block shifting; for accumulated
//! frames (the mean of frames 1 to f, each on its own grid under block shifting), frame
//! f's.

use strata_render::rgb_image::RgbImage;

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
/// grid of `block_size` × `block_size` blocks shifted by `shift` (pixel (x, y) lies in
/// block ((x + sx) / B, (y + sy) / B), as `BlockGrid::block_of` has it). `None` where it
/// cannot be computed: images of different sizes, no block boundary inside the image, or
/// no difference at all between neighbours within blocks.
pub fn block_edge_contrast(image: &RgbImage, reference: &RgbImage, block_size: u32, shift: (u32, u32)) -> Option<f64> {
    if (image.width, image.height) != (reference.width, reference.height) || block_size < 2 {
        return None;
    }
    let errors = relative_luminance_errors(image, reference);
    let (width, height) = (image.width as usize, image.height as usize);
    let block = block_size as usize;
    // |differences| of neighbours within blocks and across their edges.
    let (mut within, mut across) = (Vec::new(), Vec::new());
    let mut add = |a: usize, b: usize, crosses: bool| {
        let difference = (errors[a] - errors[b]).abs();
        if crosses { across.push(difference) } else { within.push(difference) }
    };
    for y in 0..height {
        for x in 0..width {
            let here = y * width + x;
            if x + 1 < width {
                add(here, here + 1, (x + 1 + shift.0 as usize).is_multiple_of(block));
            }
            if y + 1 < height {
                add(here, here + width, (y + 1 + shift.1 as usize).is_multiple_of(block));
            }
        }
    }
    let (across, within) = (median(&mut across)?, median(&mut within)?);
    if within == 0.0 {
        return None;
    }
    let contrast = across / within - 1.0;
    contrast.is_finite().then_some(contrast)
}

/// The median of `values` (reordered); `None` for none.
fn median(values: &mut [f64]) -> Option<f64> {
    if values.is_empty() {
        return None;
    }
    let middle = values.len() / 2;
    let (_, &mut upper, _) = values.select_nth_unstable_by(middle, f64::total_cmp);
    if values.len() % 2 == 1 {
        return Some(upper);
    }
    let lower = values[..middle].iter().copied().fold(f64::NEG_INFINITY, f64::max);
    Some((lower + upper) / 2.0)
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
        let contrast = block_edge_contrast(&white, &reference, 16, (0, 0)).unwrap();
        assert!(contrast.abs() < 0.05, "independent noise: {contrast}");
        // A few fireflies on block edges do not decide it.
        let fireflies = image(256, |x, y| {
            let firefly = x % 16 == 15 && y % 64 == 0;
            1.0 + 0.1 * noise(x, y, 1) + if firefly { 1e4 } else { 0.0 }
        });
        let contrast = block_edge_contrast(&fireflies, &reference, 16, (0, 0)).unwrap();
        assert!(contrast.abs() < 0.05, "noise with fireflies on edges: {contrast}");
        // The same noise plus an offset shared by each 16 x 16 block: the error jumps at
        // block edges.
        let blocky = image(256, |x, y| 1.0 + 0.1 * noise(x, y, 1) + 0.1 * noise(x / 16, y / 16, 2));
        let contrast = block_edge_contrast(&blocky, &reference, 16, (0, 0)).unwrap();
        assert!(contrast > 0.2, "block offsets: {contrast}");
        // Seen on a grid of another size, the same blocks mostly fall inside its blocks'
        // pairs or across them alike (8 divides 16: every 16-edge is an 8-edge, half the
        // 8-edges are not): weaker, still positive.
        let on_8 = block_edge_contrast(&blocky, &reference, 8, (0, 0)).unwrap();
        assert!(0.0 < on_8 && on_8 < contrast, "on the 8 grid: {on_8}");
        // Blocks shifted by (5, 11), measured on the grid shifted alike and on the
        // unshifted one.
        let shifted = image(256, |x, y| 1.0 + 0.1 * noise(x, y, 1) + 0.1 * noise((x + 5) / 16, (y + 11) / 16, 2));
        let on_its_grid = block_edge_contrast(&shifted, &reference, 16, (5, 11)).unwrap();
        let off_grid = block_edge_contrast(&shifted, &reference, 16, (0, 0)).unwrap();
        assert!(on_its_grid > 0.2 && off_grid.abs() < 0.05, "on its grid {on_its_grid}, off it {off_grid}");
    }

    #[test]
    fn what_cannot_be_computed_is_none() {
        let reference = image(16, |_, _| 1.0);
        assert_eq!(block_edge_contrast(&reference, &reference, 4, (0, 0)), None, "no difference at all");
        let noisy = image(16, |x, y| 1.0 + noise(x, y, 3));
        assert_eq!(block_edge_contrast(&noisy, &reference, 16, (0, 0)), None, "no edge inside a 16 x 16 image");
        assert_eq!(block_edge_contrast(&noisy, &image(8, |_, _| 1.0), 4, (0, 0)), None, "sizes differ");
    }
}
