//! The paper's selection step on paper and in 1-D (§4.2, Fig. 3), before any rendering.
//!
//! # Setting
//! A pool holds n candidates x_1..x_n drawn independently from a source pdf p, each with
//! its one-sample estimate f(x_i)/p(x_i) as sort key; the pool is sorted by key (the
//! histogram). K = 4 candidates are *selected* from the sorted pool by a pattern of K
//! positions in [0, 1), position → index ⌊pos·n⌋ (clamped to n − 1), and one of them is
//! *resampled* with probability proportional to the resampling weight
//! w_j = p̂(x_j) / p(x_j) (p̂: the target function). The estimate is
//!
//! ```text
//! Y = f(x_s) / p̂(x_s) · (1/K) Σ_{j ∈ S} w_j
//! ```
//!
//! # Why it is unbiased
//! Given the pool and the selected multiset S, resampling gives
//! E[Y | S] = (1/K) Σ_{j∈S} w_j · f(x_j)/p̂(x_j) = (1/K) Σ_{j∈S} f(x_j)/p(x_j),
//! provided p̂ > 0 wherever f ≠ 0. Writing c_i for how often candidate i is in S,
//! E\[Y | pool\] = (1/K) Σ_i E\[c_i\] · f(x_i)/p(x_i). If **every candidate's expected
//! selection count is K/n whatever the pool's order**, this is (1/n) Σ_i f(x_i)/p(x_i),
//! the plain pool average, whose expectation is ∫ f. Two conditions matter:
//!
//! 1. The pattern's positions must cover [0, 1) uniformly: each of K positions is
//!    uniform on its own interval of length 1/K and the intervals tile [0, 1) (random
//!    offset: [j/K, (j+1)/K); antithetic: [0, ¼), (¼, ½], [½, ¾), (¾, 1]). Then
//!    E\[c_i\] = K · (1/n) for every index i, duplicates counted when n < K.
//!    [`expected_counts`] computes E\[c_i\] exactly (piecewise-linear positions, integrated
//!    over u), and the tests check it equals K/n.
//! 2. The resampling weights must not depend on which subset was drawn: w_j is a function
//!    of candidate j alone and the normalisation is the fixed 1/K. (A weight that looked at
//!    the other selected candidates, e.g. normalising by the subset's own spread, would
//!    break the step from E[Y | S] to the pool average.) In the renderer, where candidates
//!    come from different pixels, strata uses 1/K weights among the K selected candidates
//!    combined with the pixel's own canonical candidate by pairwise MIS (Lin et al. 2022),
//!    for the same reason.
//!
//! Sorting changes *which* subsets are likely, not the marginal counts: that is where
//! the variance reduction comes from, and why it is free of bias.

mod patterns;
mod ris_1d;

pub use patterns::{K, SelectionPattern, expected_counts, select, variance_of_selected_mean};
pub use ris_1d::{Estimate, OneDimensionalProblem, run_estimates};
