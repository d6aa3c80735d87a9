//! A clone of strata passes its tests and runs its two README commands with nothing beside
//! it (issue 41): no source, build file or script reads the project's `../shared` folder
//! (the test scenes are committed under `scenes/`). The suite cannot run from such a clone
//! inside CI without a second build, so this test reads the tree for the paths instead.

use std::path::{Path, PathBuf};

/// Every file under `folder` whose name says it is code, a build file or a script.
fn code_files(folder: &Path, found: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(folder) else { return };
    for entry in entries.filter_map(Result::ok) {
        let path = entry.path();
        let name = entry.file_name().to_string_lossy().into_owned();
        if path.is_dir() {
            if !matches!(name.as_str(), "target" | ".git" | "benchmarks") {
                code_files(&path, found);
            }
        } else if ["rs", "toml", "sh", "py", "c", "h", "cpp", "wgsl"].iter().any(|e| name.ends_with(&format!(".{e}")))
            || name == "run"
        {
            found.push(path);
        }
    }
}

#[test]
fn nothing_reads_the_folder_beside_the_checkout() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut files = Vec::new();
    code_files(&root, &mut files);
    assert!(files.len() > 100, "the walk found {} files", files.len());
    // Spelled in two pieces so that this file does not match itself.
    let forbidden = [format!("../{}", "shared"), format!("{}/scenes", "shared")];
    let offenders: Vec<String> = files
        .iter()
        .filter(|path| !path.ends_with("self_contained.rs"))
        .filter(|path| {
            let text = std::fs::read_to_string(path).unwrap_or_default();
            forbidden.iter().any(|f| text.contains(f.as_str()))
        })
        .map(|path| path.display().to_string())
        .collect();
    assert!(offenders.is_empty(), "files that read ../shared: {offenders:?}");
    assert!(root.join("scenes/cornell-box/scene.json").is_file(), "the test scenes are committed");
}
