//! The record of one `strata compare` run: what was run (command line, settings, scene,
//! reference), on what (backend and device, crate version, git revision) and when, and
//! how long each method took per frame. Written as `run.json` and shown at the foot of
//! `report.html` and `summary.txt`, so a folder of results says where it came from.

use serde::Serialize;

/// The git revision the binary was built from (`build.rs`), or "unknown" outside a
/// git checkout.
pub const GIT_REVISION: &str = env!("STRATA_GIT_REVISION");

/// Everything a reader needs to know to trust, or redo, one comparison.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RunRecord {
    /// The command line as typed (arguments shell-quoted where needed).
    pub command_line: String,
    /// The backend and device (`Backend::info().summary()`).
    pub backend: String,
    /// The `strata` crate's version.
    pub version: String,
    /// The git revision of the build ([`GIT_REVISION`]).
    pub git_revision: String,
    /// When the run started, RFC 3339 in UTC.
    pub date: String,
    /// The scene's name (file stem, or "default scene").
    pub scene: String,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Frames per seed.
    pub frames: u32,
    /// Seeds (independent renders per method).
    pub seeds: u32,
    /// Temporal reuse (false: frames accumulated).
    pub temporal: bool,
    /// How the reference was obtained: a file, or path tracing at N spp (and how long).
    pub reference: String,
    /// The settings every method shared, by name.
    pub settings: serde_json::Map<String, serde_json::Value>,
    /// The scene loader's warnings (what it left out or replaced, naming file and line).
    pub warnings: Vec<String>,
    /// Per method: mean wall time of one frame in milliseconds (rendering only, on
    /// `backend`; not the measuring or writing).
    pub frame_ms: Vec<MethodTime>,
    /// Wall time of the whole run in seconds, reference included.
    pub seconds: f64,
}

/// One method's time per frame.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MethodTime {
    /// The method's name.
    pub method: String,
    /// Mean wall time of one frame in milliseconds.
    pub frame_ms: f64,
}

impl RunRecord {
    /// The record as indented JSON.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("a run record serialises") + "\n"
    }

    /// The record as `name: value` lines, for `summary.txt` and the report page.
    pub fn lines(&self) -> Vec<(String, String)> {
        let mut lines = vec![
            ("command".to_string(), self.command_line.clone()),
            ("backend".to_string(), self.backend.clone()),
            ("strata".to_string(), format!("{} (git {})", self.version, self.git_revision)),
            ("date".to_string(), self.date.clone()),
            (
                "scene".to_string(),
                format!(
                    "{}, {}x{}, {} frames x {} seeds, {}",
                    self.scene,
                    self.width,
                    self.height,
                    self.frames,
                    self.seeds,
                    if self.temporal { "temporal reuse" } else { "frames accumulated" }
                ),
            ),
            ("reference".to_string(), self.reference.clone()),
        ];
        let settings: Vec<String> = self.settings.iter().map(|(k, v)| format!("{k} = {v}")).collect();
        lines.push(("settings".to_string(), settings.join(", ")));
        if !self.warnings.is_empty() {
            lines.push((format!("scene warnings ({})", self.warnings.len()), self.warnings.join("; ")));
        }
        let times: Vec<String> = self.frame_ms.iter().map(|t| format!("{} {:.1} ms", t.method, t.frame_ms)).collect();
        lines.push(("time per frame".to_string(), times.join(", ")));
        lines.push(("whole run".to_string(), crate::progress::words(std::time::Duration::from_secs_f64(self.seconds))));
        lines
    }
}

/// This process's command line, each argument quoted for a POSIX shell where it needs
/// it. Arguments need not be UTF-8 (a path on Linux is any bytes but NUL): such an
/// argument is written in the `$'...'` quoting of bash, zsh and POSIX 2024 shells, with
/// every byte that is not printable ASCII as `\xHH`, so the line still reproduces the run.
pub fn command_line() -> String {
    let mut args = std::env::args_os();
    let program = args.next().map(|p| {
        let path = std::path::PathBuf::from(&p);
        path.file_name().map(std::ffi::OsStr::to_os_string).unwrap_or(p)
    });
    program.into_iter().chain(args).map(|a| shell_quote_os(&a)).collect::<Vec<_>>().join(" ")
}

/// `argument` as one word of a POSIX shell command, whatever its bytes.
fn shell_quote_os(argument: &std::ffi::OsStr) -> String {
    if let Some(text) = argument.to_str() {
        return shell_quote(text);
    }
    let bytes = argument.as_encoded_bytes();
    let mut quoted = String::from("$'");
    for &byte in bytes {
        match byte {
            b'\\' | b'\'' => {
                quoted.push('\\');
                quoted.push(byte as char);
            }
            0x20..=0x7e => quoted.push(byte as char),
            _ => quoted.push_str(&format!("\\x{byte:02x}")),
        }
    }
    quoted + "'"
}

/// `text` as one word of a POSIX shell command.
fn shell_quote(text: &str) -> String {
    let plain = !text.is_empty() && text.chars().all(|c| c.is_ascii_alphanumeric() || "-_./=,:+@%".contains(c));
    if plain { text.to_string() } else { format!("'{}'", text.replace('\'', "'\\''")) }
}

/// Now, RFC 3339 in UTC to the second.
pub fn now_rfc3339() -> String {
    humantime::format_rfc3339_seconds(std::time::SystemTime::now()).to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arguments_are_quoted_only_where_a_shell_needs_it() {
        assert_eq!(shell_quote("--width"), "--width");
        assert_eq!(shell_quote("scenes/cornell-box/scene.json"), "scenes/cornell-box/scene.json");
        assert_eq!(shell_quote("a b"), "'a b'");
        assert_eq!(shell_quote("it's"), "'it'\\''s'");
        assert_eq!(shell_quote(""), "''");
    }

    #[cfg(unix)]
    #[test]
    fn arguments_that_are_not_utf8_are_quoted_byte_for_byte() {
        use std::os::unix::ffi::OsStrExt;
        let argument = std::ffi::OsStr::from_bytes(b"out/bad\xff it's\\");
        assert_eq!(shell_quote_os(argument), "$'out/bad\\xff it\\'s\\\\'");
        assert_eq!(shell_quote_os(std::ffi::OsStr::new("a b")), "'a b'");
    }

    #[test]
    fn the_date_is_rfc3339_utc() {
        let date = now_rfc3339();
        assert_eq!(date.len(), "2026-11-25T08:00:00Z".len(), "{date}");
        assert!(date.ends_with('Z') && date.as_bytes()[10] == b'T', "{date}");
    }
}
