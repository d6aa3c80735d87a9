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
