//! What the four SVGF kernels (`kernels/wgsl/denoise/`) compute, with the same
//! operations in the same order: the oracle the cross-backend check holds every backend
//! to, and what the unit tests below pin to the paper's behaviour (edges stop the filter,
//! a history is reprojected, short histories take their variance from neighbours).

use crate::denoise_types::{DenoiseGuide, DenoiseParams, MIN_ALBEDO, SHORT_HISTORY};

/// An image of `width * height` values, row by row.
type Image<T> = Vec<T>;

fn has_surface(g: &DenoiseGuide) -> bool {
    g.depth > 0.0
}

fn demodulation(albedo: [f32; 3]) -> [f32; 3] {
    albedo.map(|a| if a > MIN_ALBEDO { a } else { 1.0 })
}

/// Rec. 709 luminance, as the kernels compute it.
pub fn luminance(c: [f32; 3]) -> f32 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// SVGF's w_n: max(0, a·b)^(2^normal_power_log2), by squaring.
pub fn normal_weight(params: &DenoiseParams, a: [f32; 3], b: [f32; 3]) -> f32 {
    let mut w = dot(a, b).max(0.0);
    for _ in 0..params.svgf.normal_power_log2 {
        w *= w;
    }
    w
}

fn pixel_at(params: &DenoiseParams, x: i32, y: i32) -> Option<usize> {
    if x < 0 || y < 0 || x >= params.width as i32 || y >= params.height as i32 {
        return None;
    }
    Some(y as usize * params.width as usize + x as usize)
}

fn depth_slope(params: &DenoiseParams, guides: &[DenoiseGuide], x: i32, y: i32, depth: f32) -> [f32; 2] {
    let mut slope = [0.0f32; 2];
    for (axis, value) in slope.iter_mut().enumerate() {
        let mut smallest = -1.0f32;
        for side in [-1, 1] {
            let (dx, dy) = if axis == 0 { (side, 0) } else { (0, side) };
            if let Some(q) = pixel_at(params, x + dx, y + dy).filter(|&q| has_surface(&guides[q])) {
                let d = (guides[q].depth - depth).abs();
                if smallest < 0.0 || d < smallest {
                    smallest = d;
                }
            }
        }
        *value = smallest.max(0.0);
    }
    slope
}

fn object_weight(params: &DenoiseParams, a: &DenoiseGuide, b: &DenoiseGuide) -> f32 {
    if params.svgf.object_edges != 0 && a.mesh != b.mesh { 0.0 } else { 1.0 }
}

fn depth_distance(params: &DenoiseParams, depth: f32, other: f32, slope: [f32; 2], offset: [f32; 2]) -> f32 {
    let expected =
        params.svgf.sigma_depth * ((slope[0] * offset[0]).abs() + (slope[1] * offset[1]).abs()) + 1e-3 * depth;
    (depth - other).abs() / expected
}

/// `sum += w * value`, component by component (as the kernels' vector arithmetic).
fn add_weighted(sum: &mut [f32], w: f32, value: &[f32]) {
    for (s, v) in sum.iter_mut().zip(value) {
        *s += w * v;
    }
}

fn rgb(v: [f32; 4]) -> [f32; 3] {
    [v[0], v[1], v[2]]
}

/// The temporal pass's inputs besides the settings (`svgf_temporal`'s bindings 1-6).
pub struct TemporalInputs<'a> {
    /// This frame's noisy colour (rgb; w unused).
    pub colour: &'a [[f32; 4]],
    /// This frame's guide.
    pub guides: &'a [DenoiseGuide],
    /// The previous frame's guide.
    pub previous_guides: &'a [DenoiseGuide],
    /// The previous frame's history (its first à-trous level's illumination).
    pub history: &'a [[f32; 4]],
    /// The previous frame's integrated illumination (w: history length).
    pub previous_integrated: &'a [[f32; 4]],
    /// The previous frame's moments.
    pub previous_moments: &'a [[f32; 2]],
}

/// `svgf_temporal`: the integrated illumination with its history length, and the moments.
pub fn temporal(params: &DenoiseParams, inputs: &TemporalInputs) -> (Image<[f32; 4]>, Image<[f32; 2]>) {
    let (width, height) = (params.width as usize, params.height as usize);
    let mut integrated = vec![[0.0; 4]; width * height];
    let mut moments = vec![[0.0; 2]; width * height];
    for y in 0..height {
        for x in 0..width {
            let pixel = y * width + x;
            let g = &inputs.guides[pixel];
            let c = rgb(inputs.colour[pixel]);
            if !has_surface(g) {
                integrated[pixel] = [c[0], c[1], c[2], 0.0];
                continue;
            }
            let demodulation = demodulation(g.albedo);
            let illumination: [f32; 3] = std::array::from_fn(|i| c[i] / demodulation[i]);
            let mut weight_sum = 0.0f32;
            let mut previous_illumination = [0.0f32; 3];
            let mut previous_moment = [0.0f32; 2];
            let mut previous_length = 0.0f32;
            if params.history != 0 {
                let position = [x as f32 + g.motion[0], y as f32 + g.motion[1]];
                let corner = position.map(f32::floor);
                let f = [position[0] - corner[0], position[1] - corner[1]];
                for tap in 0..4u32 {
                    let (dx, dy) = (tap & 1, tap >> 1);
                    let (qx, qy) = (corner[0] + dx as f32, corner[1] + dy as f32);
                    if !(qx >= 0.0 && qy >= 0.0 && qx < params.width as f32 && qy < params.height as f32) {
                        continue;
                    }
                    let w = (if dx == 1 { f[0] } else { 1.0 - f[0] }) * (if dy == 1 { f[1] } else { 1.0 - f[1] });
                    let q = qy as usize * width + qx as usize;
                    let previous = &inputs.previous_guides[q];
                    let same_surface = has_surface(previous)
                        && previous.mesh == g.mesh
                        && (previous.depth - g.depth).abs() <= params.svgf.depth_tolerance * g.depth
                        && dot(g.normal, previous.normal) >= params.svgf.normal_tolerance;
                    if w > 0.0 && same_surface {
                        weight_sum += w;
                        add_weighted(&mut previous_illumination, w, &inputs.history[q][..3]);
                        add_weighted(&mut previous_moment, w, &inputs.previous_moments[q]);
                        previous_length += w * inputs.previous_integrated[q][3];
                    }
                }
            }
            let mut length = 1.0f32;
            if weight_sum > 1e-3 {
                previous_illumination = previous_illumination.map(|v| v / weight_sum);
                previous_moment = previous_moment.map(|v| v / weight_sum);
                length = (previous_length / weight_sum + 1.0).min(params.svgf.max_history);
            }
            let alpha_colour = params.svgf.alpha_colour.max(1.0 / length);
            let alpha_moments = params.svgf.alpha_moments.max(1.0 / length);
            let l = luminance(illumination);
            let moment = [l, l * l];
            let mix = |old: f32, new: f32, alpha: f32| old * (1.0 - alpha) + new * alpha;
            integrated[pixel] = [
                mix(previous_illumination[0], illumination[0], alpha_colour),
                mix(previous_illumination[1], illumination[1], alpha_colour),
                mix(previous_illumination[2], illumination[2], alpha_colour),
                length,
            ];
            moments[pixel] =
                [mix(previous_moment[0], moment[0], alpha_moments), mix(previous_moment[1], moment[1], alpha_moments)];
        }
    }
    (integrated, moments)
}

/// `svgf_variance`: illumination (rgb) and its luminance variance (w).
pub fn variance(
    params: &DenoiseParams,
    guides: &[DenoiseGuide],
    integrated: &[[f32; 4]],
    moments: &[[f32; 2]],
) -> Image<[f32; 4]> {
    let (width, height) = (params.width as usize, params.height as usize);
    let mut out = vec![[0.0; 4]; width * height];
    for y in 0..height {
        for x in 0..width {
            let pixel = y * width + x;
            let g = &guides[pixel];
            let own = integrated[pixel];
            if !has_surface(g) {
                out[pixel] = [own[0], own[1], own[2], 0.0];
                continue;
            }
            let length = own[3];
            if length >= SHORT_HISTORY {
                let m = moments[pixel];
                out[pixel] = [own[0], own[1], own[2], (m[1] - m[0] * m[0]).max(0.0)];
                continue;
            }
            let (xi, yi) = (x as i32, y as i32);
            let slope = depth_slope(params, guides, xi, yi, g.depth);
            let l = luminance(rgb(own));
            let mut weight_sum = 0.0f32;
            let mut illumination = [0.0f32; 3];
            let mut moment = [0.0f32; 2];
            for dy in -3..=3 {
                for dx in -3..=3 {
                    let Some(q) = pixel_at(params, xi + dx, yi + dy).filter(|&q| has_surface(&guides[q])) else {
                        continue;
                    };
                    let other = integrated[q];
                    let exponent = depth_distance(params, g.depth, guides[q].depth, slope, [dx as f32, dy as f32])
                        + (l - luminance(rgb(other))).abs() / params.svgf.sigma_luminance;
                    let w = object_weight(params, g, &guides[q])
                        * normal_weight(params, g.normal, guides[q].normal)
                        * (-exponent).exp();
                    weight_sum += w;
                    add_weighted(&mut illumination, w, &other[..3]);
                    add_weighted(&mut moment, w, &moments[q]);
                }
            }
            let weight_sum = weight_sum.max(1e-20);
            let illumination = illumination.map(|v| v / weight_sum);
            let moment = moment.map(|v| v / weight_sum);
            let variance = (moment[1] - moment[0] * moment[0]).max(0.0) * SHORT_HISTORY / length.max(1.0);
            out[pixel] = [illumination[0], illumination[1], illumination[2], variance];
        }
    }
    out
}

fn b3_spline(tap: i32) -> f32 {
    match tap.abs() {
        0 => 3.0 / 8.0,
        1 => 1.0 / 4.0,
        _ => 1.0 / 16.0,
    }
}

/// `svgf_atrous`: one level (taps `params.step` apart) of the edge-avoiding filter.
pub fn atrous(params: &DenoiseParams, guides: &[DenoiseGuide], level_in: &[[f32; 4]]) -> Image<[f32; 4]> {
    let (width, height) = (params.width as usize, params.height as usize);
    let mut out = vec![[0.0; 4]; width * height];
    let step = params.step as i32;
    for y in 0..height {
        for x in 0..width {
            let pixel = y * width + x;
            let g = &guides[pixel];
            let own = level_in[pixel];
            if !has_surface(g) {
                out[pixel] = own;
                continue;
            }
            let (xi, yi) = (x as i32, y as i32);
            let slope = depth_slope(params, guides, xi, yi, g.depth);
            let l = luminance(rgb(own));
            let (mut blurred, mut blur_weight) = (0.0f32, 0.0f32);
            for dy in -1..=1 {
                for dx in -1..=1 {
                    if let Some(q) = pixel_at(params, xi + dx, yi + dy).filter(|&q| has_surface(&guides[q])) {
                        let w = (if dx == 0 { 0.5 } else { 0.25 }) * (if dy == 0 { 0.5 } else { 0.25 });
                        blurred += w * level_in[q][3];
                        blur_weight += w;
                    }
                }
            }
            let luminance_scale = params.svgf.sigma_luminance * (blurred / blur_weight).max(0.0).sqrt() + 1e-10;
            let mut weight_sum = 0.0f32;
            let mut illumination = [0.0f32; 3];
            let mut variance = 0.0f32;
            let mut deviation = 0.0f32;
            for dy in -2..=2 {
                for dx in -2..=2 {
                    let Some(q) = pixel_at(params, xi + dx * step, yi + dy * step).filter(|&q| has_surface(&guides[q]))
                    else {
                        continue;
                    };
                    let other = level_in[q];
                    let offset = [(dx * step) as f32, (dy * step) as f32];
                    let exponent = depth_distance(params, g.depth, guides[q].depth, slope, offset)
                        + (l - luminance(rgb(other))).abs() / luminance_scale;
                    let w = b3_spline(dx)
                        * b3_spline(dy)
                        * object_weight(params, g, &guides[q])
                        * normal_weight(params, g.normal, guides[q].normal)
                        * (-exponent).exp();
                    weight_sum += w;
                    add_weighted(&mut illumination, w, &other[..3]);
                    variance += w * w * other[3];
                    deviation += w * other[3].max(0.0).sqrt();
                }
            }
            let rho = params.svgf.error_correlation;
            if rho > 0.0 {
                variance = (1.0 - rho) * variance + rho * deviation * deviation;
            }
            let weight_sum = weight_sum.max(1e-20);
            out[pixel] = [
                illumination[0] / weight_sum,
                illumination[1] / weight_sum,
                illumination[2] / weight_sum,
                variance / (weight_sum * weight_sum),
            ];
        }
    }
    out
}

/// `svgf_modulate`: the denoised colour (w 0).
pub fn modulate(guides: &[DenoiseGuide], colour: &[[f32; 4]], filtered: &[[f32; 4]]) -> Image<[f32; 4]> {
    guides
        .iter()
        .zip(colour.iter().zip(filtered))
        .map(|(g, (c, f))| {
            if !has_surface(g) {
                return [c[0], c[1], c[2], 0.0];
            }
            let d = demodulation(g.albedo);
            [f[0] * d[0], f[1] * d[1], f[2] * d[2], 0.0]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// SVGF's settings (the renderer's defaults) at `width` x `height`.
    fn params(width: u32, height: u32, step: u32, history: bool) -> DenoiseParams {
        DenoiseParams { history: u32::from(history), step, ..DenoiseParams::paper(width, height) }
    }

    fn plane(depth: f32, normal: [f32; 3], mesh: u32) -> DenoiseGuide {
        DenoiseGuide { albedo: [0.5; 3], depth, normal, mesh, motion: [0.0; 2], _pad: [0; 2] }
    }

    /// A 16 x 8 image: left half `left`, right half `right`, illumination 1 on the left
    /// and 3 on the right with ±`noise` in a checkerboard, variance `variance`.
    fn split(left: DenoiseGuide, right: DenoiseGuide, noise: f32, variance: f32) -> (Vec<DenoiseGuide>, Vec<[f32; 4]>) {
        let (mut guides, mut levels) = (Vec::new(), Vec::new());
        for y in 0..8 {
            for x in 0..16 {
                let sign = if (x + y) % 2 == 0 { 1.0 } else { -1.0 };
                let (g, value) = if x < 8 { (left, 1.0) } else { (right, 3.0) };
                guides.push(g);
                let v = value + sign * noise;
                levels.push([v, v, v, variance]);
            }
        }
        (guides, levels)
    }

    fn mean_of_side(out: &[[f32; 4]], right: bool) -> (f32, f32) {
        let values: Vec<f32> = (0..8)
            .flat_map(|y| (0..16).map(move |x| (x, y)))
            .filter(|&(x, _)| (x >= 8) == right)
            .map(|(x, y)| out[y * 16 + x][0])
            .collect();
        let mean = values.iter().sum::<f32>() / values.len() as f32;
        let spread = values.iter().map(|v| (v - mean).abs()).fold(0.0, f32::max);
        (mean, spread)
    }

    #[test]
    fn the_filter_removes_noise_within_a_surface() {
        let g = plane(2.0, [0.0, 0.0, 1.0], 0);
        let (guides, mut levels) = split(g, g, 0.3, 0.09);
        // One surface, one illumination (1 on both halves): the filter averages it.
        for v in &mut levels {
            let value = if v[0] > 2.0 { v[0] - 2.0 } else { v[0] };
            *v = [value, value, value, v[3]];
        }
        let out = atrous(&params(16, 8, 1, false), &guides, &levels);
        let (_, spread_before) = mean_of_side(&levels, false);
        let (mean, spread) = mean_of_side(&out, false);
        assert!((mean - 1.0).abs() < 0.02 && spread < 0.5 * spread_before, "mean {mean}, spread {spread}");
        // The variance left is smaller too (filtered with the squared weights).
        assert!(out[3 * 16 + 4][3] < 0.5 * 0.09, "{}", out[3 * 16 + 4][3]);
    }

    #[test]
    fn depth_normal_and_luminance_edges_stop_the_filter() {
        let near = plane(2.0, [0.0, 0.0, 1.0], 0);
        // Each kind of edge alone between the halves, with illumination 1 and 3 across it:
        // a depth or normal edge with a variance that lets the luminance weight mix the
        // halves (as the last case shows), a luminance step alone on one surface with a
        // variance small against it.
        let edges = [
            ("depth", plane(4.0, [0.0, 0.0, 1.0], 0), 4.0),
            // 20 degrees apart: cos^128 is 3e-4.
            ("normal", plane(2.0, [0.342, 0.0, 0.940], 0), 4.0),
            ("luminance", near, 0.01),
        ];
        for (edge, far, variance) in edges {
            let (guides, levels) = split(near, far, 0.0, variance);
            for step in [1, 2, 4] {
                let out = atrous(&params(16, 8, step, false), &guides, &levels);
                let (left, _) = mean_of_side(&out, false);
                let (right, _) = mean_of_side(&out, true);
                assert!(
                    (left - 1.0).abs() < 0.01 && (right - 3.0).abs() < 0.01,
                    "{edge} edge, step {step}: {left} {right}"
                );
            }
        }
        // Without the edge (same surface, same luminance scale as the noise) the halves mix.
        let (guides, levels) = split(near, near, 0.0, 4.0);
        let out = atrous(&params(16, 8, 1, false), &guides, &levels);
        assert!(out[3 * 16 + 7][0] > 1.2, "{}", out[3 * 16 + 7][0]);
        // Two objects in one plane mix too, unless object edges stop the filter.
        let (guides, levels) = split(near, plane(2.0, [0.0, 0.0, 1.0], 1), 0.0, 4.0);
        let out = atrous(&params(16, 8, 1, false), &guides, &levels);
        assert!(out[3 * 16 + 7][0] > 1.2, "{}", out[3 * 16 + 7][0]);
        let mut objects = params(16, 8, 1, false);
        objects.svgf.object_edges = 1;
        let out = atrous(&objects, &guides, &levels);
        let (left, right) = (mean_of_side(&out, false).0, mean_of_side(&out, true).0);
        assert!(left == 1.0 && right == 3.0, "object edge: {left} {right}");
        let out = variance(&objects, &guides, &levels, &vec![[1.0, 1.0]; 128]);
        assert_eq!(out[3 * 16 + 7][..3], [1.0; 3], "the spatial variance estimate stops there too");
    }

    #[test]
    fn the_history_is_taken_where_the_motion_points_and_only_from_the_same_surface() {
        let (width, height) = (6u32, 1u32);
        let g = DenoiseGuide { motion: [1.0, 0.0], ..plane(2.0, [0.0, 0.0, 1.0], 0) };
        let mut guides = vec![g; 6];
        guides[1].motion = [0.5, 0.0]; // halfway between pixels 1 and 2
        let mut previous_guides = vec![plane(2.0, [0.0, 0.0, 1.0], 0); 6];
        previous_guides[3].mesh = 9; // pixel 2's history: another object
        // Pixel 0 sees colour 1 on albedo 0.5: illumination 2, luminance 2.
        let mut colour = vec![[0.0f32; 4]; 6];
        colour[0] = [1.0; 4];
        let history: Vec<[f32; 4]> = (0..6).map(|x| [x as f32 * 10.0; 4]).collect();
        let mut previous_integrated = vec![[0.0, 0.0, 0.0, 9.0]; 6];
        previous_integrated[5][3] = 1.0; // pixel 4's history: one frame long
        let previous_moments = vec![[1.0, 2.0]; 6];
        let inputs = TemporalInputs {
            colour: &colour,
            guides: &guides,
            previous_guides: &previous_guides,
            history: &history,
            previous_integrated: &previous_integrated,
            previous_moments: &previous_moments,
        };
        let (integrated, moments) = temporal(&params(width, height, 1, true), &inputs);
        let close = |a: &[f32], b: &[f32]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-5);
        // Pixel 0 continues pixel 1's history of 9 frames: its 10th frame weighs alpha =
        // 0.2 in the colour (10 · 0.8 + 2 · 0.2) and in the moments of the luminance.
        assert!(close(&integrated[0], &[8.4, 8.4, 8.4, 10.0]), "{:?}", integrated[0]);
        assert!(close(&moments[0], &[1.0 * 0.8 + 2.0 * 0.2, 2.0 * 0.8 + 4.0 * 0.2]), "{:?}", moments[0]);
        // Pixel 1's history is half pixel 1's, half pixel 2's (their colours and lengths).
        assert!(close(&integrated[1], &[12.0, 12.0, 12.0, 10.0]), "{:?}", integrated[1]);
        // Pixel 4 continues a history of one frame: the two are averaged uniformly.
        assert!(close(&integrated[4], &[25.0, 25.0, 25.0, 2.0]), "{:?}", integrated[4]);
        // Pixel 2's is another object's: it starts again.
        assert_eq!(integrated[2], [0.0, 0.0, 0.0, 1.0]);
        // Pixel 5's lies outside the image.
        assert_eq!(integrated[5][3], 1.0);
        // Without history nothing is reprojected.
        let (fresh, _) = temporal(&params(width, height, 1, false), &inputs);
        assert!(fresh.iter().all(|p| p[3] == 1.0));
    }

    #[test]
    fn short_histories_take_their_variance_from_their_neighbours() {
        let g = plane(2.0, [0.0, 0.0, 1.0], 0);
        let guides = vec![g; 9];
        // Luminances 1 and 2 alternate; each pixel's own moments say variance 0.
        let integrated: Vec<[f32; 4]> =
            (0..9).map(|i| if i % 2 == 0 { [1.0, 1.0, 1.0, 2.0] } else { [2.0, 2.0, 2.0, 2.0] }).collect();
        let moments: Vec<[f32; 2]> = integrated.iter().map(|p| [p[0], p[0] * p[0]]).collect();
        let out = variance(&params(3, 3, 1, true), &guides, &integrated, &moments);
        assert!(out[4][3] > 0.2, "spatial variance {}", out[4][3]);
        // The shorter the history, the larger the variance: 4 / length times the spatial.
        let one_frame: Vec<[f32; 4]> = integrated.iter().map(|p| [p[0], p[1], p[2], 1.0]).collect();
        let boosted = variance(&params(3, 3, 1, true), &guides, &one_frame, &moments);
        assert!((boosted[4][3] / out[4][3] - 2.0).abs() < 1e-5, "{} against {}", boosted[4][3], out[4][3]);
        // A long history uses its own moments.
        let long: Vec<[f32; 4]> = integrated.iter().map(|p| [p[0], p[1], p[2], 8.0]).collect();
        let out = variance(&params(3, 3, 1, true), &guides, &long, &moments);
        assert_eq!(out[4][3], 0.0);
    }

    #[test]
    fn sky_passes_through_and_the_albedo_comes_back() {
        let sky = DenoiseGuide::default();
        let surface = DenoiseGuide { albedo: [0.5, 0.0, 2.0], ..plane(1.0, [0.0, 0.0, 1.0], 0) };
        let out = modulate(&[sky, surface], &[[7.0, 8.0, 9.0, 1.0], [0.0; 4]], &[[0.0; 4], [2.0, 3.0, 4.0, 0.0]]);
        assert_eq!(out, vec![[7.0, 8.0, 9.0, 0.0], [1.0, 3.0, 8.0, 0.0]]);
    }
}
