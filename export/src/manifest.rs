//! `manifest.json`: everything an engine needs to create the pass's pipelines and bind
//! its buffers without reading Rust, derived from naga's reflection of the kernels (the
//! registry), the pass's buffer plan (`strata_kernels::pass_plan::Stage::bindings`,
//! `PassBuffer::size_rule`) and the Rust twins of the structs: never written by hand.
//! Every field is documented here and, for readers of the package, in its README.

use crate::translations::{MSL_SIZES_BUFFER, Translated};
use serde::Serialize;
use strata_embed::wgsl::ModuleId;
use strata_kernels::layout::ShaderStruct;
use strata_kernels::pass_plan::{PassBuffer, SizeRule, Stage, Writer};
use strata_kernels::{BindingKind, Kernel};

/// The version of this manifest's layout: raised when a field changes meaning or goes
/// away (a field added keeps it).
pub const SCHEMA_VERSION: u32 = 1;

/// The whole manifest.
#[derive(Serialize)]
pub struct Manifest {
    /// [`SCHEMA_VERSION`].
    pub schema_version: u32,
    /// The strata version that wrote the package.
    pub strata_version: String,
    /// What the package is, in one line.
    pub description: String,
    /// The pass's kernels; a frame runs one histogram kernel, then `strata_select`, then
    /// (if the engine resamples with the pass) `strata_resample`.
    pub kernels: Vec<KernelEntry>,
    /// Every buffer the kernels bind: the engine's and the pass's own.
    pub buffers: Vec<BufferEntry>,
    /// The structs the buffers hold, with every field's offset (C layout = WGSL layout).
    pub structs: Vec<StructEntry>,
    /// The constants the kernels and the host share (object ids, slots, sampler ids).
    pub constants: Vec<ConstantEntry>,
    /// The sampler variants (`SelectionParams.sampler`).
    pub samplers: Vec<SamplerEntry>,
    /// The blue-noise tables' file and layout.
    pub blue_noise: BlueNoiseEntry,
    /// How a frame runs.
    pub frame: FrameEntry,
    /// The variables of the kernels' `dispatch` formulas, each with its definition.
    pub dispatch_variables: Vec<(&'static str, &'static str)>,
    /// Which histogram kernel to run where (all three give the same output), as
    /// `strata_kernels::KernelId::fastest_histogram` chooses for strata's own passes.
    pub choosing_the_histogram: Vec<&'static str>,
    /// What the device must offer for a `width` × `height` image, as the Rust passes check
    /// before they make anything (Vulkan's limit names).
    pub device_requirements: Vec<(&'static str, String)>,
}

/// [`Manifest::choosing_the_histogram`], the rule of `KernelId::fastest_histogram`.
pub const CHOOSING_THE_HISTOGRAM: [&str; 3] = [
    "a CPU driver (VK_PHYSICAL_DEVICE_TYPE_CPU, e.g. lavapipe) with B <= 16: block_histogram_rank",
    "otherwise, a device with subgroup basic and shuffle operations in compute: block_histogram_subgroup",
    "otherwise: block_histogram",
];

/// The variables the dispatch formulas use.
pub const DISPATCH_VARIABLES: [(&str, &str); 7] = [
    ("width, height", "the image's size in pixels"),
    ("B", "the block size (StrataSelectionSettings.block_size)"),
    ("shift_x, shift_y", "the frame's block-grid shift (strata_grid_shift; 0 without block shifting)"),
    ("blocks_x, blocks_y", "ceil((width + shift_x) / B), ceil((height + shift_y) / B)"),
    ("blocks_per_workgroup", "STRATA_HISTOGRAM_SLOTS_PER_WORKGROUP / (B * B)"),
    ("groups", "ceil(blocks_x * blocks_y / blocks_per_workgroup): the histogram's workgroups in all"),
    ("max_workgroups", "the device's smallest maxComputeWorkGroupCount component (at least 1)"),
];

/// One kernel.
#[derive(Serialize)]
pub struct KernelEntry {
    /// Its name (the file stem of its translations).
    pub name: String,
    /// `histogram`, `select` or `resample`.
    pub stage: &'static str,
    /// For a histogram kernel, how it sorts (all three give the same output).
    pub variant: Option<&'static str>,
    /// The entry point's name in each language.
    pub entry_point: PerLanguage<String>,
    /// The files, relative to the package.
    pub files: PerLanguage<String>,
    /// `@workgroup_size`.
    pub workgroup_size: [u32; 3],
    /// Workgroup memory the kernel uses, in bytes.
    pub workgroup_memory_bytes: u64,
    /// Device features beyond core Vulkan 1.1 / SM 6.0 / MSL 2.1 / GLSL 4.50: `subgroups`
    /// (Vulkan: subgroup basic and shuffle operations in compute shaders; HLSL: wave
    /// intrinsics; MSL: SIMD-group functions).
    pub required_features: Vec<&'static str>,
    /// Workgroups of its dispatch (x, y, z), as formulas of the variables of
    /// [`Manifest::dispatch_variables`] (`strata_frame_params` computes them).
    pub dispatch: [String; 3],
    /// The uniform it reads, by struct name.
    pub uniform: String,
    /// Its bindings, by binding number.
    pub bindings: Vec<BindingEntry>,
    /// The MSL array-sizes buffer: where naga's MSL reads each runtime-sized binding's
    /// size in bytes (one `uint` each, in the order of `msl.sized_bindings`).
    pub msl_sizes_buffer: MslSizes,
}

/// A value per language.
#[derive(Serialize)]
pub struct PerLanguage<T> {
    /// SPIR-V (Vulkan 1.1).
    pub spirv: T,
    /// HLSL (shader model 6.0).
    pub hlsl: T,
    /// MSL 2.1.
    pub msl: T,
    /// GLSL 4.50 for Vulkan.
    pub glsl: T,
    /// WGSL.
    pub wgsl: T,
}

/// One binding of a kernel.
#[derive(Serialize)]
pub struct BindingEntry {
    /// The WGSL variable's name.
    pub name: String,
    /// The buffer bound there ([`BufferEntry::name`]).
    pub buffer: &'static str,
    /// `uniform_buffer` or `storage_buffer`.
    pub descriptor_type: &'static str,
    /// `read` or `read_write` (a uniform is `read`).
    pub access: &'static str,
    /// Descriptor set (WGSL `@group`).
    pub set: u32,
    /// Binding (WGSL `@binding`).
    pub binding: u32,
    /// HLSL register (`b0`, `t1`, `u6`) and space.
    pub hlsl: HlslRegister,
    /// MSL `[[buffer(n)]]`.
    pub msl_buffer: u32,
    /// The element type (WGSL name; the struct is in `structs` unless a scalar).
    pub element: String,
    /// Bytes per element (the array stride).
    pub stride: u32,
    /// Whether the binding is a runtime-sized array.
    pub runtime_sized: bool,
}

/// An HLSL register.
#[derive(Serialize)]
pub struct HlslRegister {
    /// `b`, `t` or `u` and the number.
    pub register: String,
    /// The space.
    pub space: u32,
}

/// The MSL array-sizes buffer of one kernel.
#[derive(Serialize)]
pub struct MslSizes {
    /// Its `[[buffer(n)]]`.
    pub buffer: u32,
    /// The bindings whose sizes it holds, in order (one `uint` of bytes each).
    pub sized_bindings: Vec<String>,
}

/// One buffer.
#[derive(Serialize)]
pub struct BufferEntry {
    /// Its name.
    pub name: &'static str,
    /// `engine` (the engine creates and writes it), `pass` (the pass's own).
    pub owner: &'static str,
    /// Who writes it: `engine` (before the pass reads it), `host_every_frame` (the
    /// uniforms, from `strata_frame_params`), `host_once` (after creating it: the
    /// blue-noise tables), `pass` (a kernel).
    pub written_by: &'static str,
    /// Whether the engine may leave it out: `payloads` (then a pixel's payload is its
    /// index, `SelectionParams.identity_payload` is 1 and any storage buffer of at least 4
    /// bytes is bound in its place), and `resample_inputs` with `resampled` together (then
    /// `strata_resample` is not run).
    pub optional: bool,
    /// Its smallest size.
    pub size: SizeEntry,
}

/// A size rule.
#[derive(Serialize)]
pub struct SizeEntry {
    /// `fixed`, `per_pixel` or `per_block` (blocks of the largest grid any frame has:
    /// `strata_max_blocks`).
    pub rule: &'static str,
    /// Bytes (in all, per pixel or per block).
    pub bytes: u64,
    /// The same as a formula of `width`, `height` and `max_blocks`.
    pub formula: String,
}

/// A struct's layout.
#[derive(Serialize)]
pub struct StructEntry {
    /// Its WGSL name (`Strata` + it in `strata.h`).
    pub name: &'static str,
    /// Its size in bytes.
    pub size: usize,
    /// Its fields.
    pub fields: Vec<FieldEntry>,
}

/// A field.
#[derive(Serialize)]
pub struct FieldEntry {
    /// Its name.
    pub name: &'static str,
    /// Its byte offset.
    pub offset: usize,
    /// Its size in bytes.
    pub size: usize,
    /// Its WGSL type.
    pub wgsl_type: String,
}

/// A constant.
#[derive(Serialize)]
pub struct ConstantEntry {
    /// Its WGSL name.
    pub name: String,
    /// Its macro in `strata.h` (the sampler ids are `StrataSampler`'s values instead).
    pub c_name: String,
    /// `u32` or `f32`.
    pub wgsl_type: &'static str,
    /// Its value (an `f32` as the shortest decimal that reads back to its bits).
    pub value: serde_json::Value,
}

/// A sampler variant.
#[derive(Serialize)]
pub struct SamplerEntry {
    /// Its name.
    pub name: &'static str,
    /// Its id (`SelectionParams.sampler`).
    pub id: u32,
}

/// The blue-noise tables.
#[derive(Serialize)]
pub struct BlueNoiseEntry {
    /// The file, relative to the package: little-endian `u32` words, uploaded as they are
    /// to the `blue_noise` buffer once.
    pub file: String,
    /// Its size in bytes.
    pub bytes: u64,
    /// Word offsets of the three tables in it.
    pub sobol_offset: u32,
    /// Word offset of the scrambling table.
    pub scrambling_offset: u32,
    /// Word offset of the ranking table.
    pub ranking_offset: u32,
    /// Where the tables come from.
    pub origin: String,
}

/// One frame.
#[derive(Serialize)]
pub struct FrameEntry {
    /// The commands of one frame, in order.
    pub sequence: Vec<String>,
    /// The C functions that compute the uniforms and dispatch sizes.
    pub functions: String,
}

/// The stage's name.
fn stage_name(stage: Stage) -> &'static str {
    match stage {
        Stage::Histogram => "histogram",
        Stage::Select => "select",
        Stage::Resample => "resample",
    }
}

/// The buffer entry of `buffer`.
pub fn buffer_entry(buffer: PassBuffer) -> BufferEntry {
    let (rule, bytes, formula) = match buffer.size_rule() {
        SizeRule::Fixed(bytes) => ("fixed", bytes, bytes.to_string()),
        SizeRule::PerPixel(bytes) => ("per_pixel", bytes, format!("{bytes} * width * height")),
        SizeRule::PerBlock(bytes) => ("per_block", bytes, format!("{bytes} * max_blocks")),
    };
    BufferEntry {
        name: buffer.name(),
        owner: if buffer.engine_owned() { "engine" } else { "pass" },
        written_by: match buffer.writer() {
            Writer::Engine => "engine",
            Writer::HostEveryFrame => "host_every_frame",
            Writer::HostOnce => "host_once",
            Writer::Pass => "pass",
        },
        optional: matches!(buffer, PassBuffer::Payloads | PassBuffer::ResampleInputs | PassBuffer::Resampled),
        size: SizeEntry { rule, bytes, formula },
    }
}

/// The kernel entry of `module` translated as `translated`.
pub fn kernel_entry(module: ModuleId, kernel: &Kernel, translated: &Translated) -> KernelEntry {
    let name = kernel.name().to_string();
    let stage = Stage::of(module.kernel()).expect("every module is a stage of the pass");
    let bindings: Vec<BindingEntry> = kernel
        .bindings
        .iter()
        .map(|binding| {
            let buffer = stage
                .bindings()
                .iter()
                .find(|(wgsl, _)| *wgsl == binding.name)
                .map(|(_, buffer)| buffer.name())
                .expect("the pass plan names every binding (its test checks it)");
            let (_, register, space) = translated
                .hlsl_registers
                .iter()
                .find(|(wgsl, _, _)| *wgsl == binding.name)
                .cloned()
                .expect("every binding's register was found");
            BindingEntry {
                name: binding.name.clone(),
                buffer,
                descriptor_type: if binding.kind == BindingKind::Uniform { "uniform_buffer" } else { "storage_buffer" },
                access: if binding.is_writable() { "read_write" } else { "read" },
                set: binding.group,
                binding: binding.binding,
                hlsl: HlslRegister { register, space },
                msl_buffer: binding.binding,
                element: binding.element.type_name.clone(),
                stride: binding.element.stride,
                runtime_sized: binding.element.count.is_none(),
            }
        })
        .collect();
    let [x, y, _] = kernel.workgroup_size;
    let dispatch = match stage {
        Stage::Histogram => [
            "min(groups, max_workgroups)".to_string(),
            "ceil(groups / min(groups, max_workgroups))".to_string(),
            "1".to_string(),
        ],
        Stage::Select | Stage::Resample => [format!("ceil(width / {x})"), format!("ceil(height / {y})"), "1".into()],
    };
    let file = |folder: &str, extension: &str| format!("kernels/{folder}/{name}.{extension}");
    KernelEntry {
        stage: stage_name(stage),
        variant: match module {
            ModuleId::Histogram => Some("network"),
            ModuleId::HistogramSubgroup => Some("network_subgroup"),
            ModuleId::HistogramRank => Some("rank"),
            _ => None,
        },
        entry_point: PerLanguage {
            spirv: kernel.entry_point().to_string(),
            hlsl: translated.hlsl.entry_point.clone(),
            msl: translated.msl.entry_point.clone(),
            glsl: "main".into(),
            wgsl: kernel.entry_point().to_string(),
        },
        files: PerLanguage {
            spirv: file("spirv", "spv"),
            hlsl: file("hlsl", "hlsl"),
            msl: file("msl", "metal"),
            glsl: file("glsl", "comp"),
            wgsl: file("wgsl", "wgsl"),
        },
        workgroup_size: kernel.workgroup_size,
        workgroup_memory_bytes: kernel.workgroup_memory_bytes(),
        required_features: if kernel.spec.features.subgroup { vec!["subgroups"] } else { Vec::new() },
        dispatch,
        uniform: kernel
            .bindings
            .iter()
            .find(|b| b.kind == BindingKind::Uniform)
            .map(|b| b.element.type_name.clone())
            .unwrap_or_default(),
        msl_sizes_buffer: MslSizes { buffer: MSL_SIZES_BUFFER, sized_bindings: translated.msl_sized_bindings.clone() },
        bindings,
        name,
    }
}

/// The layout of `T` from its Rust twin, with each field's WGSL type from `kernel`'s IR.
pub fn struct_entry<T: ShaderStruct>(kernel: &Kernel) -> StructEntry {
    let module = &kernel.module;
    let wgsl_types: Vec<(String, String)> = module
        .types
        .iter()
        .find(|(_, ty)| ty.name.as_deref() == Some(T::WGSL_NAME))
        .map(|(_, ty)| match &ty.inner {
            naga::TypeInner::Struct { members, .. } => members
                .iter()
                .map(|m| (m.name.clone().unwrap_or_default(), strata_kernels::binding::type_name(module, m.ty)))
                .collect(),
            _ => Vec::new(),
        })
        .unwrap_or_default();
    StructEntry {
        name: T::WGSL_NAME,
        size: size_of::<T>(),
        fields: T::fields()
            .into_iter()
            .map(|field| FieldEntry {
                name: field.name,
                offset: field.offset,
                size: field.size,
                wgsl_type: wgsl_types.iter().find(|(n, _)| n == field.name).map(|(_, t)| t.clone()).unwrap_or_default(),
            })
            .collect(),
    }
}
