//! Everything that can go wrong on a backend, typed.

use thiserror::Error;

impl BackendError {
    /// `backend` cannot bind `binding` of `kernel`, with why.
    pub fn unavailable_binding(
        backend: &str,
        kernel: &strata_kernels::Kernel,
        binding: &strata_kernels::BindingInfo,
        why: &str,
    ) -> Self {
        BackendError::Unavailable {
            backend: backend.into(),
            what: format!(
                "kernel `{}` binding {} (`{}`: {})",
                kernel.name(),
                binding.binding,
                binding.name,
                binding.element.type_name
            ),
            why: why.into(),
        }
    }
}

/// A backend failure. Messages name the kernel, binding, limit or value at fault.
#[derive(Debug, Error)]
pub enum BackendError {
    /// No device of the requested kind exists.
    #[error("{backend}: no adapter found ({reason})")]
    NoAdapter {
        /// Backend that looked.
        backend: String,
        /// What was tried.
        reason: String,
    },
    /// The device could not be created.
    #[error("{backend}: device creation failed: {reason}")]
    DeviceCreation {
        /// Backend.
        backend: String,
        /// Driver's message.
        reason: String,
    },
    /// The kernel needs a feature the device lacks.
    #[error("kernel `{kernel}` needs {feature}, which {device} does not support")]
    MissingFeature {
        /// Kernel name.
        kernel: String,
        /// Feature name.
        feature: String,
        /// Device summary.
        device: String,
    },
    /// A size beyond what the device allows.
    #[error("{what} needs {limit} = {requested}, but the device allows at most {available}")]
    LimitExceeded {
        /// What asked (kernel, buffer).
        what: String,
        /// Limit name.
        limit: &'static str,
        /// Requested value.
        requested: u64,
        /// Device's maximum.
        available: u64,
    },
    /// Bindings that do not fit the kernel.
    #[error("kernel `{kernel}`, binding {binding}: {reason}")]
    Binding {
        /// Kernel name.
        kernel: String,
        /// WGSL binding number.
        binding: u32,
        /// What is wrong.
        reason: String,
    },
    /// A binding named by a WGSL variable the kernel does not declare.
    #[error("kernel `{kernel}` declares no binding named `{name}`")]
    UnknownBinding {
        /// Kernel name.
        kernel: String,
        /// The name asked for.
        name: String,
    },
    /// A buffer id this backend does not own (destroyed or from another backend).
    #[error("unknown buffer {0}")]
    UnknownBuffer(u64),
    /// A buffer size or write that cannot be done.
    #[error("buffer `{label}`: {reason}")]
    Buffer {
        /// Buffer label.
        label: String,
        /// What is wrong.
        reason: String,
    },
    /// A texture id this backend does not own.
    #[error("unknown texture {0}")]
    UnknownTexture(u64),
    /// A sampler id this backend does not own.
    #[error("unknown sampler {0}")]
    UnknownSampler(u64),
    /// A texture size, mip level or write that cannot be done.
    #[error("texture `{label}`: {reason}")]
    Texture {
        /// Texture label.
        label: String,
        /// What is wrong.
        reason: String,
    },
    /// Something this backend cannot do at all (a format, a binding kind), named.
    #[error("{backend}: {what} is unavailable: {why}")]
    Unavailable {
        /// Backend.
        backend: String,
        /// What was asked.
        what: String,
        /// Why not.
        why: String,
    },
    /// The API's validation rejected an operation.
    #[error("{backend}: validation error in {operation}: {message}")]
    Validation {
        /// Backend.
        backend: String,
        /// What was being done.
        operation: String,
        /// Validator's message.
        message: String,
    },
    /// Out of device memory.
    #[error("{backend}: out of memory in {operation}")]
    OutOfMemory {
        /// Backend.
        backend: String,
        /// What was being done.
        operation: String,
    },
    /// The device was lost; the backend must be created again.
    #[error("{backend}: device lost: {reason}")]
    DeviceLost {
        /// Backend.
        backend: String,
        /// Driver's reason.
        reason: String,
    },
    /// Timing was asked of a device without timestamp queries.
    #[error("{0}: timestamp queries are not supported")]
    NoTimestamps(String),
    /// The kernel failed to translate for this backend.
    #[error(transparent)]
    Kernel(#[from] strata_kernels::KernelError),
}
