//! A warning when `XDG_RUNTIME_DIR` names a folder other users can write (`/tmp`), or
//! could create or redirect.
//!
//! Why: Mesa's Vulkan device-select layer, an implicit layer that the Vulkan loader puts
//! into every Vulkan program (lavapipe's included), connects to
//! `$XDG_RUNTIME_DIR/wayland-0` to learn which GPU the desktop shows, and reads what
//! answers there (measured on Mesa 22.3: a socket listening at that name receives the
//! Wayland client's first request from `strata compare`). In a folder anyone can write,
//! another user can create that socket first and answer. The layer is loaded by the
//! Vulkan loader, outside strata's code, so strata says so once and goes on.

use std::path::Path;

/// The warning for `XDG_RUNTIME_DIR`'s value `dir`, one line, or `None` when it is a
/// folder of this user's own that nobody else may write, or a name nobody else can create.
pub fn shared_runtime_dir_warning(dir: &Path) -> Option<String> {
    let why = why_shared(dir)?;
    Some(format!(
        "warning: XDG_RUNTIME_DIR={:?}: {why}; Mesa's Vulkan layer connects to a display socket in it \
         (wayland-0), which another user could create first: set XDG_RUNTIME_DIR to a folder of your own, \
         e.g. export XDG_RUNTIME_DIR=$(mktemp -d)",
        dir.as_os_str()
    ))
}

/// What lets another user decide what `dir/wayland-0` is, or `None`.
#[cfg(unix)]
fn why_shared(dir: &Path) -> Option<String> {
    use std::os::unix::fs::MetadataExt;
    // SAFETY: geteuid has no preconditions and cannot fail.
    let me = unsafe { libc::geteuid() };
    // A link another user owns can be pointed elsewhere by them whatever it points at now.
    if let Ok(link) = std::fs::symlink_metadata(dir)
        && link.file_type().is_symlink()
        && link.uid() != me
    {
        return Some(format!("is a link owned by user {}, who can point it elsewhere", link.uid()));
    }
    match std::fs::metadata(dir) {
        Ok(metadata) if metadata.is_dir() => strata_files::owned_and_unshared(&metadata).err(),
        Ok(_) => None,
        // Missing: whoever may write the nearest folder above it can create it. Only other
        // users' write bit counts here: a group-writable folder is the rule under a user
        // private group (umask 002, where cargo's own target folder is 0775), and the tests
        // give strata a missing name there.
        Err(_) => dir.ancestors().skip(1).find_map(|above| std::fs::metadata(above).ok().map(|m| (above, m))).and_then(
            |(above, metadata)| {
                (metadata.mode() & 0o002 != 0)
                    .then(|| format!("does not exist, and others may write {:?}, where it would be", above.as_os_str()))
            },
        ),
    }
}

/// Without Unix permissions there is nothing to check.
#[cfg(not(unix))]
fn why_shared(_dir: &Path) -> Option<String> {
    None
}

/// Prints [`shared_runtime_dir_warning`] for this process's `XDG_RUNTIME_DIR` on standard
/// error, if there is one.
pub fn warn_if_shared() {
    if let Some(dir) = std::env::var_os("XDG_RUNTIME_DIR")
        && let Some(warning) = shared_runtime_dir_warning(Path::new(&dir))
    {
        eprintln!("{warning}");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[cfg(unix)]
    #[test]
    fn a_folder_others_can_write_or_create_is_warned_about_and_a_private_one_is_not() {
        use std::os::unix::fs::PermissionsExt;
        let root = strata_files::private_scratch_folder("strata-runtime-dir-").unwrap();
        assert_eq!(shared_runtime_dir_warning(root.path()), None);
        assert_eq!(shared_runtime_dir_warning(&root.path().join("missing")), None, "a name only this user can make");
        std::fs::set_permissions(root.path(), std::fs::Permissions::from_mode(0o770)).unwrap();
        assert_eq!(
            shared_runtime_dir_warning(&root.path().join("missing")),
            None,
            "group-writable, as under umask 002"
        );
        std::fs::set_permissions(root.path(), std::fs::Permissions::from_mode(0o1777)).unwrap();
        let warning = shared_runtime_dir_warning(root.path()).expect("a folder anyone can write is warned about");
        assert!(warning.starts_with(&format!("warning: XDG_RUNTIME_DIR={:?}: ", root.path())), "{warning}");
        assert!(warning.contains("wayland-0") && !warning.contains('\n'), "{warning}");
        let missing = shared_runtime_dir_warning(&root.path().join("missing")).expect("a name anyone can create");
        assert!(missing.contains("does not exist, and others may write"), "{missing}");
        // A name with a line break stays on one line.
        let odd = root.path().join("a\nb");
        std::fs::create_dir(&odd).unwrap();
        std::fs::set_permissions(&odd, std::fs::Permissions::from_mode(0o777)).unwrap();
        assert!(!shared_runtime_dir_warning(&odd).unwrap().contains('\n'));
    }
}
