//! The interpreter's register bytecode: one [`Insn`] per operation, its operands
//! resolved at compile time to word offsets in the frame's register file (a `Reg`), so
//! that running an instruction needs no look-up of types, slots or expressions.
//!
//! A frame's register file holds, in this order, the value of every expression that
//! needs storage, the function's local variables (and those of every callee inlined into
//! it), all as 32-bit words. Values that are known when the kernel is compiled
//! (literals, constants, pointers to globals that an instruction reads as values) are
//! filled into each code's register template once and never recomputed.
//!
//! Why every instruction type sits here, the boxed operands of the rarer ones too
//! ([`ElementLoad`], [`ImageInsn`], ...): this file is the contract between the compiler
//! ([`super::decode`] and the passes, which write instructions) and the executor
//! ([`super::interp`], [`super::execute`], [`super::image`], which run them). Neither
//! side's code lives here, so both import it and it imports neither.

use super::lanes::{LaneRegs, Members};
use super::layout::Piece;
pub(super) use super::layout::Reg;
use naga::ScalarKind;

/// A scalar binary operator resolved for its operand kind (WGSL semantics, see
/// [`BinOp::apply`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum BinOp {
    AddF,
    SubF,
    MulF,
    DivF,
    ModF,
    AddI,
    SubI,
    MulI,
    DivU,
    DivS,
    ModU,
    ModS,
    EqF,
    NeF,
    LtF,
    LeF,
    GtF,
    GeF,
    Eq,
    Ne,
    LtS,
    LeS,
    GtS,
    GeS,
    LtU,
    LeU,
    GtU,
    GeU,
    And,
    Xor,
    Or,
    LogicalAnd,
    LogicalOr,
    Shl,
    ShrU,
    ShrS,
}

impl BinOp {
    /// The operator `op` on components of kind `kind`; `None` where WGSL has none
    /// (mirrors `arith::binary`, the tests' reference, compiled for tests only, case by case).
    pub(super) fn resolve(op: naga::BinaryOperator, kind: ScalarKind) -> Option<Self> {
        use BinOp as O;
        use ScalarKind as K;
        use naga::BinaryOperator as B;
        Some(match (op, kind) {
            (B::Add, K::Float) => O::AddF,
            (B::Subtract, K::Float) => O::SubF,
            (B::Multiply, K::Float) => O::MulF,
            (B::Divide, K::Float) => O::DivF,
            (B::Modulo, K::Float) => O::ModF,
            (B::Add, K::Uint | K::Sint) => O::AddI,
            (B::Subtract, K::Uint | K::Sint) => O::SubI,
            (B::Multiply, K::Uint | K::Sint) => O::MulI,
            (B::Divide, K::Uint) => O::DivU,
            (B::Divide, K::Sint) => O::DivS,
            (B::Modulo, K::Uint) => O::ModU,
            (B::Modulo, K::Sint) => O::ModS,
            (B::Equal, K::Float) => O::EqF,
            (B::NotEqual, K::Float) => O::NeF,
            (B::Less, K::Float) => O::LtF,
            (B::LessEqual, K::Float) => O::LeF,
            (B::Greater, K::Float) => O::GtF,
            (B::GreaterEqual, K::Float) => O::GeF,
            (B::Equal, _) => O::Eq,
            (B::NotEqual, _) => O::Ne,
            (B::Less, K::Sint) => O::LtS,
            (B::LessEqual, K::Sint) => O::LeS,
            (B::Greater, K::Sint) => O::GtS,
            (B::GreaterEqual, K::Sint) => O::GeS,
            (B::Less, _) => O::LtU,
            (B::LessEqual, _) => O::LeU,
            (B::Greater, _) => O::GtU,
            (B::GreaterEqual, _) => O::GeU,
            (B::And, _) => O::And,
            (B::ExclusiveOr, _) => O::Xor,
            (B::InclusiveOr, _) => O::Or,
            (B::LogicalAnd, K::Bool) => O::LogicalAnd,
            (B::LogicalOr, K::Bool) => O::LogicalOr,
            (B::ShiftLeft, K::Uint | K::Sint) => O::Shl,
            (B::ShiftRight, K::Uint) => O::ShrU,
            (B::ShiftRight, K::Sint) => O::ShrS,
            _ => return None,
        })
    }

    /// `a op c` on one component.
    #[inline(always)]
    pub(super) fn apply(self, a: u32, c: u32) -> u32 {
        use BinOp as O;
        let f = f32::from_bits;
        let b = u32::from;
        let (ia, ic) = (a as i32, c as i32);
        match self {
            O::AddF => (f(a) + f(c)).to_bits(),
            O::SubF => (f(a) - f(c)).to_bits(),
            O::MulF => (f(a) * f(c)).to_bits(),
            O::DivF => (f(a) / f(c)).to_bits(),
            O::ModF => (f(a) % f(c)).to_bits(),
            O::AddI => a.wrapping_add(c),
            O::SubI => a.wrapping_sub(c),
            O::MulI => a.wrapping_mul(c),
            O::DivU => a.checked_div(c).unwrap_or(a),
            O::DivS => ia.checked_div(ic).unwrap_or(ia) as u32,
            O::ModU => a.checked_rem(c).unwrap_or(0),
            O::ModS => ia.checked_rem(ic).unwrap_or(0) as u32,
            O::EqF => b(f(a) == f(c)),
            O::NeF => b(f(a) != f(c)),
            O::LtF => b(f(a) < f(c)),
            O::LeF => b(f(a) <= f(c)),
            O::GtF => b(f(a) > f(c)),
            O::GeF => b(f(a) >= f(c)),
            O::Eq => b(a == c),
            O::Ne => b(a != c),
            O::LtS => b(ia < ic),
            O::LeS => b(ia <= ic),
            O::GtS => b(ia > ic),
            O::GeS => b(ia >= ic),
            O::LtU => b(a < c),
            O::LeU => b(a <= c),
            O::GtU => b(a > c),
            O::GeU => b(a >= c),
            O::And => a & c,
            O::Xor => a ^ c,
            O::Or => a | c,
            O::LogicalAnd => b(a != 0 && c != 0),
            O::LogicalOr => b(a != 0 || c != 0),
            O::Shl => a << (c & 31),
            O::ShrU => a >> (c & 31),
            O::ShrS => (ia >> (c & 31)) as u32,
        }
    }
}

/// A unary operator resolved for its operand kind.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum UnOp {
    /// Float negation: flips the sign bit.
    NegF,
    /// Wrapping integer negation.
    NegI,
    /// `!b`.
    Not,
    /// `~x`.
    BitNot,
}

impl UnOp {
    /// `op x` on one component.
    #[inline(always)]
    pub(super) fn apply(self, x: u32) -> u32 {
        match self {
            UnOp::NegF => x ^ 0x8000_0000,
            UnOp::NegI => (x as i32).wrapping_neg() as u32,
            UnOp::Not => u32::from(x == 0),
            UnOp::BitNot => !x,
        }
    }
}

/// A computation too rare to deserve its own instruction (matrix products, most math
/// functions, packing): a closure over a group's register file and members, operands
/// captured.
pub(super) type Compute = Box<dyn Fn(&mut [u32], Members) + Send + Sync>;

/// The [`Compute`] that runs `f` on each member's registers in turn (`f` compiled into
/// the loop over the members, one dynamic call per group rather than per member).
pub(super) fn per_lane(f: impl Fn(&mut LaneRegs) + Send + Sync + 'static) -> Compute {
    Box::new(move |file, members| {
        let width = members.width();
        members.for_each(|lane| f(&mut LaneRegs::new(file, lane, width)))
    })
}

/// A call of a function that was not inlined.
pub(super) struct CallInsn {
    /// Index of the callee's code in the program.
    pub code: u32,
    /// Per argument: (caller register, words, callee register).
    pub arguments: Box<[(Reg, u32, Reg)]>,
    /// Caller register and words of the return value.
    pub result: Option<(Reg, u32)>,
}

/// A WGSL atomic read-modify-write.
pub(super) struct AtomicInsn {
    /// Register of the pointer.
    pub pointer: Reg,
    pub fun: naga::AtomicFunction,
    /// Register of the operand.
    pub value: Reg,
    /// Register of `compare` for a compare-exchange.
    pub compare: Option<Reg>,
    /// Min and max compare as signed integers.
    pub signed: bool,
    /// Register receiving the old value (and the `exchanged` flag after it).
    pub result: Option<Reg>,
}

/// A subgroup gather (shuffle, broadcast): every invocation of the workgroup stops
/// here and the values are exchanged between them.
pub(super) struct GatherInsn {
    pub mode: naga::GatherMode,
    /// Register of the lane index or delta, if the mode has one.
    pub index: Option<Reg>,
    pub argument: Reg,
    pub len: u32,
    pub result: Reg,
}

/// What a subgroup collective computes over the lanes of a subgroup.
#[derive(Clone, Copy, Debug)]
pub(super) enum CollectiveFun {
    /// `subgroupBallot`: bit `lane` of a `vec4<u32>` set where the predicate holds
    /// (every lane when there is no predicate).
    Ballot { predicate: Option<Reg> },
    /// `subgroupAll`, `subgroupAdd`, `subgroupInclusiveMul`, ...: the operator over the
    /// subgroup (reduce) or over the lanes up to this one (inclusive or exclusive scan),
    /// component-wise, lane by lane in order.
    Operation { op: naga::SubgroupOperation, collective: naga::CollectiveOperation, kind: naga::ScalarKind },
}

/// A subgroup collective operation: every invocation of the workgroup stops here and
/// each receives the result over its subgroup.
pub(super) struct CollectiveInsn {
    pub fun: CollectiveFun,
    pub argument: Reg,
    pub len: u32,
    pub result: Reg,
}

/// Runs of words of a value (first word, words), in increasing order: the words of a
/// load that its uses read ([`super::load_fields`]).
pub(super) type Runs = Box<[(u32, u32)]>;

/// Element `index` (clamped to the array's last, as WGSL does) of the runtime-sized array
/// at byte `address` of bound buffer `buffer`, elements `stride` bytes apart, loaded
/// into `dst`: `len` words, or only `runs` (first word, words) where given. A
/// `PtrIndexRt` and a load fused into one instruction: why and when in
/// [`super::element_load`].
pub(super) struct ElementLoad {
    /// First register of the loaded value.
    pub dst: Reg,
    /// Index of the bound buffer.
    pub buffer: u32,
    /// Byte of the array's first element in the buffer.
    pub address: u32,
    /// Register of the element index.
    pub index: Reg,
    /// Bytes from one element to the next.
    pub stride: u32,
    /// The array's element count if it has a fixed size (a uniform buffer's
    /// `array<T, N>`), `None` for a runtime-sized array (its count is the buffer's).
    pub count: Option<u32>,
    /// Words of the value.
    pub len: u32,
    /// The runs of words its uses read ([`super::load_fields`]), or `None`: all.
    pub runs: Option<Runs>,
}

impl ElementLoad {
    /// The buffer word where the element of `index` starts, for a buffer of `bytes`
    /// bytes: the element clamped as `PtrIndexRt` clamps it ([`element_offset`]), or for
    /// a fixed-size array as `PtrIndex` does (to its last element; words past the
    /// buffer's end then read as 0, as through the pointer).
    #[inline(always)]
    pub(super) fn first_word(&self, bytes: usize, index: u32) -> usize {
        let address = self.address as usize;
        match self.count {
            Some(count) => (address + index.min(count.saturating_sub(1)) as usize * self.stride as usize) / 4,
            None => {
                let available = bytes.saturating_sub(address);
                (address + element_offset(available, self.stride as usize, index as usize)) / 4
            }
        }
    }

    /// [`Self::first_word`] for a buffer of `bytes` bytes as a clamp computed once for
    /// the instruction, so that each member's word is a `min`, a multiply and an add
    /// (the element loads were a fifth of the path tracer's time on the interpreter, and
    /// `element_offset`'s checked arithmetic per member much of it).
    #[inline(always)]
    pub(super) fn clamp(&self, bytes: usize) -> ElementClamp {
        let (address, stride) = (self.address as usize, self.stride as usize);
        let last = match self.count {
            Some(count) => count.saturating_sub(1) as usize,
            // `element_offset`'s element 0 for a zero stride.
            None if stride == 0 => 0,
            // `element_offset` keeps `index` while `(index + 1) * stride <= available`,
            // that is while `index < available / stride`, and gives the last whole
            // element (or element 0 where none is whole) otherwise: `index` clamped to
            // `max(available / stride, 1) - 1` either way.
            None => (bytes.saturating_sub(address) / stride).max(1) - 1,
        };
        ElementClamp { address, stride, last }
    }

    /// The array's element count, in a buffer of `bytes` bytes (for the sanitizer's
    /// index check).
    pub(super) fn elements(&self, bytes: usize) -> u64 {
        match self.count {
            Some(count) => u64::from(count),
            None => (bytes.saturating_sub(self.address as usize) / self.stride.max(1) as usize) as u64,
        }
    }
}

/// The element an [`ElementLoad`] reads, as a clamp of the index worked out once per
/// instruction ([`ElementLoad::clamp`]).
#[derive(Clone, Copy)]
pub(super) struct ElementClamp {
    /// Byte of the array's first element in the buffer.
    address: usize,
    /// Bytes from one element to the next.
    stride: usize,
    /// The last element an index reads (larger ones read it).
    last: usize,
}

impl ElementClamp {
    /// The buffer word where the element of `index` starts, as
    /// [`ElementLoad::first_word`] gives it. No overflow: `address + last * stride` is at
    /// most the buffer's size for a runtime-sized array, and at most (2^32 - 1)^2 for a
    /// fixed one (a `u32` address, count and stride).
    #[inline(always)]
    pub(super) fn first_word(self, index: u32) -> usize {
        (self.address + (index as usize).min(self.last) * self.stride) / 4
    }
}

/// Where element `index` of an array of elements `stride` apart starts, in a region of
/// `available` units from the array's start: the element clamped to the last one that
/// fits (WGSL), element 0 where none fits (its words then read as 0). No division
/// where the element lies inside (the common case).
#[inline(always)]
pub(super) fn element_offset(available: usize, stride: usize, index: usize) -> usize {
    // `index` and `stride` come from the kernel and its data: the end is computed
    // without wrapping (an end past usize::MAX is outside every region).
    if stride == 0 {
        0
    } else if index.checked_add(1).and_then(|n| n.checked_mul(stride)).is_some_and(|end| end <= available) {
        index * stride
    } else {
        ((available / stride).max(1) - 1) * stride
    }
}

/// What an image instruction does.
#[derive(Clone, Copy, Debug)]
pub(super) enum ImageOp {
    /// `textureLoad`: coordinate, optional layer and level; 4 words out.
    Load,
    /// `textureStore`: coordinate, optional layer, 4 words in.
    Store,
    /// `textureDimensions`: optional level; 1 to 3 words out.
    Size,
    /// `textureNumLevels`.
    NumLevels,
    /// `textureNumLayers`.
    NumLayers,
    /// `textureSampleLevel` (level register, or level 0 when absent).
    SampleLevel,
    /// `textureGather` of component 0 to 3 (level 0).
    Gather(u8),
}

/// An image built-in, operands resolved to registers (by [`super::image_lower`]; run by
/// [`super::image`]).
pub(super) struct ImageInsn {
    pub op: ImageOp,
    /// Register of the image value (its slot in the first word's low 24 bits).
    pub image: Reg,
    /// Register of the sampler value (sampling only).
    pub sampler: Reg,
    /// Register of the coordinate (integers for loads and stores, f32 for sampling).
    pub coordinate: Reg,
    /// Its components (1 to 3).
    pub coordinates: u8,
    /// Register of the array layer, if the texture is arrayed.
    pub layer: Option<Reg>,
    /// Register of the mip level (an integer, or an f32 for sampling).
    pub level: Option<Reg>,
    /// Register of the value a store writes.
    pub value: Reg,
    /// A sampling offset in texels (a constant of the shader).
    pub offset: [i32; 3],
    /// Register of the result.
    pub result: Reg,
}

/// One bytecode instruction. Unless said otherwise operands are registers, `n` counts
/// components, and a `s*` stride is 1 for a vector operand and 0 for a scalar one
/// broadcast over the components.
pub(super) enum Insn {
    /// Copies one word.
    Copy1 { dst: Reg, src: Reg },
    /// Copies two words.
    Copy2 { dst: Reg, src: Reg },
    /// Copies three words.
    Copy3 { dst: Reg, src: Reg },
    /// Copies four words.
    Copy4 { dst: Reg, src: Reg },
    /// Copies `len` words.
    Copy { dst: Reg, src: Reg, len: u32 },
    /// Zeroes `len` words.
    Zero { dst: Reg, len: u32 },
    /// Scalar binary operation.
    Bin { op: BinOp, dst: Reg, a: Reg, b: Reg },
    /// Component-wise binary operation.
    BinV { op: BinOp, dst: Reg, a: Reg, b: Reg, n: u8, sa: u8, sb: u8 },
    /// Component-wise unary operation.
    Un { op: UnOp, dst: Reg, src: Reg, n: u8 },
    /// `select(reject, accept, cond)` component-wise.
    Select { dst: Reg, cond: Reg, accept: Reg, reject: Reg, n: u8, sc: u8 },
    /// `dst[i] = src[pattern[i]]`.
    Swizzle { dst: Reg, src: Reg, pattern: [u8; 4], n: u8 },
    /// `dst[i] = src[0]`.
    Splat { dst: Reg, src: Reg, n: u8 },
    /// Numeric conversion component-wise.
    Convert { from: ScalarKind, to: ScalarKind, dst: Reg, src: Reg, n: u8 },
    /// `len` words of a value at `base + min(index, count - 1) * stride` (dynamic index
    /// into a vector, matrix or array value).
    Extract { dst: Reg, base: Reg, index: Reg, count: u32, stride: u32, len: u32 },
    /// Pointer plus a constant word offset.
    PtrAdd { dst: Reg, base: Reg, add: u32 },
    /// Pointer to element `min(index, count - 1)` of stride `stride` words.
    PtrIndex { dst: Reg, base: Reg, index: Reg, count: u32, stride: u32 },
    /// Pointer into a runtime-sized array: the count comes from the memory's size.
    PtrIndexRt { dst: Reg, base: Reg, index: Reg, stride: u32 },
    /// Reads `len` words through a pointer register.
    Load { dst: Reg, pointer: Reg, len: u32 },
    /// Reads the words of `runs` (first word, words) of a `len`-word value through a
    /// pointer register: a struct whose other words are never read
    /// ([`super::load_fields`]).
    LoadRuns { dst: Reg, pointer: Reg, len: u32, runs: Runs },
    /// An element of a runtime-sized array in a buffer known when compiling, loaded
    /// (`PtrIndexRt` and a load fused: [`super::element_load`]).
    LoadElement(Box<ElementLoad>),
    /// Writes `len` words through a pointer register.
    Store { pointer: Reg, src: Reg, len: u32 },
    /// Reads a value holding f16 through a pointer into a buffer: naga's layout there,
    /// the register layout here.
    LoadMixed { dst: Reg, pointer: Reg, plan: Box<[Piece]> },
    /// Writes a value holding f16 through a pointer into a buffer.
    StoreMixed { pointer: Reg, src: Reg, plan: Box<[Piece]> },
    /// Reads workgroup memory at a word address known when compiling.
    LoadWorkgroup { dst: Reg, address: u32, len: u32 },
    /// Writes workgroup memory at a known word address.
    StoreWorkgroup { address: u32, src: Reg, len: u32 },
    /// Reads private memory at a known word address.
    LoadPrivate { dst: Reg, address: u32, len: u32 },
    /// Writes private memory at a known word address.
    StorePrivate { address: u32, src: Reg, len: u32 },
    /// Reads bound buffer `buffer` at a known word address (pointers into buffers count
    /// bytes; these static addresses are words).
    LoadBuffer { dst: Reg, buffer: u32, address: u32, len: u32 },
    /// Writes bound buffer `buffer` at a known word address.
    StoreBuffer { buffer: u32, address: u32, src: Reg, len: u32 },
    /// `arrayLength(pointer)` of an array whose elements are `stride` words.
    ArrayLength { dst: Reg, pointer: Reg, stride: u32 },
    /// A rare computation.
    Compute(Compute),
    /// Continues at `target`.
    Jump(u32),
    /// Continues at `target` when the bool register is false.
    JumpUnless { cond: Reg, target: u32 },
    /// Continues at the target of the first case equal to the selector, else at `default`.
    Switch { selector: Reg, cases: Box<[(u32, u32)]>, default: u32 },
    /// Calls a function that was not inlined.
    Call(Box<CallInsn>),
    /// Returns `len` words from `src` (`len` 0: no value).
    Return { src: Reg, len: u32 },
    /// Control barrier of the workgroup; `workgroup` and `storage`: whether it orders
    /// workgroup memory and storage buffers (`workgroupBarrier`, `storageBarrier`;
    /// read by the sanitizer only).
    Barrier { workgroup: bool, storage: bool },
    /// Atomic read-modify-write.
    Atomic(Box<AtomicInsn>),
    /// Subgroup gather.
    Gather(Box<GatherInsn>),
    /// Subgroup ballot, reduction or scan.
    Collective(Box<CollectiveInsn>),
    /// A texture built-in (load, store, query, sample, gather).
    Image(Box<ImageInsn>),
    /// An unsupported construct reached at run time: (what, WGSL line).
    Fail(Box<(String, u32)>),
    /// An instruction whose accesses the sanitizer checks before running it (only in
    /// a sanitizing program: [`super::sanitize`]).
    Checked(Box<Insn>),
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_element_clamp_gives_first_words_word() {
        // Runtime-sized arrays (whole, partial and no elements in the buffer, a zero
        // stride) and fixed ones, at and past every edge.
        for (count, address, stride) in
            [(None, 0, 16), (None, 8, 12), (None, 4, 4), (None, 0, 0), (Some(3), 4, 8), (Some(0), 0, 8)]
        {
            let load = ElementLoad { dst: 0, buffer: 0, address, index: 0, stride, count, len: 1, runs: None };
            for bytes in [0, 4, 8, 12, 16, 20, 44, 48, 52, 64] {
                let clamp = load.clamp(bytes);
                for index in (0..20).chain([u32::MAX - 1, u32::MAX]) {
                    assert_eq!(
                        clamp.first_word(index),
                        load.first_word(bytes, index),
                        "count {count:?}, address {address}, stride {stride}, bytes {bytes}, index {index}"
                    );
                }
            }
        }
    }

    #[test]
    fn resolved_operators_match_the_reference_arithmetic() {
        use naga::BinaryOperator as B;
        let ops = [
            B::Add,
            B::Subtract,
            B::Multiply,
            B::Divide,
            B::Modulo,
            B::Equal,
            B::NotEqual,
            B::Less,
            B::LessEqual,
            B::Greater,
            B::GreaterEqual,
            B::And,
            B::ExclusiveOr,
            B::InclusiveOr,
            B::LogicalAnd,
            B::LogicalOr,
            B::ShiftLeft,
            B::ShiftRight,
        ];
        let values = [0u32, 1, 2, 7, 31, 33, 0x8000_0000, 0xffff_ffff, 0x7fff_ffff, 0x3f80_0000, 0x7fc0_0000];
        for op in ops {
            for kind in [ScalarKind::Float, ScalarKind::Sint, ScalarKind::Uint, ScalarKind::Bool] {
                let resolved = BinOp::resolve(op, kind);
                assert_eq!(
                    resolved.is_some(),
                    super::super::arith::binary(op, kind, 0, 0).is_some(),
                    "{op:?} {kind:?}"
                );
                let Some(resolved) = resolved else { continue };
                for &a in &values {
                    for &c in &values {
                        let (got, want) = (resolved.apply(a, c), super::super::arith::binary(op, kind, a, c));
                        // A NaN's payload is not specified (Rust's float semantics; Miri
                        // picks payloads at random): two NaNs agree.
                        let nan = |bits: u32| kind == ScalarKind::Float && f32::from_bits(bits).is_nan();
                        let both_nan = want.is_some_and(|want| nan(want) && nan(got));
                        assert!(Some(got) == want || both_nan, "{op:?} {kind:?} {a:#x} {c:#x}: {got:#x} {want:x?}");
                    }
                }
            }
        }
    }
}
