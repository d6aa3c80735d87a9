//! # strata-export: the kernel package for engines outside Rust
//!
//! [`export`] writes a self-contained, versioned folder with everything an engine in C,
//! C++ or any language needs to run strata's stratified selection pass (Salaün et al.,
//! SIGGRAPH 2025) on its own GPU API, without Rust:
//!
//! | path | what |
//! |---|---|
//! | `README.md` | per API (Vulkan, D3D12, Metal) how to bind, record and synchronise; what the engine writes when; what is tested where |
//! | `manifest.json` | per kernel: entry points, workgroup size, features, per binding its set/binding, HLSL register and space, MSL buffer index, element type and stride; the buffers' size rules and writers; the structs' layouts; the constants; the dispatch formulas ([`manifest`]) |
//! | `include/strata.h` | the records and constants as C11, generated from the structs' single Rust declarations, with `_Static_assert` on every size and offset ([`c_header`]) |
//! | `include/strata.glsl`, `include/strata.hlsli`, `include/strata.wgsl` | the same records and constants for the engine's own shaders ([`shader_headers`]) |
//! | `include/strata_frame.h` | the per-frame uniforms and dispatch sizes in plain C, as `strata-embed` computes them |
//! | `include/strata_vk.h` | the C ABI of the `strata-vk` library (cbindgen, [`abi_header`]) |
//! | `CMakeLists.txt`, `lib/cmake/strata/` | the CMake package (`add_subdirectory`, `find_package(strata CONFIG)`): targets `strata::headers`, `strata::vk`, the kernels' folders per language |
//! | `lib/pkgconfig/strata.pc` | the pkg-config module |
//! | `examples/cpp/` | a C++17 consumer built with CMake |
//! | `kernels/{spirv,hlsl,msl,glsl,wgsl}/` | every kernel in every language ([`translations`]) |
//! | `data/blue_noise.bin` | the blue-noise tables, uploaded once |
//! | `web/strata.js`, `web/strata.d.ts`, `web/example.html`, `web/example.js` | the pass for web engines: an ES module that runs it on a WebGPU `GPUDevice`, generated from the manifest, its TypeScript declarations and an example page ([`es_module`]) |
//!
//! `cargo xtask export --out DIR` runs it. The folder is written next to `DIR` first and
//! moved into place whole; an existing `DIR` is replaced only if it is an earlier package
//! holding nothing but the files its manifest lists and the files every package has: a
//! file or folder the user added anywhere in it refuses the export by name before any
//! work (the export never deletes a user's files). Errors are one line naming `DIR` once
//! and the OS error once, never the temporary folder beside it.
//!
//! ```
//! let scratch = strata_files::private_scratch_folder("my-package-")?; // removed when dropped
//! let out = scratch.path().join("package");
//! let package = strata_export::export(&out)?;
//! assert!(package.files.iter().any(|f| f == "include/strata.h"));
//! let manifest: serde_json::Value = serde_json::from_slice(&std::fs::read(out.join("manifest.json"))?)?;
//! assert_eq!(manifest["schema_version"], 2);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod abi_header;
pub mod c_header;
pub mod es_module;
pub mod manifest;
pub mod shader_headers;
pub mod translations;

use std::path::{Path, PathBuf};
use strata_embed::wgsl::ModuleId;
use strata_kernels::Registry;
use strata_kernels::constants::{module_constants, shared};
use strata_kernels::embed_types::{ResampleInput, ResampleOutput, SelectedCandidates, SelectionParams};
use strata_kernels::gpu::{ConstantValue, GpuConstant};
use strata_kernels::pass_plan::PassBuffer;
use strata_kernels::selection::SamplerVariant;
use strata_kernels::types::{BlockStats, Candidate, ClusterSpan, HistogramParams};

/// Why the package could not be written; each message is one line naming what is wrong.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    /// The output folder cannot be used.
    #[error("--out {path}: {why}")]
    Out {
        /// The folder.
        path: String,
        /// What is wrong with it.
        why: String,
    },
    /// The package could not be written: a file in it, the temporary folder beside the
    /// output folder, or the swap into place.
    #[error("--out {path}: {what}: {why}")]
    Write {
        /// The output folder, as the user named it.
        path: String,
        /// What failed (`cannot write kernels/spirv/strata_select.spv`), naming package
        /// files relative to the package, never the temporary folder.
        what: String,
        /// The OS error.
        why: String,
    },
    /// A kernel could not be translated (a bug: the message names kernel and language).
    #[error("translation: {0}")]
    Translation(String),
    /// A header could not be generated.
    #[error("header: {0}")]
    Header(String),
    /// A kernel failed to load.
    #[error(transparent)]
    Kernel(#[from] strata_kernels::KernelError),
}

/// The file that marks a folder as a package (and holds its manifest).
pub const MANIFEST: &str = "manifest.json";

/// What [`export`] wrote.
#[derive(Debug)]
pub struct Exported {
    /// The package's folder.
    pub folder: PathBuf,
    /// Its files, relative to it.
    pub files: Vec<String>,
}

/// The kernels the package carries, in run order (the three histogram variants first).
pub const MODULES: [ModuleId; 5] = ModuleId::ALL;

/// The structs the package declares.
fn structs() -> Vec<c_header::HeaderStruct> {
    use c_header::HeaderStruct;
    vec![
        HeaderStruct::of::<Candidate>(),
        HeaderStruct::of::<ClusterSpan>(),
        HeaderStruct::of::<BlockStats>(),
        HeaderStruct::of::<HistogramParams>(),
        HeaderStruct::of::<SelectionParams>(),
        HeaderStruct::of::<SelectedCandidates>(),
        HeaderStruct::of::<ResampleInput>(),
        HeaderStruct::of::<ResampleOutput>(),
    ]
}

/// The shared constants the exported kernels use (names from naga's IR, values checked
/// against [`shared`] by strata's constant test), in [`shared`]'s order.
fn constants(registry: &Registry) -> Vec<GpuConstant> {
    let used: Vec<String> = MODULES
        .iter()
        .flat_map(|&id| module_constants(&registry.get(id.kernel()).module))
        .map(|(name, _)| name)
        .collect();
    shared().into_iter().filter(|c| used.iter().any(|u| u == c.name)).collect()
}

/// Writes the package into `out` (module documentation).
pub fn export(out: &Path) -> Result<Exported, ExportError> {
    let out_error = |why: String| ExportError::Out { path: out.display().to_string(), why };
    check_out(out).map_err(out_error)?;
    let registry = Registry::shared()?;
    let version = env!("CARGO_PKG_VERSION");
    let mut files: Vec<(String, Vec<u8>)> = Vec::new();
    let mut kernels = Vec::new();
    let mut workgroup_sizes = Vec::new();
    for module in MODULES {
        let kernel = registry.get(module.kernel());
        let translated = translations::translate(kernel)?;
        let entry = manifest::kernel_entry(module, kernel, &translated);
        files.push((entry.files.spirv.clone(), bytemuck::cast_slice(&translated.spirv).to_vec()));
        files.push((entry.files.hlsl.clone(), translated.hlsl.text.clone().into_bytes()));
        files.push((entry.files.msl.clone(), translated.msl.text.clone().into_bytes()));
        files.push((entry.files.glsl.clone(), translated.glsl.clone().into_bytes()));
        files.push((entry.files.wgsl.clone(), translated.wgsl.clone().into_bytes()));
        workgroup_sizes.push((kernel.name().to_string(), kernel.workgroup_size));
        kernels.push(entry);
    }
    let structs = structs();
    let constants = constants(registry);
    let packed = strata_kernels::blue_noise::BlueNoiseTables::new().packed();
    let blue_noise: Vec<u8> = packed.iter().flat_map(|w| w.to_le_bytes()).collect();
    let manifest = manifest::Manifest {
        schema_version: manifest::SCHEMA_VERSION,
        strata_version: version.to_string(),
        description: "strata's stratified selection pass (Salaün et al., SIGGRAPH 2025, §4): per B x B block a histogram \
                      of the engine's candidates by object and luminance, then K stratified candidates per pixel and an \
                      optional resampling"
            .into(),
        buffers: PassBuffer::ALL.iter().map(|&b| manifest::buffer_entry(b)).collect(),
        structs: structs.iter().map(|s| manifest_struct(&s.entry)).collect(),
        constants: constants
            .iter()
            .map(|&GpuConstant { name, value, .. }| manifest::ConstantEntry {
                name: name.to_string(),
                c_name: if name.starts_with("SAMPLER_") {
                    name.replacen("SAMPLER_", "STRATA_SAMPLER_", 1)
                } else {
                    c_header::c_name(name)
                },
                wgsl_type: match value {
                    ConstantValue::U32(_) => "u32",
                    ConstantValue::F32(_) => "f32",
                },
                value: match value {
                    ConstantValue::U32(v) => v.into(),
                    ConstantValue::F32(v) => serde_json::Number::from_f64(f64::from(v)).map_or(0.into(), Into::into),
                },
            })
            .collect(),
        samplers: SamplerVariant::ALL.iter().map(|v| manifest::SamplerEntry { name: v.name(), id: v.id() }).collect(),
        blue_noise: manifest::BlueNoiseEntry {
            file: "data/blue_noise.bin".into(),
            bytes: blue_noise.len() as u64,
            sobol_word_offset: strata_kernels::blue_noise::PACKED_SOBOL,
            scrambling_word_offset: strata_kernels::blue_noise::PACKED_SCRAMBLING,
            ranking_word_offset: strata_kernels::blue_noise::PACKED_RANKING,
            origin: "Heitz et al. 2019, 'A Low-Discrepancy Sampler that Distributes Monte Carlo Errors as a Blue Noise \
                     in Screen Space', 256-spp tables (crate blue-noise-sampler, MIT)"
                .into(),
        },
        frame: manifest::FrameEntry {
            inputs: manifest::frame_inputs(),
            sequence: manifest::sequence(),
            functions: "include/strata_frame.h: strata_frame_params, strata_max_blocks, strata_grid_shift".into(),
        },
        kernels,
        variables: manifest::variables("HISTOGRAM_SLOTS_PER_WORKGROUP"),
        histogram_choice: manifest::histogram_choice(),
        device_requirements: device_requirements(registry),
    };
    let json = serde_json::to_string_pretty(&manifest).map_err(|e| ExportError::Header(e.to_string()))? + "\n";
    let value: serde_json::Value = serde_json::from_str(&json).map_err(|e| ExportError::Header(e.to_string()))?;
    let wgsl = |path: &str| {
        files.iter().find(|(name, _)| name == path).and_then(|(_, bytes)| String::from_utf8(bytes.clone()).ok())
    };
    let web = es_module::files(&value, &wgsl)?;
    files.push((MANIFEST.into(), json.into_bytes()));
    files.push(("data/blue_noise.bin".into(), blue_noise));
    files.push((
        "include/strata.h".into(),
        c_header::header(&structs, &constants, &workgroup_sizes, version)?.into_bytes(),
    ));
    for language in shader_headers::Language::ALL {
        files.push((
            language.file().into(),
            shader_headers::header(language, &structs, &constants, version)?.into_bytes(),
        ));
    }
    files.push(("include/strata_frame.h".into(), include_bytes!("../package/strata_frame.h").to_vec()));
    files.push(("include/strata_vk.h".into(), abi_header::header(version)?.into_bytes()));
    files.push(("README.md".into(), include_bytes!("../package/README.md").to_vec()));
    for (path, text) in es_module::FILES.into_iter().zip(web) {
        files.push((path.into(), text.into_bytes()));
    }
    for (path, template) in BUILD_FILES {
        files.push((path.into(), with_version(template, version)?.into_bytes()));
    }
    write_package(out, &files)?;
    Ok(Exported { folder: out.to_path_buf(), files: files.into_iter().map(|(name, _)| name).collect() })
}

/// What the device must offer (`strata_embed`'s `check_limits`, as formulas).
fn device_requirements(registry: &Registry) -> Vec<(&'static str, String)> {
    let kernels: Vec<&strata_kernels::Kernel> = MODULES.iter().map(|&m| registry.get(m.kernel())).collect();
    let storage = kernels
        .iter()
        .map(|k| k.bindings.iter().filter(|b| b.kind != strata_kernels::BindingKind::Uniform).count())
        .max();
    let shared = kernels.iter().map(|k| k.workgroup_memory_bytes()).max();
    let invocations = kernels.iter().map(|k| k.invocations()).max();
    let size_x = kernels.iter().map(|k| k.workgroup_size[0]).max();
    let size_y = kernels.iter().map(|k| k.workgroup_size[1]).max();
    let largest: Vec<String> = PassBuffer::ALL
        .iter()
        .filter(|b| !matches!(b.size_rule(), strata_kernels::pass_plan::SizeRule::Fixed(_)))
        .map(|&b| manifest::buffer_entry(b).size.formula)
        .collect();
    vec![
        ("maxPerStageDescriptorStorageBuffers", format!(">= {}", storage.unwrap_or(0))),
        ("maxComputeSharedMemorySize", format!(">= {} (the kernel run's workgroup_memory_bytes)", shared.unwrap_or(0))),
        ("maxComputeWorkGroupInvocations", format!(">= {}", invocations.unwrap_or(0))),
        ("maxComputeWorkGroupSize", format!(">= ({}, {}, 1)", size_x.unwrap_or(0), size_y.unwrap_or(0))),
        ("maxComputeWorkGroupCount", "every component >= max(ceil(width / 8), ceil(height / 8))".into()),
        ("maxStorageBufferRange", format!(">= the largest of {}", largest.join(", "))),
    ]
}

/// The manifest's copy of a header struct.
fn manifest_struct(entry: &manifest::StructEntry) -> manifest::StructEntry {
    manifest::StructEntry {
        name: entry.name,
        size: entry.size,
        fields: entry
            .fields
            .iter()
            .map(|f| manifest::FieldEntry {
                name: f.name,
                offset: f.offset,
                size: f.size,
                wgsl_type: f.wgsl_type.clone(),
            })
            .collect(),
    }
}

/// The files every package has besides those its manifest names (the kernels'
/// translations and the blue-noise tables).
pub const FIXED_FILES: [&str; 19] = [
    "README.md",
    MANIFEST,
    "include/strata.h",
    "include/strata.glsl",
    "include/strata.hlsli",
    "include/strata.wgsl",
    "include/strata_frame.h",
    "include/strata_vk.h",
    "CMakeLists.txt",
    "lib/cmake/strata/strataConfig.cmake",
    "lib/cmake/strata/strataConfigVersion.cmake",
    "lib/cmake/strata/strataTargets.cmake",
    "lib/pkgconfig/strata.pc",
    "examples/cpp/CMakeLists.txt",
    "examples/cpp/main.cpp",
    es_module::FILES[0],
    es_module::FILES[1],
    es_module::FILES[2],
    es_module::FILES[3],
];

/// The package's build-system files (CMake package, pkg-config) and its C++ example: each
/// path in the package with its template, in which `@STRATA_VERSION@`,
/// `@STRATA_VERSION_MAJOR@` and `@STRATA_VERSION_MINOR@` become the workspace's version.
const BUILD_FILES: [(&str, &str); 7] = [
    ("CMakeLists.txt", include_str!("../package/CMakeLists.txt")),
    ("lib/cmake/strata/strataConfig.cmake", include_str!("../package/cmake/strataConfig.cmake")),
    ("lib/cmake/strata/strataConfigVersion.cmake", include_str!("../package/cmake/strataConfigVersion.cmake")),
    ("lib/cmake/strata/strataTargets.cmake", include_str!("../package/cmake/strataTargets.cmake")),
    ("lib/pkgconfig/strata.pc", include_str!("../package/pkgconfig/strata.pc")),
    ("examples/cpp/CMakeLists.txt", include_str!("../package/examples/cpp/CMakeLists.txt")),
    ("examples/cpp/main.cpp", include_str!("../package/examples/cpp/main.cpp")),
];

/// `template` with the version's placeholders filled in.
fn with_version(template: &str, version: &str) -> Result<String, ExportError> {
    let [major, minor, _] = c_header::version_parts(version)?;
    Ok(template
        .replace("@STRATA_VERSION_MAJOR@", &major.to_string())
        .replace("@STRATA_VERSION_MINOR@", &minor.to_string())
        .replace("@STRATA_VERSION@", version))
}

/// The largest manifest read from an earlier package.
const MAX_MANIFEST_BYTES: u64 = 16 << 20;

/// The OS error of `error` alone (`Permission denied (os error 13)`), without the path
/// some wrappers (`tempfile`) add to it: the message names the user's folder instead.
fn os_error(error: &std::io::Error) -> String {
    if let Some(code) = error.raw_os_error() {
        return std::io::Error::from_raw_os_error(code).to_string();
    }
    // `tempfile` wraps the OS error in a private type that prints it, then ` at path "…"`.
    match error.get_ref().map(ToString::to_string) {
        Some(text) => text.split_once(" at path ").map_or(text.clone(), |(os, _)| os.to_string()),
        None => error.kind().to_string(),
    }
}

/// Whether the last part of `out` as written is `.` or `..` (`pkg/.`, `pkg/..`, `pkg/./`):
/// [`Path::components`] drops a trailing `.`, so `pkg/.` would look like `pkg`, and the
/// swap into place would fail (EBUSY) only after all the work.
fn ends_in_dots(out: &Path) -> bool {
    let bytes = out.as_os_str().as_encoded_bytes();
    let trimmed = bytes.iter().rposition(|&b| b != b'/').map_or(&bytes[..0], |end| &bytes[..=end]);
    let last = trimmed.rsplit(|&b| b == b'/').next().unwrap_or_default();
    last == b"." || last == b".."
}

/// The files an earlier package's `manifest` lists (every kernel's translations, the
/// blue-noise tables) and [`FIXED_FILES`]; `None` if it is not a strata manifest.
fn listed_files(manifest: &[u8]) -> Option<Vec<String>> {
    let manifest: serde_json::Value = serde_json::from_slice(manifest).ok()?;
    manifest.get("schema_version")?;
    manifest.get("strata_version")?;
    let mut files: Vec<String> = FIXED_FILES.iter().map(|f| f.to_string()).collect();
    for kernel in manifest.get("kernels")?.as_array()? {
        if let Some(languages) = kernel.get("files").and_then(|f| f.as_object()) {
            files.extend(languages.values().filter_map(|f| f.as_str()).map(str::to_string));
        }
    }
    if let Some(file) = manifest.get("blue_noise").and_then(|b| b.get("file")).and_then(|f| f.as_str()) {
        files.push(file.to_string());
    }
    Some(files)
}

/// The first entry below `out` (a package's folder) that is not one of `listed` nor a
/// folder holding one of them: a file, link or folder of the user's, relative to `out`
/// (`include/engine.h`, `kernels/custom/`). Folders are read in name order.
fn first_foreign(out: &Path, listed: &[String]) -> Result<Option<String>, String> {
    let mut folders = vec![String::new()];
    while let Some(folder) = folders.pop() {
        let path = if folder.is_empty() { out.to_path_buf() } else { out.join(&folder) };
        let mut entries = Vec::new();
        for entry in std::fs::read_dir(&path).map_err(|e| format!("cannot read {folder}: {}", os_error(&e)))? {
            let entry = entry.map_err(|e| format!("cannot read {folder}: {}", os_error(&e)))?;
            let file_type = entry.file_type().map_err(|e| format!("cannot read {folder}: {}", os_error(&e)))?;
            entries.push((entry.file_name(), file_type));
        }
        entries.sort_by(|a, b| a.0.cmp(&b.0));
        let mut below = Vec::new();
        for (name, file_type) in entries {
            let Some(name) = name.to_str() else {
                return Ok(Some(format!("{folder}{}", name.to_string_lossy())));
            };
            let relative = format!("{folder}{name}");
            // `file_type` does not follow links: a link is an entry of its own, replaced
            // (never followed) only where the package has a file of that name.
            if file_type.is_dir() {
                let inside = format!("{relative}/");
                if !listed.iter().any(|f| f.starts_with(&inside)) {
                    return Ok(Some(inside));
                }
                below.push(inside);
            } else if !listed.contains(&relative) {
                return Ok(Some(relative));
            }
        }
        folders.extend(below.into_iter().rev());
    }
    Ok(None)
}

/// Whether `out` may be written: a path ending in a folder's own name, absent, an empty
/// folder, or an earlier package (a folder with a [`MANIFEST`] of this schema's kind,
/// holding nothing but the files it lists and [`FIXED_FILES`], at any depth). Anything
/// else is refused, naming the first entry of the user's: the export never deletes a
/// user's files.
fn check_out(out: &Path) -> Result<(), String> {
    if ends_in_dots(out) || !matches!(out.components().next_back(), Some(std::path::Component::Normal(_))) {
        return Err("give the package folder's own name (not `.`, `..` or a root)".into());
    }
    let Ok(metadata) = std::fs::symlink_metadata(out) else { return Ok(()) };
    if !metadata.is_dir() {
        return Err("exists and is not a folder".into());
    }
    let mut entries = std::fs::read_dir(out).map_err(|e| os_error(&e))?;
    if entries.next().is_none() {
        return Ok(());
    }
    let manifest = strata_files::read_named_regular_capped(&out.join(MANIFEST), MAX_MANIFEST_BYTES).ok();
    let Some(listed) = manifest.as_deref().and_then(listed_files) else {
        return Err(
            "is a folder with other files in it (not an earlier strata package): choose an empty or new folder".into(),
        );
    };
    if let Some(foreign) = first_foreign(out, &listed)? {
        return Err(format!(
            "is an earlier package with `{foreign}` added to it, which the export would delete: move it out, or \
             choose another folder"
        ));
    }
    Ok(())
}

/// Writes `files` into a temporary sibling of `out`, then swaps it into place (an earlier
/// package there is renamed aside, then removed), so `out` is a whole package, new or
/// old, at every moment.
fn write_package(out: &Path, files: &[(String, Vec<u8>)]) -> Result<(), ExportError> {
    let name = out.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_else(|| "package".into());
    let failed = |what: String| {
        move |error: std::io::Error| ExportError::Write { path: out.display().to_string(), what, why: os_error(&error) }
    };
    // A new folder of a random name beside `out` (made by mkdir, mode 0700, so nothing
    // planted at a predictable name is written through), kept from here on: it is
    // renamed into place or removed below.
    let parent = match out.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent,
        _ => Path::new("."),
    };
    let temporary = strata_files::private_scratch_folder_in(parent, &format!(".{name}.tmp-"))
        .map_err(failed("cannot make the new package's folder beside it".into()))?
        .keep();
    let aside = out.with_file_name(format!(".{name}.old-{}", std::process::id()));
    let written = files.iter().try_for_each(|(relative, bytes)| {
        let path = temporary.join(relative);
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent).map_err(failed(format!("cannot write {relative}")))?;
        }
        std::fs::write(&path, bytes).map_err(failed(format!("cannot write {relative}")))
    });
    if let Err(error) = written {
        let _ = std::fs::remove_dir_all(&temporary);
        return Err(error);
    }
    // Checked again just before anything is moved: the folder may have changed.
    if let Err(why) = check_out(out) {
        let _ = std::fs::remove_dir_all(&temporary);
        return Err(ExportError::Out { path: out.display().to_string(), why });
    }
    let earlier = out.exists();
    if earlier && let Err(error) = std::fs::rename(out, &aside) {
        let _ = std::fs::remove_dir_all(&temporary);
        return Err(failed("cannot move the earlier package aside".into())(error));
    }
    if let Err(error) = std::fs::rename(&temporary, out) {
        if earlier {
            let _ = std::fs::rename(&aside, out);
        }
        let _ = std::fs::remove_dir_all(&temporary);
        return Err(failed("cannot move the new package into place".into())(error));
    }
    if earlier {
        let _ = std::fs::remove_dir_all(&aside);
    }
    Ok(())
}
