//! The texture corpus (`tests/data/textures/`, written here): every texture built-in the
//! backends support (`textureLoad`, `textureStore`, `textureDimensions`,
//! `textureNumLevels`, `textureNumLayers`, `textureSampleLevel`, `textureGather`), each
//! storage format, every shape (1-D, 2-D, 2-D array, 3-D), mip levels, out-of-range
//! loads and stores, read-write storage textures, a separable filter through workgroup
//! memory, and samplers of each filter and address mode: each case with its inputs, the
//! bound its float outputs are held to (and why), the paths that refuse it (and the
//! refusal they must give), and a rule of its own where WGSL allows several answers.
//! `cargo xtask check` prints its table; `tests/tests/textures.rs` asserts it and that a
//! corrupted output is caught.

use crate::BackendSlot;
use crate::agreement::{FloatBound, Judgement, Tolerance, judge};
use crate::corpus_rng::Rng;
use crate::run_kernel::{
    BackendRun, GroupedImages, GroupedInputs, ImageInput, OpenBackends, open_backends, run_on_open,
};
use strata_backends::{AddressMode, FilterMode, SamplerDesc, TextureDesc};
use strata_kernels::{Kernel, TexelFormat, TextureDimension};

/// A case's own rule on one backend's outputs: `Err` says what WGSL does not allow.
pub type CaseRule = fn(&TextureCase, &BackendRun) -> Result<(), String>;

/// One texture-corpus run.
pub struct TextureCase {
    /// The corpus file.
    pub file: &'static str,
    /// Its entry point.
    pub entry: &'static str,
    /// Name in messages and in the table (the file and what varies).
    pub name: String,
    /// Workgroups dispatched.
    pub workgroups: [u32; 3],
    /// Buffer contents by `(group, binding)`.
    pub buffers: GroupedInputs,
    /// Textures and samplers by `(group, binding)`.
    pub images: GroupedImages,
    /// Bounds for f32 words (integers and texels otherwise exact), each with why.
    pub bounds: Vec<(&'static str, FloatBound, &'static str)>,
    /// Paths that must refuse the kernel (a one-line "unavailable" naming why).
    pub refused_by: &'static [&'static str],
    /// A rule of the case's own on every run's outputs (what WGSL allows), if any.
    pub rule: Option<CaseRule>,
}

/// The WGSL of a corpus file (compiled in, so the check needs no folder beside it).
pub fn source(file: &str) -> &'static str {
    match file {
        "load.wgsl" => include_str!("../../tests/data/textures/load.wgsl"),
        "integer.wgsl" => include_str!("../../tests/data/textures/integer.wgsl"),
        "store.wgsl" => include_str!("../../tests/data/textures/store.wgsl"),
        "read_write.wgsl" => include_str!("../../tests/data/textures/read_write.wgsl"),
        "shapes.wgsl" => include_str!("../../tests/data/textures/shapes.wgsl"),
        "blur.wgsl" => include_str!("../../tests/data/textures/blur.wgsl"),
        "sample.wgsl" => include_str!("../../tests/data/textures/sample.wgsl"),
        "downsample.wgsl" => include_str!("../../tests/data/textures/downsample.wgsl"),
        "two_groups.wgsl" => include_str!("../../tests/data/textures/two_groups.wgsl"),
        "cross_group_sampler.wgsl" => include_str!("../../tests/data/textures/cross_group_sampler.wgsl"),
        other => panic!("{other} is not in the texture corpus"),
    }
}

/// Random bytes of one texel of `format`: any bytes for 8-bit and 32-bit integer
/// formats, floats in [lo, hi] for the float formats.
fn texel(format: TexelFormat, rng: &mut Rng, (lo, hi): (f32, f32)) -> Vec<u8> {
    let mut floats = |n: usize| -> Vec<f32> { (0..n).map(|_| rng.range(lo, hi)).collect() };
    match format {
        TexelFormat::Rgba8Unorm | TexelFormat::Rgba8Uint | TexelFormat::R32Uint | TexelFormat::R32Sint => {
            rng.next().to_le_bytes().to_vec()
        }
        TexelFormat::Rgba16Float => {
            floats(4).iter().flat_map(|&f| half::f16::from_f32(f).to_bits().to_le_bytes()).collect()
        }
        TexelFormat::Rgba32Float => floats(4).iter().flat_map(|f| f.to_le_bytes()).collect(),
        TexelFormat::R32Float => floats(1).iter().flat_map(|f| f.to_le_bytes()).collect(),
    }
}

/// A texture of random texels at every level (floats in `range`).
fn texture(
    dimension: TextureDimension,
    size: [u32; 3],
    mip_levels: u32,
    format: TexelFormat,
    seed: u64,
    range: (f32, f32),
) -> ImageInput {
    let desc =
        TextureDesc { label: format!("{}-{}", dimension.wgsl(), format.wgsl()), dimension, size, mip_levels, format };
    let mut rng = Rng(seed);
    let levels = (0..mip_levels)
        .map(|level| {
            let [w, h, d] = desc.level_size(level);
            (0..w * h * d).flat_map(|_| texel(format, &mut rng, range)).collect()
        })
        .collect();
    ImageInput::Texture { desc, levels }
}

/// A texture nobody writes before the kernel (a write-only storage texture).
fn blank(dimension: TextureDimension, size: [u32; 3], format: TexelFormat) -> ImageInput {
    let desc = TextureDesc {
        label: format!("{}-{}", dimension.wgsl(), format.wgsl()),
        dimension,
        size,
        mip_levels: 1,
        format,
    };
    ImageInput::Texture { desc, levels: Vec::new() }
}

fn bytes<T: bytemuck::NoUninit>(values: &[T]) -> Vec<u8> {
    bytemuck::cast_slice(values).to_vec()
}

/// Any two f32 words: for outputs judged by a rule of their own.
const ANY_ULP: FloatBound = FloatBound { ulp: u32::MAX, abs: 0.0 };

/// Why out-of-range loads are judged apart.
const OUTSIDE: &str = "WGSL lets an out-of-range textureLoad return any texel, (0, 0, 0, 0) or (0, 0, 0, 1): \
     judged by that rule (the interpreter and naga's checked SPIR-V give zeros; lavapipe's robustness gives \
     (0, 0, 0, 1) for one-component formats)";

/// Why a float read from an 8-bit unorm texel may be one ULP off.
const UNORM_READ: &str = "Vulkan defines the value as c / 255; lavapipe computes c * (1 / 255), one ULP away for \
     some c, where the interpreter rounds the division correctly";

/// The bound of a filtered value: a device quantises the bilinear weights to
/// `subTexelPrecisionBits` (Vulkan's minimum and lavapipe's: 8) and the blend between
/// levels to `mipmapPrecisionBits` (8 too); with texels in [0, 1] each of the three
/// blends can move the result by 2^-8, so 3 / 256 bounds the difference from the
/// interpreter's exact weights.
const FILTERED: FloatBound = FloatBound { ulp: 0, abs: 3.0 / 256.0 };

/// Every texel of `image` (each level) as the four floats a load returns (unorm as
/// c / 255, missing components 0 and alpha 1).
fn texel_values(image: &ImageInput) -> Vec<[f32; 4]> {
    let ImageInput::Texture { desc, levels } = image else { panic!("a texture") };
    let bytes = desc.format.bytes_per_texel() as usize;
    levels
        .iter()
        .flat_map(|level| level.chunks_exact(bytes))
        .map(|t| {
            let f = |i: usize| f32::from_le_bytes(t[4 * i..4 * i + 4].try_into().unwrap());
            let h = |i: usize| half::f16::from_le_bytes([t[2 * i], t[2 * i + 1]]).to_f32();
            match desc.format {
                TexelFormat::Rgba8Unorm => [0, 1, 2, 3].map(|i| f32::from(t[i]) / 255.0),
                TexelFormat::Rgba16Float => [h(0), h(1), h(2), h(3)],
                TexelFormat::Rgba32Float => [f(0), f(1), f(2), f(3)],
                TexelFormat::R32Float => [f(0), 0.0, 0.0, 1.0],
                other => panic!("{} is not a float format", other.wgsl()),
            }
        })
        .collect()
}

/// WGSL's rule for `outside` of load.wgsl: each out-of-range load is zero, (0, 0, 0, 1)
/// or a texel of the texture (within a ULP, as unorm reads are).
fn outside_rule(case: &TextureCase, run: &BackendRun) -> Result<(), String> {
    let Ok(outputs) = &run.outputs else { return Ok(()) };
    let allowed = texel_values(&case.images[0].1);
    let Some(outside) = outputs.iter().find(|o| o.name == "outside") else { return Ok(()) };
    let outside: &[f32] = bytemuck::cast_slice(&outside.bytes);
    for (index, value) in outside.chunks_exact(4).enumerate() {
        let close = |a: &[f32; 4]| a.iter().zip(value).all(|(x, y)| x.to_bits().abs_diff(y.to_bits()) <= 1);
        if ![[0.0; 4], [0.0, 0.0, 0.0, 1.0]].iter().chain(&allowed).any(close) {
            return Err(format!("read {value:?} out of range at slot {index}, which WGSL does not allow"));
        }
    }
    Ok(())
}

fn load_cases() -> Vec<TextureCase> {
    let (width, height, levels) = (16u32, 12u32, 3u32);
    let window = (width + 4, height + 4);
    [TexelFormat::Rgba8Unorm, TexelFormat::Rgba16Float, TexelFormat::Rgba32Float, TexelFormat::R32Float]
        .into_iter()
        .enumerate()
        .map(|(seed, format)| TextureCase {
            file: "load.wgsl",
            entry: "main",
            name: format!("load.wgsl on {}", format.wgsl()),
            workgroups: [window.0.div_ceil(8), window.1.div_ceil(8), levels + 1],
            buffers: vec![
                ((0, 1), vec![0; (window.0 * window.1 * (levels + 1) * 16) as usize]),
                ((0, 2), vec![0; (4 * (1 + 2 * levels)) as usize]),
                ((0, 3), vec![0; (window.0 * window.1 * (levels + 1) * 16) as usize]),
            ],
            images: vec![(
                (0, 0),
                texture(TextureDimension::D2, [width, height, 1], levels, format, seed as u64 + 1, (-4.0, 4.0)),
            )],
            bounds: if format == TexelFormat::Rgba8Unorm {
                vec![("texels", FloatBound { ulp: 1, abs: 0.0 }, UNORM_READ), ("outside", ANY_ULP, OUTSIDE)]
            } else {
                vec![("outside", ANY_ULP, OUTSIDE)]
            },
            refused_by: &[],
            rule: Some(outside_rule),
        })
        .collect()
}

fn integer_cases() -> Vec<TextureCase> {
    let (width, height) = (13u32, 9u32);
    let size = [width, height, 1];
    [TexelFormat::Rgba8Uint, TexelFormat::R32Uint]
        .into_iter()
        .enumerate()
        .map(|(seed, unsigned)| TextureCase {
            file: "integer.wgsl",
            entry: "main",
            name: format!("integer.wgsl on {} and r32sint", unsigned.wgsl()),
            workgroups: [width.div_ceil(8), height.div_ceil(8), 1],
            buffers: vec![
                ((0, 2), vec![0; (width * height * 16) as usize]),
                ((0, 3), vec![0; (width * height * 16) as usize]),
            ],
            images: vec![
                ((0, 0), texture(TextureDimension::D2, size, 1, unsigned, 10 + seed as u64, (0.0, 1.0))),
                ((0, 1), texture(TextureDimension::D2, size, 1, TexelFormat::R32Sint, 20 + seed as u64, (0.0, 1.0))),
            ],
            bounds: Vec::new(),
            refused_by: &[],
            rule: None,
        })
        .collect()
}

fn store_case() -> TextureCase {
    let (width, height) = (13u32, 9u32);
    let mut rng = Rng(3);
    let mut values: Vec<f32> = (0..width * height * 4).map(|_| rng.range(-0.5, 1.5)).collect();
    // Exact halfway cases of the unorm conversion (k + 0.5) / 255 and the ends.
    for (i, k) in (0..40).enumerate() {
        values[i] = (k as f32 * 6.0 + 0.5) / 255.0;
    }
    values[40..44].copy_from_slice(&[0.0, 1.0, -0.0, 1.0 + f32::EPSILON]);
    TextureCase {
        file: "store.wgsl",
        entry: "main",
        name: "store.wgsl".into(),
        workgroups: [width.div_ceil(8), height.div_ceil(8), 1],
        buffers: vec![((0, 7), bytes(&values))],
        images: TexelFormat::ALL
            .iter()
            .enumerate()
            .map(|(b, &f)| ((0, b as u32), blank(TextureDimension::D2, [width, height, 1], f)))
            .collect(),
        bounds: Vec::new(),
        refused_by: &["ash-slang"],
        rule: None,
    }
}

fn read_write_case() -> TextureCase {
    let (width, height) = (11u32, 7u32);
    let size = [width, height, 1];
    TextureCase {
        file: "read_write.wgsl",
        entry: "main",
        name: "read_write.wgsl".into(),
        workgroups: [width.div_ceil(8), height.div_ceil(8), 1],
        buffers: GroupedInputs::new(),
        images: vec![
            ((0, 0), texture(TextureDimension::D2, size, 1, TexelFormat::R32Uint, 4, (0.0, 1.0))),
            ((0, 1), texture(TextureDimension::D2, size, 1, TexelFormat::R32Float, 5, (-2.0, 2.0))),
            ((0, 2), texture(TextureDimension::D2, size, 1, TexelFormat::R32Float, 6, (-2.0, 2.0))),
        ],
        bounds: Vec::new(),
        refused_by: &["ash-slang"],
        rule: None,
    }
}

fn shapes_case() -> TextureCase {
    TextureCase {
        file: "shapes.wgsl",
        entry: "main",
        name: "shapes.wgsl".into(),
        workgroups: [1, 1, 4],
        buffers: vec![((0, 6), vec![0; 32])],
        images: vec![
            ((0, 0), texture(TextureDimension::D1, [8, 1, 1], 1, TexelFormat::R32Float, 7, (0.0, 4.0))),
            ((0, 1), texture(TextureDimension::D2Array, [8, 8, 4], 1, TexelFormat::Rgba16Float, 8, (-2.0, 2.0))),
            ((0, 2), texture(TextureDimension::D3, [8, 8, 4], 2, TexelFormat::Rgba32Float, 9, (-2.0, 2.0))),
            ((0, 3), blank(TextureDimension::D1, [8, 1, 1], TexelFormat::R32Uint)),
            ((0, 4), blank(TextureDimension::D2Array, [8, 8, 4], TexelFormat::Rgba32Float)),
            ((0, 5), blank(TextureDimension::D3, [8, 8, 4], TexelFormat::Rgba32Float)),
        ],
        bounds: Vec::new(),
        refused_by: &["wgpu-gl", "ash-slang"],
        rule: None,
    }
}

fn blur_cases() -> Vec<TextureCase> {
    let (width, height) = (100u32, 37u32);
    [("blur_x", [width.div_ceil(64), height, 1]), ("blur_y", [width, height.div_ceil(64), 1])]
        .into_iter()
        .map(|(entry, workgroups)| TextureCase {
            file: "blur.wgsl",
            entry,
            name: format!("blur.wgsl {entry}"),
            workgroups,
            buffers: GroupedInputs::new(),
            images: vec![
                ((0, 0), texture(TextureDimension::D2, [width, height, 1], 1, TexelFormat::Rgba8Unorm, 12, (0.0, 1.0))),
                ((0, 1), blank(TextureDimension::D2, [width, height, 1], TexelFormat::Rgba16Float)),
            ],
            bounds: Vec::new(),
            refused_by: &[],
            rule: None,
        })
        .collect()
}

fn sample_cases() -> Vec<TextureCase> {
    let (width, height, levels) = (16u32, 16u32, 3u32);
    let mut rng = Rng(21);
    let probes: Vec<f32> =
        (0..256).flat_map(|_| [rng.range(-0.6, 1.6), rng.range(-0.6, 1.6), rng.range(-0.5, 3.5), 0.0]).collect();
    let samplers = [
        ("nearest, clamp", SamplerDesc::uniform(FilterMode::Nearest, AddressMode::ClampToEdge)),
        ("linear, repeat", SamplerDesc::uniform(FilterMode::Linear, AddressMode::Repeat)),
        ("linear, mirror", SamplerDesc::uniform(FilterMode::Linear, AddressMode::MirrorRepeat)),
        (
            "linear magnification, nearest minification, mixed addressing",
            SamplerDesc {
                address: [AddressMode::MirrorRepeat, AddressMode::ClampToEdge, AddressMode::Repeat],
                mag_filter: FilterMode::Linear,
                min_filter: FilterMode::Nearest,
                mipmap_filter: FilterMode::Linear,
            },
        ),
    ];
    let mut cases = Vec::new();
    for format in [TexelFormat::Rgba8Unorm, TexelFormat::Rgba16Float] {
        for (seed, (what, sampler)) in samplers.iter().enumerate() {
            cases.push(TextureCase {
                file: "sample.wgsl",
                entry: "main",
                name: format!("sample.wgsl on {} with {what}", format.wgsl()),
                workgroups: [4, 1, 1],
                buffers: vec![((0, 2), bytes(&probes)), ((0, 3), vec![0; 256 * 3 * 16])],
                images: vec![
                    (
                        (0, 0),
                        texture(TextureDimension::D2, [width, height, 1], levels, format, 30 + seed as u64, (0.0, 1.0)),
                    ),
                    ((0, 1), ImageInput::Sampler(*sampler)),
                ],
                bounds: vec![(
                    "sampled",
                    FILTERED,
                    "weights quantised to 8 bits of sub-texel and mipmap precision by the device, exact in the \
                     interpreter",
                )],
                refused_by: &[],
                rule: None,
            });
        }
    }
    cases
}

fn two_groups_case() -> TextureCase {
    let (width, height) = (21u32, 13u32);
    let params: [u32; 2] = [0.75f32.to_bits(), 16];
    TextureCase {
        file: "two_groups.wgsl",
        entry: "main",
        name: "two_groups.wgsl (groups 0 and 2)".into(),
        workgroups: [width.div_ceil(8), height.div_ceil(8), 1],
        buffers: vec![((0, 1), bytes(&params))],
        images: vec![
            ((0, 0), texture(TextureDimension::D2, [width, height, 1], 1, TexelFormat::Rgba8Unorm, 40, (0.0, 1.0))),
            ((2, 0), blank(TextureDimension::D2, [width, height, 1], TexelFormat::Rgba8Unorm)),
        ],
        bounds: vec![(
            "result",
            FloatBound { ulp: 1, abs: 0.0 },
            "gain × c / 255 stored as unorm: lavapipe's c × (1/255) may round it to the next step",
        )],
        refused_by: &[],
        rule: None,
    }
}

fn cross_group_sampler_case() -> TextureCase {
    let (width, height) = (19u32, 11u32);
    TextureCase {
        file: "cross_group_sampler.wgsl",
        entry: "main",
        name: "cross_group_sampler.wgsl (sampler in group 0, image in group 1, r32float in group 2)".into(),
        workgroups: [width.div_ceil(8), height.div_ceil(8), 1],
        buffers: Vec::new(),
        images: vec![
            ((0, 0), ImageInput::Sampler(SamplerDesc::uniform(FilterMode::Linear, AddressMode::ClampToEdge))),
            ((1, 0), texture(TextureDimension::D2, [width, height, 1], 1, TexelFormat::Rgba8Unorm, 50, (0.0, 1.0))),
            ((1, 1), blank(TextureDimension::D2, [width, height, 1], TexelFormat::Rgba8Unorm)),
            ((2, 0), texture(TextureDimension::D2, [width, height, 1], 1, TexelFormat::R32Float, 51, (0.0, 1.0))),
        ],
        bounds: vec![(
            "result",
            FloatBound { ulp: 3, abs: 0.0 },
            "five linearly filtered taps (8-bit sub-texel weights on the device, exact in the interpreter) \
             averaged and stored as unorm: up to a few steps apart",
        )],
        refused_by: &[],
        rule: None,
    }
}

/// Every case of the corpus, in table order.
pub fn texture_cases() -> Vec<TextureCase> {
    let mut cases = load_cases();
    cases.extend(integer_cases());
    cases.push(store_case());
    cases.push(cross_group_sampler_case());
    cases.push(read_write_case());
    cases.push(shapes_case());
    cases.extend(blur_cases());
    cases.extend(sample_cases());
    cases.push(two_groups_case());
    cases
}

impl TextureCase {
    /// The tolerance its outputs are judged with.
    pub fn tolerance(&self) -> Tolerance {
        Tolerance {
            float: FloatBound::default(),
            per_buffer: self.bounds.iter().map(|(name, bound, _)| (name.to_string(), *bound)).collect(),
        }
    }

    /// Runs the case on `slots`.
    pub fn run(&self, slots: &[BackendSlot]) -> Vec<BackendRun> {
        self.run_on(&mut open_backends(slots))
    }

    /// Runs the case on backends already open.
    pub fn run_on(&self, backends: &mut OpenBackends) -> Vec<BackendRun> {
        match Kernel::from_wgsl(self.file, source(self.file).into(), self.entry, false) {
            Ok(kernel) => run_on_open(&kernel, &self.buffers, &self.images, self.workgroups, backends),
            Err(error) => backends
                .iter()
                .map(|(name, _)| BackendRun { backend: name.clone(), outputs: Err(error.to_string()) })
                .collect(),
        }
    }

    /// Per backend that ran or refused, one verdict against the interpreter: agrees
    /// (with how), refused as expected (with why), or fails (with why).
    pub fn verdicts(&self, runs: &[BackendRun]) -> Vec<(String, Verdict)> {
        let judgement: Judgement = match judge(runs, Some("cpu"), &self.tolerance()) {
            Ok(judgement) => judgement,
            Err(why) => return runs.iter().map(|r| (r.backend.clone(), Verdict::Fails(why.clone()))).collect(),
        };
        runs.iter()
            .map(|run| {
                let verdict = match &run.outputs {
                    // What the `webgpu` path refuses depends on the browser's adapter (its
                    // per-stage limits, SwiftShader's known bug): any refusal by name is
                    // taken from it, and the table lists it.
                    Err(why)
                        if (self.refused_by.contains(&run.backend.as_str()) || run.backend == "webgpu")
                            && why.contains("is unavailable") =>
                    {
                        Verdict::Refused(why.clone())
                    }
                    Err(why) => Verdict::Fails(why.clone()),
                    Ok(_) if self.refused_by.contains(&run.backend.as_str()) => {
                        Verdict::Fails("ran a kernel it is expected to refuse (update the refusal)".into())
                    }
                    Ok(_) => {
                        let buffers: Vec<_> = judgement.buffers.iter().filter(|b| b.backend == run.backend).collect();
                        let rule = self.rule.map_or(Ok(()), |rule| rule(self, run));
                        match (buffers.iter().find(|b| !b.passes()), rule) {
                            (Some(beyond), _) => Verdict::Fails(format!("`{}`: {}", beyond.name, beyond.describe())),
                            (None, Err(why)) => Verdict::Fails(why),
                            (None, Ok(())) if buffers.iter().all(|b| b.differing == 0) => Verdict::Identical,
                            (None, Ok(())) => Verdict::WithinBound,
                        }
                    }
                };
                (run.backend.clone(), verdict)
            })
            .collect()
    }
}

/// How one backend did on one case.
#[derive(Clone, Debug, PartialEq)]
pub enum Verdict {
    /// Every output bit-identical to the interpreter's.
    Identical,
    /// Every output within its declared bound (and the case's rule).
    WithinBound,
    /// Refused as the case expects, with the one-line reason.
    Refused(String),
    /// Failed, beyond a bound or against the rule.
    Fails(String),
}

impl Verdict {
    /// Whether it is what the corpus expects.
    pub fn passes(&self) -> bool {
        !matches!(self, Verdict::Fails(_))
    }
}

/// Every case's verdicts on every backend slot of the check (a slot that cannot open
/// counts as refusing every case, with its reason). The slots run in parallel, one
/// worker per core, each on its own device ([`crate::parallel`]); the verdicts come in
/// the slots' order.
pub fn run_texture_corpus() -> Vec<(String, Vec<(String, Verdict)>)> {
    run_texture_corpus_on(crate::backend_slots())
}

/// `slots` with the interpreter (`cpu`) first where it is missing: the corpus's outputs are
/// judged against its.
pub fn with_reference(mut slots: Vec<crate::BackendSlot>) -> Vec<crate::BackendSlot> {
    if !slots.iter().any(|slot| slot.name == "cpu") {
        slots.splice(0..0, crate::backend_slots().into_iter().filter(|slot| slot.name == "cpu"));
    }
    slots
}

/// [`run_texture_corpus`] on `slots` only (`run_kernel::named_slots`) and the interpreter
/// ([`with_reference`]).
pub fn run_texture_corpus_on(slots: Vec<crate::BackendSlot>) -> Vec<(String, Vec<(String, Verdict)>)> {
    let slots = with_reference(slots);
    let cases = texture_cases();
    // Per slot: its runs of every case, or why it did not open.
    let per_slot: Vec<Result<Vec<BackendRun>, String>> = crate::parallel::map(&slots, |slot| {
        let mut backends = open_backends(std::slice::from_ref(slot));
        if let Some((_, Err(why))) = backends.first() {
            return Err(why.clone());
        }
        Ok(cases.iter().flat_map(|case| case.run_on(&mut backends)).collect())
    });
    cases
        .iter()
        .enumerate()
        .map(|(index, case)| {
            let runs: Vec<BackendRun> =
                per_slot.iter().filter_map(|runs| runs.as_ref().ok().map(|runs| runs[index].clone())).collect();
            let mut verdicts = case.verdicts(&runs);
            verdicts.extend(slots.iter().zip(&per_slot).filter_map(|(slot, runs)| {
                runs.as_ref().err().map(|e| (slot.name.to_string(), Verdict::Refused(format!("no device: {e}"))))
            }));
            (case.name.clone(), verdicts)
        })
        .collect()
}

/// The corpus as a table (cases × backends), then one line per distinct refusal or
/// failure.
pub fn render_table(results: &[(String, Vec<(String, Verdict)>)]) -> String {
    // The backends the corpus ran on (every one has a verdict per case, a refusal at
    // least), in report order.
    let backends: Vec<String> = crate::backend_slots()
        .iter()
        .map(|s| s.name.to_string())
        .filter(|name| results.iter().any(|(_, verdicts)| verdicts.iter().any(|(b, _)| b == name)))
        .collect();
    let width = results.iter().map(|(name, _)| name.len()).max().unwrap_or(4).max(12);
    let mut text = format!("{:<width$}", "texture corpus");
    for backend in &backends {
        text += &format!(" {backend:<12}");
    }
    text += "\n";
    let mut notes: Vec<String> = Vec::new();
    for (name, verdicts) in results {
        text += &format!("{name:<width$}");
        for backend in &backends {
            let cell = match verdicts.iter().find(|(b, _)| b == backend).map(|(_, v)| v) {
                Some(Verdict::Identical) => "identical",
                Some(Verdict::WithinBound) => "within bound",
                Some(Verdict::Refused(why)) => {
                    let note = format!("unavailable on {backend}: {why}");
                    if !notes.contains(&note) {
                        notes.push(note);
                    }
                    "unavailable"
                }
                Some(Verdict::Fails(why)) => {
                    notes.push(format!("FAILS {name} on {backend}: {why}"));
                    "FAILS"
                }
                None => "-",
            };
            text += &format!(" {cell:<12}");
        }
        text += "\n";
    }
    for note in notes {
        text += &format!("  {}\n", note.replace('\n', " "));
    }
    text
}
