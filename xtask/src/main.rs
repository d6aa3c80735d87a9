//! `cargo xtask`: project automation.
//!
//! * `cargo xtask shaders [--strict]`: translates every registry kernel with naga to
//!   SPIR-V, HLSL, MSL and GLSL under `target/shaders/` and validates each output with
//!   the external validator for its language (see `strata_kernels::validate`). Exits
//!   non-zero if any output is invalid; with `--strict`, also if a validator that can
//!   exist on this machine is missing (CI uses this).
//! * `cargo xtask check [--full] [--kernel NAME,...]`: runs every registry kernel on every available backend
//!   (wgpu Vulkan and GL, ash on naga's SPIR-V and on glslang's compilation of naga's
//!   GLSL and HLSL) with generated inputs and compares the outputs with the kernels'
//!   references; prints a kernels × backends table and exits non-zero on any mismatch.
//! * `cargo xtask run FILE.wgsl --entry NAME --workgroups X,Y,Z --buffer 0:B=FILE ...
//!   [--size 0:B=BYTES] --backend cpu|wgpu|wgpu-gl|ash|ash-glsl|ash-hlsl|all [--out DIR]`:
//!   runs any WGSL compute shader, writes every writable buffer to
//!   `DIR/BACKEND/0_B_NAME.bin`, and with several backends says whether they agree.

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
    /// Run any WGSL compute shader on chosen backends.
    Run {
        /// The WGSL file.
        shader: PathBuf,
        /// Compute entry point.
        #[arg(long)]
        entry: String,
        /// Workgroups X,Y,Z.
        #[arg(long, value_parser = parse_workgroups, default_value = "1,1,1")]
        workgroups: [u32; 3],
        /// GROUP:BINDING=FILE: buffer contents (repeatable).
        #[arg(long = "buffer", value_parser = parse_buffer)]
        buffers: Vec<(u32, u32, PathBuf)>,
        /// GROUP:BINDING=BYTES: a zero-filled buffer of that size (default: the binding's minimum).
        #[arg(long = "size", value_parser = parse_size)]
        sizes: Vec<(u32, u32, u64)>,
        /// Backends, comma-separated, or `all`.
        #[arg(long, default_value = "cpu", value_delimiter = ',')]
        backend: Vec<String>,
        /// Output folder.
        #[arg(long, default_value = "target/run")]
        out: PathBuf,
    },
    /// Check that every kernel gives identical outputs on every backend.
    Check {
        /// At least 20 seeds at several sizes per kernel (default: 3 seeds, small sizes).
        #[arg(long)]
        full: bool,
        /// Only these kernels (registry names, comma-separated); all when left out.
        #[arg(long, value_delimiter = ',')]
        kernel: Vec<String>,
    },
}

fn main() -> Result<()> {
    match Cli::parse().command {
        Command::Shaders { strict, out } => shaders(strict, out),
        Command::Check { full, kernel } => check(full, &kernel),
        Command::Run { shader, entry, workgroups, buffers, sizes, backend, out } => {
            run(strata_check::run_kernel::RunRequest {
                shader,
                entry,
                workgroups,
                buffers,
                sizes,
                backends: backend,
                out,
            })
        }
    }
}

fn check(full: bool, only: &[String]) -> Result<()> {
    let registry = Registry::shared()?;
    let mut checks = strata_check::kernel_checks();
    if let Some(unknown) = only.iter().find(|name| !checks.iter().any(|c| registry.get(c.kernel()).name() == *name)) {
        let names: Vec<&str> = checks.iter().map(|c| registry.get(c.kernel()).name()).collect();
        bail!("--kernel {unknown}: no such kernel (kernels: {})", names.join(", "));
    }
    if !only.is_empty() {
        checks.retain(|c| only.iter().any(|name| registry.get(c.kernel()).name() == name));
    }
    let report = strata_check::run_checks(strata_check::CheckConfig { full }, checks);
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

fn parse_workgroups(text: &str) -> Result<[u32; 3], String> {
    let parts: Vec<u32> = text
        .split(',')
        .map(|p| p.trim().parse::<u32>().map_err(|e| format!("`{p}`: {e}")))
        .collect::<Result<_, _>>()?;
    match parts.as_slice() {
        [x] => Ok([*x, 1, 1]),
        [x, y] => Ok([*x, *y, 1]),
        [x, y, z] => Ok([*x, *y, *z]),
        _ => Err(format!("`{text}`: expected X, X,Y or X,Y,Z")),
    }
}

fn parse_binding(text: &str) -> Result<(u32, u32, &str), String> {
    let (target, value) = text.split_once('=').ok_or_else(|| format!("`{text}`: expected GROUP:BINDING=VALUE"))?;
    let (group, binding) = target.split_once(':').ok_or_else(|| format!("`{target}`: expected GROUP:BINDING"))?;
    let group = group.parse().map_err(|e| format!("group `{group}`: {e}"))?;
    let binding = binding.parse().map_err(|e| format!("binding `{binding}`: {e}"))?;
    Ok((group, binding, value))
}

fn parse_buffer(text: &str) -> Result<(u32, u32, PathBuf), String> {
    parse_binding(text).map(|(g, b, v)| (g, b, PathBuf::from(v)))
}

fn parse_size(text: &str) -> Result<(u32, u32, u64), String> {
    let (g, b, v) = parse_binding(text)?;
    Ok((g, b, v.parse().map_err(|e| format!("size `{v}`: {e}"))?))
}

fn run(request: strata_check::run_kernel::RunRequest) -> Result<()> {
    let runs = strata_check::run_kernel::run_kernel(&request)?;
    let mut failed = false;
    for run in &runs {
        match &run.outputs {
            Ok(outputs) => println!(
                "{:<12} ok: {} output buffer(s) in {}",
                run.backend,
                outputs.len(),
                request.out.join(&run.backend).display()
            ),
            Err(error) => {
                failed = true;
                println!("{:<12} FAILED: {error}", run.backend);
            }
        }
    }
    if runs.iter().filter(|r| r.outputs.is_ok()).count() > 1 {
        match strata_check::run_kernel::disagreement(&runs) {
            None => println!("backends agree: every output identical"),
            Some(difference) => bail!("backends disagree: {difference}"),
        }
    }
    if failed {
        bail!("the shader failed on at least one backend");
    }
    Ok(())
}
