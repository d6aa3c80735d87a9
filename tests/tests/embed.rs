//! The embedding API (`strata-embed`) on a raw wgpu device, as an engine would use it:
//! outputs identical to the plain-Rust statement of the kernels over sizes, settings and
//! frames; the exported WGSL modules, compiled on their own, giving the same outputs;
//! the selection's statistics (every run member selected K/n times in expectation over
//! renders; temporal stratification over frames); the resampling's choice frequencies;
//! and every configuration error named at configuration or bind time.

use strata_embed::contract::{
    CANONICAL_SLOT, Candidate, INVALID_SLOT, NO_PAYLOAD, ResampleInput, ResampleOutput, SelectedCandidates,
};
use strata_embed::wgsl::{ModuleId, module};
use strata_embed::{
    EmbedError, Executor, SamplerVariant, SelectionSettings, WgpuBuffers, WgpuResampleBuffers, WgpuSelection,
};
use strata_kernels::BlockGrid;
use strata_kernels::blue_noise::BlueNoiseTables;
use strata_kernels::reference::block_histogram::{block_histogram, unmasked};
use strata_kernels::reference::stratified_selection::{resample, select};
use strata_tests::{engine_device, read_wgpu_buffer};
use wgpu::util::DeviceExt;

const USAGE: wgpu::BufferUsages =
    wgpu::BufferUsages::STORAGE.union(wgpu::BufferUsages::COPY_SRC).union(wgpu::BufferUsages::COPY_DST);

/// An engine's buffers for one image.
struct EngineBuffers {
    candidates: wgpu::Buffer,
    payloads: wgpu::Buffer,
    selections: wgpu::Buffer,
    inputs: wgpu::Buffer,
    outputs: wgpu::Buffer,
}

impl EngineBuffers {
    fn new(device: &wgpu::Device, candidates: &[Candidate], payloads: &[u32], inputs: &[ResampleInput]) -> Self {
        let init = |contents: &[u8]| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: None, contents, usage: USAGE })
        };
        let empty = |bytes: usize| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: None,
                size: (bytes * candidates.len()) as u64,
                usage: USAGE,
                mapped_at_creation: false,
            })
        };
        Self {
            candidates: init(bytemuck::cast_slice(candidates)),
            payloads: init(bytemuck::cast_slice(payloads)),
            selections: empty(size_of::<SelectedCandidates>()),
            inputs: init(bytemuck::cast_slice(inputs)),
            outputs: empty(size_of::<ResampleOutput>()),
        }
    }

    fn bind(&self, with_payloads: bool) -> WgpuBuffers<'_> {
        WgpuBuffers {
            candidates: (&self.candidates).into(),
            payloads: with_payloads.then(|| (&self.payloads).into()),
            selections: (&self.selections).into(),
            resample: Some(WgpuResampleBuffers { inputs: (&self.inputs).into(), outputs: (&self.outputs).into() }),
        }
    }
}

/// Deterministic test candidates: `objects` clusters, keys with ties, a few invalid and
/// a few pixels without a candidate.
fn candidates(width: u32, height: u32, objects: u32, seed: u32) -> Vec<Candidate> {
    (0..width * height)
        .map(|p| {
            let h = strata_kernels::reference::stratified_selection::selection_hash(p ^ seed.wrapping_mul(0x9e37_79b9));
            let key = match h % 53 {
                0 => f32::NAN,
                1 => -1.0,
                _ => (h >> 8) as f32 % 29.0 * 0.25,
            };
            let object_id =
                if h.is_multiple_of(61) { strata_embed::contract::OBJECT_ID_NONE } else { (h >> 20) % objects };
            Candidate { key, object_id }
        })
        .collect()
}

/// Per-pixel resampling inputs: weights in [0, 4) with zeros, and with `invalid` a few
/// NaN, infinite and negative ones.
fn resample_inputs(count: usize, seed: u32, invalid: bool) -> Vec<ResampleInput> {
    let hash = strata_kernels::reference::stratified_selection::selection_hash;
    (0..count as u32)
        .map(|p| {
            let h = |i: u32| hash(p ^ hash(i ^ seed));
            let w = |i: u32| match h(i) % 71 {
                0..10 => 0.0,
                10 if invalid => f32::NAN,
                11 if invalid => f32::INFINITY,
                12 if invalid => -1.0,
                _ => (h(i) >> 8) as f32 / 16_777_216.0 * 4.0,
            };
            ResampleInput {
                weights: [w(0), w(1), w(2), w(3)],
                targets: [1.0, 2.0, 0.5, 3.0],
                canonical_weight: w(4),
                canonical_target: 1.5,
                canonical_payload: p,
                _pad: 0,
            }
        })
        .collect()
}

/// Runs frame `frame` through the pass: selection, then resampling of `inputs`.
fn run_frame(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    pass: &WgpuSelection,
    buffers: &EngineBuffers,
    with_payloads: bool,
    frame: u32,
) -> (Vec<SelectedCandidates>, Vec<ResampleOutput>) {
    let bindings = pass.bind(device, &buffers.bind(with_payloads)).unwrap_or_else(|e| panic!("{e}"));
    let mut encoder = device.create_command_encoder(&Default::default());
    pass.encode_selection(queue, &mut encoder, &bindings, frame).unwrap();
    pass.encode_resampling(&mut encoder, &bindings).unwrap();
    queue.submit([encoder.finish()]);
    (read_wgpu_buffer(device, queue, &buffers.selections), read_wgpu_buffer(device, queue, &buffers.outputs))
}

/// The pass's outputs for every combination of image size, block size, K, sampler,
/// masking, block shifting and payload mode, frames 0-2, equal the Rust reference bit
/// for bit (histogram on the frame's shifted grid, selection, resampling).
#[test]
fn pass_matches_the_reference() {
    let Some((device, queue)) = engine_device("pass_matches_the_reference", None) else {
        return;
    };
    let tables = BlueNoiseTables::new();
    let samplers = SamplerVariant::ALL;
    let cases = [(1, 1, 4), (37, 21, 8), (64, 48, 16), (70, 33, 32), (16, 16, 16)];
    for (index, &(width, height, block_size)) in cases.iter().enumerate() {
        let settings = SelectionSettings {
            block_size,
            candidates: 1 + index as u32 % 4,
            masking: index % 2 == 0,
            block_shift: index % 3 != 0,
            sampler: samplers[index % samplers.len()],
        };
        let context = format!("{width}x{height} {settings:?}");
        let candidates = candidates(width, height, 3, index as u32);
        let pixels = candidates.len();
        let payloads: Vec<u32> = (0..pixels as u32).map(|p| p * 3 + 7).collect();
        let inputs = resample_inputs(pixels, index as u32, true);
        let buffers = EngineBuffers::new(&device, &candidates, &payloads, &inputs);
        let mut pass =
            WgpuSelection::new(&device, settings, width, height).unwrap_or_else(|e| panic!("{context}: {e}"));
        pass.set_seed(17 * index as u32);
        for frame in 0..3 {
            let with_payloads = frame != 1;
            let (selections, resampled) = run_frame(&device, &queue, &pass, &buffers, with_payloads, frame);
            let params = pass.frame_params(frame, !with_payloads).unwrap();
            let h = params.histogram;
            let grid = BlockGrid::new(width, height, block_size).unwrap().with_shift(h.shift_x, h.shift_y).unwrap();
            let clustered = if settings.masking { candidates.clone() } else { unmasked(&candidates) };
            let histogram = block_histogram(grid, &clustered);
            let want =
                select(&params.selection, &tables, &candidates, &payloads, &histogram.sorted_pixels, &histogram.spans);
            for p in 0..pixels {
                assert_eq!(
                    bytemuck::bytes_of(&selections[p]),
                    bytemuck::bytes_of(&want[p]),
                    "{context} frame {frame} pixel {p}: {:?} vs {:?}",
                    selections[p],
                    want[p]
                );
            }
            let want = resample(&want, &inputs);
            for p in 0..pixels {
                assert_eq!(resampled[p], want[p], "{context} frame {frame} pixel {p}: resampling");
            }
            if block_size == 16 && width == 64 {
                assert!(selections.iter().any(|s| s.selected > 0 && s.payloads[0] != NO_PAYLOAD));
                assert!(resampled.iter().any(|r| r.slot == INVALID_SLOT), "the inputs hold no invalid weight");
            }
        }
    }
}

/// The exported WGSL modules, compiled by wgpu on their own with their exported
/// bind-group layouts and run in the documented order, give exactly the pass's outputs.
#[test]
fn exported_wgsl_modules_give_the_same_outputs() {
    let Some((device, queue)) = engine_device("exported_wgsl_modules_give_the_same_outputs", None) else {
        return;
    };
    let (width, height) = (45, 30);
    let settings = SelectionSettings { block_shift: true, ..Default::default() };
    let candidates = candidates(width, height, 4, 99);
    let pixels = candidates.len();
    let payloads: Vec<u32> = (0..pixels as u32).rev().collect();
    let inputs = resample_inputs(pixels, 3, true);
    let buffers = EngineBuffers::new(&device, &candidates, &payloads, &inputs);
    let mut pass = WgpuSelection::new(&device, settings, width, height).unwrap();
    pass.set_seed(5);
    let frame = 11;
    let (want_selections, want_resampled) = run_frame(&device, &queue, &pass, &buffers, true, frame);

    // The same frame by hand from the exported modules.
    let params = pass.frame_params(frame, false).unwrap();
    let tables = BlueNoiseTables::new();
    let storage = |contents: &[u8]| {
        device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: None, contents, usage: USAGE })
    };
    let uniform = |contents: &[u8]| {
        device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: None,
            contents,
            usage: wgpu::BufferUsages::UNIFORM,
        })
    };
    let blocks = 64 * 64;
    let histogram_params = uniform(bytemuck::bytes_of(&params.histogram));
    let selection_params = uniform(bytemuck::bytes_of(&params.selection));
    let candidate_buffer = storage(bytemuck::cast_slice(&candidates));
    let sorted = storage(&vec![0; pixels * 4]);
    let spans = storage(&vec![0; pixels * 12]);
    let stats = storage(&vec![0; blocks * 12]);
    let blue_noise = storage(bytemuck::cast_slice(&tables.packed()));
    let payload_buffer = storage(bytemuck::cast_slice(&payloads));
    let selections = storage(&vec![0; pixels * size_of::<SelectedCandidates>()]);
    let input_buffer = storage(bytemuck::cast_slice(&inputs));
    let resampled = storage(&vec![0; pixels * size_of::<ResampleOutput>()]);
    let subgroups = device.features().contains(wgpu::Features::SUBGROUP);
    let executor = Executor::of_device(&format!("{:?}", device.adapter_info().device_type), false);
    let histogram_id = strata_embed::wgsl::histogram_module(settings.block_size, subgroups, executor);
    // A CPU driver (lavapipe) ranks blocks of every size, a GPU sorts them with the network.
    let network = if subgroups { ModuleId::HistogramSubgroup } else { ModuleId::Histogram };
    let expected = if executor == Executor::CpuDriver { ModuleId::HistogramRank } else { network };
    assert_eq!(histogram_id, expected, "{executor:?}");
    let runs: [(ModuleId, Vec<&wgpu::Buffer>, [u32; 3]); 3] = [
        (
            histogram_id,
            vec![&histogram_params, &candidate_buffer, &sorted, &spans, &stats],
            params.histogram_workgroups,
        ),
        (
            ModuleId::Select,
            vec![&selection_params, &candidate_buffer, &payload_buffer, &sorted, &spans, &blue_noise, &selections],
            params.pixel_workgroups,
        ),
        (ModuleId::Resample, vec![&selection_params, &selections, &input_buffer, &resampled], params.pixel_workgroups),
    ];
    let mut encoder = device.create_command_encoder(&Default::default());
    for (id, resources, [x, y, z]) in &runs {
        let module = module(*id).unwrap();
        assert_eq!(module.bindings.len(), resources.len(), "{id:?}: binding count");
        let entries = module.wgpu_layout_entries();
        let layout =
            device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: None, entries: &entries });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: None,
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: None,
            source: wgpu::ShaderSource::Wgsl(module.source.as_str().into()),
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: None,
            layout: Some(&pipeline_layout),
            module: &shader,
            entry_point: Some(&module.entry_point),
            compilation_options: Default::default(),
            cache: None,
        });
        let group_entries: Vec<_> = module
            .bindings
            .iter()
            .zip(resources)
            .map(|(b, buffer)| wgpu::BindGroupEntry { binding: b.binding, resource: buffer.as_entire_binding() })
            .collect();
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &layout,
            entries: &group_entries,
        });
        let mut compute = encoder.begin_compute_pass(&Default::default());
        compute.set_pipeline(&pipeline);
        compute.set_bind_group(0, &group, &[]);
        compute.dispatch_workgroups(*x, *y, *z);
    }
    queue.submit([encoder.finish()]);
    let got_selections: Vec<SelectedCandidates> = read_wgpu_buffer(&device, &queue, &selections);
    let got_resampled: Vec<ResampleOutput> = read_wgpu_buffer(&device, &queue, &resampled);
    assert_eq!(bytemuck::cast_slice::<_, u32>(&got_selections), bytemuck::cast_slice::<_, u32>(&want_selections));
    assert_eq!(got_resampled, want_resampled);
}

/// What `selection_counts` repeats.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Renders {
    /// Frame 5 of independent renders (a new seed each).
    Independent,
    /// Frame 5 of one render again and again (the negative control: nothing random).
    SameSeed,
    /// Frames 0, 1, ... of one render.
    Frames,
}

/// Counts, per pixel and run position, how often the pass selects each member of the
/// pixel's run over `renders` repetitions with K = `k`.
fn selection_counts(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    sampler: SamplerVariant,
    k: u32,
    renders: u32,
    mode: Renders,
) -> Vec<Vec<u32>> {
    let (width, height) = (16, 16);
    // Two objects with runs of 48 and 208 pixels; distinct keys.
    let candidates: Vec<Candidate> = (0..width * height)
        .map(|p| Candidate { key: (p * 37 % 256) as f32, object_id: u32::from((p % 16) < 3) })
        .collect();
    let payloads: Vec<u32> = (0..width * height).collect();
    let inputs = resample_inputs(candidates.len(), 0, false);
    let buffers = EngineBuffers::new(device, &candidates, &payloads, &inputs);
    let histogram = block_histogram(BlockGrid::new(width, height, 16).unwrap(), &candidates);
    let mut counts: Vec<Vec<u32>> = histogram.spans.iter().map(|span| vec![0; span.length as usize]).collect();
    let settings = SelectionSettings { sampler, candidates: k, ..Default::default() };
    let mut pass = WgpuSelection::new(device, settings, width, height).unwrap();
    pass.set_seed(1);
    for render in 0..renders {
        let frame = match mode {
            Renders::Independent => {
                pass.set_seed(1000 + render);
                5
            }
            Renders::SameSeed => 5,
            Renders::Frames => render,
        };
        let (selections, _) = run_frame(device, queue, &pass, &buffers, false, frame);
        for (pixel, selection) in selections.iter().enumerate() {
            let span = histogram.spans[pixel];
            assert_eq!(selection.selected, k, "pixel {pixel}: slots filled");
            for &payload in &selection.payloads[..k as usize] {
                let position = (span.offset..span.offset + span.length)
                    .position(|i| histogram.sorted_pixels[i as usize] == payload)
                    .expect("selected from the pixel's own run");
                counts[pixel][position] += 1;
            }
        }
    }
    counts
}

/// Over independent renders every member of a pixel's run is selected K/n times per
/// render in expectation (what keeps the fixed 1/K normalisation unbiased), for every
/// K from 1 to 4 and every sampler variant. The same statistics fail on the same render
/// repeated and on the positions `strata-embed` once used for K < 4 (the first K slots
/// of the four-slot antithetic pattern, which never reach the top of a run).
#[test]
fn every_run_member_is_selected_k_over_n_times() {
    let Some((device, queue)) = engine_device("every_run_member_is_selected_k_over_n_times", None) else {
        return;
    };
    let renders = 96;
    for sampler in SamplerVariant::ALL {
        for k in 1..=4 {
            let counts = selection_counts(&device, &queue, sampler, k, renders, Renders::Independent);
            if let Err(message) = k_over_n(&counts, renders, k) {
                panic!("{sampler:?} K = {k}: {message}");
            }
        }
    }
    // The check can fail: the same render repeated selects the same members every time.
    let counts = selection_counts(&device, &queue, SamplerVariant::Antithetic, 4, 64, Renders::SameSeed);
    assert!(k_over_n(&counts, 64, 4).is_err(), "a deterministic selection passed the K/n check");
    // ... and on the old biased positions, drawn here with the same run lengths.
    for k in 1..4 {
        let counts = biased_counts(k, renders);
        let verdict = k_over_n(&counts, renders, k);
        assert!(verdict.is_err(), "K = {k}: the first K antithetic slots passed the K/n check");
    }
}

/// Counts of the positions `strata-embed` used before the selection had one home: the
/// first K of {b, 1/2 - b, 1/2 + b, 1 - b} / ... (the four-slot antithetic pattern) with
/// b uniform, for runs of 48 and 208 members as in [`selection_counts`].
fn biased_counts(k: u32, renders: u32) -> Vec<Vec<u32>> {
    let pattern = strata_kernels::selection::StratifiedPattern::antithetic(4);
    let mut state = 0x1234_5678u32;
    let mut counts: Vec<Vec<u32>> = (0..256).map(|p| vec![0; if p % 16 < 3 { 48 } else { 208 }]).collect();
    for _ in 0..renders {
        for members in &mut counts {
            state = strata_kernels::reference::stratified_selection::selection_hash(state);
            let b = (state >> 8) as f32 / 16_777_216.0;
            let n = members.len();
            for position in &pattern.positions(b)[..k as usize] {
                members[((position * n as f32) as usize).min(n - 1)] += 1;
            }
        }
    }
    counts
}

/// Whether per-pixel counts of selected run members are consistent with every member
/// being selected renders·K/n times in expectation. Two Pearson statistics, each against
/// independent uniform draws (the stratified patterns disperse less, so both are upper
/// bounds for them): the sum over pixels of each pixel's chi-square across its members
/// (any member over- or under-selected; z-score of the summed chi-square under 6), and
/// one chi-square of all selections by relative run position in 8 bins (a part of every
/// run never reached; under 60 at 7 degrees of freedom, p ≈ 1e-10).
fn k_over_n(counts: &[Vec<u32>], renders: u32, k: u32) -> Result<(), String> {
    let draws = f64::from(renders * k);
    let (mut statistic, mut freedom) = (0.0, 0.0);
    let (mut observed, mut expected) = ([0.0f64; 8], [0.0f64; 8]);
    for members in counts {
        let n = members.len();
        let mean = draws / n as f64;
        for (position, &count) in members.iter().enumerate() {
            statistic += (f64::from(count) - mean).powi(2) / mean;
            let bin = position * 8 / n;
            observed[bin] += f64::from(count);
            expected[bin] += mean;
        }
        freedom += (n - 1) as f64;
    }
    let z = (statistic - freedom) / (2.0 * freedom).sqrt();
    if z > 6.0 {
        return Err(format!("members' chi-square {statistic:.0} on {freedom} degrees of freedom (z = {z:.1})"));
    }
    let by_position: f64 = observed.iter().zip(&expected).map(|(o, e)| (o - e).powi(2) / e).sum();
    if by_position > 60.0 {
        return Err(format!(
            "selections by relative run position {observed:?}, {expected:.0?} expected (chi-square {by_position:.0})"
        ));
    }
    Ok(())
}

/// Over the 256 frames of one render, the antithetic blue-noise positions visit every
/// member of a run almost exactly K·256/n times (the temporal stratification of Table
/// 2), far more evenly than uncorrelated random positions.
#[test]
fn blue_noise_stratifies_selection_over_frames() {
    let Some((device, queue)) = engine_device("blue_noise_stratifies_selection_over_frames", None) else {
        return;
    };
    let spread = |sampler| {
        let k = 4;
        let counts = selection_counts(&device, &queue, sampler, k, 256, Renders::Frames);
        let mut squared = 0.0;
        let mut cells = 0.0;
        for members in &counts {
            let expected = f64::from(256 * k) / members.len() as f64;
            for &count in members {
                squared += (f64::from(count) - expected).powi(2) / expected;
                cells += 1.0;
            }
        }
        squared / cells
    };
    let antithetic = spread(SamplerVariant::Antithetic);
    let random = spread(SamplerVariant::Random);
    eprintln!("mean (count - expected)^2 / expected over 256 frames: antithetic {antithetic:.4}, random {random:.4}");
    // Random positions: multinomial counts, (count - mean)^2 / mean ~ 1. Stratified: far less.
    assert!(random > 0.5 && random < 1.5, "random: {random}");
    assert!(antithetic < 0.1 * random, "antithetic {antithetic} vs random {random}");
}

/// Over renders, the resampling keeps each of the canonical and selected samples with
/// probability weight / sum (inverse CDF with a uniform number), and W = sum / target.
#[test]
fn resampling_chooses_in_proportion_to_the_weights() {
    let Some((device, queue)) = engine_device("resampling_chooses_in_proportion_to_the_weights", None) else {
        return;
    };
    let (width, height) = (8, 8);
    let candidates: Vec<Candidate> = (0..64).map(|p| Candidate { key: p as f32, object_id: 0 }).collect();
    let payloads: Vec<u32> = (0..64).collect();
    let inputs = resample_inputs(64, 7, false);
    let buffers = EngineBuffers::new(&device, &candidates, &payloads, &inputs);
    let renders = 400u32;
    let mut chosen = vec![[0u32; 5]; 64];
    let mut pass =
        WgpuSelection::new(&device, SelectionSettings { block_size: 8, ..Default::default() }, width, height).unwrap();
    for render in 0..renders {
        pass.set_seed(render);
        let (_, resampled) = run_frame(&device, &queue, &pass, &buffers, true, 3);
        for (pixel, output) in resampled.iter().enumerate() {
            let input = &inputs[pixel];
            let sum = input.canonical_weight + input.weights.iter().sum::<f32>();
            assert!((output.weight_sum - sum).abs() <= 1e-5 * sum);
            match output.slot {
                CANONICAL_SLOT => {
                    chosen[pixel][4] += 1;
                    assert_eq!(output.weight, output.weight_sum / input.canonical_target);
                }
                slot @ 0..4 => {
                    chosen[pixel][slot as usize] += 1;
                    assert_eq!(output.weight, output.weight_sum / input.targets[slot as usize]);
                }
                other => panic!("pixel {pixel}: slot {other:#x} with positive weights"),
            }
        }
    }
    for (pixel, counts) in chosen.iter().enumerate() {
        let input = &inputs[pixel];
        let sum = f64::from(input.canonical_weight + input.weights.iter().sum::<f32>());
        let weights = [input.weights[0], input.weights[1], input.weights[2], input.weights[3], input.canonical_weight];
        for (slot, &count) in counts.iter().enumerate() {
            let p = f64::from(weights[slot]) / sum;
            let expected = p * f64::from(renders);
            let sigma = (f64::from(renders) * p * (1.0 - p)).sqrt().max(0.5);
            assert!(
                (f64::from(count) - expected).abs() < 5.0 * sigma,
                "pixel {pixel} slot {slot}: chosen {count} times, {expected:.1} expected"
            );
        }
    }
}

fn expect_error(result: Result<impl Sized, EmbedError>, fragments: &[&str]) {
    let Err(error) = result else {
        panic!("expected an error mentioning {fragments:?}");
    };
    let message = error.to_string();
    for fragment in fragments {
        assert!(message.contains(fragment), "`{message}` does not mention `{fragment}`");
    }
}

/// Bad settings, bad engine buffers and devices below the pass's needs are errors at
/// configuration or bind time that name the field, buffer or limit.
#[test]
fn bad_configurations_are_named_errors() {
    let Some((device, queue)) = engine_device("bad_configurations_are_named_errors", None) else {
        return;
    };
    let new = |settings: SelectionSettings, w, h| WgpuSelection::new(&device, settings, w, h);
    expect_error(
        new(SelectionSettings { block_size: 12, ..Default::default() }, 8, 8),
        &["block_size = 12", "4, 8, 16 or 32"],
    );
    expect_error(new(SelectionSettings { block_size: 64, ..Default::default() }, 8, 8), &["block_size = 64"]);
    expect_error(new(SelectionSettings { candidates: 5, ..Default::default() }, 8, 8), &["candidates = 5"]);
    expect_error(new(SelectionSettings { candidates: 0, ..Default::default() }, 8, 8), &["candidates = 0"]);
    expect_error(new(SelectionSettings::default(), 0, 8), &["0x8"]);

    let pass = new(SelectionSettings::default(), 20, 10).unwrap();
    let candidates = candidates(20, 10, 2, 0);
    let inputs = resample_inputs(200, 0, false);
    let good = EngineBuffers::new(&device, &candidates, &vec![0; 200], &inputs);
    let small = EngineBuffers::new(&device, &candidates[..199], &vec![0; 199], &inputs[..199]);
    let mut buffers = good.bind(true);
    buffers.candidates = (&small.candidates).into();
    expect_error(pass.bind(&device, &buffers), &["`candidates`", "1592 bytes", "1600", "20x10"]);
    let mut buffers = good.bind(true);
    buffers.selections = (&small.selections).into();
    expect_error(pass.bind(&device, &buffers), &["`selections`"]);
    let mut buffers = good.bind(true);
    buffers.payloads = Some((&small.payloads).into());
    expect_error(pass.bind(&device, &buffers), &["`payloads`"]);
    let mut buffers = good.bind(true);
    buffers.resample = Some(WgpuResampleBuffers { inputs: (&small.inputs).into(), outputs: (&good.outputs).into() });
    expect_error(pass.bind(&device, &buffers), &["`resample_inputs`"]);
    let mut buffers = good.bind(true);
    buffers.candidates = strata_embed::WgpuBufferSlice { buffer: &good.candidates, offset: 4 };
    expect_error(pass.bind(&device, &buffers), &["`candidates`", "offset 4"]);
    let uniform_only = device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: 4096,
        usage: wgpu::BufferUsages::UNIFORM,
        mapped_at_creation: false,
    });
    let mut buffers = good.bind(true);
    buffers.candidates = (&uniform_only).into();
    expect_error(pass.bind(&device, &buffers), &["`candidates`", "STORAGE"]);
    let mut buffers = good.bind(true);
    buffers.resample = None;
    let bindings = pass.bind(&device, &buffers).unwrap();
    let mut encoder = device.create_command_encoder(&Default::default());
    expect_error(pass.encode_resampling(&mut encoder, &bindings), &["resampling buffers"]);
    drop(queue);

    // Devices below the pass's needs.
    for (limits, width, fragments) in [
        (
            wgpu::Limits { max_storage_buffers_per_shader_stage: 4, ..wgpu::Limits::downlevel_defaults() },
            16,
            &["max_storage_buffers_per_shader_stage", "is 4", "needs 6", "strata_select"][..],
        ),
        (
            wgpu::Limits { max_compute_workgroup_storage_size: 4096, ..wgpu::Limits::default() },
            16,
            &["max_compute_workgroup_storage_size", "is 4096", "block_histogram"][..],
        ),
        (
            wgpu::Limits { max_compute_workgroups_per_dimension: 16, ..wgpu::Limits::default() },
            200,
            &["max_compute_workgroups_per_dimension", "200x8"][..],
        ),
    ] {
        let Some((limited, _)) = engine_device("bad_configurations_are_named_errors", Some(limits)) else {
            return;
        };
        expect_error(WgpuSelection::new(&limited, SelectionSettings::default(), width, 8), fragments);
    }
}
