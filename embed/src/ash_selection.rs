//! [`AshSelection`]: the pass on an engine's own Vulkan device through `ash`, from naga's
//! SPIR-V of the same WGSL kernels, recording into the engine's command buffer with the
//! engine's buffers.

use crate::ash_objects::{Created, OwnBuffer, Pipeline, descriptor_type, destroy_pipeline, vk_error};
use crate::binding_plan::{EngineBuffers, OwnBuffers, ResampleBuffers, Resource};
use crate::contract::check_size;
use crate::error::EmbedError;
use crate::frame::VulkanBarrier;
use crate::frame::{FrameId, FrameParams, frame_params, max_blocks};
use crate::limits::{DeviceLimits, VULKAN_NAMES, check_limits};
use crate::wgsl::{ModuleId, module};
use ash::vk;
use std::sync::atomic::{AtomicU32, Ordering};
use strata_kernels::Executor;
use strata_kernels::blue_noise::BlueNoiseTables;
use strata_kernels::pass_plan::PassBuffer;
use strata_kernels::selection::SelectionSettings;
use strata_kernels::translate::{TranslateOptions, WorkgroupZeroInit};

/// The engine's Vulkan objects the pass is created on (the instance created with
/// `apiVersion` 1.1 or newer and a Vulkan 1.1 device; nothing has to be enabled beyond
/// core features). Holding one promises nothing about the handles' lifetimes: that is
/// [`AshSelection::new`]'s contract.
#[derive(Clone, Copy)]
pub struct AshDevice<'a> {
    /// The instance.
    pub instance: &'a ash::Instance,
    /// The physical device behind `device`.
    pub physical_device: vk::PhysicalDevice,
    /// The logical device.
    pub device: &'a ash::Device,
    /// Whether the engine enabled `shaderZeroInitializeWorkgroupMemory` on `device`
    /// (Vulkan 1.3 core, or `VK_KHR_zero_initialize_workgroup_memory`). WGSL promises
    /// zeroed workgroup memory: with the feature the driver zeroes it, without it each
    /// pipeline zeroes it in loops its invocations share (`strata_kernels::translate`); on
    /// lavapipe making the pass takes the same time either way (38.9 and 39.4 ms; 365 ms
    /// before 2026-11-30 with naga's own zeroing: BENCHMARKS.md, "embed"). `false` is
    /// always correct. `true` for a device that lacks the
    /// feature is refused; `true` for one that has it but where the engine did not
    /// enable it cannot be detected and makes the pipelines invalid usage.
    pub shader_zero_initialize_workgroup_memory: bool,
}

/// Whether the physical device has `shaderZeroInitializeWorkgroupMemory`: Vulkan 1.3, or
/// the extension listed, and the feature reported.
fn zero_initialize_workgroup_memory(
    instance: &ash::Instance,
    physical_device: vk::PhysicalDevice,
    api_version: u32,
) -> bool {
    let listed = || {
        let extension = ash::khr::zero_initialize_workgroup_memory::NAME;
        // SAFETY: valid instance and physical device handles from the engine.
        unsafe { instance.enumerate_device_extension_properties(physical_device) }
            .unwrap_or_default()
            .iter()
            .any(|e| e.extension_name_as_c_str() == Ok(extension))
    };
    if api_version < vk::API_VERSION_1_3 && !listed() {
        return false;
    }
    let mut zero_init = vk::PhysicalDeviceZeroInitializeWorkgroupMemoryFeatures::default();
    let mut features = vk::PhysicalDeviceFeatures2::default().push_next(&mut zero_init);
    // SAFETY: valid handles from the engine, whose instance is Vulkan 1.1 or newer (AshDevice's
    // contract) on a device of 1.1 or newer (checked before); the chained struct is one the
    // device knows (1.3, or its extension listed).
    unsafe { instance.get_physical_device_features2(physical_device, &mut features) };
    zero_init.shader_zero_initialize_workgroup_memory == vk::TRUE
}

/// A range of an engine buffer: records start at `offset` (a multiple of
/// `minStorageBufferOffsetAlignment`) and `size` bytes may be used.
#[derive(Clone, Copy, Debug)]
pub struct AshBufferSlice {
    /// The buffer (created with `STORAGE_BUFFER` usage).
    pub buffer: vk::Buffer,
    /// Byte offset of the first record.
    pub offset: u64,
    /// Bytes from `offset` the pass may use.
    pub size: u64,
}

/// The engine's buffers for [`AshSelection::bind`] (see [`crate::contract`]).
pub type AshBuffers = EngineBuffers<AshBufferSlice>;

/// The engine's buffers of the resampling pass.
pub type AshResampleBuffers = ResampleBuffers<AshBufferSlice>;

/// Descriptor sets of one set of engine buffers, made by [`AshSelection::bind`]; free
/// them with [`AshSelection::destroy_bindings`].
#[derive(Debug)]
pub struct AshBindings {
    pool: vk::DescriptorPool,
    histogram: vk::DescriptorSet,
    select: vk::DescriptorSet,
    resample: Option<vk::DescriptorSet>,
    identity_payload: bool,
}

/// The stratified selection on an engine's Vulkan device (see [`crate::WgpuSelection`]
/// for the frame's sequence; here the uniforms are written inside the command buffer with
/// `vkCmdUpdateBuffer`, so several frames may be recorded into one submission).
///
/// The pass inserts its own barriers: before its first dispatch, a global memory barrier
/// from the engine's shader and transfer writes; between its dispatches; and after the
/// last, one making its outputs visible to the engine's later shader and transfer reads.
/// Destroy it with [`Self::destroy`] once the device no longer uses it.
///
/// Threads: every method but [`Self::destroy`] takes `&self`, so one pass may bind and
/// record from several threads at once (each into its own command buffer, whose pool the
/// engine synchronises as Vulkan requires). The command buffers share the pass's own
/// buffers (uniforms, histogram), so their executions on the device must not overlap:
/// submit them to one queue, whose submission order the pass's barriers follow, or order
/// them with semaphores.
pub struct AshSelection {
    device: ash::Device,
    settings: SelectionSettings,
    seed: AtomicU32,
    width: u32,
    height: u32,
    max_workgroups: u32,
    offset_alignment: u64,
    /// The device's `maxStorageBufferRange`: the most bytes an engine slice may span.
    max_storage_buffer_range: u64,
    histogram: Pipeline,
    select: Pipeline,
    resample: Pipeline,
    own: OwnBuffers<OwnBuffer>,
}

/// Whether compute shaders may use subgroup shuffles (Vulkan 1.1 subgroup properties).
fn subgroup_shuffles(instance: &ash::Instance, physical_device: vk::PhysicalDevice) -> bool {
    let mut subgroup = vk::PhysicalDeviceSubgroupProperties::default();
    let mut properties = vk::PhysicalDeviceProperties2::default().push_next(&mut subgroup);
    // SAFETY: valid instance and physical device handles from the engine.
    unsafe { instance.get_physical_device_properties2(physical_device, &mut properties) };
    let operations = vk::SubgroupFeatureFlags::BASIC | vk::SubgroupFeatureFlags::SHUFFLE;
    subgroup.supported_stages.contains(vk::ShaderStageFlags::COMPUTE)
        && subgroup.supported_operations.contains(operations)
}

impl AshSelection {
    /// Builds the pipelines (naga's SPIR-V) and the pass's own buffers for a `width` ×
    /// `height` image; fails, naming the setting or the device limit, when the settings
    /// are out of range or the device cannot run the pass at this size. Uses the histogram
    /// module [`crate::wgsl::histogram_module`] picks for the device's type (the subgroup
    /// network on a GPU whose compute shaders have subgroup shuffles). Frames belong to
    /// the render of seed 0 until [`Self::set_seed`].
    ///
    /// # Safety
    /// The caller guarantees that
    /// * `vulkan.instance` was loaded for a live `VkInstance` created with `apiVersion`
    ///   1.1 or newer, and `vulkan.physical_device` is one of its physical devices;
    /// * `vulkan.device` was loaded for a live `VkDevice` created from that physical
    ///   device;
    /// * if `vulkan.shader_zero_initialize_workgroup_memory` is true, the engine enabled
    ///   `shaderZeroInitializeWorkgroupMemory` on that device (a device that lacks the
    ///   feature is refused; one that has it but where it is not enabled cannot be
    ///   detected);
    /// * the device and the instance stay alive until [`Self::destroy`] has returned (a
    ///   pass dropped without it leaks its Vulkan objects).
    pub unsafe fn new(
        vulkan: AshDevice,
        settings: SelectionSettings,
        width: u32,
        height: u32,
    ) -> Result<Self, EmbedError> {
        crate::frame::grid(&settings, width, height)?;
        // SAFETY: live handles (this function's contract).
        let properties = unsafe { vulkan.instance.get_physical_device_properties(vulkan.physical_device) };
        if properties.api_version < vk::API_VERSION_1_1 {
            return Err(EmbedError::DeviceLimit {
                limit: "apiVersion",
                available: u64::from(properties.api_version),
                needed: u64::from(vk::API_VERSION_1_1),
                why: "naga's SPIR-V 1.3 needs Vulkan 1.1".into(),
            });
        }
        if vulkan.shader_zero_initialize_workgroup_memory
            && !zero_initialize_workgroup_memory(vulkan.instance, vulkan.physical_device, properties.api_version)
        {
            return Err(EmbedError::UnsupportedFeature {
                field: "AshDevice.shader_zero_initialize_workgroup_memory",
                feature: "shaderZeroInitializeWorkgroupMemory",
            });
        }
        let translate = TranslateOptions {
            workgroup_zero_init: if vulkan.shader_zero_initialize_workgroup_memory {
                WorkgroupZeroInit::Native
            } else {
                WorkgroupZeroInit::Polyfill
            },
        };
        let executor = Executor::of_device(&format!("{:?}", properties.device_type), false);
        let subgroups = subgroup_shuffles(vulkan.instance, vulkan.physical_device);
        let histogram_module = crate::wgsl::histogram_module(settings.block_size, subgroups, executor);
        let limits = properties.limits;
        let blocks = max_blocks(&settings, width, height);
        check_limits(DeviceLimits::vulkan(&limits), &VULKAN_NAMES, histogram_module, width, height, blocks)?;
        // SAFETY: valid handles from the engine.
        let memory = unsafe { vulkan.instance.get_physical_device_memory_properties(vulkan.physical_device) };
        let device = vulkan.device.clone();
        let mut created = Created { device: &device, translate, pipelines: Vec::new(), buffers: Vec::new() };
        let histogram = created.pipeline(&module(histogram_module)?)?;
        let select = created.pipeline(&module(ModuleId::Select)?)?;
        let resample = created.pipeline(&module(ModuleId::Resample)?)?;
        let pixels = u64::from(width) * u64::from(height);
        let uniform = vk::BufferUsageFlags::UNIFORM_BUFFER | vk::BufferUsageFlags::TRANSFER_DST;
        let storage = vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_SRC;
        let local = vk::MemoryPropertyFlags::DEVICE_LOCAL;
        let host = vk::MemoryPropertyFlags::HOST_VISIBLE | vk::MemoryPropertyFlags::HOST_COHERENT;
        let packed = BlueNoiseTables::new().packed();
        let own = OwnBuffers::make(pixels, blocks, |own, size| match own {
            PassBuffer::BlueNoise => created.buffer(
                &memory,
                size,
                vk::BufferUsageFlags::STORAGE_BUFFER,
                host,
                Some(bytemuck::cast_slice(&packed)),
            ),
            PassBuffer::HistogramParams | PassBuffer::SelectionParams => {
                created.buffer(&memory, size, uniform, local, None)
            }
            PassBuffer::Payloads => created.buffer(&memory, size, vk::BufferUsageFlags::STORAGE_BUFFER, local, None),
            _ => created.buffer(&memory, size, storage, local, None),
        })?;
        created.keep();
        Ok(Self {
            device,
            settings,
            seed: AtomicU32::new(0),
            width,
            height,
            max_workgroups: limits.max_compute_work_group_count.iter().copied().min().unwrap_or(1),
            offset_alignment: limits.min_storage_buffer_offset_alignment.max(1),
            max_storage_buffer_range: u64::from(limits.max_storage_buffer_range),
            histogram,
            select,
            resample,
            own,
        })
    }

    /// The settings.
    pub fn settings(&self) -> &SelectionSettings {
        &self.settings
    }

    /// Starts an independent render: a new seed for the frames recorded from now on
    /// (for example per run of an unbiasedness test); costs nothing. Shared access: a
    /// frame recorded on another thread at the same moment gets the old or the new seed.
    pub fn set_seed(&self, seed: u32) {
        self.seed.store(seed, Ordering::Relaxed);
    }

    /// The seed of the frames recorded from now on.
    pub fn seed(&self) -> u32 {
        self.seed.load(Ordering::Relaxed)
    }

    /// The parameters frame `frame` runs with.
    pub fn frame_params(&self, frame: u32, identity_payload: bool) -> Result<FrameParams, EmbedError> {
        let id = FrameId { frame, seed: self.seed(), identity_payload };
        Ok(frame_params(&self.settings, self.width, self.height, id, self.max_workgroups)?)
    }

    /// The checks of [`Self::bind`]'s errors, in that order, before any Vulkan call.
    fn check_slices(&self, buffers: &AshBuffers) -> Result<(), EmbedError> {
        let mut ranges = Vec::new();
        for (role, slice) in buffers.roles() {
            let (buffer, offset, size) = (role.name(), slice.offset, slice.size);
            if !offset.is_multiple_of(self.offset_alignment) {
                return Err(EmbedError::BufferOffset { buffer, offset, alignment: self.offset_alignment });
            }
            let end = offset.checked_add(size).ok_or(EmbedError::BufferEnd { buffer, offset, size })?;
            if size > self.max_storage_buffer_range {
                return Err(EmbedError::BufferRange {
                    buffer,
                    size,
                    limit: "maxStorageBufferRange",
                    max: self.max_storage_buffer_range,
                });
            }
            check_size(role, size, self.width, self.height)?;
            ranges.push((buffer, slice.buffer, offset, end));
        }
        for (i, &(first, buffer, first_start, first_end)) in ranges.iter().enumerate() {
            for &(second, other, second_start, second_end) in &ranges[i + 1..] {
                if buffer == other && first_start < second_end && second_start < first_end {
                    return Err(EmbedError::BufferOverlap {
                        first,
                        first_start,
                        first_end,
                        second,
                        second_start,
                        second_end,
                    });
                }
            }
        }
        Ok(())
    }

    /// Checks the engine's buffers against the contract and writes their descriptor sets.
    ///
    /// # Errors
    /// Each refusal names the buffer's role and the values, and is made before any Vulkan
    /// call: a slice's offset not a multiple of `minStorageBufferOffsetAlignment`
    /// ([`EmbedError::BufferOffset`]); `offset + size` past byte 2^64 - 1
    /// ([`EmbedError::BufferEnd`]); a size over `maxStorageBufferRange`
    /// ([`EmbedError::BufferRange`]; `VK_WHOLE_SIZE` included) or under what the contract
    /// needs for the image ([`EmbedError::BufferTooSmall`]); two slices of one `VkBuffer`
    /// in overlapping bytes ([`EmbedError::BufferOverlap`]: every role needs bytes of its
    /// own; the pass writes `selections` and `resampled` while it reads the others, and no
    /// engine needs two roles read from the same bytes). A failed Vulkan call is
    /// [`EmbedError::Api`].
    ///
    /// # Safety
    /// The caller guarantees that every slice's `buffer` is a live `VkBuffer` of the
    /// pass's device, created with `STORAGE_BUFFER` usage, with memory bound; that every
    /// slice the checks let through lies inside its buffer (`offset + size` at most the
    /// buffer's size: Vulkan cannot be asked a buffer's size; a slice the checks refuse
    /// never reaches the driver); and that the buffers and their memory stay alive while
    /// a command buffer recorded with the returned bindings is recording or pending.
    pub unsafe fn bind(&self, buffers: &AshBuffers) -> Result<AshBindings, EmbedError> {
        self.check_slices(buffers)?;
        let sets = 3u32;
        let pool_sizes = [
            vk::DescriptorPoolSize { ty: vk::DescriptorType::UNIFORM_BUFFER, descriptor_count: sets },
            vk::DescriptorPoolSize { ty: vk::DescriptorType::STORAGE_BUFFER, descriptor_count: 16 },
        ];
        let info = vk::DescriptorPoolCreateInfo::default().max_sets(sets).pool_sizes(&pool_sizes);
        // SAFETY: valid device; the pool is destroyed by destroy_bindings.
        let pool = unsafe { self.device.create_descriptor_pool(&info, None) }
            .map_err(|e| vk_error("creating the descriptor pool", e))?;
        let layouts =
            [self.histogram.objects.set_layout, self.select.objects.set_layout, self.resample.objects.set_layout];
        let count = if buffers.resample.is_some() { 3 } else { 2 };
        let allocate = vk::DescriptorSetAllocateInfo::default().descriptor_pool(pool).set_layouts(&layouts[..count]);
        // SAFETY: the pool has room for these sets.
        let allocated = match unsafe { self.device.allocate_descriptor_sets(&allocate) } {
            Ok(sets) => sets,
            Err(error) => {
                // SAFETY: the pool is unused.
                unsafe { self.device.destroy_descriptor_pool(pool, None) };
                return Err(vk_error("allocating descriptor sets", error));
            }
        };
        let plan = buffers.plan(&self.own);
        let mut writes =
            vec![(allocated[0], &self.histogram, plan.histogram), (allocated[1], &self.select, plan.select)];
        if let Some(resources) = plan.resample {
            writes.push((allocated[2], &self.resample, resources));
        }
        for (set, pipeline, resources) in &writes {
            let numbered = strata_kernels::pass_plan::numbered(pipeline.kernel, resources);
            let infos: Vec<[vk::DescriptorBufferInfo; 1]> = numbered
                .iter()
                .map(|(_, resource)| {
                    [match *resource {
                        Resource::Own(own) => {
                            vk::DescriptorBufferInfo { buffer: own.buffer, offset: 0, range: own.size }
                        }
                        Resource::Engine(s) => {
                            vk::DescriptorBufferInfo { buffer: s.buffer, offset: s.offset, range: s.size }
                        }
                    }]
                })
                .collect();
            let descriptor_writes: Vec<_> = infos
                .iter()
                .zip(&numbered)
                .map(|(info, (binding, _))| {
                    vk::WriteDescriptorSet::default()
                        .dst_set(*set)
                        .dst_binding(*binding)
                        .descriptor_type(descriptor_type(pipeline.kernel, *binding))
                        .buffer_info(info)
                })
                .collect();
            // SAFETY: the sets are this pool's; the engine's buffers are live buffers of the
            // device holding their ranges (this function's contract), whose offsets,
            // sizes and overlaps were checked above.
            unsafe { self.device.update_descriptor_sets(&descriptor_writes, &[]) };
        }
        Ok(AshBindings {
            pool,
            histogram: allocated[0],
            select: allocated[1],
            resample: allocated.get(2).copied(),
            identity_payload: buffers.payloads.is_none(),
        })
    }

    /// Frees the descriptor sets of `bindings`.
    ///
    /// # Safety
    /// No pending command buffer may still use them.
    pub unsafe fn destroy_bindings(&self, bindings: AshBindings) {
        // SAFETY: the caller guarantees the sets are no longer in use.
        unsafe { self.device.destroy_descriptor_pool(bindings.pool, None) };
    }

    /// Records `barrier` (one of [`VulkanBarrier`]'s, which the export's manifest lists).
    fn barrier(&self, command_buffer: vk::CommandBuffer, barrier: VulkanBarrier) {
        let memory = vk::MemoryBarrier::default()
            .src_access_mask(vk::AccessFlags::from_raw(barrier.src_access))
            .dst_access_mask(vk::AccessFlags::from_raw(barrier.dst_access));
        // SAFETY: the caller of the recording functions guarantees a recording command buffer.
        unsafe {
            self.device.cmd_pipeline_barrier(
                command_buffer,
                vk::PipelineStageFlags::from_raw(barrier.src_stages),
                vk::PipelineStageFlags::from_raw(barrier.dst_stages),
                vk::DependencyFlags::empty(),
                &[memory],
                &[],
                &[],
            )
        };
    }

    fn dispatch(
        &self,
        command_buffer: vk::CommandBuffer,
        pipeline: &Pipeline,
        set: vk::DescriptorSet,
        groups: [u32; 3],
    ) {
        // SAFETY: as for `barrier`; the set matches the pipeline's layout.
        unsafe {
            self.device.cmd_bind_pipeline(command_buffer, vk::PipelineBindPoint::COMPUTE, pipeline.objects.pipeline);
            self.device.cmd_bind_descriptor_sets(
                command_buffer,
                vk::PipelineBindPoint::COMPUTE,
                pipeline.objects.layout,
                0,
                &[set],
                &[],
            );
            self.device.cmd_dispatch(command_buffer, groups[0], groups[1], groups[2]);
        }
        self.barrier(command_buffer, VulkanBarrier::AFTER_DISPATCH);
    }

    /// Records frame `frame`'s uniform updates, histogram and selection.
    ///
    /// # Safety
    /// `command_buffer` must be in the recording state, outside a render pass, on a queue
    /// with compute support, of the device the pass was made on; `bindings` must come from
    /// this pass and its buffers must stay alive until the commands complete.
    pub unsafe fn record_selection(
        &self,
        command_buffer: vk::CommandBuffer,
        bindings: &AshBindings,
        frame: u32,
    ) -> Result<(), EmbedError> {
        let params = self.frame_params(frame, bindings.identity_payload)?;
        // Earlier work (the engine's candidate writes, an earlier frame's reads of the
        // uniforms) before the updates and dispatches.
        self.barrier(command_buffer, VulkanBarrier::BEFORE_PASS);
        // SAFETY: per this function's contract.
        unsafe {
            self.device.cmd_update_buffer(
                command_buffer,
                self.own.histogram_params.buffer,
                0,
                bytemuck::bytes_of(&params.histogram),
            );
            self.device.cmd_update_buffer(
                command_buffer,
                self.own.selection_params.buffer,
                0,
                bytemuck::bytes_of(&params.selection),
            );
        }
        self.barrier(command_buffer, VulkanBarrier::AFTER_UPDATES);
        self.dispatch(command_buffer, &self.histogram, bindings.histogram, params.histogram_workgroups);
        self.dispatch(command_buffer, &self.select, bindings.select, params.pixel_workgroups);
        Ok(())
    }

    /// Records the resampling of the engine's `resample_inputs`.
    ///
    /// # Safety
    /// As for [`Self::record_selection`], after it in the same or an earlier submission.
    pub unsafe fn record_resampling(
        &self,
        command_buffer: vk::CommandBuffer,
        bindings: &AshBindings,
    ) -> Result<(), EmbedError> {
        let set = bindings.resample.ok_or(EmbedError::NoResampleBuffers)?;
        self.barrier(command_buffer, VulkanBarrier::BEFORE_PASS);
        let workgroups = crate::frame::pixel_workgroups(self.width, self.height)?;
        self.dispatch(command_buffer, &self.resample, set, workgroups);
        Ok(())
    }

    /// Destroys the pipelines and the pass's own buffers.
    ///
    /// # Safety
    /// No pending command buffer may still use the pass.
    pub unsafe fn destroy(self) {
        let buffers = self.own.all();
        // SAFETY: the caller guarantees nothing uses them any more.
        unsafe {
            for buffer in buffers {
                self.device.destroy_buffer(buffer.buffer, None);
                self.device.free_memory(buffer.memory, None);
            }
            for pipeline in [&self.histogram, &self.select, &self.resample] {
                destroy_pipeline(&self.device, pipeline);
            }
        }
    }
}
