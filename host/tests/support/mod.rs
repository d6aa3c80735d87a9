//! Checks shared by the host's integration tests (each test file that needs them
//! declares `mod support;`).

pub mod denoised_run;
