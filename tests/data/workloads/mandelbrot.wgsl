// Mandelbrot escape counts: pixel (x, y) of a width x height image samples
// c = (x0 + (x + 0.5) * scale, y0 + (y + 0.5) * scale) and iterates z = z^2 + c from 0,
// as zx' = zx*zx - zy*zy + cx, zy' = 2*zx*zy + cy, until zx*zx + zy*zy > 4 or
// max_iter iterations; out[y * width + x] = the iteration count (u32).
// Bindings: 0 uniform params (width, height, max_iter, unused, x0, y0, scale, unused),
// 1 out (read_write).

struct Params { width: u32, height: u32, max_iter: u32, unused0: u32, x0: f32, y0: f32, scale: f32, unused1: f32 }

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read_write> out: array<u32>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if gid.x >= params.width || gid.y >= params.height {
        return;
    }
    let cx = params.x0 + (f32(gid.x) + 0.5) * params.scale;
    let cy = params.y0 + (f32(gid.y) + 0.5) * params.scale;
    var zx = 0.0;
    var zy = 0.0;
    var i = 0u;
    loop {
        if i >= params.max_iter || zx * zx + zy * zy > 4.0 {
            break;
        }
        let xt = zx * zx - zy * zy + cx;
        zy = 2.0 * zx * zy + cy;
        zx = xt;
        i += 1u;
    }
    out[gid.y * params.width + gid.x] = i;
}
