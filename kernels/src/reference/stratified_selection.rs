//! What the embeddable selection kernels (`strata_select`, `strata_resample`,
//! `wgsl/embed/`) compute, stated in plain Rust with the same f32 operations in the same
//! order, so that a backend's output can be compared bit for bit (up to the registry's
//! small ULP bound for the float outputs).

use crate::blue_noise::BlueNoiseTables;
use crate::embed_types::{
    CANONICAL_SLOT, INVALID_SLOT, MAX_SELECTED, NO_PAYLOAD, NO_SLOT, ResampleInput, ResampleOutput, SelectedCandidates,
    SelectionParams,
};
use crate::types::{Candidate, ClusterSpan, OBJECT_ID_NONE};

/// PCG hash (Jarzynski and Olano 2020), WGSL `selection_hash`.
pub fn selection_hash(v: u32) -> u32 {
    let state = v.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

fn unit_float(bits: u32) -> f32 {
    (bits >> 8) as f32 * (1.0 / 16_777_216.0)
}

const BELOW_ONE: f32 = 0.999_999_94;

fn fract(x: f32) -> f32 {
    x - x.floor()
}

/// The K selection positions in [0, 1) and the resampling number of one pixel in one
/// frame (WGSL `selection_numbers`).
pub fn selection_numbers(params: &SelectionParams, tables: &BlueNoiseTables, x: u32, y: u32) -> ([f32; 4], f32) {
    let mut state = selection_hash(x ^ selection_hash(y ^ selection_hash(params.frame ^ selection_hash(params.seed))));
    let mut white = || {
        state = selection_hash(state);
        unit_float(state)
    };
    let blue = |sample_index: u32, dimension: u32, white: &mut dyn FnMut() -> f32| {
        let shift = unit_float(selection_hash(params.seed ^ selection_hash(0x5eed_u32.wrapping_add(dimension))));
        let k = tables.stratum(x, y, sample_index, dimension) as f32;
        fract((k + white()) / 256.0 + shift).min(BELOW_ONE)
    };
    let k = params.candidates.clamp(1, MAX_SELECTED) as f32;
    let sample_index = params.frame & 255;
    let offsets = |u: f32| [0.0f32, 1.0, 2.0, 3.0].map(|step| (u + step / k).min(BELOW_ONE));
    match params.sampler {
        0 => {
            let positions = [white(), white(), white(), white()];
            (positions, white())
        }
        1 => {
            let first = params.frame.wrapping_mul(4);
            let positions = [0, 1, 2, 3].map(|j| blue(first.wrapping_add(j), 0, &mut white));
            (positions, blue(first, 1, &mut white))
        }
        2 => {
            let u = white() / k;
            (offsets(u), white())
        }
        3 => {
            let u = blue(sample_index, 0, &mut white) / k;
            (offsets(u), blue(sample_index, 1, &mut white))
        }
        _ => {
            let u = blue(sample_index, 0, &mut white) * 0.25;
            let positions = [u, 0.5 - u, 0.5 + u, 1.0 - u].map(|p| p.min(BELOW_ONE));
            (positions, blue(sample_index, 1, &mut white))
        }
    }
}

/// `strata_select` on the CPU: per pixel, the K payloads of its cluster's run at its
/// stratified positions. `payloads` is read unless `params.identity_payload` is 1.
pub fn select(
    params: &SelectionParams,
    tables: &BlueNoiseTables,
    candidates: &[Candidate],
    payloads: &[u32],
    sorted_pixels: &[u32],
    spans: &[ClusterSpan],
) -> Vec<SelectedCandidates> {
    let mut out = Vec::with_capacity((params.width * params.height) as usize);
    for y in 0..params.height {
        for x in 0..params.width {
            let pixel = (y * params.width + x) as usize;
            let (positions, resample_number) = selection_numbers(params, tables, x, y);
            let mut result = SelectedCandidates { payloads: [NO_PAYLOAD; 4], resample_number, ..Default::default() };
            let span = spans[pixel];
            if candidates[pixel].object_id != OBJECT_ID_NONE && span.length > 0 {
                let k = params.candidates.clamp(1, MAX_SELECTED);
                let n = span.length;
                result.run_length = n;
                result.run_valid = span.valid;
                result.selected = k;
                for (payload, position) in result.payloads.iter_mut().zip(positions).take(k as usize) {
                    let index = span.offset + ((position * n as f32).floor() as u32).min(n - 1);
                    let source = sorted_pixels[index as usize];
                    *payload = if params.identity_payload != 0 { source } else { payloads[source as usize] };
                }
            }
            out.push(result);
        }
    }
    out
}

fn usable(value: f32) -> bool {
    let bits = value.to_bits();
    bits & 0x7fff_ffff == 0 || (bits >> 31 == 0 && bits < 0x7f80_0000)
}

/// `strata_resample` on the CPU: inverse-CDF choice among the canonical sample and the
/// selected ones with the pixel's resampling number.
pub fn resample(selections: &[SelectedCandidates], inputs: &[ResampleInput]) -> Vec<ResampleOutput> {
    let invalid = |sum| ResampleOutput { payload: NO_PAYLOAD, slot: INVALID_SLOT, weight: 0.0, weight_sum: sum };
    selections
        .iter()
        .zip(inputs)
        .map(|(selection, input)| {
            let k = selection.selected as usize;
            let mut ok = usable(input.canonical_weight) && usable(input.canonical_target);
            let mut total = input.canonical_weight;
            for slot in 0..k {
                ok = ok && usable(input.weights[slot]) && usable(input.targets[slot]);
                total += input.weights[slot];
            }
            if !ok || !usable(total) {
                return invalid(0.0);
            }
            if total <= 0.0 {
                return ResampleOutput { payload: NO_PAYLOAD, slot: NO_SLOT, weight: 0.0, weight_sum: 0.0 };
            }
            let u = selection.resample_number * total;
            let mut running = input.canonical_weight;
            let mut found = u < running;
            let mut chosen = if input.canonical_weight > 0.0 { CANONICAL_SLOT } else { NO_SLOT };
            for slot in 0..k {
                if !found && input.weights[slot] > 0.0 {
                    running += input.weights[slot];
                    chosen = slot as u32;
                    found = u < running;
                }
            }
            let (payload, target) = if chosen < MAX_SELECTED {
                (selection.payloads[chosen as usize], input.targets[chosen as usize])
            } else {
                (input.canonical_payload, input.canonical_target)
            };
            if target <= 0.0 {
                return invalid(total);
            }
            ResampleOutput { payload, slot: chosen, weight: total / target, weight_sum: total }
        })
        .collect()
}
