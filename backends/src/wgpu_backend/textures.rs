//! The wgpu backend's textures and samplers: one `wgpu::Texture` per [`TextureId`]
//! (sampled and storage usage at once), written with `Queue::write_texture`, read back
//! through a staging buffer whose rows are padded to wgpu's 256-byte copy alignment.

use super::buffers::map_read;
use super::errors::ErrorSink;
use crate::device_info::DeviceInfo;
use crate::error::BackendError;
use crate::texture::{AddressMode, FilterMode, SamplerDesc, SamplerId, TextureDesc, TextureId};
use std::collections::HashMap;
use strata_kernels::{StorageTextureAccess, TexelFormat, TexelKind, TextureDimension};

pub(super) struct TextureEntry {
    pub(super) texture: wgpu::Texture,
    pub(super) desc: TextureDesc,
}

#[derive(Default)]
pub(super) struct TextureTable {
    next: u64,
    textures: HashMap<u64, TextureEntry>,
    /// Each sampler with what it was created as (the bind check reads its filters).
    samplers: HashMap<u64, (wgpu::Sampler, SamplerDesc)>,
}

/// The wgpu format of a strata texel format.
pub(crate) fn wgpu_format(format: TexelFormat) -> wgpu::TextureFormat {
    match format {
        TexelFormat::Rgba8Unorm => wgpu::TextureFormat::Rgba8Unorm,
        TexelFormat::Rgba8Uint => wgpu::TextureFormat::Rgba8Uint,
        TexelFormat::Rgba16Float => wgpu::TextureFormat::Rgba16Float,
        TexelFormat::Rgba32Float => wgpu::TextureFormat::Rgba32Float,
        TexelFormat::R32Float => wgpu::TextureFormat::R32Float,
        TexelFormat::R32Uint => wgpu::TextureFormat::R32Uint,
        TexelFormat::R32Sint => wgpu::TextureFormat::R32Sint,
    }
}

/// The view dimension a kernel's binding of `dimension` needs.
pub(super) fn view_dimension(dimension: TextureDimension) -> wgpu::TextureViewDimension {
    match dimension {
        TextureDimension::D1 => wgpu::TextureViewDimension::D1,
        TextureDimension::D2 => wgpu::TextureViewDimension::D2,
        TextureDimension::D2Array => wgpu::TextureViewDimension::D2Array,
        TextureDimension::D3 => wgpu::TextureViewDimension::D3,
    }
}

/// The sample type of a sampled texture whose components read as `kind` (float
/// textures `filterable` where a sampler may filter them).
pub(super) fn sample_type(kind: TexelKind, filterable: bool) -> wgpu::TextureSampleType {
    match kind {
        TexelKind::Float => wgpu::TextureSampleType::Float { filterable },
        TexelKind::Sint => wgpu::TextureSampleType::Sint,
        TexelKind::Uint => wgpu::TextureSampleType::Uint,
    }
}

/// wgpu's storage access.
pub(super) fn storage_access(access: StorageTextureAccess) -> wgpu::StorageTextureAccess {
    match access {
        StorageTextureAccess::Read => wgpu::StorageTextureAccess::ReadOnly,
        StorageTextureAccess::Write => wgpu::StorageTextureAccess::WriteOnly,
        StorageTextureAccess::ReadWrite => wgpu::StorageTextureAccess::ReadWrite,
    }
}

fn extent(size: [u32; 3]) -> wgpu::Extent3d {
    wgpu::Extent3d { width: size[0], height: size[1], depth_or_array_layers: size[2] }
}

impl TextureTable {
    pub(super) fn create(
        &mut self,
        device: &wgpu::Device,
        errors: &ErrorSink,
        info: &DeviceInfo,
        desc: &TextureDesc,
    ) -> Result<TextureId, BackendError> {
        desc.check(info)?;
        let scope = errors.scope(device);
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some(&desc.label),
            size: extent(desc.size),
            mip_level_count: desc.mip_levels,
            sample_count: 1,
            dimension: match desc.dimension {
                TextureDimension::D1 => wgpu::TextureDimension::D1,
                TextureDimension::D2 | TextureDimension::D2Array => wgpu::TextureDimension::D2,
                TextureDimension::D3 => wgpu::TextureDimension::D3,
            },
            format: wgpu_format(desc.format),
            usage: wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::STORAGE_BINDING
                | wgpu::TextureUsages::COPY_SRC
                | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        scope.finish(&format!("creation of texture `{}`", desc.label))?;
        self.next += 1;
        self.textures.insert(self.next, TextureEntry { texture, desc: desc.clone() });
        Ok(TextureId(self.next))
    }

    pub(super) fn get(&self, id: TextureId) -> Result<&TextureEntry, BackendError> {
        self.textures.get(&id.0).ok_or(BackendError::UnknownTexture(id.0))
    }

    pub(super) fn destroy(&mut self, id: TextureId) -> Result<(), BackendError> {
        let entry = self.textures.remove(&id.0).ok_or(BackendError::UnknownTexture(id.0))?;
        entry.texture.destroy();
        Ok(())
    }

    pub(super) fn write(
        &self,
        queue: &wgpu::Queue,
        id: TextureId,
        level: u32,
        data: &[u8],
    ) -> Result<(), BackendError> {
        let entry = self.get(id)?;
        entry.desc.check_level(level, data.len())?;
        let [w, h, d] = entry.desc.level_size(level);
        queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &entry.texture,
                mip_level: level,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            data,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(w * entry.desc.format.bytes_per_texel()),
                rows_per_image: Some(h),
            },
            extent([w, h, d]),
        );
        Ok(())
    }

    pub(super) fn read(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        errors: &ErrorSink,
        id: TextureId,
        level: u32,
    ) -> Result<Vec<u8>, BackendError> {
        let entry = self.get(id)?;
        entry.desc.check_level(level, entry.desc.level_bytes(level) as usize)?;
        let [w, h, d] = entry.desc.level_size(level);
        let row = (w * entry.desc.format.bytes_per_texel()) as usize;
        let padded_row =
            row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT as usize) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT as usize;
        let size = (padded_row * h as usize * d as usize) as u64;
        let scope = errors.scope(device);
        let staging = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("strata texture read-back"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder =
            device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("texture read-back") });
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture: &entry.texture,
                mip_level: level,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &staging,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(padded_row as u32),
                    rows_per_image: Some(h),
                },
            },
            extent([w, h, d]),
        );
        queue.submit([encoder.finish()]);
        scope.finish(&format!("read-back of texture `{}`", entry.desc.label))?;
        let padded = map_read(device, errors, &staging, size)?;
        staging.destroy();
        Ok(padded.chunks_exact(padded_row).flat_map(|r| &r[..row]).copied().collect())
    }

    pub(super) fn create_sampler(&mut self, device: &wgpu::Device, desc: &SamplerDesc) -> SamplerId {
        let address = |mode: AddressMode| match mode {
            AddressMode::ClampToEdge => wgpu::AddressMode::ClampToEdge,
            AddressMode::Repeat => wgpu::AddressMode::Repeat,
            AddressMode::MirrorRepeat => wgpu::AddressMode::MirrorRepeat,
        };
        let filter = |mode: FilterMode| match mode {
            FilterMode::Nearest => wgpu::FilterMode::Nearest,
            FilterMode::Linear => wgpu::FilterMode::Linear,
        };
        let mipmap = match desc.mipmap_filter {
            FilterMode::Nearest => wgpu::MipmapFilterMode::Nearest,
            FilterMode::Linear => wgpu::MipmapFilterMode::Linear,
        };
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("strata sampler"),
            address_mode_u: address(desc.address[0]),
            address_mode_v: address(desc.address[1]),
            address_mode_w: address(desc.address[2]),
            mag_filter: filter(desc.mag_filter),
            min_filter: filter(desc.min_filter),
            mipmap_filter: mipmap,
            ..Default::default()
        });
        self.next += 1;
        self.samplers.insert(self.next, (sampler, *desc));
        SamplerId(self.next)
    }

    pub(super) fn sampler(&self, id: SamplerId) -> Result<&wgpu::Sampler, BackendError> {
        self.samplers.get(&id.0).map(|(sampler, _)| sampler).ok_or(BackendError::UnknownSampler(id.0))
    }

    /// What sampler `id` was created as.
    pub(super) fn sampler_desc(&self, id: SamplerId) -> Result<SamplerDesc, BackendError> {
        self.samplers.get(&id.0).map(|(_, desc)| *desc).ok_or(BackendError::UnknownSampler(id.0))
    }

    pub(super) fn destroy_sampler(&mut self, id: SamplerId) -> Result<(), BackendError> {
        self.samplers.remove(&id.0).map(|_| ()).ok_or(BackendError::UnknownSampler(id.0))
    }
}
