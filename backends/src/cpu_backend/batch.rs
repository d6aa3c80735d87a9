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

/// How many invocations a batch of a smaller dispatch holds at most (one of fewer than
/// [`WIDE_BATCHES`] × [`BATCH_INVOCATIONS`] invocations): 512 as before, so that a 32²
/// frame's 16 workgroups still make two batches for two cores rather than one.
const SMALL_DISPATCH_BATCH: u32 = 512;

/// How many full batches a dispatch must fill before its batches are
/// [`BATCH_INVOCATIONS`] wide.
const WIDE_BATCHES: u64 = 4;

/// How many workgroups of `program` run as one batch in a dispatch of `total`
/// workgroups: 1 where the kernel could observe it (a barrier or a subgroup operation),
/// else as many as fit in [`BATCH_INVOCATIONS`], or in [`SMALL_DISPATCH_BATCH`] where the
/// dispatch is small. Why a rule on the dispatch and not on the machine's cores: what a
/// batch holds, and so what a test's dispatch exercises, is then the same on every
/// machine.
pub(super) fn workgroups_per_batch(program: &Program, total: u64) -> u64 {
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
    let wide = total.saturating_mul(u64::from(invocations)) >= WIDE_BATCHES * u64::from(BATCH_INVOCATIONS);
    let most = if wide { BATCH_INVOCATIONS } else { SMALL_DISPATCH_BATCH };
    u64::from((most / invocations).max(1))
}

#[cfg(test)]
mod tests {
    use super::super::decode::compile_program;
    use super::workgroups_per_batch;
    use strata_kernels::Kernel;

    /// Workgroups per batch of a 64-wide kernel whose body is `body` (with a read-write
    /// `data` array and a workgroup array `slots`), in a dispatch of `total` workgroups.
    fn per_batch_of(body: &str, total: u64) -> u64 {
        let subgroup = body.contains("subgroup");
        let source = format!(
            "@group(0) @binding(0) var<storage, read_write> data: array<u32>;\n\
             var<workgroup> slots: array<u32, 64>;\n\
             @compute @workgroup_size(64) fn main(@builtin(local_invocation_index) i: u32) {{\n{body}\n}}"
        );
        let kernel = Kernel::from_wgsl("batch.wgsl", source, "main", subgroup).expect("valid WGSL");
        workgroups_per_batch(&compile_program(&kernel).expect("compiles"), total)
    }

    /// Workgroups per batch of a large dispatch.
    fn per_batch(body: &str) -> u64 {
        per_batch_of(body, 1 << 20)
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
    fn small_dispatches_keep_batches_of_512() {
        let body = "data[i] = i;";
        // A 32² frame's 16 workgroups of 64, up to 63: two or more batches of 8.
        assert_eq!(per_batch_of(body, 16), 8);
        assert_eq!(per_batch_of(body, 63), 8);
        // From four batches of 1 024 invocations on (a 64² frame), batches of 16.
        assert_eq!(per_batch_of(body, 64), 16);
        assert_eq!(per_batch_of(body, u64::MAX), 16);
        assert_eq!(per_batch_of(body, 0), 8);
    }
}
