//! The wgpu backend's buffers: one storage/uniform buffer per [`BufferId`], read back
//! through a staging buffer.

use super::errors::ErrorSink;
use crate::backend::BufferId;
use crate::bindings_check::check_buffer_size;
use crate::device_info::DeviceInfo;
use crate::error::BackendError;
use std::collections::HashMap;

pub(super) struct BufferEntry {
    pub(super) buffer: wgpu::Buffer,
    pub(super) size: u64,
    pub(super) label: String,
}

#[derive(Default)]
pub(super) struct BufferTable {
    next: u64,
    entries: HashMap<u64, BufferEntry>,
}

impl BufferTable {
    pub(super) fn create(
        &mut self,
        device: &wgpu::Device,
        errors: &ErrorSink,
        info: &DeviceInfo,
        label: &str,
        size: u64,
    ) -> Result<BufferId, BackendError> {
        check_buffer_size(label, size, info)?;
        let padded = size.div_ceil(4) * 4;
        let scope = errors.scope(device);
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: padded,
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::UNIFORM
                | wgpu::BufferUsages::COPY_SRC
                | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        scope.finish(&format!("creation of buffer `{label}` ({size} bytes)"))?;
        self.next += 1;
        self.entries.insert(self.next, BufferEntry { buffer, size, label: label.into() });
        Ok(BufferId(self.next))
    }

    pub(super) fn get(&self, id: BufferId) -> Result<&BufferEntry, BackendError> {
        self.entries.get(&id.0).ok_or(BackendError::UnknownBuffer(id.0))
    }

    pub(super) fn destroy(&mut self, id: BufferId) -> Result<(), BackendError> {
        let entry = self.entries.remove(&id.0).ok_or(BackendError::UnknownBuffer(id.0))?;
        entry.buffer.destroy();
        Ok(())
    }
}

/// Copies `entry` to a staging buffer and maps it.
pub(super) fn read_back(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    errors: &ErrorSink,
    entry: &BufferEntry,
) -> Result<Vec<u8>, BackendError> {
    let padded = entry.buffer.size();
    let scope = errors.scope(device);
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("strata read-back"),
        size: padded,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("read-back") });
    encoder.copy_buffer_to_buffer(&entry.buffer, 0, &staging, 0, padded);
    queue.submit([encoder.finish()]);
    scope.finish(&format!("read-back of `{}`", entry.label))?;
    let mut bytes = map_read(device, errors, &staging, padded)?;
    bytes.truncate(entry.size as usize);
    staging.destroy();
    Ok(bytes)
}

/// Maps `buffer` (MAP_READ) after all submitted work and copies out `size` bytes.
pub(super) fn map_read(
    device: &wgpu::Device,
    errors: &ErrorSink,
    buffer: &wgpu::Buffer,
    size: u64,
) -> Result<Vec<u8>, BackendError> {
    let (sender, receiver) = std::sync::mpsc::channel();
    let slice = buffer.slice(..size);
    slice.map_async(wgpu::MapMode::Read, move |result| {
        let _ = sender.send(result);
    });
    device.poll(wgpu::PollType::wait_indefinitely()).map_err(|e| errors.lost_or(e.to_string()))?;
    errors.check_lost()?;
    match receiver.recv() {
        Ok(Ok(())) => {}
        Ok(Err(e)) => return Err(errors.lost_or(format!("mapping for read-back failed: {e}"))),
        Err(_) => return Err(errors.lost_or("mapping callback never ran".into())),
    }
    let bytes = slice.get_mapped_range().map_err(|e| errors.lost_or(format!("mapped range: {e}")))?.to_vec();
    buffer.unmap();
    Ok(bytes)
}
