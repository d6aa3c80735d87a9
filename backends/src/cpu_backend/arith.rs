//! Scalar semantics as WGSL defines them (not Rust's): wrapping integer arithmetic,
//! division and remainder by zero, masked shift amounts, saturating float→int
//! conversion, IEEE f32 without fused multiply-add. Values are 32-bit patterns.

#[cfg(test)]
use naga::BinaryOperator;
use naga::{MathFunction, ScalarKind};

fn f(x: u32) -> f32 {
    f32::from_bits(x)
}

#[cfg(test)]
fn b(x: bool) -> u32 {
    u32::from(x)
}

/// `a op b` for one component of kind `kind`; `None` if the operator does not apply.
/// The reference that the bytecode's resolved operators ([`super::insn::BinOp`]) are
/// tested against.
#[cfg(test)]
pub(super) fn binary(op: BinaryOperator, kind: ScalarKind, a: u32, c: u32) -> Option<u32> {
    use BinaryOperator as B;
    use ScalarKind as K;
    let (ia, ic) = (a as i32, c as i32);
    Some(match (op, kind) {
        (B::Add, K::Float) => (f(a) + f(c)).to_bits(),
        (B::Subtract, K::Float) => (f(a) - f(c)).to_bits(),
        (B::Multiply, K::Float) => (f(a) * f(c)).to_bits(),
        (B::Divide, K::Float) => (f(a) / f(c)).to_bits(),
        // WGSL: e1 - e2 * trunc(e1 / e2); Rust's % is fmod (the exact remainder).
        (B::Modulo, K::Float) => (f(a) % f(c)).to_bits(),
        (B::Add, K::Uint | K::Sint) => a.wrapping_add(c),
        (B::Subtract, K::Uint | K::Sint) => a.wrapping_sub(c),
        (B::Multiply, K::Uint | K::Sint) => a.wrapping_mul(c),
        // Division by zero yields the dividend; so does i32::MIN / -1.
        (B::Divide, K::Uint) => a.checked_div(c).unwrap_or(a),
        (B::Divide, K::Sint) => ia.checked_div(ic).unwrap_or(ia) as u32,
        // Remainder by zero (and of i32::MIN by -1) yields 0.
        (B::Modulo, K::Uint) => a.checked_rem(c).unwrap_or(0),
        (B::Modulo, K::Sint) => ia.checked_rem(ic).unwrap_or(0) as u32,
        (B::Equal, K::Float) => b(f(a) == f(c)),
        (B::NotEqual, K::Float) => b(f(a) != f(c)),
        (B::Less, K::Float) => b(f(a) < f(c)),
        (B::LessEqual, K::Float) => b(f(a) <= f(c)),
        (B::Greater, K::Float) => b(f(a) > f(c)),
        (B::GreaterEqual, K::Float) => b(f(a) >= f(c)),
        (B::Equal, _) => b(a == c),
        (B::NotEqual, _) => b(a != c),
        (B::Less, K::Sint) => b(ia < ic),
        (B::LessEqual, K::Sint) => b(ia <= ic),
        (B::Greater, K::Sint) => b(ia > ic),
        (B::GreaterEqual, K::Sint) => b(ia >= ic),
        (B::Less, _) => b(a < c),
        (B::LessEqual, _) => b(a <= c),
        (B::Greater, _) => b(a > c),
        (B::GreaterEqual, _) => b(a >= c),
        (B::And, _) => a & c,
        (B::ExclusiveOr, _) => a ^ c,
        (B::InclusiveOr, _) => a | c,
        (B::LogicalAnd, K::Bool) => b(a != 0 && c != 0),
        (B::LogicalOr, K::Bool) => b(a != 0 || c != 0),
        // Shift amounts are taken modulo the bit width.
        (B::ShiftLeft, K::Uint | K::Sint) => a << (c & 31),
        (B::ShiftRight, K::Uint) => a >> (c & 31),
        (B::ShiftRight, K::Sint) => (ia >> (c & 31)) as u32,
        _ => return None,
    })
}

/// Largest f32 not above i32::MAX, and not above u32::MAX.
const I32_MAX_F32: f32 = 2_147_483_520.0;
const U32_MAX_F32: f32 = 4_294_967_040.0;

/// Numeric conversion as WGSL defines it. Float → int truncates after clamping to the
/// range of floats that the integer type represents (so `u32(4294967296.0)` is
/// 4294967040, not u32::MAX); NaN → 0 (implementation-defined in WGSL: D3D and
/// WebAssembly also give 0, lavapipe's x86 conversion gives i32::MIN).
#[inline]
pub(super) fn convert(value: u32, from: ScalarKind, to: ScalarKind) -> Option<u32> {
    use ScalarKind as K;
    Some(match (from, to) {
        (K::Float, K::Sint) => (f(value).clamp(-2_147_483_648.0, I32_MAX_F32) as i32) as u32,
        (K::Float, K::Uint) => f(value).clamp(0.0, U32_MAX_F32) as u32,
        (K::Sint, K::Float) => (value as i32 as f32).to_bits(),
        (K::Uint, K::Float) => (value as f32).to_bits(),
        (K::Bool, K::Float) => {
            if value != 0 {
                1.0f32.to_bits()
            } else {
                0
            }
        }
        (K::Bool, K::Uint | K::Sint) => u32::from(value != 0),
        (K::Float, K::Bool) => u32::from(f(value) != 0.0),
        (K::Uint | K::Sint, K::Bool) => u32::from(value != 0),
        (K::Uint | K::Sint, K::Uint | K::Sint) | (K::Float, K::Float) | (K::Bool, K::Bool) => value,
        _ => return None,
    })
}

/// Component-wise math functions of up to three arguments. `None`: not supported here.
///
/// Implementation choices where WGSL leaves results implementation-defined: `min`/`max`
/// of a NaN return the other operand (Rust's `f32::min`), transcendental functions use
/// Rust's `f32` functions (correctly rounded or within a few ULP on glibc), `round` rounds
/// half to even as WGSL requires.
#[inline]
pub(super) fn math(fun: MathFunction, kind: ScalarKind, x: u32, y: u32, z: u32) -> Option<u32> {
    use MathFunction as M;
    use ScalarKind as K;
    let (ix, iy, iz) = (x as i32, y as i32, z as i32);
    Some(match (fun, kind) {
        (M::Abs, K::Float) => f(x).abs().to_bits(),
        (M::Abs, K::Sint) => ix.wrapping_abs() as u32,
        (M::Abs, K::Uint) => x,
        (M::Min, K::Float) => f(x).min(f(y)).to_bits(),
        (M::Min, K::Sint) => ix.min(iy) as u32,
        (M::Min, K::Uint) => x.min(y),
        (M::Max, K::Float) => f(x).max(f(y)).to_bits(),
        (M::Max, K::Sint) => ix.max(iy) as u32,
        (M::Max, K::Uint) => x.max(y),
        (M::Clamp, K::Float) => f(x).max(f(y)).min(f(z)).to_bits(),
        (M::Clamp, K::Sint) => ix.max(iy).min(iz) as u32,
        (M::Clamp, K::Uint) => x.max(y).min(z),
        (M::Saturate, K::Float) => f(x).clamp(0.0, 1.0).to_bits(),
        (M::Floor, K::Float) => f(x).floor().to_bits(),
        (M::Ceil, K::Float) => f(x).ceil().to_bits(),
        (M::Round, K::Float) => f(x).round_ties_even().to_bits(),
        (M::Trunc, K::Float) => f(x).trunc().to_bits(),
        (M::Fract, K::Float) => (f(x) - f(x).floor()).to_bits(),
        (M::Sqrt, K::Float) => f(x).sqrt().to_bits(),
        (M::InverseSqrt, K::Float) => (1.0 / f(x).sqrt()).to_bits(),
        (M::Exp, K::Float) => f(x).exp().to_bits(),
        (M::Exp2, K::Float) => f(x).exp2().to_bits(),
        (M::Log, K::Float) => f(x).ln().to_bits(),
        (M::Log2, K::Float) => f(x).log2().to_bits(),
        (M::Pow, K::Float) => f(x).powf(f(y)).to_bits(),
        (M::Sin, K::Float) => f(x).sin().to_bits(),
        (M::Cos, K::Float) => f(x).cos().to_bits(),
        (M::Tan, K::Float) => f(x).tan().to_bits(),
        (M::Asin, K::Float) => f(x).asin().to_bits(),
        (M::Acos, K::Float) => f(x).acos().to_bits(),
        (M::Atan, K::Float) => f(x).atan().to_bits(),
        (M::Atan2, K::Float) => f(x).atan2(f(y)).to_bits(),
        (M::Asinh, K::Float) => f(x).asinh().to_bits(),
        (M::Acosh, K::Float) => f(x).acosh().to_bits(),
        (M::Atanh, K::Float) => f(x).atanh().to_bits(),
        (M::Radians, K::Float) => (f(x) * (std::f32::consts::PI / 180.0)).to_bits(),
        (M::Degrees, K::Float) => (f(x) * (180.0 / std::f32::consts::PI)).to_bits(),
        // x · 2^e, exact until the single rounding to f32 (f64 holds every f32 times any
        // power of two in ±400 exactly; beyond that the result saturates anyway).
        (M::Ldexp, K::Float) => ((f64::from(f(x)) * 2f64.powi(iy.clamp(-400, 400))) as f32).to_bits(),
        (M::Sinh, K::Float) => f(x).sinh().to_bits(),
        (M::Cosh, K::Float) => f(x).cosh().to_bits(),
        (M::Tanh, K::Float) => f(x).tanh().to_bits(),
        (M::Sign, K::Float) => {
            let v = f(x);
            (if v > 0.0 {
                1.0f32
            } else if v < 0.0 {
                -1.0
            } else {
                0.0
            })
            .to_bits()
        }
        (M::Sign, K::Sint) => ix.signum() as u32,
        (M::Step, K::Float) => (if f(y) >= f(x) { 1.0f32 } else { 0.0 }).to_bits(),
        (M::Mix, K::Float) => (f(x) * (1.0 - f(z)) + f(y) * f(z)).to_bits(),
        (M::SmoothStep, K::Float) => {
            let t = ((f(z) - f(x)) / (f(y) - f(x))).clamp(0.0, 1.0);
            (t * t * (3.0 - 2.0 * t)).to_bits()
        }
        // Fused: one rounding, as WGSL's fma allows and Rust's mul_add guarantees.
        (M::Fma, K::Float) => f(x).mul_add(f(y), f(z)).to_bits(),
        // Through binary16 and back: round to nearest even, overflow to ±Inf.
        (M::QuantizeToF16, K::Float) => f16_to_f32(f32_to_f16(x)),
        (M::CountTrailingZeros, K::Uint | K::Sint) => x.trailing_zeros(),
        (M::CountLeadingZeros, K::Uint | K::Sint) => x.leading_zeros(),
        (M::CountOneBits, K::Uint | K::Sint) => x.count_ones(),
        (M::ReverseBits, K::Uint | K::Sint) => x.reverse_bits(),
        (M::FirstTrailingBit, K::Uint | K::Sint) => {
            if x == 0 {
                u32::MAX
            } else {
                x.trailing_zeros()
            }
        }
        (M::FirstLeadingBit, K::Uint) => {
            if x == 0 {
                u32::MAX
            } else {
                31 - x.leading_zeros()
            }
        }
        (M::FirstLeadingBit, K::Sint) => {
            let v = if ix < 0 { !x } else { x };
            if v == 0 { u32::MAX } else { 31 - v.leading_zeros() }
        }
        _ => return None,
    })
}

/// The binary16 nearest to f32 `x` (ties to even; too large: ±Inf; NaN stays NaN,
/// quiet, with the sign and the top payload bits kept).
pub(super) fn f32_to_f16(x: u32) -> u32 {
    u32::from(half::f16::from_f32(f(x)).to_bits())
}

/// The f32 equal to binary16 `h` (the low 16 bits; exact, denormals included).
pub(super) fn f16_to_f32(h: u32) -> u32 {
    half::f16::from_bits(h as u16).to_f32().to_bits()
}

/// Rounds an f32 to the nearest binary16 value, as an f32 (how registers hold f16).
pub(super) fn round_f16(x: u32) -> u32 {
    f16_to_f32(f32_to_f16(x))
}

/// Numeric conversion where the source or the target is an f16 (held as the f32 of
/// equal value). Integers → f16 round once (through f64, which holds them exactly);
/// f16 → integer truncates after clamping to the range both types hold (±Inf → ±65504
/// as naga's clamp bounds for f16 make it), NaN → 0. `None`: unsupported.
pub(super) fn convert_half(value: u32, from: naga::Scalar, to: naga::Scalar) -> Option<u32> {
    use ScalarKind as K;
    let half = |s: naga::Scalar| s.kind == K::Float && s.width == 2;
    let plain = |s: naga::Scalar| s.width == 4 || s.kind == K::Bool || half(s);
    if !plain(from) || !plain(to) {
        return None;
    }
    let round64 = |v: f64| half::f16::from_f64(v).to_f32().to_bits();
    Some(match (from.kind, to.kind) {
        (K::Float, K::Float) if half(to) => round_f16(value),
        (K::Float, K::Float) => value,
        (K::Float, K::Sint) => convert(f(value).clamp(-65504.0, 65504.0).to_bits(), K::Float, K::Sint)?,
        (K::Float, K::Uint) => convert(f(value).clamp(0.0, 65504.0).to_bits(), K::Float, K::Uint)?,
        (K::Sint, K::Float) => round64(f64::from(value as i32)),
        (K::Uint, K::Float) => round64(f64::from(value)),
        _ => convert(value, from.kind, to.kind)?,
    })
}

/// `modf(x)`: (fract, whole) with whole = trunc(x) and fract = x - whole, both with
/// x's sign. Where WGSL leaves the sign of a zero or a NaN's bits open, the choices are
/// lavapipe's (Mesa computes sign(x) · (|x| - floor|x|) and sign(x) · floor|x|): ±0 gives
/// (+0, +0), ±Inf gives (±0, ±Inf), a NaN gives its quiet, positive self twice.
pub(super) fn modf(x: u32) -> (u32, u32) {
    let v = f(x);
    if v.is_nan() {
        let nan = (x & 0x7fff_ffff) | 0x0040_0000;
        return (nan, nan);
    }
    if v == 0.0 {
        return (0, 0);
    }
    let whole = v.trunc();
    let fract = if v.is_infinite() { 0.0f32.copysign(v) } else { (v - whole).copysign(v) };
    (fract.to_bits(), whole.to_bits())
}

/// `frexp(x)`: (fract, exp) with x = fract · 2^exp and |fract| in [0.5, 1); a
/// denormal is normalised first. ±0 gives (±0, 0); ±Inf and NaN (undefined in WGSL)
/// give (x, 129), the exponent field less 126, as lavapipe does.
pub(super) fn frexp(x: u32) -> (u32, u32) {
    let v = f(x);
    if v == 0.0 {
        return (x, 0);
    }
    if !v.is_finite() {
        return (x, 129);
    }
    // A denormal is scaled into the normal range first (exactly: by 2^32).
    let (bits, bias) = if (x >> 23) & 0xff == 0 { ((v * 4_294_967_296.0).to_bits(), 32) } else { (x, 0) };
    let exponent = ((bits >> 23) & 0xff) as i32 - 126 - bias;
    ((bits & 0x807f_ffff) | (126 << 23), exponent as u32)
}

/// `extractBits(e, offset, count)` and `insertBits(e, newbits, offset, count)`.
pub(super) fn bits(fun: MathFunction, kind: ScalarKind, e: u32, a: u32, b2: u32, c: u32) -> Option<u32> {
    match fun {
        MathFunction::ExtractBits => {
            let offset = a.min(32);
            let count = b2.min(32 - offset);
            if count == 0 {
                return Some(0);
            }
            let field = (e >> offset) & if count == 32 { u32::MAX } else { (1 << count) - 1 };
            Some(if kind == ScalarKind::Sint && count < 32 && field >> (count - 1) & 1 == 1 {
                field | !((1 << count) - 1)
            } else {
                field
            })
        }
        MathFunction::InsertBits => {
            let offset = b2.min(32);
            let count = c.min(32 - offset);
            if count == 0 {
                return Some(e);
            }
            let mask = (if count == 32 { u32::MAX } else { (1 << count) - 1 }) << offset;
            Some((e & !mask) | ((a << offset) & mask))
        }
        _ => None,
    }
}

/// `pack*` builtins: a vector of floats (or integers) into one u32. `None`: not a pack.
pub(super) fn pack(fun: MathFunction, v: &[u32]) -> Option<u32> {
    use MathFunction as M;
    let unorm = |x: u32, max: f32| (f(x).clamp(0.0, 1.0) * max).round_ties_even() as u32;
    let snorm = |x: u32, max: f32| ((f(x).clamp(-1.0, 1.0) * max).round_ties_even() as i32) as u32;
    Some(match fun {
        M::Pack4x8unorm => (0..4).fold(0, |acc, i| acc | (unorm(v[i], 255.0) & 0xff) << (8 * i)),
        M::Pack4x8snorm => (0..4).fold(0, |acc, i| acc | (snorm(v[i], 127.0) & 0xff) << (8 * i)),
        M::Pack2x16unorm => (0..2).fold(0, |acc, i| acc | (unorm(v[i], 65535.0) & 0xffff) << (16 * i)),
        M::Pack2x16snorm => (0..2).fold(0, |acc, i| acc | (snorm(v[i], 32767.0) & 0xffff) << (16 * i)),
        // WGSL: the binary16 values of v[0] (low half) and v[1] (high half).
        M::Pack2x16float => f32_to_f16(v[0]) | f32_to_f16(v[1]) << 16,
        M::Pack4xI8 => (0..4).fold(0, |acc, i| acc | (v[i] & 0xff) << (8 * i)),
        M::Pack4xU8 => (0..4).fold(0, |acc, i| acc | (v[i] & 0xff) << (8 * i)),
        M::Pack4xI8Clamp => (0..4).fold(0, |acc, i| acc | ((v[i] as i32).clamp(-128, 127) as u32 & 0xff) << (8 * i)),
        M::Pack4xU8Clamp => (0..4).fold(0, |acc, i| acc | v[i].min(255) << (8 * i)),
        _ => return None,
    })
}

/// `unpack*` builtins: one u32 into a vector. `None`: not an unpack.
pub(super) fn unpack(fun: MathFunction, x: u32) -> Option<Vec<u32>> {
    use MathFunction as M;
    let byte = |i: u32| (x >> (8 * i)) & 0xff;
    let half = |i: u32| (x >> (16 * i)) & 0xffff;
    Some(match fun {
        M::Unpack4x8unorm => (0..4).map(|i| (byte(i) as f32 / 255.0).to_bits()).collect(),
        M::Unpack4x8snorm => (0..4).map(|i| ((byte(i) as u8 as i8 as f32 / 127.0).max(-1.0)).to_bits()).collect(),
        M::Unpack2x16unorm => (0..2).map(|i| (half(i) as f32 / 65535.0).to_bits()).collect(),
        M::Unpack2x16snorm => (0..2).map(|i| ((half(i) as u16 as i16 as f32 / 32767.0).max(-1.0)).to_bits()).collect(),
        M::Unpack2x16float => (0..2).map(|i| f16_to_f32(half(i))).collect(),
        M::Unpack4xI8 => (0..4).map(|i| byte(i) as u8 as i8 as i32 as u32).collect(),
        M::Unpack4xU8 => (0..4).map(byte).collect(),
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use BinaryOperator as B;
    use ScalarKind as K;

    #[test]
    fn wgsl_integer_edge_cases() {
        assert_eq!(binary(B::Divide, K::Uint, 7, 0), Some(7));
        assert_eq!(binary(B::Divide, K::Sint, i32::MIN as u32, -1i32 as u32), Some(i32::MIN as u32));
        assert_eq!(binary(B::Modulo, K::Sint, 7, 0), Some(0));
        assert_eq!(binary(B::Modulo, K::Sint, -7i32 as u32, 3), Some(-1i32 as u32));
        assert_eq!(binary(B::ShiftLeft, K::Uint, 1, 33), Some(2));
        assert_eq!(binary(B::ShiftRight, K::Sint, -8i32 as u32, 1), Some(-4i32 as u32));
        assert_eq!(binary(B::Add, K::Uint, u32::MAX, 2), Some(1));
    }

    #[test]
    fn wgsl_float_conversions_saturate() {
        assert_eq!(convert(f32::NAN.to_bits(), K::Float, K::Sint), Some(0));
        assert_eq!(convert(1e20f32.to_bits(), K::Float, K::Sint), Some(2_147_483_520));
        assert_eq!(convert(4_294_967_296.0f32.to_bits(), K::Float, K::Uint), Some(4_294_967_040));
        assert_eq!(convert((-5.0f32).to_bits(), K::Float, K::Uint), Some(0));
        assert_eq!(math(MathFunction::Round, K::Float, 2.5f32.to_bits(), 0, 0), Some(2.0f32.to_bits()));
        assert_eq!(math(MathFunction::CountTrailingZeros, K::Uint, 0, 0, 0), Some(32));
        assert_eq!(bits(MathFunction::ExtractBits, K::Sint, 0b1100, 2, 2, 0), Some(u32::MAX));
        assert_eq!(bits(MathFunction::InsertBits, K::Uint, 0, 0b11, 4, 2), Some(0b110000));
    }
}
