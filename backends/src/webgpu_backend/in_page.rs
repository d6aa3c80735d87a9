//! The WebGPU backend inside a web page (wasm32): the page that loaded this module holds
//! the device, and [`PageChannel`] hands it each framed message through two functions
//! the page imports into the module (module `strata_webgpu`), which run the message
//! with the same executor as the bridge's page (`executor.js`).
//!
//! The calls are synchronous, as [`crate::Backend`] is, so the module must run in a
//! worker that may block: `exchange` posts the message to the page's thread and waits
//! (`Atomics.wait`) until the answer is in shared memory; `take_answer` copies it in.
//! The page's side is `web/page/worker.js` and `web/page/main.js` of the repository.

use super::channel::Channel;
use std::time::Duration;

#[link(wasm_import_module = "strata_webgpu")]
unsafe extern "C" {
    /// Sends the `length` bytes at `message` to the page, waits for its answer and
    /// returns the answer's length in bytes, or `u32::MAX` when the page is gone or did not
    /// answer within `timeout_ms`.
    fn exchange(message: *const u8, length: u32, timeout_ms: u32) -> u32;
    /// Copies the answer `exchange` announced into the `length` bytes at `into` (`length`
    /// as `exchange` returned).
    fn take_answer(into: *mut u8, length: u32);
}

/// The page this module runs in, as a [`Channel`].
pub(super) struct PageChannel;

impl Channel for PageChannel {
    fn exchange(&mut self, message: &[u8], timeout: Duration) -> Result<Vec<u8>, String> {
        let length = u32::try_from(message.len())
            .map_err(|_| format!("a message of {} bytes is too long for the page", message.len()))?;
        let timeout_ms = u32::try_from(timeout.as_millis()).unwrap_or(u32::MAX);
        // SAFETY: `message` is a live slice of `length` bytes, which the page only reads
        // during the call.
        let answer = unsafe { exchange(message.as_ptr(), length, timeout_ms) };
        if answer == u32::MAX {
            return Err(format!("no answer from the page within {} s (or its device is gone)", timeout.as_secs()));
        }
        let mut bytes = vec![0u8; answer as usize];
        // SAFETY: `bytes` holds exactly the `answer` bytes the page announced, and the
        // page writes only those, during the call.
        unsafe { take_answer(bytes.as_mut_ptr(), answer) };
        Ok(bytes)
    }
}
