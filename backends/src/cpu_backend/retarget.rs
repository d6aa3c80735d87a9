//! Store forwarding: a value computed by the instruction just before its only use, a
//! store into a local variable or an inlined callee's `return`, is computed straight
//! into the variable's (or the call result's) registers instead of its own and then
//! copied.
//!
//! Why: naga IR loads a variable into a new expression and stores an expression into a
//! variable, so `top1 = top0;` or `i = i + 1u;` compiled word for word ends with a copy.
//! In the path tracer a fifth of the executed instructions were such copies.
//!
//! Sound because the value has no other use (its naga reference count is 1: the store),
//! so nothing reads its own registers afterwards; the instruction is the only one
//! that computed it (tracked by [`Compiler::last_value`]); and the instruction still
//! reads the same operands once its destination moves. The instruction computes each
//! destination word from the same words of its operands or reads all of them first, so an
//! operand may equal the new destination but must not partly overlap it (checked per
//! instruction kind, [`retargetable`]).

use super::compiler::{Compiler, LastValue, Scope};
use super::insn::{Insn, Reg};
use naga::{Expression, Handle};

impl Compiler<'_> {
    /// Makes the instruction that computed `value` (`len` words) write `dst` instead, if
    /// `value` of `scope` was the last expression compiled, by one instruction, and has
    /// no other use. True if it did (the caller then emits no copy).
    pub(super) fn retarget_last(&mut self, scope: &Scope, value: Handle<Expression>, dst: Reg, len: u32) -> bool {
        let Some(last) = self.last_value.take() else { return false };
        let index = value.index();
        if last != LastValue::new(scope, value, self.insns.len().wrapping_sub(1))
            || scope.info[value].ref_count != 1
            || scope.lens[index] != len
            || scope.constant[index]
        {
            return false;
        }
        let Some(insn) = self.insns.last_mut() else { return false };
        retargetable(insn, scope.regs[index], dst, len)
    }
}

/// Rewrites `insn`, which writes `len` words at `src`, to write them at `dst`, if it
/// writes exactly those words and reads no operand that partly overlaps `dst..dst +
/// len`; false (unchanged) otherwise.
fn retargetable(insn: &mut Insn, src: Reg, dst: Reg, len: u32) -> bool {
    let end = dst + len;
    // An operand of `words` words read with `stride` per destination word: elementwise
    // from the same words (equal ranges, stride 1) or not overlapping at all.
    let fits = |operand: Reg, words: u32, stride: u8| {
        (operand == dst && stride == 1 && words == len) || operand + words.max(1) <= dst || end <= operand
    };
    let apart = |operand: Reg, words: u32| operand + words.max(1) <= dst || end <= operand;
    let span = |n: u8, stride: u8| if stride == 0 { 1 } else { u32::from(n) };
    let (target, ok) = match insn {
        Insn::Copy1 { dst: d, src: s } if len == 1 => (d, fits(*s, 1, 1)),
        Insn::Copy2 { dst: d, src: s } if len == 2 => (d, fits(*s, 2, 1)),
        Insn::Copy3 { dst: d, src: s } if len == 3 => (d, fits(*s, 3, 1)),
        Insn::Copy4 { dst: d, src: s } if len == 4 => (d, fits(*s, 4, 1)),
        Insn::Copy { dst: d, src: s, len: n } if *n == len => (d, fits(*s, len, 1)),
        Insn::Zero { dst: d, len: n } if *n == len => (d, true),
        Insn::Bin { dst: d, a, b, .. } if len == 1 => (d, fits(*a, 1, 1) && fits(*b, 1, 1)),
        Insn::BinV { dst: d, a, b, n, sa, sb, .. } if u32::from(*n) == len => {
            (d, fits(*a, span(*n, *sa), *sa) && fits(*b, span(*n, *sb), *sb))
        }
        Insn::Un { dst: d, src: s, n, .. } | Insn::Convert { dst: d, src: s, n, .. } if u32::from(*n) == len => {
            (d, fits(*s, len, 1))
        }
        Insn::Select { dst: d, cond, accept, reject, n, sc } if u32::from(*n) == len => {
            (d, fits(*cond, span(*n, *sc), *sc) && fits(*accept, len, 1) && fits(*reject, len, 1))
        }
        Insn::Splat { dst: d, src: s, n } if u32::from(*n) == len => (d, apart(*s, 1)),
        Insn::Swizzle { dst: d, src: s, n, .. } if u32::from(*n) == len => (d, apart(*s, 4)),
        Insn::Load { dst: d, pointer, len: n } if *n == len => (d, apart(*pointer, 2)),
        Insn::LoadElement(load) if load.len == len && load.runs.is_none() => {
            let index = load.index;
            (&mut load.dst, apart(index, 1))
        }
        Insn::LoadBuffer { dst: d, len: n, .. }
        | Insn::LoadPrivate { dst: d, len: n, .. }
        | Insn::LoadWorkgroup { dst: d, len: n, .. }
            if *n == len =>
        {
            (d, true)
        }
        _ => return false,
    };
    if *target != src || !ok {
        return false;
    }
    *target = dst;
    true
}

#[cfg(test)]
mod tests {
    use super::super::decode::tests::compiled;
    use super::*;

    fn copies(body: &str) -> usize {
        compiled(body).iter().filter(|i| matches!(i, Insn::Copy1 { .. })).count()
    }

    /// The copies of a kernel that declares `a` and stores it into the buffer.
    fn baseline() -> usize {
        copies("var a = 0u; data[id.x] = a;")
    }

    #[test]
    fn stored_values_are_computed_in_place() {
        // The load of `a` for `a * 3u` reads in place (`load_alias`); the two stores
        // copy nothing.
        assert_eq!(copies("var a = 0u; a = x + 1u; a = a * 3u; data[id.x] = a;"), baseline());
    }

    #[test]
    fn values_used_again_keep_their_registers() {
        // `y` is read after the store: computed into its own registers, then copied.
        assert_eq!(copies("var a = 0u; let y = x + 1u; a = y; data[id.x] = a + y;"), baseline() + 1);
    }
}
