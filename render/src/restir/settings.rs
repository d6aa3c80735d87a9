//! What a ReSTIR render does, one documented setting per field.

use crate::histogram_pass::PassError;
use strata_kernels::restir_types::{
    METHOD_RESTIR, METHOD_RESTIR_DISC, METHOD_STRATA, RestirParams, SHADING_EXPECTATION, SHADING_SAMPLE,
};
use strata_kernels::selection::SelectionSettings;

/// How each pixel chooses the K candidates it resamples.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[derive(serde::Serialize)]
#[serde(rename_all = "kebab-case")]
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
    /// Baseline: plain per-pixel RIS, no reuse. Each pixel keeps its own canonical
    /// candidate (the same initial candidates as every method: RIS over light and BSDF
    /// samples, `restir/entry_candidates.wgsl`) and shades it, with no spatial or
    /// temporal reuse and no histogram: what Bevy Solari ships by default since its v8
    /// (bevyengine/bevy#25513), which turned ReSTIR off for the correlations and boiling
    /// that confuse its denoiser. K, the temporal settings and the order of reuse do not
    /// apply ([`RestirSettings::as_run`]).
    Ris,
}

impl Method {
    /// The baselines strata is compared with, in the order tables list them.
    pub const BASELINES: [Method; 3] = [Method::Restir, Method::RestirDisc, Method::Ris];

    /// The name used on the command line and in CSV files.
    pub fn name(self) -> &'static str {
        match self {
            Method::Strata => "strata",
            Method::Restir => "restir",
            Method::RestirDisc => "restir-disc",
            Method::Ris => "ris",
        }
    }

    /// Whether the method needs the block histogram.
    pub fn uses_histogram(self) -> bool {
        matches!(self, Method::Strata | Method::Restir)
    }

    /// Whether the method reuses other pixels' or frames' samples (every method but
    /// [`Method::Ris`]).
    pub fn reuses(self) -> bool {
        self != Method::Ris
    }
}

/// Which parts of a pixel's estimate the shading pass writes: a diagnostic that splits
/// the error into what resampling acts on and what it does not.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[derive(serde::Serialize)]
#[serde(rename_all = "kebab-case")]
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
#[derive(serde::Serialize)]
#[serde(rename_all = "kebab-case")]
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

/// In which order a frame reuses its neighbours' and its history's samples.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[derive(serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ReuseOrder {
    /// By the camera, the default since 2026-11-29: `temporal-first` while the camera
    /// stands still, `spatial-first` when it moves. Measured (BENCHMARKS.md, "What the
    /// viewer sees"): still, temporal-first lowers every method's error over frames 1-32
    /// to 0.75-0.90 of the paper's order's; under an orbit spatial-first gives the same raw
    /// RelMSE, 1 % less after SVGF, 8-11 % lower FLIP raw and after SVGF, and half the
    /// correlated error after SVGF. A renderer not told whether its camera moves runs
    /// `temporal-first` (`RestirRenderer::new`).
    #[default]
    Auto,
    /// The paper's (§5.1), and the default before 2026-11-27: the spatial selection on
    /// this frame's candidates, then the temporal merge of its result with the history.
    /// The stratification acts on the current frame's candidates only, whose share of
    /// each merge fades as the history grows.
    SpatialFirst,
    /// The standard ReSTIR order (Bitterli et al. 2020), the default for a still camera:
    /// each pixel's candidate merges with its history first, then the histogram sorts the
    /// merged reservoirs by their estimates p̂ W and the spatial selection reuses K of them
    /// (pairwise MIS with confidence weights: `restir/entry_spatial.wgsl`); the spatial
    /// result is the history of the next frame. Two more passes per frame, about 2 %
    /// more time, and every method's error lower over frames 1-32 (BENCHMARKS.md, "The
    /// temporal lever").
    TemporalFirst,
}

impl ReuseOrder {
    /// The name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            ReuseOrder::Auto => "auto",
            ReuseOrder::SpatialFirst => "spatial-first",
            ReuseOrder::TemporalFirst => "temporal-first",
        }
    }

    /// The order a render runs: [`ReuseOrder::Auto`] resolved by whether the camera
    /// moves (spatial-first) or stands still (temporal-first); the others as they are.
    pub fn for_camera(self, moving: bool) -> ReuseOrder {
        match self {
            ReuseOrder::Auto if moving => ReuseOrder::SpatialFirst,
            ReuseOrder::Auto => ReuseOrder::TemporalFirst,
            order => order,
        }
    }
}

/// Settings of a ReSTIR render; the defaults are the paper's (§5.1) but for the order of
/// reuse ([`ReuseOrder`]) and what BENCHMARKS.md's "Levers" measured.
///
/// The one declaration of each setting: the field docs are the command line's `--help`
/// (`strata compare` flattens this struct; with the `clap` feature), the field names
/// the run record's keys (serde), [`RestirSettings::check`] their one validation and
/// [`RestirSettings::uniform`] what the kernels read of them.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct RestirSettings {
    /// Candidate selection. Default: strata. (Not a flag: `strata compare` runs the
    /// methods it is given side by side.)
    #[cfg_attr(feature = "clap", arg(skip))]
    #[serde(skip)]
    pub method: Method,
    /// The histogram and the selection (§4.1-4.3): block size, K (the candidates every
    /// method resamples per pixel besides its own), object masking, block shifting and
    /// strata's sampler variant. The baselines use K, and restir the histogram; the
    /// sampler variant is strata's alone. Default: the paper's.
    #[cfg_attr(feature = "clap", command(flatten))]
    #[serde(flatten)]
    pub selection: SelectionSettings,
    /// Temporal reuse, on unless --accumulate: each frame's reservoir merges with the
    /// previous frame's. Off, each frame stands alone and frames are accumulated instead
    /// (Fig. 5 / 10).
    #[cfg_attr(feature = "clap", arg(long = "accumulate", action = clap::ArgAction::SetFalse))]
    pub temporal: bool,
    /// Previous reservoirs drawn per pixel like spatial candidates (the paper's Fig. 11),
    /// 0 to 4, merged besides the pixel's own reprojected one.
    ///
    /// 0: standard temporal reuse. 1-4: strata draws them from a histogram of the
    /// block's reprojected reservoirs at stratified positions (sampler dimensions 2 and
    /// 3), restir uniformly from the same cluster, restir-disc from a disc; each costs 2
    /// shadow rays and lets disoccluded pixels use their neighbours' histories.
    #[cfg_attr(feature = "clap", arg(long, default_value_t = RestirSettings::default().temporal_candidates))]
    pub temporal_candidates: u32,
    /// Cap of the previous reservoir's M before a temporal merge (the paper's 20): lower
    /// reacts faster and lets a rare bright sample fade sooner, higher reuses more.
    ///
    /// Beyond the cap the history decays as an exponential moving average.
    #[cfg_attr(feature = "clap", arg(long, default_value_t = RestirSettings::default().temporal_cap))]
    pub temporal_cap: f32,
    /// Neighbourhood radius in pixels of `restir-disc`'s candidates.
    #[cfg_attr(feature = "clap", arg(long, default_value_t = RestirSettings::default().disc_radius))]
    pub disc_radius: f32,
    /// A conductor at the primary hit resamples only from this GGX alpha up; smoother
    /// ones are smooth vertices (see --specular-chain).
    ///
    /// Reconnecting through a near-mirror lobe is noisy. 0.05 lets glossy surfaces down
    /// to alpha 0.05 resample (BENCHMARKS.md, "Glossy primary hits resample": with
    /// temporal reuse every method's error halves on veach-ajar, whose floor has alpha
    /// 0.1, and falls 2-3 % on objects-grid; the previous default 0.2, ReSTIR PT's rule,
    /// left such surfaces to path-trace alone).
    #[cfg_attr(feature = "clap", arg(long, default_value_t = RestirSettings::default().min_roughness))]
    pub min_roughness: f32,
    /// Smooth vertices (glass, conductors below --min-roughness) a pixel's path may pass
    /// through to the rough vertex it resamples at, for every method alike; 0: pixels
    /// whose primary hit is smooth path-trace on their own (1 sample per frame, no reuse).
    ///
    /// A pixel seeing a mirror or glass resamples at the first rough surface behind it,
    /// the chain's throughput weighting the result (the primary surface replacement of
    /// RTXDI-style renderers, unbiased: `restir/entry_candidates.wgsl` derives it). At
    /// most 16; the scene's `max_depth` bounds the chain too. The default 4 covers a
    /// mirror, a glass object in and out, glass seen in a mirror.
    #[cfg_attr(feature = "clap", arg(long, default_value_t = RestirSettings::default().specular_chain))]
    pub specular_chain: u32,
    /// `true`: a conductor below --min-roughness resamples at its own vertex by random
    /// replay (its candidates are the random numbers of the rest of its path, re-traced
    /// by the pixels that reuse them), for every method alike; `false`: it is a smooth
    /// vertex of --specular-chain.
    ///
    /// ReSTIR PT's second shift beside reconnection (not its hybrid within one path: a
    /// path here is reconnected at the vertex after its resampling vertex or replayed
    /// whole; `restir/reservoir.wgsl`, "Random replay", derives why this is unbiased).
    /// Each candidate a pixel weighs costs one traced path instead of one shadow ray.
    /// Dielectrics always go through the chain.
    #[cfg_attr(
        feature = "clap",
        arg(long, default_value_t = RestirSettings::default().glossy_replay, action = clap::ArgAction::Set)
    )]
    pub glossy_replay: bool,
    /// No reconnection to a vertex closer than this (scene units) to a primary hit;
    /// 0: 1e-3 of the scene's extent.
    ///
    /// The geometry term is singular there.
    #[cfg_attr(feature = "clap", arg(long, default_value_t = RestirSettings::default().min_distance))]
    pub min_distance: f32,
    /// Which parts of each pixel's estimate the frames show (a diagnostic: `base` is what
    /// no selection touches, `resampled` the reservoir's sample; read their variance over
    /// seeds, since each part alone is biased against the reference).
    #[cfg_attr(feature = "clap", arg(long, value_enum, default_value_t = RestirSettings::default().shaded_parts))]
    pub shaded_parts: ShadedParts,
    /// The resampled part of each pixel, for every method alike: the expectation of the
    /// frame's final resampling over its choice (every candidate's colour, no ray;
    /// unbiased), or the kept sample f(Y) V W with one shadow ray (the paper's, and the
    /// default before 2026-11-25).
    #[cfg_attr(feature = "clap", arg(long, value_enum, default_value_t = RestirSettings::default().shading))]
    pub shading: Shading,
    /// The order of reuse, for every method alike: `temporal-first` (the standard ReSTIR
    /// order: merge the history into each pixel's candidate, then select among the
    /// block's merged reservoirs, sorted by their estimates), `spatial-first` (the
    /// paper's: select among this frame's candidates, then merge the history) or `auto`
    /// (the default: temporal-first for a still camera, spatial-first for a moving one,
    /// which is where each measured better).
    ///
    /// Without temporal reuse (--accumulate) both orders resample this frame's candidates
    /// with the same weights, and the renderer runs the spatial-first passes (two fewer).
    #[cfg_attr(feature = "clap", arg(long, value_enum, default_value_t = RestirSettings::default().reuse_order))]
    pub reuse_order: ReuseOrder,
    /// Permutation sampling of the temporal source, for every method that reuses history
    /// (RTXDI's decorrelation, on by default there): each pixel takes the history of a
    /// pixel 1 or 3 away on each axis from where it reprojects, a per-frame permutation
    /// of the image, so that neighbours' histories stop chaining. Unbiased (the pairwise
    /// MIS weights evaluate the target at the source actually used; tested).
    ///
    /// Within each aligned 4 x 4 group of pixels, shifted by a per-frame random offset,
    /// x and y are mirrored; a permuted source on another surface (the same similarity
    /// test as reprojection) falls back to the reprojected pixel.
    #[cfg_attr(
        feature = "clap",
        arg(long, default_value_t = RestirSettings::default().permutation_sampling, action = clap::ArgAction::Set)
    )]
    pub permutation_sampling: bool,
    /// Strength of RTXDI's boiling filter after each temporal merge, 0 (off) to 1:
    /// a reservoir whose contribution weight W exceeds its 8 x 8 workgroup's mean nonzero
    /// W by the factor 10 / strength - 9 is emptied (at 1, anything above the mean).
    ///
    /// Biased by design: it removes rare bright samples (the "boiling" flashes reuse spreads
    /// over a neighbourhood), so the image darkens where they carry light; BENCHMARKS.md
    /// ("What the viewer sees") gives the measured bias.
    #[cfg_attr(feature = "clap", arg(long, default_value_t = RestirSettings::default().boiling_filter))]
    pub boiling_filter: f32,
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
            reuse_order: ReuseOrder::Auto,
            permutation_sampling: false,
            boiling_filter: 0.0,
        }
    }
}

impl RestirSettings {
    /// The kernels' uniform as these settings fill it ([`RestirSettings::as_run`]'s: ris
    /// with K = 0 and no temporal reuse): everything but what changes frame by frame
    /// (`temporal`, on from the second frame; the previous camera) and what the renderer
    /// resolves against the scene (`min_distance` when 0), which the renderer sets over it.
    pub fn uniform(&self) -> RestirParams {
        let run = self.as_run();
        RestirParams {
            method: match run.method {
                Method::Strata => METHOD_STRATA,
                Method::Restir => METHOD_RESTIR,
                Method::RestirDisc => METHOD_RESTIR_DISC,
                // No slot is drawn with K = 0, so no method's draw is read.
                Method::Ris => METHOD_RESTIR,
            },
            candidates: run.selection.candidates,
            sampler: run.selection.sampler.id(),
            temporal: u32::from(run.temporal),
            temporal_cap: run.temporal_cap,
            disc_radius: run.disc_radius,
            min_distance: run.min_distance,
            min_roughness: run.min_roughness,
            specular_chain: run.specular_chain,
            replay: u32::from(run.glossy_replay),
            permutation_sampling: u32::from(run.permutation_sampling),
            boiling_filter: run.boiling_filter,
            temporal_candidates: run.temporal_candidates,
            shaded_parts: run.shaded_parts.bits(),
            shading: match run.shading {
                Shading::Sample => SHADING_SAMPLE,
                Shading::Expectation => SHADING_EXPECTATION,
            },
            ..RestirParams::default()
        }
    }

    /// What a frame runs of these settings: themselves, but for [`Method::Ris`], which
    /// reuses nothing: K = 0 (no slot is drawn), no temporal reuse, no drawn previous
    /// reservoirs, no permutation or boiling filter (both act on the temporal merge), and
    /// the paper's order of passes (with K = 0 and no history both orders
    /// keep each pixel's canonical candidate; the paper's runs two passes fewer). The one
    /// place that says what ris leaves out; [`RestirSettings::check`] is for the settings
    /// as given (K = 0 is no setting a user may choose).
    pub fn as_run(self) -> RestirSettings {
        if self.method.reuses() {
            return self;
        }
        let selection = SelectionSettings { candidates: 0, ..self.selection };
        RestirSettings {
            selection,
            temporal: false,
            temporal_candidates: 0,
            reuse_order: ReuseOrder::SpatialFirst,
            permutation_sampling: false,
            boiling_filter: 0.0,
            ..self
        }
    }

    /// These settings for a camera that moves or stands still: [`ReuseOrder::Auto`]
    /// resolved ([`ReuseOrder::for_camera`]).
    pub fn for_camera(self, moving: bool) -> RestirSettings {
        RestirSettings { reuse_order: self.reuse_order.for_camera(moving), ..self }
    }

    /// Refuses settings the kernels cannot run, naming the field and value.
    pub fn check(&self) -> Result<(), PassError> {
        self.selection.validate().map_err(|error| PassError::Input(error.to_string()))?;
        if self.temporal_candidates > 4 {
            return Err(PassError::Input(format!("temporal candidates {}: must be 0 to 4", self.temporal_candidates)));
        }
        if !(self.temporal_cap >= 1.0 && self.temporal_cap.is_finite()) {
            return Err(PassError::Input(format!("temporal cap {}: must be at least 1", self.temporal_cap)));
        }
        if !(self.disc_radius > 0.0 && self.disc_radius <= MAX_DISC_RADIUS) {
            return Err(PassError::Input(format!(
                "disc radius {}: must be positive and at most {MAX_DISC_RADIUS} pixels",
                self.disc_radius
            )));
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
        if !(0.0..=1.0).contains(&self.boiling_filter) {
            return Err(PassError::Input(format!(
                "boiling filter {}: must be 0 (off) to 1 (strongest)",
                self.boiling_filter
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

/// The largest [`RestirSettings::disc_radius`]: the widest image side the command line
/// accepts, so that every offset the disc draws stays an integer the kernels can hold.
pub const MAX_DISC_RADIUS: f32 = 16384.0;

/// The longest smooth chain [`RestirSettings::specular_chain`] accepts (a path has at most
/// the scene's `max_depth` segments anyway).
pub const MAX_SPECULAR_CHAIN: u32 = 16;

#[cfg(all(test, feature = "clap"))]
mod tests {
    use super::*;
    use clap::{Parser, ValueEnum};

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        restir: RestirSettings,
    }

    /// The command line's defaults are `Default`'s, and every flag reaches its field.
    #[test]
    fn command_line_defaults_are_the_defaults_and_each_flag_lands_in_its_field() {
        assert_eq!(Cli::try_parse_from(["strata"]).unwrap().restir, RestirSettings::default());
        let moved = Cli::try_parse_from([
            "strata",
            "--block-size",
            "8",
            "--accumulate",
            "--temporal-candidates",
            "2",
            "--temporal-cap",
            "7",
            "--disc-radius",
            "12",
            "--min-roughness",
            "0.2",
            "--specular-chain",
            "1",
            "--glossy-replay",
            "true",
            "--min-distance",
            "0.01",
            "--shaded-parts",
            "base",
            "--shading",
            "sample",
            "--permutation-sampling",
            "true",
            "--boiling-filter",
            "0.2",
        ])
        .unwrap()
        .restir;
        let want = RestirSettings {
            selection: SelectionSettings { block_size: 8, ..SelectionSettings::default() },
            temporal: false,
            temporal_candidates: 2,
            temporal_cap: 7.0,
            disc_radius: 12.0,
            min_roughness: 0.2,
            specular_chain: 1,
            glossy_replay: true,
            min_distance: 0.01,
            shaded_parts: ShadedParts::Base,
            shading: Shading::Sample,
            permutation_sampling: true,
            boiling_filter: 0.2,
            ..RestirSettings::default()
        };
        assert_eq!(moved, want);
    }

    /// The run record names each field as the struct does and each choice as the
    /// command line does.
    #[test]
    fn the_record_uses_the_field_names_and_the_command_lines_values() {
        let record = serde_json::to_value(RestirSettings::default()).unwrap();
        let keys: Vec<&str> = record.as_object().unwrap().keys().map(String::as_str).collect();
        for field in ["block_size", "candidates", "masking", "block_shift", "sampler", "temporal", "shading"] {
            assert!(keys.contains(&field), "{field} missing from {keys:?}");
        }
        assert!(!keys.contains(&"method"), "the method is the comparison's, not a shared setting");
        fn same_names<T: ValueEnum + serde::Serialize>() {
            for value in T::value_variants() {
                let clap_name = value.to_possible_value().unwrap().get_name().to_string();
                assert_eq!(serde_json::to_value(value).unwrap(), serde_json::Value::from(clap_name));
            }
        }
        same_names::<Method>();
        same_names::<ShadedParts>();
        same_names::<Shading>();
        same_names::<ReuseOrder>();
    }
}

#[cfg(test)]
mod as_run_tests {
    use super::*;

    /// ris reuses nothing, whoever reads its settings: its uniform draws no slot and merges
    /// no history, and its passes run in the paper's order; the other methods run as given.
    #[test]
    fn ris_runs_without_reuse() {
        let ris = RestirSettings {
            method: Method::Ris,
            temporal_candidates: 2,
            permutation_sampling: true,
            boiling_filter: 0.5,
            ..RestirSettings::default()
        };
        let uniform = ris.uniform();
        assert_eq!((uniform.candidates, uniform.temporal, uniform.temporal_candidates), (0, 0, 0));
        assert_eq!((uniform.permutation_sampling, uniform.boiling_filter), (0, 0.0));
        assert_eq!(ris.as_run().reuse_order, ReuseOrder::SpatialFirst);
        ris.check().expect("ris with the default K is a valid setting");
        let strata = RestirSettings { temporal_candidates: 2, ..RestirSettings::default() };
        assert_eq!(strata.as_run(), strata);
        assert_eq!(strata.uniform().candidates, strata.selection.candidates);
    }
}
