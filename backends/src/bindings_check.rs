//! Checks every backend makes before a dispatch, so that a mistake becomes a clear
//! [`BackendError`] instead of a validation panic or a silent wrong result.
//!
//! Sizes and offsets here come from the caller: no arithmetic may wrap or panic (the
//! lint below refuses a plain `+`; sums are `checked_add`, and a sum that does not fit
//! is refused, naming its values).

#![deny(clippy::arithmetic_side_effects)]

use crate::backend::{Bind, BufferId, Resource};
use crate::device_info::DeviceInfo;
use crate::error::BackendError;
use crate::texture::{FilterMode, SamplerDesc, SamplerId, TextureDesc, TextureId};
use strata_kernels::{BindingInfo, BindingKind, Kernel, TexelKind};

/// Bytes of private and function memory per invocation a CPU driver (lavapipe) is given
/// a kernel with ([`Kernel::private_memory_bytes`]): llvmpipe compiles per-invocation
/// arrays slowly and into much memory. Measured on Mesa 22.3.6 with its shader cache
/// off, an `array<u32, N>` written at one index and read at another: 4 KiB compiled in
/// 10.7 s, 16 KiB took over a minute, 64 KiB over 100 s, and 512 MiB took 23 GB of
/// memory before it was killed (issue 58). The project's kernels take at most 1.3 KiB;
/// the interpreter has its own, larger cap, and a GPU's compiler spills such arrays to
/// memory.
pub const CPU_DRIVER_PRIVATE_BYTES: u64 = 4096;

/// Whether `device` can run `kernel`: features, workgroup size, workgroup memory, storage
/// buffer count, and on a CPU driver the private and function memory per invocation.
pub fn check_kernel_fits(kernel: &Kernel, device: &DeviceInfo) -> Result<(), BackendError> {
    let limits = &device.limits;
    if device.is_cpu_driver() {
        let requested = kernel.private_memory_bytes();
        if requested > CPU_DRIVER_PRIVATE_BYTES {
            return Err(BackendError::LimitExceeded {
                what: format!(
                    "kernel `{}` on a CPU driver, which compiles per-invocation arrays for minutes",
                    kernel.name()
                ),
                limit: "private and function memory bytes per invocation",
                requested,
                available: CPU_DRIVER_PRIVATE_BYTES,
            });
        }
    }
    if kernel.spec.features.subgroup && device.subgroup_sizes.is_none() {
        return Err(BackendError::MissingFeature {
            kernel: kernel.name().into(),
            feature: "subgroup operations".into(),
            device: device.summary(),
        });
    }
    let what = || format!("kernel `{}`", kernel.name());
    let exceeded = |limit, requested: u64, available: u64| {
        if requested > available {
            Err(BackendError::LimitExceeded { what: what(), limit, requested, available })
        } else {
            Ok(())
        }
    };
    exceeded(
        "invocations per workgroup",
        u64::from(kernel.invocations()),
        u64::from(limits.max_invocations_per_workgroup),
    )?;
    for (axis, (&size, &max)) in kernel.workgroup_size.iter().zip(&limits.max_workgroup_size).enumerate() {
        exceeded(["workgroup size x", "workgroup size y", "workgroup size z"][axis], u64::from(size), u64::from(max))?;
    }
    exceeded("workgroup memory bytes", kernel.workgroup_memory_bytes(), limits.max_workgroup_storage)?;
    exceeded("bind groups", u64::from(kernel.group_count()), u64::from(limits.max_bind_groups))?;
    let storage = kernel.bindings.iter().filter(|b| matches!(b.kind, BindingKind::Storage(_))).count();
    exceeded("storage buffers per stage", storage as u64, u64::from(limits.max_storage_buffers_per_stage))
}

/// How the checks look up a backend's resources: a buffer's size, a texture's
/// description, a sampler's description (each an error for an id the backend does not
/// own).
pub struct ResourceLookup<'a> {
    /// Size in bytes of a buffer.
    pub buffer_size: &'a dyn Fn(BufferId) -> Result<u64, BackendError>,
    /// What a texture was created as.
    pub texture: &'a dyn Fn(TextureId) -> Result<TextureDesc, BackendError>,
    /// What a sampler was created as.
    pub sampler: &'a dyn Fn(SamplerId) -> Result<SamplerDesc, BackendError>,
}

/// Whether `binds` bind every binding of `kernel` once, each with a resource of its kind:
/// buffers large enough and within the device's binding limits, textures of the shape,
/// texel kind and format the kernel declares, samplers where it samples, and no
/// filtering sampler sampling an integer texture (Vulkan leaves it undefined).
pub fn check_binds(
    kernel: &Kernel,
    binds: &[Bind],
    device: &DeviceInfo,
    lookup: &ResourceLookup,
) -> Result<(), BackendError> {
    let error = |(group, binding): (u32, u32), reason: String| BackendError::Binding {
        kernel: kernel.name().into(),
        binding,
        reason: if group == 0 { reason } else { format!("(group {group}) {reason}") },
    };
    for (index, bind) in binds.iter().enumerate() {
        if binds[..index].iter().any(|b| b.slot() == bind.slot()) {
            return Err(error(bind.slot(), "bound twice".into()));
        }
        if kernel.binding(bind.group, bind.binding).is_none() {
            return Err(error(bind.slot(), "the kernel has no such binding".into()));
        }
    }
    // One resource at several bindings: WebGPU allows it only when none of them writes
    // (a writable storage binding is an exclusive usage within a dispatch).
    for (index, bind) in binds.iter().enumerate() {
        for other in binds[..index].iter().filter(|b| b.resource == bind.resource) {
            let writes = |b: &Bind| kernel.binding(b.group, b.binding).is_some_and(|info| info.is_writable());
            if writes(bind) || writes(other) {
                return Err(error(
                    bind.slot(),
                    format!(
                        "its {} is also bound at binding {}, and one of them is writable",
                        bind.resource.describe(),
                        other.binding
                    ),
                ));
            }
        }
    }
    for info in &kernel.bindings {
        let slot = (info.group, info.binding);
        let bind = binds
            .iter()
            .find(|b| b.slot() == slot)
            .ok_or_else(|| error(slot, format!("`{}` is not bound", info.name)))?;
        let wrong_kind = || {
            error(
                slot,
                format!("`{}` is a {}, but {} is bound", info.name, info.element.type_name, bind.resource.describe()),
            )
        };
        match (info.kind, bind.resource) {
            (BindingKind::Uniform | BindingKind::Storage(_), Resource::Buffer(buffer)) => {
                check_buffer_binding(kernel, info, (lookup.buffer_size)(buffer)?, device)?;
            }
            (
                kind @ (BindingKind::SampledTexture { .. } | BindingKind::StorageTexture { .. }),
                Resource::Texture(texture),
            ) => {
                let desc = (lookup.texture)(texture)?;
                // A sampled texture takes any format of its texel kind, a storage texture
                // its own format alone.
                let fits = match kind {
                    BindingKind::SampledTexture { dimension, kind } => {
                        desc.dimension == dimension && desc.format.kind() == kind
                    }
                    BindingKind::StorageTexture { dimension, format, .. } => {
                        desc.dimension == dimension && desc.format == format
                    }
                    _ => unreachable!("matched as a texture"),
                };
                if !fits {
                    return Err(error(
                        slot,
                        format!(
                            "`{}` is a {}, but texture `{}` is a {} texture of {}",
                            info.name,
                            info.element.type_name,
                            desc.label,
                            desc.dimension.wgsl(),
                            desc.format.wgsl()
                        ),
                    ));
                }
            }
            (BindingKind::Sampler, Resource::Sampler(sampler)) => {
                (lookup.sampler)(sampler)?;
            }
            _ => return Err(wrong_kind()),
        }
    }
    check_filtering(kernel, binds, device, lookup)
}

/// Whether every sampler that filters linearly (magnifying, minifying or between mip
/// levels) samples only textures it may filter. An integer texel cannot be filtered:
/// Vulkan makes it undefined (VUID-vkCmdDispatch-magFilter-04553, -mipmapMode-04770) and
/// lavapipe and the interpreter returned numbers, WebGPU refuses it; so every path
/// refuses it here, naming the sampler binding, the texture binding and the format.
/// `r32float` and `rgba32float` are filterable only where the device says so
/// ([`DeviceInfo::float32_filterable`]; wgpu-gl on llvmpipe lacks `FLOAT32_FILTERABLE`
/// and wgpu refused the bind group in its own words): elsewhere the kernel is refused
/// as [`BackendError::MissingFeature`], naming both bindings, the format and the
/// feature, which `xtask run --backend all` lists as the path being unavailable.
/// `binds` are [`check_binds`]'s, already matched to the kernel's bindings.
fn check_filtering(
    kernel: &Kernel,
    binds: &[Bind],
    device: &DeviceInfo,
    lookup: &ResourceLookup,
) -> Result<(), BackendError> {
    let info = |slot: (u32, u32)| kernel.binding(slot.0, slot.1);
    let bound = |slot: (u32, u32)| binds.iter().find(|b| b.slot() == slot).map(|b| b.resource);
    // The IR walk only where a texture that may be unfilterable and a sampler are both
    // bound.
    let unfilterable = |b: &BindingInfo| match b.kind {
        BindingKind::SampledTexture { kind, .. } => kind != TexelKind::Float || !device.float32_filterable,
        _ => false,
    };
    if !kernel.bindings.iter().any(unfilterable) || !kernel.bindings.iter().any(|b| b.kind == BindingKind::Sampler) {
        return Ok(());
    }
    for pair in strata_kernels::combined_samplers::sampled_pairs(kernel) {
        let (Some(Resource::Texture(texture)), Some(Resource::Sampler(sampler))) =
            (bound(pair.texture), bound(pair.sampler))
        else {
            continue;
        };
        let desc = (lookup.sampler)(sampler)?;
        let filters = [desc.mag_filter, desc.min_filter, desc.mipmap_filter].contains(&FilterMode::Linear);
        let texture_desc = (lookup.texture)(texture)?;
        let format = texture_desc.format;
        let float = format.kind() == TexelKind::Float;
        if !filters || (float && (format.filterable() || device.float32_filterable)) {
            continue;
        }
        let name = |slot: (u32, u32)| info(slot).map_or_else(String::new, |b| format!("`{}` ", b.name));
        let at = |slot: (u32, u32)| match slot {
            (0, binding) => format!("binding {binding}"),
            (group, binding) => format!("group {group} binding {binding}"),
        };
        if float {
            return Err(BackendError::MissingFeature {
                kernel: kernel.name().into(),
                feature: format!(
                    "linear filtering of {} (sampler {}({}) filters texture {}({})), the feature \
                     FLOAT32_FILTERABLE (or give that sampler nearest filtering)",
                    format.wgsl(),
                    name(pair.sampler),
                    at(pair.sampler),
                    name(pair.texture),
                    at(pair.texture),
                ),
                device: device.summary(),
            });
        }
        return Err(BackendError::Binding {
            kernel: kernel.name().into(),
            binding: pair.sampler.1,
            reason: format!(
                "sampler {}({}) filters linearly, but it samples texture {}({}) of {}, an integer format no \
                 sampler may filter (Vulkan's VUID-vkCmdDispatch-magFilter-04553): give that sampler nearest \
                 filtering",
                name(pair.sampler),
                at(pair.sampler),
                name(pair.texture),
                at(pair.texture),
                texture_desc.format.wgsl()
            ),
        });
    }
    Ok(())
}

/// Whether a buffer of `size` bytes fits buffer binding `info`.
fn check_buffer_binding(
    kernel: &Kernel,
    info: &BindingInfo,
    size: u64,
    device: &DeviceInfo,
) -> Result<(), BackendError> {
    if size < info.min_size() {
        return Err(BackendError::Binding {
            kernel: kernel.name().into(),
            binding: info.binding,
            reason: format!(
                "`{}` needs at least {} bytes ({} of {}), the buffer has {size}",
                info.name,
                info.min_size(),
                info.element.count.unwrap_or(1),
                info.element.type_name
            ),
        });
    }
    let (limit, available) = match info.kind {
        BindingKind::Uniform => ("uniform binding bytes", device.limits.max_uniform_binding),
        _ => ("storage binding bytes", device.limits.max_storage_binding),
    };
    if size > available {
        return Err(BackendError::LimitExceeded {
            what: format!("kernel `{}` binding `{}`", kernel.name(), info.name),
            limit,
            requested: size,
            available,
        });
    }
    Ok(())
}

/// Whether the device accepts `workgroups` in one dispatch.
pub fn check_workgroups(kernel: &Kernel, workgroups: [u32; 3], device: &DeviceInfo) -> Result<(), BackendError> {
    for &count in &workgroups {
        if u64::from(count) > u64::from(device.limits.max_workgroups_per_dimension) {
            return Err(BackendError::LimitExceeded {
                what: format!("dispatch of `{}`", kernel.name()),
                limit: "workgroups per dimension",
                requested: u64::from(count),
                available: u64::from(device.limits.max_workgroups_per_dimension),
            });
        }
    }
    Ok(())
}

/// Whether a buffer of `size` bytes can be created: at least one byte, at most the
/// device's buffer size.
pub fn check_buffer_size(label: &str, size: u64, device: &DeviceInfo) -> Result<(), BackendError> {
    if size == 0 {
        return Err(BackendError::Buffer {
            label: label.into(),
            reason: "size 0: buffers must hold at least one byte".into(),
        });
    }
    if size.checked_next_multiple_of(4).is_none() {
        return Err(BackendError::Buffer {
            label: label.into(),
            reason: format!("size {size}: rounded up to whole 4-byte words it passes u64::MAX"),
        });
    }
    if size > device.limits.max_buffer_size {
        return Err(BackendError::LimitExceeded {
            what: format!("buffer `{label}`"),
            limit: "buffer bytes",
            requested: size,
            available: device.limits.max_buffer_size,
        });
    }
    Ok(())
}

/// Whether `len` bytes can be written at `offset` into a buffer of `size` bytes: both
/// multiples of 4, and `offset + len` at most `size` without wrapping (an end past
/// `u64::MAX` is refused, naming the values, never wrapped around into the buffer).
/// What a backend's write may rely on: on `Ok`, `offset..offset + len` lies in `0..size`.
pub fn check_write(label: &str, size: u64, offset: u64, len: usize) -> Result<(), BackendError> {
    let refuse = |reason: String| Err(BackendError::Buffer { label: label.into(), reason });
    if !offset.is_multiple_of(4) || !len.is_multiple_of(4) {
        return refuse(format!(
            "write of {len} bytes at offset {offset} into {size} bytes (offset and length must be multiples of 4)"
        ));
    }
    let Some(end) = u64::try_from(len).ok().and_then(|len| offset.checked_add(len)) else {
        return refuse(format!(
            "write of {len} bytes at offset {offset}: its end lies past the end of u64 ({}), \
             so it cannot lie inside the buffer's {size} bytes",
            u64::MAX
        ));
    };
    if end > size {
        return refuse(format!("write of {len} bytes at offset {offset} into {size} bytes: it ends at byte {end}"));
    }
    Ok(())
}

/// The byte range `offset..offset + len` of a write into a buffer of `size` bytes, as
/// [`check_write`] accepts it, in `usize` for indexing the buffer's memory: an error
/// where `check_write` refuses the write or the range does not fit in `usize`. On `Ok`
/// the range lies inside `0..size`.
pub fn write_range(label: &str, size: u64, offset: u64, len: usize) -> Result<std::ops::Range<usize>, BackendError> {
    check_write(label, size, offset, len)?;
    let start = usize::try_from(offset).ok();
    match start.and_then(|start| start.checked_add(len).map(|end| start..end)) {
        Some(range) => Ok(range),
        None => Err(BackendError::Buffer {
            label: label.into(),
            reason: format!("write of {len} bytes at offset {offset}: the offset does not fit in this machine's usize"),
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::{check_write, write_range};

    #[test]
    fn a_write_whose_end_wraps_past_u64_max_is_refused() {
        // offset + len wraps to 0 (u64::MAX - 3 + 4): an unchecked sum passed it, and the
        // ash backend then copied to `mapped + offset`, 4 bytes before the mapping.
        let error = check_write("target", 16, u64::MAX - 3, 4).expect_err("a wrapped range is refused");
        let message = error.to_string();
        assert!(message.contains("18446744073709551612"), "{message}");
        assert!(message.contains("past the end of u64"), "{message}");
        // Every other wrapped end too (the sum lands inside the buffer).
        assert!(check_write("target", 16, u64::MAX - 7, 16).is_err());
        assert!(check_write("target", 64, 1 << 63, 0).is_err());
    }

    #[test]
    fn writes_inside_the_buffer_and_up_to_its_end_pass() {
        assert!(check_write("target", 16, 0, 16).is_ok());
        assert!(check_write("target", 16, 12, 4).is_ok());
        assert!(check_write("target", 16, 16, 0).is_ok());
        assert!(check_write("target", 16, 16, 4).is_err());
        assert!(check_write("target", 16, 2, 4).is_err());
        assert!(check_write("target", 16, 0, 6).is_err());
        assert_eq!(write_range("target", 16, 8, 8).unwrap(), 8..16);
        assert!(write_range("target", 16, u64::MAX - 3, 4).is_err());
    }
}
