//! The CPU interpreter of naga IR: registry kernels at every subgroup size, control flow
//! and atomics on hand-written kernels, WGSL integer semantics against lavapipe, and
//! clear errors for what it does not support.

use strata_backends::ash_backend::{AshBackend, AshOptions, SpirvSource};
use strata_backends::backend::{download, upload};
use strata_backends::cpu_backend::{CpuBackend, CpuOptions, DispatchCounts};
use strata_backends::{Backend, BackendError, Bind};
use strata_kernels::reference::block_histogram::block_histogram;
use strata_kernels::types::BLOCK_SIZES;
use strata_kernels::{BlockGrid, Kernel};
use strata_render::histogram_pass::{BlockHistogramPass, HistogramVariant};
use strata_render::synthetic::{CandidateMix, candidate_image};
use strata_tests::run_words;

#[test]
fn histogram_kernels_match_the_reference_at_every_subgroup_size() {
    for subgroup_size in [None, Some(1), Some(8), Some(32)] {
        let mut cpu = CpuBackend::new(CpuOptions { subgroup_size, ..CpuOptions::default() }).unwrap();
        let variant = if subgroup_size.is_some() { HistogramVariant::Subgroup } else { HistogramVariant::Portable };
        for (width, height) in [(17, 33), (40, 24)] {
            for block_size in BLOCK_SIZES {
                let grid = BlockGrid::new(width, height, block_size).unwrap();
                let candidates = candidate_image(
                    width,
                    height,
                    u64::from(block_size),
                    CandidateMix { awkward: 0.3, ..Default::default() },
                );
                let pass = BlockHistogramPass::new(&mut cpu, variant, grid).unwrap();
                let output = pass.run(&mut cpu, &candidates).unwrap();
                pass.destroy(&mut cpu).unwrap();
                assert_eq!(
                    output,
                    block_histogram(grid, &candidates),
                    "{subgroup_size:?} {width}x{height} B={block_size}"
                );
            }
        }
    }
}

/// `count` f32 bit patterns uniform in [-4, 4) from an LCG seeded with `seed`.
fn uniform_floats(seed: u32, count: usize) -> Vec<u32> {
    let mut state = seed;
    (0..count)
        .map(|_| {
            state = state.wrapping_mul(1_103_515_245).wrapping_add(12345);
            ((state >> 8) as f32 / (1 << 24) as f32 * 8.0 - 4.0).to_bits()
        })
        .collect()
}

/// The interpreter's f32 words `got` against lavapipe's `want`: sums of products may
/// contract to fused multiply-adds on the GPU and transcendentals differ between
/// implementations, a few ULPs; values that cancel to near zero turn a small absolute
/// error into many ULPs, so 0.5 % of outliers beyond 64 ULP are allowed.
fn assert_close_to_lavapipe(what: &str, got: Vec<u32>, want: Vec<u32>) {
    use strata_check::{Compare, Output, compare_outputs};
    let expected = [Output { name: "output", words: want, compare: Compare::Float { ulp: 64, max_outside: 0.005 } }];
    let agreement = compare_outputs(&[Output { name: "output", words: got, compare: Compare::Exact }], &expected)
        .unwrap_or_else(|mismatch| panic!("{what}: {mismatch}"));
    eprintln!("{what}: max {} ULP, {:.2}% beyond 64 ULP", agreement.max_ulp, agreement.outside_share() * 100.0);
}

const CONTROL_FLOW: &str = r#"
@group(0) @binding(0) var<storage, read> input: array<u32>;
@group(0) @binding(1) var<storage, read_write> output: array<u32>;
var<workgroup> total: atomic<u32>;
var<workgroup> maximum: atomic<u32>;
var<workgroup> exchanged: atomic<u32>;
var<private> calls: u32 = 7u;

struct Pair { a: u32, b: vec3<u32> }

fn bump(p: ptr<function, u32>, by: u32) -> u32 {
    *p += by;
    calls += 1u;
    return *p * 2u;
}

fn collatz(start: u32) -> u32 {
    var n = start;
    var steps = 0u;
    loop {
        if n <= 1u { break; }
        if (n & 1u) == 0u { n = n / 2u; continue; }
        n = 3u * n + 1u;
        continuing {
            steps += 1u;
            break if steps >= 500u;
        }
    }
    return steps;
}

@compute @workgroup_size(16)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let x = input[id.x];
    var acc = 0u;
    for (var i = 0u; i < x % 7u; i++) {
        switch i {
            case 0u, 3u: { acc += 10u; }
            case 5u: { acc += 100u; break; }
            default: { acc += 1u; }
        }
    }
    var local = x;
    let doubled = bump(&local, 3u);
    var pair = Pair(x, vec3<u32>(x, x + 1u, x + 2u));
    pair.b.z += 1u;
    let swizzled = pair.b.zyx;
    atomicAdd(&total, x & 255u);
    atomicMax(&maximum, x);
    let old = atomicCompareExchangeWeak(&exchanged, 0u, li + 1u);
    workgroupBarrier();
    let base = id.x * 8u;
    output[base] = acc;
    output[base + 1u] = doubled + local;
    output[base + 2u] = swizzled.x * 3u + swizzled.z;
    output[base + 3u] = collatz(x % 1000u + 1u);
    output[base + 4u] = atomicLoad(&total);
    output[base + 5u] = atomicLoad(&maximum);
    output[base + 6u] = select(0u, 1u, old.exchanged) + calls;
    output[base + 7u] = countOneBits(x) + reverseBits(x) + (x << (x & 63u)) + extractBits(x, 3u, 5u);
}
"#;

/// What the control-flow kernel must compute, stated in Rust.
fn control_flow_reference(inputs: &[u32]) -> Vec<u32> {
    let mut out = Vec::new();
    for group in inputs.chunks(16) {
        let total = group.iter().fold(0u32, |t, x| t.wrapping_add(x & 255));
        let maximum = *group.iter().max().unwrap();
        for (li, &x) in group.iter().enumerate() {
            let mut acc = 0u32;
            for i in 0..x % 7 {
                acc += match i {
                    0 | 3 => 10,
                    5 => 100,
                    _ => 1,
                };
            }
            let local = x.wrapping_add(3);
            let doubled = local.wrapping_mul(2);
            let swizzled = [x.wrapping_add(3), x.wrapping_add(1), x];
            // WGSL's loop: `continue` runs the continuing block too, so every pass counts.
            let collatz = {
                let (mut n, mut steps) = (x % 1000 + 1, 0u32);
                while n > 1 {
                    n = if n & 1 == 0 { n / 2 } else { 3 * n + 1 };
                    steps += 1;
                    if steps >= 500 {
                        break;
                    }
                }
                steps
            };
            let exchanged = u32::from(li == 0);
            out.extend([
                acc,
                doubled.wrapping_add(local),
                swizzled[0].wrapping_mul(3).wrapping_add(swizzled[2]),
                collatz,
                total,
                maximum,
                exchanged + 8,
                x.count_ones()
                    .wrapping_add(x.reverse_bits())
                    .wrapping_add(x << (x & 63 & 31))
                    .wrapping_add((x >> 3) & 31),
            ]);
        }
    }
    out
}

#[test]
fn control_flow_calls_pointers_and_atomics_follow_wgsl() {
    let kernel = Kernel::from_wgsl("control_flow.wgsl", CONTROL_FLOW.into(), "main", false).unwrap();
    let inputs: Vec<u32> = (0..64u32).map(|i| i.wrapping_mul(2_654_435_761) ^ (i << 3)).collect();
    let mut cpu = CpuBackend::new(CpuOptions::default()).unwrap();
    let got = run_words(&mut cpu, &kernel, &inputs, 64 * 8, 4);
    assert_eq!(got, control_flow_reference(&inputs));
}

/// Inlined callees in a lane-dependent loop, called again while values computed after an
/// earlier call are still live: the interpreter's compiler gives a callee's registers to
/// the caller's later values once the callee's body is compiled, and shares registers
/// between equal constants. The callee's literals must keep their values (they are in the
/// template, written once), its variable must start at zero on every call, and a value
/// living across a later inlining of the same callee must keep its own registers.
const REGISTER_REUSE: &str = r#"
@group(0) @binding(0) var<storage, read> input: array<u32>;
@group(0) @binding(1) var<storage, read_write> output: array<u32>;

fn mix_in(x: u32, salt: u32) -> u32 {
    var scratch: u32;
    scratch += x * 2654435761u;
    scratch ^= salt + 40503u;
    return (scratch >> 7u) + 1013904223u;
}

fn pair(x: u32) -> vec2<u32> {
    let a = mix_in(x, 1u);
    let b = mix_in(a, 2u);
    return vec2<u32>(a, b);
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let x = input[id.x];
    var acc = 0u;
    for (var i = 0u; i < 3u + (x & 3u); i++) {
        let before = acc + i;
        let p = pair(before ^ x);
        let after = p.x + p.y * 3u;
        acc = before + after + mix_in(after, i);
    }
    output[id.x] = acc;
}
"#;

/// What the register-reuse kernel must compute, stated in Rust.
fn register_reuse_reference(inputs: &[u32]) -> Vec<u32> {
    let mix_in = |x: u32, salt: u32| {
        ((x.wrapping_mul(2_654_435_761) ^ salt.wrapping_add(40503)) >> 7).wrapping_add(1_013_904_223)
    };
    inputs
        .iter()
        .map(|&x| {
            let mut acc = 0u32;
            for i in 0..3 + (x & 3) {
                let before = acc.wrapping_add(i);
                let a = mix_in(before ^ x, 1);
                let b = mix_in(a, 2);
                let after = a.wrapping_add(b.wrapping_mul(3));
                acc = before.wrapping_add(after).wrapping_add(mix_in(after, i));
            }
            acc
        })
        .collect()
}

#[test]
fn inlined_callees_registers_serve_later_values_without_clobbering() {
    let kernel = Kernel::from_wgsl("register_reuse.wgsl", REGISTER_REUSE.into(), "main", false).unwrap();
    let inputs: Vec<u32> = (0..128u32).map(|i| i.wrapping_mul(2_246_822_519) ^ (i << 5)).collect();
    let mut cpu = CpuBackend::new(CpuOptions::default()).unwrap();
    let got = run_words(&mut cpu, &kernel, &inputs, 128, 2);
    assert_eq!(got, register_reuse_reference(&inputs));
}

/// A struct with padding (`n` starts at byte 16) built after an inlined callee that ran
/// in some invocations only: its registers may be the callee's, reused, and a store
/// writes the padding words too. They must be zeros, as GPUs leave a fresh buffer's
/// padding, not what the registers last held.
const PADDING: &str = r#"
struct Hit { t: f32, n: vec3<f32> }
@group(0) @binding(0) var<storage, read> input: array<u32>;
@group(0) @binding(1) var<storage, read_write> output: array<Hit>;

fn scratch_sum(x: f32) -> f32 {
    var tmp: array<f32, 16>;
    for (var i = 0; i < 16; i++) {
        tmp[i] = x * f32(i) + 1.0;
    }
    return tmp[5] + tmp[15];
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let x = input[id.x];
    var t = 0.0;
    if x % 3u == 0u {
        t = scratch_sum(f32(x));
    }
    output[id.x] = Hit(t, vec3<f32>(f32(id.x), 2.0, 3.0));
}
"#;

#[test]
fn padding_of_stored_structs_is_zero() {
    let kernel = Kernel::from_wgsl("padding.wgsl", PADDING.into(), "main", false).unwrap();
    let inputs: Vec<u32> = (0..128u32).map(|i| i.wrapping_mul(2_654_435_761) >> 7).collect();
    let mut cpu = CpuBackend::new(CpuOptions::default()).unwrap();
    let got = run_words(&mut cpu, &kernel, &inputs, 128 * 8, 2);
    for (i, (hit, &x)) in got.chunks(8).zip(&inputs).enumerate() {
        let t = if x % 3 == 0 { (x as f32 * 5.0 + 1.0) + (x as f32 * 15.0 + 1.0) } else { 0.0 };
        let want = [t.to_bits(), 0, 0, 0, (i as f32).to_bits(), 2.0f32.to_bits(), 3.0f32.to_bits(), 0];
        assert_eq!(hit, want, "invocation {i} (x = {x})");
    }
}

/// Bools in workgroup, private and function memory: naga lays a bool out in one byte
/// (an `array<bool, 16>` has a stride of 1), while the interpreter holds each in a word
/// of its own. Offsets taken from naga's layout once put every element of a bool array,
/// and both bools of a struct, in word 0: a flag set by four invocations read as set at
/// all sixteen (and as a race on word 0 that excused the difference). Written by a
/// tester of issue 58 (fresh variants of the workgroup-zeroing class).
const BOOLS: &str = r#"
struct Pair { a: bool, b: bool, c: u32 }
struct Cell { on: vec2<bool>, n: u32 }
@group(0) @binding(0) var<storage, read> input: array<u32>;
@group(0) @binding(1) var<storage, read_write> output: array<u32>;
var<workgroup> flags: array<bool, 16>;
var<workgroup> cells: array<Cell, 4>;
var<private> private_flags: array<bool, 8>;
var<private> pair: Pair;

@compute @workgroup_size(16)
fn main(@builtin(local_invocation_index) i: u32) {
    if i < 4u {
        flags[i] = true;
        cells[i].on.y = i == 2u;
    }
    var local = array<vec2<bool>, 3>();
    local[2].y = true;
    private_flags[5] = input[0] == 0u;
    pair.b = true;
    pair.c = 9u;
    workgroupBarrier();
    var count = 0u;
    for (var k = 0u; k < 16u; k++) { if flags[k] { count += 1u; } }
    var on = 0u;
    for (var k = 0u; k < 4u; k++) { if cells[k].on.x { on += 10u; } if cells[k].on.y { on += 1u; } }
    var private_set = 0u;
    for (var k = 0u; k < 8u; k++) { if private_flags[k] { private_set += 1u; } }
    var local_set = 0u;
    for (var k = 0u; k < 3u; k++) { if local[k].x { local_set += 10u; } if local[k].y { local_set += 1u; } }
    let at = i * 6u;
    output[at] = count;
    output[at + 1u] = on;
    output[at + 2u] = private_set;
    output[at + 3u] = local_set;
    output[at + 4u] = select(0u, 1u, pair.a) * 10u + select(0u, 1u, pair.b);
    output[at + 5u] = pair.c;
}
"#;

#[test]
fn bools_in_arrays_and_structs_each_take_their_own_word() {
    let kernel = Kernel::from_wgsl("bools.wgsl", BOOLS.into(), "main", false).unwrap();
    for sanitize in [false, true] {
        let mut cpu = CpuBackend::new(CpuOptions { sanitize, ..CpuOptions::default() }).unwrap();
        let got = run_words(&mut cpu, &kernel, &[0], 16 * 6, 1);
        for (i, words) in got.chunks(6).enumerate() {
            assert_eq!(words, [4, 1, 1, 1, 1, 9], "invocation {i}, sanitize {sanitize}");
        }
    }
}

/// Chains of functions deeper than the interpreter inlines (each function's code
/// inlines 8 levels of callees, so `main` → `l8` → `l16` are real calls, and from the
/// `l3` branch `main` → `l11` → `l19`): entered from divergent branches at two places,
/// lane-dependent loops and a `switch` at the bottom, a pointer to the entry point's
/// variable written two frames down, and a barrier inside a call that every invocation
/// makes (`s9`, called through `s8`). The workgroup-at-a-time executor must run each
/// invocation's own path through the calls and bring the invocations back together.
const DIVERGENT_CALLS: &str = r#"
@group(0) @binding(0) var<storage, read> input: array<u32>;
@group(0) @binding(1) var<storage, read_write> output: array<u32>;
var<workgroup> total: atomic<u32>;
var<workgroup> slots: array<u32, 64>;

fn l19(p: ptr<function, u32>, x: u32) -> u32 {
    var n = x;
    var steps = 0u;
    loop {
        if n <= 1u { break; }
        switch n % 3u {
            case 0u: { n = n / 3u; }
            case 1u: { n = n - 1u; }
            default: { n = n + 1u; }
        }
        steps += 1u;
    }
    *p += steps;
    return steps;
}
fn l18(p: ptr<function, u32>, x: u32) -> u32 {
    if (x & 1u) == 0u { return l19(p, x) + 1u; }
    return l19(p, x + 7u);
}
fn l17(p: ptr<function, u32>, x: u32) -> u32 { return l18(p, x) + 1u; }
fn l16(p: ptr<function, u32>, x: u32) -> u32 { return l17(p, x) + 1u; }
fn l15(p: ptr<function, u32>, x: u32) -> u32 { return l16(p, x) + 1u; }
fn l14(p: ptr<function, u32>, x: u32) -> u32 { return l15(p, x) + 1u; }
fn l13(p: ptr<function, u32>, x: u32) -> u32 { return l14(p, x) + 1u; }
fn l12(p: ptr<function, u32>, x: u32) -> u32 { return l13(p, x) + 1u; }
fn l11(p: ptr<function, u32>, x: u32) -> u32 { return l12(p, x) + 1u; }
fn l10(p: ptr<function, u32>, x: u32) -> u32 { return l11(p, x) + 1u; }
fn l9(p: ptr<function, u32>, x: u32) -> u32 { return l10(p, x) + 1u; }
fn l8(p: ptr<function, u32>, x: u32) -> u32 { return l9(p, x) + 1u; }
fn l7(p: ptr<function, u32>, x: u32) -> u32 { return l8(p, x) + 1u; }
fn l6(p: ptr<function, u32>, x: u32) -> u32 { return l7(p, x) + 1u; }
fn l5(p: ptr<function, u32>, x: u32) -> u32 { return l6(p, x) + 1u; }
fn l4(p: ptr<function, u32>, x: u32) -> u32 { return l5(p, x) + 1u; }
fn l3(p: ptr<function, u32>, x: u32) -> u32 { return l4(p, x) + 1u; }
fn l2(p: ptr<function, u32>, x: u32) -> u32 { return l3(p, x) + 1u; }
fn l1(p: ptr<function, u32>, x: u32) -> u32 { return l2(p, x) + 1u; }
fn l0(p: ptr<function, u32>, x: u32) -> u32 { return l1(p, x) + 1u; }

fn s9(li: u32) -> u32 {
    workgroupBarrier();
    return slots[63u - li];
}
fn s8(li: u32) -> u32 { return s9(li) + 1u; }
fn s7(li: u32) -> u32 { return s8(li) + 1u; }
fn s6(li: u32) -> u32 { return s7(li) + 1u; }
fn s5(li: u32) -> u32 { return s6(li) + 1u; }
fn s4(li: u32) -> u32 { return s5(li) + 1u; }
fn s3(li: u32) -> u32 { return s4(li) + 1u; }
fn s2(li: u32) -> u32 { return s3(li) + 1u; }
fn s1(li: u32) -> u32 { return s2(li) + 1u; }
fn s0(li: u32) -> u32 { return s1(li) + 1u; }

@compute @workgroup_size(64)
fn main(@builtin(local_invocation_index) li: u32, @builtin(global_invocation_id) id: vec3<u32>) {
    let x = input[id.x];
    var acc = 0u;
    var result = 0u;
    if x % 3u == 0u {
        result = l0(&acc, x % 500u);
    } else if x % 3u == 1u {
        result = 1000u + l3(&acc, x % 300u);
    }
    slots[li] = result;
    atomicAdd(&total, acc);
    let mirrored = s0(li);
    workgroupBarrier();
    output[id.x * 3u] = result;
    output[id.x * 3u + 1u] = acc;
    output[id.x * 3u + 2u] = mirrored + atomicLoad(&total);
}
"#;

/// What the divergent-calls kernel must compute, stated in Rust.
fn divergent_calls_reference(inputs: &[u32]) -> Vec<u32> {
    let steps = |x: u32| {
        let (mut n, mut steps) = (x, 0u32);
        while n > 1 {
            n = match n % 3 {
                0 => n / 3,
                1 => n - 1,
                _ => n + 1,
            };
            steps += 1;
        }
        steps
    };
    // l18: (result, what it adds to *p); l0 adds 18 on top of it, l3 adds 15.
    let l18 = |x: u32| if x & 1 == 0 { (steps(x) + 1, steps(x)) } else { (steps(x + 7), steps(x + 7)) };
    let mut out = Vec::new();
    for group in inputs.chunks(64) {
        let per_lane: Vec<(u32, u32)> = group
            .iter()
            .map(|&x| match x % 3 {
                0 => {
                    let (r, a) = l18(x % 500);
                    (r + 18, a)
                }
                1 => {
                    let (r, a) = l18(x % 300);
                    (1000 + r + 15, a)
                }
                _ => (0, 0),
            })
            .collect();
        let total: u32 = per_lane.iter().map(|&(_, a)| a).sum();
        for (li, &(result, acc)) in per_lane.iter().enumerate() {
            // s0 returns slots[63 - li] plus one per level above s9.
            out.extend([result, acc, per_lane[63 - li].0 + 9 + total]);
        }
    }
    out
}

#[test]
fn divergent_calls_of_functions_not_inlined_reconverge() {
    let kernel = Kernel::from_wgsl("divergent_calls.wgsl", DIVERGENT_CALLS.into(), "main", false).unwrap();
    let inputs: Vec<u32> = (0..128u32).map(|i| i.wrapping_mul(2_246_822_519).rotate_left(7) ^ i).collect();
    for subgroup_size in [None, Some(8)] {
        let mut cpu = CpuBackend::new(CpuOptions { subgroup_size, ..CpuOptions::default() }).unwrap();
        let got = run_words(&mut cpu, &kernel, &inputs, 128 * 3, 2);
        assert_eq!(got, divergent_calls_reference(&inputs), "subgroup size {subgroup_size:?}");
    }
}

const INTEGER_SEMANTICS: &str = r#"
@group(0) @binding(0) var<storage, read> input: array<u32>;
@group(0) @binding(1) var<storage, read_write> output: array<u32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let a = input[2u * id.x];
    let b = input[2u * id.x + 1u];
    let ia = bitcast<i32>(a);
    let ib = bitcast<i32>(b);
    let fa = bitcast<f32>(a);
    let o = id.x * 12u;
    output[o] = a / b;
    output[o + 1u] = a % b;
    output[o + 2u] = bitcast<u32>(ia / ib);
    output[o + 3u] = bitcast<u32>(ia % ib);
    output[o + 4u] = a << (b & 31u);
    output[o + 5u] = bitcast<u32>(ia >> (b & 31u));
    output[o + 6u] = bitcast<u32>(-ia);
    output[o + 7u] = u32(fa);
    output[o + 8u] = bitcast<u32>(i32(fa));
    output[o + 9u] = firstLeadingBit(a) ^ bitcast<u32>(firstLeadingBit(ia)) ^ firstTrailingBit(b);
    output[o + 10u] = min(a, b) + bitcast<u32>(max(ia, ib)) + countLeadingZeros(b);
    output[o + 11u] = insertBits(a, b, 5u, 9u) ^ bitcast<u32>(extractBits(ia, 7u, 11u));
}
"#;

#[test]
fn integer_semantics_agree_with_lavapipe_bit_for_bit() {
    let kernel = Kernel::from_wgsl("integer_semantics.wgsl", INTEGER_SEMANTICS.into(), "main", false).unwrap();
    let edges = [0u32, 1, 2, 31, 32, 0x7fff_ffff, 0x8000_0000, 0xffff_ffff, 0xffff_fffe, 7, 0x4f80_0000, 0xcf00_0000];
    let mut inputs = Vec::new();
    for &a in &edges {
        for &b in &edges {
            inputs.extend([a, b]);
        }
    }
    let mut state = 0x1234_5678_u32;
    while inputs.len() < 2 * 256 {
        state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        inputs.push(state ^ (state >> 13));
    }
    let pairs = inputs.len() / 2;
    let mut cpu = CpuBackend::new(CpuOptions::default()).unwrap();
    let got = run_words(&mut cpu, &kernel, &inputs, pairs * 12, (pairs / 64) as u32);
    // Spot checks of WGSL's rules, independent of any GPU.
    let at = |a_index: usize, b_index: usize, k: usize| got[(a_index * edges.len() + b_index) * 12 + k];
    assert_eq!(at(6, 0, 0), 0x8000_0000, "division by zero yields the dividend");
    assert_eq!(at(6, 0, 1), 0, "remainder by zero yields 0");
    assert_eq!(at(6, 7, 2), 0x8000_0000, "i32::MIN / -1 yields the dividend");
    assert_eq!(at(1, 4, 4), 1, "shift amounts are masked");
    assert_eq!(at(10, 0, 8), 2_147_483_520, "float to int clamps to the largest float the type holds");
    let Some(mut gpu) = strata_tests::vulkan_backend("integer_semantics_agree_with_lavapipe_bit_for_bit") else {
        return;
    };
    let want = run_words(&mut gpu, &kernel, &inputs, pairs * 12, (pairs / 64) as u32);
    // NaN → integer is implementation-defined: the interpreter gives 0 (as D3D and
    // WebAssembly do), lavapipe's x86 conversion gives i32::MIN. Not compared.
    let nan_conversion = |i: usize| (i % 12 == 7 || i % 12 == 8) && f32::from_bits(inputs[2 * (i / 12)]).is_nan();
    if let Some(i) = (0..want.len()).find(|&i| got[i] != want[i] && !nan_conversion(i)) {
        panic!("output[{i}] (pair {}, op {}): cpu {:#x}, lavapipe {:#x}", i / 12, i % 12, got[i], want[i]);
    }
}

#[test]
fn unsupported_constructs_are_named_with_their_line() {
    let source = r#"
@group(0) @binding(0) var<storage, read> input: array<u32>;
@group(0) @binding(1) var<storage, read_write> output: array<f32>;
@compute @workgroup_size(1)
fn main() {
    let wide = u64(input[0]) << 40u;
    output[0] = f32(countOneBits(wide));
}
"#;
    let kernel = Kernel::from_wgsl("count64.wgsl", source.into(), "main", false).unwrap();
    let mut cpu = CpuBackend::new(CpuOptions::default()).unwrap();
    let input = upload(&mut cpu, "input", &[1u32]).unwrap();
    let output = cpu.create_buffer("output", 4).unwrap();
    let error = cpu.dispatch(&kernel, &[Bind::new(0, input), Bind::new(1, output)], [1, 1, 1]).unwrap_err();
    assert!(matches!(error, BackendError::Validation { .. }), "{error}");
    let message = error.to_string();
    assert!(message.contains("unsupported: math function CountOneBits on 64-bit integers"), "{message}");
    assert!(message.contains("(WGSL line 7)"), "{message}");
}

#[test]
fn an_array_whose_override_has_no_value_is_refused_by_name_not_run_as_zeros() {
    let source = r#"
override N: u32;
@group(0) @binding(0) var<storage, read> input: array<u32>;
@group(0) @binding(1) var<storage, read_write> output: array<u32>;
var<workgroup> staged: array<u32, N * 2u>;
@compute @workgroup_size(4)
fn main(@builtin(local_invocation_index) i: u32) {
    staged[i] = input[i] + 1u;
    workgroupBarrier();
    output[i] = staged[3u - i];
}
"#;
    let overrides = [("N".to_string(), 2.0)];
    let kernel = Kernel::from_wgsl_with_overrides("staged.wgsl", source.into(), "main", false, &overrides).unwrap();
    let mut cpu = CpuBackend::new(CpuOptions::default()).unwrap();
    // With N given, the array has 4 words and the kernel runs (it once read zeros).
    assert_eq!(run_words(&mut cpu, &kernel, &[10, 20, 30, 40], 4, 1), [41, 31, 21, 11]);
    // Without a value for the size's override (a module the overrides were never
    // applied to): an error naming the variable and its line, never zeros.
    let mut unapplied =
        Kernel::from_wgsl_with_overrides("staged.wgsl", source.into(), "main", false, &overrides).unwrap();
    for (_, item) in unapplied.module.overrides.iter_mut() {
        item.init = None;
    }
    let mut cpu = CpuBackend::new(CpuOptions::default()).unwrap();
    let input = upload(&mut cpu, "input", &[1u32; 4]).unwrap();
    let output = cpu.create_buffer("output", 16).unwrap();
    let error = cpu.dispatch(&unapplied, &[Bind::new(0, input), Bind::new(1, output)], [1, 1, 1]).unwrap_err();
    let message = error.to_string();
    assert!(message.contains("`staged`") && message.contains("value is not known"), "{message}");
    assert!(message.contains("(WGSL line 5)"), "{message}");
}

#[test]
fn barrier_in_nonuniform_control_flow_error_names_line_and_function() {
    // The barrier is in a small function, which the interpreter inlines into its caller:
    // the error must still name the barrier's own line and function.
    let source = r#"
@group(0) @binding(0) var<storage, read> input: array<u32>;
@group(0) @binding(1) var<storage, read_write> output: array<u32>;
var<workgroup> scratch: array<u32, 64>;

fn sync_step(i: u32) {
    scratch[i] = i;
    workgroupBarrier();
}

@compute @workgroup_size(64)
fn main(@builtin(local_invocation_index) i: u32) {
    if input[i] < 32u {
        sync_step(i);
    }
    output[i] = scratch[i];
}
"#;
    let kernel = Kernel::from_wgsl("nonuniform.wgsl", source.into(), "main", false).unwrap();
    let mut cpu = CpuBackend::new(CpuOptions::default()).unwrap();
    let inputs: Vec<u32> = (0..64).collect();
    let input = upload(&mut cpu, "input", &inputs).unwrap();
    let output = cpu.create_buffer("output", 256).unwrap();
    let error = cpu.dispatch(&kernel, &[Bind::new(0, input), Bind::new(1, output)], [1, 1, 1]).unwrap_err();
    let message = error.to_string();
    assert!(message.contains("non-uniform control flow"), "{message}");
    assert!(message.contains("WGSL line 8 in `sync_step`"), "{message}");
}

/// A 64-wide kernel whose invocations each step a generator `bound` times (a WGSL
/// expression of `input` and the local index `i`), running `in_loop` after each step.
fn stepping_kernel(name: &str, bound: &str, in_loop: &str) -> Kernel {
    let source = format!(
        r#"
@group(0) @binding(0) var<storage, read> input: array<u32>;
@group(0) @binding(1) var<storage, read_write> output: array<u32>;
@compute @workgroup_size(64)
fn main(@builtin(local_invocation_index) i: u32) {{
    var x = i;
    for (var n = 0u; n < {bound}; n++) {{
        x = x * 1664525u + 1013904223u;
        {in_loop}
    }}
    output[i] = x;
}}
"#
    );
    Kernel::from_wgsl(name, source, "main", false).unwrap()
}

/// What one workgroup of `kernel` executed on `inputs`.
fn counts_of(cpu: &mut CpuBackend, kernel: &Kernel, inputs: &[u32]) -> DispatchCounts {
    run_words(cpu, kernel, inputs, 64, 1);
    let counts = cpu.take_counts_by_kernel();
    assert_eq!(counts.len(), 1, "one kernel dispatched");
    counts[&kernel.id]
}

/// The SIMT issue model (`DispatchCounts::warp_issues`): a warp with one busy lane costs
/// as many issues as a full one, while the instruction count follows the busy lanes.
#[test]
fn warp_issues_charge_divergent_warps_as_full_ones() {
    let kernel = stepping_kernel("warp_issues.wgsl", "input[i]", "");
    let mut cpu = CpuBackend::new(CpuOptions::default()).unwrap();
    let mut counts_with = |busy: &[u32]| {
        let inputs: Vec<u32> = (0..64).map(|i| if busy.contains(&i) { 200 } else { 0 }).collect();
        counts_of(&mut cpu, &kernel, &inputs)
    };
    let all = counts_with(&(0..64).collect::<Vec<_>>());
    let one_per_warp = counts_with(&[5, 40]);
    let two_in_one_warp = counts_with(&[5, 6]);
    // Both warps loop 200 times either way: the same issues, 2/64 of the instructions.
    assert!(one_per_warp.instructions * 10 < all.instructions, "{one_per_warp:?} vs {all:?}");
    let ratio = one_per_warp.warp_issues as f64 / all.warp_issues as f64;
    assert!((0.95..=1.05).contains(&ratio), "{one_per_warp:?} vs {all:?}");
    // One warp loops, the other does not: about half the issues.
    let ratio = two_in_one_warp.warp_issues as f64 / all.warp_issues as f64;
    assert!((0.45..=0.55).contains(&ratio), "{two_in_one_warp:?} vs {all:?}");
    // A full workgroup: one issue per warp per instruction.
    assert_eq!(all.instructions, 32 * all.warp_issues);
}

/// A whole workgroup that reaches a barrier together runs on past it without stopping
/// (`interp::run_until_sync`): the instructions before each barrier still count. Each turn
/// of a loop with a barrier costs every invocation the same instructions, so the count
/// grows by the same amount with every turn.
#[test]
fn instructions_before_each_barrier_count() {
    let kernel = stepping_kernel("barrier_loop.wgsl", "input[0]", "workgroupBarrier();");
    let mut cpu = CpuBackend::new(CpuOptions::default()).unwrap();
    let [one, two, three] = [1, 2, 3].map(|turns| counts_of(&mut cpu, &kernel, &[turns]).instructions);
    let turn = two.checked_sub(one).expect("a second turn cannot cost fewer instructions");
    assert!(turn > 0 && turn % 64 == 0, "a turn costs {turn} instructions: {one}, {two}, {three}");
    assert_eq!(three - two, turn, "{one}, {two}, {three}");
}

#[test]
fn bad_subgroup_sizes_are_refused() {
    assert!(CpuBackend::new(CpuOptions { subgroup_size: Some(12), ..CpuOptions::default() }).is_err());
    assert!(CpuBackend::new(CpuOptions { subgroup_size: Some(0), ..CpuOptions::default() }).is_err());
}

#[test]
fn storage_atomics_are_atomic_across_parallel_workgroups() {
    let source = r#"
@group(0) @binding(0) var<storage, read> input: array<u32>;
@group(0) @binding(1) var<storage, read_write> output: array<atomic<u32>>;
@compute @workgroup_size(32)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    atomicAdd(&output[0], input[id.x]);
    atomicMax(&output[1], input[id.x]);
    atomicOr(&output[2], 1u << (id.x % 32u));
    atomicSub(&output[3], 1u);
}
"#;
    let kernel = Kernel::from_wgsl("atomics.wgsl", source.into(), "main", false).unwrap();
    let inputs: Vec<u32> = (0..32 * 64).map(|i| i * 7 % 1001).collect();
    let mut cpu = CpuBackend::new(CpuOptions::default()).unwrap();
    let got = run_words(&mut cpu, &kernel, &inputs, 4, 64);
    let sum = inputs.iter().fold(0u32, |a, &x| a.wrapping_add(x));
    assert_eq!(got, vec![sum, *inputs.iter().max().unwrap(), u32::MAX, 0u32.wrapping_sub(32 * 64)]);
}

const FLOAT_MATH: &str = r#"
@group(0) @binding(0) var<storage, read> input: array<f32>;
@group(0) @binding(1) var<storage, read_write> output: array<f32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let x = input[2u * id.x];
    let y = input[2u * id.x + 1u];
    let m = mat3x3<f32>(vec3<f32>(x, y, 1.0), vec3<f32>(0.5, x * y, -y), vec3<f32>(2.0, 0.25, x));
    let n = mat2x3<f32>(vec3<f32>(y, 1.0, 0.0), vec3<f32>(-x, 2.0, 3.0));
    let v = m * vec3<f32>(1.0, y, x);
    let w = vec3<f32>(x, 0.5, y) * m;
    let p = m * n;
    let t = transpose(m);
    let o = id.x * 18u;
    output[o] = v.x + v.y + v.z;
    output[o + 1u] = w.x - w.y + w.z;
    output[o + 2u] = p[0].x + p[1].z;
    output[o + 3u] = t[1].x + t[2].y;
    output[o + 4u] = determinant(m);
    output[o + 5u] = x * y + x / (abs(y) + 1.0);
    output[o + 6u] = sqrt(abs(x)) + floor(y) + ceil(x) + round(y) + fract(x) + trunc(y);
    output[o + 7u] = min(x, y) + max(x, y) + clamp(x, -1.0, 1.0) + sign(y) + step(x, y);
    output[o + 8u] = dot(v, w) + length(v) + distance(v, w);
    output[o + 9u] = normalize(vec3<f32>(x, y, 1.0)).y;
    output[o + 10u] = mix(x, y, 0.25) + smoothstep(-1.0, 1.0, x);
    output[o + 11u] = cross(v, vec3<f32>(0.0, 1.0, 2.0)).z;
    output[o + 12u] = f32(i32(x * 100.0)) + f32(u32(abs(y) * 10.0));
    output[o + 13u] = exp2(clamp(x, -10.0, 10.0)) + log2(abs(y) + 1.0);
    output[o + 14u] = sin(x) + cos(y);
    output[o + 15u] = inverseSqrt(abs(x) + 1.0) + pow(abs(y) + 1.0, 1.5);
    let packed = pack4x8unorm(vec4<f32>(x * 0.25, y * 0.25, 0.5, fract(x))) ^ pack2x16snorm(vec2<f32>(y * 0.3, -x * 0.3));
    let unpacked = unpack4x8snorm(packed) + vec4<f32>(unpack2x16unorm(packed), unpack2x16snorm(~packed));
    output[o + 16u] = bitcast<f32>(packed & 0x3fffffffu);
    output[o + 17u] = unpacked.x + unpacked.y + unpacked.z + unpacked.w + unpack4x8unorm(packed).z;
}
"#;

#[test]
fn float_math_and_matrices_agree_with_lavapipe_within_ulps() {
    let kernel = Kernel::from_wgsl("float_math.wgsl", FLOAT_MATH.into(), "main", false).unwrap();
    let inputs = uniform_floats(12345, 2 * 128);
    let mut cpu = CpuBackend::new(CpuOptions::default()).unwrap();
    let got = run_words(&mut cpu, &kernel, &inputs, 128 * 18, 2);
    assert!(got.iter().all(|w| f32::from_bits(*w).is_finite()), "every result is finite");
    let Some(mut gpu) = strata_tests::vulkan_backend("float_math_and_matrices_agree_with_lavapipe_within_ulps") else {
        return;
    };
    let want = run_words(&mut gpu, &kernel, &inputs, 128 * 18, 2);
    assert_close_to_lavapipe("float math", got, want);
}

const GEOMETRY: &str = r#"
@group(0) @binding(0) var<storage, read> input: array<f32>;
@group(0) @binding(1) var<storage, read_write> output: array<f32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let k = 4u * id.x;
    let a = vec4<f32>(input[k], input[k + 1u], input[k + 2u], input[k + 3u]);
    let b = a.wzyx * vec4<f32>(1.5, -0.75, 3.0, 0.125);
    let o = id.x * 17u;
    var v = a.xyz;
    if (id.x % 3u == 1u) {
        // A masked group: the store keeps the branch a branch.
        v = normalize(v);
        output[o] = 1.0;
    }
    let n2 = normalize(a.xy);
    let n4 = normalize(a);
    let c = cross(a.xyz, b.xyz);
    output[o] = v.x;
    output[o + 1u] = v.y;
    output[o + 2u] = v.z;
    output[o + 3u] = n2.x;
    output[o + 4u] = n2.y;
    output[o + 5u] = n4.x;
    output[o + 6u] = n4.w;
    output[o + 7u] = length(a.x);
    output[o + 8u] = length(a.xy);
    output[o + 9u] = length(a.xyz);
    output[o + 10u] = length(a);
    output[o + 11u] = distance(a.xy, b.xy);
    output[o + 12u] = distance(a.xyz, b.xyz);
    output[o + 13u] = distance(a, b);
    output[o + 14u] = c.x;
    output[o + 15u] = c.y;
    output[o + 16u] = c.z;
}
"#;

/// `normalize`, `length`, `distance` and `cross` on the interpreter give the bits of
/// their formulas (the sum of squares from 0 in component order, one square root, a
/// division per component; the cross product's three differences), also in a masked
/// group (a third of the invocations), and on zero vectors, infinities, NaNs,
/// squares that overflow and subnormals (a NaN compared as a NaN, its payload aside).
/// The interpreter runs them as closures with the function fixed (`math_call.rs`,
/// `geometric`), which must compute what the general form does; lavapipe is compared
/// within ulps by the tests above.
#[test]
fn geometric_functions_give_the_bits_of_their_formulas() {
    let kernel = Kernel::from_wgsl("geometry.wgsl", GEOMETRY.into(), "main", false).unwrap();
    const INVOCATIONS: usize = 192;
    let mut inputs = uniform_floats(4242, 4 * INVOCATIONS);
    for p in 0..INVOCATIONS {
        let special = match p % 8 {
            0 => Some([0.0, -0.0, 0.0, 0.0]),
            1 => Some([f32::INFINITY, 1.0, -2.0, 0.5]),
            2 => Some([1.0, f32::NAN, 3.0, -1.0]),
            3 => Some([3e19, -2e19, 1e19, 4e19]),
            4 => Some([1e-40, -3e-41, 2e-39, 5e-42]),
            _ => None,
        };
        if let Some(values) = special {
            for (i, x) in values.iter().enumerate() {
                inputs[4 * p + i] = x.to_bits();
            }
        }
    }
    let mut cpu = CpuBackend::new(CpuOptions::default()).unwrap();
    let got = run_words(&mut cpu, &kernel, &inputs, INVOCATIONS * 17, 3);
    let f = f32::from_bits;
    let length = |v: &[f32]| v.iter().fold(0.0f32, |sum, &x| sum + x * x).sqrt();
    let normalize = |v: &[f32]| -> Vec<f32> { v.iter().map(|&x| x / length(v)).collect() };
    let distance = |a: &[f32], b: &[f32]| {
        let d: Vec<f32> = a.iter().zip(b).map(|(x, y)| x - y).collect();
        length(&d)
    };
    for p in 0..INVOCATIONS {
        let a: Vec<f32> = (0..4).map(|i| f(inputs[4 * p + i])).collect();
        let b = [a[3] * 1.5, a[2] * -0.75, a[1] * 3.0, a[0] * 0.125];
        let v = if p % 3 == 1 { normalize(&a[..3]) } else { a[..3].to_vec() };
        let (n2, n4) = (normalize(&a[..2]), normalize(&a));
        let cross = [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
        let want = [
            v[0],
            v[1],
            v[2],
            n2[0],
            n2[1],
            n4[0],
            n4[3],
            length(&a[..1]),
            length(&a[..2]),
            length(&a[..3]),
            length(&a),
            distance(&a[..2], &b[..2]),
            distance(&a[..3], &b[..3]),
            distance(&a, &b),
            cross[0],
            cross[1],
            cross[2],
        ];
        for (k, want) in want.iter().enumerate() {
            let have = f(got[17 * p + k]);
            let same = have.to_bits() == want.to_bits() || (have.is_nan() && want.is_nan());
            assert!(same, "invocation {p}, output {k}: {have} against {want}");
        }
    }
}

const MORE_MATH: &str = r#"
@group(0) @binding(0) var<storage, read> input: array<f32>;
@group(0) @binding(1) var<storage, read_write> output: array<f32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let x = input[2u * id.x];
    let y = input[2u * id.x + 1u];
    let i = normalize(vec3<f32>(x, -1.0, y));
    let n = normalize(vec3<f32>(0.25 * y, 1.0, 0.5));
    let r = reflect(i, n);
    let glass = refract(i, n, 1.0 / 1.5);
    // eta 1.5 from inside: total internal reflection (k < 0) for grazing directions.
    let inside = refract(i, n, 1.5);
    let f = faceForward(n, i, vec3<f32>(x, y, 1.0));
    let o = id.x * 16u;
    output[o] = r.x + r.y + r.z;
    output[o + 1u] = glass.x - glass.y + glass.z;
    output[o + 2u] = inside.x + inside.y - inside.z;
    output[o + 3u] = f.x + f.y + f.z;
    output[o + 4u] = asinh(x);
    output[o + 5u] = acosh(abs(y) + 1.0);
    output[o + 6u] = atanh(clamp(0.2 * x, -0.9, 0.9));
    output[o + 7u] = radians(x * 45.0);
    output[o + 8u] = degrees(y);
    output[o + 9u] = ldexp(x, i32(y * 32.0));
    output[o + 10u] = ldexp(vec2<f32>(y, x), vec2<i32>(-140, 127)).x + ldexp(x, 200);
    output[o + 11u] = ldexp(y, -200);
    let a = bitcast<u32>(x);
    let b = bitcast<u32>(y) ^ 0x80ff7f01u;
    output[o + 12u] = bitcast<f32>(dot4I8Packed(a, b));
    output[o + 13u] = bitcast<f32>(dot4U8Packed(a, b));
    output[o + 14u] = bitcast<f32>(dot4I8Packed(b, 0x80808080u));
    output[o + 15u] = bitcast<f32>(dot4U8Packed(0xffffffffu, b));
}
"#;

#[test]
fn reflect_refract_hyperbolic_ldexp_and_packed_dots_agree_with_lavapipe() {
    let kernel = Kernel::from_wgsl("more_math.wgsl", MORE_MATH.into(), "main", false).unwrap();
    let inputs = uniform_floats(777, 2 * 128);
    let mut cpu = CpuBackend::new(CpuOptions::default()).unwrap();
    let got = run_words(&mut cpu, &kernel, &inputs, 128 * 16, 2);
    // Known values on the interpreter: total internal reflection gives the zero vector,
    // ldexp saturates and flushes exactly.
    let f = f32::from_bits;
    for p in 0..128 {
        let (x, y) = (f(inputs[2 * p]), f(inputs[2 * p + 1]));
        let at = |k: usize| f(got[16 * p + k]);
        assert_eq!(at(9), x * 2f32.powi((y * 32.0) as i32), "ldexp({x}, {y} * 32)");
        assert_eq!(at(11), y * 2f32.powi(-100) * 2f32.powi(-100), "ldexp({y}, -200)");
        if x != 0.0 {
            assert!(at(10).is_infinite(), "ldexp({x}, 200) overflows");
        }
        assert_eq!(at(7).to_bits(), (x * 45.0 * (std::f32::consts::PI / 180.0)).to_bits());
    }
    let Some(mut gpu) =
        strata_tests::vulkan_backend("reflect_refract_hyperbolic_ldexp_and_packed_dots_agree_with_lavapipe")
    else {
        return;
    };
    let want = run_words(&mut gpu, &kernel, &inputs, 128 * 16, 2);
    // The packed dot products are integers: bit for bit.
    let integer = |i: usize| i % 16 >= 12;
    if let Some(i) = (0..want.len()).find(|&i| integer(i) && got[i] != want[i]) {
        panic!("output[{i}] (packed dot {}): cpu {:#x}, lavapipe {:#x}", i % 16 - 12, got[i], want[i]);
    }
    let floats = |words: &[u32]| (0..words.len()).filter(|&i| !integer(i)).map(|i| words[i]).collect::<Vec<_>>();
    assert_close_to_lavapipe("more math", floats(&got), floats(&want));
}

/// Subgroup ballots, reductions and scans, per invocation 24 outputs; `WG` is replaced by
/// the workgroup size (a multiple of the subgroup size, or not: a partial last subgroup).
const SUBGROUP_COLLECTIVES: &str = r#"
@group(0) @binding(0) var<storage, read> input: array<u32>;
@group(0) @binding(1) var<storage, read_write> output: array<u32>;

@compute @workgroup_size(WG)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(subgroup_size) size: u32) {
    let x = input[id.x];
    let s = bitcast<i32>(x);
    let small = f32(x & 255u);
    let o = id.x * 24u;
    output[o] = size;
    output[o + 1u] = subgroupAdd(x);
    output[o + 2u] = bitcast<u32>(subgroupMul(s | 1));
    output[o + 3u] = bitcast<u32>(subgroupMin(s));
    output[o + 4u] = subgroupMax(x);
    output[o + 5u] = subgroupAnd(x);
    output[o + 6u] = subgroupOr(x);
    output[o + 7u] = subgroupXor(x);
    output[o + 8u] = u32(subgroupAll((x & 3u) != 0u));
    output[o + 9u] = u32(subgroupAny((x & 63u) == 5u));
    output[o + 10u] = subgroupInclusiveAdd(x);
    output[o + 11u] = subgroupExclusiveAdd(x);
    output[o + 12u] = subgroupInclusiveMul(x | 1u);
    output[o + 13u] = bitcast<u32>(subgroupExclusiveMul(s));
    let ballot = subgroupBallot((x & 1u) == 1u);
    output[o + 14u] = ballot.x;
    output[o + 15u] = ballot.y;
    output[o + 16u] = ballot.z;
    output[o + 17u] = ballot.w;
    // Small integers as floats: every sum is exact, whatever the order.
    output[o + 18u] = bitcast<u32>(subgroupAdd(small));
    output[o + 19u] = bitcast<u32>(subgroupMin(small - 100.0));
    output[o + 20u] = bitcast<u32>(subgroupMax(vec2<f32>(small, -small)).y);
    output[o + 21u] = subgroupExclusiveAdd(vec3<u32>(x, 1u, x >> 3u)).z;
    output[o + 22u] = subgroupBallot().x;
    output[o + 23u] = bitcast<u32>(subgroupMax(s));
}
"#;

#[test]
fn subgroup_ballots_reductions_and_scans_agree_with_lavapipe_bit_for_bit() {
    let Some(mut gpu) =
        strata_tests::vulkan_backend("subgroup_ballots_reductions_and_scans_agree_with_lavapipe_bit_for_bit")
    else {
        return;
    };
    let mut state = 4242u32;
    let inputs: Vec<u32> = (0..240)
        .map(|i| {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            if i % 7 == 0 { state | 3 } else { state }
        })
        .collect();
    for workgroup_size in [64u32, 20] {
        let source = SUBGROUP_COLLECTIVES.replace("WG", &workgroup_size.to_string());
        let kernel = Kernel::from_wgsl("subgroup_collectives.wgsl", source, "main", true).unwrap();
        let workgroups = inputs.len() as u32 / workgroup_size;
        let want = run_words(&mut gpu, &kernel, &inputs, inputs.len() * 24, workgroups);
        // The interpreter runs with lavapipe's subgroup size.
        let mut cpu = CpuBackend::new(CpuOptions { subgroup_size: Some(want[0]), ..CpuOptions::default() }).unwrap();
        let got = run_words(&mut cpu, &kernel, &inputs, inputs.len() * 24, workgroups);
        if let Some(i) = (0..want.len()).find(|&i| got[i] != want[i]) {
            panic!(
                "workgroup size {workgroup_size}, subgroup size {}: output[{i}] (invocation {}, output {}): cpu {:#x}, lavapipe {:#x}",
                want[0],
                i / 24,
                i % 24,
                got[i],
                want[i]
            );
        }
    }
}

const STRUCT_ARGUMENTS: &str = r#"
@group(0) @binding(0) var<storage, read> input: array<u32>;
@group(0) @binding(1) var<storage, read_write> output: array<u32>;

struct Ids {
    @builtin(local_invocation_index) index: u32,
    @builtin(global_invocation_id) global: vec3<u32>,
    @builtin(workgroup_id) group: vec3<u32>,
}
struct Counts { @builtin(num_workgroups) groups: vec3<u32> }

@compute @workgroup_size(4, 2, 1)
fn main(ids: Ids, @builtin(local_invocation_id) local: vec3<u32>, counts: Counts) {
    let flat = ids.global.x + ids.global.y * 4u * counts.groups.x;
    let o = flat * 8u;
    output[o] = ids.index;
    output[o + 1u] = ids.global.x;
    output[o + 2u] = ids.global.y;
    output[o + 3u] = ids.group.x * 100u + ids.group.y;
    output[o + 4u] = local.x + 10u * local.y;
    output[o + 5u] = counts.groups.x * 10u + counts.groups.y;
    output[o + 6u] = input[flat % arrayLength(&input)];
    output[o + 7u] = ids.group.z + counts.groups.z;
}
"#;

#[test]
fn struct_entry_point_arguments_agree_with_lavapipe() {
    let kernel = Kernel::from_wgsl("struct_arguments.wgsl", STRUCT_ARGUMENTS.into(), "main", false).unwrap();
    let inputs: Vec<u32> = (0..16).map(|i| i * 7 + 1).collect();
    let run = |backend: &mut dyn Backend| -> Vec<u32> {
        let input = upload(backend, "input", &inputs).unwrap();
        let output = backend.create_buffer("output", 3 * 4 * 2 * 2 * 8 * 4).unwrap();
        backend.dispatch(&kernel, &[Bind::new(0, input), Bind::new(1, output)], [3, 2, 1]).unwrap();
        download(backend, output).unwrap()
    };
    let got = run(&mut CpuBackend::new(CpuOptions::default()).unwrap());
    // Invocation (global x 5, y 3): workgroup (1, 1), local (1, 1), index 5.
    let o = (5 + 3 * 12) * 8;
    assert_eq!(&got[o..o + 6], &[5, 5, 3, 101, 11, 32]);
    let Some(mut gpu) = strata_tests::vulkan_backend("struct_entry_point_arguments_agree_with_lavapipe") else {
        return;
    };
    assert_eq!(got, run(&mut gpu));
}

const HALF_AND_SPLIT: &str = r#"
@group(0) @binding(0) var<storage, read> input: array<u32>;
@group(0) @binding(1) var<storage, read_write> output: array<u32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let n = arrayLength(&input);
    let a = input[id.x];
    let b = input[(id.x * 7u + 3u) % n];
    let x = bitcast<f32>(a);
    let y = bitcast<f32>(b);
    let m = modf(x);
    let e = frexp(x);
    let mv = modf(vec3<f32>(x, y, -x));
    let ev = frexp(vec2<f32>(y, x));
    let u = unpack2x16float(a);
    let q = quantizeToF16(vec2<f32>(y, x));
    let o = id.x * 20u;
    output[o] = bitcast<u32>(m.fract);
    output[o + 1u] = bitcast<u32>(m.whole);
    output[o + 2u] = bitcast<u32>(e.fract);
    output[o + 3u] = bitcast<u32>(e.exp);
    output[o + 4u] = bitcast<u32>(quantizeToF16(x));
    output[o + 5u] = pack2x16float(vec2<f32>(x, y));
    output[o + 6u] = bitcast<u32>(u.x);
    output[o + 7u] = bitcast<u32>(u.y);
    output[o + 8u] = bitcast<u32>(mv.fract.x);
    output[o + 9u] = bitcast<u32>(mv.fract.y);
    output[o + 10u] = bitcast<u32>(mv.fract.z);
    output[o + 11u] = bitcast<u32>(mv.whole.x);
    output[o + 12u] = bitcast<u32>(mv.whole.y);
    output[o + 13u] = bitcast<u32>(mv.whole.z);
    output[o + 14u] = bitcast<u32>(ev.fract.x);
    output[o + 15u] = bitcast<u32>(ev.fract.y);
    output[o + 16u] = bitcast<u32>(ev.exp.x);
    output[o + 17u] = bitcast<u32>(ev.exp.y);
    output[o + 18u] = bitcast<u32>(q.x);
    output[o + 19u] = bitcast<u32>(q.y);
}
"#;

/// f32 bit patterns at the edges of f32 and of binary16.
fn half_edge_inputs() -> Vec<u32> {
    let mut inputs: Vec<u32> = vec![
        0,
        0x8000_0000,
        1,
        0x8000_0001,
        0x007f_ffff,
        0x0080_0000,
        0x7fc0_0000,
        0xffc0_0000,
        0x7f80_0001,
        0x7fc0_1234,
        0x7f80_0000,
        0xff80_0000,
        0x7f7f_ffff,
    ];
    let floats = [
        65504.0f32,
        -65504.0,
        65519.99,
        65520.0,
        -65520.0,
        65536.0,
        1e10,
        -1e-10,
        5.960_464_5e-8, // 2^-24, the smallest binary16 denormal
        2.980_232_2e-8, // 2^-25: halfway to zero, ties to even (zero)
        4.470_348_4e-8, // 3 * 2^-26: rounds up to 2^-24
        8.940_697e-8,   // 3 * 2^-25: halfway between 2^-24 and 2^-23, ties to even
        6.103_515_6e-5, // 2^-14, the smallest normal binary16
        6.097_555e-5,   // just below: the largest denormal region
        1.0 + 1.0 / 2048.0,
        1.0 + 3.0 / 2048.0,
        1.0 + 1.0 / 4096.0,
        -2.5,
        0.5,
        1.5,
        3.0,
        -7.75,
        0.999_999_94,
        1e-30,
        -123.456,
        2049.0,
        2051.0,
        4097.0,
    ];
    inputs.extend(floats.iter().map(|v| v.to_bits()));
    // Pairs of binary16 edges for unpack2x16float: ±0, denormals, NaNs, ±Inf, max.
    inputs.extend([0x7c00_fc00u32, 0x7e01_7c01, 0x0001_0400, 0x83ff_8001, 0x7bff_fbff, 0x3c00_bc00, 0x8000_0000]);
    let mut state = 0x9e37_79b9u32;
    while inputs.len() < 256 {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        // Half of them random bits, half floats around binary16's range.
        inputs.push(if inputs.len().is_multiple_of(2) {
            state
        } else {
            let exponent = 100 + (state >> 24) % 48;
            (state & 0x807f_ffff) | exponent << 23
        });
    }
    inputs
}

#[test]
fn modf_frexp_and_binary16_conversions_agree_with_lavapipe_bit_for_bit() {
    let kernel = Kernel::from_wgsl("half_and_split.wgsl", HALF_AND_SPLIT.into(), "main", false).unwrap();
    let inputs = half_edge_inputs();
    let count = inputs.len();
    let mut cpu = CpuBackend::new(CpuOptions::default()).unwrap();
    let got = run_words(&mut cpu, &kernel, &inputs, count * 20, (count / 64) as u32);
    // Spot checks independent of any GPU.
    let at = |value: f32, k: usize| got[inputs.iter().position(|&w| w == value.to_bits()).unwrap() * 20 + k];
    assert_eq!(at(-7.75, 0), (-0.75f32).to_bits(), "modf fract");
    assert_eq!(at(-7.75, 1), (-7.0f32).to_bits(), "modf whole");
    assert_eq!((at(-7.75, 2), at(-7.75, 3)), ((-0.968_75f32).to_bits(), 3), "frexp");
    assert_eq!(at(65520.0, 4), f32::INFINITY.to_bits(), "quantizeToF16 overflows to infinity");
    assert_eq!(at(65519.99, 4), 65504.0f32.to_bits(), "below the rounding boundary: f16 max");
    assert_eq!(at(2.980_232_2e-8, 4), 0, "ties to even: zero");
    assert_eq!(at(4.470_348_4e-8, 4), 5.960_464_5e-8f32.to_bits(), "rounds up to the smallest denormal");
    assert_eq!(at(1.0 + 1.0 / 2048.0, 4), 1.0f32.to_bits(), "tie to even, down");
    assert_eq!(at(1.0 + 3.0 / 2048.0, 4), (1.0f32 + 2.0 / 1024.0).to_bits(), "tie to even, up");
    let Some(mut gpu) =
        strata_tests::vulkan_backend("modf_frexp_and_binary16_conversions_agree_with_lavapipe_bit_for_bit")
    else {
        return;
    };
    let want = run_words(&mut gpu, &kernel, &inputs, count * 20, (count / 64) as u32);
    let denormal = |w: u32| w & 0x7f80_0000 == 0 && w & 0x007f_ffff != 0;
    // Excused, each only where lavapipe's result is the stated one:
    // - quantizeToF16 of a value in binary16's denormal range: the interpreter keeps the
    //   denormal (WGSL: the same as unpack2x16float(pack2x16float(e)), and both of those
    //   keep denormals on lavapipe too); lavapipe's OpQuantizeToF16 flushes it to +0,
    //   which SPIR-V allows.
    // - frexp of an f32 denormal: the interpreter normalises it; lavapipe returns the
    //   raw mantissa with exponent -126 (fract outside [0.5, 1)).
    let excused = |i: usize| {
        let (x, y) = (inputs[i / 20], inputs[(i / 20 * 7 + 3) % count]);
        let value = f32::from_bits(got[i]).abs();
        match i % 20 {
            4 | 18 | 19 => value > 0.0 && value < 6.103_515_6e-5 && want[i] == 0,
            2 | 3 | 15 | 17 => denormal(x),
            14 | 16 => denormal(y),
            _ => false,
        }
    };
    let mismatches: Vec<String> = (0..want.len())
        .filter(|&i| got[i] != want[i] && !excused(i))
        .map(|i| {
            let (x, y) = (inputs[i / 20], inputs[(i / 20 * 7 + 3) % count]);
            format!("x {x:#010x} y {y:#010x} op {}: cpu {:#010x}, lavapipe {:#010x}", i % 20, got[i], want[i])
        })
        .collect();
    assert!(mismatches.is_empty(), "{} mismatches:\n{}", mismatches.len(), mismatches.join("\n"));
    let excused_count = (0..want.len()).filter(|&i| got[i] != want[i]).count();
    eprintln!("binary16/modf/frexp: {} words, {excused_count} excused differences", want.len());
}

const INT64_SEMANTICS: &str = r#"
@group(0) @binding(0) var<storage, read> input: array<u64>;
@group(0) @binding(1) var<storage, read_write> output: array<u64>;

struct Tagged { tag: u32, value: i64, halves: vec2<u32> }
var<workgroup> shared_values: array<Tagged, 64>;
var<private> bias: i64 = -5000000000li;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let a = input[2u * id.x];
    let b = input[2u * id.x + 1u];
    let ia = bitcast<i64>(a);
    let ib = bitcast<i64>(b);
    let s = u32(b);
    let fa = bitcast<f32>(u32(a));
    shared_values[li] = Tagged(li, ia + bias, vec2<u32>(u32(b), u32(b >> 32u)));
    workgroupBarrier();
    let other = shared_values[63u - li];
    let o = id.x * 24u;
    output[o] = a + b;
    output[o + 1u] = a - b;
    output[o + 2u] = a * b;
    output[o + 3u] = a / b;
    output[o + 4u] = a % b;
    output[o + 5u] = bitcast<u64>(ia / ib);
    output[o + 6u] = bitcast<u64>(ia % ib);
    output[o + 7u] = (a & b) ^ (a | ~b);
    output[o + 8u] = a << s;
    output[o + 9u] = a >> s;
    output[o + 10u] = bitcast<u64>(ia >> s);
    output[o + 11u] = bitcast<u64>(-ia);
    output[o + 12u] = u64(select(0u, 1u, a < b)) | u64(select(0u, 2u, ia < ib)) | u64(select(0u, 4u, a == b))
        | u64(select(0u, 8u, ia >= ib)) | u64(select(0u, 16u, a > b)) | u64(select(0u, 32u, ia <= ib))
        | u64(select(0u, 64u, a != b)) | u64(select(0u, 128u, ia > ib)) | u64(select(0u, 256u, a <= b));
    output[o + 13u] = u64(fa);
    output[o + 14u] = bitcast<u64>(i64(fa));
    output[o + 15u] = u64(bitcast<u32>(f32(ia))) | (u64(bitcast<u32>(f32(a))) << 32u);
    output[o + 16u] = u64(i32(s)) ^ (bitcast<u64>(i64(u32(a))) << 1u);
    output[o + 17u] = bitcast<u64>(i64(i32(s))) ^ u64(u32(a >> 32u)) ^ (u64(bitcast<u32>(i32(ib))) << 7u);
    // naga 30 cannot express bitcast<vec2<u32>>(u64) (its `As` keeps the width): halves by shifts.
    output[o + 18u] = (a << 32u) | (a >> 32u);
    let va = vec2<i64>(ia, ib);
    let vb = vec2<i64>(ib, 3li);
    let vr = va * vb + select(va, vb, va < vb) - vec2<i64>(7li);
    output[o + 19u] = bitcast<u64>(vr.x);
    output[o + 20u] = bitcast<u64>(vr.y) ^ u64(all(va == vb)) ^ u64(i64(true));
    output[o + 21u] = bitcast<u64>(abs(ia)) ^ min(a, b) ^ bitcast<u64>(max(ia, ib)) ^ max(a, 1000lu);
    output[o + 22u] = bitcast<u64>(clamp(ia, -1000li, 1000li) + sign(ib) + other.value) ^ u64(other.tag)
        ^ (u64(other.halves.x) << 3u) ^ (u64(other.halves.y) << 32u);
    let vs = vec2<u64>(a, b) << vec2<u32>(s, 63u);
    output[o + 23u] = vs.x ^ (vs.y >> 1u) ^ vec3<u64>(a, b, a ^ b)[s % 3u] ^ u64(f32(a) > 1e18);
}
"#;

#[test]
fn int64_semantics_agree_with_lavapipe_bit_for_bit() {
    let kernel = Kernel::from_wgsl("int64_semantics.wgsl", INT64_SEMANTICS.into(), "main", false).unwrap();
    let edges: [u64; 16] = [
        0,
        1,
        2,
        63,
        64,
        65,
        i64::MAX as u64,
        i64::MIN as u64,
        u64::MAX,
        u64::MAX - 1,
        0xffff_ffff,
        0x1_0000_0000,
        0x5f00_0000,           // low word 2^63 as f32
        0xffff_ffff_df00_0000, // low word -2^63 as f32
        0x0000_0003_5f80_0000, // low word 2^64 as f32
        0x8000_0000_4f80_0000, // low word 2^32 as f32
    ];
    let mut values = Vec::new();
    for &a in &edges {
        for &b in &edges {
            values.extend([a, b]);
        }
    }
    let mut state = 0x2545_f491_4f6c_dd1du64;
    while values.len() < 2 * 320 {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        // Some small magnitudes too, where the operators' edge cases live.
        values.push(if values.len() % 3 == 0 { state % 200 } else { state });
    }
    let inputs: Vec<u32> = values.iter().flat_map(|v| [*v as u32, (*v >> 32) as u32]).collect();
    let pairs = values.len() / 2;
    let words = pairs * 24 * 2;
    let mut cpu = CpuBackend::new(CpuOptions::default()).unwrap();
    let got = run_words(&mut cpu, &kernel, &inputs, words, (pairs / 64) as u32);
    let wide = |w: &[u32], i: usize| u64::from(w[2 * i]) | u64::from(w[2 * i + 1]) << 32;
    // Spot checks of WGSL's rules, independent of any GPU.
    let at = |ai: usize, bi: usize, k: usize| wide(&got, (ai * edges.len() + bi) * 24 + k);
    assert_eq!(at(7, 0, 5), i64::MIN as u64, "division by zero yields the dividend");
    assert_eq!(at(7, 8, 5), i64::MIN as u64, "i64::MIN / -1 yields the dividend");
    assert_eq!(at(7, 8, 6), 0, "i64::MIN % -1 yields 0");
    assert_eq!(at(1, 5, 8), 2, "shift amounts are taken modulo 64");
    assert_eq!(at(12, 0, 14), 9_223_371_487_098_961_920, "f32 to i64 clamps to the largest float below 2^63");
    assert_eq!(at(1, 0, 18), 1 << 32, "halves swapped");
    let Some(mut gpu) = strata_tests::vulkan_backend("int64_semantics_agree_with_lavapipe_bit_for_bit") else {
        return;
    };
    let want = run_words(&mut gpu, &kernel, &inputs, words, (pairs / 64) as u32);
    // NaN → integer is implementation-defined (see the 32-bit test): not compared.
    let nan_conversion = |i: usize| matches!(i % 24, 13 | 14) && f32::from_bits(values[2 * (i / 24)] as u32).is_nan();
    // Widening between signednesses (u64(i32), i64(u32)): the interpreter extends by
    // the source's signedness, preserving the value, as naga's constant evaluator does
    // (so folded and run-time conversions agree); naga's SPIR-V extends by the target's
    // (UConvert / SConvert). Excused where both follow their rule exactly.
    let mixed_widening = |i: usize| {
        let (a, b) = (values[2 * (i / 24)] as u32, values[2 * (i / 24) + 1] as u32);
        let (sext, zext) = (|x: u32| x as i32 as i64 as u64, |x: u32| u64::from(x));
        i % 24 == 16 && wide(&got, i) == sext(b) ^ (zext(a) << 1) && wide(&want, i) == zext(b) ^ (sext(a) << 1)
    };
    let mismatches: Vec<String> = (0..words / 2)
        .filter(|&i| wide(&got, i) != wide(&want, i) && !nan_conversion(i) && !mixed_widening(i))
        .map(|i| {
            let (a, b) = (values[2 * (i / 24)], values[2 * (i / 24) + 1]);
            format!("a {a:#x} b {b:#x} op {}: cpu {:#x}, lavapipe {:#x}", i % 24, wide(&got, i), wide(&want, i))
        })
        .collect();
    assert!(mismatches.is_empty(), "{} mismatches:\n{}", mismatches.len(), mismatches.join("\n"));
    // The ash backend runs it too (it enables shaderInt64, which Vulkan requires for
    // naga's Int64 capability; lavapipe's validation layer did not flag its absence).
    let options = AshOptions { validation: true, source: SpirvSource::Naga, subgroups: false, ..Default::default() };
    let mut ash = AshBackend::new(options).expect("lavapipe through ash");
    assert_eq!(run_words(&mut ash, &kernel, &inputs, words, (pairs / 64) as u32), want, "ash and wgpu agree");
}

const F16_SEMANTICS: &str = r#"
enable f16;
@group(0) @binding(0) var<storage, read> input: array<u32>;
@group(0) @binding(1) var<storage, read_write> output: array<u32>;
var<private> scale: f16 = 0.5h;

fn half_at(i: u32) -> f16 {
    return f16(bitcast<f32>(input[i]));
}

fn bits(x: f16) -> u32 {
    return bitcast<u32>(f32(x));
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let x = half_at(2u * id.x);
    let y = half_at(2u * id.x + 1u);
    var acc = vec3<f16>(x, y, scale);
    acc *= 2.0h;
    let o = id.x * 22u;
    output[o] = bits(x);
    output[o + 1u] = bits(x + y);
    output[o + 2u] = bits(x - y);
    output[o + 3u] = bits(x * y);
    output[o + 4u] = bits(x / y);
    output[o + 5u] = bits(sqrt(abs(x)));
    output[o + 6u] = bits(-x * scale + 1.0h);
    output[o + 7u] = select(0u, 1u, x < y) | select(0u, 2u, x == y) | select(0u, 4u, x >= y)
        | select(0u, 8u, x != y) | select(0u, 16u, x > y) | select(0u, 32u, x <= y);
    output[o + 8u] = bitcast<u32>(i32(x));
    output[o + 9u] = u32(y);
    output[o + 10u] = bits(f16(bitcast<i32>(input[2u * id.x])));
    output[o + 11u] = bits(f16(input[2u * id.x + 1u] >> 12u));
    let v = vec3<f16>(x, y, scale) * vec3<f16>(y, x, x) + acc;
    output[o + 12u] = bits(v.x);
    output[o + 13u] = bits(v.y);
    output[o + 14u] = bits(v.z);
    output[o + 15u] = bits(dot(vec2<f16>(x, y), vec2<f16>(y, scale)));
    output[o + 16u] = bits(floor(x)) ^ bits(ceil(y)) ^ bits(trunc(x * 3.0h)) ^ (bits(round(y * 0.25h)) >> 1u);
    output[o + 17u] = bits(min(x, y)) ^ bits(max(x, -y)) ^ (bits(clamp(x, -1.0h, 1.0h)) >> 3u);
    output[o + 18u] = bits(fract(x)) ^ bits(sign(y)) ^ u32(f32(x) == f32(y));
    let w = select(vec2<f16>(y, x), vec2<f16>(x, y), vec2<bool>(x < y, y < x));
    output[o + 19u] = bits(w.x - w.y) ^ bits(vec4<f16>(x, y, x, y)[id.x % 4u]);
    let m = modf(vec2<f16>(x, y));
    output[o + 20u] = bits(m.fract.x) ^ (bits(m.whole.y) >> 1u);
    // (frexp of an f16 is not testable: naga 30 types its exponent i16, which needs
    // SHADER_INT16.)
    output[o + 21u] = bits(modf(y).whole);
}
"#;

#[test]
fn f16_arithmetic_and_conversions_agree_with_lavapipe_bit_for_bit() {
    let kernel = Kernel::from_wgsl("f16_semantics.wgsl", F16_SEMANTICS.into(), "main", false).unwrap();
    let mut inputs: Vec<u32> = Vec::new();
    let edges: Vec<u32> = [
        0.0f32,
        -0.0,
        1.0,
        -1.0,
        0.5,
        65504.0,
        -65504.0,
        65520.0,
        3.0,
        -7.25,
        1.0 + 1.0 / 2048.0,
        1e-7,
        6.0e-5,
        100.5,
        -0.75,
    ]
    .iter()
    .map(|v| v.to_bits())
    .chain([0x7fc0_0000, 0xff80_0000, 0x7f80_0000, 0x3380_0000, 0xb3c0_0000])
    .collect();
    for &a in &edges {
        for &b in &edges {
            inputs.extend([a, b]);
        }
    }
    let mut state = 0x1357_9bdfu32;
    while inputs.len() < 2 * 640 {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        // Floats within binary16's range and beyond, most in its normal range.
        let exponent = 100 + (state >> 24) % 50;
        inputs.push((state & 0x807f_ffff) | exponent << 23);
    }
    let pairs = inputs.len() / 2;
    let mut cpu = CpuBackend::new(CpuOptions::default()).unwrap();
    let got = run_words(&mut cpu, &kernel, &inputs, pairs * 22, (pairs / 64) as u32);
    let at = |a: f32, b: f32, k: usize| {
        let pair = (0..pairs).find(|&p| inputs[2 * p] == a.to_bits() && inputs[2 * p + 1] == b.to_bits()).unwrap();
        got[pair * 22 + k]
    };
    assert_eq!(at(65520.0, 0.0, 0), f32::INFINITY.to_bits(), "f32 -> f16 overflows to infinity");
    assert_eq!(at(1.0 + 1.0 / 2048.0, 0.0, 0), 1.0f32.to_bits(), "ties to even");
    assert_eq!(at(65504.0, 65504.0, 1), f32::INFINITY.to_bits(), "f16 sums overflow");
    assert_eq!(at(1.0, 1e-7, 1), 1.0f32.to_bits(), "f16 sums round");
    assert_eq!(at(3.0, 1.0, 4), 3.0f32.to_bits(), "f16 division");
    assert_eq!(at(1.0, 3.0, 4), 0.333_251_95f32.to_bits(), "1/3 rounded to binary16");
    let Some(mut gpu) = strata_tests::vulkan_backend("f16_arithmetic_and_conversions_agree_with_lavapipe_bit_for_bit")
    else {
        return;
    };
    let want = run_words(&mut gpu, &kernel, &inputs, pairs * 22, (pairs / 64) as u32);
    // Bit for bit, except where lavapipe is allowed to differ, each named:
    // - an operand that is NaN or ±Inf as an f16: Vulkan (without float controls) and
    //   WGSL's finite-math assumption leave the results of arithmetic on them open, and
    //   lavapipe's optimiser uses that (`x != NaN` false, dot products giving Inf for
    //   IEEE's NaN); NaN → integer is implementation-defined. Conversions are compared.
    // - `a * b + c` and dot products: lavapipe keeps f16 products and sums in f32 until
    //   the end (one rounding: contraction, excess precision, no intermediate overflow);
    //   the interpreter rounds every operation. Within 2 binary16 ULPs, or the
    //   interpreter's result overflowed where lavapipe's wider intermediate did not.
    // - the sign of a zero from min/max/sums of zeros (lavapipe's algebraic rewrites
    //   do not keep signed zeros).
    let special = |w: u32| !f32::from_bits(w).is_finite() || f32::from_bits(w).abs() >= 65520.0;
    let within_two_ulps = |x: u32, y: u32| {
        let (x, y) = (f32::from_bits(x), f32::from_bits(y));
        let ulp = (x.abs().max(y.abs()).max(6.103_515_6e-5) * (1.0 / 1024.0)).max(5.960_464_5e-8);
        (x - y).abs() <= 2.0 * ulp
    };
    let zero_sign_only = |x: u32, y: u32| matches!(x ^ y, 0x8000_0000 | 0x4000_0000 | 0x1000_0000 | 0x9000_0000);
    // Why a differing word is allowed to differ, if it is.
    let excuse = |i: usize| -> Option<&'static str> {
        let (a, b) = (inputs[2 * (i / 22)], inputs[2 * (i / 22) + 1]);
        let (g, w) = (got[i], want[i]);
        if matches!(i % 22, 0 | 10 | 11) {
            return None;
        }
        if matches!(i % 22, 8 | 9) {
            return (f32::from_bits(a).is_nan() || f32::from_bits(b).is_nan()).then_some("NaN -> integer");
        }
        if special(a) || special(b) {
            return Some("NaN or Inf operand");
        }
        if zero_sign_only(g, w) && matches!(i % 22, 12 | 13 | 15 | 17 | 18) {
            return Some("sign of a zero");
        }
        if matches!(i % 22, 12 | 13 | 15) {
            if within_two_ulps(g, w) {
                return Some("a * b + c within 2 ULPs");
            }
            if !f32::from_bits(g).is_finite() {
                return Some("intermediate overflow");
            }
        }
        None
    };
    let mut reasons = std::collections::BTreeMap::new();
    for i in (0..want.len()).filter(|&i| got[i] != want[i]) {
        *reasons.entry(excuse(i).unwrap_or("not excused")).or_insert(0) += 1;
    }
    eprintln!("f16: {} words; differing: {reasons:?}", want.len());
    let mismatches: Vec<String> = (0..want.len())
        .filter(|&i| got[i] != want[i] && excuse(i).is_none())
        .map(|i| {
            let (a, b) = (inputs[2 * (i / 22)], inputs[2 * (i / 22) + 1]);
            format!("a {a:#010x} b {b:#010x} op {}: cpu {:#010x}, lavapipe {:#010x}", i % 22, got[i], want[i])
        })
        .collect();
    assert!(mismatches.is_empty(), "{} mismatches:\n{}", mismatches.len(), mismatches.join("\n"));
    // The ash backend enables shaderFloat16 for it.
    let options = AshOptions { validation: true, source: SpirvSource::Naga, subgroups: false, ..Default::default() };
    let mut ash = AshBackend::new(options).expect("lavapipe through ash");
    assert_eq!(run_words(&mut ash, &kernel, &inputs, pairs * 22, (pairs / 64) as u32), want, "ash and wgpu agree");
}

const F16_MEMORY: &str = r#"
enable f16;
struct Mixed { a: f16, b: vec3<f16>, c: u32, d: vec2<f16>, e: array<f16, 3> }
@group(0) @binding(0) var<storage, read> input: array<f16>;
@group(0) @binding(1) var<storage, read_write> output: array<Mixed>;
var<workgroup> tile: array<vec2<f16>, 64>;
var<private> lut: array<f16, 4> = array<f16, 4>(1.0h, -2.0h, 0.5h, 65504.0h);

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let i = id.x;
    let x = input[2u * i];
    let y = input[2u * i + 1u];
    tile[li] = vec2<f16>(x, y);
    workgroupBarrier();
    let t = tile[63u - li];
    var m: Mixed;
    m.a = x * y;
    m.b = vec3<f16>(t, lut[i % 4u]);
    m.c = (bitcast<u32>(f32(x + y)) ^ i) + (arrayLength(&input) << 20u);
    m.d = t.yx - vec2<f16>(y);
    m.e[i % 3u] = x;
    m.e[2] = lut[(i + 1u) % 4u] * t.x;
    output[i] = m;
    output[i].b.y = y;
    output[i].e[(i + 2u) % 3u] = output[i].e[i % 3u] + 1.0h;
    let p = &output[i].d;
    (*p)[i % 2u] = (*p).x * 2.0h;
}
"#;

#[test]
fn f16_in_buffers_workgroup_memory_and_structs_agrees_with_lavapipe_bit_for_bit() {
    let kernel = Kernel::from_wgsl("f16_memory.wgsl", F16_MEMORY.into(), "main", false).unwrap();
    // Two binary16 per word: ±0, denormals, the largest finite, then finite random ones.
    let mut halves: Vec<u16> = vec![0, 0x8000, 0x0001, 0x83ff, 0x7bff, 0xfbff, 0x3c00, 0x3555, 0x0400, 0xc900];
    let mut state = 0xace1u32;
    while halves.len() < 2 * 256 {
        state = state.wrapping_mul(1_103_515_245).wrapping_add(12345);
        let h = (state >> 16) as u16;
        // Keep them finite: exponent field below 31, mostly in a moderate range.
        let exponent = 9 + (h >> 10) % 12;
        halves.push((h & 0x83ff) | exponent << 10);
    }
    let inputs: Vec<u32> = halves.chunks(2).map(|p| u32::from(p[0]) | u32::from(p[1]) << 16).collect();
    let count = inputs.len();
    let mut cpu = CpuBackend::new(CpuOptions::default()).unwrap();
    let got = run_words(&mut cpu, &kernel, &inputs, count * 8, (count / 64) as u32);
    // naga's layout: a@0, b@8 (6 bytes), c@16, d@20, e@24 (stride 2), 32 bytes each.
    let half = |words: &[u32], byte: usize| (words[byte / 4] >> (8 * (byte % 4))) & 0xffff;
    assert_eq!(half(&got, 10), u32::from(halves[1]), "output[0].b.y = y, stored through a pointer to a half");
    assert_eq!(got[4] >> 20, 512, "arrayLength of an array<f16> counts halves");
    let Some(mut gpu) =
        strata_tests::vulkan_backend("f16_in_buffers_workgroup_memory_and_structs_agrees_with_lavapipe_bit_for_bit")
    else {
        return;
    };
    let want = run_words(&mut gpu, &kernel, &inputs, count * 8, (count / 64) as u32);
    let mismatches: Vec<String> = (0..want.len())
        .filter(|&i| got[i] != want[i])
        .map(|i| format!("output[{}] word {}: cpu {:#010x}, lavapipe {:#010x}", i / 8, i % 8, got[i], want[i]))
        .collect();
    assert!(mismatches.is_empty(), "{} mismatches:\n{}", mismatches.len(), mismatches.join("\n"));
    // Every member written (padding, bytes 6-7 and 30-31, stays zero on both).
    let written = (0..count).filter(|&i| (0..8).all(|w| w == 1 || w == 7 || got[i * 8 + w] != 0)).count();
    assert!(written > count * 9 / 10, "{written} of {count} structs have every member non-zero");
    eprintln!("first struct: {:08x?}", &got[..8]);
}

#[test]
fn f16_matrices_are_refused_with_their_line() {
    let source = "enable f16;\n@group(0) @binding(0) var<storage, read_write> output: array<u32>;\n\
                  var<private> m: mat2x2<f16>;\n@compute @workgroup_size(1)\nfn main() {\n    output[0] = 1u;\n    _ = &m;\n}\n";
    let kernel = Kernel::from_wgsl("f16_matrix.wgsl", source.into(), "main", false).unwrap();
    let mut cpu = CpuBackend::new(CpuOptions::default()).unwrap();
    let output = cpu.create_buffer("output", 4).unwrap();
    let message = cpu.dispatch(&kernel, &[Bind::new(0, output)], [1, 1, 1]).unwrap_err().to_string();
    assert!(message.contains("unsupported: f16 matrices"), "{message}");
    assert!(message.contains("(WGSL line 3)"), "{message}");
}

/// One buffer bound at two read-only bindings (WebGPU allows it): the interpreter reads
/// it through both and keeps its contents (it once moved the buffer out for the first
/// binding, gave the second an empty one, and put that back last: zeros, then an empty
/// buffer for every later dispatch).
#[test]
fn a_buffer_bound_at_two_read_only_bindings_is_read_through_both_and_kept() {
    use strata_kernels::denoise_types::DenoiseGuide;
    let mut backend = CpuBackend::new(CpuOptions::default()).unwrap();
    let kernel = strata_kernels::Registry::shared().unwrap().get(strata_kernels::KernelId::SvgfModulate);
    let params = strata_render::denoise::SvgfSettings::default().params(4, 1, 0, false);
    let colour: Vec<[f32; 4]> = (0..4).map(|i| [i as f32 + 1.0; 4]).collect();
    let guide = DenoiseGuide { albedo: [1.0; 3], depth: 1.0, normal: [0.0, 0.0, 1.0], ..Default::default() };
    let buffers = [
        upload(&mut backend, "params", &[params]).unwrap(),
        upload(&mut backend, "colour and filtered", &colour).unwrap(),
        upload(&mut backend, "guides", &[guide; 4]).unwrap(),
        backend.create_buffer("denoised", 64).unwrap(),
    ];
    let bind = |name: &str, buffer| Bind::new(kernel.binding_named(name).unwrap().binding, buffer);
    let binds = [
        bind("params", buffers[0]),
        bind("colour", buffers[1]),
        bind("guides", buffers[2]),
        bind("filtered", buffers[1]),
        bind("denoised", buffers[3]),
    ];
    for _ in 0..2 {
        backend.dispatch(kernel, &binds, [1, 1, 1]).unwrap();
        let denoised: Vec<[f32; 4]> = download(&mut backend, buffers[3]).unwrap();
        let expected: Vec<[f32; 4]> = colour.iter().map(|c| [c[0], c[1], c[2], 0.0]).collect();
        assert_eq!(denoised, expected, "the filtered colour, read through the second binding");
        assert_eq!(download::<[f32; 4]>(&mut backend, buffers[1]).unwrap(), colour, "the shared buffer is kept");
    }
}

/// A kernel whose every invocation calls `long`, a function too large to be inlined
/// (over the compiler's `INLINE_EXPRESSIONS`), where a third of them return early and the
/// others run on. `long` adds 1 through a pointer before it branches: an invocation that
/// ran its start twice would count one too many.
fn early_returns_kernel() -> String {
    let mut source = String::from(
        "@group(0) @binding(0) var<storage, read> input: array<u32>;\n\
         @group(0) @binding(1) var<storage, read_write> output: array<u32>;\n\
         fn long(p: ptr<function, u32>, x: u32) -> u32 {\n\
             *p += 1u;\n\
             if x % 3u == 0u { return x; }\n\
             var y = x;\n",
    );
    for k in 0..200 {
        source += &format!("    y = (y ^ {k}u) * 3u + (y >> 7u);\n");
    }
    source += "    *p += 10u;\n\
                   return y;\n\
               }\n\
               @compute @workgroup_size(64)\n\
               fn main(@builtin(global_invocation_id) id: vec3<u32>) {\n\
                   var acc = 0u;\n\
                   let result = long(&acc, input[id.x]);\n\
                   output[2u * id.x] = result;\n\
                   output[2u * id.x + 1u] = acc;\n\
               }\n";
    source
}

#[test]
fn invocations_left_in_a_call_when_others_return_early_go_on_where_they_were() {
    let kernel = Kernel::from_wgsl("early_returns.wgsl", early_returns_kernel(), "main", false).unwrap();
    let inputs: Vec<u32> = (0..256u32).map(|i| i.wrapping_mul(2_654_435_761).rotate_left(11) ^ i).collect();
    let expected: Vec<u32> = inputs
        .iter()
        .flat_map(|&x| {
            if x % 3 == 0 {
                return [x, 1];
            }
            let y = (0..200u32).fold(x, |y, k| (y ^ k).wrapping_mul(3).wrapping_add(y >> 7));
            [y, 11]
        })
        .collect();
    let mut cpu = CpuBackend::new(CpuOptions::default()).unwrap();
    assert_eq!(run_words(&mut cpu, &kernel, &inputs, 256 * 2, 4), expected);
}
