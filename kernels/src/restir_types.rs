//! The ReSTIR passes' records and constants (used by `restir/reservoir.wgsl` and the
//! passes), declared once ([`crate::gpu`]): the WGSL module `gpu/restir.wgsl` is
//! generated from them.

use crate::gpu::{GpuModule, StructDeclaration, gpu_constants, gpu_struct};

gpu_constants! {
    fn constants;
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
    /// `Primary.flags`: the pixel resamples (its resampling vertex, y1 or the first rough
    /// vertex behind a smooth chain, is rough enough to reconnect from).
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
}

gpu_struct! {
    /// Settings of the ReSTIR kernels (WGSL `RestirParams`).
    pub struct RestirParams {
        /// `METHOD_*`.
        pub method: u32,
        /// K, candidates selected per pixel (1 to 4; 0 in the temporal-first order's first
        /// pass: `restir_select` then writes each pixel's canonical candidate alone).
        pub candidates: u32,
        /// strata's sampler variant (`SAMPLER_*` of [`crate::selection`], Table 2). Object
        /// masking (§4.3) is the histogram's own setting (`HistogramParams.masking`).
        pub sampler: u32,
        /// 1: temporal reuse on (merge with the previous frame's reservoir).
        pub temporal: u32,
        /// Cap of the previous reservoir's M before a temporal merge (paper: 20).
        pub temporal_cap: f32,
        /// Radius in pixels of restir-disc's neighbourhood.
        pub disc_radius: f32,
        /// No reconnection to an x2 closer than this to either primary hit.
        pub min_distance: f32,
        /// Smallest GGX alpha of a conductor primary hit that resamples.
        pub min_roughness: f32,
        /// Previous frame's camera origin (the previous camera, for reprojection).
        pub previous_origin: [f32; 3] as "vec3<f32>",
        /// Previous frame's tan(horizontal half fov).
        pub previous_tan_half_x: f32,
        /// Previous frame's forward vector.
        pub previous_forward: [f32; 3] as "vec3<f32>",
        /// Previous frame's tan(vertical half fov).
        pub previous_tan_half_y: f32,
        /// Previous frame's right vector.
        pub previous_right: [f32; 3] as "vec3<f32>",
        /// T, previous reservoirs drawn per pixel from the block's histogram of reprojected
        /// reservoirs (Fig. 11), 0 to 4, merged besides the pixel's own reprojected one.
        pub temporal_candidates: u32,
        /// Previous frame's up vector.
        pub previous_up: [f32; 3] as "vec3<f32>",
        /// What restir_shade writes: bit 0 the pixel's own estimate (base), bit 1 the
        /// reservoir's sample (3: the image; 1 or 2: to measure one part's variance).
        pub shaded_parts: u32,
        /// `SHADING_*`: the resampled part as the kept sample or as the expectation of the
        /// frame's final resampling (`Reservoir::expected`).
        pub shading: u32,
        /// Smooth vertices (dielectrics, conductors below `min_roughness`) a camera path may
        /// pass through to the vertex it resamples at (0: only a rough primary hit
        /// resamples, or with `replay` a glossy conductor at it).
        pub specular_chain: u32,
        /// 1: a glossy conductor (GGX alpha below `min_roughness`) resamples at its own vertex
        /// by random replay instead of passing as a smooth vertex of the chain.
        pub replay: u32,
        /// 1: permutation sampling of the temporal source (RTXDI's decorrelation): the
        /// reprojected previous pixel is mirrored within its aligned 4 x 4 group, the
        /// groups shifted by a per-frame random offset, so that neighbouring pixels take
        /// their histories from each other's places (`restir/entry_temporal_keys.wgsl`).
        pub permutation_sampling: u32,
        /// Strength of the boiling filter in (0, 1] (RTXDI's; biased): after the temporal
        /// merge a reservoir whose W exceeds the workgroup's mean nonzero W by the factor
        /// 10 / strength - 9 is emptied (`restir/entry_temporal.wgsl`); 0: off.
        pub boiling_filter: f32,
        /// Padding.
        pub _pad2: u32,
        /// Padding.
        pub _pad3: u32,
        /// Padding.
        pub _pad4: u32,
    }
}

gpu_struct! {
    /// The G-buffer: the vertex one pixel resamples at (WGSL `Primary`). That is the
    /// camera ray's hit y1, or, when y1 is smooth and `RestirParams::specular_chain`
    /// allows, the first rough vertex the camera path reaches through smooth ones
    /// (`restir/entry_candidates.wgsl`): the pixel then resamples the light that vertex
    /// reflects along the chain, and shading multiplies by the chain's throughput.
    pub struct Primary {
        /// Vertex position.
        pub position: [f32; 3] as "vec3<f32>",
        /// Object id (the histogram's masking key).
        pub object_id: u32,
        /// Geometric normal, flipped towards `wo` for two-sided materials.
        pub normal: [f32; 3] as "vec3<f32>",
        /// Material index.
        pub material: u32,
        /// Unit direction towards the previous vertex of the path (the camera, or the chain).
        pub wo: [f32; 3] as "vec3<f32>",
        /// `PRIMARY_*` bits.
        pub flags: u32,
        /// Albedo at the vertex.
        pub albedo: [f32; 3] as "vec3<f32>",
        /// Length of the path from the camera to `position`.
        pub depth: f32,
        /// The chain's throughput: product of the BSDF sampling weights f cos / pdf of its
        /// smooth vertices (1 without a chain).
        pub throughput: [f32; 3] as "vec3<f32>",
        /// Number of the path segment that reached the vertex (1: the camera ray). Pixels
        /// share candidates only with the same segment: a candidate's reflected radiance
        /// was estimated with the segments left after it (`RenderParams::max_depth`).
        pub segment: u32,
        /// The camera ray's hit y1 (`position` without a chain): temporal reprojection
        /// follows the point the pixel sees.
        pub camera_hit: [f32; 3] as "vec3<f32>",
        /// Padding.
        pub _pad: u32,
    }
}

gpu_struct! {
    /// One pixel's candidate (WGSL `PathCandidate`).
    pub struct PathCandidate {
        /// x2, or the direction of an environment candidate; `KIND_REPLAY`: the vertex it
        /// was drawn at.
        pub position: [f32; 3] as "vec3<f32>",
        /// `KIND_*`.
        pub kind: u32,
        /// x2's geometric normal flipped towards the y1 that found it; `KIND_REPLAY`: the
        /// vertex's direction towards the previous vertex.
        pub normal: [f32; 3] as "vec3<f32>",
        /// x2's emissive triangle when seen from its emitting side, else `NO_LIGHT`;
        /// `KIND_REPLAY`: the PCG state the rest of the path starts from.
        pub light: u32,
        /// Radiance x2 reflects towards y1 (emission excluded), a one-sample estimate;
        /// `KIND_REPLAY`: the replayed path's estimate Ĉ(y, u) at the vertex it was drawn
        /// at (kept so that its own pixel need not trace it again).
        pub reflected: [f32; 3] as "vec3<f32>",
        /// Unbiased contribution weight W for its own pixel (RIS over its BSDF and light
        /// samples; 0 for none).
        pub weight: f32,
    }
}

gpu_struct! {
    /// One pixel's reservoir (WGSL `Reservoir`).
    pub struct Reservoir {
        /// The sample.
        pub sample: PathCandidate,
        /// Unbiased contribution weight W of `sample` for this pixel.
        pub weight: f32,
        /// M, canonical samples behind the reservoir (one per frame).
        pub count: f32,
        /// p̂ of `sample` at this pixel (luminance of its contribution, visibility included).
        pub target_value: f32,
        /// Padding.
        pub _pad: u32,
        /// The expectation, over the choice alone, of this frame's final resampling at this
        /// pixel: sum_i w_i f(x_i) / p̂(x_i) over every candidate i it chose from (RGB,
        /// visibility included, as in p̂); what `SHADING_EXPECTATION` shades.
        /// E[f(Y) W | candidates] = this, so shading with it in place of f(Y) V W is
        /// unbiased and never noisier; it costs no ray (p̂ already traced each candidate's
        /// visibility). Not merged over frames: only `sample` is.
        pub expected: [f32; 3] as "vec3<f32>",
        /// Padding.
        pub _pad_expected: f32,
    }
}

/// The WGSL module `gpu/restir.wgsl`: the constants and structs above.
pub fn gpu_module() -> GpuModule {
    GpuModule {
        path: "gpu/restir.wgsl",
        source: "kernels/src/restir_types.rs",
        readers: None,
        constants: constants(),
        structs: vec![
            StructDeclaration::of::<RestirParams>(),
            StructDeclaration::of::<Primary>(),
            StructDeclaration::of::<PathCandidate>(),
            StructDeclaration::of::<Reservoir>(),
        ],
    }
}
