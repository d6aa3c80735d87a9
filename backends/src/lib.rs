//! Backends that run strata's registry kernels: one [`Backend`] trait, so the host never
//! knows which one runs.
//!
//! * [`wgpu_backend::WgpuBackend`]: wgpu on Vulkan (lavapipe included) or GL.
//! * [`ash_backend::AshBackend`]: raw Vulkan through ash on naga's SPIR-V, or on SPIR-V
//!   that glslang compiled from naga's GLSL or HLSL.
//!
//! Every failure is a [`BackendError`]: no adapter, a missing feature, a limit the device
//! cannot meet, a binding that does not fit the kernel, a validation error, a lost
//! device. None of them panics.

pub mod ash_backend;
pub mod backend;
pub mod bindings_check;
pub mod cpu_backend;
pub mod device_info;
pub mod error;
pub mod require_gpu;
pub mod wgpu_backend;

pub use ash_backend::{AshBackend, AshOptions, SpirvSource};
pub use backend::{Backend, Bind, BufferId};
pub use device_info::{DeviceInfo, DeviceLimits};
pub use error::BackendError;
pub use require_gpu::{GPU_REQUIRED_VARIABLE, gpu_required};
pub use wgpu_backend::{WgpuBackend, WgpuOptions};
