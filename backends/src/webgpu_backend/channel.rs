//! How the WebGPU backend's messages reach the page that holds the device: [`Channel`],
//! and natively [`BrowserChannel`], the loopback bridge to a headless Chromium tab.
//! (In a web page the channel is the page itself: `in_page.rs`.)

use std::time::Duration;

/// One framed message to the page and its framed answer ([`super::framing`]). `Send`, so
/// that the backend can move to another thread as it could before channels.
pub(super) trait Channel: Send {
    /// Sends `message` and waits up to `timeout` for the page's answer; the error says
    /// why none came.
    fn exchange(&mut self, message: &[u8], timeout: Duration) -> Result<Vec<u8>, String>;
}

#[cfg(not(target_arch = "wasm32"))]
pub(super) use native::BrowserChannel;

#[cfg(not(target_arch = "wasm32"))]
mod native {
    use super::super::bridge::{Server, WaitError};
    use super::super::browser::Browser;
    use super::super::framing::frame;
    use super::Channel;
    use serde_json::json;
    use std::time::Duration;

    /// The bridge's server and the headless Chromium whose page answers it.
    pub(in crate::webgpu_backend) struct BrowserChannel {
        // Dropped first: the page's request is answered (closed) before the browser goes.
        pub(in crate::webgpu_backend) server: Server,
        pub(in crate::webgpu_backend) browser: Browser,
    }

    impl BrowserChannel {
        /// The page's next message, or why none came within `timeout`.
        pub(in crate::webgpu_backend) fn wait(&mut self, timeout: Duration) -> Result<Vec<u8>, WaitError> {
            let browser = &mut self.browser;
            self.server.receive(timeout, &mut || browser.exited().map_or(Ok(()), Err))
        }
    }

    impl Channel for BrowserChannel {
        fn exchange(&mut self, message: &[u8], timeout: Duration) -> Result<Vec<u8>, String> {
            self.server.send(message, timeout).map_err(|why| format!("{why}{}", self.browser.log_tail()))?;
            match self.wait(timeout) {
                Ok(body) => Ok(body),
                Err(WaitError::Gone(why)) => Err(why),
                Err(WaitError::Timeout) => Err(format!(
                    "no answer from the page in Chromium within {} s{}",
                    timeout.as_secs(),
                    self.browser.log_tail()
                )),
            }
        }
    }

    impl Drop for BrowserChannel {
        fn drop(&mut self) {
            // Tells the page to stop asking; the browser is killed right after anyway.
            let _ = self.server.send(&frame(&json!({ "close": true }), &[]), Duration::from_secs(1));
        }
    }
}
