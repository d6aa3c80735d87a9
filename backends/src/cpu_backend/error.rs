//! Errors of the CPU interpreter.

use crate::error::BackendError;

/// An IR construct the interpreter does not support, with its source line.
pub(super) fn unsupported(what: &str, line: u32) -> BackendError {
    BackendError::Validation {
        backend: "cpu".into(),
        operation: "interpreting naga IR".into(),
        message: format!("unsupported: {what} (WGSL line {line})"),
    }
}

/// A kernel that cannot run as written (e.g. a barrier in non-uniform control flow).
pub(super) fn invalid(kernel: &str, what: String) -> BackendError {
    BackendError::Validation { backend: "cpu".into(), operation: format!("running `{kernel}`"), message: what }
}
