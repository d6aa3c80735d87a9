//! The [`Backend`] on raw Vulkan through ash, running naga's SPIR-V (or SPIR-V that
//! glslang compiled from naga's GLSL or HLSL, to execute those translations too).
//!
//! Deliberately simple: every buffer lives in host-visible, coherent memory (persistently
//! mapped), and every dispatch is recorded, submitted and waited for on its own. That is
//! the right trade for a reference and cross-check backend; an engine's own Vulkan code
//! does its own memory management.

mod device;
mod device_setup;
mod images;
mod pipelines;
mod texture_paths;

pub use pipelines::{PipelineObjects, create_compute_pipeline, descriptor_type, destroy_compute_pipeline};

use crate::backend::{Backend, Bind, BufferId, Resource};
use crate::bindings_check::{
    ResourceLookup, check_binds, check_buffer_size, check_kernel_fits, check_workgroups, write_range,
};
use crate::device_info::DeviceInfo;
use crate::error::BackendError;
use crate::texture::{SamplerDesc, SamplerId, TextureDesc, TextureId};
use ash::vk;
use device::{Descriptor, VulkanDevice};
use images::AshImage;
use pipelines::PipelineCache;
use std::collections::HashMap;
use std::time::Duration;
use strata_kernels::{BindingKind, Kernel};

/// Where the SPIR-V the ash backend runs comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SpirvSource {
    /// naga's SPIR-V back end.
    Naga,
    /// glslang's compilation of naga's GLSL output.
    GlslangFromGlsl,
    /// glslang's compilation of naga's HLSL output.
    GlslangFromHlsl,
    /// Slang's compilation of naga's HLSL output (a second HLSL front end;
    /// `strata_kernels::slang`).
    SlangFromHlsl,
}

impl SpirvSource {
    /// Backend name suffix.
    pub fn name(self) -> &'static str {
        match self {
            SpirvSource::Naga => "ash",
            SpirvSource::GlslangFromGlsl => "ash-glsl",
            SpirvSource::GlslangFromHlsl => "ash-hlsl",
            SpirvSource::SlangFromHlsl => "ash-slang",
        }
    }
}

/// How to open an [`AshBackend`].
#[derive(Clone, Debug)]
pub struct AshOptions {
    /// Enable `VK_LAYER_KHRONOS_validation`; its warnings and errors are collected
    /// (see [`AshBackend::validation_messages`]). Fails if the layer is not installed.
    pub validation: bool,
    /// Where the SPIR-V comes from.
    pub source: SpirvSource,
    /// Let kernels use subgroup operations when the device supports them.
    pub subgroups: bool,
    /// The folder the driver's `VkPipelineCache` is kept in between runs; `None`: no
    /// file. Default: [`crate::pipeline_cache_file::default_folder`].
    pub pipeline_cache: Option<std::path::PathBuf>,
    /// Let the driver zero workgroup memory where the device offers it (Vulkan 1.3's
    /// `shaderZeroInitializeWorkgroupMemory`), as wgpu does. `false`: every pipeline zeroes
    /// it in the shader, in loops its invocations share
    /// ([`strata_kernels::translate::WorkgroupZeroInit::Polyfill`]), as on a device without
    /// the feature. Default `true`.
    pub driver_zeroes_workgroup_memory: bool,
}

impl Default for AshOptions {
    fn default() -> Self {
        Self {
            validation: false,
            source: SpirvSource::Naga,
            subgroups: true,
            pipeline_cache: crate::pipeline_cache_file::default_folder(),
            driver_zeroes_workgroup_memory: true,
        }
    }
}

/// A buffer and its persistent mapping.
///
/// Invariant (relied on by the copies of `write_buffer` and `read_buffer`): `mapped`
/// points at the start of a host-coherent mapping of at least `size` bytes (the buffer's
/// memory, `size` rounded up to whole words, mapped whole), alive until the buffer is
/// destroyed, and `usize::try_from(size)` succeeded when the buffer was created.
struct AshBuffer {
    buffer: vk::Buffer,
    memory: vk::DeviceMemory,
    mapped: *mut u8,
    size: u64,
    label: String,
}

/// A Vulkan device driven through ash.
pub struct AshBackend {
    // Field order is drop order: buffers and pipelines go before the device.
    buffers: HashMap<u64, AshBuffer>,
    images: HashMap<u64, AshImage>,
    /// Each sampler with what it was created as (the bind check reads its filters).
    samplers: HashMap<u64, (vk::Sampler, SamplerDesc)>,
    /// The sampler state of a combined image sampler whose texture is only loaded
    /// (naga's GLSL combines every sampled texture with one), made when first needed.
    any_sampler: Option<vk::Sampler>,
    next_buffer: u64,
    pipelines: PipelineCache,
    vulkan: VulkanDevice,
    info: DeviceInfo,
}

impl AshBackend {
    /// Opens the best Vulkan device: a discrete GPU first, a CPU device (lavapipe) last.
    pub fn new(options: AshOptions) -> Result<Self, BackendError> {
        if options.source == SpirvSource::SlangFromHlsl {
            if let Err(error) = strata_kernels::slang::tool() {
                return Err(BackendError::NoAdapter {
                    backend: options.source.name().into(),
                    reason: error.to_string(),
                });
            }
        } else if options.source != SpirvSource::Naga {
            let probe = std::process::Command::new("glslangValidator").arg("--version").output();
            if !probe.is_ok_and(|out| out.status.success()) {
                return Err(BackendError::NoAdapter {
                    backend: options.source.name().into(),
                    reason: "glslangValidator is not installed (Debian: apt-get install glslang-tools)".into(),
                });
            }
        }
        let vulkan = VulkanDevice::open(&options)?;
        let info = vulkan.device_info(&options);
        let driver_cache = options.pipeline_cache.as_ref().and_then(|folder| {
            let file = crate::pipeline_cache_file::PipelineCacheFile::new(folder, &vulkan.pipeline_cache_key());
            pipelines::DriverCache::open(&vulkan, file)
        });
        let pipelines = PipelineCache::new(options.source, driver_cache);
        Ok(Self {
            buffers: HashMap::new(),
            images: HashMap::new(),
            samplers: HashMap::new(),
            any_sampler: None,
            next_buffer: 0,
            pipelines,
            vulkan,
            info,
        })
    }

    /// Warnings and errors the validation layer reported so far (empty without validation).
    pub fn validation_messages(&self) -> Vec<String> {
        self.vulkan.validation_messages()
    }

    fn buffer(&self, id: BufferId) -> Result<&AshBuffer, BackendError> {
        self.buffers.get(&id.0).ok_or(BackendError::UnknownBuffer(id.0))
    }

    fn image(&self, id: TextureId) -> Result<&AshImage, BackendError> {
        self.images.get(&id.0).ok_or(BackendError::UnknownTexture(id.0))
    }

    fn sampler(&self, id: SamplerId) -> Result<vk::Sampler, BackendError> {
        self.sampler_desc(id).map(|(sampler, _)| sampler)
    }

    fn sampler_desc(&self, id: SamplerId) -> Result<(vk::Sampler, SamplerDesc), BackendError> {
        self.samplers.get(&id.0).copied().ok_or(BackendError::UnknownSampler(id.0))
    }

    fn run(
        &mut self,
        kernel: &Kernel,
        binds: &[Bind],
        workgroups: [u32; 3],
        timed: bool,
    ) -> Result<Option<Duration>, BackendError> {
        self.check_kernel(kernel)?;
        check_workgroups(kernel, workgroups, &self.info)?;
        let lookup = ResourceLookup {
            buffer_size: &|id| self.buffer(id).map(|b| b.size),
            texture: &|id| self.image(id).map(|image| image.desc.clone()),
            sampler: &|id| self.sampler_desc(id).map(|(_, desc)| desc),
        };
        check_binds(kernel, binds, &self.info, &lookup)?;
        let pipeline = self.pipelines.get_or_create(&self.vulkan, kernel)?;
        let combined = pipeline.plan.slots.iter().any(|s| s.ty == vk::DescriptorType::COMBINED_IMAGE_SAMPLER);
        if combined && self.any_sampler.is_none() {
            self.any_sampler = Some(self.vulkan.create_sampler(&crate::texture::SamplerDesc::default())?);
        }
        let resource_at =
            |slot: (u32, u32)| binds.iter().find(|b| b.slot() == slot).map(|b| b.resource).expect("checked binds");
        let descriptors = pipeline
            .plan
            .slots
            .iter()
            .map(|slot| {
                let (ty, paired) = (slot.ty, slot.sampler);
                let descriptor = match resource_at(slot.wgsl) {
                    Resource::Buffer(id) => Descriptor::Buffer(self.buffer(id)?.buffer),
                    Resource::Texture(id) if ty == vk::DescriptorType::COMBINED_IMAGE_SAMPLER => {
                        let sampler = match paired.map(resource_at) {
                            Some(Resource::Sampler(sampler)) => self.sampler(sampler)?,
                            _ => self.any_sampler.expect("created above"),
                        };
                        Descriptor::Combined(self.image(id)?.sampled_view, sampler)
                    }
                    Resource::Texture(id) => {
                        let image = self.image(id)?;
                        let storage = kernel
                            .binding(slot.wgsl.0, slot.wgsl.1)
                            .is_some_and(|info| matches!(info.kind, BindingKind::StorageTexture { .. }));
                        Descriptor::Image(if storage { image.storage_view } else { image.sampled_view })
                    }
                    Resource::Sampler(id) => Descriptor::Sampler(self.sampler(id)?),
                };
                Ok((slot.set, slot.binding, ty, descriptor))
            })
            .collect::<Result<Vec<_>, BackendError>>()?;
        self.vulkan.dispatch(pipeline.handles(), kernel, &descriptors, workgroups, timed)
    }
}

impl Backend for AshBackend {
    fn info(&self) -> &DeviceInfo {
        &self.info
    }

    fn create_buffer(&mut self, label: &str, size: u64) -> Result<BufferId, BackendError> {
        check_buffer_size(label, size, &self.info)?;
        // The copies index the mapping in usize; whole words (checked not to wrap).
        let padded = size.checked_next_multiple_of(4).filter(|&padded| usize::try_from(padded).is_ok());
        let Some(padded) = padded else {
            return Err(BackendError::Buffer {
                label: label.into(),
                reason: format!("size {size}: more bytes than this machine can address"),
            });
        };
        let (buffer, memory, mapped) = self.vulkan.create_buffer(label, padded)?;
        self.next_buffer += 1;
        self.buffers.insert(self.next_buffer, AshBuffer { buffer, memory, mapped, size, label: label.into() });
        Ok(BufferId(self.next_buffer))
    }

    fn write_buffer(&mut self, buffer: BufferId, offset: u64, data: &[u8]) -> Result<(), BackendError> {
        let entry = self.buffer(buffer)?;
        // Checked without wrapping: on Ok the range lies inside `0..entry.size`.
        let range = write_range(&entry.label, entry.size, offset, data.len())?;
        // SAFETY: `range` lies inside the buffer's `size` bytes and is `data.len()` long
        // (`write_range`'s contract, checked without wrapping), which the mapping covers from `mapped`
        // (`AshBuffer`'s invariant), so `mapped + range.start` and the `data.len()` bytes
        // after it are inside the mapping; `data` is host memory of ours, not the
        // mapping, so the two do not overlap; and no dispatch is in flight (dispatches
        // complete before `dispatch` returns), so the device does not touch the memory.
        unsafe {
            std::ptr::copy_nonoverlapping(data.as_ptr(), entry.mapped.add(range.start), data.len());
        }
        Ok(())
    }

    fn read_buffer(&mut self, buffer: BufferId) -> Result<Vec<u8>, BackendError> {
        let entry = self.buffer(buffer)?;
        let size = usize::try_from(entry.size).map_err(|_| BackendError::Buffer {
            label: entry.label.clone(),
            reason: format!("size {}: more bytes than this machine can address", entry.size),
        })?;
        let mut bytes = Vec::new();
        bytes.try_reserve_exact(size).map_err(|_| BackendError::OutOfMemory {
            backend: "ash".into(),
            operation: format!("read-back of buffer `{}` ({size} bytes)", entry.label),
        })?;
        bytes.resize(size, 0);
        // SAFETY: `bytes` holds `size` bytes, the buffer's size, which the mapping covers
        // from `mapped` (`AshBuffer`'s invariant); the two do not overlap, and no
        // dispatch is in flight (as in `write_buffer`).
        unsafe {
            std::ptr::copy_nonoverlapping(entry.mapped, bytes.as_mut_ptr(), bytes.len());
        }
        Ok(bytes)
    }

    fn destroy_buffer(&mut self, buffer: BufferId) -> Result<(), BackendError> {
        let entry = self.buffers.remove(&buffer.0).ok_or(BackendError::UnknownBuffer(buffer.0))?;
        self.vulkan.destroy_buffer(entry.buffer, entry.memory);
        Ok(())
    }

    fn create_texture(&mut self, desc: &TextureDesc) -> Result<TextureId, BackendError> {
        desc.check(&self.info)?;
        let image = self.vulkan.create_image(desc)?;
        self.next_buffer += 1;
        self.images.insert(self.next_buffer, image);
        Ok(TextureId(self.next_buffer))
    }

    fn write_texture(&mut self, texture: TextureId, level: u32, data: &[u8]) -> Result<(), BackendError> {
        let image = self.image(texture)?;
        image.desc.check_level(level, data.len())?;
        self.vulkan.write_image(image, level, data)
    }

    fn read_texture(&mut self, texture: TextureId, level: u32) -> Result<Vec<u8>, BackendError> {
        let image = self.image(texture)?;
        image.desc.check_level(level, image.desc.level_bytes(level) as usize)?;
        self.vulkan.read_image(image, level)
    }

    fn destroy_texture(&mut self, texture: TextureId) -> Result<(), BackendError> {
        let image = self.images.remove(&texture.0).ok_or(BackendError::UnknownTexture(texture.0))?;
        self.vulkan.destroy_image(&image);
        Ok(())
    }

    fn create_sampler(&mut self, desc: &SamplerDesc) -> Result<SamplerId, BackendError> {
        let sampler = self.vulkan.create_sampler(desc)?;
        self.next_buffer += 1;
        self.samplers.insert(self.next_buffer, (sampler, *desc));
        Ok(SamplerId(self.next_buffer))
    }

    fn destroy_sampler(&mut self, sampler: SamplerId) -> Result<(), BackendError> {
        let (sampler, _) = self.samplers.remove(&sampler.0).ok_or(BackendError::UnknownSampler(sampler.0))?;
        self.vulkan.destroy_sampler(sampler);
        Ok(())
    }

    fn check_kernel(&self, kernel: &Kernel) -> Result<(), BackendError> {
        check_kernel_fits(kernel, &self.info)
    }

    fn dispatch(&mut self, kernel: &Kernel, binds: &[Bind], workgroups: [u32; 3]) -> Result<(), BackendError> {
        self.run(kernel, binds, workgroups, false).map(|_| ())
    }

    fn dispatch_timed(
        &mut self,
        kernel: &Kernel,
        binds: &[Bind],
        workgroups: [u32; 3],
    ) -> Result<Duration, BackendError> {
        if !self.info.timestamps {
            return Err(BackendError::NoTimestamps(self.info.backend.clone()));
        }
        self.run(kernel, binds, workgroups, true)?.ok_or_else(|| BackendError::NoTimestamps(self.info.backend.clone()))
    }
}

impl Drop for AshBackend {
    fn drop(&mut self) {
        self.vulkan.wait_idle();
        for (_, entry) in self.buffers.drain() {
            self.vulkan.destroy_buffer(entry.buffer, entry.memory);
        }
        for (_, image) in self.images.drain() {
            self.vulkan.destroy_image(&image);
        }
        for (_, (sampler, _)) in self.samplers.drain() {
            self.vulkan.destroy_sampler(sampler);
        }
        if let Some(sampler) = self.any_sampler.take() {
            self.vulkan.destroy_sampler(sampler);
        }
        self.pipelines.destroy(&self.vulkan);
    }
}

/// A failed Vulkan call as a backend error naming what was being done.
fn vk_error(operation: &str, result: vk::Result) -> BackendError {
    match result {
        vk::Result::ERROR_DEVICE_LOST => BackendError::DeviceLost { backend: "ash".into(), reason: operation.into() },
        vk::Result::ERROR_OUT_OF_DEVICE_MEMORY | vk::Result::ERROR_OUT_OF_HOST_MEMORY => {
            BackendError::OutOfMemory { backend: "ash".into(), operation: operation.into() }
        }
        other => BackendError::Validation {
            backend: "ash".into(),
            operation: operation.into(),
            message: format!("{other:?}"),
        },
    }
}
