//! Fuzzing the CPU interpreter with generated WGSL programs: none may make it crash or
//! hang; integer programs, exact-mode float programs and barrier programs must agree
//! with lavapipe bit for bit, general float programs only roughly (reported).

use strata_backends::backend::{download, upload};
use strata_backends::cpu_backend::{CpuBackend, CpuOptions};
use strata_backends::{Backend, Bind};
use strata_kernels::Kernel;
use strata_tests::wgsl_fuzz::{FloatMode, TOTALS, barrier_program, float_program, integer_program};

fn run(backend: &mut dyn Backend, kernel: &Kernel, inputs: &[u32]) -> Vec<u32> {
    run_sized(backend, kernel, inputs, inputs.len())
}

/// Runs `kernel` with `inputs` at binding 0 and `output_words` words at binding 1, one
/// invocation per 4 input words (workgroups of 64).
fn run_sized(backend: &mut dyn Backend, kernel: &Kernel, inputs: &[u32], output_words: usize) -> Vec<u32> {
    let input = upload(backend, "input", inputs).unwrap();
    let output = backend.create_buffer("output", (output_words * 4) as u64).unwrap();
    backend
        .dispatch(kernel, &[Bind::new(0, input), Bind::new(1, output)], [(inputs.len() / 256) as u32, 1, 1])
        .unwrap();
    let words = download(backend, output).unwrap();
    backend.destroy_buffer(input).unwrap();
    backend.destroy_buffer(output).unwrap();
    words
}

#[test]
fn generated_integer_programs_agree_with_lavapipe() {
    let seeds: u64 = std::env::var("STRATA_FUZZ_PROGRAMS").ok().and_then(|v| v.parse().ok()).unwrap_or(40);
    let mut cpu = CpuBackend::new(CpuOptions::default()).unwrap();
    let mut gpu = strata_tests::vulkan_backend("generated_integer_programs_agree_with_lavapipe");
    let mut inputs: Vec<u32> = vec![0, 1, 0xffff_ffff, 0x8000_0000, 0x7fff_ffff, 31, 32, 2];
    let mut state = 0x9e37_79b9_u32;
    while inputs.len() < 256 {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        inputs.push(state);
    }
    for seed in 0..seeds {
        let source = integer_program(seed);
        let kernel = Kernel::from_wgsl(&format!("fuzz-{seed}.wgsl"), source.clone(), "main", false)
            .unwrap_or_else(|e| panic!("generated program {seed} is invalid WGSL: {e}\n{source}"));
        let got = run(&mut cpu, &kernel, &inputs);
        if let Some(gpu) = gpu.as_mut() {
            let want = run(gpu, &kernel, &inputs);
            if let Some(i) = (0..want.len()).find(|&i| got[i] != want[i]) {
                panic!(
                    "program {seed}: output[{i}] = {:#x} on the interpreter, {:#x} on lavapipe\n{source}",
                    got[i], want[i]
                );
            }
        }
    }
}

/// How many programs each fuzz test generates: `STRATA_FUZZ_PROGRAMS` or `default`.
fn program_count(default: u64) -> u64 {
    std::env::var("STRATA_FUZZ_PROGRAMS").ok().and_then(|v| v.parse().ok()).unwrap_or(default)
}

/// Seconds a generated program may take on the interpreter before the test calls it a hang.
const HANG_SECONDS: u64 = 30;

/// Runs `source` on the interpreter in a thread of its own: the dispatch must return Ok,
/// neither panic nor take longer than [`HANG_SECONDS`]. Returns the backend for reuse.
fn interpret_guarded(
    cpu: CpuBackend,
    seed: u64,
    source: &str,
    inputs: &[u32],
    output_words: usize,
) -> (CpuBackend, Vec<u32>) {
    let (sender, receiver) = std::sync::mpsc::channel();
    let (source_copy, inputs) = (source.to_string(), inputs.to_vec());
    std::thread::spawn(move || {
        let mut cpu = cpu;
        let result = (|| {
            let kernel = Kernel::from_wgsl(&format!("fuzz-{seed}.wgsl"), source_copy, "main", false)
                .map_err(|e| format!("invalid WGSL: {e}"))?;
            let input = upload(&mut cpu, "input", &inputs).map_err(|e| e.to_string())?;
            let output = cpu.create_buffer("output", (output_words * 4) as u64).map_err(|e| e.to_string())?;
            let binds = [Bind::new(0, input), Bind::new(1, output)];
            cpu.dispatch(&kernel, &binds, [(inputs.len() / 256) as u32, 1, 1])
                .map_err(|e| format!("dispatch failed: {e}"))?;
            let words = download(&mut cpu, output).map_err(|e| e.to_string())?;
            cpu.destroy_buffer(input).map_err(|e| e.to_string())?;
            cpu.destroy_buffer(output).map_err(|e| e.to_string())?;
            Ok::<_, String>(words)
        })();
        let _ = sender.send((cpu, result));
    });
    match receiver.recv_timeout(std::time::Duration::from_secs(HANG_SECONDS)) {
        Ok((cpu, Ok(words))) => (cpu, words),
        Ok((_, Err(error))) => panic!("program {seed} on the interpreter: {error}\n{source}"),
        Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {
            panic!("program {seed} hangs the interpreter (> {HANG_SECONDS} s)\n{source}")
        }
        Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => {
            panic!("program {seed} panics the interpreter (message above)\n{source}")
        }
    }
}

/// Float inputs: signed zeros, denormals, NaNs (quiet and signalling, both signs),
/// infinities, the extremes of the normal range, values around 2^24, then random bit
/// patterns and random moderate values. `finite`: NaNs and infinities left out.
fn float_inputs(words: usize, finite: bool) -> Vec<u32> {
    let special: [u32; 24] = [
        0x0000_0000,
        0x8000_0000,
        0x3f80_0000,
        0xbf80_0000,
        0x0000_0001,
        0x8000_0001,
        0x007f_ffff,
        0x0080_0000,
        0x7f7f_ffff,
        0xff7f_ffff,
        0x3f00_0000,
        0x4b80_0000,
        0x4b80_0001,
        0xcb7f_ffff,
        0x0d80_0000,
        0x4049_0fdb,
        0x7fc0_0000,
        0xffc0_0000,
        0x7f80_0001,
        0x7f80_0000,
        0xff80_0000,
        0x7fff_ffff,
        0xd01502f9,
        0x3eaa_aaab,
    ];
    let is_special = |w: u32| w & 0x7f80_0000 == 0x7f80_0000;
    let mut inputs: Vec<u32> = special.iter().copied().filter(|&w| !(finite && is_special(w))).collect();
    let mut state = 0x2545_f491_u32;
    while inputs.len() < words {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        let word = match state % 3 {
            0 => state.rotate_left(7),
            _ => ((state >> 8) as f32 / (1 << 24) as f32 * 200.0 - 100.0).to_bits(),
        };
        if !(finite && is_special(word)) {
            inputs.push(word);
        }
    }
    inputs
}

/// Bit equality, except that +0 and −0 count as equal: lavapipe does not preserve the
/// sign of zero (Vulkan lets it without `SignedZeroInfNanPreserve`): it folds
/// `f32(i32(x))` into `trunc(x)` (−0 for x in (−1, 0) where IEEE gives +0) and
/// `clamp(-0.0, lo, hi)` gives +0. No exact-mode operation turns the sign of a zero into
/// a different non-zero value (no division by a possible zero), so this hides nothing else.
fn same_up_to_zero_sign(a: u32, b: u32) -> bool {
    a == b || (a | b) & 0x7fff_ffff == 0
}

#[test]
fn generated_exact_float_programs_agree_with_lavapipe_bit_for_bit() {
    let mut cpu = CpuBackend::new(CpuOptions::default()).unwrap();
    let mut gpu = strata_tests::vulkan_backend("generated_exact_float_programs_agree_with_lavapipe_bit_for_bit");
    let mut inputs = float_inputs(512, true);
    *inputs.last_mut().unwrap() = 0; // the key of `o(x)`
    for seed in 0..program_count(40) {
        let source = float_program(seed, FloatMode::Exact);
        let got;
        (cpu, got) = interpret_guarded(cpu, seed, &source, &inputs, 1024);
        if let Some(gpu) = gpu.as_mut() {
            let kernel = Kernel::from_wgsl(&format!("exact-{seed}.wgsl"), source.clone(), "main", false).unwrap();
            let want = run_sized(gpu, &kernel, &inputs, 1024);
            if let Some(i) = (0..want.len()).find(|&i| !same_up_to_zero_sign(got[i], want[i])) {
                let input = &inputs[i / 8 * 4..i / 8 * 4 + 4];
                panic!(
                    "exact program {seed}: output[{i}] = {:#010x} ({}) on the interpreter, {:#010x} ({}) on \
                     lavapipe; inputs {input:#010x?}\n{source}",
                    got[i],
                    f32::from_bits(got[i]),
                    want[i],
                    f32::from_bits(want[i])
                );
            }
        }
    }
}

/// Whether two f32 bit patterns agree loosely: equal, both NaN, or within 16 ULPs.
fn roughly_equal(a: u32, b: u32) -> bool {
    let (x, y) = (f32::from_bits(a), f32::from_bits(b));
    if a == b || (x.is_nan() && y.is_nan()) {
        return true;
    }
    if x.is_nan() || y.is_nan() || x.is_sign_negative() != y.is_sign_negative() {
        return x == y;
    }
    a.abs_diff(b) <= 16
}

#[test]
fn generated_general_float_programs_never_crash_the_interpreter() {
    let mut cpu = CpuBackend::new(CpuOptions::default()).unwrap();
    let mut gpu = strata_tests::vulkan_backend("generated_general_float_programs_never_crash_the_interpreter");
    let inputs = float_inputs(512, false);
    let (mut agree, mut total, mut identical_programs) = (0usize, 0usize, 0u64);
    let count = program_count(60);
    for seed in 0..count {
        let source = float_program(seed, FloatMode::General);
        let got;
        (cpu, got) = interpret_guarded(cpu, seed, &source, &inputs, 1024);
        if let Some(gpu) = gpu.as_mut() {
            let kernel = Kernel::from_wgsl(&format!("general-{seed}.wgsl"), source.clone(), "main", false).unwrap();
            let want = run_sized(gpu, &kernel, &inputs, 1024);
            agree += got.iter().zip(&want).filter(|&(&g, &w)| roughly_equal(g, w)).count();
            total += want.len();
            identical_programs += u64::from(got == want);
        }
    }
    if total > 0 {
        // NaN comparisons, transcendentals of huge arguments and signed zeros from min/max
        // legitimately differ; the share is reported, and only a collapse fails the test.
        eprintln!(
            "general float programs: {agree} of {total} outputs ({:.1}%) within 16 ULP of lavapipe (NaN = NaN), \
             {identical_programs} of {count} programs bit-identical",
            agree as f64 * 100.0 / total as f64
        );
        assert!(agree * 2 > total, "fewer than half the outputs agree with lavapipe");
    }
}

/// Runs a [`barrier_program`] on `groups` workgroups of `size`: (output, totals).
fn run_barrier(backend: &mut dyn Backend, kernel: &Kernel, size: u32, groups: u32) -> (Vec<u32>, Vec<u32>) {
    let n = (size * groups) as usize;
    let mut state = 0x1234_5678_u32 ^ size;
    let inputs: Vec<u32> = (0..n)
        .map(|_| {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            state
        })
        .collect();
    let initial: Vec<u32> = TOTALS.iter().map(|&(_, value)| value).collect();
    let input = upload(backend, "input", &inputs).unwrap();
    let output = backend.create_buffer("output", (n * 8) as u64).unwrap();
    let totals = upload(backend, "totals", &initial).unwrap();
    backend
        .dispatch(kernel, &[Bind::new(0, input), Bind::new(1, output), Bind::new(2, totals)], [groups, 1, 1])
        .unwrap();
    let result = (download(backend, output).unwrap(), download(backend, totals).unwrap());
    for buffer in [input, output, totals] {
        backend.destroy_buffer(buffer).unwrap();
    }
    result
}

#[test]
fn generated_barrier_programs_agree_with_lavapipe() {
    let mut cpu = CpuBackend::new(CpuOptions::default()).unwrap();
    let mut gpu = strata_tests::vulkan_backend("generated_barrier_programs_agree_with_lavapipe");
    for seed in 0..program_count(40) {
        let (source, size) = barrier_program(seed);
        let groups = 1 + (seed % 4) as u32;
        let kernel = Kernel::from_wgsl(&format!("barrier-{seed}.wgsl"), source.clone(), "main", false)
            .unwrap_or_else(|e| panic!("barrier program {seed} is invalid WGSL: {e}\n{source}"));
        let got = run_barrier(&mut cpu, &kernel, size, groups);
        if let Some(gpu) = gpu.as_mut() {
            let want = run_barrier(gpu, &kernel, size, groups);
            if let Some(i) = (0..want.0.len()).find(|&i| got.0[i] != want.0[i]) {
                panic!(
                    "barrier program {seed} (S = {size}, {groups} groups): output[{i}] = {:#x} on the interpreter, \
                     {:#x} on lavapipe\n{source}",
                    got.0[i], want.0[i]
                );
            }
            assert_eq!(got.1, want.1, "barrier program {seed} (S = {size}, {groups} groups): totals\n{source}");
        }
    }
}

#[test]
fn generated_programs_use_every_construct() {
    let programs: String = (0..40).map(integer_program).collect();
    for construct in ["for (var", "switch", "if ", "/ ", "% ", "<<", ">>", "select(", "firstLeadingBit", "bitcast<i32>"]
    {
        assert!(programs.contains(construct), "no `{construct}` in 40 generated programs");
    }
    let exact: String = (0..40).map(|seed| float_program(seed, FloatMode::Exact)).collect();
    for construct in [
        " + ",
        " - ",
        " * ",
        " / o(abs(",
        "sqrt(abs(",
        "min(",
        "max(",
        "floor(",
        "ceil(",
        "trunc(",
        "round(",
        "select(",
        " < ",
        " >= ",
        " == ",
        " != ",
        "f32(i32(",
        "f32(u32(",
        "& 0xffff0000u",
        "loop {",
        "for (var",
        "if ",
    ] {
        assert!(exact.contains(construct), "no `{construct}` in 40 exact float programs");
    }
    for construct in ["exp(", "log(", "sin(", "cos(", "pow(", "atan2("] {
        assert!(!exact.contains(construct), "`{construct}` in an exact float program");
    }
    let barrier: String = (0..40).map(|seed| barrier_program(seed).0).collect();
    for construct in [
        "workgroupBarrier()",
        "storageBarrier()",
        "workgroupUniformLoad(",
        "atomicCompareExchangeWeak(",
        "atomicAdd(&counters",
        "atomicMax(&counters",
        "atomicMin(&counters",
        "atomicXor(&counters",
        "atomicAdd(&totals",
        "atomicMax(&totals",
        "atomicMin(&totals",
        "atomicXor(&totals",
        "for (var s = ",
        "@workgroup_size(S)",
        "const S: u32 = 1u;",
        "const S: u32 = 256u;",
    ] {
        assert!(barrier.contains(construct), "no `{construct}` in 40 barrier programs");
    }
    let general: String = (0..200).map(|seed| float_program(seed, FloatMode::General)).collect();
    for construct in [
        "sqrt(",
        "exp(",
        "log(",
        "sin(",
        "cos(",
        "pow(",
        "min(",
        "max(",
        "clamp(",
        "floor(",
        "fract(",
        "abs(",
        "sign(",
        "mix(",
        "fma(",
        "length(w)",
        "normalize(w)",
        "dot(w",
        "f32(i32(",
        "f32(u32(",
        "bitcast<f32>(",
        "select(",
        "w = ",
        "n ^= i32(",
        "loop {",
        "3.4e38f",
    ] {
        assert!(general.contains(construct), "no `{construct}` in 200 general float programs");
    }
}

/// The f32 math builtins the float fuzzer would use, each in a one-line kernel: the
/// interpreter must run every one of them (a typed "unsupported" error is a gap).
const FLOAT_BUILTINS: &[&str] = &[
    "sqrt(x)",
    "inverseSqrt(x)",
    "exp(x)",
    "exp2(x)",
    "log(x)",
    "log2(x)",
    "sin(x)",
    "cos(x)",
    "tan(x)",
    "asin(x)",
    "acos(x)",
    "atan(x)",
    "sinh(x)",
    "cosh(x)",
    "tanh(x)",
    "asinh(x)",
    "acosh(x)",
    "atanh(x)",
    "floor(x)",
    "ceil(x)",
    "round(x)",
    "trunc(x)",
    "fract(x)",
    "abs(x)",
    "sign(x)",
    "saturate(x)",
    "degrees(x)",
    "radians(x)",
    "pow(x, y)",
    "min(x, y)",
    "max(x, y)",
    "atan2(x, y)",
    "step(x, y)",
    "clamp(x, y, 2.0f)",
    "mix(x, y, 0.25f)",
    "fma(x, y, x)",
    "smoothstep(0.0f, 1.0f, x)",
    "ldexp(x, i32(y) & 15)",
    "modf(x).fract",
    "frexp(x).fract",
    "f32(frexp(x).exp)",
    "quantizeToF16(x)",
    "length(vec3<f32>(x, y, 1.0f))",
    "distance(vec2<f32>(x, y), vec2<f32>(y, x))",
    "normalize(vec2<f32>(x, y)).x",
    "dot(vec3<f32>(x, y, 1.0f), vec3<f32>(y, x, 2.0f))",
    "cross(vec3<f32>(x, y, 1.0f), vec3<f32>(y, 2.0f, x)).z",
    "reflect(vec2<f32>(x, y), vec2<f32>(0.6f, 0.8f)).x",
    "faceForward(vec2<f32>(x, y), vec2<f32>(y, x), vec2<f32>(1.0f, 0.0f)).x",
    "refract(vec2<f32>(x, y), vec2<f32>(0.6f, 0.8f), 0.5f).y",
    "determinant(mat2x2<f32>(x, y, y, x))",
];

/// Which of [`FLOAT_BUILTINS`] the interpreter rejects.
fn unsupported_float_builtins() -> Vec<String> {
    let mut cpu = CpuBackend::new(CpuOptions::default()).unwrap();
    let inputs: Vec<u32> = (0..256).map(|i| (i as f32 * 0.37 - 20.0).to_bits()).collect();
    let mut unsupported = Vec::new();
    for call in FLOAT_BUILTINS {
        let source = format!(
            "@group(0) @binding(0) var<storage, read> input: array<u32>;
@group(0) @binding(1) var<storage, read_write> output: array<u32>;
@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {{
    let x = bitcast<f32>(input[id.x * 4u]);
    let y = bitcast<f32>(input[id.x * 4u + 1u]);
    output[id.x * 4u] = bitcast<u32>({call});
}}
"
        );
        let kernel = Kernel::from_wgsl("builtin.wgsl", source, "main", false).unwrap_or_else(|e| panic!("{call}: {e}"));
        let input = upload(&mut cpu, "input", &inputs).unwrap();
        let output = cpu.create_buffer("output", 1024).unwrap();
        if let Err(error) = cpu.dispatch(&kernel, &[Bind::new(0, input), Bind::new(1, output)], [1, 1, 1]) {
            unsupported.push(format!("{call}: {error}"));
        }
    }
    unsupported
}

#[test]
fn every_float_math_builtin_runs_on_the_interpreter() {
    let unsupported = unsupported_float_builtins();
    assert!(unsupported.is_empty(), "the interpreter rejects:\n{}", unsupported.join("\n"));
}
