//! # strata-vk: the stratified selection for engines in C and C++
//!
//! The pass of [`strata_embed::AshSelection`] (histogram, stratified selection,
//! resampling; Salaün et al., SIGGRAPH 2025) behind a C ABI, on the engine's own Vulkan
//! objects: the engine hands over its `VkInstance`, `VkPhysicalDevice`, `VkDevice` and
//! `vkGetInstanceProcAddr`, binds its own `VkBuffer`s and records into its own
//! `VkCommandBuffer`s. Its header, `strata_vk.h`, is generated from this file by
//! cbindgen (`cargo xtask export`); `strata_frame.h` and `strata.h` of the same package
//! declare the settings and the buffers' records.
//!
//! Every function returns a [`StrataStatus`] and, where the caller passes a
//! [`StrataError`], fills it with the status and a one-line message naming the argument,
//! field, buffer or device limit at fault. Nothing unwinds across the boundary: a panic
//! inside the pass (a bug) is caught and reported as [`StrataStatus::Internal`]. A null
//! pointer, a handle that is not a live one of this library's, bindings of another pass,
//! or a pass destroyed while its bindings live are refused with
//! [`StrataStatus::InvalidArgument`].
//!
//! Versions and validation: [`strata_vk_create`] takes `STRATA_VERSION` of the headers the
//! caller compiled against and refuses another major version ([`StrataStatus::Version`]).
//! In validation mode ([`strata_vk_set_validation`], on by default in a debug build) a
//! frame index that does not advance by one is refused ([`StrataStatus::FrameIndex`]);
//! [`strata_vk_check_frame`] checks a frame an engine records with the package's kernels
//! itself (its dispatches and buffer sizes), without a device.
//!
//! Handles: a `StrataVkPass *` or `StrataVkBindings *` is an opaque value, not an
//! address: each is a number handed out once and never again (a counter), looked up in a
//! table of live handles; nothing is ever read through it. So a destroyed handle stays
//! refused even when later passes or bindings are made, and can never name one of them.
//!
//! Threads: any call may be made from any thread, and calls on different passes run
//! concurrently. On one pass, [`strata_vk_set_seed`], [`strata_vk_bind`],
//! [`strata_vk_record_selection`] and [`strata_vk_record_resampling`] may also run from
//! several threads at once: each takes shared access only. Each thread records into its
//! own command buffer (Vulkan wants a command buffer and its pool synchronised by the
//! engine), and as the command buffers of one pass share its own buffers (uniforms,
//! histogram), their executions must not overlap on the device: submit them to one queue
//! (the pass's barriers follow its submission order) or order them with semaphores. A
//! frame recorded while another thread sets the seed gets the old or the new one.
//! [`strata_vk_destroy_bindings`] and [`strata_vk_destroy`] refuse, with
//! [`StrataStatus::InvalidArgument`], a handle that a call on another thread is using at
//! that moment: nothing is freed under a running call (and the engine should not destroy
//! what another of its threads is recording with).
//!
//! From Rust, as C calls it (a pass needs a live Vulkan device: see `examples/c/` and
//! `tests/tests/c_abi.rs`):
//!
//! ```
//! use strata_vk::*;
//! let mut error = StrataError { status: StrataStatus::Ok, message: [0; STRATA_ERROR_MESSAGE_BYTES] };
//! let mut pass = std::ptr::null_mut();
//! // SAFETY: null pointers are refused, never read.
//! let status =
//!     unsafe { strata_vk_create(LIBRARY_VERSION, std::ptr::null(), std::ptr::null(), 16, 16, &mut pass, &mut error) };
//! assert_eq!(status, StrataStatus::InvalidArgument);
//! // SAFETY: a static NUL-terminated string.
//! let version = unsafe { std::ffi::CStr::from_ptr(strata_vk_version()) };
//! assert_eq!(version.to_str()?, env!("CARGO_PKG_VERSION"));
//! // Headers of another major version are refused before anything else.
//! let [major, minor, patch] = version_parts(LIBRARY_VERSION);
//! let newer = make_version(major + 1, minor, patch);
//! // SAFETY: as above.
//! let status = unsafe { strata_vk_create(newer, std::ptr::null(), std::ptr::null(), 16, 16, &mut pass, &mut error) };
//! assert_eq!(status, StrataStatus::Version);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use ash::vk::{self, Handle};
use std::ffi::c_char;
use strata_embed::{AshBindings, AshBufferSlice, AshBuffers, AshDevice, AshResampleBuffers, AshSelection, EmbedError};
use strata_embed::{SamplerVariant, SelectionSettings};

mod guard;
mod validation;
use guard::{Failure, NewHandle, bindings_of, guarded, invalid, pass_of, remove_bindings, remove_pass};

/// `VkInstance` (from `vulkan.h`).
pub type VkInstance = vk::Instance;
/// `VkPhysicalDevice` (from `vulkan.h`).
pub type VkPhysicalDevice = vk::PhysicalDevice;
/// `VkDevice` (from `vulkan.h`).
pub type VkDevice = vk::Device;
/// `VkBuffer` (from `vulkan.h`).
pub type VkBuffer = vk::Buffer;
/// `VkCommandBuffer` (from `vulkan.h`).
pub type VkCommandBuffer = vk::CommandBuffer;
/// `PFN_vkGetInstanceProcAddr` (from `vulkan.h`); may be null only to be refused.
#[allow(non_camel_case_types)]
pub type PFN_vkGetInstanceProcAddr =
    Option<unsafe extern "system" fn(instance: vk::Instance, name: *const c_char) -> vk::PFN_vkVoidFunction>;

/// What a call returned.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StrataStatus {
    /// Done.
    Ok = 0,
    /// A null pointer, a handle that is not this library's, bindings of another pass,
    /// an inconsistent buffer set.
    InvalidArgument = 1,
    /// A selection setting out of range (the message names the field).
    Settings = 2,
    /// An image of 0 pixels or more than 2^32 - 1.
    ImageSize = 3,
    /// An engine buffer too small or bound at an unaligned offset (the message names it).
    Buffer = 4,
    /// The device cannot run the pass (a limit, a feature, its Vulkan version).
    Device = 5,
    /// A Vulkan call failed (the message names the call and its VkResult).
    Vulkan = 6,
    /// A bug of this library: a panic caught at the boundary.
    Internal = 7,
    /// The headers the caller compiled against (`STRATA_VERSION`, passed to
    /// [`strata_vk_create`]) are of another major version than the library (before 1.0: of
    /// another minor version), so their records and functions may not be the library's.
    Version = 8,
    /// Validation: a frame index that does not advance by one from the previous frame's.
    FrameIndex = 9,
    /// Validation: a dispatch of other workgroup counts than the pass's (the message says
    /// which, and the likely mistake).
    Dispatch = 10,
}

/// A version as one number, as `STRATA_MAKE_VERSION` of `strata.h` packs it (Vulkan's
/// packing): `major << 22 | minor << 12 | patch`.
pub const fn make_version(major: u32, minor: u32, patch: u32) -> u32 {
    (major << 22) | (minor << 12) | patch
}

/// The three numbers of a version packed by [`make_version`].
pub const fn version_parts(version: u32) -> [u32; 3] {
    [version >> 22, (version >> 12) & 0x3ff, version & 0xfff]
}

/// A decimal number of a `CARGO_PKG_VERSION_*` variable, at compile time.
const fn decimal(text: &str) -> u32 {
    let bytes = text.as_bytes();
    let mut value = 0;
    let mut i = 0;
    while i < bytes.len() {
        assert!(bytes[i].is_ascii_digit(), "a version number is decimal");
        value = value * 10 + (bytes[i] - b'0') as u32;
        i += 1;
    }
    value
}

/// The library's own version, packed by [`make_version`]: the workspace's version, as
/// `STRATA_VERSION` of the `strata.h` exported beside it.
pub const LIBRARY_VERSION: u32 = make_version(
    decimal(env!("CARGO_PKG_VERSION_MAJOR")),
    decimal(env!("CARGO_PKG_VERSION_MINOR")),
    decimal(env!("CARGO_PKG_VERSION_PATCH")),
);

/// Whether headers of version `header` (packed) may be used with this library: the same
/// major version and, before 1.0, the same minor version (semantic versioning, as Cargo
/// reads it); otherwise a one-line message naming both versions.
pub fn check_header_version(header: u32) -> Result<(), String> {
    let [major, minor, patch] = version_parts(header);
    let [own_major, own_minor, _] = version_parts(LIBRARY_VERSION);
    if major == own_major && (own_major != 0 || minor == own_minor) {
        return Ok(());
    }
    let which = if own_major == 0 { "another minor version before 1.0" } else { "another major version" };
    Err(format!(
        "header_version = {header} ({major}.{minor}.{patch}, STRATA_VERSION of the strata.h compiled against): this \
         library is strata_vk {}, and headers of {which} do not match it; use the headers exported with the library",
        env!("CARGO_PKG_VERSION")
    ))
}

/// Bytes of [`StrataError::message`], its terminating NUL included.
pub const STRATA_ERROR_MESSAGE_BYTES: usize = 512;

/// A call's status and, unless it is `STRATA_STATUS_OK`, a one-line NUL-terminated
/// message (UTF-8, cut at a character boundary to fit).
#[repr(C)]
pub struct StrataError {
    /// The status the call returned.
    pub status: StrataStatus,
    /// What went wrong, naming the argument, field, buffer or limit.
    pub message: [c_char; STRATA_ERROR_MESSAGE_BYTES],
}

/// The selection's settings: the C twin of `StrataSelectionSettings` in `strata_frame.h`
/// (declared there, not in `strata_vk.h`).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct StrataSelectionSettings {
    /// B: 4, 8, 16 or 32.
    pub block_size: u32,
    /// K: 1 to 4.
    pub candidates: u32,
    /// A `StrataSampler` (`strata.h`).
    pub sampler: u32,
    /// 1: object masking; 0: none.
    pub masking: u32,
    /// 1: block shifting; 0: none.
    pub block_shift: u32,
}

/// The engine's Vulkan objects the pass is made on: an instance of `apiVersion` 1.1 or
/// newer and a device of Vulkan 1.1 or newer with a compute queue; nothing needs enabling
/// beyond core features.
#[repr(C)]
#[derive(Clone, Copy)]
pub struct StrataVkDevice {
    /// The loader's (or the instance's) `vkGetInstanceProcAddr`: every other function
    /// is looked up through it.
    pub get_instance_proc_addr: PFN_vkGetInstanceProcAddr,
    /// The instance.
    pub instance: VkInstance,
    /// The physical device behind `device`.
    pub physical_device: VkPhysicalDevice,
    /// The logical device.
    pub device: VkDevice,
    /// 1 if the engine enabled `shaderZeroInitializeWorkgroupMemory` on `device` (the
    /// driver then zeroes workgroup memory; pipelines build faster on some drivers); 0 is
    /// always correct.
    pub shader_zero_initialize_workgroup_memory: u32,
}

/// A range of an engine buffer (created with `VK_BUFFER_USAGE_STORAGE_BUFFER_BIT`):
/// records start at `offset`, a multiple of `minStorageBufferOffsetAlignment`, and `size`
/// bytes from it may be used.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct StrataVkBufferSlice {
    /// The buffer; `VK_NULL_HANDLE` where a buffer is optional and not given.
    pub buffer: VkBuffer,
    /// Byte offset of the first record.
    pub offset: u64,
    /// Bytes from `offset`.
    pub size: u64,
}

/// The engine's buffers (the contract of `strata.h`: one record per pixel, row-major).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct StrataVkBuffers {
    /// `StrataCandidate` per pixel, written by the engine before the selection.
    pub candidates: StrataVkBufferSlice,
    /// `uint32_t` payload per pixel, or `VK_NULL_HANDLE`: a pixel's payload is its index.
    pub payloads: StrataVkBufferSlice,
    /// `StrataSelectedCandidates` per pixel, written by the pass.
    pub selections: StrataVkBufferSlice,
    /// `StrataResampleInput` per pixel, written by the engine after the selection; or
    /// `VK_NULL_HANDLE` (with `resampled`) when the engine resamples on its own.
    pub resample_inputs: StrataVkBufferSlice,
    /// `StrataResampleOutput` per pixel, written by the pass's resampling; or
    /// `VK_NULL_HANDLE` with `resample_inputs`.
    pub resampled: StrataVkBufferSlice,
}

/// A pass made by [`strata_vk_create`]. Opaque: a `StrataVkPass *` is a handle value
/// (handed out once, never reused, never dereferenced), not an address.
///
/// Threads: any call may be made from any thread. On one pass, [`strata_vk_set_seed`],
/// [`strata_vk_bind`], [`strata_vk_record_selection`] and
/// [`strata_vk_record_resampling`] may run from several threads at once (shared access).
/// Each thread records into its own command buffer, from a pool no other thread uses
/// meanwhile. The command buffers of one pass share its own buffers (uniforms,
/// histogram): their executions must not overlap on the device, so submit them to one
/// queue (the pass's barriers follow its submission order) or order them with
/// semaphores. [`strata_vk_destroy`] and [`strata_vk_destroy_bindings`] refuse a handle
/// that a call on another thread is using at that moment (nothing is freed under it).
pub struct StrataVkPass {
    _handle_only: (),
}

/// Descriptor sets of one set of engine buffers, made by [`strata_vk_bind`]. Opaque: a
/// `StrataVkBindings *` is a handle value (never reused, never dereferenced), not an
/// address. Several threads may record with them at once; destroying them is refused
/// while one of them does.
pub struct StrataVkBindings {
    _handle_only: (),
}

/// What a pass handle stands for.
pub(crate) struct Pass {
    /// Kept for the pass's lifetime: the device's functions were loaded through it.
    _instance: ash::Instance,
    selection: AshSelection,
    /// The validation mode and the last frame recorded ([`strata_vk_set_validation`]).
    frames: validation::FrameOrder,
}

/// What the table shares between threads must be shareable.
const _: () = {
    const fn shared<T: Send + Sync>() {}
    shared::<Pass>();
    shared::<AshBindings>();
};

/// The settings as the pass takes them; a `Settings` failure naming the field otherwise.
pub(crate) fn settings_of(settings: &StrataSelectionSettings) -> Result<SelectionSettings, Failure> {
    let flag = |name: &str, value: u32| match value {
        0 => Ok(false),
        1 => Ok(true),
        _ => Err(Failure { status: StrataStatus::Settings, message: format!("{name} = {value}: must be 0 or 1") }),
    };
    let sampler = SamplerVariant::from_id(settings.sampler).ok_or_else(|| Failure {
        status: StrataStatus::Settings,
        message: format!(
            "sampler = {}: must be a StrataSampler (0 to {})",
            settings.sampler,
            SamplerVariant::ALL.len() - 1
        ),
    })?;
    let settings = SelectionSettings {
        block_size: settings.block_size,
        candidates: settings.candidates,
        masking: flag("masking", settings.masking)?,
        block_shift: flag("block_shift", settings.block_shift)?,
        sampler,
    };
    settings.validate().map_err(|e| Failure { status: StrataStatus::Settings, message: e.to_string() })?;
    Ok(settings)
}

/// Makes the pass for a `width` × `height` image on the engine's device: its pipelines
/// (naga's SPIR-V of the kernels; the histogram kernel chosen for the device) and its own
/// buffers (about 1.3 MiB + 16 bytes per pixel). On success `*pass` holds it; destroy it
/// with [`strata_vk_destroy`].
///
/// `header_version` is `STRATA_VERSION` of the `strata.h` the caller compiled against:
/// headers of another major version (before 1.0, of another minor version) are refused
/// with `STRATA_STATUS_VERSION` before anything else is read.
///
/// # Safety
/// `device`, `settings` and `pass` are null (refused) or valid; `device` holds handles
/// of a live instance (`apiVersion` 1.1 or newer), one of its physical devices and a live
/// device made from it, with `get_instance_proc_addr` the loader's or the instance's;
/// the instance and the device stay alive until the pass is destroyed; if
/// `device->shader_zero_initialize_workgroup_memory` is 1, the feature is enabled on the
/// device; `error` is null or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn strata_vk_create(
    header_version: u32,
    device: *const StrataVkDevice,
    settings: *const StrataSelectionSettings,
    width: u32,
    height: u32,
    pass: *mut *mut StrataVkPass,
    error: *mut StrataError,
) -> StrataStatus {
    // SAFETY: per this function's contract.
    unsafe {
        guarded(error, || {
            if let Some(out) = pass.as_mut() {
                *out = std::ptr::null_mut();
            }
            check_header_version(header_version)
                .map_err(|message| Failure { status: StrataStatus::Version, message })?;
            let out = pass.as_mut().ok_or_else(|| invalid("pass (the result pointer) is NULL"))?;
            let device = device.as_ref().ok_or_else(|| invalid("device is NULL"))?;
            let settings = settings_of(settings.as_ref().ok_or_else(|| invalid("settings is NULL"))?)?;
            let get_instance_proc_addr =
                device.get_instance_proc_addr.ok_or_else(|| invalid("device->get_instance_proc_addr is NULL"))?;
            for (name, null) in [
                ("device->instance", device.instance.is_null()),
                ("device->physical_device", device.physical_device.is_null()),
                ("device->device", device.device.is_null()),
            ] {
                if null {
                    return Err(invalid(format!("{name} is VK_NULL_HANDLE")));
                }
            }
            let zero_init = match device.shader_zero_initialize_workgroup_memory {
                0 => false,
                1 => true,
                other => {
                    return Err(invalid(format!(
                        "device->shader_zero_initialize_workgroup_memory = {other}: must be 0 or 1"
                    )));
                }
            };
            let static_fn = ash::StaticFn { get_instance_proc_addr };
            let instance = ash::Instance::load(&static_fn, device.instance);
            let logical = ash::Device::load(instance.fp_v1_0(), device.device);
            let vulkan = AshDevice {
                instance: &instance,
                physical_device: device.physical_device,
                device: &logical,
                shader_zero_initialize_workgroup_memory: zero_init,
            };
            let handle = NewHandle::reserve()?;
            // SAFETY: the instance and device functions were loaded for the caller's live
            // instance and device, which outlive the pass, and the feature flag is true
            // only where enabled (this function's contract).
            let selection = AshSelection::new(vulkan, settings, width, height)?;
            *out = handle.insert_pass(Pass { _instance: instance, selection, frames: validation::FrameOrder::new() });
            Ok(())
        })
    }
}

/// Starts an independent render: the frames recorded from now on belong to `seed`
/// (0 until the first call). May run while other threads record with the pass: a frame
/// recorded at the same moment gets the old or the new seed.
///
/// # Safety
/// `error` is null or writable (`pass` may be any value: it is looked up, never read).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn strata_vk_set_seed(
    pass: *mut StrataVkPass,
    seed: u32,
    error: *mut StrataError,
) -> StrataStatus {
    // SAFETY: per this function's contract.
    unsafe {
        guarded(error, || {
            let owner = pass_of(pass, "pass")?;
            owner.selection.set_seed(seed);
            owner.frames.restart();
            Ok(())
        })
    }
}

/// The engine's buffer slice, checked where it is required.
fn slice(slice: &StrataVkBufferSlice, name: &str, required: bool) -> Result<Option<AshBufferSlice>, Failure> {
    if slice.buffer.is_null() {
        return if required { Err(invalid(format!("buffers->{name}.buffer is VK_NULL_HANDLE"))) } else { Ok(None) };
    }
    Ok(Some(AshBufferSlice { buffer: slice.buffer, offset: slice.offset, size: slice.size }))
}

/// Checks the engine's buffers against the contract (sizes for the pass's image, offset
/// alignment, `offset + size` within 2^64 - 1 and `size` within the device's
/// `maxStorageBufferRange`, no two ranges of one buffer overlapping: each refused with
/// `STRATA_STATUS_BUFFER` and a message naming the buffer and the values) and writes
/// their descriptor sets; on success `*bindings` holds them, to be freed by
/// [`strata_vk_destroy_bindings`]. May run while other threads use the pass.
///
/// # Safety
/// `buffers` and `bindings` are null (refused) or valid; each buffer given is a live
/// `VkBuffer` of the pass's device, created with `VK_BUFFER_USAGE_STORAGE_BUFFER_BIT`,
/// with memory bound, at least `offset + size` bytes large; the buffers and their memory
/// stay alive while a command buffer recorded with the bindings is recording or pending;
/// `error` is null or writable (`pass` may be any value: it is looked up, never read).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn strata_vk_bind(
    pass: *mut StrataVkPass,
    buffers: *const StrataVkBuffers,
    bindings: *mut *mut StrataVkBindings,
    error: *mut StrataError,
) -> StrataStatus {
    // SAFETY: per this function's contract.
    unsafe {
        guarded(error, || {
            let out = bindings.as_mut().ok_or_else(|| invalid("bindings (the result pointer) is NULL"))?;
            *out = std::ptr::null_mut();
            let owner = pass_of(pass, "pass")?;
            let buffers = buffers.as_ref().ok_or_else(|| invalid("buffers is NULL"))?;
            let resample = match (
                slice(&buffers.resample_inputs, "resample_inputs", false)?,
                slice(&buffers.resampled, "resampled", false)?,
            ) {
                (Some(inputs), Some(outputs)) => Some(AshResampleBuffers { inputs, outputs }),
                (None, None) => None,
                _ => {
                    return Err(invalid(
                        "buffers->resample_inputs and buffers->resampled: give both (the pass resamples) or neither",
                    ));
                }
            };
            let ash_buffers = AshBuffers {
                candidates: slice(&buffers.candidates, "candidates", true)?.expect("required"),
                payloads: slice(&buffers.payloads, "payloads", false)?,
                selections: slice(&buffers.selections, "selections", true)?.expect("required"),
                resample,
            };
            let handle = NewHandle::reserve()?;
            // SAFETY: the engine's buffers are live storage buffers of the pass's device
            // holding their ranges, alive while the bindings are used (this function's
            // contract).
            let made = owner.selection.bind(&ash_buffers)?;
            *out = handle.insert_bindings(made, pass);
            Ok(())
        })
    }
}

/// Checks a recording call's handles and command buffer, then records with `record`.
///
/// # Safety
/// As [`strata_vk_record_selection`].
unsafe fn recording(
    pass: *mut StrataVkPass,
    bindings: *const StrataVkBindings,
    command_buffer: VkCommandBuffer,
    error: *mut StrataError,
    frame: Option<u32>,
    record: impl FnOnce(&AshSelection, &AshBindings) -> Result<(), EmbedError>,
) -> StrataStatus {
    // SAFETY: per this function's contract.
    unsafe {
        guarded(error, || {
            let owner = pass_of(pass, "pass")?;
            let bindings = bindings_of(bindings, pass)?;
            if command_buffer.is_null() {
                return Err(invalid("command_buffer is NULL"));
            }
            // The frame's order is taken only once the frame records.
            let order = frame.map(|frame| owner.frames.check(frame)).transpose()?;
            record(&owner.selection, &bindings)?;
            if let Some(order) = order {
                order.commit();
            }
            Ok(())
        })
    }
}

/// Records frame `frame`'s uniform updates, histogram and selection into the engine's
/// command buffer, with the barriers the pass needs (from the engine's earlier shader and
/// transfer writes, between its dispatches, and to the engine's later reads). Several
/// threads may record with one pass (and one set of bindings) at once, each into its own
/// command buffer (see [`StrataVkPass`] for how to submit them).
///
/// # Safety
/// `command_buffer` is recording, outside a render pass, on a queue with compute, of the
/// pass's device, and no other thread records into it or its pool meanwhile; the
/// bindings' buffers stay alive until it has executed; `error` is null or writable
/// (`pass` and `bindings` may be any values: they are looked up, never read).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn strata_vk_record_selection(
    pass: *mut StrataVkPass,
    bindings: *const StrataVkBindings,
    command_buffer: VkCommandBuffer,
    frame: u32,
    error: *mut StrataError,
) -> StrataStatus {
    // SAFETY: per this function's contract; the command buffer is checked non-null first.
    unsafe {
        recording(pass, bindings, command_buffer, error, Some(frame), |selection, bound| {
            selection.record_selection(command_buffer, bound, frame)
        })
    }
}

/// Records the resampling of the engine's `resample_inputs` (after the selection, in the
/// same or an earlier submission).
///
/// # Safety
/// As [`strata_vk_record_selection`].
#[unsafe(no_mangle)]
pub unsafe extern "C" fn strata_vk_record_resampling(
    pass: *mut StrataVkPass,
    bindings: *const StrataVkBindings,
    command_buffer: VkCommandBuffer,
    error: *mut StrataError,
) -> StrataStatus {
    // SAFETY: as above.
    unsafe {
        recording(pass, bindings, command_buffer, error, None, |selection, bound| {
            selection.record_resampling(command_buffer, bound)
        })
    }
}

/// Frees the descriptor sets of `bindings` (null: nothing); a second call with the same
/// handle is refused (it is no longer live, and its value is never handed out again).
/// Refused while a call on another thread records with them.
///
/// # Safety
/// No pending command buffer uses them; `error` is null or writable (`pass` and
/// `bindings` may be any values: they are looked up, never read).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn strata_vk_destroy_bindings(
    pass: *mut StrataVkPass,
    bindings: *mut StrataVkBindings,
    error: *mut StrataError,
) -> StrataStatus {
    // SAFETY: per this function's contract.
    unsafe {
        guarded(error, || {
            if bindings.is_null() {
                return Ok(());
            }
            let (owner, bindings) = remove_bindings(bindings, pass)?;
            // SAFETY: out of the table and used by no call; no pending command buffer
            // uses them (this function's contract).
            owner.selection.destroy_bindings(bindings);
            Ok(())
        })
    }
}

/// Destroys the pass's pipelines and buffers (null: nothing). Refused while bindings of
/// the pass live (destroy them first: they hold the pass's descriptor sets) and while a
/// call on another thread uses the pass; a second call with the same handle is refused.
///
/// # Safety
/// No pending command buffer uses the pass; `error` is null or writable (`pass` may be
/// any value: it is looked up, never read).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn strata_vk_destroy(pass: *mut StrataVkPass, error: *mut StrataError) -> StrataStatus {
    // SAFETY: per this function's contract.
    unsafe {
        guarded(error, || {
            if pass.is_null() {
                return Ok(());
            }
            // SAFETY: out of the table, without bindings and used by no call; no pending
            // command buffer uses it (this function's contract).
            remove_pass(pass)?.selection.destroy();
            Ok(())
        })
    }
}

/// Turns the pass's validation mode on (`enabled` 1) or off (0); it is on from
/// [`strata_vk_create`] in a debug build of the library, off in a release build. With it,
/// [`strata_vk_record_selection`] refuses with `STRATA_STATUS_FRAME_INDEX` a frame index
/// other than the previous frame's plus one (the first frame after [`strata_vk_create`] or
/// [`strata_vk_set_seed`] may be any): a frame index left at 0 repeats the first frame's
/// selections every frame, silently. Frames recorded on several threads at once must then
/// still be recorded in order.
///
/// # Safety
/// `error` is null or writable (`pass` may be any value: it is looked up, never read).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn strata_vk_set_validation(
    pass: *mut StrataVkPass,
    enabled: u32,
    error: *mut StrataError,
) -> StrataStatus {
    // SAFETY: per this function's contract.
    unsafe {
        guarded(error, || {
            let owner = pass_of(pass, "pass")?;
            let on = match enabled {
                0 => false,
                1 => true,
                other => return Err(invalid(format!("enabled = {other}: must be 0 or 1"))),
            };
            owner.frames.set_enabled(on);
            Ok(())
        })
    }
}

/// `StrataFrameCheck.previous_frame` when no frame was recorded before.
pub const STRATA_NO_FRAME: u32 = u32::MAX;

/// The bytes of each buffer an engine binds for one frame when it records the pass itself
/// (route 1: the package's kernels), for [`strata_vk_check_frame`]; 0 for an optional
/// buffer it does not bind (`payloads`; `resample_inputs` with `resampled`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct StrataBufferBytes {
    /// `candidates`.
    pub candidates: u64,
    /// `payloads` (0: none, a pixel's payload is its index).
    pub payloads: u64,
    /// `selections`.
    pub selections: u64,
    /// `resample_inputs` (0 with `resampled`: no resampling).
    pub resample_inputs: u64,
    /// `resampled`.
    pub resampled: u64,
    /// `sorted_pixels`.
    pub sorted_pixels: u64,
    /// `spans`.
    pub spans: u64,
    /// `block_stats`.
    pub block_stats: u64,
    /// `blue_noise`.
    pub blue_noise: u64,
    /// `histogram_params`.
    pub histogram_params: u64,
    /// `selection_params`.
    pub selection_params: u64,
}

/// What an engine that records the pass itself is about to record for one frame: the
/// validation mode of route 1, [`strata_vk_check_frame`].
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct StrataFrameCheck {
    /// The settings (`strata_frame.h`).
    pub settings: StrataSelectionSettings,
    /// The image's width in pixels.
    pub width: u32,
    /// The image's height in pixels.
    pub height: u32,
    /// The frame index passed to `strata_frame_params`.
    pub frame: u32,
    /// The previous frame's index, or `STRATA_NO_FRAME` for the first frame of a render.
    pub previous_frame: u32,
    /// The render's seed.
    pub seed: u32,
    /// The device's smallest `maxComputeWorkGroupCount` component.
    pub max_workgroups: u32,
    /// The histogram kernel's `vkCmdDispatch` (x, y, z).
    pub histogram_workgroups: [u32; 3],
    /// `strata_select`'s (and `strata_resample`'s) `vkCmdDispatch`.
    pub pixel_workgroups: [u32; 3],
    /// The bytes of each buffer bound.
    pub buffer_bytes: StrataBufferBytes,
}

/// Checks one frame an engine records with the package's kernels itself (route 1; the
/// library's own recording needs no such check) against what the pass needs: the settings,
/// the frame index advancing by one, every buffer's size for the settings and the image
/// (`STRATA_STATUS_BUFFER`), and both dispatches' workgroup counts
/// (`STRATA_STATUS_DISPATCH`); each failure is a status and a one-line message naming the
/// field, the values and the likely mistake (the kernels do not check: too few workgroups,
/// or buffers too small, give silently wrong records). Needs no device.
///
/// # Safety
/// `check` is null (refused) or valid; `error` is null or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn strata_vk_check_frame(
    check: *const StrataFrameCheck,
    error: *mut StrataError,
) -> StrataStatus {
    // SAFETY: per this function's contract.
    unsafe {
        guarded(error, || {
            let check = check.as_ref().ok_or_else(|| invalid("check is NULL"))?;
            validation::check_frame(check)
        })
    }
}

/// The library's version, `MAJOR.MINOR.PATCH` (static, NUL-terminated).
#[unsafe(no_mangle)]
pub extern "C" fn strata_vk_version() -> *const c_char {
    concat!(env!("CARGO_PKG_VERSION"), "\0").as_ptr().cast()
}

/// The library's version as one number, packed as `STRATA_MAKE_VERSION` packs it
/// (compare it with `STRATA_VERSION` of the headers).
#[unsafe(no_mangle)]
pub extern "C" fn strata_vk_version_number() -> u32 {
    LIBRARY_VERSION
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::guard::report;

    #[test]
    fn messages_are_cut_at_a_character_boundary_and_terminated() {
        let mut error = StrataError { status: StrataStatus::Ok, message: [1; STRATA_ERROR_MESSAGE_BYTES] };
        let long = "é".repeat(STRATA_ERROR_MESSAGE_BYTES);
        // SAFETY: a valid, writable error.
        unsafe { report(&mut error, StrataStatus::Buffer, &long) };
        let end = error.message.iter().position(|&c| c == 0).expect("terminated");
        let bytes: Vec<u8> = error.message[..end].iter().map(|&c| c as u8).collect();
        let text = String::from_utf8(bytes).expect("whole characters");
        assert!(end < STRATA_ERROR_MESSAGE_BYTES && text.chars().all(|c| c == 'é') && text.len() == end);
        assert_eq!(error.status, StrataStatus::Buffer);
    }

    #[test]
    fn a_panic_inside_a_call_is_a_status_not_an_unwind() {
        let mut error = StrataError { status: StrataStatus::Ok, message: [0; STRATA_ERROR_MESSAGE_BYTES] };
        // SAFETY: a valid, writable error.
        let status = unsafe { guarded(&mut error, || panic!("a bug")) };
        assert_eq!(status, StrataStatus::Internal);
        let end = error.message.iter().position(|&c| c == 0).unwrap();
        let text: String = error.message[..end].iter().map(|&c| c as u8 as char).collect();
        assert!(text.contains("a bug"), "{text}");
    }
}
