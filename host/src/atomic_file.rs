//! Output files that are either complete or absent. Every file strata writes is first
//! written under a hidden temporary name in the same folder (`.NAME.tmp-PID.EXT`, the
//! extension kept because some encoders choose the format by it) and then renamed into
//! place, which POSIX makes atomic within one file system. A run killed while writing
//! leaves at most a hidden temporary file, never a truncated EXR, PNG or CSV under the
//! final name that looks valid; the next run into the folder removes such leftovers
//! ([`is_temporary`]).

use std::path::{Path, PathBuf};

/// The hidden temporary name `path` is written under before the rename.
pub fn temporary_path(path: &Path) -> PathBuf {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let temporary = match name.rsplit_once('.') {
        Some((stem, extension)) => format!(".{stem}.tmp-{}.{extension}", std::process::id()),
        None => format!(".{name}.tmp-{}", std::process::id()),
    };
    path.with_file_name(temporary)
}

/// Whether a file name is one of [`temporary_path`]'s (of any process).
pub fn is_temporary(name: &str) -> bool {
    name.starts_with('.') && name.contains(".tmp-")
}

/// Writes a file through `write`, which is given the temporary path to create, then
/// renames it to `path`. On any error the temporary file is removed and `path` is left
/// as it was.
pub fn write_with<E>(path: &Path, write: impl FnOnce(&Path) -> Result<(), E>) -> Result<(), AtomicError<E>> {
    let temporary = temporary_path(path);
    if let Err(error) = write(&temporary) {
        let _ = std::fs::remove_file(&temporary);
        return Err(AtomicError::Write(error));
    }
    std::fs::rename(&temporary, path).map_err(|error| {
        let _ = std::fs::remove_file(&temporary);
        AtomicError::Rename(error)
    })
}

/// Writes `bytes` to `path` through a temporary file; an error names `path`.
pub fn write(path: &Path, bytes: impl AsRef<[u8]>) -> anyhow::Result<()> {
    write_with(path, |temporary| std::fs::write(temporary, bytes.as_ref())).map_err(|error| {
        anyhow::anyhow!(
            "{}: cannot write: {}",
            path.display(),
            match error {
                AtomicError::Write(e) | AtomicError::Rename(e) => e,
            }
        )
    })
}

/// Why an atomic write failed.
#[derive(Debug)]
pub enum AtomicError<E> {
    /// Writing the temporary file failed.
    Write(E),
    /// Renaming it into place failed.
    Rename(std::io::Error),
}

impl<E: std::fmt::Display> std::fmt::Display for AtomicError<E> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            AtomicError::Write(error) => write!(f, "{error}"),
            AtomicError::Rename(error) => write!(f, "cannot move the finished file into place: {error}"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_appears_whole_or_not_at_all() {
        let folder = std::env::temp_dir().join(format!("strata-atomic-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&folder);
        std::fs::create_dir_all(&folder).unwrap();
        let path = folder.join("errors.csv");
        write(&path, "a,b\n").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "a,b\n");
        // A writer that fails half-way leaves neither the file nor its temporary.
        let failed = write_with(&folder.join("image.png"), |temporary| {
            std::fs::write(temporary, b"half")?;
            Err(std::io::Error::other("killed"))
        });
        assert!(failed.is_err());
        let names: Vec<String> = std::fs::read_dir(&folder)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names, ["errors.csv"]);
        let temporary = temporary_path(&folder.join("strata_frame001.png"));
        let name = temporary.file_name().unwrap().to_string_lossy().into_owned();
        assert!(name.starts_with(".strata_frame001.tmp-") && name.ends_with(".png") && is_temporary(&name));
        assert!(!is_temporary("strata_frame001.png"));
        std::fs::remove_dir_all(&folder).unwrap();
    }
}
