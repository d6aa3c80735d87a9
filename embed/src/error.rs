//! [`EmbedError`]: everything the pass refuses, reported when the pass is configured or
//! its buffers are bound, never as a validation panic at dispatch.

use thiserror::Error;

/// Why the pass cannot be configured, bound or recorded.
#[derive(Debug, Error)]
pub enum EmbedError {
    /// A [`crate::SelectionSettings`] field is out of range.
    #[error("SelectionSettings.{0}")]
    Setting(#[from] strata_kernels::selection::SettingError),
    /// Zero or too many pixels.
    #[error("image size {width}x{height}: {why}")]
    ImageSize {
        /// Width.
        width: u32,
        /// Height.
        height: u32,
        /// What is wrong.
        why: String,
    },
    /// The device's limit is below what the pass needs.
    #[error("device limit {limit} is {available}, but the stratified selection needs {needed} ({why})")]
    DeviceLimit {
        /// The limit's name as the API spells it.
        limit: &'static str,
        /// The device's value.
        available: u64,
        /// What the pass needs.
        needed: u64,
        /// What needs it.
        why: String,
    },
    /// The engine's device description claims a feature its physical device lacks.
    #[error("{field} is true, but the physical device does not support {feature}")]
    UnsupportedFeature {
        /// The field that claims it.
        field: &'static str,
        /// The feature as Vulkan spells it.
        feature: &'static str,
    },
    /// An engine buffer is smaller than the contract requires.
    #[error(
        "buffer `{buffer}` has {size} bytes from its offset, but a {width}x{height} image needs {needed} ({per_pixel} bytes per pixel)"
    )]
    BufferTooSmall {
        /// The buffer's role in the contract.
        buffer: &'static str,
        /// Its size.
        size: u64,
        /// Bytes needed.
        needed: u64,
        /// Record size.
        per_pixel: u64,
        /// Image width.
        width: u32,
        /// Image height.
        height: u32,
    },
    /// An engine buffer was created without a usage the pass needs.
    #[error("buffer `{buffer}` lacks the usage {usage} (create it with it)")]
    BufferUsage {
        /// The buffer's role in the contract.
        buffer: &'static str,
        /// The missing usage.
        usage: &'static str,
    },
    /// An engine buffer's offset is not aligned as the API requires.
    #[error("buffer `{buffer}` is bound at offset {offset}, which is not a multiple of {alignment}")]
    BufferOffset {
        /// The buffer's role.
        buffer: &'static str,
        /// Its offset.
        offset: u64,
        /// The device's storage-buffer offset alignment.
        alignment: u64,
    },
    /// An engine buffer's range is larger than one storage-buffer descriptor of the device
    /// may see.
    #[error("buffer `{buffer}` is bound with {size} bytes, more than the device limit {limit} ({max} bytes)")]
    BufferRange {
        /// The buffer's role.
        buffer: &'static str,
        /// The size given.
        size: u64,
        /// The limit's name as the API spells it.
        limit: &'static str,
        /// The device's value.
        max: u64,
    },
    /// An engine buffer's offset plus size is past the last byte address (2^64 - 1).
    #[error("buffer `{buffer}` is bound at offset {offset} with {size} bytes, which ends past byte 2^64 - 1")]
    BufferEnd {
        /// The buffer's role.
        buffer: &'static str,
        /// Its offset.
        offset: u64,
        /// Its size.
        size: u64,
    },
    /// Two engine buffers are overlapping ranges of one API buffer.
    #[error(
        "buffers `{first}` (bytes {first_start}..{first_end}) and `{second}` (bytes {second_start}..{second_end}) overlap in one buffer: each needs bytes of its own"
    )]
    BufferOverlap {
        /// The first buffer's role.
        first: &'static str,
        /// Where its range starts.
        first_start: u64,
        /// Where its range ends (exclusive).
        first_end: u64,
        /// The second buffer's role.
        second: &'static str,
        /// Where its range starts.
        second_start: u64,
        /// Where its range ends (exclusive).
        second_end: u64,
    },
    /// Resampling was recorded with bindings that have no resampling buffers.
    #[error("the bindings were made without resampling buffers (ResampleBuffers), so resampling cannot be recorded")]
    NoResampleBuffers,
    /// A kernel failed to load (a bug of this crate; the message names the kernel).
    #[error(transparent)]
    Kernel(#[from] strata_kernels::KernelError),
    /// The graphics API failed.
    #[error("{api} error during {operation}: {message}")]
    Api {
        /// `wgpu` or `Vulkan`.
        api: &'static str,
        /// What was being done.
        operation: String,
        /// The API's message.
        message: String,
    },
}

impl From<strata_kernels::pass_plan::PlanError> for EmbedError {
    fn from(error: strata_kernels::pass_plan::PlanError) -> Self {
        use strata_kernels::pass_plan::PlanError;
        match error {
            PlanError::Setting(error) => EmbedError::Setting(error),
            PlanError::ImageSize { width, height, why } => EmbedError::ImageSize { width, height, why },
            PlanError::Kernel(error) => EmbedError::Kernel(error),
        }
    }
}
