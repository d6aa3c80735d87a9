// A workgroup's inclusive prefix sum of WG * ITEMS words (u32, wrapping), where both sizes
// are overrides without a default (the pipeline must give them) and the workgroup arrays
// are sized by override expressions. Written for strata's corpus (issue 41: the CPU
// interpreter once gave such arrays no memory and returned zeros without an error).
//
// Bindings: @group(0) @binding(0) `input` (read), @binding(1) `output` (read_write).
// Workgroup w scans input[w * WG * ITEMS ..][.. WG * ITEMS] into the same words of output.
override WG: u32;
override ITEMS: u32;

@group(0) @binding(0) var<storage, read> input: array<u32>;
@group(0) @binding(1) var<storage, read_write> output: array<u32>;

// The lanes' totals twice: the two halves of a ping-pong (Hillis-Steele) scan.
var<workgroup> totals: array<u32, WG * 2u>;
var<workgroup> tile: array<u32, WG * ITEMS>;

@compute @workgroup_size(WG)
fn main(@builtin(local_invocation_index) lane: u32, @builtin(workgroup_id) group: vec3<u32>) {
    let base = group.x * WG * ITEMS;
    // Coalesced: lane k reads words k, k + WG, k + 2 WG, ...
    for (var k = 0u; k < ITEMS; k++) {
        tile[lane + k * WG] = input[base + lane + k * WG];
    }
    workgroupBarrier();
    // Each lane scans its own ITEMS consecutive words.
    var sum = 0u;
    for (var k = 0u; k < ITEMS; k++) {
        sum += tile[lane * ITEMS + k];
        tile[lane * ITEMS + k] = sum;
    }
    totals[lane] = sum;
    workgroupBarrier();
    // The lanes' totals scanned with doubling offsets, a barrier in every round.
    var source = 0u;
    for (var offset = 1u; offset < WG; offset *= 2u) {
        var value = totals[source + lane];
        if (lane >= offset) {
            value += totals[source + lane - offset];
        }
        totals[WG - source + lane] = value;
        source = WG - source;
        workgroupBarrier();
    }
    var before = 0u;
    if (lane > 0u) {
        before = totals[source + lane - 1u];
    }
    for (var k = 0u; k < ITEMS; k++) {
        tile[lane * ITEMS + k] += before;
    }
    workgroupBarrier();
    for (var k = 0u; k < ITEMS; k++) {
        output[base + lane + k * WG] = tile[lane + k * WG];
    }
}
