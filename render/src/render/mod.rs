//! The path tracer (CONVENTIONS.md's integrator in WGSL): a [`Scene`] flattened into
//! device arrays ([`GpuScene`]), the environment's importance-sampling tables, and the
//! progressive [`PathTracer`] that adds one sample per pixel per dispatch.
//!
//! [`Scene`]: crate::scene::Scene

pub mod environment_cdf;
pub mod gpu_scene;
pub mod path_tracer;

pub use gpu_scene::GpuScene;
pub use path_tracer::{Film, LightSampling, PathTracer, RenderSettings, SceneBuffers, render};
