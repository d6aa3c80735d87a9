//! Compositions built in place: the components of a vector or struct that is composed
//! (`Quad(select(..), select(..), select(..))`, `vec4(a.xz, b.xz)`) are computed straight
//! into the composition's registers, so that the composition itself copies nothing.
//!
//! Why: the compiler otherwise gives each component registers of its own and the
//! `Compose` copies them, word for word, into the composition's. In the block histogram's
//! sorting network (strata/histogram_network.wgsl), which builds every compare-exchange's
//! result as a struct of vectors and every element permutation as vectors of swizzles,
//! such copies were about a third of the rows the interpreter computed (issue 59,
//! docs/benchmarks/interpreter.md).
//!
//! Which components: those emitted before the composition by the same run of
//! consecutive `Emit` statements (naga's front end splits one line's expressions into
//! several around each constant it evaluates; nothing runs between them), used by
//! nothing else (naga reference count 1), not evaluated when the scope opened, without
//! registers yet, and of a kind whose lowering computes the value
//! into the expression's own registers ([`computed_in_own_registers`]; a kind that makes
//! the value an alias of another's registers, a consecutive swizzle say, takes no slot).
//! A component that is itself a composition takes its slot and then places its own
//! components in it, so nested compositions (`Quad(vec4(a.xz, b.xz), ..)`) copy
//! nothing either.
//!
//! Sound because the composition's registers are taken before the run's first expression
//! is compiled (from the free ranges, or they are an inlined callee's result registers or
//! the composition's slot in an enclosing one), so no value computed or alive in between
//! can hold them; each placed component writes only its own words of them (its operands are
//! other values, never the composition or its components, which nothing but the
//! composition reads); and the composition then finds each component where it would
//! have copied it and emits no copy ([`Compiler::copy`] drops a copy onto itself). A
//! composition given the registers of an inlined callee's result
//! ([`Scope::return_in_place`]) places its components there: nothing else in the callee
//! reads or writes those registers, and within a run of `Emit` statements no other
//! statement runs between a component and the composition.
//!
//! Placement runs where [`Compiler::block`] compiles a block. The branches that
//! if-conversion speculates ([`super::if_conversion`]) are compiled statement by
//! statement and keep their copies; a speculation undone is compiled again as a block,
//! with placement.

use super::compiler::{Compiler, NONE, Scope};
use super::constant::compose_offsets;
use naga::{Expression, Handle};
use std::collections::HashSet;

impl Compiler<'_> {
    /// Before the expressions `handles` of a run of consecutive `Emit` statements of
    /// `scope` are compiled: gives each composition among them with a component to place
    /// registers (unless it was evaluated when the scope opened, or needs registers never
    /// shared), and those components their words of them, as the module comment
    /// describes. Nothing is compiled here.
    pub(super) fn place_compositions(&mut self, scope: &mut Scope, handles: &[Handle<Expression>]) {
        let emitted: HashSet<Handle<Expression>> = handles.iter().copied().collect();
        // Compositions given registers here (a nested one by its parent).
        let mut placed: HashSet<Handle<Expression>> = HashSet::new();
        // Outermost first: a composition comes after its components in the arena.
        for &record in handles.iter().rev() {
            let Expression::Compose { ref components, .. } = scope.function.expressions[record] else { continue };
            let index = record.index();
            if scope.pre_emitted[index] {
                continue;
            }
            let in_result = scope.inlined && scope.result.is_some_and(|(reg, _)| reg == scope.regs[index]);
            let free_to_place = scope.regs[index] == NONE && !scope.dead_after.own_registers(record);
            if !(free_to_place || in_result || placed.contains(&record)) {
                continue;
            }
            let lens: Vec<u32> = components.iter().map(|c| scope.lens[c.index()]).collect();
            let Ok(offsets) = compose_offsets(self.module, self.ty(scope, record), &lens) else { continue };
            let slots: Vec<(Handle<Expression>, u32)> = components
                .iter()
                .copied()
                .zip(offsets)
                .filter(|&(c, at)| {
                    let i = c.index();
                    emitted.contains(&c)
                        && i < index
                        && at + scope.lens[i] <= scope.lens[index]
                        && scope.info[c].ref_count == 1
                        && scope.regs[i] == NONE
                        && !scope.pre_emitted[i]
                        && !scope.dead_after.own_registers(c)
                        && computed_in_own_registers(&scope.function.expressions[c])
                })
                .collect();
            if slots.is_empty() {
                continue;
            }
            let base = self.reg(scope, record);
            for (component, at) in slots {
                scope.regs[component.index()] = base + at;
                placed.insert(component);
            }
        }
    }
}

/// Whether the lowering of `expression` ([`super::expression`]) computes its value into
/// the expression's own registers ([`Compiler::reg`]) with instructions that read only
/// its operands: arithmetic, selections, math and relational functions, conversions,
/// splats, swizzles and compositions. Kinds that alias another value's registers where
/// they can (a consecutive swizzle, a bitcast) re-point them, which leaves the slot unused
/// and the composition copying as before. Loads, accesses, calls and image operations are
/// left out: their lowerings read memory or fuse with neighbouring instructions.
fn computed_in_own_registers(expression: &Expression) -> bool {
    matches!(
        expression,
        Expression::Binary { .. }
            | Expression::Unary { .. }
            | Expression::Select { .. }
            | Expression::Math { .. }
            | Expression::Relational { .. }
            | Expression::As { .. }
            | Expression::Splat { .. }
            | Expression::Swizzle { .. }
            | Expression::Compose { .. }
    )
}

#[cfg(test)]
mod tests {
    use super::super::decode::tests::{INVOCATIONS, compiled_with, kernel_with, run_kernel};
    use super::super::insn::Insn;

    /// The copies among the entry point's instructions for `body` (after `declarations`).
    fn copies(declarations: &str, body: &str) -> usize {
        compiled_with(declarations, body)
            .iter()
            .filter(|insn| {
                matches!(
                    insn,
                    Insn::Copy1 { .. }
                        | Insn::Copy2 { .. }
                        | Insn::Copy3 { .. }
                        | Insn::Copy4 { .. }
                        | Insn::Copy { .. }
                )
            })
            .count()
    }

    /// `data` after the kernel ran on `data[i] = i`.
    fn run(declarations: &str, body: &str) -> Vec<u32> {
        run_kernel(&kernel_with(declarations, body))
    }

    /// `f` of each invocation's `x`.
    fn expected(f: impl Fn(u32) -> u32) -> Vec<u32> {
        (0..INVOCATIONS).map(f).collect()
    }

    const PAIR: &str = "struct Pair { low: vec2<u32>, high: vec2<u32> }";

    #[test]
    fn a_vector_of_computed_components_is_built_without_copies() {
        let body = "let v = vec4<u32>(x * 3u, x + 1u, x ^ 5u, x >> 1u);\n\
                    data[id.x] = v.x + v.y * 2u + v.z * 3u + v.w * 4u;";
        assert_eq!(copies("", body), 0);
        assert_eq!(run("", body), expected(|x| x * 3 + (x + 1) * 2 + (x ^ 5) * 3 + (x >> 1) * 4));
    }

    #[test]
    fn a_struct_of_vectors_of_swizzles_is_built_without_copies() {
        // The sorting network's shape: a struct whose members are vectors composed of
        // swizzles and arithmetic (two levels placed).
        let body = "let w = vec4<u32>(x ^ 1u, x + 1u, x + 2u, x * 7u);\n\
                    let p = Pair(vec2<u32>(w.w ^ 9u, w.x + 3u), w.zx * vec2<u32>(2u));\n\
                    data[id.x] = p.low.x + p.low.y * 10u + p.high.x * 100u + p.high.y * 1000u;";
        assert_eq!(copies(PAIR, body), 0);
        let f = |x: u32| ((x * 7) ^ 9) + ((x ^ 1) + 3) * 10 + (x + 2) * 2 * 100 + (x ^ 1) * 2 * 1000;
        assert_eq!(run(PAIR, body), expected(f));
    }

    #[test]
    fn a_component_used_elsewhere_keeps_its_registers() {
        // `a` is read after the composition too: it must not live in the vector's words
        // (the copy stays), and both values stay right.
        let body = "let a = x * 3u;\n\
                    let v = vec2<u32>(a, x + 1u);\n\
                    data[id.x] = v.x * 100u + v.y + a;";
        assert_eq!(copies("", body), 1);
        assert_eq!(run("", body), expected(|x| x * 3 * 100 + x + 1 + x * 3));
    }

    #[test]
    fn compositions_in_converted_and_compiled_branches() {
        // Straight-line branches (if-conversion speculates both and selects; nothing is
        // placed in them) and a branch with a loop (not speculated: compiled as branches,
        // each block with placement): the values.
        let selected = "var r = vec2<u32>();\n\
                        if x > 20u { r = vec2<u32>(x * 2u, x + 1u); } else { r = vec2<u32>(x ^ 3u, 7u); }\n\
                        data[id.x] = r.x * 1000u + r.y;";
        let f = |x: u32| if x > 20 { x * 2 * 1000 + x + 1 } else { (x ^ 3) * 1000 + 7 };
        assert_eq!(run("", selected), expected(f));
        let looped = "var r = vec2<u32>();\n\
                      if x > 20u { r = vec2<u32>(x * 2u, x + 1u); } else { for (var i = 0u; i < 2u; i++) { r = vec2<u32>(x ^ 3u, 7u + i); } }\n\
                      data[id.x] = r.x * 1000u + r.y;";
        let g = |x: u32| if x > 20 { x * 2 * 1000 + x + 1 } else { (x ^ 3) * 1000 + 8 };
        assert_eq!(run("", looped), expected(g));
    }

    #[test]
    fn an_inlined_callee_builds_its_result_in_the_callers_registers() {
        // `pick`'s shape (strata/histogram_network.wgsl): a callee returning a struct of
        // selects, which it builds in its result's registers.
        let declarations = "struct Pair { low: vec2<u32>, high: vec2<u32> }\n\
                            fn pick(a: Pair, b: Pair, take: vec2<bool>) -> Pair {\n\
                            return Pair(select(a.low, b.low, take), select(a.high, b.high, take));\n}";
        let body = "let a = Pair(vec2<u32>(x ^ 1u, x + 1u), vec2<u32>(x + 2u, x + 3u));\n\
                    let b = Pair(vec2<u32>(x * 5u, x + 9u), vec2<u32>(x * 7u, x + 11u));\n\
                    let p = pick(a, b, vec2<bool>(x % 2u == 0u, x > 30u));\n\
                    data[id.x] = p.low.x + p.low.y * 10u + p.high.x * 100u + p.high.y * 1000u;";
        assert_eq!(copies(declarations, body), 0);
        let f = |x: u32| {
            let low = (if x.is_multiple_of(2) { x * 5 } else { x ^ 1 }, if x > 30 { x + 9 } else { x + 1 });
            let high = (if x.is_multiple_of(2) { x * 7 } else { x + 2 }, if x > 30 { x + 11 } else { x + 3 });
            low.0 + low.1 * 10 + high.0 * 100 + high.1 * 1000
        };
        assert_eq!(run(declarations, body), expected(f));
    }
}
