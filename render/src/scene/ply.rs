//! Binary little-endian PLY meshes as the shared scenes store them (CONVENTIONS.md
//! "Geometry"): vertices with float `x y z` and optional `s t`, faces as
//! `list uchar int vertex_indices`, triangles only. Other scalar property types are
//! read and ignored; ASCII and big-endian files are refused with a clear error.
//!
//! A header that declares more elements than the rest of the file can hold (each element
//! needs at least the bytes of its scalar properties and list counts) is refused before
//! anything is read; so are non-finite positions and texture coordinates, and face indices
//! that are not whole numbers within the vertex list.

use super::SceneError;
use std::path::{Path, PathBuf};

/// A triangle mesh read from a PLY file.
#[derive(Clone, Debug, PartialEq)]
pub struct PlyMesh {
    /// Vertex positions.
    pub positions: Vec<[f32; 3]>,
    /// Texture coordinates (`s t`), if present.
    pub uvs: Option<Vec<[f32; 2]>>,
    /// Triangles as vertex indices.
    pub faces: Vec<[u32; 3]>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(name: &str) -> Option<Scalar> {
        Some(match name {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    /// The value at the start of `bytes` as f64 (ints exactly).
    fn read(self, bytes: &[u8]) -> f64 {
        match self {
            Scalar::I8 => f64::from(bytes[0] as i8),
            Scalar::U8 => f64::from(bytes[0]),
            Scalar::I16 => f64::from(i16::from_le_bytes([bytes[0], bytes[1]])),
            Scalar::U16 => f64::from(u16::from_le_bytes([bytes[0], bytes[1]])),
            Scalar::I32 => f64::from(i32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]])),
            Scalar::U32 => f64::from(u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]])),
            Scalar::F32 => f64::from(f32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]])),
            Scalar::F64 => f64::from_le_bytes(bytes[..8].try_into().expect("8 bytes")),
        }
    }
}

enum Property {
    Scalar(String, Scalar),
    List(String, Scalar, Scalar),
}

struct Element {
    name: String,
    count: usize,
    properties: Vec<Property>,
}

/// A word of a PLY header as an error may quote it: at most 24 characters, anything but
/// printable ASCII shown as `?` (a header is the file's first bytes, whatever the file).
fn quoted_token(word: &str) -> String {
    const MOST: usize = 24;
    let mut quoted: String = word.chars().take(MOST).map(|c| if c.is_ascii_graphic() { c } else { '?' }).collect();
    if word.chars().count() > MOST {
        quoted.push_str("...");
    }
    quoted
}

fn ply_error(path: &Path, element: impl Into<String>, message: impl Into<String>) -> SceneError {
    SceneError::Ply { path: PathBuf::from(path), element: element.into(), message: message.into() }
}

/// Where the body of a PLY file starts: just after the first `end_header` line's line
/// break (`\n` or `\r\n`).
fn header_end(bytes: &[u8]) -> Option<usize> {
    const KEYWORD: &[u8] = b"end_header";
    let mut from = 0;
    while let Some(found) = bytes[from..].windows(KEYWORD.len()).position(|w| w == KEYWORD) {
        let after = from + found + KEYWORD.len();
        match &bytes[after..] {
            [b'\n', ..] => return Some(after + 1),
            [b'\r', b'\n', ..] => return Some(after + 2),
            _ => from = after,
        }
    }
    None
}

/// Reads a binary little-endian PLY triangle mesh from the file `path`.
pub fn read_ply(path: &Path) -> Result<PlyMesh, SceneError> {
    let bytes = crate::scene::read_capped(path).map_err(|source| SceneError::Io { path: path.into(), source })?;
    parse_ply(path, &bytes)
}

/// Reads the binary little-endian PLY triangle mesh in `bytes` (`path` names it in errors).
///
/// The header is text: a leading byte order mark is dropped
/// ([`super::without_bom`]) and its lines may end in `\n` or `\r\n` (the body starts
/// after the line break that ends `end_header`).
pub fn parse_ply(path: &Path, bytes: &[u8]) -> Result<PlyMesh, SceneError> {
    let bytes = super::without_bom(bytes);
    let header_end = header_end(bytes).ok_or_else(|| {
        ply_error(path, "header", "no `end_header` line (ending in a line feed, or a carriage return and line feed)")
    })?;
    let header = std::str::from_utf8(&bytes[..header_end]).map_err(|_| ply_error(path, "header", "not text"))?;
    let mut lines = header.lines();
    if lines.next() != Some("ply") {
        return Err(ply_error(path, "header line 1", "not a PLY file (first line is not `ply`)"));
    }
    let mut elements: Vec<Element> = Vec::new();
    for (number, line) in lines.enumerate() {
        let words: Vec<&str> = line.split_whitespace().collect();
        let at = format!("header line {}", number + 2);
        match words.as_slice() {
            ["format", "binary_little_endian", _] => {}
            ["format", other, _] => {
                return Err(ply_error(
                    path,
                    at,
                    format!("format `{}` is not supported (binary_little_endian only)", quoted_token(other)),
                ));
            }
            ["comment", ..] | ["obj_info", ..] | ["end_header"] | [] => {}
            ["element", name, count] => elements.push(Element {
                name: name.to_string(),
                count: count
                    .parse()
                    .map_err(|_| ply_error(path, &at, format!("bad element count `{}`", quoted_token(count))))?,
                properties: Vec::new(),
            }),
            ["property", "list", count, item, name] => {
                let (Some(count), Some(item)) = (Scalar::parse(count), Scalar::parse(item)) else {
                    return Err(ply_error(
                        path,
                        at,
                        format!("unknown list types `{} {}`", quoted_token(count), quoted_token(item)),
                    ));
                };
                let element = elements.last_mut().ok_or_else(|| ply_error(path, &at, "property before any element"))?;
                element.properties.push(Property::List(name.to_string(), count, item));
            }
            ["property", kind, name] => {
                let kind = Scalar::parse(kind)
                    .ok_or_else(|| ply_error(path, &at, format!("unknown type `{}`", quoted_token(kind))))?;
                let element = elements.last_mut().ok_or_else(|| ply_error(path, &at, "property before any element"))?;
                element.properties.push(Property::Scalar(name.to_string(), kind));
            }
            // The line is not quoted: a scene may name any file as its mesh, and an error
            // must not print what that file holds (SECURITY.md); its number finds it.
            _ => {
                return Err(ply_error(
                    path,
                    at,
                    format!(
                        "cannot read this line of {} words (expected format, element, property, comment or end_header)",
                        words.len()
                    ),
                ));
            }
        }
    }
    let mut offset = header_end;
    let mut mesh = PlyMesh { positions: Vec::new(), uvs: None, faces: Vec::new() };
    let truncated = |what: String| ply_error(path, what, "the file ends early (truncated)");
    for element in &elements {
        // The fewest bytes one element takes: its scalars and its lists' counts.
        let smallest: usize = element
            .properties
            .iter()
            .map(|p| match p {
                Property::Scalar(_, kind) | Property::List(_, kind, _) => kind.size(),
            })
            .sum();
        let remaining = bytes.len() - offset;
        if smallest == 0 {
            if element.count > 0 && (element.name == "vertex" || element.name == "face") {
                return Err(ply_error(path, format!("element {}", element.name), "the element has no properties"));
            }
            continue;
        }
        if element.count.checked_mul(smallest).is_none_or(|needed| needed > remaining) {
            return Err(ply_error(
                path,
                format!("element {}", element.name),
                format!(
                    "the header declares {} elements of at least {smallest} bytes, but only {remaining} bytes follow",
                    element.count
                ),
            ));
        }
        for index in 0..element.count {
            let mut values: Vec<(&str, f64)> = Vec::new();
            let mut list: Vec<f64> = Vec::new();
            for property in &element.properties {
                match property {
                    Property::Scalar(name, kind) => {
                        let end = offset + kind.size();
                        let slice =
                            bytes.get(offset..end).ok_or_else(|| truncated(format!("{} {index}", element.name)))?;
                        values.push((name, kind.read(slice)));
                        offset = end;
                    }
                    Property::List(name, count, item) => {
                        let keep = name == "vertex_indices" || name == "vertex_index";
                        let slice = bytes
                            .get(offset..offset + count.size())
                            .ok_or_else(|| truncated(format!("{} {index}", element.name)))?;
                        let n = count.read(slice) as usize;
                        offset += count.size();
                        for _ in 0..n {
                            let slice = bytes
                                .get(offset..offset + item.size())
                                .ok_or_else(|| truncated(format!("{} {index}", element.name)))?;
                            if keep {
                                list.push(item.read(slice));
                            }
                            offset += item.size();
                        }
                    }
                }
            }
            let get = |name: &str| values.iter().find(|(n, _)| *n == name).map(|(_, v)| *v);
            match element.name.as_str() {
                "vertex" => {
                    let (Some(x), Some(y), Some(z)) = (get("x"), get("y"), get("z")) else {
                        return Err(ply_error(path, "vertex properties", "vertices need x, y and z"));
                    };
                    let position = [x as f32, y as f32, z as f32];
                    if position.iter().any(|c| !c.is_finite()) {
                        return Err(ply_error(
                            path,
                            format!("vertex {index}"),
                            format!("coordinate is not finite: {position:?}"),
                        ));
                    }
                    mesh.positions.push(position);
                    if let (Some(s), Some(t)) = (get("s").or(get("u")), get("t").or(get("v"))) {
                        let uv = [s as f32, t as f32];
                        if uv.iter().any(|c| !c.is_finite()) {
                            return Err(ply_error(
                                path,
                                format!("vertex {index}"),
                                format!("texture coordinate is not finite: {uv:?}"),
                            ));
                        }
                        mesh.uvs.get_or_insert_with(Vec::new).push(uv);
                    }
                }
                "face" => {
                    if list.len() != 3 {
                        return Err(ply_error(
                            path,
                            format!("face {index}"),
                            format!("{} vertices: only triangles are supported", list.len()),
                        ));
                    }
                    let face = [list[0], list[1], list[2]];
                    let outside = |i: f64| !(i >= 0.0 && i.fract() == 0.0 && i < mesh.positions.len() as f64);
                    if let Some(bad) = face.iter().find(|&&i| outside(i)) {
                        return Err(ply_error(
                            path,
                            format!("face {index}"),
                            format!("vertex index {bad} out of range (the mesh has {} vertices)", mesh.positions.len()),
                        ));
                    }
                    mesh.faces.push(face.map(|i| i as u32));
                }
                _ => {}
            }
        }
    }
    if mesh.uvs.as_ref().is_some_and(|uvs| uvs.len() != mesh.positions.len()) {
        return Err(ply_error(path, "vertex properties", "only some vertices have texture coordinates"));
    }
    if mesh.faces.is_empty() {
        return Err(ply_error(path, "faces", "the mesh has no triangles"));
    }
    Ok(mesh)
}

/// A triangle as its three corners.
pub type TriangleCorners = [[f32; 3]; 3];
/// Texture coordinates at a triangle's three corners.
pub type CornerUvs = [[f32; 2]; 3];

impl PlyMesh {
    /// The triangles (and their corner UVs) without the zero-area ones, and how many
    /// were dropped.
    pub fn triangles_without_degenerate(&self) -> (Vec<TriangleCorners>, Option<Vec<CornerUvs>>, usize) {
        let mut triangles = Vec::with_capacity(self.faces.len());
        let mut uvs = self.uvs.as_ref().map(|_| Vec::with_capacity(self.faces.len()));
        let mut dropped = 0;
        for face in &self.faces {
            let [a, b, c] = face.map(|i| self.positions[i as usize]);
            let (u, v) = ([b[0] - a[0], b[1] - a[1], b[2] - a[2]], [c[0] - a[0], c[1] - a[1], c[2] - a[2]]);
            let cross = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
            if cross.iter().all(|&x| x == 0.0) {
                dropped += 1;
                continue;
            }
            triangles.push([a, b, c]);
            if let (Some(out), Some(source)) = (uvs.as_mut(), self.uvs.as_ref()) {
                out.push(face.map(|i| source[i as usize]));
            }
        }
        (triangles, uvs, dropped)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Security finding 9: a scene may name any file as its mesh; an error about that
    /// file's header must not print the file's text (once it printed the whole line).
    #[test]
    fn header_errors_do_not_quote_the_files_text() {
        let secret = b"ply\nformat binary_little_endian 1.0\npassword=hunter2 and more\nend_header\n";
        let message = parse_ply(Path::new("mesh.ply"), secret).unwrap_err().to_string();
        assert!(!message.contains("hunter2"), "{message}");
        assert!(message.contains("mesh.ply") && message.contains("header line 3"), "{message}");
        let long = format!("ply\nformat {} 1.0\nend_header\n", "s".repeat(200));
        let message = parse_ply(Path::new("mesh.ply"), long.as_bytes()).unwrap_err().to_string();
        assert!(message.len() < 200 && message.contains("..."), "{message}");
    }

    /// One triangle, its header lines ended by `newline`, after `prefix`.
    fn triangle(prefix: &[u8], newline: &str) -> Vec<u8> {
        let header = [
            "ply",
            "format binary_little_endian 1.0",
            "element vertex 3",
            "property float x",
            "property float y",
            "property float z",
            "element face 1",
            "property list uchar int vertex_indices",
            "end_header",
            "",
        ]
        .join(newline);
        let mut bytes = [prefix, header.as_bytes()].concat();
        for value in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
            bytes.extend(value.to_le_bytes());
        }
        bytes.push(3);
        for index in [0i32, 1, 2] {
            bytes.extend(index.to_le_bytes());
        }
        bytes
    }

    #[test]
    fn crlf_headers_and_a_byte_order_mark_read_the_same() {
        let path = Path::new("mesh.ply");
        let plain = parse_ply(path, &triangle(b"", "\n")).unwrap();
        assert_eq!(plain.faces, [[0, 1, 2]]);
        // The body starts after `end_header\r\n`: a byte off and every number would shift.
        assert_eq!(parse_ply(path, &triangle(b"", "\r\n")).unwrap(), plain);
        assert_eq!(parse_ply(path, &triangle(super::super::UTF8_BOM, "\r\n")).unwrap(), plain);
        // `end_header` without a line break after it is no header's end.
        let cut = triangle(b"", "\n");
        let end = cut.windows(10).position(|w| w == b"end_header").unwrap() + 10;
        let message = parse_ply(path, &cut[..end]).unwrap_err().to_string();
        assert!(message.contains("no `end_header` line"), "{message}");
    }
}
