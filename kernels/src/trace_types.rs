//! Host twins of the BVH traversal kernel's structs (`kernels/wgsl/trace/`). The node
//! and triangle layouts are obvhs' `Bvh2Node` and `Triangle` (glam `Vec3A` is 16 bytes),
//! so obvhs' arrays upload as they are; tests check both twins.

use bytemuck::{Pod, Zeroable};

/// `primitive` of a [`Hit`] that hit nothing.
pub const MISS: u32 = 0xffff_ffff;
/// `primitive` of a [`Hit`] whose traversal overflowed its stack.
pub const STACK_OVERFLOW: u32 = 0xffff_fffe;
/// Traversal stack entries per ray (`TRACE_STACK_DEPTH` in WGSL).
pub const TRACE_STACK_DEPTH: u32 = 48;

/// A BVH2 node exactly as obvhs lays out `Bvh2Node` (WGSL `BvhNode`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuBvhNode {
    /// Box minimum.
    pub aabb_min: [f32; 3],
    /// Vec3A padding.
    pub _pad0: u32,
    /// Box maximum.
    pub aabb_max: [f32; 3],
    /// Vec3A padding.
    pub _pad1: u32,
    /// 0 for inner nodes, else the leaf's primitive count.
    pub prim_count: u32,
    /// First child (inner) or first entry of `primitive_indices` (leaf).
    pub first_index: u32,
    /// obvhs' spare field.
    pub meta1: u32,
    /// obvhs' spare field.
    pub meta2: u32,
}

/// A triangle exactly as obvhs lays out `Triangle` (WGSL `Triangle`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuTriangle {
    /// First vertex.
    pub v0: [f32; 3],
    /// Vec3A padding.
    pub _pad0: u32,
    /// Second vertex.
    pub v1: [f32; 3],
    /// Vec3A padding.
    pub _pad1: u32,
    /// Third vertex.
    pub v2: [f32; 3],
    /// Vec3A padding.
    pub _pad2: u32,
}

/// A ray (WGSL `Ray`): hits count for tmin < t < tmax.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Ray {
    /// Origin.
    pub origin: [f32; 3],
    /// Smallest accepted t.
    pub tmin: f32,
    /// Direction (not necessarily unit length; nonzero and finite).
    pub direction: [f32; 3],
    /// Largest accepted t.
    pub tmax: f32,
}

/// The closest hit of a ray (WGSL `Hit`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
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

/// Sizes of one traversal dispatch (WGSL `TraceParams`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
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

/// The pinhole camera of the `camera_rays` kernel (WGSL `CameraParams`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct CameraParams {
    /// Eye position.
    pub origin: [f32; 3],
    /// Near clip distance along `forward`.
    pub near_clip: f32,
    /// Unit viewing direction.
    pub forward: [f32; 3],
    /// tan of half the horizontal field of view.
    pub tan_half_x: f32,
    /// Unit right vector (image +x).
    pub right: [f32; 3],
    /// tan of half the vertical field of view.
    pub tan_half_y: f32,
    /// Unit up vector (image −y).
    pub up: [f32; 3],
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
