//! Per-frame parameters shared by the wgpu and ash flavours: the shifted block grid and
//! the selection's uniform, and the dispatch sizes of the three kernels.

use crate::error::EmbedError;
use strata_kernels::embed_types::SelectionParams;
use strata_kernels::selection::SelectionSettings;
use strata_kernels::types::HistogramParams;
use strata_kernels::{BlockGrid, KernelId, Registry};

/// Everything one frame's dispatches need.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrameParams {
    /// The histogram kernel's uniform (shifted grid when block shifting is on).
    pub histogram: HistogramParams,
    /// `strata_select`'s and `strata_resample`'s uniform.
    pub selection: SelectionParams,
    /// Workgroups of the histogram dispatch.
    pub histogram_workgroups: [u32; 3],
    /// Workgroups of the per-pixel dispatches (`strata_select`, `strata_resample`).
    pub pixel_workgroups: [u32; 3],
}

/// The image's grid, checked (the settings are validated first).
pub fn grid(settings: &SelectionSettings, width: u32, height: u32) -> Result<BlockGrid, EmbedError> {
    settings.validate()?;
    BlockGrid::new(width, height, settings.block_size).map_err(|error| EmbedError::ImageSize {
        width,
        height,
        why: error.to_string(),
    })
}

/// Block-grid shift of frame `frame` of the render `seed`: (0, 0) without block shifting,
/// else a hash of the frame and seed in 0..B per axis.
pub fn grid_shift(settings: &SelectionSettings, frame: u32, seed: u32) -> (u32, u32) {
    if !settings.block_shift {
        return (0, 0);
    }
    strata_kernels::block_grid::frame_shift(settings.block_size, frame, seed)
}

/// Most blocks any frame's grid has (a shifted grid has up to one more row and column).
pub fn max_blocks(settings: &SelectionSettings, width: u32, height: u32) -> u64 {
    match grid(settings, width, height) {
        Ok(grid) if settings.block_shift => u64::from(grid.max_shifted_block_count()),
        Ok(grid) => u64::from(grid.block_count()),
        Err(_) => 0,
    }
}

/// Workgroups of `strata_select` and `strata_resample` over a `width` × `height` image,
/// from the kernels' own `@workgroup_size`.
pub(crate) fn pixel_workgroups(width: u32, height: u32) -> Result<[u32; 3], EmbedError> {
    let registry = Registry::shared()?;
    let [x, y, _] = registry.get(KernelId::StrataSelect).workgroup_size;
    debug_assert_eq!(registry.get(KernelId::StrataResample).workgroup_size, [x, y, 1]);
    Ok([width.div_ceil(x), height.div_ceil(y), 1])
}

/// Which frame of which render, and how the engine hands out payloads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrameId {
    /// Frame index (the blue-noise sample index is frame mod 256).
    pub frame: u32,
    /// Seed of the render: independent renders need different seeds.
    pub seed: u32,
    /// A pixel's payload is its index (the engine binds no payloads buffer).
    pub identity_payload: bool,
}

/// The parameters of one frame; `max_workgroups` is the device's per-dimension limit.
pub fn frame_params(
    settings: &SelectionSettings,
    width: u32,
    height: u32,
    id: FrameId,
    max_workgroups: u32,
) -> Result<FrameParams, EmbedError> {
    let FrameId { frame, seed, identity_payload } = id;
    let (sx, sy) = grid_shift(settings, frame, seed);
    let grid = grid(settings, width, height)?.with_shift(sx, sy).map_err(|e| EmbedError::ImageSize {
        width,
        height,
        why: e.to_string(),
    })?;
    let histogram_workgroups = grid.histogram_workgroups(max_workgroups);
    let x = histogram_workgroups[0];
    let selection = SelectionParams {
        width,
        height,
        frame,
        seed,
        candidates: settings.candidates,
        sampler: settings.sampler.id(),
        identity_payload: u32::from(identity_payload),
        _pad: 0,
    };
    Ok(FrameParams {
        histogram: grid.histogram_params(x, settings.masking),
        selection,
        histogram_workgroups,
        pixel_workgroups: pixel_workgroups(width, height)?,
    })
}
