//! The interpreter's memory model. A pointer is two words: a region tag (and the
//! region's index) in the first, an offset in the second: bytes into a bound buffer
//! (naga's layout, where an f16 takes two bytes), register words elsewhere. Regions: a bound buffer
//! (shared between the workgroups running on other threads, so its words are atomics,
//! read and written relaxed), the workgroup's memory, the invocation's private memory,
//! and a frame's register file (function-space variables live among a frame's
//! registers; the tag carries the frame's depth in the invocation's call stack).
//!
//! Out-of-bounds words read as 0 and are not written.

use super::lanes::{LaneRegs, Words};
use super::layout::{Piece, Reg};
use smallvec::smallvec;
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

/// A suspended or running call of a compiled function. Its registers are the column of
/// its invocation in its code's lane-minor file ([`super::lanes`]): WGSL has no
/// recursion, so an invocation has at most one frame of each code.
pub(super) struct Frame {
    /// Index of the function's code in the program.
    pub code: u32,
    /// Next instruction (or, while stopped at a barrier, the barrier).
    pub pc: u32,
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
    /// Every code's lane-minor register file (the running code's taken out).
    pub files: &'a mut [Vec<u32>],
    /// The codes of the invocation's callers, outermost first (a pointer's frame depth
    /// indexes it).
    pub callers: &'a [u32],
    /// The invocation's lane in the files.
    pub lane: usize,
    /// Lanes per file.
    pub width: usize,
}

/// Reads `len` words of `memory` from `start` into registers `dst..`; missing words read
/// as 0.
#[inline(always)]
fn read_plain(memory: &[u32], start: usize, regs: &mut LaneRegs, dst: usize, len: usize) {
    match memory.get(start..start + len) {
        Some(words) => regs.write(dst, words),
        None => {
            for i in 0..len {
                regs[dst + i] = memory.get(start + i).copied().unwrap_or(0);
            }
        }
    }
}

/// Writes registers `src..src + len` into `memory` at `start`; missing words are skipped.
#[inline(always)]
fn write_plain(memory: &mut [u32], start: usize, regs: &LaneRegs, src: usize, len: usize) {
    for i in 0..len {
        if let Some(slot) = memory.get_mut(start + i) {
            *slot = regs[src + i];
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
    /// The register file of the caller at `depth`.
    fn caller(&mut self, depth: usize) -> LaneRegs<'_> {
        LaneRegs::new(&mut self.files[self.callers[depth] as usize], self.lane, self.width)
    }

    /// Reads `len` words at pointer `(tag, offset)` into `regs[dst..]`.
    pub(super) fn load(&mut self, regs: &mut LaneRegs, (tag, offset): (u32, u32), dst: usize, len: usize) {
        let start = offset as usize;
        match tag & TAG_MASK {
            BUFFER => {
                let memory = &self.buffers[(tag & !TAG_MASK) as usize];
                for i in 0..len {
                    regs[dst + i] = memory.get(start / 4 + i).map_or(0, |w| w.load(Ordering::Relaxed));
                }
            }
            WORKGROUP => read_plain(self.workgroup, start, regs, dst, len),
            PRIVATE => read_plain(self.private, start, regs, dst, len),
            _ => {
                let depth = (tag & !TAG_MASK) as usize;
                if depth >= self.callers.len() {
                    // The running frame: a register-to-register copy.
                    if start + len <= regs.len() {
                        regs.copy(dst, start, len);
                    } else {
                        let mut value: Words = smallvec![0; len];
                        read_regs(regs, start, &mut value);
                        regs.write(dst, &value);
                    }
                } else {
                    let caller = self.caller(depth);
                    let words = caller.len();
                    for i in 0..len {
                        regs[dst + i] = if start + i < words { caller[start + i] } else { 0 };
                    }
                }
            }
        }
    }

    /// Writes `regs[src..src + len]` at pointer `(tag, offset)`.
    pub(super) fn store(&mut self, regs: &mut LaneRegs, (tag, offset): (u32, u32), src: usize, len: usize) {
        let start = offset as usize;
        match tag & TAG_MASK {
            BUFFER => {
                let memory = &self.buffers[(tag & !TAG_MASK) as usize];
                for i in 0..len {
                    if let Some(word) = memory.get(start / 4 + i) {
                        word.store(regs[src + i], Ordering::Relaxed);
                    }
                }
            }
            WORKGROUP => write_plain(self.workgroup, start, regs, src, len),
            PRIVATE => write_plain(self.private, start, regs, src, len),
            _ => {
                let depth = (tag & !TAG_MASK) as usize;
                if depth >= self.callers.len() {
                    if start + len <= regs.len() {
                        regs.copy(start, src, len);
                    } else {
                        let value = regs.read(src, len);
                        write_regs(regs, start, &value);
                    }
                } else {
                    let value = regs.read(src, len);
                    write_regs(&mut self.caller(depth), start, &value);
                }
            }
        }
    }

    /// Size of the region of pointer tag `tag` in the pointer's units: bytes for a
    /// buffer, words elsewhere (`regs`: the running frame's registers).
    pub(super) fn words(&self, regs: &LaneRegs, tag: u32) -> usize {
        match tag & TAG_MASK {
            BUFFER => self.buffers[(tag & !TAG_MASK) as usize].len() * 4,
            WORKGROUP => self.workgroup.len(),
            PRIVATE => self.private.len(),
            _ => {
                let depth = (tag & !TAG_MASK) as usize;
                if depth >= self.callers.len() {
                    regs.len()
                } else {
                    self.files[self.callers[depth] as usize].len() / self.width
                }
            }
        }
    }

    /// Applies `apply` to the word at `(tag, offset)` and returns the old word; a real
    /// atomic in buffers, a plain read and write elsewhere (one thread runs a workgroup).
    pub(super) fn atomic(&mut self, regs: &mut LaneRegs, (tag, offset): (u32, u32), apply: impl Fn(u32) -> u32) -> u32 {
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
                WORKGROUP => old[0] = self.workgroup.get(start).copied().unwrap_or(0),
                PRIVATE => old[0] = self.private.get(start).copied().unwrap_or(0),
                _ => {
                    let depth = (tag & !TAG_MASK) as usize;
                    if depth >= self.callers.len() {
                        read_regs(regs, start, &mut old);
                    } else {
                        read_regs(&self.caller(depth), start, &mut old);
                    }
                }
            }
            let new = [apply(old[0])];
            match tag & TAG_MASK {
                WORKGROUP => {
                    if let Some(slot) = self.workgroup.get_mut(start) {
                        *slot = new[0];
                    }
                }
                PRIVATE => {
                    if let Some(slot) = self.private.get_mut(start) {
                        *slot = new[0];
                    }
                }
                _ => {
                    let depth = (tag & !TAG_MASK) as usize;
                    if depth >= self.callers.len() {
                        write_regs(regs, start, &new);
                    } else {
                        write_regs(&mut self.caller(depth), start, &new);
                    }
                }
            }
            old[0]
        }
    }
}

/// Reads registers `start..` of a frame into `out`; registers past the file read as 0.
#[inline(always)]
fn read_regs(regs: &LaneRegs, start: usize, out: &mut [u32]) {
    let len = regs.len();
    for (i, word) in out.iter_mut().enumerate() {
        *word = if start + i < len { regs[start + i] } else { 0 };
    }
}

/// Writes `value` into registers `start..` of a frame; registers past the file are skipped.
#[inline(always)]
fn write_regs(regs: &mut LaneRegs, start: usize, value: &[u32]) {
    let len = regs.len();
    for (i, &word) in value.iter().enumerate() {
        if start + i < len {
            regs[start + i] = word;
        }
    }
}

/// Reads a value holding f16 from buffer `memory` at byte `start` into `regs[dst..]`,
/// piece by piece (binary16 → the f32 of equal value); missing words read as 0.
pub(super) fn read_mixed(memory: &[AtomicU32], start: usize, regs: &mut LaneRegs, dst: usize, plan: &[Piece]) {
    for piece in plan {
        match *piece {
            Piece::Words { memory: at, reg, len } => {
                let mut value: Words = smallvec![0; len as usize];
                read_buffer(memory, (start + at as usize) / 4, &mut value);
                regs.write(dst + reg as usize, &value);
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
pub(super) fn write_mixed(memory: &[AtomicU32], start: usize, regs: &LaneRegs, src: usize, plan: &[Piece]) {
    for piece in plan {
        match *piece {
            Piece::Words { memory: at, reg, len } => {
                write_buffer(memory, (start + at as usize) / 4, &regs.read(src + reg as usize, len as usize));
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
