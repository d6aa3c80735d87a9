//! Errors of loading and translating kernels.

use thiserror::Error;

/// A kernel that fails to parse, validate or translate.
#[derive(Clone, Debug, Error)]
pub enum KernelError {
    /// naga's WGSL front end rejected the source.
    #[error("kernel `{kernel}`: WGSL parse error\n{message}")]
    Parse {
        /// Registry name of the kernel.
        kernel: String,
        /// naga's diagnostic, with the fragment file and line.
        message: String,
    },
    /// naga's validator rejected the module.
    #[error("kernel `{kernel}`: validation error\n{message}")]
    Validation {
        /// Registry name of the kernel.
        kernel: String,
        /// naga's diagnostic.
        message: String,
    },
    /// The module lacks the entry point the registry names.
    #[error("kernel `{kernel}`: no compute entry point `{entry}`")]
    MissingEntryPoint {
        /// Registry name of the kernel.
        kernel: String,
        /// The entry point looked for.
        entry: String,
    },
    /// A resource the registry cannot describe (for example a texture binding).
    #[error("kernel `{kernel}`: binding @group({group}) @binding({binding}) `{name}`: {reason}")]
    UnsupportedBinding {
        /// Registry name of the kernel.
        kernel: String,
        /// WGSL group.
        group: u32,
        /// WGSL binding.
        binding: u32,
        /// Variable name.
        name: String,
        /// What is not supported.
        reason: String,
    },
    /// Pipeline-overridable constants could not be resolved.
    #[error("kernel `{kernel}`: override: {message}")]
    Override {
        /// Registry name of the kernel.
        kernel: String,
        /// What is wrong, naming the constant.
        message: String,
    },
    /// A naga back end failed.
    #[error("kernel `{kernel}`: {target} translation failed: {message}")]
    Translation {
        /// Registry name of the kernel.
        kernel: String,
        /// Target language.
        target: &'static str,
        /// naga's message.
        message: String,
    },
}
