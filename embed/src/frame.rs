//! Per-frame parameters shared by the wgpu and ash flavours: the shifted block grid and
//! the selection's uniform, and the dispatch sizes of the three kernels. They are the one
//! plan of the pass in `strata_kernels::pass_plan` (which strata's renderer and the
//! export package follow too), re-exported here; its errors convert into
//! [`crate::EmbedError`].

pub use strata_kernels::pass_plan::{
    FrameId, FrameParams, frame_params, grid, grid_shift, max_blocks, pixel_workgroups,
};
