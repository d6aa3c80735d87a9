//! Values known before a kernel runs: literals and the module's constant expressions
//! (`global_expressions`), laid out in register words.

use super::layout::{element_step, member_step, words_of};
use super::matrix::column_words;
use naga::{Expression, Handle, TypeInner};

/// A literal's words (64-bit integers: low word first).
pub(super) fn literal(value: &naga::Literal) -> Option<Vec<u32>> {
    let wide = |v: u64| vec![v as u32, (v >> 32) as u32];
    Some(match *value {
        naga::Literal::F32(v) => vec![v.to_bits()],
        naga::Literal::U32(v) => vec![v],
        naga::Literal::I32(v) => vec![v as u32],
        naga::Literal::Bool(v) => vec![u32::from(v)],
        naga::Literal::U64(v) => wide(v),
        naga::Literal::I64(v) => wide(v as u64),
        naga::Literal::F16(v) => vec![v.to_f32().to_bits()],
        _ => return None,
    })
}

/// Value of a constant expression of the module (`global_expressions`).
pub(super) fn global_value(
    module: &naga::Module,
    values: &[Vec<u32>],
    handle: Handle<Expression>,
) -> Result<Vec<u32>, String> {
    let inner_of = |ty: Handle<naga::Type>| &module.types[ty].inner;
    Ok(match &module.global_expressions[handle] {
        Expression::Literal(value) => literal(value).ok_or_else(|| format!("literal {value:?}"))?,
        Expression::Constant(c) => values[module.constants[*c].init.index()].clone(),
        Expression::ZeroValue(ty) => vec![0; words_of(module, inner_of(*ty))? as usize],
        Expression::Splat { size, value } => values[value.index()].repeat(*size as usize),
        Expression::Compose { ty, components } => {
            let parts: Vec<&[u32]> = components.iter().map(|c| values[c.index()].as_slice()).collect();
            compose(module, inner_of(*ty), &parts)?
        }
        other => return Err(format!("constant expression {other:?}")),
    })
}

/// Word offset of each part of a value of type `inner` composed of parts of `lens` words.
pub(super) fn compose_offsets(module: &naga::Module, inner: &TypeInner, lens: &[u32]) -> Result<Vec<u32>, String> {
    Ok(match *inner {
        TypeInner::Vector { .. } => lens.iter().scan(0, |at, len| Some(std::mem::replace(at, *at + len))).collect(),
        TypeInner::Struct { .. } => (0..lens.len() as u32).map(|i| member_step(module, inner, i, false)).collect(),
        TypeInner::Array { base, stride, .. } => {
            let step = element_step(module, base, stride, false);
            (0..lens.len() as u32).map(|i| i * step).collect()
        }
        TypeInner::Matrix { rows, .. } => (0..lens.len()).map(|i| (i * column_words(rows)) as u32).collect(),
        _ => return Err(format!("composing {inner:?}")),
    })
}

/// Lays out `parts` as a value of type `inner`.
pub(super) fn compose(module: &naga::Module, inner: &TypeInner, parts: &[&[u32]]) -> Result<Vec<u32>, String> {
    let mut out = vec![0u32; words_of(module, inner)? as usize];
    let lens: Vec<u32> = parts.iter().map(|p| p.len() as u32).collect();
    let offsets = compose_offsets(module, inner, &lens)?;
    for (part, at) in parts.iter().zip(offsets) {
        let at = at as usize;
        let len = part.len().min(out.len().saturating_sub(at));
        out[at..at + len].copy_from_slice(&part[..len]);
    }
    Ok(out)
}
