//! Intel Open Image Denoise as strata's second denoiser (`--denoise oidn`): on a synthetic
//! image whose clean answer is known it removes most of the noise; a library that is not
//! there is one line saying what to install; and `strata compare --denoise oidn` measures
//! every frame after it.
//!
//! The tests that need the library (`pip install pyoidn==2.5.1.0`) say so and pass where
//! it is missing, unless `STRATA_REQUIRE_OIDN=1` (CI sets it), where they fail.

mod support;

#[path = "support/no_display.rs"]
mod no_display;
use no_display::NO_DISPLAY;
use std::path::PathBuf;
use std::process::Command;
use strata::evaluation::metrics::relmse;
use strata_kernels::denoise_types::DenoiseGuide;
use strata_render::denoise::{OidnDenoiser, OidnLibrary};
use strata_render::rgb_image::RgbImage;

/// The library, or `None` with a note where it is missing and not required.
fn library() -> Option<OidnLibrary> {
    match OidnLibrary::find() {
        Ok(library) => Some(library),
        Err(error) => {
            assert!(std::env::var("STRATA_REQUIRE_OIDN").as_deref() != Ok("1"), "STRATA_REQUIRE_OIDN=1 but {error}");
            eprintln!("note: {error}; Open Image Denoise was not tested");
            None
        }
    }
}

/// `strata` with every Vulkan driver hidden (the CPU interpreter), so that it runs on any
/// machine.
fn strata() -> Command {
    let mut command = Command::new(env!("CARGO_BIN_EXE_strata"));
    command
        .env("VK_ICD_FILENAMES", "/nonexistent/strata-no-driver.json")
        .env("VK_DRIVER_FILES", "/nonexistent/strata-no-driver.json")
        .env_remove("VK_ADD_DRIVER_FILES")
        .env_remove("VK_ADD_ICD_FILENAMES")
        .env("XDG_RUNTIME_DIR", NO_DISPLAY);
    command
}

/// A 64 x 48 frame with a known answer: a checkerboard albedo (8-pixel squares of 0.8 and
/// 0.3) under smooth HDR lighting (0.5 to 4), and the same with seeded noise of mean 1
/// (each pixel times 2u, u uniform: RelMSE about 1/3), as a renderer's 1-spp frame.
fn synthetic() -> (RgbImage, Vec<[f32; 4]>, Vec<DenoiseGuide>) {
    let (width, height) = (64u32, 48u32);
    let mut state: u64 = 0x853c_49e6_748f_ea9b;
    let mut uniform = move || {
        // xorshift64*: a fixed sequence, the same on every machine.
        state ^= state >> 12;
        state ^= state << 25;
        state ^= state >> 27;
        (state.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 40) as f32 / (1u64 << 24) as f32
    };
    let mut clean = RgbImage::new(width, height);
    let (mut noisy, mut guides) = (Vec::new(), Vec::new());
    for y in 0..height {
        for x in 0..width {
            let albedo = if (x / 8 + y / 8) % 2 == 0 { 0.8 } else { 0.3 };
            let light = 0.5 + 3.5 * (x as f32 / width as f32) * (0.5 + 0.5 * (y as f32 / height as f32));
            let value = [albedo * light, albedo * light * 0.9, albedo * light * 0.7];
            clean.pixels[(y * width + x) as usize] = value;
            let n = 2.0 * uniform();
            noisy.push([value[0] * n, value[1] * n, value[2] * n, 0.0]);
            guides.push(DenoiseGuide {
                albedo: [albedo, albedo * 0.9, albedo * 0.7],
                depth: 1.0,
                normal: [0.0, 0.0, 1.0],
                mesh: 0,
                motion: [0.0, 0.0],
                _pad: [0, 0],
            });
        }
    }
    (clean, noisy, guides)
}

#[test]
fn oidn_removes_most_of_the_noise_of_an_image_with_a_known_answer() {
    let Some(library) = library() else { return };
    let (clean, noisy, guides) = synthetic();
    let mut denoiser = OidnDenoiser::new(library, clean.width, clean.height).unwrap();
    let denoised = denoiser.denoise_frame(&noisy, &guides).unwrap();
    let before = relmse(&RgbImage::from_rgba(clean.width, clean.height, &noisy), &clean).unwrap();
    let after = relmse(&denoised, &clean).unwrap();
    assert!(before > 0.2, "the noisy image's RelMSE is {before}");
    assert!(after * 20.0 < before, "RelMSE {before} before OIDN, {after} after: not 20 times lower");
    // The filter is made once and runs again on the next frame alike.
    let again = denoiser.denoise_frame(&noisy, &guides).unwrap();
    assert!(relmse(&again, &clean).unwrap() * 20.0 < before);
    // Input OIDN cannot take is refused with a line naming it, not passed on.
    let mut negative = noisy.clone();
    negative[5][1] = -1.0;
    let message = denoiser.denoise_frame(&negative, &guides).unwrap_err().to_string();
    assert!(message.contains("colour pixel (5, 0)"), "{message}");
    let message = denoiser.denoise_frame(&noisy[1..], &guides).unwrap_err().to_string();
    assert!(message.contains("colour image has 3071 pixels"), "{message}");
}

#[test]
fn a_missing_library_is_one_line_saying_what_to_install() {
    let out: PathBuf =
        std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("strata-oidn-missing-{}", std::process::id()));
    let output = strata()
        .args(["compare", "--width", "32", "--height", "32", "--frames", "2", "--seeds", "2", "--denoise", "oidn"])
        .arg("--out")
        .arg(&out)
        .env("STRATA_OIDN_LIBRARY", "/nonexistent/strata/libOpenImageDenoise.so.2")
        .output()
        .expect("the strata binary runs");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success(), "a missing library was not refused:\n{stderr}");
    assert_eq!(
        stderr.trim_end(),
        "error: --denoise oidn: STRATA_OIDN_LIBRARY=/nonexistent/strata/libOpenImageDenoise.so.2: no such file (set \
         it to the path of libOpenImageDenoise.so.2, or unset it)"
    );
    assert!(!out.exists(), "the output folder was made before the library was found");
    // A library that is not OIDN is named as such.
    let error = OidnLibrary::open(std::path::Path::new("libc.so.6")).unwrap_err().to_string();
    assert_eq!(error, "libc.so.6 has no function oidnNewDevice: not Open Image Denoise 2");
}

#[test]
fn compare_with_oidn_measures_every_frame_denoised() {
    if library().is_none() {
        return;
    }
    let out: PathBuf =
        std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("strata-oidn-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let output = strata()
        .args(["compare", "--width", "32", "--height", "32", "--frames", "3", "--seeds", "3"])
        .args(["--reference-spp", "16", "--denoise", "oidn", "--out"])
        .arg(&out)
        .output()
        .expect("the strata binary runs");
    support::denoised_run::assert_denoised_run(&output, &out, "OIDN", 3);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(stdout.contains("What the viewer sees, denoised frames"), "no denoised viewer table:\n{stdout}");
    let _ = std::fs::remove_dir_all(&out);
}
