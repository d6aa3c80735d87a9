//! The 1-D RIS experiment: a known integral, a pool of n candidates, K = 4 selected by
//! each pattern, one resampled; the mean must be the integral and the variances rank
//! the patterns.

use super::patterns::{K, SelectionPattern, select};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

/// Integrand f, source pdf p on [0, 1] and target p̂ of the experiment.
#[derive(Clone, Copy, Debug)]
pub struct OneDimensionalProblem {
    /// Candidates per pool.
    pub pool: usize,
    /// A deliberate bug for the tests: normalise by the number of *distinct* selected
    /// candidates instead of K, a weight that depends on which subset was drawn.
    pub subset_dependent_normalisation: bool,
}

impl OneDimensionalProblem {
    /// f(x) = 3x² + 0.5·sin(6πx)², ∫₀¹ f = 1 + 0.25.
    pub fn f(x: f64) -> f64 {
        3.0 * x * x + 0.5 * (6.0 * std::f64::consts::PI * x).sin().powi(2)
    }
    /// The exact integral of f over [0, 1].
    pub const INTEGRAL: f64 = 1.25;
    /// Source pdf: p(x) = 0.5 + x (a mild ramp; x sampled by inversion).
    pub fn p(x: f64) -> f64 {
        0.5 + x
    }
    fn sample(u: f64) -> f64 {
        // CDF(x) = 0.5x + 0.5x² = u  →  x = -0.5 + sqrt(0.25 + 2u).
        -0.5 + (0.25 + 2.0 * u).sqrt()
    }
    /// Target function: an approximation of f (positive wherever f is).
    pub fn target(x: f64) -> f64 {
        3.0 * x * x + 0.25
    }

    /// One estimate: a fresh pool, sorted by key f/p, K selected by `pattern`, one
    /// resampled with weights p̂/p, Y = f(x_s)/p̂(x_s) · (1/K) Σ w.
    pub fn estimate(&self, pattern: SelectionPattern, rng: &mut impl Rng) -> f64 {
        let mut pool: Vec<(f64, f64)> = (0..self.pool)
            .map(|_| {
                let x = Self::sample(rng.random());
                (Self::f(x) / Self::p(x), x)
            })
            .collect();
        pool.sort_by(|a, b| a.0.total_cmp(&b.0));
        let selected = select(pattern, self.pool, rng).map(|i| pool[i].1);
        let weights = selected.map(|x| Self::target(x) / Self::p(x));
        let total: f64 = weights.iter().sum();
        let mut pick = rng.random::<f64>() * total;
        let mut chosen = selected[K - 1];
        for (x, w) in selected.iter().zip(weights) {
            if pick < w {
                chosen = *x;
                break;
            }
            pick -= w;
        }
        let normalisation = if self.subset_dependent_normalisation {
            let mut indices = selected;
            indices.sort_by(f64::total_cmp);
            1 + indices.windows(2).filter(|w| w[0] != w[1]).count()
        } else {
            K
        };
        Self::f(chosen) / Self::target(chosen) * total / normalisation as f64
    }
}

/// Mean and variance of many independent estimates.
#[derive(Clone, Copy, Debug)]
pub struct Estimate {
    /// Sample mean.
    pub mean: f64,
    /// Sample variance of one estimate.
    pub variance: f64,
    /// Estimates averaged.
    pub count: usize,
}

impl Estimate {
    /// Half-width of the confidence interval of the mean at `z` standard errors.
    pub fn half_width(&self, z: f64) -> f64 {
        z * (self.variance / self.count as f64).sqrt()
    }
}

/// `count` independent estimates with `pattern` from `seed`.
pub fn run_estimates(problem: OneDimensionalProblem, pattern: SelectionPattern, count: usize, seed: u64) -> Estimate {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let (mut sum, mut sum_sq) = (0.0, 0.0);
    for _ in 0..count {
        let y = problem.estimate(pattern, &mut rng);
        sum += y;
        sum_sq += y * y;
    }
    let mean = sum / count as f64;
    Estimate { mean, variance: (sum_sq / count as f64 - mean * mean) * count as f64 / (count - 1) as f64, count }
}
