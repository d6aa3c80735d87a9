//! Records the git revision the `strata` binary is built from (`STRATA_GIT_REVISION`,
//! read by `evaluation::record`), so every `run.json` says which code made it. Outside a
//! git checkout, or without git, it is "unknown". It is HEAD at build time: edits not
//! yet committed do not show (tracking them would rebuild the crate on every change).

use std::process::Command;

fn main() {
    let git = |args: &[&str]| -> Option<String> {
        let output = Command::new("git").args(args).output().ok()?;
        output.status.success().then(|| String::from_utf8_lossy(&output.stdout).trim().to_string())
    };
    let revision = match git(&["rev-parse", "--short=12", "HEAD"]) {
        Some(hash) if !hash.is_empty() => hash,
        _ => "unknown".to_string(),
    };
    println!("cargo:rustc-env=STRATA_GIT_REVISION={revision}");
    // Rebuild when HEAD moves (a commit, a checkout).
    if let Some(dir) = git(&["rev-parse", "--git-dir"]) {
        for file in ["HEAD", "logs/HEAD"] {
            println!("cargo:rerun-if-changed={dir}/{file}");
        }
    }
    println!("cargo:rerun-if-changed=build.rs");
}
