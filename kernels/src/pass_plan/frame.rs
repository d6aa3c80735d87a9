//! What one frame of the pass writes and dispatches: the block grid shifted for the
//! frame (§5.3 / limitations: a different shift every frame), the histogram's and the
//! selection's uniforms, and the workgroup counts of the three kernels.

use crate::embed_types::SelectionParams;
use crate::selection::{SelectionSettings, SettingError};
use crate::types::HistogramParams;
use crate::{BlockGrid, GridError, KernelError, KernelId, Registry};
use thiserror::Error;

/// Why a frame's parameters cannot be made.
#[derive(Debug, Error)]
pub enum PlanError {
    /// A [`SelectionSettings`] field is out of range.
    #[error("SelectionSettings.{0}")]
    Setting(#[from] SettingError),
    /// Zero or too many pixels, or a shift of the block size or more.
    #[error("image size {width}x{height}: {why}")]
    ImageSize {
        /// Width.
        width: u32,
        /// Height.
        height: u32,
        /// What is wrong.
        why: String,
    },
    /// A kernel failed to load (a bug; the message names the kernel).
    #[error(transparent)]
    Kernel(#[from] KernelError),
}

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

/// One frame's histogram dispatch: its grid, uniform and workgroups.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct HistogramDispatch {
    /// The grid, shifted for the frame.
    pub grid: BlockGrid,
    /// The histogram kernel's uniform.
    pub params: HistogramParams,
    /// Workgroups, in rows of at most the device's per-dimension limit.
    pub workgroups: [u32; 3],
}

/// The image's grid, checked (the settings are validated first).
pub fn grid(settings: &SelectionSettings, width: u32, height: u32) -> Result<BlockGrid, PlanError> {
    settings.validate()?;
    BlockGrid::new(width, height, settings.block_size).map_err(|error| image_size(width, height, error))
}

fn image_size(width: u32, height: u32, error: GridError) -> PlanError {
    PlanError::ImageSize { width, height, why: error.to_string() }
}

/// Block-grid shift of frame `frame` of the render `seed`: (0, 0) without block shifting,
/// else a hash of the frame and seed in 0..B per axis.
pub fn grid_shift(settings: &SelectionSettings, frame: u32, seed: u32) -> (u32, u32) {
    if !settings.block_shift {
        return (0, 0);
    }
    crate::block_grid::frame_shift(settings.block_size, frame, seed)
}

/// Most blocks any frame's grid has (a shifted grid has up to one more row and column).
pub fn max_blocks(settings: &SelectionSettings, width: u32, height: u32) -> u64 {
    match grid(settings, width, height) {
        Ok(grid) if settings.block_shift => u64::from(grid.max_shifted_block_count()),
        Ok(grid) => u64::from(grid.block_count()),
        Err(_) => 0,
    }
}

/// The histogram dispatch over `grid` moved to `shift` (each in 0..B), with or without
/// object masking (§4.3), on a device of at most `max_workgroups` per dimension.
pub fn histogram_dispatch(
    grid: BlockGrid,
    shift: (u32, u32),
    masking: bool,
    max_workgroups: u32,
) -> Result<HistogramDispatch, GridError> {
    let grid = grid.with_shift(shift.0, shift.1)?;
    let workgroups = grid.histogram_workgroups(max_workgroups);
    Ok(HistogramDispatch { grid, params: grid.histogram_params(workgroups[0], masking), workgroups })
}

/// Workgroups of `strata_select` and `strata_resample` over a `width` × `height` image,
/// from the kernels' own `@workgroup_size`.
pub fn pixel_workgroups(width: u32, height: u32) -> Result<[u32; 3], PlanError> {
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
) -> Result<FrameParams, PlanError> {
    let FrameId { frame, seed, identity_payload } = id;
    let histogram = histogram_dispatch(
        grid(settings, width, height)?,
        grid_shift(settings, frame, seed),
        settings.masking,
        max_workgroups,
    )
    .map_err(|error| image_size(width, height, error))?;
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
        histogram: histogram.params,
        selection,
        histogram_workgroups: histogram.workgroups,
        pixel_workgroups: pixel_workgroups(width, height)?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A shifted frame's histogram covers the image with the frame's shift, and every
    /// shift stays inside the grid's largest block count.
    #[test]
    fn shifted_frames_stay_within_the_largest_grid() {
        let settings = SelectionSettings { block_shift: true, block_size: 8, ..SelectionSettings::default() };
        let blocks = max_blocks(&settings, 100, 60);
        let mut shifts = std::collections::HashSet::new();
        for frame in 0..64 {
            let id = FrameId { frame, seed: 5, identity_payload: false };
            let params = frame_params(&settings, 100, 60, id, 65535).unwrap();
            let (sx, sy) = grid_shift(&settings, frame, 5);
            assert_eq!((params.histogram.shift_x, params.histogram.shift_y), (sx, sy));
            let grid = grid(&settings, 100, 60).unwrap().with_shift(sx, sy).unwrap();
            assert!(u64::from(grid.block_count()) <= blocks);
            shifts.insert((sx, sy));
        }
        assert!(shifts.len() > 8, "the shift changes from frame to frame");
        let still = SelectionSettings { block_shift: false, ..settings };
        assert_eq!(grid_shift(&still, 3, 5), (0, 0));
    }

    #[test]
    fn bad_settings_and_sizes_name_what_is_wrong() {
        let id = FrameId { frame: 0, seed: 0, identity_payload: true };
        let bad = SelectionSettings { block_size: 12, ..SelectionSettings::default() };
        let error = frame_params(&bad, 64, 64, id, 65535).unwrap_err().to_string();
        assert!(error.starts_with("SelectionSettings.block_size = 12"), "{error}");
        let error = frame_params(&SelectionSettings::default(), 0, 64, id, 65535).unwrap_err().to_string();
        assert!(error.starts_with("image size 0x64"), "{error}");
    }
}
