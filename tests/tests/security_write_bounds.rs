//! A write's range is checked without wrapping on every backend: an offset near
//! `u64::MAX` whose end wraps past zero is refused by the safe `Backend::write_buffer`
//! with an error naming it, and nothing is written. (The unchecked `offset + len` once
//! wrapped in release builds, and the ash backend copied the data to `mapping + offset`,
//! before its mapping.)

use strata_backends::ash_backend::{AshBackend, AshOptions, SpirvSource};
use strata_backends::cpu_backend::{CpuBackend, CpuOptions};
use strata_backends::{Backend, BackendError, gpu_required};
use strata_tests::vulkan_backend;

/// Checks `backend`'s writes into a 16-byte buffer: wrapped ranges refused, the buffer
/// untouched by them, in-range writes (up to the last word) still done.
fn wrapped_writes_are_refused(backend: &mut dyn Backend) {
    let buffer = backend.create_buffer("target", 16).unwrap();
    backend.write_buffer(buffer, 0, &[1; 16]).unwrap();
    for (offset, len) in [(u64::MAX - 3, 4), (u64::MAX - 7, 16), (u64::MAX - 15, 16), (1 << 63, 4)] {
        let error = backend.write_buffer(buffer, offset, &vec![0xee; len]).unwrap_err();
        assert!(matches!(error, BackendError::Buffer { .. }), "{error}");
        let message = error.to_string();
        assert!(message.contains(&format!("at offset {offset}")) && message.contains("`target`"), "{message}");
    }
    assert_eq!(backend.read_buffer(buffer).unwrap(), [1; 16], "a refused write wrote");
    // Past the end without wrapping: refused as before.
    assert!(backend.write_buffer(buffer, 16, &[0; 4]).is_err());
    // The last word and an empty write at the end still go through.
    backend.write_buffer(buffer, 12, &[2; 4]).unwrap();
    backend.write_buffer(buffer, 16, &[]).unwrap();
    let mut expected = [1u8; 16];
    expected[12..].fill(2);
    assert_eq!(backend.read_buffer(buffer).unwrap(), expected);
    backend.destroy_buffer(buffer).unwrap();
}

#[test]
fn cpu_refuses_a_write_whose_end_wraps() {
    wrapped_writes_are_refused(&mut CpuBackend::new(CpuOptions::default()).unwrap());
}

#[test]
fn ash_refuses_a_write_whose_end_wraps() {
    let options = AshOptions { source: SpirvSource::Naga, pipeline_cache: None, ..Default::default() };
    match AshBackend::new(options) {
        Ok(mut backend) => wrapped_writes_are_refused(&mut backend),
        Err(error @ BackendError::NoAdapter { .. }) if !gpu_required() => {
            eprintln!("SKIPPED ash_refuses_a_write_whose_end_wraps: {error}");
        }
        Err(error) => panic!("ash backend: {error}"),
    }
}

#[test]
fn wgpu_refuses_a_write_whose_end_wraps() {
    if let Some(mut backend) = vulkan_backend("wgpu_refuses_a_write_whose_end_wraps") {
        wrapped_writes_are_refused(&mut backend);
    }
}
