//! `scene-json`: the shared scenes' JSON description through `load_scene_from`, with its
//! meshes, texture and environment map held in memory (any `.ply`, `.png` or `.exr` path
//! resolves to a small valid file, so that mutated descriptions still reach the mesh,
//! texture and environment code).

use super::super::mutate::{FuzzRng, mutate_lines};
use super::super::{Outcome, Target, build, json, oracle};
use super::number;
use arbitrary::Unstructured;
use rand::Rng;
use std::path::Path;
use strata_render::scene::{FileSource, MemoryFiles, load_scene_from};

/// Where the input lies in the in-memory file system.
const SCENE: &str = "scene/fuzz.json";

/// Keys whose values the JSON mutations prefer.
const FOCUS: &[&str] = &[
    "radiance",
    "scale",
    "to_world",
    "fov_deg",
    "fov_axis",
    "width",
    "height",
    "near_clip",
    "far_clip",
    "origin",
    "target",
    "up",
    "alpha",
    "eta",
    "k",
    "int_ior",
    "ext_ior",
    "reflectance",
    "uv_scale",
    "color0",
    "color1",
    "mesh",
    "file",
    "texture",
    "max_depth",
    "rr_depth",
    "material",
    "emitter",
];

/// The target, with its in-memory files.
pub(super) struct SceneJson {
    files: MemoryFiles,
}

impl SceneJson {
    pub(super) fn new() -> SceneJson {
        let mut files = MemoryFiles::default();
        files.insert("scene/meshes/cube.ply", build::cube_ply());
        files.by_extension.insert("ply".into(), build::quad_ply());
        files.by_extension.insert("png".into(), build::texture_png());
        files.by_extension.insert("exr".into(), build::environment_exr(exr::prelude::Compression::ZIP16));
        SceneJson { files }
    }
}

/// The files plus the input as the scene description.
struct WithScene<'a> {
    scene: &'a [u8],
    files: &'a MemoryFiles,
}

impl FileSource for WithScene<'_> {
    fn read(&self, path: &Path) -> std::io::Result<Vec<u8>> {
        if path == Path::new(SCENE) { Ok(self.scene.to_vec()) } else { self.files.read(path) }
    }
}

/// A scene description with `materials`, `shapes` and `environment` (JSON texts).
fn scene(materials: &str, shapes: &str, environment: &str) -> Vec<u8> {
    format!(
        r#"{{"name": "fuzz", "coordinate_system": "right-handed, +Y up",
 "camera": {{"origin": [0.5, 0.5, 3], "target": [0.5, 0.5, 0], "up": [0, 1, 0], "fov_deg": 40, "fov_axis": "smaller",
   "width": 16, "height": 8, "near_clip": 0.01, "far_clip": 100}},
 "integrator": {{"type": "path", "max_depth": 8, "rr_depth": 5, "hide_emitters": false}},
 "materials": {materials},
 "shapes": {shapes},
 "environment": {environment}}}"#
    )
    .into_bytes()
}

impl Target for SceneJson {
    fn name(&self) -> &'static str {
        "scene-json"
    }

    fn seeds(&self, shared: Option<&Path>) -> Vec<Vec<u8>> {
        let mut seeds = vec![
            scene(
                r#"{"white": {"type": "diffuse", "reflectance": [0.8, 0.7, 0.6], "two_sided": true},
                    "light": {"type": "black"}}"#,
                r#"[{"id": "box", "mesh": "meshes/cube.ply", "material": "white"},
                    {"id": "lamp", "mesh": "meshes/quad.ply", "material": "light", "normals": "face",
                     "emitter": {"radiance": [10, 9, 8]}}]"#,
                "null",
            ),
            scene(
                r#"{"checker": {"type": "diffuse", "reflectance": {"checkerboard": {"color0": [0.1, 0.1, 0.1],
                       "color1": [0.9, 0.9, 0.9], "uv_scale": [4, 4]}}},
                    "wood": {"type": "diffuse", "reflectance": {"texture": "textures/wood.png", "srgb": true,
                       "filter": "bilinear", "wrap": "repeat", "uv_scale": [2, 1]}},
                    "metal": {"type": "roughconductor", "distribution": "ggx", "alpha": 0.2,
                       "eta": [0.2, 0.9, 1.1], "k": [3.9, 2.4, 2.2], "two_sided": true},
                    "glass": {"type": "dielectric", "int_ior": 1.5, "ext_ior": 1.0}}"#,
                r#"[{"id": "floor", "mesh": "meshes/floor.ply", "material": "checker"},
                    {"id": "table", "mesh": "meshes/table.ply", "material": "wood"},
                    {"id": "ball", "mesh": "meshes/cube.ply", "material": "metal"},
                    {"id": "vase", "mesh": "meshes/vase.ply", "material": "glass"}]"#,
                r#"{"file": "textures/envmap.exr", "scale": 1.5,
                    "to_world": [[0, 0, 1, 0], [0, 1, 0, 0], [-1, 0, 0, 0], [0, 0, 0, 1]]}"#,
            ),
            scene(
                r#"{"white": {"type": "diffuse", "reflectance": [0.5, 0.5, 0.5]}}"#,
                r#"[{"id": "a", "mesh": "a.ply", "material": "white"}]"#,
                r#"{"file": "sky.exr", "scale": 1}"#,
            ),
        ];
        if let Some(shared) = shared {
            for name in ["cornell-box", "matpreview", "veach-ajar", "objects-grid"] {
                seeds.extend(build::files_in(&shared.join(name), "json", 64 << 10));
            }
        }
        seeds
    }

    fn generate(&self, u: &mut Unstructured) -> arbitrary::Result<Vec<u8>> {
        let triple = |u: &mut Unstructured| -> arbitrary::Result<String> {
            Ok(format!("[{}, {}, {}]", number(u)?, number(u)?, number(u)?))
        };
        let mut materials = Vec::new();
        for index in 0..u.int_in_range(0..=4)? {
            let body = match u.int_in_range(0..=5)? {
                0 => format!(r#"{{"type": "diffuse", "reflectance": {}}}"#, triple(u)?),
                1 => format!(
                    r#"{{"type": "diffuse", "reflectance": {{"checkerboard": {{"color0": {}, "color1": {}, "uv_scale": [{}, {}]}}}}}}"#,
                    triple(u)?,
                    triple(u)?,
                    number(u)?,
                    number(u)?
                ),
                2 => format!(
                    r#"{{"type": "diffuse", "reflectance": {{"texture": "t{index}.png", "srgb": {}, "uv_scale": [{}, {}]}}}}"#,
                    u.arbitrary::<bool>()?,
                    number(u)?,
                    number(u)?
                ),
                3 => format!(
                    r#"{{"type": "roughconductor", "distribution": "ggx", "alpha": {}, "eta": {}, "k": {}}}"#,
                    number(u)?,
                    triple(u)?,
                    triple(u)?
                ),
                4 => format!(r#"{{"type": "dielectric", "int_ior": {}, "ext_ior": {}}}"#, number(u)?, number(u)?),
                _ => r#"{"type": "black", "two_sided": true}"#.into(),
            };
            materials.push(format!(r#""m{index}": {body}"#));
        }
        let mut shapes = Vec::new();
        for index in 0..u.int_in_range(0..=4)? {
            let emitter =
                if u.arbitrary()? { format!(r#", "emitter": {{"radiance": {}}}"#, triple(u)?) } else { String::new() };
            let mesh = *u.choose(&["meshes/cube.ply", "quad.ply", "missing.obj", "../x.ply"])?;
            let material = u.int_in_range(0..=4)?;
            shapes.push(format!(r#"{{"id": "s{index}", "mesh": "{mesh}", "material": "m{material}"{emitter}}}"#));
        }
        let environment = match u.int_in_range(0..=2)? {
            0 => "null".to_string(),
            1 => format!(r#"{{"file": "sky.exr", "scale": {}}}"#, number(u)?),
            _ => {
                let rows: Vec<String> = (0..4)
                    .map(|_| Ok(format!("[{}, {}, {}, {}]", number(u)?, number(u)?, number(u)?, number(u)?)))
                    .collect::<arbitrary::Result<_>>()?;
                format!(r#"{{"file": "sky.exr", "scale": 1, "to_world": [{}]}}"#, rows.join(", "))
            }
        };
        let mut text =
            scene(&format!("{{{}}}", materials.join(", ")), &format!("[{}]", shapes.join(", ")), &environment);
        // The camera's numbers too, sometimes.
        if u.arbitrary()? {
            let camera = format!(
                r#""camera": {{"origin": {}, "target": {}, "up": {}, "fov_deg": {}, "fov_axis": "{}", "width": {}, "height": {}, "near_clip": {}, "far_clip": {}}}"#,
                triple(u)?,
                triple(u)?,
                triple(u)?,
                number(u)?,
                u.choose(&["x", "smaller", "y"])?,
                super::count(u)?,
                super::count(u)?,
                number(u)?,
                number(u)?
            );
            let as_text = String::from_utf8_lossy(&text).into_owned();
            let start = as_text.find(r#""camera""#).unwrap_or(0);
            let end = as_text[start..].find('}').map_or(start, |e| start + e + 1);
            text = format!("{}{camera}{}", &as_text[..start], &as_text[end..]).into_bytes();
        }
        Ok(text)
    }

    fn mutate(&self, rng: &mut FuzzRng, input: &[u8]) -> Option<Vec<u8>> {
        if rng.random_range(0..4) == 0 {
            let mut copy = input.to_vec();
            mutate_lines(rng, &mut copy);
            return Some(copy);
        }
        json::mutate_json(rng, input, FOCUS)
    }

    fn execute(&self, input: &[u8]) -> Outcome {
        let files = WithScene { scene: input, files: &self.files };
        match load_scene_from(Path::new(SCENE), &files) {
            Ok(scene) => match oracle::check_scene(&scene) {
                Ok(()) => Outcome::Accepted,
                Err(problem) => Outcome::Bug(problem),
            },
            Err(error) => Outcome::Refused(error.to_string()),
        }
    }
}
