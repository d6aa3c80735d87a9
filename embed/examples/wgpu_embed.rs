//! A minimal engine on wgpu that owns its device and buffers and adopts the stratified
//! selection: it writes one candidate per pixel (luminance key + object id) and keeps
//! its reservoirs in its own buffer, in its own order (payload = reservoir index); the
//! pass selects K = 4 reservoirs per pixel from the pixel's object within its 16 × 16
//! block; the engine's own shader turns them into resampling weights; the pass resamples.
//!
//! Run: `cargo run -p strata-embed --example wgpu_embed`. Exits non-zero if a check fails.

use strata_embed::contract::{CANONICAL_SLOT, Candidate, ResampleInput, ResampleOutput, SelectedCandidates};
use strata_embed::{SelectionSettings, WgpuBuffers, WgpuResampleBuffers, WgpuSelection};
use wgpu::util::DeviceExt;

const WIDTH: u32 = 96;
const HEIGHT: u32 = 64;

/// The engine's resampling shader: reads the selected reservoirs, evaluates its target
/// function (here the reservoir's luminance, the same at every pixel, so equal MIS
/// weights 1 / (K + 1) are exact) and writes the weights.
const ENGINE_SHADER: &str = r#"
struct EngineReservoir { luminance: f32, weight: f32 }
@group(0) @binding(0) var<storage, read> reservoirs: array<EngineReservoir>;
@group(0) @binding(1) var<storage, read> selections: array<SelectedCandidates>;
@group(0) @binding(2) var<storage, read_write> inputs: array<ResampleInput>;
@group(0) @binding(3) var<storage, read> own_reservoir: array<u32>;

@compute @workgroup_size(64)
fn engine_weights(@builtin(global_invocation_id) id: vec3<u32>) {
    let pixel = id.x;
    if pixel >= arrayLength(&selections) { return; }
    let selection = selections[pixel];
    let share = 1.0 / f32(selection.selected + 1u);
    let canonical = reservoirs[own_reservoir[pixel]];
    var input = ResampleInput(vec4<f32>(0.0), vec4<f32>(0.0), 0.0, 0.0, own_reservoir[pixel], 0u);
    input.canonical_target = canonical.luminance;
    input.canonical_weight = share * canonical.luminance * canonical.weight;
    for (var slot = 0u; slot < selection.selected; slot++) {
        let r = reservoirs[selection.payloads[slot]];
        input.targets[slot] = r.luminance;
        input.weights[slot] = share * r.luminance * r.weight;
    }
    inputs[pixel] = input;
}
"#;

fn object_of(x: u32, y: u32) -> u32 {
    // Three objects: a disc over two half-planes.
    let (dx, dy) = (x as f32 - 48.0, y as f32 - 32.0);
    if dx * dx + dy * dy < 400.0 { 2 } else { u32::from(x + y > 80) }
}

fn main() {
    if let Err(error) = run() {
        eprintln!("wgpu_embed: {error}");
        std::process::exit(1);
    }
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    // The engine's device (any adapter; subgroups if it has them).
    let mut descriptor = wgpu::InstanceDescriptor::new_without_display_handle();
    descriptor.backends = wgpu::Backends::VULKAN;
    let instance = wgpu::Instance::new(descriptor);
    let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions::default()))?;
    let features = adapter.features() & wgpu::Features::SUBGROUP;
    let (device, queue) = pollster::block_on(
        adapter.request_device(&wgpu::DeviceDescriptor { required_features: features, ..Default::default() }),
    )?;
    println!("adapter: {} ({:?})", adapter.get_info().name, adapter.get_info().backend);

    // The engine's data: one candidate per pixel and its reservoirs, stored in reverse
    // pixel order to show that payloads are the engine's own indices.
    let pixels = (WIDTH * HEIGHT) as usize;
    let mut candidates = Vec::with_capacity(pixels);
    let mut reservoirs = vec![[0f32; 2]; pixels];
    let mut own_reservoir = Vec::with_capacity(pixels);
    for y in 0..HEIGHT {
        for x in 0..WIDTH {
            let pixel = (y * WIDTH + x) as usize;
            let luminance = 0.1 + ((x * 7 + y * 13) % 17) as f32 / 4.0;
            candidates.push(Candidate { key: luminance, object_id: object_of(x, y) });
            reservoirs[pixels - 1 - pixel] = [luminance, 1.0];
            own_reservoir.push((pixels - 1 - pixel) as u32);
        }
    }
    let storage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST;
    let init = |label: &str, contents: &[u8]| {
        device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: Some(label), contents, usage: storage })
    };
    let empty = |label: &str, bytes_per_pixel: usize| {
        device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: (bytes_per_pixel * pixels) as u64,
            usage: storage,
            mapped_at_creation: false,
        })
    };
    let candidate_buffer = init("candidates", bytemuck::cast_slice(&candidates));
    let payload_buffer = init("payloads", bytemuck::cast_slice(&own_reservoir));
    let reservoir_buffer = init("reservoirs", bytemuck::cast_slice(&reservoirs));
    let selections = empty("selections", size_of::<SelectedCandidates>());
    let resample_inputs = empty("resample inputs", size_of::<ResampleInput>());
    let resampled = empty("resampled", size_of::<ResampleOutput>());

    // The pass, with the paper's settings, bound to the engine's buffers.
    let pass = WgpuSelection::new(&device, SelectionSettings::default(), WIDTH, HEIGHT)?;
    let bindings = pass.bind(
        &device,
        &WgpuBuffers {
            candidates: (&candidate_buffer).into(),
            payloads: Some((&payload_buffer).into()),
            selections: (&selections).into(),
            resample: Some(WgpuResampleBuffers { inputs: (&resample_inputs).into(), outputs: (&resampled).into() }),
        },
    )?;

    // The engine's own shader, with the contract's WGSL declarations prepended.
    let source = strata_embed::wgsl::contract_source() + ENGINE_SHADER;
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("engine weights"),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    let engine_pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("engine weights"),
        layout: None,
        module: &module,
        entry_point: Some("engine_weights"),
        compilation_options: Default::default(),
        cache: None,
    });
    let engine_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("engine weights"),
        layout: &engine_pipeline.get_bind_group_layout(0),
        entries: &[
            wgpu::BindGroupEntry { binding: 0, resource: reservoir_buffer.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 1, resource: selections.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 2, resource: resample_inputs.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 3, resource: payload_buffer.as_entire_binding() },
        ],
    });

    let mean_luminance = candidates.iter().map(|c| f64::from(c.key)).sum::<f64>() / pixels as f64;
    let frames = 8;
    let mut canonical_chosen = 0usize;
    for frame in 0..frames {
        let mut encoder = device.create_command_encoder(&Default::default());
        pass.encode_selection(&queue, &mut encoder, &bindings, frame)?;
        {
            let mut compute = encoder.begin_compute_pass(&Default::default());
            compute.set_pipeline(&engine_pipeline);
            compute.set_bind_group(0, &engine_group, &[]);
            compute.dispatch_workgroups((pixels as u32).div_ceil(64), 1, 1);
        }
        pass.encode_resampling(&mut encoder, &bindings)?;
        queue.submit([encoder.finish()]);
        let chosen: Vec<SelectedCandidates> = read(&device, &queue, &selections)?;
        let outputs: Vec<ResampleOutput> = read(&device, &queue, &resampled)?;
        // Checks: every selected reservoir belongs to a pixel of the same object in the
        // same 16 x 16 block, and W = sum / target.
        for (pixel, (selection, output)) in chosen.iter().zip(&outputs).enumerate() {
            let (x, y) = (pixel as u32 % WIDTH, pixel as u32 / WIDTH);
            if selection.selected != 4 {
                return Err(format!("pixel {pixel}: {} candidates selected, want 4", selection.selected).into());
            }
            for &payload in &selection.payloads {
                let source = pixels - 1 - payload as usize;
                let (sx, sy) = (source as u32 % WIDTH, source as u32 / WIDTH);
                if (sx / 16, sy / 16) != (x / 16, y / 16) || object_of(sx, sy) != object_of(x, y) {
                    return Err(
                        format!("pixel ({x}, {y}) selected pixel ({sx}, {sy}) of another block or object").into()
                    );
                }
            }
            let target = reservoirs[output.payload as usize][0];
            if (output.weight * target - output.weight_sum).abs() > 1e-4 * output.weight_sum {
                return Err(format!(
                    "pixel {pixel}: W = {} but sum / target = {}",
                    output.weight,
                    output.weight_sum / target
                )
                .into());
            }
            canonical_chosen += usize::from(output.slot == CANONICAL_SLOT);
        }
        // The resampled estimate f(Y) W of each pixel, f = luminance: its image mean is an
        // unbiased estimate of the mean luminance.
        let estimate = outputs.iter().map(|o| f64::from(reservoirs[o.payload as usize][0] * o.weight)).sum::<f64>();
        println!(
            "frame {frame}: {pixels} pixels, 4 candidates each from their own object and block; mean of f(Y) W {:.4} (mean luminance {mean_luminance:.4})",
            estimate / pixels as f64
        );
    }
    let share = canonical_chosen as f64 / (pixels * frames as usize) as f64;
    println!(
        "the canonical sample was kept in {:.1} % of the pixels (about 1 / (K + 1) = 20 % expected)",
        100.0 * share
    );
    println!("ok");
    Ok(())
}

/// Copies a buffer back to the CPU.
fn read<T: bytemuck::Pod>(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    buffer: &wgpu::Buffer,
) -> Result<Vec<T>, Box<dyn std::error::Error>> {
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("read back"),
        size: buffer.size(),
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    encoder.copy_buffer_to_buffer(buffer, 0, &staging, 0, buffer.size());
    queue.submit([encoder.finish()]);
    let (sender, receiver) = std::sync::mpsc::channel();
    staging.slice(..).map_async(wgpu::MapMode::Read, move |result| {
        let _ = sender.send(result);
    });
    device.poll(wgpu::PollType::wait_indefinitely())?;
    receiver.recv()??;
    let data = bytemuck::cast_slice(&staging.slice(..).get_mapped_range()?).to_vec();
    Ok(data)
}
