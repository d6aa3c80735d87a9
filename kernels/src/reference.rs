//! Plain-Rust statements of what the kernels compute: the oracles of the tests.

pub mod block_histogram;
pub mod bvh_trace;
pub mod camera_rays;
pub mod stratified_selection;
pub mod svgf;
