//! Which buffer goes to which binding of which kernel, written once for both API
//! flavours: the engine's buffers (generic over how an API names a buffer range) and the
//! pass's own buffers (generic over an API's buffer type).

use crate::contract::BufferRole;
use crate::wgsl::WgslModule;

/// The engine's buffers of the contract ([`crate::contract`]); `S` is the API's buffer
/// range ([`crate::WgpuBufferSlice`], [`crate::AshBufferSlice`]).
#[derive(Clone, Copy, Debug)]
pub struct EngineBuffers<S> {
    /// One `Candidate` per pixel, written by the engine before the selection.
    pub candidates: S,
    /// One payload per pixel; `None`: a pixel's payload is its index.
    pub payloads: Option<S>,
    /// One `SelectedCandidates` per pixel, written by the pass.
    pub selections: S,
    /// The resampling buffers, if the engine resamples with the pass.
    pub resample: Option<ResampleBuffers<S>>,
}

/// The engine's buffers of the resampling pass.
#[derive(Clone, Copy, Debug)]
pub struct ResampleBuffers<S> {
    /// One `ResampleInput` per pixel, written by the engine after the selection.
    pub inputs: S,
    /// One `ResampleOutput` per pixel, written by the pass.
    pub outputs: S,
}

/// The pass's own buffers; `B` is the API's buffer type.
pub(crate) struct OwnBuffers<B> {
    pub histogram_params: B,
    pub selection_params: B,
    pub sorted_pixels: B,
    pub spans: B,
    pub block_stats: B,
    /// The blue-noise tables, packed (`BlueNoiseTables::packed`).
    pub blue_noise: B,
    /// Bound as `payloads` when the engine has none (never read then).
    pub unused_payloads: B,
}

impl<B> OwnBuffers<B> {
    /// Every buffer, for destruction.
    pub fn all(&self) -> [&B; 7] {
        [
            &self.histogram_params,
            &self.selection_params,
            &self.sorted_pixels,
            &self.spans,
            &self.block_stats,
            &self.blue_noise,
            &self.unused_payloads,
        ]
    }
}

/// One binding's resource.
pub(crate) enum Resource<'a, B, S> {
    /// A buffer of the pass, bound whole.
    Own(&'a B),
    /// A range of an engine buffer.
    Engine(S),
}

impl<B, S: Copy> Clone for Resource<'_, B, S> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<B, S: Copy> Copy for Resource<'_, B, S> {}

/// Resources of the three kernels' bindings, each under its WGSL variable's name (the
/// binding numbers come from the registry, [`BindingPlan::numbered`]).
pub(crate) struct BindingPlan<'a, B, S> {
    pub histogram: Vec<(&'static str, Resource<'a, B, S>)>,
    pub select: Vec<(&'static str, Resource<'a, B, S>)>,
    pub resample: Option<Vec<(&'static str, Resource<'a, B, S>)>>,
}

impl<'a, B, S: Copy> BindingPlan<'a, B, S> {
    /// `resources` with the binding number `module` declares for each name, in binding
    /// order; every binding of the module must be given.
    pub fn numbered(
        module: &WgslModule,
        resources: &[(&'static str, Resource<'a, B, S>)],
    ) -> Vec<(u32, Resource<'a, B, S>)> {
        let mut numbered: Vec<(u32, Resource<'a, B, S>)> = resources
            .iter()
            .map(|(name, resource)| {
                let binding = module.bindings.iter().find(|b| b.name == *name).unwrap_or_else(|| {
                    panic!("{}: no binding named `{name}` (the plan and the WGSL disagree)", module.entry_point)
                });
                (binding.binding, *resource)
            })
            .collect();
        numbered.sort_by_key(|(binding, _)| *binding);
        assert_eq!(
            numbered.len(),
            module.bindings.len(),
            "{}: the plan must bind every binding of the module",
            module.entry_point
        );
        numbered
    }
}

impl<S: Copy> EngineBuffers<S> {
    /// The buffers given, with their roles (for the contract's checks).
    pub(crate) fn roles(&self) -> Vec<(BufferRole, S)> {
        let mut roles = vec![(BufferRole::Candidates, self.candidates), (BufferRole::Selections, self.selections)];
        if let Some(payloads) = self.payloads {
            roles.push((BufferRole::Payloads, payloads));
        }
        if let Some(resample) = self.resample {
            roles.extend([(BufferRole::ResampleInputs, resample.inputs), (BufferRole::Resampled, resample.outputs)]);
        }
        roles
    }

    /// What each binding of `block_histogram`, `strata_select` and `strata_resample`
    /// gets, by the WGSL variable's name (`kernels/wgsl/strata/histogram.wgsl`,
    /// `kernels/wgsl/embed/entry_*.wgsl`).
    pub(crate) fn plan<'a, B>(&self, own: &'a OwnBuffers<B>) -> BindingPlan<'a, B, S> {
        use Resource::{Engine, Own};
        let payloads = self.payloads.map_or(Own(&own.unused_payloads), Engine);
        BindingPlan {
            histogram: vec![
                ("params", Own(&own.histogram_params)),
                ("candidates", Engine(self.candidates)),
                ("sorted_pixels", Own(&own.sorted_pixels)),
                ("spans", Own(&own.spans)),
                ("block_stats", Own(&own.block_stats)),
            ],
            select: vec![
                ("params", Own(&own.selection_params)),
                ("candidates", Engine(self.candidates)),
                ("payloads", payloads),
                ("sorted_pixels", Own(&own.sorted_pixels)),
                ("spans", Own(&own.spans)),
                ("blue_noise", Own(&own.blue_noise)),
                ("selections", Engine(self.selections)),
            ],
            resample: self.resample.map(|resample| {
                vec![
                    ("params", Own(&own.selection_params)),
                    ("selections", Engine(self.selections)),
                    ("resample_inputs", Engine(resample.inputs)),
                    ("resampled", Engine(resample.outputs)),
                ]
            }),
        }
    }
}
