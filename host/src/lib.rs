//! strata's evaluation and command line: `compare`, `metrics`, plots, the report page
//! and the `strata` binary (in `main.rs`), over the product crate [`strata_render`],
//! whose modules a program names by that crate's paths (`strata_render::scene`,
//! `strata_render::restir`, ...): one name per module.
//!
//! An engine that renders depends on `strata-render` alone: this crate adds the
//! plotting, font, progress and time-formatting dependencies that only an evaluation
//! needs.
//!
//! ```
//! use strata::evaluation::metrics::relmse;
//! use strata_render::rgb_image::RgbImage;
//!
//! // Relative MSE of an image against its reference (the paper's error measure, §6).
//! let reference = RgbImage { width: 4, height: 4, pixels: vec![[1.0, 0.5, 0.25]; 16] };
//! let image = RgbImage { pixels: vec![[1.1, 0.5, 0.25]; 16], ..reference.clone() };
//! let error = relmse(&image, &reference)?;
//! assert!(error > 0.0 && error < 0.02);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod evaluation;
pub mod progress;
