//! # strata-embed: the paper's stratified selection in your engine
//!
//! Histogram stratification (Salaün et al., SIGGRAPH 2025) replaces ReSTIR's uniform
//! random choice of spatial candidates by a stratified one: per B × B block, candidates
//! are clustered by object and sorted by luminance (a histogram), and each pixel takes K
//! candidates of its own cluster at antithetic, temporally blue-noise positions of that
//! sorted run; resampling then picks one by inverse CDF. The method is independent of
//! how candidates are made or shaded (§4.2), so this crate gives an engine that already
//! runs ReSTIR just that pass, over its own buffers:
//!
//! * [`WgpuSelection`] (feature `wgpu`) records into the engine's `wgpu` command encoder;
//! * [`AshSelection`] (feature `ash`) records into the engine's Vulkan command buffer;
//! * [`wgsl::module`] hands out the same kernels as WGSL source with their bind-group
//!   layouts, for engines that compose shaders themselves.
//!
//! The engine writes, per pixel, a [`contract::Candidate`] (luminance key and cluster
//! id) and optionally a payload index into its own reservoir storage; it gets back K
//! payload indices per pixel ([`contract::SelectedCandidates`]) and keeps its own shift
//! mapping, target function and shading. If it writes its resampling weights
//! ([`contract::ResampleInput`]), the pass also makes the stratified inverse-CDF choice
//! and the unbiased contribution weight ([`contract::ResampleOutput`]). The layouts, who
//! writes what and when: [`contract`]. The knobs: [`SelectionSettings`].
//!
//! Examples that run: `cargo run -p strata-embed --example wgpu_embed` and
//! `--example ash_embed`.
//!
//! What one frame needs, without a device: the uniforms and dispatch sizes (the same
//! numbers the C header `strata_frame.h` of the export package computes).
//!
//! ```
//! use strata_embed::SelectionSettings;
//! use strata_embed::frame::{FrameId, frame_params};
//!
//! let settings = SelectionSettings { block_shift: true, ..SelectionSettings::default() };
//! let id = FrameId { frame: 3, seed: 7, identity_payload: true };
//! let params = frame_params(&settings, 1920, 1080, id, 65535)?;
//! assert_eq!(params.pixel_workgroups, [240, 135, 1]);
//! assert!(params.histogram.shift_x < 16 && params.histogram.block_size == 16);
//! # Ok::<(), strata_embed::EmbedError>(())
//! ```

mod binding_plan;
pub mod contract;
mod error;
pub mod frame;
mod limits;
pub mod wgsl;

#[cfg(feature = "ash")]
mod ash_objects;
#[cfg(feature = "ash")]
mod ash_selection;
#[cfg(feature = "wgpu")]
mod wgpu_selection;

#[cfg(feature = "ash")]
pub use ash_selection::{AshBindings, AshBufferSlice, AshBuffers, AshDevice, AshResampleBuffers, AshSelection};
pub use binding_plan::{EngineBuffers, ResampleBuffers};
pub use error::EmbedError;
/// What runs the kernels (a GPU, a CPU driver such as lavapipe), for
/// [`wgsl::histogram_module`]'s choice.
pub use strata_kernels::Executor;
/// The pass as data (its buffers, their bindings by name, who writes them and how large
/// they are): the one plan strata's renderer and the export package follow too.
pub use strata_kernels::pass_plan::{PassBuffer, SizeRule, Stage, Writer};
/// The selection's settings and sampler variants: the paper's one settings struct, shared
/// with strata's renderer and command line.
pub use strata_kernels::selection::{SamplerVariant, SelectionSettings};
#[cfg(feature = "wgpu")]
pub use wgpu_selection::{WgpuBindings, WgpuBufferSlice, WgpuBuffers, WgpuResampleBuffers, WgpuSelection};
