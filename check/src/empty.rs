//! Check of the empty kernel: it must leave its buffer exactly as it was.

use super::{Case, CheckConfig, Compare, KernelCheck, Output};
use strata_backends::backend::{download, upload};
use strata_backends::{Backend, Bind};
use strata_kernels::{KernelId, Registry};
use strata_render::histogram_pass::PassError;

/// Checks [`KernelId::Empty`].
pub struct EmptyCheck;

fn contents(case: &Case) -> Vec<u32> {
    (0..case.width).map(|i| i.wrapping_mul(0x9e37_79b9) ^ case.seed as u32).collect()
}

impl KernelCheck for EmptyCheck {
    fn kernel(&self) -> KernelId {
        KernelId::Empty
    }

    fn cases(&self, config: CheckConfig) -> Vec<Case> {
        let seeds = if config.full { 20 } else { 3 };
        (0..seeds)
            .map(|seed| Case {
                label: format!("{} words, {} workgroups", 64 << (seed % 4), 1 + seed % 5),
                width: 64 << (seed % 4),
                height: 1 + (seed % 5) as u32,
                block_size: 0,
                seed,
                family: 0,
            })
            .collect()
    }

    fn run(&self, backend: &mut dyn Backend, case: &Case) -> Result<Vec<Output>, PassError> {
        let kernel = Registry::shared()?.get(KernelId::Empty);
        let sink = upload(backend, "sink", &contents(case))?;
        let result = backend.dispatch(kernel, &[Bind::new(0, sink)], [case.height, 1, 1]);
        let words = result.and_then(|()| download::<u32>(backend, sink));
        backend.destroy_buffer(sink)?;
        Ok(vec![Output { name: "sink", words: words?, compare: Compare::Exact }])
    }

    fn reference(&self, case: &Case) -> Vec<Output> {
        vec![Output { name: "sink", words: contents(case), compare: Compare::Exact }]
    }
}
