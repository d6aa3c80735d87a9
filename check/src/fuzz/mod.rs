//! The loaders' fuzz harness (`cargo xtask fuzz`, and a short fixed-seed run under
//! `cargo test`): a structure-aware mutation fuzzer on the stable toolchain, one target
//! per loader:
//!
//! | target | loader |
//! |---|---|
//! | `scene-json` | `scene::load_scene_from` on a scene description (its meshes, texture and environment in memory) |
//! | `ply` | `scene::parse_ply` |
//! | `gltf` | `scene::load_gltf_from` on `.gltf` JSON and `.glb` containers |
//! | `obj` | `scene::load_obj_from` on an OBJ and its MTL library |
//! | `exr` | `scene::Environment::from_exr_bytes` and `rgb_image::RgbImage::read_exr` (references) |
//! | `errors-csv` | `evaluation::compare::parse_errors_csv` of the host crate, handed in ([`Readers`]) |
//!
//! Each target starts from small valid files written in code ([`build`]) plus, when the
//! shared scenes are beside the checkout, their small real files; inputs are mutated byte
//! by byte ([`mutate`]), structurally (JSON values, PLY header counts, glTF accessor
//! fields, EXR header attributes: [`json`] and the targets' own), or generated afresh from
//! random bytes through `arbitrary`. Every input runs under `catch_unwind` with a panic
//! hook that also sees the panics a loader contains itself; a watchdog thread calls an
//! input that runs over the limit (2 s) a hang, and [`GuardedAllocator`] calls one
//! allocation over the limit (1 GiB) a finding. A loaded scene must also pass
//! [`oracle::check_scene`] (no NaN, infinite or negative number where the renderer needs
//! a finite one). Inputs that produce an outcome not seen before (an error message with its
//! values blurred, [`engine::outcome_kind`]) join the corpus; their count is the
//! campaign's rough coverage figure. A campaign is deterministic from its seed.

mod alloc;
pub mod build;
pub mod engine;
pub mod json;
pub mod mutate;
pub mod oracle;
mod targets;

pub use alloc::{GuardedAllocator, set_allocation_limit};
pub use engine::{Campaign, CampaignReport, Finding, Verdict, execute, run_campaign};
pub use mutate::FuzzRng;

use std::path::{Path, PathBuf};

/// What a target says about one input.
#[derive(Clone, Debug, PartialEq)]
pub enum Outcome {
    /// The loader accepted it and the result is sound.
    Accepted,
    /// The loader accepted it, with a remark worth counting as its own outcome (a value
    /// that a loader outside this harness's reach lets through, such as a NaN pixel of a
    /// reference image).
    Noted(String),
    /// The loader refused it with this message (the expected answer to a bad file).
    Refused(String),
    /// The loader accepted it but the result breaks an invariant (a NaN radiance...).
    Bug(String),
}

/// One fuzz target: a loader, its seeds, its generator and its structure-aware mutations.
pub trait Target: Send + Sync {
    /// Name on the command line and folder of its findings, e.g. `ply`.
    fn name(&self) -> &'static str;
    /// Valid inputs written in code, plus the small real files under `shared` (the shared
    /// scenes' folder) when given and present.
    fn seeds(&self, shared: Option<&Path>) -> Vec<Vec<u8>>;
    /// An input built from random bytes (structure chosen by `arbitrary`).
    fn generate(&self, u: &mut arbitrary::Unstructured) -> arbitrary::Result<Vec<u8>>;
    /// One structure-aware mutation of `input`; `None` when it does not apply (the engine
    /// then mutates bytes).
    fn mutate(&self, rng: &mut FuzzRng, input: &[u8]) -> Option<Vec<u8>>;
    /// Runs the loader on `input`.
    fn execute(&self, input: &[u8]) -> Outcome;
}

/// The readers the harness fuzzes but does not link: the evaluation's, in the host crate
/// `strata`, which stands beside this crate on strata-render, not below it. The program
/// that runs the campaigns hands them in (`cargo xtask fuzz`, the `fuzz_regressions`
/// test).
#[derive(Clone, Copy, Debug)]
pub struct Readers {
    /// `errors.csv` as `strata plot` reads it (`strata::evaluation::compare::parse_errors_csv`):
    /// each accepted row's RelMSE, pRelMSE, MSE and luminance RelMSE (0 when the file has
    /// none).
    pub errors_csv: fn(&str) -> Result<Vec<[f64; 4]>, String>,
}

/// Every target, in a fixed order: strata-render's loaders, then `readers`.
pub fn targets(readers: Readers) -> Vec<Box<dyn Target>> {
    targets::all(readers)
}

/// The folder of committed findings: `tests/data/fuzz` of the workspace.
pub fn findings_folder() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/data/fuzz")
}

/// The test scenes committed in the repository (`scenes/`, copies of the shared scenes
/// with their licences), if the checkout has them.
pub fn shared_scenes() -> Option<PathBuf> {
    let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes");
    folder.is_dir().then_some(folder)
}

/// Runs every committed finding under `folder` (`<target>/<file>`) through its target
/// again: each file with the verdict it gets now, a run over `hang_after` being a crash
/// (its thread is left behind). A file in a folder that names no target is an error.
pub fn replay_findings(
    folder: &Path,
    readers: Readers,
    hang_after: std::time::Duration,
) -> Result<Vec<(PathBuf, Verdict)>, String> {
    let targets = targets(readers);
    let mut results = Vec::new();
    let Ok(entries) = std::fs::read_dir(folder) else { return Ok(results) };
    let mut folders: Vec<PathBuf> = entries.filter_map(Result::ok).map(|e| e.path()).filter(|p| p.is_dir()).collect();
    folders.sort();
    for target_folder in folders {
        let name = target_folder.file_name().and_then(|n| n.to_str()).unwrap_or_default().to_string();
        if !targets.iter().any(|t| t.name() == name) {
            return Err(format!("{}: no fuzz target named `{name}`", target_folder.display()));
        }
        let mut files: Vec<PathBuf> = std::fs::read_dir(&target_folder)
            .map_err(|e| format!("{}: {e}", target_folder.display()))?
            .filter_map(Result::ok)
            .map(|e| e.path())
            .filter(|p| p.is_file())
            .collect();
        files.sort();
        for file in files {
            let input = std::fs::read(&file).map_err(|e| format!("{}: {e}", file.display()))?;
            let target = targets::all(readers).into_iter().find(|t| t.name() == name).expect("the same targets");
            let (sender, receiver) = std::sync::mpsc::channel();
            std::thread::spawn(move || sender.send(execute(target.as_ref(), &input)));
            let verdict = receiver.recv_timeout(hang_after).unwrap_or_else(|_| Verdict::Crash {
                signature: "hang".into(),
                message: format!("still running after {} s", hang_after.as_secs_f64()),
            });
            results.push((file, verdict));
        }
    }
    Ok(results)
}
