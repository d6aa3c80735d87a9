//! The discrete Fourier transform for [`super::correlation`]'s power spectrum, written here
//! because the workspace has no FFT crate: X_k = Σₙ xₙ · e^(−2πi·kn/N), no normalisation.
//! Lengths that are powers of two take the iterative radix-2 Cooley–Tukey algorithm
//! (O(N log N)); other lengths the direct sum (O(N²)), which for an image's rows and
//! columns up to a few hundred pixels is still a fraction of a second. Two dimensions are
//! rows, then columns.

/// A complex number as (real, imaginary).
pub type Complex = [f64; 2];

fn mul(a: Complex, b: Complex) -> Complex {
    [a[0] * b[0] - a[1] * b[1], a[0] * b[1] + a[1] * b[0]]
}

/// e^(−2πi·k/n) for k in 0..n.
fn twiddles(n: usize) -> Vec<Complex> {
    (0..n)
        .map(|k| {
            let angle = -std::f64::consts::TAU * k as f64 / n as f64;
            [angle.cos(), angle.sin()]
        })
        .collect()
}

/// The forward DFT of `values`, in place.
pub fn dft(values: &mut [Complex]) {
    let n = values.len();
    if n <= 1 {
        return;
    }
    if n.is_power_of_two() {
        radix_2(values);
    } else {
        direct(values);
    }
}

/// The direct sum, any length: X_k = Σₙ xₙ · w^((k·n) mod N).
fn direct(values: &mut [Complex]) {
    let n = values.len();
    let w = twiddles(n);
    let input = values.to_vec();
    for (k, out) in values.iter_mut().enumerate() {
        let mut sum = [0.0, 0.0];
        for (j, &x) in input.iter().enumerate() {
            let t = mul(x, w[(k * j) % n]);
            sum[0] += t[0];
            sum[1] += t[1];
        }
        *out = sum;
    }
}

/// Iterative radix-2 Cooley–Tukey (decimation in time), length a power of two.
fn radix_2(values: &mut [Complex]) {
    let n = values.len();
    let bits = n.trailing_zeros();
    for i in 0..n {
        let j = i.reverse_bits() >> (usize::BITS - bits);
        if i < j {
            values.swap(i, j);
        }
    }
    let w = twiddles(n);
    let mut len = 2;
    while len <= n {
        let step = n / len;
        for start in (0..n).step_by(len) {
            for j in 0..len / 2 {
                let (a, b) = (values[start + j], mul(values[start + j + len / 2], w[j * step]));
                values[start + j] = [a[0] + b[0], a[1] + b[1]];
                values[start + j + len / 2] = [a[0] - b[0], a[1] - b[1]];
            }
        }
        len *= 2;
    }
}

/// The forward 2-D DFT of a row-major `width` × `height` array, in place:
/// X(u, v) = Σ_{x,y} x(x, y) · e^(−2πi (ux/W + vy/H)).
pub fn dft_2d(values: &mut [Complex], width: usize, height: usize) {
    assert_eq!(values.len(), width * height, "dft_2d: {} values for {width}x{height}", values.len());
    for row in values.chunks_mut(width.max(1)) {
        dft(row);
    }
    let mut column = vec![[0.0, 0.0]; height];
    for x in 0..width {
        for (y, c) in column.iter_mut().enumerate() {
            *c = values[y * width + x];
        }
        dft(&mut column);
        for (y, c) in column.iter().enumerate() {
            values[y * width + x] = *c;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::evaluation::test_noise::Rng;

    /// The textbook sum, with each angle computed afresh.
    fn reference_dft(values: &[Complex]) -> Vec<Complex> {
        let n = values.len();
        (0..n)
            .map(|k| {
                values.iter().enumerate().fold([0.0, 0.0], |sum, (j, x)| {
                    let angle = -std::f64::consts::TAU * (k * j) as f64 / n as f64;
                    let t = mul(*x, [angle.cos(), angle.sin()]);
                    [sum[0] + t[0], sum[1] + t[1]]
                })
            })
            .collect()
    }

    fn random(n: usize, rng: &mut Rng) -> Vec<Complex> {
        (0..n).map(|_| [rng.normal(), rng.normal()]).collect()
    }

    #[test]
    fn both_algorithms_match_the_textbook_sum() {
        let mut rng = Rng::new(21);
        for n in [1, 2, 4, 8, 64, 3, 6, 12, 45] {
            let input = random(n, &mut rng);
            let mut fast = input.clone();
            dft(&mut fast);
            for (a, b) in fast.iter().zip(reference_dft(&input)) {
                assert!((a[0] - b[0]).abs() < 1e-9 && (a[1] - b[1]).abs() < 1e-9, "n = {n}: {a:?} vs {b:?}");
            }
        }
    }

    #[test]
    fn known_transforms_in_two_dimensions() {
        // A delta at the origin transforms to all ones; a plane wave of frequency (3, 1) on
        // 8 × 6 to W·H at (3, 1) and zero elsewhere.
        let (width, height) = (8, 6);
        let mut delta = vec![[0.0, 0.0]; width * height];
        delta[0] = [1.0, 0.0];
        dft_2d(&mut delta, width, height);
        assert!(delta.iter().all(|c| (c[0] - 1.0).abs() < 1e-12 && c[1].abs() < 1e-12));
        let mut wave: Vec<Complex> = (0..width * height)
            .map(|i| {
                let (x, y) = ((i % width) as f64, (i / width) as f64);
                let angle = std::f64::consts::TAU * (3.0 * x / width as f64 + y / height as f64);
                [angle.cos(), angle.sin()]
            })
            .collect();
        dft_2d(&mut wave, width, height);
        for (i, c) in wave.iter().enumerate() {
            let expected = if i == width + 3 { (width * height) as f64 } else { 0.0 };
            assert!((c[0] - expected).abs() < 1e-9 && c[1].abs() < 1e-9, "{i}: {c:?}");
        }
    }
}
