//! Evaluating one naga expression into its register slot.

use super::arith;
use super::error::unsupported;
use super::exec::{Exec, Frame, Invocation};
use crate::error::BackendError;
use naga::{Expression, Handle, ScalarKind, TypeInner};
use smallvec::{SmallVec, smallvec};

/// A value: its words, inline up to a vec4.
pub(super) type Words = SmallVec<[u32; 4]>;

/// Scalar kind and component count of a scalar or vector type.
pub(super) fn shape(inner: &TypeInner) -> Option<(ScalarKind, usize)> {
    match *inner {
        TypeInner::Scalar(s) | TypeInner::Atomic(s) => Some((s.kind, 1)),
        TypeInner::Vector { size, scalar } => Some((scalar.kind, size as usize)),
        _ => None,
    }
}

fn literal(value: &naga::Literal) -> Option<u32> {
    Some(match *value {
        naga::Literal::F32(v) => v.to_bits(),
        naga::Literal::U32(v) => v,
        naga::Literal::I32(v) => v as u32,
        naga::Literal::Bool(v) => u32::from(v),
        _ => return None,
    })
}

use super::matrix::column_words;

/// Value of a constant expression of the module (`global_expressions`).
pub(super) fn global_value(
    module: &naga::Module,
    values: &[Vec<u32>],
    handle: Handle<Expression>,
) -> Result<Vec<u32>, String> {
    let inner_of = |ty: Handle<naga::Type>| &module.types[ty].inner;
    Ok(match &module.global_expressions[handle] {
        Expression::Literal(value) => vec![literal(value).ok_or_else(|| format!("literal {value:?}"))?],
        Expression::Constant(c) => values[module.constants[*c].init.index()].clone(),
        Expression::ZeroValue(ty) => vec![0; super::program::words_of(module, inner_of(*ty))? as usize],
        Expression::Splat { size, value } => values[value.index()].repeat(*size as usize),
        Expression::Compose { ty, components } => {
            let parts: Vec<&[u32]> = components.iter().map(|c| values[c.index()].as_slice()).collect();
            compose(module, inner_of(*ty), &parts)?
        }
        other => return Err(format!("constant expression {other:?}")),
    })
}

/// Lays out `parts` as a value of type `inner`.
pub(super) fn compose(module: &naga::Module, inner: &TypeInner, parts: &[&[u32]]) -> Result<Vec<u32>, String> {
    let mut out = vec![0u32; super::program::words_of(module, inner)? as usize];
    match *inner {
        TypeInner::Vector { .. } => {
            let flat: Vec<u32> = parts.iter().flat_map(|p| p.iter().copied()).collect();
            let len = out.len();
            out.copy_from_slice(&flat[..len]);
        }
        TypeInner::Struct { ref members, .. } => {
            for (member, part) in members.iter().zip(parts) {
                let at = member.offset as usize / 4;
                out[at..at + part.len()].copy_from_slice(part);
            }
        }
        TypeInner::Array { stride, .. } => {
            for (i, part) in parts.iter().enumerate() {
                let at = i * stride as usize / 4;
                out[at..at + part.len()].copy_from_slice(part);
            }
        }
        TypeInner::Matrix { rows, .. } => {
            for (i, part) in parts.iter().enumerate() {
                let at = i * column_words(rows);
                out[at..at + part.len()].copy_from_slice(part);
            }
        }
        _ => return Err(format!("composing {inner:?}")),
    }
    Ok(out)
}

impl Exec<'_> {
    /// The value of expression `handle` of `frame`'s function.
    pub(super) fn eval(
        &self,
        invocation: &Invocation,
        frame: &Frame,
        handle: Handle<Expression>,
    ) -> Result<Words, BackendError> {
        let program = self.program;
        let function = program.function(frame.function);
        let expressions = &program.naga_function(frame.function).expressions;
        let module = &program.module;
        let line = || function.line_of_expression(handle);
        let reg = |h: Handle<Expression>| -> &[u32] {
            let slot = function.slots[h.index()];
            &frame.regs[slot.offset as usize..(slot.offset + slot.len) as usize]
        };
        let ty = |h: Handle<Expression>| &function.types[h.index()];
        let result_len = function.slots[handle.index()].len as usize;
        let fail = |what: String| unsupported(&what, line());
        Ok(match &expressions[handle] {
            Expression::Literal(value) => smallvec![literal(value).ok_or_else(|| fail(format!("literal {value:?}")))?],
            Expression::Constant(c) => {
                program.global_values[module.constants[*c].init.index()].iter().copied().collect()
            }
            Expression::ZeroValue(_) => smallvec![0; result_len],
            Expression::Compose { components, .. } => {
                let parts: Vec<&[u32]> = components.iter().map(|c| reg(*c)).collect();
                compose(module, ty(handle), &parts).map_err(fail)?.into()
            }
            Expression::Splat { size, value } => reg(*value).repeat(*size as usize).into(),
            Expression::Swizzle { size, vector, pattern } => {
                let v = reg(*vector);
                pattern[..*size as usize].iter().map(|c| v[*c as usize]).collect()
            }
            Expression::Access { base, index } => {
                let index = reg(*index)[0];
                self.access(invocation, function, frame, *base, index, true, result_len).map_err(fail)?
            }
            Expression::AccessIndex { base, index } => {
                self.access(invocation, function, frame, *base, *index, false, result_len).map_err(fail)?
            }
            Expression::Load { pointer } => {
                let p = reg(*pointer);
                self.read(invocation, (p[0], p[1]), result_len)
            }
            Expression::Unary { op, expr } => {
                let (kind, _) = shape(ty(*expr)).ok_or_else(|| fail("unary operator on a composite".into()))?;
                reg(*expr)
                    .iter()
                    .map(|&x| match (op, kind) {
                        (naga::UnaryOperator::Negate, ScalarKind::Float) => x ^ 0x8000_0000,
                        (naga::UnaryOperator::Negate, _) => (x as i32).wrapping_neg() as u32,
                        (naga::UnaryOperator::LogicalNot, _) => u32::from(x == 0),
                        (naga::UnaryOperator::BitwiseNot, _) => !x,
                    })
                    .collect()
            }
            Expression::Binary { op, left, right }
                if matches!(ty(*left), TypeInner::Matrix { .. }) || matches!(ty(*right), TypeInner::Matrix { .. }) =>
            {
                super::matrix::binary(*op, ty(*left), reg(*left), ty(*right), reg(*right))
                    .ok_or_else(|| fail(format!("{op:?} on matrices")))?
                    .into()
            }
            Expression::Binary { op, left, right } => {
                let (kind, _) = shape(ty(*left)).ok_or_else(|| fail(format!("{op:?} on composites")))?;
                let (a, b) = (reg(*left), reg(*right));
                let n = a.len().max(b.len());
                (0..n)
                    .map(|i| {
                        let x = a[if a.len() == 1 { 0 } else { i }];
                        let y = b[if b.len() == 1 { 0 } else { i }];
                        arith::binary(*op, kind, x, y).ok_or_else(|| fail(format!("{op:?} on {kind:?}")))
                    })
                    .collect::<Result<_, _>>()?
            }
            Expression::Select { condition, accept, reject } => {
                let (c, a, r) = (reg(*condition), reg(*accept), reg(*reject));
                (0..a.len()).map(|i| if c[if c.len() == 1 { 0 } else { i }] != 0 { a[i] } else { r[i] }).collect()
            }
            Expression::Relational { fun, argument } => {
                let v = reg(*argument);
                match fun {
                    naga::RelationalFunction::All => smallvec![u32::from(v.iter().all(|&x| x != 0))],
                    naga::RelationalFunction::Any => smallvec![u32::from(v.iter().any(|&x| x != 0))],
                    naga::RelationalFunction::IsNan => {
                        v.iter().map(|&x| u32::from(f32::from_bits(x).is_nan())).collect()
                    }
                    naga::RelationalFunction::IsInf => {
                        v.iter().map(|&x| u32::from(f32::from_bits(x).is_infinite())).collect()
                    }
                }
            }
            Expression::Math { fun: naga::MathFunction::Transpose, arg, .. } => match ty(*arg) {
                TypeInner::Matrix { columns, rows, .. } => super::matrix::transpose(reg(*arg), *columns, *rows).into(),
                other => return Err(fail(format!("transpose of {other:?}"))),
            },
            Expression::Math { fun: naga::MathFunction::Determinant, arg, .. } => match ty(*arg) {
                TypeInner::Matrix { columns, .. } => smallvec![super::matrix::determinant(reg(*arg), *columns)],
                other => return Err(fail(format!("determinant of {other:?}"))),
            },
            Expression::Math { fun, arg, .. } if arith::pack(*fun, &[0; 4]).is_some() => {
                smallvec![arith::pack(*fun, reg(*arg)).ok_or_else(|| fail(format!("{fun:?}")))?]
            }
            Expression::Math { fun, arg, .. } if arith::unpack(*fun, 0).is_some() => {
                arith::unpack(*fun, reg(*arg)[0]).ok_or_else(|| fail(format!("{fun:?}")))?.into()
            }
            Expression::Math { fun, arg, arg1, arg2, arg3 } => {
                let (kind, comps) = shape(ty(*arg)).ok_or_else(|| fail(format!("{fun:?} on a composite")))?;
                self.math(*fun, kind, comps, reg(*arg), arg1.map(reg), arg2.map(reg), arg3.map(reg))
                    .ok_or_else(|| fail(format!("math function {fun:?} on {kind:?}")))?
            }
            Expression::As { expr, kind, convert } => {
                let (from, _) = shape(ty(*expr)).ok_or_else(|| fail("conversion of a composite".into()))?;
                match convert {
                    None => reg(*expr).iter().copied().collect(),
                    Some(4) | Some(1) => reg(*expr)
                        .iter()
                        .map(|&x| arith::convert(x, from, *kind).ok_or_else(|| fail(format!("{from:?} as {kind:?}"))))
                        .collect::<Result<_, _>>()?,
                    Some(width) => return Err(fail(format!("conversion to {}-bit", width * 8))),
                }
            }
            Expression::ArrayLength(pointer) => {
                let p = reg(*pointer);
                let stride = match ty(*pointer) {
                    TypeInner::Pointer { base, .. } => match module.types[*base].inner {
                        TypeInner::Array { stride, .. } => stride / 4,
                        _ => return Err(fail("arrayLength of a non-array".into())),
                    },
                    _ => return Err(fail("arrayLength of a non-pointer".into())),
                };
                let words = self.memory_words(invocation, p[0]);
                smallvec![(words.saturating_sub(p[1] as usize) / stride.max(1) as usize) as u32]
            }
            // Written by their statements (Call, Atomic, WorkGroupUniformLoad, subgroup ops).
            Expression::CallResult(_)
            | Expression::AtomicResult { .. }
            | Expression::WorkGroupUniformLoadResult { .. }
            | Expression::SubgroupOperationResult { .. } => reg(handle).iter().copied().collect(),
            other => {
                let name = format!("{other:?}");
                let name = name.split([' ', '(', '{']).next().unwrap_or("expression").to_string();
                return Err(fail(format!("expression `{name}`")));
            }
        })
    }

    /// `base[index]`: pointer arithmetic when `base` is a pointer, extraction otherwise.
    /// Dynamic indices are clamped into range (naga's `Restrict` bounds-check policy).
    #[allow(clippy::too_many_arguments)]
    fn access(
        &self,
        invocation: &Invocation,
        function: &super::program::CompiledFunction,
        frame: &Frame,
        base: Handle<Expression>,
        index: u32,
        dynamic: bool,
        result_len: usize,
    ) -> Result<Words, String> {
        let module = &self.program.module;
        let slot = function.slots[base.index()];
        let value = &frame.regs[slot.offset as usize..(slot.offset + slot.len) as usize];
        let clamp = |len: usize| if dynamic { (index as usize).min(len.saturating_sub(1)) } else { index as usize };
        match &function.types[base.index()] {
            TypeInner::Pointer { base: pointee, .. } => {
                let (tag, offset) = (value[0], value[1] as usize);
                let step = match module.types[*pointee].inner {
                    TypeInner::Array { size, stride, .. } => {
                        let stride = stride as usize / 4;
                        let len = match size {
                            naga::ArraySize::Constant(n) => n.get() as usize,
                            _ => (self.memory_words(invocation, tag).saturating_sub(offset) / stride.max(1)).max(1),
                        };
                        clamp(len) * stride
                    }
                    TypeInner::Struct { ref members, .. } => members[index as usize].offset as usize / 4,
                    TypeInner::Vector { size, .. } => clamp(size as usize),
                    TypeInner::Matrix { columns, rows, .. } => clamp(columns as usize) * column_words(rows),
                    ref other => return Err(format!("indexing through a pointer to {other:?}")),
                };
                Ok(smallvec![tag, (offset + step) as u32])
            }
            TypeInner::ValuePointer { size: Some(size), .. } => {
                Ok(smallvec![value[0], value[1] + clamp(*size as usize) as u32])
            }
            TypeInner::Vector { size, .. } => Ok(smallvec![value[clamp(*size as usize)]]),
            TypeInner::Array { size, stride, .. } => {
                let len = match size {
                    naga::ArraySize::Constant(n) => n.get() as usize,
                    _ => return Err("indexing a runtime-sized array value".into()),
                };
                let at = clamp(len) * *stride as usize / 4;
                Ok(value[at..at + result_len].iter().copied().collect())
            }
            TypeInner::Struct { members, .. } => {
                let at = members[index as usize].offset as usize / 4;
                Ok(value[at..at + result_len].iter().copied().collect())
            }
            TypeInner::Matrix { columns, rows, .. } => {
                let at = clamp(*columns as usize) * column_words(*rows);
                Ok(value[at..at + result_len].iter().copied().collect())
            }
            other => Err(format!("indexing {other:?}")),
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn math(
        &self,
        fun: naga::MathFunction,
        kind: ScalarKind,
        comps: usize,
        a: &[u32],
        b: Option<&[u32]>,
        c: Option<&[u32]>,
        d: Option<&[u32]>,
    ) -> Option<Words> {
        use naga::MathFunction as M;
        let f = f32::from_bits;
        let pick = |v: Option<&[u32]>, i: usize| v.map_or(0, |v| v[if v.len() == 1 { 0 } else { i }]);
        match fun {
            M::Dot if kind == ScalarKind::Float => {
                let b = b?;
                // Sequential sum of products, no fused multiply-add.
                let sum = (0..comps).fold(0.0f32, |acc, i| acc + f(a[i]) * f(b[i]));
                Some(smallvec![sum.to_bits()])
            }
            M::Dot => {
                let b = b?;
                Some(smallvec![(0..comps).fold(0u32, |acc, i| acc.wrapping_add(a[i].wrapping_mul(b[i])))])
            }
            M::Length => Some(smallvec![(0..comps).fold(0.0f32, |acc, i| acc + f(a[i]) * f(a[i])).sqrt().to_bits()]),
            M::Distance => {
                let b = b?;
                let sum = (0..comps).fold(0.0f32, |acc, i| {
                    let d = f(a[i]) - f(b[i]);
                    acc + d * d
                });
                Some(smallvec![sum.sqrt().to_bits()])
            }
            M::Normalize => {
                let length = (0..comps).fold(0.0f32, |acc, i| acc + f(a[i]) * f(a[i])).sqrt();
                Some(a.iter().map(|&x| (f(x) / length).to_bits()).collect())
            }
            M::Cross => {
                let b = b?;
                let (x, y) = (|i: usize| f(a[i]), |i: usize| f(b[i]));
                Some(smallvec![
                    (x(1) * y(2) - x(2) * y(1)).to_bits(),
                    (x(2) * y(0) - x(0) * y(2)).to_bits(),
                    (x(0) * y(1) - x(1) * y(0)).to_bits(),
                ])
            }
            M::ExtractBits | M::InsertBits => {
                (0..comps).map(|i| arith::bits(fun, kind, a[i], pick(b, i), pick(c, i), pick(d, i))).collect()
            }
            _ => (0..comps).map(|i| arith::math(fun, kind, a[i], pick(b, i), pick(c, i))).collect(),
        }
    }
}
