//! Whether another process is still running: how a leftover temporary file, named after
//! the process that wrote it, is told from one being written now (render's atomic file
//! writer, the pipeline cache file, `strata compare`'s folder lock).

use std::path::Path;

/// Whether process `pid` is running, as this process's `/proc` sees it (Linux and other
/// systems with `/proc`; elsewhere every process counts as running, so nothing of another
/// process is ever removed). A process of another PID namespace or another host sharing
/// the folder is not seen: its temporary would count as a dead one's (its rename would
/// then fail, naming the file; nothing half-written is left).
pub fn is_running(pid: u32) -> bool {
    if !Path::new("/proc/self").exists() {
        return true;
    }
    Path::new(&format!("/proc/{pid}")).exists()
}

/// The process id in a temporary file's `name` between `prefix` and `suffix`, if it is
/// written as `std::process::id()` writes it (digits, no leading zero).
pub fn writer_between(name: &str, prefix: &str, suffix: &str) -> Option<u32> {
    let digits = name.strip_prefix(prefix)?.strip_suffix(suffix)?;
    let pid: u32 = digits.parse().ok()?;
    (pid.to_string() == digits).then_some(pid)
}

/// The id of a process that has just ended (it runs `true` and waits for it): what tests
/// of leftover cleanup name as a dead writer. (The id may be reused by a new process
/// later; at once that is unlikely.)
pub fn an_ended_process() -> u32 {
    let mut child = std::process::Command::new("true").spawn().expect("`true` runs");
    let pid = child.id();
    let _ = child.wait();
    pid
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn this_process_runs_and_an_ended_one_does_not() {
        assert!(is_running(std::process::id()));
        assert_eq!(is_running(an_ended_process()), !Path::new("/proc/self").exists());
    }

    #[test]
    fn only_a_plain_process_id_is_read() {
        assert_eq!(writer_between(".a.tmp-123.exr", ".a.tmp-", ".exr"), Some(123));
        for name in [".a.tmp-0123.exr", ".a.tmp-+123.exr", ".a.tmp-.exr", ".a.tmp-12x.exr", ".b.tmp-123.exr"] {
            assert_eq!(writer_between(name, ".a.tmp-", ".exr"), None, "{name}");
        }
    }
}
