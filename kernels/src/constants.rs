//! The WGSL constants the host shares with the kernels, each with its Rust value, and a
//! reader of the constants naga parsed from a module.
//!
//! Constants have values that must agree (an object id the histogram treats as "no
//! object", a sampler id, a slot number). Those declared with
//! `gpu_constants!` ([`crate::gpu`]) are written into WGSL from their Rust declaration; the
//! others (the selection's, the blue noise's, the histogram's `SLOTS`, `R2_STEP`) are
//! written on both sides. [`SHARED`] lists both kinds, by WGSL name: the export package
//! declares the ones its kernels use. The test
//! below reads every `const` of every registry kernel from naga's IR and compares it
//! with [`SHARED`]; a WGSL constant that is in neither [`SHARED`] nor [`KERNEL_PRIVATE`]
//! fails it, so a new constant is classified when it is written.

use crate::blue_noise::{OPTIMISED_DIMENSIONS, PACKED_RANKING, PACKED_SCRAMBLING, PACKED_SOBOL, TILE_SIZE};
use crate::gpu::ConstantValue;
use crate::{denoise_types, embed_types, render_types, restir_types, selection, trace_types, types};

/// Every WGSL constant the host also uses, by its WGSL name, with the Rust twin's value.
pub const SHARED: &[(&str, ConstantValue)] = {
    use ConstantValue::{F32, U32};
    &[
        ("OBJECT_ID_NONE", U32(types::OBJECT_ID_NONE)),
        ("OBJECT_ID_ENVIRONMENT", U32(types::OBJECT_ID_ENVIRONMENT)),
        ("INVALID_KEY", U32(types::INVALID_KEY)),
        ("SLOTS", U32(types::HISTOGRAM_SLOTS_PER_WORKGROUP)),
        ("MAX_SELECTED", U32(selection::MAX_SELECTED)),
        ("BELOW_ONE", F32(selection::BELOW_ONE)),
        ("SAMPLER_RANDOM", U32(selection::SAMPLER_RANDOM)),
        ("SAMPLER_HEITZ", U32(selection::SAMPLER_HEITZ)),
        ("SAMPLER_RANDOM_OFFSET", U32(selection::SAMPLER_RANDOM_OFFSET)),
        ("SAMPLER_RANDOM_OFFSET_BLUE_NOISE", U32(selection::SAMPLER_RANDOM_OFFSET_BLUE_NOISE)),
        ("SAMPLER_ANTITHETIC", U32(selection::SAMPLER_ANTITHETIC)),
        ("BLUE_NOISE_TILE", U32(TILE_SIZE)),
        ("BLUE_NOISE_DIMENSIONS_PER_PIXEL", U32(OPTIMISED_DIMENSIONS)),
        ("BLUE_NOISE_SOBOL", U32(PACKED_SOBOL)),
        ("BLUE_NOISE_SCRAMBLING", U32(PACKED_SCRAMBLING)),
        ("BLUE_NOISE_RANKING", U32(PACKED_RANKING)),
        ("BLUE_NOISE_RANKING_WORDS", U32(TILE_SIZE * TILE_SIZE * OPTIMISED_DIMENSIONS)),
        ("NO_PAYLOAD", U32(embed_types::NO_PAYLOAD)),
        ("CANONICAL_SLOT", U32(embed_types::CANONICAL_SLOT)),
        ("NO_SLOT", U32(embed_types::NO_SLOT)),
        ("INVALID_SLOT", U32(embed_types::INVALID_SLOT)),
        ("KIND_NONE", U32(restir_types::KIND_NONE)),
        ("KIND_SURFACE", U32(restir_types::KIND_SURFACE)),
        ("KIND_ENVIRONMENT", U32(restir_types::KIND_ENVIRONMENT)),
        ("KIND_PRIVATE", U32(restir_types::KIND_PRIVATE)),
        ("KIND_REPLAY", U32(restir_types::KIND_REPLAY)),
        ("PRIMARY_HIT", U32(restir_types::PRIMARY_HIT)),
        ("PRIMARY_RESAMPLE", U32(restir_types::PRIMARY_RESAMPLE)),
        ("PRIMARY_REPLAY", U32(restir_types::PRIMARY_REPLAY)),
        ("METHOD_STRATA", U32(restir_types::METHOD_STRATA)),
        ("METHOD_RESTIR", U32(restir_types::METHOD_RESTIR)),
        ("METHOD_RESTIR_DISC", U32(restir_types::METHOD_RESTIR_DISC)),
        ("SHADING_SAMPLE", U32(restir_types::SHADING_SAMPLE)),
        ("SHADING_EXPECTATION", U32(restir_types::SHADING_EXPECTATION)),
        ("FLAG_SAMPLE_LIGHTS", U32(render_types::FLAG_SAMPLE_LIGHTS)),
        ("FLAG_HIT_LIGHTS", U32(render_types::FLAG_HIT_LIGHTS)),
        ("FLAG_RUSSIAN_ROULETTE", U32(render_types::FLAG_RUSSIAN_ROULETTE)),
        ("FLAG_PIXEL_CENTRES", U32(render_types::FLAG_PIXEL_CENTRES)),
        ("FLAG_STRATIFIED_FILM", U32(render_types::FLAG_STRATIFIED_FILM)),
        ("R2_STEP_X", U32(render_types::R2_STEP[0])),
        ("R2_STEP_Y", U32(render_types::R2_STEP[1])),
        ("MATERIAL_DIFFUSE", U32(render_types::MATERIAL_DIFFUSE)),
        ("MATERIAL_CONDUCTOR", U32(render_types::MATERIAL_CONDUCTOR)),
        ("MATERIAL_DIELECTRIC", U32(render_types::MATERIAL_DIELECTRIC)),
        ("ALBEDO_CONSTANT", U32(render_types::ALBEDO_CONSTANT)),
        ("ALBEDO_CHECKERBOARD", U32(render_types::ALBEDO_CHECKERBOARD)),
        ("ALBEDO_TEXTURE", U32(render_types::ALBEDO_TEXTURE)),
        ("NO_LIGHT", U32(render_types::NO_LIGHT)),
        ("MISS", U32(trace_types::MISS)),
        ("STACK_OVERFLOW", U32(trace_types::STACK_OVERFLOW)),
        ("TRACE_STACK_DEPTH", U32(trace_types::TRACE_STACK_DEPTH)),
        ("MIN_ALBEDO", F32(denoise_types::MIN_ALBEDO)),
        ("SHORT_HISTORY", F32(denoise_types::SHORT_HISTORY)),
    ]
};

/// WGSL constants no host code reads: a kernel's own sizes and sentinels.
pub const KERNEL_PRIVATE: &[&str] = &[
    // Each ReSTIR pass's random stream (restir/resampling_core.wgsl).
    "STREAM_SELECT",
    "STREAM_SPATIAL",
    "STREAM_TEMPORAL",
    // The histogram's register layout and its padding key (strata/histogram.wgsl).
    "ELEMS",
    "ELEM_BITS",
    "INVOCATIONS",
    "MAX_SEGMENTS",
    "SENTINEL_KEY",
    // The traversal stack's entries kept in registers (trace/traverse.wgsl).
    "REGISTER_STACK",
    // "No temporal source" and "no pixel" between two ReSTIR passes' locals.
    "NO_SOURCE",
    "NO_PIXEL",
    // The resampling core's slots and the id of its kept canonical sample
    // (restir/resampling_core.wgsl).
    "MAX_SLOTS",
    "CANONICAL_KEPT",
    // How restir_candidates' walk along the camera path ended (restir/entry_candidates.wgsl).
    "EXIT_OTHER",
    "EXIT_REPLAY",
    "EXIT_PATH_TRACE",
    // Mathematics.
    "PI",
    "INFINITY",
];

/// The named constants of `module` whose value is a `u32` or `f32` literal, with their
/// values (others, e.g. vectors, are left out).
pub fn module_constants(module: &naga::Module) -> Vec<(String, ConstantValue)> {
    module
        .constants
        .iter()
        .filter_map(|(_, constant)| {
            let name = constant.name.clone()?;
            let value = match module.global_expressions[constant.init] {
                naga::Expression::Literal(naga::Literal::U32(v)) => ConstantValue::U32(v),
                naga::Expression::Literal(naga::Literal::F32(v)) => ConstantValue::F32(v),
                _ => return None,
            };
            Some((name, value))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Registry;

    /// Every constant of every registry kernel equals its Rust twin (f32 bit for bit),
    /// or is declared kernel-private; every twin is found in some kernel.
    #[test]
    fn wgsl_constants_equal_their_rust_twins() {
        let registry = Registry::shared().unwrap();
        let mut seen = std::collections::HashSet::new();
        for kernel in registry.kernels() {
            for (name, value) in module_constants(&kernel.module) {
                if KERNEL_PRIVATE.contains(&name.as_str()) {
                    continue;
                }
                let twin = SHARED.iter().find(|(shared, _)| *shared == name).map(|&(_, v)| v);
                let Some(twin) = twin else {
                    panic!(
                        "{}: WGSL constant {name} has no Rust twin in SHARED nor a place in KERNEL_PRIVATE",
                        kernel.name()
                    )
                };
                let equal = match (value, twin) {
                    (ConstantValue::F32(a), ConstantValue::F32(b)) => a.to_bits() == b.to_bits(),
                    (a, b) => a == b,
                };
                assert!(equal, "{}: WGSL {name} = {value:?}, Rust twin {twin:?}", kernel.name());
                seen.insert(name);
            }
        }
        for (name, _) in SHARED {
            assert!(seen.contains(*name), "twin {name}: no registry kernel declares it");
        }
    }

    /// The check reads values: a module whose constant differs from its twin is caught.
    #[test]
    fn a_differing_constant_is_read_as_such() {
        let module = naga::front::wgsl::parse_str("const INVALID_KEY: u32 = 7u;\nconst BELOW_ONE: f32 = 0.5;").unwrap();
        let constants = module_constants(&module);
        assert_eq!(constants.len(), 2);
        for (name, value) in constants {
            let twin = SHARED.iter().find(|(shared, _)| *shared == name).unwrap().1;
            assert_ne!(value, twin, "{name}");
        }
    }
}
