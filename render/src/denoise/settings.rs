//! The denoiser's settings, one documented field each; the defaults are the paper's
//! (Schied et al. 2017, §4 and §5).

use crate::histogram_pass::PassError;
use strata_kernels::denoise_types::{DenoiseParams, PAPER_LEVELS, SvgfFilter};

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
    /// `svgf-objects` whose à-trous variance propagation assumes the noise of the pixels
    /// it averages correlated with ρ = 0.15 ([`SvgfFilter::error_correlation`]), the lag-1
    /// correlation of ReSTIR's error the viewer metrics measure: SVGF's own formula
    /// assumes independent noise, which reuse breaks (issue 55's lever; not in the paper).
    SvgfCorrelated,
    /// Intel Open Image Denoise's `RT` filter (the neural denoiser of Blender/Cycles) on
    /// the CPU, with the guides' albedo and normal: spatial only, each frame filtered on
    /// its own with no history. Its library is opened at run time (`pip install
    /// pyoidn==2.5.1.0`, or set STRATA_OIDN_LIBRARY to libOpenImageDenoise.so.2).
    Oidn,
}

impl Denoiser {
    /// The name used on the command line and in file names.
    pub fn name(self) -> &'static str {
        match self {
            Denoiser::Svgf => "svgf",
            Denoiser::SvgfObjects => "svgf-objects",
            Denoiser::SvgfCorrelated => "svgf-correlated",
            Denoiser::Oidn => "oidn",
        }
    }

    /// The filter's name in headings: `SVGF` (either configuration) or `OIDN`.
    pub fn title(self) -> &'static str {
        match self {
            Denoiser::Svgf | Denoiser::SvgfObjects | Denoiser::SvgfCorrelated => "SVGF",
            Denoiser::Oidn => "OIDN",
        }
    }

    /// Its SVGF settings; `None` for OIDN, which is not SVGF and takes none.
    pub fn svgf_settings(self) -> Option<SvgfSettings> {
        match self {
            Denoiser::Svgf => Some(SvgfSettings::default()),
            Denoiser::SvgfObjects => Some(SvgfSettings::default().with_object_edges(true)),
            Denoiser::SvgfCorrelated => {
                let objects = SvgfSettings::default().with_object_edges(true);
                Some(SvgfSettings { filter: SvgfFilter { error_correlation: 0.15, ..objects.filter }, ..objects })
            }
            Denoiser::Oidn => None,
        }
    }
}

/// SVGF's settings: the levels of its à-trous filter, and the filter's settings as the
/// kernels read them ([`SvgfFilter`], each field declared there once).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SvgfSettings {
    /// Levels of the à-trous filter, their taps 1, 2, 4, ... pixels apart (SVGF: 5, a
    /// footprint of 2^levels * 2 + 1 = 65 pixels), 1 to 10.
    pub levels: u32,
    /// The filter's settings, copied into every pass's uniform as they are.
    pub filter: SvgfFilter,
}

impl Default for SvgfSettings {
    /// The paper's settings ([`SvgfFilter::paper`], [`PAPER_LEVELS`]).
    fn default() -> Self {
        SvgfSettings { levels: PAPER_LEVELS, filter: SvgfFilter::paper() }
    }
}

impl SvgfSettings {
    /// These settings with the spatial filters also stopping at object boundaries
    /// ([`SvgfFilter::object_edges`]) or not.
    pub fn with_object_edges(self, object_edges: bool) -> SvgfSettings {
        SvgfSettings { filter: SvgfFilter { object_edges: u32::from(object_edges), ..self.filter }, ..self }
    }

    /// Every field within its documented range; the error names the field and value.
    pub fn check(&self) -> Result<(), PassError> {
        let fail = |field: &str, value: String, rule: &str| {
            Err(PassError::Input(format!("SVGF setting {field} = {value}: must be {rule}")))
        };
        let filter = &self.filter;
        if !(1..=10).contains(&self.levels) {
            return fail("levels", self.levels.to_string(), "1 to 10");
        }
        for (field, value) in [("alpha_colour", filter.alpha_colour), ("alpha_moments", filter.alpha_moments)] {
            if !(value > 0.0 && value <= 1.0) {
                return fail(field, value.to_string(), "in (0, 1]");
            }
        }
        for (field, value) in [("sigma_luminance", filter.sigma_luminance), ("sigma_depth", filter.sigma_depth)] {
            if !(value.is_finite() && value > 0.0) {
                return fail(field, value.to_string(), "finite and positive");
            }
        }
        if filter.normal_power_log2 > 10 {
            return fail("normal_power_log2", filter.normal_power_log2.to_string(), "0 to 10");
        }
        if !(filter.max_history.is_finite() && filter.max_history >= 1.0) {
            return fail("max_history", filter.max_history.to_string(), "finite and 1 or more");
        }
        if !(filter.depth_tolerance > 0.0 && filter.depth_tolerance <= 1.0) {
            return fail("depth_tolerance", filter.depth_tolerance.to_string(), "in (0, 1]");
        }
        if !(-1.0..=1.0).contains(&filter.normal_tolerance) {
            return fail("normal_tolerance", filter.normal_tolerance.to_string(), "in [-1, 1]");
        }
        if filter.object_edges > 1 {
            return fail("object_edges", filter.object_edges.to_string(), "0 or 1");
        }
        if !(0.0..1.0).contains(&filter.error_correlation) {
            return fail("error_correlation", filter.error_correlation.to_string(), "in [0, 1)");
        }
        Ok(())
    }

    /// The kernels' uniform for an image of `width` x `height` at à-trous `level`, with
    /// or without history: the one mapping from the settings to the uniform.
    pub fn params(&self, width: u32, height: u32, level: u32, history: bool) -> DenoiseParams {
        DenoiseParams { width, height, history: u32::from(history), step: 1 << level, svgf: self.filter }
    }
}

#[cfg(test)]
mod tests {
    use super::SvgfSettings;
    use strata_kernels::denoise_types::SvgfFilter;

    #[test]
    fn the_defaults_pass_and_each_bad_value_is_named() {
        SvgfSettings::default().check().unwrap();
        let paper = SvgfFilter::paper();
        let filter = |filter: SvgfFilter| SvgfSettings { filter, ..Default::default() };
        let bad = [
            SvgfSettings { levels: 0, ..Default::default() },
            filter(SvgfFilter { alpha_colour: 0.0, ..paper }),
            filter(SvgfFilter { alpha_moments: f32::NAN, ..paper }),
            filter(SvgfFilter { sigma_luminance: f32::INFINITY, ..paper }),
            filter(SvgfFilter { sigma_depth: -1.0, ..paper }),
            filter(SvgfFilter { normal_power_log2: 11, ..paper }),
            filter(SvgfFilter { max_history: 0.5, ..paper }),
            filter(SvgfFilter { depth_tolerance: 0.0, ..paper }),
            filter(SvgfFilter { normal_tolerance: 2.0, ..paper }),
            filter(SvgfFilter { object_edges: 2, ..paper }),
            filter(SvgfFilter { error_correlation: 1.0, ..paper }),
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
            "object_edges",
            "error_correlation",
        ];
        for (settings, field) in bad.iter().zip(fields) {
            let message = settings.check().unwrap_err().to_string();
            assert!(message.contains(field), "{message}");
        }
    }

    /// The uniform is the settings' filter as it is, with the frame's and the level's
    /// numbers.
    #[test]
    fn the_uniform_carries_the_filter_unchanged() {
        let settings = SvgfSettings::default().with_object_edges(true);
        let params = settings.params(640, 480, 3, true);
        assert_eq!((params.width, params.height, params.step, params.history), (640, 480, 8, 1));
        assert_eq!(params.svgf, settings.filter);
        assert_eq!(params.svgf.object_edges, 1);
    }
}
