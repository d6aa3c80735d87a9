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
        let image = image::open(path).map_err(|error| match error {
            image::ImageError::IoError(source) => SceneError::Io { path: path.into(), source },
            other => SceneError::Image { path: path.into(), message: other.to_string() },
        })?;
        let rgba = image.to_rgba8();
        let (width, height) = rgba.dimensions();
        if width == 0 || height == 0 {
            return Err(SceneError::Image { path: path.into(), message: "the image has no pixels".into() });
        }
        Ok(Texture::from_rgba8(path.display().to_string(), width, height, rgba.as_raw(), srgb))
    }
}
