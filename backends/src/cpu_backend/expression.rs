//! Lowering one naga expression to bytecode: its operands' registers resolved, its
//! types looked at once here and never again at run time. Field and component
//! extraction with a constant index, and bitcasts, cost no instruction: the result is
//! the source's register range. Constructs the interpreter does not support lower to a
//! [`Insn::Fail`] naming the construct and its line, reported only if reached.

use super::arith;
use super::compiler::{Compiler, NONE, Scope};
use super::constant::{compose_offsets, literal};
use super::insn::{BinOp, Insn, Reg, UnOp, per_lane};
use super::lanes::LaneRegs;
use super::layout::{
    Place, Words, array_length, byte_addressed, component_step, component_words, consecutive, element_step, is_half,
    is_wide, member_step, scalar_shape, shape,
};
use super::math_call::{put, slice};
use super::matrix::column_words;
use super::wide;
use crate::error::BackendError;
use naga::{Expression, Handle, ScalarKind, TypeInner};
use smallvec::smallvec;

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
            Expression::Literal(ref value) => match literal(value) {
                Some(v) => {
                    self.constant(scope, handle, &v);
                }
                None => {
                    self.reg_permanent(scope, handle);
                    self.fail(format!("literal {value:?}"), line);
                }
            },
            Expression::Constant(c) => {
                let value = self.global_values[module.constants[c].init.index()].clone();
                self.constant(scope, handle, &value);
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
                        // Padding between members is zeroed, not left as whatever the
                        // registers last held (they may be another value's, reused): a
                        // store writes a value's padding words too.
                        let mut covered = vec![false; len as usize];
                        for (&part, &at) in lens.iter().zip(&offsets) {
                            for word in covered.iter_mut().skip(at as usize).take(part as usize) {
                                *word = true;
                            }
                        }
                        let mut word = 0;
                        while word < covered.len() {
                            let gap = covered[word..].iter().take_while(|&&c| !c).count();
                            if gap > 0 {
                                self.push(Insn::Zero { dst: dst + word as Reg, len: gap as u32 });
                            }
                            word += gap + covered[word + gap..].iter().take_while(|&&c| c).count();
                        }
                        // Members that lie next to each other in their sources too (the
                        // fields of a record read from one row, `Node(r0.xyz, r0.w)`) are
                        // copied as one range.
                        let mut runs: Vec<(Reg, Reg, u32)> = Vec::with_capacity(parts.len());
                        for ((src, part), at) in parts.into_iter().zip(offsets) {
                            let words = part.min(len.saturating_sub(at));
                            match runs.last_mut() {
                                Some((to, from, n)) if *to + *n == dst + at && *from + *n == src => *n += words,
                                _ => runs.push((dst + at, src, words)),
                            }
                        }
                        for (to, from, words) in runs {
                            self.copy(to, from, words);
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
                if let Some(first) = consecutive(size, &pattern) {
                    // Consecutive components (`v.yzw`): the vector's own registers, as for
                    // one component (`access_index`).
                    scope.regs[index] = src + first;
                } else {
                    let dst = self.reg(scope, handle);
                    let mut p = [0u8; 4];
                    for (i, c) in pattern.iter().enumerate() {
                        p[i] = *c as u8;
                    }
                    self.push(Insn::Swizzle { dst, src, pattern: p, n: size as u8 });
                }
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
                            TypeInner::Array { base: element, size, stride } => match array_length(module, size) {
                                Ok(Some(n)) => Ok(Insn::PtrIndex {
                                    dst,
                                    base: base_reg,
                                    index: index_reg,
                                    count: n,
                                    stride: element_step(module, element, stride, bytes),
                                }),
                                // Runtime-sized arrays live only in buffers, whose length
                                // the instruction reads at run time.
                                Ok(None) if bytes => Ok(Insn::PtrIndexRt {
                                    dst,
                                    base: base_reg,
                                    index: index_reg,
                                    stride: element_step(module, element, stride, bytes),
                                }),
                                Ok(None) => Err(format!("a runtime-sized array in {space:?} memory")),
                                Err(what) => Err(what),
                            },
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
                    TypeInner::Array { base: element, size, stride } => match array_length(module, *size) {
                        Ok(Some(n)) => Ok(Insn::Extract {
                            dst,
                            base: base_reg,
                            index: index_reg,
                            count: n,
                            stride: element_step(module, *element, *stride, false),
                            len,
                        }),
                        Ok(None) => Err("indexing a runtime-sized array value".to_string()),
                        Err(what) => Err(what),
                    },
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
                match scope.places[pointer.index()] {
                    // Read in place (`load_alias`): the variable's own registers.
                    Some(Place::Local(variable)) if scope.in_place_loads[index] && scope.regs[index] == NONE => {
                        scope.regs[index] = variable;
                    }
                    _ => {
                        let dst = self.reg(scope, handle);
                        let runs = scope.partial_loads[index].take();
                        self.load(scope, pointer, dst, len, runs);
                    }
                }
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
                self.push(Insn::Compute(per_lane(move |regs: &mut LaneRegs| {
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
                self.push(Insn::Compute(per_lane(move |regs: &mut LaneRegs| {
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
                    self.push(Insn::Compute(per_lane(move |regs: &mut LaneRegs| {
                        let value =
                            super::matrix::binary(op, &ta, &slice(regs, a), &tb, &slice(regs, b)).expect("probed");
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
                    self.push(Insn::Compute(per_lane(move |regs: &mut LaneRegs| {
                        for i in 0..lc as usize {
                            let src = if regs[cond + i] != 0 { accept } else { reject };
                            regs.copy(dst + i * w, src + i * w, w);
                        }
                    })));
                } else {
                    self.push(Insn::Select { dst, cond, accept, reject, n: n as u8, sc: u8::from(lc != 1) });
                }
            }
            Expression::Relational { fun, argument } => {
                let v = operand!(argument);
                let dst = self.reg(scope, handle);
                self.push(Insn::Compute(per_lane(move |regs: &mut LaneRegs| {
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
                self.push(Insn::Compute(per_lane(move |regs: &mut LaneRegs| {
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
                self.push(Insn::Compute(per_lane(move |regs: &mut LaneRegs| {
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
                        if n < len {
                            self.push(Insn::Zero { dst: dst + n, len: len - n });
                        }
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
            Expression::ImageLoad { .. } | Expression::ImageSample { .. } | Expression::ImageQuery { .. } => {
                self.image_expression(scope, handle)?;
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
            TypeInner::Array { base: element, size, stride } => match array_length(module, *size) {
                Ok(Some(_)) => Ok((false, index * element_step(module, *element, *stride, false))),
                Ok(None) => Err("indexing a runtime-sized array value".to_string()),
                Err(what) => Err(what),
            },
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
            Ok((false, step)) => scope.regs[i] = self.reg(scope, base) + step,
            Ok((true, step)) => match scope.places[base.index()] {
                // A pointer known now: its register is made where one is read
                // (`Compiler::place_reg`), in the template or set when the frame starts.
                Some(place) => {
                    scope.places[i] = Some(place.offset(step));
                    scope.constant[i] = !matches!(place, Place::Local(_));
                }
                None => {
                    let base_reg = self.reg(scope, base);
                    let dst = self.reg(scope, handle);
                    self.push(Insn::PtrAdd { dst, base: base_reg, add: step });
                }
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::decode::tests::compiled;
    use super::super::insn::Insn;

    #[test]
    fn consecutive_components_are_the_vectors_own_registers() {
        let body =
            "let v = vec4<u32>(x, x + 1u, x * 3u, 7u); let t = v.yzw; let u = v.wx; data[id.x] = t.x + t.z + u.y;";
        // `.yzw` reads v's registers; `.wx` is a swizzle.
        assert_eq!(compiled(body).iter().filter(|i| matches!(i, Insn::Swizzle { .. })).count(), 1);
    }
}
