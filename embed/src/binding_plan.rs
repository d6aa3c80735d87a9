//! Which buffer goes to which binding of which kernel, written once for both API
//! flavours: the engine's buffers (generic over how an API names a buffer range) and the
//! pass's own buffers (generic over an API's buffer type).

use crate::contract::BufferRole;

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
    /// Blue-noise sobol, scrambling, ranking.
    pub tables: [B; 3],
    /// Bound as `payloads` when the engine has none (never read then).
    pub unused_payloads: B,
}

impl<B> OwnBuffers<B> {
    /// Every buffer, for destruction.
    pub fn all(&self) -> [&B; 9] {
        [
            &self.histogram_params,
            &self.selection_params,
            &self.sorted_pixels,
            &self.spans,
            &self.block_stats,
            &self.tables[0],
            &self.tables[1],
            &self.tables[2],
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

/// Resources of the three kernels' bindings, in binding order.
pub(crate) struct BindingPlan<'a, B, S> {
    pub histogram: Vec<Resource<'a, B, S>>,
    pub select: Vec<Resource<'a, B, S>>,
    pub resample: Option<Vec<Resource<'a, B, S>>>,
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
    /// gets (their WGSL declarations: `kernels/wgsl/embed/entry_*.wgsl`).
    pub(crate) fn plan<'a, B>(&self, own: &'a OwnBuffers<B>) -> BindingPlan<'a, B, S> {
        use Resource::{Engine, Own};
        let payloads = self.payloads.map_or(Own(&own.unused_payloads), Engine);
        BindingPlan {
            histogram: vec![
                Own(&own.histogram_params),
                Engine(self.candidates),
                Own(&own.sorted_pixels),
                Own(&own.spans),
                Own(&own.block_stats),
            ],
            select: vec![
                Own(&own.selection_params),
                Engine(self.candidates),
                payloads,
                Own(&own.sorted_pixels),
                Own(&own.spans),
                Own(&own.tables[0]),
                Own(&own.tables[1]),
                Own(&own.tables[2]),
                Engine(self.selections),
            ],
            resample: self.resample.map(|resample| {
                vec![
                    Own(&own.selection_params),
                    Engine(self.selections),
                    Engine(resample.inputs),
                    Engine(resample.outputs),
                ]
            }),
        }
    }
}
