//! The validation mode: the frame index's order on a pass ([`FrameOrder`]), and the check
//! of a frame an engine records itself ([`check_frame`]).

use crate::guard::Failure;
use crate::{STRATA_NO_FRAME, StrataFrameCheck, StrataStatus, settings_of};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Mutex, MutexGuard, PoisonError};
use strata_embed::PassBuffer;
use strata_embed::frame::{FrameId, frame_params, grid, grid_shift, max_blocks};

/// Whether a pass checks its frames' order, and the last frame it recorded.
pub(crate) struct FrameOrder {
    enabled: AtomicBool,
    last: Mutex<Option<u32>>,
}

/// A frame whose order was checked, taken as the last frame once it has recorded
/// ([`Pending::commit`]); holds the order's lock until then (frames of one pass then record
/// one after another).
pub(crate) struct Pending<'a> {
    taken: Option<(MutexGuard<'a, Option<u32>>, u32)>,
}

impl Pending<'_> {
    /// Takes the frame as the last one recorded.
    pub(crate) fn commit(self) {
        if let Some((mut last, frame)) = self.taken {
            *last = Some(frame);
        }
    }
}

impl FrameOrder {
    /// On in a debug build of the library, off in a release build; no frame yet.
    pub(crate) fn new() -> Self {
        Self { enabled: AtomicBool::new(cfg!(debug_assertions)), last: Mutex::new(None) }
    }

    /// Turns the check on or off.
    pub(crate) fn set_enabled(&self, enabled: bool) {
        self.enabled.store(enabled, Ordering::SeqCst);
    }

    /// A new render (`strata_vk_set_seed`): its first frame may have any index.
    pub(crate) fn restart(&self) {
        *self.last.lock().unwrap_or_else(PoisonError::into_inner) = None;
    }

    /// Whether `frame` may be recorded next: with the check on, it must be the last
    /// frame's plus one (any frame first).
    pub(crate) fn check(&self, frame: u32) -> Result<Pending<'_>, Failure> {
        if !self.enabled.load(Ordering::SeqCst) {
            return Ok(Pending { taken: None });
        }
        let last = self.last.lock().unwrap_or_else(PoisonError::into_inner);
        if let Some(previous) = *last {
            frame_follows(frame, previous)?;
        }
        Ok(Pending { taken: Some((last, frame)) })
    }
}

/// A `FrameIndex` failure unless `frame` is `previous + 1`.
fn frame_follows(frame: u32, previous: u32) -> Result<(), Failure> {
    let next = previous.wrapping_add(1);
    if frame == next {
        return Ok(());
    }
    let why = if frame == previous {
        "repeated: every frame then makes the same selections as the first (a frame index left at 0)"
    } else {
        "skipped or out of order"
    };
    Err(Failure {
        status: StrataStatus::FrameIndex,
        message: format!(
            "frame = {frame}: the previous frame was {previous}, so this one must be {next}; the frame index is {why}; \
             it advances by one each frame (strata_vk_set_seed starts a new render, strata_vk_set_validation(pass, 0) \
             turns this check off)"
        ),
    })
}

/// [`crate::strata_vk_check_frame`].
pub(crate) fn check_frame(check: &StrataFrameCheck) -> Result<(), Failure> {
    let settings = settings_of(&check.settings)?;
    let (width, height) = (check.width, check.height);
    let image_size = |why: String| Failure { status: StrataStatus::ImageSize, message: why };
    let grid = grid(&settings, width, height).map_err(|e| image_size(e.to_string()))?;
    if check.previous_frame != STRATA_NO_FRAME {
        frame_follows(check.frame, check.previous_frame)?;
    }
    let bytes = &check.buffer_bytes;
    let blocks = max_blocks(&settings, width, height);
    let resampling = bytes.resample_inputs != 0 || bytes.resampled != 0;
    for (name, given, buffer, optional) in [
        ("candidates", bytes.candidates, PassBuffer::Candidates, false),
        ("payloads", bytes.payloads, PassBuffer::Payloads, true),
        ("selections", bytes.selections, PassBuffer::Selections, false),
        ("resample_inputs", bytes.resample_inputs, PassBuffer::ResampleInputs, !resampling),
        ("resampled", bytes.resampled, PassBuffer::Resampled, !resampling),
        ("sorted_pixels", bytes.sorted_pixels, PassBuffer::SortedPixels, false),
        ("spans", bytes.spans, PassBuffer::Spans, false),
        ("block_stats", bytes.block_stats, PassBuffer::BlockStats, false),
        ("blue_noise", bytes.blue_noise, PassBuffer::BlueNoise, false),
        ("histogram_params", bytes.histogram_params, PassBuffer::HistogramParams, false),
        ("selection_params", bytes.selection_params, PassBuffer::SelectionParams, false),
    ] {
        let needed = buffer.bytes(width, height, blocks);
        if (given == 0 && optional) || given >= needed {
            continue;
        }
        let per = match buffer.size_rule() {
            strata_embed::SizeRule::PerPixel(b) => format!("{b} per pixel of {width}x{height}"),
            strata_embed::SizeRule::PerBlock(b) => format!("{b} per block of the largest grid, {blocks} blocks"),
            strata_embed::SizeRule::Fixed(_) => "fixed".into(),
        };
        return Err(Failure {
            status: StrataStatus::Buffer,
            message: format!(
                "buffer_bytes.{name} = {given}: the pass needs {needed} ({per}); the kernels write past a smaller buffer's \
                 end or leave records unwritten (a buffer sized for a smaller image or another setting?)"
            ),
        });
    }
    let id = FrameId { frame: check.frame, seed: check.seed, identity_payload: bytes.payloads == 0 };
    let want =
        frame_params(&settings, width, height, id, check.max_workgroups).map_err(|e| image_size(e.to_string()))?;
    if check.pixel_workgroups != want.pixel_workgroups {
        let [x, y, _] = strata_embed::wgsl::module(strata_embed::wgsl::ModuleId::Select)?.workgroup_size;
        let hint = if check.pixel_workgroups == [width / x, height / y, 1] {
            "floor instead of ceil: the last columns or rows of pixels are never written"
        } else {
            "ceil(width / workgroup width), ceil(height / workgroup height), 1"
        };
        return Err(dispatch_failure("pixel_workgroups", check.pixel_workgroups, want.pixel_workgroups, hint));
    }
    if check.histogram_workgroups != want.histogram_workgroups {
        let (sx, sy) = grid_shift(&settings, check.frame, check.seed);
        let shifted = grid.with_shift(sx, sy).map_err(|e| image_size(e.to_string()))?;
        let given = check.histogram_workgroups;
        let hint = if given == [shifted.blocks_x(), shifted.blocks_y(), 1]
            || given == [grid.blocks_x(), grid.blocks_y(), 1]
        {
            "one workgroup per block in 2-D: a histogram workgroup sorts STRATA_HISTOGRAM_SLOTS_PER_WORKGROUP / (B * B) \
             blocks, in rows of at most max_workgroups (manifest.json's dispatch)"
        } else if (sx, sy) != (0, 0) && given == grid.histogram_workgroups(check.max_workgroups) {
            "the frame's block shift ignored: the grid of a shifted frame has more blocks (strata_grid_shift)"
        } else {
            "the histogram's dispatch is manifest.json's expressions (strata_frame_params computes them)"
        };
        return Err(dispatch_failure("histogram_workgroups", given, want.histogram_workgroups, hint));
    }
    Ok(())
}

/// A `Dispatch` failure: `field` was `given`, the pass needs `want`.
fn dispatch_failure(field: &str, given: [u32; 3], want: [u32; 3], hint: &str) -> Failure {
    let [a, b, c] = given;
    let [x, y, z] = want;
    Failure {
        status: StrataStatus::Dispatch,
        message: format!("{field} = {a}x{b}x{c}: the pass needs {x}x{y}x{z}; {hint}"),
    }
}
