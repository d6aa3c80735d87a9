// A 3-D dispatch over a volume (written here): each invocation hashes its global id
// with wrapping u32 multiplies and adds (the arithmetic of hash-based noise), chooses
// per component between two vectors with `select` on a vec3<bool>, and writes one
// vec4<u32> per voxel plus one f32 from the selected vector. Tests u32 wrap-around,
// shift amounts masked to 0-31, and WGSL's integer division everywhere: signed `/` and
// `%` of negative numbers (the remainder takes the dividend's sign), by zero (`a / 0`
// is a, `a % 0` is 0, signed and unsigned) and i32::MIN by -1 (MIN, remainder 0).
// Bindings: 0 uniform dims (x, y, z, seed), 1 words (read_write, vec4<u32> per voxel:
// wrapped, shifted ^ unsigned quotient ^ unsigned remainder, signed quotient, signed
// remainder), 2 shades (read_write, f32 per voxel). Workgroup 4 × 4 × 4.

struct Dims {
    x: u32,
    y: u32,
    z: u32,
    seed: u32,
}

@group(0) @binding(0) var<uniform> dims: Dims;
@group(0) @binding(1) var<storage, read_write> words: array<vec4<u32>>;
@group(0) @binding(2) var<storage, read_write> shades: array<f32>;

fn hash(v: u32) -> u32 {
    var h = v * 747796405u + 2891336453u;
    h = ((h >> ((h >> 28u) + 4u)) ^ h) * 277803737u;
    return (h >> 22u) ^ h;
}

@compute @workgroup_size(4, 4, 4)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if any(gid >= vec3<u32>(dims.x, dims.y, dims.z)) {
        return;
    }
    let index = (gid.z * dims.y + gid.y) * dims.x + gid.x;
    let h = hash(index ^ dims.seed);
    let wrapped = h * 0x9E3779B9u + 0xFFFFFFF0u;
    let shift = h & 63u;
    let shifted = wrapped << (shift & 31u);
    let small = h & 7u;
    let unsigned_mix = shifted ^ (wrapped / small) ^ (wrapped % small);
    // One voxel in 16 divides i32::MIN; the divisor is 5, -7, 0 or -1.
    let lowest = bitcast<i32>(0x80000000u);
    let signed = select(bitcast<i32>(h), lowest, ((h >> 8u) & 15u) == 0u);
    let pick = (h >> 12u) & 3u;
    let divisor = select(select(5, -7, pick == 1u), select(0, -1, pick == 3u), pick >= 2u);
    let quotient = signed / divisor;
    let remainder = signed % divisor;
    let a = vec3<f32>(f32(h & 0xffu), f32((h >> 8u) & 0xffu), f32((h >> 16u) & 0xffu)) / 255.0;
    let b = vec3<f32>(gid) / vec3<f32>(f32(dims.x), f32(dims.y), f32(dims.z));
    let lanes = (vec3<u32>(h, h >> 1u, h >> 2u) & vec3<u32>(1u)) == vec3<u32>(1u);
    let chosen = select(a, b, lanes);
    words[index] = vec4<u32>(wrapped, unsigned_mix, bitcast<u32>(quotient), bitcast<u32>(remainder));
    shades[index] = dot(chosen, vec3<f32>(0.25, 0.5, 0.25));
}
