//! The fuzz targets, one loader each, and what their generators share.

mod errors_csv;
mod exr;
mod gltf;
mod obj;
mod ply;
mod scene_json;

use super::mutate::EDGE_NUMBERS;
use super::{Readers, Target};
use arbitrary::Unstructured;

/// Every target, in the order `cargo xtask fuzz` runs them.
pub(super) fn all(readers: Readers) -> Vec<Box<dyn Target>> {
    let mut targets = render_loaders();
    targets.push(Box::new(errors_csv::ErrorsCsv { read: readers.errors_csv }));
    targets
}

/// The targets of strata-render's loaders, which this crate links.
fn render_loaders() -> Vec<Box<dyn Target>> {
    vec![
        Box::new(scene_json::SceneJson::new()),
        Box::new(ply::Ply),
        Box::new(gltf::Gltf::new()),
        Box::new(obj::Obj::new()),
        Box::new(exr::Exr::new()),
    ]
}

/// A number as text for a generated file: mostly plausible, sometimes an edge value
/// (`NaN`, `1e39`, `-1`, ...), sometimes any f32 bit pattern.
pub(super) fn number(u: &mut Unstructured) -> arbitrary::Result<String> {
    Ok(match u.int_in_range(0..=9)? {
        0 => u.choose(EDGE_NUMBERS)?.to_string(),
        1 => format!("{:?}", f32::from_bits(u.arbitrary()?)),
        _ => format!("{}", f64::from(u.int_in_range(-2000i32..=2000)?) / 100.0),
    })
}

/// A small count for a generated file: mostly 0–8, sometimes an edge value.
pub(super) fn count(u: &mut Unstructured) -> arbitrary::Result<String> {
    Ok(match u.int_in_range(0..=7)? {
        0 => u.choose(&["0", "-1", "4294967295", "4294967296", "18446744073709551615", "1000000000"])?.to_string(),
        _ => u.int_in_range(0u32..=8)?.to_string(),
    })
}

#[cfg(test)]
mod tests {
    use super::super::{Verdict, execute};

    /// The seeds written in code load (so that mutants start from files that reach deep),
    /// except those written to be refused. (`errors-csv`'s, whose reader is handed in, are
    /// the `fuzz_regressions` test's.)
    #[test]
    fn seeds_written_in_code_are_accepted() {
        for target in super::render_loaders() {
            let seeds = target.seeds(None);
            let verdicts: Vec<Verdict> = seeds.iter().map(|s| execute(target.as_ref(), s)).collect();
            let refused: Vec<String> = verdicts
                .iter()
                .enumerate()
                .filter(|(_, v)| !matches!(v, Verdict::Accepted | Verdict::Noted(_)))
                .map(|(i, v)| format!("seed {i}: {v:?}"))
                .collect();
            // exr: the grey image (no R channel) and the one with a NaN pixel, which both
            // its loaders refuse.
            let expected = match target.name() {
                "exr" => 2,
                _ => 0,
            };
            assert_eq!(refused.len(), expected, "{}: {refused:#?}", target.name());
        }
    }
}
