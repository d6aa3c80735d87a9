//! Backends that run strata's registry kernels: one [`Backend`] trait, so the host never
//! knows which one runs.
//!
//! * [`wgpu_backend::WgpuBackend`]: wgpu on Vulkan (lavapipe included) or GL.
//! * [`ash_backend::AshBackend`]: raw Vulkan through ash on naga's SPIR-V, or on SPIR-V
//!   that glslang compiled from naga's GLSL or HLSL.
//! * [`webgpu_backend::WebGpuBackend`]: WebGPU in headless Chromium (Dawn; Tint compiles
//!   the WGSL), driven over a loopback bridge.
//!
//! Every failure is a [`BackendError`]: no adapter, a missing feature, a limit the device
//! cannot meet, a binding that does not fit the kernel, a validation error, a lost
//! device. None of them panics.
//!
//! ```
//! use strata_backends::backend::{download, upload};
//! use strata_backends::cpu_backend::{CpuBackend, CpuOptions};
//! use strata_backends::{Backend, Bind};
//! use strata_kernels::Kernel;
//!
//! // Any WGSL compute shader, on the CPU interpreter (no device needed); a
//! // `WgpuBackend` or `AshBackend` runs it the same way on a GPU.
//! let source = "@group(0) @binding(0) var<storage, read_write> data: array<u32>;
//!     @compute @workgroup_size(4) fn main(@builtin(global_invocation_id) id: vec3<u32>) {
//!         data[id.x] = data[id.x] * 2u + 1u;
//!     }";
//! let kernel = Kernel::from_wgsl("double.wgsl", source.into(), "main", false)?;
//! let mut cpu = CpuBackend::new(CpuOptions::default())?;
//! let data = upload(&mut cpu, "data", &[1u32, 2, 3, 4])?;
//! cpu.dispatch(&kernel, &[Bind::new(0, data)], [1, 1, 1])?;
//! assert_eq!(download::<u32>(&mut cpu, data)?, [3, 5, 7, 9]);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#[cfg(not(target_arch = "wasm32"))]
pub mod ash_backend;
pub mod backend;
pub mod bindings_check;
pub mod cpu_backend;
pub mod device_info;
pub mod error;
pub mod pipeline_cache_file;
pub mod processes;
pub mod require_gpu;
pub mod texture;
pub mod webgpu_backend;
pub mod wgpu_backend;

#[cfg(not(target_arch = "wasm32"))]
pub use ash_backend::{AshBackend, AshOptions, SpirvSource};
pub use backend::{Backend, Bind, BufferId, Resource};
pub use device_info::{DeviceInfo, DeviceLimits};
pub use error::BackendError;
pub use require_gpu::{GPU_REQUIRED_VARIABLE, gpu_required};
pub use texture::{AddressMode, FilterMode, SamplerDesc, SamplerId, TextureDesc, TextureId};
pub use webgpu_backend::{WebGpuBackend, WebGpuOptions};
pub use wgpu_backend::{WgpuBackend, WgpuOptions};
