//! Loads read in place: a load of a local variable (or of a field of one, at a place
//! known when compiling) takes the variable's own registers instead of a copy of them,
//! where nothing can write the variable while the loaded value is still used.
//!
//! Why: naga IR reads a variable through a `Load` expression, which the compiler
//! otherwise lowers to a copy into the expression's registers. In the path tracer's
//! BVH loop most of the copies left after store forwarding ([`super::retarget`]) were
//! such loads, read once right after: the node index at the loop's head, the
//! short-circuit temporaries of `&&` and `||` read by the branch after their `if`.
//!
//! Sound because the value and the variable hold the same words from the load until
//! the variable is next written, and every use of the value comes before that:
//! - the uses counted are those of the load and of the expressions that share its
//!   registers (a field or component taken with a constant index, consecutive
//!   components, a bitcast); their number must equal naga's reference counts, so a use
//!   this analysis does not see (an expression kind it does not list, the continuing
//!   block of a loop reading a body's value) keeps the copy;
//! - they all lie in the rest of the block that emits the load, and no statement from
//!   the load up to and including the one holding the last use may write the variable
//!   (a store or call through a pointer into it, or a statement this file does not
//!   know); a compound statement (`if`, `switch`, loop, block) counts as a whole, so a
//!   store later in a loop body that also holds a use is seen; an expression that reads
//!   the load and is emitted twice (naga IR allows it in two branches, WGSL does not
//!   produce it) keeps the copy, as its uses would be counted twice;
//! - instructions that write a variable are only those of its stores: a copy; the
//!   value's own instruction moved by store forwarding, which is the last instruction
//!   before the store, so nothing runs in between; or if-conversion's selects, which run
//!   after both branches' values and check that none reads a variable an earlier select
//!   wrote on its side of the branch.

use naga::valid::FunctionInfo;
use naga::{Block, Expression, Function, Handle, LocalVariable, Statement};

/// Per expression of `function` (validated: `info`): true for a load that may read its
/// variable's registers in place.
pub(super) fn in_place_loads(function: &Function, info: &FunctionInfo) -> Vec<bool> {
    let expressions = &function.expressions;
    let count = expressions.len();
    // The load whose registers each expression shares, if any.
    let mut shares: Vec<Option<Handle<Expression>>> = vec![None; count];
    // Per candidate load: the uses of every expression sharing its registers.
    let mut uses_needed = vec![0usize; count];
    for (handle, expression) in expressions.iter() {
        let load = match *expression {
            Expression::Load { pointer } if variable_of(function, pointer, Indices::Constant).is_some() => Some(handle),
            Expression::AccessIndex { base, .. } => shares[base.index()],
            Expression::Swizzle { size, vector, pattern } if super::layout::consecutive(size, &pattern).is_some() => {
                shares[vector.index()]
            }
            Expression::As { expr, convert: None, .. } => shares[expr.index()],
            _ => None,
        };
        if let Some(load) = load {
            shares[handle.index()] = Some(load);
            uses_needed[load.index()] += info[handle].ref_count;
        }
    }
    let analysis = Analysis { function, shares, uses_needed };
    let mut in_place = vec![false; count];
    analysis.block(&function.body, &mut in_place);
    in_place
}

/// How a pointer may reach its variable: through constant indices only (an offset known
/// when compiling, what a load read in place needs) or through any index (what a store
/// may write).
#[derive(Clone, Copy, PartialEq)]
enum Indices {
    Constant,
    Any,
}

/// The local variable `pointer` points into through `indices`, if it does.
fn variable_of(
    function: &Function,
    mut pointer: Handle<Expression>,
    indices: Indices,
) -> Option<Handle<LocalVariable>> {
    loop {
        match function.expressions[pointer] {
            Expression::AccessIndex { base, .. } => pointer = base,
            Expression::Access { base, .. } if indices == Indices::Any => pointer = base,
            Expression::LocalVariable(variable) => return Some(variable),
            _ => return None,
        }
    }
}

/// What a scan for a load's uses has found so far.
#[derive(Default)]
struct Uses {
    /// Uses counted.
    found: usize,
    /// The expressions emitted with a use, in order.
    readers: Vec<Handle<Expression>>,
    /// Whether one of them was emitted twice (its uses counted twice: refused).
    emitted_twice: bool,
}

struct Analysis<'a> {
    function: &'a Function,
    /// Per expression: the candidate load whose registers it shares.
    shares: Vec<Option<Handle<Expression>>>,
    /// Per candidate load: the references to it and to the expressions sharing it.
    uses_needed: Vec<usize>,
}

impl Analysis<'_> {
    /// Decides every candidate load emitted in `block` and in the blocks it contains.
    fn block(&self, block: &Block, in_place: &mut [bool]) {
        for (at, statement) in block.iter().enumerate() {
            match statement {
                Statement::Emit(range) => {
                    for handle in range.clone() {
                        if let Expression::Load { pointer } = self.function.expressions[handle]
                            && self.shares[handle.index()] == Some(handle)
                        {
                            let variable = variable_of(self.function, pointer, Indices::Constant).expect("a candidate");
                            in_place[handle.index()] = self.reads_in_place(block, at, handle, variable);
                        }
                    }
                }
                _ => nested(statement, |inner| self.block(inner, in_place)),
            }
        }
    }

    /// Whether every use of `load` (emitted by statement `at` of `block`, a load of
    /// `variable`) comes before anything may write `variable`.
    fn reads_in_place(
        &self,
        block: &Block,
        at: usize,
        load: Handle<Expression>,
        variable: Handle<LocalVariable>,
    ) -> bool {
        let needed = self.uses_needed[load.index()];
        let Statement::Emit(range) = &block[at] else { return false };
        let mut uses = Uses::default();
        // Expressions emitted after the load by the same statement.
        for handle in range.clone().filter(|h| h.index() > load.index()) {
            self.emitted_uses(handle, load, &mut uses);
        }
        for statement in block.iter().skip(at + 1) {
            if uses.found >= needed {
                break;
            }
            if self.may_write(statement, variable) {
                return false;
            }
            self.statement_uses(statement, load, &mut uses);
        }
        uses.found == needed && !uses.emitted_twice
    }

    /// Counts the uses of `load` by `handle`, emitted here, into `uses`.
    fn emitted_uses(&self, handle: Handle<Expression>, load: Handle<Expression>, uses: &mut Uses) {
        let found = self.expression_uses(&self.function.expressions[handle], load);
        if found > 0 {
            uses.emitted_twice |= uses.readers.contains(&handle);
            uses.readers.push(handle);
            uses.found += found;
        }
    }

    /// How many times `expression` reads `load`'s registers as an operand.
    fn expression_uses(&self, expression: &Expression, load: Handle<Expression>) -> usize {
        let mut uses = 0;
        let mut operand = |h: Handle<Expression>| uses += usize::from(self.shares[h.index()] == Some(load));
        match *expression {
            Expression::Compose { ref components, .. } => components.iter().for_each(|&c| operand(c)),
            Expression::Access { base, index } => {
                operand(base);
                operand(index);
            }
            Expression::AccessIndex { base, .. } => operand(base),
            Expression::Splat { value, .. } => operand(value),
            Expression::Swizzle { vector, .. } => operand(vector),
            Expression::Load { pointer } => operand(pointer),
            Expression::Unary { expr, .. }
            | Expression::As { expr, .. }
            | Expression::Derivative { expr, .. }
            | Expression::Relational { argument: expr, .. }
            | Expression::ArrayLength(expr) => operand(expr),
            Expression::Binary { left, right, .. } => {
                operand(left);
                operand(right);
            }
            Expression::Select { condition, accept, reject } => {
                operand(condition);
                operand(accept);
                operand(reject);
            }
            Expression::Math { arg, arg1, arg2, arg3, .. } => {
                operand(arg);
                [arg1, arg2, arg3].into_iter().flatten().for_each(operand);
            }
            // Others are not counted: a load they read keeps its copy (the counts differ).
            _ => {}
        }
        uses
    }

    /// Counts the uses of `load` by `statement` (with the blocks it contains) into `uses`.
    fn statement_uses(&self, statement: &Statement, load: Handle<Expression>, uses: &mut Uses) {
        let counts = |h: Handle<Expression>| usize::from(self.shares[h.index()] == Some(load));
        if let Statement::Emit(ref range) = *statement {
            range.clone().for_each(|h| self.emitted_uses(h, load, uses));
        }
        uses.found += match *statement {
            Statement::If { condition, .. } => counts(condition),
            Statement::Switch { selector, .. } => counts(selector),
            Statement::Loop { break_if, .. } => break_if.map_or(0, counts),
            Statement::Return { value } => value.map_or(0, counts),
            Statement::Store { pointer, value } => counts(pointer) + counts(value),
            Statement::Call { ref arguments, .. } => arguments.iter().map(|&a| counts(a)).sum(),
            _ => 0,
        };
        nested(statement, |block| block.iter().for_each(|s| self.statement_uses(s, load, uses)));
    }

    /// Whether running `statement` may write `variable`'s registers: a store or an
    /// atomic through a pointer into it, a call given such a pointer, or a statement kind
    /// not known to write only elsewhere.
    fn may_write(&self, statement: &Statement, variable: Handle<LocalVariable>) -> bool {
        let into = |pointer: Handle<Expression>| variable_of(self.function, pointer, Indices::Any) == Some(variable);
        let own = match *statement {
            Statement::Store { pointer, .. } | Statement::Atomic { pointer, .. } => into(pointer),
            Statement::Call { ref arguments, .. } => arguments.iter().any(|&a| into(a)),
            Statement::Emit(_)
            | Statement::Block(_)
            | Statement::If { .. }
            | Statement::Switch { .. }
            | Statement::Loop { .. }
            | Statement::Break
            | Statement::Continue
            | Statement::Return { .. }
            | Statement::Kill
            | Statement::ControlBarrier(_)
            | Statement::MemoryBarrier(_)
            | Statement::ImageStore { .. }
            | Statement::WorkGroupUniformLoad { .. }
            | Statement::SubgroupBallot { .. }
            | Statement::SubgroupGather { .. }
            | Statement::SubgroupCollectiveOperation { .. } => false,
            _ => true,
        };
        let mut inner = false;
        nested(statement, |block| inner |= block.iter().any(|s| self.may_write(s, variable)));
        own || inner
    }
}

/// Calls `visit` with each block `statement` contains.
pub(super) fn nested(statement: &Statement, mut visit: impl FnMut(&Block)) {
    match statement {
        Statement::Block(block) => visit(block),
        Statement::If { accept, reject, .. } => {
            visit(accept);
            visit(reject);
        }
        Statement::Switch { cases, .. } => cases.iter().for_each(|case| visit(&case.body)),
        Statement::Loop { body, continuing, .. } => {
            visit(body);
            visit(continuing);
        }
        _ => {}
    }
}

#[cfg(test)]
mod tests {
    use super::super::decode::tests::compiled;
    use super::super::insn::Insn;

    fn copies(body: &str) -> usize {
        compiled(body).iter().filter(|i| matches!(i, Insn::Copy1 { .. })).count()
    }

    #[test]
    fn loads_read_in_place_until_their_variable_is_written() {
        // The copies of declaring `k` and `a` (their initialisers).
        let declared = copies("var k = 0u; var a = x; data[id.x] = k + a;");
        // The loop's head reads `k`, its end stores `k`: no copy for the loads.
        let loop_body = "var k = 0u; var a = x; loop { let cur = k; if cur >= a { break; } k = cur + 1u; } \
            data[id.x] = k + a;";
        assert_eq!(copies(loop_body), declared);
        // The loaded value is used after the store: one copy keeps it.
        assert_eq!(copies("var k = 0u; var a = x; let old = a; a = a + 5u; data[id.x] = old + a + k;"), declared + 1);
        // A call given a pointer to the variable writes it: `old` keeps a copy.
        let bump = "} fn bump(p: ptr<function, u32>) { *p += 1u;";
        let without_old = copies(&format!("var a = x; bump(&a); data[id.x] = a; {bump}"));
        assert_eq!(copies(&format!("var a = x; let old = a; bump(&a); data[id.x] = old + a; {bump}")), without_old + 1);
    }
}
