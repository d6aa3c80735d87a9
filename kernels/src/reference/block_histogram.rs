//! What the block-histogram kernel computes, stated in plain Rust.

use crate::block_grid::BlockGrid;
use crate::types::{BlockStats, Candidate, ClusterSpan, INVALID_KEY, OBJECT_ID_NONE, canonical_key};

/// Outputs of the block-histogram pass.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct HistogramOutput {
    /// Per block, its pixels ordered by (object id, canonical key, pixel index).
    pub sorted_pixels: Vec<u32>,
    /// Per pixel, its own cluster's run in `sorted_pixels`.
    pub spans: Vec<ClusterSpan>,
    /// Per block, its counters.
    pub stats: Vec<BlockStats>,
}

/// The cluster of its block a candidate joins (paper §4.3, WGSL `cluster_of` in
/// `strata/masking.wgsl`): its object id with masking, else 0; pixels without a candidate
/// keep [`OBJECT_ID_NONE`] either way.
pub fn cluster_of(candidate: Candidate, masking: bool) -> u32 {
    if masking || candidate.object_id == OBJECT_ID_NONE { candidate.object_id } else { 0 }
}

/// The candidates with their object ids replaced by their clusters ([`cluster_of`]):
/// what [`block_histogram`], which sorts by object id, needs to state a pass with
/// masking off.
pub fn unmasked(candidates: &[Candidate]) -> Vec<Candidate> {
    candidates.iter().map(|&c| Candidate { object_id: cluster_of(c, false), ..c }).collect()
}

/// Sort key of a pixel's candidate.
pub fn sort_key(candidate: Candidate, pixel: u32) -> (u32, u32, u32) {
    (candidate.object_id, canonical_key(candidate), pixel)
}

/// Sorts one block's entries in place, the way the kernel orders them.
pub fn sort_block(candidates: &[Candidate], entries: &mut [u32]) {
    entries.sort_unstable_by_key(|&pixel| sort_key(candidates[pixel as usize], pixel));
}

/// The histogram pass on the CPU.
pub fn block_histogram(grid: BlockGrid, candidates: &[Candidate]) -> HistogramOutput {
    assert_eq!(candidates.len(), grid.pixel_count(), "one candidate per pixel");
    let mut sorted_pixels = vec![0u32; grid.pixel_count()];
    let mut spans = vec![ClusterSpan::default(); grid.pixel_count()];
    let mut stats = Vec::with_capacity(grid.block_count() as usize);
    for block in 0..grid.block_count() {
        let rect = grid.block(block);
        let range = rect.base as usize..(rect.base + rect.len()) as usize;
        let entries = &mut sorted_pixels[range.clone()];
        for (local, entry) in entries.iter_mut().enumerate() {
            *entry = rect.pixel(grid.width, local as u32);
        }
        sort_block(candidates, entries);
        let mut block_stats = BlockStats::default();
        let mut start = 0;
        while start < entries.len() {
            let object = candidates[entries[start] as usize].object_id;
            let end =
                start + entries[start..].iter().take_while(|&&p| candidates[p as usize].object_id == object).count();
            let valid = entries[start..end]
                .iter()
                .take_while(|&&p| canonical_key(candidates[p as usize]) != INVALID_KEY)
                .count();
            block_stats.clusters += 1;
            if object == OBJECT_ID_NONE {
                block_stats.empty += (end - start) as u32;
            } else {
                block_stats.invalid += (end - start - valid) as u32;
            }
            for &pixel in &entries[start..end] {
                spans[pixel as usize] =
                    ClusterSpan { offset: rect.base + start as u32, length: (end - start) as u32, valid: valid as u32 };
            }
            start = end;
        }
        stats.push(block_stats);
    }
    HistogramOutput { sorted_pixels, spans, stats }
}
