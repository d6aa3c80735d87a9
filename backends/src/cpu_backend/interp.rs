//! The group loop, a workgroup (or a batch of them, [`super::batch`]) at a time: runs
//! the bytecode of every invocation of the batch until each ends or reaches a barrier or
//! subgroup operation. Where the whole batch reaches one as a single group, it is completed
//! there and the batch goes on; otherwise each invocation stops at it (that instruction
//! still next) so that [`super::dispatch`] can synchronise them.
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
//!
//! Registers are lane-minor ([`super::lanes`]): each code has one register file for the
//! whole workgroup (or batch), so an instruction run for a group is a loop over
//! contiguous words.

use super::counts::DispatchCounts;
use super::error::{invalid, unsupported};
use super::execute::{GroupMemory, execute};
use super::insn::{BinOp, CallInsn, Insn, UnOp};
use super::invocations::{Batch, Invocation};
use super::lanes::{LaneRegs, Members, N as LANES};
use super::limit::{FUEL, Limit};
use super::memory::{FUNCTION, Frame};
use super::places::{Places, lanes_in, members_of};
use super::program::Program;
use super::sanitize::{Sanitizer, Sanitizing};
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

/// The scheduler's working lists, kept from one synchronisation point to the next.
#[derive(Default)]
pub(super) struct Scratch {
    members: Vec<usize>,
    /// The running group as a set: bit `l % 64` of word `l / 64` for member `l`.
    lanes: Vec<u64>,
    /// Per lane, all ones for a member of the running group (see [`Members::Masked`]);
    /// only the chunks of 64 lanes with a member are written.
    mask: Vec<u32>,
    /// Each member's next instruction after a [`GroupEnd::Split`].
    targets: Vec<u32>,
    /// The members that jump at a [`GroupEnd::Branch`], as a set like `lanes`.
    taken: Vec<u64>,
    caller_codes: Vec<u32>,
    places: Places,
}

/// `$body` with `$operator` a function computing the `BinOp` equal to `$op`: one copy of
/// the loop per operator, so that the operator is decided once, outside it. A function
/// item rather than a closure: closures passed to the row loops were not always
/// inlined into them, and then each word went through the operator's jump table.
macro_rules! per_operator {
    ($op:expr, |$operator:ident| $body:expr) => {
        per_operator!(@ $op, $operator, $body, AddF, SubF, MulF, DivF, ModF, AddI, SubI, MulI, DivU, DivS,
            ModU, ModS, EqF, NeF, LtF, LeF, GtF, GeF, Eq, Ne, LtS, LeS, GtS, GeS, LtU, LeU, GtU, GeU, And, Xor,
            Or, LogicalAnd, LogicalOr, Shl, ShrU, ShrS)
    };
    (@ $op:expr, $operator:ident, $body:expr, $($variant:ident),*) => {
        match $op {
            $(BinOp::$variant => {
                #[inline(always)]
                fn $operator(a: u32, c: u32) -> u32 {
                    BinOp::$variant.apply(a, c)
                }
                $body
            })*
        }
    };
}

/// Why a group stopped running together.
enum GroupEnd {
    /// It reached the place where other invocations wait (or a uniform jump did): every
    /// member continues at this instruction.
    Meet(u32),
    /// A conditional jump sent some members to `target` (those of the set `taken`) and
    /// the others on to `fall`.
    Branch { target: u32, fall: u32 },
    /// A switch sent the members different ways: each continues at its entry of
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

/// Runs every invocation of a batch until it returns from the entry point or stops
/// at a barrier or subgroup operation (one the whole batch reaches as a single group is
/// completed at once, [`super::sync_point::complete_sync`], and not stopped at); `stops[i]`
/// says where invocation `i` stopped.
/// Counts what the groups executed into `counts`. Fails when the dispatch runs past
/// `limit`.
#[allow(clippy::too_many_arguments)]
pub(super) fn run_until_sync(
    program: &Program,
    invocations: &mut [Invocation],
    memory: &mut Batch,
    scratch: &mut Scratch,
    buffers: &[Vec<AtomicU32>],
    counts: &mut DispatchCounts,
    stops: &mut Vec<Option<Stop>>,
    (limit, sanitizer): (&Limit, Option<&Sanitizer>),
) -> Result<(), BackendError> {
    stops.clear();
    stops.extend(invocations.iter().map(|inv| if inv.frame.is_some() { None } else { Some(Stop::Done) }));
    let width = invocations.len();
    let Scratch { members, lanes, mask, targets, taken, caller_codes, places } = scratch;
    const { assert!(super::counts::WARP_WIDTH == 32, "a warp is half a word of the set") };
    // Whether each invocation's SIMT index is its lane (workgroups a whole number of
    // warps wide, as both benches' are): a group's warps are then the 32-bit halves of
    // its set with a member.
    let warps_are_halves = invocations.iter().enumerate().all(|(lane, inv)| inv.simt_index as usize == lane);
    // While every runnable invocation has the same callers (the common case: no call, as
    // small functions are inlined; or all in the same call, as the histogram's network
    // functions), where an invocation is is its next instruction in one code alone: the
    // group to run is then found from `places`, the invocations by instruction, instead
    // of by comparing stacks.
    let instructions = program.codes.iter().map(|code| code.insns.len()).max().unwrap_or(0);
    // Whether `places` holds every runnable invocation, all in code `placed_code` under
    // the same callers. While it does, `places` alone says where they are: their running
    // frames' instructions are left as they were and written when the frames are needed
    // again (a call or return of some of them only).
    let mut placed = false;
    let mut placed_code = program.entry;
    // Whether the stacks may have become the same again since they were last compared
    // (at the start, after a return or a stop).
    let mut compare = true;
    loop {
        // The group furthest behind, and the instruction where it meets the next one.
        members.clear();
        let mut meet = u32::MAX;
        if !placed && compare {
            compare = false;
            if let Some(code) = same_stack(invocations, stops) {
                let running = invocations.iter().zip(stops.iter()).enumerate().filter_map(|(lane, (inv, stop))| {
                    inv.frame.as_ref().filter(|_| stop.is_none()).map(|frame| (lane, frame.pc))
                });
                places.rebuild(instructions, width, running);
                (placed, placed_code) = (true, code);
            }
        }
        let leader = if placed {
            let Some((at, next)) = places.take_first(lanes) else { return Ok(()) };
            meet = next;
            // The leader is the first member (an invocation stopped inside a call may be
            // lane 0, and the group's callers are its leader's).
            let first = lanes.iter().position(|&bits| bits != 0).expect("a group has members");
            (first * 64 + lanes[first].trailing_zeros() as usize, placed_code, at)
        } else {
            let mut leader = None;
            for (i, stop) in stops.iter().enumerate() {
                if stop.is_none() && leader.is_none_or(|l: usize| position(&invocations[i], &invocations[l]).is_lt()) {
                    leader = Some(i);
                }
            }
            let Some(leader) = leader else { return Ok(()) };
            lanes.clear();
            lanes.resize(width.div_ceil(64), 0);
            for (i, stop) in stops.iter().enumerate() {
                if stop.is_some() {
                    continue;
                }
                if position(&invocations[i], &invocations[leader]).is_eq() {
                    members.push(i);
                    lanes[i / 64] |= 1 << (i % 64);
                } else if let Some(pc) = meeting_point(&invocations[leader], &invocations[i]) {
                    meet = meet.min(pc);
                }
            }
            let frame = invocations[leader].frame.as_ref().expect("running invocations have frames");
            (leader, frame.code, frame.pc)
        };
        let (leader, code_index, pc) = leader;
        // How many members the group has. `members` is empty until they are listed, which
        // is only where needed: by `group_of` for a group of a few, and by the ends that
        // go member by member.
        let size = lanes.iter().map(|bits| bits.count_ones() as usize).sum::<usize>();
        // Members at the same place have the same callers.
        caller_codes.clear();
        caller_codes.extend(invocations[leader].callers.iter().map(|f| f.code));
        // An invocation's position in the batch is its lane in the register files:
        // its workgroup's place in the batch times the workgroup's size, plus its local
        // index (dispatch.rs).
        let group = group_of(members, size, lanes, mask, width);
        let whole_batch = size == width;
        let mut steps = 0;
        let mut start = pc;
        let end = loop {
            let mut file = std::mem::take(&mut memory.files[code_index as usize]);
            let mut group_memory = GroupMemory {
                buffers,
                workgroup: &mut memory.shared,
                workgroup_words: program.workgroup_words as usize,
                per_workgroup: program.workgroup_size.iter().product::<u32>() as usize,
                private: &mut memory.private,
                private_words: memory.private_words,
                files: &mut memory.files,
                callers: caller_codes,
                width,
                limit,
                fuel: memory.fuel,
                sanitizer: match (sanitizer, memory.sanitizing.as_mut()) {
                    (Some(shared), Some(local)) => Some(Sanitizing { shared, local }),
                    _ => None,
                },
            };
            let end = run_group(
                program,
                code_index,
                (start, meet),
                group,
                &mut file,
                &mut group_memory,
                &mut steps,
                (targets, taken),
            );
            memory.fuel = group_memory.fuel;
            memory.files[code_index as usize] = file;
            match end {
                // The whole batch reached a barrier or subgroup operation together (none
                // has finished, none is elsewhere): completed here and now, as the
                // dispatch would complete it once every invocation had stopped there, and
                // the same group runs on past it without a round through the scheduler (a
                // subgroup kernel's batch is one workgroup, so its shuffles mostly end
                // here). Where the invocations are is recorded once the group ends otherwise.
                Ok(GroupEnd::Sync(at)) if whole_batch => {
                    super::sync_point::complete_sync(program, invocations, memory, code_index, at);
                    start = at + 1;
                }
                other => break other,
            }
        };
        if warps_are_halves {
            let warps = lanes.iter().map(|&bits| u64::from(bits as u32 != 0) + u64::from(bits >> 32 != 0)).sum();
            counts.add_counted_group(steps, size as u64, warps);
        } else {
            counts.add_group(steps, lanes_in(lanes).map(|i| invocations[i].simt_index));
        }
        let end = end?;
        if members.is_empty() && !matches!(end, GroupEnd::Meet(_) | GroupEnd::Branch { .. }) {
            members_of(lanes, members);
        }
        match end {
            GroupEnd::Meet(pc) if placed => places.add_set(pc, lanes, None),
            GroupEnd::Meet(pc) => {
                for &i in members.iter() {
                    invocations[i].frame.as_mut().expect("running").pc = pc;
                }
            }
            GroupEnd::Branch { target, fall } if placed => {
                places.add_set(target, taken, None);
                places.add_set(fall, lanes, Some(taken));
            }
            GroupEnd::Branch { target, fall } => {
                for &i in members.iter() {
                    let jumps = taken[i / 64] >> (i % 64) & 1 != 0;
                    invocations[i].frame.as_mut().expect("running").pc = if jumps { target } else { fall };
                }
            }
            GroupEnd::Split => {
                for (&i, &pc) in members.iter().zip(targets.iter()) {
                    if placed {
                        places.add(pc, i);
                    } else {
                        invocations[i].frame.as_mut().expect("running").pc = pc;
                    }
                }
            }
            GroupEnd::Sync(pc) => {
                for &i in members.iter() {
                    invocations[i].frame.as_mut().expect("running").pc = pc;
                    stops[i] = Some(Stop::Sync(code_index, pc));
                }
                // The invocations still running may now share their callers.
                compare = !placed;
            }
            GroupEnd::Call(return_pc) => {
                let Insn::Call(call) = &program.codes[code_index as usize].insns[return_pc as usize - 1] else {
                    unreachable!("a group ends with Call at a call instruction")
                };
                if caller_codes.len() >= 256 {
                    return Err(invalid(&program.name, "call depth above 256 (recursion?)".into()));
                }
                let group = if members.len() == width { Members::All(width) } else { Members::Some(members, width) };
                enter_function(program, &mut memory.files, code_index, call, group, caller_codes.len() as u32 + 1)?;
                if placed && places.is_empty() {
                    // Every runnable invocation calls: they still share their callers, and
                    // all start the callee at its first instruction.
                    places.rebuild(instructions, width, members.iter().map(|&i| (i, 0)));
                    placed_code = call.code;
                } else if placed {
                    // Only some call: the frames take over from `places`, every runnable
                    // invocation's instruction written back.
                    hand_back(places, invocations);
                    placed = false;
                }
                for &i in members.iter() {
                    let invocation = &mut invocations[i];
                    let frame = invocation.frame.as_mut().expect("running");
                    frame.pc = return_pc;
                    let callee = Frame { code: call.code, pc: 0, result: call.result };
                    invocation.callers.push(std::mem::replace(frame, callee));
                }
            }
            GroupEnd::Return { src, len } => {
                // From the entry point the members are done, and the invocations left
                // still share their (empty) callers: the sets stay. From a call, those
                // left in the code no longer share the returning ones' callers: their
                // instructions written back, and the stacks compared again.
                if placed && !caller_codes.is_empty() {
                    hand_back(places, invocations);
                    placed = false;
                }
                for &i in members.iter() {
                    if return_from_function(&mut invocations[i], &mut memory.files, i, width, src, len) {
                        stops[i] = Some(Stop::Done);
                    }
                }
                compare = !placed;
            }
        }
    }
}

/// Writes the place of every invocation in `places` into its running frame and empties
/// `places`: the frames are where the scheduler finds the invocations from then on.
fn hand_back(places: &mut Places, invocations: &mut [Invocation]) {
    places.drain(|i, pc| invocations[i].frame.as_mut().expect("running").pc = pc);
}

/// The code every runnable invocation (`stops[i]` empty) runs, where they all run the
/// same code under the same callers (the same codes and return addresses); `None` where
/// they do not or none is runnable.
fn same_stack(invocations: &[Invocation], stops: &[Option<Stop>]) -> Option<u32> {
    let mut running = invocations.iter().zip(stops).filter(|(_, stop)| stop.is_none()).map(|(inv, _)| inv);
    let first = running.next()?;
    let code = first.frame.as_ref()?.code;
    let same = |inv: &Invocation| {
        inv.frame.as_ref().is_some_and(|frame| frame.code == code)
            && inv.callers.len() == first.callers.len()
            && inv.callers.iter().zip(&first.callers).all(|(a, b)| a.code == b.code && a.pc == b.pc)
    };
    running.all(same).then_some(code)
}

/// Allocates a code's register file for `width` lanes, every register at its template
/// value, the first time a worker thread runs the code (see [`super::program::Code::locals`]);
/// an error naming kernel `kernel` where the machine cannot give the memory (its size
/// is within the caps of [`super::budget`]).
pub(super) fn open_file(file: &mut Vec<u32>, template: &[u32], width: usize, kernel: &str) -> Result<(), BackendError> {
    // A batch narrower than the last (the dispatch's last one) needs a file of its width.
    if file.len() != template.len() * width {
        file.clear();
        super::budget::try_reserve(file, template.len() * width, || {
            format!("the registers of a batch of `{kernel}` ({} words for {width} invocations)", template.len())
        })?;
        for &value in template {
            file.extend(std::iter::repeat_n(value, width));
        }
    }
    Ok(())
}

/// The group of invocations of the set `lanes` (a word per 64 lanes; `size` of them) of
/// a batch `width` wide: all of them; in a batch a multiple of 64 wide, members filling
/// half or more of the chunks of 64 lanes they touch (by mask, those chunks computed
/// whole: cheaper than member by member from there on, and a batch's divergent groups
/// touch few chunks); or fewer, listed in `members` (where they are not listed yet). Half
/// since a listed member's words share one bound (`lanes.rs`): the path tracer 2 % faster
/// than with a quarter, the histogram the same; an eighth 6 % slower, and only chunks
/// every lane of which is a member 8 % slower (docs/benchmarks/interpreter.md).
fn group_of<'a>(
    members: &'a mut Vec<usize>,
    size: usize,
    lanes: &'a [u64],
    mask: &'a mut Vec<u32>,
    width: usize,
) -> Members<'a> {
    const { assert!(LANES == 64, "a chunk of lanes is a word of the set") };
    if size == width {
        return Members::All(width);
    }
    if width.is_multiple_of(LANES) && width <= 64 * LANES {
        let chunks = lanes.iter().enumerate().fold(0u64, |chunks, (c, &bits)| chunks | u64::from(bits != 0) << c);
        if size * 2 >= chunks.count_ones() as usize * LANES {
            // Only the chunks with a member are read (`Members::Masked`): only they are
            // written, from their words of the set.
            mask.resize(width, 0);
            let mut touched = chunks;
            while touched != 0 {
                let c = touched.trailing_zeros() as usize;
                touched &= touched - 1;
                let bits = lanes[c];
                for (i, word) in mask[c * LANES..][..LANES].iter_mut().enumerate() {
                    *word = 0u32.wrapping_sub((bits >> i) as u32 & 1);
                }
            }
            return Members::Masked(lanes, &mask[..], chunks);
        }
    }
    if members.is_empty() {
        members_of(lanes, members);
    }
    Members::Some(members, width)
}

/// Two distinct register files of `files`.
fn two_files(files: &mut [Vec<u32>], a: usize, b: usize) -> (&mut Vec<u32>, &mut Vec<u32>) {
    if a < b {
        let (low, high) = files.split_at_mut(b);
        (&mut low[a], &mut high[0])
    } else {
        let (low, high) = files.split_at_mut(a);
        (&mut high[0], &mut low[b])
    }
}

/// Starts the callee of `call` in the members' columns of its code's file: the
/// template (its variables; the rest once per file), the arguments from the caller's file (code `caller`), the pointers to its
/// locals (their frame at `depth`).
fn enter_function(
    program: &Program,
    files: &mut [Vec<u32>],
    caller: u32,
    call: &CallInsn,
    group: Members,
    depth: u32,
) -> Result<(), BackendError> {
    if call.code == caller {
        return Err(invalid(&program.name, "a function calls itself (recursion)".into()));
    }
    let callee = &program.codes[call.code as usize];
    let (caller_file, callee_file) = two_files(files, caller as usize, call.code as usize);
    let width = group.width();
    open_file(callee_file, &callee.template, width, &program.kernel)?;
    for &(reg, words) in &callee.locals {
        for r in reg as usize..(reg + words) as usize {
            group.fill(callee_file, r, 1, callee.template[r]);
        }
    }
    for &(src, len, dst) in call.arguments.iter() {
        for k in 0..len as usize {
            let (src, dst) = (src as usize + k, dst as usize + k);
            group.for_each(|l| callee_file[dst * width + l] = caller_file[src * width + l]);
        }
    }
    for &(reg, offset) in &callee.local_pointers {
        group.fill(callee_file, reg as usize, 1, FUNCTION | depth);
        group.fill(callee_file, reg as usize + 1, 1, offset);
    }
    Ok(())
}

/// Pops `invocation`'s running frame (its column `lane` of the files), copying `len`
/// words from `src` to the caller's result registers; true when it returned from the
/// entry point.
fn return_from_function(
    invocation: &mut Invocation,
    files: &mut [Vec<u32>],
    lane: usize,
    width: usize,
    src: u32,
    len: u32,
) -> bool {
    let Invocation { frame: running, callers, .. } = invocation;
    let returned = running.take().expect("running");
    match callers.pop() {
        None => true,
        Some(caller) => {
            if let Some((dst, words)) = returned.result
                && len > 0
            {
                let (from, to) = two_files(files, returned.code as usize, caller.code as usize);
                for k in 0..words.min(len) as usize {
                    to[(dst as usize + k) * width + lane] = from[(src as usize + k) * width + lane];
                }
            }
            *running = Some(caller);
            false
        }
    }
}

/// Runs the group `group` (all at instruction `pc` of code `code_index`, whose register
/// file is `file`) together until it reaches `meet`, a branch splits it (a conditional
/// jump: the members that jump into `taken`; a switch: each member's next instruction
/// into `targets`), it calls or returns, or it stops at a barrier or subgroup
/// operation. Adds the instructions the group executed (each for every member) to
/// `steps`.
#[allow(clippy::too_many_arguments)]
fn run_group(
    program: &Program,
    code_index: u32,
    (pc, meet): (u32, u32),
    group: Members,
    file: &mut [u32],
    memory: &mut GroupMemory,
    steps: &mut u64,
    (targets, taken): (&mut Vec<u32>, &mut Vec<u64>),
) -> Result<GroupEnd, BackendError> {
    let insns = &program.codes[code_index as usize].insns[..];
    let width = memory.width;
    let mut pc = pc as usize;
    let mut count = 0u64;
    // One unit of fuel per group started and per jump taken (every loop iteration
    // takes one): when it is spent, whether the dispatch must stop (`limit`). `$at`: the
    // instruction where the group is, named in the error.
    macro_rules! burn {
        ($at:expr) => {
            memory.fuel -= 1;
            if memory.fuel == 0 {
                memory.fuel = FUEL;
                if let Some(stop) = memory.limit.poll() {
                    let (file, line, function) = program.place(code_index, $at as u32);
                    return Err(memory.limit.error(stop, &program.kernel, &format!("{file}:{line}"), &function));
                }
            }
        };
    }
    burn!(pc);
    let end = loop {
        // At or past an invocation that waits: let it catch up (and merge when equal).
        if pc >= meet as usize {
            break GroupEnd::Meet(pc as u32);
        }
        let insn = &insns[pc];
        pc += 1;
        count += 1;
        match insn {
            Insn::Jump(target) => {
                burn!(pc - 1);
                pc = *target as usize;
            }
            Insn::JumpUnless { cond, target } => {
                let jumping = group.zeros(&file[*cond as usize * width..][..width], taken);
                if jumping == group.len() {
                    burn!(pc - 1);
                    pc = *target as usize;
                } else if jumping > 0 {
                    break GroupEnd::Branch { target: *target, fall: pc as u32 };
                }
            }
            Insn::Switch { selector, cases, default } => {
                let row = *selector as usize * width;
                let target = |l: usize| {
                    let value = file[row + l];
                    cases.iter().find(|(v, _)| *v == value).map_or(*default, |(_, t)| *t)
                };
                targets.clear();
                group.for_each(|l| targets.push(target(l)));
                let first = targets[0];
                if targets.iter().all(|&t| t == first) {
                    pc = first as usize;
                } else {
                    break GroupEnd::Split;
                }
            }
            Insn::Call(_) => break GroupEnd::Call(pc as u32),
            Insn::Return { src, len } => break GroupEnd::Return { src: *src, len: *len },
            Insn::Barrier { .. } | Insn::Gather(_) | Insn::Collective(_) => break GroupEnd::Sync(pc as u32 - 1),
            Insn::Fail(failure) => return Err(unsupported(&failure.0, failure.1)),
            // Row operations: each register of the group's members at once (`lanes`).
            Insn::Copy1 { dst, src } => group.copy(file, *dst as usize, *src as usize, 1),
            Insn::Copy2 { dst, src } => group.copy(file, *dst as usize, *src as usize, 2),
            Insn::Copy3 { dst, src } => group.copy(file, *dst as usize, *src as usize, 3),
            Insn::Copy4 { dst, src } => group.copy(file, *dst as usize, *src as usize, 4),
            Insn::Copy { dst, src, len } => group.copy(file, *dst as usize, *src as usize, *len as usize),
            Insn::Zero { dst, len } => group.fill(file, *dst as usize, *len as usize, 0),
            Insn::Bin { op, dst, a, b } => {
                let (dst, a, b) = (*dst as usize, *a as usize, *b as usize);
                per_operator!(op, |operator| group.binary(file, (dst, a, b), 1, operator));
            }
            Insn::BinV { op, dst, a, b, n, sa, sb } => {
                let (dst, a, b, n, sa, sb) =
                    (*dst as usize, *a as usize, *b as usize, *n as usize, *sa as usize, *sb as usize);
                per_operator!(op, |operator| if sa == 1 && sb == 1 {
                    group.binary(file, (dst, a, b), n, operator);
                } else {
                    for i in 0..n {
                        group.binary(file, (dst + i, a + i * sa, b + i * sb), 1, operator);
                    }
                });
            }
            Insn::Un { op, dst, src, n } => {
                let (dst, src, n) = (*dst as usize, *src as usize, *n as usize);
                macro_rules! each {
                    ($op:expr) => {{
                        #[inline(always)]
                        fn operator(x: u32) -> u32 {
                            $op.apply(x)
                        }
                        group.unary(file, dst, src, n, operator);
                    }};
                }
                match op {
                    UnOp::NegF => each!(UnOp::NegF),
                    UnOp::NegI => each!(UnOp::NegI),
                    UnOp::Not => each!(UnOp::Not),
                    UnOp::BitNot => each!(UnOp::BitNot),
                }
            }
            Insn::Select { dst, cond, accept, reject, n, sc } => {
                let (dst, cond, accept, reject) = (*dst as usize, *cond as usize, *accept as usize, *reject as usize);
                if *sc == 1 {
                    group.select(file, (dst, cond, accept, reject), *n as usize);
                } else {
                    for i in 0..*n as usize {
                        group.select(file, (dst + i, cond, accept + i, reject + i), 1);
                    }
                }
            }
            Insn::Splat { dst, src, n } => {
                for i in 0..*n as usize {
                    group.copy(file, *dst as usize + i, *src as usize, 1);
                }
            }
            Insn::Swizzle { dst, src, pattern, n } => {
                let (dst, src, n) = (*dst as usize, *src as usize, *n as usize);
                if dst + n <= src || src + 4 <= dst {
                    for (i, &p) in pattern.iter().enumerate().take(n) {
                        group.copy(file, dst + i, src + p as usize, 1);
                    }
                } else {
                    // Overlapping (not compiled today): every source word read first.
                    group.for_each(|l| {
                        let mut regs = LaneRegs::new(file, l, width);
                        let v = pattern.map(|p| regs[src + p as usize]);
                        regs.write(dst, &v[..n]);
                    });
                }
            }
            Insn::Convert { from, to, dst, src, n } => {
                let (dst, src, n) = (*dst as usize, *src as usize, *n as usize);
                // The conversions between floats and integers with the kinds fixed, so
                // that each is compiled into its row loop (they were a call a lane).
                macro_rules! each {
                    ($from:expr, $to:expr) => {
                        group.unary(file, dst, src, n, |x| {
                            super::arith::convert(x, $from, $to).expect("checked when compiled")
                        })
                    };
                }
                use naga::ScalarKind as K;
                match (*from, *to) {
                    (K::Float, K::Sint) => each!(K::Float, K::Sint),
                    (K::Float, K::Uint) => each!(K::Float, K::Uint),
                    (K::Sint, K::Float) => each!(K::Sint, K::Float),
                    (K::Uint, K::Float) => each!(K::Uint, K::Float),
                    (from, to) => each!(from, to),
                }
            }
            Insn::Extract { dst, base, index, count, stride, len } => {
                let (dst, base, index, len) = (*dst as usize, *base as usize, *index as usize, *len as usize);
                let (last, stride) = (count.saturating_sub(1) as usize, *stride as usize);
                group.for_each(|l| {
                    let mut regs = LaneRegs::new(file, l, width);
                    let at = (regs[index] as usize).min(last) * stride;
                    regs.copy(dst, base + at, len);
                });
            }
            Insn::PtrAdd { dst, base, add } => {
                let (dst, base, add) = (*dst as usize, *base as usize, *add);
                group.copy(file, dst, base, 1);
                group.unary(file, dst + 1, base + 1, 1, |offset| offset.wrapping_add(add));
            }
            Insn::PtrIndex { dst, base, index, count, stride } => {
                let (dst, base, index) = (*dst as usize, *base as usize, *index as usize);
                let (last, stride) = (count.saturating_sub(1) as usize, *stride as usize);
                group.binary(file, (dst + 1, base + 1, index), 1, |offset, i| {
                    (offset as usize + (i as usize).min(last) * stride) as u32
                });
                group.copy(file, dst, base, 1);
            }
            Insn::Compute(compute) => compute(file, group),
            Insn::Checked(checked) => {
                super::checked::execute(checked, program, code_index, pc as u32 - 1, file, group, memory)
            }
            _ => execute(insn, file, group, memory),
        }
    };
    *steps += count;
    Ok(end)
}
