//! The integer hash the selection kernels and the host share: PCG's output permutation
//! (Jarzynski and Olano 2020, "Hash Functions for GPU Rendering"), WGSL `selection_hash`
//! in `kernels/wgsl/strata/selection.wgsl`. Product code (the block grid's per-frame
//! shift) and the Rust references both call it from here.

/// PCG hash (Jarzynski and Olano 2020), WGSL `selection_hash`.
pub fn selection_hash(v: u32) -> u32 {
    let state = v.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}
