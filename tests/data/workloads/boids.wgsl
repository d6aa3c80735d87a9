// One step of a boids flock in the cube [-1, 1)^3. Boid i looks at every other boid j
// (in index order) at distance length(pos_j - pos_i) < radius: it sums their positions
// and velocities, and for those closer than separation it subtracts
// normalize(d) / dist (d = pos_j - pos_i). With n neighbours it steers by
// cohesion * (center / n - pos) + alignment * (mean velocity - vel) + repulsion
// * separation sum; the speed is clamped to max_speed (vel * (max_speed / speed)),
// pos += vel * dt, and the position wraps back into the cube.
// Bindings: 0 uniform params (count, dt, radius, separation, cohesion, alignment,
// repulsion, max_speed), 1 src boids (read), 2 dst boids (read_write); a boid is
// { pos: vec4<f32>, vel: vec4<f32> } with w unused (carried along).

struct Params {
    count: u32,
    dt: f32,
    radius: f32,
    separation: f32,
    cohesion: f32,
    alignment: f32,
    repulsion: f32,
    max_speed: f32,
}
struct Boid { pos: vec4<f32>, vel: vec4<f32> }

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> src: array<Boid>;
@group(0) @binding(2) var<storage, read_write> dst: array<Boid>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if i >= params.count {
        return;
    }
    let me = src[i];
    let pos = me.pos.xyz;
    var vel = me.vel.xyz;
    var center = vec3<f32>(0.0);
    var heading = vec3<f32>(0.0);
    var push = vec3<f32>(0.0);
    var n = 0u;
    for (var j = 0u; j < params.count; j++) {
        if j == i {
            continue;
        }
        let other = src[j];
        let d = other.pos.xyz - pos;
        let dist = length(d);
        if dist < params.radius {
            center += other.pos.xyz;
            heading += other.vel.xyz;
            n += 1u;
            if dist < params.separation && dist > 0.0 {
                push -= normalize(d) / dist;
            }
        }
    }
    if n > 0u {
        let inv = 1.0 / f32(n);
        vel += ((center * inv - pos) * params.cohesion + (heading * inv - vel) * params.alignment) * params.dt;
    }
    vel += push * (params.repulsion * params.dt);
    let speed = length(vel);
    if speed > params.max_speed {
        vel = vel * (params.max_speed / speed);
    }
    var next = pos + vel * params.dt;
    next = next - 2.0 * floor((next + 1.0) * 0.5);
    dst[i] = Boid(vec4<f32>(next, me.pos.w), vec4<f32>(vel, me.vel.w));
}
