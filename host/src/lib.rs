//! strata's host: the passes that drive the kernels on any [`Backend`], synthetic
//! inputs, and the `strata` command line (in `main.rs`).
//!
//! [`Backend`]: strata_backends::Backend

pub mod backend_choice;
pub mod compare;
pub mod estimator;
pub mod histogram_pass;
pub mod metrics;
pub mod plot;
pub mod render;
pub mod restir;
pub mod rgb_image;
pub mod scene;
pub mod synthetic;
pub mod trace_pass;
pub mod variance;

pub use histogram_pass::{BlockHistogramPass, HistogramVariant, PassError};
