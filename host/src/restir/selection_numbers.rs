//! The numbers each pixel's selection and resampling use in one frame, by sampler
//! variant (the paper's Table 2, [`SamplerVariant`]).
//!
//! Per pixel three `[f32; 4]`: the K spatial selection positions in [0, 1); the spatial
//! resampling number in `.0` and the temporal one in `.1`; the T temporal selection
//! positions (multiple temporal reservoirs, Fig. 11). Blue-noise values come from
//! [`BlueNoiseTables`] at sample index frame mod 256: dimensions 0 and 1 (the first
//! optimised pair) for the spatial selection and resampling, 2 and 3 (the second pair)
//! for the temporal ones. The temporal pattern of the antithetic variant is Fig. 3's for
//! T = 4, {v, 1 − v} with v in [0, ½) for T = 2, and the random offset otherwise.
//!
//! Unbiasedness needs every position to be uniform on [0, 1) over independent renders:
//! the blue-noise strata (k + 0.5)/256 are replaced by (k + ξ)/256 with ξ white per pixel
//! and frame, and every value is shifted by one offset per render seed (a toroidal
//! shift of all pixels and frames together). Neither changes the stratification across
//! frames nor the blue-noise distribution across pixels.

use super::RestirSettings;
use crate::sampler::{BlueNoiseTables, SamplerVariant};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg32;

/// Three `[f32; 4]` per pixel, row-major (see the module docs).
pub fn selection_numbers(
    tables: &BlueNoiseTables,
    settings: &RestirSettings,
    width: u32,
    height: u32,
    frame: u32,
    seed: u32,
) -> Vec<[f32; 4]> {
    let k = settings.candidates.clamp(1, 4) as usize;
    let t = settings.temporal_candidates.clamp(1, 4) as usize;
    let mut render_rng = Pcg32::seed_from_u64(u64::from(seed) ^ 0x5eed_0ff5e7);
    let shift: [f64; 4] = std::array::from_fn(|_| render_rng.random());
    let mut rng = Pcg32::seed_from_u64((u64::from(seed) << 32) ^ u64::from(frame).wrapping_mul(0x9e37_79b9_7f4a_7c15));
    let sample_index = frame % 256;
    let mut numbers = Vec::with_capacity(3 * (width * height) as usize);
    for y in 0..height {
        for x in 0..width {
            let blue = |rng: &mut Pcg32, index: u32, dimension: u32| -> f64 {
                let stratum = f64::from(tables.stratum(x, y, index, dimension));
                let value = (stratum + rng.random::<f64>()) / 256.0 + shift[dimension as usize & 3];
                value.fract()
            };
            // Positions and resampling number of `count` slots from sampler dimensions
            // (first, first + 1).
            let mut pattern = |count: usize, first: u32| -> ([f64; 4], f64) {
                let offsets = |u: f64| std::array::from_fn(|j| (u + j as f64) / count as f64);
                let rng = &mut rng;
                match settings.sampler {
                    SamplerVariant::Antithetic if count == 4 => {
                        let u = blue(rng, sample_index, first) / 4.0;
                        ([u, 0.5 - u, 0.5 + u, 1.0 - u], blue(rng, sample_index, first + 1))
                    }
                    SamplerVariant::Antithetic if count == 2 => {
                        let v = blue(rng, sample_index, first) / 2.0;
                        ([v, 1.0 - v, 0.0, 0.0], blue(rng, sample_index, first + 1))
                    }
                    SamplerVariant::Antithetic | SamplerVariant::RandomOffsetBlueNoise => {
                        let u = blue(rng, sample_index, first);
                        (offsets(u), blue(rng, sample_index, first + 1))
                    }
                    SamplerVariant::Heitz => {
                        let positions = std::array::from_fn(|j| blue(rng, (4 * frame + j as u32) % 256, first));
                        (positions, blue(rng, (4 * frame) % 256, first + 1))
                    }
                    SamplerVariant::RandomOffset => (offsets(rng.random()), rng.random()),
                    SamplerVariant::Random => (std::array::from_fn(|_| rng.random()), rng.random()),
                }
            };
            let (positions, resample) = pattern(k, 0);
            let (temporal_positions, temporal_resample) = pattern(t, 2);
            // Positions stay below 1 in f32 (1 - u rounds to 1 for tiny u).
            let clamp = |v: f64| (v as f32).clamp(0.0, 1.0 - f32::EPSILON / 2.0);
            numbers.push(positions.map(clamp));
            numbers.push([clamp(resample), clamp(temporal_resample), 0.0, 0.0]);
            numbers.push(temporal_positions.map(clamp));
        }
    }
    numbers
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Over many renders (seeds), the K selection positions together are uniform on
    /// [0, 1) (each stratified pattern puts one position in each quarter, uniform there;
    /// the independent ones are each uniform), which is what gives every member of a run
    /// the expected selection count K/n; and the resampling number is uniform.
    #[test]
    fn positions_are_uniform_over_renders() {
        let tables = BlueNoiseTables::new();
        for sampler in [
            SamplerVariant::Antithetic,
            SamplerVariant::RandomOffsetBlueNoise,
            SamplerVariant::Heitz,
            SamplerVariant::RandomOffset,
            SamplerVariant::Random,
        ] {
            let settings = RestirSettings { sampler, temporal_candidates: 4, ..Default::default() };
            let bins = 8;
            let mut positions = vec![0u32; bins];
            let mut resample = vec![0u32; bins];
            let renders = 4000;
            for seed in 0..renders {
                let numbers = selection_numbers(&tables, &settings, 1, 1, 3, seed);
                for &v in numbers[0].iter().chain(&numbers[2]) {
                    assert!((0.0..1.0).contains(&v), "{sampler:?}: {v}");
                    positions[(v * bins as f32) as usize] += 1;
                }
                resample[(numbers[1][0] * bins as f32) as usize] += 1;
                resample[(numbers[1][1] * bins as f32) as usize] += 1;
            }
            for (counts, draws) in [(&positions, 8 * renders), (&resample, 2 * renders)] {
                let expected = f64::from(draws) / bins as f64;
                // 6 sigma of a binomial count (an upper bound for the stratified ones).
                let sigma = (expected * (1.0 - 1.0 / bins as f64)).sqrt();
                for (bin, &count) in counts.iter().enumerate() {
                    assert!(
                        (f64::from(count) - expected).abs() < 6.0 * sigma,
                        "{sampler:?} bin {bin}: {count} vs {expected}"
                    );
                }
            }
        }
    }

    /// The antithetic positions of one frame are the pattern of Fig. 3.
    #[test]
    fn antithetic_positions_mirror() {
        let tables = BlueNoiseTables::new();
        let numbers = selection_numbers(&tables, &RestirSettings::default(), 4, 4, 0, 1);
        for pixel in numbers.chunks_exact(3) {
            let [a, b, c, d] = pixel[0];
            assert!(a < 0.25 && (a + b - 0.5).abs() < 1e-6 && (c - 0.5 - a).abs() < 1e-6 && (d + a - 1.0).abs() < 1e-6);
        }
    }
}
