//! A [`Figure`] written as `{stem}.svg` and `{stem}.png`. The PNG is drawn at twice its
//! size and scaled down, which smooths plotters' un-antialiased lines; its text uses
//! DejaVu Sans embedded in the binary (the `dejavu` crate), so no installed font is
//! needed. The SVG names the `sans-serif` family and leaves the font to the viewer.

use super::figure::{Figure, SIZE, draw};
use anyhow::{Context, Result, anyhow};
use plotters::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// The PNG's size relative to [`SIZE`] (sharper in reports and on high-density screens).
const PNG_SCALE: f64 = 1.5;
/// The PNG is drawn this many times larger, then scaled down.
const SUPERSAMPLING: f64 = 2.0;

/// `stem` with `suffix` appended to its file name (`out/relmse` + `.svg`); unlike
/// `with_extension`, a dot already in the name stays.
pub(super) fn with_suffix(stem: &Path, suffix: &str) -> PathBuf {
    let mut name = stem.as_os_str().to_owned();
    name.push(suffix);
    PathBuf::from(name)
}

/// Makes the embedded DejaVu Sans the `sans-serif` family of plotters' text (once per
/// process); plotters measures text with it for the SVG too.
fn register_font() -> Result<()> {
    static REGISTERED: OnceLock<Result<(), String>> = OnceLock::new();
    REGISTERED
        .get_or_init(|| {
            for (style, bytes) in
                [(FontStyle::Normal, dejavu::sans::regular()), (FontStyle::Bold, dejavu::sans::bold())]
            {
                plotters::style::register_font("sans-serif", style, bytes)
                    .map_err(|_| "the embedded DejaVu Sans font does not load".to_string())?;
            }
            Ok(())
        })
        .clone()
        .map_err(|e| anyhow!(e))
}

/// The SVG document of `figure`.
pub(super) fn svg(figure: &Figure) -> Result<String> {
    register_font()?;
    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, SIZE).into_drawing_area();
        draw(&root, figure, 1.0).map_err(|e| anyhow!("cannot draw the plot: {e}"))?;
        root.present().map_err(|e| anyhow!("cannot draw the plot: {e}"))?;
    }
    Ok(text)
}

/// The PNG image of `figure`, [`PNG_SCALE`] times [`SIZE`].
pub(super) fn png(figure: &Figure) -> Result<image::RgbImage> {
    register_font()?;
    let scale = PNG_SCALE * SUPERSAMPLING;
    let (width, height) = ((f64::from(SIZE.0) * scale) as u32, (f64::from(SIZE.1) * scale) as u32);
    let mut pixels = vec![0u8; width as usize * height as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut pixels, (width, height)).into_drawing_area();
        draw(&root, figure, scale).map_err(|e| anyhow!("cannot draw the plot: {e}"))?;
        root.present().map_err(|e| anyhow!("cannot draw the plot: {e}"))?;
    }
    let large =
        image::RgbImage::from_raw(width, height, pixels).context("the plot's pixel buffer has the wrong size")?;
    let (small_width, small_height) = ((f64::from(SIZE.0) * PNG_SCALE) as u32, (f64::from(SIZE.1) * PNG_SCALE) as u32);
    Ok(image::imageops::resize(&large, small_width, small_height, image::imageops::FilterType::Triangle))
}

/// The files of `figure`: `{stem}.svg` and `{stem}.png`, encoded in memory. An error
/// names the file.
pub(super) fn encode(figure: &Figure, stem: &Path) -> Result<Vec<(PathBuf, Vec<u8>)>> {
    let (svg_path, png_path) = (with_suffix(stem, ".svg"), with_suffix(stem, ".png"));
    let document = svg(figure).with_context(|| format!("{}: cannot write", svg_path.display()))?;
    let bytes = png(figure)
        .and_then(|image| {
            strata_render::rgb_image::encode_png(
                image.as_raw(),
                image.width(),
                image.height(),
                image::ExtendedColorType::Rgb8,
            )
            .map_err(|e| anyhow!(e))
        })
        .with_context(|| format!("{}: cannot write", png_path.display()))?;
    Ok(vec![(svg_path, document.into_bytes()), (png_path, bytes)])
}

/// Writes `files` as one set ([`strata_render::atomic_file::write_set`]: all of them or none);
/// returns their paths.
pub(super) fn write_files(files: &[(PathBuf, Vec<u8>)]) -> Result<Vec<PathBuf>> {
    let set: Vec<(&Path, &[u8])> = files.iter().map(|(path, bytes)| (path.as_path(), bytes.as_slice())).collect();
    strata_render::atomic_file::write_set(&set)?;
    Ok(files.iter().map(|(path, _)| path.clone()).collect())
}

/// Writes `{stem}.svg` and `{stem}.png`, both or neither; returns their paths.
pub(super) fn write(figure: &Figure, stem: &Path) -> Result<Vec<PathBuf>> {
    write_files(&encode(figure, stem)?)
}
