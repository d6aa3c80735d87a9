//! The backends the check runs on. Adding a backend is one line in [`backend_slots`].

use strata_backends::ash_backend::{AshBackend, AshOptions, SpirvSource};
use strata_backends::cpu_backend::{CpuBackend, CpuOptions};
use strata_backends::webgpu_backend::{WebGpuBackend, WebGpuOptions, find_chromium};
use strata_backends::wgpu_backend::{WgpuApi, WgpuBackend, WgpuOptions};
use strata_backends::{Backend, BackendError};

/// A named way to open a backend.
#[derive(Clone, Copy)]
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
    /// Whether the backend makes Vulkan calls through this machine's loader, which the
    /// Khronos layer sees (`cargo xtask validate` runs the check on these columns under
    /// it). The interpreter and wgpu's GL backend make none, and Chromium's WebGPU runs on
    /// its own SwiftShader with the layer's variables removed (`webgpu_backend::Browser`).
    pub host_vulkan: bool,
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

/// Without wgpu's `validation`: under wgpu the Khronos layer's messages go to the `log`
/// crate, which the check does not read, so it could fail nothing here and only cost time.
/// `cargo xtask validate` runs the check's Vulkan columns (`BackendSlot::host_vulkan`) under the
/// layer switched on from outside, and fails on its errors and warnings.
fn wgpu(api: WgpuApi) -> Result<Box<dyn Backend>, BackendError> {
    Ok(Box::new(WgpuBackend::new(WgpuOptions { api, validation: false, subgroups: true, ..Default::default() })?))
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
            host_vulkan: false,
        },
        BackendSlot {
            name: "wgpu-vulkan",
            open: || wgpu(WgpuApi::Vulkan),
            needs_vulkan: true,
            toolchain: nothing_to_install,
            host_vulkan: true,
        },
        BackendSlot {
            name: "wgpu-gl",
            open: || wgpu(WgpuApi::Gl),
            needs_vulkan: false,
            toolchain: nothing_to_install,
            host_vulkan: false,
        },
        BackendSlot {
            name: "ash",
            open: || ash(SpirvSource::Naga),
            needs_vulkan: true,
            toolchain: nothing_to_install,
            host_vulkan: true,
        },
        BackendSlot {
            name: "ash-glsl",
            open: || ash(SpirvSource::GlslangFromGlsl),
            needs_vulkan: true,
            toolchain: glslang,
            host_vulkan: true,
        },
        BackendSlot {
            name: "ash-hlsl",
            open: || ash(SpirvSource::GlslangFromHlsl),
            needs_vulkan: true,
            toolchain: glslang,
            host_vulkan: true,
        },
        // Slang is a pip package, not part of the Vulkan stack: a machine without it
        // reports the column unavailable (CI installs it).
        BackendSlot {
            name: "ash-slang",
            open: || ash(SpirvSource::SlangFromHlsl),
            needs_vulkan: false,
            toolchain: slang,
            host_vulkan: true,
        },
        // Chromium's WebGPU (Dawn; Tint compiles the WGSL, a front end other than naga)
        // in a headless tab: a machine without Chromium reports the column unavailable
        // (CI installs it).
        BackendSlot {
            name: "webgpu",
            open: || Ok(Box::new(WebGpuBackend::new(WebGpuOptions::default())?)),
            needs_vulkan: false,
            toolchain: chromium,
            host_vulkan: false,
        },
    ]
}

#[cfg(test)]
mod tests {
    /// The layer sees the Vulkan columns alone, Slang's among them (its `needs_vulkan` is
    /// false for another reason: Slang is a pip package).
    #[test]
    fn the_layer_sees_the_vulkan_columns_alone() {
        let seen: Vec<&str> = super::backend_slots().iter().filter(|s| s.host_vulkan).map(|s| s.name).collect();
        assert_eq!(seen, ["wgpu-vulkan", "ash", "ash-glsl", "ash-hlsl", "ash-slang"]);
    }
}
