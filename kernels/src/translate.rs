//! naga's back ends with the options strata uses everywhere.
//!
//! * SPIR-V 1.3 without naga's DEBUG flag (its OpSource language marker makes Debian's
//!   validation layer report "Invalid source language operand: 10").
//! * HLSL shader model 6.0 (wave intrinsics for the subgroup kernels); registers follow
//!   WGSL: `@group(g) @binding(b)` → `register(?b, space g)`.
//! * MSL 2.3 with an explicit per-entry-point buffer map (`[[buffer(b)]]`).
//! * GLSL 4.50 core with `layout(binding = b)` from a binding map (GLSL has no sets),
//!   integer `/` and `%` written as helpers with WGSL's meaning (`integer_division`).
//!
//! WGSL zero-initialises workgroup memory. [`WorkgroupZeroInit`] says who does it: the
//! shader (loops the invocations share, then a barrier: correct everywhere; `Zeroed`
//! below), the driver (`shaderZeroInitializeWorkgroupMemory`, Vulkan 1.3), or nobody, for
//! tools that reject naga's initialisers (glslang's HLSL front end); strata's kernels
//! initialise every workgroup variable they read, so they are correct without it.

use crate::error::KernelError;
use crate::registry::Kernel;

/// Who zero-initialises workgroup memory.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WorkgroupZeroInit {
    /// The shader writes the zeros: in loops the invocations share wherever they can be
    /// written ([`crate::workgroup_zero_loops`]), else by naga's own polyfill.
    Polyfill,
    /// The driver does (SPIR-V only; Vulkan's `shaderZeroInitializeWorkgroupMemory`).
    Native,
    /// Nobody: only for kernels that initialise what they read.
    Off,
}

/// Options shared by the back ends.
#[derive(Clone, Copy, Debug)]
pub struct TranslateOptions {
    /// Zero-initialisation of workgroup variables.
    pub workgroup_zero_init: WorkgroupZeroInit,
}

impl Default for TranslateOptions {
    fn default() -> Self {
        Self { workgroup_zero_init: WorkgroupZeroInit::Polyfill }
    }
}

/// The module a writer translates, and whether the writer itself zeroes workgroup memory.
///
/// With [`WorkgroupZeroInit::Polyfill`] the shader zeroes it, in loops that the
/// workgroup's invocations share ([`crate::workgroup_zero_loops`], ending in a barrier)
/// wherever they can be written, and the writer's own zeroing is off. naga's writers would
/// have one invocation store each variable whole: an array as one null constant in SPIR-V,
/// one constructor with an argument per element in GLSL. lavapipe compiled a
/// block-histogram kernel of the kernel package's SPIR-V so zeroed in 25-30 s, against
/// under a second in loops or zeroed by the driver, and a new machine (no shader cache)
/// paid that for every variant it met (docs/benchmarks/ci-time.md, tenth session). Where
/// no loops can be written (an override-sized array, a struct holding an atomic), the
/// writer zeroes as before. [`WorkgroupZeroInit::Native`] leaves the module to the writer
/// (SPIR-V: the driver zeroes; the text writers: zeroing in the source, as before), and
/// [`WorkgroupZeroInit::Off`] zeroes nothing.
struct Zeroed {
    /// The kernel's module with the zeroing loops, and its validation info; `None` for the
    /// kernel's own.
    rewritten: Option<(naga::Module, naga::valid::ModuleInfo)>,
    /// Whether the writer's own zeroing stays on.
    writer_zeroes: bool,
}

impl Zeroed {
    /// How `kernel` is zeroed for `target` (the writer's name, for errors) under `options`.
    fn new(kernel: &Kernel, options: TranslateOptions, target: &'static str) -> Result<Self, KernelError> {
        match options.workgroup_zero_init {
            WorkgroupZeroInit::Polyfill => {
                let rewritten =
                    crate::workgroup_zero_loops::zero_in_loops(&kernel.module, &kernel.info, kernel.entry_point())
                        .map_err(|e| error(kernel, target, e))?;
                let writer_zeroes = rewritten.is_none();
                Ok(Self { rewritten, writer_zeroes })
            }
            WorkgroupZeroInit::Native => Ok(Self { rewritten: None, writer_zeroes: true }),
            WorkgroupZeroInit::Off => Ok(Self { rewritten: None, writer_zeroes: false }),
        }
    }

    /// The module (and its info) the writer translates: the rewritten one, else the kernel's.
    fn module<'a>(&'a self, kernel: &'a Kernel) -> (&'a naga::Module, &'a naga::valid::ModuleInfo) {
        match &self.rewritten {
            Some((module, info)) => (module, info),
            None => (&kernel.module, &kernel.info),
        }
    }
}

/// A translated kernel in one target language.
#[derive(Clone, Debug)]
pub struct Translation {
    /// Source text (for SPIR-V, the disassembly is not produced; see [`Translation::words`]).
    pub text: String,
    /// SPIR-V words (empty for text targets).
    pub words: Vec<u32>,
    /// The entry point's name in the output (back ends rename some, e.g. `sort_256` → `sort_256_`).
    pub entry_point: String,
}

fn error(kernel: &Kernel, target: &'static str, message: impl ToString) -> KernelError {
    KernelError::Translation { kernel: kernel.name().into(), target, message: message.to_string() }
}

/// SPIR-V for Vulkan 1.1+, the entry point alone.
pub fn spirv(kernel: &Kernel, options: TranslateOptions) -> Result<Translation, KernelError> {
    use naga::back::spv;
    let mut flags = spv::WriterFlags::empty();
    flags.set(spv::WriterFlags::LABEL_VARYINGS, true);
    let zeroed = Zeroed::new(kernel, options, "SPIR-V")?;
    let spv_options = spv::Options {
        lang_version: (1, 3),
        flags,
        bounds_check_policies: image_bounds_checks(),
        zero_initialize_workgroup_memory: match (options.workgroup_zero_init, zeroed.writer_zeroes) {
            (WorkgroupZeroInit::Native, _) => spv::ZeroInitializeWorkgroupMemoryMode::Native,
            (WorkgroupZeroInit::Polyfill, true) => spv::ZeroInitializeWorkgroupMemoryMode::Polyfill,
            _ => spv::ZeroInitializeWorkgroupMemoryMode::None,
        },
        ..spv::Options::default()
    };
    let pipeline =
        spv::PipelineOptions { shader_stage: naga::ShaderStage::Compute, entry_point: kernel.entry_point().into() };
    let (module, info) = zeroed.module(kernel);
    let words = spv::write_vec(module, info, &spv_options, Some(&pipeline)).map_err(|e| error(kernel, "SPIR-V", e))?;
    Ok(Translation { text: String::new(), words, entry_point: kernel.entry_point().into() })
}

/// HLSL (shader model 6.0) for DXC, or glslang's HLSL front end.
pub fn hlsl(kernel: &Kernel, options: TranslateOptions) -> Result<Translation, KernelError> {
    use naga::back::hlsl;
    let zeroed = Zeroed::new(kernel, options, "HLSL")?;
    let hlsl_options = hlsl::Options {
        shader_model: hlsl::ShaderModel::V6_0,
        zero_initialize_workgroup_memory: zeroed.writer_zeroes,
        ..hlsl::Options::default()
    };
    let pipeline =
        hlsl::PipelineOptions { entry_point: Some((naga::ShaderStage::Compute, kernel.entry_point().into())) };
    let mut text = String::new();
    let (module, info) = zeroed.module(kernel);
    let reflection = hlsl::Writer::new(&mut text, &hlsl_options, &pipeline)
        .write(module, info, None)
        .map_err(|e| error(kernel, "HLSL", e))?;
    let entry_point = translated_name(kernel, "HLSL", reflection.entry_point_names)?;
    Ok(Translation { text, words: Vec::new(), entry_point })
}

/// Metal Shading Language 2.3.
pub fn msl(kernel: &Kernel, options: TranslateOptions) -> Result<Translation, KernelError> {
    msl_version(kernel, options, (2, 3))
}

/// Metal Shading Language of `version` (major, minor): buffers at `[[buffer(binding)]]`,
/// the array-sizes buffer at 30.
pub fn msl_version(kernel: &Kernel, options: TranslateOptions, version: (u8, u8)) -> Result<Translation, KernelError> {
    use naga::back::msl;
    let zeroed = Zeroed::new(kernel, options, "MSL")?;
    let mut resources = msl::BindingMap::default();
    for binding in &kernel.bindings {
        resources.insert(
            naga::ResourceBinding { group: binding.group, binding: binding.binding },
            msl::BindTarget {
                buffer: Some(binding.binding as u8),
                mutable: binding.is_writable(),
                ..Default::default()
            },
        );
    }
    let mut per_entry_point_map = msl::EntryPointResourceMap::default();
    per_entry_point_map.insert(
        kernel.entry_point().into(),
        msl::EntryPointResources { resources, immediates_buffer: None, sizes_buffer: Some(30) },
    );
    let msl_options = msl::Options {
        lang_version: version,
        per_entry_point_map,
        fake_missing_bindings: false,
        zero_initialize_workgroup_memory: zeroed.writer_zeroes,
        ..msl::Options::default()
    };
    let pipeline = msl::PipelineOptions {
        entry_point: Some((naga::ShaderStage::Compute, kernel.entry_point().into())),
        ..Default::default()
    };
    let (module, info) = zeroed.module(kernel);
    let (text, info) = msl::write_string(module, info, &msl_options, &pipeline).map_err(|e| error(kernel, "MSL", e))?;
    let entry_point = translated_name(kernel, "MSL", info.entry_point_names)?;
    Ok(Translation { text, words: Vec::new(), entry_point })
}

/// GLSL 4.50 core; bindings from WGSL's `@binding` (a kernel of several groups gets them
/// flattened into one set: `Kernel::flat_binding`).
pub fn glsl(kernel: &Kernel, options: TranslateOptions) -> Result<Translation, KernelError> {
    use naga::back::glsl;
    let zeroed = Zeroed::new(kernel, options, "GLSL")?;
    let mut binding_map = glsl::BindingMap::default();
    for binding in &kernel.bindings {
        let flat = kernel.flat_binding(binding.group, binding.binding) as u8;
        binding_map.insert(naga::ResourceBinding { group: binding.group, binding: binding.binding }, flat);
    }
    let glsl_options = glsl::Options {
        version: glsl::Version::Desktop(450),
        writer_flags: glsl::WriterFlags::empty(),
        binding_map,
        zero_initialize_workgroup_memory: zeroed.writer_zeroes,
    };
    let pipeline = glsl::PipelineOptions {
        shader_stage: naga::ShaderStage::Compute,
        entry_point: kernel.entry_point().into(),
        multiview: None,
    };
    // GLSL leaves integer `%` of negative numbers and division by zero undefined; WGSL
    // does not (see `integer_division`). And naga's writer passes unsigned texture
    // levels where GLSL takes `int` (see `signed_image_levels`).
    let (zeroed_module, zeroed_info) = zeroed.module(kernel);
    let defined = crate::signed_image_levels::defined_for_glsl(zeroed_module, zeroed_info)
        .map_err(|e| error(kernel, "GLSL", e))?;
    let (module, info) = match &defined {
        Some((module, info)) => (module, info),
        None => (zeroed_module, zeroed_info),
    };
    let mut text = String::new();
    glsl::Writer::new(&mut text, module, info, &glsl_options, &pipeline, image_bounds_checks())
        .and_then(|mut writer| writer.write())
        .map_err(|e| error(kernel, "GLSL", e))?;
    Ok(Translation { text, words: Vec::new(), entry_point: "main".into() })
}

/// The bounds checks every translation gets: none on buffers and arrays (as before:
/// Vulkan's robust buffer access and the kernels' own bounds serve), and out-of-range
/// texture loads defined to read zero, as the interpreter's do (naga's
/// `ReadZeroSkipWrite`; a device without robust image access would otherwise read
/// anything).
fn image_bounds_checks() -> naga::proc::BoundsCheckPolicies {
    naga::proc::BoundsCheckPolicies {
        image_load: naga::proc::BoundsCheckPolicy::ReadZeroSkipWrite,
        ..naga::proc::BoundsCheckPolicies::default()
    }
}

fn translated_name<E: std::fmt::Display>(
    kernel: &Kernel,
    target: &'static str,
    names: Vec<Result<String, E>>,
) -> Result<String, KernelError> {
    // With an entry point chosen in the pipeline options, the back ends write (and name)
    // that one alone; otherwise one name per entry point of the module.
    let index = if names.len() == 1 { 0 } else { kernel.entry_index() };
    match names.into_iter().nth(index) {
        Some(Ok(name)) => Ok(name),
        Some(Err(e)) => Err(error(kernel, target, e)),
        None => Err(error(kernel, target, "the back end reported no entry point name")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn polyfilled() -> TranslateOptions {
        TranslateOptions { workgroup_zero_init: WorkgroupZeroInit::Polyfill }
    }

    /// The block histogram's workgroup arrays (1024 slots) zeroed in loops by every text
    /// writer, and by none of naga's whole-array forms: GLSL's constructor with an argument
    /// per element (lavapipe took 0.8 to 3.4 minutes a kernel to compile it on `ash-glsl`),
    /// HLSL's cast of zero to the array type (which glslang's HLSL front end refuses), MSL's
    /// `= {}`. (SPIR-V's whole-array null constant is covered by `tests/tests/corpus.rs`,
    /// which runs the loops on a device.)
    #[test]
    fn a_polyfilled_kernel_zeroes_its_workgroup_arrays_in_loops_in_every_language() {
        let registry = crate::Registry::shared().unwrap();
        let kernel = registry.get(crate::KernelId::BlockHistogram);
        // One element stored per trip: `shared_local[i] = 0u;` in GLSL, `shared_local[min(i,
        // 1023u)] = ZeroValueuint();` in HLSL.
        let zeroed = |line: &str| {
            let line = line.trim();
            line.starts_with("shared_local[") && (line.ends_with("] = 0u;") || line.ends_with("] = ZeroValueuint();"))
        };
        let glsl = glsl(kernel, polyfilled()).unwrap().text;
        assert!(glsl.lines().any(zeroed), "no zeroing loop in the GLSL");
        assert!(!glsl.contains(&"0u, ".repeat(64)), "a zeroing constructor in the GLSL");
        let hlsl = hlsl(kernel, polyfilled()).unwrap().text;
        assert!(hlsl.lines().any(zeroed), "no zeroing loop in the HLSL");
        assert!(!hlsl.contains("[1024])0"), "a zeroing cast in the HLSL");
        let msl = msl(kernel, polyfilled()).unwrap().text;
        assert!(!msl.contains("shared_local = {}"), "a whole-array zeroing in the MSL");
        assert!(!spirv(kernel, polyfilled()).unwrap().words.is_empty());
    }

    /// Where no loop can be written (a struct holding an atomic has no zero value to store),
    /// the writer zeroes as naga does; with `Off` nobody does.
    #[test]
    fn a_struct_holding_an_atomic_is_left_to_the_writer() {
        let source = "struct Tally { hits: atomic<u32>, misses: u32 }
            var<workgroup> tally: Tally;
            @group(0) @binding(0) var<storage, read_write> o: array<u32>;
            @compute @workgroup_size(64) fn main(@builtin(local_invocation_index) i: u32) {
                atomicAdd(&tally.hits, 1u);
                workgroupBarrier();
                o[i] = atomicLoad(&tally.hits);
            }";
        let kernel = Kernel::from_wgsl("tally.wgsl", source.into(), "main", false).unwrap();
        let zeroes_tally = |text: &str| text.lines().any(|line| line.trim_start().starts_with("tally = "));
        assert!(zeroes_tally(&glsl(&kernel, polyfilled()).unwrap().text), "the writer's zeroing is gone");
        let off = TranslateOptions { workgroup_zero_init: WorkgroupZeroInit::Off };
        assert!(!zeroes_tally(&glsl(&kernel, off).unwrap().text), "zeroed with zeroing off");
    }
}
