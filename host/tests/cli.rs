//! The `strata` command line as a user runs it: the README's compare command at a tiny
//! size, its fall-back to the CPU interpreter when no Vulkan device exists, and the
//! errors that bad arguments and missing files give (a message naming the value or the
//! file, exit status 1, no panic, nothing rendered first).

#[path = "support/no_display.rs"]
mod no_display;
use no_display::NO_DISPLAY;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A fresh, empty folder for one test, under cargo's `target/tmp`, not the shared `/tmp`, where
/// another user could create the name first.
fn scratch(name: &str) -> PathBuf {
    let dir =
        std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("strata-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("a scratch folder");
    dir
}

/// `strata ARGS` with every Vulkan driver hidden from the loader, so the command line
/// must fall back to the CPU interpreter (and does so on any machine).
fn strata_without_vulkan(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_strata"))
        .args(args)
        .env("VK_ICD_FILENAMES", "/nonexistent/strata-no-driver.json")
        .env("VK_DRIVER_FILES", "/nonexistent/strata-no-driver.json")
        .env_remove("VK_ADD_DRIVER_FILES")
        .env_remove("VK_ADD_ICD_FILENAMES")
        .env("RUST_BACKTRACE", "0")
        .env("RUST_LIB_BACKTRACE", "0")
        .env("XDG_RUNTIME_DIR", NO_DISPLAY)
        .output()
        .expect("the strata binary runs")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// Asserts that `output` is a refusal (exit status 1, no panic) whose message contains
/// every one of `names`.
fn assert_refused(output: &Output, names: &[&str]) {
    let stderr = text(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "expected a refusal; stderr:\n{stderr}");
    assert!(!stderr.contains("panicked"), "a panic instead of an error:\n{stderr}");
    for name in names {
        assert!(stderr.contains(name), "the error does not name `{name}`:\n{stderr}");
    }
}

#[test]
fn compare_without_a_vulkan_device_runs_on_the_interpreter_and_says_so() {
    let out = scratch("compare");
    let args = ["compare", "--width", "16", "--height", "16", "--frames", "2", "--seeds", "3", "--reference-spp", "4"];
    let output = strata_without_vulkan(&[&args[..], &["--out", out_str(&out)]].concat());
    let (stdout, stderr) = (text(&output.stdout), text(&output.stderr));
    assert!(output.status.success(), "compare failed:\n{stdout}\n{stderr}");
    assert!(stderr.contains("no GPU adapter found") && stderr.contains("CPU interpreter"), "no notice:\n{stderr}");
    assert!(stdout.contains("backend: cpu"), "{stdout}");
    // The summary table: a row per method and per ratio, labelled in its first column.
    let labels: Vec<&str> = stdout.lines().filter_map(|l| l.split(" | ").next()).map(str::trim).collect();
    for row in ["restir", "restir-disc", "strata", "÷ restir", "÷ restir-disc", "÷ restir luma"] {
        assert!(labels.contains(&row), "no `{row}` row in the summary:\n{stdout}");
    }
    for file in [
        "reference.exr",
        "reference.png",
        "relmse.svg",
        "variance.csv",
        "strata_frame001.exr",
        "strata_frame002.png",
        "restir_frame002_relmse.exr",
        "restir-disc_frame001_relmse.png",
    ] {
        assert!(out.join(file).is_file(), "{file} was not written");
    }
    // errors.csv: one row per method, frame and seed, with finite positive errors.
    let csv = std::fs::read_to_string(out.join("errors.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    for column in ["method", "frame", "seed", "relmse", "prelmse", "mse"] {
        assert!(header.contains(&column), "errors.csv lacks column {column}: {header:?}");
    }
    let rows: Vec<Vec<&str>> = lines.map(|line| line.split(',').collect()).collect();
    assert_eq!(rows.len(), 3 * 2 * 3, "3 methods x 2 frames x 3 seeds");
    let relmse = header.iter().position(|c| *c == "relmse").unwrap();
    for row in &rows {
        let value: f64 = row[relmse].parse().unwrap();
        assert!(value.is_finite() && value > 0.0, "relmse {value} in {row:?}");
    }
    // `strata plot` redraws the plot from the CSV and says the same whole-run ratios.
    let svg = out.join("again.svg");
    let plot = strata_without_vulkan(&["plot", out.join("errors.csv").to_str().unwrap(), "--out", out_str(&svg)]);
    assert!(plot.status.success(), "{}", text(&plot.stderr));
    assert!(std::fs::read_to_string(&svg).unwrap().starts_with("<svg"));
    // The whole-run ratios, each `... over frames 1-2 (...): MEAN ± HALF (N seeds)`; the
    // plot reads them from the CSV's 7 significant digits, so they agree to rounding. With
    // both regimes (the default) compare says which each line is.
    let ratios = |stdout: &str, regime: &str| -> Vec<(String, f64)> {
        stdout
            .lines()
            .filter_map(|l| l.strip_prefix(regime))
            .filter(|l| l.contains(" over frames 1-2 "))
            .map(|l| {
                let mean = l.split("): ").nth(1).and_then(|r| r.split(' ').next()).unwrap();
                (l.split(" over ").next().unwrap().to_string(), mean.parse().unwrap())
            })
            .collect()
    };
    let (from_compare, from_plot) = (ratios(&stdout, "temporal reuse: "), ratios(&text(&plot.stdout), ""));
    assert_eq!(from_compare.len(), 2, "a whole-run ratio per baseline:\n{stdout}");
    // The accumulated regime's, from its own CSV.
    let accumulated = strata_without_vulkan(&[
        "plot",
        out.join("errors_accumulated.csv").to_str().unwrap(),
        "--out",
        out_str(&out.join("accumulated.svg")),
    ]);
    assert!(accumulated.status.success(), "{}", text(&accumulated.stderr));
    let (accumulated_compare, accumulated_plot) =
        (ratios(&stdout, "accumulated frames: "), ratios(&text(&accumulated.stdout), ""));
    assert_eq!(accumulated_compare.len(), 2, "a whole-run ratio per baseline, accumulated:\n{stdout}");
    let pairs = from_compare.iter().zip(&from_plot).chain(accumulated_compare.iter().zip(&accumulated_plot));
    assert_eq!(from_compare.len(), from_plot.len());
    assert_eq!(accumulated_compare.len(), accumulated_plot.len());
    for ((label, a), (plot_label, b)) in pairs {
        assert!(label == plot_label && (a - b).abs() <= 2e-4 && *a > 0.0, "{label} {a} against {plot_label} {b}");
    }
    let _ = std::fs::remove_dir_all(&out);
}

/// `--reuse-order auto` (the default) is resolved by the camera path and recorded as the
/// order that ran: temporal-first for a still camera, spatial-first for a moving one.
#[test]
fn the_default_reuse_order_follows_the_camera() {
    for (path, order) in [("static", "temporal-first"), ("orbit:1", "spatial-first")] {
        let out = scratch(&format!("order-{}", path.replace(':', "-")));
        let output = Command::new(env!("CARGO_BIN_EXE_strata"))
            .args(["compare", "--width", "8", "--height", "8", "--frames", "2", "--seeds", "2"])
            .args(["--reference-spp", "1", "--methods", "strata", "--both-regimes", "false"])
            .args(["--camera-path", path, "--out", out_str(&out)])
            .env("XDG_RUNTIME_DIR", NO_DISPLAY)
            .output()
            .unwrap();
        assert!(output.status.success(), "{}", text(&output.stderr));
        let record: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).unwrap()).unwrap();
        let recorded = record.pointer("/settings/reuse_order").and_then(|v| v.as_str());
        assert_eq!(recorded, Some(order), "--camera-path {path}: {record}");
        let _ = std::fs::remove_dir_all(&out);
    }
}

#[test]
fn bad_compare_arguments_are_refused_before_anything_renders() {
    let out = scratch("refused");
    // The argument parser's refusals (exit status 2): the selection's own ranges, and the
    // ReSTIR settings' numbers, quoted as typed.
    for (arguments, names) in [
        (["--block-size", "12"], ["--block-size", "'12'"]),
        (["--candidates", "5"], ["--candidates", "5"]),
        (["--temporal-cap", "0"], ["--temporal-cap", "'0'"]),
        (["--min-roughness", "NaN"], ["--min-roughness", "'NaN'"]),
        (["--min-distance", "inf"], ["--min-distance", "'inf'"]),
        (["--disc-radius", "16385"], ["--disc-radius", "'16385'"]),
    ] {
        let output = strata_without_vulkan(&[&["compare", "--out", out_str(&out)][..], &arguments[..]].concat());
        let stderr = text(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "expected the parser's refusal; stderr:\n{stderr}");
        assert!(names.iter().all(|name| stderr.contains(name)), "{arguments:?}: {stderr}");
        assert!(!out.join("reference.exr").exists(), "{arguments:?} rendered a reference");
    }
    let cases: [(&[&str], &[&str]); 7] = [
        (&["--width", "0"], &["--width 0"]),
        (&["--accumulate", "--camera-path", "orbit:2"], &["--accumulate", "--camera-path orbit:2"]),
        (&["--temporal-candidates", "9"], &["temporal candidates 9"]),
        (&["--specular-chain", "99"], &["specular chain 99"]),
        (&["--frames", "0"], &["--frames"]),
        (&["--frames", "4294967295"], &["--frames 4294967295", "at most 100000"]),
        (&["--seeds", "20000"], &["--seeds 20000", "at most 10000"]),
    ];
    for (arguments, names) in cases {
        let output = strata_without_vulkan(&[&["compare", "--out", out_str(&out)][..], arguments].concat());
        assert_refused(&output, names);
        assert!(!text(&output.stdout).contains("rendering the reference"), "{arguments:?} rendered first");
        assert!(!out.join("reference.exr").exists(), "{arguments:?} rendered a reference");
    }
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn missing_and_unreadable_files_are_named() {
    let out = scratch("files");
    let missing_scene = out.join("no-such-scene.json");
    let output = strata_without_vulkan(&["compare", missing_scene.to_str().unwrap()]);
    assert_refused(&output, &["no-such-scene.json", "cannot read"]);
    // The OS reason is said once, not twice.
    assert_eq!(text(&output.stderr).matches("No such file").count(), 1, "{}", text(&output.stderr));

    let xml = out.join("scene.xml");
    std::fs::write(&xml, "<scene/>").unwrap();
    assert_refused(&strata_without_vulkan(&["render", xml.to_str().unwrap()]), &["scene.xml", "xml"]);

    let missing_exr = out.join("missing.exr");
    let output = strata_without_vulkan(&["metrics", missing_exr.to_str().unwrap(), missing_exr.to_str().unwrap()]);
    assert_refused(&output, &["missing.exr"]);

    let not_an_exr = out.join("text.exr");
    std::fs::write(&not_an_exr, "not an image").unwrap();
    let output =
        strata_without_vulkan(&["compare", "--reference", not_an_exr.to_str().unwrap(), "--out", out_str(&out)]);
    assert_refused(&output, &["text.exr"]);

    let missing_csv = out.join("missing.csv");
    assert_refused(&strata_without_vulkan(&["plot", missing_csv.to_str().unwrap()]), &["missing.csv"]);
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn a_reference_of_another_size_is_refused_naming_both_sizes() {
    let out = scratch("reference-size");
    let reference = out.join("reference.exr");
    let output =
        strata_without_vulkan(&["render", "--width", "8", "--height", "6", "--spp", "1", "--out", out_str(&out)]);
    assert!(output.status.success(), "{}", text(&output.stderr));
    let rendered = std::fs::read_dir(&out)
        .unwrap()
        .map(|entry| entry.unwrap().path())
        .find(|path| path.extension().is_some_and(|e| e == "exr"))
        .expect("render wrote an EXR");
    std::fs::rename(rendered, &reference).unwrap();
    let output = strata_without_vulkan(&[
        "compare",
        "--width",
        "16",
        "--height",
        "16",
        "--frames",
        "1",
        "--seeds",
        "1",
        "--reference",
        reference.to_str().unwrap(),
        "--out",
        out_str(&out),
    ]);
    assert_refused(&output, &["8x6", "16x16"]);
    let _ = std::fs::remove_dir_all(&out);
}

fn out_str(path: &Path) -> &str {
    path.to_str().expect("a UTF-8 temporary path")
}

#[test]
fn a_user_mistake_is_one_line_without_a_backtrace_even_with_rust_backtrace_set() {
    let out = scratch("one-line-error");
    let missing = out.join("no-such-reference.exr");
    let output = Command::new(env!("CARGO_BIN_EXE_strata"))
        .args(["compare", "--width", "8", "--height", "8", "--reference"])
        .arg(&missing)
        .arg("--out")
        .arg(&out)
        .env("RUST_BACKTRACE", "1")
        .env("RUST_LIB_BACKTRACE", "1")
        .env("XDG_RUNTIME_DIR", NO_DISPLAY)
        .output()
        .expect("the strata binary runs");
    let stderr = text(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "{stderr}");
    let lines: Vec<&str> = stderr.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "more than one line:\n{stderr}");
    assert!(lines[0].starts_with("error: ") && lines[0].contains("no-such-reference.exr"), "{stderr}");
    assert!(!stderr.to_lowercase().contains("backtrace"), "{stderr}");
    std::fs::remove_dir_all(&out).unwrap();
}

/// An `XDG_RUNTIME_DIR` that other users can write (as `/tmp`) gets one warning line before
/// anything else (Mesa's Vulkan layer connects to a display socket there; runtime_dir.rs in
/// the binary says why); a folder of the user's own gets none.
#[cfg(unix)]
#[test]
fn a_runtime_folder_others_can_write_is_warned_about_in_one_line() {
    use std::os::unix::fs::PermissionsExt;
    let out = scratch("shared-runtime-dir");
    let shared = out.join("shared");
    std::fs::create_dir(&shared).unwrap();
    std::fs::set_permissions(&shared, std::fs::Permissions::from_mode(0o1777)).unwrap();
    let missing = out.join("no-such-reference.exr");
    let run = |runtime: &Path| {
        let output = Command::new(env!("CARGO_BIN_EXE_strata"))
            .args(["compare", "--width", "8", "--height", "8", "--reference"])
            .arg(&missing)
            .arg("--out")
            .arg(&out)
            .env("XDG_RUNTIME_DIR", runtime)
            .output()
            .expect("the strata binary runs");
        assert_eq!(output.status.code(), Some(1), "{}", text(&output.stderr));
        text(&output.stderr).lines().filter(|l| !l.trim().is_empty()).map(str::to_string).collect::<Vec<_>>()
    };
    let lines = run(&shared);
    assert_eq!(lines.len(), 2, "{lines:#?}");
    let warning = format!("warning: XDG_RUNTIME_DIR={:?}: ", shared.as_os_str());
    assert!(lines[0].starts_with(&warning) && lines[0].contains("wayland-0"), "{lines:#?}");
    assert!(lines[1].starts_with("error: ") && lines[1].contains("no-such-reference.exr"), "{lines:#?}");
    let private = out.join("private");
    std::fs::create_dir(&private).unwrap();
    std::fs::set_permissions(&private, std::fs::Permissions::from_mode(0o700)).unwrap();
    let lines = run(&private);
    assert_eq!(lines.len(), 1, "{lines:#?}");
    std::fs::remove_dir_all(&out).unwrap();
}

#[test]
fn a_second_run_into_the_same_folder_replaces_the_first_runs_files() {
    let out = scratch("rerun");
    std::fs::write(out.join("strata_frame999.png"), b"an older run's image").unwrap();
    std::fs::write(out.join("notes.txt"), b"the user's own file").unwrap();
    // The older run recorded its image (output_folder::RECORD_NAME): only recorded files go.
    std::fs::write(out.join(strata::evaluation::output_folder::RECORD_NAME), "strata_frame999.png\n").unwrap();
    let args = ["compare", "--width", "8", "--height", "8", "--frames", "1", "--seeds", "2", "--reference-spp", "2"];
    let output = strata_without_vulkan(&[&args[..], &["--out", out_str(&out)]].concat());
    assert!(output.status.success(), "{}", text(&output.stderr));
    assert!(text(&output.stdout).contains("removed 1 files of an earlier run"), "{}", text(&output.stdout));
    assert!(!out.join("strata_frame999.png").exists() && out.join("notes.txt").exists());
    for file in ["report.html", "summary.txt", "run.json", "errors.csv", "relmse.svg", "relmse.png", "reference.png"] {
        assert!(out.join(file).exists(), "no {file}");
    }
    // Every file the run wrote is one a later run recognises and is recorded, so a later
    // run removes it (the names in report.rs and in output_folder.rs cannot drift apart),
    // and nothing hidden is left but the record.
    let record_name = strata::evaluation::output_folder::RECORD_NAME;
    let recorded = std::fs::read_to_string(out.join(record_name)).unwrap();
    for entry in std::fs::read_dir(&out).unwrap() {
        let name = entry.unwrap().file_name().to_string_lossy().into_owned();
        if name != "notes.txt" && name != record_name {
            assert!(strata::evaluation::output_folder::is_run_output(&name), "`{name}` would survive a later run");
            assert!(recorded.lines().any(|line| line == name), "`{name}` is not in the record");
        }
    }
    let record: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).unwrap()).unwrap();
    assert_eq!(record["width"], 8);
    assert!(record["command_line"].as_str().unwrap().contains("--reference-spp 2"), "{record}");
    assert!(record["backend"].as_str().unwrap().starts_with("cpu"), "{record}");
    // The interpreter sorts with the network (ranking pays B² comparisons lane by lane).
    let histogram = record["settings"]["histogram_kernel"].as_str();
    assert!(matches!(histogram, Some("block_histogram" | "block_histogram_subgroup")), "{record}");
    std::fs::remove_dir_all(&out).unwrap();
}

/// `docs/cli.md` is every subcommand's `--help`, so the flag reference and the command
/// line never disagree. `STRATA_BLESS=1` rewrites the file from the binary.
#[test]
fn the_flag_reference_is_the_commands_help() {
    let mut reference = String::from(
        "# Every flag of `strata`\n\n[← README](../README.md)\n\nThe `--help` of each command, generated from the argument types: \
         `STRATA_BLESS=1 cargo test -p strata --test cli` rewrites this file, and the test fails when it differs \
         from the binary.\n",
    );
    for command in ["compare", "render", "metrics", "plot", "histogram"] {
        let output = Command::new(env!("CARGO_BIN_EXE_strata")).args([command, "--help"]).output().unwrap();
        assert!(output.status.success(), "{command} --help");
        let help = text(&output.stdout);
        reference += &format!("\n## strata {command}\n\n```text\n{}\n```\n", help.trim_end());
    }
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/cli.md");
    if std::env::var_os("STRATA_BLESS").is_some() {
        std::fs::write(&path, &reference).unwrap();
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == reference,
        "docs/cli.md is not the commands' --help: run STRATA_BLESS=1 cargo test -p strata --test cli"
    );
}
