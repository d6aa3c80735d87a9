//! One instruction for one invocation: what the group loop of [`super::interp`] hands to
//! each member in turn (arithmetic not looped over the group itself, memory loads and
//! stores through pointers, atomics), never control flow.

use super::insn::Insn;
use super::interp::Lane;
use super::memory::{BUFFER, Memory, TAG_MASK, copy_words, read_buffer, read_mixed, write_buffer, write_mixed};
use std::sync::atomic::AtomicU32;

/// Executes, for one invocation, an instruction that `run_group` neither runs itself
/// (control flow) nor loops over the group on its own (the most frequent ones).
#[inline(always)]
pub(super) fn execute(insn: &Insn, lane: &mut Lane, buffers: &[Vec<AtomicU32>], workgroup: &mut [u32]) {
    let Lane { regs, private, callers } = lane;
    let regs = &mut **regs;
    match insn {
        Insn::Un { op, dst, src, n } => {
            for i in 0..*n as usize {
                regs[*dst as usize + i] = op.apply(regs[*src as usize + i]);
            }
        }
        Insn::Swizzle { dst, src, pattern, n } => {
            let (dst, src) = (*dst as usize, *src as usize);
            let at = |i: usize| src + pattern[i] as usize;
            // Component by component: gathering into an array and copying it out made
            // the CPU forward two 4-byte stores into one 8-byte load, which stalls.
            match *n {
                2 => {
                    let (x, y) = (regs[at(0)], regs[at(1)]);
                    regs[dst] = x;
                    regs[dst + 1] = y;
                }
                3 => {
                    let (x, y, z) = (regs[at(0)], regs[at(1)], regs[at(2)]);
                    regs[dst] = x;
                    regs[dst + 1] = y;
                    regs[dst + 2] = z;
                }
                _ => {
                    let v = [regs[at(0)], regs[at(1)], regs[at(2)], regs[at(3)]];
                    for (i, &x) in v.iter().enumerate().take(*n as usize) {
                        regs[dst + i] = x;
                    }
                }
            }
        }
        Insn::Convert { from, to, dst, src, n } => {
            for i in 0..*n as usize {
                regs[*dst as usize + i] =
                    super::arith::convert(regs[*src as usize + i], *from, *to).expect("checked when compiled");
            }
        }
        Insn::Image(image) => super::image::execute(image, regs, buffers),
        Insn::PtrAdd { dst, base, add } => {
            let (dst, base) = (*dst as usize, *base as usize);
            regs[dst] = regs[base];
            regs[dst + 1] = regs[base + 1].wrapping_add(*add);
        }
        Insn::PtrIndex { dst, base, index, count, stride } => {
            let (dst, base) = (*dst as usize, *base as usize);
            let at = (regs[*index as usize] as usize).min(count.saturating_sub(1) as usize) * *stride as usize;
            regs[dst] = regs[base];
            regs[dst + 1] = (regs[base + 1] as usize + at) as u32;
        }
        Insn::PtrIndexRt { dst, base, index, stride } => {
            let (dst, base) = (*dst as usize, *base as usize);
            let (tag, offset) = (regs[base], regs[base + 1] as usize);
            let memory =
                Memory { buffers, workgroup: &mut *workgroup, private: &mut private[..], callers: &mut callers[..] };
            let stride = *stride as usize;
            let len = (memory.words(regs, tag).saturating_sub(offset) / stride.max(1)).max(1);
            let at = (regs[*index as usize] as usize).min(len - 1) * stride;
            regs[dst] = tag;
            regs[dst + 1] = (offset + at) as u32;
        }
        Insn::Load { dst, pointer, len } => {
            let pointer = (regs[*pointer as usize], regs[*pointer as usize + 1]);
            let mut memory =
                Memory { buffers, workgroup: &mut *workgroup, private: &mut private[..], callers: &mut callers[..] };
            memory.load(regs, pointer, *dst as usize, *len as usize);
        }
        Insn::Store { pointer, src, len } => {
            let pointer = (regs[*pointer as usize], regs[*pointer as usize + 1]);
            let mut memory =
                Memory { buffers, workgroup: &mut *workgroup, private: &mut private[..], callers: &mut callers[..] };
            memory.store(regs, pointer, *src as usize, *len as usize);
        }
        Insn::LoadMixed { dst, pointer, plan } => {
            let (tag, offset) = (regs[*pointer as usize], regs[*pointer as usize + 1]);
            // Only pointers into buffers get a plan.
            if tag & TAG_MASK == BUFFER {
                let buffer = &buffers[(tag & !TAG_MASK) as usize];
                read_mixed(buffer, offset as usize, regs, *dst as usize, plan);
            }
        }
        Insn::StoreMixed { pointer, src, plan } => {
            let (tag, offset) = (regs[*pointer as usize], regs[*pointer as usize + 1]);
            if tag & TAG_MASK == BUFFER {
                let buffer = &buffers[(tag & !TAG_MASK) as usize];
                write_mixed(buffer, offset as usize, regs, *src as usize, plan);
            }
        }
        Insn::LoadWorkgroup { dst, address, len } => {
            let (dst, address, len) = (*dst as usize, *address as usize, *len as usize);
            copy_words(&mut regs[dst..dst + len], &workgroup[address..address + len]);
        }
        Insn::StoreWorkgroup { address, src, len } => {
            let (src, address, len) = (*src as usize, *address as usize, *len as usize);
            copy_words(&mut workgroup[address..address + len], &regs[src..src + len]);
        }
        Insn::LoadPrivate { dst, address, len } => {
            let (dst, address, len) = (*dst as usize, *address as usize, *len as usize);
            copy_words(&mut regs[dst..dst + len], &private[address..address + len]);
        }
        Insn::StorePrivate { address, src, len } => {
            let (src, address, len) = (*src as usize, *address as usize, *len as usize);
            copy_words(&mut private[address..address + len], &regs[src..src + len]);
        }
        Insn::LoadBuffer { dst, buffer, address, len } => {
            let (dst, len) = (*dst as usize, *len as usize);
            read_buffer(&buffers[*buffer as usize], *address as usize, &mut regs[dst..dst + len]);
        }
        Insn::StoreBuffer { buffer, address, src, len } => {
            let (src, len) = (*src as usize, *len as usize);
            write_buffer(&buffers[*buffer as usize], *address as usize, &regs[src..src + len]);
        }
        Insn::ArrayLength { dst, pointer, stride } => {
            let (tag, offset) = (regs[*pointer as usize], regs[*pointer as usize + 1]);
            let memory =
                Memory { buffers, workgroup: &mut *workgroup, private: &mut private[..], callers: &mut callers[..] };
            let words = memory.words(regs, tag);
            regs[*dst as usize] = (words.saturating_sub(offset as usize) / (*stride).max(1) as usize) as u32;
        }
        Insn::Atomic(atomic) => {
            use naga::AtomicFunction as A;
            let pointer = (regs[atomic.pointer as usize], regs[atomic.pointer as usize + 1]);
            let operand = regs[atomic.value as usize];
            let expected = atomic.compare.map(|c| regs[c as usize]);
            let (fun, signed) = (atomic.fun, atomic.signed);
            let apply = move |old: u32| -> u32 {
                match fun {
                    A::Add => old.wrapping_add(operand),
                    A::Subtract => old.wrapping_sub(operand),
                    A::And => old & operand,
                    A::InclusiveOr => old | operand,
                    A::ExclusiveOr => old ^ operand,
                    A::Min if signed => (old as i32).min(operand as i32) as u32,
                    A::Max if signed => (old as i32).max(operand as i32) as u32,
                    A::Min => old.min(operand),
                    A::Max => old.max(operand),
                    A::Exchange { compare: None } => operand,
                    A::Exchange { compare: Some(_) } => {
                        if Some(old) == expected {
                            operand
                        } else {
                            old
                        }
                    }
                }
            };
            let mut memory =
                Memory { buffers, workgroup: &mut *workgroup, private: &mut private[..], callers: &mut callers[..] };
            let old = memory.atomic(regs, pointer, apply);
            if let Some(result) = atomic.result {
                regs[result as usize] = old;
                if let Some(expected) = expected {
                    regs[result as usize + 1] = u32::from(old == expected);
                }
            }
        }
        Insn::Copy1 { .. }
        | Insn::Copy2 { .. }
        | Insn::Copy3 { .. }
        | Insn::Copy4 { .. }
        | Insn::Copy { .. }
        | Insn::Zero { .. }
        | Insn::Bin { .. }
        | Insn::BinV { .. }
        | Insn::Select { .. }
        | Insn::Splat { .. }
        | Insn::Extract { .. }
        | Insn::Compute(_) => unreachable!("run for the whole group by `run_group`"),
        Insn::Jump(_)
        | Insn::JumpUnless { .. }
        | Insn::Switch { .. }
        | Insn::Call(_)
        | Insn::Return { .. }
        | Insn::Barrier
        | Insn::Gather(_)
        | Insn::Collective(_)
        | Insn::Fail(_) => unreachable!("control flow is run by the group"),
    }
}
