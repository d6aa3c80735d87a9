//! The texture corpus (`strata_check::texture_corpus`, kernels in `tests/data/textures/`)
//! on every path: each case's outputs (storage buffers and storage textures) judged
//! against the interpreter's, integer and 8-bit integer texels bit for bit, unorm and
//! f16 texels within a rounding step, f32 words within the case's declared bound,
//! out-of-range loads by WGSL's rule; the paths a case names must refuse it with a
//! reason; and a corrupted output of each case must be caught.

use strata_check::run_kernel::open_backends;
use strata_check::texture_corpus::{TextureCase, Verdict, texture_cases};
use strata_tests::corpus_support::{ONE_CASE_AT_A_TIME, assert_corruption_caught, available_slots};

/// Runs every case of `file` everywhere it can and asserts its verdicts.
fn check_file(file: &str) {
    let slots = available_slots("the texture corpus");
    let cases: Vec<TextureCase> = texture_cases().into_iter().filter(|c| c.file == file).collect();
    assert!(!cases.is_empty(), "no case of {file}");
    let _turn = ONE_CASE_AT_A_TIME.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    let mut backends = open_backends(&slots);
    for case in cases {
        let runs = case.run_on(&mut backends);
        let verdicts = case.verdicts(&runs);
        for (backend, verdict) in &verdicts {
            eprintln!("{} {backend:<12} {verdict:?}", case.name);
        }
        let failures: Vec<String> = verdicts
            .iter()
            .filter_map(|(backend, verdict)| match verdict {
                Verdict::Fails(why) => Some(format!("{backend}: {why}")),
                _ => None,
            })
            .collect();
        assert!(failures.is_empty(), "{}:\n{}", case.name, failures.join("\n"));
        assert_corruption_caught(&runs, &case.tolerance(), &case.name);
    }
}

#[test]
fn loads_sizes_and_levels_of_every_float_format_agree_in_and_out_of_range() {
    check_file("load.wgsl");
}

#[test]
fn integer_texels_load_bit_for_bit() {
    check_file("integer.wgsl");
}

#[test]
fn stores_convert_to_every_storage_format_as_vulkan_defines() {
    check_file("store.wgsl");
}

#[test]
fn read_write_storage_textures_update_in_place_and_drop_out_of_range_stores() {
    check_file("read_write.wgsl");
}

#[test]
fn one_d_array_and_three_d_textures_load_store_and_count_alike() {
    check_file("shapes.wgsl");
}

#[test]
fn a_separable_blur_through_workgroup_memory_agrees_within_a_rounding_step() {
    check_file("blur.wgsl");
}

#[test]
fn sampling_and_gathering_agree_within_the_filtering_precision_for_every_sampler() {
    check_file("sample.wgsl");
}

#[test]
fn a_kernel_of_two_bind_groups_with_one_skipped_runs_everywhere() {
    check_file("two_groups.wgsl");
}

#[test]
fn a_sampler_in_one_group_filters_a_texture_in_another() {
    check_file("cross_group_sampler.wgsl");
}

#[test]
fn the_out_of_range_rule_refuses_a_value_wgsl_does_not_allow() {
    let case = texture_cases().into_iter().find(|c| c.name == "load.wgsl on r32float").unwrap();
    let slots = strata_check::run_kernel::named_slots(&["cpu".into()]).unwrap();
    let mut runs = case.run(&slots);
    assert!(case.verdicts(&runs)[0].1.passes());
    // An out-of-range slot that reads 0.5 (no texel of the texture, not 0 or 1).
    let outputs = runs[0].outputs.as_mut().unwrap();
    let outside = outputs.iter_mut().find(|o| o.name == "outside").unwrap();
    outside.bytes[..4].copy_from_slice(&0.5f32.to_le_bytes());
    let rule = case.rule.unwrap();
    assert!(rule(&case, &runs[0]).unwrap_err().contains("out of range at slot 0"));
}
