//! What a ReSTIR render does, one documented setting per field.

use crate::histogram_pass::PassError;
use strata_kernels::selection::SelectionSettings;

/// How each pixel chooses the K candidates it resamples.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Method {
    /// The paper: the block's candidates clustered by object id and sorted by luminance,
    /// K taken by the sampler variant's pattern (antithetic by default), resampled by
    /// inverse CDF.
    #[default]
    Strata,
    /// Baseline: K uniformly random candidates (with replacement) of the same block
    /// cluster, streaming weighted reservoir sampling.
    Restir,
    /// Baseline: standard ReSTIR, K uniformly random pixels in a disc of
    /// `disc_radius` pixels, rejected unless normal and depth are similar.
    RestirDisc,
}

impl Method {
    /// The name used on the command line and in CSV files.
    pub fn name(self) -> &'static str {
        match self {
            Method::Strata => "strata",
            Method::Restir => "restir",
            Method::RestirDisc => "restir-disc",
        }
    }

    /// Whether the method needs the block histogram.
    pub fn uses_histogram(self) -> bool {
        !matches!(self, Method::RestirDisc)
    }
}

/// Which parts of a pixel's estimate the shading pass writes: a diagnostic that splits
/// the error into what resampling acts on and what it does not.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum ShadedParts {
    /// Everything: the image (default).
    #[default]
    All,
    /// Only what the pixel estimates on its own and no candidate selection touches:
    /// emission at the primary hit, next-event estimation there, and the whole path of
    /// pixels that do not resample. Biased by design (the resampled light is missing);
    /// measure it by its variance over seeds, not against a reference.
    Base,
    /// Only the reservoir's sample, f(Y) V W: the part the selection acts on.
    Resampled,
}

impl ShadedParts {
    /// The bits of `RestirParams.shaded_parts`: 1 the base, 2 the resampled part.
    pub fn bits(self) -> u32 {
        match self {
            ShadedParts::All => 3,
            ShadedParts::Base => 1,
            ShadedParts::Resampled => 2,
        }
    }
}

/// What the shading pass adds for the resampled part of a pixel.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Shading {
    /// The kept sample, f(Y) V W, with one shadow ray (the paper's; the default before
    /// 2026-11-25 and in the measurements made before).
    Sample,
    /// The expectation of the frame's final resampling over its choice, sum_i w_i f(x_i)
    /// / p̂(x_i) over every candidate it chose from (the spatial selection's canonical and
    /// K candidates without temporal reuse; the temporal merge's current and previous
    /// reservoirs with it): unbiased (it is E[f(Y) W | candidates]), never noisier, no
    /// shadow ray (p̂ already includes visibility), and the colours of every candidate
    /// reach the image instead of the one kept (a luminance p̂ cannot resample colour).
    /// The reservoir kept for reuse is unchanged. The default: every method's error is
    /// lower at no cost (BENCHMARKS.md, "Levers").
    #[default]
    Expectation,
}

/// Settings of a ReSTIR render; the defaults are the paper's (§5.1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RestirSettings {
    /// Candidate selection. Default: strata.
    pub method: Method,
    /// The histogram and the selection (§4.1-4.3): block size, K (the candidates every
    /// method resamples per pixel besides its own), object masking, block shifting and
    /// strata's sampler variant. The baselines use K, and restir the histogram; the
    /// sampler variant is strata's alone. Default: the paper's.
    pub selection: SelectionSettings,
    /// Merge each frame's reservoir with the previous frame's (temporal reuse). Off: each
    /// frame stands alone (the accumulation mode of Fig. 5 / 10). Default on.
    pub temporal: bool,
    /// T, previous reservoirs drawn per pixel (0 to 4) and merged besides the pixel's own
    /// reprojected one. 0: standard temporal reuse. 1-4: the paper's Fig. 11, temporal
    /// reservoirs drawn like spatial candidates: strata from a histogram of the block's
    /// reprojected reservoirs at stratified positions (sampler dimensions 2 and 3),
    /// restir uniformly from the same cluster, restir-disc from a disc; each costs 2
    /// shadow rays and lets disoccluded pixels use their neighbours' histories. Default 0.
    pub temporal_candidates: u32,
    /// Cap of the previous reservoir's M before a merge; beyond it the history decays as
    /// an exponential moving average. Higher: more reuse, slower reaction. Default 20.
    pub temporal_cap: f32,
    /// Neighbourhood radius in pixels of `restir-disc`. Default 30.
    pub disc_radius: f32,
    /// A conductor at the primary hit resamples only from this GGX alpha up (smoother ones
    /// path-trace on their own: reconnecting through a near-mirror lobe is noisy). Default
    /// 0.05: glossy surfaces down to alpha 0.05 resample (BENCHMARKS.md, "Glossy primary
    /// hits resample": with temporal reuse every method's error halves on veach-ajar, whose
    /// floor has alpha 0.1, and falls 2–3 % on objects-grid; the previous default 0.2,
    /// ReSTIR PT's rule, left such surfaces to path-trace alone).
    pub min_roughness: f32,
    /// Smooth vertices (dielectrics, conductors below `min_roughness`) a camera path may
    /// pass through to find the vertex it resamples at: a pixel seeing a mirror or glass
    /// resamples at the first rough surface behind it, the chain's throughput weighting
    /// the result (the primary surface replacement of RTXDI-style renderers, unbiased:
    /// `restir/entry_candidates.wgsl` derives it). 0: only a rough primary hit resamples (or,
    /// with `glossy_replay`, a glossy conductor at it)
    /// and every other pixel path-traces alone (the only behaviour until 2026-11-25).
    /// At most 16; the scene's `max_depth` bounds the chain too. Default 4 (a mirror,
    /// a glass object in and out, glass seen in a mirror).
    pub specular_chain: u32,
    /// Random replay at glossy conductors (ReSTIR PT's second shift beside reconnection;
    /// not its hybrid within one path: a path here is reconnected at the vertex after its
    /// resampling vertex or replayed whole). On: a conductor below
    /// `min_roughness` resamples at its own vertex, its candidates being the random numbers
    /// of the rest of its path, which other such pixels re-trace from their own vertex
    /// (`restir/reservoir.wgsl`, "Random replay", derives why this is unbiased); each
    /// candidate a pixel weighs costs one traced path instead of one shadow ray. Off: such
    /// a conductor is a smooth vertex of `specular_chain` (or path-traces alone). Dielectrics
    /// always go through the chain.
    pub glossy_replay: bool,
    /// No reconnection to a vertex closer than this (scene units) to a primary hit
    /// (the geometry term is singular there). Default: 1e-3 of the scene's extent, set by
    /// the renderer when 0.
    pub min_distance: f32,
    /// Which parts of the estimate the frame shows (a diagnostic). Default: all.
    pub shaded_parts: ShadedParts,
    /// The resampled part as the kept sample or as the final resampling's expectation.
    /// Default: the expectation.
    pub shading: Shading,
}

impl Default for RestirSettings {
    fn default() -> Self {
        RestirSettings {
            method: Method::Strata,
            selection: SelectionSettings::default(),
            temporal_candidates: 0,
            temporal: true,
            temporal_cap: 20.0,
            disc_radius: 30.0,
            min_roughness: 0.05,
            specular_chain: 4,
            glossy_replay: false,
            min_distance: 0.0,
            shaded_parts: ShadedParts::All,
            shading: Shading::Expectation,
        }
    }
}

impl RestirSettings {
    /// Refuses settings the kernels cannot run, naming the field and value.
    pub fn check(&self) -> Result<(), PassError> {
        self.selection.validate().map_err(|error| PassError::Input(error.to_string()))?;
        if self.temporal_candidates > 4 {
            return Err(PassError::Input(format!("temporal candidates {}: must be 0 to 4", self.temporal_candidates)));
        }
        if !(self.temporal_cap >= 1.0 && self.temporal_cap.is_finite()) {
            return Err(PassError::Input(format!("temporal cap {}: must be at least 1", self.temporal_cap)));
        }
        if !(self.disc_radius > 0.0 && self.disc_radius.is_finite()) {
            return Err(PassError::Input(format!("disc radius {}: must be positive", self.disc_radius)));
        }
        if !(self.min_distance >= 0.0 && self.min_distance.is_finite()) {
            return Err(PassError::Input(format!(
                "min distance {}: must be 0 (automatic) or a positive length",
                self.min_distance
            )));
        }
        if !(self.min_roughness >= 0.0 && self.min_roughness.is_finite()) {
            return Err(PassError::Input(format!(
                "min roughness {}: must be a GGX alpha of 0 or more",
                self.min_roughness
            )));
        }
        if self.specular_chain > MAX_SPECULAR_CHAIN {
            return Err(PassError::Input(format!(
                "specular chain {}: must be 0 to {MAX_SPECULAR_CHAIN}",
                self.specular_chain
            )));
        }
        Ok(())
    }
}

/// The longest smooth chain [`RestirSettings::specular_chain`] accepts (a path has at most
/// the scene's `max_depth` segments anyway).
pub const MAX_SPECULAR_CHAIN: u32 = 16;
