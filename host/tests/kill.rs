//! A run killed part-way leaves complete files or none: `strata compare` and `strata
//! render` are killed (SIGKILL, no chance to clean up) at several points of a run, and
//! every file left under its final name must read back whole (PNG and EXR decode, the
//! CSV parses, run.json is JSON, report.html and the SVGs are closed). Temporary files
//! are hidden (`.NAME.tmp-PID-RANDOM.EXT`), and the next run into the folder takes over the
//! dead run's lock, removes the leftovers and succeeds.

#[path = "support/no_display.rs"]
mod no_display;
use no_display::NO_DISPLAY;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// A fresh empty folder of this test process, under cargo's `target/tmp`, not the shared `/tmp`,
/// where another user could create the name first; the test removes it once it passed.
fn scratch(name: &str) -> PathBuf {
    let dir =
        std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("strata-kill-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("a scratch folder");
    dir
}

fn strata(args: &[&str], out: &Path) -> Command {
    let mut command = Command::new(env!("CARGO_BIN_EXE_strata"));
    command
        .args(args)
        .arg("--out")
        .arg(out)
        .env("XDG_RUNTIME_DIR", NO_DISPLAY)
        .stdout(Stdio::null())
        .stderr(Stdio::null());
    command
}

/// Checks that every visible file in `folder` is complete; returns how many there are.
fn assert_complete(folder: &Path) -> usize {
    let mut count = 0;
    for entry in std::fs::read_dir(folder).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        if name.starts_with('.') {
            continue;
        }
        count += 1;
        let text = || std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
        match path.extension().and_then(|e| e.to_str()) {
            Some("png") => {
                image::open(&path).unwrap_or_else(|e| panic!("{name} is truncated: {e}"));
            }
            Some("exr") => {
                strata_render::rgb_image::RgbImage::read_exr(&path)
                    .unwrap_or_else(|e| panic!("{name} is truncated: {e}"));
            }
            Some("csv") if name == "errors.csv" => {
                strata::evaluation::compare::parse_errors_csv(&text()).unwrap_or_else(|e| panic!("{name}: {e}"));
            }
            Some("json") => {
                serde_json::from_str::<serde_json::Value>(&text()).unwrap_or_else(|e| panic!("{name}: {e}"));
            }
            Some("html") => assert!(text().trim_end().ends_with("</html>"), "{name} is truncated"),
            Some("svg") => assert!(text().trim_end().ends_with("</svg>"), "{name} is truncated"),
            _ => assert!(text().ends_with('\n'), "{name} is truncated"),
        }
    }
    count
}

/// Runs `warm_up` (the same command, smaller) to build the kernels and `args` once to
/// time it, then kills `args` at fractions of that time and checks the folder each time;
/// finally a run into the last killed run's folder must succeed.
fn kill_at_several_points(name: &str, args: &[&str], warm_up: &[&str]) {
    // A first run builds the kernels (on a machine whose shader cache lacks them, that is
    // most of its time: in a CI run whose shader cache lacked two changed kernels this test
    // took 248 s, the runs below sleeping for fractions of it), so the second, timed run is
    // what a killed run repeats. The kernels do not depend on the image's size or the
    // number of frames, seeds or samples, so the first run is the smallest that runs
    // every pass (two frames, for the temporal passes; two seeds, which compare needs).
    let first = scratch(&format!("{name}-first"));
    let mut folders = vec![first.clone()];
    assert!(strata(warm_up, &first).status().unwrap().success(), "the first uninterrupted run failed");
    let timing = scratch(&format!("{name}-timing"));
    folders.push(timing.clone());
    let started = Instant::now();
    assert!(strata(args, &timing).status().unwrap().success(), "the uninterrupted run failed");
    let whole = started.elapsed();
    assert!(assert_complete(&timing) > 0);
    let timing_copy = timing.clone();
    let mut last = timing;
    for (index, fraction) in [0.15, 0.35, 0.55, 0.75, 0.9, 0.97].into_iter().enumerate() {
        let out = scratch(&format!("{name}-{index}"));
        folders.push(out.clone());
        let mut child = strata(args, &out).spawn().unwrap();
        std::thread::sleep(whole.mul_f64(fraction));
        let _ = child.kill();
        let _ = child.wait();
        assert_complete(&out);
        last = out;
    }
    // The next run takes over: a stale lock and hidden leftovers do not stop it. A
    // leftover of every file the run writes is planted too (a kill between writing and
    // renaming, which the points above hit only by chance), as a dead process left it.
    let dead = strata_backends::processes::an_ended_process();
    for entry in std::fs::read_dir(&timing_copy).unwrap() {
        let name = entry.unwrap().file_name().to_string_lossy().into_owned();
        if name.starts_with('.') {
            continue;
        }
        let leftover = match name.rsplit_once('.') {
            Some((stem, extension)) => format!(".{stem}.tmp-{dead}.{extension}"),
            None => format!(".{name}.tmp-{dead}"),
        };
        std::fs::write(last.join(leftover), b"half").unwrap();
    }
    assert!(strata(args, &last).status().unwrap().success(), "a run after a killed one failed");
    let leftovers: Vec<String> = std::fs::read_dir(&last)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with('.') && n != strata::evaluation::output_folder::RECORD_NAME)
        .collect();
    assert!(leftovers.is_empty(), "leftovers after a complete run: {leftovers:?}");
    assert!(Duration::from_secs(0) < whole);
    folders.into_iter().for_each(|folder| std::fs::remove_dir_all(folder).unwrap());
}

/// The check itself: a truncated PNG, EXR or report under a final name is caught.
#[test]
fn the_check_catches_truncated_files() {
    let whole = scratch("truncated-source");
    let args = ["compare", "--width", "16", "--height", "16", "--frames", "2", "--seeds", "2", "--reference-spp", "4"];
    assert!(strata(&args, &whole).status().unwrap().success());
    for name in ["strata_frame001.png", "reference.exr", "report.html", "run.json", "errors.csv"] {
        let out = scratch(&format!("truncated-{name}"));
        let bytes = std::fs::read(whole.join(name)).unwrap();
        std::fs::write(out.join(name), &bytes[..bytes.len() * 2 / 3]).unwrap();
        let caught = std::panic::catch_unwind(|| assert_complete(&out)).is_err();
        assert!(caught, "a truncated {name} passed the check");
        std::fs::remove_dir_all(out).unwrap();
    }
    std::fs::remove_dir_all(whole).unwrap();
}

#[test]
fn a_killed_compare_leaves_complete_files_or_none() {
    // 4 frames of 2 seeds write the same kinds of files as more (frames 1, 2 and 4 as
    // images; every table and figure) in 3.9 s against 5.6 s for 8 frames of 3 seeds.
    let args = ["compare", "--width", "32", "--height", "32", "--frames", "4", "--seeds", "2", "--reference-spp", "32"];
    let warm_up = ["compare", "--width", "8", "--height", "8", "--frames", "2", "--seeds", "2", "--reference-spp", "1"];
    kill_at_several_points("compare", &args, &warm_up);
}

#[test]
fn a_killed_render_leaves_complete_files_or_none() {
    let warm_up = ["render", "--width", "8", "--height", "8", "--spp", "1"];
    kill_at_several_points("render", &["render", "--width", "48", "--height", "48", "--spp", "48"], &warm_up);
}
