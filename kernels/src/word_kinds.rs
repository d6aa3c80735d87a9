//! What each 32-bit word of a buffer holds (an f32, an integer, or padding), read from
//! naga's IR, so that tools comparing a kernel's outputs across backends can hold
//! integers to bit-exact agreement, f32 values to a ULP bound, and ignore padding whose
//! contents no language defines.

use naga::proc::Layouter;

/// The kind of one 32-bit word of a buffer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WordKind {
    /// An `f32` (alone, or a component of a vector or matrix).
    Float,
    /// Anything compared bit for bit: `u32`, `i32`, `bool`, atomics, and the words of
    /// 64-bit and 16-bit scalars (two `f16` share a word, so neither can be bounded in
    /// f32 ULPs).
    Integer,
    /// Two IEEE binary16 values a device rounded from f32 (an `rgba16float` texel's
    /// components as a store writes them): Vulkan leaves the rounding of a float
    /// conversion to the implementation, so each half may be either representable
    /// neighbour of the exact value; compared within one f16 ULP each.
    HalfPair,
    /// Four 8-bit unsigned normalised values (an `rgba8unorm` texel): compared as steps
    /// of 1/255, each byte within the float bound's ULP count (a filtered or blended
    /// value a device rounds one step the other way is a step, not a wrong bit).
    Unorm8x4,
    /// Bytes no member covers (struct and array padding): backends may leave anything.
    Padding,
}

/// The kinds of a buffer's words: a fixed head, then (for a runtime-sized array, at the
/// top level or as a struct's last member) its element's kinds repeated.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct WordKinds {
    /// The words of the fixed-size part.
    pub head: Vec<WordKind>,
    /// The words of one runtime-array element (its stride); empty without one.
    pub tail: Vec<WordKind>,
}

impl WordKinds {
    /// The kind of word `index`; words past a fixed-size buffer are padding.
    pub fn of(&self, index: usize) -> WordKind {
        if index < self.head.len() {
            self.head[index]
        } else if self.tail.is_empty() {
            WordKind::Padding
        } else {
            self.tail[(index - self.head.len()) % self.tail.len()]
        }
    }

    /// Whether any word is an f32.
    pub fn has_floats(&self) -> bool {
        self.head.iter().chain(&self.tail).any(|&kind| kind == WordKind::Float)
    }

    /// The kinds of the words of a texture of `format`, texel after texel: f32 words
    /// for the 32-bit float formats, f16 pairs for `rgba16float`, unorm steps for
    /// `rgba8unorm`, bit-exact integers for the others.
    pub fn of_texels(format: crate::texture::TexelFormat) -> WordKinds {
        use crate::texture::TexelFormat as F;
        let kind = match format {
            F::Rgba32Float | F::R32Float => WordKind::Float,
            F::Rgba16Float => WordKind::HalfPair,
            F::Rgba8Unorm => WordKind::Unorm8x4,
            _ => WordKind::Integer,
        };
        WordKinds { head: Vec::new(), tail: vec![kind; format.bytes_per_texel() as usize / 4] }
    }

    /// The kinds of a buffer of type `ty`.
    pub fn of_type(module: &naga::Module, layouter: &Layouter, ty: naga::Handle<naga::Type>) -> WordKinds {
        let mut kinds = WordKinds::default();
        let size = layouter[ty].size as usize;
        kinds.head = vec![WordKind::Padding; size.div_ceil(4)];
        if let Some((offset, element)) = fill(module, layouter, ty, 0, &mut kinds.head) {
            kinds.head.truncate(offset / 4);
            let stride = layouter[element].size.max(1) as usize;
            let mut tail = vec![WordKind::Padding; stride.div_ceil(4)];
            fill(module, layouter, element, 0, &mut tail);
            // The element's stride may exceed its size (an array<vec3<f32>> has stride 16).
            if let naga::TypeInner::Array { stride, .. } = runtime_array_at(module, ty) {
                tail.resize((stride as usize).div_ceil(4), WordKind::Padding);
            }
            kinds.tail = tail;
        }
        kinds
    }
}

/// The runtime-sized array of `ty` (itself, or its last member), as its type.
fn runtime_array_at(module: &naga::Module, ty: naga::Handle<naga::Type>) -> naga::TypeInner {
    match &module.types[ty].inner {
        naga::TypeInner::Struct { members, .. } => match members.last() {
            Some(last) => runtime_array_at(module, last.ty),
            None => module.types[ty].inner.clone(),
        },
        inner => inner.clone(),
    }
}

/// Marks the words of `ty` placed at byte `offset` in `out`; returns the byte offset and
/// element type of a runtime-sized array if `ty` ends in one.
fn fill(
    module: &naga::Module,
    layouter: &Layouter,
    ty: naga::Handle<naga::Type>,
    offset: usize,
    out: &mut Vec<WordKind>,
) -> Option<(usize, naga::Handle<naga::Type>)> {
    let mut mark = |at: usize, bytes: usize, kind: WordKind| {
        for word in at / 4..(at + bytes).div_ceil(4) {
            if word >= out.len() {
                out.resize(word + 1, WordKind::Padding);
            }
            out[word] = kind;
        }
    };
    let scalar_kind = |scalar: naga::Scalar| match (scalar.kind, scalar.width) {
        (naga::ScalarKind::Float, 4) => WordKind::Float,
        _ => WordKind::Integer,
    };
    match &module.types[ty].inner {
        naga::TypeInner::Scalar(scalar) | naga::TypeInner::Atomic(scalar) => {
            mark(offset, usize::from(scalar.width), scalar_kind(*scalar));
        }
        naga::TypeInner::Vector { size, scalar } => {
            let width = usize::from(scalar.width);
            mark(offset, width * *size as usize, scalar_kind(*scalar));
        }
        naga::TypeInner::Matrix { columns, rows, scalar } => {
            let width = usize::from(scalar.width);
            // A column is aligned like a vector of `rows` (vec3 columns take 16 bytes).
            let column_stride = layouter[ty].size as usize / *columns as usize;
            for c in 0..*columns as usize {
                mark(offset + c * column_stride, width * *rows as usize, scalar_kind(*scalar));
            }
        }
        naga::TypeInner::Array { base, size, stride } => match size {
            naga::ArraySize::Constant(n) => {
                for k in 0..n.get() as usize {
                    fill(module, layouter, *base, offset + k * *stride as usize, out);
                }
            }
            _ => return Some((offset, *base)),
        },
        naga::TypeInner::Struct { members, .. } => {
            for member in members {
                if let Some(runtime) = fill(module, layouter, member.ty, offset + member.offset as usize, out) {
                    return Some(runtime);
                }
            }
        }
        // Nothing else can be in a buffer; compare it bit for bit.
        _ => mark(offset, layouter[ty].size as usize, WordKind::Integer),
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kinds(source: &str) -> WordKinds {
        let module = naga::front::wgsl::parse_str(source).unwrap();
        let mut layouter = Layouter::default();
        layouter.update(module.to_ctx()).unwrap();
        let (_, var) = module.global_variables.iter().next().unwrap();
        WordKinds::of_type(&module, &layouter, var.ty)
    }

    use WordKind::{Float as F, Integer as I, Padding as P};

    #[test]
    fn a_struct_of_seven_floats_is_followed_by_padding() {
        let k = kinds(
            "struct S { a: f32, b: f32, c: f32, d: f32, e: f32, f: f32, g: f32 }
             @group(0) @binding(0) var<uniform> s: S;",
        );
        // Seven floats (28 bytes); the rest of a 32-byte uniform buffer is padding.
        assert_eq!(k.head, vec![F; 7]);
        assert!(k.tail.is_empty());
        assert_eq!((k.of(6), k.of(7)), (F, P));
    }

    #[test]
    fn runtime_arrays_repeat_their_element_after_the_head() {
        let k = kinds(
            "struct E { id: u32, p: vec3<f32> }
             struct B { count: u32, flags: vec2<u32>, items: array<E> }
             @group(0) @binding(0) var<storage, read_write> b: B;",
        );
        // count, padding (vec2 aligns to 8), flags; E is { id, pad ×3, p.xyz, pad }.
        assert_eq!(k.head, vec![I, P, I, I]);
        assert_eq!(k.tail, vec![I, P, P, P, F, F, F, P]);
        assert_eq!(k.of(4), I);
        assert_eq!(k.of(4 + 8 + 5), F);
        let plain = kinds("@group(0) @binding(0) var<storage, read> v: array<vec3<f32>>;");
        assert_eq!((plain.head.len(), plain.tail.clone()), (0, vec![F, F, F, P]));
    }

    #[test]
    fn atomics_matrices_and_wide_scalars() {
        let k = kinds(
            "enable f16;
             struct S { n: atomic<u32>, m: mat3x3<f32>, h: vec2<f16> }
             @group(0) @binding(0) var<storage, read_write> s: S;",
        );
        assert_eq!(k.of(0), I);
        // mat3x3 at offset 16: three vec3 columns of 16 bytes.
        assert_eq!(&k.head[4..16], &[F, F, F, P, F, F, F, P, F, F, F, P]);
        assert_eq!(k.of(16), I);
    }
}
