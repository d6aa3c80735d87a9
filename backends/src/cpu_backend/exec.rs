//! Running a compiled kernel: workgroups one after another, the invocations of a
//! workgroup round-robin from barrier to barrier, each a resumable stack of frames.

use super::error::{invalid, unsupported};
use super::program::{CompiledFunction, Op};
use crate::error::BackendError;
use naga::{Expression, Handle, ScalarKind, TypeInner};
use std::sync::atomic::{AtomicU32, Ordering};

/// Region tags in the first word of a pointer value.
const BUFFER: u32 = 1 << 24;
const WORKGROUP: u32 = 2 << 24;
const PRIVATE: u32 = 3 << 24;
pub(super) const BUFFER_TAG: u32 = BUFFER;
pub(super) const WORKGROUP_TAG: u32 = WORKGROUP;
pub(super) const PRIVATE_TAG: u32 = PRIVATE;
const FUNCTION: u32 = 4 << 24;
const TAG_MASK: u32 = 0xff << 24;

/// A kernel ready to run: its module, compiled functions and global layout.
pub(super) struct Program {
    pub module: naga::Module,
    pub name: String,
    pub functions: Vec<CompiledFunction>,
    /// naga handle of each entry of `functions`.
    pub function_handles: Vec<Handle<naga::Function>>,
    pub entry: CompiledFunction,
    /// Index of the entry point in `module.entry_points`.
    pub entry_index: usize,
    pub entry_arguments: Vec<Option<naga::BuiltIn>>,
    pub workgroup_size: [u32; 3],
    /// Per global variable: (region tag, word offset in its region).
    pub globals: Vec<(u32, u32)>,
    pub workgroup_words: u32,
    /// Initial contents of private memory.
    pub private_init: Vec<u32>,
    /// Values of the module's constant expressions.
    pub global_values: Vec<Vec<u32>>,
}

pub(super) struct Frame {
    /// Index into `Program::functions`, or `usize::MAX` for the entry point.
    pub function: usize,
    pc: u32,
    pub regs: Vec<u32>,
    locals: Vec<u32>,
    /// The caller's expression that receives the return value.
    result: Option<Handle<Expression>>,
}

pub(super) struct Invocation {
    frames: Vec<Frame>,
    /// Register and local buffers of returned frames, reused by later calls.
    spare: Vec<(Vec<u32>, Vec<u32>)>,
    private: Vec<u32>,
    builtins: Builtins,
}

#[derive(Clone, Copy, Default)]
struct Builtins {
    local_id: [u32; 3],
    local_index: u32,
    global_id: [u32; 3],
    workgroup_id: [u32; 3],
    num_workgroups: [u32; 3],
    subgroup_size: u32,
    lane: u32,
    subgroup_id: u32,
    num_subgroups: u32,
}

/// Why an invocation stopped running.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Stop {
    Done,
    /// At a barrier or subgroup op: (function, op index).
    Sync(usize, u32),
}

/// Runs `program` on `workgroups` with `buffers` bound (in the kernel's binding order).
/// Independent workgroups run in parallel on the machine's cores; buffer words are
/// atomics (relaxed loads and stores, real read-modify-write for WGSL atomics).
pub(super) fn run(
    program: &Program,
    buffers: &mut [Vec<u32>],
    workgroups: [u32; 3],
    subgroup_size: u32,
) -> Result<u64, BackendError> {
    let executed = std::sync::atomic::AtomicU64::new(0);
    let shared: Vec<Vec<AtomicU32>> =
        buffers.iter_mut().map(|words| std::mem::take(words).into_iter().map(AtomicU32::new).collect()).collect();
    let total = u64::from(workgroups[0]) * u64::from(workgroups[1]) * u64::from(workgroups[2]);
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get()).min(total.max(1) as usize);
    let next = std::sync::atomic::AtomicU64::new(0);
    let result = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..threads)
            .map(|_| {
                scope.spawn(|| -> Result<(), BackendError> {
                    loop {
                        let index = next.fetch_add(1, Ordering::Relaxed);
                        if index >= total {
                            return Ok(());
                        }
                        let wx = (index % u64::from(workgroups[0])) as u32;
                        let wy = (index / u64::from(workgroups[0]) % u64::from(workgroups[1])) as u32;
                        let wz = (index / (u64::from(workgroups[0]) * u64::from(workgroups[1]))) as u32;
                        match run_workgroup(program, &shared, [wx, wy, wz], workgroups, subgroup_size) {
                            Ok(count) => {
                                executed.fetch_add(count, Ordering::Relaxed);
                            }
                            Err(error) => {
                                // Stop the other threads early.
                                next.store(total, Ordering::Relaxed);
                                return Err(error);
                            }
                        }
                    }
                })
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().unwrap_or_else(|_| Err(invalid(&program.name, "a worker panicked".into()))))
            .collect::<Result<Vec<()>, _>>()
    });
    for (words, atomics) in buffers.iter_mut().zip(shared) {
        *words = atomics.into_iter().map(AtomicU32::into_inner).collect();
    }
    result.map(|_| executed.into_inner())
}

fn run_workgroup(
    program: &Program,
    buffers: &[Vec<AtomicU32>],
    [wx, wy, wz]: [u32; 3],
    workgroups: [u32; 3],
    subgroup_size: u32,
) -> Result<u64, BackendError> {
    let [sx, sy, sz] = program.workgroup_size;
    let count = (sx * sy * sz) as usize;
    let subgroup_size = subgroup_size.max(1);
    let num_subgroups = (count as u32).div_ceil(subgroup_size);
    let mut workgroup = vec![0u32; program.workgroup_words as usize];
    let mut invocations: Vec<Invocation> = (0..count as u32)
        .map(|index| {
            let local = [index % sx, index / sx % sy, index / (sx * sy)];
            let builtins = Builtins {
                local_id: local,
                local_index: index,
                global_id: [wx * sx + local[0], wy * sy + local[1], wz * sz + local[2]],
                workgroup_id: [wx, wy, wz],
                num_workgroups: workgroups,
                subgroup_size,
                lane: index % subgroup_size,
                subgroup_id: index / subgroup_size,
                num_subgroups,
            };
            Invocation { frames: Vec::new(), spare: Vec::new(), private: program.private_init.clone(), builtins }
        })
        .collect();
    let mut exec = Exec { program, executed: 0, buffers, workgroup: &mut workgroup };
    for invocation in &mut invocations {
        exec.enter_entry(invocation)?;
    }
    loop {
        let mut stops = Vec::with_capacity(count);
        for invocation in &mut invocations {
            stops.push(exec.run_until_stop(invocation)?);
        }
        if stops.iter().all(|s| *s == Stop::Done) {
            break;
        }
        let first = stops[0];
        if let Some(other) = stops.iter().find(|s| **s != first) {
            let describe = |stop: &Stop| match *stop {
                Stop::Done => "the end of the kernel".to_string(),
                Stop::Sync(function, pc) => {
                    let f = program.function(function);
                    format!("the barrier or subgroup operation at WGSL line {} in `{}`", f.lines[pc as usize], f.name)
                }
            };
            return Err(invalid(
                &program.name,
                format!(
                    "a barrier or subgroup operation was reached in non-uniform control flow: one invocation is at {}, another at {}",
                    describe(&first),
                    describe(other)
                ),
            ));
        }
        // Everyone waits at the same op: a barrier needs nothing more; a
        // subgroup gather is computed for all invocations now.
        let Stop::Sync(function, pc) = first else { unreachable!() };
        if let Op::Gather { mode, argument, result } = &program.function(function).ops[pc as usize] {
            exec.gather(&mut invocations, *mode, *argument, *result)?;
        }
        for invocation in &mut invocations {
            invocation.frames.last_mut().expect("waiting invocations have frames").pc += 1;
        }
    }
    Ok(exec.executed)
}

impl Program {
    pub(super) fn function(&self, index: usize) -> &CompiledFunction {
        if index == usize::MAX { &self.entry } else { &self.functions[index] }
    }

    pub(super) fn naga_function(&self, index: usize) -> &naga::Function {
        if index == usize::MAX {
            &self.module.entry_points[self.entry_index].function
        } else {
            &self.module.functions[self.function_handles[index]]
        }
    }
}

pub(super) struct Exec<'a> {
    pub program: &'a Program,
    /// Expressions evaluated so far (for ns-per-expression figures).
    pub executed: u64,
    buffers: &'a [Vec<AtomicU32>],
    workgroup: &'a mut Vec<u32>,
}

impl Exec<'_> {
    fn enter_entry(&mut self, invocation: &mut Invocation) -> Result<(), BackendError> {
        let entry = &self.program.entry;
        let mut frame = Frame {
            function: usize::MAX,
            pc: 0,
            regs: vec![0; entry.register_words as usize],
            locals: vec![0; entry.local_words as usize],
            result: None,
        };
        let arguments: Vec<Vec<u32>> = self
            .program
            .entry_arguments
            .iter()
            .map(|builtin| builtin_value(*builtin, &invocation.builtins))
            .collect::<Result<_, _>>()?;
        let arguments: Vec<&[u32]> = arguments.iter().map(Vec::as_slice).collect();
        self.start_frame(&mut frame, invocation, &arguments)?;
        invocation.frames.push(frame);
        Ok(())
    }

    /// Evaluates the frame's constant, variable and argument expressions and
    /// initialises its local variables.
    fn start_frame(
        &mut self,
        frame: &mut Frame,
        invocation: &Invocation,
        arguments: &[&[u32]],
    ) -> Result<(), BackendError> {
        let function = self.program.function(frame.function);
        let naga_function = self.program.naga_function(frame.function);
        let depth = invocation.frames.len() as u32;
        let template = match function.template.get() {
            Some(template) => template,
            None => {
                // Constants and global pointers do not depend on the frame: evaluate them
                // once, in pre-emit order (operands come first in naga's arena).
                for &handle in &function.pre_emit {
                    let value: Vec<u32> = match &naga_function.expressions[handle] {
                        Expression::FunctionArgument(_) | Expression::LocalVariable(_) => continue,
                        Expression::GlobalVariable(g) => {
                            let (tag, offset) = self.program.globals[g.index()];
                            vec![tag, offset]
                        }
                        _ => self.eval(invocation, frame, handle)?.into_vec(),
                    };
                    let slot = function.slots[handle.index()];
                    frame.regs[slot.offset as usize..(slot.offset + slot.len) as usize].copy_from_slice(&value);
                }
                function.template.get_or_init(|| frame.regs.clone())
            }
        };
        frame.regs.copy_from_slice(template);
        for &handle in &function.pre_emit {
            let slot = function.slots[handle.index()];
            let range = slot.offset as usize..(slot.offset + slot.len) as usize;
            match &naga_function.expressions[handle] {
                Expression::FunctionArgument(i) => frame.regs[range].copy_from_slice(arguments[*i as usize]),
                Expression::LocalVariable(l) => {
                    frame.regs[range].copy_from_slice(&[FUNCTION | depth, function.local_offsets[l.index()]])
                }
                _ => {}
            }
        }
        for (index, (_, local)) in naga_function.local_variables.iter().enumerate() {
            if let Some(init) = local.init {
                let slot = function.slots[init.index()];
                let offset = function.local_offsets[index] as usize;
                let value = frame.regs[slot.offset as usize..(slot.offset + slot.len) as usize].to_vec();
                frame.locals[offset..offset + value.len()].copy_from_slice(&value);
            }
        }
        Ok(())
    }

    fn run_until_stop(&mut self, invocation: &mut Invocation) -> Result<Stop, BackendError> {
        loop {
            let Some(frame) = invocation.frames.last() else { return Ok(Stop::Done) };
            let function_index = frame.function;
            let function = self.program.function(function_index);
            let pc = frame.pc;
            let op = &function.ops[pc as usize];
            match op {
                Op::Barrier | Op::Gather { .. } => return Ok(Stop::Sync(function_index, pc)),
                _ => {}
            }
            invocation.frames.last_mut().expect("checked").pc += 1;
            match op {
                Op::Emit(range) => {
                    self.executed += u64::from(range.end - range.start);
                    for index in range.clone() {
                        let handle = function.handles[index as usize];
                        let value = self.eval(invocation, invocation.frames.last().expect("checked"), handle)?;
                        self.set_reg(invocation, handle, &value);
                    }
                }
                Op::Jump(target) => invocation.frames.last_mut().expect("checked").pc = *target,
                Op::JumpUnless { condition, target } => {
                    if self.reg(invocation, *condition)[0] == 0 {
                        invocation.frames.last_mut().expect("checked").pc = *target;
                    }
                }
                Op::Switch { selector, cases } => {
                    let value = self.reg(invocation, *selector)[0];
                    let target = cases
                        .iter()
                        .find(|(v, _)| *v == Some(value))
                        .or_else(|| cases.iter().find(|(v, _)| v.is_none()))
                        .map(|(_, t)| *t)
                        .expect("every switch has a default");
                    invocation.frames.last_mut().expect("checked").pc = target;
                }
                Op::Store { pointer, value } => {
                    let pointer = self.pointer(invocation, *pointer);
                    let value = self.reg(invocation, *value).to_vec();
                    self.write(invocation, pointer, &value);
                }
                Op::LoadInto { pointer, result } => {
                    let pointer = self.pointer(invocation, *pointer);
                    let len = self.slot(invocation, *result).1;
                    let value = self.read(invocation, pointer, len);
                    self.set_reg(invocation, *result, &value);
                }
                Op::Call { function: callee, arguments, result } => {
                    let compiled = &self.program.functions[callee.index()];
                    let (mut regs, mut locals) = invocation.spare.pop().unwrap_or_default();
                    regs.clear();
                    regs.resize(compiled.register_words as usize, 0);
                    locals.clear();
                    locals.resize(compiled.local_words as usize, 0);
                    let mut frame = Frame { function: callee.index(), pc: 0, regs, locals, result: *result };
                    let values: Vec<&[u32]> = arguments.iter().map(|a| self.reg(invocation, *a)).collect();
                    if invocation.frames.len() > 256 {
                        return Err(invalid(&self.program.name, "call depth above 256 (recursion?)".into()));
                    }
                    self.start_frame(&mut frame, invocation, &values)?;
                    invocation.frames.push(frame);
                }
                Op::Return(value) => {
                    let value = value.map(|v| self.reg(invocation, v).to_vec());
                    let frame = invocation.frames.pop().expect("checked");
                    if let (Some(result), Some(value)) = (frame.result, value) {
                        self.set_reg(invocation, result, &value);
                    }
                    invocation.spare.push((frame.regs, frame.locals));
                }
                Op::Atomic { pointer, fun, value, result } => {
                    self.atomic(invocation, *pointer, *fun, *value, *result, function)?;
                }
                Op::Barrier | Op::Gather { .. } => unreachable!("handled above"),
            }
        }
    }

    fn slot(&self, invocation: &Invocation, handle: Handle<Expression>) -> (usize, usize) {
        let frame = invocation.frames.last().expect("running invocations have frames");
        let slot = self.program.function(frame.function).slots[handle.index()];
        (slot.offset as usize, slot.len as usize)
    }

    fn reg<'i>(&self, invocation: &'i Invocation, handle: Handle<Expression>) -> &'i [u32] {
        let (offset, len) = self.slot(invocation, handle);
        &invocation.frames.last().expect("checked").regs[offset..offset + len]
    }

    fn set_reg(&self, invocation: &mut Invocation, handle: Handle<Expression>, value: &[u32]) {
        let (offset, len) = self.slot(invocation, handle);
        invocation.frames.last_mut().expect("checked").regs[offset..offset + len].copy_from_slice(&value[..len]);
    }

    fn pointer(&self, invocation: &Invocation, handle: Handle<Expression>) -> (u32, u32) {
        let words = self.reg(invocation, handle);
        (words[0], words[1])
    }

    /// Reads `len` words; out-of-bounds words read as 0.
    pub(super) fn read(&self, invocation: &Invocation, (tag, offset): (u32, u32), len: usize) -> super::eval::Words {
        let start = offset as usize;
        if tag & TAG_MASK == BUFFER {
            let memory = &self.buffers[(tag & !TAG_MASK) as usize];
            return (start..start + len).map(|i| memory.get(i).map_or(0, |w| w.load(Ordering::Relaxed))).collect();
        }
        let memory: &[u32] = match tag & TAG_MASK {
            WORKGROUP => self.workgroup,
            PRIVATE => &invocation.private,
            _ => &invocation.frames[(tag & !TAG_MASK) as usize].locals,
        };
        (start..start + len).map(|i| memory.get(i).copied().unwrap_or(0)).collect()
    }

    /// Writes words; out-of-bounds words are skipped.
    fn write(&mut self, invocation: &mut Invocation, (tag, offset): (u32, u32), value: &[u32]) {
        if tag & TAG_MASK == BUFFER {
            let memory = &self.buffers[(tag & !TAG_MASK) as usize];
            for (i, &word) in value.iter().enumerate() {
                if let Some(slot) = memory.get(offset as usize + i) {
                    slot.store(word, Ordering::Relaxed);
                }
            }
            return;
        }
        let memory: &mut [u32] = match tag & TAG_MASK {
            WORKGROUP => self.workgroup,
            PRIVATE => &mut invocation.private,
            _ => &mut invocation.frames[(tag & !TAG_MASK) as usize].locals,
        };
        for (i, &word) in value.iter().enumerate() {
            if let Some(slot) = memory.get_mut(offset as usize + i) {
                *slot = word;
            }
        }
    }

    pub(super) fn memory_words(&self, invocation: &Invocation, tag: u32) -> usize {
        match tag & TAG_MASK {
            BUFFER => self.buffers[(tag & !TAG_MASK) as usize].len(),
            WORKGROUP => self.workgroup.len(),
            PRIVATE => invocation.private.len(),
            _ => invocation.frames[(tag & !TAG_MASK) as usize].locals.len(),
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn atomic(
        &mut self,
        invocation: &mut Invocation,
        pointer: Handle<Expression>,
        fun: naga::AtomicFunction,
        value: Handle<Expression>,
        result: Option<Handle<Expression>>,
        function: &CompiledFunction,
    ) -> Result<(), BackendError> {
        use naga::AtomicFunction as A;
        let pointer_value = self.pointer(invocation, pointer);
        let operand = self.reg(invocation, value)[0];
        let expected = match fun {
            A::Exchange { compare: Some(compare) } => Some(self.reg(invocation, compare)[0]),
            _ => None,
        };
        let kind = match &function.types[value.index()] {
            TypeInner::Scalar(s) => s.kind,
            _ => ScalarKind::Uint,
        };
        let kind_is_signed = kind == ScalarKind::Sint;
        let apply = move |old: u32| -> u32 {
            match fun {
                A::Add => old.wrapping_add(operand),
                A::Subtract => old.wrapping_sub(operand),
                A::And => old & operand,
                A::InclusiveOr => old | operand,
                A::ExclusiveOr => old ^ operand,
                A::Min if kind_is_signed => (old as i32).min(operand as i32) as u32,
                A::Max if kind_is_signed => (old as i32).max(operand as i32) as u32,
                A::Min => old.min(operand),
                A::Max => old.max(operand),
                A::Exchange { compare: None } => operand,
                A::Exchange { compare: Some(_) } => {
                    if Some(old) == expected {
                        operand
                    } else {
                        old
                    }
                }
            }
        };
        let old = if pointer_value.0 & TAG_MASK == BUFFER {
            // Shared between workgroups running on other threads: a real atomic.
            match self.buffers[(pointer_value.0 & !TAG_MASK) as usize].get(pointer_value.1 as usize) {
                Some(word) => {
                    word.fetch_update(Ordering::Relaxed, Ordering::Relaxed, |old| Some(apply(old))).unwrap_or(0)
                }
                None => 0,
            }
        } else {
            let old = self.read(invocation, pointer_value, 1)[0];
            self.write(invocation, pointer_value, &[apply(old)]);
            old
        };
        let result_words: super::eval::Words = match expected {
            Some(expected) => smallvec::smallvec![old, u32::from(old == expected)],
            None => smallvec::smallvec![old],
        };
        if let Some(result) = result {
            self.set_reg(invocation, result, &result_words);
        }
        Ok(())
    }

    /// Computes a subgroup gather for every invocation of the workgroup.
    fn gather(
        &mut self,
        invocations: &mut [Invocation],
        mode: naga::GatherMode,
        argument: Handle<Expression>,
        result: Handle<Expression>,
    ) -> Result<(), BackendError> {
        use naga::GatherMode as G;
        let values: Vec<Vec<u32>> = invocations.iter().map(|inv| self.reg(inv, argument).to_vec()).collect();
        let index_of = |inv: &Invocation, handle| self.reg(inv, handle)[0];
        let mut results = Vec::with_capacity(invocations.len());
        for invocation in invocations.iter() {
            let b = invocation.builtins;
            let base = b.subgroup_id * b.subgroup_size;
            let lane = b.lane;
            let source = match mode {
                G::BroadcastFirst => 0,
                G::Broadcast(h) | G::Shuffle(h) => index_of(invocation, h),
                G::ShuffleDown(h) => lane.wrapping_add(index_of(invocation, h)),
                G::ShuffleUp(h) => lane.wrapping_sub(index_of(invocation, h)),
                G::ShuffleXor(h) => lane ^ index_of(invocation, h),
                G::QuadBroadcast(h) => (lane & !3) | (index_of(invocation, h) & 3),
                G::QuadSwap(direction) => match direction {
                    naga::Direction::X => lane ^ 1,
                    naga::Direction::Y => lane ^ 2,
                    naga::Direction::Diagonal => lane ^ 3,
                },
            };
            // Lanes outside the subgroup are indeterminate in WGSL: the invocation's own value.
            let source_index = base.wrapping_add(source) as usize;
            let in_range = source < b.subgroup_size && source_index < values.len();
            results.push(if in_range { values[source_index].clone() } else { values[b.local_index as usize].clone() });
        }
        for (invocation, value) in invocations.iter_mut().zip(results) {
            self.set_reg(invocation, result, &value);
        }
        Ok(())
    }
}

fn builtin_value(builtin: Option<naga::BuiltIn>, b: &Builtins) -> Result<Vec<u32>, BackendError> {
    use naga::BuiltIn as B;
    Ok(match builtin {
        Some(B::LocalInvocationId) => b.local_id.to_vec(),
        Some(B::LocalInvocationIndex) => vec![b.local_index],
        Some(B::GlobalInvocationId) => b.global_id.to_vec(),
        Some(B::WorkGroupId) => b.workgroup_id.to_vec(),
        Some(B::NumWorkGroups) => b.num_workgroups.to_vec(),
        Some(B::SubgroupSize) => vec![b.subgroup_size],
        Some(B::SubgroupInvocationId) => vec![b.lane],
        Some(B::SubgroupId) => vec![b.subgroup_id],
        Some(B::NumSubgroups) => vec![b.num_subgroups],
        other => return Err(unsupported(&format!("entry point argument {other:?}"), 0)),
    })
}
