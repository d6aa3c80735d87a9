//! What keeps the C boundary safe: the table of live handles (a pointer is dereferenced
//! only if this library made it and has not destroyed it), failures as a status and a
//! message, and the guard every exported call runs inside (panics caught, the outcome
//! written into the caller's `StrataError`).

use crate::{STRATA_ERROR_MESSAGE_BYTES, StrataError, StrataStatus, StrataVkBindings, StrataVkPass};
use std::ffi::c_char;
use strata_embed::EmbedError;

/// A live handle: a pass (with how many of its bindings live) or bindings (with their
/// pass).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Live {
    Pass { bindings: usize },
    Bindings { owner: usize },
}

/// Every live handle, by address: a pointer handed in is dereferenced only if it is here
/// with the right kind.
pub(crate) static LIVE: std::sync::Mutex<Vec<(usize, Live)>> = std::sync::Mutex::new(Vec::new());

/// The table of live handles (a panic elsewhere never leaves it unusable).
pub(crate) fn live() -> std::sync::MutexGuard<'static, Vec<(usize, Live)>> {
    LIVE.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
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
        let status = match &error {
            EmbedError::Setting(_) => StrataStatus::Settings,
            EmbedError::ImageSize { .. } => StrataStatus::ImageSize,
            EmbedError::BufferTooSmall { .. } | EmbedError::BufferOffset { .. } | EmbedError::BufferUsage { .. } => {
                StrataStatus::Buffer
            }
            EmbedError::DeviceLimit { .. } | EmbedError::UnsupportedFeature { .. } => StrataStatus::Device,
            EmbedError::NoResampleBuffers => StrataStatus::InvalidArgument,
            EmbedError::Api { .. } => StrataStatus::Vulkan,
            _ => StrataStatus::Internal,
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

/// The live pass behind `pass`.
///
/// # Safety
/// Only a live pass of this library is dereferenced (the table of live handles is asked
/// first); the caller does not use it from two threads at once.
pub(crate) unsafe fn pass_of<'a>(pass: *mut StrataVkPass, argument: &str) -> Result<&'a mut StrataVkPass, Failure> {
    if pass.is_null() {
        return Err(invalid(format!("{argument} is NULL")));
    }
    if !live().iter().any(|&(address, kind)| address == pass as usize && matches!(kind, Live::Pass { .. })) {
        return Err(invalid(format!("{argument} is not a live pass made by strata_vk_create")));
    }
    // SAFETY: a live pass: made by strata_vk_create and not yet destroyed.
    Ok(unsafe { &mut *pass })
}

/// The live bindings behind `bindings`, made by `pass`.
///
/// # Safety
/// As [`pass_of`].
pub(crate) unsafe fn bindings_of<'a>(
    bindings: *const StrataVkBindings,
    pass: *const StrataVkPass,
) -> Result<&'a StrataVkBindings, Failure> {
    if bindings.is_null() {
        return Err(invalid("bindings is NULL"));
    }
    match live().iter().find(|&&(address, _)| address == bindings as usize).map(|&(_, kind)| kind) {
        Some(Live::Bindings { owner }) if owner == pass as usize => {}
        Some(Live::Bindings { .. }) => return Err(invalid("bindings were made by another pass")),
        _ => return Err(invalid("bindings is not live bindings made by strata_vk_bind")),
    }
    // SAFETY: live bindings: made by strata_vk_bind and not yet destroyed.
    Ok(unsafe { &*bindings })
}
