//! The denoiser's records and constants (`kernels/wgsl/denoise/`): the per-pixel guide
//! an engine supplies and the SVGF passes' uniform, declared once ([`crate::gpu`]): the
//! WGSL module `gpu/denoise.wgsl` is generated from them.

use crate::gpu::{GpuModule, StructDeclaration, gpu_constants, gpu_struct};

gpu_struct! {
    /// What the denoiser reads of a pixel's surface (WGSL `DenoiseGuide`, 48 bytes, std430):
    /// its G-buffer, as engines already keep one (SVGF, Schied et al. 2017, §3 and §4.1).
    /// The renderer writes it in `restir/entry_guide.wgsl`; an engine writes its own.
    pub struct DenoiseGuide {
        /// Reflectance divided out before filtering and multiplied in after (SVGF §4:
        /// filtering untextured illumination keeps texture detail sharp); components at or
        /// below [`MIN_ALBEDO`] are left alone.
        pub albedo: [f32; 3] as "vec3<f32>",
        /// Linear depth of the surface (distance along the pixel's ray; the renderer gives
        /// the path length through a mirror chain, where SVGF uses clip-space depth); 0: no
        /// surface (the sky): the pixel is passed through unfiltered and never used as a
        /// neighbour.
        pub depth: f32,
        /// Unit world-space normal.
        pub normal: [f32; 3] as "vec3<f32>",
        /// Object id: history is taken only from a pixel that saw the same object.
        pub mesh: u32,
        /// The surface point's previous image position minus its current one, in pixels (a
        /// motion vector without the camera's sub-pixel jitter).
        pub motion: [f32; 2] as "vec2<f32>",
        /// Padding.
        pub _pad: [u32; 2] as "vec2<u32>",
    }
}

gpu_struct! {
    /// SVGF's filter settings: what a user chooses of [`DenoiseParams`], declared here
    /// once; `strata_render::denoise::SvgfSettings` holds them as they are, and
    /// [`SvgfFilter::paper`] gives the paper's (Schied et al. 2017, §4 and §5).
    pub struct SvgfFilter {
        /// Weight of the new frame in the colour's exponential moving average (SVGF:
        /// 0.2), in (0, 1]; a history shorter than 1/alpha frames is averaged uniformly
        /// instead.
        pub alpha_colour: f32,
        /// Weight of the new frame in the luminance moments' moving average (SVGF: 0.2),
        /// in (0, 1].
        pub alpha_moments: f32,
        /// σ_l: how many standard deviations of luminance apart two pixels may be before
        /// the filter stops mixing them (SVGF: 4); finite and positive.
        pub sigma_luminance: f32,
        /// σ_z: how many times the depth change its local slope predicts two pixels may
        /// differ by before the filter stops mixing them (SVGF: 1); finite and positive.
        pub sigma_depth: f32,
        /// The normal weight is max(0, n·n')^(2^normal_power_log2) (SVGF: σ_n = 128, i.e.
        /// 7), 0 to 10; computed by squaring: the same on every backend, where pow() is
        /// not.
        pub normal_power_log2: u32,
        /// History lengths stop growing here (frames), 1 or more: after that the moving
        /// averages weigh the new frame `alpha_*`.
        pub max_history: f32,
        /// Reprojection: a previous pixel continues this one's history if it saw the same
        /// object at a depth within this fraction (0.1, the renderer's own temporal test;
        /// SVGF's implementation scales its depth test by screen-space derivatives), in
        /// (0, 1]...
        pub depth_tolerance: f32,
        /// ...and its normal is within this cosine (0.906: 25 degrees), in [-1, 1].
        pub normal_tolerance: f32,
        /// 1: the spatial filters (variance estimate, à-trous) also give weight 0 between
        /// pixels of different objects (`DenoiseGuide::mesh`), as the temporal pass does;
        /// 0: SVGF's own weights, which stop at depth, normal and luminance edges only.
        pub object_edges: u32,
        /// The correlation ρ in [0, 1) that the à-trous filter's variance propagation
        /// assumes between the noise of the pixels it averages: 0 (SVGF's) treats each
        /// pixel's noise as independent, Σ w² σ²; ReSTIR's reuse makes neighbours' errors
        /// positively correlated (lag 1 up to 0.15-0.18 measured), so the filtered
        /// variance is larger, ((1 - ρ) Σ w² σ² + ρ (Σ w σ)²) / (Σ w)², and the next
        /// level's luminance weights are less strict (`denoise/entry_atrous.wgsl`).
        pub error_correlation: f32,
        /// Padding.
        pub _pad1: u32,
        /// Padding.
        pub _pad2: u32,
    }
}

gpu_struct! {
    /// The uniform of one SVGF pass (WGSL `DenoiseParams`): the frame's and the level's
    /// numbers, and the filter's settings as the user chose them.
    pub struct DenoiseParams {
        /// Image width in pixels.
        pub width: u32,
        /// Image height in pixels.
        pub height: u32,
        /// 1: the history buffers hold the previous frame's (0: the first frame, or a cut).
        pub history: u32,
        /// À-trous: the distance in pixels between this level's taps (2^level).
        pub step: u32,
        /// The filter's settings (at byte 16, where a uniform may hold a struct; not named
        /// `filter`, a word WGSL reserves).
        pub svgf: SvgfFilter,
    }
}

/// Levels of SVGF's à-trous filter in the paper (Schied et al. 2017): taps 1, 2, 4, 8
/// and 16 pixels apart.
pub const PAPER_LEVELS: u32 = 5;

impl SvgfFilter {
    /// The paper's settings (Schied et al. 2017: α = 0.2 for colour and moments, σ_l = 4,
    /// σ_z = 1, σ_n = 128, a history of at most 32 frames) with the renderer's
    /// reprojection tolerances (depth within 10 %, normals within 25°), no object edges.
    pub fn paper() -> SvgfFilter {
        SvgfFilter {
            alpha_colour: 0.2,
            alpha_moments: 0.2,
            sigma_luminance: 4.0,
            sigma_depth: 1.0,
            normal_power_log2: 7,
            max_history: 32.0,
            depth_tolerance: 0.1,
            normal_tolerance: 0.906,
            object_edges: 0,
            ..SvgfFilter::default()
        }
    }
}

impl DenoiseParams {
    /// [`SvgfFilter::paper`]'s settings for the first level (step 1) of a frame without
    /// history.
    pub fn paper(width: u32, height: u32) -> DenoiseParams {
        DenoiseParams { width, height, history: 0, step: 1, svgf: SvgfFilter::paper() }
    }
}

gpu_constants! {
    fn constants;
    /// Albedo components at or below this are not divided out (a black or nearly black
    /// surface: its colour is its emission, which dividing would blow up).
    pub const MIN_ALBEDO: f32 = 1e-3;
    /// Histories shorter than this many frames take their variance from their neighbours
    /// (SVGF §4.2).
    pub const SHORT_HISTORY: f32 = 4.0;
}

/// The WGSL module `gpu/denoise.wgsl`: the constants and structs above.
pub fn gpu_module() -> GpuModule {
    GpuModule {
        path: "gpu/denoise.wgsl",
        source: "kernels/src/denoise_types.rs",
        readers: None,
        constants: constants(),
        structs: vec![
            StructDeclaration::of::<DenoiseGuide>(),
            StructDeclaration::of::<SvgfFilter>(),
            StructDeclaration::of::<DenoiseParams>(),
        ],
    }
}
