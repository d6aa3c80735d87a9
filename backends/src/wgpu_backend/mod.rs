//! The [`Backend`] on wgpu: the platform's own API (Vulkan on Linux, lavapipe on
//! machines without a GPU; Metal on macOS; DX12, else Vulkan, on Windows) or GL.

mod buffers;
mod errors;
mod gl_textures;
mod pipelines;
mod textures;

pub use pipelines::{kernel_pipeline, layout_entries};
// The WebGPU backend builds the same bind group layouts.
pub(crate) use pipelines::layout_entries_with;
pub(crate) use textures::wgpu_format;

use crate::backend::{Backend, Bind, BufferId, Resource};
use crate::bindings_check::{ResourceLookup, check_binds, check_kernel_fits, check_workgroups, check_write};
use crate::device_info::{DeviceInfo, DeviceLimits};
use crate::error::BackendError;
use crate::pipeline_cache_file::PipelineCacheFile;
use crate::texture::{SamplerDesc, SamplerId, TextureDesc, TextureId};
use buffers::BufferTable;
use errors::ErrorSink;
use pipelines::PipelineCache;
use std::time::Duration;
use strata_kernels::{BindingKind, Kernel};
use textures::TextureTable;

/// Which wgpu backend to open.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WgpuApi {
    /// The platform's primary API: Vulkan, Metal or DX12, whichever the build has and
    /// the machine offers (wgpu's `Backends::PRIMARY`).
    Primary,
    /// Vulkan (lavapipe counts).
    Vulkan,
    /// OpenGL / GLES through EGL.
    Gl,
}

/// How to open a [`WgpuBackend`].
#[derive(Clone, Debug)]
pub struct WgpuOptions {
    /// The graphics API.
    pub api: WgpuApi,
    /// Turn on the API's validation (Vulkan validation layer where installed).
    pub validation: bool,
    /// Request subgroup operations when the adapter has them.
    pub subgroups: bool,
    /// The folder the driver's pipeline cache is kept in between runs, where the
    /// adapter has one (wgpu's `PIPELINE_CACHE`, Vulkan only); `None`: no file.
    /// Default: [`crate::pipeline_cache_file::default_folder`].
    pub pipeline_cache: Option<std::path::PathBuf>,
}

impl Default for WgpuOptions {
    fn default() -> Self {
        Self {
            api: WgpuApi::Vulkan,
            validation: false,
            subgroups: true,
            pipeline_cache: crate::pipeline_cache_file::default_folder(),
        }
    }
}

/// A wgpu device running registry kernels.
pub struct WgpuBackend {
    device: wgpu::Device,
    queue: wgpu::Queue,
    info: DeviceInfo,
    buffers: BufferTable,
    textures: TextureTable,
    pipelines: PipelineCache,
    errors: ErrorSink,
    timestamps: Option<(wgpu::QuerySet, wgpu::Buffer, wgpu::Buffer)>,
}

impl WgpuBackend {
    /// Opens the first adapter of `options.api`.
    pub fn new(options: WgpuOptions) -> Result<Self, BackendError> {
        let backend_name = match options.api {
            WgpuApi::Primary => "wgpu",
            WgpuApi::Vulkan => "wgpu-vulkan",
            WgpuApi::Gl => "wgpu-gl",
        };
        let mut descriptor = wgpu::InstanceDescriptor::new_without_display_handle();
        descriptor.backends = match options.api {
            WgpuApi::Primary => wgpu::Backends::PRIMARY,
            WgpuApi::Vulkan => wgpu::Backends::VULKAN,
            WgpuApi::Gl => wgpu::Backends::GL,
        };
        // VALIDATION only: DEBUG makes naga's SPIR-V carry an OpSource marker that
        // Debian's validation layer misreports.
        descriptor.flags =
            if options.validation { wgpu::InstanceFlags::VALIDATION } else { wgpu::InstanceFlags::empty() };
        let instance = wgpu::Instance::new(descriptor);
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: None,
            apply_limit_buckets: false,
        }))
        .map_err(|e| BackendError::NoAdapter { backend: backend_name.into(), reason: e.to_string() })?;

        let adapter_features = adapter.features();
        let mut features = wgpu::Features::empty();
        let subgroups = options.subgroups && adapter_features.contains(wgpu::Features::SUBGROUP);
        if subgroups {
            features |= wgpu::Features::SUBGROUP;
        }
        // 64-bit integers and f16 in shaders where the adapter has them (lavapipe
        // does), so that external kernels using `i64`/`u64`/`f16` run.
        features |= adapter_features & (wgpu::Features::SHADER_INT64 | wgpu::Features::SHADER_F16);
        // Filtering of 32-bit float textures and read-write storage textures of every
        // format the adapter allows, where it has them (lavapipe does).
        features |= adapter_features
            & (wgpu::Features::FLOAT32_FILTERABLE | wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES);
        let timestamps = adapter_features.contains(wgpu::Features::TIMESTAMP_QUERY);
        if timestamps {
            features |= wgpu::Features::TIMESTAMP_QUERY;
        }
        // The driver's pipeline cache, kept in a file named after the device.
        let cache_file = match (&options.pipeline_cache, wgpu::util::pipeline_cache_key(&adapter.get_info())) {
            (Some(folder), Some(key)) if adapter_features.contains(wgpu::Features::PIPELINE_CACHE) => {
                features |= wgpu::Features::PIPELINE_CACHE;
                Some(PipelineCacheFile::new(folder, &key))
            }
            _ => None,
        };
        let limits = adapter.limits();
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("strata"),
            required_features: features,
            required_limits: limits.clone(),
            ..Default::default()
        }))
        .map_err(|e| BackendError::DeviceCreation { backend: backend_name.into(), reason: e.to_string() })?;

        let adapter_info = adapter.get_info();
        // The API the adapter runs on names the backend (`wgpu-vulkan`, `wgpu-metal`,
        // `wgpu-dx12`, `wgpu-gl`).
        let backend_name: &'static str = match adapter_info.backend {
            wgpu::Backend::Vulkan => "wgpu-vulkan",
            wgpu::Backend::Metal => "wgpu-metal",
            wgpu::Backend::Dx12 => "wgpu-dx12",
            wgpu::Backend::Gl => "wgpu-gl",
            _ => backend_name,
        };
        let errors = ErrorSink::install(&device, backend_name);
        let info = DeviceInfo {
            backend: backend_name.into(),
            adapter: adapter_info.name.clone(),
            device_type: format!("{:?}", adapter_info.device_type),
            driver: format!("{} {}", adapter_info.driver, adapter_info.driver_info).trim().into(),
            subgroup_sizes: subgroups.then_some((adapter_info.subgroup_min_size, adapter_info.subgroup_max_size)),
            timestamps,
            float32_filterable: features.contains(wgpu::Features::FLOAT32_FILTERABLE),
            limits: DeviceLimits {
                max_workgroup_storage: u64::from(limits.max_compute_workgroup_storage_size),
                max_invocations_per_workgroup: limits.max_compute_invocations_per_workgroup,
                max_workgroup_size: [
                    limits.max_compute_workgroup_size_x,
                    limits.max_compute_workgroup_size_y,
                    limits.max_compute_workgroup_size_z,
                ],
                max_workgroups_per_dimension: limits.max_compute_workgroups_per_dimension,
                max_storage_binding: limits.max_storage_buffer_binding_size,
                max_uniform_binding: limits.max_uniform_buffer_binding_size,
                max_buffer_size: limits.max_buffer_size,
                max_storage_buffers_per_stage: limits.max_storage_buffers_per_shader_stage,
                max_texture_2d: limits.max_texture_dimension_2d.min(limits.max_texture_dimension_1d),
                max_texture_3d: limits.max_texture_dimension_3d,
                max_texture_layers: limits.max_texture_array_layers,
                max_bind_groups: limits.max_bind_groups,
            },
        };
        let timestamps = timestamps.then(|| {
            let set = device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("strata timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: 2,
            });
            let resolve = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("strata timestamp resolve"),
                size: 16,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            let readback = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("strata timestamp readback"),
                size: 16,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            (set, resolve, readback)
        });
        let driver_cache = cache_file.and_then(|file| pipelines::DriverCache::open(&device, &errors, file));
        let pipelines = PipelineCache::new(options.api == WgpuApi::Gl, driver_cache);
        Ok(Self {
            device,
            queue,
            info,
            buffers: BufferTable::default(),
            textures: TextureTable::default(),
            pipelines,
            errors,
            timestamps,
        })
    }

    /// The device memory allocations alive once submitted work has completed (count,
    /// bytes), from wgpu's allocator report: what a leak check watches over a long run
    /// (wgpu frees destroyed resources when it next polls, so this waits for the device
    /// first). `None` where wgpu keeps no report (its GL backend).
    pub fn live_allocations(&self) -> Option<(usize, u64)> {
        self.device.poll(wgpu::PollType::wait_indefinitely()).ok()?;
        let report = self.device.generate_allocator_report()?;
        Some((report.allocations.len(), report.total_allocated_bytes))
    }

    fn encode(
        &mut self,
        kernel: &Kernel,
        binds: &[Bind],
        workgroups: [u32; 3],
        timed: bool,
    ) -> Result<(), BackendError> {
        self.check_kernel(kernel)?;
        check_workgroups(kernel, workgroups, &self.info)?;
        let lookup = ResourceLookup {
            buffer_size: &|id| self.buffers.get(id).map(|b| b.size),
            texture: &|id| self.textures.get(id).map(|t| t.desc.clone()),
            sampler: &|id| self.textures.sampler_desc(id),
        };
        check_binds(kernel, binds, &self.info, &lookup)?;
        // Sampled float textures bound with a format this device cannot filter get a
        // layout of their own (`pipelines::layout_entries_with`).
        let mut unfilterable: Vec<(u32, u32)> = binds
            .iter()
            .filter_map(|bind| match bind.resource {
                Resource::Texture(id) => Some((bind, id)),
                _ => None,
            })
            .filter(|(bind, _)| {
                kernel.binding(bind.group, bind.binding).is_some_and(|info| {
                    matches!(info.kind, BindingKind::SampledTexture { kind: strata_kernels::TexelKind::Float, .. })
                })
            })
            .filter(|(_, id)| {
                self.textures
                    .get(*id)
                    .is_ok_and(|entry| !entry.desc.format.filterable() && !self.info.float32_filterable)
            })
            .map(|(bind, _)| (bind.group, bind.binding))
            .collect();
        unfilterable.sort_unstable();
        let pipeline = self.pipelines.get_or_create(&self.device, &self.errors, kernel, unfilterable)?;
        let scope = self.errors.scope(&self.device);
        // A storage texture binding sees one mip level (level 0); a sampled one all.
        let views = binds
            .iter()
            .map(|bind| match bind.resource {
                Resource::Texture(id) => {
                    let storage = kernel
                        .binding(bind.group, bind.binding)
                        .is_some_and(|info| matches!(info.kind, BindingKind::StorageTexture { .. }));
                    let entry = self.textures.get(id)?;
                    Ok(Some(entry.texture.create_view(&wgpu::TextureViewDescriptor {
                        dimension: Some(textures::view_dimension(entry.desc.dimension)),
                        mip_level_count: storage.then_some(1),
                        ..Default::default()
                    })))
                }
                _ => Ok(None),
            })
            .collect::<Result<Vec<_>, BackendError>>()?;
        let entries = binds
            .iter()
            .zip(&views)
            .map(|(bind, view)| {
                let resource = match (bind.resource, view) {
                    (Resource::Buffer(id), _) => self.buffers.get(id)?.buffer.as_entire_binding(),
                    (Resource::Sampler(id), _) => wgpu::BindingResource::Sampler(self.textures.sampler(id)?),
                    (Resource::Texture(_), Some(view)) => wgpu::BindingResource::TextureView(view),
                    (Resource::Texture(id), None) => return Err(BackendError::UnknownTexture(id.0)),
                };
                Ok((bind.group, wgpu::BindGroupEntry { binding: bind.binding, resource }))
            })
            .collect::<Result<Vec<_>, BackendError>>()?;
        // One bind group per group of the pipeline's layout (empty for a skipped group).
        let bind_groups: Vec<wgpu::BindGroup> = pipeline
            .layouts
            .iter()
            .enumerate()
            .map(|(group, layout)| {
                let entries: Vec<wgpu::BindGroupEntry> =
                    entries.iter().filter(|(g, _)| *g as usize == group).map(|(_, e)| e.clone()).collect();
                self.device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some(kernel.name()),
                    layout,
                    entries: &entries,
                })
            })
            .collect();
        let mut encoder =
            self.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(kernel.name()) });
        {
            let timestamp_writes = match (&self.timestamps, timed) {
                (Some((set, _, _)), true) => Some(wgpu::ComputePassTimestampWrites {
                    query_set: set,
                    beginning_of_pass_write_index: Some(0),
                    end_of_pass_write_index: Some(1),
                }),
                _ => None,
            };
            let mut pass = encoder
                .begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some(kernel.name()), timestamp_writes });
            pass.set_pipeline(&pipeline.pipeline);
            for (group, bind_group) in bind_groups.iter().enumerate() {
                pass.set_bind_group(group as u32, bind_group, &[]);
            }
            pass.dispatch_workgroups(workgroups[0], workgroups[1], workgroups[2]);
        }
        if let (Some((set, resolve, readback)), true) = (&self.timestamps, timed) {
            encoder.resolve_query_set(set, 0..2, resolve, 0);
            encoder.copy_buffer_to_buffer(resolve, 0, readback, 0, 16);
        }
        self.queue.submit([encoder.finish()]);
        scope.finish(&format!("dispatch of `{}`", kernel.name()))
    }

    fn wait(&self) -> Result<(), BackendError> {
        self.device.poll(wgpu::PollType::wait_indefinitely()).map_err(|e| self.errors.lost_or(e.to_string()))?;
        self.errors.check_lost()
    }
}

impl Backend for WgpuBackend {
    fn info(&self) -> &DeviceInfo {
        &self.info
    }

    fn create_buffer(&mut self, label: &str, size: u64) -> Result<BufferId, BackendError> {
        self.buffers.create(&self.device, &self.errors, &self.info, label, size)
    }

    fn write_buffer(&mut self, buffer: BufferId, offset: u64, data: &[u8]) -> Result<(), BackendError> {
        let entry = self.buffers.get(buffer)?;
        check_write(&entry.label, entry.size, offset, data.len())?;
        self.queue.write_buffer(&entry.buffer, offset, data);
        Ok(())
    }

    fn read_buffer(&mut self, buffer: BufferId) -> Result<Vec<u8>, BackendError> {
        let entry = self.buffers.get(buffer)?;
        buffers::read_back(&self.device, &self.queue, &self.errors, entry)
    }

    fn destroy_buffer(&mut self, buffer: BufferId) -> Result<(), BackendError> {
        self.buffers.destroy(buffer)
    }

    fn create_texture(&mut self, desc: &TextureDesc) -> Result<TextureId, BackendError> {
        self.textures.create(&self.device, &self.errors, &self.info, desc)
    }

    fn write_texture(&mut self, texture: TextureId, level: u32, data: &[u8]) -> Result<(), BackendError> {
        self.textures.write(&self.queue, texture, level, data)
    }

    fn read_texture(&mut self, texture: TextureId, level: u32) -> Result<Vec<u8>, BackendError> {
        self.textures.read(&self.device, &self.queue, &self.errors, texture, level)
    }

    fn destroy_texture(&mut self, texture: TextureId) -> Result<(), BackendError> {
        self.textures.destroy(texture)
    }

    fn create_sampler(&mut self, desc: &SamplerDesc) -> Result<SamplerId, BackendError> {
        Ok(self.textures.create_sampler(&self.device, desc))
    }

    fn destroy_sampler(&mut self, sampler: SamplerId) -> Result<(), BackendError> {
        self.textures.destroy_sampler(sampler)
    }

    fn check_kernel(&self, kernel: &Kernel) -> Result<(), BackendError> {
        if self.info.backend == "wgpu-gl" {
            gl_textures::check_gl_textures(kernel)?;
        }
        check_kernel_fits(kernel, &self.info)
    }

    fn dispatch(&mut self, kernel: &Kernel, binds: &[Bind], workgroups: [u32; 3]) -> Result<(), BackendError> {
        self.encode(kernel, binds, workgroups, false)
    }

    fn dispatch_timed(
        &mut self,
        kernel: &Kernel,
        binds: &[Bind],
        workgroups: [u32; 3],
    ) -> Result<Duration, BackendError> {
        if self.timestamps.is_none() {
            return Err(BackendError::NoTimestamps(self.info.backend.clone()));
        }
        self.encode(kernel, binds, workgroups, true)?;
        self.wait()?;
        let (_, _, readback) = self.timestamps.as_ref().expect("checked above");
        let bytes = buffers::map_read(&self.device, &self.errors, readback, 16)?;
        let ticks: [u64; 2] = bytemuck::pod_read_unaligned(&bytes);
        let nanos = ticks[1].saturating_sub(ticks[0]) as f64 * f64::from(self.queue.get_timestamp_period());
        Ok(Duration::from_nanos(nanos as u64))
    }
}
