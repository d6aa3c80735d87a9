//! The per-pixel blue-noise sampler (Heitz et al. 2019, `strata_kernels::selection`): values from
//! the tables by hand, stratification of each pixel's sequence, the blue-noise
//! distribution over the tile, and `sampler.wgsl` returning the same bits as the host.

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use strata_backends::backend::{download, upload};
use strata_backends::cpu_backend::{CpuBackend, CpuOptions};
use strata_backends::{Backend, Bind, gpu_required};
use strata_kernels::Kernel;
use strata_kernels::blue_noise::{BlueNoiseTables, SAMPLES, TILE_SIZE, WGSL_BUFFER_NAME};

/// [x, y, sample, dimension]; where the reference reads [ranking, sobol, scrambling]; what
/// it reads there and the ranked index [ranking, ranked, sobol, scrambling]; the stratum.
type HandCase = ([u32; 4], [usize; 3], [u32; 4], u32);

#[test]
fn sampler_matches_hand_computed_values() {
    let tables = BlueNoiseTables::new();
    // Entries looked up by hand in the crate's spp256.rs: ranking[dimension + pixel*8],
    // ranked = sample ^ ranking, sobol[dimension + ranked*256], scrambling[dimension % 8 +
    // pixel*8]; the stratum is sobol ^ scrambling and the sample (0.5 + stratum) / 256.
    #[rustfmt::skip]
    let cases: [HandCase; 5] = [
        // pixel 0: ranking[0] = 73, ranked 0 ^ 73 = 73, sobol[18688] = 173, scrambling[0] = 146.
        ([0, 0, 0, 0], [0, 18688, 0], [73, 73, 173, 146], 63),
        // pixel 5 + 7*128 = 901: ranking[7210] = 140, 3 ^ 140 = 143, sobol[36610] = 40,
        // scrambling[7210] = 27.
        ([5, 7, 3, 2], [7210, 36610, 7210], [140, 143, 40, 27], 51),
        // wraps to pixel (2, 3) = 386, sample 44: ranking[3089] = 18, 44 ^ 18 = 62,
        // sobol[15873] = 118, scrambling[3089] = 169.
        ([130, 3, 300, 1], [3089, 15873, 3089], [18, 62, 118, 169], 223),
        // dimension 9 reads the ranking of pixel 2 (the reference's indexing) and the
        // scrambling of dimension 1: ranking[17] = 188, 17 ^ 188 = 173, sobol[44297] = 76,
        // scrambling[9] = 86.
        ([1, 0, 17, 9], [17, 44297, 9], [188, 173, 76, 86], 26),
        // last pixel, dimension 255: the reference's ranking index 131319 wraps to 247:
        // ranking[247] = 155, 255 ^ 155 = 100, sobol[25855] = 241, scrambling[131071] = 14.
        ([127, 127, 255, 255], [247, 25855, 131071], [155, 100, 241, 14], 255),
    ];
    for ([x, y, s, d], [ranking_at, sobol_at, scrambling_at], [ranking, ranked, sobol, scrambling], stratum) in cases {
        assert_eq!(tables.ranking[ranking_at], ranking, "ranking[{ranking_at}]");
        assert_eq!((s % 256) ^ ranking, ranked);
        assert_eq!(tables.sobol[sobol_at], sobol, "sobol[{sobol_at}]");
        assert_eq!(tables.scrambling[scrambling_at], scrambling, "scrambling[{scrambling_at}]");
        assert_eq!(sobol ^ scrambling, stratum);
        assert_eq!(tables.stratum(x, y, s, d), stratum, "({x}, {y}, {s}, {d})");
        assert_eq!(tables.sample(x, y, s, d), (0.5 + stratum as f32) / 256.0, "({x}, {y}, {s}, {d})");
    }
    assert_eq!(tables.sample(0, 0, 0, 0), 0.248_046_88);
}

/// Strata of dimensions 0 and 1 of one pixel over its 256 sample indices.
fn pixel_pairs(tables: &BlueNoiseTables, x: u32, y: u32) -> Vec<(u32, u32)> {
    (0..SAMPLES).map(|s| (tables.stratum(x, y, s, 0), tables.stratum(x, y, s, 1))).collect()
}

/// Whether `points` (strata in 0..256 per axis), 2^m of them, form a (0, m, 2)-net in base
/// 2: every elementary interval 2^-i × 2^-(m-i) holds exactly one point.
fn is_net(points: &[(u32, u32)], m: u32) -> bool {
    assert_eq!(points.len(), 1 << m);
    (0..=m).all(|i| {
        let mut seen = vec![false; 1 << m];
        points.iter().all(|&(a, b)| {
            let cell = (((a >> (8 - i)) << (m - i)) | (b >> (8 - (m - i)))) as usize;
            !std::mem::replace(&mut seen[cell], true)
        })
    })
}

#[test]
fn each_pixel_sequence_is_stratified() {
    let tables = BlueNoiseTables::new();
    for y in 0..TILE_SIZE {
        for x in 0..TILE_SIZE {
            // Every dimension over the 256 samples: each stratum (0.5 + k) / 256 once.
            for dimension in 0..8 {
                let mut seen = [false; 256];
                for s in 0..SAMPLES {
                    let k = tables.stratum(x, y, s, dimension) as usize;
                    assert!(!seen[k], "pixel ({x}, {y}) dimension {dimension}: stratum {k} twice");
                    seen[k] = true;
                }
            }
            // Dimensions (0, 1): a (0, 8, 2)-net, i.e. one point in each of the 256 cells
            // of every grid 2^i × 2^(8-i) (16 × 16 included).
            assert!(is_net(&pixel_pairs(&tables, x, y), 8), "pixel ({x}, {y}): (0, 1) is not a (0, 8, 2)-net");
        }
    }
}

#[test]
fn every_aligned_run_of_frames_is_a_net() {
    // The ranking XORs the sample index, so 2^m consecutive sample indices starting at a
    // multiple of 2^m are an aligned block of the Sobol sequence: frames 4f..4f+3 cover
    // 4 strata of dimension 0, 16 frames a 4 × 4 grid of (0, 1), and so on. A sub-tile of
    // pixels (the property is per pixel; every pixel is checked at m = 8 above).
    let tables = BlueNoiseTables::new();
    for y in (0..TILE_SIZE).step_by(3) {
        for x in (0..TILE_SIZE).step_by(5) {
            let pairs = pixel_pairs(&tables, x, y);
            for m in 0..=8 {
                for block in pairs.chunks_exact(1 << m) {
                    assert!(is_net(block, m), "pixel ({x}, {y}): 2^{m} samples from {:?}", block[0]);
                }
            }
        }
    }
}

#[test]
fn dimensions_two_and_three_are_not_a_net() {
    // Only (0, 1) of the Sobol table forms a (0, 2)-sequence: record that the pairs
    // (2, 3) etc. are optimised for blue noise but are not (0, 8, 2)-nets, so selection
    // and resampling must use (0, 1).
    let tables = BlueNoiseTables::new();
    let pairs: Vec<(u32, u32)> =
        (0..SAMPLES).map(|s| (tables.stratum(9, 4, s, 2), tables.stratum(9, 4, s, 3))).collect();
    assert!(!is_net(&pairs, 8));
}

/// Variance of the means of the 8×8 blocks of a 128² image, divided by its value for
/// i.i.d. uniform values (1/12/64).
fn box_variance_ratio(image: &[f32]) -> f64 {
    const BOX: usize = 8;
    let side = TILE_SIZE as usize;
    let means: Vec<f64> = (0..(side / BOX) * (side / BOX))
        .map(|b| {
            let (bx, by) = (b % (side / BOX) * BOX, b / (side / BOX) * BOX);
            let sum: f64 = (0..BOX * BOX).map(|i| f64::from(image[(by + i / BOX) * side + bx + i % BOX])).sum::<f64>();
            sum / (BOX * BOX) as f64
        })
        .collect();
    let mean = means.iter().sum::<f64>() / means.len() as f64;
    let variance = means.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / means.len() as f64;
    variance / (1.0 / 12.0 / (BOX * BOX) as f64)
}

#[test]
fn a_frame_over_the_tile_is_blue_noise() {
    // At a fixed sample index the tile's values have little low-frequency energy: the
    // 8×8 box averages vary far less than for white noise (ratio 1). Measured over all
    // 256 sample indices (mean, min, max): dimension 0 0.149, 0.119, 0.179; dimension 1
    // 0.358, 0.135, 0.587 (the tables optimise the pair (0, 1) jointly, and the second
    // coordinate's own projection less); dimensions 2–7 alike (even 0.15–0.21, odd
    // 0.36–0.41); dimension 8, not optimised, 0.914, 0.865, 0.964, about white.
    let tables = BlueNoiseTables::new();
    let side = TILE_SIZE;
    // (dimension, bound on the mean ratio, bound on the largest) or, for dimension 8, a
    // lower bound on the mean: it is not blue noise.
    for (dimension, mean_bound, max_bound) in [(0, 0.2, 0.25), (1, 0.45, 0.7), (8, 0.75, f64::INFINITY)] {
        let ratios: Vec<f64> = (0..SAMPLES)
            .map(|s| {
                let image: Vec<f32> =
                    (0..side * side).map(|p| tables.sample(p % side, p / side, s, dimension)).collect();
                box_variance_ratio(&image)
            })
            .collect();
        let mean = ratios.iter().sum::<f64>() / ratios.len() as f64;
        let max = ratios.iter().copied().fold(0.0, f64::max);
        let min = ratios.iter().copied().fold(f64::INFINITY, f64::min);
        println!(
            "dimension {dimension}: 8x8 box-mean variance / white noise's: mean {mean:.3}, min {min:.3}, max {max:.3}"
        );
        if dimension < 8 {
            assert!(mean < mean_bound && max < max_bound, "dimension {dimension}: mean {mean}, max {max}");
        } else {
            assert!(mean > mean_bound, "dimension {dimension}: mean {mean}");
        }
    }
    // The same statistic on white noise, to show it separates the two.
    let mut rng = Pcg64Mcg::seed_from_u64(6);
    let white: Vec<f64> = (0..16)
        .map(|_| box_variance_ratio(&(0..side * side).map(|_| rng.random::<f32>()).collect::<Vec<_>>()))
        .collect();
    let white_mean = white.iter().sum::<f64>() / white.len() as f64;
    println!("white noise: mean ratio {white_mean:.3} over {} images", white.len());
    assert!((0.8..1.2).contains(&white_mean), "white noise ratio {white_mean}");
    assert!(white.iter().all(|&r| r > 0.5), "{white:?}");
}

const TEST_ENTRY: &str = r#"
@group(0) @binding(0) var<storage, read> blue_noise: array<u32>;
// (pixel x, pixel y, sample index, dimension) per invocation.
@group(0) @binding(1) var<storage, read> queries: array<vec4<u32>>;
@group(0) @binding(2) var<storage, read_write> samples: array<u32>;

@compute @workgroup_size(64)
fn sampler_test(@builtin(global_invocation_id) id: vec3<u32>) {
    let q = queries[id.x];
    samples[id.x] = bitcast<u32>(blue_noise_sample(q.xy, q.z, q.w));
}
"#;

/// Pixels, sample indices and dimensions around every wrap and table edge: 4096 queries.
fn queries() -> Vec<[u32; 4]> {
    let pixels = [0, 1, 63, 126, 127, 128, 200, 4095];
    let samples = [0, 1, 2, 77, 255, 256, 300, 1_000_003];
    let dimensions = [0, 1, 2, 7, 8, 9, 255, 256];
    let mut queries = Vec::new();
    for &x in &pixels {
        for &y in &pixels {
            for &s in &samples {
                for &d in &dimensions {
                    queries.push([x, y, s, d]);
                }
            }
        }
    }
    queries
}

/// Runs `strata/blue_noise.wgsl` (after the host) on `backend` and compares the bits.
fn wgsl_matches_host(backend: &mut dyn Backend) {
    // The file with what it imports (the table offsets of gpu/blue_noise.wgsl).
    let include = strata_kernels::wgsl_files::with_imports("strata/blue_noise.wgsl").unwrap_or_else(|e| panic!("{e}"));
    let kernel = Kernel::from_wgsl("sampler_test.wgsl", format!("{include}\n{TEST_ENTRY}"), "sampler_test", false)
        .unwrap_or_else(|e| panic!("{e}"));
    let tables = BlueNoiseTables::new();
    let queries = queries();
    assert_eq!(kernel.binding(0, 0).map(|b| b.name.as_str()), Some(WGSL_BUFFER_NAME));
    let mut bound = vec![upload(backend, WGSL_BUFFER_NAME, &tables.packed()).unwrap()];
    bound.push(upload(backend, "queries", &queries).unwrap());
    let output = upload(backend, "samples", &vec![strata_tests::POISON; queries.len()]).unwrap();
    bound.push(output);
    let binds: Vec<Bind> = bound.iter().enumerate().map(|(i, &b)| Bind::new(i as u32, b)).collect();
    backend.dispatch(&kernel, &binds, [queries.len() as u32 / 64, 1, 1]).unwrap();
    let got: Vec<u32> = download(backend, output).unwrap();
    for buffer in bound {
        backend.destroy_buffer(buffer).unwrap();
    }
    assert_eq!(got.len(), queries.len());
    for (&[x, y, s, d], bits) in queries.iter().zip(got) {
        let want = tables.sample(x, y, s, d);
        assert_eq!(bits, want.to_bits(), "({x}, {y}, {s}, {d}): WGSL {}, host {want}", f32::from_bits(bits));
    }
}

#[test]
fn wgsl_sampler_matches_the_host_on_the_interpreter() {
    wgsl_matches_host(&mut CpuBackend::new(CpuOptions::default()).unwrap());
}

#[test]
fn wgsl_sampler_matches_the_host_on_vulkan() {
    let Some(mut backend) = strata_tests::vulkan_backend("wgsl_sampler_matches_the_host_on_vulkan") else {
        assert!(!gpu_required());
        return;
    };
    wgsl_matches_host(&mut backend);
}
