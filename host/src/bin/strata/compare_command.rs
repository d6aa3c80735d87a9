//! `strata compare`: its arguments, the run of every method and seed against the
//! reference, and the printed summary (ratios with intervals, ratios over frames,
//! variance over seeds).

use anyhow::{Context, Result, bail};
use std::path::PathBuf;
use strata::backend_choice::{BackendChoice, open_backend};
use strata::evaluation::compare::Comparison;
use strata::evaluation::report::{ReportOptions, run_and_report};
use strata::render::{GpuScene, RenderSettings};
use strata::restir::{Method, RestirSettings, ShadedParts};
use strata::rgb_image::RgbImage;
use strata::scene::parse_camera_path;
use strata_kernels::selection::SelectionSettings;

use super::{scene_and_settings, scene_stem};

#[derive(clap::Args)]
pub(crate) struct CompareArgs {
    /// Scene file; the built-in default scene when left out.
    scene: Option<PathBuf>,
    /// Frames per seed.
    #[arg(long, default_value_t = 32)]
    frames: u32,
    /// Methods, comma-separated.
    #[arg(long, value_enum, value_delimiter = ',', default_values_t = [Method::Restir, Method::RestirDisc, Method::Strata])]
    methods: Vec<Method>,
    /// Independent renders (seeds 1..=N) per method.
    #[arg(long, default_value_t = 8)]
    seeds: u32,
    /// Output folder.
    #[arg(long, default_value = "out/compare")]
    out: PathBuf,
    /// Reference image (linear EXR of the same size); rendered by the path tracer when
    /// left out.
    #[arg(long)]
    reference: Option<PathBuf>,
    /// Samples per pixel of the rendered reference.
    #[arg(long, default_value_t = 1024)]
    reference_spp: u32,
    /// Image width (default: the scene camera's).
    #[arg(long)]
    width: Option<u32>,
    /// Image height (default: the scene camera's).
    #[arg(long)]
    height: Option<u32>,
    /// The histogram and the selection (§4.1-4.3), shared by every method except where
    /// a field says otherwise.
    #[command(flatten)]
    selection: SelectionSettings,
    /// No temporal reuse: frames are accumulated instead (Fig. 5 / 10).
    #[arg(long)]
    accumulate: bool,
    /// Previous reservoirs drawn per pixel like spatial candidates (the paper's Fig. 11),
    /// 0 to 4, merged besides the pixel's own reprojected one.
    #[arg(long, default_value_t = 0)]
    temporal_candidates: u32,
    /// Camera rays through pixel centres, no film jitter, for the methods and the
    /// rendered reference alike (a diagnostic: without jitter a pixel's history sees the
    /// same primary hit every frame).
    #[arg(long)]
    pixel_centres: bool,
    /// Which parts of each pixel's estimate the frames show (a diagnostic: `base` is what
    /// no selection touches, `resampled` the reservoir's sample; read their variance over
    /// seeds, since each part alone is biased against the reference).
    #[arg(long, value_enum, default_value_t = ShadedParts::All)]
    shaded_parts: ShadedParts,
    /// A conductor at the primary hit resamples only from this GGX alpha up; smoother
    /// ones path-trace on their own (1 sample per frame, no reuse).
    #[arg(long, default_value_t = RestirSettings::default().min_roughness)]
    min_roughness: f32,
    /// No reconnection to a vertex closer than this (scene units) to a primary hit;
    /// 0: 1e-3 of the scene's extent.
    #[arg(long, default_value_t = RestirSettings::default().min_distance)]
    min_distance: f32,
    /// Camera motion: `static`, `orbit:DEGREES_PER_FRAME`, `dolly:DISTANCE_PER_FRAME` or
    /// a keyframe JSON file. A moving camera needs a reference per frame: they are
    /// path-traced (`--reference-spp` each) and `--reference` is refused.
    #[arg(long, default_value = "static")]
    camera_path: String,
    /// Exposure of the PNG previews.
    #[arg(long, default_value_t = 1.0)]
    exposure: f32,
    /// Backend to run on.
    #[arg(long, value_enum, default_value_t = BackendChoice::Auto)]
    backend: BackendChoice,
}

pub(crate) fn compare(args: CompareArgs) -> Result<()> {
    let (scene, render) = scene_and_settings(&args.scene, args.width, args.height)?;
    let render = RenderSettings { pixel_centres: args.pixel_centres, ..render };
    if args.frames == 0 || args.seeds == 0 {
        bail!("--frames and --seeds must be at least 1");
    }
    let restir = RestirSettings {
        selection: args.selection,
        temporal: !args.accumulate,
        temporal_candidates: args.temporal_candidates,
        shaded_parts: args.shaded_parts,
        min_roughness: args.min_roughness,
        min_distance: args.min_distance,
        ..RestirSettings::default()
    };
    // Refused settings are said before the reference takes its minutes.
    restir.check()?;
    let gpu_scene = GpuScene::build(&scene)?;
    let mut backend = open_backend(args.backend)?;
    println!("backend: {}", backend.info().summary());
    std::fs::create_dir_all(&args.out).with_context(|| format!("{}: cannot create the folder", args.out.display()))?;
    let camera_path = parse_camera_path(&args.camera_path, &render.camera)?;
    let cameras: Vec<_> = if camera_path.is_static() {
        Vec::new()
    } else {
        (0..args.frames).map(|f| camera_path.camera_at(&render.camera, f)).collect()
    };
    if !cameras.is_empty() && args.reference.is_some() {
        bail!("--reference: a moving camera (--camera-path {}) needs a reference per frame", args.camera_path);
    }
    let references = if cameras.is_empty() {
        vec![single_reference(&args, backend.as_mut(), &gpu_scene, &render)?]
    } else {
        println!(
            "rendering {} references (one per frame): {} spp path tracing each",
            cameras.len(),
            args.reference_spp
        );
        let bar = indicatif::ProgressBar::new(cameras.len() as u64);
        let mut references = Vec::new();
        for (frame, camera) in cameras.iter().enumerate() {
            let settings = RenderSettings { seed: 0x7ef + frame as u32, camera: camera.clone(), ..render.clone() };
            let image = strata::render::render(backend.as_mut(), &gpu_scene, &settings, args.reference_spp, |_| {})?;
            image.write_exr(&args.out.join(format!("reference_frame{:03}.exr", frame + 1)))?;
            references.push(image);
            bar.inc(1);
        }
        bar.finish_and_clear();
        references
    };
    let reference = &references[0];
    if (reference.width, reference.height) != (render.camera.width, render.camera.height) {
        bail!(
            "the reference is {}x{} but the render is {}x{}",
            reference.width,
            reference.height,
            render.camera.width,
            render.camera.height
        );
    }
    let comparison = Comparison {
        methods: args.methods.clone(),
        frames: args.frames,
        seeds: (1..=args.seeds).collect(),
        restir,
        accumulate: args.accumulate,
        cameras,
    };
    let options = ReportOptions {
        methods: args.methods.clone(),
        frames: args.frames,
        seeds: args.seeds,
        out: args.out.clone(),
        exposure: args.exposure,
        scene_name: args.scene.as_ref().and_then(|p| scene_stem(p)).unwrap_or_else(|| "default scene".into()),
        accumulate: args.accumulate,
    };
    run_and_report(&options, backend.as_mut(), &gpu_scene, &render, scene.extent(), &comparison, &references)
}

/// The reference image: `--reference`, or path-traced at `--reference-spp` and written
/// to the output folder.
fn single_reference(
    args: &CompareArgs,
    backend: &mut dyn strata_backends::Backend,
    gpu_scene: &GpuScene,
    render: &RenderSettings,
) -> Result<RgbImage> {
    Ok(match &args.reference {
        Some(path) => RgbImage::read_exr(path)?,
        None => {
            println!("rendering the reference: {} spp path tracing", args.reference_spp);
            let settings = RenderSettings { seed: 0x7ef, ..render.clone() };
            let bar = indicatif::ProgressBar::new(u64::from(args.reference_spp));
            let image = strata::render::render(backend, gpu_scene, &settings, args.reference_spp, |done| {
                bar.set_position(u64::from(done))
            })?;
            bar.finish_and_clear();
            let path = args.out.join("reference.exr");
            image.write_exr(&path)?;
            image.write_png(&args.out.join("reference.png"), args.exposure)?;
            image
        }
    })
}
