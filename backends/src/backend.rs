//! The [`Backend`] trait: buffers and textures in, kernel dispatched, buffers and
//! textures out.

use crate::device_info::DeviceInfo;
use crate::error::BackendError;
use crate::texture::{SamplerDesc, SamplerId, TextureDesc, TextureId};
use std::time::Duration;
use strata_kernels::Kernel;

/// A buffer owned by a backend.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct BufferId(pub u64);

/// What a binding receives: a buffer (bound whole), a texture (all its mip levels) or a
/// sampler.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Resource {
    /// A uniform or storage buffer.
    Buffer(BufferId),
    /// A sampled or storage texture.
    Texture(TextureId),
    /// A sampler.
    Sampler(SamplerId),
}

impl Resource {
    /// What it is, for messages ("buffer 3", "texture 1", "sampler 2").
    pub fn describe(self) -> String {
        match self {
            Self::Buffer(id) => format!("buffer {}", id.0),
            Self::Texture(id) => format!("texture {}", id.0),
            Self::Sampler(id) => format!("sampler {}", id.0),
        }
    }
}

/// A resource bound at `@group(group) @binding(binding)` of a dispatch.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Bind {
    /// WGSL group (registry kernels use 0 only).
    pub group: u32,
    /// WGSL binding number.
    pub binding: u32,
    /// What is bound.
    pub resource: Resource,
}

impl Bind {
    /// Binds `buffer` at group 0, `binding`.
    pub fn new(binding: u32, buffer: BufferId) -> Self {
        Self { group: 0, binding, resource: Resource::Buffer(buffer) }
    }

    /// Binds `texture` at group 0, `binding`.
    pub fn texture(binding: u32, texture: TextureId) -> Self {
        Self { group: 0, binding, resource: Resource::Texture(texture) }
    }

    /// Binds `sampler` at group 0, `binding`.
    pub fn sampler(binding: u32, sampler: SamplerId) -> Self {
        Self { group: 0, binding, resource: Resource::Sampler(sampler) }
    }

    /// Binds `resource` at `@group(group) @binding(binding)`.
    pub fn at(group: u32, binding: u32, resource: Resource) -> Self {
        Self { group, binding, resource }
    }

    /// Its `(group, binding)`.
    pub fn slot(&self) -> (u32, u32) {
        (self.group, self.binding)
    }

    /// The buffer bound, if a buffer is.
    pub fn buffer(&self) -> Option<BufferId> {
        match self.resource {
            Resource::Buffer(id) => Some(id),
            _ => None,
        }
    }

    /// `buffers`, each under its WGSL variable's name, bound at the binding number
    /// `kernel` declares for it (the registry's reflection; never a number written by
    /// hand). A name the kernel's source declares but its entry point never reaches is
    /// left out (naga drops such bindings); a name it does not declare is an error.
    pub fn named(kernel: &Kernel, buffers: &[(&str, BufferId)]) -> Result<Vec<Bind>, BackendError> {
        let mut binds = Vec::with_capacity(buffers.len());
        for &(name, buffer) in buffers {
            if let Some(info) = kernel.binding_named(name) {
                binds.push(Bind::new(info.binding, buffer));
            } else if !kernel.declares(name) {
                return Err(BackendError::UnknownBinding { kernel: kernel.name().to_string(), name: name.to_string() });
            }
        }
        Ok(binds)
    }
}

/// Something that runs registry kernels.
///
/// Dispatches are ordered: a dispatch sees the writes of every earlier dispatch and
/// upload; [`Backend::read_buffer`] waits for all of them.
pub trait Backend {
    /// The device and what it can do.
    fn info(&self) -> &DeviceInfo;

    /// A zero-filled buffer of `size` bytes (> 0) usable as uniform or storage buffer.
    fn create_buffer(&mut self, label: &str, size: u64) -> Result<BufferId, BackendError>;

    /// Writes `data` at byte `offset`; offset and length must be multiples of 4.
    fn write_buffer(&mut self, buffer: BufferId, offset: u64, data: &[u8]) -> Result<(), BackendError>;

    /// The buffer's whole contents, after every submitted dispatch has finished.
    fn read_buffer(&mut self, buffer: BufferId) -> Result<Vec<u8>, BackendError>;

    /// Frees the buffer.
    fn destroy_buffer(&mut self, buffer: BufferId) -> Result<(), BackendError>;

    /// A zero-filled texture (every mip level), usable as sampled and as storage texture
    /// of its format.
    fn create_texture(&mut self, desc: &TextureDesc) -> Result<TextureId, BackendError>;

    /// Replaces mip `level` of `texture` with `data` (the whole level, see
    /// [`crate::texture`] for the byte order).
    fn write_texture(&mut self, texture: TextureId, level: u32, data: &[u8]) -> Result<(), BackendError>;

    /// Mip `level` of `texture`, after every submitted dispatch has finished.
    fn read_texture(&mut self, texture: TextureId, level: u32) -> Result<Vec<u8>, BackendError>;

    /// Frees the texture.
    fn destroy_texture(&mut self, texture: TextureId) -> Result<(), BackendError>;

    /// A sampler.
    fn create_sampler(&mut self, desc: &SamplerDesc) -> Result<SamplerId, BackendError>;

    /// Frees the sampler.
    fn destroy_sampler(&mut self, sampler: SamplerId) -> Result<(), BackendError>;

    /// Whether the device can run `kernel` at all (features, workgroup size and memory);
    /// the error says what is missing.
    fn check_kernel(&self, kernel: &Kernel) -> Result<(), BackendError>;

    /// Runs `kernel` on `workgroups` workgroups with `binds` (every binding the kernel
    /// uses, each exactly once, with a resource of the binding's kind).
    fn dispatch(&mut self, kernel: &Kernel, binds: &[Bind], workgroups: [u32; 3]) -> Result<(), BackendError>;

    /// Like [`Backend::dispatch`], waits for it, and returns the device time of the pass
    /// from timestamp queries.
    fn dispatch_timed(
        &mut self,
        kernel: &Kernel,
        binds: &[Bind],
        workgroups: [u32; 3],
    ) -> Result<Duration, BackendError>;
}

/// Writes a Pod slice into a new buffer.
pub fn upload<T: bytemuck::Pod>(backend: &mut dyn Backend, label: &str, data: &[T]) -> Result<BufferId, BackendError> {
    let bytes: &[u8] = bytemuck::cast_slice(data);
    let buffer = backend.create_buffer(label, bytes.len() as u64)?;
    backend.write_buffer(buffer, 0, bytes)?;
    Ok(buffer)
}

/// Reads a buffer back as a Vec of Pod values.
pub fn download<T: bytemuck::Pod>(backend: &mut dyn Backend, buffer: BufferId) -> Result<Vec<T>, BackendError> {
    let bytes = backend.read_buffer(buffer)?;
    let size = std::mem::size_of::<T>();
    Ok(bytes[..bytes.len() / size * size].chunks_exact(size).map(bytemuck::pod_read_unaligned).collect())
}
