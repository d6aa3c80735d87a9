//! `cargo xtask check`'s default run under `cargo test`: every registry kernel on every
//! backend, outputs identical to the reference. Under `STRATA_REQUIRE_GPU=1` every
//! Vulkan backend must be available, and under `STRATA_REQUIRE_BROWSER=1` the `webgpu`
//! path (Chromium's WebGPU).

use strata_backends::gpu_required;
use strata_check::{CellResult, CheckConfig, backend_slots, kernel_checks, run_check};

#[test]
fn every_kernel_is_identical_on_every_backend() {
    let report = run_check(CheckConfig { full: false });
    eprintln!("{}", report.render());
    let failures = report.failures();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    for slot in backend_slots() {
        for check in kernel_checks() {
            let cell = report.cell(check.kernel(), slot.name);
            if let Some(CellResult::Unavailable(why)) = cell {
                let missing_backend = !why.contains("needs subgroup operations");
                assert!(
                    !(gpu_required() && slot.needs_vulkan && missing_backend),
                    "{} is unavailable although STRATA_REQUIRE_GPU is set: {why}",
                    slot.name
                );
            }
        }
    }
    // Tint's column is there where Chromium must be: from both browsers the slot is
    // shared out over, no cell is unavailable but for a limit or feature the device lacks.
    if strata_backends::webgpu_backend::browser_required() {
        let cell = report.cell(strata_kernels::KernelId::BlockHistogram, "webgpu");
        assert!(matches!(cell, Some(CellResult::Identical { .. })), "webgpu: {cell:?}");
        for check in kernel_checks() {
            if let Some(CellResult::Unavailable(why)) = report.cell(check.kernel(), "webgpu") {
                assert!(why.contains("needs"), "webgpu is unavailable for {:?}: {why}", check.kernel());
            }
        }
    }
    // The portable kernel runs everywhere a Vulkan device exists.
    if gpu_required() {
        for slot in backend_slots().iter().filter(|s| s.needs_vulkan) {
            let cell = report.cell(strata_kernels::KernelId::BlockHistogram, slot.name);
            assert!(matches!(cell, Some(CellResult::Identical { .. })), "{}: {cell:?}", slot.name);
        }
    }
}
