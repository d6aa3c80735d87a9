//! The lat-long environment map (CONVENTIONS.md "Emitters"): an RGB float EXR, its
//! radiance scale and rotation, loaded and checked on the host.

use super::SceneError;
use super::exr_decode::{RgbExr, decode_rgb_exr};
use std::path::{Path, PathBuf};

/// A loaded environment map.
#[derive(Clone, Debug, PartialEq)]
pub struct Environment {
    /// The EXR file.
    pub file: PathBuf,
    /// Width in texels (φ).
    pub width: u32,
    /// Height in texels (θ; row 0 = the +Y pole of the map's frame).
    pub height: u32,
    /// Row-major linear RGB radiance, before `scale`.
    pub texels: Vec<[f32; 3]>,
    /// Radiance scale.
    pub scale: f32,
    /// R, the rotation from the map's frame to the world (rows).
    pub to_world: [[f32; 3]; 3],
}

impl Environment {
    /// Loads `file` (RGB, half or float samples), refusing negative or non-finite
    /// radiance with the pixel named, and a `to_world` that is not a rotation.
    pub fn load(file: &Path, scale: f32, to_world: Option<[[f32; 4]; 4]>) -> Result<Environment, SceneError> {
        let bytes = crate::scene::read_capped(file).map_err(|source| SceneError::Io { path: file.into(), source })?;
        Environment::from_exr_bytes(file, &bytes, scale, to_world)
    }

    /// [`Environment::load`] of the EXR file in `bytes` (`file` names it in errors),
    /// decoded by [`decode_rgb_exr`] (which refuses an image larger than its file can hold
    /// before allocating its pixels).
    pub fn from_exr_bytes(
        file: &Path,
        bytes: &[u8],
        scale: f32,
        to_world: Option<[[f32; 4]; 4]>,
    ) -> Result<Environment, SceneError> {
        let error = |message: String| SceneError::Image { path: file.into(), message };
        let RgbExr { width, height, texels } = decode_rgb_exr(file, bytes)?;
        if width == 0 || height == 0 {
            return Err(error("the image has no pixels".into()));
        }
        if let Some(index) = texels.iter().position(|t| t.iter().any(|c| !c.is_finite() || *c < 0.0)) {
            return Err(error(format!(
                "pixel ({}, {}) has radiance {:?}: must be finite and non-negative",
                index % width,
                index / width,
                texels[index]
            )));
        }
        if !scale.is_finite() || scale < 0.0 {
            return Err(SceneError::Image {
                path: file.into(),
                message: format!("environment scale {scale} must be finite and non-negative"),
            });
        }
        let brightest = texels.iter().flatten().fold(0.0f32, |a, &b| a.max(b));
        if f64::from(brightest) * f64::from(scale) > f64::from(super::MAX_RADIANCE) {
            return Err(error(format!(
                "radiance {brightest:e} × scale {scale} is above the {:e} a scene may emit (sums of such samples \
                 overflow single-precision floats)",
                super::MAX_RADIANCE
            )));
        }
        let rotation = match to_world {
            Some(m) => [[m[0][0], m[0][1], m[0][2]], [m[1][0], m[1][1], m[1][2]], [m[2][0], m[2][1], m[2][2]]],
            None => [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        };
        let r = glam::Mat3::from_cols_array_2d(&rotation).transpose();
        let gram = r.transpose() * r;
        if !gram.abs_diff_eq(glam::Mat3::IDENTITY, 1e-3) || (r.determinant() - 1.0).abs() > 1e-3 {
            return Err(error(format!("to_world {rotation:?} is not a rotation (the map can only be rotated)")));
        }
        Ok(Environment {
            file: file.into(),
            width: width as u32,
            height: height as u32,
            texels,
            scale,
            to_world: rotation,
        })
    }
}
