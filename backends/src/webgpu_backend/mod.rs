//! The [`Backend`] on WebGPU in a browser: Chromium's implementation (Dawn, with Tint
//! compiling the WGSL: a front end independent of naga), its device held by a page in a
//! headless tab.
//!
//! [`WebGpuBackend::new`] starts a loopback server (`bridge`) and headless Chromium on its
//! page (`browser`); the page (`page.js` with `executor.js`, written for strata) opens the
//! adapter and the device, and from then on every call of the [`Backend`] trait is a
//! message the page runs and answers (in a web page, wasm32, the page the module runs in
//! does the same: `in_page.rs`): buffers, textures and samplers created, written, read and
//! destroyed, pipelines created from the kernel's own WGSL ([`Kernel::source`], with
//! `enable subgroups;` put first for a kernel that uses them) and the bind group layouts
//! the wgpu backend builds ([`crate::wgpu_backend::layout_entries`]), dispatches.
//! Contents travel as raw bytes. Calls that return nothing (creations, writes, untimed
//! dispatches, destructions) are queued and sent with the next call that returns
//! something, so that a kernel's run costs a round trip per read rather than per call;
//! an error among them is reported by that call, naming the operation that failed.
//!
//! Before anything reaches the page the backend makes the checks every backend makes
//! ([`crate::bindings_check`]), against the device's WebGPU limits: a kernel that needs
//! more (workgroup memory, storage buffers per stage) or subgroups on a device without
//! them is refused by [`Backend::check_kernel`], naming the limit. Every wait for the
//! page has a timeout, and a browser that exits ends the wait at once with the end of
//! its log: a browser that never answers is an error, not a hang.

#[cfg(not(target_arch = "wasm32"))]
mod bridge;
#[cfg(not(target_arch = "wasm32"))]
mod browser;
mod channel;
#[cfg(not(target_arch = "wasm32"))]
mod devtools;
mod framing;
#[cfg(target_arch = "wasm32")]
mod in_page;
#[cfg(not(target_arch = "wasm32"))]
mod loopback;
#[cfg(not(target_arch = "wasm32"))]
pub mod page_server;

/// The script that runs the backend's messages on a `GPUDevice` (`executor.js`, an ES
/// module exporting `run`, `frame` and `unframe`): the bridge's page imports it, and so
/// does any page that holds the device for `WebGpuBackend::in_this_page` (wasm32).
pub const EXECUTOR_JS: &str = include_str!("executor.js");

#[cfg(not(target_arch = "wasm32"))]
pub use browser::{BROWSER_REQUIRED_VARIABLE, Browser, CHROMIUM_VARIABLE, browser_required, find_chromium};
#[cfg(not(target_arch = "wasm32"))]
pub use devtools::DevTools;

use crate::backend::{Backend, Bind, BufferId, Resource};
use crate::bindings_check::{
    ResourceLookup, check_binds, check_buffer_size, check_kernel_fits, check_workgroups, check_write,
};
use crate::device_info::{DeviceInfo, DeviceLimits};
use crate::error::BackendError;
use crate::texture::{AddressMode, FilterMode, SamplerDesc, SamplerId, TextureDesc, TextureId};
use channel::Channel;
use serde_json::{Value, json};
use std::collections::{HashMap, HashSet};
use std::path::PathBuf;
use std::time::Duration;
use strata_kernels::{BindingKind, Kernel, TexelFormat, TextureDimension};

/// The backend's name in reports and errors.
const NAME: &str = "webgpu";

/// The per-stage limits WebGPU has beside those of [`DeviceLimits`]: what a kernel's
/// bindings count against each, and its WebGPU name.
const STAGE_LIMITS: [(&str, &str); 4] = [
    ("storage textures", "maxStorageTexturesPerShaderStage"),
    ("sampled textures", "maxSampledTexturesPerShaderStage"),
    ("samplers", "maxSamplersPerShaderStage"),
    ("uniform buffers", "maxUniformBuffersPerShaderStage"),
];

/// How many of `kernel`'s bindings count against the per-stage limit of `what`
/// ([`STAGE_LIMITS`]).
fn stage_count(kernel: &Kernel, what: &str) -> usize {
    kernel
        .bindings
        .iter()
        .filter(|b| match what {
            "storage textures" => matches!(b.kind, BindingKind::StorageTexture { .. }),
            "sampled textures" => matches!(b.kind, BindingKind::SampledTexture { .. }),
            "samplers" => matches!(b.kind, BindingKind::Sampler),
            _ => matches!(b.kind, BindingKind::Uniform),
        })
        .count()
}

/// Whether `kernel` samples a texture with a constant texel offset. SwiftShader (the
/// adapter headless Chromium has without a GPU) places the offset wrongly on the second
/// of the two mip levels that linear mipmap filtering blends: measured on a 2-level
/// texture at level 0.5, level 1 was read two texels off instead of one, on this path
/// and identically on every Vulkan path over SwiftShader (naga's SPIR-V, glslang's,
/// Slang's: `VK_ICD_FILENAMES` naming Chromium's `vk_swiftshader_icd.json`), so a driver
/// bug, not Tint's. Such a dispatch with a sampler that filters mip levels linearly is
/// refused by name there.
fn samples_with_offsets(kernel: &Kernel) -> bool {
    let functions = kernel.module.functions.iter().map(|(_, f)| f);
    functions.chain(kernel.module.entry_points.iter().map(|ep| &ep.function)).any(|function| {
        function.expressions.iter().any(|(_, e)| matches!(e, naga::Expression::ImageSample { offset: Some(_), .. }))
    })
}

/// Operations queued before they are sent without waiting for a call that returns
/// something (a long run of dispatches without a read).
const MAX_QUEUED: usize = 256;

/// How to open a [`WebGpuBackend`].
#[derive(Clone, Debug)]
pub struct WebGpuOptions {
    /// The Chromium binary; `None`: [`find_chromium`] (`STRATA_CHROMIUM`, else `PATH`).
    pub browser: Option<PathBuf>,
    /// Request the `subgroups` feature when the adapter has it.
    pub subgroups: bool,
    /// How long the browser may take to start and open its device.
    pub start_timeout: Duration,
    /// How long one call may wait for the page's answer (a pipeline's compilation by a
    /// CPU driver included).
    pub reply_timeout: Duration,
}

impl Default for WebGpuOptions {
    fn default() -> Self {
        Self {
            browser: None,
            subgroups: true,
            start_timeout: Duration::from_secs(60),
            reply_timeout: Duration::from_secs(600),
        }
    }
}

/// A WebGPU device in a headless Chromium tab running registry kernels.
pub struct WebGpuBackend {
    info: DeviceInfo,
    /// WebGPU's per-stage limits that [`DeviceLimits`] does not hold: (what is counted,
    /// WebGPU's name of the limit, the device's value).
    stage_limits: Vec<(&'static str, &'static str, u64)>,
    /// Whether the adapter is SwiftShader ([`samples_with_offsets`]).
    swiftshader: bool,
    link: Link,
    next: u64,
    buffers: HashMap<u64, (u64, String)>,
    textures: HashMap<u64, TextureDesc>,
    samplers: HashMap<u64, SamplerDesc>,
    /// The pipelines the page holds, by [`pipeline_key`].
    pipelines: HashSet<String>,
}

/// The page's side of the backend: the channel to it, the queued operations.
struct Link {
    channel: Box<dyn Channel>,
    ops: Vec<Value>,
    /// What each queued operation is, for its error.
    what: Vec<String>,
    payload: Vec<u8>,
    reply_timeout: Duration,
}

/// An operation the page refused, as it said.
struct PageError {
    /// `validation`, `out-of-memory`, `internal`, `lost`, `shader`, `pipeline`,
    /// `unavailable`, `no-adapter`, `device`, `other`.
    kind: String,
    message: String,
    /// The operation, from the page's error scope or the queued operation's description.
    what: String,
    /// For `shader`: the line and column in the WGSL the page compiled, and how many
    /// errors it found.
    location: Option<(u64, u64, u64)>,
}

impl Link {
    fn queue(&mut self, op: Value, what: String) {
        self.ops.push(op);
        self.what.push(what);
    }

    /// Queues `op` with `bytes` attached under `key` (as `[offset, length]`).
    fn queue_with(&mut self, mut op: Value, key: &str, bytes: &[u8], what: String) {
        op[key] = json!([self.payload.len(), bytes.len()]);
        self.payload.extend_from_slice(bytes);
        self.queue(op, what);
    }

    /// Sends the queued operations and waits for the page's answer: the bytes of each
    /// operation that returns some, in order.
    fn flush(&mut self) -> Result<Vec<Vec<u8>>, PageError> {
        if self.ops.is_empty() {
            return Ok(Vec::new());
        }
        let ops = std::mem::take(&mut self.ops);
        let what = std::mem::take(&mut self.what);
        let payload = std::mem::take(&mut self.payload);
        let message = framing::frame(&json!({ "ops": ops }), &payload);
        drop(payload);
        let lost = |reason: String| PageError {
            kind: "lost".into(),
            message: reason,
            what: what.last().cloned().unwrap_or_default(),
            location: None,
        };
        let answer = self.channel.exchange(&message, self.reply_timeout).map_err(lost)?;
        drop(message);
        let (header, bytes) =
            framing::unframe(&answer).map_err(|e| lost(format!("the page's answer is broken: {e}")))?;
        if let Some(message) = header.get("error").and_then(Value::as_str) {
            let index = header.get("op").and_then(Value::as_u64).unwrap_or(0) as usize;
            let location = header.get("line").and_then(Value::as_u64).map(|line| {
                let get = |key| header.get(key).and_then(Value::as_u64).unwrap_or(0);
                (line, get("column"), get("count"))
            });
            return Err(PageError {
                kind: header.get("kind").and_then(Value::as_str).unwrap_or("other").to_string(),
                message: message.to_string(),
                what: header
                    .get("what")
                    .and_then(Value::as_str)
                    .map(str::to_string)
                    .or_else(|| what.get(index).cloned())
                    .unwrap_or_default(),
                location,
            });
        }
        let results = header
            .get("results")
            .and_then(Value::as_array)
            .ok_or_else(|| lost("the page's answer has no results".into()))?;
        results
            .iter()
            .map(|range| {
                let start = range.get(0).and_then(Value::as_u64).unwrap_or(u64::MAX) as usize;
                let length = range.get(1).and_then(Value::as_u64).unwrap_or(u64::MAX) as usize;
                start
                    .checked_add(length)
                    .and_then(|end| bytes.get(start..end))
                    .map(<[u8]>::to_vec)
                    .ok_or_else(|| lost(format!("the page's answer has no bytes {start}+{length}")))
            })
            .collect()
    }
}

/// The page's key of `kernel`'s pipeline for binds in which the sampled float textures
/// `unfilterable` cannot be filtered (as the wgpu backend keys its pipelines).
fn pipeline_key(kernel: &Kernel, unfilterable: &[(u32, u32)]) -> String {
    format!("{:?}{unfilterable:?}", kernel.pipeline_key())
}

/// The WGSL Tint compiles: the kernel's source, with `enable subgroups;` first where it
/// uses subgroup operations and does not say so (naga needs no such line; WebGPU does).
/// Returns the text and how many lines were put before the source.
fn tint_source(kernel: &Kernel) -> (String, u64) {
    strata_kernels::source::webgpu_source(&kernel.source.text, kernel.spec.features.subgroup)
}

/// WebGPU's name of a texture view dimension.
fn view_dimension(dimension: TextureDimension) -> &'static str {
    match dimension {
        TextureDimension::D1 => "1d",
        TextureDimension::D2 => "2d",
        TextureDimension::D2Array => "2d-array",
        TextureDimension::D3 => "3d",
    }
}

/// A bind group layout entry of the wgpu backend as WebGPU's `GPUBindGroupLayoutEntry`.
fn layout_entry(entry: &wgpu::BindGroupLayoutEntry) -> Value {
    let view = |dimension: wgpu::TextureViewDimension| match dimension {
        wgpu::TextureViewDimension::D1 => "1d",
        wgpu::TextureViewDimension::D2Array => "2d-array",
        wgpu::TextureViewDimension::D3 => "3d",
        wgpu::TextureViewDimension::Cube => "cube",
        wgpu::TextureViewDimension::CubeArray => "cube-array",
        _ => "2d",
    };
    let mut value = json!({ "binding": entry.binding, "visibility": 4 });
    match entry.ty {
        wgpu::BindingType::Buffer { ty, min_binding_size, .. } => {
            let kind = match ty {
                wgpu::BufferBindingType::Uniform => "uniform",
                wgpu::BufferBindingType::Storage { read_only: true } => "read-only-storage",
                wgpu::BufferBindingType::Storage { read_only: false } => "storage",
            };
            value["buffer"] = json!({ "type": kind, "minBindingSize": min_binding_size.map_or(0, |n| n.get()) });
        }
        wgpu::BindingType::Texture { sample_type, view_dimension, multisampled } => {
            let sample = match sample_type {
                wgpu::TextureSampleType::Float { filterable: true } => "float",
                wgpu::TextureSampleType::Float { filterable: false } => "unfilterable-float",
                wgpu::TextureSampleType::Sint => "sint",
                wgpu::TextureSampleType::Uint => "uint",
                wgpu::TextureSampleType::Depth => "depth",
            };
            value["texture"] =
                json!({ "sampleType": sample, "viewDimension": view(view_dimension), "multisampled": multisampled });
        }
        wgpu::BindingType::StorageTexture { access, format, view_dimension } => {
            let access = match access {
                wgpu::StorageTextureAccess::ReadOnly => "read-only",
                wgpu::StorageTextureAccess::WriteOnly => "write-only",
                _ => "read-write",
            };
            let format = TexelFormat::ALL
                .into_iter()
                .find(|f| crate::wgpu_backend::wgpu_format(*f) == format)
                .map_or("unknown", TexelFormat::wgsl);
            value["storageTexture"] =
                json!({ "access": access, "format": format, "viewDimension": view(view_dimension) });
        }
        wgpu::BindingType::Sampler(kind) => {
            let kind = match kind {
                wgpu::SamplerBindingType::Filtering => "filtering",
                wgpu::SamplerBindingType::NonFiltering => "non-filtering",
                wgpu::SamplerBindingType::Comparison => "comparison",
            };
            value["sampler"] = json!({ "type": kind });
        }
        wgpu::BindingType::AccelerationStructure { .. } | wgpu::BindingType::ExternalTexture => {
            value["unsupported"] = json!(true);
        }
    }
    value
}

impl WebGpuBackend {
    /// Starts headless Chromium on the bridge's page and opens its WebGPU device. A
    /// missing browser, a browser without WebGPU or without an adapter is
    /// [`BackendError::Unavailable`] or [`BackendError::NoAdapter`], saying which.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn new(options: WebGpuOptions) -> Result<Self, BackendError> {
        let unavailable = |why: String| BackendError::Unavailable {
            backend: NAME.into(),
            what: "WebGPU in headless Chromium".into(),
            why,
        };
        let binary = match &options.browser {
            Some(path) if path.is_file() => path.clone(),
            Some(path) => return Err(unavailable(format!("{}: no such browser", path.display()))),
            None => find_chromium().map_err(unavailable)?,
        };
        let server = bridge::Server::start().map_err(unavailable)?;
        let browser = Browser::launch(&binary, &server.url()).map_err(unavailable)?;
        let mut channel = channel::BrowserChannel { server, browser };
        match channel.wait(options.start_timeout) {
            Ok(_) => {}
            Err(bridge::WaitError::Gone(why)) => return Err(unavailable(why)),
            Err(bridge::WaitError::Timeout) => {
                return Err(unavailable(format!(
                    "the page did not load within {} s{}",
                    options.start_timeout.as_secs(),
                    channel.browser.log_tail()
                )));
            }
        }
        let fallback_name = binary.display().to_string();
        Self::open(Box::new(channel), &options, &fallback_name, unavailable)
    }

    /// Opens the WebGPU device of the page this module runs in (a web page's worker,
    /// `web/page/` of the repository), as [`WebGpuBackend::new`] opens Chromium's.
    /// Only `options.subgroups` and the timeouts apply.
    #[cfg(target_arch = "wasm32")]
    pub fn in_this_page(options: WebGpuOptions) -> Result<Self, BackendError> {
        let unavailable =
            |why: String| BackendError::Unavailable { backend: NAME.into(), what: "WebGPU in this page".into(), why };
        Self::open(Box::new(in_page::PageChannel), &options, "this page", unavailable)
    }

    /// Opens the device of the page behind `channel` (`init`), which has loaded.
    /// `fallback_name` names the browser where its user agent does not.
    fn open(
        channel: Box<dyn Channel>,
        options: &WebGpuOptions,
        fallback_name: &str,
        unavailable: impl Fn(String) -> BackendError,
    ) -> Result<Self, BackendError> {
        let mut link = Link {
            channel,
            ops: Vec::new(),
            what: Vec::new(),
            payload: Vec::new(),
            reply_timeout: options.start_timeout,
        };
        link.queue(json!({ "op": "init", "subgroups": options.subgroups }), "opening the WebGPU device".into());
        let header = match link.flush() {
            Ok(mut results) if results.len() == 1 => results.remove(0),
            Ok(_) => return Err(unavailable("the page's answer to `init` has no device".into())),
            Err(error) => {
                return Err(match error.kind.as_str() {
                    "no-adapter" => BackendError::NoAdapter { backend: NAME.into(), reason: error.message },
                    "device" => BackendError::DeviceCreation { backend: NAME.into(), reason: error.message },
                    _ => unavailable(error.message),
                });
            }
        };
        link.reply_timeout = options.reply_timeout;
        let device: Value = serde_json::from_slice(&header)
            .map_err(|e| unavailable(format!("the page's device description is not JSON: {e}")))?;
        let info = device_info(&device, fallback_name);
        let limit = |name: &str| device.get("limits").and_then(|l| l.get(name)).and_then(Value::as_u64).unwrap_or(0);
        let stage_limits = STAGE_LIMITS.iter().map(|&(what, name)| (what, name, limit(name))).collect();
        let swiftshader = device.get("architecture").and_then(Value::as_str) == Some("swiftshader");
        Ok(Self {
            info,
            stage_limits,
            swiftshader,
            link,
            next: 0,
            buffers: HashMap::new(),
            textures: HashMap::new(),
            samplers: HashMap::new(),
            pipelines: HashSet::new(),
        })
    }

    fn id(&mut self) -> u64 {
        self.next += 1;
        self.next
    }

    /// Sends what is queued; the page's error as a [`BackendError`]. `kernel` locates a
    /// shader error in its source (`lines_before`: lines put before the source).
    fn flush(&mut self, kernel: Option<(&Kernel, u64)>) -> Result<Vec<Vec<u8>>, BackendError> {
        self.link.flush().map_err(|error| {
            // The page stops at an error: a pipeline queued after it was never made.
            self.pipelines.clear();
            convert(error, kernel)
        })
    }

    fn buffer(&self, id: BufferId) -> Result<&(u64, String), BackendError> {
        self.buffers.get(&id.0).ok_or(BackendError::UnknownBuffer(id.0))
    }

    fn texture(&self, id: TextureId) -> Result<&TextureDesc, BackendError> {
        self.textures.get(&id.0).ok_or(BackendError::UnknownTexture(id.0))
    }

    /// Queues a dispatch of `kernel` (creating its pipeline first where the page has
    /// none); a timed one is sent at once, and its two timestamps returned.
    /// Sends `op`, a read-back, at once and returns the page's bytes, which must be
    /// `expected` long (`whose`: "the buffer's", "the level's", for the error).
    fn read_back(&mut self, op: Value, what: String, expected: u64, whose: &str) -> Result<Vec<u8>, BackendError> {
        self.link.queue(op, what.clone());
        let bytes = self.flush(None)?.pop().filter(|bytes| bytes.len() as u64 == expected);
        bytes.ok_or_else(|| BackendError::Validation {
            backend: NAME.into(),
            operation: what,
            message: format!("the page sent other than {whose} {expected} bytes"),
        })
    }

    fn encode(
        &mut self,
        kernel: &Kernel,
        binds: &[Bind],
        workgroups: [u32; 3],
        timed: bool,
    ) -> Result<Option<Vec<u8>>, BackendError> {
        self.check_kernel(kernel)?;
        check_workgroups(kernel, workgroups, &self.info)?;
        let lookup = ResourceLookup {
            buffer_size: &|id| self.buffer(id).map(|b| b.0),
            texture: &|id| self.texture(id).cloned(),
            sampler: &|id| self.samplers.get(&id.0).copied().ok_or(BackendError::UnknownSampler(id.0)),
        };
        check_binds(kernel, binds, &self.info, &lookup)?;
        let linear_mipmaps = binds.iter().any(|bind| {
            let Resource::Sampler(id) = bind.resource else { return false };
            self.samplers.get(&id.0).is_some_and(|desc| desc.mipmap_filter == FilterMode::Linear)
        });
        if self.swiftshader && linear_mipmaps && samples_with_offsets(kernel) {
            return Err(BackendError::Unavailable {
                backend: NAME.into(),
                what: format!("sampling with a texel offset and linear mipmap filtering (kernel `{}`)", kernel.name()),
                why: "SwiftShader reads the second mip level at the wrong place (a driver bug: every Vulkan \
                      path over SwiftShader gives the same)"
                    .into(),
            });
        }
        // Sampled float textures of a format the device cannot filter get a layout of
        // their own, as on wgpu.
        let mut unfilterable: Vec<(u32, u32)> = binds
            .iter()
            .filter(|bind| {
                let Resource::Texture(id) = bind.resource else { return false };
                let float = kernel.binding(bind.group, bind.binding).is_some_and(|info| {
                    matches!(info.kind, BindingKind::SampledTexture { kind: strata_kernels::TexelKind::Float, .. })
                });
                float && self.texture(id).is_ok_and(|desc| !desc.format.filterable() && !self.info.float32_filterable)
            })
            .map(|bind| bind.slot())
            .collect();
        unfilterable.sort_unstable();
        let key = pipeline_key(kernel, &unfilterable);
        let (source, lines_before) = tint_source(kernel);
        if !self.pipelines.contains(&key) {
            let layouts: Vec<Value> = (0..kernel.group_count())
                .map(|group| {
                    let entries = crate::wgpu_backend::layout_entries_with(kernel, group, &unfilterable);
                    Value::Array(entries.iter().map(layout_entry).collect())
                })
                .collect();
            let constants: serde_json::Map<String, Value> =
                kernel.overrides().iter().map(|(name, value)| (name.clone(), json!(value))).collect();
            let op = json!({
                "op": "pipeline",
                "key": key,
                "label": kernel.name(),
                "entry": kernel.entry_point(),
                "layouts": layouts,
                "constants": constants,
            });
            self.link.queue_with(op, "wgsl", source.as_bytes(), format!("pipeline creation for `{}`", kernel.name()));
            // At once, so that a compilation error is located in the kernel's files.
            self.flush(Some((kernel, lines_before)))?;
            self.pipelines.insert(key.clone());
        }
        let binds: Vec<Value> = binds
            .iter()
            .map(|bind| {
                let mut value = json!({ "group": bind.group, "binding": bind.binding });
                match bind.resource {
                    Resource::Buffer(id) => value["buffer"] = json!(id.0),
                    Resource::Sampler(id) => value["sampler"] = json!(id.0),
                    Resource::Texture(id) => {
                        let storage = kernel
                            .binding(bind.group, bind.binding)
                            .is_some_and(|info| matches!(info.kind, BindingKind::StorageTexture { .. }));
                        value["texture"] = json!(id.0);
                        value["storage"] = json!(storage);
                        value["viewDimension"] = json!(view_dimension(self.texture(id)?.dimension));
                    }
                }
                Ok(value)
            })
            .collect::<Result<_, BackendError>>()?;
        let op = json!({
            "op": "dispatch",
            "key": key,
            "label": kernel.name(),
            "binds": binds,
            "workgroups": workgroups,
            "timed": timed,
        });
        self.link.queue(op, format!("dispatch of `{}`", kernel.name()));
        if timed {
            // The answer carries the pass's two timestamps.
            let mut results = self.flush(None)?;
            return results.pop().filter(|bytes| bytes.len() == 16).map(Some).ok_or_else(|| BackendError::Validation {
                backend: NAME.into(),
                operation: format!("timing of `{}`", kernel.name()),
                message: "the page sent no timestamps".into(),
            });
        }
        if self.link.ops.len() >= MAX_QUEUED {
            self.flush(None)?;
        }
        Ok(None)
    }
}

/// The page's error as a [`BackendError`]; a shader error located in `kernel`'s files.
fn convert(error: PageError, kernel: Option<(&Kernel, u64)>) -> BackendError {
    let PageError { kind, message, what, location } = error;
    match kind.as_str() {
        "out-of-memory" => BackendError::OutOfMemory { backend: NAME.into(), operation: what },
        "lost" => BackendError::DeviceLost { backend: NAME.into(), reason: message },
        "no-adapter" => BackendError::NoAdapter { backend: NAME.into(), reason: message },
        "device" => BackendError::DeviceCreation { backend: NAME.into(), reason: message },
        "unavailable" => BackendError::Unavailable { backend: NAME.into(), what, why: message },
        "shader" => {
            let (line, column, count) = location.unwrap_or_default();
            let place = match kernel {
                Some((kernel, before)) if line > before => {
                    let (path, local) = kernel.source.locate((line - before) as usize);
                    format!("{path}:{local}:{column}")
                }
                _ => format!("line {line}:{column}"),
            };
            let more = if count > 1 { format!(" (and {} more)", count - 1) } else { String::new() };
            let name = kernel.map_or("the kernel", |(kernel, _)| kernel.name());
            BackendError::Validation {
                backend: NAME.into(),
                operation: format!("Tint's compilation of `{name}`"),
                message: format!("{place}: {message}{more}"),
            }
        }
        "internal" => BackendError::Validation {
            backend: NAME.into(),
            operation: what,
            message: format!("internal error: {message}"),
        },
        _ => BackendError::Validation { backend: NAME.into(), operation: what, message },
    }
}

/// The device the page opened, from its description (`init`'s answer).
fn device_info(device: &Value, fallback_name: &str) -> DeviceInfo {
    let text = |key: &str| device.get(key).and_then(Value::as_str).unwrap_or("").to_string();
    let limit = |name: &str| device.get("limits").and_then(|l| l.get(name)).and_then(Value::as_u64).unwrap_or(0);
    let limit32 = |name: &str| u32::try_from(limit(name)).unwrap_or(u32::MAX);
    let has = |feature: &str| {
        device.get("features").and_then(Value::as_array).is_some_and(|list| list.iter().any(|f| f == feature))
    };
    let subgroups = device.get("subgroups").and_then(Value::as_array).map(|sizes| {
        let size = |i: usize| sizes.get(i).and_then(Value::as_u64).and_then(|n| u32::try_from(n).ok()).unwrap_or(0);
        (size(0), size(1))
    });
    let parts: Vec<String> =
        ["vendor", "architecture", "device", "description"].iter().map(|k| text(k)).filter(|t| !t.is_empty()).collect();
    let architecture = text("architecture");
    // WebGPU does not say what kind of device an adapter is; SwiftShader and a fallback
    // adapter run on the CPU.
    let cpu = device.get("fallback").and_then(Value::as_bool).unwrap_or(false) || architecture == "swiftshader";
    let browser = text("userAgent")
        .split_whitespace()
        .find(|word| word.starts_with("HeadlessChrome/") || word.starts_with("Chrome/"))
        .map(str::to_string)
        .unwrap_or_else(|| fallback_name.to_string());
    DeviceInfo {
        backend: NAME.into(),
        adapter: if parts.is_empty() { "unnamed adapter".into() } else { parts.join(" ") },
        device_type: if cpu { "Cpu".into() } else { "Gpu".into() },
        driver: format!("{browser} (Dawn, Tint)"),
        subgroup_sizes: subgroups,
        timestamps: has("timestamp-query"),
        float32_filterable: has("float32-filterable"),
        limits: DeviceLimits {
            max_workgroup_storage: limit("maxComputeWorkgroupStorageSize"),
            max_invocations_per_workgroup: limit32("maxComputeInvocationsPerWorkgroup"),
            max_workgroup_size: [
                limit32("maxComputeWorkgroupSizeX"),
                limit32("maxComputeWorkgroupSizeY"),
                limit32("maxComputeWorkgroupSizeZ"),
            ],
            max_workgroups_per_dimension: limit32("maxComputeWorkgroupsPerDimension"),
            max_storage_binding: limit("maxStorageBufferBindingSize"),
            max_uniform_binding: limit("maxUniformBufferBindingSize"),
            max_buffer_size: limit("maxBufferSize"),
            max_storage_buffers_per_stage: limit32("maxStorageBuffersPerShaderStage"),
            max_texture_2d: limit32("maxTextureDimension2D").min(limit32("maxTextureDimension1D")),
            max_texture_3d: limit32("maxTextureDimension3D"),
            max_texture_layers: limit32("maxTextureArrayLayers"),
            max_bind_groups: limit32("maxBindGroups"),
        },
    }
}

/// The page's operation `op` on level `level` of `texture` (a write or a read-back): its
/// size and row pitch, tightly packed.
fn level_op(op: &str, texture: TextureId, level: u32, desc: &TextureDesc) -> Value {
    let size = desc.level_size(level);
    json!({
        "op": op,
        "id": texture.0,
        "level": level,
        "size": size,
        "bytesPerRow": size[0] * desc.format.bytes_per_texel(),
    })
}

fn address_mode(mode: AddressMode) -> &'static str {
    match mode {
        AddressMode::ClampToEdge => "clamp-to-edge",
        AddressMode::Repeat => "repeat",
        AddressMode::MirrorRepeat => "mirror-repeat",
    }
}

fn filter_mode(mode: FilterMode) -> &'static str {
    match mode {
        FilterMode::Nearest => "nearest",
        FilterMode::Linear => "linear",
    }
}

impl Backend for WebGpuBackend {
    fn info(&self) -> &DeviceInfo {
        &self.info
    }

    fn create_buffer(&mut self, label: &str, size: u64) -> Result<BufferId, BackendError> {
        check_buffer_size(label, size, &self.info)?;
        let id = self.id();
        let op = json!({ "op": "createBuffer", "id": id, "size": size, "label": label });
        self.link.queue(op, format!("creation of buffer `{label}` ({size} bytes)"));
        self.buffers.insert(id, (size, label.to_string()));
        Ok(BufferId(id))
    }

    fn write_buffer(&mut self, buffer: BufferId, offset: u64, data: &[u8]) -> Result<(), BackendError> {
        let (size, label) = self.buffer(buffer)?;
        check_write(label, *size, offset, data.len())?;
        if data.is_empty() {
            return Ok(());
        }
        let what = format!("write of buffer `{label}`");
        self.link.queue_with(json!({ "op": "writeBuffer", "id": buffer.0, "offset": offset }), "data", data, what);
        Ok(())
    }

    fn read_buffer(&mut self, buffer: BufferId) -> Result<Vec<u8>, BackendError> {
        let (size, label) = self.buffer(buffer)?;
        let (size, what) = (*size, format!("read-back of buffer `{label}`"));
        self.read_back(json!({ "op": "readBuffer", "id": buffer.0 }), what, size, "the buffer's")
    }

    fn destroy_buffer(&mut self, buffer: BufferId) -> Result<(), BackendError> {
        let (_, label) = self.buffers.remove(&buffer.0).ok_or(BackendError::UnknownBuffer(buffer.0))?;
        self.link.queue(json!({ "op": "destroyBuffer", "id": buffer.0 }), format!("destruction of buffer `{label}`"));
        Ok(())
    }

    fn create_texture(&mut self, desc: &TextureDesc) -> Result<TextureId, BackendError> {
        desc.check(&self.info)?;
        let id = self.id();
        let dimension = match desc.dimension {
            TextureDimension::D1 => "1d",
            TextureDimension::D2 | TextureDimension::D2Array => "2d",
            TextureDimension::D3 => "3d",
        };
        let op = json!({
            "op": "createTexture",
            "id": id,
            "label": desc.label,
            "dimension": dimension,
            "size": desc.size,
            "mipLevels": desc.mip_levels,
            "format": desc.format.wgsl(),
        });
        self.link.queue(op, format!("creation of texture `{}`", desc.label));
        self.textures.insert(id, desc.clone());
        Ok(TextureId(id))
    }

    fn write_texture(&mut self, texture: TextureId, level: u32, data: &[u8]) -> Result<(), BackendError> {
        let desc = self.texture(texture)?;
        desc.check_level(level, data.len())?;
        let op = level_op("writeTexture", texture, level, desc);
        let what = format!("write of texture `{}` level {level}", desc.label);
        self.link.queue_with(op, "data", data, what);
        Ok(())
    }

    fn read_texture(&mut self, texture: TextureId, level: u32) -> Result<Vec<u8>, BackendError> {
        let desc = self.texture(texture)?;
        let expected = desc.level_bytes(level);
        desc.check_level(level, expected as usize)?;
        let op = level_op("readTexture", texture, level, desc);
        let what = format!("read-back of texture `{}` level {level}", desc.label);
        self.read_back(op, what, expected, "the level's")
    }

    fn destroy_texture(&mut self, texture: TextureId) -> Result<(), BackendError> {
        let desc = self.textures.remove(&texture.0).ok_or(BackendError::UnknownTexture(texture.0))?;
        let what = format!("destruction of texture `{}`", desc.label);
        self.link.queue(json!({ "op": "destroyTexture", "id": texture.0 }), what);
        Ok(())
    }

    fn create_sampler(&mut self, desc: &SamplerDesc) -> Result<SamplerId, BackendError> {
        let id = self.id();
        let descriptor = json!({
            "label": "strata sampler",
            "addressModeU": address_mode(desc.address[0]),
            "addressModeV": address_mode(desc.address[1]),
            "addressModeW": address_mode(desc.address[2]),
            "magFilter": filter_mode(desc.mag_filter),
            "minFilter": filter_mode(desc.min_filter),
            "mipmapFilter": filter_mode(desc.mipmap_filter),
        });
        self.link.queue(
            json!({ "op": "createSampler", "id": id, "descriptor": descriptor }),
            format!("creation of sampler {id}"),
        );
        self.samplers.insert(id, *desc);
        Ok(SamplerId(id))
    }

    fn destroy_sampler(&mut self, sampler: SamplerId) -> Result<(), BackendError> {
        self.samplers.remove(&sampler.0).ok_or(BackendError::UnknownSampler(sampler.0))?;
        self.link
            .queue(json!({ "op": "destroySampler", "id": sampler.0 }), format!("destruction of sampler {}", sampler.0));
        Ok(())
    }

    fn check_kernel(&self, kernel: &Kernel) -> Result<(), BackendError> {
        check_kernel_fits(kernel, &self.info)?;
        for &(what, name, limit) in &self.stage_limits {
            let count = stage_count(kernel, what);
            if count as u64 > limit {
                return Err(BackendError::Unavailable {
                    backend: NAME.into(),
                    what: format!("kernel `{}` with {count} {what}", kernel.name()),
                    why: format!("the device allows at most {limit} per shader stage (WebGPU's {name})"),
                });
            }
        }
        Ok(())
    }

    fn dispatch(&mut self, kernel: &Kernel, binds: &[Bind], workgroups: [u32; 3]) -> Result<(), BackendError> {
        self.encode(kernel, binds, workgroups, false).map(|_| ())
    }

    fn dispatch_timed(
        &mut self,
        kernel: &Kernel,
        binds: &[Bind],
        workgroups: [u32; 3],
    ) -> Result<Duration, BackendError> {
        if !self.info.timestamps {
            return Err(BackendError::NoTimestamps(NAME.into()));
        }
        let bytes = self.encode(kernel, binds, workgroups, true)?.unwrap_or_default();
        let ticks: [u64; 2] = bytemuck::pod_read_unaligned(&bytes);
        // WebGPU's timestamps are in nanoseconds.
        Ok(Duration::from_nanos(ticks[1].saturating_sub(ticks[0])))
    }
}
