//! The buffer contract between an engine and the pass: which buffers exist, their record
//! layouts (the `#[repr(C)]` structs declared once in `strata_kernels`, from which the
//! kernels' WGSL declarations are generated), who writes each and when.
//!
//! | buffer | record (bytes per pixel) | written by | read by |
//! |---|---|---|---|
//! | `candidates` | [`Candidate`] (8): luminance key, cluster id | the engine, before [`selection`](crate) | histogram, `strata_select` |
//! | `payloads` (optional) | `u32` (4): index into the engine's reservoir storage | the engine | `strata_select` |
//! | `selections` | [`SelectedCandidates`] (32): K payloads, resampling number, run size | `strata_select` | the engine; `strata_resample` |
//! | `resample_inputs` | [`ResampleInput`] (48): the engine's weights and targets | the engine, after selection | `strata_resample` |
//! | `resampled` | [`ResampleOutput`] (16): chosen payload, slot, W | `strata_resample` | the engine |
//!
//! All buffers are row-major, one record per pixel, pixel index `y * width + x`, at an
//! offset that is a multiple of the device's storage-buffer offset alignment. Every
//! buffer needs storage usage; the pass reads `candidates`, `payloads` and
//! `resample_inputs` only and writes `selections` and `resampled` whole (every pixel).
//!
//! Candidate keys: the luminance of the candidate's own one-sample estimate (f/p at its
//! pixel), ≥ 0. NaN, ±∞ and negative keys mark a candidate invalid: it sorts after the
//! valid ones of its cluster (its weight should be 0). Cluster id: the object id of the
//! pixel's primary hit (any u32 below 0xfffffffe), [`OBJECT_ID_ENVIRONMENT`] for a pixel
//! that sees the environment, [`OBJECT_ID_NONE`] for a pixel without a candidate (it gets
//! no selection).
//!
//! Payloads: without a payloads buffer, a pixel's payload is its pixel index (engines
//! with one reservoir per pixel). With one, `payloads[p]` is returned for pixel p.
//!
//! Resampling weights (engine side): for the canonical sample c of pixel i and each
//! selected slot j, the engine evaluates its own shift mapping and target function and
//! writes w = m · p̂_i · W with an MIS weight m whose pair terms depend only on (c, j), a
//! fixed 1/K normalisation, and W the sample's unbiased contribution weight (strata's own
//! renderer uses pairwise MIS; see docs/restir.md, "Why the selection stays unbiased").

pub use strata_kernels::embed_types::{
    CANONICAL_SLOT, INVALID_SLOT, MAX_SELECTED, NO_PAYLOAD, NO_SLOT, ResampleInput, ResampleOutput, SelectedCandidates,
    SelectionParams,
};
use strata_kernels::pass_plan::PassBuffer;
pub use strata_kernels::types::{Candidate, ClusterSpan, OBJECT_ID_ENVIRONMENT, OBJECT_ID_NONE};

/// The engine-visible buffers of the contract.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BufferRole {
    /// One [`Candidate`] per pixel.
    Candidates,
    /// One `u32` payload per pixel (optional).
    Payloads,
    /// One [`SelectedCandidates`] per pixel.
    Selections,
    /// One [`ResampleInput`] per pixel.
    ResampleInputs,
    /// One [`ResampleOutput`] per pixel.
    Resampled,
}

impl BufferRole {
    /// Every role, in pipeline order.
    pub const ALL: [BufferRole; 5] = [
        BufferRole::Candidates,
        BufferRole::Payloads,
        BufferRole::Selections,
        BufferRole::ResampleInputs,
        BufferRole::Resampled,
    ];

    /// The pass's buffer this role is (`strata_kernels::pass_plan`).
    pub fn buffer(self) -> PassBuffer {
        match self {
            BufferRole::Candidates => PassBuffer::Candidates,
            BufferRole::Payloads => PassBuffer::Payloads,
            BufferRole::Selections => PassBuffer::Selections,
            BufferRole::ResampleInputs => PassBuffer::ResampleInputs,
            BufferRole::Resampled => PassBuffer::Resampled,
        }
    }

    /// The name used in errors and docs.
    pub fn name(self) -> &'static str {
        self.buffer().name()
    }

    /// Bytes per pixel.
    pub fn bytes_per_pixel(self) -> u64 {
        self.buffer().size_rule().bytes(1, 0)
    }

    /// Bytes for a `width` × `height` image.
    pub fn size(self, width: u32, height: u32) -> u64 {
        self.buffer().bytes(width, height, 0)
    }
}

/// Checks that a buffer of `size` bytes (from its binding offset) holds `role` for the
/// image.
pub(crate) fn check_size(role: BufferRole, size: u64, width: u32, height: u32) -> Result<(), crate::EmbedError> {
    let needed = role.size(width, height);
    if size < needed {
        return Err(crate::EmbedError::BufferTooSmall {
            buffer: role.name(),
            size,
            needed,
            per_pixel: role.bytes_per_pixel(),
            width,
            height,
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wgsl::ModuleId;
    use strata_kernels::pass_plan::Stage;

    /// Every engine buffer of the contract is bound with the WGSL element type of the
    /// table above and the stride of its host record (layouts: strata_kernels' layout
    /// test), and written by exactly the kernels the table names.
    #[test]
    fn contract_matches_the_kernels_bindings() {
        let registry = strata_kernels::Registry::shared().unwrap();
        let elements = [
            (BufferRole::Candidates, "Candidate"),
            (BufferRole::Payloads, "u32"),
            (BufferRole::Selections, "SelectedCandidates"),
            (BufferRole::ResampleInputs, "ResampleInput"),
            (BufferRole::Resampled, "ResampleOutput"),
        ];
        for (role, element) in elements {
            let mut places = 0;
            for id in ModuleId::ALL {
                let kernel = registry.get(id.kernel());
                let stage = Stage::of(id.kernel()).unwrap();
                for (name, _) in stage.bindings().iter().filter(|(_, buffer)| *buffer == role.buffer()) {
                    let bound = kernel.bindings.iter().find(|b| b.name == *name).unwrap();
                    assert_eq!(bound.element.type_name, element, "{role:?} in {id:?}");
                    assert_eq!(u64::from(bound.element.stride), role.bytes_per_pixel(), "{role:?} in {id:?}");
                    let writes = matches!((role, stage), (BufferRole::Selections, Stage::Select))
                        || matches!((role, stage), (BufferRole::Resampled, Stage::Resample));
                    assert_eq!(bound.is_writable(), writes, "{role:?} in {id:?}: written by the pass?");
                    places += 1;
                }
            }
            assert!(places > 0, "{role:?} is bound somewhere");
        }
    }

    /// Block shifting moves the grid by a different offset in 0..B most frames.
    #[test]
    fn block_shift_varies_per_frame() {
        let settings = crate::SelectionSettings { block_shift: true, ..Default::default() };
        let shifts: Vec<_> = (0..64).map(|frame| crate::frame::grid_shift(&settings, frame, 0)).collect();
        assert!(shifts.iter().all(|&(x, y)| x < 16 && y < 16));
        let distinct: std::collections::HashSet<_> = shifts.iter().collect();
        assert!(distinct.len() > 40, "{} distinct shifts", distinct.len());
        let off = crate::SelectionSettings::default();
        assert!((0..64).all(|frame| crate::frame::grid_shift(&off, frame, 0) == (0, 0)));
    }
}
