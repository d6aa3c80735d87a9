//! Temporary files beside their target, created so that nothing planted at their name can
//! redirect the write, and renamed into place once complete.
//!
//! A temporary is named `.STEM.tmp-PID-RANDOM.EXT` for a target `STEM.EXT`, in the
//! target's folder (a rename is atomic only within one file system). Why each part:
//! - created with `O_CREAT | O_EXCL` ([`tempfile`]): if anything already has the name (a
//!   symbolic link someone planted, pointing at a file of the user's), the creation fails
//!   and another random name is tried; a link is never written through;
//! - `RANDOM`: the name cannot be guessed ahead, so it cannot be planted at all;
//! - `PID`: a run killed between writing and renaming leaves a temporary that a later
//!   write of the same target recognises as a dead process's and removes
//!   ([`remove_dead_temporaries`]), while a running process's is left alone.

use std::path::Path;

/// A temporary file beside a target, removed when dropped unless [`Self::persist`]ed.
#[derive(Debug)]
pub struct TemporaryFile {
    inner: tempfile::NamedTempFile,
}

impl TemporaryFile {
    /// Creates a new, empty temporary file for `target` in `target`'s folder (module
    /// documentation), readable and writable by the owner only until persisted.
    pub fn beside(target: &Path) -> std::io::Result<Self> {
        let folder = folder_of(target);
        let name = target.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        let (prefix, suffix) = affixes(&name);
        let inner = tempfile::Builder::new()
            .prefix(&format!("{prefix}{}-", std::process::id()))
            .suffix(&suffix)
            .rand_bytes(8)
            .tempfile_in(folder)?;
        Ok(Self { inner })
    }

    /// The open file, to write into.
    pub fn file(&self) -> &std::fs::File {
        self.inner.as_file()
    }

    /// Where the temporary is.
    pub fn path(&self) -> &Path {
        self.inner.path()
    }

    /// Renames the temporary to `target` (atomic within one file system), replacing a
    /// regular file of that name. The caller has written and synced it.
    pub fn persist(self, target: &Path) -> std::io::Result<()> {
        self.inner.persist(target).map(drop).map_err(|error| error.error)
    }
}

/// Writes `bytes` to `path` whole or not at all: into a [`TemporaryFile`] beside it,
/// synced, then renamed over it. A symbolic link at `path` is replaced, never written
/// through; nothing is ever written through a link at a temporary's name. (strata's
/// images and reports go through `strata_render::atomic_file`, which adds its checks of
/// the target on top of this.)
pub fn write_whole(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    use std::io::Write;
    remove_dead_temporaries(path);
    let temporary = TemporaryFile::beside(path)?;
    let mut file = temporary.file();
    file.write_all(bytes)?;
    file.sync_all()?;
    temporary.persist(path)
}

/// The folder a target's temporaries go in (`.` for a bare file name).
fn folder_of(target: &Path) -> &Path {
    match target.parent() {
        Some(folder) if !folder.as_os_str().is_empty() => folder,
        _ => Path::new("."),
    }
}

/// The parts of a temporary's name around `PID-RANDOM` for a target named `target_name`.
fn affixes(target_name: &str) -> (String, String) {
    match target_name.rsplit_once('.') {
        Some((stem, extension)) if !stem.is_empty() => (format!(".{stem}.tmp-"), format!(".{extension}")),
        _ => (format!(".{target_name}.tmp-"), String::new()),
    }
}

/// Whether the file name `name` is a temporary of some target (of any process).
pub fn is_temporary(name: &str) -> bool {
    name.starts_with('.') && any_temporary_writer(name).is_some()
}

/// The process that made `name`, if `name` is a temporary of the target named
/// `target_name` (`.STEM.tmp-PID-RANDOM.EXT`, or the older `.STEM.tmp-PID.EXT`).
pub fn temporary_writer(target_name: &str, name: &str) -> Option<u32> {
    let (prefix, suffix) = affixes(target_name);
    writer_of(name.strip_prefix(&prefix)?.strip_suffix(&suffix)?)
}

/// The process that made `name`, if `name` is a temporary of any target.
pub fn any_temporary_writer(name: &str) -> Option<u32> {
    let (_, after) = name.rsplit_once(".tmp-")?;
    // `PID-RANDOM.EXT`, `PID-RANDOM`, `PID.EXT` or `PID`; RANDOM is alphanumeric.
    let middle = after.split('.').next()?;
    writer_of(middle)
}

/// `PID` or `PID-RANDOM` (as [`TemporaryFile::beside`] writes them) to the process id.
fn writer_of(middle: &str) -> Option<u32> {
    let (digits, random) = match middle.split_once('-') {
        Some((digits, random)) => (digits, Some(random)),
        None => (middle, None),
    };
    if random.is_some_and(|r| r.is_empty() || !r.bytes().all(|b| b.is_ascii_alphanumeric())) {
        return None;
    }
    let pid: u32 = digits.parse().ok()?;
    (pid.to_string() == digits).then_some(pid)
}

/// Whether process `pid` is running, as this process's `/proc` sees it (Linux and other
/// systems with `/proc`; elsewhere every process counts as running, so nothing of another
/// process is ever removed). A process of another PID namespace or another host sharing
/// the folder is not seen: its temporary counts as a dead one's (its rename then fails,
/// naming the file; nothing half-written is left).
pub fn process_is_running(pid: u32) -> bool {
    if !Path::new("/proc/self").exists() {
        return true;
    }
    Path::new(&format!("/proc/{pid}")).exists()
}

/// Removes the temporaries of `target` that processes no longer running left (a run
/// killed between writing and renaming); a running process's (another run writing the same
/// name now) are kept, and so is anything that is not a regular file. Returns the names
/// removed. Best effort: a leftover that cannot be listed or removed stays, hidden.
pub fn remove_dead_temporaries(target: &Path) -> Vec<String> {
    let Some(target_name) = target.file_name() else { return Vec::new() };
    let target_name = target_name.to_string_lossy();
    let Ok(entries) = std::fs::read_dir(folder_of(target)) else { return Vec::new() };
    let mut removed = Vec::new();
    for entry in entries.flatten() {
        let name = entry.file_name().to_string_lossy().into_owned();
        let Some(pid) = temporary_writer(&target_name, &name) else { continue };
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

/// The temporary name an older strata (before random suffixes) used for `target`: what
/// the tests plant as a link at a predictable name.
#[cfg(test)]
fn legacy_temporary_path(target: &Path, pid: u32) -> std::path::PathBuf {
    let name = target.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let (prefix, suffix) = affixes(&name);
    target.with_file_name(format!("{prefix}{pid}{suffix}"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    #[test]
    fn temporary_names_carry_the_writer_and_only_plain_ids_are_read() {
        assert_eq!(temporary_writer("a.exr", ".a.tmp-123.exr"), Some(123));
        assert_eq!(temporary_writer("a.exr", ".a.tmp-123-x9Yz0aQw.exr"), Some(123));
        assert_eq!(any_temporary_writer(".a.tmp-123-x9Yz0aQw.exr"), Some(123));
        assert_eq!(temporary_writer("lock", ".lock.tmp-7-ab"), Some(7));
        for name in [".a.tmp-0123.exr", ".a.tmp-+123.exr", ".a.tmp-.exr", ".a.tmp-12x.exr", ".b.tmp-123.exr"] {
            assert_eq!(temporary_writer("a.exr", name), None, "{name}");
        }
        assert_eq!(temporary_writer("a.exr", ".a.tmp-123-.exr"), None);
        assert_eq!(temporary_writer("a.exr", ".a.tmp-123-a/b.exr"), None);
        assert!(is_temporary(".a.tmp-123-x9Yz0aQw.exr") && !is_temporary("a.tmp-1.exr"));
    }

    #[test]
    fn a_temporary_is_persisted_whole_or_removed() {
        let folder = tempfile::Builder::new().prefix("strata-files-temp-").tempdir().unwrap();
        let target = folder.path().join("image.png");
        let temporary = TemporaryFile::beside(&target).unwrap();
        let name = temporary.path().file_name().unwrap().to_string_lossy().into_owned();
        assert_eq!(temporary_writer("image.png", &name), Some(std::process::id()), "{name}");
        temporary.file().write_all(b"bytes").unwrap();
        temporary.persist(&target).unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"bytes");
        let dropped = TemporaryFile::beside(&target).unwrap();
        let dropped_path = dropped.path().to_path_buf();
        drop(dropped);
        assert!(!dropped_path.exists());
        assert_eq!(std::fs::read_dir(folder.path()).unwrap().count(), 1);
    }

    /// The finding this module exists for: a symbolic link planted at the name a writer
    /// would use must not be written through. With a predictable name (the older
    /// `.STEM.tmp-PID.EXT`) the planted link is at the exact name; here every name is
    /// fresh and created exclusively, so the link's target keeps its bytes.
    #[cfg(unix)]
    #[test]
    fn a_link_planted_at_the_temporary_name_is_never_written_through() {
        let folder = tempfile::Builder::new().prefix("strata-files-link-").tempdir().unwrap();
        let victim = folder.path().join("victim.txt");
        std::fs::write(&victim, b"the user's").unwrap();
        let target = folder.path().join("out.csv");
        let planted = legacy_temporary_path(&target, std::process::id());
        std::os::unix::fs::symlink(&victim, &planted).unwrap();
        let temporary = TemporaryFile::beside(&target).unwrap();
        assert_ne!(temporary.path(), planted);
        temporary.file().write_all(b"ours").unwrap();
        temporary.persist(&target).unwrap();
        assert_eq!(std::fs::read(&victim).unwrap(), b"the user's");
        assert_eq!(std::fs::read(&target).unwrap(), b"ours");
        assert!(std::fs::symlink_metadata(&planted).unwrap().file_type().is_symlink());
    }

    #[test]
    fn dead_writers_temporaries_go_and_running_ones_stay() {
        let folder = tempfile::Builder::new().prefix("strata-files-dead-").tempdir().unwrap();
        let target = folder.path().join("a.exr");
        let mut ended = std::process::Command::new("true").spawn().unwrap();
        let dead_pid = ended.id();
        ended.wait().unwrap();
        let dead = format!(".a.tmp-{dead_pid}-abc.exr");
        let own = format!(".a.tmp-{}-abc.exr", std::process::id());
        let other = format!(".b.tmp-{dead_pid}-abc.exr");
        for name in [&dead, &own, &other] {
            std::fs::write(folder.path().join(name), b"half").unwrap();
        }
        let expected = if Path::new("/proc/self").exists() { vec![dead.clone()] } else { vec![] };
        assert_eq!(remove_dead_temporaries(&target), expected);
        assert!(folder.path().join(&own).exists() && folder.path().join(&other).exists());
    }
}
