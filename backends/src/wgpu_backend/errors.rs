//! wgpu reports errors asynchronously; this turns them into [`BackendError`]s.
//!
//! Operations run inside error scopes (validation, out-of-memory, internal) that are
//! popped right after; anything that escapes a scope is caught by an uncaptured-error
//! handler (wgpu's default one panics) and reported by the next check. Device loss is
//! recorded by a callback and reported by every later wait.

use crate::error::BackendError;
use std::sync::{Arc, Mutex};

/// Errors and device loss of one wgpu device.
#[derive(Clone)]
pub(super) struct ErrorSink {
    backend: String,
    /// Errors that escaped every scope, as (out of memory, message): kept as text, since
    /// a `wgpu::Error` cannot cross threads on wasm32, where the handler must be `Send`.
    uncaptured: Arc<Mutex<Vec<(bool, String)>>>,
    lost: Arc<Mutex<Option<String>>>,
}

impl ErrorSink {
    pub(super) fn install(device: &wgpu::Device, backend: &str) -> Self {
        let sink = Self { backend: backend.into(), uncaptured: Arc::default(), lost: Arc::default() };
        let uncaptured = Arc::clone(&sink.uncaptured);
        device.on_uncaptured_error(Arc::new(move |error| {
            if let Ok(mut list) = uncaptured.lock() {
                list.push((matches!(error, wgpu::Error::OutOfMemory { .. }), error.to_string()));
            }
        }));
        let lost = Arc::clone(&sink.lost);
        device.set_device_lost_callback(move |reason, message| {
            if let Ok(mut slot) = lost.lock() {
                *slot = Some(format!("{reason:?}: {message}"));
            }
        });
        sink
    }

    /// Opens error scopes for one operation.
    pub(super) fn scope(&self, device: &wgpu::Device) -> Scope {
        let guards = vec![
            device.push_error_scope(wgpu::ErrorFilter::Internal),
            device.push_error_scope(wgpu::ErrorFilter::OutOfMemory),
            device.push_error_scope(wgpu::ErrorFilter::Validation),
        ];
        Scope { sink: self.clone(), guards }
    }

    /// The device-lost error, if the device was lost.
    pub(super) fn check_lost(&self) -> Result<(), BackendError> {
        match self.lost.lock().ok().and_then(|slot| slot.clone()) {
            Some(reason) => Err(BackendError::DeviceLost { backend: self.backend.clone(), reason }),
            None => Ok(()),
        }
    }

    /// Device loss if it happened, otherwise a validation error carrying `message`.
    pub(super) fn lost_or(&self, message: String) -> BackendError {
        match self.check_lost() {
            Err(lost) => lost,
            Ok(()) => BackendError::Validation { backend: self.backend.clone(), operation: "wait".into(), message },
        }
    }

    fn convert(&self, error: wgpu::Error, operation: &str) -> BackendError {
        self.convert_escaped((matches!(error, wgpu::Error::OutOfMemory { .. }), error.to_string()), operation)
    }

    /// An error as the uncaptured-error handler keeps it: (out of memory, message).
    fn convert_escaped(&self, (out_of_memory, message): (bool, String), operation: &str) -> BackendError {
        if out_of_memory {
            BackendError::OutOfMemory { backend: self.backend.clone(), operation: operation.into() }
        } else {
            BackendError::Validation { backend: self.backend.clone(), operation: operation.into(), message }
        }
    }
}

/// Open error scopes; [`Scope::finish`] pops them.
pub(super) struct Scope {
    sink: ErrorSink,
    guards: Vec<wgpu::ErrorScopeGuard>,
}

impl Scope {
    /// Pops the scopes; the first error caught (or escaped, or a device loss) is returned.
    pub(super) fn finish(mut self, operation: &str) -> Result<(), BackendError> {
        let mut first = None;
        while let Some(guard) = self.guards.pop() {
            if let Some(error) = pollster::block_on(guard.pop()) {
                first.get_or_insert(error);
            }
        }
        if let Some(error) = first {
            return Err(self.sink.convert(error, operation));
        }
        if let Some(error) = self.sink.uncaptured.lock().ok().and_then(|mut list| list.pop()) {
            return Err(self.sink.convert_escaped(error, operation));
        }
        self.sink.check_lost()
    }
}
