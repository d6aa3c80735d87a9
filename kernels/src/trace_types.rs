//! The BVH traversal's and the camera kernel's records and constants, declared once
//! ([`crate::gpu`]): the WGSL module `gpu/trace.wgsl` is generated from them. The node
//! and triangle layouts are obvhs' `Bvh2Node` and `Triangle` (glam `Vec3A` is 16 bytes),
//! so obvhs' arrays upload as they are.

use crate::gpu::{GpuModule, StructDeclaration, gpu_constants, gpu_struct};

gpu_constants! {
    fn constants;
    /// `primitive` of a [`Hit`] that hit nothing.
    pub const MISS: u32 = 0xffff_ffff;
    /// `primitive` of a [`Hit`] whose traversal overflowed its stack.
    pub const STACK_OVERFLOW: u32 = 0xffff_fffe;
    /// Traversal stack entries per ray (`TRACE_STACK_DEPTH` in WGSL).
    pub const TRACE_STACK_DEPTH: u32 = 48;
}

gpu_struct! {
    /// A BVH2 node exactly as obvhs lays out `Bvh2Node` (WGSL `BvhNode`).
    pub struct GpuBvhNode as "BvhNode" {
        /// Box minimum.
        pub aabb_min: [f32; 3] as "vec3<f32>",
        /// Vec3A padding.
        pub _pad0: u32,
        /// Box maximum.
        pub aabb_max: [f32; 3] as "vec3<f32>",
        /// Vec3A padding.
        pub _pad1: u32,
        /// 0 for an inner node (children at `first_index` and `first_index + 1`); otherwise
        /// the leaf's primitive count, its primitives at `primitive_indices[first_index..]`.
        pub prim_count: u32,
        /// First child (inner) or first entry of `primitive_indices` (leaf).
        pub first_index: u32,
        /// obvhs' spare field.
        pub meta1: u32,
        /// obvhs' spare field.
        pub meta2: u32,
    }
}

gpu_struct! {
    /// A triangle exactly as obvhs lays out `Triangle` (WGSL `Triangle`), counter-clockwise.
    pub struct GpuTriangle as "Triangle" {
        /// First vertex.
        pub v0: [f32; 3] as "vec3<f32>",
        /// Vec3A padding.
        pub _pad0: u32,
        /// Second vertex.
        pub v1: [f32; 3] as "vec3<f32>",
        /// Vec3A padding.
        pub _pad1: u32,
        /// Third vertex.
        pub v2: [f32; 3] as "vec3<f32>",
        /// Vec3A padding.
        pub _pad2: u32,
    }
}

gpu_struct! {
    /// A ray (WGSL `Ray`): hits count for tmin < t < tmax.
    pub struct Ray {
        /// Origin.
        pub origin: [f32; 3] as "vec3<f32>",
        /// Smallest accepted t.
        pub tmin: f32,
        /// Direction (not necessarily unit length; nonzero and finite).
        pub direction: [f32; 3] as "vec3<f32>",
        /// Largest accepted t.
        pub tmax: f32,
    }
}

gpu_struct! {
    /// The closest hit of a ray (WGSL `Hit`): primitive = [`MISS`] when nothing was hit (t =
    /// tmax, u = v = 0), [`STACK_OVERFLOW`] when the traversal stack overflowed (a BVH
    /// deeper than [`TRACE_STACK_DEPTH`]).
    pub struct Hit {
        /// Distance along the ray (tmax for a miss).
        pub t: f32,
        /// Barycentric weight of v1.
        pub u: f32,
        /// Barycentric weight of v2.
        pub v: f32,
        /// Index of the triangle, [`MISS`] or [`STACK_OVERFLOW`].
        pub primitive: u32,
    }
}

gpu_struct! {
    /// Sizes of one traversal dispatch (WGSL `TraceParams`).
    #[derive(Eq)]
    pub struct TraceParams {
        /// Rays in the batch.
        pub ray_count: u32,
        /// Workgroups per row of the 2-D dispatch.
        pub workgroups_x: u32,
        /// Padding.
        pub _pad0: u32,
        /// Padding.
        pub _pad1: u32,
    }
}

gpu_struct! {
    /// The pinhole camera of the `camera_rays` kernel (WGSL `CameraParams`).
    pub struct CameraParams {
        /// Eye position.
        pub origin: [f32; 3] as "vec3<f32>",
        /// Near clip distance along `forward`.
        pub near_clip: f32,
        /// Unit viewing direction.
        pub forward: [f32; 3] as "vec3<f32>",
        /// tan of half the horizontal field of view.
        pub tan_half_x: f32,
        /// Unit right vector (image +x).
        pub right: [f32; 3] as "vec3<f32>",
        /// tan of half the vertical field of view.
        pub tan_half_y: f32,
        /// Unit up vector (image −y).
        pub up: [f32; 3] as "vec3<f32>",
        /// tmax of the rays.
        pub far_clip: f32,
        /// Image width.
        pub width: u32,
        /// Image height.
        pub height: u32,
        /// 0: pixel centres; otherwise the seed of the per-pixel jitter.
        pub jitter_seed: u32,
        /// Padding.
        pub _pad: u32,
    }
}

/// The WGSL module `gpu/trace.wgsl`: the constants and structs above.
pub fn gpu_module() -> GpuModule {
    GpuModule {
        path: "gpu/trace.wgsl",
        source: "kernels/src/trace_types.rs",
        readers: None,
        constants: constants(),
        structs: vec![
            StructDeclaration::of::<GpuBvhNode>(),
            StructDeclaration::of::<GpuTriangle>(),
            StructDeclaration::of::<Ray>(),
            StructDeclaration::of::<Hit>(),
            StructDeclaration::of::<TraceParams>(),
            StructDeclaration::of::<CameraParams>(),
        ],
    }
}
