//! ReSTIR (issue 6) is unbiased: for every method, the mean of many independent frames
//! converges to the path-traced reference within its confidence interval.
//!
//! Frames without temporal reuse are independent given their seeds (each frame draws
//! new paths and, over seeds, uniform selection numbers), so the frame images are i.i.d.
//! estimates of the pixel integrals. Both the ReSTIR mean and the path-traced reference
//! are averaged over 8 x 8 pixel regions; each region's difference is divided by its
//! standard error (both estimates' frame-to-frame spread). With temporal reuse frames are
//! correlated, so independent renders (seeds) are averaged instead, each scored by the
//! mean of its frames from [`FIRST_SCORED_FRAME`] on (see there).
//!
//! Each test states its power: the smallest bias of the whole image that its pooled test
//! catches with probability 0.99 ([`detectable_bias`]), asserted against the bound the
//! test was designed for, so that a change that costs power fails here.
//!
//! Needs Vulkan (skips without it unless `STRATA_REQUIRE_GPU=1`).

use std::sync::OnceLock;

use strata_backends::{Backend, gpu_required};
use strata_kernels::selection::{SamplerVariant, SelectionSettings};
use strata_render::render::{Film, GpuScene, PathTracer, RenderSettings};
use strata_render::restir::{Method, RestirRenderer, RestirSettings, ReuseOrder, ShadedParts, Shading};
use strata_render::rgb_image::RgbImage;
use strata_render::scene::{Camera, CameraPath, Scene, default_scene};

const SIZE: u32 = 32;
const REGION: u32 = 8;

/// With temporal reuse a render is scored by the mean of its frames from this one on (the
/// first with history merged twice: the own reservoir's cap of 2 and the temporal-first
/// order's cap of 20 bind from frame 3; in the spatial-first order the merged M grows by
/// one a frame and the cap binds only near frame 20, beyond every test here), not by its last
/// frame alone. Over 96 renders of the default room the image total of frames 3..6
/// averaged spread 0.18-0.20 times as much (variance) as frame 6 alone, frames 3..8
/// 0.09-0.11 times (own reservoir at cap 2, four drawn, the defaults): successive frames
/// barely correlate (new paths every frame; the stratified film's successive points are
/// even negatively correlated), so 8 scored frames of 64 renders test the history's
/// steady state with the power 512 renders' frame 6 had, at a sixth of the frames. A bias
/// that only the 6th frame and no later one had would be diluted; the merge is the same
/// from frame 3 on.
const FIRST_SCORED_FRAME: u32 = 3;

/// Independent renders per temporal test: the z scores use the renders' own spread, with
/// 63 degrees of freedom here, so that the thresholds below (set for a normal z) still
/// hold: |t₆₃| > 4.5 has probability 3e-5 (7e-6 for a normal z). Fewer renders widen the
/// tails faster than they save time.
const TEMPORAL_RENDERS: std::ops::Range<u32> = 1..65;

/// Frames of restir's temporal renders held to the reference at [`TEMPORAL_RENDERS`]
/// renders (the own reservoir, both reuse orders, the mirror-floor room), scored 3-5.
/// Six frames resolved 2.99-4.04 % against stated bounds of 5.8-7.7 %; five resolve
/// 3.92-4.83 % (0.63-0.69 of each bound; docs/benchmarks/ci-time.md "Fewer frames where
/// the power allows") for a sixth fewer frames.
const BASE_TEMPORAL_FRAMES: u32 = 5;

/// Frames of each variant paired with restir over four drawn temporal reservoirs, scored
/// 3-6. Scored 3-4 they resolved as finely (1.35-1.58 % against 1.23-1.53 %, stated 2.0 %)
/// but missed a bias that grows with the history: strata's canonical weight in
/// `restir_spatial` 3 % too large gave pooled z 3.97 over frames 3-4 and 5.08 over 3-6.
const DRAWN_PAIRED_FRAMES: u32 = 6;

// The tests' stated power: the smallest bias of the whole image, relative to its total,
// that each catches with probability 0.99 ([`detectable_bias`]). Each is what the test
// measured before its renders were scored as above (2026-11-28, BENCHMARKS.md "The
// statistical tests' power"), rounded up; the tests now measure 0.5-0.8 times as much.
/// Without temporal reuse, 8 renders of 64 frames (unchanged).
const POWER_ACCUMULATED: f64 = 0.034;
/// A method or shading paired with restir's expectation frame by frame, without temporal
/// reuse ([`assert_same_mean_with_power`]): a bias one has and the other lacks, relative
/// to the reference image (each method alone against the reference took 8 renders of 64
/// frames and resolved 2.8 %, 5.0 % in the mirror-floor room with 32).
const POWER_PAIRED: f64 = 0.010;
/// A method paired with restir with temporal reuse ([`temporal_pairs`]): a bias one has and
/// restir lacks, relative to the reference image. Each method alone against the reference
/// resolved 3.0-7.7 % (the unpaired tests' bounds below); the pairs measured 0.4-1.5 %.
const POWER_TEMPORAL_PAIRED: f64 = 0.020;
/// The seeds of paired runs: 2 renders of 32 frames, 64 differences.
const PAIRED_SEEDS: std::ops::Range<u32> = 1..3;
/// The own temporal reservoir alone at cap 2 (128 renders' frame 6 before).
const POWER_TEMPORAL_OWN: f64 = 0.058;
/// The own and four drawn temporal reservoirs (512 renders' frame 6 before).
const POWER_TEMPORAL_DRAWN: f64 = 0.030;
/// Both reuse orders (128 renders' frame 6 before).
const POWER_REUSE_ORDER: f64 = 0.058;
/// The glass/metal/environment room without temporal reuse, held to the reference (8
/// renders of 32 frames, unchanged).
const POWER_GLASS: f64 = 0.017;
/// A method paired with restir in the glass/metal/environment room without temporal
/// reuse ([`GLASS_PARTNERS`]): measured 0.63-0.83 % (2 renders of 32 frames), where each
/// ran 8 of 32 against the reference at [`POWER_GLASS`] before.
const POWER_GLASS_PAIRED: f64 = 0.012;
/// The glass/metal/environment room with temporal reuse (96 renders' frame 6 before).
const POWER_GLASS_TEMPORAL: f64 = 0.028;
/// The mirror-floor room without temporal reuse (8 renders of 32 frames, unchanged).
const POWER_SHORT_PATHS: f64 = 0.060;
/// The mirror-floor room with temporal reuse (96 renders' frame 6 before).
const POWER_SHORT_PATHS_TEMPORAL: f64 = 0.077;
/// The white film with temporal reuse (128 renders' frame 6 before).
const POWER_FILM_TEMPORAL: f64 = 0.052;
/// The orbiting camera (128 renders' frame 6 before).
const POWER_MOVING_CAMERA: f64 = 0.061;

/// Per region and channel: the running sum and sum of squares of region means; and of
/// each estimate's total over every region and channel (for the pooled test, whose
/// terms are correlated: the three channels of a region move together).
#[derive(Clone)]
struct RegionStats {
    sum: Vec<f64>,
    squares: Vec<f64>,
    total_sum: f64,
    total_squares: f64,
    count: f64,
}

impl RegionStats {
    fn new() -> Self {
        let n = ((SIZE / REGION) * (SIZE / REGION) * 3) as usize;
        RegionStats { sum: vec![0.0; n], squares: vec![0.0; n], total_sum: 0.0, total_squares: 0.0, count: 0.0 }
    }

    /// Statistics of a difference whose every estimate is exactly 0: a reference that
    /// [`z_scores`] and [`pooled_z`] test a difference against.
    fn zero() -> Self {
        RegionStats { count: 2.0, ..RegionStats::new() }
    }

    /// The mean of each region and channel of `image`.
    fn region_means(image: &RgbImage) -> Vec<f64> {
        let regions = SIZE / REGION;
        let mut means = vec![0.0f64; ((SIZE / REGION) * (SIZE / REGION) * 3) as usize];
        for y in 0..SIZE {
            for x in 0..SIZE {
                let p = image.pixels[(y * SIZE + x) as usize];
                let r = ((y / REGION) * regions + x / REGION) as usize;
                for c in 0..3 {
                    means[r * 3 + c] += f64::from(p[c]) / f64::from(REGION * REGION);
                }
            }
        }
        means
    }

    fn add(&mut self, image: &RgbImage) {
        self.add_means(&Self::region_means(image));
    }

    /// One estimate of the difference `image - base`, region by region.
    fn add_difference(&mut self, image: &RgbImage, base: &RgbImage) {
        let means: Vec<f64> =
            Self::region_means(image).iter().zip(Self::region_means(base)).map(|(a, b)| a - b).collect();
        self.add_means(&means);
    }

    fn add_means(&mut self, means: &[f64]) {
        for (i, m) in means.iter().enumerate() {
            self.sum[i] += m;
            self.squares[i] += m * m;
        }
        let total: f64 = means.iter().sum();
        self.total_sum += total;
        self.total_squares += total * total;
        self.count += 1.0;
    }

    /// The estimates of `self` and `other` together (two runs of the same setting over
    /// different seeds).
    fn merged(mut self, other: &RegionStats) -> Self {
        for (mine, theirs) in self.sum.iter_mut().zip(&other.sum) {
            *mine += theirs;
        }
        for (mine, theirs) in self.squares.iter_mut().zip(&other.squares) {
            *mine += theirs;
        }
        self.total_sum += other.total_sum;
        self.total_squares += other.total_squares;
        self.count += other.count;
        self
    }

    /// The same estimates with every estimate's image total raised by `shift` (a
    /// deliberately biased variant of a paired difference): the totals' spread stays what
    /// it was. (Raising `total_sum` alone, as this file once did, left `total_squares`
    /// behind: the variance came out negative, its square root NaN, and the pooled z
    /// enormous whatever the data, so that check could not fail.)
    fn with_total_shifted(&self, shift: f64) -> Self {
        RegionStats {
            total_sum: self.total_sum + shift * self.count,
            total_squares: self.total_squares + 2.0 * shift * self.total_sum + shift * shift * self.count,
            ..self.clone()
        }
    }

    /// The same estimates scaled by `factor` (a deliberately biased variant).
    fn scaled(&self, factor: f64) -> Self {
        RegionStats {
            sum: self.sum.iter().map(|s| s * factor).collect(),
            squares: self.squares.iter().map(|s| s * factor * factor).collect(),
            total_sum: self.total_sum * factor,
            total_squares: self.total_squares * factor * factor,
            count: self.count,
        }
    }

    fn mean(&self, i: usize) -> f64 {
        self.sum[i] / self.count
    }

    /// Variance of the mean.
    fn variance_of_mean(&self, i: usize) -> f64 {
        let m = self.mean(i);
        (self.squares[i] / self.count - m * m) * self.count / (self.count - 1.0) / self.count
    }

    /// Mean of the totals and its variance.
    fn total(&self) -> (f64, f64) {
        let m = self.total_sum / self.count;
        (m, (self.total_squares / self.count - m * m) / (self.count - 1.0))
    }
}

/// The selection at 8 x 8 blocks (the 32 x 32 test image holds 16 of them).
fn blocks_of_8() -> SelectionSettings {
    SelectionSettings { block_size: 8, ..Default::default() }
}

fn settings(scene: &Scene, seed: u32) -> RenderSettings {
    RenderSettings::for_scene(scene, SIZE, SIZE, seed)
}

/// Path-traced reference: `samples` one-sample frames.
fn reference(backend: &mut dyn Backend, scene: &Scene, samples: u32) -> RegionStats {
    reference_from(backend, scene, samples, &settings(scene, 0).camera)
}

/// The default scene's 2048-sample reference, rendered once for every test of this file
/// that needs it (its seeds are fixed, so each test would render the same one).
fn default_reference(backend: &mut dyn Backend) -> RegionStats {
    static REFERENCE: OnceLock<RegionStats> = OnceLock::new();
    REFERENCE.get_or_init(|| reference(backend, &default_scene(), 2048)).clone()
}

/// Path-traced reference seen from `camera`.
fn reference_from(backend: &mut dyn Backend, scene: &Scene, samples: u32, camera: &Camera) -> RegionStats {
    let gpu_scene = GpuScene::build(scene).unwrap();
    let mut stats = RegionStats::new();
    // Batches of 4 samples, each batch one i.i.d. estimate.
    for batch in 0..samples / 4 {
        let render = RenderSettings { camera: camera.clone(), ..settings(scene, 50_000 + batch) };
        let mut tracer = PathTracer::new(backend, &gpu_scene, &render).unwrap();
        for _ in 0..4 {
            tracer.add_sample(backend).unwrap();
        }
        stats.add(&tracer.image(backend).unwrap());
        tracer.destroy(backend).unwrap();
    }
    stats
}

/// Path-traced reference of the mean of the images seen from `cameras`: `samples` per
/// camera, in batches of 4 per camera, each batch's mean over the cameras one i.i.d.
/// estimate (as many samples in all as [`reference`] takes for `samples` times the
/// cameras, and as precise).
fn reference_along(backend: &mut dyn Backend, scene: &Scene, samples: u32, cameras: &[Camera]) -> RegionStats {
    let gpu_scene = GpuScene::build(scene).unwrap();
    let mut stats = RegionStats::new();
    for batch in 0..samples / 4 {
        let mut images = Vec::new();
        for (index, camera) in cameras.iter().enumerate() {
            let seed = 60_000 + batch * cameras.len() as u32 + index as u32;
            let render = RenderSettings { camera: camera.clone(), ..settings(scene, seed) };
            let mut tracer = PathTracer::new(backend, &gpu_scene, &render).unwrap();
            for _ in 0..4 {
                tracer.add_sample(backend).unwrap();
            }
            images.push(tracer.image(backend).unwrap());
            tracer.destroy(backend).unwrap();
        }
        stats.add(&mean_image(&images));
    }
    stats
}

/// z of every region and channel of `ours` against `reference`.
fn z_scores(ours: &RegionStats, reference: &RegionStats) -> Vec<f64> {
    (0..ours.sum.len())
        .map(|i| {
            let se = (ours.variance_of_mean(i) + reference.variance_of_mean(i)).sqrt();
            (ours.mean(i) - reference.mean(i)) / se.max(1e-12)
        })
        .collect()
}

/// z of the image's total (every region and channel summed) against the reference's: the
/// pooled test, exact whatever the correlation between regions and channels.
fn pooled_z(ours: &RegionStats, reference: &RegionStats) -> f64 {
    let (a, var_a) = ours.total();
    let (b, var_b) = reference.total();
    (a - b) / (var_a + var_b).sqrt().max(1e-12)
}

/// The smallest bias of the whole image, relative to the reference's total, that the
/// pooled test catches with probability 0.99: |z| > 4.5 at the bias's z less 2.33
/// standard errors.
fn detectable_bias(ours: &RegionStats, reference: &RegionStats) -> f64 {
    let (_, var_a) = ours.total();
    let (b, var_b) = reference.total();
    (4.5 + 2.33) * (var_a + var_b).sqrt() / b
}

/// Paired runs: `differences` (each estimate a frame of one setting less the same seed's
/// and frame's image under another) have mean 0 by the same three tests
/// [`assert_unbiased`] applies against a reference, and resolve a difference of
/// `max_bias` of the reference image's total or less with probability 0.99. Without
/// temporal reuse every method and shading traces the same paths and candidates from a
/// seed and frame (only the selection and the shading of what it keeps differ), so the
/// difference of two frames spreads far less than either: over 128 frames of the default
/// room, 0.5 % (expectation) and 0.5-0.7 % (sample) of a frame's variance, strata or
/// restir-disc less restir. A few paired frames then catch a bias of one method that the
/// other lacks far more finely than the unpaired frames of each against the reference.
fn assert_same_mean_with_power(what: &str, differences: &RegionStats, reference: &RegionStats, max_bias: f64) {
    let (_, variance) = differences.total();
    // Two settings that rendered the same images would pass every test below with z = 0.
    assert!(variance > 0.0, "{what}: every difference is 0: the two settings rendered the same images");
    assert_unbiased(what, differences, &RegionStats::zero());
    let (total, _) = reference.total();
    let detectable = (4.5 + 2.33) * variance.sqrt() / total;
    eprintln!(
        "{what}: resolves a difference of {:.3} % of the image (power 0.99), stated {:.1} %",
        100.0 * detectable,
        100.0 * max_bias
    );
    assert!(
        detectable <= max_bias,
        "{what}: resolves only a difference of {:.3} % of the image with power 0.99, stated {:.1} %",
        100.0 * detectable,
        100.0 * max_bias
    );
}

/// [`assert_unbiased`], and the test's power at least as stated: it catches a bias of the
/// whole image of `max_bias` (relative) with probability 0.99 or more.
fn assert_unbiased_with_power(what: &str, ours: &RegionStats, reference: &RegionStats, max_bias: f64) {
    assert_unbiased(what, ours, reference);
    let detectable = detectable_bias(ours, reference);
    eprintln!(
        "{what}: detects a bias of {:.2} % of the image (power 0.99), stated {:.1} %",
        100.0 * detectable,
        100.0 * max_bias
    );
    assert!(
        detectable <= max_bias,
        "{what}: detects only a bias of {:.2} % of the image with power 0.99, stated {:.1} %",
        100.0 * detectable,
        100.0 * max_bias
    );
}

fn assert_unbiased(what: &str, ours: &RegionStats, reference: &RegionStats) {
    let z = z_scores(ours, reference);
    let mean_square = z.iter().map(|z| z * z).sum::<f64>() / z.len() as f64;
    let max = z.iter().fold(0.0f64, |m, z| m.max(z.abs()));
    let pooled = pooled_z(ours, reference);
    eprintln!("{what}: regions' mean z² {mean_square:.2}, max |z| {max:.2}, pooled z {pooled:.2} over {}", z.len());
    // 48 region-channels: mean z² of 48 χ²₁ values exceeds 2 with probability ~1e-4 if
    // independent (a region's channels are correlated, which widens it). A bias shared by
    // the image shows in the pooled z of its total, N(0, 1) without bias: |z| > 4.5 has
    // probability 7e-6. (It once summed the 48 z values over √48, which treated the
    // channels as independent and spread about √3 times wider than N(0, 1).)
    assert!(mean_square < 2.0, "{what}: regions differ from the reference beyond noise");
    assert!(pooled.abs() < 4.5, "{what}: the image is off as a whole (pooled z {pooled:.2})");
    assert!(max < 5.0, "{what}: a region is off by {max:.1} sigma");
}

/// Per seed, the mean of its frames from [`FIRST_SCORED_FRAME`] on with temporal reuse
/// (one independent estimate per render), or every frame without it. Frames of one
/// render are then counted as independent; with the default stratified film their film
/// positions are negatively correlated, so the spread overstates the mean's variance and
/// the z scores are, if anything, smaller than they should be.
fn restir_frames(
    backend: &mut dyn Backend,
    scene: &Scene,
    restir: RestirSettings,
    seeds: std::ops::Range<u32>,
    frames: u32,
) -> RegionStats {
    restir_frames_along(backend, scene, restir, seeds, frames, &CameraPath::Static, |render| render)
}

/// The pixel-wise mean of same-sized images.
fn mean_image(images: &[RgbImage]) -> RgbImage {
    let mut mean = RgbImage::new(images[0].width, images[0].height);
    let weight = 1.0 / images.len() as f32;
    for image in images {
        for (m, p) in mean.pixels.iter_mut().zip(&image.pixels) {
            for c in 0..3 {
                m[c] += p[c] * weight;
            }
        }
    }
    mean
}

/// [`restir_frames`] with the camera moving along `path` and each seed's render settings
/// changed by `adjust`.
fn restir_frames_along(
    backend: &mut dyn Backend,
    scene: &Scene,
    restir: RestirSettings,
    seeds: std::ops::Range<u32>,
    frames: u32,
    path: &CameraPath,
    adjust: impl Fn(RenderSettings) -> RenderSettings,
) -> RegionStats {
    let gpu_scene = GpuScene::build(scene).unwrap();
    let mut stats = RegionStats::new();
    for seed in seeds {
        let images = render_frames(backend, &gpu_scene, scene, restir, seed, frames, path, &adjust);
        if restir.temporal {
            stats.add(&scored_mean(&images, frames));
        } else {
            images.iter().for_each(|image| stats.add(image));
        }
    }
    stats
}

/// Every frame of one render of `frames` frames of `restir` from `seed`, the camera moving
/// along `path` and the render settings changed by `adjust` (frame 1 first).
#[allow(clippy::too_many_arguments)]
fn render_frames(
    backend: &mut dyn Backend,
    gpu_scene: &GpuScene,
    scene: &Scene,
    restir: RestirSettings,
    seed: u32,
    frames: u32,
    path: &CameraPath,
    adjust: &impl Fn(RenderSettings) -> RenderSettings,
) -> Vec<RgbImage> {
    let mut renderer =
        RestirRenderer::new(backend, gpu_scene, &adjust(settings(scene, seed)), restir, scene.extent()).unwrap();
    let images = (0..frames)
        .map(|frame| {
            let camera = path.camera_at(&settings(scene, seed).camera, frame);
            let (image, frame_stats) = renderer.render_frame(backend, Some(&camera)).unwrap();
            assert_eq!(frame_stats.invalid_pixels, 0);
            image
        })
        .collect();
    renderer.destroy(backend).unwrap();
    images
}

/// The mean of a temporal render's frames [`FIRST_SCORED_FRAME`] to `last` (`images[0]` is
/// frame 1): the render's one estimate.
fn scored_mean(images: &[RgbImage], last: u32) -> RgbImage {
    assert!(last >= FIRST_SCORED_FRAME, "a temporal render of {last} frames scores none");
    mean_image(&images[FIRST_SCORED_FRAME as usize - 1..last as usize])
}

/// Frames a paired temporal variant renders ([`temporal_pairs`]): frame 3 alone is scored,
/// the first at which the own reservoir's cap and the temporal-first order's bind.
const PAIRED_TEMPORAL_FRAMES: u32 = 3;

/// With temporal reuse, `base` over `base_renders` of `base_frames` frames (each scored by
/// the mean of its frames from [`FIRST_SCORED_FRAME`] on, for the reference), and each
/// variant `(settings, frames)` over the first [`TEMPORAL_RENDERS`] of those seeds, less
/// the same seed's base over the same frames: one estimate of the difference per render.
///
/// With temporal reuse the methods' reservoirs diverge over frames, but every frame still
/// traces the same paths and candidates from a seed, so a variant's render less the base's
/// spreads far less than either. Measured over 24 renders of the default room (totals of
/// the image; variance of the difference scored on frame 3 alone, relative to the
/// variant's own frames 3-6): the own reservoir at cap 2 0.08 (strata, restir-disc), both
/// orders at the defaults 0.12-0.20 (temporal-first) and 0.02-0.06 (spatial-first), the
/// white film 0.09-0.17, the mirror-floor room with four drawn reservoirs 0.10-0.14; with
/// four drawn reservoirs in the default room 0.48-0.57 over frames 3-8 (0.51-0.63 over
/// 3-6). So a variant renders 3 frames where it rendered 6 (5 in the spatial-first order,
/// whose history count keeps growing; 6 with four drawn reservoirs) and its bias (one restir lacks) is caught more
/// finely; restir, held to the reference, catches a bias they share. In the
/// glass/metal/environment room the difference spreads as much as the variant (0.7-1.7):
/// no temporal pairs there. (docs/benchmarks/ci-time.md, "Temporal pairs".)
fn temporal_pairs(
    backend: &mut dyn Backend,
    scene: &Scene,
    base: RestirSettings,
    (base_renders, base_frames): (std::ops::Range<u32>, u32),
    variants: &[(RestirSettings, u32)],
    adjust: impl Fn(RenderSettings) -> RenderSettings,
) -> (RegionStats, Vec<RegionStats>) {
    assert!(base.temporal && variants.iter().all(|(v, frames)| v.temporal && *frames <= base_frames));
    assert!(base_renders.start <= TEMPORAL_RENDERS.start && TEMPORAL_RENDERS.end <= base_renders.end);
    let gpu_scene = GpuScene::build(scene).unwrap();
    let path = CameraPath::Static;
    let mut ours = RegionStats::new();
    let mut differences = vec![RegionStats::new(); variants.len()];
    for seed in base_renders {
        let base_images = render_frames(backend, &gpu_scene, scene, base, seed, base_frames, &path, &adjust);
        ours.add(&scored_mean(&base_images, base_frames));
        if !TEMPORAL_RENDERS.contains(&seed) {
            continue;
        }
        for ((variant, frames), difference) in variants.iter().zip(&mut differences) {
            let images = render_frames(backend, &gpu_scene, scene, *variant, seed, *frames, &path, &adjust);
            difference.add_difference(&scored_mean(&images, *frames), &scored_mean(&base_images, *frames));
        }
    }
    (ours, differences)
}

/// What [`paired_differences`] rendered: `base` and each variant over the same seeds and
/// frames, and each variant less `base`, frame by frame.
struct PairedRuns {
    base: RegionStats,
    variants: Vec<RegionStats>,
    differences: Vec<RegionStats>,
}

/// Without temporal reuse: per seed and frame, each of `variants` less `base` (both
/// rendered from that seed and frame, with `adjust` applied to the render settings).
fn paired_differences(
    backend: &mut dyn Backend,
    scene: &Scene,
    base: RestirSettings,
    variants: &[RestirSettings],
    seeds: std::ops::Range<u32>,
    frames: u32,
    adjust: impl Fn(RenderSettings) -> RenderSettings,
) -> PairedRuns {
    let gpu_scene = GpuScene::build(scene).unwrap();
    let mut base_stats = RegionStats::new();
    let mut variant_stats = vec![RegionStats::new(); variants.len()];
    let mut differences = vec![RegionStats::new(); variants.len()];
    for seed in seeds {
        let render = adjust(settings(scene, seed));
        let mut renderers: Vec<RestirRenderer> = std::iter::once(&base)
            .chain(variants)
            .map(|restir| {
                assert!(!restir.temporal, "paired differences are for frames without temporal reuse");
                RestirRenderer::new(backend, &gpu_scene, &render, *restir, scene.extent()).unwrap()
            })
            .collect();
        for _ in 0..frames {
            let images: Vec<RgbImage> = renderers
                .iter_mut()
                .map(|renderer| {
                    let (image, stats) = renderer.render_frame(backend, None).unwrap();
                    assert_eq!(stats.invalid_pixels, 0);
                    image
                })
                .collect();
            base_stats.add(&images[0]);
            for ((difference, own), image) in differences.iter_mut().zip(&mut variant_stats).zip(&images[1..]) {
                difference.add_difference(image, &images[0]);
                own.add(image);
            }
        }
        for renderer in renderers {
            renderer.destroy(backend).unwrap();
        }
    }
    PairedRuns { base: base_stats, variants: variant_stats, differences }
}

/// Without temporal reuse every method converges to the path tracer's image, shading the
/// final resampling's expectation (the default) and the kept sample: restir's expectation
/// against the reference over 8 renders of 64 frames (a conditional expectation of the
/// sample's estimate, it spreads less over frames than the sample: checked), and restir's
/// sample, strata, restir-disc and ris (plain per-pixel RIS, no reuse) paired with
/// restir's expectation frame by frame
/// ([`assert_same_mean_with_power`]): until
/// 2026-11-28 each method ran 8 × 64 frames against the reference, resolving 2.8 % where
/// the pairs now resolve about 0.5 %.
#[test]
fn every_method_converges_to_the_path_traced_reference() {
    let Some(mut backend) = strata_tests::vulkan_backend("every_method_converges_to_the_path_traced_reference") else {
        assert!(!gpu_required());
        return;
    };
    let scene = default_scene();
    let reference = default_reference(&mut backend);
    let settings = |method, shading| RestirSettings {
        method,
        shading,
        temporal: false,
        selection: blocks_of_8(),
        ..RestirSettings::default()
    };
    // restir's expectation against the reference.
    let expected = restir_frames(&mut backend, &scene, settings(Method::Restir, Shading::Expectation), 1..9, 64);
    assert_unbiased_with_power("restir expectation without temporal reuse", &expected, &reference, POWER_ACCUMULATED);
    // The test can fail: the same frames 3 % too bright are caught.
    let pooled = pooled_z(&expected.scaled(1.03), &reference);
    assert!(pooled > 4.5, "restir: a 3 % bias gives pooled z {pooled:.2} only");
    // restir's sample shading, strata and restir-disc with both, paired with restir's
    // expectation frame by frame: a bias of theirs that restir's expectation lacks shows
    // in the differences, one they share with it in its run above.
    let variants = [
        settings(Method::Restir, Shading::Sample),
        settings(Method::Strata, Shading::Expectation),
        settings(Method::Strata, Shading::Sample),
        settings(Method::RestirDisc, Shading::Expectation),
        settings(Method::RestirDisc, Shading::Sample),
        settings(Method::Ris, Shading::Expectation),
        settings(Method::Ris, Shading::Sample),
        // The quad-antithetic sampler (complementary strata across each 2 x 2 quad).
        RestirSettings {
            selection: SelectionSettings { sampler: SamplerVariant::QuadAntithetic, ..blocks_of_8() },
            ..settings(Method::Strata, Shading::Expectation)
        },
    ];
    let base = settings(Method::Restir, Shading::Expectation);
    let paired = paired_differences(&mut backend, &scene, base, &variants, PAIRED_SEEDS, 32, |render| render);
    // Over the same frames, restir's expectation spreads less than its sample.
    let spread = |stats: &RegionStats| (0..stats.sum.len()).map(|i| stats.variance_of_mean(i)).sum::<f64>();
    assert!(
        spread(&paired.base) < spread(&paired.variants[0]),
        "restir: the expectation's frames spread more than the sample's"
    );
    for (variant, difference) in variants.iter().zip(&paired.differences) {
        let what = format!(
            "{} {:?} ({} sampler) less restir expectation, without temporal reuse",
            variant.method.name(),
            variant.shading,
            variant.selection.sampler.name()
        );
        assert_same_mean_with_power(&what, difference, &reference, POWER_PAIRED);
        // The paired test can fail: the variant's frames 1 % too bright are caught.
        let (total, _) = reference.total();
        let brighter = difference.with_total_shifted(0.01 * total);
        assert!(pooled_z(&brighter, &RegionStats::zero()) > 4.5, "{what}: a 1 % difference goes unnoticed");
    }
}

/// `--disc-radius` is a public setting: restir-disc stays unbiased with a disc of 2
/// pixels (few neighbours, most of them rejected by the normal and depth tests) and one
/// wider than the image (most draws land outside it and leave the slot empty), without
/// temporal reuse (every frame scored), each paired with restir frame by frame
/// ([`assert_same_mean_with_power`]; 8 renders of 64 frames each against the reference
/// until 2026-11-28). With temporal reuse (the own reservoir and 4 drawn from the disc)
/// both radii are paired with restir in
/// [`temporal_reuse_stays_unbiased_with_drawn_reservoirs`].
#[test]
fn restir_disc_stays_unbiased_for_any_disc_radius() {
    let test = "restir_disc_stays_unbiased_for_any_disc_radius";
    let Some(mut backend) = strata_tests::vulkan_backend(test) else {
        assert!(!gpu_required());
        return;
    };
    let scene = default_scene();
    let reference = default_reference(&mut backend);
    for disc_radius in [2.0, 1000.0] {
        let restir = RestirSettings {
            method: Method::RestirDisc,
            disc_radius,
            temporal: false,
            selection: blocks_of_8(),
            ..RestirSettings::default()
        };
        // Without temporal reuse, paired frame by frame with restir (which
        // every_method_converges_to_the_path_traced_reference holds to the reference).
        let base = RestirSettings { method: Method::Restir, ..restir };
        let differences =
            paired_differences(&mut backend, &scene, base, &[restir], PAIRED_SEEDS, 32, |r| r).differences;
        let what = format!("restir-disc, disc radius {disc_radius}, less restir, no temporal reuse");
        assert_same_mean_with_power(&what, &differences[0], &reference, POWER_PAIRED);
    }
}

/// With temporal reuse every method stays unbiased over independent renders with the
/// reprojected previous reservoir alone (restir over frames 3 to 5, the others paired
/// with it on frame 3), then with four more drawn like
/// spatial candidates (Fig. 11: strata from the temporal histogram, restir uniformly from
/// the cluster, restir-disc from its disc): merging more history makes
/// the frames' distribution heavier-tailed (an earlier variant without the own reservoir
/// gave restir a region mean z² of 2.08 at 256 renders and 1.24 at 1024: noise, not
/// bias). The runs with the own reservoir alone cap M at 2, which binds from frame 2 on
/// (a merge capping M on one side of its MIS weights only was seen failing here, in the
/// spatial-first order: mean z² 359; in the default temporal-first order the spatial pass
/// sums M, so the default cap of 20 binds too from frame 3). Default settings otherwise:
/// the temporal-first order, expectation shading (the kept sample's shading
/// with temporal reuse is tested on the glass/metal/environment room). restir is held to
/// the reference; strata and restir-disc to restir on the same seeds ([`temporal_pairs`]).
#[test]
fn temporal_reuse_stays_unbiased_with_the_own_reservoir() {
    let Some(mut backend) = strata_tests::vulkan_backend("temporal_reuse_stays_unbiased_with_the_own_reservoir") else {
        assert!(!gpu_required());
        return;
    };
    let scene = default_scene();
    let reference = default_reference(&mut backend);
    let own = |method| RestirSettings {
        method,
        selection: blocks_of_8(),
        temporal_candidates: 0,
        temporal_cap: 2.0,
        ..RestirSettings::default()
    };
    let variants = [(own(Method::Strata), PAIRED_TEMPORAL_FRAMES), (own(Method::RestirDisc), PAIRED_TEMPORAL_FRAMES)];
    let (ours, differences) = temporal_pairs(
        &mut backend,
        &scene,
        own(Method::Restir),
        (TEMPORAL_RENDERS, BASE_TEMPORAL_FRAMES),
        &variants,
        |r| r,
    );
    let what = format!("restir with the own temporal reservoir alone, cap 2, frames 3-{BASE_TEMPORAL_FRAMES}");
    assert_unbiased_with_power(&what, &ours, &reference, POWER_TEMPORAL_OWN);
    for ((variant, _), difference) in variants.iter().zip(&differences) {
        let what = format!("{} less restir, own temporal reservoir alone, cap 2, frame 3", variant.method.name());
        assert_same_mean_with_power(&what, difference, &reference, POWER_TEMPORAL_PAIRED);
    }
}

/// The own and four drawn temporal reservoirs at the default cap (above): restir over 128
/// renders of 8 frames, 6 of them scored (heavier tails, see above; the 512 renders' frame
/// 6 this replaced detected 2.9 %: the reference's share of the variance grows as ours
/// shrinks, so 64 renders would only have kept that), and paired with it over the first 64
/// renders over 6 frames, 4 of them scored: strata, restir-disc, and restir-disc at disc
/// radii 2 and 1000 (the difference of drawn reservoirs spreads about half as much as
/// either; the radii ran 64 renders of 8 frames against the reference before).
#[test]
fn temporal_reuse_stays_unbiased_with_drawn_reservoirs() {
    let Some(mut backend) = strata_tests::vulkan_backend("temporal_reuse_stays_unbiased_with_drawn_reservoirs") else {
        assert!(!gpu_required());
        return;
    };
    let scene = default_scene();
    let reference = default_reference(&mut backend);
    let drawn = |method| RestirSettings {
        method,
        selection: blocks_of_8(),
        temporal_candidates: 4,
        ..RestirSettings::default()
    };
    let disc = |disc_radius| RestirSettings { disc_radius, ..drawn(Method::RestirDisc) };
    let frames = DRAWN_PAIRED_FRAMES;
    let variants = [
        (drawn(Method::Strata), frames),
        (drawn(Method::RestirDisc), frames),
        (disc(2.0), frames),
        (disc(1000.0), frames),
    ];
    let (ours, differences) =
        temporal_pairs(&mut backend, &scene, drawn(Method::Restir), (1..129, 8), &variants, |r| r);
    let cap = RestirSettings::default().temporal_cap;
    let what = format!("restir with own + 4 drawn temporal reservoirs, cap {cap}, frames 3-8");
    assert_unbiased_with_power(&what, &ours, &reference, POWER_TEMPORAL_DRAWN);
    for ((variant, frames), difference) in variants.iter().zip(&differences) {
        let name = if variant.disc_radius == RestirSettings::default().disc_radius {
            variant.method.name().to_string()
        } else {
            format!("{}, disc radius {}", variant.method.name(), variant.disc_radius)
        };
        let what = format!("{name} less restir, own + 4 drawn temporal reservoirs, frames 3-{frames}");
        assert_same_mean_with_power(&what, difference, &reference, POWER_TEMPORAL_PAIRED);
    }
}

/// Both orders of reuse stay unbiased for every method over independent renders (restir
/// over frames 3 to 5 against the reference, the others paired with it). The
/// temporal-first order (the default: the history merged into each pixel's canonical
/// candidate first, then K of the block's merged reservoirs reused under
/// pairwise MIS with confidence weights) is what every other temporal test here runs;
/// these run it with the default cap and strata shading the kept sample too, whose W the
/// next frame reuses. Its spatial pass sums the merged M (5 after the first frame at K =
/// 4, 30 after the second), so the cap of 20 binds from the third frame on, on the
/// history's side of each merge. The paper's spatial-first order is scored with the same
/// settings. restir (expectation shading) is held to the reference; strata with both
/// shadings and restir-disc to restir in the same order on the same seeds
/// ([`temporal_pairs`]).
#[test]
fn reuse_order_stays_unbiased() {
    let Some(mut backend) = strata_tests::vulkan_backend("reuse_order_stays_unbiased") else {
        assert!(!gpu_required());
        return;
    };
    let scene = default_scene();
    let reference = default_reference(&mut backend);
    for reuse_order in [ReuseOrder::TemporalFirst, ReuseOrder::SpatialFirst] {
        let settings = |method, shading| RestirSettings {
            method,
            shading,
            selection: blocks_of_8(),
            reuse_order,
            ..RestirSettings::default()
        };
        // In the spatial-first order the merged M grows by one a frame (1 + min(M, 20)), so
        // its variants are scored over frames 3 to 5 as restir is, each frame's merge with
        // another history count; the temporal-first order's cap binds from frame 3.
        let frames =
            if reuse_order == ReuseOrder::SpatialFirst { BASE_TEMPORAL_FRAMES } else { PAIRED_TEMPORAL_FRAMES };
        let variants = [
            (settings(Method::Strata, Shading::Expectation), frames),
            (settings(Method::Strata, Shading::Sample), frames),
            (settings(Method::RestirDisc, Shading::Expectation), frames),
        ];
        let base = settings(Method::Restir, Shading::Expectation);
        let (ours, differences) =
            temporal_pairs(&mut backend, &scene, base, (TEMPORAL_RENDERS, BASE_TEMPORAL_FRAMES), &variants, |r| r);
        let what = format!("restir {}, Expectation shading, frames 3-{BASE_TEMPORAL_FRAMES}", reuse_order.name());
        assert_unbiased_with_power(&what, &ours, &reference, POWER_REUSE_ORDER);
        for ((variant, _), difference) in variants.iter().zip(&differences) {
            let scored =
                if frames == FIRST_SCORED_FRAME { "frame 3".to_string() } else { format!("frames 3-{frames}") };
            let what = format!(
                "{} {}, {:?} shading, less restir, {scored}",
                variant.method.name(),
                reuse_order.name(),
                variant.shading
            );
            assert_same_mean_with_power(&what, difference, &reference, POWER_TEMPORAL_PAIRED);
        }
    }
}

/// The `--shaded-parts` diagnostic: the base and the resampled part add up to the
/// image, pixel by pixel, and the base does not depend on the selection method.
#[test]
fn shaded_parts_add_up_to_the_image() {
    let Some(mut backend) = strata_tests::vulkan_backend("shaded_parts_add_up_to_the_image") else {
        assert!(!gpu_required());
        return;
    };
    let scene = default_scene();
    let gpu_scene = GpuScene::build(&scene).unwrap();
    let mut frame_3 = |method, shaded_parts| {
        let restir = RestirSettings { method, selection: blocks_of_8(), shaded_parts, ..RestirSettings::default() };
        let mut renderer =
            RestirRenderer::new(&mut backend, &gpu_scene, &settings(&scene, 7), restir, scene.extent()).unwrap();
        let mut image = None;
        for _ in 0..3 {
            image = Some(renderer.render_frame(&mut backend, None).unwrap().0);
        }
        renderer.destroy(&mut backend).unwrap();
        image.unwrap()
    };
    let strata_base = frame_3(Method::Strata, ShadedParts::Base);
    let restir_base = frame_3(Method::Restir, ShadedParts::Base);
    assert_eq!(strata_base.pixels, restir_base.pixels, "the base must not depend on the selection");
    for method in [Method::Strata, Method::Restir] {
        let all = frame_3(method, ShadedParts::All);
        let resampled = frame_3(method, ShadedParts::Resampled);
        let mut lit = 0;
        for ((a, b), r) in all.pixels.iter().zip(&strata_base.pixels).zip(&resampled.pixels) {
            for c in 0..3 {
                assert!((a[c] - (b[c] + r[c])).abs() <= 1e-5 * (1.0 + a[c].abs()), "{a:?} != {b:?} + {r:?}");
            }
            lit += usize::from(r.iter().any(|&v| v > 0.0));
        }
        // Most pixels of the default scene resample some indirect light.
        assert!(lit > all.pixels.len() / 2, "{}: only {lit} pixels have a resampled part", method.name());
    }
}

/// `dispatch_only` (the warm-up of `strata compare`) dispatches just the kernels named:
/// with none, a frame leaves every buffer as it was; with the candidates' kernel alone,
/// only the G-buffer and candidates are written; with `None` again the frame is the
/// image an untouched renderer renders.
#[test]
fn dispatch_only_runs_just_the_kernels_named() {
    use strata_kernels::KernelId;
    let Some(mut backend) = strata_tests::vulkan_backend("dispatch_only_runs_just_the_kernels_named") else {
        assert!(!gpu_required());
        return;
    };
    let scene = default_scene();
    let gpu_scene = GpuScene::build(&scene).unwrap();
    let render = RenderSettings {
        camera: Camera { width: 16, height: 16, ..settings(&scene, 3).camera },
        ..settings(&scene, 3)
    };
    let restir = RestirSettings { selection: blocks_of_8(), ..RestirSettings::default() };
    let new =
        |backend: &mut dyn Backend| RestirRenderer::new(backend, &gpu_scene, &render, restir, scene.extent()).unwrap();
    let mut warm_up = new(&mut backend);
    warm_up.dispatch_only(Some(Vec::new()));
    let (nothing, _) = warm_up.render_frame(&mut backend, None).unwrap();
    assert!(nothing.pixels.iter().all(|p| *p == [0.0; 3]), "no kernel ran, yet the frame was written");
    warm_up.dispatch_only(Some(vec![KernelId::RestirCandidates]));
    warm_up.render_frame(&mut backend, None).unwrap();
    let buffers = warm_up.frame_buffers(&mut backend).unwrap();
    assert!(buffers.base_radiance.iter().any(|p| p[..3].iter().any(|&c| c > 0.0)), "the candidates pass ran");
    assert!(buffers.image.iter().all(|p| *p == [0.0; 4]), "only the candidates pass should have run");
    warm_up.destroy(&mut backend).unwrap();
    let mut again = new(&mut backend);
    again.dispatch_only(Some(vec![KernelId::RestirShade]));
    again.dispatch_only(None);
    let (image, _) = again.render_frame(&mut backend, None).unwrap();
    again.destroy(&mut backend).unwrap();
    let mut plain = new(&mut backend);
    let (want, _) = plain.render_frame(&mut backend, None).unwrap();
    plain.destroy(&mut backend).unwrap();
    assert_eq!(image.pixels, want.pixels);
}

/// `min_roughness` decides which conductors resample at the primary hit: with the default
/// scene's white surfaces (floor, ceiling, back wall, boxes) made a GGX conductor of alpha
/// 0.1, they have no resampled part at a threshold of 0.2 (the default until 2026-11-25)
/// and have one at 0.05 (today's default). Smooth chains are off here: with them, pixels
/// below the threshold resample behind the conductor instead
/// (`specular_chains_let_smooth_primary_hits_resample`).
#[test]
fn min_roughness_decides_which_conductors_resample() {
    let Some(mut backend) = strata_tests::vulkan_backend("min_roughness_decides_which_conductors_resample") else {
        assert!(!gpu_required());
        return;
    };
    let mut scene = default_scene();
    scene.materials[0] = strata_render::scene::Material::RoughConductor {
        alpha: 0.1,
        eta: [0.2, 0.9, 1.1],
        k: [3.9, 2.4, 2.2],
        two_sided: true,
    };
    let gpu_scene = GpuScene::build(&scene).unwrap();
    let mut lit_pixels = |min_roughness: f32| {
        let restir = RestirSettings {
            min_roughness,
            specular_chain: 0,
            shaded_parts: ShadedParts::Resampled,
            ..RestirSettings::default()
        };
        let mut renderer =
            RestirRenderer::new(&mut backend, &gpu_scene, &settings(&scene, 5), restir, scene.extent()).unwrap();
        let image = renderer.render_frame(&mut backend, None).unwrap().0;
        renderer.destroy(&mut backend).unwrap();
        image.pixels.iter().filter(|p| p.iter().any(|&v| v > 0.0)).count()
    };
    let (strict, loose) = (lit_pixels(0.2), lit_pixels(0.05));
    let total = (SIZE * SIZE) as usize;
    // Only the red and green walls resample at 0.2; the conductor (floor, ceiling, back
    // wall and both boxes) covers well over a fifth of the image.
    assert!(strict < total / 2, "{strict} of {total} pixels resample at 0.2");
    assert!(loose > strict + total / 5, "{loose} pixels resample at 0.05, {strict} at 0.2");
}

/// A two-sided GGX conductor of alpha 0.01, below the default `min_roughness`: a smooth
/// vertex that chains pass through.
fn near_mirror() -> strata_render::scene::Material {
    strata_render::scene::Material::RoughConductor {
        alpha: 0.01,
        eta: [0.2, 0.9, 1.1],
        k: [3.9, 2.4, 2.2],
        two_sided: true,
    }
}

/// `specular_chain` lets pixels whose primary hit is smooth resample at the first rough
/// vertex behind it: with the default scene's floor, ceiling and back wall a near-mirror
/// conductor (alpha 0.01, below the default `min_roughness`) and its tall box glass, those
/// pixels have no resampled part without chains and have one with the default chain; the
/// resampling vertices behind them lie off the camera ray's hit, reached by a later
/// segment, and the chain's throughput is below 1.
#[test]
fn specular_chains_let_smooth_primary_hits_resample() {
    let Some(mut backend) = strata_tests::vulkan_backend("specular_chains_let_smooth_primary_hits_resample") else {
        assert!(!gpu_required());
        return;
    };
    let mut scene = default_scene();
    scene.materials[0] = near_mirror();
    scene.materials.push(strata_render::scene::Material::Dielectric { int_ior: 1.5, ext_ior: 1.0 });
    let glass = scene.materials.len() - 1;
    scene.shapes.iter_mut().filter(|shape| shape.name == "tall box").for_each(|shape| shape.material = glass);
    let gpu_scene = GpuScene::build(&scene).unwrap();
    let mut resampling = |specular_chain: u32| {
        let restir = RestirSettings {
            specular_chain,
            shaded_parts: ShadedParts::Resampled,
            temporal: false,
            ..RestirSettings::default()
        };
        let mut renderer =
            RestirRenderer::new(&mut backend, &gpu_scene, &settings(&scene, 5), restir, scene.extent()).unwrap();
        let image = renderer.render_frame(&mut backend, None).unwrap().0;
        let primaries = renderer.frame_buffers(&mut backend).unwrap().primaries;
        renderer.destroy(&mut backend).unwrap();
        let lit = image.pixels.iter().filter(|p| p.iter().any(|&v| v > 0.0)).count();
        (lit, primaries)
    };
    let ((off, off_primaries), (on, on_primaries)) = (resampling(0), resampling(4));
    let total = (SIZE * SIZE) as usize;
    let resamples =
        |p: &&strata_kernels::restir_types::Primary| p.flags & strata_kernels::restir_types::PRIMARY_RESAMPLE != 0;
    assert!(off_primaries.iter().filter(resamples).all(|p| p.segment == 1 && p.throughput == [1.0; 3]));
    let chained: Vec<_> = on_primaries.iter().filter(resamples).filter(|p| p.segment > 1).collect();
    eprintln!("{on} pixels resample with chains ({} behind one), {off} without", chained.len());
    // The mirror surfaces and the glass cover well over half the image; chains between
    // the mirrors that escape through the open front find no rough vertex.
    assert!(on > off + total / 5, "{on} pixels resample with chains, {off} without");
    assert!(chained.len() > total / 5, "only {} pixels resample behind a chain", chained.len());
    for p in &chained {
        assert!(p.camera_hit != p.position, "{p:?}");
        assert!(p.throughput.iter().all(|&t| t > 0.0 && t.is_finite()), "{p:?}");
    }
    // Behind the mirrors (Fresnel below 1); a way into and out of glass keeps 1.
    let dimmed = chained.iter().filter(|p| p.throughput.iter().all(|&t| t < 1.0)).count();
    assert!(dimmed > total / 8, "only {dimmed} chains dim the light");
}

/// `pixel_centres` reaches the ReSTIR frames: the primary hits are then the same for
/// every seed and frame (and differ with film jitter); the path tracer, which renders
/// the references, does the same.
#[test]
fn pixel_centres_remove_the_film_jitter() {
    let Some(mut backend) = strata_tests::vulkan_backend("pixel_centres_remove_the_film_jitter") else {
        assert!(!gpu_required());
        return;
    };
    let scene = default_scene();
    let gpu_scene = GpuScene::build(&scene).unwrap();
    let film = |centres: bool| if centres { Film::Centres } else { Film::White };
    let mut primaries = |seed: u32, pixel_centres: bool| {
        let render = RenderSettings { film: film(pixel_centres), ..settings(&scene, seed) };
        let mut renderer =
            RestirRenderer::new(&mut backend, &gpu_scene, &render, RestirSettings::default(), scene.extent()).unwrap();
        renderer.render_frame(&mut backend, None).unwrap();
        renderer.render_frame(&mut backend, None).unwrap();
        let buffers = renderer.frame_buffers(&mut backend).unwrap();
        renderer.destroy(&mut backend).unwrap();
        buffers.primaries.iter().map(|p| p.position).collect::<Vec<_>>()
    };
    assert_eq!(primaries(1, true), primaries(2, true));
    assert_ne!(primaries(1, false), primaries(2, false));
    // The path tracer (references): with only the camera segment (max depth 1) the image
    // is the emission seen directly, the same for every seed at pixel centres, and
    // different at the light's edges with jitter.
    let mut emission = |seed: u32, pixel_centres: bool| {
        let render = RenderSettings { film: film(pixel_centres), max_depth: 1, ..settings(&scene, seed) };
        strata_render::render::render(&mut backend, &gpu_scene, &render, 1, |_| {}).unwrap().pixels
    };
    let centres = emission(3, true);
    assert!(centres.iter().any(|p| p[0] > 0.0), "the light is in view");
    assert_eq!(centres, emission(4, true));
    assert_ne!(emission(3, false), emission(4, false));
}

/// The renderers run kernels specialised for what they know before the first frame
/// (`Registry::specialised`): without the replayed path's re-trace when random replay is
/// off (`random_replay = false`), and reading the scene's rows from their uniform copy
/// when the scene fits it (`scene_in_uniform = true`). In the default room no surface is
/// a glossy conductor, so no pixel replays either way, and the same room with unused
/// materials enough to overflow the uniform copy renders the same image from the storage
/// buffer: the default room's kernels (no replay, the uniform copy) must render the same
/// frames bit for bit as those with the re-trace and as those that read the storage
/// buffer (every method, both reuse orders between them, temporal reuse with four drawn
/// reservoirs, the kept sample's shading), and the path tracer the same image both ways.
/// Seen failing with the specialised reconnection 0.1 % darker, and with the uniform copy
/// written from its second row. (The fourth combination, the re-trace with the storage
/// buffer, is left out: its kernels would be compiled for this test alone, on a new
/// machine about 30 s. That backends cache the variants apart is the registry's unit
/// test: their pipeline keys differ.)
#[test]
fn specialised_kernels_render_the_same_frames() {
    use strata_kernels::render_types::SCENE_UNIFORM_ROWS;
    use strata_render::scene::Material;
    let Some(mut backend) = strata_tests::vulkan_backend("specialised_kernels_render_the_same_frames") else {
        assert!(!gpu_required());
        return;
    };
    let scene = default_scene();
    let small = GpuScene::build(&scene).unwrap();
    let mut padded_scene = scene.clone();
    let unused = Material::Diffuse { albedo: strata_render::scene::Albedo::Constant([0.5; 3]), two_sided: false };
    padded_scene.materials.extend(std::iter::repeat_n(unused, SCENE_UNIFORM_ROWS as usize / 4));
    let padded = GpuScene::build(&padded_scene).unwrap();
    assert!(small.fits_uniform_copy() && !padded.fits_uniform_copy());
    let render = RenderSettings {
        camera: Camera { width: 16, height: 16, ..settings(&scene, 5).camera },
        ..settings(&scene, 5)
    };
    let traced = |gpu_scene: &GpuScene, backend: &mut dyn Backend| {
        strata_render::render::render(backend, gpu_scene, &render, 4, |_| {}).unwrap().pixels
    };
    assert!(traced(&small, &mut backend) == traced(&padded, &mut backend), "the path tracer's uniform copy differs");
    let runs = [
        (Method::Strata, ReuseOrder::TemporalFirst),
        (Method::Restir, ReuseOrder::SpatialFirst),
        (Method::RestirDisc, ReuseOrder::TemporalFirst),
    ];
    for (method, reuse_order) in runs {
        let frames = |glossy_replay: bool, gpu_scene: &GpuScene, backend: &mut dyn Backend| {
            let restir = RestirSettings {
                method,
                reuse_order,
                glossy_replay,
                temporal_candidates: 4,
                shading: Shading::Sample,
                selection: blocks_of_8(),
                ..RestirSettings::default()
            };
            let mut renderer = RestirRenderer::new(backend, gpu_scene, &render, restir, scene.extent()).unwrap();
            let images: Vec<_> = (0..3).map(|_| renderer.render_frame(backend, None).unwrap().0.pixels).collect();
            renderer.destroy(backend).unwrap();
            images
        };
        let default_kernels = frames(false, &small, &mut backend);
        assert!(default_kernels[2].iter().any(|p| p[0] > 0.0), "a black frame");
        for (glossy_replay, gpu_scene, what) in [(true, &small, "with the re-trace"), (false, &padded, "from storage")]
        {
            let other = frames(glossy_replay, gpu_scene, &mut backend);
            assert!(
                default_kernels == other,
                "{} {reuse_order:?}: the kernels {what} render other frames",
                method.name()
            );
        }
    }
}

/// The stratified film sequence spreads a pixel's successive samples over the pixel:
/// with only the camera segment (max depth 1) the image is the emission seen directly,
/// whose only noise is where in the pixel the ray starts (the light's edges). Averaged
/// over 16 samples, that noise's variance over seeds is far below the white sequence's.
#[test]
fn stratified_film_averages_away_the_anti_aliasing_noise() {
    let Some(mut backend) = strata_tests::vulkan_backend("stratified_film_averages_away_the_anti_aliasing_noise")
    else {
        assert!(!gpu_required());
        return;
    };
    let scene = default_scene();
    let gpu_scene = GpuScene::build(&scene).unwrap();
    let mut variance = |film: Film| {
        let images: Vec<RgbImage> = (0..32)
            .map(|seed| {
                let render = RenderSettings { film, max_depth: 1, ..settings(&scene, 700 + seed) };
                strata_render::render::render(&mut backend, &gpu_scene, &render, 16, |_| {}).unwrap()
            })
            .collect();
        let n = images.len() as f64;
        (0..images[0].pixels.len())
            .map(|i| {
                let values: Vec<f64> = images.iter().map(|image| f64::from(image.pixels[i][0])).collect();
                let mean = values.iter().sum::<f64>() / n;
                values.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / (n - 1.0)
            })
            .sum::<f64>()
    };
    let (white, stratified) = (variance(Film::White), variance(Film::Stratified));
    eprintln!("anti-aliasing variance over 16 samples: white {white:.4e}, stratified {stratified:.4e}");
    assert!(white > 0.0, "the light's edges are in view");
    assert!(stratified < 0.5 * white, "stratified {stratified:.3e} against white {white:.3e}");
}

#[test]
fn bad_restir_settings_are_errors_naming_the_value() {
    let mut backend = strata_backends::cpu_backend::CpuBackend::new(Default::default()).unwrap();
    let scene = default_scene();
    let gpu_scene = GpuScene::build(&scene).unwrap();
    let render = settings(&scene, 1);
    let cases: [(RestirSettings, &str); 12] = [
        (
            RestirSettings {
                selection: SelectionSettings { block_size: 12, ..Default::default() },
                ..Default::default()
            },
            "block_size = 12",
        ),
        (RestirSettings { min_roughness: f32::NAN, ..Default::default() }, "min roughness NaN"),
        (RestirSettings { min_distance: -1.0, ..Default::default() }, "min distance -1"),
        (
            RestirSettings {
                selection: SelectionSettings { candidates: 5, ..Default::default() },
                ..Default::default()
            },
            "candidates = 5",
        ),
        (RestirSettings { temporal_cap: 0.5, ..Default::default() }, "temporal cap 0.5"),
        (RestirSettings { temporal_candidates: 5, ..Default::default() }, "temporal candidates 5"),
        (RestirSettings { specular_chain: 17, ..Default::default() }, "specular chain 17"),
        (RestirSettings { disc_radius: f32::NAN, ..Default::default() }, "disc radius NaN"),
        (RestirSettings { disc_radius: 1e9, ..Default::default() }, "disc radius 1000000000"),
        (RestirSettings { boiling_filter: f32::NAN, ..Default::default() }, "boiling filter NaN"),
        (RestirSettings { boiling_filter: -0.1, ..Default::default() }, "boiling filter -0.1"),
        (RestirSettings { boiling_filter: 1.5, ..Default::default() }, "boiling filter 1.5"),
    ];
    for (restir, expected) in cases {
        let error = RestirRenderer::new(&mut backend, &gpu_scene, &render, restir, 1.0).err().unwrap().to_string();
        assert!(error.contains(expected), "{error}");
    }
    let mut empty = settings(&scene, 1);
    empty.camera.width = 0;
    let error = RestirRenderer::new(&mut backend, &gpu_scene, &empty, RestirSettings::default(), 1.0)
        .err()
        .unwrap()
        .to_string();
    assert!(error.contains("0x32"), "{error}");
}

/// With the camera orbiting, reprojection and the disocclusion test decide what is
/// reused, and the block grid shifts every frame: frames 3 to 6 of independent renders
/// match the path-traced images of those frames' cameras (their mean, both sides), in
/// both orders and with permutation sampling.
#[test]
fn temporal_reuse_with_a_moving_camera_stays_unbiased() {
    let Some(mut backend) = strata_tests::vulkan_backend("temporal_reuse_with_a_moving_camera_stays_unbiased") else {
        assert!(!gpu_required());
        return;
    };
    let scene = default_scene();
    let base = settings(&scene, 0).camera;
    let path = CameraPath::orbit(&base, 1.5);
    let cameras: Vec<Camera> = (FIRST_SCORED_FRAME - 1..6).map(|frame| path.camera_at(&base, frame)).collect();
    let reference = reference_along(&mut backend, &scene, 512, &cameras);
    // The defaults for a moving camera (`strata compare` resolves `--reuse-order auto` so:
    // the spatial-first order).
    let restir = RestirSettings {
        selection: SelectionSettings { block_shift: true, ..blocks_of_8() },
        ..RestirSettings::default()
    }
    .for_camera(true);
    assert_eq!(restir.reuse_order, ReuseOrder::SpatialFirst);
    // Three settings of 48 renders each (64 before there were three): the default for a
    // moving camera, the temporal-first order (what a renderer not told of the motion
    // runs), and permutation sampling (`--permutation-sampling`: each pixel merges the
    // history of a pixel 1 or 3 away per axis from where it reprojects).
    let temporal_first = RestirSettings { reuse_order: ReuseOrder::TemporalFirst, ..restir };
    let permuted = RestirSettings { permutation_sampling: true, ..restir };
    for (restir, what) in [
        (restir, "strata with temporal reuse, spatial-first, orbiting camera, shifting grid, frames 3-6"),
        (temporal_first, "strata with temporal reuse, temporal-first, orbiting camera, shifting grid, frames 3-6"),
        (permuted, "strata with permutation sampling, spatial-first, orbiting camera, shifting grid, frames 3-6"),
    ] {
        let ours = restir_frames_along(&mut backend, &scene, restir, 1..49, 6, &path, |render| render);
        assert_unbiased_with_power(what, &ours, &reference, POWER_MOVING_CAMERA);
    }
}

/// RTXDI's boiling filter (`--boiling-filter`) is biased by design, and these tests see
/// it: at strength 1 (a reservoir whose W exceeds its workgroup's mean is emptied) the
/// default room's frames 3 to 6 are darker than the reference by far more than the test
/// resolves (the measured bias is printed; BENCHMARKS.md "What the viewer sees"). The
/// same renders without the filter are unbiased (temporal_reuse_stays_unbiased_*).
#[test]
fn the_boiling_filter_darkens_the_image_as_documented() {
    let Some(mut backend) = strata_tests::vulkan_backend("the_boiling_filter_darkens_the_image_as_documented") else {
        assert!(!gpu_required());
        return;
    };
    let scene = default_scene();
    let reference = default_reference(&mut backend);
    let restir = RestirSettings { boiling_filter: 1.0, selection: blocks_of_8(), ..RestirSettings::default() };
    // Half the renders of the unbiasedness tests: a bias of this size needs no more
    // (pooled z -20.0 with 64 renders, -15.8 with 32).
    let ours = restir_frames(&mut backend, &scene, restir, 1..33, 6);
    let (filtered, _) = ours.total();
    let (truth, _) = reference.total();
    let pooled = pooled_z(&ours, &reference);
    eprintln!(
        "boiling filter at strength 1, strata, frames 3-6: {:+.2} % against the reference (pooled z {pooled:.1}, \
         resolving {:.2} %)",
        100.0 * (filtered / truth - 1.0),
        100.0 * detectable_bias(&ours, &reference)
    );
    assert!(pooled < -4.5, "the boiling filter's bias went unseen: pooled z {pooled:.2}");
    // And it is the documented bias, not a filter that empties far more (or a wrong factor).
    let bias = filtered / truth - 1.0;
    assert!((-0.15..-0.04).contains(&bias), "the boiling filter's bias is {:+.2} %, documented -9 %", 100.0 * bias);
}

/// The two decorrelation settings reach their kernels: on a still camera every resampling
/// pixel's temporal source is the pixel itself without permutation sampling, and with it
/// a third or more of the sources move (to a pixel 1 or 3 away per axis; the others fail
/// the similarity test there and keep theirs) while almost every previous pixel still
/// feeds one pixel; the boiling filter at strength 1 empties some of the merged
/// reservoirs (those above their workgroup's mean W) and not most.
#[test]
fn the_decorrelation_settings_reach_the_kernels() {
    let Some(mut backend) = strata_tests::vulkan_backend("the_decorrelation_settings_reach_the_kernels") else {
        assert!(!gpu_required());
        return;
    };
    let scene = default_scene();
    let gpu_scene = GpuScene::build(&scene).unwrap();
    let render = settings(&scene, 5);
    let last_frame = |backend: &mut dyn Backend, restir: RestirSettings| {
        let mut renderer = RestirRenderer::new(backend, &gpu_scene, &render, restir, scene.extent()).unwrap();
        for _ in 0..3 {
            renderer.render_frame(backend, None).unwrap();
        }
        let buffers = renderer.frame_buffers(backend).unwrap();
        renderer.destroy(backend).unwrap();
        buffers
    };
    let restir =
        RestirSettings { selection: blocks_of_8(), reuse_order: ReuseOrder::SpatialFirst, ..Default::default() };
    let plain = last_frame(&mut backend, restir);
    let permuted = last_frame(&mut backend, RestirSettings { permutation_sampling: true, ..restir });
    let with_source: Vec<usize> =
        (0..plain.temporal_sources.len()).filter(|&p| plain.temporal_sources[p] != u32::MAX).collect();
    assert!(with_source.len() > plain.temporal_sources.len() / 2, "most pixels have a history");
    assert!(with_source.iter().all(|&p| plain.temporal_sources[p] == p as u32), "a still camera reprojects in place");
    let moved = with_source.iter().filter(|&&p| permuted.temporal_sources[p] != p as u32).count();
    // At 32 x 32 a pixel 1 or 3 away often lies on another object or at another depth, and
    // the pixel keeps its reprojected source (45 % moved when this was written).
    assert!(moved * 3 > with_source.len(), "permutation moved only {moved} of {} sources", with_source.len());
    let mut feeds = std::collections::HashMap::new();
    for &p in &with_source {
        *feeds.entry(permuted.temporal_sources[p]).or_insert(0u32) += 1;
    }
    let shared = feeds.values().filter(|&&n| n > 1).count();
    eprintln!(
        "permutation: {moved} of {} sources moved, {shared} of {} previous pixels feed two or more",
        with_source.len(),
        feeds.len()
    );
    assert!(shared * 10 < feeds.len(), "{shared} of {} previous pixels feed more than one pixel", feeds.len());
    let boiled = last_frame(&mut backend, RestirSettings { boiling_filter: 1.0, ..restir });
    let alive =
        |buffers: &strata_render::restir::FrameBuffers| buffers.reservoirs.iter().filter(|r| r.weight > 0.0).count();
    let (before, after) = (alive(&plain), alive(&boiled));
    eprintln!("boiling filter at strength 1: {after} of {before} reservoirs kept");
    assert!(after < before && after * 2 > before, "the boiling filter left {after} of {before} reservoirs");
}

/// The default room with what the diffuse scene never exercises: its tall box glass
/// (primary hits resample behind it through a smooth chain, or path-trace alone without
/// chains; candidates on it stay private), its short box a GGX conductor of alpha 0.3 and
/// its back wall a glossy one of alpha 0.1 (both resampled: from the default
/// `min_roughness` of 0.05 up), its red wall a conductor of alpha 0.03 (below it: a smooth
/// vertex, resampled behind or path-traced alone like the glass), and an environment map
/// shining in through the open front (candidates reconnected by direction).
fn glass_metal_environment_scene() -> Scene {
    use strata_render::scene::Material;
    let mut scene = default_scene();
    let metal = |alpha| Material::RoughConductor { alpha, eta: [0.2, 0.9, 1.1], k: [3.9, 2.4, 2.2], two_sided: true };
    scene.materials.extend([Material::Dielectric { int_ior: 1.5, ext_ior: 1.0 }, metal(0.3), metal(0.1), metal(0.03)]);
    let count = scene.materials.len();
    for shape in &mut scene.shapes {
        match shape.name.as_str() {
            "tall box" => shape.material = count - 4,
            "short box" => shape.material = count - 3,
            "back" => shape.material = count - 2,
            "left" => shape.material = count - 1,
            _ => {}
        }
    }
    scene.environment = Some(strata_check::fuzz::build::generated_environment(2.0));
    scene
}

/// Frames of each temporal render in the glass/metal/environment room, scored from frame 3
/// on. Its frames spread far more than the default room's (a few pixels see the light
/// through glass or off the near-mirror wall), and the mean of frames 3-5 spread as much as
/// that of 3-6 (0.92-1.00 times the variance over 24 renders, strata and restir-disc; the
/// default room's 1.2): the sixth frame bought no power here.
const GLASS_TEMPORAL_FRAMES: u32 = 5;

/// Every method stays unbiased where glass, glossy and rough metal and an environment
/// map decide which pixels and candidates are reused, with and without temporal reuse,
/// shading the kept sample or the final resampling's expectation, with smooth chains (the
/// default) and without, with random replay at the alpha-0.03 wall (strata shading the
/// sample, the baselines the expectation) and without; a 3 % bias is caught on the same
/// scene, with replay.
/// One test per method (they share the cores), all against one reference. Without
/// temporal reuse restir's three runs are held to the reference, and restir-disc's three
/// (the same settings) and strata's without chains are paired with them frame by frame
/// ([`assert_same_mean_with_power`], [`GLASS_PARTNERS`]); strata's other two, with
/// settings restir does not run, are held to the reference.
fn glass_metal_and_environment_reuse_stays_unbiased(test: &str, method: Method) {
    static REFERENCE: OnceLock<RegionStats> = OnceLock::new();
    let Some(mut backend) = strata_tests::vulkan_backend(test) else {
        assert!(!gpu_required());
        return;
    };
    let scene = glass_metal_environment_scene();
    let reference = REFERENCE.get_or_init(|| reference(&mut backend, &scene, 2048)).clone();
    for (shading, specular_chain, glossy_replay) in glass_runs(method) {
        let restir = RestirSettings {
            method,
            shading,
            specular_chain,
            glossy_replay,
            temporal: false,
            selection: blocks_of_8(),
            ..RestirSettings::default()
        };
        let partners: Vec<RestirSettings> = if method == Method::Restir {
            GLASS_PARTNERS
                .iter()
                .map(|&partner| RestirSettings { method: partner, ..restir })
                .filter(|partner| glass_runs(partner.method).contains(&(shading, specular_chain, glossy_replay)))
                .collect()
        } else {
            Vec::new()
        };
        // Paired with restir in restir's test (below): nothing to render here.
        let paired_elsewhere = GLASS_PARTNERS.contains(&method)
            && glass_runs(Method::Restir).contains(&(shading, specular_chain, glossy_replay));
        if !paired_elsewhere {
            // restir's first seeds with its partners in lockstep, then the rest alone: the
            // same frames restir_frames renders over 1..9.
            let paired = paired_differences(&mut backend, &scene, restir, &partners, PAIRED_SEEDS, 32, |render| render);
            let ours = restir_frames(&mut backend, &scene, restir, PAIRED_SEEDS.end..9, 32).merged(&paired.base);
            let what = format!("{} without temporal reuse, glass/metal/environment", glass_run_name(&restir));
            assert_unbiased_with_power(&what, &ours, &reference, POWER_GLASS);
            if method == Method::Strata && shading == Shading::Sample {
                let pooled = pooled_z(&ours.scaled(1.03), &reference);
                assert!(pooled > 4.5, "a 3 % bias gives pooled z {pooled:.2} only");
            }
            for (partner, difference) in partners.iter().zip(&paired.differences) {
                let what =
                    format!("{} less restir, without temporal reuse, glass/metal/environment", glass_run_name(partner));
                assert_same_mean_with_power(&what, difference, &reference, POWER_GLASS_PAIRED);
                // The paired test can fail: the partner's frames 3 % too bright are caught.
                let (total, _) = reference.total();
                let brighter = difference.with_total_shifted(0.03 * total);
                assert!(pooled_z(&brighter, &RegionStats::zero()) > 4.5, "{what}: a 3 % difference goes unnoticed");
            }
        }
        let restir = RestirSettings { temporal: true, ..restir };
        let ours = restir_frames(&mut backend, &scene, restir, TEMPORAL_RENDERS, GLASS_TEMPORAL_FRAMES);
        let what = format!(
            "{} with temporal reuse, frames 3-{GLASS_TEMPORAL_FRAMES}, glass/metal/environment",
            glass_run_name(&restir)
        );
        assert_unbiased_with_power(&what, &ours, &reference, POWER_GLASS_TEMPORAL);
    }
}

/// The methods whose runs without temporal reuse in the glass/metal/environment room are
/// paired with restir's where restir runs the same setting. Their difference from restir
/// spreads about a tenth as much as their frames (0.09-0.13 of the variance per region,
/// 0.10-0.11 of the image total's; 64 frames of each of restir's three settings,
/// restir-disc and strata against restir), so 2 renders of 32 frames resolve more finely
/// than the 8 of 32 each ran against the reference before (docs/benchmarks/ci-time.md,
/// "Compiling less for the tests, and the glass room's pairs").
const GLASS_PARTNERS: [Method; 2] = [Method::RestirDisc, Method::Strata];

/// A glass-room run's method and (shading, smooth chain, random replay), as its messages
/// name it.
fn glass_run_name(settings: &RestirSettings) -> String {
    format!(
        "{} ({:?}, chain {}, replay {})",
        settings.method.name(),
        settings.shading,
        settings.specular_chain,
        settings.glossy_replay
    )
}

/// The (shading, smooth chain, random replay) of `method`'s runs in the
/// glass/metal/environment room: random replay in one of the runs with chains, each
/// method with one shading (a replayed candidate costs a traced path per weighing: two
/// runs each took CI +5 min).
fn glass_runs(method: Method) -> [(Shading, u32, bool); 3] {
    let chains = RestirSettings::default().specular_chain;
    let replay_with = if method == Method::Strata { Shading::Sample } else { Shading::Expectation };
    [
        (Shading::Sample, chains, replay_with == Shading::Sample),
        (Shading::Expectation, chains, replay_with == Shading::Expectation),
        (Shading::Expectation, 0, false),
    ]
}

#[test]
fn glass_metal_and_environment_reuse_stays_unbiased_restir() {
    let test = "glass_metal_and_environment_reuse_stays_unbiased_restir";
    glass_metal_and_environment_reuse_stays_unbiased(test, Method::Restir);
}

#[test]
fn glass_metal_and_environment_reuse_stays_unbiased_restir_disc() {
    let test = "glass_metal_and_environment_reuse_stays_unbiased_restir_disc";
    glass_metal_and_environment_reuse_stays_unbiased(test, Method::RestirDisc);
}

#[test]
fn glass_metal_and_environment_reuse_stays_unbiased_strata() {
    let test = "glass_metal_and_environment_reuse_stays_unbiased_strata";
    glass_metal_and_environment_reuse_stays_unbiased(test, Method::Strata);
}

/// The default room with a mirror floor (a GGX conductor of alpha 0.01, below the default
/// `min_roughness`) and paths of at most 3 segments: a pixel seeing the floor resamples at
/// the back wall or a box behind it (segment 2), whose candidates, reached by segment 3,
/// can only bring emission, while a pixel seeing that wall or box directly resamples at
/// segment 1 and its candidates bring one bounce more.
fn mirror_floor_short_paths_scene() -> Scene {
    let mut scene = Scene { max_depth: 3, rr_depth: 3, ..default_scene() };
    scene.materials.push(near_mirror());
    let mirror = scene.materials.len() - 1;
    scene.shapes.iter_mut().filter(|shape| shape.name == "floor").for_each(|shape| shape.material = mirror);
    scene
}

/// Pixels share candidates only when their paths reach their resampling vertices with the
/// same segment (`same_segment` in `restir/reservoir.wgsl`): a candidate's reflected
/// radiance holds the segments its own path had left. In the mirror-floor room with paths
/// of 3 segments every candidate of a segment-2 pixel reflects nothing (the segment after
/// it is the last), so a reservoir of a segment-2 pixel holding a sample with reflected
/// light took a segment-1 pixel's candidate. Checked after the spatial selection and
/// after the temporal merge (own and four drawn previous reservoirs), over 6 frames of
/// every method, with object masking off so that every block mixes both kinds of pixel.
/// (The mixing is real: segment-1 samples with reflected light are checked to be there.)
/// The bias such sharing adds is below what the statistical test next to it resolves:
/// that test passes with the rule removed.
#[test]
fn pixels_share_candidates_only_at_the_same_segment() {
    let Some(mut backend) = strata_tests::vulkan_backend("pixels_share_candidates_only_at_the_same_segment") else {
        assert!(!gpu_required());
        return;
    };
    let scene = mirror_floor_short_paths_scene();
    let gpu_scene = GpuScene::build(&scene).unwrap();
    for method in [Method::Strata, Method::Restir, Method::RestirDisc] {
        let selection = SelectionSettings { masking: false, ..blocks_of_8() };
        // Four drawn temporal reservoirs besides the own one: the temporal histogram mixes
        // segments as the spatial one does.
        let restir = RestirSettings { method, selection, temporal_candidates: 4, ..RestirSettings::default() };
        let mut renderer =
            RestirRenderer::new(&mut backend, &gpu_scene, &settings(&scene, 11), restir, scene.extent()).unwrap();
        let (mut behind, mut reflecting) = (0usize, 0usize);
        for frame in 1..=6 {
            renderer.render_frame(&mut backend, None).unwrap();
            let buffers = renderer.frame_buffers(&mut backend).unwrap();
            for (pass, reservoirs) in [("selection", &buffers.selected), ("temporal merge", &buffers.reservoirs)] {
                for (pixel, (p, r)) in buffers.primaries.iter().zip(reservoirs.iter()).enumerate() {
                    let resamples = p.flags & strata_kernels::restir_types::PRIMARY_RESAMPLE != 0;
                    if !resamples || r.weight.is_nan() || r.weight <= 0.0 {
                        continue;
                    }
                    let reflected = r.sample.reflected.iter().any(|&v| v != 0.0);
                    match p.segment {
                        1 => reflecting += usize::from(reflected),
                        2 => {
                            behind += 1;
                            assert!(
                                !reflected,
                                "{}, frame {frame}, {pass}: pixel {pixel} resampling at segment 2 holds a sample \
                                 with reflected light {:?}: another segment's candidate",
                                method.name(),
                                r.sample.reflected
                            );
                        }
                        segment => panic!("pixel {pixel} resamples at segment {segment} with paths of 3"),
                    }
                }
            }
        }
        renderer.destroy(&mut backend).unwrap();
        eprintln!("{}: {behind} segment-2 reservoirs, {reflecting} segment-1 ones with reflected light", method.name());
        assert!(behind > 6 * 2 * 40, "{}: only {behind} segment-2 reservoirs over 6 frames", method.name());
        assert!(reflecting > 6 * 2 * 200, "{}: only {reflecting} segment-1 samples reflect light", method.name());
    }
}

/// Smooth chains on short paths stay unbiased: in the mirror-floor room with paths of 3
/// segments (above), for every method without temporal reuse and with it (own and four
/// drawn previous reservoirs), object masking off so that blocks mix pixels resampling at
/// segments 1 and 2. restir is held to the reference; strata and restir-disc are paired
/// with restir frame by frame without temporal reuse ([`assert_same_mean_with_power`]) and
/// render by render with it ([`temporal_pairs`]).
#[test]
fn smooth_chains_on_short_paths_stay_unbiased() {
    let Some(mut backend) = strata_tests::vulkan_backend("smooth_chains_on_short_paths_stay_unbiased") else {
        assert!(!gpu_required());
        return;
    };
    let scene = mirror_floor_short_paths_scene();
    let reference = reference(&mut backend, &scene, 2048);
    let selection = SelectionSettings { masking: false, ..blocks_of_8() };
    let accumulated = |method| RestirSettings { method, temporal: false, selection, ..RestirSettings::default() };
    // Without temporal reuse: restir against the reference, strata and restir-disc paired
    // with it frame by frame.
    let ours = restir_frames(&mut backend, &scene, accumulated(Method::Restir), 1..9, 32);
    assert_unbiased_with_power("restir, 3 segments, without temporal reuse", &ours, &reference, POWER_SHORT_PATHS);
    let variants = [accumulated(Method::Strata), accumulated(Method::RestirDisc)];
    let base = accumulated(Method::Restir);
    let differences = paired_differences(&mut backend, &scene, base, &variants, PAIRED_SEEDS, 32, |r| r).differences;
    for (variant, difference) in variants.iter().zip(&differences) {
        let what = format!("{} less restir, 3 segments, without temporal reuse", variant.method.name());
        assert_same_mean_with_power(&what, difference, &reference, POWER_PAIRED);
    }
    // With temporal reuse, four drawn previous reservoirs besides the own one (their
    // histogram mixes segments too): restir against the reference, strata and restir-disc
    // paired with it ([`temporal_pairs`]).
    let temporal = |method| RestirSettings { temporal: true, temporal_candidates: 4, ..accumulated(method) };
    let variants =
        [(temporal(Method::Strata), PAIRED_TEMPORAL_FRAMES), (temporal(Method::RestirDisc), PAIRED_TEMPORAL_FRAMES)];
    let (ours, differences) = temporal_pairs(
        &mut backend,
        &scene,
        temporal(Method::Restir),
        (TEMPORAL_RENDERS, BASE_TEMPORAL_FRAMES),
        &variants,
        |r| r,
    );
    let what = format!("restir, 3 segments, temporal reuse + 4 drawn, frames 3-{BASE_TEMPORAL_FRAMES}");
    assert_unbiased_with_power(&what, &ours, &reference, POWER_SHORT_PATHS_TEMPORAL);
    for ((variant, _), difference) in variants.iter().zip(&differences) {
        let what = format!("{} less restir, 3 segments, temporal reuse + 4 drawn, frame 3", variant.method.name());
        assert_same_mean_with_power(&what, difference, &reference, POWER_TEMPORAL_PAIRED);
    }
}

/// Both film sequences keep every method unbiased. The default, [`Film::Stratified`]
/// (each pixel's frames take successive points of its own R2 sequence from a random
/// start), is what the other tests here and `reference` use; this one checks the white
/// sequence (independent uniform points, the default before 2026-11-25) against that
/// reference: the path tracer, and every method with temporal reuse over independent
/// renders (restir's frames 3 to 6, the others paired with it on frame 3) and accumulated
/// over 64 frames (restir against the reference, strata and restir-disc paired with
/// restir: render by render with temporal reuse, [`temporal_pairs`], frame by frame
/// without). A start shared by every pixel and seed was seen to fail here (the references
/// then disagree).
#[test]
fn both_film_sequences_stay_unbiased() {
    let Some(mut backend) = strata_tests::vulkan_backend("both_film_sequences_stay_unbiased") else {
        assert!(!gpu_required());
        return;
    };
    let scene = default_scene();
    let reference = default_reference(&mut backend);
    let gpu_scene = GpuScene::build(&scene).unwrap();
    assert_eq!(settings(&scene, 0).film, Film::Stratified, "the reference's film is the default");
    let mut white_reference = RegionStats::new();
    for batch in 0..512 {
        let render = RenderSettings { film: Film::White, ..settings(&scene, 90_000 + batch) };
        white_reference.add(&strata_render::render::render(&mut backend, &gpu_scene, &render, 4, |_| {}).unwrap());
    }
    assert_unbiased("path tracer, white film", &white_reference, &reference);
    let white = |render| RenderSettings { film: Film::White, ..render };
    let settings =
        |method, temporal| RestirSettings { method, temporal, selection: blocks_of_8(), ..RestirSettings::default() };
    // With temporal reuse: restir against the reference, strata and restir-disc paired
    // with it ([`temporal_pairs`]).
    let variants = [
        (settings(Method::Strata, true), PAIRED_TEMPORAL_FRAMES),
        (settings(Method::RestirDisc, true), PAIRED_TEMPORAL_FRAMES),
    ];
    let (ours, differences) =
        temporal_pairs(&mut backend, &scene, settings(Method::Restir, true), (TEMPORAL_RENDERS, 6), &variants, white);
    // Six frames, not BASE_TEMPORAL_FRAMES: at frames 3-5 this run resolved 4.16 % against
    // its stated 5.2 (3.37 % at 3-6), too close to the bound to pass every run.
    assert_unbiased_with_power("restir white film, temporal, frames 3-6", &ours, &reference, POWER_FILM_TEMPORAL);
    for ((variant, _), difference) in variants.iter().zip(&differences) {
        let what = format!("{} less restir, white film, temporal, frame 3", variant.method.name());
        assert_same_mean_with_power(&what, difference, &reference, POWER_TEMPORAL_PAIRED);
    }
    // Accumulated: restir against the reference, strata and restir-disc paired with it.
    let restir = settings(Method::Restir, false);
    let ours = restir_frames_along(&mut backend, &scene, restir, 1..9, 64, &CameraPath::Static, white);
    assert_unbiased_with_power("restir white film, accumulated", &ours, &reference, POWER_ACCUMULATED);
    let variants = [settings(Method::Strata, false), settings(Method::RestirDisc, false)];
    let differences = paired_differences(&mut backend, &scene, restir, &variants, PAIRED_SEEDS, 32, white).differences;
    for (variant, difference) in variants.iter().zip(&differences) {
        let what = format!("{} less restir, white film, accumulated", variant.method.name());
        assert_same_mean_with_power(&what, difference, &reference, POWER_PAIRED);
    }
}
