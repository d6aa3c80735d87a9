//! What opening the ash backend's device needs besides the device itself: the choice of
//! physical device and the long-lived per-device objects (command pool and buffer, fence,
//! timestamp queries), each destroyed if opening fails half-way.

use super::{AshOptions, vk_error};
use crate::error::BackendError;
use ash::vk;

/// The device's long-lived objects while they are being created.
#[derive(Default)]
pub(super) struct DeviceObjects {
    pub(super) command_pool: Option<vk::CommandPool>,
    pub(super) command_buffer: Option<vk::CommandBuffer>,
    pub(super) fence: Option<vk::Fence>,
    pub(super) query_pool: Option<vk::QueryPool>,
}

impl DeviceObjects {
    pub(super) fn create(&mut self, device: &ash::Device, family: u32, timestamps: bool) -> Result<(), BackendError> {
        // SAFETY: valid device; on error the caller destroys what was created.
        unsafe {
            let pool = device
                .create_command_pool(
                    &vk::CommandPoolCreateInfo::default()
                        .queue_family_index(family)
                        .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER),
                    None,
                )
                .map_err(|e| vk_error("creating the command pool", e))?;
            self.command_pool = Some(pool);
            let buffers = device
                .allocate_command_buffers(
                    &vk::CommandBufferAllocateInfo::default()
                        .command_pool(pool)
                        .level(vk::CommandBufferLevel::PRIMARY)
                        .command_buffer_count(1),
                )
                .map_err(|e| vk_error("allocating a command buffer", e))?;
            self.command_buffer = Some(buffers[0]);
            self.fence = Some(
                device
                    .create_fence(&vk::FenceCreateInfo::default(), None)
                    .map_err(|e| vk_error("creating a fence", e))?,
            );
            if timestamps {
                self.query_pool = Some(
                    device
                        .create_query_pool(
                            &vk::QueryPoolCreateInfo::default().query_type(vk::QueryType::TIMESTAMP).query_count(2),
                            None,
                        )
                        .map_err(|e| vk_error("creating the timestamp query pool", e))?,
                );
            }
        }
        Ok(())
    }

    pub(super) fn destroy(&mut self, device: &ash::Device) {
        // SAFETY: nothing was submitted; each object is destroyed once.
        unsafe {
            if let Some(pool) = self.query_pool.take() {
                device.destroy_query_pool(pool, None);
            }
            if let Some(fence) = self.fence.take() {
                device.destroy_fence(fence, None);
            }
            if let Some(pool) = self.command_pool.take() {
                device.destroy_command_pool(pool, None);
            }
        }
    }
}

/// The best physical device with a compute queue and Vulkan 1.1: discrete first, CPU last.
pub(super) fn pick_device(
    instance: &ash::Instance,
    options: &AshOptions,
) -> Result<(vk::PhysicalDevice, u32), BackendError> {
    // SAFETY: plain enumeration.
    let devices = unsafe { instance.enumerate_physical_devices() }.map_err(|e| vk_error("enumerating devices", e))?;
    let rank = |kind: vk::PhysicalDeviceType| match kind {
        vk::PhysicalDeviceType::DISCRETE_GPU => 0,
        vk::PhysicalDeviceType::INTEGRATED_GPU => 1,
        vk::PhysicalDeviceType::VIRTUAL_GPU => 2,
        vk::PhysicalDeviceType::CPU => 3,
        _ => 4,
    };
    let mut best = None;
    for device in devices {
        // SAFETY: valid handle from enumeration.
        let properties = unsafe { instance.get_physical_device_properties(device) };
        if properties.api_version < vk::API_VERSION_1_1 {
            continue;
        }
        let families = unsafe { instance.get_physical_device_queue_family_properties(device) };
        let Some(family) = families.iter().position(|f| f.queue_flags.contains(vk::QueueFlags::COMPUTE)) else {
            continue;
        };
        let key = rank(properties.device_type);
        if best.is_none_or(|(k, _, _)| key < k) {
            best = Some((key, device, family as u32));
        }
    }
    best.map(|(_, device, family)| (device, family)).ok_or_else(|| BackendError::NoAdapter {
        backend: options.source.name().into(),
        reason: "no Vulkan 1.1 device with a compute queue".into(),
    })
}
