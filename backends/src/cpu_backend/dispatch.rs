//! A dispatch of a compiled kernel: its workgroups in parallel on the machine's cores, the
//! invocations of a workgroup together from barrier to barrier, each a resumable stack
//! of frames (see [`super::interp`]); several workgroups together as one batch where
//! the kernel cannot tell ([`super::batch`]).

use super::budget::try_reserve;
use super::counts::DispatchCounts;
use super::error::{invalid, unsupported};
use super::interp::{self, Stop};
use super::invocations::{Batch, Invocation};
use super::limit::{FUEL, Limit, abandoned};
use super::memory::{FUNCTION, Frame};
use super::program::Program;
use super::sanitize::{FindingKind, Sanitizer};
use crate::error::BackendError;
use std::sync::atomic::{AtomicU32, AtomicU64, Ordering};

/// Builtin values of one invocation.
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

/// Runs `program` on `workgroups` with `buffers` bound (in the kernel's binding order).
/// Independent workgroups run in parallel on the machine's cores; buffer words are
/// atomics (relaxed loads and stores, real read-modify-write for WGSL atomics). Returns
/// what the dispatch executed ([`DispatchCounts`]). Every thread stops, and the
/// dispatch fails, once it runs past `limit` ([`super::limit`]); with `sanitizer`,
/// `program` is a sanitizing one and its findings go there ([`super::sanitize`]).
pub(super) fn run(
    program: &Program,
    buffers: &mut [Vec<u32>],
    workgroups: [u32; 3],
    subgroup_size: u32,
    (limit, sanitizer): (&Limit, Option<&Sanitizer>),
) -> Result<DispatchCounts, BackendError> {
    let instructions = AtomicU64::new(0);
    let warp_issues = AtomicU64::new(0);
    let total = u64::from(workgroups[0]) * u64::from(workgroups[1]) * u64::from(workgroups[2]);
    limit.set_workgroups(total);
    // Batches and threads as the interpreter's memory caps allow (`budget`): each
    // invocation holds its private memory and a column of every code's registers.
    // Planned before the buffers are taken, so that a refusal leaves them as they were.
    let registers: u64 = program.codes.iter().map(|code| code.template.len() as u64).sum();
    let plan = super::budget::plan_batches(
        &program.kernel,
        super::budget::bytes_of(program.private_init.len() as u64 + registers),
        u64::from(program.workgroup_size.iter().product::<u32>()),
        super::budget::bytes_of(u64::from(program.workgroup_words)),
        super::batch::workgroups_per_batch(program, total),
        std::thread::available_parallelism().map_or(1, |n| n.get()),
    )?;
    let per_batch = plan.workgroups;
    let batches = total.div_ceil(per_batch);
    let threads = plan.threads.min(batches.max(1) as usize);
    let shared: Vec<Vec<AtomicU32>> =
        buffers.iter_mut().map(|words| std::mem::take(words).into_iter().map(AtomicU32::new).collect()).collect();
    let next = AtomicU64::new(0);
    let result = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..threads)
            .map(|_| {
                scope.spawn(|| -> Result<(), BackendError> {
                    let mut worker = Worker {
                        memory: Batch {
                            files: vec![Vec::new(); program.codes.len()],
                            private: Vec::new(),
                            private_words: program.private_init.len(),
                            shared: Vec::new(),
                            fuel: FUEL,
                            sanitizing: sanitizer.map(|_| Default::default()),
                        },
                        invocations: Vec::new(),
                        scratch: interp::Scratch::default(),
                    };
                    // The sanitizer's counts of this thread, added to the dispatch's at its end.
                    let flush = |worker: &mut Worker| {
                        if let (Some(shared), Some(local)) = (sanitizer, worker.memory.sanitizing.as_mut()) {
                            local.flush(shared, program);
                        }
                    };
                    loop {
                        let batch = next.fetch_add(1, Ordering::Relaxed);
                        if batch >= batches {
                            flush(&mut worker);
                            return Ok(());
                        }
                        let first = batch * per_batch;
                        let last = (first + per_batch).min(total);
                        match run_batch(
                            program,
                            &shared,
                            &mut worker,
                            first..last,
                            workgroups,
                            subgroup_size,
                            (limit, sanitizer),
                        ) {
                            Ok(counts) => {
                                limit.finished(last - first);
                                instructions.fetch_add(counts.instructions, Ordering::Relaxed);
                                warp_issues.fetch_add(counts.warp_issues, Ordering::Relaxed);
                            }
                            // Stopped because another thread failed: that thread's error is
                            // the dispatch's.
                            Err(error) if abandoned(&error) => {
                                flush(&mut worker);
                                return Ok(());
                            }
                            Err(error) => {
                                // Stop the other threads: those waiting for a batch, and
                                // those running one at their next look at the limit.
                                next.store(batches, Ordering::Relaxed);
                                limit.fail();
                                flush(&mut worker);
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
    result.map(|_| DispatchCounts { instructions: instructions.into_inner(), warp_issues: warp_issues.into_inner() })
}

/// The words of a builtin: up to three, and how many.
fn builtin_value(builtin: naga::BuiltIn, b: &Builtins) -> Result<([u32; 3], usize), BackendError> {
    use naga::BuiltIn as B;
    let one = |x: u32| ([x, 0, 0], 1);
    Ok(match builtin {
        B::LocalInvocationId => (b.local_id, 3),
        B::LocalInvocationIndex => one(b.local_index),
        B::GlobalInvocationId => (b.global_id, 3),
        B::WorkGroupId => (b.workgroup_id, 3),
        B::NumWorkGroups => (b.num_workgroups, 3),
        B::SubgroupSize => one(b.subgroup_size),
        B::SubgroupInvocationId => one(b.lane),
        B::SubgroupId => one(b.subgroup_id),
        B::NumSubgroups => one(b.num_subgroups),
        other => return Err(unsupported(&format!("entry point argument {other:?}"), 0)),
    })
}

/// Starts the entry point's frame in every invocation's column of the entry code's
/// register file: the template (its variables; the rest once per file), the builtins of each (`builtins[lane]`), the pointers
/// to its locals.
fn enter_entry_point(program: &Program, file: &mut Vec<u32>, builtins: &[Builtins]) -> Result<(), BackendError> {
    let code = &program.codes[program.entry as usize];
    let width = builtins.len();
    super::interp::open_file(file, &code.template, width, &program.kernel)?;
    for &(reg, words) in &code.locals {
        for r in reg as usize..(reg + words) as usize {
            file[r * width..][..width].fill(code.template[r]);
        }
    }
    for &(argument, reg, len) in &code.arguments {
        for &(builtin, offset) in &program.entry_arguments[argument as usize] {
            for (lane, b) in builtins.iter().enumerate() {
                let (value, words) = builtin_value(builtin, b)?;
                let at = (reg + offset) as usize;
                let n = (len.saturating_sub(offset) as usize).min(words);
                for (k, &word) in value[..n].iter().enumerate() {
                    file[(at + k) * width + lane] = word;
                }
            }
        }
    }
    for &(reg, offset) in &code.local_pointers {
        file[reg as usize * width..][..width].fill(FUNCTION);
        file[(reg as usize + 1) * width..][..width].fill(offset);
    }
    Ok(())
}

/// What a worker thread keeps from one batch to the next (allocated once).
struct Worker {
    /// The batch's memory.
    memory: Batch,
    /// The batch's invocations.
    invocations: Vec<Invocation>,
    /// The scheduler's lists.
    scratch: interp::Scratch,
}

/// Runs the workgroups `batch` (flat indices, x fastest) together as one wide workgroup
/// of their invocations, workgroup after workgroup in local-index order: one workgroup
/// unless [`super::batch`] found that the kernel cannot tell.
fn run_batch(
    program: &Program,
    buffers: &[Vec<AtomicU32>],
    worker: &mut Worker,
    batch: std::ops::Range<u64>,
    workgroups: [u32; 3],
    subgroup_size: u32,
    (limit, sanitizer): (&Limit, Option<&Sanitizer>),
) -> Result<DispatchCounts, BackendError> {
    let Worker { memory, invocations, scratch } = worker;
    let first_workgroup = batch.start;
    let [sx, sy, sz] = program.workgroup_size;
    let per_workgroup = sx * sy * sz;
    let subgroup_size = subgroup_size.max(1);
    let num_subgroups = per_workgroup.div_ceil(subgroup_size);
    // Each workgroup's invocations start a new warp in the SIMT count.
    let warp_stride = per_workgroup.next_multiple_of(super::counts::WARP_WIDTH);
    invocations.clear();
    let mut builtins = Vec::with_capacity(((batch.end - batch.start) * u64::from(per_workgroup)) as usize);
    for (k, flat) in batch.enumerate() {
        let wx = (flat % u64::from(workgroups[0])) as u32;
        let wy = (flat / u64::from(workgroups[0]) % u64::from(workgroups[1])) as u32;
        let wz = (flat / (u64::from(workgroups[0]) * u64::from(workgroups[1]))) as u32;
        for index in 0..per_workgroup {
            let local = [index % sx, index / sx % sy, index / (sx * sy)];
            let b = Builtins {
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
            invocations.push(Invocation {
                frame: Some(Frame { code: program.entry, pc: 0, result: None }),
                callers: Vec::new(),
                lane: b.lane,
                subgroup_id: b.subgroup_id,
                subgroup_size,
                local_index: index,
                simt_index: k as u32 * warp_stride + index,
            });
            builtins.push(b);
        }
    }
    let count = invocations.len();
    // Zero-initialised workgroup memory, one region per workgroup of the batch (sizes
    // within the caps, `run`; allocated without aborting where the machine cannot).
    let what = |space: &'static str| move || format!("the {space} memory of a batch of `{}`", program.kernel);
    let shared_words = count / per_workgroup as usize * program.workgroup_words as usize;
    memory.shared.clear();
    try_reserve(&mut memory.shared, shared_words, what("workgroup"))?;
    memory.shared.resize(shared_words, 0);
    if let Some(local) = memory.sanitizing.as_mut() {
        // Every word of the batch's workgroup memory unwritten, no access yet.
        local.workgroup.clear();
        try_reserve(&mut local.workgroup, shared_words, what("workgroup shadow"))?;
        local.workgroup.resize(shared_words, Default::default());
        local.start_batch(first_workgroup * u64::from(per_workgroup));
    }
    enter_entry_point(program, &mut memory.files[program.entry as usize], &builtins)?;
    memory.private.clear();
    try_reserve(&mut memory.private, count * program.private_init.len(), what("private"))?;
    for _ in 0..count {
        memory.private.extend_from_slice(&program.private_init);
    }
    let invocations = &mut invocations[..];
    let mut counts = DispatchCounts::default();
    let mut stops = Vec::with_capacity(count);
    let mut reached = Vec::with_capacity(count);
    loop {
        interp::run_until_sync(
            program,
            invocations,
            memory,
            scratch,
            buffers,
            &mut counts,
            &mut reached,
            (limit, sanitizer),
        )?;
        stops.clear();
        stops.extend(reached.iter().map(|stop| stop.expect("every invocation stopped")));
        if stops.iter().all(|s| *s == Stop::Done) {
            break;
        }
        let first = stops[0];
        if let Some(other) = stops.iter().find(|s| **s != first) {
            let describe = |stop: &Stop| match *stop {
                Stop::Done => "the end of the kernel".to_string(),
                Stop::Sync(code, pc) => {
                    let code = &program.codes[code as usize];
                    format!(
                        "the barrier or subgroup operation at WGSL line {} in `{}`",
                        code.lines[pc as usize], program.names[code.sources[pc as usize] as usize]
                    )
                }
            };
            let (first_at, other_at) = (describe(&first), describe(other));
            // The sanitizer lists it with the rest (at the first place named).
            let place = match (first, *other) {
                (Stop::Sync(code, pc), _) | (_, Stop::Sync(code, pc)) => Some((code, pc)),
                _ => None,
            };
            if let (Some(shared), Some(local), Some((code, pc))) = (sanitizer, memory.sanitizing.as_mut(), place) {
                local.found(shared, program, (FindingKind::NonUniformBarrier, code, pc), || {
                    format!("one invocation is at {first_at}, another at {other_at}")
                });
            }
            return Err(invalid(
                &program.name,
                format!(
                    "a barrier or subgroup operation was reached in non-uniform control flow: one invocation is at {first_at}, another at {other_at}"
                ),
            ));
        }
        // Everyone waits at the same instruction.
        let Stop::Sync(code, pc) = first else { unreachable!() };
        super::sync_point::complete_sync(program, invocations, memory, code, pc);
        for invocation in invocations.iter_mut() {
            invocation.frame.as_mut().expect("waiting invocations have frames").pc += 1;
        }
    }
    Ok(counts)
}
