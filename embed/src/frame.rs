//! Per-frame parameters shared by the wgpu and ash flavours: the shifted block grid and
//! the selection's uniform, and the dispatch sizes of the three kernels. They are the one
//! plan of the pass in `strata_kernels::pass_plan` (which strata's renderer and the
//! export package follow too), re-exported here; its errors convert into
//! [`crate::EmbedError`].

pub use strata_kernels::pass_plan::{
    FrameId, FrameParams, frame_params, grid, grid_shift, max_blocks, pixel_workgroups,
};

/// A Vulkan memory barrier of the frame's sequence (`vkCmdPipelineBarrier` with one
/// `VkMemoryBarrier`), as raw `VkPipelineStageFlags` and `VkAccessFlags` bits: the one
/// statement of the pass's synchronisation, which the ash flavour records and the export
/// package's `manifest.json` lists (`frame.sequence`), so that they cannot differ.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct VulkanBarrier {
    /// `srcStageMask`.
    pub src_stages: u32,
    /// `srcAccessMask` (of the `VkMemoryBarrier`).
    pub src_access: u32,
    /// `dstStageMask`.
    pub dst_stages: u32,
    /// `dstAccessMask`.
    pub dst_access: u32,
}

/// The `VkPipelineStageFlagBits` the barriers use, with their Vulkan names.
pub const VULKAN_STAGES: [(u32, &str); 3] = [
    (0x0000_0800, "VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT"),
    (0x0000_1000, "VK_PIPELINE_STAGE_TRANSFER_BIT"),
    (0x0001_0000, "VK_PIPELINE_STAGE_ALL_COMMANDS_BIT"),
];

/// The `VkAccessFlagBits` the barriers use, with their Vulkan names.
pub const VULKAN_ACCESS: [(u32, &str); 5] = [
    (0x0000_0008, "VK_ACCESS_UNIFORM_READ_BIT"),
    (0x0000_0020, "VK_ACCESS_SHADER_READ_BIT"),
    (0x0000_0040, "VK_ACCESS_SHADER_WRITE_BIT"),
    (0x0000_0800, "VK_ACCESS_TRANSFER_READ_BIT"),
    (0x0000_1000, "VK_ACCESS_TRANSFER_WRITE_BIT"),
];

const COMPUTE_SHADER: u32 = VULKAN_STAGES[0].0;
const TRANSFER: u32 = VULKAN_STAGES[1].0;
const ALL_COMMANDS: u32 = VULKAN_STAGES[2].0;
const UNIFORM_READ: u32 = VULKAN_ACCESS[0].0;
const SHADER_READ: u32 = VULKAN_ACCESS[1].0;
const SHADER_WRITE: u32 = VULKAN_ACCESS[2].0;
const TRANSFER_READ: u32 = VULKAN_ACCESS[3].0;
const TRANSFER_WRITE: u32 = VULKAN_ACCESS[4].0;
/// Every access a later command of the pass or of the engine may make.
const EVERY_READ_AND_WRITE: u32 = UNIFORM_READ | SHADER_READ | SHADER_WRITE | TRANSFER_READ | TRANSFER_WRITE;

impl VulkanBarrier {
    /// Before the pass's first command of a recording (a frame's uniform updates, the
    /// resampling's dispatch): every earlier shader or transfer write (the engine's
    /// candidates, payloads and weights) and every earlier read of the uniforms (the
    /// previous frame's dispatches: without it `vkCmdUpdateBuffer` is a write-after-read
    /// hazard) before the transfers and dispatches.
    pub const BEFORE_PASS: VulkanBarrier = VulkanBarrier {
        src_stages: ALL_COMMANDS,
        src_access: SHADER_WRITE | TRANSFER_WRITE,
        dst_stages: COMPUTE_SHADER | TRANSFER,
        dst_access: EVERY_READ_AND_WRITE,
    };
    /// After the uniform updates: the transfer writes before the dispatches' reads.
    pub const AFTER_UPDATES: VulkanBarrier = VulkanBarrier {
        src_stages: TRANSFER,
        src_access: TRANSFER_WRITE,
        dst_stages: COMPUTE_SHADER | TRANSFER,
        dst_access: EVERY_READ_AND_WRITE,
    };
    /// After each dispatch: its writes before the next dispatch's (or the engine's
    /// shader and transfer) reads and writes.
    pub const AFTER_DISPATCH: VulkanBarrier = VulkanBarrier {
        src_stages: COMPUTE_SHADER,
        src_access: SHADER_WRITE,
        dst_stages: COMPUTE_SHADER | TRANSFER,
        dst_access: EVERY_READ_AND_WRITE,
    };

    /// The Vulkan names of the bits of `flags` in `table` ([`VULKAN_STAGES`],
    /// [`VULKAN_ACCESS`]), in the table's order.
    pub fn names(flags: u32, table: &[(u32, &'static str)]) -> Vec<&'static str> {
        table.iter().filter(|(bit, _)| flags & bit != 0).map(|(_, name)| *name).collect()
    }
}
