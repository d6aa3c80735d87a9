//! The denoiser's settings, one documented field each; the defaults are the paper's
//! (Schied et al. 2017, §4 and §5).

use crate::histogram_pass::PassError;
use strata_kernels::denoise_types::{DenoiseParams, PAPER_LEVELS};

/// Which denoiser filters the frames (`strata compare --denoise`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[derive(serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Denoiser {
    /// Spatiotemporal variance-guided filtering (Schied et al. 2017) with
    /// [`SvgfSettings::default`]: temporal accumulation through the motion vectors, a
    /// variance estimate, five levels of an edge-avoiding à-trous wavelet filter.
    Svgf,
    /// SVGF whose spatial filters also stop at object boundaries (the guide's object id),
    /// as its temporal pass does: not in the paper; around lights it removes most of the
    /// paper's filter's error (BENCHMARKS.md).
    SvgfObjects,
}

impl Denoiser {
    /// The name used on the command line and in file names.
    pub fn name(self) -> &'static str {
        match self {
            Denoiser::Svgf => "svgf",
            Denoiser::SvgfObjects => "svgf-objects",
        }
    }

    /// Its settings.
    pub fn settings(self) -> SvgfSettings {
        match self {
            Denoiser::Svgf => SvgfSettings::default(),
            Denoiser::SvgfObjects => SvgfSettings { object_edges: true, ..SvgfSettings::default() },
        }
    }
}

/// SVGF's settings.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct SvgfSettings {
    /// Levels of the à-trous filter, their taps 1, 2, 4, ... pixels apart (SVGF: 5, a
    /// footprint of 2^levels * 2 + 1 = 65 pixels), 1 to 10.
    pub levels: u32,
    /// Weight of the new frame in the colour's moving average (SVGF: 0.2), in (0, 1].
    pub alpha_colour: f32,
    /// Weight of the new frame in the luminance moments' moving average (SVGF: 0.2), in
    /// (0, 1].
    pub alpha_moments: f32,
    /// σ_l: how many standard deviations of luminance apart two pixels may be before
    /// the filter stops mixing them (SVGF: 4); finite and positive.
    pub sigma_luminance: f32,
    /// σ_z: how many times the depth change its local slope predicts two pixels may
    /// differ by before the filter stops mixing them (SVGF: 1); finite and positive.
    pub sigma_depth: f32,
    /// The normal weight is cos^(2^normal_power_log2) of the angle between normals
    /// (SVGF: σ_n = 128, i.e. 7); 0 to 10.
    pub normal_power_log2: u32,
    /// History lengths stop growing here (frames), 1 or more: after that the moving
    /// averages weigh the new frame `alpha_*`.
    pub max_history: f32,
    /// Reprojection: a previous pixel continues this one's history if it saw the same
    /// object at a depth within this fraction (0.1, the renderer's own temporal test;
    /// SVGF's implementation scales its depth test by screen-space derivatives), in
    /// (0, 1]...
    pub depth_tolerance: f32,
    /// ...and its normal is within this cosine (0.906: 25 degrees), in [-1, 1].
    pub normal_tolerance: f32,
    /// The spatial filters (variance estimate, à-trous) also give weight 0 between
    /// pixels of different objects (not in SVGF, which stops at depth, normal and
    /// luminance edges only; default off, as in the paper).
    pub object_edges: bool,
}

impl Default for SvgfSettings {
    /// The paper's settings ([`DenoiseParams::paper`]).
    fn default() -> Self {
        let paper = DenoiseParams::paper(0, 0);
        SvgfSettings {
            levels: PAPER_LEVELS,
            alpha_colour: paper.alpha_colour,
            alpha_moments: paper.alpha_moments,
            sigma_luminance: paper.sigma_luminance,
            sigma_depth: paper.sigma_depth,
            normal_power_log2: paper.normal_power_log2,
            max_history: paper.max_history,
            depth_tolerance: paper.depth_tolerance,
            normal_tolerance: paper.normal_tolerance,
            object_edges: paper.object_edges != 0,
        }
    }
}

impl SvgfSettings {
    /// Every field within its documented range; the error names the field and value.
    pub fn check(&self) -> Result<(), PassError> {
        let fail = |field: &str, value: String, rule: &str| {
            Err(PassError::Input(format!("SVGF setting {field} = {value}: must be {rule}")))
        };
        if !(1..=10).contains(&self.levels) {
            return fail("levels", self.levels.to_string(), "1 to 10");
        }
        for (field, value) in [("alpha_colour", self.alpha_colour), ("alpha_moments", self.alpha_moments)] {
            if !(value > 0.0 && value <= 1.0) {
                return fail(field, value.to_string(), "in (0, 1]");
            }
        }
        for (field, value) in [("sigma_luminance", self.sigma_luminance), ("sigma_depth", self.sigma_depth)] {
            if !(value.is_finite() && value > 0.0) {
                return fail(field, value.to_string(), "finite and positive");
            }
        }
        if self.normal_power_log2 > 10 {
            return fail("normal_power_log2", self.normal_power_log2.to_string(), "0 to 10");
        }
        if !(self.max_history.is_finite() && self.max_history >= 1.0) {
            return fail("max_history", self.max_history.to_string(), "finite and 1 or more");
        }
        if !(self.depth_tolerance > 0.0 && self.depth_tolerance <= 1.0) {
            return fail("depth_tolerance", self.depth_tolerance.to_string(), "in (0, 1]");
        }
        if !(-1.0..=1.0).contains(&self.normal_tolerance) {
            return fail("normal_tolerance", self.normal_tolerance.to_string(), "in [-1, 1]");
        }
        Ok(())
    }

    /// The kernels' uniform for an image of `width` x `height` at à-trous `level`, with
    /// or without history.
    pub fn params(&self, width: u32, height: u32, level: u32, history: bool) -> DenoiseParams {
        DenoiseParams {
            width,
            height,
            history: u32::from(history),
            step: 1 << level,
            alpha_colour: self.alpha_colour,
            alpha_moments: self.alpha_moments,
            sigma_luminance: self.sigma_luminance,
            sigma_depth: self.sigma_depth,
            normal_power_log2: self.normal_power_log2,
            max_history: self.max_history,
            depth_tolerance: self.depth_tolerance,
            normal_tolerance: self.normal_tolerance,
            object_edges: u32::from(self.object_edges),
            _pad0: 0,
            _pad1: 0,
            _pad2: 0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::SvgfSettings;

    #[test]
    fn the_defaults_pass_and_each_bad_value_is_named() {
        SvgfSettings::default().check().unwrap();
        let bad = [
            SvgfSettings { levels: 0, ..Default::default() },
            SvgfSettings { alpha_colour: 0.0, ..Default::default() },
            SvgfSettings { alpha_moments: f32::NAN, ..Default::default() },
            SvgfSettings { sigma_luminance: f32::INFINITY, ..Default::default() },
            SvgfSettings { sigma_depth: -1.0, ..Default::default() },
            SvgfSettings { normal_power_log2: 11, ..Default::default() },
            SvgfSettings { max_history: 0.5, ..Default::default() },
            SvgfSettings { depth_tolerance: 0.0, ..Default::default() },
            SvgfSettings { normal_tolerance: 2.0, ..Default::default() },
        ];
        let fields = [
            "levels",
            "alpha_colour",
            "alpha_moments",
            "sigma_luminance",
            "sigma_depth",
            "normal_power_log2",
            "max_history",
            "depth_tolerance",
            "normal_tolerance",
        ];
        for (settings, field) in bad.iter().zip(fields) {
            let message = settings.check().unwrap_err().to_string();
            assert!(message.contains(field), "{message}");
        }
    }
}
