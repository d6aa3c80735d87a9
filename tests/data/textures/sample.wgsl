// textureSampleLevel and textureGather through a sampler, at coordinates inside and
// outside [0, 1] and at fractional levels, with a constant texel offset too; the
// sampler's filtering and addressing are the test's choice.
// Written for strata's texture corpus (issue 42).
//
// Bindings (group 0): 0 `image` texture_2d<f32> (mipmapped); 1 `image_sampler` sampler;
// 2 `probes` one vec4<f32> per probe (u, v, level, unused); 3 `sampled` three vec4<f32>
// per probe (textureSampleLevel, the same with offset (1, -1), textureGather of green).
// Dispatch: (ceil(probes / 64), 1, 1).

@group(0) @binding(0) var image: texture_2d<f32>;
@group(0) @binding(1) var image_sampler: sampler;
@group(0) @binding(2) var<storage, read> probes: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> sampled: array<vec4<f32>>;

@compute @workgroup_size(64, 1, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= arrayLength(&probes)) {
        return;
    }
    let probe = probes[id.x];
    sampled[3u * id.x] = textureSampleLevel(image, image_sampler, probe.xy, probe.z);
    sampled[3u * id.x + 1u] = textureSampleLevel(image, image_sampler, probe.xy, probe.z, vec2<i32>(1, -1));
    sampled[3u * id.x + 2u] = textureGather(1, image, image_sampler, probe.xy);
}
