//! strata's criterion benchmarks live in `benches/benches/`; results and the exact
//! commands are in `BENCHMARKS.md`. This library holds what they share.

use strata_kernels::types::Candidate;
use strata_render::synthetic::{CandidateMix, candidate_image};

/// The benchmark image: 1024 × 1024 = 1M candidates, default mix, fixed seed.
pub fn benchmark_candidates() -> (u32, u32, Vec<Candidate>) {
    let (width, height) = (1024, 1024);
    (width, height, candidate_image(width, height, 2025, CandidateMix::default()))
}
