//! The BVH closest-hit kernel against obvhs' own CPU traversal (an independent
//! implementation with Möller–Trumbore intersection) and bad input.

use glam::Vec3A;
use obvhs::ray::{Ray as ObvhsRay, RayHit};
use strata_backends::cpu_backend::{CpuBackend, CpuOptions};
use strata_backends::{Backend, gpu_required};
use strata_kernels::trace_types::{MISS, Ray};
use strata_render::synthetic::{rays_into_cube, triangle_soup};
use strata_render::trace_pass::{SceneBvh, TracePass};

fn obvhs_closest(soup: &[[[f32; 3]; 3]], rays: &[Ray]) -> Vec<(u32, f32)> {
    let (tris, bvh) = strata_render::trace_pass::build_obvhs(soup);
    rays.iter()
        .map(|r| {
            let ray = ObvhsRay::new(Vec3A::from(r.origin), Vec3A::from(r.direction), r.tmin, r.tmax);
            let mut hit = RayHit::none();
            if bvh.ray_traverse(ray, &mut hit, |ray, id| tris[bvh.primitive_indices[id] as usize].intersect(ray)) {
                (bvh.primitive_indices[hit.primitive_id as usize], hit.t)
            } else {
                (MISS, r.tmax)
            }
        })
        .collect()
}

fn agree_with_obvhs(backend: &mut dyn Backend) {
    let soup = triangle_soup(3000, 77);
    let rays = rays_into_cube(20_000, 78);
    let scene = SceneBvh::build(&soup).unwrap();
    let pass = TracePass::new(backend, &scene).unwrap();
    let hits = pass.trace(backend, &rays).unwrap();
    pass.destroy(backend).unwrap();
    let reference = obvhs_closest(&soup, &rays);
    let hit_count = hits.iter().filter(|h| h.primitive != MISS).count();
    assert!(hit_count > rays.len() / 5, "only {hit_count} of {} rays hit: the test is too easy", rays.len());
    let same = hits.iter().zip(&reference).filter(|(h, (p, _))| h.primitive == *p).count();
    let share = same as f64 / rays.len() as f64;
    assert!(share >= 0.999, "only {:.3}% of rays hit the same triangle as obvhs", share * 100.0);
    for (hit, (primitive, t)) in hits.iter().zip(&reference) {
        if hit.primitive == *primitive && hit.primitive != MISS {
            assert!((hit.t - t).abs() <= 1e-4 * t.abs().max(1.0), "t {} vs obvhs {t}", hit.t);
        }
    }
}

#[test]
fn closest_hits_agree_with_obvhs_on_the_interpreter() {
    agree_with_obvhs(&mut CpuBackend::new(CpuOptions::default()).unwrap());
}

#[test]
fn closest_hits_agree_with_obvhs_on_vulkan() {
    let Some(mut backend) = strata_tests::vulkan_backend("closest_hits_agree_with_obvhs_on_vulkan") else {
        assert!(!gpu_required());
        return;
    };
    agree_with_obvhs(&mut backend);
}

#[test]
fn bad_geometry_and_rays_are_named() {
    assert!(SceneBvh::build(&[]).err().unwrap().to_string().contains("at least one triangle"));
    let error = SceneBvh::build(&[[[0.0, 0.0, 0.0], [1.0, f32::NAN, 0.0], [0.0, 1.0, 0.0]]]).err().unwrap();
    assert!(error.to_string().contains("triangle 0 has a NaN"), "{error}");
    let mut cpu = CpuBackend::new(CpuOptions::default()).unwrap();
    let scene = SceneBvh::build(&triangle_soup(10, 1)).unwrap();
    let pass = TracePass::new(&mut cpu, &scene).unwrap();
    let mut rays = rays_into_cube(5, 2);
    rays[3].direction = [0.0, 0.0, 0.0];
    let error = pass.trace(&mut cpu, &rays).unwrap_err().to_string();
    assert!(error.contains("ray 3"), "{error}");
    assert!(pass.trace(&mut cpu, &[]).unwrap().is_empty());
}

/// Camera rays of a real scene (the shared matpreview: 61 600 triangles, a large ground
/// plane and a dense mesh) hit what obvhs hits. Rays with an unbounded tmax (1e30) once
/// made every box count as hit (limit + 1 == limit) and half the rays missed on lavapipe.
fn scene_camera_rays_agree_with_obvhs(backend: &mut dyn Backend) {
    let path = strata_tests::scenes_folder().join("matpreview/scene.json");
    let scene = strata_render::scene::Scene::load(&path).unwrap();
    let (soup, _) = scene.triangles_with_ids();
    let frame = strata_render::scene::CameraFrame::new(&scene.camera).unwrap();
    let (w, h) = (40u32, 30u32);
    let mut rays = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let (origin, direction) = frame.ray((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32);
            rays.push(Ray { origin: origin.into(), tmin: 0.0, direction: direction.into(), tmax: 1e30 });
        }
    }
    let bvh = SceneBvh::build(&soup).unwrap();
    let pass = TracePass::new(backend, &bvh).unwrap();
    let hits = pass.trace(backend, &rays).unwrap();
    pass.destroy(backend).unwrap();
    let reference = obvhs_closest(&soup, &rays);
    let hit_count = reference.iter().filter(|(p, _)| *p != MISS).count();
    assert!(hit_count > rays.len() / 3, "only {hit_count} of {} rays hit", rays.len());
    let same = hits.iter().zip(&reference).filter(|(h, (p, _))| h.primitive == *p).count();
    assert!(same as f64 >= 0.995 * rays.len() as f64, "only {same} of {} rays agree with obvhs", rays.len());
}

#[test]
fn scene_camera_rays_agree_with_obvhs_on_the_interpreter() {
    scene_camera_rays_agree_with_obvhs(&mut CpuBackend::new(CpuOptions::default()).unwrap());
}

#[test]
fn scene_camera_rays_agree_with_obvhs_on_vulkan() {
    let Some(mut backend) = strata_tests::vulkan_backend("scene_camera_rays_agree_with_obvhs_on_vulkan") else {
        assert!(!gpu_required());
        return;
    };
    scene_camera_rays_agree_with_obvhs(&mut backend);
}

/// A hand-built BVH whose traversal stack grows by one entry per level: inner node k has
/// the next inner node on the left and leaf k on the right, every box the same, so the
/// left child is visited first and leaf k waits on the stack. Leaf k holds a triangle in
/// the plane z = k; ray r starts at z = -1 with tmin just short of z = r, so its closest
/// hit is triangle r, reached only through the stack entry pushed at level r. With more
/// levels than TRACE_STACK_DEPTH the traversal reports STACK_OVERFLOW.
fn chain_bvh(levels: u32) -> SceneBvh {
    use strata_kernels::trace_types::{GpuBvhNode, GpuTriangle};
    let top = levels as f32 + 1.0;
    let node = |prim_count, first_index| GpuBvhNode {
        aabb_min: [-10.0, -10.0, -1.0],
        aabb_max: [10.0, 10.0, top],
        prim_count,
        first_index,
        ..Default::default()
    };
    let mut nodes = vec![node(0, 1)];
    for k in 0..levels {
        // Children of inner node k at 2k + 1 (left) and 2k + 2 (right: leaf k).
        nodes.push(if k + 1 < levels { node(0, 2 * k + 3) } else { node(1, levels) });
        nodes.push(node(1, k));
    }
    let triangles = (0..=levels)
        .map(|k| {
            let z = k as f32;
            GpuTriangle { v0: [-10.0, -10.0, z], v1: [10.0, -10.0, z], v2: [0.0, 10.0, z], ..Default::default() }
        })
        .collect();
    SceneBvh { nodes, primitive_indices: (0..=levels).collect(), triangles }
}

fn deep_stacks(backend: &mut dyn Backend) {
    use strata_kernels::reference::bvh_trace::closest_hit;
    use strata_kernels::trace_types::{STACK_OVERFLOW, TRACE_STACK_DEPTH};
    for levels in [3, 20, TRACE_STACK_DEPTH, TRACE_STACK_DEPTH + 1] {
        let scene = chain_bvh(levels);
        // Every ray of ray_count, so that all 64 lanes of a workgroup (each with its own
        // slice of the stack in workgroup memory) go deep.
        let ray_count = 150;
        let rays: Vec<Ray> = (0..ray_count)
            .map(|i| {
                let r = i % (levels + 1);
                Ray { origin: [0.0, 0.0, -1.0], tmin: r as f32 + 0.5, direction: [0.0, 0.0, 1.0], tmax: 1e30 }
            })
            .collect();
        let pass = TracePass::new(backend, &scene).unwrap();
        let hits = pass.trace(backend, &rays).unwrap();
        pass.destroy(backend).unwrap();
        for (i, (hit, ray)) in hits.iter().zip(&rays).enumerate() {
            let r = i as u32 % (levels + 1);
            let expected = if levels > TRACE_STACK_DEPTH { STACK_OVERFLOW } else { r };
            assert_eq!(hit.primitive, expected, "{levels} levels, ray {r}: {hit:?}");
            let reference = closest_hit(&scene.nodes, &scene.primitive_indices, &scene.triangles, ray);
            assert_eq!(reference.primitive, expected, "reference, {levels} levels, ray {r}");
            if expected != STACK_OVERFLOW {
                assert_eq!(hit.t, r as f32 + 1.0, "{levels} levels, ray {r}");
            }
        }
    }
}

#[test]
fn deep_stacks_spill_and_overflow_on_the_interpreter() {
    deep_stacks(&mut CpuBackend::new(CpuOptions::default()).unwrap());
}

#[test]
fn deep_stacks_spill_and_overflow_on_vulkan() {
    let Some(mut backend) = strata_tests::vulkan_backend("deep_stacks_spill_and_overflow_on_vulkan") else {
        assert!(!gpu_required());
        return;
    };
    deep_stacks(&mut backend);
}
