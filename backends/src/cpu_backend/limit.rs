//! The interpreter's time limit per dispatch ([`super::CpuOptions::time_limit`]): a
//! kernel that never ends (`loop {}`, a `while` whose condition never changes, a spin
//! on memory no other workgroup will write) ends the dispatch with an error naming the
//! kernel, the limit and where an invocation was, instead of hanging the caller.
//!
//! Why wall time and not a count of instructions: the count a dispatch may take depends
//! on the kernel and the build (a debug build runs many times slower than a release
//! one), while what the caller cannot wait past is time. The default,
//! [`DEFAULT_TIME_LIMIT`], is 60 s: far above any single dispatch of the project's own
//! tests and benchmarks on the interpreter (the longest take seconds, in debug), so
//! that no real work reaches it, and short enough that a hung kernel is reported while
//! someone still waits for it. Set it per backend ([`super::CpuOptions::time_limit`];
//! `None`: no limit) or per run (`cargo xtask run --time-limit SECONDS`).
//!
//! Cost: every kernel that runs forever runs a backward jump forever (loops are the
//! only backward jumps of the bytecode), and every group the scheduler starts passes
//! [`super::interp`]'s group loop: both take one unit of *fuel*, a counter of the
//! worker thread; only when [`FUEL`] units are spent is the clock read (and the flag
//! that stops every thread looked at). One decrement and one well-predicted branch per
//! loop iteration of a whole group, not per invocation: not measurable (docs/kernels.md,
//! "The time limit and the interpreter as a sanitizer", gives the timings).
//!
//! Every worker thread stops: the first thread past the deadline raises the dispatch's
//! stop flag and each other thread sees it at its next clock read; a thread that
//! fails for another reason raises it too, so that the others do not run on.

use super::error::invalid;
use crate::error::BackendError;
use std::sync::atomic::{AtomicU8, AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// The interpreter's default time limit per dispatch (module documentation says why).
pub const DEFAULT_TIME_LIMIT: Duration = Duration::from_secs(60);

/// Fuel units (backward jumps and groups started) between two reads of the clock: a
/// few microseconds of the shortest loop (`loop {}`: one jump per iteration), some
/// milliseconds of long loop bodies over wide groups.
pub(super) const FUEL: u32 = 1 << 12;

/// Nothing stopped the dispatch.
const RUNNING: u8 = 0;
/// The deadline passed.
const EXPIRED: u8 = 1;
/// A thread failed for another reason.
const FAILED: u8 = 2;

/// Marks the error of a thread that stopped because another one failed (never
/// returned from a dispatch: the failing thread's error is).
const ABANDONED: &str = "stopped: another worker thread failed";

/// One dispatch's deadline and stop flag, shared by its worker threads.
pub(super) struct Limit {
    /// When the dispatch must have ended (`None`: never).
    deadline: Option<Instant>,
    /// The limit, for messages.
    limit: Option<Duration>,
    /// [`RUNNING`], [`EXPIRED`] or [`FAILED`].
    state: AtomicU8,
    /// The dispatch's workgroups, and how many have finished (for the message: a dispatch
    /// that is only large finishes some, an endless loop in every workgroup none).
    workgroups: AtomicU64,
    finished: AtomicU64,
}

/// Why a worker must stop, when its fuel is spent.
pub(super) enum Stop {
    /// The dispatch ran past its time limit.
    Expired,
    /// Another worker thread failed.
    Abandon,
}

impl Limit {
    /// The limit of a dispatch starting now (`None`: no limit).
    pub(super) fn starting_now(limit: Option<Duration>) -> Self {
        Self {
            deadline: limit.and_then(|l| Instant::now().checked_add(l)),
            limit,
            state: AtomicU8::new(RUNNING),
            workgroups: AtomicU64::new(0),
            finished: AtomicU64::new(0),
        }
    }

    /// The dispatch has `workgroups` workgroups.
    pub(super) fn set_workgroups(&self, workgroups: u64) {
        self.workgroups.store(workgroups, Ordering::Relaxed);
    }

    /// `count` more workgroups have finished.
    pub(super) fn finished(&self, count: u64) {
        self.finished.fetch_add(count, Ordering::Relaxed);
    }

    /// Whether the worker must stop (read when its fuel is spent).
    #[cold]
    #[inline(never)]
    pub(super) fn poll(&self) -> Option<Stop> {
        match self.state.load(Ordering::Relaxed) {
            EXPIRED => return Some(Stop::Expired),
            FAILED => return Some(Stop::Abandon),
            _ => {}
        }
        if self.deadline.is_some_and(|deadline| Instant::now() >= deadline) {
            let _ = self.state.compare_exchange(RUNNING, EXPIRED, Ordering::Relaxed, Ordering::Relaxed);
            return Some(Stop::Expired);
        }
        None
    }

    /// Raises the stop flag for a thread that failed (unless the deadline already did).
    pub(super) fn fail(&self) {
        let _ = self.state.compare_exchange(RUNNING, FAILED, Ordering::Relaxed, Ordering::Relaxed);
    }

    /// The error of a worker stopped by `stop` while an invocation was at `place`
    /// (`file:line`) in function `function` of `kernel`.
    pub(super) fn error(&self, stop: Stop, kernel: &str, place: &str, function: &str) -> BackendError {
        match stop {
            Stop::Abandon => invalid(kernel, ABANDONED.into()),
            Stop::Expired => {
                let limit = self.limit.map_or_else(|| "none".to_string(), describe);
                let (finished, workgroups) =
                    (self.finished.load(Ordering::Relaxed), self.workgroups.load(Ordering::Relaxed));
                let hint = if finished == 0 {
                    "a loop that never ends?"
                } else {
                    "a dispatch too large for the limit, or a loop that never ends in some workgroups?"
                };
                invalid(
                    kernel,
                    format!(
                        "the dispatch ran past the interpreter's time limit of {limit} (CpuOptions::time_limit, \
                         `xtask run --time-limit`): an invocation was at {place} in `{function}`, \
                         {finished} of {workgroups} workgroups done ({hint})"
                    ),
                )
            }
        }
    }
}

/// Whether `error` is the error of a thread stopped because another one failed.
pub(super) fn abandoned(error: &BackendError) -> bool {
    matches!(error, BackendError::Validation { message, .. } if message == ABANDONED)
}

/// A limit as people write it: `200 ms`, `60 s`, `1.5 s`.
pub(super) fn describe(limit: Duration) -> String {
    if limit < Duration::from_secs(1) {
        format!("{} ms", limit.as_millis())
    } else if limit.subsec_millis() == 0 {
        format!("{} s", limit.as_secs())
    } else {
        format!("{:.3} s", limit.as_secs_f64())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_are_written_as_people_write_them() {
        assert_eq!(describe(Duration::from_millis(200)), "200 ms");
        assert_eq!(describe(Duration::from_secs(60)), "60 s");
        assert_eq!(describe(Duration::from_millis(1500)), "1.500 s");
    }

    #[test]
    fn a_limit_expires_and_stops_everyone_while_no_limit_never_does() {
        let limit = Limit::starting_now(Some(Duration::ZERO));
        assert!(matches!(limit.poll(), Some(Stop::Expired)));
        limit.fail();
        assert!(matches!(limit.poll(), Some(Stop::Expired)), "the first reason stays");
        let none = Limit::starting_now(None);
        assert!(none.poll().is_none());
        none.fail();
        assert!(matches!(none.poll(), Some(Stop::Abandon)));
        assert!(abandoned(&none.error(Stop::Abandon, "k", "k.wgsl:1", "main")));
        assert!(!abandoned(&limit.error(Stop::Expired, "k", "k.wgsl:1", "main")));
    }
}
