//! Realistic compute workloads of the kinds engines and public samples run — a tiled
//! matrix multiply, a two-level prefix sum, a histogram with reductions, a separable
//! blur, n-body and boids steps, Collatz step counts, a Mandelbrot set, a bitonic sort,
//! an f32 tree reduction, a hash-based Monte Carlo estimate with signed integer math, a
//! small sphere ray tracer, linear blend skinning and per-pixel linked lists (as
//! order-independent transparency builds them) — each run on the CPU interpreter, on
//! wgpu (lavapipe) and on ash. The interpreter must give exactly what a small Rust reference computes in
//! the same order; the Vulkan backends must agree with the interpreter bit for bit on
//! integer outputs and within a stated ULP bound on float outputs (a GPU may contract a
//! multiply and an add into a fused multiply-add, or reassociate), and on Mandelbrot
//! escape counts for all but a small share of pixels. Wall times per backend are
//! printed (not asserted).

use std::time::Instant;

use strata_backends::ash_backend::{AshBackend, AshOptions, SpirvSource};
use strata_backends::backend::{download, upload};
use strata_backends::cpu_backend::{CpuBackend, CpuOptions};
use strata_backends::{Backend, BackendError, Bind, BufferId, gpu_required};
use strata_check::{Agreement, Compare, Output, compare_outputs};
use strata_kernels::Kernel;

fn kernel(path: &str, source: &str) -> Kernel {
    Kernel::from_wgsl(path, source.into(), "main", false).unwrap_or_else(|e| panic!("{path}: {e}"))
}

fn open_ash(test: &str) -> Option<AshBackend> {
    match AshBackend::new(AshOptions {
        validation: true,
        source: SpirvSource::Naga,
        subgroups: false,
        ..Default::default()
    }) {
        Ok(backend) => Some(backend),
        Err(error @ BackendError::NoAdapter { .. }) if !gpu_required() => {
            eprintln!("SKIPPED {test} on ash: {error} (set STRATA_REQUIRE_GPU=1 to make this a failure)");
            None
        }
        Err(error) => panic!("{test}: ash backend: {error}"),
    }
}

/// Runs `run` on the interpreter, then on wgpu and ash when there is a Vulkan device;
/// returns (backend, output words) with the interpreter first, and prints wall times
/// (wgpu twice: the first run includes pipeline creation).
fn run_everywhere(test: &str, run: impl Fn(&mut dyn Backend) -> Vec<u32>) -> Vec<(&'static str, Vec<u32>)> {
    let mut results = Vec::new();
    let mut cpu = CpuBackend::new(CpuOptions::default()).unwrap();
    let start = Instant::now();
    results.push(("interpreter", run(&mut cpu)));
    let interpreter = start.elapsed();
    let Some(mut wgpu) = strata_tests::vulkan_backend(test) else {
        eprintln!("{test}: interpreter {:.1} ms", interpreter.as_secs_f64() * 1e3);
        return results;
    };
    let start = Instant::now();
    results.push(("wgpu", run(&mut wgpu)));
    let wgpu_first = start.elapsed();
    let start = Instant::now();
    let again = run(&mut wgpu);
    let wgpu_second = start.elapsed();
    assert_eq!(again, results[1].1, "{test}: wgpu gives the same output twice");
    if let Some(mut ash) = open_ash(test) {
        let start = Instant::now();
        results.push(("ash", run(&mut ash)));
        let ash_time = start.elapsed();
        let messages = ash.validation_messages();
        assert!(messages.is_empty(), "{test}: validation layer:\n{}", messages.join("\n"));
        eprintln!("{test}: ash (lavapipe) {:.1} ms", ash_time.as_secs_f64() * 1e3);
    }
    eprintln!(
        "{test}: interpreter {:.1} ms, wgpu (lavapipe) {:.1} ms first / {:.1} ms second run",
        interpreter.as_secs_f64() * 1e3,
        wgpu_first.as_secs_f64() * 1e3,
        wgpu_second.as_secs_f64() * 1e3
    );
    results
}

/// Compares the interpreter's words with another backend's under `compare`.
fn agree(test: &str, backend: &str, interpreter: &[u32], other: &[u32], compare: Compare) -> Agreement {
    let got = [Output { name: "out", words: interpreter.to_vec(), compare: Compare::Exact }];
    let want = [Output { name: "out", words: other.to_vec(), compare }];
    let agreement =
        compare_outputs(&got, &want).unwrap_or_else(|mismatch| panic!("{test}: interpreter vs {backend}: {mismatch}"));
    eprintln!(
        "{test}: interpreter vs {backend}: max {} ULP, {} of {} floats beyond the bound",
        agreement.max_ulp, agreement.outside, agreement.floats
    );
    agreement
}

/// Checks the interpreter (first result) against the reference bit for bit, then every
/// other backend against the interpreter under `compare`.
fn check(test: &str, results: &[(&'static str, Vec<u32>)], reference: &[u32], compare: Compare) {
    let (_, interpreter) = &results[0];
    assert_eq!(interpreter.len(), reference.len(), "{test}: output length");
    let differing: Vec<usize> = (0..reference.len()).filter(|&i| interpreter[i] != reference[i]).collect();
    assert!(
        differing.is_empty(),
        "{test}: the interpreter differs from the Rust reference at {} of {} words, first at {}: {:#x} vs {:#x}",
        differing.len(),
        reference.len(),
        differing[0],
        interpreter[differing[0]],
        reference[differing[0]]
    );
    for (backend, words) in &results[1..] {
        agree(test, backend, interpreter, words, compare);
    }
}

fn bits(values: &[f32]) -> Vec<u32> {
    values.iter().map(|v| v.to_bits()).collect()
}

/// A small deterministic generator (PCG-like LCG, high bits).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u32 {
        self.0 = self.0.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 32) as u32
    }

    fn unit(&mut self) -> f32 {
        (self.next() >> 8) as f32 / (1u32 << 24) as f32
    }

    fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.unit()
    }
}

fn dispatch(backend: &mut dyn Backend, kernel: &Kernel, buffers: &[BufferId], workgroups: [u32; 3]) {
    let binds: Vec<Bind> = buffers.iter().enumerate().map(|(i, &b)| Bind::new(i as u32, b)).collect();
    backend.dispatch(kernel, &binds, workgroups).unwrap();
}

fn destroy(backend: &mut dyn Backend, buffers: &[BufferId]) {
    for &buffer in buffers {
        backend.destroy_buffer(buffer).unwrap();
    }
}

// ---------------------------------------------------------------------------------------
// 1. Tiled matrix multiply.

const MATMUL: &str = include_str!("../data/workloads/matmul.wgsl");

/// C = A * B summed as the kernel does: k in order, padded with zero products up to a
/// multiple of 16.
fn matmul_reference(m: usize, k: usize, n: usize, a: &[f32], b: &[f32]) -> Vec<f32> {
    let mut c = vec![0.0f32; m * n];
    for row in 0..m {
        for col in 0..n {
            let mut acc = 0.0f32;
            for kk in 0..k.div_ceil(16) * 16 {
                let (va, vb) = if kk < k { (a[row * k + kk], b[kk * n + col]) } else { (0.0, 0.0) };
                acc += va * vb;
            }
            c[row * n + col] = acc;
        }
    }
    c
}

#[test]
fn tiled_matrix_multiply_agrees_with_the_reference_and_lavapipe() {
    let kernel = kernel("matmul.wgsl", MATMUL);
    for (m, k, n) in [(64usize, 48usize, 80usize), (61, 45, 77)] {
        let test = format!("matmul {m}x{k} * {k}x{n}");
        let mut rng = Rng((m * k * n) as u64);
        // Positive inputs: no cancellation, so a fused multiply-add on the GPU moves a
        // sum by a few ULPs at most.
        let a: Vec<f32> = (0..m * k).map(|_| rng.range(0.0, 1.0)).collect();
        let b: Vec<f32> = (0..k * n).map(|_| rng.range(0.0, 2.0)).collect();
        let reference = bits(&matmul_reference(m, k, n, &a, &b));
        let results = run_everywhere(&test, |backend| {
            let dims = upload(backend, "dims", &[m as u32, k as u32, n as u32, 0]).unwrap();
            let a = upload(backend, "a", &a).unwrap();
            let b = upload(backend, "b", &b).unwrap();
            let c = backend.create_buffer("c", (m * n * 4) as u64).unwrap();
            dispatch(backend, &kernel, &[dims, a, b, c], [n.div_ceil(16) as u32, m.div_ceil(16) as u32, 1]);
            let words = download(backend, c).unwrap();
            destroy(backend, &[dims, a, b, c]);
            words
        });
        // 48 products per output; contraction skips one rounding per step, a relative
        // error of about 2^-24 each: 8 ULP is ample.
        check(&test, &results, &reference, Compare::Float { ulp: 8, max_outside: 0.0 });
    }
}

// ---------------------------------------------------------------------------------------
// 2. Two-level prefix sum.

const SCAN_BLOCKS: &str = include_str!("../data/workloads/scan_blocks.wgsl");
const ADD_OFFSETS: &str = include_str!("../data/workloads/add_offsets.wgsl");

#[test]
fn two_level_prefix_sum_is_exact_on_every_backend() {
    let scan = kernel("scan_blocks.wgsl", SCAN_BLOCKS);
    let add = kernel("add_offsets.wgsl", ADD_OFFSETS);
    let count = 256usize * 37 + 100;
    let blocks = count.div_ceil(256);
    let mut rng = Rng(7);
    // 20-bit values: the running sum wraps around u32 several times.
    let input: Vec<u32> = (0..count).map(|_| rng.next() >> 12).collect();
    let reference: Vec<u32> = input
        .iter()
        .scan(0u32, |sum, &v| {
            *sum = sum.wrapping_add(v);
            Some(*sum)
        })
        .collect();
    let results = run_everywhere("prefix sum", |backend| {
        let params = upload(backend, "params", &[count as u32, 0, 0, 0]).unwrap();
        let block_params = upload(backend, "block params", &[blocks as u32, 0, 0, 0]).unwrap();
        let input = upload(backend, "input", &input).unwrap();
        let out = backend.create_buffer("out", (count * 4) as u64).unwrap();
        let sums = backend.create_buffer("block sums", (blocks * 4) as u64).unwrap();
        let scanned = backend.create_buffer("scanned sums", (blocks * 4) as u64).unwrap();
        let total = backend.create_buffer("total", 4).unwrap();
        dispatch(backend, &scan, &[params, input, out, sums], [blocks as u32, 1, 1]);
        dispatch(backend, &scan, &[block_params, sums, scanned, total], [1, 1, 1]);
        dispatch(backend, &add, &[params, scanned, out], [blocks as u32, 1, 1]);
        let mut words = download(backend, out).unwrap();
        words.extend(download::<u32>(backend, total).unwrap());
        destroy(backend, &[params, block_params, input, out, sums, scanned, total]);
        words
    });
    let mut want = reference.clone();
    want.push(*reference.last().unwrap());
    check("prefix sum", &results, &want, Compare::Exact);
}

// ---------------------------------------------------------------------------------------
// 3. Histogram and reductions.

const HISTOGRAM: &str = include_str!("../data/workloads/histogram.wgsl");

#[test]
fn histogram_and_reductions_are_exact_on_every_backend() {
    let kernel = kernel("histogram.wgsl", HISTOGRAM);
    let count = 40_000usize;
    let mut rng = Rng(99);
    // Skewed: low bins are much fuller than high ones, so workgroup atomics contend.
    let values: Vec<u32> = (0..count)
        .map(|_| {
            let x = rng.next();
            x >> (x & 15)
        })
        .collect();
    let mut want = vec![0u32; 256];
    for v in &values {
        want[((v >> 8) & 255) as usize] += 1;
    }
    want.push(*values.iter().max().unwrap());
    want.push(*values.iter().min().unwrap());
    want.push(values.iter().fold(0u32, |s, v| s.wrapping_add(*v)));
    want.push(0);
    let results = run_everywhere("histogram", |backend| {
        let params = upload(backend, "params", &[count as u32, 0, 0, 0]).unwrap();
        let input = upload(backend, "values", &values).unwrap();
        let bins = backend.create_buffer("bins", 256 * 4).unwrap();
        let stats = upload(backend, "stats", &[0, u32::MAX, 0, 0]).unwrap();
        dispatch(backend, &kernel, &[params, input, bins, stats], [16, 1, 1]);
        let mut words = download(backend, bins).unwrap();
        words.extend(download::<u32>(backend, stats).unwrap());
        destroy(backend, &[params, input, bins, stats]);
        words
    });
    check("histogram", &results, &want, Compare::Exact);
}

// ---------------------------------------------------------------------------------------
// 4. Separable Gaussian blur.

const BLUR: &str = include_str!("../data/workloads/blur.wgsl");
const BLUR_WEIGHTS: [f32; 9] =
    [0.00390625, 0.03125, 0.109375, 0.21875, 0.2734375, 0.21875, 0.109375, 0.03125, 0.00390625];

fn blur_pass(src: &[f32], width: usize, height: usize, direction: u32) -> Vec<f32> {
    let (length, across_count) = if direction == 0 { (width, height) } else { (height, width) };
    let pixel =
        |along: usize, across: usize| if direction == 0 { across * width + along } else { along * width + across };
    let mut dst = vec![0.0f32; width * height];
    for across in 0..across_count {
        for along in 0..length {
            let mut sum = 0.0f32;
            for (j, weight) in BLUR_WEIGHTS.iter().enumerate() {
                let a = (along as i64 + j as i64 - 4).clamp(0, length as i64 - 1) as usize;
                sum += weight * src[pixel(a, across)];
            }
            dst[pixel(along, across)] = sum;
        }
    }
    dst
}

#[test]
fn separable_blur_agrees_with_the_reference_and_lavapipe() {
    let kernel = kernel("blur.wgsl", BLUR);
    let (width, height) = (157usize, 75usize);
    let mut rng = Rng(3);
    // A smooth gradient with noise and a bright square: edges exercise clamp-to-edge.
    let image: Vec<f32> = (0..width * height)
        .map(|i| {
            let (x, y) = (i % width, i / width);
            let square = if (40..70).contains(&x) && (20..50).contains(&y) { 4.0 } else { 0.0 };
            x as f32 / width as f32 + y as f32 / height as f32 + square + rng.range(0.0, 0.5)
        })
        .collect();
    let reference = bits(&blur_pass(&blur_pass(&image, width, height, 0), width, height, 1));
    let results = run_everywhere("blur", |backend| {
        let horizontal = upload(backend, "horizontal", &[width as u32, height as u32, 0, 0]).unwrap();
        let vertical = upload(backend, "vertical", &[width as u32, height as u32, 1, 0]).unwrap();
        let src = upload(backend, "image", &image).unwrap();
        let temp = backend.create_buffer("temp", (width * height * 4) as u64).unwrap();
        let dst = backend.create_buffer("blurred", (width * height * 4) as u64).unwrap();
        dispatch(backend, &kernel, &[horizontal, src, temp], [width.div_ceil(64) as u32, height as u32, 1]);
        dispatch(backend, &kernel, &[vertical, temp, dst], [height.div_ceil(64) as u32, width as u32, 1]);
        let words = download(backend, dst).unwrap();
        destroy(backend, &[horizontal, vertical, src, temp, dst]);
        words
    });
    // Nine positive products per pass, two passes: 4 ULP covers contraction.
    check("blur", &results, &reference, Compare::Float { ulp: 4, max_outside: 0.0 });
}

// ---------------------------------------------------------------------------------------
// 5. N-body step.

const NBODY: &str = include_str!("../data/workloads/nbody.wgsl");
const NBODY_STEPS: usize = 4;

/// One step as the kernel computes it; a body is [px, py, pz, mass, vx, vy, vz, w].
fn nbody_step(bodies: &[[f32; 8]], dt: f32, softening: f32) -> Vec<[f32; 8]> {
    bodies
        .iter()
        .map(|me| {
            let mut acc = [0.0f32; 3];
            for other in bodies {
                let d = [other[0] - me[0], other[1] - me[1], other[2] - me[2]];
                let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2] + softening;
                let s = other[3] / (r2 * r2.sqrt());
                for c in 0..3 {
                    acc[c] += d[c] * s;
                }
            }
            let mut next = *me;
            for c in 0..3 {
                next[4 + c] = me[4 + c] + acc[c] * dt;
                next[c] = me[c] + next[4 + c] * dt;
            }
            next
        })
        .collect()
}

#[test]
fn nbody_steps_agree_with_the_reference_and_lavapipe() {
    let kernel = kernel("nbody.wgsl", NBODY);
    let count = 200usize;
    let (dt, softening) = (0.01f32, 0.05f32);
    let mut rng = Rng(2024);
    let bodies: Vec<[f32; 8]> = (0..count)
        .map(|_| {
            let mut b = [0.0f32; 8];
            for v in &mut b[..3] {
                *v = rng.range(-1.0, 1.0);
            }
            b[3] = rng.range(0.001, 0.01);
            for v in &mut b[4..7] {
                *v = rng.range(-0.1, 0.1);
            }
            b[7] = rng.unit();
            b
        })
        .collect();
    let mut reference = bodies.clone();
    for _ in 0..NBODY_STEPS {
        reference = nbody_step(&reference, dt, softening);
    }
    let reference: Vec<f32> = reference.concat();
    let flat: Vec<f32> = bodies.concat();
    let results = run_everywhere("nbody", |backend| {
        let params = upload(backend, "params", &[count as u32, dt.to_bits(), softening.to_bits(), 0]).unwrap();
        let mut a = upload(backend, "bodies a", &flat).unwrap();
        let mut b = backend.create_buffer("bodies b", (flat.len() * 4) as u64).unwrap();
        for _ in 0..NBODY_STEPS {
            dispatch(backend, &kernel, &[params, a, b], [count.div_ceil(64) as u32, 1, 1]);
            std::mem::swap(&mut a, &mut b);
        }
        let words = download(backend, a).unwrap();
        destroy(backend, &[params, a, b]);
        words
    });
    // 200 softened interactions per step, four steps; contraction and a GPU's division
    // and square root may each move the last bits, and positions that nearly cancel
    // (a coordinate near 0) show small absolute errors as many ULPs: a share may exceed.
    check("nbody", &results, &bits(&reference), Compare::Float { ulp: 64, max_outside: 0.02 });
}

// ---------------------------------------------------------------------------------------
// 6. Collatz and Mandelbrot.

const COLLATZ: &str = include_str!("../data/workloads/collatz.wgsl");
const MANDELBROT: &str = include_str!("../data/workloads/mandelbrot.wgsl");

fn collatz_steps(start: u32) -> u32 {
    let (mut n, mut steps) = (start, 0);
    while n > 1 && steps < 256 {
        n = if n & 1 == 0 { n >> 1 } else { n.wrapping_mul(3).wrapping_add(1) };
        steps += 1;
    }
    steps
}

#[test]
fn collatz_step_counts_are_exact_on_every_backend() {
    let kernel = kernel("collatz.wgsl", COLLATZ);
    let mut rng = Rng(11);
    // Small starts, random ones below a million, and large ones whose 3n + 1 wraps.
    let mut input: Vec<u32> = (0..1024).collect();
    input.extend((0..2048).map(|_| rng.next() % 1_000_000));
    input.extend((0..1000).map(|_| rng.next() | 0x8000_0001));
    let reference: Vec<u32> = input.iter().map(|&n| collatz_steps(n)).collect();
    assert!(reference.contains(&256), "some start runs into the step bound");
    let results = run_everywhere("collatz", |backend| {
        let buffer = upload(backend, "input", &input).unwrap();
        let out = backend.create_buffer("out", (input.len() * 4) as u64).unwrap();
        dispatch(backend, &kernel, &[buffer, out], [input.len().div_ceil(64) as u32, 1, 1]);
        let words = download(backend, out).unwrap();
        destroy(backend, &[buffer, out]);
        words
    });
    check("collatz", &results, &reference, Compare::Exact);
}

struct Mandelbrot {
    width: u32,
    height: u32,
    max_iter: u32,
    x0: f32,
    y0: f32,
    scale: f32,
}

impl Mandelbrot {
    fn params(&self) -> [u32; 8] {
        [self.width, self.height, self.max_iter, 0, self.x0.to_bits(), self.y0.to_bits(), self.scale.to_bits(), 0]
    }

    fn reference(&self) -> Vec<u32> {
        let mut out = Vec::with_capacity((self.width * self.height) as usize);
        for y in 0..self.height {
            for x in 0..self.width {
                let cx = self.x0 + (x as f32 + 0.5) * self.scale;
                let cy = self.y0 + (y as f32 + 0.5) * self.scale;
                let (mut zx, mut zy, mut i) = (0.0f32, 0.0f32, 0);
                while i < self.max_iter && zx * zx + zy * zy <= 4.0 {
                    let xt = zx * zx - zy * zy + cx;
                    zy = 2.0 * zx * zy + cy;
                    zx = xt;
                    i += 1;
                }
                out.push(i);
            }
        }
        out
    }
}

#[test]
fn mandelbrot_escape_counts_agree_with_the_reference_and_mostly_with_lavapipe() {
    let kernel = kernel("mandelbrot.wgsl", MANDELBROT);
    let set = Mandelbrot { width: 160, height: 120, max_iter: 200, x0: -2.2, y0: -1.2, scale: 0.02 };
    let reference = set.reference();
    let results = run_everywhere("mandelbrot", |backend| {
        let params = upload(backend, "params", &set.params()).unwrap();
        let out = backend.create_buffer("out", u64::from(set.width * set.height * 4)).unwrap();
        dispatch(backend, &kernel, &[params, out], [set.width.div_ceil(8), set.height.div_ceil(8), 1]);
        let words = download(backend, out).unwrap();
        destroy(backend, &[params, out]);
        words
    });
    let (_, interpreter) = &results[0];
    assert_eq!(interpreter, &reference, "the interpreter gives the reference's counts");
    for (backend, words) in &results[1..] {
        let differing: Vec<u32> =
            interpreter.iter().zip(words).filter(|(a, b)| a != b).map(|(a, b)| a.abs_diff(*b)).collect();
        let share = differing.len() as f64 / interpreter.len() as f64;
        eprintln!(
            "mandelbrot: interpreter vs {backend}: {} of {} pixels ({:.3}%) differ, by at most {} iterations",
            differing.len(),
            interpreter.len(),
            share * 100.0,
            differing.iter().max().unwrap_or(&0)
        );
        // Iterates near the set's boundary are chaotic: one rounding done differently
        // there changes the escape count, so a small share of pixels may differ. A GPU
        // may contract to fused multiply-adds; lavapipe (Mesa 22.3) instead reassociates
        // `zx * zx - zy * zy + cx` into `(zx * zx + cx) - zy * zy` (its counts match a
        // Rust model doing that on every pixel), which moves 25 of 19200 pixels (0.13%)
        // by up to 85 iterations.
        assert!(share <= 0.02, "mandelbrot: {:.3}% of pixels differ on {backend}", share * 100.0);
    }
}

// ---------------------------------------------------------------------------------------
// 7. Bitonic sort.

const BITONIC_GLOBAL: &str = include_str!("../data/workloads/bitonic_global.wgsl");
const BITONIC_LOCAL: &str = include_str!("../data/workloads/bitonic_local.wgsl");

#[test]
fn bitonic_sort_is_exact_on_every_backend() {
    let global = kernel("bitonic_global.wgsl", BITONIC_GLOBAL);
    let local = kernel("bitonic_local.wgsl", BITONIC_LOCAL);
    let count = 4096u32;
    let mut rng = Rng(5);
    // Full-range keys and a run of repeated small ones.
    let keys: Vec<u32> = (0..count).map(|i| if i % 7 == 0 { i % 13 } else { rng.next() }).collect();
    let mut reference = keys.clone();
    reference.sort_unstable();
    // Distances of 256 and more run in storage memory, one dispatch each; the rest of
    // a stage runs in workgroup memory in one dispatch.
    let mut steps = Vec::new();
    let mut k = 2;
    while k <= count {
        let mut j = k / 2;
        while j >= 256 {
            steps.push((true, [k, j, count, 0]));
            j /= 2;
        }
        steps.push((false, [k, j, count, 0]));
        k *= 2;
    }
    let results = run_everywhere("bitonic sort", |backend| {
        let buffer = upload(backend, "keys", &keys).unwrap();
        let mut params = Vec::new();
        for (in_storage, words) in &steps {
            let step = upload(backend, "params", words).unwrap();
            if *in_storage {
                dispatch(backend, &global, &[step, buffer], [count / 256, 1, 1]);
            } else {
                dispatch(backend, &local, &[step, buffer], [count / 256, 1, 1]);
            }
            params.push(step);
        }
        let words = download(backend, buffer).unwrap();
        destroy(backend, &params);
        destroy(backend, &[buffer]);
        words
    });
    check("bitonic sort", &results, &reference, Compare::Exact);
}

// ---------------------------------------------------------------------------------------
// 8. Tree reduction of f32 values.

const REDUCE: &str = include_str!("../data/workloads/reduce.wgsl");

/// One pass of the reduction kernel: a (sum, min, max, sum of squares) per 256 loaded
/// values, combined in the kernel's tree order.
fn reduce_pass(items: &[[f32; 4]]) -> Vec<[f32; 4]> {
    let identity = [0.0, 3.0e38, -3.0e38, 0.0];
    items
        .chunks(256)
        .map(|chunk| {
            let mut tile = [identity; 256];
            tile[..chunk.len()].copy_from_slice(chunk);
            let mut s = 128;
            while s > 0 {
                for li in 0..s {
                    let (a, b) = (tile[li], tile[li + s]);
                    tile[li] = [a[0] + b[0], a[1].min(b[1]), a[2].max(b[2]), a[3] + b[3]];
                }
                s /= 2;
            }
            tile[0]
        })
        .collect()
}

#[test]
fn tree_reduction_agrees_with_the_reference_and_lavapipe() {
    let kernel = kernel("reduce.wgsl", REDUCE);
    let count = 256usize * 40 + 77;
    let blocks = count.div_ceil(256);
    let mut rng = Rng(31);
    let values: Vec<f32> = (0..count).map(|_| rng.range(-100.0, 100.0)).collect();
    let items: Vec<[f32; 4]> = values.iter().map(|&v| [v, v, v, v * v]).collect();
    let partials = reduce_pass(&items);
    let total = reduce_pass(&partials);
    let reference = bits(&[partials.concat(), total.concat()].concat());
    let results = run_everywhere("reduction", |backend| {
        let first = upload(backend, "params", &[count as u32, 0, 0, 0]).unwrap();
        let second = upload(backend, "params", &[blocks as u32, 1, 0, 0]).unwrap();
        let input = upload(backend, "values", &values).unwrap();
        let partials = backend.create_buffer("partials", (blocks * 16) as u64).unwrap();
        let total = backend.create_buffer("total", 16).unwrap();
        dispatch(backend, &kernel, &[first, input, partials], [blocks as u32, 1, 1]);
        dispatch(backend, &kernel, &[second, partials, total], [1, 1, 1]);
        let mut words = download(backend, partials).unwrap();
        words.extend(download::<u32>(backend, total).unwrap());
        destroy(backend, &[first, second, input, partials, total]);
        words
    });
    // Additions only (the squares are rounded before they reach workgroup memory): a
    // GPU has nothing to contract; 4 ULP leaves room for a different rounding of sums
    // that cancel.
    check("reduction", &results, &reference, Compare::Float { ulp: 4, max_outside: 0.0 });
}

// ---------------------------------------------------------------------------------------
// 9. Boids.

const BOIDS: &str = include_str!("../data/workloads/boids.wgsl");
const BOIDS_STEPS: usize = 3;

#[derive(Clone, Copy)]
struct Flock {
    dt: f32,
    radius: f32,
    separation: f32,
    cohesion: f32,
    alignment: f32,
    repulsion: f32,
    max_speed: f32,
}

impl Flock {
    fn params(&self, count: u32) -> [u32; 8] {
        let f = [self.dt, self.radius, self.separation, self.cohesion, self.alignment, self.repulsion, self.max_speed];
        let mut words = [count; 8];
        for (w, v) in words[1..].iter_mut().zip(f) {
            *w = v.to_bits();
        }
        words
    }

    /// One step as the kernel computes it (WGSL `length` is sqrt(x*x + y*y + z*z) and
    /// `normalize(d)` is d / length(d) on the interpreter); a boid is
    /// [px, py, pz, pw, vx, vy, vz, vw].
    fn step(&self, boids: &[[f32; 8]]) -> Vec<[f32; 8]> {
        let length = |v: [f32; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        boids
            .iter()
            .enumerate()
            .map(|(i, me)| {
                let pos = [me[0], me[1], me[2]];
                let mut vel = [me[4], me[5], me[6]];
                let (mut center, mut heading, mut push, mut n) = ([0.0f32; 3], [0.0f32; 3], [0.0f32; 3], 0u32);
                for (j, other) in boids.iter().enumerate() {
                    if j == i {
                        continue;
                    }
                    let d = [other[0] - pos[0], other[1] - pos[1], other[2] - pos[2]];
                    let dist = length(d);
                    if dist < self.radius {
                        for c in 0..3 {
                            center[c] += other[c];
                            heading[c] += other[4 + c];
                        }
                        n += 1;
                        if dist < self.separation && dist > 0.0 {
                            for c in 0..3 {
                                push[c] -= d[c] / dist / dist;
                            }
                        }
                    }
                }
                if n > 0 {
                    let inv = 1.0 / n as f32;
                    for c in 0..3 {
                        vel[c] += ((center[c] * inv - pos[c]) * self.cohesion
                            + (heading[c] * inv - vel[c]) * self.alignment)
                            * self.dt;
                    }
                }
                let scale = self.repulsion * self.dt;
                for c in 0..3 {
                    vel[c] += push[c] * scale;
                }
                let speed = length(vel);
                if speed > self.max_speed {
                    let s = self.max_speed / speed;
                    for v in &mut vel {
                        *v *= s;
                    }
                }
                let mut next = *me;
                for c in 0..3 {
                    let p = pos[c] + vel[c] * self.dt;
                    next[c] = p - 2.0 * ((p + 1.0) * 0.5).floor();
                    next[4 + c] = vel[c];
                }
                next
            })
            .collect()
    }
}

#[test]
fn boids_steps_agree_with_the_reference_and_lavapipe() {
    let kernel = kernel("boids.wgsl", BOIDS);
    let count = 300usize;
    let flock = Flock {
        dt: 0.02,
        radius: 0.3,
        separation: 0.08,
        cohesion: 0.5,
        alignment: 0.8,
        repulsion: 0.002,
        max_speed: 0.5,
    };
    let mut rng = Rng(77);
    let boids: Vec<[f32; 8]> = (0..count)
        .map(|_| {
            let mut b = [0.0f32; 8];
            for v in &mut b[..3] {
                *v = rng.range(-1.0, 1.0);
            }
            for v in &mut b[4..7] {
                *v = rng.range(-0.3, 0.3);
            }
            b[3] = rng.unit();
            b[7] = rng.unit();
            b
        })
        .collect();
    let mut reference = boids.clone();
    for _ in 0..BOIDS_STEPS {
        reference = flock.step(&reference);
    }
    let flat: Vec<f32> = boids.concat();
    let results = run_everywhere("boids", |backend| {
        let params = upload(backend, "params", &flock.params(count as u32)).unwrap();
        let mut a = upload(backend, "boids a", &flat).unwrap();
        let mut b = backend.create_buffer("boids b", (flat.len() * 4) as u64).unwrap();
        for _ in 0..BOIDS_STEPS {
            dispatch(backend, &kernel, &[params, a, b], [count.div_ceil(64) as u32, 1, 1]);
            std::mem::swap(&mut a, &mut b);
        }
        let words = download(backend, a).unwrap();
        destroy(backend, &[params, a, b]);
        words
    });
    // A GPU may compute normalize with an inverse square root and contract the steering
    // sums; a neighbour right at the radius may then count on one side and not the
    // other, so a share of values may exceed the bound.
    check("boids", &results, &bits(&reference.concat()), Compare::Float { ulp: 64, max_outside: 0.02 });
}

// ---------------------------------------------------------------------------------------
// 10. Monte Carlo pi with signed integer arithmetic.

const MONTE_CARLO: &str = include_str!("../data/workloads/monte_carlo.wgsl");

fn pcg_hash(s: u32) -> u32 {
    let t = s.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let w = ((t >> ((t >> 28) + 4)) ^ t).wrapping_mul(277_803_737);
    (w >> 22) ^ w
}

#[test]
fn monte_carlo_pi_and_signed_integer_math_are_exact_on_every_backend() {
    let kernel = kernel("monte_carlo.wgsl", MONTE_CARLO);
    let (invocations, samples, seed) = (64 * 24u32, 40u32, 0x5eed_1234u32);
    let mut inside = 0u32;
    let mut signed = Vec::new();
    for g in 0..invocations {
        let mut h = pcg_hash(g ^ seed);
        let (mut acc, mut lo, mut hi, mut magnitude) = (0i32, i32::MAX, i32::MIN, 0i32);
        for _ in 0..samples {
            h = pcg_hash(h);
            let x = h >> 20;
            h = pcg_hash(h);
            let y = h >> 20;
            if x * x + y * y < 4096 * 4096 {
                inside += 1;
            }
            let v = h as i32;
            acc = acc.wrapping_add(v / 7).wrapping_sub(v % 13).wrapping_add(v >> 3);
            lo = lo.min(v);
            hi = hi.max(v);
            magnitude = magnitude.wrapping_add(v.wrapping_abs());
        }
        signed.extend([acc, lo, hi, magnitude].map(|v| v as u32));
    }
    let pi = 4.0 * f64::from(inside) / f64::from(invocations * samples);
    assert!((pi - std::f64::consts::PI).abs() < 0.05, "the estimate {pi} is near pi");
    let mut reference = vec![inside];
    reference.extend(signed);
    let results = run_everywhere("monte carlo", |backend| {
        let params = upload(backend, "params", &[samples, seed, 0, 0]).unwrap();
        let total = backend.create_buffer("total", 4).unwrap();
        let signed = backend.create_buffer("signed", u64::from(invocations * 16)).unwrap();
        dispatch(backend, &kernel, &[params, total, signed], [invocations / 64, 1, 1]);
        let mut words = download(backend, total).unwrap();
        words.extend(download::<u32>(backend, signed).unwrap());
        destroy(backend, &[params, total, signed]);
        words
    });
    check("monte carlo", &results, &reference, Compare::Exact);
}

// ---------------------------------------------------------------------------------------
// 11. Ray tracing spheres.

const RAYTRACE: &str = include_str!("../data/workloads/raytrace.wgsl");

type Vec3 = [f32; 3];

fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: Vec3, b: Vec3) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn scaled(a: Vec3, s: f32) -> Vec3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

fn add(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// The kernel's `hit`: the nearer root beyond 0.001, else the farther, else -1.
fn hit_sphere(origin: Vec3, dir: Vec3, sphere: [f32; 4]) -> f32 {
    let oc = sub(origin, [sphere[0], sphere[1], sphere[2]]);
    let b = dot(oc, dir);
    let c = dot(oc, oc) - sphere[3] * sphere[3];
    let disc = b * b - c;
    if disc < 0.0 {
        return -1.0;
    }
    let root = disc.sqrt();
    if -b - root > 0.001 {
        -b - root
    } else if -b + root > 0.001 {
        -b + root
    } else {
        -1.0
    }
}

fn raytrace_reference(width: u32, height: u32, eye: Vec3, light: Vec3, spheres: &[[f32; 8]]) -> Vec<f32> {
    let mut out = Vec::new();
    for y in 0..height {
        for x in 0..width {
            let u = (x as f32 + 0.5) / width as f32 * 2.0 - 1.0;
            let v = (y as f32 + 0.5) / height as f32 * 2.0 - 1.0;
            let aspect = width as f32 / height as f32;
            let d = [u * aspect, -v, -1.5];
            let length = dot(d, d).sqrt();
            let dir = [d[0] / length, d[1] / length, d[2] / length];
            let (mut best, mut nearest) = (1.0e30f32, None);
            for (i, sphere) in spheres.iter().enumerate() {
                let t = hit_sphere(eye, dir, [sphere[0], sphere[1], sphere[2], sphere[3]]);
                if t > 0.0 && t < best {
                    best = t;
                    nearest = Some(i);
                }
            }
            match nearest {
                None => {
                    let s = 0.5 * (dir[1] + 1.0);
                    let sky = [0.5, 0.7, 1.0];
                    out.extend((0..3).map(|c| (1.0 - s) * 1.0 + s * sky[c]));
                    out.push(-1.0);
                }
                Some(i) => {
                    let sphere = spheres[i];
                    let p = add(eye, scaled(dir, best));
                    let centre = [sphere[0], sphere[1], sphere[2]];
                    let offset = sub(p, centre);
                    let n = [offset[0] / sphere[3], offset[1] / sphere[3], offset[2] / sphere[3]];
                    let mut diffuse = dot(n, light).max(0.0);
                    let start = add(p, scaled(n, 0.001));
                    if spheres.iter().any(|s| hit_sphere(start, light, [s[0], s[1], s[2], s[3]]) > 0.0) {
                        diffuse = 0.0;
                    }
                    out.extend((0..3).map(|c| sphere[4 + c] * (0.1 + 0.9 * diffuse)));
                    out.push(best);
                }
            }
        }
    }
    out
}

#[test]
fn ray_traced_spheres_agree_with_the_reference_and_lavapipe() {
    let kernel = kernel("raytrace.wgsl", RAYTRACE);
    let (width, height) = (96u32, 64u32);
    let eye = [0.0, 0.2, 0.0];
    let l = [0.5f32, 0.8, 0.3];
    let length = dot(l, l).sqrt();
    let light = [l[0] / length, l[1] / length, l[2] / length];
    // Centre xyz, radius, albedo rgb, unused; the first is the ground.
    let spheres: Vec<[f32; 8]> = vec![
        [0.0, -1000.5, -3.0, 1000.0, 0.6, 0.6, 0.5, 0.0],
        [0.0, 0.0, -3.0, 0.5, 0.9, 0.2, 0.2, 0.0],
        [1.1, 0.0, -3.5, 0.5, 0.2, 0.8, 0.3, 0.0],
        [-1.1, 0.1, -2.7, 0.45, 0.2, 0.3, 0.9, 0.0],
        [0.4, -0.3, -2.2, 0.2, 0.9, 0.9, 0.1, 0.0],
        [-0.5, 0.6, -4.0, 0.4, 0.7, 0.4, 0.8, 0.0],
    ];
    let reference = raytrace_reference(width, height, eye, light, &spheres);
    assert!(reference.chunks(4).any(|p| p[3] < 0.0), "some rays miss");
    let camera: Vec<u32> = [width, height, spheres.len() as u32, 0]
        .into_iter()
        .chain([eye[0], eye[1], eye[2], 0.0, light[0], light[1], light[2], 0.0].map(f32::to_bits))
        .collect();
    let flat: Vec<f32> = spheres.concat();
    let results = run_everywhere("ray trace", |backend| {
        let camera = upload(backend, "camera", &camera).unwrap();
        let spheres = upload(backend, "spheres", &flat).unwrap();
        let out = backend.create_buffer("image", u64::from(width * height * 16)).unwrap();
        dispatch(backend, &kernel, &[camera, spheres, out], [width.div_ceil(8), height.div_ceil(8), 1]);
        let words = download(backend, out).unwrap();
        destroy(backend, &[camera, spheres, out]);
        words
    });
    // Dot products may contract; a pixel at a shadow or silhouette edge may then flip,
    // so a share of values may exceed the bound.
    check("ray trace", &results, &bits(&reference), Compare::Float { ulp: 16, max_outside: 0.01 });
}

// ---------------------------------------------------------------------------------------
// 12. Linear blend skinning.

const SKINNING: &str = include_str!("../data/workloads/skinning.wgsl");

type Mat4 = [[f32; 4]; 4];

/// The interpreter's matrix-vector product: for each row, column 0 * v[0] + column 1 *
/// v[1] + ... in column order.
fn mat_vec<const R: usize>(columns: &[[f32; 4]], v: &[f32]) -> [f32; R] {
    std::array::from_fn(|i| (1..v.len()).fold(columns[0][i] * v[0], |acc, k| acc + columns[k][i] * v[k]))
}

fn skin_reference(bones: &[Mat4], vertex: &[f32; 16]) -> [f32; 8] {
    let joints = &vertex[12..16];
    let weights = &vertex[8..12];
    let mut skin = [[0.0f32; 4]; 4];
    for k in 0..4 {
        let bone = bones[joints[k].to_bits() as usize];
        for (c, column) in skin.iter_mut().enumerate() {
            for (r, x) in column.iter_mut().enumerate() {
                let term = bone[c][r] * weights[k];
                *x = if k == 0 { term } else { *x + term };
            }
        }
    }
    let position: [f32; 4] = mat_vec(&skin, &[vertex[0], vertex[1], vertex[2], 1.0]);
    let n: [f32; 3] = mat_vec(&skin[..3], &vertex[4..7]);
    let length = n.iter().fold(0.0f32, |acc, x| acc + x * x).sqrt();
    let mut out = [0.0f32; 8];
    out[..4].copy_from_slice(&position);
    for c in 0..3 {
        out[4 + c] = n[c] / length;
    }
    out
}

#[test]
fn skinned_vertices_agree_with_the_reference_and_lavapipe() {
    let kernel = kernel("skinning.wgsl", SKINNING);
    let mut rng = Rng(404);
    let bones: Vec<Mat4> = (0..8)
        .map(|_| {
            let mut m = [[0.0f32; 4]; 4];
            for (c, column) in m.iter_mut().enumerate() {
                for (r, x) in column.iter_mut().enumerate().take(3) {
                    *x = rng.range(-0.5, 0.5) + if c == r { 1.0 } else { 0.0 };
                }
            }
            m[3] = [rng.range(-2.0, 2.0), rng.range(-2.0, 2.0), rng.range(-2.0, 2.0), 1.0];
            m
        })
        .collect();
    let vertices: Vec<[f32; 16]> = (0..2000)
        .map(|_| {
            let mut v = [0.0f32; 16];
            for x in &mut v[..3] {
                *x = rng.range(-1.0, 1.0);
            }
            v[3] = 1.0;
            for x in &mut v[4..7] {
                *x = rng.range(-1.0, 1.0);
            }
            let raw: [f32; 4] = std::array::from_fn(|_| rng.unit());
            let sum: f32 = raw.iter().sum();
            for k in 0..4 {
                v[8 + k] = raw[k] / sum;
                v[12 + k] = f32::from_bits(rng.next() % 8);
            }
            v
        })
        .collect();
    let reference: Vec<f32> = vertices.iter().flat_map(|v| skin_reference(&bones, v)).collect();
    let bone_words: Vec<f32> = bones.iter().flat_map(|m| m.concat()).collect();
    let vertex_words: Vec<f32> = vertices.concat();
    let results = run_everywhere("skinning", |backend| {
        let bones = upload(backend, "bones", &bone_words).unwrap();
        let vertices = upload(backend, "vertices", &vertex_words).unwrap();
        let out = backend.create_buffer("skinned", (reference.len() * 4) as u64).unwrap();
        dispatch(backend, &kernel, &[bones, vertices, out], [2000u32.div_ceil(64), 1, 1]);
        let words = download(backend, out).unwrap();
        destroy(backend, &[bones, vertices, out]);
        words
    });
    // WGSL fixes no order for the sums of a matrix product: the interpreter adds
    // columns first to last, lavapipe (Mesa's SPIR-V translation) last to first (its
    // output matches a Rust model doing that bit for bit). Coordinates that nearly
    // cancel then show the different rounding as many ULPs: 37 of 16000 values are
    // beyond 16 ULP (up to 512) on lavapipe, so a share may exceed the bound.
    check("skinning", &results, &bits(&reference), Compare::Float { ulp: 16, max_outside: 0.01 });
}

// ---------------------------------------------------------------------------------------
// An interpreter bug found while writing the skinning workload.

const NEGATIVE_ZERO_PRODUCTS: &str = r#"
@group(0) @binding(0) var<storage, read> input: array<f32>;
@group(0) @binding(1) var<storage, read_write> out: array<f32>;

@compute @workgroup_size(1)
fn main() {
    let m = mat2x2<f32>(vec2<f32>(input[0], input[1]), vec2<f32>(input[2], input[3]));
    let v = vec2<f32>(input[4], input[5]);
    let a = m * v;
    let b = v * m;
    let c = m * mat2x2<f32>(v, v);
    out[0] = a.x;
    out[1] = a.y;
    out[2] = b.x;
    out[3] = b.y;
    out[4] = c[0].x;
    out[5] = c[1].y;
    out[6] = dot(v, m[0]);
}
"#;

/// Every product of `m = (-1)` and `v = (0, 0)` is -0.0, and so is their IEEE sum
/// (lavapipe gives -0.0). A regression test: the interpreter once started matrix-vector,
/// vector-matrix and matrix-matrix sums at +0.0 and returned +0.0.
#[test]
fn matrix_products_of_negative_zeros_are_negative_zero() {
    let kernel = kernel("negative_zero_products.wgsl", NEGATIVE_ZERO_PRODUCTS);
    let input = [-1.0f32, -1.0, -1.0, -1.0, 0.0, 0.0];
    let results = run_everywhere("negative zero products", |backend| {
        let buffer = upload(backend, "input", &input).unwrap();
        let out = backend.create_buffer("out", 7 * 4).unwrap();
        dispatch(backend, &kernel, &[buffer, out], [1, 1, 1]);
        let words = download(backend, out).unwrap();
        destroy(backend, &[buffer, out]);
        words
    });
    check("negative zero products", &results, &bits(&[-0.0; 7]), Compare::Exact);
}

// ---------------------------------------------------------------------------------------
// 13. Per-pixel linked lists (order-independent transparency).

const LIST_BUILD: &str = include_str!("../data/workloads/list_build.wgsl");
const LIST_RESOLVE: &str = include_str!("../data/workloads/list_resolve.wgsl");

#[test]
fn per_pixel_linked_lists_resolve_exactly_on_every_backend() {
    let build = kernel("list_build.wgsl", LIST_BUILD);
    let resolve = kernel("list_resolve.wgsl", LIST_RESOLVE);
    let (pixels, count) = (1024u32, 6000usize);
    let mut rng = Rng(8);
    // (pixel, depth, colour); a few exact depth ties make the colour tie-break matter.
    let fragments: Vec<(u32, f32, u32)> = (0..count)
        .map(|i| {
            let depth = if i % 50 == 0 { 0.5 } else { rng.unit() };
            (rng.next() % pixels, depth, rng.next())
        })
        .collect();
    let mut lists = vec![Vec::new(); pixels as usize];
    for &(pixel, depth, colour) in &fragments {
        lists[pixel as usize].push((depth, colour));
    }
    let mut reference = Vec::new();
    for list in &mut lists {
        assert!(list.len() <= 32, "every list fits the resolve kernel's bound");
        list.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let h = list.iter().fold(17u32, |h, &(_, colour)| h.wrapping_mul(31).wrapping_add(colour));
        reference.extend([list.len() as u32, list.first().map_or(0, |f| f.1), h]);
    }
    let words: Vec<u32> = fragments.iter().flat_map(|&(p, d, c)| [p, d.to_bits(), c, 0]).collect();
    let results = run_everywhere("linked lists", |backend| {
        let fragments = upload(backend, "fragments", &words).unwrap();
        let counter = backend.create_buffer("counter", 4).unwrap();
        let heads = upload(backend, "heads", &vec![u32::MAX; pixels as usize]).unwrap();
        let nodes = backend.create_buffer("nodes", 8192 * 16).unwrap();
        let out = backend.create_buffer("out", u64::from(pixels * 12)).unwrap();
        dispatch(backend, &build, &[fragments, counter, heads, nodes], [count.div_ceil(64) as u32, 1, 1]);
        dispatch(backend, &resolve, &[heads, nodes, out], [pixels / 64, 1, 1]);
        let mut words = download(backend, out).unwrap();
        words.extend(download::<u32>(backend, counter).unwrap());
        destroy(backend, &[fragments, counter, heads, nodes, out]);
        words
    });
    reference.push(count as u32);
    check("linked lists", &results, &reference, Compare::Exact);
}
