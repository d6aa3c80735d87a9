//! Shaders written the way outside projects write them (`tests/data/corpus/`, written
//! here): overrides in `@workgroup_size` and in expressions, workgroup arrays sized by
//! override expressions (overrides without defaults), a uniform struct of seven
//! f32, read-only runtime arrays of structs read through `arrayLength`,
//! `distance`/`normalize`/`exp`/`log`/`pow` in loops, atomics on storage and workgroup
//! memory, 2-D and 3-D dispatches, `select` on vectors, u32 wrap-around and signed
//! division and remainder. Each runs on all six paths (the interpreter, wgpu on Vulkan
//! and GL, ash on naga's SPIR-V and on glslang's compilation of naga's GLSL and HLSL)
//! through the same code as `cargo xtask run`, and every output buffer is judged against
//! the interpreter's: integer words bit for bit, f32 words within the bound the case
//! declares, with the reason beside it. Every case also checks that the judgement fails
//! once one backend's output is corrupted (an integer word and, where there are floats,
//! a float word moved past its bound).

use strata_check::BackendSlot;
use strata_check::agreement::{FloatBound, Judgement, Tolerance, judge};
use strata_check::corpus_rng::Rng;
use strata_check::run_kernel::{BackendRun, Inputs, named_slots, run_loaded};
use strata_kernels::Kernel;
use strata_tests::corpus_support::{ONE_CASE_AT_A_TIME, assert_corruption_caught, available_slots, failures};

/// One corpus shader run.
struct Case {
    file: &'static str,
    entry: &'static str,
    overrides: Vec<(String, f64)>,
    workgroups: [u32; 3],
    inputs: Inputs,
    /// Bounds for f32 buffers (integers are always exact), each with why.
    bounds: Vec<(&'static str, FloatBound, &'static str)>,
    /// Reorders outputs whose order backends may choose (atomic slot claims).
    normalise: Option<fn(&mut BackendRun)>,
}

fn source(file: &str) -> String {
    let path = format!("{}/data/corpus/{file}", env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"))
}

fn bytes<T: bytemuck::NoUninit>(values: &[T]) -> Vec<u8> {
    bytemuck::cast_slice(values).to_vec()
}

fn run_case(case: &Case, slots: &[BackendSlot]) -> (Kernel, Vec<BackendRun>, Judgement) {
    let _turn = ONE_CASE_AT_A_TIME.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    let kernel = Kernel::from_wgsl_with_overrides(case.file, source(case.file), case.entry, false, &case.overrides)
        .unwrap_or_else(|e| panic!("{}: {e}", case.file));
    let mut runs = run_loaded(&kernel, &case.inputs, case.workgroups, slots);
    if let Some(normalise) = case.normalise {
        runs.iter_mut().for_each(normalise);
    }
    let tolerance = Tolerance {
        float: FloatBound::default(),
        per_buffer: case.bounds.iter().map(|(name, bound, _)| (name.to_string(), *bound)).collect(),
    };
    let judgement = judge(&runs, Some("cpu"), &tolerance).unwrap_or_else(|e| panic!("{}: {e}", case.file));
    for buffer in &judgement.buffers {
        eprintln!("{} {:<12} `{}`: {}", case.file, buffer.backend, buffer.name, buffer.describe());
    }
    (kernel, runs, judgement)
}

/// Runs the case, asserts every backend within tolerance, then corrupts the last
/// backend's output and asserts that the judgement catches it.
fn check(case: Case) {
    let slots = available_slots("the corpus");
    let (_, runs, judgement) = run_case(&case, &slots);
    let failures = failures(&judgement);
    assert!(failures.is_empty(), "{}:\n{}", case.file, failures.join("\n"));
    let tolerance = Tolerance {
        float: FloatBound::default(),
        per_buffer: case.bounds.iter().map(|(name, bound, _)| (name.to_string(), *bound)).collect(),
    };
    assert_corruption_caught(&runs, &tolerance, case.file);
}

#[test]
fn flocking_with_a_seven_float_uniform_and_array_length_agrees_everywhere() {
    let mut rng = Rng(11);
    let count = 1024usize;
    let mut boids = Vec::new();
    for _ in 0..count {
        boids.extend([rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), rng.range(-0.1, 0.1), rng.range(-0.1, 0.1)]);
    }
    // dt, cohesion, separation, alignment distances, their three scales (+ padding).
    let sim = [0.04f32, 0.1, 0.025, 0.025, 0.02, 0.05, 0.005, 0.0];
    check(Case {
        file: "flock2d.wgsl",
        entry: "main",
        overrides: Vec::new(),
        workgroups: [count.div_ceil(64) as u32, 1, 1],
        inputs: vec![(0, bytes(&sim)), (1, bytes(&boids)), (2, vec![0; count * 16]), (3, vec![0; count * 16])],
        bounds: vec![(
            "boids_out",
            FloatBound { ulp: 4, abs: 1.5e-8 },
            "the Vulkan paths are bit-identical to the interpreter; wgpu-gl (Mesa's GL compiler) differs by \
             up to 2 ULP of the operands, ~4e-9 at the 0.1 speed scale, which after cancellation is up to 512 \
             ULP of a velocity near 1e-4: two ULPs of 0.1 absolute (1.5e-8) cover it",
        )],
        normalise: None,
    });
}

fn life_case(overrides: Vec<(String, f64)>, tile: u32) -> Case {
    let (width, height) = (64u32, 48u32);
    let mut rng = Rng(5);
    let cells: Vec<u32> = (0..width * height).map(|_| u32::from(rng.next() % 100 < 35)).collect();
    Case {
        file: "life.wgsl",
        entry: "main",
        overrides,
        workgroups: [width.div_ceil(tile), height.div_ceil(tile), 1],
        inputs: vec![(0, bytes(&[width, height])), (1, bytes(&cells)), (2, vec![0; (width * height * 4) as usize])],
        bounds: Vec::new(),
        normalise: None,
    }
}

#[test]
fn overrides_in_workgroup_size_and_expressions_agree_everywhere() {
    // The defaults: 8 × 8 workgroups, Conway's rule.
    check(life_case(Vec::new(), 8));
    // Overridden: 4 × 4 workgroups (four times as many) and birth on 2 neighbours.
    check(life_case(vec![("tile".into(), 4.0), ("birth".into(), 2.0)], 4));
}

#[test]
fn overriding_a_constant_changes_the_result_identically() {
    let slots = available_slots("the corpus");
    let (_, default_runs, _) = run_case(&life_case(Vec::new(), 8), &slots);
    let (_, overridden, _) = run_case(&life_case(vec![("birth".into(), 2.0)], 8), &slots);
    let cells = |runs: &[BackendRun]| runs[0].outputs.as_ref().unwrap()[0].bytes.clone();
    assert_ne!(cells(&default_runs), cells(&overridden), "birth = 2 must change the generation");
    // Leaving tile at 8 with 4 × 4 dispatch sizes would leave cells unwritten: the
    // workgroup size really is the override's.
    let kernel =
        Kernel::from_wgsl_with_overrides("life.wgsl", source("life.wgsl"), "main", false, &[("tile".into(), 4.0)])
            .unwrap();
    assert_eq!(kernel.workgroup_size, [4, 4, 1]);
}

#[test]
fn bad_overrides_are_named() {
    let load = |overrides: &[(String, f64)]| {
        Kernel::from_wgsl_with_overrides("life.wgsl", source("life.wgsl"), "main", false, overrides)
            .unwrap_err()
            .to_string()
    };
    let error = load(&[("tiles".into(), 4.0)]);
    assert!(error.contains("`tiles` is not an override") && error.contains("tile, birth"), "{error}");
    let error = load(&[("tile".into(), -1.0)]);
    assert!(error.contains("tile=-1"), "{error}");
    let error = load(&[("tile".into(), 0.0)]);
    assert!(error.contains("workgroup_size"), "{error}");
    let error = load(&[("birth".into(), 2.0), ("birth".into(), 3.0)]);
    assert!(error.contains("`birth` is given twice"), "{error}");
}

#[test]
fn softmax_with_exp_agrees_within_the_precision_of_exp() {
    let (rows, columns) = (32u32, 200u32);
    let mut rng = Rng(3);
    let logits: Vec<f32> = (0..rows * columns).map(|_| rng.range(-9.0, 9.0)).collect();
    check(Case {
        file: "softmax.wgsl",
        entry: "main",
        overrides: Vec::new(),
        workgroups: [rows, 1, 1],
        inputs: vec![(0, bytes(&[rows, columns])), (1, bytes(&logits)), (2, vec![0; (rows * columns * 4) as usize])],
        bounds: vec![(
            "probabilities",
            FloatBound { ulp: 40, abs: 0.0 },
            "every GPU path is bit-identical to every other; the interpreter's exp is the platform's \
             (within 1 ULP) and lavapipe's is within Vulkan's 3 + 2|x| ULP with x = logit - max down to -18 \
             here (39 ULP); the sum and the quotient add a rounding each",
        )],
        normalise: None,
    });
}

fn transcendental_case(entry: &'static str, bounds: Vec<(&'static str, FloatBound, &'static str)>) -> Case {
    let count = 4096usize;
    let mut rng = Rng(17);
    let inputs: Vec<f32> = (0..count).map(|_| rng.range(0.05, 8.0)).collect();
    let mut buffers = vec![(0, bytes(&inputs))];
    buffers.extend((1..=5).map(|b| (b, vec![0u8; count * 4])));
    Case {
        file: "transcendentals.wgsl",
        entry,
        overrides: Vec::new(),
        workgroups: [count.div_ceil(64) as u32, 1, 1],
        inputs: buffers,
        bounds,
        normalise: None,
    }
}

/// The interpreter's bounds against lavapipe per function (docs/kernels.md, "Running your own
/// kernels"): measured on this corpus, within Vulkan's precision requirements.
const NEAR_ONE: f32 = 4.8e-7; // 2^-21: Vulkan's absolute bound for log and log2 on [0.5, 2]

#[test]
fn exp_log_and_pow_agree_within_their_stated_bounds() {
    let why = "the interpreter's functions are the platform's (within 1 ULP); lavapipe's are within \
               Vulkan's: exp and exp2 3 + 2|x| ULP, log and log2 3 ULP outside [0.5, 2] and 2^-21 \
               absolute inside, pow as exp2(y log2 x)";
    check(transcendental_case(
        "main",
        vec![
            ("exps", FloatBound { ulp: 11, abs: 0.0 }, why),
            ("logs", FloatBound { ulp: 4, abs: NEAR_ONE }, why),
            ("pows", FloatBound { ulp: 6, abs: 0.0 }, why),
            ("exp2s", FloatBound { ulp: 11, abs: 0.0 }, why),
            ("log2s", FloatBound { ulp: 4, abs: NEAR_ONE }, why),
        ],
    ));
    // Four steps of each, each step a contraction: the bounds of one step, a few times.
    check(transcendental_case(
        "iterated",
        vec![
            ("exps", FloatBound { ulp: 8, abs: 0.0 }, why),
            ("logs", FloatBound { ulp: 4, abs: 0.0 }, why),
            ("pows", FloatBound { ulp: 16, abs: 0.0 }, why),
            ("exp2s", FloatBound { ulp: 8, abs: 0.0 }, why),
            ("log2s", FloatBound { ulp: 4, abs: 0.0 }, why),
        ],
    ));
}

/// The slot each workgroup claims depends on the order workgroups run in; the values
/// must be the same multiset.
fn sort_slots(run: &mut BackendRun) {
    if let Ok(outputs) = &mut run.outputs {
        for output in outputs.iter_mut().filter(|o| o.name == "slots") {
            let mut words: Vec<u32> = bytemuck::pod_collect_to_vec(&output.bytes);
            words.sort_unstable();
            output.bytes = bytes(&words);
        }
    }
}

#[test]
fn storage_and_workgroup_atomics_are_exact_everywhere() {
    let count = 5000u32;
    let workgroups = count.div_ceil(128);
    let mut rng = Rng(23);
    let values: Vec<u32> = (0..count).map(|_| rng.next()).collect();
    let summary = [u32::MAX, 0, 0, 0, 0];
    let case = Case {
        file: "atomics.wgsl",
        entry: "main",
        overrides: Vec::new(),
        workgroups: [workgroups, 1, 1],
        inputs: vec![
            (0, bytes(&values)),
            (1, vec![0; 256]),
            (2, bytes(&summary)),
            (3, vec![0; workgroups as usize * 4]),
        ],
        bounds: Vec::new(),
        normalise: Some(sort_slots),
    };
    // The interpreter against plain Rust: the histogram, min, max, or, xor.
    let (_, runs, _) = run_case(&case, &[named_slots(&["cpu".into()]).unwrap().remove(0)]);
    let outputs = runs[0].outputs.as_ref().unwrap();
    let bins: Vec<u32> = bytemuck::pod_collect_to_vec(&outputs[0].bytes);
    let mut want = vec![0u32; 64];
    values.iter().for_each(|v| want[(v >> 26) as usize] += 1);
    assert_eq!(bins, want);
    let summary: Vec<u32> = bytemuck::pod_collect_to_vec(&outputs[1].bytes);
    let or = values.iter().fold(0, |a, v| a | (v & 0x0f0f_0f0f));
    let xor = values.iter().fold(0, |a, v| a ^ v);
    let extremes = (*values.iter().min().unwrap(), *values.iter().max().unwrap());
    assert_eq!(summary, vec![extremes.0, extremes.1, or, xor, workgroups]);
    check(case);
}

#[test]
fn a_3d_dispatch_with_wrapping_integers_and_vector_select_agrees_everywhere() {
    let dims = [13u32, 9, 7, 0x0123_4567];
    let voxels = (dims[0] * dims[1] * dims[2]) as usize;
    let case = Case {
        file: "volume.wgsl",
        entry: "main",
        overrides: Vec::new(),
        workgroups: [dims[0].div_ceil(4), dims[1].div_ceil(4), dims[2].div_ceil(4)],
        inputs: vec![(0, bytes(&dims)), (1, vec![0; voxels * 16]), (2, vec![0; voxels * 4])],
        bounds: vec![(
            "shades",
            FloatBound { ulp: 2, abs: 0.0 },
            "a three-term dot product: the HLSL path (glslang's OpDot) and Mesa's GL compiler round it \
             differently from a multiply-then-add, by up to 2 ULP",
        )],
        normalise: None,
    };
    // The interpreter against plain Rust for the integer words (WGSL's wrapping and
    // truncating semantics).
    let (_, runs, _) = run_case(&case, &[named_slots(&["cpu".into()]).unwrap().remove(0)]);
    let words: Vec<u32> = bytemuck::pod_collect_to_vec(&runs[0].outputs.as_ref().unwrap()[0].bytes);
    let hash = |v: u32| {
        let h = v.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
        let h = ((h >> ((h >> 28) + 4)) ^ h).wrapping_mul(277_803_737);
        (h >> 22) ^ h
    };
    for index in 0..voxels as u32 {
        let h = hash(index ^ dims[3]);
        let wrapped = h.wrapping_mul(0x9E37_79B9).wrapping_add(0xFFFF_FFF0);
        let shifted = wrapped << (h & 31);
        let small = h & 7;
        // WGSL: a / 0 = a, a % 0 = 0.
        let (uq, ur) = (wrapped.checked_div(small).unwrap_or(wrapped), wrapped.checked_rem(small).unwrap_or(0));
        let signed = if (h >> 8) & 15 == 0 { i32::MIN } else { h as i32 };
        let divisor = [5, -7, 0, -1][((h >> 12) & 3) as usize];
        // WGSL: a / 0 = a, a % 0 = 0, MIN / -1 = MIN, MIN % -1 = 0; otherwise truncated.
        let (q, r) = match divisor {
            0 => (signed, 0),
            d => (signed.wrapping_div(d), signed.wrapping_rem(d)),
        };
        let want = [wrapped, shifted ^ uq ^ ur, q as u32, r as u32];
        assert_eq!(&words[4 * index as usize..4 * index as usize + 4], &want, "voxel {index}");
    }
    check(case);
}

/// The scan of `scan_override.wgsl` at `wg` lanes × `items` words per lane over `groups`
/// workgroups, and the exact result (each workgroup's tile scanned on its own).
fn scan_case(wg: u32, items: u32, groups: u32) -> (Case, Vec<u32>) {
    let mut rng = Rng(41 + u64::from(wg));
    let words = (wg * items * groups) as usize;
    let input: Vec<u32> = (0..words).map(|_| rng.next()).collect();
    let mut exact = Vec::with_capacity(words);
    for tile in input.chunks((wg * items) as usize) {
        let mut sum = 0u32;
        exact.extend(tile.iter().map(|x| {
            sum = sum.wrapping_add(*x);
            sum
        }));
    }
    let case = Case {
        file: "scan_override.wgsl",
        entry: "main",
        overrides: vec![("WG".into(), f64::from(wg)), ("ITEMS".into(), f64::from(items))],
        workgroups: [groups, 1, 1],
        inputs: vec![(0, bytes(&input)), (1, vec![0; words * 4])],
        bounds: Vec::new(),
        normalise: None,
    };
    (case, exact)
}

#[test]
fn workgroup_arrays_sized_by_overrides_scan_exactly_everywhere() {
    for (wg, items, groups) in [(64, 4, 8), (48, 3, 5)] {
        let (case, exact) = scan_case(wg, items, groups);
        // The interpreter alone against the exact scan: with no GPU the check below
        // compares it only with itself.
        let cpu = named_slots(&["cpu".to_string()]).unwrap();
        let (kernel, runs, _) = run_case(&case, &cpu);
        assert_eq!(kernel.workgroup_memory_bytes(), u64::from(4 * (2 * wg + wg * items)));
        let output = &runs[0].outputs.as_ref().expect("the interpreter ran")[0];
        assert!(output.bytes == bytes(&exact), "wg {wg}, items {items}: the interpreter's scan is not exact");
        check(scan_case(wg, items, groups).0);
    }
}

/// Workgroup memory read before any write must be zero on every path (WGSL's promise):
/// a counter nobody initialises, the unwritten rows of a 2-D array of vectors, a struct
/// with an array member. The glslang HLSL path once skipped the zeroing (a count of
/// 1690510940 instead of 64) and Slang refused naga's zeroing of the 2-D array; both now
/// get loops (`strata_kernels::hlsl_zero_init`).
#[test]
fn workgroup_memory_starts_zeroed_everywhere() {
    let groups = 4u32;
    let case = Case {
        file: "workgroup_zeroing.wgsl",
        entry: "main",
        overrides: Vec::new(),
        workgroups: [groups, 1, 1],
        inputs: vec![(0, vec![0xAB; (groups * 3 * 4) as usize]), (1, vec![0xAB; (groups * 4) as usize])],
        bounds: Vec::new(),
        normalise: None,
    };
    let slots = available_slots("the corpus");
    let (_, runs, judgement) = run_case(&case, &slots);
    let failures = failures(&judgement);
    assert!(failures.is_empty(), "{}:\n{}", case.file, failures.join("\n"));
    let counts: &[u32] = bytemuck::cast_slice(&runs[0].outputs.as_ref().unwrap()[0].bytes);
    assert_eq!(counts, [64, 0, 16].repeat(groups as usize), "the interpreter itself");
    let untouched: &[f32] = bytemuck::cast_slice(&runs[0].outputs.as_ref().unwrap()[1].bytes);
    assert_eq!(untouched, vec![0.0; groups as usize]);
    assert_corruption_caught(&runs, &Tolerance::default(), case.file);
}

/// The same kernel on ash with naga's SPIR-V where the shader zeroes its workgroup memory
/// itself, in the loops `strata_kernels::translate` writes into naga's IR (what an engine
/// gets from the kernel package, and the embed pass on a device without the driver's
/// zeroing). lavapipe offers the driver's zeroing, which the ash column of the test above
/// takes, so without this test those loops would run on no device here.
#[test]
fn workgroup_memory_starts_zeroed_when_the_shader_zeroes_it() {
    use strata_backends::Backend;
    use strata_backends::ash_backend::{AshBackend, AshOptions, SpirvSource};
    use strata_backends::backend::{download, upload};
    let test = "workgroup_memory_starts_zeroed_when_the_shader_zeroes_it";
    let options = AshOptions {
        source: SpirvSource::Naga,
        pipeline_cache: None,
        driver_zeroes_workgroup_memory: false,
        ..Default::default()
    };
    let mut backend = match AshBackend::new(options) {
        Ok(backend) => backend,
        Err(error) if !strata_backends::gpu_required() => {
            eprintln!("SKIPPED {test}: {error}");
            return;
        }
        Err(error) => panic!("{test}: {error}"),
    };
    let file = "workgroup_zeroing.wgsl";
    let kernel = Kernel::from_wgsl(file, source(file), "main", false).unwrap_or_else(|e| panic!("{file}: {e}"));
    let groups = 4u32;
    let counts = upload(&mut backend, "counts", &vec![0xABAB_ABABu32; (groups * 3) as usize]).unwrap();
    let untouched = upload(&mut backend, "untouched", &vec![0xABAB_ABABu32; groups as usize]).unwrap();
    let binds = [strata_backends::Bind::new(0, counts), strata_backends::Bind::new(1, untouched)];
    // Twice: a second dispatch finds the workgroup memory the first one left.
    for run in 0..2 {
        backend.dispatch(&kernel, &binds, [groups, 1, 1]).unwrap();
        let got: Vec<u32> = download(&mut backend, counts).unwrap();
        assert_eq!(got, [64, 0, 16].repeat(groups as usize), "run {run}: counts");
        let got: Vec<u32> = download(&mut backend, untouched).unwrap();
        assert_eq!(got, vec![0.0f32.to_bits(); groups as usize], "run {run}: the unwritten rows");
    }
}

/// Private and function `var`s without an initialiser must start zeroed on every path:
/// private arrays (1-D, a non-square array of arrays, of structs), a private struct with
/// an array member, and function-local arrays of arrays in the entry point and a helper.
/// glslang refused naga's HLSL zeroing (`(uint[8])0`) of every such array and Slang the
/// non-square ones, so both HLSL paths failed; they now get loops
/// (`strata_kernels::hlsl_zero_init`).
#[test]
fn private_and_function_arrays_start_zeroed_everywhere() {
    let invocations = 32u32;
    let case = Case {
        file: "private_zeroing.wgsl",
        entry: "main",
        overrides: Vec::new(),
        workgroups: [invocations / 16, 1, 1],
        inputs: vec![(0, vec![0xAB; (invocations * 4) as usize]), (1, vec![0xAB; (invocations * 4) as usize])],
        bounds: Vec::new(),
        normalise: None,
    };
    let slots = available_slots("the corpus");
    let (_, runs, judgement) = run_case(&case, &slots);
    let failures = failures(&judgement);
    assert!(failures.is_empty(), "{}:\n{}", case.file, failures.join("\n"));
    let sums: &[u32] = bytemuck::cast_slice(&runs[0].outputs.as_ref().unwrap()[0].bytes);
    let exact: Vec<u32> = (0..invocations).map(|i| 2 * i + 16).collect();
    assert_eq!(sums, exact, "the interpreter itself");
    let weights: &[f32] = bytemuck::cast_slice(&runs[0].outputs.as_ref().unwrap()[1].bytes);
    assert_eq!(weights, vec![1.75; invocations as usize]);
    assert_corruption_caught(&runs, &Tolerance::default(), case.file);
}
