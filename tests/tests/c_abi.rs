//! The C ABI of `strata_vk` (capi/) called as C calls it, with what a careless engine
//! passes: null pointers, handles that are not the library's, bindings of another pass,
//! buffers too small, settings out of range, a device claiming a feature it lacks. Every
//! call returns a status and a one-line message naming the argument, field or buffer;
//! nothing unwinds across the boundary. (That the pass computes what the Rust pass
//! computes is `export_c.rs`'s, through the C program.)

use ash::vk::{self, Handle};
use strata_tests::AshEngine;
use strata_vk::*;

fn message(error: &StrataError) -> String {
    let bytes: Vec<u8> = error.message.iter().take_while(|&&c| c != 0).map(|&c| c as u8).collect();
    String::from_utf8(bytes).unwrap()
}

fn no_error() -> StrataError {
    StrataError { status: StrataStatus::Ok, message: [0; STRATA_ERROR_MESSAGE_BYTES] }
}

fn settings() -> StrataSelectionSettings {
    StrataSelectionSettings { block_size: 16, candidates: 4, sampler: 4, masking: 1, block_shift: 0 }
}

fn device(engine: &AshEngine) -> StrataVkDevice {
    StrataVkDevice {
        get_instance_proc_addr: Some(engine.get_instance_proc_addr()),
        instance: engine.instance.handle(),
        physical_device: engine.physical_device,
        device: engine.device.handle(),
        shader_zero_initialize_workgroup_memory: 0,
    }
}

/// `strata_vk_create` on `device` with `settings` at 16 × 8: the status, the message and
/// the pass (null unless made).
fn create(device: &StrataVkDevice, settings: &StrataSelectionSettings) -> (StrataStatus, String, *mut StrataVkPass) {
    let mut error = no_error();
    let mut pass = std::ptr::null_mut();
    // SAFETY: valid pointers; the device's handles are live.
    let status = unsafe { strata_vk_create(device, settings, 16, 8, &mut pass, &mut error) };
    assert_eq!(status, error.status, "the status returned and the one reported agree");
    (status, message(&error), pass)
}

#[test]
fn bad_arguments_are_status_codes_with_messages() {
    let Some(engine) = AshEngine::open_plain("bad_arguments_are_status_codes_with_messages") else { return };
    let good = device(&engine);
    // Null pointers: named.
    let mut error = no_error();
    let mut pass = std::ptr::null_mut();
    // SAFETY: null pointers are what is under test; the function refuses them.
    let status = unsafe { strata_vk_create(std::ptr::null(), &settings(), 16, 8, &mut pass, &mut error) };
    assert_eq!((status, message(&error).as_str()), (StrataStatus::InvalidArgument, "device is NULL"));
    // SAFETY: as above.
    let status = unsafe { strata_vk_create(&good, std::ptr::null(), 16, 8, &mut pass, std::ptr::null_mut()) };
    assert_eq!(status, StrataStatus::InvalidArgument, "a NULL error pointer is allowed");
    let missing_loader = StrataVkDevice { get_instance_proc_addr: None, ..good };
    assert!(create(&missing_loader, &settings()).1.contains("get_instance_proc_addr is NULL"));
    let missing_device = StrataVkDevice { device: vk::Device::null(), ..good };
    assert!(create(&missing_device, &settings()).1.contains("device->device is VK_NULL_HANDLE"));
    // Settings: the field, its value, what it may be.
    for (bad, field) in [
        (StrataSelectionSettings { block_size: 12, ..settings() }, "block_size = 12"),
        (StrataSelectionSettings { candidates: 0, ..settings() }, "candidates = 0"),
        (StrataSelectionSettings { sampler: 9, ..settings() }, "sampler = 9"),
        (StrataSelectionSettings { masking: 2, ..settings() }, "masking = 2"),
    ] {
        let (status, text, pass) = create(&good, &bad);
        assert_eq!(status, StrataStatus::Settings, "{text}");
        assert!(text.contains(field) && !text.contains('\n'), "{text}");
        assert!(pass.is_null());
    }
    let (status, text, _) = create(&StrataVkDevice { shader_zero_initialize_workgroup_memory: 5, ..good }, &settings());
    assert_eq!(status, StrataStatus::InvalidArgument, "{text}");
    // An image of no pixels.
    let mut error = no_error();
    // SAFETY: valid pointers.
    let status = unsafe { strata_vk_create(&good, &settings(), 0, 8, &mut pass, &mut error) };
    assert_eq!(status, StrataStatus::ImageSize, "{}", message(&error));

    // A pass, and what is refused once it exists.
    let (status, text, pass) = create(&good, &settings());
    assert_eq!(status, StrataStatus::Ok, "{text}");
    let (_, _, other) = create(&good, &settings());
    let slice = |buffer: vk::Buffer, size: u64| StrataVkBufferSlice { buffer, offset: 0, size };
    let pixels = 16 * 8;
    let buffers = [
        engine.buffer(8 * pixels, &[]),
        engine.buffer(32 * pixels, &[]),
        engine.buffer(48 * pixels, &[]),
        engine.buffer(16 * pixels, &[]),
    ];
    let none = slice(vk::Buffer::null(), 0);
    let good_buffers = StrataVkBuffers {
        candidates: slice(buffers[0].0, 8 * pixels),
        payloads: none,
        selections: slice(buffers[1].0, 32 * pixels),
        resample_inputs: slice(buffers[2].0, 48 * pixels),
        resampled: slice(buffers[3].0, 16 * pixels),
    };
    let bind = |pass: *mut StrataVkPass, buffers: &StrataVkBuffers| {
        let mut error = no_error();
        let mut bindings = std::ptr::null_mut();
        // SAFETY: the pass pointer is under test; the rest are valid.
        let status = unsafe { strata_vk_bind(pass, buffers, &mut bindings, &mut error) };
        (status, message(&error), bindings)
    };
    let small = StrataVkBuffers { selections: slice(buffers[1].0, 32 * pixels - 4), ..good_buffers };
    let (status, text, _) = bind(pass, &small);
    assert_eq!(status, StrataStatus::Buffer);
    assert!(text.contains("`selections`") && text.contains("4092"), "{text}");
    let half = StrataVkBuffers { resampled: none, ..good_buffers };
    let (status, text, _) = bind(pass, &half);
    assert_eq!(status, StrataStatus::InvalidArgument);
    assert!(text.contains("resample_inputs and buffers->resampled"), "{text}");
    // A handle that is not a pass: looked up among the live handles, never read.
    let mut not_a_pass = [0u8; 1];
    let (status, text, _) = bind(not_a_pass.as_mut_ptr().cast(), &good_buffers);
    assert_eq!(
        (status, text.as_str()),
        (StrataStatus::InvalidArgument, "pass is not a live pass made by strata_vk_create")
    );
    let (status, text, bindings) = bind(pass, &good_buffers);
    assert_eq!(status, StrataStatus::Ok, "{text}");
    // Bindings of another pass, and bindings passed as a pass.
    let mut error = no_error();
    // SAFETY: the handles are under test; the command buffer is never used when they are refused.
    let status = unsafe { strata_vk_record_selection(other, bindings, vk::CommandBuffer::from_raw(1), 0, &mut error) };
    assert_eq!(
        (status, message(&error).as_str()),
        (StrataStatus::InvalidArgument, "bindings were made by another pass")
    );
    // SAFETY: as above.
    let status = unsafe { strata_vk_set_seed(bindings.cast(), 3, &mut error) };
    assert_eq!(status, StrataStatus::InvalidArgument, "{}", message(&error));
    // SAFETY: as above.
    let status = unsafe { strata_vk_record_resampling(pass, bindings, vk::CommandBuffer::null(), &mut error) };
    assert_eq!((status, message(&error).as_str()), (StrataStatus::InvalidArgument, "command_buffer is NULL"));
    // A pass is not destroyed under its live bindings.
    // SAFETY: the pass is live; the call refuses.
    let status = unsafe { strata_vk_destroy(pass, &mut error) };
    assert_eq!(status, StrataStatus::InvalidArgument);
    assert!(message(&error).contains("1 bindings of this pass are still live"), "{}", message(&error));
    // Teardown, and null handles to the destroyers are nothing.
    // SAFETY: nothing was submitted; each handle is destroyed once, and the second
    // destruction of the bindings is refused without touching them.
    unsafe {
        assert_eq!(strata_vk_destroy_bindings(pass, bindings, &mut error), StrataStatus::Ok);
        assert_eq!(strata_vk_destroy_bindings(pass, bindings, &mut error), StrataStatus::InvalidArgument);
        assert!(message(&error).contains("not live bindings"), "{}", message(&error));
        assert_eq!(strata_vk_destroy_bindings(pass, std::ptr::null_mut(), &mut error), StrataStatus::Ok);
        assert_eq!(strata_vk_destroy(pass, &mut error), StrataStatus::Ok);
        assert_eq!(strata_vk_destroy(other, &mut error), StrataStatus::Ok);
        assert_eq!(strata_vk_destroy(std::ptr::null_mut(), &mut error), StrataStatus::Ok);
    }
    for buffer in buffers {
        engine.free(buffer);
    }
    // SAFETY: a static NUL-terminated string.
    let version = unsafe { std::ffi::CStr::from_ptr(strata_vk_version()) };
    assert_eq!(version.to_str().unwrap(), env!("CARGO_PKG_VERSION"));
}
