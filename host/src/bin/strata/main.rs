//! The `strata` command line.

mod compare_command;
mod histogram_command;
mod runtime_dir;
mod warm_up;

/// `--exposure` and other scales: a finite, positive number (NaN or a negative exposure
/// would write black pictures, an infinite one white ones).
pub(crate) fn finite_positive(text: &str) -> Result<f32, String> {
    match text.trim().parse::<f32>() {
        Ok(value) if value.is_finite() && value > 0.0 => Ok(value),
        Ok(_) => Err(format!("{text}: must be finite and positive (and within single precision)")),
        Err(error) => Err(format!("{text}: {error}")),
    }
}

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand};
use std::path::{Path, PathBuf};
use std::time::Instant;
use strata::evaluation::metrics::{self, Metric};
use strata_render::backend_choice::{BackendChoice, open_backend};
use strata_render::render::{GpuScene, LightSampling, RenderSettings};
use strata_render::restir::{Method, RestirSettings};
use strata_render::rgb_image::RgbImage;
use strata_render::scene::{Scene, default_scene, load_scene_file};

/// strata: histogram-stratified ReSTIR.
#[derive(Parser)]
#[command(version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run the block-histogram kernel on a generated candidate image, check it against
    /// the Rust reference and print what it did.
    Histogram(histogram_command::HistogramArgs),
    /// Path-trace a scene progressively (the reference mode) and write a linear float EXR
    /// and a tone-mapped sRGB PNG preview.
    Render(RenderArgs),
    /// Render the ReSTIR methods from the same seeds and measure every frame against a
    /// reference: images, error maps, a CSV and a summary table.
    Compare(compare_command::CompareArgs),
    /// Plot RelMSE and strata's ratio to each baseline against frame from one or more
    /// `strata compare` errors.csv files (several are overlaid), as SVG and PNG.
    Plot(PlotArgs),
    /// Compare an EXR image with a reference EXR: MSE, RelMSE (paper and common forms),
    /// pRelMSE; optionally write the per-pixel RelMSE map as EXR and false-colour PNG.
    Metrics(MetricsArgs),
}

#[derive(clap::Args)]
struct PlotArgs {
    /// errors.csv files written by `strata compare`. One gives the RelMSE plot and the
    /// strata ÷ baseline plot; several are overlaid (methods keep their colours, runs get
    /// line styles), e.g. block shift off and on.
    #[arg(required = true, value_name = "CSV")]
    csv: Vec<PathBuf>,
    /// The legend's name of each CSV, in the CSVs' order (as many as CSVs). Default: each
    /// CSV's folder name, or its file name where folder names repeat.
    #[arg(long = "label", value_name = "NAME")]
    labels: Vec<String>,
    /// Where to write, without extension (a `.svg` or `.png` given is dropped). One CSV:
    /// STEM.svg/.png and STEM_ratio.svg/.png (default stem `relmse`); several:
    /// STEM_relmse.svg/.png and STEM_ratio.svg/.png (default stem `overlay`).
    #[arg(long, value_name = "STEM")]
    out: Option<PathBuf>,
    /// Title of the plots. Default: the labels.
    #[arg(long)]
    title: Option<String>,
}

#[derive(clap::Args)]
struct MetricsArgs {
    /// The image (linear RGB EXR).
    image: PathBuf,
    /// The reference (linear RGB EXR of the same size).
    reference: PathBuf,
    /// Write the per-pixel error map of `--map-metric` to this EXR, and a false-colour
    /// PNG beside it.
    #[arg(long)]
    map: Option<PathBuf>,
    /// Metric of the error map.
    #[arg(long, value_enum, default_value_t = Metric::Relmse)]
    map_metric: Metric,
    /// Exposure of the tone mapping FLIP compares at (as `compare`'s previews):
    /// finite and positive.
    #[arg(long, default_value_t = 1.0, value_parser = finite_positive)]
    exposure: f32,
}

#[derive(clap::Args)]
struct RenderArgs {
    /// Scene file (`scene.json` of the shared scenes); the built-in default scene when
    /// left out.
    scene: Option<PathBuf>,
    /// Samples per pixel.
    #[arg(long, default_value_t = 64)]
    spp: u32,
    /// Output folder (created if missing).
    #[arg(long, default_value = "out/render")]
    out: PathBuf,
    /// Image width (default: the scene camera's).
    #[arg(long)]
    width: Option<u32>,
    /// Image height (default: the scene camera's).
    #[arg(long)]
    height: Option<u32>,
    /// Path segments including the camera ray (default: the scene's).
    #[arg(long)]
    max_depth: Option<u32>,
    /// Seed of the render.
    #[arg(long, default_value_t = 1)]
    seed: u32,
    /// How light is found.
    #[arg(long, value_enum, default_value_t = LightSampling::Mis)]
    light_sampling: LightSampling,
    /// Turn Russian roulette off.
    #[arg(long)]
    no_russian_roulette: bool,
    /// Exposure of the PNG preview (the EXR is never scaled): finite and positive.
    #[arg(long, default_value_t = 1.0, value_parser = finite_positive)]
    exposure: f32,
    /// Backend to run on.
    #[arg(long, value_enum, default_value_t = BackendChoice::Auto)]
    backend: BackendChoice,
}

/// Runs the command; an error (a user's mistake, a missing file, a device that refuses)
/// is one line on standard error and exit status 1, with no backtrace whatever
/// `RUST_BACKTRACE` says. Panics, which are bugs, keep theirs. The commands that open a
/// Vulkan device first warn about an `XDG_RUNTIME_DIR` others could plant a display socket
/// in (`runtime_dir.rs`).
fn main() -> std::process::ExitCode {
    quiet_output_failures();
    write_limits_are_errors();
    let command = parse_command_line().command;
    if matches!(command, Command::Histogram(_) | Command::Render(_) | Command::Compare(_)) {
        runtime_dir::warn_if_shared();
    }
    let result = match command {
        Command::Histogram(args) => histogram_command::histogram(args),
        Command::Render(args) => render(args),
        Command::Metrics(args) => metrics(args),
        Command::Compare(args) => compare_command::compare(args),
        Command::Plot(args) => plot(args),
    };
    match result {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("error: {error:#}");
            std::process::ExitCode::FAILURE
        }
    }
}

/// Sets one number field of the ReSTIR settings.
type SetNumber = fn(&mut RestirSettings, f32);

/// The ReSTIR settings' number flags of `compare`, each with the setter of its field.
const RESTIR_NUMBER_FLAGS: [(&str, SetNumber); 5] = [
    ("disc_radius", |s, v| s.disc_radius = v),
    ("boiling_filter", |s, v| s.boiling_filter = v),
    ("temporal_cap", |s, v| s.temporal_cap = v),
    ("min_roughness", |s, v| s.min_roughness = v),
    ("min_distance", |s, v| s.min_distance = v),
];

/// The command line as parsed, the ReSTIR settings' number flags checked as they are
/// read: a refused value is quoted as the user typed it (`--disc-radius 4294967295`,
/// which a float prints as 4294967300), with the flag's name. The rule stays
/// [`RestirSettings::check`]'s, run on the default settings with that one field set.
fn parse_command_line() -> Cli {
    use clap::{CommandFactory, FromArgMatches};
    let command = Cli::command().mut_subcommand("compare", |compare| {
        RESTIR_NUMBER_FLAGS
            .iter()
            .fold(compare, |compare, &(id, set)| compare.mut_arg(id, |arg| arg.value_parser(restir_number(set))))
    });
    Cli::from_arg_matches(&command.get_matches()).unwrap_or_else(|error| error.exit())
}

/// A parser of one ReSTIR number flag: the number, and [`RestirSettings::check`] on the
/// default settings with it set by `set`; its refusal is the rule, without the number as
/// the check formats it (clap quotes the text and the flag).
fn restir_number(set: SetNumber) -> impl Fn(&str) -> Result<f32, String> + Clone + Send + Sync + 'static {
    move |text: &str| {
        let value = text.trim().parse::<f32>().map_err(|error| error.to_string())?;
        let mut settings = RestirSettings::default();
        set(&mut settings, value);
        match settings.check() {
            Ok(()) => Ok(value),
            Err(error) => {
                let message = error.to_string();
                Err(message.split_once(": ").map_or(message.clone(), |(_, rule)| rule.to_string()))
            }
        }
    }
}

/// A file-size limit (`ulimit -f`) reached while writing would kill the process by
/// SIGXFSZ before it could say anything, leaving the writer's temporary file behind.
/// Ignored, the write fails with "File too large" instead, which the one writer
/// (`atomic_file`) reports naming the file, removing its temporary.
fn write_limits_are_errors() {
    #[cfg(unix)]
    // SAFETY: `signal` with `SIG_IGN` installs no handler code; it is called once, before
    // any other thread exists.
    unsafe {
        libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
    }
}

/// Standard output or error that cannot be written (a full disk behind `> FILE`,
/// `/dev/full`, a pipe whose reader has gone, as in `strata plot ... | head -1`) ends the
/// run with one line and status 1 (141, silently, for a closed pipe, as a shell's
/// SIGPIPE would), instead of the standard library's panic and backtrace. Other panics,
/// which are bugs, keep theirs.
fn quiet_output_failures() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let payload = info.payload();
        let message = payload
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| payload.downcast_ref::<&str>().copied())
            .unwrap_or_default();
        if let Some(rest) = message.strip_prefix("failed printing to ") {
            if message.contains("Broken pipe") {
                std::process::exit(141);
            }
            use std::io::Write;
            let (stream, why) = rest.split_once(": ").unwrap_or((rest, ""));
            let _ = writeln!(
                std::io::stderr(),
                "error: standard {}: cannot write: {why}",
                stream.trim_start_matches("std")
            );
            std::process::exit(1);
        }
        default(info);
    }));
}

/// The scene file (or the built-in scene) and its render settings at the requested size.
pub(crate) fn scene_and_settings(
    scene: &Option<PathBuf>,
    width: Option<u32>,
    height: Option<u32>,
) -> Result<(Scene, RenderSettings)> {
    let scene = match scene {
        Some(path) => load_scene_file(path)?,
        None => default_scene(),
    };
    // Said once here; `compare` also keeps them in its run record.
    for warning in &scene.warnings {
        eprintln!("warning: {warning}");
    }
    let width = width.unwrap_or(scene.camera.width);
    let height = height.unwrap_or(scene.camera.height);
    // Said before a backend opens or a reference starts rendering.
    for (flag, value) in [("--width", width), ("--height", height)] {
        if value == 0 {
            bail!("{flag} 0: the image must be at least 1x1 pixels");
        }
        if value > strata_render::scene::MAX_IMAGE_SIDE {
            bail!("{flag} {value}: each side of the image must be at most {}", strata_render::scene::MAX_IMAGE_SIDE);
        }
    }
    let settings = RenderSettings::for_scene(&scene, width, height, 1);
    Ok((scene, settings))
}

fn plot(args: PlotArgs) -> Result<()> {
    use strata::evaluation::{compare, plot, summary};
    /// Each CSV's folder name; its file name where folder names repeat or are missing;
    /// its path where those repeat too.
    fn default_labels(paths: &[PathBuf]) -> Vec<String> {
        let distinct = |labels: &[Option<String>]| {
            labels.iter().all(Option::is_some) && labels.iter().enumerate().all(|(i, l)| !labels[..i].contains(l))
        };
        let name = |p: Option<&std::ffi::OsStr>| p.map(|n| n.to_string_lossy().into_owned()).filter(|n| !n.is_empty());
        let folders: Vec<Option<String>> = paths.iter().map(|p| name(p.parent().and_then(|p| p.file_name()))).collect();
        let files: Vec<Option<String>> = paths.iter().map(|p| name(p.file_stem())).collect();
        match (distinct(&folders), distinct(&files)) {
            (true, _) => folders.into_iter().flatten().collect(),
            (false, true) => files.into_iter().flatten().collect(),
            _ => paths.iter().map(|p| p.display().to_string()).collect(),
        }
    }
    if !args.labels.is_empty() && args.labels.len() != args.csv.len() {
        bail!(
            "{} --label for {} CSV files: give one label per CSV, in the same order, or none",
            args.labels.len(),
            args.csv.len()
        );
    }
    // What the user typed is drawn as typed, or refused: a control character would make
    // the SVG invalid XML (the figure replaces any that reach it from elsewhere).
    for (flag, text) in args.title.iter().map(|t| ("--title", t)).chain(args.labels.iter().map(|l| ("--label", l))) {
        if let Some((index, c)) = text.chars().enumerate().find(|&(_, c)| c.is_control()) {
            bail!(
                "{flag} {text:?}: character {} is the control character U+{:04X}; a title or label is one line of \
                 printable text",
                index + 1,
                u32::from(c)
            );
        }
    }
    for (index, label) in args.labels.iter().enumerate() {
        if args.labels[..index].contains(label) {
            bail!("--label `{label}`: given twice; the legend could not tell the runs apart");
        }
    }
    let same_file = |a: &PathBuf, b: &PathBuf| match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => a == b,
    };
    for (index, path) in args.csv.iter().enumerate() {
        if let Some(earlier) = args.csv[..index].iter().find(|earlier| same_file(earlier, path)) {
            bail!("{}: the same CSV as {}; give each run once", path.display(), earlier.display());
        }
    }
    let labels = if args.labels.is_empty() { default_labels(&args.csv) } else { args.labels.clone() };
    let mut runs = Vec::new();
    for (path, label) in args.csv.iter().zip(labels) {
        let text =
            strata_render::scene::read_text_capped(path).with_context(|| format!("{}: cannot read", path.display()))?;
        let errors = compare::parse_errors_csv(&text).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
        runs.push((label, errors));
    }
    let several = runs.len() > 1;
    let mut stem = args.out.clone().unwrap_or_else(|| PathBuf::from(if several { "overlay" } else { "relmse" }));
    if stem.extension().is_some_and(|e| e == "svg" || e == "png") {
        stem.set_extension("");
    }
    let title =
        args.title.clone().unwrap_or_else(|| runs.iter().map(|(l, _)| l.as_str()).collect::<Vec<_>>().join(" vs "));
    let frames_of = |errors: &[compare::FrameError]| errors.iter().map(|e| e.frame + 1).max().unwrap_or(1);
    let written: Vec<PathBuf> = if several {
        plot::write_overlay_plots(&runs, &title, &stem)?
    } else {
        let errors = &runs[0].1;
        let mut methods: Vec<Method> = Vec::new();
        for e in errors {
            if !methods.contains(&e.method) {
                methods.push(e.method);
            }
        }
        let frames = frames_of(errors);
        let mut ratio = stem.as_os_str().to_owned();
        ratio.push("_ratio");
        plot::write_relmse_and_ratio_plots(errors, &methods, frames, &title, &stem, Path::new(&ratio))?
    };
    println!("wrote {}", written.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", "));
    for (label, errors) in &runs {
        let has_ratio =
            Method::BASELINES.iter().any(|&b| compare::relmse_ratio_over_frames(errors, Method::Strata, b).is_some());
        if several && has_ratio {
            println!("{label}:");
        }
        summary::print_ratio_over_frames(errors, frames_of(errors));
    }
    Ok(())
}

fn metrics(args: MetricsArgs) -> Result<()> {
    // The map's names are checked before anything is read or measured.
    let map_png = args.map.as_ref().map(|map| map.with_extension("png"));
    if let Some(map) = &args.map {
        if !map.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr")) {
            bail!(
                "--map {}: the error map is an EXR file and its false-colour picture a PNG beside it; give a name \
                 ending in .exr",
                map.display()
            );
        }
        for output in [map, map_png.as_ref().expect("set with map")] {
            for (flag, input) in [("the image", &args.image), ("the reference", &args.reference)] {
                if same_file(output, input) {
                    bail!("--map {}: would overwrite {flag} {}", map.display(), input.display());
                }
            }
        }
    }
    if let (Some(map), Some(png)) = (&args.map, &map_png) {
        strata_render::atomic_file::check_target(map)?;
        strata_render::atomic_file::check_target(png)?;
    }
    let image = RgbImage::read_exr(&args.image)?;
    let reference = RgbImage::read_exr(&args.reference)?;
    strata::evaluation::image_checks::check_reference(&reference, &args.reference.display().to_string())?;
    // The map is made before anything is printed: a map that single precision cannot hold
    // is an error, not a half-done command.
    let map = match &args.map {
        Some(path) => {
            let map = metrics::error_map(&image, &reference, args.map_metric)?;
            if let Some(i) = map.iter().position(|&e| !(e as f32).is_finite()) {
                bail!(
                    "--map {}: the error at pixel ({}, {}) is {:e}, beyond single precision (the images differ by \
                     more than an EXR can hold)",
                    path.display(),
                    i % image.width as usize,
                    i / image.width as usize,
                    map[i]
                );
            }
            Some(map)
        }
        None => None,
    };
    let context = || format!("{} against {}", args.image.display(), args.reference.display());
    println!("mse            {:.6e}", metrics::mse(&image, &reference).with_context(context)?);
    println!("relmse         {:.6e}", metrics::relmse(&image, &reference).with_context(context)?);
    println!("relmse-common  {:.6e}", metrics::relmse_common(&image, &reference).with_context(context)?);
    println!("prelmse        {:.6e}", metrics::prelmse(&image, &reference).with_context(context)?);
    println!("relmse-luma    {:.6e}", metrics::relmse_luminance(&image, &reference).with_context(context)?);
    match strata::evaluation::flip::mean_flip(&image, &reference, args.exposure).with_context(context)? {
        Some(flip) => println!("flip           {flip:.6e}  (LDR-FLIP at --exposure {})", args.exposure),
        None => println!("flip           not computed (a build without the `flip` feature)"),
    }
    let (m, r) = (image.mean(), reference.mean());
    println!("mean image     ({:.5}, {:.5}, {:.5})", m[0], m[1], m[2]);
    println!("mean reference ({:.5}, {:.5}, {:.5})", r[0], r[1], r[2]);
    if let (Some(path), Some(map)) = (&args.map, map) {
        let map_image =
            RgbImage { width: image.width, height: image.height, pixels: map.iter().map(|&e| [e as f32; 3]).collect() };
        map_image.write_exr(path)?;
        let png = map_png.expect("set with map");
        metrics::false_colour(&map, image.width, image.height).write_png(&png, 1.0)?;
        println!("wrote {} and {}", path.display(), png.display());
    }
    Ok(())
}

fn render(args: RenderArgs) -> Result<()> {
    let (scene, defaults) = scene_and_settings(&args.scene, args.width, args.height)?;
    if args.spp == 0 {
        bail!("--spp 0: at least one sample per pixel is needed");
    }
    let settings = RenderSettings {
        seed: args.seed,
        max_depth: args.max_depth.unwrap_or(scene.max_depth),
        light_sampling: args.light_sampling,
        russian_roulette: !args.no_russian_roulette,
        ..defaults
    };
    // The output is checked before the samples take their time: the folder made, the
    // names free for the writer, and the folder writable (`compare` learns that from its
    // lock file; a read-only folder failed only after the whole render).
    std::fs::create_dir_all(&args.out).with_context(|| format!("{}: cannot create the folder", args.out.display()))?;
    let stem = args.scene.as_ref().and_then(|p| scene_stem(p)).unwrap_or_else(|| "default".into());
    let (exr, png) = (args.out.join(with_extension(&stem, "exr")), args.out.join(with_extension(&stem, "png")));
    strata_render::atomic_file::check_target(&exr)?;
    strata_render::atomic_file::check_target(&png)?;
    check_writable(&args.out, &exr)?;
    let gpu_scene = GpuScene::build(&scene)?;
    let mut backend = open_backend(args.backend)?;
    println!("backend: {}", backend.info().summary());
    println!(
        "scene: {} ({} triangles, {} emissive, environment: {}), {}x{}, {} spp, max depth {}",
        scene.name,
        gpu_scene.triangles.len(),
        gpu_scene.light_count(),
        if scene.environment.is_some() { "yes" } else { "no" },
        settings.camera.width,
        settings.camera.height,
        args.spp,
        settings.max_depth
    );
    let mut progress = strata::progress::Progress::new("render", u64::from(args.spp), "spp");
    let started = Instant::now();
    let image = strata_render::render::render(backend.as_mut(), &gpu_scene, &settings, args.spp, |done| {
        progress.set(u64::from(done))
    })
    .map_err(|e| name_the_size(e.into(), settings.camera.width, settings.camera.height))?;
    progress.finish();
    if strata::evaluation::image_checks::is_black(&image) {
        eprintln!(
            "warning: the rendered image is black everywhere ({}x{} pixels of 0): does the camera see any light (is \
             it inside a closed object, pointed away from the scene, or is the scene unlit)?",
            image.width, image.height
        );
    }
    let seconds = started.elapsed().as_secs_f64();
    image.write_exr(&exr)?;
    image.write_png(&png, args.exposure)?;
    if let Some(warning) = strata::evaluation::image_checks::black_preview(&image, args.exposure) {
        eprintln!("warning: {}: {warning}", png.display());
    }
    let mean = image.mean();
    println!(
        "rendered in {seconds:.1} s ({:.1} ms per sample per pixel); mean radiance ({:.4}, {:.4}, {:.4})",
        seconds * 1e3 / f64::from(args.spp),
        mean[0],
        mean[1],
        mean[2]
    );
    println!("wrote {} and {}", exr.display(), png.display());
    Ok(())
}

/// Whether the writer will be able to write `target` into `folder`: a temporary file of
/// the writer's own kind is made beside `target` and removed at once. An error names the
/// folder and the OS's reason (a read-only folder or file system, no permission).
fn check_writable(folder: &Path, target: &Path) -> Result<()> {
    let probe = strata_files::TemporaryFile::beside(target).map_err(|error| {
        // tempfile appends the temporary's random name, which means nothing to the user.
        let text = error.to_string();
        let reason =
            text.rsplit_once(" at path \"").filter(|(_, name)| name.contains(".tmp-")).map_or(&*text, |(r, _)| r);
        anyhow::anyhow!("--out {}: cannot write into the folder: {reason}", folder.display())
    })?;
    drop(probe);
    Ok(())
}

/// `error` with the image size named first where the device refused a buffer as too
/// large (the message otherwise names only an internal kernel binding).
pub(crate) fn name_the_size(error: anyhow::Error, width: u32, height: u32) -> anyhow::Error {
    use strata_backends::BackendError;
    use strata_render::histogram_pass::PassError;
    let limit = |b: &BackendError| matches!(b, BackendError::LimitExceeded { .. });
    let too_large = error.chain().any(|cause| {
        cause.downcast_ref::<BackendError>().is_some_and(limit)
            || cause.downcast_ref::<PassError>().is_some_and(|p| matches!(p, PassError::Backend(b) if limit(b)))
    });
    if too_large {
        error.context(format!(
            "--width {width} --height {height}: {} pixels are too many for this device; choose a smaller image",
            u64::from(width) * u64::from(height)
        ))
    } else {
        error
    }
}

/// Whether `a` and `b` name the same file: the same path, or the same file on disk
/// (through links, `..` or another spelling).
fn same_file(a: &std::path::Path, b: &std::path::Path) -> bool {
    if a == b {
        return true;
    }
    match (std::fs::canonicalize(a), std::fs::canonicalize(b)) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    }
}

/// `cornell-box` for `.../cornell-box/scene.json`, else the file stem; the bytes of the
/// path kept (a file name need not be UTF-8).
pub(crate) fn scene_stem(path: &std::path::Path) -> Option<std::ffi::OsString> {
    let stem = path.file_stem()?;
    if let Some(variant) = stem.to_str().and_then(|s| s.strip_prefix("scene")) {
        let mut name = path.parent()?.file_name()?.to_os_string();
        name.push(variant);
        return Some(name);
    }
    Some(stem.to_os_string())
}

/// `stem.extension` without reading `stem` as text.
fn with_extension(stem: &std::ffi::OsStr, extension: &str) -> std::ffi::OsString {
    let mut name = stem.to_os_string();
    name.push(".");
    name.push(extension);
    name
}
