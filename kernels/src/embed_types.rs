//! The embeddable selection's records and constants: the buffer contract between an
//! engine and the `strata_select` / `strata_resample` kernels, declared once
//! ([`crate::gpu`]): the WGSL module `gpu/embed.wgsl` is generated from them.

use crate::gpu::{GpuModule, StructDeclaration, gpu_constants, gpu_struct};

gpu_constants! {
    fn constants;
    /// A slot without a candidate, or a pixel without a selection.
    pub const NO_PAYLOAD: u32 = 0xffff_ffff;
    /// [`ResampleOutput::slot`]: the pixel's own (canonical) sample was chosen.
    pub const CANONICAL_SLOT: u32 = 4;
    /// [`ResampleOutput::slot`]: every weight was zero; nothing chosen.
    pub const NO_SLOT: u32 = 0xffff_ffff;
    /// [`ResampleOutput::slot`]: a weight or target was NaN, infinite or negative, or a
    /// positive weight came with a zero target; nothing chosen.
    pub const INVALID_SLOT: u32 = 0xffff_fffe;
}
pub use crate::selection::MAX_SELECTED;

gpu_struct! {
    /// Per-frame settings of `strata_select` and `strata_resample` (WGSL `SelectionParams`,
    /// a uniform).
    #[derive(Eq)]
    pub struct SelectionParams {
        /// Image width in pixels.
        pub width: u32,
        /// Image height in pixels.
        pub height: u32,
        /// Frame index (the blue-noise sample index is frame mod 256).
        pub frame: u32,
        /// Render seed: decorrelates independent renders (white jitter, one toroidal shift).
        pub seed: u32,
        /// K in 1..=4.
        pub candidates: u32,
        /// The sampler variant's [`crate::selection::SamplerVariant::id`].
        pub sampler: u32,
        /// 1: the payload of a pixel is its index (the payloads buffer is not read).
        pub identity_payload: u32,
        /// Padding.
        pub _pad: u32,
    }
}

gpu_struct! {
    /// What `strata_select` gives each pixel (WGSL `SelectedCandidates`, 32 bytes).
    pub struct SelectedCandidates {
        /// The K selected payloads; slots ≥ K, and every slot of a pixel without a
        /// candidate, hold [`NO_PAYLOAD`].
        pub payloads: [u32; 4] as "vec4<u32>",
        /// The pixel's resampling number in [0, 1) for this frame.
        pub resample_number: f32,
        /// n: candidates in the pixel's cluster run (0 without a candidate).
        pub run_length: u32,
        /// Valid candidates of the run (finite, non-negative keys; they come first).
        pub run_valid: u32,
        /// Slots filled: K, or 0.
        pub selected: u32,
    }
}

gpu_struct! {
    /// What the engine gives `strata_resample` per pixel (WGSL `ResampleInput`, 48 bytes):
    /// resampling weights and target values at this pixel of each selected sample and of
    /// its own canonical sample, from the engine's own shift mapping.
    pub struct ResampleInput {
        /// Resampling weight of each selected slot's sample (0 for unused slots): its MIS
        /// weight × target at this pixel × its unbiased contribution weight.
        pub weights: [f32; 4] as "vec4<f32>",
        /// Target value at this pixel of each selected slot's sample.
        pub targets: [f32; 4] as "vec4<f32>",
        /// Resampling weight of the pixel's own (canonical) sample.
        pub canonical_weight: f32,
        /// Its target value.
        pub canonical_target: f32,
        /// Its payload.
        pub canonical_payload: u32,
        /// Padding.
        pub _pad: u32,
    }
}

gpu_struct! {
    /// What `strata_resample` gives each pixel (WGSL `ResampleOutput`, 16 bytes).
    pub struct ResampleOutput {
        /// The chosen sample's payload ([`NO_PAYLOAD`] when nothing was chosen).
        pub payload: u32,
        /// Its slot 0..K, [`CANONICAL_SLOT`], [`NO_SLOT`] or [`INVALID_SLOT`].
        pub slot: u32,
        /// Unbiased contribution weight W = (sum of weights) / target of the chosen sample.
        pub weight: f32,
        /// Sum of the weights.
        pub weight_sum: f32,
    }
}

/// The WGSL module `gpu/embed.wgsl`: the constants and structs above.
pub fn gpu_module() -> GpuModule {
    GpuModule {
        path: "gpu/embed.wgsl",
        source: "kernels/src/embed_types.rs",
        readers: None,
        constants: constants(),
        structs: vec![
            StructDeclaration::of::<SelectionParams>(),
            StructDeclaration::of::<SelectedCandidates>(),
            StructDeclaration::of::<ResampleInput>(),
            StructDeclaration::of::<ResampleOutput>(),
        ],
    }
}
