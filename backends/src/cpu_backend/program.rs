//! What the compiler hands the executor: a [`Program`], the compiled functions of one
//! kernel ([`Code`]: instructions, register template, argument registers) and the
//! layout of its global memory, with what messages need to name a WGSL place.
//!
//! Why a file of its own, beside [`super::insn`] and below the compiler: the executor
//! ([`super::interp`], [`super::dispatch`], [`super::batch`]) and the sanitizer read a
//! program and never compile one, so they import this and not the compiler
//! ([`super::decode`] writes it).

use super::insn::{Insn, Reg};

/// One compiled function (with its inlined callees).
pub(super) struct Code {
    /// The bytecode.
    pub insns: Vec<Insn>,
    /// WGSL line of each instruction, for messages.
    pub lines: Vec<u32>,
    /// Per instruction: index in [`Program::names`] of the function it came from.
    pub sources: Vec<u32>,
    /// Initial register file: compile-time values filled in, zeros elsewhere.
    pub template: Vec<u32>,
    /// Registers of pointers to local variables that an instruction reads (loads and
    /// stores at a known variable need none): (register, variable's register), set to
    /// (function tag | frame depth, variable's register) when a frame starts.
    pub local_pointers: Vec<(Reg, u32)>,
    /// The function's own local variables (register, words): set from the template
    /// when a frame starts. Every other register is either a compile-time value (in
    /// the template, never written) or an expression's, written where the expression
    /// is evaluated before any use reads it (uses are dominated by the emission; a
    /// struct load of some fields writes the words its uses read, [`super::load_fields`]), so
    /// a register file is filled from the template once and then only these are reset
    /// (inlined callees' variables are zeroed by instructions of their own).
    pub locals: Vec<(Reg, u32)>,
    /// Per argument read by the function: (argument index, register, words).
    pub arguments: Vec<(u32, Reg, u32)>,
}

/// A kernel ready to run: its compiled functions and global layout.
pub(super) struct Program {
    /// The entry point's name.
    pub name: String,
    /// The kernel's name, for messages about its memory ([`super::budget`]).
    pub kernel: String,
    /// Per module function (by handle index), then the entry point.
    pub codes: Vec<Code>,
    /// Index of the entry point's code.
    pub entry: u32,
    /// Function names, for messages.
    pub names: Vec<String>,
    /// Per entry-point argument: its builtins and their register offsets in it (one at
    /// offset 0 for a builtin argument, one per member for a struct of builtins).
    pub entry_arguments: Vec<Vec<(naga::BuiltIn, u32)>>,
    /// `@workgroup_size`.
    pub workgroup_size: [u32; 3],
    /// Words of workgroup memory.
    pub workgroup_words: u32,
    /// Initial contents of private memory.
    pub private_init: Vec<u32>,
    /// The bindings' WGSL names, in the kernel's binding order (for the sanitizer's
    /// findings).
    pub binding_names: Vec<String>,
    /// Workgroup variables: (first word, words, WGSL name), for the sanitizer's findings.
    pub workgroup_variables: Vec<(u32, u32, String)>,
    /// The kernel's WGSL, whose lines [`Code::lines`] count (a registry kernel's is
    /// composed of several files: [`Program::place`] names the file).
    pub source: strata_kernels::source::ComposedSource,
}

impl Program {
    /// Where instruction `pc` of code `code` came from: (WGSL file, line in it, function).
    pub(super) fn place(&self, code: u32, pc: u32) -> (String, u32, String) {
        let code = &self.codes[code as usize];
        let line = code.lines.get(pc as usize).copied().unwrap_or(0);
        let source = code.sources.get(pc as usize);
        let function = source.and_then(|&s| self.names.get(s as usize)).cloned().unwrap_or_default();
        if line == 0 {
            return (String::new(), 0, function);
        }
        let (file, local) = self.source.locate(line as usize);
        (file.to_string(), local as u32, function)
    }
}
