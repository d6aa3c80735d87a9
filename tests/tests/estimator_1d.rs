//! The 1-D RIS test of the stratified-ReSTIR issue: every selection pattern's estimator
//! converges to the known integral within its confidence interval, and stratified
//! selection (random offset, antithetic) has lower variance than uniform random
//! selection. Prints the measured variances.

use strata_estimator::{OneDimensionalProblem, SelectionPattern, run_estimates};

#[test]
fn every_pattern_is_unbiased_and_stratification_lowers_variance() {
    let count = 200_000;
    let mut variances = Vec::new();
    for (seed, pattern) in SelectionPattern::ALL.into_iter().enumerate() {
        for pool in [3usize, 32] {
            let estimate = run_estimates(
                OneDimensionalProblem { pool, subset_dependent_normalisation: false },
                pattern,
                count,
                1000 + seed as u64 * 7 + pool as u64,
            );
            let error = (estimate.mean - OneDimensionalProblem::INTEGRAL).abs();
            // 99.99 % two-sided interval: a correct estimator fails this 1 time in 10 000.
            assert!(
                error < estimate.half_width(3.9),
                "{pattern:?}, pool {pool}: mean {} vs {} (± {})",
                estimate.mean,
                OneDimensionalProblem::INTEGRAL,
                estimate.half_width(3.9)
            );
            eprintln!("{pattern:?} pool {pool}: mean {:.5} variance {:.5}", estimate.mean, estimate.variance);
            if pool == 32 {
                variances.push((pattern, estimate.variance));
            }
        }
    }
    let variance = |p| variances.iter().find(|(q, _)| *q == p).unwrap().1;
    assert!(variance(SelectionPattern::RandomOffset) < variance(SelectionPattern::UniformRandom));
    assert!(variance(SelectionPattern::Antithetic) < variance(SelectionPattern::UniformRandom));
}

#[test]
fn a_subset_dependent_weight_is_caught_as_bias() {
    // Normalising by the number of distinct selected candidates (instead of K) makes the
    // weight depend on the drawn subset; with a pool of 3, duplicates are common and the
    // same test must see the bias.
    let problem = OneDimensionalProblem { pool: 3, subset_dependent_normalisation: true };
    let estimate = run_estimates(problem, SelectionPattern::UniformRandom, 200_000, 5);
    let error = (estimate.mean - OneDimensionalProblem::INTEGRAL).abs();
    assert!(error > estimate.half_width(3.9), "bias not detected: mean {}", estimate.mean);
}
