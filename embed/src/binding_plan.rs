//! The engine's and the pass's own buffers of the wgpu and ash flavours, bound by the
//! one plan of the pass (`strata_kernels::pass_plan`: which buffer goes to which
//! binding, by the WGSL variable's name, and how large each is), which the export
//! package for engines outside Rust serialises too.

use crate::contract::BufferRole;
use strata_kernels::pass_plan::{PassBuffer, Stage};

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
    /// Makes each of the pass's own buffers with `make(buffer, bytes)`, sized by its
    /// [`SizeRule`](crate::SizeRule) for `pixels` pixels and `blocks` blocks (the unused
    /// payloads buffer takes 4 bytes).
    pub fn make<E>(pixels: u64, blocks: u64, mut make: impl FnMut(PassBuffer, u64) -> Result<B, E>) -> Result<Self, E> {
        let mut own = |buffer: PassBuffer| make(buffer, buffer.size_rule().bytes(pixels, blocks));
        Ok(OwnBuffers {
            histogram_params: own(PassBuffer::HistogramParams)?,
            selection_params: own(PassBuffer::SelectionParams)?,
            sorted_pixels: own(PassBuffer::SortedPixels)?,
            spans: own(PassBuffer::Spans)?,
            block_stats: own(PassBuffer::BlockStats)?,
            blue_noise: own(PassBuffer::BlueNoise)?,
            unused_payloads: make(PassBuffer::Payloads, 4)?,
        })
    }

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
/// binding numbers come from the registry, `strata_kernels::pass_plan::numbered`).
pub(crate) struct BindingPlan<'a, B, S> {
    pub histogram: Vec<(&'static str, Resource<'a, B, S>)>,
    pub select: Vec<(&'static str, Resource<'a, B, S>)>,
    pub resample: Option<Vec<(&'static str, Resource<'a, B, S>)>>,
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
    /// gets ([`Stage::bindings`]).
    pub(crate) fn plan<'a, B>(&self, own: &'a OwnBuffers<B>) -> BindingPlan<'a, B, S> {
        use Resource::{Engine, Own};
        let resource = |buffer: PassBuffer| -> Option<Resource<'a, B, S>> {
            Some(match buffer {
                PassBuffer::HistogramParams => Own(&own.histogram_params),
                PassBuffer::SelectionParams => Own(&own.selection_params),
                PassBuffer::SortedPixels => Own(&own.sorted_pixels),
                PassBuffer::Spans => Own(&own.spans),
                PassBuffer::BlockStats => Own(&own.block_stats),
                PassBuffer::BlueNoise => Own(&own.blue_noise),
                PassBuffer::Candidates => Engine(self.candidates),
                PassBuffer::Payloads => self.payloads.map_or(Own(&own.unused_payloads), Engine),
                PassBuffer::Selections => Engine(self.selections),
                PassBuffer::ResampleInputs => Engine(self.resample?.inputs),
                PassBuffer::Resampled => Engine(self.resample?.outputs),
            })
        };
        let stage = |stage: Stage| -> Option<Vec<(&'static str, Resource<'a, B, S>)>> {
            stage.bindings().iter().map(|&(name, buffer)| Some((name, resource(buffer)?))).collect()
        };
        BindingPlan {
            histogram: stage(Stage::Histogram).expect("the histogram binds no resampling buffer"),
            select: stage(Stage::Select).expect("the selection binds no resampling buffer"),
            resample: stage(Stage::Resample),
        }
    }
}
