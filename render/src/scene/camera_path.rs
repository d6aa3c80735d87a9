//! Animated cameras for temporal reuse: where the camera is at each frame of a sequence.
//!
//! A [`CameraPath`] moves a base [`Camera`]'s `origin` and `target` over frames; every
//! other field (up vector, field of view, resolution, clip distances) stays the base's.
//! Paths are keyframed ([`CameraPath::Keyframes`], loaded from JSON by
//! [`CameraPath::load`]) or one of two built-in closed forms: [`CameraPath::orbit`]
//! (circle around the target) and [`CameraPath::dolly`] (straight along the view
//! direction). [`parse_camera_path`] reads the command-line spelling of all of them.
//!
//! Keyframes are interpolated by Catmull-Rom splines in frame time: each key's tangent is
//! the finite difference of its neighbours, `(p[i+1] - p[i-1]) / (f[i+1] - f[i-1])`, and the
//! first and last keys use the one-sided difference to their only neighbour. For evenly
//! spaced keys this is exactly the uniform Catmull-Rom spline; for unevenly spaced keys the
//! speed stays continuous across keys. The curve passes through every key exactly, two keys
//! give a straight line at constant speed, and frames before the first key or after the
//! last one hold that key (clamping).

use super::{Camera, CameraFrame, SceneError};
use glam::DVec3;
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// One key of a keyframed camera path: where the camera is and what it looks at on `frame`.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct CameraKeyframe {
    /// Frame number of the key (fractional frames allowed); strictly increasing along a path.
    pub frame: f32,
    /// Eye position on that frame.
    pub origin: [f32; 3],
    /// Point looked at on that frame (never equal to `origin`).
    pub target: [f32; 3],
}

/// How the camera moves over the frames of a sequence; [`CameraPath::camera_at`] gives the
/// camera of one frame.
///
/// The built-ins are closed forms rather than keyframes, so that they run for any number
/// of frames and an orbit stays exactly on its circle.
#[derive(Clone, Debug, PartialEq)]
pub enum CameraPath {
    /// The base camera on every frame.
    Static,
    /// Catmull-Rom interpolation through keys with strictly increasing, finite frames
    /// (the module documentation has the details), clamped to the first and last key.
    /// No keys is the base camera; one key holds that key on every frame.
    /// [`CameraPath::load`] checks the keys; a path built by hand should follow the same rules.
    Keyframes(Vec<CameraKeyframe>),
    /// The origin turns around `center` about the axis `axis` (through `center`), by
    /// `degrees_per_frame` each frame, counter-clockwise seen from the tip of `axis`
    /// (right-hand rule); the camera keeps looking at `center`.
    Orbit {
        /// Eye position on frame 0.
        start: [f32; 3],
        /// Point looked at and turned around.
        center: [f32; 3],
        /// Rotation axis, unit length (the base camera's up vector), or zero for no rotation.
        axis: [f32; 3],
        /// Angle turned per frame, degrees.
        degrees_per_frame: f32,
    },
    /// Origin and target both move along `direction` by `distance_per_frame` each frame.
    Dolly {
        /// Eye position on frame 0.
        origin: [f32; 3],
        /// Point looked at on frame 0.
        target: [f32; 3],
        /// Unit view direction on frame 0 (`target - origin`, normalised), or zero for no motion.
        direction: [f32; 3],
        /// Distance moved per frame, scene units; positive moves towards the target.
        distance_per_frame: f32,
    },
}

/// The file format read by [`CameraPath::load`].
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CameraPathFile {
    keyframes: Vec<CameraKeyframe>,
}

impl CameraPath {
    /// Orbit around `base.target` about `base.up` (through the target) by `degrees_per_frame`
    /// each frame, starting at `base.origin`: the distance to the target stays the same.
    /// A zero or non-finite up vector gives no rotation.
    pub fn orbit(base: &Camera, degrees_per_frame: f32) -> CameraPath {
        CameraPath::Orbit {
            start: base.origin,
            center: base.target,
            axis: unit_or_zero(DVec3::from(base.up.map(f64::from))),
            degrees_per_frame,
        }
    }

    /// Move origin and target of `base` along its view direction by `distance_per_frame`
    /// each frame (positive: forwards). A base whose origin equals its target does not move.
    pub fn dolly(base: &Camera, distance_per_frame: f32) -> CameraPath {
        CameraPath::Dolly {
            origin: base.origin,
            target: base.target,
            direction: unit_or_zero(dvec(base.target) - dvec(base.origin)),
            distance_per_frame,
        }
    }

    /// Loads a keyframed path from a JSON file
    /// `{"keyframes": [{"frame": 0, "origin": [x, y, z], "target": [x, y, z]}, ...]}`.
    ///
    /// Errors name the file and the JSON field: malformed JSON or unknown fields, no
    /// keyframes, a non-finite frame or one not after the previous key's
    /// (`keyframes[2].frame`), a non-finite coordinate (`keyframes[1].origin[0]`), a target
    /// equal to its origin (`keyframes[0].target`).
    pub fn load(path: &Path) -> Result<CameraPath, SceneError> {
        let text =
            crate::scene::read_text_capped(path).map_err(|source| SceneError::Io { path: path.into(), source })?;
        let deserializer = &mut serde_json::Deserializer::from_str(&text);
        let file: CameraPathFile = serde_path_to_error::deserialize(deserializer).map_err(|error| {
            SceneError::Json { path: path.into(), field: error.path().to_string(), message: error.inner().to_string() }
        })?;
        validate_keyframes(path, &file.keyframes)?;
        Ok(CameraPath::Keyframes(file.keyframes))
    }

    /// The camera on `frame`: `base` with the path's origin and target for that frame.
    pub fn camera_at(&self, base: &Camera, frame: u32) -> Camera {
        let frame = f64::from(frame);
        let (origin, target) = match self {
            CameraPath::Static => return base.clone(),
            CameraPath::Keyframes(keys) => match keyframes_at(keys, frame) {
                Some(pair) => pair,
                None => return base.clone(),
            },
            CameraPath::Orbit { start, center, axis, degrees_per_frame } => {
                let angle = (f64::from(*degrees_per_frame) * frame).rem_euclid(360.0).to_radians();
                let center = dvec(*center);
                let origin = center + rotate(dvec(*start) - center, dvec(*axis), angle);
                (origin, center)
            }
            CameraPath::Dolly { origin, target, direction, distance_per_frame } => {
                let step = dvec(*direction) * (f64::from(*distance_per_frame) * frame);
                (dvec(*origin) + step, dvec(*target) + step)
            }
        };
        Camera { origin: origin.as_vec3().to_array(), target: target.as_vec3().to_array(), ..base.clone() }
    }

    /// The one camera of every frame, when every frame gets the same: the base camera for
    /// [`CameraPath::Static`] (and no keys), **that key's camera** for a single keyframe,
    /// the start for an orbit by a whole number of turns (or about no axis) and a dolly by
    /// 0 (or along no direction). `None` when the camera moves.
    ///
    /// This is the camera a still run renders from (one reference, frames that may be
    /// accumulated): a caller never takes "still" to mean "the base camera", which
    /// rendered a one-keyframe path from the scene's camera while the run's record named
    /// the path's file.
    pub fn still_camera(&self, base: &Camera) -> Option<Camera> {
        let still = match self {
            CameraPath::Static => true,
            CameraPath::Keyframes(keys) => keys.len() <= 1,
            CameraPath::Orbit { axis, degrees_per_frame, .. } => {
                degrees_per_frame.rem_euclid(360.0) == 0.0 || *axis == [0.0; 3]
            }
            CameraPath::Dolly { direction, distance_per_frame, .. } => {
                *distance_per_frame == 0.0 || *direction == [0.0; 3]
            }
        };
        still.then(|| self.camera_at(base, 0))
    }

    /// The camera of each of frames `0..frames`, every one checked
    /// ([`CameraFrame::checked`]): the first that cannot make rays (between keys that
    /// can, a spline may pass through a view along `up`, or bring origin and target
    /// together) is an error naming its frame, before anything is rendered.
    pub fn frame_cameras(&self, base: &Camera, frames: u32) -> Result<Vec<Camera>, String> {
        (0..frames)
            .map(|frame| {
                let camera = self.camera_at(base, frame);
                match CameraFrame::checked(&camera) {
                    Ok(_) => Ok(camera),
                    Err(why) => Err(format!(
                        "frame {frame} (counted from 0, as keyframes count): origin {:?}, target {:?}: {why}",
                        camera.origin, camera.target
                    )),
                }
            })
            .collect()
    }
}

/// Reads a camera path from its command-line spelling:
///
/// - `static`: the base camera on every frame;
/// - `orbit:DEG`: [`CameraPath::orbit`] by `DEG` degrees per frame (e.g. `orbit:0.5`);
/// - `dolly:D`: [`CameraPath::dolly`] by `D` scene units per frame (negative backs away);
/// - anything else: a keyframe JSON file for [`CameraPath::load`] (write `./static` for a
///   file named `static`).
///
/// A number that is not finite, an orbit about a zero `base.up` or a dolly of a base
/// whose origin equals its target is an error naming `spec` and the field. A keyframe
/// file is checked whole before anything renders: besides [`CameraPath::load`]'s rules,
/// each key's camera (`base` with the key's origin and target) must be able to make rays
/// ([`CameraFrame::checked`]: a key looking along `base.up` is an error naming
/// `keyframes[i].target`).
pub fn parse_camera_path(spec: impl AsRef<std::ffi::OsStr>, base: &Camera) -> Result<CameraPath, SceneError> {
    let spec = spec.as_ref();
    // A path that is not UTF-8 names a keyframe file; the keywords are ASCII.
    let Some(spec) = spec.to_str() else { return keyframe_file(Path::new(spec), base) };
    let error =
        |field: &str, message: String| SceneError::Json { path: PathBuf::from(spec), field: field.into(), message };
    let number = |field: &str, text: &str, unit: &str| -> Result<f32, SceneError> {
        match text.trim().parse::<f32>() {
            Ok(value) if value.is_finite() => Ok(value),
            _ => Err(error(field, format!("`{text}` is not a finite number of {unit} per frame"))),
        }
    };
    if spec == "static" {
        Ok(CameraPath::Static)
    } else if let Some(degrees) = spec.strip_prefix("orbit:") {
        let degrees = number("orbit", degrees, "degrees")?;
        let up = DVec3::from(base.up.map(f64::from));
        if !(up.is_finite() && up.length() > 0.0) {
            return Err(error("camera.up", format!("{:?}: an orbit needs a nonzero up vector as its axis", base.up)));
        }
        Ok(CameraPath::orbit(base, degrees))
    } else if let Some(distance) = spec.strip_prefix("dolly:") {
        let distance = number("dolly", distance, "scene units")?;
        if base.origin == base.target {
            return Err(error(
                "camera.target",
                format!("{:?} equals the origin: a dolly needs a view direction", base.target),
            ));
        }
        Ok(CameraPath::dolly(base, distance))
    } else {
        keyframe_file(Path::new(spec), base)
    }
}

/// [`CameraPath::load`], then every key's camera checked against `base` (what
/// [`parse_camera_path`] adds to the load).
fn keyframe_file(path: &Path, base: &Camera) -> Result<CameraPath, SceneError> {
    let loaded = CameraPath::load(path)?;
    if let CameraPath::Keyframes(keys) = &loaded {
        for (index, key) in keys.iter().enumerate() {
            let camera = Camera { origin: key.origin, target: key.target, ..base.clone() };
            if let Err(why) = CameraFrame::checked(&camera) {
                return Err(SceneError::Json {
                    path: path.into(),
                    field: format!("keyframes[{index}].target"),
                    message: format!(
                        "{:?} seen from origin {:?} with the scene camera's up {:?}: {why}",
                        key.target, key.origin, base.up
                    ),
                });
            }
        }
    }
    Ok(loaded)
}

/// Checks the rules of [`CameraPath::load`] on the keys read from `path`.
fn validate_keyframes(path: &Path, keys: &[CameraKeyframe]) -> Result<(), SceneError> {
    let error = |field: String, message: String| SceneError::Json { path: path.into(), field, message };
    if keys.is_empty() {
        return Err(error("keyframes".into(), "a camera path needs at least one keyframe".into()));
    }
    for (index, key) in keys.iter().enumerate() {
        if !key.frame.is_finite() {
            return Err(error(format!("keyframes[{index}].frame"), format!("{} is not finite", key.frame)));
        }
        if let Some(previous) = index.checked_sub(1).map(|i| keys[i].frame)
            && key.frame <= previous
        {
            return Err(error(
                format!("keyframes[{index}].frame"),
                format!(
                    "{} is not after the previous key's frame {previous}: frames must increase strictly",
                    key.frame
                ),
            ));
        }
        for (name, point) in [("origin", key.origin), ("target", key.target)] {
            if let Some(axis) = point.iter().position(|c| !c.is_finite()) {
                return Err(error(
                    format!("keyframes[{index}].{name}[{axis}]"),
                    format!("{} is not finite", point[axis]),
                ));
            }
        }
        if key.origin == key.target {
            return Err(error(
                format!("keyframes[{index}].target"),
                format!("{:?} equals the origin: the camera would look nowhere", key.target),
            ));
        }
    }
    Ok(())
}

/// Origin and target at `frame` along `keys` (`None` without keys).
fn keyframes_at(keys: &[CameraKeyframe], frame: f64) -> Option<(DVec3, DVec3)> {
    let first = keys.first()?;
    let last = keys.last()?;
    let whole = |key: &CameraKeyframe| (dvec(key.origin), dvec(key.target));
    if frame <= f64::from(first.frame) {
        return Some(whole(first));
    }
    if frame >= f64::from(last.frame) {
        return Some(whole(last));
    }
    // keys[i].frame <= frame < keys[i + 1].frame, with i + 1 < keys.len() as frame < last.frame.
    let i = keys.partition_point(|key| f64::from(key.frame) <= frame) - 1;
    let origin = hermite_segment(keys, i, frame, |key| key.origin);
    let target = hermite_segment(keys, i, frame, |key| key.target);
    Some((origin, target))
}

/// The value of the spline through `point(keys[..])` at `frame`, on the segment from key
/// `i` to key `i + 1`.
fn hermite_segment(
    keys: &[CameraKeyframe],
    i: usize,
    frame: f64,
    point: impl Fn(&CameraKeyframe) -> [f32; 3],
) -> DVec3 {
    let time = |k: usize| f64::from(keys[k].frame);
    let at = |k: usize| dvec(point(&keys[k]));
    // Tangent at key k in units per frame: central difference, one-sided at the ends.
    let tangent = |k: usize| {
        let before = k.saturating_sub(1);
        let after = (k + 1).min(keys.len() - 1);
        (at(after) - at(before)) / (time(after) - time(before))
    };
    let span = time(i + 1) - time(i);
    let t = (frame - time(i)) / span;
    let (t2, t3) = (t * t, t * t * t);
    let h00 = 2.0 * t3 - 3.0 * t2 + 1.0;
    let h10 = t3 - 2.0 * t2 + t;
    let h01 = -2.0 * t3 + 3.0 * t2;
    let h11 = t3 - t2;
    at(i) * h00 + tangent(i) * (h10 * span) + at(i + 1) * h01 + tangent(i + 1) * (h11 * span)
}

/// Rotates `v` by `angle` radians about the unit `axis` (Rodrigues' formula).
fn rotate(v: DVec3, axis: DVec3, angle: f64) -> DVec3 {
    let (sin, cos) = angle.sin_cos();
    v * cos + axis.cross(v) * sin + axis * (axis.dot(v) * (1.0 - cos))
}

fn dvec(p: [f32; 3]) -> DVec3 {
    DVec3::from(p.map(f64::from))
}

/// `v` normalised, or zero if it has no direction (zero or non-finite length).
fn unit_or_zero(v: DVec3) -> [f32; 3] {
    let length = v.length();
    if length.is_finite() && length > 0.0 { (v / length).as_vec3().to_array() } else { [0.0; 3] }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::default_scene;

    fn base() -> Camera {
        default_scene().camera
    }

    fn key(frame: f32, origin: [f32; 3], target: [f32; 3]) -> CameraKeyframe {
        CameraKeyframe { frame, origin, target }
    }

    fn keys() -> Vec<CameraKeyframe> {
        vec![
            key(0.0, [0.0, 1.0, -5.0], [0.0, 1.0, 0.0]),
            key(4.0, [3.0, 2.0, -4.0], [0.5, 1.0, 0.0]),
            key(6.0, [5.0, 1.5, 0.0], [1.0, 0.0, 0.5]),
            key(13.0, [2.0, 0.0, 4.0], [0.0, 0.0, 0.0]),
        ]
    }

    fn distance(a: [f32; 3], b: [f32; 3]) -> f32 {
        (glam::Vec3::from(a) - glam::Vec3::from(b)).length()
    }

    /// Writes `text` to `NAME.json` in a new folder of a random name; the caller removes
    /// the folder (the path's parent).
    fn temp_file(name: &str, text: &str) -> PathBuf {
        let folder = strata_files::private_scratch_folder("strata-camera-path-").unwrap().keep();
        let path = folder.join(format!("{name}.json"));
        std::fs::write(&path, text).unwrap();
        path
    }

    /// The field named by loading `text` as a camera path file, which must fail.
    fn load_error_field(name: &str, text: &str) -> (String, String) {
        let path = temp_file(name, text);
        let result = CameraPath::load(&path);
        std::fs::remove_dir_all(path.parent().unwrap()).unwrap();
        match result {
            Err(error @ SceneError::Json { .. }) => {
                let message = error.to_string();
                assert!(message.contains(&path.display().to_string()), "{message} does not name the file");
                let SceneError::Json { field, .. } = error else { unreachable!() };
                (field, message)
            }
            other => panic!("{name}: expected a JSON error, got {other:?}"),
        }
    }

    #[test]
    fn interpolation_passes_through_every_key_exactly() {
        let base = base();
        let path = CameraPath::Keyframes(keys());
        for key in keys() {
            let camera = path.camera_at(&base, key.frame as u32);
            assert_eq!((camera.origin, camera.target), (key.origin, key.target), "frame {}", key.frame);
            assert_eq!((camera.up, camera.fov_deg, camera.width), (base.up, base.fov_deg, base.width));
        }
        // Between keys the curve is smooth: consecutive frames stay close and differ from the keys.
        let middle = path.camera_at(&base, 2);
        assert_ne!(middle.origin, keys()[0].origin);
        assert_ne!(middle.origin, keys()[1].origin);
        for frame in 0..13 {
            let step = distance(path.camera_at(&base, frame).origin, path.camera_at(&base, frame + 1).origin);
            assert!(step < 3.0, "frame {frame}: jump of {step}");
        }
    }

    #[test]
    fn evenly_spaced_keys_follow_the_uniform_catmull_rom_spline() {
        let points = [[0.0f32, 0.0, 0.0], [4.0, 1.0, 0.0], [6.0, -2.0, 3.0], [9.0, 0.0, 1.0]];
        let keys: Vec<_> =
            points.iter().enumerate().map(|(i, p)| key(10.0 * i as f32, *p, [p[0], p[1], p[2] + 1.0])).collect();
        let path = CameraPath::Keyframes(keys);
        let [p0, p1, p2, p3] = points.map(glam::Vec3::from);
        for frame in 10..=20 {
            let t = (frame - 10) as f32 / 10.0;
            // The textbook uniform Catmull-Rom segment from p1 to p2.
            let expected = 0.5
                * (2.0 * p1
                    + (p2 - p0) * t
                    + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * t * t
                    + (3.0 * p1 - p0 - 3.0 * p2 + p3) * t * t * t);
            let camera = path.camera_at(&base(), frame);
            assert!((glam::Vec3::from(camera.origin) - expected).length() < 1e-4, "frame {frame}: {:?}", camera.origin);
            assert!((glam::Vec3::from(camera.target) - expected - glam::Vec3::Z).length() < 1e-4, "frame {frame}");
        }
    }

    #[test]
    fn two_keys_move_linearly_at_constant_speed() {
        let path = CameraPath::Keyframes(vec![
            key(10.0, [0.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
            key(20.0, [10.0, 0.0, 0.0], [10.0, 0.0, 1.0]),
        ]);
        for frame in 10..=20 {
            let camera = path.camera_at(&base(), frame);
            let x = (frame - 10) as f32;
            assert!(distance(camera.origin, [x, 0.0, 0.0]) < 1e-5, "frame {frame}: {:?}", camera.origin);
            assert!(distance(camera.target, [x, 0.0, 1.0]) < 1e-5, "frame {frame}: {:?}", camera.target);
        }
    }

    #[test]
    fn frames_outside_the_keys_clamp_to_the_first_and_last_key() {
        let base = base();
        let mut keys = keys();
        for k in &mut keys {
            k.frame += 5.0;
        }
        let path = CameraPath::Keyframes(keys.clone());
        for frame in [0, 3, 5] {
            let camera = path.camera_at(&base, frame);
            assert_eq!((camera.origin, camera.target), (keys[0].origin, keys[0].target), "frame {frame}");
        }
        for frame in [18, 19, 1000, u32::MAX] {
            let camera = path.camera_at(&base, frame);
            assert_eq!((camera.origin, camera.target), (keys[3].origin, keys[3].target), "frame {frame}");
        }
    }

    #[test]
    fn a_single_keyframe_and_static_are_still_each_with_its_own_camera() {
        let base = base();
        let single = CameraPath::Keyframes(vec![key(3.0, [1.0, 2.0, 3.0], [0.0, 0.0, 0.0])]);
        // A single key is still, from the key's camera, not the base's.
        let still = single.still_camera(&base).expect("one key does not move");
        assert_eq!((still.origin, still.target), ([1.0, 2.0, 3.0], [0.0, 0.0, 0.0]));
        assert_eq!((still.up, still.fov_deg, still.width), (base.up, base.fov_deg, base.width));
        assert_eq!(CameraPath::Static.still_camera(&base), Some(base.clone()));
        assert_eq!(CameraPath::Keyframes(Vec::new()).still_camera(&base), Some(base.clone()));
        assert_eq!(CameraPath::orbit(&base, 720.0).still_camera(&base), Some(base.clone()));
        assert_eq!(CameraPath::Keyframes(keys()).still_camera(&base), None);
        for frame in [0, 3, 7, 100] {
            let camera = single.camera_at(&base, frame);
            assert_eq!((camera.origin, camera.target), ([1.0, 2.0, 3.0], [0.0, 0.0, 0.0]));
            assert_eq!(CameraPath::Static.camera_at(&base, frame), base);
            assert_eq!(CameraPath::Keyframes(Vec::new()).camera_at(&base, frame), base);
        }
    }

    #[test]
    fn orbit_keeps_the_distance_to_the_target_and_turns_by_the_angle() {
        let base = base();
        let up = glam::Vec3::from(base.up).normalize();
        let flat = |camera: &Camera| {
            let v = glam::Vec3::from(camera.origin) - glam::Vec3::from(camera.target);
            v - up * v.dot(up)
        };
        let radius = distance(base.origin, base.target);
        let path = CameraPath::orbit(&base, 7.5);
        assert_eq!(path.still_camera(&base), None);
        let start = flat(&base);
        for frame in [0u32, 1, 4, 12, 30, 47] {
            let camera = path.camera_at(&base, frame);
            assert_eq!(camera.target, base.target);
            assert_eq!((camera.up, camera.fov_deg, camera.height), (base.up, base.fov_deg, base.height));
            let r = distance(camera.origin, camera.target);
            assert!((r - radius).abs() < 1e-4 * radius, "frame {frame}: distance {r} vs {radius}");
            // Height along the axis is unchanged, the turn is 7.5° per frame, counter-clockwise about up.
            let height = (glam::Vec3::from(camera.origin) - glam::Vec3::from(base.origin)).dot(up);
            assert!(height.abs() < 1e-4 * radius, "frame {frame}: moved {height} along up");
            let now = flat(&camera);
            let signed = start.cross(now).dot(up).atan2(start.dot(now)).to_degrees();
            let expected = (7.5 * frame as f32 + 180.0).rem_euclid(360.0) - 180.0;
            assert!((signed - expected).abs() < 1e-3, "frame {frame}: turned {signed}°, expected {expected}°");
        }
        // A full turn comes back to the start.
        let back = CameraPath::orbit(&base, 90.0).camera_at(&base, 4);
        assert!(distance(back.origin, base.origin) < 1e-3, "{:?} vs {:?}", back.origin, base.origin);
    }

    #[test]
    fn dolly_moves_origin_and_target_by_the_distance_along_the_view() {
        let base = base();
        let view = (glam::Vec3::from(base.target) - glam::Vec3::from(base.origin)).normalize();
        for step in [2.5f32, -4.0] {
            let path = CameraPath::dolly(&base, step);
            for frame in [0u32, 1, 10, 33] {
                let camera = path.camera_at(&base, frame);
                let moved = glam::Vec3::from(camera.origin) - glam::Vec3::from(base.origin);
                let moved_target = glam::Vec3::from(camera.target) - glam::Vec3::from(base.target);
                let expected = view * step * frame as f32;
                assert!((moved - expected).length() < 1e-3, "frame {frame}: moved {moved} vs {expected}");
                assert!((moved_target - expected).length() < 1e-3, "frame {frame}: target moved {moved_target}");
                assert_eq!(camera.fov_deg, base.fov_deg);
            }
        }
        assert_eq!(CameraPath::dolly(&base, 0.0).still_camera(&base), Some(base.clone()));
    }

    #[test]
    fn parse_reads_static_orbit_dolly_and_files() {
        let base = base();
        assert_eq!(parse_camera_path("static", &base).unwrap(), CameraPath::Static);
        assert_eq!(parse_camera_path("orbit:1.5", &base).unwrap(), CameraPath::orbit(&base, 1.5));
        assert_eq!(parse_camera_path("dolly:-3", &base).unwrap(), CameraPath::dolly(&base, -3.0));
        let path = temp_file(
            "good",
            r#"{"keyframes": [{"frame": 0, "origin": [0, 1, -5], "target": [0, 1, 0]},
                              {"frame": 2.5, "origin": [1, 1, -5], "target": [0, 1, 0]}]}"#,
        );
        let parsed = parse_camera_path(path.to_str().unwrap(), &base);
        std::fs::remove_dir_all(path.parent().unwrap()).unwrap();
        assert_eq!(
            parsed.unwrap(),
            CameraPath::Keyframes(vec![
                key(0.0, [0.0, 1.0, -5.0], [0.0, 1.0, 0.0]),
                key(2.5, [1.0, 1.0, -5.0], [0.0, 1.0, 0.0]),
            ])
        );
    }

    #[test]
    fn parse_errors_name_the_spec_and_the_field() {
        let base = base();
        let field = |spec: &str, base: &Camera| match parse_camera_path(spec, base) {
            Err(SceneError::Json { path, field, .. }) => {
                assert_eq!(path, PathBuf::from(spec));
                field
            }
            other => panic!("{spec}: expected an error, got {other:?}"),
        };
        assert_eq!(field("orbit:fast", &base), "orbit");
        assert_eq!(field("orbit:NaN", &base), "orbit");
        assert_eq!(field("dolly:inf", &base), "dolly");
        assert_eq!(field("dolly:", &base), "dolly");
        assert_eq!(field("orbit:1", &Camera { up: [0.0; 3], ..base.clone() }), "camera.up");
        assert_eq!(field("dolly:1", &Camera { target: base.origin, ..base.clone() }), "camera.target");
        let folder = strata_files::private_scratch_folder("strata-camera-path-").unwrap();
        let missing = folder.path().join("missing.json");
        assert!(matches!(parse_camera_path(missing.to_str().unwrap(), &base), Err(SceneError::Io { .. })));
    }

    #[test]
    fn json_errors_name_the_field() {
        let good = r#"{"frame": 0, "origin": [0, 0, -1], "target": [0, 0, 0]}"#;
        let cases = [
            ("empty", r#"{"keyframes": []}"#.to_string(), "keyframes"),
            ("not-increasing", format!(r#"{{"keyframes": [{good}, {good}]}}"#), "keyframes[1].frame"),
            (
                "decreasing",
                format!(
                    r#"{{"keyframes": [{good}, {{"frame": 2, "origin": [1, 0, 0], "target": [0, 0, 0]}},
                                       {{"frame": 1, "origin": [2, 0, 0], "target": [0, 0, 0]}}]}}"#
                ),
                "keyframes[2].frame",
            ),
            (
                "infinite-frame",
                format!(r#"{{"keyframes": [{good}, {{"frame": 1e39, "origin": [1, 0, 0], "target": [0, 0, 0]}}]}}"#),
                "keyframes[1].frame",
            ),
            (
                "infinite-origin",
                format!(r#"{{"keyframes": [{good}, {{"frame": 1, "origin": [1, -1e40, 0], "target": [0, 0, 0]}}]}}"#),
                "keyframes[1].origin[1]",
            ),
            (
                "infinite-target",
                r#"{"keyframes": [{"frame": 0, "origin": [0, 0, 1], "target": [0, 0, 1e39]}]}"#.to_string(),
                "keyframes[0].target[2]",
            ),
            (
                "origin-is-target",
                format!(r#"{{"keyframes": [{good}, {{"frame": 1, "origin": [1, 2, 3], "target": [1, 2, 3]}}]}}"#),
                "keyframes[1].target",
            ),
            (
                "unknown-field",
                format!(
                    r#"{{"keyframes": [{good}, {{"frame": 1, "origin": [1, 0, 0], "target": [0, 0, 0], "fov": 3}}]}}"#
                ),
                "keyframes[1].fov",
            ),
            (
                "short-origin",
                format!(r#"{{"keyframes": [{good}, {{"frame": 1, "origin": [1, 0], "target": [0, 0, 0]}}]}}"#),
                "keyframes[1].origin",
            ),
            ("frame-not-a-number", r#"{"keyframes": [{"frame": "zero"}]}"#.to_string(), "keyframes[0].frame"),
        ];
        for (name, text, expected) in cases {
            let (field, message) = load_error_field(name, &text);
            assert_eq!(field, expected, "{name}: {message}");
            assert!(message.contains(expected), "{name}: {message}");
        }
    }

    #[test]
    fn every_key_is_checked_against_the_base_camera_when_parsed() {
        let base = Camera { up: [0.0, 1.0, 0.0], ..base() };
        // Key 2 looks straight down the up axis: no right vector, so no rays.
        let text = r#"{"keyframes": [{"frame": 0, "origin": [0, 1, -5], "target": [0, 1, 0]},
                                     {"frame": 1, "origin": [1, 1, -5], "target": [0, 1, 0]},
                                     {"frame": 2, "origin": [0, 5, 0], "target": [0, 1, 0]}]}"#;
        let path = temp_file("along-up", text);
        let parsed = parse_camera_path(&path, &base);
        std::fs::remove_dir_all(path.parent().unwrap()).unwrap();
        match parsed {
            Err(error @ SceneError::Json { .. }) => {
                let message = error.to_string();
                assert!(message.contains("keyframes[2].target"), "{message}");
                assert!(message.contains("parallel to `up`"), "{message}");
                assert!(!message.contains("fov_axis"), "{message}");
            }
            other => panic!("expected an error naming keyframes[2].target, got {other:?}"),
        }
    }

    #[test]
    fn frame_cameras_name_the_first_frame_that_cannot_make_rays() {
        let base = Camera { up: [0.0, 1.0, 0.0], ..base() };
        // Valid keys whose spline brings origin onto target at frame 1.
        let path = CameraPath::Keyframes(vec![
            key(0.0, [0.0, 0.0, -1.0], [0.0, 0.0, 1.0]),
            key(2.0, [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]),
        ]);
        assert_eq!(path.frame_cameras(&base, 1).map(|c| c.len()), Ok(1));
        let error = path.frame_cameras(&base, 3).unwrap_err();
        assert!(error.starts_with("frame 1 "), "{error}");
        assert!(error.contains("target equals origin"), "{error}");
        let moving = CameraPath::orbit(&base, 10.0).frame_cameras(&base, 5).unwrap();
        assert_eq!(moving.len(), 5);
        assert_eq!(moving[3], CameraPath::orbit(&base, 10.0).camera_at(&base, 3));
    }
}
