//! Temporal flicker: how much a frame's pixels change from frame to frame where the scene
//! does not, the boiling and flicker that engine developers report (issue 55).
//!
//! **Still camera** ([`flicker`]): per pixel, the standard deviation of its Rec. 709
//! luminance Y over a window of frames divided by its mean over them, the metric RTXPT
//! issue 58 (NVIDIA-RTX/RTXPT) uses: per-pixel standard deviation over a window of frames ÷
//! mean. The window is the frames after the first `skip` (which a temporal method spends
//! filling its history); the standard deviation is the sample one, √(Σ (Yₜ − Ȳ)² / (n − 1))
//! over the n frames of the window, so that its square does not depend on n in expectation.
//! Luminance, not each channel, because flicker is a change of brightness a viewer sees, and
//! the ratio of a channel near 0 would be dominated by colour noise in dark channels. Pixels
//! whose mean luminance is at most [`DARK`] have no meaningful ratio: they are left out and
//! counted ([`Flicker::excluded`]). The result is the mean of the ratio over the other
//! pixels. A pixel alternating between luminances a and b over an even n frames scores
//! √(n/(n − 1)) · |a − b| / (a + b); a constant pixel scores 0; Gaussian noise of standard
//! deviation σ about μ scores about σ/μ.
//!
//! **Moving camera** ([`temporal_error_change`]): the frame-to-frame change of the error
//! along the motion vectors. With eₜ = fₜ − refₜ the error of frame t (per channel) and
//! prev(p) where pixel p of frame t was in frame t − 1 ([`PreviousPixels`]), the mean over
//! pixels, channels and pairs of frames of
//!
//! ```text
//! (eₜ(p) − eₜ₋₁(prev(p)))² / (refₜ(p) + 10⁻⁴)
//! ```
//!
//! in the form of the paper's RelMSE (per channel, like it, so the two compare: errors
//! independent from frame to frame score 2 × the relative variance, errors carried unchanged
//! along the motion score 0, and errors with correlation ρ between frames 2(1 − ρ) × the
//! relative variance). Pixels without a previous pixel (disoccluded or come into view) are
//! left out and counted. The camera's motion is removed by following the motion vectors, so
//! what is left is the error's own change: the flicker of a moving frame.

use strata_render::rgb_image::RgbImage;

/// Mean luminance at or below which a pixel has no flicker ratio (the ε of the paper's RelMSE).
pub const DARK: f64 = 1e-4;

/// Why a flicker cannot be computed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum FlickerError {
    /// Fewer than 2 frames are left after the skipped ones.
    #[error("{what} needs at least 2 frames after skipping {skip}, got {got} in all")]
    TooFewFrames {
        /// What was asked for.
        what: &'static str,
        /// Frames skipped.
        skip: usize,
        /// Frames given.
        got: usize,
    },
    /// Lists of frames, references and previous-pixel maps that do not go together.
    #[error("{frames} frames need {needed} {what}, got {got}")]
    Counts {
        /// Frames given.
        frames: usize,
        /// What is missing or extra: `references` or `previous-pixel maps`.
        what: &'static str,
        /// How many it needs.
        needed: usize,
        /// How many it got.
        got: usize,
    },
    /// An image or map is not the size of frame 0.
    #[error("{which} is {width}x{height} but frame 0 is {expected_width}x{expected_height}")]
    Size {
        /// `frame t`, `reference t` or `previous-pixel map t`.
        which: String,
        /// Its width.
        width: u32,
        /// Its height.
        height: u32,
        /// Frame 0's width.
        expected_width: u32,
        /// Frame 0's height.
        expected_height: u32,
    },
    /// The frames have no pixels.
    #[error("the frames are empty (0 pixels)")]
    Empty,
    /// A value is NaN or infinite.
    #[error("{which} has a non-finite value at pixel ({x}, {y})")]
    NonFinite {
        /// `frame t` or `reference t`.
        which: String,
        /// Column.
        x: u32,
        /// Row.
        y: u32,
    },
    /// A reference is negative, where 1 / (r + 10⁻⁴) means nothing.
    #[error("reference {frame} is negative at pixel ({x}, {y}): relative errors divide by reference + 1e-4")]
    NegativeReference {
        /// Frame index.
        frame: usize,
        /// Column.
        x: u32,
        /// Row.
        y: u32,
    },
    /// A previous pixel lies outside the frame.
    #[error("previous-pixel map {map} sends pixel ({x}, {y}) to ({px}, {py}), outside the {width}x{height} frame")]
    OutsideFrame {
        /// Map index (it maps frame `map + 1` to frame `map`).
        map: usize,
        /// Column of the pixel.
        x: u32,
        /// Row of the pixel.
        y: u32,
        /// Column it was sent to.
        px: u32,
        /// Row it was sent to.
        py: u32,
        /// Frame width.
        width: u32,
        /// Frame height.
        height: u32,
    },
    /// Every pixel was left out.
    #[error("{0}")]
    NothingToMeasure(&'static str),
    /// A result is not finite.
    #[error("the {0} is not finite")]
    NonFiniteResult(&'static str),
}

/// A still camera's flicker ([`flicker`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Flicker {
    /// Mean over the measured pixels of std ÷ mean of their luminance over the window.
    pub mean: f64,
    /// Pixels measured.
    pub pixels: usize,
    /// Pixels left out: mean luminance at most [`DARK`].
    pub excluded: usize,
    /// Frames in the window (after the skipped ones).
    pub frames: usize,
}

/// Rec. 709 luminance of a pixel.
fn luminance(p: &[f32; 3]) -> f64 {
    0.2126 * f64::from(p[0]) + 0.7152 * f64::from(p[1]) + 0.0722 * f64::from(p[2])
}

/// Checks that `images` (named `name t`) all have frame 0's size and finite values.
fn check_images(images: &[RgbImage], name: &str, first: &RgbImage) -> Result<(), FlickerError> {
    for (t, image) in images.iter().enumerate() {
        if (image.width, image.height) != (first.width, first.height) || image.pixels.len() != first.pixels.len() {
            return Err(FlickerError::Size {
                which: format!("{name} {t}"),
                width: image.width,
                height: image.height,
                expected_width: first.width,
                expected_height: first.height,
            });
        }
        if let Some(i) = image.pixels.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
            let (x, y) = ((i % image.width as usize) as u32, (i / image.width as usize) as u32);
            return Err(FlickerError::NonFinite { which: format!("{name} {t}"), x, y });
        }
    }
    Ok(())
}

/// Checks the frames of a flicker measurement: at least `skip + 2`, one size, not empty, finite.
fn check_frames(frames: &[RgbImage], skip: usize, what: &'static str) -> Result<(), FlickerError> {
    if frames.len() < skip.saturating_add(2) {
        return Err(FlickerError::TooFewFrames { what, skip, got: frames.len() });
    }
    if frames[0].pixels.is_empty() {
        return Err(FlickerError::Empty);
    }
    check_images(frames, "frame", &frames[0])
}

/// Per pixel (row-major), the still-camera flicker (module documentation) of `frames` after
/// the first `skip`: the sample standard deviation of the luminance ÷ its mean, or `None`
/// for a pixel whose mean luminance is at most [`DARK`].
pub fn flicker_map(frames: &[RgbImage], skip: usize) -> Result<Vec<Option<f64>>, FlickerError> {
    check_frames(frames, skip, "flicker")?;
    let window = &frames[skip..];
    let n = window.len() as f64;
    let pixels = frames[0].pixels.len();
    let mut mean = vec![0.0; pixels];
    for frame in window {
        for (m, p) in mean.iter_mut().zip(&frame.pixels) {
            *m += luminance(p) / n;
        }
    }
    let mut squares = vec![0.0; pixels];
    for frame in window {
        for ((q, p), m) in squares.iter_mut().zip(&frame.pixels).zip(&mean) {
            let d = luminance(p) - m;
            *q += d * d;
        }
    }
    Ok(mean.iter().zip(&squares).map(|(&m, &q)| (m > DARK).then(|| (q / (n - 1.0)).sqrt() / m)).collect())
}

/// The still camera's flicker (module documentation): the mean of [`flicker_map`] over the
/// pixels that have one. An error if there are fewer than `skip + 2` frames, their sizes
/// differ, a value is not finite, or every pixel is dark.
pub fn flicker(frames: &[RgbImage], skip: usize) -> Result<Flicker, FlickerError> {
    let map = flicker_map(frames, skip)?;
    let measured: Vec<f64> = map.iter().flatten().copied().collect();
    if measured.is_empty() {
        return Err(FlickerError::NothingToMeasure(
            "every pixel's mean luminance is at most 1e-4: no flicker to measure",
        ));
    }
    let mean = measured.iter().sum::<f64>() / measured.len() as f64;
    if !mean.is_finite() {
        return Err(FlickerError::NonFiniteResult("flicker"));
    }
    Ok(Flicker { mean, pixels: measured.len(), excluded: map.len() - measured.len(), frames: frames.len() - skip })
}

/// Where each pixel of a frame was in the frame before: the motion vectors of a moving
/// camera, as pixel positions (row-major, `width × height` entries).
#[derive(Clone, Debug, PartialEq)]
pub struct PreviousPixels {
    /// Width of both frames.
    pub width: u32,
    /// Height of both frames.
    pub height: u32,
    /// For pixel (x, y) of frame t, at index y · width + x: its pixel (column, row) in frame
    /// t − 1, or `None` where it was not visible there (disoccluded, or out of view).
    pub previous: Vec<Option<(u32, u32)>>,
}

impl PreviousPixels {
    /// A still camera: every pixel was where it is.
    pub fn still(width: u32, height: u32) -> PreviousPixels {
        let previous = (0..height).flat_map(|y| (0..width).map(move |x| Some((x, y)))).collect();
        PreviousPixels { width, height, previous }
    }

    /// From motion vectors in pixels, `motion[y · width + x]` = (position in frame t) −
    /// (position in frame t − 1) of what pixel (x, y) shows: its previous pixel is
    /// (x − mx, y − my) rounded to the nearest pixel, `None` where that lies outside the frame
    /// or the vector is not finite. Rounding, not interpolation: a bilinear blend of four
    /// previous errors would average their noise away and understate the change.
    pub fn from_motion_vectors(width: u32, height: u32, motion: &[[f32; 2]]) -> PreviousPixels {
        let previous = (0..height)
            .flat_map(|y| (0..width).map(move |x| (x, y)))
            .zip(motion)
            .map(|((x, y), m)| {
                let (px, py) = ((f64::from(x) - f64::from(m[0])).round(), (f64::from(y) - f64::from(m[1])).round());
                let inside = px.is_finite()
                    && py.is_finite()
                    && (0.0..f64::from(width)).contains(&px)
                    && (0.0..f64::from(height)).contains(&py);
                inside.then_some((px as u32, py as u32))
            })
            .collect();
        PreviousPixels { width, height, previous }
    }
}

/// A moving camera's frame-to-frame change of the error ([`temporal_error_change`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ErrorChange {
    /// Mean over pixels, channels and pairs of frames of
    /// (eₜ(p) − eₜ₋₁(prev(p)))² / (refₜ(p) + 10⁻⁴).
    pub mean: f64,
    /// (Pixel, pair of frames) pairs measured.
    pub pairs: usize,
    /// (Pixel, pair of frames) pairs left out: no previous pixel.
    pub disoccluded: usize,
    /// Pairs of consecutive frames in the window.
    pub frame_pairs: usize,
}

/// The moving camera's flicker (module documentation): the relative change of the error along
/// the motion vectors, over the pairs of consecutive frames after the first `skip` frames.
/// `frames[t]` is frame t, `references[t]` its reference, and `previous[t]` maps frame t + 1
/// to frame t (so there is one map fewer than frames). An error if the counts or sizes do not
/// go together, a value is not finite, a reference is negative, a previous pixel is outside
/// the frame, or no pixel has a previous one.
pub fn temporal_error_change(
    frames: &[RgbImage],
    references: &[RgbImage],
    previous: &[PreviousPixels],
    skip: usize,
) -> Result<ErrorChange, FlickerError> {
    check_frames(frames, skip, "the error change along motion")?;
    if references.len() != frames.len() {
        return Err(FlickerError::Counts {
            frames: frames.len(),
            what: "references",
            needed: frames.len(),
            got: references.len(),
        });
    }
    if previous.len() + 1 != frames.len() {
        return Err(FlickerError::Counts {
            frames: frames.len(),
            what: "previous-pixel maps",
            needed: frames.len() - 1,
            got: previous.len(),
        });
    }
    let first = &frames[0];
    let (width, height) = (first.width, first.height);
    check_images(references, "reference", first)?;
    for (frame, reference) in references.iter().enumerate() {
        if let Some(i) = reference.pixels.iter().position(|p| p.iter().any(|&c| c < 0.0)) {
            let (x, y) = ((i % width as usize) as u32, (i / width as usize) as u32);
            return Err(FlickerError::NegativeReference { frame, x, y });
        }
    }
    for (map, pixels) in previous.iter().enumerate() {
        if (pixels.width, pixels.height) != (width, height) || pixels.previous.len() != first.pixels.len() {
            return Err(FlickerError::Size {
                which: format!("previous-pixel map {map}"),
                width: pixels.width,
                height: pixels.height,
                expected_width: width,
                expected_height: height,
            });
        }
        for (i, p) in pixels.previous.iter().enumerate() {
            if let Some((px, py)) = *p
                && (px >= width || py >= height)
            {
                let (x, y) = ((i % width as usize) as u32, (i / width as usize) as u32);
                return Err(FlickerError::OutsideFrame { map, x, y, px, py, width, height });
            }
        }
    }
    let error =
        |t: usize, i: usize, c: usize| f64::from(frames[t].pixels[i][c]) - f64::from(references[t].pixels[i][c]);
    let (mut total, mut pairs, mut disoccluded) = (0.0, 0usize, 0usize);
    for t in skip + 1..frames.len() {
        for (i, p) in previous[t - 1].previous.iter().enumerate() {
            let Some((px, py)) = *p else {
                disoccluded += 1;
                continue;
            };
            let j = py as usize * width as usize + px as usize;
            let change: f64 = (0..3)
                .map(|c| {
                    let d = error(t, i, c) - error(t - 1, j, c);
                    d * d / (f64::from(references[t].pixels[i][c]) + 1e-4)
                })
                .sum();
            total += change / 3.0;
            pairs += 1;
        }
    }
    if pairs == 0 {
        return Err(FlickerError::NothingToMeasure("no pixel has a previous pixel: no error change to measure"));
    }
    let mean = total / pairs as f64;
    if !mean.is_finite() {
        return Err(FlickerError::NonFiniteResult("error change along motion"));
    }
    Ok(ErrorChange { mean, pairs, disoccluded, frame_pairs: frames.len() - skip - 1 })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::evaluation::test_noise::Rng;

    /// A `size` × `size` image of `value(x, y)`.
    fn image(size: u32, mut value: impl FnMut(u32, u32) -> [f32; 3]) -> RgbImage {
        RgbImage { width: size, height: size, pixels: (0..size * size).map(|i| value(i % size, i / size)).collect() }
    }

    #[test]
    fn a_pixel_alternating_between_two_values_has_a_known_flicker() {
        // Grey pixels alternating 1 and 3 over 8 frames after 2 skipped frames of 100:
        // mean 2, sample std √(8/7) · 1, flicker √(8/7) / 2. A constant column scores 0,
        // a black column is excluded.
        let (a, b) = (1.0f32, 3.0f32);
        let mut frames: Vec<RgbImage> = (0..10)
            .map(|t| {
                image(4, |x, _| match x {
                    0 => [0.0; 3],
                    1 => [0.5; 3],
                    _ => [if t % 2 == 0 { a } else { b }; 3],
                })
            })
            .collect();
        frames[0] = image(4, |_, _| [100.0; 3]);
        frames[1] = image(4, |_, _| [100.0; 3]);
        let expected_alternating = (8.0f64 / 7.0).sqrt() * f64::from(b - a) / f64::from(a + b);
        let map = flicker_map(&frames, 2).unwrap();
        assert_eq!(map[0], None);
        assert!(map[1].unwrap().abs() < 1e-12, "{map:?}");
        assert!((map[2].unwrap() - expected_alternating).abs() < 1e-6, "{map:?}");
        let measured = flicker(&frames, 2).unwrap();
        assert_eq!((measured.pixels, measured.excluded, measured.frames), (12, 4, 8));
        // 8 pixels at the alternating value, 4 at 0.
        assert!((measured.mean - expected_alternating * 8.0 / 12.0).abs() < 1e-6, "{measured:?}");
        // Luminance, not channels: a colour that alternates between red and green of equal
        // luminance does not flicker.
        let (red, green) = (1.0 / 0.2126, 1.0 / 0.7152);
        let colour: Vec<RgbImage> =
            (0..6).map(|t| image(2, |_, _| if t % 2 == 0 { [red, 0.0, 0.0] } else { [0.0, green, 0.0] })).collect();
        assert!(flicker(&colour, 0).unwrap().mean < 1e-6);
    }

    #[test]
    fn gaussian_noise_flickers_by_sigma_over_mu() {
        // Luminance μ = 2 with noise σ = 0.2 on every channel alike (so σ in luminance too),
        // 32 frames: std/mean ≈ 0.1 (the sample std's own bias, c₄(32) ≈ 0.992, is inside the
        // tolerance).
        let mut rng = Rng::new(11);
        let frames: Vec<RgbImage> = (0..33)
            .map(|_| {
                image(32, |_, _| {
                    let v = (2.0 + 0.2 * rng.normal()) as f32;
                    [v; 3]
                })
            })
            .collect();
        let measured = flicker(&frames, 1).unwrap();
        assert!((measured.mean - 0.1).abs() < 0.003, "{measured:?}");
        assert_eq!((measured.pixels, measured.excluded, measured.frames), (1024, 0, 32));
    }

    #[test]
    fn flicker_errors_name_the_problem() {
        let frames = vec![image(2, |_, _| [1.0; 3]); 3];
        assert_eq!(
            flicker(&frames, 2).unwrap_err().to_string(),
            "flicker needs at least 2 frames after skipping 2, got 3 in all"
        );
        let dark = vec![image(2, |_, _| [0.0; 3]); 3];
        assert!(flicker(&dark, 0).unwrap_err().to_string().starts_with("every pixel's mean luminance"));
        let mut mixed = frames.clone();
        mixed[1] = image(3, |_, _| [1.0; 3]);
        assert_eq!(flicker(&mixed, 0).unwrap_err().to_string(), "frame 1 is 3x3 but frame 0 is 2x2");
        mixed[1] = image(2, |x, y| if (x, y) == (1, 0) { [f32::INFINITY; 3] } else { [1.0; 3] });
        assert_eq!(flicker(&mixed, 0).unwrap_err().to_string(), "frame 1 has a non-finite value at pixel (1, 0)");
        assert_eq!(flicker(&vec![image(0, |_, _| [0.0; 3]); 2], 0).unwrap_err(), FlickerError::Empty);
    }

    #[test]
    fn motion_vectors_give_the_rounded_previous_pixel() {
        let motion = [[1.0, 0.0], [0.4, -0.6], [f32::NAN, 0.0], [-1.0, 0.0]];
        let previous = PreviousPixels::from_motion_vectors(2, 2, &motion);
        // (0,0) − (1,0) leaves the frame; (1,0) − (0.4,−0.6) → (0.6, 0.6) → (1, 1);
        // a NaN vector has none; (1,1) − (−1,0) → (2,1) leaves the frame.
        assert_eq!(previous.previous, vec![None, Some((1, 1)), None, None]);
        assert_eq!(PreviousPixels::still(2, 1).previous, vec![Some((0, 0)), Some((1, 0))]);
    }

    /// A camera panning `dx` pixels a frame over a world whose reference at world column u
    /// is 0.5 + (u mod 7) / 4 and whose error at world point (u, y) evolves as
    /// Eₜ = ρ Eₜ₋₁ + √(1 − ρ²) σ g (stationary variance σ²), scaled by √ref so that its
    /// relative variance is σ². Frame t shows world column x + t · dx at pixel x, so pixel x
    /// of frame t was at x + dx in frame t − 1.
    fn panning(frames: usize, dx: u32, rho: f64, sigma: f64) -> (Vec<RgbImage>, Vec<RgbImage>, Vec<PreviousPixels>) {
        const SIZE: u32 = 48;
        let world_width = SIZE as usize + frames * dx as usize;
        let world_reference = |u: usize| 0.5 + (u % 7) as f64 / 4.0;
        let mut rng = Rng::new(12);
        let mut world: Vec<[f64; 3]> =
            (0..world_width * SIZE as usize).map(|_| [0; 3].map(|_| sigma * rng.normal())).collect();
        let (mut images, mut references, mut previous) = (Vec::new(), Vec::new(), Vec::new());
        for t in 0..frames {
            if t > 0 {
                for e in world.iter_mut().flatten() {
                    *e = rho * *e + (1.0 - rho * rho).sqrt() * sigma * rng.normal();
                }
                let motion = vec![[-(dx as f32), 0.0]; (SIZE * SIZE) as usize];
                previous.push(PreviousPixels::from_motion_vectors(SIZE, SIZE, &motion));
            }
            let u = |x: u32| x as usize + t * dx as usize;
            references.push(image(SIZE, |x, _| [world_reference(u(x)) as f32; 3]));
            images.push(image(SIZE, |x, y| {
                let r = world_reference(u(x));
                let e = world[y as usize * world_width + u(x)];
                e.map(|e| (r + r.sqrt() * e) as f32)
            }));
        }
        (images, references, previous)
    }

    #[test]
    fn the_error_change_along_motion_has_a_known_value() {
        // ρ = 0.75, σ² = 0.04: E[(Eₜ − Eₜ₋₁)²] = 2(1 − ρ)σ² = 0.02 per relative unit (the
        // reference r over r + 1e-4 shrinks it by < 0.03 %). Without following the motion the
        // pixel would be compared with another world point: 2σ² = 0.08. 48 × 48 × 3 values
        // over 7 pairs of frames after 1 skipped: standard error ≈ 0.02 · √2/√(45·48·3·7) ≈ 2.3e-4.
        let (frames, references, previous) = panning(9, 3, 0.75, 0.2);
        let change = temporal_error_change(&frames, &references, &previous, 1).unwrap();
        assert!((change.mean - 0.02).abs() < 1.5e-3, "{change:?}");
        // The 3 columns that come into view each frame have no previous pixel.
        assert_eq!((change.frame_pairs, change.disoccluded, change.pairs), (7, 7 * 3 * 48, 7 * 45 * 48));
        // Errors carried unchanged along the motion (ρ = 1) do not change at all.
        let (frames, references, previous) = panning(4, 2, 1.0, 0.2);
        let carried = temporal_error_change(&frames, &references, &previous, 0).unwrap();
        assert!(carried.mean < 1e-10, "{carried:?}");
        // Independent errors (ρ = 0) on a still camera: 2σ².
        let (frames, references, _) = panning(6, 0, 0.0, 0.2);
        let still = vec![PreviousPixels::still(48, 48); 5];
        let independent = temporal_error_change(&frames, &references, &still, 0).unwrap();
        assert!((independent.mean - 0.08).abs() < 4e-3, "{independent:?}");
    }

    #[test]
    fn error_change_errors_name_the_problem() {
        let (frames, references, previous) = panning(3, 1, 0.5, 0.1);
        let message = temporal_error_change(&frames, &references[..2], &previous, 0).unwrap_err().to_string();
        assert_eq!(message, "3 frames need 3 references, got 2");
        let message = temporal_error_change(&frames, &references, &previous[..1], 0).unwrap_err().to_string();
        assert_eq!(message, "3 frames need 2 previous-pixel maps, got 1");
        let message = temporal_error_change(&frames, &references, &previous, 2).unwrap_err().to_string();
        assert!(message.starts_with("the error change along motion needs at least 2 frames after skipping 2"));
        let mut outside = previous.clone();
        outside[1].previous[5] = Some((48, 0));
        let message = temporal_error_change(&frames, &references, &outside, 0).unwrap_err().to_string();
        assert_eq!(message, "previous-pixel map 1 sends pixel (5, 0) to (48, 0), outside the 48x48 frame");
        let mut negative = references.clone();
        negative[2].pixels[48] = [-1.0; 3];
        let message = temporal_error_change(&frames, &negative, &previous, 0).unwrap_err().to_string();
        assert!(message.starts_with("reference 2 is negative at pixel (0, 1)"), "{message}");
        let blind = vec![PreviousPixels { previous: vec![None; 48 * 48], ..previous[0].clone() }; 2];
        let message = temporal_error_change(&frames, &references, &blind, 0).unwrap_err().to_string();
        assert!(message.starts_with("no pixel has a previous pixel"), "{message}");
        let small = vec![PreviousPixels::still(4, 4); 2];
        let message = temporal_error_change(&frames, &references, &small, 0).unwrap_err().to_string();
        assert_eq!(message, "previous-pixel map 0 is 4x4 but frame 0 is 48x48");
    }
}
