//! One ReSTIR frame after another on any backend: the scene uploaded once, per-frame
//! buffers (two G-buffers and two reservoir buffers alternate for temporal reuse), and
//! the five passes dispatched in order (seven in the temporal-first order:
//! [`ReuseOrder::TemporalFirst`]). A frame without a temporal merge (no temporal reuse,
//! or the first frame) skips `restir_temporal_keys` and `restir_temporal`: the selection
//! is written where the merge would have copied it.

use super::{RestirSettings, ReuseOrder};
use crate::histogram_pass::{BlockHistogramPass, HistogramVariant, PassError};
use crate::render::{GpuScene, RenderSettings, SceneBuffers};
use crate::rgb_image::RgbImage;
use crate::scene::{Camera, CameraFrame};
use strata_backends::backend::{download, upload};
use strata_backends::{Backend, BackendError, Bind, BufferId};
use strata_kernels::blue_noise::BlueNoiseTables;
use strata_kernels::denoise_types::DenoiseGuide;
use strata_kernels::render_types::{FLAG_HIT_LIGHTS, FLAG_SAMPLE_LIGHTS, RenderParams};
use strata_kernels::restir_types::{PathCandidate, Primary, Reservoir, RestirParams};
use strata_kernels::types::Candidate;
use strata_kernels::{BlockGrid, Kernel, KernelId, Registry, Specialisation};

/// What one frame did besides its image.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameStats {
    /// Pixels whose sample was dropped as invalid (non-finite, traversal overflow).
    pub invalid_pixels: u32,
    /// Device time of each pass (candidates, histogram, select, temporal (sources,
    /// temporal histogram and merge), shade; in the temporal-first order the histogram
    /// includes its keys' pass and select the spatial reuse after the merge) from
    /// timestamp queries, when [`RestirRenderer::set_timed`] is on and the backend has
    /// them; zero otherwise (and for the histogram of restir-disc, which skips it, and for
    /// the temporal entry of a frame without a temporal merge, which skips its passes).
    pub pass_times: [std::time::Duration; 5],
}

/// The last frame's per-pixel buffers, as the kernels wrote them.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameBuffers {
    /// `restir_candidates`: the G-buffer.
    pub primaries: Vec<Primary>,
    /// `restir_candidates`: each pixel's candidate.
    pub candidates: Vec<PathCandidate>,
    /// `restir_candidates`: the histogram's input.
    pub histogram_candidates: Vec<Candidate>,
    /// `restir_candidates`: what each pixel estimates alone (rgb, invalid flag).
    pub base_radiance: Vec<[f32; 4]>,
    /// `restir_select`: the reservoirs after selection (in the temporal-first order each
    /// pixel's canonical candidate as a reservoir).
    pub selected: Vec<Reservoir>,
    /// `restir_temporal_keys`: the temporal histogram's input.
    pub temporal_keys: Vec<Candidate>,
    /// `restir_temporal_keys`: each pixel's temporal source pixel.
    pub temporal_sources: Vec<u32>,
    /// The final reservoirs: `restir_temporal`'s (`restir_spatial`'s in the temporal-first
    /// order; `restir_select`'s in a spatial-first frame without a temporal merge).
    pub reservoirs: Vec<Reservoir>,
    /// `restir_shade`: the frame (rgb, invalid flag).
    pub image: Vec<[f32; 4]>,
}

/// The ReSTIR renderer of one scene, image size and settings.
pub struct RestirRenderer {
    kernels: [&'static Kernel; 5],
    /// What its kernels are specialised for ([`specialisation_for`]).
    specialisation: Specialisation,
    settings: RestirSettings,
    render: RenderSettings,
    params: RenderParams,
    scene: SceneBuffers,
    histogram: BlockHistogramPass,
    /// The histogram of the temporal candidates (T > 0 with a histogram method).
    temporal_histogram: Option<BlockHistogramPass>,
    /// Per pixel its temporal source pixel (`restir_temporal_keys`).
    temporal_sources: BufferId,
    /// The temporal keys when there is no temporal histogram to hold them (T = 0).
    temporal_keys: BufferId,
    /// Heitz et al.'s tables packed in one buffer (`strata/blue_noise.wgsl`), from which
    /// the selection kernels draw their numbers (§4.2).
    blue_noise: BufferId,
    render_params: BufferId,
    restir_params: BufferId,
    primaries: [BufferId; 2],
    candidates: BufferId,
    base_radiance: BufferId,
    selected: BufferId,
    reservoirs: [BufferId; 2],
    frame_out: BufferId,
    /// Frames rendered; the next frame's index.
    frame: u32,
    previous_camera: Option<CameraFrame>,
    min_distance: f32,
    timed: bool,
    /// With a denoiser ([`RestirRenderer::enable_guides`]): `restir_guide`, this
    /// frame's and the previous frame's guides (alternating like the G-buffers), and the
    /// first frame that wrote one.
    guides: Option<(&'static Kernel, [BufferId; 2], u32)>,
    /// Warm-up only ([`RestirRenderer::dispatch_only`]): the kernels frames dispatch.
    dispatch_only: Option<Vec<KernelId>>,
    /// The temporal-first order's passes and buffers ([`ReuseOrder::TemporalFirst`]).
    temporal_first: Option<TemporalFirst>,
}

/// What the temporal-first order adds: `restir_select` runs with K = 0 (each pixel's
/// canonical candidate alone, from its own uniform), `restir_temporal` merges the history
/// into it (from the second frame; the first frame's selection is written to `merged`
/// directly), `restir_reservoir_keys` gives the histogram the merged reservoirs' estimates
/// and `restir_spatial` reuses K of them into the final reservoirs.
struct TemporalFirst {
    keys_kernel: &'static Kernel,
    spatial_kernel: &'static Kernel,
    /// `RestirParams` with K = 0, for the canonical pass.
    canonical_params: BufferId,
    /// The temporal merge's output (the selection's in the first frame), the spatial pass's
    /// input.
    merged: BufferId,
}

/// What a denoiser reads of the last frame ([`RestirRenderer::denoiser_inputs`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DenoiserInputs {
    /// The frame's colour (`vec4<f32>` per pixel: rgb, invalid flag).
    pub colour: BufferId,
    /// Its `DenoiseGuide`s.
    pub guides: BufferId,
    /// The previous frame's `DenoiseGuide`s (this frame's on the first frame).
    pub previous_guides: BufferId,
}

/// What the renderer's kernels are specialised for ([`Registry::specialised`]): random
/// replay only with `glossy_replay`, the scene's rows from their uniform copy where they
/// fit it.
fn specialisation_for(glossy_replay: bool, scene: &GpuScene) -> Specialisation {
    Specialisation { random_replay: glossy_replay, scene_in_uniform: scene.fits_uniform_copy() }
}

impl RestirRenderer {
    /// Uploads the scene and creates every buffer; `render` gives the camera (its image
    /// size), seed, depths and Russian roulette (light sampling is always MIS). The
    /// renderer is not told whether its camera will move: [`ReuseOrder::Auto`] runs the
    /// still camera's order, so a caller whose camera moves resolves it first
    /// ([`RestirSettings::for_camera`], as `strata compare` does).
    pub fn new(
        backend: &mut dyn Backend,
        scene: &GpuScene,
        render: &RenderSettings,
        settings: RestirSettings,
        scene_extent: f32,
    ) -> Result<Self, PassError> {
        settings.check()?;
        let settings = settings.as_run().for_camera(false);
        let registry = Registry::shared()?;
        // Without random replay no pixel replays, and the kernels that weigh candidates
        // (select, spatial, temporal, shade) are specialised without the replayed path's
        // re-trace (`random_replay` in restir/reservoir.wgsl; the other passes never reach
        // it and are their general selves): the same outputs, and on a CPU driver that runs
        // every branch under a mask (lavapipe) those passes take 30-45 % less time. A scene
        // that fits the rows' uniform copy is read from there (`scene_in_uniform` in
        // render/scene.wgsl): the same outputs, a frame 10-20 % faster on lavapipe.
        let specialisation = specialisation_for(settings.glossy_replay, scene);
        let kernel = |id| -> Result<&'static Kernel, PassError> { Ok(registry.specialised(id, specialisation)?) };
        let kernels = [
            kernel(KernelId::RestirCandidates)?,
            kernel(KernelId::RestirSelect)?,
            kernel(KernelId::RestirTemporalKeys)?,
            kernel(KernelId::RestirTemporal)?,
            kernel(KernelId::RestirShade)?,
        ];
        for kernel in kernels {
            backend.check_kernel(kernel)?;
        }
        let camera = &render.camera;
        if camera.width == 0 || camera.height == 0 {
            return Err(PassError::Input(format!(
                "image size {}x{}: must be at least 1x1",
                camera.width, camera.height
            )));
        }
        let selection = settings.selection;
        let grid = BlockGrid::new(camera.width, camera.height, selection.block_size)?;
        let histogram = BlockHistogramPass::with_masking(backend, HistogramVariant::Auto, grid, selection.masking)?;
        let temporal_histogram = if settings.temporal_candidates > 0 && settings.method.uses_histogram() {
            Some(BlockHistogramPass::with_masking(backend, HistogramVariant::Auto, grid, selection.masking)?)
        } else {
            None
        };
        let pixels = u64::from(camera.width) * u64::from(camera.height);
        // Without temporal reuse the two orders resample the same samples with the same
        // weights (each merged reservoir is its canonical candidate, M = 1): the
        // paper's passes do it with two passes fewer.
        let temporal_first = match settings.reuse_order {
            ReuseOrder::TemporalFirst if settings.temporal => {
                let [keys_kernel, spatial_kernel] =
                    [kernel(KernelId::RestirReservoirKeys)?, kernel(KernelId::RestirSpatial)?];
                backend.check_kernel(keys_kernel)?;
                backend.check_kernel(spatial_kernel)?;
                Some(TemporalFirst {
                    keys_kernel,
                    spatial_kernel,
                    canonical_params: upload(backend, "canonical restir params", &[RestirParams::default()])?,
                    merged: backend.create_buffer("merged reservoirs", pixels * size_of::<Reservoir>() as u64)?,
                })
            }
            ReuseOrder::TemporalFirst | ReuseOrder::SpatialFirst => None,
            ReuseOrder::Auto => unreachable!("resolved by for_camera above"),
        };
        let scene_buffers = SceneBuffers::upload(backend, scene)?;
        let mut params = render.params(&scene.params)?;
        // ReSTIR always combines light sampling and BSDF hits (its candidates' RIS needs
        // both); every other flag is the render settings' own.
        params.flags |= FLAG_SAMPLE_LIGHTS | FLAG_HIT_LIGHTS;
        let buffer = |backend: &mut dyn Backend, name: &str, bytes: u64| backend.create_buffer(name, bytes);
        let primary_size = pixels * size_of::<Primary>() as u64;
        let reservoir_size = pixels * size_of::<Reservoir>() as u64;
        let renderer = RestirRenderer {
            kernels,
            specialisation,
            settings,
            render: render.clone(),
            params,
            scene: scene_buffers,
            histogram,
            temporal_histogram,
            temporal_sources: buffer(backend, "temporal sources", pixels * 4)?,
            temporal_keys: buffer(backend, "temporal keys", pixels * size_of::<Candidate>() as u64)?,
            blue_noise: upload(backend, "blue noise", &BlueNoiseTables::new().packed())?,
            render_params: upload(backend, "render params", &[params])?,
            restir_params: upload(backend, "restir params", &[RestirParams::default()])?,
            primaries: [
                buffer(backend, "primary hits A", primary_size)?,
                buffer(backend, "primary hits B", primary_size)?,
            ],
            candidates: buffer(backend, "path candidates", pixels * size_of::<PathCandidate>() as u64)?,
            base_radiance: buffer(backend, "base radiance", pixels * 16)?,
            selected: buffer(backend, "selected reservoirs", reservoir_size)?,
            reservoirs: [
                buffer(backend, "reservoirs A", reservoir_size)?,
                buffer(backend, "reservoirs B", reservoir_size)?,
            ],
            frame_out: buffer(backend, "frame", pixels * 16)?,
            frame: 0,
            previous_camera: None,
            min_distance: if settings.min_distance > 0.0 { settings.min_distance } else { 1e-3 * scene_extent },
            timed: false,
            guides: None,
            dispatch_only: None,
            temporal_first,
        };
        Ok(renderer)
    }

    /// For warming up a CPU driver that compiles each kernel at its first dispatch (and
    /// lavapipe compiles it for the uniform values it then sees, inlining some): from
    /// now on frames dispatch only `kernels` (every pass again with `None`), so that
    /// threads with a device each can compile the kernels side by side on small
    /// renderers with the run's own settings. Frames rendered so are not images: drop
    /// the renderer after.
    pub fn dispatch_only(&mut self, kernels: Option<Vec<KernelId>>) {
        self.dispatch_only = kernels;
    }

    /// Time every pass with timestamp queries (each dispatch then waits for the device).
    pub fn set_timed(&mut self, timed: bool) {
        self.timed = timed;
    }

    /// From the next frame on, also write a denoiser's guide (pass 6, `restir_guide`):
    /// see [`RestirRenderer::denoiser_inputs`].
    pub fn enable_guides(&mut self, backend: &mut dyn Backend) -> Result<(), PassError> {
        if self.guides.is_some() {
            return Ok(());
        }
        let kernel = Registry::shared()?.specialised(KernelId::RestirGuide, self.specialisation)?;
        backend.check_kernel(kernel)?;
        let (width, height) = (self.render.camera.width, self.render.camera.height);
        let bytes = u64::from(width) * u64::from(height) * size_of::<DenoiseGuide>() as u64;
        let buffers = [backend.create_buffer("guides A", bytes)?, backend.create_buffer("guides B", bytes)?];
        self.guides = Some((kernel, buffers, self.frame));
        Ok(())
    }

    /// The last frame's colour and guides, for a denoiser; `None` before
    /// [`RestirRenderer::enable_guides`] or before a frame with guides.
    pub fn denoiser_inputs(&self) -> Option<DenoiserInputs> {
        let (_, guides, first) = self.guides?;
        if self.frame <= first {
            return None;
        }
        let last = ((self.frame + 1) % 2) as usize;
        // On the first frame with a guide there is no earlier one: its own stands in.
        let previous = if self.frame == first + 1 { last } else { 1 - last };
        Some(DenoiserInputs { colour: self.frame_out, guides: guides[last], previous_guides: guides[previous] })
    }

    /// Frames rendered so far.
    pub fn frames(&self) -> u32 {
        self.frame
    }

    /// Renders the next frame seen from `camera` (same image size as at creation; `None`:
    /// the creation camera) and returns its image.
    pub fn render_frame(
        &mut self,
        backend: &mut dyn Backend,
        camera: Option<&Camera>,
    ) -> Result<(RgbImage, FrameStats), PassError> {
        let camera = camera.unwrap_or(&self.render.camera).clone();
        if (camera.width, camera.height) != (self.render.camera.width, self.render.camera.height) {
            return Err(PassError::Input(format!(
                "camera image size {}x{} differs from the renderer's {}x{}",
                camera.width, camera.height, self.render.camera.width, self.render.camera.height
            )));
        }
        let render = RenderSettings { camera: camera.clone(), ..self.render.clone() };
        let frame_camera = CameraFrame::checked(&camera).map_err(|why| {
            PassError::Input(format!(
                "frame {} (counted from 0): camera (origin {:?}, target {:?}): {why}",
                self.frame, camera.origin, camera.target
            ))
        })?;
        let selection = self.settings.selection;
        if selection.block_shift && self.settings.method.uses_histogram() {
            self.histogram.set_frame(backend, &selection, self.frame, self.render.seed)?;
            if let Some(temporal) = &mut self.temporal_histogram {
                temporal.set_frame(backend, &selection, self.frame, self.render.seed)?;
            }
        }
        let params =
            RenderParams { sample_index: self.frame, flags: self.params.flags, ..render.params(&self.params)? };
        backend.write_buffer(self.render_params, 0, bytemuck::bytes_of(&params))?;
        let previous = self.previous_camera.unwrap_or(frame_camera);
        let restir = RestirParams {
            temporal: u32::from(self.settings.temporal && self.frame > 0),
            min_distance: self.min_distance,
            previous_origin: previous.origin.into(),
            previous_tan_half_x: previous.tan_half_x,
            previous_forward: previous.forward.into(),
            previous_tan_half_y: previous.tan_half_y,
            previous_right: previous.right.into(),
            previous_up: previous.up.into(),
            ..self.settings.uniform()
        };
        backend.write_buffer(self.restir_params, 0, bytemuck::bytes_of(&restir))?;
        if let Some(first) = &self.temporal_first {
            let canonical = RestirParams { candidates: 0, ..restir };
            backend.write_buffer(first.canonical_params, 0, bytemuck::bytes_of(&canonical))?;
        }
        let (width, height) = (camera.width, camera.height);

        let current = (self.frame % 2) as usize;
        let previous_index = 1 - current;
        // The scene, the settings and the pass's own buffers by their WGSL names, restricted
        // to what `kernel` uses (naga drops bindings an entry point never reaches).
        let with_restir = |kernel: &Kernel, restir: BufferId, extra: &[(&str, BufferId)]| {
            let mut named = self.scene.named(self.render_params);
            named.push(("restir", restir));
            named.extend_from_slice(extra);
            Bind::named(kernel, &named).map_err(PassError::from)
        };
        let with = |kernel: &Kernel, extra: &[(&str, BufferId)]| with_restir(kernel, self.restir_params, extra);
        // The temporal-first order: select writes the canonical reservoirs (K = 0), the
        // merge its own buffer, and the histogram waits for the merged reservoirs' keys.
        let first = self.temporal_first.as_ref();
        let select_restir = first.map_or(self.restir_params, |f| f.canonical_params);
        let merged_out = self.merge_output(current);
        // A frame without a temporal merge (no temporal reuse, or the first frame) would
        // have restir_temporal copy each selected reservoir unchanged (RestirParams.temporal
        // = 0 merges nothing and skips the boiling filter), so select writes where the
        // merge would and the merge is not dispatched: on lavapipe a dispatch costs about
        // half a millisecond whatever it does, 5-7 % of a 32 x 32 frame without temporal
        // reuse (docs/benchmarks/ci-time.md, "Where a 32 × 32 ReSTIR frame's CPU goes").
        let temporal_on = self.merges(self.frame);
        let selected_out = if temporal_on { self.selected } else { merged_out };
        let [candidates_kernel, select_kernel, keys_kernel, temporal_kernel, shade_kernel] = self.kernels;
        let timed = self.timed && backend.info().timestamps;
        let mut pass_times = [std::time::Duration::ZERO; 5];
        let only = self.dispatch_only.as_deref();
        let wanted = |kernel: &Kernel| only.is_none_or(|ids| ids.contains(&kernel.id));
        let run =
            |backend: &mut dyn Backend, kernel: &Kernel, binds: &[Bind]| -> Result<std::time::Duration, PassError> {
                if !wanted(kernel) {
                    return Ok(std::time::Duration::ZERO);
                }
                let [group_x, group_y, _] = kernel.workgroup_size;
                let groups = [width.div_ceil(group_x), height.div_ceil(group_y), 1];
                if timed {
                    return Ok(backend.dispatch_timed(kernel, binds, groups)?);
                }
                backend.dispatch(kernel, binds, groups)?;
                Ok(std::time::Duration::ZERO)
            };
        pass_times[0] = run(
            backend,
            candidates_kernel,
            &with(
                candidates_kernel,
                &[
                    ("primary_out", self.primaries[current]),
                    ("candidates_out", self.candidates),
                    ("histogram_in", self.histogram.candidates),
                    ("base_radiance", self.base_radiance),
                ],
            )?,
        )?;
        let histogram = |backend: &mut dyn Backend| -> Result<std::time::Duration, PassError> {
            if !self.settings.method.uses_histogram() || !wanted(self.histogram.kernel()) {
                return Ok(std::time::Duration::ZERO);
            }
            if timed {
                return self.histogram.dispatch_timed(backend);
            }
            self.histogram.dispatch(backend)?;
            Ok(std::time::Duration::ZERO)
        };
        if first.is_none() {
            pass_times[1] = histogram(backend)?;
        }
        pass_times[2] = run(
            backend,
            select_kernel,
            &with_restir(
                select_kernel,
                select_restir,
                &[
                    ("primaries", self.primaries[current]),
                    ("path_candidates", self.candidates),
                    ("sorted_pixels", self.histogram.sorted_pixels),
                    ("spans", self.histogram.spans),
                    ("reservoirs_out", selected_out),
                    ("blue_noise", self.blue_noise),
                ],
            )?,
        )?;
        // Temporal sources, with T > 0 their histogram (the spatial histogram's runs stand
        // in for it when unused: the merge reads them only with T > 0), then the merge.
        if temporal_on {
            pass_times[3] = run(
                backend,
                keys_kernel,
                &with(
                    keys_kernel,
                    &[
                        ("primaries", self.primaries[current]),
                        ("previous_primaries", self.primaries[previous_index]),
                        ("previous_reservoirs", self.reservoirs[previous_index]),
                        ("temporal_keys", self.temporal_keys_buffer()),
                        ("temporal_sources", self.temporal_sources),
                    ],
                )?,
            )?;
            if let Some(temporal) = self.temporal_histogram.as_ref().filter(|t| wanted(t.kernel())) {
                pass_times[3] += if timed {
                    temporal.dispatch_timed(backend)?
                } else {
                    temporal.dispatch(backend)?;
                    std::time::Duration::ZERO
                };
            }
            let temporal_runs = self.temporal_histogram.as_ref().unwrap_or(&self.histogram);
            pass_times[3] += run(
                backend,
                temporal_kernel,
                &with(
                    temporal_kernel,
                    &[
                        ("primaries", self.primaries[current]),
                        ("previous_primaries", self.primaries[previous_index]),
                        ("current_reservoirs", self.selected),
                        ("previous_reservoirs", self.reservoirs[previous_index]),
                        ("merged_reservoirs", merged_out),
                        ("temporal_sorted_pixels", temporal_runs.sorted_pixels),
                        ("temporal_spans", temporal_runs.spans),
                        ("temporal_sources", self.temporal_sources),
                        ("blue_noise", self.blue_noise),
                    ],
                )?,
            )?;
        }
        if let Some(first) = first {
            if self.settings.method.uses_histogram() {
                pass_times[1] = run(
                    backend,
                    first.keys_kernel,
                    &with(
                        first.keys_kernel,
                        &[
                            ("primaries", self.primaries[current]),
                            ("merged_reservoirs", first.merged),
                            ("histogram_in", self.histogram.candidates),
                        ],
                    )?,
                )?;
                pass_times[1] += histogram(backend)?;
            }
            pass_times[2] += run(
                backend,
                first.spatial_kernel,
                &with(
                    first.spatial_kernel,
                    &[
                        ("primaries", self.primaries[current]),
                        ("reservoirs_in", first.merged),
                        ("sorted_pixels", self.histogram.sorted_pixels),
                        ("spans", self.histogram.spans),
                        ("reservoirs_out", self.reservoirs[current]),
                        ("blue_noise", self.blue_noise),
                    ],
                )?,
            )?;
        }
        pass_times[4] = run(
            backend,
            shade_kernel,
            &with(
                shade_kernel,
                &[
                    ("primaries", self.primaries[current]),
                    ("reservoirs", self.reservoirs[current]),
                    ("base_in", self.base_radiance),
                    ("frame_out", self.frame_out),
                ],
            )?,
        )?;
        if let Some((guide_kernel, guides, _)) = self.guides {
            run(
                backend,
                guide_kernel,
                &with(guide_kernel, &[("primaries", self.primaries[current]), ("guides_out", guides[current])])?,
            )?;
        }
        let pixels: Vec<[f32; 4]> = download(backend, self.frame_out)?;
        self.frame += 1;
        self.previous_camera = Some(frame_camera);
        let invalid_pixels = pixels.iter().filter(|p| p[3] != 0.0).count() as u32;
        let image = RgbImage::from_rgba(width, height, &pixels);
        Ok((image, FrameStats { invalid_pixels, pass_times }))
    }

    /// The final reservoirs of the last frame, one per pixel.
    pub fn reservoirs(&self, backend: &mut dyn Backend) -> Result<Vec<Reservoir>, PassError> {
        let last = ((self.frame + 1) % 2) as usize;
        Ok(download(backend, self.reservoirs[last])?)
    }

    /// Every per-pixel buffer of the last frame, read back (tests and the cross-backend
    /// check).
    pub fn frame_buffers(&self, backend: &mut dyn Backend) -> Result<FrameBuffers, PassError> {
        let last = ((self.frame + 1) % 2) as usize;
        Ok(FrameBuffers {
            primaries: download(backend, self.primaries[last])?,
            candidates: download(backend, self.candidates)?,
            histogram_candidates: download(backend, self.histogram.candidates)?,
            base_radiance: download(backend, self.base_radiance)?,
            selected: download(backend, self.selected_buffer(last))?,
            temporal_keys: download(backend, self.temporal_keys_buffer())?,
            temporal_sources: download(backend, self.temporal_sources)?,
            reservoirs: download(backend, self.reservoirs[last])?,
            image: download(backend, self.frame_out)?,
        })
    }

    /// Where `restir_select` wrote in the last frame, whose reservoirs are
    /// `reservoirs[last]`: its own buffer, which the temporal merge read, or in a frame
    /// without a merge where the merge would have written (see `render_frame`).
    fn selected_buffer(&self, last: usize) -> BufferId {
        let merged = self.frame.checked_sub(1).is_some_and(|frame| self.merges(frame));
        if merged { self.selected } else { self.merge_output(last) }
    }

    /// Where the temporal merge writes in a frame whose reservoirs are
    /// `reservoirs[current]`: those, or the temporal-first order's `merged`, which
    /// `restir_spatial` then reuses.
    fn merge_output(&self, current: usize) -> BufferId {
        self.temporal_first.as_ref().map_or(self.reservoirs[current], |first| first.merged)
    }

    /// Whether frame `frame` (counted from 0) merges the history: temporal reuse on, and a
    /// previous frame to merge.
    fn merges(&self, frame: u32) -> bool {
        self.settings.temporal && frame > 0
    }

    /// Where `restir_temporal_keys` writes: the temporal histogram's input, or a buffer
    /// of its own without one.
    fn temporal_keys_buffer(&self) -> BufferId {
        self.temporal_histogram.as_ref().map_or(self.temporal_keys, |histogram| histogram.candidates)
    }

    /// The histogram candidates of the last frame (key and object id per pixel).
    pub fn histogram_candidates(&self, backend: &mut dyn Backend) -> Result<Vec<Candidate>, PassError> {
        Ok(download(backend, self.histogram.candidates)?)
    }

    /// Frees every buffer.
    pub fn destroy(self, backend: &mut dyn Backend) -> Result<(), PassError> {
        self.scene.destroy(backend)?;
        self.histogram.destroy(backend)?;
        if let Some(temporal) = self.temporal_histogram {
            temporal.destroy(backend)?;
        }
        let buffers = [
            self.temporal_sources,
            self.temporal_keys,
            self.render_params,
            self.restir_params,
            self.primaries[0],
            self.primaries[1],
            self.candidates,
            self.base_radiance,
            self.selected,
            self.reservoirs[0],
            self.reservoirs[1],
            self.blue_noise,
            self.frame_out,
        ];
        let guides = self.guides.map(|(_, guides, _)| guides).into_iter().flatten();
        let temporal_first = self.temporal_first.map(|f| [f.canonical_params, f.merged]).into_iter().flatten();
        buffers
            .into_iter()
            .chain(guides)
            .chain(temporal_first)
            .try_for_each(|b| backend.destroy_buffer(b))
            .map_err(|e: BackendError| e.into())
    }
}
