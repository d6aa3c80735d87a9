//! What a barrier or subgroup operation does once every invocation of the batch stands
//! at it: a barrier nothing more (but the sanitizer's note of it); a subgroup gather
//! (broadcast, shuffle) computed for all invocations at once, and a collective (ballot,
//! reduction, scan) too, combined lane by lane in WGSL's scalar semantics.
//!
//! Why a file of its own: both the dispatch ([`super::dispatch`], once every invocation
//! has stopped there) and the group loop ([`super::interp`], when the whole batch reached
//! it as one group) complete them, and each of those calls the other's code otherwise.

use super::insn::Insn;
use super::invocations::{Batch, Invocation};
use super::program::Program;
use smallvec::SmallVec;

/// Completes the barrier or subgroup operation at instruction `pc` of code `code`, where
/// every invocation of the batch stands: a barrier needs nothing more (but the sanitizer's
/// note of it); a subgroup gather or collective is computed for all invocations now. The
/// caller moves them past it. (Run by the dispatch once every invocation has stopped
/// there, and by [`super::interp::run_until_sync`] at once when the whole batch reached it
/// as one group.)
pub(super) fn complete_sync(program: &Program, invocations: &[Invocation], memory: &mut Batch, code: u32, pc: u32) {
    let file = &mut memory.files[code as usize];
    match &program.codes[code as usize].insns[pc as usize] {
        Insn::Gather(gather) => self::gather(invocations, file, gather),
        Insn::Collective(collective) => self::collective(invocations, file, collective),
        Insn::Barrier { workgroup, storage } => {
            if let Some(local) = memory.sanitizing.as_mut() {
                local.barrier(*workgroup, *storage);
            }
        }
        _ => {}
    }
}

/// Computes a subgroup gather for every invocation of the workgroup (never a batch of
/// several: [`super::batch`] keeps kernels with subgroup operations one workgroup at a
/// time, so a local index is a lane of the register file).
fn gather(invocations: &[Invocation], file: &mut [u32], gather: &super::insn::GatherInsn) {
    use naga::GatherMode as G;
    let width = invocations.len();
    let (argument, len) = (gather.argument as usize, gather.len as usize);
    let sources: SmallVec<[usize; 64]> = invocations
        .iter()
        .map(|invocation| {
            let index = gather.index.map_or(0, |reg| file[reg as usize * width + invocation.local_index as usize]);
            let base = invocation.subgroup_id * invocation.subgroup_size;
            let lane = invocation.lane;
            let source = match gather.mode {
                G::BroadcastFirst => 0,
                G::Broadcast(_) | G::Shuffle(_) => index,
                G::ShuffleDown(_) => lane.wrapping_add(index),
                G::ShuffleUp(_) => lane.wrapping_sub(index),
                G::ShuffleXor(_) => lane ^ index,
                G::QuadBroadcast(_) => (lane & !3) | (index & 3),
                G::QuadSwap(direction) => match direction {
                    naga::Direction::X => lane ^ 1,
                    naga::Direction::Y => lane ^ 2,
                    naga::Direction::Diagonal => lane ^ 3,
                },
            };
            // Lanes outside the subgroup are indeterminate in WGSL: the invocation's own value.
            let source_index = base.wrapping_add(source) as usize;
            let in_range = source < invocation.subgroup_size && source_index < invocations.len();
            if in_range { source_index } else { invocation.local_index as usize }
        })
        .collect();
    // Component by component: the argument's row read through the sources, then written
    // to the result's row (every row read before any is written, as the result may be
    // the argument's registers).
    let mut rows: SmallVec<[u32; 256]> = SmallVec::with_capacity(width * len);
    for k in 0..len {
        let row = (argument + k) * width;
        rows.extend(sources.iter().map(|&from| file[row + from]));
    }
    let result = gather.result as usize;
    file[result * width..(result + len) * width].copy_from_slice(&rows);
}

/// Computes a subgroup ballot, reduction or scan for every invocation of the workgroup:
/// the lanes of a subgroup are the invocations `subgroup_id * size ..` in local-index
/// order, combined lane by lane in that order (float sums and products therefore
/// associate left to right; GPUs may use another order, a few ULPs apart). One
/// workgroup at a time, as for [`gather`].
fn collective(invocations: &[Invocation], file: &mut [u32], collective: &super::insn::CollectiveInsn) {
    use super::insn::CollectiveFun;
    use naga::CollectiveOperation as C;
    let width = invocations.len();
    let reg = |member: &Invocation, r: usize| file[r * width + member.local_index as usize];
    let len = collective.len as usize;
    let mut results = vec![0u32; invocations.len() * len];
    for (i, invocation) in invocations.iter().enumerate() {
        let size = invocation.subgroup_size as usize;
        let base = invocation.subgroup_id as usize * size;
        let members = &invocations[base..(base + size).min(invocations.len())];
        let lane = invocation.lane as usize;
        let out = &mut results[i * len..i * len + len];
        match collective.fun {
            CollectiveFun::Ballot { predicate } => {
                for (l, member) in members.iter().enumerate() {
                    if predicate.is_none_or(|p| reg(member, p as usize) != 0) {
                        out[l / 32] |= 1 << (l % 32);
                    }
                }
            }
            CollectiveFun::Operation { op, collective: mode, kind } => {
                let lanes = match mode {
                    C::Reduce => members,
                    C::InclusiveScan => &members[..=lane],
                    C::ExclusiveScan => &members[..lane],
                };
                let argument = collective.argument as usize;
                for (c, word) in out.iter_mut().enumerate() {
                    *word = lanes
                        .iter()
                        .fold(identity(op, kind), |acc, member| combine(op, kind, acc, reg(member, argument + c)));
                }
            }
        }
    }
    write_results(file, width, collective.result as usize, len, &results);
}

/// Writes each invocation's `len` words of `results` (lane-major) at register `result`
/// of its column.
fn write_results(file: &mut [u32], width: usize, result: usize, len: usize, results: &[u32]) {
    for (lane, words) in results.chunks_exact(len.max(1)).enumerate().take(width) {
        for (k, &word) in words.iter().enumerate() {
            file[(result + k) * width + lane] = word;
        }
    }
}

/// The value an empty subgroup operation gives (exclusive scans' first lane).
fn identity(op: naga::SubgroupOperation, kind: naga::ScalarKind) -> u32 {
    use naga::ScalarKind as K;
    use naga::SubgroupOperation as O;
    match (op, kind) {
        (O::All, _) => 1,
        (O::Any | O::Add | O::Or | O::Xor, K::Float) => 0.0f32.to_bits(),
        (O::Any | O::Add | O::Or | O::Xor, _) => 0,
        (O::Mul, K::Float) => 1.0f32.to_bits(),
        (O::Mul, _) => 1,
        (O::And, K::Bool) => 1,
        (O::And, _) => u32::MAX,
        (O::Min, K::Float) => f32::INFINITY.to_bits(),
        (O::Min, K::Sint) => i32::MAX as u32,
        (O::Min, _) => u32::MAX,
        (O::Max, K::Float) => f32::NEG_INFINITY.to_bits(),
        (O::Max, K::Sint) => i32::MIN as u32,
        (O::Max, _) => 0,
    }
}

/// One step of a subgroup operation, with WGSL's scalar semantics.
fn combine(op: naga::SubgroupOperation, kind: naga::ScalarKind, acc: u32, x: u32) -> u32 {
    use super::insn::BinOp;
    use naga::ScalarKind as K;
    use naga::SubgroupOperation as O;
    match (op, kind) {
        (O::All | O::And, _) => acc & x,
        (O::Any | O::Or, _) => acc | x,
        (O::Xor, _) => acc ^ x,
        (O::Add, K::Float) => BinOp::AddF.apply(acc, x),
        (O::Add, _) => BinOp::AddI.apply(acc, x),
        (O::Mul, K::Float) => BinOp::MulF.apply(acc, x),
        (O::Mul, _) => BinOp::MulI.apply(acc, x),
        (O::Min, _) => super::arith::math(naga::MathFunction::Min, kind, acc, x, 0).unwrap_or(acc),
        (O::Max, _) => super::arith::math(naga::MathFunction::Max, kind, acc, x, 0).unwrap_or(acc),
    }
}
