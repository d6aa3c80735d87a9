//! The kernel package for engines outside Rust (`strata-export`) and the C program that
//! uses it (`examples/c/`), as an engine developer in C would: the package exported, the
//! C program built with `cc -std=c11 -Wall -Wextra -Werror` against the package's headers,
//! the system Vulkan headers, Jansson and the `strata_vk` library, then run by both routes
//! (the package alone; the C ABI) over several frames. Every route's selections and
//! resampling results must equal the wgpu flavour of `strata-embed` bit for bit, for every
//! K and two sampler variants (and every histogram kernel, by route 1). The manifest is
//! checked against naga's reflection of every kernel, and the check is shown to fail with
//! one binding number of the manifest changed and with one field offset of `strata.h`
//! changed.

use std::path::{Path, PathBuf};
use std::process::Command;
use strata_embed::contract::{ResampleInput, ResampleOutput, SelectedCandidates};
use strata_embed::wgsl::{ModuleId, module};
use strata_embed::{SamplerVariant, SelectionSettings};
use strata_tests::{EmbedInputs, engine_device, engine_inputs, first_frame_difference, wgpu_embed_frames};

const WIDTH: u32 = 45;
const HEIGHT: u32 = 29;
const FRAMES: u32 = 4;
const SEED: u32 = 7;
/// The `XDG_RUNTIME_DIR` of the programs this test starts: a name that does not exist, in
/// cargo's target folder, not the shared `/tmp` (Mesa's Vulkan layer connects to
/// `$XDG_RUNTIME_DIR/wayland-0`; SECURITY.md, "The display socket").
const NO_DISPLAY: &str = concat!(env!("CARGO_TARGET_TMPDIR"), "/no-display");

/// The workspace's root.
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// A fresh folder under the workspace's target.
fn scratch(name: &str) -> PathBuf {
    let folder = root().join("target/export-c-test").join(format!("{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&folder);
    std::fs::create_dir_all(&folder).unwrap();
    folder
}

/// One run's per-frame outputs.
type Frames = Vec<(Vec<SelectedCandidates>, Vec<ResampleOutput>)>;

/// Frames 0..FRAMES of the wgpu flavour for `settings`, with the engine's payloads.
fn wgpu_frames(device: &wgpu::Device, queue: &wgpu::Queue, settings: SelectionSettings) -> Frames {
    wgpu_frames_with(device, queue, settings, true)
}

/// [`wgpu_frames`], with or without a payloads buffer (without: a pixel's payload is its
/// index).
fn wgpu_frames_with(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    settings: SelectionSettings,
    with_payloads: bool,
) -> Frames {
    wgpu_frames_sized(device, queue, settings, with_payloads, (WIDTH, HEIGHT))
}

/// [`wgpu_frames_with`] for an image of `size`.
fn wgpu_frames_sized(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    settings: SelectionSettings,
    with_payloads: bool,
    (width, height): (u32, u32),
) -> Frames {
    let (candidates, payloads, resample) = engine_inputs(width, height);
    let inputs = EmbedInputs {
        width,
        height,
        candidates: &candidates,
        payloads: with_payloads.then_some(payloads.as_slice()),
        resample: &resample,
    };
    wgpu_embed_frames(device, queue, settings, SEED, &inputs, FRAMES)
}

/// The shared library `strata_vk`, built by cargo beside the test binaries.
fn library_folder() -> PathBuf {
    let deps = std::env::current_exe().unwrap().parent().unwrap().to_path_buf();
    for folder in [deps.clone(), deps.join("..")] {
        if folder.join("libstrata_vk.so").exists() {
            return folder;
        }
    }
    panic!("libstrata_vk.so is not in {} (cargo builds it with the workspace)", deps.display());
}

/// Builds the C program against `package`'s headers; the compiler's output on failure.
fn build_c(package: &Path, out: &Path) -> Result<PathBuf, String> {
    let program = out.join("strata_c");
    let sources =
        ["main.c", "engine.c", "route_package.c", "route_library.c"].map(|f| root().join("examples/c").join(f));
    let library = library_folder();
    let output = Command::new("cc")
        .args(["-std=c11", "-Wall", "-Wextra", "-Werror", "-O1", "-I"])
        .arg(package.join("include"))
        .args(&sources)
        .arg("-o")
        .arg(&program)
        .args(["-lvulkan", "-ljansson", "-L"])
        .arg(&library)
        .arg("-lstrata_vk")
        .arg(format!("-Wl,-rpath,{}", library.display()))
        .output()
        .map_err(|e| format!("cc cannot run: {e} (install gcc)"))?;
    if !output.status.success() {
        return Err(String::from_utf8_lossy(&output.stderr).into_owned());
    }
    Ok(program)
}

/// Writes the engine's input files into `folder`.
fn write_inputs(folder: &Path) {
    write_inputs_with(folder, true);
}

/// [`write_inputs`], with or without `payloads.bin`.
fn write_inputs_with(folder: &Path, with_payloads: bool) {
    write_engine_inputs(folder, with_payloads, (WIDTH, HEIGHT));
}

/// [`write_inputs_with`] for an image of `size`.
fn write_engine_inputs(folder: &Path, with_payloads: bool, (width, height): (u32, u32)) {
    let (candidates, payloads, resample) = engine_inputs(width, height);
    std::fs::write(folder.join("candidates.bin"), bytemuck::cast_slice(&candidates)).unwrap();
    if with_payloads {
        std::fs::write(folder.join("payloads.bin"), bytemuck::cast_slice(&payloads)).unwrap();
    }
    std::fs::write(folder.join("resample_inputs.bin"), bytemuck::cast_slice(&resample)).unwrap();
}

/// Runs the C program's `route` with `settings`; its frames, or its message.
fn run_c(
    program: &Path,
    route: &str,
    package: &Path,
    histogram: &str,
    settings: SelectionSettings,
    folder: &Path,
) -> Result<Frames, String> {
    run_c_sized(program, route, package, histogram, settings, folder, (WIDTH, HEIGHT))
}

/// [`run_c`] for an image of `size`, whose inputs are in `folder`.
fn run_c_sized(
    program: &Path,
    route: &str,
    package: &Path,
    histogram: &str,
    settings: SelectionSettings,
    folder: &Path,
    (width, height): (u32, u32),
) -> Result<Frames, String> {
    let out = folder.join(format!("{route}-{histogram}-{}-{}", settings.candidates, settings.sampler.name()));
    std::fs::create_dir_all(&out).unwrap();
    let number = |v: u32| v.to_string();
    let output = Command::new(program)
        .args([route, folder.to_str().unwrap(), out.to_str().unwrap()])
        .args(["--package", package.to_str().unwrap(), "--histogram", histogram])
        .args(["--width", &number(width), "--height", &number(height), "--frames", &number(FRAMES)])
        .args(["--seed", &number(SEED), "--block-size", &number(settings.block_size)])
        .args(["--candidates", &number(settings.candidates), "--sampler", &number(settings.sampler.id())])
        .args([
            "--masking",
            &number(u32::from(settings.masking)),
            "--block-shift",
            &number(u32::from(settings.block_shift)),
        ])
        .env("XDG_RUNTIME_DIR", NO_DISPLAY)
        // cargo's LD_LIBRARY_PATH names target/debug, whose libstrata_vk.so only a build of
        // the workspace refreshes: the program finds the library by its rpath instead
        // (`library_folder`, the one this test binary was built with).
        .env_remove("LD_LIBRARY_PATH")
        .output()
        .unwrap();
    if !output.status.success() {
        return Err(String::from_utf8_lossy(&output.stderr).into_owned());
    }
    std::fs::write(out.join("stderr.txt"), &output.stderr).unwrap();
    Ok((0..FRAMES)
        .map(|frame| {
            let read = |name: &str| std::fs::read(out.join(format!("{name}_{frame}.bin"))).unwrap();
            (bytemuck::pod_collect_to_vec(&read("selections")), bytemuck::pod_collect_to_vec(&read("resampled")))
        })
        .collect())
}

/// The histogram kernel strata's rule (`KernelId::fastest_histogram`) picks for blocks of
/// `block_size` on the Vulkan device the C program opens (the first one).
fn fastest_histogram_of_the_device(block_size: u32) -> String {
    use ash::vk;
    let engine = strata_tests::AshEngine::open_plain("fastest_histogram_of_the_device").unwrap();
    let mut subgroup = vk::PhysicalDeviceSubgroupProperties::default();
    let mut properties = vk::PhysicalDeviceProperties2::default().push_next(&mut subgroup);
    // SAFETY: a live instance and one of its physical devices.
    unsafe { engine.instance.get_physical_device_properties2(engine.physical_device, &mut properties) };
    let device_type = properties.properties.device_type;
    let shuffles = subgroup.supported_stages.contains(vk::ShaderStageFlags::COMPUTE)
        && subgroup.supported_operations.contains(vk::SubgroupFeatureFlags::BASIC | vk::SubgroupFeatureFlags::SHUFFLE);
    let executor = strata_kernels::Executor::of_device(&format!("{device_type:?}"), false);
    let kernel = strata_kernels::KernelId::fastest_histogram(block_size, shuffles, executor);
    strata_kernels::Registry::shared().unwrap().get(kernel).name().to_string()
}

#[test]
fn both_c_routes_equal_the_rust_pass_bit_for_bit() {
    let Some((device, queue)) = engine_device("both_c_routes_equal_the_rust_pass_bit_for_bit", None) else {
        return;
    };
    let folder = scratch("routes");
    let package = folder.join("package");
    strata_export::export(&package).unwrap();
    let program = build_c(&package, &folder).unwrap_or_else(|e| panic!("the C program does not build:\n{e}"));
    write_inputs(&folder);
    // A second image size, a multiple of the block (45 × 29 is not), in its own folder.
    let multiple = (64, 32);
    let second = folder.join("64x32");
    std::fs::create_dir_all(&second).unwrap();
    write_engine_inputs(&second, true, multiple);
    let mut runs = 0;
    for sampler in [SamplerVariant::Antithetic, SamplerVariant::Random] {
        for candidates in 1..=4 {
            let settings =
                SelectionSettings { block_size: 8, candidates, sampler, block_shift: true, ..Default::default() };
            for (size, inputs) in [((WIDTH, HEIGHT), &folder), (multiple, &second)] {
                let want = wgpu_frames_sized(&device, &queue, settings, true, size);
                let what = format!("K = {candidates}, {sampler:?}, {}x{}", size.0, size.1);
                let library =
                    run_c_sized(&program, "library", &package, "block_histogram", settings, inputs, size).unwrap();
                assert_eq!(first_frame_difference(&library, &want), None, "route 2 (library), {what}");
                // Route 1 (the manifest alone) with every histogram kernel (the same output).
                for histogram in ["block_histogram", "block_histogram_rank", "block_histogram_subgroup"] {
                    let package_route = run_c_sized(&program, "package", &package, histogram, settings, inputs, size)
                        .unwrap_or_else(|e| panic!("route 1 ({histogram}), {what}: {e}"));
                    assert_eq!(first_frame_difference(&package_route, &want), None, "route 1 ({histogram}), {what}");
                    runs += 1;
                }
            }
        }
    }
    assert_eq!(runs, 2 * 4 * 2 * 3);
    // Route 1 choosing its histogram kernel by the manifest's `histogram_choice`: the
    // kernel strata's own rule picks for this device, and the same output.
    let settings = SelectionSettings { block_size: 8, candidates: 3, block_shift: true, ..Default::default() };
    let want = wgpu_frames(&device, &queue, settings);
    let auto = run_c(&program, "package", &package, "auto", settings, &folder).unwrap();
    assert_eq!(first_frame_difference(&auto, &want), None, "route 1, histogram_choice");
    let said = std::fs::read_to_string(folder.join("package-auto-3-antithetic/stderr.txt")).unwrap();
    let chosen = fastest_histogram_of_the_device(8);
    assert!(said.contains(&format!("histogram_choice: {chosen}\n")), "{said} (strata's rule: {chosen})");
    // Without a payloads buffer (a pixel's payload is its index), by both routes.
    let bare = folder.join("no-payloads");
    std::fs::create_dir_all(&bare).unwrap();
    write_inputs_with(&bare, false);
    let settings = SelectionSettings { block_size: 16, candidates: 4, ..Default::default() };
    let want = wgpu_frames_with(&device, &queue, settings, false);
    for route in ["library", "package"] {
        let got = run_c(&program, route, &package, "block_histogram", settings, &bare).unwrap();
        assert_eq!(first_frame_difference(&got, &want), None, "route {route} without payloads");
    }
    let _ = std::fs::remove_dir_all(&folder);
}

#[test]
fn a_wrong_binding_number_in_the_manifest_or_offset_in_the_header_is_caught() {
    let Some((device, queue)) =
        engine_device("a_wrong_binding_number_in_the_manifest_or_offset_in_the_header_is_caught", None)
    else {
        return;
    };
    let folder = scratch("broken");
    let package = folder.join("package");
    strata_export::export(&package).unwrap();
    let program = build_c(&package, &folder).unwrap();
    write_inputs(&folder);
    let settings = SelectionSettings { block_size: 8, candidates: 4, ..Default::default() };
    let want = wgpu_frames(&device, &queue, settings);
    assert_eq!(
        first_frame_difference(
            &run_c(&program, "package", &package, "block_histogram", settings, &folder).unwrap(),
            &want
        ),
        None
    );
    // strata_select's `sorted_pixels` and `spans` swap binding numbers in the manifest.
    let manifest_path = package.join("manifest.json");
    let original = std::fs::read_to_string(&manifest_path).unwrap();
    let mut manifest: serde_json::Value = serde_json::from_str(&original).unwrap();
    let select = manifest["kernels"].as_array_mut().unwrap().iter_mut().find(|k| k["name"] == "strata_select").unwrap();
    let bindings = select["bindings"].as_array_mut().unwrap();
    let number = |name: &str| bindings.iter().position(|b| b["name"] == name).unwrap();
    let (a, b) = (number("sorted_pixels"), number("spans"));
    let (binding_a, binding_b) = (bindings[a]["binding"].clone(), bindings[b]["binding"].clone());
    bindings[a]["binding"] = binding_b;
    bindings[b]["binding"] = binding_a;
    std::fs::write(&manifest_path, serde_json::to_string_pretty(&manifest).unwrap()).unwrap();
    let swapped = run_c(&program, "package", &package, "block_histogram", settings, &folder)
        .expect("a swapped binding of two storage buffers still runs (the sizes fit): only its outputs are wrong");
    assert!(first_frame_difference(&swapped, &want).is_some(), "a swapped binding went unnoticed");
    // A manifest of another schema version: refused by the reader, naming it.
    manifest["schema_version"] = serde_json::json!(strata_export::manifest::SCHEMA_VERSION + 1);
    std::fs::write(&manifest_path, serde_json::to_string_pretty(&manifest).unwrap()).unwrap();
    let Err(error) = run_c(&program, "package", &package, "block_histogram", settings, &folder) else {
        panic!("a manifest of another schema version must be refused");
    };
    assert!(error.contains("schema_version"), "{error}");
    std::fs::write(&manifest_path, original).unwrap();
    // strata.h of another major version: the program builds, and the library refuses it
    // at create, naming the header's version.
    let header_path = package.join("include/strata.h");
    let header = std::fs::read_to_string(&header_path).unwrap();
    let major: u32 = env!("CARGO_PKG_VERSION_MAJOR").parse().unwrap();
    let newer = header.replacen(
        &format!("#define STRATA_VERSION_MAJOR {major}\n"),
        &format!("#define STRATA_VERSION_MAJOR {}\n", major + 1),
        1,
    );
    assert_ne!(newer, header, "strata.h declares STRATA_VERSION_MAJOR as the workspace's major version");
    std::fs::write(&header_path, newer).unwrap();
    let newer_program = build_c(&package, &folder).unwrap();
    let Err(error) = run_c(&newer_program, "library", &package, "block_histogram", settings, &folder) else {
        panic!("headers of another major version must be refused");
    };
    assert!(error.contains("header_version") && error.contains(env!("CARGO_PKG_VERSION")), "{error}");
    std::fs::write(&header_path, &header).unwrap();
    // A field of StrataSelectedCandidates moved in strata.h: the build fails on its assert.
    let moved = header.replacen("    uint32_t run_length;\n", "    uint32_t spare;\n    uint32_t run_length;\n", 1);
    assert_ne!(moved, header, "the header declares StrataSelectedCandidates.run_length");
    std::fs::write(&header_path, moved).unwrap();
    let error = build_c(&package, &folder).expect_err("a moved field must not build");
    assert!(error.contains("StrataSelectedCandidates"), "{error}");
    let _ = std::fs::remove_dir_all(&folder);
}

#[test]
fn the_manifest_is_naga_s_reflection_of_every_kernel() {
    let folder = scratch("manifest");
    let package = folder.join("package");
    let exported = strata_export::export(&package).unwrap();
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(package.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(manifest["schema_version"], strata_export::manifest::SCHEMA_VERSION);
    let kernels = manifest["kernels"].as_array().unwrap();
    assert_eq!(kernels.len(), ModuleId::ALL.len());
    for id in ModuleId::ALL {
        let reflected = module(id).unwrap();
        let kernel = kernels.iter().find(|k| k["entry_point"]["wgsl"] == reflected.entry_point.as_str()).unwrap();
        assert_eq!(kernel["workgroup_size"], serde_json::json!(reflected.workgroup_size), "{id:?}");
        assert_eq!(kernel["workgroup_memory_bytes"], reflected.workgroup_memory_bytes, "{id:?}");
        assert_eq!(kernel["required_features"].as_array().unwrap().is_empty(), !reflected.needs_subgroups, "{id:?}");
        let bindings = kernel["bindings"].as_array().unwrap();
        assert_eq!(bindings.len(), reflected.bindings.len(), "{id:?}");
        for (entry, binding) in bindings.iter().zip(&reflected.bindings) {
            let what = format!("{id:?} `{}`", binding.name);
            assert_eq!(entry["name"], binding.name.as_str(), "{what}");
            assert_eq!(
                (entry["set"].as_u64(), entry["binding"].as_u64()),
                (Some(0), Some(u64::from(binding.binding))),
                "{what}"
            );
            assert_eq!(entry["descriptor_type"] == "uniform_buffer", binding.uniform, "{what}");
            assert_eq!(entry["access"] == "read_write", binding.writable, "{what}");
            assert_eq!(entry["element"], binding.element.as_str(), "{what}");
            assert_eq!(entry["stride"], binding.stride, "{what}");
            assert_eq!(entry["msl_buffer"], binding.binding, "{what}");
            let register = entry["hlsl"]["register"].as_str().unwrap();
            let class = if binding.uniform {
                'b'
            } else if binding.writable {
                'u'
            } else {
                't'
            };
            assert!(register.starts_with(class), "{what}: {register}");
            // Every file the entry names exists, and the HLSL declares the register.
            let hlsl = std::fs::read_to_string(package.join(kernel["files"]["hlsl"].as_str().unwrap())).unwrap();
            let declared = format!("{} : register({register}, space0)", binding.name);
            assert!(hlsl.contains(&declared), "{what}: `{declared}` not in the HLSL");
            let metal = std::fs::read_to_string(package.join(kernel["files"]["msl"].as_str().unwrap())).unwrap();
            let parameter = format!("{} [[buffer({})]]", binding.name, binding.binding);
            assert!(metal.contains(&parameter), "{what}: `{parameter}` not in the MSL");
            let glsl = std::fs::read_to_string(package.join(kernel["files"]["glsl"].as_str().unwrap())).unwrap();
            assert!(glsl.contains(&format!("set = 0, binding = {})", binding.binding)), "{what}: GLSL has no set");
        }
        let spirv = std::fs::read(package.join(kernel["files"]["spirv"].as_str().unwrap())).unwrap();
        assert_eq!(&spirv[..4], &0x0723_0203u32.to_le_bytes(), "{id:?}: not SPIR-V");
        // The MSL sizes buffer's members, read from the .metal file (`sizeN`: global N of
        // the kernel's module), in the manifest's order.
        let metal = std::fs::read_to_string(package.join(kernel["files"]["msl"].as_str().unwrap())).unwrap();
        let registry_kernel = strata_kernels::Registry::shared().unwrap().get(id.kernel());
        let globals: Vec<String> =
            registry_kernel.module.global_variables.iter().map(|(_, g)| g.name.clone().unwrap_or_default()).collect();
        let members: Vec<String> = metal
            .split("struct _mslBufferSizes {")
            .nth(1)
            .map(|body| body.split("};").next().unwrap_or(""))
            .unwrap_or("")
            .lines()
            .filter_map(|l| l.trim().strip_prefix("uint size")?.strip_suffix(';')?.parse::<usize>().ok())
            .map(|i| globals[i].clone())
            .collect();
        let listed: Vec<String> = kernel["msl_sizes_buffer"]["sized_bindings"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_str().unwrap().to_string())
            .collect();
        assert_eq!(listed, members, "{id:?}: the MSL sizes buffer's order");
        // The GLSL for Vulkan compiles with glslang as such (`-V`), sets and all; the SPIR-V
        // passes spirv-val for Vulkan 1.1.
        let glsl = package.join(kernel["files"]["glsl"].as_str().unwrap());
        let compiled = folder.join(format!("{}.glsl.spv", reflected.entry_point));
        for (tool, args) in [
            (
                "glslangValidator",
                vec![
                    "-V".into(),
                    "--target-env".into(),
                    "vulkan1.1".into(),
                    "-S".into(),
                    "comp".into(),
                    glsl.clone().into_os_string(),
                    "-o".into(),
                    compiled.into_os_string(),
                ],
            ),
            (
                "spirv-val",
                vec![
                    "--target-env".into(),
                    "vulkan1.1".into(),
                    package.join(kernel["files"]["spirv"].as_str().unwrap()).into_os_string(),
                ],
            ),
        ] {
            let args: Vec<std::ffi::OsString> = args;
            match strata_kernels::glslang::run_tool(tool, &args.iter().map(|a| a.as_os_str()).collect::<Vec<_>>()) {
                Ok(()) => {}
                Err(strata_kernels::glslang::ToolError::Missing(tool))
                    if std::env::var_os("STRATA_REQUIRE_VALIDATORS").is_none() =>
                {
                    eprintln!("SKIPPED {tool} of {id:?}: not installed");
                }
                Err(error) => panic!("{id:?}: {error}"),
            }
        }
    }
    // The buffers cover every binding, and every struct's size is its Rust twin's.
    let buffers: Vec<&str> =
        manifest["buffers"].as_array().unwrap().iter().map(|b| b["name"].as_str().unwrap()).collect();
    for kernel in kernels {
        for binding in kernel["bindings"].as_array().unwrap() {
            assert!(buffers.contains(&binding["buffer"].as_str().unwrap()), "{binding}");
        }
    }
    // Every struct's field offsets and size as naga lays the WGSL struct out.
    for entry in manifest["structs"].as_array().unwrap() {
        let name = entry["name"].as_str().unwrap();
        let registry = strata_kernels::Registry::shared().unwrap();
        let (module, handle) = registry
            .kernels()
            .iter()
            .find_map(|k| {
                k.module.types.iter().find(|(_, t)| t.name.as_deref() == Some(name)).map(|(h, _)| (&k.module, h))
            })
            .unwrap_or_else(|| panic!("no kernel declares {name}"));
        let mut layouter = naga::proc::Layouter::default();
        layouter.update(module.to_ctx()).unwrap();
        assert_eq!(entry["size"], layouter[handle].size, "{name}");
        let naga::TypeInner::Struct { members, .. } = &module.types[handle].inner else { panic!("{name}") };
        let fields = entry["fields"].as_array().unwrap();
        assert_eq!(fields.len(), members.len(), "{name}");
        for (field, member) in fields.iter().zip(members) {
            assert_eq!(field["name"], member.name.as_deref().unwrap(), "{name}");
            assert_eq!(field["offset"], member.offset, "{name}.{}", field["name"]);
        }
    }
    let size = |name: &str| {
        manifest["structs"].as_array().unwrap().iter().find(|s| s["name"] == name).unwrap()["size"].clone()
    };
    assert_eq!(size("SelectedCandidates"), size_of::<SelectedCandidates>());
    assert_eq!(size("ResampleInput"), size_of::<ResampleInput>());
    assert!(exported.files.iter().any(|f| f == "data/blue_noise.bin"));
    let _ = std::fs::remove_dir_all(&folder);
}

#[test]
fn the_headers_compile_as_strict_c11_and_cpp() {
    let folder = scratch("headers");
    let package = folder.join("package");
    strata_export::export(&package).unwrap();
    let source = folder.join("headers.c");
    std::fs::write(
        &source,
        "#include \"strata_vk.h\"\nint main(void) { return (int)sizeof(StrataFrameParams) == 0; }\n",
    )
    .unwrap();
    for (compiler, standard) in [("cc", "-std=c11"), ("c++", "-std=c++17")] {
        let mut command = Command::new(compiler);
        command.arg(standard).args(["-Wall", "-Wextra", "-Werror", "-fsyntax-only", "-I"]).arg(package.join("include"));
        if compiler == "c++" {
            command.args(["-x", "c++"]);
        }
        let output = command.arg(&source).output().unwrap_or_else(|e| panic!("{compiler}: {e}"));
        assert!(output.status.success(), "{compiler} {standard}:\n{}", String::from_utf8_lossy(&output.stderr));
    }
    let _ = std::fs::remove_dir_all(&folder);
}

#[test]
fn the_export_refuses_a_folder_that_is_not_a_package() {
    let folder = scratch("refuse");
    std::fs::write(folder.join("notes.txt"), "the user's").unwrap();
    let message = strata_export::export(&folder).unwrap_err().to_string();
    assert!(message.contains("--out") && message.contains("other files"), "{message}");
    assert!(folder.join("notes.txt").exists());
    let file = folder.join("notes.txt");
    let message = strata_export::export(&file).unwrap_err().to_string();
    assert!(message.contains("not a folder"), "{message}");
    // An earlier package is replaced whole; one with a file of the user's added is not.
    let package = folder.join("package");
    strata_export::export(&package).unwrap();
    strata_export::export(&package).unwrap();
    assert!(package.join("manifest.json").is_file());
    std::fs::write(package.join("engine.cmake"), "the user's").unwrap();
    let message = strata_export::export(&package).unwrap_err().to_string();
    assert!(message.contains("`engine.cmake` added to it"), "{message}");
    assert!(package.join("engine.cmake").exists() && package.join("manifest.json").exists());
    let message = strata_export::export(&package.join("..")).unwrap_err().to_string();
    assert!(message.contains("own name"), "{message}");
    let _ = std::fs::remove_dir_all(&folder);
}

/// The error as `xtask` prints it: the message and each cause, `: `-separated (anyhow's
/// `{:#}`).
fn printed(error: &dyn std::error::Error) -> String {
    let mut text = error.to_string();
    let mut cause = error.source();
    while let Some(inner) = cause {
        text = format!("{text}: {inner}");
        cause = inner.source();
    }
    text
}

/// Only the files an earlier package's manifest lists (and the files every package has)
/// may be replaced: a file or folder the user added anywhere below is refused by name
/// before any work, and stays.
#[test]
fn the_export_refuses_a_package_with_the_user_s_files_below_it() {
    let folder = scratch("refuse-below");
    let package = folder.join("package");
    strata_export::export(&package).unwrap();
    for added in ["include/engine.h", "kernels/spirv/mine.spv", "data/extra.bin", "kernels/custom/notes.txt"] {
        let path = package.join(added);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(&path, "the user's").unwrap();
        let message = printed(&strata_export::export(&package).unwrap_err());
        let named = if added.starts_with("kernels/custom") { "kernels/custom" } else { added };
        assert!(message.contains(&format!("`{named}")), "{added}: {message}");
        assert!(path.exists(), "{added} was deleted");
        std::fs::remove_file(&path).unwrap();
        if added.starts_with("kernels/custom") {
            std::fs::remove_dir(path.parent().unwrap()).unwrap();
        }
    }
    // An empty folder the user made is theirs too.
    std::fs::create_dir(package.join("include/mine")).unwrap();
    let message = printed(&strata_export::export(&package).unwrap_err());
    assert!(message.contains("`include/mine"), "{message}");
    std::fs::remove_dir(package.join("include/mine")).unwrap();
    strata_export::export(&package).unwrap();
    let _ = std::fs::remove_dir_all(&folder);
}

/// `--out pkg/.` (and `pkg/..`) is refused before any work, not after it with EBUSY; a
/// failed write names the user's `--out` once and the OS error once, never the
/// temporary folder beside it.
#[test]
fn export_errors_name_the_out_folder_once_and_nothing_temporary() {
    let folder = scratch("errors");
    let package = folder.join("package");
    strata_export::export(&package).unwrap();
    for dotted in ["package/.", "package/./", "package/.."] {
        let out = PathBuf::from(format!("{}/{dotted}", folder.display()));
        let message = printed(&strata_export::export(&out).unwrap_err());
        assert!(message.contains("own name"), "{dotted}: {message}");
    }
    let leftovers: Vec<String> = std::fs::read_dir(&folder)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n != "package")
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
    // The temporary folder's name (`.NAME.tmp-` and 10 random characters) is past the
    // 255 bytes a file name may have: making it fails.
    let long = folder.join("p".repeat(245));
    let message = printed(&strata_export::export(&long).unwrap_err());
    assert!(!message.contains(".tmp-") && message.matches("os error 36").count() == 1, "{message}");
    assert_eq!(message.matches(&"p".repeat(245)).count(), 1, "{message}");
    // Deep enough that the files inside the temporary folder pass PATH_MAX (4096 bytes):
    // writing them fails.
    let mut deep = folder.clone();
    while deep.as_os_str().len() < 4000 {
        deep = deep.join("d".repeat(200));
    }
    let deep = deep.parent().unwrap().join("d".repeat(4040 - deep.parent().unwrap().as_os_str().len()));
    std::fs::create_dir_all(&deep).unwrap();
    let out = deep.join("pkg");
    let message = printed(&strata_export::export(&out).unwrap_err());
    assert!(!message.contains(".tmp-") && message.matches("os error 36").count() == 1, "{message}");
    assert_eq!(message.matches(&out.display().to_string()).count(), 1, "{message}");
    assert!(!message.contains('\n'), "{message}");
    let _ = std::fs::remove_dir_all(&folder);
}

/// Frame parameters of `strata_frame.h` against `strata_kernels::pass_plan::frame_params` for
/// many settings, sizes, frames, seeds and workgroup limits, byte for byte.
#[test]
fn strata_frame_h_computes_what_frame_rs_does() {
    use strata_kernels::pass_plan::{FrameId, frame_params};
    let folder = scratch("frame");
    let package = folder.join("package");
    strata_export::export(&package).unwrap();
    let source = folder.join("frame.c");
    std::fs::write(
        &source,
        r#"#include <stdio.h>
#include "strata_frame.h"
int main(void) {
    unsigned b, k, s, m, bs, w, h, f, seed, id, mw;
    while (scanf("%u %u %u %u %u %u %u %u %u %u %u", &b, &k, &s, &m, &bs, &w, &h, &f, &seed, &id, &mw) == 11) {
        StrataSelectionSettings settings = {b, k, s, m, bs};
        StrataFrameParams p;
        char message[128];
        if (strata_frame_params(&settings, w, h, f, seed, id, mw, &p, message, sizeof message)) {
            printf("error %s\n", message);
            continue;
        }
        const unsigned char *bytes = (const unsigned char *)&p;
        for (size_t i = 0; i < sizeof p; i++) printf("%02x", bytes[i]);
        printf(" %llu\n", (unsigned long long)strata_max_blocks(&settings, w, h));
    }
    return 0;
}
"#,
    )
    .unwrap();
    let program = folder.join("frame");
    let built = Command::new("cc")
        .args(["-std=c11", "-Wall", "-Wextra", "-Werror", "-I"])
        .arg(package.join("include"))
        .arg(&source)
        .arg("-o")
        .arg(&program)
        .output()
        .unwrap();
    assert!(built.status.success(), "{}", String::from_utf8_lossy(&built.stderr));
    // Cases: every block size, K, sampler and flag, sizes from 1 pixel to 4096 wide, frames
    // and seeds from a generator, workgroup limits from 1 up.
    let mut state = 0x2545_f491_u64;
    let mut next = |range: u32| {
        state = state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
        ((state >> 33) as u32) % range
    };
    let mut cases = Vec::new();
    for case in 0..600u32 {
        let settings = SelectionSettings {
            block_size: [4, 8, 16, 32][case as usize % 4],
            candidates: 1 + case / 4 % 4,
            masking: case % 3 == 0,
            block_shift: case % 2 == 1,
            sampler: SamplerVariant::ALL[case as usize % SamplerVariant::ALL.len()],
        };
        let (width, height) = match case % 5 {
            0 => (1, 1),
            1 => (1 + next(4096), 1 + next(8)),
            _ => (1 + next(700), 1 + next(500)),
        };
        let id = FrameId { frame: next(u32::MAX), seed: next(u32::MAX), identity_payload: case % 7 == 0 };
        let max_workgroups = [1, 3, 65535, 8][case as usize % 4];
        cases.push((settings, width, height, id, max_workgroups));
    }
    let input: String = cases
        .iter()
        .map(|(s, w, h, id, mw)| {
            format!(
                "{} {} {} {} {} {w} {h} {} {} {} {mw}\n",
                s.block_size,
                s.candidates,
                s.sampler.id(),
                u32::from(s.masking),
                u32::from(s.block_shift),
                id.frame,
                id.seed,
                u32::from(id.identity_payload)
            )
        })
        .collect();
    let mut child = Command::new(&program)
        .env("XDG_RUNTIME_DIR", NO_DISPLAY)
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    use std::io::Write;
    child.stdin.take().unwrap().write_all(input.as_bytes()).unwrap();
    let output = child.wait_with_output().unwrap();
    let lines: Vec<String> = String::from_utf8(output.stdout).unwrap().lines().map(String::from).collect();
    assert_eq!(lines.len(), cases.len());
    for ((settings, width, height, id, max_workgroups), line) in cases.iter().zip(&lines) {
        let params = frame_params(settings, *width, *height, *id, *max_workgroups).unwrap();
        let mut bytes = bytemuck::bytes_of(&params.histogram).to_vec();
        bytes.extend_from_slice(bytemuck::bytes_of(&params.selection));
        bytes.extend(params.histogram_workgroups.iter().chain(&params.pixel_workgroups).flat_map(|w| w.to_le_bytes()));
        let hex: String = bytes.iter().map(|b| format!("{b:02x}")).collect();
        let blocks = strata_kernels::pass_plan::max_blocks(settings, *width, *height);
        assert_eq!(line, &format!("{hex} {blocks}"), "{settings:?} {width}x{height} {id:?} max {max_workgroups}");
    }
    // Bad settings are refused by both, naming the field in C as in Rust.
    let refused = Command::new(&program)
        .env("XDG_RUNTIME_DIR", NO_DISPLAY)
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .spawn()
        .and_then(|mut child| {
            child
                .stdin
                .take()
                .unwrap()
                .write_all(b"12 4 4 1 0 8 8 0 0 0 1\n4 5 4 1 0 8 8 0 0 0 1\n4 4 9 1 0 8 8 0 0 0 1\n")?;
            child.wait_with_output()
        })
        .unwrap();
    // The messages are Rust's own (`SelectionSettings::validate`) where Rust has the field.
    let rust = |settings: SelectionSettings| format!("error {}", settings.validate().unwrap_err());
    let expected = [
        rust(SelectionSettings { block_size: 12, ..SelectionSettings::default() }),
        rust(SelectionSettings { block_size: 4, candidates: 5, ..SelectionSettings::default() }),
        format!("error sampler = 9: must be a StrataSampler (0 to {})", SamplerVariant::ALL.len() - 1),
    ];
    let said: Vec<&str> = std::str::from_utf8(&refused.stdout).unwrap().lines().collect();
    assert_eq!(said, expected);
    let _ = std::fs::remove_dir_all(&folder);
}

/// The package's HLSL, as exported, compiled by a second front end (Slang, not the
/// glslang whose HLSL bugs strata works around) and run through route 1 in place of
/// naga's SPIR-V: the same outputs as the Rust pass, bit for bit.
#[test]
fn the_exported_hlsl_compiled_by_slang_equals_the_rust_pass() {
    let Some((device, queue)) = engine_device("the_exported_hlsl_compiled_by_slang_equals_the_rust_pass", None) else {
        return;
    };
    let folder = scratch("slang");
    let package = folder.join("package");
    strata_export::export(&package).unwrap();
    let manifest_path = package.join("manifest.json");
    let mut manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&manifest_path).unwrap()).unwrap();
    for kernel in manifest["kernels"].as_array_mut().unwrap() {
        let hlsl = package.join(kernel["files"]["hlsl"].as_str().unwrap());
        let entry = kernel["entry_point"]["hlsl"].as_str().unwrap().to_string();
        let words = match strata_kernels::slang::compile_hlsl(&hlsl, &entry) {
            Ok(words) => words,
            Err(strata_kernels::glslang::ToolError::Missing(what))
                if std::env::var_os("STRATA_REQUIRE_VALIDATORS").is_none() =>
            {
                eprintln!("SKIPPED: {what} (STRATA_REQUIRE_VALIDATORS=1 makes this a failure)");
                return;
            }
            Err(error) => panic!("{}: {error}", kernel["name"]),
        };
        std::fs::write(package.join(kernel["files"]["spirv"].as_str().unwrap()), bytemuck::cast_slice(&words)).unwrap();
        kernel["entry_point"]["spirv"] = entry.into();
    }
    std::fs::write(&manifest_path, serde_json::to_string_pretty(&manifest).unwrap()).unwrap();
    let program = build_c(&package, &folder).unwrap();
    write_inputs(&folder);
    let histograms = ["block_histogram", "block_histogram_rank", "block_histogram_subgroup"];
    for (candidates, sampler) in [
        (1, SamplerVariant::Antithetic),
        (2, SamplerVariant::Antithetic),
        (3, SamplerVariant::Random),
        (4, SamplerVariant::Antithetic),
    ] {
        let settings =
            SelectionSettings { block_size: 8, candidates, sampler, block_shift: true, ..Default::default() };
        let want = wgpu_frames(&device, &queue, settings);
        let histogram = histograms[candidates as usize % 3];
        let got = run_c(&program, "package", &package, histogram, settings, &folder)
            .unwrap_or_else(|e| panic!("Slang's SPIR-V of {histogram}: {e}"));
        assert_eq!(
            first_frame_difference(&got, &want),
            None,
            "Slang's SPIR-V, {histogram}, K = {candidates}, {sampler:?}"
        );
    }
    let _ = std::fs::remove_dir_all(&folder);
}

/// Runs `command`; its stdout, or a panic with the command and its output.
fn run_tool(command: &mut Command) -> String {
    let output = command.output().unwrap_or_else(|e| panic!("{command:?}: {e}"));
    let text = |bytes: &[u8]| String::from_utf8_lossy(bytes).into_owned();
    assert!(output.status.success(), "{command:?}:\n{}\n{}", text(&output.stdout), text(&output.stderr));
    text(&output.stdout)
}

/// Whether `tool` runs; if not, a panic where CI requires it (STRATA_REQUIRE_GPU, which
/// CI sets for every test needing an outside tool), else false (the test is skipped).
fn tool_present(tool: &str, test: &str) -> bool {
    if Command::new(tool).arg("--version").output().is_ok_and(|o| o.status.success()) {
        return true;
    }
    assert!(
        std::env::var_os("STRATA_REQUIRE_GPU").is_none(),
        "{test}: `{tool}` is not installed (STRATA_REQUIRE_GPU is set; apt-get install cmake pkgconf)"
    );
    eprintln!("SKIPPED {test}: `{tool}` is not installed");
    false
}

#[test]
fn the_package_builds_with_cmake_both_ways_and_pkg_config_resolves() {
    let test = "the_package_builds_with_cmake_both_ways_and_pkg_config_resolves";
    if !["cmake", "pkg-config", "c++"].iter().all(|tool| tool_present(tool, test)) {
        return;
    }
    let scratch = strata_files::private_scratch_folder("strata-cmake-").unwrap();
    let package = scratch.path().join("package");
    strata_export::export(&package).unwrap();
    let library = library_folder().join("libstrata_vk.so");
    let source = package.join("examples/cpp");
    let path = |p: &Path| p.to_str().unwrap().to_string();
    // The C++17 consumer, configured by find_package and by add_subdirectory, built and run.
    for (way, setting) in [
        ("find_package", format!("-DCMAKE_PREFIX_PATH={}", path(&package))),
        ("add_subdirectory", format!("-DSTRATA_PACKAGE={}", path(&package))),
    ] {
        let build = scratch.path().join(way);
        run_tool(
            Command::new("cmake")
                .args(["-S", &path(&source), "-B", &path(&build), &setting])
                .arg(format!("-DSTRATA_VK_LIBRARY={}", path(&library))),
        );
        run_tool(Command::new("cmake").args(["--build", &path(&build)]));
        let said = run_tool(
            Command::new(build.join("strata_consumer"))
                .env_remove("LD_LIBRARY_PATH")
                .env("XDG_RUNTIME_DIR", NO_DISPLAY),
        );
        assert!(said.ends_with(": ok\n") && said.contains(env!("CARGO_PKG_VERSION")), "{way}: {said}");
    }
    // find_package asking for the next major version is refused by strataConfigVersion.cmake.
    let newer = scratch.path().join("newer");
    std::fs::create_dir(&newer).unwrap();
    let major: u32 = env!("CARGO_PKG_VERSION_MAJOR").parse().unwrap();
    std::fs::write(
        newer.join("CMakeLists.txt"),
        format!("cmake_minimum_required(VERSION 3.16)\nproject(newer LANGUAGES NONE)\nfind_package(strata {}.0 CONFIG REQUIRED)\n", major + 1),
    )
    .unwrap();
    let refused = Command::new("cmake")
        .args(["-S", &path(&newer), "-B", &path(&newer.join("build"))])
        .arg(format!("-DCMAKE_PREFIX_PATH={}", path(&package)))
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&refused.stderr);
    assert!(!refused.status.success() && text.contains(env!("CARGO_PKG_VERSION")), "{text}");
    // pkg-config resolves the flags, and they build the same consumer.
    let flags = run_tool(
        Command::new("pkg-config")
            .args(["--cflags", "--libs", "strata"])
            .env("PKG_CONFIG_PATH", package.join("lib/pkgconfig")),
    );
    let include = package.join("include").canonicalize().unwrap();
    let includes = |flag: &str| flag.strip_prefix("-I").and_then(|p| Path::new(p).canonicalize().ok());
    assert!(flags.split_whitespace().any(|f| includes(f).as_ref() == Some(&include)), "{flags}: no -I of include/");
    assert!(flags.split_whitespace().any(|f| f == "-lstrata_vk"), "{flags}");
    let program = scratch.path().join("pkg_config_consumer");
    run_tool(
        Command::new("c++")
            .args(["-std=c++17", "-Wall", "-Wextra", "-Werror"])
            .arg(source.join("main.cpp"))
            .arg(format!("-DSTRATA_CONSUMER_SPIRV_DIR=\"{}\"", path(&package.join("kernels/spirv"))))
            .arg(format!("-DSTRATA_CONSUMER_MANIFEST=\"{}\"", path(&package.join("manifest.json"))))
            .args(flags.split_whitespace())
            .arg(format!("-L{}", path(&library_folder())))
            .arg(format!("-Wl,-rpath,{}", path(&library_folder())))
            .arg("-o")
            .arg(&program),
    );
    let said = run_tool(Command::new(&program).env_remove("LD_LIBRARY_PATH").env("XDG_RUNTIME_DIR", NO_DISPLAY));
    assert!(said.ends_with(": ok\n"), "pkg-config: {said}");
}

/// Each record's size and its fields' (name, offset), in order, by struct name.
type Layouts = std::collections::BTreeMap<String, (u64, Vec<(String, u64)>)>;

/// The layouts `strata.h` asserts (`sizeof(StrataX) == N`, `offsetof(StrataX, f) == N`).
fn strata_h_layouts(header: &str) -> Layouts {
    let mut layouts = Layouts::new();
    for line in header.lines().filter_map(|l| l.strip_prefix("STRATA_STATIC_ASSERT(")) {
        let number = |text: &str| text.split(',').next().unwrap().trim().parse::<u64>().unwrap();
        if let Some(rest) = line.strip_prefix("sizeof(") {
            let (name, after) = rest.split_once(") == ").unwrap();
            layouts.entry(name.into()).or_default().0 = number(after);
        } else if let Some(rest) = line.strip_prefix("offsetof(") {
            let (name, after) = rest.split_once(", ").unwrap();
            let (field, after) = after.split_once(") == ").unwrap();
            layouts.entry(name.into()).or_default().1.push((field.into(), number(after)));
        }
    }
    layouts
}

/// The layouts of the `Strata*` structs of a SPIR-V module, from `spirv-dis`'s text:
/// member names and `Offset`s, and the size as the `ArrayStride` of a runtime array of it.
fn spirv_layouts(disassembly: &str) -> Layouts {
    let mut names = std::collections::HashMap::new();
    let mut members: std::collections::HashMap<(String, u64), String> = std::collections::HashMap::new();
    let mut offsets: Vec<(String, u64, u64)> = Vec::new();
    let mut arrays = std::collections::HashMap::new();
    let mut strides = std::collections::HashMap::new();
    for line in disassembly.lines() {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["OpName", id, name] => {
                // Slang names a record's copy laid out for a storage buffer `<name>_std430`.
                let name = name.trim_matches('"');
                names.insert(id.to_string(), name.strip_suffix("_std430").unwrap_or(name).to_string());
            }
            ["OpMemberName", id, index, name] => {
                members.insert((id.to_string(), index.parse().unwrap()), name.trim_matches('"').to_string());
            }
            ["OpMemberDecorate", id, index, "Offset", offset] => {
                offsets.push((id.to_string(), index.parse().unwrap(), offset.parse().unwrap()));
            }
            ["OpDecorate", id, "ArrayStride", stride] => {
                strides.insert(id.to_string(), stride.parse::<u64>().unwrap());
            }
            [array, "=", "OpTypeRuntimeArray", element] => {
                arrays.insert(array.to_string(), element.to_string());
            }
            _ => {}
        }
    }
    let mut layouts = Layouts::new();
    for (id, index, offset) in offsets {
        let Some(name) = names.get(&id).filter(|n| n.starts_with("Strata")) else { continue };
        // A field named by a reserved word has `_` after it in GLSL and HLSL.
        let field = members.get(&(id.clone(), index)).map_or("", |m| m.strip_suffix('_').unwrap_or(m)).to_string();
        let entry = layouts.entry(name.clone()).or_default();
        entry.1.push((field, offset));
        if let Some(stride) = arrays.iter().find(|(_, element)| **element == id).and_then(|(a, _)| strides.get(a)) {
            entry.0 = *stride;
        }
    }
    layouts
}

/// The layouts naga gives the `Strata*` structs of a WGSL module.
fn wgsl_layouts(source: &str) -> Result<Layouts, String> {
    let module = naga::front::wgsl::parse_str(source).map_err(|e| e.emit_to_string(source))?;
    let mut layouter = naga::proc::Layouter::default();
    layouter.update(module.to_ctx()).map_err(|e| e.to_string())?;
    let mut layouts = Layouts::new();
    for (handle, ty) in module.types.iter() {
        if let (Some(name), naga::TypeInner::Struct { members, span }) = (&ty.name, &ty.inner)
            && name.starts_with("Strata")
        {
            let fields = members.iter().map(|m| (m.name.clone().unwrap_or_default(), u64::from(m.offset))).collect();
            assert_eq!(layouter[handle].size, *span);
            layouts.insert(name.clone(), (u64::from(*span), fields));
        }
    }
    Ok(layouts)
}

/// The first difference between `got` (a shader include's layouts) and `want` (strata.h's).
fn layout_difference(got: &Layouts, want: &Layouts) -> Option<String> {
    for (name, (size, fields)) in want {
        let Some((got_size, got_fields)) = got.get(name) else { return Some(format!("{name}: not declared")) };
        if got_fields != fields {
            return Some(format!("{name}: fields {got_fields:?}, strata.h {fields:?}"));
        }
        if got_size != size {
            return Some(format!("{name}: {got_size} bytes, strata.h {size}"));
        }
    }
    None
}

/// The layouts of the records as `language`'s include declares them, compiled by glslang
/// (GLSL, HLSL: a compute shader with a storage buffer of each record, disassembled by
/// spirv-dis), Slang (`hlsl-slang`: the same HLSL shader, Slang's SPIR-V disassembled by
/// spirv-dis) or naga (WGSL); `None` if a tool is missing and not required.
fn include_layouts(
    language: &str,
    include: &Path,
    structs: &[String],
    folder: &Path,
) -> Option<Result<Layouts, String>> {
    let include_text = std::fs::read_to_string(include).unwrap();
    if language == "wgsl" {
        let mut shader = include_text;
        for (i, name) in structs.iter().enumerate() {
            shader += &format!("@group(0) @binding({i}) var<storage, read_write> b{i}: array<{name}>;\n");
        }
        let copies: String = (0..structs.len()).map(|i| format!("    b{i}[0] = b{i}[1];\n")).collect();
        shader += &format!("@compute @workgroup_size(1)\nfn main() {{\n{copies}}}\n");
        return Some(wgsl_layouts(&shader));
    }
    let file_name = include.file_name().unwrap().to_str().unwrap();
    let (source, args): (String, Vec<&str>) = if language == "glsl" {
        let buffers: String = structs
            .iter()
            .enumerate()
            .map(|(i, n)| format!("layout(std430, set = 0, binding = {i}) buffer B{i} {{ {n} r[]; }} b{i};\n"))
            .collect();
        let copies: String = (0..structs.len()).map(|i| format!("    b{i}.r[0] = b{i}.r[1];\n")).collect();
        (
            format!(
                "#version 450\n#extension GL_GOOGLE_include_directive : require\n#include \"{file_name}\"\n\
                 layout(local_size_x = 1) in;\n{buffers}void main() {{\n{copies}}}\n"
            ),
            vec!["-V", "--target-env", "vulkan1.1", "-S", "comp"],
        )
    } else {
        let buffers: String = structs
            .iter()
            .enumerate()
            .map(|(i, n)| format!("RWStructuredBuffer<{n}> b{i} : register(u{i});\n"))
            .collect();
        let copies: String = (0..structs.len()).map(|i| format!("    b{i}[0] = b{i}[1];\n")).collect();
        (
            format!("#include \"{file_name}\"\n{buffers}[numthreads(1, 1, 1)]\nvoid main() {{\n{copies}}}\n"),
            vec!["-D", "-V", "--target-env", "vulkan1.1", "-S", "comp", "-e", "main"],
        )
    };
    let shader = include.with_file_name(format!("layout_{language}.comp"));
    std::fs::write(&shader, source).unwrap();
    let spirv = folder.join(format!("layout_{language}.spv"));
    let text = folder.join(format!("layout_{language}.spvasm"));
    let mut tools = Vec::new();
    if language == "hlsl-slang" {
        match strata_kernels::slang::compile_hlsl(&shader, "main") {
            Ok(words) => std::fs::write(&spirv, bytemuck::cast_slice::<u32, u8>(&words)).unwrap(),
            Err(strata_kernels::glslang::ToolError::Missing(tool))
                if std::env::var_os("STRATA_REQUIRE_VALIDATORS").is_none() =>
            {
                eprintln!("SKIPPED the {language} include's layout: {tool} is not installed");
                return None;
            }
            Err(error) => return Some(Err(format!("{language}: {error}"))),
        }
    } else {
        let mut glslang: Vec<std::ffi::OsString> = args.iter().map(Into::into).collect();
        glslang.extend([shader.clone().into_os_string(), "-o".into(), spirv.clone().into_os_string()]);
        tools.push(("glslangValidator", glslang));
    }
    tools.push(("spirv-dis", vec![spirv.into_os_string(), "-o".into(), text.clone().into_os_string()]));
    for (tool, args) in tools {
        match strata_kernels::glslang::run_tool(tool, &args.iter().map(|a| a.as_os_str()).collect::<Vec<_>>()) {
            Ok(()) => {}
            Err(strata_kernels::glslang::ToolError::Missing(tool))
                if std::env::var_os("STRATA_REQUIRE_VALIDATORS").is_none() =>
            {
                eprintln!("SKIPPED the {language} include's layout: `{tool}` is not installed");
                return None;
            }
            Err(error) => return Some(Err(format!("{language}: {error}"))),
        }
    }
    std::fs::remove_file(&shader).unwrap();
    Some(Ok(spirv_layouts(&std::fs::read_to_string(text).unwrap())))
}

#[test]
fn the_shader_includes_lay_out_every_record_as_strata_h_does() {
    let scratch = strata_files::private_scratch_folder("strata-includes-").unwrap();
    let package = scratch.path().join("package");
    strata_export::export(&package).unwrap();
    let want = strata_h_layouts(&std::fs::read_to_string(package.join("include/strata.h")).unwrap());
    assert!(want.len() >= 8 && want.contains_key("StrataSelectedCandidates"), "{want:?}");
    let structs: Vec<String> = want.keys().cloned().collect();
    let mut checked = 0;
    for (language, file, field, spare) in [
        ("glsl", "strata.glsl", "    uint run_length;\n", "    uint spare;\n"),
        ("hlsl", "strata.hlsli", "    uint run_length;\n", "    uint spare;\n"),
        ("hlsl-slang", "strata.hlsli", "    uint run_length;\n", "    uint spare;\n"),
        ("wgsl", "strata.wgsl", "    run_length: u32,\n", "    spare: u32,\n"),
    ] {
        let include = package.join("include").join(file);
        let Some(got) = include_layouts(language, &include, &structs, scratch.path()) else { continue };
        let got = got.unwrap_or_else(|e| panic!("{file} does not compile: {e}"));
        assert_eq!(layout_difference(&got, &want), None, "{file} against strata.h");
        // One field moved (a spare word before StrataSelectedCandidates.run_length): seen.
        let text = std::fs::read_to_string(&include).unwrap();
        let moved = text.replacen(field, &format!("{spare}{field}"), 1);
        assert_ne!(moved, text, "{file} declares StrataSelectedCandidates.run_length");
        std::fs::write(&include, moved).unwrap();
        let got = include_layouts(language, &include, &structs, scratch.path()).unwrap().unwrap();
        let difference = layout_difference(&got, &want).unwrap_or_default();
        assert!(difference.starts_with("StrataSelectedCandidates"), "{file} with a field moved: {difference:?}");
        std::fs::write(&include, text).unwrap();
        checked += 1;
    }
    if std::env::var_os("STRATA_REQUIRE_VALIDATORS").is_some() {
        assert_eq!(checked, 4);
    }
}

/// Runs route 1 of `program` over `package` with the Khronos validation layer and its
/// synchronization validation on; the layer's output (it prints to stdout and stderr).
fn run_synchronization_validated(program: &Path, package: &Path, inputs: &Path) -> String {
    let out = inputs.join("validated");
    std::fs::create_dir_all(&out).unwrap();
    let output = Command::new(program)
        .args(["package", inputs.to_str().unwrap(), out.to_str().unwrap(), "--package", package.to_str().unwrap()])
        .args(["--width", &WIDTH.to_string(), "--height", &HEIGHT.to_string(), "--frames", "4"])
        .args(["--block-size", "8", "--candidates", "4", "--block-shift", "1", "--histogram", "auto"])
        .env("XDG_RUNTIME_DIR", NO_DISPLAY)
        .env_remove("LD_LIBRARY_PATH")
        .env("VK_INSTANCE_LAYERS", "VK_LAYER_KHRONOS_validation")
        .env("VK_LAYER_ENABLES", "VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT")
        .output()
        .unwrap();
    let text = format!("{}{}", String::from_utf8_lossy(&output.stdout), String::from_utf8_lossy(&output.stderr));
    assert!(output.status.success(), "{text}");
    text
}

#[test]
fn the_manifest_route_is_clean_under_synchronization_validation() {
    let test = "the_manifest_route_is_clean_under_synchronization_validation";
    let Some(_) = engine_device(test, None) else { return };
    let scratch = strata_files::private_scratch_folder("strata-sync-").unwrap();
    let package = scratch.path().join("package");
    strata_export::export(&package).unwrap();
    let program = build_c(&package, scratch.path()).unwrap_or_else(|e| panic!("the C program does not build:\n{e}"));
    write_inputs(scratch.path());
    // The manifest with its barriers taken out: the layer must see the hazards, or it is not
    // running (not installed: skipped unless CI's STRATA_REQUIRE_VALIDATORS).
    let broken = scratch.path().join("no-barriers");
    let manifest_text = std::fs::read_to_string(package.join("manifest.json")).unwrap();
    let mut manifest: serde_json::Value = serde_json::from_str(&manifest_text).unwrap();
    manifest["frame"]["sequence"].as_array_mut().unwrap().retain(|step| step["op"] != "barrier");
    for file in &strata_export::export(&broken).unwrap().files {
        assert!(broken.join(file).exists());
    }
    std::fs::write(broken.join("manifest.json"), serde_json::to_string(&manifest).unwrap()).unwrap();
    let without = run_synchronization_validated(&program, &broken, scratch.path());
    if !without.contains("SYNC-HAZARD") {
        assert!(
            std::env::var_os("STRATA_REQUIRE_VALIDATORS").is_none(),
            "{test}: no hazard reported without barriers: the validation layer did not run (install \
             vulkan-validationlayers)\n{without}"
        );
        eprintln!("SKIPPED {test}: the Khronos validation layer is not installed");
        return;
    }
    let with = run_synchronization_validated(&program, &package, scratch.path());
    assert!(!with.contains("SYNC-HAZARD") && !with.contains("Validation Error"), "{with}");
}
