//! How closely backends agree on a shader's outputs (`cargo xtask run`, the corpus
//! test): every output buffer of every backend against the same buffer of a reference
//! backend, word by word, with each word's kind read from the IR. Integer words
//! (`u32`, `i32`, atomics, ids, flags, counts) must be identical; `f32` words may differ
//! by a declared number of units in the last place; padding is skipped. The verdict
//! names how many words differ and the largest ULP distance, never only the first.

use crate::compare::ulp_distance;
use crate::run_data::BackendRun;
use strata_kernels::WordKind;

/// How far an `f32` word may be from the reference's.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FloatBound {
    /// Units in the last place (0: bit-exact).
    pub ulp: u32,
    /// Values this close in absolute terms pass whatever their ULP distance (0: off).
    /// A result that cancels to near zero (a difference of two velocities, or `log` of
    /// a value near one) keeps the absolute error of its operands, which is many ULPs of
    /// the small result; Vulkan states `log`'s precision near one this way (2^-21).
    pub abs: f32,
}

impl FloatBound {
    /// Whether `got` is within the bound of `want` (bit patterns).
    pub fn admits(&self, got: u32, want: u32) -> bool {
        ulp_distance(got, want) <= self.ulp || (f32::from_bits(got) - f32::from_bits(want)).abs() <= self.abs
    }
}

/// The bounds for `f32` words: one for every buffer, or per buffer name.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Tolerance {
    /// Bound for buffers not named in `per_buffer` (default: bit-exact).
    pub float: FloatBound,
    /// (WGSL variable name, bound) overrides.
    pub per_buffer: Vec<(String, FloatBound)>,
}

impl Tolerance {
    /// The bound for buffer `name`.
    pub fn bound_for(&self, name: &str) -> FloatBound {
        self.per_buffer.iter().find(|(n, _)| n == name).map_or(self.float, |(_, bound)| *bound)
    }

    /// The tolerance `--ulp` and `--abs` give (`cargo xtask run`): plain values for every
    /// buffer, `BUFFER=` ones for that buffer (whose other half falls back to the plain
    /// value). A bound given twice for the same target (two plain `--ulp`, or two
    /// `--abs out=...`) is refused naming both flags, never one of them silently kept;
    /// whether a named buffer exists is the run's check (in `run_kernel.rs`).
    pub fn from_flags(ulp: &[(Option<String>, u32)], abs: &[(Option<String>, f32)]) -> Result<Tolerance, String> {
        fn once<T: std::fmt::Display>(flag: &str, given: &[(Option<String>, T)]) -> Result<(), String> {
            for (index, (target, bound)) in given.iter().enumerate() {
                if let Some((_, first)) = given[..index].iter().find(|(t, _)| t == target) {
                    let text = |bound: &T| match target {
                        Some(name) => format!("{flag} {name}={bound}"),
                        None => format!("{flag} {bound}"),
                    };
                    let what = target.as_ref().map_or("every buffer".to_string(), |name| format!("`{name}`"));
                    return Err(format!(
                        "{}: the bound for {what} is given twice ({} first): give it once",
                        text(bound),
                        text(first)
                    ));
                }
            }
            Ok(())
        }
        once("--ulp", ulp)?;
        once("--abs", abs)?;
        let mut tolerance = Tolerance::default();
        if let Some((_, bound)) = ulp.iter().find(|(buffer, _)| buffer.is_none()) {
            tolerance.float.ulp = *bound;
        }
        if let Some((_, bound)) = abs.iter().find(|(buffer, _)| buffer.is_none()) {
            tolerance.float.abs = *bound;
        }
        let named = ulp.iter().filter_map(|(b, _)| b.clone()).chain(abs.iter().filter_map(|(b, _)| b.clone()));
        for name in named {
            if tolerance.per_buffer.iter().any(|(n, _)| *n == name) {
                continue;
            }
            let mut bound = tolerance.float;
            if let Some((_, ulp)) = ulp.iter().find(|(b, _)| b.as_deref() == Some(&name)) {
                bound.ulp = *ulp;
            }
            if let Some((_, abs)) = abs.iter().find(|(b, _)| b.as_deref() == Some(&name)) {
                bound.abs = *abs;
            }
            tolerance.per_buffer.push((name, bound));
        }
        Ok(tolerance)
    }
}

/// One backend's buffer against the reference's.
#[derive(Clone, Debug, PartialEq)]
pub struct BufferAgreement {
    /// The backend judged.
    pub backend: String,
    /// `@binding` number.
    pub binding: u32,
    /// WGSL variable name.
    pub name: String,
    /// Words compared (padding excluded).
    pub words: usize,
    /// Words not bit-identical (integers and floats).
    pub differing: usize,
    /// Integer words not identical.
    pub integers_differing: usize,
    /// Float words beyond the bound.
    pub floats_beyond: usize,
    /// Largest ULP distance among float words (NaN against a number counts as
    /// `u32::MAX`).
    pub max_ulp: u32,
    /// Largest distance in 1/255 steps among `rgba8unorm` texel bytes.
    pub max_steps: u32,
    /// The bound applied to float words (and, its ULP count, to unorm steps).
    pub bound: FloatBound,
    /// The first word beyond the tolerance: (index, this backend's bits, reference bits).
    pub first_beyond: Option<(usize, u32, u32)>,
}

impl BufferAgreement {
    /// Whether the buffer is within the tolerance.
    pub fn passes(&self) -> bool {
        self.integers_differing == 0 && self.floats_beyond == 0
    }

    /// One line: identical, within the bound, or how far beyond it.
    pub fn describe(&self) -> String {
        if self.differing == 0 {
            return format!("identical ({} words)", self.words);
        }
        self.differences() + if self.passes() { ": within tolerance" } else { ": FAILS" }
    }

    /// One line for a buffer of a kernel whose results WGSL leaves undefined (`why`: the
    /// sanitizer's finding, e.g. an index out of range): identical, within the bound,
    /// or how it differs and why that is allowed, never a failure. Which words an
    /// undefined access can reach is not computed (a value read out of range flows
    /// anywhere), so any difference is allowed.
    pub fn describe_undefined(&self, why: &impl std::fmt::Display) -> String {
        if self.passes() {
            return self.describe();
        }
        format!("{}: undefined by WGSL: {why}", self.differences())
    }

    /// How the buffer differs (when it does), without the verdict.
    fn differences(&self) -> String {
        let mut text = format!("{} of {} words differ", self.differing, self.words);
        if self.max_ulp > 0 {
            text += &format!(", max {} ULP on floats (bound {}", ulp_text(self.max_ulp), self.bound.ulp);
            if self.bound.abs > 0.0 {
                text += &format!(" or {:e} absolute", self.bound.abs);
            }
            text += ")";
        }
        if self.max_steps > 0 {
            text += &format!(", max {} unorm steps (bound {})", self.max_steps, self.bound.ulp);
        }
        if self.integers_differing > 0 {
            text += &format!(", {} integer words differ", self.integers_differing);
        }
        if self.floats_beyond > 0 {
            text += &format!(", {} floats beyond the bound", self.floats_beyond);
        }
        if let Some((index, got, want)) = self.first_beyond {
            text += &format!("; first at word {index}: {got:#010x}, reference {want:#010x}");
        }
        text
    }
}

fn ulp_text(ulp: u32) -> String {
    if ulp == u32::MAX { "NaN-vs-number".into() } else { ulp.to_string() }
}

/// Every backend's judgement against the reference.
#[derive(Clone, Debug, PartialEq)]
pub struct Judgement {
    /// The reference backend.
    pub reference: String,
    /// Every output buffer of every other backend that ran.
    pub buffers: Vec<BufferAgreement>,
    /// Backends that could not run the shader, with why.
    pub failed: Vec<(String, String)>,
}

impl Judgement {
    /// Whether every backend ran and every buffer is within tolerance.
    pub fn passes(&self) -> bool {
        self.failed.is_empty() && self.buffers.iter().all(BufferAgreement::passes)
    }
}

/// Judges every run against the reference: `reference` by name, or the first backend
/// that ran. `None` if fewer than one backend ran; an error if the named reference did
/// not run.
pub fn judge(runs: &[BackendRun], reference: Option<&str>, tolerance: &Tolerance) -> Result<Judgement, String> {
    let failed: Vec<(String, String)> =
        runs.iter().filter_map(|r| r.outputs.as_ref().err().map(|e| (r.backend.clone(), e.clone()))).collect();
    let reference_run = match reference {
        Some(name) => {
            runs.iter().find(|r| r.backend == name).ok_or_else(|| format!("reference `{name}` did not run"))?
        }
        None => runs.iter().find(|r| r.outputs.is_ok()).ok_or_else(|| "no backend ran the shader".to_string())?,
    };
    let reference_outputs =
        reference_run.outputs.as_ref().map_err(|e| format!("the reference `{}` failed: {e}", reference_run.backend))?;
    let mut buffers = Vec::new();
    for run in runs.iter().filter(|r| r.backend != reference_run.backend) {
        let Ok(outputs) = &run.outputs else { continue };
        for (want, got) in reference_outputs.iter().zip(outputs) {
            let bound = tolerance.bound_for(&want.name);
            let mut agreement = BufferAgreement {
                backend: run.backend.clone(),
                binding: want.binding,
                name: want.name.clone(),
                words: 0,
                differing: 0,
                integers_differing: 0,
                floats_beyond: 0,
                max_ulp: 0,
                max_steps: 0,
                bound,
                first_beyond: None,
            };
            let words = want.bytes.len().max(got.bytes.len()) / 4;
            for index in 0..words {
                let kind = want.kinds.of(index);
                if kind == WordKind::Padding {
                    continue;
                }
                agreement.words += 1;
                let read = |bytes: &[u8]| {
                    bytes.get(4 * index..4 * index + 4).map(|w| u32::from_le_bytes(w.try_into().unwrap()))
                };
                let (Some(g), Some(w)) = (read(&got.bytes), read(&want.bytes)) else {
                    // Sizes differ: count the missing word as an integer mismatch.
                    agreement.differing += 1;
                    agreement.integers_differing += 1;
                    continue;
                };
                if g == w {
                    continue;
                }
                agreement.differing += 1;
                let beyond = match kind {
                    WordKind::Float => {
                        let distance = ulp_distance(g, w);
                        agreement.max_ulp = agreement.max_ulp.max(distance);
                        let beyond = !bound.admits(g, w);
                        agreement.floats_beyond += usize::from(beyond);
                        beyond
                    }
                    WordKind::Unorm8x4 => {
                        let steps = (0..4).map(|i| ((g >> (8 * i)) & 0xff).abs_diff((w >> (8 * i)) & 0xff)).max();
                        let steps = steps.unwrap_or(0);
                        agreement.max_steps = agreement.max_steps.max(steps);
                        let beyond = steps > bound.ulp;
                        agreement.floats_beyond += usize::from(beyond);
                        beyond
                    }
                    WordKind::HalfPair => {
                        let beyond = !halves_within_one_ulp(g, w);
                        agreement.floats_beyond += usize::from(beyond);
                        beyond
                    }
                    _ => {
                        agreement.integers_differing += 1;
                        true
                    }
                };
                if beyond && agreement.first_beyond.is_none() {
                    agreement.first_beyond = Some((index, g, w));
                }
            }
            buffers.push(agreement);
        }
    }
    Ok(Judgement { reference: reference_run.backend.clone(), buffers, failed })
}

/// Whether each f16 of `got` is `want`'s or one of its representable neighbours (the
/// other rounding a device may choose); NaN only against NaN.
fn halves_within_one_ulp(got: u32, want: u32) -> bool {
    let ordered = |h: u32| -> Option<i32> {
        let h = h & 0xffff;
        let nan = h & 0x7c00 == 0x7c00 && h & 0x03ff != 0;
        // Sign-magnitude to a monotonic integer line (-0 and +0 both 0).
        (!nan).then(|| if h & 0x8000 != 0 { -((h & 0x7fff) as i32) } else { h as i32 })
    };
    [0, 16].iter().all(|&shift| match (ordered(got >> shift), ordered(want >> shift)) {
        (Some(g), Some(w)) => (g - w).abs() <= 1,
        (None, None) => true,
        _ => false,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run_data::OutputBuffer;
    use strata_kernels::WordKinds;

    fn ulps(ulp: u32) -> Tolerance {
        Tolerance { float: FloatBound { ulp, abs: 0.0 }, ..Tolerance::default() }
    }

    fn run(backend: &str, words: &[u32]) -> BackendRun {
        let bytes = words.iter().flat_map(|w| w.to_le_bytes()).collect();
        // Words alternate: integer, float, padding, float.
        let kinds = WordKinds {
            head: Vec::new(),
            tail: vec![WordKind::Integer, WordKind::Float, WordKind::Padding, WordKind::Float],
        };
        BackendRun {
            backend: backend.into(),
            outputs: Ok(vec![OutputBuffer { group: 0, binding: 1, name: "out".into(), bytes, kinds }]),
        }
    }

    #[test]
    fn integers_must_match_floats_may_differ_within_the_bound_padding_is_skipped() {
        let one = 1.0f32.to_bits();
        let reference = run("cpu", &[7, one, 0, one, 8, one, 0, one]);
        let close = run("gl", &[7, one + 3, 0xdead, one, 8, one, 0, one - 2]);
        let tolerance = ulps(3);
        let judgement = judge(&[reference.clone(), close.clone()], None, &tolerance).unwrap();
        let buffer = &judgement.buffers[0];
        assert_eq!((buffer.words, buffer.differing, buffer.max_ulp), (6, 2, 3));
        assert!(judgement.passes(), "{}", buffer.describe());
        let strict = ulps(2);
        let judgement = judge(&[reference.clone(), close.clone()], None, &strict).unwrap();
        assert!(!judgement.passes());
        assert_eq!(judgement.buffers[0].first_beyond, Some((1, one + 3, one)));
        let per_buffer =
            Tolerance { per_buffer: vec![("out".into(), FloatBound { ulp: 3, abs: 0.0 })], ..Tolerance::default() };
        assert!(judge(&[reference.clone(), close.clone()], None, &per_buffer).unwrap().passes());
        // One ULP of 1.0 is 1.2e-7: an absolute floor of 4e-7 covers three.
        let absolute = Tolerance { float: FloatBound { ulp: 0, abs: 4e-7 }, ..Tolerance::default() };
        assert!(judge(&[reference.clone(), close.clone()], None, &absolute).unwrap().passes());
        let too_small = Tolerance { float: FloatBound { ulp: 0, abs: 2e-7 }, ..Tolerance::default() };
        assert!(!judge(&[reference.clone(), close], None, &too_small).unwrap().passes());
        let wrong_id = run("hlsl", &[7, one, 0, one, 9, one, 0, one]);
        let judgement = judge(&[reference, wrong_id], None, &ulps(1000)).unwrap();
        assert_eq!(judgement.buffers[0].integers_differing, 1);
        assert!(judgement.buffers[0].describe().ends_with("FAILS"), "{}", judgement.buffers[0].describe());
    }

    #[test]
    fn a_difference_wgsl_leaves_undefined_is_described_so_and_never_fails() {
        let reference = run("cpu", &[7, 0, 0, 0]);
        let judgement = judge(&[reference.clone(), run("gpu", &[0, 0, 0, 0])], None, &ulps(0)).unwrap();
        let why = "out-of-range index at k.wgsl:3 in `main` (index 8, length 8)";
        let text = judgement.buffers[0].describe_undefined(&why);
        assert_eq!(
            text,
            "1 of 3 words differ, 1 integer words differ; first at word 0: 0x00000000, reference 0x00000007: \
             undefined by WGSL: out-of-range index at k.wgsl:3 in `main` (index 8, length 8)"
        );
        let same = judge(&[reference, run("gpu", &[7, 0, 0, 0])], None, &ulps(0)).unwrap();
        assert_eq!(same.buffers[0].describe_undefined(&why), "identical (3 words)");
    }

    #[test]
    fn half_pairs_admit_either_rounding_and_nothing_further() {
        let one = 0x3c00u32;
        let pair = |low: u32, high: u32| low | high << 16;
        assert!(halves_within_one_ulp(pair(one, one + 1), pair(one, one)));
        assert!(halves_within_one_ulp(pair(one - 1, 0x8001), pair(one, 0x0000)));
        assert!(!halves_within_one_ulp(pair(one + 2, one), pair(one, one)));
        assert!(!halves_within_one_ulp(pair(one, 0x7e00), pair(one, 0x7c00)), "NaN is not next to infinity");
    }

    #[test]
    fn unorm_texels_are_judged_in_steps_against_the_ulp_bound() {
        let run = |backend: &str, word: u32| BackendRun {
            backend: backend.into(),
            outputs: Ok(vec![OutputBuffer {
                group: 0,
                binding: 0,
                name: "texels".into(),
                bytes: word.to_le_bytes().to_vec(),
                kinds: WordKinds { head: vec![WordKind::Unorm8x4], tail: Vec::new() },
            }]),
        };
        let one_step = [run("cpu", 0x10_20_30_40), run("gpu", 0x10_21_30_40)];
        let exact = judge(&one_step, None, &ulps(0)).unwrap();
        assert!(!exact.passes());
        assert!(exact.buffers[0].describe().contains("max 1 unorm steps (bound 0)"), "{}", exact.buffers[0].describe());
        assert!(judge(&one_step, None, &ulps(1)).unwrap().passes());
        let two_steps = [run("cpu", 0x10_20_30_40), run("gpu", 0x10_20_30_42)];
        assert!(!judge(&two_steps, None, &ulps(1)).unwrap().passes());
    }

    #[test]
    fn a_failed_backend_fails_the_judgement_and_a_named_reference_must_have_run() {
        let reference = run("cpu", &[1, 0, 0, 0]);
        let broken = BackendRun { backend: "ash-hlsl".into(), outputs: Err("glslang rejected it".into()) };
        let judgement = judge(&[reference.clone(), broken.clone()], None, &Tolerance::default()).unwrap();
        assert!(!judgement.passes());
        assert_eq!(judgement.failed, vec![("ash-hlsl".to_string(), "glslang rejected it".to_string())]);
        assert!(judge(&[reference.clone(), broken], Some("ash-hlsl"), &Tolerance::default()).is_err());
        assert!(judge(&[reference], Some("metal"), &Tolerance::default()).unwrap_err().contains("metal"));
    }
}
