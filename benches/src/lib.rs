//! strata's criterion benchmarks live in `benches/benches/`; results and the exact
//! commands are in `BENCHMARKS.md`. This library holds what they share.

pub mod pass_times;

pub use pass_times::PassTimes;
use strata_backends::Backend;
use strata_backends::wgpu_backend::{WgpuBackend, WgpuOptions};
use strata_kernels::types::Candidate;
use strata_render::synthetic::{CandidateMix, candidate_image};

/// The benchmark image: 1024 × 1024 = 1M candidates, default mix, fixed seed.
pub fn benchmark_candidates() -> (u32, u32, Vec<Candidate>) {
    let (width, height) = (1024, 1024);
    (width, height, candidate_image(width, height, 2025, CandidateMix::default()))
}

/// The embedding benches' 1280 × 720 image: keys with many levels, 6 objects in vertical
/// bands, a few pixels (one in 101) without a candidate.
pub fn engine_candidates(width: u32, height: u32) -> Vec<Candidate> {
    (0..width * height)
        .map(|p| Candidate {
            key: ((p.wrapping_mul(2_654_435_761)) >> 20) as f32,
            object_id: if p % 101 == 0 { u32::MAX } else { (p % width) / 214 },
        })
        .collect()
}

/// The wgpu device a bench runs on (the default options), its summary printed first; or,
/// where none opens here, `None` after a line saying that `what` is skipped and why.
pub fn open_wgpu(what: &str) -> Option<WgpuBackend> {
    match WgpuBackend::new(WgpuOptions::default()) {
        Ok(backend) => {
            eprintln!("device: {}", backend.info().summary());
            Some(backend)
        }
        Err(error) => {
            eprintln!("{what} skipped: {error}");
            None
        }
    }
}
