//! The interpreter compiler's optimising passes keep WGSL's semantics: if-conversion
//! (an `if` that only stores into local variables becomes selects), store forwarding (a
//! value computed straight into the variable it is stored in), loads read in place (a
//! loaded value that is the variable's own registers), struct loads of the fields used
//! and jump cleanup. The kernels below put each pass at its edges, per invocation on
//! divergent inputs, and their outputs are checked word for word against the same
//! programs written in Rust.

use strata_backends::cpu_backend::{CpuBackend, CpuOptions};
use strata_kernels::Kernel;
use strata_tests::run_words;

const PASSES: &str = r#"
@group(0) @binding(0) var<storage, read> input: array<u32>;
@group(0) @binding(1) var<storage, read_write> output: array<u32>;

struct Pair { a: u32, b: u32 }

const OUTPUTS: u32 = 21u;

fn bump(p: ptr<function, u32>) {
    *p += 10u;
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    let x = input[i];
    let c = (x & 1u) != 0u;
    let d = (x & 2u) != 0u;
    let o = i * OUTPUTS;

    // Short-circuit operators (naga lowers them to an if storing into a local).
    let both = c && (x % 3u == 0u);
    let either = d || (x / max(x & 12u, 1u) > 5u);
    output[o] = u32(both) | (u32(either) << 1u);

    // Each branch reads the variable the other one writes.
    var p = x;
    var q = x ^ 0x55u;
    if c { p = q; } else { q = p + 7u; }
    output[o + 1u] = p * 3u + q;

    // A field in one branch, the whole struct in the other.
    var s = Pair(x, x + 1u);
    if d { s.a = 9u; } else { s = Pair(3u, 4u); }
    output[o + 2u] = s.a * 100u + s.b;

    // A load after a store in the same branch, and a branch that stores nothing.
    var t = 5u;
    if c { t = x; t = t * 2u; } else { }
    output[o + 3u] = t;

    // Division by zero and an index that are only computed where they are defined.
    var u = 0u;
    let table = array<u32, 4>(10u, 20u, 30u, 40u);
    let m = x % 4u;
    if m != 0u { u = 100u / m + table[m]; } else { u = 1u; }
    output[o + 4u] = u;

    // Nested: the inner if is converted, the outer one is a branch.
    var w = 7u;
    if d { if c { w = 1u; } else { w = 2u; } }
    output[o + 5u] = w;

    // A loop with continue and break (jumps to jumps, jumps to the next instruction).
    var n = 0u;
    var k = 0u;
    loop {
        k += 1u;
        if k > (x & 15u) { break; }
        if (k & 1u) == 0u { continue; }
        n += k;
    }
    output[o + 6u] = n;

    // A register stack shifted each iteration, and a counter updated in place.
    var r0 = x;
    var r1 = 0u;
    var r2 = 0u;
    for (var j = 0u; j < (x & 7u); j++) {
        r2 = r1;
        r1 = r0;
        r0 = r0 * 3u + j;
    }
    output[o + 7u] = r0 ^ (r1 << 1u) ^ (r2 << 2u);

    // Values computed from the variable they are stored into.
    var v = vec3<u32>(x, x + 1u, x + 2u);
    v = v.zxy;
    v = v + v.x;
    var e = Pair(x, x >> 3u);
    e = Pair(e.b, e.a);
    output[o + 8u] = v.x + v.y * 7u + v.z * 49u + e.a * 1000u + e.b;

    // A switch with a fall-through-free default.
    var z = 0u;
    switch x & 3u {
        case 0u: { z = 11u; }
        case 1u, 2u: { z = 22u; }
        default: { z = 33u; }
    }
    output[o + 9u] = z;

    // Several stores per branch, one variable stored in one branch only.
    var f = 1u;
    var g = 2u;
    var h = 3u;
    if (x & 4u) != 0u { f = x; g = f + 1u; } else { h = x; f = 5u; }
    output[o + 10u] = f * 10000u + g * 100u + h;

    // A select of a whole vector by an if.
    var vec_value = vec4<f32>(1.0, 2.0, 3.0, 4.0);
    if c { vec_value = vec4<f32>(f32(x), 0.5, -1.0, 8.0); }
    output[o + 11u] = bitcast<u32>(dot(vec_value, vec4<f32>(1.0, 2.0, 4.0, 8.0)));

    // A value stored and used again: it keeps its own registers.
    var stored = 0u;
    let y = x * 5u + 1u;
    stored = y;
    output[o + 12u] = stored * 3u + y;

    // Loads read in place only while their variable keeps the value: a value used
    // after a store into its variable.
    var a = x;
    let old = a;
    a = a + 5u;
    output[o + 13u] = old * 7u + a;

    // A value used in a loop that stores its variable; a value read at a loop's head and
    // stored back at its end.
    var b = x & 7u;
    let start = b;
    var acc = 0u;
    for (var j = 0u; j < 3u; j++) { acc += start; b += 1u; }
    var cnt = 0u;
    var sum = 0u;
    loop {
        let cur = cnt;
        if cur >= (x & 7u) { break; }
        sum += cur;
        cnt = cur + 1u;
    }
    output[o + 14u] = acc * 1000u + sum * 10u + b;

    // A swap through a loaded value.
    var s0 = x;
    var s1 = x * 3u;
    let t0 = s0;
    s0 = s1;
    s1 = t0;
    output[o + 15u] = s0 * 10u + s1;

    // If-conversion where one branch stores a loaded value before storing its variable,
    // and the other branch stores that variable too (its select comes first).
    var f2 = x;
    var g2 = 0u;
    if c { f2 = 9u; } else { let t = f2; g2 = t; f2 = 4u; }
    output[o + 16u] = f2 * 1000u + g2;

    // Fields: a field's value used after a store into the field; a whole struct's field
    // used after a store into another field.
    var pr = Pair(x, x + 1u);
    let fa = pr.a;
    pr.a = fa + pr.b;
    let whole = pr;
    pr.b = 0u;
    output[o + 17u] = pr.a * 3u + fa + whole.b * 5u + pr.b;

    // A condition read from the variable its if stores.
    var flag = (x & 8u) != 0u;
    var o2 = 0u;
    if flag { flag = false; o2 = 1u; } else { flag = true; o2 = 2u; }
    output[o + 18u] = u32(flag) * 10u + o2;

    // A value used after a call that writes its variable through a pointer.
    var bp = x;
    let before = bp;
    bump(&bp);
    output[o + 19u] = before * 2u + bp;

    // If-conversion where one branch stores a variable the other branch reads in place:
    // each side's lanes see the variable as it was.
    var a3 = 0u;
    var b3 = x;
    if c { b3 = 0u; } else { a3 = b3; }
    output[o + 20u] = a3 * 1000u + b3;
}
"#;

const OUTPUTS: usize = 21;

/// The kernel's program in Rust.
fn reference(x: u32) -> [u32; OUTPUTS] {
    let c = x & 1 != 0;
    let d = x & 2 != 0;
    let mut out = [0u32; OUTPUTS];
    let both = c && x.is_multiple_of(3);
    let either = d || x / (x & 12).max(1) > 5;
    out[0] = u32::from(both) | (u32::from(either) << 1);
    let (mut p, mut q) = (x, x ^ 0x55);
    if c {
        p = q;
    } else {
        q = p.wrapping_add(7);
    }
    out[1] = p.wrapping_mul(3).wrapping_add(q);
    let (a, b) = if d { (9, x.wrapping_add(1)) } else { (3, 4) };
    out[2] = a * 100 + b;
    out[3] = if c { x.wrapping_mul(2) } else { 5 };
    let m = x % 4;
    out[4] = 100u32.checked_div(m).map_or(1, |q| q + [10, 20, 30, 40][m as usize]);
    out[5] = match (d, c) {
        (true, true) => 1,
        (true, false) => 2,
        _ => 7,
    };
    out[6] = (1..=(x & 15)).filter(|k| k & 1 == 1).sum();
    let (mut r0, mut r1, mut r2) = (x, 0u32, 0u32);
    for j in 0..(x & 7) {
        r2 = r1;
        r1 = r0;
        r0 = r0.wrapping_mul(3).wrapping_add(j);
    }
    out[7] = r0 ^ (r1 << 1) ^ (r2 << 2);
    let v = [x.wrapping_add(2), x, x.wrapping_add(1)];
    let v = v.map(|c| c.wrapping_add(v[0]));
    let (ea, eb) = (x >> 3, x);
    out[8] = v[0]
        .wrapping_add(v[1].wrapping_mul(7))
        .wrapping_add(v[2].wrapping_mul(49))
        .wrapping_add(ea.wrapping_mul(1000))
        .wrapping_add(eb);
    out[9] = match x & 3 {
        0 => 11,
        1 | 2 => 22,
        _ => 33,
    };
    let (f, g, h) = if x & 4 != 0 { (x, x.wrapping_add(1), 3) } else { (5, 2, x) };
    out[10] = f.wrapping_mul(10000).wrapping_add(g.wrapping_mul(100)).wrapping_add(h);
    let vec_value = if c { [x as f32, 0.5, -1.0, 8.0] } else { [1.0, 2.0, 3.0, 4.0] };
    // WGSL's dot: the products summed in order (no contraction on the interpreter).
    let weights = [1.0f32, 2.0, 4.0, 8.0];
    let dot = vec_value.iter().zip(weights).fold(0.0f32, |sum, (a, w)| sum + a * w);
    out[11] = dot.to_bits();
    let y = x.wrapping_mul(5).wrapping_add(1);
    out[12] = y.wrapping_mul(3).wrapping_add(y);
    out[13] = x.wrapping_mul(7).wrapping_add(x.wrapping_add(5));
    let b = x & 7;
    out[14] = (3 * b) * 1000 + (0..b).sum::<u32>() * 10 + b + 3;
    out[15] = x.wrapping_mul(3).wrapping_mul(10).wrapping_add(x);
    let (f2, g2) = if c { (9u32, 0u32) } else { (4, x) };
    out[16] = f2 * 1000 + g2;
    let fa = x;
    let pa = fa.wrapping_add(x.wrapping_add(1));
    out[17] = pa.wrapping_mul(3).wrapping_add(fa).wrapping_add(x.wrapping_add(1).wrapping_mul(5));
    let flag = x & 8 == 0;
    out[18] = u32::from(flag) * 10 + if x & 8 != 0 { 1 } else { 2 };
    out[19] = x.wrapping_mul(2).wrapping_add(x.wrapping_add(10));
    out[20] = if c { 0 } else { x.wrapping_mul(1000).wrapping_add(x) };
    out
}

#[test]
fn optimising_passes_keep_wgsl_semantics_on_divergent_lanes() {
    let kernel = Kernel::from_wgsl("passes.wgsl", PASSES.into(), "main", false).unwrap();
    // Small values exercise every branch in both directions within each workgroup; the
    // large ones wrap.
    let inputs: Vec<u32> =
        (0..256u32).map(|i| if i < 192 { i.wrapping_mul(37) % 97 } else { i.wrapping_mul(2_654_435_761) }).collect();
    let mut cpu = CpuBackend::new(CpuOptions::default()).unwrap();
    let got = run_words(&mut cpu, &kernel, &inputs, inputs.len() * OUTPUTS, inputs.len() as u32 / 64);
    for (i, &x) in inputs.iter().enumerate() {
        let want = reference(x);
        let have = &got[i * OUTPUTS..(i + 1) * OUTPUTS];
        for (k, (h, w)) in have.iter().zip(want).enumerate() {
            assert_eq!(*h, w, "invocation {i} (input {x}), output {k}: {have:?} against {want:?}");
        }
    }
}

/// naga accepts a loop body's expression used by the continuing block even where a
/// `continue` skipped it (WGSL forbids this; naga does not check). Store forwarding must
/// not compute such a value into the variable at the body's end: a `continue` lands
/// between that instruction and the store, which then copies what the expression's
/// registers last held (here `e` = 1 at `i` = 2: v = 1 + 100), as without the pass.
#[test]
fn a_store_at_the_start_of_a_continuing_block_stays_a_copy() {
    let source = r#"
@group(0) @binding(0) var<storage, read> input: array<u32>;
@group(0) @binding(1) var<storage, read_write> output: array<u32>;
@compute @workgroup_size(1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    var v = 0u;
    var i = input[id.x];
    loop {
        if i >= 3u { break; }
        if i == 2u { continue; }
        let e = i;
        continuing {
            v = e;
            v = v + 100u;
            i = i + 1u;
        }
    }
    output[id.x] = v;
}
"#;
    let kernel = Kernel::from_wgsl("continuing.wgsl", source.into(), "main", false).unwrap();
    let mut cpu = CpuBackend::new(CpuOptions::default()).unwrap();
    let got = run_words(&mut cpu, &kernel, &[0], 1, 1);
    assert_eq!(got, [101]);
}

/// The 4-word records and the two bindings of the load tests below.
const QUADS: &str = "
struct Quad { a: u32, b: u32, c: u32, d: u32 }
@group(0) @binding(0) var<storage, read> quads: array<Quad>;
@group(0) @binding(1) var<storage, read_write> output: array<u32>;
";

/// Structs loaded through a pointer load only the fields their uses read (the
/// interpreter's `load_fields`): fields read directly, through a callee, in divergent
/// branches; from a buffer (an index past the end clamps to the last element), from
/// workgroup memory and from private memory; beside loads that must stay whole (a
/// store of the whole value). Checked word for word against Rust.
#[test]
fn struct_loads_read_the_fields_their_uses_need() {
    let source = QUADS.to_string()
        + r#"var<workgroup> shared_quads: array<Quad, 64>;
var<private> own: array<Quad, 2>;

fn cross(q: Quad) -> u32 {
    return q.a * 7u + q.c;
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    let i = id.x;
    let o = i * 6u;
    let q = quads[i];
    output[o] = q.b * 3u + q.d;
    output[o + 1u] = cross(quads[(i * 5u) % 64u]);
    var picked = 0u;
    if (q.a & 1u) != 0u {
        picked = quads[i + 1000u].c;
    } else {
        let far = quads[63u - i];
        picked = far.b + far.d * 2u;
    }
    output[o + 2u] = picked;
    shared_quads[lane] = Quad(q.d, q.c, q.b, q.a);
    workgroupBarrier();
    let n = shared_quads[(lane + 9u) % 64u];
    output[o + 3u] = n.a ^ (n.d << 4u);
    own[q.b & 1u] = Quad(i, q.a, q.b, q.c);
    let p = own[q.b & 1u];
    output[o + 4u] = p.a + p.c * 5u;
    var whole = quads[i / 2u];
    whole.b += 1u;
    output[o + 5u] = whole.a + whole.b + whole.c + whole.d;
}
"#;
    let kernel = Kernel::from_wgsl("struct_loads.wgsl", source, "main", false).unwrap();
    let words: Vec<u32> = (0..256u32).map(|k| k.wrapping_mul(2_654_435_761) >> (k % 7)).collect();
    let quad = |k: usize| -> [u32; 4] { words[4 * k.min(63)..][..4].try_into().unwrap() };
    let mut cpu = CpuBackend::new(CpuOptions::default()).unwrap();
    let got = run_words(&mut cpu, &kernel, &words, 64 * 6, 1);
    for i in 0..64usize {
        let [a, b, _, d] = quad(i);
        let cross = {
            let q = quad(i * 5 % 64);
            q[0].wrapping_mul(7).wrapping_add(q[2])
        };
        let picked = if a & 1 != 0 {
            quad(i + 1000)[2]
        } else {
            let f = quad(63 - i);
            f[1].wrapping_add(f[3].wrapping_mul(2))
        };
        let n = quad((i + 9) % 64);
        let shared = n[3] ^ (n[0] << 4);
        let private = (i as u32).wrapping_add(b.wrapping_mul(5));
        let w = quad(i / 2);
        let whole = w[0].wrapping_add(w[1].wrapping_add(1)).wrapping_add(w[2]).wrapping_add(w[3]);
        let want = [b.wrapping_mul(3).wrapping_add(d), cross, picked, shared, private, whole];
        assert_eq!(&got[i * 6..(i + 1) * 6], &want, "invocation {i}");
    }
}

/// Element loads of a runtime-sized array that starts after a header, in a buffer that
/// ends inside an element: the interpreter loads them in one instruction
/// (`element_load.rs`), which must clamp an index to the last whole element and count
/// from the array's first byte, as the pointer and the load it replaces did.
#[test]
fn element_loads_after_a_header_clamp_to_the_last_whole_element() {
    let source = r#"
struct Quad { a: u32, b: u32, c: u32, d: u32 }
struct Table { count: u32, p0: u32, p1: u32, p2: u32, quads: array<Quad> }
@group(0) @binding(0) var<storage, read> table: Table;
@group(0) @binding(1) var<storage, read_write> output: array<u32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    let q = table.quads[i * 3u];
    output[2u * i] = q.a ^ (q.d << 1u);
    output[2u * i + 1u] = table.quads[i].c + table.count;
}
"#;
    let kernel = Kernel::from_wgsl("element_loads.wgsl", source.into(), "main", false).unwrap();
    // 30 words: a 4-word header and six whole quads (the last two words belong to none).
    let words: Vec<u32> = (0..30u32).map(|k| k.wrapping_mul(2_654_435_761) >> (k % 5)).collect();
    let quad = |k: usize| -> [u32; 4] { words[4 + 4 * k.min(5)..][..4].try_into().unwrap() };
    let mut cpu = CpuBackend::new(CpuOptions::default()).unwrap();
    let got = run_words(&mut cpu, &kernel, &words, 128 * 2, 2);
    for i in 0..128usize {
        let q = quad(i * 3);
        let want = [q[0] ^ (q[3] << 1), quad(i)[2].wrapping_add(words[0])];
        assert_eq!(&got[i * 2..(i + 1) * 2], &want, "invocation {i}");
    }
}

/// Element loads of a fixed-size array in a buffer (a uniform buffer's rows, as
/// `render/scene.wgsl` reads a small scene): one instruction too, clamping an index past
/// the end to the last element as the pointer it replaces did (`PtrIndex`), after a
/// header.
#[test]
fn element_loads_of_a_fixed_size_array_clamp_to_its_last_element() {
    let source = r#"
struct Rows { first: vec4<u32>, rows: array<vec4<u32>, 40> }
@group(0) @binding(0) var<storage, read> table: Rows;
@group(0) @binding(1) var<storage, read_write> output: array<u32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    let row = table.rows[(i * 7u) % 64u];
    output[i] = row.x ^ (row.w << 3u) ^ table.first.y;
}
"#;
    let kernel = Kernel::from_wgsl("fixed_element_loads.wgsl", source.into(), "main", false).unwrap();
    let words: Vec<u32> = (0..164u32).map(|k| k.wrapping_mul(2_654_435_761) >> (k % 7)).collect();
    let mut cpu = CpuBackend::new(CpuOptions::default()).unwrap();
    let got = run_words(&mut cpu, &kernel, &words, 128, 2);
    for (i, &have) in got.iter().enumerate() {
        let row = 4 + 4 * ((i * 7) % 64).min(39);
        let want = words[row] ^ (words[row + 3] << 3) ^ words[1];
        assert_eq!(have, want, "invocation {i}");
    }
}

/// Element loads as a group executes them (`load_element` in the interpreter's
/// `execute.rs`), in a batch of several workgroups (512 invocations, `batch.rs`): a group
/// whose members all read one element (each word read once, its rows filled), workgroups
/// that each read one element (chunks of 64 members that agree in a group that does not),
/// members at elements of their own with indices past the end clamped, each of these also
/// in a branch that a third of the invocations take (a masked group, whose other lanes
/// must keep the words they hold in the same variable), in one that every other workgroup
/// takes (a masked group whose chunks agree) and in one that one invocation per workgroup
/// takes (a few members, lane by lane); two fields of an element (the other words not
/// loaded); indices past the end, clamped to the last whole element (the buffer ends
/// three words into one more); and a load at an address known when compiling
/// (`LoadBuffer`, read once). The buffer stores in the branches keep them branches (an
/// `if` of loads into variables alone becomes selects).
#[test]
fn element_loads_of_uniform_chunked_and_divergent_groups() {
    let source = QUADS.to_string()
        + r#"
@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(workgroup_id) group: vec3<u32>) {
    let i = id.x;
    // The last element: the same for every invocation, not known when compiling.
    let last = arrayLength(&quads) - 1u;
    var same = quads[last - 2u];
    var per_group = quads[group.x * 2u];
    var own = quads[i * 3u];
    if (i % 3u == 1u) {
        same = quads[last];
        per_group = quads[group.x * 5u + 1u];
        own = quads[i * 7u + 1u];
        output[i * 4u] = 1u;
    }
    if (group.x % 2u == 0u) {
        per_group = quads[group.x * 3u + 2u];
        output[i * 4u + 1u] = 1u;
    }
    if (i % 64u == 5u) {
        same = quads[last - 1u];
        per_group = quads[group.x + 7u];
        own = quads[i + 2u];
        output[i * 4u + 2u] = 1u;
    }
    let part = quads[i * 2u + 1u].b ^ quads[i / 64u].d;
    output[i * 4u] = same.a ^ (same.d << 1u);
    output[i * 4u + 1u] = per_group.b + per_group.c;
    output[i * 4u + 2u] = own.a ^ (own.d << 2u);
    output[i * 4u + 3u] = part + quads[3u].c;
}
"#;
    let kernel = Kernel::from_wgsl("group_element_loads.wgsl", source, "main", false).unwrap();
    // 300 whole quads and three words of a 301st, which is no element of the array.
    let words: Vec<u32> = (0..4 * 301 - 1).map(|k: u32| k.wrapping_mul(2_654_435_761) >> (k % 7)).collect();
    let quad = |k: usize| -> [u32; 4] { words[4 * k.min(299)..][..4].try_into().unwrap() };
    let mut cpu = CpuBackend::new(CpuOptions::default()).unwrap();
    const GROUPS: usize = 12;
    let got = run_words(&mut cpu, &kernel, &words, GROUPS * 64 * 4, GROUPS as u32);
    for i in 0..GROUPS * 64 {
        let (group, third, even, one) = (i / 64, i % 3 == 1, (i / 64) % 2 == 0, i % 64 == 5);
        let same = quad(if one {
            298
        } else if third {
            299
        } else {
            297
        });
        let per_group = quad(if one {
            group + 7
        } else if even {
            group * 3 + 2
        } else if third {
            group * 5 + 1
        } else {
            group * 2
        });
        let own = quad(if one {
            i + 2
        } else if third {
            i * 7 + 1
        } else {
            i * 3
        });
        let part = (quad(i * 2 + 1)[1] ^ quad(i / 64)[3]).wrapping_add(quad(3)[2]);
        let want = [same[0] ^ (same[3] << 1), per_group[1].wrapping_add(per_group[2]), own[0] ^ (own[3] << 2), part];
        assert_eq!(&got[i * 4..(i + 1) * 4], &want, "invocation {i}");
    }
}

/// The passes that keep the generated row readers (`gpu/scene_rows.wgsl`) and their
/// callers from copying what they read (issue 59): a struct or call result returned by
/// an inlined callee is computed in the call's result registers; consecutive components
/// (`row.yzw`) are the vector's own registers, also when it is a variable read in place
/// that is stored afterwards; a branch on a constant compiles only the side it takes.
/// Each output puts one of them at its edge: values computed before their `return` and
/// returned in one branch, results passed on through two calls, a swap of a struct's
/// fields into the result, returns inside a loop and a switch.
#[test]
fn returned_records_and_consecutive_components_keep_wgsl_semantics() {
    let source = r#"
@group(0) @binding(0) var<storage, read> input: array<u32>;
@group(0) @binding(1) var<storage, read_write> output: array<u32>;

struct Pair { a: u32, b: u32 }
struct Halves { lo: vec2<u32>, hi: vec2<u32> }

const FOLDED: bool = false;

fn make(x: u32) -> Pair { return Pair(x + 1u, x * 2u); }
fn forward(x: u32) -> Pair { return make(x); }
fn swapped(p: Pair) -> Pair { return Pair(p.b, p.a); }
fn pick(c: bool, x: u32) -> Pair {
    let first = Pair(x, 1u);
    let second = Pair(2u, x);
    if c { return first; }
    return second;
}
fn branchy(c: bool, x: u32) -> Pair {
    if c { return Pair(x, 3u); } else { return make(x + 5u); }
}
fn halves(row: vec4<u32>) -> Halves { return Halves(row.xy, row.zw); }
fn first_set_bit(x: u32) -> Pair {
    for (var i = 0u; i < 8u; i++) {
        if ((x >> i) & 1u) == 1u { return Pair(i, x >> i); }
    }
    return Pair(99u, x);
}
fn by_case(x: u32) -> Pair {
    switch x & 3u {
        case 0u: { return Pair(1u, x); }
        case 1u: { return make(x); }
        default: { return Pair(x, 2u); }
    }
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    let x = input[i];
    let c = (x & 1u) != 0u;
    let o = i * 10u;
    let f = forward(x);
    output[o] = f.a * 1000u + f.b;
    let s = swapped(swapped(swapped(forward(x))));
    output[o + 1u] = s.a * 1000u + s.b;
    let p = pick(c, x);
    output[o + 2u] = p.a * 1000u + p.b;
    let q = branchy(c, x);
    output[o + 3u] = q.a * 1000u + q.b;
    var row = vec4<u32>(x, x + 1u, x + 2u, x + 3u);
    let tail = row.yzw;
    row.y = 0u;
    output[o + 4u] = tail.x * 10000u + tail.y * 100u + tail.z + row.y;
    let h = halves(vec4<u32>(x, x ^ 5u, x * 3u, 7u));
    output[o + 5u] = h.lo.y * 1000u + h.hi.x + h.hi.y + h.lo.x;
    var k = 0u;
    if FOLDED { k = x; } else { k = x + 9u; }
    output[o + 6u] = k;
    if !FOLDED { output[o + 7u] = 1u; } else { output[o + 7u] = 2u; }
    let b = first_set_bit(x);
    output[o + 8u] = b.a * 1000u + b.b;
    let w = by_case(x);
    output[o + 9u] = w.a * 1000u + w.b;
}
"#;
    let kernel = Kernel::from_wgsl("returns.wgsl", source.into(), "main", false).unwrap();
    let inputs: Vec<u32> = (0..128u32).map(|i| i.wrapping_mul(2_654_435_761) >> (i % 9)).collect();
    let mut cpu = CpuBackend::new(CpuOptions::default()).unwrap();
    let got = run_words(&mut cpu, &kernel, &inputs, inputs.len() * 10, 2);
    for (i, &x) in inputs.iter().enumerate() {
        let c = x & 1 != 0;
        let pair = |a: u32, b: u32| a.wrapping_mul(1000).wrapping_add(b);
        let (ma, mb) = (x.wrapping_add(1), x.wrapping_mul(2));
        let picked = if c { pair(x, 1) } else { pair(2, x) };
        let branched = if c { pair(x, 3) } else { pair(x.wrapping_add(6), x.wrapping_add(5).wrapping_mul(2)) };
        let tail = x.wrapping_add(1).wrapping_mul(10000).wrapping_add(x.wrapping_add(2).wrapping_mul(100));
        let halves = (x ^ 5).wrapping_mul(1000).wrapping_add(x.wrapping_mul(3)).wrapping_add(7).wrapping_add(x);
        let want = [
            pair(ma, mb),
            pair(mb, ma),
            picked,
            branched,
            tail.wrapping_add(x.wrapping_add(3)),
            halves,
            x.wrapping_add(9),
            1,
            (0..8).find(|b| (x >> b) & 1 == 1).map_or(pair(99, x), |b| pair(b, x >> b)),
            match x & 3 {
                0 => pair(1, x),
                1 => pair(ma, mb),
                _ => pair(x, 2),
            },
        ];
        assert_eq!(&got[i * 10..(i + 1) * 10], &want, "invocation {i} (input {x})");
    }
}

#[test]
fn records_composed_from_whole_call_results_keep_wgsl_semantics() {
    // `node` is a row reader as gpu/scene_rows.wgsl writes them: its rows are read
    // straight into the record's words. In `either` the rows also feed a second
    // composition, in another order, so they must keep their own registers: placed in the
    // record, the second composition's first copy would overwrite `r0.x` before reading it.
    // In `pick` each return takes a row of its own whole: placed, both rows would share
    // the result's words, and `s` would overwrite `r` (a reviewer's case).
    let source = r#"
@group(0) @binding(0) var<storage, read> input: array<u32>;
@group(0) @binding(1) var<storage, read_write> output: array<u32>;

struct Node { lo: vec3<f32>, a: u32, hi: vec3<u32>, b: u32, c: vec2<u32>, d: u32, e: u32 }

fn row(i: u32) -> vec4<u32> { return vec4<u32>(input[i], input[i + 1u], input[i + 2u], input[i + 3u]); }
fn node(i: u32) -> Node {
    let r0 = row(i);
    let r1 = row(i + 4u);
    let r2 = row(i + 8u);
    return Node(bitcast<vec3<f32>>(r0.xyz), r0.w, r1.xyz, r1.w, r2.xy, r2.z, r2.w);
}
fn either(c: bool, i: u32) -> Node {
    let r0 = row(i);
    let r1 = row(i + 4u);
    let r2 = row(i + 8u);
    if c { return Node(bitcast<vec3<f32>>(r0.xyz), r0.w, r1.xyz, r1.w, r2.xy, r2.z, r2.w); }
    return Node(bitcast<vec3<f32>>(r1.yzw), r0.x, r0.yzw, r2.x, r1.xx, r2.y, r2.w);
}
struct Two { v: vec4<u32>, k: u32 }
fn pick(c: bool, i: u32) -> Two {
    let r = row(i);
    let s = row(i + 4u);
    if c { return Two(s, 1u); }
    return Two(r, 2u);
}
fn words(n: Node) -> array<u32, 12> {
    return array<u32, 12>(bitcast<u32>(n.lo.x), bitcast<u32>(n.lo.y), bitcast<u32>(n.lo.z), n.a,
        n.hi.x, n.hi.y, n.hi.z, n.b, n.c.x, n.c.y, n.d, n.e);
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    let first = words(node(i * 12u));
    let second = words(either((input[i * 12u] & 1u) != 0u, i * 12u));
    for (var k = 0u; k < 12u; k++) {
        output[i * 29u + k] = first[k];
        output[i * 29u + 12u + k] = second[k];
    }
    let t = pick((input[i * 12u] & 2u) != 0u, i * 12u);
    output[i * 29u + 24u] = t.v.x;
    output[i * 29u + 25u] = t.v.y;
    output[i * 29u + 26u] = t.v.z;
    output[i * 29u + 27u] = t.v.w;
    output[i * 29u + 28u] = t.k;
}
"#;
    let kernel = Kernel::from_wgsl("rows.wgsl", source.into(), "main", false).unwrap();
    let inputs: Vec<u32> = (0..128 * 12u32).map(|i| i.wrapping_mul(2_654_435_761) ^ (i >> 3)).collect();
    let mut cpu = CpuBackend::new(CpuOptions::default()).unwrap();
    let got = run_words(&mut cpu, &kernel, &inputs, 128 * 29, 2);
    for (i, w) in inputs.chunks(12).enumerate() {
        let second: Vec<u32> = if w[0] & 1 != 0 {
            w.to_vec()
        } else {
            vec![w[5], w[6], w[7], w[0], w[1], w[2], w[3], w[8], w[4], w[4], w[9], w[11]]
        };
        let picked = if w[0] & 2 != 0 { [w[4], w[5], w[6], w[7], 1] } else { [w[0], w[1], w[2], w[3], 2] };
        assert_eq!(&got[i * 29..i * 29 + 12], w, "invocation {i}: node");
        assert_eq!(&got[i * 29 + 12..i * 29 + 24], &second[..], "invocation {i}: either");
        assert_eq!(&got[i * 29 + 24..(i + 1) * 29], &picked, "invocation {i}: pick");
    }
}
