//! `render`: the path tracer and the ReSTIR frame, side by side in one run.
//!
//! * `path_trace_512/{wgpu}`: one 1-sample frame of the default scene at 512 x 512 on
//!   lavapipe (device time from timestamp queries).
//! * `path_trace_128/{wgpu,interpreter}`: the same frame at 128 x 128 on lavapipe and on
//!   the CPU interpreter (wall time: the interpreter has no timestamps), for their ratio.
//! * `restir_frame_256/{method}`: one ReSTIR frame at 256 x 256 (all five passes, device
//!   time summed), strata against the two baselines; each pass's mean time over the
//!   benchmark's frames is printed to stderr.
//! * `histogram_share_256/B{4,8,16,32}`: strata frames at each block size; the histogram
//!   pass's share of the frame is printed to stderr (criterion measures the whole frame).
//! * `histogram_share_simt_256/B{4,8,16,32}`: the same frames on the CPU interpreter
//!   (wall time); printed: the histogram's share of the frame in the issue slots of a
//!   32-wide SIMT GPU (`strata_backends::cpu_backend::DispatchCounts`), a device-neutral
//!   estimate of its share on a GPU, for ranking and for the subgroup network.
//!
//! Run: `cargo bench -p strata-benches --bench render`.

use criterion::{Criterion, criterion_group, criterion_main};
use std::time::Duration;
use strata_backends::Backend;
use strata_backends::cpu_backend::{CpuBackend, CpuOptions, DispatchCounts, WARP_WIDTH};
use strata_benches::PassTimes;
use strata_kernels::selection::SelectionSettings;
use strata_kernels::{BlockGrid, Executor, KernelId};
use strata_render::histogram_pass::{BlockHistogramPass, HistogramVariant};
use strata_render::render::{GpuScene, PathTracer, RenderSettings};
use strata_render::restir::{Method, RestirRenderer, RestirSettings, ReuseOrder, Shading};
use strata_render::scene::{Scene, default_scene};
use strata_render::synthetic::{CandidateMix, candidate_image};

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
    // The frames' times are their passes' timestamps: zero on a device without them, and
    // criterion's warm-up would then wait forever.
    if !backend.info().timestamps {
        eprintln!("restir_frame_256 and histogram_share_256 skipped: the device has no timestamp queries");
        return;
    }
    let scene = default_scene();
    let gpu_scene = GpuScene::build(&scene).expect("default scene");
    let render = settings(&scene, 256);
    let mut group = c.benchmark_group("restir_frame_256");
    group.sample_size(10).measurement_time(Duration::from_secs(10));
    // Every method with each shading of the resampled part (`expectation`: no shadow ray
    // in the shading pass, a few more BSDF evaluations in select and temporal).
    // And with expectation shading in the temporal-first order (two more passes:
    // `restir_reservoir_keys` and `restir_spatial`; select then runs with K = 0).
    let spatial_first = [Shading::Sample, Shading::Expectation].into_iter().flat_map(|shading| {
        [Method::Strata, Method::Restir, Method::RestirDisc].map(|method| (method, shading, ReuseOrder::SpatialFirst))
    });
    let temporal_first = [Method::Strata, Method::Restir, Method::RestirDisc]
        .map(|method| (method, Shading::Expectation, ReuseOrder::TemporalFirst));
    // And plain per-pixel RIS, the equal-time baseline (no reuse: its frames run the
    // paper's passes without temporal reuse and no histogram, whatever the order).
    let ris = [(Method::Ris, Shading::Expectation, ReuseOrder::SpatialFirst)];
    for (method, shading, reuse_order) in spatial_first.chain(temporal_first).chain(ris) {
        let restir = RestirSettings { method, shading, reuse_order, ..RestirSettings::default() };
        let mut renderer = RestirRenderer::new(backend, &gpu_scene, &render, restir, scene.extent()).expect("renderer");
        renderer.set_timed(true);
        // The first frame builds the pipelines (seconds on a GPU driver); inside criterion's
        // warm-up it leaves the GPU idle and too few frames to bring its clocks back up.
        renderer.render_frame(backend, None).expect("first frame");
        let name = match (shading, reuse_order) {
            (Shading::Sample, _) => method.name().to_string(),
            (Shading::Expectation, ReuseOrder::SpatialFirst) => format!("{}/expectation", method.name()),
            (Shading::Expectation, ReuseOrder::TemporalFirst) => {
                format!("{}/expectation/temporal-first", method.name())
            }
            (Shading::Expectation, ReuseOrder::Auto) => unreachable!("the bench names each order it runs"),
        };
        let mut passes = PassTimes::default();
        group.bench_function(&name, |b| {
            b.iter_custom(|n| {
                (0..n).map(|_| passes.add(renderer.render_frame(backend, None).expect("frame").1.pass_times)).sum()
            })
        });
        passes.print(&name);
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
        renderer.render_frame(backend, None).expect("first frame");
        let mut passes = PassTimes::default();
        group.bench_function(format!("B{block_size}"), |b| {
            b.iter_custom(|n| {
                (0..n).map(|_| passes.add(renderer.render_frame(backend, None).expect("frame").1.pass_times)).sum()
            })
        });
        passes.print(&format!("B{block_size}"));
        renderer.destroy(backend).expect("destroy");
    }
    group.finish();
}

/// The histogram's share of a strata frame in SIMT issue slots (see the module doc).
/// The interpreter's renderer runs the histogram network (its own fastest choice);
/// ranking and the subgroup network are counted on a generated 256² candidate image of
/// the same grid, and the network on that image is printed beside the frame's own
/// network count, to show how far the generated input stands in for the frame's.
fn histogram_share_simt(c: &mut Criterion) {
    let scene = default_scene();
    let gpu_scene = GpuScene::build(&scene).expect("default scene");
    let render = settings(&scene, 256);
    let mut cpu =
        CpuBackend::new(CpuOptions { subgroup_size: Some(WARP_WIDTH), ..CpuOptions::default() }).expect("interpreter");
    let is_histogram = |id: &KernelId| {
        matches!(id, KernelId::BlockHistogram | KernelId::BlockHistogramSubgroup | KernelId::BlockHistogramRank)
    };
    let mut group = c.benchmark_group("histogram_share_simt_256");
    group.sample_size(10).sampling_mode(criterion::SamplingMode::Flat).measurement_time(Duration::from_secs(20));
    for block_size in [4, 8, 16, 32] {
        let selection = SelectionSettings { block_size, ..SelectionSettings::default() };
        let restir = RestirSettings { selection, ..RestirSettings::default() };
        // Made on first use, so that a filter leaving this block size out renders nothing.
        let mut running: Option<(RestirRenderer, u64)> = None;
        group.bench_function(format!("B{block_size}"), |b| {
            let (renderer, frames) = running.get_or_insert_with(|| {
                let mut renderer =
                    RestirRenderer::new(&mut cpu, &gpu_scene, &render, restir, scene.extent()).expect("renderer");
                // The first frame has no history to merge: count from the second on.
                renderer.render_frame(&mut cpu, None).expect("frame");
                cpu.take_counts_by_kernel();
                (renderer, 0)
            });
            b.iter(|| {
                *frames += 1;
                renderer.render_frame(&mut cpu, None).expect("frame")
            })
        });
        let Some((renderer, frames)) = running else { continue };
        renderer.destroy(&mut cpu).expect("destroy");
        let counts = cpu.take_counts_by_kernel();
        if frames == 0 {
            continue;
        }
        let rest: DispatchCounts = counts.iter().filter(|(id, _)| !is_histogram(id)).map(|(_, c)| *c).sum();
        let network_in_frame: DispatchCounts = counts.iter().filter(|(id, _)| is_histogram(id)).map(|(_, c)| *c).sum();
        let grid = BlockGrid::new(256, 256, block_size).expect("grid");
        let candidates = candidate_image(256, 256, 7, CandidateMix::default());
        let mut standalone = |variant: HistogramVariant| {
            let pass = BlockHistogramPass::with_masking(&mut cpu, variant, grid, selection.masking).expect("pass");
            pass.upload_candidates(&mut cpu, &candidates).expect("upload");
            pass.dispatch(&mut cpu).expect("dispatch");
            pass.destroy(&mut cpu).expect("destroy");
            cpu.take_counts_by_kernel().into_values().sum::<DispatchCounts>()
        };
        // Both kernels a GPU might run, whichever `KernelId::fastest_histogram` picks.
        let rank_alone = standalone(HistogramVariant::Rank).warp_issues as f64;
        let network_alone = standalone(HistogramVariant::Subgroup).warp_issues as f64;
        let per_frame = |n: u64| n as f64 / frames as f64;
        // A histogram kernel's share of a frame made of it and the rest of the frame.
        let histogram_share = |issues: f64| 100.0 * issues / (issues + per_frame(rest.warp_issues));
        eprintln!(
            "B{block_size}: histogram share of a frame's warp issues: ranking {:.1} % ({rank_alone:.3e}), \
             the subgroup network {:.1} % ({network_alone:.3e} on the generated image, {:.3e} in the frame); \
             a GPU runs {:?}",
            histogram_share(rank_alone),
            histogram_share(network_alone),
            per_frame(network_in_frame.warp_issues),
            KernelId::fastest_histogram(block_size, true, Executor::Gpu),
        );
        // The other passes' shares of a frame with the network.
        let frame = network_alone + per_frame(rest.warp_issues);
        let share = |issues: f64| 100.0 * issues / frame;
        let mut passes: Vec<_> = counts.iter().filter(|(id, _)| !is_histogram(id)).collect();
        passes.sort_by_key(|(id, _)| format!("{id:?}"));
        for (id, count) in passes {
            eprintln!("  {id:?}: {:.1} %", share(per_frame(count.warp_issues)));
        }
    }
    group.finish();
}

fn render(c: &mut Criterion) {
    histogram_share_simt(c);
    let Some(mut wgpu) = strata_benches::open_wgpu("render benchmarks") else { return };
    path_trace(c, "wgpu", &mut wgpu, 512);
    path_trace(c, "wgpu", &mut wgpu, 128);
    let mut interpreter = CpuBackend::new(CpuOptions::default()).expect("interpreter");
    path_trace(c, "interpreter", &mut interpreter, 128);
    restir_frames(c, &mut wgpu);
}

criterion_group!(benches, render);
criterion_main!(benches);
