//! The records of the paper's pass the kernels share with the host (candidates, the
//! histogram's outputs and its uniform) and their constants, declared once
//! ([`crate::gpu`]): the WGSL module `gpu/strata.wgsl` is generated from them.

use crate::gpu::{GpuModule, StructDeclaration, gpu_constants, gpu_struct};

gpu_constants! {
    fn constants;
    /// Slots one workgroup of the histogram kernel sorts: 1024 / B² whole blocks per
    /// workgroup.
    pub const HISTOGRAM_SLOTS_PER_WORKGROUP: u32 = 1024;
    /// `OBJECT_ID_NONE`: the pixel has no candidate (no hit and no environment, or no valid path).
    pub const OBJECT_ID_NONE: u32 = 0xffff_ffff;
    /// `OBJECT_ID_ENVIRONMENT`: the camera ray escaped; the environment is one cluster of its own.
    pub const OBJECT_ID_ENVIRONMENT: u32 = 0xffff_fffe;
    /// `INVALID_KEY`: canonical sort key of an invalid candidate, above every valid key
    /// (0xffffffff is left to padding).
    pub const INVALID_KEY: u32 = 0xffff_fffe;
}
/// Block sizes the histogram pass accepts.
pub const BLOCK_SIZES: [u32; 4] = [4, 8, 16, 32];

gpu_struct! {
    /// One candidate per pixel (WGSL `Candidate`), written by the candidate pass or by an
    /// embedding engine.
    pub struct Candidate {
        /// Luminance of the candidate's own one-sample estimate f/p at its own pixel
        /// (paper §4.1). NaN, ±Inf and negative values make the candidate invalid.
        pub key: f32,
        /// Object id of the pixel's first hit; [`OBJECT_ID_ENVIRONMENT`] for a camera ray
        /// that escaped to the environment, [`OBJECT_ID_NONE`] for a pixel without a
        /// candidate.
        pub object_id: u32,
    }
}

gpu_struct! {
    /// Where a pixel's own cluster lies in its block's sorted list (WGSL `ClusterSpan`).
    #[derive(Eq, Hash)]
    pub struct ClusterSpan {
        /// Index into `sorted_pixels` of the run's first candidate.
        pub offset: u32,
        /// Candidates in the run, valid and invalid.
        pub length: u32,
        /// The run's first `valid` candidates are valid; the rest have weight 0.
        pub valid: u32,
    }
}

gpu_struct! {
    /// Per-block counters of the histogram pass (WGSL `BlockStats`).
    #[derive(Eq, Hash)]
    pub struct BlockStats {
        /// Distinct object ids in the block, the no-candidate cluster included.
        pub clusters: u32,
        /// Candidates with an object id but a NaN, infinite or negative key.
        pub invalid: u32,
        /// Pixels without a candidate.
        pub empty: u32,
    }
}

gpu_struct! {
    /// Sizes of one histogram dispatch (WGSL `HistogramParams`, a uniform), filled by the
    /// host (kernels never use `num_workgroups`).
    #[derive(Eq)]
    pub struct HistogramParams {
        /// Image width in pixels.
        pub width: u32,
        /// Image height in pixels.
        pub height: u32,
        /// B: blocks are B × B pixels, B in [`BLOCK_SIZES`].
        pub block_size: u32,
        /// log2(B).
        pub log2_block_size: u32,
        /// Blocks per row, ceil(width / B).
        pub blocks_x: u32,
        /// Blocks per column, ceil(height / B).
        pub blocks_y: u32,
        /// Workgroups per row of the 2-D dispatch grid.
        pub workgroups_x: u32,
        /// Block grid shift sx in 0..B (paper §5.3): block edges at x = -shift_x (mod B);
        /// blocks_x and blocks_y count the shifted grid.
        pub shift_x: u32,
        /// Block grid shift sy in 0..B.
        pub shift_y: u32,
        /// 1: candidates cluster by object id (§4.3); 0: one cluster per block (pixels without
        /// a candidate still form their own run).
        pub masking: u32,
        /// Padding.
        pub _pad0: u32,
        /// Padding to 48 bytes.
        pub _pad1: u32,
    }
}

/// Canonical sort key of a candidate, decided on its bit pattern so that every backend
/// agrees: -0 → 0, denormals kept, NaN / ±Inf / negative → [`INVALID_KEY`], and every
/// key of a pixel without a candidate is [`INVALID_KEY`]. Mirrors WGSL `canonical_key`.
pub fn canonical_key(candidate: Candidate) -> u32 {
    let bits = candidate.key.to_bits();
    let magnitude = bits & 0x7fff_ffff;
    if candidate.object_id == OBJECT_ID_NONE {
        INVALID_KEY
    } else if magnitude == 0 {
        0
    } else if bits >> 31 != 0 || magnitude >= 0x7f80_0000 {
        INVALID_KEY
    } else {
        bits
    }
}

/// The WGSL module `gpu/strata.wgsl`: the constants and structs above.
pub fn gpu_module() -> GpuModule {
    GpuModule {
        path: "gpu/strata.wgsl",
        source: "kernels/src/types.rs",
        readers: None,
        constants: constants(),
        structs: vec![
            StructDeclaration::of::<Candidate>(),
            StructDeclaration::of::<ClusterSpan>(),
            StructDeclaration::of::<BlockStats>(),
            StructDeclaration::of::<HistogramParams>(),
        ],
    }
}
