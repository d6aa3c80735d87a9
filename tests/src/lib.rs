//! Shared helpers of strata's integration tests.

pub mod corpus_support;
pub mod wgsl_fuzz;

use strata_backends::wgpu_backend::{WgpuApi, WgpuBackend, WgpuOptions};
use strata_backends::{BackendError, GPU_REQUIRED_VARIABLE, gpu_required};

/// Dispatches `kernel` on `workgroups` workgroups with `inputs` bound as binding 0 and an
/// output buffer of `outputs` words as binding 1; returns the output's words.
pub fn run_words(
    backend: &mut dyn strata_backends::Backend,
    kernel: &strata_kernels::Kernel,
    inputs: &[u32],
    outputs: usize,
    workgroups: u32,
) -> Vec<u32> {
    use strata_backends::backend::{download, upload};
    let input = upload(backend, "input", inputs).unwrap();
    let output = backend.create_buffer("output", outputs as u64 * 4).unwrap();
    let binds = [strata_backends::Bind::new(0, input), strata_backends::Bind::new(1, output)];
    backend.dispatch(kernel, &binds, [workgroups, 1, 1]).unwrap();
    let words = download(backend, output).unwrap();
    backend.destroy_buffer(input).unwrap();
    backend.destroy_buffer(output).unwrap();
    words
}

/// The test scenes committed in the repository (`scenes/`: the shared JSON + PLY scenes
/// with their licences), so that a clone alone passes its tests.
pub fn scenes_folder() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes")
}

/// The wgpu Vulkan backend, or `None` (with a note on stderr) when the machine has no
/// Vulkan device. Under `STRATA_REQUIRE_GPU=1` a missing device fails the test instead.
///
/// Without the Vulkan validation layer: under wgpu the layer's messages go to the `log`
/// crate, which no test reads, so here it could fail nothing, and it cost about an eighth
/// of the statistical tests' CPU time (tests/tests/restir.rs, docs/benchmarks/ci-time.md
/// "The validation layer where nothing reads it"). wgpu still validates every call itself.
/// The layer's verdict on the wgpu route is read where it counts: `cargo xtask validate`
/// runs `strata render` and `strata compare` (every method, with temporal reuse and
/// accumulated) under it with synchronization validation and fails on any error or
/// warning, and the ash backend's tests assert on the messages they collect.
pub fn vulkan_backend(test: &str) -> Option<WgpuBackend> {
    open_or_skip(test, WgpuOptions { api: WgpuApi::Vulkan, validation: false, subgroups: true, ..Default::default() })
}

/// Like [`vulkan_backend`] with explicit options.
pub fn open_or_skip(test: &str, options: WgpuOptions) -> Option<WgpuBackend> {
    match WgpuBackend::new(options) {
        Ok(backend) => Some(backend),
        Err(error @ BackendError::NoAdapter { .. }) if !gpu_required() => {
            eprintln!("SKIPPED {test}: {error} (set {GPU_REQUIRED_VARIABLE}=1 to make this a failure)");
            None
        }
        Err(error) => {
            panic!("{test}: {error} ({GPU_REQUIRED_VARIABLE} is set: a GPU device is required)")
        }
    }
}

/// A 32-bit pattern written into output buffers before a run, so that elements the
/// kernel fails to write are caught.
pub const POISON: u32 = 0xdead_beef;

/// A raw wgpu Vulkan device (no strata backend around it), as an embedding engine would
/// own one, with `limits` (the adapter's own when `None`) and subgroups if the adapter
/// has them; `None` (with a note on stderr) when the machine has no Vulkan device, a
/// failure under `STRATA_REQUIRE_GPU=1`.
pub fn engine_device(test: &str, limits: Option<wgpu::Limits>) -> Option<(wgpu::Device, wgpu::Queue)> {
    let mut descriptor = wgpu::InstanceDescriptor::new_without_display_handle();
    descriptor.backends = wgpu::Backends::VULKAN;
    let instance = wgpu::Instance::new(descriptor);
    let adapter = match pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions::default())) {
        Ok(adapter) => adapter,
        Err(error) if !gpu_required() => {
            eprintln!(
                "SKIPPED {test}: no Vulkan adapter: {error} (set {GPU_REQUIRED_VARIABLE}=1 to make this a failure)"
            );
            return None;
        }
        Err(error) => panic!("{test}: no Vulkan adapter: {error} ({GPU_REQUIRED_VARIABLE} is set)"),
    };
    let descriptor = wgpu::DeviceDescriptor {
        required_features: adapter.features() & wgpu::Features::SUBGROUP,
        required_limits: limits.unwrap_or_else(|| adapter.limits()),
        ..Default::default()
    };
    let device = pollster::block_on(adapter.request_device(&descriptor)).unwrap_or_else(|e| panic!("{test}: {e}"));
    Some(device)
}

/// Copies a wgpu buffer back to the CPU (test helper; panics on failure).
pub fn read_wgpu_buffer<T: bytemuck::Pod>(device: &wgpu::Device, queue: &wgpu::Queue, buffer: &wgpu::Buffer) -> Vec<T> {
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("read back"),
        size: buffer.size(),
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    encoder.copy_buffer_to_buffer(buffer, 0, &staging, 0, buffer.size());
    queue.submit([encoder.finish()]);
    staging.slice(..).map_async(wgpu::MapMode::Read, |result| result.expect("map"));
    device.poll(wgpu::PollType::wait_indefinitely()).expect("poll");
    let view = staging.slice(..).get_mapped_range().expect("mapped");
    bytemuck::cast_slice(&view).to_vec()
}

/// A raw Vulkan device made through ash, as an embedding engine would own one: the
/// first physical device with a compute queue, that queue, a command pool, and
/// `shaderZeroInitializeWorkgroupMemory` where [`AshEngine::open`] was asked for it and
/// the device has it. `None` (with a note) without a Vulkan loader or device; a failure
/// under `STRATA_REQUIRE_GPU=1`.
pub struct AshEngine {
    _entry: ash::Entry,
    /// The instance.
    pub instance: ash::Instance,
    /// The physical device.
    pub physical_device: ash::vk::PhysicalDevice,
    /// The device.
    pub device: ash::Device,
    /// Its compute queue.
    pub queue: ash::vk::Queue,
    /// A pool for one-shot command buffers.
    pub command_pool: ash::vk::CommandPool,
    /// Whether `shaderZeroInitializeWorkgroupMemory` is enabled on the device.
    pub zero_initializes_workgroup_memory: bool,
}

impl AshEngine {
    /// Opens the device with `shaderZeroInitializeWorkgroupMemory` enabled where the
    /// device has it, as an engine that wants fast pipeline builds would, or `None` (see
    /// the type's docs).
    pub fn open(test: &str) -> Option<Self> {
        Self::open_with(test, true)
    }

    /// Opens the device with core features only (zeroing of workgroup memory left to the
    /// shaders), or `None` (see the type's docs).
    pub fn open_plain(test: &str) -> Option<Self> {
        Self::open_with(test, false)
    }

    /// The loader's `vkGetInstanceProcAddr`, as a C engine hands it to `strata_vk_create`.
    pub fn get_instance_proc_addr(&self) -> ash::vk::PFN_vkGetInstanceProcAddr {
        self._entry.static_fn().get_instance_proc_addr
    }

    /// The device as the embeddable pass takes it.
    pub fn embed_device(&self) -> strata_embed::AshDevice<'_> {
        strata_embed::AshDevice {
            instance: &self.instance,
            physical_device: self.physical_device,
            device: &self.device,
            shader_zero_initialize_workgroup_memory: self.zero_initializes_workgroup_memory,
        }
    }

    fn open_with(test: &str, zero_init_if_supported: bool) -> Option<Self> {
        use ash::vk;
        let fail = |why: String| -> Option<Self> {
            if gpu_required() {
                panic!("{test}: {why} ({GPU_REQUIRED_VARIABLE} is set)");
            }
            eprintln!("SKIPPED {test}: {why} (set {GPU_REQUIRED_VARIABLE}=1 to make this a failure)");
            None
        };
        // SAFETY: loading the system's Vulkan loader, then plain object creation with
        // valid create infos; every object is destroyed in Drop.
        unsafe {
            let entry = match ash::Entry::load() {
                Ok(entry) => entry,
                Err(error) => return fail(format!("no Vulkan loader: {error}")),
            };
            let app = vk::ApplicationInfo::default().api_version(vk::API_VERSION_1_2);
            let instance = match entry.create_instance(&vk::InstanceCreateInfo::default().application_info(&app), None)
            {
                Ok(instance) => instance,
                Err(error) => return fail(format!("vkCreateInstance: {error:?}")),
            };
            let found = instance.enumerate_physical_devices().unwrap_or_default().into_iter().find_map(|pd| {
                instance
                    .get_physical_device_queue_family_properties(pd)
                    .iter()
                    .position(|f| f.queue_flags.contains(vk::QueueFlags::COMPUTE))
                    .map(|family| (pd, family as u32))
            });
            let Some((physical_device, family)) = found else {
                instance.destroy_instance(None);
                return fail("no Vulkan device with a compute queue".into());
            };
            let priorities = [1.0];
            let queues =
                [vk::DeviceQueueCreateInfo::default().queue_family_index(family).queue_priorities(&priorities)];
            // The feature through its extension (the instance is 1.2): asked for only where
            // the device is 1.1 or newer and lists the extension.
            let extension = ash::khr::zero_initialize_workgroup_memory::NAME;
            let has_extension = instance.get_physical_device_properties(physical_device).api_version
                >= vk::API_VERSION_1_1
                && instance
                    .enumerate_device_extension_properties(physical_device)
                    .unwrap_or_default()
                    .iter()
                    .any(|e| e.extension_name_as_c_str() == Ok(extension));
            let mut supported = vk::PhysicalDeviceZeroInitializeWorkgroupMemoryFeatures::default();
            if zero_init_if_supported && has_extension {
                instance.get_physical_device_features2(
                    physical_device,
                    &mut vk::PhysicalDeviceFeatures2::default().push_next(&mut supported),
                );
            }
            let zero_init = supported.shader_zero_initialize_workgroup_memory == vk::TRUE;
            let mut enabled = vk::PhysicalDeviceZeroInitializeWorkgroupMemoryFeatures::default()
                .shader_zero_initialize_workgroup_memory(true);
            let extensions = [extension.as_ptr()];
            let mut create = vk::DeviceCreateInfo::default().queue_create_infos(&queues);
            if zero_init {
                create = create.enabled_extension_names(&extensions).push_next(&mut enabled);
            }
            let device = instance
                .create_device(physical_device, &create, None)
                .unwrap_or_else(|e| panic!("{test}: vkCreateDevice: {e:?}"));
            let queue = device.get_device_queue(family, 0);
            let command_pool = device
                .create_command_pool(&vk::CommandPoolCreateInfo::default().queue_family_index(family), None)
                .unwrap_or_else(|e| panic!("{test}: vkCreateCommandPool: {e:?}"));
            Some(Self {
                _entry: entry,
                instance,
                physical_device,
                device,
                queue,
                command_pool,
                zero_initializes_workgroup_memory: zero_init,
            })
        }
    }

    /// A host-visible, coherent storage buffer filled with `contents` (zeros past it).
    pub fn buffer(&self, size: u64, contents: &[u8]) -> (ash::vk::Buffer, ash::vk::DeviceMemory) {
        use ash::vk;
        // SAFETY: valid device; the caller frees the buffer with `free`.
        unsafe {
            let info = vk::BufferCreateInfo::default().size(size).usage(vk::BufferUsageFlags::STORAGE_BUFFER);
            let buffer = self.device.create_buffer(&info, None).expect("buffer");
            let requirements = self.device.get_buffer_memory_requirements(buffer);
            let memory = self.instance.get_physical_device_memory_properties(self.physical_device);
            let wanted = vk::MemoryPropertyFlags::HOST_VISIBLE | vk::MemoryPropertyFlags::HOST_COHERENT;
            let index = (0..memory.memory_type_count)
                .find(|&i| {
                    requirements.memory_type_bits & (1 << i) != 0
                        && memory.memory_types[i as usize].property_flags.contains(wanted)
                })
                .expect("host-visible memory");
            let allocate =
                vk::MemoryAllocateInfo::default().allocation_size(requirements.size).memory_type_index(index);
            let memory = self.device.allocate_memory(&allocate, None).expect("memory");
            self.device.bind_buffer_memory(buffer, memory, 0).expect("bind");
            let mapped =
                self.device.map_memory(memory, 0, size, vk::MemoryMapFlags::empty()).expect("map").cast::<u8>();
            std::ptr::write_bytes(mapped, 0, size as usize);
            std::ptr::copy_nonoverlapping(contents.as_ptr(), mapped, contents.len().min(size as usize));
            self.device.unmap_memory(memory);
            (buffer, memory)
        }
    }

    /// Reads a buffer made by [`Self::buffer`].
    pub fn read<T: bytemuck::Pod>(&self, memory: ash::vk::DeviceMemory, size: u64) -> Vec<T> {
        // SAFETY: host-visible memory of at least `size` bytes; the queue is idle.
        unsafe {
            let mapped =
                self.device.map_memory(memory, 0, size, ash::vk::MemoryMapFlags::empty()).expect("map").cast::<u8>();
            let data = bytemuck::cast_slice(std::slice::from_raw_parts(mapped, size as usize)).to_vec();
            self.device.unmap_memory(memory);
            data
        }
    }

    /// Frees a buffer made by [`Self::buffer`].
    pub fn free(&self, (buffer, memory): (ash::vk::Buffer, ash::vk::DeviceMemory)) {
        // SAFETY: the queue is idle.
        unsafe {
            self.device.destroy_buffer(buffer, None);
            self.device.free_memory(memory, None);
        }
    }

    /// Records with `record`, submits, waits.
    pub fn submit(&self, record: impl FnOnce(ash::vk::CommandBuffer)) {
        use ash::vk;
        // SAFETY: valid pool and queue; waited for before freeing.
        unsafe {
            let info = vk::CommandBufferAllocateInfo::default()
                .command_pool(self.command_pool)
                .level(vk::CommandBufferLevel::PRIMARY)
                .command_buffer_count(1);
            let command_buffer = self.device.allocate_command_buffers(&info).expect("command buffer")[0];
            self.device.begin_command_buffer(command_buffer, &vk::CommandBufferBeginInfo::default()).expect("begin");
            record(command_buffer);
            self.device.end_command_buffer(command_buffer).expect("end");
            let buffers = [command_buffer];
            self.device
                .queue_submit(self.queue, &[vk::SubmitInfo::default().command_buffers(&buffers)], vk::Fence::null())
                .expect("submit");
            self.device.queue_wait_idle(self.queue).expect("wait");
            self.device.free_command_buffers(self.command_pool, &buffers);
        }
    }
}

impl Drop for AshEngine {
    fn drop(&mut self) {
        // SAFETY: children are destroyed by their owners first; the device is idle.
        unsafe {
            let _ = self.device.device_wait_idle();
            self.device.destroy_command_pool(self.command_pool, None);
            self.device.destroy_device(None);
            self.instance.destroy_instance(None);
        }
    }
}

/// The resampling inputs the embedding tests and benches give pixel p of `count`: weights
/// 1, 0.5 (p mod 3), 2 and `fourth_weight`, targets 1 to 4, a canonical sample of weight
/// 0.25 and target 0.5 whose payload is p.
pub fn resample_inputs(count: u32, fourth_weight: f32) -> Vec<strata_embed::contract::ResampleInput> {
    (0..count)
        .map(|p| strata_embed::contract::ResampleInput {
            weights: [1.0, 0.5 * (p % 3) as f32, 2.0, fourth_weight],
            targets: [1.0, 2.0, 3.0, 4.0],
            canonical_weight: 0.25,
            canonical_target: 0.5,
            canonical_payload: p,
            _pad: 0,
        })
        .collect()
}

/// The engine's buffers that the routes to the embeddable pass are compared on (the C
/// program of the kernel package, the ES module in Chromium), for a `width` × `height`
/// image: one candidate per pixel over a few objects, with some invalid keys (NaN) and
/// pixels without a candidate (`u32::MAX`), payloads, and resampling inputs.
#[allow(clippy::type_complexity)]
pub fn engine_inputs(
    width: u32,
    height: u32,
) -> (Vec<strata_embed::contract::Candidate>, Vec<u32>, Vec<strata_embed::contract::ResampleInput>) {
    let pixels = width * height;
    let candidates = (0..pixels)
        .map(|p| {
            let key = if p % 37 == 5 { f32::NAN } else { ((p * 7919) % 113) as f32 * 0.05 };
            let object_id = if p % 53 == 0 { u32::MAX } else { (p % width) / 11 + 4 * (p / width / 8) };
            strata_embed::contract::Candidate { key, object_id }
        })
        .collect();
    let payloads = (0..pixels).map(|p| p.wrapping_mul(2_654_435_761) >> 7).collect();
    let resample = (0..pixels)
        .map(|p| strata_embed::contract::ResampleInput {
            weights: [1.0 + (p % 5) as f32, 0.5 * (p % 3) as f32, 2.0, 0.25],
            targets: [1.0, 2.0, 3.0, 4.0],
            canonical_weight: 0.75,
            canonical_target: 0.5,
            canonical_payload: p,
            _pad: 0,
        })
        .collect();
    (candidates, payloads, resample)
}

/// The engine's inputs of one run of the embeddable pass.
pub struct EmbedInputs<'a> {
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// One candidate per pixel.
    pub candidates: &'a [strata_embed::contract::Candidate],
    /// One payload per pixel, or `None` (a pixel's payload is its index).
    pub payloads: Option<&'a [u32]>,
    /// One resampling input per pixel.
    pub resample: &'a [strata_embed::contract::ResampleInput],
}

/// Each frame's selections and resampling results.
pub type EmbedFrames =
    Vec<(Vec<strata_embed::contract::SelectedCandidates>, Vec<strata_embed::contract::ResampleOutput>)>;

/// The first frame and pixel where two routes' frames differ, in words (`None` when they
/// are equal byte for byte).
pub fn first_frame_difference(got: &EmbedFrames, want: &EmbedFrames) -> Option<String> {
    for (frame, ((gs, gr), (ws, wr))) in got.iter().zip(want).enumerate() {
        if (gs.len(), gr.len()) != (ws.len(), wr.len()) {
            return Some(format!(
                "frame {frame}: {} selections and {} resampled against {} and {}",
                gs.len(),
                gr.len(),
                ws.len(),
                wr.len()
            ));
        }
        if let Some(p) = (0..ws.len()).find(|&p| bytemuck::bytes_of(&gs[p]) != bytemuck::bytes_of(&ws[p])) {
            return Some(format!("frame {frame}, pixel {p}: selection {:?} against {:?}", gs[p], ws[p]));
        }
        if let Some(p) = (0..wr.len()).find(|&p| bytemuck::bytes_of(&gr[p]) != bytemuck::bytes_of(&wr[p])) {
            return Some(format!("frame {frame}, pixel {p}: resampled {:?} against {:?}", gr[p], wr[p]));
        }
    }
    (got.len() != want.len()).then(|| format!("{} frames against {}", got.len(), want.len()))
}

/// Frames `0..frames` of `strata_embed`'s wgpu flavour over `inputs`, with `settings` and
/// render `seed`: what every other route to the pass (ash, the C ABI, the C program from
/// the kernel package) must equal bit for bit.
pub fn wgpu_embed_frames(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    settings: strata_embed::SelectionSettings,
    seed: u32,
    inputs: &EmbedInputs,
    frames: u32,
) -> EmbedFrames {
    use strata_embed::contract::{ResampleOutput, SelectedCandidates};
    use wgpu::util::DeviceExt;
    let usage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC;
    let init =
        |contents: &[u8]| device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: None, contents, usage });
    let pixels = (inputs.width * inputs.height) as usize;
    let candidates = init(bytemuck::cast_slice(inputs.candidates));
    let payloads = inputs.payloads.map(|p| init(bytemuck::cast_slice(p)));
    let selections = init(&vec![0; pixels * size_of::<SelectedCandidates>()]);
    let weights = init(bytemuck::cast_slice(inputs.resample));
    let outputs = init(&vec![0; pixels * size_of::<ResampleOutput>()]);
    let mut pass = strata_embed::WgpuSelection::new(device, settings, inputs.width, inputs.height).unwrap();
    pass.set_seed(seed);
    let bindings = pass
        .bind(
            device,
            &strata_embed::WgpuBuffers {
                candidates: (&candidates).into(),
                payloads: payloads.as_ref().map(Into::into),
                selections: (&selections).into(),
                resample: Some(strata_embed::WgpuResampleBuffers {
                    inputs: (&weights).into(),
                    outputs: (&outputs).into(),
                }),
            },
        )
        .unwrap();
    (0..frames)
        .map(|frame| {
            let mut encoder = device.create_command_encoder(&Default::default());
            pass.encode_selection(queue, &mut encoder, &bindings, frame).unwrap();
            pass.encode_resampling(&mut encoder, &bindings).unwrap();
            queue.submit([encoder.finish()]);
            (read_wgpu_buffer(device, queue, &selections), read_wgpu_buffer(device, queue, &outputs))
        })
        .collect()
}
