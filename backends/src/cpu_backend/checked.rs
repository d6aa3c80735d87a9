//! The sanitizer at run time: an [`Insn::Checked`] instruction of a sanitizing program
//! ([`super::sanitize`]) run for a group. Each member's access is worked out from its
//! registers (the index against the length, the words a load or store touches) and
//! handed to [`super::sanitize`]'s checks, then the instruction runs as usual
//! ([`super::execute`]; an index clamped as the normal program clamps it).
//!
//! Why apart from [`super::sanitize`]: the sanitizer's state rides along in the
//! group's memory ([`super::execute::GroupMemory`] holds a [`Sanitizing`]), so that
//! state sits below the executor, while running a checked instruction needs the
//! executor: this file sits above both, beside the group loop ([`super::interp`]) that
//! calls it.

use super::execute::{self, GroupMemory};
use super::insn::Insn;
use super::lanes::{LaneRegs, Members};
use super::layout::Piece;
use super::memory::{BUFFER, TAG_MASK, WORKGROUP};
use super::program::Program;
use super::sanitize::{FindingKind, Local, Op, Sanitizer, Sanitizing, Touch, check_access, site_of};

/// Runs checked instruction `insn` (instruction `pc` of code `code`) for `members`:
/// each member's access checked and recorded, then the instruction as usual.
#[allow(clippy::too_many_arguments)]
pub(super) fn execute(
    insn: &Insn,
    program: &Program,
    code: u32,
    pc: u32,
    file: &mut [u32],
    members: Members,
    memory: &mut GroupMemory,
) {
    check(insn, program, code, pc, file, members, memory);
    let width = memory.width;
    match *insn {
        Insn::PtrIndex { dst, base, index, count, stride } => members.for_each(|lane| {
            let mut regs = LaneRegs::new(file, lane, width);
            let (tag, offset, i) = (regs[base as usize], regs[base as usize + 1], regs[index as usize]);
            let at = (i as usize).min(count.saturating_sub(1) as usize) * stride as usize;
            regs[dst as usize] = tag;
            regs[dst as usize + 1] = (offset as usize + at) as u32;
        }),
        Insn::Extract { dst, base, index, count, stride, len } => members.for_each(|lane| {
            let mut regs = LaneRegs::new(file, lane, width);
            let at = (regs[index as usize] as usize).min(count.saturating_sub(1) as usize) * stride as usize;
            regs.copy(dst as usize, base as usize + at, len as usize);
        }),
        _ => execute::execute(insn, file, members, memory),
    }
}

/// Checks and records each member's access of `insn`.
#[allow(clippy::too_many_arguments)]
fn check(
    insn: &Insn,
    program: &Program,
    code: u32,
    pc: u32,
    file: &mut [u32],
    members: Members,
    memory: &mut GroupMemory,
) {
    let width = memory.width;
    let (per_workgroup, workgroup_words) = (memory.per_workgroup, memory.workgroup_words);
    let GroupMemory { buffers, sanitizer, .. } = memory;
    let Some(Sanitizing { shared, local }) = sanitizer else { return };
    let (shared, local): (&Sanitizer, &mut Local) = (shared, local);
    let buffers: &[_] = buffers;
    let buffer_words = |tag: u32| buffers.get((tag & !TAG_MASK) as usize).map_or(0, |b| b.len());
    let binding = |slot: u32| {
        program.binding_names.get(slot as usize).map_or_else(|| format!("binding {slot}"), |n| format!("`{n}`"))
    };
    let site = site_of(code, pc);
    members.for_each(|lane| {
        let regs = LaneRegs::new(file, lane, width);
        let me = local.first_id + lane as u64;
        // The lane's workgroup's region in the batch's workgroup memory (and shadows).
        let region =
            if workgroup_words == 0 || per_workgroup == width { 0 } else { lane / per_workgroup } * workgroup_words;
        // An index check: `index` against `length` elements.
        let index_check = |local: &mut Local, index: u64, length: u64, of: &dyn Fn() -> String| {
            if index >= length {
                local.found(shared, program, (FindingKind::OutOfRangeIndex, code, pc), || {
                    format!("index {index}, length {length}{}", of())
                });
            }
        };
        let pointer = |reg: u32| (regs[reg as usize], regs[reg as usize + 1] as usize);
        let mut touches: smallvec::SmallVec<[Touch; 2]> = smallvec::SmallVec::new();
        let through = |op: Op, (tag, offset): (u32, usize), len: usize| match tag & TAG_MASK {
            BUFFER => Touch { op, tag, word: offset / 4, len },
            _ => Touch { op, tag, word: offset, len },
        };
        match insn {
            Insn::PtrIndex { index, count, .. } | Insn::Extract { index, count, .. } => {
                index_check(local, u64::from(regs[*index as usize]), u64::from(*count), &String::new);
            }
            Insn::PtrIndexRt { base, index, stride, .. } => {
                let (tag, offset) = pointer(*base);
                if tag & TAG_MASK == BUFFER {
                    let available = (buffer_words(tag) * 4).saturating_sub(offset);
                    let length = (available / (*stride).max(1) as usize) as u64;
                    index_check(local, u64::from(regs[*index as usize]), length, &|| {
                        format!(" (elements in {})", binding(tag & !TAG_MASK))
                    });
                }
            }
            Insn::LoadElement(load) => {
                let bytes = buffer_words(BUFFER | load.buffer) * 4;
                let length = load.elements(bytes);
                let index = regs[load.index as usize];
                index_check(local, u64::from(index), length, &|| format!(" (elements in {})", binding(load.buffer)));
                let first = load.first_word(bytes, index);
                match &load.runs {
                    Some(runs) => touches.extend(runs.iter().map(|&(start, words)| Touch {
                        op: Op::Read,
                        tag: BUFFER | load.buffer,
                        word: first + start as usize,
                        len: words as usize,
                    })),
                    None => touches.push(Touch {
                        op: Op::Read,
                        tag: BUFFER | load.buffer,
                        word: first,
                        len: load.len as usize,
                    }),
                }
            }
            Insn::Load { pointer: p, len, .. } => touches.push(through(Op::Read, pointer(*p), *len as usize)),
            Insn::LoadRuns { pointer: p, runs, .. } => {
                let (tag, offset) = pointer(*p);
                for &(start, words) in runs.iter() {
                    let mut touch = through(Op::Read, (tag, offset), words as usize);
                    touch.word += start as usize;
                    touches.push(touch);
                }
            }
            Insn::Store { pointer: p, len, .. } => touches.push(through(Op::Write, pointer(*p), *len as usize)),
            Insn::LoadMixed { pointer: p, plan, .. } | Insn::StoreMixed { pointer: p, plan, .. } => {
                let op = if matches!(insn, Insn::LoadMixed { .. }) { Op::Read } else { Op::Write };
                let (tag, offset) = pointer(*p);
                // Whole words only: two halves of a word are different WGSL locations.
                for piece in plan.iter() {
                    match *piece {
                        Piece::Words { memory: at, len, .. } => {
                            touches.push(Touch { op, tag, word: (offset + at as usize) / 4, len: len as usize })
                        }
                        Piece::Half { memory: at, .. } => {
                            let word = (offset + at as usize) / 4;
                            if word >= buffer_words(tag) {
                                touches.push(Touch { op, tag, word, len: 1 });
                            }
                        }
                    }
                }
            }
            Insn::LoadWorkgroup { address, len, .. } => {
                touches.push(Touch { op: Op::Read, tag: WORKGROUP, word: *address as usize, len: *len as usize })
            }
            Insn::StoreWorkgroup { address, len, .. } => {
                touches.push(Touch { op: Op::Write, tag: WORKGROUP, word: *address as usize, len: *len as usize })
            }
            Insn::LoadBuffer { buffer, address, len, .. } => {
                touches.push(Touch { op: Op::Read, tag: BUFFER | buffer, word: *address as usize, len: *len as usize })
            }
            Insn::StoreBuffer { buffer, address, len, .. } => {
                touches.push(Touch { op: Op::Write, tag: BUFFER | buffer, word: *address as usize, len: *len as usize })
            }
            Insn::Atomic(atomic) => touches.push(through(Op::Atomic, pointer(atomic.pointer), 1)),
            _ => {}
        }
        for touch in touches {
            check_access(shared, local, program, (code, pc, site), me, &touch, &buffer_words, &binding, region);
        }
    });
}
