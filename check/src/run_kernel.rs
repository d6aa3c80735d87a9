//! Running any WGSL compute shader on chosen backends (`cargo xtask run`): buffers from
//! files or zero-filled, outputs written back, and with several backends a verdict on
//! whether they agree. For engine developers checking their own kernels.

use crate::{BackendSlot, backend_slots};
use anyhow::{Context, Result, bail};
use std::path::{Path, PathBuf};
use strata_backends::{Backend, Bind};
use strata_kernels::Kernel;

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
    /// Backend names (`cpu`, `wgpu-vulkan`, `wgpu-gl`, `ash`, `ash-glsl`, `ash-hlsl`; `all`).
    pub backends: Vec<String>,
    /// Where output buffers are written (one folder per backend).
    pub out: PathBuf,
}

/// One backend's run.
#[derive(Clone, Debug)]
pub struct BackendRun {
    /// Backend name.
    pub backend: String,
    /// Writable buffers after the run: (binding, variable name, bytes), or the error.
    pub outputs: Result<Vec<(u32, String, Vec<u8>)>, String>,
}

/// Loads the shader; subgroup operations are allowed if the module needs them.
pub fn load_shader(path: &Path, entry: &str) -> Result<Kernel> {
    let source = std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    let name = path.display().to_string();
    match Kernel::from_wgsl(&name, source.clone(), entry, false) {
        Ok(kernel) => Ok(kernel),
        Err(first) => Kernel::from_wgsl(&name, source, entry, true).map_err(|_| anyhow::anyhow!("{first}")),
    }
}

fn contents(request: &RunRequest, binding: &strata_kernels::BindingInfo) -> Result<Vec<u8>> {
    if let Some((_, _, file)) = request.buffers.iter().find(|(g, b, _)| *g == binding.group && *b == binding.binding) {
        let mut bytes = std::fs::read(file).with_context(|| format!("cannot read buffer file {}", file.display()))?;
        if bytes.is_empty() {
            bail!("buffer file {} is empty", file.display());
        }
        bytes.resize(bytes.len().div_ceil(4) * 4, 0);
        return Ok(bytes);
    }
    if let Some((_, _, size)) = request.sizes.iter().find(|(g, b, _)| *g == binding.group && *b == binding.binding) {
        if *size == 0 {
            bail!("--size {}:{}=0: buffers need at least one byte", binding.group, binding.binding);
        }
        return Ok(vec![0; (size.div_ceil(4) * 4) as usize]);
    }
    Ok(vec![0; binding.min_size().div_ceil(4) as usize * 4])
}

fn run_on(backend: &mut dyn Backend, kernel: &Kernel, request: &RunRequest) -> Result<Vec<(u32, String, Vec<u8>)>> {
    backend.check_kernel(kernel)?;
    let mut binds = Vec::new();
    for binding in &kernel.bindings {
        let bytes = contents(request, binding)?;
        let buffer = backend.create_buffer(&binding.name, bytes.len() as u64)?;
        backend.write_buffer(buffer, 0, &bytes)?;
        binds.push((binding, buffer));
    }
    let plain: Vec<Bind> = binds.iter().map(|(b, id)| Bind::new(b.binding, *id)).collect();
    backend.dispatch(kernel, &plain, request.workgroups)?;
    let mut outputs = Vec::new();
    for (binding, buffer) in &binds {
        if binding.is_writable() {
            outputs.push((binding.binding, binding.name.clone(), backend.read_buffer(*buffer)?));
        }
        backend.destroy_buffer(*buffer)?;
    }
    Ok(outputs)
}

/// Runs the request on every named backend and writes the outputs under `request.out`.
pub fn run_kernel(request: &RunRequest) -> Result<Vec<BackendRun>> {
    for (group, binding, _) in &request.buffers {
        if *group != 0 {
            bail!("--buffer {group}:{binding}: only @group(0) is supported");
        }
    }
    let kernel = load_shader(&request.shader, &request.entry)?;
    for (group, binding, file) in &request.buffers {
        if kernel.binding(*group, *binding).is_none() {
            bail!("--buffer {group}:{binding}={}: entry point `{}` has no such binding", file.display(), request.entry);
        }
    }
    let slots: Vec<BackendSlot> = backend_slots();
    let names: Vec<String> = if request.backends.iter().any(|b| b == "all") {
        slots.iter().map(|s| s.name.to_string()).collect()
    } else {
        request.backends.clone()
    };
    let mut runs = Vec::new();
    for name in names {
        let alias = match name.as_str() {
            "wgpu" => "wgpu-vulkan",
            other => other,
        };
        let Some(slot) = slots.iter().find(|s| s.name == alias) else {
            let known: Vec<_> = slots.iter().map(|s| s.name).collect();
            bail!("unknown backend `{name}`: one of {}, wgpu or all", known.join(", "));
        };
        let outputs = (slot.open)()
            .map_err(anyhow::Error::from)
            .and_then(|mut backend| run_on(backend.as_mut(), &kernel, request))
            .map_err(|e| e.to_string());
        if let Ok(outputs) = &outputs {
            let dir = request.out.join(slot.name);
            std::fs::create_dir_all(&dir).with_context(|| format!("cannot create {}", dir.display()))?;
            for (binding, variable, bytes) in outputs {
                let file = dir.join(format!("0_{binding}_{variable}.bin"));
                std::fs::write(&file, bytes).with_context(|| format!("cannot write {}", file.display()))?;
            }
        }
        runs.push(BackendRun { backend: slot.name.to_string(), outputs });
    }
    Ok(runs)
}

/// The first disagreement between runs that succeeded, as text; `None` if they agree.
pub fn disagreement(runs: &[BackendRun]) -> Option<String> {
    let mut ok = runs.iter().filter_map(|r| r.outputs.as_ref().ok().map(|o| (&r.backend, o)));
    let (first_name, first) = ok.next()?;
    for (name, outputs) in ok {
        for ((binding, variable, a), (_, _, b)) in first.iter().zip(outputs.iter()) {
            if let Some(word) = (0..a.len() / 4).find(|&w| a[4 * w..4 * w + 4] != b[4 * w..4 * w + 4]) {
                let read = |bytes: &[u8]| {
                    u32::from_le_bytes([bytes[4 * word], bytes[4 * word + 1], bytes[4 * word + 2], bytes[4 * word + 3]])
                };
                return Some(format!(
                    "binding {binding} `{variable}` word {word}: {first_name} {:#x}, {name} {:#x}",
                    read(a),
                    read(b)
                ));
            }
        }
    }
    None
}
