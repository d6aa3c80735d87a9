//! [`DevTools`]: Chromium's DevTools protocol over the pipe `--remote-debugging-pipe` opens,
//! for what a page cannot do for itself, such as a screenshot of what it shows (the live
//! page's test takes the README's picture so).
//!
//! Chromium reads commands from its descriptor 3 and writes answers and events to its
//! descriptor 4, each message JSON ended by a NUL byte. No port is opened: nothing else on
//! the machine can reach the browser. A reader thread hands the messages over, so that
//! every wait has a timeout.

use std::io::{BufRead, BufReader, PipeReader, PipeWriter, Write};
use std::sync::mpsc::{Receiver, RecvTimeoutError, channel};
use std::time::Duration;

/// How long one command may wait for its answer.
const ANSWER_TIMEOUT: Duration = Duration::from_secs(60);

/// The largest message read (a screenshot of a large window is a few MiB of base64).
const MAX_MESSAGE: usize = 256 << 20;

/// The browser's end of the two pipes, given to [`super::Browser::launch_with_devtools`]:
/// what becomes its descriptors 3 (it reads) and 4 (it writes).
pub(super) struct BrowserEnds {
    /// Chromium's descriptor 3.
    pub reads: PipeReader,
    /// Chromium's descriptor 4.
    pub writes: PipeWriter,
}

/// A DevTools session with a browser started by [`super::Browser::launch_with_devtools`].
pub struct DevTools {
    to_browser: PipeWriter,
    messages: Receiver<Result<serde_json::Value, String>>,
    next_id: u64,
}

impl DevTools {
    /// Two pipes: this side's [`DevTools`] and the browser's ends.
    pub(super) fn pipes() -> Result<(DevTools, BrowserEnds), String> {
        let (browser_reads, to_browser) =
            std::io::pipe().map_err(|e| format!("cannot create the DevTools pipe to Chromium: {e}"))?;
        let (from_browser, browser_writes) =
            std::io::pipe().map_err(|e| format!("cannot create the DevTools pipe from Chromium: {e}"))?;
        let (sender, messages) = channel();
        std::thread::spawn(move || {
            let mut reader = BufReader::new(from_browser);
            loop {
                let mut message = Vec::new();
                let read = std::io::Read::take(&mut reader, MAX_MESSAGE as u64).read_until(0, &mut message);
                let parsed = match read {
                    Ok(0) => Err("Chromium closed its DevTools pipe".to_string()),
                    Ok(_) if message.last() != Some(&0) => {
                        Err(format!("a DevTools message of more than {MAX_MESSAGE} bytes, or cut short"))
                    }
                    Ok(_) => serde_json::from_slice(&message[..message.len() - 1])
                        .map_err(|e| format!("a DevTools message that is not JSON: {e}")),
                    Err(e) => Err(format!("reading Chromium's DevTools pipe: {e}")),
                };
                let stop = parsed.is_err();
                if sender.send(parsed).is_err() || stop {
                    return;
                }
            }
        });
        let devtools = DevTools { to_browser, messages, next_id: 1 };
        Ok((devtools, BrowserEnds { reads: browser_reads, writes: browser_writes }))
    }

    /// Sends `method` with `params` (to the page attached as `session`, or to the browser)
    /// and returns its result; an error answer, a closed pipe or no answer within a minute
    /// of sending (events that arrive meanwhile are skipped, and do not extend it) is an
    /// error naming the method. (The write itself has no timeout: the pipe's buffer takes a
    /// command whole unless the browser has stopped reading, which its exit ends.)
    pub fn call(
        &mut self,
        session: Option<&str>,
        method: &str,
        params: serde_json::Value,
    ) -> Result<serde_json::Value, String> {
        let id = self.next_id;
        self.next_id += 1;
        let mut command = serde_json::json!({ "id": id, "method": method, "params": params });
        if let Some(session) = session {
            command["sessionId"] = session.into();
        }
        let mut bytes = command.to_string().into_bytes();
        bytes.push(0);
        self.to_browser.write_all(&bytes).map_err(|e| format!("DevTools {method}: cannot write to Chromium: {e}"))?;
        let deadline = std::time::Instant::now() + ANSWER_TIMEOUT;
        loop {
            let left = deadline.saturating_duration_since(std::time::Instant::now());
            let message = match self.messages.recv_timeout(left) {
                Ok(message) => message.map_err(|e| format!("DevTools {method}: {e}"))?,
                Err(RecvTimeoutError::Timeout) => {
                    return Err(format!("DevTools {method}: no answer within {} s", ANSWER_TIMEOUT.as_secs()));
                }
                Err(RecvTimeoutError::Disconnected) => return Err(format!("DevTools {method}: the reader stopped")),
            };
            if message["id"] != id {
                continue;
            }
            if let Some(error) = message.get("error") {
                return Err(format!("DevTools {method}: {error}"));
            }
            return Ok(message["result"].clone());
        }
    }

    /// A PNG of what the browser's first page shows now, as a person would see it.
    pub fn screenshot(&mut self) -> Result<Vec<u8>, String> {
        use base64::Engine;
        let targets = self.call(None, "Target.getTargets", serde_json::json!({}))?;
        let page = targets["targetInfos"]
            .as_array()
            .and_then(|targets| targets.iter().find(|t| t["type"] == "page"))
            .and_then(|page| page["targetId"].as_str())
            .ok_or_else(|| format!("DevTools: no page among the browser's targets: {targets}"))?
            .to_string();
        let attached =
            self.call(None, "Target.attachToTarget", serde_json::json!({ "targetId": page, "flatten": true }))?;
        let session = attached["sessionId"]
            .as_str()
            .ok_or_else(|| format!("DevTools: attaching to the page gave no session: {attached}"))?
            .to_string();
        let shot = self.call(Some(&session), "Page.captureScreenshot", serde_json::json!({ "format": "png" }))?;
        let data = shot["data"].as_str().ok_or("DevTools: the screenshot has no data")?;
        base64::engine::general_purpose::STANDARD
            .decode(data)
            .map_err(|e| format!("DevTools: the screenshot is not base64: {e}"))
    }
}
