//! The live comparison the page runs: the built-in scene rendered by [`METHODS`] from one
//! seed, frame after frame with temporal reuse (the defaults of `strata compare`), each
//! frame scored against a reference image by the paper's RelMSE, raw and, while the
//! denoiser is on, after SVGF.
//!
//! Written once for both of its hosts: the page's WebAssembly module on the browser's
//! WebGPU, and the page's test, which runs it natively on lavapipe from the same seeds
//! and holds the page's ratio to the native run's.

use strata_backends::Backend;
use strata_backends::backend::download;
use strata_render::denoise::{SvgfDenoiser, SvgfSettings};
use strata_render::error_metric::{Metric, false_colour, map_mean};
use strata_render::histogram_pass::PassError;
use strata_render::render::{GpuScene, PathTracer, RenderSettings};
use strata_render::restir::{Method, RestirRenderer, RestirSettings};
use strata_render::rgb_image::{RgbImage, linear_to_srgb8};
use strata_render::scene::{Scene, default_scene};

/// The methods the page shows, left to right: plain per-pixel RIS (no reuse: what Bevy
/// Solari ships), ReSTIR's uniform selection, and the stratified one.
pub const METHODS: [Method; 3] = [Method::Ris, Method::Restir, Method::Strata];

/// Samples per pixel of the reference the page is scored against.
pub const REFERENCE_SAMPLES: u32 = 1024;

/// The reference's seed: apart from every method's seed, so that its noise is
/// independent of theirs.
#[cfg(not(target_arch = "wasm32"))]
const REFERENCE_SEED: u32 = 1_000_000;

/// What the page runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LiveSettings {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// The seed of every method's frames (each method renders the same paths' candidates).
    pub seed: u32,
}

impl Default for LiveSettings {
    /// 64 × 64, seed 1: a frame of the three methods in well under a second on
    /// SwiftShader, Chromium's WebGPU without a GPU.
    fn default() -> Self {
        Self { width: 64, height: 64, seed: 1 }
    }
}

/// The largest width or height the page renders: a page's comparison, not a benchmark
/// (and its byte counts stay far inside a 32-bit `usize`).
pub const MAX_SIZE: u32 = 1024;

impl LiveSettings {
    /// The size is 1 to [`MAX_SIZE`] pixels each way; the error names the value.
    pub fn check(&self) -> Result<(), String> {
        for (name, value) in [("width", self.width), ("height", self.height)] {
            if !(1..=MAX_SIZE).contains(&value) {
                return Err(format!("{name} {value}: the page renders 1 to {MAX_SIZE} pixels"));
            }
        }
        Ok(())
    }

    /// The settings as the page's `page.json` states them.
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::json!({ "width": self.width, "height": self.height, "seed": self.seed })
    }

    fn render(&self, scene: &Scene, seed: u32) -> RenderSettings {
        RenderSettings::for_scene(scene, self.width, self.height, seed)
    }
}

/// The reference image the page is scored against: the path tracer at
/// [`REFERENCE_SAMPLES`] samples per pixel, from a seed of its own. (Rendered where the
/// page is served, not in it.)
#[cfg(not(target_arch = "wasm32"))]
pub fn reference(backend: &mut dyn Backend, settings: &LiveSettings) -> Result<RgbImage, PassError> {
    let scene = default_scene();
    let gpu_scene = GpuScene::build(&scene)?;
    let render = settings.render(&scene, REFERENCE_SEED);
    strata_render::render::render(backend, &gpu_scene, &render, REFERENCE_SAMPLES, |_| {})
}

/// The reference as the page fetches it (`reference.bin`): its pixels' R, G, B as
/// little-endian `f32`, row-major.
pub fn reference_bytes(reference: &RgbImage) -> Vec<u8> {
    reference.pixels.iter().flatten().flat_map(|c| c.to_le_bytes()).collect()
}

/// [`reference_bytes`] read back; the error names what is wrong with them.
pub fn reference_from_bytes(settings: &LiveSettings, bytes: &[u8]) -> Result<RgbImage, String> {
    settings.check()?;
    let pixels = settings.width as usize * settings.height as usize;
    if bytes.len() != pixels * 12 {
        return Err(format!(
            "reference.bin: {} bytes, where a {}x{} image of RGB f32 has {}",
            bytes.len(),
            settings.width,
            settings.height,
            pixels * 12
        ));
    }
    let values: Vec<f32> = bytes.chunks_exact(4).map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect();
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        return Err(format!("reference.bin: value {i} is {}, not a finite number", values[i]));
    }
    let pixels = values.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    Ok(RgbImage { width: settings.width, height: settings.height, pixels })
}

/// The built-in scene and its GPU form, once `settings` and `reference` have been checked
/// (the size in range, the reference that size).
fn scene_for(settings: &LiveSettings, reference: &RgbImage) -> Result<(Scene, GpuScene), PassError> {
    settings.check().map_err(PassError::Input)?;
    if (reference.width, reference.height) != (settings.width, settings.height) {
        return Err(PassError::Input(format!(
            "the reference is {}x{}, the page renders {}x{}",
            reference.width, reference.height, settings.width, settings.height
        )));
    }
    let scene = default_scene();
    let gpu_scene = GpuScene::build(&scene)?;
    Ok((scene, gpu_scene))
}

/// `image` as the page's canvases draw it: 8-bit sRGB RGBA, alpha 255.
fn rgba8(image: &RgbImage) -> impl Iterator<Item = u8> + '_ {
    image.pixels.iter().flat_map(|p| [linear_to_srgb8(p[0]), linear_to_srgb8(p[1]), linear_to_srgb8(p[2]), 255])
}

/// A RelMSE summed over frames, for a running mean and a ratio of sums.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Running {
    sum: f64,
    frames: u32,
}

impl Running {
    fn add(&mut self, value: f64) {
        self.sum += value;
        self.frames += 1;
    }

    fn mean(&self) -> Option<f64> {
        (self.frames > 0).then(|| self.sum / f64::from(self.frames))
    }
}

/// One method's renderer, denoiser and running scores.
struct MethodRun {
    method: Method,
    renderer: RestirRenderer,
    denoiser: Option<SvgfDenoiser>,
    raw: Running,
    denoised: Running,
}

/// One method's frame as the page shows it.
#[derive(Clone, Debug, PartialEq)]
pub struct MethodFrame {
    /// The method.
    pub method: Method,
    /// This frame's RelMSE (raw).
    pub relmse: f64,
    /// The mean RelMSE of every frame so far (raw).
    pub mean_relmse: f64,
    /// This frame's RelMSE after the denoiser, while it is on.
    pub denoised_relmse: Option<f64>,
    /// The mean RelMSE after the denoiser of every frame since it was first turned on.
    pub mean_denoised_relmse: Option<f64>,
    /// The image shown: the denoised one while the denoiser is on, else the raw one.
    pub shown: RgbImage,
    /// The shown image's RelMSE per pixel against the reference, in false colour
    /// ([`strata_render::error_metric::false_colour`]: 1e-4 black to 1 white, log scale).
    pub error_map: RgbImage,
}

/// Everything one frame of the comparison gives.
#[derive(Clone, Debug, PartialEq)]
pub struct LiveFrame {
    /// Frames rendered so far (1 after the first).
    pub frame: u32,
    /// [`METHODS`]' frames, in that order.
    pub methods: Vec<MethodFrame>,
    /// strata's RelMSE summed over every frame so far ÷ restir's (a ratio of sums, as
    /// `strata compare` pools a seed's frames).
    pub strata_over_restir: f64,
    /// The same after the denoiser, over the frames it was on.
    pub denoised_strata_over_restir: Option<f64>,
}

impl LiveFrame {
    /// The frame's scores as the page reads them (no images).
    pub fn to_json(&self) -> serde_json::Value {
        let methods: Vec<serde_json::Value> = self
            .methods
            .iter()
            .map(|m| {
                serde_json::json!({
                    "name": m.method.name(),
                    "relmse": m.relmse,
                    "meanRelmse": m.mean_relmse,
                    "denoisedRelmse": m.denoised_relmse,
                    "meanDenoisedRelmse": m.mean_denoised_relmse,
                })
            })
            .collect();
        serde_json::json!({
            "frame": self.frame,
            "methods": methods,
            "strataOverRestir": self.strata_over_restir,
            "denoisedStrataOverRestir": self.denoised_strata_over_restir,
        })
    }

    /// The shown images, then their error maps, as 8-bit sRGB RGBA (alpha 255), one
    /// after the other in [`METHODS`]' order: what the page's canvases draw.
    pub fn rgba8(&self) -> Vec<u8> {
        let images = self.methods.iter().map(|m| &m.shown);
        images.chain(self.methods.iter().map(|m| &m.error_map)).flat_map(rgba8).collect()
    }
}

/// The running comparison.
pub struct LiveComparison {
    settings: LiveSettings,
    reference: RgbImage,
    runs: Vec<MethodRun>,
    frames: u32,
    /// Whether the denoiser runs on the next frame.
    denoise: bool,
}

impl LiveComparison {
    /// Uploads the scene and creates each method's renderer; `reference` must be the
    /// settings' size.
    pub fn new(backend: &mut dyn Backend, settings: LiveSettings, reference: RgbImage) -> Result<Self, PassError> {
        let (scene, gpu_scene) = scene_for(&settings, &reference)?;
        let render = settings.render(&scene, settings.seed);
        let mut runs = Vec::new();
        for method in METHODS {
            let restir = RestirSettings { method, ..RestirSettings::default() };
            let renderer = RestirRenderer::new(backend, &gpu_scene, &render, restir, scene.extent())?;
            runs.push(MethodRun {
                method,
                renderer,
                denoiser: None,
                raw: Running::default(),
                denoised: Running::default(),
            });
        }
        Ok(Self { settings, reference, runs, frames: 0, denoise: false })
    }

    /// Turns the SVGF denoiser on or off from the next frame. Turned on again, it starts
    /// a new history (the frames it skipped would leave its own stale).
    pub fn set_denoiser(&mut self, backend: &mut dyn Backend, on: bool) -> Result<(), PassError> {
        if on && !self.denoise {
            for run in &mut self.runs {
                match &mut run.denoiser {
                    Some(denoiser) => denoiser.reset(),
                    None => {
                        run.renderer.enable_guides(backend)?;
                        let (width, height) = (self.settings.width, self.settings.height);
                        run.denoiser = Some(SvgfDenoiser::new(backend, width, height, SvgfSettings::default())?);
                    }
                }
            }
        }
        self.denoise = on;
        Ok(())
    }

    /// Renders the next frame of every method and scores it.
    pub fn frame(&mut self, backend: &mut dyn Backend) -> Result<LiveFrame, PassError> {
        self.frames += 1;
        let mut methods = Vec::new();
        for run in &mut self.runs {
            let name = format!("{} frame {}", run.method.name(), self.frames);
            let (image, stats) = run.renderer.render_frame(backend, None)?;
            if stats.invalid_pixels > 0 {
                return Err(PassError::Input(format!("{name}: {} pixels had invalid samples", stats.invalid_pixels)));
            }
            // The image's RelMSE and its per-pixel map (the shown image's is drawn).
            let score = |image: &RgbImage, what: &str| {
                let map = Metric::Relmse.map(image, &self.reference).unwrap_or_default();
                match map_mean(&map) {
                    Some(mean) => Ok((mean, map)),
                    None => Err(PassError::Input(format!(
                        "{name}{what}: no RelMSE (a pixel is not a finite number, or the sizes differ)"
                    ))),
                }
            };
            let (relmse, mut map) = score(&image, "")?;
            run.raw.add(relmse);
            let mut denoised_relmse = None;
            let mut shown = image;
            if self.denoise {
                let (Some(denoiser), Some(inputs)) = (&mut run.denoiser, run.renderer.denoiser_inputs()) else {
                    return Err(PassError::Input(format!("{name}: the denoiser is on but has no guides")));
                };
                let output = denoiser.denoise(backend, inputs.colour, inputs.guides, inputs.previous_guides)?;
                let pixels: Vec<[f32; 4]> = download(backend, output)?;
                let denoised = RgbImage::from_rgba(shown.width, shown.height, &pixels);
                let (value, denoised_map) = score(&denoised, ", denoised")?;
                run.denoised.add(value);
                denoised_relmse = Some(value);
                shown = denoised;
                map = denoised_map;
            }
            let error_map = false_colour(&map, shown.width, shown.height);
            methods.push(MethodFrame {
                method: run.method,
                relmse,
                mean_relmse: run.raw.mean().unwrap_or(relmse),
                denoised_relmse,
                mean_denoised_relmse: run.denoised.mean(),
                shown,
                error_map,
            });
        }
        let sums = |pick: fn(&MethodRun) -> Running| {
            let of = |method| self.runs.iter().find(|r| r.method == method).map(pick).unwrap_or_default();
            let (strata, restir) = (of(Method::Strata), of(Method::Restir));
            (restir.frames > 0 && restir.sum > 0.0).then(|| strata.sum / restir.sum)
        };
        let strata_over_restir = sums(|r| r.raw)
            .ok_or_else(|| PassError::Input("restir's RelMSE is 0: the ratio cannot be computed".into()))?;
        Ok(LiveFrame {
            frame: self.frames,
            methods,
            strata_over_restir,
            denoised_strata_over_restir: sums(|r| r.denoised),
        })
    }

    /// Frees every buffer.
    pub fn destroy(self, backend: &mut dyn Backend) -> Result<(), PassError> {
        for run in self.runs {
            run.renderer.destroy(backend)?;
            if let Some(denoiser) = run.denoiser {
                denoiser.destroy(backend)?;
            }
        }
        Ok(())
    }
}

/// What the page shows where the device cannot run the ReSTIR kernels (a browser's WebGPU
/// allows fewer storage buffers per shader stage than they bind: docs/web.md): the path
/// tracer converging, one sample per pixel a frame, scored against the same reference.
/// It runs the page's whole route (the scene's upload, dispatches, read-backs) on the
/// browser's device, and says plainly that ReSTIR is not what is shown.
pub struct LivePathTracer {
    tracer: PathTracer,
    reference: RgbImage,
}

/// One frame of [`LivePathTracer`].
#[derive(Clone, Debug, PartialEq)]
pub struct PathTracerFrame {
    /// Samples per pixel so far (one a frame).
    pub samples: u32,
    /// The RelMSE of their mean against the reference.
    pub relmse: f64,
    /// Their mean.
    pub image: RgbImage,
}

impl PathTracerFrame {
    /// The frame's score as the page reads it (no image).
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::json!({ "frame": self.samples, "pathTracer": { "samples": self.samples, "relmse": self.relmse } })
    }

    /// The image as 8-bit sRGB RGBA (alpha 255).
    pub fn rgba8(&self) -> Vec<u8> {
        rgba8(&self.image).collect()
    }
}

impl LivePathTracer {
    /// Uploads the scene for the path tracer at the settings' size and seed; `reference`
    /// must be that size.
    pub fn new(backend: &mut dyn Backend, settings: LiveSettings, reference: RgbImage) -> Result<Self, PassError> {
        let (scene, gpu_scene) = scene_for(&settings, &reference)?;
        let tracer = PathTracer::new(backend, &gpu_scene, &settings.render(&scene, settings.seed))?;
        Ok(Self { tracer, reference })
    }

    /// Adds one sample per pixel and scores the mean so far.
    pub fn frame(&mut self, backend: &mut dyn Backend) -> Result<PathTracerFrame, PassError> {
        self.tracer.add_sample(backend)?;
        let image = self.tracer.image(backend)?;
        let samples = self.tracer.samples();
        let relmse = Metric::Relmse.mean(&image, &self.reference).ok_or_else(|| {
            PassError::Input(format!("the path tracer at {samples} samples: no RelMSE (a pixel is not finite)"))
        })?;
        Ok(PathTracerFrame { samples, relmse, image })
    }

    /// Frees every buffer.
    pub fn destroy(self, backend: &mut dyn Backend) -> Result<(), PassError> {
        Ok(self.tracer.destroy(backend)?)
    }
}
