//! Lowering one naga expression to bytecode: its operands' registers resolved, its
//! types looked at once here and never again at run time. Field and component
//! extraction with a constant index, and bitcasts, cost no instruction: the result is
//! the source's register range. Constructs the interpreter does not support lower to a
//! [`Insn::Fail`] naming the construct and its line, reported only if reached.

use super::arith;
use super::constant::{compose_offsets, literal};
use super::decode::{Compiler, Scope};
use super::insn::{BinOp, Insn, Reg, UnOp};
use super::layout::{
    Place, byte_addressed, component_step, component_words, element_step, is_half, is_wide, member_step, scalar_shape,
    shape,
};
use super::matrix::column_words;
use super::wide;
use crate::error::BackendError;
use naga::{Expression, Handle, ScalarKind, TypeInner};
use smallvec::{SmallVec, smallvec};

/// A value: its words, inline up to a vec4.
pub(super) type Words = SmallVec<[u32; 4]>;

/// The f32 dot product of two vectors of f32 words: a sequential sum of products, no fused
/// multiply-add, starting from the first product rather than +0 so that products that are
/// all -0 sum to -0.
fn dot(a: &[u32], b: &[u32]) -> f32 {
    let f = f32::from_bits;
    (1..a.len()).fold(f(a[0]) * f(b[0]), |acc, i| acc + f(a[i]) * f(b[i]))
}

/// Math functions on vectors and scalars (the reference implementation, value by value).
#[allow(clippy::too_many_arguments)]
fn math(
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
        M::Dot if kind == ScalarKind::Float => Some(smallvec![dot(&a[..comps], &b?[..comps]).to_bits()]),
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
        M::Reflect => {
            // e1 - 2 dot(e2, e1) e2
            let b = b?;
            let d = dot(&b[..comps], &a[..comps]);
            Some((0..comps).map(|i| (f(a[i]) - 2.0 * d * f(b[i])).to_bits()).collect())
        }
        M::Refract => {
            // k = 1 - η² (1 - dot(e2, e1)²); k < 0: the zero vector; else
            // η e1 - (η dot(e2, e1) + sqrt(k)) e2.
            let (b, eta) = (b?, f(c?[0]));
            let d = dot(&b[..comps], &a[..comps]);
            let k = 1.0 - eta * eta * (1.0 - d * d);
            if k < 0.0 {
                return Some((0..comps).map(|_| 0.0f32.to_bits()).collect());
            }
            let scale = eta * d + k.sqrt();
            Some((0..comps).map(|i| (eta * f(a[i]) - scale * f(b[i])).to_bits()).collect())
        }
        M::FaceForward => {
            // e1 if dot(e2, e3) < 0, else -e1.
            let (b, c) = (b?, c?);
            let keep = dot(&b[..comps], &c[..comps]) < 0.0;
            Some(a[..comps].iter().map(|&x| if keep { x } else { (-f(x)).to_bits() }).collect())
        }
        M::Dot4I8Packed | M::Dot4U8Packed => {
            let b = b?;
            let signed = fun == M::Dot4I8Packed;
            let byte = |word: u32, i: u32| {
                let byte = (word >> (8 * i)) & 0xff;
                if signed { byte as u8 as i8 as i32 as u32 } else { byte }
            };
            Some(smallvec![(0..4).fold(0u32, |acc, i| acc.wrapping_add(byte(a[0], i).wrapping_mul(byte(b[0], i))))])
        }
        M::ExtractBits | M::InsertBits => {
            (0..comps).map(|i| arith::bits(fun, kind, a[i], pick(b, i), pick(c, i), pick(d, i))).collect()
        }
        _ => (0..comps).map(|i| arith::math(fun, kind, a[i], pick(b, i), pick(c, i))).collect(),
    }
}

/// Reads `len` words at `reg` of a register file.
fn slice(regs: &[u32], (reg, len): (Reg, u32)) -> &[u32] {
    &regs[reg as usize..(reg + len) as usize]
}

/// Writes `value` at `dst`, at most `len` words.
fn put(regs: &mut [u32], dst: Reg, len: u32, value: &[u32]) {
    let n = (len as usize).min(value.len());
    regs[dst as usize..dst as usize + n].copy_from_slice(&value[..n]);
}

impl Compiler<'_> {
    /// Lowers expression `handle` of `scope`: gives it a register (its own or its
    /// source's) and appends the instructions that compute it.
    pub(super) fn expression(&mut self, scope: &mut Scope, handle: Handle<Expression>) -> Result<(), BackendError> {
        let module = self.module;
        let index = handle.index();
        let line = scope.lines[index];
        self.line = line;
        let len = scope.lens[index];
        let function = scope.function;
        let expression = &function.expressions[handle];
        // Operand registers and words.
        macro_rules! operand {
            ($h:expr) => {{
                let h = $h;
                (self.reg(scope, h), scope.lens[h.index()])
            }};
        }
        match *expression {
            Expression::Literal(ref value) => {
                let dst = self.reg(scope, handle);
                match literal(value) {
                    Some(v) => {
                        let n = v.len().min(len as usize);
                        self.template[dst as usize..dst as usize + n].copy_from_slice(&v[..n]);
                    }
                    None => self.fail(format!("literal {value:?}"), line),
                }
            }
            Expression::Constant(c) => {
                let dst = self.reg(scope, handle);
                let value = &self.global_values[module.constants[c].init.index()];
                let n = value.len().min(len as usize);
                self.template[dst as usize..dst as usize + n].copy_from_slice(&value[..n]);
            }
            Expression::ZeroValue(_) => {
                let dst = self.reg(scope, handle);
                self.push(Insn::Zero { dst, len });
            }
            Expression::Compose { ref components, .. } => {
                let parts: Vec<(Reg, u32)> = components.iter().map(|c| operand!(*c)).collect();
                let lens: Vec<u32> = parts.iter().map(|p| p.1).collect();
                match compose_offsets(module, self.ty(scope, handle), &lens) {
                    Ok(offsets) => {
                        let dst = self.reg(scope, handle);
                        for ((src, part), at) in parts.into_iter().zip(offsets) {
                            self.copy(dst + at, src, part.min(len.saturating_sub(at)));
                        }
                    }
                    Err(what) => {
                        self.reg(scope, handle);
                        self.fail(what, line);
                    }
                }
            }
            Expression::Splat { size, value } => {
                let (src, w) = operand!(value);
                let dst = self.reg(scope, handle);
                if w == 1 {
                    self.push(Insn::Splat { dst, src, n: size as u8 });
                } else {
                    for i in 0..size as u32 {
                        self.copy(dst + i * w, src, w);
                    }
                }
            }
            Expression::Swizzle { size, vector, pattern } if is_wide(self.ty(scope, vector)) => {
                let (src, _) = operand!(vector);
                let dst = self.reg(scope, handle);
                for (i, c) in pattern.iter().take(size as usize).enumerate() {
                    self.copy(dst + 2 * i as u32, src + 2 * *c as u32, 2);
                }
            }
            Expression::Swizzle { size, vector, pattern } => {
                let (src, _) = operand!(vector);
                let dst = self.reg(scope, handle);
                let mut p = [0u8; 4];
                for (i, c) in pattern.iter().enumerate() {
                    p[i] = *c as u8;
                }
                self.push(Insn::Swizzle { dst, src, pattern: p, n: size as u8 });
            }
            Expression::Access { base, index: index_handle } => {
                let (base_reg, _) = operand!(base);
                let (index_reg, _) = operand!(index_handle);
                let dst = self.reg(scope, handle);
                let insn = match self.ty(scope, base) {
                    TypeInner::Pointer { base: pointee, space } => {
                        // Pointers into buffers count bytes, others register words.
                        let bytes = byte_addressed(*space);
                        match module.types[*pointee].inner {
                            TypeInner::Array { base: element, size: naga::ArraySize::Constant(n), stride } => {
                                Ok(Insn::PtrIndex {
                                    dst,
                                    base: base_reg,
                                    index: index_reg,
                                    count: n.get(),
                                    stride: element_step(module, element, stride, bytes),
                                })
                            }
                            TypeInner::Array { base: element, stride, .. } => Ok(Insn::PtrIndexRt {
                                dst,
                                base: base_reg,
                                index: index_reg,
                                stride: element_step(module, element, stride, bytes),
                            }),
                            TypeInner::Vector { size, scalar } => Ok(Insn::PtrIndex {
                                dst,
                                base: base_reg,
                                index: index_reg,
                                count: size as u32,
                                stride: component_step(scalar, bytes),
                            }),
                            TypeInner::Matrix { columns, rows, .. } => Ok(Insn::PtrIndex {
                                dst,
                                base: base_reg,
                                index: index_reg,
                                count: columns as u32,
                                stride: column_words(rows) as u32 * if bytes { 4 } else { 1 },
                            }),
                            ref other => Err(format!("indexing through a pointer to {other:?}")),
                        }
                    }
                    TypeInner::ValuePointer { size: Some(size), scalar, space } => Ok(Insn::PtrIndex {
                        dst,
                        base: base_reg,
                        index: index_reg,
                        count: *size as u32,
                        stride: component_step(*scalar, byte_addressed(*space)),
                    }),
                    TypeInner::Vector { size, scalar } => Ok(Insn::Extract {
                        dst,
                        base: base_reg,
                        index: index_reg,
                        count: *size as u32,
                        stride: component_words(*scalar),
                        len: component_words(*scalar),
                    }),
                    TypeInner::Array { base: element, size: naga::ArraySize::Constant(n), stride } => {
                        Ok(Insn::Extract {
                            dst,
                            base: base_reg,
                            index: index_reg,
                            count: n.get(),
                            stride: element_step(module, *element, *stride, false),
                            len,
                        })
                    }
                    TypeInner::Array { .. } => Err("indexing a runtime-sized array value".to_string()),
                    TypeInner::Matrix { columns, rows, .. } => Ok(Insn::Extract {
                        dst,
                        base: base_reg,
                        index: index_reg,
                        count: *columns as u32,
                        stride: column_words(*rows) as u32,
                        len,
                    }),
                    other => Err(format!("indexing {other:?}")),
                };
                match insn {
                    Ok(insn) => {
                        self.push(insn);
                    }
                    Err(what) => self.fail(what, line),
                }
            }
            Expression::AccessIndex { base, index: i } => self.access_index(scope, handle, base, i),
            Expression::Load { pointer } => {
                self.reg(scope, pointer);
                let dst = self.reg(scope, handle);
                self.load(scope, pointer, dst, len);
            }
            Expression::Unary { op, expr } if is_wide(self.ty(scope, expr)) => {
                let (src, n) = operand!(expr);
                let dst = self.reg(scope, handle);
                let apply: fn(u64) -> u64 = match op {
                    naga::UnaryOperator::Negate => u64::wrapping_neg,
                    naga::UnaryOperator::BitwiseNot => |x| !x,
                    naga::UnaryOperator::LogicalNot => {
                        self.fail("`!` on 64-bit integers".into(), line);
                        return Ok(());
                    }
                };
                self.push(Insn::Compute(Box::new(move |regs: &mut [u32]| {
                    for i in (0..n as usize).step_by(2) {
                        let x = wide::read(regs, src as usize + i);
                        wide::write(regs, dst as usize + i, apply(x));
                    }
                })));
            }
            Expression::Binary { op, left, right } if is_wide(self.ty(scope, left)) => {
                let (a, _) = operand!(left);
                let (b, _) = operand!(right);
                let dst = self.reg(scope, handle);
                let (Some((scalar, ca)), Some((right_scalar, cb))) =
                    (scalar_shape(self.ty(scope, left)), scalar_shape(self.ty(scope, right)))
                else {
                    self.fail(format!("{op:?} on 64-bit integers and composites"), line);
                    return Ok(());
                };
                let signed = scalar.kind == ScalarKind::Sint;
                if wide::binary(op, signed, 0, 1).is_none() {
                    self.fail(format!("{op:?} on 64-bit integers"), line);
                    return Ok(());
                }
                let n = ca.max(cb);
                let (sa, sb) = (usize::from(ca != 1), usize::from(cb != 1));
                // Shift amounts are u32: one word per component.
                let wb = component_words(right_scalar) as usize;
                let (a, b, dst) = (a as usize, b as usize, dst as usize);
                self.push(Insn::Compute(Box::new(move |regs: &mut [u32]| {
                    for i in 0..n {
                        let x = wide::read(regs, a + 2 * i * sa);
                        let y = if wb == 2 { wide::read(regs, b + 2 * i * sb) } else { u64::from(regs[b + i * sb]) };
                        match wide::binary(op, signed, x, y).expect("probed") {
                            wide::Out::Wide(v) => wide::write(regs, dst + 2 * i, v),
                            wide::Out::Bool(v) => regs[dst + i] = u32::from(v),
                        }
                    }
                })));
            }
            Expression::Unary { op, expr } => {
                let (src, n) = operand!(expr);
                let dst = self.reg(scope, handle);
                match shape(self.ty(scope, expr)) {
                    Some((kind, _)) => {
                        let op = match (op, kind) {
                            (naga::UnaryOperator::Negate, ScalarKind::Float) => UnOp::NegF,
                            (naga::UnaryOperator::Negate, _) => UnOp::NegI,
                            (naga::UnaryOperator::LogicalNot, _) => UnOp::Not,
                            (naga::UnaryOperator::BitwiseNot, _) => UnOp::BitNot,
                        };
                        self.push(Insn::Un { op, dst, src, n: n as u8 });
                    }
                    None => self.fail("unary operator on a composite".into(), line),
                }
            }
            Expression::Binary { op, left, right }
                if matches!(self.ty(scope, left), TypeInner::Matrix { .. })
                    || matches!(self.ty(scope, right), TypeInner::Matrix { .. }) =>
            {
                let a = operand!(left);
                let b = operand!(right);
                let dst = self.reg(scope, handle);
                let (ta, tb) = (self.ty(scope, left).clone(), self.ty(scope, right).clone());
                let probe = super::matrix::binary(op, &ta, &vec![0; a.1 as usize], &tb, &vec![0; b.1 as usize]);
                if probe.is_none() {
                    self.fail(format!("{op:?} on matrices"), line);
                } else {
                    self.push(Insn::Compute(Box::new(move |regs: &mut [u32]| {
                        let value =
                            super::matrix::binary(op, &ta, slice(regs, a), &tb, slice(regs, b)).expect("probed");
                        put(regs, dst, len, &value);
                    })));
                }
            }
            Expression::Binary { op, left, right } => {
                let (a, la) = operand!(left);
                let (b, lb) = operand!(right);
                let dst = self.reg(scope, handle);
                let Some((kind, _)) = shape(self.ty(scope, left)) else {
                    self.fail(format!("{op:?} on composites"), line);
                    return Ok(());
                };
                let Some(resolved) = BinOp::resolve(op, kind) else {
                    self.fail(format!("{op:?} on {kind:?}"), line);
                    return Ok(());
                };
                let n = la.max(lb);
                if n == 1 {
                    self.push(Insn::Bin { op: resolved, dst, a, b });
                } else {
                    let (sa, sb) = (u8::from(la != 1), u8::from(lb != 1));
                    self.push(Insn::BinV { op: resolved, dst, a, b, n: n as u8, sa, sb });
                }
                // f16 arithmetic: computed in f32 (exact or correctly rounded there, as
                // f32 has more than 2 * 11 + 2 bits), then rounded to binary16.
                if is_half(self.ty(scope, handle)) {
                    self.round_half(dst, len);
                }
            }
            Expression::Select { condition, accept, reject } => {
                let (cond, lc) = operand!(condition);
                let (accept, n) = operand!(accept);
                let (reject, _) = operand!(reject);
                let dst = self.reg(scope, handle);
                if lc != 1 && n != lc {
                    // Components of several words (64-bit) under a vector condition.
                    let w = (n / lc) as usize;
                    let (dst, cond, accept, reject) = (dst as usize, cond as usize, accept as usize, reject as usize);
                    self.push(Insn::Compute(Box::new(move |regs: &mut [u32]| {
                        for i in 0..lc as usize {
                            let src = if regs[cond + i] != 0 { accept } else { reject };
                            regs.copy_within(src + i * w..src + (i + 1) * w, dst + i * w);
                        }
                    })));
                } else {
                    self.push(Insn::Select { dst, cond, accept, reject, n: n as u8, sc: u8::from(lc != 1) });
                }
            }
            Expression::Relational { fun, argument } => {
                let v = operand!(argument);
                let dst = self.reg(scope, handle);
                self.push(Insn::Compute(Box::new(move |regs: &mut [u32]| {
                    let value: Words = {
                        let v = slice(regs, v);
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
                    };
                    put(regs, dst, len, &value);
                })));
            }
            Expression::Math { fun, arg, arg1, arg2, arg3 } => {
                self.math(scope, handle, fun, [Some(arg), arg1, arg2, arg3])
            }
            Expression::As { expr, kind, convert: Some(width) }
                if is_wide(self.ty(scope, expr)) || wide::is_wide(naga::Scalar { kind, width }) =>
            {
                let (src, _) = operand!(expr);
                let dst = self.reg(scope, handle);
                let Some((from, comps)) = scalar_shape(self.ty(scope, expr)) else {
                    self.fail("conversion of a composite".into(), line);
                    return Ok(());
                };
                let to = naga::Scalar { kind, width };
                if wide::convert(0, from, to).is_none() {
                    self.fail(format!("conversion from {from:?} to {to:?}"), line);
                    return Ok(());
                }
                let (ws, wd) = (component_words(from) as usize, component_words(to) as usize);
                let (src, dst) = (src as usize, dst as usize);
                self.push(Insn::Compute(Box::new(move |regs: &mut [u32]| {
                    for i in 0..comps {
                        let x = if ws == 2 { wide::read(regs, src + 2 * i) } else { u64::from(regs[src + i]) };
                        let v = wide::convert(x, from, to).expect("probed");
                        if wd == 2 {
                            wide::write(regs, dst + 2 * i, v);
                        } else {
                            regs[dst + i] = v as u32;
                        }
                    }
                })));
            }
            Expression::As { expr, kind, convert: Some(width) }
                if is_half(self.ty(scope, expr)) || (kind == ScalarKind::Float && width == 2) =>
            {
                let (src, _) = operand!(expr);
                let dst = self.reg(scope, handle);
                let Some((from, comps)) = scalar_shape(self.ty(scope, expr)) else {
                    self.fail("conversion of a composite".into(), line);
                    return Ok(());
                };
                let to = naga::Scalar { kind, width };
                if arith::convert_half(0, from, to).is_none() {
                    self.fail(format!("conversion from {from:?} to {to:?}"), line);
                    return Ok(());
                }
                let (src, dst) = (src as usize, dst as usize);
                self.push(Insn::Compute(Box::new(move |regs: &mut [u32]| {
                    for i in 0..comps {
                        regs[dst + i] = arith::convert_half(regs[src + i], from, to).expect("probed");
                    }
                })));
            }
            Expression::As { expr, kind, convert } => {
                let (src, n) = operand!(expr);
                let Some((from, _)) = shape(self.ty(scope, expr)) else {
                    self.reg(scope, handle);
                    self.fail("conversion of a composite".into(), line);
                    return Ok(());
                };
                match convert {
                    // A bitcast: the same words.
                    None if n == len => scope.regs[index] = src,
                    None => {
                        let dst = self.reg(scope, handle);
                        self.copy(dst, src, n.min(len));
                    }
                    Some(4) | Some(1) => {
                        let dst = self.reg(scope, handle);
                        if arith::convert(0, from, kind).is_some() {
                            self.push(Insn::Convert { from, to: kind, dst, src, n: n as u8 });
                        } else {
                            self.fail(format!("{from:?} as {kind:?}"), line);
                        }
                    }
                    Some(width) => {
                        self.reg(scope, handle);
                        self.fail(format!("conversion to {}-bit", width * 8), line);
                    }
                }
            }
            Expression::ArrayLength(pointer) => {
                let (p, _) = operand!(pointer);
                let dst = self.reg(scope, handle);
                let stride = match self.ty(scope, pointer) {
                    TypeInner::Pointer { base, .. } => match module.types[*base].inner {
                        // Runtime-sized arrays live in buffers: bytes.
                        TypeInner::Array { stride, .. } => Ok(stride),
                        _ => Err("arrayLength of a non-array"),
                    },
                    _ => Err("arrayLength of a non-pointer"),
                };
                match stride {
                    Ok(stride) => {
                        self.push(Insn::ArrayLength { dst, pointer: p, stride });
                    }
                    Err(what) => self.fail(what.into(), line),
                }
            }
            // Written by their statements (Call, Atomic, WorkGroupUniformLoad, subgroup ops).
            Expression::CallResult(_)
            | Expression::AtomicResult { .. }
            | Expression::WorkGroupUniformLoadResult { .. }
            | Expression::SubgroupOperationResult { .. }
            | Expression::SubgroupBallotResult => {
                self.reg(scope, handle);
            }
            // Pre-emitted when the scope opens.
            Expression::FunctionArgument(_) | Expression::GlobalVariable(_) | Expression::LocalVariable(_) => {
                self.reg(scope, handle);
            }
            ref other => {
                self.reg(scope, handle);
                let name = format!("{other:?}");
                let name = name.split([' ', '(', '{']).next().unwrap_or("expression").to_string();
                self.fail(format!("expression `{name}`"), line);
            }
        }
        Ok(())
    }

    /// `base.index` with a constant index: a pointer offset (known when compiling if
    /// the base's target is), or the base's own registers for a value.
    fn access_index(&mut self, scope: &mut Scope, handle: Handle<Expression>, base: Handle<Expression>, index: u32) {
        let module = self.module;
        let line = self.line;
        let base_reg = self.reg(scope, base);
        let step = match self.ty(scope, base) {
            TypeInner::Pointer { base: pointee, space } => {
                // Pointers into buffers count bytes, others register words.
                let bytes = byte_addressed(*space);
                let inner = &module.types[*pointee].inner;
                match *inner {
                    TypeInner::Array { base: element, stride, .. } => {
                        Ok((true, index * element_step(module, element, stride, bytes)))
                    }
                    TypeInner::Struct { .. } => Ok((true, member_step(module, inner, index, bytes))),
                    TypeInner::Vector { scalar, .. } => Ok((true, index * component_step(scalar, bytes))),
                    TypeInner::Matrix { rows, .. } => {
                        Ok((true, index * column_words(rows) as u32 * if bytes { 4 } else { 1 }))
                    }
                    ref other => Err(format!("indexing through a pointer to {other:?}")),
                }
            }
            TypeInner::ValuePointer { size: Some(_), scalar, space } => {
                Ok((true, index * component_step(*scalar, byte_addressed(*space))))
            }
            TypeInner::Vector { scalar, .. } => Ok((false, index * component_words(*scalar))),
            TypeInner::Array { base: element, size: naga::ArraySize::Constant(_), stride } => {
                Ok((false, index * element_step(module, *element, *stride, false)))
            }
            TypeInner::Array { .. } => Err("indexing a runtime-sized array value".to_string()),
            inner @ TypeInner::Struct { .. } => Ok((false, member_step(module, inner, index, false))),
            TypeInner::Matrix { rows, .. } => Ok((false, index * column_words(*rows) as u32)),
            other => Err(format!("indexing {other:?}")),
        };
        let i = handle.index();
        match step {
            Err(what) => {
                self.reg(scope, handle);
                self.fail(what, line);
            }
            // A component or field of a value: the value's registers.
            Ok((false, step)) => scope.regs[i] = base_reg + step,
            Ok((true, step)) => match scope.places[base.index()] {
                Some(place) => {
                    let place = place.offset(step);
                    scope.places[i] = Some(place);
                    let dst = self.reg(scope, handle);
                    match place {
                        // Pointer values known now: in the template, or set when the frame starts.
                        Place::Local(variable) => self.local_pointers.push((dst, variable)),
                        _ => {
                            self.template[dst as usize] = self.template[base_reg as usize];
                            self.template[dst as usize + 1] = self.template[base_reg as usize + 1] + step;
                            scope.constant[i] = true;
                        }
                    }
                }
                None => {
                    let dst = self.reg(scope, handle);
                    self.push(Insn::PtrAdd { dst, base: base_reg, add: step });
                }
            },
        }
    }

    /// A math function: a closure over the reference implementation.
    fn math(
        &mut self,
        scope: &mut Scope,
        handle: Handle<Expression>,
        fun: naga::MathFunction,
        args: [Option<Handle<Expression>>; 4],
    ) {
        use naga::MathFunction as M;
        let line = self.line;
        let len = scope.lens[handle.index()];
        let operands: Vec<Option<(Reg, u32)>> =
            args.iter().map(|a| a.map(|h| (self.reg(scope, h), scope.lens[h.index()]))).collect();
        let dst = self.reg(scope, handle);
        let arg = args[0].expect("math functions have an argument");
        let a = operands[0].expect("first argument");
        let arg_type = self.ty(scope, arg).clone();
        let compute: Result<super::insn::Compute, String> = match fun {
            M::Transpose => match arg_type {
                TypeInner::Matrix { columns, rows, .. } => Ok(Box::new(move |regs: &mut [u32]| {
                    let value = super::matrix::transpose(slice(regs, a), columns, rows);
                    put(regs, dst, len, &value);
                })),
                other => Err(format!("transpose of {other:?}")),
            },
            M::Determinant => match arg_type {
                TypeInner::Matrix { columns, .. } => Ok(Box::new(move |regs: &mut [u32]| {
                    let value = super::matrix::determinant(slice(regs, a), columns);
                    put(regs, dst, len, &[value]);
                })),
                other => Err(format!("determinant of {other:?}")),
            },
            // Results are naga's predeclared structs: (fract, whole) and (fract, exp).
            M::Modf | M::Frexp => match (shape(&arg_type), self.ty(scope, handle)) {
                (Some((ScalarKind::Float, comps)), TypeInner::Struct { members, .. })
                    if members.len() == 2 && a.1 as usize == comps =>
                {
                    let second = dst + member_step(self.module, self.ty(scope, handle), 1, false);
                    Ok(Box::new(move |regs: &mut [u32]| {
                        for i in 0..comps {
                            let x = regs[a.0 as usize + i];
                            let (first, other) = if fun == M::Modf { arith::modf(x) } else { arith::frexp(x) };
                            regs[dst as usize + i] = first;
                            regs[second as usize + i] = other;
                        }
                    }))
                }
                _ => Err(format!("{fun:?} of {arg_type:?}")),
            },
            _ if is_wide(&arg_type) => {
                let (scalar, comps) = scalar_shape(&arg_type).expect("a scalar or vector");
                let signed = scalar.kind == ScalarKind::Sint;
                if wide::math(fun, signed, 0, 0, 0).is_none() {
                    Err(format!("math function {fun:?} on 64-bit integers"))
                } else {
                    let (b, c) = (operands[1], operands[2]);
                    Ok(Box::new(move |regs: &mut [u32]| {
                        for i in 0..comps {
                            let at = |o: Option<(Reg, u32)>| o.map_or(0, |(r, _)| wide::read(regs, r as usize + 2 * i));
                            let value = wide::math(fun, signed, wide::read(regs, a.0 as usize + 2 * i), at(b), at(c));
                            wide::write(regs, dst as usize + 2 * i, value.expect("probed"));
                        }
                    }))
                }
            }
            _ if arith::pack(fun, &[0; 4]).is_some() => Ok(Box::new(move |regs: &mut [u32]| {
                let value = arith::pack(fun, slice(regs, a)).expect("a pack function");
                put(regs, dst, len, &[value]);
            })),
            _ if arith::unpack(fun, 0).is_some() => Ok(Box::new(move |regs: &mut [u32]| {
                let value = arith::unpack(fun, regs[a.0 as usize]).expect("an unpack function");
                put(regs, dst, len, &value);
            })),
            _ => match shape(&arg_type) {
                None => Err(format!("{fun:?} on a composite")),
                Some((kind, comps)) => {
                    let zeros = [0u32; 4];
                    let z = |o: Option<(Reg, u32)>| o.map(|(_, l)| &zeros[..(l as usize).min(4)]);
                    let probe = math(fun, kind, comps, &zeros[..comps], z(operands[1]), z(operands[2]), z(operands[3]));
                    if probe.is_none() {
                        Err(format!("math function {fun:?} on {kind:?}"))
                    } else {
                        let (b, c, d) = (operands[1], operands[2], operands[3]);
                        if let (M::Min | M::Max | M::Clamp | M::Abs, 1, ScalarKind::Uint | ScalarKind::Sint) =
                            (fun, comps, kind)
                        {
                            // Integer clamps are common enough for a closure without allocation.
                            Ok(Box::new(move |regs: &mut [u32]| {
                                let x = regs[a.0 as usize];
                                let y = b.map_or(0, |b| regs[b.0 as usize]);
                                let z = c.map_or(0, |c| regs[c.0 as usize]);
                                regs[dst as usize] = arith::math(fun, kind, x, y, z).expect("probed");
                            }))
                        } else {
                            Ok(Box::new(move |regs: &mut [u32]| {
                                let value = math(
                                    fun,
                                    kind,
                                    comps,
                                    slice(regs, a),
                                    b.map(|b| slice(regs, b)),
                                    c.map(|c| slice(regs, c)),
                                    d.map(|d| slice(regs, d)),
                                )
                                .expect("probed");
                                put(regs, dst, len, &value);
                            }))
                        }
                    }
                }
            },
        };
        match compute {
            Ok(compute) => {
                self.push(Insn::Compute(compute));
                // f16 results: computed in f32, rounded to binary16 once.
                if is_half(self.ty(scope, handle)) {
                    self.round_half(dst, len);
                }
            }
            Err(what) => self.fail(what, line),
        }
    }

    /// Rounds the `len` f16 values at `dst` (held as f32) to binary16.
    fn round_half(&mut self, dst: Reg, len: u32) {
        let (dst, len) = (dst as usize, len as usize);
        self.push(Insn::Compute(Box::new(move |regs: &mut [u32]| {
            for x in &mut regs[dst..dst + len] {
                *x = arith::round_f16(*x);
            }
        })));
    }
}
