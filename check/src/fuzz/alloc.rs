//! A global allocator for fuzzing processes: the system allocator, except that while a
//! campaign runs, one allocation larger than the limit ([`set_allocation_limit`]) is a
//! finding: a loader allocated from a declared count it did not check. The input is
//! written as `huge-<hash>` in the campaign's crash folder and the process exits with
//! status 3 (an allocation that large could exhaust memory, which no `catch_unwind`
//! would see). Declared in the fuzzing binaries with
//! `#[global_allocator] static ALLOCATOR: GuardedAllocator = GuardedAllocator;`.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

/// Bytes one allocation may take while armed; 0: unlimited.
static LIMIT: AtomicUsize = AtomicUsize::new(0);

/// Who reports an allocation over the limit (the campaign engine registers itself; this
/// module knows nothing of it). Never returns: it writes the input and exits.
static ON_HUGE: std::sync::OnceLock<fn(usize)> = std::sync::OnceLock::new();

/// Registers `report` as the handler of an allocation over the limit (the first
/// registration stays).
pub fn on_huge_allocation(report: fn(usize)) {
    let _ = ON_HUGE.set(report);
}

/// Reports an allocation of `size` bytes over the limit through the registered handler.
fn report(size: usize) {
    if let Some(report) = ON_HUGE.get() {
        report(size);
    }
}

/// The system allocator with the limit of [`set_allocation_limit`].
pub struct GuardedAllocator;

/// Arms the guard at `bytes` per allocation (0 disarms it). Returns the previous limit.
pub fn set_allocation_limit(bytes: usize) -> usize {
    LIMIT.swap(bytes, Ordering::SeqCst)
}

/// Whether an allocation of `size` bytes is over an armed limit; disarms the guard then,
/// so that reporting it can allocate.
fn over_limit(size: usize) -> bool {
    let limit = LIMIT.load(Ordering::Relaxed);
    limit != 0 && size > limit && LIMIT.compare_exchange(limit, 0, Ordering::SeqCst, Ordering::SeqCst).is_ok()
}

// SAFETY: every call is forwarded to `System` with the same arguments; the report on an
// oversized request runs before forwarding and never unwinds (it exits the process).
unsafe impl GlobalAlloc for GuardedAllocator {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if over_limit(layout.size()) {
            report(layout.size());
        }
        // SAFETY: forwarded unchanged.
        unsafe { System.alloc(layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        if over_limit(layout.size()) {
            report(layout.size());
        }
        // SAFETY: forwarded unchanged.
        unsafe { System.alloc_zeroed(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: forwarded unchanged.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if over_limit(new_size) {
            report(new_size);
        }
        // SAFETY: forwarded unchanged.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}
