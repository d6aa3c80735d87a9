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
    let resample = (0..pixels)
        .map(|p| ResampleInput {
            weights: [1.0, 0.5 * (p % 3) as f32, 2.0, 0.0],
            targets: [1.0, 2.0, 3.0, 4.0],
            canonical_weight: 0.25,
            canonical_target: 0.5,
            canonical_payload: p,
            _pad: 0,
        })
        .collect();
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
    let mut pass = AshSelection::new(vulkan, settings(), WIDTH, HEIGHT).unwrap();
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
    let error = pass.bind(&bad).unwrap_err().to_string();
    assert!(error.contains("`selections`") && error.contains("50x27"), "{error}");
    let mut bad = good;
    bad.candidates.offset = 3;
    let error = pass.bind(&bad).unwrap_err().to_string();
    assert!(error.contains("`candidates`") && error.contains("offset 3"), "{error}");
    let error = AshSelection::new(vulkan, SelectionSettings { block_size: 3, ..settings() }, WIDTH, HEIGHT)
        .err()
        .expect("block size 3 refused")
        .to_string();
    assert!(error.contains("block_size = 3"), "{error}");

    let bindings = pass.bind(&good).unwrap();
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
