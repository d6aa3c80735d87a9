//! `errors-csv`: the `errors.csv` of `strata compare` through `parse_errors_csv` (as
//! `strata plot` reads it: the bytes must be UTF-8 first). Structure-aware mutations
//! replace one field with an edge value (`NaN`, `inf`, `-1`, `0`, empty, `4294967296`,
//! an unknown method), or add or drop a field or line.
//!
//! The reader is the evaluation's (the host crate `strata`, which stands beside this one
//! on strata-render, not below it), so the program that runs the campaign hands it in
//! ([`Readers::errors_csv`](super::super::Readers::errors_csv)).

use super::super::mutate::{EDGE_NUMBERS, FuzzRng, mutate_lines};
use super::super::{Outcome, Target};
use arbitrary::Unstructured;
use rand::Rng;
use std::path::Path;
use strata_render::restir::Method;

/// The target, over the reader it was handed.
pub(super) struct ErrorsCsv {
    /// `parse_errors_csv`: each accepted row's RelMSE, pRelMSE, MSE and luminance RelMSE.
    pub(super) read: fn(&str) -> Result<Vec<[f64; 4]>, String>,
}

/// Two earlier headers, which the reader still reads: the generator's.
const HEADERS: [&str; 2] =
    ["method,frame,seed,relmse,prelmse,mse,relmse_luminance", "method,frame,seed,relmse,prelmse,mse"];

/// The header `strata compare` writes today (`evaluation::compare::errors_csv`), which
/// the seeds carry; a test of the workspace (`fuzz_regressions`) holds the complete grid
/// below to the bytes that writer gives for it.
const WRITTEN_HEADER: &str = "method,frame,seed,relmse,prelmse,mse,relmse_luminance,flip,block_edge";

impl Target for ErrorsCsv {
    fn name(&self) -> &'static str {
        "errors-csv"
    }

    fn seeds(&self, _shared: Option<&Path>) -> Vec<Vec<u8>> {
        // A complete grid (every method at every frame and seed), as `compare` writes it:
        // frames 1-based, errors as `{:.6e}`, an unknown value an empty field.
        let mut grid = format!("{WRITTEN_HEADER}\n");
        for (index, method) in [Method::Strata, Method::Restir, Method::RestirDisc].into_iter().enumerate() {
            for frame in 0..3u32 {
                for seed in 1..=2 {
                    let relmse = 0.5 / f64::from(frame + 1) + 0.01 * index as f64;
                    let luminance = if frame != 1 { format!("{:.6e}", 0.125) } else { String::new() };
                    let (name, prelmse, mse) = (method.name(), 0.25, 1e-3);
                    grid +=
                        &format!("{name},{},{seed},{relmse:.6e},{prelmse:.6e},{mse:.6e},{luminance},,\n", frame + 1);
                }
            }
        }
        let old = format!("{}\nrestir-disc,3,8,0.5,0.25,1e-3\nstrata,3,8,1,1,1\n\n", HEADERS[1]);
        vec![grid.into_bytes(), old.into_bytes()]
    }

    fn generate(&self, u: &mut Unstructured) -> arbitrary::Result<Vec<u8>> {
        let mut text = format!("{}\n", u.choose(&HEADERS)?);
        for _ in 0..u.int_in_range(0..=6)? {
            let mut fields = vec![u.choose(&["strata", "restir", "restir-disc", "Strata", "", "x"])?.to_string()];
            for _ in 0..u.int_in_range(4..=7)? {
                fields.push(if u.ratio(1, 3)? {
                    u.choose(EDGE_NUMBERS)?.to_string()
                } else {
                    u.int_in_range(0u32..=9)?.to_string()
                });
            }
            text += &fields.join(",");
            text += u.choose(&["\n", "\r\n", ""])?;
        }
        Ok(text.into_bytes())
    }

    fn mutate(&self, rng: &mut FuzzRng, input: &[u8]) -> Option<Vec<u8>> {
        let text = std::str::from_utf8(input).ok()?;
        if rng.random_range(0..3) == 0 {
            let mut bytes = input.to_vec();
            mutate_lines(rng, &mut bytes);
            return Some(bytes);
        }
        let mut lines: Vec<String> = text.lines().map(String::from).collect();
        if lines.len() < 2 {
            return None;
        }
        let line = 1 + rng.random_range(0..lines.len() - 1);
        let mut fields: Vec<String> = lines[line].split(',').map(String::from).collect();
        let field = rng.random_range(0..fields.len());
        match rng.random_range(0..4) {
            0 => {
                fields.remove(field);
            }
            1 => fields.insert(field, "0".into()),
            2 if field == 0 => fields[0] = ["", "STRATA", "restir_disc", "strata "][rng.random_range(0..4)].into(),
            _ => fields[field] = EDGE_NUMBERS[rng.random_range(0..EDGE_NUMBERS.len())].into(),
        }
        lines[line] = fields.join(",");
        Some(lines.join("\n").into_bytes())
    }

    fn execute(&self, input: &[u8]) -> Outcome {
        let Ok(text) = std::str::from_utf8(input) else { return Outcome::Refused("not UTF-8".into()) };
        match (self.read)(text) {
            Ok(rows) => {
                let values: Vec<f64> = rows.into_iter().flatten().collect();
                if values.iter().any(|v| !v.is_finite()) {
                    Outcome::Noted("rows accepted with non-finite errors".into())
                } else if values.iter().any(|v| *v < 0.0) {
                    Outcome::Noted("rows accepted with negative errors".into())
                } else {
                    Outcome::Accepted
                }
            }
            Err(message) => Outcome::Refused(message),
        }
    }
}
