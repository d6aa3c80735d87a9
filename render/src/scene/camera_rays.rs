//! Primary rays of the pinhole camera exactly as CONVENTIONS.md states them:
//! forward = normalize(target − origin), right = normalize(cross(forward, up)),
//! true_up = cross(right, forward); film position (px, py) ∈ [0, 1]², (0, 0) top-left;
//! dir = normalize(forward + (2px − 1)·tan(hfov_x)·right − (2py − 1)·tan(hfov_y)·true_up);
//! rays start on the near plane.

use super::Camera;
use glam::Vec3;
use strata_kernels::trace_types::CameraParams;

/// Why a camera whose numbers overflow has no frame.
const BEYOND_PRECISION: &str = "the camera's vectors or opening angle are beyond single precision";

/// The camera's frame and field of view, ready to make rays.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraFrame {
    /// Eye position.
    pub origin: Vec3,
    /// Unit viewing direction.
    pub forward: Vec3,
    /// Unit right vector (image +x).
    pub right: Vec3,
    /// Unit up vector (image −y).
    pub up: Vec3,
    /// tan of half the horizontal field of view.
    pub tan_half_x: f32,
    /// tan of half the vertical field of view.
    pub tan_half_y: f32,
    /// Near clip distance along `forward`.
    pub near_clip: f32,
}

impl CameraFrame {
    /// The frame of `camera`; `None` if `fov_axis` is neither `x` nor `smaller`, or the
    /// camera looks along its up vector ([`CameraFrame::checked`] says which).
    pub fn new(camera: &Camera) -> Option<CameraFrame> {
        CameraFrame::unchecked(camera).ok()
    }

    /// The frame of `camera`, or why it has none, in words that name the camera's fields:
    /// `fov_axis` other than `x` or `smaller`, `target` equal to `origin`, a view
    /// direction parallel to `up` (or `up` zero), or vectors or an opening angle beyond
    /// single precision. Each reason is the one that holds: a valid `fov_axis` is never
    /// blamed for a view along `up` (one message named both and so contradicted itself:
    /// "fov_axis `smaller` must be `x` or `smaller`").
    pub fn checked(camera: &Camera) -> Result<CameraFrame, String> {
        let frame = CameraFrame::unchecked(camera)?;
        let directions = [frame.forward, frame.right, frame.up].iter().all(|v| v.is_finite());
        if !(directions && frame.origin.is_finite() && frame.tan_half_x.is_finite() && frame.tan_half_y.is_finite()) {
            return Err(BEYOND_PRECISION.into());
        }
        Ok(frame)
    }

    /// [`CameraFrame::checked`] without the finiteness check.
    fn unchecked(camera: &Camera) -> Result<CameraFrame, String> {
        let origin = Vec3::from(camera.origin);
        let (w, h) = (camera.width as f32, camera.height as f32);
        let tan_half = (camera.fov_deg.to_radians() * 0.5).tan();
        let (tan_half_x, tan_half_y) = match camera.fov_axis.as_str() {
            "x" => (tan_half, tan_half * h / w),
            "smaller" if w <= h => (tan_half, tan_half * h / w),
            "smaller" => (tan_half * w / h, tan_half),
            other => return Err(format!("fov_axis `{other}`: expected `x` or `smaller`")),
        };
        let view = Vec3::from(camera.target) - origin;
        if view == Vec3::ZERO {
            return Err("target equals origin: the camera has no view direction".into());
        }
        let forward = view.try_normalize().ok_or(BEYOND_PRECISION)?;
        let side = forward.cross(Vec3::from(camera.up));
        let right = side.try_normalize().ok_or(if side.is_finite() {
            "the view direction (target - origin) is parallel to `up` (or `up` is zero): the image would have no \
             horizontal direction"
        } else {
            BEYOND_PRECISION
        })?;
        let up = right.cross(forward);
        Ok(CameraFrame { origin, forward, right, up, tan_half_x, tan_half_y, near_clip: camera.near_clip })
    }

    /// The `camera_rays` kernel's parameters for a `width × height` image; `jitter_seed`
    /// 0 gives pixel centres.
    pub fn params(&self, width: u32, height: u32, far_clip: f32, jitter_seed: u32) -> CameraParams {
        CameraParams {
            origin: self.origin.into(),
            near_clip: self.near_clip,
            forward: self.forward.into(),
            tan_half_x: self.tan_half_x,
            right: self.right.into(),
            tan_half_y: self.tan_half_y,
            up: self.up.into(),
            far_clip,
            width,
            height,
            jitter_seed,
            _pad: 0,
        }
    }

    /// The ray through film position (px, py): its start on the near plane and its unit
    /// direction.
    pub fn ray(&self, px: f32, py: f32) -> (Vec3, Vec3) {
        let direction = (self.forward + (2.0 * px - 1.0) * self.tan_half_x * self.right
            - (2.0 * py - 1.0) * self.tan_half_y * self.up)
            .normalize();
        (self.origin + direction * (self.near_clip / direction.dot(self.forward)), direction)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera(width: u32, height: u32, axis: &str) -> Camera {
        Camera {
            origin: [0.0, 0.0, 0.0],
            target: [0.0, 0.0, 1.0],
            up: [0.0, 1.0, 0.0],
            fov_deg: 90.0,
            fov_axis: axis.into(),
            width,
            height,
            near_clip: 0.5,
            far_clip: 100.0,
        }
    }

    #[test]
    fn rays_follow_the_conventions() {
        let frame = CameraFrame::new(&camera(200, 100, "smaller")).unwrap();
        // Looking down +z with +y up: right = forward × up = (0,0,1) × (0,1,0) = (-1,0,0).
        assert!((frame.right - Vec3::new(-1.0, 0.0, 0.0)).length() < 1e-6);
        let (start, centre) = frame.ray(0.5, 0.5);
        assert!((centre - Vec3::Z).length() < 1e-6 && (start - Vec3::new(0.0, 0.0, 0.5)).length() < 1e-6);
        // The smaller axis (vertical) spans 90°: the top edge is 45° up.
        let (_, top) = frame.ray(0.5, 0.0);
        assert!((top.y - top.z).abs() < 1e-6 && top.y > 0.0);
        // The wider axis follows from the aspect ratio: tan(half_x) = 2.
        let (_, left_edge) = frame.ray(0.0, 0.5);
        assert!((left_edge.x / left_edge.z - 2.0).abs() < 1e-5, "{left_edge}");
        let x_axis = CameraFrame::new(&camera(200, 100, "x")).unwrap();
        assert!((x_axis.tan_half_x - 1.0).abs() < 1e-6 && (x_axis.tan_half_y - 0.5).abs() < 1e-6);
        assert!(CameraFrame::new(&camera(8, 8, "diagonal")).is_none());
    }

    #[test]
    fn the_kernel_reference_makes_the_same_rays() {
        let camera = camera(16, 8, "smaller");
        let frame = CameraFrame::new(&camera).unwrap();
        let params = frame.params(16, 8, 100.0, 0);
        for (x, y) in [(0, 0), (7, 3), (15, 7)] {
            let ray = strata_kernels::reference::camera_rays::camera_ray(&params, x, y);
            let (origin, direction) = frame.ray((x as f32 + 0.5) / 16.0, (y as f32 + 0.5) / 8.0);
            assert!((Vec3::from(ray.direction) - direction).length() < 1e-6);
            assert!((Vec3::from(ray.origin) - origin).length() < 1e-5);
        }
    }
}
