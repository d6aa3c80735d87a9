//! `backends`: the same passes on wgpu and on ash, side by side in one run.
//!
//! * `histogram_portable`, `histogram_subgroup`: the block-histogram kernel on 1M
//!   candidates at B = 16, device time per dispatch from timestamp queries.
//! * `empty_device`: the empty kernel (one workgroup), device time: the GPU-side cost of a
//!   pass.
//! * `empty_wall`: the empty kernel, wall time of a timed dispatch including submission,
//!   waiting and reading the timestamps back: the host-side cost of a pass.
//!
//! Run: `cargo bench -p strata-benches --bench backends`.

use criterion::{Criterion, criterion_group, criterion_main};
use std::time::Duration;
use strata_backends::ash_backend::{AshBackend, AshOptions};
use strata_backends::wgpu_backend::{WgpuBackend, WgpuOptions};
use strata_backends::{Backend, BackendError, Bind};
use strata_benches::benchmark_candidates;
use strata_kernels::{BlockGrid, KernelId, Registry};
use strata_render::histogram_pass::{BlockHistogramPass, HistogramVariant};

/// A backend opened without API validation (it would distort timings), or why not.
type Opened = Result<Box<dyn Backend>, BackendError>;

fn backends() -> Vec<(&'static str, Opened)> {
    vec![
        ("wgpu", WgpuBackend::new(WgpuOptions::default()).map(|b| Box::new(b) as Box<dyn Backend>)),
        ("ash", AshBackend::new(AshOptions::default()).map(|b| Box::new(b) as Box<dyn Backend>)),
    ]
}

fn device_time(
    b: &mut criterion::Bencher<'_>,
    backend: &mut dyn Backend,
    mut dispatch: impl FnMut(&mut dyn Backend) -> Duration,
) {
    b.iter_custom(|iterations| (0..iterations).map(|_| dispatch(&mut *backend)).sum());
}

fn compare_backends(c: &mut Criterion) {
    let (width, height, candidates) = benchmark_candidates();
    let grid = BlockGrid::new(width, height, 16).expect("valid grid");
    let empty = Registry::shared().expect("registry").get(KernelId::Empty);
    let mut group = c.benchmark_group("backends");
    group.sample_size(10).measurement_time(Duration::from_secs(8));
    for (name, backend) in backends() {
        let mut backend = match backend {
            Ok(backend) => backend,
            Err(error) => {
                eprintln!("{name} skipped: {error}");
                continue;
            }
        };
        eprintln!("{name}: {}", backend.info().summary());
        for (label, variant) in
            [("histogram_portable", HistogramVariant::Portable), ("histogram_subgroup", HistogramVariant::Subgroup)]
        {
            let Ok(pass) = BlockHistogramPass::new(backend.as_mut(), variant, grid) else {
                eprintln!("{name}/{label} skipped: unsupported");
                continue;
            };
            pass.upload_candidates(backend.as_mut(), &candidates).expect("upload");
            group.bench_function(format!("{label}/{name}"), |b| {
                device_time(b, backend.as_mut(), |backend| pass.dispatch_timed(backend).expect("dispatch"))
            });
            pass.destroy(backend.as_mut()).expect("destroy");
        }
        let sink = backend.create_buffer("sink", 256).expect("buffer");
        let binds = [Bind::new(0, sink)];
        group.bench_function(format!("empty_device/{name}"), |b| {
            device_time(b, backend.as_mut(), |backend| {
                backend.dispatch_timed(empty, &binds, [1, 1, 1]).expect("dispatch")
            })
        });
        group.bench_function(format!("empty_wall/{name}"), |b| {
            b.iter(|| backend.dispatch_timed(empty, &binds, [1, 1, 1]).expect("dispatch"))
        });
        backend.destroy_buffer(sink).expect("destroy");
    }
    group.finish();
}

criterion_group!(benches, compare_backends);
criterion_main!(benches);
