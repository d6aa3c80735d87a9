//! Importance sampling of the lat-long environment (the host half of
//! `kernels/wgsl/render/environment.wgsl`): piecewise constant over W × H cells in
//! (u, v), cell (i, j) weighted by the largest luminance that bilinear filtering can
//! produce inside it, times sin θ at its centre. Taking the largest over the footprint
//! keeps the density positive wherever the filtered map has radiance, which unbiased
//! NEE needs.

use crate::scene::Environment;

/// Rec. 709 luminance.
pub fn luminance(c: [f32; 3]) -> f32 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

/// The CDFs as the kernel reads them: the marginal over rows (H + 1 entries) and then
/// one CDF per row (W + 1 entries each); `None` when the map is black everywhere.
pub fn environment_cdf(environment: &Environment) -> Option<Vec<f32>> {
    let (w, h) = (environment.width as usize, environment.height as usize);
    let texel = |x: isize, y: usize| {
        let column = x.rem_euclid(w as isize) as usize;
        luminance(environment.texels[y * w + column]).max(0.0)
    };
    let mut rows = Vec::with_capacity(h);
    let mut row_totals = Vec::with_capacity(h);
    for j in 0..h {
        // Continuous rows covered by v in [j/H, (j+1)/H]: y = v (H - 1).
        let y_low = (j as f64 * (h - 1) as f64 / h as f64).floor() as usize;
        let y_high = (((j + 1) as f64 * (h - 1) as f64 / h as f64).ceil() as usize).min(h - 1);
        let sin_theta = (std::f64::consts::PI * (j as f64 + 0.5) / h as f64).sin();
        let weights: Vec<f64> = (0..w)
            .map(|i| {
                let mut largest = 0.0f32;
                for y in y_low..=y_high {
                    for dx in -1..=1 {
                        largest = largest.max(texel(i as isize + dx, y));
                    }
                }
                f64::from(largest) * sin_theta
            })
            .collect();
        row_totals.push(weights.iter().sum::<f64>());
        rows.push(weights);
    }
    let total: f64 = row_totals.iter().sum();
    if total <= 0.0 || !total.is_finite() {
        return None;
    }
    let mut cdf = Vec::with_capacity(h + 1 + h * (w + 1));
    cdf.extend(prefix_cdf(&row_totals));
    for row in &rows {
        if row.iter().sum::<f64>() > 0.0 {
            cdf.extend(prefix_cdf(row));
        } else {
            // Never selected (its marginal probability is 0); uniform keeps it well formed.
            cdf.extend((0..=w).map(|i| i as f32 / w as f32));
        }
    }
    Some(cdf)
}

/// Normalised inclusive prefix sums with a leading 0 and a final exact 1.
fn prefix_cdf(weights: &[f64]) -> Vec<f32> {
    let total: f64 = weights.iter().sum();
    let mut cdf = Vec::with_capacity(weights.len() + 1);
    let mut running = 0.0f64;
    cdf.push(0.0);
    for w in weights {
        running += w;
        cdf.push((running / total) as f32);
    }
    *cdf.last_mut().unwrap() = 1.0;
    cdf
}

#[cfg(test)]
mod tests {
    use super::*;

    fn environment(width: u32, height: u32, texels: Vec<[f32; 3]>) -> Environment {
        Environment {
            file: "test.exr".into(),
            width,
            height,
            texels,
            scale: 1.0,
            to_world: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        }
    }

    #[test]
    fn cdfs_are_monotone_and_end_at_one() {
        let texels = (0..64).map(|i| [(i % 7) as f32, 0.0, (i / 8) as f32 * 0.1]).collect();
        let cdf = environment_cdf(&environment(8, 8, texels)).unwrap();
        assert_eq!(cdf.len(), 9 + 8 * 9);
        for block in [&cdf[..9]].into_iter().chain(cdf[9..].chunks(9)) {
            assert_eq!(block[0], 0.0);
            assert_eq!(*block.last().unwrap(), 1.0);
            assert!(block.windows(2).all(|p| p[0] <= p[1]), "{block:?}");
        }
    }

    #[test]
    fn a_single_bright_texel_keeps_its_whole_bilinear_footprint_positive() {
        let mut texels = vec![[0.0; 3]; 16 * 8];
        texels[3 * 16 + 5] = [1.0, 1.0, 1.0];
        let cdf = environment_cdf(&environment(16, 8, texels)).unwrap();
        let row = |j: usize| cdf[j + 1] - cdf[j];
        // Row 3 of texels covers cells whose continuous rows reach y = 3.
        assert!(row(3) > 0.0 && row(4) > 0.0, "{:?}", &cdf[..9]);
        let cells = |j: usize| &cdf[9 + j * 17..9 + (j + 1) * 17];
        let positive: Vec<usize> = (0..16).filter(|&i| cells(3)[i + 1] > cells(3)[i]).collect();
        assert_eq!(positive, [4, 5, 6], "column 5 reaches cells 4..=6 under bilinear filtering");
        assert!(environment_cdf(&environment(4, 4, vec![[0.0; 3]; 16])).is_none());
    }
}
