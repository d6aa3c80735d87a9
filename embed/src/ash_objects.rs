//! The Vulkan objects of [`crate::AshSelection`] and how they are made: its pipelines
//! (naga's SPIR-V of the registry's kernels, a descriptor set layout from each kernel's
//! bindings) and its own buffers, created through [`Created`], which destroys whatever
//! was made if creation fails half-way.

use crate::error::EmbedError;
use crate::wgsl::WgslModule;
use ash::vk;
use strata_kernels::Registry;
use strata_kernels::translate::{TranslateOptions, spirv};

/// A compute pipeline of one kernel, with its layouts and the module it runs.
pub(crate) struct Pipeline {
    pub(crate) pipeline: vk::Pipeline,
    pub(crate) layout: vk::PipelineLayout,
    pub(crate) set_layout: vk::DescriptorSetLayout,
    pub(crate) module: WgslModule,
}

/// A buffer the pass owns, with its memory.
pub(crate) struct OwnBuffer {
    pub(crate) buffer: vk::Buffer,
    pub(crate) memory: vk::DeviceMemory,
    pub(crate) size: u64,
}

/// An [`EmbedError`] of a failed Vulkan call.
pub(crate) fn vk_error(operation: &str, result: vk::Result) -> EmbedError {
    EmbedError::Api { api: "Vulkan", operation: operation.into(), message: format!("{result:?}") }
}

/// The descriptor type of binding `binding` of `module`.
pub(crate) fn descriptor_type(module: &WgslModule, binding: u32) -> vk::DescriptorType {
    match module.bindings.iter().find(|b| b.binding == binding) {
        Some(b) if b.uniform => vk::DescriptorType::UNIFORM_BUFFER,
        _ => vk::DescriptorType::STORAGE_BUFFER,
    }
}

/// # Safety
/// The pipeline must be unused.
pub(crate) unsafe fn destroy_pipeline(device: &ash::Device, pipeline: &Pipeline) {
    // SAFETY: per the function's contract.
    unsafe {
        device.destroy_pipeline(pipeline.pipeline, None);
        device.destroy_pipeline_layout(pipeline.layout, None);
        device.destroy_descriptor_set_layout(pipeline.set_layout, None);
    }
}

/// Objects made so far by [`AshSelection::new`], destroyed if it fails half-way.
pub(crate) struct Created<'a> {
    pub(crate) device: &'a ash::Device,
    /// How the pipelines' SPIR-V zeroes workgroup memory.
    pub(crate) translate: TranslateOptions,
    pub(crate) pipelines: Vec<(vk::Pipeline, vk::PipelineLayout, vk::DescriptorSetLayout)>,
    pub(crate) buffers: Vec<(vk::Buffer, vk::DeviceMemory)>,
}

impl Created<'_> {
    pub(crate) fn pipeline(&mut self, module: &WgslModule) -> Result<Pipeline, EmbedError> {
        let kernel = Registry::shared()?.get(module.id.kernel());
        let code = spirv(kernel, self.translate)?;
        let layout_bindings: Vec<_> = module
            .bindings
            .iter()
            .map(|b| {
                vk::DescriptorSetLayoutBinding::default()
                    .binding(b.binding)
                    .descriptor_type(descriptor_type(module, b.binding))
                    .descriptor_count(1)
                    .stage_flags(vk::ShaderStageFlags::COMPUTE)
            })
            .collect();
        let device = self.device;
        let operation = format!("creating the `{}` pipeline", module.entry_point);
        // SAFETY: valid device; every object is destroyed by `Drop` on failure or by
        // AshSelection::destroy.
        unsafe {
            let set_layout = device
                .create_descriptor_set_layout(
                    &vk::DescriptorSetLayoutCreateInfo::default().bindings(&layout_bindings),
                    None,
                )
                .map_err(|e| vk_error(&operation, e))?;
            let layouts = [set_layout];
            let layout = match device
                .create_pipeline_layout(&vk::PipelineLayoutCreateInfo::default().set_layouts(&layouts), None)
            {
                Ok(layout) => layout,
                Err(e) => {
                    device.destroy_descriptor_set_layout(set_layout, None);
                    return Err(vk_error(&operation, e));
                }
            };
            self.pipelines.push((vk::Pipeline::null(), layout, set_layout));
            let shader = device
                .create_shader_module(&vk::ShaderModuleCreateInfo::default().code(&code.words), None)
                .map_err(|e| vk_error(&operation, e))?;
            let entry = std::ffi::CString::new(code.entry_point).expect("entry points have no NUL");
            let stage = vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::COMPUTE)
                .module(shader)
                .name(&entry);
            let info = vk::ComputePipelineCreateInfo::default().stage(stage).layout(layout);
            let result = device.create_compute_pipelines(vk::PipelineCache::null(), &[info], None);
            device.destroy_shader_module(shader, None);
            let pipeline = result.map_err(|(_, e)| vk_error(&operation, e))?[0];
            self.pipelines.last_mut().expect("pushed above").0 = pipeline;
            Ok(Pipeline { pipeline, layout, set_layout, module: module.clone() })
        }
    }

    pub(crate) fn buffer(
        &mut self,
        memory: &vk::PhysicalDeviceMemoryProperties,
        size: u64,
        usage: vk::BufferUsageFlags,
        preferred: vk::MemoryPropertyFlags,
        contents: Option<&[u8]>,
    ) -> Result<OwnBuffer, EmbedError> {
        let device = self.device;
        let info = vk::BufferCreateInfo::default().size(size).usage(usage).sharing_mode(vk::SharingMode::EXCLUSIVE);
        // SAFETY: valid device; objects are recorded for cleanup right after creation.
        unsafe {
            let buffer = device.create_buffer(&info, None).map_err(|e| vk_error("creating a buffer", e))?;
            let requirements = device.get_buffer_memory_requirements(buffer);
            let candidates = (0..memory.memory_type_count).filter(|&i| requirements.memory_type_bits & (1 << i) != 0);
            let flags = |i: u32| memory.memory_types[i as usize].property_flags;
            let required = if contents.is_some() {
                vk::MemoryPropertyFlags::HOST_VISIBLE | vk::MemoryPropertyFlags::HOST_COHERENT
            } else {
                vk::MemoryPropertyFlags::empty()
            };
            let chosen = candidates
                .clone()
                .find(|&i| flags(i).contains(preferred | required))
                .or_else(|| candidates.clone().find(|&i| flags(i).contains(required)));
            let Some(type_index) = chosen else {
                device.destroy_buffer(buffer, None);
                return Err(EmbedError::Api {
                    api: "Vulkan",
                    operation: "allocating buffer memory".into(),
                    message: format!("no memory type with {required:?} for a buffer of usage {usage:?}"),
                });
            };
            let allocate =
                vk::MemoryAllocateInfo::default().allocation_size(requirements.size).memory_type_index(type_index);
            let memory = match device.allocate_memory(&allocate, None) {
                Ok(memory) => memory,
                Err(e) => {
                    device.destroy_buffer(buffer, None);
                    return Err(vk_error("allocating buffer memory", e));
                }
            };
            self.buffers.push((buffer, memory));
            device.bind_buffer_memory(buffer, memory, 0).map_err(|e| vk_error("binding buffer memory", e))?;
            if let Some(bytes) = contents {
                let mapped = device
                    .map_memory(memory, 0, size, vk::MemoryMapFlags::empty())
                    .map_err(|e| vk_error("mapping buffer memory", e))?;
                std::ptr::copy_nonoverlapping(bytes.as_ptr(), mapped.cast::<u8>(), bytes.len());
                device.unmap_memory(memory);
            }
            Ok(OwnBuffer { buffer, memory, size })
        }
    }

    /// Everything succeeded: ownership passes to the AshSelection.
    pub(crate) fn keep(mut self) {
        self.pipelines.clear();
        self.buffers.clear();
    }
}

impl Drop for Created<'_> {
    fn drop(&mut self) {
        // SAFETY: these objects were never used by a command buffer.
        unsafe {
            for &(pipeline, layout, set_layout) in &self.pipelines {
                self.device.destroy_pipeline(pipeline, None);
                self.device.destroy_pipeline_layout(layout, None);
                self.device.destroy_descriptor_set_layout(set_layout, None);
            }
            for &(buffer, memory) in &self.buffers {
                self.device.destroy_buffer(buffer, None);
                self.device.free_memory(memory, None);
            }
        }
    }
}
