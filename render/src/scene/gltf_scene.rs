//! glTF 2.0 scenes (`.gltf` with its buffers and images, or binary `.glb`) through the
//! `gltf` crate, turned into the renderer's world-space triangles, materials and camera.
//!
//! * Geometry: every instance of a mesh primitive in the default scene (or the first
//!   scene; without scenes, every root node) becomes one [`Shape`] with its own object id,
//!   in world space through the whole node hierarchy. Triangles, strips and fans are read;
//!   points and lines are an error naming the mesh and primitive. An instance whose
//!   transform mirrors (negative determinant) has its winding swapped, so that the
//!   geometric normal stays on the glTF front side. Zero-area triangles are dropped and
//!   counted as in PLY meshes; NaN or infinite vertices are errors. Skins and morph targets
//!   are ignored (the bind pose is used).
//! * Camera: the first perspective camera met in the node hierarchy (depth first). Its
//!   image is 512 pixels wide, and 512 / `aspectRatio` high (512 × 512 without one;
//!   `aspectRatio` must lie in [1/16, 16], [`MAX_GLTF_ASPECT_RATIO`]); `yfov`
//!   becomes the horizontal opening angle 2·atan(tan(yfov/2)·width/height) with `fov_axis`
//!   `x`, so the vertical field of view is exactly `yfov`. Without `zfar`, the far clip lies
//!   beyond the whole scene. Without a perspective camera: a camera framing the scene,
//!   looking down −Z.
//! * Materials (metallic-roughness): `metallicFactor` ≥ 0.5 gives a GGX conductor with
//!   alpha = max(roughness², 10⁻³) (factors outside [0, 1]: an error) whose complex IOR reproduces the base colour
//!   (Gulbrandsen 2014, edge tint = base colour); otherwise a diffuse material with the
//!   base colour factor, times the base colour texture (decoded as sRGB, the factor baked
//!   into its texels) read with the texture's `texCoord` set. `doubleSided` gives
//!   `two_sided`. Emission is `emissiveFactor` × `KHR_materials_emissive_strength`, from
//!   the front side only (the renderer's area lights are one-sided). Not used: the base
//!   colour texture of metals, metallic-roughness, normal, occlusion and emissive textures,
//!   alpha, samplers
//!   (always bilinear with repeat wrap), texture transforms, transmission and other
//!   extensions. A primitive without a material gets grey diffuse 0.8 (not the glTF default
//!   white metal, which nobody means).
//!
//! Errors name the file and the glTF field (`meshes[0].primitives[1].mode`,
//! `accessors[3]`, ...): a missing file, malformed JSON or GLB, an invalid document, data
//! outside its buffer, an accessor of the wrong type, an accessor whose declared count
//! needs more bytes than its buffer view holds (checked before anything is allocated), a
//! NaN, infinite or negative colour factor, a singular or non-finite node transform. The
//! `gltf` crate can panic on some malformed documents; such a panic becomes an error too.
//! Buffers and images named by URI are `data:` URIs or files relative to the glTF file,
//! read through the loader's [`FileSource`].

use super::files::{self, DiskFiles, FileSource};
use super::gltf_check::{
    check_accessor_sizes, check_glb_header, check_position_accessors, document_error, json_error, raw_json,
};
use super::mesh_util::{
    DEFAULT_IMAGE_SIDE, assemble_scene, bounds, checked_triangles, default_material, emission, far_clip_beyond, metal,
    tinted, without_panic,
};
use super::texture::{decode_image, rgba8};
use super::uri::{self, Resolved};
use super::{Albedo, Camera, Material, Scene, SceneError, Shape, Texture};
use glam::{Mat3, Mat4, Vec3};
use gltf::Document;
use gltf::accessor::{Accessor, DataType, Dimensions};
use gltf::camera::Perspective;
use gltf::mesh::Mode;
use std::collections::HashMap;
use std::path::Path;

/// Loads a glTF 2.0 file (`.gltf` or `.glb`) as a scene (module documentation).
pub fn load_gltf(path: &Path) -> Result<Scene, SceneError> {
    let bytes = crate::scene::read_capped(path).map_err(|source| SceneError::Io { path: path.into(), source })?;
    load_gltf_from(path, &bytes, &DiskFiles)
}

/// Loads the glTF 2.0 document in `bytes` (JSON or GLB, the contents of `path`), reading
/// the buffers and images it names by relative URI through `files`.
pub fn load_gltf_from(path: &Path, bytes: &[u8], files: &dyn FileSource) -> Result<Scene, SceneError> {
    without_panic(|| load_bytes(path, bytes, files))
        .unwrap_or_else(|message| Err(json_error(path, "(document)", message)))
}

/// Refuses a document that is not glTF 2.x (`asset.version` "1.0" is a different format
/// whose fields the loader would misread; a version must be `MAJOR.MINOR` in digits), or
/// one whose `asset.minVersion` asks for more than the 2.0 this loader reads.
fn check_version(path: &Path, raw: &serde_json::Value) -> Result<(), SceneError> {
    /// `MAJOR.MINOR` in digits, as the glTF schema's pattern `^[0-9]+\.[0-9]+$` says.
    fn major_minor(text: &str) -> Option<(u64, u64)> {
        let (major, minor) = text.split_once('.')?;
        let digits = |t: &str| !t.is_empty() && t.bytes().all(|b| b.is_ascii_digit());
        if !(digits(major) && digits(minor)) {
            return None;
        }
        Some((major.parse().ok()?, minor.parse().ok()?))
    }
    match raw.pointer("/asset/version").and_then(serde_json::Value::as_str) {
        Some(text) if major_minor(text).is_some_and(|(major, _)| major == 2) => {}
        Some(text) => return Err(json_error(path, "asset.version", format!("`{text}`: only glTF 2.x is read"))),
        None => return Err(json_error(path, "asset.version", "missing: a glTF 2.0 document names its version")),
    }
    match raw.pointer("/asset/minVersion") {
        None => Ok(()),
        Some(value) => match value.as_str().and_then(major_minor) {
            Some((2, 0)) => Ok(()),
            _ => Err(json_error(
                path,
                "asset.minVersion",
                format!("{value}: this loader reads glTF 2.0, and the document needs a later version"),
            )),
        },
    }
}

/// The widest and (as its reciprocal) the tallest camera `aspectRatio` a glTF camera may
/// have: 16, a 512 × 32 image (and 1/16, 512 × 8192). Beyond it the image is a few rows
/// or columns whose other side spans nearly 180° (600 gave 512 × 1 pixels, black).
pub const MAX_GLTF_ASPECT_RATIO: f32 = 16.0;

/// How far from 1 the length of a node's rotation quaternion may be (exporters write
/// unit quaternions rounded to a few decimals); beyond it the rotation is an error,
/// since glam would turn a zero quaternion into no rotation at all.
const QUATERNION_LENGTH_TOLERANCE: f32 = 1e-2;

/// Loads the document in `bytes`, read from `path`.
fn load_bytes(path: &Path, bytes: &[u8], files: &dyn FileSource) -> Result<Scene, SceneError> {
    // A `.gltf` is JSON text: saved with a byte order mark, it is the same document.
    let bytes = files::without_bom(bytes);
    check_glb_header(path, bytes)?;
    let raw = raw_json(bytes).map_err(|message| json_error(path, "(document)", message))?;
    check_version(path, &raw)?;
    check_position_accessors(path, &raw)?;
    let gltf::Gltf { document, blob } = gltf::Gltf::from_slice(bytes).map_err(|e| document_error(path, e))?;
    let folder = path.parent().unwrap_or(Path::new("."));
    let buffers = load_buffers(path, folder, &document, blob, files)?;
    for view in document.views() {
        let available = buffers.get(view.buffer().index()).map_or(0, |b| b.len());
        if view.offset().checked_add(view.length()).is_none_or(|end| end > available) {
            return Err(json_error(
                path,
                format!("bufferViews[{}]", view.index()),
                format!(
                    "bytes {}..+{} lie outside buffer {} ({available} bytes)",
                    view.offset(),
                    view.length(),
                    view.buffer().index()
                ),
            ));
        }
    }
    check_accessor_sizes(path, &document)?;
    let mut loader = Loader {
        path,
        folder,
        files,
        raw,
        buffers,
        materials: Vec::new(),
        material_names: Vec::new(),
        material_info: Vec::new(),
        default_material: None,
        textures: Vec::new(),
        texture_cache: HashMap::new(),
    };
    for material in document.materials() {
        loader.add_material(&material)?;
    }
    let (shapes, camera_node) = loader.instances(&document)?;
    let camera = match camera_node {
        Some((node, world, view)) => match view.projection() {
            gltf::camera::Projection::Perspective(perspective) => {
                Some(loader.camera(node, world, &perspective, bounds(&shapes))?)
            }
            gltf::camera::Projection::Orthographic(_) => None,
        },
        None => None,
    };
    let name = path.file_stem().map_or_else(|| path.display().to_string(), |s| s.to_string_lossy().into_owned());
    assemble_scene(name, camera, (loader.materials, loader.material_names), shapes, loader.textures)
        .map_err(|message| json_error(path, "(scene)", message))
}

/// The contents of every buffer of `document`: the GLB's binary chunk, a `data:` URI, or a
/// file relative to `folder` read through `files`; each padded to a multiple of 4 bytes and
/// at least as long as its declared `byteLength`.
fn load_buffers(
    path: &Path,
    folder: &Path,
    document: &Document,
    mut blob: Option<Vec<u8>>,
    files: &dyn FileSource,
) -> Result<Vec<Vec<u8>>, SceneError> {
    let mut buffers = Vec::new();
    for buffer in document.buffers() {
        let field = format!("buffers[{}]", buffer.index());
        let mut data = match buffer.source() {
            gltf::buffer::Source::Bin => blob
                .take()
                .ok_or_else(|| json_error(path, &field, "cannot load the buffer data: the GLB has no binary chunk"))?,
            gltf::buffer::Source::Uri(text) => match uri::resolve(text, folder)
                .map_err(|message| json_error(path, &field, format!("cannot load the buffer data: {message}")))?
            {
                Resolved::Data(data) => data,
                Resolved::File(file) => files::read(files, &file)?,
            },
        };
        while !data.len().is_multiple_of(4) {
            data.push(0);
        }
        if data.len() < buffer.length() {
            return Err(json_error(
                path,
                field,
                format!("cannot load the buffer data: byteLength {} but only {} bytes", buffer.length(), data.len()),
            ));
        }
        buffers.push(data);
    }
    Ok(buffers)
}

/// What a shape needs from its material beyond the BSDF.
struct MaterialInfo {
    /// Emitted radiance, if any.
    emission: Option<[f32; 3]>,
    /// Texture coordinate set of the colour texture, if the material has one.
    tex_coord: Option<u32>,
}

/// The conversion's state.
struct Loader<'a> {
    /// The file, for messages.
    path: &'a Path,
    /// Where relative URIs start.
    folder: &'a Path,
    /// Where files named by URI are read.
    files: &'a dyn FileSource,
    /// The document as plain JSON.
    raw: serde_json::Value,
    /// Buffer contents, by index.
    buffers: Vec<Vec<u8>>,
    /// Renderer materials: the document's, by index, then the default one if needed.
    materials: Vec<Material>,
    /// Names of `materials`.
    material_names: Vec<String>,
    /// Emission and texture coordinate set of the document's materials, by index.
    material_info: Vec<MaterialInfo>,
    /// Index of the grey default material, once a primitive needs it.
    default_material: Option<usize>,
    /// Decoded textures.
    textures: Vec<Texture>,
    /// Texture index by (image index, tint bits).
    texture_cache: HashMap<(usize, [u32; 3]), usize>,
}

/// The first perspective camera: its node index, world matrix and camera.
type CameraNode<'d> = (usize, Mat4, gltf::Camera<'d>);

impl Loader<'_> {
    /// An error about `field`.
    fn error(&self, field: impl Into<String>, message: impl Into<String>) -> SceneError {
        json_error(self.path, field, message)
    }

    /// Converts material `material` of the document (module documentation).
    fn add_material(&mut self, material: &gltf::Material) -> Result<(), SceneError> {
        let index = material.index().unwrap_or(self.materials.len());
        let field = format!("materials[{index}]");
        let pbr = material.pbr_metallic_roughness();
        let [r, g, b, alpha] = pbr.base_color_factor();
        let (metallic, roughness) = (pbr.metallic_factor(), pbr.roughness_factor());
        if ![r, g, b, alpha, metallic, roughness].iter().all(|c| (0.0..=1.0).contains(c)) {
            return Err(self.error(
                format!("{field}.pbrMetallicRoughness"),
                format!(
                    "base colour {:?}, metallic {metallic}, roughness {roughness}: each must lie in [0, 1] (a base \
                     colour above 1 creates energy)",
                    [r, g, b, alpha]
                ),
            ));
        }
        let two_sided = material.double_sided();
        let mut tex_coord = None;
        let bsdf = if metallic >= 0.5 {
            metal([r, g, b], roughness * roughness, two_sided)
        } else if let Some(info) = pbr.base_color_texture() {
            tex_coord = Some(info.tex_coord());
            let texture = self.texture(info.texture().source(), [r, g, b])?;
            Material::Diffuse { albedo: Albedo::Texture { texture, uv_scale: [1.0, 1.0] }, two_sided }
        } else {
            Material::Diffuse { albedo: Albedo::Constant([r, g, b]), two_sided }
        };
        let pointer = format!("/materials/{index}/extensions/KHR_materials_emissive_strength/emissiveStrength");
        let strength = self.raw.pointer(&pointer).and_then(serde_json::Value::as_f64).unwrap_or(1.0) as f32;
        let radiance = material.emissive_factor().map(|c| c * strength);
        let emission = emission(radiance).map_err(|message| self.error(format!("{field}.emissiveFactor"), message))?;
        self.materials.push(bsdf);
        self.material_names.push(material.name().map_or_else(|| field.clone(), String::from));
        self.material_info.push(MaterialInfo { emission, tex_coord });
        Ok(())
    }

    /// Index of the renderer material of a primitive's material (the default if it has none).
    fn material_index(&mut self, material: &gltf::Material) -> usize {
        if let Some(index) = material.index() {
            return index;
        }
        *self.default_material.get_or_insert_with(|| {
            self.materials.push(default_material());
            self.material_names.push("(default)".into());
            self.materials.len() - 1
        })
    }

    /// Index of the texture decoding `image` as sRGB, times `tint`.
    fn texture(&mut self, image: gltf::Image, tint: [f32; 3]) -> Result<usize, SceneError> {
        let key = (image.index(), tint.map(f32::to_bits));
        if let Some(&index) = self.texture_cache.get(&key) {
            return Ok(index);
        }
        let field = format!("images[{}]", image.index());
        let json = self.raw.pointer(&format!("/images/{}", image.index()));
        let has = |name: &str| json.and_then(|j| j.get(name)).is_some_and(|v| !v.is_null());
        if has("bufferView") && !has("mimeType") {
            return Err(self.error(field, "an image in a buffer view needs a `mimeType`"));
        }
        if !has("bufferView") && !has("uri") {
            return Err(self.error(field, "the image has neither `uri` nor `bufferView`"));
        }
        let what = match image.source() {
            gltf::image::Source::Uri { uri, .. } if !uri.starts_with("data:") => format!("`{uri}`"),
            _ => "the image".into(),
        };
        let name = format!("{}#{field}", self.path.display());
        let encoded = match image.source() {
            gltf::image::Source::View { view, .. } => {
                let bytes = self
                    .buffers
                    .get(view.buffer().index())
                    .and_then(|buffer| buffer.get(view.offset()..view.offset().checked_add(view.length())?));
                bytes
                    .ok_or_else(|| self.error(field.clone(), "the image's buffer view lies outside its buffer"))?
                    .to_vec()
            }
            gltf::image::Source::Uri { uri, .. } => match uri::resolve(uri, self.folder)
                .map_err(|message| self.error(field.clone(), format!("cannot decode {what}: {message}")))?
            {
                Resolved::Data(data) => data,
                Resolved::File(file) => files::read(self.files, &file)?,
            },
        };
        let decoded = decode_image(Path::new(&name), &encoded)?;
        let (width, height) = (decoded.width(), decoded.height());
        let rgba = rgba8(&decoded);
        if width == 0 || height == 0 || rgba.len() != 4 * width as usize * height as usize {
            return Err(self.error(field, format!("{what}: {width}×{height} pixels do not match its data")));
        }
        self.textures.push(tinted(Texture::from_rgba8(name, width, height, &rgba, true), tint));
        self.texture_cache.insert(key, self.textures.len() - 1);
        Ok(self.textures.len() - 1)
    }

    /// Every mesh-primitive instance of the scene as a shape, and the first perspective camera.
    fn instances<'d>(&mut self, document: &'d Document) -> Result<(Vec<Shape>, Option<CameraNode<'d>>), SceneError> {
        let roots: Vec<gltf::Node> = match document.default_scene().or_else(|| document.scenes().next()) {
            Some(scene) => scene.nodes().collect(),
            None => {
                let children: Vec<usize> = document.nodes().flat_map(|n| n.children().map(|c| c.index())).collect();
                document.nodes().filter(|n| !children.contains(&n.index())).collect()
            }
        };
        let mut reached = vec![false; document.nodes().len()];
        let mut stack: Vec<(gltf::Node, Mat4)> = roots.into_iter().rev().map(|n| (n, Mat4::IDENTITY)).collect();
        let mut shapes = Vec::new();
        let mut camera = None;
        while let Some((node, parent)) = stack.pop() {
            let field = format!("nodes[{}]", node.index());
            if std::mem::replace(&mut reached[node.index()], true) {
                return Err(self.error(field, "the node is reached twice: the node hierarchy must be a tree"));
            }
            if let gltf::scene::Transform::Decomposed { rotation, .. } = node.transform() {
                let length = rotation.iter().map(|c| c * c).sum::<f32>().sqrt();
                if (length - 1.0).abs().is_nan() || (length - 1.0).abs() > QUATERNION_LENGTH_TOLERANCE {
                    return Err(self.error(
                        format!("{field}.rotation"),
                        format!("{rotation:?} has length {length}: a rotation is a unit quaternion"),
                    ));
                }
            }
            let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
            if !world.is_finite() {
                return Err(self.error(field, format!("the world transform is not finite: {world:?}")));
            }
            if let Some(mesh) = node.mesh() {
                for primitive in mesh.primitives() {
                    shapes.push(self.shape(&node, world, &mesh, &primitive, shapes.len() as u32)?);
                }
            }
            if let (None, Some(view)) = (&camera, node.camera())
                && matches!(view.projection(), gltf::camera::Projection::Perspective(_))
            {
                camera = Some((node.index(), world, view));
            }
            stack.extend(node.children().collect::<Vec<_>>().into_iter().rev().map(|c| (c, world)));
        }
        if shapes.is_empty() {
            return Err(self.error("(scene)", "the scene has no mesh instances"));
        }
        Ok((shapes, camera))
    }

    /// Checks that `accessor` holds `dimensions` of one of `types` and can be read, for `use`.
    fn check_accessor(
        &self,
        accessor: &Accessor,
        what: &str,
        dimensions: Dimensions,
        types: &[DataType],
    ) -> Result<(), SceneError> {
        let field = format!("accessors[{}]", accessor.index());
        let fail = |message: String| Err(self.error(field.clone(), format!("{what}: {message}")));
        if accessor.dimensions() != dimensions || !types.contains(&accessor.data_type()) {
            return fail(format!(
                "{:?} of {:?}: expected {dimensions:?} of {types:?}",
                accessor.dimensions(),
                accessor.data_type()
            ));
        }
        if accessor.count() == 0 || accessor.sparse().is_some_and(|s| s.count() == 0) {
            return fail("no elements".into());
        }
        if let Some(stride) = accessor.view().and_then(|v| v.stride())
            && stride < accessor.size()
        {
            return fail(format!("byte stride {stride} is smaller than an element ({} bytes)", accessor.size()));
        }
        Ok(())
    }

    /// The shape of one instance of `primitive` of `mesh` under `node` (world matrix `world`).
    fn shape(
        &mut self,
        node: &gltf::Node,
        world: Mat4,
        mesh: &gltf::Mesh,
        primitive: &gltf::Primitive,
        object_id: u32,
    ) -> Result<Shape, SceneError> {
        let field = format!("meshes[{}].primitives[{}]", mesh.index(), primitive.index());
        let material = primitive.material();
        let material_index = self.material_index(&material);
        let info = material.index().and_then(|i| self.material_info.get(i));
        let (emission, textured_with) = info.map_or((None, None), |i| (i.emission, i.tex_coord));
        let tex_coord = textured_with.unwrap_or(0);
        let buffers = &self.buffers;
        let reader = primitive.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
        let outside = |accessor: &Accessor| {
            self.error(format!("accessors[{}]", accessor.index()), "its data lies outside its buffer view")
        };
        let Some(position_accessor) = primitive.get(&gltf::Semantic::Positions) else {
            return Err(self.error(format!("{field}.attributes"), "no POSITION"));
        };
        self.check_accessor(&position_accessor, "POSITION", Dimensions::Vec3, &[DataType::F32])?;
        let positions: Vec<[f32; 3]> = reader.read_positions().ok_or_else(|| outside(&position_accessor))?.collect();
        let indices: Vec<u32> = match primitive.indices() {
            Some(accessor) => {
                self.check_accessor(
                    &accessor,
                    "indices",
                    Dimensions::Scalar,
                    &[DataType::U8, DataType::U16, DataType::U32],
                )?;
                reader.read_indices().ok_or_else(|| outside(&accessor))?.into_u32().collect()
            }
            None => (0..positions.len() as u32).collect(),
        };
        let mut faces: Vec<[u32; 3]> = match primitive.mode() {
            Mode::Triangles if indices.len().is_multiple_of(3) => {
                indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect()
            }
            Mode::Triangles => {
                return Err(self.error(field, format!("{} indices: not a multiple of 3", indices.len())));
            }
            Mode::TriangleStrip => (0..indices.len().saturating_sub(2))
                .map(|i| [indices[i], indices[i + 1 + i % 2], indices[i + 2 - i % 2]])
                .collect(),
            Mode::TriangleFan => {
                (1..indices.len().saturating_sub(1)).map(|i| [indices[i], indices[i + 1], indices[0]]).collect()
            }
            other => {
                let name = mesh.name().map(|n| format!(" (mesh `{n}`)")).unwrap_or_default();
                return Err(self.error(
                    format!("{field}.mode"),
                    format!("{other:?}{name}: only triangle primitives (triangles, strips, fans) are supported"),
                ));
            }
        };
        let uvs = match primitive.get(&gltf::Semantic::TexCoords(tex_coord)) {
            Some(accessor) => {
                let what = format!("TEXCOORD_{tex_coord}");
                self.check_accessor(&accessor, &what, Dimensions::Vec2, &[DataType::F32, DataType::U8, DataType::U16])?;
                Some(reader.read_tex_coords(tex_coord).ok_or_else(|| outside(&accessor))?.into_f32().collect())
            }
            // A textured material needs the coordinates it names: without them every
            // texel lookup would be a guess.
            None if textured_with.is_some() => {
                return Err(self.error(
                    format!("{field}.attributes"),
                    format!(
                        "no TEXCOORD_{tex_coord}, which the base colour texture of material `{}` reads",
                        material.name().map_or_else(|| format!("materials[{:?}]", material.index()), String::from)
                    ),
                ));
            }
            None => None,
        };
        if Mat3::from_mat4(world).determinant() < 0.0 {
            faces.iter_mut().for_each(|f| f.swap(1, 2));
        }
        let to_world = |p: [f32; 3]| world.transform_point3(Vec3::from(p)).into();
        let mesh_triangles = checked_triangles(positions, to_world, uvs, faces).map_err(|problem| {
            self.error(
                field.clone(),
                format!("{} (instance of nodes[{}]): {}", problem.element, node.index(), problem.message),
            )
        })?;
        let mut name = node.name().or(mesh.name()).map_or_else(|| format!("nodes[{}]", node.index()), String::from);
        if mesh.primitives().len() > 1 {
            name = format!("{name}#{}", primitive.index());
        }
        Ok(Shape {
            name,
            object_id,
            material: material_index,
            emission,
            triangles: mesh_triangles.triangles,
            uvs: mesh_triangles.uvs,
            degenerate_dropped: mesh_triangles.degenerate_dropped,
        })
    }

    /// The renderer's camera for the perspective camera of node `node` (module documentation).
    fn camera(
        &self,
        node: usize,
        world: Mat4,
        perspective: &Perspective,
        scene_bounds: (Vec3, Vec3),
    ) -> Result<Camera, SceneError> {
        let field = format!("nodes[{node}].camera");
        let yfov = perspective.yfov();
        if !(yfov > 0.0 && yfov < std::f32::consts::PI) {
            return Err(self.error(field, format!("yfov {yfov} must lie in (0, π)")));
        }
        let (width, height) = match perspective.aspect_ratio() {
            Some(aspect) if (1.0 / MAX_GLTF_ASPECT_RATIO..=MAX_GLTF_ASPECT_RATIO).contains(&aspect) => {
                (DEFAULT_IMAGE_SIDE, (DEFAULT_IMAGE_SIDE as f32 / aspect).round() as u32)
            }
            Some(aspect) => {
                return Err(self.error(
                    field,
                    format!(
                        "aspectRatio {aspect} must lie in [1/{MAX_GLTF_ASPECT_RATIO}, {MAX_GLTF_ASPECT_RATIO}] (the image is \
                         {DEFAULT_IMAGE_SIDE} pixels wide, so {} to {} pixels high)",
                        (DEFAULT_IMAGE_SIDE as f32 / MAX_GLTF_ASPECT_RATIO) as u32,
                        (DEFAULT_IMAGE_SIDE as f32 * MAX_GLTF_ASPECT_RATIO) as u32
                    ),
                ));
            }
            None => (DEFAULT_IMAGE_SIDE, DEFAULT_IMAGE_SIDE),
        };
        let near_clip = perspective.znear();
        if !(near_clip.is_finite() && near_clip > 0.0) {
            return Err(self.error(field, format!("znear {near_clip} must be > 0")));
        }
        let far_clip = perspective.zfar();
        if let Some(far) = far_clip.filter(|&far| !(far.is_finite() && far > near_clip)) {
            return Err(self.error(field, format!("zfar {far} must be finite and beyond znear {near_clip}")));
        }
        let origin = world.transform_point3(Vec3::ZERO);
        let forward = world.transform_vector3(Vec3::NEG_Z).normalize_or_zero();
        let up = world.transform_vector3(Vec3::Y).normalize_or_zero();
        if forward == Vec3::ZERO
            || forward.cross(up).length_squared().is_nan()
            || forward.cross(up).length_squared() <= 1e-12
        {
            return Err(self.error(format!("nodes[{node}]"), "the camera's transform has no view direction or up"));
        }
        let fov_x = 2.0 * ((yfov * 0.5).tan() * width as f32 / height as f32).atan();
        if !(fov_x.to_degrees() > 1e-3 && fov_x.to_degrees() < 180.0) {
            return Err(self.error(field, format!("yfov {yfov} gives a horizontal opening of {fov_x} radians")));
        }
        Ok(Camera {
            origin: origin.into(),
            target: (origin + forward).into(),
            up: up.into(),
            fov_deg: fov_x.to_degrees(),
            fov_axis: "x".into(),
            width,
            height,
            near_clip,
            far_clip: far_clip.unwrap_or_else(|| far_clip_beyond(origin, scene_bounds)),
        })
    }
}
