// ReSTIR pass 5: shading. Each pixel's image value is what it estimated on its own
// (emission at y1, the smooth chain before its resampling vertex, or its whole path when
// it does not resample) plus its reservoir's part, times the chain's throughput
// (Primary.throughput, 1 without a chain): with RestirParams.shading = SHADING_SAMPLE its
// sample, f(Y) V(y1, Y) W, with one shadow ray; with SHADING_EXPECTATION the expectation
// of the frame's final resampling over its choice (Reservoir.expected, no ray). A sample
// of kind PRIVATE can only be the pixel's own (nobody else can reconnect to it) and was
// found along an unoccluded ray: it needs no shadow ray. RestirParams.shaded_parts can
// leave out either part, to measure the other's variance (a diagnostic).
//
// Bindings (group 0): 0-2 the scene (3-7 unused), 8 RestirParams, and
//   9  storage, read     array<Primary>     G-buffer
//   10 storage, read     array<Reservoir>   final reservoirs
//   11 storage, read     array<vec4<f32>>   base radiance (rgb; a = 1 for an invalid sample)
//   12 storage, rw       array<vec4<f32>>   the frame: rgb; a = 1 for an invalid sample
//
// Dispatch: 8 x 8 pixels per workgroup.

// #import render/scene.wgsl
// #import restir/reservoir.wgsl

@group(0) @binding(9) var<storage, read> primaries: array<Primary>;
@group(0) @binding(10) var<storage, read> reservoirs: array<Reservoir>;
@group(0) @binding(11) var<storage, read> base_in: array<vec4<f32>>;
@group(0) @binding(12) var<storage, read_write> frame_out: array<vec4<f32>>;

@compute @workgroup_size(8, 8)
fn restir_shade(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    let pixel = id.y * params.width + id.x;
    let p = primaries[pixel];
    let base = base_in[pixel];
    var radiance = base.xyz;
    if (restir.shaded_parts & 1u) == 0u {
        radiance = vec3<f32>(0.0);
    }
    let reservoir = reservoirs[pixel];
    // The resampled part is the light reflected at the resampling vertex; behind a
    // smooth chain it reaches the camera weighted by the chain's throughput.
    if (restir.shaded_parts & 2u) != 0u && (p.flags & PRIMARY_RESAMPLE) != 0u && restir.shading == SHADING_EXPECTATION {
        radiance += p.throughput * reservoir.expected;
    } else if (restir.shaded_parts & 2u) != 0u && (p.flags & PRIMARY_RESAMPLE) != 0u && reservoir.weight > 0.0 {
        let y = reservoir.sample;
        var seen = y.kind == KIND_PRIVATE;
        if !seen {
            seen = reconnectable(p, y) && candidate_visible(p, y, lane);
        }
        if seen {
            radiance += p.throughput * integrand(p, y, lane) * reservoir.weight;
        }
    }
    var invalid = base.w;
    if !finite3(radiance) {
        radiance = vec3<f32>(0.0);
        invalid = 1.0;
    }
    frame_out[pixel] = vec4<f32>(radiance, invalid);
}
