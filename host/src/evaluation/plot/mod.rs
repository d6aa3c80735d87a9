//! The plots of `strata compare`, `strata plot` and the report page, each written as
//! SVG (for the page) and PNG (for anything else) from one drawing code on plotters:
//!
//! * [`write_relmse_plot`]: RelMSE against frame on log-log axes, one line per method
//!   with its 95 % band over seeds;
//! * [`write_ratio_plot`]: strata ÷ each baseline, paired per seed, against a dashed 1;
//! * [`write_overlay_plots`]: several runs in one figure (the paper's Fig. 11, block
//!   shift on/off), told apart by line style;
//! * [`write_correlation_plot`] and [`write_spectrum_plot`]: what the viewer sees, the
//!   error's correlation between pixels by lag and its radial power spectrum, per method
//!   and stage (issue 55): the curves behind the viewer table's single numbers.
//!
//! Every method has one colour everywhere ([`method_colour`], which the HTML report uses
//! too), so a reader learns it once; before, colours followed list order and strata was
//! green in one plot and red in the next. Files: `style` (colours, dashes), `axis` (the
//! log2/log10/linear axes and their ticks), `series` (rows → lines), `figure` (drawing
//! one figure on any backend, x frames or linear), `output` (SVG and PNG files), `plots`
//! (the public plots against frame), `viewer_plots` (the viewer's figures).

mod axis;
mod figure;
mod output;
mod plots;
mod series;
mod style;
#[cfg(test)]
mod tests;
mod viewer_plots;
#[cfg(test)]
mod viewer_tests;

pub use plots::{relmse_svg, write_overlay_plots, write_ratio_plot, write_relmse_and_ratio_plots, write_relmse_plot};
pub use style::method_colour;
pub use viewer_plots::{write_correlation_plot, write_spectrum_plot};
