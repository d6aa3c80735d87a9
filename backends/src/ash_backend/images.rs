//! The ash backend's textures and samplers: one `VkImage` per texture (sampled, storage
//! and transfer usage, optimal tiling), in `GENERAL` layout between operations so that a
//! dispatch binds it as sampled or storage image without a transition (a copy moves it
//! to the transfer layout and back); two views
//! (every mip level for sampling, level 0 for storage); uploads and read-backs through a
//! host-visible staging buffer, each submitted and waited for on its own.

use super::device::VulkanDevice;
use super::vk_error;
use crate::error::BackendError;
use crate::texture::{AddressMode, FilterMode, SamplerDesc, TextureDesc};
use ash::vk;
use strata_kernels::{TexelFormat, TextureDimension};

/// A texture's Vulkan objects.
pub(super) struct AshImage {
    pub(super) image: vk::Image,
    pub(super) memory: vk::DeviceMemory,
    /// Every mip level (what a sampled binding sees).
    pub(super) sampled_view: vk::ImageView,
    /// Mip level 0 alone (what a storage binding sees).
    pub(super) storage_view: vk::ImageView,
    pub(super) desc: TextureDesc,
}

/// Vulkan's format of a strata texel format.
pub(super) fn vk_format(format: TexelFormat) -> vk::Format {
    match format {
        TexelFormat::Rgba8Unorm => vk::Format::R8G8B8A8_UNORM,
        TexelFormat::Rgba8Uint => vk::Format::R8G8B8A8_UINT,
        TexelFormat::Rgba16Float => vk::Format::R16G16B16A16_SFLOAT,
        TexelFormat::Rgba32Float => vk::Format::R32G32B32A32_SFLOAT,
        TexelFormat::R32Float => vk::Format::R32_SFLOAT,
        TexelFormat::R32Uint => vk::Format::R32_UINT,
        TexelFormat::R32Sint => vk::Format::R32_SINT,
    }
}

fn layers(desc: &TextureDesc) -> u32 {
    if desc.dimension == TextureDimension::D2Array { desc.size[2] } else { 1 }
}

/// The extent of mip `level` as Vulkan counts it (an array's layers apart).
fn level_extent(desc: &TextureDesc, level: u32) -> vk::Extent3D {
    let [w, h, d] = desc.level_size(level);
    let depth = if desc.dimension == TextureDimension::D3 { d } else { 1 };
    vk::Extent3D { width: w, height: h, depth }
}

fn subresources(desc: &TextureDesc, levels: std::ops::Range<u32>) -> vk::ImageSubresourceRange {
    vk::ImageSubresourceRange {
        aspect_mask: vk::ImageAspectFlags::COLOR,
        base_mip_level: levels.start,
        level_count: levels.end - levels.start,
        base_array_layer: 0,
        layer_count: layers(desc),
    }
}

impl VulkanDevice {
    /// Creates `desc`'s image in `GENERAL` layout, zero-filled, with its two views.
    pub(super) fn create_image(&self, desc: &TextureDesc) -> Result<AshImage, BackendError> {
        let operation = format!("creating texture `{}`", desc.label);
        let error = |e| vk_error(&operation, e);
        let image_type = match desc.dimension {
            TextureDimension::D1 => vk::ImageType::TYPE_1D,
            TextureDimension::D2 | TextureDimension::D2Array => vk::ImageType::TYPE_2D,
            TextureDimension::D3 => vk::ImageType::TYPE_3D,
        };
        let view_type = match desc.dimension {
            TextureDimension::D1 => vk::ImageViewType::TYPE_1D,
            TextureDimension::D2 => vk::ImageViewType::TYPE_2D,
            TextureDimension::D2Array => vk::ImageViewType::TYPE_2D_ARRAY,
            TextureDimension::D3 => vk::ImageViewType::TYPE_3D,
        };
        // SAFETY: valid device and create infos; every object made is destroyed on the
        // error paths (through `destroy_image`, which skips null handles).
        unsafe {
            let image = self
                .device
                .create_image(
                    &vk::ImageCreateInfo::default()
                        .image_type(image_type)
                        .format(vk_format(desc.format))
                        .extent(level_extent(desc, 0))
                        .mip_levels(desc.mip_levels)
                        .array_layers(layers(desc))
                        .samples(vk::SampleCountFlags::TYPE_1)
                        .tiling(vk::ImageTiling::OPTIMAL)
                        .usage(
                            vk::ImageUsageFlags::SAMPLED
                                | vk::ImageUsageFlags::STORAGE
                                | vk::ImageUsageFlags::TRANSFER_SRC
                                | vk::ImageUsageFlags::TRANSFER_DST,
                        )
                        .sharing_mode(vk::SharingMode::EXCLUSIVE)
                        .initial_layout(vk::ImageLayout::UNDEFINED),
                    None,
                )
                .map_err(error)?;
            let mut made = AshImage {
                image,
                memory: vk::DeviceMemory::null(),
                sampled_view: vk::ImageView::null(),
                storage_view: vk::ImageView::null(),
                desc: desc.clone(),
            };
            let requirements = self.device.get_image_memory_requirements(image);
            let result = (|| {
                made.memory = self.allocate(requirements).map_err(error)?;
                self.device.bind_image_memory(image, made.memory, 0).map_err(error)?;
                let view = |levels: u32| {
                    self.device.create_image_view(
                        &vk::ImageViewCreateInfo::default()
                            .image(image)
                            .view_type(view_type)
                            .format(vk_format(desc.format))
                            .subresource_range(subresources(desc, 0..levels)),
                        None,
                    )
                };
                made.sampled_view = view(desc.mip_levels).map_err(error)?;
                made.storage_view = view(1).map_err(error)?;
                let range = subresources(desc, 0..desc.mip_levels);
                self.submit_once(&operation, |cb| {
                    let to_general = vk::ImageMemoryBarrier::default()
                        .src_access_mask(vk::AccessFlags::empty())
                        .dst_access_mask(vk::AccessFlags::TRANSFER_WRITE)
                        .old_layout(vk::ImageLayout::UNDEFINED)
                        .new_layout(vk::ImageLayout::GENERAL)
                        .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                        .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                        .image(image)
                        .subresource_range(range);
                    self.device.cmd_pipeline_barrier(
                        cb,
                        vk::PipelineStageFlags::TOP_OF_PIPE,
                        vk::PipelineStageFlags::TRANSFER,
                        vk::DependencyFlags::empty(),
                        &[],
                        &[],
                        &[to_general],
                    );
                    self.device.cmd_clear_color_image(
                        cb,
                        image,
                        vk::ImageLayout::GENERAL,
                        &vk::ClearColorValue { uint32: [0; 4] },
                        &[range],
                    );
                    self.transfer_done(cb);
                })
            })();
            match result {
                Ok(()) => Ok(made),
                Err(e) => {
                    self.destroy_image(&made);
                    Err(e)
                }
            }
        }
    }

    /// Frees a texture's objects (null handles skipped).
    pub(super) fn destroy_image(&self, image: &AshImage) {
        // SAFETY: no dispatch is in flight between calls; the objects are not used again.
        unsafe {
            self.device.destroy_image_view(image.sampled_view, None);
            self.device.destroy_image_view(image.storage_view, None);
            self.device.destroy_image(image.image, None);
            self.device.free_memory(image.memory, None);
        }
    }

    /// Replaces mip `level` of `image` with `data` (checked to be the whole level).
    pub(super) fn write_image(&self, image: &AshImage, level: u32, data: &[u8]) -> Result<(), BackendError> {
        let operation = format!("writing texture `{}`", image.desc.label);
        let (buffer, memory, mapped) = self.create_buffer("texture upload", data.len().max(4) as u64)?;
        // SAFETY: the mapping holds at least `data.len()` bytes.
        unsafe { std::ptr::copy_nonoverlapping(data.as_ptr(), mapped, data.len()) };
        let region = copy_region(&image.desc, level);
        let result = self.submit_once(&operation, |cb| {
            let copy = vk::ImageLayout::TRANSFER_DST_OPTIMAL;
            self.relayout(cb, image, vk::ImageLayout::GENERAL, copy);
            // SAFETY: recording into the one-shot command buffer.
            unsafe {
                self.device.cmd_copy_buffer_to_image(cb, buffer, image.image, copy, &[region]);
            }
            self.relayout(cb, image, copy, vk::ImageLayout::GENERAL);
            self.transfer_done(cb);
        });
        self.destroy_buffer(buffer, memory);
        result
    }

    /// Mip `level` of `image`, tightly packed.
    pub(super) fn read_image(&self, image: &AshImage, level: u32) -> Result<Vec<u8>, BackendError> {
        let operation = format!("reading texture `{}`", image.desc.label);
        let size = image.desc.level_bytes(level) as usize;
        let (buffer, memory, mapped) = self.create_buffer("texture read-back", size.max(4) as u64)?;
        let region = copy_region(&image.desc, level);
        let result = self.submit_once(&operation, |cb| {
            let copy = vk::ImageLayout::TRANSFER_SRC_OPTIMAL;
            self.relayout(cb, image, vk::ImageLayout::GENERAL, copy);
            // SAFETY: recording into the one-shot command buffer.
            unsafe {
                self.device.cmd_copy_image_to_buffer(cb, image.image, copy, buffer, &[region]);
            }
            self.relayout(cb, image, copy, vk::ImageLayout::GENERAL);
            self.transfer_done(cb);
        });
        let mut bytes = vec![0u8; size];
        if result.is_ok() {
            // SAFETY: the mapping holds `size` bytes, written by the finished copy.
            unsafe { std::ptr::copy_nonoverlapping(mapped, bytes.as_mut_ptr(), size) };
        }
        self.destroy_buffer(buffer, memory);
        result.map(|()| bytes)
    }

    /// A sampler of `desc`.
    pub(super) fn create_sampler(&self, desc: &SamplerDesc) -> Result<vk::Sampler, BackendError> {
        let address = |mode: AddressMode| match mode {
            AddressMode::ClampToEdge => vk::SamplerAddressMode::CLAMP_TO_EDGE,
            AddressMode::Repeat => vk::SamplerAddressMode::REPEAT,
            AddressMode::MirrorRepeat => vk::SamplerAddressMode::MIRRORED_REPEAT,
        };
        let filter = |mode: FilterMode| match mode {
            FilterMode::Nearest => vk::Filter::NEAREST,
            FilterMode::Linear => vk::Filter::LINEAR,
        };
        let info = vk::SamplerCreateInfo::default()
            .mag_filter(filter(desc.mag_filter))
            .min_filter(filter(desc.min_filter))
            .mipmap_mode(match desc.mipmap_filter {
                FilterMode::Nearest => vk::SamplerMipmapMode::NEAREST,
                FilterMode::Linear => vk::SamplerMipmapMode::LINEAR,
            })
            .address_mode_u(address(desc.address[0]))
            .address_mode_v(address(desc.address[1]))
            .address_mode_w(address(desc.address[2]))
            .min_lod(0.0)
            .max_lod(vk::LOD_CLAMP_NONE);
        // SAFETY: valid device and create info.
        unsafe { self.device.create_sampler(&info, None) }.map_err(|e| vk_error("creating a sampler", e))
    }

    /// Frees a sampler.
    pub(super) fn destroy_sampler(&self, sampler: vk::Sampler) {
        // SAFETY: no dispatch is in flight between calls.
        unsafe { self.device.destroy_sampler(sampler, None) };
    }

    /// Moves every subresource of `image` from layout `from` to `to`, after every earlier
    /// shader and transfer access and before every later one (copies use the transfer
    /// layouts; dispatches see `GENERAL`).
    fn relayout(&self, cb: vk::CommandBuffer, image: &AshImage, from: vk::ImageLayout, to: vk::ImageLayout) {
        let all = vk::AccessFlags::SHADER_READ
            | vk::AccessFlags::SHADER_WRITE
            | vk::AccessFlags::TRANSFER_READ
            | vk::AccessFlags::TRANSFER_WRITE;
        let barrier = vk::ImageMemoryBarrier::default()
            .src_access_mask(all)
            .dst_access_mask(all)
            .old_layout(from)
            .new_layout(to)
            .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .image(image.image)
            .subresource_range(subresources(&image.desc, 0..image.desc.mip_levels));
        let stages = vk::PipelineStageFlags::COMPUTE_SHADER | vk::PipelineStageFlags::TRANSFER;
        // SAFETY: recording into a command buffer being recorded.
        unsafe {
            self.device.cmd_pipeline_barrier(cb, stages, stages, vk::DependencyFlags::empty(), &[], &[], &[barrier]);
        }
    }

    /// Makes a transfer's writes visible to later transfers, shaders and the host.
    fn transfer_done(&self, cb: vk::CommandBuffer) {
        let barrier = vk::MemoryBarrier::default().src_access_mask(vk::AccessFlags::TRANSFER_WRITE).dst_access_mask(
            vk::AccessFlags::SHADER_READ
                | vk::AccessFlags::SHADER_WRITE
                | vk::AccessFlags::TRANSFER_READ
                | vk::AccessFlags::TRANSFER_WRITE
                | vk::AccessFlags::HOST_READ,
        );
        // SAFETY: recording into a command buffer being recorded.
        unsafe {
            self.device.cmd_pipeline_barrier(
                cb,
                vk::PipelineStageFlags::TRANSFER,
                vk::PipelineStageFlags::COMPUTE_SHADER
                    | vk::PipelineStageFlags::TRANSFER
                    | vk::PipelineStageFlags::HOST,
                vk::DependencyFlags::empty(),
                &[barrier],
                &[],
                &[],
            );
        }
    }
}

/// The copy of mip `level` between a tightly packed buffer and the image.
fn copy_region(desc: &TextureDesc, level: u32) -> vk::BufferImageCopy {
    vk::BufferImageCopy {
        buffer_offset: 0,
        buffer_row_length: 0,
        buffer_image_height: 0,
        image_subresource: vk::ImageSubresourceLayers {
            aspect_mask: vk::ImageAspectFlags::COLOR,
            mip_level: level,
            base_array_layer: 0,
            layer_count: layers(desc),
        },
        image_offset: vk::Offset3D::default(),
        image_extent: level_extent(desc, level),
    }
}
