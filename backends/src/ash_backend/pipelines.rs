//! One compute pipeline per registry kernel for the ash backend: SPIR-V from naga (or
//! from glslang on naga's GLSL / HLSL), descriptor set 0 laid out from the registry.
//! [`create_compute_pipeline`] and [`destroy_compute_pipeline`] are the Vulkan plumbing
//! strata-embed's ash flavour uses too.

use super::SpirvSource;
use super::device::{ComputePipeline, VulkanDevice};
use crate::error::BackendError;
use crate::pipeline_cache_file::PipelineCacheFile;
use ash::vk;
use std::collections::HashMap;
use std::ffi::CString;
use std::sync::Arc;
use strata_kernels::combined_samplers::combined_samplers;
use strata_kernels::glslang::{self, GlslangInput};
use strata_kernels::hlsl_samplers;
use strata_kernels::translate::{self, TranslateOptions, WorkgroupZeroInit};
use strata_kernels::{BindingInfo, BindingKind, Kernel, PipelineKey};

/// The Vulkan objects of one compute pipeline with one descriptor set (set 0).
#[derive(Clone, Copy, Debug)]
pub struct PipelineObjects {
    /// Set 0's layout, from the kernel's bindings.
    pub set_layout: vk::DescriptorSetLayout,
    /// The pipeline layout (set 0 only).
    pub layout: vk::PipelineLayout,
    /// The compute pipeline.
    pub pipeline: vk::Pipeline,
}

/// The descriptor type of a binding of `kind`.
pub fn descriptor_type(kind: BindingKind) -> vk::DescriptorType {
    match kind {
        BindingKind::Uniform => vk::DescriptorType::UNIFORM_BUFFER,
        BindingKind::Storage(_) => vk::DescriptorType::STORAGE_BUFFER,
        BindingKind::SampledTexture { .. } => vk::DescriptorType::SAMPLED_IMAGE,
        BindingKind::StorageTexture { .. } => vk::DescriptorType::STORAGE_IMAGE,
        BindingKind::Sampler => vk::DescriptorType::SAMPLER,
    }
}

/// Creates a compute pipeline of the SPIR-V `words` at `entry_point`, with descriptor set
/// 0 laid out from `bindings` (compute stage, one descriptor each). On failure nothing
/// is left behind; the shader module is destroyed once the pipeline exists.
///
/// # Safety
/// `device` must be a valid device; the objects must be destroyed with
/// [`destroy_compute_pipeline`] once unused.
pub unsafe fn create_compute_pipeline(
    device: &ash::Device,
    words: &[u32],
    entry_point: &std::ffi::CStr,
    bindings: &[BindingInfo],
) -> Result<PipelineObjects, vk::Result> {
    let slots: Vec<(u32, vk::DescriptorType)> = bindings.iter().map(|b| (b.binding, descriptor_type(b.kind))).collect();
    // SAFETY: the caller's contract.
    let (set_layouts, layout, pipeline) =
        unsafe { create_with_sets(device, vk::PipelineCache::null(), words, entry_point, &[slots])? };
    Ok(PipelineObjects { set_layout: set_layouts[0], layout, pipeline })
}

/// The set layouts, pipeline layout and pipeline of `words` with descriptor sets
/// `sets` (per set, its (binding, descriptor type) slots; an empty set for a group the
/// kernel skips).
///
/// # Safety
/// As [`create_compute_pipeline`]; the objects must be destroyed once unused; `cache`
/// null or a pipeline cache of `device`.
unsafe fn create_with_sets(
    device: &ash::Device,
    cache: vk::PipelineCache,
    words: &[u32],
    entry_point: &std::ffi::CStr,
    sets: &[Vec<(u32, vk::DescriptorType)>],
) -> Result<(Vec<vk::DescriptorSetLayout>, vk::PipelineLayout, vk::Pipeline), vk::Result> {
    // SAFETY: valid device (the caller's contract) and create infos; every object made
    // is destroyed on the error paths.
    unsafe {
        let mut set_layouts = Vec::with_capacity(sets.len());
        let destroy_sets = |layouts: &[vk::DescriptorSetLayout]| {
            for &layout in layouts {
                device.destroy_descriptor_set_layout(layout, None);
            }
        };
        for slots in sets {
            let bindings: Vec<_> = slots
                .iter()
                .map(|&(binding, ty)| {
                    vk::DescriptorSetLayoutBinding::default()
                        .binding(binding)
                        .descriptor_type(ty)
                        .descriptor_count(1)
                        .stage_flags(vk::ShaderStageFlags::COMPUTE)
                })
                .collect();
            match device
                .create_descriptor_set_layout(&vk::DescriptorSetLayoutCreateInfo::default().bindings(&bindings), None)
            {
                Ok(layout) => set_layouts.push(layout),
                Err(e) => {
                    destroy_sets(&set_layouts);
                    return Err(e);
                }
            }
        }
        let module = match device.create_shader_module(&vk::ShaderModuleCreateInfo::default().code(words), None) {
            Ok(module) => module,
            Err(e) => {
                destroy_sets(&set_layouts);
                return Err(e);
            }
        };
        let layout = match device
            .create_pipeline_layout(&vk::PipelineLayoutCreateInfo::default().set_layouts(&set_layouts), None)
        {
            Ok(layout) => layout,
            Err(e) => {
                destroy_sets(&set_layouts);
                device.destroy_shader_module(module, None);
                return Err(e);
            }
        };
        let stage = vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::COMPUTE)
            .module(module)
            .name(entry_point);
        let create = [vk::ComputePipelineCreateInfo::default().stage(stage).layout(layout)];
        let result = device.create_compute_pipelines(cache, &create, None);
        device.destroy_shader_module(module, None);
        match result {
            Ok(pipelines) => Ok((set_layouts, layout, pipelines[0])),
            Err((_, e)) => {
                device.destroy_pipeline_layout(layout, None);
                destroy_sets(&set_layouts);
                Err(e)
            }
        }
    }
}

/// Destroys what [`create_compute_pipeline`] made.
///
/// # Safety
/// No command buffer that uses the pipeline may be pending; each pipeline is destroyed
/// once.
pub unsafe fn destroy_compute_pipeline(device: &ash::Device, objects: &PipelineObjects) {
    // SAFETY: per the function's contract.
    unsafe {
        device.destroy_pipeline(objects.pipeline, None);
        device.destroy_pipeline_layout(objects.layout, None);
        device.destroy_descriptor_set_layout(objects.set_layout, None);
    }
}

/// One descriptor as a pipeline's SPIR-V expects it.
#[derive(Clone, Copy, Debug)]
pub(super) struct DescriptorSlot {
    /// Its descriptor set and binding in the SPIR-V.
    pub(super) set: u32,
    pub(super) binding: u32,
    pub(super) ty: vk::DescriptorType,
    /// The WGSL `(group, binding)` whose resource it holds.
    pub(super) wgsl: (u32, u32),
    /// For a combined image sampler (naga's GLSL), the WGSL sampler whose state it
    /// carries (`None`: any sampler, the texture is only loaded).
    pub(super) sampler: Option<(u32, u32)>,
}

/// The descriptor sets as a pipeline's SPIR-V expects them.
#[derive(Clone, Debug)]
pub(super) struct DescriptorPlan {
    pub(super) slots: Vec<DescriptorSlot>,
    /// Descriptor sets of the pipeline layout.
    pub(super) sets: u32,
}

impl DescriptorPlan {
    /// The plan of `kernel` compiled from `source`: WGSL group g is set g, one descriptor
    /// per binding, except on the GLSL path, which has no sets (every binding in set 0,
    /// numbered by `Kernel::flat_binding`), makes each sampled texture a combined image
    /// sampler and gives samplers no descriptor of their own
    /// (`strata_kernels::combined_samplers`).
    fn of(kernel: &Kernel, source: SpirvSource) -> Result<Self, BackendError> {
        let plain = |b: &BindingInfo| DescriptorSlot {
            set: b.group,
            binding: b.binding,
            ty: descriptor_type(b.kind),
            wgsl: (b.group, b.binding),
            sampler: None,
        };
        if source != SpirvSource::GlslangFromGlsl {
            return Ok(Self { slots: kernel.bindings.iter().map(plain).collect(), sets: kernel.group_count() });
        }
        let pairs = combined_samplers(kernel).map_err(|why| BackendError::Unavailable {
            backend: source.name().into(),
            what: format!("kernel `{}`", kernel.name()),
            why: format!("{why}: naga's GLSL combines each texture with one sampler"),
        })?;
        let slots = kernel
            .bindings
            .iter()
            .filter(|b| b.kind != BindingKind::Sampler)
            .map(|b| {
                let pair = pairs.iter().find(|(texture, _)| *texture == (b.group, b.binding));
                DescriptorSlot {
                    set: 0,
                    binding: kernel.flat_binding(b.group, b.binding),
                    ty: if pair.is_some() {
                        vk::DescriptorType::COMBINED_IMAGE_SAMPLER
                    } else {
                        descriptor_type(b.kind)
                    },
                    wgsl: (b.group, b.binding),
                    sampler: pair.and_then(|(_, sampler)| *sampler),
                }
            })
            .collect();
        Ok(Self { slots, sets: 1 })
    }

    /// Per set, its (binding, descriptor type) slots.
    fn sets(&self) -> Vec<Vec<(u32, vk::DescriptorType)>> {
        (0..self.sets)
            .map(|set| self.slots.iter().filter(|s| s.set == set).map(|s| (s.binding, s.ty)).collect())
            .collect()
    }
}

pub(super) struct AshPipeline {
    set_layouts: Vec<vk::DescriptorSetLayout>,
    layout: vk::PipelineLayout,
    pipeline: vk::Pipeline,
    /// What each descriptor is.
    pub(super) plan: DescriptorPlan,
}

impl AshPipeline {
    /// What a dispatch binds.
    pub(super) fn handles(&self) -> ComputePipeline<'_> {
        ComputePipeline { set_layouts: &self.set_layouts, layout: self.layout, pipeline: self.pipeline }
    }
}

pub(super) struct PipelineCache {
    source: SpirvSource,
    pipelines: HashMap<PipelineKey, Arc<AshPipeline>>,
    /// The driver's pipeline cache and the file it is kept in between runs, where a
    /// folder was given (`AshOptions::pipeline_cache`).
    driver_cache: Option<DriverCache>,
}

/// A `VkPipelineCache` filled from its file at the start and saved after each new
/// pipeline ([`crate::pipeline_cache_file`]).
pub(super) struct DriverCache {
    cache: vk::PipelineCache,
    file: PipelineCacheFile,
}

impl DriverCache {
    /// The cache of `vulkan`'s device from `file` (empty when the file is missing or not
    /// whole, or when the driver refuses its data); `None` if the driver cannot make one.
    pub(super) fn open(vulkan: &VulkanDevice, mut file: PipelineCacheFile) -> Option<Self> {
        let create = |data: &[u8]| {
            // SAFETY: a valid device; the data are empty or what vkGetPipelineCacheData
            // gave an earlier run, as far as a file in the user's own cache folder can
            // tell (its header and CRC catch a damaged or foreign file; whoever can write
            // the folder can also write the user's programs), and the driver checks its
            // own header (vendor, device, pipelineCacheUUID) and ignores another
            // driver's data.
            unsafe {
                vulkan.device.create_pipeline_cache(&vk::PipelineCacheCreateInfo::default().initial_data(data), None)
            }
        };
        if let Some(cache) = file.read().and_then(|data| create(&data).ok()) {
            return Some(Self { cache, file });
        }
        // No file, or data the driver refuses outright: start empty.
        file.refused();
        create(&[]).ok().map(|cache| Self { cache, file })
    }

    /// Saves the driver's data if it changed.
    fn save(&mut self, vulkan: &VulkanDevice) {
        // SAFETY: the cache belongs to this device and is not being written meanwhile
        // (one thread owns the backend).
        if let Ok(data) = unsafe { vulkan.device.get_pipeline_cache_data(self.cache) } {
            self.file.save(&data);
        }
    }
}

impl PipelineCache {
    pub(super) fn new(source: SpirvSource, driver_cache: Option<DriverCache>) -> Self {
        Self { source, pipelines: HashMap::new(), driver_cache }
    }

    /// SPIR-V words and entry point name of `kernel` from this cache's source.
    fn spirv(&self, kernel: &Kernel, native_zero_init: bool) -> Result<(Vec<u32>, String), BackendError> {
        let glslang_input = match self.source {
            SpirvSource::Naga => {
                let workgroup_zero_init =
                    if native_zero_init { WorkgroupZeroInit::Native } else { WorkgroupZeroInit::Polyfill };
                // No naga DEBUG flag: Debian's validation layer misreads its OpSource marker.
                let translation = translate::spirv(kernel, TranslateOptions { workgroup_zero_init })?;
                return Ok((translation.words, translation.entry_point));
            }
            SpirvSource::GlslangFromGlsl => GlslangInput::Glsl,
            SpirvSource::GlslangFromHlsl => GlslangInput::Hlsl,
            SpirvSource::SlangFromHlsl => return self.slang(kernel),
        };
        // One new private folder per compilation (random name, mode 0700, made by mkdir,
        // which fails rather than reuse a folder someone else created first: the files
        // in it are compiled and read back as SPIR-V): threads of one process compile
        // kernels of the same name (every external kernel is named after its entry point,
        // often `main`). Removed when dropped.
        let failed = |message: String| BackendError::Validation {
            backend: self.source.name().into(),
            operation: format!("glslang compilation of `{}`", kernel.name()),
            message,
        };
        let dir = strata_files::private_scratch_folder("strata-glslang-")
            .map_err(|e| failed(format!("cannot make a private work folder: {e}")))?;
        glslang::compile(kernel, glslang_input, dir.path()).map_err(|error| failed(error.to_string()))
    }

    /// naga's HLSL of `kernel` (workgroup memory zeroed in the shader, as exported)
    /// compiled by Slang.
    fn slang(&self, kernel: &Kernel) -> Result<(Vec<u32>, String), BackendError> {
        let failed = |message: String| BackendError::Validation {
            backend: self.source.name().into(),
            operation: format!("Slang compilation of `{}`", kernel.name()),
            message,
        };
        let translation =
            translate::hlsl(kernel, TranslateOptions { workgroup_zero_init: WorkgroupZeroInit::Polyfill })?;
        // A new private folder, as for glslang above.
        let dir = strata_files::private_scratch_folder("strata-slang-")
            .map_err(|e| failed(format!("cannot make a private work folder: {e}")))?;
        let file = dir.path().join(format!("{}.hlsl", kernel.name()));
        let text = hlsl_samplers::plain_samplers(&translation.text).map_err(failed)?;
        // Slang refuses naga's zeroing of arrays of arrays (`(float3[4][128])0`), in
        // workgroup, private and function memory alike.
        let text = strata_kernels::hlsl_zero_init::zero_init_as_loops(&text);
        std::fs::write(&file, &text).map_err(|e| failed(format!("{}: {e}", file.display())))?;
        let words =
            strata_kernels::slang::compile_hlsl(&file, &translation.entry_point).map_err(|e| failed(e.to_string()))?;
        Ok((words, translation.entry_point))
    }

    pub(super) fn get_or_create(
        &mut self,
        vulkan: &VulkanDevice,
        kernel: &Kernel,
    ) -> Result<Arc<AshPipeline>, BackendError> {
        if let Some(pipeline) = self.pipelines.get(&kernel.pipeline_key()) {
            return Ok(Arc::clone(pipeline));
        }
        super::texture_paths::check_texture_bindings(self.source, kernel)?;
        let plan = DescriptorPlan::of(kernel, self.source)?;
        let (words, entry_point) = self.spirv(kernel, vulkan.native_zero_init)?;
        let entry_point = CString::new(entry_point).map_err(|e| BackendError::Validation {
            backend: self.source.name().into(),
            operation: format!("pipeline of `{}`", kernel.name()),
            message: e.to_string(),
        })?;
        let operation = format!("pipeline creation for `{}`", kernel.name());
        let error = |result: vk::Result| BackendError::Validation {
            backend: self.source.name().into(),
            operation: operation.clone(),
            message: format!("{result:?}"),
        };
        let cache = self.driver_cache.as_ref().map_or(vk::PipelineCache::null(), |d| d.cache);
        // SAFETY: a valid device and its cache; the pipeline is destroyed in `destroy`.
        let (set_layouts, layout, pipeline) =
            unsafe { create_with_sets(&vulkan.device, cache, &words, &entry_point, &plan.sets()) }.map_err(error)?;
        if let Some(driver_cache) = &mut self.driver_cache {
            driver_cache.save(vulkan);
        }
        let pipeline = Arc::new(AshPipeline { set_layouts, layout, pipeline, plan });
        self.pipelines.insert(kernel.pipeline_key(), Arc::clone(&pipeline));
        Ok(pipeline)
    }

    pub(super) fn destroy(&mut self, vulkan: &VulkanDevice) {
        let device = &vulkan.device;
        if let Some(driver_cache) = self.driver_cache.take() {
            // SAFETY: the device is idle; the cache is destroyed once.
            unsafe { device.destroy_pipeline_cache(driver_cache.cache, None) };
        }
        for (_, pipeline) in self.pipelines.drain() {
            // SAFETY: the device is idle; each pipeline is destroyed once.
            unsafe {
                device.destroy_pipeline(pipeline.pipeline, None);
                device.destroy_pipeline_layout(pipeline.layout, None);
                for &set_layout in &pipeline.set_layouts {
                    device.destroy_descriptor_set_layout(set_layout, None);
                }
            }
        }
    }
}
