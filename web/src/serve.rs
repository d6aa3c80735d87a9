//! Building the page's WebAssembly module and gathering the page's files: what `cargo
//! xtask web` serves and what the page's test loads (native only).

use crate::live::{LiveSettings, REFERENCE_SAMPLES, reference_bytes};
use std::path::{Path, PathBuf};
use std::process::Command;
use strata_render::rgb_image::RgbImage;

/// The target folder of the module's build, below the workspace's `target/`: a folder of
/// its own, so that a build started while another cargo holds `target/` (the page's test
/// runs inside `cargo test`) waits for nobody.
pub const MODULE_TARGET_DIR: &str = "target/web";

/// The command that builds the module, as [`build_module`] runs it in the workspace's
/// root (CI runs the same one early, in the background). Debug build without debug info,
/// and unoptimised: the workspace's debug profile optimises the dependencies (opt-level 1)
/// and the interpreter (2) for the native tests, which the page does not run; the page's
/// host work is light (the frame's time is the GPU's), and the module compiles in 78
/// CPU-s instead of 141 on the 2-core VM (docs/benchmarks/ci-time.md). Warnings in
/// strata-web are errors here: its wasm32-only code is outside the workspace's (native)
/// clippy step.
pub const BUILD_COMMAND: [&str; 17] = [
    "rustc",
    "--quiet",
    "--package",
    "strata-web",
    "--target",
    "wasm32-unknown-unknown",
    "--crate-type",
    "cdylib",
    "--target-dir",
    MODULE_TARGET_DIR,
    "--config",
    "profile.dev.package.\"*\".opt-level=0",
    "--config",
    "profile.dev.package.strata-backends.opt-level=0",
    "--",
    "-D",
    "warnings",
];

/// Builds the module (cargo with [`BUILD_COMMAND`] in `workspace`, the repository's root)
/// and returns its path. The error says what is missing: the wasm32 target first of all.
pub fn build_module(workspace: &Path) -> Result<PathBuf, String> {
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let output = Command::new(&cargo)
        .current_dir(workspace)
        .args(BUILD_COMMAND)
        .env("CARGO_PROFILE_DEV_DEBUG", "0")
        .output()
        .map_err(|e| format!("cannot run cargo ({}): {e}", Path::new(&cargo).display()))?;
    if !output.status.success() {
        let stderr = String::from_utf8_lossy(&output.stderr);
        if stderr.contains("wasm32-unknown-unknown") && stderr.contains("target may not be installed") {
            return Err("the wasm32 target is not installed: rustup target add wasm32-unknown-unknown".into());
        }
        // The first error is the cause; the last is cargo's "could not compile".
        let first = stderr.lines().find(|l| l.starts_with("error")).unwrap_or("no message");
        return Err(format!("building the page's module failed: {first}"));
    }
    let module = workspace.join(MODULE_TARGET_DIR).join("wasm32-unknown-unknown/debug/strata_web.wasm");
    if module.is_file() { Ok(module) } else { Err(format!("{}: not built", module.display())) }
}

/// Every file of the page, by its path below the page's folder: the page's own
/// ([`crate::PAGE_FILES`]), the executor, the module, the reference and `page.json`
/// (the settings and the reference's samples).
pub fn page_files(module: Vec<u8>, settings: &LiveSettings, reference: &RgbImage) -> Vec<(String, Vec<u8>)> {
    let mut config = settings.to_json();
    config["referenceSamples"] = REFERENCE_SAMPLES.into();
    let mut files: Vec<(String, Vec<u8>)> =
        crate::PAGE_FILES.iter().map(|(name, text)| (name.to_string(), text.as_bytes().to_vec())).collect();
    files.push(("executor.js".into(), strata_backends::webgpu_backend::EXECUTOR_JS.as_bytes().to_vec()));
    files.push(("strata_web.wasm".into(), module));
    files.push(("reference.bin".into(), reference_bytes(reference)));
    files.push(("page.json".into(), config.to_string().into_bytes()));
    files
}

#[cfg(test)]
mod tests {
    use super::BUILD_COMMAND;

    /// CI builds the module early, in the background, with the same command, so that the
    /// page's test finds it built: a command that drifted apart would build it twice (the
    /// second time inside the tests, about 80 CPU-s on CI's 2 cores).
    #[test]
    fn ci_builds_the_module_with_the_same_command() {
        let run = concat!(env!("CARGO_MANIFEST_DIR"), "/../.ci/run");
        let script = std::fs::read_to_string(run).unwrap_or_else(|e| panic!("{run}: {e}"));
        let joined = script.replace("\\\n", " ");
        let line = joined
            .lines()
            .find(|line| line.contains("cargo rustc") && line.contains("strata-web"))
            .unwrap_or_else(|| panic!("{run}: no `cargo rustc` of strata-web"));
        let command = &line[line.find("cargo rustc").unwrap()..line.find('>').unwrap_or(line.len())];
        let words: Vec<&str> = command.split_whitespace().skip(1).map(|word| word.trim_matches('\'')).collect();
        assert_eq!(words, BUILD_COMMAND, "{run} builds the page's module otherwise than serve::BUILD_COMMAND");
    }
}
