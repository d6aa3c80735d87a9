//! [`Acceptor`]: the loopback listener that the WebGPU backend's bridge and the test
//! pages' [`super::page_server::PageServer`] share: a port on `127.0.0.1` that the system
//! picks, a random 128-bit token that every path the server answers starts with, and a
//! thread that hands each connection to the server's handler on a thread of its own,
//! until the acceptor is dropped.

use std::net::{Ipv4Addr, SocketAddr, TcpListener, TcpStream};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

/// Where a server answers: its address and token.
#[derive(Clone, Debug)]
pub(super) struct Route {
    /// `127.0.0.1:PORT`.
    pub(super) address: SocketAddr,
    /// 32 hexadecimal digits from the system's random source.
    pub(super) token: String,
}

impl Route {
    /// The path prefix of every request the server answers: `/TOKEN/`.
    pub(super) fn prefix(&self) -> String {
        format!("/{}/", self.token)
    }

    /// The `Host` header a request for this server carries (a page elsewhere that
    /// resolves its own name to 127.0.0.1 sends another).
    pub(super) fn host(&self) -> String {
        self.address.to_string()
    }

    /// `http://127.0.0.1:PORT/TOKEN/` followed by `path`.
    pub(super) fn url(&self, path: &str) -> String {
        format!("http://{}/{}/{path}", self.address, self.token)
    }
}

/// A listening loopback port and its accepting thread; dropping it stops the thread.
pub(super) struct Acceptor {
    route: Route,
    stop: Arc<AtomicBool>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl Acceptor {
    /// Binds a loopback port, draws the token and starts accepting: every connection goes
    /// to the handler that `make_handler` returns for the route, on a thread named `name`
    /// (`what` names the server in errors).
    pub(super) fn start<H>(what: &str, name: &str, make_handler: impl FnOnce(&Route) -> H) -> Result<Self, String>
    where
        H: Fn(TcpStream) + Send + Sync + 'static,
    {
        let listener = TcpListener::bind((Ipv4Addr::LOCALHOST, 0))
            .map_err(|e| format!("cannot listen on a loopback port: {e}"))?;
        let address = listener.local_addr().map_err(|e| format!("cannot read the loopback port: {e}"))?;
        let mut random = [0u8; 16];
        getrandom::fill(&mut random).map_err(|e| format!("no random numbers for the page's token: {e}"))?;
        let route = Route { address, token: random.iter().map(|b| format!("{b:02x}")).collect() };
        let handler = Arc::new(make_handler(&route));
        let stop = Arc::new(AtomicBool::new(false));
        let stopped = Arc::clone(&stop);
        let request_name = format!("{name}-request");
        let thread = std::thread::Builder::new()
            .name(format!("{name}-accept"))
            .spawn(move || {
                for stream in listener.incoming() {
                    if stopped.load(Ordering::Acquire) {
                        break;
                    }
                    let Ok(stream) = stream else { continue };
                    let handler = Arc::clone(&handler);
                    let _ = std::thread::Builder::new().name(request_name.clone()).spawn(move || handler(stream));
                }
            })
            .map_err(|e| format!("cannot start the {what}'s thread: {e}"))?;
        Ok(Self { route, stop, thread: Some(thread) })
    }

    /// The server's address and token.
    pub(super) fn route(&self) -> &Route {
        &self.route
    }
}

impl Drop for Acceptor {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Release);
        // Wakes the accepting thread, which then sees the flag.
        let _ = TcpStream::connect_timeout(&self.route.address, Duration::from_secs(1));
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}
