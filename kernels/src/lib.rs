//! strata's compute kernels, written once in WGSL.
//!
//! ```
//! use strata_kernels::{BlockGrid, KernelId, Registry};
//! use strata_kernels::reference::block_histogram::block_histogram;
//! use strata_kernels::types::Candidate;
//!
//! // Every kernel, parsed and validated by naga, with what its IR says.
//! let registry = Registry::shared()?;
//! let histogram = registry.get(KernelId::BlockHistogram);
//! assert_eq!(histogram.workgroup_size, [64, 1, 1]);
//! assert!(histogram.bindings.iter().any(|b| b.name == "candidates"));
//! // Its plain-Rust statement: one 16 x 16 block, two objects.
//! let grid = BlockGrid::new(16, 16, 16)?;
//! let candidates: Vec<Candidate> =
//!     (0..256).map(|p| Candidate { key: (p % 7) as f32, object_id: p / 128 }).collect();
//! let output = block_histogram(grid, &candidates);
//! assert_eq!(output.stats[0].clusters, 2);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! * [`catalogue`]: every kernel the project ships, as declared (entry file, entry point,
//!   features, float tolerance), its fragments derived by [`wgsl_imports`] from the
//!   `// #import` lines of the files ([`wgsl_files`]); [`registry`]: each parsed and validated by naga, with
//!   its workgroup size and bindings read from naga's IR.
//! * [`constants`]: the WGSL constants the host shares, checked against their Rust values.
//! * [`gpu`]: the structs and constants the kernels share with the host, declared once in
//!   Rust ([`types`], [`restir_types`], ...), which generates their WGSL modules
//!   (`// #import gpu/strata.wgsl`); [`layout`] holds each struct to naga's layout of it.
//! * [`translate`]: naga's SPIR-V, HLSL, MSL and GLSL back ends with the options every
//!   backend of the project uses.
//! * [`reference`](mod@reference): plain-Rust statements of what each kernel computes, the oracle of
//!   the tests.
//! * [`selection`]: the paper's stratified selection on the host (§4.2): the settings
//!   struct every user shares, the sampler variants and the table of position patterns.
//! * [`pass_plan`]: the paper's pass as data (buffers, bindings by name, per-frame
//!   uniforms, grid shift and dispatch sizes): the one driver that strata's renderer,
//!   strata-embed and the export package follow.
//!
//! Where the paper lives in WGSL (`kernels/wgsl/strata/`): §4.1 `histogram.wgsl` (with
//! its records in `candidate.wgsl`, its sorting in `histogram_network.wgsl` or
//! `histogram_rank.wgsl`), §4.2 `selection.wgsl` (and its last step,
//! `resampling.wgsl`), §4.3 `masking.wgsl`.

pub mod binding;
pub mod block_grid;
pub mod blue_noise;
pub mod catalogue;
pub mod combined_samplers;
pub mod constants;
pub mod denoise_types;
pub mod embed_types;
pub mod error;
pub mod glsl_zero_init;
pub mod glslang;
pub mod gpu;
pub mod hash;
pub mod hlsl_samplers;
pub mod hlsl_zero_init;
pub mod integer_division;
mod ir_edit;
pub mod layout;
pub mod pass_plan;
pub mod reference;
pub mod registry;
pub mod render_types;
pub mod restir_types;
pub mod selection;
pub mod signed_image_levels;
pub mod slang;
pub mod source;
pub mod texture;
pub mod trace_types;
pub mod translate;
pub mod types;
pub mod validate;
pub mod wgsl_files;
pub mod wgsl_imports;
pub mod word_kinds;
pub mod workgroup_zero_loops;

pub use binding::{BindingAccess, BindingInfo, BindingKind, ElementLayout};
pub use block_grid::{BlockGrid, BlockRect, GridError};
pub use catalogue::Executor;
pub use error::KernelError;
pub use registry::{Kernel, KernelId, PipelineKey, RANDOM_REPLAY, Registry, SCENE_IN_UNIFORM, Specialisation};
pub use texture::{StorageTextureAccess, TexelFormat, TexelKind, TextureDimension};
pub use word_kinds::{WordKind, WordKinds};
