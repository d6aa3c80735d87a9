//! Spatio-temporal reservoir resampling of path candidates, with the paper's histogram
//! stratification (`strata`) and two baselines that share every other stage
//! (`restir`: K uniformly random candidates of the same block cluster, streaming
//! reservoir; `restir-disc`: K uniformly random pixels in a disc with normal/depth
//! rejection).
//!
//! One frame is five kernels (`kernels/wgsl/restir/`): candidates (G-buffer, each pixel's
//! own estimate, one path candidate per pixel), the block histogram (strata and restir
//! only), selection + resampling with the pixel's canonical candidate, temporal reuse
//! and shading. See [`RestirRenderer`] for the buffers and [`selection_numbers`] for the
//! sampler variants of the paper's Table 2.

mod pipeline;
mod selection_numbers;
mod settings;

pub use pipeline::{FrameBuffers, FrameStats, RestirRenderer};
pub use selection_numbers::selection_numbers;
pub use settings::{Method, RestirSettings, ShadedParts};
