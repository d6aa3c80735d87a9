//! The backends the check runs on. Adding a backend is one line in [`backend_slots`].

use strata_backends::ash_backend::{AshBackend, AshOptions, SpirvSource};
use strata_backends::cpu_backend::{CpuBackend, CpuOptions};
use strata_backends::wgpu_backend::{WgpuApi, WgpuBackend, WgpuOptions};
use strata_backends::{Backend, BackendError};

/// A named way to open a backend.
pub struct BackendSlot {
    /// Column name in the report.
    pub name: &'static str,
    /// Opens it (with API validation where available).
    pub open: fn() -> Result<Box<dyn Backend>, BackendError>,
    /// Whether a Vulkan device makes this backend mandatory under `STRATA_REQUIRE_GPU=1`.
    pub needs_vulkan: bool,
}

fn wgpu(api: WgpuApi) -> Result<Box<dyn Backend>, BackendError> {
    let validation = api == WgpuApi::Vulkan;
    Ok(Box::new(WgpuBackend::new(WgpuOptions { api, validation, subgroups: true, ..Default::default() })?))
}

fn ash(source: SpirvSource) -> Result<Box<dyn Backend>, BackendError> {
    Ok(Box::new(AshBackend::new(AshOptions { validation: false, source, subgroups: true, ..Default::default() })?))
}

/// Every backend of the check, in report order.
pub fn backend_slots() -> Vec<BackendSlot> {
    vec![
        BackendSlot {
            name: "cpu",
            open: || Ok(Box::new(CpuBackend::new(CpuOptions::default())?)),
            needs_vulkan: false,
        },
        BackendSlot { name: "wgpu-vulkan", open: || wgpu(WgpuApi::Vulkan), needs_vulkan: true },
        BackendSlot { name: "wgpu-gl", open: || wgpu(WgpuApi::Gl), needs_vulkan: false },
        BackendSlot { name: "ash", open: || ash(SpirvSource::Naga), needs_vulkan: true },
        BackendSlot { name: "ash-glsl", open: || ash(SpirvSource::GlslangFromGlsl), needs_vulkan: true },
        BackendSlot { name: "ash-hlsl", open: || ash(SpirvSource::GlslangFromHlsl), needs_vulkan: true },
        // Slang is a pip package, not part of the Vulkan stack: a machine without it
        // reports the column unavailable (CI installs it).
        BackendSlot { name: "ash-slang", open: || ash(SpirvSource::SlangFromHlsl), needs_vulkan: false },
    ]
}
