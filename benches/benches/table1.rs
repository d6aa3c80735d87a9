//! `table1`: the paper's Table 1 on the device at hand: the histogram pass's share of a
//! strata frame at 1920 × 1080 with 16 × 16 blocks (the paper gives 3-7 % on GPUs; the
//! project's target is at most 2 %), and every method's frame time at that size.
//!
//! * `table1_1920x1080/{strata,restir,restir-disc,ris}`: one ReSTIR frame of the default
//!   scene with the default settings (16 × 16 blocks, temporal reuse, the default order and
//!   histogram kernel for the device), device time of all its passes from timestamp
//!   queries; each pass's mean time and share of the frame is printed to stderr, and for
//!   strata a `table1:` line with the histogram's share.
//!
//! Meant for a GPU (`benchmarks/device/table1.sh` runs the built executable on a lent
//! machine; docs/benchmarks/render.md, "Table 1 on a GPU"). On lavapipe a 1080p frame
//! takes seconds: `STRATA_TABLE1_SIZE=WxH` (e.g. `160x90`) runs the same at another size.
//!
//! Run: `cargo bench -p strata-benches --bench table1`.

use criterion::{Criterion, criterion_group, criterion_main};
use std::time::Duration;
use strata_backends::Backend;
use strata_backends::wgpu_backend::{WgpuBackend, WgpuOptions};
use strata_benches::PassTimes;
use strata_render::render::{GpuScene, RenderSettings};
use strata_render::restir::{Method, RestirRenderer, RestirSettings};
use strata_render::scene::default_scene;

/// The image size: the paper's 1920 × 1080, or `STRATA_TABLE1_SIZE` (`WxH`); `Err` names
/// the value that is not a size.
fn image_size() -> Result<(u32, u32), String> {
    let Ok(value) = std::env::var("STRATA_TABLE1_SIZE") else { return Ok((1920, 1080)) };
    let parsed = value.split_once('x').and_then(|(w, h)| Some((w.parse::<u32>().ok()?, h.parse::<u32>().ok()?)));
    match parsed {
        Some((w, h)) if (1..=8192).contains(&w) && (1..=8192).contains(&h) => Ok((w, h)),
        _ => Err(format!("STRATA_TABLE1_SIZE={value}: not WIDTHxHEIGHT with each 1 to 8192")),
    }
}

fn table1(c: &mut Criterion) {
    let (width, height) = match image_size() {
        Ok(size) => size,
        Err(error) => {
            eprintln!("table1: {error}");
            std::process::exit(2);
        }
    };
    let mut backend = match WgpuBackend::new(WgpuOptions::default()) {
        Ok(backend) => backend,
        Err(error) => {
            eprintln!("table1 skipped: {error}");
            return;
        }
    };
    eprintln!("device: {}", backend.info().summary());
    let scene = default_scene();
    let gpu_scene = GpuScene::build(&scene).expect("default scene");
    let render = RenderSettings::for_scene(&scene, width, height, 1);
    let mut group = c.benchmark_group(format!("table1_{width}x{height}"));
    group.sample_size(10).measurement_time(Duration::from_secs(5));
    for method in [Method::Strata, Method::Restir, Method::RestirDisc, Method::Ris] {
        let restir = RestirSettings { method, ..RestirSettings::default() };
        let mut renderer = RestirRenderer::new(&mut backend, &gpu_scene, &render, restir, scene.extent())
            .unwrap_or_else(|e| panic!("{}: {e}", method.name()));
        renderer.set_timed(true);
        // The first frame builds the pipelines and merges nothing temporally: outside the
        // measurement (as in the render bench).
        renderer.render_frame(&mut backend, None).expect("first frame");
        let mut passes = PassTimes::default();
        group.bench_function(method.name(), |b| {
            b.iter_custom(|n| {
                (0..n).map(|_| passes.add(renderer.render_frame(&mut backend, None).expect("frame").1.pass_times)).sum()
            })
        });
        passes.print(method.name());
        if method == Method::Strata
            && let Some(share) = passes.share(1)
        {
            eprintln!(
                "table1: {width}x{height}, blocks of {}: the histogram pass is {share:.2} % of strata's frame \
                 (paper, Table 1: 3-7 % on GPUs; target at most 2 %)",
                restir.selection.block_size
            );
        }
        renderer.destroy(&mut backend).expect("destroy");
    }
    group.finish();
}

criterion_group!(benches, table1);
criterion_main!(benches);
