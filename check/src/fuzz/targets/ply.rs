//! `ply`: binary little-endian PLY meshes through `parse_ply`, then
//! `triangles_without_degenerate` as the scene loader calls it. Structure-aware
//! mutations change the header (element counts to 0, ±1, huge or negative; property
//! types; list count and item types; the format line) or the body's numbers (a
//! coordinate to NaN or infinity, an index to −1 or 2³¹).

use super::super::mutate::{FuzzRng, line_spans, number_replacement};
use super::super::{Outcome, Target, build};
use super::count;
use arbitrary::Unstructured;
use rand::Rng;
use std::path::Path;
use strata_render::scene::parse_ply;

/// The target.
pub(super) struct Ply;

/// Scalar type names a PLY header may use.
const TYPES: &[&str] =
    &["char", "uchar", "short", "ushort", "int", "uint", "float", "double", "int8", "uint8", "float64", "long", ""];

/// Where the header ends (just past `end_header\n`).
fn header_end(input: &[u8]) -> Option<usize> {
    input.windows(11).position(|w| w == b"end_header\n").map(|p| p + 11)
}

impl Target for Ply {
    fn name(&self) -> &'static str {
        "ply"
    }

    fn seeds(&self, shared: Option<&Path>) -> Vec<Vec<u8>> {
        let mut seeds = vec![build::quad_ply(), build::cube_ply()];
        // Every scalar type, an unknown element and an ignored list, as other exporters write.
        let mut odd = b"ply\nformat binary_little_endian 1.0\nobj_info odd\nelement vertex 3\nproperty double x\n\
property double y\nproperty double z\nproperty uchar red\nproperty short s16\nproperty ushort u16\n\
property uint u32\nproperty char i8\nproperty float u\nproperty float v\nelement face 1\n\
property list uint uint vertex_index\nproperty list uchar float extra\nelement material 1\nproperty int id\nend_header\n"
            .to_vec();
        for v in [[0.0f64, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
            for c in v {
                odd.extend(c.to_le_bytes());
            }
            odd.extend([7u8]);
            odd.extend((-3i16).to_le_bytes());
            odd.extend(9u16.to_le_bytes());
            odd.extend(11u32.to_le_bytes());
            odd.extend([0xffu8]);
            odd.extend(0.5f32.to_le_bytes());
            odd.extend(0.25f32.to_le_bytes());
        }
        odd.extend(3u32.to_le_bytes());
        for i in [0u32, 1, 2] {
            odd.extend(i.to_le_bytes());
        }
        odd.extend([1u8]);
        odd.extend(1.0f32.to_le_bytes());
        odd.extend(42i32.to_le_bytes());
        seeds.push(odd);
        if let Some(shared) = shared {
            for name in ["cornell-box", "matpreview", "veach-ajar", "objects-grid"] {
                seeds.extend(build::files_in(&shared.join(name).join("meshes"), "ply", 24 << 10));
            }
        }
        seeds
    }

    fn generate(&self, u: &mut Unstructured) -> arbitrary::Result<Vec<u8>> {
        let mut header = String::from("ply\n");
        header += u.choose(&[
            "format binary_little_endian 1.0\n",
            "format binary_little_endian 1.0\n",
            "format ascii 1.0\n",
            "format binary_big_endian 1.0\n",
            "",
        ])?;
        for _ in 0..u.int_in_range(0..=3)? {
            let name = u.choose(&["vertex", "face", "edge", "vertex", "face"])?;
            header += &format!("element {name} {}\n", count(u)?);
            for _ in 0..u.int_in_range(0..=4)? {
                if u.ratio(1, 4)? {
                    let list = u.choose(&["vertex_indices", "vertex_index", "other"])?;
                    header += &format!("property list {} {} {list}\n", u.choose(TYPES)?, u.choose(TYPES)?);
                } else {
                    let property = u.choose(&["x", "y", "z", "s", "t", "u", "v", "nx", "red"])?;
                    header += &format!("property {} {property}\n", u.choose(TYPES)?);
                }
            }
        }
        header += "end_header\n";
        let mut bytes = header.into_bytes();
        let length = u.int_in_range(0..=512)?;
        let body: &[u8] = u.bytes(length)?;
        bytes.extend_from_slice(body);
        Ok(bytes)
    }

    fn mutate(&self, rng: &mut FuzzRng, input: &[u8]) -> Option<Vec<u8>> {
        let end = header_end(input)?;
        let mut out = input.to_vec();
        if rng.random_bool(0.6) {
            // The header: one line changed.
            let lines: Vec<(usize, usize)> = line_spans(&input[..end]);
            let (start, stop) = lines[rng.random_range(0..lines.len())];
            let line = String::from_utf8_lossy(&input[start..stop]).into_owned();
            let words: Vec<&str> = line.split_whitespace().collect();
            let replacement = match words.as_slice() {
                ["element", name, old] => {
                    let new = match rng.random_range(0..3) {
                        0 => number_replacement(rng, old.as_bytes()),
                        1 => {
                            ["0", "-1", "4294967296", "18446744073709551615", "99999999"][rng.random_range(0..5)].into()
                        }
                        _ => old.parse::<u64>().map_or("1".into(), |n| n.saturating_add(1).to_string()),
                    };
                    format!("element {name} {new}")
                }
                ["property", "list", _, _, name] => format!(
                    "property list {} {} {name}",
                    TYPES[rng.random_range(0..TYPES.len())],
                    TYPES[rng.random_range(0..TYPES.len())]
                ),
                ["property", _, name] => format!("property {} {name}", TYPES[rng.random_range(0..TYPES.len())]),
                ["format", ..] => ["format ascii 1.0", "format binary_big_endian 1.0", "format binary_little_endian 2"]
                    [rng.random_range(0..3)]
                .into(),
                _ => format!("element vertex {}", rng.random_range(0..5)),
            };
            out.splice(start..stop, replacement.into_bytes());
        } else if out.len() >= end + 4 {
            // The body: a 4-byte word (aligned to the body's start) set to an edge value.
            let words = (out.len() - end) / 4;
            let at = end + 4 * rng.random_range(0..words) + rng.random_range(0..2usize);
            let at = at.min(out.len() - 4);
            let value: [u8; 4] = match rng.random_range(0..8) {
                0 => f32::NAN.to_le_bytes(),
                1 => f32::INFINITY.to_le_bytes(),
                2 => f32::NEG_INFINITY.to_le_bytes(),
                3 => (-1i32).to_le_bytes(),
                4 => i32::MAX.to_le_bytes(),
                5 => 1e30f32.to_le_bytes(),
                6 => [255, 255, 255, 255],
                _ => rng.random_range(0u32..16).to_le_bytes(),
            };
            out[at..at + 4].copy_from_slice(&value);
        } else {
            return None;
        }
        Some(out)
    }

    fn execute(&self, input: &[u8]) -> Outcome {
        let mesh = match parse_ply(Path::new("fuzz.ply"), input) {
            Ok(mesh) => mesh,
            Err(error) => return Outcome::Refused(error.to_string()),
        };
        if let Some(p) = mesh.positions.iter().find(|p| p.iter().any(|c| !c.is_finite())) {
            return Outcome::Bug(format!("position {p:?} is not finite"));
        }
        if let Some(uvs) = &mesh.uvs {
            if uvs.len() != mesh.positions.len() {
                return Outcome::Bug("texture coordinates and positions differ in number".into());
            }
            if let Some(uv) = uvs.iter().find(|t| t.iter().any(|c| !c.is_finite())) {
                return Outcome::Bug(format!("texture coordinate {uv:?} is not finite"));
            }
        }
        if mesh.faces.iter().flatten().any(|&i| i as usize >= mesh.positions.len()) {
            return Outcome::Bug("a face index is out of range".into());
        }
        let (triangles, uvs, dropped) = mesh.triangles_without_degenerate();
        if triangles.len() + dropped != mesh.faces.len() || uvs.is_some_and(|uvs| uvs.len() != triangles.len()) {
            return Outcome::Bug("triangles, texture coordinates and dropped faces do not add up".into());
        }
        Outcome::Accepted
    }
}
