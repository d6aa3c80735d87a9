//! What a texture binding of a kernel is, read from naga's IR: its dimension, the kind of
//! its texels and, for a storage texture, its format and access. The backends size,
//! convert and compare texels from these, so each fact is stated once here.

/// The shape of a texture binding (`texture_1d`, `texture_2d`, `texture_2d_array`,
/// `texture_3d`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TextureDimension {
    /// `texture_1d`, `texture_storage_1d`.
    D1,
    /// `texture_2d`, `texture_storage_2d`.
    D2,
    /// `texture_2d_array`, `texture_storage_2d_array`: 2-D layers.
    D2Array,
    /// `texture_3d`, `texture_storage_3d`.
    D3,
}

impl TextureDimension {
    /// The dimension of a naga image type; `None` for cube maps.
    pub fn of(dim: naga::ImageDimension, arrayed: bool) -> Option<Self> {
        match (dim, arrayed) {
            (naga::ImageDimension::D1, false) => Some(Self::D1),
            (naga::ImageDimension::D2, false) => Some(Self::D2),
            (naga::ImageDimension::D2, true) => Some(Self::D2Array),
            (naga::ImageDimension::D3, false) => Some(Self::D3),
            _ => None,
        }
    }

    /// How many coordinates address a texel within a layer (1, 2 or 3).
    pub fn coordinates(self) -> u32 {
        match self {
            Self::D1 => 1,
            Self::D2 | Self::D2Array => 2,
            Self::D3 => 3,
        }
    }

    /// WGSL's name of the sampled texture type's shape (`2d_array`, ...).
    pub fn wgsl(self) -> &'static str {
        match self {
            Self::D1 => "1d",
            Self::D2 => "2d",
            Self::D2Array => "2d_array",
            Self::D3 => "3d",
        }
    }
}

/// What a texel's components are read as in WGSL (`f32`, `i32`, `u32`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TexelKind {
    /// `f32` components (float, unorm and snorm formats).
    Float,
    /// `i32` components.
    Sint,
    /// `u32` components.
    Uint,
}

/// A texel format a kernel can bind: the storage formats every backend of the project
/// supports, and what a sampled texture is created with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TexelFormat {
    /// Four 8-bit unsigned normalised components (`c / 255` when read).
    Rgba8Unorm,
    /// Four 8-bit unsigned integers.
    Rgba8Uint,
    /// Four IEEE binary16 floats.
    Rgba16Float,
    /// Four IEEE binary32 floats.
    Rgba32Float,
    /// One IEEE binary32 float.
    R32Float,
    /// One 32-bit unsigned integer.
    R32Uint,
    /// One 32-bit signed integer.
    R32Sint,
}

impl TexelFormat {
    /// Every format, in the order the documentation lists them.
    pub const ALL: [TexelFormat; 7] = [
        Self::Rgba8Unorm,
        Self::Rgba8Uint,
        Self::Rgba16Float,
        Self::Rgba32Float,
        Self::R32Float,
        Self::R32Uint,
        Self::R32Sint,
    ];

    /// The format of a naga storage texture; `None` for one the project does not support.
    pub fn of(format: naga::StorageFormat) -> Option<Self> {
        use naga::StorageFormat as F;
        Some(match format {
            F::Rgba8Unorm => Self::Rgba8Unorm,
            F::Rgba8Uint => Self::Rgba8Uint,
            F::Rgba16Float => Self::Rgba16Float,
            F::Rgba32Float => Self::Rgba32Float,
            F::R32Float => Self::R32Float,
            F::R32Uint => Self::R32Uint,
            F::R32Sint => Self::R32Sint,
            _ => return None,
        })
    }

    /// Its WGSL name (`rgba8unorm`, ...), as `--storage-texture` and messages spell it.
    pub fn wgsl(self) -> &'static str {
        match self {
            Self::Rgba8Unorm => "rgba8unorm",
            Self::Rgba8Uint => "rgba8uint",
            Self::Rgba16Float => "rgba16float",
            Self::Rgba32Float => "rgba32float",
            Self::R32Float => "r32float",
            Self::R32Uint => "r32uint",
            Self::R32Sint => "r32sint",
        }
    }

    /// The format named `name` in WGSL's spelling.
    pub fn from_wgsl(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|f| f.wgsl() == name)
    }

    /// Bytes of one texel.
    pub fn bytes_per_texel(self) -> u32 {
        match self {
            Self::Rgba8Unorm | Self::Rgba8Uint | Self::R32Float | Self::R32Uint | Self::R32Sint => 4,
            Self::Rgba16Float => 8,
            Self::Rgba32Float => 16,
        }
    }

    /// Components stored per texel (1 or 4); a load fills the others as Vulkan does
    /// (0 for green and blue, 1 for alpha).
    pub fn components(self) -> u32 {
        match self {
            Self::R32Float | Self::R32Uint | Self::R32Sint => 1,
            _ => 4,
        }
    }

    /// What WGSL reads its components as.
    pub fn kind(self) -> TexelKind {
        match self {
            Self::Rgba8Uint | Self::R32Uint => TexelKind::Uint,
            Self::R32Sint => TexelKind::Sint,
            _ => TexelKind::Float,
        }
    }

    /// Whether a sampler may filter it linearly (WebGPU: the float formats but
    /// `r32float` and `rgba32float`, which are unfilterable without a feature).
    pub fn filterable(self) -> bool {
        matches!(self, Self::Rgba8Unorm | Self::Rgba16Float)
    }
}

/// How a kernel may use a storage texture.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum StorageTextureAccess {
    /// `read`.
    Read,
    /// `write`.
    Write,
    /// `read_write`.
    ReadWrite,
}

impl StorageTextureAccess {
    /// The access of a naga storage texture.
    pub fn of(access: naga::StorageAccess) -> Self {
        let load = access.contains(naga::StorageAccess::LOAD);
        let store = access.contains(naga::StorageAccess::STORE);
        match (load, store) {
            (true, true) => Self::ReadWrite,
            (false, true) => Self::Write,
            _ => Self::Read,
        }
    }

    /// Whether the kernel may write through it.
    pub fn writes(self) -> bool {
        self != Self::Read
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_format_round_trips_through_its_wgsl_name() {
        for format in TexelFormat::ALL {
            assert_eq!(TexelFormat::from_wgsl(format.wgsl()), Some(format));
            assert_eq!(format.bytes_per_texel() % 4, 0, "{format:?} fills whole words");
        }
        assert_eq!(TexelFormat::from_wgsl("bgra8unorm"), None);
    }
}
