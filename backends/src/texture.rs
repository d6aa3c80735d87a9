//! Textures and samplers as every backend creates them: what is asked for
//! ([`TextureDesc`], [`SamplerDesc`]), the bytes of a mip level, and the checks every
//! backend makes before it creates one, so a wrong size is one clear error everywhere.
//!
//! A mip level's bytes are its texels tightly packed, row after row, then slice after
//! slice (a 3-D texture's depth, a 2-D array's layers), each texel in its format's byte
//! layout (little-endian components, red first), as `write_texture` takes them and
//! `read_texture` returns them.

use crate::device_info::DeviceInfo;
use crate::error::BackendError;
use strata_kernels::{TexelFormat, TextureDimension};

/// A texture owned by a backend.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct TextureId(pub u64);

/// A sampler owned by a backend.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct SamplerId(pub u64);

/// A texture to create: usable as a sampled texture and as a storage texture of its
/// format at once.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TextureDesc {
    /// Name in messages.
    pub label: String,
    /// Its shape; a kernel binding it must declare the same.
    pub dimension: TextureDimension,
    /// Width, height and depth (a 2-D array's layer count) of mip level 0; unused axes 1.
    pub size: [u32; 3],
    /// Mip levels (each half the previous one's size, rounded down, at least 1; a 2-D
    /// array's layer count does not shrink).
    pub mip_levels: u32,
    /// Texel format.
    pub format: TexelFormat,
}

impl TextureDesc {
    /// The size of mip `level`: each axis halved per level, at least 1 (the layers of a
    /// 2-D array stay).
    pub fn level_size(&self, level: u32) -> [u32; 3] {
        let shrink = |n: u32| (n >> level).max(1);
        match self.dimension {
            TextureDimension::D1 => [shrink(self.size[0]), 1, 1],
            TextureDimension::D2 => [shrink(self.size[0]), shrink(self.size[1]), 1],
            TextureDimension::D2Array => [shrink(self.size[0]), shrink(self.size[1]), self.size[2]],
            TextureDimension::D3 => [shrink(self.size[0]), shrink(self.size[1]), shrink(self.size[2])],
        }
    }

    /// Bytes of mip `level` (see the module's comment for their order).
    pub fn level_bytes(&self, level: u32) -> u64 {
        let [w, h, d] = self.level_size(level);
        u64::from(w) * u64::from(h) * u64::from(d) * u64::from(self.format.bytes_per_texel())
    }

    /// Whether the texture can be created: sizes at least 1 and within `device`'s 2-D
    /// and 3-D texture limits, unused axes 1, mip levels that exist.
    pub fn check(&self, device: &DeviceInfo) -> Result<(), BackendError> {
        let error = |reason: String| BackendError::Texture { label: self.label.clone(), reason };
        let [w, h, d] = self.size;
        if w == 0 || h == 0 || d == 0 {
            return Err(error(format!("size {w}x{h}x{d}: every axis must be at least 1")));
        }
        let unused_ok = match self.dimension {
            TextureDimension::D1 => h == 1 && d == 1,
            TextureDimension::D2 => d == 1,
            TextureDimension::D2Array | TextureDimension::D3 => true,
        };
        if !unused_ok {
            return Err(error(format!(
                "size {w}x{h}x{d}: a {} texture uses {} axes (the others must be 1)",
                self.dimension.wgsl(),
                self.dimension.coordinates()
            )));
        }
        let (limit, name, largest) = match self.dimension {
            TextureDimension::D3 => (device.limits.max_texture_3d, "texture 3-D size", w.max(h).max(d)),
            TextureDimension::D2Array if d > device.limits.max_texture_layers => {
                (device.limits.max_texture_layers, "texture array layers", d)
            }
            _ => (device.limits.max_texture_2d, "texture 2-D size", w.max(h)),
        };
        if largest > limit {
            return Err(BackendError::LimitExceeded {
                what: format!("texture `{}`", self.label),
                limit: name,
                requested: u64::from(largest),
                available: u64::from(limit),
            });
        }
        let largest_axis = match self.dimension {
            TextureDimension::D2Array => w.max(h),
            _ => w.max(h).max(d),
        };
        let levels = 32 - largest_axis.leading_zeros();
        if self.mip_levels == 0 || self.mip_levels > levels {
            return Err(error(format!("{} mip levels: a {w}x{h}x{d} texture has 1 to {levels}", self.mip_levels)));
        }
        Ok(())
    }

    /// Whether `data` is a whole mip `level`.
    pub fn check_level(&self, level: u32, data_len: usize) -> Result<(), BackendError> {
        let error = |reason: String| BackendError::Texture { label: self.label.clone(), reason };
        if level >= self.mip_levels {
            return Err(error(format!("mip level {level}: the texture has {}", self.mip_levels)));
        }
        let expected = self.level_bytes(level);
        if data_len as u64 != expected {
            let [w, h, d] = self.level_size(level);
            return Err(error(format!(
                "{data_len} bytes for mip level {level}: it holds {w}x{h}x{d} {} texels, {expected} bytes",
                self.format.wgsl()
            )));
        }
        Ok(())
    }
}

/// How a sampler picks texels between and beyond texel centres.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FilterMode {
    /// The nearest texel (mip level).
    Nearest,
    /// A linear blend of the nearest two per axis (mip levels).
    Linear,
}

/// What a sampler reads at a coordinate outside [0, 1].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum AddressMode {
    /// The edge texel.
    ClampToEdge,
    /// The texture repeats.
    Repeat,
    /// The texture repeats, every other copy mirrored.
    MirrorRepeat,
}

/// A sampler to create (WebGPU's `GPUSamplerDescriptor`, without comparison and
/// anisotropy).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SamplerDesc {
    /// Addressing of u, v and w.
    pub address: [AddressMode; 3],
    /// Filter when the texture is magnified.
    pub mag_filter: FilterMode,
    /// Filter when it is minified.
    pub min_filter: FilterMode,
    /// Filter between mip levels.
    pub mipmap_filter: FilterMode,
}

impl Default for SamplerDesc {
    /// Nearest filtering, clamped to the edge: WebGPU's defaults.
    fn default() -> Self {
        Self {
            address: [AddressMode::ClampToEdge; 3],
            mag_filter: FilterMode::Nearest,
            min_filter: FilterMode::Nearest,
            mipmap_filter: FilterMode::Nearest,
        }
    }
}

impl SamplerDesc {
    /// One filter and one address mode for every axis and case.
    pub fn uniform(filter: FilterMode, address: AddressMode) -> Self {
        Self { address: [address; 3], mag_filter: filter, min_filter: filter, mipmap_filter: filter }
    }
}
