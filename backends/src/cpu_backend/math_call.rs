//! Lowering WGSL's math builtins (`naga::Expression::Math`): each call becomes a closure
//! over the reference implementation of [`super::arith`] (and [`super::matrix`]),
//! applied value by value, with f16 results rounded to binary16.

use super::arith;
use super::compiler::{Compiler, Scope};
use super::insn::{Compute, Insn, Reg, per_lane};
use super::lanes::{LaneRegs, Members, Words};
use super::layout::{is_half, is_wide, member_step, scalar_shape, shape};
use super::wide;
use naga::{Expression, Handle, ScalarKind, TypeInner};

/// The f32 dot product of two vectors of f32 words: a sequential sum of products, no fused
/// multiply-add, starting from the first product rather than +0 so that products that are
/// all -0 sum to -0.
fn dot(a: &[u32], b: &[u32]) -> f32 {
    let f = f32::from_bits;
    (1..a.len()).fold(f(a[0]) * f(b[0]), |acc, i| acc + f(a[i]) * f(b[i]))
}

/// Math functions on vectors and scalars (the reference implementation, value by value):
/// writes the result's words into `out` and returns how many (`None`: WGSL has no such
/// function for these operands). Results are written in place rather than collected,
/// because this runs once per call and invocation.
#[allow(clippy::too_many_arguments)]
#[inline]
fn math(
    fun: naga::MathFunction,
    kind: ScalarKind,
    comps: usize,
    a: &[u32],
    b: Option<&[u32]>,
    c: Option<&[u32]>,
    d: Option<&[u32]>,
    out: &mut [u32; 4],
) -> Option<usize> {
    use naga::MathFunction as M;
    let f = f32::from_bits;
    let pick = |v: Option<&[u32]>, i: usize| v.map_or(0, |v| v[if v.len() == 1 { 0 } else { i }]);
    let one = |out: &mut [u32; 4], word: u32| {
        out[0] = word;
        Some(1)
    };
    match fun {
        M::Dot if kind == ScalarKind::Float => one(out, dot(&a[..comps], &b?[..comps]).to_bits()),
        M::Dot => {
            let b = b?;
            one(out, (0..comps).fold(0u32, |acc, i| acc.wrapping_add(a[i].wrapping_mul(b[i]))))
        }
        M::Length => one(out, sum_of_squares(a[..comps].iter().map(|&x| f(x))).sqrt().to_bits()),
        M::Distance => {
            let b = b?;
            one(out, sum_of_squares((0..comps).map(|i| f(a[i]) - f(b[i]))).sqrt().to_bits())
        }
        M::Normalize => {
            let length = sum_of_squares(a[..comps].iter().map(|&x| f(x))).sqrt();
            for (o, &x) in out.iter_mut().zip(a) {
                *o = (f(x) / length).to_bits();
            }
            Some(a.len())
        }
        M::Cross => {
            let b = b?;
            let value = cross(std::array::from_fn(|i| f(a[i])), std::array::from_fn(|i| f(b[i])));
            for (o, v) in out.iter_mut().zip(value) {
                *o = v.to_bits();
            }
            Some(3)
        }
        M::Reflect => {
            // e1 - 2 dot(e2, e1) e2
            let b = b?;
            let d = dot(&b[..comps], &a[..comps]);
            for i in 0..comps {
                out[i] = (f(a[i]) - 2.0 * d * f(b[i])).to_bits();
            }
            Some(comps)
        }
        M::Refract => {
            // k = 1 - η² (1 - dot(e2, e1)²); k < 0: the zero vector; else
            // η e1 - (η dot(e2, e1) + sqrt(k)) e2.
            let (b, eta) = (b?, f(c?[0]));
            let d = dot(&b[..comps], &a[..comps]);
            let k = 1.0 - eta * eta * (1.0 - d * d);
            if k < 0.0 {
                out[..comps].fill(0.0f32.to_bits());
                return Some(comps);
            }
            let scale = eta * d + k.sqrt();
            for i in 0..comps {
                out[i] = (eta * f(a[i]) - scale * f(b[i])).to_bits();
            }
            Some(comps)
        }
        M::FaceForward => {
            // e1 if dot(e2, e3) < 0, else -e1.
            let (b, c) = (b?, c?);
            let keep = dot(&b[..comps], &c[..comps]) < 0.0;
            for i in 0..comps {
                out[i] = if keep { a[i] } else { (-f(a[i])).to_bits() };
            }
            Some(comps)
        }
        M::Dot4I8Packed | M::Dot4U8Packed => {
            let b = b?;
            let signed = fun == M::Dot4I8Packed;
            let byte = |word: u32, i: u32| {
                let byte = (word >> (8 * i)) & 0xff;
                if signed { byte as u8 as i8 as i32 as u32 } else { byte }
            };
            one(out, (0..4).fold(0u32, |acc, i| acc.wrapping_add(byte(a[0], i).wrapping_mul(byte(b[0], i)))))
        }
        M::ExtractBits | M::InsertBits => {
            for i in 0..comps {
                out[i] = arith::bits(fun, kind, a[i], pick(b, i), pick(c, i), pick(d, i))?;
            }
            Some(comps)
        }
        _ => {
            for i in 0..comps {
                out[i] = arith::math(fun, kind, a[i], pick(b, i), pick(c, i))?;
            }
            Some(comps)
        }
    }
}

/// Operand rows of a component-wise math call: (first register, step per component: 1
/// for a vector, 0 for a scalar broadcast over the components).
type Operand = (usize, usize);

/// The row form of a component-wise function: component `i` of every member at once,
/// `f` compiled into the loop over them (absent operands are 0).
fn component_rows(
    f: impl Fn(u32, u32, u32) -> u32 + Copy + Send + Sync + 'static,
    dst: usize,
    n: usize,
    (a, sa): Operand,
    b: Option<Operand>,
    c: Option<Operand>,
) -> Compute {
    Box::new(move |file: &mut [u32], members: Members| {
        for i in 0..n {
            let row = |o: Option<Operand>| o.map(|(r, s)| r + i * s);
            // One and two operands as the row operations the compiler vectorises over a
            // whole group (`min`, `max`, `abs`, ... in a BVH loop's box tests).
            match (row(b), row(c)) {
                (None, None) => members.unary(file, dst + i, a + i * sa, 1, |x| f(x, 0, 0)),
                (Some(b), None) => members.binary(file, (dst + i, a + i * sa, b), 1, |x, y| f(x, y, 0)),
                (b, c) => members.ternary(file, dst + i, a + i * sa, b, c, f),
            }
        }
    })
}

/// The sum of the squares of `x`, from 0 in order: `length`, `normalize` and `distance`
/// take it, in [`math`] and in [`geometric`] alike (so with the same bits).
#[inline(always)]
fn sum_of_squares(x: impl Iterator<Item = f32>) -> f32 {
    x.fold(0.0f32, |sum, v| sum + v * v)
}

/// `cross(x, y)`, in [`math`] and in [`geometric`].
#[inline(always)]
fn cross(x: [f32; 3], y: [f32; 3]) -> [f32; 3] {
    [x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2], x[0] * y[1] - x[1] * y[0]]
}

/// `normalize`, `length`, `distance` and `cross` of float vectors with the function
/// fixed, so that each member's words are read straight from its registers and no match
/// on the function runs per member (the general form copied every operand out and
/// matched per member: `normalize` alone cost the path tracer's large groups about 50
/// cycles a member). Their formulas are [`math`]'s ([`sum_of_squares`], [`cross`]), so
/// the same bits.
fn geometric(
    fun: naga::MathFunction,
    kind: ScalarKind,
    comps: usize,
    dst: Reg,
    (a, a_len): (Reg, u32),
    b: Option<(Reg, u32)>,
) -> Option<Compute> {
    use naga::MathFunction as M;
    if kind != ScalarKind::Float || a_len as usize != comps || !(1..=4).contains(&comps) {
        return None;
    }
    let (dst, a) = (dst as usize, a as usize);
    let f = f32::from_bits;
    // Every operand word read before the first result word is written (the result may
    // share registers with an operand).
    let read = move |regs: &LaneRegs, at: usize| -> [f32; 4] {
        std::array::from_fn(|i| if i < comps { f(regs[at + i]) } else { 0.0 })
    };
    let squares = move |x: &[f32; 4]| sum_of_squares(x[..comps].iter().copied());
    match (fun, b) {
        (M::Normalize, None) => Some(per_lane(move |regs: &mut LaneRegs| {
            let x = read(regs, a);
            let length = squares(&x).sqrt();
            for (i, v) in x[..comps].iter().enumerate() {
                regs[dst + i] = (v / length).to_bits();
            }
        })),
        (M::Length, None) => Some(per_lane(move |regs: &mut LaneRegs| {
            regs[dst] = squares(&read(regs, a)).sqrt().to_bits();
        })),
        (M::Distance, Some((b, b_len))) if b_len as usize == comps => {
            let b = b as usize;
            Some(per_lane(move |regs: &mut LaneRegs| {
                let (x, y) = (read(regs, a), read(regs, b));
                regs[dst] = sum_of_squares((0..comps).map(|i| x[i] - y[i])).sqrt().to_bits();
            }))
        }
        (M::Cross, Some((b, 3))) if comps == 3 => {
            let b = b as usize;
            Some(per_lane(move |regs: &mut LaneRegs| {
                let (x, y) = (read(regs, a), read(regs, b));
                let value = cross([x[0], x[1], x[2]], [y[0], y[1], y[2]]);
                for (i, v) in value.iter().enumerate() {
                    regs[dst + i] = v.to_bits();
                }
            }))
        }
        _ => None,
    }
}

/// The common component-wise functions of [`arith::math`] with the function and kind
/// fixed, so that the compiler specialises each (the path tracer spends a fifth of its
/// interpreted time in math builtins, and matching on the function per component was
/// most of that); `None`: use the general form, which gives the same results.
fn specialised(
    fun: naga::MathFunction,
    kind: ScalarKind,
    dst: usize,
    n: usize,
    a: Operand,
    b: Option<Operand>,
    c: Option<Operand>,
) -> Option<Compute> {
    use ScalarKind as K;
    use naga::MathFunction as M;
    macro_rules! table {
        ($(($fun:ident, $kind:ident)),*) => {
            match (fun, kind) {
                $((M::$fun, K::$kind) => Some(component_rows(
                    |x, y, z| arith::math(M::$fun, K::$kind, x, y, z).unwrap_or(0),
                    dst,
                    n,
                    a,
                    b,
                    c,
                )),)*
                _ => None,
            }
        };
    }
    table!(
        (Abs, Float),
        (Min, Float),
        (Max, Float),
        (Clamp, Float),
        (Saturate, Float),
        (Floor, Float),
        (Ceil, Float),
        (Fract, Float),
        (Sqrt, Float),
        (InverseSqrt, Float),
        (Exp, Float),
        (Log, Float),
        (Pow, Float),
        (Sin, Float),
        (Cos, Float),
        (Atan2, Float),
        (Acos, Float),
        (Sign, Float),
        (Mix, Float),
        (Fma, Float),
        (Min, Uint),
        (Max, Uint),
        (Clamp, Uint),
        (Min, Sint),
        (Max, Sint),
        (Clamp, Sint),
        (Abs, Sint),
        (CountOneBits, Uint),
        (FirstTrailingBit, Uint),
        (FirstLeadingBit, Uint),
        (ReverseBits, Uint)
    )
}

/// Reads `len` words at `reg` of an invocation's registers.
pub(super) fn slice(regs: &LaneRegs, (reg, len): (Reg, u32)) -> Words {
    regs.read(reg as usize, len as usize)
}

/// Writes `value` at `dst`, at most `len` words.
pub(super) fn put(regs: &mut LaneRegs, dst: Reg, len: u32, value: &[u32]) {
    let n = (len as usize).min(value.len());
    regs.write(dst as usize, &value[..n]);
}

impl Compiler<'_> {
    /// A math function: a closure over the reference implementation.
    pub(super) fn math(
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
                TypeInner::Matrix { columns, rows, .. } => Ok(per_lane(move |regs: &mut LaneRegs| {
                    let value = super::matrix::transpose(&slice(regs, a), columns, rows);
                    put(regs, dst, len, &value);
                })),
                other => Err(format!("transpose of {other:?}")),
            },
            M::Determinant => match arg_type {
                TypeInner::Matrix { columns, .. } => Ok(per_lane(move |regs: &mut LaneRegs| {
                    let value = super::matrix::determinant(&slice(regs, a), columns);
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
                    Ok(per_lane(move |regs: &mut LaneRegs| {
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
                    Ok(per_lane(move |regs: &mut LaneRegs| {
                        for i in 0..comps {
                            let at = |o: Option<(Reg, u32)>| o.map_or(0, |(r, _)| wide::read(regs, r as usize + 2 * i));
                            let value = wide::math(fun, signed, wide::read(regs, a.0 as usize + 2 * i), at(b), at(c));
                            wide::write(regs, dst as usize + 2 * i, value.expect("probed"));
                        }
                    }))
                }
            }
            _ if arith::pack(fun, &[0; 4]).is_some() => Ok(per_lane(move |regs: &mut LaneRegs| {
                let value = arith::pack(fun, &slice(regs, a)).expect("a pack function");
                put(regs, dst, len, &[value]);
            })),
            _ if arith::unpack(fun, 0).is_some() => Ok(per_lane(move |regs: &mut LaneRegs| {
                let value = arith::unpack(fun, regs[a.0 as usize]).expect("an unpack function");
                put(regs, dst, len, &value);
            })),
            _ => match shape(&arg_type) {
                None => Err(format!("{fun:?} on a composite")),
                Some((kind, comps)) => {
                    let zeros = [0u32; 4];
                    let z = |o: Option<(Reg, u32)>| o.map(|(_, l)| &zeros[..(l as usize).min(4)]);
                    let probe = math(
                        fun,
                        kind,
                        comps,
                        &zeros[..comps],
                        z(operands[1]),
                        z(operands[2]),
                        z(operands[3]),
                        &mut [0; 4],
                    );
                    if probe.is_none() {
                        Err(format!("math function {fun:?} on {kind:?}"))
                    } else {
                        let (b, c, d) = (operands[1], operands[2], operands[3]);
                        // Operands of one word are broadcast over the components; absent
                        // ones are 0, as in the general form.
                        let at = |o: Option<(Reg, u32)>| o.map(|(r, l)| (r as usize, usize::from(l > 1)));
                        let rows = (at(Some(a)).expect("a first argument"), at(b), at(c));
                        let (rows_dst, n) = (dst as usize, comps.min(len as usize));
                        if let Some(compute) = specialised(fun, kind, rows_dst, n, rows.0, rows.1, rows.2) {
                            Ok(compute)
                        } else if let Some(compute) = geometric(fun, kind, comps, dst, a, b) {
                            Ok(compute)
                        } else if let (M::Dot, ScalarKind::Float, Some(b)) = (fun, kind, b) {
                            let (a, b, dst) = (a.0 as usize, b.0 as usize, dst as usize);
                            Ok(per_lane(move |regs: &mut LaneRegs| {
                                // `dot`'s order of operations, without copying the operands out.
                                let f = |r: usize| f32::from_bits(regs[r]);
                                let sum = (1..comps).fold(f(a) * f(b), |sum, i| sum + f(a + i) * f(b + i));
                                regs[dst] = sum.to_bits();
                            }))
                        } else {
                            Ok(per_lane(move |regs: &mut LaneRegs| {
                                let mut value = [0u32; 4];
                                let (b, c, d) =
                                    (b.map(|b| slice(regs, b)), c.map(|c| slice(regs, c)), d.map(|d| slice(regs, d)));
                                let words = math(
                                    fun,
                                    kind,
                                    comps,
                                    &slice(regs, a),
                                    b.as_deref(),
                                    c.as_deref(),
                                    d.as_deref(),
                                    &mut value,
                                )
                                .expect("probed");
                                put(regs, dst, len, &value[..words]);
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
    pub(super) fn round_half(&mut self, dst: Reg, len: u32) {
        let (dst, len) = (dst as usize, len as usize);
        self.push(Insn::Compute(per_lane(move |regs: &mut LaneRegs| {
            for r in dst..dst + len {
                regs[r] = arith::round_f16(regs[r]);
            }
        })));
    }
}
