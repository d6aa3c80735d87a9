//! Where a pixel's K slots fall in its sorted cluster run: the position patterns of the
//! paper's Fig. 3 and Table 2, stated once as data.
//!
//! A stratified pattern places slot j at (offset_j + sign_j · b) / K from one number b
//! in [0, 1); as b sweeps [0, 1) each slot sweeps a stratum of width 1/K, and the K
//! strata tile [0, 1) exactly once ([`StratifiedPattern::strata`]). The antithetic
//! pattern mirrors its slots in pairs, which integrates a linear ramp of sorted values
//! exactly:
//!
//! | K | antithetic positions | as the paper writes it (u = b/4) |
//! |---|---|---|
//! | 4 | {b, 2 − b, 2 + b, 4 − b} / 4 | {u, ½ − u, ½ + u, 1 − u} (Fig. 3) |
//! | 3 | {b, 1 + b, 3 − b} / 3 | one mirrored pair on the outer strata, the middle one offset |
//! | 2 | {b, 2 − b} / 2 | {v, 1 − v} |
//! | 1 | {b} | |
//!
//! The random-offset patterns put slot j at (j + b) / K. The paper defines the
//! antithetic pattern for K = 4 and says it extends to other powers of two; K = 3 is our
//! extension. Taking the first K of the 4-slot pattern instead would be biased: with
//! K = 2 the positions {u, ½ − u} never reach the upper half of a run.
//!
//! The WGSL twin is `stratified_positions` in `kernels/wgsl/strata/selection.wgsl`; the
//! kernels' Rust reference ([`crate::reference::stratified_selection`]) and the 1-D
//! estimator study (the `strata-estimator` crate, `estimator/`) evaluate this table rather than restating it.

crate::gpu::gpu_constants! {
    pub(crate) fn pattern_constants;
    /// Most slots a pixel selects (the kernels keep the per-slot values in `vec4`s:
    /// registers on every target, where local arrays would need array constructors that
    /// glslang's HLSL front end rejects).
    pub const MAX_SELECTED: u32 = 4;
    /// Largest `f32` below 1: positions are clamped to it so that they stay in [0, 1)
    /// after rounding.
    pub const BELOW_ONE: f32 = 0.999_999_94;
}

/// How a sampler variant draws the positions of a pixel's K slots in one frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Pattern {
    /// Each slot's position is its own uniform number (`random`: white noise; `heitz`: K
    /// consecutive samples of the pixel's blue-noise sequence).
    Independent,
    /// All slots from one number b (the random offsets and antithetic).
    Stratified(StratifiedPattern),
}

/// A stratified pattern of `count` slots: slot j at (offsets\[j\] + signs\[j\] · b) / count.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StratifiedPattern {
    /// K, slots used (1 to 4); entries from K on are unused.
    pub count: u32,
    /// offset_j per slot, a whole number.
    pub offsets: [f32; 4],
    /// sign_j per slot, +1 or −1 (0 in unused slots).
    pub signs: [f32; 4],
}

impl StratifiedPattern {
    /// The antithetic pattern of `count` slots (clamped to 1..=4), as in the table above.
    pub fn antithetic(count: u32) -> Self {
        let count = count.clamp(1, MAX_SELECTED);
        let (offsets, signs) = match count {
            4 => ([0.0, 2.0, 2.0, 4.0], [1.0, -1.0, 1.0, -1.0]),
            3 => ([0.0, 1.0, 3.0, 0.0], [1.0, 1.0, -1.0, 0.0]),
            2 => ([0.0, 2.0, 0.0, 0.0], [1.0, -1.0, 0.0, 0.0]),
            _ => ([0.0; 4], [1.0, 0.0, 0.0, 0.0]),
        };
        Self { count, offsets, signs }
    }

    /// The random-offset pattern of `count` slots (clamped to 1..=4): slot j at (j + b) / K.
    pub fn random_offset(count: u32) -> Self {
        Self { count: count.clamp(1, MAX_SELECTED), offsets: [0.0, 1.0, 2.0, 3.0], signs: [1.0; 4] }
    }

    /// The positions for b in [0, 1), computed with the kernels' `f32` operations in
    /// their order, clamped below 1 (slots from `count` on are meaningless).
    pub fn positions(&self, b: f32) -> [f32; 4] {
        let k = self.count as f32;
        std::array::from_fn(|j| ((self.offsets[j] + self.signs[j] * b) / k).min(BELOW_ONE))
    }

    /// The position of slot `slot` for b in [0, 1), in `f64` (for exact studies).
    pub fn position(&self, slot: usize, b: f64) -> f64 {
        (f64::from(self.offsets[slot]) + f64::from(self.signs[slot]) * b) / f64::from(self.count)
    }

    /// The interval each used slot sweeps as b sweeps [0, 1): (low, high), of width 1/K.
    pub fn strata(&self) -> Vec<(f64, f64)> {
        (0..self.count as usize)
            .map(|j| {
                let (a, b) = (self.position(j, 0.0), self.position(j, 1.0));
                (a.min(b), a.max(b))
            })
            .collect()
    }
}

/// Index into a pool of `n` (> 0) of position `position` in [0, 1]: ⌊position · n⌋
/// clamped to n − 1 (WGSL `run_member` without the run's offset).
pub fn index_of(position: f64, n: usize) -> usize {
    ((position * n as f64) as usize).min(n - 1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::selection::SamplerVariant;

    const STRATIFIED: [SamplerVariant; 4] = [
        SamplerVariant::RandomOffset,
        SamplerVariant::RandomOffsetBlueNoise,
        SamplerVariant::Antithetic,
        SamplerVariant::QuadAntithetic,
    ];

    /// What makes the selection unbiased: the strata of every stratified pattern tile
    /// [0, 1) exactly once, so the K positions together have density K on [0, 1).
    #[test]
    fn every_stratified_pattern_tiles_the_unit_interval_once() {
        for sampler in STRATIFIED {
            for count in 1..=MAX_SELECTED {
                let Pattern::Stratified(p) = sampler.pattern(count) else { panic!("{sampler:?} is stratified") };
                let mut strata = p.strata();
                strata.sort_by(|a, b| a.0.total_cmp(&b.0));
                let mut edge = 0.0;
                for (low, high) in strata {
                    assert_eq!(low, edge, "{sampler:?} K = {count}: a gap or an overlap at {edge}");
                    assert!((high - low - 1.0 / f64::from(count)).abs() < 1e-15);
                    edge = high;
                }
                assert!((edge - 1.0).abs() < 1e-15, "{sampler:?} K = {count}: ends at {edge}");
            }
        }
    }

    /// The check above catches the bias of taking the first K slots of the 4-slot
    /// antithetic pattern.
    #[test]
    fn the_first_slots_of_the_four_slot_pattern_do_not_tile() {
        let four = StratifiedPattern::antithetic(4);
        let mut first_two = four.strata()[..2].to_vec();
        first_two.sort_by(|a, b| a.0.total_cmp(&b.0));
        // {u, 1/2 - u}: [0, 1/4) and (1/4, 1/2], the upper half never reached.
        assert_eq!(first_two.last().unwrap().1, 0.5);
    }

    /// The 4-slot antithetic positions are the paper's Fig. 3, bit for bit in `f32`.
    #[test]
    fn four_antithetic_slots_are_fig_3() {
        for b in [0.0f32, 1e-7, 0.3, 0.5, 0.999_999_94] {
            let u = b * 0.25;
            let want = [u, 0.5 - u, 0.5 + u, 1.0 - u].map(|p| p.min(BELOW_ONE));
            assert_eq!(StratifiedPattern::antithetic(4).positions(b), want, "b = {b}");
        }
    }

    #[test]
    fn positions_stay_below_one() {
        for sampler in STRATIFIED {
            for count in 1..=MAX_SELECTED {
                let Pattern::Stratified(p) = sampler.pattern(count) else { unreachable!() };
                for b in [0.0, 1e-9, 0.5, BELOW_ONE] {
                    for &position in &p.positions(b)[..count as usize] {
                        assert!((0.0..1.0).contains(&position), "{sampler:?} K = {count} b = {b}: {position}");
                    }
                }
            }
        }
    }
}
