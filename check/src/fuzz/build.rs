//! Small valid files written in code, the seeds every target starts from without
//! the scene files: binary PLY meshes, PNG textures, RGB EXR images (each compression the
//! `exr` crate writes).

use exr::prelude::{Compression, Encoding, Image, Layer, LayerAttributes, SpecificChannels, WritableImage};

/// A binary little-endian PLY of `vertices` (with `uvs` as `s t` if given) and
/// triangles `faces` (`list uchar int vertex_indices`), as the shared scenes store them.
pub fn ply(vertices: &[[f32; 3]], uvs: Option<&[[f32; 2]]>, faces: &[[i32; 3]]) -> Vec<u8> {
    let uv_properties = if uvs.is_some() { "property float s\nproperty float t\n" } else { "" };
    let mut bytes = format!(
        "ply\nformat binary_little_endian 1.0\ncomment written by the fuzz harness\nelement vertex {}\n\
         property float x\nproperty float y\nproperty float z\n{uv_properties}element face {}\n\
         property list uchar int vertex_indices\nend_header\n",
        vertices.len(),
        faces.len()
    )
    .into_bytes();
    for (index, v) in vertices.iter().enumerate() {
        for c in v {
            bytes.extend(c.to_le_bytes());
        }
        if let Some(uvs) = uvs {
            for c in uvs[index] {
                bytes.extend(c.to_le_bytes());
            }
        }
    }
    for f in faces {
        bytes.push(3);
        for i in f {
            bytes.extend(i.to_le_bytes());
        }
    }
    bytes
}

/// A unit quad in the z = 0 plane with texture coordinates, facing +z.
pub fn quad_ply() -> Vec<u8> {
    let vertices = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
    let uvs = [[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]];
    ply(&vertices, Some(&uvs), &[[0, 1, 2], [0, 2, 3]])
}

/// A unit cube (12 triangles, one of them degenerate as in veach-ajar's meshes: 13 faces).
pub fn cube_ply() -> Vec<u8> {
    let vertices: Vec<[f32; 3]> =
        (0..8).map(|i| [(i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32]).collect();
    let faces = [
        [0, 2, 1],
        [1, 2, 3],
        [4, 5, 6],
        [5, 7, 6],
        [0, 1, 4],
        [1, 5, 4],
        [2, 6, 3],
        [3, 6, 7],
        [0, 4, 2],
        [2, 4, 6],
        [1, 3, 5],
        [3, 7, 5],
        [0, 0, 1],
    ];
    ply(&vertices, None, &faces)
}

/// A PNG of `width` × `height` RGBA pixels.
pub fn png(width: u32, height: u32, rgba: &[u8]) -> Vec<u8> {
    let image = image::RgbaImage::from_raw(width, height, rgba.to_vec()).expect("width × height × 4 bytes");
    let mut bytes = std::io::Cursor::new(Vec::new());
    image.write_to(&mut bytes, image::ImageFormat::Png).expect("PNG into memory");
    bytes.into_inner()
}

/// A 2 × 2 checker texture.
pub fn texture_png() -> Vec<u8> {
    png(2, 2, &[255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 255])
}

/// An RGB float EXR of `width` × `height` pixels from `pixel(x, y)`, with `compression`.
pub fn exr(
    width: usize,
    height: usize,
    compression: Compression,
    pixel: impl Fn(usize, usize) -> [f32; 3] + Sync,
) -> Vec<u8> {
    let channels = SpecificChannels::rgb(|position: exr::math::Vec2<usize>| {
        let [r, g, b] = pixel(position.x(), position.y());
        (r, g, b)
    });
    let encoding = Encoding { compression, ..Encoding::default() };
    let layer = Layer::new((width, height), LayerAttributes::named("rgb"), encoding, channels);
    let mut bytes = std::io::Cursor::new(Vec::new());
    Image::from_layer(layer).write().to_buffered(&mut bytes).expect("EXR into memory");
    bytes.into_inner()
}

/// A small sky: brighter at the top.
pub fn environment_exr(compression: Compression) -> Vec<u8> {
    exr(8, 4, compression, |x, y| [0.1 * x as f32, 1.0 / (1.0 + y as f32), 0.5])
}

/// Every compression the `exr` crate writes.
pub const COMPRESSIONS: [Compression; 6] = [
    Compression::Uncompressed,
    Compression::RLE,
    Compression::ZIP1,
    Compression::ZIP16,
    Compression::PIZ,
    Compression::PXR24,
];

/// The files of `folder` (not recursive) whose names end with `extension` and that are at
/// most `largest` bytes, sorted by name; nothing if the folder is missing.
pub fn files_in(folder: &std::path::Path, extension: &str, largest: u64) -> Vec<Vec<u8>> {
    let Ok(entries) = std::fs::read_dir(folder) else { return Vec::new() };
    let mut paths: Vec<_> = entries
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.extension().and_then(|e| e.to_str()) == Some(extension))
        .filter(|p| std::fs::metadata(p).is_ok_and(|m| m.len() <= largest))
        .collect();
    paths.sort();
    paths.into_iter().filter_map(|p| std::fs::read(p).ok()).collect()
}

/// Standard base64 with padding (the `data:` URIs of glTF buffers and images).
pub fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for chunk in bytes.chunks(3) {
        let n = chunk.iter().enumerate().fold(0u32, |n, (i, &b)| n | u32::from(b) << (16 - 8 * i));
        for i in 0..4 {
            out.push(if i <= chunk.len() { ALPHABET[(n >> (18 - 6 * i) & 63) as usize] as char } else { '=' });
        }
    }
    out
}

/// A small generated environment map (8 x 4 texels of varied colours) at `scale`: the
/// environment light of the glass/metal rooms that the cross-backend check and the
/// unbiasedness tests render.
pub fn generated_environment(scale: f32) -> strata_render::scene::Environment {
    let (width, height) = (8u32, 4u32);
    strata_render::scene::Environment {
        file: "generated".into(),
        width,
        height,
        texels: (0..width * height).map(|i| [0.1 + (i % 5) as f32 * 0.3, 0.5, 0.2 + (i % 3) as f32]).collect(),
        scale,
        to_world: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
    }
}
