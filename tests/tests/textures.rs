//! Texture kernels on every path (`tests/data/textures/`, written here): every texture
//! built-in the backends support (`textureLoad`, `textureStore`, `textureDimensions`,
//! `textureNumLevels`, `textureNumLayers`, `textureSampleLevel`, `textureGather`), each
//! storage format, every shape (1-D, 2-D, 2-D array, 3-D), mip levels, out-of-range
//! loads and stores, read-write storage textures, a separable filter through workgroup
//! memory, and samplers of each filter and address mode. Each case runs through the
//! code of `cargo xtask run` and every output (storage buffers and storage textures) is
//! judged against the interpreter's: integer and 8/16-bit texel words bit for bit, f32
//! words within the case's declared bound, with the reason beside it; each case also
//! checks that a corrupted output is caught.

use strata_backends::{AddressMode, FilterMode, SamplerDesc, TextureDesc};
use strata_check::BackendSlot;
use strata_check::agreement::{FloatBound, Tolerance, judge};
use strata_check::run_kernel::{BackendRun, ImageInput, ImageInputs, Inputs, run_loaded_with_images};
use strata_kernels::{Kernel, TexelFormat, TextureDimension};
use strata_tests::corpus_support::{ONE_CASE_AT_A_TIME, assert_corruption_caught, available_slots, failures};

/// One texture-corpus run.
struct Case {
    file: &'static str,
    entry: &'static str,
    /// Name in messages (the file and what varies).
    name: String,
    workgroups: [u32; 3],
    buffers: Inputs,
    images: ImageInputs,
    /// Bounds for f32 words (integers and 8/16-bit texels are always exact), with why.
    bounds: Vec<(&'static str, FloatBound, &'static str)>,
    /// Backends that must refuse the kernel (a one-line "unavailable" naming why).
    refused_by: &'static [&'static str],
}

fn source(file: &str) -> String {
    let path = format!("{}/data/textures/{file}", env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"))
}

/// A small deterministic generator (LCG, high bits).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u32 {
        self.0 = self.0.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 32) as u32
    }

    fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * ((self.next() >> 8) as f32 / (1u32 << 24) as f32)
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

fn tolerance(case: &Case) -> Tolerance {
    Tolerance {
        float: FloatBound::default(),
        per_buffer: case.bounds.iter().map(|(name, bound, _)| (name.to_string(), *bound)).collect(),
    }
}

fn run_case(case: &Case, slots: &[BackendSlot]) -> Vec<BackendRun> {
    let _turn = ONE_CASE_AT_A_TIME.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    let kernel = Kernel::from_wgsl(case.file, source(case.file), case.entry, false)
        .unwrap_or_else(|e| panic!("{}: {e}", case.file));
    run_loaded_with_images(&kernel, &case.buffers, &case.images, case.workgroups, slots)
}

/// Runs the case everywhere, asserts every output within its bound against the
/// interpreter's, and that a corrupted output would be caught; returns the runs.
fn check(case: Case) -> Vec<BackendRun> {
    let slots = available_slots("the texture corpus");
    let runs = run_case(&case, &slots);
    let judgement = judge(&runs, Some("cpu"), &tolerance(&case)).unwrap_or_else(|e| panic!("{}: {e}", case.name));
    for buffer in &judgement.buffers {
        eprintln!("{} {:<12} `{}`: {}", case.name, buffer.backend, buffer.name, buffer.describe());
    }
    for (backend, why) in judgement.failed.iter().filter(|(backend, _)| case.refused_by.contains(&backend.as_str())) {
        assert!(why.contains("is unavailable"), "{}: {backend} must refuse with a reason, not fail: {why}", case.name);
        eprintln!("{} {backend:<12} refuses: {why}", case.name);
    }
    for backend in case.refused_by {
        let ran = runs.iter().any(|r| r.backend == *backend && r.outputs.is_ok());
        assert!(!ran, "{}: {backend} ran a kernel it is expected to refuse (update the refusal)", case.name);
    }
    let mut judgement = judgement;
    judgement.failed.retain(|(backend, _)| !case.refused_by.contains(&backend.as_str()));
    let failures = failures(&judgement);
    assert!(failures.is_empty(), "{}:\n{}", case.name, failures.join("\n"));
    assert_corruption_caught(&runs, &tolerance(&case), &case.name);
    runs
}

/// Any two f32 words: for outputs judged by a rule of their own.
const ANY_ULP: FloatBound = FloatBound { ulp: u32::MAX, abs: 0.0 };

/// Why out-of-range loads are judged apart.
const OUTSIDE: &str = "WGSL lets an out-of-range textureLoad return any texel, (0, 0, 0, 0) or (0, 0, 0, 1): \
     judged by that rule below (the interpreter and naga's checked SPIR-V give zeros; lavapipe's robustness gives \
     (0, 0, 0, 1) for one-component formats)";

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

/// Why a float read from an 8-bit unorm texel may be one ULP off.
const UNORM_READ: &str = "Vulkan defines the value as c / 255; lavapipe computes c * (1 / 255), one ULP away for \
     some c, where the interpreter rounds the division correctly";

#[test]
fn loads_sizes_and_levels_of_every_float_format_agree_in_and_out_of_range() {
    let (width, height, levels) = (16u32, 12u32, 3u32);
    let window = (width + 4, height + 4);
    for (seed, format) in
        [TexelFormat::Rgba8Unorm, TexelFormat::Rgba16Float, TexelFormat::Rgba32Float, TexelFormat::R32Float]
            .into_iter()
            .enumerate()
    {
        let image = texture(TextureDimension::D2, [width, height, 1], levels, format, seed as u64 + 1, (-4.0, 4.0));
        let runs = check(Case {
            file: "load.wgsl",
            entry: "main",
            name: format!("load.wgsl on {}", format.wgsl()),
            workgroups: [window.0.div_ceil(8), window.1.div_ceil(8), levels + 1],
            buffers: vec![
                (1, vec![0; (window.0 * window.1 * (levels + 1) * 16) as usize]),
                (2, vec![0; (4 * (1 + 2 * levels)) as usize]),
                (3, vec![0; (window.0 * window.1 * (levels + 1) * 16) as usize]),
            ],
            images: vec![(0, image)],
            bounds: if format == TexelFormat::Rgba8Unorm {
                vec![("texels", FloatBound { ulp: 1, abs: 0.0 }, UNORM_READ), ("outside", ANY_ULP, OUTSIDE)]
            } else {
                vec![("outside", ANY_ULP, OUTSIDE)]
            },
            refused_by: &[],
        });
        let allowed = texel_values(&texture(
            TextureDimension::D2,
            [width, height, 1],
            levels,
            format,
            seed as u64 + 1,
            (-4.0, 4.0),
        ));
        for run in &runs {
            let Ok(outputs) = &run.outputs else { continue };
            let outside: &[f32] = bytemuck::cast_slice(&outputs.iter().find(|o| o.name == "outside").unwrap().bytes);
            for (index, value) in outside.chunks_exact(4).enumerate() {
                let close = |a: &[f32; 4]| a.iter().zip(value).all(|(x, y)| x.to_bits().abs_diff(y.to_bits()) <= 1);
                assert!(
                    [[0.0; 4], [0.0, 0.0, 0.0, 1.0]].iter().chain(&allowed).any(close),
                    "load.wgsl on {}: {} read {value:?} out of range at slot {index}, which WGSL does not allow",
                    format.wgsl(),
                    run.backend
                );
            }
        }
    }
}

#[test]
fn integer_texels_load_bit_for_bit() {
    let (width, height) = (13u32, 9u32);
    for (seed, unsigned) in [TexelFormat::Rgba8Uint, TexelFormat::R32Uint].into_iter().enumerate() {
        check(Case {
            file: "integer.wgsl",
            entry: "main",
            name: format!("integer.wgsl on {} and r32sint", unsigned.wgsl()),
            workgroups: [width.div_ceil(8), height.div_ceil(8), 1],
            buffers: vec![(2, vec![0; (width * height * 16) as usize]), (3, vec![0; (width * height * 16) as usize])],
            images: vec![
                (0, texture(TextureDimension::D2, [width, height, 1], 1, unsigned, 10 + seed as u64, (0.0, 1.0))),
                (
                    1,
                    texture(
                        TextureDimension::D2,
                        [width, height, 1],
                        1,
                        TexelFormat::R32Sint,
                        20 + seed as u64,
                        (0.0, 1.0),
                    ),
                ),
            ],
            bounds: Vec::new(),
            refused_by: &[],
        });
    }
}

#[test]
fn stores_convert_to_every_storage_format_as_vulkan_defines() {
    let (width, height) = (13u32, 9u32);
    let mut rng = Rng(3);
    let mut values: Vec<f32> = (0..width * height * 4).map(|_| rng.range(-0.5, 1.5)).collect();
    // Exact halfway cases of the unorm conversion (k + 0.5) / 255 and the ends.
    for (i, k) in (0..40).enumerate() {
        values[i] = (k as f32 * 6.0 + 0.5) / 255.0;
    }
    values[40..44].copy_from_slice(&[0.0, 1.0, -0.0, 1.0 + f32::EPSILON]);
    let formats = [
        TexelFormat::Rgba8Unorm,
        TexelFormat::Rgba8Uint,
        TexelFormat::Rgba16Float,
        TexelFormat::Rgba32Float,
        TexelFormat::R32Float,
        TexelFormat::R32Uint,
        TexelFormat::R32Sint,
    ];
    check(Case {
        file: "store.wgsl",
        entry: "main",
        name: "store.wgsl".into(),
        workgroups: [width.div_ceil(8), height.div_ceil(8), 1],
        buffers: vec![(7, bytes(&values))],
        images: formats
            .iter()
            .enumerate()
            .map(|(b, &f)| (b as u32, blank(TextureDimension::D2, [width, height, 1], f)))
            .collect(),
        bounds: Vec::new(),
        refused_by: &["ash-slang"],
    });
}

#[test]
fn read_write_storage_textures_update_in_place_and_drop_out_of_range_stores() {
    let (width, height) = (11u32, 7u32);
    let size = [width, height, 1];
    check(Case {
        file: "read_write.wgsl",
        entry: "main",
        name: "read_write.wgsl".into(),
        workgroups: [width.div_ceil(8), height.div_ceil(8), 1],
        buffers: Vec::new(),
        images: vec![
            (0, texture(TextureDimension::D2, size, 1, TexelFormat::R32Uint, 4, (0.0, 1.0))),
            (1, texture(TextureDimension::D2, size, 1, TexelFormat::R32Float, 5, (-2.0, 2.0))),
            (2, texture(TextureDimension::D2, size, 1, TexelFormat::R32Float, 6, (-2.0, 2.0))),
        ],
        bounds: Vec::new(),
        refused_by: &["ash-slang"],
    });
}

#[test]
fn one_d_array_and_three_d_textures_load_store_and_count_alike() {
    check(Case {
        file: "shapes.wgsl",
        entry: "main",
        name: "shapes.wgsl".into(),
        workgroups: [1, 1, 4],
        buffers: vec![(6, vec![0; 32])],
        images: vec![
            (0, texture(TextureDimension::D1, [8, 1, 1], 1, TexelFormat::R32Float, 7, (0.0, 4.0))),
            (1, texture(TextureDimension::D2Array, [8, 8, 4], 1, TexelFormat::Rgba16Float, 8, (-2.0, 2.0))),
            (2, texture(TextureDimension::D3, [8, 8, 4], 2, TexelFormat::Rgba32Float, 9, (-2.0, 2.0))),
            (3, blank(TextureDimension::D1, [8, 1, 1], TexelFormat::R32Uint)),
            (4, blank(TextureDimension::D2Array, [8, 8, 4], TexelFormat::Rgba32Float)),
            (5, blank(TextureDimension::D3, [8, 8, 4], TexelFormat::Rgba32Float)),
        ],
        bounds: Vec::new(),
        refused_by: &["wgpu-gl", "ash-slang"],
    });
}

#[test]
fn a_separable_blur_through_workgroup_memory_agrees_bit_for_bit() {
    let (width, height) = (100u32, 37u32);
    for (entry, workgroups) in
        [("blur_x", [width.div_ceil(64), height, 1]), ("blur_y", [width, height.div_ceil(64), 1])]
    {
        check(Case {
            file: "blur.wgsl",
            entry,
            name: format!("blur.wgsl {entry}"),
            workgroups,
            buffers: Vec::new(),
            images: vec![
                (0, texture(TextureDimension::D2, [width, height, 1], 1, TexelFormat::Rgba8Unorm, 12, (0.0, 1.0))),
                (1, blank(TextureDimension::D2, [width, height, 1], TexelFormat::Rgba16Float)),
            ],
            bounds: Vec::new(),
            refused_by: &[],
        });
    }
}

/// The bound of a filtered value: a device quantises the bilinear weights to
/// `subTexelPrecisionBits` (Vulkan's minimum and lavapipe's: 8) and the blend between
/// levels to `mipmapPrecisionBits` (8 too); with texels in [0, 1] each of the three
/// blends can move the result by 2^-8, so 3 / 256 bounds the difference from the
/// interpreter's exact weights.
const FILTERED: FloatBound = FloatBound { ulp: 0, abs: 3.0 / 256.0 };

#[test]
fn sampling_and_gathering_agree_within_the_filtering_precision_for_every_sampler() {
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
    for format in [TexelFormat::Rgba8Unorm, TexelFormat::Rgba16Float] {
        for (seed, (what, sampler)) in samplers.iter().enumerate() {
            check(Case {
                file: "sample.wgsl",
                entry: "main",
                name: format!("sample.wgsl on {} with {what}", format.wgsl()),
                workgroups: [4, 1, 1],
                buffers: vec![(2, bytes(&probes)), (3, vec![0; 256 * 3 * 16])],
                images: vec![
                    (
                        0,
                        texture(TextureDimension::D2, [width, height, 1], levels, format, 30 + seed as u64, (0.0, 1.0)),
                    ),
                    (1, ImageInput::Sampler(*sampler)),
                ],
                bounds: vec![(
                    "sampled",
                    FILTERED,
                    "weights quantised to 8 bits of sub-texel and mipmap precision by the device, exact in the \
                     interpreter",
                )],
                refused_by: &["ash-hlsl", "ash-slang"],
            });
        }
    }
}
