//! SPIR-V compiled by glslang from naga's GLSL and HLSL output: runs the translated
//! sources themselves (through the ash backend), a far stronger check than parsing them.

use crate::registry::Kernel;
use crate::translate::{self, TranslateOptions, WorkgroupZeroInit};
use std::path::Path;
use std::process::Command;

/// Which naga output glslang compiles.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum GlslangInput {
    /// naga's GLSL 4.50 (`glslangValidator -V`), its workgroup zero-initialisation
    /// rewritten as loops, which compile in seconds where naga's constructors took
    /// minutes ([`crate::glsl_zero_init`]).
    Glsl,
    /// naga's HLSL SM 6.0 (`glslangValidator -D -V`), its zero-initialisation of
    /// workgroup, private and function arrays rewritten as loops glslang accepts
    /// ([`crate::hlsl_zero_init`]).
    Hlsl,
}

/// Why glslang produced no SPIR-V.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ToolError {
    /// The tool is not installed.
    Missing(String),
    /// The tool ran and failed, or could not run.
    Failed(String),
}

impl std::fmt::Display for ToolError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ToolError::Missing(tool) => write!(f, "`{tool}` is not installed"),
            ToolError::Failed(message) => f.write_str(message),
        }
    }
}

/// Runs `tool` with `args`; stdout and stderr go into the error.
pub fn run_tool(tool: &str, args: &[&std::ffi::OsStr]) -> Result<(), ToolError> {
    match Command::new(tool).args(args).output() {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Err(ToolError::Missing(tool.into())),
        Err(e) => Err(ToolError::Failed(format!("`{tool}` could not run: {e}"))),
        Ok(out) if out.status.success() => Ok(()),
        Ok(out) => Err(ToolError::Failed(format!(
            "`{tool}` rejected it:\n{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        ))),
    }
}

/// Writes naga's `input` translation of `kernel` to `dir`, compiles it with glslang for
/// Vulkan 1.1 and returns the SPIR-V words and the entry point name.
pub fn compile(kernel: &Kernel, input: GlslangInput, dir: &Path) -> Result<(Vec<u32>, String), ToolError> {
    std::fs::create_dir_all(dir).map_err(|e| ToolError::Failed(format!("{}: {e}", dir.display())))?;
    let (translation, extension) = match input {
        GlslangInput::Glsl => (translate::glsl(kernel, TranslateOptions::default()), "comp"),
        GlslangInput::Hlsl => {
            // Zeroed as WGSL promises: outside kernels count into workgroup variables.
            (translate::hlsl(kernel, TranslateOptions { workgroup_zero_init: WorkgroupZeroInit::Polyfill }), "hlsl")
        }
    };
    let mut translation = translation.map_err(|e| ToolError::Failed(e.to_string()))?;
    if input == GlslangInput::Glsl {
        translation.text = crate::glsl_zero_init::zero_init_as_loops(&translation.text);
    }
    if input == GlslangInput::Hlsl {
        translation.text = byte_address_lengths_in_bytes(&translation.text)?;
        translation.text = crate::hlsl_samplers::plain_samplers(&translation.text).map_err(ToolError::Failed)?;
        translation.text = crate::hlsl_zero_init::zero_init_as_loops(&translation.text);
    }
    let source = dir.join(format!("{}.{extension}", kernel.name()));
    let output = dir.join(format!("{}.{extension}.spv", kernel.name()));
    std::fs::write(&source, &translation.text).map_err(|e| ToolError::Failed(format!("{}: {e}", source.display())))?;
    use std::ffi::OsStr;
    let mut args: Vec<&OsStr> = Vec::new();
    if input == GlslangInput::Hlsl {
        args.extend([OsStr::new("-D"), OsStr::new("-e"), OsStr::new(&translation.entry_point)]);
    }
    args.extend([OsStr::new("-V"), OsStr::new("--target-env"), OsStr::new("vulkan1.1")]);
    args.extend([OsStr::new("-S"), OsStr::new("comp"), source.as_os_str(), OsStr::new("-o"), output.as_os_str()]);
    run_tool("glslangValidator", &args)?;
    let bytes = std::fs::read(&output).map_err(|e| ToolError::Failed(format!("{}: {e}", output.display())))?;
    if bytes.len() % 4 != 0 {
        return Err(ToolError::Failed(format!("{}: not a SPIR-V file", output.display())));
    }
    let words = bytes.chunks_exact(4).map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]])).collect();
    Ok((words, translation.entry_point))
}

/// The statement in naga's `arrayLength` helpers (`NagaBufferLength`,
/// `NagaRWBufferLength`) that asks a `(RW)ByteAddressBuffer` for its size.
const GET_DIMENSIONS: &str = "    buffer.GetDimensions(ret);\n";

/// Works around a glslang bug on the HLSL path: glslang's HLSL front end (12.0.0, as
/// Debian ships it) compiles `ByteAddressBuffer::GetDimensions(out uint)` to
/// `OpArrayLength` of the buffer's `uint` array, which counts 4-byte words, where HLSL
/// defines (and DXC returns) bytes. naga's `arrayLength` helpers divide that size by
/// the array stride, so under glslang every runtime array read 4× too short: a loop to
/// `arrayLength` saw a quarter of its elements (a flocking step found almost no
/// neighbours). Scaling the result by 4 inside naga's helpers restores bytes.
///
/// `tests/tests/glslang_hlsl_buffer_length.rs` holds a six-line HLSL reproducer: it
/// fails when a glslang that returns bytes is installed, and then this function must
/// go. Refuses (rather than compile something wrong) HLSL whose buffer `GetDimensions`
/// calls are not all in naga's helpers as this function knows them.
pub fn byte_address_lengths_in_bytes(hlsl: &str) -> Result<String, ToolError> {
    // A buffer's call passes one plain `uint` variable; a texture's passes components
    // (`ret.x`) or several values, and is not affected.
    let calls = hlsl
        .match_indices(".GetDimensions(")
        .filter(|(at, call)| {
            let arguments = &hlsl[at + call.len()..];
            let arguments = &arguments[..arguments.find(')').unwrap_or(arguments.len())];
            !arguments.contains(',') && !arguments.contains('.')
        })
        .count();
    let helpers = hlsl.matches(GET_DIMENSIONS).count();
    if calls != helpers {
        return Err(ToolError::Failed(format!(
            "naga's HLSL has {calls} GetDimensions call(s), {helpers} of them in the buffer-length helpers this \
             workaround knows (kernels/src/glslang.rs): naga's output changed, update the workaround"
        )));
    }
    Ok(hlsl.replace(
        GET_DIMENSIONS,
        "    buffer.GetDimensions(ret);\n    ret = ret * 4u; // glslang returns 4-byte words, not bytes\n",
    ))
}
