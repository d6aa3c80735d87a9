//! What the shader-corpus tests share (`corpus.rs` for buffers, `textures.rs` for
//! textures): the backends that can open here, one case at a time, the judgement's
//! failures as lines, and the negative control that a corrupted output is caught.

use strata_backends::webgpu_backend::{BROWSER_REQUIRED_VARIABLE, browser_required};
use strata_backends::{BackendError, GPU_REQUIRED_VARIABLE, gpu_required};
use strata_check::BackendSlot;
use strata_check::agreement::{Judgement, Tolerance, judge};
use strata_check::run_kernel::{BackendRun, named_slots};
use strata_kernels::WordKind;

/// One case at a time: six backends' devices at once per test thread crashed the
/// process (SIGSEGV inside the drivers with eight threads), and each case already keeps
/// both cores busy.
pub static ONE_CASE_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// The slots that can open here; a slot without a device is skipped (with a note naming
/// `what`), or fails the test under `STRATA_REQUIRE_GPU=1` when it needs Vulkan; the
/// `webgpu` slot without Chromium is skipped too, or fails under
/// `STRATA_REQUIRE_BROWSER=1`. Each slot is opened once per test process to find out
/// (a browser start for `webgpu`), not once per test.
pub fn available_slots(what: &str) -> Vec<BackendSlot> {
    /// Per slot: opened, or whether it found no adapter and the error.
    type Probed = Vec<(&'static str, Result<(), (bool, String)>)>;
    static PROBED: std::sync::OnceLock<Probed> = std::sync::OnceLock::new();
    let _turn = ONE_CASE_AT_A_TIME.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    let probed = PROBED.get_or_init(|| {
        named_slots(&["all".to_string()])
            .unwrap()
            .iter()
            .map(|slot| {
                let opened = (slot.open)()
                    .map(drop)
                    .map_err(|error| (matches!(error, BackendError::NoAdapter { .. }), error.to_string()));
                (slot.name, opened)
            })
            .collect()
    });
    let mut slots = Vec::new();
    for slot in named_slots(&["all".to_string()]).unwrap() {
        let opened = probed.iter().find(|(name, _)| *name == slot.name).map(|(_, opened)| opened.clone());
        match opened.expect("every slot probed") {
            Ok(()) => slots.push(slot),
            Err((true, error)) if !(gpu_required() && slot.needs_vulkan) => {
                eprintln!("SKIPPED {} in {what}: {error} (see {GPU_REQUIRED_VARIABLE})", slot.name);
            }
            Err((_, error)) if slot.name == "webgpu" && !browser_required() => {
                eprintln!("SKIPPED {} in {what}: {error} (see {BROWSER_REQUIRED_VARIABLE})", slot.name);
            }
            Err((_, error)) => panic!("{}: {error}", slot.name),
        }
    }
    slots
}

/// Every backend that failed and every output beyond its bound, one line each.
pub fn failures(judgement: &Judgement) -> Vec<String> {
    judgement
        .failed
        .iter()
        .map(|(backend, why)| format!("{backend} failed: {why}"))
        .chain(
            judgement
                .buffers
                .iter()
                .filter(|b| !b.passes())
                .map(|b| format!("{} `{}`: {}", b.backend, b.name, b.describe())),
        )
        .collect()
}

/// Negative control: corrupts the output of the last backend that ran (an integer word by one bit, an
/// f16 pair by four steps, a float word far past any bound) and asserts that the same
/// judgement fails.
pub fn assert_corruption_caught(runs: &[BackendRun], tolerance: &Tolerance, case: &str) {
    // The last backend that ran (one may have refused the kernel).
    let Some(last) = runs.iter().rposition(|r| r.backend != "cpu" && r.outputs.is_ok()) else {
        return;
    };
    let outputs = runs[last].outputs.as_ref().expect("found as Ok");
    for kind in [WordKind::Integer, WordKind::Float, WordKind::HalfPair, WordKind::Unorm8x4] {
        let Some((buffer, index)) = outputs
            .iter()
            .enumerate()
            .find_map(|(b, o)| (0..o.bytes.len() / 4).find(|&i| o.kinds.of(i) == kind).map(|i| (b, i)))
        else {
            continue;
        };
        let mut corrupted = runs.to_vec();
        let output = &mut corrupted[last].outputs.as_mut().unwrap()[buffer];
        let name = output.name.clone();
        let word = &mut output.bytes[4 * index..4 * index + 4];
        let value = u32::from_le_bytes(word.try_into().unwrap());
        let bad = match kind {
            WordKind::Integer => value ^ 1,
            // Four f16 steps: beyond the one a device's rounding may take, even from a
            // word that already differs by one.
            WordKind::HalfPair => value ^ 4,
            // 128 steps of 1/255: past any bound a case declares.
            WordKind::Unorm8x4 => value ^ 0x80,
            _ => value ^ 0xc000_0000,
        };
        word.copy_from_slice(&bad.to_le_bytes());
        let verdict = judge(&corrupted, Some("cpu"), tolerance).unwrap();
        assert!(!verdict.passes(), "{case}: a corrupted {kind:?} word of `{name}` was not caught");
    }
}
