//! Comparing a kernel's outputs with the expected ones.

/// How an output is compared.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Compare {
    /// Integers and orderings: bit for bit.
    Exact,
    /// Words bit for bit, except a share `max_outside` (0..1) that may differ: integer
    /// outputs of float-dependent control flow (the triangle a ray hits at a near-tie).
    WordsWithOutliers {
        /// Largest share of differing words.
        max_outside: f64,
    },
    /// f32 values within `ulp` units in the last place (NaN must meet NaN). Kernels whose
    /// control flow depends on float results (BVH traversal, path tracing) may let a
    /// share `max_outside` of the values exceed the bound; 0 allows none.
    Float {
        /// ULP bound per value.
        ulp: u32,
        /// Largest share of values (0..1) allowed beyond `ulp`.
        max_outside: f64,
    },
}

/// How closely outputs agreed.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Agreement {
    /// Largest ULP difference among float values within their bound.
    pub max_ulp: u32,
    /// Float values beyond their bound (allowed by `max_outside`).
    pub outside: usize,
    /// Float values compared.
    pub floats: usize,
}

impl Agreement {
    /// Combines two agreements.
    pub fn merge(self, other: Agreement) -> Agreement {
        Agreement {
            max_ulp: self.max_ulp.max(other.max_ulp),
            outside: self.outside + other.outside,
            floats: self.floats + other.floats,
        }
    }

    /// Share of float values beyond their bound.
    pub fn outside_share(&self) -> f64 {
        if self.floats == 0 { 0.0 } else { self.outside as f64 / self.floats as f64 }
    }
}

/// One named output buffer as 32-bit words.
#[derive(Clone, Debug, PartialEq)]
pub struct Output {
    /// Buffer name (the WGSL variable).
    pub name: &'static str,
    /// Contents.
    pub words: Vec<u32>,
    /// How to compare it.
    pub compare: Compare,
}

/// The first difference found.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Mismatch {
    /// Output name.
    pub output: &'static str,
    /// Word index (None: lengths differ).
    pub index: Option<usize>,
    /// What was found.
    pub got: u64,
    /// What was expected.
    pub want: u64,
}

impl std::fmt::Display for Mismatch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.index {
            Some(i) => write!(f, "{}[{i}] = {:#x}, want {:#x}", self.output, self.got, self.want),
            None => write!(f, "{}: {} words, want {}", self.output, self.got, self.want),
        }
    }
}

/// Distance in ULPs between two f32 bit patterns (NaN to NaN is 0, NaN to a number is max).
pub fn ulp_distance(a: u32, b: u32) -> u32 {
    let (fa, fb) = (f32::from_bits(a), f32::from_bits(b));
    if fa.is_nan() || fb.is_nan() {
        return if fa.is_nan() && fb.is_nan() { 0 } else { u32::MAX };
    }
    let ordered = |bits: u32| -> i64 { if bits >> 31 == 0 { i64::from(bits) } else { -i64::from(bits & 0x7fff_ffff) } };
    (ordered(a) - ordered(b)).unsigned_abs().min(u64::from(u32::MAX)) as u32
}

/// The number of `outside` words (index, got, want) if within the share `max_outside` of
/// `want`'s words, else the first of them as a mismatch.
fn allow_outliers(want: &Output, outside: &[(usize, u32, u32)], max_outside: f64) -> Result<usize, Mismatch> {
    let allowed = (max_outside * want.words.len() as f64).floor() as usize;
    match outside.first() {
        Some(&(index, g, w)) if outside.len() > allowed => {
            Err(Mismatch { output: want.name, index: Some(index), got: u64::from(g), want: u64::from(w) })
        }
        _ => Ok(outside.len()),
    }
}

/// Compares `got` with `want` output by output.
pub fn compare_outputs(got: &[Output], want: &[Output]) -> Result<Agreement, Mismatch> {
    let mut agreement = Agreement::default();
    for want in want {
        let Some(got) = got.iter().find(|o| o.name == want.name) else {
            return Err(Mismatch { output: want.name, index: None, got: 0, want: want.words.len() as u64 });
        };
        if got.words.len() != want.words.len() {
            return Err(Mismatch {
                output: want.name,
                index: None,
                got: got.words.len() as u64,
                want: want.words.len() as u64,
            });
        }
        let mut pairs = got.words.iter().zip(&want.words).enumerate();
        match want.compare {
            Compare::Exact => {
                if let Some((index, (&g, &w))) = pairs.find(|(_, (g, w))| g != w) {
                    return Err(Mismatch {
                        output: want.name,
                        index: Some(index),
                        got: u64::from(g),
                        want: u64::from(w),
                    });
                }
            }
            Compare::WordsWithOutliers { max_outside } => {
                let outside: Vec<_> = pairs.filter(|(_, (g, w))| g != w).map(|(i, (&g, &w))| (i, g, w)).collect();
                agreement.outside += allow_outliers(want, &outside, max_outside)?;
                agreement.floats += want.words.len();
            }
            Compare::Float { ulp, max_outside } => {
                let mut outside = Vec::new();
                for (index, (&g, &w)) in pairs {
                    let distance = ulp_distance(g, w);
                    if distance <= ulp {
                        agreement.max_ulp = agreement.max_ulp.max(distance);
                    } else {
                        outside.push((index, g, w));
                    }
                }
                agreement.outside += allow_outliers(want, &outside, max_outside)?;
                agreement.floats += want.words.len();
            }
        }
    }
    Ok(agreement)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ulps_count_across_zero_and_nan() {
        assert_eq!(ulp_distance(1.0f32.to_bits(), 1.0f32.to_bits()), 0);
        assert_eq!(ulp_distance(1.0f32.to_bits(), (1.0f32.to_bits()) + 3), 3);
        assert_eq!(ulp_distance(0.0f32.to_bits(), (-0.0f32).to_bits()), 0);
        assert_eq!(ulp_distance(f32::from_bits(1).to_bits(), (-f32::from_bits(1)).to_bits()), 2);
        assert_eq!(ulp_distance(f32::NAN.to_bits(), f32::NAN.to_bits()), 0);
        assert_eq!(ulp_distance(f32::NAN.to_bits(), 1.0f32.to_bits()), u32::MAX);
    }

    #[test]
    fn the_first_difference_is_reported() {
        let want = [Output { name: "a", words: vec![1, 2, 3], compare: Compare::Exact }];
        let got = [Output { name: "a", words: vec![1, 5, 3], compare: Compare::Exact }];
        let mismatch = compare_outputs(&got, &want).unwrap_err();
        assert_eq!(mismatch.to_string(), "a[1] = 0x5, want 0x2");
        let floats =
            [Output { name: "f", words: vec![1.0f32.to_bits()], compare: Compare::Float { ulp: 2, max_outside: 0.0 } }];
        let close = [Output { name: "f", words: vec![1.0f32.to_bits() + 2], compare: Compare::Exact }];
        assert_eq!(compare_outputs(&close, &floats).map(|a| a.max_ulp), Ok(2));
        let far = [Output { name: "f", words: vec![1.0f32.to_bits() + 3], compare: Compare::Exact }];
        assert!(compare_outputs(&far, &floats).is_err());
    }

    #[test]
    fn a_declared_share_of_outliers_is_allowed_and_counted() {
        let values: Vec<u32> = (0..1000).map(|i| (1.0 + i as f32).to_bits()).collect();
        let mut noisy = values.clone();
        noisy[10] += 1000;
        noisy[20] += 1000;
        let want = |max_outside| {
            [Output { name: "image", words: values.clone(), compare: Compare::Float { ulp: 4, max_outside } }]
        };
        let got = [Output { name: "image", words: noisy, compare: Compare::Exact }];
        let agreement = compare_outputs(&got, &want(0.002)).unwrap();
        assert_eq!((agreement.outside, agreement.floats), (2, 1000));
        assert!((agreement.outside_share() - 0.002).abs() < 1e-12);
        let mismatch = compare_outputs(&got, &want(0.001)).unwrap_err();
        assert_eq!(mismatch.index, Some(10));
    }
}
