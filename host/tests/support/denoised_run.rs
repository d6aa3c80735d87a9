//! What every `strata compare --denoise ...` run must leave, checked once for the tests of
//! each denoiser (`denoise.rs`, `oidn.rs`): included by `mod support;` in each.

use std::path::Path;
use std::process::Output;

/// `output` is a successful run of `--frames frames` that scored every frame after the
/// denoiser titled `title` ("SVGF", "OIDN"): its tables and whole-run ratio, the denoised
/// errors CSV with a row (and a different error) for every raw one, and the denoised
/// images of the last frame and of the first frame's error.
pub fn assert_denoised_run(output: &Output, out: &Path, title: &str, frames: u32) {
    let (stdout, stderr) = (String::from_utf8_lossy(&output.stdout), String::from_utf8_lossy(&output.stderr));
    assert!(output.status.success(), "compare --denoise ({title}) failed:\n{stdout}\n{stderr}");
    assert!(stdout.contains(&format!("After {title} denoising")), "no denoised table:\n{stdout}");
    let ratio = format!("after {title}, strata ÷ restir over frames 1-{frames}");
    assert!(stdout.contains(&ratio), "no denoised whole-run ratio:\n{stdout}");
    let last = format!("strata_denoised_frame{frames:03}.png");
    for file in ["errors_denoised.csv", last.as_str(), "restir_denoised_frame001_relmse.exr"] {
        assert!(out.join(file).is_file(), "{file} was not written");
    }
    let read = |name: &str| {
        strata::evaluation::compare::parse_errors_csv(&std::fs::read_to_string(out.join(name)).unwrap()).unwrap()
    };
    let (raw, denoised) = (read("errors.csv"), read("errors_denoised.csv"));
    assert_eq!(denoised.len(), raw.len(), "a denoised row for every raw one");
    assert!(raw.iter().zip(&denoised).all(|(r, d)| r.relmse != d.relmse), "a denoised frame scored as the raw one");
}
