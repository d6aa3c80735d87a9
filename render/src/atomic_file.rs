//! Output files that are either complete or absent: strata's one writer of files.
//!
//! Every encoder (EXR, PNG, CSV, SVG, JSON, HTML) makes its bytes in memory; [`write()`]
//! then puts them on the disk under a hidden temporary name in the same folder
//! (`.NAME.tmp-PID.EXT`), forces them to the device (`fsync`, which is where a full disk
//! or a failing device says so for data a write call had accepted into the page cache),
//! checks that the file holds every byte, and only then renames it into place, which
//! POSIX makes atomic within one file system. So:
//! - a run killed while writing leaves at most a hidden temporary file, never a truncated
//!   EXR, PNG or CSV under the final name that looks valid; the next write of that name
//!   removes the temporaries that processes no longer running left for it
//!   ([`remove_dead_temporaries`]), and `strata compare` clears a whole folder's
//!   ([`is_temporary`]);
//! - a full disk is an error naming the file, never a 0-byte file reported as written;
//! - the target must be a regular file or absent: a rename would silently replace a
//!   device node (`/dev/full`), a folder's entry of another kind or a symbolic link with
//!   a regular file, so those are refused before anything is written;
//! - the target must not be a file the process read as an input ([`note_input`], which
//!   every loader's read calls): an error map, a frame or a render never replaces a
//!   reference, a texture or an environment map of the same name.

use std::io::Write;
use std::path::{Path, PathBuf};

/// The hidden temporary name `path` is written under before the rename.
pub fn temporary_path(path: &Path) -> PathBuf {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let (prefix, suffix) = temporary_affixes(&name);
    path.with_file_name(format!("{prefix}{}{suffix}", std::process::id()))
}

/// Whether a file name is one of [`temporary_path`]'s (of any process).
pub fn is_temporary(name: &str) -> bool {
    name.starts_with('.') && name.contains(".tmp-")
}

/// Whether temporary file `name` ([`is_temporary`]) may be removed: its writer, named
/// after `.tmp-`, has ended (or is not named there). A running process's temporary (a
/// render writing into the same folder now) is kept.
pub fn is_left_over(name: &str) -> bool {
    let Some((_, after)) = name.rsplit_once(".tmp-") else { return false };
    let digits = after.split('.').next().unwrap_or_default();
    match strata_backends::processes::writer_between(digits, "", "") {
        Some(pid) => pid != std::process::id() && !process_is_running(pid),
        None => true,
    }
}

pub use strata_backends::processes::is_running as process_is_running;

/// The name parts around the process id of `target_name`'s temporaries.
fn temporary_affixes(target_name: &str) -> (String, String) {
    match target_name.rsplit_once('.') {
        Some((stem, extension)) => (format!(".{stem}.tmp-"), format!(".{extension}")),
        None => (format!(".{target_name}.tmp-"), String::new()),
    }
}

/// The process that wrote temporary file `name` for the target named `target_name`, if
/// `name` is one of that target's temporaries ([`temporary_path`] of another process).
#[cfg(test)]
fn temporary_writer(target_name: &str, name: &str) -> Option<u32> {
    let (prefix, suffix) = temporary_affixes(target_name);
    strata_backends::processes::writer_between(name, &prefix, &suffix)
}

/// Removes the temporary files of `path` that processes no longer running left (a run
/// killed between writing and renaming); those of running processes (another run writing
/// the same name now) are kept ([`process_is_running`] says what it cannot see). Returns
/// the names removed. Best effort: a leftover that cannot be listed or removed stays,
/// hidden, and harms nothing.
pub fn remove_dead_temporaries(path: &Path) -> Vec<String> {
    let (Some(folder), Some(target_name)) = (path.parent(), path.file_name()) else { return Vec::new() };
    let folder = if folder.as_os_str().is_empty() { Path::new(".") } else { folder };
    let (prefix, suffix) = temporary_affixes(&target_name.to_string_lossy());
    let Ok(entries) = std::fs::read_dir(folder) else { return Vec::new() };
    let mut removed = Vec::new();
    for entry in entries.flatten() {
        let name = entry.file_name().to_string_lossy().into_owned();
        let Some(pid) = strata_backends::processes::writer_between(&name, &prefix, &suffix) else { continue };
        let regular = entry.file_type().is_ok_and(|t| t.is_file());
        if regular
            && pid != std::process::id()
            && !process_is_running(pid)
            && std::fs::remove_file(entry.path()).is_ok()
        {
            removed.push(name);
        }
    }
    removed.sort();
    removed
}

/// Why a file cannot be written; the message names the file.
#[derive(Debug, thiserror::Error)]
pub enum WriteError {
    /// Something other than a regular file (a device, a folder, a socket, a symbolic
    /// link) already has the name: replacing it is never what a user asked for.
    #[error("{path}: is {kind}, not a regular file: strata writes only regular files and does not replace it")]
    NotRegular {
        /// The target.
        path: String,
        /// What is there ("a character device", "a folder", ...).
        kind: &'static str,
    },
    /// The target is a file this process read as an input.
    #[error("{path}: is an input of this run; an output never replaces one (choose another output name or folder)")]
    Input {
        /// The target.
        path: String,
    },
    /// Writing, syncing or renaming failed (a full disk, no permission, ...).
    #[error("{path}: cannot write: {error}")]
    Io {
        /// The target.
        path: String,
        /// The operating system's error (in the message, not a `source`: a chain of
        /// causes printed after it would say it twice).
        error: std::io::Error,
    },
    /// The file on disk is shorter than what was written (a file system that accepted
    /// the bytes and lost them).
    #[error("{path}: cannot write: {written} of {expected} bytes reached the disk")]
    Short {
        /// The target.
        path: String,
        /// Bytes found on disk.
        written: u64,
        /// Bytes written.
        expected: u64,
    },
}

/// What kind of entry `metadata` describes, in words, if it is not a regular file.
fn not_regular(metadata: &std::fs::Metadata) -> Option<&'static str> {
    let kind = metadata.file_type();
    if kind.is_file() {
        return None;
    }
    if kind.is_dir() {
        return Some("a folder");
    }
    if kind.is_symlink() {
        return Some("a symbolic link");
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if kind.is_char_device() {
            return Some("a character device");
        }
        if kind.is_block_device() {
            return Some("a block device");
        }
        if kind.is_fifo() {
            return Some("a named pipe");
        }
        if kind.is_socket() {
            return Some("a socket");
        }
    }
    Some("not a regular file")
}

/// The files this process read as inputs ([`note_input`]): an output never replaces one.
static INPUTS: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());

/// Records that `path` was read as an input (a scene, mesh, texture, environment map,
/// reference, CSV), so that no output of this process replaces it.
pub fn note_input(path: &Path) {
    if let Ok(canonical) = path.canonicalize() {
        INPUTS.lock().unwrap_or_else(std::sync::PoisonError::into_inner).push(canonical);
    }
}

/// Refuses `path` if something other than a regular file has its name (a missing file
/// is fine: it is about to be created), or if it is a file this process read as an input.
pub fn check_target(path: &Path) -> Result<(), WriteError> {
    match std::fs::symlink_metadata(path) {
        Ok(metadata) => match not_regular(&metadata) {
            Some(kind) => Err(WriteError::NotRegular { path: path.display().to_string(), kind }),
            None => {
                let canonical = path.canonicalize().ok();
                let inputs = INPUTS.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
                if canonical.is_some_and(|c| inputs.contains(&c)) {
                    Err(WriteError::Input { path: path.display().to_string() })
                } else {
                    Ok(())
                }
            }
        },
        Err(_) => Ok(()),
    }
}

/// Writes `bytes` to `path`, complete or not at all (module documentation). On any error
/// the temporary file is removed and `path` is left as it was.
pub fn write(path: &Path, bytes: impl AsRef<[u8]>) -> Result<(), WriteError> {
    write_set(&[(path, bytes.as_ref())])
}

/// Writes several files as one: every target is checked, then every file is written under
/// its temporary name and synced, and only when all of them are complete are they renamed
/// into place. So a full disk, a size limit or a refused target on the last file leaves
/// none of them (a plot's SVG never stands without its PNG); the earlier files of those
/// names stay as they were.
pub fn write_set(files: &[(&Path, &[u8])]) -> Result<(), WriteError> {
    for (path, _) in files {
        check_target(path)?;
    }
    for (path, _) in files {
        remove_dead_temporaries(path);
    }
    let mut staged: Vec<PathBuf> = Vec::new();
    let result = (|| -> Result<(), WriteError> {
        for (path, bytes) in files {
            staged.push(temporary_path(path));
            stage(path, bytes)?;
        }
        for (path, _) in files {
            // Checked again: something may have taken the name while the bytes were written.
            check_target(path)?;
        }
        for (path, _) in files {
            let io = |error: std::io::Error| WriteError::Io { path: path.display().to_string(), error };
            std::fs::rename(temporary_path(path), path).map_err(io)?;
        }
        Ok(())
    })();
    if result.is_err() {
        for temporary in staged {
            let _ = std::fs::remove_file(temporary);
        }
    }
    result
}

/// Writes `bytes` under `path`'s temporary name, synced and checked for length.
fn stage(path: &Path, bytes: &[u8]) -> Result<(), WriteError> {
    let io = |error: std::io::Error| WriteError::Io { path: path.display().to_string(), error };
    let mut file = std::fs::File::create(temporary_path(path)).map_err(io)?;
    file.write_all(bytes).map_err(io)?;
    file.sync_all().map_err(io)?;
    let on_disk = file.metadata().map_err(io)?.len();
    if on_disk != bytes.len() as u64 {
        return Err(WriteError::Short {
            path: path.display().to_string(),
            written: on_disk,
            expected: bytes.len() as u64,
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let folder = std::env::temp_dir().join(format!("strata-atomic-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&folder);
        std::fs::create_dir_all(&folder).unwrap();
        folder
    }

    fn names(folder: &Path) -> Vec<String> {
        let mut names: Vec<String> =
            std::fs::read_dir(folder).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
        names.sort();
        names
    }

    #[test]
    fn a_file_appears_whole_and_its_temporary_is_gone() {
        let folder = scratch("whole");
        let path = folder.join("errors.csv");
        write(&path, "a,b\n").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "a,b\n");
        write(&path, "c\n").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "c\n");
        assert_eq!(names(&folder), ["errors.csv"]);
        let temporary = temporary_path(&folder.join("strata_frame001.png"));
        let name = temporary.file_name().unwrap().to_string_lossy().into_owned();
        assert!(name.starts_with(".strata_frame001.tmp-") && name.ends_with(".png") && is_temporary(&name));
        assert!(!is_temporary("strata_frame001.png"));
        // This process's temporary is not a leftover; one with no process id is.
        assert!(!is_left_over(&name));
        assert!(is_left_over(".strata_frame001.tmp-x.png"));
        std::fs::remove_dir_all(&folder).unwrap();
    }

    #[test]
    fn what_is_not_a_regular_file_is_never_replaced() {
        let folder = scratch("irregular");
        std::fs::create_dir(folder.join("a-folder.png")).unwrap();
        let message = write(&folder.join("a-folder.png"), b"x").unwrap_err().to_string();
        assert!(message.contains("a-folder.png: is a folder"), "{message}");
        #[cfg(unix)]
        {
            std::fs::write(folder.join("target.csv"), b"kept").unwrap();
            std::os::unix::fs::symlink(folder.join("target.csv"), folder.join("link.csv")).unwrap();
            let message = write(&folder.join("link.csv"), b"x").unwrap_err().to_string();
            assert!(message.contains("link.csv: is a symbolic link"), "{message}");
            assert_eq!(std::fs::read(folder.join("target.csv")).unwrap(), b"kept");
            let full = Path::new("/dev/full");
            if full.exists() {
                let message = write(full, b"x").unwrap_err().to_string();
                assert!(message.contains("/dev/full: is a character device"), "{message}");
                assert!(std::fs::symlink_metadata(full).unwrap().file_type().is_file().eq(&false));
            }
        }
        // Nothing was left behind.
        assert!(names(&folder).iter().all(|n| !is_temporary(n)), "{:?}", names(&folder));
        std::fs::remove_dir_all(&folder).unwrap();
    }

    #[test]
    fn a_failed_write_leaves_the_old_file_and_no_temporary() {
        let folder = scratch("failed");
        let path = folder.join("run.json");
        write(&path, "old").unwrap();
        // A folder in the temporary's place makes creating it fail.
        std::fs::create_dir(temporary_path(&path)).unwrap();
        assert!(write(&path, "new").is_err());
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "old");
        std::fs::remove_dir_all(&folder).unwrap();
    }

    #[test]
    fn a_write_removes_the_temporaries_a_dead_process_left_for_its_name() {
        let folder = scratch("leftovers");
        let dead = strata_backends::processes::an_ended_process();
        // A process still running (another run writing the same name now): kept.
        let mut living = std::process::Command::new("sleep").arg("60").spawn().unwrap();
        let doomed = format!(".default.tmp-{dead}.exr");
        let kept = [
            format!(".default.tmp-{}.exr", living.id()),
            format!(".default.tmp-{dead}.png"),  // another target's
            format!(".default.tmp-{dead}x.exr"), // not a process id
            format!(".other.tmp-{dead}.exr"),    // another target's
            "notes.txt".to_string(),
        ];
        for name in kept.iter().chain([&doomed]) {
            std::fs::write(folder.join(name), b"x").unwrap();
        }
        write(&folder.join("default.exr"), b"image").unwrap();
        let _ = living.kill();
        let _ = living.wait();
        let left = names(&folder);
        assert_eq!(left.contains(&doomed), !Path::new("/proc/self").exists(), "{left:?}");
        for name in &kept {
            assert!(left.contains(name), "{name} was removed: {left:?}");
        }
        assert_eq!(std::fs::read(folder.join("default.exr")).unwrap(), b"image");
        assert_eq!(temporary_writer("default.exr", &doomed), Some(dead));
        assert_eq!(temporary_writer("default.exr", ".default.tmp-.exr"), None);
        assert_eq!(temporary_writer("LICENSE", &format!(".LICENSE.tmp-{dead}")), Some(dead));
        std::fs::remove_dir_all(&folder).unwrap();
    }

    #[test]
    fn a_set_is_written_whole_or_not_at_all() {
        let folder = scratch("set");
        let (svg, png) = (folder.join("plot.svg"), folder.join("plot.png"));
        write_set(&[(&svg, b"svg 1"), (&png, b"png 1")]).unwrap();
        // The second file's temporary cannot be created: neither file changes.
        std::fs::create_dir(temporary_path(&png)).unwrap();
        assert!(write_set(&[(&svg, b"svg 2"), (&png, b"png 2")]).is_err());
        assert_eq!(std::fs::read(&svg).unwrap(), b"svg 1");
        assert_eq!(std::fs::read(&png).unwrap(), b"png 1");
        std::fs::remove_dir(temporary_path(&png)).unwrap();
        assert_eq!(names(&folder), ["plot.png", "plot.svg"]);
        // A refused target anywhere in the set: nothing is written.
        let link = folder.join("new.svg");
        std::fs::create_dir(folder.join("new.png")).unwrap();
        assert!(write_set(&[(&link, b"x"), (&folder.join("new.png"), b"y")]).is_err());
        assert!(!link.exists());
        std::fs::remove_dir_all(&folder).unwrap();
    }
}
