//! The live comparison page (issue 60, `web/`) as a person opens it: its WebAssembly
//! module built for wasm32 (strata's renderer, on the browser's WebGPU through
//! `WebGpuBackend::in_this_page`), served over loopback with its reference, loaded in
//! headless Chromium, [`FRAMES`] frames.
//!
//! Where the browser's device runs the ReSTIR kernels (Chromium 156 on SwiftShader does
//! since the scene is one storage buffer: every pass binds at most 10), the page renders
//! ris, restir and strata, the SVGF denoiser on from frame [`DENOISE_FROM`], and posts
//! what it showed: every image and error map must have more than one value and every
//! score be finite.
//! Its scores must be the native run's from the same seed (strata-web's `LiveComparison`
//! on lavapipe): each method's mean RelMSE, raw and after the denoiser, and both strata ÷
//! restir ratios within [`SAME_SEED`] (the two devices compile the kernels apart, Tint and
//! naga, and a path that takes another branch on a last-bit difference shifts a score a
//! little: measured 0.2 % at most). The ratios must also lie within 4 sd of the native
//! runs from [`NATIVE_SEEDS`] seeds, the interval the README's claim is read with.
//!
//! Where it does not (a browser that allows fewer storage buffers per stage: docs/web.md),
//! the page must say why in one line naming the kernel and the limit, and show the path
//! tracer converging instead: its image must have more than one value, its RelMSE must
//! fall with the samples, and its last one must be the native path tracer's from the same
//! seed within 2 %; the comparison then runs natively from the page's seed alone (the
//! page's own code, checked where the page cannot run it).
//!
//! Without Chromium or the wasm32 target the test says so and passes, unless
//! `STRATA_REQUIRE_BROWSER=1` (CI) makes that a failure; without Vulkan likewise unless
//! `STRATA_REQUIRE_GPU=1`.

use std::path::Path;
use std::time::Duration;
use strata_backends::webgpu_backend::page_server::PageServer;
use strata_backends::webgpu_backend::{Browser, browser_required, find_chromium};
use strata_web::live::{LiveComparison, LiveFrame, LivePathTracer, LiveSettings};
use strata_web::serve::{build_module, page_files};

/// Frames the page renders.
const FRAMES: u32 = 12;
/// The first frame with the denoiser on.
const DENOISE_FROM: u32 = 7;
/// The native runs' seeds; the page runs the first.
const NATIVE_SEEDS: std::ops::Range<u32> = 1..7;
/// How far (relative) the page's scores may lie from the native run's from the same seed:
/// ten times the 0.2 % measured (restir's mean raw RelMSE; ris agreed to 1e-7, strata to
/// 0.04 %, every score after the denoiser to 0.02 %: Chromium 156, SwiftShader, against
/// lavapipe). Seen failing: a page served a reference 10 % brighter scored ris's mean
/// RelMSE 7.6 % off, while both ratios moved only 0.1-0.3 % (so the ratios alone would not
/// have seen it: each method's score is checked).
const SAME_SEED: f64 = 0.02;

/// The last frame of one native run of the page's comparison from `seed`.
fn native_run(
    backend: &mut dyn strata_backends::Backend,
    seed: u32,
    reference: &strata_render::rgb_image::RgbImage,
) -> LiveFrame {
    let settings = LiveSettings { seed, ..LiveSettings::default() };
    let mut live = LiveComparison::new(backend, settings, reference.clone()).unwrap();
    let mut last = None;
    for frame in 1..=FRAMES {
        live.set_denoiser(backend, frame >= DENOISE_FROM).unwrap();
        last = Some(live.frame(backend).unwrap());
    }
    live.destroy(backend).unwrap();
    last.unwrap()
}

/// Mean and sample standard deviation.
fn spread(values: &[f64]) -> (f64, f64) {
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let variance = values.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / (n - 1.0);
    (mean, variance.sqrt())
}

/// The page's screenshot: a PNG of the browser's window in which the method images show
/// (more than a few hundred colours: the page's text and plot alone have a few dozen
/// shades of anti-aliasing grey; three noisy renders have thousands), written to
/// `target/tmp/web-page.png` for the README (`docs/web-page.png`; docs/web.md says how).
fn check_screenshot(png: &[u8], comparison: bool) {
    let image = image::load_from_memory_with_format(png, image::ImageFormat::Png)
        .unwrap_or_else(|e| panic!("the screenshot is not a PNG: {e}"))
        .to_rgb8();
    let (width, height) = image.dimensions();
    assert!(width >= 800 && height >= 600, "the screenshot is {width}×{height}, smaller than the window");
    let colours: std::collections::HashSet<[u8; 3]> = image.pixels().map(|p| p.0).collect();
    let least = if comparison { 2000 } else { 500 };
    assert!(
        colours.len() >= least,
        "the screenshot has {} colours, fewer than {least}: no images shown",
        colours.len()
    );
    let path = Path::new(env!("CARGO_TARGET_TMPDIR")).join("web-page.png");
    strata_files::write_whole(&path, png).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    eprintln!("the page's screenshot ({} colours): {}", colours.len(), path.display());
}

#[test]
fn the_live_page_runs_as_natively_or_says_why_and_path_traces() {
    let test = "the_live_page_runs_as_natively_or_says_why_and_path_traces";
    let chromium = match find_chromium() {
        Ok(chromium) => chromium,
        Err(error) => {
            assert!(!browser_required(), "STRATA_REQUIRE_BROWSER=1 but {error}");
            eprintln!("note: {test} not run: {error}");
            return;
        }
    };
    let workspace = Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap();
    let module = match build_module(workspace) {
        Ok(module) => std::fs::read(module).unwrap(),
        Err(error) => {
            assert!(!browser_required(), "STRATA_REQUIRE_BROWSER=1 but {error}");
            eprintln!("note: {test} not run: {error}");
            return;
        }
    };
    let Some(mut backend) = strata_tests::vulkan_backend(test) else { return };
    let settings = LiveSettings::default();
    let reference = strata_web::live::reference(&mut backend, &settings).unwrap();

    let server = PageServer::start(page_files(module, &settings, &reference)).unwrap();
    let url = server.url(&format!("index.html?frames={FRAMES}&denoise-from={DENOISE_FROM}"));
    let (mut browser, mut devtools) = Browser::launch_with_devtools(&chromium, &url).unwrap();
    let (name, body) = server
        .receive(Duration::from_secs(300), &mut || browser.exited().map_or(Ok(()), Err))
        .unwrap_or_else(|e| panic!("{e}{}", browser.log_tail()));
    let body: serde_json::Value = serde_json::from_slice(&body).unwrap();
    assert_eq!(name, "result", "the page failed: {body}{}", browser.log_tail());
    // What a person sees now, through the browser's own eyes: the README's picture.
    let screenshot = devtools.screenshot().unwrap_or_else(|e| panic!("{e}{}", browser.log_tail()));
    drop(browser);
    check_screenshot(&screenshot, body["mode"] == "comparison");
    let scores = &body["scores"];
    assert_eq!(scores["frame"], FRAMES, "{body}");

    // The comparison natively: what the page must reproduce (every seed), or where the
    // page cannot run it the page's seed alone, a check of the page's own code
    // (strata-web's live module) natively.
    let seeds = if body["mode"] == "comparison" { NATIVE_SEEDS } else { NATIVE_SEEDS.start..NATIVE_SEEDS.start + 1 };
    let runs: Vec<LiveFrame> = seeds.map(|seed| native_run(&mut backend, seed, &reference)).collect();
    let native: Vec<(f64, f64)> =
        runs.iter().map(|run| (run.strata_over_restir, run.denoised_strata_over_restir.unwrap_or(f64::NAN))).collect();
    for (raw, denoised) in &native {
        assert!(raw.is_finite() && *raw > 0.0 && denoised.is_finite() && *denoised > 0.0, "native ratios {native:?}");
    }
    eprintln!("native strata ÷ restir (raw, after SVGF) per seed: {native:?}");

    if body["mode"] == "path-tracer" {
        let why = body["unavailable"].as_str().unwrap_or_default();
        assert!(
            why.starts_with("kernel `restir_") && why.contains("but the device allows at most"),
            "the page's reason for the path tracer does not name the kernel and the limit: {body}"
        );
        assert_eq!(body["varied"], serde_json::json!([true]), "a blank or flat image: {body}");
        let errors: Vec<f64> =
            body["relmse"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap_or(f64::NAN)).collect();
        assert_eq!(errors.len(), FRAMES as usize, "{body}");
        assert!(errors.iter().all(|e| e.is_finite() && *e > 0.0), "{errors:?}");
        assert!(errors[errors.len() - 1] < 0.5 * errors[0], "the path tracer does not converge: {errors:?}");
        let mut tracer = LivePathTracer::new(&mut backend, settings, reference.clone()).unwrap();
        let native = (0..FRAMES).map(|_| tracer.frame(&mut backend).unwrap().relmse).last().unwrap();
        tracer.destroy(&mut backend).unwrap();
        let page = errors[errors.len() - 1];
        eprintln!(
            "note: {test}: {why}; the path tracer at {FRAMES} samples: RelMSE {page:.4e} in the page, {native:.4e} natively"
        );
        // The same kernel from the same seed on another compiler and device: measured
        // 0.02 % apart (4.9977e-3 against 4.9985e-3, Chromium 156 on SwiftShader).
        assert!((page / native - 1.0).abs() < 0.02, "the path tracer's RelMSE: {page} in the page, {native} natively");
        return;
    }
    assert_eq!(body["mode"], "comparison", "{body}");
    eprintln!("the page showed its frames at (ms since it started): {}", body["frameTimes"]);
    assert_eq!(body["varied"], serde_json::json!([true, true, true]), "a blank or flat image: {body}");
    assert_eq!(body["mapsVaried"], serde_json::json!([true, true, true]), "a blank or flat error map: {body}");
    assert_eq!(body["checkbox"], true, "the denoiser's checkbox does not show it on: {body}");
    for method in scores["methods"].as_array().unwrap() {
        for key in ["relmse", "meanRelmse", "denoisedRelmse", "meanDenoisedRelmse"] {
            let value = method[key].as_f64().unwrap_or(f64::NAN);
            assert!(value.is_finite() && value > 0.0, "{} {key} = {value}: {body}", method["name"]);
        }
    }
    let page = (
        scores["strataOverRestir"].as_f64().unwrap_or(f64::NAN),
        scores["denoisedStrataOverRestir"].as_f64().unwrap_or(f64::NAN),
    );

    // The same seed: the page's every score is the native run's.
    let same_seed = &runs[0];
    let mut pairs = vec![("strata ÷ restir raw".to_string(), page.0, native[0].0)];
    pairs.push(("strata ÷ restir after SVGF".to_string(), page.1, native[0].1));
    let page_methods = scores["methods"].as_array().unwrap();
    assert_eq!(page_methods.len(), same_seed.methods.len(), "the page's methods: {body}");
    for (method, native) in page_methods.iter().zip(&same_seed.methods) {
        assert_eq!(method["name"], native.method.name(), "{body}");
        let name = native.method.name();
        pairs.push((format!("{name}'s mean RelMSE"), method["meanRelmse"].as_f64().unwrap(), native.mean_relmse));
        pairs.push((
            format!("{name}'s mean RelMSE after SVGF"),
            method["meanDenoisedRelmse"].as_f64().unwrap(),
            native.mean_denoised_relmse.unwrap_or(f64::NAN),
        ));
    }
    for (what, page, native) in &pairs {
        let apart = page / native - 1.0;
        eprintln!("{what}: the page {page:.5}, natively from the same seed {native:.5} ({:+.3} %)", 100.0 * apart);
        assert!(
            apart.abs() <= SAME_SEED,
            "{what}: the page's {page:.5} is {:.2} % from the native run's {native:.5} from the same seed (at most {} %)",
            100.0 * apart.abs(),
            100.0 * SAME_SEED
        );
    }

    for (what, page, values) in [
        ("raw", page.0, native.iter().map(|r| r.0).collect::<Vec<_>>()),
        ("after SVGF", page.1, native.iter().map(|r| r.1).collect()),
    ] {
        let (mean, deviation) = spread(&values);
        eprintln!(
            "strata ÷ restir {what}: the page {page:.4}; natively, seed {} {:.4}, over {} seeds {mean:.4} ± {deviation:.4} (sd)",
            NATIVE_SEEDS.start,
            values[0],
            values.len()
        );
        assert!(page.is_finite(), "the page's ratio {what} is {page}");
        assert!(
            (page - mean).abs() <= 4.0 * deviation,
            "the page's strata ÷ restir {what}, {page:.4}, is outside the native runs' {mean:.4} ± 4 × {deviation:.4}"
        );
    }
}
