// An empty kernel: measures a backend's fixed cost per dispatch (benches/benches/backends.rs).
// It writes nothing (the condition never holds for a real dispatch), which the
// cross-backend check verifies on every backend.
//
// Bindings (group 0):
//   0 storage, rw   array<u32>   sink: left untouched

@group(0) @binding(0) var<storage, read_write> sink: array<u32>;

@compute @workgroup_size(64)
fn empty(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x == 0xffffffffu {
        sink[0] = 0u;
    }
}
