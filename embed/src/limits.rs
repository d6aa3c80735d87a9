//! What the pass needs of a device, checked at configuration time against the device's
//! limits (the same numbers for the wgpu and ash flavours).

use crate::contract::BufferRole;
use crate::error::EmbedError;
use crate::wgsl::{ModuleId, module};

/// A device's limits, in the units both APIs share.
#[derive(Clone, Copy, Debug)]
pub(crate) struct DeviceLimits {
    pub storage_buffers_per_stage: u64,
    pub workgroup_storage_bytes: u64,
    pub invocations_per_workgroup: u64,
    pub workgroup_size_x: u64,
    pub workgroup_size_y: u64,
    pub workgroups_per_dimension: u64,
    pub storage_binding_bytes: u64,
}

/// Names of the limits in each API.
pub(crate) struct LimitNames {
    pub storage_buffers_per_stage: &'static str,
    pub workgroup_storage_bytes: &'static str,
    pub invocations_per_workgroup: &'static str,
    pub workgroup_size_x: &'static str,
    pub workgroup_size_y: &'static str,
    pub workgroups_per_dimension: &'static str,
    pub storage_binding_bytes: &'static str,
}

fn need(limit: &'static str, available: u64, needed: u64, why: impl FnOnce() -> String) -> Result<(), EmbedError> {
    if available < needed {
        return Err(EmbedError::DeviceLimit { limit, available, needed, why: why() });
    }
    Ok(())
}

/// Checks every limit the pass needs for a `width` × `height` image with `histogram`.
pub(crate) fn check_limits(
    limits: DeviceLimits,
    names: &LimitNames,
    histogram: ModuleId,
    width: u32,
    height: u32,
    blocks: u64,
) -> Result<(), EmbedError> {
    for id in [histogram, ModuleId::Select, ModuleId::Resample] {
        let module = module(id)?;
        let storage = module.bindings.iter().filter(|b| !b.uniform).count() as u64;
        let name = &module.entry_point;
        need(names.storage_buffers_per_stage, limits.storage_buffers_per_stage, storage, || {
            format!("`{name}` binds {storage} storage buffers")
        })?;
        need(names.workgroup_storage_bytes, limits.workgroup_storage_bytes, module.workgroup_memory_bytes, || {
            format!("`{name}` keeps 1024 sort slots of every block size in workgroup memory")
        })?;
        let [x, y, z] = module.workgroup_size;
        need(names.invocations_per_workgroup, limits.invocations_per_workgroup, u64::from(x * y * z), || {
            format!("`{name}` has @workgroup_size({x}, {y}, {z})")
        })?;
        need(names.workgroup_size_x, limits.workgroup_size_x, u64::from(x), || format!("`{name}`"))?;
        need(names.workgroup_size_y, limits.workgroup_size_y, u64::from(y), || format!("`{name}`"))?;
    }
    let widest = u64::from(width.div_ceil(8).max(height.div_ceil(8)));
    need(names.workgroups_per_dimension, limits.workgroups_per_dimension, widest, || {
        format!("a {width}x{height} image in 8x8-pixel workgroups")
    })?;
    let largest = BufferRole::ALL
        .iter()
        .map(|role| (role.size(width, height), role.name()))
        .chain([(blocks * 12, "block_stats")])
        .max()
        .unwrap_or((0, ""));
    need(names.storage_binding_bytes, limits.storage_binding_bytes, largest.0, || {
        format!("buffer `{}` of a {width}x{height} image", largest.1)
    })
}

#[cfg(feature = "wgpu")]
impl DeviceLimits {
    pub(crate) fn wgpu(limits: &wgpu::Limits) -> Self {
        Self {
            storage_buffers_per_stage: limits.max_storage_buffers_per_shader_stage.into(),
            workgroup_storage_bytes: limits.max_compute_workgroup_storage_size.into(),
            invocations_per_workgroup: limits.max_compute_invocations_per_workgroup.into(),
            workgroup_size_x: limits.max_compute_workgroup_size_x.into(),
            workgroup_size_y: limits.max_compute_workgroup_size_y.into(),
            workgroups_per_dimension: limits.max_compute_workgroups_per_dimension.into(),
            storage_binding_bytes: limits.max_storage_buffer_binding_size,
        }
    }
}

/// wgpu's names of the limits.
#[cfg(feature = "wgpu")]
pub(crate) const WGPU_NAMES: LimitNames = LimitNames {
    storage_buffers_per_stage: "max_storage_buffers_per_shader_stage",
    workgroup_storage_bytes: "max_compute_workgroup_storage_size",
    invocations_per_workgroup: "max_compute_invocations_per_workgroup",
    workgroup_size_x: "max_compute_workgroup_size_x",
    workgroup_size_y: "max_compute_workgroup_size_y",
    workgroups_per_dimension: "max_compute_workgroups_per_dimension",
    storage_binding_bytes: "max_storage_buffer_binding_size",
};

#[cfg(feature = "ash")]
impl DeviceLimits {
    pub(crate) fn vulkan(limits: &ash::vk::PhysicalDeviceLimits) -> Self {
        Self {
            storage_buffers_per_stage: limits.max_per_stage_descriptor_storage_buffers.into(),
            workgroup_storage_bytes: limits.max_compute_shared_memory_size.into(),
            invocations_per_workgroup: limits.max_compute_work_group_invocations.into(),
            workgroup_size_x: limits.max_compute_work_group_size[0].into(),
            workgroup_size_y: limits.max_compute_work_group_size[1].into(),
            workgroups_per_dimension: limits.max_compute_work_group_count.iter().copied().min().unwrap_or(0).into(),
            storage_binding_bytes: limits.max_storage_buffer_range.into(),
        }
    }
}

/// Vulkan's names of the limits.
#[cfg(feature = "ash")]
pub(crate) const VULKAN_NAMES: LimitNames = LimitNames {
    storage_buffers_per_stage: "maxPerStageDescriptorStorageBuffers",
    workgroup_storage_bytes: "maxComputeSharedMemorySize",
    invocations_per_workgroup: "maxComputeWorkGroupInvocations",
    workgroup_size_x: "maxComputeWorkGroupSize[0]",
    workgroup_size_y: "maxComputeWorkGroupSize[1]",
    workgroups_per_dimension: "maxComputeWorkGroupCount",
    storage_binding_bytes: "maxStorageBufferRange",
};
