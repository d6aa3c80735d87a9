//! Lowering naga statements to bytecode ([`super::compiler`] opens functions, this file
//! compiles their bodies): stores, control flow as jumps (`if` around its accept block, loops as
//! a backward jump, `break`/`continue` patched when the construct closes, `switch` as a
//! table of (value, target)), barriers, atomics, subgroup operations and calls (small
//! callees inlined into the caller's frame).

use super::compiler::{Compiler, INLINE_BUDGET, INLINE_DEPTH, INLINE_EXPRESSIONS, LastValue, Scope};
use super::error::unsupported;
use super::insn::{CallInsn, CollectiveFun, CollectiveInsn, GatherInsn, Insn, Reg};
use super::layout::{Place, is_half, is_wide, shape};
use super::liveness::Slot;
use crate::error::BackendError;
use naga::{Expression, Handle, Statement, TypeInner};

impl Compiler<'_> {
    /// Lowers every statement of `block` in order, freeing the registers of the values
    /// that die after each ([`super::liveness`]).
    pub(super) fn block(&mut self, scope: &mut Scope, block: &naga::Block) -> Result<(), BackendError> {
        let mut after_emit = false;
        for (at, (statement, span)) in block.span_iter().enumerate() {
            // At the first of consecutive `Emit` statements: the compositions among their
            // expressions given registers before any of them is compiled, their components
            // placed in them (`compose_in_place`). Consecutive because naga's front end
            // splits one line's expressions around every constant it evaluates.
            let emit = matches!(statement, Statement::Emit(_));
            if emit && !after_emit {
                let emitted: Vec<Handle<Expression>> = block[at..]
                    .iter()
                    .map_while(|next| match next {
                        Statement::Emit(range) => Some(range.clone()),
                        _ => None,
                    })
                    .flatten()
                    .collect();
                self.place_compositions(scope, &emitted);
            }
            after_emit = emit;
            self.statement(scope, statement, *span)?;
            self.free_dead(scope, Slot::Statement(statement));
        }
        Ok(())
    }

    /// Lowers one statement.
    pub(super) fn statement(
        &mut self,
        scope: &mut Scope,
        statement: &Statement,
        span: naga::Span,
    ) -> Result<(), BackendError> {
        let line = self.lines_of.line(span);
        self.line = line;
        self.source = scope.source;
        // Only a store or return right after an expression may compute it in place
        // (`retarget`): any other statement may place a jump target in between.
        if !matches!(statement, Statement::Emit(_) | Statement::Store { .. } | Statement::Return { .. }) {
            self.last_value = None;
        }
        match statement {
            Statement::Emit(range) => {
                for handle in range.clone() {
                    if !scope.pre_emitted[handle.index()] {
                        self.took_over = None;
                        let first = self.insns.len();
                        self.expression(scope, handle)?;
                        // A fused load computes its value in the instruction before.
                        let first = match self.took_over.take() {
                            Some(index) if index + 1 == first => index,
                            _ => first,
                        };
                        self.last_value = Some(LastValue::new(scope, handle, first));
                    }
                    self.free_dead(scope, Slot::Expression(handle));
                }
            }
            Statement::Block(block) => self.block(scope, block)?,
            // A branch on a constant (a pipeline constant once specialised, such as
            // render/scene.wgsl's `scene_in_uniform` on every row read): only the side it
            // takes is compiled, as a driver's compiler keeps only that side. Otherwise the
            // interpreter tested the constant on every execution (issue 59: the path
            // tracer's frame, docs/benchmarks/interpreter.md).
            Statement::If { condition, accept, reject } if scope.constant[condition.index()] => {
                let reg = self.reg(scope, *condition) as usize;
                let (taken, skipped) = if self.template[reg] != 0 { (accept, reject) } else { (reject, accept) };
                self.block(scope, taken)?;
                // The values whose last read was on the side not taken are dead here too.
                for slot in super::liveness::slots(skipped) {
                    self.free_dead(scope, slot);
                }
            }
            Statement::If { condition, accept, reject }
                if !self.sanitize && self.if_as_select(scope, *condition, accept, reject)? => {}
            Statement::If { condition, accept, reject } => {
                let cond = self.reg(scope, *condition);
                self.line = line;
                let jump_reject = self.push(Insn::JumpUnless { cond, target: 0 });
                self.block(scope, accept)?;
                self.line = line;
                self.source = scope.source;
                if reject.is_empty() {
                    let end = self.here();
                    self.patch(jump_reject, end);
                } else {
                    let jump_end = self.push(Insn::Jump(0));
                    let reject_start = self.here();
                    self.patch(jump_reject, reject_start);
                    self.block(scope, reject)?;
                    let end = self.here();
                    self.patch(jump_end, end);
                }
            }
            Statement::Switch { selector, cases } => {
                let selector = self.reg(scope, *selector);
                let switch_at = self.push(Insn::Switch { selector, cases: Box::new([]), default: 0 });
                // A switch is a breakable construct.
                scope.loops.push((Vec::new(), Vec::new()));
                let mut targets = Vec::new();
                let mut fallthrough_jumps: Vec<usize> = Vec::new();
                let mut end_jumps = Vec::new();
                for case in cases {
                    let start = self.here();
                    for at in fallthrough_jumps.drain(..) {
                        self.patch(at, start);
                    }
                    let value = match case.value {
                        naga::SwitchValue::I32(v) => Some(v as u32),
                        naga::SwitchValue::U32(v) => Some(v),
                        naga::SwitchValue::Default => None,
                    };
                    targets.push((value, start));
                    self.block(scope, &case.body)?;
                    self.line = line;
                    self.source = scope.source;
                    let jump = self.push(Insn::Jump(0));
                    if case.fall_through {
                        fallthrough_jumps.push(jump);
                    } else {
                        end_jumps.push(jump);
                    }
                }
                let end = self.here();
                for at in end_jumps.into_iter().chain(fallthrough_jumps) {
                    self.patch(at, end);
                }
                let (breaks, continues) = scope.loops.pop().expect("pushed above");
                for at in breaks {
                    self.patch(at, end);
                }
                // `continue` inside a switch belongs to the enclosing loop.
                if let Some(outer) = scope.loops.last_mut() {
                    outer.1.extend(continues);
                }
                // The first case with the selector's value, else the first default, else the end.
                let mut listed: Vec<(u32, u32)> = Vec::new();
                for (value, target) in &targets {
                    if let Some(value) = value
                        && !listed.iter().any(|(v, _)| v == value)
                    {
                        listed.push((*value, *target));
                    }
                }
                let default = targets.iter().find(|(v, _)| v.is_none()).map_or(end, |(_, t)| *t);
                self.insns[switch_at] = Insn::Switch { selector, cases: listed.into_boxed_slice(), default };
            }
            Statement::Loop { body, continuing, break_if } => {
                let start = self.here();
                scope.loops.push((Vec::new(), Vec::new()));
                self.block(scope, body)?;
                let continuing_start = self.here();
                // `continue` jumps here, between the body's last expression and the
                // continuing block's first store, which naga lets use it (WGSL forbids a
                // `continue` before a declaration the continuing block uses; naga does
                // not check): that store must stay a copy (`retarget`).
                self.last_value = None;
                self.block(scope, continuing)?;
                self.line = line;
                self.source = scope.source;
                match break_if {
                    // Loop again unless the condition holds; fall through to the end if it does.
                    Some(condition) => {
                        let cond = self.reg(scope, *condition);
                        self.push(Insn::JumpUnless { cond, target: start })
                    }
                    None => self.push(Insn::Jump(start)),
                };
                let end = self.here();
                let (breaks, continues) = scope.loops.pop().expect("pushed above");
                for at in breaks {
                    self.patch(at, end);
                }
                for at in continues {
                    self.patch(at, continuing_start);
                }
            }
            Statement::Break => {
                let at = self.push(Insn::Jump(0));
                scope.loops.last_mut().ok_or_else(|| unsupported("`break` outside a loop", line))?.0.push(at);
            }
            Statement::Continue => {
                let at = self.push(Insn::Jump(0));
                // Continue skips enclosing switches: recorded on the innermost construct
                // and moved outwards when a switch closes.
                scope.loops.last_mut().ok_or_else(|| unsupported("`continue` outside a loop", line))?.1.push(at);
            }
            Statement::Return { value: value_handle } => {
                let value = value_handle.map(|v| (self.reg(scope, v), scope.lens[v.index()]));
                self.line = line;
                if scope.inlined {
                    if let (Some((src, len)), Some((dst, words)), Some(handle)) = (value, scope.result, *value_handle)
                        && !(len == words && self.retarget_last(scope, handle, dst, len))
                    {
                        self.copy(dst, src, len.min(words));
                    }
                    let at = self.push(Insn::Jump(0));
                    scope.returns.push(at);
                } else {
                    let (src, len) = value.unwrap_or((0, 0));
                    self.push(Insn::Return { src, len });
                }
            }
            Statement::ControlBarrier(flags) => {
                // A subgroup barrier orders both for the sanitizer: it cannot tell the
                // subgroups apart, and an order too many misses a race rather than
                // reporting one that is not.
                use naga::Barrier as B;
                let workgroup = flags.intersects(B::WORK_GROUP | B::SUB_GROUP);
                let storage = flags.intersects(B::STORAGE | B::TEXTURE | B::SUB_GROUP);
                self.push(Insn::Barrier { workgroup, storage });
            }
            // Memory barriers order memory only; one thread runs a workgroup in order.
            Statement::MemoryBarrier(_) => {}
            Statement::Store { pointer, value } => {
                let src = self.reg(scope, *value);
                let len = scope.lens[value.index()];
                let in_place = match scope.places[pointer.index()] {
                    Some(Place::Local(variable)) => self.retarget_last(scope, *value, variable, len),
                    _ => false,
                };
                if !in_place {
                    self.store(scope, *pointer, src, len);
                }
            }
            Statement::Call { function, arguments, result } => self.call(scope, *function, arguments, *result)?,
            Statement::WorkGroupUniformLoad { pointer, result } => {
                self.push(Insn::Barrier { workgroup: true, storage: false });
                let dst = self.reg(scope, *result);
                let len = scope.lens[result.index()];
                self.line = line;
                self.load(scope, *pointer, dst, len, None);
                self.push(Insn::Barrier { workgroup: true, storage: false });
            }
            Statement::Atomic { pointer, fun, value, result } => {
                let signed = matches!(self.ty(scope, *value), TypeInner::Scalar(s) if s.kind == naga::ScalarKind::Sint);
                let compare = match fun {
                    naga::AtomicFunction::Exchange { compare: Some(compare) } => Some(self.reg(scope, *compare)),
                    _ => None,
                };
                let atomic = super::insn::AtomicInsn {
                    pointer: self.reg(scope, *pointer),
                    fun: *fun,
                    value: self.reg(scope, *value),
                    compare,
                    signed,
                    result: result.map(|r| self.reg(scope, r)),
                };
                self.line = line;
                self.push(Insn::Atomic(Box::new(atomic)));
            }
            Statement::SubgroupGather { mode, argument, result } => {
                use naga::GatherMode as G;
                let index = match mode {
                    G::BroadcastFirst | G::QuadSwap(_) => None,
                    G::Broadcast(h)
                    | G::Shuffle(h)
                    | G::ShuffleDown(h)
                    | G::ShuffleUp(h)
                    | G::ShuffleXor(h)
                    | G::QuadBroadcast(h) => Some(self.reg(scope, *h)),
                };
                let gather = GatherInsn {
                    mode: *mode,
                    index,
                    argument: self.reg(scope, *argument),
                    len: scope.lens[argument.index()],
                    result: self.reg(scope, *result),
                };
                self.line = line;
                self.push(Insn::Gather(Box::new(gather)));
            }
            Statement::SubgroupBallot { result, predicate } => {
                let collective = CollectiveInsn {
                    fun: CollectiveFun::Ballot { predicate: predicate.map(|p| self.reg(scope, p)) },
                    argument: 0,
                    len: 4,
                    result: self.reg(scope, *result),
                };
                self.line = line;
                self.push(Insn::Collective(Box::new(collective)));
            }
            Statement::SubgroupCollectiveOperation { op, collective_op, argument, result } => {
                let ty = self.ty(scope, *argument);
                let kind = match shape(ty) {
                    Some((kind, _)) if !is_wide(ty) && !is_half(ty) => kind,
                    _ => return Err(unsupported(&format!("subgroup {op:?} {collective_op:?} on {ty:?}"), line)),
                };
                let collective = CollectiveInsn {
                    fun: CollectiveFun::Operation { op: *op, collective: *collective_op, kind },
                    argument: self.reg(scope, *argument),
                    len: scope.lens[argument.index()],
                    result: self.reg(scope, *result),
                };
                self.line = line;
                self.push(Insn::Collective(Box::new(collective)));
            }
            Statement::ImageStore { image, coordinate, array_index, value } => {
                self.image_store(scope, *image, *coordinate, *array_index, *value)?;
            }
            other => {
                let name = format!("{other:?}");
                let name = name.split([' ', '(', '{']).next().unwrap_or("statement").to_string();
                return Err(unsupported(&format!("statement `{name}`"), line));
            }
        }
        Ok(())
    }

    /// A call: inlined if the callee is small, the nesting shallow and the code's inlining
    /// budget not spent, else a `Call`.
    fn call(
        &mut self,
        scope: &mut Scope,
        function: Handle<naga::Function>,
        arguments: &[Handle<Expression>],
        result: Option<Handle<Expression>>,
    ) -> Result<(), BackendError> {
        let module = self.module;
        let info = self.info;
        let callee = &module.functions[function];
        let line = self.line;
        let result = result.map(|r| (self.reg(scope, r), scope.lens[r.index()]));
        let size = callee.expressions.len();
        if size <= INLINE_EXPRESSIONS && scope.depth < INLINE_DEPTH && self.inlined + size <= INLINE_BUDGET {
            self.inlined += size;
            // A pointer argument with a known target passes its place, and its register
            // only if it has one: the callee makes it where one is read (`place_reg`).
            let values: Vec<(Reg, Option<Place>)> = arguments
                .iter()
                .map(|a| match scope.places[a.index()] {
                    Some(place) => (scope.regs[a.index()], Some(place)),
                    None => (self.reg(scope, *a), None),
                })
                .collect();
            let mut unused = Vec::new();
            let mark = self.mark();
            let mut inner = self.open(callee, &info[function], Some(&values), result, scope.depth + 1, &mut unused)?;
            self.block(&mut inner, &callee.body)?;
            let end = self.here();
            for at in std::mem::take(&mut inner.returns) {
                self.patch(at, end);
            }
            // The callee's registers, dead from here on, serve the caller's later values.
            self.release(mark);
        } else {
            let callee_arguments = &self.arguments[function.index()];
            let arguments = callee_arguments
                .iter()
                .map(|&(i, dst, len)| {
                    let src = self.reg(scope, arguments[i as usize]);
                    (src, len, dst)
                })
                .collect();
            self.line = line;
            self.source = scope.source;
            self.push(Insn::Call(Box::new(CallInsn { code: function.index() as u32, arguments, result })));
        }
        self.line = line;
        self.source = scope.source;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::super::decode::tests::compiled_with;
    use super::super::insn::Insn;

    /// Branch instructions (a jump on a condition, or the select of an if-conversion) of
    /// a kernel with `declarations` whose body branches on `condition`.
    fn branches(declarations: &str, condition: &str) -> usize {
        let body = format!("if {condition} {{ data[id.x] = x + 1u; }} else {{ data[id.x] = x * 3u; }}");
        compiled_with(declarations, &body)
            .iter()
            .filter(|i| matches!(i, Insn::JumpUnless { .. } | Insn::Select { .. }))
            .count()
    }

    #[test]
    fn a_call_tree_that_doubles_at_every_level_stops_inlining_at_the_budget() {
        // f(k) calls f(k-1) twice, 14 levels within the inlining depth: 2^14 copies of f0
        // (about 40 IR expressions) if every call were inlined, 650 000 expressions.
        let mut declarations = String::from("fn f0(x: u32) -> u32 { var y = x;");
        for i in 0..10 {
            declarations += &format!(" y = y * {}u + (y >> 3u);", i + 3);
        }
        declarations += " return y; }\n";
        for k in 1..=14 {
            declarations += &format!("fn f{k}(x: u32) -> u32 {{ return f{p}(x) ^ f{p}(x + 1u); }}\n", p = k - 1);
        }
        let insns = compiled_with(&declarations, "data[id.x] = f14(x);");
        let calls = insns.iter().filter(|i| matches!(i, Insn::Call(_))).count();
        assert!(calls > 0, "the whole tree was inlined: {} instructions", insns.len());
    }

    #[test]
    fn a_branch_on_a_constant_compiles_only_the_side_it_takes() {
        assert_eq!(branches("const F: bool = false;", "F"), 0);
        assert_eq!(branches("const F: bool = true;", "!F"), 0);
        // The same branch on a value: a branch.
        assert_eq!(branches("", "x > 3u"), 1);
    }
}
