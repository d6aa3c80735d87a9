//! `exr`: OpenEXR files through `Environment::from_exr_bytes` (environment maps) and
//! `RgbImage::read_exr` (references; it reads a file, so each input is written to a
//! temporary file first). Structure-aware mutations parse the header's attributes and set
//! a data or display window corner, the compression, the line order, a channel's type or
//! sampling, a tile size or an attribute's size field to an edge value, or change an offset
//! table entry or a chunk's header; the generator writes headers from scratch.

use super::super::mutate::FuzzRng;
use super::super::{Outcome, Target, build};
use arbitrary::Unstructured;
use exr::prelude::{Compression, Encoding, Image, Layer, LayerAttributes, SpecificChannels, WritableImage};
use rand::Rng;
use std::path::{Path, PathBuf};
use strata_render::rgb_image::RgbImage;
use strata_render::scene::{Environment, decode_rgb_exr};

/// One attribute of an EXR header: where its size field and value lie.
struct Attribute {
    name: String,
    kind: String,
    size_at: usize,
    value: std::ops::Range<usize>,
}

/// The attributes of the first header of `input` and where the header ends (after its
/// terminating zero byte), if the file parses that far.
fn attributes(input: &[u8]) -> Option<(Vec<Attribute>, usize)> {
    if input.len() < 8 || input[..4] != [0x76, 0x2f, 0x31, 0x01] {
        return None;
    }
    let mut at = 8;
    let mut found = Vec::new();
    let text = |at: &mut usize| -> Option<String> {
        let end = input[*at..].iter().position(|&b| b == 0)? + *at;
        let text = String::from_utf8_lossy(&input[*at..end]).into_owned();
        *at = end + 1;
        Some(text)
    };
    loop {
        if *input.get(at)? == 0 {
            return Some((found, at + 1));
        }
        let name = text(&mut at)?;
        let kind = text(&mut at)?;
        let size_at = at;
        let size = i32::from_le_bytes(input.get(at..at + 4)?.try_into().ok()?);
        let start = at + 4;
        let end = start.checked_add(usize::try_from(size).ok()?)?;
        if end > input.len() {
            return None;
        }
        found.push(Attribute { name, kind, size_at, value: start..end });
        at = end;
    }
}

/// Edge values for a 32-bit integer field.
fn edge_i32(rng: &mut FuzzRng, old: i32) -> i32 {
    [
        0,
        -1,
        1,
        2,
        3,
        old.wrapping_add(1),
        old.wrapping_sub(1),
        old.wrapping_mul(1024),
        i32::MAX,
        i32::MIN,
        65535,
        1 << 20,
        1 << 30,
    ][rng.random_range(0..13)]
}

/// The target, with its temporary file for `read_exr`.
pub(super) struct Exr {
    folder: PathBuf,
    /// The private folder (random name, mode 0700) `folder` is, removed with the target.
    _scratch: Option<strata_files::TempDir>,
}

impl Exr {
    pub(super) fn new() -> Exr {
        // A new private folder, never one someone else made first under a fixed name.
        match strata_files::private_scratch_folder("strata-fuzz-exr-") {
            Ok(scratch) => Exr { folder: scratch.path().to_path_buf(), _scratch: Some(scratch) },
            // No temporary folder: every input is then refused as unwritable, by name.
            Err(_) => Exr { folder: PathBuf::from("/nonexistent/strata-fuzz-exr"), _scratch: None },
        }
    }
}

/// A header attribute: name, type, value.
fn attribute(out: &mut Vec<u8>, name: &str, kind: &str, value: &[u8]) {
    out.extend(name.as_bytes());
    out.push(0);
    out.extend(kind.as_bytes());
    out.push(0);
    out.extend((value.len() as i32).to_le_bytes());
    out.extend(value);
}

impl Target for Exr {
    fn name(&self) -> &'static str {
        "exr"
    }

    fn seeds(&self, _shared: Option<&Path>) -> Vec<Vec<u8>> {
        let mut seeds: Vec<Vec<u8>> = build::COMPRESSIONS.iter().map(|&c| build::environment_exr(c)).collect();
        // Half-float RGBA in 4 × 4 tiles, and a grey image.
        let channels = SpecificChannels::rgba(|p: exr::math::Vec2<usize>| {
            (half::f16::from_f32(p.x() as f32), half::f16::from_f32(0.5), half::f16::from_f32(2.0), half::f16::ONE)
        });
        let encoding = Encoding {
            compression: Compression::ZIP1,
            blocks: exr::prelude::Blocks::Tiles(exr::math::Vec2(4, 4)),
            // Its four blocks in order, so that the seed is the same bytes every time.
            line_order: exr::prelude::LineOrder::Increasing,
        };
        let layer = Layer::new((6, 5), LayerAttributes::named("tiles"), encoding, channels);
        let mut bytes = std::io::Cursor::new(Vec::new());
        Image::from_layer(layer).write().to_buffered(&mut bytes).expect("EXR into memory");
        seeds.push(bytes.into_inner());
        let grey = SpecificChannels::build().with_channel("Y").with_pixel_fn(|_| (0.5f32,));
        let layer = Layer::new((3, 2), LayerAttributes::named("grey"), Encoding::default(), grey);
        let mut bytes = std::io::Cursor::new(Vec::new());
        Image::from_layer(layer).write().to_buffered(&mut bytes).expect("EXR into memory");
        seeds.push(bytes.into_inner());
        // Pixels that the environment refuses: NaN, negative, infinite.
        seeds.push(build::exr(2, 2, Compression::Uncompressed, |x, y| match (x, y) {
            (0, 0) => [f32::NAN, 0.0, 0.0],
            (1, 0) => [-1.0, 0.0, 0.0],
            _ => [f32::INFINITY, 1.0, 1.0],
        }));
        seeds
    }

    fn generate(&self, u: &mut Unstructured) -> arbitrary::Result<Vec<u8>> {
        let tiled = u.ratio(1, 4)?;
        let mut out = vec![0x76, 0x2f, 0x31, 0x01, 2, if tiled { 2 } else { 0 }, 0, 0];
        let mut channels = Vec::new();
        for name in ["A", "B", "G", "R", "Y"] {
            if u.ratio(3, 4)? {
                channels.extend(name.as_bytes());
                channels.push(0);
                channels.extend(u.int_in_range(0i32..=3)?.to_le_bytes());
                channels.extend([0, 0, 0, 0]);
                let sampling = if u.ratio(1, 8)? { u.int_in_range(0i32..=3)? } else { 1 };
                channels.extend(sampling.to_le_bytes());
                channels.extend(sampling.to_le_bytes());
            }
        }
        channels.push(0);
        attribute(&mut out, "channels", "chlist", &channels);
        attribute(&mut out, "compression", "compression", &[u.int_in_range(0u8..=10)?]);
        let corner = |u: &mut Unstructured| -> arbitrary::Result<i32> {
            Ok(if u.ratio(1, 6)? { u.arbitrary()? } else { u.int_in_range(-2..=9)? })
        };
        let window: Vec<u8> = (0..4)
            .map(|_| corner(u))
            .collect::<arbitrary::Result<Vec<i32>>>()?
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        attribute(&mut out, "dataWindow", "box2i", &window);
        attribute(&mut out, "displayWindow", "box2i", &window);
        attribute(&mut out, "lineOrder", "lineOrder", &[u.int_in_range(0u8..=3)?]);
        attribute(&mut out, "pixelAspectRatio", "float", &f32::from_bits(u.arbitrary()?).to_le_bytes());
        attribute(&mut out, "screenWindowCenter", "v2f", &[0; 8]);
        attribute(&mut out, "screenWindowWidth", "float", &1.0f32.to_le_bytes());
        if tiled {
            let mut description = Vec::new();
            description.extend(u.int_in_range(0u32..=17)?.to_le_bytes());
            description.extend(u.int_in_range(0u32..=17)?.to_le_bytes());
            description.push(u.int_in_range(0u8..=2)?);
            attribute(&mut out, "tiles", "tiledesc", &description);
        }
        out.push(0);
        // An offset table and chunks of random data.
        let chunks = u.int_in_range(0usize..=12)?;
        let table_end = out.len() + 8 * chunks;
        let mut body = Vec::new();
        let mut table = Vec::new();
        for index in 0..chunks {
            table.extend(((table_end + body.len()) as u64).to_le_bytes());
            body.extend((index as i32).to_le_bytes());
            if tiled {
                body.extend([0u8; 12]);
            }
            let length = u.int_in_range(0..=96)?;
            let data = u.bytes(length)?;
            body.extend((data.len() as i32).to_le_bytes());
            body.extend(data);
        }
        out.extend(table);
        out.extend(body);
        Ok(out)
    }

    fn mutate(&self, rng: &mut FuzzRng, input: &[u8]) -> Option<Vec<u8>> {
        let (attributes, header_end) = attributes(input)?;
        let mut out = input.to_vec();
        let choice = rng.random_range(0..10);
        if choice < 6 && !attributes.is_empty() {
            let attribute = &attributes[rng.random_range(0..attributes.len())];
            let value = attribute.value.clone();
            let int_at = |rng: &mut FuzzRng| value.start + 4 * rng.random_range(0..(value.len() / 4).max(1));
            match attribute.kind.as_str() {
                _ if rng.random_range(0..6) == 0 => {
                    let old = i32::from_le_bytes(out[attribute.size_at..attribute.size_at + 4].try_into().ok()?);
                    let new = edge_i32(rng, old);
                    out[attribute.size_at..attribute.size_at + 4].copy_from_slice(&new.to_le_bytes());
                }
                "box2i" | "chlist" | "tiledesc" | "int" | "v2i" | "box2f" if value.len() >= 4 => {
                    let at = int_at(rng).min(value.end - 4);
                    let old = i32::from_le_bytes(out[at..at + 4].try_into().ok()?);
                    let new = edge_i32(rng, old);
                    out[at..at + 4].copy_from_slice(&new.to_le_bytes());
                }
                "compression" | "lineOrder" if !value.is_empty() => {
                    out[value.start] = [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 255][rng.random_range(0..12)];
                }
                "float" | "v2f" if value.len() >= 4 => {
                    let at = int_at(rng).min(value.end - 4);
                    let new = [f32::NAN, f32::INFINITY, 0.0, -1.0, 1e-30][rng.random_range(0..5)];
                    out[at..at + 4].copy_from_slice(&new.to_le_bytes());
                }
                _ if !value.is_empty() => {
                    let at = rng.random_range(value.clone());
                    out[at] = rng.random();
                }
                _ => return None,
            }
            let _ = &attribute.name;
        } else if choice < 8 && out.len() >= header_end + 8 {
            // An offset table entry.
            let entries = ((out.len() - header_end) / 8).min(64);
            let at = header_end + 8 * rng.random_range(0..entries);
            let old = u64::from_le_bytes(out[at..at + 8].try_into().ok()?);
            let new = [
                0,
                u64::MAX,
                out.len() as u64,
                out.len() as u64 - 1,
                old.wrapping_add(1),
                old.wrapping_sub(4),
                1 << 40,
            ][rng.random_range(0..7)];
            out[at..at + 8].copy_from_slice(&new.to_le_bytes());
        } else if out.len() >= header_end + 8 {
            // A chunk header (its line or tile position, or its data size).
            let first = u64::from_le_bytes(out[header_end..header_end + 8].try_into().ok()?) as usize;
            let at = first.checked_add(4 * rng.random_range(0..2usize))?;
            if at.checked_add(4).is_none_or(|end| end > out.len()) {
                return None;
            }
            let old = i32::from_le_bytes(out[at..at + 4].try_into().ok()?);
            let new = edge_i32(rng, old);
            out[at..at + 4].copy_from_slice(&new.to_le_bytes());
        } else {
            return None;
        }
        Some(out)
    }

    fn execute(&self, input: &[u8]) -> Outcome {
        let name = Path::new("fuzz.exr");
        let environment = match Environment::from_exr_bytes(name, input, 1.0, None) {
            Ok(environment) => {
                if environment.texels.len() != environment.width as usize * environment.height as usize
                    || environment.texels.is_empty()
                {
                    return Outcome::Bug("environment texels do not match its size".into());
                }
                if let Some(t) = environment.texels.iter().find(|t| t.iter().any(|c| !(c.is_finite() && *c >= 0.0))) {
                    return Outcome::Bug(format!("environment texel {t:?} accepted"));
                }
                Ok(())
            }
            Err(error) => Err(error.to_string()),
        };
        // `read_exr` (references) allocates the declared data window before checking it (a
        // 100-byte file asks for 27 GB: tests/data/fuzz/exr/huge-e8118b09d6b6ef84), and
        // decodes on the `exr` crate's worker threads, where a decompressor's panic aborts
        // the process (B44 blocks in debug builds). Its file is not this harness's to fix
        // (RELIABILITY.md): it runs only on inputs that `decode_rgb_exr` decodes.
        if let Err(decode) = decode_rgb_exr(name, input) {
            return match environment {
                Ok(()) => Outcome::Bug(format!("the environment accepted what decode_rgb_exr refuses: {decode}")),
                Err(error) => Outcome::Refused(error),
            };
        }
        // `read_exr` reads a file: one per thread, in this process's folder.
        let file = self.folder.join(format!("{:?}.exr", std::thread::current().id()).replace(['(', ')'], ""));
        if strata_files::write_whole(&file, input).is_err() {
            return Outcome::Refused("cannot write the temporary file".into());
        }
        let reference = RgbImage::read_exr(&file);
        let _ = std::fs::remove_file(&file);
        let reference = match reference {
            Ok(image) => {
                if image.pixels.len() != image.width as usize * image.height as usize {
                    return Outcome::Bug("reference pixels do not match its size".into());
                }
                if image.pixels.iter().any(|p| p.iter().any(|c| !c.is_finite())) {
                    Some("reference accepted with non-finite pixels")
                } else if image.pixels.iter().any(|p| p.iter().any(|c| *c < 0.0)) {
                    Some("reference accepted with negative pixels")
                } else {
                    None
                }
            }
            Err(_) => Some("reference refused"),
        };
        match (environment, reference) {
            (Ok(()), None) => Outcome::Accepted,
            (Ok(()), Some(remark)) => Outcome::Noted(format!("environment accepted, {remark}")),
            (Err(error), Some("reference refused")) => Outcome::Refused(error),
            (Err(error), Some(remark)) => Outcome::Noted(format!("{remark}; environment: {error}")),
            (Err(error), None) => Outcome::Noted(format!("reference accepted; environment: {error}")),
        }
    }
}
