//! `cargo xtask web`: builds the live comparison page's module for wasm32, renders its
//! reference on this machine's device, and serves the page on a loopback address until
//! stopped (strata-web).

use anyhow::{Context, Result, anyhow};
use std::path::Path;
use std::time::Duration;
use strata_backends::webgpu_backend::page_server::PageServer;
use strata_render::backend_choice::{BackendChoice, open_backend};
use strata_web::live::{LiveSettings, REFERENCE_SAMPLES, reference};
use strata_web::serve::{build_module, page_files};

/// Builds, renders the reference and serves; `seconds`: stop after that long (scripts),
/// else run until interrupted.
pub fn web(seconds: Option<u64>) -> Result<()> {
    let workspace = Path::new(env!("CARGO_MANIFEST_DIR")).parent().context("xtask's folder has no parent")?;
    println!("building the page's module for wasm32 (about a minute the first time)");
    let module = build_module(workspace).map_err(|e| anyhow!(e))?;
    let module = std::fs::read(&module).with_context(|| format!("{}", module.display()))?;
    let settings = LiveSettings::default();
    println!(
        "rendering the reference ({REFERENCE_SAMPLES} samples per pixel, {}x{}) on this machine",
        settings.width, settings.height
    );
    let mut backend = open_backend(BackendChoice::Auto)?;
    let image = reference(backend.as_mut(), &settings)?;
    let server = PageServer::start(page_files(module, &settings, &image)).map_err(|e| anyhow!(e))?;
    println!("serving the live comparison page at\n  {}", server.url("index.html"));
    println!("(loopback only; open it in a browser with WebGPU on this machine. Ctrl-C stops.)");
    let wait = seconds.map_or(Duration::MAX, Duration::from_secs);
    // The page posts nothing unless a test asks it to; the server answers it meanwhile.
    match server.receive(wait, &mut || Ok(())) {
        Ok((name, _)) => println!("the page posted `{name}` (a test's URL?)"),
        Err(_) => println!("stopped after {} s", wait.as_secs()),
    }
    Ok(())
}
