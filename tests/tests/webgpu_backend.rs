//! The WebGPU backend (`strata_backends::webgpu_backend`): Chromium's WebGPU, driven
//! from a headless tab over the loopback bridge. A buffer round trip, a dispatch with a
//! known answer (and its timing), a texture round trip through a kernel, Tint's refusal
//! of a kernel as one line naming the file and line; a missing browser (named by the
//! options or by `STRATA_CHROMIUM`) is "unavailable" for the backend, the check's
//! column and `xtask run --backend all`, and a browser that never loads the page or
//! exits at once is an error within the start timeout, not a hang.
//!
//! Needs Chromium with WebGPU (Debian's `chromium`, or `STRATA_CHROMIUM=/path`): without
//! it the tests say so and pass, unless `STRATA_REQUIRE_BROWSER=1` (CI sets it), where a
//! missing browser or adapter fails.

use strata_backends::backend::{download, upload};
use strata_backends::texture::TextureDesc;
use strata_backends::webgpu_backend::{WebGpuBackend, WebGpuOptions, browser_required};
use strata_backends::{Backend, BackendError, Bind};
use strata_kernels::{Kernel, TexelFormat, TextureDimension};

/// The backend, or `None` (with a note) where this machine has no browser or adapter;
/// under `STRATA_REQUIRE_BROWSER=1` that fails.
fn open() -> Option<WebGpuBackend> {
    match WebGpuBackend::new(WebGpuOptions::default()) {
        Ok(backend) => Some(backend),
        Err(error) => {
            assert!(!browser_required(), "STRATA_REQUIRE_BROWSER=1 but the WebGPU backend did not open: {error}");
            eprintln!("note: the WebGPU backend is unavailable here, not tested: {error}");
            None
        }
    }
}

#[test]
fn a_buffer_comes_back_as_written() {
    let Some(mut gpu) = open() else { return };
    eprintln!("{}", gpu.info().summary());
    let words: Vec<u32> = (0..1000u32).map(|i| i.wrapping_mul(2_654_435_761) ^ 0xdead_beef).collect();
    let buffer = upload(&mut gpu, "words", &words).unwrap();
    assert_eq!(download::<u32>(&mut gpu, buffer).unwrap(), words);
    // A write at an offset replaces only its words; a size that is not whole words
    // comes back at its length.
    gpu.write_buffer(buffer, 8, &[1, 0, 0, 0, 2, 0, 0, 0]).unwrap();
    let back = download::<u32>(&mut gpu, buffer).unwrap();
    assert_eq!(&back[..4], &[words[0], words[1], 1, 2]);
    assert_eq!(&back[4..], &words[4..]);
    let odd = gpu.create_buffer("odd", 7).unwrap();
    assert_eq!(gpu.read_buffer(odd).unwrap(), vec![0; 7]);
    gpu.destroy_buffer(odd).unwrap();
    gpu.destroy_buffer(buffer).unwrap();
    assert!(matches!(gpu.read_buffer(buffer), Err(BackendError::UnknownBuffer(_))));
}

#[test]
fn a_dispatch_gives_the_known_answer() {
    let Some(mut gpu) = open() else { return };
    let source = "struct Params { scale: u32, offset: u32 }
        @group(0) @binding(0) var<uniform> params: Params;
        @group(0) @binding(1) var<storage, read> input: array<u32>;
        @group(0) @binding(2) var<storage, read_write> output: array<u32>;
        @compute @workgroup_size(64) fn main(@builtin(global_invocation_id) id: vec3<u32>) {
            if id.x < arrayLength(&input) {
                output[id.x] = input[id.x] * params.scale + params.offset + id.x;
            }
        }";
    let kernel = Kernel::from_wgsl("affine.wgsl", source.into(), "main", false).unwrap();
    let input: Vec<u32> = (0..300).collect();
    let params = upload(&mut gpu, "params", &[3u32, 7]).unwrap();
    let input_buffer = upload(&mut gpu, "input", &input).unwrap();
    let output = gpu.create_buffer("output", 4 * 300).unwrap();
    let binds = [Bind::new(0, params), Bind::new(1, input_buffer), Bind::new(2, output)];
    gpu.dispatch(&kernel, &binds, [5, 1, 1]).unwrap();
    let expected: Vec<u32> = input.iter().enumerate().map(|(i, x)| x * 3 + 7 + i as u32).collect();
    assert_eq!(download::<u32>(&mut gpu, output).unwrap(), expected);
    // Twice more, the second timed (the pipeline is the page's already).
    gpu.write_buffer(params, 0, bytemuck::cast_slice(&[1u32, 0])).unwrap();
    gpu.dispatch(&kernel, &binds, [5, 1, 1]).unwrap();
    if gpu.info().timestamps {
        let time = gpu.dispatch_timed(&kernel, &binds, [5, 1, 1]).unwrap();
        assert!(time < std::time::Duration::from_secs(10), "{time:?}");
    }
    let expected: Vec<u32> = input.iter().enumerate().map(|(i, x)| x + i as u32).collect();
    assert_eq!(download::<u32>(&mut gpu, output).unwrap(), expected);
}

#[test]
fn a_texture_goes_through_a_kernel() {
    let Some(mut gpu) = open() else { return };
    let source = "@group(0) @binding(0) var source: texture_2d<u32>;
        @group(0) @binding(1) var destination: texture_storage_2d<r32uint, write>;
        @compute @workgroup_size(8, 8) fn main(@builtin(global_invocation_id) id: vec3<u32>) {
            let size = textureDimensions(source);
            if id.x < size.x && id.y < size.y {
                let texel = textureLoad(source, id.xy, 0);
                textureStore(destination, id.xy, vec4<u32>(texel.x + texel.w * 1000u, 0u, 0u, 1u));
            }
        }";
    let kernel = Kernel::from_wgsl("copy.wgsl", source.into(), "main", false).unwrap();
    let (width, height) = (13u32, 5u32);
    let desc = |label: &str, format| TextureDesc {
        label: label.into(),
        dimension: TextureDimension::D2,
        size: [width, height, 1],
        mip_levels: 1,
        format,
    };
    let source_texture = gpu.create_texture(&desc("source", TexelFormat::Rgba8Uint)).unwrap();
    let texels: Vec<u8> = (0..width * height).flat_map(|i| [i as u8, 0, 0, (i % 7) as u8]).collect();
    gpu.write_texture(source_texture, 0, &texels).unwrap();
    assert_eq!(gpu.read_texture(source_texture, 0).unwrap(), texels);
    let target = gpu.create_texture(&desc("target", TexelFormat::R32Uint)).unwrap();
    gpu.dispatch(&kernel, &[Bind::texture(0, source_texture), Bind::texture(1, target)], [2, 1, 1]).unwrap();
    let words: Vec<u32> = bytemuck::pod_collect_to_vec(&gpu.read_texture(target, 0).unwrap());
    let expected: Vec<u32> = (0..width * height).map(|i| (i % 256) + (i % 7) * 1000).collect();
    assert_eq!(words, expected);
}

#[test]
fn a_kernel_tint_refuses_is_one_line_naming_its_file_and_line() {
    let Some(mut gpu) = open() else { return };
    // naga takes 64-bit integers in external kernels (the interpreter and Vulkan run
    // them); WGSL has none, and Tint says so.
    let source = "@group(0) @binding(0) var<storage, read_write> data: array<u32>;
        @compute @workgroup_size(1) fn main() {
            let wide: i64 = i64(data[0]) + 1li;
            data[0] = u32(wide);
        }";
    let kernel = Kernel::from_wgsl("wide.wgsl", source.into(), "main", false).unwrap();
    let data = upload(&mut gpu, "data", &[41u32]).unwrap();
    let error = gpu.dispatch(&kernel, &[Bind::new(0, data)], [1, 1, 1]).expect_err("Tint refuses i64");
    let message = error.to_string();
    eprintln!("{message}");
    assert!(!message.contains('\n'), "{message}");
    assert!(message.starts_with("webgpu: validation error in Tint's compilation of `main`: wide.wgsl:3:"), "{message}");
    // The backend goes on after an error.
    let other = upload(&mut gpu, "other", &[1u32, 2]).unwrap();
    assert_eq!(download::<u32>(&mut gpu, other).unwrap(), [1, 2]);
}

#[test]
fn a_missing_browser_is_unavailable() {
    let options = WebGpuOptions { browser: Some("/nonexistent/chromium".into()), ..Default::default() };
    let error = WebGpuBackend::new(options).err().expect("no browser, no backend");
    let message = error.to_string();
    assert!(matches!(error, BackendError::Unavailable { .. }), "{message}");
    assert!(message.contains("/nonexistent/chromium: no such browser"), "{message}");
}

/// A "browser" that is a shell script running `body`, in a private folder.
fn fake_browser(body: &str) -> (strata_files::TempDir, std::path::PathBuf) {
    use std::os::unix::fs::PermissionsExt;
    let folder = strata_files::private_scratch_folder("strata-webgpu-test-").unwrap();
    let path = folder.path().join("chromium");
    std::fs::write(&path, format!("#!/bin/sh\n{body}\n")).unwrap();
    std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o700)).unwrap();
    (folder, path)
}

#[test]
fn a_browser_that_never_loads_the_page_times_out() {
    let (_folder, browser) = fake_browser("exec sleep 60");
    let started = std::time::Instant::now();
    let options = WebGpuOptions {
        browser: Some(browser),
        start_timeout: std::time::Duration::from_secs(2),
        ..Default::default()
    };
    let message = WebGpuBackend::new(options).err().expect("no page, no backend").to_string();
    assert!(message.contains("the page did not load within 2 s"), "{message}");
    assert!(started.elapsed() < std::time::Duration::from_secs(10), "{:?}", started.elapsed());
}

#[test]
fn a_browser_that_exits_is_reported_at_once() {
    let (_folder, browser) = fake_browser("echo 'no display' >&2; exit 3");
    let started = std::time::Instant::now();
    let options = WebGpuOptions { browser: Some(browser), ..Default::default() };
    let message = WebGpuBackend::new(options).err().expect("no browser, no backend").to_string();
    assert!(message.contains("Chromium exited (exit status: 3); its log ends: no display"), "{message}");
    assert!(started.elapsed() < std::time::Duration::from_secs(10), "{:?}", started.elapsed());
}

/// Run by [`a_browser_named_by_the_environment_that_is_missing_is_unavailable`] with
/// `STRATA_CHROMIUM=/nonexistent/chromium`.
#[test]
#[ignore = "run by a_browser_named_by_the_environment_that_is_missing_is_unavailable in a child process"]
fn child_with_a_missing_browser() {
    let why = "STRATA_CHROMIUM=/nonexistent/chromium: no such file";
    let message = WebGpuBackend::new(WebGpuOptions::default()).err().expect("no browser").to_string();
    assert_eq!(message, format!("webgpu: WebGPU in headless Chromium is unavailable: {why}"));
    // The check's column and `xtask run --backend all` say the same.
    let slot = strata_check::backend_slots().into_iter().find(|slot| slot.name == "webgpu").expect("a webgpu slot");
    assert_eq!((slot.toolchain)(), Err(why.to_string()));
    assert!((slot.open)().err().expect("no browser").to_string().ends_with(why));
}

#[test]
fn a_browser_named_by_the_environment_that_is_missing_is_unavailable() {
    let status = std::process::Command::new(std::env::current_exe().unwrap())
        .args(["--exact", "child_with_a_missing_browser", "--ignored", "--nocapture"])
        .env("STRATA_CHROMIUM", "/nonexistent/chromium")
        .status()
        .unwrap();
    assert!(status.success(), "the child run failed: {status}");
}
