// One step of a 2-D flock, shaped like the flocking samples of public WebGPU
// collections (written here): a uniform struct of seven f32 (an odd member count, so
// the struct is padded to 32 bytes), a read-only runtime array of structs whose length
// comes from arrayLength, and distance / normalize in a loop over every other boid.
// Boid i sums the positions of boids within `cohesion_distance`, the offsets
// normalize(pos_i - pos_j) of those within `separation_distance` and the velocities of
// those within `alignment_distance`; each sum steers the velocity by its scale, the
// speed is clamped to 0.1 and the position wraps into [-1, 1).
// Bindings: 0 uniform SimParams, 1 boids_in (read), 2 boids_out (read_write).
// Integer counts of each neighbourhood go to the w-less `counts` output (binding 3):
// a backend that never finds a neighbour shows it there.

struct SimParams {
    dt: f32,
    cohesion_distance: f32,
    separation_distance: f32,
    alignment_distance: f32,
    cohesion_scale: f32,
    separation_scale: f32,
    alignment_scale: f32,
}

struct Boid {
    pos: vec2<f32>,
    vel: vec2<f32>,
}

@group(0) @binding(0) var<uniform> sim: SimParams;
@group(0) @binding(1) var<storage, read> boids_in: array<Boid>;
@group(0) @binding(2) var<storage, read_write> boids_out: array<Boid>;
@group(0) @binding(3) var<storage, read_write> counts: array<vec4<u32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let count = arrayLength(&boids_in);
    let i = gid.x;
    if i >= count {
        return;
    }
    let me = boids_in[i];
    var center = vec2<f32>(0.0);
    var push = vec2<f32>(0.0);
    var heading = vec2<f32>(0.0);
    var near = vec3<u32>(0u);
    for (var j = 0u; j < count; j++) {
        if j == i {
            continue;
        }
        let other = boids_in[j];
        let d = distance(other.pos, me.pos);
        if d < sim.cohesion_distance {
            center += other.pos;
            near.x += 1u;
        }
        if d < sim.separation_distance && d > 0.0 {
            push += normalize(me.pos - other.pos);
            near.y += 1u;
        }
        if d < sim.alignment_distance {
            heading += other.vel;
            near.z += 1u;
        }
    }
    var vel = me.vel;
    if near.x > 0u {
        vel += (center / f32(near.x) - me.pos) * sim.cohesion_scale;
    }
    vel += push * sim.separation_scale;
    if near.z > 0u {
        vel += heading / f32(near.z) * sim.alignment_scale;
    }
    let speed = length(vel);
    if speed > 0.1 {
        vel = vel * (0.1 / speed);
    }
    var pos = me.pos + vel * sim.dt;
    pos = select(pos, pos - 2.0 * sign(pos), abs(pos) > vec2<f32>(1.0));
    boids_out[i] = Boid(pos, vel);
    counts[i] = vec4<u32>(near, count);
}
