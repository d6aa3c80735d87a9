//! Loads of a runtime-sized buffer array's element, `nodes[i]`, as one instruction
//! ([`ElementLoad`]) instead of a pointer computed into registers (`PtrIndexRt`) and a
//! load through it.
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
//! the two did ([`super::insn::element_offset`], `execute.rs`).
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
    /// of a runtime-sized array in a buffer known when compiling, computed by the last
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
        let Some(&Insn::PtrIndexRt { dst: computed, index, stride, .. }) = self.insns.last() else { return false };
        if computed != scope.regs[pointer.index()] {
            return false;
        }
        let load = ElementLoad { dst, buffer, address, index, stride, len, runs: runs.clone() };
        *self.insns.last_mut().expect("checked above") = Insn::LoadElement(Box::new(load));
        self.took_over = Some(last);
        true
    }
}

#[cfg(test)]
mod tests {
    use super::super::decode::tests::compiled;
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
    fn a_fused_load_stored_into_a_variable_is_loaded_into_it() {
        let copies = |body: &str| compiled(body).iter().filter(|i| matches!(i, Insn::Copy1 { .. })).count();
        // The load computed straight into `v` (store forwarding): no more copies than
        // without it.
        assert_eq!(copies("var v = 0u; v = data[x % 7u]; data[id.x] = v;"), copies("var v = 0u; data[id.x] = v;"));
    }
}
