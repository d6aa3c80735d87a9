//! Picking a backend for the command line: the GPU if there is one.

use strata_backends::ash_backend::{AshBackend, AshOptions};
use strata_backends::cpu_backend::{CpuBackend, CpuOptions};
use strata_backends::wgpu_backend::{WgpuApi, WgpuBackend, WgpuOptions};
use strata_backends::{Backend, BackendError};

/// Backends the command line can be asked for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum BackendChoice {
    /// The best available: wgpu on the platform's API (Vulkan on Linux, Metal on macOS,
    /// DX12 or Vulkan on Windows), else the CPU interpreter.
    Auto,
    /// wgpu on the platform's API (Vulkan, Metal or DX12).
    Wgpu,
    /// wgpu on OpenGL (no subgroups).
    WgpuGl,
    /// Raw Vulkan through ash, on naga's SPIR-V.
    Ash,
    /// The CPU interpreter of naga IR (no GPU needed; slow).
    Cpu,
}

/// Opens the requested backend as [`open_backend`] does, without the notice of a
/// fall-back (for a helper's second device: the user was told once already).
pub fn open_backend_quietly(choice: BackendChoice) -> Result<Box<dyn Backend>, BackendError> {
    match choice {
        BackendChoice::Auto => match WgpuBackend::new(WgpuOptions { api: WgpuApi::Primary, ..Default::default() }) {
            Ok(backend) => Ok(Box::new(backend)),
            Err(_) => Ok(Box::new(CpuBackend::new(CpuOptions::default())?)),
        },
        other => open_backend(other),
    }
}

/// Opens the requested backend. `Auto` falls back to the CPU interpreter of naga IR,
/// with a one-line notice on stderr, when no Vulkan adapter exists.
pub fn open_backend(choice: BackendChoice) -> Result<Box<dyn Backend>, BackendError> {
    let api = match choice {
        BackendChoice::Auto | BackendChoice::Wgpu => WgpuApi::Primary,
        BackendChoice::WgpuGl => WgpuApi::Gl,
        BackendChoice::Ash => return Ok(Box::new(AshBackend::new(AshOptions::default())?)),
        BackendChoice::Cpu => return Ok(Box::new(CpuBackend::new(CpuOptions::default())?)),
    };
    match WgpuBackend::new(WgpuOptions { api, ..Default::default() }) {
        Ok(backend) => Ok(Box::new(backend)),
        Err(BackendError::NoAdapter { reason, .. }) if choice == BackendChoice::Auto => {
            eprintln!(
                "notice: no GPU adapter found ({reason}); running on the CPU interpreter of naga IR, which is slow \
                 (for a Vulkan device on the CPU: apt-get install mesa-vulkan-drivers)"
            );
            Ok(Box::new(CpuBackend::new(CpuOptions::default())?))
        }
        Err(other) => Err(other),
    }
}
