//! What the stratified selection computes (`kernels/wgsl/strata/selection.wgsl` and
//! `resampling.wgsl`, through the embeddable kernels `strata_select` and
//! `strata_resample`), stated in plain Rust with the same f32 operations in the same
//! order, so that a backend's output can be compared bit for bit (up to the registry's
//! small ULP bound for the float outputs). The positions come from the one table of
//! patterns, [`crate::selection::patterns`].

use crate::blue_noise::BlueNoiseTables;
use crate::embed_types::{
    CANONICAL_SLOT, INVALID_SLOT, NO_PAYLOAD, NO_SLOT, ResampleInput, ResampleOutput, SelectedCandidates,
    SelectionParams,
};
use crate::selection::patterns::BELOW_ONE;
use crate::selection::{MAX_SELECTED, Pattern, SamplerVariant};
use crate::types::{Candidate, ClusterSpan, OBJECT_ID_NONE};

pub use crate::hash::selection_hash;

fn unit_float(bits: u32) -> f32 {
    (bits >> 8) as f32 * (1.0 / 16_777_216.0)
}

fn fract(x: f32) -> f32 {
    x - x.floor()
}

/// One pixel's selection numbers in one frame (WGSL `SelectionNumbers`): the positions
/// of its slots in [0, 1) and its resampling number.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SelectionNumbers {
    /// Slot positions (slots from K on are meaningless).
    pub positions: [f32; 4],
    /// The resampling number.
    pub resample: f32,
}

/// WGSL `selection_numbers`: the numbers of `count` slots (clamped to 1..=4) of pixel
/// (x, y) in frame `frame` of render `seed` for sampler variant `sampler` (its
/// [`SamplerVariant::id`]; unknown ids behave as antithetic), from the sampler's
/// dimension pair `pair` (0: spatial slots, 1: temporal slots).
pub fn selection_numbers(
    tables: &BlueNoiseTables,
    (x, y): (u32, u32),
    frame: u32,
    seed: u32,
    sampler: u32,
    count: u32,
    pair: u32,
) -> SelectionNumbers {
    let mut state = selection_hash(
        x ^ selection_hash(
            y ^ selection_hash(frame ^ selection_hash(seed.wrapping_add(pair.wrapping_mul(0x9e37_79b9)))),
        ),
    );
    let mut white = || {
        state = selection_hash(state);
        unit_float(state)
    };
    let blue_at = |(x, y): (u32, u32), sample_index: u32, dimension: u32, white: &mut dyn FnMut() -> f32| {
        let shift = unit_float(selection_hash(seed ^ selection_hash(0x5eed_u32.wrapping_add(dimension))));
        let k = tables.stratum(x, y, sample_index, dimension) as f32;
        fract((k + white()) / 256.0 + shift).min(BELOW_ONE)
    };
    let blue = |sample_index: u32, dimension: u32, white: &mut dyn FnMut() -> f32| {
        blue_at((x, y), sample_index, dimension, white)
    };
    let k = count.clamp(1, MAX_SELECTED);
    let (position_dimension, resample_dimension) = (2 * pair, 2 * pair + 1);
    let sample_index = frame & 255;
    // Unknown ids behave as antithetic, as WGSL's default branch does.
    let variant = SamplerVariant::from_id(sampler).unwrap_or(SamplerVariant::Antithetic);
    let stratified = |b: f32| match variant.pattern(k) {
        Pattern::Stratified(pattern) => pattern.positions(b),
        Pattern::Independent => unreachable!("only stratified variants place their slots from one number"),
    };
    match variant {
        SamplerVariant::Random => {
            let positions = [white(), white(), white(), white()];
            SelectionNumbers { positions, resample: white() }
        }
        SamplerVariant::Heitz => {
            let first = k.wrapping_mul(frame);
            let positions = [0, 1, 2, 3].map(|j| blue(first.wrapping_add(j), position_dimension, &mut white));
            SelectionNumbers { positions, resample: blue(first, resample_dimension, &mut white) }
        }
        SamplerVariant::RandomOffset => {
            let b = white();
            SelectionNumbers { positions: stratified(b), resample: white() }
        }
        SamplerVariant::RandomOffsetBlueNoise | SamplerVariant::Antithetic => {
            let b = blue(sample_index, position_dimension, &mut white);
            SelectionNumbers { positions: stratified(b), resample: blue(sample_index, resample_dimension, &mut white) }
        }
        SamplerVariant::QuadAntithetic => {
            let place = ((x & 1) + 2 * (y & 1)).wrapping_add(frame) & 3;
            let quad = blue_at((x / 2, y / 2), sample_index, position_dimension, &mut white);
            let b = fract(quad + place as f32 * 0.25).min(BELOW_ONE);
            SelectionNumbers { positions: stratified(b), resample: blue(sample_index, resample_dimension, &mut white) }
        }
    }
}

/// WGSL `run_member`: index into the sorted list of the member at `position` of the run
/// `span` (not empty).
pub fn run_member(span: ClusterSpan, position: f32) -> u32 {
    let n = span.length;
    span.offset + ((position * n as f32).floor() as u32).min(n - 1)
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
            let k = params.candidates.clamp(1, MAX_SELECTED);
            let numbers = selection_numbers(tables, (x, y), params.frame, params.seed, params.sampler, k, 0);
            let mut result = SelectedCandidates {
                payloads: [NO_PAYLOAD; 4],
                resample_number: numbers.resample,
                ..Default::default()
            };
            let span = spans[pixel];
            if candidates[pixel].object_id != OBJECT_ID_NONE && span.length > 0 {
                result.run_length = span.length;
                result.run_valid = span.valid;
                result.selected = k;
                for (payload, &position) in result.payloads.iter_mut().zip(&numbers.positions).take(k as usize) {
                    let source = sorted_pixels[run_member(span, position) as usize];
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
