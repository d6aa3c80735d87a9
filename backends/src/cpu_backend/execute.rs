//! The instructions that the group loop of [`super::interp`] runs member by member
//! (memory through pointers, atomics, textures): decoded once for the group, then
//! executed for each member in turn; never control flow. Some go a register at a time
//! instead: a buffer's words at an address known when compiling (the same for every
//! member), a buffer array's element (`load_element`), and loads and stores through
//! pointers into the workgroup memory of a batch of one workgroup. And [`GroupMemory`],
//! what they reach besides the running code's registers.
//!
//! Why [`GroupMemory`] is defined here and not in the group loop that fills it: this
//! file and the sanitizer's checked instructions ([`super::checked`]) take it, and both
//! sit below the group loop, so that the loop's file imports them and none of them
//! imports it back.

use super::insn::{ElementLoad, Insn, element_offset};
use super::lanes::{LaneRegs, Members};
use super::limit::Limit;
use super::memory::{BUFFER, Memory, TAG_MASK, WORKGROUP, read_mixed, write_buffer, write_mixed};
use super::sanitize::Sanitizing;
use std::sync::atomic::{AtomicU32, Ordering};

/// What the members of a running group reach besides the running code's registers.
pub(super) struct GroupMemory<'a> {
    /// Bound buffers in the kernel's binding order.
    pub buffers: &'a [Vec<AtomicU32>],
    /// The batch's workgroup memory: `workgroup_words` per workgroup, in order.
    pub workgroup: &'a mut [u32],
    /// Words of workgroup memory per workgroup.
    pub workgroup_words: usize,
    /// Invocations per workgroup (lane `l` is in the batch's workgroup `l / per_workgroup`).
    pub per_workgroup: usize,
    /// Every invocation's private memory, `private_words` each.
    pub private: &'a mut [u32],
    /// Words of private memory per invocation.
    pub private_words: usize,
    /// Every code's register file (the running code's taken out).
    pub files: &'a mut [Vec<u32>],
    /// The codes of the group's callers, outermost first.
    pub callers: &'a [u32],
    /// Lanes per register file (the batch's invocations).
    pub width: usize,
    /// The dispatch's time limit.
    pub limit: &'a Limit,
    /// Fuel left before the limit is looked at.
    pub fuel: u32,
    /// The sanitizer, when the dispatch sanitizes.
    pub sanitizer: Option<Sanitizing<'a>>,
}

/// Executes, for each member of `members` (lanes of the running file `file`), an
/// instruction that `run_group` neither runs itself (control flow) nor runs as row
/// operations.
pub(super) fn execute(insn: &Insn, file: &mut [u32], members: Members, group: &mut GroupMemory) {
    let width = group.width;
    let (private_words, workgroup_words, per_workgroup) =
        (group.private_words, group.workgroup_words, group.per_workgroup);
    let GroupMemory { buffers, workgroup: shared, private: privates, files, callers, .. } = group;
    let buffers: &[_] = buffers;
    // `$body` for each member, with its registers, lane and private memory.
    macro_rules! each_lane {
        (|$regs:ident, $lane:ident, $private:ident| $body:block) => {
            members.for_each(|$lane| {
                let mut lane_regs = LaneRegs::new(file, $lane, width);
                let $regs = &mut lane_regs;
                let $private = &mut privates[$lane * private_words..($lane + 1) * private_words];
                let _ = (&$regs, &$private);
                $body
            })
        };
    }
    // The memory of lane `$lane`'s workgroup (a batch holds several: `super::batch`);
    // computed where used, as it costs a division where the batch has several.
    macro_rules! workgroup {
        ($lane:ident) => {{
            let first = if workgroup_words == 0 || per_workgroup == width { 0 } else { $lane / per_workgroup };
            &mut shared[first * workgroup_words..][..workgroup_words]
        }};
    }
    macro_rules! memory {
        ($lane:ident, $private:ident) => {
            Memory {
                buffers,
                workgroup: workgroup!($lane),
                private: &mut *$private,
                files: &mut **files,
                callers,
                lane: $lane,
                width,
            }
        };
    }
    // Whether the batch is one workgroup (or has no workgroup memory): every member's
    // workgroup memory is then the same words.
    let one_workgroup = workgroup_words == 0 || per_workgroup == width;
    match insn {
        Insn::Image(image) => each_lane!(|regs, lane, private| {
            super::image::execute(image, regs, buffers);
        }),
        Insn::PtrIndexRt { dst, base, index, stride } => each_lane!(|regs, lane, private| {
            let (dst, base) = (*dst as usize, *base as usize);
            let (tag, offset) = (regs[base], regs[base + 1] as usize);
            let (stride, index) = (*stride as usize, regs[*index as usize] as usize);
            // Buffers (the common case) inline; the other regions' sizes in `Memory`.
            let size = match tag & TAG_MASK {
                BUFFER => buffers[(tag & !TAG_MASK) as usize].len() * 4,
                _ => memory!(lane, private).words(regs, tag),
            };
            let at = element_offset(size.saturating_sub(offset), stride, index);
            regs[dst] = tag;
            regs[dst + 1] = (offset + at) as u32;
        }),
        // A whole value, or the runs (first word, words) of it that its uses read
        // (`load_fields`): each word as WGSL reads it, 0 outside its buffer or region.
        Insn::Load { dst, pointer, len } | Insn::LoadRuns { dst, pointer, len, .. } => {
            let whole = [(0, *len)];
            let runs: &[(u32, u32)] = match insn {
                Insn::LoadRuns { runs, .. } => runs,
                _ => &whole,
            };
            let (dst, pointer) = (*dst as usize, *pointer as usize);
            // Every member's pointer into the one workgroup's memory of the batch (a kernel
            // with barriers: the histogram's exchanges): a register's row at a time, without
            // each member's registers, region and memory looked up apart. Not where the
            // value's registers overlap the pointer's, which the rows would overwrite.
            if one_workgroup
                && (dst + *len as usize <= pointer || pointer + 2 <= dst)
                && members.all(|lane| file[pointer * width + lane] & TAG_MASK == WORKGROUP)
            {
                let workgroup = &shared[..workgroup_words];
                for &(start, words) in runs {
                    for i in start as usize..(start + words) as usize {
                        members.for_each(|lane| {
                            let offset = file[(pointer + 1) * width + lane] as usize;
                            file[(dst + i) * width + lane] = workgroup.get(offset + i).copied().unwrap_or(0);
                        });
                    }
                }
                return;
            }
            each_lane!(|regs, lane, private| {
                let (tag, offset) = (regs[pointer], regs[pointer + 1] as usize);
                // The common regions inline; the others (and the general rules) in `Memory`.
                match tag & TAG_MASK {
                    BUFFER => load_runs(&buffers[(tag & !TAG_MASK) as usize], offset / 4, runs, regs, dst),
                    WORKGROUP => {
                        let workgroup = workgroup!(lane);
                        for &(start, words) in runs {
                            for i in start as usize..(start + words) as usize {
                                regs[dst + i] = workgroup.get(offset + i).copied().unwrap_or(0);
                            }
                        }
                    }
                    // Private and function memory: the whole value (words nobody reads too).
                    _ => memory!(lane, private).load(regs, (tag, offset as u32), dst, *len as usize),
                }
            })
        }
        Insn::LoadElement(load) => load_element(load, &buffers[load.buffer as usize], file, members, width),
        Insn::Store { pointer, src, len } => {
            let (src, len) = (*src as usize, *len as usize);
            // As the loads above: into the one workgroup's memory, member after member
            // (the order the per-member path writes in) without each one's registers,
            // region and memory looked up apart.
            let p = *pointer as usize;
            if one_workgroup && members.all(|lane| file[p * width + lane] & TAG_MASK == WORKGROUP) {
                let workgroup = &mut shared[..workgroup_words];
                members.for_each(|lane| {
                    let offset = file[(p + 1) * width + lane] as usize;
                    for i in 0..len {
                        if let Some(word) = workgroup.get_mut(offset + i) {
                            *word = file[(src + i) * width + lane];
                        }
                    }
                });
                return;
            }
            each_lane!(|regs, lane, private| {
                let (tag, offset) = (regs[*pointer as usize], regs[*pointer as usize + 1] as usize);
                match tag & TAG_MASK {
                    BUFFER => {
                        let memory = &buffers[(tag & !TAG_MASK) as usize];
                        for i in 0..len {
                            if let Some(word) = memory.get(offset / 4 + i) {
                                word.store(regs[src + i], Ordering::Relaxed);
                            }
                        }
                    }
                    WORKGROUP => {
                        let workgroup = workgroup!(lane);
                        for i in 0..len {
                            if let Some(word) = workgroup.get_mut(offset + i) {
                                *word = regs[src + i];
                            }
                        }
                    }
                    _ => memory!(lane, private).store(regs, (tag, offset as u32), src, len),
                }
            })
        }
        Insn::LoadMixed { dst, pointer, plan } => each_lane!(|regs, lane, private| {
            let (tag, offset) = (regs[*pointer as usize], regs[*pointer as usize + 1]);
            // Only pointers into buffers get a plan.
            if tag & TAG_MASK == BUFFER {
                let buffer = &buffers[(tag & !TAG_MASK) as usize];
                read_mixed(buffer, offset as usize, regs, *dst as usize, plan);
            }
        }),
        Insn::StoreMixed { pointer, src, plan } => each_lane!(|regs, lane, private| {
            let (tag, offset) = (regs[*pointer as usize], regs[*pointer as usize + 1]);
            if tag & TAG_MASK == BUFFER {
                let buffer = &buffers[(tag & !TAG_MASK) as usize];
                write_mixed(buffer, offset as usize, regs, *src as usize, plan);
            }
        }),
        Insn::LoadWorkgroup { dst, address, len } => each_lane!(|regs, lane, private| {
            let (dst, address, len) = (*dst as usize, *address as usize, *len as usize);
            regs.write(dst, &workgroup!(lane)[address..address + len]);
        }),
        Insn::StoreWorkgroup { address, src, len } => each_lane!(|regs, lane, private| {
            let (src, address, len) = (*src as usize, *address as usize, *len as usize);
            let workgroup = workgroup!(lane);
            for i in 0..len {
                workgroup[address + i] = regs[src + i];
            }
        }),
        Insn::LoadPrivate { dst, address, len } => each_lane!(|regs, lane, private| {
            let (dst, address, len) = (*dst as usize, *address as usize, *len as usize);
            regs.write(dst, &private[address..address + len]);
        }),
        Insn::StorePrivate { address, src, len } => each_lane!(|regs, lane, private| {
            let (src, address, len) = (*src as usize, *address as usize, *len as usize);
            for i in 0..len {
                private[address + i] = regs[src + i];
            }
        }),
        // The same words for every member (the address is known when compiling): read once,
        // then each register's row filled. The members read at one instant, which is one
        // of the orders the kernel's own racing writes (if any) allow.
        Insn::LoadBuffer { dst, buffer, address, len } => {
            let memory = &buffers[*buffer as usize];
            for i in 0..*len as usize {
                let word = memory.get(*address as usize + i).map_or(0, |w| w.load(Ordering::Relaxed));
                members.fill(file, *dst as usize + i, 1, word);
            }
        }
        Insn::StoreBuffer { buffer, address, src, len } => each_lane!(|regs, lane, private| {
            let (src, len) = (*src as usize, *len as usize);
            write_buffer(&buffers[*buffer as usize], *address as usize, &regs.read(src, len));
        }),
        Insn::ArrayLength { dst, pointer, stride } => each_lane!(|regs, lane, private| {
            let (tag, offset) = (regs[*pointer as usize], regs[*pointer as usize + 1]);
            let memory = memory!(lane, private);
            let words = memory.words(regs, tag);
            regs[*dst as usize] = (words.saturating_sub(offset as usize) / (*stride).max(1) as usize) as u32;
        }),
        Insn::Atomic(atomic) => each_lane!(|regs, lane, private| {
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
            let mut memory = memory!(lane, private);
            let old = memory.atomic(regs, pointer, apply);
            if let Some(result) = atomic.result {
                regs[result as usize] = old;
                if let Some(expected) = expected {
                    regs[result as usize + 1] = u32::from(old == expected);
                }
            }
        }),
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
        | Insn::Un { .. }
        | Insn::PtrAdd { .. }
        | Insn::PtrIndex { .. }
        | Insn::Swizzle { .. }
        | Insn::Convert { .. }
        | Insn::Compute(_) => unreachable!("run for the whole group by `run_group`"),
        Insn::Jump(_)
        | Insn::JumpUnless { .. }
        | Insn::Switch { .. }
        | Insn::Call(_)
        | Insn::Return { .. }
        | Insn::Barrier { .. }
        | Insn::Checked(_)
        | Insn::Gather(_)
        | Insn::Collective(_)
        | Insn::Fail(_) => unreachable!("control flow is run by the group"),
    }
}

/// [`Insn::LoadElement`] for `members`, a register at a time rather than a member at a
/// time as the other loads. Why: a register's row holds one word of every lane, so a
/// member's value is a column, its words a row apart; and a BVH walk's members mostly
/// stand at the same node, so the whole group, or a chunk of it, mostly reads one
/// element. The path tracer's node and triangle loads took a third of its large groups'
/// time member by member (about 15 cycles a member for a 4-word element; 8 now).
///
/// A group that reads one element: each word read once and its rows filled (the row
/// operation keeps the other lanes). Otherwise members go in chunks of `CHUNK`, so that
/// their first words fit on the stack: a chunk reads each word once where its members
/// agree, else one word of each member per row. A chunk's indices are all read before
/// any of its words is written, and a member's words land only in its own column, so an
/// index register that the value overwrites is read as it was. Words past the buffer's
/// end read as 0, as through the pointer.
fn load_element(load: &ElementLoad, memory: &[AtomicU32], file: &mut [u32], members: Members, width: usize) {
    const CHUNK: usize = 64;
    let whole = [(0, load.len)];
    let runs: &[(u32, u32)] = load.runs.as_deref().unwrap_or(&whole);
    let (dst, index, bytes) = (load.dst as usize, load.index as usize, memory.len() * 4);
    let word = |first: usize, i: usize| memory.get(first + i).map_or(0, |w| w.load(Ordering::Relaxed));
    let registers = || runs.iter().flat_map(|&(start, words)| start as usize..(start + words) as usize);
    // Whether every member reads the same element (then one read fills the rows), found
    // out no further than the first member that does not.
    let clamp = load.clamp(bytes);
    let mut leader = None;
    let same = members.all(|lane| {
        let first = clamp.first_word(file[index * width + lane]);
        *leader.get_or_insert(first) == first
    });
    if let (true, Some(first)) = (same, leader) {
        for i in registers() {
            members.fill(file, dst + i, 1, word(first, i));
        }
        return;
    }
    let write_rows = |file: &mut [u32], lanes: &[usize], firsts: &[usize]| {
        let Some(&leader) = firsts.first() else { return };
        let same = firsts.iter().all(|&first| first == leader);
        for i in registers() {
            let row = &mut file[(dst + i) * width..][..width];
            if same {
                let value = word(leader, i);
                lanes.iter().for_each(|&lane| row[lane] = value);
            } else {
                lanes.iter().zip(firsts).for_each(|(&lane, &first)| row[lane] = word(first, i));
            }
        }
    };
    let (mut lanes, mut firsts, mut n) = ([0usize; CHUNK], [0usize; CHUNK], 0);
    members.for_each(|lane| {
        lanes[n] = lane;
        firsts[n] = clamp.first_word(file[index * width + lane]);
        n += 1;
        if n == CHUNK {
            write_rows(file, &lanes, &firsts);
            n = 0;
        }
    });
    write_rows(file, &lanes[..n], &firsts[..n]);
}

/// Loads the `runs` (first word, words) of the value at word `first` of buffer `memory`
/// into registers `dst + first word ..` of `regs`; words past the buffer's end read as 0.
#[inline(always)]
fn load_runs(memory: &[AtomicU32], first: usize, runs: &[(u32, u32)], regs: &mut LaneRegs, dst: usize) {
    for &(start, words) in runs {
        let (start, words) = (start as usize, words as usize);
        let first = first + start;
        match memory.get(first..first + words) {
            // Inside the buffer (the common case): one bounds check.
            Some(run) => regs.write_each(dst + start, run.iter().map(|w| w.load(Ordering::Relaxed))),
            None => {
                for i in 0..words {
                    regs[dst + start + i] = memory.get(first + i).map_or(0, |w| w.load(Ordering::Relaxed));
                }
            }
        }
    }
}
