//! Headless Chromium for the WebGPU backend: finding it, starting it on the bridge's
//! page with a profile of its own, and stopping it.
//!
//! The profile, Chromium's configuration and cache folders (where its crash reporter
//! writes) and its log all live in one private scratch folder of this process (mode
//! 0700, a random name made with `mkdir`: `strata_files::private_scratch_folder`),
//! removed when the browser is dropped. Chromium runs in a process group of its own,
//! killed whole on drop, so that no renderer or GPU process outlives the backend.

use super::devtools::{BrowserEnds, DevTools};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

/// The environment variable naming the Chromium binary to run (a path, used as it is);
/// unset, the backend looks for `chromium`, `chromium-browser`, `google-chrome` and
/// `google-chrome-stable` on `PATH`.
pub const CHROMIUM_VARIABLE: &str = "STRATA_CHROMIUM";

/// The environment variable that makes a missing browser or WebGPU adapter an error of
/// the tests that need one, instead of a skip (CI sets it).
pub const BROWSER_REQUIRED_VARIABLE: &str = "STRATA_REQUIRE_BROWSER";

/// Whether `STRATA_REQUIRE_BROWSER` is set to anything but empty or `0`.
pub fn browser_required() -> bool {
    std::env::var(BROWSER_REQUIRED_VARIABLE).is_ok_and(|v| !v.is_empty() && v != "0")
}

/// The Chromium binary: `STRATA_CHROMIUM` where set (it must name a file), else the first
/// of Chromium's usual names found on `PATH`. The error says what was looked for and how
/// to install it.
pub fn find_chromium() -> Result<PathBuf, String> {
    if let Some(path) = std::env::var_os(CHROMIUM_VARIABLE).filter(|p| !p.is_empty()) {
        let path = PathBuf::from(path);
        return if path.is_file() {
            Ok(path)
        } else {
            Err(format!("{CHROMIUM_VARIABLE}={}: no such file", path.display()))
        };
    }
    let names = ["chromium", "chromium-browser", "google-chrome", "google-chrome-stable"];
    let folders: Vec<PathBuf> =
        std::env::var_os("PATH").map(|p| std::env::split_paths(&p).collect()).unwrap_or_default();
    names.iter().find_map(|name| folders.iter().map(|folder| folder.join(name)).find(|path| path.is_file())).ok_or_else(
        || {
            format!(
                "no Chromium found ({} on PATH; apt-get install chromium, or set {CHROMIUM_VARIABLE})",
                names.join(", ")
            )
        },
    )
}

/// A running headless Chromium and its private folder: the WebGPU backend's page, or any
/// page a test serves ([`super::page_server::PageServer`]). Killed with its whole process
/// group, and its folder removed, on drop.
pub struct Browser {
    child: Child,
    folder: strata_files::TempDir,
    /// Chromium's temporary folder where `folder` is too deep for it ([`temporary_folder`]).
    _temporary: Option<strata_files::TempDir>,
}

/// The longest path a Unix socket may have (`sun_path` holds 108 bytes on Linux, 104 on
/// macOS, with the terminating NUL).
const SOCKET_PATH_MAX: usize = 103;
/// What Chromium adds to its temporary folder for its profile lock's socket:
/// `/.org.chromium.Chromium.XXXXXX/SingletonSocket`.
const CHROMIUM_SOCKET_TAIL: usize = "/.org.chromium.Chromium.XXXXXX/SingletonSocket".len();

/// Chromium's temporary folder: `private` (the launch's own folder), or where the system's
/// temporary folder is deep enough that Chromium's socket path there would exceed what a
/// Unix socket may have (Chromium then fails to start: "Failed to create socket
/// directory"), a private folder of its own in `/tmp`, made the same way (mode 0700, a
/// random name made with `mkdir`, so nothing planted there is used).
/// (Elsewhere than on Unix Chromium's lock is no socket: the launch folder always.)
fn temporary_folder(private: &Path) -> Result<Option<strata_files::TempDir>, String> {
    if !cfg!(unix) || private.as_os_str().len() + CHROMIUM_SOCKET_TAIL <= SOCKET_PATH_MAX {
        return Ok(None);
    }
    strata_files::private_scratch_folder_in(Path::new("/tmp"), "strata-cr-")
        .map(Some)
        .map_err(|e| format!("cannot create a private temporary folder for Chromium in /tmp: {e}"))
}

/// Lines of Chromium's log that say nothing about WebGPU (no D-Bus in a container).
fn noise(line: &str) -> bool {
    line.contains("dbus") || line.contains("DBus") || line.trim().is_empty()
}

impl Browser {
    /// Starts `binary` headless on `url`, with WebGPU on (SwiftShader's Vulkan where no
    /// GPU is, as on CI).
    pub fn launch(binary: &Path, url: &str) -> Result<Self, String> {
        Self::start(binary, url, None)
    }

    /// [`Self::launch`] with the DevTools protocol on a pipe of its own (no port) and a
    /// 1280 × 1240 window: for what a test asks of the browser rather than the page, such
    /// as a screenshot ([`DevTools::screenshot`]).
    pub fn launch_with_devtools(binary: &Path, url: &str) -> Result<(Self, DevTools), String> {
        let (devtools, ends) = DevTools::pipes()?;
        Ok((Self::start(binary, url, Some(ends))?, devtools))
    }

    fn start(binary: &Path, url: &str, devtools: Option<BrowserEnds>) -> Result<Self, String> {
        let folder = strata_files::private_scratch_folder("strata-webgpu-")
            .map_err(|e| format!("cannot create a private folder for Chromium's profile: {e}"))?;
        let log = std::fs::File::create_new(folder.path().join("chromium.log"))
            .map_err(|e| format!("cannot create Chromium's log file: {e}"))?;
        let log_err = log.try_clone().map_err(|e| format!("cannot share Chromium's log file: {e}"))?;
        let temporary = temporary_folder(folder.path())?;
        let chromium_temporary = temporary.as_ref().map_or(folder.path(), |t| t.path());
        let mut command = Command::new(binary);
        command
            .arg("--headless=new")
            .arg(format!("--user-data-dir={}", folder.path().join("profile").display()))
            .args([
                "--enable-unsafe-webgpu",
                "--enable-webgpu-developer-features",
                "--enable-features=Vulkan",
                "--use-vulkan=native",
                "--disable-gpu-sandbox",
                "--no-first-run",
                "--no-default-browser-check",
                "--disable-extensions",
                "--disable-background-networking",
                "--disable-component-update",
                "--disable-sync",
                "--disable-default-apps",
                "--mute-audio",
                "--enable-logging=stderr",
                "--v=0",
            ])
            // Chromium refuses to run as root with its sandbox on.
            .args(running_as_root().then_some("--no-sandbox"))
            .args(devtools.as_ref().map_or(&[][..], |_| &["--remote-debugging-pipe", "--window-size=1280,1240"][..]))
            .arg(url)
            .env("XDG_CONFIG_HOME", folder.path().join("config"))
            .env("XDG_CACHE_HOME", folder.path().join("cache"))
            // Chromium puts its profile lock's socket folder (org.chromium.Chromium.*) in
            // the temporary folder and removes it only when it exits cleanly; it is
            // killed here (Drop), so in the shared /tmp one folder stayed behind per
            // launch (hundreds after a day of tests). In the private folder it goes with it
            // (or in a private one in /tmp where that is too deep for a socket).
            .env("TMPDIR", chromium_temporary)
            // macOS's Chromium reads its temporary folder from this, not TMPDIR.
            .env("MAC_CHROMIUM_TMPDIR", chromium_temporary)
            // A Vulkan layer switched on for strata's own Vulkan work (`xtask validate`)
            // is not Chromium's: its GPU process would load it and log into strata's log.
            .env_remove("VK_INSTANCE_LAYERS")
            .env_remove("VK_LOADER_LAYERS_ENABLE")
            .env_remove("VK_LAYER_SETTINGS_PATH")
            .stdin(Stdio::null())
            .stdout(log)
            .stderr(log_err);
        #[cfg(unix)]
        {
            use std::os::unix::process::CommandExt;
            command.process_group(0);
            if let Some(ends) = &devtools {
                use std::os::fd::AsRawFd;
                let (reads, writes) = (ends.reads.as_raw_fd(), ends.writes.as_raw_fd());
                // SAFETY: the closure runs in the child between fork and exec, where only
                // async-signal-safe functions may be called: it calls fcntl, dup2 and
                // close alone and allocates nothing (the error is built from errno). Both
                // descriptors are open: `ends` owns them until after `spawn` returns. Each
                // is first copied above 9, so that moving one to 3 or 4 cannot close the
                // other, and the copies dup2 makes have no close-on-exec flag. (Were std's
                // own exec-error pipe at 3 or 4, dup2 would close it and a failed exec
                // would show as the browser exiting at once, which `exited` reports.)
                unsafe {
                    command.pre_exec(move || {
                        let high_reads = libc::fcntl(reads, libc::F_DUPFD, 10);
                        let high_writes = libc::fcntl(writes, libc::F_DUPFD, 10);
                        if high_reads < 0
                            || high_writes < 0
                            || libc::dup2(high_reads, 3) < 0
                            || libc::dup2(high_writes, 4) < 0
                        {
                            return Err(std::io::Error::last_os_error());
                        }
                        libc::close(high_reads);
                        libc::close(high_writes);
                        Ok(())
                    });
                }
            }
        }
        #[cfg(not(unix))]
        if devtools.is_some() {
            return Err("the DevTools pipe needs a Unix system (Chromium's descriptors 3 and 4)".into());
        }
        let child = command.spawn().map_err(|e| format!("{} does not start: {e}", binary.display()))?;
        // The browser's ends now live in the browser; this process's copies go, so that
        // the reader sees the pipe close when the browser exits.
        drop(devtools);
        Ok(Self { child, folder, _temporary: temporary })
    }

    /// Why the browser is no longer running, with the end of its log; `None` while it runs.
    pub fn exited(&mut self) -> Option<String> {
        match self.child.try_wait() {
            Ok(Some(status)) => Some(format!("Chromium exited ({status}){}", self.log_tail())),
            Ok(None) => None,
            Err(error) => Some(format!("Chromium cannot be waited for: {error}")),
        }
    }

    /// The last lines of Chromium's log that are not noise, as `: line | line`, or
    /// nothing.
    pub fn log_tail(&self) -> String {
        let path = self.folder.path().join("chromium.log");
        let bytes = strata_files::read_regular_capped(&path, 64 << 20).unwrap_or_default();
        let text = String::from_utf8_lossy(&bytes);
        let lines: Vec<&str> = text.lines().filter(|line| !noise(line)).collect();
        let tail = &lines[lines.len().saturating_sub(4)..];
        if tail.is_empty() { String::new() } else { format!("; its log ends: {}", tail.join(" | ")) }
    }
}

#[cfg(unix)]
fn running_as_root() -> bool {
    // SAFETY: geteuid has no preconditions and cannot fail.
    unsafe { libc::geteuid() == 0 }
}

#[cfg(not(unix))]
fn running_as_root() -> bool {
    false
}

impl Drop for Browser {
    fn drop(&mut self) {
        #[cfg(unix)]
        if let Ok(group) = libc::pid_t::try_from(self.child.id()) {
            // SAFETY: kill has no memory preconditions; the group is the one the child
            // leads (process_group(0)), and the child is not waited for yet, so its id
            // is not reused.
            unsafe {
                libc::kill(-group, libc::SIGKILL);
            }
        }
        let _ = self.child.kill();
        let _ = self.child.wait();
        // The folder goes with `self.folder`.
    }
}

#[cfg(all(test, unix))]
mod tests {
    use super::*;

    /// A launch folder shallow enough keeps Chromium's temporary folder; one too deep for
    /// Chromium's socket gets a private folder in /tmp, short enough, removed when dropped.
    #[test]
    fn chromium_s_socket_path_fits_whatever_the_temporary_folder() {
        assert!(temporary_folder(Path::new("/tmp/strata-webgpu-0123456789")).unwrap().is_none());
        let deep = PathBuf::from(format!("/home/{}/strata-webgpu-0123456789", "x".repeat(60)));
        let temporary = temporary_folder(&deep).unwrap().expect("a folder in /tmp for a deep path");
        let path = temporary.path().to_path_buf();
        assert!(path.starts_with("/tmp") && path.is_dir(), "{}", path.display());
        assert!(path.as_os_str().len() + CHROMIUM_SOCKET_TAIL <= SOCKET_PATH_MAX, "{}", path.display());
        strata_files::check_private(&path).unwrap();
        drop(temporary);
        assert!(!path.exists(), "{} stays after the browser", path.display());
    }
}
