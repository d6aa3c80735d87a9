//! Jump cleanup, once a code is compiled: a jump to a forward jump goes straight to the
//! final target, instructions no path reaches are removed, and so are jumps to the next
//! instruction; the remaining targets are renumbered.
//!
//! Why: structured lowering leaves many of them. An inlined callee's `return` as its
//! last statement jumps to the instruction after it; a loop's `if i < n {} else {
//! break; }` jumps over the `break`'s jump; a `continue` jumps to an empty continuing
//! block that jumps back. Each costs the interpreter a dispatch per group, and the path
//! tracer's BVH loop ran one of them per four other instructions.
//!
//! The order of the instructions is kept, so structured code stays laid out in order
//! (what the scheduler's reconvergence relies on, [`super::interp`]). A call's return
//! address is the instruction after the call, which stays after it.

use super::insn::Insn;

/// Jumps followed through at most this many jumps.
const THREAD_HOPS: usize = 16;

/// Cleans up the jumps of one code: `lines` and `sources` are its per-instruction
/// tables, kept in step.
pub(super) fn clean_up_jumps(insns: &mut Vec<Insn>, lines: &mut Vec<u32>, sources: &mut Vec<u32>) {
    thread_jumps(insns);
    // Removing an instruction may make a jump reach the next one: a few rounds.
    for _ in 0..4 {
        let keep = kept(insns);
        if keep.iter().all(|&k| k) {
            break;
        }
        remove(insns, lines, sources, &keep);
    }
}

/// Points every jump past the forward unconditional jumps at its target.
fn thread_jumps(insns: &mut [Insn]) {
    let jumps: Vec<Option<u32>> =
        insns.iter().map(|insn| if let Insn::Jump(t) = insn { Some(*t) } else { None }).collect();
    let resolve = |mut target: u32| {
        for _ in 0..THREAD_HOPS {
            match jumps.get(target as usize) {
                // Forward only: a jump through a loop's back edge would send the lanes
                // that take it to the loop's start alone, ahead of the others still in
                // the body, where they used to wait at the back edge and go round
                // together (measured: 12 % more group steps in the path tracer).
                Some(Some(next)) if *next > target => target = *next,
                _ => break,
            }
        }
        target
    };
    for insn in insns {
        for_each_target(insn, |t| *t = resolve(*t));
    }
}

/// Calls `f` on every jump target of `insn` (none for an instruction that falls through).
fn for_each_target(insn: &mut Insn, mut f: impl FnMut(&mut u32)) {
    match insn {
        Insn::Jump(t) | Insn::JumpUnless { target: t, .. } => f(t),
        Insn::Switch { cases, default, .. } => {
            cases.iter_mut().for_each(|(_, t)| f(t));
            f(default);
        }
        _ => {}
    }
}

/// Per instruction, whether it stays: reached from the first instruction, and not a
/// jump (conditional or not) to the next one.
fn kept(insns: &[Insn]) -> Vec<bool> {
    let mut reached = vec![false; insns.len()];
    let mut pending = vec![0usize];
    while let Some(at) = pending.pop() {
        if at >= insns.len() || reached[at] {
            continue;
        }
        reached[at] = true;
        match &insns[at] {
            Insn::Jump(t) => pending.push(*t as usize),
            Insn::JumpUnless { target, .. } => pending.extend([*target as usize, at + 1]),
            Insn::Switch { cases, default, .. } => {
                pending.extend(cases.iter().map(|&(_, t)| t as usize));
                pending.push(*default as usize);
            }
            Insn::Return { .. } => {}
            _ => pending.push(at + 1),
        }
    }
    insns
        .iter()
        .enumerate()
        .map(|(at, insn)| {
            let to_next = match insn {
                Insn::Jump(t) | Insn::JumpUnless { target: t, .. } => *t as usize == at + 1,
                _ => false,
            };
            reached[at] && !to_next
        })
        .collect()
}

/// Removes the instructions not kept and renumbers the targets: a removed instruction's
/// index becomes that of the next kept one (where a removed jump to the next instruction
/// would have gone; no kept jump targets an unreached instruction).
fn remove(insns: &mut Vec<Insn>, lines: &mut Vec<u32>, sources: &mut Vec<u32>, keep: &[bool]) {
    let mut renumbered = Vec::with_capacity(insns.len() + 1);
    let mut next = 0u32;
    for &k in keep {
        renumbered.push(next);
        next += u32::from(k);
    }
    renumbered.push(next);
    for insn in insns.iter_mut() {
        for_each_target(insn, |t| *t = renumbered[*t as usize]);
    }
    retain_kept(insns, keep);
    retain_kept(lines, keep);
    retain_kept(sources, keep);
}

/// Keeps the items whose entry of `keep` is true (`retain` visits them in order).
fn retain_kept<T>(items: &mut Vec<T>, keep: &[bool]) {
    let mut keep = keep.iter();
    items.retain(|_| *keep.next().expect("one flag per item"));
}

#[cfg(test)]
mod tests {
    use super::super::decode::tests::compiled;
    use super::*;

    #[test]
    fn no_jump_lands_on_the_next_instruction_or_a_forward_jump() {
        let insns = compiled(
            "var n = 0u;\n\
             for (var j = 0u; j < x; j++) { if j == 5u { continue; } if j > 9u { break; } n += j; }\n\
             data[id.x] = n;",
        );
        for (at, insn) in insns.iter().enumerate() {
            let target = match insn {
                Insn::Jump(t) | Insn::JumpUnless { target: t, .. } => *t as usize,
                _ => continue,
            };
            assert_ne!(target, at + 1, "instruction {at} jumps to the next one");
            if let Some(Insn::Jump(next)) = insns.get(target) {
                assert!(*next as usize <= target, "instruction {at} jumps to a forward jump at {target}");
            }
        }
    }
}
