//! Host twins of the ReSTIR passes' records (`wgsl/restir/reservoir.wgsl`), checked
//! against naga's layout by [`crate::layout::check_struct`].

use bytemuck::{Pod, Zeroable};

/// `PathCandidate.kind`: no candidate (zero contribution).
pub const KIND_NONE: u32 = 0;
/// `PathCandidate.kind`: a Lambertian x2 other pixels may reconnect to.
pub const KIND_SURFACE: u32 = 1;
/// `PathCandidate.kind`: an environment direction.
pub const KIND_ENVIRONMENT: u32 = 2;
/// `PathCandidate.kind`: a non-Lambertian x2, usable by its own pixel only.
pub const KIND_PRIVATE: u32 = 3;
/// `PathCandidate.kind`: the random numbers of the rest of a glossy vertex's path (the PCG
/// state in `light`), shared with other replay pixels by random replay.
pub const KIND_REPLAY: u32 = 4;

/// `Primary.flags`: the camera ray hit a surface.
pub const PRIMARY_HIT: u32 = 1;
/// `Primary.flags`: the pixel resamples (its primary hit is rough enough).
pub const PRIMARY_RESAMPLE: u32 = 2;
/// `Primary.flags`: the pixel resamples by random replay at a glossy conductor
/// (`RestirParams::replay`); it takes `KIND_REPLAY` candidates only.
pub const PRIMARY_REPLAY: u32 = 4;

/// `RestirParams.method`: histogram + antithetic selection, inverse-CDF resampling.
pub const METHOD_STRATA: u32 = 0;
/// `RestirParams.method`: K uniformly random candidates of the same cluster.
pub const METHOD_RESTIR: u32 = 1;
/// `RestirParams.method`: K uniformly random pixels in a disc.
pub const METHOD_RESTIR_DISC: u32 = 2;

/// `RestirParams.shading`: the resampled part is the kept sample's f(Y) V W.
pub const SHADING_SAMPLE: u32 = 0;
/// `RestirParams.shading`: the resampled part is `Reservoir::expected`, the expectation of
/// the frame's final resampling over its choice.
pub const SHADING_EXPECTATION: u32 = 1;

/// Settings of the ReSTIR kernels (WGSL `RestirParams`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct RestirParams {
    /// `METHOD_*`.
    pub method: u32,
    /// K, candidates selected per pixel (0 in the temporal-first order's first pass:
    /// `restir_select` then writes the canonical candidate alone).
    pub candidates: u32,
    /// strata's sampler variant (`SAMPLER_*` of [`crate::selection`], Table 2). Object
    /// masking (§4.3) is the histogram's own setting (`HistogramParams.masking`).
    pub sampler: u32,
    /// 1: temporal reuse on.
    pub temporal: u32,
    /// Cap of the previous reservoir's M before a merge.
    pub temporal_cap: f32,
    /// restir-disc's radius in pixels.
    pub disc_radius: f32,
    /// No reconnection to an x2 closer than this to a primary hit.
    pub min_distance: f32,
    /// Smallest GGX alpha of a conductor primary hit that resamples.
    pub min_roughness: f32,
    /// Previous frame's camera origin.
    pub previous_origin: [f32; 3],
    /// Previous frame's tan(horizontal half fov).
    pub previous_tan_half_x: f32,
    /// Previous frame's forward vector.
    pub previous_forward: [f32; 3],
    /// Previous frame's tan(vertical half fov).
    pub previous_tan_half_y: f32,
    /// Previous frame's right vector.
    pub previous_right: [f32; 3],
    /// T, previous reservoirs drawn per pixel besides its own (0 to 4).
    pub temporal_candidates: u32,
    /// Previous frame's up vector.
    pub previous_up: [f32; 3],
    /// What restir_shade writes: bit 0 the pixel's own estimate, bit 1 the reservoir's
    /// sample (3: the image; 1 or 2: a diagnostic of one part).
    pub shaded_parts: u32,
    /// `SHADING_*`: the resampled part as the kept sample or as `Reservoir::expected`.
    pub shading: u32,
    /// Smooth vertices a camera path may pass through to the vertex it resamples at (0:
    /// only a rough primary hit resamples, or with `replay` a glossy conductor at it).
    pub specular_chain: u32,
    /// 1: a glossy conductor (GGX alpha below `min_roughness`) resamples at its own vertex
    /// by random replay instead of passing as a smooth vertex of the chain.
    pub replay: u32,
    /// Padding.
    pub _pad2: u32,
}

/// The vertex one pixel resamples at (WGSL `Primary`): the camera ray's hit, or the
/// first rough vertex behind a chain of smooth ones.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Primary {
    /// Vertex position.
    pub position: [f32; 3],
    /// Object id (the histogram's masking key).
    pub object_id: u32,
    /// Geometric normal, flipped towards `wo` for two-sided materials.
    pub normal: [f32; 3],
    /// Material index.
    pub material: u32,
    /// Unit direction towards the previous vertex (the camera, or the chain).
    pub wo: [f32; 3],
    /// `PRIMARY_*` bits.
    pub flags: u32,
    /// Albedo at the vertex.
    pub albedo: [f32; 3],
    /// Length of the path from the camera.
    pub depth: f32,
    /// Throughput of the smooth chain before the vertex (1 without one).
    pub throughput: [f32; 3],
    /// Number of the path segment that reached the vertex (1: the camera ray).
    pub segment: u32,
    /// The camera ray's hit (temporal reprojection follows it).
    pub camera_hit: [f32; 3],
    /// Padding.
    pub _pad: u32,
}

/// One pixel's candidate (WGSL `PathCandidate`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct PathCandidate {
    /// x2, or the direction of an environment candidate; `KIND_REPLAY`: the vertex it
    /// was drawn at.
    pub position: [f32; 3],
    /// `KIND_*`.
    pub kind: u32,
    /// x2's geometric normal flipped towards the y1 that found it; `KIND_REPLAY`: the
    /// vertex's direction towards the previous vertex.
    pub normal: [f32; 3],
    /// x2's emissive triangle when seen from its emitting side, else `NO_LIGHT`;
    /// `KIND_REPLAY`: the PCG state the rest of the path starts from.
    pub light: u32,
    /// Radiance x2 reflects towards y1 (emission excluded); `KIND_REPLAY`: the replayed
    /// path's estimate at the vertex it was drawn at.
    pub reflected: [f32; 3],
    /// Unbiased contribution weight W for its own pixel (0 for none).
    pub weight: f32,
}

/// One pixel's reservoir (WGSL `Reservoir`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Reservoir {
    /// The sample.
    pub sample: PathCandidate,
    /// Unbiased contribution weight W.
    pub weight: f32,
    /// M, canonical samples behind the reservoir.
    pub count: f32,
    /// p̂ of the sample at its pixel.
    pub target_value: f32,
    /// Padding.
    pub _pad: u32,
    /// The expectation of the frame's final resampling over its choice at this pixel
    /// (RGB): what `SHADING_EXPECTATION` shades.
    pub expected: [f32; 3],
    /// Padding.
    pub _pad_expected: f32,
}
