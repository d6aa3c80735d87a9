//! The folder a `strata compare` run writes into, kept to one run at a time. A run takes
//! the folder's lock file first (a second run while it is held is refused, naming the
//! process); then the files an earlier run wrote there and temporary files a killed run
//! left are removed, so an old run's images never sit beside a new run's CSV.
//!
//! Which files are an earlier run's is read from the folder's record ([`RECORD_NAME`]):
//! every run appends the name of each file to it before the file appears
//! ([`strata_render::atomic_file::record_outputs`]), so a killed run's files are listed too. A
//! name alone proves nothing: a user's own `variance.csv` or `strata_frame042.png` in the
//! folder is never removed. Where such a file has a name this run may write, the run is
//! refused before anything is removed (it would replace it at the end), naming the file.
//! The reference the new run reads is kept, wherever it lies.

use anyhow::{Context, Result, bail};
use std::path::{Path, PathBuf};
use strata_render::restir::Method;

/// The lock file's name in the folder.
pub const LOCK_NAME: &str = ".strata-compare.lock";

/// The record of the files runs wrote into the folder, one name a line.
pub const RECORD_NAME: &str = ".strata-compare.files";

/// The most bytes read from the lock file (a process id) and from the record.
const LOCK_BYTES: u64 = 64;
const RECORD_BYTES: u64 = 16 << 20;

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
                // Read as a regular file of a few bytes only: a link, a named pipe or a
                // device at the lock's name is neither followed nor waited on.
                let holder = match strata_files::read_regular_capped(&path, LOCK_BYTES) {
                    Ok(bytes) => String::from_utf8(bytes).ok().and_then(|t| t.trim().parse::<u32>().ok()),
                    Err(strata_files::ReadError::NotRegular { .. }) => bail!(
                        "{}: is not a regular file; strata compare neither follows nor removes it: remove it \
                         yourself, or choose another --out",
                        path.display()
                    ),
                    Err(_) => None,
                };
                match holder {
                    Some(pid) if strata_render::atomic_file::process_is_running(pid) && may_be_strata(pid) => bail!(
                        "{}: another strata compare (process {pid}) is writing into this folder; wait for it or \
                         choose another --out (if no such run is going on, remove {})",
                        folder.display(),
                        path.display()
                    ),
                    // A run that was killed, a lock half-written, or a lock whose process id
                    // now belongs to another program (ids are reused): take it over.
                    _ => std::fs::remove_file(&path)
                        .with_context(|| format!("{}: cannot remove a stale lock", path.display()))?,
                }
            }
            Err(error) => return Err(error).with_context(|| format!("{}: cannot create the lock", path.display())),
        }
    }
    bail!("{}: the lock keeps being taken by other runs", folder.display())
}

/// Whether the running process `pid` may be a `strata compare`: its name (Linux's
/// `/proc/PID/comm`) starts with `strata` (the binary, or a test binary of this crate),
/// or cannot be read (then it is taken for one, so a live run is never taken over). A
/// lock whose process id a later, unrelated program got is stale, not "another strata
/// compare".
fn may_be_strata(pid: u32) -> bool {
    match std::fs::read_to_string(format!("/proc/{pid}/comm")) {
        Ok(name) => name.trim_end().starts_with("strata"),
        Err(_) => true,
    }
}

/// Whether `name` is a file a comparison run writes: the CSVs, the summary, the record,
/// the report page and its plots and colour bar, the reference and every method's frame
/// images and error maps.
pub fn is_run_output(name: &str) -> bool {
    const FIXED: [&str; 10] = [
        "errors.csv",
        "viewer.csv",
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
    // The viewer's figures: viewer_correlation_STAGE and viewer_spectrum_STAGE.
    if let Some(stage) = stem.strip_prefix("viewer_correlation_").or_else(|| stem.strip_prefix("viewer_spectrum_")) {
        return matches!(stage, "raw" | "denoised");
    }
    // reference_frameNNN, METHOD_frameNNN, METHOD_frameNNN_relmse, and the same of
    // METHOD_denoised.
    let stem = stem.strip_suffix("_relmse").unwrap_or(stem);
    let Some((prefix, frame)) = stem.rsplit_once("_frame") else { return false };
    let prefix = prefix.strip_suffix("_denoised").unwrap_or(prefix);
    let method = Method::BASELINES.iter().chain([&Method::Strata]).any(|m| m.name() == prefix);
    (prefix == "reference" || method) && !frame.is_empty() && frame.bytes().all(|b| b.is_ascii_digit())
}

/// The names the folder's record lists ([`RECORD_NAME`]): plain file names only (no
/// folder part, not hidden); none if there is no record. A record that is not a regular
/// file, or too large, is an error naming it.
fn recorded(folder: &Path) -> Result<std::collections::BTreeSet<String>> {
    let path = folder.join(RECORD_NAME);
    let bytes = match strata_files::read_regular_capped(&path, RECORD_BYTES) {
        Ok(bytes) => bytes,
        Err(strata_files::ReadError::Missing { .. }) => return Ok(Default::default()),
        Err(error) => bail!("{error}; remove it yourself, or choose another --out"),
    };
    Ok(String::from_utf8_lossy(&bytes)
        .lines()
        .filter(|name| !name.is_empty() && !name.starts_with('.') && !name.contains(['/', '\\']))
        .map(str::to_string)
        .collect())
}

/// Creates `folder` if needed, takes its [`lock`] and removes the files an earlier run
/// recorded there ([`RECORD_NAME`]) and temporary files a killed run left
/// ([`strata_render::atomic_file`]), except `keep` (the reference this run reads, which may be an
/// earlier run's `reference.exr`). Then starts this run's record
/// ([`strata_render::atomic_file::record_outputs`]). Returns the lock, to hold until the run has
/// written everything, and the names removed.
///
/// Everything is checked before anything is removed: a file under a name the run writes
/// that no earlier run recorded (a user's own), an entry under such a name that is not a
/// regular file (the writer would refuse it at the end), or one that is an input of this
/// run (a scene, mesh, texture or camera path named `run.json`, `summary.txt`, ...:
/// removing it and writing the run's file there would destroy it), is refused while the
/// earlier run's files are all still there.
pub fn prepare(folder: &Path, keep: Option<&Path>) -> Result<(FolderLock, Vec<String>)> {
    std::fs::create_dir_all(folder).with_context(|| format!("{}: cannot create the folder", folder.display()))?;
    let lock = lock(folder)?;
    let recorded = recorded(folder)?;
    let keep: Option<PathBuf> = keep.and_then(|k| k.canonicalize().ok());
    let mut doomed = Vec::new();
    let mut kept_names = Vec::new();
    let entries = std::fs::read_dir(folder).with_context(|| format!("{}: cannot list the folder", folder.display()))?;
    for entry in entries {
        let entry = entry.with_context(|| format!("{}: cannot list the folder", folder.display()))?;
        let name = entry.file_name().to_string_lossy().into_owned();
        let path = entry.path();
        let output = is_run_output(&name);
        let earlier = recorded.contains(&name);
        let temporary = strata_render::atomic_file::is_temporary(&name);
        if !(output || earlier || temporary) || (temporary && !strata_render::atomic_file::is_left_over(&name)) {
            continue;
        }
        let regular = entry.file_type().is_ok_and(|t| t.is_file());
        let kept = regular && keep.is_some() && path.canonicalize().ok() == keep;
        if kept && name == "reference.exr" {
            // The run reads it and, given a reference, writes no file of that name.
            if earlier {
                kept_names.push(name);
            }
            continue;
        }
        if kept {
            bail!(
                "--reference {}: this run writes a file of that name into --out {}; copy the reference elsewhere \
                 or choose another --out",
                path.display(),
                folder.display()
            );
        }
        if output {
            strata_render::atomic_file::check_target(&path)?;
            if regular && !earlier && !temporary {
                bail!(
                    "{}: no earlier strata compare recorded writing this file (in {}), and this run may write a file \
                     of that name: strata compare neither removes nor replaces a file it did not write; move it, or \
                     choose another --out",
                    path.display(),
                    RECORD_NAME
                );
            }
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
    // The new record starts with what was kept of the earlier one.
    let record = folder.join(RECORD_NAME);
    let text: String = kept_names.iter().map(|name| format!("{name}\n")).collect();
    strata_render::atomic_file::write(&record, text)?;
    strata_render::atomic_file::record_outputs(folder, &record);
    Ok((lock, removed))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A new empty folder of a random name (the test removes it).
    fn scratch(name: &str) -> PathBuf {
        strata_files::private_scratch_folder(&format!("strata-output-folder-{name}-")).unwrap().keep()
    }

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
            "viewer_correlation_raw.svg",
            "viewer_correlation_denoised.png",
            "viewer_spectrum_raw.png",
            "viewer_spectrum_denoised.svg",
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
            "viewer_spectrum_other.png",
            "viewer_correlation_raw.csv",
        ] {
            assert!(!is_run_output(name), "{name}");
        }
    }

    #[test]
    fn an_earlier_runs_files_go_and_the_rest_stays() {
        let folder = scratch("earlier");
        // A temporary of a process that has ended (a killed run's) goes; one of a process
        // still running (a render writing into the folder now) stays.
        let ended = strata_backends::processes::an_ended_process();
        let mut running = std::process::Command::new("sleep").arg("60").spawn().unwrap();
        let (dead, alive) = (format!(".relmse.tmp-{ended}.png"), format!(".default.tmp-{}.exr", running.id()));
        for name in ["errors.csv", "strata_frame001.png", "notes.txt", "reference.exr", &dead, &alive] {
            std::fs::write(folder.join(name), b"x").unwrap();
        }
        std::fs::write(folder.join(RECORD_NAME), "errors.csv\nstrata_frame001.png\nreference.exr\n../escape\n")
            .unwrap();
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
        // A lock whose process id belongs to another program now (`sleep`) is stale.
        let mut other = std::process::Command::new("sleep").arg("60").spawn().unwrap();
        std::fs::write(folder.join(LOCK_NAME), other.id().to_string()).unwrap();
        let taken = prepare(&folder, None);
        let _ = other.kill();
        let _ = other.wait();
        let (lock, removed) = taken.expect("a lock held by `sleep` is not another strata compare's");
        assert_eq!(removed, ["reference.exr"]);
        drop(lock);
        // A lock left by a process that has ended is taken over.
        std::fs::write(folder.join(LOCK_NAME), u32::MAX.to_string()).unwrap();
        let (_lock, removed) = prepare(&folder, None).unwrap();
        assert!(removed.is_empty(), "{removed:?}");
        drop(_lock);
        std::fs::remove_dir_all(&folder).unwrap();
    }

    /// Security finding 6: `prepare` once removed every file whose name looked like a
    /// run's output, so a user's own `variance.csv` or `strata_frame042.png` in `--out` was
    /// deleted. Only recorded files go; an unrecorded one under an output's name refuses
    /// the run before anything is removed; other names are never touched.
    #[test]
    fn a_users_files_are_never_removed() {
        let folder = scratch("user");
        for name in ["errors.csv", "variance.csv", "strata_frame042.png", "notes.txt"] {
            std::fs::write(folder.join(name), b"the user's").unwrap();
        }
        std::fs::write(folder.join(RECORD_NAME), "errors.csv\n").unwrap();
        let refused = prepare(&folder, None).unwrap_err().to_string();
        assert!(refused.contains("did not write"), "{refused}");
        for name in ["errors.csv", "variance.csv", "strata_frame042.png", "notes.txt"] {
            assert_eq!(std::fs::read(folder.join(name)).unwrap(), b"the user's", "{name}");
        }
        std::fs::remove_file(folder.join("variance.csv")).unwrap();
        std::fs::remove_file(folder.join("strata_frame042.png")).unwrap();
        let (_lock, removed) = prepare(&folder, None).unwrap();
        assert_eq!(removed, ["errors.csv"]);
        assert_eq!(std::fs::read(folder.join("notes.txt")).unwrap(), b"the user's");
        drop(_lock);
        std::fs::remove_dir_all(&folder).unwrap();
    }

    /// Security finding 9: the lock file was read through links and named pipes (a FIFO
    /// there hung `strata compare`).
    #[cfg(unix)]
    #[test]
    fn a_pipe_or_link_at_the_locks_name_is_refused_at_once() {
        let folder = scratch("lock");
        let fifo = folder.join(LOCK_NAME);
        let name = std::ffi::CString::new(fifo.as_os_str().as_encoded_bytes()).unwrap();
        // SAFETY: a valid NUL-terminated path; mkfifo only creates the entry.
        assert_eq!(unsafe { libc::mkfifo(name.as_ptr(), 0o600) }, 0);
        let (sender, receiver) = std::sync::mpsc::channel();
        let inside = folder.clone();
        std::thread::spawn(move || sender.send(lock(&inside).map(drop).map_err(|e| e.to_string())).unwrap());
        let refused = receiver.recv_timeout(std::time::Duration::from_secs(10)).expect("the lock's pipe hung");
        assert!(refused.unwrap_err().contains("not a regular file"));
        std::fs::remove_file(&fifo).unwrap();
        std::os::unix::fs::symlink("/dev/zero", &fifo).unwrap();
        assert!(lock(&folder).unwrap_err().to_string().contains("not a regular file"));
        std::fs::remove_dir_all(&folder).unwrap();
    }

    /// An input of the run under a name the run writes, or a link there, is refused
    /// before any earlier file is removed.
    #[test]
    fn nothing_is_removed_when_an_entry_would_be_refused() {
        let folder = scratch("refused");
        for name in ["errors.csv", "report.html", "summary.txt", "strata_frame001.exr"] {
            std::fs::write(folder.join(name), b"x").unwrap();
        }
        let record = "errors.csv\nreport.html\nsummary.txt\nstrata_frame001.exr\nrun.json\nvariance.csv\n";
        std::fs::write(folder.join(RECORD_NAME), record).unwrap();
        // A scene file named like the run's record, read as an input.
        std::fs::write(folder.join("run.json"), b"{}").unwrap();
        strata_render::atomic_file::note_input(&folder.join("run.json"));
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
