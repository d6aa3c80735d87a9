//! `guards`: what the package kernels' buffer guards cost (issue 56): every buffer access
//! of the block histogram, `strata_select` and `strata_resample` is checked against the
//! bound buffer's length (`arrayLength`), so that a buffer too small for the image is
//! never read or written past its end (tests/tests/kernel_guards.rs).
//!
//! Each kernel runs twice side by side in one run, on the ash backend (naga's SPIR-V with
//! no bounds checks of its own: what an engine runs from the exported package, unlike
//! wgpu, which adds its own checks) at 1280 × 720, B = 16:
//! * `guards_720p/<kernel>/guarded`: the kernel as the registry has it;
//! * `guards_720p/<kernel>/unguarded`: the same source with every `arrayLength(&buffer)`
//!   replaced by `0xffffffffu`, so each guard's comparison is always true and the
//!   compiler folds it away: the kernel as it was before the guards.
//!
//! Before them, a paired measurement prints the ratio guarded ÷ unguarded per kernel
//! (median and 10-90 % range over rounds that time both back to back).
//!
//! Run: `cargo bench -p strata-benches --bench guards`.

use criterion::{Criterion, criterion_group, criterion_main};
use std::time::Duration;
use strata_backends::ash_backend::{AshBackend, AshOptions, SpirvSource};
use strata_backends::backend::upload;
use strata_backends::{Backend, Bind};
use strata_kernels::blue_noise::BlueNoiseTables;
use strata_kernels::embed_types::{SelectedCandidates, SelectionParams};
use strata_kernels::selection::SamplerVariant;
use strata_kernels::types::{BlockStats, ClusterSpan};
use strata_kernels::{BlockGrid, Kernel, KernelId, Registry};

const WIDTH: u32 = 1280;
const HEIGHT: u32 = 720;
const BLOCK: u32 = 16;
/// Rounds of the paired measurement.
const PAIRED_ROUNDS: usize = 40;

/// `kernel` with its guards folded away (see the module comment).
fn unguarded(kernel: &Kernel) -> Kernel {
    let mut text = kernel.source.text.clone();
    for binding in &kernel.bindings {
        text = text.replace(&format!("arrayLength(&{})", binding.name), "0xffffffffu");
    }
    assert!(!text.contains("arrayLength("), "{}: a guard left", kernel.name());
    let subgroup = kernel.id == KernelId::BlockHistogramSubgroup;
    Kernel::from_wgsl(kernel.name(), text, kernel.entry_point(), subgroup).expect("the unguarded kernel")
}

fn zeroed(backend: &mut dyn Backend, label: &str, bytes: usize) -> strata_backends::BufferId {
    upload(backend, label, &vec![0u32; bytes / 4]).expect("buffer")
}

fn guards(c: &mut Criterion) {
    let mut backend = match AshBackend::new(AshOptions { source: SpirvSource::Naga, ..Default::default() }) {
        Ok(backend) => backend,
        Err(error) => {
            eprintln!("guards bench: no Vulkan device: {error}");
            return;
        }
    };
    let registry = Registry::shared().expect("registry");
    let pixels = (WIDTH * HEIGHT) as usize;
    let candidates = strata_benches::engine_candidates(WIDTH, HEIGHT);
    let grid = BlockGrid::new(WIDTH, HEIGHT, BLOCK).expect("grid");
    let workgroups = grid.histogram_workgroups(65_535);
    let histogram_params =
        upload(&mut backend, "histogram params", &[grid.histogram_params(workgroups[0], true)]).unwrap();
    let candidate_buffer = upload(&mut backend, "candidates", &candidates).unwrap();
    let sorted = zeroed(&mut backend, "sorted_pixels", pixels * 4);
    let spans = zeroed(&mut backend, "spans", pixels * size_of::<ClusterSpan>());
    let stats = zeroed(&mut backend, "block_stats", grid.block_count() as usize * size_of::<BlockStats>());
    let selection_params = SelectionParams {
        width: WIDTH,
        height: HEIGHT,
        frame: 5,
        seed: 9,
        candidates: 4,
        sampler: SamplerVariant::default().id(),
        identity_payload: 0,
        _pad: 0,
    };
    let selection_params = upload(&mut backend, "selection params", &[selection_params]).unwrap();
    let payloads: Vec<u32> = (0..pixels as u32).map(|p| p ^ 0x55).collect();
    let payloads = upload(&mut backend, "payloads", &payloads).unwrap();
    let blue_noise = upload(&mut backend, "blue noise", &BlueNoiseTables::new().packed()).unwrap();
    let selections = zeroed(&mut backend, "selections", pixels * size_of::<SelectedCandidates>());
    let inputs = strata_tests::resample_inputs(pixels as u32, 0.25);
    let inputs = upload(&mut backend, "resample inputs", &inputs).unwrap();
    let resampled = zeroed(&mut backend, "resampled", pixels * 16);

    let histogram_binds = vec![
        Bind::new(0, histogram_params),
        Bind::new(1, candidate_buffer),
        Bind::new(2, sorted),
        Bind::new(3, spans),
        Bind::new(4, stats),
    ];
    let select_binds = vec![
        Bind::new(0, selection_params),
        Bind::new(1, candidate_buffer),
        Bind::new(2, payloads),
        Bind::new(3, sorted),
        Bind::new(4, spans),
        Bind::new(5, blue_noise),
        Bind::new(6, selections),
    ];
    let resample_binds =
        vec![Bind::new(0, selection_params), Bind::new(1, selections), Bind::new(2, inputs), Bind::new(3, resampled)];
    let pixel_groups = [WIDTH.div_ceil(8), HEIGHT.div_ceil(8), 1];
    let runs = [
        (KernelId::BlockHistogram, &histogram_binds, workgroups),
        (KernelId::BlockHistogramRank, &histogram_binds, workgroups),
        (KernelId::StrataSelect, &select_binds, pixel_groups),
        (KernelId::StrataResample, &resample_binds, pixel_groups),
    ];

    // Paired rounds first: each round times the guarded and the unguarded kernel back to
    // back (in alternating order), so a load that changes during the run (another build
    // on the machine) moves both; the ratio's median and its 10-90 % range over rounds.
    for (id, binds, groups) in runs {
        let guarded = registry.get(id);
        let unguarded = unguarded(guarded);
        let mut ratios = Vec::new();
        for round in 0..PAIRED_ROUNDS {
            let mut time =
                |kernel: &Kernel| backend.dispatch_timed(kernel, binds, groups).expect("dispatch").as_secs_f64();
            let (g, u) = if round % 2 == 0 {
                let g = time(guarded);
                (g, time(&unguarded))
            } else {
                let u = time(&unguarded);
                (time(guarded), u)
            };
            ratios.push(g / u);
        }
        ratios.sort_by(f64::total_cmp);
        let at = |q: f64| ratios[((ratios.len() - 1) as f64 * q).round() as usize];
        eprintln!(
            "paired guarded / unguarded, {}: median {:.3} (10-90 %: {:.3}-{:.3}, {PAIRED_ROUNDS} rounds)",
            guarded.name(),
            at(0.5),
            at(0.1),
            at(0.9)
        );
    }

    let mut group = c.benchmark_group("guards_720p");
    group.sample_size(20).measurement_time(Duration::from_secs(6));
    for (id, binds, groups) in runs {
        let guarded = registry.get(id);
        let unguarded = unguarded(guarded);
        for (label, kernel) in [("guarded", guarded), ("unguarded", &unguarded)] {
            group.bench_function(format!("{}/{label}", guarded.name()), |b| {
                b.iter_custom(|iterations| {
                    (0..iterations).map(|_| backend.dispatch_timed(kernel, binds, groups).expect("dispatch")).sum()
                })
            });
        }
    }
    group.finish();
}

criterion_group!(benches, guards);
criterion_main!(benches);
