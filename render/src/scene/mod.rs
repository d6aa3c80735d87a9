//! Scenes: the JSON + PLY description of the shared test scenes (`scenes/`,
//! every formula in their CONVENTIONS.md), loaded into triangles with object ids (the
//! paper's masking key, §4.3), materials, emitters, a camera and an environment. glTF 2.0
//! (`.gltf`, `.glb`) and Wavefront OBJ + MTL files load into the same [`Scene`]
//! ([`load_gltf`], [`load_obj`]; what they keep and how they map materials and cameras is
//! in their modules' documentation); [`load_scene_file`] picks the loader by extension.
//!
//! Bad input is an error naming the file and the field or element: a missing file,
//! malformed JSON or PLY, a NaN or infinite vertex, an index out of range, a mesh whose
//! triangles all have zero area, an unknown material type or a shape naming a material
//! that does not exist. Zero-area triangles inside an otherwise valid mesh are dropped
//! and counted (the reference scenes contain some: 62 in veach-ajar's door handle); they
//! cannot be hit and carry no light.
//!
//! Numbers are checked where they are read: a NaN, infinite or (where it means nothing)
//! negative camera field, reflectance, emitted radiance, material parameter, texture or
//! environment texel, or a transform that is singular or not finite, is an error naming
//! the field; nothing is clamped but a GGX alpha below [`MIN_ALPHA`], which every loader
//! renders at [`MIN_ALPHA`] ([`ggx_alpha`]; a JSON scene, whose format promises alpha as
//! written, says so in a warning). Text files may start with a UTF-8 byte order mark
//! ([`without_bom`]) and end lines in CRLF. Sizes are checked before allocating: a count
//! declared in a file (PLY elements, glTF accessors, EXR data windows) must fit in the
//! bytes that follow. Every loader reads through a [`FileSource`], so a scene can be loaded from
//! memory ([`load_scene_from`], [`MemoryFiles`]) as well as from disk.

mod camera_path;
mod camera_rays;
mod default_scene;
mod description;
mod description_check;
mod environment;
mod exr_decode;
mod files;
mod gltf_check;
mod gltf_scene;
mod material;
mod mesh_util;
mod obj_check;
mod obj_scene;
mod ply;
mod texture;
mod uri;

pub use camera_path::{CameraKeyframe, CameraPath, parse_camera_path};
pub use camera_rays::CameraFrame;
pub use default_scene::default_scene;
pub use description::{Camera, EmitterDescription, EnvironmentDescription, MaterialDescription, Reflectance};
pub use description_check::MAX_IMAGE_SIDE;
pub use environment::Environment;
pub use exr_decode::{
    MAX_BLOCK_BYTES, MAX_BLOCK_BYTES_PER_FILE_BYTE, MAX_EXR_TEXELS, MAX_TEXELS_PER_FILE_BYTE, RgbExr, decode_rgb_exr,
};
pub use files::{
    DiskFiles, FileSource, MAX_INPUT_FILE_BYTES, MemoryFiles, UTF8_BOM, read_capped, read_text_capped, without_bom,
};
pub use gltf_scene::{MAX_GLTF_ASPECT_RATIO, load_gltf, load_gltf_from};
pub use material::{Albedo, MIN_ALPHA, Material, ggx_alpha};
pub use obj_scene::{load_obj, load_obj_from};
pub use ply::{PlyMesh, parse_ply, read_ply};
pub use texture::{MAX_TEXTURE_BYTES, Texture, srgb_to_linear};

use std::path::{Path, PathBuf};
use thiserror::Error;

/// The largest radiance an emitter or an environment texel (times its scale) may have:
/// 10¹⁵, far above any physical light in the scenes' units (the sun's is about 10⁹ in
/// W sr⁻¹ m⁻²), and low enough that everything computed from it stays finite in single
/// precision (10³⁸): the sums of billions of samples, and an error map's squared error
/// over RelMSE's 10⁻⁴ floor, (100 × 10¹⁵)² / 10⁻⁴ = 10³⁸ for a firefly a hundred times
/// the light at a black reference pixel. At 10²⁰ (the limit until 2026-11-26) a compare
/// of such a light failed at its first error map.
pub const MAX_RADIANCE: f32 = 1e15;

/// A scene file or mesh that cannot be loaded.
#[derive(Debug, Error)]
pub enum SceneError {
    /// A file could not be read (the OS error is the source, so an error chain names it
    /// once).
    #[error("{path}: cannot read the file")]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// The JSON does not describe a scene; `field` is the JSON path of the problem.
    #[error("{}: field `{field}`: {}", .path.display(), one_line(.message))]
    Json {
        /// The file.
        path: PathBuf,
        /// JSON path, e.g. `materials.glass.type`.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// An image (texture or environment map) that cannot be used.
    #[error("{}: {}", .path.display(), one_line(.message))]
    Image {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A PLY file that cannot be read; `element` says where.
    #[error("{}: {element}: {}", .path.display(), one_line(.message))]
    Ply {
        /// The file.
        path: PathBuf,
        /// Header line, vertex or face at fault.
        element: String,
        /// What is wrong.
        message: String,
    },
}

/// `message` as one line: every run of whitespace that holds a line break becomes one
/// space, and trailing whitespace goes. A decoder's own text (the `image` crate's JPEG
/// errors end in a blank line) then never splits the one `error:` line a refusal is.
fn one_line(message: &str) -> String {
    let mut line = String::with_capacity(message.len());
    for (index, piece) in message.trim_end().split(['\n', '\r']).enumerate() {
        if index == 0 {
            line.push_str(piece);
        } else if !piece.trim().is_empty() {
            line.truncate(line.trim_end().len());
            line.push(' ');
            line.push_str(piece.trim_start());
        }
    }
    line
}

/// One shape of the scene: a mesh with its object id, material and emission.
#[derive(Clone, Debug, PartialEq)]
pub struct Shape {
    /// The shape's id in the scene file.
    pub name: String,
    /// Object id: the shape's index, the key of the histogram's clusters.
    pub object_id: u32,
    /// Index into [`Scene::materials`].
    pub material: usize,
    /// Radiance of a one-sided area emitter, if the shape emits.
    pub emission: Option<[f32; 3]>,
    /// Triangles in world space (counter-clockwise), zero-area ones dropped.
    pub triangles: Vec<[[f32; 3]; 3]>,
    /// Texture coordinates per triangle corner, if the mesh has them.
    pub uvs: Option<Vec<[[f32; 2]; 3]>>,
    /// Zero-area triangles dropped from the mesh.
    pub degenerate_dropped: usize,
}

/// A loaded scene.
#[derive(Clone, Debug)]
pub struct Scene {
    /// Scene name.
    pub name: String,
    /// The camera.
    pub camera: Camera,
    /// Maximum path segments including the camera ray (CONVENTIONS.md).
    pub max_depth: u32,
    /// Depth from which Russian roulette runs.
    pub rr_depth: u32,
    /// Materials, by index; `material_names[i]` is the name of `materials[i]`.
    pub materials: Vec<Material>,
    /// Material names in the scene file.
    pub material_names: Vec<String>,
    /// Shapes; shape `i` has object id `i`.
    pub shapes: Vec<Shape>,
    /// Textures that materials refer to, decoded to linear RGB.
    pub textures: Vec<Texture>,
    /// The environment map.
    pub environment: Option<Environment>,
    /// What the loader left out or replaced and said so (an OBJ face of two vertices, a
    /// material name no library defines, a missing material library, a JSON alpha below
    /// [`MIN_ALPHA`]): each names the file and line or field; the command line prints them once and the run record keeps them.
    pub warnings: Vec<String>,
}

impl Scene {
    /// Loads `scene.json` and the meshes it names (paths relative to its folder).
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        Scene::load_from(path, &DiskFiles)
    }

    /// Loads the scene description `path` and the files it names through `files`.
    pub fn load_from(path: &Path, files: &dyn FileSource) -> Result<Scene, SceneError> {
        let text = files::read_text(files, path)?;
        let description = description::parse(path, &text)?;
        description_check::check(path, &description)?;
        let folder = path.parent().unwrap_or(Path::new("."));
        let mut material_names: Vec<String> = description.materials.keys().cloned().collect();
        material_names.sort();
        let mut textures = Vec::new();
        let mut warnings = Vec::new();
        let materials = material_names
            .iter()
            .map(|name| {
                let description = &description.materials[name];
                resolve_material(path, folder, name, description, files, &mut textures, &mut warnings)
            })
            .collect::<Result<Vec<_>, _>>()?;
        let mut shapes = Vec::with_capacity(description.shapes.len());
        for (index, shape) in description.shapes.iter().enumerate() {
            let material =
                material_names.iter().position(|m| *m == shape.material).ok_or_else(|| SceneError::Json {
                    path: path.into(),
                    field: format!("shapes[{index}].material"),
                    message: format!(
                        "no material named `{}` (materials: {})",
                        shape.material,
                        material_names.join(", ")
                    ),
                })?;
            let mesh_path = folder.join(&shape.mesh);
            let mesh = parse_ply(&mesh_path, &files::read(files, &mesh_path)?)?;
            let (triangles, uvs, degenerate_dropped) = mesh.triangles_without_degenerate();
            if triangles.is_empty() {
                return Err(SceneError::Ply {
                    path: mesh_path,
                    element: "faces".into(),
                    message: "every triangle has zero area".into(),
                });
            }
            shapes.push(Shape {
                name: shape.id.clone(),
                object_id: index as u32,
                material,
                emission: shape.emitter.as_ref().map(|e| e.radiance),
                triangles,
                uvs,
                degenerate_dropped,
            });
        }
        let environment = match description.environment {
            Some(e) => {
                let file = folder.join(&e.file);
                Some(Environment::from_exr_bytes(&file, &files::read(files, &file)?, e.scale, e.to_world)?)
            }
            None => None,
        };
        Ok(Scene {
            name: description.name,
            camera: description.camera,
            max_depth: description.integrator.max_depth,
            rr_depth: description.integrator.rr_depth,
            materials,
            material_names,
            shapes,
            textures,
            environment,
            warnings,
        })
    }

    /// Length of the diagonal of the bounding box of every triangle (1 when empty).
    pub fn extent(&self) -> f32 {
        let mut low = [f32::INFINITY; 3];
        let mut high = [f32::NEG_INFINITY; 3];
        for v in self.shapes.iter().flat_map(|s| s.triangles.iter().flatten()) {
            for c in 0..3 {
                low[c] = low[c].min(v[c]);
                high[c] = high[c].max(v[c]);
            }
        }
        let diagonal = (0..3).map(|c| (high[c] - low[c]).powi(2)).sum::<f32>().sqrt();
        if diagonal.is_finite() && diagonal > 0.0 { diagonal } else { 1.0 }
    }

    /// Triangles of every shape, in shape order, with their object ids.
    pub fn triangles_with_ids(&self) -> (Vec<[[f32; 3]; 3]>, Vec<u32>) {
        let mut triangles = Vec::new();
        let mut ids = Vec::new();
        for shape in &self.shapes {
            triangles.extend_from_slice(&shape.triangles);
            ids.extend(std::iter::repeat_n(shape.object_id, shape.triangles.len()));
        }
        (triangles, ids)
    }
}

/// Loads a scene file by its extension: `.json` (the shared scenes' description), `.gltf`
/// or `.glb` (glTF 2.0), `.obj` (Wavefront OBJ with its MTL libraries).
pub fn load_scene_file(path: &Path) -> Result<Scene, SceneError> {
    load_scene_from(path, &DiskFiles)
}

/// [`load_scene_file`] reading the scene file and every file it names through `files`.
pub fn load_scene_from(path: &Path, files: &dyn FileSource) -> Result<Scene, SceneError> {
    match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
        Some("json") => Scene::load_from(path, files),
        Some("gltf" | "glb") => load_gltf_from(path, &files::read(files, path)?, files),
        Some("obj") => load_obj_from(path, &files::read(files, path)?, files),
        other => Err(SceneError::Json {
            path: path.into(),
            field: "(file)".into(),
            message: format!(
                "unknown scene format `{}`: expected a .json scene description, a .gltf or .glb (glTF 2.0) \
                 or an .obj (Wavefront OBJ + MTL) file",
                other.unwrap_or("(no extension)")
            ),
        }),
    }
}

/// The renderer's material for the description `name` of scene file `path`, loading its
/// texture (relative to `folder`) into `textures`; what it renders otherwise than the
/// file says (an alpha below [`MIN_ALPHA`]) goes to `warnings`, naming the field.
fn resolve_material(
    path: &Path,
    folder: &Path,
    name: &str,
    description: &MaterialDescription,
    files: &dyn FileSource,
    textures: &mut Vec<Texture>,
    warnings: &mut Vec<String>,
) -> Result<Material, SceneError> {
    let field = |field: &str, message: String| SceneError::Json {
        path: path.into(),
        field: format!("materials.{name}.{field}"),
        message,
    };
    let positive = |value: f32, what: &str| {
        if value.is_finite() && value > 0.0 { Ok(value) } else { Err(field(what, format!("{value} must be > 0"))) }
    };
    Ok(match description {
        MaterialDescription::Diffuse { reflectance, two_sided } => {
            let albedo = match reflectance {
                Reflectance::Constant(c) => Albedo::Constant(*c),
                Reflectance::Checkerboard { checkerboard } => Albedo::Checkerboard {
                    color0: checkerboard.color0,
                    color1: checkerboard.color1,
                    uv_scale: checkerboard.uv_scale,
                },
                Reflectance::Texture { texture, srgb, filter, wrap, uv_scale } => {
                    if let Some(filter) = filter.as_deref().filter(|f| *f != "bilinear") {
                        return Err(field("reflectance.filter", format!("`{filter}`: only `bilinear` is supported")));
                    }
                    if let Some(wrap) = wrap.as_deref().filter(|w| *w != "repeat") {
                        return Err(field("reflectance.wrap", format!("`{wrap}`: only `repeat` is supported")));
                    }
                    let file = folder.join(texture);
                    textures.push(Texture::decode(&file, &files::read(files, &file)?, *srgb)?);
                    Albedo::Texture { texture: textures.len() - 1, uv_scale: uv_scale.unwrap_or([1.0, 1.0]) }
                }
            };
            Material::Diffuse { albedo, two_sided: *two_sided }
        }
        MaterialDescription::Black { two_sided } => Material::black(*two_sided),
        MaterialDescription::Roughconductor { distribution, alpha, eta, k, two_sided } => {
            if distribution != "ggx" {
                return Err(field("distribution", format!("`{distribution}`: only `ggx` is supported")));
            }
            let alpha = positive(*alpha, "alpha")?;
            // The loaders' one rule (OBJ and glTF apply it too); the format promises
            // alpha as written, so the change is said.
            let rendered = ggx_alpha(alpha);
            if rendered != alpha {
                warnings.push(format!(
                    "{}: field `materials.{name}.alpha`: {alpha:e} is below {MIN_ALPHA}, the smoothest GGX the \
                     renderer samples; rendered at {MIN_ALPHA}",
                    path.display()
                ));
            }
            Material::RoughConductor { alpha: rendered, eta: *eta, k: *k, two_sided: *two_sided }
        }
        MaterialDescription::Dielectric { int_ior, ext_ior, .. } => {
            Material::Dielectric { int_ior: positive(*int_ior, "int_ior")?, ext_ior: positive(*ext_ior, "ext_ior")? }
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_print_on_one_line_whatever_a_decoder_says() {
        let error = SceneError::Image {
            path: "broken.jpg".into(),
            message: "Format error decoding Jpeg: I/O errors Not enough bytes\n\n".into(),
        };
        assert_eq!(error.to_string(), "broken.jpg: Format error decoding Jpeg: I/O errors Not enough bytes");
        assert_eq!(one_line("first line  \r\n   second\n\nthird "), "first line second third");
        assert_eq!(one_line("two  spaces kept"), "two  spaces kept");
    }

    /// A JSON scene of one conductor quad (alpha `alpha`) under an emitting quad.
    fn conductor_scene(alpha: &str) -> MemoryFiles {
        let mut ply = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
            property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
            .to_vec();
        for value in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
            ply.extend(value.to_le_bytes());
        }
        ply.push(3);
        for index in [0i32, 1, 2] {
            ply.extend(index.to_le_bytes());
        }
        let scene = format!(
            r#"{{"name": "t", "camera": {{"origin": [0, 0, 3], "target": [0, 0, 0], "up": [0, 1, 0], "fov_deg": 40,
            "fov_axis": "x", "width": 8, "height": 8, "near_clip": 0.1, "far_clip": 100}},
            "integrator": {{"type": "path", "max_depth": 8, "rr_depth": 5, "hide_emitters": false}},
            "materials": {{"metal": {{"type": "roughconductor", "distribution": "ggx", "alpha": {alpha},
            "eta": [0.2, 0.9, 1.1], "k": [3.9, 2.4, 2.2], "two_sided": true}}}},
            "shapes": [{{"id": "a", "mesh": "a.ply", "material": "metal", "emitter": {{"radiance": [1, 1, 1]}}}}]}}"#
        );
        let mut files = MemoryFiles::default();
        files.insert("scene.json", scene).insert("a.ply", ply);
        files
    }

    #[test]
    fn a_json_alpha_below_the_floor_renders_at_the_floor_with_a_warning() {
        let load = |alpha: &str| Scene::load_from(Path::new("scene.json"), &conductor_scene(alpha)).unwrap();
        let tiny = load("1e-30");
        let Material::RoughConductor { alpha, .. } = tiny.materials[0] else { panic!("{:?}", tiny.materials) };
        assert_eq!(alpha, MIN_ALPHA);
        assert_eq!(tiny.warnings.len(), 1, "{:?}", tiny.warnings);
        assert!(tiny.warnings[0].contains("materials.metal.alpha") && tiny.warnings[0].contains("1e-30"));
        let floor = load("0.001");
        assert!(floor.warnings.is_empty(), "{:?}", floor.warnings);
        assert_eq!(floor.materials, tiny.materials);
        let rough = load("0.3");
        assert!(matches!(rough.materials[0], Material::RoughConductor { alpha: 0.3, .. }));
        // Not finite and positive: refused by name, as before.
        let error = Scene::load_from(Path::new("scene.json"), &conductor_scene("0")).unwrap_err().to_string();
        assert!(error.contains("materials.metal.alpha"), "{error}");
    }
}
