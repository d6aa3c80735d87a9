//! `embed`: what the embeddable pass costs an engine per frame, on an engine-owned wgpu
//! device, side by side in one run (wall time of a submission that waits for completion;
//! lavapipe has no concurrent work to hide it behind).
//!
//! * `embed_720p/select_B{4,8,16,32}`: histogram + selection at 1280 × 720 per block size.
//! * `embed_720p/select_resample_B16`: the same plus the resampling pass.
//! * `embed_720p/empty_submit`: an empty submission and wait, the floor of the others.
//! * `embed_build/ash_polyfill`, `embed_build/ash_native`: what making and destroying the
//!   ash flavour's pass costs (its three pipelines and buffers) on a raw Vulkan device,
//!   with `AshDevice::shader_zero_initialize_workgroup_memory` false (the pipelines zero
//!   workgroup memory themselves) and true (the driver does; the device has the feature
//!   enabled), side by side on the same device.
//!
//! Run: `cargo bench -p strata-benches --bench embed`.

use criterion::{Criterion, criterion_group, criterion_main};
use std::time::Duration;
use strata_embed::contract::{ResampleInput, ResampleOutput, SelectedCandidates};
use strata_embed::{SelectionSettings, WgpuBuffers, WgpuResampleBuffers, WgpuSelection};
use wgpu::util::DeviceExt;

const WIDTH: u32 = 1280;
const HEIGHT: u32 = 720;

fn device() -> Option<(wgpu::Device, wgpu::Queue)> {
    let mut descriptor = wgpu::InstanceDescriptor::new_without_display_handle();
    descriptor.backends = wgpu::Backends::VULKAN;
    let instance = wgpu::Instance::new(descriptor);
    let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions::default())).ok()?;
    let descriptor = wgpu::DeviceDescriptor {
        required_features: adapter.features() & wgpu::Features::SUBGROUP,
        required_limits: adapter.limits(),
        ..Default::default()
    };
    pollster::block_on(adapter.request_device(&descriptor)).ok()
}

fn wait(device: &wgpu::Device) {
    device.poll(wgpu::PollType::wait_indefinitely()).expect("poll");
}

fn embed(c: &mut Criterion) {
    let Some((device, queue)) = device() else {
        eprintln!("embed bench: no Vulkan device");
        return;
    };
    let pixels = (WIDTH * HEIGHT) as usize;
    let candidates = strata_benches::engine_candidates(WIDTH, HEIGHT);
    let usage = wgpu::BufferUsages::STORAGE;
    let init =
        |contents: &[u8]| device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: None, contents, usage });
    let candidate_buffer = init(bytemuck::cast_slice(&candidates));
    let selections = init(&vec![0; pixels * size_of::<SelectedCandidates>()]);
    let inputs = vec![
        ResampleInput {
            weights: [1.0; 4],
            targets: [1.0; 4],
            canonical_weight: 1.0,
            canonical_target: 1.0,
            ..Default::default()
        };
        pixels
    ];
    let input_buffer = init(bytemuck::cast_slice(&inputs));
    let outputs = init(&vec![0; pixels * size_of::<ResampleOutput>()]);
    let buffers = WgpuBuffers {
        candidates: (&candidate_buffer).into(),
        payloads: None,
        selections: (&selections).into(),
        resample: Some(WgpuResampleBuffers { inputs: (&input_buffer).into(), outputs: (&outputs).into() }),
    };

    let mut group = c.benchmark_group("embed_720p");
    group.sample_size(20).measurement_time(Duration::from_secs(6));
    group.bench_function("empty_submit", |b| {
        b.iter(|| {
            queue.submit([device.create_command_encoder(&Default::default()).finish()]);
            wait(&device);
        })
    });
    for block_size in [4, 8, 16, 32] {
        let pass = WgpuSelection::new(&device, SelectionSettings { block_size, ..Default::default() }, WIDTH, HEIGHT)
            .expect("pass");
        let bindings = pass.bind(&device, &buffers).expect("bind");
        let mut frame = 0;
        group.bench_function(format!("select_B{block_size}"), |b| {
            b.iter(|| {
                let mut encoder = device.create_command_encoder(&Default::default());
                pass.encode_selection(&queue, &mut encoder, &bindings, frame).expect("encode");
                queue.submit([encoder.finish()]);
                wait(&device);
                frame += 1;
            })
        });
        if block_size == 16 {
            group.bench_function("select_resample_B16", |b| {
                b.iter(|| {
                    let mut encoder = device.create_command_encoder(&Default::default());
                    pass.encode_selection(&queue, &mut encoder, &bindings, frame).expect("encode");
                    pass.encode_resampling(&mut encoder, &bindings).expect("encode");
                    queue.submit([encoder.finish()]);
                    wait(&device);
                    frame += 1;
                })
            });
        }
    }
    group.finish();
}

/// `embed_build`: AshSelection::new + destroy on one device, zeroing workgroup memory in
/// the shaders or leaving it to the driver. Each iteration ends with a submission: lavapipe
/// frees destroyed pipelines only when its queue next does work (RELIABILITY.md).
fn embed_build(c: &mut Criterion) {
    let Some(engine) = strata_tests::AshEngine::open("embed_build bench") else {
        return;
    };
    if !engine.zero_initializes_workgroup_memory {
        eprintln!("embed_build bench: the device cannot zero workgroup memory itself");
        return;
    }
    let mut group = c.benchmark_group("embed_build");
    group.sample_size(10).measurement_time(Duration::from_secs(10));
    for (name, native) in [("ash_polyfill", false), ("ash_native", true)] {
        let vulkan =
            strata_embed::AshDevice { shader_zero_initialize_workgroup_memory: native, ..engine.embed_device() };
        group.bench_function(name, |b| {
            b.iter(|| {
                // SAFETY: the engine's live handles, with shaderZeroInitializeWorkgroupMemory
                // enabled where `native` claims it (checked above); the engine outlives
                // the pass.
                let pass =
                    unsafe { strata_embed::AshSelection::new(vulkan, SelectionSettings::default(), WIDTH, HEIGHT) }
                        .expect("pass");
                // SAFETY: nothing was recorded with the pass.
                unsafe { pass.destroy() };
                engine.submit(|_| {});
            })
        });
    }
    group.finish();
}

criterion_group!(benches, embed, embed_build);
criterion_main!(benches);
