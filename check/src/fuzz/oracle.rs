//! What a loaded scene must satisfy, whatever file it came from: the fuzz targets call
//! [`check_scene`] on every scene a loader accepts, and a violation is a finding like a
//! panic. A loader must refuse (or clamp, documented) a NaN, infinite or negative number
//! rather than hand it to the renderer, where it becomes a NaN image.

use strata_render::scene::{Albedo, CameraFrame, Material, Scene};

/// The first number of `scene` that the renderer cannot use, described.
pub fn check_scene(scene: &Scene) -> Result<(), String> {
    let finite = |what: &str, values: &[f32]| {
        if values.iter().all(|v| v.is_finite()) { Ok(()) } else { Err(format!("{what} {values:?} is not finite")) }
    };
    let non_negative = |what: &str, values: &[f32]| {
        if values.iter().all(|v| v.is_finite() && *v >= 0.0) {
            Ok(())
        } else {
            Err(format!("{what} {values:?} is not finite and ≥ 0"))
        }
    };
    let positive = |what: &str, values: &[f32]| {
        if values.iter().all(|v| v.is_finite() && *v > 0.0) {
            Ok(())
        } else {
            Err(format!("{what} {values:?} is not finite and > 0"))
        }
    };
    let camera = &scene.camera;
    finite("camera origin, target, up", &[camera.origin, camera.target, camera.up].concat())?;
    positive("camera fov, width, height", &[camera.fov_deg, camera.width as f32, camera.height as f32])?;
    if camera.fov_deg.is_nan() || camera.fov_deg >= 180.0 {
        return Err(format!("camera fov {} is not below 180°", camera.fov_deg));
    }
    non_negative("camera near clip", &[camera.near_clip])?;
    if !(camera.far_clip.is_finite() && camera.far_clip > camera.near_clip) {
        return Err(format!("camera far clip {} is not finite beyond the near clip", camera.far_clip));
    }
    let frame = CameraFrame::new(camera).ok_or("the camera has no frame (fov_axis, or up along the view)")?;
    finite("camera frame", &[frame.forward.to_array(), frame.right.to_array(), frame.up.to_array()].concat())?;
    finite("camera fov tangents", &[frame.tan_half_x, frame.tan_half_y])?;
    if scene.material_names.len() != scene.materials.len() {
        return Err("material names and materials differ in number".into());
    }
    for (index, material) in scene.materials.iter().enumerate() {
        let what = format!("material {index}");
        match material {
            Material::Diffuse { albedo, .. } => match albedo {
                Albedo::Constant(c) => non_negative(&what, c)?,
                Albedo::Checkerboard { color0, color1, uv_scale } => {
                    non_negative(&what, &[*color0, *color1].concat())?;
                    finite(&what, uv_scale)?;
                }
                Albedo::Texture { texture, uv_scale } => {
                    finite(&what, uv_scale)?;
                    if *texture >= scene.textures.len() {
                        return Err(format!("{what}: texture {texture} does not exist"));
                    }
                }
            },
            Material::RoughConductor { alpha, eta, k, .. } => {
                positive(&what, &[*alpha])?;
                positive(&what, eta)?;
                non_negative(&what, k)?;
            }
            Material::Dielectric { int_ior, ext_ior } => positive(&what, &[*int_ior, *ext_ior])?,
        }
    }
    for texture in &scene.textures {
        if texture.texels.len() != texture.width as usize * texture.height as usize || texture.texels.is_empty() {
            return Err(format!(
                "texture {}: {} texels for {}×{}",
                texture.name,
                texture.texels.len(),
                texture.width,
                texture.height
            ));
        }
        if let Some(texel) = texture.texels.iter().find(|t| t.iter().any(|c| !(c.is_finite() && *c >= 0.0))) {
            return Err(format!("texture {}: texel {texel:?}", texture.name));
        }
    }
    for shape in &scene.shapes {
        let what = format!("shape `{}`", shape.name);
        if shape.material >= scene.materials.len() {
            return Err(format!("{what}: material {} does not exist", shape.material));
        }
        if let Some(radiance) = shape.emission {
            non_negative(&format!("{what} emission"), &radiance)?;
        }
        if shape.triangles.is_empty() {
            return Err(format!("{what} has no triangles"));
        }
        if let Some(t) = shape.triangles.iter().find(|t| t.iter().flatten().any(|c| !c.is_finite())) {
            return Err(format!("{what}: triangle {t:?} is not finite"));
        }
        if let Some(uvs) = &shape.uvs {
            if uvs.len() != shape.triangles.len() {
                return Err(format!("{what}: {} uv triples for {} triangles", uvs.len(), shape.triangles.len()));
            }
            if let Some(uv) = uvs.iter().find(|t| t.iter().flatten().any(|c| !c.is_finite())) {
                return Err(format!("{what}: texture coordinates {uv:?} are not finite"));
            }
        }
    }
    if let Some(environment) = &scene.environment {
        non_negative("environment scale", &[environment.scale])?;
        finite("environment rotation", environment.to_world.as_flattened())?;
        if environment.texels.len() != environment.width as usize * environment.height as usize {
            return Err("environment texels do not match its size".into());
        }
        if let Some(texel) = environment.texels.iter().find(|t| t.iter().any(|c| !(c.is_finite() && *c >= 0.0))) {
            return Err(format!("environment texel {texel:?}"));
        }
    }
    Ok(())
}
