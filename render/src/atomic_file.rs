//! Output files that are either complete or absent: strata's one writer of files.
//!
//! Every encoder (EXR, PNG, CSV, SVG, JSON, HTML) makes its bytes in memory; [`write()`]
//! then puts them on the disk under a hidden temporary name in the same folder
//! (`.NAME.tmp-PID-RANDOM.EXT`, created exclusively: [`strata_files::TemporaryFile`], so
//! a symbolic link someone planted at a temporary's name is never written through), forces them to the device (`fsync`, which is where a full disk
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

/// Whether a file name is a temporary of this writer's (of any process and target).
pub fn is_temporary(name: &str) -> bool {
    strata_files::is_temporary(name)
}

/// Whether temporary file `name` ([`is_temporary`]) may be removed: its writer, named
/// after `.tmp-`, has ended (or is not named there). A running process's temporary (a
/// render writing into the same folder now) is kept.
pub fn is_left_over(name: &str) -> bool {
    match strata_files::any_temporary_writer(name) {
        Some(pid) => pid != std::process::id() && !process_is_running(pid),
        None => true,
    }
}

pub use strata_files::process_is_running;

/// Removes the temporary files of `path` that processes no longer running left (a run
/// killed between writing and renaming); those of running processes (another run writing
/// the same name now) are kept ([`process_is_running`] says what it cannot see). Returns
/// the names removed. Best effort: a leftover that cannot be listed or removed stays,
/// hidden, and harms nothing.
pub fn remove_dead_temporaries(path: &Path) -> Vec<String> {
    strata_files::remove_dead_temporaries(path)
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

/// A folder whose outputs are recorded by name ([`record_outputs`]).
#[derive(Debug)]
struct OutputRecord {
    folder: PathBuf,
    journal: PathBuf,
}

/// The folder this process records its outputs in, if any.
static RECORD: std::sync::Mutex<Option<OutputRecord>> = std::sync::Mutex::new(None);

/// From now on, the name of every file this process writes into `folder` is appended to
/// `journal` (one name a line) before the file appears under that name, so that a later
/// run removes exactly the files this one wrote, even if this one is killed halfway
/// (`strata compare`'s output folder: it never removes a file of the user's that merely
/// has a name like its outputs).
pub fn record_outputs(folder: &Path, journal: &Path) {
    let folder = folder.canonicalize().unwrap_or_else(|_| folder.to_path_buf());
    *RECORD.lock().unwrap_or_else(std::sync::PoisonError::into_inner) =
        Some(OutputRecord { folder, journal: journal.to_path_buf() });
}

/// Appends the names of `files` that lie in the recorded folder to its journal.
fn note_outputs(files: &[(&Path, &[u8])]) -> Result<(), WriteError> {
    let record = RECORD.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    let Some(record) = record.as_ref() else { return Ok(()) };
    let mut names = String::new();
    for (path, _) in files {
        let parent = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
        let in_folder = parent.canonicalize().is_ok_and(|p| p == record.folder);
        if let (true, Some(name)) = (in_folder, path.file_name()) {
            names += &format!("{}\n", name.to_string_lossy());
        }
    }
    if names.is_empty() {
        return Ok(());
    }
    let io = |error: std::io::Error| WriteError::Io { path: record.journal.display().to_string(), error };
    let mut options = std::fs::OpenOptions::new();
    options.append(true).create(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NOFOLLOW).mode(0o600);
    }
    let mut journal = options.open(&record.journal).map_err(io)?;
    journal.write_all(names.as_bytes()).map_err(io)?;
    journal.sync_all().map_err(io)
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
    // Every file complete under its temporary name before any is renamed; a temporary
    // not renamed is removed when dropped (an error anywhere leaves none).
    let mut staged = Vec::with_capacity(files.len());
    for (path, bytes) in files {
        staged.push(stage(path, bytes)?);
    }
    for (path, _) in files {
        // Checked again: something may have taken the name while the bytes were written.
        check_target(path)?;
    }
    note_outputs(files)?;
    for ((path, _), temporary) in files.iter().zip(staged) {
        temporary.persist(path).map_err(|error| WriteError::Io { path: path.display().to_string(), error })?;
    }
    Ok(())
}

/// Writes `bytes` under a new temporary name beside `path`, synced and checked for length.
fn stage(path: &Path, bytes: &[u8]) -> Result<strata_files::TemporaryFile, WriteError> {
    let io = |error: std::io::Error| WriteError::Io { path: path.display().to_string(), error };
    let temporary = strata_files::TemporaryFile::beside(path).map_err(io)?;
    let mut file = temporary.file();
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
    Ok(temporary)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A new empty folder of a random name (the test removes it).
    fn scratch(name: &str) -> PathBuf {
        strata_files::private_scratch_folder(&format!("strata-atomic-{name}-")).unwrap().keep()
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
        let name = format!(".strata_frame001.tmp-{}-a1B2c3D4.png", std::process::id());
        assert!(is_temporary(&name));
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
        std::fs::remove_dir_all(&folder).unwrap();
    }

    /// Security finding 5: a symbolic link planted at the name the writer's temporary
    /// had (`.NAME.tmp-PID.EXT`, predictable) made a render overwrite the link's target,
    /// then rename the link into place.
    #[cfg(unix)]
    #[test]
    fn a_link_planted_at_a_temporary_name_is_never_written_through() {
        let folder = scratch("planted");
        let victim = folder.join("victim.txt");
        std::fs::write(&victim, b"the user's").unwrap();
        let path = folder.join("default.exr");
        let planted = folder.join(format!(".default.tmp-{}.exr", std::process::id()));
        std::os::unix::fs::symlink(&victim, &planted).unwrap();
        write(&path, b"image").unwrap();
        assert_eq!(std::fs::read(&victim).unwrap(), b"the user's", "written through the planted link");
        assert!(std::fs::symlink_metadata(&path).unwrap().file_type().is_file(), "the link was renamed into place");
        assert_eq!(std::fs::read(&path).unwrap(), b"image");
        std::fs::remove_dir_all(&folder).unwrap();
    }

    #[test]
    fn a_set_is_written_whole_or_not_at_all() {
        let folder = scratch("set");
        let (svg, png) = (folder.join("plot.svg"), folder.join("plot.png"));
        write_set(&[(&svg, b"svg 1"), (&png, b"png 1")]).unwrap();
        // The second file's temporary cannot be created (its folder is missing): neither
        // file changes, and no temporary is left.
        let missing = folder.join("missing").join("plot.png");
        assert!(write_set(&[(&svg, b"svg 2"), (&missing, b"png 2")]).is_err());
        assert_eq!(std::fs::read(&svg).unwrap(), b"svg 1");
        assert_eq!(std::fs::read(&png).unwrap(), b"png 1");
        assert_eq!(names(&folder), ["plot.png", "plot.svg"]);
        // A refused target anywhere in the set: nothing is written.
        let link = folder.join("new.svg");
        std::fs::create_dir(folder.join("new.png")).unwrap();
        assert!(write_set(&[(&link, b"x"), (&folder.join("new.png"), b"y")]).is_err());
        assert!(!link.exists());
        std::fs::remove_dir_all(&folder).unwrap();
    }
}
