//! `denoise`: what SVGF costs beside the frame it filters, side by side in one run.
//!
//! * `svgf_256/wgpu`: the four SVGF passes (temporal, variance, five à-trous levels,
//!   modulation) on a 256 x 256 ReSTIR frame of the default scene, device time from
//!   timestamp queries on lavapipe (or the device wgpu opens).
//! * `svgf_256/frame`: the ReSTIR frame it filters (strata, its five passes; the guide
//!   pass is not timed), the same way, for the ratio.
//!
//! Run: `cargo bench -p strata-benches --bench denoise`.

use criterion::{Criterion, criterion_group, criterion_main};
use std::time::Duration;
use strata_backends::Backend;
use strata_render::denoise::{SvgfDenoiser, SvgfSettings};
use strata_render::render::{GpuScene, RenderSettings};
use strata_render::restir::{RestirRenderer, RestirSettings};
use strata_render::scene::default_scene;

fn svgf(c: &mut Criterion) {
    let Some(mut backend) = strata_benches::open_wgpu("denoise") else { return };
    let backend: &mut dyn Backend = &mut backend;
    let scene = default_scene();
    let gpu_scene = GpuScene::build(&scene).expect("default scene");
    let render = RenderSettings::for_scene(&scene, 256, 256, 1);
    let mut renderer =
        RestirRenderer::new(backend, &gpu_scene, &render, RestirSettings::default(), scene.extent()).expect("renderer");
    renderer.enable_guides(backend).expect("guides");
    renderer.set_timed(true);
    let mut denoiser = SvgfDenoiser::new(backend, 256, 256, SvgfSettings::default()).expect("denoiser");
    denoiser.set_timed(true);
    // The first frame builds the pipelines.
    renderer.render_frame(backend, None).expect("first frame");
    let mut group = c.benchmark_group("svgf_256");
    group.sample_size(10).measurement_time(Duration::from_secs(10));
    group.bench_function("frame", |b| {
        b.iter_custom(|n| {
            (0..n)
                .map(|_| renderer.render_frame(backend, None).expect("frame").1.pass_times.iter().sum::<Duration>())
                .sum()
        })
    });
    let inputs = renderer.denoiser_inputs().expect("a frame with guides");
    group.bench_function("wgpu", |b| {
        b.iter_custom(|n| {
            (0..n)
                .map(|_| {
                    denoiser.denoise(backend, inputs.colour, inputs.guides, inputs.previous_guides).expect("denoise");
                    denoiser.last_time()
                })
                .sum()
        })
    });
    group.finish();
    denoiser.destroy(backend).expect("destroy");
    renderer.destroy(backend).expect("destroy");
}

criterion_group!(benches, svgf);
criterion_main!(benches);
