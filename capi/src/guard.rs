//! What keeps the C boundary safe: the table of live handles, failures as a status and a
//! message, and the guard every exported call runs inside (panics caught, the outcome
//! written into the caller's `StrataError`).
//!
//! Handles. The pointer a C caller holds (`StrataVkPass *`, `StrataVkBindings *`) is not
//! an address: its value is a number handed out once from a counter (1, 2, 3, ... shared
//! by passes and bindings, never reused), and the table maps it to the object, kept in an
//! [`Arc`]. Nothing is ever read through the pointer: a null, foreign or destroyed value,
//! or one of the other kind, is simply not found and is refused, and since no value is
//! handed out twice, a destroyed handle stays refused whatever is made after it.
//!
//! Threads. A call looks its handles up under the table's lock, clones their `Arc`s and
//! releases the lock before any work, so calls on one pass run at the same time and each
//! has shared access (`&`) to the pass: no `&mut` is ever made from the table. A
//! destruction takes the object out of the table, under the lock, only if the table's
//! `Arc` is the only one ([`Arc::try_unwrap`]); while a call on another thread holds a
//! clone, the destruction is refused, so nothing is freed under a running call.

use crate::{Pass, STRATA_ERROR_MESSAGE_BYTES, StrataError, StrataStatus, StrataVkBindings, StrataVkPass};
use std::collections::BTreeMap;
use std::ffi::c_char;
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};
use strata_embed::{AshBindings, EmbedError};

/// A live pass and how many of its bindings live.
struct PassEntry {
    pass: Arc<Pass>,
    bindings: usize,
}

/// Live bindings and the handle of the pass that made them.
struct BindingsEntry {
    bindings: Arc<AshBindings>,
    owner: u64,
}

/// Every live handle by its value, and the next value to hand out.
struct Table {
    next: u64,
    passes: BTreeMap<u64, PassEntry>,
    bindings: BTreeMap<u64, BindingsEntry>,
}

static TABLE: Mutex<Table> = Mutex::new(Table { next: 1, passes: BTreeMap::new(), bindings: BTreeMap::new() });

/// The table of live handles (a panic elsewhere never leaves it unusable: every change
/// to it is made whole before anything that could panic).
fn table() -> MutexGuard<'static, Table> {
    TABLE.lock().unwrap_or_else(PoisonError::into_inner)
}

/// The value of a handle (0, never handed out, where it does not fit).
fn value_of<T>(handle: *const T) -> u64 {
    u64::try_from(handle.addr()).unwrap_or(0)
}

/// A handle value, never handed out before and never again: reserved before the object
/// it stands for is made.
pub(crate) struct NewHandle(u64);

impl NewHandle {
    /// The next value.
    pub(crate) fn reserve() -> Result<Self, Failure> {
        let mut table = table();
        let value = table.next;
        // The value must be a pointer's (usize) and the counter must not wrap: else no
        // handle is made any more (never one handed out before).
        let next = value.checked_add(1).filter(|_| usize::try_from(value).is_ok()).ok_or_else(|| Failure {
            status: StrataStatus::Internal,
            message: "this process has used up the library's handle values".into(),
        })?;
        table.next = next;
        Ok(Self(value))
    }

    /// The handle as C holds it: a value, not an address (never dereferenced).
    fn handle<T>(&self) -> *mut T {
        std::ptr::without_provenance_mut(usize::try_from(self.0).expect("checked by reserve"))
    }

    /// Enters `pass` into the table under this value; its handle.
    pub(crate) fn insert_pass(self, pass: Pass) -> *mut StrataVkPass {
        let handle = self.handle();
        table().passes.insert(self.0, PassEntry { pass: Arc::new(pass), bindings: 0 });
        handle
    }

    /// Enters `bindings` made by `owner` into the table under this value; their handle.
    /// The caller holds `owner`'s `Arc` (from [`pass_of`]), so the pass is still live.
    pub(crate) fn insert_bindings(self, bindings: AshBindings, owner: *const StrataVkPass) -> *mut StrataVkBindings {
        let handle = self.handle();
        let mut table = table();
        let owner = value_of(owner);
        table.passes.get_mut(&owner).expect("a pass is not destroyed while a call holds it").bindings += 1;
        table.bindings.insert(self.0, BindingsEntry { bindings: Arc::new(bindings), owner });
        handle
    }
}

/// The live pass behind `pass`, shared with the table for the call's duration.
pub(crate) fn pass_of(pass: *const StrataVkPass, argument: &str) -> Result<Arc<Pass>, Failure> {
    if pass.is_null() {
        return Err(invalid(format!("{argument} is NULL")));
    }
    let table = table();
    let entry = table
        .passes
        .get(&value_of(pass))
        .ok_or_else(|| invalid(format!("{argument} is not a live pass made by strata_vk_create")))?;
    Ok(Arc::clone(&entry.pass))
}

/// The live bindings behind `bindings`, made by `pass`, shared with the table for the
/// call's duration.
pub(crate) fn bindings_of(
    bindings: *const StrataVkBindings,
    pass: *const StrataVkPass,
) -> Result<Arc<AshBindings>, Failure> {
    if bindings.is_null() {
        return Err(invalid("bindings is NULL"));
    }
    match table().bindings.get(&value_of(bindings)) {
        Some(entry) if entry.owner == value_of(pass) => Ok(Arc::clone(&entry.bindings)),
        Some(_) => Err(invalid("bindings were made by another pass")),
        None => Err(invalid("bindings is not live bindings made by strata_vk_bind")),
    }
}

/// Takes the live `bindings` of the live `pass` out of the table: the bindings, to be
/// destroyed, and the pass (shared for the call's duration). Refused while a call on
/// another thread uses them.
pub(crate) fn remove_bindings(
    bindings: *const StrataVkBindings,
    pass: *const StrataVkPass,
) -> Result<(Arc<Pass>, AshBindings), Failure> {
    if pass.is_null() {
        return Err(invalid("pass is NULL"));
    }
    let (value, owner) = (value_of(bindings), value_of(pass));
    let mut table = table();
    if !table.passes.contains_key(&owner) {
        return Err(invalid("pass is not a live pass made by strata_vk_create"));
    }
    let entry = match table.bindings.remove(&value) {
        Some(entry) if entry.owner == owner => entry,
        Some(entry) => {
            table.bindings.insert(value, entry);
            return Err(invalid("bindings were made by another pass"));
        }
        None => return Err(invalid("bindings is not live bindings made by strata_vk_bind")),
    };
    let bindings = match Arc::try_unwrap(entry.bindings) {
        Ok(bindings) => bindings,
        Err(shared) => {
            table.bindings.insert(value, BindingsEntry { bindings: shared, owner });
            return Err(invalid(
                "bindings are in use by a call on another thread (strata_vk_record_*): destroy them once it has returned",
            ));
        }
    };
    let pass = table.passes.get_mut(&owner).expect("checked above");
    pass.bindings -= 1;
    Ok((Arc::clone(&pass.pass), bindings))
}

/// Takes the live `pass` out of the table, to be destroyed. Refused while bindings of it
/// live or a call on another thread uses it.
pub(crate) fn remove_pass(pass: *const StrataVkPass) -> Result<Pass, Failure> {
    let value = value_of(pass);
    let mut table = table();
    let entry =
        table.passes.remove(&value).ok_or_else(|| invalid("pass is not a live pass made by strata_vk_create"))?;
    if entry.bindings > 0 {
        let message = format!(
            "{} bindings of this pass are still live: destroy them first (strata_vk_destroy_bindings)",
            entry.bindings
        );
        table.passes.insert(value, entry);
        return Err(invalid(message));
    }
    Arc::try_unwrap(entry.pass).map_err(|shared| {
        table.passes.insert(value, PassEntry { pass: shared, bindings: 0 });
        invalid("pass is in use by a call on another thread: destroy it once that call has returned")
    })
}

/// Why a call failed.
pub(crate) struct Failure {
    pub(crate) status: StrataStatus,
    pub(crate) message: String,
}

pub(crate) fn invalid(message: impl Into<String>) -> Failure {
    Failure { status: StrataStatus::InvalidArgument, message: message.into() }
}

impl From<EmbedError> for Failure {
    fn from(error: EmbedError) -> Self {
        // Every variant by name: a new one must be given its status here.
        let status = match &error {
            EmbedError::Setting(_) => StrataStatus::Settings,
            EmbedError::ImageSize { .. } => StrataStatus::ImageSize,
            EmbedError::BufferTooSmall { .. }
            | EmbedError::BufferOffset { .. }
            | EmbedError::BufferUsage { .. }
            | EmbedError::BufferRange { .. }
            | EmbedError::BufferEnd { .. }
            | EmbedError::BufferOverlap { .. } => StrataStatus::Buffer,
            EmbedError::DeviceLimit { .. } | EmbedError::UnsupportedFeature { .. } => StrataStatus::Device,
            EmbedError::NoResampleBuffers => StrataStatus::InvalidArgument,
            EmbedError::Api { .. } => StrataStatus::Vulkan,
            EmbedError::Kernel(_) => StrataStatus::Internal,
        };
        Failure { status, message: error.to_string() }
    }
}

/// Writes `status` and `message` into `error` (if not null).
///
/// # Safety
/// `error` is null or points to a writable `StrataError`.
pub(crate) unsafe fn report(error: *mut StrataError, status: StrataStatus, message: &str) {
    if error.is_null() {
        return;
    }
    let mut end = message.len().min(STRATA_ERROR_MESSAGE_BYTES - 1);
    while !message.is_char_boundary(end) {
        end -= 1;
    }
    // SAFETY: per this function's contract; written through raw pointers, never reading
    // what the caller's struct held (its status may be any bits).
    unsafe {
        std::ptr::addr_of_mut!((*error).status).write(status);
        let text = std::ptr::addr_of_mut!((*error).message).cast::<c_char>();
        for (i, &byte) in message.as_bytes()[..end].iter().enumerate() {
            text.add(i).write(byte as c_char);
        }
        text.add(end).write(0);
    }
}

/// Runs `call`, catching panics, and reports its outcome through `error`.
///
/// # Safety
/// `error` is null or points to a writable `StrataError`.
pub(crate) unsafe fn guarded(error: *mut StrataError, call: impl FnOnce() -> Result<(), Failure>) -> StrataStatus {
    let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(call)).unwrap_or_else(|payload| {
        let what = payload
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown panic".into());
        Err(Failure { status: StrataStatus::Internal, message: format!("internal error (a bug of strata-vk): {what}") })
    });
    let (status, message) = match outcome {
        Ok(()) => (StrataStatus::Ok, String::new()),
        Err(failure) => (failure.status, failure.message),
    };
    // SAFETY: per this function's contract.
    unsafe { report(error, status, &message) };
    status
}
