//! Whether another process is still running: how a leftover temporary file, named after
//! the process that wrote it, is told from one being written now (render's atomic file
//! writer, the pipeline cache file, `strata compare`'s folder lock).

pub use strata_files::process_is_running as is_running;

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
        assert_eq!(is_running(an_ended_process()), !std::path::Path::new("/proc/self").exists());
    }
}
