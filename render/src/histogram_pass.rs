//! The block-histogram pass on any backend: buffers, parameters, dispatch, read-back.
//! A thin runner of the one plan of the paper's pass (`strata_kernels::pass_plan`): its
//! buffers are sized, bound (by the WGSL variable's name) and shifted per frame as the
//! plan says, the same plan strata-embed records into an engine's command buffers.

use strata_backends::backend::{download, upload};
use strata_backends::{Backend, BackendError, Bind, BufferId};
use strata_kernels::pass_plan::{PassBuffer, Stage, histogram_dispatch};
use strata_kernels::reference::block_histogram::HistogramOutput;
use strata_kernels::selection::SelectionSettings;
use strata_kernels::types::{BlockStats, Candidate, ClusterSpan};
use strata_kernels::{BlockGrid, Executor, GridError, Kernel, KernelError, KernelId, Registry};
use thiserror::Error;

/// Slots one workgroup sorts (`HISTOGRAM_SLOTS_PER_WORKGROUP`, `strata/histogram.wgsl`).
pub const SLOTS_PER_WORKGROUP: u32 = strata_kernels::types::HISTOGRAM_SLOTS_PER_WORKGROUP;

/// Which entry point of the histogram kernel to run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HistogramVariant {
    /// Workgroup memory only; runs everywhere.
    Portable,
    /// Subgroup shuffles for the middle strides; needs subgroup support.
    Subgroup,
    /// Each element's position counted over its block (`block_histogram_rank`); runs
    /// everywhere, same outputs.
    Rank,
    /// The fastest measured ([`KernelId::fastest_histogram`]): on a GPU and on the
    /// interpreter the network (with subgroups if the device has them), on a CPU driver
    /// such as lavapipe ranking at every block size.
    Auto,
}

/// The kernel [`HistogramVariant::Auto`] runs for `block_size` on this device
/// ([`KernelId::fastest_histogram`] for its executor and subgroup support).
pub fn auto_kernel(info: &strata_backends::DeviceInfo, block_size: u32) -> KernelId {
    let executor = Executor::of_device(&info.device_type, info.is_interpreter());
    KernelId::fastest_histogram(block_size, info.subgroup_sizes.is_some(), executor)
}

/// Whether `device` can hold the histogram pass's buffers for `grid`: each of them
/// (candidates, sorted pixels, cluster spans, block stats) within one storage binding
/// and one buffer. Checked before anything is allocated; the error names the image,
/// the buffer that does not fit, its bytes, the device's limit and the most pixels it
/// takes, so that a caller can put its own flags in front ([`PassError::ImageTooLarge`]).
pub fn check_image_fits(device: &strata_backends::DeviceInfo, grid: BlockGrid) -> Result<(), PassError> {
    let limit = device.limits.max_storage_binding.min(device.limits.max_buffer_size);
    let blocks = u64::from(grid.max_shifted_block_count().max(grid.block_count()));
    for buffer in [PassBuffer::Candidates, PassBuffer::SortedPixels, PassBuffer::Spans, PassBuffer::BlockStats] {
        let bytes = buffer.bytes(grid.width, grid.height, blocks);
        if bytes > limit {
            // The per-pixel buffers are the large ones: the most pixels the largest fits.
            let per_pixel = [PassBuffer::Candidates, PassBuffer::SortedPixels, PassBuffer::Spans]
                .iter()
                .map(|b| b.bytes(1, 1, 0))
                .max()
                .unwrap_or(1);
            return Err(PassError::ImageTooLarge {
                width: grid.width,
                height: grid.height,
                buffer: buffer.name(),
                bytes,
                limit,
                max_pixels: limit / per_pixel,
            });
        }
    }
    Ok(())
}

/// A failure of a host pass.
#[derive(Debug, Error)]
pub enum PassError {
    /// Bad image or block size.
    #[error(transparent)]
    Grid(#[from] GridError),
    /// The backend failed.
    #[error(transparent)]
    Backend(#[from] BackendError),
    /// The kernel failed to load.
    #[error(transparent)]
    Kernel(#[from] KernelError),
    /// Input that a pass cannot take, described.
    #[error("{0}")]
    Input(String),
    /// An image whose pass buffers do not fit the device ([`check_image_fits`]).
    #[error(
        "a {width}x{height} image ({pixels} pixels) needs {bytes} bytes of `{buffer}`, past this device's limit of \
         {limit} bytes per storage buffer: at most {max_pixels} pixels (width x height)",
        pixels = u64::from(*width) * u64::from(*height)
    )]
    ImageTooLarge {
        /// Image width.
        width: u32,
        /// Image height.
        height: u32,
        /// The pass buffer that does not fit.
        buffer: &'static str,
        /// Its bytes.
        bytes: u64,
        /// The device's limit in bytes (storage binding, buffer size: the smaller).
        limit: u64,
        /// The most pixels the device takes.
        max_pixels: u64,
    },
    /// Candidate count differs from the pixel count.
    #[error("{width}x{height} image needs {expected} candidates, got {got}")]
    CandidateCount {
        /// Image width.
        width: u32,
        /// Image height.
        height: u32,
        /// Pixels.
        expected: usize,
        /// Candidates given.
        got: usize,
    },
}

/// The histogram pass for one image size and block size, with its buffers.
pub struct BlockHistogramPass {
    kernel: &'static Kernel,
    grid: BlockGrid,
    masking: bool,
    workgroups: [u32; 3],
    /// The kernel's bindings, numbered by the registry from the plan's names.
    binds: Vec<Bind>,
    /// Uniform `HistogramParams`.
    pub params: BufferId,
    /// Input: one `Candidate` per pixel.
    pub candidates: BufferId,
    /// Output: per block, its pixel indices in sorted order.
    pub sorted_pixels: BufferId,
    /// Output: per pixel, its cluster's `ClusterSpan`.
    pub spans: BufferId,
    /// Output: per block, its `BlockStats`.
    pub block_stats: BufferId,
}

impl BlockHistogramPass {
    /// Creates the buffers and checks that `backend` can run the chosen variant; clusters
    /// by object id.
    pub fn new(backend: &mut dyn Backend, variant: HistogramVariant, grid: BlockGrid) -> Result<Self, PassError> {
        Self::with_masking(backend, variant, grid, true)
    }

    /// [`Self::new`] with object masking (§4.3) on or off: off puts every candidate of a
    /// block in one cluster.
    pub fn with_masking(
        backend: &mut dyn Backend,
        variant: HistogramVariant,
        grid: BlockGrid,
        masking: bool,
    ) -> Result<Self, PassError> {
        let registry = Registry::shared()?;
        let id = match variant {
            HistogramVariant::Portable => KernelId::BlockHistogram,
            HistogramVariant::Subgroup => KernelId::BlockHistogramSubgroup,
            HistogramVariant::Rank => KernelId::BlockHistogramRank,
            HistogramVariant::Auto => auto_kernel(backend.info(), grid.block_size),
        };
        let kernel = registry.get(id);
        backend.check_kernel(kernel)?;
        check_image_fits(backend.info(), grid)?;
        let max_workgroups = backend.info().limits.max_workgroups_per_dimension;
        let frame = histogram_dispatch(grid, (grid.shift_x, grid.shift_y), masking, max_workgroups)?;
        // Room for every shift of the grid (set_grid_shift).
        let blocks = u64::from(grid.max_shifted_block_count().max(grid.block_count()));
        let bytes = |buffer: PassBuffer| buffer.bytes(grid.width, grid.height, blocks);
        let params = upload(backend, "histogram params", &[frame.params])?;
        let candidates = backend.create_buffer("candidates", bytes(PassBuffer::Candidates))?;
        let sorted_pixels = backend.create_buffer("sorted pixels", bytes(PassBuffer::SortedPixels))?;
        let spans = backend.create_buffer("cluster spans", bytes(PassBuffer::Spans))?;
        let block_stats = backend.create_buffer("block stats", bytes(PassBuffer::BlockStats))?;
        let binds = Stage::Histogram
            .bind(kernel, |buffer| match buffer {
                PassBuffer::HistogramParams => Some(params),
                PassBuffer::Candidates => Some(candidates),
                PassBuffer::SortedPixels => Some(sorted_pixels),
                PassBuffer::Spans => Some(spans),
                PassBuffer::BlockStats => Some(block_stats),
                _ => None,
            })
            .expect("the histogram binds only the buffers above")
            .into_iter()
            .map(|(binding, buffer)| Bind::new(binding, buffer))
            .collect();
        Ok(Self {
            kernel,
            grid,
            masking,
            workgroups: frame.workgroups,
            binds,
            params,
            candidates,
            sorted_pixels,
            spans,
            block_stats,
        })
    }

    /// Moves the block grid to shift (sx, sy), each in 0..B (§5.3 / limitations: a
    /// different shift every frame), for the next dispatches.
    pub fn set_grid_shift(&mut self, backend: &mut dyn Backend, shift_x: u32, shift_y: u32) -> Result<(), PassError> {
        let max_workgroups = backend.info().limits.max_workgroups_per_dimension;
        let frame = histogram_dispatch(self.grid, (shift_x, shift_y), self.masking, max_workgroups)?;
        backend.write_buffer(self.params, 0, bytemuck::bytes_of(&frame.params))?;
        self.grid = frame.grid;
        self.workgroups = frame.workgroups;
        Ok(())
    }

    /// Shifts the grid for frame `frame` of the render `seed` as the plan says
    /// ([`strata_kernels::pass_plan::grid_shift`]: not at all without block shifting).
    pub fn set_frame(
        &mut self,
        backend: &mut dyn Backend,
        settings: &SelectionSettings,
        frame: u32,
        seed: u32,
    ) -> Result<(), PassError> {
        let (shift_x, shift_y) = strata_kernels::pass_plan::grid_shift(settings, frame, seed);
        self.set_grid_shift(backend, shift_x, shift_y)
    }

    /// The kernel this pass runs.
    pub fn kernel(&self) -> &'static Kernel {
        self.kernel
    }

    /// The image's block grid.
    pub fn grid(&self) -> BlockGrid {
        self.grid
    }

    /// Workgroups of one dispatch.
    pub fn workgroups(&self) -> [u32; 3] {
        self.workgroups
    }

    /// Fills every output buffer with `pattern`, so that an element the kernel fails to
    /// write is caught by a comparison (tests and the cross-backend check).
    pub fn poison_outputs(&self, backend: &mut dyn Backend, pattern: u32) -> Result<(), PassError> {
        let pixels = self.grid.pixel_count();
        let words = [
            (self.sorted_pixels, pixels),
            (self.spans, pixels * size_of::<ClusterSpan>() / 4),
            (self.block_stats, self.grid.block_count() as usize * size_of::<BlockStats>() / 4),
        ];
        for (buffer, count) in words {
            backend.write_buffer(buffer, 0, bytemuck::cast_slice(&vec![pattern; count]))?;
        }
        Ok(())
    }

    /// Uploads one candidate per pixel.
    pub fn upload_candidates(&self, backend: &mut dyn Backend, candidates: &[Candidate]) -> Result<(), PassError> {
        if candidates.len() != self.grid.pixel_count() {
            return Err(PassError::CandidateCount {
                width: self.grid.width,
                height: self.grid.height,
                expected: self.grid.pixel_count(),
                got: candidates.len(),
            });
        }
        backend.write_buffer(self.candidates, 0, bytemuck::cast_slice(candidates))?;
        Ok(())
    }

    /// Runs the pass on the uploaded candidates.
    pub fn dispatch(&self, backend: &mut dyn Backend) -> Result<(), PassError> {
        backend.dispatch(self.kernel, &self.binds, self.workgroups)?;
        Ok(())
    }

    /// Runs the pass and returns its device time (timestamp queries).
    pub fn dispatch_timed(&self, backend: &mut dyn Backend) -> Result<std::time::Duration, PassError> {
        Ok(backend.dispatch_timed(self.kernel, &self.binds, self.workgroups)?)
    }

    /// Reads the outputs back.
    pub fn read_output(&self, backend: &mut dyn Backend) -> Result<HistogramOutput, PassError> {
        Ok(HistogramOutput {
            sorted_pixels: download(backend, self.sorted_pixels)?,
            spans: download(backend, self.spans)?,
            stats: {
                let mut stats: Vec<BlockStats> = download(backend, self.block_stats)?;
                stats.truncate(self.grid.block_count() as usize);
                stats
            },
        })
    }

    /// Uploads, runs and reads back in one call.
    pub fn run(&self, backend: &mut dyn Backend, candidates: &[Candidate]) -> Result<HistogramOutput, PassError> {
        self.upload_candidates(backend, candidates)?;
        self.dispatch(backend)?;
        self.read_output(backend)
    }

    /// Frees the pass's buffers.
    pub fn destroy(self, backend: &mut dyn Backend) -> Result<(), PassError> {
        for buffer in [self.params, self.candidates, self.sorted_pixels, self.spans, self.block_stats] {
            backend.destroy_buffer(buffer)?;
        }
        Ok(())
    }
}
