//! The paper's pass (§4: block histogram, stratified selection, resampling) as data: the
//! one statement every runner follows. It says which buffers the pass has and how large
//! they are ([`buffers`]), which buffer goes to which binding of which kernel, by the
//! WGSL variable's name ([`stages`]), and what each frame writes and dispatches: the
//! shifted block grid, the uniforms and the workgroup counts ([`frame`]).
//!
//! Its runners are thin: strata's renderer binds the histogram through the `Backend`
//! trait from it (`strata_render::histogram_pass`), `strata-embed` records it into an
//! engine's wgpu encoder or Vulkan command buffer, and `strata-export` serialises it
//! into the package's `manifest.json` and `strata_frame.h` for engines outside Rust.
//! Binding numbers are never written here: they come from naga's reflection of the
//! kernels (the registry), looked up by name ([`stages::numbered`]).
//!
//! ```
//! use strata_kernels::pass_plan::{FrameId, PassBuffer, Stage, frame_params};
//! use strata_kernels::selection::SelectionSettings;
//!
//! let settings = SelectionSettings { block_shift: true, ..SelectionSettings::default() };
//! let id = FrameId { frame: 3, seed: 7, identity_payload: true };
//! let frame = frame_params(&settings, 1920, 1080, id, 65535)?;
//! assert_eq!(frame.pixel_workgroups, [240, 135, 1]);
//! assert!(Stage::Histogram.bindings().contains(&("candidates", PassBuffer::Candidates)));
//! # Ok::<(), strata_kernels::pass_plan::PlanError>(())
//! ```

pub mod buffers;
pub mod frame;
pub mod stages;

pub use buffers::{PassBuffer, SizeRule, Writer};
pub use frame::{
    FrameId, FrameParams, HistogramDispatch, PlanError, frame_params, grid, grid_shift, histogram_dispatch, max_blocks,
    pixel_workgroups,
};
pub use stages::{Stage, numbered};
