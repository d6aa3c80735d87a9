//! The dispatch loop, a workgroup at a time: runs the bytecode of every invocation of a
//! workgroup until each ends or reaches a barrier or subgroup operation, where it stops
//! (that instruction still next) so that [`super::exec`] can synchronise them.
//!
//! Invocations at the same place (the same instruction of the same call stack) run as
//! one *group*: each instruction is decoded and dispatched once and executed for every
//! member, in local-index order, before the next. That is what makes the interpreter
//! fast: a kernel's invocations mostly run the same instructions, so the dispatch's
//! branch is decided once per instruction and workgroup instead of once per invocation.
//! Divergence is handled by scheduling, not masks: when a branch splits a group, each
//! member keeps its own next instruction, and the group to run next is always the one
//! *furthest behind* (smallest instruction index, outermost frame first; inside a call
//! before back in its caller). Structured code is laid out in order, so the lanes ahead
//! wait at the join (the end of an `if`, a loop's exit, a call's return) until the
//! others arrive, and a group stops as soon as it reaches the place where another waits,
//! so they merge there. Every invocation still executes exactly the instructions it
//! would alone; only the interleaving between barriers changes, which a kernel free of
//! data races cannot observe (outputs are checked byte for byte against the
//! one-invocation-at-a-time executor this replaced: BENCHMARKS.md, "interpreter").

use super::counts::DispatchCounts;
use super::decode::Program;
use super::error::{invalid, unsupported};
use super::execute::execute;
use super::insn::{BinOp, CallInsn, Insn};
use super::memory::{Frame, copy_regs, zero_words};
use crate::error::BackendError;
use std::cmp::Ordering;
use std::sync::atomic::AtomicU32;

/// Why an invocation stopped running.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(super) enum Stop {
    /// It returned from the entry point.
    Done,
    /// At a barrier or subgroup gather: (code, instruction index).
    Sync(u32, u32),
}

/// One invocation: its running frame, its callers' frames, its private memory.
pub(super) struct Invocation {
    /// The running frame (`None` once the entry point returned).
    pub frame: Option<Frame>,
    /// Callers of the running frame, outermost first.
    pub callers: Vec<Frame>,
    /// Register files of returned frames, reused by later calls (and by the entry frame
    /// of the next workgroup the same thread runs).
    pub spare: Vec<Vec<u32>>,
    /// Private memory.
    pub private: Vec<u32>,
    /// Subgroup lane, subgroup index and size, local index (for gathers).
    pub lane: u32,
    /// Index of the invocation's subgroup.
    pub subgroup_id: u32,
    /// Invocations per subgroup.
    pub subgroup_size: u32,
    /// `local_invocation_index`.
    pub local_index: u32,
}

/// `regs[dst + i] = f(regs[a + i * sa], regs[b + i * sb])` for `i < n`.
#[inline(always)]
fn component_wise(
    regs: &mut [u32],
    (dst, a, b, n, sa, sb): (usize, usize, usize, usize, usize, usize),
    f: impl Fn(u32, u32) -> u32,
) {
    for i in 0..n {
        regs[dst + i] = f(regs[a + i * sa], regs[b + i * sb]);
    }
}

/// `copy_regs` in every member's registers.
#[inline(always)]
fn copy_in_each(lanes: &mut [Lane], dst: u32, src: u32, len: u32) {
    let (dst, src, len) = (dst as usize, src as usize, len as usize);
    for lane in lanes.iter_mut() {
        copy_regs(lane.regs, dst, src, len);
    }
}

/// `$body` with `$operator` bound to the constant `BinOp` equal to `$op`: one copy of the
/// loop per operator, so that the operator is decided once, outside it.
macro_rules! per_operator {
    ($op:expr, |$operator:ident| $body:expr) => {
        per_operator!(@ $op, $operator, $body, AddF, SubF, MulF, DivF, ModF, AddI, SubI, MulI, DivU, DivS,
            ModU, ModS, EqF, NeF, LtF, LeF, GtF, GeF, Eq, Ne, LtS, LeS, GtS, GeS, LtU, LeU, GtU, GeU, And, Xor,
            Or, LogicalAnd, LogicalOr, Shl, ShrU, ShrS)
    };
    (@ $op:expr, $operator:ident, $body:expr, $($variant:ident),*) => {
        match $op {
            $(BinOp::$variant => {
                let $operator = BinOp::$variant;
                $body
            })*
        }
    };
}

/// One member of a running group: the registers of its running frame and the memory
/// only it sees.
pub(super) struct Lane<'a> {
    /// The running frame's registers.
    pub(super) regs: &'a mut [u32],
    /// Private memory.
    pub(super) private: &'a mut [u32],
    /// Callers' frames (their registers, for pointers into them).
    pub(super) callers: &'a mut [Frame],
}

/// An empty vector with the allocation of `lanes`, to borrow the next group's lanes into
/// (groups are formed hundreds of thousands of times per dispatch; allocating each was
/// 5 % of the path tracer).
fn recycle<'b>(mut lanes: Vec<Lane<'_>>) -> Vec<Lane<'b>> {
    lanes.clear();
    lanes.into_iter().map(|_| unreachable!("the vector is empty")).collect()
}

/// Why a group stopped running together.
enum GroupEnd {
    /// It reached the place where other invocations wait (or a uniform jump did): every
    /// member continues at this instruction.
    Meet(u32),
    /// A branch sent the members different ways: each continues at its entry of
    /// `targets`.
    Split,
    /// Every member calls (the instruction after the call is the return address).
    Call(u32),
    /// Every member returns `len` words from `src`.
    Return { src: u32, len: u32 },
    /// Every member stopped at the barrier or subgroup operation at this instruction.
    Sync(u32),
}

/// Orders two invocations by how far they are: the one to run first is `Less`. Call
/// stacks compare outermost frame first by instruction index (a caller's index is its
/// return address); where one stack continues the other's, the deeper one is behind
/// (it must still return to where the other already is).
fn position(a: &Invocation, b: &Invocation) -> Ordering {
    let (pa, pb) = (a.frame.as_ref().map_or(u32::MAX, |f| f.pc), b.frame.as_ref().map_or(u32::MAX, |f| f.pc));
    let (da, db) = (a.callers.len(), b.callers.len());
    for (ca, cb) in a.callers.iter().zip(&b.callers) {
        if ca.pc != cb.pc {
            return ca.pc.cmp(&cb.pc);
        }
    }
    match da.cmp(&db) {
        Ordering::Equal => pa.cmp(&pb),
        // `a` is shallower: compare its instruction with `b`'s return address at that depth.
        Ordering::Less => pa.cmp(&b.callers[da].pc).then(Ordering::Greater),
        Ordering::Greater => a.callers[db].pc.cmp(&pb).then(Ordering::Less),
    }
}

/// Where `other` is in the frame `leader` runs, if it is in that frame (same callers) or
/// inside a call made from it: the instruction at which the leader's group must stop to
/// meet it.
fn meeting_point(leader: &Invocation, other: &Invocation) -> Option<u32> {
    let depth = leader.callers.len();
    if other.callers.len() < depth || leader.callers.iter().zip(&other.callers).any(|(a, b)| a.pc != b.pc) {
        return None;
    }
    match other.callers.get(depth) {
        Some(frame) => Some(frame.pc),
        None => other.frame.as_ref().map(|f| f.pc),
    }
}

/// Runs every invocation of a workgroup until it returns from the entry point or stops
/// at a barrier or subgroup operation; `stops[i]` says where invocation `i` stopped.
/// Counts what the groups executed into `counts`.
pub(super) fn run_until_sync(
    program: &Program,
    invocations: &mut [Invocation],
    buffers: &[Vec<AtomicU32>],
    workgroup: &mut [u32],
    counts: &mut DispatchCounts,
    stops: &mut Vec<Option<Stop>>,
) -> Result<(), BackendError> {
    stops.clear();
    stops.extend(invocations.iter().map(|inv| if inv.frame.is_some() { None } else { Some(Stop::Done) }));
    let mut members: Vec<usize> = Vec::with_capacity(invocations.len());
    let mut targets: Vec<u32> = Vec::with_capacity(invocations.len());
    // While no invocation is inside a call (the common case: small functions are
    // inlined), where an invocation is is its next instruction alone: the group to run is
    // then found from these words (`u32::MAX`: stopped) instead of by comparing stacks.
    let mut pcs: Vec<u32> = invocations
        .iter()
        .zip(stops.iter())
        .map(|(inv, stop)| if stop.is_none() { inv.frame.as_ref().map_or(u32::MAX, |f| f.pc) } else { u32::MAX })
        .collect();
    // Runnable invocations inside a call (stopped ones no longer count).
    let mut in_calls = invocations.iter().filter(|inv| !inv.callers.is_empty()).count();
    let mut spare_lanes = Vec::new();
    loop {
        // The group furthest behind, and the instruction where it meets the next one.
        members.clear();
        let mut meet = u32::MAX;
        let leader = if in_calls == 0 {
            let behind = pcs.iter().copied().min().unwrap_or(u32::MAX);
            if behind == u32::MAX {
                return Ok(());
            }
            // Without branches: which invocations are members is unpredictable, and a
            // branch on it mispredicted often enough to cost a fifth of the path tracer.
            members.resize(pcs.len(), 0);
            let mut count = 0;
            for (i, &pc) in pcs.iter().enumerate() {
                members[count] = i;
                count += usize::from(pc == behind);
                meet = meet.min(if pc == behind { u32::MAX } else { pc });
            }
            members.truncate(count);
            members[0]
        } else {
            let mut leader = None;
            for (i, stop) in stops.iter().enumerate() {
                if stop.is_none() && leader.is_none_or(|l: usize| position(&invocations[i], &invocations[l]).is_lt()) {
                    leader = Some(i);
                }
            }
            let Some(leader) = leader else { return Ok(()) };
            for (i, stop) in stops.iter().enumerate() {
                if stop.is_some() {
                    continue;
                }
                if position(&invocations[i], &invocations[leader]).is_eq() {
                    members.push(i);
                } else if let Some(pc) = meeting_point(&invocations[leader], &invocations[i]) {
                    meet = meet.min(pc);
                }
            }
            leader
        };
        let frame = invocations[leader].frame.as_ref().expect("running invocations have frames");
        let (code_index, pc) = (frame.code, frame.pc);
        let end = {
            let mut lanes = recycle(std::mem::take(&mut spare_lanes));
            // The members' invocations, borrowed apart by splitting the slice at each
            // (they are in increasing order).
            let mut rest = &mut invocations[..];
            let mut start = 0;
            for &i in &members {
                let (invocation, tail) = std::mem::take(&mut rest)[i - start..].split_first_mut().expect("a member");
                (rest, start) = (tail, i + 1);
                let Invocation { frame, private, callers, .. } = invocation;
                let frame = frame.as_mut().expect("running invocations have frames");
                lanes.push(Lane { regs: &mut frame.regs[..], private: &mut private[..], callers: &mut callers[..] });
            }
            let mut steps = 0;
            let end =
                run_group(program, code_index, pc, meet, &mut lanes, buffers, workgroup, &mut steps, &mut targets);
            spare_lanes = recycle(lanes);
            // An invocation's position in the workgroup is its local index (exec.rs).
            counts.add_group(steps, members.iter().map(|&i| i as u32));
            end?
        };
        match end {
            GroupEnd::Meet(pc) => {
                for &i in &members {
                    invocations[i].frame.as_mut().expect("running").pc = pc;
                }
            }
            GroupEnd::Split => {
                for (&i, &pc) in members.iter().zip(&targets) {
                    invocations[i].frame.as_mut().expect("running").pc = pc;
                }
            }
            GroupEnd::Sync(pc) => {
                for &i in &members {
                    invocations[i].frame.as_mut().expect("running").pc = pc;
                    stops[i] = Some(Stop::Sync(code_index, pc));
                    in_calls -= usize::from(!invocations[i].callers.is_empty());
                }
            }
            GroupEnd::Call(return_pc) => {
                let Insn::Call(call) = &program.codes[code_index as usize].insns[return_pc as usize - 1] else {
                    unreachable!("a group ends with Call at a call instruction")
                };
                for &i in &members {
                    in_calls += usize::from(invocations[i].callers.is_empty());
                    call_function(program, &mut invocations[i], call, return_pc)?;
                }
            }
            GroupEnd::Return { src, len } => {
                for &i in &members {
                    if return_from_function(&mut invocations[i], src, len) {
                        stops[i] = Some(Stop::Done);
                    }
                    in_calls -= usize::from(stops[i].is_none() && invocations[i].callers.is_empty());
                }
            }
        }
        for &i in &members {
            pcs[i] = match (&stops[i], &invocations[i].frame) {
                (None, Some(frame)) => frame.pc,
                _ => u32::MAX,
            };
        }
    }
}

/// Pushes a frame for `call` on `invocation`'s stack, its caller continuing at `return_pc`.
fn call_function(
    program: &Program,
    invocation: &mut Invocation,
    call: &CallInsn,
    return_pc: u32,
) -> Result<(), BackendError> {
    let Invocation { frame: running, callers, spare, .. } = invocation;
    if callers.len() >= 256 {
        return Err(invalid(&program.name, "call depth above 256 (recursion?)".into()));
    }
    let frame = running.as_mut().expect("running");
    let callee = &program.codes[call.code as usize];
    let mut callee_regs = spare.pop().unwrap_or_default();
    callee_regs.clear();
    callee_regs.extend_from_slice(&callee.template);
    for &(src, len, dst) in call.arguments.iter() {
        callee_regs[dst as usize..(dst + len) as usize]
            .copy_from_slice(&frame.regs[src as usize..(src + len) as usize]);
    }
    let depth = callers.len() as u32 + 1;
    for &(reg, offset) in &callee.local_pointers {
        callee_regs[reg as usize] = super::memory::FUNCTION | depth;
        callee_regs[reg as usize + 1] = offset;
    }
    frame.pc = return_pc;
    let callee_frame = Frame { code: call.code, pc: 0, regs: callee_regs, result: call.result };
    callers.push(std::mem::replace(frame, callee_frame));
    Ok(())
}

/// Pops `invocation`'s running frame, copying `len` words from `src` to the caller's
/// result registers; true when it returned from the entry point.
fn return_from_function(invocation: &mut Invocation, src: u32, len: u32) -> bool {
    let Invocation { frame: running, callers, spare, .. } = invocation;
    let returned = running.take().expect("running");
    match callers.pop() {
        None => {
            spare.push(returned.regs);
            true
        }
        Some(mut caller) => {
            if let Some((dst, words)) = returned.result
                && len > 0
            {
                let (src, words) = (src as usize, words.min(len) as usize);
                caller.regs[dst as usize..dst as usize + words].copy_from_slice(&returned.regs[src..src + words]);
            }
            spare.push(returned.regs);
            *running = Some(caller);
            false
        }
    }
}

/// Runs the group `lanes` (all at instruction `pc` of code `code_index`) together until
/// it reaches `meet`, a branch splits it (each member's next instruction into
/// `targets`), it calls or returns, or it stops at a barrier or subgroup operation.
/// `steps`: how many instructions the group executed (each for every member).
#[allow(clippy::too_many_arguments)]
fn run_group(
    program: &Program,
    code_index: u32,
    pc: u32,
    meet: u32,
    lanes: &mut [Lane],
    buffers: &[Vec<AtomicU32>],
    workgroup: &mut [u32],
    steps: &mut u64,
    targets: &mut Vec<u32>,
) -> Result<GroupEnd, BackendError> {
    let insns = &program.codes[code_index as usize].insns[..];
    let mut pc = pc as usize;
    let mut count = 0u64;
    let end = loop {
        // At or past an invocation that waits: let it catch up (and merge when equal).
        if pc >= meet as usize {
            break GroupEnd::Meet(pc as u32);
        }
        let insn = &insns[pc];
        pc += 1;
        count += 1;
        match insn {
            Insn::Jump(target) => pc = *target as usize,
            Insn::JumpUnless { cond, target } => {
                let taken = lanes.iter().filter(|lane| lane.regs[*cond as usize] == 0).count();
                if taken == lanes.len() {
                    pc = *target as usize;
                } else if taken > 0 {
                    targets.clear();
                    targets.extend(
                        lanes.iter().map(|lane| if lane.regs[*cond as usize] == 0 { *target } else { pc as u32 }),
                    );
                    break GroupEnd::Split;
                }
            }
            Insn::Switch { selector, cases, default } => {
                let target = |lane: &Lane| {
                    let value = lane.regs[*selector as usize];
                    cases.iter().find(|(v, _)| *v == value).map_or(*default, |(_, t)| *t)
                };
                let first = target(&lanes[0]);
                if lanes.iter().all(|lane| target(lane) == first) {
                    pc = first as usize;
                } else {
                    targets.clear();
                    targets.extend(lanes.iter().map(target));
                    break GroupEnd::Split;
                }
            }
            Insn::Call(_) => break GroupEnd::Call(pc as u32),
            Insn::Return { src, len } => break GroupEnd::Return { src: *src, len: *len },
            Insn::Barrier | Insn::Gather(_) | Insn::Collective(_) => break GroupEnd::Sync(pc as u32 - 1),
            Insn::Fail(failure) => return Err(unsupported(&failure.0, failure.1)),
            // The most frequent instructions get their own loop over the members, their
            // operands and operator decoded once for the whole group; `execute` runs the
            // others member by member.
            Insn::Copy1 { dst, src } => copy_in_each(lanes, *dst, *src, 1),
            Insn::Copy2 { dst, src } => copy_in_each(lanes, *dst, *src, 2),
            Insn::Copy3 { dst, src } => copy_in_each(lanes, *dst, *src, 3),
            Insn::Copy4 { dst, src } => copy_in_each(lanes, *dst, *src, 4),
            Insn::Copy { dst, src, len } => copy_in_each(lanes, *dst, *src, *len),
            Insn::Zero { dst, len } => {
                let (dst, len) = (*dst as usize, *len as usize);
                for lane in lanes.iter_mut() {
                    zero_words(&mut lane.regs[dst..dst + len]);
                }
            }
            Insn::Bin { op, dst, a, b } => {
                let (dst, a, b) = (*dst as usize, *a as usize, *b as usize);
                per_operator!(op, |operator| for lane in lanes.iter_mut() {
                    let regs = &mut *lane.regs;
                    regs[dst] = operator.apply(regs[a], regs[b]);
                });
            }
            Insn::BinV { op, dst, a, b, n, sa, sb } => {
                let operands = (*dst as usize, *a as usize, *b as usize, *n as usize, *sa as usize, *sb as usize);
                per_operator!(op, |operator| for lane in lanes.iter_mut() {
                    component_wise(lane.regs, operands, |x, y| operator.apply(x, y));
                });
            }
            Insn::Select { dst, cond, accept, reject, n, sc } => {
                let (dst, cond, accept, reject) = (*dst as usize, *cond as usize, *accept as usize, *reject as usize);
                let (n, sc) = (*n as usize, *sc as usize);
                for lane in lanes.iter_mut() {
                    let regs = &mut *lane.regs;
                    for i in 0..n {
                        regs[dst + i] = if regs[cond + i * sc] != 0 { regs[accept + i] } else { regs[reject + i] };
                    }
                }
            }
            Insn::Splat { dst, src, n } => {
                let (dst, src, n) = (*dst as usize, *src as usize, *n as usize);
                for lane in lanes.iter_mut() {
                    let value = lane.regs[src];
                    lane.regs[dst..dst + n].fill(value);
                }
            }
            Insn::Extract { dst, base, index, count, stride, len } => {
                let (dst, base, index, len) = (*dst as usize, *base as usize, *index as usize, *len as usize);
                let (last, stride) = (count.saturating_sub(1) as usize, *stride as usize);
                for lane in lanes.iter_mut() {
                    let at = (lane.regs[index] as usize).min(last) * stride;
                    copy_regs(lane.regs, dst, base + at, len);
                }
            }
            Insn::Compute(compute) => {
                for lane in lanes.iter_mut() {
                    compute(lane.regs);
                }
            }
            _ => {
                for lane in lanes.iter_mut() {
                    execute(insn, lane, buffers, workgroup);
                }
            }
        }
    };
    *steps = count;
    Ok(end)
}
