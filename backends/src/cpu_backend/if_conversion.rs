//! If-conversion: an `if` whose branches only compute values and store them into local
//! variables is compiled without a branch. Both branches' values are computed, then each
//! stored variable gets one `Select` between its two new values (a branch that does not
//! store it keeps the old value).
//!
//! Why: a branch taken one way by some members of a group and the other way by the rest
//! splits the group ([`super::interp`]). Each half then runs on its own with a scheduler
//! round trip before they merge again. A `Select` is one row operation for the whole
//! group. The common case is the short-circuit operators: naga's WGSL front end lowers
//! `a && b` and `a || b` into an `if` that stores `b` or a constant into a local
//! variable. In a BVH traversal these conditions differ between lanes most of the time.
//!
//! Sound because the expressions a branch emits have no side effects (naga expressions
//! only read; stores, calls and atomics are statements), every operation is defined for
//! every input in WGSL (division by zero, out-of-range indices clamped, out-of-bounds
//! memory reads 0), and the stores are deferred to the selects after both branches'
//! expressions, each of which was emitted before the first store of its branch or does
//! not read memory. A value may be a variable's own registers (a load read in place,
//! [`super::load_alias`]), read when its select runs: the selects are refused if one
//! would read a variable that an earlier select changed in the same branch's lanes. The compiled branches are checked instruction by instruction; if
//! one holds anything but register and memory reads (a runtime failure for an
//! unsupported construct, a jump), the compilation is undone and the `if` is compiled
//! as a branch.

use super::compiler::{Compiler, Scope};
use super::error::unsupported;
use super::insn::{Insn, Reg};
use super::layout::Place;
use super::liveness::slots;
use crate::error::BackendError;
use naga::{Expression, Handle, Statement};

/// At most this many IR expressions emitted by the two branches together: both branches
/// always run once converted, so a long branch would cost more than the split it saves.
const SPECULATED_EXPRESSIONS: usize = 12;

/// At most this many stores per branch.
const STORES_PER_BRANCH: usize = 4;

/// A store of a branch: the variable's registers and words, and the new value's register.
#[derive(Clone, Copy)]
struct LocalStore {
    variable: Reg,
    len: u32,
    value: Reg,
}

impl Compiler<'_> {
    /// Compiles `if condition { accept } else { reject }` as selects if both branches
    /// only emit expressions and store into local variables; false (nothing compiled)
    /// otherwise.
    pub(super) fn if_as_select(
        &mut self,
        scope: &mut Scope,
        condition: Handle<Expression>,
        accept: &naga::Block,
        reject: &naga::Block,
    ) -> Result<bool, BackendError> {
        let (Some(accept_count), Some(reject_count)) =
            (branch_shape(self.module, scope, accept), branch_shape(self.module, scope, reject))
        else {
            return Ok(false);
        };
        if accept_count + reject_count > SPECULATED_EXPRESSIONS || (accept.is_empty() && reject.is_empty()) {
            return Ok(false);
        }
        let line = self.line;
        let cond = self.reg(scope, condition);
        let start = self.here() as usize;
        let (regs, places, constant) = (scope.regs.clone(), scope.places.clone(), scope.constant.clone());
        let owned = scope.owned.clone();
        let (free, runtime) = (self.free.clone(), self.runtime.len());
        let local_pointers = self.local_pointers.len();
        // No register is freed inside the branches: the selects read their values after
        // both, and an undone compilation must leave the registers as they were.
        let free_early = std::mem::replace(&mut self.free_early, false);
        let stores = self.speculate(scope, accept).and_then(|a| Ok((a, self.speculate(scope, reject)?)));
        self.free_early = free_early;
        let (accept_stores, reject_stores) = stores?;
        let selects = match (accept_stores, reject_stores) {
            (Some(a), Some(r)) if self.insns[start..].iter().all(speculable) => {
                merge(&a, &r).filter(|selects| reads_before_writes(selects, cond))
            }
            _ => None,
        };
        self.line = line;
        self.source = scope.source;
        // The speculated expressions are no store's to forward (`retarget`).
        self.last_value = None;
        let Some(selects) = selects else {
            // Undo: the `if` is compiled as a branch, its expressions anew.
            self.truncate(start);
            (scope.regs, scope.places, scope.constant, scope.owned) = (regs, places, constant, owned);
            self.free = free;
            self.runtime.truncate(runtime);
            self.local_pointers.truncate(local_pointers);
            return Ok(false);
        };
        for (variable, len, accept, reject) in selects {
            // `n` is a byte: long values in pieces.
            for at in (0..len).step_by(u8::MAX as usize) {
                let n = (len - at).min(u32::from(u8::MAX));
                self.push(Insn::Select {
                    dst: variable + at,
                    cond,
                    accept: accept + at,
                    reject: reject + at,
                    n: n as u8,
                    sc: 0,
                });
            }
        }
        // Now that the selects have read them, the values that die in the branches.
        for slot in slots(accept).into_iter().chain(slots(reject)) {
            self.free_dead(scope, slot);
        }
        Ok(true)
    }

    /// Compiles a branch's expressions; returns its stores (`None` if one is not into a
    /// local variable).
    fn speculate(&mut self, scope: &mut Scope, block: &naga::Block) -> Result<Option<Vec<LocalStore>>, BackendError> {
        let mut stores = Vec::new();
        for (statement, span) in block.span_iter() {
            match statement {
                Statement::Emit(_) => self.statement(scope, statement, *span)?,
                Statement::Store { pointer, value } => match scope.places[pointer.index()] {
                    Some(Place::Local(variable)) => {
                        let value_reg = self.reg(scope, *value);
                        stores.push(LocalStore { variable, len: scope.lens[value.index()], value: value_reg });
                    }
                    _ => return Ok(None),
                },
                _ => {
                    return Err(unsupported(
                        "internal: if-conversion of a branch that is not straight-line",
                        self.line,
                    ));
                }
            }
        }
        Ok(Some(stores))
    }
}

/// The number of expressions `block` emits if it is a branch if-conversion can take:
/// only `Emit` and `Store` statements, at most [`STORES_PER_BRANCH`] stores, and no
/// memory read emitted after its first store (deferring the stores must not change what
/// a load sees).
fn branch_shape(module: &naga::Module, scope: &Scope, block: &naga::Block) -> Option<usize> {
    let mut emitted = 0;
    let mut stores = 0;
    for statement in block.iter() {
        match statement {
            Statement::Emit(range) => {
                for handle in range.clone() {
                    if stores > 0 && matches!(scope.function.expressions[handle], Expression::Load { .. }) {
                        return None;
                    }
                    emitted += 1;
                }
            }
            // Only into function-space variables: a store into memory is a side effect
            // (refused here rather than after compiling the branch, which would be undone).
            Statement::Store { pointer, .. }
                if stores < STORES_PER_BRANCH && into_function_space(module, scope, *pointer) =>
            {
                stores += 1
            }
            _ => return None,
        }
    }
    Some(emitted)
}

/// Whether `pointer` points into the function address space (a local variable).
fn into_function_space(module: &naga::Module, scope: &Scope, pointer: Handle<Expression>) -> bool {
    use naga::{AddressSpace, TypeInner};
    matches!(
        scope.info[pointer].ty.inner_with(&module.types),
        TypeInner::Pointer { space: AddressSpace::Function, .. }
            | TypeInner::ValuePointer { space: AddressSpace::Function, .. }
    )
}

/// Whether an instruction compiled from an expression may run where its branch was not
/// taken: it reads registers or memory and writes only its own registers.
fn speculable(insn: &Insn) -> bool {
    matches!(
        insn,
        Insn::Copy1 { .. }
            | Insn::Copy2 { .. }
            | Insn::Copy3 { .. }
            | Insn::Copy4 { .. }
            | Insn::Copy { .. }
            | Insn::Zero { .. }
            | Insn::Bin { .. }
            | Insn::BinV { .. }
            | Insn::Un { .. }
            | Insn::Select { .. }
            | Insn::Swizzle { .. }
            | Insn::Splat { .. }
            | Insn::Convert { .. }
            | Insn::Extract { .. }
            | Insn::PtrAdd { .. }
            | Insn::PtrIndex { .. }
            | Insn::PtrIndexRt { .. }
            | Insn::Load { .. }
            | Insn::LoadRuns { .. }
            | Insn::LoadElement(_)
            | Insn::LoadMixed { .. }
            | Insn::LoadWorkgroup { .. }
            | Insn::LoadPrivate { .. }
            | Insn::LoadBuffer { .. }
            | Insn::ArrayLength { .. }
            | Insn::Compute(_)
    )
}

/// The selects of the two branches' stores: per variable (register, words, value if
/// accepted, value if rejected), the variable itself where a branch does not store it.
/// `None` where stores overlap without covering the same registers (a field of a
/// variable in one branch, the whole variable in the other).
fn merge(accept: &[LocalStore], reject: &[LocalStore]) -> Option<Vec<(Reg, u32, Reg, Reg)>> {
    let overlap = |a: &LocalStore, b: &LocalStore| a.variable < b.variable + b.len && b.variable < a.variable + a.len;
    let same = |a: &LocalStore, b: &LocalStore| a.variable == b.variable && a.len == b.len;
    // Within a branch the last store of a variable wins.
    let last = |stores: &[LocalStore]| -> Option<Vec<LocalStore>> {
        let mut kept: Vec<LocalStore> = Vec::new();
        for store in stores {
            match kept.iter().position(|k| overlap(k, store)) {
                Some(i) if same(&kept[i], store) => kept[i] = *store,
                Some(_) => return None,
                None => kept.push(*store),
            }
        }
        Some(kept)
    };
    let (accept, reject) = (last(accept)?, last(reject)?);
    let mut selects = Vec::new();
    for a in &accept {
        match reject.iter().find(|r| overlap(a, r)) {
            Some(r) if same(a, r) => selects.push((a.variable, a.len, a.value, r.value)),
            Some(_) => return None,
            None => selects.push((a.variable, a.len, a.value, a.variable)),
        }
    }
    for r in reject.iter().filter(|r| !accept.iter().any(|a| overlap(a, r))) {
        selects.push((r.variable, r.len, r.variable, r.value));
    }
    Some(selects)
}

/// Whether the selects, run in order, read only what the branches read before any
/// store (a value may be a variable's registers, a load read in place:
/// [`super::load_alias`]): no select reads, on one side of the branch, a variable that an
/// earlier select wrote on that side (a variable a branch does not store keeps its
/// words in that branch's lanes), the condition is no variable, and a select's value is
/// its own variable exactly or lies apart from it.
fn reads_before_writes(selects: &[(Reg, u32, Reg, Reg)], cond: Reg) -> bool {
    let apart = |at: Reg, len: u32, other: Reg, other_len: u32| at + len <= other || other + other_len <= at;
    selects.iter().enumerate().all(|(i, &(variable, len, accept, reject))| {
        // `value`, read on the side whose stored values `side` picks from a select.
        let reads_before_writes = |value: Reg, side: fn(&(Reg, u32, Reg, Reg)) -> Reg| {
            (value == variable || apart(value, len, variable, len))
                && selects[..i]
                    .iter()
                    .all(|earlier| side(earlier) == earlier.0 || apart(value, len, earlier.0, earlier.1))
        };
        apart(cond, 1, variable, len) && reads_before_writes(accept, |s| s.2) && reads_before_writes(reject, |s| s.3)
    })
}

#[cfg(test)]
mod tests {
    use super::super::decode::tests::compiled;
    use super::*;

    fn branches(insns: &[Insn]) -> usize {
        insns.iter().filter(|i| matches!(i, Insn::JumpUnless { .. } | Insn::Jump(_))).count()
    }

    #[test]
    fn short_circuit_operators_compile_without_branches() {
        let insns = compiled("data[id.x] = u32((x > 3u && x < 9u) || x == 20u);");
        assert_eq!(branches(&insns), 0);
        assert_eq!(insns.iter().filter(|i| matches!(i, Insn::Select { .. })).count(), 2);
    }

    #[test]
    fn branches_with_side_effects_or_reloads_stay_branches() {
        // A store into a buffer.
        assert!(branches(&compiled("if x > 3u { data[0] = 1u; }")) > 0);
        // A load of a variable after a store into it in the same branch.
        assert!(branches(&compiled("var t = 0u; if x > 3u { t = x; t = t * 2u; } data[id.x] = t;")) > 0);
        // The same without the reload is converted.
        assert_eq!(branches(&compiled("var t = 0u; if x > 3u { t = x * 2u; } data[id.x] = t;")), 0);
        // A branch storing a variable the other reads in place: converted (each side's
        // lanes see the variable unchanged) ...
        let other_side = "var a = 0u; var b = x; if x > 3u { b = 0u; } else { a = b; } data[id.x] = a + b;";
        assert_eq!(branches(&compiled(other_side)), 0);
        // ... but not where both branches store it and one reads it first.
        let both_sides = "var a = 0u; var b = x; if x > 3u { b = 9u; } else { let t = b; a = t; b = 4u; } \
            data[id.x] = a + b;";
        assert!(branches(&compiled(both_sides)) > 0);
    }
}
