//! Evaluation of the renderer: [`compare`] renders every method from the same seeds
//! against a reference ([`image_checks`] says what an image must be to be scored), [`metrics`] and [`variance`] measure the images (with and
//! without the reference), [`plot`] draws RelMSE and ratios over frames, [`summary`]
//! makes the ratio and variance tables, [`crops`] picks close-ups, [`page`] writes
//! `report.html`, [`record`] says what ran where, [`output_folder`] keeps one run per
//! folder, and [`report`] runs a whole comparison from a plain options struct, and [`viewer`] measures what
//! the viewer sees (bias and residual noise, flicker, the error's correlation). It runs the renderer and the command line runs it, so it is
//! a module of the host crate rather than a crate below it.

pub mod bias_noise;
pub mod block_structure;
pub mod compare;
pub mod correlation;
pub mod crops;
mod fft;
pub mod flicker;
pub mod flip;
pub mod image_checks;
pub mod metrics;
pub mod output_folder;
pub mod page;
pub mod plot;
pub mod record;
pub mod report;
pub mod summary;
#[cfg(test)]
mod test_noise;
pub mod variance;
pub mod viewer;
