//! Check of the block-histogram kernels: generated candidate images, every block size,
//! partial blocks, equal keys, NaN / ±Inf / negative / denormal keys, blocks with no
//! valid candidate; shifted block grids (§5.3) and object masking off (odd loop seeds
//! are unmasked, those not divisible by 3 shifted); all outputs are integers and must match
//! the reference bit for bit.

use super::{Case, CheckConfig, Compare, KernelCheck, Output};
use strata_backends::Backend;
use strata_kernels::reference::block_histogram::{HistogramOutput, block_histogram, unmasked};
use strata_kernels::types::{BLOCK_SIZES, Candidate, OBJECT_ID_NONE};
use strata_kernels::{BlockGrid, KernelId};
use strata_render::histogram_pass::{BlockHistogramPass, HistogramVariant, PassError};
use strata_render::synthetic::{CandidateMix, candidate_image};

/// Checks one of the two histogram kernels.
pub struct HistogramCheck(pub KernelId);

const FAMILIES: [&str; 3] = ["mostly valid", "mostly invalid", "no candidates"];

fn candidates(case: &Case) -> Vec<Candidate> {
    let awkward = if case.family == 0 { 0.05 } else { 0.6 };
    let mix = CandidateMix { objects: 1 + (case.seed % 9) as u32, key_levels: 1 + (case.seed % 17) as u32, awkward };
    let mut image = candidate_image(case.width, case.height, case.seed, mix);
    if case.family == 2 {
        for candidate in &mut image {
            candidate.object_id = OBJECT_ID_NONE;
        }
    }
    image
}

/// The case's loop seed (bits 16 and up of its seed, see `cases`).
fn loop_seed(case: &Case) -> u64 {
    case.seed >> 16
}

/// Odd loop seeds run without object masking.
fn masking(case: &Case) -> bool {
    loop_seed(case).is_multiple_of(2)
}

/// Seeds not divisible by 3 shift the block grid.
fn grid(case: &Case) -> Result<BlockGrid, strata_kernels::GridError> {
    let grid = BlockGrid::new(case.width, case.height, case.block_size)?;
    let seed = loop_seed(case);
    if seed.is_multiple_of(3) {
        return Ok(grid);
    }
    let b = u64::from(case.block_size);
    grid.with_shift((seed * 5 % b) as u32, (seed * 3 % b) as u32)
}

fn outputs(output: HistogramOutput) -> Vec<Output> {
    vec![
        Output { name: "sorted_pixels", words: output.sorted_pixels, compare: Compare::Exact },
        Output { name: "spans", words: bytemuck::cast_slice(&output.spans).to_vec(), compare: Compare::Exact },
        Output { name: "block_stats", words: bytemuck::cast_slice(&output.stats).to_vec(), compare: Compare::Exact },
    ]
}

impl KernelCheck for HistogramCheck {
    fn kernel(&self) -> KernelId {
        self.0
    }

    fn cases(&self, config: CheckConfig) -> Vec<Case> {
        let (seeds, sizes): (u64, &[(u32, u32)]) = if config.full {
            (20, &[(1, 1), (17, 33), (64, 64), (129, 65), (333, 200)])
        } else {
            (3, &[(1, 1), (17, 33), (40, 24)])
        };
        let mut cases = Vec::new();
        for seed in 0..seeds {
            let family = (seed % 3) as u32;
            for &(width, height) in sizes {
                for block_size in BLOCK_SIZES {
                    cases.push(Case {
                        label: format!("{width}x{height} B={block_size} seed {seed} ({})", FAMILIES[family as usize]),
                        width,
                        height,
                        block_size,
                        seed: 0xc0ffee ^ seed << 16 ^ u64::from(width) << 4 ^ u64::from(block_size),
                        family,
                    });
                }
            }
        }
        cases
    }

    fn run(&self, backend: &mut dyn Backend, case: &Case) -> Result<Vec<Output>, PassError> {
        let grid = grid(case)?;
        let variant = match self.0 {
            KernelId::BlockHistogramSubgroup => HistogramVariant::Subgroup,
            KernelId::BlockHistogramRank => HistogramVariant::Rank,
            _ => HistogramVariant::Portable,
        };
        let pass = BlockHistogramPass::with_masking(backend, variant, grid, masking(case))?;
        pass.poison_outputs(backend, 0xdead_beef)?;
        let result = pass.run(backend, &candidates(case));
        pass.destroy(backend)?;
        Ok(outputs(result?))
    }

    fn reference(&self, case: &Case) -> Vec<Output> {
        let grid = grid(case).expect("cases have valid grids");
        let candidates = candidates(case);
        let candidates = if masking(case) { candidates } else { unmasked(&candidates) };
        outputs(block_histogram(grid, &candidates))
    }
}
