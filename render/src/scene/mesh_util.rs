//! What the mesh-file loaders (glTF, OBJ + MTL) share: checking a mesh and dropping its
//! zero-area triangles (the PLY loader's policy), a camera that frames the scene when the
//! file has none, the integrator defaults, metallic colours as complex IORs, tinted
//! textures, and a guard that turns a panic inside a third-party parser into an error.

use super::ply::{CornerUvs, TriangleCorners};
use super::{Camera, Material, PlyMesh, Scene, Shape, Texture};
use glam::Vec3;

/// Maximum path segments of a scene whose file names no integrator (as the built-in
/// default scene and the shared scenes).
pub(super) const DEFAULT_MAX_DEPTH: u32 = 8;
/// Russian-roulette start depth of a scene whose file names no integrator.
pub(super) const DEFAULT_RR_DEPTH: u32 = 5;
/// Reflectance of the grey diffuse material given to a mesh without a material.
pub(super) const DEFAULT_GREY: f32 = 0.8;
pub(super) use super::material::MIN_ALPHA;

/// The grey diffuse material of a mesh without one.
pub(super) fn default_material() -> Material {
    Material::diffuse([DEFAULT_GREY; 3])
}

/// Something wrong with one element of a mesh: each loader names the file and the mesh.
#[derive(Debug)]
pub(super) struct MeshProblem {
    /// The vertex, triangle or attribute at fault.
    pub element: String,
    /// What is wrong.
    pub message: String,
}

/// A mesh's triangles in world space, zero-area ones dropped.
#[derive(Debug)]
pub(super) struct MeshTriangles {
    /// Triangles (counter-clockwise).
    pub triangles: Vec<TriangleCorners>,
    /// Texture coordinates per corner, if the mesh has them.
    pub uvs: Option<Vec<CornerUvs>>,
    /// Zero-area triangles dropped.
    pub degenerate_dropped: usize,
}

/// Checks a mesh (finite vertices and texture coordinates, indices in range, as many
/// texture coordinates as vertices), moves its vertices to world space with `to_world`,
/// and drops its zero-area triangles (in world space) as the PLY loader does; a mesh whose
/// triangles all have zero area is an error.
pub(super) fn checked_triangles(
    positions: Vec<[f32; 3]>,
    to_world: impl Fn([f32; 3]) -> [f32; 3],
    uvs: Option<Vec<[f32; 2]>>,
    faces: Vec<[u32; 3]>,
) -> Result<MeshTriangles, MeshProblem> {
    let problem = |element: String, message: String| MeshProblem { element, message };
    let not_finite = |positions: &[[f32; 3]]| positions.iter().position(|p| p.iter().any(|c| !c.is_finite()));
    if let Some(index) = not_finite(&positions) {
        return Err(problem(format!("vertex {index}"), format!("coordinate is not finite: {:?}", positions[index])));
    }
    let positions: Vec<[f32; 3]> = positions.into_iter().map(to_world).collect();
    if let Some(index) = not_finite(&positions) {
        let message = format!("not finite in world space: {:?} (the transform overflows)", positions[index]);
        return Err(problem(format!("vertex {index}"), message));
    }
    if let Some(uvs) = &uvs {
        if uvs.len() != positions.len() {
            return Err(problem(
                "texture coordinates".into(),
                format!("{} texture coordinates for {} vertices", uvs.len(), positions.len()),
            ));
        }
        if let Some((index, uv)) = uvs.iter().enumerate().find(|(_, uv)| uv.iter().any(|c| !c.is_finite())) {
            return Err(problem(format!("vertex {index}"), format!("texture coordinate is not finite: {uv:?}")));
        }
    }
    if let Some((index, face)) =
        faces.iter().enumerate().find(|(_, f)| f.iter().any(|&i| i as usize >= positions.len()))
    {
        return Err(problem(
            format!("triangle {index}"),
            format!("vertex indices {face:?} out of range (the mesh has {} vertices)", positions.len()),
        ));
    }
    if faces.is_empty() {
        return Err(problem("triangles".into(), "the mesh has no triangles".into()));
    }
    let (triangles, uvs, degenerate_dropped) = PlyMesh { positions, uvs, faces }.triangles_without_degenerate();
    if triangles.is_empty() {
        return Err(problem("triangles".into(), "every triangle has zero area".into()));
    }
    Ok(MeshTriangles { triangles, uvs, degenerate_dropped })
}

/// The axis-aligned bounds (min, max) of every triangle of `shapes`.
pub(super) fn bounds(shapes: &[Shape]) -> (Vec3, Vec3) {
    let corners = shapes.iter().flat_map(|s| s.triangles.iter().flatten()).map(|&p| Vec3::from(p));
    corners.fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| (lo.min(p), hi.max(p)))
}

/// A far clip distance beyond every corner of the bounds as seen from `origin`.
pub(super) fn far_clip_beyond(origin: Vec3, (lo, hi): (Vec3, Vec3)) -> f32 {
    let farthest = (0..8)
        .map(|i| {
            Vec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            )
        })
        .map(|corner| corner.distance(origin))
        .fold(0.0f32, f32::max);
    2.0 * farthest.max(1e-3)
}

/// Opening angle (degrees, both axes of the square image) of the framing camera.
const FRAMING_FOV_DEG: f32 = 40.0;
/// Image side (pixels) of cameras made up for files that have none, or that give no size.
pub(super) const DEFAULT_IMAGE_SIDE: u32 = 512;

/// A camera for a file that has none: a square image, looking down −Z (up +Y) at the centre
/// of the bounds from far enough that their bounding sphere fills the view.
pub(super) fn framing_camera(shapes: &[Shape]) -> Camera {
    let (lo, hi) = bounds(shapes);
    let centre = (lo + hi) * 0.5;
    let radius = (hi - lo).length().max(1e-3) * 0.5;
    let distance = radius / (FRAMING_FOV_DEG.to_radians() * 0.5).sin();
    let origin = centre + Vec3::Z * distance;
    Camera {
        origin: origin.into(),
        target: centre.into(),
        up: [0.0, 1.0, 0.0],
        fov_deg: FRAMING_FOV_DEG,
        fov_axis: "smaller".into(),
        width: DEFAULT_IMAGE_SIDE,
        height: DEFAULT_IMAGE_SIDE,
        near_clip: distance * 1e-3,
        far_clip: far_clip_beyond(origin, (lo, hi)),
    }
}

/// A scene with the default integrator settings; the framing camera if `camera` is `None`.
/// An error if the camera is not finite: vertices so far apart that their extent overflows
/// f32 leave no camera that frames them (nor a far clip beyond them).
pub(super) fn assemble_scene(
    name: String,
    camera: Option<Camera>,
    (materials, material_names): (Vec<Material>, Vec<String>),
    shapes: Vec<Shape>,
    textures: Vec<Texture>,
) -> Result<Scene, String> {
    let camera = camera.unwrap_or_else(|| framing_camera(&shapes));
    let numbers = [camera.origin, camera.target, camera.up].concat();
    if super::CameraFrame::new(&camera).is_none_or(|f| !(f.forward.is_finite() && f.right.is_finite())) {
        return Err(format!(
            "the camera looks from {:?} along its up vector {:?} (or at a point it cannot tell from its own position)",
            camera.origin, camera.up
        ));
    }
    if numbers.iter().any(|c| !c.is_finite())
        || !(camera.near_clip.is_finite() && camera.far_clip.is_finite() && camera.far_clip > camera.near_clip)
    {
        let (lo, hi) = bounds(&shapes);
        return Err(format!(
            "the scene's extent from {lo} to {hi} overflows f32: no camera frames it (origin {:?}, far clip {})",
            camera.origin, camera.far_clip
        ));
    }
    Ok(Scene {
        name,
        camera,
        max_depth: DEFAULT_MAX_DEPTH,
        rr_depth: DEFAULT_RR_DEPTH,
        materials,
        material_names,
        shapes,
        textures,
        environment: None,
        warnings: Vec::new(),
    })
}

/// A GGX conductor whose normal-incidence reflectance is `colour`, with the same colour as
/// edge tint: the complex IOR of Gulbrandsen, "Artist Friendly Metallic Fresnel" (JCGT
/// 2014), per channel; `alpha` goes through the loaders' one rule,
/// [`super::material::ggx_alpha`].
pub(super) fn metal(colour: [f32; 3], alpha: f32, two_sided: bool) -> Material {
    let mut eta = [0.0; 3];
    let mut k = [0.0; 3];
    for channel in 0..3 {
        let r = colour[channel].clamp(0.0, 0.99);
        let g = colour[channel].clamp(0.0, 1.0);
        let n_min = (1.0 - r) / (1.0 + r);
        let n_max = (1.0 + r.sqrt()) / (1.0 - r.sqrt());
        let n = g * n_min + (1.0 - g) * n_max;
        let k2 = ((n + 1.0) * (n + 1.0) * r - (n - 1.0) * (n - 1.0)) / (1.0 - r);
        eta[channel] = n;
        k[channel] = k2.max(0.0).sqrt();
    }
    Material::RoughConductor { alpha: super::material::ggx_alpha(alpha), eta, k, two_sided }
}

/// `texture` with every texel multiplied by `factor` (a material's constant colour times
/// its colour texture, baked).
pub(super) fn tinted(mut texture: Texture, factor: [f32; 3]) -> Texture {
    if factor != [1.0; 3] {
        for texel in &mut texture.texels {
            for (c, f) in texel.iter_mut().zip(factor) {
                *c *= f;
            }
        }
    }
    texture
}

/// `Some(radiance)` if any channel is positive; an error message if one is negative or not
/// finite.
pub(super) fn emission(radiance: [f32; 3]) -> Result<Option<[f32; 3]>, String> {
    if radiance.iter().any(|c| !c.is_finite() || *c < 0.0 || *c > super::MAX_RADIANCE) {
        return Err(format!("emitted radiance {radiance:?} must lie in [0, {:e}]", super::MAX_RADIANCE));
    }
    Ok(radiance.iter().any(|&c| c > 0.0).then_some(radiance))
}

/// Runs a third-party parser on untrusted input; a panic inside it becomes `Err` with the
/// panic's message (a backstop: the loaders check what they can before calling it).
pub(super) fn without_panic<T>(parse: impl FnOnce() -> T) -> Result<T, String> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(parse)).map_err(|payload| {
        let message = payload
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown panic".into());
        format!("the parser failed on this file: {message}")
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Normal-incidence reflectance of the complex IOR n + ik against vacuum.
    fn f0(n: f32, k: f32) -> f32 {
        ((n - 1.0) * (n - 1.0) + k * k) / ((n + 1.0) * (n + 1.0) + k * k)
    }

    #[test]
    fn metal_reflects_its_colour_at_normal_incidence() {
        let colour = [0.95, 0.64, 0.54];
        let Material::RoughConductor { eta, k, alpha, .. } = metal(colour, 0.0, true) else { panic!() };
        assert_eq!(alpha, MIN_ALPHA);
        for c in 0..3 {
            assert!((f0(eta[c], k[c]) - colour[c]).abs() < 1e-4, "{c}: {} vs {}", f0(eta[c], k[c]), colour[c]);
        }
    }

    #[test]
    fn all_degenerate_meshes_are_refused_and_others_counted() {
        let p = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let mesh = checked_triangles(p.clone(), |p| p, None, vec![[0, 1, 2], [0, 1, 3]]).unwrap();
        assert_eq!((mesh.triangles.len(), mesh.degenerate_dropped), (1, 1));
        let flat = checked_triangles(p.clone(), |p| p, None, vec![[0, 1, 2]]).unwrap_err();
        assert_eq!(flat.message, "every triangle has zero area");
        let range = checked_triangles(p, |p| p, None, vec![[0, 1, 9]]).unwrap_err();
        assert_eq!(range.element, "triangle 0");
    }

    #[test]
    fn a_panic_becomes_an_error() {
        let error = without_panic(|| -> u32 { panic!("boom") }).unwrap_err();
        assert!(error.contains("boom"), "{error}");
    }
}
