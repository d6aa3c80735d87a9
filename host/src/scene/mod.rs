//! Scenes: the JSON + PLY description of the shared test scenes (`../shared/scenes`,
//! every formula in their CONVENTIONS.md), loaded into triangles with object ids (the
//! paper's masking key, §4.3), materials, emitters, a camera and an environment.
//!
//! Bad input is an error naming the file and the field or element: a missing file,
//! malformed JSON or PLY, a NaN or infinite vertex, an index out of range, a mesh whose
//! triangles all have zero area, an unknown material type or a shape naming a material
//! that does not exist. Zero-area triangles inside an otherwise valid mesh are dropped
//! and counted (the reference scenes contain some: 62 in veach-ajar's door handle); they
//! cannot be hit and carry no light.

mod camera_rays;
mod default_scene;
mod description;
mod ply;

pub use camera_rays::CameraFrame;
pub use default_scene::default_scene;
pub use description::{Camera, EmitterDescription, EnvironmentDescription, MaterialDescription, Reflectance};
pub use ply::{PlyMesh, read_ply};

use std::path::{Path, PathBuf};
use thiserror::Error;

/// A scene file or mesh that cannot be loaded.
#[derive(Debug, Error)]
pub enum SceneError {
    /// A file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// The JSON does not describe a scene; `field` is the JSON path of the problem.
    #[error("{path}: field `{field}`: {message}")]
    Json {
        /// The file.
        path: PathBuf,
        /// JSON path, e.g. `materials.glass.type`.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// A PLY file that cannot be read; `element` says where.
    #[error("{path}: {element}: {message}")]
    Ply {
        /// The file.
        path: PathBuf,
        /// Header line, vertex or face at fault.
        element: String,
        /// What is wrong.
        message: String,
    },
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
    pub materials: Vec<MaterialDescription>,
    /// Material names in the scene file.
    pub material_names: Vec<String>,
    /// Shapes; shape `i` has object id `i`.
    pub shapes: Vec<Shape>,
    /// The environment map, with its file resolved against the scene folder.
    pub environment: Option<EnvironmentDescription>,
}

impl Scene {
    /// Loads `scene.json` and the meshes it names (paths relative to its folder).
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        let text = std::fs::read_to_string(path).map_err(|source| SceneError::Io { path: path.into(), source })?;
        let description = description::parse(path, &text)?;
        let folder = path.parent().unwrap_or(Path::new("."));
        let mut material_names: Vec<String> = description.materials.keys().cloned().collect();
        material_names.sort();
        let materials = material_names.iter().map(|name| description.materials[name].clone()).collect();
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
            let mesh = read_ply(&mesh_path)?;
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
        let environment = description.environment.map(|mut environment| {
            environment.file = folder.join(&environment.file);
            environment
        });
        Ok(Scene {
            name: description.name,
            camera: description.camera,
            max_depth: description.integrator.max_depth,
            rr_depth: description.integrator.rr_depth,
            materials,
            material_names,
            shapes,
            environment,
        })
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
