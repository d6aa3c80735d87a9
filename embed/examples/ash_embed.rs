//! A minimal raw-Vulkan engine (through `ash`) that adopts the stratified selection: it
//! owns its instance, device, queue, command buffers and buffers; the pass records into
//! its command buffer with its buffers. The engine writes one candidate per pixel, the
//! pass selects K = 4 payloads per pixel, the engine computes its resampling weights (on
//! the CPU here; a shader in a real engine) and the pass resamples. The selections are
//! compared with the plain-Rust statement of the kernels, bit for bit.
//!
//! Run: `cargo run -p strata-embed --example ash_embed`. Exits non-zero if a check fails.

use ash::vk;
use strata_embed::contract::{Candidate, ResampleInput, ResampleOutput, SelectedCandidates};
use strata_embed::{AshBufferSlice, AshBuffers, AshDevice, AshResampleBuffers, AshSelection, SelectionSettings};
use strata_kernels::blue_noise::BlueNoiseTables;
use strata_kernels::reference::block_histogram::block_histogram;
use strata_kernels::reference::stratified_selection::{resample, select};

const WIDTH: u32 = 80;
const HEIGHT: u32 = 48;

type Error = Box<dyn std::error::Error>;

/// The engine's Vulkan objects.
struct Engine {
    _entry: ash::Entry,
    instance: ash::Instance,
    physical_device: vk::PhysicalDevice,
    device: ash::Device,
    queue: vk::Queue,
    command_pool: vk::CommandPool,
    memory: vk::PhysicalDeviceMemoryProperties,
}

/// A host-visible engine buffer, mapped.
struct HostBuffer {
    buffer: vk::Buffer,
    memory: vk::DeviceMemory,
    size: u64,
    mapped: *mut u8,
}

impl HostBuffer {
    fn slice(&self) -> AshBufferSlice {
        AshBufferSlice { buffer: self.buffer, offset: 0, size: self.size }
    }

    fn write<T: bytemuck::Pod>(&self, data: &[T]) {
        let bytes: &[u8] = bytemuck::cast_slice(data);
        assert!(bytes.len() as u64 <= self.size);
        // SAFETY: the mapping is host-coherent and at least `size` bytes long.
        unsafe { std::ptr::copy_nonoverlapping(bytes.as_ptr(), self.mapped, bytes.len()) };
    }

    fn read<T: bytemuck::Pod>(&self) -> Vec<T> {
        // SAFETY: as for `write`; the GPU work that wrote it has completed.
        let bytes = unsafe { std::slice::from_raw_parts(self.mapped, self.size as usize) };
        bytemuck::cast_slice(bytes).to_vec()
    }
}

impl Engine {
    fn new() -> Result<Self, Error> {
        // SAFETY: loads the system's Vulkan loader.
        let entry = unsafe { ash::Entry::load()? };
        let app = vk::ApplicationInfo::default().application_name(c"ash_embed").api_version(vk::API_VERSION_1_2);
        // SAFETY: valid create info.
        let instance =
            unsafe { entry.create_instance(&vk::InstanceCreateInfo::default().application_info(&app), None)? };
        // SAFETY: valid instance.
        let physical_devices = unsafe { instance.enumerate_physical_devices()? };
        let (physical_device, family) = physical_devices
            .iter()
            .find_map(|&pd| {
                // SAFETY: valid physical device.
                let families = unsafe { instance.get_physical_device_queue_family_properties(pd) };
                families
                    .iter()
                    .position(|f| f.queue_flags.contains(vk::QueueFlags::COMPUTE))
                    .map(|family| (pd, family as u32))
            })
            .ok_or("no Vulkan device with a compute queue")?;
        let priorities = [1.0];
        let queues = [vk::DeviceQueueCreateInfo::default().queue_family_index(family).queue_priorities(&priorities)];
        // SAFETY: valid physical device and create info.
        let device = unsafe {
            instance.create_device(
                physical_device,
                &vk::DeviceCreateInfo::default().queue_create_infos(&queues),
                None,
            )?
        };
        // SAFETY: valid device; the family was requested.
        let queue = unsafe { device.get_device_queue(family, 0) };
        let pool_info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(family)
            .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
        // SAFETY: valid device.
        let command_pool = unsafe { device.create_command_pool(&pool_info, None)? };
        // SAFETY: valid handles.
        let memory = unsafe { instance.get_physical_device_memory_properties(physical_device) };
        // SAFETY: valid handles.
        let name = unsafe { instance.get_physical_device_properties(physical_device) };
        println!("device: {:?}", name.device_name_as_c_str().unwrap_or(c"?"));
        Ok(Self { _entry: entry, instance, physical_device, device, queue, command_pool, memory })
    }

    fn buffer(&self, size: u64) -> Result<HostBuffer, Error> {
        let info = vk::BufferCreateInfo::default()
            .size(size)
            .usage(vk::BufferUsageFlags::STORAGE_BUFFER)
            .sharing_mode(vk::SharingMode::EXCLUSIVE);
        // SAFETY: valid device; the buffer is destroyed in `destroy_buffer`.
        unsafe {
            let buffer = self.device.create_buffer(&info, None)?;
            let requirements = self.device.get_buffer_memory_requirements(buffer);
            let wanted = vk::MemoryPropertyFlags::HOST_VISIBLE | vk::MemoryPropertyFlags::HOST_COHERENT;
            let type_index = (0..self.memory.memory_type_count)
                .find(|&i| {
                    requirements.memory_type_bits & (1 << i) != 0
                        && self.memory.memory_types[i as usize].property_flags.contains(wanted)
                })
                .ok_or("no host-visible memory")?;
            let allocate =
                vk::MemoryAllocateInfo::default().allocation_size(requirements.size).memory_type_index(type_index);
            let memory = self.device.allocate_memory(&allocate, None)?;
            self.device.bind_buffer_memory(buffer, memory, 0)?;
            let mapped = self.device.map_memory(memory, 0, size, vk::MemoryMapFlags::empty())?.cast::<u8>();
            Ok(HostBuffer { buffer, memory, size, mapped })
        }
    }

    /// Records with `record` into a fresh command buffer, submits it and waits.
    fn submit(&self, record: impl FnOnce(vk::CommandBuffer) -> Result<(), Error>) -> Result<(), Error> {
        let info = vk::CommandBufferAllocateInfo::default()
            .command_pool(self.command_pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(1);
        // SAFETY: valid pool; the buffer is freed below after the queue is idle.
        unsafe {
            let command_buffer = self.device.allocate_command_buffers(&info)?[0];
            self.device.begin_command_buffer(command_buffer, &vk::CommandBufferBeginInfo::default())?;
            record(command_buffer)?;
            self.device.end_command_buffer(command_buffer)?;
            let buffers = [command_buffer];
            self.device.queue_submit(
                self.queue,
                &[vk::SubmitInfo::default().command_buffers(&buffers)],
                vk::Fence::null(),
            )?;
            self.device.queue_wait_idle(self.queue)?;
            self.device.free_command_buffers(self.command_pool, &buffers);
        }
        Ok(())
    }

    fn destroy_buffer(&self, buffer: HostBuffer) {
        // SAFETY: the queue is idle.
        unsafe {
            self.device.destroy_buffer(buffer.buffer, None);
            self.device.free_memory(buffer.memory, None);
        }
    }
}

impl Drop for Engine {
    fn drop(&mut self) {
        // SAFETY: every child object was destroyed; the queue is idle.
        unsafe {
            let _ = self.device.device_wait_idle();
            self.device.destroy_command_pool(self.command_pool, None);
            self.device.destroy_device(None);
            self.instance.destroy_instance(None);
        }
    }
}

fn main() {
    if let Err(error) = run() {
        eprintln!("ash_embed: {error}");
        std::process::exit(1);
    }
}

fn run() -> Result<(), Error> {
    let engine = Engine::new()?;
    let pixels = (WIDTH * HEIGHT) as usize;
    // The engine's candidates: three objects, luminance keys with ties and a few invalid
    // ones; payload = pixel index (no payload buffer).
    let candidates: Vec<Candidate> = (0..pixels as u32)
        .map(|p| {
            let (x, y) = (p % WIDTH, p / WIDTH);
            let key = if p % 97 == 0 { f32::NAN } else { ((x * 5 + y * 3) % 11) as f32 * 0.3 };
            Candidate { key, object_id: (x / 27 + y / 20) % 3 }
        })
        .collect();
    let candidate_buffer = engine.buffer(size_of_val(candidates.as_slice()) as u64)?;
    candidate_buffer.write(&candidates);
    let selections = engine.buffer((pixels * size_of::<SelectedCandidates>()) as u64)?;
    let inputs = engine.buffer((pixels * size_of::<ResampleInput>()) as u64)?;
    let outputs = engine.buffer((pixels * size_of::<ResampleOutput>()) as u64)?;

    let settings = SelectionSettings { block_shift: true, ..SelectionSettings::default() };
    let vulkan = AshDevice {
        instance: &engine.instance,
        physical_device: engine.physical_device,
        device: &engine.device,
        // This engine enabled core features only. One that enables
        // shaderZeroInitializeWorkgroupMemory says so here, and the pass's pipelines
        // leave zeroing workgroup memory to the driver (faster to build on some drivers).
        shader_zero_initialize_workgroup_memory: false,
    };
    // SAFETY: the engine's live instance (API 1.2), its physical device and a device made
    // from it, with core features only (so no zero-initialisation claimed); the engine
    // outlives the pass, destroyed below.
    let pass = unsafe { AshSelection::new(vulkan, settings, WIDTH, HEIGHT) }?;
    // SAFETY: four live storage buffers of the pass's device, each slice its whole
    // buffer, destroyed only after the pass and its bindings.
    let bindings = unsafe {
        pass.bind(&AshBuffers {
            candidates: candidate_buffer.slice(),
            payloads: None,
            selections: selections.slice(),
            resample: Some(AshResampleBuffers { inputs: inputs.slice(), outputs: outputs.slice() }),
        })
    }?;

    let tables = BlueNoiseTables::new();
    let result = (|| -> Result<(), Error> {
        for frame in 0..6 {
            // SAFETY: the command buffer is recording; the buffers live until the wait.
            engine.submit(|cb| Ok(unsafe { pass.record_selection(cb, &bindings, frame) }?))?;
            let got: Vec<SelectedCandidates> = selections.read();
            // The same frame in plain Rust: the histogram on the frame's shifted grid, then
            // the selection.
            let params = pass.frame_params(frame, true)?;
            let h = params.histogram;
            let grid = strata_kernels::BlockGrid::new(WIDTH, HEIGHT, h.block_size)?.with_shift(h.shift_x, h.shift_y)?;
            let histogram = block_histogram(grid, &candidates);
            let want = select(&params.selection, &tables, &candidates, &[], &histogram.sorted_pixels, &histogram.spans);
            if let Some(p) = (0..pixels).find(|&p| bytemuck::bytes_of(&got[p]) != bytemuck::bytes_of(&want[p])) {
                return Err(format!("frame {frame} pixel {p}: {:?}, the reference says {:?}", got[p], want[p]).into());
            }
            // The engine's weights: target = the key (0 for invalid keys), W = 1, equal MIS.
            let target = |payload: u32| {
                let key = candidates[payload as usize].key;
                if key.is_finite() { key } else { 0.0 }
            };
            let weights: Vec<ResampleInput> = got
                .iter()
                .enumerate()
                .map(|(pixel, s)| {
                    let share = 1.0 / (s.selected + 1) as f32;
                    let mut input = ResampleInput { canonical_payload: pixel as u32, ..Default::default() };
                    input.canonical_target = target(pixel as u32);
                    input.canonical_weight = share * input.canonical_target;
                    for slot in 0..s.selected as usize {
                        input.targets[slot] = target(s.payloads[slot]);
                        input.weights[slot] = share * input.targets[slot];
                    }
                    input
                })
                .collect();
            inputs.write(&weights);
            // SAFETY: as above.
            engine.submit(|cb| Ok(unsafe { pass.record_resampling(cb, &bindings) }?))?;
            let resampled: Vec<ResampleOutput> = outputs.read();
            let want = resample(&got, &weights);
            let mismatches = (0..pixels).filter(|&p| resampled[p].payload != want[p].payload).count();
            if mismatches > 0 {
                return Err(format!("frame {frame}: {mismatches} resampled payloads differ from the reference").into());
            }
            let (sx, sy) = (h.shift_x, h.shift_y);
            println!(
                "frame {frame}: grid shift ({sx}, {sy}); {pixels} selections and resampled choices identical to the reference"
            );
        }
        Ok(())
    })();
    // SAFETY: every submission was waited for.
    unsafe {
        pass.destroy_bindings(bindings);
        pass.destroy();
    }
    for buffer in [candidate_buffer, selections, inputs, outputs] {
        engine.destroy_buffer(buffer);
    }
    result?;
    println!("ok");
    Ok(())
}
