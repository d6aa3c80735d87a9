//! `block_sort`: the block-histogram kernel on wgpu (lavapipe here) against native Rust
//! per-block sorting of the same 1M candidates at B = 16.
//!
//! * `native_sort_unstable_by`: `sort_unstable_by_key` of each block's pixel indices by
//!   (object id, canonical key, pixel): the sort alone, one thread.
//! * `native_reference`: the whole Rust reference (sort, spans, counters), one thread.
//! * `wgpu_portable`, `wgpu_subgroup`: the kernel's device time per dispatch from
//!   timestamp queries (candidates already uploaded; outputs left on the device).
//! * `wgpu_rank`: the `block_histogram_rank` kernel (same outputs, positions by counting),
//!   same measure.
//!
//! Run: `cargo bench -p strata-benches --bench block_sort`.

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use std::time::Duration;
use strata_benches::benchmark_candidates;
use strata_kernels::BlockGrid;
use strata_kernels::reference::block_histogram::{block_histogram, sort_block};
use strata_render::histogram_pass::{BlockHistogramPass, HistogramVariant};

fn block_sort(c: &mut Criterion) {
    let (width, height, candidates) = benchmark_candidates();
    let grid = BlockGrid::new(width, height, 16).expect("valid grid");
    let mut group = c.benchmark_group("block_sort_1M_B16");
    group.sample_size(10).measurement_time(Duration::from_secs(10));

    let mut entries = vec![0u32; grid.pixel_count()];
    group.bench_function("native_sort_unstable_by", |b| {
        b.iter(|| {
            for block in 0..grid.block_count() {
                let rect = grid.block(block);
                let slice = &mut entries[rect.base as usize..(rect.base + rect.len()) as usize];
                for (local, entry) in slice.iter_mut().enumerate() {
                    *entry = rect.pixel(width, local as u32);
                }
                sort_block(&candidates, slice);
            }
            black_box(&entries);
        })
    });
    group.bench_function("native_reference", |b| b.iter(|| black_box(block_histogram(grid, &candidates))));

    let Some(mut backend) = strata_benches::open_wgpu("wgpu benchmarks") else { return };
    for (name, variant) in [
        ("wgpu_portable", HistogramVariant::Portable),
        ("wgpu_subgroup", HistogramVariant::Subgroup),
        ("wgpu_rank", HistogramVariant::Rank),
    ] {
        let pass = match BlockHistogramPass::new(&mut backend, variant, grid) {
            Ok(pass) => pass,
            Err(error) => {
                eprintln!("{name} skipped: {error}");
                continue;
            }
        };
        pass.upload_candidates(&mut backend, &candidates).expect("upload");
        group.bench_function(name, |b| {
            b.iter_custom(|iterations| {
                (0..iterations).map(|_| pass.dispatch_timed(&mut backend).expect("dispatch")).sum()
            })
        });
        pass.destroy(&mut backend).expect("destroy");
    }
    group.finish();
}

criterion_group!(benches, block_sort);
criterion_main!(benches);
