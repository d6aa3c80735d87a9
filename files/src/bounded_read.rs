//! Whole reads of regular files, bounded: what a cache, a lock file or any other file
//! that a program finds by name (rather than one the user named) is read through.
//!
//! Why each guard: such a path may hold whatever someone else put there. A named pipe
//! would block a plain `open` (and a `read`) forever; a link to `/dev/zero` would be read
//! until memory runs out; a link to another user's file would be read as ours. So the file
//! is opened with `O_NOFOLLOW` (a link is refused, not followed) and `O_NONBLOCK` (a pipe
//! opens at once), its type is checked on the open descriptor (`fstat`, so nothing can be
//! swapped in between the check and the read), its size is checked against the cap before
//! any byte is allocated, and the read itself stops one byte past the cap in case the
//! file grows meanwhile.

use std::io::Read;
use std::path::{Path, PathBuf};

/// Why a bounded read failed; the message names the file.
#[derive(Debug, thiserror::Error)]
pub enum ReadError {
    /// No entry of that name (a cache not written yet, a lock released).
    #[error("{path}: does not exist")]
    Missing {
        /// The file.
        path: PathBuf,
    },
    /// Something other than a regular file has the name: a symbolic link, a named pipe,
    /// a device, a folder or a socket.
    #[error(
        "{path}: is not a regular file (pipes, devices and folders are never read, nor links found rather than named)"
    )]
    NotRegular {
        /// The file.
        path: PathBuf,
    },
    /// The file is larger than the caller's cap.
    #[error("{path}: {size} bytes, more than the {cap} read from such a file")]
    TooLarge {
        /// The file.
        path: PathBuf,
        /// Its size (or, if it grew while being read, the bytes read so far).
        size: u64,
        /// The caller's cap.
        cap: u64,
    },
    /// Opening or reading failed (no permission, an I/O error).
    #[error("{path}: cannot read: {error}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating system's error.
        error: std::io::Error,
    },
}

/// The whole contents of the regular file `path`, at most `cap` bytes: a symbolic link,
/// a named pipe, a device or a folder at `path` is refused without being followed,
/// opened for long or read (module documentation).
pub fn read_regular_capped(path: &Path, cap: u64) -> Result<Vec<u8>, ReadError> {
    read_capped(path, cap, false)
}

/// As [`read_regular_capped`], but a symbolic link is followed: for a file the user named
/// (`xtask run --buffer`), where a link to the user's own file is ordinary. What it leads
/// to must still be a regular file within the cap (a link to `/dev/zero` is refused).
pub fn read_named_regular_capped(path: &Path, cap: u64) -> Result<Vec<u8>, ReadError> {
    read_capped(path, cap, true)
}

fn read_capped(path: &Path, cap: u64, follow_links: bool) -> Result<Vec<u8>, ReadError> {
    let io = |error: std::io::Error| ReadError::Io { path: path.to_path_buf(), error };
    let file = match open_without_waiting(path, follow_links) {
        Ok(file) => file,
        Err(error) if error.kind() == std::io::ErrorKind::NotFound => {
            return Err(ReadError::Missing { path: path.to_path_buf() });
        }
        // ELOOP: `O_NOFOLLOW` met a symbolic link at the last component.
        Err(error) if is_link_refusal(&error) => return Err(ReadError::NotRegular { path: path.to_path_buf() }),
        Err(error) => return Err(io(error)),
    };
    let metadata = file.metadata().map_err(io)?;
    if !metadata.is_file() {
        return Err(ReadError::NotRegular { path: path.to_path_buf() });
    }
    if metadata.len() > cap {
        return Err(ReadError::TooLarge { path: path.to_path_buf(), size: metadata.len(), cap });
    }
    let mut bytes = Vec::new();
    let expected = usize::try_from(metadata.len()).map_err(|_| ReadError::TooLarge {
        path: path.to_path_buf(),
        size: metadata.len(),
        cap,
    })?;
    bytes.try_reserve_exact(expected).map_err(|_| ReadError::TooLarge {
        path: path.to_path_buf(),
        size: metadata.len(),
        cap,
    })?;
    file.take(cap.saturating_add(1)).read_to_end(&mut bytes).map_err(io)?;
    if bytes.len() as u64 > cap {
        return Err(ReadError::TooLarge { path: path.to_path_buf(), size: bytes.len() as u64, cap });
    }
    Ok(bytes)
}

/// Opens `path` for reading without waiting for a named pipe's writer, and unless
/// `follow_links`, without following a final symbolic link.
fn open_without_waiting(path: &Path, follow_links: bool) -> std::io::Result<std::fs::File> {
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        let no_follow = if follow_links { 0 } else { libc::O_NOFOLLOW };
        options.custom_flags(no_follow | libc::O_NONBLOCK);
    }
    #[cfg(not(unix))]
    {
        // No O_NOFOLLOW: refuse a link seen before opening (a window remains there).
        if !follow_links && std::fs::symlink_metadata(path)?.file_type().is_symlink() {
            return Err(std::io::Error::new(std::io::ErrorKind::InvalidInput, "a symbolic link"));
        }
    }
    options.open(path)
}

/// Whether `error` is `open`'s refusal of a symbolic link under `O_NOFOLLOW`.
fn is_link_refusal(error: &std::io::Error) -> bool {
    #[cfg(unix)]
    {
        error.raw_os_error() == Some(libc::ELOOP)
    }
    #[cfg(not(unix))]
    {
        error.kind() == std::io::ErrorKind::InvalidInput
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch() -> tempfile::TempDir {
        tempfile::Builder::new().prefix("strata-files-read-").tempdir().unwrap()
    }

    #[test]
    fn a_regular_file_within_the_cap_reads_whole_and_a_larger_one_is_refused() {
        let folder = scratch();
        let path = folder.path().join("cache.bin");
        std::fs::write(&path, b"twelve bytes").unwrap();
        assert_eq!(read_regular_capped(&path, 12).unwrap(), b"twelve bytes");
        let error = read_regular_capped(&path, 11).unwrap_err();
        assert!(matches!(error, ReadError::TooLarge { size: 12, cap: 11, .. }), "{error}");
        assert!(matches!(read_regular_capped(&folder.path().join("none"), 1), Err(ReadError::Missing { .. })));
    }

    #[cfg(unix)]
    #[test]
    fn links_pipes_and_devices_are_refused_without_hanging_or_reading_them() {
        let folder = scratch();
        let target = folder.path().join("secret");
        std::fs::write(&target, b"not ours").unwrap();
        let link = folder.path().join("link");
        std::os::unix::fs::symlink(&target, &link).unwrap();
        let zero = folder.path().join("zero");
        std::os::unix::fs::symlink("/dev/zero", &zero).unwrap();
        let fifo = folder.path().join("fifo");
        let name = std::ffi::CString::new(fifo.as_os_str().as_encoded_bytes()).unwrap();
        // SAFETY: a valid NUL-terminated path; mkfifo only creates the entry.
        assert_eq!(unsafe { libc::mkfifo(name.as_ptr(), 0o600) }, 0);
        for path in [&link, &zero, &fifo, &folder.path().to_path_buf(), &std::path::PathBuf::from("/dev/zero")] {
            let error = read_regular_capped(path, 1 << 20).unwrap_err();
            assert!(matches!(error, ReadError::NotRegular { .. }), "{}: {error}", path.display());
        }
        // A file the user named may be a link to a regular file, never to a device or pipe.
        assert_eq!(read_named_regular_capped(&link, 1 << 20).unwrap(), b"not ours");
        for path in [&zero, &fifo] {
            let error = read_named_regular_capped(path, 1 << 20).unwrap_err();
            assert!(matches!(error, ReadError::NotRegular { .. }), "{}: {error}", path.display());
        }
    }
}
