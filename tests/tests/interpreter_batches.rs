//! The interpreter runs the workgroups of a kernel without barriers or subgroup
//! operations several at a time, as one batch (backends/src/cpu_backend/batch.rs). What
//! a kernel can observe must not change: each workgroup keeps its own zeroed workgroup
//! memory and its own builtins, and the SIMT issue count stays per workgroup.

use strata_backends::cpu_backend::{CpuBackend, CpuOptions, DispatchCounts};
use strata_kernels::Kernel;
use strata_tests::run_words;

/// 48 invocations per workgroup: not a multiple of the 32-wide warps of the issue count,
/// and ten of them to a batch of at most 512 invocations.
const WORKGROUP: u32 = 48;

/// Each invocation reads its slot of workgroup memory (zero at the start of every
/// workgroup), writes a value naming its workgroup and lane, adds to it in a loop of
/// `input[lane]` turns (so the lanes diverge) and writes what it reads back.
const SOURCE: &str = r#"
@group(0) @binding(0) var<storage, read> input: array<u32>;
@group(0) @binding(1) var<storage, read_write> output: array<u32>;
var<workgroup> slots: array<u32, 48>;

@compute @workgroup_size(48)
fn main(
    @builtin(local_invocation_index) i: u32,
    @builtin(workgroup_id) workgroup: vec3<u32>,
    @builtin(global_invocation_id) global: vec3<u32>,
) {
    let before = slots[i];
    slots[i] = workgroup.x * 1000u + i + 1u;
    for (var k = 0u; k < input[i]; k++) {
        slots[i] += k;
    }
    output[global.x] = before * 1000000u + slots[i];
}
"#;

/// The loop's turns per lane: 0 to 12, unequal neighbours.
fn turns() -> Vec<u32> {
    (0..WORKGROUP).map(|i| (i * 7) % 13).collect()
}

/// What `SOURCE` writes for `workgroups` workgroups.
fn expected(workgroups: u32) -> Vec<u32> {
    let turns = turns();
    (0..workgroups * WORKGROUP)
        .map(|g| {
            let (workgroup, i) = (g / WORKGROUP, g % WORKGROUP);
            workgroup * 1000 + i + 1 + (0..turns[i as usize]).sum::<u32>()
        })
        .collect()
}

/// Outputs and counts of one dispatch of `workgroups` workgroups.
fn run(cpu: &mut CpuBackend, kernel: &Kernel, workgroups: u32) -> (Vec<u32>, DispatchCounts) {
    let words = run_words(cpu, kernel, &turns(), (workgroups * WORKGROUP) as usize, workgroups);
    let counts = cpu.take_counts_by_kernel();
    assert_eq!(counts.len(), 1, "one kernel dispatched");
    (words, counts[&kernel.id])
}

#[test]
fn batched_workgroups_keep_their_own_memory_builtins_and_warps() {
    let kernel = Kernel::from_wgsl("batches.wgsl", SOURCE.into(), "main", false).unwrap();
    let mut cpu = CpuBackend::new(CpuOptions::default()).unwrap();
    // 23 workgroups: batches of 10, 10 and 3 (the last one narrower than its files).
    let (words, counts) = run(&mut cpu, &kernel, 23);
    let want = expected(23);
    if let Some(g) = (0..want.len()).find(|&g| words[g] != want[g]) {
        panic!("invocation {g}: {} where {} was expected", words[g], want[g]);
    }
    // Every workgroup runs the same instructions (the turns depend on the lane only), so
    // 23 of them cost 23 times one, in instructions and in warp issues: a batch must not
    // put two workgroups' invocations in one 32-wide warp.
    let (one_words, one) = run(&mut cpu, &kernel, 1);
    assert_eq!(one_words, expected(1));
    assert_eq!(counts.instructions, 23 * one.instructions, "{counts:?} vs 23 x {one:?}");
    assert_eq!(counts.warp_issues, 23 * one.warp_issues, "{counts:?} vs 23 x {one:?}");
}
