//! What `strata compare` does once the reference exists: every method and seed rendered
//! ([`super::compare::run_comparison`]) and, in the output folder, the first seed's
//! images and error maps at the written frames, `errors.csv`, the plots (error against
//! frame, and the viewer's correlation and spectrum figures), `variance.csv`
//! (3 seeds or more), `summary.txt` (the printed summary), `run.json` (the run's
//! record) and `report.html` (all of it on one page, [`super::page`]). Driven by
//! [`ReportOptions`], a plain struct: the command line fills it from its arguments, and
//! anything else (a script, a test) can too.

use super::compare::{Comparison, SeenFrame, errors_csv, run_comparison};
use super::crops::{self, Crop};
use super::metrics::{self, Metric};
use super::page::{CropShown, FrameImages, MethodImage, Page, RegimeRatios};
use super::record::{MethodTime, RunRecord};
use super::summary::{self, SeedImages, Table};
use crate::progress::Progress;
use anyhow::Result;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};
use strata_render::render::{GpuScene, RenderSettings};
use strata_render::restir::Method;
use strata_render::rgb_image::RgbImage;

/// The other regime of `strata compare --both-regimes`: every method and seed again with
/// temporal reuse switched (accumulated frames for a temporal run, and the other way),
/// against the same references; its errors go to their own CSV
/// ([`OtherRegime::csv_name`]), the summary and the page's headline.
#[derive(Clone, Debug)]
pub struct OtherRegime {
    /// What to run: the run's comparison with `restir.temporal` switched (and no denoiser).
    pub comparison: Comparison,
    /// The render settings (the other regime's film).
    pub render: RenderSettings,
}

impl OtherRegime {
    /// The CSV its errors are written to.
    pub fn csv_name(&self) -> &'static str {
        if self.comparison.restir.temporal { "errors_temporal.csv" } else { "errors_accumulated.csv" }
    }
}

/// A regime as the summary and the page name it.
pub fn regime_name(temporal: bool) -> &'static str {
    if temporal { "temporal reuse" } else { "accumulated frames" }
}

/// What to run and where to write it. The scene, size, frames, seeds and mode are the
/// record's ([`RunRecord`]), stated once.
#[derive(Clone, Debug)]
pub struct ReportOptions {
    /// The methods, in the order their rows are printed.
    pub methods: Vec<Method>,
    /// Output folder (exists, and holds no earlier run's files: see
    /// [`super::output_folder::prepare`]).
    pub out: PathBuf,
    /// Exposure of the PNG previews.
    pub exposure: f32,
    /// Close-ups the user asked for (`--crop`), shown before the automatic ones.
    pub crops: Vec<Crop>,
    /// Automatic close-ups, chosen where the methods differ most.
    pub automatic_crops: usize,
    /// The run's record so far (what, where, when: scene, size, frames, seeds, mode); the
    /// frame times and the whole run's duration are filled in here.
    pub record: RunRecord,
    /// When the run began (the reference included), for the record's duration.
    pub started: Instant,
    /// The other regime, measured too (`--both-regimes`); `None`: the run's own only.
    pub other_regime: Option<OtherRegime>,
}

/// The frames whose images are written and shown: 1, 2, 4, … and the last (0-based).
pub fn shown_frames(frames: u32) -> Vec<u32> {
    (0..frames).filter(|f| (f + 1).is_power_of_two() || f + 1 == frames).collect()
}

/// Seed 1's image of one method at one shown frame, as the page needs it.
struct Written {
    image: String,
    error_map: String,
    relmse: f64,
    map: Vec<f64>,
}

/// Renders every method and seed, writes the files and prints the summary (see the
/// module docs).
pub fn run_and_report(
    options: &ReportOptions,
    backend: &mut dyn strata_backends::Backend,
    gpu_scene: &GpuScene,
    render: &RenderSettings,
    extent: f32,
    comparison: &Comparison,
    references: &[RgbImage],
) -> Result<()> {
    let out = &options.out;
    let (frames, seeds) = (options.record.frames, options.record.seeds);
    let regimes = 1 + u64::from(options.other_regime.is_some());
    let total = regimes * u64::from(frames) * u64::from(seeds) * options.methods.len() as u64;
    let mut progress = Progress::new("methods", total, "frames");
    let compared = Instant::now();
    let mut write_error: Option<anyhow::Error> = None;
    let shown = shown_frames(frames);
    let mut seed_images: SeedImages = HashMap::new();
    let mut written: HashMap<(Method, u32), Written> = HashMap::new();
    let mut render_time: HashMap<Method, (Duration, u32)> = HashMap::new();
    // Frames black everywhere where their reference is not: scored, and said once.
    let mut black_frames: Vec<String> = Vec::new();
    let block_size = comparison.restir.selection.block_size;
    let mut viewer = super::viewer::ViewerCollector::new(frames, block_size, !comparison.cameras.is_empty());
    let measured = run_comparison(backend, gpu_scene, render, extent, comparison, references, |seen| {
        let SeenFrame { method, seed, frame, image, denoised, took, .. } = seen;
        viewer.add(seen, references);
        progress.inc(1);
        let reference = references.get(frame as usize).unwrap_or(&references[0]);
        if super::image_checks::black_against(image, reference) {
            black_frames.push(format!("{} frame {}, seed {seed}", method.name(), frame + 1));
        }
        let time = render_time.entry(method).or_default();
        time.0 += took;
        time.1 += 1;
        if !shown.contains(&frame) {
            return;
        }
        if seeds >= 3 {
            seed_images.entry((method, frame)).or_default().push(image.clone());
        }
        if seed == 1 {
            match write_frame(out, method.name(), frame, image, reference, options.exposure) {
                Ok(w) => {
                    written.insert((method, frame), w);
                }
                Err(error) => {
                    write_error.get_or_insert(error);
                }
            }
            if let Some(denoised) = denoised {
                let name = format!("{}_denoised", method.name());
                if let Err(error) = write_frame(out, &name, frame, denoised, reference, options.exposure) {
                    write_error.get_or_insert(error);
                }
            }
        }
    })?;
    let errors = measured.raw;
    if let Some(error) = write_error {
        return Err(error);
    }
    let compare_seconds = compared.elapsed().as_secs_f64();
    write(&out.join("errors.csv"), errors_csv(&errors))?;
    if !measured.denoised.is_empty() {
        write(&out.join("errors_denoised.csv"), errors_csv(&measured.denoised))?;
    }
    let other_errors = match &options.other_regime {
        Some(other) => {
            let run = |_: SeenFrame<'_>| progress.inc(1);
            let measured =
                run_comparison(backend, gpu_scene, &other.render, extent, &other.comparison, references, run)?;
            write(&out.join(other.csv_name()), errors_csv(&measured.raw))?;
            Some((regime_name(other.comparison.restir.temporal), measured.raw))
        }
        None => None,
    };
    progress.finish();

    // Plots.
    let mode = regime_name(options.record.temporal);
    let title =
        format!("{} {}x{}, {} seeds, {mode}", options.record.scene, render.camera.width, render.camera.height, seeds);
    let plotted = super::plot::write_relmse_and_ratio_plots(
        &errors,
        &options.methods,
        frames,
        &title,
        &out.join("relmse"),
        &out.join("relmse_ratio"),
    )?;
    let mut plots =
        vec![("relmse.svg".to_string(), "RelMSE against frame: mean and 95 % interval over seeds".to_string())];
    if plotted.contains(&out.join("relmse_ratio.svg")) {
        plots.push((
            "relmse_ratio.svg".to_string(),
            "strata ÷ each baseline against frame: paired per seed, mean and 95 % interval".to_string(),
        ));
    }

    // The summary: printed, in summary.txt and on the page.
    let heading = format!(
        "{} frames x {} seeds x {} methods in {compare_seconds:.1} s; RelMSE (paper's form), mean ± 95% CI over seeds:",
        frames,
        seeds,
        options.methods.len(),
    );
    let mut tables: Vec<Table> = vec![summary::relmse_table(&errors, &options.methods, &shown, &heading)];
    let mut text = tables[0].to_text();
    // With both regimes each whole-run line says which it is, side by side.
    let label = if other_errors.is_some() { format!("{mode}: ") } else { String::new() };
    for line in summary::whole_run_lines(&errors, frames) {
        text += &format!("{label}{line}\n");
    }
    if let Some((regime, other)) = &other_errors {
        let heading = format!(
            "The same methods and seeds with {regime} ({}): RelMSE, mean ± 95% CI over seeds:",
            options.other_regime.as_ref().map_or("", |o| o.csv_name())
        );
        let table = summary::relmse_table(other, &options.methods, &shown, &heading);
        text += &table.to_text();
        tables.push(table);
        for line in summary::whole_run_lines(other, frames) {
            text += &format!("{regime}: {line}\n");
        }
    }
    if let Some(flip) = summary::flip_table(&errors, &options.methods, &shown) {
        text += &flip.to_text();
        tables.push(flip);
    }
    if let Some(blocks) = summary::block_edge_table(&errors, &options.methods, &shown, block_size) {
        text += &blocks.to_text();
        tables.push(blocks);
    }
    if !measured.denoised.is_empty() {
        let denoised = &measured.denoised;
        let filter = comparison.denoise.map_or("the denoiser", |d| d.title());
        let heading = format!(
            "After {filter} denoising (each method's frames as rendered, filtered alike): RelMSE, mean ± 95% CI over \
             seeds:"
        );
        let relmse = summary::relmse_table(denoised, &options.methods, &shown, &heading);
        text += &relmse.to_text();
        tables.push(relmse);
        for line in summary::whole_run_lines(denoised, frames) {
            text += &format!("after {filter}, {line}\n");
        }
        let more = [
            summary::flip_table(denoised, &options.methods, &shown),
            summary::block_edge_table(denoised, &options.methods, &shown, block_size),
        ];
        for mut table in more.into_iter().flatten() {
            table.title = format!("After {filter} denoising: {}", table.title);
            text += &table.to_text();
            tables.push(table);
        }
    }
    let last_reference = references.get(frames as usize - 1).unwrap_or(&references[0]);
    let viewer = viewer.finish(&options.methods, last_reference)?;
    write(&out.join("viewer.csv"), viewer.csv_text())?;
    plots.extend(write_viewer_plots(out, &viewer.curves, &title)?);
    text += &viewer.to_text();
    tables.extend(viewer.tables.iter().cloned());
    if seeds >= 3 {
        let (variance, csv) = summary::variance_tables(&options.methods, &shown, &seed_images, references)?;
        write(&out.join("variance.csv"), csv)?;
        for table in &variance {
            text += &table.to_text();
        }
        tables.extend(variance);
    }
    print!("{text}");

    // The record.
    let mut record = options.record.clone();
    if let Some(first) = black_frames.first() {
        let warning = format!(
            "{first}{} black everywhere while the reference is not (scored as rendered: at a few pixels and one \
             sample per frame this happens; otherwise look at the scene's light)",
            match black_frames.len() {
                1 => " is".to_string(),
                n => format!(" and {} more frames are", n - 1),
            }
        );
        eprintln!("warning: {warning}");
        record.warnings.push(warning);
    }
    if let Some(warning) = super::image_checks::black_preview(&references[0], options.exposure) {
        eprintln!("warning: {warning}");
        record.warnings.push(warning);
    }
    record.frame_ms = options
        .methods
        .iter()
        .filter_map(|&m| {
            let (time, count) = render_time.get(&m)?;
            Some(MethodTime { method: m.name().to_string(), frame_ms: time.as_secs_f64() * 1e3 / f64::from(*count) })
        })
        .collect();
    record.seconds = options.started.elapsed().as_secs_f64();
    let record_text: String = record.lines().iter().map(|(k, v)| format!("{k}: {v}\n")).collect();
    write(&out.join("summary.txt"), format!("{text}\n{record_text}"))?;
    write(&out.join("run.json"), record.to_json())?;

    // The page.
    let reference_png = write_reference_pngs(out, references, &shown, options.exposure)?;
    write_colour_bar(&out.join("relmse_colourbar.png"))?;
    let (width, height) = (render.camera.width, render.camera.height);
    let page_crops = choose_crops(options, &written, width, height);
    let frames = shown
        .iter()
        .map(|&frame| FrameImages {
            frame,
            reference: reference_png(frame),
            methods: options
                .methods
                .iter()
                .filter_map(|&method| {
                    let w = written.get(&(method, frame))?;
                    Some(MethodImage {
                        method,
                        image: w.image.clone(),
                        error_map: w.error_map.clone(),
                        relmse: w.relmse,
                        crop_relmse: page_crops.iter().map(|c| c.crop.mean_of(&w.map, width)).collect(),
                    })
                })
                .collect(),
        })
        .collect();
    let last = shown.last().copied().unwrap_or(0);
    let page = Page {
        title: format!("strata compare: {}, {mode}", options.record.scene),
        record: &record,
        size: (width, height),
        frames,
        crops: page_crops,
        crop_frames: if last == 0 { vec![0] } else { vec![0, last] },
        whole_run: std::iter::once(RegimeRatios {
            regime: mode.to_string(),
            ratios: summary::whole_run_ratios(&errors),
        })
        .chain(other_errors.iter().map(|(regime, other)| RegimeRatios {
            regime: regime.to_string(),
            ratios: summary::whole_run_ratios(other),
        }))
        .collect(),
        plots,
        tables,
        notes: viewer.notes.clone(),
        colour_bar: "relmse_colourbar.png".to_string(),
    };
    let report = out.join("report.html");
    write(&report, page.to_html())?;
    println!("wrote the report {} (with summary.txt, run.json, errors.csv, plots and images)", report.display());
    Ok(())
}

/// The viewer's figures (issue 55) per stage the curves hold, raw then denoised:
/// `viewer_correlation_{stage}` and `viewer_spectrum_{stage}` as SVG and PNG. Returns
/// each SVG's file name with its caption for the page, which says what to read from it.
fn write_viewer_plots(
    out: &Path,
    curves: &[super::viewer::ViewerCurves],
    title: &str,
) -> Result<Vec<(String, String)>> {
    use super::plot::{write_correlation_plot, write_spectrum_plot};
    use super::viewer::Stage;
    let mut plots = Vec::new();
    for stage in [Stage::Raw, Stage::Denoised] {
        let name = stage.name();
        let frames = match stage {
            Stage::Raw => "Raw frames",
            Stage::Denoised => "Denoised frames",
        };
        let stem = format!("viewer_correlation_{name}");
        if write_correlation_plot(curves, stage, title, &out.join(&stem))? {
            plots.push((
                format!("{stem}.svg"),
                format!(
                    "{frames}: correlation of the error between pixels k apart, inside a block (solid) and \
                     across a block edge (dashed); below 0 inside a block, errors are negatively correlated and a \
                     spatial filter cancels them"
                ),
            ));
        }
        let stem = format!("viewer_spectrum_{name}");
        if write_spectrum_plot(curves, stage, title, &out.join(&stem))? {
            plots.push((
                format!("{stem}.svg"),
                format!(
                    "{frames}: the error's power against radial frequency, ÷ white noise's (dashed 1); below 1 \
                     at low frequencies, the error is blue-noise-like and a blur removes it"
                ),
            ));
        }
    }
    Ok(plots)
}

/// Writes `text` to `path`, complete or not at all; an error names the file.
fn write(path: &Path, text: String) -> Result<()> {
    Ok(strata_render::atomic_file::write(path, text)?)
}

/// Writes one seed-1 frame of a method: EXR and PNG, and its RelMSE map as EXR and
/// false-colour PNG.
fn write_frame(
    out: &Path,
    name: &str,
    frame: u32,
    image: &RgbImage,
    reference: &RgbImage,
    exposure: f32,
) -> Result<Written> {
    let stem = format!("{name}_frame{:03}", frame + 1);
    image.write_exr(&out.join(format!("{stem}.exr")))?;
    image.write_png(&out.join(format!("{stem}.png")), exposure)?;
    let map = metrics::error_map(image, reference, Metric::Relmse)?;
    metrics::false_colour(&map, image.width, image.height).write_png(&out.join(format!("{stem}_relmse.png")), 1.0)?;
    RgbImage { width: image.width, height: image.height, pixels: map.iter().map(|&e| [e as f32; 3]).collect() }
        .write_exr(&out.join(format!("{stem}_relmse.exr")))?;
    let relmse = map.iter().sum::<f64>() / map.len().max(1) as f64;
    Ok(Written { image: format!("{stem}.png"), error_map: format!("{stem}_relmse.png"), relmse, map })
}

/// The reference PNGs the page shows: `reference.png` for a static camera, one per shown
/// frame for a moving one. Returns the file name of each frame's reference.
fn write_reference_pngs(
    out: &Path,
    references: &[RgbImage],
    shown: &[u32],
    exposure: f32,
) -> Result<impl Fn(u32) -> String + use<>> {
    let moving = references.len() > 1;
    if moving {
        for &frame in shown {
            let reference = references.get(frame as usize).unwrap_or(&references[0]);
            reference.write_png(&out.join(format!("reference_frame{:03}.png", frame + 1)), exposure)?;
        }
    } else {
        references[0].write_png(&out.join("reference.png"), exposure)?;
    }
    Ok(
        move |frame: u32| {
            if moving { format!("reference_frame{:03}.png", frame + 1) } else { "reference.png".to_string() }
        },
    )
}

/// The error maps' colour bar: [`metrics::false_colour`] over RelMSE 1e-4 to 1.
fn write_colour_bar(path: &Path) -> Result<()> {
    let (width, height) = (320u32, 14u32);
    let map: Vec<f64> = (0..height)
        .flat_map(|_| (0..width).map(move |x| 10f64.powf(-4.0 + 4.0 * f64::from(x) / f64::from(width - 1))))
        .collect();
    Ok(metrics::false_colour(&map, width, height).write_png(path, 1.0)?)
}

/// The user's crops, then the automatic ones, chosen on frame 1's error maps.
fn choose_crops(
    options: &ReportOptions,
    written: &HashMap<(Method, u32), Written>,
    width: u32,
    height: u32,
) -> Vec<CropShown> {
    let maps: Vec<Vec<f64>> =
        options.methods.iter().filter_map(|&m| written.get(&(m, 0)).map(|w| w.map.clone())).collect();
    let automatic = crops::where_methods_differ(&maps, width, height, options.automatic_crops, &options.crops);
    options
        .crops
        .iter()
        .map(|&crop| CropShown { crop, automatic: false })
        .chain(automatic.into_iter().map(|crop| CropShown { crop, automatic: true }))
        .collect()
}
