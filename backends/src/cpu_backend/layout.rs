//! Where values live: the words a naga type takes in registers, the byte and word steps
//! of fields, elements and components in each address space, how f16 values move
//! between buffers and registers, and what a pointer points at when that is known at
//! compile time. Shared by the compiler ([`super::compiler`], [`super::expression`]), its
//! analyses ([`super::load_alias`], [`super::load_fields`]), the instructions
//! ([`super::insn`]) and memory access ([`super::memory`]), and dependent on none of them.
//!
//! Sizes and offsets here come from the kernel's types: no arithmetic may wrap or panic
//! (the lint below). A size that does not fit in `u32` words is an error; offsets inside
//! a value naga validated (whose bytes fit in `u32`) saturate, which never happens for
//! such a value and would read as out of bounds if it did.

#![deny(clippy::arithmetic_side_effects)]

use super::wide;
use naga::{Handle, Module, ScalarKind, TypeInner};
use smallvec::SmallVec;

/// Word offset of a value in the frame's register file.
pub(super) type Reg = u32;

/// The element count of an array of size `size`: `Some(n)` for a fixed count, `None`
/// for a runtime-sized array. An array sized by an override expression
/// (`array<u32, WG * 2u>`) stays `Pending` in naga's type arena after the overrides are
/// applied (`process_overrides` evaluates each override's initialiser, not the types),
/// so its count is resolved here from the override's value, as naga's own back ends do;
/// an override without a value is an error naming it, never an array of no elements.
pub(super) fn array_length(module: &Module, size: naga::ArraySize) -> Result<Option<u32>, String> {
    match size.resolve(module.to_ctx()) {
        Ok(naga::proc::IndexableLength::Known(n)) => Ok(Some(n)),
        Ok(naga::proc::IndexableLength::Dynamic) => Ok(None),
        Err(error) => {
            let name = match size {
                naga::ArraySize::Pending(handle) => module.overrides[handle]
                    .name
                    .clone()
                    .map_or_else(|| "an override expression".into(), |n| format!("override `{n}`")),
                _ => "its size".into(),
            };
            Err(format!("an array sized by {name} whose value is not known ({error})"))
        }
    }
}

/// Bits of a scalar of `scalar`, for messages.
fn bits(scalar: naga::Scalar) -> u32 {
    u32::from(scalar.width).saturating_mul(8)
}

/// `a * b` words, or the error of a type of more than `u32::MAX` words.
fn product(a: u32, b: u32) -> Result<u32, String> {
    a.checked_mul(b).ok_or_else(|| format!("a type of more than {} words ({a} × {b})", u32::MAX))
}

/// Words of a value of type `inner` (bool and every 32-bit scalar: one word; 64-bit
/// integers: two, the low word first); an error for a type of more than `u32::MAX`
/// words.
pub(super) fn words_of(module: &Module, inner: &TypeInner) -> Result<u32, String> {
    Ok(match *inner {
        TypeInner::Atomic(s) if s.width != 4 => return Err(format!("{}-bit atomics", bits(s))),
        TypeInner::Scalar(s) | TypeInner::Atomic(s) => {
            scalar_words(s).ok_or_else(|| format!("{}-bit scalars", bits(s)))?
        }
        TypeInner::Vector { size, scalar } => {
            product(size as u32, scalar_words(scalar).ok_or_else(|| format!("{}-bit vectors", bits(scalar)))?)?
        }
        // Textures and samplers are held like pointers: their binding slot and 0.
        TypeInner::Pointer { .. }
        | TypeInner::ValuePointer { .. }
        | TypeInner::Image { .. }
        | TypeInner::Sampler { .. } => 2,
        TypeInner::Matrix { scalar, .. } if scalar.width == 2 => return Err("f16 matrices".into()),
        TypeInner::Matrix { columns, rows, .. } => {
            // Columns are padded like vec3 → 4 words in memory.
            let row_words = if rows == naga::VectorSize::Tri { 4 } else { rows as u32 };
            product(columns as u32, row_words)?
        }
        // Register layout of composites holding f16 or bool: a word per f16 or bool,
        // members and elements one after the other (naga's layout, 2 bytes per f16 and
        // 1 per bool, is used in buffers only, where bools never are).
        TypeInner::Array { base, size, .. } if own_register_layout(module, &module.types[base].inner) => {
            match array_length(module, size)? {
                Some(n) => product(n, words_of(module, &module.types[base].inner)?)?,
                None => return Err("runtime-sized arrays as values".into()),
            }
        }
        TypeInner::Struct { ref members, .. } if own_register_layout(module, inner) => {
            let mut words = 0u32;
            for member in members {
                let member = words_of(module, &module.types[member.ty].inner)?;
                words = words.checked_add(member).ok_or_else(|| format!("a struct of more than {} words", u32::MAX))?;
            }
            words
        }
        TypeInner::Array { base, size, stride } => {
            // The element type must be supported too.
            words_of(module, &module.types[base].inner)?;
            match array_length(module, size)? {
                // In u64: n * stride may pass u32::MAX bytes while its words fit.
                Some(n) => u32::try_from(u64::from(n).saturating_mul(u64::from(stride)) / 4)
                    .map_err(|_| format!("an array of more than {} words ({n} × {stride} bytes)", u32::MAX))?,
                None => return Err("runtime-sized arrays as values".into()),
            }
        }
        TypeInner::Struct { span, .. } => span / 4,
        _ => return Err(format!("type {inner:?}")),
    })
}

/// Words of one scalar: 1 for bool and 32-bit scalars, 2 for 64-bit integers; `None`
/// for scalars the interpreter does not support.
///
/// An f16 takes a word of its own in registers, holding the f32 of equal value (every
/// operation producing an f16 rounds to binary16). Registers, function, private and
/// workgroup memory (which only the interpreter sees) use this register layout; bound
/// buffers use naga's (two bytes per f16), and loads and stores of types holding f16
/// convert between the two ([`load_plan`]). Pointers into buffers count bytes,
/// pointers elsewhere count words. f16 matrices are refused.
pub(super) fn scalar_words(scalar: naga::Scalar) -> Option<u32> {
    match (scalar.kind, scalar.width) {
        (naga::ScalarKind::Bool, _) | (_, 4) | (naga::ScalarKind::Float, 2) => Some(1),
        (naga::ScalarKind::Sint | naga::ScalarKind::Uint, 8) => Some(2),
        _ => None,
    }
}

/// Whether pointers into `space` count bytes (bound buffers, laid out as naga says)
/// rather than register words.
pub(super) fn byte_addressed(space: naga::AddressSpace) -> bool {
    matches!(space, naga::AddressSpace::Uniform | naga::AddressSpace::Storage { .. })
}

/// Offset of member `index` of struct `inner`: bytes (`bytes`), else register words.
pub(super) fn member_step(module: &Module, inner: &TypeInner, index: u32, bytes: bool) -> u32 {
    let TypeInner::Struct { ref members, .. } = *inner else { return 0 };
    if bytes {
        members[index as usize].offset
    } else if !own_register_layout(module, inner) {
        members[index as usize].offset / 4
    } else {
        members[..index as usize].iter().map(|m| words_of(module, &module.types[m.ty].inner).unwrap_or(0)).sum()
    }
}

/// Distance between elements of an array of `base` with naga stride `stride`: bytes
/// (`bytes`), else register words.
pub(super) fn element_step(module: &Module, base: Handle<naga::Type>, stride: u32, bytes: bool) -> u32 {
    let inner = &module.types[base].inner;
    if bytes {
        stride
    } else if !own_register_layout(module, inner) {
        stride / 4
    } else {
        words_of(module, inner).unwrap_or(0)
    }
}

/// Distance between components of a vector of `scalar`: bytes (`bytes`), else words.
pub(super) fn component_step(scalar: naga::Scalar, bytes: bool) -> u32 {
    match (bytes, scalar.width) {
        (true, 1) => 4, // bool
        (true, width) => u32::from(width),
        (false, 8) if scalar.kind != naga::ScalarKind::Float => 2,
        (false, _) => 1,
    }
}

/// One piece of a load or store between a buffer (naga's layout) and registers.
#[derive(Clone, Copy, Debug)]
pub(super) enum Piece {
    /// `len` words at byte offset `memory` ↔ register word `reg`.
    Words { memory: u32, reg: u32, len: u32 },
    /// The binary16 at byte offset `memory` ↔ the f32 at register word `reg`.
    Half { memory: u32, reg: u32 },
}

/// How a value of type `inner` holding f16 moves between a buffer at byte `memory` and
/// registers at word `reg`.
pub(super) fn load_plan(module: &Module, inner: &TypeInner, memory: u32, reg: u32, out: &mut Vec<Piece>) {
    if !contains_f16(module, inner) {
        let len = words_of(module, inner).unwrap_or(0);
        match out.last_mut() {
            Some(Piece::Words { memory: m, reg: r, len: l })
                if m.saturating_add(l.saturating_mul(4)) == memory && r.saturating_add(*l) == reg =>
            {
                *l = l.saturating_add(len)
            }
            _ => out.push(Piece::Words { memory, reg, len }),
        }
        return;
    }
    match *inner {
        TypeInner::Scalar(_) => out.push(Piece::Half { memory, reg }),
        TypeInner::Vector { size, .. } => {
            out.extend((0..size as u32).map(|i| Piece::Half {
                memory: memory.saturating_add(i.saturating_mul(2)),
                reg: reg.saturating_add(i),
            }))
        }
        TypeInner::Array { base, size, stride } => {
            // Only values of known size are loaded (words_of refuses the others first).
            let n = array_length(module, size).ok().flatten().unwrap_or(0);
            let words = words_of(module, &module.types[base].inner).unwrap_or(0);
            for i in 0..n {
                let (memory, reg) =
                    (memory.saturating_add(i.saturating_mul(stride)), reg.saturating_add(i.saturating_mul(words)));
                load_plan(module, &module.types[base].inner, memory, reg, out);
            }
        }
        TypeInner::Struct { ref members, .. } => {
            for (i, member) in members.iter().enumerate() {
                let step = member_step(module, inner, i as u32, false);
                let (memory, reg) = (memory.saturating_add(member.offset), reg.saturating_add(step));
                load_plan(module, &module.types[member.ty].inner, memory, reg, out);
            }
        }
        _ => {}
    }
}

/// Whether a value of type `inner` is laid out in registers (and in function, private
/// and workgroup memory) otherwise than naga lays it out: it holds an f16 (a word in
/// registers, 2 bytes in naga's layout) or a bool (a word in registers, 1 byte in
/// naga's: a stride of `/ 4` would put four bools, or all of a struct's, in one word).
/// Such types take [`words_of`]'s member-by-member layout.
pub(super) fn own_register_layout(module: &Module, inner: &TypeInner) -> bool {
    match *inner {
        TypeInner::Scalar(s) | TypeInner::Vector { scalar: s, .. } | TypeInner::Matrix { scalar: s, .. } => {
            s.kind == naga::ScalarKind::Bool || (s.kind == naga::ScalarKind::Float && s.width == 2)
        }
        TypeInner::Array { base, .. } | TypeInner::BindingArray { base, .. } => {
            own_register_layout(module, &module.types[base].inner)
        }
        TypeInner::Struct { ref members, .. } => {
            members.iter().any(|m| own_register_layout(module, &module.types[m.ty].inner))
        }
        _ => false,
    }
}

/// Whether a value of type `inner` holds an f16 anywhere.
pub(super) fn contains_f16(module: &Module, inner: &TypeInner) -> bool {
    match *inner {
        TypeInner::Scalar(s) | TypeInner::Vector { scalar: s, .. } | TypeInner::Matrix { scalar: s, .. } => {
            s.kind == naga::ScalarKind::Float && s.width == 2
        }
        TypeInner::Array { base, .. } | TypeInner::BindingArray { base, .. } => {
            contains_f16(module, &module.types[base].inner)
        }
        TypeInner::Struct { ref members, .. } => {
            members.iter().any(|m| contains_f16(module, &module.types[m.ty].inner))
        }
        _ => false,
    }
}

/// Where a pointer points, when that is known at compile time.
#[derive(Clone, Copy, Debug)]
pub(super) enum Place {
    /// A local variable: its register in the running frame.
    Local(Reg),
    /// Workgroup memory at this word.
    Workgroup(u32),
    /// Private memory at this word.
    Private(u32),
    /// Bound buffer (slot, byte).
    Buffer(u32, u32),
}

impl Place {
    /// The place `step` words or bytes further (saturating: see the module's note).
    pub(super) fn offset(self, step: u32) -> Self {
        match self {
            Place::Local(r) => Place::Local(r.saturating_add(step)),
            Place::Workgroup(a) => Place::Workgroup(a.saturating_add(step)),
            Place::Private(a) => Place::Private(a.saturating_add(step)),
            Place::Buffer(b, a) => Place::Buffer(b, a.saturating_add(step)),
        }
    }
}

/// Scalar kind and component count of a scalar or vector type.
pub(super) fn shape(inner: &TypeInner) -> Option<(ScalarKind, usize)> {
    match *inner {
        TypeInner::Scalar(s) | TypeInner::Atomic(s) => Some((s.kind, 1)),
        TypeInner::Vector { size, scalar } => Some((scalar.kind, size as usize)),
        _ => None,
    }
}

/// Scalar and component count of a scalar or vector type.
pub(super) fn scalar_shape(inner: &TypeInner) -> Option<(naga::Scalar, usize)> {
    match *inner {
        TypeInner::Scalar(s) | TypeInner::Atomic(s) => Some((s, 1)),
        TypeInner::Vector { size, scalar } => Some((scalar, size as usize)),
        _ => None,
    }
}

/// Whether `inner` is a 64-bit integer scalar or vector.
pub(super) fn is_wide(inner: &TypeInner) -> bool {
    scalar_shape(inner).is_some_and(|(s, _)| wide::is_wide(s))
}

/// Whether `inner` is an f16 scalar or vector.
pub(super) fn is_half(inner: &TypeInner) -> bool {
    scalar_shape(inner).is_some_and(|(s, _)| s.kind == ScalarKind::Float && s.width == 2)
}

/// Words per component of a vector (or of a pointer to one) of scalar `scalar`.
pub(super) fn component_words(scalar: naga::Scalar) -> u32 {
    if wide::is_wide(scalar) { 2 } else { 1 }
}

/// A value: its words, inline up to a vec4.
pub(super) type Words = SmallVec<[u32; 4]>;

/// The first component of a swizzle whose components are consecutive (`.xyz`, `.zw`),
/// which reads the vector's registers from there on; `None` for any other pattern. (The
/// expression compiler gives such a swizzle the vector's registers, and the analysis of
/// loads read in place, [`super::load_alias`], follows the registers through it.)
pub(super) fn consecutive(size: naga::VectorSize, pattern: &[naga::SwizzleComponent; 4]) -> Option<u32> {
    let first = pattern[0] as u32;
    (0..size as u32).all(|i| pattern[i as usize] as u32 == first.saturating_add(i)).then_some(first)
}
