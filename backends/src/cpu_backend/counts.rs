//! What a dispatch executed, counted two ways: bytecode instructions per invocation, and
//! the issue slots a SIMT GPU would spend on the same execution.
//!
//! Why the second count: the interpreter's time says little about a GPU, where a
//! kernel's cost is mostly how many instructions its warps issue. The interpreter already
//! runs the invocations that stand at the same instruction as one group ([`super::interp`]),
//! just as a warp issues one instruction for all its active lanes; counting, for every
//! instruction a group executes, the 32-wide warps its members belong to gives the issue
//! slots of a machine that reconverges where the interpreter merges groups. Idle lanes of
//! a divergent or partly filled warp therefore cost what they cost on a GPU, which is what
//! separates a regular kernel (the histogram) from a divergent one (path tracing).
//!
//! Not modelled (so the count is a share of issue slots, not a time): memory latency and
//! bandwidth (a path tracer's BVH loads wait far longer than a workgroup-memory access),
//! barrier cost, the width of an instruction (a vec3 operation is one bytecode
//! instruction, three GPU instructions) and whatever the interpreter's compiler removed
//! (inlined calls, aliased fields, constants).

/// Invocations per warp of the modelled machine (NVIDIA's warps, AMD's wave32). Warps are
/// consecutive local invocation indices, as GPUs lay them out.
pub const WARP_WIDTH: u32 = 32;

/// Counts of one dispatch (or a sum of dispatches).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DispatchCounts {
    /// Bytecode instructions executed, summed over invocations.
    pub instructions: u64,
    /// Issue slots of a [`WARP_WIDTH`]-wide SIMT machine: for every instruction a group
    /// executed, the number of distinct warps among its members.
    pub warp_issues: u64,
}

impl DispatchCounts {
    /// Adds `steps` instructions executed together by a group whose members have the
    /// local invocation indices `members` (in increasing order).
    pub(super) fn add_group(&mut self, steps: u64, members: impl Iterator<Item = u32>) {
        // Sorted members put each warp's lanes next to each other, so a warp is counted
        // when it differs from the previous member's.
        let mut width = 0u64;
        let mut warps = 0u64;
        let mut last_warp = u32::MAX;
        for index in members {
            debug_assert!(last_warp == u32::MAX || index / WARP_WIDTH >= last_warp, "members out of order");
            width += 1;
            let warp = index / WARP_WIDTH;
            warps += u64::from(warp != last_warp);
            last_warp = warp;
        }
        self.add_counted_group(steps, width, warps);
    }

    /// Adds `steps` instructions executed together by a group of `width` members in
    /// `warps` warps, counted by the caller (from the group's set of lanes, where each
    /// invocation's SIMT index is its lane).
    #[inline(always)]
    pub(super) fn add_counted_group(&mut self, steps: u64, width: u64, warps: u64) {
        self.instructions += steps * width;
        self.warp_issues += steps * warps;
    }
}

impl std::ops::AddAssign for DispatchCounts {
    fn add_assign(&mut self, other: Self) {
        self.instructions += other.instructions;
        self.warp_issues += other.warp_issues;
    }
}

impl std::iter::Sum for DispatchCounts {
    fn sum<I: Iterator<Item = Self>>(counts: I) -> Self {
        counts.fold(Self::default(), |mut total, c| {
            total += c;
            total
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_group_costs_one_issue_per_warp_it_touches() {
        let mut counts = DispatchCounts::default();
        // A full first warp: 32 lanes, one issue per instruction.
        counts.add_group(10, 0..32);
        assert_eq!(counts, DispatchCounts { instructions: 320, warp_issues: 10 });
        // Two lanes of different warps: two issues per instruction for two lanes' work.
        counts.add_group(5, [3, 40].into_iter());
        assert_eq!(counts, DispatchCounts { instructions: 330, warp_issues: 20 });
        // One lane alone still costs its warp a whole issue.
        counts.add_group(1, [63].into_iter());
        assert_eq!(counts, DispatchCounts { instructions: 331, warp_issues: 21 });
    }
}
