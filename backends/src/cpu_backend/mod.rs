//! The [`Backend`] that needs no GPU: an interpreter of naga IR running the same WGSL
//! kernels on the CPU. It is the reference executor of the cross-backend check and the
//! command line's fallback when no GPU adapter exists.
//!
//! Each kernel is compiled once into a register bytecode (`insn`; a `program`, made by
//! `decode` from the functions `compiler` and the lowering files compile): instructions
//! whose operands are word offsets in the frame's register file, small callees inlined,
//! fields and bitcasts aliasing their source's registers, compile-time values in a
//! register template, and a pointer whose target is known when compiling given a
//! register only where an instruction reads it (most loads and stores through it are
//! compiled to the target itself; not those of a value holding `f16` in a buffer, nor
//! atomics). Passes make the code shorter and less divergent: an `if` that
//! only stores into locals becomes selects (`if_conversion`), a value stored right
//! after it is computed goes straight into the variable, and a call result that a
//! returned record takes whole into the record's registers (`retarget`), a local's load
//! reads the variable's registers where nothing writes it before the value's last use
//! (`load_alias`), an array element's pointer and its load become one instruction
//! (`element_load`), and jumps to jumps or to the next instruction are tidied away
//! (`jump_cleanup`). `interp` runs it;
//! `memory` is the pointer model (offsets in bytes into bound buffers, in register
//! words elsewhere). Workgroups run in parallel on the machine's cores;
//! the invocations of a workgroup run together from barrier to barrier (`dispatch`; the
//! workgroups of a kernel without barriers or subgroup operations several at a time as
//! one batch, `batch`), each
//! a resumable stack of frames (`invocations`), so every invocation reaches a barrier
//! before any passes it, and the barrier or subgroup operation is then completed for all
//! (`sync_point`); those at the same place run as one group, each instruction decoded
//! once for the whole group (`interp`), as a loop over the members' words: registers are
//! lane-minor, one file per code for the whole workgroup with register `r` of invocation
//! `l` at `r * width + l` (`lanes`; its row loops compiled for AVX2 too, chosen at run
//! time). Each dispatch is counted (`counts`): instructions, and
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
//! A dispatch has a time limit (`limit`; [`CpuOptions::time_limit`], 60 s by default):
//! a kernel that never ends fails with an error naming the kernel, the limit and the
//! WGSL line and function where an invocation was, on every worker thread at once. With
//! [`CpuOptions::sanitize`] the interpreter is also a sanitizer (`sanitize`): it
//! reports out-of-range indices, accesses past a binding's end, reads of workgroup
//! memory nobody wrote, data races on workgroup and storage memory, and barriers in
//! non-uniform control flow, as [`Finding`]s ([`CpuBackend::take_findings`]).
//!
//! The interpreter's own memory is capped (`budget`): 64 MiB of private, function
//! (registers) or workgroup memory per invocation or workgroup and of constants,
//! checked from the types when a kernel is compiled; 1 GiB per batch (batches shrink to
//! fit) and 4 GiB for a dispatch's threads together. A kernel over a cap, or memory the
//! machine cannot give, is a [`BackendError::OutOfMemory`] naming the kernel, the
//! memory, the size and the cap, never an abort.
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
mod budget;
mod checked;
mod compiler;
mod compose_in_place;
mod constant;
mod counts;
mod decode;
mod dispatch;
mod element_load;
mod error;
mod execute;
mod expression;
mod if_conversion;
mod image;
mod image_lower;
mod insn;
mod interp;
mod invocations;
mod jump_cleanup;
mod lanes;
mod layout;
mod limit;
mod liveness;
mod load_alias;
mod load_fields;
mod math_call;
mod matrix;
mod memory;
mod places;
mod program;
mod retarget;
mod sanitize;
mod statement;
mod sync_point;
mod wide;

use crate::backend::{Backend, Bind, BufferId, Resource};
use crate::bindings_check::{
    ResourceLookup, check_binds, check_buffer_size, check_kernel_fits, check_workgroups, write_range,
};
use crate::device_info::{DeviceInfo, DeviceLimits};
use crate::error::BackendError;
use crate::texture::{SamplerDesc, SamplerId, TextureDesc, TextureId};
pub use counts::{DispatchCounts, WARP_WIDTH};
pub use limit::DEFAULT_TIME_LIMIT;
use program::Program;
pub use sanitize::{Finding, FindingKind, MAX_FINDINGS};
use std::collections::HashMap;
use std::time::{Duration, Instant};
use strata_kernels::{Kernel, KernelId, PipelineKey};

/// How to configure the interpreter.
#[derive(Clone, Copy, Debug)]
pub struct CpuOptions {
    /// Subgroup size for kernels that use subgroup operations; `None`: no subgroups.
    pub subgroup_size: Option<u32>,
    /// Wall time a dispatch may take before it fails naming where the kernel was
    /// (default [`DEFAULT_TIME_LIMIT`]; `None`: no limit).
    pub time_limit: Option<Duration>,
    /// Run as a sanitizer ([`Finding`], [`CpuBackend::take_findings`]); off by default:
    /// it costs several times the normal mode's time (docs/kernels.md).
    pub sanitize: bool,
}

impl Default for CpuOptions {
    fn default() -> Self {
        Self { subgroup_size: Some(8), time_limit: Some(DEFAULT_TIME_LIMIT), sanitize: false }
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
    /// Word range of mip `level` (a level of the texture: `TextureDesc::check_level`
    /// first), clamped to the texture's words.
    fn level_words(&self, level: u32) -> std::ops::Range<usize> {
        let words = |bytes: u64| usize::try_from(bytes / 4).unwrap_or(usize::MAX).min(self.words.len());
        let before = (0..level).fold(0u64, |sum, l| sum.saturating_add(self.desc.level_bytes(l)));
        let start = words(before);
        start..words(before.saturating_add(self.desc.level_bytes(level))).max(start)
    }
}

/// The words of `bytes` bytes (whole words), zeroed, or an error naming `what` where the
/// machine cannot give them (instead of aborting the process).
fn zeroed_words(bytes: u64, what: impl FnOnce() -> String) -> Result<Vec<u32>, BackendError> {
    match usize::try_from(bytes.div_ceil(4)) {
        Ok(words) => budget::try_zeroed(words, what),
        Err(_) => Err(BackendError::OutOfMemory { backend: "cpu".into(), operation: what() }),
    }
}

/// `words` as little-endian bytes, the first `len` of them, or an error naming `what`
/// where the machine cannot give the memory.
fn to_bytes(words: &[u32], len: usize, what: impl FnOnce() -> String) -> Result<Vec<u8>, BackendError> {
    let mut bytes = Vec::new();
    budget::try_reserve(&mut bytes, len, what)?;
    bytes.extend(words.iter().flat_map(|w| w.to_le_bytes()).take(len));
    Ok(bytes)
}

/// The naga-IR interpreter as a backend.
pub struct CpuBackend {
    info: DeviceInfo,
    options: CpuOptions,
    buffers: HashMap<u64, CpuBuffer>,
    textures: HashMap<u64, CpuTexture>,
    samplers: HashMap<u64, SamplerDesc>,
    next_buffer: u64,
    /// Compiled programs, by kernel and overrides ([`Kernel::pipeline_key`]).
    programs: HashMap<PipelineKey, Program>,
    /// Sanitizing programs ([`CpuOptions::sanitize`]), compiled apart.
    sanitizing: HashMap<PipelineKey, Program>,
    last_counts: DispatchCounts,
    counts_by_kernel: HashMap<KernelId, DispatchCounts>,
    /// The sanitizer's findings since the last [`CpuBackend::take_findings`].
    findings: Vec<Finding>,
    /// Occurrences past [`MAX_FINDINGS`] sites per dispatch, since then.
    findings_dropped: u64,
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
            float32_filterable: true,
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
            sanitizing: HashMap::new(),
            last_counts: DispatchCounts::default(),
            counts_by_kernel: HashMap::new(),
            findings: Vec::new(),
            findings_dropped: 0,
        })
    }

    /// The program of `kernel` (the sanitizing one when the backend sanitizes), compiled
    /// the first time.
    fn program(&mut self, kernel: &Kernel) -> Result<&Program, BackendError> {
        let sanitize = self.options.sanitize;
        let programs = if sanitize { &mut self.sanitizing } else { &mut self.programs };
        if let std::collections::hash_map::Entry::Vacant(slot) = programs.entry(kernel.pipeline_key()) {
            slot.insert(decode::compile(kernel, sanitize)?);
        }
        Ok(&programs[&kernel.pipeline_key()])
    }

    /// What the sanitizer found ([`CpuOptions::sanitize`]) in the dispatches since the
    /// last call, each dispatch's findings in WGSL line order (at most [`MAX_FINDINGS`]
    /// sites per dispatch), and how many occurrences past that cap were only counted.
    /// Taking them resets the list. Empty when the backend does not sanitize.
    pub fn take_findings(&mut self) -> (Vec<Finding>, u64) {
        (std::mem::take(&mut self.findings), std::mem::take(&mut self.findings_dropped))
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

    /// The words a binding's slot holds during a dispatch (moved out of a buffer, so
    /// that it is not copied; a texture's with a header before them; put back by
    /// [`CpuBackend::put_back`]). An error, with the resource left as it was, where the
    /// machine cannot give a texture's copy.
    fn take_bound(&mut self, resource: Resource) -> Result<Vec<u32>, BackendError> {
        Ok(match resource {
            Resource::Buffer(id) => std::mem::take(&mut self.buffers.get_mut(&id.0).expect("checked").words),
            Resource::Texture(id) => {
                let texture = self.textures.get_mut(&id.0).expect("checked");
                let words =
                    image::bind_texture(&texture.desc, &texture.words).map_err(|_| BackendError::OutOfMemory {
                        backend: "cpu".into(),
                        operation: format!("binding texture `{}` ({} words)", texture.desc.label, texture.words.len()),
                    })?;
                texture.words = Vec::new();
                words
            }
            Resource::Sampler(id) => image::bind_sampler(&self.samplers[&id.0]),
        })
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
        let words = zeroed_words(size, || format!("creation of buffer `{label}` ({size} bytes)"))?;
        self.next_buffer += 1;
        self.buffers.insert(self.next_buffer, CpuBuffer { words, size, label: label.into() });
        Ok(BufferId(self.next_buffer))
    }

    fn write_buffer(&mut self, buffer: BufferId, offset: u64, data: &[u8]) -> Result<(), BackendError> {
        let entry = self.buffers.get_mut(&buffer.0).ok_or(BackendError::UnknownBuffer(buffer.0))?;
        // Checked without wrapping: the range lies inside the buffer's bytes, so its
        // words inside `words` (the buffer's size rounded up to whole words).
        let range = write_range(&entry.label, entry.size, offset, data.len())?;
        let words = range.start / 4..range.end / 4;
        let Some(target) = entry.words.get_mut(words) else {
            return Err(BackendError::Buffer {
                label: entry.label.clone(),
                reason: format!("internal: write range {range:?} outside the buffer's {} bytes", entry.size),
            });
        };
        for (word, chunk) in target.iter_mut().zip(data.chunks_exact(4)) {
            *word = u32::from_le_bytes([chunk[0], chunk[1], chunk[2], chunk[3]]);
        }
        Ok(())
    }

    fn read_buffer(&mut self, buffer: BufferId) -> Result<Vec<u8>, BackendError> {
        let entry = self.buffer(buffer)?;
        let len = usize::try_from(entry.size).unwrap_or(usize::MAX).min(entry.words.len() * 4);
        to_bytes(&entry.words, len, || format!("read-back of buffer `{}` ({len} bytes)", entry.label))
    }

    fn destroy_buffer(&mut self, buffer: BufferId) -> Result<(), BackendError> {
        self.buffers.remove(&buffer.0).map(|_| ()).ok_or(BackendError::UnknownBuffer(buffer.0))
    }

    fn create_texture(&mut self, desc: &TextureDesc) -> Result<TextureId, BackendError> {
        desc.check(&self.info)?;
        let bytes = (0..desc.mip_levels).fold(0u64, |sum, l| sum.saturating_add(desc.level_bytes(l)));
        let words = zeroed_words(bytes, || format!("creation of texture `{}` ({bytes} bytes)", desc.label))?;
        self.next_buffer += 1;
        self.textures.insert(self.next_buffer, CpuTexture { desc: desc.clone(), words });
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
        let bytes = usize::try_from(entry.desc.level_bytes(level)).unwrap_or(usize::MAX);
        entry.desc.check_level(level, bytes)?;
        let words = &entry.words[entry.level_words(level)];
        to_bytes(words, words.len() * 4, || format!("read-back of texture `{}` ({bytes} bytes)", entry.desc.label))
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
            sampler: &|id| self.samplers.get(&id.0).copied().ok_or(BackendError::UnknownSampler(id.0)),
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
        let mut taken = Ok(());
        for (index, resource) in resources.iter().enumerate() {
            let words = match first_of(index) {
                Some(first) => {
                    let mut copy = Vec::new();
                    budget::try_reserve(&mut copy, bound[first].len(), || {
                        format!(
                            "binding {} of `{}` again ({} words)",
                            resource.describe(),
                            kernel.name(),
                            bound[first].len()
                        )
                    })
                    .map(|()| {
                        copy.extend_from_slice(&bound[first]);
                        copy
                    })
                }
                None => self.take_bound(*resource),
            };
            match words {
                Ok(words) => bound.push(words),
                Err(error) => {
                    taken = Err(error);
                    break;
                }
            }
        }
        let key = kernel.pipeline_key();
        let program = if self.options.sanitize { &self.sanitizing[&key] } else { &self.programs[&key] };
        let sanitizer = self.options.sanitize.then(|| {
            let per_workgroup = kernel.workgroup_size.iter().product::<u32>();
            sanitize::Sanitizer::new(per_workgroup, workgroups, bound.iter().map(Vec::len))
        });
        let limit = limit::Limit::starting_now(self.options.time_limit);
        let result = match taken {
            Ok(()) => dispatch::run(program, &mut bound, workgroups, subgroup_size, (&limit, sanitizer.as_ref())),
            Err(error) => Err(error),
        };
        if let Some(sanitizer) = sanitizer {
            let (findings, dropped) = sanitizer.into_findings();
            self.findings.extend(findings);
            self.findings_dropped += dropped;
        }
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

#[cfg(test)]
mod tests {
    use super::{CpuBackend, CpuOptions};
    use crate::backend::{Backend, Bind, download, upload};
    use strata_kernels::Kernel;

    /// A small kernel through the public API (private, function and workgroup memory,
    /// a barrier, atomics, worker threads), and writes checked at the buffer's edges:
    /// what Miri runs of the interpreter (SECURITY.md, "Miri").
    #[test]
    fn a_kernel_runs_end_to_end_and_writes_stay_inside_the_buffer() {
        let source = "@group(0) @binding(0) var<storage, read_write> data: array<u32>;
            @group(0) @binding(1) var<storage, read_write> total: atomic<u32>;
            var<private> seen: array<u32, 4>;
            var<workgroup> row: array<u32, 4>;
            @compute @workgroup_size(4) fn main(@builtin(local_invocation_index) i: u32,
                                                @builtin(global_invocation_id) id: vec3<u32>) {
                var sum = 0u;
                seen[i] = data[id.x];
                row[i] = seen[i] * 2u;
                workgroupBarrier();
                for (var k = 0u; k < 4u; k++) { sum += row[k]; }
                data[id.x] = sum + i;
                atomicAdd(&total, 1u);
            }";
        let kernel = Kernel::from_wgsl("end_to_end.wgsl", source.into(), "main", false).expect("valid WGSL");
        let mut cpu = CpuBackend::new(CpuOptions::default()).unwrap();
        let data = upload(&mut cpu, "data", &[1u32, 2, 3, 4, 10, 20, 30, 40]).unwrap();
        let total = cpu.create_buffer("total", 4).unwrap();
        cpu.dispatch(&kernel, &[Bind::new(0, data), Bind::new(1, total)], [2, 1, 1]).unwrap();
        assert_eq!(download::<u32>(&mut cpu, data).unwrap(), [20, 21, 22, 23, 200, 201, 202, 203]);
        assert_eq!(download::<u32>(&mut cpu, total).unwrap(), [8]);
        // The last word, then ranges past the end, wrapped or not: refused, unwritten.
        cpu.write_buffer(data, 28, &7u32.to_le_bytes()).unwrap();
        for offset in [32, u64::MAX - 3, u64::MAX - 31] {
            assert!(cpu.write_buffer(data, offset, &[9; 4]).is_err(), "offset {offset}");
        }
        assert_eq!(download::<u32>(&mut cpu, data).unwrap(), [20, 21, 22, 23, 200, 201, 202, 7]);
    }
}
