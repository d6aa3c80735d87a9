//! [`PageServer`]: a loopback HTTP server for a test page in headless Chromium
//! ([`super::Browser`]): it serves a fixed set of files from memory and takes what the
//! page posts back.
//!
//! Like the WebGPU backend's bridge, it listens on `127.0.0.1` at a port the system picks
//! and answers only requests whose `Host` is that address and whose path starts with a
//! random 128-bit token: `GET /TOKEN/PATH` for one of its files (a query string is
//! ignored), `POST /TOKEN/post/NAME` for a result (answered at once with an empty 200).
//! Anything else gets a 404. Its content security policy lets a page run only the
//! server's own scripts, workers, fetches and frames, and compile WebAssembly. Files
//! are served from memory only, so no path the page asks for reaches the file system.

use super::bridge::{read_request, respond_with};
use super::loopback::Acceptor;
use std::collections::HashMap;
use std::net::TcpStream;
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// The pages' content security policy: same-origin scripts, workers, fetches and frames
/// (a test page may run another page of the package in a frame), inline styles, and the
/// compilation of same-origin WebAssembly (the live comparison page's module).
const POLICY: &str = "default-src 'none'; script-src 'self' 'wasm-unsafe-eval'; worker-src 'self'; connect-src 'self'; frame-src 'self'; img-src 'self'; style-src 'self' 'unsafe-inline'";

/// How long one read of a request may wait.
const READ_TIMEOUT: Duration = Duration::from_secs(30);

/// A running server (stopped on drop).
pub struct PageServer {
    acceptor: Acceptor,
    posts: mpsc::Receiver<(String, Vec<u8>)>,
}

/// The content type of a file by its extension.
fn content_type(path: &str) -> &'static str {
    match path.rsplit_once('.').map(|(_, extension)| extension) {
        Some("html") => "text/html; charset=utf-8",
        Some("js" | "mjs") => "text/javascript; charset=utf-8",
        Some("json") => "application/json",
        Some("css") => "text/css; charset=utf-8",
        // `WebAssembly.instantiateStreaming` takes nothing else.
        Some("wasm") => "application/wasm",
        Some("ts") => "text/plain; charset=utf-8",
        _ => "application/octet-stream",
    }
}

impl PageServer {
    /// Binds a loopback port and serves `files` (each a path below the page's folder, such
    /// as `index.html` or `web/strata.js`, and its bytes).
    pub fn start(files: Vec<(String, Vec<u8>)>) -> Result<Self, String> {
        let (sender, posts) = mpsc::channel();
        let files: HashMap<String, Vec<u8>> = files.into_iter().collect();
        let acceptor = Acceptor::start("page server", "strata-page", |route| {
            let (prefix, host) = (route.prefix(), route.host());
            move |stream| handle(stream, &files, &sender, &prefix, &host)
        })?;
        Ok(Self { acceptor, posts })
    }

    /// The address of the file `path` (`index.html`).
    pub fn url(&self, path: &str) -> String {
        self.acceptor.route().url(path)
    }

    /// Waits up to `timeout` for the page's next post (`Duration::MAX`: without end),
    /// asking `alive` every 100 ms whether the page can still post (an error ends the wait
    /// with it); returns the post's `NAME` and body.
    pub fn receive(
        &self,
        timeout: Duration,
        alive: &mut dyn FnMut() -> Result<(), String>,
    ) -> Result<(String, Vec<u8>), String> {
        // A timeout past what the clock can hold (Duration::MAX) waits without end.
        let deadline = Instant::now().checked_add(timeout);
        loop {
            let left = deadline.map_or(Duration::MAX, |d| d.saturating_duration_since(Instant::now()));
            if left.is_zero() {
                return Err(format!("the page posted nothing within {} s", timeout.as_secs()));
            }
            match self.posts.recv_timeout(left.min(Duration::from_millis(100))) {
                Ok(post) => return Ok(post),
                Err(mpsc::RecvTimeoutError::Timeout) => alive()?,
                Err(mpsc::RecvTimeoutError::Disconnected) => return Err("the page server stopped".into()),
            }
        }
    }
}

fn handle(
    mut stream: TcpStream,
    files: &HashMap<String, Vec<u8>>,
    posts: &mpsc::Sender<(String, Vec<u8>)>,
    prefix: &str,
    host: &str,
) {
    if stream.set_read_timeout(Some(READ_TIMEOUT)).is_err() {
        return;
    }
    let Ok(Some(request)) = read_request(&stream) else { return };
    // A page's query (`index.html?frames=12`) is the page's own business.
    let path = request.path.split('?').next().unwrap_or_default();
    let path = if request.host == host { path.strip_prefix(prefix) } else { None };
    let _ = match (request.method.as_str(), path) {
        ("GET", Some(path)) if files.contains_key(path) => {
            respond_with(&mut stream, "200 OK", content_type(path), &files[path], POLICY)
        }
        ("POST", Some(path)) if path.starts_with("post/") => {
            let name = path["post/".len()..].to_string();
            let _ = posts.send((name, request.body));
            respond_with(&mut stream, "200 OK", "text/plain", b"", POLICY)
        }
        _ => respond_with(&mut stream, "404 Not Found", "text/plain", b"not found", POLICY),
    };
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::{Read, Write};

    fn ask(server: &PageServer, request: &str) -> Vec<u8> {
        let mut stream = TcpStream::connect(server.acceptor.route().address).unwrap();
        stream.write_all(request.as_bytes()).unwrap();
        let mut response = Vec::new();
        stream.read_to_end(&mut response).unwrap();
        response
    }

    #[test]
    fn serves_its_files_under_the_token_and_takes_posts() {
        let server = PageServer::start(vec![("web/a.js".into(), b"export {};".to_vec())]).unwrap();
        let (host, token) = (server.acceptor.route().address.to_string(), server.acceptor.route().token.clone());
        let file = ask(&server, &format!("GET /{token}/web/a.js HTTP/1.1\r\nHost: {host}\r\n\r\n"));
        assert!(file.starts_with(b"HTTP/1.1 200 OK") && file.ends_with(b"export {};"));
        assert!(String::from_utf8_lossy(&file).contains("text/javascript"));
        for request in [
            format!("GET /web/a.js HTTP/1.1\r\nHost: {host}\r\n\r\n"),
            format!("GET /{token}/web/b.js HTTP/1.1\r\nHost: {host}\r\n\r\n"),
            format!("GET /{token}/web/a.js HTTP/1.1\r\nHost: elsewhere.example\r\n\r\n"),
        ] {
            assert!(ask(&server, &request).starts_with(b"HTTP/1.1 404"), "{request:?}");
        }
        let posted = ask(
            &server,
            &format!("POST /{token}/post/result HTTP/1.1\r\nHost: {host}\r\nContent-Length: 3\r\n\r\nabc"),
        );
        assert!(posted.starts_with(b"HTTP/1.1 200 OK"));
        let (name, body) = server.receive(Duration::from_secs(10), &mut || Ok(())).unwrap();
        assert_eq!((name.as_str(), body.as_slice()), ("result", &b"abc"[..]));
        let gone = server.receive(Duration::from_secs(10), &mut || Err("the browser exited".into()));
        assert_eq!(gone.unwrap_err(), "the browser exited");
    }
}
