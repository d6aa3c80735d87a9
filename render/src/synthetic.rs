//! Generated candidate images for tests, benchmarks and the `strata histogram` command:
//! object regions with many equal keys, plus every kind of awkward value.

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use strata_kernels::types::{Candidate, OBJECT_ID_ENVIRONMENT, OBJECT_ID_NONE};

/// What a generated image contains.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CandidateMix {
    /// Distinct object ids (besides environment and none).
    pub objects: u32,
    /// Distinct key values per object: small numbers give many equal keys.
    pub key_levels: u32,
    /// Share of pixels with awkward values: NaN, ±Inf, negative, -0, denormal keys,
    /// environment misses and pixels without a candidate.
    pub awkward: f64,
}

impl Default for CandidateMix {
    fn default() -> Self {
        Self { objects: 6, key_levels: 16, awkward: 0.05 }
    }
}

/// A `width × height` candidate image from `seed`. Objects occupy noisy rectangular
/// regions so that blocks hold one to a few clusters, as a rendered image does.
pub fn candidate_image(width: u32, height: u32, seed: u64, mix: CandidateMix) -> Vec<Candidate> {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let objects = mix.objects.max(1);
    let cell = rng.random_range(3..=24u32);
    let offsets: Vec<u32> = (0..8).map(|_| rng.random_range(0..objects)).collect();
    let mut image = Vec::with_capacity(width as usize * height as usize);
    for y in 0..height {
        for x in 0..width {
            let region = (x / cell + 3 * (y / cell)) as usize % offsets.len();
            // Object k gets id (7919 k + 13) mod 1,000,003 (spread over the id range;
            // in 64 bits, so that any `objects` is taken).
            let id_of = |object: u32, offset: u64| ((u64::from(object) * 7919 + offset) % 1_000_003) as u32;
            let mut object_id = id_of(offsets[region], 13);
            if rng.random_bool(0.1) {
                object_id = id_of(rng.random_range(0..objects), 0);
            }
            let level = rng.random_range(0..mix.key_levels.max(1));
            let mut key = level as f32 * 0.25;
            if rng.random_bool(mix.awkward.clamp(0.0, 1.0)) {
                match rng.random_range(0..9) {
                    0 => key = f32::NAN,
                    1 => key = f32::INFINITY,
                    2 => key = f32::NEG_INFINITY,
                    3 => key = -rng.random_range(0.0..4.0f32) - f32::MIN_POSITIVE,
                    4 => key = -0.0,
                    5 => key = f32::from_bits(rng.random_range(1..0x0080_0000)),
                    6 => object_id = OBJECT_ID_ENVIRONMENT,
                    7 => object_id = OBJECT_ID_NONE,
                    _ => key = f32::from_bits(0x7fc0_0000 | rng.random_range(1..0x0040_0000)),
                }
            }
            image.push(Candidate { key, object_id });
        }
    }
    image
}

/// `count` random triangles in the cube [-1, 1]³ (sizes from tiny to a third of the
/// cube, some sharing edges and vertices, some coplanar), for BVH tests.
pub fn triangle_soup(count: usize, seed: u64) -> Vec<[[f32; 3]; 3]> {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let mut triangles: Vec<[[f32; 3]; 3]> = Vec::with_capacity(count);
    for i in 0..count {
        let size = 10f32.powf(rng.random_range(-2.5..-0.5));
        let center: [f32; 3] = [rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0)];
        let mut vertex = || center.map(|c| c + rng.random_range(-size..size));
        let mut triangle = [vertex(), vertex(), vertex()];
        // Every eighth triangle shares an edge with the previous one.
        if i % 8 == 7 {
            let previous = triangles[i - 1];
            triangle[0] = previous[1];
            triangle[1] = previous[0];
        }
        // Every sixteenth lies in the plane z = 0.25.
        if i % 16 == 5 {
            for v in &mut triangle {
                v[2] = 0.25;
            }
        }
        triangles.push(triangle);
    }
    triangles
}

/// `count` rays from points around the cube towards points inside it, with some
/// axis-aligned directions (zero components) among them.
pub fn rays_into_cube(count: usize, seed: u64) -> Vec<strata_kernels::trace_types::Ray> {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    (0..count)
        .map(|i| {
            let origin: [f32; 3] =
                [rng.random_range(-3.0..3.0), rng.random_range(-3.0..3.0), rng.random_range(-3.0..3.0)];
            let target: [f32; 3] =
                [rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0)];
            let mut direction = [target[0] - origin[0], target[1] - origin[1], target[2] - origin[2]];
            if i % 10 == 3 {
                direction = [0.0, 0.0, if origin[2] > 0.0 { -1.0 } else { 1.0 }];
            }
            strata_kernels::trace_types::Ray { origin, tmin: 1e-4, direction, tmax: 100.0 }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn images_contain_every_awkward_kind_and_equal_keys() {
        let image = candidate_image(128, 128, 7, CandidateMix { awkward: 0.2, ..Default::default() });
        assert!(image.iter().any(|c| c.key.is_nan()));
        assert!(image.iter().any(|c| c.key == f32::INFINITY));
        assert!(image.iter().any(|c| c.key == f32::NEG_INFINITY));
        assert!(image.iter().any(|c| c.key.is_subnormal()));
        assert!(image.iter().any(|c| c.key == 0.0 && c.key.is_sign_negative()));
        assert!(image.iter().any(|c| c.object_id == OBJECT_ID_NONE));
        assert!(image.iter().any(|c| c.object_id == OBJECT_ID_ENVIRONMENT));
        let equal = image.iter().filter(|c| c.key == 1.0).count();
        assert!(equal > 100, "{equal}");
        let again = candidate_image(128, 128, 7, CandidateMix { awkward: 0.2, ..Default::default() });
        let bits = |image: &[Candidate]| image.iter().map(|c| (c.key.to_bits(), c.object_id)).collect::<Vec<_>>();
        assert_eq!(bits(&image), bits(&again), "the same seed gives the same image");
    }
}
