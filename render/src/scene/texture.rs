//! Textures decoded to linear RGB on the host, so that every backend filters the same
//! numbers (CONVENTIONS.md: 8-bit sRGB PNG, exact sRGB EOTF).

use super::SceneError;
use std::path::Path;

/// A texture in linear RGB, row 0 = the top row of the image file.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    /// Where it came from (a file, or a glTF image), for messages.
    pub name: String,
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Row-major linear RGB texels.
    pub texels: Vec<[f32; 3]>,
}

/// The most bytes a texture's decoded pixels may take (256 MiB: an 8192 × 8192 RGBA8
/// image), so that a small file declaring a huge image is refused before it is decoded.
pub const MAX_TEXTURE_BYTES: u64 = 256 << 20;

/// The exact sRGB EOTF (IEC 61966-2-1), 8-bit code to linear.
pub fn srgb_to_linear(code: u8) -> f32 {
    let c = f32::from(code) / 255.0;
    if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}

impl Texture {
    /// Decodes 8-bit RGB(A) pixels, through the sRGB EOTF when `srgb`, else as c / 255.
    pub fn from_rgba8(name: String, width: u32, height: u32, rgba: &[u8], srgb: bool) -> Texture {
        let decode = |c: u8| if srgb { srgb_to_linear(c) } else { f32::from(c) / 255.0 };
        let texels = rgba.chunks_exact(4).map(|p| [decode(p[0]), decode(p[1]), decode(p[2])]).collect();
        Texture { name, width, height, texels }
    }

    /// Loads a PNG (or another format the `image` crate decodes here).
    pub fn load(path: &Path, srgb: bool) -> Result<Texture, SceneError> {
        let bytes = crate::scene::read_capped(path).map_err(|source| SceneError::Io { path: path.into(), source })?;
        Texture::decode(path, &bytes, srgb)
    }

    /// Decodes the image file in `bytes` (its format guessed from its contents; `path`
    /// names it in errors and in [`Texture::name`]). Images over [`MAX_TEXTURE_BYTES`]
    /// of decoded pixels are refused before they are decoded.
    pub fn decode(path: &Path, bytes: &[u8], srgb: bool) -> Result<Texture, SceneError> {
        let image = decode_image(path, bytes)?;
        let rgba = image.to_rgba8();
        let (width, height) = rgba.dimensions();
        if width == 0 || height == 0 {
            return Err(SceneError::Image { path: path.into(), message: "the image has no pixels".into() });
        }
        Ok(Texture::from_rgba8(path.display().to_string(), width, height, rgba.as_raw(), srgb))
    }
}

/// Decodes the image file in `bytes` (format guessed from its contents), refusing one
/// whose pixels would take more than [`MAX_TEXTURE_BYTES`] before decoding them.
pub(super) fn decode_image(path: &Path, bytes: &[u8]) -> Result<image::DynamicImage, SceneError> {
    let mut reader = image::ImageReader::new(std::io::Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|source| SceneError::Io { path: path.into(), source })?;
    let mut limits = image::Limits::default();
    limits.max_alloc = Some(MAX_TEXTURE_BYTES);
    reader.limits(limits);
    reader.decode().map_err(|error| match error {
        image::ImageError::IoError(source) => SceneError::Io { path: path.into(), source },
        other => SceneError::Image { path: path.into(), message: other.to_string() },
    })
}

/// The pixels of a decoded image as 8-bit RGBA (grey replicated, 16-bit channels rounded
/// as (v · 255 + 32767) / 65535, float channels clamped to [0, 1] and rounded, NaN as 0,
/// alpha 255 where there is none).
pub(super) fn rgba8(image: &image::DynamicImage) -> Vec<u8> {
    use image::DynamicImage as D;
    match image {
        D::ImageLuma16(_) | D::ImageLumaA16(_) | D::ImageRgb16(_) | D::ImageRgba16(_) => {
            image.to_rgba16().into_raw().into_iter().map(|v| ((u32::from(v) * 255 + 32767) / 65535) as u8).collect()
        }
        D::ImageRgb32F(_) | D::ImageRgba32F(_) => image
            .to_rgba32f()
            .into_raw()
            .into_iter()
            .map(|v| if v.is_nan() { 0 } else { (v.clamp(0.0, 1.0) * 255.0).round() as u8 })
            .collect(),
        _ => image.to_rgba8().into_raw(),
    }
}
