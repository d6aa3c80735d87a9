//! `interpreter`: the CPU interpreter of naga IR against lavapipe on the same kernel and
//! input, side by side in one run, and its cost per executed IR expression.
//!
//! * `histogram_128x128/cpu`, `histogram_128x128/wgpu`: the subgroup histogram kernel on
//!   128 × 128 generated candidates at B = 16, wall time of a dispatch that waits for
//!   completion (`dispatch_timed`), same subgroup size 8 on both.
//!
//! Run: `cargo bench -p strata-benches --bench interpreter`.

use criterion::{Criterion, criterion_group, criterion_main};
use std::time::{Duration, Instant};
use strata_backends::cpu_backend::{CpuBackend, CpuOptions};
use strata_kernels::BlockGrid;
use strata_render::histogram_pass::{BlockHistogramPass, HistogramVariant};
use strata_render::synthetic::{CandidateMix, candidate_image};

fn interpreter(c: &mut Criterion) {
    let grid = BlockGrid::new(128, 128, 16).expect("valid grid");
    let candidates = candidate_image(128, 128, 7, CandidateMix::default());
    let mut group = c.benchmark_group("interpreter");
    group.sample_size(10).measurement_time(Duration::from_secs(8));

    let mut cpu = CpuBackend::new(CpuOptions { subgroup_size: Some(8), ..CpuOptions::default() }).expect("interpreter");
    let pass = BlockHistogramPass::new(&mut cpu, HistogramVariant::Subgroup, grid).expect("pass");
    pass.upload_candidates(&mut cpu, &candidates).expect("upload");
    let started = Instant::now();
    pass.dispatch(&mut cpu).expect("dispatch");
    let elapsed = started.elapsed();
    let instructions = cpu.instructions_in_last_dispatch();
    eprintln!(
        "cpu: {instructions} bytecode instructions in {:.1} ms: {:.1} ns per instruction (2 threads)",
        elapsed.as_secs_f64() * 1e3,
        elapsed.as_secs_f64() * 1e9 / instructions as f64
    );
    group.bench_function("histogram_128x128/cpu", |b| b.iter(|| pass.dispatch_timed(&mut cpu).expect("dispatch")));

    if let Some(mut wgpu) = strata_benches::open_wgpu("wgpu") {
        let pass = BlockHistogramPass::new(&mut wgpu, HistogramVariant::Subgroup, grid).expect("pass");
        pass.upload_candidates(&mut wgpu, &candidates).expect("upload");
        group
            .bench_function("histogram_128x128/wgpu", |b| b.iter(|| pass.dispatch_timed(&mut wgpu).expect("dispatch")));
    }
    group.finish();
}

criterion_group!(benches, interpreter);
criterion_main!(benches);
