//! Several workgroups run as one wide batch, where the kernel cannot tell (one
//! exception below).
//!
//! Why: a divergent kernel's workgroup ends with a few invocations still looping (the
//! path tracer's longest BVH walks), and the group loop of [`super::interp`] then decodes
//! every instruction for one to seven members: on the path tracer, 61 % of the group
//! instructions of a 128^2 frame ran for fewer than eight invocations. The stragglers of
//! several workgroups stand in the same loop, so in one batch they run as one group.
//!
//! When: a kernel sees its workgroup through barriers, subgroup operations and
//! workgroup memory only. Without barriers and subgroup operations its invocations
//! never wait for one another, so which of them run side by side is not observable
//! (buffer memory and atomics are ordered arbitrarily across workgroups on a GPU too).
//! Every invocation still gets its own workgroup's builtins and its own workgroup's
//! memory: a batch holds one zeroed region per workgroup (the path tracer keeps its
//! BVH stack there, a slice per invocation).
//!
//! One thing a batch does change: a kernel whose invocations spin until another
//! workgroup has written something may now wait forever (the scheduler always runs the
//! group furthest behind, here the spinning one, as it already did within a workgroup).
//! WGSL promises no forward progress between workgroups, so such a kernel is not
//! portable; before batches it finished here because workgroups ran in index order.

use super::insn::Insn;
use super::program::Program;

/// How many invocations a batch holds at most: sixteen of the common 64-wide workgroups,
/// where the path tracer's 128² frame is now fastest (512 was 4-5 % slower, 2 048 the
/// same within the noise, 4 096 and 256 about 10 % slower: docs/benchmarks/interpreter.md,
/// "The path tracer's loads by rows"; in 2026-11-28's code 512 had been the fastest).
pub(super) const BATCH_INVOCATIONS: u32 = 1024;

/// How many workgroups of `program` run as one batch in a dispatch of `total` workgroups
/// on `threads` threads: 1 where the kernel could observe it (a barrier or a subgroup
/// operation), else as many as fit in [`BATCH_INVOCATIONS`] but no more than leave each
/// thread a batch (a dispatch of 16 workgroups of 64 runs as two batches of 8 on two
/// threads, not one of 16 on one).
pub(super) fn workgroups_per_batch(program: &Program, total: u64, threads: usize) -> u64 {
    let [x, y, z] = program.workgroup_size;
    let invocations = (x * y * z).max(1);
    let synchronises = program
        .codes
        .iter()
        .flat_map(|code| &code.insns)
        .any(|insn| matches!(insn, Insn::Barrier { .. } | Insn::Gather(_) | Insn::Collective(_)));
    if synchronises {
        return 1;
    }
    let per_thread = total.div_ceil(threads.max(1) as u64);
    u64::from((BATCH_INVOCATIONS / invocations).max(1)).min(per_thread).max(1)
}

#[cfg(test)]
mod tests {
    use super::super::decode::compile_program;
    use super::workgroups_per_batch;
    use strata_kernels::Kernel;

    /// Workgroups per batch of a 64-wide kernel whose body is `body` (with a read-write
    /// `data` array and a workgroup array `slots`), in a dispatch of `total` workgroups on
    /// `threads` threads.
    fn per_batch_of(body: &str, total: u64, threads: usize) -> u64 {
        let subgroup = body.contains("subgroup");
        let source = format!(
            "@group(0) @binding(0) var<storage, read_write> data: array<u32>;\n\
             var<workgroup> slots: array<u32, 64>;\n\
             @compute @workgroup_size(64) fn main(@builtin(local_invocation_index) i: u32) {{\n{body}\n}}"
        );
        let kernel = Kernel::from_wgsl("batch.wgsl", source, "main", subgroup).expect("valid WGSL");
        workgroups_per_batch(&compile_program(&kernel).expect("compiles"), total, threads)
    }

    /// Workgroups per batch of a large dispatch on two threads.
    fn per_batch(body: &str) -> u64 {
        per_batch_of(body, 1 << 20, 2)
    }

    #[test]
    fn only_kernels_that_never_wait_run_in_batches() {
        // Workgroup memory alone: each workgroup of the batch gets its own.
        assert_eq!(per_batch("slots[i] = i; data[i] = slots[i];"), 16);
        // A barrier (including workgroupUniformLoad's): one workgroup at a time.
        assert_eq!(per_batch("slots[i] = i; workgroupBarrier(); data[i] = slots[63u - i];"), 1);
        assert_eq!(per_batch("data[i] = workgroupUniformLoad(&slots[0]);"), 1);
        assert_eq!(per_batch("storageBarrier(); data[i] = i;"), 1);
        // A subgroup operation: the subgroups are the workgroup's.
        assert_eq!(per_batch("data[i] = subgroupAdd(i);"), 1);
        assert_eq!(per_batch("data[i] = subgroupShuffle(i, 0u);"), 1);
    }

    #[test]
    fn every_thread_gets_a_batch_before_batches_grow() {
        let body = "data[i] = i;";
        assert_eq!(per_batch_of(body, 16, 2), 8);
        assert_eq!(per_batch_of(body, 17, 2), 9);
        assert_eq!(per_batch_of(body, 256, 2), 16);
        assert_eq!(per_batch_of(body, 256, 64), 4);
        assert_eq!(per_batch_of(body, 1, 2), 1);
        assert_eq!(per_batch_of(body, 3, 0), 3);
    }
}
