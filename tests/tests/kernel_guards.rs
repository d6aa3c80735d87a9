//! The package's kernels stay inside their buffers when an engine binds buffers too small
//! for its image (issue 56, "misuse is caught, not silent"): the block histogram's three
//! entry points, `strata_select` and `strata_resample` guard every buffer access by the
//! bound buffer's length (`arrayLength`).
//!
//! Each misuse of the package README's "Common mistakes" that shrinks a buffer (a
//! candidate buffer sized for a smaller image, the selections at half size, ...), and
//! selections left unwritten as the resampling's input, runs twice:
//! - on the CPU interpreter with its sanitizer, which reports every access past a
//!   buffer's end (what lies there is the guard area an engine's allocator would have
//!   handed to something else). Without the guards each case below gives such findings:
//!   this is the test that fails on an unguarded kernel;
//! - on lavapipe through the ash backend, which runs naga's SPIR-V with no bounds checks
//!   of its own (the exported kernels' translation), and the words of every buffer must
//!   equal the interpreter's. (lavapipe may clamp accesses itself, so this half alone
//!   could not see a missing guard; it sees that the guarded kernels agree.)
//!
//! The C ABI's validation mode names these mistakes before they reach a kernel
//! (tests/tests/c_abi.rs); the guards are what remains when it is off.

use strata_backends::ash_backend::{AshBackend, AshOptions, SpirvSource};
use strata_backends::backend::{download, upload};
use strata_backends::cpu_backend::{CpuBackend, CpuOptions};
use strata_backends::{Backend, BackendError, Bind, gpu_required};
use strata_kernels::blue_noise::BlueNoiseTables;
use strata_kernels::embed_types::SelectionParams;
use strata_kernels::selection::SamplerVariant;
use strata_kernels::types::{BlockStats, Candidate, ClusterSpan};
use strata_kernels::{BlockGrid, KernelId, Registry};
use strata_tests::POISON;

const WIDTH: u32 = 20;
const HEIGHT: u32 = 12;
const BLOCK: u32 = 8;

/// One dispatch: the kernel, its buffers as words by binding (the uniform too, never
/// shrunk), and the workgroups.
struct Dispatch {
    label: String,
    kernel: KernelId,
    buffers: Vec<(u32, Vec<u32>)>,
    workgroups: [u32; 3],
}

fn words<T: bytemuck::Pod>(values: &[T]) -> Vec<u32> {
    bytemuck::cast_slice(values).to_vec()
}

fn pixels() -> u32 {
    WIDTH * HEIGHT
}

fn candidates(count: u32) -> Vec<Candidate> {
    (0..count).map(|p| Candidate { key: ((p * 7919) % 101) as f32 * 0.1, object_id: (p % WIDTH) / 7 }).collect()
}

/// A buffer of `len` elements of `words_per` words, poisoned.
fn poisoned(len: u32, words_per: u32) -> Vec<u32> {
    vec![POISON; (len * words_per) as usize]
}

fn histogram(kernel: KernelId, label: &str, candidate_count: u32, sorted: u32, spans: u32, stats: u32) -> Dispatch {
    let grid = BlockGrid::new(WIDTH, HEIGHT, BLOCK).unwrap();
    let workgroups = grid.histogram_workgroups(65_535);
    let params = grid.histogram_params(workgroups[0], true);
    let span_words = (size_of::<ClusterSpan>() / 4) as u32;
    let stats_words = (size_of::<BlockStats>() / 4) as u32;
    Dispatch {
        label: format!("{kernel:?}: {label}"),
        kernel,
        buffers: vec![
            (0, words(&[params])),
            (1, words(&candidates(candidate_count))),
            (2, poisoned(sorted, 1)),
            (3, poisoned(spans, span_words)),
            (4, poisoned(stats, stats_words)),
        ],
        workgroups,
    }
}

/// The histogram's outputs for the whole image, computed on `backend` with right-sized
/// buffers, as the inputs of the selection.
fn histogram_outputs(backend: &mut dyn Backend) -> (Vec<u32>, Vec<u32>) {
    let n = pixels();
    let dispatch = histogram(KernelId::BlockHistogram, "right-sized", n, n, n, 64);
    let outputs = run(backend, &dispatch).unwrap();
    (outputs[2].1.clone(), outputs[3].1.clone())
}

fn selection_params(identity_payload: bool) -> SelectionParams {
    SelectionParams {
        width: WIDTH,
        height: HEIGHT,
        frame: 5,
        seed: 9,
        candidates: 3,
        sampler: SamplerVariant::default().id(),
        identity_payload: u32::from(identity_payload),
        _pad: 0,
    }
}

/// strata_select with each buffer at `sizes` (elements): candidates, payloads,
/// sorted_pixels, spans, blue-noise words, selections.
fn select(label: &str, histogram: &(Vec<u32>, Vec<u32>), sizes: [u32; 6], identity_payload: bool) -> Dispatch {
    let [candidate_count, payload_count, sorted, spans, noise, selections] = sizes;
    let (sorted_pixels, span_words) = histogram;
    let span_len = size_of::<ClusterSpan>() / 4;
    let payloads: Vec<u32> = (0..payload_count).map(|p| p ^ 0x55).collect();
    Dispatch {
        label: format!("strata_select: {label}"),
        kernel: KernelId::StrataSelect,
        buffers: vec![
            (0, words(&[selection_params(identity_payload)])),
            (1, words(&candidates(candidate_count))),
            (2, payloads),
            (3, sorted_pixels[..sorted as usize].to_vec()),
            (4, span_words[..spans as usize * span_len].to_vec()),
            (5, BlueNoiseTables::new().packed()[..noise as usize].to_vec()),
            (6, poisoned(selections, 8)),
        ],
        workgroups: [WIDTH.div_ceil(8), HEIGHT.div_ceil(8), 1],
    }
}

/// strata_resample with `selections`, `inputs` and `outputs` elements.
fn resample(label: &str, selected: &[u32], selections: u32, inputs: u32, outputs: u32) -> Dispatch {
    let resample_inputs = strata_tests::resample_inputs(inputs, 0.0);
    Dispatch {
        label: format!("strata_resample: {label}"),
        kernel: KernelId::StrataResample,
        buffers: vec![
            (0, words(&[selection_params(false)])),
            (1, selected[..selections as usize * 8].to_vec()),
            (2, words(&resample_inputs)),
            (3, poisoned(outputs, 4)),
        ],
        workgroups: [WIDTH.div_ceil(8), HEIGHT.div_ceil(8), 1],
    }
}

/// Runs `dispatch`; every buffer's words afterwards, by binding.
fn run(backend: &mut dyn Backend, dispatch: &Dispatch) -> Result<Vec<(u32, Vec<u32>)>, BackendError> {
    let kernel = Registry::shared().unwrap().get(dispatch.kernel);
    let mut ids = Vec::new();
    for (binding, contents) in &dispatch.buffers {
        // An empty buffer cannot be bound; one word stands for "none".
        let contents = if contents.is_empty() { vec![POISON] } else { contents.clone() };
        ids.push((*binding, upload(backend, &format!("binding {binding}"), &contents)?));
    }
    let binds: Vec<Bind> = ids.iter().map(|&(binding, id)| Bind::new(binding, id)).collect();
    backend.dispatch(kernel, &binds, dispatch.workgroups)?;
    let mut out = Vec::new();
    for (binding, id) in ids {
        out.push((binding, download::<u32>(backend, id)?));
        backend.destroy_buffer(id)?;
    }
    Ok(out)
}

fn sanitizing() -> CpuBackend {
    CpuBackend::new(CpuOptions { sanitize: true, ..CpuOptions::default() }).unwrap()
}

fn ash() -> Option<AshBackend> {
    match AshBackend::new(AshOptions { source: SpirvSource::Naga, subgroups: true, ..Default::default() }) {
        Ok(backend) => Some(backend),
        Err(error @ BackendError::NoAdapter { .. }) if !gpu_required() => {
            eprintln!("SKIPPED the lavapipe half: {error} (set STRATA_REQUIRE_GPU=1 to make this a failure)");
            None
        }
        Err(error) => panic!("ash backend: {error}"),
    }
}

/// Every misuse that shrinks a buffer, for the three histogram entry points and the two
/// embedding kernels.
fn misuses(cpu: &mut CpuBackend) -> Vec<Dispatch> {
    let n = pixels();
    let smaller = (WIDTH / 2) * (HEIGHT / 2);
    let mut cases = Vec::new();
    for kernel in [KernelId::BlockHistogram, KernelId::BlockHistogramRank, KernelId::BlockHistogramSubgroup] {
        cases.push(histogram(kernel, "candidates for a smaller image", smaller, n, n, 64));
        cases.push(histogram(kernel, "sorted_pixels at half size", n, n / 2, n, 64));
        cases.push(histogram(kernel, "spans at half size", n, n, n / 2, 64));
        cases.push(histogram(kernel, "block_stats of one block", n, n, n, 1));
        cases.push(histogram(kernel, "every buffer of one element", 1, 1, 1, 1));
    }
    let outputs = histogram_outputs(cpu);
    let noise = BlueNoiseTables::new().packed().len() as u32;
    cases.push(select("selections at half size", &outputs, [n, n, n, n, noise, n / 2], false));
    cases.push(select("candidates for a smaller image", &outputs, [smaller, n, n, n, noise, n], false));
    cases.push(select("spans for a smaller image", &outputs, [n, n, n, smaller, noise, n], false));
    cases.push(select("sorted_pixels at half size", &outputs, [n, n, n / 2, n, noise, n], false));
    cases.push(select("payloads for a smaller image", &outputs, [n, smaller, n, n, noise, n], false));
    cases.push(select("blue noise truncated", &outputs, [n, n, n, n, 1000, n], true));
    let selected = run(cpu, &select("right-sized", &outputs, [n, n, n, n, noise, n], false)).unwrap()[6].1.clone();
    cases.push(resample("resampled at half size", &selected, n, n, n / 2));
    cases.push(resample("selections for a smaller image", &selected, smaller, n, n));
    cases.push(resample("inputs for a smaller image", &selected, n, smaller, n));
    // Selections strata_select never wrote (the pixels its guards skip): their counts are
    // whatever the buffer held, and must not become the resampling's loop bounds.
    cases.push(resample("selections never written", &poisoned(n, 8), n, n, n));
    // The right-sized runs that made the inputs above touched nothing outside either.
    let (findings, dropped) = cpu.take_findings();
    let undefined: Vec<String> = findings.iter().filter(|f| f.kind.undefined()).map(|f| f.to_string()).collect();
    assert!(undefined.is_empty() && dropped == 0, "right-sized runs: {undefined:#?}");
    cases
}

#[test]
fn no_kernel_of_the_package_reads_or_writes_past_a_buffer_too_small_for_its_image() {
    let mut cpu = sanitizing();
    let cases = misuses(&mut cpu);
    let mut lavapipe = ash();
    let mut outside = Vec::new();
    let mut disagree = Vec::new();
    for case in &cases {
        let interpreted = run(&mut cpu, case).unwrap_or_else(|e| panic!("{}: {e}", case.label));
        let (findings, dropped) = cpu.take_findings();
        let undefined: Vec<String> = findings.iter().filter(|f| f.kind.undefined()).map(|f| f.to_string()).collect();
        if !undefined.is_empty() || dropped > 0 {
            outside.push(format!("{}: {}", case.label, undefined.join("; ")));
        }
        if let Some(lavapipe) = lavapipe.as_mut() {
            let native = run(lavapipe, case).unwrap_or_else(|e| panic!("{} on lavapipe: {e}", case.label));
            for ((binding, a), (_, b)) in interpreted.iter().zip(&native) {
                if a != b {
                    disagree.push(format!("{}: binding {binding}", case.label));
                }
            }
        }
    }
    assert!(outside.is_empty(), "accesses outside a buffer:\n{}", outside.join("\n"));
    assert!(disagree.is_empty(), "the interpreter and lavapipe differ:\n{}", disagree.join("\n"));
}

/// A shrunk buffer holds the elements a right-sized run writes there, where the kernel's
/// reads do not depend on the missing part: a guard drops what lies past the end, it
/// does not change what lies inside.
#[test]
fn a_guard_changes_nothing_inside_the_buffer() {
    let mut cpu = sanitizing();
    let n = pixels();
    let whole = run(&mut cpu, &histogram(KernelId::BlockHistogram, "right-sized", n, n, n, 64)).unwrap();
    let (findings, _) = cpu.take_findings();
    assert!(findings.iter().all(|f| !f.kind.undefined()), "{findings:#?}");
    let half = run(&mut cpu, &histogram(KernelId::BlockHistogram, "spans at half size", n, n, n / 2, 64)).unwrap();
    assert_eq!(half[2].1, whole[2].1, "sorted_pixels");
    assert_eq!(half[3].1[..], whole[3].1[..half[3].1.len()], "the spans the half-sized buffer holds");
    assert_eq!(half[4].1, whole[4].1, "block_stats");
}
