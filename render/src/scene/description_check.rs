//! The numbers of a parsed scene description, checked before anything is loaded: JSON
//! numbers beyond f32 (`1e39`) parse as infinity, so a file can hand the renderer an
//! infinite radiance or a NaN direction without ever writing `NaN`. Each problem is an
//! error naming the JSON field; nothing is clamped.

use super::SceneError;
use super::description::{MaterialDescription, Reflectance, SceneDescription};
use std::path::Path;

/// The largest image side a scene may ask for (the renderer allocates width × height
/// pixels per buffer).
pub const MAX_IMAGE_SIDE: u32 = 16384;

/// What a group of numbers must be.
#[derive(Clone, Copy)]
enum Rule {
    /// Finite.
    Finite,
    /// Finite and ≥ 0.
    NonNegative,
    /// Finite and > 0.
    Positive,
    /// An emitted radiance: in [0, [`super::MAX_RADIANCE`]].
    Radiance,
    /// A reflectance: in [0, 1] (above 1 a surface would reflect more light than
    /// arrives, creating energy).
    Reflectance,
}

impl Rule {
    fn holds(self, value: f32) -> bool {
        match self {
            Rule::Finite => value.is_finite(),
            Rule::NonNegative => value.is_finite() && value >= 0.0,
            Rule::Positive => value.is_finite() && value > 0.0,
            Rule::Radiance => (0.0..=super::MAX_RADIANCE).contains(&value),
            Rule::Reflectance => (0.0..=1.0).contains(&value),
        }
    }

    fn describe(self) -> &'static str {
        match self {
            Rule::Finite => "must be finite",
            Rule::NonNegative => "must be finite and ≥ 0",
            Rule::Positive => "must be finite and > 0",
            Rule::Radiance => {
                "each must lie in [0, 1e15] (the squared errors of brighter light overflow single precision)"
            }
            Rule::Reflectance => "each must lie in [0, 1] (a reflectance above 1 creates energy)",
        }
    }
}

/// Checks every number of `description` (read from `path`): camera, materials, emitters,
/// environment.
pub(super) fn check(path: &Path, description: &SceneDescription) -> Result<(), SceneError> {
    let error = |field: String, message: String| SceneError::Json { path: path.into(), field, message };
    let numbers = |field: String, values: &[f32], rule: Rule| -> Result<(), SceneError> {
        match values.iter().find(|v| !rule.holds(**v)) {
            Some(_) => Err(error(field, format!("{values:?}: {}", rule.describe()))),
            None => Ok(()),
        }
    };
    // Fields the format has but the renderer implements for one value only: any other
    // value is refused, never rendered as if the field were absent.
    let integrator = &description.integrator;
    if integrator.kind != "path" {
        return Err(error("integrator.type".into(), format!("`{}`: only `path` is implemented", integrator.kind)));
    }
    if integrator.hide_emitters {
        return Err(error(
            "integrator.hide_emitters".into(),
            "true: emitters seen directly by the camera cannot be hidden; only false is implemented".into(),
        ));
    }
    for (index, shape) in description.shapes.iter().enumerate() {
        // Ids name shapes in messages, warnings and object ids: two shapes of one id
        // could not be told apart.
        if let Some(first) = description.shapes[..index].iter().position(|earlier| earlier.id == shape.id) {
            return Err(error(
                format!("shapes[{index}].id"),
                format!("`{}`: shapes[{first}] has this id already; each shape's id must be its own", shape.id),
            ));
        }
        if let Some(normals) = shape.normals.as_deref().filter(|n| *n != "face") {
            return Err(error(
                format!("shapes[{index}].normals"),
                format!("`{normals}`: only `face` (geometric normals) is implemented"),
            ));
        }
    }
    let camera = &description.camera;
    numbers("camera.origin".into(), &camera.origin, Rule::Finite)?;
    numbers("camera.target".into(), &camera.target, Rule::Finite)?;
    numbers("camera.up".into(), &camera.up, Rule::Finite)?;
    if !(camera.fov_deg > 0.0 && camera.fov_deg < 180.0) {
        return Err(error("camera.fov_deg".into(), format!("{} must lie in (0, 180)", camera.fov_deg)));
    }
    if camera.fov_axis != "x" && camera.fov_axis != "smaller" {
        return Err(error("camera.fov_axis".into(), format!("`{}`: expected `x` or `smaller`", camera.fov_axis)));
    }
    if camera.width == 0 || camera.height == 0 || camera.width > MAX_IMAGE_SIDE || camera.height > MAX_IMAGE_SIDE {
        return Err(error(
            "camera.width".into(),
            format!("{}×{} pixels: each side must lie in 1..={MAX_IMAGE_SIDE}", camera.width, camera.height),
        ));
    }
    if let Err(why) = super::CameraFrame::checked(camera) {
        return Err(error("camera.target".into(), why));
    }
    numbers("camera.near_clip".into(), &[camera.near_clip], Rule::NonNegative)?;
    if !(camera.far_clip.is_finite() && camera.far_clip > camera.near_clip) {
        return Err(error(
            "camera.far_clip".into(),
            format!("{} must be finite and beyond near_clip {}", camera.far_clip, camera.near_clip),
        ));
    }
    for (name, material) in &description.materials {
        let field = |what: &str| format!("materials.{name}.{what}");
        match material {
            MaterialDescription::Diffuse { reflectance, .. } => match reflectance {
                Reflectance::Constant(c) => numbers(field("reflectance"), c, Rule::Reflectance)?,
                Reflectance::Checkerboard { checkerboard } => {
                    numbers(field("reflectance.checkerboard.color0"), &checkerboard.color0, Rule::Reflectance)?;
                    numbers(field("reflectance.checkerboard.color1"), &checkerboard.color1, Rule::Reflectance)?;
                    numbers(field("reflectance.checkerboard.uv_scale"), &checkerboard.uv_scale, Rule::Finite)?;
                }
                Reflectance::Texture { uv_scale, .. } => {
                    numbers(field("reflectance.uv_scale"), uv_scale.as_ref().map_or(&[], |s| &s[..]), Rule::Finite)?
                }
            },
            MaterialDescription::Black { .. } => {}
            MaterialDescription::Roughconductor { eta, k, .. } => {
                numbers(field("eta"), eta, Rule::Positive)?;
                numbers(field("k"), k, Rule::NonNegative)?;
            }
            // alpha and the IORs are checked as the material is resolved.
            MaterialDescription::Dielectric { .. } => {}
        }
    }
    for (index, shape) in description.shapes.iter().enumerate() {
        if let Some(emitter) = &shape.emitter {
            numbers(format!("shapes[{index}].emitter.radiance"), &emitter.radiance, Rule::Radiance)?;
        }
    }
    if let Some(environment) = &description.environment {
        numbers("environment.scale".into(), &[environment.scale], Rule::NonNegative)?;
        if let Some(matrix) = &environment.to_world {
            numbers("environment.to_world".into(), matrix.as_flattened(), Rule::Finite)?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::super::description::parse;
    use super::*;

    fn scene(camera: &str, material: &str, shape: &str, environment: &str) -> String {
        format!(
            r#"{{"name": "t", "camera": {{{camera}}}, "integrator": {{"type": "path", "max_depth": 8, "rr_depth": 5,
            "hide_emitters": false}}, "materials": {{"m": {material}}}, "shapes": [{shape}], "environment": {environment}}}"#
        )
    }

    const CAMERA: &str = r#""origin": [0, 0, 3], "target": [0, 0, 0], "up": [0, 1, 0], "fov_deg": 40, "fov_axis": "x",
        "width": 8, "height": 8, "near_clip": 0.01, "far_clip": 100"#;
    const MATERIAL: &str = r#"{"type": "diffuse", "reflectance": [0.5, 0.5, 0.5]}"#;
    const SHAPE: &str = r#"{"id": "a", "mesh": "a.ply", "material": "m"}"#;

    /// The error `check` gives the scene, or "ok".
    fn verdict(text: &str) -> String {
        let path = Path::new("s.json");
        check(path, &parse(path, text).unwrap()).map_or_else(|e| e.to_string(), |()| "ok".into())
    }

    #[test]
    fn numbers_beyond_f32_nan_and_negative_values_name_their_field() {
        assert_eq!(verdict(&scene(CAMERA, MATERIAL, SHAPE, "null")), "ok");
        let cases = [
            (
                scene(
                    CAMERA,
                    MATERIAL,
                    r#"{"id": "a", "mesh": "a.ply", "material": "m", "emitter": {"radiance": [1e39, 1, 1]}}"#,
                    "null",
                ),
                "shapes[0].emitter.radiance",
            ),
            (
                scene(CAMERA, r#"{"type": "diffuse", "reflectance": [-1, 0, 0]}"#, SHAPE, "null"),
                "materials.m.reflectance",
            ),
            (
                scene(
                    CAMERA,
                    r#"{"type": "roughconductor", "distribution": "ggx", "alpha": 0.1, "eta": [1e39, 1, 1], "k": [0, 0, 0]}"#,
                    SHAPE,
                    "null",
                ),
                "materials.m.eta",
            ),
            (
                scene(&CAMERA.replace(r#""fov_deg": 40"#, r#""fov_deg": 1e39"#), MATERIAL, SHAPE, "null"),
                "camera.fov_deg",
            ),
            (
                scene(&CAMERA.replace(r#""origin": [0, 0, 3]"#, r#""origin": [0, 1e39, 3]"#), MATERIAL, SHAPE, "null"),
                "camera.origin",
            ),
            (
                scene(&CAMERA.replace(r#""up": [0, 1, 0]"#, r#""up": [0, 0, 1]"#), MATERIAL, SHAPE, "null"),
                "camera.target",
            ),
            (scene(&CAMERA.replace(r#""width": 8"#, r#""width": 0"#), MATERIAL, SHAPE, "null"), "camera.width"),
            (
                scene(&CAMERA.replace(r#""far_clip": 100"#, r#""far_clip": 0.001"#), MATERIAL, SHAPE, "null"),
                "camera.far_clip",
            ),
            (scene(CAMERA, MATERIAL, SHAPE, r#"{"file": "e.exr", "scale": -1}"#), "environment.scale"),
            (
                scene(
                    CAMERA,
                    MATERIAL,
                    SHAPE,
                    r#"{"file": "e.exr", "scale": 1, "to_world": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 1e39], [0, 0, 0, 1]]}"#,
                ),
                "environment.to_world",
            ),
            (scene(CAMERA, MATERIAL, &format!("{SHAPE}, {SHAPE}"), "null"), "shapes[1].id"),
        ];
        for (text, field) in cases {
            let message = verdict(&text);
            assert!(message.contains(&format!("s.json: field `{field}`")), "{field}: {message}");
        }
    }
}
