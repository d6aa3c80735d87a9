//! Vulkan instance, device, queue, memory and command submission for the ash backend.

use super::device_setup::{DeviceObjects, pick_device};
use super::{AshOptions, vk_error};
use crate::device_info::{DeviceInfo, DeviceLimits};
use crate::error::BackendError;
use ash::vk;
use std::ffi::{CStr, c_void};
use std::sync::{Arc, Mutex};
use std::time::Duration;
use strata_kernels::Kernel;

const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";

type Messages = Arc<Mutex<Vec<String>>>;

unsafe extern "system" fn on_validation_message(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    _types: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user: *mut c_void,
) -> vk::Bool32 {
    // SAFETY: `user` is the `Messages` box owned by VulkanDevice, alive until the
    // messenger is destroyed; `data` is valid for the duration of the call.
    unsafe {
        let messages = &*(user as *const Messages);
        let text = if data.is_null() || (*data).p_message.is_null() {
            "<no message>".to_string()
        } else {
            CStr::from_ptr((*data).p_message).to_string_lossy().into_owned()
        };
        if let Ok(mut list) = messages.lock() {
            list.push(format!("{severity:?}: {text}"));
        }
    }
    vk::FALSE
}

/// What one binding of a dispatch receives.
#[derive(Clone, Copy)]
pub(super) enum Descriptor {
    /// A uniform or storage buffer, whole.
    Buffer(vk::Buffer),
    /// A sampled or storage image view (in `GENERAL` layout).
    Image(vk::ImageView),
    /// A combined image sampler: a view and the sampler state it is read with.
    Combined(vk::ImageView, vk::Sampler),
    /// A sampler.
    Sampler(vk::Sampler),
}

/// The Vulkan objects a dispatch binds, as [`super::pipelines`] creates them per kernel.
#[derive(Clone, Copy)]
pub(super) struct ComputePipeline<'a> {
    /// The descriptor-set layouts, set 0 first.
    pub(super) set_layouts: &'a [vk::DescriptorSetLayout],
    /// The pipeline layout.
    pub(super) layout: vk::PipelineLayout,
    /// The compute pipeline.
    pub(super) pipeline: vk::Pipeline,
}

pub(super) struct VulkanDevice {
    _entry: ash::Entry,
    instance: ash::Instance,
    debug: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT, Box<Messages>)>,
    physical: vk::PhysicalDevice,
    pub(super) device: ash::Device,
    queue: vk::Queue,
    memory_type: u32,
    command_pool: vk::CommandPool,
    command_buffer: vk::CommandBuffer,
    fence: vk::Fence,
    query_pool: Option<vk::QueryPool>,
    timestamp_period: f64,
    subgroup_size: Option<u32>,
    /// The driver zero-initialises workgroup memory (`shaderZeroInitializeWorkgroupMemory`).
    pub(super) native_zero_init: bool,
}

impl VulkanDevice {
    pub(super) fn open(options: &AshOptions) -> Result<Self, BackendError> {
        // SAFETY: loading the system Vulkan loader; failure is reported, not assumed.
        let entry = unsafe { ash::Entry::load() }.map_err(|e| BackendError::NoAdapter {
            backend: options.source.name().into(),
            reason: format!("no Vulkan loader: {e}"),
        })?;
        let mut layers = Vec::new();
        let mut extensions = Vec::new();
        if options.validation {
            // SAFETY: plain enumeration.
            let available = unsafe { entry.enumerate_instance_layer_properties() }
                .map_err(|e| vk_error("enumerating layers", e))?;
            let found =
                available.iter().any(|layer| layer.layer_name_as_c_str().is_ok_and(|name| name == VALIDATION_LAYER));
            if !found {
                return Err(BackendError::DeviceCreation {
                    backend: options.source.name().into(),
                    reason: "validation requested but VK_LAYER_KHRONOS_validation is not installed \
                             (Debian: apt-get install vulkan-validationlayers)"
                        .into(),
                });
            }
            layers.push(VALIDATION_LAYER.as_ptr());
            extensions.push(ash::ext::debug_utils::NAME.as_ptr());
        }
        let app = vk::ApplicationInfo::default().application_name(c"strata").api_version(vk::API_VERSION_1_3);
        let create = vk::InstanceCreateInfo::default()
            .application_info(&app)
            .enabled_layer_names(&layers)
            .enabled_extension_names(&extensions);
        // SAFETY: valid create info with static strings.
        let instance = unsafe { entry.create_instance(&create, None) }.map_err(|e| BackendError::NoAdapter {
            backend: options.source.name().into(),
            reason: format!("vkCreateInstance failed: {e:?}"),
        })?;
        let mut this_debug = None;
        if options.validation {
            let messages: Box<Messages> = Box::default();
            let utils = ash::ext::debug_utils::Instance::new(&entry, &instance);
            let info = vk::DebugUtilsMessengerCreateInfoEXT::default()
                .message_severity(
                    vk::DebugUtilsMessageSeverityFlagsEXT::WARNING | vk::DebugUtilsMessageSeverityFlagsEXT::ERROR,
                )
                .message_type(
                    vk::DebugUtilsMessageTypeFlagsEXT::GENERAL
                        | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                        | vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE,
                )
                .pfn_user_callback(Some(on_validation_message))
                .user_data(&*messages as *const Messages as *mut c_void);
            // SAFETY: the callback's user data outlives the messenger (both in `debug`).
            match unsafe { utils.create_debug_utils_messenger(&info, None) } {
                Ok(messenger) => this_debug = Some((utils, messenger, messages)),
                Err(e) => {
                    // SAFETY: nothing else was created from the instance.
                    unsafe { instance.destroy_instance(None) };
                    return Err(vk_error("creating the debug messenger", e));
                }
            }
        }
        let mut partial = PartialInstance { instance: Some(instance), debug: this_debug };
        let instance_ref = partial.instance.as_ref().expect("set above");
        let (physical, family) = pick_device(instance_ref, options)?;
        // SAFETY: valid physical device.
        let properties = unsafe { instance_ref.get_physical_device_properties(physical) };
        let families = unsafe { instance_ref.get_physical_device_queue_family_properties(physical) };
        let mut subgroup = vk::PhysicalDeviceSubgroupProperties::default();
        let mut properties2 = vk::PhysicalDeviceProperties2::default().push_next(&mut subgroup);
        // SAFETY: Vulkan 1.1 core query on a 1.1 device.
        unsafe { instance_ref.get_physical_device_properties2(physical, &mut properties2) };
        let subgroup_size = (options.subgroups
            && subgroup.supported_stages.contains(vk::ShaderStageFlags::COMPUTE)
            && subgroup.supported_operations.contains(
                vk::SubgroupFeatureFlags::BASIC
                    | vk::SubgroupFeatureFlags::SHUFFLE
                    | vk::SubgroupFeatureFlags::SHUFFLE_RELATIVE,
            ))
        .then_some(subgroup.subgroup_size);
        // The driver zero-initialises workgroup memory where it can (Vulkan 1.3) and the
        // options allow, instead of the shader's own loops and barrier per workgroup.
        let mut vulkan13 = vk::PhysicalDeviceVulkan13Features::default();
        if properties.api_version >= vk::API_VERSION_1_3 {
            let mut features2 = vk::PhysicalDeviceFeatures2::default().push_next(&mut vulkan13);
            // SAFETY: Vulkan 1.1 core query; the 1.3 struct only on a 1.3 device.
            unsafe { instance_ref.get_physical_device_features2(physical, &mut features2) };
        }
        // f16 in shaders and in storage buffers where the device has them (naga's SPIR-V
        // for a kernel using f16 declares Float16 and, for f16 in buffers,
        // StorageBuffer16BitAccess).
        let (mut vulkan11, mut vulkan12) =
            (vk::PhysicalDeviceVulkan11Features::default(), vk::PhysicalDeviceVulkan12Features::default());
        if properties.api_version >= vk::API_VERSION_1_2 {
            let mut features2 =
                vk::PhysicalDeviceFeatures2::default().push_next(&mut vulkan11).push_next(&mut vulkan12);
            // SAFETY: Vulkan 1.1 core query; the 1.2 structs only on a 1.2 device.
            unsafe { instance_ref.get_physical_device_features2(physical, &mut features2) };
        }
        let float16 = vulkan12.shader_float16 == vk::TRUE;
        let mut enable12 = vk::PhysicalDeviceVulkan12Features::default().shader_float16(true);
        let mut enable11 = vk::PhysicalDeviceVulkan11Features::default()
            .storage_buffer16_bit_access(vulkan11.storage_buffer16_bit_access == vk::TRUE)
            .uniform_and_storage_buffer16_bit_access(vulkan11.uniform_and_storage_buffer16_bit_access == vk::TRUE);
        let native_zero_init =
            options.driver_zeroes_workgroup_memory && vulkan13.shader_zero_initialize_workgroup_memory == vk::TRUE;
        let mut enable13 =
            vk::PhysicalDeviceVulkan13Features::default().shader_zero_initialize_workgroup_memory(native_zero_init);
        let priorities = [1.0f32];
        let queue_info =
            [vk::DeviceQueueCreateInfo::default().queue_family_index(family).queue_priorities(&priorities)];
        // 64-bit integers in shaders where the device has them (naga's SPIR-V for a
        // kernel using `i64`/`u64` declares the Int64 capability).
        // SAFETY: valid physical device.
        let core_features = unsafe { instance_ref.get_physical_device_features(physical) };
        let enabled = vk::PhysicalDeviceFeatures::default().shader_int64(core_features.shader_int64 == vk::TRUE);
        let mut device_info =
            vk::DeviceCreateInfo::default().queue_create_infos(&queue_info).enabled_features(&enabled);
        if native_zero_init {
            device_info = device_info.push_next(&mut enable13);
        }
        if float16 {
            device_info = device_info.push_next(&mut enable12).push_next(&mut enable11);
        }
        // SAFETY: valid physical device and create info.
        let device = unsafe { instance_ref.create_device(physical, &device_info, None) }.map_err(|e| {
            BackendError::DeviceCreation { backend: options.source.name().into(), reason: format!("{e:?}") }
        })?;
        // SAFETY: the queue family was requested above.
        let queue = unsafe { device.get_device_queue(family, 0) };
        let memory = unsafe { instance_ref.get_physical_device_memory_properties(physical) };
        let wanted = vk::MemoryPropertyFlags::HOST_VISIBLE | vk::MemoryPropertyFlags::HOST_COHERENT;
        let memory_type = (0..memory.memory_type_count)
            .find(|&i| memory.memory_types[i as usize].property_flags.contains(wanted))
            .ok_or_else(|| BackendError::DeviceCreation {
                backend: options.source.name().into(),
                reason: "no host-visible, coherent memory type".into(),
            });
        let memory_type = match memory_type {
            Ok(index) => index,
            Err(error) => {
                // SAFETY: nothing was created from the device yet.
                unsafe { device.destroy_device(None) };
                return Err(error);
            }
        };
        let timestamps = properties.limits.timestamp_compute_and_graphics == vk::TRUE
            && properties.limits.timestamp_period > 0.0
            && families[family as usize].timestamp_valid_bits > 0;
        let mut objects = DeviceObjects::default();
        if let Err(error) = objects.create(&device, family, timestamps) {
            objects.destroy(&device);
            // SAFETY: every child object was destroyed just above.
            unsafe { device.destroy_device(None) };
            return Err(error);
        }
        let DeviceObjects { command_pool, command_buffer, fence, query_pool } = objects;
        let (command_pool, command_buffer, fence) =
            (command_pool.expect("created"), command_buffer.expect("created"), fence.expect("created"));
        let (instance, debug) = partial.take();
        Ok(Self {
            _entry: entry,
            instance,
            debug,
            physical,
            device,
            queue,
            memory_type,
            command_pool,
            command_buffer,
            fence,
            query_pool,
            timestamp_period: f64::from(properties.limits.timestamp_period),
            subgroup_size,
            native_zero_init,
        })
    }

    /// The pipeline cache file's name for this device: API, vendor and device ids (the
    /// driver's own header in the data tells driver builds apart).
    pub(super) fn pipeline_cache_key(&self) -> String {
        // SAFETY: Vulkan 1.0 core query on this instance's physical device.
        let properties = unsafe { self.instance.get_physical_device_properties(self.physical) };
        format!("ash_pipeline_cache_vulkan_{}_{}", properties.vendor_id, properties.device_id)
    }

    pub(super) fn device_info(&self, options: &AshOptions) -> DeviceInfo {
        let mut maintenance3 = vk::PhysicalDeviceMaintenance3Properties::default();
        let mut driver = vk::PhysicalDeviceDriverProperties::default();
        let mut properties2 =
            vk::PhysicalDeviceProperties2::default().push_next(&mut maintenance3).push_next(&mut driver);
        // SAFETY: Vulkan 1.1 core query (driver properties: 1.2, zeroed if unsupported).
        unsafe { self.instance.get_physical_device_properties2(self.physical, &mut properties2) };
        let properties = properties2.properties;
        let limits = properties.limits;
        let name = properties.device_name_as_c_str().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        let driver_name = driver.driver_name_as_c_str().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        let driver_info = driver.driver_info_as_c_str().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        // Linear filtering of the 32-bit float formats, in the optimal tiling images use.
        let float32_filterable = [vk::Format::R32_SFLOAT, vk::Format::R32G32B32A32_SFLOAT].into_iter().all(|format| {
            // SAFETY: Vulkan 1.0 core query on this instance's physical device.
            let properties = unsafe { self.instance.get_physical_device_format_properties(self.physical, format) };
            properties.optimal_tiling_features.contains(vk::FormatFeatureFlags::SAMPLED_IMAGE_FILTER_LINEAR)
        });
        DeviceInfo {
            backend: options.source.name().into(),
            adapter: name,
            device_type: format!("{:?}", properties.device_type),
            driver: format!("{driver_name} {driver_info}").trim().into(),
            subgroup_sizes: self.subgroup_size.map(|s| (s, s)),
            timestamps: self.query_pool.is_some(),
            float32_filterable,
            limits: DeviceLimits {
                max_workgroup_storage: u64::from(limits.max_compute_shared_memory_size),
                max_invocations_per_workgroup: limits.max_compute_work_group_invocations,
                max_workgroup_size: limits.max_compute_work_group_size,
                max_workgroups_per_dimension: limits.max_compute_work_group_count.iter().copied().min().unwrap_or(0),
                max_storage_binding: u64::from(limits.max_storage_buffer_range),
                max_uniform_binding: u64::from(limits.max_uniform_buffer_range),
                max_buffer_size: maintenance3.max_memory_allocation_size,
                max_storage_buffers_per_stage: limits.max_per_stage_descriptor_storage_buffers,
                max_texture_2d: limits.max_image_dimension2_d.min(limits.max_image_dimension1_d),
                max_texture_3d: limits.max_image_dimension3_d,
                max_texture_layers: limits.max_image_array_layers,
                max_bind_groups: limits.max_bound_descriptor_sets,
            },
        }
    }

    pub(super) fn validation_messages(&self) -> Vec<String> {
        self.debug
            .as_ref()
            .and_then(|(_, _, messages)| messages.lock().ok().map(|list| list.clone()))
            .unwrap_or_default()
    }

    pub(super) fn create_buffer(
        &self,
        label: &str,
        size: u64,
    ) -> Result<(vk::Buffer, vk::DeviceMemory, *mut u8), BackendError> {
        let operation = format!("creating buffer `{label}` ({size} bytes)");
        // SAFETY: valid device; every object is destroyed on the error paths.
        unsafe {
            let buffer = self
                .device
                .create_buffer(
                    &vk::BufferCreateInfo::default()
                        .size(size)
                        .usage(
                            vk::BufferUsageFlags::STORAGE_BUFFER
                                | vk::BufferUsageFlags::UNIFORM_BUFFER
                                | vk::BufferUsageFlags::TRANSFER_SRC
                                | vk::BufferUsageFlags::TRANSFER_DST,
                        )
                        .sharing_mode(vk::SharingMode::EXCLUSIVE),
                    None,
                )
                .map_err(|e| vk_error(&operation, e))?;
            let requirements = self.device.get_buffer_memory_requirements(buffer);
            if requirements.memory_type_bits & (1 << self.memory_type) == 0 {
                self.device.destroy_buffer(buffer, None);
                return Err(BackendError::Buffer {
                    label: label.into(),
                    reason: "the device cannot place storage buffers in host-visible memory".into(),
                });
            }
            let memory = match self.device.allocate_memory(
                &vk::MemoryAllocateInfo::default()
                    .allocation_size(requirements.size)
                    .memory_type_index(self.memory_type),
                None,
            ) {
                Ok(memory) => memory,
                Err(e) => {
                    self.device.destroy_buffer(buffer, None);
                    return Err(vk_error(&operation, e));
                }
            };
            let bound = self.device.bind_buffer_memory(buffer, memory, 0);
            let mapped =
                bound.and_then(|()| self.device.map_memory(memory, 0, vk::WHOLE_SIZE, vk::MemoryMapFlags::empty()));
            match mapped {
                Ok(pointer) => {
                    std::ptr::write_bytes(pointer as *mut u8, 0, size as usize);
                    Ok((buffer, memory, pointer as *mut u8))
                }
                Err(e) => {
                    self.device.destroy_buffer(buffer, None);
                    self.device.free_memory(memory, None);
                    Err(vk_error(&operation, e))
                }
            }
        }
    }

    pub(super) fn destroy_buffer(&self, buffer: vk::Buffer, memory: vk::DeviceMemory) {
        // SAFETY: no dispatch is in flight between calls; the buffer is not used again.
        unsafe {
            self.device.destroy_buffer(buffer, None);
            self.device.free_memory(memory, None);
        }
    }

    /// Memory for an image of `requirements`: the host-visible type buffers use where the
    /// image allows it, else the first type it allows.
    pub(super) fn allocate(&self, requirements: vk::MemoryRequirements) -> Result<vk::DeviceMemory, vk::Result> {
        let bits = requirements.memory_type_bits;
        let index = if bits & (1 << self.memory_type) != 0 { self.memory_type } else { bits.trailing_zeros().min(31) };
        let info = vk::MemoryAllocateInfo::default().allocation_size(requirements.size).memory_type_index(index);
        // SAFETY: valid device and allocate info.
        unsafe { self.device.allocate_memory(&info, None) }
    }

    /// Records commands with `record` into the command buffer, submits them and waits.
    pub(super) fn submit_once(
        &self,
        operation: &str,
        record: impl FnOnce(vk::CommandBuffer),
    ) -> Result<(), BackendError> {
        let error = |e| vk_error(operation, e);
        let cb = self.command_buffer;
        // SAFETY: the command buffer is idle between calls (every submission is waited
        // for); the fence is reset after the wait.
        unsafe {
            self.device.reset_command_buffer(cb, vk::CommandBufferResetFlags::empty()).map_err(error)?;
            self.device
                .begin_command_buffer(
                    cb,
                    &vk::CommandBufferBeginInfo::default().flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT),
                )
                .map_err(error)?;
            record(cb);
            self.device.end_command_buffer(cb).map_err(error)?;
            let command_buffers = [cb];
            let submit = [vk::SubmitInfo::default().command_buffers(&command_buffers)];
            self.device.queue_submit(self.queue, &submit, self.fence).map_err(error)?;
            self.device.wait_for_fences(&[self.fence], true, u64::MAX).map_err(error)?;
            self.device.reset_fences(&[self.fence]).map_err(error)
        }
    }

    /// Records, submits and waits for one dispatch; returns its device time if `timed`.
    pub(super) fn dispatch(
        &self,
        pipeline: ComputePipeline,
        kernel: &Kernel,
        descriptors: &[(u32, u32, vk::DescriptorType, Descriptor)],
        workgroups: [u32; 3],
        timed: bool,
    ) -> Result<Option<Duration>, BackendError> {
        let operation = format!("dispatch of `{}`", kernel.name());
        let error = |e| vk_error(&operation, e);
        let mut sizes: Vec<vk::DescriptorPoolSize> = Vec::new();
        for &(_, _, ty, _) in descriptors {
            match sizes.iter_mut().find(|size| size.ty == ty) {
                Some(size) => size.descriptor_count += 1,
                None => sizes.push(vk::DescriptorPoolSize { ty, descriptor_count: 1 }),
            }
        }
        // SAFETY: all handles are valid; the pool is destroyed after the fence wait.
        unsafe {
            let pool = self
                .device
                .create_descriptor_pool(
                    &vk::DescriptorPoolCreateInfo::default()
                        .max_sets(pipeline.set_layouts.len() as u32)
                        .pool_sizes(&sizes),
                    None,
                )
                .map_err(error)?;
            let result = (|| {
                let sets = self
                    .device
                    .allocate_descriptor_sets(
                        &vk::DescriptorSetAllocateInfo::default()
                            .descriptor_pool(pool)
                            .set_layouts(pipeline.set_layouts),
                    )
                    .map_err(error)?;
                let buffer_infos: Vec<[vk::DescriptorBufferInfo; 1]> = descriptors
                    .iter()
                    .map(|&(_, _, _, descriptor)| match descriptor {
                        Descriptor::Buffer(buffer) => {
                            [vk::DescriptorBufferInfo { buffer, offset: 0, range: vk::WHOLE_SIZE }]
                        }
                        _ => [vk::DescriptorBufferInfo::default()],
                    })
                    .collect();
                let image_infos: Vec<[vk::DescriptorImageInfo; 1]> = descriptors
                    .iter()
                    .map(|&(_, _, _, descriptor)| {
                        let info = vk::DescriptorImageInfo::default().image_layout(vk::ImageLayout::GENERAL);
                        [match descriptor {
                            Descriptor::Image(view) => info.image_view(view),
                            Descriptor::Combined(view, sampler) => info.image_view(view).sampler(sampler),
                            Descriptor::Sampler(sampler) => info.sampler(sampler),
                            Descriptor::Buffer(_) => info,
                        }]
                    })
                    .collect();
                let writes: Vec<_> = descriptors
                    .iter()
                    .zip(buffer_infos.iter().zip(&image_infos))
                    .map(|(&(set, binding, ty, descriptor), (buffer_info, image_info))| {
                        let write = vk::WriteDescriptorSet::default()
                            .dst_set(sets[set as usize])
                            .dst_binding(binding)
                            .descriptor_type(ty);
                        match descriptor {
                            Descriptor::Buffer(_) => write.buffer_info(buffer_info),
                            _ => write.image_info(image_info),
                        }
                    })
                    .collect();
                self.device.update_descriptor_sets(&writes, &[]);
                let queries = self.query_pool.filter(|_| timed);
                self.submit_once(&operation, |cb| {
                    if let Some(queries) = queries {
                        self.device.cmd_reset_query_pool(cb, queries, 0, 2);
                        self.device.cmd_write_timestamp(cb, vk::PipelineStageFlags::TOP_OF_PIPE, queries, 0);
                    }
                    self.device.cmd_bind_pipeline(cb, vk::PipelineBindPoint::COMPUTE, pipeline.pipeline);
                    self.device.cmd_bind_descriptor_sets(
                        cb,
                        vk::PipelineBindPoint::COMPUTE,
                        pipeline.layout,
                        0,
                        &sets,
                        &[],
                    );
                    self.device.cmd_dispatch(cb, workgroups[0], workgroups[1], workgroups[2]);
                    if let Some(queries) = queries {
                        self.device.cmd_write_timestamp(cb, vk::PipelineStageFlags::BOTTOM_OF_PIPE, queries, 1);
                    }
                    // The dispatch's writes, visible to the host, to later dispatches and to
                    // the copies that read textures back.
                    let barrier =
                        vk::MemoryBarrier::default().src_access_mask(vk::AccessFlags::SHADER_WRITE).dst_access_mask(
                            vk::AccessFlags::HOST_READ
                                | vk::AccessFlags::SHADER_READ
                                | vk::AccessFlags::SHADER_WRITE
                                | vk::AccessFlags::TRANSFER_READ,
                        );
                    self.device.cmd_pipeline_barrier(
                        cb,
                        vk::PipelineStageFlags::COMPUTE_SHADER,
                        vk::PipelineStageFlags::HOST
                            | vk::PipelineStageFlags::COMPUTE_SHADER
                            | vk::PipelineStageFlags::TRANSFER,
                        vk::DependencyFlags::empty(),
                        &[barrier],
                        &[],
                        &[],
                    );
                })?;
                match queries {
                    Some(queries) => {
                        let mut ticks = [0u64; 2];
                        self.device
                            .get_query_pool_results(
                                queries,
                                0,
                                &mut ticks,
                                vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT,
                            )
                            .map_err(error)?;
                        let nanos = ticks[1].saturating_sub(ticks[0]) as f64 * self.timestamp_period;
                        Ok(Some(Duration::from_nanos(nanos as u64)))
                    }
                    None => Ok(None),
                }
            })();
            self.device.destroy_descriptor_pool(pool, None);
            result
        }
    }

    pub(super) fn wait_idle(&self) {
        // SAFETY: valid device.
        let _ = unsafe { self.device.device_wait_idle() };
    }
}

impl Drop for VulkanDevice {
    fn drop(&mut self) {
        // SAFETY: the owner (AshBackend) destroyed buffers and pipelines first and
        // waited for the device to be idle.
        unsafe {
            let _ = self.device.device_wait_idle();
            if let Some(pool) = self.query_pool {
                self.device.destroy_query_pool(pool, None);
            }
            self.device.destroy_fence(self.fence, None);
            self.device.destroy_command_pool(self.command_pool, None);
            self.device.destroy_device(None);
            if let Some((utils, messenger, _messages)) = self.debug.take() {
                utils.destroy_debug_utils_messenger(messenger, None);
            }
            self.instance.destroy_instance(None);
        }
    }
}

/// Instance and messenger until the device exists: destroyed if opening fails.
struct PartialInstance {
    instance: Option<ash::Instance>,
    debug: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT, Box<Messages>)>,
}

impl PartialInstance {
    #[allow(clippy::type_complexity)]
    fn take(
        &mut self,
    ) -> (ash::Instance, Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT, Box<Messages>)>) {
        (self.instance.take().expect("taken once"), self.debug.take())
    }
}

impl Drop for PartialInstance {
    fn drop(&mut self) {
        // SAFETY: only reached when opening failed before the device took ownership.
        unsafe {
            if let Some((utils, messenger, _)) = self.debug.take() {
                utils.destroy_debug_utils_messenger(messenger, None);
            }
            if let Some(instance) = self.instance.take() {
                instance.destroy_instance(None);
            }
        }
    }
}
