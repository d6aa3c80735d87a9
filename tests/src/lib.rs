//! Shared helpers of strata's integration tests.

pub mod wgsl_fuzz;

use strata_backends::wgpu_backend::{WgpuApi, WgpuBackend, WgpuOptions};
use strata_backends::{BackendError, GPU_REQUIRED_VARIABLE, gpu_required};

/// The wgpu Vulkan backend with validation on, or `None` (with a note on stderr) when
/// the machine has no Vulkan device. Under `STRATA_REQUIRE_GPU=1` a missing device
/// fails the test instead.
pub fn vulkan_backend(test: &str) -> Option<WgpuBackend> {
    open_or_skip(test, WgpuOptions { api: WgpuApi::Vulkan, validation: true, subgroups: true })
}

/// Like [`vulkan_backend`] with explicit options.
pub fn open_or_skip(test: &str, options: WgpuOptions) -> Option<WgpuBackend> {
    match WgpuBackend::new(options) {
        Ok(backend) => Some(backend),
        Err(error @ BackendError::NoAdapter { .. }) if !gpu_required() => {
            eprintln!("SKIPPED {test}: {error} (set {GPU_REQUIRED_VARIABLE}=1 to make this a failure)");
            None
        }
        Err(error) => {
            panic!("{test}: {error} ({GPU_REQUIRED_VARIABLE} is set: a GPU device is required)")
        }
    }
}

/// A 32-bit pattern written into output buffers before a run, so that elements the
/// kernel fails to write are caught.
pub const POISON: u32 = 0xdead_beef;

/// A raw wgpu Vulkan device (no strata backend around it), as an embedding engine would
/// own one, with `limits` (the adapter's own when `None`) and subgroups if the adapter
/// has them; `None` (with a note on stderr) when the machine has no Vulkan device, a
/// failure under `STRATA_REQUIRE_GPU=1`.
pub fn engine_device(test: &str, limits: Option<wgpu::Limits>) -> Option<(wgpu::Device, wgpu::Queue)> {
    let mut descriptor = wgpu::InstanceDescriptor::new_without_display_handle();
    descriptor.backends = wgpu::Backends::VULKAN;
    let instance = wgpu::Instance::new(descriptor);
    let adapter = match pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions::default())) {
        Ok(adapter) => adapter,
        Err(error) if !gpu_required() => {
            eprintln!(
                "SKIPPED {test}: no Vulkan adapter: {error} (set {GPU_REQUIRED_VARIABLE}=1 to make this a failure)"
            );
            return None;
        }
        Err(error) => panic!("{test}: no Vulkan adapter: {error} ({GPU_REQUIRED_VARIABLE} is set)"),
    };
    let descriptor = wgpu::DeviceDescriptor {
        required_features: adapter.features() & wgpu::Features::SUBGROUP,
        required_limits: limits.unwrap_or_else(|| adapter.limits()),
        ..Default::default()
    };
    let device = pollster::block_on(adapter.request_device(&descriptor)).unwrap_or_else(|e| panic!("{test}: {e}"));
    Some(device)
}

/// Copies a wgpu buffer back to the CPU (test helper; panics on failure).
pub fn read_wgpu_buffer<T: bytemuck::Pod>(device: &wgpu::Device, queue: &wgpu::Queue, buffer: &wgpu::Buffer) -> Vec<T> {
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("read back"),
        size: buffer.size(),
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    encoder.copy_buffer_to_buffer(buffer, 0, &staging, 0, buffer.size());
    queue.submit([encoder.finish()]);
    staging.slice(..).map_async(wgpu::MapMode::Read, |result| result.expect("map"));
    device.poll(wgpu::PollType::wait_indefinitely()).expect("poll");
    let view = staging.slice(..).get_mapped_range().expect("mapped");
    bytemuck::cast_slice(&view).to_vec()
}
