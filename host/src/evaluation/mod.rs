//! Evaluation of the renderer: [`compare`] renders every method from the same seeds
//! against a reference, [`metrics`] and [`variance`] measure the images (with and
//! without the reference), [`plot`] draws RelMSE over frames, [`summary`] prints the
//! ratio and variance tables and [`report`] runs a whole comparison from a plain options
//! struct. It runs the renderer and the command line runs it, so it is
//! a module of the host crate rather than a crate below it.

pub mod compare;
pub mod metrics;
pub mod plot;
pub mod report;
pub mod summary;
pub mod variance;
