//! `memory_reads`: what one vec4 read costs a kernel on this device, by the memory it reads
//! from (a storage buffer, a uniform buffer, a texture, workgroup memory) and by whether the
//! lanes read different entries or the same one. Each entry point of
//! `benches/kernels/memory_reads.wgsl` runs the same 64 dependent steps per invocation over
//! 65 536 invocations; `no_reads` is the steps without the reads (and `workgroup_fill` the
//! workgroup entry points' copy of the table), so each row less that one is the reads' cost:
//! 4 194 304 reads of a vec4 per dispatch. Device time per dispatch from timestamp queries.
//!
//! Why: on lavapipe the kernels that trace rays spend much of their time reading BVH nodes
//! and triangles from the scene's storage buffer, and a CPU driver prices reads unlike a GPU
//! (docs/benchmarks/ci-time.md, twelfth section).
//!
//! Run: `cargo bench -p strata-benches --bench memory_reads`.

use criterion::{Criterion, criterion_group, criterion_main};
use std::time::Duration;
use strata_backends::texture::TextureDesc;
use strata_backends::{Backend, Bind};
use strata_kernels::Kernel;
use strata_kernels::texture::{TexelFormat, TextureDimension};

/// The kernels, read from the file at compile time.
const SOURCE: &str = include_str!("../kernels/memory_reads.wgsl");

/// Entries of the table (4096 vec4<u32>: 64 KiB, the most a uniform binding may hold).
const ENTRIES: u32 = 4096;

/// Workgroups of 64 invocations per dispatch.
const WORKGROUPS: u32 = 1024;

/// Each entry point and the resources it binds (by binding number).
const ENTRY_POINTS: [(&str, &[u32]); 8] = [
    ("no_reads", &[]),
    ("storage_divergent", &[0]),
    ("storage_same_entry", &[0]),
    ("uniform_divergent", &[1]),
    ("texture_divergent", &[2]),
    ("workgroup_fill", &[0]),
    ("workgroup_divergent", &[0]),
    ("workgroup_same_entry", &[0]),
];

fn memory_reads(c: &mut Criterion) {
    let Some(mut backend) = strata_benches::open_wgpu("memory_reads") else { return };
    // Words that spread the chain over the whole table.
    let words: Vec<u32> = (0..ENTRIES * 4).map(|i| i.wrapping_mul(2_654_435_761) >> 8).collect();
    let bytes: &[u8] = bytemuck::cast_slice(&words);
    let table = backend.create_buffer("table", bytes.len() as u64).expect("buffer");
    backend.write_buffer(table, 0, bytes).expect("upload");
    let texture = backend
        .create_texture(&TextureDesc {
            label: "table texture".into(),
            dimension: TextureDimension::D2,
            size: [64, ENTRIES / 64, 1],
            mip_levels: 1,
            format: TexelFormat::Rgba32Float,
        })
        .expect("texture");
    backend.write_texture(texture, 0, bytes).expect("upload");
    let sink = backend.create_buffer("sink", u64::from(WORKGROUPS * 64 * 4)).expect("buffer");
    let mut group = c.benchmark_group("memory_reads");
    group.sample_size(20).measurement_time(Duration::from_secs(4));
    for (entry, resources) in ENTRY_POINTS {
        let kernel = Kernel::from_wgsl("benches/kernels/memory_reads.wgsl", SOURCE.to_string(), entry, false)
            .unwrap_or_else(|e| panic!("{entry}: {e}"));
        let mut binds = vec![Bind::new(3, sink)];
        for &binding in resources {
            binds.push(if binding == 2 { Bind::texture(2, texture) } else { Bind::new(binding, table) });
        }
        group.bench_function(entry, |b| {
            b.iter_custom(|iterations| {
                (0..iterations)
                    .map(|_| backend.dispatch_timed(&kernel, &binds, [WORKGROUPS, 1, 1]).expect("dispatch"))
                    .sum()
            })
        });
    }
    group.finish();
}

criterion_group!(benches, memory_reads);
criterion_main!(benches);
