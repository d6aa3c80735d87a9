//! The folder a `strata compare` run writes into, kept to one run at a time. A run takes
//! the folder's lock file first (a second run while it is held is refused, naming the
//! process); then the files an earlier run wrote there (recognised by name:
//! [`is_run_output`]) and temporary files a killed run left are removed, so an old
//! run's images never sit beside a new run's CSV. Files with other names are left alone,
//! and so is the reference image the new run reads, wherever it lies.

use anyhow::{Context, Result, bail};
use std::path::{Path, PathBuf};

/// The lock file's name in the folder.
pub const LOCK_NAME: &str = ".strata-compare.lock";

/// The folder's lock, held while a run writes into it; dropping it removes the lock file.
#[derive(Debug)]
pub struct FolderLock {
    path: PathBuf,
}

impl Drop for FolderLock {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.path);
    }
}

/// Takes `folder`'s lock, or says which run holds it. A lock whose process has ended
/// (a killed run) is taken over.
pub fn lock(folder: &Path) -> Result<FolderLock> {
    let path = folder.join(LOCK_NAME);
    for _ in 0..2 {
        match std::fs::OpenOptions::new().write(true).create_new(true).open(&path) {
            Ok(mut file) => {
                use std::io::Write;
                file.write_all(std::process::id().to_string().as_bytes())
                    .with_context(|| format!("{}: cannot write the lock", path.display()))?;
                return Ok(FolderLock { path });
            }
            Err(error) if error.kind() == std::io::ErrorKind::AlreadyExists => {
                let holder = std::fs::read_to_string(&path).ok().and_then(|t| t.trim().parse::<u32>().ok());
                match holder {
                    Some(pid) if crate::atomic_file::process_is_running(pid) => bail!(
                        "{}: another strata compare (process {pid}) is writing into this folder; wait for it or \
                         choose another --out (if no such run is going on, remove {})",
                        folder.display(),
                        path.display()
                    ),
                    // A run that was killed, or a lock half-written: take it over.
                    _ => std::fs::remove_file(&path)
                        .with_context(|| format!("{}: cannot remove a stale lock", path.display()))?,
                }
            }
            Err(error) => return Err(error).with_context(|| format!("{}: cannot create the lock", path.display())),
        }
    }
    bail!("{}: the lock keeps being taken by other runs", folder.display())
}

/// Whether `name` is a file a comparison run writes: the CSVs, the summary, the record,
/// the report page and its plots and colour bar, the reference and every method's frame
/// images and error maps.
pub fn is_run_output(name: &str) -> bool {
    const FIXED: [&str; 9] = [
        "errors.csv",
        "errors_denoised.csv",
        "errors_accumulated.csv",
        "errors_temporal.csv",
        "variance.csv",
        "summary.txt",
        "run.json",
        "report.html",
        "relmse_colourbar.png",
    ];
    if FIXED.contains(&name) {
        return true;
    }
    let Some((stem, extension)) = name.rsplit_once('.') else { return false };
    let image = matches!(extension, "png" | "exr" | "svg");
    if !image {
        return false;
    }
    if stem == "relmse" || stem == "relmse_ratio" || stem == "reference" {
        return true;
    }
    // reference_frameNNN, METHOD_frameNNN, METHOD_frameNNN_relmse, and the same of
    // METHOD_denoised.
    let stem = stem.strip_suffix("_relmse").unwrap_or(stem);
    let Some((prefix, frame)) = stem.rsplit_once("_frame") else { return false };
    let prefix = prefix.strip_suffix("_denoised").unwrap_or(prefix);
    let methods = ["reference", "strata", "restir", "restir-disc"];
    methods.contains(&prefix) && !frame.is_empty() && frame.bytes().all(|b| b.is_ascii_digit())
}

/// Creates `folder` if needed, takes its [`lock`] and removes the files an earlier run
/// wrote there and temporary files a killed run left ([`crate::atomic_file`]), except
/// `keep` (the reference this run reads, which may be an earlier run's `reference.exr`).
/// Returns the lock, to hold until the run has written everything, and the names removed.
///
/// Everything is checked before anything is removed: an entry under a name the run
/// writes that is not a regular file (the writer would refuse it at the end), or that is
/// an input of this run (a scene, mesh, texture or camera path named `run.json`,
/// `summary.txt`, ...: removing it and writing the run's file there would destroy it), is
/// refused while the earlier run's files are all still there.
pub fn prepare(folder: &Path, keep: Option<&Path>) -> Result<(FolderLock, Vec<String>)> {
    std::fs::create_dir_all(folder).with_context(|| format!("{}: cannot create the folder", folder.display()))?;
    let lock = lock(folder)?;
    let keep: Option<PathBuf> = keep.and_then(|k| k.canonicalize().ok());
    let mut doomed = Vec::new();
    let entries = std::fs::read_dir(folder).with_context(|| format!("{}: cannot list the folder", folder.display()))?;
    for entry in entries {
        let entry = entry.with_context(|| format!("{}: cannot list the folder", folder.display()))?;
        let name = entry.file_name().to_string_lossy().into_owned();
        let path = entry.path();
        let output = is_run_output(&name);
        let temporary = crate::atomic_file::is_temporary(&name);
        if !(output || temporary) || (temporary && !crate::atomic_file::is_left_over(&name)) {
            continue;
        }
        let regular = entry.file_type().is_ok_and(|t| t.is_file());
        let kept = regular && keep.is_some() && path.canonicalize().ok() == keep;
        if kept && name == "reference.exr" {
            // The run reads it and, given a reference, writes no file of that name.
            continue;
        }
        if kept {
            bail!(
                "--reference {}: this run writes a file of that name into --out {}; copy the reference elsewhere                  or choose another --out",
                path.display(),
                folder.display()
            );
        }
        if output {
            crate::atomic_file::check_target(&path)?;
        }
        if regular {
            doomed.push((name, path));
        }
    }
    let mut removed = Vec::new();
    for (name, path) in doomed {
        std::fs::remove_file(&path)
            .with_context(|| format!("{}: cannot remove this file of an earlier run", path.display()))?;
        removed.push(name);
    }
    removed.sort();
    Ok((lock, removed))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn run_outputs_are_recognised_by_name() {
        for name in [
            "errors.csv",
            "report.html",
            "run.json",
            "relmse.svg",
            "relmse_ratio.png",
            "reference.exr",
            "reference_frame003.exr",
            "strata_frame001.png",
            "restir-disc_frame032_relmse.exr",
        ] {
            assert!(is_run_output(name), "{name}");
        }
        for name in [
            "notes.txt",
            "my_reference.exr",
            "strata_frame.png",
            "strata_frame01a.png",
            "scene.json",
            "other_frame001.png",
        ] {
            assert!(!is_run_output(name), "{name}");
        }
    }

    #[test]
    fn an_earlier_runs_files_go_and_the_rest_stays() {
        let folder = std::env::temp_dir().join(format!("strata-output-folder-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&folder);
        std::fs::create_dir_all(&folder).unwrap();
        // A temporary of a process that has ended (a killed run's) goes; one of a process
        // still running (a render writing into the folder now) stays.
        let ended = strata_backends::processes::an_ended_process();
        let mut running = std::process::Command::new("sleep").arg("60").spawn().unwrap();
        let (dead, alive) = (format!(".relmse.tmp-{ended}.png"), format!(".default.tmp-{}.exr", running.id()));
        for name in ["errors.csv", "strata_frame001.png", "notes.txt", "reference.exr", &dead, &alive] {
            std::fs::write(folder.join(name), b"x").unwrap();
        }
        let (lock, removed) = prepare(&folder, Some(&folder.join("reference.exr"))).unwrap();
        let _ = running.kill();
        let _ = running.wait();
        assert_eq!(removed, [dead.as_str(), "errors.csv", "strata_frame001.png"]);
        assert!(folder.join("notes.txt").exists() && folder.join("reference.exr").exists());
        assert!(folder.join(&alive).exists());
        std::fs::remove_file(folder.join(&alive)).unwrap();
        // While the lock is held a second run is refused, naming this process.
        let refused = prepare(&folder, None).unwrap_err().to_string();
        assert!(refused.contains(&format!("process {}", std::process::id())), "{refused}");
        drop(lock);
        assert!(!folder.join(LOCK_NAME).exists());
        // A lock left by a process that has ended is taken over.
        std::fs::write(folder.join(LOCK_NAME), u32::MAX.to_string()).unwrap();
        let (_lock, removed) = prepare(&folder, None).unwrap();
        assert_eq!(removed, ["reference.exr"]);
        drop(_lock);
        std::fs::remove_dir_all(&folder).unwrap();
    }

    /// An input of the run under a name the run writes, or a link there, is refused
    /// before any earlier file is removed.
    #[test]
    fn nothing_is_removed_when_an_entry_would_be_refused() {
        let folder = std::env::temp_dir().join(format!("strata-output-folder-refused-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&folder);
        std::fs::create_dir_all(&folder).unwrap();
        for name in ["errors.csv", "report.html", "summary.txt", "strata_frame001.exr"] {
            std::fs::write(folder.join(name), b"x").unwrap();
        }
        // A scene file named like the run's record, read as an input.
        std::fs::write(folder.join("run.json"), b"{}").unwrap();
        crate::atomic_file::note_input(&folder.join("run.json"));
        let refused = prepare(&folder, None).unwrap_err().to_string();
        assert!(refused.contains("run.json") && refused.contains("input"), "{refused}");
        // A reference named like a frame the run writes.
        std::fs::remove_file(folder.join("run.json")).unwrap();
        let refused = prepare(&folder, Some(&folder.join("strata_frame001.exr"))).unwrap_err().to_string();
        assert!(refused.contains("--reference"), "{refused}");
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink("/nonexistent", folder.join("variance.csv")).unwrap();
            let refused = prepare(&folder, None).unwrap_err().to_string();
            assert!(refused.contains("symbolic link"), "{refused}");
            std::fs::remove_file(folder.join("variance.csv")).unwrap();
        }
        for name in ["errors.csv", "report.html", "summary.txt", "strata_frame001.exr"] {
            assert!(folder.join(name).exists(), "{name} was removed by a refused run");
        }
        std::fs::remove_dir_all(&folder).unwrap();
    }
}
