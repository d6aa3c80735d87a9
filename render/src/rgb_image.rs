//! Linear RGB images: the renderer's output, read and written as float EXR (through the
//! exr crate) and previewed as tone-mapped sRGB PNG.

use std::path::Path;
use thiserror::Error;

/// An image file that cannot be read or written.
#[derive(Debug, Error)]
#[error("{path}: {message}")]
pub struct ImageError {
    /// The file.
    pub path: String,
    /// What went wrong.
    pub message: String,
}

/// A row-major linear RGB image, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct RgbImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Pixels, `width × height`.
    pub pixels: Vec<[f32; 3]>,
}

impl RgbImage {
    /// The image of a kernel's `vec4<f32>` per pixel (rgb, and a fourth word the image
    /// leaves out: the frame's invalid flag, the denoiser's variance), row-major.
    pub fn from_rgba(width: u32, height: u32, pixels: &[[f32; 4]]) -> RgbImage {
        RgbImage { width, height, pixels: pixels.iter().map(|p| [p[0], p[1], p[2]]).collect() }
    }

    /// A black image.
    pub fn new(width: u32, height: u32) -> RgbImage {
        RgbImage { width, height, pixels: vec![[0.0; 3]; width as usize * height as usize] }
    }

    /// Mean of every channel of every pixel.
    pub fn mean(&self) -> [f64; 3] {
        let mut sum = [0.0f64; 3];
        for p in &self.pixels {
            for c in 0..3 {
                sum[c] += f64::from(p[c]);
            }
        }
        sum.map(|s| s / self.pixels.len().max(1) as f64)
    }

    /// Reads the R, G and B channels of an EXR's first layer through
    /// [`crate::scene::decode_rgb_exr`] (its size checked before anything is allocated,
    /// decoding on this thread with a decoder's panic turned into an error) and refuses
    /// an image with a NaN or infinite pixel, naming the first: a reference with one
    /// would make every RelMSE NaN.
    pub fn read_exr(path: &Path) -> Result<RgbImage, ImageError> {
        let error = |message: String| ImageError { path: path.display().to_string(), message };
        let bytes = crate::scene::read_capped(path).map_err(|e| error(e.to_string()))?;
        let exr = crate::scene::decode_rgb_exr(path, &bytes).map_err(|e| match e {
            crate::scene::SceneError::Image { message, .. } => error(message),
            other => error(other.to_string()),
        })?;
        let (width, height) = (u32::try_from(exr.width), u32::try_from(exr.height));
        let (Ok(width), Ok(height)) = (width, height) else {
            return Err(error(format!("{}x{} pixels is too large", exr.width, exr.height)));
        };
        let image = RgbImage { width, height, pixels: exr.texels };
        if let Some((x, y)) = image.first_non_finite() {
            return Err(error(format!(
                "pixel ({x}, {y}) is {:?}: an image with non-finite values cannot be measured",
                image.pixels[(y * width + x) as usize]
            )));
        }
        Ok(image)
    }

    /// The first pixel (x, y) with a NaN or infinite channel, in row order.
    pub fn first_non_finite(&self) -> Option<(u32, u32)> {
        let index = self.pixels.iter().position(|p| p.iter().any(|c| !c.is_finite()))?;
        let width = self.width.max(1) as usize;
        Some(((index % width) as u32, (index / width) as u32))
    }

    /// Refuses an image with a NaN or infinite pixel, naming the first, so that no
    /// output file hides one.
    fn check_finite(&self, path: &Path) -> Result<(), ImageError> {
        match self.first_non_finite() {
            None => Ok(()),
            Some((x, y)) => Err(ImageError {
                path: path.display().to_string(),
                message: format!(
                    "pixel ({x}, {y}) is {:?}: an image with non-finite values is not written",
                    self.pixels[(y * self.width + x) as usize]
                ),
            }),
        }
    }

    /// The float32 RGB EXR file of the image, in memory.
    pub fn exr_bytes(&self) -> Result<Vec<u8>, String> {
        use exr::prelude::{Encoding, Image, LineOrder, SpecificChannels, Vec2, WritableImage};
        let width = self.width as usize;
        // Blocks in increasing order: the crate's default (unspecified) lets its threads
        // write each compressed block as it is done, so two runs of one render wrote the
        // same pixels in different files. In order, it still compresses in parallel.
        let encoding = Encoding { line_order: LineOrder::Increasing, ..Encoding::FAST_LOSSLESS };
        let channels = SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| {
            let p = self.pixels[y * width + x];
            (p[0], p[1], p[2])
        });
        let mut bytes = std::io::Cursor::new(Vec::new());
        Image::from_encoded_channels((width, self.height as usize), encoding, channels)
            .write()
            .to_buffered(&mut bytes)
            .map_err(|e| e.to_string())?;
        Ok(bytes.into_inner())
    }

    /// The 8-bit sRGB PNG file of the image (radiance × `exposure`, clamped to [0, 1],
    /// sRGB-encoded), in memory.
    pub fn png_bytes(&self, exposure: f32) -> Result<Vec<u8>, String> {
        let pixels: Vec<u8> = self.pixels.iter().flat_map(|p| p.map(|c| linear_to_srgb8(c * exposure))).collect();
        encode_png(&pixels, self.width, self.height, image::ExtendedColorType::Rgb8)
    }

    /// Writes a float32 RGB EXR, complete or not at all ([`crate::atomic_file`]).
    pub fn write_exr(&self, path: &Path) -> Result<(), ImageError> {
        self.check_finite(path)?;
        let error = |message: String| ImageError { path: path.display().to_string(), message };
        let bytes = self.exr_bytes().map_err(error)?;
        crate::atomic_file::write(path, bytes).map_err(|e| without_path(path, e))
    }

    /// Writes an 8-bit sRGB PNG: radiance × `exposure`, clamped to [0, 1], sRGB-encoded;
    /// complete or not at all. `exposure` must be finite and positive (a NaN or negative
    /// one would write a black picture, an infinite one a white one).
    pub fn write_png(&self, path: &Path, exposure: f32) -> Result<(), ImageError> {
        self.check_finite(path)?;
        let error = |message: String| ImageError { path: path.display().to_string(), message };
        if !(exposure.is_finite() && exposure > 0.0) {
            return Err(error(format!("exposure {exposure}: must be finite and positive")));
        }
        let bytes = self.png_bytes(exposure).map_err(error)?;
        crate::atomic_file::write(path, bytes).map_err(|e| without_path(path, e))
    }
}

/// A PNG file of 8-bit `pixels` in memory.
pub fn encode_png(pixels: &[u8], width: u32, height: u32, colour: image::ExtendedColorType) -> Result<Vec<u8>, String> {
    use image::ImageEncoder;
    let mut bytes = Vec::new();
    image::codecs::png::PngEncoder::new(&mut bytes)
        .write_image(pixels, width, height, colour)
        .map_err(|e| e.to_string())?;
    Ok(bytes)
}

/// An [`ImageError`] of a failed [`crate::atomic_file::write`] (whose message names the
/// file already).
fn without_path(path: &Path, error: crate::atomic_file::WriteError) -> ImageError {
    let text = error.to_string();
    let prefix = format!("{}: ", path.display());
    ImageError { path: path.display().to_string(), message: text.strip_prefix(&prefix).unwrap_or(&text).to_string() }
}

/// sRGB OETF of a linear value, clamped to [0, 1] and rounded to 8 bits (NaN gives 0).
pub fn linear_to_srgb8(linear: f32) -> u8 {
    let c = if linear.is_nan() { 0.0 } else { linear.clamp(0.0, 1.0) };
    let encoded = if c <= 0.003_130_8 { 12.92 * c } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 };
    (encoded * 255.0 + 0.5) as u8
}

#[cfg(test)]
mod tests {
    use super::RgbImage;

    /// One image gives one EXR file, byte for byte, every time: by default the exr crate
    /// compresses blocks on several threads and writes each as it is done, so two runs
    /// of the same render wrote the same pixels in different files. The file says its
    /// blocks are in increasing order (the check that fails every time on such a writer;
    /// the repeated writes fail only where the threads happened to finish out of order).
    #[test]
    fn an_image_gives_the_same_exr_bytes_every_time() {
        let (width, height) = (512, 384);
        let pixels = (0..width * height)
            .map(|i| {
                let x = i as f32;
                [x.sin().abs(), (x * 0.37).cos().abs(), x * 1e-3]
            })
            .collect();
        let image = RgbImage { width, height, pixels };
        let first = image.exr_bytes().unwrap();
        let meta = exr::meta::MetaData::read_from_buffered(std::io::Cursor::new(&first), false).unwrap();
        assert_eq!(meta.headers[0].line_order, exr::meta::attribute::LineOrder::Increasing);
        for attempt in 0..40 {
            assert!(image.exr_bytes().unwrap() == first, "attempt {attempt} wrote other bytes");
        }
    }
}
