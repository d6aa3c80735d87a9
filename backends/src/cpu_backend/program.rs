//! naga IR compiled once into a flat program per function: a register slot per
//! expression (a fixed word range of the frame's register file, sized by the expression's
//! type) and a list of ops with jumps, so that an invocation is a resumable
//! (function, pc, registers) state that can stop at a barrier and go on later.

use super::error::unsupported;
use crate::error::BackendError;
use naga::{Expression, Handle, Module, Statement, TypeInner};

/// Words of a value of type `inner` (bool and every 32-bit scalar: one word).
pub(super) fn words_of(module: &Module, inner: &TypeInner) -> Result<u32, String> {
    Ok(match *inner {
        TypeInner::Scalar(s) | TypeInner::Atomic(s) => {
            if s.width != 4 && s.kind != naga::ScalarKind::Bool {
                return Err(format!("{}-bit scalars", s.width * 8));
            }
            1
        }
        TypeInner::Vector { size, scalar } => {
            if scalar.width != 4 && scalar.kind != naga::ScalarKind::Bool {
                return Err(format!("{}-bit vectors", scalar.width * 8));
            }
            size as u32
        }
        TypeInner::Pointer { .. } | TypeInner::ValuePointer { .. } => 2,
        TypeInner::Matrix { columns, rows, .. } => {
            // Columns are padded like vec3 → 4 words in memory.
            let row_words = if rows == naga::VectorSize::Tri { 4 } else { rows as u32 };
            columns as u32 * row_words
        }
        TypeInner::Array { base, size, stride } => {
            // The element type must be supported too.
            words_of(module, &module.types[base].inner)?;
            match size {
                naga::ArraySize::Constant(n) => n.get() * stride / 4,
                _ => return Err("runtime-sized arrays as values".into()),
            }
        }
        TypeInner::Struct { span, .. } => span / 4,
        _ => return Err(format!("type {inner:?}")),
    })
}

/// Where an expression's value lives in the frame's register file.
#[derive(Clone, Copy, Debug)]
pub(super) struct Slot {
    pub offset: u32,
    pub len: u32,
}

/// One op of a compiled function.
#[derive(Clone, Debug)]
pub(super) enum Op {
    /// Evaluate these expressions in order (naga's `Emit`).
    Emit(std::ops::Range<u32>),
    Jump(u32),
    /// Jump when the bool register is false.
    JumpUnless {
        condition: Handle<Expression>,
        target: u32,
    },
    /// Jump to the first case whose value equals the selector (else the default).
    Switch {
        selector: Handle<Expression>,
        cases: Vec<(Option<u32>, u32)>,
    },
    Store {
        pointer: Handle<Expression>,
        value: Handle<Expression>,
    },
    Call {
        function: Handle<naga::Function>,
        arguments: Vec<Handle<Expression>>,
        result: Option<Handle<Expression>>,
    },
    Return(Option<Handle<Expression>>),
    /// Workgroup (control) barrier: every invocation must reach this same op.
    Barrier,
    /// Load into `result` (the middle of `workgroupUniformLoad`: barrier, load, barrier).
    LoadInto {
        pointer: Handle<Expression>,
        result: Handle<Expression>,
    },
    Atomic {
        pointer: Handle<Expression>,
        fun: naga::AtomicFunction,
        value: Handle<Expression>,
        result: Option<Handle<Expression>>,
    },
    /// A subgroup gather: every invocation of the workgroup must reach this same op.
    Gather {
        mode: naga::GatherMode,
        argument: Handle<Expression>,
        result: Handle<Expression>,
    },
}

/// A compiled function.
pub(super) struct CompiledFunction {
    pub ops: Vec<Op>,
    /// Per expression handle index: its register slot.
    pub slots: Vec<Slot>,
    pub register_words: u32,
    /// Per local variable: word offset in the frame's local memory.
    pub local_offsets: Vec<u32>,
    pub local_words: u32,
    /// Expressions evaluated when the frame starts (literals, constants, variables, arguments).
    pub pre_emit: Vec<Handle<Expression>>,
    /// Source line of each op, for messages.
    pub lines: Vec<u32>,
    /// Type of each expression.
    pub types: Vec<TypeInner>,
    /// Source line of each expression.
    pub expression_lines: Vec<u32>,
    /// Handle of each expression, by index.
    pub handles: Vec<Handle<Expression>>,
    /// Registers with every frame-independent pre-emit value (constants, global variable
    /// pointers) filled in, made on the first call and copied into every later frame.
    pub template: std::sync::OnceLock<Vec<u32>>,
    pub name: String,
}

/// Byte offsets where source lines start, for span → line lookups.
pub(super) struct LineIndex(Vec<usize>);

impl LineIndex {
    pub(super) fn new(source: &str) -> Self {
        Self(std::iter::once(0).chain(source.match_indices('\n').map(|(i, _)| i + 1)).collect())
    }

    /// 1-based line of a span's start (0 for spans without a position).
    pub(super) fn line(&self, span: naga::Span) -> u32 {
        span.to_range().map_or(0, |r| self.0.partition_point(|&start| start <= r.start) as u32)
    }
}

struct Builder<'a> {
    lines_of: &'a LineIndex,
    ops: Vec<Op>,
    lines: Vec<u32>,
    /// Per enclosing loop: (ops to patch for break, continue target or None while unknown,
    /// ops to patch for continue).
    loops: Vec<(Vec<usize>, Vec<usize>)>,
}

impl Builder<'_> {
    fn line(&self, span: naga::Span) -> u32 {
        self.lines_of.line(span)
    }

    fn push(&mut self, op: Op, span: naga::Span) -> usize {
        self.ops.push(op);
        self.lines.push(self.line(span));
        self.ops.len() - 1
    }

    fn here(&self) -> u32 {
        self.ops.len() as u32
    }

    fn patch(&mut self, at: usize, target: u32) {
        match &mut self.ops[at] {
            Op::Jump(t) | Op::JumpUnless { target: t, .. } => *t = target,
            _ => unreachable!("only jumps are patched"),
        }
    }

    fn block(&mut self, block: &naga::Block) -> Result<(), BackendError> {
        for (statement, span) in block.span_iter() {
            self.statement(statement, *span)?;
        }
        Ok(())
    }

    fn statement(&mut self, statement: &Statement, span: naga::Span) -> Result<(), BackendError> {
        match statement {
            Statement::Emit(range) => {
                let (first, last) = match range.first_and_last() {
                    Some((first, last)) => (first.index() as u32, last.index() as u32 + 1),
                    None => return Ok(()),
                };
                self.push(Op::Emit(first..last), span);
            }
            Statement::Block(block) => self.block(block)?,
            Statement::If { condition, accept, reject } => {
                let jump_reject = self.push(Op::JumpUnless { condition: *condition, target: 0 }, span);
                self.block(accept)?;
                let jump_end = self.push(Op::Jump(0), span);
                let reject_start = self.here();
                self.patch(jump_reject, reject_start);
                self.block(reject)?;
                let end = self.here();
                self.patch(jump_end, end);
            }
            Statement::Switch { selector, cases } => {
                let switch_at = self.push(Op::Switch { selector: *selector, cases: Vec::new() }, span);
                // A switch is a breakable construct.
                self.loops.push((Vec::new(), Vec::new()));
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
                    self.block(&case.body)?;
                    let jump = self.push(Op::Jump(0), span);
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
                let (breaks, continues) = self.loops.pop().expect("pushed above");
                for at in breaks {
                    self.patch(at, end);
                }
                // `continue` inside a switch belongs to the enclosing loop.
                if let Some(outer) = self.loops.last_mut() {
                    outer.1.extend(continues);
                }
                if !targets.iter().any(|(v, _)| v.is_none()) {
                    targets.push((None, end));
                }
                self.ops[switch_at] = Op::Switch { selector: *selector, cases: targets };
            }
            Statement::Loop { body, continuing, break_if } => {
                let start = self.here();
                self.loops.push((Vec::new(), Vec::new()));
                self.block(body)?;
                let continuing_start = self.here();
                self.block(continuing)?;
                match break_if {
                    // Loop again unless the condition holds; fall through to the end if it does.
                    Some(condition) => self.push(Op::JumpUnless { condition: *condition, target: start }, span),
                    None => self.push(Op::Jump(start), span),
                };
                let end = self.here();
                let (breaks, continues) = self.loops.pop().expect("pushed above");
                for at in breaks {
                    self.patch(at, end);
                }
                for at in continues {
                    self.patch(at, continuing_start);
                }
            }
            Statement::Break => {
                let at = self.push(Op::Jump(0), span);
                let line = self.line(span);
                self.loops.last_mut().ok_or_else(|| unsupported("`break` outside a loop", line))?.0.push(at);
            }
            Statement::Continue => {
                let at = self.push(Op::Jump(0), span);
                let line = self.line(span);
                // Continue skips enclosing switches: recorded on the innermost construct
                // and moved outwards when a switch closes.
                self.loops.last_mut().ok_or_else(|| unsupported("`continue` outside a loop", line))?.1.push(at);
            }
            Statement::Return { value } => {
                self.push(Op::Return(*value), span);
            }
            Statement::ControlBarrier(_) => {
                self.push(Op::Barrier, span);
            }
            // Memory barriers order memory only; one thread runs a workgroup in order.
            Statement::MemoryBarrier(_) => {}
            Statement::Store { pointer, value } => {
                self.push(Op::Store { pointer: *pointer, value: *value }, span);
            }
            Statement::Call { function, arguments, result } => {
                self.push(Op::Call { function: *function, arguments: arguments.clone(), result: *result }, span);
            }
            Statement::WorkGroupUniformLoad { pointer, result } => {
                self.push(Op::Barrier, span);
                self.push(Op::LoadInto { pointer: *pointer, result: *result }, span);
                self.push(Op::Barrier, span);
            }
            Statement::Atomic { pointer, fun, value, result } => {
                self.push(Op::Atomic { pointer: *pointer, fun: *fun, value: *value, result: *result }, span);
            }
            Statement::SubgroupGather { mode, argument, result } => {
                self.push(Op::Gather { mode: *mode, argument: *argument, result: *result }, span);
            }
            other => {
                let name = format!("{other:?}");
                let name = name.split([' ', '(', '{']).next().unwrap_or("statement").to_string();
                return Err(unsupported(&format!("statement `{name}`"), self.line(span)));
            }
        }
        Ok(())
    }
}

/// Compiles `function` (whose expression types are in `info`).
pub(super) fn compile_function(
    module: &Module,
    function: &naga::Function,
    info: &naga::valid::FunctionInfo,
    lines_of: &LineIndex,
) -> Result<CompiledFunction, BackendError> {
    let mut slots = Vec::with_capacity(function.expressions.len());
    let mut types = Vec::with_capacity(function.expressions.len());
    let mut expression_lines = Vec::with_capacity(function.expressions.len());
    let mut offset = 0u32;
    let mut pre_emit = Vec::new();
    // Constant expressions (literals, constants, and compositions of them) are never
    // emitted: they are evaluated when a frame starts, like variables and arguments.
    let kinds = naga::proc::ExpressionKindTracker::from_arena(&function.expressions);
    for (handle, expression) in function.expressions.iter() {
        let inner = info[handle].ty.inner_with(&module.types);
        types.push(inner.clone());
        let line = lines_of.line(function.expressions.get_span(handle));
        expression_lines.push(line);
        let len = words_of(module, inner).map_err(|what| unsupported(&what, line))?;
        slots.push(Slot { offset, len });
        offset += len;
        if kinds.is_const(handle)
            || matches!(
                expression,
                Expression::Literal(_)
                    | Expression::Constant(_)
                    | Expression::ZeroValue(_)
                    | Expression::FunctionArgument(_)
                    | Expression::GlobalVariable(_)
                    | Expression::LocalVariable(_)
            )
        {
            pre_emit.push(handle);
        }
    }
    let mut local_offsets = Vec::new();
    let mut local_words = 0;
    for (_, local) in function.local_variables.iter() {
        local_offsets.push(local_words);
        local_words += words_of(module, &module.types[local.ty].inner).map_err(|what| unsupported(&what, 0))?;
    }
    let mut builder = Builder { lines_of, ops: Vec::new(), lines: Vec::new(), loops: Vec::new() };
    builder.block(&function.body)?;
    builder.ops.push(Op::Return(None));
    builder.lines.push(0);
    Ok(CompiledFunction {
        ops: builder.ops,
        slots,
        register_words: offset,
        local_offsets,
        local_words,
        pre_emit,
        lines: builder.lines,
        types,
        expression_lines,
        handles: function.expressions.iter().map(|(h, _)| h).collect(),
        template: std::sync::OnceLock::new(),
        name: function.name.clone().unwrap_or_default(),
    })
}

impl CompiledFunction {
    /// WGSL source line of an expression.
    pub(super) fn line_of_expression(&self, handle: Handle<Expression>) -> u32 {
        self.expression_lines.get(handle.index()).copied().unwrap_or(0)
    }
}
