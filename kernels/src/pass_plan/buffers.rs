//! Every buffer the paper's pass binds: who writes it, when, and how large it is.

use crate::embed_types::{ResampleInput, ResampleOutput, SelectedCandidates, SelectionParams};
use crate::types::{BlockStats, Candidate, ClusterSpan, HistogramParams};

/// Every buffer the pass binds: the engine's (strata-embed's contract) and the pass's
/// own.
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
    /// The candidates ([`Candidate`] per pixel): the engine's, or the renderer's.
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
    /// The host, every frame, before the dispatches (the uniforms: [`super::frame_params`]).
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
    /// Bytes per block of the largest block grid any frame has ([`super::max_blocks`]:
    /// with block shifting one more row and column).
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

    /// The buffer's name: the name strata-embed's contract and the export manifest give
    /// it.
    pub fn name(self) -> &'static str {
        match self {
            PassBuffer::HistogramParams => "histogram_params",
            PassBuffer::SelectionParams => "selection_params",
            PassBuffer::SortedPixels => "sorted_pixels",
            PassBuffer::Spans => "spans",
            PassBuffer::BlockStats => "block_stats",
            PassBuffer::BlueNoise => "blue_noise",
            PassBuffer::Candidates => "candidates",
            PassBuffer::Payloads => "payloads",
            PassBuffer::Selections => "selections",
            PassBuffer::ResampleInputs => "resample_inputs",
            PassBuffer::Resampled => "resampled",
        }
    }

    /// Whether the engine owns it and hands it to the pass (strata-embed's contract);
    /// otherwise the pass creates it.
    pub fn engine_owned(self) -> bool {
        matches!(
            self,
            PassBuffer::Candidates
                | PassBuffer::Payloads
                | PassBuffer::Selections
                | PassBuffer::ResampleInputs
                | PassBuffer::Resampled
        )
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
            PassBuffer::BlueNoise => SizeRule::Fixed(4 * u64::from(crate::blue_noise::PACKED_WORDS)),
            PassBuffer::Candidates => per_pixel(size_of::<Candidate>()),
            PassBuffer::Selections => per_pixel(size_of::<SelectedCandidates>()),
            PassBuffer::ResampleInputs => per_pixel(size_of::<ResampleInput>()),
            PassBuffer::Resampled => per_pixel(size_of::<ResampleOutput>()),
        }
    }

    /// Bytes for a `width` × `height` image whose largest grid has `blocks` blocks.
    pub fn bytes(self, width: u32, height: u32, blocks: u64) -> u64 {
        self.size_rule().bytes(u64::from(width) * u64::from(height), blocks)
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
