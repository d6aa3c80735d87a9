//! strata's product: scenes, the path tracer, stratified ReSTIR and the passes that
//! drive the kernels on any [`Backend`], and synthetic inputs. What an engine or a
//! program that renders depends on; the evaluation (compare, metrics, plots, the report)
//! and the `strata` command line live in the `strata` crate above it.
//!
//! [`Backend`]: strata_backends::Backend
//!
//! ```
//! use strata_render::histogram_pass::{BlockHistogramPass, HistogramVariant};
//! use strata_render::synthetic::{CandidateMix, candidate_image};
//! use strata_backends::cpu_backend::{CpuBackend, CpuOptions};
//! use strata_kernels::BlockGrid;
//!
//! // The paper's block histogram (§4.1) as a pass, on the interpreter here.
//! let mut backend = CpuBackend::new(CpuOptions::default())?;
//! let grid = BlockGrid::new(32, 16, 16)?;
//! let candidates = candidate_image(32, 16, 1, CandidateMix::default());
//! let pass = BlockHistogramPass::new(&mut backend, HistogramVariant::Auto, grid)?;
//! let output = pass.run(&mut backend, &candidates)?;
//! assert_eq!(output, strata_kernels::reference::block_histogram::block_histogram(grid, &candidates));
//! pass.destroy(&mut backend)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod atomic_file;
// The command line's backends (ash, wgpu): native only.
#[cfg(not(target_arch = "wasm32"))]
pub mod backend_choice;
pub mod denoise;
pub mod error_metric;
pub mod histogram_pass;
pub mod render;
pub mod restir;
pub mod rgb_image;
pub mod scene;
pub mod synthetic;
pub mod trace_pass;

pub use histogram_pass::{BlockHistogramPass, HistogramVariant, PassError};
