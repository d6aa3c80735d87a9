//! [`SamplerVariant`]: where the selection's numbers come from, the variants of the
//! paper's Table 2 (ablation of histogram sampling strategies).

use super::patterns::{Pattern, StratifiedPattern};

/// How the selection draws its random numbers and places its K slots (Table 2). "Temporal
/// blue noise" means one sample of Heitz et al. 2019's sampler
/// ([`crate::blue_noise::BlueNoiseTables`]) per pixel and frame, sample index frame mod
/// 256: dimension 0 places the spatial slots and dimension 1 drives the resampling (2 and
/// 3 for the temporal slots of Fig. 11). Every variant is unbiased for every K: each
/// position is uniform on [0, 1) over independent renders.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[cfg_attr(feature = "serde", derive(serde::Serialize), serde(rename_all = "kebab-case"))]
pub enum SamplerVariant {
    /// Uncorrelated slots (Table 2's "ReSTIR"): K independent white-noise positions per
    /// pixel and frame, and a white-noise resampling number; no stratification within or
    /// across frames.
    Random,
    /// Heitz et al. 2019 with K samples per frame: slot j takes its position from
    /// dimension 0 at sample index (K·frame + j) mod 256, K consecutive points of the
    /// pixel's sequence; resampling from dimension 1 at sample index K·frame.
    Heitz,
    /// Random-offset stratification with white noise: one number b per pixel and frame,
    /// slot j at (j + b) / K. Stratified within a frame, uncorrelated across frames.
    RandomOffset,
    /// Random offset + temporal blue noise: slot j at (j + b) / K with b from the
    /// blue-noise sampler; resampling from its second dimension.
    RandomOffsetBlueNoise,
    /// Antithetic + temporal blue noise (the paper's method, the default): b from the
    /// blue-noise sampler, mirrored slots (Fig. 3; K = 4: {u, ½ − u, ½ + u, 1 − u} with
    /// u = b/4; see [`super::patterns`] for K < 4); resampling from its second dimension.
    #[default]
    Antithetic,
    /// Antithetic + temporal blue noise with complementary strata across each 2 × 2 quad
    /// of pixels (issue 55's lever against correlated error; not in the paper): the quad
    /// shares one blue-noise value b_q (the blue noise of the quad's position) and its
    /// pixels take b = b_q + q/4 mod 1, q the pixel's place in the quad turned by one every
    /// frame. Within each stratum of the antithetic pattern the four pixels then sit a
    /// quarter of the stratum apart, so neighbours take different members of a sorted run
    /// (one darker, one brighter) and their errors can cancel under a spatial filter. Each
    /// b is still uniform over renders (a shift mod 1 of a uniform number), so the
    /// selection stays unbiased; resampling from the pixel's own second dimension.
    QuadAntithetic,
}

impl SamplerVariant {
    /// Every variant, in Table 2's order.
    pub const ALL: [SamplerVariant; 6] = [
        SamplerVariant::Random,
        SamplerVariant::Heitz,
        SamplerVariant::RandomOffset,
        SamplerVariant::RandomOffsetBlueNoise,
        SamplerVariant::Antithetic,
        SamplerVariant::QuadAntithetic,
    ];

    /// The WGSL `SAMPLER_*` constant of the variant (`kernels/wgsl/strata/selection.wgsl`).
    pub fn id(self) -> u32 {
        match self {
            SamplerVariant::Random => SAMPLER_RANDOM,
            SamplerVariant::Heitz => SAMPLER_HEITZ,
            SamplerVariant::RandomOffset => SAMPLER_RANDOM_OFFSET,
            SamplerVariant::RandomOffsetBlueNoise => SAMPLER_RANDOM_OFFSET_BLUE_NOISE,
            SamplerVariant::Antithetic => SAMPLER_ANTITHETIC,
            SamplerVariant::QuadAntithetic => SAMPLER_QUAD_ANTITHETIC,
        }
    }

    /// The variant's name, as the command line's `--sampler` and the export's
    /// `manifest.json` spell it.
    pub fn name(self) -> &'static str {
        match self {
            SamplerVariant::Random => "random",
            SamplerVariant::Heitz => "heitz",
            SamplerVariant::RandomOffset => "random-offset",
            SamplerVariant::RandomOffsetBlueNoise => "random-offset-blue-noise",
            SamplerVariant::Antithetic => "antithetic",
            SamplerVariant::QuadAntithetic => "quad-antithetic",
        }
    }

    /// The variant whose [`Self::id`] is `id`, if any.
    pub fn from_id(id: u32) -> Option<Self> {
        Self::ALL.into_iter().find(|variant| variant.id() == id)
    }

    /// The position pattern of `count` slots (the table of [`super::patterns`]).
    pub fn pattern(self, count: u32) -> Pattern {
        match self {
            SamplerVariant::Random | SamplerVariant::Heitz => Pattern::Independent,
            SamplerVariant::RandomOffset | SamplerVariant::RandomOffsetBlueNoise => {
                Pattern::Stratified(StratifiedPattern::random_offset(count))
            }
            SamplerVariant::Antithetic | SamplerVariant::QuadAntithetic => {
                Pattern::Stratified(StratifiedPattern::antithetic(count))
            }
        }
    }
}

crate::gpu::gpu_constants! {
    pub(crate) fn sampler_constants;
    /// Sampler variant id of `SamplerVariant::Random` (`SelectionParams.sampler`).
    pub const SAMPLER_RANDOM: u32 = 0;
    /// Sampler variant id of `SamplerVariant::Heitz`.
    pub const SAMPLER_HEITZ: u32 = 1;
    /// Sampler variant id of `SamplerVariant::RandomOffset`.
    pub const SAMPLER_RANDOM_OFFSET: u32 = 2;
    /// Sampler variant id of `SamplerVariant::RandomOffsetBlueNoise`.
    pub const SAMPLER_RANDOM_OFFSET_BLUE_NOISE: u32 = 3;
    /// Sampler variant id of `SamplerVariant::Antithetic`.
    pub const SAMPLER_ANTITHETIC: u32 = 4;
    /// Sampler variant id of `SamplerVariant::QuadAntithetic`.
    pub const SAMPLER_QUAD_ANTITHETIC: u32 = 5;
}

#[cfg(all(test, feature = "clap"))]
mod tests {
    use super::*;

    /// The names are the command line's.
    #[test]
    fn names_are_the_command_lines() {
        for variant in SamplerVariant::ALL {
            let clap_name = clap::ValueEnum::to_possible_value(&variant).unwrap().get_name().to_string();
            assert_eq!(variant.name(), clap_name);
        }
    }

    /// The run record's names are the command line's.
    #[cfg(feature = "serde")]
    #[test]
    fn record_names_are_the_command_lines() {
        for variant in SamplerVariant::ALL {
            let record = serde_json::to_value(variant).unwrap();
            assert_eq!(record, serde_json::Value::from(variant.name()));
        }
    }
}
