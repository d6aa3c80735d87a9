//! Checks that a `#[repr(C)]` host struct and its WGSL twin agree byte for byte.
//!
//! vec3 padding, a field added on one side only, a reordered field: each makes the GPU
//! read garbage without any error. [`check_struct`] compares the host struct's size and
//! every field's name, offset and size with naga's layout of the WGSL struct.

use crate::denoise_types::{DenoiseGuide, DenoiseParams};
use crate::embed_types::{ResampleInput, ResampleOutput, SelectedCandidates, SelectionParams};
use crate::render_types::{EmissiveTriangle, GpuMaterial, RenderParams, TriangleInfo};
use crate::restir_types::{PathCandidate, Primary, Reservoir, RestirParams};
use crate::trace_types::{CameraParams, GpuBvhNode, GpuTriangle, Hit, Ray, TraceParams};
use crate::types::{BlockStats, Candidate, ClusterSpan, HistogramParams};
use naga::proc::Layouter;

/// One field of a host struct.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct HostField {
    /// Field name (the WGSL member must have the same name).
    pub name: &'static str,
    /// Byte offset.
    pub offset: usize,
    /// Byte size.
    pub size: usize,
}

/// A host struct with a WGSL twin of the same name.
pub trait ShaderStruct: bytemuck::Pod {
    /// Name of the WGSL struct.
    const WGSL_NAME: &'static str;
    /// The struct's fields in declaration order.
    fn fields() -> Vec<HostField>;
}

/// Implements [`ShaderStruct`] for `$ty` with the listed fields.
macro_rules! shader_struct {
    ($ty:ty, $wgsl:literal, [$($field:ident),* $(,)?]) => {
        impl ShaderStruct for $ty {
            const WGSL_NAME: &'static str = $wgsl;
            fn fields() -> Vec<HostField> {
                fn size_of_field<T, F>(_: impl Fn(&T) -> &F) -> usize {
                    core::mem::size_of::<F>()
                }
                vec![$(HostField {
                    name: stringify!($field),
                    offset: core::mem::offset_of!($ty, $field),
                    size: size_of_field(|s: &$ty| &s.$field),
                }),*]
            }
        }
    };
}

shader_struct!(Candidate, "Candidate", [key, object_id]);
shader_struct!(ClusterSpan, "ClusterSpan", [offset, length, valid]);
shader_struct!(BlockStats, "BlockStats", [clusters, invalid, empty]);
shader_struct!(
    HistogramParams,
    "HistogramParams",
    [
        width,
        height,
        block_size,
        log2_block_size,
        blocks_x,
        blocks_y,
        workgroups_x,
        shift_x,
        shift_y,
        masking,
        _pad0,
        _pad1
    ]
);

shader_struct!(
    SelectionParams,
    "SelectionParams",
    [width, height, frame, seed, candidates, sampler, identity_payload, _pad]
);
shader_struct!(SelectedCandidates, "SelectedCandidates", [payloads, resample_number, run_length, run_valid, selected]);
shader_struct!(
    ResampleInput,
    "ResampleInput",
    [weights, targets, canonical_weight, canonical_target, canonical_payload, _pad]
);
shader_struct!(ResampleOutput, "ResampleOutput", [payload, slot, weight, weight_sum]);

shader_struct!(GpuBvhNode, "BvhNode", [aabb_min, _pad0, aabb_max, _pad1, prim_count, first_index, meta1, meta2]);
shader_struct!(GpuTriangle, "Triangle", [v0, _pad0, v1, _pad1, v2, _pad2]);
shader_struct!(Ray, "Ray", [origin, tmin, direction, tmax]);
shader_struct!(Hit, "Hit", [t, u, v, primitive]);
shader_struct!(TraceParams, "TraceParams", [ray_count, workgroups_x, _pad0, _pad1]);
shader_struct!(
    CameraParams,
    "CameraParams",
    [origin, near_clip, forward, tan_half_x, right, tan_half_y, up, far_clip, width, height, jitter_seed, _pad]
);

shader_struct!(
    RenderParams,
    "RenderParams",
    [
        width,
        height,
        sample_index,
        seed,
        max_depth,
        rr_depth,
        light_count,
        flags,
        camera_origin,
        near_clip,
        camera_forward,
        tan_half_x,
        camera_right,
        tan_half_y,
        camera_up,
        environment_probability,
        env_from_world_0,
        env_scale,
        env_from_world_1,
        env_width,
        env_from_world_2,
        env_height,
        env_to_world_0,
        env_texel_offset,
        env_to_world_1,
        _pad0,
        env_to_world_2,
        ray_epsilon,
    ]
);
shader_struct!(TriangleInfo, "TriangleInfo", [object_id, material, light, has_uv, uv0, uv1, uv2, _pad0, _pad1]);
shader_struct!(
    GpuMaterial,
    "Material",
    [kind, two_sided, albedo_kind, texel_offset, color0, alpha, color1, eta, uv_scale, texture_width, texture_height]
);
shader_struct!(EmissiveTriangle, "EmissiveTriangle", [radiance, triangle, cdf, probability, area, _pad]);

shader_struct!(
    RestirParams,
    "RestirParams",
    [
        method,
        candidates,
        sampler,
        temporal,
        temporal_cap,
        disc_radius,
        min_distance,
        min_roughness,
        previous_origin,
        previous_tan_half_x,
        previous_forward,
        previous_tan_half_y,
        previous_right,
        temporal_candidates,
        previous_up,
        shaded_parts,
        shading,
        specular_chain,
        replay,
        _pad2,
    ]
);
shader_struct!(
    Primary,
    "Primary",
    [position, object_id, normal, material, wo, flags, albedo, depth, throughput, segment, camera_hit, _pad]
);
shader_struct!(DenoiseGuide, "DenoiseGuide", [albedo, depth, normal, mesh, motion, _pad]);
shader_struct!(
    DenoiseParams,
    "DenoiseParams",
    [
        width,
        height,
        history,
        step,
        alpha_colour,
        alpha_moments,
        sigma_luminance,
        sigma_depth,
        normal_power_log2,
        max_history,
        depth_tolerance,
        normal_tolerance,
        object_edges,
        _pad0,
        _pad1,
        _pad2
    ]
);
shader_struct!(PathCandidate, "PathCandidate", [position, kind, normal, light, reflected, weight]);
shader_struct!(Reservoir, "Reservoir", [sample, weight, count, target_value, _pad, expected, _pad_expected]);

/// Compares `T` with the struct `T::WGSL_NAME` of `module`; the error lists every
/// difference.
pub fn check_struct<T: ShaderStruct>(module: &naga::Module) -> Result<(), String> {
    let (_, ty) = module
        .types
        .iter()
        .find(|(_, ty)| ty.name.as_deref() == Some(T::WGSL_NAME))
        .ok_or_else(|| format!("no WGSL struct `{}` in the module", T::WGSL_NAME))?;
    let naga::TypeInner::Struct { members, span } = &ty.inner else {
        return Err(format!("WGSL `{}` is not a struct", T::WGSL_NAME));
    };
    let mut layouter = Layouter::default();
    layouter.update(module.to_ctx()).map_err(|e| format!("naga layouter: {e}"))?;
    let mut problems = Vec::new();
    let host_size = core::mem::size_of::<T>();
    if *span as usize != host_size {
        problems.push(format!("size: WGSL {span} bytes, host {host_size} bytes"));
    }
    let host = T::fields();
    if host.len() != members.len() {
        problems.push(format!("field count: WGSL {}, host {}", members.len(), host.len()));
    }
    for (index, (wgsl, host)) in members.iter().zip(&host).enumerate() {
        let wgsl_name = wgsl.name.as_deref().unwrap_or("<unnamed>");
        let wgsl_size = layouter[wgsl.ty].size as usize;
        if wgsl_name != host.name {
            problems.push(format!("field {index}: WGSL `{wgsl_name}`, host `{}`", host.name));
        }
        if wgsl.offset as usize != host.offset {
            problems.push(format!("field `{}`: WGSL offset {}, host offset {}", host.name, wgsl.offset, host.offset));
        }
        if wgsl_size != host.size {
            problems.push(format!("field `{}`: WGSL size {wgsl_size}, host size {}", host.name, host.size));
        }
    }
    if problems.is_empty() {
        Ok(())
    } else {
        Err(format!("host struct and WGSL `{}` differ:\n  {}", T::WGSL_NAME, problems.join("\n  ")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A host struct holding a 16-byte vector (like glam's `Vec3A`) before an id.
    #[repr(C)]
    #[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
    struct Padded {
        position: [f32; 4],
        id: u32,
        pad: [u32; 3],
    }
    shader_struct!(Padded, "Padded", [position, id, pad]);

    fn module(source: &str) -> naga::Module {
        naga::front::wgsl::parse_str(source).unwrap()
    }

    #[test]
    fn vec3_padding_is_caught() {
        // WGSL puts a u32 right after a vec3<f32>, at offset 12: the host has it at 16.
        let bad = module("struct Padded { position: vec3<f32>, id: u32, pad: vec3<u32> }");
        let error = check_struct::<Padded>(&bad).unwrap_err();
        assert!(error.contains("field `id`: WGSL offset 12, host offset 16"), "{error}");
        assert!(error.contains("field `position`: WGSL size 12, host size 16"), "{error}");
        let good = module("struct Padded { position: vec4<f32>, id: u32, pad: array<u32, 3> }");
        check_struct::<Padded>(&good).unwrap();
    }

    #[test]
    fn renamed_and_missing_fields_are_caught() {
        let renamed = module("struct Padded { pos: vec4<f32>, id: u32, pad: array<u32, 3> }");
        assert!(check_struct::<Padded>(&renamed).unwrap_err().contains("`pos`"));
        let missing = module("struct Other { id: u32 }");
        assert!(check_struct::<Padded>(&missing).unwrap_err().contains("no WGSL struct"));
    }
}
