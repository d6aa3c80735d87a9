// The scene as the path-tracing kernels see it: the frame's parameters, the BVH with its
// triangles in leaf order, per-triangle attributes, materials, emissive triangles,
// texels (textures and the environment map) and the environment's sampling CDFs.
// The records and their constants are declared once in Rust, kernels/src/render_types.rs,
// which generates gpu/render.wgsl and the records' readers gpu/scene_rows.wgsl.
//
// The seven arrays lie end to end in one storage buffer of 16-byte rows, each record in
// its rows as in an array of its own, each array from the row RenderParams names
// (`nodes_row`, `triangles_row`, ...; the host's GpuScene::rows). One buffer, not seven,
// because a browser's WebGPU allows a stage 10 storage buffers, and the ReSTIR passes
// bind up to 9 of their own. A scene of at most SCENE_UNIFORM_ROWS rows is also bound as
// a uniform copy, which kernels specialised with scene_in_uniform read instead. The
// accessors below, through scene_row, are all that reads either.
//
// Bindings (group 0), shared by every kernel that includes this fragment:
//   0 uniform            RenderParams              image, camera, environment, flags, rows
//   1 storage, read      array<vec4<u32>>          the scene's rows:
//                          BvhNode (3 rows)          obvhs Bvh2 nodes (root at 0)
//                          Triangle (3 rows)         triangles in BVH leaf order
//                          TriangleInfo (3 rows)     object id, material, light, UVs
//                          Material (4 rows)         materials
//                          EmissiveTriangle (2 rows) area lights with their selection CDF
//                          vec4<f32> (1 row)         texels: textures, then the environment
//                          f32 (4 per row)           environment CDFs (marginal, conditionals)
//   2 uniform            array<vec4<u32>, SCENE_UNIFORM_ROWS>  the same rows when the
//                          scene fits, zeros otherwise; read with scene_in_uniform (below)

// #import gpu/render.wgsl
// #import gpu/scene_rows.wgsl
// #import trace/bvh.wgsl
// #import trace/traverse.wgsl
// #import render/random.wgsl

// The film position of pixel `pixel`'s camera ray: a uniform point of the pixel from
// `u` in [0, 1)², or its centre with FLAG_PIXEL_CENTRES.
//
// With FLAG_STRATIFIED_FILM, `u` is ignored (the caller still draws it, so the rest of
// its random numbers stay paired with an unstratified run) and sample n of the pixel
// takes point n of the R2 sequence shifted by a per-pixel random start (Cranley-Patterson
// rotation). The start is uniform, so each sample alone is a uniform point of the pixel
// (unbiased frame by frame and sample by sample); along n the points cover the pixel
// evenly, so averaging successive frames averages away the anti-aliasing noise faster
// than independent points do. Integer arithmetic (wrapping 0.32 fixed point), so every
// backend computes the same position.
fn film_position(pixel: vec2<u32>, u: vec2<f32>) -> vec2<f32> {
    if (params.flags & FLAG_PIXEL_CENTRES) != 0u {
        return vec2<f32>(pixel) + vec2<f32>(0.5);
    }
    if (params.flags & FLAG_STRATIFIED_FILM) != 0u {
        let start_x = pcg_hash(pcg_hash(params.seed ^ 0xf11ef11eu) ^ (pixel.y * params.width + pixel.x));
        let start_y = pcg_hash(start_x);
        let fixed = vec2<u32>(start_x + params.sample_index * R2_STEP_X, start_y + params.sample_index * R2_STEP_Y);
        return vec2<f32>(pixel) + vec2<f32>(fixed >> vec2<u32>(8u)) * (1.0 / 16777216.0);
    }
    return vec2<f32>(pixel) + u;
}

const PI: f32 = 3.14159265358979;
// f32's largest finite value, written exactly: the decimal 3.4028235e38 lies above it,
// which naga rounds down and WGSL (Tint) refuses as not representable.
const INFINITY: f32 = 0x1.fffffep+127f;

@group(0) @binding(0) var<uniform> params: RenderParams;
@group(0) @binding(1) var<storage, read> scene_rows: array<vec4<u32>>;
@group(0) @binding(2) var<uniform> scene_rows_uniform: array<vec4<u32>, SCENE_UNIFORM_ROWS>;

// Whether the scene's rows are read from their uniform copy (the host specialises a
// kernel with true when the scene has at most SCENE_UNIFORM_ROWS rows: the default room
// has 307). Why: lavapipe reads a storage buffer one lane at a time, with a branch per
// lane and per component, and a uniform buffer with a branch-free gather; the
// path tracer at 128 x 128 takes 21.7 ms a sample against 29.6, a ReSTIR frame 10-20 % less
// (benches/benches/memory_reads.rs; docs/benchmarks/ci-time.md, twelfth section). On a
// GPU either is fine. Specialised (a pipeline constant), not a uniform flag: lavapipe
// runs both sides of a branch, and the constant lets the driver drop the other read.
override scene_in_uniform: bool = false;

// Row `row` of the scene's rows (gpu/scene_rows.wgsl's readers read every record
// through it).
fn scene_row(row: u32) -> vec4<u32> {
    if scene_in_uniform {
        return scene_rows_uniform[row];
    }
    return scene_rows[row];
}

fn bvh_node(index: u32) -> BvhNode {
    return read_bvh_node(params.nodes_row, index);
}

fn bvh_triangle(index: u32) -> Triangle {
    return read_triangle(params.triangles_row, index);
}

fn scene_triangle_info(index: u32) -> TriangleInfo {
    return read_triangle_info(params.triangle_info_row, index);
}

fn scene_material(index: u32) -> Material {
    return read_material(params.materials_row, index);
}

fn scene_light(index: u32) -> EmissiveTriangle {
    return read_emissive_triangle(params.lights_row, index);
}

fn scene_texel(index: u32) -> vec4<f32> {
    return bitcast<vec4<f32>>(scene_row(params.texels_row + index));
}

fn scene_environment_cdf(index: u32) -> f32 {
    return bitcast<f32>(scene_row(params.environment_cdf_row + index / 4u)[index % 4u]);
}

var<workgroup> trace_stack: array<u32, 2560>;

// The triangles were reordered into leaf order on the host.
fn leaf_triangle(slot: u32) -> u32 {
    return slot;
}

// What a ray hit, in world space.
struct Surface {
    position: vec3<f32>,
    // Unit geometric normal (counter-clockwise winding), not flipped.
    normal: vec3<f32>,
    uv: vec2<f32>,
    object_id: u32,
    material: u32,
    light: u32,
}

fn surface_at(hit: Hit) -> Surface {
    let tri = bvh_triangle(hit.primitive);
    let info = scene_triangle_info(hit.primitive);
    let w = 1.0 - hit.u - hit.v;
    let position = w * tri.v0 + hit.u * tri.v1 + hit.v * tri.v2;
    let normal = normalize(cross(tri.v1 - tri.v0, tri.v2 - tri.v0));
    var uv = vec2<f32>(hit.u, hit.v);
    if info.has_uv != 0u {
        uv = w * info.uv0 + hit.u * info.uv1 + hit.v * info.uv2;
    }
    return Surface(position, normal, uv, info.object_id, info.material, info.light);
}

// A ray leaving `position` along `direction`, its origin pushed off the surface to the
// side the ray goes, so it cannot hit the triangle it starts on.
fn spawn_ray(position: vec3<f32>, normal: vec3<f32>, direction: vec3<f32>, tmax: f32) -> Ray {
    let side = select(-normal, normal, dot(normal, direction) > 0.0);
    let extent = max(max(abs(position.x), abs(position.y)), max(abs(position.z), 1.0));
    let origin = position + side * (params.ray_epsilon * extent);
    return Ray(origin, 0.0, direction, tmax);
}

// The shadow ray of the segment from `position` (on a surface with `normal`) to
// `target_point`, which lies on a light. The segment starts at the offset origin of
// spawn_ray and stops the same scale-relative epsilon short of the target, so neither
// the surface nor the light's own triangle can occlude it; tmax <= 0 when nothing is
// left to test (ray_unblocked then says so without a traversal).
fn shadow_ray_to(position: vec3<f32>, normal: vec3<f32>, target_point: vec3<f32>) -> Ray {
    let start = spawn_ray(position, normal, target_point - position, 0.0).origin;
    let to_target = target_point - start;
    let distance = length(to_target);
    let extent = max(max(abs(target_point.x), abs(target_point.y)), max(abs(target_point.z), 1.0));
    let tmax = distance - params.ray_epsilon * extent;
    if tmax <= 0.0 {
        return Ray(start, 0.0, to_target, tmax);
    }
    return Ray(start, 0.0, to_target / distance, tmax);
}

// The shadow ray from `position` towards the environment along `direction`.
fn shadow_ray_along(position: vec3<f32>, normal: vec3<f32>, direction: vec3<f32>) -> Ray {
    return spawn_ray(position, normal, direction, INFINITY);
}

// True when nothing blocks shadow ray `ray` (shadow_ray_to, shadow_ray_along). Callers
// choose the ray in branches and call this once (next-event estimation, a candidate's
// visibility): a driver inlines each call site's BVH traversal, and the traversals were
// most of what a CPU driver took minutes to compile (BENCHMARKS "First run on a fresh
// machine"). restir_candidates' draw_candidate tests its shadow rays through its own one
// traversal, which also finds its BSDF sample's next vertex.
fn ray_unblocked(ray: Ray, lane: u32) -> bool {
    if ray.tmax <= 0.0 {
        return true;
    }
    return traverse(ray, lane, true).primitive == MISS;
}

// The camera ray through film position `film` (pixels, (0, 0) the top-left corner),
// starting on the near plane (CONVENTIONS.md "Camera").
fn camera_ray(film: vec2<f32>) -> Ray {
    let px = film.x / f32(params.width);
    let py = film.y / f32(params.height);
    let sx = (2.0 * px - 1.0) * params.tan_half_x;
    let sy = (2.0 * py - 1.0) * params.tan_half_y;
    let direction = normalize(params.camera_forward + sx * params.camera_right - sy * params.camera_up);
    let start = params.camera_origin + direction * (params.near_clip / dot(direction, params.camera_forward));
    return Ray(start, 0.0, direction, INFINITY);
}
