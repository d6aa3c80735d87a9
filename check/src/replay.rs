//! Pass replay: checking one pass of a chain (a ReSTIR frame) on identical inputs.
//!
//! A frame is a chain of dispatches, each reading what the ones before wrote. Compared
//! at the end of the chain, one value that rounds differently early (an `atan2` within
//! Vulkan's precision, a fused multiply-add) sends a path or a reservoir elsewhere, and
//! everything after differs for reasons that are not the later passes' own. So the
//! interpreter runs the whole chain once through a [`RecordingBackend`], which keeps
//! every bound buffer before and after each dispatch; each backend then runs one recorded
//! dispatch alone ([`replay`]) on the interpreter's exact inputs, and its outputs are
//! compared with what the interpreter wrote: integer words (ids, flags, counts, kinds)
//! bit for bit, f32 words within the kernel's bound, padding skipped (word kinds from
//! the IR).

use crate::compare::{Compare, Output};
use std::collections::HashMap;
use std::sync::{Arc, Mutex};
use std::time::Duration;
use strata_backends::{
    Backend, BackendError, Bind, BufferId, DeviceInfo, SamplerDesc, SamplerId, TextureDesc, TextureId,
};
use strata_kernels::{Kernel, KernelId, Registry, Specialisation, WordKind};

/// One dispatch as the interpreter ran it.
#[derive(Clone, Debug)]
pub struct RecordedDispatch {
    /// The kernel's specialisation: the renderers run registry kernels specialised for
    /// their settings and scene ([`Registry::specialised`]), and a replay runs the same one.
    pub specialisation: Specialisation,
    /// Workgroups dispatched.
    pub workgroups: [u32; 3],
    /// Per bound buffer: (binding, contents before, contents after).
    pub binds: Vec<(u32, Vec<u8>, Vec<u8>)>,
}

/// The last dispatch of each kernel a chain ran.
pub type Recording = HashMap<KernelId, RecordedDispatch>;

/// A backend that forwards everything to `inner` and records each dispatch of the
/// kernels in `kernels`.
pub struct RecordingBackend<'a> {
    inner: &'a mut dyn Backend,
    kernels: Vec<KernelId>,
    /// What was recorded so far.
    pub recording: Recording,
}

impl<'a> RecordingBackend<'a> {
    /// Records dispatches of `kernels` run through it on `inner`.
    pub fn new(inner: &'a mut dyn Backend, kernels: &[KernelId]) -> Self {
        Self { inner, kernels: kernels.to_vec(), recording: Recording::new() }
    }
}

impl Backend for RecordingBackend<'_> {
    fn info(&self) -> &DeviceInfo {
        self.inner.info()
    }

    fn create_buffer(&mut self, label: &str, size: u64) -> Result<BufferId, BackendError> {
        self.inner.create_buffer(label, size)
    }

    fn write_buffer(&mut self, buffer: BufferId, offset: u64, data: &[u8]) -> Result<(), BackendError> {
        self.inner.write_buffer(buffer, offset, data)
    }

    fn read_buffer(&mut self, buffer: BufferId) -> Result<Vec<u8>, BackendError> {
        self.inner.read_buffer(buffer)
    }

    fn destroy_buffer(&mut self, buffer: BufferId) -> Result<(), BackendError> {
        self.inner.destroy_buffer(buffer)
    }

    fn create_texture(&mut self, desc: &TextureDesc) -> Result<TextureId, BackendError> {
        self.inner.create_texture(desc)
    }

    fn write_texture(&mut self, texture: TextureId, level: u32, data: &[u8]) -> Result<(), BackendError> {
        self.inner.write_texture(texture, level, data)
    }

    fn read_texture(&mut self, texture: TextureId, level: u32) -> Result<Vec<u8>, BackendError> {
        self.inner.read_texture(texture, level)
    }

    fn destroy_texture(&mut self, texture: TextureId) -> Result<(), BackendError> {
        self.inner.destroy_texture(texture)
    }

    fn create_sampler(&mut self, desc: &SamplerDesc) -> Result<SamplerId, BackendError> {
        self.inner.create_sampler(desc)
    }

    fn destroy_sampler(&mut self, sampler: SamplerId) -> Result<(), BackendError> {
        self.inner.destroy_sampler(sampler)
    }

    fn check_kernel(&self, kernel: &Kernel) -> Result<(), BackendError> {
        self.inner.check_kernel(kernel)
    }

    fn dispatch(&mut self, kernel: &Kernel, binds: &[Bind], workgroups: [u32; 3]) -> Result<(), BackendError> {
        if !self.kernels.contains(&kernel.id) {
            return self.inner.dispatch(kernel, binds, workgroups);
        }
        // The recorded kernels (the renderers' passes) bind buffers only.
        let buffers = binds
            .iter()
            .map(|b| {
                b.buffer().ok_or_else(|| BackendError::Binding {
                    kernel: kernel.name().into(),
                    binding: b.binding,
                    reason: "a pass replay records buffers only".into(),
                })
            })
            .collect::<Result<Vec<BufferId>, _>>()?;
        let before: Vec<Vec<u8>> = buffers.iter().map(|&b| self.inner.read_buffer(b)).collect::<Result<_, _>>()?;
        self.inner.dispatch(kernel, binds, workgroups)?;
        let mut recorded = Vec::new();
        for ((bind, &buffer), before) in binds.iter().zip(&buffers).zip(before) {
            recorded.push((bind.binding, before, self.inner.read_buffer(buffer)?));
        }
        let specialisation = Specialisation::of(kernel);
        self.recording.insert(kernel.id, RecordedDispatch { specialisation, workgroups, binds: recorded });
        Ok(())
    }

    fn dispatch_timed(
        &mut self,
        kernel: &Kernel,
        binds: &[Bind],
        workgroups: [u32; 3],
    ) -> Result<Duration, BackendError> {
        self.dispatch(kernel, binds, workgroups)?;
        Ok(Duration::ZERO)
    }
}

/// The recording of `kernels` made by `run` on the interpreter, made once per process
/// for each `(kernels, key)`: every kernel's check and every backend replay the same.
pub fn recorded(
    kernels: &[KernelId],
    key: &str,
    run: impl FnOnce(&mut dyn Backend) -> Result<(), strata_render::histogram_pass::PassError>,
) -> Arc<Recording> {
    static RECORDINGS: Mutex<Vec<(String, Arc<Recording>)>> = Mutex::new(Vec::new());
    let key = format!("{kernels:?} {key}");
    let mut recordings = RECORDINGS.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    if let Some((_, recording)) = recordings.iter().find(|(k, _)| *k == key) {
        return Arc::clone(recording);
    }
    let mut interpreter =
        strata_backends::cpu_backend::CpuBackend::new(Default::default()).expect("the interpreter always opens");
    let mut recorder = RecordingBackend::new(&mut interpreter, kernels);
    run(&mut recorder).unwrap_or_else(|e| panic!("the interpreter runs {key}: {e}"));
    let recording = Arc::new(std::mem::take(&mut recorder.recording));
    recordings.push((key, Arc::clone(&recording)));
    recording
}

/// The interpreter's outputs of its recorded dispatch of `kernel_id`, as [`outputs`].
pub fn recorded_outputs(kernel_id: KernelId, recording: &Recording, float: Compare) -> Vec<Output> {
    let dispatch = &recording[&kernel_id];
    let after: Vec<Vec<u8>> = dispatch.binds.iter().map(|(_, _, after)| after.clone()).collect();
    outputs(kernel_id, dispatch, &after, float)
}

/// Replays the recorded dispatch of `kernel_id` on `backend`, as [`outputs`].
pub fn replayed_outputs(
    backend: &mut dyn Backend,
    kernel_id: KernelId,
    recording: &Recording,
    float: Compare,
) -> Result<Vec<Output>, BackendError> {
    let dispatch = &recording[&kernel_id];
    let registry = Registry::shared().map_err(|e| BackendError::Validation {
        backend: "replay".into(),
        operation: "registry".into(),
        message: e.to_string(),
    })?;
    let kernel = registry.specialised(kernel_id, dispatch.specialisation).map_err(|e| BackendError::Validation {
        backend: "replay".into(),
        operation: "registry".into(),
        message: e.to_string(),
    })?;
    let after = replay(backend, kernel, dispatch)?;
    Ok(outputs(kernel_id, dispatch, &after, float))
}

/// Runs the recorded dispatch of `kernel` on `backend` from the recorded inputs and
/// returns the contents of every binding afterwards, in the recording's order.
pub fn replay(
    backend: &mut dyn Backend,
    kernel: &Kernel,
    dispatch: &RecordedDispatch,
) -> Result<Vec<Vec<u8>>, BackendError> {
    let mut buffers = Vec::new();
    for (binding, before, _) in &dispatch.binds {
        let label = kernel.binding(0, *binding).map_or("replayed", |b| b.name.as_str());
        let buffer = backend.create_buffer(label, before.len() as u64)?;
        backend.write_buffer(buffer, 0, before)?;
        buffers.push(buffer);
    }
    let binds: Vec<Bind> = dispatch.binds.iter().zip(&buffers).map(|((b, _, _), id)| Bind::new(*b, *id)).collect();
    let result = backend.dispatch(kernel, &binds, dispatch.workgroups);
    let mut after = Vec::new();
    for buffer in buffers {
        if result.is_ok() {
            after.push(backend.read_buffer(buffer)?);
        }
        backend.destroy_buffer(buffer)?;
    }
    result.map(|()| after)
}

/// A `'static` name for an output, leaked once per distinct text.
fn static_name(text: String) -> &'static str {
    static NAMES: std::sync::Mutex<Vec<&'static str>> = std::sync::Mutex::new(Vec::new());
    let mut names = NAMES.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    if let Some(name) = names.iter().find(|n| **n == text) {
        return name;
    }
    let name: &'static str = Box::leak(text.into_boxed_str());
    names.push(name);
    name
}

/// The writable bindings' contents (`after`, in the order of `dispatch.binds`) as
/// outputs: per binding, its integer words compared exactly and its f32 words under
/// `float`.
pub fn outputs(kernel_id: KernelId, dispatch: &RecordedDispatch, after: &[Vec<u8>], float: Compare) -> Vec<Output> {
    let registry = Registry::shared().expect("the registry loads");
    let kernel = registry.get(kernel_id);
    let mut outputs = Vec::new();
    for ((binding, _, _), bytes) in dispatch.binds.iter().zip(after) {
        let Some(info) = kernel.binding(0, *binding).filter(|b| b.is_writable()) else {
            continue;
        };
        let words: Vec<u32> = bytemuck::pod_collect_to_vec(bytes);
        let pick = |kind: WordKind| -> Vec<u32> {
            words.iter().enumerate().filter(|(i, _)| info.words.of(*i) == kind).map(|(_, w)| *w).collect()
        };
        let integers = pick(WordKind::Integer);
        if !integers.is_empty() {
            let name = static_name(format!("{} (integers)", info.name));
            outputs.push(Output { name, words: integers, compare: Compare::Exact });
        }
        let floats = pick(WordKind::Float);
        if !floats.is_empty() {
            let name = static_name(format!("{} (floats)", info.name));
            outputs.push(Output { name, words: floats, compare: float });
        }
    }
    outputs
}
