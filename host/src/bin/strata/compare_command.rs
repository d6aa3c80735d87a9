//! `strata compare`: its arguments, the reference (read or path-traced, sized to the
//! backend), and the run of every method and seed against it, which writes the report
//! (`strata::evaluation::report`).

use anyhow::{Result, bail};
use std::path::PathBuf;
use std::time::Instant;
use strata::evaluation::compare::Comparison;
use strata::evaluation::crops::{self, Crop};
use strata::evaluation::image_checks::check_reference;
use strata::evaluation::output_folder;
use strata::evaluation::record::{self, RunRecord};
use strata::evaluation::report::{OtherRegime, ReportOptions, run_and_report};
use strata::progress::Progress;
use strata_render::backend_choice::{BackendChoice, open_backend};
use strata_render::denoise::{Denoiser, OidnLibrary};
use strata_render::render::{Film, GpuScene, RenderSettings};
use strata_render::restir::{Method, RestirSettings};
use strata_render::rgb_image::RgbImage;
use strata_render::scene::parse_camera_path;

use super::{scene_and_settings, scene_stem};

/// The most frames per seed a comparison takes (about a day at 256 x 256 on lavapipe).
const MAX_FRAMES: u32 = 100_000;
/// The most seeds a comparison takes.
const MAX_SEEDS: u32 = 10_000;

#[derive(clap::Args)]
pub(crate) struct CompareArgs {
    /// Scene file; the built-in default scene when left out.
    scene: Option<PathBuf>,
    /// Frames per seed (the measurements in BENCHMARKS.md use 32).
    #[arg(long, default_value_t = 16)]
    frames: u32,
    /// Methods, comma-separated.
    #[arg(long, value_enum, value_delimiter = ',', default_values_t = [Method::Restir, Method::RestirDisc, Method::Strata])]
    methods: Vec<Method>,
    /// Independent renders (seeds 1..=N) per method; the intervals need 2, the variance
    /// tables 3 (the measurements in BENCHMARKS.md use 8).
    #[arg(long, default_value_t = 4)]
    seeds: u32,
    /// Output folder: `report.html` and everything it shows. Files an earlier run wrote
    /// there are removed first; other files are left alone.
    #[arg(long, default_value = "out/compare")]
    out: PathBuf,
    /// Reference image (linear EXR of the same size); rendered by the path tracer when
    /// left out.
    #[arg(long)]
    reference: Option<PathBuf>,
    /// Samples per pixel of the rendered reference [default: 1024 on a Vulkan or GL
    /// device, 256 on the CPU interpreter, which is about 6x slower].
    #[arg(long)]
    reference_spp: Option<u32>,
    /// A close-up for the report, `x,y,w,h` in pixels (repeatable); shown before the
    /// automatic ones.
    #[arg(long, value_name = "X,Y,W,H")]
    crop: Vec<Crop>,
    /// Close-ups chosen automatically where the methods' errors differ most.
    #[arg(long, default_value_t = 2)]
    auto_crops: usize,
    /// Image width [default: the scene camera's; half of it on the CPU interpreter].
    #[arg(long)]
    width: Option<u32>,
    /// Image height [default: the scene camera's; half of it on the CPU interpreter].
    #[arg(long)]
    height: Option<u32>,
    /// The ReSTIR settings every method shares (the selection's among them): declared,
    /// documented and validated once, in `strata_render::restir::RestirSettings`.
    #[command(flatten)]
    restir: RestirSettings,
    /// Camera rays through pixel centres, no film jitter, for the methods and the
    /// rendered reference alike (a diagnostic: without jitter a pixel's history sees the
    /// same primary hit every frame).
    #[arg(long)]
    pixel_centres: bool,
    /// Where in its pixel each frame's camera ray starts: `stratified`, successive points
    /// of the pixel's own R2 sequence from a random start (uniform frame by frame, so
    /// unbiased, and evenly spread across frames), or `white`, independent uniform
    /// points. Default: stratified with --accumulate (every method's error -21 to -25 %),
    /// white with temporal reuse (where consecutive frames far apart in the pixel reuse
    /// each other's reservoirs less well: +6 to +10 % on cornell-box). The rendered
    /// reference always takes the stratified sequence (or pixel centres).
    /// `--pixel-centres` removes the jitter instead.
    #[arg(long, value_enum, conflicts_with = "pixel_centres")]
    film: Option<Film>,
    /// Camera motion: `static`, `orbit:DEGREES_PER_FRAME`, `dolly:DISTANCE_PER_FRAME` or
    /// a keyframe JSON file. A moving camera needs a reference per frame: they are
    /// path-traced (`--reference-spp` each) and `--reference` is refused.
    #[arg(long, default_value = "static")]
    camera_path: std::ffi::OsString,
    /// Exposure of the PNG previews: finite and positive.
    #[arg(long, default_value_t = 1.0, value_parser = super::finite_positive)]
    exposure: f32,
    /// Also measure every frame after a denoiser: `svgf` (Schied et al. 2017, with the
    /// paper's settings) or `svgf-objects` (its spatial filters also stop at object
    /// boundaries), its history reprojected from frame to frame, or `oidn` (Intel Open
    /// Image Denoise on the CPU with the albedo and normal guides, each frame alone; `pip
    /// install pyoidn==2.5.1.0`, or set STRATA_OIDN_LIBRARY to libOpenImageDenoise.so.2),
    /// applied alike to every method's frames as rendered. Writes `errors_denoised.csv`,
    /// the denoised previews and the same tables for them.
    #[arg(long, value_enum)]
    denoise: Option<Denoiser>,
    /// Also run every method and seed in the other regime, against the same reference:
    /// accumulated frames when the run reuses temporally, temporal reuse with
    /// `--accumulate` (each with its default film unless `--film` or `--pixel-centres`
    /// says otherwise; no denoiser). The summary and the report's headline then give
    /// strata's gain in both side by side (the paper's shows most in accumulated
    /// frames); its errors go to `errors_accumulated.csv` (or `errors_temporal.csv`).
    /// Skipped, and said, with a moving camera, whose frames cannot be accumulated.
    #[arg(long, default_value_t = true, action = clap::ArgAction::Set, value_name = "BOOL")]
    both_regimes: bool,
    /// Backend to run on.
    #[arg(long, value_enum, default_value_t = BackendChoice::Auto)]
    backend: BackendChoice,
}

/// The render settings at the size to run: on the CPU interpreter, which is about 6x
/// slower than lavapipe, half the scene camera's width and height unless `--width` or
/// `--height` was given (a reference file fixes the size too), said up front.
fn sized_to_backend(
    args: &CompareArgs,
    render: RenderSettings,
    backend: &dyn strata_backends::Backend,
    reference_spp: u32,
) -> RenderSettings {
    let chosen = args.width.is_some() || args.height.is_some() || args.reference.is_some();
    if !backend.info().is_interpreter() || chosen {
        return render;
    }
    let (width, height) = ((render.camera.width / 2).max(1), (render.camera.height / 2).max(1));
    println!(
        "on the CPU interpreter: rendering at {width}x{height} (half the scene camera's {}x{}) with a {reference_spp}-spp \
         reference, to finish in minutes; --width, --height and --reference-spp choose",
        render.camera.width, render.camera.height
    );
    let mut camera = render.camera.clone();
    camera.width = width;
    camera.height = height;
    RenderSettings { camera, ..render }
}

/// Reference samples per pixel when `--reference-spp` is left out: fewer on the CPU
/// interpreter, so that the README's first command ends in minutes there too.
fn default_reference_spp(backend: &dyn strata_backends::Backend) -> u32 {
    if backend.info().is_interpreter() { 256 } else { 1024 }
}

pub(crate) fn compare(args: CompareArgs) -> Result<()> {
    let mut size = None;
    compare_sized(&args, &mut size).map_err(|e| match size {
        Some((width, height)) => super::name_the_size(e, width, height),
        None => e,
    })
}

/// [`compare`], which says the image size in `size` once it is known.
fn compare_sized(args: &CompareArgs, size: &mut Option<(u32, u32)>) -> Result<()> {
    let started = Instant::now();
    let date = record::now_rfc3339();
    let (scene, render) = scene_and_settings(&args.scene, args.width, args.height)?;
    if args.reference_spp == Some(0) {
        bail!("--reference-spp 0: at least one sample per pixel is needed");
    }
    // Read before any long work, and before the output folder is cleared (the file may
    // lie in it).
    let given_reference = args.reference.as_deref().map(RgbImage::read_exr).transpose()?;
    if let (Some(image), Some(path)) = (&given_reference, &args.reference) {
        check_reference(image, &path.display().to_string())?;
    }
    let film = film_of(args, args.restir.temporal);
    let render = RenderSettings { film, ..render };
    if args.frames == 0 || args.seeds == 0 {
        bail!("--frames and --seeds must be at least 1");
    }
    // Every frame's measurements are kept (and written to errors.csv): a count no run
    // could finish would only fill the memory first.
    for (flag, value, most) in [("--frames", args.frames, MAX_FRAMES), ("--seeds", args.seeds, MAX_SEEDS)] {
        if value > most {
            bail!("{flag} {value}: at most {most} (each frame of each seed is rendered and measured)");
        }
    }
    for (index, method) in args.methods.iter().enumerate() {
        if args.methods[..index].contains(method) {
            bail!("--methods: `{}` is named twice; name each method once", method.name());
        }
    }
    for (index, crop) in args.crop.iter().enumerate() {
        if args.crop[..index].contains(crop) {
            bail!("--crop {crop}: given twice; give each close-up once");
        }
    }
    let restir = args.restir;
    // Refused settings are said before the reference takes its minutes.
    restir.check()?;
    if args.denoise == Some(Denoiser::Oidn) {
        let library = OidnLibrary::find().map_err(strata::evaluation::compare::oidn_error)?;
        println!("denoiser: Open Image Denoise, {}", library.path());
    }
    let gpu_scene = GpuScene::build(&scene)?;
    let mut backend = open_backend(args.backend)?;
    println!("backend: {}", backend.info().summary());
    let reference_spp = args.reference_spp.unwrap_or_else(|| default_reference_spp(backend.as_ref()));
    let render = sized_to_backend(args, render, backend.as_ref(), reference_spp);
    *size = Some((render.camera.width, render.camera.height));
    for crop in &args.crop {
        crops::check_inside(crop, render.camera.width, render.camera.height)?;
    }
    // The whole path is read and every frame's camera checked here, before the output
    // folder is touched or a reference renders.
    let flag = || format!("--camera-path {}", args.camera_path.to_string_lossy());
    let camera_path = parse_camera_path(&args.camera_path, &render.camera)
        .map_err(|error| anyhow::anyhow!("--camera-path {:#}", anyhow::Error::from(error)))?;
    let (render, cameras) = match camera_path.still_camera(&render.camera) {
        // A still path renders from its own camera (one keyframe: that key's).
        Some(camera) => (RenderSettings { camera, ..render }, Vec::new()),
        None => {
            let cameras = camera_path
                .frame_cameras(&render.camera, args.frames)
                .map_err(|why| anyhow::anyhow!("{}: {why}", flag()))?;
            (render, cameras)
        }
    };
    // `--reuse-order auto` (the default) by the camera: temporal-first still,
    // spatial-first moving (RestirSettings::for_camera says why).
    let restir = restir.for_camera(!cameras.is_empty());
    if !cameras.is_empty() && !args.restir.temporal {
        bail!(
            "--accumulate with {}: accumulated frames would average different viewpoints and be measured against \
             one frame's reference; accumulate with a static camera, or use temporal reuse",
            flag()
        );
    }
    if !cameras.is_empty() && args.reference.is_some() {
        bail!("--reference: a moving camera ({}) needs a reference per frame", flag());
    }
    // While the reference renders, two more devices build and run the methods' kernels
    // (warm_up.rs: why, and why their devices come and go while this thread waits).
    let warm_up = (!backend.info().is_interpreter())
        .then(|| crate::warm_up::WarmUp::start(args.backend, scene.clone(), args.methods.clone(), restir));
    // Held until the report is written: a second run into the folder is refused meanwhile.
    let (_lock, removed) = output_folder::prepare(&args.out, args.reference.as_deref())?;
    if !removed.is_empty() {
        println!("removed {} files of an earlier run from {}", removed.len(), args.out.display());
    }
    let reference_text;
    let references = if let Some(image) = given_reference {
        reference_text = args.reference.as_ref().map(|p| p.display().to_string()).unwrap_or_default();
        vec![image]
    } else if cameras.is_empty() {
        let rendered = Instant::now();
        let image = rendered_reference(args, reference_spp, backend.as_mut(), &gpu_scene, &render)?;
        reference_text =
            format!("path-traced, {reference_spp} spp, in {}", strata::progress::words(rendered.elapsed()));
        vec![image]
    } else {
        println!("rendering {} references (one per frame): {reference_spp} spp path tracing each", cameras.len(),);
        let rendered = Instant::now();
        let mut progress = Progress::new("references", cameras.len() as u64, "frames");
        let mut references = Vec::new();
        for (frame, camera) in cameras.iter().enumerate() {
            let settings = RenderSettings {
                seed: 0x7ef + frame as u32,
                camera: camera.clone(),
                film: reference_film(render.film),
                ..render.clone()
            };
            let image = strata_render::render::render(backend.as_mut(), &gpu_scene, &settings, reference_spp, |_| {})?;
            check_reference(&image, &format!("the path-traced reference of frame {}", frame + 1))?;
            image.write_exr(&args.out.join(format!("reference_frame{:03}.exr", frame + 1)))?;
            references.push(image);
            progress.inc(1);
        }
        progress.finish();
        reference_text = format!(
            "path-traced per frame ({}), {reference_spp} spp each, in {}",
            args.camera_path.to_string_lossy(),
            strata::progress::words(rendered.elapsed())
        );
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
    if let Some(warm_up) = warm_up {
        // Joined before the methods run, so that no kernel is compiled twice at once.
        if !warm_up.is_finished() {
            println!(
                "waiting for the methods' kernels to finish compiling (once per machine: Mesa's cache keeps them)"
            );
        }
        warm_up.join();
    }
    let comparison = Comparison {
        methods: args.methods.clone(),
        frames: args.frames,
        seeds: (1..=args.seeds).collect(),
        restir,
        cameras,
        exposure: args.exposure,
        denoise: args.denoise,
    };
    let record = RunRecord {
        command_line: record::command_line(),
        backend: backend.info().summary(),
        version: env!("CARGO_PKG_VERSION").to_string(),
        git_revision: record::GIT_REVISION.to_string(),
        date,
        scene: args
            .scene
            .as_ref()
            .and_then(|p| scene_stem(p))
            .map_or_else(|| "default scene".into(), |s| s.to_string_lossy().into_owned()),
        width: render.camera.width,
        height: render.camera.height,
        frames: args.frames,
        seeds: args.seeds,
        temporal: args.restir.temporal,
        reference: reference_text,
        settings: settings_record(&restir, args, render.film, backend.info()),
        warnings: scene.warnings.clone(),
        frame_ms: Vec::new(),
        seconds: 0.0,
    };
    let other_regime = match (args.both_regimes, comparison.cameras.is_empty()) {
        (true, true) => Some(OtherRegime {
            comparison: Comparison {
                restir: RestirSettings { temporal: !restir.temporal, ..restir },
                denoise: None,
                ..comparison.clone()
            },
            render: RenderSettings { film: film_of(args, !restir.temporal), ..render.clone() },
        }),
        (true, false) => {
            println!("the accumulated regime is left out: a moving camera's frames cannot be accumulated");
            None
        }
        (false, _) => None,
    };
    let options = ReportOptions {
        other_regime,
        methods: args.methods.clone(),
        out: args.out.clone(),
        exposure: args.exposure,
        crops: args.crop.clone(),
        automatic_crops: args.auto_crops,
        record,
        started,
    };
    run_and_report(&options, backend.as_mut(), &gpu_scene, &render, scene.extent(), &comparison, &references)
}

/// The film of a regime: pixel centres or the user's film when given, else the regime's
/// default (stratified for accumulated frames, white with temporal reuse).
fn film_of(args: &CompareArgs, temporal: bool) -> Film {
    match (args.pixel_centres, args.film) {
        (true, _) => Film::Centres,
        (false, Some(film)) => film,
        (false, None) if !temporal => Film::Stratified,
        (false, None) => Film::White,
    }
}

/// The settings every method shared, by name, for the run's record.
fn settings_record(
    restir: &RestirSettings,
    args: &CompareArgs,
    film: Film,
    device: &strata_backends::DeviceInfo,
) -> serde_json::Map<String, serde_json::Value> {
    let mut map = match serde_json::to_value(restir) {
        Ok(serde_json::Value::Object(map)) => map,
        _ => unreachable!("RestirSettings serialises to an object"),
    };
    let mut put = |name: &str, value: serde_json::Value| {
        map.insert(name.to_string(), value);
    };
    put("methods", args.methods.iter().map(|m| m.name()).collect::<Vec<_>>().join(",").into());
    // Every histogram kernel gives the same output; which one ran depends on the device.
    let histogram = strata_render::histogram_pass::auto_kernel(device, restir.selection.block_size);
    put("histogram_kernel", histogram.spec().map(|spec| spec.name.to_string()).into());
    put("film", clap::ValueEnum::to_possible_value(&film).map(|p| p.get_name().to_string()).into());
    put("camera_path", args.camera_path.to_string_lossy().into_owned().into());
    put("denoise", args.denoise.map(|d| d.name()).into());
    put("both_regimes", args.both_regimes.into());
    map
}

/// The reference path-traced at `spp` and written to the output folder.
/// The film of a rendered reference: it averages many samples of each pixel, where the
/// stratified sequence converges fastest; pixel centres stay pixel centres.
fn reference_film(methods: Film) -> Film {
    if methods == Film::Centres { Film::Centres } else { Film::Stratified }
}

fn rendered_reference(
    args: &CompareArgs,
    spp: u32,
    backend: &mut dyn strata_backends::Backend,
    gpu_scene: &GpuScene,
    render: &RenderSettings,
) -> Result<RgbImage> {
    println!("rendering the reference: {spp} spp path tracing at {}x{}", render.camera.width, render.camera.height);
    let settings = RenderSettings { seed: 0x7ef, film: reference_film(render.film), ..render.clone() };
    let mut progress = Progress::new("reference", u64::from(spp), "spp");
    let image =
        strata_render::render::render(backend, gpu_scene, &settings, spp, |done| progress.set(u64::from(done)))?;
    progress.finish();
    check_reference(&image, "the path-traced reference")?;
    image.write_exr(&args.out.join("reference.exr"))?;
    Ok(image)
}
