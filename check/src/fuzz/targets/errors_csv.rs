//! `errors-csv`: the `errors.csv` of `strata compare` through `parse_errors_csv` (as
//! `strata plot` reads it: the bytes must be UTF-8 first). Structure-aware mutations
//! replace one field with an edge value (`NaN`, `inf`, `-1`, `0`, empty, `4294967296`,
//! an unknown method), or add or drop a field or line.

use super::super::mutate::{EDGE_NUMBERS, FuzzRng, mutate_lines};
use super::super::{Outcome, Target};
use arbitrary::Unstructured;
use rand::Rng;
use std::path::Path;
use strata::evaluation::compare::{FrameError, errors_csv, parse_errors_csv};
use strata::restir::Method;

/// The target.
pub(super) struct ErrorsCsv;

/// The two headers the parser reads.
const HEADERS: [&str; 2] =
    ["method,frame,seed,relmse,prelmse,mse,relmse_luminance", "method,frame,seed,relmse,prelmse,mse"];

impl Target for ErrorsCsv {
    fn name(&self) -> &'static str {
        "errors-csv"
    }

    fn seeds(&self, _shared: Option<&Path>) -> Vec<Vec<u8>> {
        // Complete grids (every method at every frame and seed), as `compare` writes them.
        let mut errors = Vec::new();
        for (index, method) in [Method::Strata, Method::Restir, Method::RestirDisc].into_iter().enumerate() {
            for frame in 0..3 {
                for seed in 1..=2 {
                    errors.push(FrameError {
                        method,
                        frame,
                        seed,
                        relmse: 0.5 / f64::from(frame + 1) + 0.01 * index as f64,
                        prelmse: 0.25,
                        mse: 1e-3,
                        relmse_luminance: (frame != 1).then_some(0.125),
                        flip: None,
                        block_edge: None,
                    });
                }
            }
        }
        let old = format!("{}\nrestir-disc,3,8,0.5,0.25,1e-3\nstrata,3,8,1,1,1\n\n", HEADERS[1]);
        vec![errors_csv(&errors).into_bytes(), old.into_bytes()]
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
        match parse_errors_csv(text) {
            Ok(errors) => {
                let values =
                    errors.iter().flat_map(|e| [e.relmse, e.prelmse, e.mse, e.relmse_luminance.unwrap_or(0.0)]);
                let values: Vec<f64> = values.collect();
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
