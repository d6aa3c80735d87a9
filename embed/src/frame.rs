//! Per-frame parameters shared by the wgpu and ash flavours: the shifted block grid and
//! the selection's uniform, and the dispatch sizes of the three kernels.

use crate::error::EmbedError;
use crate::settings::SelectionSettings;
use strata_kernels::embed_types::{SelectionParams, sampler_id};
use strata_kernels::types::{HISTOGRAM_SLOTS_PER_WORKGROUP, HistogramParams};
use strata_kernels::{BlockGrid, GridError};

/// Everything one frame's dispatches need.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrameParams {
    /// The histogram kernel's uniform (shifted grid when block shifting is on).
    pub histogram: HistogramParams,
    /// `strata_select`'s and `strata_resample`'s uniform.
    pub selection: SelectionParams,
    /// Workgroups of the histogram dispatch.
    pub histogram_workgroups: [u32; 3],
    /// Workgroups of the per-pixel dispatches (8 × 8 pixels each).
    pub pixel_workgroups: [u32; 3],
}

/// The image's grid, checked.
pub(crate) fn grid(settings: &SelectionSettings, width: u32, height: u32) -> Result<BlockGrid, EmbedError> {
    BlockGrid::new(width, height, settings.block_size).map_err(|error| match error {
        GridError::BlockSize(_) => EmbedError::Setting {
            field: "block_size",
            value: settings.block_size.to_string(),
            expected: "a power of two from 4 to 32 (4, 8, 16 or 32)",
        },
        other => EmbedError::ImageSize { width, height, why: other.to_string() },
    })
}

/// Block-grid shift of a frame: (0, 0) without block shifting, else a hash of the frame
/// and seed in 0..B per axis.
pub fn grid_shift(settings: &SelectionSettings, frame: u32) -> (u32, u32) {
    if !settings.block_shift {
        return (0, 0);
    }
    strata_kernels::block_grid::frame_shift(settings.block_size, frame, settings.seed)
}

/// Most blocks any frame's grid has (a shifted grid has up to one more row and column).
pub(crate) fn max_blocks(settings: &SelectionSettings, width: u32, height: u32) -> u64 {
    match grid(settings, width, height) {
        Ok(grid) if settings.block_shift => u64::from(grid.max_shifted_block_count()),
        Ok(grid) => u64::from(grid.block_count()),
        Err(_) => 0,
    }
}

/// The parameters of frame `frame`; `max_workgroups` is the device's per-dimension limit.
pub fn frame_params(
    settings: &SelectionSettings,
    width: u32,
    height: u32,
    frame: u32,
    identity_payload: bool,
    max_workgroups: u32,
) -> Result<FrameParams, EmbedError> {
    let (sx, sy) = grid_shift(settings, frame);
    let grid = grid(settings, width, height)?.with_shift(sx, sy).map_err(|e| EmbedError::ImageSize {
        width,
        height,
        why: e.to_string(),
    })?;
    let blocks_per_workgroup = HISTOGRAM_SLOTS_PER_WORKGROUP / (settings.block_size * settings.block_size);
    let total = grid.block_count().div_ceil(blocks_per_workgroup);
    let x = total.min(max_workgroups.max(1));
    let histogram_workgroups = [x, total.div_ceil(x), 1];
    let selection = SelectionParams {
        width,
        height,
        frame,
        seed: settings.seed,
        candidates: settings.candidates,
        sampler: sampler_id(settings.sampler),
        identity_payload: u32::from(identity_payload),
        _pad: 0,
    };
    Ok(FrameParams {
        histogram: grid.histogram_params(x, settings.masking),
        selection,
        histogram_workgroups,
        pixel_workgroups: [width.div_ceil(8), height.div_ceil(8), 1],
    })
}
