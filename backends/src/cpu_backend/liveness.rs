//! Where each value of a function dies: the point of the compile walk after which no
//! instruction reads its registers again, so that the compiler ([`super::compiler`]) can
//! hand them to a later value.
//!
//! Why: every expression used to keep its own register range for the whole code (only an
//! inlined callee's ranges were freed, when its body ended), so the path tracer's frame
//! held about 1 400 registers per invocation, most of them dead; each group's registers
//! (rows of 32 lanes, [`super::lanes`]) then spread over more cache lines than the
//! values alive at any time need (issue 59, docs/benchmarks/interpreter.md).
//!
//! The walk numbers points in the order the compiler lowers a function: each emitted
//! expression, and each statement after everything nested in it (so a statement's own
//! operands, such as an `if`'s condition that if-conversion's selects read after both
//! branches, count as used at its end). A value dies after its last use, with four
//! corrections that make the rule sound for the code the compiler makes:
//! - **Aliases.** A component, a field, a consecutive swizzle or a bitcast is compiled
//!   into its source's own registers ([`super::expression`]), and an element pointer's
//!   index is read again by the load that fuses it ([`super::element_load`]): a use of
//!   `Access`, `AccessIndex`, `Swizzle` or a bitcast (`As` without conversion) is a use of
//!   its operands too (for an `Access` into a value rather than a pointer, longer than
//!   needed, which is safe).
//! - **Loops.** A value defined before a loop and used in it is read again on the next
//!   iteration: it lives to the loop's end.
//! - **`continue`.** A loop's continuing block and `break_if` may read a value of its body
//!   that a `continue` skipped (WGSL forbids it, naga does not check): such a value gets
//!   registers of its own, never shared ([`DeadAfter::own_registers`]), so that it keeps
//!   its previous iteration's words as before.
//! - **Never freed.** Values evaluated when the scope opens (constants, arguments,
//!   variables' pointers, whose registers are made there or, for a pointer with a known
//!   target, where an instruction first reads it) and variables' initialisers; and every
//!   value of a function with a statement this walk does not know, or with an
//!   expression emitted twice (naga IR allows it in two blocks, WGSL does not produce
//!   it), whose two emissions would share one death.
//!
//! Sound because naga's functions are structured: every jump but a loop's back edge goes
//! forward in this order, and a value is emitted before its uses on every path (naga
//! scopes an expression to the block that emits it), so a register is free for a later
//! value once no later point reads it, except across a back edge, which the loop rule
//! covers.

use naga::{Expression, Function, Handle, Statement};
use std::collections::{HashMap, HashSet};

/// A point of the compile walk after which values may die.
#[derive(Clone, Copy)]
pub(super) enum Slot<'a> {
    /// After an emitted expression is compiled.
    Expression(Handle<Expression>),
    /// After a statement is compiled, with everything nested in it.
    Statement(&'a Statement),
}

/// The values that die after each point of one function.
#[derive(Default)]
pub(super) struct DeadAfter {
    /// By the emitted expression.
    expressions: HashMap<Handle<Expression>, Vec<Handle<Expression>>>,
    /// By the statement's address: a function's statements do not move while it is
    /// compiled (a pass that compiled a copy of a block would find nothing here, and so
    /// free nothing, which is safe).
    statements: HashMap<*const Statement, Vec<Handle<Expression>>>,
    /// Values of a loop body read in its continuing block or `break_if`.
    own: HashSet<Handle<Expression>>,
}

impl DeadAfter {
    /// Whether `value` needs registers no other value ever takes: one of a loop body's
    /// that its continuing block or `break_if` reads, where a `continue` may have skipped
    /// computing it (the module comment).
    pub(super) fn own_registers(&self, value: Handle<Expression>) -> bool {
        self.own.contains(&value)
    }

    /// The values whose last read is at `slot`.
    pub(super) fn at(&self, slot: Slot) -> &[Handle<Expression>] {
        let dead = match slot {
            Slot::Expression(handle) => self.expressions.get(&handle),
            Slot::Statement(statement) => self.statements.get(&(statement as *const Statement)),
        };
        dead.map_or(&[], Vec::as_slice)
    }
}

/// Where each value of `function` dies, never for the expressions `keep` marks (those
/// evaluated when the scope opens); nothing dies in a function with a statement the walk
/// does not know or an expression emitted twice.
pub(super) fn dead_after(function: &Function, keep: &[bool]) -> DeadAfter {
    let count = function.expressions.len();
    let mut walk = Walk {
        function,
        defined: vec![UNSEEN; count],
        last: vec![UNSEEN; count],
        keys: Vec::new(),
        loops: Vec::new(),
        known: true,
        own: HashSet::new(),
    };
    walk.block(&function.body);
    if !walk.known {
        return DeadAfter::default();
    }
    let mut keep = keep.to_vec();
    for (_, local) in function.local_variables.iter() {
        if let Some(init) = local.init {
            keep[init.index()] = true;
        }
    }
    let mut dead = DeadAfter { own: walk.own, ..DeadAfter::default() };
    for (handle, _) in function.expressions.iter() {
        let index = handle.index();
        if keep[index] || walk.defined[index] == UNSEEN {
            continue;
        }
        // A value never read dies where it is computed.
        let point = if walk.last[index] == UNSEEN { walk.defined[index] } else { walk.last[index] };
        match walk.keys[point as usize] {
            Key::Expression(at) => dead.expressions.entry(at).or_default().push(handle),
            Key::Statement(at) => dead.statements.entry(at).or_default().push(handle),
        }
    }
    dead
}

/// Every point inside `block`, nested ones too: where the values that die in a block
/// compiled without freeing (if-conversion's branches) or not compiled at all (the side of
/// a branch on a constant not taken) are freed after it.
pub(super) fn slots(block: &naga::Block) -> Vec<Slot<'_>> {
    let mut all = Vec::new();
    for statement in block.iter() {
        match statement {
            Statement::Emit(range) => all.extend(range.clone().map(Slot::Expression)),
            Statement::Block(inner) => all.extend(slots(inner)),
            Statement::If { accept, reject, .. } => all.extend(slots(accept).into_iter().chain(slots(reject))),
            Statement::Switch { cases, .. } => all.extend(cases.iter().flat_map(|case| slots(&case.body))),
            Statement::Loop { body, continuing, .. } => all.extend(slots(body).into_iter().chain(slots(continuing))),
            _ => {}
        }
        all.push(Slot::Statement(statement));
    }
    all
}

/// Not numbered yet.
const UNSEEN: u32 = u32::MAX;

/// What a point is.
#[derive(Clone, Copy)]
enum Key {
    Expression(Handle<Expression>),
    Statement(*const Statement),
}

/// A loop the walk is inside.
struct OpenLoop {
    /// Its first point.
    start: u32,
    /// The first point of its continuing block, once the walk is there.
    continuing: Option<u32>,
    /// Values that live to its end.
    to_end: Vec<Handle<Expression>>,
}

/// The walk's state.
struct Walk<'a> {
    /// The function walked.
    function: &'a Function,
    /// Per expression: the point that computes it.
    defined: Vec<u32>,
    /// Per expression: the last point that reads it.
    last: Vec<u32>,
    /// Per point: what it is.
    keys: Vec<Key>,
    /// The loops around the walk, outermost first.
    loops: Vec<OpenLoop>,
    /// No statement of a kind the walk does not know so far, no expression emitted twice.
    known: bool,
    /// Values of a loop body read in its continuing block or `break_if`.
    own: HashSet<Handle<Expression>>,
}

impl Walk<'_> {
    /// The next point's number.
    fn next(&self) -> u32 {
        self.keys.len() as u32
    }

    /// Numbers a new point.
    fn point(&mut self, key: Key) -> u32 {
        self.keys.push(key);
        self.next() - 1
    }

    /// Walks the statements of `block` in order.
    fn block(&mut self, block: &naga::Block) {
        for statement in block.iter() {
            self.statement(statement);
        }
    }

    /// Walks `statement`: what nests in it, then its own point (an `Emit` has a point per
    /// expression instead). [`slots`] lists the same points and must change with it.
    fn statement(&mut self, statement: &Statement) {
        use Statement as S;
        let mut reads: Vec<Handle<Expression>> = Vec::new();
        let mut results: Vec<Handle<Expression>> = Vec::new();
        match statement {
            S::Emit(range) => {
                for handle in range.clone() {
                    let at = self.point(Key::Expression(handle));
                    self.define(handle, at);
                    for operand in operands(&self.function.expressions[handle]) {
                        self.read(operand, at);
                    }
                }
                return;
            }
            S::Block(block) => self.block(block),
            S::If { condition, accept, reject } => {
                self.block(accept);
                self.block(reject);
                reads.push(*condition);
            }
            S::Switch { selector, cases } => {
                for case in cases {
                    self.block(&case.body);
                }
                reads.push(*selector);
            }
            S::Loop { body, continuing, break_if } => {
                self.loops.push(OpenLoop { start: self.next(), continuing: None, to_end: Vec::new() });
                self.block(body);
                let continuing_start = self.next();
                self.loops.last_mut().expect("pushed above").continuing = Some(continuing_start);
                self.block(continuing);
                if let Some(condition) = break_if {
                    // Read at the loop's end, where the walk still counts as inside it.
                    let at = self.point(Key::Statement(statement));
                    self.read(*condition, at);
                }
                let open = self.loops.pop().expect("pushed above");
                let end = match break_if {
                    Some(_) => self.next() - 1,
                    None => self.point(Key::Statement(statement)),
                };
                for value in open.to_end {
                    let last = &mut self.last[value.index()];
                    *last = if *last == UNSEEN { end } else { (*last).max(end) };
                }
                return;
            }
            S::Break | S::Continue | S::Kill | S::ControlBarrier(_) | S::MemoryBarrier(_) => {}
            S::Return { value } => reads.extend(*value),
            S::Store { pointer, value } => reads.extend([*pointer, *value]),
            S::ImageStore { image, coordinate, array_index, value } => {
                reads.extend([*image, *coordinate, *value]);
                reads.extend(*array_index);
            }
            S::Atomic { pointer, fun, value, result } => {
                reads.extend([*pointer, *value]);
                if let naga::AtomicFunction::Exchange { compare: Some(compare) } = fun {
                    reads.push(*compare);
                }
                results.extend(*result);
            }
            S::WorkGroupUniformLoad { pointer, result } => {
                reads.push(*pointer);
                results.push(*result);
            }
            S::Call { arguments, result, .. } => {
                reads.extend(arguments);
                results.extend(*result);
            }
            S::SubgroupBallot { result, predicate } => {
                reads.extend(*predicate);
                results.push(*result);
            }
            S::SubgroupGather { mode, argument, result } => {
                use naga::GatherMode as G;
                match mode {
                    G::BroadcastFirst | G::QuadSwap(_) => {}
                    G::Broadcast(h)
                    | G::Shuffle(h)
                    | G::ShuffleDown(h)
                    | G::ShuffleUp(h)
                    | G::ShuffleXor(h)
                    | G::QuadBroadcast(h) => reads.push(*h),
                }
                reads.push(*argument);
                results.push(*result);
            }
            S::SubgroupCollectiveOperation { argument, result, .. } => {
                reads.push(*argument);
                results.push(*result);
            }
            S::ImageAtomic { .. } | S::RayQuery { .. } | S::RayPipelineFunction(_) | S::CooperativeStore { .. } => {
                self.known = false;
            }
        }
        let at = self.point(Key::Statement(statement));
        for value in reads {
            self.read(value, at);
        }
        for value in results {
            self.define(value, at);
        }
    }

    /// `value` is computed at point `at`; a second time makes the walk give up.
    fn define(&mut self, value: Handle<Expression>, at: u32) {
        let defined = &mut self.defined[value.index()];
        if *defined != UNSEEN {
            self.known = false;
        }
        *defined = at;
    }

    /// `value` is read at point `at`, and so are the values whose registers it is
    /// ([`operands`] of an alias).
    fn read(&mut self, value: Handle<Expression>, at: u32) {
        let index = value.index();
        let defined = self.defined[index];
        // A body's value read in the loop's continuing block or `break_if` gets registers
        // of its own (a `continue` may have skipped computing it).
        let skippable = |open: &OpenLoop| {
            open.continuing.is_some_and(|continuing| at >= continuing && defined >= open.start && defined < continuing)
        };
        if self.loops.iter().any(skippable) {
            self.own.insert(value);
        }
        // A value defined before a loop lives to the end of the outermost such loop.
        let outlived = self.loops.iter_mut().find(|open| defined == UNSEEN || defined < open.start);
        match outlived {
            Some(open) => open.to_end.push(value),
            None => {
                let last = &mut self.last[index];
                *last = if *last == UNSEEN { at } else { (*last).max(at) };
            }
        }
        if aliases(&self.function.expressions[value]) {
            for operand in operands(&self.function.expressions[value]) {
                self.read(operand, at);
            }
        }
    }
}

/// Whether the compiler may place `expression` in its operand's registers, or read an
/// operand again where the value is used (a fused element load's index).
fn aliases(expression: &Expression) -> bool {
    matches!(
        expression,
        Expression::Access { .. }
            | Expression::AccessIndex { .. }
            | Expression::Swizzle { .. }
            | Expression::As { convert: None, .. }
    )
}

/// The expressions `expression` reads.
fn operands(expression: &Expression) -> Vec<Handle<Expression>> {
    use Expression as E;
    match expression {
        E::Literal(_)
        | E::Constant(_)
        | E::Override(_)
        | E::ZeroValue(_)
        | E::FunctionArgument(_)
        | E::GlobalVariable(_)
        | E::LocalVariable(_)
        | E::CallResult(_)
        | E::AtomicResult { .. }
        | E::WorkGroupUniformLoadResult { .. }
        | E::RayQueryProceedResult
        | E::SubgroupBallotResult
        | E::SubgroupOperationResult { .. } => Vec::new(),
        E::Compose { components, .. } => components.clone(),
        E::Access { base, index } => vec![*base, *index],
        E::AccessIndex { base, .. } => vec![*base],
        E::Splat { value, .. } => vec![*value],
        E::Swizzle { vector, .. } => vec![*vector],
        E::Load { pointer } => vec![*pointer],
        E::ImageSample { image, sampler, coordinate, array_index, offset, level, depth_ref, .. } => {
            let mut all = vec![*image, *sampler, *coordinate];
            all.extend(array_index.iter().chain(offset).chain(depth_ref));
            match level {
                naga::SampleLevel::Auto | naga::SampleLevel::Zero => {}
                naga::SampleLevel::Exact(h) | naga::SampleLevel::Bias(h) => all.push(*h),
                naga::SampleLevel::Gradient { x, y } => all.extend([*x, *y]),
            }
            all
        }
        E::ImageLoad { image, coordinate, array_index, sample, level } => {
            let mut all = vec![*image, *coordinate];
            all.extend(array_index.iter().chain(sample).chain(level));
            all
        }
        E::ImageQuery { image, query } => {
            let mut all = vec![*image];
            if let naga::ImageQuery::Size { level: Some(level) } = query {
                all.push(*level);
            }
            all
        }
        E::Unary { expr, .. } => vec![*expr],
        E::Binary { left, right, .. } => vec![*left, *right],
        E::Select { condition, accept, reject } => vec![*condition, *accept, *reject],
        E::Derivative { expr, .. } => vec![*expr],
        E::Relational { argument, .. } => vec![*argument],
        E::Math { arg, arg1, arg2, arg3, .. } => {
            let mut all = vec![*arg];
            all.extend(arg1.iter().chain(arg2).chain(arg3));
            all
        }
        E::As { expr, .. } => vec![*expr],
        E::ArrayLength(array) => vec![*array],
        E::RayQueryVertexPositions { query, .. } | E::RayQueryGetIntersection { query, .. } => vec![*query],
        E::CooperativeLoad { data, .. } => vec![data.pointer, data.stride],
        E::CooperativeMultiplyAdd { a, b, c } => vec![*a, *b, *c],
    }
}

#[cfg(test)]
mod tests {
    use super::super::decode::tests::{INVOCATIONS, entry_code, kernel_with, run_kernel};
    use strata_kernels::Kernel;

    /// A kernel whose body is `body` after `let x = data[id.x];`.
    fn kernel(body: &str) -> Kernel {
        kernel_with("", body)
    }

    /// `data` after the kernel ran on `data[i] = i`.
    fn run(body: &str) -> Vec<u32> {
        run_kernel(&kernel(body))
    }

    /// The entry code's register words.
    fn registers(body: &str) -> usize {
        entry_code(&kernel(body)).template.len()
    }

    /// `f` of each invocation's `x`.
    fn expected(f: impl Fn(u32) -> u32) -> Vec<u32> {
        (0..INVOCATIONS).map(f).collect()
    }

    #[test]
    fn a_chain_of_temporaries_takes_the_registers_of_the_dead_ones() {
        // 32 steps of three operations each: 96 one-word values, at most three alive at once.
        let mut body = String::from("let a0 = x;\n");
        for i in 1..=32 {
            body += &format!("let a{i} = a{p} * 5u + (a{p} >> 1u);\n", p = i - 1);
        }
        body += "data[id.x] = a32;";
        let words = registers(&body);
        assert!(words < 24, "{words} register words for a chain of 96 values, three alive at once");
        let chain = |x: u32| (0..32).fold(x, |a, _| a.wrapping_mul(5).wrapping_add(a >> 1));
        assert_eq!(run(&body), expected(chain));
    }

    #[test]
    fn a_value_from_before_a_loop_outlives_the_loop() {
        // `k`'s last read is inside the loop, which reads it again on the next iteration.
        // `s = u ^ (u >> 3u)`, not `s = u`: a value stored right after it is computed is
        // computed into the variable (`retarget`), and would leave `k`'s registers unwritten.
        let body = "let k = x * 7u + 3u; var s = 0u;
            for (var i = 0u; i < 5u; i++) { let t = (i * 3u + 1u) ^ k; let u = s * 31u + t; s = u ^ (u >> 3u); }
            data[id.x] = s;";
        let f = |x: u32| {
            let k = x * 7 + 3;
            (0..5u32).fold(0u32, |s, i| {
                let u = s.wrapping_mul(31).wrapping_add((i * 3 + 1) ^ k);
                u ^ (u >> 3)
            })
        };
        assert_eq!(run(body), expected(f));
    }

    #[test]
    fn a_component_keeps_its_vector_alive() {
        // `v.y` and `v.zw` are `v`'s own registers: `v` lives as long as they do.
        let body = "let v = vec4<u32>(x, x + 1u, x * 2u, x ^ 5u); let y = v.y; let w = v.zw;
            let p = y * 3u; let q = p + w.x; let r = q ^ w.y;
            data[id.x] = r + y;";
        let f = |x: u32| ((x + 1) * 3 + x * 2) ^ (x ^ 5);
        assert_eq!(run(body), expected(|x| f(x) + x + 1));
    }

    #[test]
    fn a_converted_branch_keeps_its_values_until_the_selects_read_them() {
        // If-conversion computes both branches, then selects: `k + 1u` must survive the
        // other branch's values.
        let body = "var a = 0u; let k = x * 3u;
            if x > 7u { a = k + 1u; } else { a = k * 2u + (k >> 1u); }
            let z = x * 11u; data[id.x] = a + z;";
        let f = |x: u32| if x > 7 { x * 3 + 1 } else { x * 6 + ((x * 3) >> 1) } + x * 11;
        assert_eq!(run(body), expected(f));
        // `k`, stored by one branch, read last by an expression of the other: freed there,
        // `* 3u` would take its registers before the select reads them.
        let body = "var a = 0u; let k = x * 3u;
            if x > 7u { a = k; } else { a = (k + 1u) * 3u; }
            let z = x * 11u; data[id.x] = a + z;";
        let f = |x: u32| if x > 7 { x * 3 } else { (x * 3 + 1) * 3 } + x * 11;
        assert_eq!(run(body), expected(f));
    }

    #[test]
    fn a_switch_an_inlined_call_and_a_continuing_block_together_compute_as_written() {
        // A smoke test of the constructs together (the rules' own tests are above): `k`
        // from before the loop read in `break if`; `a` and `b` of the body read by a
        // switch's cases, an inlined callee and the continuing block; an element load
        // whose index has no other read.
        let declarations = "fn mix_in(v: u32, k: u32) -> u32 { let t = v * 2654435761u; return (t >> (k & 7u)) ^ k; }";
        let body = "let own = data[id.x & 63u]; let k = x * 7u + 3u; var s = own; var i = 0u;
            loop {
                let a = x * 3u + i;
                let b = a ^ (i << 2u);
                switch i & 3u {
                    case 0u: { s = s + b; }
                    case 1u, 2u: { s = s ^ (a * 5u); }
                    default: { s = s + 7u; }
                }
                s = s + mix_in(b, i);
                continuing { i = i + 1u + (b & 1u); break if i >= 9u + (a & 3u) + (k & 1u); }
            }
            data[id.x] = s;";
        let mix_in = |v: u32, k: u32| (v.wrapping_mul(2654435761) >> (k & 7)) ^ k;
        let f = |x: u32| {
            let k = x * 7 + 3;
            let (mut s, mut i) = (x, 0u32);
            loop {
                let a = x * 3 + i;
                let b = a ^ (i << 2);
                s = match i & 3 {
                    0 => s.wrapping_add(b),
                    1 | 2 => s ^ a.wrapping_mul(5),
                    _ => s.wrapping_add(7),
                };
                s = s.wrapping_add(mix_in(b, i));
                i = i + 1 + (b & 1);
                if i >= 9 + (a & 3) + (k & 1) {
                    break s;
                }
            }
        };
        assert_eq!(run_kernel(&kernel_with(declarations, body)), expected(f));
    }

    #[test]
    fn a_function_with_an_expression_emitted_twice_frees_nothing() {
        // naga IR may emit an expression in two blocks (WGSL does not): its two emissions
        // would share one death, so the walk gives up.
        let body = "let a = x * 3u; let b = a + 1u; data[id.x] = b;";
        let kernel = kernel(body);
        let function = &kernel.module.entry_points[0].function;
        let keep = vec![false; function.expressions.len()];
        let slots = |function: &naga::Function| {
            let dead = super::dead_after(function, &keep);
            super::slots(&function.body).into_iter().map(|slot| dead.at(slot).len()).sum::<usize>()
        };
        assert!(slots(function) > 0, "values die in the kernel as written");
        let mut twice = function.clone();
        let emit = twice.body.iter().find(|s| matches!(s, naga::Statement::Emit(_))).expect("an emit").clone();
        twice.body.push(emit, naga::Span::UNDEFINED);
        assert_eq!(slots(&twice), 0);
    }
}
