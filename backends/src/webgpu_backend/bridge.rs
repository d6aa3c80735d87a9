//! The loopback HTTP server between the WebGPU backend and its page.
//!
//! It listens on `127.0.0.1` at a port the system picks, and answers only requests whose
//! path starts with a random 128-bit token (from the operating system's generator) and
//! whose `Host` is that address: the page (`/TOKEN/`), its scripts (`/TOKEN/page.js`,
//! `/TOKEN/executor.js`) and
//! the exchange (`POST /TOKEN/exchange`). Anything else gets a 404 and is forgotten. Every
//! response closes its connection.
//!
//! The exchange is a long poll: the page posts its answer to the previous message, and
//! the server holds that request open until the backend has its next message, which is
//! the response. One thread accepts connections and one short-lived thread per
//! connection reads its request (each read under a timeout), so that a connection that
//! never sends anything (Chromium opens spare ones) blocks nobody; the backend's thread
//! waits for exchanges on a channel, with a timeout.

use super::loopback::Acceptor;
use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// The page and its scripts, written for strata (this folder).
const PAGE_HTML: &str = include_str!("page.html");
const PAGE_JS: &str = include_str!("page.js");

/// The largest request body taken (an answer carrying a buffer's contents): WebGPU's
/// buffers stay below 4 GiB on every device Chromium drives.
const MAX_BODY: u64 = 4 << 30;

/// How long one read of a request may wait (its headers, a piece of its body).
const READ_TIMEOUT: Duration = Duration::from_secs(30);

/// One exchange request of the page: its body, and the connection to answer on.
struct Exchange {
    body: Vec<u8>,
    stream: TcpStream,
}

/// The server: its address and token, and the exchanges the page has posted.
pub(super) struct Server {
    acceptor: Acceptor,
    exchanges: mpsc::Receiver<Exchange>,
    /// The page's exchange waiting for the next message.
    waiting: Option<TcpStream>,
}

/// Why no answer came.
pub(super) enum WaitError {
    /// None within the timeout.
    Timeout,
    /// `alive` said the other side is gone, and why.
    Gone(String),
}

impl Server {
    /// Binds a loopback port and starts accepting.
    pub(super) fn start() -> Result<Self, String> {
        let (sender, exchanges) = mpsc::channel();
        let acceptor = Acceptor::start("bridge", "strata-webgpu", |route| {
            let routes = Routes { prefix: route.prefix(), host: route.host() };
            move |stream| routes.handle(stream, &sender)
        })?;
        Ok(Self { acceptor, exchanges, waiting: None })
    }

    /// The page's address.
    pub(super) fn url(&self) -> String {
        self.acceptor.route().url("")
    }

    /// Waits for the page's next exchange, up to `timeout`, asking `alive` every 100 ms
    /// whether the page can still answer; returns its body and keeps the request open
    /// for [`Server::send`].
    pub(super) fn receive(
        &mut self,
        timeout: Duration,
        alive: &mut dyn FnMut() -> Result<(), String>,
    ) -> Result<Vec<u8>, WaitError> {
        let deadline = Instant::now() + timeout;
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            if left.is_zero() {
                return Err(WaitError::Timeout);
            }
            match self.exchanges.recv_timeout(left.min(Duration::from_millis(100))) {
                Ok(exchange) => {
                    self.waiting = Some(exchange.stream);
                    return Ok(exchange.body);
                }
                Err(mpsc::RecvTimeoutError::Timeout) => alive().map_err(WaitError::Gone)?,
                Err(mpsc::RecvTimeoutError::Disconnected) => {
                    return Err(WaitError::Gone("the bridge's server stopped".into()));
                }
            }
        }
    }

    /// Answers the waiting exchange with `message` (one framed message).
    pub(super) fn send(&mut self, message: &[u8], timeout: Duration) -> Result<(), String> {
        let mut stream = self.waiting.take().ok_or("the page is not waiting for a message")?;
        stream.set_write_timeout(Some(timeout)).map_err(|e| e.to_string())?;
        respond(&mut stream, "200 OK", "application/octet-stream", message)
            .map_err(|e| format!("cannot send the page its message: {e}"))
    }
}

/// What the server answers, from the token and the address the page must use.
struct Routes {
    /// `/TOKEN/`.
    prefix: String,
    host: String,
}

impl Routes {
    fn handle(&self, mut stream: TcpStream, exchanges: &mpsc::Sender<Exchange>) {
        if stream.set_read_timeout(Some(READ_TIMEOUT)).is_err() {
            return;
        }
        let Ok(Some(request)) = read_request(&stream) else { return };
        // A request for another host (a page elsewhere resolving its name to 127.0.0.1)
        // or another path is not ours.
        let path = if request.host == self.host { request.path.strip_prefix(&self.prefix) } else { None };
        let _ = match (request.method.as_str(), path) {
            ("GET", Some("")) => respond(&mut stream, "200 OK", "text/html; charset=utf-8", PAGE_HTML.as_bytes()),
            ("GET", Some("page.js")) => {
                respond(&mut stream, "200 OK", "text/javascript; charset=utf-8", PAGE_JS.as_bytes())
            }
            ("GET", Some("executor.js")) => {
                respond(&mut stream, "200 OK", "text/javascript; charset=utf-8", super::EXECUTOR_JS.as_bytes())
            }
            ("POST", Some("exchange")) => {
                let _ = exchanges.send(Exchange { body: request.body, stream });
                return;
            }
            _ => respond(&mut stream, "404 Not Found", "text/plain", b"not found"),
        };
    }
}

/// One HTTP request as the bridge reads it.
pub(super) struct Request {
    /// `GET`, `POST`, ...
    pub(super) method: String,
    /// The path as sent.
    pub(super) path: String,
    /// The `Host` header.
    pub(super) host: String,
    /// The body.
    pub(super) body: Vec<u8>,
}

/// One HTTP/1.1 request: its line, `Host` and `Content-Length` headers and body; `None`
/// for one that is malformed, too long or too slow.
pub(super) fn read_request(stream: &TcpStream) -> std::io::Result<Option<Request>> {
    let mut reader = BufReader::new(stream);
    let mut line = String::new();
    let mut header_bytes = 0usize;
    let mut read_line = |reader: &mut BufReader<&TcpStream>, line: &mut String| -> std::io::Result<bool> {
        line.clear();
        let n = reader.by_ref().take(8192).read_line(line)?;
        header_bytes += n;
        Ok(n > 0 && line.ends_with('\n') && header_bytes <= 65536)
    };
    if !read_line(&mut reader, &mut line)? {
        return Ok(None);
    }
    let mut parts = line.split_whitespace();
    let (Some(method), Some(path)) = (parts.next(), parts.next()) else { return Ok(None) };
    let (method, path) = (method.to_string(), path.to_string());
    let mut host = String::new();
    let mut length = 0u64;
    loop {
        if !read_line(&mut reader, &mut line)? {
            return Ok(None);
        }
        let header = line.trim_end();
        if header.is_empty() {
            break;
        }
        if let Some((name, value)) = header.split_once(':') {
            if name.eq_ignore_ascii_case("host") {
                host = value.trim().to_string();
            } else if name.eq_ignore_ascii_case("content-length") {
                match value.trim().parse::<u64>() {
                    Ok(n) if n <= MAX_BODY => length = n,
                    _ => return Ok(None),
                }
            } else if name.eq_ignore_ascii_case("transfer-encoding") {
                // The page's fetch always sends a length.
                return Ok(None);
            }
        }
    }
    let mut body = Vec::new();
    reader.take(length).read_to_end(&mut body)?;
    if body.len() as u64 != length {
        return Ok(None);
    }
    Ok(Some(Request { method, path, host, body }))
}

/// The bridge's content security policy: its own scripts and exchanges only.
const POLICY: &str = "default-src 'none'; script-src 'self'; connect-src 'self'";

/// Writes one response that closes the connection (no caching, same-origin scripts and
/// fetches only).
pub(super) fn respond(stream: &mut TcpStream, status: &str, content_type: &str, body: &[u8]) -> std::io::Result<()> {
    respond_with(stream, status, content_type, body, POLICY)
}

/// [`respond`] with the content security policy `policy`. Every response also isolates
/// its page from other origins (COOP and COEP): a page of these servers loads only their
/// own files, and isolation is what lets the live comparison page's worker wait on
/// shared memory (`SharedArrayBuffer`).
pub(super) fn respond_with(
    stream: &mut TcpStream,
    status: &str,
    content_type: &str,
    body: &[u8],
    policy: &str,
) -> std::io::Result<()> {
    let head = format!(
        "HTTP/1.1 {status}\r\nContent-Type: {content_type}\r\nContent-Length: {}\r\nCache-Control: no-store\r\n\
         Content-Security-Policy: {policy}\r\n\
         Cross-Origin-Opener-Policy: same-origin\r\nCross-Origin-Embedder-Policy: require-corp\r\n\
         X-Content-Type-Options: nosniff\r\nConnection: close\r\n\r\n",
        body.len()
    );
    stream.write_all(head.as_bytes())?;
    stream.write_all(body)?;
    stream.flush()
}

#[cfg(test)]
mod tests {
    use super::super::framing::{frame, unframe};
    use super::*;

    /// Sends `request` to the server and returns its whole response.
    fn ask(server: &Server, request: &str) -> String {
        let mut stream = TcpStream::connect(server.acceptor.route().address).unwrap();
        stream.write_all(request.as_bytes()).unwrap();
        let mut response = String::new();
        stream.read_to_string(&mut response).unwrap();
        response
    }

    #[test]
    fn only_the_token_and_the_servers_own_host_are_answered() {
        let server = Server::start().unwrap();
        let (host, token) = (server.acceptor.route().address.to_string(), server.acceptor.route().token.clone());
        assert_eq!(token.len(), 32, "128 random bits as hex");
        let page = ask(&server, &format!("GET /{token}/ HTTP/1.1\r\nHost: {host}\r\n\r\n"));
        assert!(page.starts_with("HTTP/1.1 200 OK") && page.contains("page.js"), "{page}");
        let script = ask(&server, &format!("GET /{token}/page.js HTTP/1.1\r\nHost: {host}\r\n\r\n"));
        assert!(script.starts_with("HTTP/1.1 200 OK") && script.contains("executor.js"), "{script}");
        let executor = ask(&server, &format!("GET /{token}/executor.js HTTP/1.1\r\nHost: {host}\r\n\r\n"));
        assert!(executor.starts_with("HTTP/1.1 200 OK") && executor.contains("requestAdapter"), "{executor}");
        assert!(executor.contains("Cross-Origin-Embedder-Policy: require-corp"), "{executor}");
        // Without the token, with another token, or through another name (a page of
        // some site whose name resolves to 127.0.0.1): nothing.
        for request in [
            format!("GET / HTTP/1.1\r\nHost: {host}\r\n\r\n"),
            format!("GET /{}/ HTTP/1.1\r\nHost: {host}\r\n\r\n", "0".repeat(32)),
            format!(
                "GET /{token}/ HTTP/1.1\r\nHost: attacker.example:{}\r\n\r\n",
                server.acceptor.route().address.port()
            ),
            format!("GET /{token}/../page.js HTTP/1.1\r\nHost: {host}\r\n\r\n"),
        ] {
            let response = ask(&server, &request);
            assert!(response.starts_with("HTTP/1.1 404"), "{request:?}: {response}");
        }
        // Two servers never share a token.
        assert_ne!(Server::start().unwrap().acceptor.route().token, token);
    }

    #[test]
    fn an_exchange_waits_for_its_message_and_a_silent_page_times_out() {
        let mut server = Server::start().unwrap();
        let (address, host, token) = (
            server.acceptor.route().address,
            server.acceptor.route().address.to_string(),
            server.acceptor.route().token.clone(),
        );
        let page = std::thread::spawn(move || {
            let mut stream = TcpStream::connect(address).unwrap();
            let body = frame(&serde_json::json!({ "ready": true }), b"abc");
            let head =
                format!("POST /{token}/exchange HTTP/1.1\r\nHost: {host}\r\nContent-Length: {}\r\n\r\n", body.len());
            stream.write_all(head.as_bytes()).unwrap();
            stream.write_all(&body).unwrap();
            let mut response = Vec::new();
            stream.read_to_end(&mut response).unwrap();
            response
        });
        let body = server.receive(Duration::from_secs(10), &mut || Ok(())).ok().expect("the page's exchange");
        let (header, payload) = unframe(&body).unwrap();
        assert_eq!((header["ready"].as_bool(), payload), (Some(true), &b"abc"[..]));
        server.send(&frame(&serde_json::json!({ "ops": [] }), b"xyz"), Duration::from_secs(10)).unwrap();
        let response = page.join().unwrap();
        assert!(response.starts_with(b"HTTP/1.1 200 OK") && response.ends_with(b"xyz"));
        let started = Instant::now();
        assert!(matches!(server.receive(Duration::from_millis(300), &mut || Ok(())), Err(WaitError::Timeout)));
        assert!(started.elapsed() < Duration::from_secs(5));
        let gone = server.receive(Duration::from_secs(10), &mut || Err("the browser exited".into()));
        assert!(matches!(gone, Err(WaitError::Gone(why)) if why == "the browser exited"));
    }

    #[test]
    fn a_message_without_a_whole_header_is_refused() {
        assert!(unframe(&[1, 0]).is_err());
        assert!(unframe(&[9, 0, 0, 0, b'{', b'}']).is_err());
        assert!(unframe(&[2, 0, 0, 0, b'{', b'x']).is_err());
        let message = frame(&serde_json::json!({ "a": 1 }), b"");
        let (header, payload) = unframe(&message).unwrap();
        assert_eq!((header["a"].as_u64(), payload.len()), (Some(1), 0));
    }
}
