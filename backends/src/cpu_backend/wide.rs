//! 64-bit integers (`i64`, `u64`): two words per scalar, the low word first (the
//! storage layout's byte order), with WGSL's semantics as for 32 bits: wrapping
//! arithmetic, division and remainder by zero (and of `i64::MIN` by -1) giving the
//! dividend and 0, shift amounts (`u32`) taken modulo 64, float → integer conversion
//! clamped to the largest float the type holds. These lower to closures
//! ([`super::insn::Compute`]): rare enough that the dispatch loop need not know them.

use super::lanes::LaneRegs;
use naga::{BinaryOperator, Scalar, ScalarKind};

/// Reads the 64-bit value at word `at` of `regs`.
#[inline(always)]
pub(super) fn read(regs: &LaneRegs, at: usize) -> u64 {
    u64::from(regs[at]) | u64::from(regs[at + 1]) << 32
}

/// Writes a 64-bit value at word `at` of `regs`.
#[inline(always)]
pub(super) fn write(regs: &mut LaneRegs, at: usize, value: u64) {
    regs[at] = value as u32;
    regs[at + 1] = (value >> 32) as u32;
}

/// The result of a binary operator on one component.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Out {
    /// A 64-bit integer.
    Wide(u64),
    /// A comparison's bool.
    Bool(bool),
}

/// `a op c` on 64-bit components (`c` is the `u32` shift amount for shifts); `None`
/// where WGSL has no such operator.
pub(super) fn binary(op: BinaryOperator, signed: bool, a: u64, c: u64) -> Option<Out> {
    use BinaryOperator as B;
    use Out::{Bool, Wide};
    let (ia, ic) = (a as i64, c as i64);
    Some(match op {
        B::Add => Wide(a.wrapping_add(c)),
        B::Subtract => Wide(a.wrapping_sub(c)),
        B::Multiply => Wide(a.wrapping_mul(c)),
        // Division by zero (and i64::MIN / -1) yields the dividend.
        B::Divide if signed => Wide(ia.checked_div(ic).unwrap_or(ia) as u64),
        B::Divide => Wide(a.checked_div(c).unwrap_or(a)),
        // Remainder by zero (and of i64::MIN by -1) yields 0.
        B::Modulo if signed => Wide(ia.checked_rem(ic).unwrap_or(0) as u64),
        B::Modulo => Wide(a.checked_rem(c).unwrap_or(0)),
        B::Equal => Bool(a == c),
        B::NotEqual => Bool(a != c),
        B::Less if signed => Bool(ia < ic),
        B::LessEqual if signed => Bool(ia <= ic),
        B::Greater if signed => Bool(ia > ic),
        B::GreaterEqual if signed => Bool(ia >= ic),
        B::Less => Bool(a < c),
        B::LessEqual => Bool(a <= c),
        B::Greater => Bool(a > c),
        B::GreaterEqual => Bool(a >= c),
        B::And => Wide(a & c),
        B::ExclusiveOr => Wide(a ^ c),
        B::InclusiveOr => Wide(a | c),
        B::ShiftLeft => Wide(a << (c & 63)),
        B::ShiftRight if signed => Wide((ia >> (c & 63)) as u64),
        B::ShiftRight => Wide(a >> (c & 63)),
        B::LogicalAnd | B::LogicalOr => return None,
    })
}

/// Largest f32 not above i64::MAX, and not above u64::MAX.
const I64_MAX_F32: f32 = 9_223_371_487_098_961_920.0;
const U64_MAX_F32: f32 = 18_446_742_974_197_923_840.0;

/// Whether `scalar` is a 64-bit integer.
pub(super) fn is_wide(scalar: Scalar) -> bool {
    scalar.width == 8 && matches!(scalar.kind, ScalarKind::Sint | ScalarKind::Uint)
}

/// Numeric conversion between scalars of which at least one is a 64-bit integer; the
/// source's bits in `value` (one word zero-extended, or two). `None`: unsupported.
/// Integers widen by their own signedness (`i32` sign-extends, `u32` zero-extends),
/// narrow by keeping the low bits; integers → f32 round to nearest even; f32 → integer
/// truncates after clamping as WGSL says (NaN → 0, as for 32 bits).
pub(super) fn convert(value: u64, from: Scalar, to: Scalar) -> Option<u64> {
    use ScalarKind as K;
    let supported = |s: Scalar| matches!((s.kind, s.width), (K::Sint | K::Uint, 4 | 8) | (K::Float, 4) | (K::Bool, _));
    if !supported(from) || !supported(to) {
        return None;
    }
    let float = f32::from_bits(value as u32);
    // The source as a 64-bit integer pattern (floats handled apart).
    let integer = match (from.kind, from.width) {
        (K::Sint, 4) => value as u32 as i32 as i64 as u64,
        (K::Bool, _) => u64::from(value != 0),
        _ => value,
    };
    Some(match (from.kind, to.kind, to.width) {
        (K::Float, K::Sint, 8) => float.clamp(-9_223_372_036_854_775_808.0, I64_MAX_F32) as i64 as u64,
        (K::Float, K::Uint, 8) => float.clamp(0.0, U64_MAX_F32) as u64,
        (K::Float, K::Sint | K::Uint, _) => {
            return super::arith::convert(value as u32, K::Float, to.kind).map(u64::from);
        }
        (K::Float, K::Float, _) => value,
        (K::Float, K::Bool, _) => u64::from(float != 0.0),
        (K::Sint, K::Float, _) => u64::from((integer as i64 as f32).to_bits()),
        (K::Uint | K::Bool, K::Float, _) => u64::from((integer as f32).to_bits()),
        (_, K::Bool, _) => u64::from(integer != 0),
        (_, K::Sint | K::Uint, 8) => integer,
        (_, K::Sint | K::Uint, _) => integer & 0xffff_ffff,
        _ => return None,
    })
}

/// Component-wise math functions on 64-bit integers: `abs`, `min`, `max`, `clamp`,
/// `sign`. `None`: unsupported.
pub(super) fn math(fun: naga::MathFunction, signed: bool, x: u64, y: u64, z: u64) -> Option<u64> {
    use naga::MathFunction as M;
    let (ix, iy, iz) = (x as i64, y as i64, z as i64);
    Some(match (fun, signed) {
        (M::Abs, true) => ix.wrapping_abs() as u64,
        (M::Abs, false) => x,
        (M::Min, true) => ix.min(iy) as u64,
        (M::Min, false) => x.min(y),
        (M::Max, true) => ix.max(iy) as u64,
        (M::Max, false) => x.max(y),
        (M::Clamp, true) => ix.max(iy).min(iz) as u64,
        (M::Clamp, false) => x.max(y).min(z),
        (M::Sign, true) => ix.signum() as u64,
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use BinaryOperator as B;

    #[test]
    fn wgsl_edge_cases_at_64_bits() {
        let min = i64::MIN as u64;
        assert_eq!(binary(B::Divide, true, min, u64::MAX), Some(Out::Wide(min)));
        assert_eq!(binary(B::Divide, false, 7, 0), Some(Out::Wide(7)));
        assert_eq!(binary(B::Modulo, true, min, u64::MAX), Some(Out::Wide(0)));
        assert_eq!(binary(B::ShiftLeft, false, 1, 65), Some(Out::Wide(2)));
        assert_eq!(binary(B::ShiftRight, true, min, 63), Some(Out::Wide(u64::MAX)));
        let s = |kind, width| Scalar { kind, width };
        let (f32s, i64s, u64s, i32s) =
            (s(ScalarKind::Float, 4), s(ScalarKind::Sint, 8), s(ScalarKind::Uint, 8), s(ScalarKind::Sint, 4));
        assert_eq!(convert(u64::from(1e30f32.to_bits()), f32s, i64s), Some(I64_MAX_F32 as i64 as u64));
        assert_eq!(convert(u64::from((-1.0f32).to_bits()), f32s, u64s), Some(0));
        assert_eq!(convert(u64::from(f32::NAN.to_bits()), f32s, i64s), Some(0));
        assert_eq!(convert(0xffff_ffff, i32s, i64s), Some(u64::MAX));
        assert_eq!(convert(u64::MAX, i64s, i32s), Some(0xffff_ffff));
        assert_eq!(convert(u64::MAX, u64s, f32s), Some(u64::from(1.844_674_4e19f32.to_bits())));
    }
}
