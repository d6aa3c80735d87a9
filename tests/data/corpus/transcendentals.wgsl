// exp, log, pow, exp2 and log2 of each input value, each also iterated in a loop the
// way tone mappers and physics steps use them (written here). One invocation per
// input; every function has its own output binding so a bound can be stated per
// function.
// Bindings: 0 inputs (read, f32 in [0.05, 8)), 1 exps, 2 logs, 3 pows, 4 exp2s,
// 5 log2s (read_write, one f32 per input each).

@group(0) @binding(0) var<storage, read> inputs: array<f32>;
@group(0) @binding(1) var<storage, read_write> exps: array<f32>;
@group(0) @binding(2) var<storage, read_write> logs: array<f32>;
@group(0) @binding(3) var<storage, read_write> pows: array<f32>;
@group(0) @binding(4) var<storage, read_write> exp2s: array<f32>;
@group(0) @binding(5) var<storage, read_write> log2s: array<f32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if i >= arrayLength(&inputs) {
        return;
    }
    let x = inputs[i];
    exps[i] = exp(x - 4.0);
    logs[i] = log(x);
    pows[i] = pow(x, 1.0 / 2.2);
    exp2s[i] = exp2(x - 4.0);
    log2s[i] = log2(x);
}

// The same functions applied four times in a loop, each step feeding the next. The
// steps are contractions (each maps its range into itself with a slope below one), so a
// difference of a few ULPs in one step does not grow through the next.
@compute @workgroup_size(64)
fn iterated(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if i >= arrayLength(&inputs) {
        return;
    }
    var e = inputs[i] * 0.25;
    var l = inputs[i] + 1.0;
    var p = inputs[i];
    for (var step = 0u; step < 4u; step++) {
        e = exp(e * 0.5) * 0.5;
        l = log(l) + 1.5;
        p = pow(p, 0.9) + 0.1;
    }
    exps[i] = e;
    logs[i] = l;
    pows[i] = p;
    exp2s[i] = exp2(e);
    log2s[i] = log2(l);
}
