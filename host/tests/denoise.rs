//! `strata compare --denoise svgf` as a user runs it: every frame measured after the
//! denoiser too (`errors_denoised.csv`, the denoised previews, the same tables), and the
//! denoiser doing its job: its frames are far smoother than the raw ones.

mod support;

#[path = "support/no_display.rs"]
mod no_display;
use no_display::NO_DISPLAY;
use std::path::PathBuf;
use std::process::Command;

#[test]
fn compare_with_svgf_measures_every_frame_denoised_and_the_frames_are_smoother() {
    let out: PathBuf =
        std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("strata-denoise-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    // On the interpreter (every Vulkan driver hidden), so that it runs on any machine.
    let output = Command::new(env!("CARGO_BIN_EXE_strata"))
        .args(["compare", "--width", "32", "--height", "24", "--frames", "6", "--seeds", "2"])
        .args(["--reference-spp", "64", "--denoise", "svgf", "--out"])
        .arg(&out)
        .env("VK_ICD_FILENAMES", "/nonexistent/strata-no-driver.json")
        .env("VK_DRIVER_FILES", "/nonexistent/strata-no-driver.json")
        .env_remove("VK_ADD_DRIVER_FILES")
        .env_remove("VK_ADD_ICD_FILENAMES")
        .env("XDG_RUNTIME_DIR", NO_DISPLAY)
        .output()
        .expect("the strata binary runs");
    support::denoised_run::assert_denoised_run(&output, &out, "SVGF", 6);
    // The denoiser removes noise: neighbouring pixels of seed 1's last frame differ far
    // less after it. (Its RelMSE at 32 x 24, where most pixels touch an edge, is
    // dominated by its blur; BENCHMARKS.md measures it at 256 wide.)
    for method in ["strata", "restir", "restir-disc"] {
        let roughness = |name: String| -> f64 {
            let image = strata_render::rgb_image::RgbImage::read_exr(&out.join(name)).unwrap();
            let luminance = |p: [f32; 3]| f64::from(0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]);
            let rows = image.pixels.chunks(image.width as usize);
            rows.flat_map(|row| row.windows(2).map(|w| (luminance(w[0]) - luminance(w[1])).abs())).sum()
        };
        let before = roughness(format!("{method}_frame006.exr"));
        let after = roughness(format!("{method}_denoised_frame006.exr"));
        assert!(after < 0.7 * before, "{method}: neighbours differ by {before} in all raw, {after} denoised");
    }
    let _ = std::fs::remove_dir_all(&out);
}
