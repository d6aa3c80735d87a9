//! `render`: the path tracer and the ReSTIR frame, side by side in one run.
//!
//! * `path_trace_512/{wgpu}`: one 1-sample frame of the default scene at 512 x 512 on
//!   lavapipe (device time from timestamp queries).
//! * `path_trace_128/{wgpu,interpreter}`: the same frame at 128 x 128 on lavapipe and on
//!   the CPU interpreter (wall time: the interpreter has no timestamps), for their ratio.
//! * `restir_frame_256/{method}`: one ReSTIR frame at 256 x 256 (all five passes, device
//!   time summed), strata against the two baselines.
//! * `histogram_share_256/B{4,8,16,32}`: strata frames at each block size; the histogram
//!   pass's share of the frame is printed to stderr (criterion measures the whole frame).
//!
//! Run: `cargo bench -p strata-benches --bench render`.

use criterion::{Criterion, criterion_group, criterion_main};
use std::time::Duration;
use strata::render::{GpuScene, PathTracer, RenderSettings};
use strata::restir::{Method, RestirRenderer, RestirSettings, Shading};
use strata::scene::{Scene, default_scene};
use strata_backends::Backend;
use strata_backends::cpu_backend::{CpuBackend, CpuOptions};
use strata_backends::wgpu_backend::{WgpuBackend, WgpuOptions};
use strata_kernels::selection::SelectionSettings;

fn settings(scene: &Scene, size: u32) -> RenderSettings {
    RenderSettings::for_scene(scene, size, size, 1)
}

fn path_trace(c: &mut Criterion, name: &str, backend: &mut dyn Backend, size: u32) {
    let scene = default_scene();
    let gpu_scene = GpuScene::build(&scene).expect("default scene");
    let mut tracer = PathTracer::new(backend, &gpu_scene, &settings(&scene, size)).expect("path tracer");
    let mut group = c.benchmark_group(format!("path_trace_{size}"));
    group.sample_size(10).measurement_time(Duration::from_secs(10));
    group.bench_function(name, |b| {
        b.iter_custom(|n| (0..n).map(|_| tracer.add_sample_timed(backend).expect("frame")).sum())
    });
    group.finish();
    tracer.destroy(backend).expect("destroy");
}

fn restir_frames(c: &mut Criterion, backend: &mut dyn Backend) {
    let scene = default_scene();
    let gpu_scene = GpuScene::build(&scene).expect("default scene");
    let render = settings(&scene, 256);
    let mut group = c.benchmark_group("restir_frame_256");
    group.sample_size(10).measurement_time(Duration::from_secs(10));
    // Every method with each shading of the resampled part (`expectation`: no shadow ray
    // in the shading pass, a few more BSDF evaluations in select and temporal).
    let runs = [Shading::Sample, Shading::Expectation]
        .into_iter()
        .flat_map(|shading| [Method::Strata, Method::Restir, Method::RestirDisc].map(|method| (method, shading)));
    for (method, shading) in runs {
        let restir = RestirSettings { method, shading, ..RestirSettings::default() };
        let mut renderer = RestirRenderer::new(backend, &gpu_scene, &render, restir, scene.extent()).expect("renderer");
        renderer.set_timed(true);
        let name = match shading {
            Shading::Sample => method.name().to_string(),
            Shading::Expectation => format!("{}/expectation", method.name()),
        };
        group.bench_function(name, |b| {
            b.iter_custom(|n| {
                (0..n)
                    .map(|_| renderer.render_frame(backend, None).expect("frame").1.pass_times.iter().sum::<Duration>())
                    .sum()
            })
        });
        renderer.destroy(backend).expect("destroy");
    }
    group.finish();
    let mut group = c.benchmark_group("histogram_share_256");
    group.sample_size(10).measurement_time(Duration::from_secs(10));
    for block_size in [4, 8, 16, 32] {
        let selection = SelectionSettings { block_size, ..SelectionSettings::default() };
        let restir = RestirSettings { selection, ..RestirSettings::default() };
        let mut renderer = RestirRenderer::new(backend, &gpu_scene, &render, restir, scene.extent()).expect("renderer");
        renderer.set_timed(true);
        let mut passes = [Duration::ZERO; 5];
        group.bench_function(format!("B{block_size}"), |b| {
            b.iter_custom(|n| {
                (0..n)
                    .map(|_| {
                        let times = renderer.render_frame(backend, None).expect("frame").1.pass_times;
                        for (total, t) in passes.iter_mut().zip(times) {
                            *total += t;
                        }
                        times.iter().sum::<Duration>()
                    })
                    .sum()
            })
        });
        let total: Duration = passes.iter().sum();
        // Nothing ran when a filter left this block size out.
        if !total.is_zero() {
            eprintln!(
                "B{block_size}: histogram {:.1} % of the frame's device time (candidates {:.1} %, select {:.1} %, \
             temporal {:.1} %, shade {:.1} %)",
                100.0 * passes[1].as_secs_f64() / total.as_secs_f64(),
                100.0 * passes[0].as_secs_f64() / total.as_secs_f64(),
                100.0 * passes[2].as_secs_f64() / total.as_secs_f64(),
                100.0 * passes[3].as_secs_f64() / total.as_secs_f64(),
                100.0 * passes[4].as_secs_f64() / total.as_secs_f64(),
            );
        }
        renderer.destroy(backend).expect("destroy");
    }
    group.finish();
}

fn render(c: &mut Criterion) {
    let mut wgpu = match WgpuBackend::new(WgpuOptions::default()) {
        Ok(backend) => backend,
        Err(error) => {
            eprintln!("render benchmarks skipped: {error}");
            return;
        }
    };
    eprintln!("wgpu: {}", wgpu.info().summary());
    path_trace(c, "wgpu", &mut wgpu, 512);
    path_trace(c, "wgpu", &mut wgpu, 128);
    let mut interpreter = CpuBackend::new(CpuOptions::default()).expect("interpreter");
    path_trace(c, "interpreter", &mut interpreter, 128);
    restir_frames(c, &mut wgpu);
}

criterion_group!(benches, render);
criterion_main!(benches);
