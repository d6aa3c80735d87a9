// Sine and cosine of an angle given in turns (2π · turns radians), computed here rather
// than by the builtins, so that every backend returns the same value within an ULP or
// two.
//
// Why: WGSL (like Vulkan) lets sin and cos err by 2^-11 absolute on [-π, π], and drivers
// use that room. SwiftShader, the WebGPU device of headless Chromium, is 1.9e-4 off
// (up to 42 563 ULP near a zero), against 6e-8 on lavapipe and the interpreter; a
// sampled direction that far off moves a path's next vertex, and the cross-backend check
// saw 0.1-0.4 % of the ReSTIR passes' values beyond their bound on WebGPU. Every angle the kernels draw is a fraction of a
// turn (φ = 2π u, θ = π v), so the reduction below is exact and the polynomials need
// only cover an eighth of a turn.
//
// Reduction: q = round(4 t) and r = t − q/4 in [−1/8, 1/8] (exact: q/4 is within a
// factor 2 of t or zero), x = 2π r in [−π/4, π/4]; then sin(x + q π/2) is ±sin x or
// ±cos x. On [−π/4, π/4] the Taylor series to x^11 (sine) and x^12 (cosine) leave a
// truncation error below 1e-11, far under f32's rounding, so the result is the correctly
// rounded value within the Horner evaluation's few roundings (backends that fuse
// a * b + c differ by an ULP).

// sin(2π t) and cos(2π t) for a finite t; t in [0, 1] for the kernels' angles.
fn sin_cos_turns(turns: f32) -> vec2<f32> {
    let t = fract(turns);
    let quadrant = round(4.0 * t);
    let x = (t - 0.25 * quadrant) * 6.2831855;
    let z = x * x;
    let s = x + x * z * (-1.0 / 6.0 + z * (1.0 / 120.0 + z * (-1.0 / 5040.0 + z * (1.0 / 362880.0 + z * (-1.0 / 39916800.0)))));
    let c = 1.0 + z * (-0.5 + z * (1.0 / 24.0 + z * (-1.0 / 720.0 + z * (1.0 / 40320.0 + z * (-1.0 / 3628800.0 + z * (1.0 / 479001600.0))))));
    switch u32(quadrant) % 4u {
        case 1u: {
            return vec2<f32>(c, -s);
        }
        case 2u: {
            return vec2<f32>(-s, -c);
        }
        case 3u: {
            return vec2<f32>(-c, s);
        }
        default: {
            return vec2<f32>(s, c);
        }
    }
}
