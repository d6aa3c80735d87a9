//! The ash backend with `VK_LAYER_KHRONOS_validation` on: the histogram kernel gives the
//! reference's output and the layer reports nothing; errors are typed, not panics.

use strata_backends::ash_backend::{AshBackend, AshOptions, SpirvSource};
use strata_backends::{Backend, BackendError, Bind, gpu_required};
use strata_kernels::reference::block_histogram::block_histogram;
use strata_kernels::{BlockGrid, KernelId, Registry};
use strata_render::histogram_pass::{BlockHistogramPass, HistogramVariant};
use strata_render::synthetic::{CandidateMix, candidate_image};

fn open(validation: bool, subgroups: bool) -> Option<AshBackend> {
    match AshBackend::new(AshOptions { validation, source: SpirvSource::Naga, subgroups, ..Default::default() }) {
        Ok(backend) => Some(backend),
        Err(error @ BackendError::NoAdapter { .. }) if !gpu_required() => {
            eprintln!("SKIPPED: {error} (set STRATA_REQUIRE_GPU=1 to make this a failure)");
            None
        }
        Err(error) => panic!("ash backend: {error}"),
    }
}

#[test]
fn validation_layer_reports_nothing_for_the_histogram_kernels() {
    let Some(mut backend) = open(true, true) else {
        return;
    };
    for variant in [HistogramVariant::Portable, HistogramVariant::Subgroup] {
        for (width, height, block_size) in [(17, 33, 4), (64, 48, 16), (70, 40, 32)] {
            let grid = BlockGrid::new(width, height, block_size).unwrap();
            let candidates = candidate_image(width, height, 9, CandidateMix { awkward: 0.2, ..Default::default() });
            let pass = BlockHistogramPass::new(&mut backend, variant, grid).unwrap();
            let output = pass.run(&mut backend, &candidates).unwrap();
            let time = pass.dispatch_timed(&mut backend).unwrap();
            assert!(time.as_nanos() > 0);
            pass.destroy(&mut backend).unwrap();
            assert_eq!(output, block_histogram(grid, &candidates), "{variant:?} {width}x{height} B={block_size}");
        }
    }
    let messages = backend.validation_messages();
    assert!(messages.is_empty(), "validation layer:\n{}", messages.join("\n"));
}

#[test]
fn ash_errors_are_typed() {
    let Some(mut backend) = open(false, false) else {
        return;
    };
    let registry = Registry::shared().unwrap();
    let error = backend.check_kernel(registry.get(KernelId::BlockHistogramSubgroup)).unwrap_err();
    assert!(matches!(error, BackendError::MissingFeature { .. }), "{error}");
    let kernel = registry.get(KernelId::BlockHistogram);
    let buffers: Vec<_> = (0..5).map(|i| backend.create_buffer(&format!("b{i}"), 64).unwrap()).collect();
    let binds: Vec<_> = buffers.iter().enumerate().map(|(i, &b)| Bind::new(i as u32, b)).collect();
    let error = backend.dispatch(kernel, &binds[1..], [1, 1, 1]).unwrap_err();
    assert!(error.to_string().contains("`params` is not bound"), "{error}");
    let limit = backend.info().limits.max_workgroups_per_dimension;
    let error = backend.dispatch(kernel, &binds, [1, limit + 1, 1]).unwrap_err();
    assert!(matches!(error, BackendError::LimitExceeded { .. }), "{error}");
    assert!(backend.create_buffer("empty", 0).is_err());
    let error = backend.write_buffer(buffers[1], 0, &[0u8; 68]).unwrap_err();
    assert!(error.to_string().contains("write of 68 bytes at offset 0 into 64 bytes"), "{error}");
    backend.destroy_buffer(buffers[1]).unwrap();
    assert!(matches!(backend.read_buffer(buffers[1]), Err(BackendError::UnknownBuffer(_))));
    // A dispatch of zero-filled buffers must still run: blocks of 4, a 1x1 image.
    let params = strata_kernels::BlockGrid::new(1, 1, 4).unwrap().histogram_params(1, true);
    backend.write_buffer(buffers[0], 0, bytemuck::bytes_of(&params)).unwrap();
    let fresh = backend.create_buffer("stats", 64).unwrap();
    let mut binds = binds.clone();
    binds[1] = Bind::new(1, fresh);
    backend.dispatch(kernel, &binds, [1, 1, 1]).unwrap();
}
