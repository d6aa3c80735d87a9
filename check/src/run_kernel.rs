//! Running any WGSL compute shader on chosen backends (`cargo xtask run`): buffers from
//! files or zero-filled, `override` constants set by name, outputs written back, and
//! with several backends each output buffer judged against a reference backend under a
//! declared tolerance (see [`crate::agreement`]). For engine developers checking their
//! own kernels.

use crate::agreement::Tolerance;
pub use crate::run_data::{
    BackendRun, GroupedImages, GroupedInputs, ImageInput, ImageInputs, Inputs, MAX_INPUT_BYTES, OutputBuffer, Slot,
    read_input,
};
use crate::run_images::ImageSpec;
use crate::{BackendSlot, backend_slots};
use anyhow::{Context, Result, bail};
use std::path::{Path, PathBuf};
use strata_backends::cpu_backend::{CpuBackend, CpuOptions, DEFAULT_TIME_LIMIT, Finding};
use strata_backends::{Backend, BackendError, Bind, BufferId, Resource, SamplerId, TextureId};
use strata_kernels::{BindingKind, Kernel};

/// What to run.
#[derive(Clone, Debug)]
pub struct RunRequest {
    /// The WGSL file.
    pub shader: PathBuf,
    /// Compute entry point.
    pub entry: String,
    /// Workgroups to dispatch.
    pub workgroups: [u32; 3],
    /// Buffer contents: (group, binding, file).
    pub buffers: Vec<(u32, u32, PathBuf)>,
    /// Zero-filled buffer sizes in bytes: (group, binding, bytes).
    pub sizes: Vec<(u32, u32, u64)>,
    /// Values of `override` constants, by name or by `@id` number (`3` or `@3`); the
    /// rest keep their WGSL defaults ([`crate::overrides`]).
    pub overrides: Vec<crate::overrides::OverrideFlag>,
    /// Textures and samplers (see [`crate::run_images`]).
    pub images: Vec<ImageSpec>,
    /// Backend names (`cpu`, `wgpu-vulkan`, `wgpu-gl`, `ash`, `ash-glsl`, `ash-hlsl`,
    /// `ash-slang`; `wgpu` for `wgpu-vulkan`; `all` for every path available here).
    pub backends: Vec<String>,
    /// Where output buffers are written (one folder per backend).
    pub out: PathBuf,
    /// `--ulp N` (every buffer) and `--ulp BUFFER=N` flags: see
    /// [`Tolerance::from_flags`]; each buffer named must be an output of the entry point.
    pub ulp: Vec<(Option<String>, u32)>,
    /// `--abs E` and `--abs BUFFER=E` flags, as `ulp`.
    pub abs: Vec<(Option<String>, f32)>,
    /// `--time-limit`: the interpreter's limit per dispatch (`None`: its default,
    /// [`strata_backends::cpu_backend::DEFAULT_TIME_LIMIT`]).
    pub time_limit: Option<std::time::Duration>,
    /// `--sanitize`: run the interpreter as a sanitizer even when no other path is
    /// compared with it (it always is when one is: [`RunOutcome::findings`]).
    pub sanitize: bool,
}

/// The largest shader file read (WGSL text).
pub const MAX_SHADER_BYTES: u64 = 64 << 20;

/// Loads the shader with `overrides` (by name or `@id` number: [`crate::overrides`]);
/// subgroup operations are allowed if the module needs them.
pub fn load_shader(path: &Path, entry: &str, overrides: &[crate::overrides::OverrideFlag]) -> Result<Kernel> {
    load_shader_resolved(path, entry, overrides).map(|(kernel, _)| kernel)
}

/// [`load_shader`], and the overrides as resolved (for errors about the workgroup size).
fn load_shader_resolved(
    path: &Path,
    entry: &str,
    overrides: &[crate::overrides::OverrideFlag],
) -> Result<(Kernel, crate::overrides::ResolvedOverrides)> {
    let bytes = read_input(path, MAX_SHADER_BYTES)?;
    let mut source = String::from_utf8(bytes).map_err(|_| anyhow::anyhow!("{}: is not UTF-8 text", path.display()))?;
    // A leading byte order mark (some editors save one) is dropped, as by every text
    // reader of `strata`; naga would refuse it as the first token.
    if source.starts_with('\u{feff}') {
        source.drain(..'\u{feff}'.len_utf8());
    }
    let name = path.display().to_string();
    // A module that does not parse is left to the loader, whose error has the location.
    let resolved = match naga::front::wgsl::parse_str(&source) {
        Ok(module) => crate::overrides::resolve(&module, entry, overrides).map_err(anyhow::Error::msg)?,
        Err(_) => crate::overrides::ResolvedOverrides {
            constants: overrides.iter().map(|flag| (flag.key.clone(), flag.value)).collect(),
            ..Default::default()
        },
    };
    let constants = &resolved.constants;
    let loaded = match Kernel::from_wgsl_with_overrides(&name, source.clone(), entry, false, constants) {
        Ok(kernel) => Ok(kernel),
        Err(first) => Kernel::from_wgsl_with_overrides(&name, source, entry, true, constants)
            .map_err(|_| anyhow::anyhow!("{first}")),
    };
    match loaded {
        Ok(kernel) => Ok((kernel, resolved)),
        Err(error) if !overrides.is_empty() => {
            let flags: Vec<String> = overrides.iter().map(ToString::to_string).collect();
            Err(error.context(flags.join(", ")))
        }
        Err(error) => Err(error),
    }
}

/// A resource created for one binding of a run.
enum Created {
    Buffer(BufferId),
    Texture(TextureId),
    Sampler(SamplerId),
}

/// Group 0's inputs as grouped ones.
fn in_group_zero<T: Clone>(inputs: &[(u32, T)]) -> Vec<(Slot, T)> {
    inputs.iter().map(|(binding, value)| ((0, *binding), value.clone())).collect()
}

/// What a buffer binding receives in [`run_on`]: bytes (rounded up to whole words) or
/// that many zeros, and the flag that gave it (for messages).
struct BufferInput<'a> {
    slot: Slot,
    flag: String,
    contents: BufferContents<'a>,
}

enum BufferContents<'a> {
    Bytes(&'a [u8]),
    Zeros(u64),
}

/// Grouped inputs as [`run_on`] takes them, each named by its binding.
fn given_bytes(inputs: &GroupedInputs) -> Vec<BufferInput<'_>> {
    inputs
        .iter()
        .map(|((group, binding), bytes)| BufferInput {
            slot: (*group, *binding),
            flag: format!("the input of binding {group}:{binding}"),
            contents: BufferContents::Bytes(bytes),
        })
        .collect()
}

/// The contents of buffer `binding` on `backend`: checked against the device's buffer
/// limit before anything of the size is allocated, and allocated with `try_reserve` (a
/// size from the user's input is an error naming its flag, never an abort).
fn buffer_contents(
    backend: &dyn Backend,
    binding: &strata_kernels::BindingInfo,
    input: Option<&BufferInput>,
) -> Result<Vec<u8>> {
    let (flag, len, bytes) = match input {
        Some(BufferInput { flag, contents: BufferContents::Bytes(bytes), .. }) => {
            (flag.clone(), bytes.len() as u64, *bytes)
        }
        Some(BufferInput { flag, contents: BufferContents::Zeros(size), .. }) => (flag.clone(), *size, &[][..]),
        None => (
            format!(
                "binding {}:{} (`{}`, given no --buffer or --size: its minimum size)",
                binding.group, binding.binding, binding.name
            ),
            binding.min_size(),
            &[][..],
        ),
    };
    let padded = len
        .checked_next_multiple_of(4)
        .ok_or_else(|| anyhow::anyhow!("{flag}: {len} bytes rounded up to whole words pass u64::MAX"))?;
    strata_backends::bindings_check::check_buffer_size(&binding.name, padded, backend.info())
        .with_context(|| flag.clone())?;
    let size =
        usize::try_from(padded).with_context(|| format!("{flag}: {padded} bytes do not fit this machine's memory"))?;
    let mut contents = Vec::new();
    contents.try_reserve_exact(size).map_err(|e| anyhow::anyhow!("{flag}: cannot allocate {padded} bytes: {e}"))?;
    contents.extend_from_slice(bytes);
    contents.resize(size, 0);
    Ok(contents)
}

/// `error` from a backend's kernel check, with the `--override` flags that set the
/// workgroup size named when it is a workgroup limit that failed.
fn explain_limit(error: BackendError, kernel: &Kernel, workgroup_flags: &[String]) -> anyhow::Error {
    let workgroup_limit = matches!(&error, BackendError::LimitExceeded { limit, .. }
        if *limit == "invocations per workgroup" || limit.starts_with("workgroup size"));
    if workgroup_limit && !workgroup_flags.is_empty() {
        let [x, y, z] = kernel.workgroup_size;
        let flags = workgroup_flags.join("; ");
        return anyhow::Error::from(error).context(format!("{flags}: the workgroup size {x}x{y}x{z} comes from it"));
    }
    error.into()
}

fn run_on(
    backend: &mut dyn Backend,
    kernel: &Kernel,
    inputs: &[BufferInput],
    images: &GroupedImages,
    workgroups: [u32; 3],
    workgroup_flags: &[String],
) -> Result<Vec<OutputBuffer>> {
    backend.check_kernel(kernel).map_err(|e| explain_limit(e, kernel, workgroup_flags))?;
    let mut created = Vec::new();
    let result = (|| {
        for binding in &kernel.bindings {
            let slot = (binding.group, binding.binding);
            let image = images.iter().find(|(s, _)| *s == slot).map(|(_, input)| input);
            let resource = match (binding.kind, image) {
                (BindingKind::Sampler, Some(ImageInput::Sampler(desc))) => {
                    Created::Sampler(backend.create_sampler(desc)?)
                }
                (BindingKind::Sampler, _) => {
                    bail!("binding {} (`{}`) is a sampler: give it one", binding.binding, binding.name)
                }
                (kind, Some(ImageInput::Texture { desc, levels })) if kind.is_texture() => {
                    let texture = backend.create_texture(desc)?;
                    created.push((binding, Created::Texture(texture)));
                    for (level, bytes) in levels.iter().enumerate() {
                        backend.write_texture(texture, level as u32, bytes)?;
                    }
                    continue;
                }
                (kind, _) if kind.is_texture() => {
                    bail!(
                        "binding {} (`{}`) is a {}: give it a texture",
                        binding.binding,
                        binding.name,
                        binding.element.type_name
                    )
                }
                _ => {
                    let input = inputs.iter().find(|input| input.slot == slot);
                    let bytes = buffer_contents(&*backend, binding, input)?;
                    let buffer = backend.create_buffer(&binding.name, bytes.len() as u64)?;
                    created.push((binding, Created::Buffer(buffer)));
                    backend.write_buffer(buffer, 0, &bytes)?;
                    continue;
                }
            };
            created.push((binding, resource));
        }
        let binds: Vec<Bind> = created
            .iter()
            .map(|(b, resource)| {
                let resource = match resource {
                    Created::Buffer(id) => Resource::Buffer(*id),
                    Created::Texture(id) => Resource::Texture(*id),
                    Created::Sampler(id) => Resource::Sampler(*id),
                };
                Bind::at(b.group, b.binding, resource)
            })
            .collect();
        backend.dispatch(kernel, &binds, workgroups)?;
        let mut outputs = Vec::new();
        for (binding, resource) in &created {
            let bytes = match resource {
                Created::Buffer(id) if binding.is_writable() => backend.read_buffer(*id)?,
                Created::Texture(id) if binding.is_writable() => backend.read_texture(*id, 0)?,
                _ => continue,
            };
            outputs.push(OutputBuffer {
                group: binding.group,
                binding: binding.binding,
                name: binding.name.clone(),
                bytes,
                kinds: binding.words.clone(),
            });
        }
        Ok(outputs)
    })();
    for (_, resource) in created {
        // A failed run's error is the one to report, not a clean-up's.
        let _ = match resource {
            Created::Buffer(id) => backend.destroy_buffer(id),
            Created::Texture(id) => backend.destroy_texture(id),
            Created::Sampler(id) => backend.destroy_sampler(id),
        };
    }
    result
}

/// The backend slots named by `names` (`all` for every one; `wgpu` is `wgpu-vulkan`).
/// A path named twice (`cpu,cpu`, `wgpu,wgpu-vulkan`) or `all` beside other names is
/// refused by name rather than run twice or dropped.
pub fn named_slots(names: &[String]) -> Result<Vec<BackendSlot>> {
    let slots = backend_slots();
    if names.iter().any(|b| b == "all") {
        if let Some(other) = names.iter().find(|b| *b != "all") {
            bail!("--backend all,{other}: `all` already names every path: give `all` alone or name each path");
        }
        if names.len() > 1 {
            bail!("--backend all,all: `all` is named twice");
        }
        return Ok(slots);
    }
    let mut chosen: Vec<BackendSlot> = Vec::new();
    for name in names {
        let alias = if name == "wgpu" { "wgpu-vulkan" } else { name.as_str() };
        let Some(slot) = slots.iter().find(|s| s.name == alias) else {
            let known: Vec<_> = slots.iter().map(|s| s.name).collect();
            bail!("unknown backend `{name}`: one of {}, wgpu or all", known.join(", "));
        };
        if chosen.iter().any(|c| c.name == slot.name) {
            bail!("--backend {}: `{}` is named twice: name each path once", names.join(","), slot.name);
        }
        chosen.push(*slot);
    }
    Ok(chosen)
}

/// Runs a loaded kernel with buffer `inputs` on every slot; a backend that cannot open
/// or fails records its error instead of outputs.
pub fn run_loaded(kernel: &Kernel, inputs: &Inputs, workgroups: [u32; 3], slots: &[BackendSlot]) -> Vec<BackendRun> {
    run_loaded_with_images(kernel, inputs, &ImageInputs::new(), workgroups, slots)
}

/// [`run_loaded`] with textures and samplers too; writable storage textures come back
/// (mip level 0) among the outputs, their words' kinds from their format.
pub fn run_loaded_with_images(
    kernel: &Kernel,
    inputs: &Inputs,
    images: &ImageInputs,
    workgroups: [u32; 3],
    slots: &[BackendSlot],
) -> Vec<BackendRun> {
    run_loaded_in_groups(kernel, &in_group_zero(inputs), &in_group_zero(images), workgroups, slots)
}

/// [`run_loaded_with_images`] for a kernel of any bind groups: inputs by
/// `(group, binding)`.
pub fn run_loaded_in_groups(
    kernel: &Kernel,
    inputs: &GroupedInputs,
    images: &GroupedImages,
    workgroups: [u32; 3],
    slots: &[BackendSlot],
) -> Vec<BackendRun> {
    slots
        .iter()
        .map(|slot| BackendRun {
            backend: slot.name.to_string(),
            outputs: (slot.open)()
                .map_err(anyhow::Error::from)
                .and_then(|mut backend| run_on(backend.as_mut(), kernel, &given_bytes(inputs), images, workgroups, &[]))
                .map_err(|e| format!("{e:#}")),
        })
        .collect()
}

/// Backends opened once for many runs: each slot's name and its backend, or why it did
/// not open.
pub type OpenBackends = Vec<(String, Result<Box<dyn Backend>, String>)>;

/// Opens every slot once, for [`run_on_open`].
pub fn open_backends(slots: &[BackendSlot]) -> OpenBackends {
    slots.iter().map(|slot| (slot.name.to_string(), (slot.open)().map_err(|e| e.to_string()))).collect()
}

/// [`run_loaded_in_groups`] on backends already open (many kernels run without a device
/// created per kernel and backend).
pub fn run_on_open(
    kernel: &Kernel,
    inputs: &GroupedInputs,
    images: &GroupedImages,
    workgroups: [u32; 3],
    backends: &mut OpenBackends,
) -> Vec<BackendRun> {
    backends
        .iter_mut()
        .map(|(name, backend)| BackendRun {
            backend: name.clone(),
            outputs: match backend {
                Ok(backend) => run_on(backend.as_mut(), kernel, &given_bytes(inputs), images, workgroups, &[])
                    .map_err(|e| format!("{e:#}")),
                Err(why) => Err(why.clone()),
            },
        })
        .collect()
}

/// What [`run_kernel`] ran and what came of it.
#[derive(Debug)]
pub struct RunOutcome {
    /// The shader as loaded (overrides applied).
    pub kernel: Kernel,
    /// One run per backend, in the order named (under `all`, those available here).
    pub runs: Vec<BackendRun>,
    /// Under `--backend all`, the paths not available here and why: a toolchain not
    /// installed (Slang, glslang), no device (no Vulkan driver; with
    /// `STRATA_REQUIRE_GPU=1` a Vulkan path without a device fails instead), or a device
    /// without a feature the kernel needs (linear filtering of `rgba32float` on wgpu-gl).
    pub unavailable: Vec<(String, String)>,
    /// The tolerance `--ulp` and `--abs` gave, every buffer it names an output.
    pub tolerance: Tolerance,
    /// Whether the interpreter ran as a sanitizer: with `--sanitize`, or whenever its
    /// outputs are compared with another path's (so that a difference WGSL allows is
    /// told from a bug).
    pub sanitized: bool,
    /// What the sanitizer found in the interpreter's run, and the occurrences past its
    /// cap of sites.
    pub findings: (Vec<Finding>, u64),
}

impl RunOutcome {
    /// The first finding that makes the kernel's results undefined by WGSL (an index
    /// out of range, a data race, ...), which explains a path that differs from the
    /// interpreter ([`crate::agreement::BufferAgreement::describe_undefined`]).
    pub fn undefined_behaviour(&self) -> Option<&Finding> {
        self.findings.0.iter().find(|finding| finding.kind.undefined())
    }

    /// Why output buffer `name` may differ from the interpreter's, if the run did
    /// something WGSL leaves undefined: the first such finding that names the buffer (an
    /// index out of range in it, a race on its words, an access past its end), else the
    /// run's first, said to be one of several when there are more (a value read out of
    /// range or raced on can reach any buffer).
    pub fn undefined_behaviour_for(&self, name: &str) -> Option<String> {
        undefined_reason(&self.findings.0, name)
    }
}

/// [`RunOutcome::undefined_behaviour_for`] over `findings`.
fn undefined_reason(findings: &[Finding], name: &str) -> Option<String> {
    let undefined: Vec<&Finding> = findings.iter().filter(|finding| finding.kind.undefined()).collect();
    let quoted = format!("`{name}`");
    if let Some(own) = undefined.iter().find(|finding| finding.detail.contains(&quoted)) {
        return Some(own.to_string());
    }
    let first = undefined.first()?;
    Some(match undefined.len() {
        1 => first.to_string(),
        n => format!("{first}, the first of {n} undefined findings listed above, none in {quoted}"),
    })
}

/// The math functions of the interpreter whose results differ from GPU drivers' within
/// Vulkan's precision (not bit for bit) that `kernel`'s entry point calls, by WGSL name.
pub fn inexact_functions(kernel: &Kernel) -> Vec<&'static str> {
    use naga::MathFunction as M;
    let mut used = Vec::new();
    let mut look = |expressions: &naga::Arena<naga::Expression>| {
        for (_, expression) in expressions.iter() {
            if let naga::Expression::Math { fun, .. } = expression {
                let name = match fun {
                    M::Exp => "exp",
                    M::Exp2 => "exp2",
                    M::Log => "log",
                    M::Log2 => "log2",
                    M::Pow => "pow",
                    _ => continue,
                };
                if !used.contains(&name) {
                    used.push(name);
                }
            }
        }
    };
    for (_, function) in kernel.module.functions.iter() {
        look(&function.expressions);
    }
    look(&kernel.module.entry_points[kernel.entry_index()].function.expressions);
    used
}

/// The `--buffer` and `--size` flags checked against `kernel` before any file is read
/// or anything allocated: each names a buffer binding of the entry point, at most once
/// (two flags for one binding are refused by name, never one of them dropped), a size
/// is at least one byte and at most [`MAX_INPUT_BYTES`].
fn check_buffer_flags(kernel: &Kernel, request: &RunRequest) -> Result<Vec<(Slot, String)>> {
    let mut given: Vec<(Slot, String)> = Vec::new();
    let flags = request
        .buffers
        .iter()
        .map(|(g, b, file)| ((*g, *b), format!("--buffer {g}:{b}={}", file.display()), None))
        .chain(request.sizes.iter().map(|(g, b, size)| ((*g, *b), format!("--size {g}:{b}={size}"), Some(*size))));
    for ((group, binding), flag, size) in flags {
        let Some(info) = kernel.binding(group, binding) else {
            bail!("{flag}: entry point `{}` has no such binding", request.entry);
        };
        if info.kind.is_texture() || info.kind == BindingKind::Sampler {
            let give = if info.kind == BindingKind::Sampler { "--sampler" } else { "--texture or --storage-texture" };
            bail!(
                "{flag}: binding {group}:{binding} (`{}`) is a {}, not a buffer: give it {give}",
                info.name,
                info.element.type_name
            );
        }
        if let Some((_, first)) = given.iter().find(|(slot, _)| *slot == (group, binding)) {
            bail!("{flag}: binding {group}:{binding} (`{}`) is given twice ({first} first): give it once", info.name);
        }
        match size {
            Some(0) => bail!("{flag}: buffers need at least one byte"),
            Some(size) if size > MAX_INPUT_BYTES => {
                bail!("{flag}: {size} bytes is more than xtask run's cap of {MAX_INPUT_BYTES} bytes (4 GiB)")
            }
            _ => {}
        }
        given.push(((group, binding), flag));
    }
    Ok(given)
}

/// Whether every buffer `--ulp` and `--abs` name is an output (a writable binding) of
/// `kernel`: a bound for a buffer that is not one would silently judge nothing.
fn check_tolerance_targets(kernel: &Kernel, request: &RunRequest) -> Result<()> {
    let outputs: Vec<&str> = kernel.bindings.iter().filter(|b| b.is_writable()).map(|b| b.name.as_str()).collect();
    let named =
        request.ulp.iter().filter_map(|(name, n)| name.as_ref().map(|name| (name, format!("--ulp {name}={n}")))).chain(
            request.abs.iter().filter_map(|(name, e)| name.as_ref().map(|name| (name, format!("--abs {name}={e}")))),
        );
    for (name, flag) in named {
        if !outputs.contains(&name.as_str()) {
            let list = if outputs.is_empty() { "none".to_string() } else { outputs.join(", ") };
            bail!("{flag}: entry point `{}` has no output buffer `{name}` (its outputs: {list})", request.entry);
        }
    }
    Ok(())
}

/// Runs the request on every named backend and writes the outputs under `request.out`
/// (`BACKEND/GROUP_BINDING_NAME.bin`; a storage texture also as `.png` or `.exr`).
///
/// Every flag is checked before a file is read or a backend opened (module
/// documentation of [`crate::overrides`], [`named_slots`], the buffer and image flags,
/// [`Tolerance::from_flags`]). Under `all`, a path whose toolchain is not installed, that
/// has no device here, or whose device lacks a feature the kernel needs
/// ([`BackendError::MissingFeature`]: subgroups, linear filtering of `rgba32float`) is
/// listed in [`RunOutcome::unavailable`] instead of run.
pub fn run_kernel(request: &RunRequest) -> Result<RunOutcome> {
    let every = request.backends.iter().any(|b| b == "all");
    let slots = named_slots(&request.backends)?;
    let tolerance = Tolerance::from_flags(&request.ulp, &request.abs).map_err(anyhow::Error::msg)?;
    let (kernel, resolved) = load_shader_resolved(&request.shader, &request.entry, &request.overrides)?;
    check_tolerance_targets(&kernel, request)?;
    let flags = check_buffer_flags(&kernel, request)?;
    let mut files = Vec::new();
    for (group, binding, file) in &request.buffers {
        let bytes = read_input(file, MAX_INPUT_BYTES)?;
        if bytes.is_empty() {
            bail!("--buffer {group}:{binding}={}: the file is empty", file.display());
        }
        files.push(bytes);
    }
    let images = crate::run_images::image_inputs(&kernel, &request.images)?;
    let mut contents = files.iter().map(|bytes| BufferContents::Bytes(bytes));
    let mut sizes = request.sizes.iter().map(|(_, _, size)| BufferContents::Zeros(*size));
    let inputs: Vec<BufferInput> = flags
        .into_iter()
        .enumerate()
        .map(|(index, (slot, flag))| {
            let contents = if index < request.buffers.len() { contents.next() } else { sizes.next() };
            BufferInput { slot, flag, contents: contents.expect("one per flag") }
        })
        .collect();
    let mut runs = Vec::new();
    let mut unavailable = Vec::new();
    // The interpreter sanitizes when asked, or when another path is compared with it.
    let sanitized = request.sanitize || (slots.len() > 1 && slots.iter().any(|slot| slot.name == "cpu"));
    let mut findings = (Vec::new(), 0);
    for slot in &slots {
        let name = slot.name.to_string();
        if every && let Err(why) = (slot.toolchain)() {
            unavailable.push((name, why));
            continue;
        }
        if slot.name == "cpu" {
            let options = CpuOptions {
                time_limit: Some(request.time_limit.unwrap_or(DEFAULT_TIME_LIMIT)),
                sanitize: sanitized,
                ..CpuOptions::default()
            };
            let outputs = CpuBackend::new(options).map_err(|e| e.to_string()).and_then(|mut cpu| {
                let outputs =
                    run_on(&mut cpu, &kernel, &inputs, &images, request.workgroups, &resolved.workgroup_flags)
                        .map_err(|e| format!("{e:#}"));
                findings = cpu.take_findings();
                outputs
            });
            runs.push(BackendRun { backend: name, outputs });
            continue;
        }
        let outputs = match (slot.open)() {
            Ok(mut backend) => {
                match run_on(backend.as_mut(), &kernel, &inputs, &images, request.workgroups, &resolved.workgroup_flags)
                {
                    // A feature this kernel needs and this device lacks (FLOAT32_FILTERABLE
                    // on wgpu-gl): the path is unavailable for it, as for a missing device;
                    // so is what the browser's WebGPU refuses by name (its limits).
                    Err(error)
                        if every
                            && match error.downcast_ref::<BackendError>() {
                                Some(BackendError::MissingFeature { .. }) => true,
                                Some(BackendError::Unavailable { .. } | BackendError::LimitExceeded { .. }) => {
                                    slot.name == "webgpu"
                                }
                                _ => false,
                            } =>
                    {
                        unavailable.push((name, format!("{error:#}")));
                        continue;
                    }
                    outputs => outputs.map_err(|e| format!("{e:#}")),
                }
            }
            Err(why) if every && !(slot.needs_vulkan && strata_backends::gpu_required()) => {
                unavailable.push((name, why.to_string()));
                continue;
            }
            Err(why) => Err(why.to_string()),
        };
        runs.push(BackendRun { backend: name, outputs });
    }
    for run in &runs {
        if let Ok(outputs) = &run.outputs {
            let dir = request.out.join(&run.backend);
            std::fs::create_dir_all(&dir).with_context(|| format!("cannot create {}", dir.display()))?;
            for output in outputs {
                let stem = dir.join(format!("{}_{}_{}", output.group, output.binding, output.name));
                let file = stem.with_extension("bin");
                // Whole or not at all, never through a link at its or a temporary's name.
                strata_render::atomic_file::write(&file, &output.bytes)?;
                let texture = images.iter().find_map(|(slot, input)| match input {
                    ImageInput::Texture { desc, .. } if *slot == (output.group, output.binding) => Some(desc),
                    _ => None,
                });
                if let Some(desc) = texture {
                    crate::run_images::write_picture(&stem, output, desc)?;
                }
            }
        }
    }
    Ok(RunOutcome { kernel, runs, unavailable, tolerance, sanitized, findings })
}

#[cfg(test)]
mod undefined_reason_tests {
    use super::*;
    use strata_backends::cpu_backend::FindingKind;

    fn finding(kind: FindingKind, line: u32, detail: &str) -> Finding {
        Finding {
            kind,
            kernel: "main".into(),
            file: "k.wgsl".into(),
            line,
            function: "main".into(),
            detail: detail.into(),
            count: 1,
        }
    }

    /// A differing buffer is explained by the finding that names it, not by the run's
    /// first (which blamed a workgroup race for a difference an index out of range in
    /// the buffer caused); without one, the first is said to be one of several.
    #[test]
    fn a_buffer_is_explained_by_its_own_finding() {
        let findings = [
            finding(FindingKind::WorkgroupRace, 4, "invocation 1 writes word 0 of `tile` that invocation 0 wrote"),
            finding(FindingKind::OutOfRangeIndex, 9, "index 70, length 64 (elements in `out`)"),
        ];
        let out = undefined_reason(&findings, "out").unwrap();
        assert!(out.contains("k.wgsl:9") && out.contains("`out`"), "{out}");
        let other = undefined_reason(&findings, "other").unwrap();
        assert!(other.contains("k.wgsl:4") && other.contains("the first of 2 undefined findings"), "{other}");
        assert_eq!(undefined_reason(&findings[..1], "other").unwrap(), findings[0].to_string());
        assert!(undefined_reason(&[], "out").is_none());
    }
}
