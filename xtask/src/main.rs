//! `cargo xtask`: project automation.
//!
//! * `cargo xtask shaders [--strict]`: translates every registry kernel with naga to
//!   SPIR-V, HLSL, MSL and GLSL under `target/shaders/` and validates each output with
//!   the external validator for its language (see `strata_kernels::validate`). Exits
//!   non-zero if any output is invalid; with `--strict`, also if a validator that can
//!   exist on this machine is missing (CI uses this).
//! * `cargo xtask check [--full] [--kernel NAME,...]`: runs every registry kernel on every available backend
//!   (wgpu Vulkan and GL, ash on naga's SPIR-V and on glslang's compilation of naga's
//!   GLSL and HLSL, Slang's of the HLSL, Chromium's WebGPU) with generated inputs and compares the outputs with the kernels'
//!   references; prints a kernels × backends table, then the texture corpus's table
//!   (`strata_check::texture_corpus`, against the interpreter; not with `--kernel`), and
//!   exits non-zero on any mismatch. The backends run in parallel, one per core, and a
//!   progress line per kernel and backend (with the time left, estimated) goes to
//!   standard error.
//! * `cargo xtask run FILE.wgsl --entry NAME --workgroups X,Y,Z --buffer G:B=FILE ...
//!   [--size G:B=BYTES] [--texture G:B=FILE] [--storage-texture G:B=WxH[:FORMAT]]
//!   [--sampler G:B=FILTER,ADDRESS] [--override NAME=VALUE ...] [--ulp N | --ulp BUFFER=N ...] [--abs E | --abs BUFFER=E ...]
//!   [--reference BACKEND] [--time-limit SECONDS] [--sanitize]
//!   --backend cpu|wgpu|wgpu-gl|ash|ash-glsl|ash-hlsl|ash-slang|webgpu|all [--out DIR]`:
//!   runs any WGSL compute shader, writes every writable buffer and storage texture to
//!   `DIR/BACKEND/G_B_NAME.bin` (a storage texture also as `.png` or `.exr`), and with several backends reports per backend and
//!   buffer whether it is identical to the reference backend's, or how many words
//!   differ and by how many ULP; exits non-zero only when a backend fails or a buffer
//!   exceeds the tolerance (integers: exact; f32 words: `--ulp`, default 0). Every flag
//!   is checked first: a binding given twice, a backend named twice, a bound for a
//!   buffer that is not an output, an override value its type or naga's workgroup size
//!   cannot take, a size past 4 GiB are one-line errors naming the flag. `all` lists a
//!   path whose toolchain is missing (or that has no device, or whose device lacks a
//!   feature the kernel needs) as unavailable. The
//!   interpreter (`cpu`) stops a dispatch past `--time-limit` (default 60 s) naming where
//!   the kernel was, and runs as a sanitizer whenever another path is compared with it
//!   (or with `--sanitize`): its findings are listed, and a buffer that differs from a
//!   kernel WGSL leaves undefined (an index out of range, a data race) is reported as
//!   `undefined by WGSL: ...`, which does not fail the run.
//!
//! * `cargo xtask fuzz [--target T,...] [--seconds N] [--executions N] [--seed S]
//!   [--crash-dir DIR] [--hang-ms MS] [--no-shared]`: fuzzes the loaders (scene JSON, PLY,
//!   glTF/GLB, OBJ/MTL, EXR, errors.csv; `strata_check::fuzz`), each target for N seconds
//!   (default 10) or N executions from the seed (default 1); prints per target the
//!   executions, rate, distinct outcomes and findings. A panic or a loaded scene with a NaN
//!   where a number must be finite is written to `tests/data/fuzz/<target>/crash-<hash>`
//!   and the run exits 1 naming it; a hang (an input over 2 s) or one allocation over
//!   1 GiB writes `hang-`/`huge-<hash>` and exits 2 or 3 at once. Commit the files: the
//!   `fuzz_regressions` test runs each of them again.
//!
//! * `cargo xtask export --out DIR`: the kernel package for engines outside Rust
//!   (`strata_export`: translations, manifest.json, strata.h, strata_frame.h,
//!   strata_vk.h, the blue-noise tables, a README per API).
//!
//! * `cargo xtask validate`: `strata render`, `strata compare` (temporal and
//!   accumulated, wgpu and ash), both embed examples and `xtask check` under
//!   `VK_LAYER_KHRONOS_validation` with synchronization validation; fails on any error or
//!   warning, reports best-practices notes (see `validate.rs`).
//!
//! Errors, a disagreement included, print one line (no backtrace, whatever
//! `RUST_BACKTRACE` says: they are findings, not bugs of xtask) and exit with 1.

mod fuzz;
#[cfg(test)]
mod tests;
mod validate;
mod web;

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand};
use std::path::PathBuf;
use strata_check::agreement::judge;
use strata_check::overrides::OverrideFlag;
use strata_check::run_images::{self, ImageSpec, SamplerDesc, StorageTextureSize, TextureFile};
use strata_check::run_kernel::RunRequest;
use strata_kernels::Registry;
use strata_kernels::validate::{Target, Verdict, translate_and_validate};

/// The system allocator, with a limit per allocation while a fuzz input runs.
#[global_allocator]
static ALLOCATOR: strata_check::fuzz::GuardedAllocator = strata_check::fuzz::GuardedAllocator;

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
    Run(Box<RunArgs>),
    /// Check that every kernel gives identical outputs on every backend.
    Check {
        /// At least 20 seeds at several sizes per kernel (default: 3 seeds, small sizes).
        #[arg(long)]
        full: bool,
        /// Only these kernels (registry names, comma-separated); all when left out.
        #[arg(long, value_delimiter = ',')]
        kernel: Vec<String>,
        /// Only these backends (report names: cpu, wgpu-vulkan, wgpu-gl, ash, ash-glsl,
        /// ash-hlsl, ash-slang, webgpu, or wgpu for wgpu-vulkan; comma-separated), for the
        /// kernels and the texture corpus (which runs cpu, its reference, in any case); all
        /// when left out or `all`.
        #[arg(long, value_delimiter = ',')]
        backend: Vec<String>,
    },
    /// Fuzz the scene, image and CSV loaders (structure-aware mutation, fixed seed).
    Fuzz(fuzz::FuzzArgs),
    /// Run render, compare, the embed examples and the check under the Vulkan validation
    /// layer with synchronization validation; fail on any error or warning.
    Validate,
    /// Write the kernel package for engines outside Rust: every kernel of the embeddable
    /// pass in SPIR-V, HLSL, MSL, GLSL and WGSL, manifest.json, the C headers and the
    /// blue-noise tables (strata-export).
    Export {
        /// The package's folder: new, empty, or an earlier package holding only the files
        /// its manifest lists (replaced whole; a file of yours anywhere in it refuses the
        /// export by name).
        #[arg(long)]
        out: PathBuf,
    },
    /// Serve the live comparison page (ris, restir and strata in the browser on WebGPU):
    /// builds its module for wasm32 and renders its reference first.
    Web {
        /// Stop after this many seconds (default: run until interrupted).
        #[arg(long)]
        seconds: Option<u64>,
    },
}

/// `cargo xtask run`'s arguments.
#[derive(clap::Args)]
struct RunArgs {
    /// The WGSL file.
    shader: PathBuf,
    /// Compute entry point.
    #[arg(long)]
    entry: String,
    /// Workgroups X,Y,Z.
    #[arg(long, value_parser = parse_workgroups, default_value = "1,1,1")]
    workgroups: [u32; 3],
    /// GROUP:BINDING=FILE: buffer contents (repeatable, once per binding).
    #[arg(long = "buffer", value_parser = parse_buffer)]
    buffers: Vec<(u32, u32, PathBuf)>,
    /// GROUP:BINDING=BYTES: a zero-filled buffer of that size, at most 4 GiB and the
    /// device's buffer limit (default: the binding's minimum; not with --buffer for the
    /// same binding).
    #[arg(long = "size", value_parser = parse_size)]
    sizes: Vec<(u32, u32, u64)>,
    /// GROUP:BINDING=FILE: a texture from a PNG (rgba8unorm, the 8-bit codes), an EXR
    /// (rgba32float), or raw texels written FILE@WxH:FORMAT or FILE@WxHxD:FORMAT (e.g.
    /// t.bin@64x64:rgba8unorm: the value is split at its last `@`; a value ending in .png
    /// or .exr is always a picture, so my@photo.png is the picture); its shape is the
    /// kernel's (repeatable, once per binding).
    #[arg(long = "texture", value_parser = parse_texture)]
    textures: Vec<(u32, u32, TextureFile)>,
    /// GROUP:BINDING=WxH, WxHxD or WxH:FORMAT: a zero-filled storage texture, written back as
    /// raw texels and a PNG (rgba8unorm) or EXR (float formats) (repeatable).
    #[arg(long = "storage-texture", value_parser = parse_storage)]
    storage_textures: Vec<(u32, u32, StorageTextureSize)>,
    /// GROUP:BINDING=FILTER,ADDRESS: a sampler, `nearest` or `linear`, `clamp`, `repeat`
    /// or `mirror` (repeatable).
    #[arg(long = "sampler", value_parser = parse_sampler_flag)]
    samplers: Vec<(u32, u32, SamplerDesc)>,
    /// NAME=VALUE: the value of an `override` constant (repeatable; by name, or by its
    /// `@id` number as ID=VALUE or @ID=VALUE, whether or not it has a name). Others keep
    /// their WGSL defaults. Applied once, by naga, before any backend sees the shader, so
    /// every backend runs the same specialisation (`webgpu`, which compiles the WGSL
    /// itself, gets the same values as its pipeline's constants).
    #[arg(long = "override", value_parser = OverrideFlag::parse)]
    overrides: Vec<OverrideFlag>,
    /// Backends, comma-separated, each once, or `all` (cpu, wgpu-vulkan, wgpu-gl, ash,
    /// ash-glsl, ash-hlsl, ash-slang, webgpu; `wgpu` means wgpu-vulkan). `all` runs every
    /// path available here and lists the others as unavailable (a missing toolchain such
    /// as Slang's or Chromium, no device, a device without a feature the kernel needs,
    /// such as linear filtering of `rgba32float`, or a WebGPU limit) without failing; a
    /// path named on its own must run.
    #[arg(long, default_value = "cpu", value_delimiter = ',')]
    backend: Vec<String>,
    /// Tolerance for f32 words: N units in the last place for every buffer, or
    /// BUFFER=N for one output buffer (repeatable). Integer words (detected from the
    /// IR) must always be identical; padding is not compared. Default 0.
    #[arg(long = "ulp", value_parser = parse_ulp)]
    ulp: Vec<(Option<String>, u32)>,
    /// Absolute floor for f32 words: E for every buffer or BUFFER=E for one
    /// (repeatable); words this close pass whatever their ULP distance (results that
    /// cancel to near zero, `log` near 1). Default: off.
    #[arg(long = "abs", value_parser = parse_abs)]
    abs: Vec<(Option<String>, f32)>,
    /// The backend the others are compared with (default: the first that ran).
    #[arg(long)]
    reference: Option<String>,
    /// The interpreter's time limit per dispatch, in seconds (default 60): a kernel
    /// running longer (a loop that never ends) fails naming where it was.
    #[arg(long = "time-limit", value_parser = parse_time_limit)]
    time_limit: Option<std::time::Duration>,
    /// Run the interpreter as a sanitizer and list its findings (out-of-range indices,
    /// reads of unwritten workgroup memory, data races, barriers in non-uniform control
    /// flow); on by itself whenever `cpu` is compared with another path.
    #[arg(long)]
    sanitize: bool,
    /// Output folder.
    #[arg(long, default_value = "target/run")]
    out: PathBuf,
}

fn main() {
    if let Err(error) = execute(Cli::parse()) {
        // `{:#}` puts anyhow's causes on the line; `{:?}` would add a backtrace.
        eprintln!("error: {error:#}");
        std::process::exit(1);
    }
}

/// Runs one command.
fn execute(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Shaders { strict, out } => shaders(strict, out),
        Command::Check { full, kernel, backend } => check(full, &kernel, &backend),
        Command::Validate => validate::validate(),
        Command::Fuzz(args) => fuzz::fuzz(args),
        Command::Web { seconds } => web::web(seconds),
        Command::Export { out } => strata_export::export(&out)
            .map(|exported| {
                println!("wrote the kernel package {} ({} files)", exported.folder.display(), exported.files.len())
            })
            .map_err(Into::into),
        Command::Run(args) => {
            let RunArgs {
                shader,
                entry,
                workgroups,
                buffers,
                sizes,
                textures,
                storage_textures,
                samplers,
                overrides,
                backend,
                ulp,
                abs,
                reference,
                time_limit,
                sanitize,
                out,
            } = *args;
            let images = images(&textures, &storage_textures, &samplers);
            let request = RunRequest {
                shader,
                entry,
                workgroups,
                buffers,
                sizes,
                overrides,
                images,
                backends: backend,
                out,
                ulp,
                abs,
                time_limit,
                sanitize,
            };
            run(request, reference.as_deref())
        }
    }
}

fn check(full: bool, only: &[String], backends: &[String]) -> Result<()> {
    let registry = Registry::shared()?;
    let slots = if backends.is_empty() {
        strata_check::backend_slots()
    } else {
        strata_check::run_kernel::named_slots(backends)?
    };
    let mut checks = strata_check::kernel_checks();
    if let Some(unknown) = only.iter().find(|name| !checks.iter().any(|c| registry.get(c.kernel()).name() == *name)) {
        let names: Vec<&str> = checks.iter().map(|c| registry.get(c.kernel()).name()).collect();
        bail!("--kernel {unknown}: no such kernel (kernels: {})", names.join(", "));
    }
    if !only.is_empty() {
        checks.retain(|c| only.iter().any(|name| registry.get(c.kernel()).name() == name));
    }
    // Progress on standard error (the report is standard output): a first run on a CPU
    // driver compiles every kernel once per slot, minutes, so say where it is and about
    // how long is left.
    let progress = |p: &strata_check::Progress| {
        eprintln!(
            "check: {}/{} {} on {} ({} in, about {} left)",
            p.done,
            p.total,
            p.kernel,
            p.slot,
            minutes(p.elapsed),
            minutes(p.remaining())
        );
    };
    let report =
        strata_check::run_checks_reporting_on(strata_check::CheckConfig { full }, checks, slots.clone(), &progress);
    print!("{}", report.render());
    // The texture corpus (kernels outside the registry) unless only some kernels were asked for.
    let textures = if only.is_empty() {
        let slots = strata_check::texture_corpus::with_reference(slots);
        let names: Vec<&str> = slots.iter().map(|slot| slot.name).collect();
        eprintln!("check: the texture corpus on {}", names.join(", "));
        strata_check::texture_corpus::run_texture_corpus_on(slots)
    } else {
        Vec::new()
    };
    if !textures.is_empty() {
        print!("\n{}", strata_check::texture_corpus::render_table(&textures));
    }
    let texture_failures =
        textures.iter().flat_map(|(_, verdicts)| verdicts).filter(|(_, verdict)| !verdict.passes()).count();
    let failures = report.failures();
    if !failures.is_empty() || texture_failures > 0 {
        bail!("{} kernel/backend pair(s) and {texture_failures} texture case/backend pair(s) failed", failures.len());
    }
    Ok(())
}

/// `1 min 05 s`, `42 s`.
fn minutes(duration: std::time::Duration) -> String {
    let seconds = duration.as_secs();
    if seconds < 60 { format!("{seconds} s") } else { format!("{} min {:02} s", seconds / 60, seconds % 60) }
}

fn shaders(strict: bool, out: PathBuf) -> Result<()> {
    std::fs::create_dir_all(&out).with_context(|| format!("--out {}: cannot create the folder", out.display()))?;
    let registry = Registry::load()?;
    let mut failures = 0;
    let mut missing = 0;
    println!("{:<28} {:<7} verdict", "kernel", "target");
    // The validators are external processes, one at a time per kernel: kernels go to one
    // worker per core (each kernel's files are its own), the table is printed in order.
    let kernels = registry.kernels();
    let verdicts = strata_check::parallel::map(kernels, |kernel| {
        Target::ALL.map(|target| translate_and_validate(kernel, target, &out))
    });
    for (kernel, results) in kernels.iter().zip(verdicts) {
        for (target, (path, verdict)) in Target::ALL.into_iter().zip(results) {
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

fn parse_texture(text: &str) -> Result<(u32, u32, TextureFile), String> {
    let (g, b, v) = parse_binding(text)?;
    Ok((g, b, run_images::parse_texture_file(v)?))
}

fn parse_storage(text: &str) -> Result<(u32, u32, StorageTextureSize), String> {
    let (g, b, v) = parse_binding(text)?;
    Ok((g, b, run_images::parse_storage_texture(v)?))
}

fn parse_sampler_flag(text: &str) -> Result<(u32, u32, SamplerDesc), String> {
    let (g, b, v) = parse_binding(text)?;
    Ok((g, b, run_images::parse_sampler(v)?))
}

/// The image flags as one list.
fn images(
    textures: &[(u32, u32, TextureFile)],
    storage: &[(u32, u32, StorageTextureSize)],
    samplers: &[(u32, u32, SamplerDesc)],
) -> Vec<ImageSpec> {
    textures
        .iter()
        .map(|(g, b, file)| ImageSpec::Texture((*g, *b), file.clone()))
        .chain(storage.iter().map(|(g, b, (size, format))| ImageSpec::StorageTexture((*g, *b), *size, *format)))
        .chain(samplers.iter().map(|(g, b, desc)| ImageSpec::Sampler((*g, *b), *desc)))
        .collect()
}

/// `N` (every buffer) or `BUFFER=N` (one buffer).
fn parse_bound<T: std::str::FromStr>(text: &str, what: &str) -> Result<(Option<String>, T), String>
where
    T::Err: std::fmt::Display,
{
    let (buffer, bound) = match text.split_once('=') {
        Some((buffer, bound)) => (Some(buffer.trim().to_string()), bound),
        None => (None, text),
    };
    let bound = bound.trim().parse().map_err(|e| format!("`{text}`: {what} `{bound}`: {e}"))?;
    Ok((buffer, bound))
}

fn parse_ulp(text: &str) -> Result<(Option<String>, u32), String> {
    parse_bound(text, "ULP bound")
}

fn parse_abs(text: &str) -> Result<(Option<String>, f32), String> {
    let (buffer, bound): (Option<String>, f32) = parse_bound(text, "absolute bound")?;
    if !(bound.is_finite() && bound >= 0.0) {
        return Err(format!("`{text}`: the absolute bound must be a finite number ≥ 0"));
    }
    Ok((buffer, bound))
}

/// `--time-limit SECONDS`: a positive number of seconds, at most a day.
fn parse_time_limit(text: &str) -> Result<std::time::Duration, String> {
    match text.trim().parse::<f64>() {
        Ok(seconds) if seconds.is_finite() && seconds > 0.0 && seconds <= 86_400.0 => {
            Ok(std::time::Duration::from_secs_f64(seconds))
        }
        _ => Err(format!("`{text}`: the time limit must be a number of seconds above 0 and at most 86400")),
    }
}

fn run(request: RunRequest, reference: Option<&str>) -> Result<()> {
    let reference = reference.map(|name| if name == "wgpu" { "wgpu-vulkan" } else { name });
    if let Some(name) = reference {
        let named = strata_check::run_kernel::named_slots(&request.backends)?;
        if !named.iter().any(|slot| slot.name == name) {
            let names: Vec<&str> = named.iter().map(|slot| slot.name).collect();
            bail!("--reference {name}: not among the backends run ({})", names.join(", "));
        }
    }
    let outcome = strata_check::run_kernel::run_kernel(&request)?;
    let tolerance = &outcome.tolerance;
    let runs = &outcome.runs;
    for run in runs {
        match &run.outputs {
            Ok(outputs) => println!(
                "{:<12} ran: {} output buffer(s) in {}",
                run.backend,
                outputs.len(),
                request.out.join(&run.backend).display()
            ),
            Err(error) => println!("{:<12} FAILED: {}", run.backend, error.replace('\n', " ")),
        }
    }
    for (backend, why) in &outcome.unavailable {
        println!("{backend:<12} unavailable: {}", why.replace('\n', " "));
    }
    let (findings, dropped) = &outcome.findings;
    if outcome.sanitized {
        match findings.len() {
            0 => println!("sanitizer: no finding in the interpreter's run"),
            n => println!("sanitizer: {n} finding(s) in the interpreter's run:"),
        }
        for finding in findings {
            let what = if finding.kind.undefined() { "undefined by WGSL" } else { "note" };
            println!("  {what}: {finding}");
        }
        if *dropped > 0 {
            println!("  and {dropped} more occurrence(s) past the first {} places", findings.len());
        }
    }
    let undefined = outcome.undefined_behaviour();
    let ran = runs.iter().filter(|r| r.outputs.is_ok()).count();
    if ran > 1 || reference.is_some() {
        let judgement = judge(runs, reference, tolerance).map_err(anyhow::Error::msg)?;
        println!("against {}:", judgement.reference);
        for buffer in &judgement.buffers {
            let verdict = match outcome.undefined_behaviour_for(&buffer.name) {
                Some(why) => buffer.describe_undefined(&why),
                None => buffer.describe(),
            };
            println!("{:<12} {} `{}`: {}", buffer.backend, buffer.binding, buffer.name, verdict);
        }
        let inexact = strata_check::run_kernel::inexact_functions(&outcome.kernel);
        let interpreter_compared = runs.iter().any(|r| r.backend == "cpu" && r.outputs.is_ok());
        if interpreter_compared && !inexact.is_empty() && judgement.buffers.iter().any(|b| b.max_ulp > 0) {
            println!(
                "note: the shader calls {}; the interpreter computes them within 1 ULP and GPU drivers \
                 within Vulkan's precision, so float outputs differ by a few ULP (README, \"Running your own \
                 kernels\", gives the bound per function)",
                inexact.join(", ")
            );
        }
        // A kernel WGSL leaves undefined may give each path its own result: a difference
        // is reported as such, not failed (docs/kernels.md, "The time limit and the
        // interpreter as a sanitizer").
        let beyond = judgement.buffers.iter().filter(|b| !b.passes() && undefined.is_none()).count();
        if beyond > 0 {
            bail!("{beyond} output buffer(s) beyond the tolerance (integers exact, f32 within --ulp)");
        }
    }
    let failed = runs.len() - ran;
    if failed > 0 {
        bail!("{failed} backend(s) could not run the shader");
    }
    Ok(())
}
