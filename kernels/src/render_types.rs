//! The path tracer's records and constants (the scene as `render/scene.wgsl` binds it),
//! declared once ([`crate::gpu`]): the WGSL module `gpu/render.wgsl` is generated from
//! them.

use crate::gpu::{GpuModule, RowReaders, StructDeclaration, gpu_constants, gpu_struct};
use crate::trace_types::{GpuBvhNode, GpuTriangle};

gpu_constants! {
    fn constants;
    /// The R2 sequence's step along x (Roberts 2018: 1/φ₂, φ₂ the plastic number) in
    /// 0.32 fixed point, so that every backend computes the same film position.
    pub const R2_STEP_X: u32 = 3_242_174_889;
    /// The R2 sequence's step along y (1/φ₂²) in 0.32 fixed point.
    pub const R2_STEP_Y: u32 = 2_447_445_414;
    /// `RenderParams.flags`: next-event estimation (light sampling).
    pub const FLAG_SAMPLE_LIGHTS: u32 = 1;
    /// `RenderParams.flags`: emission found by BSDF sampling counts (MIS when both are set).
    pub const FLAG_HIT_LIGHTS: u32 = 2;
    /// `RenderParams.flags`: Russian roulette from `rr_depth`.
    pub const FLAG_RUSSIAN_ROULETTE: u32 = 4;
    /// `RenderParams.flags`: camera rays through pixel centres instead of a random point of
    /// each pixel (no film jitter; a diagnostic: the image is then a point-sampled one).
    pub const FLAG_PIXEL_CENTRES: u32 = 8;
    /// `RenderParams.flags`: a pixel's film positions over its sample indices (frames) follow
    /// the R2 sequence from a per-pixel random start, instead of independent uniform points:
    /// each sample alone is still a uniform point of the pixel, and successive samples
    /// cover it evenly.
    pub const FLAG_STRATIFIED_FILM: u32 = 16;

    /// `Material.kind`: Lambertian diffuse.
    pub const MATERIAL_DIFFUSE: u32 = 0;
    /// `Material.kind`: GGX rough conductor.
    pub const MATERIAL_CONDUCTOR: u32 = 1;
    /// `Material.kind`: smooth dielectric.
    pub const MATERIAL_DIELECTRIC: u32 = 2;

    /// `Material.albedo_kind`: `color0`.
    pub const ALBEDO_CONSTANT: u32 = 0;
    /// `Material.albedo_kind`: checkerboard of `color0` and `color1`.
    pub const ALBEDO_CHECKERBOARD: u32 = 1;
    /// `Material.albedo_kind`: bilinear texture at `texel_offset`.
    pub const ALBEDO_TEXTURE: u32 = 2;

    /// `TriangleInfo.light` of a triangle that does not emit.
    pub const NO_LIGHT: u32 = u32::MAX;

    /// Rows of the scene's uniform copy (`scene_rows_uniform`, 16 KiB: the smallest
    /// uniform binding every device allows): a scene of at most this many rows is read
    /// from there by kernels specialised with `scene_in_uniform` (`render/scene.wgsl`).
    pub const SCENE_UNIFORM_ROWS: u32 = 1024;
}

gpu_struct! {
    /// Per-frame parameters of the path-tracing kernels (WGSL `RenderParams`).
    pub struct RenderParams {
        /// Image width in pixels.
        pub width: u32,
        /// Image height in pixels.
        pub height: u32,
        /// Index of the sample in each pixel's sequence (the frame, progressively).
        pub sample_index: u32,
        /// Seed of the whole render.
        pub seed: u32,
        /// Path segments including the camera ray (CONVENTIONS.md).
        pub max_depth: u32,
        /// Depth from which Russian roulette runs.
        pub rr_depth: u32,
        /// Number of emissive triangles.
        pub light_count: u32,
        /// `FLAG_*` bits.
        pub flags: u32,
        /// Camera position.
        pub camera_origin: [f32; 3] as "vec3<f32>",
        /// Near clip distance (rays start on the near plane).
        pub near_clip: f32,
        /// Unit viewing direction.
        pub camera_forward: [f32; 3] as "vec3<f32>",
        /// tan of half the horizontal field of view.
        pub tan_half_x: f32,
        /// Unit right vector (image +x).
        pub camera_right: [f32; 3] as "vec3<f32>",
        /// tan of half the vertical field of view.
        pub tan_half_y: f32,
        /// Unit true up vector (image −y).
        pub camera_up: [f32; 3] as "vec3<f32>",
        /// Probability of sampling the environment rather than an area light in NEE.
        pub environment_probability: f32,
        /// Row 0 of inverse(R) (world to environment).
        pub env_from_world_0: [f32; 3] as "vec3<f32>",
        /// Environment radiance scale.
        pub env_scale: f32,
        /// Row 1 of inverse(R).
        pub env_from_world_1: [f32; 3] as "vec3<f32>",
        /// Environment map width (0: no environment).
        pub env_width: u32,
        /// Row 2 of inverse(R).
        pub env_from_world_2: [f32; 3] as "vec3<f32>",
        /// Environment map height.
        pub env_height: u32,
        /// Row 0 of R (environment to world).
        pub env_to_world_0: [f32; 3] as "vec3<f32>",
        /// First texel of the environment in the texel buffer.
        pub env_texel_offset: u32,
        /// Row 1 of R.
        pub env_to_world_1: [f32; 3] as "vec3<f32>",
        /// Padding.
        pub _pad0: u32,
        /// Row 2 of R.
        pub env_to_world_2: [f32; 3] as "vec3<f32>",
        /// Ray-origin offset relative to max(|p|, 1), which avoids self-intersection.
        pub ray_epsilon: f32,
        /// First row of the BVH nodes in the scene's rows (`gpu/scene_rows.wgsl`).
        pub nodes_row: u32,
        /// First row of the leaf-ordered triangles.
        pub triangles_row: u32,
        /// First row of the triangles' attributes.
        pub triangle_info_row: u32,
        /// First row of the materials.
        pub materials_row: u32,
        /// First row of the emissive triangles.
        pub lights_row: u32,
        /// First row of the texels (one per row).
        pub texels_row: u32,
        /// First row of the environment's CDFs (four per row).
        pub environment_cdf_row: u32,
        /// Padding.
        pub _pad1: u32,
    }
}

gpu_struct! {
    /// Per-triangle attributes in BVH leaf order (WGSL `TriangleInfo`).
    pub struct TriangleInfo {
        /// The mesh instance's object id (the histogram's masking key).
        pub object_id: u32,
        /// Index into the materials.
        pub material: u32,
        /// Index into the emissive triangles, or [`NO_LIGHT`].
        pub light: u32,
        /// 1 when `uv0..uv2` hold the mesh's texture coordinates; otherwise the surface UV
        /// is the hit's barycentrics.
        pub has_uv: u32,
        /// UV at vertex 0.
        pub uv0: [f32; 2] as "vec2<f32>",
        /// UV at vertex 1.
        pub uv1: [f32; 2] as "vec2<f32>",
        /// UV at vertex 2.
        pub uv2: [f32; 2] as "vec2<f32>",
        /// Padding.
        pub _pad0: u32,
        /// Padding.
        pub _pad1: u32,
    }
}

gpu_struct! {
    /// A material (WGSL `Material`); the meaning of the colours depends on `kind`.
    pub struct GpuMaterial as "Material" {
        /// `MATERIAL_*`.
        pub kind: u32,
        /// 1 when back-side hits see the front-side BSDF.
        pub two_sided: u32,
        /// `ALBEDO_*`.
        pub albedo_kind: u32,
        /// First texel of the texture in the texel buffer.
        pub texel_offset: u32,
        /// Diffuse reflectance, checkerboard colour 0, or the conductor's eta.
        pub color0: [f32; 3] as "vec3<f32>",
        /// GGX alpha.
        pub alpha: f32,
        /// Checkerboard colour 1, or the conductor's k.
        pub color1: [f32; 3] as "vec3<f32>",
        /// Dielectric interior over exterior IOR.
        pub eta: f32,
        /// UV scale of a texture or checkerboard.
        pub uv_scale: [f32; 2] as "vec2<f32>",
        /// Texture width in texels.
        pub texture_width: u32,
        /// Texture height in texels.
        pub texture_height: u32,
    }
}

gpu_struct! {
    /// An emissive triangle with its selection probability (WGSL `EmissiveTriangle`).
    pub struct EmissiveTriangle {
        /// Emitted radiance (one-sided, along the geometric normal).
        pub radiance: [f32; 3] as "vec3<f32>",
        /// Index into the leaf-ordered triangles.
        pub triangle: u32,
        /// Inclusive CDF of selection; the last is exactly 1.
        pub cdf: f32,
        /// Selection probability.
        pub probability: f32,
        /// Triangle area.
        pub area: f32,
        /// Padding.
        pub _pad: u32,
    }
}

/// The WGSL module `gpu/scene_rows.wgsl`: readers of the scene's records from the rows
/// the path-tracing kernels bind for the whole scene, through `render/scene.wgsl`'s
/// `scene_row` (the storage buffer `scene_rows`, or its uniform copy for a small scene).
/// One buffer instead of seven keeps every ReSTIR pass within the 10 storage buffers per
/// stage a browser's WebGPU allows (the temporal pass binds 9 of its own). The host
/// appends the arrays in 16-byte rows and gives where each starts in `RenderParams.*_row`.
pub fn scene_rows_module() -> GpuModule {
    GpuModule {
        path: "gpu/scene_rows.wgsl",
        source: "kernels/src/render_types.rs",
        readers: Some(RowReaders {
            row_function: "scene_row",
            imports: vec!["gpu/trace.wgsl", "gpu/render.wgsl"],
            structs: vec![
                StructDeclaration::of::<GpuBvhNode>(),
                StructDeclaration::of::<GpuTriangle>(),
                StructDeclaration::of::<TriangleInfo>(),
                StructDeclaration::of::<GpuMaterial>(),
                StructDeclaration::of::<EmissiveTriangle>(),
            ],
        }),
        constants: Vec::new(),
        structs: Vec::new(),
    }
}

/// The WGSL module `gpu/render.wgsl`: the constants and structs above.
pub fn gpu_module() -> GpuModule {
    GpuModule {
        path: "gpu/render.wgsl",
        source: "kernels/src/render_types.rs",
        readers: None,
        constants: constants(),
        structs: vec![
            StructDeclaration::of::<RenderParams>(),
            StructDeclaration::of::<TriangleInfo>(),
            StructDeclaration::of::<GpuMaterial>(),
            StructDeclaration::of::<EmissiveTriangle>(),
        ],
    }
}
