//! glTF 2.0 and Wavefront OBJ + MTL scenes: small files written here, loaded through
//! `load_scene_file`, checked for world-space geometry, object ids, texture coordinates,
//! materials, emitters and cameras; bad files are refused with errors that name them.

use glam::Vec3;
use serde_json::{Value, json};
use std::path::{Path, PathBuf};
use strata_check::fuzz::build::base64;
use strata_render::scene::{Albedo, CameraFrame, Material, Scene, SceneError, load_scene_file, srgb_to_linear};

/// A fresh empty folder of this test process, under cargo's `target/tmp`, not the shared `/tmp`,
/// where another user could create the name first.
fn temp_folder(name: &str) -> PathBuf {
    let dir =
        std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("strata-formats-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn write(dir: &Path, name: &str, bytes: impl AsRef<[u8]>) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

/// A PNG of `width` × 1 RGBA pixels.
fn png(pixels: &[[u8; 4]]) -> Vec<u8> {
    let image = image::RgbaImage::from_raw(pixels.len() as u32, 1, pixels.concat()).unwrap();
    let mut bytes = std::io::Cursor::new(Vec::new());
    image.write_to(&mut bytes, image::ImageFormat::Png).unwrap();
    bytes.into_inner()
}

/// One glTF buffer with its views and accessors, built up as data is added.
#[derive(Default)]
struct GltfData {
    bytes: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl GltfData {
    /// Adds an accessor of `count` elements of `kind` (`VEC3`, ...) and `component` type
    /// over `data`; returns its index.
    fn add(&mut self, data: &[u8], count: usize, kind: &str, component: u32, extra: Value) -> usize {
        while !self.bytes.len().is_multiple_of(4) {
            self.bytes.push(0);
        }
        self.views.push(json!({"buffer": 0, "byteOffset": self.bytes.len(), "byteLength": data.len()}));
        self.bytes.extend_from_slice(data);
        let mut accessor =
            json!({"bufferView": self.views.len() - 1, "componentType": component, "count": count, "type": kind});
        if let Value::Object(extra) = extra {
            accessor.as_object_mut().unwrap().extend(extra);
        }
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }

    fn positions(&mut self, points: &[[f32; 3]]) -> usize {
        let bytes: Vec<u8> = points.iter().flatten().flat_map(|c| c.to_le_bytes()).collect();
        let min = (0..3).map(|i| points.iter().map(|p| p[i]).fold(f32::INFINITY, f32::min)).collect::<Vec<_>>();
        let max = (0..3).map(|i| points.iter().map(|p| p[i]).fold(f32::NEG_INFINITY, f32::max)).collect::<Vec<_>>();
        self.add(&bytes, points.len(), "VEC3", 5126, json!({"min": min, "max": max}))
    }

    fn uvs(&mut self, uvs: &[[f32; 2]]) -> usize {
        let bytes: Vec<u8> = uvs.iter().flatten().flat_map(|c| c.to_le_bytes()).collect();
        self.add(&bytes, uvs.len(), "VEC2", 5126, json!({}))
    }

    fn indices(&mut self, indices: &[u16]) -> usize {
        let bytes: Vec<u8> = indices.iter().flat_map(|i| i.to_le_bytes()).collect();
        self.add(&bytes, indices.len(), "SCALAR", 5123, json!({}))
    }

    /// `document` with this buffer (as a base64 data URI), its views and accessors.
    fn gltf(&self, mut document: Value) -> Vec<u8> {
        let uri = format!("data:application/octet-stream;base64,{}", base64(&self.bytes));
        document["buffers"] = json!([{"byteLength": self.bytes.len(), "uri": uri}]);
        self.finish(document)
    }

    /// `document` with this buffer as the BIN chunk of a GLB file.
    fn glb(&self, mut document: Value) -> Vec<u8> {
        document["buffers"] = json!([{"byteLength": self.bytes.len()}]);
        let mut json = self.finish(document);
        while !json.len().is_multiple_of(4) {
            json.push(b' ');
        }
        let mut bin = self.bytes.clone();
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        let total = 12 + 8 + json.len() + 8 + bin.len();
        let mut glb = Vec::new();
        glb.extend_from_slice(b"glTF");
        glb.extend(2u32.to_le_bytes());
        glb.extend((total as u32).to_le_bytes());
        glb.extend((json.len() as u32).to_le_bytes());
        glb.extend_from_slice(b"JSON");
        glb.extend(json);
        glb.extend((bin.len() as u32).to_le_bytes());
        glb.extend_from_slice(b"BIN\0");
        glb.extend(bin);
        glb
    }

    fn finish(&self, mut document: Value) -> Vec<u8> {
        document["asset"] = json!({"version": "2.0"});
        document["bufferViews"] = json!(self.views);
        document["accessors"] = json!(self.accessors);
        serde_json::to_vec_pretty(&document).unwrap()
    }
}

const TRIANGLE: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
const TRIANGLE_UVS: [[f32; 2]; 3] = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];

fn close(a: [f32; 3], b: [f32; 3]) -> bool {
    Vec3::from(a).distance(Vec3::from(b)) < 1e-5
}

fn normal(t: &[[f32; 3]; 3]) -> Vec3 {
    let [a, b, c] = t.map(Vec3::from);
    (b - a).cross(c - a).normalize()
}

/// Where `point` lands in the camera's image, in [−1, 1]² when visible.
fn project(frame: &CameraFrame, point: [f32; 3]) -> (f32, f32) {
    let d = Vec3::from(point) - frame.origin;
    let depth = d.dot(frame.forward);
    (d.dot(frame.right) / depth / frame.tan_half_x, d.dot(frame.up) / depth / frame.tan_half_y)
}

/// Asserts that every vertex of the scene lies inside its camera's view.
fn assert_framed(scene: &Scene) {
    let frame = CameraFrame::new(&scene.camera).unwrap();
    for point in scene.shapes.iter().flat_map(|s| s.triangles.iter().flatten()) {
        let (x, y) = project(&frame, *point);
        assert!(x.abs() <= 1.0 && y.abs() <= 1.0, "{point:?} lands at ({x}, {y}), outside the image");
    }
}

#[test]
fn gltf_node_hierarchy_gives_world_space_instances_with_their_own_ids() {
    let dir = temp_folder("hierarchy");
    let mut data = GltfData::default();
    let positions = data.positions(&TRIANGLE);
    let uvs = data.uvs(&TRIANGLE_UVS);
    let indices = data.indices(&[0, 1, 2]);
    let quad = data.positions(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]]);
    let quad_indices = data.indices(&[0, 1, 2, 0, 2, 3]);
    let strip = data.positions(&[[0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0], [1.0, 1.0, 1.0]]);
    let s = std::f32::consts::FRAC_1_SQRT_2;
    let document = json!({
        "scene": 0,
        "scenes": [{"nodes": [0, 2, 3]}],
        "nodes": [
            {"name": "parent", "translation": [10.0, 0.0, 0.0], "scale": [2.0, 2.0, 2.0], "children": [1]},
            {"name": "child", "translation": [0.0, 1.0, 0.0], "rotation": [0.0, 0.0, s, s], "mesh": 0},
            {"name": "mirror", "scale": [-1.0, 1.0, 1.0], "mesh": 0},
            {"name": "plain", "matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, -3, 1], "mesh": 1},
            {"name": "not in the scene", "mesh": 0}
        ],
        "meshes": [
            {"name": "triangle", "primitives": [{"attributes": {"POSITION": positions, "TEXCOORD_0": uvs}, "indices": indices}]},
            {"name": "two parts", "primitives": [
                {"attributes": {"POSITION": quad}, "indices": quad_indices},
                {"attributes": {"POSITION": strip}, "mode": 5}
            ]}
        ]
    });
    let path = write(&dir, "hierarchy.gltf", data.gltf(document));
    let scene = load_scene_file(&path).unwrap();
    let names: Vec<&str> = scene.shapes.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["child", "mirror", "plain#0", "plain#1"]);
    for (index, shape) in scene.shapes.iter().enumerate() {
        assert_eq!(shape.object_id, index as u32);
    }
    assert_eq!(scene.shapes.iter().map(|s| s.triangles.len()).collect::<Vec<_>>(), [1, 1, 2, 2]);
    // child: parent (translate 10 x, scale 2) of (translate 1 y, rotate 90° about z).
    let child = scene.shapes[0].triangles[0];
    for (got, want) in child.iter().zip([[10.0, 2.0, 0.0], [10.0, 4.0, 0.0], [8.0, 2.0, 0.0]]) {
        assert!(close(*got, want), "{child:?}");
    }
    assert_eq!(scene.shapes[0].uvs.as_deref(), Some(&[TRIANGLE_UVS][..]));
    // The mirrored instance keeps its front side: winding swapped, normal still +z.
    let mirror = &scene.shapes[1];
    assert!(close(mirror.triangles[0][1], [0.0, 1.0, 0.0]) && close(mirror.triangles[0][2], [-1.0, 0.0, 0.0]));
    assert!(normal(&mirror.triangles[0]).z > 0.99);
    assert_eq!(mirror.uvs.as_ref().unwrap()[0], [[0.0, 0.0], [0.0, 1.0], [1.0, 0.0]]);
    // matrix node: translation −3 in z; strip triangles keep a consistent (+z) winding.
    assert!(scene.shapes[2].triangles.iter().flatten().all(|p| p[2] == -3.0));
    assert!(scene.shapes[3].triangles.iter().all(|t| normal(t).z > 0.99 && t.iter().all(|p| p[2] == -2.0)));
    // No material: grey diffuse 0.8, no emission; no camera: one framing the scene along −Z.
    assert!(scene.shapes.iter().all(|s| s.emission.is_none() && s.material == 0));
    assert_eq!(scene.materials, [Material::diffuse([0.8; 3])]);
    let forward = (Vec3::from(scene.camera.target) - Vec3::from(scene.camera.origin)).normalize();
    assert!(forward.abs_diff_eq(Vec3::NEG_Z, 1e-6), "{forward}");
    assert_framed(&scene);
    assert_eq!((scene.max_depth, scene.rr_depth), (8, 5));
    std::fs::remove_dir_all(dir).unwrap();
}

/// A glTF document of one triangle per material (and one without), with a texture and cameras.
fn materials_document(data: &mut GltfData) -> Value {
    let positions = data.positions(&TRIANGLE);
    let uvs = data.uvs(&TRIANGLE_UVS);
    let primitive = |material: Option<usize>| {
        let mut p = json!({"attributes": {"POSITION": positions, "TEXCOORD_0": uvs}});
        if let Some(m) = material {
            p["material"] = json!(m);
        }
        p
    };
    let texture = format!("data:image/png;base64,{}", base64(&png(&[[255, 0, 0, 255], [0, 128, 255, 255]])));
    json!({
        "extensionsUsed": ["KHR_materials_emissive_strength"],
        "scenes": [{"nodes": [0, 1, 2, 3]}],
        "nodes": [
            {"name": "shapes", "mesh": 0},
            {"name": "orthographic", "camera": 0},
            {"name": "eye", "camera": 1, "translation": [0.0, 0.0, 5.0], "rotation": [0.0, std::f32::consts::FRAC_1_SQRT_2, 0.0, std::f32::consts::FRAC_1_SQRT_2]},
            {"name": "second eye", "camera": 2}
        ],
        "cameras": [
            {"type": "orthographic", "orthographic": {"xmag": 1.0, "ymag": 1.0, "znear": 0.1, "zfar": 10.0}},
            {"type": "perspective", "perspective": {"yfov": 0.5, "aspectRatio": 2.0, "znear": 0.1, "zfar": 100.0}},
            {"type": "perspective", "perspective": {"yfov": 1.0, "znear": 0.1}}
        ],
        "meshes": [{"primitives": [primitive(Some(0)), primitive(Some(1)), primitive(Some(2)), primitive(Some(3)), primitive(None)]}],
        "materials": [
            {"name": "matte", "doubleSided": true, "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.25, 0.125, 1.0], "metallicFactor": 0.0}},
            {"name": "gold", "pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.6, 0.3, 1.0], "metallicFactor": 1.0, "roughnessFactor": 0.5}},
            {"name": "lamp", "emissiveFactor": [1.0, 0.5, 0.25], "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4.0}},
             "pbrMetallicRoughness": {"baseColorFactor": [0.0, 0.0, 0.0, 1.0], "metallicFactor": 0.0}},
            {"name": "textured", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 1.0, 1.0, 1.0], "metallicFactor": 0.0,
             "baseColorTexture": {"index": 0}}}
        ],
        "textures": [{"source": 0}],
        "images": [{"uri": texture}]
    })
}

/// Normal-incidence reflectance of the complex IOR n + ik against vacuum.
fn fresnel_0(n: f32, k: f32) -> f32 {
    ((n - 1.0) * (n - 1.0) + k * k) / ((n + 1.0) * (n + 1.0) + k * k)
}

#[test]
fn gltf_materials_emission_textures_and_camera() {
    let dir = temp_folder("materials");
    let mut data = GltfData::default();
    let document = materials_document(&mut data);
    let scene = load_scene_file(&write(&dir, "materials.gltf", data.gltf(document))).unwrap();
    assert_eq!(scene.material_names, ["matte", "gold", "lamp", "textured", "(default)"]);
    assert_eq!(scene.shapes.iter().map(|s| s.material).collect::<Vec<_>>(), [0, 1, 2, 3, 4]);
    assert_eq!(scene.materials[0], Material::Diffuse { albedo: Albedo::Constant([0.5, 0.25, 0.125]), two_sided: true });
    let Material::RoughConductor { alpha, eta, k, two_sided } = &scene.materials[1] else {
        panic!("gold is {:?}", scene.materials[1]);
    };
    assert_eq!((*alpha, *two_sided), (0.25, false));
    for (c, want) in [0.9, 0.6, 0.3].into_iter().enumerate() {
        assert!((fresnel_0(eta[c], k[c]) - want).abs() < 1e-4, "gold reflects its base colour head-on");
    }
    let emissions: Vec<_> = scene.shapes.iter().map(|s| s.emission).collect();
    assert_eq!(emissions, [None, None, Some([4.0, 2.0, 1.0]), None, None]);
    let Material::Diffuse { albedo: Albedo::Texture { texture, uv_scale }, two_sided: false } = &scene.materials[3]
    else {
        panic!("textured is {:?}", scene.materials[3]);
    };
    assert_eq!(*uv_scale, [1.0, 1.0]);
    let texture = &scene.textures[*texture];
    assert_eq!((texture.width, texture.height), (2, 1));
    // sRGB-decoded texels times the base colour factor (0.5, 1, 1).
    assert_eq!(texture.texels, [[0.5, 0.0, 0.0], [0.0, srgb_to_linear(128), 1.0]]);
    assert_eq!(scene.shapes[3].uvs.as_deref(), Some(&[TRIANGLE_UVS][..]));
    assert_eq!(scene.materials[4], Material::diffuse([0.8; 3]));
    // The first perspective camera: 2:1, vertical field of view exactly yfov, looking down
    // −x (rotated 90° about y from −z).
    let camera = &scene.camera;
    assert_eq!((camera.width, camera.height, camera.fov_axis.as_str()), (512, 256, "x"));
    assert!((camera.fov_deg - (2.0 * (0.25f32.tan() * 2.0).atan()).to_degrees()).abs() < 1e-4);
    assert_eq!((camera.near_clip, camera.far_clip), (0.1, 100.0));
    let frame = CameraFrame::new(camera).unwrap();
    assert!((frame.tan_half_y - 0.25f32.tan()).abs() < 1e-6, "{}", frame.tan_half_y);
    assert!(frame.origin.abs_diff_eq(Vec3::new(0.0, 0.0, 5.0), 1e-6));
    assert!(frame.forward.abs_diff_eq(Vec3::NEG_X, 1e-6), "{}", frame.forward);
    assert!(frame.up.abs_diff_eq(Vec3::Y, 1e-6), "{}", frame.up);
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn glb_files_load_like_gltf() {
    let dir = temp_folder("glb");
    let mut data = GltfData::default();
    let document = materials_document(&mut data);
    let from_gltf = load_scene_file(&write(&dir, "scene.gltf", data.gltf(document.clone()))).unwrap();
    let from_glb = load_scene_file(&write(&dir, "scene.glb", data.glb(document))).unwrap();
    assert_eq!(from_glb.shapes, from_gltf.shapes);
    assert_eq!(from_glb.materials, from_gltf.materials);
    let texels = |scene: &Scene| scene.textures.iter().map(|t| t.texels.clone()).collect::<Vec<_>>();
    assert_eq!(texels(&from_glb), texels(&from_gltf));
    assert_eq!(from_glb.camera, from_gltf.camera);
    assert_eq!(from_glb.shapes[2].emission, Some([4.0, 2.0, 1.0]), "the emissive strength is read from GLB too");
    std::fs::remove_dir_all(dir).unwrap();
}

/// The MTL library of `scene.obj`.
const MTL: &str = "\
newmtl red
Kd 0.5 0.1 0.1
newmtl light
Kd 0 0 0
Ke 10 10 10
newmtl glass
illum 7
Ni 1.33
newmtl gold
Kd 0.9 0.6 0.3
Pm 1
Pr 0.5
newmtl textured
Kd 0.5 0.5 0.5
map_Kd tex.png
newmtl mirror
illum 5
Ks 0.9 0.9 0.9
Ns 1000
";

/// Seven objects: a quad, a light, glass with a zero-area triangle, gold, a textured
/// triangle, a mirror and one with an unknown material.
const OBJ: &str = "\
mtllib scene.mtl
v -1 -1 0
v 1 -1 0
v 1 1 0
v -1 1 0
v 3 -1 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
o floor
usemtl red
f 1/1 2/2 3/3 4/4
o lamp
usemtl light
f 1 2 3
o glass
usemtl glass
f 1 2 3
f 1 2 5
o gold
usemtl gold
f 1 2 3
o picture
usemtl textured
f 1/1 2/2 3/3
o mirror
usemtl mirror
f 1 2 3
o unknown
usemtl nowhere
f 1 3 4
";

#[test]
fn obj_and_mtl_give_shapes_materials_and_a_framing_camera() {
    let dir = temp_folder("obj");
    write(&dir, "scene.mtl", MTL);
    write(&dir, "tex.png", png(&[[255, 255, 255, 255], [0, 0, 0, 255]]));
    let scene = load_scene_file(&write(&dir, "scene.obj", OBJ)).unwrap();
    let names: Vec<&str> = scene.shapes.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["floor", "lamp", "glass", "gold", "picture", "mirror", "unknown"]);
    for (index, shape) in scene.shapes.iter().enumerate() {
        assert_eq!(shape.object_id, index as u32);
    }
    let floor = &scene.shapes[0];
    assert_eq!(floor.triangles.len(), 2, "the quad is triangulated");
    assert_eq!(floor.triangles[0], [[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [1.0, 1.0, 0.0]]);
    assert_eq!(floor.uvs.as_ref().unwrap()[0], [[0.0, 1.0], [1.0, 1.0], [1.0, 0.0]], "v is flipped");
    assert!(scene.shapes[1].uvs.is_none());
    assert_eq!((scene.shapes[2].triangles.len(), scene.shapes[2].degenerate_dropped), (1, 1));
    let material = |shape: usize| &scene.materials[scene.shapes[shape].material];
    assert_eq!(*material(0), Material::Diffuse { albedo: Albedo::Constant([0.5, 0.1, 0.1]), two_sided: true });
    assert_eq!(scene.shapes[1].emission, Some([10.0, 10.0, 10.0]));
    assert!(scene.shapes.iter().enumerate().all(|(i, s)| (i == 1) == s.emission.is_some()));
    assert_eq!(*material(2), Material::Dielectric { int_ior: 1.33, ext_ior: 1.0 });
    assert!(matches!(material(3), Material::RoughConductor { alpha, two_sided: true, .. } if *alpha == 0.25));
    let Material::Diffuse { albedo: Albedo::Texture { texture, .. }, .. } = material(4) else {
        panic!("picture is {:?}", material(4));
    };
    assert_eq!(scene.textures[*texture].texels, [[0.5; 3], [0.0; 3]], "Kd 0.5 times the texture");
    assert!(
        matches!(material(5), Material::RoughConductor { alpha, .. } if (*alpha - (2.0f32 / 1002.0).sqrt()).abs() < 1e-6)
    );
    assert_eq!(*material(6), Material::diffuse([0.8; 3]));
    // The framing camera sees every vertex and hits the floor through the image centre.
    assert_framed(&scene);
    let (triangles, ids) = scene.triangles_with_ids();
    let (tris, bvh) = strata_render::trace_pass::build_obvhs(&triangles);
    let frame = CameraFrame::new(&scene.camera).unwrap();
    let (origin, direction) = frame.ray(0.5, 0.5);
    let ray = obvhs::ray::Ray::new(origin.into(), direction.into(), 0.0, scene.camera.far_clip);
    let mut hit = obvhs::ray::RayHit::none();
    assert!(bvh.ray_traverse(ray, &mut hit, |r, i| tris[bvh.primitive_indices[i] as usize].intersect(r)));
    assert!(ids[bvh.primitive_indices[hit.primitive_id as usize] as usize] < 7);
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn obj_without_its_material_library_is_grey() {
    let dir = temp_folder("nomtl");
    let scene = load_scene_file(&write(&dir, "lonely.obj", OBJ)).unwrap();
    assert_eq!(scene.shapes.len(), 7);
    assert_eq!(scene.materials, [Material::diffuse([0.8; 3])]);
    assert_eq!(scene.material_names, ["(default)"]);
    assert!(scene.shapes.iter().all(|s| s.material == 0 && s.emission.is_none()));
    std::fs::remove_dir_all(dir).unwrap();
}

/// The error of loading `name` with `contents` from `dir`, as text.
fn refused(dir: &Path, name: &str, contents: impl AsRef<[u8]>) -> String {
    let path = write(dir, name, contents);
    match load_scene_file(&path) {
        Ok(_) => panic!("{name} loaded"),
        Err(error) => error.to_string(),
    }
}

#[test]
fn bad_files_are_refused_with_their_names() {
    let dir = temp_folder("bad");
    for name in ["gone.gltf", "gone.glb", "gone.obj"] {
        let error = load_scene_file(&dir.join(name)).unwrap_err();
        assert!(matches!(error, SceneError::Io { .. }) && error.to_string().contains(name), "{error}");
    }
    let unknown = load_scene_file(&dir.join("scene.fbx")).unwrap_err().to_string();
    assert!(unknown.contains("scene.fbx") && unknown.contains(".gltf") && unknown.contains(".obj"), "{unknown}");

    let malformed = refused(&dir, "malformed.gltf", "{\"asset\": {\"version\": \"2.0\"}, \"nodes\": [");
    assert!(malformed.contains("malformed.gltf") && malformed.contains("not valid glTF JSON"), "{malformed}");
    let not_glb = refused(&dir, "short.glb", b"glTF\x02\x00\x00\x00");
    assert!(not_glb.contains("short.glb"), "{not_glb}");

    let mut data = GltfData::default();
    let positions = data.positions(&TRIANGLE);
    let lines = json!({"scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"name": "wire", "primitives": [{"attributes": {"POSITION": positions}, "mode": 1}]}]});
    let lines = refused(&dir, "lines.gltf", data.gltf(lines));
    assert!(lines.contains("lines.gltf") && lines.contains("meshes[0].primitives[0].mode"), "{lines}");
    assert!(lines.contains("wire") && lines.contains("only triangle primitives"), "{lines}");

    let dangling = json!({"scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 7}}]}]});
    let dangling = refused(&dir, "dangling.gltf", data.gltf(dangling));
    assert!(dangling.contains("dangling.gltf") && dangling.contains("accessor 7 does not exist"), "{dangling}");

    let mut short = GltfData::default();
    let positions = short.positions(&TRIANGLE);
    short.accessors[positions]["count"] = json!(30);
    let overrun = json!({"scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": positions}}]}]});
    let overrun = refused(&dir, "overrun.gltf", short.gltf(overrun));
    assert!(overrun.contains("overrun.gltf") && overrun.contains("accessors[0]"), "{overrun}");

    let mut nan = GltfData::default();
    let positions = nan.positions(&[[0.0, 0.0, 0.0], [f32::NAN, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    nan.accessors[positions]["min"] = json!([0.0, 0.0, 0.0]);
    nan.accessors[positions]["max"] = json!([1.0, 1.0, 0.0]);
    let document = json!({"scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": positions}}]}]});
    let nan = refused(&dir, "nan.gltf", nan.gltf(document));
    assert!(nan.contains("nan.gltf") && nan.contains("vertex 1") && nan.contains("not finite"), "{nan}");

    let nan = refused(&dir, "nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n");
    assert!(nan.contains("nan.obj") && nan.contains("vertex 1") && nan.contains("not finite"), "{nan}");
    let flat = refused(&dir, "flat.obj", "o line\nv 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n");
    assert!(flat.contains("flat.obj") && flat.contains("every triangle has zero area"), "{flat}");
    let garbage = refused(&dir, "garbage.obj", "v 0 zero 0\n");
    assert!(garbage.contains("garbage.obj"), "{garbage}");
    let empty = refused(&dir, "empty.obj", "# nothing\n");
    assert!(empty.contains("empty.obj") && empty.contains("no triangles"), "{empty}");
    std::fs::remove_dir_all(dir).unwrap();
}
