//! `manifest.json`: everything an engine needs to create the pass's pipelines and bind
//! its buffers without reading Rust, derived from naga's reflection of the kernels (the
//! registry), the pass's buffer plan (`strata_kernels::pass_plan::Stage::bindings`,
//! `PassBuffer::size_rule`) and the structs' single Rust declarations: never written by hand.
//! Every field is documented here and, for readers of the package, in its README.

use crate::translations::{MSL_SIZES_BUFFER, Translated};
use serde::Serialize;
use strata_embed::wgsl::ModuleId;
use strata_kernels::gpu::StructDeclaration;
use strata_kernels::pass_plan::{PassBuffer, SizeRule, Stage, Writer};
use strata_kernels::{BindingKind, Kernel};

/// The version of this manifest's layout: raised when a field changes meaning or goes
/// away (a field added keeps it).
pub const SCHEMA_VERSION: u32 = 2;

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
    /// The variables of the kernels' `dispatch` and the buffers' `size.expr`, in an order
    /// where each is defined before it is used: one per entry.
    pub variables: Vec<Variable>,
    /// Which histogram kernel to run on a device (all three give the same output), as
    /// `strata_kernels::KernelId::fastest_histogram` chooses for strata's own passes.
    pub histogram_choice: HistogramChoice,
    /// What the device must offer for a `width` × `height` image, as the Rust passes check
    /// before they make anything (Vulkan's limit names).
    pub device_requirements: Vec<(&'static str, String)>,
}

/// An integer expression over named variables, as JSON: a number, a variable's name, or
/// `{"op": OP, "args": [...]}` with OP one of `add`, `sub`, `mul` (of all the arguments),
/// `div` (floor of a / b), `ceil_div` (ceiling of a / b), `min`, `max` (of all the
/// arguments). Unsigned 64-bit arithmetic; no argument of `div` or `ceil_div` is 0.
#[derive(Serialize, Clone, Debug, PartialEq)]
#[serde(untagged)]
pub enum Expr {
    /// A whole number.
    Number(u64),
    /// A variable of [`Manifest::variables`].
    Variable(&'static str),
    /// An operation on its arguments.
    Operation {
        /// `add`, `sub`, `mul`, `div`, `ceil_div`, `min` or `max`.
        op: &'static str,
        /// Its arguments.
        args: Vec<Expr>,
    },
}

impl Expr {
    /// Its value with each variable's value from `value`; an error naming an unknown
    /// variable or operation, a division by 0 or an overflow.
    pub fn evaluate(&self, value: &dyn Fn(&str) -> Option<u64>) -> Result<u64, String> {
        match self {
            Expr::Number(n) => Ok(*n),
            Expr::Variable(name) => value(name).ok_or_else(|| format!("variable `{name}` has no value")),
            Expr::Operation { op, args } => {
                let args = args.iter().map(|a| a.evaluate(value)).collect::<Result<Vec<u64>, String>>()?;
                let overflow = || format!("`{op}` of {args:?} overflows");
                let pair = || match args.as_slice() {
                    [a, b] if *b != 0 => Ok((*a, *b)),
                    _ => Err(format!("`{op}` of {args:?}: two arguments, the second not 0")),
                };
                match *op {
                    "add" => args.iter().try_fold(0u64, |a, b| a.checked_add(*b)).ok_or_else(overflow),
                    "mul" => args.iter().try_fold(1u64, |a, b| a.checked_mul(*b)).ok_or_else(overflow),
                    "sub" => pair().and_then(|(a, b)| a.checked_sub(b).ok_or_else(overflow)),
                    "div" => pair().map(|(a, b)| a / b),
                    "ceil_div" => pair().map(|(a, b)| a.div_ceil(b)),
                    "min" => args.iter().copied().min().ok_or_else(|| "`min` of nothing".to_string()),
                    "max" => args.iter().copied().max().ok_or_else(|| "`max` of nothing".to_string()),
                    other => Err(format!("operation `{other}` is not one of add, sub, mul, div, ceil_div, min, max")),
                }
            }
        }
    }
}

/// A variable of the formulas: exactly one of `input`, `constant` and `expr` says where its
/// value comes from.
#[derive(Serialize)]
pub struct Variable {
    /// Its name, as the expressions use it.
    pub name: &'static str,
    /// What it is.
    pub meaning: &'static str,
    /// For a value the engine supplies: where it takes it from.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub input: Option<&'static str>,
    /// For a constant: its `name` in [`Manifest::constants`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub constant: Option<&'static str>,
    /// For a derived value: its expression over the variables listed before it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub expr: Option<Expr>,
}

/// A variable the engine supplies.
fn input(name: &'static str, meaning: &'static str, from: &'static str) -> Variable {
    Variable { name, meaning, input: Some(from), constant: None, expr: None }
}

/// A derived variable.
fn derived(name: &'static str, meaning: &'static str, expr: Expr) -> Variable {
    Variable { name, meaning, input: None, constant: None, expr: Some(expr) }
}

/// `op` of `args`.
fn op(op: &'static str, args: Vec<Expr>) -> Expr {
    Expr::Operation { op, args }
}

/// The variable `name`.
fn var(name: &'static str) -> Expr {
    Expr::Variable(name)
}

/// [`Manifest::variables`]: those of the dispatch formulas (`strata_kernels`'
/// `BlockGrid::histogram_workgroups`, `pass_plan::pixel_workgroups`) and of the per-block
/// sizes (`pass_plan::max_blocks`); `slots` is the name of the WGSL constant of the
/// histogram's slots per workgroup.
pub fn variables(slots: &'static str) -> Vec<Variable> {
    let padded = |extent: &'static str| op("add", vec![var(extent), var("max_shift")]);
    vec![
        input("width", "the image's width in pixels", "the engine's image (strata_vk_create's width)"),
        input("height", "the image's height in pixels", "the engine's image (strata_vk_create's height)"),
        input("B", "the block size", "StrataSelectionSettings.block_size"),
        input("block_shift", "1 with block shifting, else 0", "StrataSelectionSettings.block_shift"),
        input(
            "shift_x",
            "the frame's block-grid shift along x (0 without block shifting)",
            "strata_grid_shift(settings, frame_index, seed, &shift_x, &shift_y) of strata_frame.h",
        ),
        input(
            "shift_y",
            "the frame's block-grid shift along y (0 without block shifting)",
            "strata_grid_shift(settings, frame_index, seed, &shift_x, &shift_y) of strata_frame.h",
        ),
        input(
            "max_compute_work_group_count_x",
            "the device's limit",
            "VkPhysicalDeviceLimits.maxComputeWorkGroupCount[0]",
        ),
        input(
            "max_compute_work_group_count_y",
            "the device's limit",
            "VkPhysicalDeviceLimits.maxComputeWorkGroupCount[1]",
        ),
        input(
            "max_compute_work_group_count_z",
            "the device's limit",
            "VkPhysicalDeviceLimits.maxComputeWorkGroupCount[2]",
        ),
        Variable {
            name: "slots_per_workgroup",
            meaning: "pixels a histogram workgroup sorts",
            input: None,
            constant: Some(slots),
            expr: None,
        },
        derived("pixels", "pixels of the image", op("mul", vec![var("width"), var("height")])),
        derived(
            "blocks_x",
            "blocks per row of the frame's shifted grid",
            op("ceil_div", vec![op("add", vec![var("width"), var("shift_x")]), var("B")]),
        ),
        derived(
            "blocks_y",
            "block rows of the frame's shifted grid",
            op("ceil_div", vec![op("add", vec![var("height"), var("shift_y")]), var("B")]),
        ),
        derived(
            "blocks_per_workgroup",
            "whole blocks a histogram workgroup sorts",
            op("div", vec![var("slots_per_workgroup"), op("mul", vec![var("B"), var("B")])]),
        ),
        derived(
            "groups",
            "the histogram's workgroups in all",
            op("ceil_div", vec![op("mul", vec![var("blocks_x"), var("blocks_y")]), var("blocks_per_workgroup")]),
        ),
        derived(
            "max_workgroups",
            "workgroups per dimension of a dispatch: the device's smallest limit, at least 1",
            op(
                "max",
                vec![
                    Expr::Number(1),
                    op(
                        "min",
                        vec![
                            var("max_compute_work_group_count_x"),
                            var("max_compute_work_group_count_y"),
                            var("max_compute_work_group_count_z"),
                        ],
                    ),
                ],
            ),
        ),
        derived(
            "histogram_x",
            "the histogram's workgroups per row of its dispatch",
            op("min", vec![var("groups"), var("max_workgroups")]),
        ),
        derived(
            "max_shift",
            "the largest shift any frame has: B - 1 with block shifting, else 0",
            op("mul", vec![var("block_shift"), op("sub", vec![var("B"), Expr::Number(1)])]),
        ),
        derived(
            "max_blocks",
            "blocks of the largest grid any frame has (strata_max_blocks)",
            op(
                "mul",
                vec![op("ceil_div", vec![padded("width"), var("B")]), op("ceil_div", vec![padded("height"), var("B")])],
            ),
        ),
    ]
}

/// [`Manifest::histogram_choice`]: the inputs and the rules, first match wins.
#[derive(Serialize)]
pub struct HistogramChoice {
    /// What the rules test: each with where the engine reads it.
    pub inputs: Vec<ChoiceInput>,
    /// The rules in order: the first whose every condition holds names the kernel (the
    /// last has none).
    pub rules: Vec<ChoiceRule>,
}

/// An input of the histogram choice.
#[derive(Serialize)]
pub struct ChoiceInput {
    /// Its name.
    pub name: &'static str,
    /// `string`, `bool` or `integer`.
    #[serde(rename = "type")]
    pub kind: &'static str,
    /// Where the engine reads it.
    pub from: &'static str,
}

/// A rule of the histogram choice.
#[derive(Serialize)]
pub struct ChoiceRule {
    /// Conditions that must all hold.
    pub when: Vec<Condition>,
    /// The kernel's `name` in `kernels`.
    pub kernel: &'static str,
}

/// A condition on an input.
#[derive(Serialize)]
pub struct Condition {
    /// The input's name.
    pub input: &'static str,
    /// `equals` or `at_most`.
    pub test: &'static str,
    /// The value compared with.
    pub value: serde_json::Value,
}

/// The histogram choice of `KernelId::fastest_histogram` as rules (a test evaluates them
/// against it for every block size, subgroup support and device type).
pub fn histogram_choice() -> HistogramChoice {
    let condition = |input, test, value| Condition { input, test, value };
    HistogramChoice {
        inputs: vec![
            ChoiceInput {
                name: "device_type",
                kind: "string",
                from: "VkPhysicalDeviceProperties.deviceType, by its Vulkan name (VK_PHYSICAL_DEVICE_TYPE_CPU, ...)",
            },
            ChoiceInput {
                name: "subgroup_shuffles",
                kind: "bool",
                from: "VkPhysicalDeviceSubgroupProperties: supportedStages has VK_SHADER_STAGE_COMPUTE_BIT and supportedOperations has VK_SUBGROUP_FEATURE_BASIC_BIT and VK_SUBGROUP_FEATURE_SHUFFLE_BIT",
            },
            ChoiceInput { name: "B", kind: "integer", from: "StrataSelectionSettings.block_size" },
        ],
        rules: vec![
            ChoiceRule {
                when: vec![condition("device_type", "equals", "VK_PHYSICAL_DEVICE_TYPE_CPU".into())],
                kernel: "block_histogram_rank",
            },
            ChoiceRule {
                when: vec![condition("subgroup_shuffles", "equals", true.into())],
                kernel: "block_histogram_subgroup",
            },
            ChoiceRule { when: Vec::new(), kernel: "block_histogram" },
        ],
    }
}

impl HistogramChoice {
    /// The kernel the rules give for `inputs` (by name); an error naming an input without
    /// a value or an unknown test.
    pub fn choose(&self, inputs: &dyn Fn(&str) -> Option<serde_json::Value>) -> Result<&'static str, String> {
        for rule in &self.rules {
            let mut holds = true;
            for condition in &rule.when {
                let value =
                    inputs(condition.input).ok_or_else(|| format!("input `{}` has no value", condition.input))?;
                holds &= match condition.test {
                    "equals" => value == condition.value,
                    "at_most" => matches!((value.as_u64(), condition.value.as_u64()), (Some(a), Some(b)) if a <= b),
                    other => return Err(format!("test `{other}` is not equals or at_most")),
                };
            }
            if holds {
                return Ok(rule.kernel);
            }
        }
        Err("no rule holds".into())
    }
}

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
    /// Workgroups of its dispatch (x, y, z), as expressions of [`Manifest::variables`]
    /// (`strata_frame_params` computes the same).
    pub dispatch: [Expr; 3],
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
    /// The `VkBufferUsageFlagBits` it needs (the uniforms: `vkCmdUpdateBuffer` writes them,
    /// so `TRANSFER_DST`; the blue-noise tables: uploaded with a copy or through a mapping).
    pub vulkan_usage: Vec<&'static str>,
    /// The Vulkan limit its binding's offset must be a multiple of
    /// (`minUniformBufferOffsetAlignment`, `minStorageBufferOffsetAlignment`).
    pub offset_alignment: &'static str,
    /// `persistent` (its contents must survive from frame to frame: the blue-noise
    /// tables), or `per_frame` (written every frame before it is read).
    pub lifetime: &'static str,
    /// What it must hold before the first frame: `null` (nothing: every byte a kernel
    /// reads is written earlier in the same frame), or a file of the package.
    pub initial_contents: Option<&'static str>,
    /// When its contents are live within a frame, by `frame.sequence` step indices
    /// (first and last, inclusive); outside that range, and only there, its memory may
    /// alias other resources of the engine. Two bindings of one dispatch never alias.
    pub live_steps: [usize; 2],
}

/// A size rule.
#[derive(Serialize)]
pub struct SizeEntry {
    /// `fixed`, `per_pixel` or `per_block` (blocks of the largest grid any frame has:
    /// `strata_max_blocks`).
    pub rule: &'static str,
    /// Bytes (in all, per pixel or per block).
    pub bytes: u64,
    /// The same as a formula of `width`, `height` and `max_blocks`, for reading.
    pub formula: String,
    /// The same as an expression of [`Manifest::variables`].
    pub expr: Expr,
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
    /// Offset of the Sobol table in it, in 32-bit words (not bytes).
    pub sobol_word_offset: u32,
    /// Offset of the scrambling table, in 32-bit words.
    pub scrambling_word_offset: u32,
    /// Offset of the ranking table, in 32-bit words.
    pub ranking_word_offset: u32,
    /// Where the tables come from.
    pub origin: String,
}

/// One frame.
#[derive(Serialize)]
pub struct FrameEntry {
    /// The per-frame inputs besides the settings: the frame index and the seed.
    pub inputs: Vec<FrameInput>,
    /// The commands of one frame, in order (Vulkan's names for the barriers' flags).
    pub sequence: Vec<Step>,
    /// The C functions that compute the uniforms and dispatch sizes.
    pub functions: String,
}

/// A per-frame input.
#[derive(Serialize)]
pub struct FrameInput {
    /// Its name.
    pub name: &'static str,
    /// Where it goes (the argument of `strata_frame_params`, the field of the uniforms).
    pub passed_as: &'static str,
    /// What it is, and what goes wrong when it is misused.
    pub meaning: &'static str,
}

/// A command of the frame's sequence.
#[derive(Serialize)]
#[serde(tag = "op", rename_all = "snake_case")]
pub enum Step {
    /// The engine writes these buffers (with its own shader or transfer commands).
    EngineWrites {
        /// The buffers.
        buffers: Vec<&'static str>,
        /// Part of the optional resampling.
        optional: bool,
    },
    /// The engine reads these buffers.
    EngineReads {
        /// The buffers.
        buffers: Vec<&'static str>,
        /// Part of the optional resampling.
        optional: bool,
    },
    /// `vkCmdPipelineBarrier` with one `VkMemoryBarrier`.
    Barrier {
        /// `srcStageMask`.
        src_stages: Vec<&'static str>,
        /// `srcAccessMask`.
        src_access: Vec<&'static str>,
        /// `dstStageMask`.
        dst_stages: Vec<&'static str>,
        /// `dstAccessMask`.
        dst_access: Vec<&'static str>,
        /// Part of the optional resampling.
        optional: bool,
        /// What it orders.
        why: &'static str,
    },
    /// `vkCmdUpdateBuffer` of a uniform with a field of `StrataFrameParams`.
    UpdateUniform {
        /// The buffer.
        buffer: &'static str,
        /// The `StrataFrameParams` field written into it.
        value: &'static str,
        /// Part of the optional resampling.
        optional: bool,
    },
    /// The dispatch of the stage's kernel, with its `dispatch` expressions.
    Dispatch {
        /// `histogram` (the kernel `histogram_choice` gives), `select` or `resample`.
        stage: &'static str,
        /// Part of the optional resampling.
        optional: bool,
    },
}

/// A barrier step of `barrier`.
fn barrier_step(barrier: strata_embed::frame::VulkanBarrier, optional: bool, why: &'static str) -> Step {
    use strata_embed::frame::{VULKAN_ACCESS, VULKAN_STAGES, VulkanBarrier};
    Step::Barrier {
        src_stages: VulkanBarrier::names(barrier.src_stages, &VULKAN_STAGES),
        src_access: VulkanBarrier::names(barrier.src_access, &VULKAN_ACCESS),
        dst_stages: VulkanBarrier::names(barrier.dst_stages, &VULKAN_STAGES),
        dst_access: VulkanBarrier::names(barrier.dst_access, &VULKAN_ACCESS),
        optional,
        why,
    }
}

/// The frame's sequence: what strata-embed's ash flavour records
/// (`record_selection`, then `record_resampling`), with the same barriers
/// (`strata_embed::frame::VulkanBarrier`), and the engine's writes and reads around it.
pub fn sequence() -> Vec<Step> {
    use strata_embed::frame::VulkanBarrier;
    vec![
        Step::EngineWrites { buffers: vec!["candidates", "payloads"], optional: false },
        barrier_step(
            VulkanBarrier::BEFORE_PASS,
            false,
            "the engine's writes, and the previous frame's reads of the uniforms, before the updates",
        ),
        Step::UpdateUniform { buffer: "histogram_params", value: "histogram", optional: false },
        Step::UpdateUniform { buffer: "selection_params", value: "selection", optional: false },
        barrier_step(VulkanBarrier::AFTER_UPDATES, false, "the updates before the dispatches read the uniforms"),
        Step::Dispatch { stage: "histogram", optional: false },
        barrier_step(VulkanBarrier::AFTER_DISPATCH, false, "the histogram's writes before strata_select reads them"),
        Step::Dispatch { stage: "select", optional: false },
        barrier_step(VulkanBarrier::AFTER_DISPATCH, false, "strata_select's writes before the engine reads selections"),
        Step::EngineReads { buffers: vec!["selections"], optional: false },
        Step::EngineWrites { buffers: vec!["resample_inputs"], optional: true },
        barrier_step(
            VulkanBarrier::BEFORE_PASS,
            true,
            "the engine's resample_inputs before strata_resample reads them",
        ),
        Step::Dispatch { stage: "resample", optional: true },
        barrier_step(VulkanBarrier::AFTER_DISPATCH, true, "strata_resample's writes before the engine reads resampled"),
        Step::EngineReads { buffers: vec!["resampled"], optional: true },
    ]
}

/// The first and last step of [`sequence`] at which `buffer`'s contents are live.
fn live_steps(buffer: PassBuffer) -> [usize; 2] {
    let steps = sequence();
    let last = steps.len() - 1;
    let uses = |step: &Step| match step {
        Step::EngineWrites { buffers, .. } | Step::EngineReads { buffers, .. } => buffers.contains(&buffer.name()),
        Step::UpdateUniform { buffer: name, .. } => *name == buffer.name(),
        Step::Dispatch { stage, .. } => {
            Stage::ALL.iter().any(|s| stage_name(*s) == *stage && s.bindings().iter().any(|(_, b)| *b == buffer))
        }
        Step::Barrier { .. } => false,
    };
    match buffer {
        // Uploaded once, read by every frame.
        PassBuffer::BlueNoise => [0, last],
        _ => {
            let first = steps.iter().position(uses).unwrap_or(0);
            let final_use = steps.iter().rposition(uses).unwrap_or(last);
            [first, final_use]
        }
    }
}

/// [`FrameEntry::inputs`].
pub fn frame_inputs() -> Vec<FrameInput> {
    vec![
        FrameInput {
            name: "frame_index",
            passed_as: "strata_frame_params(..., frame, ...) -> StrataSelectionParams.frame; strata_vk_record_selection's frame",
            meaning: "the frame's number in the render, 0 for its first frame and one more for each frame after \
                      (never repeated, never skipped): it picks the frame's blue-noise sample (frame mod 256), is hashed \
                      into the white-noise numbers and, with block shifting, picks the frame's grid shift. Left at 0 (or repeated), every frame makes the first \
                      frame's selections again: no temporal stratification, and the same bias every frame",
        },
        FrameInput {
            name: "seed",
            passed_as: "strata_frame_params(..., seed, ...) -> StrataSelectionParams.seed; strata_vk_set_seed",
            meaning: "the render's seed: renders that must be independent (two views, two runs to average) need \
                      different seeds; one render keeps one seed for all its frames. It is hashed into every random \
                      number (the white noise, the blue noise's scrambling) and the grid shifts (0 is a valid seed)",
        },
    ]
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
        size: SizeEntry {
            rule,
            bytes,
            expr: match rule {
                "fixed" => Expr::Number(bytes),
                "per_pixel" => op("mul", vec![Expr::Number(bytes), var("pixels")]),
                _ => op("mul", vec![Expr::Number(bytes), var("max_blocks")]),
            },
            formula,
        },
        vulkan_usage: match buffer {
            PassBuffer::HistogramParams | PassBuffer::SelectionParams => {
                vec!["VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT", "VK_BUFFER_USAGE_TRANSFER_DST_BIT"]
            }
            PassBuffer::BlueNoise => vec!["VK_BUFFER_USAGE_STORAGE_BUFFER_BIT", "VK_BUFFER_USAGE_TRANSFER_DST_BIT"],
            _ => vec!["VK_BUFFER_USAGE_STORAGE_BUFFER_BIT"],
        },
        offset_alignment: match buffer {
            PassBuffer::HistogramParams | PassBuffer::SelectionParams => "minUniformBufferOffsetAlignment",
            _ => "minStorageBufferOffsetAlignment",
        },
        lifetime: if buffer == PassBuffer::BlueNoise { "persistent" } else { "per_frame" },
        initial_contents: (buffer == PassBuffer::BlueNoise).then_some("data/blue_noise.bin"),
        live_steps: live_steps(buffer),
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
        Stage::Histogram => {
            [var("histogram_x"), op("ceil_div", vec![var("groups"), var("histogram_x")]), Expr::Number(1)]
        }
        Stage::Select | Stage::Resample => [
            op("ceil_div", vec![var("width"), Expr::Number(u64::from(x))]),
            op("ceil_div", vec![var("height"), Expr::Number(u64::from(y))]),
            Expr::Number(1),
        ],
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

/// The layout of a declared struct: its Rust offsets and sizes (which a test of
/// strata-kernels holds equal to naga's layout of its WGSL) and its fields' WGSL types.
pub fn struct_entry(declaration: &StructDeclaration) -> StructEntry {
    StructEntry {
        name: declaration.name,
        size: declaration.size,
        fields: declaration
            .fields
            .iter()
            .map(|field| FieldEntry {
                name: field.name,
                offset: field.offset,
                size: field.size,
                wgsl_type: field.wgsl_type.to_string(),
            })
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use strata_kernels::pass_plan::{FrameId, frame_params, grid_shift, max_blocks};
    use strata_kernels::selection::{SamplerVariant, SelectionSettings};
    use strata_kernels::{Executor, KernelId};

    /// The variables' values for one frame, evaluated in their order.
    fn evaluate(variables: &[Variable], inputs: &[(&str, u64)]) -> Vec<(&'static str, u64)> {
        let mut known: Vec<(&'static str, u64)> = Vec::new();
        for variable in variables {
            let value = if let Some(expr) = &variable.expr {
                let lookup = |name: &str| known.iter().find(|(n, _)| *n == name).map(|(_, v)| *v);
                expr.evaluate(&lookup).unwrap_or_else(|e| panic!("{}: {e}", variable.name))
            } else if variable.constant.is_some() {
                u64::from(strata_kernels::types::HISTOGRAM_SLOTS_PER_WORKGROUP)
            } else {
                inputs.iter().find(|(n, _)| *n == variable.name).map(|(_, v)| *v).expect(variable.name)
            };
            known.push((variable.name, value));
        }
        known
    }

    /// The manifest's dispatch and size expressions give what the pass plan computes, for
    /// every block size, with and without block shifting, over image sizes that are and are
    /// not multiples of the block, frames with different shifts and small and large device
    /// limits.
    #[test]
    fn the_expressions_compute_what_the_pass_plan_does() {
        let registry = strata_kernels::Registry::shared().unwrap();
        let histogram = kernel_entry_dispatch(registry, ModuleId::Histogram);
        let select = kernel_entry_dispatch(registry, ModuleId::Select);
        let variables = variables("HISTOGRAM_SLOTS_PER_WORKGROUP");
        let mut cases = 0;
        for block_size in [4, 8, 16, 32] {
            for block_shift in [false, true] {
                for (width, height) in [(45, 29), (64, 64), (1920, 1080), (1, 1), (33, 700)] {
                    for (frame, limit) in [(0, 65_535), (3, 65_535), (5, 7), (9, 1)] {
                        let settings = SelectionSettings {
                            block_size,
                            block_shift,
                            candidates: 4,
                            sampler: SamplerVariant::Antithetic,
                            masking: true,
                        };
                        let id = FrameId { frame, seed: 11, identity_payload: false };
                        let want = frame_params(&settings, width, height, id, limit).unwrap();
                        let (shift_x, shift_y) = grid_shift(&settings, frame, 11);
                        let known = evaluate(
                            &variables,
                            &[
                                ("width", u64::from(width)),
                                ("height", u64::from(height)),
                                ("B", u64::from(block_size)),
                                ("block_shift", u64::from(block_shift)),
                                ("shift_x", u64::from(shift_x)),
                                ("shift_y", u64::from(shift_y)),
                                ("max_compute_work_group_count_x", 65_535),
                                ("max_compute_work_group_count_y", u64::from(limit)),
                                ("max_compute_work_group_count_z", 65_535),
                            ],
                        );
                        let lookup = |name: &str| known.iter().find(|(n, _)| *n == name).map(|(_, v)| *v);
                        let dispatch =
                            |exprs: &[Expr; 3]| exprs.each_ref().map(|e| e.evaluate(&lookup).unwrap() as u32);
                        let what = format!(
                            "B {block_size}, shift {block_shift}, {width}x{height}, frame {frame}, limit {limit}"
                        );
                        assert_eq!(dispatch(&histogram), want.histogram_workgroups, "{what}");
                        assert_eq!(dispatch(&select), want.pixel_workgroups, "{what}");
                        assert_eq!(lookup("max_blocks"), Some(max_blocks(&settings, width, height)), "{what}");
                        for buffer in PassBuffer::ALL {
                            let entry = buffer_entry(buffer);
                            let bytes = buffer.bytes(width, height, max_blocks(&settings, width, height));
                            assert_eq!(entry.size.expr.evaluate(&lookup), Ok(bytes), "{what}, {}", buffer.name());
                        }
                        cases += 1;
                    }
                }
            }
        }
        assert_eq!(cases, 4 * 2 * 5 * 4);
    }

    /// The dispatch expressions of `module`'s kernel entry.
    fn kernel_entry_dispatch(registry: &strata_kernels::Registry, module: ModuleId) -> [Expr; 3] {
        let kernel = registry.get(module.kernel());
        let translated = crate::translations::translate(kernel).unwrap();
        kernel_entry(module, kernel, &translated).dispatch
    }

    #[test]
    fn the_histogram_rules_choose_what_fastest_histogram_does() {
        let choice = histogram_choice();
        for block_size in [4u32, 8, 16, 32] {
            for subgroups in [false, true] {
                for (device_type, executor) in [
                    ("VK_PHYSICAL_DEVICE_TYPE_CPU", Executor::CpuDriver),
                    ("VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU", Executor::Gpu),
                    ("VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU", Executor::Gpu),
                    ("VK_PHYSICAL_DEVICE_TYPE_OTHER", Executor::Gpu),
                ] {
                    let inputs = |name: &str| match name {
                        "device_type" => Some(serde_json::Value::from(device_type)),
                        "subgroup_shuffles" => Some(subgroups.into()),
                        "B" => Some(block_size.into()),
                        _ => None,
                    };
                    let want = KernelId::fastest_histogram(block_size, subgroups, executor);
                    let got = choice.choose(&inputs).unwrap();
                    assert_eq!(
                        got,
                        strata_kernels::Registry::shared().unwrap().get(want).name(),
                        "{device_type}, B {block_size}, subgroups {subgroups}"
                    );
                }
            }
        }
    }

    /// What a step does to a buffer: its pipeline stage and access, and whether it writes.
    fn accesses(step: &Step) -> Vec<(&'static str, &'static str, &'static str, bool)> {
        let engine = |buffers: &[&'static str], write: bool| -> Vec<_> {
            let access = if write { "VK_ACCESS_SHADER_WRITE_BIT" } else { "VK_ACCESS_SHADER_READ_BIT" };
            buffers.iter().map(|b| (*b, "VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT", access, write)).collect()
        };
        match step {
            Step::EngineWrites { buffers, .. } => engine(buffers, true),
            Step::EngineReads { buffers, .. } => engine(buffers, false),
            Step::UpdateUniform { buffer, .. } => {
                vec![(*buffer, "VK_PIPELINE_STAGE_TRANSFER_BIT", "VK_ACCESS_TRANSFER_WRITE_BIT", true)]
            }
            Step::Dispatch { stage, .. } => {
                let stage = Stage::ALL.into_iter().find(|s| stage_name(*s) == *stage).unwrap();
                let registry = strata_kernels::Registry::shared().unwrap();
                let kernel = registry.get(match stage {
                    Stage::Histogram => KernelId::BlockHistogram,
                    Stage::Select => KernelId::StrataSelect,
                    Stage::Resample => KernelId::StrataResample,
                });
                let bindings = stage.bindings();
                kernel
                    .bindings
                    .iter()
                    .map(|binding| {
                        let buffer = bindings.iter().find(|(n, _)| *n == binding.name).unwrap().1.name();
                        let (access, write) = if binding.kind == BindingKind::Uniform {
                            ("VK_ACCESS_UNIFORM_READ_BIT", false)
                        } else if binding.is_writable() {
                            ("VK_ACCESS_SHADER_WRITE_BIT", true)
                        } else {
                            ("VK_ACCESS_SHADER_READ_BIT", false)
                        };
                        (buffer, "VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT", access, write)
                    })
                    .collect()
            }
            Step::Barrier { .. } => Vec::new(),
        }
    }

    /// The hazards of two frames' sequences recorded back to back, as the synchronisation
    /// validation layer sees them: two accesses of one buffer, one of them a write, with
    /// no barrier between them whose source stages cover the first and destination stages
    /// the second (and, after a write, whose access masks cover both).
    fn hazards(sequence: &[Step]) -> Vec<String> {
        let two_frames: Vec<&Step> = sequence.iter().chain(sequence).collect();
        let covers = |stages: &[&str], stage: &str| {
            stages.contains(&stage) || stages.contains(&"VK_PIPELINE_STAGE_ALL_COMMANDS_BIT")
        };
        let mut found = Vec::new();
        for (i, first) in two_frames.iter().enumerate() {
            for (buffer, stage, access, write) in accesses(first) {
                for (j, second) in two_frames.iter().enumerate().skip(i + 1) {
                    let Some((_, later_stage, later_access, later_write)) =
                        accesses(second).into_iter().find(|a| a.0 == buffer)
                    else {
                        continue;
                    };
                    if write || later_write {
                        let ordered = two_frames[i + 1..j].iter().any(|step| match step {
                            Step::Barrier { src_stages, src_access, dst_stages, dst_access, .. } => {
                                covers(src_stages, stage)
                                    && covers(dst_stages, later_stage)
                                    && (!write || (src_access.contains(&access) && dst_access.contains(&later_access)))
                            }
                            _ => false,
                        });
                        if !ordered {
                            found.push(format!("`{buffer}`: step {i} ({access}) then step {j} ({later_access})"));
                        }
                    }
                    break;
                }
            }
        }
        found
    }

    #[test]
    fn two_frames_of_the_sequence_have_no_hazard() {
        assert_eq!(hazards(&sequence()), Vec::<String>::new());
        // Without the barrier before the uniform updates, the engine's candidate writes
        // race the histogram's reads.
        let mut without: Vec<Step> = sequence();
        let first_barrier = without.iter().position(|s| matches!(s, Step::Barrier { .. })).unwrap();
        without.remove(first_barrier);
        let found = hazards(&without);
        assert!(found.iter().any(|h| h.starts_with("`candidates`: step 0")), "{found:?}");
        // With schema 1's barriers (none before the updates, compute to compute after each
        // dispatch), the previous frame's reads of the uniforms race vkCmdUpdateBuffer.
        for step in &mut without {
            if let Step::Barrier { src_stages, dst_stages, .. } = step
                && src_stages.as_slice() == ["VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT"]
            {
                dst_stages.retain(|s| *s == "VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT");
            }
        }
        let found = hazards(&without);
        assert!(
            found.iter().any(|h| h.contains("_params`") && h.contains("(VK_ACCESS_UNIFORM_READ_BIT) then")),
            "{found:?}"
        );
    }

    #[test]
    fn every_buffer_is_live_where_it_is_used_and_the_tables_persist() {
        for buffer in PassBuffer::ALL {
            let entry = buffer_entry(buffer);
            let [first, last] = entry.live_steps;
            assert!(first <= last && last < sequence().len(), "{}", buffer.name());
            assert_eq!(entry.lifetime == "persistent", entry.initial_contents.is_some(), "{}", buffer.name());
        }
        let sorted = buffer_entry(PassBuffer::SortedPixels).live_steps;
        assert!(matches!(sequence()[sorted[0]], Step::Dispatch { stage: "histogram", .. }));
        assert!(matches!(sequence()[sorted[1]], Step::Dispatch { stage: "select", .. }));
    }
}
