//! Comparing a kernel's outputs with the expected ones.

/// How an output is compared.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Compare {
    /// Integers and orderings: bit for bit.
    Exact,
    /// f32 values: within this many units in the last place (NaN must meet NaN).
    FloatUlp(u32),
}

/// One named output buffer as 32-bit words.
#[derive(Clone, Debug, PartialEq, Eq)]
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
            Some(i) => write!(
                f,
                "{}[{i}] = {:#x}, want {:#x}",
                self.output, self.got, self.want
            ),
            None => write!(f, "{}: {} words, want {}", self.output, self.got, self.want),
        }
    }
}

/// Distance in ULPs between two f32 bit patterns (NaN to NaN is 0, NaN to a number is max).
pub fn ulp_distance(a: u32, b: u32) -> u32 {
    let (fa, fb) = (f32::from_bits(a), f32::from_bits(b));
    if fa.is_nan() || fb.is_nan() {
        return if fa.is_nan() && fb.is_nan() {
            0
        } else {
            u32::MAX
        };
    }
    let ordered = |bits: u32| -> i64 {
        if bits >> 31 == 0 {
            i64::from(bits)
        } else {
            -i64::from(bits & 0x7fff_ffff)
        }
    };
    (ordered(a) - ordered(b))
        .unsigned_abs()
        .min(u64::from(u32::MAX)) as u32
}

/// Compares `got` with `want` output by output; returns the largest ULP difference seen.
pub fn compare_outputs(got: &[Output], want: &[Output]) -> Result<u32, Mismatch> {
    let mut max_ulp = 0;
    for want in want {
        let Some(got) = got.iter().find(|o| o.name == want.name) else {
            return Err(Mismatch {
                output: want.name,
                index: None,
                got: 0,
                want: want.words.len() as u64,
            });
        };
        if got.words.len() != want.words.len() {
            return Err(Mismatch {
                output: want.name,
                index: None,
                got: got.words.len() as u64,
                want: want.words.len() as u64,
            });
        }
        for (index, (&g, &w)) in got.words.iter().zip(&want.words).enumerate() {
            let ok = match want.compare {
                Compare::Exact => g == w,
                Compare::FloatUlp(bound) => {
                    let ulp = ulp_distance(g, w);
                    max_ulp = max_ulp.max(ulp);
                    ulp <= bound
                }
            };
            if !ok {
                return Err(Mismatch {
                    output: want.name,
                    index: Some(index),
                    got: u64::from(g),
                    want: u64::from(w),
                });
            }
        }
    }
    Ok(max_ulp)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ulps_count_across_zero_and_nan() {
        assert_eq!(ulp_distance(1.0f32.to_bits(), 1.0f32.to_bits()), 0);
        assert_eq!(ulp_distance(1.0f32.to_bits(), (1.0f32.to_bits()) + 3), 3);
        assert_eq!(ulp_distance(0.0f32.to_bits(), (-0.0f32).to_bits()), 0);
        assert_eq!(
            ulp_distance(f32::from_bits(1).to_bits(), (-f32::from_bits(1)).to_bits()),
            2
        );
        assert_eq!(ulp_distance(f32::NAN.to_bits(), f32::NAN.to_bits()), 0);
        assert_eq!(ulp_distance(f32::NAN.to_bits(), 1.0f32.to_bits()), u32::MAX);
    }

    #[test]
    fn the_first_difference_is_reported() {
        let want = [Output {
            name: "a",
            words: vec![1, 2, 3],
            compare: Compare::Exact,
        }];
        let got = [Output {
            name: "a",
            words: vec![1, 5, 3],
            compare: Compare::Exact,
        }];
        let mismatch = compare_outputs(&got, &want).unwrap_err();
        assert_eq!(mismatch.to_string(), "a[1] = 0x5, want 0x2");
        let floats = [Output {
            name: "f",
            words: vec![1.0f32.to_bits()],
            compare: Compare::FloatUlp(2),
        }];
        let close = [Output {
            name: "f",
            words: vec![1.0f32.to_bits() + 2],
            compare: Compare::FloatUlp(2),
        }];
        assert_eq!(compare_outputs(&close, &floats), Ok(2));
        let far = [Output {
            name: "f",
            words: vec![1.0f32.to_bits() + 3],
            compare: Compare::FloatUlp(2),
        }];
        assert!(compare_outputs(&far, &floats).is_err());
    }
}
