//! `cargo xtask`: project automation.
//!
//! * `cargo xtask shaders [--strict]`: translates every registry kernel with naga to
//!   SPIR-V, HLSL, MSL and GLSL under `target/shaders/` and validates each output with
//!   the external validator for its language (see `strata_kernels::validate`). Exits
//!   non-zero if any output is invalid; with `--strict`, also if a validator that can
//!   exist on this machine is missing (CI uses this).
//! * `cargo xtask check [--full]`: runs every registry kernel on every available backend
//!   (wgpu Vulkan and GL, ash on naga's SPIR-V and on glslang's compilation of naga's
//!   GLSL and HLSL) with generated inputs and compares the outputs with the kernels'
//!   references; prints a kernels × backends table and exits non-zero on any mismatch.

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
    /// Check that every kernel gives identical outputs on every backend.
    Check {
        /// At least 20 seeds at several sizes per kernel (default: 3 seeds, small sizes).
        #[arg(long)]
        full: bool,
    },
}

fn main() -> Result<()> {
    match Cli::parse().command {
        Command::Shaders { strict, out } => shaders(strict, out),
        Command::Check { full } => check(full),
    }
}

fn check(full: bool) -> Result<()> {
    let report = strata::check::run_check(strata::check::CheckConfig { full });
    print!("{}", report.render());
    let failures = report.failures();
    if !failures.is_empty() {
        bail!("{} kernel/backend pair(s) failed", failures.len());
    }
    Ok(())
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
