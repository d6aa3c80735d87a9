//! Checks of a glTF file made before the `gltf` crate reads it, so that malformed input
//! is an error naming the field instead of a panic or a huge allocation inside the crate:
//! the GLB header, the raw JSON's position accessors, every accessor's declared size
//! against its buffer view, and the crate's own document errors turned into messages
//! that name the glTF field. Found by the loaders' fuzzer (RELIABILITY.md).

use super::SceneError;
use gltf::Document;
use std::path::Path;

/// A glTF error: `field` is the JSON path of the problem.
pub(super) fn json_error(path: &Path, field: impl Into<String>, message: impl Into<String>) -> SceneError {
    SceneError::Json { path: path.into(), field: field.into(), message: message.into() }
}

/// Refuses an accessor whose declared elements cannot fit in its buffer view (before any
/// of them is read or allocated): `count` elements of `stride` bytes from `byteOffset` must
/// end within the view. Sparse accessors' index and value views are checked the same way.
pub(super) fn check_accessor_sizes(path: &Path, document: &Document) -> Result<(), SceneError> {
    for accessor in document.accessors() {
        let field = format!("accessors[{}]", accessor.index());
        let fits = |view: &gltf::buffer::View, offset: usize, count: usize, element: usize| {
            let stride = view.stride().unwrap_or(element).max(element);
            let needed = match count {
                0 => Some(0),
                n => {
                    (n - 1).checked_mul(stride).and_then(|b| b.checked_add(element)).and_then(|b| b.checked_add(offset))
                }
            };
            needed.is_some_and(|needed| needed <= view.length())
        };
        if let Some(view) = accessor.view()
            && !fits(&view, accessor.offset(), accessor.count(), accessor.size())
        {
            return Err(json_error(
                path,
                field,
                format!(
                    "{} elements of {} bytes from byte {} do not fit in bufferViews[{}] ({} bytes)",
                    accessor.count(),
                    accessor.size(),
                    accessor.offset(),
                    view.index(),
                    view.length()
                ),
            ));
        }
        if let Some(sparse) = accessor.sparse() {
            let (indices, values) = (sparse.indices(), sparse.values());
            let index_size = indices.index_type().size();
            if sparse.count() > accessor.count()
                || !fits(&indices.view(), indices.offset(), sparse.count(), index_size)
                || !fits(&values.view(), values.offset(), sparse.count(), accessor.size())
            {
                return Err(json_error(
                    path,
                    format!("{field}.sparse"),
                    format!(
                        "{} sparse elements do not fit in the accessor ({} elements) or in their buffer views",
                        sparse.count(),
                        accessor.count()
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Refuses a GLB whose header declares a total length shorter than the header itself or
/// longer than the file (which the `gltf` crate subtracts without checking).
pub(super) fn check_glb_header(path: &Path, bytes: &[u8]) -> Result<(), SceneError> {
    if !bytes.starts_with(b"glTF") {
        return Ok(());
    }
    let field = |at: usize| bytes.get(at..at + 4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize);
    let (Some(length), Some(_version)) = (field(8), field(4)) else {
        return Err(json_error(path, "(GLB container)", "not a valid GLB file: the header is cut short"));
    };
    if !(12..=bytes.len()).contains(&length) {
        return Err(json_error(
            path,
            "(GLB container)",
            format!("not a valid GLB file: the header declares {length} bytes, the file has {}", bytes.len()),
        ));
    }
    Ok(())
}

/// The error of a document the `gltf` crate refuses.
pub(super) fn document_error(path: &Path, error: gltf::Error) -> SceneError {
    match error {
        gltf::Error::Validation(problems) => {
            let more = match problems.len() {
                0 | 1 => String::new(),
                n => format!(" (and {} more problems)", n - 1),
            };
            match problems.first() {
                Some((field, problem)) => json_error(path, field.to_string(), format!("{problem}{more}")),
                None => json_error(path, "(document)", "invalid glTF"),
            }
        }
        gltf::Error::Deserialize(e) => json_error(path, "(document)", format!("not valid glTF JSON: {e}")),
        gltf::Error::Binary(e) => json_error(path, "(GLB container)", format!("not a valid GLB file: {e}")),
        other => json_error(path, "(document)", other.to_string()),
    }
}

/// The document's JSON as plain values (for the extensions the `gltf` crate drops, and
/// for the checks made before the crate validates the document); `Null` if the container
/// is not a GLB the crate can split (it then refuses the file itself), an error if the JSON
/// cannot be read as plain values (nested deeper than 128 levels: the crate skips unknown
/// fields without that limit, so its validation could not be guarded).
pub(super) fn raw_json(bytes: &[u8]) -> Result<serde_json::Value, String> {
    let json = if bytes.starts_with(b"glTF") {
        match gltf::Glb::from_slice(bytes) {
            Ok(glb) => glb.json.into_owned(),
            Err(_) => return Ok(serde_json::Value::Null),
        }
    } else {
        bytes.to_vec()
    };
    serde_json::from_slice(&json).map_err(|e| format!("not valid glTF JSON: {e}"))
}

/// Refuses a POSITION attribute naming an accessor that does not exist, which the `gltf`
/// crate's validation indexes without checking (a panic).
pub(super) fn check_position_accessors(path: &Path, raw: &serde_json::Value) -> Result<(), SceneError> {
    let accessors = raw.get("accessors").and_then(serde_json::Value::as_array).map_or(0, Vec::len);
    let meshes = raw.get("meshes").and_then(serde_json::Value::as_array).into_iter().flatten();
    for (m, mesh) in meshes.enumerate() {
        let primitives = mesh.get("primitives").and_then(serde_json::Value::as_array).into_iter().flatten();
        for (p, primitive) in primitives.enumerate() {
            let index = primitive.pointer("/attributes/POSITION").and_then(serde_json::Value::as_u64);
            if let Some(index) = index.filter(|&i| i >= accessors as u64) {
                return Err(json_error(
                    path,
                    format!("meshes[{m}].primitives[{p}].attributes.POSITION"),
                    format!("accessor {index} does not exist (the file has {accessors})"),
                ));
            }
        }
    }
    Ok(())
}
