//! External validation of translated kernels: each output checked by the reference tool
//! for its language where this machine has one.
//!
//! | target | validator |
//! |---|---|
//! | SPIR-V | `spirv-val --target-env vulkan1.1` |
//! | GLSL 4.50 | `glslangValidator -S comp` |
//! | HLSL SM 6.0 | glslang's HLSL front end compiles it to SPIR-V (`-D -e ENTRY -V`), then `spirv-val` checks that SPIR-V |
//! | MSL 2.3 | none: Apple's Metal compiler does not exist on Linux; reported as missing |
//!
//! A validator that is not installed is reported as [`Verdict::Missing`], never as a pass.

use crate::glslang::{self, GlslangInput, ToolError, run_tool};
use crate::registry::Kernel;
use crate::translate::{self, TranslateOptions, Translation, WorkgroupZeroInit};
use std::ffi::OsStr;
use std::path::{Path, PathBuf};

/// Target languages of the translation.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Target {
    /// SPIR-V binary.
    Spirv,
    /// HLSL source.
    Hlsl,
    /// Metal Shading Language source.
    Msl,
    /// GLSL 4.50 source.
    Glsl,
}

impl Target {
    /// Every target.
    pub const ALL: [Target; 4] = [Target::Spirv, Target::Hlsl, Target::Msl, Target::Glsl];

    /// Display name.
    pub fn name(self) -> &'static str {
        match self {
            Target::Spirv => "SPIR-V",
            Target::Hlsl => "HLSL",
            Target::Msl => "MSL",
            Target::Glsl => "GLSL",
        }
    }

    /// File extension of the output.
    pub fn extension(self) -> &'static str {
        match self {
            Target::Spirv => "spv",
            Target::Hlsl => "hlsl",
            Target::Msl => "metal",
            Target::Glsl => "comp",
        }
    }

    /// Whether a validator can exist on this operating system.
    pub fn validator_possible(self) -> bool {
        self != Target::Msl
    }

    /// Translates `kernel`. HLSL is written without naga's workgroup zero-initialisation,
    /// which glslang rejects (`(float[256])0`); our kernels initialise what they read.
    pub fn translate(self, kernel: &Kernel) -> Result<Translation, crate::KernelError> {
        match self {
            Target::Spirv => translate::spirv(kernel, TranslateOptions::default()),
            Target::Hlsl => translate::hlsl(kernel, TranslateOptions { workgroup_zero_init: WorkgroupZeroInit::Off }),
            Target::Msl => translate::msl(kernel, TranslateOptions::default()),
            Target::Glsl => translate::glsl(kernel, TranslateOptions::default()),
        }
    }
}

/// What validation of one output concluded.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// The validator accepted it; names the tool chain used.
    Valid(String),
    /// The validator rejected it (or translation failed).
    Invalid(String),
    /// No validator on this machine; says which tool is missing.
    Missing(String),
}

impl Verdict {
    /// Whether this is a failure.
    pub fn is_invalid(&self) -> bool {
        matches!(self, Verdict::Invalid(_))
    }
}

impl From<Result<String, ToolError>> for Verdict {
    fn from(result: Result<String, ToolError>) -> Self {
        match result {
            Ok(tools) => Verdict::Valid(tools),
            Err(ToolError::Missing(tool)) => Verdict::Missing(format!("`{tool}` is not installed")),
            Err(ToolError::Failed(message)) => Verdict::Invalid(message),
        }
    }
}

/// Translates `kernel` to `target`, writes it to `dir/NAME.EXT` and validates it.
pub fn translate_and_validate(kernel: &Kernel, target: Target, dir: &Path) -> (PathBuf, Verdict) {
    let path = dir.join(format!("{}.{}", kernel.name(), target.extension()));
    let translation = match target.translate(kernel) {
        Ok(t) => t,
        Err(e) => return (path, Verdict::Invalid(e.to_string())),
    };
    // Whole or not at all, never through a link (strata_files::write_whole).
    let written = if target == Target::Spirv {
        strata_files::write_whole(&path, bytemuck::cast_slice::<u32, u8>(&translation.words))
    } else {
        strata_files::write_whole(&path, translation.text.as_bytes())
    };
    if let Err(e) = written {
        return (path.clone(), Verdict::Invalid(format!("cannot write {}: {e}", path.display())));
    }
    let verdict = match target {
        Target::Spirv => spirv_val(&path).map(|()| "spirv-val".to_string()).into(),
        Target::Glsl => run_tool("glslangValidator", &[OsStr::new("-S"), OsStr::new("comp"), path.as_os_str()])
            .map(|()| "glslangValidator".to_string())
            .into(),
        Target::Hlsl => glslang::compile(kernel, GlslangInput::Hlsl, dir)
            .and_then(|_| spirv_val(&dir.join(format!("{}.hlsl.spv", kernel.name()))))
            .map(|()| "glslangValidator (HLSL front end) + spirv-val".to_string())
            .into(),
        Target::Msl => Verdict::Missing("no Metal compiler exists on Linux (translation succeeded)".into()),
    };
    (path, verdict)
}

fn spirv_val(path: &Path) -> Result<(), ToolError> {
    run_tool("spirv-val", &[OsStr::new("--target-env"), OsStr::new("vulkan1.1"), path.as_os_str()])
}
