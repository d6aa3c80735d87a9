//! Textures and samplers for `cargo xtask run`: what `--texture`, `--storage-texture`
//! and `--sampler` say, the textures they make (a texture's shape always comes from the
//! kernel's declaration), and storage textures written back as pictures beside their raw
//! texels.
//!
//! * `--texture G:B=FILE.png`: an `rgba8unorm` texture of the PNG's 8-bit RGBA codes
//!   (no sRGB decoding: a texel reads as code / 255).
//! * `--texture G:B=FILE.exr`: an `rgba32float` texture of the EXR's R, G, B (alpha 1).
//! * `--texture G:B=FILE@WxHxD:FORMAT`: raw texels of one mip level (see
//!   `strata_backends::texture` for their order). The value is split at its last `@`;
//!   a value ending in `.png` or `.exr` is always a picture, `@` in its name or not
//!   (raw texels end in a format name), so `my@photo.png` is the picture.
//! * `--storage-texture G:B=WxH[xD][:FORMAT]`: a zero-filled storage texture (the
//!   format defaults to the kernel's).
//! * `--sampler G:B=FILTER,ADDRESS`: `nearest` or `linear` (magnification,
//!   minification and mip levels alike); `clamp`, `repeat` or `mirror` (every axis).
//!
//! `G` is the WGSL group: a kernel may bind several (wgpu bind groups, Vulkan descriptor
//! sets; naga's GLSL, which has no sets, gets them flattened).

use crate::run_data::{GroupedImages, ImageInput, MAX_INPUT_BYTES, OutputBuffer, Slot, read_input};
use anyhow::{Context, Result, bail};
use std::path::{Path, PathBuf};
pub use strata_backends::SamplerDesc;
use strata_backends::{AddressMode, FilterMode, TextureDesc};
use strata_kernels::{BindingKind, Kernel, TexelFormat};

/// Where a `--texture` comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum TextureFile {
    /// A PNG (`rgba8unorm`) or EXR (`rgba32float`), by extension.
    Picture(PathBuf),
    /// Raw texels of a given size and format.
    Raw {
        /// The file.
        path: PathBuf,
        /// Width, height, depth (or layers).
        size: [u32; 3],
        /// Texel format.
        format: TexelFormat,
    },
}

/// One texture or sampler of a run, by `(group, binding)`.
#[derive(Clone, Debug, PartialEq)]
pub enum ImageSpec {
    /// `--texture`.
    Texture(Slot, TextureFile),
    /// `--storage-texture`: size, and the format if given.
    StorageTexture(Slot, [u32; 3], Option<TexelFormat>),
    /// `--sampler`.
    Sampler(Slot, SamplerDesc),
}

impl ImageSpec {
    /// The `(group, binding)` it is for.
    pub fn slot(&self) -> Slot {
        match self {
            Self::Texture(s, _) | Self::StorageTexture(s, ..) | Self::Sampler(s, _) => *s,
        }
    }

    /// The flag's name: `--texture`, `--storage-texture` or `--sampler`.
    pub fn flag_name(&self) -> &'static str {
        match self {
            Self::Texture(..) => "--texture",
            Self::StorageTexture(..) => "--storage-texture",
            Self::Sampler(..) => "--sampler",
        }
    }

    /// The flag as a user writes it (`--texture 0:0=t.bin@4x4:rgba8unorm`), for messages.
    pub fn flag(&self) -> String {
        let (group, binding) = self.slot();
        let size = |[w, h, d]: [u32; 3]| if d == 1 { format!("{w}x{h}") } else { format!("{w}x{h}x{d}") };
        let value = match self {
            Self::Texture(_, TextureFile::Picture(path)) => path.display().to_string(),
            Self::Texture(_, TextureFile::Raw { path, size: s, format }) => {
                format!("{}@{}:{}", path.display(), size(*s), format.wgsl())
            }
            Self::StorageTexture(_, s, Some(format)) => format!("{}:{}", size(*s), format.wgsl()),
            Self::StorageTexture(_, s, None) => size(*s),
            Self::Sampler(_, desc) => {
                let filter = match desc.mag_filter {
                    FilterMode::Nearest => "nearest",
                    FilterMode::Linear => "linear",
                };
                let address = match desc.address[0] {
                    AddressMode::ClampToEdge => "clamp",
                    AddressMode::Repeat => "repeat",
                    AddressMode::MirrorRepeat => "mirror",
                };
                format!("{filter},{address}")
            }
        };
        format!("{} {group}:{binding}={value}", self.flag_name())
    }
}

/// Bytes of `size` texels of `format` (every axis counted), or `None` past `u64`.
fn texel_bytes(size: [u32; 3], format: TexelFormat) -> Option<u64> {
    let [w, h, d] = size.map(u64::from);
    w.checked_mul(h)?.checked_mul(d)?.checked_mul(u64::from(format.bytes_per_texel()))
}

/// Whether a texture of `size` texels of `format` stays within what xtask run reads or
/// makes ([`MAX_INPUT_BYTES`]), checked before any file is read or
/// anything allocated; the error names `flag`.
fn check_texels(flag: &str, size: [u32; 3], format: TexelFormat) -> Result<()> {
    let cap = MAX_INPUT_BYTES;
    let [w, h, d] = size;
    match texel_bytes(size, format) {
        Some(bytes) if bytes <= cap => Ok(()),
        bytes => {
            let bytes = bytes.map_or_else(
                || (u128::from(w) * u128::from(h) * u128::from(d) * u128::from(format.bytes_per_texel())).to_string(),
                |b| b.to_string(),
            );
            bail!(
                "{flag}: {w}x{h}x{d} {} texels are {bytes} bytes, more than xtask run's cap of {cap} bytes",
                format.wgsl()
            )
        }
    }
}

fn size_of(text: &str) -> Result<[u32; 3], String> {
    let axes: Vec<&str> = text.split('x').collect();
    if axes.is_empty() || axes.len() > 3 {
        return Err(format!("size `{text}`: expected WxH or WxHxD"));
    }
    let mut size = [1u32; 3];
    for (axis, value) in axes.iter().enumerate() {
        size[axis] = value.trim().parse().map_err(|e| format!("size `{text}`: `{value}`: {e}"))?;
        if size[axis] == 0 {
            return Err(format!("size `{text}`: every axis must be at least 1"));
        }
    }
    Ok(size)
}

fn format_of(text: &str) -> Result<TexelFormat, String> {
    TexelFormat::from_wgsl(text.trim()).ok_or_else(|| {
        let known: Vec<&str> = TexelFormat::ALL.iter().map(|f| f.wgsl()).collect();
        format!("format `{text}`: one of {}", known.join(", "))
    })
}

/// The file part of `--texture G:B=...`: a name ending in `.png` or `.exr` is a picture
/// (whatever `@` it holds: raw texels end in a format name, never in `.png`), anything
/// else raw texels `FILE@WxH[xD]:FORMAT`, split at the last `@`.
pub fn parse_texture_file(text: &str) -> Result<TextureFile, String> {
    let lower = text.to_ascii_lowercase();
    if lower.ends_with(".png") || lower.ends_with(".exr") {
        return Ok(TextureFile::Picture(PathBuf::from(text)));
    }
    match text.rsplit_once('@') {
        Some((path, shape)) => {
            let (size, format) = shape.split_once(':').ok_or_else(|| {
                format!("`{text}`: raw texels need FILE@WxH[xD]:FORMAT (e.g. t.bin@64x64:rgba8unorm)")
            })?;
            Ok(TextureFile::Raw { path: PathBuf::from(path), size: size_of(size)?, format: format_of(format)? })
        }
        None => {
            Err(format!("`{text}`: a .png, a .exr, or raw texels as FILE@WxH[xD]:FORMAT (e.g. t.bin@64x64:rgba8unorm)"))
        }
    }
}

/// What `--storage-texture` gives: the size, and the format if named.
pub type StorageTextureSize = ([u32; 3], Option<TexelFormat>);

/// The value part of `--storage-texture G:B=WxH[xD][:FORMAT]`.
pub fn parse_storage_texture(text: &str) -> Result<StorageTextureSize, String> {
    match text.split_once(':') {
        Some((size, format)) => Ok((size_of(size)?, Some(format_of(format)?))),
        None => Ok((size_of(text)?, None)),
    }
}

/// The value part of `--sampler G:B=FILTER,ADDRESS`.
pub fn parse_sampler(text: &str) -> Result<SamplerDesc, String> {
    let (filter, address) =
        text.split_once(',').ok_or_else(|| format!("`{text}`: expected FILTER,ADDRESS (e.g. linear,clamp)"))?;
    let filter = match filter.trim() {
        "nearest" => FilterMode::Nearest,
        "linear" => FilterMode::Linear,
        other => return Err(format!("filter `{other}`: nearest or linear")),
    };
    let address = match address.trim() {
        "clamp" => AddressMode::ClampToEdge,
        "repeat" => AddressMode::Repeat,
        "mirror" => AddressMode::MirrorRepeat,
        other => return Err(format!("address mode `{other}`: clamp, repeat or mirror")),
    };
    Ok(SamplerDesc::uniform(filter, address))
}

/// Loads a picture as texels: PNG codes as `rgba8unorm`, EXR RGB as `rgba32float`.
fn read_picture(path: &Path) -> Result<([u32; 3], TexelFormat, Vec<u8>)> {
    let lower = path.to_string_lossy().to_ascii_lowercase();
    if lower.ends_with(".exr") {
        let image = strata_render::rgb_image::RgbImage::read_exr(path)?;
        let texels = image.pixels.iter().flat_map(|p| [p[0], p[1], p[2], 1.0]).flat_map(f32::to_le_bytes).collect();
        return Ok(([image.width, image.height, 1], TexelFormat::Rgba32Float, texels));
    }
    let bytes = read_input(path, MAX_INPUT_BYTES)?;
    let image = image::load_from_memory_with_format(&bytes, image::ImageFormat::Png)
        .with_context(|| format!("texture {}: not a PNG this reader understands", path.display()))?
        .to_rgba8();
    Ok(([image.width(), image.height(), 1], TexelFormat::Rgba8Unorm, image.into_raw()))
}

/// The textures and samplers `specs` describe, for `kernel`'s bindings: each checked
/// against the binding's kind, shape and (for storage textures) format, with an error
/// naming the flag, the binding and the mismatch.
pub fn image_inputs(kernel: &Kernel, specs: &[ImageSpec]) -> Result<GroupedImages> {
    let mut inputs = GroupedImages::new();
    for (index, spec) in specs.iter().enumerate() {
        if let Some(first) = specs[..index].iter().find(|s| s.slot() == spec.slot()) {
            let (group, binding) = spec.slot();
            bail!("{}: binding {group}:{binding} is given twice ({} first): give it once", spec.flag(), first.flag());
        }
    }
    for spec in specs {
        let (group, binding) = spec.slot();
        let Some(info) = kernel.binding(group, binding) else {
            bail!("binding {group}:{binding}: entry point `{}` has no such binding", kernel.entry_point());
        };
        let what = format!("binding {group}:{binding} (`{}`: {})", info.name, info.element.type_name);
        let (dimension, declared) = match info.kind {
            BindingKind::SampledTexture { dimension, .. } => (Some(dimension), None),
            BindingKind::StorageTexture { dimension, format, .. } => (Some(dimension), Some(format)),
            _ => (None, None),
        };
        match spec {
            ImageSpec::Texture(_, TextureFile::Raw { size, format, .. }) => check_texels(&spec.flag(), *size, *format)?,
            ImageSpec::StorageTexture(_, size, format) => {
                check_texels(&spec.flag(), *size, format.or(declared).unwrap_or(TexelFormat::Rgba32Float))?
            }
            _ => {}
        }
        let input = match (spec, dimension) {
            (ImageSpec::Sampler(_, desc), _) if info.kind == BindingKind::Sampler => ImageInput::Sampler(*desc),
            (ImageSpec::Sampler(..), _) => bail!("--sampler for {what}, which is not a sampler"),
            (_, None) => bail!("a texture for {what}, which is not a texture"),
            (ImageSpec::Texture(_, file), Some(dimension)) => {
                let (size, format, texels) = match file {
                    TextureFile::Picture(path) => read_picture(path)?,
                    TextureFile::Raw { path, size, format } => {
                        let bytes = read_input(path, MAX_INPUT_BYTES)?;
                        (*size, *format, bytes)
                    }
                };
                let desc = TextureDesc { label: info.name.clone(), dimension, size, mip_levels: 1, format };
                if let Some(declared) = declared.filter(|d| *d != format) {
                    bail!(
                        "--texture for {what}: the file gives {}, the kernel declares {}",
                        format.wgsl(),
                        declared.wgsl()
                    );
                }
                desc.check_level(0, texels.len()).with_context(|| format!("--texture for {what}"))?;
                ImageInput::Texture { desc, levels: vec![texels] }
            }
            (ImageSpec::StorageTexture(_, size, format), Some(dimension)) => {
                let Some(declared) = declared else {
                    bail!("--storage-texture for {what}, which is a sampled texture (give it --texture)");
                };
                if let Some(format) = format.filter(|f| *f != declared) {
                    bail!(
                        "--storage-texture for {what}: {} given, the kernel declares {}",
                        format.wgsl(),
                        declared.wgsl()
                    );
                }
                let desc =
                    TextureDesc { label: info.name.clone(), dimension, size: *size, mip_levels: 1, format: declared };
                ImageInput::Texture { desc, levels: Vec::new() }
            }
        };
        inputs.push(((group, binding), input));
    }
    Ok(inputs)
}

/// Writes a storage texture's output beside its raw texels (`STEM.bin`): `STEM.png` for
/// `rgba8unorm` (its bytes exactly), `STEM.exr` (R, G, B) for the float formats, nothing
/// more for integer formats or a texture that is not 2-D. Returns the pictures written.
pub fn write_picture(stem: &Path, output: &OutputBuffer, desc: &TextureDesc) -> Result<Option<PathBuf>> {
    let [width, height, depth] = desc.size;
    if depth != 1 || height == 1 && desc.dimension == strata_kernels::TextureDimension::D1 {
        return Ok(None);
    }
    let texels = width as usize * height as usize;
    let bytes = &output.bytes[..(texels * desc.format.bytes_per_texel() as usize).min(output.bytes.len())];
    let floats = |per_texel: usize, read: &dyn Fn(&[u8], usize) -> f32| -> Vec<[f32; 3]> {
        bytes
            .chunks_exact(desc.format.bytes_per_texel() as usize)
            .map(|t| {
                let c = |i: usize| if i < per_texel { read(t, i) } else { 0.0 };
                [c(0), c(1), c(2)]
            })
            .collect()
    };
    let f32_at = |t: &[u8], i: usize| f32::from_le_bytes(t[4 * i..4 * i + 4].try_into().expect("4 bytes"));
    let f16_at = |t: &[u8], i: usize| half::f16::from_le_bytes([t[2 * i], t[2 * i + 1]]).to_f32();
    let pixels = match desc.format {
        TexelFormat::Rgba8Unorm => {
            let path = stem.with_extension("png");
            let image = image::RgbaImage::from_raw(width, height, bytes.to_vec())
                .context("a storage texture's bytes do not fill its size")?;
            // Encoded in memory, then written whole or not at all, never through a link
            // (strata's one writer: strata_render::atomic_file).
            let mut png = Vec::new();
            image
                .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
                .with_context(|| format!("cannot encode {}", path.display()))?;
            strata_render::atomic_file::write(&path, png)?;
            return Ok(Some(path));
        }
        TexelFormat::Rgba16Float => floats(4, &f16_at),
        TexelFormat::Rgba32Float => floats(4, &f32_at),
        TexelFormat::R32Float => floats(1, &f32_at),
        _ => return Ok(None),
    };
    let path = stem.with_extension("exr");
    let picture = strata_render::rgb_image::RgbImage { width, height, pixels };
    picture.write_exr(&path)?;
    Ok(Some(path))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_flags_parse_and_bad_values_are_named() {
        assert_eq!(parse_texture_file("a.png"), Ok(TextureFile::Picture("a.png".into())));
        assert_eq!(
            parse_texture_file("t.bin@4x2:r32float"),
            Ok(TextureFile::Raw { path: "t.bin".into(), size: [4, 2, 1], format: TexelFormat::R32Float })
        );
        assert!(parse_texture_file("t.bin").unwrap_err().contains("FILE@WxH[xD]:FORMAT"));
        // A picture's name may hold `@`: raw texels end in a format name, never `.png`.
        assert_eq!(parse_texture_file("my@photo.png"), Ok(TextureFile::Picture("my@photo.png".into())));
        assert_eq!(parse_texture_file("a@b@2x2.EXR"), Ok(TextureFile::Picture("a@b@2x2.EXR".into())));
        assert!(parse_texture_file("t.bin@4x2:bgra8").unwrap_err().contains("bgra8"));
        assert_eq!(parse_storage_texture("8x8x2"), Ok(([8, 8, 2], None)));
        assert_eq!(parse_storage_texture("8x8:rgba16float"), Ok(([8, 8, 1], Some(TexelFormat::Rgba16Float))));
        assert!(parse_storage_texture("0x8").unwrap_err().contains("at least 1"));
        let sampler = parse_sampler("linear,mirror").unwrap();
        assert_eq!((sampler.mag_filter, sampler.address[2]), (FilterMode::Linear, AddressMode::MirrorRepeat));
        assert!(parse_sampler("cubic,clamp").unwrap_err().contains("cubic"));
    }
}
