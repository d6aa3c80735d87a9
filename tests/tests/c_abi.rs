//! The C ABI of `strata_vk` (capi/) called as C calls it, with what a careless engine
//! passes: null pointers, handles that are not the library's, destroyed handles whose
//! value could be handed out again, bindings of another pass, buffers too small or
//! overlapping, settings out of range, a device claiming a feature it lacks. Every call
//! returns a status and a one-line message naming the argument, field or buffer; nothing
//! unwinds across the boundary. And its threads: two threads binding and recording on one
//! pass at once, and a handle that a call on another thread is using refused for
//! destruction. (That the pass computes what the Rust pass computes is `export_c.rs`'s,
//! through the C program.)

use ash::vk::{self, Handle as _};
use std::ffi::{CStr, c_char};
use std::sync::{Condvar, Mutex, MutexGuard, PoisonError};
use std::time::{Duration, Instant};
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
    let status = unsafe { strata_vk_create(LIBRARY_VERSION, device, settings, 16, 8, &mut pass, &mut error) };
    assert_eq!(status, error.status, "the status returned and the one reported agree");
    (status, message(&error), pass)
}

#[test]
fn headers_of_another_major_version_are_refused_at_create() {
    let [major, minor, patch] = version_parts(LIBRARY_VERSION);
    // SAFETY: a static NUL-terminated string.
    let text = unsafe { CStr::from_ptr(strata_vk_version()) }.to_str().unwrap();
    assert_eq!(text, format!("{major}.{minor}.{patch}"), "the two version queries agree");
    assert_eq!(strata_vk_version_number(), LIBRARY_VERSION);
    // Each header version with the status create gives it (a NULL device: refused as such
    // once the version is accepted, so nothing needs a Vulkan device).
    let mut cases = vec![
        (LIBRARY_VERSION, StrataStatus::InvalidArgument),
        (make_version(major, minor, patch + 1), StrataStatus::InvalidArgument),
        (make_version(major + 1, minor, patch), StrataStatus::Version),
        (make_version(major + 1, 0, 0), StrataStatus::Version),
    ];
    if major > 0 {
        cases.push((make_version(major - 1, minor, patch), StrataStatus::Version));
        cases.push((make_version(major, minor + 1, 0), StrataStatus::InvalidArgument));
    } else {
        // Before 1.0 a minor version is a major one (semantic versioning, as Cargo reads it).
        cases.push((make_version(0, minor + 1, 0), StrataStatus::Version));
    }
    for (header, want) in cases {
        let mut error = no_error();
        let mut pass: *mut StrataVkPass = std::ptr::dangling_mut();
        // SAFETY: a NULL device is refused, never read; the other pointers are valid.
        let status = unsafe { strata_vk_create(header, std::ptr::null(), &settings(), 16, 8, &mut pass, &mut error) };
        let text = message(&error);
        let [h_major, h_minor, h_patch] = version_parts(header);
        assert_eq!(status, want, "header {h_major}.{h_minor}.{h_patch}: {text}");
        assert!(pass.is_null());
        if want == StrataStatus::Version {
            let named = format!("header_version = {header} ({h_major}.{h_minor}.{h_patch}");
            assert!(text.starts_with(&named) && text.contains(env!("CARGO_PKG_VERSION")), "{text}");
            assert!(!text.contains('\n'), "{text}");
        } else {
            assert_eq!(text, "device is NULL");
        }
    }
}

#[test]
fn bad_arguments_are_status_codes_with_messages() {
    let Some(engine) = AshEngine::open_plain("bad_arguments_are_status_codes_with_messages") else { return };
    let good = device(&engine);
    // Null pointers: named.
    let mut error = no_error();
    let mut pass = std::ptr::null_mut();
    // SAFETY: null pointers are what is under test; the function refuses them.
    let status =
        unsafe { strata_vk_create(LIBRARY_VERSION, std::ptr::null(), &settings(), 16, 8, &mut pass, &mut error) };
    assert_eq!((status, message(&error).as_str()), (StrataStatus::InvalidArgument, "device is NULL"));
    // SAFETY: as above.
    let status =
        unsafe { strata_vk_create(LIBRARY_VERSION, &good, std::ptr::null(), 16, 8, &mut pass, std::ptr::null_mut()) };
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
    let status = unsafe { strata_vk_create(LIBRARY_VERSION, &good, &settings(), 0, 8, &mut pass, &mut error) };
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
    let small = StrataVkBuffers { selections: slice(buffers[1].0, 32 * pixels - 4), ..good_buffers };
    let (status, text, _) = bind(pass, &small);
    assert_eq!(status, StrataStatus::Buffer);
    assert!(text.contains("`selections`") && text.contains("4092"), "{text}");
    let half = StrataVkBuffers { resampled: none, ..good_buffers };
    let (status, text, _) = bind(pass, &half);
    assert_eq!(status, StrataStatus::InvalidArgument);
    assert!(text.contains("resample_inputs and buffers->resampled"), "{text}");
    // Two roles in overlapping bytes of one buffer: the pass would write its selections
    // over its resampled records.
    let overlapping = StrataVkBuffers { resampled: slice(buffers[1].0, 16 * pixels), ..good_buffers };
    let (status, text, _) = bind(pass, &overlapping);
    assert_eq!(status, StrataStatus::Buffer, "{text}");
    assert!(text.contains("`selections`") && text.contains("`resampled`") && !text.contains('\n'), "{text}");
    // A range that ends past 2^64 - 1 (a multiple of any offset alignment).
    let wrapping = StrataVkBufferSlice { buffer: buffers[0].0, offset: 1 << 63, size: 1 << 63 };
    let (status, text, _) = bind(pass, &StrataVkBuffers { candidates: wrapping, ..good_buffers });
    assert_eq!(status, StrataStatus::Buffer, "{text}");
    assert!(text.contains("`candidates`") && text.contains(&(1u64 << 63).to_string()), "{text}");
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

/// `strata_vk_bind` of `buffers` to `pass`: the status, the message and the bindings
/// (null unless made).
fn bind(pass: *mut StrataVkPass, buffers: &StrataVkBuffers) -> (StrataStatus, String, *mut StrataVkBindings) {
    let mut error = no_error();
    let mut bindings = std::ptr::null_mut();
    // SAFETY: the pass pointer is under test (looked up, never read, by the library); the
    // rest are valid.
    let status = unsafe { strata_vk_bind(pass, buffers, &mut bindings, &mut error) };
    assert_eq!(status, error.status, "the status returned and the one reported agree");
    (status, message(&error), bindings)
}

/// Pixels of the 16 × 8 image of [`create`].
const PIXELS: u64 = 16 * 8;

/// An engine's buffers for one pass of [`create`]'s size (candidates with a few objects
/// and luminance levels, resampling weights; selections and resampled zeroed), freed on
/// drop.
struct EngineBuffers<'a> {
    engine: &'a AshEngine,
    candidates: (vk::Buffer, vk::DeviceMemory),
    selections: (vk::Buffer, vk::DeviceMemory),
    resample_inputs: (vk::Buffer, vk::DeviceMemory),
    resampled: (vk::Buffer, vk::DeviceMemory),
}

impl<'a> EngineBuffers<'a> {
    fn new(engine: &'a AshEngine) -> Self {
        let candidates: Vec<[u32; 2]> =
            (0..PIXELS as u32).map(|p| [(((p * 7919) % 23) as f32 * 0.25).to_bits(), (p % 16) / 5]).collect();
        let weights: Vec<[f32; 12]> = (0..PIXELS as u32)
            .map(|p| {
                let w = 1.0 + (p % 3) as f32;
                [w, 0.5, 2.0, 0.25, 1.0, 2.0, 3.0, 4.0, 0.5, 0.5, f32::from_bits(p), 0.0]
            })
            .collect();
        Self {
            engine,
            candidates: engine.buffer(8 * PIXELS, bytemuck::cast_slice(&candidates)),
            selections: engine.buffer(32 * PIXELS, &[]),
            resample_inputs: engine.buffer(48 * PIXELS, bytemuck::cast_slice(&weights)),
            resampled: engine.buffer(16 * PIXELS, &[]),
        }
    }

    /// The slices as `strata_vk_bind` takes them (no payloads: a pixel's is its index).
    fn slices(&self) -> StrataVkBuffers {
        let slice =
            |(buffer, _): (vk::Buffer, vk::DeviceMemory), size: u64| StrataVkBufferSlice { buffer, offset: 0, size };
        StrataVkBuffers {
            candidates: slice(self.candidates, 8 * PIXELS),
            payloads: StrataVkBufferSlice { buffer: vk::Buffer::null(), offset: 0, size: 0 },
            selections: slice(self.selections, 32 * PIXELS),
            resample_inputs: slice(self.resample_inputs, 48 * PIXELS),
            resampled: slice(self.resampled, 16 * PIXELS),
        }
    }

    /// What the pass wrote: selections and resampled records, as words.
    fn outputs(&self) -> (Vec<u32>, Vec<u32>) {
        (self.engine.read(self.selections.1, 32 * PIXELS), self.engine.read(self.resampled.1, 16 * PIXELS))
    }
}

impl Drop for EngineBuffers<'_> {
    fn drop(&mut self) {
        for buffer in [self.candidates, self.selections, self.resample_inputs, self.resampled] {
            self.engine.free(buffer);
        }
    }
}

#[test]
fn a_destroyed_handle_stays_dead_when_its_value_could_be_handed_out_again() {
    let test = "a_destroyed_handle_stays_dead_when_its_value_could_be_handed_out_again";
    let Some(engine) = AshEngine::open(test) else { return };
    let (status, text, pass) = create(&device(&engine), &settings());
    assert_eq!(status, StrataStatus::Ok, "{text}");
    let buffers = EngineBuffers::new(&engine);
    let mut error = no_error();
    // Destroy x, bind y (the allocator may give y x's old address), then destroy x again.
    let (status, text, x) = bind(pass, &buffers.slices());
    assert_eq!(status, StrataStatus::Ok, "{text}");
    // SAFETY: live handles; nothing was recorded with x.
    assert_eq!(unsafe { strata_vk_destroy_bindings(pass, x, &mut error) }, StrataStatus::Ok);
    let (status, text, y) = bind(pass, &buffers.slices());
    assert_eq!(status, StrataStatus::Ok, "{text}");
    eprintln!("{test}: x = {x:p}, y = {y:p}");
    // SAFETY: x is a destroyed handle (what is under test: refused without being read).
    let status = unsafe { strata_vk_destroy_bindings(pass, x, &mut error) };
    assert_eq!(status, StrataStatus::InvalidArgument, "destroying x a second time: {}", message(&error));
    assert!(message(&error).contains("not live bindings"), "{}", message(&error));
    // SAFETY: as above; the command buffer is never used when the bindings are refused.
    let status = unsafe { strata_vk_record_selection(pass, x, vk::CommandBuffer::from_raw(1), 0, &mut error) };
    assert_eq!(status, StrataStatus::InvalidArgument, "recording with x: {}", message(&error));
    // y is untouched: it records, runs and is destroyed (once).
    engine.submit(|command_buffer| {
        let mut error = no_error();
        // SAFETY: a recording command buffer of the pass's device; the buffers outlive
        // the submission, which `submit` waits for.
        unsafe {
            let status = strata_vk_record_selection(pass, y, command_buffer, 0, &mut error);
            assert_eq!(status, StrataStatus::Ok, "recording with y: {}", message(&error));
            let status = strata_vk_record_resampling(pass, y, command_buffer, &mut error);
            assert_eq!(status, StrataStatus::Ok, "resampling with y: {}", message(&error));
        }
    });
    let (selections, resampled) = buffers.outputs();
    assert!(selections.iter().any(|&w| w != 0) && resampled.iter().any(|&w| w != 0), "y's commands wrote nothing");
    // SAFETY: the submission was waited for; the second call is refused untouched.
    unsafe {
        assert_eq!(strata_vk_destroy_bindings(pass, y, &mut error), StrataStatus::Ok, "{}", message(&error));
        assert_eq!(strata_vk_destroy_bindings(pass, y, &mut error), StrataStatus::InvalidArgument);
    }
    // No handle value is handed out twice, bindings or passes.
    let mut seen = std::collections::HashSet::from([x.addr(), y.addr(), pass.addr()]);
    for _ in 0..64 {
        let (status, text, bindings) = bind(pass, &buffers.slices());
        assert_eq!(status, StrataStatus::Ok, "{text}");
        assert!(seen.insert(bindings.addr()), "bindings {bindings:p} handed out a second time");
        // SAFETY: live handles, nothing recorded.
        assert_eq!(unsafe { strata_vk_destroy_bindings(pass, bindings, &mut error) }, StrataStatus::Ok);
    }
    // SAFETY: a live pass without bindings, nothing pending.
    assert_eq!(unsafe { strata_vk_destroy(pass, &mut error) }, StrataStatus::Ok, "{}", message(&error));
    let (status, text, other) = create(&device(&engine), &settings());
    assert_eq!(status, StrataStatus::Ok, "{text}");
    eprintln!("{test}: pass = {pass:p}, the next pass = {other:p}");
    assert!(seen.insert(other.addr()), "pass {other:p} handed out a second time");
    // SAFETY: `pass` is destroyed (refused without being read); `other` is live.
    unsafe {
        assert_eq!(strata_vk_set_seed(pass, 1, &mut error), StrataStatus::InvalidArgument);
        assert_eq!(strata_vk_destroy(pass, &mut error), StrataStatus::InvalidArgument);
        assert!(message(&error).contains("not a live pass"), "{}", message(&error));
        assert_eq!(strata_vk_set_seed(other, 1, &mut error), StrataStatus::Ok, "{}", message(&error));
        assert_eq!(strata_vk_destroy(other, &mut error), StrataStatus::Ok, "{}", message(&error));
    }
}

// The threading tests: the pass is made through a loader of the test's own
// (`hooked_get_instance_proc_addr`) whose `vkCmdDispatch` and `vkCreateDescriptorPool`
// wait at a gate, so that a call of the library is provably inside the driver while
// another thread calls in too.

/// The driver's functions behind the hooked loader.
#[derive(Clone, Copy)]
struct Driver {
    get_instance_proc_addr: vk::PFN_vkGetInstanceProcAddr,
    get_device_proc_addr: vk::PFN_vkGetDeviceProcAddr,
    cmd_dispatch: vk::PFN_vkCmdDispatch,
    create_descriptor_pool: vk::PFN_vkCreateDescriptorPool,
}

static DRIVER: Mutex<Option<Driver>> = Mutex::new(None);

/// The hooked tests take turns (one gate, one driver).
static HOOKED_TESTS: Mutex<()> = Mutex::new(());

fn driver() -> Driver {
    DRIVER.lock().unwrap_or_else(PoisonError::into_inner).expect("the driver's functions are installed")
}

/// `engine`'s device as `strata_vk_create` takes it, through the hooked loader.
fn hooked_device(engine: &AshEngine) -> StrataVkDevice {
    *DRIVER.lock().unwrap_or_else(PoisonError::into_inner) = Some(Driver {
        get_instance_proc_addr: engine.get_instance_proc_addr(),
        get_device_proc_addr: engine.instance.fp_v1_0().get_device_proc_addr,
        cmd_dispatch: engine.device.fp_v1_0().cmd_dispatch,
        create_descriptor_pool: engine.device.fp_v1_0().create_descriptor_pool,
    });
    StrataVkDevice { get_instance_proc_addr: Some(hooked_get_instance_proc_addr), ..device(engine) }
}

/// A function pointer as `vkGet*ProcAddr` returns it.
macro_rules! void_function {
    ($function:expr, $type:ty) => {{
        let function: $type = $function;
        // SAFETY: function pointers of one ABI; the caller casts it back to `$type`.
        Some(unsafe { std::mem::transmute::<$type, unsafe extern "system" fn()>(function) })
    }};
}

unsafe extern "system" fn hooked_get_instance_proc_addr(
    instance: vk::Instance,
    name: *const c_char,
) -> vk::PFN_vkVoidFunction {
    // SAFETY: vkGetInstanceProcAddr's contract: a NUL-terminated name.
    if unsafe { CStr::from_ptr(name) } == c"vkGetDeviceProcAddr" {
        return void_function!(hooked_get_device_proc_addr, vk::PFN_vkGetDeviceProcAddr);
    }
    // SAFETY: forwarded as received.
    unsafe { (driver().get_instance_proc_addr)(instance, name) }
}

unsafe extern "system" fn hooked_get_device_proc_addr(
    device: vk::Device,
    name: *const c_char,
) -> vk::PFN_vkVoidFunction {
    // SAFETY: vkGetDeviceProcAddr's contract: a NUL-terminated name.
    let wanted = unsafe { CStr::from_ptr(name) };
    if wanted == c"vkCmdDispatch" {
        return void_function!(hooked_cmd_dispatch, vk::PFN_vkCmdDispatch);
    }
    if wanted == c"vkCreateDescriptorPool" {
        return void_function!(hooked_create_descriptor_pool, vk::PFN_vkCreateDescriptorPool);
    }
    // SAFETY: forwarded as received.
    unsafe { (driver().get_device_proc_addr)(device, name) }
}

unsafe extern "system" fn hooked_cmd_dispatch(command_buffer: vk::CommandBuffer, x: u32, y: u32, z: u32) {
    pass_gate();
    // SAFETY: forwarded as received.
    unsafe { (driver().cmd_dispatch)(command_buffer, x, y, z) }
}

unsafe extern "system" fn hooked_create_descriptor_pool(
    device: vk::Device,
    info: *const vk::DescriptorPoolCreateInfo<'_>,
    allocator: *const vk::AllocationCallbacks<'_>,
    pool: *mut vk::DescriptorPool,
) -> vk::Result {
    pass_gate();
    // SAFETY: forwarded as received.
    unsafe { (driver().create_descriptor_pool)(device, info, allocator, pool) }
}

/// What a hooked call does at the gate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Mode {
    /// Goes on.
    Open,
    /// Waits until `threads` calls are inside at once, `times` times over, then opens.
    Meet { threads: usize, times: usize },
    /// Waits until the test opens the gate.
    Hold,
}

struct GateState {
    mode: Mode,
    /// Hooked calls waiting at the gate now.
    inside: usize,
    /// How many times the calls of a `Meet` were all inside at once.
    met: usize,
    /// Counts the meetings, so that every call of one meeting goes on.
    generation: u64,
    /// Whether a call gave up waiting ([`GATE_TIMEOUT`]).
    timed_out: bool,
}

static GATE: Mutex<GateState> =
    Mutex::new(GateState { mode: Mode::Open, inside: 0, met: 0, generation: 0, timed_out: false });
static GATE_CHANGED: Condvar = Condvar::new();

/// How long a call waits at the gate at most (the test's checks then fail, nothing hangs).
const GATE_TIMEOUT: Duration = Duration::from_secs(30);

fn gate() -> MutexGuard<'static, GateState> {
    GATE.lock().unwrap_or_else(PoisonError::into_inner)
}

fn set_gate(mode: Mode) {
    let mut state = gate();
    state.mode = mode;
    state.met = 0;
    state.timed_out = false;
    GATE_CHANGED.notify_all();
}

/// Waits (at most [`GATE_TIMEOUT`]) until `calls` hooked calls wait at the gate.
fn wait_inside(calls: usize) -> bool {
    let deadline = Instant::now() + GATE_TIMEOUT;
    let mut state = gate();
    while state.inside < calls {
        let left = deadline.saturating_duration_since(Instant::now());
        if left.is_zero() {
            return false;
        }
        state = GATE_CHANGED.wait_timeout(state, left).unwrap_or_else(PoisonError::into_inner).0;
    }
    true
}

/// A hooked call's wait at the gate.
fn pass_gate() {
    let mut state = gate();
    state.inside += 1;
    let generation = state.generation;
    GATE_CHANGED.notify_all();
    let deadline = Instant::now() + GATE_TIMEOUT;
    loop {
        if state.generation != generation {
            break;
        }
        match state.mode {
            Mode::Open => break,
            Mode::Meet { threads, times } if state.inside >= threads => {
                state.met += 1;
                state.generation += 1;
                state.mode = if times > 1 { Mode::Meet { threads, times: times - 1 } } else { Mode::Open };
                break;
            }
            _ => {}
        }
        let left = deadline.saturating_duration_since(Instant::now());
        if left.is_zero() {
            state.timed_out = true;
            break;
        }
        state = GATE_CHANGED.wait_timeout(state, left).unwrap_or_else(PoisonError::into_inner).0;
    }
    state.inside -= 1;
    GATE_CHANGED.notify_all();
}

/// Opens the gate when dropped (a failed check never leaves a thread waiting).
struct OpenOnDrop;

impl Drop for OpenOnDrop {
    fn drop(&mut self) {
        set_gate(Mode::Open);
    }
}

/// Handles sent to the test's threads (C handles are plain values a C engine shares
/// between its threads as it likes).
struct Shared<T>(*mut T);

impl<T> Clone for Shared<T> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<T> Copy for Shared<T> {}

// SAFETY: a handle is a value the library looks up; nothing is reached through it here.
unsafe impl<T> Send for Shared<T> {}
// SAFETY: as above.
unsafe impl<T> Sync for Shared<T> {}

impl<T> Shared<T> {
    fn get(self) -> *mut T {
        self.0
    }
}

/// The queue family of `engine`'s queue (AshEngine takes the first with compute).
fn compute_family(engine: &AshEngine) -> u32 {
    // SAFETY: valid handles.
    let families = unsafe { engine.instance.get_physical_device_queue_family_properties(engine.physical_device) };
    families.iter().position(|f| f.queue_flags.contains(vk::QueueFlags::COMPUTE)).expect("a compute family") as u32
}

/// Submits `command_buffer` on `engine`'s queue and waits.
fn run(engine: &AshEngine, command_buffer: vk::CommandBuffer) {
    let buffers = [command_buffer];
    // SAFETY: an ended command buffer of the device; waited for.
    unsafe {
        engine
            .device
            .queue_submit(engine.queue, &[vk::SubmitInfo::default().command_buffers(&buffers)], vk::Fence::null())
            .expect("submit");
        engine.device.queue_wait_idle(engine.queue).expect("wait");
    }
}

#[test]
fn two_threads_bind_and_record_on_one_pass_at_once() {
    let _turn = HOOKED_TESTS.lock().unwrap_or_else(PoisonError::into_inner);
    let test = "two_threads_bind_and_record_on_one_pass_at_once";
    let Some(engine) = AshEngine::open(test) else { return };
    let (status, text, pass) = create(&hooked_device(&engine), &settings());
    assert_eq!(status, StrataStatus::Ok, "{text}");
    // Threads record frames in any order (and the same frame again): validation off.
    // SAFETY: a live pass; a valid error.
    assert_eq!(unsafe { strata_vk_set_validation(pass, 0, &mut no_error()) }, StrataStatus::Ok);
    let family = compute_family(&engine);
    let buffers = [EngineBuffers::new(&engine), EngineBuffers::new(&engine)];
    let _open = OpenOnDrop;
    // Both threads must be inside strata_vk_bind at once, then inside a record call at once.
    set_gate(Mode::Meet { threads: 2, times: 2 });
    let shared = Shared(pass);
    let recorded: Vec<(vk::CommandPool, vk::CommandBuffer, Shared<StrataVkBindings>)> = std::thread::scope(|scope| {
        let threads: Vec<_> = (0..2)
            .map(|t| {
                let (engine, buffers) = (&engine, &buffers[t]);
                scope.spawn(move || {
                    let pass = shared.get();
                    // Its own command pool: a pool is externally synchronised (the engine's part).
                    let info = vk::CommandPoolCreateInfo::default().queue_family_index(family);
                    // SAFETY: valid device and create info; destroyed below.
                    let pool = unsafe { engine.device.create_command_pool(&info, None) }.expect("pool");
                    let allocate = vk::CommandBufferAllocateInfo::default()
                        .command_pool(pool)
                        .level(vk::CommandBufferLevel::PRIMARY)
                        .command_buffer_count(1);
                    // SAFETY: a pool of this thread.
                    let command_buffer = unsafe { engine.device.allocate_command_buffers(&allocate) }.unwrap()[0];
                    let (status, text, bindings) = bind(pass, &buffers.slices());
                    assert_eq!(status, StrataStatus::Ok, "thread {t}: {text}");
                    let mut error = no_error();
                    // SAFETY: a live pass; the same seed from both threads.
                    let status = unsafe { strata_vk_set_seed(pass, 7, &mut error) };
                    assert_eq!(status, StrataStatus::Ok, "thread {t}: {}", message(&error));
                    // SAFETY: this thread's command buffer, recording, of the pass's
                    // device; the buffers outlive its submission below.
                    unsafe {
                        engine.device.begin_command_buffer(command_buffer, &Default::default()).expect("begin");
                        let status = strata_vk_record_selection(pass, bindings, command_buffer, t as u32, &mut error);
                        assert_eq!(status, StrataStatus::Ok, "thread {t}: {}", message(&error));
                        let status = strata_vk_record_resampling(pass, bindings, command_buffer, &mut error);
                        assert_eq!(status, StrataStatus::Ok, "thread {t}: {}", message(&error));
                        engine.device.end_command_buffer(command_buffer).expect("end");
                    }
                    (pool, command_buffer, Shared(bindings))
                })
            })
            .collect();
        threads.into_iter().map(|thread| thread.join().expect("a recording thread failed")).collect()
    });
    let (met, timed_out) = {
        let state = gate();
        (state.met, state.timed_out)
    };
    assert!(
        met == 2 && !timed_out,
        "the two threads were not inside bind, then inside a record call, at the same time (met {met} times; a call \
         waited in vain: {timed_out})"
    );
    // Each thread's commands compute what the same frame recorded on one thread does.
    for (t, &(_, command_buffer, bindings)) in recorded.iter().enumerate() {
        run(&engine, command_buffer);
        let got = buffers[t].outputs();
        assert!(got.0.iter().any(|&w| w != 0), "thread {t}'s commands wrote no selections");
        engine.submit(|command_buffer| {
            let mut error = no_error();
            // SAFETY: a recording command buffer of the pass's device; waited for.
            unsafe {
                let status = strata_vk_record_selection(pass, bindings.get(), command_buffer, t as u32, &mut error);
                assert_eq!(status, StrataStatus::Ok, "{}", message(&error));
                let status = strata_vk_record_resampling(pass, bindings.get(), command_buffer, &mut error);
                assert_eq!(status, StrataStatus::Ok, "{}", message(&error));
            }
        });
        assert!(
            buffers[t].outputs() == got,
            "frame {t} recorded on thread {t} differs from the same frame recorded alone"
        );
    }
    let mut error = no_error();
    // SAFETY: every submission was waited for; each handle is destroyed once.
    unsafe {
        for (pool, command_buffer, bindings) in recorded {
            engine.device.free_command_buffers(pool, &[command_buffer]);
            engine.device.destroy_command_pool(pool, None);
            let status = strata_vk_destroy_bindings(pass, bindings.get(), &mut error);
            assert_eq!(status, StrataStatus::Ok, "{}", message(&error));
        }
        assert_eq!(strata_vk_destroy(pass, &mut error), StrataStatus::Ok, "{}", message(&error));
    }
}

#[test]
fn a_handle_in_use_by_a_call_on_another_thread_is_not_destroyed_under_it() {
    let _turn = HOOKED_TESTS.lock().unwrap_or_else(PoisonError::into_inner);
    let test = "a_handle_in_use_by_a_call_on_another_thread_is_not_destroyed_under_it";
    let Some(engine) = AshEngine::open(test) else { return };
    let (status, text, pass) = create(&hooked_device(&engine), &settings());
    assert_eq!(status, StrataStatus::Ok, "{text}");
    // Threads record frames in any order (and the same frame again): validation off.
    // SAFETY: a live pass; a valid error.
    assert_eq!(unsafe { strata_vk_set_validation(pass, 0, &mut no_error()) }, StrataStatus::Ok);
    let buffers = EngineBuffers::new(&engine);
    let _open = OpenOnDrop;
    let shared = Shared(pass);
    let mut error = no_error();

    // A thread inside strata_vk_bind (held in vkCreateDescriptorPool): the pass is in use.
    set_gate(Mode::Hold);
    let (destroyed, bindings) = std::thread::scope(|scope| {
        let binder = scope.spawn(|| {
            let (status, text, bindings) = bind(shared.get(), &buffers.slices());
            (status, text, Shared(bindings))
        });
        let inside = wait_inside(1);
        // SAFETY: a live pass (the call is what is under test).
        let destroyed = unsafe { strata_vk_destroy(pass, &mut error) };
        let refusal = message(&error);
        set_gate(Mode::Open);
        let (status, text, bindings) = binder.join().expect("the binding thread failed");
        assert!(inside, "the binding thread never reached vkCreateDescriptorPool");
        assert_eq!(status, StrataStatus::Ok, "{text}");
        ((destroyed, refusal), bindings.get())
    });
    eprintln!("{test}: strata_vk_destroy during strata_vk_bind: {destroyed:?}");
    assert_eq!(destroyed.0, StrataStatus::InvalidArgument, "the pass was destroyed under a call: {}", destroyed.1);
    assert!(destroyed.1.contains("in use"), "{}", destroyed.1);

    // A thread inside strata_vk_record_selection (held in vkCmdDispatch): the pass and
    // the bindings are in use.
    set_gate(Mode::Hold);
    let shared_bindings = Shared(bindings);
    let refused = std::thread::scope(|scope| {
        let recorder = scope.spawn(|| {
            let mut status = StrataStatus::Internal;
            engine.submit(|command_buffer| {
                let mut error = no_error();
                // SAFETY: a recording command buffer of the pass's device; waited for.
                status = unsafe {
                    strata_vk_record_selection(shared.get(), shared_bindings.get(), command_buffer, 0, &mut error)
                };
            });
            status
        });
        let inside = wait_inside(1);
        // SAFETY: live handles (the calls are what is under test).
        let bindings_destroyed = unsafe { strata_vk_destroy_bindings(pass, bindings, &mut error) };
        let bindings_refusal = message(&error);
        // SAFETY: as above.
        let pass_destroyed = unsafe { strata_vk_destroy(pass, &mut error) };
        let pass_refusal = message(&error);
        set_gate(Mode::Open);
        let recorded = recorder.join().expect("the recording thread failed");
        assert!(inside, "the recording thread never reached vkCmdDispatch");
        assert_eq!(recorded, StrataStatus::Ok, "the record call on the other thread");
        [(bindings_destroyed, bindings_refusal), (pass_destroyed, pass_refusal)]
    });
    eprintln!("{test}: destroying bindings, then the pass, during strata_vk_record_selection: {refused:?}");
    for (status, refusal) in &refused {
        assert_eq!(*status, StrataStatus::InvalidArgument, "destroyed under a call: {refusal}");
    }
    assert!(refused[0].1.contains("in use"), "{}", refused[0].1);
    // Once the calls have returned, both are destroyed as usual.
    // SAFETY: live handles; the submission was waited for.
    unsafe {
        assert_eq!(strata_vk_destroy_bindings(pass, bindings, &mut error), StrataStatus::Ok, "{}", message(&error));
        assert_eq!(strata_vk_destroy(pass, &mut error), StrataStatus::Ok, "{}", message(&error));
    }
}

/// A frame an engine records itself (B = 16, K = 4, block shifting, 45 × 29), as the pass
/// needs it: its dispatches and every buffer's size, for `frame` of seed 7.
fn good_check(frame: u32) -> StrataFrameCheck {
    use strata_embed::frame::{FrameId, frame_params, max_blocks};
    let settings = StrataSelectionSettings { block_size: 16, candidates: 4, sampler: 4, masking: 1, block_shift: 1 };
    let rust = strata_embed::SelectionSettings { block_size: 16, block_shift: true, ..Default::default() };
    let (width, height) = (45, 29);
    let id = FrameId { frame, seed: 7, identity_payload: false };
    let params = frame_params(&rust, width, height, id, 65_535).unwrap();
    let blocks = max_blocks(&rust, width, height);
    let bytes = |buffer: strata_embed::PassBuffer| buffer.bytes(width, height, blocks);
    use strata_embed::PassBuffer as B;
    StrataFrameCheck {
        settings,
        width,
        height,
        frame,
        previous_frame: frame.checked_sub(1).unwrap_or(STRATA_NO_FRAME),
        seed: 7,
        max_workgroups: 65_535,
        histogram_workgroups: params.histogram_workgroups,
        pixel_workgroups: params.pixel_workgroups,
        buffer_bytes: StrataBufferBytes {
            candidates: bytes(B::Candidates),
            payloads: bytes(B::Payloads),
            selections: bytes(B::Selections),
            resample_inputs: bytes(B::ResampleInputs),
            resampled: bytes(B::Resampled),
            sorted_pixels: bytes(B::SortedPixels),
            spans: bytes(B::Spans),
            block_stats: bytes(B::BlockStats),
            blue_noise: bytes(B::BlueNoise),
            histogram_params: bytes(B::HistogramParams),
            selection_params: bytes(B::SelectionParams),
        },
    }
}

/// `strata_vk_check_frame` of `check`: the status and the message.
fn check_frame(check: &StrataFrameCheck) -> (StrataStatus, String) {
    let mut error = no_error();
    // SAFETY: valid pointers.
    let status = unsafe { strata_vk_check_frame(check, &mut error) };
    assert_eq!(status, error.status);
    (status, message(&error))
}

#[test]
fn the_validation_mode_names_each_misuse_of_a_frame_an_engine_records() {
    // A frame whose block shift adds a workgroup to the histogram's dispatch.
    let frame = (1..64)
        .find(|&f| {
            let unshifted = StrataFrameCheck {
                settings: StrataSelectionSettings { block_shift: 0, ..good_check(f).settings },
                ..good_check(f)
            };
            good_check(f).histogram_workgroups != unshifted_dispatch(&unshifted)
        })
        .expect("a frame whose shift changes the histogram's dispatch");
    let good = good_check(frame);
    assert_eq!(check_frame(&good), (StrataStatus::Ok, String::new()));
    let [px, py, _] = good.pixel_workgroups;
    let blocks = |c: &StrataFrameCheck| {
        let (sx, sy) = strata_embed::frame::grid_shift(
            &strata_embed::SelectionSettings { block_size: 16, block_shift: true, ..Default::default() },
            c.frame,
            c.seed,
        );
        [(c.width + sx).div_ceil(16), (c.height + sy).div_ceil(16), 1]
    };
    let half = good.buffer_bytes.selections / 2;
    let smaller = 8 * 32 * 16;
    let cases: Vec<(&str, StrataFrameCheck, StrataStatus, &str)> = vec![
        (
            "floor instead of ceil",
            StrataFrameCheck { pixel_workgroups: [45 / 8, 29 / 8, 1], ..good },
            StrataStatus::Dispatch,
            "pixel_workgroups = 5x3x1: the pass needs 6x4x1; floor instead of ceil",
        ),
        (
            "the histogram per block in 2-D",
            StrataFrameCheck { histogram_workgroups: blocks(&good), ..good },
            StrataStatus::Dispatch,
            "one workgroup per block in 2-D",
        ),
        (
            "the histogram ignoring the block shift",
            StrataFrameCheck { histogram_workgroups: unshifted_dispatch(&good), ..good },
            StrataStatus::Dispatch,
            "block shift ignored",
        ),
        (
            "selections at half size",
            StrataFrameCheck { buffer_bytes: StrataBufferBytes { selections: half, ..good.buffer_bytes }, ..good },
            StrataStatus::Buffer,
            "buffer_bytes.selections = ",
        ),
        (
            "candidates for a smaller image",
            StrataFrameCheck { buffer_bytes: StrataBufferBytes { candidates: smaller, ..good.buffer_bytes }, ..good },
            StrataStatus::Buffer,
            "buffer_bytes.candidates = 4096: the pass needs 10440 (8 per pixel of 45x29)",
        ),
        (
            "the frame index repeated",
            StrataFrameCheck { previous_frame: frame, ..good },
            StrataStatus::FrameIndex,
            "repeated",
        ),
        (
            "a frame skipped",
            StrataFrameCheck { previous_frame: frame - 1, frame: frame + 1, ..good },
            StrataStatus::FrameIndex,
            "skipped",
        ),
        (
            "a setting out of range",
            StrataFrameCheck { settings: StrataSelectionSettings { candidates: 9, ..good.settings }, ..good },
            StrataStatus::Settings,
            "candidates = 9",
        ),
    ];
    for (misuse, check, status, named) in cases {
        let (got, text) = check_frame(&check);
        assert_eq!(got, status, "{misuse}: {text}");
        assert!(text.contains(named) && !text.contains('\n'), "{misuse}: {text}");
    }
    assert_eq!((px, py), (6, 4));
    // Without payloads or resampling (the optional buffers at 0): still a good frame.
    let bare = StrataBufferBytes { payloads: 0, resample_inputs: 0, resampled: 0, ..good.buffer_bytes };
    assert_eq!(check_frame(&StrataFrameCheck { buffer_bytes: bare, ..good }).0, StrataStatus::Ok);
    // SAFETY: a NULL check is refused, never read.
    assert_eq!(unsafe { strata_vk_check_frame(std::ptr::null(), std::ptr::null_mut()) }, StrataStatus::InvalidArgument);
}

/// The histogram's dispatch of `check`'s frame without its block shift.
fn unshifted_dispatch(check: &StrataFrameCheck) -> [u32; 3] {
    let groups = check.width.div_ceil(16) * check.height.div_ceil(16);
    let groups = groups.div_ceil(1024 / (16 * 16));
    let x = groups.min(check.max_workgroups);
    [x, groups.div_ceil(x), 1]
}

#[test]
fn a_pass_in_validation_mode_refuses_a_frame_index_that_does_not_advance_by_one() {
    let Some(engine) = AshEngine::open("a_pass_in_validation_mode_refuses_a_frame_index_that_does_not_advance_by_one")
    else {
        return;
    };
    let (status, text, pass) = create(&device(&engine), &settings());
    assert_eq!(status, StrataStatus::Ok, "{text}");
    let buffers = EngineBuffers::new(&engine);
    let (status, text, bindings) = bind(pass, &buffers.slices());
    assert_eq!(status, StrataStatus::Ok, "{text}");
    let mut error = no_error();
    // SAFETY: a live pass; validation is on by default only in a debug build.
    assert_eq!(unsafe { strata_vk_set_validation(pass, 1, &mut error) }, StrataStatus::Ok);
    let record = |frame: u32| {
        let mut result = (StrataStatus::Ok, String::new());
        engine.submit(|command_buffer| {
            let mut error = no_error();
            // SAFETY: a recording command buffer of the pass's device; waited for.
            let status = unsafe { strata_vk_record_selection(pass, bindings, command_buffer, frame, &mut error) };
            result = (status, message(&error));
        });
        result
    };
    assert_eq!(record(0).0, StrataStatus::Ok);
    assert_eq!(record(1).0, StrataStatus::Ok);
    let (status, text) = record(1);
    assert_eq!(status, StrataStatus::FrameIndex, "{text}");
    assert!(
        text.starts_with("frame = 1: the previous frame was 1, so this one must be 2") && !text.contains('\n'),
        "{text}"
    );
    let (status, text) = record(5);
    assert!(status == StrataStatus::FrameIndex && text.contains("skipped"), "{text}");
    assert_eq!(record(2).0, StrataStatus::Ok, "a refused frame is not taken as the last");
    // A new render starts anywhere; with validation off any frame records.
    // SAFETY: live handles, valid errors.
    unsafe {
        assert_eq!(strata_vk_set_seed(pass, 9, &mut error), StrataStatus::Ok);
        assert_eq!(record(40).0, StrataStatus::Ok);
        assert_eq!(strata_vk_set_validation(pass, 2, &mut error), StrataStatus::InvalidArgument);
        assert_eq!(strata_vk_set_validation(pass, 0, &mut error), StrataStatus::Ok);
    }
    assert_eq!(record(40).0, StrataStatus::Ok);
    // SAFETY: nothing pending (each submission was waited for).
    unsafe {
        assert_eq!(strata_vk_destroy_bindings(pass, bindings, &mut error), StrataStatus::Ok);
        assert_eq!(strata_vk_destroy(pass, &mut error), StrataStatus::Ok);
    }
}
