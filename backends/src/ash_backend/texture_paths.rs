//! Which texture bindings each translated path of the ash backend can bind, and why
//! not where it cannot: a one-line refusal naming the binding, its type and the path,
//! instead of a pipeline whose descriptor layout disagrees with its shader (which
//! crashes drivers rather than failing).

use super::SpirvSource;
use crate::error::BackendError;
use strata_kernels::{BindingInfo, BindingKind, Kernel};

/// Why `source` cannot bind `binding`, if it cannot.
fn refusal(source: SpirvSource, binding: &BindingInfo) -> Option<&'static str> {
    match (source, binding.kind) {
        (SpirvSource::Naga, _) => None,
        (SpirvSource::SlangFromHlsl, BindingKind::StorageTexture { format, .. }) if format.components() == 1 => Some(
            "naga's HLSL stores a 4-component value into a one-component RWTexture, which DXC truncates and \
             Slang rejects",
        ),
        _ => None,
    }
}

/// Whether `source` can bind every texture and sampler of `kernel`.
pub(super) fn check_texture_bindings(source: SpirvSource, kernel: &Kernel) -> Result<(), BackendError> {
    match kernel.bindings.iter().find_map(|b| refusal(source, b).map(|why| (b, why))) {
        None => Ok(()),
        Some((binding, why)) => Err(BackendError::unavailable_binding(source.name(), kernel, binding, why)),
    }
}
