//! Every WGSL file of `kernels/wgsl/`, embedded at compile time and found by its path,
//! and the generated modules under `gpu/` ([`crate::gpu`]): what a kernel's imports
//! ([`crate::wgsl_imports`]) are resolved against. A test checks the list against the
//! folder, so a new file cannot be left out.

use crate::fragment;
use crate::gpu::GpuModule;
use crate::source::Fragment;

/// Every file of `kernels/wgsl/`, by path.
pub static WGSL_FILES: &[Fragment] = &[
    fragment!("denoise/entry_atrous.wgsl"),
    fragment!("denoise/entry_modulate.wgsl"),
    fragment!("denoise/entry_temporal.wgsl"),
    fragment!("denoise/entry_variance.wgsl"),
    fragment!("denoise/svgf.wgsl"),
    fragment!("embed/contract.wgsl"),
    fragment!("embed/entry_resample.wgsl"),
    fragment!("embed/entry_select.wgsl"),
    fragment!("render/albedo.wgsl"),
    fragment!("render/bsdf.wgsl"),
    fragment!("render/entry_path_trace.wgsl"),
    fragment!("render/environment.wgsl"),
    fragment!("render/lights.wgsl"),
    fragment!("render/path.wgsl"),
    fragment!("render/random.wgsl"),
    fragment!("render/scene.wgsl"),
    fragment!("render/turns.wgsl"),
    fragment!("restir/block_reuse.wgsl"),
    fragment!("restir/entry_candidates.wgsl"),
    fragment!("restir/entry_guide.wgsl"),
    fragment!("restir/entry_reservoir_keys.wgsl"),
    fragment!("restir/entry_select.wgsl"),
    fragment!("restir/entry_shade.wgsl"),
    fragment!("restir/entry_spatial.wgsl"),
    fragment!("restir/entry_temporal.wgsl"),
    fragment!("restir/entry_temporal_keys.wgsl"),
    fragment!("restir/reservoir.wgsl"),
    fragment!("restir/resampling_core.wgsl"),
    fragment!("restir/reuse_slot.wgsl"),
    fragment!("strata/blue_noise.wgsl"),
    fragment!("strata/candidate.wgsl"),
    fragment!("strata/entry_histogram.wgsl"),
    fragment!("strata/entry_histogram_rank.wgsl"),
    fragment!("strata/entry_histogram_subgroup.wgsl"),
    fragment!("strata/histogram.wgsl"),
    fragment!("strata/histogram_network.wgsl"),
    fragment!("strata/histogram_rank.wgsl"),
    fragment!("strata/histogram_slot_pairs.wgsl"),
    fragment!("strata/histogram_slots.wgsl"),
    fragment!("strata/masking.wgsl"),
    fragment!("strata/resampling.wgsl"),
    fragment!("strata/selection.wgsl"),
    fragment!("trace/bvh.wgsl"),
    fragment!("trace/camera_rays.wgsl"),
    fragment!("trace/entry_closest_hit.wgsl"),
    fragment!("trace/traverse.wgsl"),
    fragment!("util/empty.wgsl"),
];

/// Every generated module, one per `*_types.rs` file, the scene's row readers, and the
/// selection's and blue noise's (listed here, above those files, rather than in
/// [`crate::gpu`], which they use to declare themselves).
pub fn gpu_modules() -> [GpuModule; 9] {
    [
        crate::types::gpu_module(),
        crate::selection::gpu_module(),
        crate::blue_noise::gpu_module(),
        crate::embed_types::gpu_module(),
        crate::trace_types::gpu_module(),
        crate::render_types::gpu_module(),
        crate::render_types::scene_rows_module(),
        crate::restir_types::gpu_module(),
        crate::denoise_types::gpu_module(),
    ]
}

/// The generated module imported as `path` (`gpu/restir.wgsl`).
pub fn gpu_module(path: &str) -> Option<GpuModule> {
    gpu_modules().into_iter().find(|module| module.path == path)
}

/// WGSL declarations of the embedding contract's records and constants (`Candidate`,
/// `ClusterSpan`, `SelectionParams`, `SelectedCandidates`, `ResampleInput`,
/// `ResampleOutput`, `NO_PAYLOAD`, ...), for an engine's own shaders that read the
/// selections and write the resampling inputs: prepend it to the shader source.
pub fn contract_wgsl() -> String {
    // contract.wgsl imports the records of candidate.wgsl and the generated modules.
    with_imports("embed/contract.wgsl").unwrap_or_else(|error| panic!("{error}"))
}

/// The WGSL file at `path` with every file it imports, directly or not, before it (the
/// text a kernel of that entry file is made of): for a test or a tool that puts its own
/// entry point after a file of `kernels/wgsl/`. An unknown path or a circle of imports is
/// an error naming the files.
pub fn with_imports(path: &str) -> Result<String, String> {
    let fragments = crate::wgsl_imports::kernel_fragments(path, &wgsl_file)?;
    Ok(crate::source::ComposedSource::compose(&fragments).text)
}

/// The file of `kernels/wgsl/` at `path` (relative to that folder), or the generated
/// module `gpu/NAME.wgsl` of the structs and constants declared in Rust ([`crate::gpu`]).
pub fn wgsl_file(path: &str) -> Option<Fragment> {
    if path.starts_with(GENERATED) {
        return gpu_module(path).map(|module| Fragment { path: path.to_string().into(), text: module.wgsl().into() });
    }
    WGSL_FILES.iter().find(|fragment| crate::wgsl_imports::wgsl_path(fragment) == path).cloned()
}

/// The folder of the generated modules' paths; `kernels/wgsl/` has no folder of that name.
pub const GENERATED: &str = "gpu/";

#[cfg(test)]
mod tests {
    use super::*;

    /// The list holds every `.wgsl` file under `kernels/wgsl/` and nothing else.
    #[test]
    fn the_list_is_the_folder() {
        fn walk(folder: &std::path::Path, root: &std::path::Path, out: &mut Vec<String>) {
            for entry in std::fs::read_dir(folder).unwrap() {
                let path = entry.unwrap().path();
                if path.is_dir() {
                    walk(&path, root, out);
                } else if path.extension().is_some_and(|e| e == "wgsl") {
                    out.push(path.strip_prefix(root).unwrap().to_string_lossy().replace('\\', "/"));
                }
            }
        }
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("wgsl");
        let mut on_disk = Vec::new();
        walk(&root, &root, &mut on_disk);
        on_disk.sort();
        let mut listed: Vec<String> =
            WGSL_FILES.iter().map(|f| crate::wgsl_imports::wgsl_path(f).to_string()).collect();
        listed.sort();
        assert_eq!(listed, on_disk, "kernels/src/wgsl_files.rs must list every file of kernels/wgsl");
    }
}
