//! The [`Backend`] that needs no GPU: an interpreter of naga IR running the same WGSL
//! kernels on the CPU. It is the reference executor of the cross-backend check and the
//! command line's fallback when no GPU adapter exists.
//!
//! Each kernel is compiled once into flat per-function programs ([`program`]): a
//! register slot per expression and ops with jumps. Workgroups run one after another; the
//! invocations of a workgroup run round-robin from barrier to barrier, each a resumable
//! stack of frames, so every invocation reaches a barrier before any passes it. A barrier
//! or subgroup operation reached in non-uniform control flow is an error naming the
//! line. Subgroup operations run with a configurable subgroup size (1, 8, 32, ...).
//!
//! Semantics follow WGSL, not Rust ([`arith`]): wrapping integers, division and remainder
//! by zero as WGSL defines them, masked shifts, saturating float→int conversion, IEEE
//! f32 without contraction. Out-of-bounds indices are clamped (naga's `Restrict` policy);
//! out-of-bounds memory words read as 0 and are not written.
//!
//! Supported today: 32-bit scalars, bool, vectors, matrices as values, fixed and
//! runtime-sized arrays, structs, pointers, function calls, loops with `continuing` and
//! `break if`, `switch`, atomics, barriers, `workgroupUniformLoad`, subgroup shuffles and
//! broadcasts, the compute builtins, matrix arithmetic, and most math functions. Anything else is an error
//! naming the construct and its WGSL line, never a panic.

mod arith;
mod error;
mod eval;
mod exec;
mod matrix;
mod program;

use crate::backend::{Backend, Bind, BufferId};
use crate::bindings_check::{check_binds, check_buffer_size, check_kernel_fits, check_workgroups, check_write};
use crate::device_info::{DeviceInfo, DeviceLimits};
use crate::error::BackendError;
use error::unsupported;
use exec::Program;
use std::collections::HashMap;
use std::time::{Duration, Instant};
use strata_kernels::{Kernel, KernelId};

/// How to configure the interpreter.
#[derive(Clone, Copy, Debug)]
pub struct CpuOptions {
    /// Subgroup size for kernels that use subgroup operations; `None`: no subgroups.
    pub subgroup_size: Option<u32>,
}

impl Default for CpuOptions {
    fn default() -> Self {
        Self { subgroup_size: Some(8) }
    }
}

struct CpuBuffer {
    words: Vec<u32>,
    size: u64,
    label: String,
}

/// The naga-IR interpreter as a backend.
pub struct CpuBackend {
    info: DeviceInfo,
    options: CpuOptions,
    buffers: HashMap<u64, CpuBuffer>,
    next_buffer: u64,
    programs: HashMap<KernelId, Program>,
    last_expressions: u64,
}

impl CpuBackend {
    /// A new interpreter.
    pub fn new(options: CpuOptions) -> Result<Self, BackendError> {
        if let Some(size) = options.subgroup_size
            && (size == 0 || !size.is_power_of_two() || size > 128)
        {
            return Err(BackendError::DeviceCreation {
                backend: "cpu".into(),
                reason: format!("subgroup size {size}: must be a power of two from 1 to 128"),
            });
        }
        let info = DeviceInfo {
            backend: "cpu".into(),
            adapter: "strata naga-IR interpreter".into(),
            device_type: "Cpu".into(),
            driver: format!("strata {}", env!("CARGO_PKG_VERSION")),
            subgroup_sizes: options.subgroup_size.map(|s| (s, s)),
            timestamps: true,
            limits: DeviceLimits {
                max_workgroup_storage: 64 * 1024,
                max_invocations_per_workgroup: 1024,
                max_workgroup_size: [1024, 1024, 64],
                max_workgroups_per_dimension: 65535,
                max_storage_binding: 1 << 30,
                max_uniform_binding: 64 * 1024,
                max_buffer_size: 1 << 30,
                max_storage_buffers_per_stage: 64,
            },
        };
        Ok(Self {
            info,
            options,
            buffers: HashMap::new(),
            next_buffer: 0,
            programs: HashMap::new(),
            last_expressions: 0,
        })
    }

    fn program(&mut self, kernel: &Kernel) -> Result<&Program, BackendError> {
        if let std::collections::hash_map::Entry::Vacant(slot) = self.programs.entry(kernel.id) {
            slot.insert(build_program(kernel)?);
        }
        Ok(&self.programs[&kernel.id])
    }

    /// IR expressions the last dispatch evaluated (for ns-per-expression figures).
    pub fn expressions_in_last_dispatch(&self) -> u64 {
        self.last_expressions
    }

    fn buffer(&self, id: BufferId) -> Result<&CpuBuffer, BackendError> {
        self.buffers.get(&id.0).ok_or(BackendError::UnknownBuffer(id.0))
    }
}

fn build_program(kernel: &Kernel) -> Result<Program, BackendError> {
    let module = kernel.module.clone();
    let source = &program::LineIndex::new(&kernel.source.text);
    let mut global_values = Vec::with_capacity(module.global_expressions.len());
    for (handle, _) in module.global_expressions.iter() {
        let value = eval::global_value(&module, &global_values, handle).map_err(|what| unsupported(&what, 0))?;
        global_values.push(value);
    }
    let mut functions = Vec::new();
    for (handle, function) in module.functions.iter() {
        functions.push(program::compile_function(&module, function, &kernel.info[handle], source)?);
    }
    let entry_index = kernel.entry_index();
    let entry_point = &module.entry_points[entry_index];
    let entry =
        program::compile_function(&module, &entry_point.function, kernel.info.get_entry_point(entry_index), source)?;
    let entry_arguments = entry_point
        .function
        .arguments
        .iter()
        .map(|argument| match argument.binding {
            Some(naga::Binding::BuiltIn(builtin)) => Ok(Some(builtin)),
            _ => Err(unsupported("entry point arguments other than builtins", 0)),
        })
        .collect::<Result<_, _>>()?;
    let mut globals = Vec::new();
    let (mut workgroup_words, mut private_words) = (0u32, 0u32);
    let mut private_init = Vec::new();
    for (_, variable) in module.global_variables.iter() {
        let words = program::words_of(&module, &module.types[variable.ty].inner).unwrap_or(0);
        let entry = match variable.space {
            naga::AddressSpace::Uniform | naga::AddressSpace::Storage { .. } => {
                let binding = variable.binding.as_ref().map_or(u32::MAX, |b| b.binding);
                let slot = kernel.bindings.iter().position(|b| b.binding == binding).unwrap_or(usize::MAX);
                (exec::BUFFER_TAG | slot as u32 & 0xff_ffff, 0)
            }
            naga::AddressSpace::WorkGroup => {
                workgroup_words += words;
                (exec::WORKGROUP_TAG, workgroup_words - words)
            }
            naga::AddressSpace::Private => {
                private_words += words;
                let value =
                    variable.init.map(|i| global_values[i.index()].clone()).unwrap_or_else(|| vec![0; words as usize]);
                private_init.extend_from_slice(&value);
                (exec::PRIVATE_TAG, private_words - words)
            }
            _ => (0, 0),
        };
        globals.push(entry);
    }
    Ok(Program {
        module: kernel.module.clone(),
        name: kernel.entry_point().to_string(),
        functions,
        function_handles: module.functions.iter().map(|(h, _)| h).collect(),
        entry,
        entry_index,
        entry_arguments,
        workgroup_size: kernel.workgroup_size,
        globals,
        workgroup_words,
        private_init,
        global_values,
    })
}

impl Backend for CpuBackend {
    fn info(&self) -> &DeviceInfo {
        &self.info
    }

    fn create_buffer(&mut self, label: &str, size: u64) -> Result<BufferId, BackendError> {
        check_buffer_size(label, size, &self.info)?;
        self.next_buffer += 1;
        self.buffers.insert(
            self.next_buffer,
            CpuBuffer { words: vec![0; size.div_ceil(4) as usize], size, label: label.into() },
        );
        Ok(BufferId(self.next_buffer))
    }

    fn write_buffer(&mut self, buffer: BufferId, offset: u64, data: &[u8]) -> Result<(), BackendError> {
        let entry = self.buffers.get_mut(&buffer.0).ok_or(BackendError::UnknownBuffer(buffer.0))?;
        check_write(&entry.label, entry.size, offset, data.len())?;
        let start = offset as usize / 4;
        for (i, chunk) in data.chunks_exact(4).enumerate() {
            entry.words[start + i] = u32::from_le_bytes([chunk[0], chunk[1], chunk[2], chunk[3]]);
        }
        Ok(())
    }

    fn read_buffer(&mut self, buffer: BufferId) -> Result<Vec<u8>, BackendError> {
        let entry = self.buffer(buffer)?;
        let mut bytes: Vec<u8> = entry.words.iter().flat_map(|w| w.to_le_bytes()).collect();
        bytes.truncate(entry.size as usize);
        Ok(bytes)
    }

    fn destroy_buffer(&mut self, buffer: BufferId) -> Result<(), BackendError> {
        self.buffers.remove(&buffer.0).map(|_| ()).ok_or(BackendError::UnknownBuffer(buffer.0))
    }

    fn check_kernel(&self, kernel: &Kernel) -> Result<(), BackendError> {
        check_kernel_fits(kernel, &self.info)
    }

    fn dispatch(&mut self, kernel: &Kernel, binds: &[Bind], workgroups: [u32; 3]) -> Result<(), BackendError> {
        self.check_kernel(kernel)?;
        check_workgroups(kernel, workgroups, &self.info)?;
        check_binds(kernel, binds, &self.info, |id| self.buffer(id).map(|b| b.size))?;
        let subgroup_size = self.options.subgroup_size.unwrap_or(1);
        self.program(kernel)?;
        // Move the bound buffers out (in the kernel's binding order), run, put them back.
        let ids: Vec<u64> = kernel
            .bindings
            .iter()
            .map(|b| binds.iter().find(|bind| bind.binding == b.binding).expect("checked").buffer.0)
            .collect();
        let mut bound: Vec<Vec<u32>> =
            ids.iter().map(|id| std::mem::take(&mut self.buffers.get_mut(id).expect("checked").words)).collect();
        let result = exec::run(&self.programs[&kernel.id], &mut bound, workgroups, subgroup_size);
        for (id, words) in ids.iter().zip(bound) {
            self.buffers.get_mut(id).expect("checked").words = words;
        }
        self.last_expressions = result?;
        Ok(())
    }

    fn dispatch_timed(
        &mut self,
        kernel: &Kernel,
        binds: &[Bind],
        workgroups: [u32; 3],
    ) -> Result<Duration, BackendError> {
        let started = Instant::now();
        self.dispatch(kernel, binds, workgroups)?;
        Ok(started.elapsed())
    }
}
