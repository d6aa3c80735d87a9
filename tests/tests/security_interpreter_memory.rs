//! The CPU interpreter's own memory (private, function and workgroup variables, the
//! module's constants) is capped: a kernel asking for more is refused with an error
//! naming the kernel, the memory space, the size and the cap, where it once aborted the
//! process ("memory allocation failed"). The backend keeps working afterwards.

use strata_backends::backend::{download, upload};
use strata_backends::cpu_backend::{CpuBackend, CpuOptions};
use strata_backends::{Backend, BackendError, Bind};
use strata_kernels::Kernel;

/// Dispatches `source` (its `main`, one binding `data`) on 64 one-invocation
/// workgroups (one batch of 64 invocations before the caps); the error.
fn refusal(source: &str) -> BackendError {
    let kernel = Kernel::from_wgsl("memory.wgsl", source.into(), "main", false).expect("valid WGSL");
    let mut cpu = CpuBackend::new(CpuOptions::default()).unwrap();
    let data = upload(&mut cpu, "data", &[5u32; 64]).unwrap();
    let error = cpu.dispatch(&kernel, &[Bind::new(0, data)], [64, 1, 1]).expect_err("refused");
    // Nothing ran, nothing was lost, and the backend still runs kernels.
    assert_eq!(download::<u32>(&mut cpu, data).unwrap(), [5; 64]);
    let small = Kernel::from_wgsl(
        "small.wgsl",
        "@group(0) @binding(0) var<storage, read_write> data: array<u32>;
         @compute @workgroup_size(4) fn main(@builtin(global_invocation_id) id: vec3<u32>) {
             data[id.x] += 1u;
         }"
        .into(),
        "main",
        false,
    )
    .unwrap();
    cpu.dispatch(&small, &[Bind::new(0, data)], [16, 1, 1]).unwrap();
    assert_eq!(download::<u32>(&mut cpu, data).unwrap(), [6; 64]);
    error
}

#[test]
fn a_private_array_beyond_the_cap_is_refused_not_aborted() {
    let error = refusal(
        "@group(0) @binding(0) var<storage, read_write> data: array<u32>;
         var<private> big: array<u32, 100000000>;
         @compute @workgroup_size(1) fn main(@builtin(global_invocation_id) id: vec3<u32>) {
             big[id.x + 7u] = data[id.x];
             data[id.x] = big[id.x + 7u] + 1u;
         }",
    );
    assert_eq!(
        error.to_string(),
        "cpu: out of memory in kernel `main`: 400000000 bytes of private memory per invocation, \
         more than the interpreter's 64 MiB cap"
    );
}

#[test]
fn a_function_array_beyond_the_cap_is_refused() {
    let error = refusal(
        "@group(0) @binding(0) var<storage, read_write> data: array<u32>;
         @compute @workgroup_size(1) fn main(@builtin(global_invocation_id) id: vec3<u32>) {
             var big: array<u32, 100000000>;
             big[id.x + 7u] = data[id.x];
             data[id.x] = big[id.x + 7u] + 1u;
         }",
    );
    let message = error.to_string();
    assert!(message.starts_with("cpu: out of memory in kernel `main`: "), "{message}");
    assert!(message.contains("bytes of function memory per invocation"), "{message}");
    assert!(message.ends_with("more than the interpreter's 64 MiB cap"), "{message}");
}

#[test]
fn an_unused_workgroup_array_beyond_the_cap_is_refused() {
    // The device's workgroup limit counts what the entry point uses; the interpreter
    // lays out every workgroup variable, so it caps them all.
    let error = refusal(
        "@group(0) @binding(0) var<storage, read_write> data: array<u32>;
         var<workgroup> big: array<u32, 100000000>;
         @compute @workgroup_size(1) fn main(@builtin(global_invocation_id) id: vec3<u32>) {
             data[id.x] += 1u;
         }
         @compute @workgroup_size(1) fn other(@builtin(global_invocation_id) id: vec3<u32>) {
             big[id.x] = 1u;
         }",
    );
    assert_eq!(
        error.to_string(),
        "cpu: out of memory in kernel `main`: 400000000 bytes of workgroup memory per workgroup, \
         more than the interpreter's 64 MiB cap"
    );
}

#[test]
fn a_constant_beyond_the_cap_is_refused() {
    let error = refusal(
        "@group(0) @binding(0) var<storage, read_write> data: array<u32>;
         var<private> big: array<u32, 100000000> = array<u32, 100000000>();
         @compute @workgroup_size(1) fn main(@builtin(global_invocation_id) id: vec3<u32>) {
             data[id.x] = big[id.x] + 1u;
         }",
    );
    let message = error.to_string();
    assert!(message.starts_with("cpu: out of memory in kernel `main`: 400000000 bytes of "), "{message}");
    assert!(message.ends_with("more than the interpreter's 64 MiB cap"), "{message}");
}

#[test]
fn a_workgroup_whose_invocations_together_pass_the_batch_cap_is_refused() {
    // 16 MiB of private memory per invocation is within the cap, but a workgroup of 64
    // such invocations holds more than a batch may.
    let error = refusal(
        "@group(0) @binding(0) var<storage, read_write> data: array<u32>;
         var<private> big: array<u32, 4194304>;
         @compute @workgroup_size(64) fn main(@builtin(global_invocation_id) id: vec3<u32>) {
             big[id.x] = data[id.x];
             data[id.x] = big[id.x] + 1u;
         }",
    );
    let message = error.to_string();
    assert!(message.starts_with("cpu: out of memory in kernel `main`: "), "{message}");
    assert!(
        message.contains("bytes of private, function and workgroup memory for a workgroup of 64 invocations"),
        "{message}"
    );
    assert!(message.ends_with("more than the interpreter's 1 GiB cap"), "{message}");
}

#[test]
fn private_memory_within_the_cap_runs_in_smaller_batches() {
    // 32 MiB per invocation: a batch of 512 one-invocation workgroups would take 16 GiB,
    // so the batches shrink to the interpreter's batch cap instead; every workgroup runs.
    let kernel = Kernel::from_wgsl(
        "within.wgsl",
        "@group(0) @binding(0) var<storage, read_write> data: array<u32>;
         var<private> big: array<u32, 8388608>;
         @compute @workgroup_size(1) fn main(@builtin(global_invocation_id) id: vec3<u32>) {
             big[8388607u - id.x] = data[id.x];
             data[id.x] = big[8388607u - id.x] * 2u + big[id.x];
         }"
        .into(),
        "main",
        false,
    )
    .unwrap();
    let mut cpu = CpuBackend::new(CpuOptions::default()).unwrap();
    let input: Vec<u32> = (0..40).collect();
    let data = upload(&mut cpu, "data", &input).unwrap();
    cpu.dispatch(&kernel, &[Bind::new(0, data)], [40, 1, 1]).unwrap();
    assert_eq!(download::<u32>(&mut cpu, data).unwrap(), input.iter().map(|x| x * 2).collect::<Vec<_>>());
}
