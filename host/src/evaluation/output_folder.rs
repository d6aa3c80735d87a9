//! The folder a `strata compare` run writes into, kept to one run at a time: before a
//! run writes anything, the files an earlier run wrote there (recognised by name:
//! [`is_run_output`]) are removed, so an old run's images never sit beside a new run's
//! CSV. Files with other names are left alone, and so is the reference image the new
//! run reads, wherever it lies.

use anyhow::{Context, Result};
use std::path::{Path, PathBuf};

/// Whether `name` is a file a comparison run writes: the CSVs, the summary, the record,
/// the report page and its plots and colour bar, the reference and every method's frame
/// images and error maps.
pub fn is_run_output(name: &str) -> bool {
    const FIXED: [&str; 6] =
        ["errors.csv", "variance.csv", "summary.txt", "run.json", "report.html", "relmse_colourbar.png"];
    if FIXED.contains(&name) {
        return true;
    }
    let Some((stem, extension)) = name.rsplit_once('.') else { return false };
    let image = matches!(extension, "png" | "exr" | "svg");
    if !image {
        return false;
    }
    if stem == "relmse" || stem == "relmse_ratio" || stem == "reference" {
        return true;
    }
    // reference_frameNNN, METHOD_frameNNN, METHOD_frameNNN_relmse.
    let stem = stem.strip_suffix("_relmse").unwrap_or(stem);
    let Some((prefix, frame)) = stem.rsplit_once("_frame") else { return false };
    let methods = ["reference", "strata", "restir", "restir-disc"];
    methods.contains(&prefix) && !frame.is_empty() && frame.bytes().all(|b| b.is_ascii_digit())
}

/// Creates `folder` if needed and removes the files an earlier run wrote there, except
/// `keep` (an input of this run). Returns the names removed.
pub fn prepare(folder: &Path, keep: Option<&Path>) -> Result<Vec<String>> {
    std::fs::create_dir_all(folder).with_context(|| format!("{}: cannot create the folder", folder.display()))?;
    let keep: Option<PathBuf> = keep.and_then(|k| k.canonicalize().ok());
    let mut removed = Vec::new();
    let entries = std::fs::read_dir(folder).with_context(|| format!("{}: cannot list the folder", folder.display()))?;
    for entry in entries {
        let entry = entry.with_context(|| format!("{}: cannot list the folder", folder.display()))?;
        let name = entry.file_name().to_string_lossy().into_owned();
        let path = entry.path();
        if !is_run_output(&name) || !entry.file_type().is_ok_and(|t| t.is_file()) {
            continue;
        }
        if keep.is_some() && path.canonicalize().ok() == keep {
            continue;
        }
        std::fs::remove_file(&path)
            .with_context(|| format!("{}: cannot remove this file of an earlier run", path.display()))?;
        removed.push(name);
    }
    removed.sort();
    Ok(removed)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn run_outputs_are_recognised_by_name() {
        for name in [
            "errors.csv",
            "report.html",
            "run.json",
            "relmse.svg",
            "relmse_ratio.png",
            "reference.exr",
            "reference_frame003.exr",
            "strata_frame001.png",
            "restir-disc_frame032_relmse.exr",
        ] {
            assert!(is_run_output(name), "{name}");
        }
        for name in [
            "notes.txt",
            "my_reference.exr",
            "strata_frame.png",
            "strata_frame01a.png",
            "scene.json",
            "other_frame001.png",
        ] {
            assert!(!is_run_output(name), "{name}");
        }
    }

    #[test]
    fn an_earlier_runs_files_go_and_the_rest_stays() {
        let folder = std::env::temp_dir().join(format!("strata-output-folder-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&folder);
        std::fs::create_dir_all(&folder).unwrap();
        for name in ["errors.csv", "strata_frame001.png", "notes.txt", "reference.exr"] {
            std::fs::write(folder.join(name), b"x").unwrap();
        }
        let removed = prepare(&folder, Some(&folder.join("reference.exr"))).unwrap();
        assert_eq!(removed, ["errors.csv", "strata_frame001.png"]);
        assert!(folder.join("notes.txt").exists() && folder.join("reference.exr").exists());
        assert!(prepare(&folder, None).unwrap() == ["reference.exr"]);
        std::fs::remove_dir_all(&folder).unwrap();
    }
}
