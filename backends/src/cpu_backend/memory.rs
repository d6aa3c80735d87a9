//! The interpreter's memory model. A pointer is two words: a region tag (and the
//! region's index) in the first, an offset in the second: bytes into a bound buffer
//! (naga's layout, where an f16 takes two bytes), register words elsewhere. Regions: a bound buffer
//! (shared between the workgroups running on other threads, so its words are atomics,
//! read and written relaxed), the workgroup's memory, the invocation's private memory,
//! and a frame's register file (function-space variables live among a frame's
//! registers; the tag carries the frame's depth in the invocation's call stack).
//!
//! Out-of-bounds words read as 0 and are not written.

use super::insn::Reg;
use super::layout::Piece;
use std::sync::atomic::{AtomicU32, Ordering};

/// Tag of a pointer into a bound buffer (the low 24 bits: its binding slot).
pub(super) const BUFFER: u32 = 1 << 24;
/// Tag of a pointer into workgroup memory.
pub(super) const WORKGROUP: u32 = 2 << 24;
/// Tag of a pointer into private memory.
pub(super) const PRIVATE: u32 = 3 << 24;
/// Tag of a pointer into a frame's registers (the low 24 bits: the frame's depth).
pub(super) const FUNCTION: u32 = 4 << 24;
/// The tag bits of a pointer's first word.
pub(super) const TAG_MASK: u32 = 0xff << 24;

/// A suspended or running call of a compiled function.
pub(super) struct Frame {
    /// Index of the function's code in the program.
    pub code: u32,
    /// Next instruction (or, while stopped at a barrier, the barrier).
    pub pc: u32,
    /// Register file: expression values and local variables.
    pub regs: Vec<u32>,
    /// Caller register and words receiving the return value.
    pub result: Option<(Reg, u32)>,
}

/// Memory other than the running frame's registers, as one invocation sees it.
pub(super) struct Memory<'a> {
    /// Bound buffers in the kernel's binding order.
    pub buffers: &'a [Vec<AtomicU32>],
    /// The workgroup's memory.
    pub workgroup: &'a mut [u32],
    /// The invocation's private memory.
    pub private: &'a mut [u32],
    /// The frames of the invocation's callers, outermost first.
    pub callers: &'a mut [Frame],
}

/// Copies `len` words `src..` to `dst..` of `regs` (the ranges may overlap).
#[inline(always)]
pub(super) fn copy_regs(regs: &mut [u32], dst: usize, src: usize, len: usize) {
    match len {
        1 => regs[dst] = regs[src],
        2 => {
            let v: [u32; 2] = regs[src..src + 2].try_into().expect("two words");
            regs[dst..dst + 2].copy_from_slice(&v);
        }
        3 => {
            let v: [u32; 3] = regs[src..src + 3].try_into().expect("three words");
            regs[dst..dst + 3].copy_from_slice(&v);
        }
        4 => {
            let v: [u32; 4] = regs[src..src + 4].try_into().expect("four words");
            regs[dst..dst + 4].copy_from_slice(&v);
        }
        // Overlapping ranges (none are compiled today) keep `copy_within`'s semantics.
        _ if dst.abs_diff(src) < len => regs.copy_within(src..src + len, dst),
        _ => {
            let (to, from) = if dst > src {
                let (low, high) = regs.split_at_mut(dst);
                (&mut high[..len], &low[src..src + len])
            } else {
                let (low, high) = regs.split_at_mut(src);
                (&mut low[dst..dst + len], &high[..len])
            };
            copy_words(to, from);
        }
    }
}

/// Copies `from` into `to` (the same length) four words at a time. Values here are a few
/// words long, where a call of the C library's `memmove` costs more than the copy (it
/// was 15 % of the histogram kernel's time).
#[inline(always)]
pub(super) fn copy_words(to: &mut [u32], from: &[u32]) {
    let mut to = to.chunks_exact_mut(4);
    let mut from = from.chunks_exact(4);
    for (to, from) in (&mut to).zip(&mut from) {
        let value: [u32; 4] = from.try_into().expect("four words");
        to.copy_from_slice(&value);
    }
    for (to, from) in to.into_remainder().iter_mut().zip(from.remainder()) {
        *to = *from;
    }
}

/// Zeroes `words` four at a time (see [`copy_words`]).
#[inline(always)]
pub(super) fn zero_words(words: &mut [u32]) {
    let mut chunks = words.chunks_exact_mut(4);
    for chunk in &mut chunks {
        chunk.copy_from_slice(&[0; 4]);
    }
    for word in chunks.into_remainder() {
        *word = 0;
    }
}

/// Reads `len` words of `memory` from `start` into `out`; missing words read as 0.
#[inline(always)]
fn read_plain(memory: &[u32], start: usize, out: &mut [u32]) {
    match memory.get(start..start + out.len()) {
        Some(words) => copy_words(out, words),
        None => {
            for (i, word) in out.iter_mut().enumerate() {
                *word = memory.get(start + i).copied().unwrap_or(0);
            }
        }
    }
}

/// Writes `value` into `memory` at `start`; missing words are skipped.
#[inline(always)]
fn write_plain(memory: &mut [u32], start: usize, value: &[u32]) {
    let len = value.len();
    match memory.get_mut(start..start + len) {
        Some(words) => words.copy_from_slice(value),
        None => {
            for (i, &word) in value.iter().enumerate() {
                if let Some(slot) = memory.get_mut(start + i) {
                    *slot = word;
                }
            }
        }
    }
}

/// Reads `len` words of buffer memory into `out`; missing words read as 0.
#[inline(always)]
pub(super) fn read_buffer(memory: &[AtomicU32], start: usize, out: &mut [u32]) {
    for (i, word) in out.iter_mut().enumerate() {
        *word = memory.get(start + i).map_or(0, |w| w.load(Ordering::Relaxed));
    }
}

/// Writes words into buffer memory; missing words are skipped.
#[inline(always)]
pub(super) fn write_buffer(memory: &[AtomicU32], start: usize, value: &[u32]) {
    for (i, &word) in value.iter().enumerate() {
        if let Some(slot) = memory.get(start + i) {
            slot.store(word, Ordering::Relaxed);
        }
    }
}

impl Memory<'_> {
    /// Reads `len` words at pointer `(tag, offset)` into `regs[dst..]`.
    pub(super) fn load(&mut self, regs: &mut [u32], (tag, offset): (u32, u32), dst: usize, len: usize) {
        let start = offset as usize;
        match tag & TAG_MASK {
            BUFFER => read_buffer(&self.buffers[(tag & !TAG_MASK) as usize], start / 4, &mut regs[dst..dst + len]),
            WORKGROUP => read_plain(self.workgroup, start, &mut regs[dst..dst + len]),
            PRIVATE => read_plain(self.private, start, &mut regs[dst..dst + len]),
            _ => {
                let depth = (tag & !TAG_MASK) as usize;
                if depth >= self.callers.len() {
                    // The running frame: a register-to-register copy.
                    if start + len <= regs.len() {
                        copy_regs(regs, dst, start, len);
                    } else {
                        for i in 0..len {
                            regs[dst + i] = regs.get(start + i).copied().unwrap_or(0);
                        }
                    }
                } else {
                    read_plain(&self.callers[depth].regs, start, &mut regs[dst..dst + len]);
                }
            }
        }
    }

    /// Writes `regs[src..src + len]` at pointer `(tag, offset)`.
    pub(super) fn store(&mut self, regs: &mut [u32], (tag, offset): (u32, u32), src: usize, len: usize) {
        let start = offset as usize;
        match tag & TAG_MASK {
            BUFFER => write_buffer(&self.buffers[(tag & !TAG_MASK) as usize], start / 4, &regs[src..src + len]),
            WORKGROUP => write_plain(self.workgroup, start, &regs[src..src + len]),
            PRIVATE => write_plain(self.private, start, &regs[src..src + len]),
            _ => {
                let depth = (tag & !TAG_MASK) as usize;
                if depth >= self.callers.len() {
                    if start + len <= regs.len() {
                        copy_regs(regs, start, src, len);
                    } else {
                        for i in 0..len {
                            if start + i < regs.len() {
                                regs[start + i] = regs[src + i];
                            }
                        }
                    }
                } else {
                    write_plain(&mut self.callers[depth].regs, start, &regs[src..src + len]);
                }
            }
        }
    }

    /// Size of the region of pointer tag `tag` in the pointer's units: bytes for a
    /// buffer, words elsewhere (`regs`: the running frame's registers).
    pub(super) fn words(&self, regs: &[u32], tag: u32) -> usize {
        match tag & TAG_MASK {
            BUFFER => self.buffers[(tag & !TAG_MASK) as usize].len() * 4,
            WORKGROUP => self.workgroup.len(),
            PRIVATE => self.private.len(),
            _ => {
                let depth = (tag & !TAG_MASK) as usize;
                if depth >= self.callers.len() { regs.len() } else { self.callers[depth].regs.len() }
            }
        }
    }

    /// Applies `apply` to the word at `(tag, offset)` and returns the old word; a real
    /// atomic in buffers, a plain read and write elsewhere (one thread runs a workgroup).
    pub(super) fn atomic(&mut self, regs: &mut [u32], (tag, offset): (u32, u32), apply: impl Fn(u32) -> u32) -> u32 {
        if tag & TAG_MASK == BUFFER {
            match self.buffers[(tag & !TAG_MASK) as usize].get(offset as usize / 4) {
                Some(word) => {
                    word.fetch_update(Ordering::Relaxed, Ordering::Relaxed, |old| Some(apply(old))).unwrap_or(0)
                }
                None => 0,
            }
        } else {
            let mut old = [0u32];
            let start = offset as usize;
            match tag & TAG_MASK {
                WORKGROUP => read_plain(self.workgroup, start, &mut old),
                PRIVATE => read_plain(self.private, start, &mut old),
                _ => {
                    let depth = (tag & !TAG_MASK) as usize;
                    if depth >= self.callers.len() {
                        read_plain(regs, start, &mut old);
                    } else {
                        read_plain(&self.callers[depth].regs, start, &mut old);
                    }
                }
            }
            let new = [apply(old[0])];
            match tag & TAG_MASK {
                WORKGROUP => write_plain(self.workgroup, start, &new),
                PRIVATE => write_plain(self.private, start, &new),
                _ => {
                    let depth = (tag & !TAG_MASK) as usize;
                    if depth >= self.callers.len() {
                        write_plain(regs, start, &new);
                    } else {
                        write_plain(&mut self.callers[depth].regs, start, &new);
                    }
                }
            }
            old[0]
        }
    }
}

/// Reads a value holding f16 from buffer `memory` at byte `start` into `regs[dst..]`,
/// piece by piece (binary16 → the f32 of equal value); missing words read as 0.
pub(super) fn read_mixed(memory: &[AtomicU32], start: usize, regs: &mut [u32], dst: usize, plan: &[Piece]) {
    for piece in plan {
        match *piece {
            Piece::Words { memory: at, reg, len } => {
                let reg = dst + reg as usize;
                read_buffer(memory, (start + at as usize) / 4, &mut regs[reg..reg + len as usize]);
            }
            Piece::Half { memory: at, reg } => {
                let byte = start + at as usize;
                let word = memory.get(byte / 4).map_or(0, |w| w.load(Ordering::Relaxed));
                regs[dst + reg as usize] = super::arith::f16_to_f32((word >> (8 * (byte & 2))) & 0xffff);
            }
        }
    }
}

/// Writes a value holding f16 from `regs[src..]` into buffer `memory` at byte `start`;
/// a binary16 replaces its half of a word atomically (the other half may belong to
/// another invocation); missing words are skipped.
pub(super) fn write_mixed(memory: &[AtomicU32], start: usize, regs: &[u32], src: usize, plan: &[Piece]) {
    for piece in plan {
        match *piece {
            Piece::Words { memory: at, reg, len } => {
                let reg = src + reg as usize;
                write_buffer(memory, (start + at as usize) / 4, &regs[reg..reg + len as usize]);
            }
            Piece::Half { memory: at, reg } => {
                let byte = start + at as usize;
                let shift = 8 * (byte & 2);
                let half = super::arith::f32_to_f16(regs[src + reg as usize]) << shift;
                if let Some(word) = memory.get(byte / 4) {
                    let mask = 0xffff << shift;
                    let _ = word.fetch_update(Ordering::Relaxed, Ordering::Relaxed, |old| Some((old & !mask) | half));
                }
            }
        }
    }
}
