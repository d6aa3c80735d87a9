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
mod path;
pub mod replay;
mod report;
mod restir;
pub mod run_images;
pub mod run_kernel;
mod selection;
mod svgf;
pub mod texture_corpus;
mod trace;

pub use backends::{BackendSlot, backend_slots};
pub use compare::{Agreement, Compare, Mismatch, Output, compare_outputs};
pub use report::{CellResult, CheckReport};

use strata::histogram_pass::PassError;
use strata_backends::Backend;
use strata_kernels::KernelId;

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

/// How one registry kernel is exercised and judged.
pub trait KernelCheck {
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
    let mut references = ReferenceCache::default();
    let mut report = CheckReport::new(
        checks.iter().map(|c| c.kernel()).collect(),
        backend_slots().iter().map(|s| s.name.to_string()).collect(),
    );
    for slot in backend_slots() {
        let mut backend = match (slot.open)() {
            Ok(backend) => backend,
            Err(error) => {
                for check in &checks {
                    report.set(check.kernel(), slot.name, CellResult::Unavailable(error.to_string()));
                }
                continue;
            }
        };
        report.set_device(slot.name, backend.info().summary());
        for check in &checks {
            if let Some(slots) = check.quick_slots().filter(|_| !config.full)
                && !slots.contains(&slot.name)
            {
                let why = format!("the quick check runs it on {} only", slots.join(", "));
                report.set(check.kernel(), slot.name, CellResult::FullRunOnly(why));
                continue;
            }
            let result = run_one(check.as_ref(), backend.as_mut(), config, &mut references);
            report.set(check.kernel(), slot.name, result);
        }
    }
    report
}

/// Reference outputs by kernel and case label.
type ReferenceCache = std::collections::HashMap<(KernelId, String), Vec<Output>>;

fn run_one(
    check: &dyn KernelCheck,
    backend: &mut dyn Backend,
    config: CheckConfig,
    references: &mut ReferenceCache,
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
        let reference = references.entry((check.kernel(), case.label.clone())).or_insert_with(|| check.reference(case));
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
