//! The paper's stratified selection (§4.2, Fig. 3, Table 2) on the host side: the one
//! settings struct every user shares ([`SelectionSettings`]), the sampler variants
//! ([`SamplerVariant`]) and the table of position patterns ([`patterns`]).
//!
//! The GPU statement is `kernels/wgsl/strata/selection.wgsl` (positions and numbers) and
//! `kernels/wgsl/strata/resampling.wgsl` (the inverse-CDF choice); the renderer's passes
//! and the embeddable pass both call it. [`crate::reference::stratified_selection`] states
//! the same in plain Rust for bit-exact tests, by evaluating [`patterns`].

pub mod patterns;
mod sampler;
mod settings;

pub use patterns::{BELOW_ONE, MAX_SELECTED, Pattern, StratifiedPattern};
pub use sampler::{
    SAMPLER_ANTITHETIC, SAMPLER_HEITZ, SAMPLER_RANDOM, SAMPLER_RANDOM_OFFSET, SAMPLER_RANDOM_OFFSET_BLUE_NOISE,
    SamplerVariant,
};
#[cfg(feature = "clap")]
pub use settings::block_size_parser;
pub use settings::{SelectionSettings, SettingError};

/// The WGSL module `gpu/selection.wgsl`: the sampler ids and the pattern table's limits
/// declared in `sampler.rs` and `patterns.rs` ([`crate::gpu`]).
pub fn gpu_module() -> crate::gpu::GpuModule {
    crate::gpu::GpuModule {
        path: "gpu/selection.wgsl",
        source: "kernels/src/selection/",
        readers: None,
        constants: [patterns::pattern_constants(), sampler::sampler_constants()].concat(),
        structs: Vec::new(),
    }
}
