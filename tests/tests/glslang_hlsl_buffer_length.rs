//! An upstream glslang bug on our HLSL path, with its minimal reproducer and the proof
//! that our workaround holds.
//!
//! HLSL defines `(RW)ByteAddressBuffer::GetDimensions(out uint)` as the buffer's size in
//! bytes (DXC returns bytes). glslang's HLSL front end (12.0.0, Debian's) compiles it to
//! `OpArrayLength` of the buffer's `uint` array, a count of 4-byte words, with nothing
//! scaling it. naga's HLSL for WGSL's `arrayLength` divides that size by the array
//! stride, so on the ash-hlsl path every runtime array read a quarter of its length: a
//! flocking step looping to `arrayLength` found almost no neighbours (4050 of 4096 words
//! wrong). `strata_kernels::glslang::byte_address_lengths_in_bytes` scales the size by 4
//! in naga's helpers before glslang compiles them.
//!
//! When a glslang that returns bytes is installed, the first test fails: then remove the
//! workaround (and this file).

use strata_kernels::Kernel;
use strata_kernels::glslang::{ToolError, byte_address_lengths_in_bytes, run_tool};

/// The SPIR-V disassembly of `tests/data/upstream/glslang_byte_address_get_dimensions.hlsl`
/// compiled by glslang, or `None` when glslang or spirv-dis is missing (allowed unless
/// `STRATA_REQUIRE_VALIDATORS=1`).
fn reproducer_disassembly() -> Option<String> {
    let source = format!("{}/data/upstream/glslang_byte_address_get_dimensions.hlsl", env!("CARGO_MANIFEST_DIR"));
    let dir =
        std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("strata-glslang-repro-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let spv = dir.join("repro.spv");
    let args: Vec<&std::ffi::OsStr> = ["-D", "-e", "main", "-V", "--target-env", "vulkan1.1", "-S", "comp"]
        .iter()
        .map(std::ffi::OsStr::new)
        .chain([std::ffi::OsStr::new(&source), std::ffi::OsStr::new("-o"), spv.as_os_str()])
        .collect();
    match run_tool("glslangValidator", &args) {
        Err(ToolError::Missing(tool)) if std::env::var_os("STRATA_REQUIRE_VALIDATORS").is_none() => {
            eprintln!("SKIPPED: `{tool}` is not installed");
            return None;
        }
        other => other.unwrap(),
    }
    let out = std::process::Command::new("spirv-dis").arg(&spv).output();
    let _ = std::fs::remove_dir_all(&dir);
    match out {
        Err(_) if std::env::var_os("STRATA_REQUIRE_VALIDATORS").is_none() => None,
        other => Some(String::from_utf8(other.expect("spirv-dis runs").stdout).unwrap()),
    }
}

#[test]
fn glslang_returns_words_not_bytes_for_get_dimensions() {
    let Some(text) = reproducer_disassembly() else { return };
    // The size is OpArrayLength of the uint array, stored as it is: no multiply by 4 or
    // shift by 2 anywhere in the shader.
    let length = text.lines().find(|l| l.contains("OpArrayLength")).expect("GetDimensions becomes OpArrayLength");
    let result = length.split_whitespace().next().unwrap();
    let scaled = text.lines().any(|l| {
        (l.contains("OpIMul") || l.contains("OpShiftLeftLogical")) && l.split_whitespace().any(|w| w == result)
    });
    assert!(
        !scaled,
        "glslang now scales GetDimensions' result: the upstream bug is fixed; remove \
         byte_address_lengths_in_bytes from kernels/src/glslang.rs and this test\n{text}"
    );
}

const ARRAY_LENGTH: &str = "
struct Item { a: vec4<f32> }
@group(0) @binding(0) var<storage, read> items: array<Item>;
@group(0) @binding(1) var<storage, read_write> length: array<u32>;
@compute @workgroup_size(1)
fn main() {
    length[0] = arrayLength(&items);
    length[1] = arrayLength(&length);
}
";

#[test]
fn the_workaround_makes_array_length_right_on_the_hlsl_path() {
    use strata_backends::ash_backend::{AshBackend, AshOptions, SpirvSource};
    use strata_backends::backend::{download, upload};
    use strata_backends::{Backend, BackendError, Bind, gpu_required};
    let kernel = Kernel::from_wgsl("array_length.wgsl", ARRAY_LENGTH.into(), "main", false).unwrap();
    let options =
        AshOptions { validation: true, source: SpirvSource::GlslangFromHlsl, subgroups: false, ..Default::default() };
    let mut ash = match AshBackend::new(options) {
        Ok(ash) => ash,
        Err(error @ BackendError::NoAdapter { .. }) if !gpu_required() => {
            eprintln!("SKIPPED: {error}");
            return;
        }
        Err(error) => panic!("{error}"),
    };
    let items = upload(&mut ash, "items", &[0.0f32; 4 * 37]).unwrap();
    let length = upload(&mut ash, "length", &[0u32; 5]).unwrap();
    match ash.dispatch(&kernel, &[Bind::new(0, items), Bind::new(1, length)], [1, 1, 1]) {
        Err(BackendError::Validation { message, .. }) if message.contains("is not installed") => {
            assert!(std::env::var_os("STRATA_REQUIRE_VALIDATORS").is_none(), "{message}");
            return;
        }
        other => other.unwrap(),
    }
    let words: Vec<u32> = download(&mut ash, length).unwrap();
    assert_eq!(&words[..2], &[37, 5], "arrayLength on the HLSL path: 37 items of 16 bytes, 5 words");
}

#[test]
fn the_workaround_refuses_hlsl_it_does_not_know() {
    let known = "uint NagaBufferLength(ByteAddressBuffer buffer)\n{\n    uint ret;\n    buffer.GetDimensions(ret);\n    return ret;\n}\n";
    let patched = byte_address_lengths_in_bytes(known).unwrap();
    assert!(patched.contains("ret = ret * 4u;"), "{patched}");
    // A texture's size query is not a buffer length: left alone.
    let texture = format!(
        "{known}uint2 d(Texture2D<float4> t) {{ uint4 ret; t.GetDimensions(0, ret.x, ret.y, ret.z); return ret.xy; }}\n"
    );
    assert_eq!(byte_address_lengths_in_bytes(&texture).unwrap().matches("ret * 4u").count(), 1);
    let unknown = format!("{known}void f() {{ uint n; other.GetDimensions(n); }}\n");
    let error = byte_address_lengths_in_bytes(&unknown).unwrap_err().to_string();
    assert!(error.contains("update the workaround"), "{error}");
}
