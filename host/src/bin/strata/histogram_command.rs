//! `strata histogram`: the block-histogram kernel alone on a generated candidate image,
//! checked against its Rust reference and timed.

use anyhow::{Result, anyhow, bail};
use std::time::Instant;
use strata_kernels::BlockGrid;
use strata_kernels::reference::block_histogram::block_histogram;
use strata_kernels::selection::{SelectionSettings, block_size_parser};
use strata_render::backend_choice::{BackendChoice, open_backend};
use strata_render::histogram_pass::{BlockHistogramPass, HistogramVariant, check_image_fits};
use strata_render::synthetic::{CandidateMix, candidate_image};

#[derive(clap::Args)]
pub(crate) struct HistogramArgs {
    /// Image width in pixels.
    #[arg(long, default_value_t = 1920)]
    width: u32,
    /// Image height in pixels.
    #[arg(long, default_value_t = 1080)]
    height: u32,
    /// Block size B (blocks are B x B).
    #[arg(long, default_value_t = SelectionSettings::default().block_size, value_parser = block_size_parser())]
    block_size: u32,
    /// Seed of the generated candidates.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Distinct object ids in the generated image.
    #[arg(long, default_value_t = 6)]
    objects: u32,
    /// Share of awkward candidates (NaN, infinite, negative keys, misses, empty pixels).
    #[arg(long, default_value_t = 0.05)]
    awkward: f64,
    /// Backend to run on.
    #[arg(long, value_enum, default_value_t = BackendChoice::Auto)]
    backend: BackendChoice,
    /// Kernel variant.
    #[arg(long, value_enum, default_value_t = VariantArg::Auto)]
    variant: VariantArg,
    /// Timed repetitions (timestamp queries) after the checked run.
    #[arg(long, default_value_t = 5)]
    repeat: u32,
}

#[derive(Clone, Copy, clap::ValueEnum)]
pub(crate) enum VariantArg {
    /// The best for this device and block size (the network on a GPU and on the
    /// interpreter, ranking on a CPU driver such as lavapipe).
    Auto,
    /// The bitonic network through workgroup memory.
    Portable,
    /// The bitonic network with subgroup shuffles.
    Subgroup,
    /// Positions counted over each block (same outputs).
    Rank,
}

pub(crate) fn histogram(args: HistogramArgs) -> Result<()> {
    let grid = BlockGrid::new(args.width, args.height, args.block_size)?;
    if args.objects == 0 {
        bail!("--objects 0: the generated image needs at least one object id");
    }
    if !(0.0..=1.0).contains(&args.awkward) {
        bail!("--awkward {}: must be a share between 0 and 1", args.awkward);
    }
    let mut backend = open_backend(args.backend)?;
    // Before the candidates are generated (8 bytes a pixel on the host) or any buffer
    // is made: the size flags, not an internal buffer, are what the user can change.
    check_image_fits(backend.info(), grid)
        .map_err(|e| anyhow!("--width {} --height {}: {e}", args.width, args.height))?;
    println!("backend: {}", backend.info().summary());
    let variant = match args.variant {
        VariantArg::Auto => HistogramVariant::Auto,
        VariantArg::Portable => HistogramVariant::Portable,
        VariantArg::Subgroup => HistogramVariant::Subgroup,
        VariantArg::Rank => HistogramVariant::Rank,
    };
    let mix = CandidateMix { objects: args.objects, awkward: args.awkward, ..Default::default() };
    let candidates = candidate_image(grid.width, grid.height, args.seed, mix);
    let pass = BlockHistogramPass::new(backend.as_mut(), variant, grid)?;
    println!(
        "kernel: {} ({} invocations per workgroup, {:?} workgroups)",
        pass.kernel().name(),
        pass.kernel().invocations(),
        pass.workgroups()
    );
    let started = Instant::now();
    let output = pass.run(backend.as_mut(), &candidates)?;
    let wall = started.elapsed();
    let reference = block_histogram(grid, &candidates);
    let matches = output == reference;
    let clusters: u64 = output.stats.iter().map(|s| u64::from(s.clusters)).sum();
    let invalid: u64 = output.stats.iter().map(|s| u64::from(s.invalid)).sum();
    let empty: u64 = output.stats.iter().map(|s| u64::from(s.empty)).sum();
    println!(
        "image: {}x{} = {} candidates, {} blocks of {}x{}",
        grid.width,
        grid.height,
        grid.pixel_count(),
        grid.block_count(),
        grid.block_size,
        grid.block_size
    );
    println!(
        "clusters: {clusters} ({:.2} per block); invalid keys: {invalid}; pixels without candidate: {empty}",
        clusters as f64 / f64::from(grid.block_count())
    );
    println!("first run (upload, dispatch, read-back): {:.1} ms", wall.as_secs_f64() * 1e3);
    if backend.info().timestamps && args.repeat > 0 {
        let mut times = Vec::new();
        for _ in 0..args.repeat {
            times.push(pass.dispatch_timed(backend.as_mut())?.as_secs_f64() * 1e3);
        }
        times.sort_by(f64::total_cmp);
        println!(
            "kernel time (timestamp queries, {} runs): median {:.2} ms, min {:.2} ms",
            times.len(),
            times[times.len() / 2],
            times[0]
        );
    }
    pass.destroy(backend.as_mut())?;
    if !matches {
        bail!("the kernel's output differs from the Rust reference");
    }
    println!("output identical to the Rust reference: yes");
    Ok(())
}
