//! The C functions the page's worker calls (wasm32 only; `web/page/worker.js`).
//!
//! One comparison per module instance. Every call that can fail returns 0 on success and
//! 1 on failure; the report (`strata_web_report_ptr` / `_len`, UTF-8 JSON) then holds
//! `{"error": "..."}`, one line naming what failed. The page passes the reference through
//! the inbox: `strata_web_inbox(length)` gives the address of `length` bytes it fills
//! before `strata_web_start`. No function takes a raw pointer from the page.

use crate::live::{LiveComparison, LivePathTracer, LiveSettings, reference_from_bytes};
use std::cell::RefCell;
use strata_backends::{BackendError, WebGpuBackend, WebGpuOptions};
use strata_render::histogram_pass::PassError;

/// What the page runs: the comparison, or where the device cannot run the ReSTIR
/// kernels the path tracer ([`LivePathTracer`]).
enum Shown {
    Comparison(LiveComparison),
    PathTracer(Box<LivePathTracer>),
}

/// What the page runs and the device it runs on.
struct Page {
    backend: WebGpuBackend,
    shown: Shown,
}

thread_local! {
    static PAGE: RefCell<Option<Page>> = const { RefCell::new(None) };
    static INBOX: RefCell<Vec<u8>> = const { RefCell::new(Vec::new()) };
    static REPORT: RefCell<Vec<u8>> = const { RefCell::new(Vec::new()) };
    static IMAGES: RefCell<Vec<u8>> = const { RefCell::new(Vec::new()) };
}

/// Sets the report to `value`; 0.
fn report(value: serde_json::Value) -> u32 {
    REPORT.with(|r| *r.borrow_mut() = value.to_string().into_bytes());
    0
}

/// Sets the report to `{"error": message}`; 1.
fn fail(message: impl std::fmt::Display) -> u32 {
    report(serde_json::json!({ "error": message.to_string() }));
    1
}

/// A panic (a bug) traps the module (`unreachable` in the page); first its message goes
/// into the report, where the worker reads it after the trap.
fn report_panics() {
    std::panic::set_hook(Box::new(|info| {
        let _ = REPORT.try_with(|r| {
            if let Ok(mut r) = r.try_borrow_mut() {
                // One line: the panic's place and message (its Display puts a newline between).
                let place = info.location().map(|l| format!("{}:{}", l.file(), l.line())).unwrap_or_default();
                let payload = info.payload();
                let message = payload
                    .downcast_ref::<&str>()
                    .copied()
                    .or_else(|| payload.downcast_ref::<String>().map(String::as_str))
                    .unwrap_or("(no message)");
                let text = format!("the module panicked at {place}: {message}").replace('\n', " ");
                *r = serde_json::json!({ "error": text }).to_string().into_bytes();
            }
        });
    }));
}

/// The address of a buffer of `length` bytes (zeroed) for the page to fill with the
/// reference before [`strata_web_start`]; valid until the next call into the module.
/// (The page's first call: it also routes panics to the report.)
#[unsafe(no_mangle)]
pub extern "C" fn strata_web_inbox(length: u32) -> *mut u8 {
    report_panics();
    INBOX.with(|inbox| {
        let mut inbox = inbox.borrow_mut();
        *inbox = vec![0; length as usize];
        inbox.as_mut_ptr()
    })
}

/// Opens the page's WebGPU device and starts the comparison at `width` × `height` from
/// `seed`, scored against the reference in the inbox ([`crate::live::reference_bytes`]).
/// Where the device's limits refuse a ReSTIR kernel, the path tracer starts instead. The
/// report then holds the device and, in that case, why (`{"adapter", "driver",
/// "unavailable"}`, the last `null` when the comparison runs).
#[unsafe(no_mangle)]
pub extern "C" fn strata_web_start(width: u32, height: u32, seed: u32) -> u32 {
    let settings = LiveSettings { width, height, seed };
    let bytes = INBOX.with(|inbox| std::mem::take(&mut *inbox.borrow_mut()));
    let reference = match reference_from_bytes(&settings, &bytes) {
        Ok(reference) => reference,
        Err(why) => return fail(why),
    };
    let mut backend = match WebGpuBackend::in_this_page(WebGpuOptions::default()) {
        Ok(backend) => backend,
        Err(error) => return fail(error),
    };
    let (shown, unavailable) = match LiveComparison::new(&mut backend, settings, reference.clone()) {
        Ok(live) => (Shown::Comparison(live), None),
        Err(error @ PassError::Backend(BackendError::LimitExceeded { .. })) => {
            match LivePathTracer::new(&mut backend, settings, reference) {
                Ok(tracer) => (Shown::PathTracer(Box::new(tracer)), Some(error.to_string())),
                Err(fallback) => return fail(format!("{error}; and the path tracer: {fallback}")),
            }
        }
        Err(error) => return fail(error),
    };
    let info = strata_backends::Backend::info(&backend).clone();
    PAGE.with(|page| *page.borrow_mut() = Some(Page { backend, shown }));
    report(serde_json::json!({ "adapter": info.adapter, "driver": info.driver, "unavailable": unavailable }))
}

/// Renders the next frame of every method, with the denoiser on when `denoise` is not
/// 0. The report holds the scores ([`crate::live::LiveFrame::to_json`]), the images
/// (`strata_web_images_ptr` / `_len`) the shown images and then their error maps
/// ([`crate::live::LiveFrame::rgba8`]); for the path tracer its sample and its image ([`crate::live::PathTracerFrame`]; `denoise` does not apply).
#[unsafe(no_mangle)]
pub extern "C" fn strata_web_frame(denoise: u32) -> u32 {
    PAGE.with(|page| {
        let mut page = page.borrow_mut();
        let Some(Page { backend, shown }) = page.as_mut() else {
            return fail("strata_web_start has not succeeded");
        };
        let frame = match shown {
            Shown::Comparison(live) => live
                .set_denoiser(backend, denoise != 0)
                .and_then(|()| live.frame(backend))
                .map(|frame| (frame.to_json(), frame.rgba8())),
            Shown::PathTracer(tracer) => tracer.frame(backend).map(|frame| (frame.to_json(), frame.rgba8())),
        };
        match frame {
            Ok((scores, rgba)) => {
                IMAGES.with(|images| *images.borrow_mut() = rgba);
                report(scores)
            }
            Err(error) => fail(error),
        }
    })
}

/// The report's address (UTF-8 JSON), valid until the next call into the module.
#[unsafe(no_mangle)]
pub extern "C" fn strata_web_report_ptr() -> *const u8 {
    REPORT.with(|r| r.borrow().as_ptr())
}

/// The report's length in bytes.
#[unsafe(no_mangle)]
pub extern "C" fn strata_web_report_len() -> u32 {
    REPORT.with(|r| r.borrow().len() as u32)
}

/// The address of the last frame's images (RGBA8, one after the other), valid
/// until the next call into the module.
#[unsafe(no_mangle)]
pub extern "C" fn strata_web_images_ptr() -> *const u8 {
    IMAGES.with(|i| i.borrow().as_ptr())
}

/// The images' length in bytes.
#[unsafe(no_mangle)]
pub extern "C" fn strata_web_images_len() -> u32 {
    IMAGES.with(|i| i.borrow().len() as u32)
}

/// getrandom's source of random bytes on wasm32 (`getrandom_backend="custom"`,
/// `.cargo/config.toml`): the page's code asks for none (every seed is explicit), so a
/// request is refused rather than answered with something that is not random.
///
/// # Safety
///
/// Called by getrandom only, with `dest` valid for `len` bytes; it writes none.
#[unsafe(no_mangle)]
unsafe extern "Rust" fn __getrandom_v03_custom(_dest: *mut u8, _len: usize) -> Result<(), getrandom::Error> {
    Err(getrandom::Error::UNSUPPORTED)
}
