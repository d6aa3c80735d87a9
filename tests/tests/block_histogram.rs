//! The block-histogram kernel against its Rust reference, on fresh random inputs with
//! many equal keys, mixed object ids and every awkward value, at every block size and at
//! image sizes with partial edge blocks; output buffers poisoned before every run.

use strata_backends::Backend;
use strata_kernels::BlockGrid;
use strata_kernels::reference::block_histogram::{HistogramOutput, block_histogram, unmasked};
use strata_kernels::types::{BLOCK_SIZES, Candidate};
use strata_render::histogram_pass::{BlockHistogramPass, HistogramVariant};
use strata_render::synthetic::{CandidateMix, candidate_image};
use strata_tests::{POISON, vulkan_backend};

fn run_poisoned(
    backend: &mut dyn Backend,
    variant: HistogramVariant,
    grid: BlockGrid,
    candidates: &[Candidate],
) -> HistogramOutput {
    let pass = BlockHistogramPass::new(backend, variant, grid).unwrap_or_else(|e| panic!("{e}"));
    pass.poison_outputs(backend, POISON).unwrap();
    let output = pass.run(backend, candidates).unwrap_or_else(|e| panic!("{e}"));
    pass.destroy(backend).unwrap();
    output
}

fn assert_same(grid: BlockGrid, variant: HistogramVariant, got: &HistogramOutput, want: &HistogramOutput) {
    let context = format!("{}x{} B={} {variant:?}", grid.width, grid.height, grid.block_size);
    if let Some(i) = (0..want.sorted_pixels.len()).find(|&i| got.sorted_pixels[i] != want.sorted_pixels[i]) {
        panic!("{context}: sorted_pixels[{i}] = {:#x}, want {:#x}", got.sorted_pixels[i], want.sorted_pixels[i]);
    }
    if let Some(i) = (0..want.spans.len()).find(|&i| got.spans[i] != want.spans[i]) {
        panic!("{context}: spans[{i}] = {:?}, want {:?}", got.spans[i], want.spans[i]);
    }
    if let Some(i) = (0..want.stats.len()).find(|&i| got.stats[i] != want.stats[i]) {
        panic!("{context}: block_stats[{i}] = {:?}, want {:?}", got.stats[i], want.stats[i]);
    }
    assert_eq!(got, want, "{context}");
}

/// Every variant of `variants` against the reference at every block size of every size in
/// `sizes`: one input (from `seed`) and one reference per size and block size, shared by
/// the variants.
fn check_sizes(variants: &[HistogramVariant], sizes: &[(u32, u32)], seed: u64) {
    let Some(mut backend) = vulkan_backend("block_histogram") else {
        return;
    };
    if variants.contains(&HistogramVariant::Subgroup) && backend.info().subgroup_sizes.is_none() {
        panic!("the Vulkan device has no subgroups: {}", backend.info().summary());
    }
    for (index, &(width, height)) in sizes.iter().enumerate() {
        for (b, &block_size) in BLOCK_SIZES.iter().enumerate() {
            let grid = BlockGrid::new(width, height, block_size).unwrap();
            let seed = seed ^ (index as u64) << 8 ^ b as u64;
            let mix =
                CandidateMix { objects: 1 + (seed % 7) as u32, key_levels: 1 + (seed % 23) as u32, awkward: 0.08 };
            let candidates = candidate_image(width, height, seed, mix);
            let want = block_histogram(grid, &candidates);
            for &variant in variants {
                let got = run_poisoned(&mut backend, variant, grid, &candidates);
                assert_same(grid, variant, &got, &want);
            }
        }
    }
}

const SMALL: &[(u32, u32)] = &[(1, 1), (17, 33), (33, 17), (64, 64), (3, 100), (129, 65)];

#[test]
fn portable_matches_reference_on_small_images() {
    check_sizes(&[HistogramVariant::Portable], SMALL, 0x5eed_0001);
}

#[test]
fn subgroup_matches_reference_on_small_images() {
    check_sizes(&[HistogramVariant::Subgroup], SMALL, 0x5eed_0002);
}

#[test]
fn rank_matches_reference_on_small_images() {
    check_sizes(&[HistogramVariant::Rank], SMALL, 0x5eed_0006);
}

/// At 1080p the three variants share each block size's input and its reference: the Rust
/// reference (unoptimised in the tests' debug build) was two thirds of this test's time
/// when each variant had inputs of its own (18.4 s; docs/benchmarks/ci-time.md).
#[test]
fn every_variant_matches_reference_at_1080p() {
    let variants = [HistogramVariant::Portable, HistogramVariant::Subgroup, HistogramVariant::Rank];
    check_sizes(&variants, &[(1920, 1080)], 0x5eed_0003);
}

/// The portable kernel on wgpu's GL backend (naga's GLSL on llvmpipe's OpenGL), which
/// has no subgroups: the path every adapter can run.
#[test]
fn portable_matches_reference_on_gl() {
    use strata_backends::wgpu_backend::{WgpuApi, WgpuOptions};
    let options = WgpuOptions { api: WgpuApi::Gl, validation: false, subgroups: true, ..Default::default() };
    let Some(mut backend) = strata_tests::open_or_skip("portable_matches_reference_on_gl", options) else {
        return;
    };
    assert!(backend.info().subgroup_sizes.is_none(), "wgpu's GL backend has no subgroups");
    for (width, height, block_size, seed) in [(17, 33, 4, 1), (40, 33, 32, 3), (33, 17, 8, 4), (20, 20, 16, 2)] {
        let grid = BlockGrid::new(width, height, block_size).unwrap();
        let candidates = candidate_image(width, height, seed, CandidateMix { awkward: 0.1, ..Default::default() });
        let got = run_poisoned(&mut backend, HistogramVariant::Auto, grid, &candidates);
        assert_same(grid, HistogramVariant::Auto, &got, &block_histogram(grid, &candidates));
    }
}

/// Shifted block grids (§5.3: the first row and column of blocks partial too) and object
/// masking off (one cluster per block), every variant, against the reference.
#[test]
fn shifted_grids_and_unmasked_clusters_match_reference() {
    let Some(mut backend) = vulkan_backend("block_histogram") else {
        return;
    };
    for (index, &(width, height)) in [(1, 1), (17, 33), (64, 64), (129, 65)].iter().enumerate() {
        for &block_size in &BLOCK_SIZES {
            let shift = (index as u32 * 7 + 1) % block_size;
            let grid =
                BlockGrid::new(width, height, block_size).unwrap().with_shift(shift, block_size - 1 - shift).unwrap();
            for masking in [true, false] {
                let seed = 0x5eed_0005 ^ u64::from(width * block_size);
                let candidates =
                    candidate_image(width, height, seed, CandidateMix { awkward: 0.08, ..Default::default() });
                let want = if masking { candidates.clone() } else { unmasked(&candidates) };
                let want = block_histogram(grid, &want);
                for variant in [HistogramVariant::Portable, HistogramVariant::Subgroup, HistogramVariant::Rank] {
                    let pass = BlockHistogramPass::with_masking(&mut backend, variant, grid, masking).unwrap();
                    pass.poison_outputs(&mut backend, POISON).unwrap();
                    let got = pass.run(&mut backend, &candidates).unwrap_or_else(|e| panic!("{e}"));
                    pass.destroy(&mut backend).unwrap();
                    assert_same(grid, variant, &got, &want);
                }
            }
        }
    }
}

/// Moving the grid of an existing pass (per frame in the renderer) gives the reference
/// of the shifted grid, and moving it back the unshifted one.
#[test]
fn set_grid_shift_moves_the_blocks() {
    let Some(mut backend) = vulkan_backend("block_histogram") else {
        return;
    };
    let grid = BlockGrid::new(45, 38, 16).unwrap();
    let candidates = candidate_image(45, 38, 77, CandidateMix::default());
    let mut pass = BlockHistogramPass::new(&mut backend, HistogramVariant::Auto, grid).unwrap();
    for (sx, sy) in [(5, 11), (15, 0), (0, 0)] {
        pass.set_grid_shift(&mut backend, sx, sy).unwrap();
        let shifted = grid.with_shift(sx, sy).unwrap();
        let got = pass.run(&mut backend, &candidates).unwrap();
        assert_same(shifted, HistogramVariant::Auto, &got, &block_histogram(shifted, &candidates));
    }
    assert!(pass.set_grid_shift(&mut backend, 16, 0).is_err());
    pass.destroy(&mut backend).unwrap();
}

/// The renderer's histogram follows the one plan of the pass frame by frame: its
/// uniform and workgroups are the ones `pass_plan::frame_params` gives strata-embed and
/// the export package for the same settings, frame and seed, and its output is the
/// reference of the frame's shifted grid.
#[test]
fn the_renderers_histogram_runs_each_frame_as_the_plan_says() {
    use strata_backends::backend::download;
    use strata_kernels::pass_plan::{FrameId, frame_params};
    use strata_kernels::selection::SelectionSettings;
    use strata_kernels::types::HistogramParams;
    let Some(mut backend) = vulkan_backend("block_histogram") else {
        return;
    };
    let settings = SelectionSettings { block_size: 8, block_shift: true, ..SelectionSettings::default() };
    let (width, height, seed) = (45, 38, 9);
    let grid = BlockGrid::new(width, height, settings.block_size).unwrap();
    let candidates = candidate_image(width, height, 78, CandidateMix::default());
    let mut pass = BlockHistogramPass::new(&mut backend, HistogramVariant::Auto, grid).unwrap();
    let max_workgroups = backend.info().limits.max_workgroups_per_dimension;
    let mut shifted_frames = 0;
    for frame in 0..6 {
        pass.set_frame(&mut backend, &settings, frame, seed).unwrap();
        let id = FrameId { frame, seed, identity_payload: true };
        let plan = frame_params(&settings, width, height, id, max_workgroups).unwrap();
        let params: Vec<HistogramParams> = download(&mut backend, pass.params).unwrap();
        assert_eq!(params[0], plan.histogram, "frame {frame}");
        assert_eq!(pass.workgroups(), plan.histogram_workgroups, "frame {frame}");
        let shifted = grid.with_shift(plan.histogram.shift_x, plan.histogram.shift_y).unwrap();
        shifted_frames += usize::from(plan.histogram.shift_x + plan.histogram.shift_y > 0);
        let got = pass.run(&mut backend, &candidates).unwrap();
        assert_same(shifted, HistogramVariant::Auto, &got, &block_histogram(shifted, &candidates));
    }
    assert!(shifted_frames >= 4, "block shifting moves the grid on most frames");
    pass.destroy(&mut backend).unwrap();
}
