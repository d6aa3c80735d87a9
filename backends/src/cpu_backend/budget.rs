//! How much of the machine's memory the interpreter's own memory may take, and
//! allocation that fails with an error instead of aborting the process.
//!
//! A kernel's private, function and workgroup variables and its constants live in
//! memory the interpreter allocates itself, sized by the kernel's types: one
//! `var<private> big: array<u32, 100000000>` asked for 400 MB per invocation, and a batch
//! of 512 invocations aborted the process ("memory allocation failed"). Three caps:
//!
//! * [`SPACE_CAP`] per memory space of one invocation (private, function: a code's
//!   registers, its variables and values) or one workgroup (workgroup), and for the
//!   module's constants: checked when the kernel is compiled ([`super::decode`]), from
//!   the types, before anything of that size is allocated;
//! * [`BATCH_CAP`] for what one batch of invocations ([`super::batch`]) holds together:
//!   batches shrink to fit, and a single workgroup above it is refused;
//! * [`DISPATCH_CAP`] for all worker threads' batches together: fewer threads run.
//!
//! Buffers and textures are capped by the device limits ([`super::CpuBackend::new`]).
//! Every allocation whose size comes from the caller or the kernel goes through
//! [`try_zeroed`] or [`try_reserve`] (`try_reserve_exact`), so that what the machine
//! cannot give is a [`BackendError::OutOfMemory`], never an abort.
//!
//! Sizes come from the kernel or the caller: no arithmetic here may wrap or panic.

#![deny(clippy::arithmetic_side_effects)]

use crate::error::BackendError;

/// Bytes one memory space may take per invocation (private, function) or workgroup
/// (workgroup), and the module's constants together: 64 MiB. The largest kernel in the
/// repository takes some tens of kilobytes (`budget::tests` measures them).
pub(super) const SPACE_CAP: u64 = 64 << 20;

/// Bytes of private, function and workgroup memory one batch of invocations may hold
/// together: 1 GiB.
pub(super) const BATCH_CAP: u64 = 1 << 30;

/// Bytes the batches of all worker threads may hold together: 4 GiB (fewer threads run
/// where batches are large).
pub(super) const DISPATCH_CAP: u64 = 4 << 30;

/// A memory space of the interpreter, for messages.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Space {
    /// `var<private>`, per invocation.
    Private,
    /// A function's registers (its `var`s and values), per invocation.
    Function,
    /// `var<workgroup>`, per workgroup.
    Workgroup,
    /// The module's constant expressions, once per kernel.
    Constants,
}

impl Space {
    /// What the message calls `bytes` of this space.
    fn describe(self, bytes: u64) -> String {
        match self {
            Space::Private => format!("{bytes} bytes of private memory per invocation"),
            Space::Function => format!("{bytes} bytes of function memory per invocation"),
            Space::Workgroup => format!("{bytes} bytes of workgroup memory per workgroup"),
            Space::Constants => format!("{bytes} bytes of constants"),
        }
    }
}

/// `bytes` in the largest whole binary unit that divides it ("64 MiB"), for caps.
fn unit(bytes: u64) -> String {
    match bytes {
        b if b >= 1 << 30 && b.is_multiple_of(1 << 30) => format!("{} GiB", b >> 30),
        b if b >= 1 << 20 && b.is_multiple_of(1 << 20) => format!("{} MiB", b >> 20),
        b => format!("{b} bytes"),
    }
}

/// Bytes of `words` 32-bit words (saturating: a count past `u64::MAX` bytes is over
/// every cap anyway).
pub(super) fn bytes_of(words: u64) -> u64 {
    words.saturating_mul(4)
}

/// The error of kernel `kernel` asking for `what` beyond `cap` bytes.
pub(super) fn over_cap(kernel: &str, what: &str, cap: u64) -> BackendError {
    BackendError::OutOfMemory {
        backend: "cpu".into(),
        operation: format!("kernel `{kernel}`: {what}, more than the interpreter's {} cap", unit(cap)),
    }
}

/// Whether `words` words of `space` fit in [`SPACE_CAP`]; the error names the kernel,
/// the space, the bytes and the cap.
pub(super) fn check_space(kernel: &str, space: Space, words: u64) -> Result<(), BackendError> {
    let bytes = bytes_of(words);
    if bytes > SPACE_CAP { Err(over_cap(kernel, &space.describe(bytes), SPACE_CAP)) } else { Ok(()) }
}

/// `a + b` words, or the error of `space` asking for more than `u64` holds.
pub(super) fn add_words(kernel: &str, space: Space, a: u64, b: u64) -> Result<u64, BackendError> {
    a.checked_add(b).ok_or_else(|| over_cap(kernel, &space.describe(u64::MAX), SPACE_CAP))
}

/// How a dispatch's batches fit the caps: workgroups per batch and worker threads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct BatchPlan {
    /// Workgroups per batch (at least 1).
    pub workgroups: u64,
    /// Worker threads (at least 1).
    pub threads: usize,
}

/// The batches of kernel `kernel` whose invocations take `per_invocation` bytes each
/// (private and function memory) and whose workgroups of `invocations` take
/// `per_workgroup` bytes of workgroup memory more: at most `wanted` workgroups per
/// batch, as many as fit in [`BATCH_CAP`], on at most `threads` threads, as many as fit
/// in [`DISPATCH_CAP`]. An error where one workgroup alone is over [`BATCH_CAP`].
pub(super) fn plan_batches(
    kernel: &str,
    per_invocation: u64,
    invocations: u64,
    per_workgroup: u64,
    wanted: u64,
    threads: usize,
) -> Result<BatchPlan, BackendError> {
    let workgroup = per_invocation.saturating_mul(invocations).saturating_add(per_workgroup);
    if workgroup > BATCH_CAP {
        let what = format!(
            "{workgroup} bytes of private, function and workgroup memory for a workgroup of {invocations} invocations"
        );
        return Err(over_cap(kernel, &what, BATCH_CAP));
    }
    let fit = BATCH_CAP.checked_div(workgroup).unwrap_or(u64::MAX);
    let workgroups = wanted.min(fit).max(1);
    let batch = workgroup.saturating_mul(workgroups).max(1);
    let fit_threads = usize::try_from(DISPATCH_CAP.checked_div(batch).unwrap_or(1)).unwrap_or(usize::MAX);
    Ok(BatchPlan { workgroups, threads: threads.min(fit_threads).max(1) })
}

/// `len` zero words, or [`BackendError::OutOfMemory`] naming `what` where the machine
/// cannot give them (instead of aborting).
pub(super) fn try_zeroed(len: usize, what: impl FnOnce() -> String) -> Result<Vec<u32>, BackendError> {
    let mut words = Vec::new();
    try_reserve(&mut words, len, what)?;
    words.resize(len, 0);
    Ok(words)
}

/// Makes room for `additional` more elements in `vec` (exactly), or
/// [`BackendError::OutOfMemory`] naming `what`.
pub(super) fn try_reserve<T>(
    vec: &mut Vec<T>,
    additional: usize,
    what: impl FnOnce() -> String,
) -> Result<(), BackendError> {
    vec.try_reserve_exact(additional)
        .map_err(|_| BackendError::OutOfMemory { backend: "cpu".into(), operation: what() })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn caps_are_named_in_binary_units() {
        assert_eq!(unit(SPACE_CAP), "64 MiB");
        assert_eq!(unit(BATCH_CAP), "1 GiB");
        assert_eq!(unit(1000), "1000 bytes");
        let error = check_space("main", Space::Private, 100_000_000).unwrap_err();
        assert_eq!(
            error.to_string(),
            "cpu: out of memory in kernel `main`: 400000000 bytes of private memory per invocation, \
             more than the interpreter's 64 MiB cap"
        );
        assert!(check_space("main", Space::Function, SPACE_CAP / 4).is_ok());
        assert!(check_space("main", Space::Function, SPACE_CAP / 4 + 1).is_err());
        // A count whose bytes pass u64::MAX saturates and is over the cap.
        assert!(check_space("main", Space::Workgroup, u64::MAX).is_err());
        assert!(add_words("main", Space::Private, u64::MAX, 1).is_err());
    }

    #[test]
    fn batches_shrink_to_the_caps_and_a_workgroup_over_them_is_refused() {
        // Small invocations: the batch the kernel wants, every thread.
        assert_eq!(plan_batches("k", 1024, 64, 4096, 8, 16).unwrap(), BatchPlan { workgroups: 8, threads: 16 });
        // 32 MiB per invocation, one-invocation workgroups: 32 per batch, 4 threads.
        let plan = plan_batches("k", 32 << 20, 1, 0, 512, 16).unwrap();
        assert_eq!(plan, BatchPlan { workgroups: 32, threads: 4 });
        // A workgroup of 64 invocations of 32 MiB: 2 GiB, refused.
        let error = plan_batches("k", 32 << 20, 64, 0, 1, 16).unwrap_err();
        assert!(error.to_string().contains("2147483648 bytes of private, function and workgroup memory"), "{error}");
        assert!(error.to_string().ends_with("more than the interpreter's 1 GiB cap"), "{error}");
        // Nothing at all (an empty kernel): the batch wanted, never a division by zero.
        assert_eq!(plan_batches("k", 0, 1, 0, 512, 2).unwrap(), BatchPlan { workgroups: 512, threads: 2 });
    }

    /// The caps leave every registry kernel room to spare: private and function memory
    /// per invocation and workgroup memory far below [`SPACE_CAP`], and batches as
    /// large as [`super::super::batch`] makes them (none shrunk).
    #[test]
    #[cfg_attr(miri, ignore = "compiles every registry kernel: minutes under Miri")]
    fn every_registry_kernel_is_far_below_the_caps() {
        let registry = strata_kernels::Registry::shared().expect("the registry loads");
        let mut largest = (0u64, String::new());
        for kernel in registry.kernels() {
            let program = super::super::decode::compile_program(kernel).expect("compiles");
            let registers: u64 = program.codes.iter().map(|code| code.template.len() as u64).sum();
            let per_invocation = bytes_of(program.private_init.len() as u64 + registers);
            let workgroup = bytes_of(u64::from(program.workgroup_words));
            let invocations = u64::from(kernel.invocations());
            let wanted = super::super::batch::workgroups_per_batch(&program, u64::MAX);
            let plan = plan_batches(kernel.name(), per_invocation, invocations, workgroup, wanted, 2).unwrap();
            assert_eq!(plan, BatchPlan { workgroups: wanted, threads: 2 }, "{}", kernel.name());
            if per_invocation.max(workgroup) > largest.0 {
                largest = (per_invocation.max(workgroup), kernel.name().to_string());
            }
        }
        eprintln!("largest: `{}`, {} bytes per invocation or workgroup", largest.1, largest.0);
        assert!(largest.0 * 64 < SPACE_CAP, "`{}` takes {} bytes", largest.1, largest.0);
    }

    #[test]
    fn an_allocation_the_machine_cannot_give_is_an_error() {
        let error = try_zeroed(usize::MAX / 2, || "a test allocation".into()).unwrap_err();
        assert_eq!(error.to_string(), "cpu: out of memory in a test allocation");
        assert_eq!(try_zeroed(3, String::new).unwrap(), [0; 3]);
    }
}
