// The lat-long environment map (CONVENTIONS.md "Emitters"): lookup and importance
// sampling. Texels are read with `scene_texel` from params.env_texel_offset, row 0 = the +Y pole.
// Sampling is piecewise constant over W x H cells in (u, v), each weighted on the host by
// the largest luminance its bilinear footprint can take times sin(theta) at its centre,
// so every direction with radiance has a positive density. `scene_environment_cdf` reads the
// marginal CDF over rows (H + 1 entries) and then one CDF per row (W + 1 entries each).

// #import render/scene.wgsl
// #import render/turns.wgsl

// (u, v) of a direction in the map's own frame.
fn environment_uv(local: vec3<f32>) -> vec2<f32> {
    let u = fract(atan2(local.x, -local.z) / (2.0 * PI));
    let v = clamp(acos(clamp(local.y, -1.0, 1.0)) / PI, 0.0, 1.0);
    return vec2<f32>(u, v);
}

fn environment_local(direction: vec3<f32>) -> vec3<f32> {
    let l = vec3<f32>(
        dot(params.env_from_world_0, direction),
        dot(params.env_from_world_1, direction),
        dot(params.env_from_world_2, direction),
    );
    return normalize(l);
}

fn environment_texel(x: u32, y: u32) -> vec3<f32> {
    return scene_texel(params.env_texel_offset + y * params.env_width + x).xyz;
}

// Radiance arriving from world direction `direction` (bilinear: texel-centred phi,
// align-corners theta, as Mitsuba 3.9.1 does), times params.env_scale.
fn environment_radiance(direction: vec3<f32>) -> vec3<f32> {
    let uv = environment_uv(environment_local(direction));
    let width = params.env_width;
    let height = params.env_height;
    let x = uv.x * f32(width) - 0.5;
    let y = uv.y * f32(height - 1u);
    let x0 = floor(x);
    let fx = x - x0;
    let column0 = u32(i32(x0) + i32(width)) % width;
    let column1 = (column0 + 1u) % width;
    let row0 = min(u32(floor(y)), height - 1u);
    let row1 = min(row0 + 1u, height - 1u);
    let fy = y - f32(row0);
    let top = mix(environment_texel(column0, row0), environment_texel(column1, row0), fx);
    let bottom = mix(environment_texel(column0, row1), environment_texel(column1, row1), fx);
    return mix(top, bottom, fy) * params.env_scale;
}

// The largest index i in [0, entries - 2] of the CDF at `base` with cdf[i] <= u:
// the cell that u falls into, never a cell of zero probability.
fn find_cell(base: u32, entries: u32, u: f32) -> u32 {
    var low = 0u;
    var high = entries - 1u;
    while high - low > 1u {
        let middle = (low + high) / 2u;
        if scene_environment_cdf(base + middle) <= u {
            low = middle;
        } else {
            high = middle;
        }
    }
    return low;
}

// Solid-angle density of `sample_environment` for world direction `direction`.
fn environment_pdf(direction: vec3<f32>) -> f32 {
    let local = environment_local(direction);
    let sin_theta = sqrt(max(0.0, 1.0 - local.y * local.y));
    if sin_theta <= 0.0 {
        return 0.0;
    }
    let uv = environment_uv(local);
    let width = params.env_width;
    let height = params.env_height;
    let column = min(u32(uv.x * f32(width)), width - 1u);
    let row = min(u32(uv.y * f32(height)), height - 1u);
    let p_row = scene_environment_cdf(row + 1u) - scene_environment_cdf(row);
    let base = height + 1u + row * (width + 1u);
    let p_column = scene_environment_cdf(base + column + 1u) - scene_environment_cdf(base + column);
    return p_row * p_column * f32(width * height) / (2.0 * PI * PI * sin_theta);
}

// A world direction drawn with density `environment_pdf`.
fn sample_environment(u: vec2<f32>) -> vec3<f32> {
    let width = params.env_width;
    let height = params.env_height;
    let row = find_cell(0u, height + 1u, u.x);
    let row_low = scene_environment_cdf(row);
    let dv = clamp((u.x - row_low) / (scene_environment_cdf(row + 1u) - row_low), 0.0, 1.0);
    let base = height + 1u + row * (width + 1u);
    let column = find_cell(base, width + 1u, u.y);
    let column_low = scene_environment_cdf(base + column);
    let du = clamp((u.y - column_low) / (scene_environment_cdf(base + column + 1u) - column_low), 0.0, 1.0);
    // θ = π v and φ = 2π u, in turns.
    let theta = sin_cos_turns(0.5 * (f32(row) + dv) / f32(height));
    let phi = sin_cos_turns((f32(column) + du) / f32(width));
    let local = vec3<f32>(theta.x * phi.x, theta.y, -theta.x * phi.y);
    let world = vec3<f32>(
        dot(params.env_to_world_0, local),
        dot(params.env_to_world_1, local),
        dot(params.env_to_world_2, local),
    );
    return normalize(world);
}
