//! What each WGSL file of `kernels/wgsl/` uses, named in the file itself, and the
//! fragment order of a kernel derived from those names.
//!
//! WGSL has no includes, so a kernel is its files concatenated ([`crate::source`]). Each
//! file names the files it uses in comment lines of its own, which keep it plain WGSL for
//! every other tool:
//!
//! ```wgsl
//! // #import restir/reservoir.wgsl
//! // #requires var<storage, read> spans: array<ClusterSpan>
//! ```
//!
//! * `#import PATH` (relative to `kernels/wgsl/`): a file whose declarations this one uses.
//!   A kernel is its entry file with every file it imports, directly or not, each once,
//!   every file after the files it imports ([`kernel_fragments`]); a kernel in the
//!   catalogue names its entry file only.
//! * `#requires DECLARATION`: a binding the file reads whose binding number belongs to the
//!   kernel that includes it, declared there (`block_reuse.wgsl` reads the histogram's
//!   output under the numbers each ReSTIR pass gives it), or a function the including
//!   kernel declares (`strata/histogram.wgsl` reads the slots through
//!   `slot_cluster_key`, which each histogram entry takes from the storage it uses). The
//!   declaration is written as the including kernel declares it, without
//!   `@group`/`@binding`, a function by its signature. A file that imports another names
//!   only the requirements the other does not already name: the test gives every
//!   `#requires` line of a file's imports its own stand-in, so a name required twice
//!   would be declared twice.
//!
//! The test `every_file_parses_with_what_it_names` makes the names true: each file,
//! with only the files it imports and the bindings it requires, must parse with naga,
//! so a file that uses a declaration it does not name fails there, naming itself.
//! (Models: Bevy's shaders name their imports through naga_oil's `#import`; naga_oil
//! follows naga's releases a step behind ours, and its modules rename what they export,
//! which the exported kernels and their line maps would then carry.)

use crate::source::Fragment;

/// The prefix of an import line.
const IMPORT: &str = "// #import ";
/// The prefix of a required binding's line.
const REQUIRES: &str = "// #requires ";

/// The paths `text` imports, in the order written.
pub fn imports(text: &str) -> Vec<&str> {
    directive_lines(text, IMPORT)
}

/// The binding declarations `text` requires of the kernel that includes it.
pub fn requires(text: &str) -> Vec<&str> {
    directive_lines(text, REQUIRES)
}

fn directive_lines<'a>(text: &'a str, prefix: &str) -> Vec<&'a str> {
    text.lines().filter_map(|line| line.strip_prefix(prefix)).map(str::trim).filter(|rest| !rest.is_empty()).collect()
}

/// A kernel's fragments: every file `entry` imports, directly or through others, each
/// once and after the files it imports itself, then `entry`. `file` gives a file by its
/// path (relative to `kernels/wgsl/`). An unknown path or a circle of imports is an
/// error naming the files.
pub fn kernel_fragments(entry: &str, file: &dyn Fn(&str) -> Option<Fragment>) -> Result<Vec<Fragment>, String> {
    let mut ordered = Vec::new();
    let mut open = Vec::new();
    visit(entry, None, file, &mut open, &mut ordered)?;
    Ok(ordered)
}

/// Depth-first: `path`'s imports, then `path` (post-order); `open` holds the chain being
/// visited, for circles.
fn visit(
    path: &str,
    importer: Option<&str>,
    file: &dyn Fn(&str) -> Option<Fragment>,
    open: &mut Vec<String>,
    ordered: &mut Vec<Fragment>,
) -> Result<(), String> {
    if ordered.iter().any(|done: &Fragment| wgsl_path(done) == path) {
        return Ok(());
    }
    if let Some(start) = open.iter().position(|p| p == path) {
        let mut chain = open[start..].to_vec();
        chain.push(path.to_string());
        return Err(format!("kernels/wgsl: a circle of imports: {}", chain.join(" -> ")));
    }
    let fragment = file(path).ok_or_else(|| match importer {
        Some(importer) => format!("kernels/wgsl/{importer}: imports {path}, which is not a WGSL file of kernels/wgsl"),
        None => format!("kernels/wgsl/{path}: not a WGSL file of kernels/wgsl"),
    })?;
    open.push(path.to_string());
    for import in imports(&fragment.text) {
        visit(import, Some(path), file, open, ordered)?;
    }
    open.pop();
    ordered.push(fragment);
    Ok(())
}

/// A fragment's path relative to `kernels/wgsl/`.
pub fn wgsl_path(fragment: &Fragment) -> &str {
    fragment.path.strip_prefix("kernels/wgsl/").unwrap_or(&fragment.path)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn files(list: &'static [(&'static str, &'static str)]) -> impl Fn(&str) -> Option<Fragment> {
        move |path| {
            list.iter()
                .find(|(p, _)| *p == path)
                .map(|(p, text)| Fragment { path: format!("kernels/wgsl/{p}").into(), text: (*text).into() })
        }
    }

    fn order(fragments: &[Fragment]) -> Vec<&str> {
        fragments.iter().map(wgsl_path).collect()
    }

    #[test]
    fn imports_come_first_each_once() {
        let file = files(&[
            ("entry.wgsl", "// #import b.wgsl\n// #import a.wgsl\nfn main() {}\n"),
            ("a.wgsl", "// #import c.wgsl\nfn a() {}\n"),
            ("b.wgsl", "// #import c.wgsl\n// #import a.wgsl\nfn b() {}\n"),
            ("c.wgsl", "fn c() {}\n"),
        ]);
        let fragments = kernel_fragments("entry.wgsl", &file).unwrap();
        assert_eq!(order(&fragments), ["c.wgsl", "a.wgsl", "b.wgsl", "entry.wgsl"]);
    }

    #[test]
    fn directives_are_whole_comment_lines() {
        let text = "// #import a.wgsl\n  // #import not_at_line_start.wgsl\n// #requires var<storage, read> s: array<u32>\n// #import \nfn f() {} // #import trailing.wgsl\n";
        assert_eq!(imports(text), ["a.wgsl"]);
        assert_eq!(requires(text), ["var<storage, read> s: array<u32>"]);
    }

    /// Each file of `kernels/wgsl/` without an entry point parses with naga given only the
    /// files it imports (directly or not) and stand-ins for the bindings they require: so
    /// every declaration it uses is one it names. (An entry file's kernel is exactly its
    /// imports and itself, which the registry parses and validates.)
    #[test]
    fn every_file_parses_with_what_it_names() {
        let mut failures = Vec::new();
        for file in crate::wgsl_files::WGSL_FILES {
            let path = wgsl_path(file);
            if file.text.contains("@compute") {
                continue;
            }
            let fragments = match kernel_fragments(path, &crate::wgsl_files::wgsl_file) {
                Ok(fragments) => fragments,
                Err(error) => {
                    failures.push(error);
                    continue;
                }
            };
            let stand_ins: String = fragments
                .iter()
                .flat_map(|f| requires(&f.text))
                .filter(|declaration| !fragments.iter().any(|f| declares(&f.text, declaration)))
                .enumerate()
                .map(|(binding, declaration)| stand_in(binding, declaration))
                .collect();
            let mut all = fragments.clone();
            all.push(Fragment { path: "(the required bindings)".into(), text: stand_ins.into() });
            let source = crate::source::ComposedSource::compose(&all);
            if let Err(error) = naga::front::wgsl::parse_str(&source.text) {
                let place = error
                    .location(&source.text)
                    .map(|at| {
                        let (fragment, line) = source.locate(at.line_number as usize);
                        format!(" at {fragment}:{line}")
                    })
                    .unwrap_or_default();
                failures.push(format!("kernels/wgsl/{path} with its imports{place}: {}", error.message()));
            }
        }
        assert!(failures.is_empty(), "files that use what they do not import:\n{}", failures.join("\n"));
    }

    /// The name a required declaration declares: `var<storage, read> spans: ...` gives
    /// `spans`, `fn lane_exchange(...) -> ...` gives `lane_exchange`.
    fn declared_name(declaration: &str) -> &str {
        let rest = declaration.strip_prefix("fn ").unwrap_or_else(|| {
            declaration.strip_prefix("var").map_or(declaration, |d| d.split_once('>').map_or(d, |(_, after)| after))
        });
        rest.trim_start().split(|c: char| !(c.is_alphanumeric() || c == '_')).next().unwrap_or("")
    }

    /// Whether `text` declares what `declaration` requires at module scope (a kernel's entry
    /// file, or a file that declares it for every includer, such as the scene's `nodes`).
    fn declares(text: &str, declaration: &str) -> bool {
        let name = declared_name(declaration);
        let kind = if declaration.starts_with("fn ") { "fn" } else { "var" };
        text.lines().any(|line| {
            let mut words = line.split_whitespace().skip_while(|w| w.starts_with('@'));
            let first = words.next().unwrap_or("");
            let named = if kind == "fn" { first == "fn" } else { first.starts_with("var") };
            let rest = line.split_once(if kind == "fn" { "fn " } else { ">" }).map_or("", |(_, r)| r).trim_start();
            named && !line.starts_with(char::is_whitespace) && rest.starts_with(name) && {
                let after = &rest[name.len()..];
                after.starts_with(|c: char| c == ':' || c == '(' || c.is_whitespace())
            }
        })
    }

    /// A stand-in for a required declaration: the binding at `@group(63) @binding(n)`, the
    /// workgroup or private variable as declared, or the function returning its result
    /// type's zero value.
    fn stand_in(binding: usize, declaration: &str) -> String {
        match declaration.strip_prefix("fn ") {
            Some(_) => match declaration.split_once("->") {
                Some((_, result)) => format!("{declaration} {{ return {}(); }}\n", result.trim()),
                None => format!("{declaration} {{}}\n"),
            },
            None if declaration.starts_with("var<workgroup>") || declaration.starts_with("var<private>") => {
                format!("{declaration};\n")
            }
            None => format!("@group(63) @binding({binding}) {declaration};\n"),
        }
    }

    #[test]
    fn unknown_files_and_circles_are_errors_naming_the_files() {
        let file = files(&[("entry.wgsl", "// #import missing.wgsl\n")]);
        let error = kernel_fragments("entry.wgsl", &file).unwrap_err();
        assert!(error.contains("kernels/wgsl/entry.wgsl: imports missing.wgsl"), "{error}");

        let file = files(&[
            ("entry.wgsl", "// #import a.wgsl\n"),
            ("a.wgsl", "// #import b.wgsl\n"),
            ("b.wgsl", "// #import a.wgsl\n"),
        ]);
        let error = kernel_fragments("entry.wgsl", &file).unwrap_err();
        assert!(error.contains("a.wgsl -> b.wgsl -> a.wgsl"), "{error}");
    }
}
