//! Compiling a kernel into a [`Program`], once per kernel (and once more for a
//! sanitizing run): the module's constants evaluated, its workgroup and private
//! variables laid out and each global given its pointer ([`super::memory`]'s region
//! tags), all held under [`super::budget`]'s caps before anything of that size is
//! allocated; the entry point's builtin arguments placed; then every function lowered
//! into a [`Code`] ([`compile_code`], callees first, as naga orders them), its jumps
//! tidied ([`super::jump_cleanup`]) and, in a sanitizing program, each instruction the
//! sanitizer checks wrapped in [`Insn::Checked`] ([`super::sanitize`]).
//!
//! Why a file of its own: this is the top of the compiler, the one place that knows
//! the whole pipeline; how one function lowers sits below it ([`super::compiler`] and the
//! files that add to its `Compiler`), and what comes out ([`Program`]) below both.

use super::budget::{Space, add_words, check_space};
use super::compiler::{LineIndex, compile_code};
use super::constant::global_value;
use super::error::unsupported;
use super::insn::{Insn, Reg};
use super::layout::{byte_addressed, contains_f16, member_step, words_of};
use super::memory;
use super::program::{Code, Program};
use crate::error::BackendError;
use naga::TypeInner;
use strata_kernels::Kernel;

/// Compiles `kernel`'s entry point and the functions of its module.
#[cfg(test)]
pub(super) fn compile_program(kernel: &Kernel) -> Result<Program, BackendError> {
    compile(kernel, false)
}

/// Compiles `kernel`'s entry point and the functions of its module; with `sanitize`, as
/// a sanitizing program ([`super::sanitize`]).
pub(super) fn compile(kernel: &Kernel, sanitize: bool) -> Result<Program, BackendError> {
    let module = &kernel.module;
    let lines_of = &LineIndex::new(&kernel.source.text);
    let name = kernel.name();
    // The constants' words, held under the cap before each is computed (its words from
    // its type; a type the interpreter cannot size is global_value's error).
    let mut global_values = Vec::with_capacity(module.global_expressions.len());
    let mut constant_words = 0u64;
    for (handle, _) in module.global_expressions.iter() {
        if let Ok(words) = words_of(module, kernel.info[handle].inner_with(&module.types)) {
            constant_words = add_words(name, Space::Constants, constant_words, u64::from(words))?;
            check_space(name, Space::Constants, constant_words)?;
        }
        let value = global_value(module, &global_values, handle).map_err(|what| unsupported(&what, 0))?;
        global_values.push(value);
    }
    let entry_index = kernel.entry_index();
    let entry_point = &module.entry_points[entry_index];
    // Each argument is a builtin or a struct of builtins (its members' register offsets).
    let entry_arguments = entry_point
        .function
        .arguments
        .iter()
        .map(|argument| match (&argument.binding, &module.types[argument.ty].inner) {
            (Some(naga::Binding::BuiltIn(builtin)), _) => Ok(vec![(*builtin, 0)]),
            (None, inner @ TypeInner::Struct { members, .. }) => members
                .iter()
                .enumerate()
                .map(|(i, member)| match member.binding {
                    Some(naga::Binding::BuiltIn(builtin)) => Ok((builtin, member_step(module, inner, i as u32, false))),
                    _ => Err(unsupported("entry point struct members other than builtins", 0)),
                })
                .collect(),
            _ => Err(unsupported("entry point arguments other than builtins", 0)),
        })
        .collect::<Result<_, _>>()?;
    let mut globals = Vec::new();
    // Every workgroup and private variable takes room, used or not, held under the caps
    // before it is allocated (the device's workgroup limit, checked before a dispatch,
    // counts only what the entry point uses).
    let (mut workgroup_words, mut private_words) = (0u64, 0u64);
    let mut private_init = Vec::new();
    let mut workgroup_variables = Vec::new();
    for (handle, variable) in module.global_variables.iter() {
        let inner = &module.types[variable.ty].inner;
        if contains_f16(module, inner) && !byte_addressed(variable.space) {
            let line = lines_of.line(module.global_variables.get_span(handle));
            words_of(module, inner).map_err(|what| unsupported(&what, line))?;
        }
        // Workgroup and private variables take room in the interpreter's own memory: a
        // type it cannot size is an error naming the variable, never a variable of no
        // words whose loads read 0 (how an override-sized workgroup array once ran).
        let words = match (variable.space, words_of(module, inner)) {
            (_, Ok(words)) => words,
            (naga::AddressSpace::Uniform | naga::AddressSpace::Storage { .. }, Err(_)) => 0,
            (_, Err(what)) => {
                let line = lines_of.line(module.global_variables.get_span(handle));
                let name = variable.name.as_deref().unwrap_or("(unnamed)");
                return Err(unsupported(&format!("{what} (`{name}`)"), line));
            }
        };
        let entry = match variable.space {
            naga::AddressSpace::Uniform | naga::AddressSpace::Storage { .. } | naga::AddressSpace::Handle => {
                let (group, binding) = variable.binding.as_ref().map_or((u32::MAX, u32::MAX), |b| (b.group, b.binding));
                let slot =
                    kernel.bindings.iter().position(|b| b.group == group && b.binding == binding).unwrap_or(usize::MAX);
                (memory::BUFFER | slot as u32 & 0xff_ffff, 0)
            }
            // Offsets below the cap (64 MiB, in words) fit in u32.
            naga::AddressSpace::WorkGroup => {
                let offset = workgroup_words as u32;
                workgroup_words = add_words(name, Space::Workgroup, workgroup_words, u64::from(words))?;
                check_space(name, Space::Workgroup, workgroup_words)?;
                workgroup_variables.push((offset, words, variable.name.clone().unwrap_or_default()));
                (memory::WORKGROUP, offset)
            }
            naga::AddressSpace::Private => {
                let offset = private_words as u32;
                private_words = add_words(name, Space::Private, private_words, u64::from(words))?;
                check_space(name, Space::Private, private_words)?;
                match variable.init {
                    Some(init) => private_init.extend_from_slice(&global_values[init.index()]),
                    None => private_init.resize(private_init.len() + words as usize, 0),
                }
                (memory::PRIVATE, offset)
            }
            _ => (0, 0),
        };
        globals.push(entry);
    }
    let mut names = Vec::new();
    let mut codes = Vec::new();
    let mut arguments: Vec<Vec<(u32, Reg, u32)>> = Vec::new();
    let buffer_count = kernel.bindings.len();
    // naga orders functions so that callees come before their callers.
    for (handle, function) in module.functions.iter() {
        let mut code = compile_code(
            module,
            &kernel.info,
            function,
            &kernel.info[handle],
            lines_of,
            &globals,
            &global_values,
            buffer_count,
            (kernel.name(), sanitize),
            &mut names,
            &arguments,
        )?;
        finish_code(&mut code, sanitize);
        arguments.push(code.arguments.clone());
        codes.push(code);
    }
    let mut entry = compile_code(
        module,
        &kernel.info,
        &entry_point.function,
        kernel.info.get_entry_point(entry_index),
        lines_of,
        &globals,
        &global_values,
        buffer_count,
        (kernel.name(), sanitize),
        &mut names,
        &arguments,
    )?;
    finish_code(&mut entry, sanitize);
    codes.push(entry);
    Ok(Program {
        name: kernel.entry_point().to_string(),
        kernel: name.to_string(),
        entry: codes.len() as u32 - 1,
        codes,
        names,
        entry_arguments,
        workgroup_size: kernel.workgroup_size,
        // At most the cap (64 MiB, in words): fits in u32.
        workgroup_words: workgroup_words as u32,
        private_init,
        binding_names: kernel.bindings.iter().map(|b| b.name.clone()).collect(),
        workgroup_variables,
        source: kernel.source.clone(),
    })
}

/// The steps after a function is lowered: its jumps tidied and, in a sanitizing
/// program, every instruction the sanitizer checks wrapped in [`Insn::Checked`].
fn finish_code(code: &mut Code, sanitize: bool) {
    super::jump_cleanup::clean_up_jumps(&mut code.insns, &mut code.lines, &mut code.sources);
    if sanitize {
        // Instruction for instruction, so jump targets stay.
        for insn in code.insns.iter_mut() {
            if is_checked(insn) {
                let inner = std::mem::replace(insn, Insn::Jump(0));
                *insn = Insn::Checked(Box::new(inner));
            }
        }
    }
}

/// Whether `insn` is checked in the sanitizing program: it indexes, or touches
/// workgroup or buffer memory (what [`super::checked`] checks at run time).
fn is_checked(insn: &Insn) -> bool {
    matches!(
        insn,
        Insn::PtrIndex { .. }
            | Insn::PtrIndexRt { .. }
            | Insn::Extract { .. }
            | Insn::Load { .. }
            | Insn::LoadRuns { .. }
            | Insn::LoadElement(_)
            | Insn::Store { .. }
            | Insn::LoadMixed { .. }
            | Insn::StoreMixed { .. }
            | Insn::LoadWorkgroup { .. }
            | Insn::StoreWorkgroup { .. }
            | Insn::LoadBuffer { .. }
            | Insn::StoreBuffer { .. }
            | Insn::Atomic(_)
    )
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    /// The entry point's instructions of a kernel whose body is `body` after `let x =
    /// data[id.x];` (`data`: a read-write `array<u32>`, `id`: the global invocation id).
    pub(in super::super) fn compiled(body: &str) -> Vec<Insn> {
        compiled_with("", body)
    }

    /// As [`compiled`], with module-scope `declarations` (structs, functions, constants,
    /// other bindings) before the kernel.
    pub(in super::super) fn compiled_with(declarations: &str, body: &str) -> Vec<Insn> {
        entry_code(&kernel_with(declarations, body)).insns
    }

    /// A kernel whose body is `body` after `let x = data[id.x];`, with module-scope
    /// `declarations` (structs, functions, constants, other bindings) before it.
    pub(in super::super) fn kernel_with(declarations: &str, body: &str) -> Kernel {
        let source = format!(
            "{declarations}\n@group(0) @binding(0) var<storage, read_write> data: array<u32>;\n\
             @compute @workgroup_size(8) fn main(@builtin(global_invocation_id) id: vec3<u32>) {{\n\
             let x = data[id.x];\n{body}\n}}"
        );
        Kernel::from_wgsl("compiled.wgsl", source, "main", false).expect("valid WGSL")
    }

    /// The entry point's code of `kernel`.
    pub(in super::super) fn entry_code(kernel: &Kernel) -> Code {
        let program = compile_program(kernel).expect("compiles");
        program.codes.into_iter().nth(program.entry as usize).expect("entry code")
    }

    /// Invocations [`run_kernel`] runs (8 workgroups of 8).
    pub(in super::super) const INVOCATIONS: u32 = 64;

    /// `data` after `kernel` (of [`kernel_with`]) ran on `data[i] = i`.
    pub(in super::super) fn run_kernel(kernel: &Kernel) -> Vec<u32> {
        run_kernel_bound(kernel, &[])
    }

    /// As [`run_kernel`], with the buffers `more` bound too, each (binding, words).
    pub(in super::super) fn run_kernel_bound(kernel: &Kernel, more: &[(u32, &[u32])]) -> Vec<u32> {
        use super::super::{CpuBackend, CpuOptions};
        use crate::backend::{Backend, Bind, download, upload};
        let mut cpu = CpuBackend::new(CpuOptions::default()).unwrap();
        let data = upload(&mut cpu, "data", &(0..INVOCATIONS).collect::<Vec<_>>()).unwrap();
        let mut binds = vec![Bind::new(0, data)];
        for &(binding, words) in more {
            binds.push(Bind::new(binding, upload(&mut cpu, "more", words).unwrap()));
        }
        cpu.dispatch(kernel, &binds, [INVOCATIONS / 8, 1, 1]).unwrap();
        download::<u32>(&mut cpu, data).unwrap()
    }
}
