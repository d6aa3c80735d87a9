//! The constants the kernels share with the host, and a reader of the constants naga
//! parsed from a module.
//!
//! Constants have values that must agree (an object id the histogram treats as "no
//! object", a sampler id, a slot number). Each is declared once, in Rust, with
//! `gpu_constants!` ([`crate::gpu`]), and written into the generated WGSL modules that the
//! kernels import; [`shared`] lists them by WGSL name, and the export package declares the
//! ones its kernels use. The test below reads every `const` of every registry kernel from
//! naga's IR: each is one of [`shared`] or listed in [`KERNEL_PRIVATE`] (a kernel's own
//! size or sentinel), so a new constant is classified when it is written, and every
//! shared constant is used by some kernel.

use crate::gpu::{ConstantValue, GpuConstant};

/// Every constant the kernels share with the host (WGSL name, value, doc): the constants
/// of the generated modules ([`crate::wgsl_files::gpu_modules`]), each declared once in
/// Rust with `gpu_constants!`, in the modules' order.
pub fn shared() -> Vec<GpuConstant> {
    crate::wgsl_files::gpu_modules().iter().flat_map(|module| module.constants.iter().copied()).collect()
}

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

    /// Every constant of every registry kernel is a shared one (generated, so equal to
    /// its Rust declaration by construction; the test still compares, f32 bit for bit) or
    /// kernel-private, and every shared constant is used by some kernel.
    #[test]
    fn every_wgsl_constant_is_shared_or_kernel_private() {
        let registry = Registry::shared().unwrap();
        let shared = shared();
        let mut seen = std::collections::HashSet::new();
        for kernel in registry.kernels() {
            for (name, value) in module_constants(&kernel.module) {
                if KERNEL_PRIVATE.contains(&name.as_str()) {
                    continue;
                }
                let Some(declared) = shared.iter().find(|c| c.name == name).map(|c| c.value) else {
                    panic!(
                        "{}: WGSL constant {name} is neither declared in Rust (gpu_constants!) nor listed in \
                         KERNEL_PRIVATE",
                        kernel.name()
                    )
                };
                let equal = match (value, declared) {
                    (ConstantValue::F32(a), ConstantValue::F32(b)) => a.to_bits() == b.to_bits(),
                    (a, b) => a == b,
                };
                assert!(equal, "{}: WGSL {name} = {value:?}, Rust {declared:?}", kernel.name());
                seen.insert(name);
            }
        }
        for constant in &shared {
            assert!(seen.contains(constant.name), "{}: no registry kernel uses it", constant.name);
        }
    }

    /// The reader gives each literal constant's name and value as WGSL wrote them, and
    /// skips the others; no shared constant is also listed as kernel-private.
    #[test]
    fn constants_are_read_by_name_and_value() {
        let module = naga::front::wgsl::parse_str(
            "const INVALID_KEY: u32 = 7u;\nconst BELOW_ONE: f32 = 0.5;\nconst V: vec2<u32> = vec2(1u);",
        )
        .unwrap();
        let mut read = module_constants(&module);
        read.sort_by(|a, b| a.0.cmp(&b.0));
        assert_eq!(
            read,
            [("BELOW_ONE".to_string(), ConstantValue::F32(0.5)), ("INVALID_KEY".to_string(), ConstantValue::U32(7))]
        );
        assert!(!shared().iter().any(|c| KERNEL_PRIVATE.contains(&c.name)));
    }
}
