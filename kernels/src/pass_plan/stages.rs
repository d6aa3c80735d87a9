//! The pass's three stages and what each binding of their kernels holds, by the WGSL
//! variable's name; the binding numbers come from the registry ([`numbered`]).

use super::buffers::PassBuffer;
use crate::{Kernel, KernelId};

/// The pass's three stages, in the order a frame runs them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// The block histogram (any of its three kernels).
    Histogram,
    /// `strata_select`.
    Select,
    /// `strata_resample` (only if the engine resamples with the pass).
    Resample,
}

impl Stage {
    /// Every stage, in order.
    pub const ALL: [Stage; 3] = [Stage::Histogram, Stage::Select, Stage::Resample];

    /// The stage a kernel runs; `None` for kernels outside the pass (strata's renderer
    /// runs the histogram stage and its own ReSTIR kernels).
    pub fn of(kernel: KernelId) -> Option<Stage> {
        match kernel {
            KernelId::BlockHistogram | KernelId::BlockHistogramSubgroup | KernelId::BlockHistogramRank => {
                Some(Stage::Histogram)
            }
            KernelId::StrataSelect => Some(Stage::Select),
            KernelId::StrataResample => Some(Stage::Resample),
            _ => None,
        }
    }

    /// What each binding of the stage's kernels holds, by the WGSL variable's name
    /// (`kernels/wgsl/strata/histogram.wgsl`, `kernels/wgsl/embed/entry_*.wgsl`).
    pub fn bindings(self) -> &'static [(&'static str, PassBuffer)] {
        match self {
            Stage::Histogram => &[
                ("params", PassBuffer::HistogramParams),
                ("candidates", PassBuffer::Candidates),
                ("sorted_pixels", PassBuffer::SortedPixels),
                ("spans", PassBuffer::Spans),
                ("block_stats", PassBuffer::BlockStats),
            ],
            Stage::Select => &[
                ("params", PassBuffer::SelectionParams),
                ("candidates", PassBuffer::Candidates),
                ("payloads", PassBuffer::Payloads),
                ("sorted_pixels", PassBuffer::SortedPixels),
                ("spans", PassBuffer::Spans),
                ("blue_noise", PassBuffer::BlueNoise),
                ("selections", PassBuffer::Selections),
            ],
            Stage::Resample => &[
                ("params", PassBuffer::SelectionParams),
                ("selections", PassBuffer::Selections),
                ("resample_inputs", PassBuffer::ResampleInputs),
                ("resampled", PassBuffer::Resampled),
            ],
        }
    }

    /// The stage's bindings with each buffer's resource (`resource(buffer)`), numbered
    /// by `kernel`'s declarations, in binding order; `None` when `resource` has none for
    /// one of them.
    pub fn bind<T: Copy>(
        self,
        kernel: &Kernel,
        mut resource: impl FnMut(PassBuffer) -> Option<T>,
    ) -> Option<Vec<(u32, T)>> {
        let resources: Option<Vec<(&'static str, T)>> =
            self.bindings().iter().map(|&(name, buffer)| Some((name, resource(buffer)?))).collect();
        Some(numbered(kernel, &resources?))
    }
}

/// `resources`, each under its WGSL variable's name, with the binding number `kernel`
/// declares for the name, in binding order.
///
/// # Panics
/// When a name is not a binding of `kernel` or a binding is left out: the plan and the
/// WGSL disagree, a bug of this crate (the tests bind every stage of every kernel).
pub fn numbered<T: Copy>(kernel: &Kernel, resources: &[(&'static str, T)]) -> Vec<(u32, T)> {
    let mut numbered: Vec<(u32, T)> = resources
        .iter()
        .map(|(name, resource)| {
            let binding = kernel.bindings.iter().find(|b| b.name == *name).unwrap_or_else(|| {
                panic!("{}: no binding named `{name}` (the pass plan and the WGSL disagree)", kernel.name())
            });
            (binding.binding, *resource)
        })
        .collect();
    numbered.sort_by_key(|(binding, _)| *binding);
    assert_eq!(
        numbered.len(),
        kernel.bindings.len(),
        "{}: the plan must bind every binding of the kernel",
        kernel.name()
    );
    numbered
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Registry;
    use crate::pass_plan::{SizeRule, Writer};

    const PASS_KERNELS: [KernelId; 5] = [
        KernelId::BlockHistogram,
        KernelId::BlockHistogramSubgroup,
        KernelId::BlockHistogramRank,
        KernelId::StrataSelect,
        KernelId::StrataResample,
    ];

    /// Every binding of every kernel of the pass is in its stage's list, and every listed
    /// buffer's record stride is the one the WGSL declares.
    #[test]
    fn every_binding_of_every_kernel_has_one_buffer_of_its_stride() {
        let registry = Registry::shared().unwrap();
        for id in PASS_KERNELS {
            let kernel = registry.get(id);
            let listed = Stage::of(id).unwrap().bindings();
            assert_eq!(listed.len(), kernel.bindings.len(), "{id:?}");
            for binding in &kernel.bindings {
                let (_, buffer) = listed.iter().find(|(name, _)| *name == binding.name).unwrap();
                match buffer.size_rule() {
                    SizeRule::PerPixel(bytes) | SizeRule::PerBlock(bytes) => {
                        assert_eq!(u64::from(binding.element.stride), bytes, "{id:?} `{}`", binding.name)
                    }
                    SizeRule::Fixed(bytes) => assert!(bytes >= binding.min_size(), "{id:?} `{}`", binding.name),
                }
                // Only the pass's kernels write, and only buffers the pass writes.
                assert!(!binding.is_writable() || buffer.writer() == Writer::Pass, "{id:?} `{}`", binding.name);
            }
        }
    }

    /// Binding by name gives each buffer the number the WGSL declares, in order.
    #[test]
    fn bind_numbers_each_buffer_by_its_wgsl_name() {
        let kernel = Registry::shared().unwrap().get(KernelId::StrataSelect);
        let bound = Stage::Select.bind(kernel, Some).unwrap();
        for (binding, buffer) in &bound {
            let name = Stage::Select.bindings().iter().find(|(_, b)| b == buffer).unwrap().0;
            let declared = kernel.bindings.iter().find(|b| b.name == name).unwrap();
            assert_eq!(declared.binding, *binding, "{name}");
        }
        assert!(bound.windows(2).all(|w| w[0].0 < w[1].0));
        assert!(Stage::Resample.bind(kernel, |_| None::<u32>).is_none());
    }

    #[test]
    #[should_panic(expected = "no binding named `payloads`")]
    fn binding_a_stage_to_another_stages_kernel_is_refused() {
        let kernel = Registry::shared().unwrap().get(KernelId::BlockHistogram);
        Stage::Select.bind(kernel, Some);
    }
}
