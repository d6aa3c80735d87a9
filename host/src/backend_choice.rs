//! Picking a backend for the command line: the GPU if there is one.

use strata_backends::ash_backend::{AshBackend, AshOptions};
use strata_backends::wgpu_backend::{WgpuApi, WgpuBackend, WgpuOptions};
use strata_backends::{Backend, BackendError};

/// Backends the command line can be asked for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum BackendChoice {
    /// The best available: wgpu on Vulkan.
    Auto,
    /// wgpu on Vulkan.
    Wgpu,
    /// wgpu on OpenGL (no subgroups).
    WgpuGl,
    /// Raw Vulkan through ash, on naga's SPIR-V.
    Ash,
}

/// Opens the requested backend.
///
/// The CPU interpreter of naga IR is the fallback without a GPU; until it exists
/// (issue 4) a machine without any Vulkan device gets the error, which names the fix
/// (install Mesa's lavapipe: `apt-get install mesa-vulkan-drivers`).
pub fn open_backend(choice: BackendChoice) -> Result<Box<dyn Backend>, BackendError> {
    let api = match choice {
        BackendChoice::Auto | BackendChoice::Wgpu => WgpuApi::Vulkan,
        BackendChoice::WgpuGl => WgpuApi::Gl,
        BackendChoice::Ash => return Ok(Box::new(AshBackend::new(AshOptions::default())?)),
    };
    match WgpuBackend::new(WgpuOptions { api, ..Default::default() }) {
        Ok(backend) => Ok(Box::new(backend)),
        Err(BackendError::NoAdapter { backend, reason }) => Err(BackendError::NoAdapter {
            backend,
            reason: format!(
                "{reason}; no GPU or Vulkan driver found (on Debian: apt-get install mesa-vulkan-drivers \
                 for lavapipe); the CPU interpreter fallback is not implemented yet"
            ),
        }),
        Err(other) => Err(other),
    }
}
