//! [`WgpuSelection`]: the pass on an engine's own `wgpu::Device`, recording into the
//! engine's command encoder with the engine's buffers.

use crate::binding_plan::{EngineBuffers, OwnBuffers, ResampleBuffers, Resource};
use crate::contract::{BufferRole, check_size};
use crate::error::EmbedError;
use crate::frame::{FrameId, FrameParams, frame_params, max_blocks};
use crate::limits::{DeviceLimits, WGPU_NAMES, check_limits};
use crate::wgsl::{ModuleId, WgslModule, module};
use strata_kernels::blue_noise::BlueNoiseTables;
use strata_kernels::pass_plan::PassBuffer;
use strata_kernels::selection::SelectionSettings;
use strata_kernels::{Executor, Kernel, Registry};
use wgpu::util::DeviceExt;

/// An engine buffer bound to the pass: the buffer and the byte offset where its records
/// start (a multiple of the device's `min_storage_buffer_offset_alignment`).
#[derive(Clone, Copy, Debug)]
pub struct WgpuBufferSlice<'a> {
    /// The buffer (created with `BufferUsages::STORAGE`).
    pub buffer: &'a wgpu::Buffer,
    /// Byte offset of the first record.
    pub offset: u64,
}

impl<'a> From<&'a wgpu::Buffer> for WgpuBufferSlice<'a> {
    fn from(buffer: &'a wgpu::Buffer) -> Self {
        Self { buffer, offset: 0 }
    }
}

/// The engine's buffers for [`WgpuSelection::bind`] (see [`crate::contract`]).
pub type WgpuBuffers<'a> = EngineBuffers<WgpuBufferSlice<'a>>;

/// The engine's buffers of the resampling pass.
pub type WgpuResampleBuffers<'a> = ResampleBuffers<WgpuBufferSlice<'a>>;

/// Bind groups of one set of engine buffers, made by [`WgpuSelection::bind`].
#[derive(Debug)]
pub struct WgpuBindings {
    histogram: wgpu::BindGroup,
    select: wgpu::BindGroup,
    resample: Option<wgpu::BindGroup>,
    identity_payload: bool,
}

struct Pipeline {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    kernel: &'static Kernel,
}

/// The stratified selection on an engine's wgpu device: the histogram pass, the
/// selection and (optionally) the resampling, for one image size and settings.
///
/// Per frame: the engine writes its candidates, calls [`Self::encode_selection`] (which
/// writes the frame's uniforms with `queue.write_buffer`, so encode at most one frame per
/// queue submission), reads `selections` in its own shaders, writes `resample_inputs`,
/// and calls [`Self::encode_resampling`] if it resamples with the pass.
pub struct WgpuSelection {
    settings: SelectionSettings,
    seed: u32,
    width: u32,
    height: u32,
    max_workgroups: u32,
    offset_alignment: u64,
    histogram: Pipeline,
    select: Pipeline,
    resample: Pipeline,
    own: OwnBuffers<wgpu::Buffer>,
}

fn api_error(operation: &str, error: wgpu::Error) -> EmbedError {
    EmbedError::Api { api: "wgpu", operation: operation.into(), message: error.to_string() }
}

/// Runs `f` in a validation and an out-of-memory error scope.
fn scoped<T>(device: &wgpu::Device, operation: &str, f: impl FnOnce() -> T) -> Result<T, EmbedError> {
    let memory = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
    let validation = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let value = f();
    let validation = pollster::block_on(validation.pop());
    let memory = pollster::block_on(memory.pop());
    match validation.or(memory) {
        Some(error) => Err(api_error(operation, error)),
        None => Ok(value),
    }
}

/// The module's pipeline, made by the backends' plumbing (an explicit bind-group layout
/// from the registry's bindings; on GL, integer division with WGSL's meaning).
fn pipeline(device: &wgpu::Device, module: &WgslModule) -> Result<Pipeline, EmbedError> {
    let kernel = Registry::shared()?.get(module.id.kernel());
    let define_integer_division = device.adapter_info().backend == wgpu::Backend::Gl;
    let (pipeline, mut layouts) =
        strata_backends::wgpu_backend::kernel_pipeline(device, kernel, define_integer_division).map_err(|error| {
            EmbedError::Api {
                api: "wgpu",
                operation: format!("creating the `{}` pipeline", module.entry_point),
                message: error.to_string(),
            }
        })?;
    // Registry kernels use group 0 alone: one layout.
    Ok(Pipeline { pipeline, layout: layouts.remove(0), kernel })
}

fn check_usage(role: BufferRole, slice: WgpuBufferSlice, alignment: u64) -> Result<(), EmbedError> {
    if !slice.buffer.usage().contains(wgpu::BufferUsages::STORAGE) {
        return Err(EmbedError::BufferUsage { buffer: role.name(), usage: "BufferUsages::STORAGE" });
    }
    if !slice.offset.is_multiple_of(alignment) {
        return Err(EmbedError::BufferOffset { buffer: role.name(), offset: slice.offset, alignment });
    }
    Ok(())
}

impl WgpuSelection {
    /// Builds the pipelines and the pass's own buffers (sorted lists, cluster spans, block
    /// counters, the blue-noise tables: about 1.3 MiB + 16 bytes per pixel) for a
    /// `width` × `height` image. Fails, naming the setting or the device limit, when the
    /// settings are out of range or the device cannot run the pass at this size. Uses
    /// the histogram module [`crate::wgsl::histogram_module`] picks for the device's type
    /// (`Device::adapter_info`; subgroups when the device was created with
    /// `Features::SUBGROUP`).
    /// Frames belong to the render of seed 0 until [`Self::set_seed`].
    pub fn new(
        device: &wgpu::Device,
        settings: SelectionSettings,
        width: u32,
        height: u32,
    ) -> Result<Self, EmbedError> {
        crate::frame::grid(&settings, width, height)?;
        let executor = Executor::of_device(&format!("{:?}", device.adapter_info().device_type), false);
        let subgroups = device.features().contains(wgpu::Features::SUBGROUP);
        let histogram_module = crate::wgsl::histogram_module(settings.block_size, subgroups, executor);
        let limits = device.limits();
        let blocks = max_blocks(&settings, width, height);
        check_limits(DeviceLimits::wgpu(&limits), &WGPU_NAMES, histogram_module, width, height, blocks)?;
        let (histogram_module, select_module, resample_module) =
            (module(histogram_module)?, module(ModuleId::Select)?, module(ModuleId::Resample)?);
        let pixels = u64::from(width) * u64::from(height);
        let tables = BlueNoiseTables::new();
        scoped(device, "creating the stratified selection's pipelines and buffers", || {
            let buffer = |label: &str, size: u64, usage: wgpu::BufferUsages| {
                device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(label),
                    size,
                    usage,
                    mapped_at_creation: false,
                })
            };
            let uniform = wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST;
            let storage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC;
            let own = OwnBuffers::make(pixels, blocks, |own, size| -> Result<wgpu::Buffer, ()> {
                let label = format!("strata {}", own.name());
                Ok(match own {
                    PassBuffer::BlueNoise => device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                        label: Some(&label),
                        contents: bytemuck::cast_slice(&tables.packed()),
                        usage: wgpu::BufferUsages::STORAGE,
                    }),
                    PassBuffer::HistogramParams | PassBuffer::SelectionParams => buffer(&label, size, uniform),
                    PassBuffer::Payloads => buffer(&label, size, wgpu::BufferUsages::STORAGE),
                    _ => buffer(&label, size, storage),
                })
            })
            .expect("wgpu reports buffer errors through the error scope");
            Ok(Self {
                settings,
                seed: 0,
                width,
                height,
                max_workgroups: limits.max_compute_workgroups_per_dimension,
                offset_alignment: limits.min_storage_buffer_offset_alignment.into(),
                histogram: pipeline(device, &histogram_module)?,
                select: pipeline(device, &select_module)?,
                resample: pipeline(device, &resample_module)?,
                own,
            })
        })?
    }

    /// The settings.
    pub fn settings(&self) -> &SelectionSettings {
        &self.settings
    }

    /// Starts an independent render: a new seed for the frames recorded from now on
    /// (for example per run of an unbiasedness test); costs nothing.
    pub fn set_seed(&mut self, seed: u32) {
        self.seed = seed;
    }

    /// The seed of the frames recorded from now on.
    pub fn seed(&self) -> u32 {
        self.seed
    }

    /// The image size.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// The histogram's outputs, for engines that read the sorted runs themselves:
    /// `sorted_pixels` (per block, pixel indices in cluster-then-key order) and `spans`
    /// (one `ClusterSpan` per pixel), valid after [`Self::encode_selection`].
    pub fn histogram_buffers(&self) -> (&wgpu::Buffer, &wgpu::Buffer) {
        (&self.own.sorted_pixels, &self.own.spans)
    }

    /// The parameters frame `frame` runs with.
    pub fn frame_params(&self, frame: u32, identity_payload: bool) -> Result<FrameParams, EmbedError> {
        let id = FrameId { frame, seed: self.seed, identity_payload };
        Ok(frame_params(&self.settings, self.width, self.height, id, self.max_workgroups)?)
    }

    /// Checks the engine's buffers against the contract and makes their bind groups.
    pub fn bind(&self, device: &wgpu::Device, buffers: &WgpuBuffers) -> Result<WgpuBindings, EmbedError> {
        for (role, slice) in buffers.roles() {
            check_usage(role, slice, self.offset_alignment)?;
            check_size(role, slice.buffer.size().saturating_sub(slice.offset), self.width, self.height)?;
        }
        fn resource<'a>(resource: &Resource<'a, wgpu::Buffer, WgpuBufferSlice<'a>>) -> wgpu::BindingResource<'a> {
            match *resource {
                Resource::Own(buffer) => buffer.as_entire_binding(),
                Resource::Engine(slice) => wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: slice.buffer,
                    offset: slice.offset,
                    size: None,
                }),
            }
        }
        let group = |pipeline: &Pipeline, resources: &[(&'static str, Resource<'_, wgpu::Buffer, WgpuBufferSlice>)]| {
            let entries: Vec<_> = strata_kernels::pass_plan::numbered(pipeline.kernel, resources)
                .iter()
                .map(|(binding, r)| wgpu::BindGroupEntry { binding: *binding, resource: resource(r) })
                .collect();
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("strata selection"),
                layout: &pipeline.layout,
                entries: &entries,
            })
        };
        let plan = buffers.plan(&self.own);
        scoped(device, "binding the engine's buffers", || WgpuBindings {
            histogram: group(&self.histogram, &plan.histogram),
            select: group(&self.select, &plan.select),
            resample: plan.resample.as_ref().map(|resources| group(&self.resample, resources)),
            identity_payload: buffers.payloads.is_none(),
        })
    }

    /// Records frame `frame`'s histogram and selection into `encoder` (two compute
    /// passes) after writing the frame's uniforms through `queue`.
    pub fn encode_selection(
        &self,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        bindings: &WgpuBindings,
        frame: u32,
    ) -> Result<(), EmbedError> {
        let params = self.frame_params(frame, bindings.identity_payload)?;
        queue.write_buffer(&self.own.histogram_params, 0, bytemuck::bytes_of(&params.histogram));
        queue.write_buffer(&self.own.selection_params, 0, bytemuck::bytes_of(&params.selection));
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("strata histogram + selection"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.histogram.pipeline);
        pass.set_bind_group(0, &bindings.histogram, &[]);
        let [x, y, z] = params.histogram_workgroups;
        pass.dispatch_workgroups(x, y, z);
        pass.set_pipeline(&self.select.pipeline);
        pass.set_bind_group(0, &bindings.select, &[]);
        let [x, y, z] = params.pixel_workgroups;
        pass.dispatch_workgroups(x, y, z);
        Ok(())
    }

    /// Records the resampling of the engine's `resample_inputs` (written after the
    /// selection of the same frame) into `encoder`.
    pub fn encode_resampling(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        bindings: &WgpuBindings,
    ) -> Result<(), EmbedError> {
        let group = bindings.resample.as_ref().ok_or(EmbedError::NoResampleBuffers)?;
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("strata resampling"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.resample.pipeline);
        pass.set_bind_group(0, group, &[]);
        let [x, y, z] = crate::frame::pixel_workgroups(self.width, self.height)?;
        pass.dispatch_workgroups(x, y, z);
        Ok(())
    }
}
