//! Running any WGSL compute shader on chosen backends (`cargo xtask run`): buffers from
//! files or zero-filled, `override` constants set by name, outputs written back, and
//! with several backends each output buffer judged against a reference backend under a
//! declared tolerance (see [`crate::agreement`]). For engine developers checking their
//! own kernels.

use crate::run_images::ImageSpec;
use crate::{BackendSlot, backend_slots};
use anyhow::{Context, Result, bail};
use std::path::{Path, PathBuf};
use strata_backends::{Backend, Bind, BufferId, Resource, SamplerDesc, SamplerId, TextureDesc, TextureId};
use strata_kernels::{BindingKind, Kernel, WordKinds};

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
    /// Values of `override` constants, by name; the rest keep their WGSL defaults.
    pub overrides: Vec<(String, f64)>,
    /// Textures and samplers (see [`crate::run_images`]).
    pub images: Vec<ImageSpec>,
    /// Backend names (`cpu`, `wgpu-vulkan`, `wgpu-gl`, `ash`, `ash-glsl`, `ash-hlsl`; `all`).
    pub backends: Vec<String>,
    /// Where output buffers are written (one folder per backend).
    pub out: PathBuf,
}

/// One writable buffer (or storage texture, its level 0) after a run.
#[derive(Clone, Debug)]
pub struct OutputBuffer {
    /// `@group` number.
    pub group: u32,
    /// `@binding` number.
    pub binding: u32,
    /// WGSL variable name.
    pub name: String,
    /// Contents.
    pub bytes: Vec<u8>,
    /// What each word holds (from the IR), for comparing.
    pub kinds: WordKinds,
}

/// One backend's run.
#[derive(Clone, Debug)]
pub struct BackendRun {
    /// Backend name.
    pub backend: String,
    /// Writable buffers after the run, or why the backend could not run the shader.
    pub outputs: Result<Vec<OutputBuffer>, String>,
}

/// The largest shader file read (WGSL text).
pub const MAX_SHADER_BYTES: u64 = 64 << 20;

/// The largest buffer or texture file read; a device's own limits are checked after.
pub const MAX_INPUT_BYTES: u64 = 4 << 30;

/// The whole regular file `path` (a link to one is followed), at most `cap` bytes: a named
/// pipe, a device (`/dev/zero`) or a link to one is refused at once by name, never waited on or read until memory runs
/// out, and the size is checked before anything is allocated.
pub fn read_input(path: &Path, cap: u64) -> Result<Vec<u8>> {
    Ok(strata_files::read_named_regular_capped(path, cap)?)
}

/// Loads the shader with `overrides`; subgroup operations are allowed if the module
/// needs them.
pub fn load_shader(path: &Path, entry: &str, overrides: &[(String, f64)]) -> Result<Kernel> {
    let bytes = read_input(path, MAX_SHADER_BYTES)?;
    let source = String::from_utf8(bytes).map_err(|_| anyhow::anyhow!("{}: is not UTF-8 text", path.display()))?;
    let name = path.display().to_string();
    match Kernel::from_wgsl_with_overrides(&name, source.clone(), entry, false, overrides) {
        Ok(kernel) => Ok(kernel),
        Err(first) => Kernel::from_wgsl_with_overrides(&name, source, entry, true, overrides)
            .map_err(|_| anyhow::anyhow!("{first}")),
    }
}

/// Initial contents of every buffer binding of `kernel`: given bytes (rounded up to
/// whole words), or zeros of the binding's minimum size.
pub type Inputs = Vec<(u32, Vec<u8>)>;

/// What a texture or sampler binding receives.
#[derive(Clone, Debug)]
pub enum ImageInput {
    /// A texture: what it is and each mip level's bytes, in order (levels not given are
    /// zero-filled; a storage texture the kernel only writes needs none).
    Texture {
        /// Its shape, size, levels and format.
        desc: TextureDesc,
        /// Bytes of levels 0, 1, ... (see `strata_backends::texture` for their order).
        levels: Vec<Vec<u8>>,
    },
    /// A sampler.
    Sampler(SamplerDesc),
}

/// The textures and samplers of a run, by binding (group 0).
pub type ImageInputs = Vec<(u32, ImageInput)>;

/// A resource created for one binding of a run.
enum Created {
    Buffer(BufferId),
    Texture(TextureId),
    Sampler(SamplerId),
}

/// A binding's `(group, binding)`.
pub type Slot = (u32, u32);

/// Buffer contents by `(group, binding)`.
pub type GroupedInputs = Vec<(Slot, Vec<u8>)>;

/// Textures and samplers by `(group, binding)`.
pub type GroupedImages = Vec<(Slot, ImageInput)>;

/// Group 0's inputs as grouped ones.
fn in_group_zero<T: Clone>(inputs: &[(u32, T)]) -> Vec<(Slot, T)> {
    inputs.iter().map(|(binding, value)| ((0, *binding), value.clone())).collect()
}

fn run_on(
    backend: &mut dyn Backend,
    kernel: &Kernel,
    inputs: &GroupedInputs,
    images: &GroupedImages,
    workgroups: [u32; 3],
) -> Result<Vec<OutputBuffer>> {
    backend.check_kernel(kernel)?;
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
                    let bytes = match inputs.iter().find(|(s, _)| *s == slot) {
                        Some((_, bytes)) => {
                            let mut bytes = bytes.clone();
                            bytes.resize(bytes.len().div_ceil(4) * 4, 0);
                            bytes
                        }
                        None => vec![0; binding.min_size().div_ceil(4) as usize * 4],
                    };
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
pub fn named_slots(names: &[String]) -> Result<Vec<BackendSlot>> {
    let slots = backend_slots();
    if names.iter().any(|b| b == "all") {
        return Ok(slots);
    }
    let mut chosen = Vec::new();
    for name in names {
        let alias = if name == "wgpu" { "wgpu-vulkan" } else { name.as_str() };
        let Some(slot) = slots.iter().find(|s| s.name == alias) else {
            let known: Vec<_> = slots.iter().map(|s| s.name).collect();
            bail!("unknown backend `{name}`: one of {}, wgpu or all", known.join(", "));
        };
        chosen.push(BackendSlot { name: slot.name, open: slot.open, needs_vulkan: slot.needs_vulkan });
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
                .and_then(|mut backend| run_on(backend.as_mut(), kernel, inputs, images, workgroups))
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
                Ok(backend) => {
                    run_on(backend.as_mut(), kernel, inputs, images, workgroups).map_err(|e| format!("{e:#}"))
                }
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
    /// One run per backend, in the order named.
    pub runs: Vec<BackendRun>,
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

/// Runs the request on every named backend and writes the outputs under `request.out`
/// (`BACKEND/GROUP_BINDING_NAME.bin`; a storage texture also as `.png` or `.exr`).
pub fn run_kernel(request: &RunRequest) -> Result<RunOutcome> {
    let kernel = load_shader(&request.shader, &request.entry, &request.overrides)?;
    let slots = named_slots(&request.backends)?;
    let mut inputs = GroupedInputs::new();
    for (group, binding, file) in &request.buffers {
        if kernel.binding(*group, *binding).is_none() {
            bail!("--buffer {group}:{binding}={}: entry point `{}` has no such binding", file.display(), request.entry);
        }
        let bytes = read_input(file, MAX_INPUT_BYTES)?;
        if bytes.is_empty() {
            bail!("buffer file {} is empty", file.display());
        }
        inputs.push(((*group, *binding), bytes));
    }
    for (group, binding, size) in &request.sizes {
        if kernel.binding(*group, *binding).is_none() {
            bail!("--size {group}:{binding}={size}: entry point `{}` has no such binding", request.entry);
        }
        if *size == 0 {
            bail!("--size {group}:{binding}=0: buffers need at least one byte");
        }
        inputs.push(((*group, *binding), vec![0; *size as usize]));
    }
    let images = crate::run_images::image_inputs(&kernel, &request.images)?;
    let runs = run_loaded_in_groups(&kernel, &inputs, &images, request.workgroups, &slots);
    for run in &runs {
        if let Ok(outputs) = &run.outputs {
            let dir = request.out.join(&run.backend);
            std::fs::create_dir_all(&dir).with_context(|| format!("cannot create {}", dir.display()))?;
            for output in outputs {
                let stem = dir.join(format!("{}_{}_{}", output.group, output.binding, output.name));
                let file = stem.with_extension("bin");
                // Whole or not at all, never through a link at its or a temporary's name.
                strata::atomic_file::write(&file, &output.bytes)?;
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
    Ok(RunOutcome { kernel, runs })
}
