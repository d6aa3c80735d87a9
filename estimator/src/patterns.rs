//! Selection patterns of K = 4 positions in [0, 1) over a sorted pool (paper Fig. 3),
//! evaluated from the one statement of the patterns in [`strata_kernels::selection`].

use rand::Rng;
use strata_kernels::selection::StratifiedPattern;
pub use strata_kernels::selection::patterns::index_of;

/// Candidates selected per pixel.
pub const K: usize = 4;

/// How K candidates are taken from a sorted pool of n.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SelectionPattern {
    /// K independent uniform positions (ReSTIR's random neighbours).
    UniformRandom,
    /// Random offset u ∈ [0, 1/K), positions u + j/K.
    RandomOffset,
    /// The paper's antithetic pattern: u ∈ [0, ¼), positions {u, ½ − u, ½ + u, 1 − u}.
    Antithetic,
}

impl SelectionPattern {
    /// Every pattern.
    pub const ALL: [SelectionPattern; 3] =
        [SelectionPattern::UniformRandom, SelectionPattern::RandomOffset, SelectionPattern::Antithetic];

    /// The stratified pattern's slots, `None` for independent positions.
    fn stratified(self) -> Option<StratifiedPattern> {
        match self {
            SelectionPattern::UniformRandom => None,
            SelectionPattern::RandomOffset => Some(StratifiedPattern::random_offset(K as u32)),
            SelectionPattern::Antithetic => Some(StratifiedPattern::antithetic(K as u32)),
        }
    }

    /// Positions for the pattern's one number u ∈ [0, 1) (b of
    /// [`StratifiedPattern`]); `UniformRandom` draws its own K numbers from `rng`.
    pub fn positions(self, u: f64, rng: &mut impl Rng) -> [f64; K] {
        match self.stratified() {
            None => std::array::from_fn(|_| rng.random::<f64>()),
            Some(pattern) => std::array::from_fn(|j| pattern.position(j, u)),
        }
    }
}

/// The K selected indices into a sorted pool of `n` (duplicates possible).
pub fn select(pattern: SelectionPattern, n: usize, rng: &mut impl Rng) -> [usize; K] {
    let u = rng.random::<f64>();
    pattern.positions(u, rng).map(|pos| index_of(pos, n))
}

/// Exact expected selection count of every index of a pool of `n`: for the stratified
/// patterns each position sweeps its stratum of width 1/K uniformly as u sweeps [0, 1)
/// (density K there), so the measure of u mapping to each index is integrated in closed
/// form; uniform random is K/n by construction.
pub fn expected_counts(pattern: SelectionPattern, n: usize) -> Vec<f64> {
    let Some(stratified) = pattern.stratified() else {
        return vec![K as f64 / n as f64; n];
    };
    let mut counts = vec![0.0; n];
    for (low, high) in stratified.strata() {
        // The clamp below 1 only matters at pos = 1, a set of measure zero.
        for (i, count) in counts.iter_mut().enumerate() {
            let cell = (i as f64 / n as f64, (i + 1) as f64 / n as f64);
            let overlap = (high.min(cell.1) - low.max(cell.0)).max(0.0);
            // Density of the position is K on its stratum.
            *count += K as f64 * overlap;
        }
    }
    counts
}

/// Exact variance of the mean of the K values a pattern selects from `sorted_values`
/// (ascending, as the histogram sorts them). Uniform random picks are independent, so
/// it is the pool's variance over K; for the stratified patterns every position is
/// affine in the one number u ∈ [0, 1/K), so the selected values are constant between
/// the u at which some position crosses a cell boundary, and the variance is integrated
/// exactly piece by piece. This is the selection's share of a pixel's variance, the only
/// part a pattern can change. Panics on an empty pool.
pub fn variance_of_selected_mean(pattern: SelectionPattern, sorted_values: &[f64]) -> f64 {
    let n = sorted_values.len();
    assert!(n > 0, "an empty pool has no selection");
    if pattern == SelectionPattern::UniformRandom {
        let mean = sorted_values.iter().sum::<f64>() / n as f64;
        let pool_variance = sorted_values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n as f64;
        return pool_variance / K as f64;
    }
    // Breakpoints of u ∈ [0, 1) (the pattern scales it to [0, 1/K)) where a position
    // crosses a cell boundary i/n.
    let mut breaks = vec![0.0, 1.0];
    for i in 0..=n {
        let boundary = i as f64 / n as f64;
        for j in 0..K {
            // The u at which a position (j + u)/K or (j + 1 − u)/K meets the boundary.
            let offset = boundary * K as f64 - j as f64;
            for t in [offset, 1.0 - offset] {
                if t > 0.0 && t < 1.0 {
                    breaks.push(t);
                }
            }
        }
    }
    breaks.sort_by(f64::total_cmp);
    breaks.dedup();
    // Stratified patterns draw nothing from the generator.
    let mut rng = rand_pcg::Pcg64Mcg::new(0);
    let (mut first, mut second) = (0.0, 0.0);
    for pair in breaks.windows(2) {
        let share = pair[1] - pair[0];
        let u = 0.5 * (pair[0] + pair[1]);
        let selected = pattern.positions(u, &mut rng).map(|pos| sorted_values[index_of(pos, n)]);
        let mean = selected.iter().sum::<f64>() / K as f64;
        first += share * mean;
        second += share * mean * mean;
    }
    second - first * first
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn every_candidate_is_selected_k_over_n_times_on_average() {
        for pattern in SelectionPattern::ALL {
            for n in [1, 2, 3, 4, 5, 7, 16, 33, 100, 256] {
                let counts = expected_counts(pattern, n);
                let want = K as f64 / n as f64;
                for (i, c) in counts.iter().enumerate() {
                    assert!((c - want).abs() < 1e-12, "{pattern:?} n={n} index {i}: {c} != {want}");
                }
            }
        }
    }

    #[test]
    fn sampled_counts_agree_with_the_exact_ones() {
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(3);
        for pattern in SelectionPattern::ALL {
            let n = 7;
            let trials = 200_000;
            let mut counts = vec![0u32; n];
            for _ in 0..trials {
                for index in select(pattern, n, &mut rng) {
                    counts[index] += 1;
                }
            }
            for (i, &c) in counts.iter().enumerate() {
                let mean = f64::from(c) / trials as f64;
                // Counts per trial are at most K: standard error below K / sqrt(trials).
                assert!(
                    (mean - K as f64 / n as f64).abs() < 5.0 * K as f64 / (trials as f64).sqrt(),
                    "{pattern:?} {i}: {mean}"
                );
            }
        }
    }

    #[test]
    fn stratification_gains_little_when_bright_candidates_are_rare() {
        // A pool of n with m bright candidates (1) among dark ones (0), sorted: for
        // m/n = q ≤ 1/4 only the antithetic position 1 − u reaches the bright ones, with
        // probability 4q, so antithetic ÷ uniform = (1 − 4q) / (1 − q): about 1 − 3q.
        let n = 256;
        for m in [1, 4, 16, 64] {
            let pool: Vec<f64> = (0..n).map(|i| if i >= n - m { 1.0 } else { 0.0 }).collect();
            let q = m as f64 / n as f64;
            let uniform = variance_of_selected_mean(SelectionPattern::UniformRandom, &pool);
            let antithetic = variance_of_selected_mean(SelectionPattern::Antithetic, &pool);
            assert!((uniform - q * (1.0 - q) / K as f64).abs() < 1e-12);
            let ratio = antithetic / uniform;
            let want = (1.0 - 4.0 * q) / (1.0 - q);
            assert!((ratio - want).abs() < 1e-9, "m = {m}: {ratio} != {want}");
        }
        // Smooth pools, by contrast, lose most of their selection variance: the mirrored
        // pairs integrate a linear ramp exactly, and a quadratic one nearly.
        let ratio = |power: i32| {
            let pool: Vec<f64> = (0..n).map(|i| (i as f64 / n as f64).powi(power)).collect();
            variance_of_selected_mean(SelectionPattern::Antithetic, &pool)
                / variance_of_selected_mean(SelectionPattern::UniformRandom, &pool)
        };
        assert!(ratio(1) < 1e-12, "{}", ratio(1));
        assert!(ratio(2) < 0.05, "{}", ratio(2));
    }

    #[test]
    fn exact_selection_variance_agrees_with_sampling() {
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(11);
        let pool: Vec<f64> = (0..13).map(|i| f64::from(i * i % 7) + 0.25 * f64::from(i)).collect();
        let mut sorted = pool.clone();
        sorted.sort_by(f64::total_cmp);
        for pattern in SelectionPattern::ALL {
            let exact = variance_of_selected_mean(pattern, &sorted);
            let trials = 400_000;
            let (mut s1, mut s2) = (0.0, 0.0);
            for _ in 0..trials {
                let mean = select(pattern, sorted.len(), &mut rng).map(|i| sorted[i]).iter().sum::<f64>() / K as f64;
                s1 += mean;
                s2 += mean * mean;
            }
            let sampled = s2 / trials as f64 - (s1 / trials as f64).powi(2);
            assert!((sampled - exact).abs() < 0.02 * exact, "{pattern:?}: sampled {sampled}, exact {exact}");
        }
    }

    #[test]
    fn antithetic_positions_mirror_each_other() {
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(1);
        let p = SelectionPattern::Antithetic.positions(0.6, &mut rng);
        assert_eq!(p, [0.15, 0.35, 0.65, 0.85]);
        assert_eq!(select(SelectionPattern::Antithetic, 1, &mut rng), [0; K]);
    }
}
