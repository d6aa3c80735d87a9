//! A kernel's resource bindings, read from naga's IR (never maintained by hand).

use crate::texture::{StorageTextureAccess, TexelFormat, TexelKind, TextureDimension};
use crate::word_kinds::WordKinds;
use naga::proc::Layouter;

/// What is bound: a uniform or storage buffer, a texture or a sampler.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BindingKind {
    /// `var<uniform>`.
    Uniform,
    /// `var<storage, ...>`.
    Storage(BindingAccess),
    /// `var t: texture_1d<T>` ... `texture_3d<T>`: a sampled texture, read with
    /// `textureLoad` and the `textureSample*` built-ins.
    SampledTexture {
        /// Its shape.
        dimension: TextureDimension,
        /// What its components read as (`T`).
        kind: TexelKind,
    },
    /// `var t: texture_storage_*<format, access>`.
    StorageTexture {
        /// Its shape.
        dimension: TextureDimension,
        /// Its texel format.
        format: TexelFormat,
        /// `read`, `write` or `read_write`.
        access: StorageTextureAccess,
    },
    /// `var s: sampler` (filtering and addressing of `textureSample*`).
    Sampler,
}

impl BindingKind {
    /// Whether a buffer (uniform or storage) is bound here.
    pub fn is_buffer(self) -> bool {
        matches!(self, Self::Uniform | Self::Storage(_))
    }

    /// Whether a texture (sampled or storage) is bound here.
    pub fn is_texture(self) -> bool {
        matches!(self, Self::SampledTexture { .. } | Self::StorageTexture { .. })
    }
}

/// Access mode of a storage buffer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BindingAccess {
    /// `read`.
    ReadOnly,
    /// `read_write`.
    ReadWrite,
}

/// Layout of what a binding holds: one value, or an array of elements.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ElementLayout {
    /// WGSL name of the element type (`u32`, `Candidate`, ...).
    pub type_name: String,
    /// Bytes between consecutive elements (the array stride; the size for one value).
    pub stride: u32,
    /// Required alignment of the element.
    pub align: u32,
    /// `Some(n)` for a fixed array of n elements or a single value (n = 1), `None` for a
    /// runtime-sized array.
    pub count: Option<u32>,
}

/// One `@group(g) @binding(b)` resource used by a kernel's entry point.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BindingInfo {
    /// WGSL group (Vulkan descriptor set). Registry kernels use group 0 only.
    pub group: u32,
    /// WGSL binding.
    pub binding: u32,
    /// Variable name in the WGSL source.
    pub name: String,
    /// Uniform or storage, with its access.
    pub kind: BindingKind,
    /// What the buffer holds.
    pub element: ElementLayout,
    /// What each 32-bit word holds (f32, integer, padding), for comparing outputs.
    pub words: WordKinds,
}

impl BindingInfo {
    /// Smallest buffer size in bytes the binding accepts (one element for runtime arrays).
    pub fn min_size(&self) -> u64 {
        u64::from(self.element.stride) * u64::from(self.element.count.unwrap_or(1))
    }

    /// Whether the kernel may write the buffer.
    pub fn is_writable(&self) -> bool {
        match self.kind {
            BindingKind::Storage(access) => access == BindingAccess::ReadWrite,
            BindingKind::StorageTexture { access, .. } => access.writes(),
            _ => false,
        }
    }
}

/// Name WGSL gives a type, for messages and checks.
pub fn type_name(module: &naga::Module, ty: naga::Handle<naga::Type>) -> String {
    use naga::common::wgsl::TypeContext;
    module.to_ctx().type_to_string(ty)
}

/// Describes the contents of the type `ty` for a buffer binding.
pub(crate) fn element_layout(
    module: &naga::Module,
    layouter: &Layouter,
    ty: naga::Handle<naga::Type>,
) -> ElementLayout {
    match module.types[ty].inner {
        naga::TypeInner::Array { base, size, stride } => ElementLayout {
            type_name: type_name(module, base),
            stride,
            align: layouter[base].alignment * 1,
            count: match size {
                naga::ArraySize::Constant(n) => Some(n.get()),
                _ => None,
            },
        },
        _ => ElementLayout {
            type_name: type_name(module, ty),
            stride: layouter[ty].size,
            align: layouter[ty].alignment * 1,
            count: Some(1),
        },
    }
}
