//! Fuzzing the CPU interpreter with generated integer-only WGSL programs: none may make it
//! crash, and every result must agree with lavapipe bit for bit.

use strata_backends::backend::{download, upload};
use strata_backends::cpu_backend::{CpuBackend, CpuOptions};
use strata_backends::{Backend, Bind};
use strata_kernels::Kernel;
use strata_tests::wgsl_fuzz::integer_program;

fn run(backend: &mut dyn Backend, kernel: &Kernel, inputs: &[u32]) -> Vec<u32> {
    let input = upload(backend, "input", inputs).unwrap();
    let output = backend.create_buffer("output", (inputs.len() * 4) as u64).unwrap();
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

#[test]
fn generated_programs_use_every_construct() {
    let programs: String = (0..40).map(integer_program).collect();
    for construct in ["for (var", "switch", "if ", "/ ", "% ", "<<", ">>", "select(", "firstLeadingBit", "bitcast<i32>"]
    {
        assert!(programs.contains(construct), "no `{construct}` in 40 generated programs");
    }
}
