//! Spatio-temporal reservoir resampling of path candidates, with the paper's histogram
//! stratification (`strata`) and two baselines that share every other stage
//! (`restir`: K uniformly random candidates of the same block cluster, streaming
//! reservoir; `restir-disc`: K uniformly random pixels in a disc with normal/depth
//! rejection).
//!
//! One frame is five kernels (`kernels/wgsl/restir/`): candidates (G-buffer, each pixel's
//! own estimate, one path candidate per pixel), the block histogram (strata and restir
//! only), selection + resampling with the pixel's canonical candidate, temporal reuse
//! and shading (and, for a denoiser, its guide). In the temporal-first order
//! ([`ReuseOrder::TemporalFirst`]) the selection runs with K = 0 (the canonical candidate
//! alone), the temporal merge follows, then the histogram of the merged reservoirs' keys
//! and the spatial reuse of K merged reservoirs (`entry_reservoir_keys.wgsl`,
//! `entry_spatial.wgsl`). See [`RestirRenderer`] for the buffers; the selection itself (§4.1-4.3)
//! lives in the kernels' `strata/` folder and [`strata_kernels::selection`].

mod pipeline;
mod settings;

pub use pipeline::{DenoiserInputs, FrameBuffers, FrameStats, RestirRenderer};
pub use settings::{MAX_SPECULAR_CHAIN, Method, RestirSettings, ReuseOrder, ShadedParts, Shading};
