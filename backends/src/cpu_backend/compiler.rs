//! Compiling one naga function into the register bytecode ([`super::insn`]): the
//! [`Compiler`]'s state while it lowers a function into a [`Code`], the [`Scope`] of the
//! function or inlined callee being lowered, and the allocation of their registers.
//!
//! Each function becomes a [`Code`]: its instructions, a register template with every
//! value known at compile time filled in, and the registers that receive its arguments.
//! Calls of small functions (at most [`INLINE_EXPRESSIONS`] IR expressions, up to
//! [`INLINE_DEPTH`] levels deep) are inlined: the callee's expressions and local
//! variables get registers of the caller's frame, its arguments are the caller's
//! registers, its returns jump to the end of its body. Every expression gets its own
//! register range while it is alive (naga evaluates each expression once where it is
//! emitted, and an expression's uses are dominated by its emission), so a field of a
//! struct value, a component of a vector or a bitcast is the source's register range
//! itself, not a copy; after its last read ([`super::liveness`]) the range serves later
//! values.
//!
//! Why the lowering itself is elsewhere: each construct adds its methods to [`Compiler`]
//! in a file of its own, above this one: expressions in [`super::expression`] (math
//! builtins in [`super::math_call`], textures in [`super::image_lower`]), statements in
//! [`super::statement`], loads and stores in [`super::access`], and the passes that make
//! the code shorter ([`super::if_conversion`], [`super::retarget`],
//! [`super::element_load`]). What the whole kernel needs (its globals, the functions in
//! order, the steps after lowering) is [`super::decode`]'s.

use super::budget::{Space, add_words, check_space};
use super::constant::{compose, literal};
use super::error::unsupported;
use super::insn::{Insn, Reg, Runs};
use super::layout::{Place, words_of};
use super::liveness::{DeadAfter, Slot};
use super::memory;
use super::program::Code;
use crate::error::BackendError;
use naga::{Expression, Handle, Module, TypeInner};

/// Callees with at most this many IR expressions are inlined.
pub(super) const INLINE_EXPRESSIONS: usize = 400;
/// Inlining stops this many calls deep. Why 16, not 8: since the scene is read through
/// generated readers and `scene_row` (render/scene.wgsl), some of the path tracer's reads
/// lie deeper than 8 calls, and a call left as a call costs far more than its body here
/// (while any invocation is inside one, the scheduler compares whole stacks): at 8 the
/// frame took 283 ms, at 16 187 ms (issue 59, docs/benchmarks/interpreter.md).
/// WGSL has no recursion, and each callee is small ([`INLINE_EXPRESSIONS`]), so the
/// depth bounds the code's growth.
pub(super) const INLINE_DEPTH: u32 = 16;
/// IR expressions one code may take in by inlining; past them calls stay calls. Why: a
/// call tree that branches at every level grows twice per level when inlined, and 16
/// levels could make a small kernel millions of instructions long (a compile error at
/// [`super::budget::SPACE_CAP`], or minutes); the largest kernel in the repository inlines
/// under 24 000 (tests/tests/kernel_size.rs holds them to budgets).
pub(super) const INLINE_BUDGET: usize = 250_000;
/// Marks an expression without a register yet.
pub(super) const NONE: Reg = Reg::MAX;

/// Byte offsets where source lines start, for span → line lookups.
pub(super) struct LineIndex(Vec<usize>);

impl LineIndex {
    /// The index of `source`'s lines.
    pub(super) fn new(source: &str) -> Self {
        Self(std::iter::once(0).chain(source.match_indices('\n').map(|(i, _)| i + 1)).collect())
    }

    /// 1-based line of a span's start (0 for spans without a position).
    pub(super) fn line(&self, span: naga::Span) -> u32 {
        span.to_range().map_or(0, |r| self.0.partition_point(|&start| start <= r.start) as u32)
    }
}

/// The last expression compiled: its scope (the naga function and the inlining depth,
/// as handles of different scopes collide), its handle and the index of its first
/// instruction. Held by the [`Compiler`] ([`Compiler::last_value`]) for the passes that
/// rewrite that instruction ([`super::retarget`], [`super::element_load`]).
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) struct LastValue {
    function: *const naga::Function,
    depth: u32,
    handle: Handle<Expression>,
    first_insn: usize,
}

impl LastValue {
    /// `handle` of `scope`, compiled from instruction `first_insn` on.
    pub(super) fn new(scope: &Scope, handle: Handle<Expression>, first_insn: usize) -> Self {
        Self { function: scope.function, depth: scope.depth, handle, first_insn }
    }
}

/// Per function being compiled into a code (the function itself or an inlined callee):
/// where its expressions and variables live.
pub(super) struct Scope<'a> {
    /// The function.
    pub function: &'a naga::Function,
    /// Its validation info (expression types).
    pub info: &'a naga::valid::FunctionInfo,
    /// Index of its name in the program's names.
    pub source: u32,
    /// Per expression: its register (`NONE` until it has one).
    pub regs: Vec<Reg>,
    /// Per expression: its words.
    pub lens: Vec<u32>,
    /// Per expression: its line.
    pub lines: Vec<u32>,
    /// Per pointer expression whose target is known when compiling: that target.
    pub places: Vec<Option<Place>>,
    /// Per expression: whether its value is in the template (a compile-time constant).
    pub constant: Vec<bool>,
    /// Per expression: evaluated when the scope starts (not again where emitted).
    pub pre_emitted: Vec<bool>,
    /// Per expression: a load that reads its variable's registers in place
    /// ([`super::load_alias`]).
    pub in_place_loads: Vec<bool>,
    /// Per expression: for a load whose uses read some of its words, those words
    /// ([`super::load_fields`]).
    pub partial_loads: Vec<Option<Runs>>,
    /// Per local variable: its register.
    pub locals: Vec<Reg>,
    /// Inlined: register and words that receive the return value.
    pub result: Option<(Reg, u32)>,
    /// Inlined: the body's return jumps, patched to its end.
    pub returns: Vec<usize>,
    /// Inlined into another function (returns are jumps).
    pub inlined: bool,
    /// Inlining depth.
    pub depth: u32,
    /// Per enclosing breakable construct: (break jumps, continue jumps).
    pub(super) loops: Vec<(Vec<usize>, Vec<usize>)>,
    /// Per expression: the index of the run-time range [`Compiler::reg`] allocated for it
    /// in [`Compiler::runtime`] ([`NOT_OWNED`] if there is none to free: a constant, an
    /// alias of another value's registers, a caller's register, a component computed in
    /// its composition's registers ([`super::compose_in_place`]), a value with registers
    /// never shared ([`DeadAfter::own_registers`]), or one freed already).
    pub(super) owned: Vec<u32>,
    /// Where each of its values dies ([`super::liveness`]).
    pub(super) dead_after: DeadAfter,
}

/// Marks an expression that owns no run-time range ([`Scope::owned`]).
const NOT_OWNED: u32 = u32::MAX;

/// Compiles one code: instructions, registers and the module context they need.
pub(super) struct Compiler<'a> {
    /// The kernel's module.
    pub module: &'a Module,
    /// Its validation info.
    pub info: &'a naga::valid::ModuleInfo,
    pub(super) lines_of: &'a LineIndex,
    /// Per global variable: (region tag, word offset).
    pub globals: &'a [(u32, u32)],
    /// Values of the module's constant expressions.
    pub global_values: &'a [Vec<u32>],
    /// Bound buffers (for checking static buffer slots).
    pub buffer_count: usize,
    /// Compiling a sanitizing program ([`super::sanitize`]): no if-conversion, whose
    /// speculated loads and indices would be reported although WGSL never makes them.
    pub sanitize: bool,
    /// The kernel's name, for messages.
    kernel: &'a str,
    /// Register words the scopes opened so far may take (their expressions' and
    /// variables' words): an upper bound of the template's length, held under
    /// [`super::budget::SPACE_CAP`] before any of it is allocated.
    committed: u64,
    /// IR expressions inlined into the code so far (held under [`INLINE_BUDGET`]).
    pub(super) inlined: usize,
    names: &'a mut Vec<String>,
    /// Per module function already compiled: its arguments' registers.
    pub(super) arguments: &'a [Vec<(u32, Reg, u32)>],
    /// The code being built.
    pub insns: Vec<Insn>,
    insn_lines: Vec<u32>,
    insn_sources: Vec<u32>,
    /// The register template being built.
    pub template: Vec<u32>,
    /// Local-variable pointer registers being built.
    pub local_pointers: Vec<(Reg, u32)>,
    /// Register ranges free for later values: dead values' ([`Compiler::free_dead`]) and
    /// those of inlined callees whose bodies are compiled ([`Compiler::release`]).
    pub(super) free: Vec<(Reg, u32)>,
    /// Ranges allocated for values computed at run time, in allocation order, each with
    /// whether it was freed already (after its value's last read, [`Compiler::free_dead`]).
    pub(super) runtime: Vec<(Reg, u32, bool)>,
    /// Whether a value's range is freed after its last read. Off while if-conversion
    /// compiles branches that may be undone or whose values its selects read afterwards
    /// ([`super::if_conversion`]).
    pub(super) free_early: bool,
    /// Ranges holding values that are not computed where they are used: compile-time
    /// values in the template, pointers set when a frame starts. Never reused.
    permanent: std::collections::HashSet<Reg>,
    /// Ranges handed out again from `free`.
    reused: std::collections::HashSet<Reg>,
    /// The register of each compile-time value in the template, by its words: equal
    /// values share registers (never written at run time), so that a callee inlined
    /// many times adds its constants once.
    constants: std::collections::HashMap<Vec<u32>, Reg>,
    /// Line of the instructions being pushed.
    pub line: u32,
    /// Source function of the instructions being pushed.
    pub source: u32,
    /// The expression compiled last, while the statement after it may store it
    /// ([`super::retarget`]).
    pub(super) last_value: Option<LastValue>,
    /// The instruction that the expression being compiled took over instead of adding
    /// its own (a fused element load, [`super::element_load`]): it computes the value.
    pub(super) took_over: Option<usize>,
}

impl Compiler<'_> {
    /// Allocates `len` registers for a value computed at run time: from the free ranges
    /// (dead values', inlined callees' already compiled) if one is large enough, else
    /// new. A free range of `len` words exactly, else a larger one, each searched from the
    /// end of the free list, where the ranges freed most recently mostly are: their
    /// registers are the likeliest still in the cache.
    pub(super) fn alloc(&mut self, len: u32) -> Reg {
        let exact = self.free.iter().rposition(|&(_, free)| free == len && len > 0);
        let fits = || self.free.iter().rposition(|&(_, free)| free > len && len > 0);
        let at = match exact.or_else(fits) {
            Some(i) => {
                let (at, free) = self.free[i];
                if free == len {
                    self.free.swap_remove(i);
                } else {
                    self.free[i] = (at + len, free - len);
                }
                self.reused.insert(at);
                at
            }
            None => self.alloc_new(len),
        };
        self.runtime.push((at, len, false));
        at
    }

    /// Allocates `len` new registers at the template's end (reused later only where
    /// [`Compiler::alloc`] records them as a run-time range).
    fn alloc_new(&mut self, len: u32) -> Reg {
        let at = self.template.len() as Reg;
        self.template.resize(self.template.len() + len as usize, 0);
        at
    }

    /// The register of `handle`, a value that is not computed where it is used (a
    /// compile-time value written into the template, a pointer set when the frame
    /// starts): new registers, never reused, since the template and the frame start
    /// write them once while the code using them may run many times.
    pub(super) fn reg_permanent(&mut self, scope: &mut Scope, handle: Handle<Expression>) -> Reg {
        let index = handle.index();
        if scope.regs[index] == NONE {
            scope.regs[index] = self.alloc_new(scope.lens[index]);
        } else if self.reused.contains(&scope.regs[index]) {
            // Not reached: these expressions get their register where they are compiled,
            // or a pointer with a known target where one is first read (`place_reg`),
            // from `reg_permanent` or `constant`, never from the reused ranges.
            self.fail("internal: a compile-time value in a reused register".into(), self.line);
        }
        self.permanent.insert(scope.regs[index]);
        scope.regs[index]
    }

    /// The register of `handle`, a compile-time value `value` (zero-extended to the
    /// expression's words), written into the template: the register of an equal value
    /// already there, or new ones.
    pub(super) fn constant(&mut self, scope: &mut Scope, handle: Handle<Expression>, value: &[u32]) -> Reg {
        let index = handle.index();
        let len = scope.lens[index] as usize;
        let mut words = value[..value.len().min(len)].to_vec();
        words.resize(len, 0);
        if scope.regs[index] == NONE {
            if let Some(&reg) = self.constants.get(&words) {
                scope.regs[index] = reg;
                return reg;
            }
            let reg = self.reg_permanent(scope, handle);
            self.template[reg as usize..reg as usize + len].copy_from_slice(&words);
            self.constants.insert(words, reg);
            reg
        } else {
            let reg = self.reg_permanent(scope, handle);
            self.template[reg as usize..reg as usize + len].copy_from_slice(&words);
            reg
        }
    }

    /// The number of run-time ranges allocated so far: what [`Compiler::release`] takes.
    pub(super) fn mark(&self) -> usize {
        self.runtime.len()
    }

    /// Frees the run-time ranges allocated since `mark`, once an inlined callee's body is
    /// compiled. Sound because a callee's values are dead after it returns (WGSL returns
    /// no pointers, the caller receives the result in its own registers), every value is
    /// written where it is evaluated before any use reads it, its variables are zeroed
    /// when its body starts, and a register taken again afterwards belongs to an
    /// expression whose uses end with its block, before the callee can run again (naga
    /// scopes expressions to the block that emits them).
    pub(super) fn release(&mut self, mark: usize) {
        for (at, len, freed) in self.runtime.drain(mark..) {
            if !freed && !self.permanent.contains(&at) {
                self.free.push((at, len));
            }
        }
    }

    /// Frees the ranges of the values of `scope` that die after `slot`
    /// ([`super::liveness`]).
    pub(super) fn free_dead(&mut self, scope: &mut Scope, slot: Slot) {
        if !self.free_early {
            return;
        }
        for index in 0..scope.dead_after.at(slot).len() {
            let handle = scope.dead_after.at(slot)[index];
            self.free_value(scope, handle);
        }
    }

    /// Frees the run-time range `handle` of `scope` owns, if it has one not freed yet.
    fn free_value(&mut self, scope: &mut Scope, handle: Handle<Expression>) {
        let owned = std::mem::replace(&mut scope.owned[handle.index()], NOT_OWNED);
        if owned == NOT_OWNED {
            return;
        }
        scope.regs[handle.index()] = NONE;
        let (at, len, freed) = &mut self.runtime[owned as usize];
        if !*freed && !self.permanent.contains(at) {
            *freed = true;
            self.free.push((*at, *len));
        }
    }

    /// Appends an instruction; returns its index.
    pub(super) fn push(&mut self, insn: Insn) -> usize {
        self.insns.push(insn);
        self.insn_lines.push(self.line);
        self.insn_sources.push(self.source);
        self.insns.len() - 1
    }

    /// Removes the instructions from index `len` on (an undone compilation).
    pub(super) fn truncate(&mut self, len: usize) {
        self.insns.truncate(len);
        self.insn_lines.truncate(len);
        self.insn_sources.truncate(len);
    }

    /// Appends a copy of `len` words (nothing when `len` is 0 or source and target agree).
    pub(super) fn copy(&mut self, dst: Reg, src: Reg, len: u32) {
        if len == 0 || dst == src {
            return;
        }
        self.push(match len {
            1 => Insn::Copy1 { dst, src },
            2 => Insn::Copy2 { dst, src },
            3 => Insn::Copy3 { dst, src },
            4 => Insn::Copy4 { dst, src },
            _ => Insn::Copy { dst, src, len },
        });
    }

    /// Appends a runtime failure for an unsupported construct.
    pub(super) fn fail(&mut self, what: String, line: u32) {
        self.push(Insn::Fail(Box::new((what, line))));
    }

    pub(super) fn here(&self) -> u32 {
        self.insns.len() as u32
    }

    pub(super) fn patch(&mut self, at: usize, to: u32) {
        match &mut self.insns[at] {
            Insn::Jump(target) | Insn::JumpUnless { target, .. } => *target = to,
            _ => unreachable!("only jumps are patched"),
        }
    }

    /// The type of expression `handle` of `scope`.
    pub(super) fn ty<'s>(&'s self, scope: &'s Scope, handle: Handle<Expression>) -> &'s TypeInner {
        scope.info[handle].ty.inner_with(&self.module.types)
    }

    /// The register of expression `handle` (allocated, zero, if it has none yet; for a
    /// pointer whose target is known when compiling, [`Compiler::place_reg`]).
    pub(super) fn reg(&mut self, scope: &mut Scope, handle: Handle<Expression>) -> Reg {
        let index = handle.index();
        if scope.regs[index] == NONE {
            if let Some(place) = scope.places[index] {
                return self.place_reg(scope, handle, place);
            }
            if scope.dead_after.own_registers(handle) {
                scope.regs[index] = self.alloc_new(scope.lens[index]);
            } else {
                scope.regs[index] = self.alloc(scope.lens[index]);
                scope.owned[index] = (self.runtime.len() - 1) as u32;
            }
        }
        scope.regs[index]
    }

    /// The register of `handle`, a pointer to `place`, made the first time an instruction
    /// reads it. Why not when the pointer is made: most pointers with a known target are
    /// only loaded from and stored through, which [`super::access`] compiles to the place
    /// itself, and every register made costs each invocation its writing when a frame
    /// starts (the template's copy, or [`Code::local_pointers`]'s fill). Made here: a
    /// local variable's pointer is set when the frame starts (its frame is known only
    /// then); any other pointer's words are in the template; either is shared by every
    /// pointer to the same target.
    fn place_reg(&mut self, scope: &mut Scope, handle: Handle<Expression>, place: Place) -> Reg {
        match place {
            Place::Local(variable) => {
                // Every pointer to one variable has the same words in a frame (an inlined
                // callee's pointer argument too), so one register serves them all. Found in
                // `local_pointers` itself, so that a speculation undone (`if_conversion`),
                // which cuts that list back, forgets it as well.
                if let Some(&(reg, _)) = self.local_pointers.iter().find(|&&(_, v)| v == variable) {
                    scope.regs[handle.index()] = reg;
                    return reg;
                }
                let reg = self.reg_permanent(scope, handle);
                self.local_pointers.push((reg, variable));
                reg
            }
            Place::Workgroup(address) => self.constant(scope, handle, &[memory::WORKGROUP, address]),
            Place::Private(address) => self.constant(scope, handle, &[memory::PRIVATE, address]),
            Place::Buffer(buffer, address) => self.constant(scope, handle, &[memory::BUFFER | buffer, address]),
        }
    }

    /// Opens the scope of `function`: registers for its expressions and variables,
    /// compile-time values into the template, the pre-emitted expressions (arguments,
    /// variables, constants) and the variables' initialisation.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn open<'f>(
        &mut self,
        function: &'f naga::Function,
        info: &'f naga::valid::FunctionInfo,
        arguments: Option<&[(Reg, Option<Place>)]>,
        result: Option<(Reg, u32)>,
        depth: u32,
        code_arguments: &mut Vec<(u32, Reg, u32)>,
    ) -> Result<Scope<'f>, BackendError> {
        let count = function.expressions.len();
        // What the scope may take, checked against the cap before anything of that size
        // is allocated: every expression and variable gets at most one register range.
        let mut lens = Vec::with_capacity(count);
        let mut lines = Vec::with_capacity(count);
        let mut words = 0u64;
        for (handle, _) in function.expressions.iter() {
            let line = self.lines_of.line(function.expressions.get_span(handle));
            let inner = info[handle].ty.inner_with(&self.module.types);
            let len = words_of(self.module, inner).map_err(|what| unsupported(&what, line))?;
            words = add_words(self.kernel, Space::Function, words, u64::from(len))?;
            lines.push(line);
            lens.push(len);
        }
        let mut local_words = Vec::with_capacity(function.local_variables.len());
        for (handle, local) in function.local_variables.iter() {
            let line = self.lines_of.line(function.local_variables.get_span(handle));
            let len =
                words_of(self.module, &self.module.types[local.ty].inner).map_err(|what| unsupported(&what, line))?;
            words = add_words(self.kernel, Space::Function, words, u64::from(len))?;
            local_words.push(len);
        }
        self.committed = add_words(self.kernel, Space::Function, self.committed, words)?;
        check_space(self.kernel, Space::Function, self.committed)?;
        let name = function.name.clone().unwrap_or_default();
        let source = match self.names.iter().position(|n| *n == name) {
            Some(at) => at as u32,
            None => {
                self.names.push(name);
                self.names.len() as u32 - 1
            }
        };
        let mut scope = Scope {
            function,
            info,
            source,
            regs: vec![NONE; count],
            lens,
            lines,
            places: vec![None; count],
            constant: vec![false; count],
            pre_emitted: vec![false; count],
            in_place_loads: super::load_alias::in_place_loads(function, info),
            partial_loads: super::load_fields::partial_loads(self.module, self.info, function, info),
            locals: Vec::new(),
            result,
            returns: Vec::new(),
            inlined: arguments.is_some(),
            depth,
            loops: Vec::new(),
            owned: vec![NOT_OWNED; count],
            dead_after: DeadAfter::default(),
        };
        for words in local_words {
            let reg = self.alloc(words);
            scope.locals.push(reg);
        }
        let saved_source = self.source;
        self.source = source;
        // Constant expressions (literals, constants, and compositions of them) are never
        // emitted: they are evaluated when the scope starts, like variables and arguments.
        let kinds = naga::proc::ExpressionKindTracker::from_arena(&function.expressions);
        for (handle, expression) in function.expressions.iter() {
            let index = handle.index();
            let pre_emit = kinds.is_const(handle)
                || matches!(
                    expression,
                    Expression::Literal(_)
                        | Expression::Constant(_)
                        | Expression::ZeroValue(_)
                        | Expression::FunctionArgument(_)
                        | Expression::GlobalVariable(_)
                        | Expression::LocalVariable(_)
                );
            if !pre_emit {
                continue;
            }
            scope.pre_emitted[index] = true;
            self.line = scope.lines[index];
            match *expression {
                Expression::FunctionArgument(i) => match arguments {
                    Some(arguments) => {
                        let (reg, place) = arguments[i as usize];
                        scope.regs[index] = reg;
                        scope.places[index] = place;
                    }
                    None => {
                        let reg = self.reg(&mut scope, handle);
                        code_arguments.push((i, reg, scope.lens[index]));
                    }
                },
                Expression::GlobalVariable(g) => {
                    let (tag, offset) = self.globals[g.index()];
                    scope.constant[index] = true;
                    scope.places[index] = match tag & memory::TAG_MASK {
                        memory::WORKGROUP => Some(Place::Workgroup(offset)),
                        memory::PRIVATE => Some(Place::Private(offset)),
                        memory::BUFFER if ((tag & !memory::TAG_MASK) as usize) < self.buffer_count => {
                            Some(Place::Buffer(tag & !memory::TAG_MASK, offset))
                        }
                        _ => None,
                    };
                    // A pointer with a place gets its register where one is read
                    // (`place_reg`); a texture or sampler, or a buffer not bound, now.
                    if scope.places[index].is_none() {
                        self.constant(&mut scope, handle, &[tag, offset]);
                    }
                }
                // Its register is made where one is read (`place_reg`).
                Expression::LocalVariable(l) => {
                    scope.places[index] = Some(Place::Local(scope.locals[l.index()]));
                }
                _ => match const_value(self, &scope, handle) {
                    Some(value) => {
                        self.constant(&mut scope, handle, &value);
                        scope.constant[index] = true;
                    }
                    None => self.expression(&mut scope, handle)?,
                },
            }
        }
        scope.dead_after = super::liveness::dead_after(function, &scope.pre_emitted);
        if scope.inlined
            && let Some((dst, words)) = result
        {
            for record in scope.return_in_place(dst, words) {
                self.components_in_place(&mut scope, record);
            }
        }
        for (index, (_, local)) in function.local_variables.iter().enumerate() {
            let variable = scope.locals[index];
            let words = words_of(self.module, &self.module.types[local.ty].inner).unwrap_or(0);
            let initialised = local.init.map_or(0, |init| scope.lens[init.index()].min(words));
            if scope.inlined && words > initialised {
                // A fresh frame's variables start zeroed; an inlined call's must be too
                // (where no initialiser writes every word).
                self.push(Insn::Zero { dst: variable, len: words });
            }
            if let Some(init) = local.init {
                let src = self.reg(&mut scope, init);
                self.copy(variable, src, initialised);
            }
        }
        self.source = saved_source;
        Ok(scope)
    }
}

/// Compiles `function` into a code (its jumps not yet tidied: [`super::decode`]).
#[allow(clippy::too_many_arguments)]
pub(super) fn compile_code(
    module: &Module,
    info: &naga::valid::ModuleInfo,
    function: &naga::Function,
    function_info: &naga::valid::FunctionInfo,
    lines_of: &LineIndex,
    globals: &[(u32, u32)],
    global_values: &[Vec<u32>],
    buffer_count: usize,
    (kernel, sanitize): (&str, bool),
    names: &mut Vec<String>,
    arguments: &[Vec<(u32, Reg, u32)>],
) -> Result<Code, BackendError> {
    let mut compiler = Compiler {
        module,
        info,
        lines_of,
        globals,
        global_values,
        buffer_count,
        sanitize,
        kernel,
        committed: 0,
        inlined: 0,
        names,
        arguments,
        insns: Vec::new(),
        insn_lines: Vec::new(),
        insn_sources: Vec::new(),
        template: Vec::new(),
        local_pointers: Vec::new(),
        free: Vec::new(),
        runtime: Vec::new(),
        free_early: true,
        permanent: Default::default(),
        reused: Default::default(),
        constants: Default::default(),
        line: 0,
        source: 0,
        last_value: None,
        took_over: None,
    };
    let mut code_arguments = Vec::new();
    let mut scope = compiler.open(function, function_info, None, None, 0, &mut code_arguments)?;
    let locals = scope
        .locals
        .iter()
        .zip(function.local_variables.iter())
        .map(|(&reg, (_, local))| (reg, words_of(module, &module.types[local.ty].inner).unwrap_or(0)))
        .collect();
    compiler.block(&mut scope, &function.body)?;
    compiler.line = 0;
    compiler.source = scope.source;
    compiler.push(Insn::Return { src: 0, len: 0 });
    Ok(Code {
        insns: compiler.insns,
        lines: compiler.insn_lines,
        sources: compiler.insn_sources,
        template: compiler.template,
        local_pointers: compiler.local_pointers,
        locals,
        arguments: code_arguments,
    })
}

/// The value of a constant expression of a function, if it can be computed from values
/// already in the template (literals, constants, zero values, splats and compositions).
pub(super) fn const_value(compiler: &Compiler, scope: &Scope, handle: Handle<Expression>) -> Option<Vec<u32>> {
    let module = compiler.module;
    let value_of = |h: Handle<Expression>| -> Option<&[u32]> {
        let i = h.index();
        if !scope.constant[i] || scope.regs[i] == NONE {
            return None;
        }
        let reg = scope.regs[i] as usize;
        Some(&compiler.template[reg..reg + scope.lens[i] as usize])
    };
    let len = scope.lens[handle.index()] as usize;
    let value = match &scope.function.expressions[handle] {
        Expression::Literal(value) => literal(value)?,
        Expression::Constant(c) => compiler.global_values[module.constants[*c].init.index()].clone(),
        Expression::ZeroValue(_) => vec![0; len],
        Expression::Splat { size, value } => value_of(*value)?.repeat(*size as usize),
        Expression::Compose { components, .. } => {
            let parts: Option<Vec<&[u32]>> = components.iter().map(|c| value_of(*c)).collect();
            compose(module, compiler.ty(scope, handle), &parts?).ok()?
        }
        _ => return None,
    };
    (value.len() == len).then_some(value)
}
