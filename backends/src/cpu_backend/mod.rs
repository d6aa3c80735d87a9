//! The [`Backend`] that needs no GPU: an interpreter of naga IR running the same WGSL
//! kernels on the CPU. It is the reference executor of the cross-backend check and the
//! command line's fallback when no GPU adapter exists.
//!
//! Each kernel is compiled once into a register bytecode (`insn`, compiled by
//! `decode` and `expression`): instructions whose operands are word offsets in the
//! frame's register file, small callees inlined, fields and bitcasts aliasing their
//! source's registers, compile-time values in a register template. Four passes make
//! the code shorter and less divergent: an `if` that only stores into locals becomes
//! selects (`if_conversion`), a value stored right after it is computed goes straight
//! into the variable (`retarget`), a local's load reads the variable's registers where
//! nothing writes it before the value's last use (`load_alias`), and jumps to jumps or
//! to the next instruction are tidied away (`jump_cleanup`). `interp` runs it;
//! `memory` is the pointer model (offsets in bytes into bound buffers, in register
//! words elsewhere). Workgroups run in parallel on the machine's cores;
//! the invocations of a workgroup run together from barrier to barrier (`exec`; the
//! workgroups of a kernel without barriers or subgroup operations several at a time as
//! one batch, `batch`), each
//! a resumable stack of frames, so every invocation reaches a barrier before any passes
//! it; those at the same place run as one group, each instruction decoded once for the
//! whole group (`interp`), as a loop over the members' words: registers are
//! lane-minor, one file per code for the whole workgroup with register `r` of invocation
//! `l` at `r * width + l` (`lanes`). Each dispatch is counted (`counts`): instructions, and
//! the issue slots a 32-wide SIMT GPU would spend on the same groups, by kernel. A
//! barrier or subgroup operation reached in non-uniform control flow is an error
//! naming the line and function. Subgroup operations run with a configurable subgroup
//! size (1, 8, 32, ...).
//!
//! Semantics follow WGSL, not Rust (`arith`): wrapping integers, division and remainder
//! by zero as WGSL defines them, masked shifts, saturating float→int conversion, IEEE
//! f32 without contraction. Out-of-bounds indices are clamped (naga's `Restrict` policy);
//! out-of-bounds memory words read as 0 and are not written.
//!
//! Supported today: 32-bit scalars, bool, 64-bit integers (`wide`: two words, low
//! first, as the storage layout has them; arithmetic, comparisons, bit operations,
//! shifts, conversions, `abs`/`min`/`max`/`clamp`/`sign`), f16 (held in a register
//! word as the f32 of equal value, every operation computed in f32 and rounded to
//! binary16; in buffers at naga's two bytes each, converted on load and store; f16
//! matrices are refused by name), vectors, matrices as values, fixed and
//! runtime-sized arrays, structs, pointers, function calls, loops with `continuing` and
//! `break if`, `switch`, atomics, barriers, `workgroupUniformLoad`, subgroup shuffles,
//! broadcasts, ballots, reductions and inclusive/exclusive scans (32-bit and bool
//! operands; lanes combined in lane order), the compute builtins (as arguments or as
//! members of struct arguments), matrix arithmetic, and
//! every WGSL math builtin on f32 (`modf` and `frexp` with their result structs;
//! `pack2x16float`, `unpack2x16float` and `quantizeToF16` through IEEE binary16,
//! rounding to nearest even, keeping denormals; `ldexp` exact up to one rounding;
//! `reflect`, `refract`, `faceForward`, `dot4I8Packed`/`dot4U8Packed`). Anything else is
//! an error naming the construct and its WGSL line, never a panic.

mod access;
mod arith;
mod batch;
mod constant;
mod counts;
mod decode;
mod element_load;
mod error;
mod exec;
mod execute;
mod expression;
mod if_conversion;
mod image;
mod image_lower;
mod insn;
mod interp;
mod jump_cleanup;
mod lanes;
mod layout;
mod load_alias;
mod load_fields;
mod math_call;
mod matrix;
mod memory;
mod places;
mod retarget;
mod statement;
mod wide;

use crate::backend::{Backend, Bind, BufferId, Resource};
use crate::bindings_check::{
    ResourceLookup, check_binds, check_buffer_size, check_kernel_fits, check_workgroups, check_write,
};
use crate::device_info::{DeviceInfo, DeviceLimits};
use crate::error::BackendError;
use crate::texture::{SamplerDesc, SamplerId, TextureDesc, TextureId};
pub use counts::{DispatchCounts, WARP_WIDTH};
use decode::Program;
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

struct CpuTexture {
    desc: TextureDesc,
    /// Every mip level's texels, in order, as little-endian words.
    words: Vec<u32>,
}

impl CpuTexture {
    /// Word range of mip `level`.
    fn level_words(&self, level: u32) -> std::ops::Range<usize> {
        let start: u64 = (0..level).map(|l| self.desc.level_bytes(l)).sum::<u64>() / 4;
        start as usize..(start + self.desc.level_bytes(level) / 4) as usize
    }
}

/// The naga-IR interpreter as a backend.
pub struct CpuBackend {
    info: DeviceInfo,
    options: CpuOptions,
    buffers: HashMap<u64, CpuBuffer>,
    textures: HashMap<u64, CpuTexture>,
    samplers: HashMap<u64, SamplerDesc>,
    next_buffer: u64,
    programs: HashMap<KernelId, Program>,
    last_counts: DispatchCounts,
    counts_by_kernel: HashMap<KernelId, DispatchCounts>,
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
                max_texture_2d: 16384,
                max_texture_3d: 2048,
                max_texture_layers: 2048,
                max_bind_groups: 8,
            },
        };
        Ok(Self {
            info,
            options,
            buffers: HashMap::new(),
            textures: HashMap::new(),
            samplers: HashMap::new(),
            next_buffer: 0,
            programs: HashMap::new(),
            last_counts: DispatchCounts::default(),
            counts_by_kernel: HashMap::new(),
        })
    }

    fn program(&mut self, kernel: &Kernel) -> Result<&Program, BackendError> {
        if let std::collections::hash_map::Entry::Vacant(slot) = self.programs.entry(kernel.id) {
            slot.insert(decode::compile_program(kernel)?);
        }
        Ok(&self.programs[&kernel.id])
    }

    /// Bytecode instructions the last dispatch executed (for ns-per-instruction
    /// figures; one instruction stands for one IR expression or statement or less,
    /// since inlining, register aliasing and compile-time constants remove some).
    pub fn instructions_in_last_dispatch(&self) -> u64 {
        self.last_counts.instructions
    }

    /// What each kernel's dispatches executed since the last call (instructions and the
    /// issue slots of a SIMT GPU, see [`DispatchCounts`]): a device-neutral profile, e.g.
    /// of one pass's share of a frame. Taking them resets the tally.
    pub fn take_counts_by_kernel(&mut self) -> HashMap<KernelId, DispatchCounts> {
        std::mem::take(&mut self.counts_by_kernel)
    }

    fn buffer(&self, id: BufferId) -> Result<&CpuBuffer, BackendError> {
        self.buffers.get(&id.0).ok_or(BackendError::UnknownBuffer(id.0))
    }

    fn texture(&self, id: TextureId) -> Result<&CpuTexture, BackendError> {
        self.textures.get(&id.0).ok_or(BackendError::UnknownTexture(id.0))
    }

    /// The words a binding's slot holds during a dispatch (moved out of a buffer or
    /// texture, so that it is not copied; put back by [`CpuBackend::put_back`]).
    fn take_bound(&mut self, resource: Resource) -> Vec<u32> {
        match resource {
            Resource::Buffer(id) => std::mem::take(&mut self.buffers.get_mut(&id.0).expect("checked").words),
            Resource::Texture(id) => {
                let texture = self.textures.get_mut(&id.0).expect("checked");
                image::bind_texture(&texture.desc, &std::mem::take(&mut texture.words))
            }
            Resource::Sampler(id) => image::bind_sampler(&self.samplers[&id.0]),
        }
    }

    /// Returns a slot's words to the buffer or texture they were taken from.
    fn put_back(&mut self, resource: Resource, mut words: Vec<u32>) {
        match resource {
            Resource::Buffer(id) => self.buffers.get_mut(&id.0).expect("checked").words = words,
            Resource::Texture(id) => {
                words.drain(..image::HEADER_WORDS);
                self.textures.get_mut(&id.0).expect("checked").words = words;
            }
            Resource::Sampler(_) => {}
        }
    }
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

    fn create_texture(&mut self, desc: &TextureDesc) -> Result<TextureId, BackendError> {
        desc.check(&self.info)?;
        let bytes: u64 = (0..desc.mip_levels).map(|l| desc.level_bytes(l)).sum();
        self.next_buffer += 1;
        self.textures.insert(self.next_buffer, CpuTexture { desc: desc.clone(), words: vec![0; bytes as usize / 4] });
        Ok(TextureId(self.next_buffer))
    }

    fn write_texture(&mut self, texture: TextureId, level: u32, data: &[u8]) -> Result<(), BackendError> {
        let entry = self.textures.get_mut(&texture.0).ok_or(BackendError::UnknownTexture(texture.0))?;
        entry.desc.check_level(level, data.len())?;
        let range = entry.level_words(level);
        for (word, chunk) in entry.words[range].iter_mut().zip(data.chunks_exact(4)) {
            *word = u32::from_le_bytes([chunk[0], chunk[1], chunk[2], chunk[3]]);
        }
        Ok(())
    }

    fn read_texture(&mut self, texture: TextureId, level: u32) -> Result<Vec<u8>, BackendError> {
        let entry = self.texture(texture)?;
        entry.desc.check_level(level, entry.desc.level_bytes(level) as usize)?;
        Ok(entry.words[entry.level_words(level)].iter().flat_map(|w| w.to_le_bytes()).collect())
    }

    fn destroy_texture(&mut self, texture: TextureId) -> Result<(), BackendError> {
        self.textures.remove(&texture.0).map(|_| ()).ok_or(BackendError::UnknownTexture(texture.0))
    }

    fn create_sampler(&mut self, desc: &SamplerDesc) -> Result<SamplerId, BackendError> {
        self.next_buffer += 1;
        self.samplers.insert(self.next_buffer, *desc);
        Ok(SamplerId(self.next_buffer))
    }

    fn destroy_sampler(&mut self, sampler: SamplerId) -> Result<(), BackendError> {
        self.samplers.remove(&sampler.0).map(|_| ()).ok_or(BackendError::UnknownSampler(sampler.0))
    }

    fn check_kernel(&self, kernel: &Kernel) -> Result<(), BackendError> {
        check_kernel_fits(kernel, &self.info)
    }

    fn dispatch(&mut self, kernel: &Kernel, binds: &[Bind], workgroups: [u32; 3]) -> Result<(), BackendError> {
        self.check_kernel(kernel)?;
        check_workgroups(kernel, workgroups, &self.info)?;
        let lookup = ResourceLookup {
            buffer_size: &|id| self.buffer(id).map(|b| b.size),
            texture: &|id| self.texture(id).map(|t| t.desc.clone()),
            sampler: &|id| self.samplers.get(&id.0).map(|_| ()).ok_or(BackendError::UnknownSampler(id.0)),
        };
        check_binds(kernel, binds, &self.info, &lookup)?;
        let subgroup_size = self.options.subgroup_size.unwrap_or(1);
        self.program(kernel)?;
        // Move the bound resources out (in the kernel's binding order), run, put them
        // back. One bound at several (read-only: checked) bindings is moved out once and
        // copied for the others, and only its first binding's words go back.
        let resources: Vec<Resource> = kernel
            .bindings
            .iter()
            .map(|b| binds.iter().find(|bind| bind.slot() == (b.group, b.binding)).expect("checked").resource)
            .collect();
        let first_of = |index: usize| resources[..index].iter().position(|r| *r == resources[index]);
        let mut bound: Vec<Vec<u32>> = Vec::with_capacity(resources.len());
        for (index, resource) in resources.iter().enumerate() {
            let words = match first_of(index) {
                Some(first) => bound[first].clone(),
                None => self.take_bound(*resource),
            };
            bound.push(words);
        }
        let result = exec::run(&self.programs[&kernel.id], &mut bound, workgroups, subgroup_size);
        for (index, (resource, words)) in resources.iter().zip(bound).enumerate() {
            if first_of(index).is_none() {
                self.put_back(*resource, words);
            }
        }
        self.last_counts = result?;
        *self.counts_by_kernel.entry(kernel.id).or_default() += self.last_counts;
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
