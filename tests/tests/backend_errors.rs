//! Bad input to the backend and the histogram pass becomes a typed error naming the
//! problem, never a panic or a silent wrong result.

use strata_backends::wgpu_backend::{WgpuApi, WgpuOptions};
use strata_backends::{Backend, BackendError, Bind};
use strata_kernels::types::{Candidate, HistogramParams};
use strata_kernels::{BlockGrid, Executor, GridError, KernelId, Registry};
use strata_render::histogram_pass::{BlockHistogramPass, HistogramVariant, PassError};
use strata_tests::{open_or_skip, vulkan_backend};

#[test]
fn bad_grids_are_refused_before_any_gpu_work() {
    assert!(matches!(BlockGrid::new(0, 10, 16), Err(GridError::EmptyImage { .. })));
    assert!(matches!(BlockGrid::new(10, 10, 6), Err(GridError::BlockSize(6))));
    assert!(matches!(BlockGrid::new(10, 10, 2), Err(GridError::BlockSize(2))));
    assert!(matches!(BlockGrid::new(10, 10, 64), Err(GridError::BlockSize(64))));
}

#[test]
fn wrong_candidate_count_is_named() {
    let Some(mut backend) = vulkan_backend("wrong_candidate_count_is_named") else {
        return;
    };
    let grid = BlockGrid::new(17, 5, 4).unwrap();
    let pass = BlockHistogramPass::new(&mut backend, HistogramVariant::Portable, grid).unwrap();
    let error = pass.run(&mut backend, &[Candidate::default(); 84]).unwrap_err();
    assert!(matches!(error, PassError::CandidateCount { expected: 85, got: 84, .. }), "{error}");
    assert!(error.to_string().contains("17x5 image needs 85 candidates, got 84"), "{error}");
}

#[test]
fn bindings_that_do_not_fit_the_kernel_are_named() {
    let Some(mut backend) = vulkan_backend("bindings_that_do_not_fit_the_kernel_are_named") else {
        return;
    };
    let kernel = Registry::shared().unwrap().get(KernelId::BlockHistogram);
    let buffers: Vec<_> = (0..5).map(|i| backend.create_buffer(&format!("b{i}"), 64).unwrap()).collect();
    let binds: Vec<_> = buffers.iter().enumerate().map(|(i, &b)| Bind::new(i as u32, b)).collect();

    let missing = backend.dispatch(kernel, &binds[..4], [1, 1, 1]).unwrap_err();
    assert!(matches!(missing, BackendError::Binding { binding: 4, .. }), "{missing}");
    assert!(missing.to_string().contains("`block_stats` is not bound"), "{missing}");

    let mut twice = binds.clone();
    twice.push(Bind::new(2, buffers[0]));
    let error = backend.dispatch(kernel, &twice, [1, 1, 1]).unwrap_err();
    assert!(error.to_string().contains("bound twice"), "{error}");

    // One buffer at a read-only and a writable binding: WebGPU forbids it.
    let mut aliased = binds.clone();
    aliased[2] = Bind::new(2, buffers[1]);
    let error = backend.dispatch(kernel, &aliased, [1, 1, 1]).unwrap_err();
    assert!(error.to_string().contains("also bound at binding 1, and one of them is writable"), "{error}");

    let mut extra = binds.clone();
    extra.push(Bind::new(9, buffers[0]));
    let error = backend.dispatch(kernel, &extra, [1, 1, 1]).unwrap_err();
    assert!(error.to_string().contains("binding 9: the kernel has no such binding"), "{error}");

    let small = backend.create_buffer("small params", 16).unwrap();
    let mut too_small = binds.clone();
    too_small[0] = Bind::new(0, small);
    let error = backend.dispatch(kernel, &too_small, [1, 1, 1]).unwrap_err();
    let params_bytes = std::mem::size_of::<HistogramParams>();
    assert!(error.to_string().contains(&format!("`params` needs at least {params_bytes} bytes")), "{error}");

    let limit = backend.info().limits.max_workgroups_per_dimension;
    let error = backend.dispatch(kernel, &binds, [limit + 1, 1, 1]).unwrap_err();
    assert!(matches!(error, BackendError::LimitExceeded { limit: "workgroups per dimension", .. }), "{error}");

    let error = backend.create_buffer("empty", 0).unwrap_err();
    assert!(error.to_string().contains("buffer `empty`: size 0"), "{error}");

    let huge = backend.info().limits.max_buffer_size + 4;
    let error = backend.create_buffer("huge", huge).unwrap_err();
    assert!(matches!(error, BackendError::LimitExceeded { limit: "buffer bytes", .. }), "{error}");

    let error = backend.write_buffer(buffers[0], 2, &[0; 4]).unwrap_err();
    assert!(error.to_string().contains("multiples of 4"), "{error}");

    backend.destroy_buffer(buffers[0]).unwrap();
    let error = backend.read_buffer(buffers[0]).unwrap_err();
    assert!(matches!(error, BackendError::UnknownBuffer(_)), "{error}");
}

#[test]
fn a_device_without_subgroups_refuses_the_subgroup_kernel() {
    let options = WgpuOptions { api: WgpuApi::Vulkan, validation: true, subgroups: false, ..Default::default() };
    let Some(mut backend) = open_or_skip("a_device_without_subgroups_refuses_the_subgroup_kernel", options) else {
        return;
    };
    let grid = BlockGrid::new(8, 8, 4).unwrap();
    let error = BlockHistogramPass::new(&mut backend, HistogramVariant::Subgroup, grid).err().unwrap();
    assert!(matches!(error, PassError::Backend(BackendError::MissingFeature { .. })), "{error}");
    assert!(error.to_string().contains("needs subgroup operations"), "{error}");
    // Auto takes the ranking kernel on a CPU driver (lavapipe) at every block size, and on a
    // GPU falls back from the subgroup network to the portable one.
    let cpu_driver = Executor::of_device(&backend.info().device_type, false) == Executor::CpuDriver;
    let want = if cpu_driver { KernelId::BlockHistogramRank } else { KernelId::BlockHistogram };
    let pass = BlockHistogramPass::new(&mut backend, HistogramVariant::Auto, grid).unwrap();
    assert_eq!(pass.kernel().id, want);
    let large = BlockGrid::new(40, 40, 32).unwrap();
    let pass = BlockHistogramPass::new(&mut backend, HistogramVariant::Auto, large).unwrap();
    assert_eq!(pass.kernel().id, want);
}

#[test]
fn timing_a_pass_returns_a_positive_duration() {
    let Some(mut backend) = vulkan_backend("timing_a_pass_returns_a_positive_duration") else {
        return;
    };
    if !backend.info().timestamps {
        eprintln!("the device has no timestamp queries");
        return;
    }
    let grid = BlockGrid::new(64, 64, 16).unwrap();
    let pass = BlockHistogramPass::new(&mut backend, HistogramVariant::Portable, grid).unwrap();
    pass.upload_candidates(&mut backend, &vec![Candidate { key: 1.0, object_id: 3 }; 4096]).unwrap();
    let time = pass.dispatch_timed(&mut backend).unwrap();
    assert!(time.as_nanos() > 0, "{time:?}");
}
