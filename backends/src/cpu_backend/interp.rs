//! The dispatch loop: runs one invocation's bytecode until it ends or reaches a
//! barrier or subgroup gather, where it stops (the barrier's instruction still next) so
//! that the workgroup's other invocations can catch up.

use super::decode::Program;
use super::error::{invalid, unsupported};
use super::insn::{BinOp, Insn};
use super::memory::{BUFFER, Frame, Memory, TAG_MASK, copy_regs, read_buffer, read_mixed, write_buffer, write_mixed};
use crate::error::BackendError;
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
    /// Register files of returned frames, reused by later calls.
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

#[inline(always)]
fn bool_bits(b: bool) -> u32 {
    u32::from(b)
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

/// Runs `invocation` until it stops; counts executed instructions into `executed`.
pub(super) fn run(
    program: &Program,
    invocation: &mut Invocation,
    buffers: &[Vec<AtomicU32>],
    workgroup: &mut [u32],
    executed: &mut u64,
) -> Result<Stop, BackendError> {
    let Invocation { frame: running, callers, spare, private, .. } = invocation;
    let mut count = 0u64;
    let result = 'frames: loop {
        let Some(frame) = running.as_mut() else { break Ok(Stop::Done) };
        let code_index = frame.code;
        let code = &program.codes[code_index as usize];
        let insns = &code.insns[..];
        let regs = &mut frame.regs[..];
        let mut pc = frame.pc as usize;
        loop {
            let insn = &insns[pc];
            pc += 1;
            count += 1;
            match insn {
                Insn::Copy1 { dst, src } => regs[*dst as usize] = regs[*src as usize],
                Insn::Copy2 { dst, src } => copy_regs(regs, *dst as usize, *src as usize, 2),
                Insn::Copy3 { dst, src } => copy_regs(regs, *dst as usize, *src as usize, 3),
                Insn::Copy4 { dst, src } => copy_regs(regs, *dst as usize, *src as usize, 4),
                Insn::Copy { dst, src, len } => copy_regs(regs, *dst as usize, *src as usize, *len as usize),
                Insn::Zero { dst, len } => regs[*dst as usize..(*dst + *len) as usize].fill(0),
                Insn::Bin { op, dst, a, b } => {
                    let (x, y) = (regs[*a as usize], regs[*b as usize]);
                    regs[*dst as usize] = match op {
                        BinOp::AddF => (f32::from_bits(x) + f32::from_bits(y)).to_bits(),
                        BinOp::MulF => (f32::from_bits(x) * f32::from_bits(y)).to_bits(),
                        BinOp::AddI => x.wrapping_add(y),
                        BinOp::Eq => bool_bits(x == y),
                        BinOp::And => x & y,
                        _ => op.apply(x, y),
                    };
                }
                Insn::BinV { op, dst, a, b, n, sa, sb } => {
                    let operands = (*dst as usize, *a as usize, *b as usize, *n as usize, *sa as usize, *sb as usize);
                    // One loop per operator, the operator's match outside it.
                    macro_rules! per_operator {
                        ($($variant:ident),*) => {
                            match op {
                                $(BinOp::$variant => component_wise(regs, operands, |x, y| BinOp::$variant.apply(x, y)),)*
                            }
                        };
                    }
                    per_operator!(
                        AddF, SubF, MulF, DivF, ModF, AddI, SubI, MulI, DivU, DivS, ModU, ModS, EqF, NeF, LtF, LeF,
                        GtF, GeF, Eq, Ne, LtS, LeS, GtS, GeS, LtU, LeU, GtU, GeU, And, Xor, Or, LogicalAnd, LogicalOr,
                        Shl, ShrU, ShrS
                    );
                }
                Insn::Un { op, dst, src, n } => {
                    for i in 0..*n as usize {
                        regs[*dst as usize + i] = op.apply(regs[*src as usize + i]);
                    }
                }
                Insn::Select { dst, cond, accept, reject, n, sc } => {
                    let (dst, cond, accept, reject) =
                        (*dst as usize, *cond as usize, *accept as usize, *reject as usize);
                    let sc = *sc as usize;
                    for i in 0..*n as usize {
                        regs[dst + i] = if regs[cond + i * sc] != 0 { regs[accept + i] } else { regs[reject + i] };
                    }
                }
                Insn::Swizzle { dst, src, pattern, n } => {
                    let src = *src as usize;
                    let v = [
                        regs[src + pattern[0] as usize],
                        regs[src + pattern[1] as usize],
                        regs[src + pattern[2] as usize],
                        regs[src + pattern[3] as usize],
                    ];
                    let n = *n as usize;
                    regs[*dst as usize..*dst as usize + n].copy_from_slice(&v[..n]);
                }
                Insn::Splat { dst, src, n } => {
                    let v = regs[*src as usize];
                    regs[*dst as usize..*dst as usize + *n as usize].fill(v);
                }
                Insn::Convert { from, to, dst, src, n } => {
                    for i in 0..*n as usize {
                        regs[*dst as usize + i] =
                            super::arith::convert(regs[*src as usize + i], *from, *to).expect("checked when compiled");
                    }
                }
                Insn::Extract { dst, base, index, count, stride, len } => {
                    let at = (regs[*index as usize] as usize).min(count.saturating_sub(1) as usize) * *stride as usize;
                    copy_regs(regs, *dst as usize, *base as usize + at, *len as usize);
                }
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
                    let memory = Memory {
                        buffers,
                        workgroup: &mut *workgroup,
                        private: &mut private[..],
                        callers: &mut callers[..],
                    };
                    let stride = *stride as usize;
                    let len = (memory.words(regs, tag).saturating_sub(offset) / stride.max(1)).max(1);
                    let at = (regs[*index as usize] as usize).min(len - 1) * stride;
                    regs[dst] = tag;
                    regs[dst + 1] = (offset + at) as u32;
                }
                Insn::Load { dst, pointer, len } => {
                    let pointer = (regs[*pointer as usize], regs[*pointer as usize + 1]);
                    let mut memory = Memory {
                        buffers,
                        workgroup: &mut *workgroup,
                        private: &mut private[..],
                        callers: &mut callers[..],
                    };
                    memory.load(regs, pointer, *dst as usize, *len as usize);
                }
                Insn::Store { pointer, src, len } => {
                    let pointer = (regs[*pointer as usize], regs[*pointer as usize + 1]);
                    let mut memory = Memory {
                        buffers,
                        workgroup: &mut *workgroup,
                        private: &mut private[..],
                        callers: &mut callers[..],
                    };
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
                    regs[dst..dst + len].copy_from_slice(&workgroup[address..address + len]);
                }
                Insn::StoreWorkgroup { address, src, len } => {
                    let (src, address, len) = (*src as usize, *address as usize, *len as usize);
                    workgroup[address..address + len].copy_from_slice(&regs[src..src + len]);
                }
                Insn::LoadPrivate { dst, address, len } => {
                    let (dst, address, len) = (*dst as usize, *address as usize, *len as usize);
                    regs[dst..dst + len].copy_from_slice(&private[address..address + len]);
                }
                Insn::StorePrivate { address, src, len } => {
                    let (src, address, len) = (*src as usize, *address as usize, *len as usize);
                    private[address..address + len].copy_from_slice(&regs[src..src + len]);
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
                    let memory = Memory {
                        buffers,
                        workgroup: &mut *workgroup,
                        private: &mut private[..],
                        callers: &mut callers[..],
                    };
                    let words = memory.words(regs, tag);
                    regs[*dst as usize] = (words.saturating_sub(offset as usize) / (*stride).max(1) as usize) as u32;
                }
                Insn::Compute(compute) => compute(regs),
                Insn::Jump(target) => pc = *target as usize,
                Insn::JumpUnless { cond, target } => {
                    if regs[*cond as usize] == 0 {
                        pc = *target as usize;
                    }
                }
                Insn::Switch { selector, cases, default } => {
                    let value = regs[*selector as usize];
                    pc = cases.iter().find(|(v, _)| *v == value).map_or(*default, |(_, t)| *t) as usize;
                }
                Insn::Call(call) => {
                    if callers.len() >= 256 {
                        break 'frames Err(invalid(&program.name, "call depth above 256 (recursion?)".into()));
                    }
                    let callee = &program.codes[call.code as usize];
                    let mut callee_regs = spare.pop().unwrap_or_default();
                    callee_regs.clear();
                    callee_regs.extend_from_slice(&callee.template);
                    for &(src, len, dst) in call.arguments.iter() {
                        callee_regs[dst as usize..(dst + len) as usize]
                            .copy_from_slice(&regs[src as usize..(src + len) as usize]);
                    }
                    let depth = callers.len() as u32 + 1;
                    for &(reg, offset) in &callee.local_pointers {
                        callee_regs[reg as usize] = super::memory::FUNCTION | depth;
                        callee_regs[reg as usize + 1] = offset;
                    }
                    frame.pc = pc as u32;
                    let callee_frame = Frame { code: call.code, pc: 0, regs: callee_regs, result: call.result };
                    callers.push(std::mem::replace(frame, callee_frame));
                    continue 'frames;
                }
                Insn::Return { src, len } => {
                    let returned = running.take().expect("running");
                    match callers.pop() {
                        None => {
                            spare.push(returned.regs);
                            break 'frames Ok(Stop::Done);
                        }
                        Some(mut caller) => {
                            if let Some((dst, words)) = returned.result
                                && *len > 0
                            {
                                let (src, words) = (*src as usize, words.min(*len) as usize);
                                caller.regs[dst as usize..dst as usize + words]
                                    .copy_from_slice(&returned.regs[src..src + words]);
                            }
                            spare.push(returned.regs);
                            *running = Some(caller);
                            continue 'frames;
                        }
                    }
                }
                Insn::Barrier | Insn::Gather(_) | Insn::Collective(_) => {
                    frame.pc = pc as u32 - 1;
                    break 'frames Ok(Stop::Sync(code_index, pc as u32 - 1));
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
                    let mut memory = Memory {
                        buffers,
                        workgroup: &mut *workgroup,
                        private: &mut private[..],
                        callers: &mut callers[..],
                    };
                    let old = memory.atomic(regs, pointer, apply);
                    if let Some(result) = atomic.result {
                        regs[result as usize] = old;
                        if let Some(expected) = expected {
                            regs[result as usize + 1] = u32::from(old == expected);
                        }
                    }
                }
                Insn::Fail(failure) => break 'frames Err(unsupported(&failure.0, failure.1)),
            }
        }
    };
    *executed += count;
    result
}
