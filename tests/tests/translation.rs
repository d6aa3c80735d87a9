//! Every registry kernel translates to SPIR-V, HLSL, MSL and GLSL and each output passes
//! its external validator. A missing validator is a failure under
//! `STRATA_REQUIRE_VALIDATORS=1` (CI), a loud skip otherwise; MSL has no validator on
//! Linux and is only required to translate.

use strata_kernels::Registry;
use strata_kernels::validate::{Target, Verdict, translate_and_validate};

#[test]
fn every_kernel_translates_and_validates_for_every_target() {
    let required = std::env::var("STRATA_REQUIRE_VALIDATORS").is_ok_and(|v| !v.is_empty() && v != "0");
    let dir =
        std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("strata-translation-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let registry = Registry::load().unwrap_or_else(|e| panic!("{e}"));
    let mut problems = Vec::new();
    for kernel in registry.kernels() {
        for target in Target::ALL {
            let (path, verdict) = translate_and_validate(kernel, target, &dir);
            match verdict {
                Verdict::Valid(_) => {}
                Verdict::Invalid(why) => problems.push(format!("{} {}: {why}", kernel.name(), target.name())),
                Verdict::Missing(why) if required && target.validator_possible() => {
                    problems.push(format!("{} {}: validator missing: {why}", kernel.name(), target.name()))
                }
                Verdict::Missing(why) => {
                    assert!(path.exists(), "{} was not written", path.display());
                    eprintln!("NOT VALIDATED {} {}: {why}", kernel.name(), target.name());
                }
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

#[test]
fn translations_keep_the_entry_point_and_bindings() {
    let registry = Registry::load().unwrap_or_else(|e| panic!("{e}"));
    for kernel in registry.kernels() {
        let glsl = Target::Glsl.translate(kernel).unwrap();
        for binding in &kernel.bindings {
            assert!(
                glsl.text.contains(&format!("binding = {}", binding.binding)),
                "{}: GLSL lacks layout(binding = {})",
                kernel.name(),
                binding.binding
            );
        }
        let hlsl = Target::Hlsl.translate(kernel).unwrap();
        assert!(hlsl.text.contains(&format!("void {}(", hlsl.entry_point)), "{}", kernel.name());
        let msl = Target::Msl.translate(kernel).unwrap();
        assert!(msl.text.contains(&format!("kernel void {}(", msl.entry_point)), "{}", kernel.name());
        for binding in &kernel.bindings {
            assert!(
                msl.text.contains(&format!("[[buffer({})]]", binding.binding)),
                "{}: MSL lacks [[buffer({})]] from the explicit buffer map",
                kernel.name(),
                binding.binding
            );
        }
    }
}
