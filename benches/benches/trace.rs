//! `trace`: closest-hit rays per second of the WGSL BVH traversal on wgpu (lavapipe
//! here) against obvhs' own native CPU traversal of the same rays through the same BVH.
//!
//! * `obvhs_native`: `Bvh2::ray_traverse` with obvhs' triangle intersection, one thread.
//! * `obvhs_native_all_cores`: the same on one scoped thread per core, each taking the
//!   next block of 1024 rays as it finishes one, so it uses the cores lavapipe uses.
//! * `obvhs_cwbvh_native`: obvhs' compressed 8-wide BVH built from the same triangles
//!   and traversed natively, one thread: what a wide BVH gains obvhs itself, i.e. the
//!   baseline a wide-BVH kernel would have to be compared with.
//! * `wgsl_wgpu`: the `bvh_closest_hit` kernel, device time per dispatch (timestamps).
//!
//! Scene: 50 000 small random triangles in a cube; 262 144 rays from around it.
//! Run: `cargo bench -p strata-benches --bench trace`.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::Vec3A;
use obvhs::ray::{Ray as ObvhsRay, RayHit};
use std::hint::black_box;
use std::time::Duration;
use strata_backends::backend::upload;
use strata_backends::{Backend, Bind};
use strata_kernels::trace_types::{Hit, TraceParams};
use strata_kernels::{KernelId, Registry};
use strata_render::synthetic::{rays_into_cube, triangle_soup};
use strata_render::trace_pass::SceneBvh;

fn trace(c: &mut Criterion) {
    // The test soup's triangles shrunk to a tenth around their centroids: a sparse scene
    // of small triangles, closer to real geometry than the heavily overlapping soup.
    let soup: Vec<[[f32; 3]; 3]> = triangle_soup(50_000, 5)
        .into_iter()
        .map(|t| {
            let centroid = [0, 1, 2].map(|k| (t[0][k] + t[1][k] + t[2][k]) / 3.0);
            t.map(|v| [0, 1, 2].map(|k| centroid[k] + 0.1 * (v[k] - centroid[k])))
        })
        .collect();
    let rays = rays_into_cube(1 << 18, 6);
    let mut group = c.benchmark_group("trace_50k_tris_262k_rays");
    group.sample_size(10).measurement_time(Duration::from_secs(10)).throughput(Throughput::Elements(rays.len() as u64));

    let (tris, bvh) = strata_render::trace_pass::build_obvhs(&soup);
    group.bench_function("obvhs_native", |b| {
        b.iter(|| {
            let mut hits = 0u32;
            for r in &rays {
                let ray = ObvhsRay::new(Vec3A::from(r.origin), Vec3A::from(r.direction), r.tmin, r.tmax);
                let mut hit = RayHit::none();
                if bvh.ray_traverse(ray, &mut hit, |ray, id| tris[bvh.primitive_indices[id] as usize].intersect(ray)) {
                    hits += 1;
                }
            }
            black_box(hits)
        })
    });

    let cw = obvhs::cwbvh::builder::build_cwbvh_from_tris(
        &tris,
        obvhs::BvhBuildParams::fast_build(),
        &mut Duration::default(),
    );
    group.bench_function("obvhs_cwbvh_native", |b| {
        b.iter(|| {
            let mut hits = 0u32;
            for r in &rays {
                let ray = ObvhsRay::new(Vec3A::from(r.origin), Vec3A::from(r.direction), r.tmin, r.tmax);
                let mut hit = RayHit::none();
                if cw.ray_traverse(ray, &mut hit, |ray, id| tris[cw.primitive_indices[id] as usize].intersect(ray)) {
                    hits += 1;
                }
            }
            black_box(hits)
        })
    });
    // Blocks of rays handed out to one thread per core as each finishes the last, so a
    // slow stretch of rays does not leave a core idle.
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    const BLOCK: usize = 1024;
    group.bench_function("obvhs_native_all_cores", |b| {
        b.iter(|| {
            let next = std::sync::atomic::AtomicUsize::new(0);
            let hits: u32 = std::thread::scope(|scope| {
                let workers: Vec<_> = (0..cores)
                    .map(|_| {
                        let (tris, bvh, rays, next) = (&tris, &bvh, &rays, &next);
                        scope.spawn(move || {
                            let mut hits = 0u32;
                            loop {
                                let start = next.fetch_add(BLOCK, std::sync::atomic::Ordering::Relaxed);
                                if start >= rays.len() {
                                    return hits;
                                }
                                for r in &rays[start..(start + BLOCK).min(rays.len())] {
                                    let ray =
                                        ObvhsRay::new(Vec3A::from(r.origin), Vec3A::from(r.direction), r.tmin, r.tmax);
                                    let mut hit = RayHit::none();
                                    if bvh.ray_traverse(ray, &mut hit, |ray, id| {
                                        tris[bvh.primitive_indices[id] as usize].intersect(ray)
                                    }) {
                                        hits += 1;
                                    }
                                }
                            }
                        })
                    })
                    .collect();
                workers.into_iter().map(|w| w.join().expect("a worker")).sum()
            });
            black_box(hits)
        })
    });

    let Some(mut backend) = strata_benches::open_wgpu("wgpu") else { return };
    let scene = SceneBvh::build(&soup).expect("scene");
    let kernel = Registry::shared().expect("registry").get(KernelId::BvhClosestHit);
    let groups = (rays.len() as u32).div_ceil(64);
    let params = TraceParams { ray_count: rays.len() as u32, workgroups_x: groups, _pad0: 0, _pad1: 0 };
    let buffers = [
        upload(&mut backend, "params", &[params]).expect("upload"),
        upload(&mut backend, "nodes", &scene.nodes).expect("upload"),
        upload(&mut backend, "primitive indices", &scene.primitive_indices).expect("upload"),
        upload(&mut backend, "triangles", &scene.triangles).expect("upload"),
        upload(&mut backend, "rays", &rays).expect("upload"),
        backend.create_buffer("hits", (rays.len() * size_of::<Hit>()) as u64).expect("buffer"),
    ];
    let binds: Vec<Bind> = buffers.iter().enumerate().map(|(i, &b)| Bind::new(i as u32, b)).collect();
    group.bench_function("wgsl_wgpu", |b| {
        b.iter_custom(|iterations| {
            (0..iterations).map(|_| backend.dispatch_timed(kernel, &binds, [groups, 1, 1]).expect("dispatch")).sum()
        })
    });
    group.finish();
}

criterion_group!(benches, trace);
criterion_main!(benches);
