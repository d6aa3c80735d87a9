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

/// Without wgpu's `validation`: under wgpu the Khronos layer's messages go to the `log`
/// crate, which the check does not read, so it could fail nothing here and only cost time.
/// `cargo xtask validate` runs the check's Vulkan columns ([`HOST_VULKAN_SLOTS`]) under the
/// layer switched on from outside, and fails on its errors and warnings.
fn wgpu(api: WgpuApi) -> Result<Box<dyn Backend>, BackendError> {
    Ok(Box::new(WgpuBackend::new(WgpuOptions { api, validation: false, subgroups: true, ..Default::default() })?))
}

fn ash(source: SpirvSource) -> Result<Box<dyn Backend>, BackendError> {
    Ok(Box::new(AshBackend::new(AshOptions { validation: false, source, subgroups: true, ..Default::default() })?))
}

/// The columns whose backends make Vulkan calls through this machine's loader, which the
/// Khronos layer sees (`cargo xtask validate` runs the check on these under it). The
/// interpreter and wgpu's GL backend make none, and Chromium's WebGPU runs on its own
/// SwiftShader with the layer's variables removed (`webgpu_backend::Browser`).
pub const HOST_VULKAN_SLOTS: &[&str] = &["wgpu-vulkan", "ash", "ash-glsl", "ash-hlsl", "ash-slang"];

/// The backends of the check named in `names` (report names, `cpu`, `ash-glsl`, ...), in
/// report order; every backend when `names` is empty or holds `all`. An unknown or empty
/// name is an error naming it and the known ones.
pub fn backend_slots_named(names: &[String]) -> Result<Vec<BackendSlot>, String> {
    let slots = backend_slots();
    if names.iter().any(|name| name == "all") {
        return Ok(slots);
    }
    if let Some(unknown) = names.iter().find(|name| !slots.iter().any(|slot| slot.name == name.as_str())) {
        if unknown.is_empty() {
            let known: Vec<&str> = slots.iter().map(|slot| slot.name).collect();
            return Err(format!("\"\": an empty name (backends: {}, or all)", known.join(", ")));
        }
        let known: Vec<&str> = slots.iter().map(|slot| slot.name).collect();
        return Err(format!("{unknown}: no such backend (backends: {}, or all)", known.join(", ")));
    }
    Ok(slots.into_iter().filter(|slot| names.is_empty() || names.iter().any(|name| name == slot.name)).collect())
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

#[cfg(test)]
mod named_tests {
    use super::backend_slots_named;

    fn names(asked: &[&str]) -> Result<Vec<&'static str>, String> {
        let asked: Vec<String> = asked.iter().map(|name| name.to_string()).collect();
        backend_slots_named(&asked).map(|slots| slots.iter().map(|slot| slot.name).collect())
    }

    #[test]
    fn the_named_backends_come_in_report_order_and_none_named_is_all() {
        assert_eq!(names(&["ash-slang", "cpu", "ash"]).unwrap(), ["cpu", "ash", "ash-slang"]);
        assert_eq!(names(&[]).unwrap().len(), super::backend_slots().len());
    }

    #[test]
    fn an_unknown_backend_is_an_error_naming_it_and_the_known_ones() {
        let why = names(&["ash", "vulkan"]).unwrap_err();
        assert!(why.starts_with("vulkan: no such backend (backends: cpu, wgpu-vulkan,"), "{why}");
        assert!(why.ends_with("webgpu, or all)"), "{why}");
        assert!(names(&[""]).unwrap_err().starts_with("\"\": an empty name (backends: cpu,"));
        assert_eq!(names(&["ash", "all"]).unwrap().len(), super::backend_slots().len());
    }

    #[test]
    fn the_host_vulkan_columns_are_columns_of_the_check() {
        let asked: Vec<&str> = super::HOST_VULKAN_SLOTS.to_vec();
        assert_eq!(names(&asked).unwrap(), asked);
    }
}
