//! The Vulkan objects of [`crate::AshSelection`] and how they are made: its pipelines
//! (naga's SPIR-V of the registry's kernels, made by the backends' plumbing,
//! `strata_backends::ash_backend::create_compute_pipeline`) and its own buffers, created
//! through [`Created`], which destroys whatever was made if creation fails half-way.

use crate::error::EmbedError;
use crate::wgsl::WgslModule;
use ash::vk;
use strata_backends::ash_backend::{PipelineObjects, create_compute_pipeline, destroy_compute_pipeline};
use strata_kernels::translate::{TranslateOptions, spirv};
use strata_kernels::{Kernel, Registry};

/// A compute pipeline of one kernel, with its layouts and the kernel it runs.
pub(crate) struct Pipeline {
    pub(crate) objects: PipelineObjects,
    pub(crate) kernel: &'static Kernel,
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

/// The descriptor type of binding `binding` of `kernel`.
pub(crate) fn descriptor_type(kernel: &Kernel, binding: u32) -> vk::DescriptorType {
    kernel
        .binding(0, binding)
        .map_or(vk::DescriptorType::STORAGE_BUFFER, |b| strata_backends::ash_backend::descriptor_type(b.kind))
}

/// # Safety
/// The pipeline must be unused.
pub(crate) unsafe fn destroy_pipeline(device: &ash::Device, pipeline: &Pipeline) {
    // SAFETY: per the function's contract.
    unsafe { destroy_compute_pipeline(device, &pipeline.objects) }
}

/// Objects made so far by [`crate::AshSelection::new`], destroyed if it fails half-way.
pub(crate) struct Created<'a> {
    pub(crate) device: &'a ash::Device,
    /// How the pipelines' SPIR-V zeroes workgroup memory.
    pub(crate) translate: TranslateOptions,
    pub(crate) pipelines: Vec<PipelineObjects>,
    pub(crate) buffers: Vec<(vk::Buffer, vk::DeviceMemory)>,
}

impl Created<'_> {
    pub(crate) fn pipeline(&mut self, module: &WgslModule) -> Result<Pipeline, EmbedError> {
        let kernel = Registry::shared()?.get(module.id.kernel());
        let code = spirv(kernel, self.translate)?;
        let entry = std::ffi::CString::new(code.entry_point).expect("entry points have no NUL");
        // SAFETY: valid device; the objects are destroyed by `Drop` if a later creation
        // fails, else by AshSelection::destroy.
        let objects = unsafe { create_compute_pipeline(self.device, &code.words, &entry, &kernel.bindings) }
            .map_err(|e| vk_error(&format!("creating the `{}` pipeline", module.entry_point), e))?;
        self.pipelines.push(objects);
        Ok(Pipeline { objects, kernel })
    }

    pub(crate) fn buffer(
        &mut self,
        memory: &vk::PhysicalDeviceMemoryProperties,
        size: u64,
        usage: vk::BufferUsageFlags,
        preferred: vk::MemoryPropertyFlags,
        contents: Option<&[u8]>,
    ) -> Result<OwnBuffer, EmbedError> {
        // The contents are copied into the mapping of `size` bytes: refused, before anything
        // is made, unless they fit.
        if let Some(bytes) = contents
            && !u64::try_from(bytes.len()).is_ok_and(|len| len <= size)
        {
            return Err(EmbedError::Api {
                api: "Vulkan",
                operation: "filling a buffer".into(),
                message: format!(
                    "{} bytes of contents for a buffer of {size} bytes (a bug of strata-embed)",
                    bytes.len()
                ),
            });
        }
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
                // `bytes.len() <= size`, checked above: the copy stays inside the mapping.
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
            for objects in &self.pipelines {
                destroy_compute_pipeline(self.device, objects);
            }
            for &(buffer, memory) in &self.buffers {
                self.device.destroy_buffer(buffer, None);
                self.device.free_memory(memory, None);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A Vulkan device of the first physical device, destroyed on drop.
    struct TestDevice {
        _entry: ash::Entry,
        instance: ash::Instance,
        physical_device: vk::PhysicalDevice,
        device: ash::Device,
    }

    impl TestDevice {
        /// The device, or `None` (with a note) where there is no Vulkan device and
        /// `STRATA_REQUIRE_GPU` is not set.
        fn open(test: &str) -> Option<Self> {
            let skip = |why: String| {
                assert!(!strata_backends::gpu_required(), "{test}: {why}");
                eprintln!("SKIPPED {test}: {why}");
                None
            };
            // SAFETY: loads the system's Vulkan loader; plain object creation with valid
            // create infos; every object is destroyed in Drop.
            unsafe {
                let entry = match ash::Entry::load() {
                    Ok(entry) => entry,
                    Err(error) => return skip(format!("no Vulkan loader: {error}")),
                };
                let app = vk::ApplicationInfo::default().api_version(vk::API_VERSION_1_1);
                let info = vk::InstanceCreateInfo::default().application_info(&app);
                let instance = match entry.create_instance(&info, None) {
                    Ok(instance) => instance,
                    Err(error) => return skip(format!("vkCreateInstance: {error:?}")),
                };
                let Some(&physical_device) = instance.enumerate_physical_devices().unwrap_or_default().first() else {
                    instance.destroy_instance(None);
                    return skip("no Vulkan device".into());
                };
                let priorities = [1.0];
                let queues = [vk::DeviceQueueCreateInfo::default().queue_family_index(0).queue_priorities(&priorities)];
                let create = vk::DeviceCreateInfo::default().queue_create_infos(&queues);
                let device = instance.create_device(physical_device, &create, None).expect("vkCreateDevice");
                Some(Self { _entry: entry, instance, physical_device, device })
            }
        }
    }

    impl Drop for TestDevice {
        fn drop(&mut self) {
            // SAFETY: every child object was destroyed (Created's Drop).
            unsafe {
                self.device.destroy_device(None);
                self.instance.destroy_instance(None);
            }
        }
    }

    #[test]
    fn contents_longer_than_the_buffer_are_refused_before_anything_is_made() {
        let Some(vulkan) = TestDevice::open("contents_longer_than_the_buffer_are_refused_before_anything_is_made")
        else {
            return;
        };
        // SAFETY: valid handles.
        let memory = unsafe { vulkan.instance.get_physical_device_memory_properties(vulkan.physical_device) };
        let mut created = Created {
            device: &vulkan.device,
            translate: TranslateOptions::default(),
            pipelines: Vec::new(),
            buffers: Vec::new(),
        };
        let (usage, host) = (vk::BufferUsageFlags::STORAGE_BUFFER, vk::MemoryPropertyFlags::HOST_VISIBLE);
        let error = created
            .buffer(&memory, 60, usage, host, Some(&[7; 61]))
            .err()
            .expect("61 bytes of contents for a 60-byte buffer are refused");
        let message = error.to_string();
        assert!(message.contains("61") && message.contains("60") && !message.contains('\n'), "{message}");
        assert!(created.buffers.is_empty(), "a buffer was made for contents that do not fit");
        // Contents of exactly the buffer's size fit (the buffer is destroyed with `created`).
        let fits = created.buffer(&memory, 60, usage, host, Some(&[7; 60])).expect("60 bytes fit");
        assert_eq!((fits.size, created.buffers.len()), (60, 1));
    }
}
