//! The pass's kernels as WGSL source modules, for engines that compose shaders
//! themselves: each module is self-contained (structs, constants, functions and one
//! entry point) and comes with its bind-group layout, read from naga's IR.
//!
//! Run order per frame: a histogram module ([`histogram_module`] picks one of the three,
//! which give the same output), then
//! [`ModuleId::Select`], then, if the engine resamples with the pass,
//! [`ModuleId::Resample`]; a storage barrier between each. Uniform contents: the
//! [`crate::frame::frame_params`] of the frame.

use crate::error::EmbedError;
use strata_kernels::{BindingAccess, BindingKind, Executor, KernelId, Registry};

/// One of the pass's kernels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ModuleId {
    /// Per-block histogram (cluster by id, bitonic sort by key), portable.
    Histogram,
    /// The same with subgroup shuffles (needs subgroup operations; same output).
    HistogramSubgroup,
    /// The same output by ranking: each candidate's position counted over its block
    /// (portable; faster than the network on a CPU driver at every block size where
    /// measured).
    HistogramRank,
    /// `strata_select`.
    Select,
    /// `strata_resample`.
    Resample,
}

impl ModuleId {
    /// Every module.
    pub const ALL: [ModuleId; 5] = [
        ModuleId::Histogram,
        ModuleId::HistogramSubgroup,
        ModuleId::HistogramRank,
        ModuleId::Select,
        ModuleId::Resample,
    ];

    /// The registry kernel of the module.
    pub fn kernel(self) -> KernelId {
        match self {
            ModuleId::Histogram => KernelId::BlockHistogram,
            ModuleId::HistogramSubgroup => KernelId::BlockHistogramSubgroup,
            ModuleId::HistogramRank => KernelId::BlockHistogramRank,
            ModuleId::Select => KernelId::StrataSelect,
            ModuleId::Resample => KernelId::StrataResample,
        }
    }
}

/// The histogram module to run for `block_size` on `executor` with or without subgroup
/// shuffles: the choice strata's own renderer makes there ([`KernelId::fastest_histogram`];
/// every choice gives the same output). On a GPU the sorting network, on a CPU driver such
/// as lavapipe ranking (BENCHMARKS.md, block_sort).
/// [`Executor::of_device`] tells them apart from the adapter's device type.
pub fn histogram_module(block_size: u32, subgroups: bool, executor: Executor) -> ModuleId {
    match KernelId::fastest_histogram(block_size, subgroups, executor) {
        KernelId::BlockHistogramRank => ModuleId::HistogramRank,
        KernelId::BlockHistogramSubgroup => ModuleId::HistogramSubgroup,
        _ => ModuleId::Histogram,
    }
}

/// How one binding of a module is declared.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ModuleBinding {
    /// `@group` (always 0).
    pub group: u32,
    /// `@binding`.
    pub binding: u32,
    /// The WGSL variable's name.
    pub name: String,
    /// `var<uniform>` when true, else `var<storage>`.
    pub uniform: bool,
    /// Whether the kernel writes it (`read_write`).
    pub writable: bool,
    /// WGSL element type (`Candidate`, `u32`, ...).
    pub element: String,
    /// Bytes per element (array stride, or the struct size for a uniform).
    pub stride: u32,
    /// Smallest size in bytes the binding accepts.
    pub min_size: u64,
}

/// A self-contained WGSL module with one compute entry point.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct WgslModule {
    /// Which kernel.
    pub id: ModuleId,
    /// The WGSL source.
    pub source: String,
    /// The entry point.
    pub entry_point: String,
    /// `@workgroup_size`.
    pub workgroup_size: [u32; 3],
    /// Workgroup memory the entry point uses, in bytes.
    pub workgroup_memory_bytes: u64,
    /// Whether it needs subgroup operations.
    pub needs_subgroups: bool,
    /// Its bind-group layout (group 0), sorted by binding.
    pub bindings: Vec<ModuleBinding>,
}

#[cfg(feature = "wgpu")]
impl WgslModule {
    /// The module's bind-group layout as wgpu entries (compute stage, no dynamic offsets,
    /// minimum binding sizes from the WGSL types).
    pub fn wgpu_layout_entries(&self) -> Vec<wgpu::BindGroupLayoutEntry> {
        let kernel = Registry::shared().expect("a module exists only for a loaded registry").get(self.id.kernel());
        strata_backends::wgpu_backend::layout_entries(kernel, 0)
    }
}

/// The module `id`.
pub fn module(id: ModuleId) -> Result<WgslModule, EmbedError> {
    let kernel = Registry::shared()?.get(id.kernel());
    Ok(WgslModule {
        id,
        source: kernel.source.text.clone(),
        entry_point: kernel.entry_point().to_string(),
        workgroup_size: kernel.workgroup_size,
        workgroup_memory_bytes: kernel.workgroup_memory_bytes(),
        needs_subgroups: kernel.spec.features.subgroup,
        bindings: kernel
            .bindings
            .iter()
            .map(|b| ModuleBinding {
                group: b.group,
                binding: b.binding,
                name: b.name.clone(),
                uniform: b.kind == BindingKind::Uniform,
                writable: b.kind == BindingKind::Storage(BindingAccess::ReadWrite),
                element: b.element.type_name.clone(),
                stride: b.element.stride,
                min_size: b.min_size(),
            })
            .collect(),
    })
}

/// WGSL declarations of the contract's records and constants, to prepend to the
/// engine's own shaders that read `selections` or write `resample_inputs`.
pub fn contract_source() -> String {
    strata_kernels::wgsl_files::contract_wgsl()
}
