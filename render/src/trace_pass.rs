//! Ray queries against a triangle BVH on any backend: obvhs builds the BVH2 on the CPU,
//! its nodes and triangles upload as they are, and the `bvh_closest_hit` kernel
//! traverses it.

use crate::histogram_pass::PassError;
use glam::Vec3A;
use obvhs::bvh2::Bvh2;
use obvhs::triangle::Triangle;
use strata_backends::backend::{download, upload};
use strata_backends::{Backend, BackendError, Bind, BufferId};
use strata_kernels::trace_types::{CameraParams, GpuBvhNode, GpuTriangle, Hit, Ray, TRACE_STACK_DEPTH, TraceParams};
use strata_kernels::{Kernel, KernelId, Registry};

/// A triangle mesh with its BVH, in the layout the kernel reads.
pub struct SceneBvh {
    /// obvhs' nodes (root at 0).
    pub nodes: Vec<GpuBvhNode>,
    /// Leaf entries → triangle indices.
    pub primitive_indices: Vec<u32>,
    /// The triangles.
    pub triangles: Vec<GpuTriangle>,
}

impl SceneBvh {
    /// Builds the BVH of `triangles` (each three vertices) with [`build_obvhs`].
    pub fn build(triangles: &[[[f32; 3]; 3]]) -> Result<Self, PassError> {
        if triangles.is_empty() {
            return Err(PassError::Input("a BVH needs at least one triangle".into()));
        }
        if let Some(index) = triangles.iter().position(|t| t.iter().flatten().any(|c| !c.is_finite())) {
            return Err(PassError::Input(format!("triangle {index} has a NaN or infinite coordinate")));
        }
        let (tris, bvh) = build_obvhs(triangles);
        // Levels below the root of the deepest leaf (obvhs counts the leaf as one): the
        // most far children a traversal can have waiting on its stack at once.
        let depth = bvh.depth(0).saturating_sub(1);
        if depth > TRACE_STACK_DEPTH as usize {
            return Err(PassError::Input(format!(
                "the scene's BVH is {depth} levels deep, more than the {TRACE_STACK_DEPTH} its traversal stack holds \
                 (geometry spread over very different scales)"
            )));
        }
        Ok(Self {
            nodes: bytemuck::cast_slice(&bvh.nodes).to_vec(),
            primitive_indices: bvh.primitive_indices.clone(),
            triangles: bytemuck::cast_slice(&tris).to_vec(),
        })
    }
}

/// At most this many triangles per BVH leaf. obvhs' fast preset allows 8, which suits
/// one ray at a time; a GPU kernel runs 8 to 64 rays side by side, and a leaf loop costs
/// as long as the longest leaf among them. Measured (BENCHMARKS.md, trace): 2 is the
/// fastest for the WGSL kernel on lavapipe (−16 % against 8; 1 and 3 slower than 2) and
/// leaves obvhs' own traversal as fast as with 8.
pub const MAX_TRIANGLES_PER_LEAF: u32 = 2;

/// obvhs triangles of `triangles` and their BVH2 (fast preset, at most
/// [`MAX_TRIANGLES_PER_LEAF`] triangles per leaf): what [`SceneBvh`] uploads, and what
/// tests and benchmarks traverse natively to compare.
pub fn build_obvhs(triangles: &[[[f32; 3]; 3]]) -> (Vec<Triangle>, Bvh2) {
    let tris: Vec<Triangle> = triangles
        .iter()
        .map(|[a, b, c]| Triangle { v0: Vec3A::from(*a), v1: Vec3A::from(*b), v2: Vec3A::from(*c) })
        .collect();
    // obvhs' `build_bvh2_from_tris` without its pre-split branch (off in the fast preset),
    // step for step: PLOC, reinsertion, leaf collapse, reinsertion. Written out because
    // that helper times itself with `Instant::now`, which panics in a web page (wasm32);
    // obvhs offers the helper as an example to reimplement.
    let params =
        obvhs::BvhBuildParams { max_prims_per_leaf: MAX_TRIANGLES_PER_LEAF, ..obvhs::BvhBuildParams::fast_build() };
    let mut bvh = obvhs::ploc::PlocBuilder::with_capacity(tris.len()).build(
        params.ploc_search_distance,
        &tris,
        (0..tris.len() as u32).collect::<Vec<_>>(),
        params.sort_precision,
        params.search_depth_threshold,
    );
    bvh.uses_spatial_splits = false;
    let mut reinsertion = obvhs::bvh2::reinsertion::ReinsertionOptimizer::default();
    reinsertion.run(&mut bvh, params.reinsertion_batch_ratio, None);
    obvhs::bvh2::leaf_collapser::collapse(
        &mut bvh,
        params.max_prims_per_leaf.clamp(1, 255),
        params.collapse_traversal_cost,
    );
    reinsertion.run(
        &mut bvh,
        params.reinsertion_batch_ratio * params.post_collapse_reinsertion_batch_ratio_multiplier,
        None,
    );
    (tris, bvh)
}

/// The closest-hit pass with its buffers on one backend.
pub struct TracePass {
    kernel: &'static Kernel,
    nodes: BufferId,
    primitive_indices: BufferId,
    triangles: BufferId,
}

impl TracePass {
    /// Uploads the BVH.
    pub fn new(backend: &mut dyn Backend, scene: &SceneBvh) -> Result<Self, PassError> {
        let kernel = Registry::shared()?.get(KernelId::BvhClosestHit);
        backend.check_kernel(kernel)?;
        Ok(Self {
            kernel,
            nodes: upload(backend, "bvh nodes", &scene.nodes)?,
            primitive_indices: upload(backend, "bvh primitive indices", &scene.primitive_indices)?,
            triangles: upload(backend, "triangles", &scene.triangles)?,
        })
    }

    /// The closest hit of every ray. Rays must have finite origins and nonzero, finite
    /// directions; the error names the first ray that does not.
    pub fn trace(&self, backend: &mut dyn Backend, rays: &[Ray]) -> Result<Vec<Hit>, PassError> {
        if rays.is_empty() {
            return Ok(Vec::new());
        }
        if let Some(index) = rays.iter().position(|r| {
            r.origin.iter().chain(&r.direction).any(|c| !c.is_finite())
                || r.direction.iter().all(|&c| c == 0.0)
                || !(r.tmin >= 0.0 && r.tmin <= r.tmax)
        }) {
            return Err(PassError::Input(format!(
                "ray {index}: origin and direction must be finite, direction nonzero, 0 <= tmin <= tmax"
            )));
        }
        let groups = (rays.len() as u32).div_ceil(64);
        let x = groups.min(backend.info().limits.max_workgroups_per_dimension.max(1));
        let params = TraceParams { ray_count: rays.len() as u32, workgroups_x: x, _pad0: 0, _pad1: 0 };
        let params_buffer = upload(backend, "trace params", &[params])?;
        let rays_buffer = upload(backend, "rays", rays)?;
        let hits_buffer = backend.create_buffer("hits", (rays.len() * size_of::<Hit>()) as u64)?;
        let buffers = [
            ("trace_params", params_buffer),
            ("nodes", self.nodes),
            ("primitive_indices", self.primitive_indices),
            ("triangles", self.triangles),
            ("rays", rays_buffer),
            ("hits", hits_buffer),
        ];
        let result = Bind::named(self.kernel, &buffers)
            .and_then(|binds| backend.dispatch(self.kernel, &binds, [x, groups.div_ceil(x), 1]));
        let hits = result.and_then(|()| download::<Hit>(backend, hits_buffer));
        for buffer in [params_buffer, rays_buffer, hits_buffer] {
            backend.destroy_buffer(buffer)?;
        }
        Ok(hits?)
    }

    /// Frees the BVH buffers.
    pub fn destroy(self, backend: &mut dyn Backend) -> Result<(), BackendError> {
        for buffer in [self.nodes, self.primitive_indices, self.triangles] {
            backend.destroy_buffer(buffer)?;
        }
        Ok(())
    }
}

/// One primary ray per pixel from the `camera_rays` kernel.
pub fn camera_rays(backend: &mut dyn Backend, params: &CameraParams) -> Result<Vec<Ray>, PassError> {
    if params.width == 0 || params.height == 0 {
        return Err(PassError::Input(format!("image size {}x{}: must be at least 1x1", params.width, params.height)));
    }
    let kernel = Registry::shared()?.get(KernelId::CameraRays);
    let pixels = params.width as u64 * params.height as u64;
    let params_buffer = upload(backend, "camera params", std::slice::from_ref(params))?;
    let rays_buffer = backend.create_buffer("camera rays", pixels * size_of::<Ray>() as u64)?;
    let workgroups = [params.width.div_ceil(8), params.height.div_ceil(8), 1];
    let result = Bind::named(kernel, &[("camera", params_buffer), ("camera_rays", rays_buffer)])
        .and_then(|binds| backend.dispatch(kernel, &binds, workgroups));
    let rays = result.and_then(|()| download::<Ray>(backend, rays_buffer));
    backend.destroy_buffer(params_buffer)?;
    backend.destroy_buffer(rays_buffer)?;
    Ok(rays?)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tiny_triangle_at(x: f32) -> [[f32; 3]; 3] {
        [[x, 0.0, 0.0], [x + 1e-3 * x.max(1.0), 0.0, 0.0], [x, 1e-3 * x.max(1.0), 0.0]]
    }

    #[test]
    fn a_bvh_deeper_than_the_traversal_stack_is_refused_by_name() {
        // Triangles at exponentially growing distances: each one's nearest cluster is all
        // the ones before it, so the BVH is a chain one level per triangle.
        let chain: Vec<_> = (0..80).map(|i| tiny_triangle_at(1.7f32.powi(i))).collect();
        let (_, bvh) = build_obvhs(&chain);
        assert!(bvh.depth(0) > TRACE_STACK_DEPTH as usize + 1, "depth {}", bvh.depth(0));
        let message = SceneBvh::build(&chain).err().expect("refused").to_string();
        assert!(message.contains("levels deep") && message.contains("48"), "{message}");
        // A few of them make a shallow BVH, which is accepted.
        assert!(SceneBvh::build(&chain[..8]).is_ok());
    }
}
