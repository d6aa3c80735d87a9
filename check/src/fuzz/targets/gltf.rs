//! `gltf`: glTF 2.0 documents (`.gltf` JSON with `data:` or file buffers, and `.glb`
//! containers) through `load_gltf_from`. Structure-aware mutations change the document's
//! JSON (preferring accessor counts and offsets, buffer view lengths and strides, component
//! types, modes, indices, transforms and material factors), rebuilding a GLB container
//! around a mutated JSON chunk, or change a GLB's length fields and binary chunk.

use super::super::mutate::{EDGE_NUMBERS, FuzzRng};
use super::super::{Outcome, Target, build, json, oracle};
use super::{count, number};
use arbitrary::Unstructured;
use rand::Rng;
use serde_json::{Value, json};
use std::path::Path;
use strata_render::scene::{MemoryFiles, load_gltf_from};

/// Keys whose values the JSON mutations prefer.
const FOCUS: &[&str] = &[
    "count",
    "byteOffset",
    "byteLength",
    "byteStride",
    "componentType",
    "type",
    "bufferView",
    "buffer",
    "indices",
    "mode",
    "POSITION",
    "TEXCOORD_0",
    "TEXCOORD_1",
    "material",
    "mesh",
    "children",
    "nodes",
    "matrix",
    "scale",
    "translation",
    "rotation",
    "camera",
    "yfov",
    "znear",
    "zfar",
    "aspectRatio",
    "emissiveFactor",
    "emissiveStrength",
    "baseColorFactor",
    "metallicFactor",
    "roughnessFactor",
    "index",
    "texCoord",
    "source",
    "uri",
    "sparse",
    "scene",
    "min",
    "max",
];

/// The target, with the external files its seeds name.
pub(super) struct Gltf {
    files: MemoryFiles,
}

/// A glTF buffer with its views and accessors, built up as data is added.
#[derive(Default)]
struct Builder {
    bytes: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Builder {
    /// Adds a view over `data` and an accessor of `count` elements of `kind`/`component`.
    fn add(&mut self, data: &[u8], count: usize, kind: &str, component: u32) -> usize {
        while !self.bytes.len().is_multiple_of(4) {
            self.bytes.push(0);
        }
        self.views.push(json!({"buffer": 0, "byteOffset": self.bytes.len(), "byteLength": data.len()}));
        self.bytes.extend_from_slice(data);
        self.accessors.push(
            json!({"bufferView": self.views.len() - 1, "componentType": component, "count": count, "type": kind}),
        );
        self.accessors.len() - 1
    }

    /// A float accessor, with the `min` and `max` that POSITION accessors need.
    fn floats(&mut self, values: &[f32], width: usize, kind: &str) -> usize {
        let bytes: Vec<u8> = values.iter().flat_map(|c| c.to_le_bytes()).collect();
        let index = self.add(&bytes, values.len() / width, kind, 5126);
        let column = |c: usize| values.iter().skip(c).step_by(width).copied();
        let min: Vec<f32> = (0..width).map(|c| column(c).fold(f32::INFINITY, f32::min)).collect();
        let max: Vec<f32> = (0..width).map(|c| column(c).fold(f32::NEG_INFINITY, f32::max)).collect();
        self.accessors[index]["min"] = json!(min);
        self.accessors[index]["max"] = json!(max);
        index
    }

    fn indices(&mut self, indices: &[u16]) -> usize {
        let bytes: Vec<u8> = indices.iter().flat_map(|c| c.to_le_bytes()).collect();
        self.add(&bytes, indices.len(), "SCALAR", 5123)
    }

    /// A view over raw `data` (an embedded image).
    fn view(&mut self, data: &[u8]) -> usize {
        while !self.bytes.len().is_multiple_of(4) {
            self.bytes.push(0);
        }
        self.views.push(json!({"buffer": 0, "byteOffset": self.bytes.len(), "byteLength": data.len()}));
        self.bytes.extend_from_slice(data);
        self.views.len() - 1
    }

    /// `document` with this buffer as a `data:` URI.
    fn gltf(self, mut document: Value) -> Vec<u8> {
        let uri = format!("data:application/octet-stream;base64,{}", build::base64(&self.bytes));
        document["buffers"] = json!([{"byteLength": self.bytes.len(), "uri": uri}]);
        document["bufferViews"] = Value::Array(self.views);
        document["accessors"] = Value::Array(self.accessors);
        serde_json::to_vec_pretty(&document).expect("JSON")
    }

    /// `document` with this buffer as the binary chunk of a GLB container.
    fn glb(self, mut document: Value) -> Vec<u8> {
        document["buffers"] = json!([{"byteLength": self.bytes.len()}]);
        document["bufferViews"] = Value::Array(self.views);
        document["accessors"] = Value::Array(self.accessors);
        glb(&serde_json::to_vec(&document).expect("JSON"), Some(&self.bytes))
    }
}

/// A GLB container of `json` and an optional binary chunk (chunks padded to 4 bytes).
fn glb(json: &[u8], bin: Option<&[u8]>) -> Vec<u8> {
    let mut json = json.to_vec();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let mut out = Vec::new();
    out.extend(b"glTF");
    out.extend(2u32.to_le_bytes());
    out.extend(0u32.to_le_bytes());
    out.extend((json.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(&json);
    if let Some(bin) = bin {
        let mut bin = bin.to_vec();
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        out.extend((bin.len() as u32).to_le_bytes());
        out.extend(b"BIN\0");
        out.extend(&bin);
    }
    let total = out.len() as u32;
    out[8..12].copy_from_slice(&total.to_le_bytes());
    out
}

/// The JSON and binary chunks of a GLB container, if `input` is one.
fn glb_chunks(input: &[u8]) -> Option<(Vec<u8>, Option<Vec<u8>>)> {
    if !input.starts_with(b"glTF") || input.len() < 20 {
        return None;
    }
    let length = u32::from_le_bytes(input[12..16].try_into().ok()?) as usize;
    let json = input.get(20..20 + length)?.to_vec();
    let rest = &input[20 + length..];
    let bin = (rest.len() >= 8).then(|| {
        let length = u32::from_le_bytes(rest[0..4].try_into().expect("4 bytes")) as usize;
        rest[8..].get(..length).unwrap_or(&rest[8..]).to_vec()
    });
    Some((json, bin))
}

/// The seed documents: a triangle; an indexed, textured quad seen by a camera; a node
/// hierarchy with a mirrored instance, a strip and a fan, emission and a metal; an
/// external buffer and image; a sparse accessor.
fn documents() -> Vec<Vec<u8>> {
    let mut seeds = Vec::new();
    let triangle = || {
        let mut b = Builder::default();
        let p = b.floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0], 3, "VEC3");
        let document = json!({
            "asset": {"version": "2.0"},
            "meshes": [{"primitives": [{"attributes": {"POSITION": p}}]}],
            "nodes": [{"mesh": 0}],
            "scenes": [{"nodes": [0]}],
            "scene": 0
        });
        (b, document)
    };
    let (b, d) = triangle();
    seeds.push(b.gltf(d));
    let (b, d) = triangle();
    seeds.push(b.glb(d));

    let textured = || {
        let mut b = Builder::default();
        let p = b.floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0], 3, "VEC3");
        let t = b.floats(&[0.0, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0], 2, "VEC2");
        let i = b.indices(&[0, 1, 2, 0, 2, 3]);
        let image = b.view(&build::texture_png());
        let document = json!({
            "asset": {"version": "2.0"},
            "meshes": [{"name": "quad", "primitives": [{"attributes": {"POSITION": p, "TEXCOORD_0": t}, "indices": i, "material": 0}]}],
            "materials": [{"name": "painted", "doubleSided": true, "pbrMetallicRoughness": {
                "baseColorFactor": [1.0, 0.8, 0.6, 1.0], "metallicFactor": 0.0,
                "baseColorTexture": {"index": 0, "texCoord": 0}}}],
            "textures": [{"source": 0, "sampler": 0}],
            "samplers": [{}],
            "images": [{"bufferView": image, "mimeType": "image/png"}],
            "cameras": [{"type": "perspective", "perspective": {"yfov": 0.7, "aspectRatio": 1.5, "znear": 0.1, "zfar": 100.0}}],
            "nodes": [{"mesh": 0}, {"camera": 0, "translation": [0.5, 0.5, 3.0]}],
            "scenes": [{"nodes": [0, 1]}]
        });
        (b, document)
    };
    let (b, d) = textured();
    seeds.push(b.gltf(d));
    let (b, d) = textured();
    seeds.push(b.glb(d));

    let mut b = Builder::default();
    let p = b.floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 0.0, 2.0, 0.0], 3, "VEC3");
    let strip = b.indices(&[0, 1, 2, 3, 4]);
    let fan = b.indices(&[0, 1, 3, 2]);
    let list = b.indices(&[0, 1, 2, 2, 1, 3]);
    let document = json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_materials_emissive_strength"],
        "meshes": [{"primitives": [{"attributes": {"POSITION": p}, "indices": strip, "mode": 5, "material": 0},
                                   {"attributes": {"POSITION": p}, "indices": fan, "mode": 6, "material": 1},
                                   {"attributes": {"POSITION": p}, "indices": list}]}],
        "materials": [
            {"emissiveFactor": [1.0, 0.5, 0.25], "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4.0}}},
            {"pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.6, 0.3, 1.0], "metallicFactor": 1.0, "roughnessFactor": 0.3}}
        ],
        "nodes": [
            {"children": [1, 2], "matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, -2, 1]},
            {"mesh": 0, "scale": [-1, 1, 1], "rotation": [0, std::f32::consts::FRAC_1_SQRT_2, 0, std::f32::consts::FRAC_1_SQRT_2]},
            {"mesh": 0, "translation": [3, 0, 0]}
        ]
    });
    seeds.push(b.gltf(document));

    // External buffer and image files, and a sparse accessor over the positions.
    let mut b = Builder::default();
    let p = b.floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0], 3, "VEC3");
    let sparse_indices = b.view(&[2u8, 0, 0, 0]);
    let sparse_values = b.view(&[0, 0, 0, 0, 0, 0, 0, 64, 0, 0, 0, 0]);
    let mut accessors = b.accessors.clone();
    accessors[p]["sparse"] = json!({"count": 1, "indices": {"bufferView": sparse_indices, "componentType": 5125},
                                    "values": {"bufferView": sparse_values}});
    let document = json!({
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": b.bytes.len(), "uri": "buffer%20data.bin"}],
        "bufferViews": b.views,
        "accessors": accessors,
        "meshes": [{"primitives": [{"attributes": {"POSITION": p}, "material": 0}]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
        "textures": [{"source": 0}],
        "images": [{"uri": "tex.png"}],
        "nodes": [{"mesh": 0}]
    });
    seeds.push(serde_json::to_vec(&document).expect("JSON"));
    seeds
}

impl Gltf {
    pub(super) fn new() -> Gltf {
        // The external buffer of the last seed: the same positions and sparse data.
        let mut files = MemoryFiles::default();
        let mut bytes: Vec<u8> =
            [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0].iter().flat_map(|c| c.to_le_bytes()).collect();
        bytes.extend([2u8, 0, 0, 0]);
        bytes.extend([0, 0, 0, 0, 0, 0, 0, 64, 0, 0, 0, 0]);
        files.insert("scene/buffer data.bin", bytes);
        files.by_extension.insert("png".into(), build::texture_png());
        files.by_extension.insert("bin".into(), vec![0; 64]);
        Gltf { files }
    }
}

impl Target for Gltf {
    fn name(&self) -> &'static str {
        "gltf"
    }

    fn seeds(&self, _shared: Option<&Path>) -> Vec<Vec<u8>> {
        documents()
    }

    fn generate(&self, u: &mut Unstructured) -> arbitrary::Result<Vec<u8>> {
        // A document over a fixed buffer of 64 bytes whose accessors, views and
        // primitives are chosen by `u`.
        let buffer: Vec<u8> = (0..64).map(|i| if i % 4 == 3 { 0x3f } else { i as u8 }).collect();
        let mut views = Vec::new();
        for _ in 0..u.int_in_range(1..=3)? {
            views.push(format!(
                r#"{{"buffer": {}, "byteOffset": {}, "byteLength": {}{}}}"#,
                u.choose(&["0", "0", "1", "-1"])?,
                count(u)?,
                u.choose(&["64", "12", "36", "0", "65", "4294967295"])?,
                if u.ratio(1, 4)? { format!(r#", "byteStride": {}"#, count(u)?) } else { String::new() }
            ));
        }
        let mut accessors = Vec::new();
        for _ in 0..u.int_in_range(1..=3)? {
            accessors.push(format!(
                r#"{{"bufferView": {}, "byteOffset": {}, "componentType": {}, "count": {}, "type": "{}", "min": [0, 0, 0], "max": [1, 1, 1]}}"#,
                u.int_in_range(0..=3)?,
                count(u)?,
                u.choose(&["5126", "5125", "5123", "5121", "5120", "5122", "0"])?,
                count(u)?,
                u.choose(&["VEC3", "VEC2", "SCALAR", "MAT4", "VEC4"])?
            ));
        }
        let mode = u.choose(&["0", "1", "3", "4", "5", "6", "7"])?;
        let indices =
            if u.arbitrary()? { format!(r#", "indices": {}"#, u.int_in_range(0..=3)?) } else { String::new() };
        let matrix: Vec<String> = (0..16).map(|_| number(u)).collect::<arbitrary::Result<_>>()?;
        let transform = match u.int_in_range(0..=3)? {
            0 => format!(r#", "matrix": [{}]"#, matrix.join(", ")),
            1 => format!(r#", "scale": [{}, {}, {}]"#, number(u)?, number(u)?, number(u)?),
            2 => format!(r#", "rotation": [{}, {}, {}, {}]"#, number(u)?, number(u)?, number(u)?, number(u)?),
            _ => String::new(),
        };
        let factor = |u: &mut Unstructured| -> arbitrary::Result<String> {
            Ok(format!("[{}, {}, {}]", number(u)?, number(u)?, number(u)?))
        };
        let document = format!(
            r#"{{"asset": {{"version": "2.0"}},
 "buffers": [{{"byteLength": 64, "uri": "data:application/octet-stream;base64,{}"}}],
 "bufferViews": [{}], "accessors": [{}],
 "materials": [{{"emissiveFactor": {}, "pbrMetallicRoughness": {{"metallicFactor": {}, "roughnessFactor": {}}}}}],
 "meshes": [{{"primitives": [{{"attributes": {{"POSITION": {}}}{indices}, "mode": {mode}, "material": 0}}]}}],
 "cameras": [{{"type": "perspective", "perspective": {{"yfov": {}, "znear": {}, "zfar": {}}}}}],
 "nodes": [{{"mesh": 0{transform}}}, {{"camera": 0, "translation": [0, 0, {}]}}]}}"#,
            build::base64(&buffer),
            views.join(", "),
            accessors.join(", "),
            factor(u)?,
            number(u)?,
            number(u)?,
            u.int_in_range(0..=3)?,
            number(u)?,
            number(u)?,
            number(u)?,
            u.choose(EDGE_NUMBERS)?,
        );
        Ok(if u.arbitrary()? { glb(document.as_bytes(), Some(&buffer)) } else { document.into_bytes() })
    }

    fn mutate(&self, rng: &mut FuzzRng, input: &[u8]) -> Option<Vec<u8>> {
        match glb_chunks(input) {
            Some((json_chunk, bin)) => match rng.random_range(0..4) {
                0 | 1 => {
                    let mutated = json::mutate_json(rng, &json_chunk, FOCUS)?;
                    Some(glb(&mutated, bin.as_deref()))
                }
                2 => {
                    // A length field of the container set to an edge value.
                    let mut out = input.to_vec();
                    let fields: Vec<usize> =
                        [8, 12, 20 + json_chunk.len()].into_iter().filter(|&f| f + 4 <= out.len()).collect();
                    let at = fields[rng.random_range(0..fields.len())];
                    let value = [0u32, 1, 4, u32::MAX, 0x7fff_ffff, out.len() as u32 + 4][rng.random_range(0..6)];
                    out[at..at + 4].copy_from_slice(&value.to_le_bytes());
                    Some(out)
                }
                _ => {
                    // The binary chunk's floats and indices.
                    let mut bin = bin?;
                    if bin.len() < 4 {
                        return None;
                    }
                    let at = 4 * rng.random_range(0..bin.len() / 4);
                    let value = [f32::NAN.to_bits(), f32::INFINITY.to_bits(), u32::MAX, 0x8000, 1e30f32.to_bits()]
                        [rng.random_range(0..5)];
                    bin[at..at + 4].copy_from_slice(&value.to_le_bytes());
                    Some(glb(&json_chunk, Some(&bin)))
                }
            },
            None => json::mutate_json(rng, input, FOCUS),
        }
    }

    fn execute(&self, input: &[u8]) -> Outcome {
        let name = if input.starts_with(b"glTF") { "scene/fuzz.glb" } else { "scene/fuzz.gltf" };
        match load_gltf_from(Path::new(name), input, &self.files) {
            Ok(scene) => match oracle::check_scene(&scene) {
                Ok(()) => Outcome::Accepted,
                Err(problem) => Outcome::Bug(problem),
            },
            Err(error) => Outcome::Refused(error.to_string()),
        }
    }
}
