//! `cargo xtask run`'s library: any WGSL compute shader on chosen backends, outputs
//! written to files, agreement reported, bad input named.

use std::path::PathBuf;
use strata_check::agreement::{FloatBound, Tolerance, judge};
use strata_check::overrides::OverrideFlag;
use strata_check::run_kernel::{RunRequest, run_kernel};

const SQUARE: &str = r#"
@group(0) @binding(0) var<storage, read> input: array<u32>;
@group(0) @binding(1) var<storage, read_write> output: array<u32>;
@compute @workgroup_size(64)
fn square(@builtin(global_invocation_id) id: vec3<u32>) {
    output[id.x] = input[id.x] * input[id.x] + id.x;
}
"#;

/// A fresh folder holding the squaring kernel and its input, under cargo's `target/tmp`, not the
/// shared `/tmp`, where another user could create the name first, and the request that runs it.
fn setup(name: &str) -> (PathBuf, RunRequest) {
    let dir =
        std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("strata-run-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("square.wgsl"), SQUARE).unwrap();
    let input: Vec<u8> = (0..128u32).flat_map(|i| (i * 3).to_le_bytes()).collect();
    std::fs::write(dir.join("in.bin"), input).unwrap();
    let request = RunRequest {
        shader: dir.join("square.wgsl"),
        entry: "square".into(),
        workgroups: [2, 1, 1],
        buffers: vec![(0, 0, dir.join("in.bin"))],
        sizes: vec![(0, 1, 512)],
        overrides: Vec::new(),
        images: Vec::new(),
        backends: vec!["cpu".into()],
        out: dir.join("out"),
        ulp: Vec::new(),
        abs: Vec::new(),
        time_limit: None,
        sanitize: false,
    };
    (dir, request)
}

/// Every backend ran (wgpu-gl may lack a device, as may every GPU backend without
/// `STRATA_REQUIRE_GPU=1`) and every output is bit-identical to the interpreter's.
fn every_backend_agrees(runs: &[strata_check::run_kernel::BackendRun]) {
    for run in runs {
        if let Err(error) = &run.outputs {
            let skippable = !strata_backends::gpu_required() || run.backend == "wgpu-gl";
            assert!(skippable, "{} failed: {error}", run.backend);
        }
    }
    let judgement = judge(runs, Some("cpu"), &Tolerance::default()).unwrap();
    assert!(judgement.buffers.iter().all(|b| b.differing == 0), "{judgement:?}");
}

#[test]
fn a_shader_runs_on_the_interpreter_and_its_output_is_written() {
    let (dir, request) = setup("cpu");
    let runs = run_kernel(&request).unwrap().runs;
    assert_eq!(runs.len(), 1);
    let bytes = std::fs::read(dir.join("out/cpu/0_1_output.bin")).unwrap();
    let words: Vec<u32> = bytes.chunks_exact(4).map(|c| u32::from_le_bytes(c.try_into().unwrap())).collect();
    let want: Vec<u32> = (0..128u32).map(|i| (i * 3) * (i * 3) + i).collect();
    assert_eq!(words, want);
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn every_backend_agrees_on_a_foreign_shader() {
    let (dir, mut request) = setup("all");
    request.backends = vec!["all".into()];
    every_backend_agrees(&run_kernel(&request).unwrap().runs);
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn bad_requests_are_named() {
    let (dir, mut request) = setup("bad");
    request.backends = vec!["metal".into()];
    let error = run_kernel(&request).unwrap_err().to_string();
    assert!(error.contains("unknown backend `metal`"), "{error}");
    request.backends = vec!["cpu".into()];
    request.buffers = vec![(0, 7, dir.join("in.bin"))];
    let error = run_kernel(&request).unwrap_err().to_string();
    assert!(error.contains("--buffer 0:7") && error.contains("no such binding"), "{error}");
    request.buffers = vec![(0, 0, dir.join("missing.bin"))];
    let error = run_kernel(&request).unwrap_err().to_string();
    assert!(error.contains("missing.bin"), "{error}");
    request.buffers = Vec::new();
    request.sizes = vec![(0, 9, 16)];
    let error = run_kernel(&request).unwrap_err().to_string();
    assert!(error.contains("--size 0:9=16") && error.contains("no such binding"), "{error}");
    request.sizes = Vec::new();
    request.overrides = vec![OverrideFlag::number("width", 3.0)];
    let error = run_kernel(&request).unwrap_err().to_string();
    assert!(error.contains("`width` is not an override"), "{error}");
    request.overrides = Vec::new();
    request.entry = "nope".into();
    let error = run_kernel(&request).unwrap_err().to_string();
    assert!(error.contains("nope"), "{error}");
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn a_shader_with_overrides_runs_everywhere_with_and_without_override() {
    let dir =
        std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("strata-run-override-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let (width, height) = (32u32, 16u32);
    let size: Vec<u8> = [width, height].iter().flat_map(|v| v.to_le_bytes()).collect();
    // A glider in an empty grid.
    let mut cells = vec![0u32; (width * height) as usize];
    for (x, y) in [(1, 0), (2, 1), (0, 2), (1, 2), (2, 2)] {
        cells[(y * width + x) as usize] = 1;
    }
    std::fs::write(dir.join("size.bin"), size).unwrap();
    std::fs::write(dir.join("cells.bin"), cells.iter().flat_map(|c| c.to_le_bytes()).collect::<Vec<u8>>()).unwrap();
    let shader = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("data/corpus/life.wgsl");
    let mut live = Vec::new();
    for (overrides, tile) in
        [(Vec::new(), 8), (vec![OverrideFlag::number("tile", 4.0), OverrideFlag::number("birth", 2.0)], 4)]
    {
        let request = RunRequest {
            shader: shader.clone(),
            entry: "main".into(),
            workgroups: [width / tile, height / tile, 1],
            buffers: vec![(0, 0, dir.join("size.bin")), (0, 1, dir.join("cells.bin"))],
            sizes: vec![(0, 2, u64::from(width * height * 4))],
            overrides,
            images: Vec::new(),
            backends: vec!["all".into()],
            out: dir.join(format!("out{tile}")),
            ulp: Vec::new(),
            abs: Vec::new(),
            time_limit: None,
            sanitize: false,
        };
        let runs = run_kernel(&request).unwrap().runs;
        every_backend_agrees(&runs);
        let count = &runs[0].outputs.as_ref().unwrap()[1].bytes;
        live.push(u32::from_le_bytes(count[..4].try_into().unwrap()));
    }
    // Conway's rule keeps the glider's five cells; birth on two neighbours grows it.
    assert_eq!(live[0], 5);
    assert_ne!(live[1], 5);
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn a_png_texture_and_a_sampler_run_everywhere_and_the_output_comes_back_as_png() {
    use strata_check::run_images::{ImageSpec, SamplerDesc, TextureFile};
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("strata-run-png-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let (width, height) = (37u32, 22u32);
    let picture = image::RgbaImage::from_fn(width, height, |x, y| {
        image::Rgba([(x * 7) as u8, (y * 11) as u8, ((x * y) % 251) as u8, 255 - x as u8])
    });
    picture.save(dir.join("in.png")).unwrap();
    let linear = SamplerDesc::uniform(strata_backends::FilterMode::Linear, strata_backends::AddressMode::ClampToEdge);
    let request = RunRequest {
        shader: PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("data/textures/downsample.wgsl"),
        entry: "main".into(),
        workgroups: [3, 2, 1],
        buffers: Vec::new(),
        sizes: Vec::new(),
        overrides: Vec::new(),
        images: vec![
            ImageSpec::Texture((0, 0), TextureFile::Picture(dir.join("in.png"))),
            ImageSpec::Sampler((0, 1), linear),
            ImageSpec::StorageTexture((0, 2), [width / 2, height / 2, 1], None),
        ],
        backends: vec!["cpu".into(), "wgpu-vulkan".into(), "wgpu-gl".into(), "ash".into()],
        out: dir.join("out"),
        ulp: Vec::new(),
        abs: Vec::new(),
        time_limit: None,
        sanitize: false,
    };
    let runs = run_kernel(&request).unwrap().runs;
    // A filtered value a device rounds with 8-bit weights may land one 1/255 step away.
    let tolerance = Tolerance { float: FloatBound { ulp: 1, abs: 0.0 }, per_buffer: Vec::new() };
    let judgement = judge(&runs, Some("cpu"), &tolerance).unwrap();
    for buffer in &judgement.buffers {
        assert!(buffer.passes(), "{} {}", buffer.backend, buffer.describe());
    }
    for run in runs.iter().filter(|r| r.outputs.is_ok()) {
        let folder = dir.join("out").join(&run.backend);
        let written = image::open(folder.join("0_2_half_size.png")).unwrap().to_rgba8();
        assert_eq!(written.dimensions(), (width / 2, height / 2));
        assert_eq!(written.into_raw(), std::fs::read(folder.join("0_2_half_size.bin")).unwrap(), "{}", run.backend);
    }
    // The centre of each 2 x 2 footprint is the four texels' mean, to a step.
    let out = std::fs::read(dir.join("out/cpu/0_2_half_size.bin")).unwrap();
    let at = |x: u32, y: u32, c: usize| f64::from(picture.get_pixel(x, y)[c]);
    let mean = (at(4, 6, 1) + at(5, 6, 1) + at(4, 7, 1) + at(5, 7, 1)) / 4.0;
    let texel = ((3 * (width / 2) + 2) * 4 + 1) as usize;
    assert!((f64::from(out[texel]) - mean).abs() <= 1.0, "{} against {mean}", out[texel]);
    // A texture whose shape the kernel does not take is refused by name.
    let mut wrong = request.clone();
    wrong.images[2] = ImageSpec::StorageTexture((0, 2), [4, 4, 1], Some(strata_kernels::TexelFormat::R32Float));
    let error = run_kernel(&wrong).unwrap_err().to_string();
    assert!(error.contains("half_size") && error.contains("r32float") && error.contains("rgba8unorm"), "{error}");
    std::fs::remove_dir_all(dir).unwrap();
}

/// `xtask run`'s sanitizer: with `--sanitize` the interpreter's findings come back with
/// the outcome (an index out of range, named by file and line), and `--time-limit`
/// stops a kernel that never ends, naming where it was (issue 58).
#[test]
fn the_interpreter_sanitizes_and_stops_endless_kernels_for_xtask_run() {
    let data = format!("{}/data/sanitizer", env!("CARGO_MANIFEST_DIR"));
    let (folder, mut request) = setup("sanitize");
    request.shader = format!("{data}/out_of_range.wgsl").into();
    request.entry = "main".into();
    request.workgroups = [1, 1, 1];
    request.buffers.clear();
    request.sizes = vec![(0, 0, 64), (0, 1, 64)];
    request.backends = vec!["cpu".into()];
    request.ulp.clear();
    request.abs.clear();
    request.out = folder.join("out");
    // Alone, the interpreter sanitizes only when asked.
    let outcome = run_kernel(&request).unwrap();
    assert!(!outcome.sanitized && outcome.findings.0.is_empty());
    request.sanitize = true;
    let outcome = run_kernel(&request).unwrap();
    let why = outcome.undefined_behaviour().expect("an undefined finding");
    assert!(why.to_string().starts_with("out-of-range index at"), "{why}");
    assert!(why.file.ends_with("out_of_range.wgsl") && why.line == 12, "{why}");
    // A loop that never ends: the cpu run fails at the limit, naming the line.
    request.shader = format!("{data}/endless.wgsl").into();
    request.sizes = vec![(0, 0, 256)];
    request.time_limit = Some(std::time::Duration::from_millis(100));
    let outcome = run_kernel(&request).unwrap();
    let error = outcome.runs[0].outputs.as_ref().expect_err("stopped");
    assert!(error.contains("time limit of 100 ms") && error.contains("endless.wgsl:9 in `main`"), "{error}");
    std::fs::remove_dir_all(folder).unwrap();
}
