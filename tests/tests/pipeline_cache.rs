//! The driver's pipeline cache kept in a file between runs (wgpu's `PipelineCache` and
//! ash's `VkPipelineCache`, `strata_backends::pipeline_cache_file`): a backend writes
//! the file when it builds a pipeline, a later backend starts from it and renders the
//! same image, and a damaged file is ignored and replaced, never handed to the driver.
//! With the validation layer on, which reports any misuse of the cache objects.

use std::path::{Path, PathBuf};
use strata_backends::ash_backend::{AshBackend, AshOptions, SpirvSource};
use strata_backends::pipeline_cache_file::PipelineCacheFile;
use strata_backends::wgpu_backend::{WgpuApi, WgpuOptions};
use strata_backends::{Backend, BackendError, gpu_required};
use strata_render::render::{GpuScene, RenderSettings};
use strata_render::scene::default_scene;

/// A path for this test process's cache folder, under cargo's `target/tmp`, not the shared `/tmp`,
/// where another user could create the name first; nothing is there yet (the cache makes it).
fn scratch(name: &str) -> PathBuf {
    let folder = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("strata-pipeline-cache-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&folder);
    folder
}

/// An 8x8 path-traced image (2 spp) of the default scene: builds the path tracer's pipeline.
fn render(backend: &mut dyn Backend) -> Vec<[f32; 3]> {
    let scene = default_scene();
    let gpu_scene = GpuScene::build(&scene).unwrap();
    let settings = RenderSettings::for_scene(&scene, 8, 8, 1);
    strata_render::render::render(backend, &gpu_scene, &settings, 2, |_| {}).unwrap().pixels
}

/// The one cache file in `folder`.
fn cache_file(folder: &Path, prefix: &str) -> PathBuf {
    let files: Vec<PathBuf> = std::fs::read_dir(folder)
        .unwrap_or_else(|e| panic!("{}: no cache folder: {e}", folder.display()))
        .map(|e| e.unwrap().path())
        .collect();
    assert_eq!(files.len(), 1, "{files:?}");
    let name = files[0].file_name().unwrap().to_string_lossy().into_owned();
    assert!(name.starts_with(prefix) && name.ends_with(".bin"), "{name}");
    files[0].clone()
}

/// Whether `path` holds a whole cache file (ours: magic, length, CRC all right).
fn whole(path: &Path) -> bool {
    let folder = path.parent().unwrap();
    let key = path.file_stem().unwrap().to_string_lossy().into_owned();
    PipelineCacheFile::new(folder, &key).read().is_some()
}

/// The file's inode: a save replaces the file (a rename), so a run that found the data it
/// would save already there leaves the inode as it was.
fn inode(path: &Path) -> u64 {
    use std::os::unix::fs::MetadataExt;
    std::fs::metadata(path).unwrap().ino()
}

/// What [`three_runs`] leaves: the file, the image, the file's first bytes.
struct Runs {
    file: PathBuf,
    image: Vec<[f32; 3]>,
    written: Vec<u8>,
}

/// Runs the same render on three backends `open` makes from `folder`: the first writes the
/// file, the second reads it (and, finding the same data, leaves it as it was), the third
/// finds it damaged.
fn three_runs(folder: &Path, prefix: &str, open: impl Fn() -> Option<Box<dyn Backend>>) -> Option<Runs> {
    let first = {
        let mut backend = open()?;
        render(backend.as_mut())
    };
    let file = cache_file(folder, prefix);
    assert!(whole(&file), "{}: not a whole cache file", file.display());
    let written = std::fs::read(&file).unwrap();
    let first_inode = inode(&file);
    let second = {
        let mut backend = open()?;
        render(backend.as_mut())
    };
    assert_eq!(first, second, "the image changed with the cache read back");
    assert_eq!(inode(&file), first_inode, "the second run saved again: it did not start from the file's data");
    assert_eq!(std::fs::read(&file).unwrap(), written);
    // A damaged file (a bit of the driver's bytes flipped): ignored, the run the same,
    // and the file written whole again.
    let mut damaged = written.clone();
    let last = damaged.len() - 1;
    damaged[last] ^= 0x10;
    std::fs::write(&file, &damaged).unwrap();
    assert!(!whole(&file));
    let third = {
        let mut backend = open()?;
        render(backend.as_mut())
    };
    assert_eq!(first, third, "the image changed after a damaged cache file");
    assert!(whole(&file), "{}: the damaged file was not replaced", file.display());
    Some(Runs { file, image: first, written })
}

fn skip_or_panic(test: &str, error: BackendError) -> Option<Box<dyn Backend>> {
    match error {
        BackendError::NoAdapter { .. } if !gpu_required() => {
            eprintln!("SKIPPED {test}: {error} (set STRATA_REQUIRE_GPU=1 to make this a failure)");
            None
        }
        error => panic!("{test}: {error}"),
    }
}

#[test]
fn wgpu_keeps_its_pipeline_cache_in_a_file() {
    let folder = scratch("wgpu");
    let open = || {
        let options = WgpuOptions {
            api: WgpuApi::Vulkan,
            validation: true,
            pipeline_cache: Some(folder.clone()),
            ..Default::default()
        };
        match strata_backends::wgpu_backend::WgpuBackend::new(options) {
            Ok(backend) => Some(Box::new(backend) as Box<dyn Backend>),
            Err(error) => skip_or_panic("wgpu", error),
        }
    };
    let Some(runs) = three_runs(&folder, "wgpu_pipeline_cache_vulkan_", open) else { return };
    // A whole file whose wgpu data were made on another adapter (a byte of the adapter
    // key in wgpu's header changed): wgpu refuses such data even with `fallback`, and the
    // backend starts from an empty cache instead of failing every pipeline.
    let key = runs.file.file_stem().unwrap().to_string_lossy().into_owned();
    let mut cache = PipelineCacheFile::new(&folder, &key);
    let mut foreign = cache.read().unwrap();
    assert_eq!(&foreign[..8], b"WGPUPLCH", "wgpu's header changed: adapt this test");
    foreign[20] ^= 0x5a;
    cache.write(&foreign);
    let mut backend = open().unwrap();
    assert_eq!(render(backend.as_mut()), runs.image, "the image changed after another adapter's cache");
    drop(backend);
    assert_eq!(std::fs::read(&runs.file).unwrap(), runs.written, "the foreign data were not replaced");
    std::fs::remove_dir_all(&folder).unwrap();
}

#[test]
fn ash_keeps_its_pipeline_cache_in_a_file() {
    let folder = scratch("ash");
    let options = AshOptions {
        validation: true,
        source: SpirvSource::Naga,
        pipeline_cache: Some(folder.clone()),
        ..Default::default()
    };
    let open = || match AshBackend::new(options.clone()) {
        Ok(backend) => Some(Box::new(backend) as Box<dyn Backend>),
        Err(error) => skip_or_panic("ash", error),
    };
    if three_runs(&folder, "ash_pipeline_cache_vulkan_", open).is_none() {
        return;
    }
    // The layer saw the cache made from the file, used and saved: nothing to report.
    let mut backend = AshBackend::new(options).unwrap();
    render(&mut backend);
    let messages = backend.validation_messages();
    assert!(messages.is_empty(), "{messages:?}");
    drop(backend);
    std::fs::remove_dir_all(&folder).unwrap();
}
