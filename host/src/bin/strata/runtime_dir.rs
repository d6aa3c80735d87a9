//! A warning when `XDG_RUNTIME_DIR` names a folder other users can write (`/tmp`).
//!
//! Why: Mesa's Vulkan device-select layer, an implicit layer that the Vulkan loader puts
//! into every Vulkan program (lavapipe's included), connects to
//! `$XDG_RUNTIME_DIR/wayland-0` to learn which GPU the desktop shows, and reads what
//! answers there (measured on Mesa 22.3: a socket listening at that name receives the
//! Wayland client's first request from `strata compare`). In a folder anyone can write,
//! another user can create that socket first and answer. The layer is loaded by the
//! Vulkan loader, outside strata's code, so strata says so once and goes on.

use std::path::Path;

/// The warning for `XDG_RUNTIME_DIR`'s value `dir`, or `None` when it is a folder of this
/// user's own that nobody else may write (or names nothing, where nothing can answer).
pub fn shared_runtime_dir_warning(dir: &Path) -> Option<String> {
    // Followed through links: the socket is looked for in the folder the name reaches.
    let metadata = std::fs::metadata(dir).ok().filter(|metadata| metadata.is_dir())?;
    let why = strata_files::owned_and_unshared(&metadata).err()?;
    Some(format!(
        "warning: XDG_RUNTIME_DIR={}: {why}; Mesa's Vulkan layer connects to a display socket in it \
         (wayland-0), which another user could create first: set XDG_RUNTIME_DIR to a folder of your own, \
         e.g. export XDG_RUNTIME_DIR=$(mktemp -d)",
        dir.display()
    ))
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
    fn a_folder_others_can_write_is_warned_about_and_a_private_one_is_not() {
        use std::os::unix::fs::PermissionsExt;
        let root = strata_files::private_scratch_folder("strata-runtime-dir-").unwrap();
        assert_eq!(shared_runtime_dir_warning(root.path()), None);
        assert_eq!(shared_runtime_dir_warning(&root.path().join("missing")), None);
        std::fs::set_permissions(root.path(), std::fs::Permissions::from_mode(0o1777)).unwrap();
        let warning = shared_runtime_dir_warning(root.path()).expect("a folder anyone can write is warned about");
        assert!(warning.starts_with(&format!("warning: XDG_RUNTIME_DIR={}: ", root.path().display())), "{warning}");
        assert!(warning.contains("wayland-0") && !warning.contains('\n'), "{warning}");
    }
}
