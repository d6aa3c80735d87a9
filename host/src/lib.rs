//! strata's host: the passes that drive the kernels on any [`Backend`], synthetic
//! inputs, and the `strata` command line (in `main.rs`).
//!
//! [`Backend`]: strata_backends::Backend

pub mod atomic_file;
pub mod backend_choice;
pub mod evaluation;
pub mod histogram_pass;
pub mod progress;
pub mod render;
pub mod restir;
pub mod rgb_image;
pub mod scene;
pub mod synthetic;
pub mod trace_pass;

pub use histogram_pass::{BlockHistogramPass, HistogramVariant, PassError};
