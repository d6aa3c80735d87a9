//! The cross-backend identity check (`cargo xtask check`, and a test under `cargo test`):
//! every registry kernel on every available backend with generated inputs, compared
//! with the kernel's Rust reference. Integer and ordering outputs must be bit-exact;
//! float outputs must stay within the ULP bound the registry declares for the kernel.
//! Also [`run_kernel`]: any WGSL compute shader on chosen backends (`cargo xtask run`),
//! judged by [`agreement`] against a reference backend under a declared tolerance.
//!
//! And [`fuzz`]: the fuzz harness of the scene, image and CSV loaders (`cargo xtask
//! fuzz`, and a short fixed-seed run under `cargo test`).
//!
//! Tooling, not product: the renderer (`strata`) and the embeddable pass know nothing of
//! it; `xtask` and the tests use it.

pub mod agreement;
mod backends;
mod camera;
mod compare;
pub mod corpus_rng;
mod empty;
pub mod fuzz;
mod histogram;
pub mod overrides;
pub mod parallel;
mod path;
pub mod replay;
mod report;
mod restir;
pub mod run_data;
pub mod run_images;
pub mod run_kernel;
mod selection;
mod svgf;
pub mod texture_corpus;
mod trace;

pub use backends::{BackendSlot, backend_slots};
pub use compare::{Agreement, Compare, Mismatch, Output, compare_outputs};
pub use report::{CellResult, CheckReport};

use strata_backends::Backend;
use strata_kernels::KernelId;
use strata_render::histogram_pass::PassError;

/// How much to check.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CheckConfig {
    /// `--full`: at least 20 seeds at several sizes per kernel; otherwise 3 seeds at small
    /// sizes (what `cargo test` runs).
    pub full: bool,
}

/// One generated input of a kernel check.
#[derive(Clone, Debug, PartialEq)]
pub struct Case {
    /// Human-readable description, used in mismatch reports.
    pub label: String,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Block size, for block kernels.
    pub block_size: u32,
    /// Seed of the generated input.
    pub seed: u64,
    /// Which input family (kernel-specific: e.g. mostly valid, mostly invalid, all empty).
    pub family: u32,
}

/// How one registry kernel is exercised and judged (from the worker of each backend
/// slot: [`run_checks_reporting`]).
pub trait KernelCheck: Sync {
    /// The kernel.
    fn kernel(&self) -> KernelId;
    /// Inputs drawn from the kernel's domain, awkward values included.
    fn cases(&self, config: CheckConfig) -> Vec<Case>;
    /// Runs the kernel on `backend`.
    fn run(&self, backend: &mut dyn Backend, case: &Case) -> Result<Vec<Output>, PassError>;
    /// What the outputs must be.
    fn reference(&self, case: &Case) -> Vec<Output>;
    /// The backend slots the quick check (not `--full`) runs this kernel on; `None`: all.
    /// Whole-renderer kernels name a few: llvmpipe compiles each of them for minutes on a
    /// machine without a warm shader cache, once per slot whose shader code differs.
    fn quick_slots(&self) -> Option<&'static [&'static str]> {
        None
    }
}

/// Every kernel check: one line per registry kernel.
pub fn kernel_checks() -> Vec<Box<dyn KernelCheck>> {
    vec![
        Box::new(histogram::HistogramCheck(KernelId::BlockHistogram)),
        Box::new(histogram::HistogramCheck(KernelId::BlockHistogramSubgroup)),
        Box::new(histogram::HistogramCheck(KernelId::BlockHistogramRank)),
        Box::new(empty::EmptyCheck),
        Box::new(trace::TraceCheck),
        Box::new(camera::CameraCheck),
        Box::new(path::PathTraceCheck),
        Box::new(restir::RestirCheck(KernelId::RestirCandidates)),
        Box::new(restir::RestirCheck(KernelId::RestirSelect)),
        Box::new(restir::RestirCheck(KernelId::RestirTemporalKeys)),
        Box::new(restir::RestirCheck(KernelId::RestirTemporal)),
        Box::new(restir::RestirCheck(KernelId::RestirReservoirKeys)),
        Box::new(restir::RestirCheck(KernelId::RestirSpatial)),
        Box::new(restir::RestirCheck(KernelId::RestirShade)),
        Box::new(restir::RestirCheck(KernelId::RestirGuide)),
        Box::new(svgf::SvgfCheck(KernelId::SvgfTemporal)),
        Box::new(svgf::SvgfCheck(KernelId::SvgfVariance)),
        Box::new(svgf::SvgfCheck(KernelId::SvgfAtrous)),
        Box::new(svgf::SvgfCheck(KernelId::SvgfModulate)),
        Box::new(selection::SelectionCheck(KernelId::StrataSelect)),
        Box::new(selection::SelectionCheck(KernelId::StrataResample)),
    ]
}

/// Runs every kernel check on every backend slot.
pub fn run_check(config: CheckConfig) -> CheckReport {
    run_checks(config, kernel_checks())
}

/// Runs `checks` on every backend slot. Each case's reference is computed once and
/// shared by the slots (for the path tracer it is an interpreter run).
pub fn run_checks(config: CheckConfig, checks: Vec<Box<dyn KernelCheck>>) -> CheckReport {
    run_checks_reporting(config, checks, &|_| {})
}

/// One finished cell of a check run (a kernel on a backend slot), for a progress line.
#[derive(Clone, Copy, Debug)]
pub struct Progress<'a> {
    /// The backend slot.
    pub slot: &'a str,
    /// The kernel's name.
    pub kernel: &'a str,
    /// Cells finished so far, this one included.
    pub done: usize,
    /// Cells in all.
    pub total: usize,
    /// Time since the run began.
    pub elapsed: std::time::Duration,
}

impl Progress<'_> {
    /// The time left if the cells still to run take as long on average as those done
    /// (they do not: a slot's first kernels compile the longest; an estimate).
    pub fn remaining(&self) -> std::time::Duration {
        let left = self.total.saturating_sub(self.done) as f64;
        self.elapsed.mul_f64(left / self.done.max(1) as f64)
    }
}

/// [`run_checks`], the backend slots in parallel, one worker per core, each slot on its
/// own device: most of a first run is a CPU driver (lavapipe) compiling every kernel
/// once per slot, one pipeline per core at a time (Vulkan lets pipelines be created
/// from several threads; each slot's device is its own anyway). A slot may be shared out
/// over several devices (`slot_parts`: `webgpu`, two browsers). `progress` is called
/// after every cell, from the worker that ran it.
pub fn run_checks_reporting(
    config: CheckConfig,
    checks: Vec<Box<dyn KernelCheck>>,
    progress: &(dyn Fn(&Progress) + Sync),
) -> CheckReport {
    run_checks_reporting_on(config, checks, backend_slots(), progress)
}

/// [`run_checks_reporting`] on `slots` only (`run_kernel::named_slots`): the report has
/// their columns alone.
pub fn run_checks_reporting_on(
    config: CheckConfig,
    checks: Vec<Box<dyn KernelCheck>>,
    slots: Vec<BackendSlot>,
    progress: &(dyn Fn(&Progress) + Sync),
) -> CheckReport {
    let references = ReferenceCache::default();
    let total = checks.len() * slots.len();
    let done = std::sync::atomic::AtomicUsize::new(0);
    let started = std::time::Instant::now();
    let names = strata_kernels::Registry::shared().ok();
    let report_cell = |slot: &str, kernel: KernelId| {
        let done = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
        let kernel = names.map_or("", |registry| registry.get(kernel).name());
        progress(&Progress { slot, kernel, done, total, elapsed: started.elapsed() });
    };
    // Each job is a part of a slot (every `parts`-th check from `part`, on a device of its
    // own); the jobs that take the longest first, so that no long one starts last.
    let mut order: Vec<(usize, usize, usize)> = (0..slots.len())
        .flat_map(|index| {
            let parts = slot_parts(slots[index].name);
            (0..parts).map(move |part| (index, part, parts))
        })
        .collect();
    order.sort_by_key(|&(index, _, parts)| std::cmp::Reverse(slot_weight(slots[index].name) / parts as u32));
    let results = parallel::map(&order, |&(index, part, parts)| {
        let slot = &slots[index];
        let mine = || checks.iter().skip(part).step_by(parts);
        let mut cells = Vec::new();
        let mut backend = match (slot.open)() {
            Ok(backend) => backend,
            Err(error) => {
                for check in mine() {
                    cells.push((check.kernel(), CellResult::Unavailable(error.to_string())));
                    report_cell(slot.name, check.kernel());
                }
                return (None, cells);
            }
        };
        let device = backend.info().summary();
        for check in mine() {
            let result = if let Some(slots) = check.quick_slots().filter(|_| !config.full)
                && !slots.contains(&slot.name)
            {
                CellResult::FullRunOnly(format!("the quick check runs it on {} only", slots.join(", ")))
            } else {
                run_one(check.as_ref(), backend.as_mut(), config, &references)
            };
            cells.push((check.kernel(), result));
            report_cell(slot.name, check.kernel());
        }
        (Some(device), cells)
    });
    let mut report = CheckReport::new(
        checks.iter().map(|c| c.kernel()).collect(),
        slots.iter().map(|s| s.name.to_string()).collect(),
    );
    for (&(index, _, _), (device, cells)) in order.iter().zip(results) {
        let name = slots[index].name;
        if let Some(device) = device {
            report.set_device(name, device);
        }
        for (kernel, result) in cells {
            report.set(kernel, name, result);
        }
    }
    report
}

/// How long a slot's run takes, roughly (its kernels' compile time on lavapipe; for
/// `webgpu`, the ReSTIR passes compiled by Tint and SwiftShader and replayed through the
/// loopback bridge): the order the workers take the slots in.
fn slot_weight(name: &str) -> u32 {
    match name {
        "webgpu" => 16,
        "ash-slang" => 6,
        "wgpu-gl" => 5,
        "ash-hlsl" | "ash-glsl" => 4,
        "wgpu-vulkan" | "ash" => 3,
        _ => 1,
    }
}

/// How many devices a slot's checks are shared out over. `webgpu` is the quick run's
/// critical path (2026-11-29, 2-core VM: 51 s of one core, while the seven other slots
/// were done on the other core after 21 s), and its browser compiles and runs on one
/// core at a time: two browsers, each with every other kernel, run it on both.
fn slot_parts(name: &str) -> usize {
    if name == "webgpu" { 2 } else { 1 }
}

/// Reference outputs by kernel and case label, shared by the workers: each computed
/// once, by the first worker that needs it (the others wait for it).
type ReferenceCache =
    std::sync::Mutex<std::collections::HashMap<(KernelId, String), std::sync::Arc<std::sync::OnceLock<Vec<Output>>>>>;

fn run_one(
    check: &dyn KernelCheck,
    backend: &mut dyn Backend,
    config: CheckConfig,
    references: &ReferenceCache,
) -> CellResult {
    let kernel = match strata_kernels::Registry::shared() {
        Ok(registry) => registry.get(check.kernel()),
        Err(error) => return CellResult::Failed(error.to_string()),
    };
    if let Err(error) = backend.check_kernel(kernel) {
        return CellResult::Unavailable(error.to_string());
    }
    let mut agreement = Agreement::default();
    let cases = check.cases(config);
    for case in &cases {
        let outputs = match check.run(backend, case) {
            Ok(outputs) => outputs,
            Err(error) => return CellResult::Failed(format!("{}: {error}", case.label)),
        };
        let cell = references
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .entry((check.kernel(), case.label.clone()))
            .or_default()
            .clone();
        let reference = cell.get_or_init(|| check.reference(case));
        match compare_outputs(&outputs, reference) {
            Ok(case_agreement) => agreement = agreement.merge(case_agreement),
            Err(mismatch) => return CellResult::Failed(format!("{}: {mismatch}", case.label)),
        }
    }
    if agreement.max_ulp == 0 && agreement.outside == 0 {
        CellResult::Identical { cases: cases.len() }
    } else {
        CellResult::WithinUlp {
            cases: cases.len(),
            max_ulp: agreement.max_ulp,
            outside_share: agreement.outside_share(),
        }
    }
}
