//! The `strata` binary against a careless or hostile user (issue 38, RELIABILITY.md
//! "Hostile input"): one test per class of defect found by ~390 runs of the release
//! binary. Every refusal is one `error:` line naming the file, field or value, exit status
//! 1 (2 for the argument parser), no panic and no backtrace although `RUST_BACKTRACE=1` is
//! set, and no file written half or under a wrong name. Runs on the CPU interpreter
//! (`--backend cpu`) at a few pixels, so it needs no device.
//!
//! `STRATA_HOSTILE_BINARY=PATH` runs the suite against another build of `strata` (how
//! each test was seen failing before its fix: against the binary of 47d7e0e).

#[path = "support/no_display.rs"]
mod no_display;
use no_display::NO_DISPLAY;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use strata_render::rgb_image::RgbImage;

/// The binary under test.
fn binary() -> PathBuf {
    std::env::var_os("STRATA_HOSTILE_BINARY").map_or_else(|| PathBuf::from(env!("CARGO_BIN_EXE_strata")), PathBuf::from)
}

/// A fresh, empty folder for one test.
fn scratch(name: &str) -> PathBuf {
    let dir =
        std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("strata-hostile-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("a scratch folder");
    dir
}

/// `strata` with `args`, a backtrace asked for, and Mesa kept quiet.
fn command(args: &[&std::ffi::OsStr]) -> Command {
    let mut command = Command::new(binary());
    command.args(args).env("RUST_BACKTRACE", "1").env("RUST_LIB_BACKTRACE", "1").env("XDG_RUNTIME_DIR", NO_DISPLAY);
    command
}

/// Runs `strata ARGS` to the end.
fn strata<S: AsRef<std::ffi::OsStr>>(args: &[S]) -> Output {
    let args: Vec<&std::ffi::OsStr> = args.iter().map(AsRef::as_ref).collect();
    command(&args).output().expect("the strata binary runs")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// Asserts a refusal: exit status `code`, no panic or backtrace, every one of `names` in
/// standard error, and (for our own errors, status 1) exactly one line there that is not
/// a warning.
fn assert_refused_with(output: &Output, code: i32, names: &[&str]) {
    let stderr = text(&output.stderr);
    assert_eq!(output.status.code(), Some(code), "expected a refusal (status {code}); stderr:\n{stderr}");
    assert!(!stderr.contains("panicked") && !stderr.contains("stack backtrace"), "a panic:\n{stderr}");
    for name in names {
        assert!(stderr.contains(name), "the error does not name `{name}`:\n{stderr}");
    }
    if code == 1 {
        let lines: Vec<&str> = stderr.lines().filter(|l| !l.trim().is_empty() && !l.starts_with("warning:")).collect();
        let errors: Vec<&&str> = lines.iter().filter(|l| l.starts_with("error: ")).collect();
        assert_eq!(errors.len(), 1, "not one error line:\n{stderr}");
    }
}

fn assert_refused(output: &Output, names: &[&str]) {
    assert_refused_with(output, 1, names);
}

fn assert_succeeded(output: &Output) {
    assert!(output.status.success(), "failed:\n{}\n{}", text(&output.stdout), text(&output.stderr));
}

/// Every file under `folder` (recursively), with its size.
fn files(folder: &Path) -> Vec<(PathBuf, u64)> {
    let mut found = Vec::new();
    let Ok(entries) = std::fs::read_dir(folder) else { return found };
    for entry in entries.map(Result::unwrap) {
        let path = entry.path();
        if path.is_dir() {
            found.extend(files(&path));
        } else {
            found.push((path.clone(), std::fs::symlink_metadata(&path).unwrap().len()));
        }
    }
    found
}

/// The committed Cornell box copied into `folder/name` with `edit` applied to its JSON;
/// returns the scene file.
fn cornell_box(folder: &Path, name: &str, edit: impl FnOnce(&mut serde_json::Value)) -> PathBuf {
    let source = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/cornell-box");
    let target = folder.join(name);
    std::fs::create_dir_all(target.join("meshes")).unwrap();
    for entry in std::fs::read_dir(source.join("meshes")).unwrap().map(Result::unwrap) {
        std::fs::copy(entry.path(), target.join("meshes").join(entry.file_name())).unwrap();
    }
    let mut scene: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(source.join("scene.json")).unwrap()).unwrap();
    edit(&mut scene);
    let file = target.join("scene.json");
    std::fs::write(&file, serde_json::to_string_pretty(&scene).unwrap()).unwrap();
    file
}

/// A small `compare` on the interpreter: `WxH`, frames, seeds, 4-spp reference.
fn compare_args(size: u32, frames: u32, seeds: u32) -> Vec<String> {
    let size = size.to_string();
    [
        "compare",
        "--backend",
        "cpu",
        "--width",
        &size,
        "--height",
        &size,
        "--frames",
        &frames.to_string(),
        "--seeds",
        &seeds.to_string(),
        "--reference-spp",
        "4",
        "--auto-crops",
        "0",
    ]
    .map(String::from)
    .to_vec()
}

/// A small `render` on the interpreter.
fn render_args(size: u32) -> Vec<String> {
    let size = size.to_string();
    ["render", "--backend", "cpu", "--width", &size, "--height", &size, "--spp", "1"].map(String::from).to_vec()
}

fn with<S: AsRef<std::ffi::OsStr>>(mut args: Vec<std::ffi::OsString>, more: &[S]) -> Vec<std::ffi::OsString> {
    args.extend(more.iter().map(|s| s.as_ref().to_os_string()));
    args
}

fn os(args: Vec<String>) -> Vec<std::ffi::OsString> {
    args.into_iter().map(Into::into).collect()
}

/// A uniform image written as EXR.
fn write_exr(path: &Path, width: u32, height: u32, value: [f32; 3]) {
    RgbImage { width, height, pixels: vec![value; (width * height) as usize] }.write_exr(path).unwrap();
}

// 1. Paths need not be UTF-8: every command takes them, and the run record quotes them.
#[cfg(unix)]
#[test]
fn paths_that_are_not_utf8_are_taken_by_every_command() {
    use std::os::unix::ffi::OsStrExt;
    let dir = scratch("non-utf8");
    let scene_folder = std::ffi::OsStr::from_bytes(b"scene-\xff");
    let scene = cornell_box(&dir, scene_folder.to_str().unwrap_or("x"), |_| {});
    let scene = {
        let odd = dir.join(scene_folder);
        std::fs::rename(scene.parent().unwrap(), &odd).unwrap();
        odd.join("scene.json")
    };
    let out = dir.join(std::ffi::OsStr::from_bytes(b"out-\xfe"));
    let output = strata(&with(os(compare_args(8, 1, 2)), &[scene.as_os_str(), "--out".as_ref(), out.as_os_str()]));
    assert_succeeded(&output);
    let record: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).unwrap()).unwrap();
    let line = record["command_line"].as_str().unwrap();
    assert!(line.contains("$'") && line.contains("\\xff") && line.contains("\\xfe"), "{line}");
    let render_out = dir.join(std::ffi::OsStr::from_bytes(b"render-\xfd"));
    assert_succeeded(&strata(&with(
        os(render_args(8)),
        &[scene.as_os_str(), "--out".as_ref(), render_out.as_os_str()],
    )));
    // Named after the scene's folder, its bytes kept.
    let mut stem = scene_folder.to_os_string();
    stem.push(".exr");
    assert!(render_out.join(&stem).is_file(), "{:?}", files(&render_out));
    assert_eq!(files(&render_out).len(), 2, "{:?}", files(&render_out));
    let _ = std::fs::remove_dir_all(&dir);
}

/// `path` as one word of a POSIX shell script: single-quoted, each `'` in it written `'\''`
/// (a checkout's path may hold any character).
fn sh_word(path: &Path) -> String {
    format!("'{}'", path.display().to_string().replace('\'', r"'\''"))
}

#[test]
fn a_path_with_quotes_and_spaces_is_one_shell_word() {
    let path = Path::new("/no/such place/it's \"here\" $HOME");
    let output = Command::new("sh").args(["-c", &format!("printf %s {}", sh_word(path))]).output().unwrap();
    assert_eq!(String::from_utf8_lossy(&output.stdout), path.to_string_lossy());
}

/// Runs `script` (sh) in a new mount namespace where `mount` is a tmpfs of `kib` KiB,
/// or `None` (with the reason) where this machine cannot make one.
fn in_small_tmpfs(mount: &Path, kib: u64, script: &str) -> Option<String> {
    let full = format!("mount -t tmpfs -o size={kib}k tmpfs {} || exit 97\n{script}", sh_word(mount));
    let output = Command::new("unshare")
        .args(["-rm", "sh", "-c", &full])
        .env("RUST_BACKTRACE", "1")
        .env("XDG_RUNTIME_DIR", NO_DISPLAY)
        .output();
    match output {
        Ok(output) if output.status.code() != Some(97) => {
            Some(text(&output.stdout) + &text(&output.stderr) + &format!("\nstatus {:?}\n", output.status.code()))
        }
        Ok(output) => {
            eprintln!("SKIPPED: no tmpfs could be mounted in a user namespace: {}", text(&output.stderr));
            None
        }
        Err(error) => {
            eprintln!("SKIPPED: `unshare` cannot run here ({error}): the full-disk test needs a small tmpfs");
            None
        }
    }
}

// 2. A full disk: an error naming the file, and no file half-written (a 0-byte PNG was
// reported as written).
#[test]
fn a_full_disk_is_an_error_and_leaves_no_half_written_file() {
    let dir = scratch("full-disk");
    // The sizes of this render's EXR and PNG on a disk with room.
    let roomy = dir.join("roomy");
    assert_succeeded(&strata(&with(os(render_args(64)), &["--out".as_ref(), roomy.as_os_str()])));
    let size = |name: &str| std::fs::metadata(roomy.join(name)).unwrap().len();
    let (exr, png) = (size("default.exr"), size("default.png"));
    assert!(png > 4096, "the PNG must need more than the one spare page: {png} bytes");
    // A disk with room for the EXR and one page more: the PNG cannot fit.
    let kib = exr.div_ceil(4096) * 4 + 4;
    let mount = dir.join("tiny");
    std::fs::create_dir_all(&mount).unwrap();
    let script = format!(
        "{} render --backend cpu --width 64 --height 64 --spp 1 --out {}; echo \"exit $?\"; ls -la {}",
        sh_word(&binary()),
        sh_word(&mount),
        sh_word(&mount)
    );
    let Some(report) = in_small_tmpfs(&mount, kib, &script) else { return };
    assert!(report.contains("exit 1"), "the render must fail on a full disk:\n{report}");
    assert!(report.contains("error: ") && report.contains("default.png: cannot write"), "{report}");
    assert!(!report.contains("panicked"), "{report}");
    // The EXR is whole; no PNG and no temporary file is left.
    assert!(report.contains(&format!(" {exr} ")) && report.contains("default.exr"), "{report}");
    assert!(!report.contains("default.png\n") && !report.contains(".tmp-"), "{report}");

    // `metrics --map` likewise: its EXR map fits, its PNG does not.
    let image = roomy.join("default.exr");
    let reference = dir.join("grey.exr");
    write_exr(&reference, 64, 64, [0.25; 3]);
    let map = roomy.join("map.exr");
    assert_succeeded(&strata(&[
        "metrics".as_ref(),
        image.as_os_str(),
        reference.as_os_str(),
        "--map".as_ref(),
        map.as_os_str(),
    ]));
    let (map_exr, map_png) = (size("map.exr"), size("map.png"));
    assert!(map_png > 4096, "the map's PNG must need more than the one spare page: {map_png} bytes");
    let kib = map_exr.div_ceil(4096) * 4 + 4;
    let script = format!(
        "{bin} metrics {image} {reference} --map {map}; echo \"exit $?\"; ls -la {mount}",
        bin = sh_word(&binary()),
        image = sh_word(&image),
        reference = sh_word(&reference),
        map = sh_word(&mount.join("map.exr")),
        mount = sh_word(&mount)
    );
    let Some(report) = in_small_tmpfs(&mount, kib, &script) else { return };
    assert!(report.contains("exit 1") && report.contains("map.png: cannot write"), "{report}");
    assert!(!report.contains("map.png\n") && !report.contains(".tmp-"), "{report}");
    let _ = std::fs::remove_dir_all(&dir);
}

// 3. An output name taken by something that is not a regular file is left alone.
#[cfg(unix)]
#[test]
fn outputs_never_replace_devices_links_pipes_or_folders() {
    let dir = scratch("not-regular");
    let image = dir.join("image.exr");
    write_exr(&image, 4, 4, [0.5; 3]);
    let link = dir.join("full.exr");
    std::os::unix::fs::symlink("/dev/full", &link).unwrap();
    let output =
        strata(&["metrics".as_ref(), image.as_os_str(), image.as_os_str(), "--map".as_ref(), link.as_os_str()]);
    assert_refused(&output, &["full.exr", "not a regular file"]);
    assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
    assert!(!std::fs::metadata("/dev/full").unwrap().is_file(), "/dev/full was replaced");
    let pipe = dir.join("pipe.exr");
    assert!(Command::new("mkfifo").arg(&pipe).status().unwrap().success());
    let output =
        strata(&["metrics".as_ref(), image.as_os_str(), image.as_os_str(), "--map".as_ref(), pipe.as_os_str()]);
    assert_refused(&output, &["pipe.exr", "named pipe"]);
    // A folder where `render` would write its PNG.
    let out = dir.join("render");
    std::fs::create_dir_all(out.join("default.png")).unwrap();
    let output = strata(&with(os(render_args(4)), &["--out".as_ref(), out.as_os_str()]));
    assert_refused(&output, &["default.png", "a folder"]);
    assert!(out.join("default.png").is_dir());
    // A pipe under the name of a plot's last file: refused before any file is written.
    let errors = dir.join("errors.csv");
    std::fs::write(&errors, csv(&[("strata", 1, 1, 0.5), ("restir", 1, 1, 1.0)])).unwrap();
    assert!(Command::new("mkfifo").arg(dir.join("p_ratio.png")).status().unwrap().success());
    let output = strata(&["plot".as_ref(), errors.as_os_str(), "--out".as_ref(), dir.join("p").as_os_str()]);
    assert_refused(&output, &["p_ratio.png", "named pipe"]);
    for written in ["p.svg", "p.png", "p_ratio.svg"] {
        assert!(!dir.join(written).exists(), "{written} was written before the refusal");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

// 4. `metrics --map` writes an EXR and a PNG beside it, never over each other or an input.
#[test]
fn the_error_map_never_overwrites_itself_or_an_input() {
    let dir = scratch("map-names");
    let (image, reference) = (dir.join("image.exr"), dir.join("reference.exr"));
    write_exr(&image, 4, 4, [0.5; 3]);
    write_exr(&reference, 4, 4, [0.25; 3]);
    let before = std::fs::read(&image).unwrap();
    let metrics = |map: &Path| {
        strata(&["metrics".as_ref(), image.as_os_str(), reference.as_os_str(), "--map".as_ref(), map.as_os_str()])
    };
    assert_refused(&metrics(&dir.join("map.png")), &["--map", "map.png", ".exr"]);
    assert!(!dir.join("map.png").exists());
    assert_refused(&metrics(&image), &["--map", "would overwrite the image"]);
    assert_refused(&metrics(&dir.join("./reference.exr")), &["--map", "would overwrite the reference"]);
    assert_eq!(std::fs::read(&image).unwrap(), before);
    let output = metrics(&dir.join("map.exr"));
    assert_succeeded(&output);
    assert!(RgbImage::read_exr(&dir.join("map.exr")).is_ok(), "the map is an EXR");
    assert!(std::fs::read(dir.join("map.png")).unwrap().starts_with(b"\x89PNG"), "the picture is a PNG");
    let _ = std::fs::remove_dir_all(&dir);
}

// 5. Radiance that overflows single precision: refused, never scored as black frames.
#[test]
fn radiance_that_overflows_is_refused_before_anything_is_scored() {
    let dir = scratch("overflow");
    let scene = cornell_box(&dir, "bright", |scene| {
        scene["environment"] = serde_json::json!({"file": "sky.exr", "scale": 1.0});
    });
    write_exr(&scene.parent().unwrap().join("sky.exr"), 8, 4, [3e38; 3]);
    let out = dir.join("out");
    let output = strata(&with(os(compare_args(8, 2, 2)), &[scene.as_os_str(), "--out".as_ref(), out.as_os_str()]));
    assert_refused(&output, &[]);
    assert!(!text(&output.stdout).contains("÷ restir"), "a summary was printed:\n{}", text(&output.stdout));
    assert!(!out.join("errors.csv").exists() && !out.join("summary.txt").exists());
    let output = strata(&with(os(render_args(8)), &[scene.as_os_str(), "--out".as_ref(), out.as_os_str()]));
    assert_refused(&output, &[]);
    // An emitter likewise.
    let scene = cornell_box(&dir, "bright-light", |scene| {
        for shape in scene["shapes"].as_array_mut().unwrap() {
            if shape.get("emitter").is_some() {
                shape["emitter"]["radiance"] = serde_json::json!([3e38, 3e38, 3e38]);
            }
        }
    });
    let output = strata(&with(os(compare_args(8, 2, 2)), &[scene.as_os_str(), "--out".as_ref(), out.as_os_str()]));
    assert_refused(&output, &[]);
    assert!(!out.join("errors.csv").exists());
    // The largest radiance accepted is scored: every image and error map stays finite.
    let scene = cornell_box(&dir, "brightest-light", |scene| {
        for shape in scene["shapes"].as_array_mut().unwrap() {
            if shape.get("emitter").is_some() {
                let most = f64::from(strata_render::scene::MAX_RADIANCE);
                shape["emitter"]["radiance"] = serde_json::json!([most, most, most]);
            }
        }
    });
    let output = strata(&with(os(compare_args(8, 2, 2)), &[scene.as_os_str(), "--out".as_ref(), out.as_os_str()]));
    assert_succeeded(&output);
    assert!(out.join("errors.csv").exists() && out.join("report.html").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

// 6. A camera that sees nothing: no RelMSE 0, no `NaN ± inf`, no black image written.
#[test]
fn a_camera_that_sees_no_light_is_refused() {
    let dir = scratch("blind");
    // Turned around, out of the open side of the box into an unlit world.
    let scene = cornell_box(&dir, "blind", |scene| {
        scene["camera"]["target"] = serde_json::json!([278, 273, -801]);
    });
    let out = dir.join("out");
    let output = strata(&with(os(compare_args(8, 2, 2)), &[scene.as_os_str(), "--out".as_ref(), out.as_os_str()]));
    assert_refused(&output, &["black everywhere"]);
    assert!(!text(&output.stdout).contains("NaN") && !out.join("errors.csv").exists());
    // `render` writes what it rendered (a black image can be what was asked for) and
    // says so in a warning.
    let output = strata(&with(os(render_args(8)), &[scene.as_os_str(), "--out".as_ref(), out.as_os_str()]));
    assert_succeeded(&output);
    assert!(
        text(&output.stderr).contains("warning: the rendered image is black everywhere"),
        "{}",
        text(&output.stderr)
    );
    // A dolly that leaves the box behind: the later frames' references are black.
    let scene = cornell_box(&dir, "away", |_| {});
    let output = strata(&with(
        os(compare_args(8, 3, 2)),
        &[scene.as_os_str(), "--camera-path".as_ref(), "dolly:-1e6".as_ref(), "--out".as_ref(), out.as_os_str()],
    ));
    assert_refused(&output, &["black everywhere"]);
    let _ = std::fs::remove_dir_all(&dir);
}

// 7. An exposure that would write black or white pictures.
#[test]
fn exposures_that_are_not_finite_and_positive_are_refused() {
    let dir = scratch("exposure");
    for value in ["NaN", "-1", "0", "inf", "1e39"] {
        let out = dir.join(value);
        let exposure = format!("--exposure={value}");
        let output = strata(&with(os(render_args(4)), &[exposure.as_str(), "--out", out.to_str().unwrap()]));
        assert_refused_with(&output, 2, &["--exposure", "finite and positive"]);
        let output = strata(&with(os(compare_args(4, 1, 2)), &[exposure.as_str(), "--out", out.to_str().unwrap()]));
        assert_refused_with(&output, 2, &["--exposure"]);
        assert!(files(&out).is_empty(), "{value}: {:?}", files(&out));
    }
    // An exposure so small that the preview is black: written, and said.
    let out = dir.join("tiny");
    let output = strata(&with(os(render_args(4)), &["--exposure=1e-40", "--out", out.to_str().unwrap()]));
    assert_succeeded(&output);
    let stderr = text(&output.stderr);
    assert!(stderr.contains("warning:") && stderr.contains("--exposure 1e-40") && stderr.contains("black"), "{stderr}");
    let _ = std::fs::remove_dir_all(&dir);
}

// 8. A reference with negative pixels gives negative or huge RelMSE: refused.
#[test]
fn references_with_negative_pixels_are_refused() {
    let dir = scratch("negative");
    let (image, reference) = (dir.join("image.exr"), dir.join("reference.exr"));
    write_exr(&image, 8, 8, [0.5; 3]);
    let mut pixels = vec![[0.25f32; 3]; 64];
    pixels[8 * 2 + 3] = [0.25, -0.5, 0.25];
    RgbImage { width: 8, height: 8, pixels }.write_exr(&reference).unwrap();
    let output = strata(&["metrics".as_ref(), image.as_os_str(), reference.as_os_str()]);
    assert_refused(&output, &["reference.exr", "pixel (3, 2)", "negative"]);
    assert!(!text(&output.stdout).contains("relmse"), "{}", text(&output.stdout));
    let out = dir.join("out");
    let output = strata(&with(
        os(compare_args(8, 1, 2)),
        &["--reference".as_ref(), reference.as_os_str(), "--out".as_ref(), out.as_os_str()],
    ));
    assert_refused(&output, &["reference.exr", "pixel (3, 2)"]);
    assert!(!out.join("errors.csv").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

// 9. A method named twice.
#[test]
fn a_method_named_twice_is_refused() {
    let dir = scratch("twice");
    let output = strata(&with(
        os(compare_args(4, 1, 2)),
        &["--methods", "strata,restir,strata", "--out", dir.to_str().unwrap()],
    ));
    assert_refused(&output, &["--methods", "`strata` is named twice"]);
    assert!(files(&dir).is_empty());
    let output = strata(&with(
        os(compare_args(4, 1, 2)),
        &["--crop", "0,0,2,2", "--crop", "0,0,2,2", "--out", dir.to_str().unwrap()],
    ));
    assert_refused(&output, &["--crop 0,0,2,2", "twice"]);
    assert!(files(&dir).is_empty());
    // The same CSV twice (under two spellings), and one label for two runs.
    let (a, b) = (dir.join("a.csv"), dir.join("b.csv"));
    let rows = [("strata", 1, 1, 0.5), ("restir", 1, 1, 1.0)];
    std::fs::write(&a, csv(&rows)).unwrap();
    std::fs::write(&b, csv(&rows)).unwrap();
    let again = dir.join(".").join("a.csv");
    let output =
        strata(&["plot".as_ref(), a.as_os_str(), again.as_os_str(), "--out".as_ref(), dir.join("p").as_os_str()]);
    assert_refused(&output, &["a.csv", "the same CSV"]);
    let output = strata(&[
        "plot".as_ref(),
        a.as_os_str(),
        b.as_os_str(),
        "--label".as_ref(),
        "x".as_ref(),
        "--label".as_ref(),
        "x".as_ref(),
        "--out".as_ref(),
        dir.join("p").as_os_str(),
    ]);
    assert_refused(&output, &["--label `x`", "twice"]);
    assert_eq!(files(&dir).len(), 2, "only the two CSVs: {:?}", files(&dir));
    let _ = std::fs::remove_dir_all(&dir);
}

/// A CSV of `rows` (method, frame, seed, relmse) in the format `compare` writes.
fn csv(rows: &[(&str, u64, u32, f64)]) -> String {
    let mut text = String::from("method,frame,seed,relmse,prelmse,mse,relmse_luminance\n");
    for (method, frame, seed, relmse) in rows {
        text += &format!("{method},{frame},{seed},{relmse},{relmse},{relmse},{relmse}\n");
    }
    text
}

/// `strata plot CSV --out STEM` with a deadline: a hang is a failure, not a stuck suite.
fn plot_within(csv_text: &str, dir: &Path, name: &str, deadline: std::time::Duration) -> Output {
    let file = dir.join(format!("{name}.csv"));
    std::fs::write(&file, csv_text).unwrap();
    let stem = dir.join(name);
    strata_within(&["plot".as_ref(), file.as_os_str(), "--out".as_ref(), stem.as_os_str()], deadline)
}

/// Runs `strata ARGS`, failing the test if it still runs after `deadline` (a hang is a
/// defect; this is no timing test).
fn strata_within(args: &[&std::ffi::OsStr], deadline: std::time::Duration) -> Output {
    let mut child =
        command(args).stdout(std::process::Stdio::piped()).stderr(std::process::Stdio::piped()).spawn().unwrap();
    let started = std::time::Instant::now();
    while child.try_wait().unwrap().is_none() {
        if started.elapsed() > deadline {
            let _ = child.kill();
            panic!("`strata {:?}` still ran after {deadline:?}", args);
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    child.wait_with_output().unwrap()
}

// 10. The work of `plot` follows the rows, not the largest frame number.
#[test]
fn plot_time_does_not_grow_with_the_frame_number() {
    let dir = scratch("plot-frames");
    let rows =
        [("strata", 1, 1, 0.5), ("strata", 4294967295, 1, 0.25), ("restir", 1, 1, 1.0), ("restir", 4294967295, 1, 0.5)];
    let output = plot_within(&csv(&rows), &dir, "far", std::time::Duration::from_secs(60));
    assert_succeeded(&output);
    assert!(!text(&output.stdout).contains("NaN") && !text(&output.stdout).contains("inf"), "{}", text(&output.stdout));
    let _ = std::fs::remove_dir_all(&dir);
}

// 11. CSVs that cannot give a number: refused, naming the line.
#[test]
fn plot_refuses_csvs_whose_numbers_cannot_be_computed() {
    let dir = scratch("plot-csv");
    let second = std::time::Duration::from_secs(60);
    let cases: [(&str, String, &[&str]); 4] = [
        ("header-only", csv(&[]), &["header-only.csv", "no measurements"]),
        (
            "subnormal",
            csv(&[("strata", 1, 1, 0.5), ("restir", 1, 1, 1e-320)]),
            &["subnormal.csv", "line 3", "smallest normal number"],
        ),
        (
            "duplicate",
            csv(&[("strata", 1, 1, 0.5), ("restir", 1, 1, 1.0), ("strata", 1, 1, 0.7)]),
            &["duplicate.csv", "line 4", "first on line 2"],
        ),
        (
            "missing",
            csv(&[("strata", 1, 1, 0.5), ("strata", 1, 2, 0.5), ("restir", 1, 1, 1.0)]),
            &["missing.csv", "restir has no row for frame 1, seed 2"],
        ),
    ];
    for (name, text_of_csv, names) in cases {
        let output = plot_within(&text_of_csv, &dir, name, second);
        assert_refused(&output, names);
        assert!(!dir.join(format!("{name}.svg")).exists(), "{name}: a plot was written");
    }
    // A baseline of error 0 (an image equal to its reference): no ratio, and it says so.
    let output = plot_within(&csv(&[("strata", 1, 1, 0.5), ("restir", 1, 1, 0.0)]), &dir, "zero", second);
    assert_succeeded(&output);
    let stdout = text(&output.stdout);
    assert!(stdout.contains("cannot be computed (restir's RelMSE is 0") && !stdout.contains("inf"), "{stdout}");
    // One seed: a ratio without an interval says so, never `± inf`.
    let output = plot_within(&csv(&[("strata", 1, 1, 0.5), ("restir", 1, 1, 1.0)]), &dir, "one-seed", second);
    assert_succeeded(&output);
    let stdout = text(&output.stdout);
    assert!(
        stdout.contains("0.5000 (1 seed: no interval)") && !stdout.contains("inf") && !stdout.contains("NaN"),
        "{stdout}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

// 12. Scene JSON: values the renderer does not implement and text after the scene.
#[test]
fn scene_fields_the_renderer_does_not_implement_are_refused_by_name() {
    let dir = scratch("scene-json");
    type Edit = fn(&mut serde_json::Value);
    let cases: [(&str, Edit, &[&str]); 6] = [
        ("hide", |s| s["integrator"]["hide_emitters"] = true.into(), &["integrator.hide_emitters", "true"]),
        (
            "same-id",
            |s| {
                let id = s["shapes"][0]["id"].clone();
                s["shapes"][1]["id"] = id;
            },
            &["shapes[1].id", "shapes[0] has this id"],
        ),
        ("volpath", |s| s["integrator"]["type"] = "volpath".into(), &["integrator.type", "`volpath`"]),
        ("normals", |s| s["shapes"][0]["normals"] = "vertex".into(), &["shapes[0].normals", "`vertex`"]),
        (
            "checker-field",
            |s| {
                let first = s["materials"].as_object().unwrap().keys().next().unwrap().clone();
                s["materials"][&first]["reflectance"] = serde_json::json!({
                    "checkerboard": {"color0": [0.1, 0.1, 0.1], "color1": [0.5, 0.5, 0.5], "uv_scale": [4, 4]},
                    "scale": 2
                });
            },
            &["unknown field `scale`", "expected one of `checkerboard`"],
        ),
        ("extra", |s| s["camera"]["aperture"] = 0.5.into(), &["camera", "unknown field `aperture`"]),
    ];
    // A key given twice (serde_json's values cannot hold one: edited as text).
    let scene = cornell_box(&dir, "twice", |s| {
        let first = s["materials"].as_object().unwrap().keys().next().unwrap().clone();
        s["materials"][&first]["reflectance"] = serde_json::json!({"texture": "a.png", "srgb": true});
    });
    let original = std::fs::read_to_string(&scene).unwrap();
    for (from, to, names) in [
        (
            "\"texture\": \"a.png\"",
            "\"texture\": \"a.png\", \"texture\": \"b.png\"",
            ["scene.json", "duplicate field `texture`"],
        ),
        (
            "\"materials\": {",
            "\"materials\": {\"white\": {\"type\": \"black\"},",
            ["scene.json", "`white` is defined twice"],
        ),
    ] {
        let twice = original.replacen(from, to, 1);
        assert_ne!(twice, original, "{from}");
        std::fs::write(&scene, twice).unwrap();
        let output =
            strata(&with(os(render_args(4)), &[scene.as_os_str(), "--out".as_ref(), dir.join("out").as_os_str()]));
        assert_refused(&output, &names);
    }
    for (name, edit, names) in cases {
        let scene = cornell_box(&dir, name, edit);
        let output =
            strata(&with(os(render_args(4)), &[scene.as_os_str(), "--out".as_ref(), dir.join("out").as_os_str()]));
        assert_refused(&output, &[&["scene.json"][..], names].concat());
    }
    let scene = cornell_box(&dir, "trailing", |_| {});
    let mut contents = std::fs::read_to_string(&scene).unwrap();
    contents += "\n{\"name\": \"a second scene\"}";
    std::fs::write(&scene, contents).unwrap();
    let output = strata(&with(os(render_args(4)), &[scene.as_os_str(), "--out".as_ref(), dir.join("out").as_os_str()]));
    assert_refused(&output, &["scene.json", "trailing"]);
    assert!(files(&dir.join("out")).is_empty());
    let _ = std::fs::remove_dir_all(&dir);
}

/// An OBJ room: a floor and a light above it (`Ke`), with `extra` OBJ lines and the MTL
/// library `mtl` (None: the library is not written).
fn obj_scene(dir: &Path, name: &str, extra: &str, mtl: Option<&str>) -> PathBuf {
    let obj = format!(
        "mtllib room.mtl\nv -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nv -0.2 1 -0.2\nv 0.2 1 -0.2\nv 0.2 1 0.2\nv -0.2 1 0.2\n\
         o floor\nusemtl floor\nf 1 4 3 2\no light\nusemtl lamp\nf 5 6 7 8\n{extra}"
    );
    let folder = dir.join(name);
    std::fs::create_dir_all(&folder).unwrap();
    std::fs::write(folder.join("room.obj"), obj).unwrap();
    if let Some(mtl) = mtl {
        std::fs::write(folder.join("room.mtl"), mtl).unwrap();
    }
    folder.join("room.obj")
}

const ROOM_MTL: &str = "newmtl floor\nKd 0.5 0.5 0.5\nnewmtl lamp\nKd 0 0 0\nKe 5 5 5\n";

// 13. OBJ faces of fewer than 3 vertices and unknown materials: a warning naming file
// and line, said once, kept in the run record.
#[test]
fn obj_short_faces_and_unknown_materials_are_warned_about_once() {
    let dir = scratch("obj-warnings");
    // Two short faces and one without a vertex (which tobj refuses whole: emptied first).
    let extra = "o bits\nusemtl nosuch\nf 1 2\nf 2 3\nf\nf 1 2 3\nusemtl nosuch\nf 3 4 1\n";
    let scene = obj_scene(&dir, "room", extra, Some(ROOM_MTL));
    let out = dir.join("out");
    let output = strata(&with(os(compare_args(8, 1, 2)), &[scene.as_os_str(), "--out".as_ref(), out.as_os_str()]));
    assert_succeeded(&output);
    let stderr = text(&output.stderr);
    let warnings: Vec<&str> = stderr.lines().filter(|l| l.starts_with("warning:")).collect();
    assert_eq!(warnings.len(), 2, "{stderr}");
    assert!(
        warnings.iter().any(|w| w.contains("room.obj: line 18 (and 2 more): 3 faces with fewer than 3")),
        "{stderr}"
    );
    assert!(warnings.iter().any(|w| w.contains("room.obj: line 17 (and 1 more): `usemtl nosuch`")), "{stderr}");
    let record: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).unwrap()).unwrap();
    assert_eq!(record["warnings"].as_array().map(Vec::len), Some(2), "{record}");
    assert!(std::fs::read_to_string(out.join("summary.txt")).unwrap().contains("scene warnings (2)"));
    // A missing library is one warning, not one per material it would have defined.
    // (Without its library the lamp has no `Ke`: the scene has no light, which is refused
    // after the one warning.)
    let scene = obj_scene(&dir, "no-library", "", None);
    let output = strata(&with(os(render_args(8)), &[scene.as_os_str(), "--out".as_ref(), out.as_os_str()]));
    assert_refused(&output, &["has no light"]);
    let stderr = text(&output.stderr);
    let warnings: Vec<&str> = stderr.lines().filter(|l| l.starts_with("warning:")).collect();
    assert_eq!(warnings.len(), 1, "{stderr}");
    assert!(warnings[0].contains("material library") && warnings[0].contains("room.mtl"), "{stderr}");
    assert!(warnings[0].contains("room.obj: line "), "the warning names the `mtllib` line: {stderr}");
    // Indented statements and a `usemtl` before its library: what tobj does is what is said.
    let scene = obj_scene(&dir, "indented", "  usemtl floor\nf 1 2 3\n", Some(ROOM_MTL));
    let output = strata(&with(os(render_args(8)), &[scene.as_os_str(), "--out".as_ref(), out.as_os_str()]));
    assert_succeeded(&output);
    assert!(!text(&output.stderr).contains("warning:"), "an indented usemtl is a usemtl:\n{}", text(&output.stderr));
    let folder = dir.join("early");
    std::fs::create_dir_all(&folder).unwrap();
    std::fs::write(folder.join("room.mtl"), ROOM_MTL).unwrap();
    let room = std::fs::read_to_string(dir.join("room/room.obj")).unwrap();
    let early = format!("usemtl floor\nf 1 2 3\n{room}");
    std::fs::write(folder.join("room.obj"), early).unwrap();
    let output =
        strata(&with(os(render_args(8)), &[folder.join("room.obj").as_os_str(), "--out".as_ref(), out.as_os_str()]));
    let stderr = text(&output.stderr);
    assert!(
        stderr.contains("room.obj: line 1: `usemtl floor` names no material of the libraries loaded before it"),
        "{stderr}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

// 14. A reflectance above 1 creates energy.
#[test]
fn reflectances_above_one_are_refused() {
    let dir = scratch("reflectance");
    let scene = cornell_box(&dir, "json", |scene| {
        let first = scene["materials"].as_object().unwrap().keys().next().unwrap().clone();
        scene["materials"][&first]["reflectance"] = serde_json::json!([2, 2, 2]);
    });
    let out = dir.join("out");
    let output = strata(&with(os(render_args(4)), &[scene.as_os_str(), "--out".as_ref(), out.as_os_str()]));
    assert_refused(&output, &["scene.json", "reflectance", "[0, 1]"]);
    let scene = obj_scene(&dir, "mtl", "", Some(&ROOM_MTL.replace("Kd 0.5 0.5 0.5", "Kd 5 5 5")));
    let output = strata(&with(os(render_args(4)), &[scene.as_os_str(), "--out".as_ref(), out.as_os_str()]));
    assert_refused(&output, &["room.mtl", "Kd", "[0, 1]"]);
    // The fractions (opacity, transparency, the PBR extension's metallic and roughness),
    // read whatever the material becomes.
    for (index, statement) in ["Tr 2", "d 1.5", "Pm 2", "Pr nan", "Pr -0.5"].iter().enumerate() {
        let mtl = ROOM_MTL.replace("Kd 0.5 0.5 0.5", &format!("Kd 0.5 0.5 0.5\n{statement}"));
        let scene = obj_scene(&dir, &format!("fraction-{index}"), "", Some(&mtl));
        let output = strata(&with(os(render_args(4)), &[scene.as_os_str(), "--out".as_ref(), out.as_os_str()]));
        let keyword = statement.split(' ').next().unwrap();
        assert_refused(&output, &["room.mtl", keyword]);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A glTF document of one textured triangle seen by a camera, with `edit` applied.
fn gltf_scene(dir: &Path, name: &str, edit: impl FnOnce(&mut serde_json::Value)) -> PathBuf {
    let folder = dir.join(name);
    std::fs::create_dir_all(&folder).unwrap();
    let positions: [[f32; 3]; 3] = [[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [0.0, 1.0, 0.0]];
    let uvs: [[f32; 2]; 3] = [[0.0, 0.0], [1.0, 0.0], [0.5, 1.0]];
    let mut bytes: Vec<u8> = positions.iter().flatten().flat_map(|c| c.to_le_bytes()).collect();
    bytes.extend(uvs.iter().flatten().flat_map(|c| c.to_le_bytes()));
    std::fs::write(folder.join("triangle.bin"), &bytes).unwrap();
    let png =
        strata_render::rgb_image::encode_png(&[200, 100, 50, 255], 1, 1, image::ExtendedColorType::Rgba8).unwrap();
    std::fs::write(folder.join("texture.png"), png).unwrap();
    let mut document = serde_json::json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0, 1]}],
        "nodes": [
            {"mesh": 0, "rotation": [0, 0, 0, 1]},
            {"camera": 0, "translation": [0, 0, 3]}
        ],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.01}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "material": 0}]}],
        "materials": [{
            "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0},
            "emissiveFactor": [1, 1, 1]
        }],
        "textures": [{"source": 0}],
        "images": [{"uri": "texture.png"}],
        "buffers": [{"uri": "triangle.bin", "byteLength": 60}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 24}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [-1, -1, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"}
        ]
    });
    edit(&mut document);
    let file = folder.join("scene.gltf");
    std::fs::write(&file, serde_json::to_string_pretty(&document).unwrap()).unwrap();
    file
}

// 15. glTF: another version, a rotation that is no rotation, a texture without the
// coordinates it names.
#[test]
fn gltf_documents_that_say_something_else_are_refused() {
    let dir = scratch("gltf");
    let out = dir.join("out");
    let render =
        |scene: &Path| strata(&with(os(render_args(4)), &[scene.as_os_str(), "--out".as_ref(), out.as_os_str()]));
    assert_succeeded(&render(&gltf_scene(&dir, "good", |_| {})));
    type Edit = fn(&mut serde_json::Value);
    let cases: [(&str, Edit, &[&str]); 6] = [
        ("version", |d| d["asset"]["version"] = "1.0".into(), &["asset.version", "`1.0`"]),
        ("version-text", |d| d["asset"]["version"] = "2.0beta".into(), &["asset.version", "`2.0beta`"]),
        ("min-version", |d| d["asset"]["minVersion"] = "2.5".into(), &["asset.minVersion", "2.5"]),
        (
            "alpha",
            |d| d["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"] = serde_json::json!([0.5, 0.5, 0.5, 2]),
            &["materials[0]", "[0, 1]"],
        ),
        (
            "quaternion",
            |d| d["nodes"][0]["rotation"] = serde_json::json!([0, 0, 0, 0]),
            &["nodes[0].rotation", "unit quaternion"],
        ),
        (
            "texcoord",
            |d| {
                d["meshes"][0]["primitives"][0]["attributes"] = serde_json::json!({"POSITION": 0});
            },
            &["meshes[0].primitives[0]", "TEXCOORD_0"],
        ),
    ];
    for (name, edit, names) in cases {
        let output = render(&gltf_scene(&dir, name, edit));
        assert_refused(&output, &[&["scene.gltf"][..], names].concat());
    }
    let _ = std::fs::remove_dir_all(&dir);
}

// 16. A generated image with no objects.
#[test]
fn a_histogram_of_no_objects_is_refused() {
    let output = strata(&["histogram", "--backend", "cpu", "--objects", "0", "--width", "32", "--height", "32"]);
    assert_refused(&output, &["--objects 0"]);
    // Many objects: ids wrap around the id range instead of overflowing (it panicked).
    let output = strata(&["histogram", "--backend", "cpu", "--objects", "600000", "--width", "32", "--height", "32"]);
    assert_succeeded(&output);
}

// 16b. An image too large for the device: the size flags and the limit are named, before
// the 2 GiB of candidates are generated (it named the internal buffer `candidates`, 44 s
// later, after generating them).
#[test]
fn a_histogram_too_large_for_the_device_names_the_size_flags_and_the_limit() {
    let started = std::time::Instant::now();
    let output = strata(&["histogram", "--backend", "cpu", "--width", "16384", "--height", "16384"]);
    // The interpreter binds at most 1 GiB: 89478485 cluster spans of 12 bytes, the
    // largest per-pixel buffer.
    assert_refused(&output, &["--width 16384 --height 16384", "1073741824 bytes", "at most 89478485 pixels"]);
    assert!(started.elapsed().as_secs() < 20, "refused only after {:?}", started.elapsed());
}

// 17. Messages that name the wrong thing; inputs that never end.
#[test]
fn messages_name_what_the_user_gave() {
    let dir = scratch("messages");
    let scene = obj_scene(&dir, "nan", "", Some(&ROOM_MTL.replace("Kd 0.5 0.5 0.5", "Kd 0.5 0.5 0.5\nNi nan")));
    let output = strata(&with(os(render_args(4)), &[scene.as_os_str(), "--out".as_ref(), dir.join("out").as_os_str()]));
    assert_refused(&output, &["room.mtl", "Ni", "positive"]);
    assert!(!text(&output.stderr).contains("0.0000"), "{}", text(&output.stderr));
    for flag in ["--width", "--height"] {
        let output = strata(&[
            "render",
            "--backend",
            "cpu",
            flag,
            "100000",
            "--spp",
            "1",
            "--out",
            dir.join("out").to_str().unwrap(),
        ]);
        assert_refused(&output, &[&format!("{flag} 100000"), "16384"]);
    }
    #[cfg(unix)]
    {
        // A scene "file" that is a device is refused at once, not read to the input limit
        // (1 GiB of /dev/zero took seconds and a gigabyte first).
        let endless = dir.join("endless.json");
        std::os::unix::fs::symlink("/dev/zero", &endless).unwrap();
        let started = std::time::Instant::now();
        let output = strata(&["render".as_ref(), "--backend".as_ref(), "cpu".as_ref(), endless.as_os_str()]);
        assert_refused(&output, &["endless.json", "is a device, not a regular file"]);
        assert!(started.elapsed() < std::time::Duration::from_secs(10), "refused after {:?}", started.elapsed());
        // A named pipe nobody writes to is read as empty at once (a plain open waited for a
        // writer forever), as a scene, an image and a CSV.
        let pipe = dir.join("pipe.exr");
        let made = Command::new("mkfifo").arg(&pipe).status().is_ok_and(|s| s.success());
        assert!(made, "mkfifo");
        let reference = dir.join("reference.exr");
        write_exr(&reference, 4, 4, [0.5; 3]);
        let minute = std::time::Duration::from_secs(60);
        let output = strata_within(&["metrics".as_ref(), pipe.as_os_str(), reference.as_os_str()], minute);
        assert_refused(&output, &["pipe.exr"]);
        let output =
            strata_within(&["render".as_ref(), "--backend".as_ref(), "cpu".as_ref(), pipe.as_os_str()], minute);
        assert_refused(&output, &["pipe.exr"]);
        let output = strata_within(&["plot".as_ref(), pipe.as_os_str()], minute);
        assert_refused(&output, &["pipe.exr"]);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

// Across classes: nothing printed or written says NaN or inf, with one seed too.
#[test]
fn no_summary_report_or_record_says_nan_or_inf() {
    let dir = scratch("no-nan");
    let out = dir.join("out");
    let output = strata(&with(os(compare_args(8, 2, 1)), &["--out".as_ref(), out.as_os_str()]));
    assert_succeeded(&output);
    let stdout = text(&output.stdout);
    for (name, contents) in [
        ("stdout", stdout.clone()),
        ("summary.txt", std::fs::read_to_string(out.join("summary.txt")).unwrap()),
        ("run.json", std::fs::read_to_string(out.join("run.json")).unwrap()),
        ("report.html", std::fs::read_to_string(out.join("report.html")).unwrap()),
    ] {
        for word in ["NaN", "inf"] {
            let found = contents.split(|c: char| !c.is_alphanumeric()).any(|w| w == word);
            assert!(!found, "{name} says `{word}`:\n{contents}");
        }
    }
    assert!(stdout.contains("(1 seed: no interval)"), "{stdout}");
    // serde_json writes a NaN as null: every time in the record is a number.
    let record: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).unwrap()).unwrap();
    assert!(record["seconds"].is_f64(), "{record}");
    for time in record["frame_ms"].as_array().unwrap() {
        assert!(time["frame_ms"].is_f64(), "{record}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

// 2 (a variant that needs no privileges): a file-size limit (RLIMIT_FSIZE, `ulimit -f`)
// that the plot's SVG fits and its PNG does not; and standard output on a full device.
#[cfg(unix)]
#[test]
fn a_write_cut_short_by_a_size_limit_is_an_error_and_leaves_no_file() {
    let dir = scratch("size-limit");
    let rows = [("strata", 1, 1, 0.5), ("restir", 1, 1, 1.0), ("strata", 2, 1, 0.4), ("restir", 2, 1, 0.9)];
    let file = dir.join("errors.csv");
    std::fs::write(&file, csv(&rows)).unwrap();
    assert_succeeded(&strata(&["plot".as_ref(), file.as_os_str(), "--out".as_ref(), dir.join("roomy").as_os_str()]));
    let size = |name: &str| std::fs::metadata(dir.join(name)).unwrap().len();
    let (svg, png) = (size("roomy.svg"), size("roomy.png"));
    assert!(svg + 2048 < png, "the PNG ({png} bytes) must be larger than the SVG ({svg} bytes)");
    // `ulimit -f` counts 512-byte blocks in dash (1024 in bash): a limit between the sizes.
    let blocks = (svg + 1024) / 512;
    let limited = dir.join("limited");
    let script =
        format!("ulimit -f {blocks}; exec {} plot {} --out {}", sh_word(&binary()), sh_word(&file), sh_word(&limited));
    let output = Command::new("sh").args(["-c", &script]).env("RUST_BACKTRACE", "1").output().unwrap();
    assert_refused(&output, &["limited.png", "cannot write"]);
    let left: Vec<String> =
        files(&dir).iter().map(|(p, _)| p.file_name().unwrap().to_string_lossy().into_owned()).collect();
    // The plot's files are one set: the SVG that fitted is not left without its PNG.
    assert!(!left.iter().any(|n| n.starts_with("limited") || n.contains(".tmp-")), "{left:?}");
    // Standard output on a full device: one line, no panic.
    let script = format!(
        "exec {} plot {} --out {} > /dev/full",
        sh_word(&binary()),
        sh_word(&file),
        sh_word(&dir.join("again"))
    );
    let output = Command::new("sh").args(["-c", &script]).env("RUST_BACKTRACE", "1").output().unwrap();
    assert_refused(&output, &["standard out", "cannot write"]);
    let _ = std::fs::remove_dir_all(&dir);
}

// 4 (another variant): an output never replaces a file the run read, whatever the names.
#[test]
fn an_output_never_replaces_an_input_of_the_run() {
    let dir = scratch("input-output");
    // The render of studio/scene.json is named studio.exr: the scene's environment map.
    let scene = cornell_box(&dir, "studio", |scene| {
        scene["environment"] = serde_json::json!({"file": "studio.exr", "scale": 1.0});
    });
    let folder = scene.parent().unwrap().to_path_buf();
    write_exr(&folder.join("studio.exr"), 8, 4, [0.5; 3]);
    let before = std::fs::read(folder.join("studio.exr")).unwrap();
    let output = strata(&with(os(render_args(4)), &[scene.as_os_str(), "--out".as_ref(), folder.as_os_str()]));
    assert_refused(&output, &["studio.exr", "input of this run"]);
    assert_eq!(std::fs::read(folder.join("studio.exr")).unwrap(), before);
    // compare into the scene's own folder, the scene named like the run's record: refused
    // before the folder is touched (it removed the scene as an earlier run's run.json).
    let record = folder.join("run.json");
    std::fs::copy(&scene, &record).unwrap();
    let scene_text = std::fs::read(&record).unwrap();
    let output = strata(&with(os(compare_args(4, 1, 2)), &[record.as_os_str(), "--out".as_ref(), folder.as_os_str()]));
    assert_refused(&output, &["run.json", "input of this run"]);
    assert_eq!(std::fs::read(&record).unwrap(), scene_text);
    // (Left there, that copy is a file no run recorded under an output's name: the next
    // compare would refuse it by name, and never remove it.)
    std::fs::remove_file(&record).unwrap();
    // A camera path file named like the summary, likewise.
    let path_file = folder.join("summary.txt");
    let keys = r#"{"keyframes": [{"frame": 0, "origin": [0, 1, 3.5], "target": [0, 1, 0]},
        {"frame": 1, "origin": [0.1, 1, 3.5], "target": [0, 1, 0]}]}"#;
    std::fs::write(&path_file, keys).unwrap();
    let path_text = std::fs::read(&path_file).unwrap();
    let output = strata(&with(
        os(compare_args(4, 2, 2)),
        &[scene.as_os_str(), "--camera-path".as_ref(), path_file.as_os_str(), "--out".as_ref(), folder.as_os_str()],
    ));
    assert_refused(&output, &["summary.txt", "input of this run"]);
    assert_eq!(std::fs::read(&path_file).unwrap(), path_text);
    let _ = std::fs::remove_dir_all(&dir);
}

// Round three (RELIABILITY.md, "Round three: loaders and camera paths").

/// Writes `keyframes` (frame, origin, target) as a camera path file `dir/name`.
fn camera_path_file(dir: &Path, name: &str, keyframes: &[(f32, [f32; 3], [f32; 3])]) -> PathBuf {
    let keys: Vec<serde_json::Value> = keyframes
        .iter()
        .map(|(frame, origin, target)| serde_json::json!({"frame": frame, "origin": origin, "target": target}))
        .collect();
    let file = dir.join(name);
    std::fs::write(&file, serde_json::json!({ "keyframes": keys }).to_string()).unwrap();
    file
}

/// Every file under `folder` with its contents.
fn contents(folder: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut found: Vec<_> =
        files(folder).into_iter().map(|(path, _)| (path.clone(), std::fs::read(&path).unwrap())).collect();
    found.sort();
    found
}

// Round three, 1. A camera path of one keyframe holds that key on every frame (the
// documentation of `CameraPath::Keyframes`): it rendered the scene's own camera while the
// run's record named the file.
#[test]
fn a_one_keyframe_camera_path_renders_from_its_key() {
    let dir = scratch("one-key");
    let (origin, target) = ([400.0f32, 300.0, -800.0], [278.0f32, 273.0, 0.0]);
    let scene = cornell_box(&dir, "box", |_| {});
    let moved = cornell_box(&dir, "moved", |scene| {
        scene["camera"]["origin"] = serde_json::json!(origin);
        scene["camera"]["target"] = serde_json::json!(target);
    });
    let key = camera_path_file(&dir, "key.json", &[(5.0, origin, target)]);
    let (with_key, moved_out) = (dir.join("with-key"), dir.join("moved-out"));
    let output = strata(&with(
        os(compare_args(8, 2, 2)),
        &[scene.as_os_str(), "--camera-path".as_ref(), key.as_os_str(), "--out".as_ref(), with_key.as_os_str()],
    ));
    assert_succeeded(&output);
    assert_succeeded(&strata(&with(
        os(compare_args(8, 2, 2)),
        &[moved.as_os_str(), "--out".as_ref(), moved_out.as_os_str()],
    )));
    // The key's camera is the camera: the same reference and the same errors as a scene
    // whose own camera is the key's.
    for name in ["reference.exr", "errors.csv"] {
        let (a, b) = (std::fs::read(with_key.join(name)).unwrap(), std::fs::read(moved_out.join(name)).unwrap());
        assert!(a == b, "{name} differs from the run whose scene camera is the key's");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

// Round three, 2. A camera path is checked whole, every keyframe and every frame's camera,
// before an earlier run's files are removed or a reference renders; the error names the
// flag, the keyframe (or frame) and the field.
#[test]
fn camera_paths_are_checked_whole_before_the_folder_is_touched() {
    let dir = scratch("path-whole");
    let scene = cornell_box(&dir, "box", |_| {});
    let out = dir.join("out");
    assert_succeeded(&strata(&with(
        os(compare_args(4, 1, 2)),
        &[scene.as_os_str(), "--out".as_ref(), out.as_os_str()],
    )));
    let earlier = contents(&out);
    // Key 1 looks straight up, along the scene camera's up vector.
    let along_up = camera_path_file(
        &dir,
        "along-up.json",
        &[(0.0, [278.0, 273.0, -800.0], [278.0, 273.0, 0.0]), (1.0, [278.0, 273.0, -800.0], [278.0, 274.0, -800.0])],
    );
    let output = strata(&with(
        os(compare_args(4, 3, 2)),
        &[scene.as_os_str(), "--camera-path".as_ref(), along_up.as_os_str(), "--out".as_ref(), out.as_os_str()],
    ));
    assert_refused(&output, &["--camera-path", "along-up.json", "keyframes[1].target", "parallel to `up`"]);
    assert!(!text(&output.stderr).contains("fov_axis"), "{}", text(&output.stderr));
    assert_eq!(contents(&out), earlier, "the earlier run's files were touched");
    // Keys that can each make rays, whose spline brings origin onto target at frame 1.
    let crossing = camera_path_file(
        &dir,
        "crossing.json",
        &[(0.0, [278.0, 273.0, -900.0], [278.0, 273.0, -700.0]), (2.0, [278.0, 273.0, -700.0], [278.0, 273.0, -900.0])],
    );
    let output = strata(&with(
        os(compare_args(4, 3, 2)),
        &[scene.as_os_str(), "--camera-path".as_ref(), crossing.as_os_str(), "--out".as_ref(), out.as_os_str()],
    ));
    assert_refused(&output, &["--camera-path", "crossing.json", "frame 1 ", "target equals origin"]);
    assert_eq!(contents(&out), earlier, "the earlier run's files were touched");
    let _ = std::fs::remove_dir_all(&dir);
}

// Round three, 3. A GGX alpha below the smallest the renderer samples (10⁻³): every loader
// renders it at 10⁻³ (OBJ and glTF did; JSON loaded 1e-30 and the render failed with
// "326 samples were invalid", naming no field); JSON, which promises alpha as written,
// says so in a warning naming the field.
#[test]
fn a_conductor_smoother_than_the_renderer_samples_renders_as_in_every_loader() {
    let dir = scratch("alpha");
    let conductor = |alpha: f64| {
        move |scene: &mut serde_json::Value| {
            let first = scene["materials"].as_object().unwrap().keys().next().unwrap().clone();
            scene["materials"][&first] = serde_json::json!({"type": "roughconductor", "distribution": "ggx",
                "alpha": alpha, "eta": [0.2, 0.9, 1.1], "k": [3.9, 2.4, 2.2], "two_sided": true});
        }
    };
    let tiny = cornell_box(&dir, "tiny", conductor(1e-30));
    let floor = cornell_box(&dir, "floor", conductor(1e-3));
    let (tiny_out, floor_out) = (dir.join("tiny-out"), dir.join("floor-out"));
    let output = strata(&with(os(render_args(8)), &[tiny.as_os_str(), "--out".as_ref(), tiny_out.as_os_str()]));
    assert_succeeded(&output);
    let stderr = text(&output.stderr);
    let warnings: Vec<&str> = stderr.lines().filter(|l| l.starts_with("warning:")).collect();
    assert_eq!(warnings.len(), 1, "{stderr}");
    assert!(warnings[0].contains("scene.json") && warnings[0].contains(".alpha`") && warnings[0].contains("0.001"));
    assert_succeeded(&strata(&with(os(render_args(8)), &[floor.as_os_str(), "--out".as_ref(), floor_out.as_os_str()])));
    let (a, b) =
        (std::fs::read(tiny_out.join("tiny.exr")).unwrap(), std::fs::read(floor_out.join("floor.exr")).unwrap());
    assert!(a == b, "alpha 1e-30 must render exactly as alpha 1e-3");
    let _ = std::fs::remove_dir_all(&dir);
}

// Round three, 4. A glTF camera's aspectRatio has an upper bound as it had a lower one
// (600 gave a 512 × 1 black image and a warning about a camera seeing no light).
#[test]
fn gltf_aspect_ratios_beyond_the_limit_are_refused() {
    let dir = scratch("aspect");
    let out = dir.join("out");
    let render =
        |scene: &Path| strata(&with(os(render_args(4)), &[scene.as_os_str(), "--out".as_ref(), out.as_os_str()]));
    for (name, aspect) in [("wide", 600.0), ("wider", 16.5), ("tall", 0.05)] {
        let scene = gltf_scene(&dir, name, |d| d["cameras"][0]["perspective"]["aspectRatio"] = aspect.into());
        assert_refused(&render(&scene), &["scene.gltf", "nodes[1].camera", "aspectRatio", "[1/16, 16]"]);
    }
    for (name, aspect) in [("widest", 16.0), ("tallest", 0.0625)] {
        let scene = gltf_scene(&dir, name, |d| d["cameras"][0]["perspective"]["aspectRatio"] = aspect.into());
        assert_succeeded(&render(&scene));
    }
    let _ = std::fs::remove_dir_all(&dir);
}

// Round three, 5. `render` into a folder it cannot write is refused before rendering (it
// rendered for 37 s, then failed). A read-only tmpfs in a user namespace: a folder's
// permissions do not stop root.
#[test]
fn render_refuses_a_folder_it_cannot_write_before_rendering() {
    let dir = scratch("read-only");
    let mount = dir.join("read-only");
    std::fs::create_dir_all(&mount).unwrap();
    // Far more samples than the deadline allows: only a refusal before rendering ends in time.
    let script = format!(
        "mount -t tmpfs -o size=64k,ro tmpfs {mount} || exit 97\ntimeout 60 {bin} render --backend cpu --width 64 \
         --height 64 --spp 100000 --out {mount}; echo \"exit $?\"",
        mount = sh_word(&mount),
        bin = sh_word(&binary())
    );
    let output = Command::new("unshare")
        .args(["-rm", "sh", "-c", &script])
        .env("RUST_BACKTRACE", "1")
        .env("XDG_RUNTIME_DIR", NO_DISPLAY)
        .output();
    let output = match output {
        Ok(output) if output.status.code() != Some(97) => output,
        other => {
            eprintln!("SKIPPED: no read-only tmpfs could be mounted in a user namespace: {other:?}");
            return;
        }
    };
    let (stdout, stderr) = (text(&output.stdout), text(&output.stderr));
    assert!(stdout.contains("exit 1"), "the render must be refused at once (124: it rendered):\n{stdout}\n{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    let errors: Vec<&str> = stderr.lines().filter(|l| l.starts_with("error: ")).collect();
    assert_eq!(errors.len(), 1, "{stderr}");
    assert!(
        errors[0].contains("--out") && errors[0].contains("read-only") && errors[0].contains("Read-only file system")
    );
    let _ = std::fs::remove_dir_all(&dir);
}

// Round three, 6. Text files saved with a UTF-8 byte order mark or CRLF line ends read as
// the same text: JSON scenes, camera paths, glTF, OBJ and MTL, PLY headers, errors.csv.
#[test]
fn text_files_with_a_byte_order_mark_or_crlf_read_the_same() {
    let dir = scratch("bom");
    let out = dir.join("out");
    let bom = |path: &Path| {
        let mut bytes = b"\xEF\xBB\xBF".to_vec();
        bytes.extend(std::fs::read(path).unwrap());
        std::fs::write(path, bytes).unwrap();
    };
    let render = |scene: &Path, name: &str| {
        let output =
            strata(&with(os(render_args(8)), &[scene.as_os_str(), "--out".as_ref(), out.join(name).as_os_str()]));
        assert_succeeded(&output);
        assert!(!text(&output.stderr).contains("warning:"), "{}", text(&output.stderr));
        let exr = files(&out.join(name)).into_iter().find(|(p, _)| p.extension().is_some_and(|e| e == "exr"));
        std::fs::read(exr.expect("an EXR was written").0).unwrap()
    };
    // JSON scene with a BOM, its PLY meshes' headers with CRLF line ends.
    let plain = cornell_box(&dir, "plain", |_| {});
    let marked = cornell_box(&dir, "marked", |_| {});
    bom(&marked);
    for entry in std::fs::read_dir(marked.parent().unwrap().join("meshes")).unwrap().map(Result::unwrap) {
        let bytes = std::fs::read(entry.path()).unwrap();
        let end = bytes.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
        let header = String::from_utf8(bytes[..end].to_vec()).unwrap().replace('\n', "\r\n");
        std::fs::write(entry.path(), [header.as_bytes(), &bytes[end..]].concat()).unwrap();
    }
    assert!(render(&plain, "plain") == render(&marked, "marked"), "the JSON + PLY scene renders otherwise");
    // OBJ and MTL with a BOM (in the MTL it hid the first `newmtl`), CRLF line ends.
    let obj = obj_scene(&dir, "obj-plain", "", Some(ROOM_MTL));
    let marked_obj = obj_scene(&dir, "obj-marked", "", Some(&ROOM_MTL.replace('\n', "\r\n")));
    let crlf = std::fs::read_to_string(&marked_obj).unwrap().replace('\n', "\r\n");
    std::fs::write(&marked_obj, crlf).unwrap();
    bom(&marked_obj);
    bom(&marked_obj.with_file_name("room.mtl"));
    assert!(render(&obj, "obj-plain") == render(&marked_obj, "obj-marked"), "the OBJ scene renders otherwise");
    // glTF JSON with a BOM.
    let gltf = gltf_scene(&dir, "gltf-plain", |_| {});
    let marked_gltf = gltf_scene(&dir, "gltf-marked", |_| {});
    bom(&marked_gltf);
    assert!(render(&gltf, "gltf-plain") == render(&marked_gltf, "gltf-marked"), "the glTF scene renders otherwise");
    // A camera path with a BOM.
    let path = camera_path_file(
        &dir,
        "path.json",
        &[(0.0, [278.0, 273.0, -800.0], [278.0, 273.0, 0.0]), (1.0, [290.0, 273.0, -800.0], [278.0, 273.0, 0.0])],
    );
    bom(&path);
    let output = strata(&with(
        os(compare_args(4, 2, 2)),
        &[
            plain.as_os_str(),
            "--camera-path".as_ref(),
            path.as_os_str(),
            "--out".as_ref(),
            out.join("path").as_os_str(),
        ],
    ));
    assert_succeeded(&output);
    // errors.csv with a BOM and CRLF line ends.
    let rows = [("strata", 1, 1, 0.5), ("restir", 1, 1, 1.0), ("strata", 1, 2, 0.4), ("restir", 1, 2, 0.9)];
    let file = dir.join("errors.csv");
    std::fs::write(&file, format!("\u{feff}{}", csv(&rows).replace('\n', "\r\n"))).unwrap();
    assert_succeeded(&strata(&["plot".as_ref(), file.as_os_str(), "--out".as_ref(), dir.join("plot").as_os_str()]));
    let _ = std::fs::remove_dir_all(&dir);
}

// Round three, 7. A control character in `plot --title` or `--label` wrote an SVG that is
// not XML, with exit status 0.
#[test]
fn plot_titles_and_labels_with_control_characters_are_refused() {
    let dir = scratch("plot-title");
    let rows = [("strata", 1, 1, 0.5), ("restir", 1, 1, 1.0), ("strata", 1, 2, 0.4), ("restir", 1, 2, 0.9)];
    let file = dir.join("errors.csv");
    std::fs::write(&file, csv(&rows)).unwrap();
    let stem = dir.join("plot");
    for (flag, value) in [("--title", "bell\u{7}"), ("--title", "two\nlines"), ("--label", "esc\u{1b}[31m")] {
        let output = strata(&[
            "plot".as_ref(),
            file.as_os_str(),
            "--out".as_ref(),
            stem.as_os_str(),
            flag.as_ref(),
            value.as_ref(),
        ]);
        assert_refused(&output, &[flag, "control character"]);
        assert!(files(&dir).iter().all(|(p, _)| p == &file), "a file was written: {:?}", files(&dir));
    }
    let _ = std::fs::remove_dir_all(&dir);
}

// Round three, 8. Messages quote what the user typed, on one line.
#[test]
fn messages_quote_the_text_given_on_one_line() {
    let dir = scratch("quoted");
    // A float prints 4294967295 as 4294967300.
    let output = strata(&["compare", "--backend", "cpu", "--disc-radius", "4294967295"]);
    assert_refused_with(&output, 2, &["--disc-radius", "'4294967295'", "16384"]);
    assert!(!text(&output.stderr).contains("4294967300"), "{}", text(&output.stderr));
    let output = strata(&["compare", "--backend", "cpu", "--temporal-cap", "1e40"]);
    assert_refused_with(&output, 2, &["--temporal-cap", "'1e40'", "at least 1"]);
    // A broken JPEG texture: the decoder's message ended in a blank line.
    let scene = cornell_box(&dir, "jpeg", |scene| {
        let first = scene["materials"].as_object().unwrap().keys().next().unwrap().clone();
        scene["materials"][&first]["reflectance"] = serde_json::json!({"texture": "broken.jpg"});
    });
    let jpeg = std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/report-screenshot.jpg")).unwrap();
    std::fs::write(scene.with_file_name("broken.jpg"), &jpeg[..700]).unwrap();
    let output = strata(&with(os(render_args(4)), &[scene.as_os_str(), "--out".as_ref(), dir.join("out").as_os_str()]));
    assert_refused(&output, &["broken.jpg"]);
    let stderr = text(&output.stderr);
    assert_eq!(stderr.lines().count(), 1, "not one line: {stderr:?}");
    let _ = std::fs::remove_dir_all(&dir);
}
