//! The backends the check runs on. Adding a backend is one line in [`backend_slots`].

use strata_backends::ash_backend::{AshBackend, AshOptions, SpirvSource};
use strata_backends::cpu_backend::{CpuBackend, CpuOptions};
use strata_backends::webgpu_backend::{WebGpuBackend, WebGpuOptions, find_chromium};
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
    /// Whether the tools the path runs besides its device (a shader compiler) are
    /// installed: `Err` says which is missing and how to install it. `--backend all`
    /// lists such a path as unavailable rather than failing the run.
    pub toolchain: fn() -> Result<(), String>,
}

/// No tools beyond the device.
fn nothing_to_install() -> Result<(), String> {
    Ok(())
}

/// glslang (`glslangValidator`, Debian's `glslang-tools`): missing only when it is not
/// found at all (one that runs and fails is the run's failure to report).
fn glslang() -> Result<(), String> {
    match strata_kernels::glslang::run_tool("glslangValidator", &[std::ffi::OsStr::new("--version")]) {
        Err(strata_kernels::glslang::ToolError::Missing(_)) => {
            Err("`glslangValidator` is not installed (apt-get install glslang-tools)".into())
        }
        _ => Ok(()),
    }
}

/// Slang (the `slangpy` wheel's library) and the C++ compiler that builds strata's driver
/// for it.
fn slang() -> Result<(), String> {
    match strata_kernels::slang::tool() {
        Err(missing @ strata_kernels::glslang::ToolError::Missing(_)) => Err(missing.to_string()),
        _ => Ok(()),
    }
}

/// Chromium (Debian's `chromium`, or `STRATA_CHROMIUM`), whose WebGPU the `webgpu` path
/// runs on.
fn chromium() -> Result<(), String> {
    find_chromium().map(|_| ())
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
            toolchain: nothing_to_install,
        },
        BackendSlot {
            name: "wgpu-vulkan",
            open: || wgpu(WgpuApi::Vulkan),
            needs_vulkan: true,
            toolchain: nothing_to_install,
        },
        BackendSlot { name: "wgpu-gl", open: || wgpu(WgpuApi::Gl), needs_vulkan: false, toolchain: nothing_to_install },
        BackendSlot { name: "ash", open: || ash(SpirvSource::Naga), needs_vulkan: true, toolchain: nothing_to_install },
        BackendSlot {
            name: "ash-glsl",
            open: || ash(SpirvSource::GlslangFromGlsl),
            needs_vulkan: true,
            toolchain: glslang,
        },
        BackendSlot {
            name: "ash-hlsl",
            open: || ash(SpirvSource::GlslangFromHlsl),
            needs_vulkan: true,
            toolchain: glslang,
        },
        // Slang is a pip package, not part of the Vulkan stack: a machine without it
        // reports the column unavailable (CI installs it).
        BackendSlot {
            name: "ash-slang",
            open: || ash(SpirvSource::SlangFromHlsl),
            needs_vulkan: false,
            toolchain: slang,
        },
        // Chromium's WebGPU (Dawn; Tint compiles the WGSL, a front end other than naga)
        // in a headless tab: a machine without Chromium reports the column unavailable
        // (CI installs it).
        BackendSlot {
            name: "webgpu",
            open: || Ok(Box::new(WebGpuBackend::new(WebGpuOptions::default())?)),
            needs_vulkan: false,
            toolchain: chromium,
        },
    ]
}
