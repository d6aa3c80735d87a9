//! Check of the embeddable selection kernels: `strata_select` on generated candidate
//! images (the reference histogram's runs, shifted grids, every sampler variant, K from 1
//! to 4, identity and engine payloads) and `strata_resample` on generated weights (zero,
//! NaN, infinite and negative ones included), against the Rust reference of
//! `strata_kernels::reference::stratified_selection`. Payloads and slots bit for bit;
//! resampling numbers and weights within the registry's ULP bound.

use super::{Case, CheckConfig, Compare, KernelCheck, Output};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg32;
use strata_backends::backend::{download, upload};
use strata_backends::{Backend, Bind};
use strata_kernels::blue_noise::BlueNoiseTables;
use strata_kernels::embed_types::{ResampleInput, ResampleOutput, SelectedCandidates, SelectionParams};
use strata_kernels::reference::block_histogram::{HistogramOutput, block_histogram};
use strata_kernels::reference::stratified_selection::{resample, select};
use strata_kernels::selection::{MAX_SELECTED, SamplerVariant};
use strata_kernels::types::Candidate;
use strata_kernels::{BlockGrid, KernelId, Registry};
use strata_render::histogram_pass::PassError;
use strata_render::synthetic::{CandidateMix, candidate_image};

/// Checks [`KernelId::StrataSelect`] or [`KernelId::StrataResample`].
pub struct SelectionCheck(pub KernelId);

/// Every sampler variant of Table 2.
const SAMPLERS: [SamplerVariant; 6] = SamplerVariant::ALL;

/// The sampler variant and K of a case family: the 24 families are every variant × every
/// K from 1 to 4 (each K has its own stratified pattern).
fn sampler_and_k(family: u32) -> (SamplerVariant, u32) {
    (SAMPLERS[family as usize % SAMPLERS.len()], 1 + family / SAMPLERS.len() as u32 % MAX_SELECTED)
}

/// The generated inputs of one case.
struct Inputs {
    params: SelectionParams,
    candidates: Vec<Candidate>,
    payloads: Vec<u32>,
    histogram: HistogramOutput,
    resample_inputs: Vec<ResampleInput>,
}

fn inputs(case: &Case) -> Inputs {
    let (width, height) = (case.width, case.height);
    let mix = CandidateMix { objects: 1 + (case.seed % 5) as u32, key_levels: 7, awkward: 0.05 };
    let candidates = candidate_image(width, height, case.seed, mix);
    let b = case.block_size;
    let grid = BlockGrid::new(width, height, b)
        .and_then(|g| g.with_shift((case.seed % u64::from(b)) as u32, (case.seed * 3 % u64::from(b)) as u32))
        .expect("cases have valid grids");
    let histogram = block_histogram(grid, &candidates);
    let mut rng = Pcg32::seed_from_u64(case.seed);
    let pixels = (width * height) as usize;
    let payloads = (0..pixels).map(|_| rng.random::<u32>() >> 4).collect();
    let params = SelectionParams {
        width,
        height,
        frame: (case.seed * 37 % 1000) as u32,
        seed: case.seed as u32,
        candidates: sampler_and_k(case.family).1,
        sampler: sampler_and_k(case.family).0.id(),
        identity_payload: (case.seed % 2) as u32,
        _pad: 0,
    };
    let weight = |rng: &mut Pcg32| match rng.random_range(0..40) {
        0..8 => 0.0,
        8 => f32::NAN,
        9 => f32::INFINITY,
        10 => -1.0,
        _ => rng.random::<f32>() * 10.0,
    };
    let resample_inputs = (0..pixels)
        .map(|_| ResampleInput {
            weights: std::array::from_fn(|_| weight(&mut rng)),
            targets: std::array::from_fn(|_| rng.random::<f32>() + 0.01),
            canonical_weight: weight(&mut rng),
            canonical_target: rng.random::<f32>() + 0.01,
            canonical_payload: rng.random(),
            _pad: 0,
        })
        .collect();
    Inputs { params, candidates, payloads, histogram, resample_inputs }
}

fn reference_selections(inputs: &Inputs, tables: &BlueNoiseTables) -> Vec<SelectedCandidates> {
    select(
        &inputs.params,
        tables,
        &inputs.candidates,
        &inputs.payloads,
        &inputs.histogram.sorted_pixels,
        &inputs.histogram.spans,
    )
}

fn ulp(kernel: KernelId) -> u32 {
    Registry::shared().ok().and_then(|r| r.get(kernel).spec.float_ulp_bound).unwrap_or(0)
}

fn selection_outputs(selections: &[SelectedCandidates]) -> Vec<Output> {
    let words: Vec<u32> = bytemuck::cast_slice(selections).to_vec();
    let (mut integers, mut floats) = (Vec::new(), Vec::new());
    for record in words.chunks_exact(8) {
        integers.extend_from_slice(&record[..4]);
        integers.extend_from_slice(&record[5..]);
        floats.push(record[4]);
    }
    vec![
        Output { name: "payloads and run counts", words: integers, compare: Compare::Exact },
        Output {
            name: "resample_number",
            words: floats,
            compare: Compare::Float { ulp: ulp(KernelId::StrataSelect), max_outside: 0.0 },
        },
    ]
}

fn resample_outputs(outputs: &[ResampleOutput]) -> Vec<Output> {
    let words: Vec<u32> = bytemuck::cast_slice(outputs).to_vec();
    let (mut integers, mut floats) = (Vec::new(), Vec::new());
    for record in words.chunks_exact(4) {
        integers.extend_from_slice(&record[..2]);
        floats.extend_from_slice(&record[2..]);
    }
    vec![
        Output { name: "payload and slot", words: integers, compare: Compare::Exact },
        Output {
            name: "weight and weight_sum",
            words: floats,
            compare: Compare::Float { ulp: ulp(KernelId::StrataResample), max_outside: 0.0 },
        },
    ]
}

impl KernelCheck for SelectionCheck {
    fn kernel(&self) -> KernelId {
        self.0
    }

    fn cases(&self, config: CheckConfig) -> Vec<Case> {
        // Seed s runs family s mod 24 (every variant × K) at every size; the quick check
        // keeps the 1 x 1 image for one seed in five.
        let families = SAMPLERS.len() as u64 * u64::from(MAX_SELECTED);
        let sizes: &[(u32, u32, u32)] = if config.full {
            &[(1, 1, 4), (17, 33, 8), (64, 64, 16), (129, 65, 32)]
        } else {
            &[(1, 1, 4), (17, 33, 8), (40, 24, 16)]
        };
        let mut cases = Vec::new();
        for seed in 0..families {
            for &(width, height, block_size) in sizes {
                if !config.full && width == 1 && seed % 5 != 0 {
                    continue;
                }
                let family = (seed % families) as u32;
                let (sampler, k) = sampler_and_k(family);
                cases.push(Case {
                    label: format!("{width}x{height} B={block_size} seed {seed} {sampler:?} K={k}"),
                    width,
                    height,
                    block_size,
                    seed: 0x5e1ec7 ^ seed << 12 ^ u64::from(width),
                    family,
                });
            }
        }
        cases
    }

    fn run(&self, backend: &mut dyn Backend, case: &Case) -> Result<Vec<Output>, PassError> {
        let registry = Registry::shared()?;
        let kernel = registry.get(self.0);
        let inputs = inputs(case);
        let pixels = inputs.candidates.len() as u64;
        let [group_x, group_y, _] = kernel.workgroup_size;
        let workgroups = [case.width.div_ceil(group_x), case.height.div_ceil(group_y), 1];
        let params = upload(backend, "selection params", &[inputs.params])?;
        let mut buffers = vec![params];
        let result = if self.0 == KernelId::StrataSelect {
            let tables = BlueNoiseTables::new();
            let binding = |name: &str| {
                kernel
                    .binding_named(name)
                    .map(|b| b.binding)
                    .ok_or_else(|| PassError::Input(format!("kernel {}: no binding named {name}", kernel.name())))
            };
            let mut binds = vec![Bind::new(binding("params")?, params)];
            let packed = tables.packed();
            let inputs_words: [(&str, &[u32]); 5] = [
                ("candidates", bytemuck::cast_slice(&inputs.candidates)),
                ("payloads", &inputs.payloads),
                ("sorted_pixels", &inputs.histogram.sorted_pixels),
                ("spans", bytemuck::cast_slice(&inputs.histogram.spans)),
                ("blue_noise", &packed),
            ];
            for (name, words) in inputs_words {
                let buffer = upload(backend, "selection input", words)?;
                buffers.push(buffer);
                binds.push(Bind::new(binding(name)?, buffer));
            }
            let out = backend.create_buffer("selections", pixels * size_of::<SelectedCandidates>() as u64)?;
            buffers.push(out);
            backend.write_buffer(out, 0, &vec![0xa5; (pixels as usize) * size_of::<SelectedCandidates>()])?;
            binds.push(Bind::new(binding("selections")?, out));
            backend.dispatch(kernel, &binds, workgroups)?;
            download::<SelectedCandidates>(backend, out).map(|s| selection_outputs(&s))
        } else {
            let selections = reference_selections(&inputs, &BlueNoiseTables::new());
            let selections = upload(backend, "selections", &selections)?;
            let resample_inputs = upload(backend, "resample inputs", &inputs.resample_inputs)?;
            let out = backend.create_buffer("resampled", pixels * size_of::<ResampleOutput>() as u64)?;
            buffers.extend([selections, resample_inputs, out]);
            backend.write_buffer(out, 0, &vec![0xa5; (pixels as usize) * size_of::<ResampleOutput>()])?;
            let binds =
                [Bind::new(0, params), Bind::new(1, selections), Bind::new(2, resample_inputs), Bind::new(3, out)];
            backend.dispatch(kernel, &binds, workgroups)?;
            download::<ResampleOutput>(backend, out).map(|r| resample_outputs(&r))
        };
        for buffer in buffers {
            backend.destroy_buffer(buffer)?;
        }
        Ok(result?)
    }

    fn reference(&self, case: &Case) -> Vec<Output> {
        let inputs = inputs(case);
        let selections = reference_selections(&inputs, &BlueNoiseTables::new());
        if self.0 == KernelId::StrataSelect {
            selection_outputs(&selections)
        } else {
            resample_outputs(&resample(&selections, &inputs.resample_inputs))
        }
    }
}
