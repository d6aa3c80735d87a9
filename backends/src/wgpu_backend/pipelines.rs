//! One compute pipeline per registry kernel, with an explicit bind group layout built
//! from the registry's bindings (so a registry mistake fails here, not silently).
//! [`kernel_pipeline`] and [`layout_entries`] are the wgpu plumbing strata-embed's wgpu
//! flavour uses too.

use super::errors::ErrorSink;
use super::textures;
use crate::error::BackendError;
use crate::pipeline_cache_file::PipelineCacheFile;
use std::borrow::Cow;
use std::collections::HashMap;
use std::num::NonZeroU64;
use std::sync::Arc;
use strata_kernels::{BindingAccess, BindingKind, Kernel};

pub(super) struct Pipeline {
    pub(super) pipeline: wgpu::ComputePipeline,
    /// One layout per bind group, group 0 first.
    pub(super) layouts: Vec<wgpu::BindGroupLayout>,
}

/// A pipeline's key: the kernel and its overrides' values ([`Kernel::pipeline_key`]), and
/// the sampled float textures (group, binding) bound with a format this device cannot
/// filter (each such set its own layout: [`layout_entries_with`]).
type PipelineKey = (strata_kernels::PipelineKey, Vec<(u32, u32)>);

pub(super) struct PipelineCache {
    /// By kernel and its unfilterable textures ([`PipelineKey`]).
    pipelines: HashMap<PipelineKey, Arc<Pipeline>>,
    /// The driver's pipeline cache and the file it is kept in between runs, where the
    /// device has one (Vulkan) and a folder was given (`WgpuOptions::pipeline_cache`).
    driver_cache: Option<DriverCache>,
    /// Whether integer `/` and `%` are rewritten with WGSL's meaning before wgpu sees the
    /// module: wgpu's GL back end writes them as GLSL's, undefined for negative operands
    /// and zero divisors (`strata_kernels::integer_division`).
    define_integer_division: bool,
}

/// wgpu's pipeline cache, filled from its file at the start and saved after each new
/// pipeline ([`crate::pipeline_cache_file`]).
pub(super) struct DriverCache {
    cache: wgpu::PipelineCache,
    file: PipelineCacheFile,
}

impl DriverCache {
    /// The cache of `device` from `file`: empty when the file is missing or not whole,
    /// or when wgpu refuses its data (made on another adapter or wgpu version; wgpu
    /// refuses such data even with `fallback`, and a cache it refused would fail every
    /// pipeline made with it). `None` when even an empty cache cannot be made: then
    /// pipelines are made without one.
    pub(super) fn open(device: &wgpu::Device, errors: &ErrorSink, mut file: PipelineCacheFile) -> Option<Self> {
        let create = |data: Option<&[u8]>| {
            let scope = errors.scope(device);
            // SAFETY: the bytes are what `get_data` gave an earlier run, as far as a
            // file in the user's own cache folder can tell (its header and CRC catch a
            // damaged or foreign file, which reads as `None`; whoever can write the
            // folder can also write the user's programs); wgpu checks its header against
            // this adapter, and the driver its own.
            let cache = unsafe {
                device.create_pipeline_cache(&wgpu::PipelineCacheDescriptor {
                    label: Some("strata pipeline cache"),
                    data,
                    fallback: true,
                })
            };
            scope.finish("pipeline cache creation").ok().map(|()| cache)
        };
        if let Some(cache) = file.read().and_then(|data| create(Some(&data))) {
            return Some(Self { cache, file });
        }
        file.refused();
        create(None).map(|cache| Self { cache, file })
    }

    /// Saves the driver's data if it changed.
    fn save(&mut self) {
        if let Some(data) = self.cache.get_data() {
            self.file.save(&data);
        }
    }
}

impl PipelineCache {
    pub(super) fn new(define_integer_division: bool, driver_cache: Option<DriverCache>) -> Self {
        Self { pipelines: HashMap::new(), driver_cache, define_integer_division }
    }

    /// `kernel`'s pipeline for binds in which the sampled float textures `unfilterable`
    /// have a format this device cannot filter (sorted; usually none).
    pub(super) fn get_or_create(
        &mut self,
        device: &wgpu::Device,
        errors: &ErrorSink,
        kernel: &Kernel,
        unfilterable: Vec<(u32, u32)>,
    ) -> Result<Arc<Pipeline>, BackendError> {
        let key = (kernel.pipeline_key(), unfilterable);
        if let Some(pipeline) = self.pipelines.get(&key) {
            return Ok(Arc::clone(pipeline));
        }
        let scope = errors.scope(device);
        let cache = self.driver_cache.as_ref().map(|d| &d.cache);
        let (pipeline, layouts) = cached_kernel_pipeline(device, kernel, self.define_integer_division, cache, &key.1)?;
        scope.finish(&format!("pipeline creation for `{}`", kernel.name()))?;
        if let Some(driver_cache) = &mut self.driver_cache {
            driver_cache.save();
        }
        let pipeline = Arc::new(Pipeline { pipeline, layouts });
        self.pipelines.insert(key, Arc::clone(&pipeline));
        Ok(pipeline)
    }
}

/// The bind group layout entries of `kernel`'s bindings in `group`: compute stage, no
/// dynamic offsets, minimum binding sizes from the WGSL types; samplers filtering (but
/// one that samples an integer texture), and a float texture filterable exactly where
/// the kernel samples it with a sampler ([`sampled_pairs`](strata_kernels::combined_samplers::sampled_pairs), through function arguments
/// too), in whatever group that sampler is (else unfilterable, so that `r32float` and
/// `rgba32float` textures read with `textureLoad` bind on devices that cannot filter
/// them). Why per texture across groups: a blur whose sampler sits in one group and
/// whose texture in another was refused by wgpu ("Non-filterable float textures can't
/// be sampled with a filtering sampler") when filterability was decided per group.
pub fn layout_entries(kernel: &Kernel, group: u32) -> Vec<wgpu::BindGroupLayoutEntry> {
    layout_entries_with(kernel, group, &[])
}

/// [`layout_entries`] for binds in which the sampled float textures `unfilterable` have
/// a format the device cannot filter (`r32float`, `rgba32float` without
/// `FLOAT32_FILTERABLE`): those textures unfilterable, and the samplers that sample them
/// non-filtering (the bind check has refused a linear one), so that a nearest sampler
/// gathers them (wgpu refused it: "Texture binding 1 expects sample type Float {
/// filterable: true }").
pub fn layout_entries_with(
    kernel: &Kernel,
    group: u32,
    unfilterable: &[(u32, u32)],
) -> Vec<wgpu::BindGroupLayoutEntry> {
    let pairs = strata_kernels::combined_samplers::sampled_pairs(kernel);
    let sampled = |group, binding| {
        pairs.iter().any(|p| p.texture == (group, binding)) && !unfilterable.contains(&(group, binding))
    };
    // A sampler that samples an integer texture cannot filter (the bind check refuses a
    // linear one first, naming both bindings), so its layout says non-filtering and a
    // nearest sampler gathers integer texels on wgpu as on every other path.
    let integer = |slot: (u32, u32)| {
        unfilterable.contains(&slot)
            || kernel.binding(slot.0, slot.1).is_some_and(
                |b| matches!(b.kind, BindingKind::SampledTexture { kind, .. } if kind != strata_kernels::TexelKind::Float),
            )
    };
    let sampler_type = |group, binding| {
        if pairs.iter().any(|p| p.sampler == (group, binding) && integer(p.texture)) {
            wgpu::SamplerBindingType::NonFiltering
        } else {
            wgpu::SamplerBindingType::Filtering
        }
    };
    kernel
        .bindings
        .iter()
        .filter(|binding| binding.group == group)
        .map(|binding| wgpu::BindGroupLayoutEntry {
            binding: binding.binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: match binding.kind {
                BindingKind::Uniform | BindingKind::Storage(_) => wgpu::BindingType::Buffer {
                    ty: match binding.kind {
                        BindingKind::Storage(access) => {
                            wgpu::BufferBindingType::Storage { read_only: access == BindingAccess::ReadOnly }
                        }
                        _ => wgpu::BufferBindingType::Uniform,
                    },
                    has_dynamic_offset: false,
                    min_binding_size: NonZeroU64::new(binding.min_size()),
                },
                BindingKind::SampledTexture { dimension, kind } => wgpu::BindingType::Texture {
                    sample_type: textures::sample_type(kind, sampled(binding.group, binding.binding)),
                    view_dimension: textures::view_dimension(dimension),
                    multisampled: false,
                },
                BindingKind::StorageTexture { dimension, format, access } => wgpu::BindingType::StorageTexture {
                    access: textures::storage_access(access),
                    format: textures::wgpu_format(format),
                    view_dimension: textures::view_dimension(dimension),
                },
                BindingKind::Sampler => wgpu::BindingType::Sampler(sampler_type(binding.group, binding.binding)),
            },
            count: None,
        })
        .collect()
}

/// `kernel`'s compute pipeline from naga's IR, with an explicit bind group layout per
/// group of its bindings ([`layout_entries`]; one for a registry kernel). `define_integer_division`: rewrite integer `/` and `%`
/// with WGSL's meaning first, as wgpu's GL back end needs (it writes GLSL's, undefined
/// for negative operands and zero divisors). wgpu reports creation errors through the
/// device's error scopes: the caller opens them.
pub fn kernel_pipeline(
    device: &wgpu::Device,
    kernel: &Kernel,
    define_integer_division: bool,
) -> Result<(wgpu::ComputePipeline, Vec<wgpu::BindGroupLayout>), BackendError> {
    cached_kernel_pipeline(device, kernel, define_integer_division, None, &[])
}

/// [`kernel_pipeline`] through the driver's pipeline `cache` where one is given.
fn cached_kernel_pipeline(
    device: &wgpu::Device,
    kernel: &Kernel,
    define_integer_division: bool,
    cache: Option<&wgpu::PipelineCache>,
    unfilterable: &[(u32, u32)],
) -> Result<(wgpu::ComputePipeline, Vec<wgpu::BindGroupLayout>), BackendError> {
    // One layout per group (a group the kernel skips gets an empty one).
    let layouts: Vec<wgpu::BindGroupLayout> = (0..kernel.group_count())
        .map(|group| {
            let entries = layout_entries_with(kernel, group, unfilterable);
            device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some(kernel.name()),
                entries: &entries,
            })
        })
        .collect();
    let layout_refs: Vec<Option<&wgpu::BindGroupLayout>> = layouts.iter().map(Some).collect();
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(kernel.name()),
        bind_group_layouts: &layout_refs,
        immediate_size: 0,
    });
    let defined = if define_integer_division {
        strata_kernels::signed_image_levels::defined_for_glsl(&kernel.module, &kernel.info).map_err(|message| {
            BackendError::Validation {
                backend: "wgpu-gl".into(),
                operation: format!("GLSL rewrites (integer division, texture levels) of `{}`", kernel.name()),
                message,
            }
        })?
    } else {
        None
    };
    let (mut naga_module, defined_info) = match defined {
        Some((module, info)) => (module, Some(info)),
        None => (kernel.module.clone(), None),
    };
    let info = defined_info.as_ref().unwrap_or(&kernel.info);
    // On GL, wgpu's GLSL zeroes each workgroup array with one constructor of an argument
    // per element, which Mesa compiled for about a minute per histogram kernel: zero in
    // loops in the IR instead, and turn the writer's zeroing off.
    let mut zero_in_writer = true;
    if define_integer_division {
        let rewritten = strata_kernels::workgroup_zero_loops::zero_in_loops(&naga_module, info, kernel.entry_point())
            .map_err(|message| BackendError::Validation {
            backend: "wgpu-gl".into(),
            operation: format!("zeroing the workgroup memory of `{}` in loops", kernel.name()),
            message,
        })?;
        if let Some((module, _)) = rewritten {
            naga_module = module;
            zero_in_writer = false;
        }
    }
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(kernel.name()),
        source: wgpu::ShaderSource::Naga(Cow::Owned(naga_module)),
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(kernel.name()),
        layout: Some(&pipeline_layout),
        module: &module,
        entry_point: Some(kernel.entry_point()),
        compilation_options: wgpu::PipelineCompilationOptions {
            zero_initialize_workgroup_memory: zero_in_writer,
            ..Default::default()
        },
        cache,
    });
    Ok((pipeline, layouts))
}
