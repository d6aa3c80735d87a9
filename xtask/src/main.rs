//! `cargo xtask`: project automation.
//!
//! * `cargo xtask shaders [--strict]`: translates every registry kernel with naga to
//!   SPIR-V, HLSL, MSL and GLSL under `target/shaders/` and validates each output with
//!   the external validator for its language (see `strata_kernels::validate`). Exits
//!   non-zero if any output is invalid; with `--strict`, also if a validator that can
//!   exist on this machine is missing (CI uses this).

use anyhow::{Result, bail};
use clap::{Parser, Subcommand};
use std::path::PathBuf;
use strata_kernels::Registry;
use strata_kernels::validate::{Target, Verdict, translate_and_validate};

#[derive(Parser)]
#[command(about = "strata project automation")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Translate and validate every registry kernel.
    Shaders {
        /// Fail when a validator is missing (except MSL's, which no Linux machine has).
        #[arg(long)]
        strict: bool,
        /// Output folder.
        #[arg(long, default_value = "target/shaders")]
        out: PathBuf,
    },
}

fn main() -> Result<()> {
    match Cli::parse().command {
        Command::Shaders { strict, out } => shaders(strict, out),
    }
}

fn shaders(strict: bool, out: PathBuf) -> Result<()> {
    std::fs::create_dir_all(&out)?;
    let registry = Registry::load()?;
    let mut failures = 0;
    let mut missing = 0;
    println!("{:<28} {:<7} verdict", "kernel", "target");
    for kernel in registry.kernels() {
        for target in Target::ALL {
            let (path, verdict) = translate_and_validate(kernel, target, &out);
            let text = match &verdict {
                Verdict::Valid(tool) => format!("valid ({tool}) -> {}", path.display()),
                Verdict::Invalid(why) => {
                    failures += 1;
                    format!("INVALID: {why}")
                }
                Verdict::Missing(why) => {
                    if target.validator_possible() {
                        missing += 1;
                    }
                    format!("not validated: {why}")
                }
            };
            println!("{:<28} {:<7} {text}", kernel.name(), target.name());
        }
    }
    if failures > 0 {
        bail!("{failures} translation(s) invalid");
    }
    if strict && missing > 0 {
        bail!("{missing} validator(s) missing (--strict): install spirv-tools and glslang-tools");
    }
    Ok(())
}
