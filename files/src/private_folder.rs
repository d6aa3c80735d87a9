//! Folders only this user can write: the per-user cache (the pipeline cache, the built
//! Slang driver) and private scratch folders (the glslang and Slang work folders).
//!
//! Why: a program strata runs, or a cache whose bytes reach the driver, must not come
//! from a name in a folder other users can write (`/tmp`): whoever creates that name
//! first decides what runs. So the cache folder is created with mode `0700`, and before
//! anything in it is trusted, it (and, for a folder strata did not create, the folder
//! above it) is checked to be a real folder (not a link) owned by this user and writable
//! by nobody else. Scratch folders get a random name and mode `0700` from `mkdir`, which
//! fails rather than reuse a folder someone else made first.

use std::path::{Path, PathBuf};

/// Why a private folder cannot be had; the message names the folder.
#[derive(Debug, thiserror::Error)]
pub enum FolderError {
    /// Neither `XDG_CACHE_HOME` nor `HOME` is set to an absolute path.
    #[error("no cache folder: neither XDG_CACHE_HOME nor HOME is an absolute path")]
    NoHome,
    /// The folder exists but someone else could have put things in it.
    #[error("{path}: {why}; strata keeps its cache and tools only in a folder of the user's own, mode 0700")]
    NotPrivate {
        /// The folder.
        path: PathBuf,
        /// What is wrong: a link, another owner, group or other write permission.
        why: String,
    },
    /// Creating or inspecting the folder failed.
    #[error("{path}: {error}")]
    Io {
        /// The folder.
        path: PathBuf,
        /// The operating system's error.
        error: std::io::Error,
    },
}

/// The per-user cache folder `$XDG_CACHE_HOME/strata`, else `$HOME/.cache/strata` (a
/// relative path in either is ignored, as the XDG specification asks), without creating
/// or checking it.
pub fn user_cache_path() -> Option<PathBuf> {
    let from = |name: &str| std::env::var_os(name).map(PathBuf::from).filter(|path| path.is_absolute());
    from("XDG_CACHE_HOME").or_else(|| from("HOME").map(|home| home.join(".cache"))).map(|base| base.join("strata"))
}

/// The per-user cache folder ([`user_cache_path`]), or `subfolder` inside it, created
/// with mode `0700` where missing and checked ([`check_private`]) before it is returned.
pub fn user_cache_folder(subfolder: Option<&str>) -> Result<PathBuf, FolderError> {
    let base = user_cache_path().ok_or(FolderError::NoHome)?;
    let folder = match subfolder {
        Some(name) => base.join(name),
        None => base,
    };
    private_folder(&folder)?;
    Ok(folder)
}

/// Creates `folder` (and missing parents) with mode `0700` where missing, then checks it
/// ([`check_private`]).
pub fn private_folder(folder: &Path) -> Result<(), FolderError> {
    let io = |error: std::io::Error| FolderError::Io { path: folder.to_path_buf(), error };
    let mut builder = std::fs::DirBuilder::new();
    builder.recursive(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::DirBuilderExt;
        builder.mode(0o700);
    }
    builder.create(folder).map_err(io)?;
    check_private(folder)
}

/// Checks that `folder` is a folder, not a symbolic link, owned by this user and writable
/// by nobody else (no group or other write bit). On systems without Unix permissions only
/// the link check is made.
pub fn check_private(folder: &Path) -> Result<(), FolderError> {
    let not_private = |why: String| FolderError::NotPrivate { path: folder.to_path_buf(), why };
    let metadata =
        std::fs::symlink_metadata(folder).map_err(|error| FolderError::Io { path: folder.to_path_buf(), error })?;
    if metadata.file_type().is_symlink() {
        return Err(not_private("is a symbolic link".into()));
    }
    if !metadata.is_dir() {
        return Err(not_private("is not a folder".into()));
    }
    owned_and_unshared(&metadata).map_err(not_private)
}

/// Whether the entry `metadata` describes belongs to this user and nobody else may write
/// it (no group or other write bit): `Err` says which is not so. What a folder strata
/// trusts ([`check_private`]) and a program it runs (the built Slang tool) must both be.
/// On systems without Unix permissions there is nothing to check.
pub fn owned_and_unshared(metadata: &std::fs::Metadata) -> Result<(), String> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        // SAFETY: geteuid has no preconditions and cannot fail.
        let me = unsafe { libc::geteuid() };
        if metadata.uid() != me {
            return Err(format!("is owned by user {}, not by this user ({me})", metadata.uid()));
        }
        let mode = metadata.mode() & 0o777;
        if mode & 0o022 != 0 {
            return Err(format!("has mode {mode:o}: others may write into it"));
        }
    }
    #[cfg(not(unix))]
    let _ = metadata;
    Ok(())
}

/// A new scratch folder of this process under the system's temporary folder, named
/// `PREFIX` plus random characters, mode `0700`, removed with everything in it when
/// dropped. `mkdir` fails on an existing name, so a folder someone else made is never
/// used.
pub fn private_scratch_folder(prefix: &str) -> std::io::Result<tempfile::TempDir> {
    tempfile::Builder::new().prefix(prefix).rand_bytes(10).tempdir()
}

/// A new scratch folder in `parent` (for a rename into place beside its target), named
/// `PREFIX` plus random characters, mode `0700`, removed when dropped unless kept.
pub fn private_scratch_folder_in(parent: &Path, prefix: &str) -> std::io::Result<tempfile::TempDir> {
    tempfile::Builder::new().prefix(prefix).rand_bytes(10).tempdir_in(parent)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[cfg(unix)]
    #[test]
    fn a_folder_others_can_write_or_a_link_is_not_private() {
        use std::os::unix::fs::PermissionsExt;
        let root = tempfile::Builder::new().prefix("strata-files-private-").tempdir().unwrap();
        let mine = root.path().join("mine");
        private_folder(&mine).unwrap();
        let mode = std::fs::metadata(&mine).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o700);
        let shared = root.path().join("shared");
        std::fs::create_dir(&shared).unwrap();
        std::fs::set_permissions(&shared, std::fs::Permissions::from_mode(0o777)).unwrap();
        let error = private_folder(&shared).unwrap_err().to_string();
        assert!(error.contains("others may write") && error.contains("shared"), "{error}");
        let link = root.path().join("link");
        std::os::unix::fs::symlink(&mine, &link).unwrap();
        assert!(check_private(&link).unwrap_err().to_string().contains("symbolic link"));
        let file = root.path().join("file");
        std::fs::write(&file, b"").unwrap();
        assert!(private_folder(&file).is_err());
    }

    #[test]
    fn scratch_folders_are_fresh_and_removed() {
        let first = private_scratch_folder("strata-files-scratch-").unwrap();
        let second = private_scratch_folder("strata-files-scratch-").unwrap();
        assert_ne!(first.path(), second.path());
        check_private(first.path()).unwrap();
        let path = first.path().to_path_buf();
        drop(first);
        assert!(!path.exists());
    }
}
