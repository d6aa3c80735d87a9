//! Every relative link and every cited repository path in the docs resolves (issue 57).
//!
//! Which files: every tracked `*.md` file (`git ls-files`; without git, a walk of the
//! repository that skips `target/` and `.git/`), and the header comment of every
//! `kernels/wgsl/**/*.wgsl` (its leading comment and blank lines, up to the first line of
//! code).
//!
//! Links (Markdown only, outside code): every `[text](target)` and reference definition
//! `[name]: target` whose target has no scheme (`https:`, `mailto:`, ...) must name a file
//! or folder that exists relative to the page; a `#anchor` (alone, or after a `.md` file)
//! must be the GitHub slug of a heading of that page: the heading's text lower-cased, every
//! character but letters, digits, `-`, `_` and spaces dropped, spaces turned into `-`, and
//! `-1`, `-2`, ... after repeats.
//!
//! Cited paths: in Markdown, a code span (text between backticks, outside fenced blocks)
//! that is one word holding a `/` and ending in one of [`PATH_EXTENSIONS`]; in a WGSL
//! header, every such word of the comment (surrounding brackets and punctuation trimmed).
//! A word holding `*`, `?`, `<`, `>`, `{`, `}`, `[`, `]`, `$`, `|`, `:`, `...`, `//`, or
//! starting with `/` or `~`, is a pattern or placeholder, not a path. A path resolves if it
//! exists relative to the repository root, to the citing file's folder, or (a `.wgsl` path)
//! to `kernels/wgsl/` or as a module the kernels crate generates (`gpu/restir.wgsl`); a
//! path whose first folder is not one of the repository's top-level entries may also be
//! the tail of a tracked file (`cpu_backend/limit.rs` for
//! `backends/src/cpu_backend/limit.rs`, in a text that names the crate). Paths inside the
//! folders of [`OUTSIDE_PREFIXES`] describe files outside the repository and are skipped.
//!
//! Failures name `file:line` and the missing target, all of them at once.
//!
//! A second test holds the README and BENCHMARKS.md to issue 57's limits: at most 250 words
//! before "## Quick start" and 900 in all (words: whitespace-separated tokens outside
//! fenced code that hold a letter or digit), and a summary of at most 400 lines whose every
//! topic row names a command and a date.

use std::collections::{BTreeSet, HashMap};
use std::path::{Path, PathBuf};
use std::process::Command;

/// The extensions that make a backticked word a repository path.
const PATH_EXTENSIONS: &[&str] = &["rs", "wgsl", "md", "json", "toml", "h", "c", "cpp", "cmake", "py", "sh", "ply"];

/// Folders the docs describe that are not in the repository: the exported kernel package's
/// `include/` and `lib/` (export/package/README.md, RELIABILITY.md), and mitsuba-data's
/// `common/` (the scenes' sources).
const OUTSIDE_PREFIXES: &[&str] = &["include/", "lib/", "common/"];

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap().to_path_buf()
}

/// Every tracked file, relative to `root`, with `/` separators.
fn tracked_files(root: &Path) -> Vec<String> {
    let listed = Command::new("git").arg("ls-files").arg("-z").current_dir(root).output();
    if let Ok(out) = listed
        && out.status.success()
    {
        return String::from_utf8_lossy(&out.stdout)
            .split('\0')
            .filter(|f| !f.is_empty() && root.join(f).is_file())
            .map(str::to_owned)
            .collect();
    }
    let mut found = Vec::new();
    walk(root, "", &mut found);
    found
}

fn walk(folder: &Path, prefix: &str, found: &mut Vec<String>) {
    let Ok(entries) = std::fs::read_dir(folder) else { return };
    for entry in entries.filter_map(Result::ok) {
        let name = entry.file_name().to_string_lossy().into_owned();
        let relative = format!("{prefix}{name}");
        let path = entry.path();
        if path.is_dir() {
            if name != "target" && name != ".git" {
                walk(&path, &format!("{relative}/"), found);
            }
        } else {
            found.push(relative);
        }
    }
}

/// GitHub's anchor of a heading's text (before repeats are numbered).
fn slug(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || matches!(c, '-' | '_' | ' '))
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

/// One line of a Markdown page: its text outside code, and the code spans that start on it.
struct Line {
    number: usize,
    prose: String,
    spans: Vec<String>,
}

/// The page's lines outside fenced code blocks, split into prose and code spans (a span
/// may run over several lines; it is reported on the line where it starts).
fn parse_markdown(text: &str) -> Vec<Line> {
    let mut lines = Vec::new();
    let mut fence: Option<&str> = None;
    // The backtick run that opened the current code span, its text and its line.
    let mut open: Option<(usize, String, usize)> = None;
    for (index, raw) in text.lines().enumerate() {
        let number = index + 1;
        let trimmed = raw.trim_start();
        if let Some(marker) = fence {
            if trimmed.starts_with(marker) {
                fence = None;
            }
            continue;
        }
        if open.is_none() {
            if trimmed.starts_with("```") {
                fence = Some("```");
                continue;
            }
            if trimmed.starts_with("~~~") {
                fence = Some("~~~");
                continue;
            }
        }
        let mut line = Line { number, prose: String::new(), spans: Vec::new() };
        let chars: Vec<char> = raw.chars().collect();
        let mut i = 0;
        while i < chars.len() {
            if chars[i] == '`' {
                let run = chars[i..].iter().take_while(|&&c| c == '`').count();
                i += run;
                match open.take() {
                    Some((ticks, text, start)) if ticks == run => {
                        if start == number {
                            line.spans.push(text);
                        } else if let Some(earlier) = lines.iter_mut().rev().find(|l: &&mut Line| l.number == start) {
                            earlier.spans.push(text);
                        }
                    }
                    Some((ticks, mut text, start)) => {
                        text.extend(std::iter::repeat_n('`', run));
                        open = Some((ticks, text, start));
                    }
                    None => open = Some((run, String::new(), number)),
                }
                continue;
            }
            match open.as_mut() {
                Some((_, text, _)) => text.push(chars[i]),
                None => line.prose.push(chars[i]),
            }
            i += 1;
        }
        if let Some((_, text, _)) = open.as_mut() {
            text.push(' ');
        }
        // A blank line ends a paragraph, and an unclosed backtick with it.
        if raw.trim().is_empty()
            && let Some((ticks, text, _)) = open.take()
        {
            line.prose.push_str(&"`".repeat(ticks));
            line.prose.push_str(&text);
        }
        lines.push(line);
    }
    lines
}

/// The anchors of a Markdown page's headings (outside fenced blocks), repeats numbered as
/// GitHub does; a heading's code spans count by their text.
fn anchors(text: &str) -> BTreeSet<String> {
    let mut seen: HashMap<String, usize> = HashMap::new();
    let mut found = BTreeSet::new();
    let mut fenced = false;
    for raw in text.lines() {
        let trimmed = raw.trim_start();
        if trimmed.starts_with("```") || trimmed.starts_with("~~~") {
            fenced = !fenced;
            continue;
        }
        let hashes = raw.chars().take_while(|&c| c == '#').count();
        if fenced || !(1..=6).contains(&hashes) || !raw[hashes..].starts_with(' ') {
            continue;
        }
        let base = slug(&raw[hashes..].trim_end_matches(['#', ' ']).replace('`', ""));
        let count = seen.entry(base.clone()).or_insert(0);
        found.insert(if *count == 0 { base.clone() } else { format!("{base}-{count}") });
        *count += 1;
    }
    found
}

/// The link targets in a line's prose: `](target)` and a reference definition's target.
fn link_targets(prose: &str) -> Vec<String> {
    let mut targets = Vec::new();
    for piece in prose.split("](").skip(1) {
        let inner = piece.split(')').next().unwrap_or("");
        let target = inner.trim().trim_start_matches('<').split(['>', ' ']).next().unwrap_or("");
        targets.push(target.to_owned());
    }
    let trimmed = prose.trim_start();
    if trimmed.starts_with('[')
        && let Some((label, rest)) = trimmed.split_once("]:")
        && !label.contains(']')
    {
        targets.push(rest.split_whitespace().next().unwrap_or("").to_owned());
    }
    targets.into_iter().filter(|t| !t.is_empty() && !has_scheme(t)).collect()
}

fn has_scheme(target: &str) -> bool {
    target.split_once(':').is_some_and(|(scheme, _)| {
        !scheme.is_empty() && scheme.chars().all(|c| c.is_ascii_alphanumeric() || matches!(c, '+' | '-' | '.'))
    })
}

/// Whether `word` counts as a cited repository path (see the module's comment).
fn is_cited_path(word: &str) -> bool {
    word.contains('/')
        && !word.contains(char::is_whitespace)
        && !word.contains(['*', '?', '<', '>', '{', '}', '[', ']', '$', '|', ':'])
        && !word.contains("...")
        && !word.contains("//")
        && !word.starts_with(['/', '~'])
        && word.rsplit_once('.').is_some_and(|(stem, ext)| !stem.ends_with('/') && PATH_EXTENSIONS.contains(&ext))
        && !OUTSIDE_PREFIXES.iter().any(|p| word.starts_with(p))
}

struct Repository {
    root: PathBuf,
    files: Vec<String>,
    top_level: BTreeSet<String>,
}

impl Repository {
    fn open() -> Self {
        let root = root();
        let files = tracked_files(&root);
        let top_level = std::fs::read_dir(&root)
            .unwrap()
            .filter_map(Result::ok)
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .collect();
        Repository { root, files, top_level }
    }

    /// Whether `path`, cited in the file `citing` (relative to the root), resolves.
    fn resolves(&self, path: &str, citing: &str) -> bool {
        let folder = Path::new(citing).parent().unwrap_or(Path::new(""));
        if self.root.join(path).exists() || self.root.join(folder).join(path).exists() {
            return true;
        }
        if path.ends_with(".wgsl") && self.root.join("kernels/wgsl").join(path).exists() {
            return true;
        }
        // A generated WGSL module (`gpu/restir.wgsl`): no file, but imported like one.
        if path.starts_with(strata_kernels::wgsl_files::GENERATED)
            && strata_kernels::wgsl_files::wgsl_file(path).is_some()
        {
            return true;
        }
        let first = path.split('/').next().unwrap_or("");
        !self.top_level.contains(first) && self.files.iter().any(|f| f.ends_with(&format!("/{path}")))
    }
}

/// What the check found: the problems, and how many links and paths it checked.
#[derive(Default)]
struct Findings {
    problems: Vec<String>,
    links: usize,
    paths: usize,
}

fn check_markdown(repo: &Repository, page: &str, findings: &mut Findings) {
    let text = std::fs::read_to_string(repo.root.join(page)).unwrap();
    let folder = Path::new(page).parent().unwrap_or(Path::new(""));
    for line in parse_markdown(&text) {
        for target in link_targets(&line.prose) {
            findings.links += 1;
            let (file, fragment) = target.split_once('#').unwrap_or((&target, ""));
            let file = file.replace("%20", " ");
            // The target relative to the repository root, then on disk.
            let relative = if file.is_empty() { PathBuf::from(page) } else { normalise(&folder.join(&file)) };
            let linked = repo.root.join(&relative);
            if !linked.exists() {
                findings.problems.push(format!(
                    "{page}:{}: link `{target}`: no file {}",
                    line.number,
                    relative.display()
                ));
                continue;
            }
            if !fragment.is_empty() && linked.is_file() && linked.extension().is_some_and(|e| e == "md") {
                let headings = anchors(&std::fs::read_to_string(&linked).unwrap());
                if !headings.contains(fragment) {
                    findings.problems.push(format!(
                        "{page}:{}: link `{target}`: no heading with the anchor #{fragment} in {}",
                        line.number,
                        relative.display()
                    ));
                }
            }
        }
        for span in &line.spans {
            let word = span.trim();
            if is_cited_path(word) {
                findings.paths += 1;
                if !repo.resolves(word, page) {
                    findings.problems.push(format!("{page}:{}: cited path `{word}` does not exist", line.number));
                }
            }
        }
    }
}

/// `path` with its `.` and `..` parts resolved, as text (no file system access).
fn normalise(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for part in path.components() {
        match part {
            std::path::Component::CurDir => {}
            std::path::Component::ParentDir => {
                out.pop();
            }
            other => out.push(other),
        }
    }
    out
}

fn check_wgsl_header(repo: &Repository, file: &str, findings: &mut Findings) {
    let text = std::fs::read_to_string(repo.root.join(file)).unwrap();
    for (index, line) in text.lines().enumerate() {
        let trimmed = line.trim();
        if trimmed.is_empty() {
            continue;
        }
        let Some(comment) = trimmed.strip_prefix("//") else { break };
        for word in comment.split_whitespace() {
            // A path starts with a name character or `.` and ends with its extension.
            let word = word
                .trim_start_matches(|c: char| !(c.is_alphanumeric() || matches!(c, '_' | '.')))
                .trim_end_matches(|c: char| !c.is_alphanumeric());
            if is_cited_path(word) {
                findings.paths += 1;
                if !repo.resolves(word, file) {
                    findings.problems.push(format!("{file}:{}: cited path `{word}` does not exist", index + 1));
                }
            }
        }
    }
}

fn check(repo: &Repository) -> Findings {
    let mut findings = Findings::default();
    for file in &repo.files {
        if file.ends_with(".md") {
            check_markdown(repo, file, &mut findings);
        } else if file.starts_with("kernels/wgsl/") && file.ends_with(".wgsl") {
            check_wgsl_header(repo, file, &mut findings);
        }
    }
    findings
}

#[test]
fn every_relative_link_and_cited_path_in_the_docs_exists() {
    let repo = Repository::open();
    let findings = check(&repo);
    assert!(
        findings.problems.is_empty(),
        "{} broken links or cited paths:\n{}",
        findings.problems.len(),
        findings.problems.join("\n")
    );
    // A parser that found nothing would pass: the docs hold hundreds of each.
    assert!(findings.links > 100, "only {} links checked", findings.links);
    assert!(findings.paths > 100, "only {} cited paths checked", findings.paths);
}

#[test]
fn slugs_and_spans_are_read_as_github_does() {
    assert_eq!(
        slug("Levers: the temporal M cap (issue 20, temporal outliers)"),
        "levers-the-temporal-m-cap-issue-20-temporal-outliers"
    );
    assert_eq!(
        slug("Glossy primary hits resample: min_roughness 0.2 → 0.05 (issue 20)"),
        "glossy-primary-hits-resample-min_roughness-02--005-issue-20"
    );
    let page = "# A\n## `x` b\n## A\ntext `a/b.rs` and [l](c.md#d)\n```\n`not/code.rs` [no](x)\n```\n";
    let heads = anchors(page);
    assert_eq!(heads, BTreeSet::from(["a".to_owned(), "a-1".to_owned(), "x-b".to_owned()]));
    let lines = parse_markdown(page);
    let text: Vec<&Line> = lines.iter().filter(|l| l.number == 4).collect();
    assert_eq!(text[0].spans, ["a/b.rs"]);
    assert_eq!(link_targets(&text[0].prose), ["c.md#d"]);
    assert!(lines.iter().all(|l| l.number < 5 || l.number > 7), "a fenced block is skipped");
    assert!(is_cited_path("host/src/evaluation/compare.rs"));
    assert!(!is_cited_path("out/compare/report.html") && !is_cited_path("kernels/wgsl/**/*.wgsl"));
    assert!(!is_cited_path("include/strata.h") && !is_cited_path("cargo run -- a/b.rs"));
    assert!(has_scheme("https://example.org") && !has_scheme("docs/restir.md#why"));
    assert_eq!(words("a b\n| x | ± |\n```\nnot counted\n```\n## Stop\nc", "## Stop"), (3, 5));
}

/// Words of a Markdown text as the README's limits count them: whitespace-separated
/// tokens outside fenced code blocks that hold a letter or digit (a table's `|` and `---`
/// and a lone `±` are not words). Returns the words before the first line starting with
/// `stop` (all of them if none) and the words in all.
fn words(text: &str, stop: &str) -> (usize, usize) {
    let mut fenced = false;
    let (mut before, mut total) = (None, 0);
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if fenced {
            continue;
        }
        if before.is_none() && line.starts_with(stop) {
            before = Some(total);
        }
        total += line.split_whitespace().filter(|w| w.chars().any(char::is_alphanumeric)).count();
    }
    (before.unwrap_or(total), total)
}

/// The README reads in minutes (issue 57): at most 250 words before the quick start and 900
/// in all; BENCHMARKS.md is a summary of at most 400 lines whose every topic row gives a
/// command (a code span) and the date of its latest measurement.
#[test]
fn the_readme_and_the_benchmarks_summary_stay_short() {
    let root = root();
    let readme = std::fs::read_to_string(root.join("README.md")).unwrap();
    assert!(readme.lines().any(|l| l.starts_with("## Quick start")), "README.md has no \"## Quick start\"");
    let (before, total) = words(&readme, "## Quick start");
    assert!(before <= 250, "README.md: {before} words before the quick start (at most 250)");
    assert!(total <= 900, "README.md: {total} words in all (at most 900)");

    let summary = std::fs::read_to_string(root.join("BENCHMARKS.md")).unwrap();
    let lines = summary.lines().count();
    assert!(lines <= 400, "BENCHMARKS.md: {lines} lines (at most 400)");
    let rows: Vec<(usize, &str)> =
        summary.lines().enumerate().filter(|(_, l)| l.starts_with("| [") && l.contains("](docs/benchmarks/")).collect();
    assert!(rows.len() >= 10, "BENCHMARKS.md: {} topic rows", rows.len());
    for (index, row) in rows {
        let has_date = row.split(['|', ' ', '(', ')']).any(|w| {
            w.len() == 10
                && w.starts_with("20")
                && w.chars().enumerate().all(|(i, c)| if i == 4 || i == 7 { c == '-' } else { c.is_ascii_digit() })
        });
        assert!(row.contains('`') && has_date, "BENCHMARKS.md:{}: a topic row without a command or a date", index + 1);
    }
}
