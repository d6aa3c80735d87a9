//! RGB OpenEXR images decoded from memory with their size checked first: the header is
//! read on its own, and a data window larger than [`MAX_EXR_TEXELS`] or than the file's
//! bytes can hold (see [`MAX_TEXELS_PER_FILE_BYTE`]) is refused before any pixel is
//! allocated, and so is a tile or scan-line block larger than [`MAX_BLOCK_BYTES`] or than
//! the file can hold (the crate reserves a chunk's declared size up to that). The `exr` crate itself calls its caller's allocation with the declared
//! size, so a 100-byte file could otherwise ask for gigabytes. Decoding runs on the
//! calling thread (the crate's worker threads abort the process when a decompressor
//! panics, as its B44 decoder does on some malformed blocks), and a panic inside the crate
//! becomes an error. Used by the environment map; the references' reader can use it the
//! same way.

use super::SceneError;
use super::mesh_util::without_panic;
use std::path::Path;

/// The most texels an EXR image may have here (8192 × 4096; 384 MiB as f32 RGB).
pub const MAX_EXR_TEXELS: usize = 8192 * 4096;

/// How many half-float RGB texels one byte of a compressed EXR can hold at most: a bound
/// above every EXR compression's best ratio (ZIP's deflate stays under 1032 : 1).
pub const MAX_TEXELS_PER_FILE_BYTE: usize = 4096 / 6;

/// The most bytes one block (a tile, or a run of scan lines) of an EXR may hold here.
pub const MAX_BLOCK_BYTES: usize = 256 << 20;

/// How many bytes of a block one byte of the file can hold at most (the same bound on
/// compression as [`MAX_TEXELS_PER_FILE_BYTE`]).
pub const MAX_BLOCK_BYTES_PER_FILE_BYTE: usize = 4096;

/// The R, G, B channels of an EXR's first layer.
#[derive(Clone, Debug, PartialEq)]
pub struct RgbExr {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Row-major RGB, row 0 at the top, exactly as stored (NaN and negative values too:
    /// each caller decides what it accepts).
    pub texels: Vec<[f32; 3]>,
}

/// Decodes the R, G and B channels (half or float) of the first layer of the EXR file in
/// `bytes`; `path` names it in errors. Refuses a file without R, G and B, integer channels,
/// and a data window larger than the file can hold, before allocating its pixels.
pub fn decode_rgb_exr(path: &Path, bytes: &[u8]) -> Result<RgbExr, SceneError> {
    let error = |message: String| SceneError::Image { path: path.into(), message };
    let meta = exr::meta::MetaData::read_from_buffered(std::io::Cursor::new(bytes), false)
        .map_err(|e| error(e.to_string()))?;
    let header = meta.headers.first().ok_or_else(|| error("the EXR has no layer".into()))?;
    let most = MAX_EXR_TEXELS.min(bytes.len().saturating_mul(MAX_TEXELS_PER_FILE_BYTE));
    for header in &meta.headers {
        let size = header.layer_size;
        if size.width().checked_mul(size.height()).is_none_or(|texels| texels > most) {
            return Err(error(format!(
                "the data window of {}×{} texels is larger than {most} (at most {MAX_EXR_TEXELS}, and what {} \
                 bytes can hold)",
                size.width(),
                size.height(),
                bytes.len()
            )));
        }
        // The crate reserves a chunk's declared byte count up to the largest block the
        // header allows (tile or scan-line block), before reading it.
        let pixels = match header.blocks {
            exr::meta::BlockDescription::Tiles(tiles) => tiles.tile_size.width().checked_mul(tiles.tile_size.height()),
            exr::meta::BlockDescription::ScanLines => {
                size.width().checked_mul(header.compression.scan_lines_per_block())
            }
        };
        let block = pixels.and_then(|p| p.checked_mul(header.channels.bytes_per_pixel));
        let largest_block = MAX_BLOCK_BYTES.min(bytes.len().saturating_mul(MAX_BLOCK_BYTES_PER_FILE_BYTE));
        if block.is_none_or(|b| b > largest_block) {
            return Err(error(format!(
                "a block of this header ({:?}) holds more than {largest_block} bytes (at most {MAX_BLOCK_BYTES}, \
                 and what {} bytes can hold)",
                header.blocks,
                bytes.len()
            )));
        }
    }
    for name in ["R", "G", "B"] {
        let channel = header.channels.list.iter().find(|c| c.name.to_string() == name).ok_or_else(|| {
            let names: Vec<String> = header.channels.list.iter().map(|c| c.name.to_string()).collect();
            error(format!("not an RGB image: no channel `{name}` (channels: {})", names.join(", ")))
        })?;
        if channel.sample_type == exr::meta::attribute::SampleType::U32 {
            return Err(error(format!("channel `{name}` holds integers, not half or float radiance")));
        }
    }
    // On this thread (the `exr` crate's worker threads abort the process when a
    // decompressor panics), with a panic turned into an error.
    let image = without_panic(|| {
        read_first_rgba_layer(
            bytes,
            |resolution, _| (resolution.width(), vec![[0.0f32; 3]; resolution.width() * resolution.height()]),
            |(width, texels): &mut (usize, Vec<[f32; 3]>),
             position: exr::math::Vec2<usize>,
             (r, g, b, _a): (f32, f32, f32, f32)| {
                texels[position.y() * *width + position.x()] = [r, g, b];
            },
        )
    })
    .map_err(error)?
    .map_err(|e| error(e.to_string()))?;
    let (width, texels) = image.layer_data.channel_data.pixels;
    let height = texels.len() / width.max(1);
    Ok(RgbExr { width, height, texels })
}

/// `exr`'s `read_first_rgba_layer_from_file` reading from memory.
fn read_first_rgba_layer<Create, Set, Pixels>(
    bytes: &[u8],
    create: Create,
    set_pixel: Set,
) -> exr::error::Result<exr::prelude::PixelImage<Pixels, exr::prelude::RgbaChannels>>
where
    Create: Fn(exr::math::Vec2<usize>, &exr::prelude::RgbaChannels) -> Pixels + 'static,
    Set: Fn(&mut Pixels, exr::math::Vec2<usize>, (f32, f32, f32, f32)) + 'static,
    Pixels: 'static,
{
    use exr::prelude::{ReadChannels, ReadLayers};
    exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .rgba_channels(create, set_pixel)
        .first_valid_layer()
        .all_attributes()
        .non_parallel()
        .from_buffered(std::io::Cursor::new(bytes))
}
