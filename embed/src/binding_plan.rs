//! Which buffer goes to which binding of which kernel, and how large each buffer is,
//! written once as data: the wgpu and ash flavours bind from it, and the export package
//! for engines outside Rust (`strata-export`'s `manifest.json`) serialises it. The
//! binding numbers themselves come from naga's reflection of the kernels (the registry);
//! here a binding is named by its WGSL variable.

use crate::contract::BufferRole;
use crate::wgsl::{ModuleId, WgslModule};
use strata_kernels::embed_types::{ResampleInput, ResampleOutput, SelectedCandidates, SelectionParams};
use strata_kernels::types::{BlockStats, Candidate, ClusterSpan, HistogramParams};

/// Every buffer the pass binds: the engine's (the contract, [`crate::contract`]) and the
/// pass's own.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PassBuffer {
    /// The histogram kernel's uniform ([`HistogramParams`]), rewritten every frame.
    HistogramParams,
    /// `strata_select`'s and `strata_resample`'s uniform ([`SelectionParams`]), rewritten
    /// every frame.
    SelectionParams,
    /// Each block's pixel indices, clustered and sorted (`u32` per pixel).
    SortedPixels,
    /// Each sorted entry's cluster run ([`ClusterSpan`] per pixel).
    Spans,
    /// Per-block counts ([`BlockStats`] per block of the largest grid).
    BlockStats,
    /// The blue-noise tables (`BlueNoiseTables::packed`), uploaded once.
    BlueNoise,
    /// The engine's candidates ([`Candidate`] per pixel).
    Candidates,
    /// The engine's payloads (`u32` per pixel), optional.
    Payloads,
    /// The selections ([`SelectedCandidates`] per pixel).
    Selections,
    /// The engine's resampling weights ([`ResampleInput`] per pixel).
    ResampleInputs,
    /// The resampling's results ([`ResampleOutput`] per pixel).
    Resampled,
}

/// Who writes a buffer, and when.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Writer {
    /// The engine, before the pass reads it (its candidates, payloads, weights).
    Engine,
    /// The host, every frame, before the dispatches (the uniforms: `frame_params`).
    HostEveryFrame,
    /// The host, once, after creating it (the blue-noise tables).
    HostOnce,
    /// One of the pass's kernels.
    Pass,
}

/// How large a buffer must be.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SizeRule {
    /// A fixed number of bytes.
    Fixed(u64),
    /// Bytes per pixel of the image.
    PerPixel(u64),
    /// Bytes per block of the largest block grid any frame has ([`crate::frame`]'s
    /// `max_blocks`: with block shifting one more row and column).
    PerBlock(u64),
}

impl SizeRule {
    /// Bytes for an image of `pixels` pixels whose largest grid has `blocks` blocks.
    pub fn bytes(self, pixels: u64, blocks: u64) -> u64 {
        match self {
            SizeRule::Fixed(bytes) => bytes,
            SizeRule::PerPixel(bytes) => bytes * pixels,
            SizeRule::PerBlock(bytes) => bytes * blocks,
        }
    }
}

impl PassBuffer {
    /// Every buffer, the pass's own first.
    pub const ALL: [PassBuffer; 11] = [
        PassBuffer::HistogramParams,
        PassBuffer::SelectionParams,
        PassBuffer::SortedPixels,
        PassBuffer::Spans,
        PassBuffer::BlockStats,
        PassBuffer::BlueNoise,
        PassBuffer::Candidates,
        PassBuffer::Payloads,
        PassBuffer::Selections,
        PassBuffer::ResampleInputs,
        PassBuffer::Resampled,
    ];

    /// The buffer's name (the contract's names for the engine's buffers).
    pub fn name(self) -> &'static str {
        match self.engine_role() {
            Some(role) => role.name(),
            None => match self {
                PassBuffer::HistogramParams => "histogram_params",
                PassBuffer::SelectionParams => "selection_params",
                PassBuffer::SortedPixels => "sorted_pixels",
                PassBuffer::Spans => "spans",
                PassBuffer::BlockStats => "block_stats",
                _ => "blue_noise",
            },
        }
    }

    /// The contract's role of an engine buffer; `None` for the pass's own.
    pub fn engine_role(self) -> Option<BufferRole> {
        match self {
            PassBuffer::Candidates => Some(BufferRole::Candidates),
            PassBuffer::Payloads => Some(BufferRole::Payloads),
            PassBuffer::Selections => Some(BufferRole::Selections),
            PassBuffer::ResampleInputs => Some(BufferRole::ResampleInputs),
            PassBuffer::Resampled => Some(BufferRole::Resampled),
            _ => None,
        }
    }

    /// How large it must be.
    pub fn size_rule(self) -> SizeRule {
        let per_pixel = |bytes: usize| SizeRule::PerPixel(bytes as u64);
        match self {
            PassBuffer::HistogramParams => SizeRule::Fixed(size_of::<HistogramParams>() as u64),
            PassBuffer::SelectionParams => SizeRule::Fixed(size_of::<SelectionParams>() as u64),
            PassBuffer::SortedPixels | PassBuffer::Payloads => per_pixel(size_of::<u32>()),
            PassBuffer::Spans => per_pixel(size_of::<ClusterSpan>()),
            PassBuffer::BlockStats => SizeRule::PerBlock(size_of::<BlockStats>() as u64),
            PassBuffer::BlueNoise => SizeRule::Fixed(4 * u64::from(strata_kernels::blue_noise::PACKED_WORDS)),
            PassBuffer::Candidates => per_pixel(size_of::<Candidate>()),
            PassBuffer::Selections => per_pixel(size_of::<SelectedCandidates>()),
            PassBuffer::ResampleInputs => per_pixel(size_of::<ResampleInput>()),
            PassBuffer::Resampled => per_pixel(size_of::<ResampleOutput>()),
        }
    }

    /// Who writes it.
    pub fn writer(self) -> Writer {
        match self {
            PassBuffer::HistogramParams | PassBuffer::SelectionParams => Writer::HostEveryFrame,
            PassBuffer::BlueNoise => Writer::HostOnce,
            PassBuffer::Candidates | PassBuffer::Payloads | PassBuffer::ResampleInputs => Writer::Engine,
            PassBuffer::SortedPixels
            | PassBuffer::Spans
            | PassBuffer::BlockStats
            | PassBuffer::Selections
            | PassBuffer::Resampled => Writer::Pass,
        }
    }
}

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

    /// The stage a module runs.
    pub fn of(module: ModuleId) -> Stage {
        match module {
            ModuleId::Histogram | ModuleId::HistogramSubgroup | ModuleId::HistogramRank => Stage::Histogram,
            ModuleId::Select => Stage::Select,
            ModuleId::Resample => Stage::Resample,
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
}

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
    /// [`SizeRule`] for `pixels` pixels and `blocks` blocks (the unused payloads buffer
    /// takes 4 bytes).
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wgsl::module;

    /// Every binding of every module is in its stage's list, and every listed buffer's
    /// record stride is the one the WGSL declares.
    #[test]
    fn every_binding_of_every_module_has_one_buffer_of_its_stride() {
        for id in ModuleId::ALL {
            let module = module(id).unwrap();
            let listed = Stage::of(id).bindings();
            assert_eq!(listed.len(), module.bindings.len(), "{id:?}");
            for binding in &module.bindings {
                let (_, buffer) = listed.iter().find(|(name, _)| *name == binding.name).unwrap();
                match buffer.size_rule() {
                    SizeRule::PerPixel(bytes) | SizeRule::PerBlock(bytes) => {
                        assert_eq!(u64::from(binding.stride), bytes, "{id:?} `{}`", binding.name)
                    }
                    SizeRule::Fixed(bytes) => assert!(bytes >= binding.min_size, "{id:?} `{}`", binding.name),
                }
                // Only the pass's kernels write, and only buffers the pass writes.
                assert!(!binding.writable || buffer.writer() == Writer::Pass, "{id:?} `{}`", binding.name);
            }
        }
    }
}
