//! What the `camera_rays` kernel computes, with the same operations in the same order.

use crate::trace_types::{CameraParams, Ray};

fn pcg_hash(value: u32) -> u32 {
    let state = value.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

fn unit_float(bits: u32) -> f32 {
    (bits >> 8) as f32 * (1.0 / 16_777_216.0)
}

/// The ray of pixel (x, y).
pub fn camera_ray(camera: &CameraParams, x: u32, y: u32) -> Ray {
    let pixel = y * camera.width + x;
    let mut jitter = (0.5f32, 0.5f32);
    if camera.jitter_seed != 0 {
        let a = pcg_hash(pixel ^ pcg_hash(camera.jitter_seed));
        jitter = (unit_float(a), unit_float(pcg_hash(a)));
    }
    let px = (x as f32 + jitter.0) / camera.width as f32;
    let py = (y as f32 + jitter.1) / camera.height as f32;
    let sx = (2.0 * px - 1.0) * camera.tan_half_x;
    let sy = (2.0 * py - 1.0) * camera.tan_half_y;
    let v: [f32; 3] = std::array::from_fn(|i| camera.forward[i] + sx * camera.right[i] - sy * camera.up[i]);
    let length = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    let direction = v.map(|c| c / length);
    let along = direction[0] * camera.forward[0] + direction[1] * camera.forward[1] + direction[2] * camera.forward[2];
    let scale = camera.near_clip / along;
    let origin = std::array::from_fn(|i| camera.origin[i] + direction[i] * scale);
    Ray { origin, tmin: 0.0, direction, tmax: camera.far_clip }
}

/// Every pixel's ray, row-major.
pub fn camera_rays(camera: &CameraParams) -> Vec<Ray> {
    (0..camera.height).flat_map(|y| (0..camera.width).map(move |x| camera_ray(camera, x, y))).collect()
}
