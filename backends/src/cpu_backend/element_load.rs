//! Loads of a buffer array's element, `nodes[i]`, as one instruction ([`ElementLoad`])
//! instead of a pointer computed into registers (`PtrIndexRt` for a runtime-sized array,
//! `PtrIndex` for a fixed-size one such as a uniform buffer's) and a load through it.
//!
//! Why: a BVH walk loads a node or a triangle per step, and the interpreter ran both
//! instructions member by member; the path tracer spent about a tenth of its time on
//! the pointer alone (reading the base pointer's tag, the buffer's size through the
//! general memory model, writing two pointer words per invocation). Where the buffer is
//! known when compiling, only the index varies by invocation.
//!
//! Sound because the pointer has no other use (naga reference count 1: this load), so
//! its registers are never read; the pointer's instruction is the one just before the
//! load (tracked by [`Compiler::last_value`], which every statement that may place a
//! jump target clears), so the index register holds the same value at the load; and
//! the fused instruction clamps the index and reads out-of-bounds words as 0 exactly as
//! the two did (a fixed-size array's index to its last element, as `PtrIndex` does;
//! [`super::insn::element_offset`], `execute.rs`).
//!
//! Where: the instruction itself ([`ElementLoad`]) is defined with the others in
//! [`super::insn`], which the executor reads; this file is the compiler's pass that
//! makes it, called where a load is lowered ([`super::access`]).

use super::compiler::{Compiler, LastValue, Scope};
use super::insn::{ElementLoad, Insn, Reg, Runs};
use super::layout::Place;
use naga::{Expression, Handle};

impl Compiler<'_> {
    /// The fused load of `pointer` (`len` words into `dst`), if `pointer` is an element
    /// of an array in a buffer known when compiling, computed by the last
    /// instruction, with no other use: that instruction is then replaced by the load.
    pub(super) fn fuse_element_load(
        &mut self,
        scope: &Scope,
        pointer: Handle<Expression>,
        dst: Reg,
        len: u32,
        runs: &Option<Runs>,
    ) -> bool {
        let last = self.insns.len().wrapping_sub(1);
        if self.last_value != Some(LastValue::new(scope, pointer, last)) || scope.info[pointer].ref_count != 1 {
            return false;
        }
        let Expression::Access { base, .. } = scope.function.expressions[pointer] else { return false };
        let Some(Place::Buffer(buffer, address)) = scope.places[base.index()] else { return false };
        let (computed, index, stride, count) = match self.insns.last() {
            Some(&Insn::PtrIndexRt { dst, index, stride, .. }) => (dst, index, stride, None),
            Some(&Insn::PtrIndex { dst, index, stride, count, .. }) => (dst, index, stride, Some(count)),
            _ => return false,
        };
        if computed != scope.regs[pointer.index()] {
            return false;
        }
        let load = ElementLoad { dst, buffer, address, index, stride, count, len, runs: runs.clone() };
        *self.insns.last_mut().expect("checked above") = Insn::LoadElement(Box::new(load));
        self.took_over = Some(last);
        true
    }
}

#[cfg(test)]
mod tests {
    use super::super::decode::tests::{compiled, compiled_with};
    use super::super::insn::Insn;

    /// The element loads and pointer computations of `body`.
    fn kinds(body: &str) -> (usize, usize) {
        let insns = compiled(body);
        let count = |f: fn(&Insn) -> bool| insns.iter().filter(|i| f(i)).count();
        (count(|i| matches!(i, Insn::LoadElement(_))), count(|i| matches!(i, Insn::PtrIndexRt { .. })))
    }

    #[test]
    fn element_loads_fuse_where_the_pointer_has_no_other_use() {
        // `x = data[id.x]` and `data[x % 7u]`: one instruction each (the store's pointer
        // stays).
        assert_eq!(kinds("data[id.x] = data[x % 7u];"), (2, 1));
        // The pointer used twice (a load and a store): kept.
        assert_eq!(kinds("let p = &data[x % 7u]; *p = *p + 1u;"), (1, 1));
        // Another instruction between the pointer and the load: kept.
        assert_eq!(kinds("let p = &data[x % 7u]; let y = x * 3u; data[id.x] = *p + y;"), (1, 2));
    }

    #[test]
    fn a_fixed_size_array_in_a_buffer_loads_its_element_in_one_instruction() {
        let insns = compiled_with(
            "struct Rows { rows: array<vec4<u32>, 8> }\n@group(0) @binding(1) var<uniform> table: Rows;",
            "let r = table.rows[x % 9u]; data[id.x] = r.y + r.w;",
        );
        let count = |f: fn(&Insn) -> bool| insns.iter().filter(|i| f(i)).count();
        // `data[id.x]` and the row: element loads; no pointer computed.
        assert_eq!(count(|i| matches!(i, Insn::LoadElement(_))), 2);
        assert_eq!(count(|i| matches!(i, Insn::PtrIndex { .. } | Insn::Load { .. } | Insn::LoadRuns { .. })), 0);
    }

    #[test]
    fn a_fused_load_stored_into_a_variable_is_loaded_into_it() {
        let copies = |body: &str| compiled(body).iter().filter(|i| matches!(i, Insn::Copy1 { .. })).count();
        // The load computed straight into `v` (store forwarding): no more copies than
        // without it.
        assert_eq!(copies("var v = 0u; v = data[x % 7u]; data[id.x] = v;"), copies("var v = 0u; data[id.x] = v;"));
    }
}
