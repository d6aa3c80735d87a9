//! The embedding API's ash flavour on a raw Vulkan device: the same selections and
//! resampling as the wgpu flavour for the same frames (block shifting on, engine
//! payloads), on a device with core features only and on one that zeroes workgroup
//! memory itself (`AshDevice::shader_zero_initialize_workgroup_memory`), and bind-time
//! errors naming the buffer.

use strata_embed::contract::{Candidate, ResampleInput, ResampleOutput, SelectedCandidates};
use strata_embed::{AshBufferSlice, AshBuffers, AshResampleBuffers, AshSelection, SelectionSettings};
use strata_tests::{AshEngine, EmbedInputs, engine_device, wgpu_embed_frames};

const WIDTH: u32 = 50;
const HEIGHT: u32 = 27;

fn inputs() -> (Vec<Candidate>, Vec<u32>, Vec<ResampleInput>) {
    let pixels = WIDTH * HEIGHT;
    let candidates = (0..pixels)
        .map(|p| Candidate { key: ((p * 7919) % 101) as f32 * 0.1, object_id: (p % WIDTH) / 17 + 3 * (p / WIDTH / 9) })
        .collect();
    let payloads = (0..pixels).map(|p| p ^ 0x55).collect();
    let resample = strata_tests::resample_inputs(pixels, 0.0);
    (candidates, payloads, resample)
}

fn settings() -> SelectionSettings {
    SelectionSettings { block_size: 8, candidates: 3, block_shift: true, ..Default::default() }
}

/// Frames 0-3 on the wgpu flavour.
fn wgpu_frames() -> Option<Frames> {
    let (device, queue) = engine_device("ash_flavour_matches_wgpu_flavour", None)?;
    let (candidates, payloads, resample) = inputs();
    let inputs = EmbedInputs {
        width: WIDTH,
        height: HEIGHT,
        candidates: &candidates,
        payloads: Some(&payloads),
        resample: &resample,
    };
    Some(wgpu_embed_frames(&device, &queue, settings(), 9, &inputs, 4))
}

type Frames = Vec<(Vec<SelectedCandidates>, Vec<ResampleOutput>)>;

#[test]
fn ash_flavour_matches_wgpu_flavour() {
    let test = "ash_flavour_matches_wgpu_flavour";
    let (Some(plain), Some(want)) = (AshEngine::open_plain(test), wgpu_frames()) else {
        return;
    };
    assert!(!plain.zero_initializes_workgroup_memory);
    matches_on(&plain, &want);
    drop(plain);
    let engine = AshEngine::open(test).unwrap();
    if engine.zero_initializes_workgroup_memory {
        matches_on(&engine, &want);
    } else {
        eprintln!("note: the device cannot zero workgroup memory itself; that path is not run");
    }
}

/// Frames 0-3 of the ash flavour on `engine` give `want`.
fn matches_on(engine: &AshEngine, want: &Frames) {
    let (candidates, payloads, resample) = inputs();
    let pixels = u64::from(WIDTH * HEIGHT);
    let sizes = [8 * pixels, 4 * pixels, 32 * pixels, 48 * pixels, 16 * pixels];
    let buffers = [
        engine.buffer(sizes[0], bytemuck::cast_slice(&candidates)),
        engine.buffer(sizes[1], bytemuck::cast_slice(&payloads)),
        engine.buffer(sizes[2], &[]),
        engine.buffer(sizes[3], bytemuck::cast_slice(&resample)),
        engine.buffer(sizes[4], &[]),
    ];
    let slice = |i: usize| AshBufferSlice { buffer: buffers[i].0, offset: 0, size: sizes[i] };
    let vulkan = engine.embed_device();
    // SAFETY: live handles of the engine, which outlives the pass (destroyed below).
    let pass = unsafe { AshSelection::new(vulkan, settings(), WIDTH, HEIGHT) }.unwrap();
    pass.set_seed(9);
    let good = AshBuffers {
        candidates: slice(0),
        payloads: Some(slice(1)),
        selections: slice(2),
        resample: Some(AshResampleBuffers { inputs: slice(3), outputs: slice(4) }),
    };
    // Bind-time errors name the buffer.
    let mut bad = good;
    bad.selections.size -= 1;
    // SAFETY: live storage buffers of the device holding the ranges given, alive until
    // after the last submission; the refused slices never reach the driver.
    let error = unsafe { pass.bind(&bad) }.unwrap_err().to_string();
    assert!(error.contains("`selections`") && error.contains("50x27"), "{error}");
    let mut bad = good;
    bad.candidates.offset = 3;
    // SAFETY: as above.
    let error = unsafe { pass.bind(&bad) }.unwrap_err().to_string();
    assert!(error.contains("`candidates`") && error.contains("offset 3"), "{error}");
    // SAFETY: as for the pass above.
    let error = unsafe { AshSelection::new(vulkan, SelectionSettings { block_size: 3, ..settings() }, WIDTH, HEIGHT) }
        .err()
        .expect("block size 3 refused")
        .to_string();
    assert!(error.contains("block_size = 3"), "{error}");

    // SAFETY: as above.
    let bindings = unsafe { pass.bind(&good) }.unwrap();
    for (frame, (want_selections, want_outputs)) in want.iter().enumerate() {
        // SAFETY: the command buffer is recording; buffers outlive the wait in submit.
        engine.submit(|cb| unsafe {
            pass.record_selection(cb, &bindings, frame as u32).unwrap();
            pass.record_resampling(cb, &bindings).unwrap();
        });
        let selections: Vec<SelectedCandidates> = engine.read(buffers[2].1, sizes[2]);
        let outputs: Vec<ResampleOutput> = engine.read(buffers[4].1, sizes[4]);
        assert_eq!(
            bytemuck::cast_slice::<_, u32>(&selections),
            bytemuck::cast_slice::<_, u32>(want_selections),
            "frame {frame}: selections"
        );
        assert_eq!(&outputs, want_outputs, "frame {frame}: resampling");
    }
    // SAFETY: every submission was waited for.
    unsafe {
        pass.destroy_bindings(bindings);
        pass.destroy();
    }
    for buffer in buffers {
        engine.free(buffer);
    }
}

/// The five roles as ranges of one engine buffer, back to back at aligned offsets, with
/// the pass on `engine`: what the bind-time range checks start from.
struct OneBuffer<'a> {
    engine: &'a AshEngine,
    buffer: (ash::vk::Buffer, ash::vk::DeviceMemory),
    /// Each role's range: candidates, payloads, selections, resample inputs, resampled.
    ranges: [(u64, u64); 5],
    pass: Option<AshSelection>,
    /// The device's minStorageBufferOffsetAlignment and maxStorageBufferRange.
    alignment: u64,
    max_range: u64,
}

impl<'a> OneBuffer<'a> {
    fn new(engine: &'a AshEngine) -> Self {
        // SAFETY: valid handles of the engine.
        let limits = unsafe { engine.instance.get_physical_device_properties(engine.physical_device) }.limits;
        let alignment = limits.min_storage_buffer_offset_alignment.max(1);
        let pixels = u64::from(WIDTH * HEIGHT);
        let mut ranges = [(0, 8 * pixels), (0, 4 * pixels), (0, 32 * pixels), (0, 48 * pixels), (0, 16 * pixels)];
        for i in 1..ranges.len() {
            ranges[i].0 = (ranges[i - 1].0 + ranges[i - 1].1).next_multiple_of(alignment);
        }
        let (last_offset, last_size) = ranges[4];
        let buffer = engine.buffer(last_offset + last_size, &[]);
        // SAFETY: live handles of the engine, which outlives the pass (destroyed on drop).
        let pass = unsafe { AshSelection::new(engine.embed_device(), settings(), WIDTH, HEIGHT) }.unwrap();
        let max_range = u64::from(limits.max_storage_buffer_range);
        Self { engine, buffer, ranges, pass: Some(pass), alignment, max_range }
    }

    /// The five ranges as the pass binds them.
    fn buffers(&self) -> AshBuffers {
        let at = |i: usize| AshBufferSlice { buffer: self.buffer.0, offset: self.ranges[i].0, size: self.ranges[i].1 };
        AshBuffers {
            candidates: at(0),
            payloads: Some(at(1)),
            selections: at(2),
            resample: Some(AshResampleBuffers { inputs: at(3), outputs: at(4) }),
        }
    }

    /// Binds `buffers`: the bindings are destroyed again; the outcome is kept.
    fn bind(&self, buffers: &AshBuffers) -> Result<(), String> {
        let pass = self.pass.as_ref().unwrap();
        // SAFETY: every slice that the checks under test let through lies inside
        // `self.buffer`, a live storage buffer of the pass's device (bind's contract; a
        // slice the checks refuse never reaches the driver). Nothing is recorded.
        let bindings = unsafe { pass.bind(buffers) }.map_err(|error| error.to_string())?;
        // SAFETY: never used.
        unsafe { pass.destroy_bindings(bindings) };
        Ok(())
    }

    /// The message of `buffers`' refusal; fails the test if they were bound.
    fn refusal(&self, buffers: &AshBuffers, case: &str) -> String {
        let message = self.bind(buffers).err().unwrap_or_else(|| panic!("{case}: bound, not refused"));
        assert!(!message.contains('\n'), "{case}: one line: {message}");
        message
    }
}

impl Drop for OneBuffer<'_> {
    fn drop(&mut self) {
        // SAFETY: nothing was recorded with the pass.
        unsafe { self.pass.take().unwrap().destroy() };
        self.engine.free(self.buffer);
    }
}

#[test]
fn bind_refuses_a_range_larger_than_max_storage_buffer_range() {
    let Some(engine) = AshEngine::open("bind_refuses_a_range_larger_than_max_storage_buffer_range") else { return };
    let one = OneBuffer::new(&engine);
    one.bind(&one.buffers()).expect("disjoint ranges of one buffer are bound");
    let max = one.max_range;
    let mut large = one.buffers();
    large.selections.size = max + 1;
    let message = one.refusal(&large, "maxStorageBufferRange + 1 bytes");
    for part in ["`selections`", "maxStorageBufferRange", &(max + 1).to_string(), &max.to_string()] {
        assert!(message.contains(part), "{part}: {message}");
    }
    // VK_WHOLE_SIZE as a size is not "the rest of the buffer" here: refused too.
    let mut whole = one.buffers();
    whole.candidates.size = ash::vk::WHOLE_SIZE;
    let message = one.refusal(&whole, "VK_WHOLE_SIZE");
    assert!(message.contains("`candidates`") && message.contains(&u64::MAX.to_string()), "{message}");
}

#[test]
fn bind_refuses_a_range_that_ends_past_the_last_byte_address() {
    let Some(engine) = AshEngine::open("bind_refuses_a_range_that_ends_past_the_last_byte_address") else { return };
    let one = OneBuffer::new(&engine);
    let mut wrapping = one.buffers();
    let resampled = wrapping.resample.as_mut().unwrap();
    // The last aligned offset: offset + size wraps around 2^64.
    resampled.outputs.offset = u64::MAX / one.alignment * one.alignment;
    let (offset, size) = (resampled.outputs.offset, resampled.outputs.size);
    let message = one.refusal(&wrapping, "offset + size past 2^64 - 1");
    for part in ["`resampled`", &offset.to_string(), &size.to_string()] {
        assert!(message.contains(part), "{part}: {message}");
    }
}

#[test]
fn bind_refuses_overlapping_ranges_of_one_buffer() {
    let Some(engine) = AshEngine::open("bind_refuses_overlapping_ranges_of_one_buffer") else { return };
    let one = OneBuffer::new(&engine);
    let [_, payloads, selections, inputs, _] = one.ranges;
    // The selections (written by the pass) one byte into the resampling inputs.
    let mut by_one = one.buffers();
    by_one.selections.size = inputs.0 - selections.0 + 1;
    let message = one.refusal(&by_one, "one byte of overlap");
    let (end, inputs_start) = (inputs.0 + 1, inputs.0);
    for part in ["`selections`", "`resample_inputs`", &end.to_string(), &inputs_start.to_string()] {
        assert!(message.contains(part), "{part}: {message}");
    }
    // Ranges that touch without overlapping are bound.
    let mut touching = one.buffers();
    touching.selections.size = inputs.0 - selections.0;
    one.bind(&touching).expect("ranges that touch are bound");
    // The selections over the payloads (the pass would write what it reads).
    let mut over = one.buffers();
    over.selections.offset = payloads.0;
    let message = one.refusal(&over, "selections over payloads");
    assert!(message.contains("`selections`") && message.contains("`payloads`"), "{message}");
    // Two roles the pass only reads, in the same bytes: refused as well (no engine
    // aliases them: a record of one type read as another is a mistake).
    let mut shared = one.buffers();
    shared.payloads.as_mut().unwrap().offset = 0;
    let message = one.refusal(&shared, "payloads over candidates");
    assert!(message.contains("`candidates`") && message.contains("`payloads`"), "{message}");
}
