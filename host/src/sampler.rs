//! The per-pixel sampler: Heitz et al. 2019's blue-noise tables and the paper's Table 2
//! sampler variants, defined in [`strata_kernels::blue_noise`] (shared with the embedding
//! crate) and re-exported here.

pub use strata_kernels::blue_noise::*;
