//! The lane-minor register file: one code's registers for every invocation of a
//! workgroup, register `r` of invocation `l` at word `r * width + l` (`width`: the
//! workgroup's invocations). An instruction run for a whole group then reads and writes
//! whole rows of contiguous words, a loop the compiler vectorises, where a file per
//! invocation put the same register of two invocations tens of kilobytes apart
//! (BENCHMARKS.md, "interpreter": that layout cost about 5 ns per invocation and
//! instruction). [`LaneRegs`] is one invocation's view of such a file, for the
//! instructions run member by member (memory through pointers, atomics, rare math).

use multiversion::multiversion;
use smallvec::SmallVec;
use std::ops::{Index, IndexMut};

/// A few words of one invocation's registers, copied out.
pub(super) type Words = SmallVec<[u32; 16]>;

/// One invocation's registers in a lane-minor file: `regs[r]` is its register `r`.
pub(super) struct LaneRegs<'a> {
    words: &'a mut [u32],
    lane: usize,
    width: usize,
}

impl<'a> LaneRegs<'a> {
    /// Invocation `lane`'s registers in `words`, a file of `width` lanes.
    #[inline(always)]
    pub(super) fn new(words: &'a mut [u32], lane: usize, width: usize) -> Self {
        debug_assert!(lane < width && words.len().is_multiple_of(width));
        Self { words, lane, width }
    }

    /// How many registers the file holds.
    #[inline(always)]
    pub(super) fn len(&self) -> usize {
        self.words.len() / self.width
    }

    /// Registers `reg..reg + len`, copied out (through an array: collecting into the
    /// small vector word by word cost more than the instructions that read them).
    #[inline(always)]
    pub(super) fn read(&self, reg: usize, len: usize) -> Words {
        const INLINE: usize = 16;
        if len > INLINE {
            return (reg..reg + len).map(|r| self[r]).collect();
        }
        let mut words = [0u32; INLINE];
        for (word, &value) in words.iter_mut().zip(self.column(reg, len)) {
            *word = value;
        }
        Words::from_buf_and_len(words, len)
    }

    /// Writes `value` into registers `reg..`.
    #[inline(always)]
    pub(super) fn write(&mut self, reg: usize, value: &[u32]) {
        self.write_each(reg, value.iter().copied());
    }

    /// Writes the words `values` yields into registers `reg..` (one bounds check for the
    /// whole column, not one per word).
    #[inline(always)]
    pub(super) fn write_each(&mut self, reg: usize, values: impl ExactSizeIterator<Item = u32>) {
        let start = self.column_start(reg, values.len());
        let column = self.words[start..].iter_mut().step_by(self.width);
        for (slot, value) in column.zip(values) {
            *slot = value;
        }
    }

    /// Registers `reg..reg + len`, in order.
    #[inline(always)]
    fn column(&self, reg: usize, len: usize) -> impl Iterator<Item = &u32> {
        self.words[self.column_start(reg, len)..].iter().step_by(self.width).take(len)
    }

    /// Where registers `reg..reg + len` start in the file, checked to lie in it.
    #[inline(always)]
    fn column_start(&self, reg: usize, len: usize) -> usize {
        assert!(len == 0 || (reg + len - 1) * self.width + self.lane < self.words.len(), "registers in the file");
        (reg * self.width + self.lane).min(self.words.len())
    }

    /// Copies registers `src..src + len` to `dst..` (the ranges may overlap: the copy
    /// reads each word before it is overwritten, as `copy_within` does).
    #[inline(always)]
    pub(super) fn copy(&mut self, dst: usize, src: usize, len: usize) {
        if dst <= src {
            for i in 0..len {
                self[dst + i] = self[src + i];
            }
        } else {
            for i in (0..len).rev() {
                self[dst + i] = self[src + i];
            }
        }
    }
}

impl Index<usize> for LaneRegs<'_> {
    type Output = u32;

    #[inline(always)]
    fn index(&self, reg: usize) -> &u32 {
        &self.words[reg * self.width + self.lane]
    }
}

impl IndexMut<usize> for LaneRegs<'_> {
    #[inline(always)]
    fn index_mut(&mut self, reg: usize) -> &mut u32 {
        &mut self.words[reg * self.width + self.lane]
    }
}

/// Lanes a row operation handles per step: its operands are copied into arrays of this
/// many words, so that the loop over them has no aliasing for the compiler to fear and,
/// for a full chunk, a length it knows (the common workgroups of 64 are one chunk).
pub(super) const N: usize = 64;

/// Runs `$body` for the chunks of a row of `$width` lanes, with `$start` the chunk's first
/// lane and `$n` its length: full chunks first (`$n` is then the constant `N`, and the
/// body is compiled for it), then the rest. A macro rather than a function taking a
/// closure: such closures were not always inlined, and then every chunk's copy became a
/// call of the C library's `memcpy` with a variable length.
macro_rules! chunks {
    ($width:expr, |$start:ident, $n:ident| $body:block) => {{
        let width: usize = $width;
        let mut $start = 0;
        while $start + N <= width {
            let $n = N;
            $body
            $start += N;
        }
        if $start < width {
            let $n = width - $start;
            $body
        }
    }};
}

/// `row[i] = words[i]` where `mask[i]` is all ones, unchanged where it is 0.
#[inline(always)]
fn keep_members(row: &mut [u32], words: &[u32; N], mask: &[u32; N]) {
    for (i, word) in row.iter_mut().enumerate() {
        *word = (words[i] & mask[i]) | (*word & !mask[i]);
    }
}

/// Calls `f(first lane, mask of the chunk)` for each chunk of [`N`] lanes of `mask` with
/// a member (bit `c` of `chunks` set for chunk `c`).
#[inline(always)]
fn each_chunk(mask: &[u32], mut chunks: u64, mut f: impl FnMut(usize, &[u32; N])) {
    while chunks != 0 {
        let c = chunks.trailing_zeros() as usize * N;
        chunks &= chunks - 1;
        f(c, mask[c..c + N].try_into().expect("chunks of N lanes"));
    }
}

/// Bit `i` set where `words[i]` is 0 and `mask[i]` all ones (`mask`: all ones or 0 per
/// lane). Eight lanes a byte, each lane's test without a branch (`w | !m == 0`), a shape
/// the compiler turns into vector compares and mask moves; a test per lane with `&&`
/// was a branch per lane and most of the time of a divergent jump.
#[inline(always)]
fn zero_bits(words: &[u32; N], mask: &[u32; N]) -> u64 {
    let mut bits = 0u64;
    for (k, (words, mask)) in words.chunks_exact(8).zip(mask.chunks_exact(8)).enumerate() {
        let mut byte = 0u8;
        for i in 0..8 {
            byte |= u8::from(words[i] | !mask[i] == 0) << i;
        }
        bits |= u64::from(byte) << (8 * k);
    }
    bits
}

/// Words `at..at + n` of `regs` (`n <= M`) copied into an array.
#[inline(always)]
fn row<const M: usize>(regs: &[u32], at: usize, n: usize) -> [u32; M] {
    let mut words = [0u32; M];
    words[..n].copy_from_slice(&regs[at..at + n]);
    words
}

/// The invocations of a running group: every lane of the file (`All`, the common case,
/// rows are contiguous) or some, listed by lane in increasing order or as a set.
#[derive(Clone, Copy)]
pub(super) enum Members<'a> {
    /// Every lane `0..width`.
    All(usize),
    /// These lanes of a file `width` lanes wide.
    Some(&'a [usize], usize),
    /// The lanes of a set (bit `l % 64` of word `l / 64` for lane `l`) of a file whose
    /// width is a multiple of [`N`], many of them: the row operations compute whole
    /// chunks of [`N`] lanes and keep the members' words (`mask`: per lane of a chunk
    /// with a member, all ones for a member, else 0; the other chunks' words are never
    /// read and may be stale), loops the compiler vectorises where a member at a time
    /// could not be (a divergent kernel's groups have tens of members); chunks without a
    /// member (bit `c` of the `u64` clear) are skipped. A set rather than a list: most
    /// such groups run only row operations before they split again, and listing hundreds
    /// of members for each was a twentieth of the path tracer's time.
    Masked(&'a [u64], &'a [u32], u64),
}

impl Members<'_> {
    /// How many invocations the group has.
    #[inline(always)]
    pub(super) fn len(self) -> usize {
        match self {
            Members::All(width) => width,
            Members::Some(lanes, _) => lanes.len(),
            Members::Masked(set, ..) => set.iter().map(|bits| bits.count_ones() as usize).sum(),
        }
    }

    /// Lanes per row of the file the members run in.
    #[inline(always)]
    pub(super) fn width(self) -> usize {
        match self {
            Members::All(width) | Members::Some(_, width) => width,
            Members::Masked(_, mask, _) => mask.len(),
        }
    }

    /// Calls `f` with each member's lane, in increasing order.
    #[inline(always)]
    pub(super) fn for_each(self, mut f: impl FnMut(usize)) {
        match self {
            Members::All(width) => (0..width).for_each(f),
            Members::Some(lanes, _) => {
                for &l in lanes {
                    f(l)
                }
            }
            Members::Masked(set, _, mut chunks) => {
                while chunks != 0 {
                    let c = chunks.trailing_zeros() as usize;
                    chunks &= chunks - 1;
                    let mut bits = set[c];
                    while bits != 0 {
                        f(c * N + bits.trailing_zeros() as usize);
                        bits &= bits - 1;
                    }
                }
            }
        }
    }

    /// Sets bit `l % 64` of word `l / 64` of `taken` for each member `l` whose word of
    /// `row` (a register's row, `width` words) is 0, and clears every other bit; returns
    /// how many members that is. What a conditional jump asks (which members jump), as a
    /// set the scheduler merges a word at a time ([`super::places`]).
    #[inline(always)]
    pub(super) fn zeros(self, row: &[u32], taken: &mut Vec<u64>) -> usize {
        const { assert!(N == 64, "a chunk is a word of the set") };
        let width = self.width();
        taken.clear();
        taken.resize(width.div_ceil(N), 0);
        match self {
            Members::All(_) => {
                for (slot, words) in taken.iter_mut().zip(row[..width].chunks(N)) {
                    *slot = match words.try_into() {
                        Ok(words) => zero_bits(words, &[u32::MAX; N]),
                        // The last chunk of a batch whose width is not a multiple of 64.
                        Err(_) => words.iter().enumerate().fold(0, |bits, (i, &w)| bits | u64::from(w == 0) << i),
                    };
                }
            }
            Members::Masked(_, mask, chunks) => each_chunk(mask, chunks, |c, mask| {
                taken[c / N] = zero_bits(row[c..c + N].try_into().expect("a chunk of N lanes"), mask)
            }),
            Members::Some(lanes, _) => {
                for &l in lanes {
                    taken[l / N] |= u64::from(row[l] == 0) << (l % N);
                }
            }
        }
        taken.iter().map(|bits| bits.count_ones() as usize).sum()
    }

    /// Whether `f` holds for every member, asked in increasing order of lanes and no
    /// further than the first member for which it does not. Its walk over a masked
    /// group's set repeats `for_each`'s on purpose: `for_each` written as `all` with a
    /// test that always holds made the path tracer's frame 3-6 % slower (measured
    /// alternated, 2026-12-01).
    #[inline(always)]
    pub(super) fn all(self, mut f: impl FnMut(usize) -> bool) -> bool {
        match self {
            Members::All(width) => (0..width).all(f),
            Members::Some(lanes, _) => lanes.iter().all(|&l| f(l)),
            Members::Masked(set, _, mut chunks) => {
                while chunks != 0 {
                    let c = chunks.trailing_zeros() as usize;
                    chunks &= chunks - 1;
                    let mut bits = set[c];
                    while bits != 0 {
                        if !f(c * N + bits.trailing_zeros() as usize) {
                            return false;
                        }
                        bits &= bits - 1;
                    }
                }
                true
            }
        }
    }

    /// `regs[dst + r row] = f(regs[a + r row], regs[b + r row])` for the members and
    /// `r < rows`, in that order (rows are register indices; each is `width` words). The
    /// rows of a vector are contiguous, so a whole group's vector operation is one loop.
    #[inline(always)]
    pub(super) fn binary(
        self,
        regs: &mut [u32],
        (dst, a, b): (usize, usize, usize),
        rows: usize,
        f: impl Fn(u32, u32) -> u32,
    ) {
        binary_rows(self, regs, (dst, a, b), rows, f)
    }

    /// `regs[dst + r row] = f(regs[src + r row])` for the members and `r < rows`.
    #[inline(always)]
    pub(super) fn unary(self, regs: &mut [u32], dst: usize, src: usize, rows: usize, f: impl Fn(u32) -> u32) {
        unary_rows(self, regs, dst, src, rows, f)
    }

    /// `regs[dst + r row] = regs[cond + r row] != 0 ? regs[accept + r row] : regs[reject
    /// + r row]` for the members and `r < rows`.
    #[inline(always)]
    pub(super) fn select(
        self,
        regs: &mut [u32],
        (dst, cond, accept, reject): (usize, usize, usize, usize),
        rows: usize,
    ) {
        select_rows(self, regs, (dst, cond, accept, reject), rows)
    }

    /// `regs[dst row] = f(regs[a row], regs[b row], regs[c row])` for the members, an
    /// absent operand row reading as 0.
    #[inline(always)]
    pub(super) fn ternary(
        self,
        regs: &mut [u32],
        dst: usize,
        a: usize,
        b: Option<usize>,
        c: Option<usize>,
        f: impl Fn(u32, u32, u32) -> u32,
    ) {
        let width = self.width();
        let value = |regs: &[u32], row: Option<usize>, l: usize| row.map_or(0, |r| regs[r * width + l]);
        self.for_each(|l| {
            let v = f(regs[a * width + l], value(regs, b, l), value(regs, c, l));
            regs[dst * width + l] = v;
        });
    }

    /// Copies `len` rows from `src` to `dst` (the ranges may overlap).
    #[inline(always)]
    pub(super) fn copy(self, regs: &mut [u32], dst: usize, src: usize, len: usize) {
        copy_rows(self, regs, dst, src, len)
    }

    /// Sets `len` rows from `dst` to `value`.
    #[inline(always)]
    pub(super) fn fill(self, regs: &mut [u32], dst: usize, len: usize, value: u32) {
        fill_rows(self, regs, dst, len, value)
    }
}

/// [`Members::binary`]. This and the four row loops below are each compiled twice, for
/// the base x86-64 instruction set and for AVX2 with the bit instructions that come with
/// it (`multiversion`); each call runs the second where the machine has them (one cached
/// feature check a call, against a loop over hundreds of lanes). Why: the loops then
/// take eight lanes a step instead of four, and the path tracer's frame on the
/// interpreter took 8-10 % less time (the histogram 5-8 %), most of what building the
/// whole workspace for AVX2 gave (11 %); BENCHMARKS.md, "interpreter". Both versions
/// compute the same bits: integer and IEEE f32 operations have one result, and Rust
/// never fuses a multiply and an add.
#[multiversion(targets("x86_64+avx2+bmi1+bmi2+lzcnt+popcnt"))]
fn binary_rows(
    members: Members<'_>,
    regs: &mut [u32],
    (dst, a, b): (usize, usize, usize),
    rows: usize,
    f: impl Fn(u32, u32) -> u32,
) {
    match members {
        Members::All(width) => chunks!(rows * width, |start, n| {
            let (d, x, y) = (dst * width + start, a * width + start, b * width + start);
            // Rows of distinct registers are `n` or more words apart: chunks of them
            // never overlap in part (checked, not assumed: see the last branch).
            let apart = |p: usize, q: usize| p.abs_diff(q) >= n;
            if apart(d, x) && apart(d, y) && apart(x, y) {
                let [out, xs, ys] = regs.get_disjoint_mut([d..d + n, x..x + n, y..y + n]).expect("rows apart");
                for i in 0..n {
                    out[i] = f(xs[i], ys[i]);
                }
            } else if apart(d, x) && x == y {
                let [out, xs] = regs.get_disjoint_mut([d..d + n, x..x + n]).expect("rows apart");
                for i in 0..n {
                    out[i] = f(xs[i], xs[i]);
                }
            } else if [(d, x), (d, y), (x, y)].iter().all(|&(p, q)| p == q || apart(p, q)) {
                // The destination is an operand (not compiled today): through copies.
                let (xs, ys) = (row::<N>(regs, x, n), row::<N>(regs, y, n));
                for (i, o) in regs[d..d + n].iter_mut().enumerate() {
                    *o = f(xs[i], ys[i]);
                }
            } else {
                // Overlapping in part (never compiled): word by word in order, as one
                // invocation at a time would.
                for i in 0..n {
                    regs[d + i] = f(regs[x + i], regs[y + i]);
                }
            }
        }),
        Members::Some(lanes, width) => {
            for r in 0..rows {
                let (d, x, y) = ((dst + r) * width, (a + r) * width, (b + r) * width);
                // Whole rows as slices of `width` words: the three reads and the write of
                // a member share one bound, which the compiler tests once per member.
                // Rows start at multiples of `width`, so two rows are the same row or
                // apart: `Err` means rows that coincide (the destination an operand).
                if let Ok([out, xs, ys]) = regs.get_disjoint_mut([d..d + width, x..x + width, y..y + width]) {
                    for &l in lanes {
                        out[l] = f(xs[l], ys[l]);
                    }
                } else if x == y && d != x {
                    let [out, xs] = regs.get_disjoint_mut([d..d + width, x..x + width]).expect("rows in the file");
                    for &l in lanes {
                        out[l] = f(xs[l], xs[l]);
                    }
                } else {
                    for &l in lanes {
                        regs[d + l] = f(regs[x + l], regs[y + l]);
                    }
                }
            }
        }
        Members::Masked(_, mask, chunks) => {
            let width = mask.len();
            for r in 0..rows {
                each_chunk(mask, chunks, |c, mask| {
                    let (xs, ys) = (&regs[(a + r) * width + c..][..N], &regs[(b + r) * width + c..][..N]);
                    let words: [u32; N] = std::array::from_fn(|i| f(xs[i], ys[i]));
                    keep_members(&mut regs[(dst + r) * width + c..][..N], &words, mask);
                });
            }
        }
    }
}

/// [`Members::unary`], compiled twice as [`binary_rows`].
#[multiversion(targets("x86_64+avx2+bmi1+bmi2+lzcnt+popcnt"))]
fn unary_rows(members: Members<'_>, regs: &mut [u32], dst: usize, src: usize, rows: usize, f: impl Fn(u32) -> u32) {
    match members {
        Members::All(width) => chunks!(rows * width, |start, n| {
            let (d, x) = (dst * width + start, src * width + start);
            if d.abs_diff(x) >= n {
                let [out, xs] = regs.get_disjoint_mut([d..d + n, x..x + n]).expect("rows apart");
                for i in 0..n {
                    out[i] = f(xs[i]);
                }
            } else if d == x {
                for o in &mut regs[d..d + n] {
                    *o = f(*o);
                }
            } else {
                // Overlapping in part (never compiled): word by word in order.
                for i in 0..n {
                    regs[d + i] = f(regs[x + i]);
                }
            }
        }),
        Members::Some(lanes, width) => {
            for r in 0..rows {
                let (d, x) = ((dst + r) * width, (src + r) * width);
                if let Ok([out, xs]) = regs.get_disjoint_mut([d..d + width, x..x + width]) {
                    for &l in lanes {
                        out[l] = f(xs[l]);
                    }
                } else {
                    // The same row (rows are the same or apart): word by word, as before.
                    for &l in lanes {
                        regs[d + l] = f(regs[x + l]);
                    }
                }
            }
        }
        Members::Masked(_, mask, chunks) => {
            let width = mask.len();
            for r in 0..rows {
                each_chunk(mask, chunks, |c, mask| {
                    let xs = &regs[(src + r) * width + c..][..N];
                    let words: [u32; N] = std::array::from_fn(|i| f(xs[i]));
                    keep_members(&mut regs[(dst + r) * width + c..][..N], &words, mask);
                });
            }
        }
    }
}

/// [`Members::select`], compiled twice as [`binary_rows`].
#[multiversion(targets("x86_64+avx2+bmi1+bmi2+lzcnt+popcnt"))]
fn select_rows(
    members: Members<'_>,
    regs: &mut [u32],
    (dst, cond, accept, reject): (usize, usize, usize, usize),
    rows: usize,
) {
    match members {
        Members::All(width) => chunks!(rows * width, |start, n| {
            let (d, c, x, y) =
                (dst * width + start, cond * width + start, accept * width + start, reject * width + start);
            if let Ok([out, cs, xs, ys]) = regs.get_disjoint_mut([d..d + n, c..c + n, x..x + n, y..y + n]) {
                // With masks, not a choice of address: the compiler vectorises this.
                for i in 0..n {
                    let mask = 0u32.wrapping_sub(u32::from(cs[i] != 0));
                    out[i] = (xs[i] & mask) | (ys[i] & !mask);
                }
            } else if [(d, c), (d, x), (d, y), (c, x), (c, y), (x, y)]
                .iter()
                .all(|&(p, q)| p == q || p.abs_diff(q) >= n)
            {
                // Rows repeated (`select(x, x, c)`, ...): through copies.
                let (cs, xs, ys) = (row::<N>(regs, c, n), row::<N>(regs, x, n), row::<N>(regs, y, n));
                for (i, o) in regs[d..d + n].iter_mut().enumerate() {
                    *o = if cs[i] != 0 { xs[i] } else { ys[i] };
                }
            } else {
                // Overlapping in part (never compiled): word by word in order.
                for i in 0..n {
                    regs[d + i] = if regs[c + i] != 0 { regs[x + i] } else { regs[y + i] };
                }
            }
        }),
        Members::Some(lanes, width) => {
            for r in 0..rows {
                let (d, c, x, y) = ((dst + r) * width, (cond + r) * width, (accept + r) * width, (reject + r) * width);
                if let Ok([out, cs, xs, ys]) =
                    regs.get_disjoint_mut([d..d + width, c..c + width, x..x + width, y..y + width])
                {
                    for &l in lanes {
                        out[l] = if cs[l] != 0 { xs[l] } else { ys[l] };
                    }
                } else {
                    // Rows that coincide (`select(x, x, c)`, the destination an operand):
                    // word by word, as before.
                    for &l in lanes {
                        regs[d + l] = if regs[c + l] != 0 { regs[x + l] } else { regs[y + l] };
                    }
                }
            }
        }
        Members::Masked(_, mask, chunks) => {
            let width = mask.len();
            for r in 0..rows {
                each_chunk(mask, chunks, |c, mask| {
                    let (cs, xs, ys) = (
                        &regs[(cond + r) * width + c..][..N],
                        &regs[(accept + r) * width + c..][..N],
                        &regs[(reject + r) * width + c..][..N],
                    );
                    let words: [u32; N] = std::array::from_fn(|i| {
                        let m = 0u32.wrapping_sub(u32::from(cs[i] != 0));
                        (xs[i] & m) | (ys[i] & !m)
                    });
                    keep_members(&mut regs[(dst + r) * width + c..][..N], &words, mask);
                });
            }
        }
    }
}

/// [`Members::copy`], compiled twice as [`binary_rows`].
#[multiversion(targets("x86_64+avx2+bmi1+bmi2+lzcnt+popcnt"))]
fn copy_rows(members: Members<'_>, regs: &mut [u32], dst: usize, src: usize, len: usize) {
    match members {
        // The rows of a value are contiguous: one copy of `len * width` words.
        Members::All(width) => regs.copy_within(src * width..(src + len) * width, dst * width),
        Members::Some(lanes, width) => {
            for i in 0..len {
                let r = if dst <= src { i } else { len - 1 - i };
                let (d, x) = ((dst + r) * width, (src + r) * width);
                if let Ok([out, xs]) = regs.get_disjoint_mut([d..d + width, x..x + width]) {
                    for &l in lanes {
                        out[l] = xs[l];
                    }
                } else {
                    // The same row: word by word, as before.
                    for &l in lanes {
                        regs[d + l] = regs[x + l];
                    }
                }
            }
        }
        Members::Masked(_, mask, chunks) => {
            let width = mask.len();
            for i in 0..len {
                let r = if dst <= src { i } else { len - 1 - i };
                each_chunk(mask, chunks, |c, mask| {
                    // The chunk's words copied out whole (one bound, a vector copy), not
                    // word by word.
                    let words: [u32; N] = regs[(src + r) * width + c..][..N].try_into().expect("a chunk of N lanes");
                    keep_members(&mut regs[(dst + r) * width + c..][..N], &words, mask);
                });
            }
        }
    }
}

/// [`Members::fill`], compiled twice as [`binary_rows`].
#[multiversion(targets("x86_64+avx2+bmi1+bmi2+lzcnt+popcnt"))]
fn fill_rows(members: Members<'_>, regs: &mut [u32], dst: usize, len: usize, value: u32) {
    match members {
        Members::All(width) => {
            for r in dst..dst + len {
                chunks!(width, |start, n| {
                    regs[r * width + start..][..n].fill(value);
                });
            }
        }
        Members::Some(lanes, width) => {
            for r in dst..dst + len {
                for &l in lanes {
                    regs[r * width + l] = value;
                }
            }
        }
        Members::Masked(_, mask, chunks) => {
            let (width, words) = (mask.len(), [value; N]);
            for r in dst..dst + len {
                each_chunk(mask, chunks, |c, mask| keep_members(&mut regs[r * width + c..][..N], &words, mask));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{Members, N};

    /// Which members of `members` `zeros` says have a zero word in `row`, and how many.
    fn zeros_of(members: Members, row: &[u32]) -> (Vec<usize>, usize) {
        let mut taken = Vec::new();
        let count = members.zeros(row, &mut taken);
        let lanes = (0..row.len()).filter(|&l| taken[l / N] >> (l % N) & 1 != 0).collect();
        (lanes, count)
    }

    #[test]
    fn zeros_are_the_members_whose_word_is_zero() {
        // Every third lane's word is 0.
        let row: Vec<u32> = (0..192).map(|l| if l % 3 == 0 { 0 } else { l + 1 }).collect();
        let expected = |members: &[usize]| members.iter().copied().filter(|l| l % 3 == 0).collect::<Vec<_>>();
        // A whole batch, and one whose last chunk is short (130 lanes).
        let all: Vec<usize> = (0..192).collect();
        assert_eq!(zeros_of(Members::All(192), &row), (expected(&all), 64));
        assert_eq!(zeros_of(Members::All(130), &row[..130]), (expected(&all[..130]), 44));
        // Some members, listed and masked: lanes 3, 6, 7, 66, 129 and 191 (chunks 0, 1, 2).
        let some = [3, 6, 7, 66, 129, 191];
        assert_eq!(zeros_of(Members::Some(&some, 192), &row), (vec![3, 6, 66, 129], 4));
        let mut mask = vec![0; 192];
        let mut set = [0u64; 3];
        for &l in &some {
            mask[l] = u32::MAX;
            set[l / N] |= 1 << (l % N);
        }
        let masked = Members::Masked(&set, &mask, 0b111);
        assert_eq!(zeros_of(masked, &row), (vec![3, 6, 66, 129], 4));
        let mut listed = Vec::new();
        masked.for_each(|l| listed.push(l));
        assert_eq!((listed, masked.len()), (some.to_vec(), 6));
        // `all` stops at the first member that fails.
        for members in [masked, Members::Some(&some, 192)] {
            let mut asked = Vec::new();
            assert!(!members.all(|l| {
                asked.push(l);
                l < 66
            }));
            assert_eq!(asked, [3, 6, 7, 66]);
            assert!(members.all(|l| l < 192));
        }
        // A chunk left out of the mask's chunks is not looked at, whatever its words.
        mask[0] = u32::MAX;
        set[0] = 0;
        assert_eq!(zeros_of(Members::Masked(&set, &mask, 0b110), &row), (vec![66, 129], 2));
    }

    /// The row operations of listed and masked members against one member and one
    /// register at a time, rows in order (what an invocation alone computes), for rows
    /// apart and for every way the rows of one instruction can coincide or overlap.
    #[test]
    fn some_members_rows_match_one_member_at_a_time() {
        const WIDTH: usize = 128;
        let start: Vec<u32> = (0..WIDTH as u32 * 12).map(|i| i.wrapping_mul(2_654_435_761) >> 7).collect();
        let some = [1, 2, 40, 64, 100, 127];
        let (mut mask, mut set) = (vec![0; WIDTH], [0u64; 2]);
        for &l in &some {
            mask[l] = u32::MAX;
            set[l / N] |= 1 << (l % N);
        }
        let groups = [Members::Some(&some, WIDTH), Members::Masked(&set, &mask, 0b11)];
        let at = |reg: usize, lane: usize| reg * WIDTH + lane;
        let f = |x: u32, y: u32| x.wrapping_mul(3) ^ y.rotate_left(5);
        // (dst, a, b, rows): apart, the destination an operand, both operands one row, all
        // three one row, and overlapping in part.
        let cases = [(0, 4, 8, 2), (4, 4, 8, 2), (8, 4, 8, 2), (0, 4, 4, 2), (4, 4, 4, 2), (5, 4, 8, 2), (3, 4, 8, 2)];
        for group in groups {
            let kind = if matches!(group, Members::Some(..)) { "listed" } else { "masked" };
            for (dst, a, b, rows) in cases {
                let mut expected = start.clone();
                for r in 0..rows {
                    for &l in &some {
                        expected[at(dst + r, l)] = f(expected[at(a + r, l)], expected[at(b + r, l)]);
                    }
                }
                let mut regs = start.clone();
                group.binary(&mut regs, (dst, a, b), rows, f);
                assert!(regs == expected, "{kind} binary {dst} <- {a}, {b} ({rows} rows)");

                let mut expected = start.clone();
                for r in 0..rows {
                    for &l in &some {
                        expected[at(dst + r, l)] = f(expected[at(a + r, l)], 7);
                    }
                }
                let mut regs = start.clone();
                group.unary(&mut regs, dst, a, rows, |x| f(x, 7));
                assert!(regs == expected, "{kind} unary {dst} <- {a} ({rows} rows)");

                // The condition in rows `b..`: zero for every other member, so that both
                // `a`'s and `a + 2`'s rows are chosen.
                let mut chosen = start.clone();
                for r in 0..rows {
                    for (k, &l) in some.iter().enumerate() {
                        chosen[at(b + r, l)] = if (k + r) % 2 == 0 { 0 } else { chosen[at(b + r, l)] | 1 };
                    }
                }
                let mut expected = chosen.clone();
                for r in 0..rows {
                    for &l in &some {
                        let from = if expected[at(b + r, l)] != 0 { a } else { a + 2 };
                        expected[at(dst + r, l)] = expected[at(from + r, l)];
                    }
                }
                let mut regs = chosen.clone();
                group.select(&mut regs, (dst, b, a, a + 2), rows);
                assert!(regs == expected, "{kind} select {dst} <- {b} ? {a} : {} ({rows} rows)", a + 2);

                // A copy of overlapping rows reads each word before it is overwritten.
                let mut expected = start.clone();
                for &l in &some {
                    let column: Vec<u32> = (0..rows).map(|r| start[at(a + r, l)]).collect();
                    for (r, &word) in column.iter().enumerate() {
                        expected[at(dst + r, l)] = word;
                    }
                }
                let mut regs = start.clone();
                group.copy(&mut regs, dst, a, rows);
                assert!(regs == expected, "{kind} copy {dst} <- {a} ({rows} rows)");
            }
        }
    }
}
