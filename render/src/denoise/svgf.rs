//! The SVGF pass on any backend: its history buffers, one uniform per à-trous level, and
//! the four kernels dispatched in order each frame.

use super::SvgfSettings;
use crate::histogram_pass::PassError;
use strata_backends::backend::upload;
use strata_backends::{Backend, Bind, BufferId};
use strata_kernels::{Kernel, KernelId, Registry};

/// SVGF over a sequence of frames of one size: it keeps each frame's history for the next.
pub struct SvgfDenoiser {
    kernels: [&'static Kernel; 4],
    settings: SvgfSettings,
    width: u32,
    height: u32,
    /// One uniform per à-trous level (level 0's also serves the temporal, variance and
    /// modulation passes; its `history` flag changes per frame).
    params: Vec<BufferId>,
    /// Integrated illumination and history length: this frame's and the previous one's.
    integrated: [BufferId; 2],
    /// Luminance moments: this frame's and the previous one's.
    moments: [BufferId; 2],
    /// The first à-trous level's output: the next frame's history.
    history: BufferId,
    /// Illumination and variance between the passes, ping-ponged.
    levels: [BufferId; 2],
    /// The denoised colour.
    output: BufferId,
    /// Frames denoised since creation or [`SvgfDenoiser::reset`].
    frame: u32,
    /// Time every pass with timestamp queries ([`SvgfDenoiser::set_timed`]).
    timed: bool,
    /// The device time of the last frame's passes (zero unless timed).
    last_time: std::time::Duration,
}

impl SvgfDenoiser {
    /// The pass for `width` x `height` frames.
    pub fn new(backend: &mut dyn Backend, width: u32, height: u32, settings: SvgfSettings) -> Result<Self, PassError> {
        settings.check()?;
        if width == 0 || height == 0 {
            return Err(PassError::Input(format!("denoiser image size {width}x{height}: must be at least 1x1")));
        }
        let registry = Registry::shared()?;
        let kernels = [KernelId::SvgfTemporal, KernelId::SvgfVariance, KernelId::SvgfAtrous, KernelId::SvgfModulate]
            .map(|id| registry.get(id));
        for kernel in kernels {
            backend.check_kernel(kernel)?;
        }
        let pixels = u64::from(width) * u64::from(height);
        let mut buffer = |name: &str, bytes: u64| backend.create_buffer(name, bytes);
        let integrated = [buffer("svgf integrated A", pixels * 16)?, buffer("svgf integrated B", pixels * 16)?];
        let moments = [buffer("svgf moments A", pixels * 8)?, buffer("svgf moments B", pixels * 8)?];
        let history = buffer("svgf history", pixels * 16)?;
        let levels = [buffer("svgf level A", pixels * 16)?, buffer("svgf level B", pixels * 16)?];
        let output = buffer("svgf output", pixels * 16)?;
        let params = (0..settings.levels)
            .map(|level| upload(backend, "svgf params", &[settings.params(width, height, level, false)]))
            .collect::<Result<_, _>>()?;
        Ok(SvgfDenoiser {
            kernels,
            settings,
            width,
            height,
            params,
            integrated,
            moments,
            history,
            levels,
            output,
            frame: 0,
            timed: false,
            last_time: std::time::Duration::ZERO,
        })
    }

    /// Time every pass with timestamp queries (each dispatch then waits for the device),
    /// when the backend has them: see [`SvgfDenoiser::last_time`].
    pub fn set_timed(&mut self, timed: bool) {
        self.timed = timed;
    }

    /// The device time of the last frame's passes, summed; zero unless timed.
    pub fn last_time(&self) -> std::time::Duration {
        self.last_time
    }

    /// The next frame starts without history (a camera cut).
    pub fn reset(&mut self) {
        self.frame = 0;
    }

    /// Denoises one frame: `colour` holds its noisy rgb per pixel (`vec4<f32>`, w
    /// unused), `guides` its [`DenoiseGuide`](strata_kernels::denoise_types::DenoiseGuide)s
    /// and `previous_guides` the previous frame's (unread on the first frame). Call it for
    /// every frame the guides' motion vectors step through (or [`SvgfDenoiser::reset`]
    /// after a skipped one): the history is the last frame this pass denoised. Returns
    /// the buffer of the denoised colour (`vec4<f32>`, w 0), valid until the next call.
    pub fn denoise(
        &mut self,
        backend: &mut dyn Backend,
        colour: BufferId,
        guides: BufferId,
        previous_guides: BufferId,
    ) -> Result<BufferId, PassError> {
        let history = self.frame > 0;
        let first = self.settings.params(self.width, self.height, 0, history);
        backend.write_buffer(self.params[0], 0, bytemuck::bytes_of(&first))?;
        let (current, previous) = ((self.frame % 2) as usize, ((self.frame + 1) % 2) as usize);
        let [temporal, variance, atrous, modulate] = self.kernels;
        let groups = [self.width.div_ceil(8), self.height.div_ceil(8), 1];
        let timed = self.timed && backend.info().timestamps;
        let mut time = std::time::Duration::ZERO;
        // Binds each of `buffers` to the kernel's binding of that name.
        let mut dispatch = |backend: &mut dyn Backend,
                            kernel: &Kernel,
                            params: BufferId,
                            buffers: &[(&str, BufferId)]|
         -> Result<(), PassError> {
            let mut named = vec![("params", params)];
            named.extend_from_slice(buffers);
            let binds = Bind::named(kernel, &named)?;
            if timed {
                time += backend.dispatch_timed(kernel, &binds, groups)?;
                return Ok(());
            }
            Ok(backend.dispatch(kernel, &binds, groups)?)
        };
        dispatch(
            backend,
            temporal,
            self.params[0],
            &[
                ("colour", colour),
                ("guides", guides),
                ("previous_guides", previous_guides),
                ("history", self.history),
                ("previous_integrated", self.integrated[previous]),
                ("previous_moments", self.moments[previous]),
                ("integrated", self.integrated[current]),
                ("moments", self.moments[current]),
            ],
        )?;
        dispatch(
            backend,
            variance,
            self.params[0],
            &[
                ("guides", guides),
                ("integrated", self.integrated[current]),
                ("moments", self.moments[current]),
                ("illumination_variance", self.levels[0]),
            ],
        )?;
        // Level 0 writes the next frame's history; the others ping-pong.
        let mut input = self.levels[0];
        for level in 0..self.settings.levels {
            let out = if level == 0 {
                self.history
            } else if input == self.levels[0] {
                self.levels[1]
            } else {
                self.levels[0]
            };
            dispatch(
                backend,
                atrous,
                self.params[level as usize],
                &[("guides", guides), ("level_in", input), ("level_out", out)],
            )?;
            input = out;
        }
        dispatch(
            backend,
            modulate,
            self.params[0],
            &[("colour", colour), ("guides", guides), ("filtered", input), ("denoised", self.output)],
        )?;
        self.last_time = time;
        self.frame += 1;
        Ok(self.output)
    }

    /// Frees every buffer.
    pub fn destroy(self, backend: &mut dyn Backend) -> Result<(), PassError> {
        let buffers = self.params.iter().copied().chain(self.integrated).chain(self.moments).chain(self.levels);
        for buffer in buffers.chain([self.history, self.output]) {
            backend.destroy_buffer(buffer)?;
        }
        Ok(())
    }
}
