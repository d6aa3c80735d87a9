//! `#[repr(C)]` twins of the denoiser's WGSL structs (`kernels/wgsl/denoise/`): the
//! per-pixel guide an engine supplies and the SVGF passes' settings. The registry's
//! layout test holds each to its WGSL declaration.

use bytemuck::{Pod, Zeroable};

/// What the denoiser reads of a pixel's surface (WGSL `DenoiseGuide`, 48 bytes): an
/// engine's G-buffer.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct DenoiseGuide {
    /// Reflectance divided out before filtering and multiplied in after; components at
    /// or below [`MIN_ALBEDO`] are left alone.
    pub albedo: [f32; 3],
    /// Linear depth of the surface (distance along the pixel's ray); 0: no surface,
    /// passed through unfiltered.
    pub depth: f32,
    /// Unit world-space normal.
    pub normal: [f32; 3],
    /// Object id: history is taken only from a pixel that saw the same object.
    pub mesh: u32,
    /// The surface point's previous image position minus its current one, in pixels.
    pub motion: [f32; 2],
    /// Padding.
    pub _pad: [u32; 2],
}

/// The settings of one SVGF pass (WGSL `DenoiseParams`, a uniform).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct DenoiseParams {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// 1: the history buffers hold the previous frame's.
    pub history: u32,
    /// À-trous: the distance in pixels between this level's taps.
    pub step: u32,
    /// Weight of the new frame in the colour's moving average.
    pub alpha_colour: f32,
    /// Weight of the new frame in the moments' moving average.
    pub alpha_moments: f32,
    /// σ_l of the luminance edge-stopping weight.
    pub sigma_luminance: f32,
    /// σ_z of the depth edge-stopping weight.
    pub sigma_depth: f32,
    /// The normal weight's exponent is 2 to this power.
    pub normal_power_log2: u32,
    /// History lengths stop growing here (frames).
    pub max_history: f32,
    /// Reprojection's relative depth tolerance.
    pub depth_tolerance: f32,
    /// Reprojection's least cosine between normals.
    pub normal_tolerance: f32,
    /// 1: the spatial filters also stop at object boundaries.
    pub object_edges: u32,
    /// Padding (a uniform is a multiple of 16 bytes).
    pub _pad0: u32,
    /// Padding.
    pub _pad1: u32,
    /// Padding.
    pub _pad2: u32,
}

/// Levels of SVGF's à-trous filter in the paper (Schied et al. 2017): taps 1, 2, 4, 8
/// and 16 pixels apart.
pub const PAPER_LEVELS: u32 = 5;

impl DenoiseParams {
    /// The paper's settings (Schied et al. 2017: α = 0.2 for colour and moments, σ_l = 4,
    /// σ_z = 1, σ_n = 128, a history of at most 32 frames) with the renderer's
    /// reprojection tolerances (depth within 10 %, normals within 25°), no object edges,
    /// for the first level (step 1) of a frame without history.
    pub fn paper(width: u32, height: u32) -> DenoiseParams {
        DenoiseParams {
            width,
            height,
            history: 0,
            step: 1,
            alpha_colour: 0.2,
            alpha_moments: 0.2,
            sigma_luminance: 4.0,
            sigma_depth: 1.0,
            normal_power_log2: 7,
            max_history: 32.0,
            depth_tolerance: 0.1,
            normal_tolerance: 0.906,
            object_edges: 0,
            _pad0: 0,
            _pad1: 0,
            _pad2: 0,
        }
    }
}

/// Albedo components at or below this are not divided out (WGSL `MIN_ALBEDO`).
pub const MIN_ALBEDO: f32 = 1e-3;
/// Histories shorter than this many frames take their variance from their neighbours
/// (WGSL `SHORT_HISTORY`).
pub const SHORT_HISTORY: f32 = 4.0;
