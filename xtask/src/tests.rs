//! `cargo xtask run`, `export` and `shaders` as a user types them (parsed by clap, run
//! in this process): every bad input is an `Err` of one line naming the flag, file or
//! value (never a panic, an abort or an input silently dropped), and the documented
//! forms work.

use super::{Cli, execute};
use clap::Parser;
use std::path::{Path, PathBuf};

/// Runs `xtask ARGS...`; a parse error or a command's error as the one line `main`
/// prints after `error: `.
fn xtask(args: &[&str]) -> Result<(), String> {
    let cli = Cli::try_parse_from(std::iter::once("xtask").chain(args.iter().copied())).map_err(|e| e.to_string())?;
    execute(cli).map_err(|e| format!("{e:#}"))
}

/// `xtask ARGS...` must fail with one line holding every one of `wanted`.
fn refused(args: &[&str], wanted: &[&str]) -> String {
    let error = match xtask(args) {
        Ok(()) => panic!("xtask {} succeeded", args.join(" ")),
        Err(error) => error,
    };
    // clap's own parse errors end with its usage hint; a command's error is one line.
    let first = error.lines().next().unwrap_or_default();
    for want in wanted {
        assert!(first.contains(want), "xtask {}: `{want}` not named in: {error}", args.join(" "));
    }
    if !error.contains("For more information, try '--help'") {
        assert!(!error.trim_end().contains('\n'), "xtask {}: more than one line: {error}", args.join(" "));
    }
    error
}

/// A new empty folder of a random name for this test (the test removes it).
fn scratch(name: &str) -> PathBuf {
    strata_files::private_scratch_folder(&format!("strata-xtask-{name}-")).unwrap().keep()
}

fn text(path: &Path) -> String {
    path.to_str().unwrap().to_string()
}

const SQUARE: &str = include_str!("../../tests/data/flags/square.wgsl");

const TEXTURE: &str = include_str!("../../tests/data/flags/texture_load.wgsl");

/// The override of the issue: an `@id` and a name, feeding the workgroup size.
const TILE: &str = "
@id(3) override tile: u32 = 8;
override scale: u32 = 1;
@group(0) @binding(0) var<storage, read_write> output: array<u32>;
@compute @workgroup_size(tile, tile)
fn main(@builtin(local_invocation_index) i: u32) {
    output[i] = tile * scale;
}
";

/// The shaders and inputs of the `run` tests in `folder`.
fn shaders(folder: &Path) {
    std::fs::write(folder.join("square.wgsl"), SQUARE).unwrap();
    std::fs::write(folder.join("texture.wgsl"), TEXTURE).unwrap();
    std::fs::write(folder.join("tile.wgsl"), TILE).unwrap();
    std::fs::write(folder.join("in.bin"), vec![3u8; 512]).unwrap();
    std::fs::write(folder.join("t.bin"), vec![7u8; 64]).unwrap();
}

/// `run FOLDER/SHADER --entry main --out FOLDER/out EXTRA...`, where `DIR/` in an extra
/// argument stands for `FOLDER/`.
fn run(folder: &Path, shader: &str, extra: &[&str]) -> Vec<String> {
    let at = format!("{}/", text(folder));
    let mut args: Vec<String> = ["run", &format!("{at}{shader}"), "--entry", "main", "--out", &format!("{at}out")]
        .iter()
        .map(|s| s.to_string())
        .collect();
    args.extend(extra.iter().map(|a| a.replace("DIR/", &at)));
    args
}

fn strs(args: &[String]) -> Vec<&str> {
    args.iter().map(String::as_str).collect()
}

fn words(path: &Path) -> Vec<u32> {
    std::fs::read(path).unwrap().chunks_exact(4).map(|c| u32::from_le_bytes(c.try_into().unwrap())).collect()
}

#[test]
fn sizes_from_input_are_refused_by_name_and_never_overflow() {
    let folder = scratch("sizes");
    shaders(&folder);
    let args = run(&folder, "square.wgsl", &["--buffer", "0:0=DIR/in.bin", "--size", "0:1=18446744073709551615"]);
    refused(&strs(&args), &["--size 0:1=18446744073709551615"]);
    let args = run(&folder, "texture.wgsl", &["--texture", "0:0=DIR/t.bin@4294967295x4294967295:rgba8unorm"]);
    refused(&strs(&args), &["--texture", "4294967295x4294967295"]);
    let args = run(&folder, "texture.wgsl", &["--texture", "0:0=DIR/t.bin@4x4x4294967295:rgba8unorm"]);
    refused(&strs(&args), &["--texture", "4x4x4294967295"]);
    let _ = std::fs::remove_dir_all(&folder);
}

/// Before the fix this test aborted the test process ("memory allocation of 100000000000
/// bytes failed"): the zeros were allocated before any limit was looked at.
#[test]
fn a_huge_size_is_refused_before_anything_is_allocated() {
    let folder = scratch("huge");
    shaders(&folder);
    let args = run(&folder, "square.wgsl", &["--buffer", "0:0=DIR/in.bin", "--size", "0:1=100000000000"]);
    refused(&strs(&args), &["--size 0:1=100000000000"]);
    let _ = std::fs::remove_dir_all(&folder);
}

#[test]
fn an_input_given_twice_is_refused_by_name() {
    let folder = scratch("twice");
    shaders(&folder);
    let cases: [(&[&str], &[&str]); 8] = [
        (&["--buffer", "0:0=DIR/in.bin", "--buffer", "0:0=DIR/t.bin", "--size", "0:1=512"], &["0:0", "--buffer"]),
        (
            &["--buffer", "0:0=DIR/in.bin", "--buffer", "0:1=DIR/in.bin", "--size", "0:1=512"],
            &["0:1", "--buffer", "--size"],
        ),
        (&["--buffer", "0:0=DIR/in.bin", "--size", "0:1=8", "--size", "0:1=512"], &["0:1", "--size"]),
        (&["--buffer", "0:0=DIR/in.bin", "--backend", "cpu,cpu"], &["--backend", "cpu", "twice"]),
        (&["--buffer", "0:0=DIR/in.bin", "--backend", "wgpu,wgpu-vulkan"], &["--backend", "wgpu-vulkan", "twice"]),
        (&["--buffer", "0:0=DIR/in.bin", "--ulp", "nosuchbuffer=3"], &["--ulp nosuchbuffer=3", "output"]),
        (&["--buffer", "0:0=DIR/in.bin", "--abs", "input=0.5"], &["--abs input=0.5", "output"]),
        (&["--buffer", "0:0=DIR/in.bin", "--ulp", "output=3", "--ulp", "output=4"], &["--ulp", "output", "twice"]),
    ];
    for (extra, wanted) in cases {
        refused(&strs(&run(&folder, "square.wgsl", extra)), wanted);
    }
    let cases: [(&[&str], &[&str]); 2] = [
        (
            &["--texture", "0:0=DIR/t.bin@4x4:rgba8unorm", "--texture", "0:0=DIR/t.bin@2x8:rgba8unorm"],
            &["0:0", "--texture"],
        ),
        (&["--texture", "0:0=DIR/t.bin@4x4:rgba8unorm", "--storage-texture", "0:0=4x4"], &["0:0", "--storage-texture"]),
    ];
    for (extra, wanted) in cases {
        refused(&strs(&run(&folder, "texture.wgsl", extra)), wanted);
    }
    // The same buffer's ULP and absolute bounds are two flags, not a duplicate.
    square_runs(&folder, &["--ulp", "output=3", "--abs", "output=0.5", "--ulp", "1"]);
    let _ = std::fs::remove_dir_all(&folder);
}

fn square_runs(folder: &Path, extra: &[&str]) {
    let mut all = vec!["--buffer", "0:0=DIR/in.bin", "--size", "0:1=512"];
    all.extend_from_slice(extra);
    let args = run(folder, "square.wgsl", &all);
    xtask(&strs(&args)).unwrap();
}

/// `--override NAME=V` and `ID=V` (and `@ID=V`) set an override declared with `@id`; a
/// value the workgroup size cannot take names the override, the value and the limit.
#[test]
fn an_override_with_an_id_is_set_by_name_or_by_id() {
    let folder = scratch("override");
    shaders(&folder);
    for (flags, tile, scale) in [
        (&[][..], 8, 1),
        (&["--override", "tile=4"][..], 4, 1),
        (&["--override", "3=2"][..], 2, 1),
        (&["--override", "@3=5", "--override", "scale=3"][..], 5, 3),
    ] {
        let mut extra = vec!["--size", "0:0=1024"];
        extra.extend_from_slice(flags);
        xtask(&strs(&run(&folder, "tile.wgsl", &extra))).unwrap();
        let written = words(&folder.join("out/cpu/0_0_output.bin"));
        let invocations = (tile * tile) as usize;
        assert!(written[..invocations].iter().all(|&w| w == tile * scale), "{flags:?}: {written:?}");
        assert!(written[invocations..].iter().all(|&w| w == 0), "{flags:?}");
    }
    let cases: [(&[&str], &[&str]); 7] = [
        (&["--override", "3=100000"], &["--override 3=100000", "tile", "16384"]),
        (&["--override", "tile=0"], &["--override tile=0", "tile", "16384"]),
        (&["--override", "tile=-1"], &["--override tile=-1", "tile", "u32"]),
        (&["--override", "tile=4.5"], &["--override tile=4.5", "u32"]),
        (&["--override", "7=4"], &["--override 7=4", "@id(7)", "tile"]),
        (&["--override", "width=4"], &["--override width=4", "tile", "scale"]),
        (&["--override", "tile=4", "--override", "3=2"], &["tile=4", "3=2", "twice"]),
    ];
    for (flags, wanted) in cases {
        let mut extra = vec!["--size", "0:0=1024"];
        extra.extend_from_slice(flags);
        refused(&strs(&run(&folder, "tile.wgsl", &extra)), wanted);
    }
    let _ = std::fs::remove_dir_all(&folder);
}

/// `shaders --out FILE` names the file.
#[test]
fn shaders_names_an_out_that_is_a_file() {
    let folder = scratch("shaders");
    let file = folder.join("not-a-folder");
    std::fs::write(&file, "the user's").unwrap();
    refused(&["shaders", "--out", &text(&file)], &[&text(&file)]);
    let _ = std::fs::remove_dir_all(&folder);
}
