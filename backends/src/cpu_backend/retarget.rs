//! Store forwarding: a value computed by the instruction just before its only use, a
//! store into a local variable or an inlined callee's `return`, is computed straight
//! into the variable's (or the call result's) registers instead of its own and then
//! copied. And a value of several instructions (a struct composed, a call's result)
//! that an inlined callee returns right after computing it is given the call result's
//! registers from the start ([`Scope::return_in_place`]); a call result that such a
//! record takes whole, word for word, is given its words of the record's registers in
//! turn ([`Compiler::components_in_place`]).
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

use super::compiler::{Compiler, LastValue, NONE, Scope};
use super::constant::compose_offsets;
use super::insn::{Insn, Reg};
use super::layout::consecutive;
use naga::{Block, Expression, Handle, Statement, TypeInner};

impl Scope<'_> {
    /// Gives the call result's registers (`dst`, `words` words) to every value of this
    /// scope (an inlined callee's) that a `return` right after it returns and nothing else
    /// uses: a struct composed (`return Node(r0.xyz, ...)`) or a call's result (`return
    /// read_node(...)`), which store forwarding cannot move (several instructions compute
    /// them). Why: the generated row readers (gpu/scene_rows.wgsl) and their callers
    /// (render/scene.wgsl's `bvh_node`) return such values; each return copied the whole
    /// record, twice per BVH node the path tracer visits (issue 59).
    ///
    /// Sound because the value is computed by the statement just before its `return` (the
    /// `Emit` holding it, or the `Call`) and used by nothing else (naga reference count 1),
    /// so the result registers, which nothing else in the callee writes, hold it from its
    /// computation to the return; several such returns (in different branches) each write
    /// them just before returning. Its operands are never the result registers: only values
    /// returned are given them, and a returned value is used by nothing else; the parts
    /// that also lie in them (a call result placed by [`Compiler::components_in_place`],
    /// a component computed in place by `compose_in_place`) are used by the record alone
    /// and computed just before it.
    ///
    /// Returns the values given the registers.
    pub(super) fn return_in_place(&mut self, dst: Reg, words: u32) -> Vec<Handle<Expression>> {
        fn visit(scope: &mut Scope, block: &Block, dst: Reg, words: u32, placed: &mut Vec<Handle<Expression>>) {
            let mut before: Option<&Statement> = None;
            for statement in block.iter() {
                match statement {
                    Statement::Return { value: Some(value) } => {
                        let computed_just_before = match before {
                            Some(Statement::Emit(range)) => range.clone().any(|h| h == *value),
                            Some(Statement::Call { result: Some(result), .. }) => result == value,
                            _ => false,
                        };
                        let index = value.index();
                        if computed_just_before
                            && matches!(
                                scope.function.expressions[*value],
                                Expression::Compose { .. } | Expression::CallResult(_)
                            )
                            && scope.info[*value].ref_count == 1
                            && scope.lens[index] == words
                            && scope.regs[index] == NONE
                            && !scope.pre_emitted[index]
                        {
                            scope.regs[index] = dst;
                            placed.push(*value);
                        }
                    }
                    Statement::Block(inner) => visit(scope, inner, dst, words, placed),
                    Statement::If { accept, reject, .. } => {
                        visit(scope, accept, dst, words, placed);
                        visit(scope, reject, dst, words, placed);
                    }
                    Statement::Switch { cases, .. } => {
                        for case in cases {
                            visit(scope, &case.body, dst, words, placed);
                        }
                    }
                    Statement::Loop { body, continuing, .. } => {
                        visit(scope, body, dst, words, placed);
                        visit(scope, continuing, dst, words, placed);
                    }
                    _ => {}
                }
                before = Some(statement);
            }
        }
        let function = self.function;
        let mut placed = Vec::new();
        visit(self, &function.body, dst, words, &mut placed);
        placed
    }
}

/// How many `return`s with a value `block` holds, nested blocks included.
fn valued_returns(block: &Block) -> usize {
    block
        .iter()
        .map(|statement| match statement {
            Statement::Return { value: Some(_) } => 1,
            Statement::Block(inner) => valued_returns(inner),
            Statement::If { accept, reject, .. } => valued_returns(accept) + valued_returns(reject),
            Statement::Switch { cases, .. } => cases.iter().map(|case| valued_returns(&case.body)).sum(),
            Statement::Loop { body, continuing, .. } => valued_returns(body) + valued_returns(continuing),
            _ => 0,
        })
        .sum()
}

impl Compiler<'_> {
    /// Gives each call result that `record`, a composition already placed by
    /// [`Scope::return_in_place`], takes whole, word for word, the words of the composition
    /// where it lands: the row readers' `return Node(bitcast<vec3<f32>>(r0.xyz), r0.w,
    /// ...)` then reads its rows (`let r0 = scene_row(row);`) straight into the call result's
    /// registers, and the composition copies nothing. Why: those copies were about half the
    /// words the path tracer copied, 12 words per BVH node visited (issue 59).
    ///
    /// A call result `r` is placed at word `at` of the composition when its components
    /// that come from `r`, through bitcasts of the same size, consecutive swizzles and
    /// components of 32-bit vectors, take `r`'s words in order to words `at..at + len` of
    /// the composition, and nothing else uses `r` or anything on those paths (naga
    /// reference counts).
    ///
    /// Only in a callee with a single `return` of a value. Sound because the
    /// composition's registers are the call result's, which nothing else in this callee
    /// writes ([`Scope::return_in_place`]; with one `return`, one record); `r`'s
    /// words are read only by the composition's components; and each word of `r` is the
    /// word the composition puts there, so its copies of `r` go onto themselves (which
    /// [`Compiler::copy`] drops), and its other components' copies write words outside
    /// `r`'s.
    pub(super) fn components_in_place(&self, scope: &mut Scope, record: Handle<Expression>) {
        let function = scope.function;
        // With two returns, two records share the result's registers, and a call result
        // placed for one would be overwritten by one placed for the other while both are
        // alive (`let r = row(i); let s = row(i + 4u); if c { return Two(s, 1u); }
        // return Two(r, 2u);`). The row readers have one.
        if valued_returns(&function.body) != 1 {
            return;
        }
        let Expression::Compose { ref components, .. } = function.expressions[record] else { return };
        let (dst, len) = (scope.regs[record.index()], scope.lens[record.index()]);
        let lens: Vec<u32> = components.iter().map(|c| scope.lens[c.index()]).collect();
        let Ok(offsets) = compose_offsets(self.module, self.ty(scope, record), &lens) else { return };
        /// A call result met among the components so far.
        struct Run {
            root: Handle<Expression>,
            /// The composition's word that its first word lands on.
            origin: i64,
            /// Its words taken so far, in order.
            words: u32,
            /// The components taken from it (its uses that the composition accounts for).
            uses: usize,
        }
        let mut runs: Vec<Run> = Vec::new();
        let mut rejected: Vec<Handle<Expression>> = Vec::new();
        for (&component, (&at, &words)) in components.iter().zip(offsets.iter().zip(&lens)) {
            let Some((root, first)) = self.word_source(scope, component) else { continue };
            let origin = i64::from(at) - i64::from(first);
            match runs.iter_mut().find(|run| run.root == root) {
                // The next words of `root`, at the next words of the composition.
                Some(run) if run.origin == origin && run.words == first => {
                    run.words += words;
                    run.uses += 1;
                }
                None if first == 0 => runs.push(Run { root, origin, words, uses: 1 }),
                _ => rejected.push(root),
            }
        }
        for Run { root, origin, words, uses } in runs {
            let index = root.index();
            if !rejected.contains(&root)
                && words == scope.lens[index]
                && uses == scope.info[root].ref_count
                && origin >= 0
                && origin + i64::from(words) <= i64::from(len)
                && scope.regs[index] == NONE
                && !scope.pre_emitted[index]
                && !scope.constant[index]
            {
                scope.regs[index] = dst + origin as Reg;
            }
        }
    }

    /// The call result whose words `value` is, and the first of them, where `value` is a
    /// call result, or takes some of one's words unchanged through expressions used once
    /// (bitcasts of the same size, consecutive swizzles and components of 32-bit vectors,
    /// which the compiler compiles into the source's own registers); `None` otherwise.
    fn word_source(&self, scope: &Scope, value: Handle<Expression>) -> Option<(Handle<Expression>, u32)> {
        let single = |of: Handle<Expression>| scope.info[of].ref_count == 1;
        let is_word_vector = |of: Handle<Expression>| matches!(self.ty(scope, of), TypeInner::Vector { scalar, .. } if scalar.width == 4);
        let mut at = value;
        let mut first = 0;
        loop {
            match scope.function.expressions[at] {
                Expression::CallResult(_) => return Some((at, first)),
                Expression::As { expr, convert: None, .. }
                    if single(at) && scope.lens[expr.index()] == scope.lens[at.index()] =>
                {
                    at = expr;
                }
                Expression::Swizzle { size, vector, pattern } if single(at) && is_word_vector(vector) => {
                    first += consecutive(size, &pattern)?;
                    at = vector;
                }
                Expression::AccessIndex { base, index } if single(at) && is_word_vector(base) => {
                    first += index;
                    at = base;
                }
                _ => return None,
            }
        }
    }

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
    use super::super::decode::tests::{compiled, compiled_with};
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

    /// The words `insns` copy.
    fn copied_words(insns: &[Insn]) -> u32 {
        insns
            .iter()
            .map(|i| match i {
                Insn::Copy1 { .. } => 1,
                Insn::Copy2 { .. } => 2,
                Insn::Copy3 { .. } => 3,
                Insn::Copy4 { .. } => 4,
                Insn::Copy { len, .. } => *len,
                _ => 0,
            })
            .sum()
    }

    #[test]
    fn records_returned_through_two_calls_are_composed_in_place() {
        let declarations = "struct P { a: u32, b: u32 }\n\
             fn make(x: u32) -> P { return P(x + 1u, x * 2u); }\n\
             fn forward(x: u32) -> P { return make(x); }";
        // The struct's two words computed straight into `p`'s registers (its members
        // into the composition's words, `compose_in_place`, and the composition into
        // the result's): no copy at all, at the composition or at either return.
        let insns = compiled_with(declarations, "let p = forward(x); data[id.x] = p.a + p.b;");
        assert_eq!(copied_words(&insns), 0);
        // A value computed before another and returned in one branch keeps its own
        // registers (the other would overwrite it in the result's).
        let declarations = "struct P { a: u32, b: u32 }\n\
             fn pick(c: bool, x: u32) -> P { let first = P(x, 1u); let second = P(2u, x); \
             if c { return first; } return second; }";
        let insns = compiled_with(declarations, "let p = pick(x > 3u, x); data[id.x] = p.a + p.b;");
        // (Both are composed, then copied at their returns: `second` too, as an `if`
        // stands between its computation and its return.)
        assert_eq!(copied_words(&insns), 2 + 2 + 2 + 2);
    }

    /// A record of three rows and its reader, as `gpu/scene_rows.wgsl` writes them
    /// (`row` stands for `scene_row`), with the reader's `return` given as `ret`.
    fn row_reader(ret: &str) -> String {
        format!(
            "@group(0) @binding(1) var<storage, read> rows: array<vec4<u32>>;\n\
             struct Node {{ lo: vec3<f32>, a: u32, hi: vec3<f32>, b: u32, c: u32, d: u32, e: u32, f: u32 }}\n\
             fn row(i: u32) -> vec4<u32> {{ return rows[i]; }}\n\
             fn read_node(i: u32) -> Node {{ let r0 = row(i); let r1 = row(i + 1u); let r2 = row(i + 2u); {ret} }}"
        )
    }

    #[test]
    fn rows_read_by_calls_are_composed_in_place() {
        let body = "let n = read_node(x); data[id.x] = n.a + n.b + n.f + bitcast<u32>(n.hi.y);";
        // Each row is read straight into its words of the record: nothing is copied.
        let reader = row_reader(
            "return Node(bitcast<vec3<f32>>(r0.xyz), r0.w, bitcast<vec3<f32>>(r1.xyz), r1.w, r2.x, r2.y, r2.z, r2.w);",
        );
        assert_eq!(copied_words(&compiled_with(&reader, body)), 0);
        // A row whose words land out of order (r0.yzw first), one that something else
        // also reads (r1.x), and one with a word computed (r2.x + extra) keep their own
        // registers and are copied: 4 words each, less the computed word, which is
        // computed in its place (`compose_in_place`).
        let reader = row_reader(
            "let extra = r1.x; return Node(bitcast<vec3<f32>>(r0.yzw), r0.x, bitcast<vec3<f32>>(r1.xyz), r1.w, \
             r2.x + extra, r2.y, r2.z, r2.w);",
        );
        assert_eq!(copied_words(&compiled_with(&reader, body)), 4 + 4 + 3);
    }

    #[test]
    fn values_used_again_keep_their_registers() {
        // `y` is read after the store: computed into its own registers, then copied.
        assert_eq!(copies("var a = 0u; let y = x + 1u; a = y; data[id.x] = a + y;"), baseline() + 1);
    }
}
