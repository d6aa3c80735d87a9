//! A kernel's WGSL source: fragments concatenated in order (WGSL has no includes), with
//! the map from lines of the whole back to fragment files for diagnostics.

use std::borrow::Cow;

/// One WGSL file: under `kernels/wgsl/` and embedded at compile time for registry
/// kernels, or read at run time for external ones.
#[derive(Clone, Debug)]
pub struct Fragment {
    /// Path (relative to `kernels/wgsl/` for registry kernels).
    pub path: Cow<'static, str>,
    /// The file's text.
    pub text: Cow<'static, str>,
}

/// Embeds `kernels/wgsl/$path` as a [`Fragment`].
#[macro_export]
macro_rules! fragment {
    ($path:literal) => {
        $crate::source::Fragment {
            path: std::borrow::Cow::Borrowed(concat!("kernels/wgsl/", $path)),
            text: std::borrow::Cow::Borrowed(include_str!(concat!(env!("CARGO_MANIFEST_DIR"), "/wgsl/", $path))),
        }
    };
}

/// The concatenated source of a kernel.
#[derive(Clone, Debug)]
pub struct ComposedSource {
    /// The WGSL naga parses.
    pub text: String,
    /// (first line in `text`, 0-based; fragment path) in ascending order.
    starts: Vec<(usize, String)>,
}

impl ComposedSource {
    /// Concatenates `fragments`, each starting on a fresh line.
    pub fn compose(fragments: &[Fragment]) -> Self {
        let mut text = String::new();
        let mut starts = Vec::with_capacity(fragments.len());
        for fragment in fragments {
            starts.push((text.lines().count(), fragment.path.to_string()));
            text.push_str(&fragment.text);
            if !text.ends_with('\n') {
                text.push('\n');
            }
        }
        Self { text, starts }
    }

    /// The fragment and 1-based line within it of 1-based `line` of the composed text.
    pub fn locate(&self, line: usize) -> (&str, usize) {
        let zero_based = line.saturating_sub(1);
        let (start, path) = self
            .starts
            .iter()
            .rev()
            .find(|(start, _)| *start <= zero_based)
            .map_or((0, "<unknown>"), |(start, path)| (*start, path.as_str()));
        (path, zero_based - start + 1)
    }

    /// "fragment:line" for a byte offset into the composed text.
    pub fn describe_offset(&self, offset: usize) -> String {
        let line = self.text[..offset.min(self.text.len())].lines().count().max(1);
        let line = if self.text[..offset.min(self.text.len())].ends_with('\n') { line + 1 } else { line };
        let (path, local) = self.locate(line);
        format!("{path}:{local}")
    }
}

/// The WGSL a WebGPU implementation (Tint, in Chromium) compiles for a kernel: `source`,
/// with `enable subgroups;` put first where the kernel uses subgroup operations
/// (`subgroups`) and does not say so; naga needs no such line, WebGPU does. Returns the
/// text and how many lines were put before the source (for mapping compiler lines back).
/// The WebGPU backend and the kernel package's ES module both use it.
pub fn webgpu_source(source: &str, subgroups: bool) -> (String, u64) {
    let enables = source.lines().any(|line| {
        let line = line.trim_start();
        line.starts_with("enable") && line.contains("subgroups")
    });
    if subgroups && !enables { (format!("enable subgroups;\n{source}"), 1) } else { (source.to_string(), 0) }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_map_back_to_fragments() {
        let source = ComposedSource::compose(&[
            Fragment { path: "a.wgsl".into(), text: "one\ntwo\n".into() },
            Fragment { path: "b.wgsl".into(), text: "three\nfour".into() },
            Fragment { path: "c.wgsl".into(), text: "five\n".into() },
        ]);
        assert_eq!(source.locate(1), ("a.wgsl", 1));
        assert_eq!(source.locate(2), ("a.wgsl", 2));
        assert_eq!(source.locate(3), ("b.wgsl", 1));
        assert_eq!(source.locate(4), ("b.wgsl", 2));
        assert_eq!(source.locate(5), ("c.wgsl", 1));
        let four = source.text.find("four").unwrap();
        assert_eq!(source.describe_offset(four), "b.wgsl:2");
        assert_eq!(source.describe_offset(0), "a.wgsl:1");
    }

    #[test]
    fn subgroup_kernels_enable_subgroups_once() {
        assert_eq!(webgpu_source("fn f() {}", true), ("enable subgroups;\nfn f() {}".to_string(), 1));
        assert_eq!(
            webgpu_source("enable subgroups;\nfn f() {}", true),
            ("enable subgroups;\nfn f() {}".to_string(), 0)
        );
        assert_eq!(webgpu_source("fn f() {}", false), ("fn f() {}".to_string(), 0));
    }
}
