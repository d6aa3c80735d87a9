//! [`SelectionSettings`]: every knob of the stratified selection in one struct, shared by
//! the renderer (`strata_render::restir::RestirSettings`), the embeddable pass
//! (`strata_embed`) and the command line (`strata compare`, which flattens it into its
//! arguments: the field docs below are its `--help`).

use super::SamplerVariant;
use super::patterns::MAX_SELECTED;
use crate::block_grid::BlockGrid;
use crate::types::BLOCK_SIZES;
use thiserror::Error;

/// A setting out of range, naming the field, its value and what it may be.
#[derive(Clone, Debug, Error, PartialEq, Eq)]
#[error("{field} = {value}: must be {expected}")]
pub struct SettingError {
    /// The field's name.
    pub field: &'static str,
    /// Its value.
    pub value: String,
    /// What it may be.
    pub expected: String,
}

/// The command line's parser of a block size: one of [`BLOCK_SIZES`], which `--help`
/// lists (the one list of block sizes; `strata compare` and `strata histogram` use it).
#[cfg(feature = "clap")]
pub fn block_size_parser() -> impl clap::builder::TypedValueParser<Value = u32> {
    // clap's possible values borrow `'static` text: four short strings, made once per
    // command-line parse.
    let names = BLOCK_SIZES.map(|size| &*Box::leak(size.to_string().into_boxed_str()));
    clap::builder::TypedValueParser::map(clap::builder::PossibleValuesParser::new(names), |text: String| {
        text.parse::<u32>().expect("a listed block size")
    })
}

/// `4, 8, 16 or 32`: [`BLOCK_SIZES`] in words.
fn block_sizes_in_words() -> String {
    let names: Vec<String> = BLOCK_SIZES.iter().map(u32::to_string).collect();
    let (last, first) = names.split_last().expect("at least one block size");
    format!("{} or {last}", first.join(", "))
}

/// The stratified selection's settings; `Default` is the paper's (§5.1: 16 × 16 blocks,
/// object masking, four antithetic candidates, temporal blue noise).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct SelectionSettings {
    /// Block size B: candidates are sorted per B x B block of pixels.
    ///
    /// Larger blocks give each cluster more candidates, hence finer strata and less
    /// noise, but join less similar pixels and cost more sorting (paper Table 1: the
    /// histogram pass is 3-10 % of a frame; Fig. 9: 16 is the best trade-off, 4 leaves
    /// blocky low-frequency error, 32 degrades slightly). Default 16.
    #[cfg_attr(
        feature = "clap",
        arg(long, default_value_t = SelectionSettings::default().block_size, value_parser = block_size_parser())
    )]
    pub block_size: u32,
    /// K: candidates selected per pixel besides its own (1 to 4).
    ///
    /// More candidates lower the variance; each costs the engine one shift mapping and
    /// its shadow rays (two in strata's renderer). The antithetic pattern mirrors its
    /// slots in pairs for K = 4 and 2, and one pair plus an offset slot for K = 3.
    /// Default 4 (the paper's).
    #[cfg_attr(feature = "clap", arg(long, default_value_t = SelectionSettings::default().candidates, value_parser = clap::value_parser!(u32).range(1..=i64::from(MAX_SELECTED))))]
    pub candidates: u32,
    /// Object masking (§4.3; on unless --no-masking): candidates cluster by object id
    /// within a block, so a pixel draws only from pixels that see the same object.
    ///
    /// Off, each block is one cluster: more candidates per stratum, but across object
    /// boundaries, where shift mappings mostly fail. Free either way. Default on.
    #[cfg_attr(feature = "clap", arg(long = "no-masking", action = clap::ArgAction::SetFalse))]
    pub masking: bool,
    /// Block shifting (--block-shift): move the block grid by a new offset every frame.
    ///
    /// The paper's limitations section: it averages block-shaped error patterns out over
    /// time. Costs nothing; pixels share histograms with different neighbours each
    /// frame. Default off, as in the paper's measurements.
    #[cfg_attr(feature = "clap", arg(long))]
    pub block_shift: bool,
    /// Sampler variant: where in a cluster's sorted run the K candidates are taken
    /// (Table 2).
    ///
    /// Antithetic with temporal blue noise (the paper's method) has the lowest error;
    /// `random` is plain ReSTIR's uncorrelated selection from the same sorted runs, for
    /// comparisons. Every variant is unbiased for every K. Default antithetic.
    #[cfg_attr(feature = "clap", arg(long, value_enum, default_value_t = SamplerVariant::Antithetic))]
    pub sampler: SamplerVariant,
}

impl Default for SelectionSettings {
    fn default() -> Self {
        Self { block_size: 16, candidates: 4, masking: true, block_shift: false, sampler: SamplerVariant::Antithetic }
    }
}

impl SelectionSettings {
    /// Checks every field (the one check of these settings, wherever they come from).
    pub fn validate(&self) -> Result<(), SettingError> {
        if BlockGrid::check_block_size(self.block_size).is_err() {
            return Err(SettingError {
                field: "block_size",
                value: self.block_size.to_string(),
                expected: block_sizes_in_words(),
            });
        }
        if !(1..=MAX_SELECTED).contains(&self.candidates) {
            return Err(SettingError {
                field: "candidates",
                value: self.candidates.to_string(),
                expected: format!("1 to {MAX_SELECTED}"),
            });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validate_names_the_field() {
        let error = SelectionSettings { block_size: 12, ..Default::default() }.validate().unwrap_err();
        assert_eq!(error.to_string(), "block_size = 12: must be 4, 8, 16 or 32");
        let error = SelectionSettings { candidates: 0, ..Default::default() }.validate().unwrap_err();
        assert_eq!(error.field, "candidates");
        for sampler in SamplerVariant::ALL {
            for candidates in 1..=4 {
                SelectionSettings { sampler, candidates, ..Default::default() }.validate().unwrap();
            }
        }
    }

    /// The command line's defaults are `Default`'s.
    #[cfg(feature = "clap")]
    #[test]
    fn command_line_defaults_are_the_defaults() {
        use clap::Parser;
        #[derive(Parser)]
        struct Cli {
            #[command(flatten)]
            selection: SelectionSettings,
        }
        let cli = Cli::try_parse_from(["strata"]).unwrap();
        assert_eq!(cli.selection, SelectionSettings::default());
        let cli = Cli::try_parse_from([
            "strata",
            "--block-size",
            "8",
            "--candidates",
            "2",
            "--no-masking",
            "--block-shift",
            "--sampler",
            "random-offset",
        ])
        .unwrap();
        let want = SelectionSettings {
            block_size: 8,
            candidates: 2,
            masking: false,
            block_shift: true,
            sampler: SamplerVariant::RandomOffset,
        };
        assert_eq!(cli.selection, want);
        for bad in [["--block-size", "12"], ["--candidates", "5"], ["--sampler", "sobol"]] {
            assert!(Cli::try_parse_from(["strata", bad[0], bad[1]]).is_err(), "{bad:?} accepted");
        }
    }
}
