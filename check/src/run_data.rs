//! The data a kernel run takes and gives (`cargo xtask run`): input files read whole
//! and capped, the inputs by binding, and each backend's output buffers. Shared by the
//! run itself ([`crate::run_kernel`]), its image inputs ([`crate::run_images`]) and its
//! judgement ([`crate::agreement`]), which therefore need not import one another.

use anyhow::Result;
use std::path::Path;
use strata_backends::{SamplerDesc, TextureDesc};
use strata_kernels::WordKinds;

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

/// The largest buffer or texture file read, and the largest zero-filled buffer or
/// texture made (`--size`, `--storage-texture`); a device's own limits are checked after,
/// before anything of the size is allocated.
pub const MAX_INPUT_BYTES: u64 = 4 << 30;

/// The whole regular file `path` (a link to one is followed), at most `cap` bytes: a named
/// pipe, a device (`/dev/zero`) or a link to one is refused at once by name, never waited on or read until memory runs
/// out, and the size is checked before anything is allocated.
pub fn read_input(path: &Path, cap: u64) -> Result<Vec<u8>> {
    Ok(strata_files::read_named_regular_capped(path, cap)?)
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

/// A binding's `(group, binding)`.
pub type Slot = (u32, u32);

/// Buffer contents by `(group, binding)`.
pub type GroupedInputs = Vec<(Slot, Vec<u8>)>;

/// Textures and samplers by `(group, binding)`.
pub type GroupedImages = Vec<(Slot, ImageInput)>;
