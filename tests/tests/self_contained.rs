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

/// GitHub's anchor of a heading: lower case, punctuation dropped, spaces as hyphens.
fn anchor(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || *c == '-' || *c == '_' || *c == ' ')
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

/// `text` without what lies between backticks (code spans and fenced blocks, where
/// `uint[4](0u, ...)` is code, not a link).
fn without_code(text: &str) -> String {
    let mut in_code = false;
    text.chars()
        .filter(|&c| {
            if c == '`' {
                in_code = !in_code;
                return false;
            }
            !in_code
        })
        .collect()
}

/// Every relative link of README.md and docs/*.md names a file that exists, and every
/// `#anchor` a heading of its file: the README's map of moved sections works.
#[test]
fn the_readme_and_docs_links_resolve() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut pages = vec![root.join("README.md"), root.join("BENCHMARKS.md")];
    for entry in std::fs::read_dir(root.join("docs")).unwrap().filter_map(Result::ok) {
        if entry.path().extension().is_some_and(|e| e == "md") {
            pages.push(entry.path());
        }
    }
    let mut checked = 0;
    for page in &pages {
        let text = without_code(&std::fs::read_to_string(page).unwrap());
        for piece in text.split("](").skip(1) {
            let target = piece.split(')').next().unwrap_or("");
            if target.starts_with("http") || target.is_empty() {
                continue;
            }
            let (file, fragment) = target.split_once('#').unwrap_or((target, ""));
            let linked = if file.is_empty() { page.clone() } else { page.parent().unwrap().join(file) };
            assert!(linked.exists(), "{}: link to {target}: no such file", page.display());
            if !fragment.is_empty() {
                let headings: Vec<String> = std::fs::read_to_string(&linked)
                    .unwrap()
                    .lines()
                    .filter_map(|l| l.trim_start_matches('#').strip_prefix(' ').filter(|_| l.starts_with('#')))
                    .map(anchor)
                    .collect();
                assert!(
                    headings.iter().any(|h| h == fragment),
                    "{}: link to {target}: no such heading",
                    page.display()
                );
            }
            checked += 1;
        }
    }
    assert!(checked > 20, "only {checked} links checked");
}
