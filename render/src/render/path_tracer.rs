//! The progressive path tracer on any backend: a [`GpuScene`] uploaded once, then one
//! `path_trace` dispatch per sample per pixel, summed on the device.

use super::gpu_scene::GpuScene;
use crate::histogram_pass::PassError;
use crate::rgb_image::RgbImage;
use crate::scene::{Camera, CameraFrame};
use strata_backends::backend::{download, upload};
use strata_backends::{Backend, BackendError, Bind, BufferId};
use strata_kernels::render_types::{
    FLAG_HIT_LIGHTS, FLAG_PIXEL_CENTRES, FLAG_RUSSIAN_ROULETTE, FLAG_SAMPLE_LIGHTS, FLAG_STRATIFIED_FILM, RenderParams,
    SCENE_UNIFORM_ROWS,
};
use strata_kernels::{Kernel, KernelId, Registry, Specialisation};

/// How light is found (all three estimate the same image).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum LightSampling {
    /// Next-event estimation and BSDF sampling, combined by the power heuristic.
    #[default]
    Mis,
    /// Next-event estimation only (emission reached by BSDF sampling counts only after
    /// a specular bounce).
    Nee,
    /// BSDF sampling only.
    Bsdf,
}

/// Where in its pixel each camera ray starts.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Film {
    /// Successive samples (frames, for ReSTIR) of a pixel take successive points of its
    /// own R2 sequence from a random start (the default): each sample alone is a uniform
    /// point of the pixel, so every estimate stays unbiased, and across samples the
    /// points cover the pixel evenly, so accumulated frames and references lose their
    /// anti-aliasing noise faster (BENCHMARKS.md, "Levers: the film sequence").
    #[default]
    Stratified,
    /// Independent uniform points of the pixel (white noise; the default before
    /// 2026-11-25, and `strata compare`'s with temporal reuse, where consecutive frames
    /// close together in the pixel reuse each other's reservoirs better).
    White,
    /// The pixel centre, no jitter: a diagnostic, the image is then point-sampled
    /// (aliased), so compare it with a reference rendered the same way.
    Centres,
}

impl Film {
    fn flags(self) -> u32 {
        match self {
            Film::Stratified => FLAG_STRATIFIED_FILM,
            Film::White => 0,
            Film::Centres => FLAG_PIXEL_CENTRES,
        }
    }
}

/// What one render computes.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    /// The camera; its `width` and `height` are the image size.
    pub camera: Camera,
    /// Seed of every random number (samples of different seeds are independent).
    pub seed: u32,
    /// Path segments including the camera ray (CONVENTIONS.md).
    pub max_depth: u32,
    /// Depth from which Russian roulette runs.
    pub rr_depth: u32,
    /// How light is found.
    pub light_sampling: LightSampling,
    /// Russian roulette on (unbiased either way).
    pub russian_roulette: bool,
    /// Where in its pixel each camera ray starts. Default: [`Film::Stratified`].
    pub film: Film,
}

impl RenderSettings {
    /// The scene's own integrator settings (depths, MIS, Russian roulette) and camera at
    /// `width` x `height`, with `seed`.
    pub fn for_scene(scene: &crate::scene::Scene, width: u32, height: u32, seed: u32) -> RenderSettings {
        RenderSettings {
            camera: Camera { width, height, ..scene.camera.clone() },
            seed,
            max_depth: scene.max_depth,
            rr_depth: scene.rr_depth,
            light_sampling: LightSampling::Mis,
            russian_roulette: true,
            film: Film::default(),
        }
    }

    /// The kernels' parameters: the scene-wide fields of `scene` (a
    /// [`GpuScene::params`]) with this render's image size, camera, seed, depths and
    /// flags, checked.
    pub fn params(&self, scene: &RenderParams) -> Result<RenderParams, PassError> {
        let camera = &self.camera;
        if camera.width == 0 || camera.height == 0 {
            return Err(PassError::Input(format!(
                "image size {}x{}: must be at least 1x1",
                camera.width, camera.height
            )));
        }
        if self.max_depth == 0 {
            return Err(PassError::Input("max_depth 0: a path needs at least its camera ray".into()));
        }
        if !(camera.fov_deg > 0.0 && camera.fov_deg < 180.0) {
            return Err(PassError::Input(format!("camera: fov_deg {} must be in (0, 180)", camera.fov_deg)));
        }
        // The reason that holds, alone (it named fov_axis for a view along `up` too).
        let frame = CameraFrame::checked(camera).map_err(|why| {
            PassError::Input(format!("camera (origin {:?}, target {:?}): {why}", camera.origin, camera.target))
        })?;
        let flags = match self.light_sampling {
            LightSampling::Mis => FLAG_SAMPLE_LIGHTS | FLAG_HIT_LIGHTS,
            LightSampling::Nee => FLAG_SAMPLE_LIGHTS,
            LightSampling::Bsdf => FLAG_HIT_LIGHTS,
        } | if self.russian_roulette { FLAG_RUSSIAN_ROULETTE } else { 0 }
            | self.film.flags();
        Ok(RenderParams {
            width: camera.width,
            height: camera.height,
            sample_index: 0,
            seed: self.seed,
            max_depth: self.max_depth,
            rr_depth: self.rr_depth,
            flags,
            camera_origin: frame.origin.into(),
            near_clip: frame.near_clip,
            camera_forward: frame.forward.into(),
            tan_half_x: frame.tan_half_x,
            camera_right: frame.right.into(),
            tan_half_y: frame.tan_half_y,
            camera_up: frame.up.into(),
            ..*scene
        })
    }
}

/// The scene's storage buffer ([`GpuScene::rows`]), bound at 1 of every path-tracing
/// kernel, and its uniform copy at 2 (`render/scene.wgsl`): the rows when they fit
/// ([`GpuScene::fits_uniform_copy`], which also decides the kernels' `scene_in_uniform`),
/// zeros otherwise.
pub struct SceneBuffers {
    rows: BufferId,
    uniform_rows: BufferId,
}

impl SceneBuffers {
    /// Uploads `scene`; a scene larger than the device's storage-binding limit is refused
    /// with both sizes and its largest array (splitting across bindings is not done).
    pub fn upload(backend: &mut dyn Backend, scene: &GpuScene) -> Result<SceneBuffers, PassError> {
        let limit = backend.info().limits.max_storage_binding;
        let size = scene.rows_size();
        if size > limit {
            let (largest, largest_size) = scene
                .sections()
                .into_iter()
                .map(|(name, bytes)| (name, bytes.len()))
                .max_by_key(|&(_, len)| len)
                .unwrap_or(("", 0));
            return Err(PassError::Input(format!(
                "the scene is too large for this device: its arrays take {:.1} MiB in one storage buffer (the \
                 largest, its {largest}, {:.1} MiB), and the device binds at most {:.1} MiB per storage buffer",
                size as f64 / 1048576.0,
                largest_size as f64 / 1048576.0,
                limit as f64 / 1048576.0
            )));
        }
        let rows = scene.rows();
        let storage = upload(backend, "scene rows", &rows)?;
        // Whatever fails from here frees what was made.
        let uniform_rows = match backend.create_buffer("scene rows (uniform copy)", u64::from(SCENE_UNIFORM_ROWS) * 16)
        {
            Ok(buffer) => buffer,
            Err(error) => {
                backend.destroy_buffer(storage)?;
                return Err(error.into());
            }
        };
        let buffers = SceneBuffers { rows: storage, uniform_rows };
        if scene.fits_uniform_copy()
            && let Err(error) = backend.write_buffer(uniform_rows, 0, bytemuck::cast_slice(&rows))
        {
            buffers.destroy(backend)?;
            return Err(error.into());
        }
        Ok(buffers)
    }

    /// The scene's buffers and the parameters `params` under their WGSL names
    /// (`render/scene.wgsl`), for [`Bind::named`].
    pub fn named(&self, params: BufferId) -> Vec<(&'static str, BufferId)> {
        vec![("params", params), ("scene_rows", self.rows), ("scene_rows_uniform", self.uniform_rows)]
    }

    /// Frees the buffers.
    pub fn destroy(self, backend: &mut dyn Backend) -> Result<(), BackendError> {
        backend.destroy_buffer(self.rows)?;
        backend.destroy_buffer(self.uniform_rows)
    }
}

/// A progressive render: samples are added one dispatch at a time.
pub struct PathTracer {
    kernel: &'static Kernel,
    scene: SceneBuffers,
    params: RenderParams,
    params_buffer: BufferId,
    accumulation: BufferId,
    samples: u32,
}

impl PathTracer {
    /// Uploads `scene` and clears the running sum.
    pub fn new(backend: &mut dyn Backend, scene: &GpuScene, settings: &RenderSettings) -> Result<Self, PassError> {
        let specialisation =
            Specialisation { scene_in_uniform: scene.fits_uniform_copy(), ..Specialisation::default() };
        let kernel = Registry::shared()?.specialised(KernelId::PathTrace, specialisation)?;
        backend.check_kernel(kernel)?;
        let params = settings.params(&scene.params)?;
        let pixels = params.width as u64 * params.height as u64;
        let scene = SceneBuffers::upload(backend, scene)?;
        let params_buffer = upload(backend, "render params", &[params])?;
        let accumulation = backend.create_buffer("accumulation", pixels * 16)?;
        backend.write_buffer(accumulation, 0, &vec![0u8; pixels as usize * 16])?;
        Ok(PathTracer { kernel, scene, params, params_buffer, accumulation, samples: 0 })
    }

    /// Samples per pixel so far.
    pub fn samples(&self) -> u32 {
        self.samples
    }

    /// Adds one sample per pixel.
    pub fn add_sample(&mut self, backend: &mut dyn Backend) -> Result<(), PassError> {
        self.add_sample_with(backend, false).map(|_| ())
    }

    /// Adds one sample per pixel and returns the dispatch's device time (timestamp
    /// queries; the wall time of the dispatch where the backend has none).
    pub fn add_sample_timed(&mut self, backend: &mut dyn Backend) -> Result<std::time::Duration, PassError> {
        self.add_sample_with(backend, true)
    }

    fn add_sample_with(&mut self, backend: &mut dyn Backend, timed: bool) -> Result<std::time::Duration, PassError> {
        let params = RenderParams { sample_index: self.samples, ..self.params };
        backend.write_buffer(self.params_buffer, 0, bytemuck::bytes_of(&params))?;
        let mut named = self.scene.named(self.params_buffer);
        named.push(("accumulation", self.accumulation));
        let binds = Bind::named(self.kernel, &named)?;
        let workgroups = [params.width.div_ceil(8), params.height.div_ceil(8), 1];
        let time = if timed && backend.info().timestamps {
            backend.dispatch_timed(self.kernel, &binds, workgroups)?
        } else if timed {
            let started = std::time::Instant::now();
            backend.dispatch(self.kernel, &binds, workgroups)?;
            backend.read_buffer(self.params_buffer)?;
            started.elapsed()
        } else {
            // Untimed, the clock is not read: a web page (wasm32) has none to read.
            backend.dispatch(self.kernel, &binds, workgroups)?;
            std::time::Duration::ZERO
        };
        self.samples += 1;
        Ok(time)
    }

    /// Waits until the device has finished every sample submitted so far.
    pub fn wait(&self, backend: &mut dyn Backend) -> Result<(), PassError> {
        backend.read_buffer(self.params_buffer)?;
        Ok(())
    }

    /// The mean of the samples so far. Samples the kernel dropped (non-finite radiance,
    /// a BVH too deep for the traversal stack) are an error naming the first pixel.
    pub fn image(&self, backend: &mut dyn Backend) -> Result<RgbImage, PassError> {
        let sums: Vec<[f32; 4]> = download(backend, self.accumulation)?;
        if let Some(index) = sums.iter().position(|s| s[3] != 0.0) {
            let dropped: f64 = sums.iter().map(|s| f64::from(s[3])).sum();
            return Err(PassError::Input(format!(
                "{dropped} samples were invalid (non-finite radiance or a traversal stack overflow), the first at \
                 pixel ({}, {})",
                index % self.params.width as usize,
                index / self.params.width as usize
            )));
        }
        let scale = 1.0 / self.samples.max(1) as f32;
        Ok(RgbImage {
            width: self.params.width,
            height: self.params.height,
            pixels: sums.iter().map(|s| [s[0] * scale, s[1] * scale, s[2] * scale]).collect(),
        })
    }

    /// Frees every buffer.
    pub fn destroy(self, backend: &mut dyn Backend) -> Result<(), BackendError> {
        self.scene.destroy(backend)?;
        backend.destroy_buffer(self.params_buffer)?;
        backend.destroy_buffer(self.accumulation)
    }
}

/// How often, at most, [`render`] waits for the device to report progress.
const PROGRESS_EVERY: std::time::Duration = std::time::Duration::from_millis(250);

/// Renders `samples` samples per pixel of `scene`; `progress` is called with the samples
/// the device has finished: after the first (which carries the kernel's compilation, so
/// that estimates can leave it out) and then at most every 250 ms (a submitted
/// dispatch is not a finished one: counting submissions told a fresh machine 9 minutes
/// for a 28-second reference).
pub fn render(
    backend: &mut dyn Backend,
    scene: &GpuScene,
    settings: &RenderSettings,
    samples: u32,
    mut progress: impl FnMut(u32),
) -> Result<RgbImage, PassError> {
    let mut tracer = PathTracer::new(backend, scene, settings)?;
    let result = (|| {
        let mut reported = std::time::Instant::now();
        for i in 0..samples {
            tracer.add_sample(backend)?;
            if i == 0 || i + 1 == samples || reported.elapsed() >= PROGRESS_EVERY {
                tracer.wait(backend)?;
                progress(i + 1);
                reported = std::time::Instant::now();
            }
        }
        tracer.image(backend)
    })();
    tracer.destroy(backend)?;
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A camera looking along `up` is refused for that reason alone: the message named a
    /// valid fov_axis too ("fov_axis `smaller` must be `x` or `smaller`, and ...").
    #[test]
    fn a_camera_that_cannot_make_rays_is_refused_for_the_reason_that_holds() {
        let scene = crate::scene::default_scene();
        let mut settings = RenderSettings::for_scene(&scene, 8, 8, 1);
        settings.camera.fov_axis = "smaller".into();
        settings.camera.origin = [0.0, 5.0, 0.0];
        settings.camera.target = [0.0, 1.0, 0.0];
        settings.camera.up = [0.0, 1.0, 0.0];
        let message = settings.params(&RenderParams::default()).unwrap_err().to_string();
        assert!(message.contains("parallel to `up`") && message.contains("[0.0, 5.0, 0.0]"), "{message}");
        assert!(!message.contains("fov_axis"), "{message}");
        settings.camera.target = [1.0, 1.0, 0.0];
        settings.camera.fov_axis = "diagonal".into();
        let message = settings.params(&RenderParams::default()).unwrap_err().to_string();
        assert!(message.contains("fov_axis `diagonal`: expected `x` or `smaller`"), "{message}");
        assert!(!message.contains("parallel"), "{message}");
    }
}
