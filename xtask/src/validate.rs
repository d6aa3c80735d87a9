//! `cargo xtask validate`: the programs that record Vulkan work, run under
//! `VK_LAYER_KHRONOS_validation` with synchronization validation on (the check that
//! finds a missing barrier, which lavapipe's in-order execution hides) and best
//! practices reported: `strata render` and `strata compare` (all three methods, temporal
//! and accumulated) on wgpu and on ash, both `strata-embed` examples (the ash one
//! records its own barriers into the engine's command buffer), and `xtask check`.
//!
//! The layer is switched on from outside (`VK_INSTANCE_LAYERS`, and a layer settings
//! file through `VK_LAYER_SETTINGS_PATH`) so every program runs exactly as users run
//! it, one per core at a time (each with its own output folder). Each writes its own
//! log under `target/validation/`; any error or warning that is
//! not a best-practices note fails the run, naming the program and the message ID.
//! Best-practices notes are counted and printed, not asserted (several are about
//! desktop GPUs and do not apply to lavapipe).
//!
//! Measured on lavapipe: removing the barrier between the uniform updates and the
//! dispatches in `embed/src/ash_selection.rs` gives 12 `SYNC-HAZARD-READ-AFTER-WRITE`
//! errors in `ash_embed`.

use anyhow::{Context, Result, bail};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

/// One program run under the layer.
struct Step {
    name: &'static str,
    program: PathBuf,
    args: Vec<String>,
}

/// The workspace root (xtask's manifest folder's parent).
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("xtask lies in the workspace").to_path_buf()
}

/// What one message of the layer's log says: its ID, severity and first line.
#[derive(Debug, PartialEq)]
struct Message {
    id: String,
    severity: String,
    text: String,
}

/// Messages of Debian 12's layer (1.3.239) that are its own mistakes, each with the
/// text that must be in the message and why it is not ours.
const KNOWN_LAYER_MISTAKES: [(&str, &str, &str); 1] = [(
    "UNASSIGNED-CoreValidation-Shader-InconsistentSpirv",
    "Invalid source language operand: 10",
    "wgpu's debug builds mark naga's SPIR-V with OpSource WGSL (10), which this layer's SPIR-V tables predate",
)];

/// The messages of a log written with `VK_DBG_LAYER_ACTION_LOG_MSG`: each starts with a
/// line `ID(SEVERITY / TYPE): msgNum: …`.
fn messages(log: &str) -> Vec<Message> {
    log.lines()
        .filter(|line| line.contains("): msgNum: "))
        .filter_map(|line| {
            let (id, rest) = line.split_once('(')?;
            let severity = rest.split_once(" / ")?.0;
            Some(Message { id: id.trim().to_string(), severity: severity.to_string(), text: line.to_string() })
        })
        .collect()
}

/// Whether a message is a best-practices note (reported, not asserted).
fn is_best_practice(message: &Message) -> bool {
    message.id.contains("BestPractices")
}

/// Whether a message is one of [`KNOWN_LAYER_MISTAKES`].
fn is_known_layer_mistake(message: &Message) -> bool {
    KNOWN_LAYER_MISTAKES.iter().any(|(id, text, _)| message.id == *id && message.text.contains(text))
}

/// Runs every step under the layer; fails on any error or warning that is not a
/// best-practices note.
pub fn validate() -> Result<()> {
    let root = root();
    let target = root.join("target");
    let folder = target.join("validation");
    std::fs::create_dir_all(&folder).with_context(|| format!("{}: cannot create", folder.display()))?;
    // The whole workspace's binaries and examples rather than the two packages': a build of
    // a few packages resolves their dependencies' features for those packages alone, which
    // differ from the workspace's (serde's `alloc`, bitflags' `std`), and rebuilt naga, wgpu
    // and 47 other crates after `cargo test --workspace` (2 min 26 s on 2 cores).
    let status = Command::new(env!("CARGO"))
        .current_dir(&root)
        .args(["build", "-q", "--workspace", "--bins", "--examples"])
        .status()
        .context("cargo build")?;
    if !status.success() {
        bail!("building strata and the embed examples failed");
    }
    let debug = target.join("debug");
    let strata = debug.join("strata");
    let small = ["--width", "24", "--height", "24"];
    // A `strata` run writing into its own folder, so that steps can run side by side.
    let strata_step = |name: &'static str, command: &str, settings: &[&str]| -> Result<Step> {
        let out = folder.join("out").join(name);
        let out = out.to_str().context("a UTF-8 target path")?;
        let args = [&[command], &small[..], settings, &["--out", out]].concat();
        Ok(Step { name, program: strata.clone(), args: args.into_iter().map(String::from).collect() })
    };
    let compare = ["--frames", "3", "--seeds", "2", "--reference-spp", "4"];
    let steps = vec![
        strata_step("render-wgpu", "render", &["--spp", "4"])?,
        strata_step("render-ash", "render", &["--spp", "4", "--backend", "ash"])?,
        strata_step("compare-wgpu", "compare", &compare)?,
        strata_step("compare-wgpu-accumulate", "compare", &[&compare[..], &["--accumulate"]].concat())?,
        strata_step("compare-ash", "compare", &[&compare[..], &["--backend", "ash"]].concat())?,
        strata_step(
            "compare-ash-accumulate",
            "compare",
            &[&compare[..], &["--backend", "ash", "--accumulate"]].concat(),
        )?,
        Step { name: "wgpu_embed", program: debug.join("examples").join("wgpu_embed"), args: vec![] },
        Step { name: "ash_embed", program: debug.join("examples").join("ash_embed"), args: vec![] },
        // The xtask the build above made (it may have replaced the running one), on the
        // columns that make Vulkan calls through this machine's loader (`host_vulkan`):
        // the layer sees nothing of the interpreter, wgpu's GL backend or Chromium's WebGPU
        // (its own SwiftShader); with them this step took 66 s (23 s without), the whole
        // command 77 s (33 s) on the 2-core VM, all of it on CI's path.
        // tests/tests/cross_backend.rs checks every column, without the layer.
        Step {
            name: "xtask-check",
            program: debug.join("xtask"),
            args: vec!["check".into(), "--backend".into(), host_vulkan_columns()],
        },
    ];
    // The steps are independent processes, mostly on one core each (pipeline compilation
    // and the layer's own work are single-threaded): one worker per core, the results
    // printed in the steps' order.
    let outcomes = strata_check::parallel::map(&steps, |step| run_step(step, &root, &folder));
    let mut failures = Vec::new();
    let mut notes: BTreeMap<String, usize> = BTreeMap::new();
    for (step, outcome) in steps.iter().zip(outcomes) {
        let outcome = outcome?;
        println!(
            "{:<26} {} ({:.0} s)",
            step.name,
            if outcome.errors.is_empty() {
                "clean".to_string()
            } else {
                format!("{} messages", outcome.errors.values().sum::<usize>())
            },
            outcome.seconds
        );
        for (id, count) in outcome.errors {
            failures.push(format!("{}: {id} x{count} (log: {})", step.name, outcome.log.display()));
        }
        for (id, count) in outcome.notes {
            *notes.entry(id).or_default() += count;
        }
    }
    if !notes.is_empty() {
        println!("best-practices notes and known mistakes of the layer (reported, not asserted):");
        for (id, count) in &notes {
            println!("  {id} x{count}");
        }
    }
    if !failures.is_empty() {
        bail!("the validation layer reported:\n{}", failures.join("\n"));
    }
    println!("no validation error or warning, synchronization validation on, in {} programs", steps.len());
    Ok(())
}

/// What the layer said of one step: its errors and warnings, its best-practices notes
/// and known layer mistakes (by ID, counted), where its log is and how long it ran.
struct Outcome {
    errors: BTreeMap<String, usize>,
    notes: BTreeMap<String, usize>,
    log: PathBuf,
    seconds: f64,
}

/// Runs one step under the layer (its settings file and log in `folder`); an error if
/// the program fails or the layer wrote no log.
fn run_step(step: &Step, root: &Path, folder: &Path) -> Result<Outcome> {
    let started = std::time::Instant::now();
    let log = folder.join(format!("{}.log", step.name));
    let _ = std::fs::remove_file(&log);
    let settings = folder.join(format!("{}.settings.txt", step.name));
    strata_files::write_whole(
        &settings,
        format!(
            "khronos_validation.report_flags = error,warn,perf\n\
             khronos_validation.debug_action = VK_DBG_LAYER_ACTION_LOG_MSG\n\
             khronos_validation.log_filename = {}\n\
             khronos_validation.enables = VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT,\
             VK_VALIDATION_FEATURE_ENABLE_BEST_PRACTICES_EXT\n",
            log.display()
        )
        .as_bytes(),
    )
    .with_context(|| format!("{}: cannot write", settings.display()))?;
    let output = Command::new(&step.program)
        .args(&step.args)
        .current_dir(root)
        .env("VK_INSTANCE_LAYERS", "VK_LAYER_KHRONOS_validation")
        .env("VK_LAYER_SETTINGS_PATH", &settings)
        .output()
        .with_context(|| format!("{}: cannot run {}", step.name, step.program.display()))?;
    if !output.status.success() {
        let stderr = String::from_utf8_lossy(&output.stderr);
        let last = stderr.lines().rev().find(|line| !line.trim().is_empty()).unwrap_or("(nothing on stderr)");
        // The status says a signal too ("signal: 11 (SIGSEGV)"): a crash inside a layer
        // or driver prints nothing of its own.
        bail!("{} failed under the validation layer ({}): {last}", step.name, output.status);
    }
    let text = std::fs::read_to_string(&log).with_context(|| {
        format!("{}: the validation layer wrote no log (is vulkan-validationlayers installed?)", log.display())
    })?;
    let mut outcome =
        Outcome { errors: BTreeMap::new(), notes: BTreeMap::new(), log, seconds: started.elapsed().as_secs_f64() };
    for message in messages(&text) {
        if is_best_practice(&message) {
            *outcome.notes.entry(message.id).or_default() += 1;
        } else if is_known_layer_mistake(&message) {
            *outcome
                .notes
                .entry(format!("{} (the layer's mistake, see KNOWN_LAYER_MISTAKES)", message.id))
                .or_default() += 1;
        } else {
            *outcome.errors.entry(format!("{} ({})", message.id, message.severity)).or_default() += 1;
        }
    }
    Ok(outcome)
}

/// The check's columns whose backends make Vulkan calls through this machine's loader
/// (`BackendSlot::host_vulkan`), as `--backend` takes them.
fn host_vulkan_columns() -> String {
    let slots = strata_check::backend_slots();
    slots.iter().filter(|slot| slot.host_vulkan).map(|slot| slot.name).collect::<Vec<_>>().join(",")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_messages_are_read_with_their_id_and_severity() {
        let log = "SYNC-HAZARD-READ-AFTER-WRITE(ERROR / SPEC): msgNum: -455515022 - Validation Error: [ x ]\n    \
                   detail line\nUNASSIGNED-BestPractices-vkCreateDevice(WARN / PERF): msgNum: 1 - note\n";
        let found = messages(log);
        assert_eq!(found.len(), 2);
        assert_eq!((found[0].id.as_str(), found[0].severity.as_str()), ("SYNC-HAZARD-READ-AFTER-WRITE", "ERROR"));
        assert!(!is_best_practice(&found[0]) && is_best_practice(&found[1]));
        assert!(!is_known_layer_mistake(&found[0]));
        let mistake = messages(
            "UNASSIGNED-CoreValidation-Shader-InconsistentSpirv(ERROR / SPEC): msgNum: 7 - SPIR-V module not valid: \
             Invalid source language operand: 10\n",
        );
        assert!(is_known_layer_mistake(&mistake[0]));
        let other = messages("UNASSIGNED-CoreValidation-Shader-InconsistentSpirv(ERROR / SPEC): msgNum: 7 - other\n");
        assert!(!is_known_layer_mistake(&other[0]));
    }
}
