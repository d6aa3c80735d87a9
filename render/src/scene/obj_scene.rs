//! Wavefront OBJ scenes with their MTL material libraries, through `tobj` (polygons
//! triangulated as fans, one index per vertex).
//!
//! * Geometry: every object (or group, or run of faces under one `usemtl`) that has faces
//!   becomes one [`Shape`] with its own object id. OBJ is right-handed with +Y up, like the
//!   renderer, so positions are used as they are. Texture coordinates get v' = 1 − v (OBJ's
//!   v = 0 is the bottom of the image, the renderer's the top); an object whose faces only
//!   partly have texture coordinates gets none. Points and lines are ignored. Zero-area
//!   triangles are dropped and counted as in PLY meshes; NaN or infinite vertices are errors.
//! * Camera: OBJ has none, so a camera framing the scene looks down −Z.
//! * Materials, in this order of precedence:
//!   - `Pm` ≥ 0.5 (the PBR extension): a GGX conductor reproducing the colour `Kd` (as glTF
//!     metals), alpha = max(`Pr`², 10⁻³), `Pr` 1 when absent (outside [0, 1]: an error);
//!   - `illum` 4, 6, 7 or 9 (the transparent models), `d` < 1 or `Tr` > 0: a smooth
//!     dielectric with interior IOR `Ni` (1.5 when absent) and exterior IOR 1. `Tf` is not
//!     looked at: exporters write `Tf 1 1 1` for opaque materials too;
//!   - `illum` 3 or 5 (mirror reflection) with a non-black `Ks`: a GGX conductor
//!     reproducing `Ks`, alpha = √(2 / (`Ns` + 2)) (the Phong exponent's usual equivalent),
//!     10⁻³ without `Ns`;
//!   - otherwise diffuse `Kd` (0.8 grey when absent), times the `map_Kd` texture (sRGB,
//!     relative to the MTL file; `Kd` is baked into its texels, 1 when absent; map options
//!     such as `-s` are ignored and the file name is the last word).
//!
//!   All are two-sided except the dielectric. `Ke` is the shape's emitted radiance, from
//!   the front (counter-clockwise) side only, as every area light of the renderer.
//!   Specular highlights of `illum` 2 and every other texture are not used. An object without
//!   a material, or whose material library is missing (reported on stderr), is grey diffuse
//!   0.8.
//!
//! Errors name the file and the object or material: a missing OBJ, a malformed OBJ or MTL,
//! a non-finite vertex or texture coordinate, a NaN, infinite or negative colour, a mesh
//! whose triangles all have zero area, an unreadable texture. The material libraries and
//! textures are read through the loader's [`FileSource`].

use super::files::{self, DiskFiles, FileSource};
use super::mesh_util::{
    DEFAULT_GREY, MIN_ALPHA, assemble_scene, checked_triangles, default_material, emission, metal, tinted,
    without_panic,
};
use super::obj_check;
use super::{Albedo, Material, Scene, SceneError, Shape, Texture};
use std::cell::RefCell;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Loads an OBJ file and the MTL libraries it names (relative to its folder) as a scene
/// (module documentation).
pub fn load_obj(path: &Path) -> Result<Scene, SceneError> {
    let bytes = crate::scene::read_capped(path).map_err(|source| SceneError::Io { path: path.into(), source })?;
    load_obj_from(path, &bytes, &DiskFiles)
}

/// Loads the OBJ in `bytes` (the contents of `path`), reading the MTL libraries and
/// textures it names through `files`.
pub fn load_obj_from(path: &Path, bytes: &[u8], files: &dyn FileSource) -> Result<Scene, SceneError> {
    without_panic(|| load_bytes(path, bytes, files)).unwrap_or_else(|message| Err(obj_error(path, "(file)", message)))
}

/// An error about `element` of the OBJ or MTL file `path`.
fn obj_error(path: &Path, element: impl Into<String>, message: impl Into<String>) -> SceneError {
    SceneError::Ply { path: path.into(), element: element.into(), message: message.into() }
}

/// Loads the OBJ in `bytes`, read from `path`.
fn load_bytes(path: &Path, bytes: &[u8], files: &dyn FileSource) -> Result<Scene, SceneError> {
    // Text saved with a byte order mark is the same text (tobj read `\u{feff}v` as an
    // unknown statement and dropped the first vertex, or hid the first `newmtl`).
    let bytes = files::without_bom(bytes);
    let folder = path.parent().unwrap_or(Path::new("."));
    let warnings = RefCell::new(Vec::new());
    let library_missing = std::cell::Cell::new(false);
    let library_error = RefCell::new(None);
    let library_of = RefCell::new(HashMap::new());
    let text = String::from_utf8_lossy(bytes);
    let statements = obj_check::material_statements(&text);
    let load_library = |relative: &Path| {
        let library = folder.join(relative);
        let text = match files.read(&library) {
            Ok(text) => files::without_bom(&text).to_vec(),
            Err(error) => {
                if error.kind() == std::io::ErrorKind::NotFound {
                    library_missing.set(true);
                    let lines: Vec<usize> = statements
                        .iter()
                        .filter(|(_, s)| *s == obj_check::MaterialStatement::Library(relative.display().to_string()))
                        .map(|(line, _)| *line)
                        .collect();
                    warnings.borrow_mut().push(format!(
                        "{}: {}: material library {} not found; its materials are grey diffuse {DEFAULT_GREY}",
                        path.display(),
                        obj_check::lines_text(&lines),
                        library.display()
                    ));
                } else {
                    *library_error.borrow_mut() = Some(SceneError::Io { path: library.clone(), source: error });
                }
                return Err(tobj::LoadError::OpenFileFailed);
            }
        };
        if let Some((line, problem)) = obj_check::short_colour(&String::from_utf8_lossy(&text)) {
            *library_error.borrow_mut() = Some(obj_error(&library, format!("line {line}"), problem));
            return Err(tobj::LoadError::MaterialParseError);
        }
        let loaded = tobj::load_mtl_buf(&mut text.as_slice());
        match &loaded {
            Ok((materials, _)) => {
                let mut library_of = library_of.borrow_mut();
                library_of.extend(materials.iter().map(|m| (m.name.clone(), library.clone())));
            }
            Err(e) => {
                *library_error.borrow_mut() = Some(obj_error(&library, "(file)", format!("not a valid MTL file: {e}")))
            }
        }
        loaded
    };
    if let Some((line, problem)) = obj_check::bad_face_index(&text) {
        return Err(obj_error(path, format!("line {line}"), problem));
    }
    let short_faces = obj_check::short_faces(&text);
    if !short_faces.is_empty() {
        warnings.borrow_mut().push(format!(
            "{}: {}: {} with fewer than 3 vertices {} not a surface; left out",
            path.display(),
            obj_check::lines_text(&short_faces),
            if short_faces.len() == 1 { "a face".to_string() } else { format!("{} faces", short_faces.len()) },
            if short_faces.len() == 1 { "is" } else { "are" }
        ));
    }
    let options = tobj::LoadOptions { triangulate: true, single_index: true, ignore_points: true, ignore_lines: true };
    // tobj reads statements' arguments from untrimmed lines: indentation removed first,
    // and faces without a vertex (which tobj refuses as a whole file, where shorter faces
    // it drops) emptied: left out with the short faces' warning (UTF-8 only; other bytes
    // go to tobj as they are, which refuses them).
    let unindented = std::str::from_utf8(bytes).ok().map(obj_check::prepared_for_tobj);
    let parsed: &[u8] = unindented.as_ref().map_or(bytes, |t| t.as_bytes());
    let (models, materials) = tobj::load_obj_buf(&mut &parsed[..], &options, load_library)
        .map_err(|e| obj_error(path, "(file)", format!("not a valid OBJ file: {e}")))?;
    if let Some(error) = library_error.into_inner() {
        return Err(error);
    }
    let library_of = library_of.into_inner();
    let mut warnings = warnings.into_inner();
    // A `usemtl` naming no material of a library that was found: its faces get the
    // default material, said once per name. (A missing library was said above.)
    // A `usemtl` whose name no library loaded *before it* defines gets the default
    // material (tobj resolves names line by line), said once per name.
    let mut known: Vec<&str> = Vec::new();
    let mut unknown: Vec<(String, Vec<usize>)> = Vec::new();
    for (line, statement) in statements.iter().cloned() {
        match statement {
            obj_check::MaterialStatement::Library(file) => {
                let library = folder.join(&file);
                known.extend(library_of.iter().filter(|(_, l)| **l == library).map(|(name, _)| name.as_str()));
            }
            obj_check::MaterialStatement::Use(name) if !known.contains(&name.as_str()) => {
                match unknown.iter_mut().find(|(n, _)| *n == name) {
                    Some((_, lines)) => lines.push(line),
                    None => unknown.push((name, vec![line])),
                }
            }
            obj_check::MaterialStatement::Use(_) => {}
        }
    }
    for (name, lines) in unknown.into_iter().filter(|_| !library_missing.get()) {
        warnings.push(format!(
            "{}: {}: `usemtl {name}` names no material of the libraries loaded before it; its faces are grey \
             diffuse {DEFAULT_GREY}",
            path.display(),
            obj_check::lines_text(&lines)
        ));
    }
    let mut converter = MaterialConverter { files, textures: Vec::new(), texture_cache: HashMap::new() };
    let mut scene_materials = Vec::new();
    let mut names = Vec::new();
    let mut emissions = Vec::new();
    for material in materials.unwrap_or_default() {
        let library = library_of.get(&material.name).cloned().unwrap_or_else(|| path.to_path_buf());
        let (bsdf, radiance) = converter.convert(&library, &material)?;
        scene_materials.push(bsdf);
        names.push(material.name.clone());
        emissions.push(radiance);
    }
    let mut default_index = None;
    let mut shapes = Vec::new();
    for (index, model) in models.iter().enumerate() {
        let mesh = &model.mesh;
        if mesh.indices.is_empty() {
            continue;
        }
        let name = if model.name.is_empty() { format!("object {index}") } else { model.name.clone() };
        let positions: Vec<[f32; 3]> = mesh.positions.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
        let uvs = (!mesh.texcoords.is_empty() && mesh.texcoords.len() == 2 * positions.len())
            .then(|| mesh.texcoords.chunks_exact(2).map(|t| [t[0], 1.0 - t[1]]).collect());
        let faces = mesh.indices.chunks_exact(3).map(|f| [f[0], f[1], f[2]]).collect();
        let mesh_triangles = checked_triangles(positions, |p| p, uvs, faces)
            .map_err(|problem| obj_error(path, format!("object `{name}` {}", problem.element), problem.message))?;
        let (material, emission) = match mesh.material_id.filter(|&m| m < scene_materials.len()) {
            Some(m) => (m, emissions[m]),
            None => {
                let default = *default_index.get_or_insert_with(|| {
                    scene_materials.push(default_material());
                    names.push("(default)".into());
                    scene_materials.len() - 1
                });
                (default, None)
            }
        };
        shapes.push(Shape {
            name,
            object_id: shapes.len() as u32,
            material,
            emission,
            triangles: mesh_triangles.triangles,
            uvs: mesh_triangles.uvs,
            degenerate_dropped: mesh_triangles.degenerate_dropped,
        });
    }
    if shapes.is_empty() {
        return Err(obj_error(path, "faces", "the file has no triangles"));
    }
    let name = path.file_stem().map_or_else(|| path.display().to_string(), |s| s.to_string_lossy().into_owned());
    let mut scene = assemble_scene(name, None, (scene_materials, names), shapes, converter.textures)
        .map_err(|message| obj_error(path, "(scene)", message))?;
    scene.warnings = warnings;
    Ok(scene)
}

/// Turns MTL materials into the renderer's, loading their textures.
struct MaterialConverter<'a> {
    /// Where textures are read.
    files: &'a dyn FileSource,
    /// Decoded textures.
    textures: Vec<Texture>,
    /// Texture index by (file, tint bits).
    texture_cache: HashMap<(PathBuf, [u32; 3]), usize>,
}

impl MaterialConverter<'_> {
    /// The BSDF and emitted radiance of `material` from the library `library` (module
    /// documentation).
    fn convert(
        &mut self,
        library: &Path,
        material: &tobj::Material,
    ) -> Result<(Material, Option<[f32; 3]>), SceneError> {
        let element = |statement: &str| format!("material `{}` {statement}", material.name);
        let number = |statement: &str| -> Result<Option<f32>, SceneError> {
            let Some(text) = material.unknown_param.get(statement) else { return Ok(None) };
            match text.trim().parse::<f32>() {
                Ok(value) if value.is_finite() => Ok(Some(value)),
                _ => Err(obj_error(library, element(statement), format!("`{text}` is not a finite number"))),
            }
        };
        // Kd and Ks are reflectances: above 1 a surface would reflect more light than
        // arrives (creating energy).
        let reflectance = |statement: &str, value: Option<[f32; 3]>| -> Result<Option<[f32; 3]>, SceneError> {
            match value {
                Some(c) if !c.iter().all(|x| (0.0..=1.0).contains(x)) => Err(obj_error(
                    library,
                    element(statement),
                    format!("{c:?}: each must lie in [0, 1] (a reflectance above 1 creates energy)"),
                )),
                other => Ok(other),
            }
        };
        /// What a scalar statement must be.
        #[derive(Clone, Copy)]
        enum Least {
            Zero,
            Positive,
        }
        let scalar = |statement: &str, value: Option<f32>, least: Least| -> Result<Option<f32>, SceneError> {
            let (holds, rule) = match least {
                Least::Zero => (value.is_none_or(|v| v.is_finite() && v >= 0.0), "must be finite and ≥ 0"),
                Least::Positive => (value.is_none_or(|v| v.is_finite() && v > 0.0), "must be finite and positive"),
            };
            match value {
                Some(v) if !holds => Err(obj_error(library, element(statement), format!("{v} {rule}"))),
                other => Ok(other),
            }
        };
        // Fractions: d and Tr (opacity and transparency), Pm and Pr (the PBR extension's
        // metallic and roughness), all read whatever the material becomes.
        let fraction = |statement: &str, value: Option<f32>| -> Result<Option<f32>, SceneError> {
            match value {
                Some(v) if !(0.0..=1.0).contains(&v) => {
                    Err(obj_error(library, element(statement), format!("{v} must lie in [0, 1]")))
                }
                other => Ok(other),
            }
        };
        let dissolve = fraction("d", material.dissolve)?;
        let transparency = fraction("Tr", number("Tr")?)?;
        let metallic = fraction("Pm", number("Pm")?)?;
        let roughness = fraction("Pr", number("Pr")?)?;
        let optical_density = scalar("Ni", material.optical_density, Least::Positive)?;
        let shininess = scalar("Ns", material.shininess, Least::Zero)?;
        let kd = reflectance("Kd", material.diffuse)?;
        let ks = reflectance("Ks", material.specular)?;
        let radiance = emission(material.emissive.unwrap_or([0.0; 3]))
            .map_err(|message| obj_error(library, element("Ke"), message))?;
        let transparent = dissolve.is_some_and(|d| d < 1.0) || transparency.is_some_and(|t| t > 0.0);
        let illum = material.illumination_model;
        let bsdf = if metallic.is_some_and(|m| m >= 0.5) {
            let roughness = roughness.unwrap_or(1.0);
            metal(kd.unwrap_or([DEFAULT_GREY; 3]), roughness * roughness, true)
        } else if transparent || matches!(illum, Some(4 | 6 | 7 | 9)) {
            let int_ior = optical_density.unwrap_or(1.5);
            Material::Dielectric { int_ior, ext_ior: 1.0 }
        } else if let (Some(3 | 5), Some(ks)) = (illum, ks)
            && ks.iter().any(|&c| c > 0.0)
        {
            let alpha = shininess.map_or(MIN_ALPHA, |n| (2.0 / (n + 2.0)).sqrt());
            metal(ks, alpha, true)
        } else if let Some(map) = &material.diffuse_texture {
            let file =
                if map.trim_start().starts_with('-') { map.split_whitespace().last().unwrap_or(map) } else { map };
            let file = library.parent().unwrap_or(Path::new(".")).join(file.trim());
            let texture = self.texture(file, kd.unwrap_or([1.0; 3]))?;
            Material::Diffuse { albedo: Albedo::Texture { texture, uv_scale: [1.0, 1.0] }, two_sided: true }
        } else {
            Material::Diffuse { albedo: Albedo::Constant(kd.unwrap_or([DEFAULT_GREY; 3])), two_sided: true }
        };
        Ok((bsdf, radiance))
    }

    /// Index of the texture of `file` (sRGB) times `tint`.
    fn texture(&mut self, file: PathBuf, tint: [f32; 3]) -> Result<usize, SceneError> {
        let key = (file, tint.map(f32::to_bits));
        if let Some(&index) = self.texture_cache.get(&key) {
            return Ok(index);
        }
        let texture = Texture::decode(&key.0, &files::read(self.files, &key.0)?, true)?;
        self.textures.push(tinted(texture, tint));
        self.texture_cache.insert(key, self.textures.len() - 1);
        Ok(self.textures.len() - 1)
    }
}
