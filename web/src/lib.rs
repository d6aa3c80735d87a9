//! strata in a web page (issue 60): the live comparison page that `cargo xtask web`
//! builds and serves.
//!
//! [`live::LiveComparison`] is what the page computes: the built-in scene rendered by
//! ris, restir and strata from one seed, frame after frame, each frame's RelMSE against a
//! reference image, the running mean of each and the strata ÷ restir ratio, raw or after
//! the SVGF denoiser. It runs on any [`strata_backends::Backend`]: in the page on the
//! browser's WebGPU (`WebGpuBackend::in_this_page`, wasm32 only), natively on
//! lavapipe for the page's test, which holds the two runs to each other.
//!
//! Compiled for `wasm32-unknown-unknown` (`cargo rustc -p strata-web --target
//! wasm32-unknown-unknown --crate-type cdylib`), the module exports the C functions of
//! `exports` (wasm32 only) that the page's worker (`web/page/worker.js`) calls.

pub mod live;
#[cfg(not(target_arch = "wasm32"))]
pub mod serve;

#[cfg(target_arch = "wasm32")]
mod exports;

/// The page's files (`web/page/`), by their path below the page's folder: what a server
/// serves beside the module (`strata_web.wasm`), the executor
/// ([`strata_backends::webgpu_backend::EXECUTOR_JS`], `executor.js`) and the reference
/// (`reference.bin`, `page.json`: `serve::page_files`).
pub const PAGE_FILES: [(&str, &str); 4] = [
    ("index.html", include_str!("../page/index.html")),
    ("main.js", include_str!("../page/main.js")),
    ("worker.js", include_str!("../page/worker.js")),
    ("style.css", include_str!("../page/style.css")),
];
