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

/// How many invocations a batch holds at most: eight of the common 64-wide workgroups,
/// where the path tracer's frame was fastest (128, 256 and 1 024 were slower:
/// BENCHMARKS.md, "Batches of workgroups").
pub(super) const BATCH_INVOCATIONS: u32 = 512;

/// How many workgroups of `program` run as one batch: 1 where the kernel could observe it
/// (a barrier or a subgroup operation), else as many as fit in [`BATCH_INVOCATIONS`].
pub(super) fn workgroups_per_batch(program: &Program) -> u32 {
    let [x, y, z] = program.workgroup_size;
    let invocations = (x * y * z).max(1);
    let synchronises = program
        .codes
        .iter()
        .flat_map(|code| &code.insns)
        .any(|insn| matches!(insn, Insn::Barrier { .. } | Insn::Gather(_) | Insn::Collective(_)));
    if synchronises { 1 } else { (BATCH_INVOCATIONS / invocations).max(1) }
}

#[cfg(test)]
mod tests {
    use super::super::decode::compile_program;
    use super::workgroups_per_batch;
    use strata_kernels::Kernel;

    /// Workgroups per batch of a 64-wide kernel whose body is `body` (with a read-write
    /// `data` array and a workgroup array `slots`).
    fn per_batch(body: &str) -> u32 {
        let subgroup = body.contains("subgroup");
        let source = format!(
            "@group(0) @binding(0) var<storage, read_write> data: array<u32>;\n\
             var<workgroup> slots: array<u32, 64>;\n\
             @compute @workgroup_size(64) fn main(@builtin(local_invocation_index) i: u32) {{\n{body}\n}}"
        );
        let kernel = Kernel::from_wgsl("batch.wgsl", source, "main", subgroup).expect("valid WGSL");
        workgroups_per_batch(&compile_program(&kernel).expect("compiles"))
    }

    #[test]
    fn only_kernels_that_never_wait_run_in_batches() {
        // Workgroup memory alone: each workgroup of the batch gets its own.
        assert_eq!(per_batch("slots[i] = i; data[i] = slots[i];"), 8);
        // A barrier (including workgroupUniformLoad's): one workgroup at a time.
        assert_eq!(per_batch("slots[i] = i; workgroupBarrier(); data[i] = slots[63u - i];"), 1);
        assert_eq!(per_batch("data[i] = workgroupUniformLoad(&slots[0]);"), 1);
        assert_eq!(per_batch("storageBarrier(); data[i] = i;"), 1);
        // A subgroup operation: the subgroups are the workgroup's.
        assert_eq!(per_batch("data[i] = subgroupAdd(i);"), 1);
        assert_eq!(per_batch("data[i] = subgroupShuffle(i, 0u);"), 1);
    }
}
