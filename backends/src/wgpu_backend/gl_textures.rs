//! The texture bindings wgpu's GL back end cannot run correctly, refused by name before
//! a dispatch (measured on Mesa's GLES 3.2 with wgpu 30 and naga 30; everything else the
//! texture corpus covers agrees with the interpreter there).

use crate::error::BackendError;
use strata_kernels::{BindingKind, Kernel, TextureDimension};

/// Why wgpu-gl cannot run `kernel`, if it cannot.
pub(super) fn check_gl_textures(kernel: &Kernel) -> Result<(), BackendError> {
    for binding in &kernel.bindings {
        let why = match binding.kind {
            BindingKind::SampledTexture { dimension: TextureDimension::D1, .. }
            | BindingKind::StorageTexture { dimension: TextureDimension::D1, .. } => {
                "GLES has no 1-D textures; wgpu emulates them with 2-D ones and the loads and sizes came back wrong \
                 (textureDimensions 1 for an 8-texel texture, texels 0)"
            }
            BindingKind::StorageTexture { dimension: TextureDimension::D3, .. } => {
                "wgpu's GL back end binds one slice of a 3-D storage texture: stores to the other slices were lost"
            }
            _ => continue,
        };
        return Err(BackendError::unavailable_binding("wgpu-gl", kernel, binding, why));
    }
    Ok(())
}
