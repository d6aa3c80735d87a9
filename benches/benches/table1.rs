//! `table1`: the paper's Table 1 on the device at hand: the histogram pass's share of a
//! strata frame at 1920 × 1080 with 16 × 16 blocks (the paper gives 3-7 % on GPUs; the
//! project's target is at most 2 %), and every method's frame time at that size.
//!
//! * `table1_1920x1080/strata/spatial-first`: one frame of the default scene in the
//!   paper's order (spatial reuse, then the temporal merge), every other setting its
//!   default (16 × 16 blocks, temporal reuse, the device's own histogram kernel). Its
//!   histogram pass is the sort alone, so its share of this frame is the Table 1 number:
//!   printed on a `table1:` line.
//! * `table1_1920x1080/{strata,restir,restir-disc,ris}`: one frame with every default,
//!   the order included (a still camera: temporal-first, whose histogram entry also holds
//!   the `restir_reservoir_keys` pass).
//!
//! Each is the device time of all the frame's passes from timestamp queries, the first
//! frame (pipelines, no temporal merge) outside the measurement; each pass's mean time and
//! share are printed to stderr. With the default settings no temporal histogram runs
//! (`temporal_candidates` 0), so no histogram work hides in the temporal pass.
//!
//! Meant for a GPU (`benchmarks/device/table1.sh` runs the built executable on a lent
//! machine; docs/benchmarks/render.md, "Table 1 on a GPU"). On lavapipe a 1080p frame
//! takes seconds: `STRATA_TABLE1_SIZE=WxH` (e.g. `160x90`) runs the same at another size.
//! A device without timestamp queries is skipped (criterion would wait forever on frames
//! that take no time).
//!
//! Run: `cargo bench -p strata-benches --bench table1`.

use criterion::{Criterion, criterion_group, criterion_main};
use std::time::Duration;
use strata_backends::Backend;
use strata_benches::PassTimes;
use strata_render::render::{GpuScene, RenderSettings};
use strata_render::restir::{Method, RestirRenderer, RestirSettings, ReuseOrder};
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
    let Some(mut backend) = strata_benches::open_wgpu("table1") else { return };
    if !backend.info().timestamps {
        eprintln!("table1 skipped: the device has no timestamp queries");
        return;
    }
    let scene = default_scene();
    let gpu_scene = GpuScene::build(&scene).expect("default scene");
    let render = RenderSettings::for_scene(&scene, width, height, 1);
    let mut group = c.benchmark_group(format!("table1_{width}x{height}"));
    group.sample_size(10).measurement_time(Duration::from_secs(5));
    let runs = [
        (Method::Strata, ReuseOrder::SpatialFirst),
        (Method::Strata, ReuseOrder::Auto),
        (Method::Restir, ReuseOrder::Auto),
        (Method::RestirDisc, ReuseOrder::Auto),
        (Method::Ris, ReuseOrder::Auto),
    ];
    for (method, reuse_order) in runs {
        let restir = RestirSettings { method, reuse_order, ..RestirSettings::default() };
        let name = match reuse_order {
            ReuseOrder::Auto => method.name().to_string(),
            order => format!("{}/{}", method.name(), order.name()),
        };
        // The first frame builds the pipelines and merges nothing temporally: outside the
        // measurement (as in the render bench). A device too small for the size (lavapipe
        // binds at most 128 MiB, a 1080p G-buffer takes 190 MiB) is a line, not a panic.
        let made = RestirRenderer::new(&mut backend, &gpu_scene, &render, restir, scene.extent()).and_then(|mut r| {
            r.set_timed(true);
            r.render_frame(&mut backend, None).map(|_| r)
        });
        let mut renderer = made.unwrap_or_else(|error| {
            eprintln!("table1: {name} at {width}x{height}: {error} (STRATA_TABLE1_SIZE sets another size)");
            std::process::exit(1);
        });
        let mut passes = PassTimes::default();
        group.bench_function(&name, |b| {
            b.iter_custom(|n| {
                (0..n).map(|_| passes.add(renderer.render_frame(&mut backend, None).expect("frame").1.pass_times)).sum()
            })
        });
        passes.print(&name);
        if reuse_order == ReuseOrder::SpatialFirst
            && let Some(share) = passes.share(1)
        {
            eprintln!(
                "table1: {width}x{height}, blocks of {}, the paper's order: the histogram pass is {share:.2} % of \
                 strata's frame (paper, Table 1: 3-7 % on GPUs; target at most 2 %)",
                restir.selection.block_size
            );
        }
        renderer.destroy(&mut backend).expect("destroy");
    }
    group.finish();
}

criterion_group!(benches, table1);
criterion_main!(benches);
