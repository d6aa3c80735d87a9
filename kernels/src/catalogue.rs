//! The catalogue of kernels strata ships: each kernel's name, WGSL fragments (composed in
//! order), entry point, device features and cross-backend float tolerance. The
//! [`crate::registry`] parses and validates what this declares.

use crate::source::Fragment;
use naga::valid::Capabilities;
use std::borrow::Cow;

/// Names a registry kernel.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum KernelId {
    /// Per-block histogram: candidates clustered by object id and sorted by key
    /// (paper §4.1, §4.3), without subgroup operations.
    BlockHistogram,
    /// The same pass exchanging elements between subgroup lanes (needs subgroups).
    BlockHistogramSubgroup,
    /// The same pass (same outputs) by ranking: each element's position counted over its
    /// block instead of a sorting network; no subgroup operations.
    BlockHistogramRank,
    /// Does nothing: measures dispatch overhead.
    Empty,
    /// Closest hit of a batch of rays through obvhs' BVH2, watertight triangle test.
    BvhClosestHit,
    /// Primary rays of the pinhole camera, one per pixel, optionally jittered.
    CameraRays,
    /// Progressive path tracing: one sample per pixel added to a running sum (NEE + MIS,
    /// area and environment lights, diffuse, GGX conductor, dielectric).
    PathTrace,
    /// ReSTIR pass 1: G-buffer, each pixel's own estimate and its path candidate.
    RestirCandidates,
    /// ReSTIR pass 3: selection of K candidates (strata, restir or restir-disc) and
    /// resampling with the pixel's canonical candidate.
    RestirSelect,
    /// ReSTIR pass 4a: temporal sources (reprojection, disocclusion) and the temporal
    /// histogram's input.
    RestirTemporalKeys,
    /// ReSTIR pass 4b: temporal reuse (M cap, one or several previous reservoirs).
    RestirTemporal,
    /// ReSTIR pass 4c (temporal-first order): the block histogram's input from the
    /// merged reservoirs (key p̂ W, object id).
    RestirReservoirKeys,
    /// ReSTIR pass 4d (temporal-first order): spatial reuse of the merged reservoirs,
    /// K of them per pixel (strata, restir or restir-disc) under pairwise MIS with
    /// confidence weights.
    RestirSpatial,
    /// ReSTIR pass 5: shading of the reservoirs' samples with one shadow ray.
    RestirShade,
    /// ReSTIR pass 6 (with a denoiser): the denoiser's guide (albedo, depth, normal,
    /// object, motion) from the G-buffer.
    RestirGuide,
    /// SVGF pass 1 (Schied et al. 2017, §4.1): temporal accumulation of the demodulated
    /// colour and of its luminance moments through the motion vectors.
    SvgfTemporal,
    /// SVGF pass 2 (§4.2): per-pixel luminance variance, spatial for short histories.
    SvgfVariance,
    /// SVGF pass 3 (§4.3): one level of the edge-avoiding à-trous wavelet filter.
    SvgfAtrous,
    /// SVGF pass 4: the filtered illumination times the albedo again.
    SvgfModulate,
    /// Embedding: K payload indices per pixel from its cluster's run at the stratified
    /// positions of the chosen sampler variant (paper §4.2, Fig. 3, Table 2).
    StrataSelect,
    /// Embedding: inverse-CDF resampling of the engine's weights (paper §4.2).
    StrataResample,
    /// A kernel from outside the registry ([`Kernel::from_wgsl`](crate::Kernel::from_wgsl)), keyed by a hash of its
    /// source and entry point so that backends can cache its pipeline.
    External(u64),
}

/// What runs the kernels, for the choices that depend on it
/// ([`KernelId::fastest_histogram`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum Executor {
    /// A GPU: warps or wavefronts of lanes that issue one instruction together and wait
    /// on memory far longer than on arithmetic.
    Gpu,
    /// A Vulkan or GL driver on the CPU (lavapipe, llvmpipe, SwiftShader): a workgroup's
    /// invocations side by side in SIMD lanes, with slow barriers.
    CpuDriver,
    /// strata's CPU interpreter of naga IR, which runs a workgroup's invocations one
    /// after another for each instruction.
    Interpreter,
}

impl Executor {
    /// The executor of a device of this type (`DeviceInfo::device_type`: the `Debug`
    /// name of `wgpu::DeviceType` or `ash::vk::PhysicalDeviceType`, e.g. `Cpu`, `CPU`,
    /// `DiscreteGpu`, `INTEGRATED_GPU`), or of strata's interpreter. Only a device that
    /// says it is a CPU counts as a CPU driver: a software renderer its driver reports as
    /// `Other` gets the GPU's choice (every choice gives the same output).
    pub fn of_device(device_type: &str, interpreter: bool) -> Executor {
        if interpreter {
            Executor::Interpreter
        } else if device_type.eq_ignore_ascii_case("cpu") {
            Executor::CpuDriver
        } else {
            Executor::Gpu
        }
    }
}

impl KernelId {
    /// Every registry kernel.
    pub const ALL: [KernelId; 21] = [
        KernelId::BlockHistogram,
        KernelId::BlockHistogramSubgroup,
        KernelId::BlockHistogramRank,
        KernelId::Empty,
        KernelId::BvhClosestHit,
        KernelId::CameraRays,
        KernelId::PathTrace,
        KernelId::RestirCandidates,
        KernelId::RestirSelect,
        KernelId::RestirTemporalKeys,
        KernelId::RestirTemporal,
        KernelId::RestirReservoirKeys,
        KernelId::RestirSpatial,
        KernelId::RestirShade,
        KernelId::RestirGuide,
        KernelId::SvgfTemporal,
        KernelId::SvgfVariance,
        KernelId::SvgfAtrous,
        KernelId::SvgfModulate,
        KernelId::StrataSelect,
        KernelId::StrataResample,
    ];

    /// The fastest block-histogram kernel for `block_size` on `executor`, with or without
    /// subgroup shuffles (all three give the same output). On a GPU the sorting network,
    /// with subgroup shuffles where the device has them: on an H200 at B = 16 and 1M
    /// candidates it takes 97.6 µs with shuffles and 150.7 µs without, ranking 248.7 µs,
    /// since ranking compares every candidate with all B² slots of its block and the
    /// network runs 36 compare-exchange stages; the SIMT issue-slot model agrees at every
    /// B (ranking ties the network at B = 4 and costs 1.4× and 3.1× its slots at B = 8 and
    /// 16). On a CPU driver (lavapipe), whose barriers are slow, ranking at every block
    /// size (at 32 × 32 since its counting loop became one loop over the block: 67 ms
    /// against the subgroup network's 97 ms and the portable one's 127 ms at 1M
    /// candidates). On strata's interpreter, which pays every
    /// comparison lane by lane, the network at every block size (ranking ties it at B = 4
    /// and is 1.1×, 1.6× and 3.5× slower at B = 8, 16, 32). BENCHMARKS.md, block_sort,
    /// render and interpreter. The one home of this choice: the renderer's
    /// `HistogramVariant::Auto` and the embed pass both call it.
    ///
    /// `block_size` stays an input of the choice (and of the C package's rules) although
    /// no executor's answer depends on it now: each executor's winner is the same at every
    /// measured block size, and a device that measures otherwise changes this body, not
    /// every caller.
    pub fn fastest_histogram(block_size: u32, subgroups: bool, executor: Executor) -> KernelId {
        let _same_winner_at_every_block_size = block_size;
        if executor == Executor::CpuDriver {
            KernelId::BlockHistogramRank
        } else if subgroups {
            KernelId::BlockHistogramSubgroup
        } else {
            KernelId::BlockHistogram
        }
    }

    /// What the registry knows of this kernel before parsing it.
    pub fn spec(self) -> Option<KernelSpec> {
        // A kernel's WGSL: its entry file and what that imports (`crate::wgsl_imports`).
        // The files are the crate's own, embedded at compile time, and every kernel is
        // built by the tests, so an unknown import or a circle is a bug found there.
        let entry = |path: &str| {
            crate::wgsl_imports::kernel_fragments(path, &crate::wgsl_files::wgsl_file)
                .unwrap_or_else(|error| panic!("{error}"))
        };
        // A ReSTIR pass: its entry file `restir/{entry}.wgsl` and what that imports.
        let restir = |name: &'static str, entry_file: &str| KernelSpec {
            name: name.into(),
            fragments: entry(&format!("restir/{entry_file}.wgsl")),
            entry_point: name.into(),
            features: KernelFeatures::empty(),
            // Checked pass by pass on identical inputs (the interpreter's, recorded):
            // integers are bit-exact everywhere; f32 values differ because llvmpipe fuses
            // multiply-adds the interpreter rounds twice (ray-triangle hits, up to ~2400
            // ULP of a candidate's weight on the all-diffuse scene) and because an
            // environment lookup turns a direction into a texel through atan2/acos,
            // which Vulkan allows 4096 ULP: the radiance it reads then moves with the
            // map's gradient (up to ~8500 ULP, 5e-4 relative, in the glass, metal and
            // environment room at 128²). 16384 ULP is 2e-3 relative.
            float_ulp_bound: Some(16384),
        };
        // An SVGF pass: its entry file `denoise/{entry}.wgsl` and what that imports.
        let svgf = |name: &'static str, entry_file: &str| KernelSpec {
            name: name.into(),
            fragments: entry(&format!("denoise/{entry_file}.wgsl")),
            entry_point: name.into(),
            features: KernelFeatures::empty(),
            // Checked against the Rust reference (reference/svgf.rs) on generated
            // guides: at most 12 ULP on llvmpipe, every path, 80 cases (exp(), whose
            // rounding the weighted sums carry). A GPU's exp() may be off by 3 + 2|x|
            // ULP (43 at x = 20, where a weight is already below 1e-8), sqrt and
            // divisions by a few, and products may be fused into multiply-adds: 256
            // ULP, 3e-5 relative.
            float_ulp_bound: Some(256),
        };
        Some(match self {
            KernelId::BlockHistogram => KernelSpec {
                name: "block_histogram".into(),
                fragments: entry("strata/entry_histogram.wgsl"),
                entry_point: "block_histogram".into(),
                features: KernelFeatures::empty(),
                float_ulp_bound: None,
            },
            KernelId::BlockHistogramSubgroup => KernelSpec {
                name: "block_histogram_subgroup".into(),
                fragments: entry("strata/entry_histogram_subgroup.wgsl"),
                entry_point: "block_histogram_subgroup".into(),
                features: KernelFeatures::SUBGROUP,
                float_ulp_bound: None,
            },
            KernelId::BlockHistogramRank => KernelSpec {
                name: "block_histogram_rank".into(),
                fragments: entry("strata/entry_histogram_rank.wgsl"),
                entry_point: "block_histogram_rank".into(),
                features: KernelFeatures::empty(),
                float_ulp_bound: None,
            },
            KernelId::Empty => KernelSpec {
                name: "empty".into(),
                fragments: entry("util/empty.wgsl"),
                entry_point: "empty".into(),
                features: KernelFeatures::empty(),
                float_ulp_bound: None,
            },
            KernelId::BvhClosestHit => KernelSpec {
                name: "bvh_closest_hit".into(),
                fragments: entry("trace/entry_closest_hit.wgsl"),
                entry_point: "bvh_closest_hit".into(),
                features: KernelFeatures::empty(),
                // Backends may contract products into fused multiply-adds; hits that change
                // triangle at near-ties are counted separately (see the check).
                float_ulp_bound: Some(8),
            },
            KernelId::CameraRays => KernelSpec {
                name: "camera_rays".into(),
                fragments: entry("trace/camera_rays.wgsl"),
                entry_point: "camera_rays_main".into(),
                features: KernelFeatures::empty(),
                // normalize() and the divisions may round differently (inverse square
                // root, reciprocals, fused multiply-adds).
                float_ulp_bound: Some(16),
            },
            KernelId::PathTrace => KernelSpec {
                name: "path_trace".into(),
                fragments: entry("render/entry_path_trace.wgsl"),
                entry_point: "path_trace".into(),
                features: KernelFeatures::empty(),
                // Paths branch on float comparisons: a one-ULP difference can send a
                // path elsewhere, so pixels are compared with a bound and a share of
                // outliers (check/src/path.rs). The bound is the ReSTIR passes' (see
                // `restir` above): an environment lookup's atan2/acos (4096 ULP in
                // Vulkan) moves the radiance it reads with the map's gradient, by up to
                // ~4300 ULP on identical inputs.
                float_ulp_bound: Some(16384),
            },
            KernelId::RestirCandidates => restir("restir_candidates", "entry_candidates"),
            KernelId::RestirSelect => restir("restir_select", "entry_select"),
            KernelId::RestirTemporalKeys => restir("restir_temporal_keys", "entry_temporal_keys"),
            KernelId::RestirTemporal => restir("restir_temporal", "entry_temporal"),
            KernelId::RestirReservoirKeys => restir("restir_reservoir_keys", "entry_reservoir_keys"),
            KernelId::RestirSpatial => restir("restir_spatial", "entry_spatial"),
            KernelId::RestirShade => restir("restir_shade", "entry_shade"),
            KernelId::RestirGuide => restir("restir_guide", "entry_guide"),
            KernelId::SvgfTemporal => svgf("svgf_temporal", "entry_temporal"),
            KernelId::SvgfVariance => svgf("svgf_variance", "entry_variance"),
            KernelId::SvgfAtrous => svgf("svgf_atrous", "entry_atrous"),
            KernelId::SvgfModulate => svgf("svgf_modulate", "entry_modulate"),
            KernelId::StrataSelect => KernelSpec {
                name: "strata_select".into(),
                fragments: entry("embed/entry_select.wgsl"),
                entry_point: "strata_select".into(),
                features: KernelFeatures::empty(),
                // Payload indices are integers; the resampling number is the one float
                // output (divisions and fract: a few ULP).
                float_ulp_bound: Some(4),
            },
            KernelId::StrataResample => KernelSpec {
                name: "strata_resample".into(),
                fragments: entry("embed/entry_resample.wgsl"),
                entry_point: "strata_resample".into(),
                features: KernelFeatures::empty(),
                // W = sum / target: one division after K + 1 additions.
                float_ulp_bound: Some(4),
            },
            KernelId::External(_) => return None,
        })
    }
}

/// Optional device features a kernel needs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct KernelFeatures {
    /// Subgroup operations in compute shaders.
    pub subgroup: bool,
}

impl KernelFeatures {
    /// Nothing beyond core WebGPU.
    pub const fn empty() -> Self {
        Self { subgroup: false }
    }
    /// Subgroup operations.
    pub const SUBGROUP: Self = Self { subgroup: true };

    /// naga's validator capabilities for these features.
    pub(crate) fn capabilities(self) -> Capabilities {
        if self.subgroup { Capabilities::SUBGROUP | Capabilities::SUBGROUP_BARRIER } else { Capabilities::empty() }
    }
}

/// A kernel as declared in the registry.
#[derive(Clone, Debug)]
pub struct KernelSpec {
    /// Registry name (also the name of translated files).
    pub name: Cow<'static, str>,
    /// WGSL fragments, concatenated in order: the entry file last, each file after the
    /// files it imports ([`crate::wgsl_imports`]).
    pub fragments: Vec<Fragment>,
    /// The compute entry point.
    pub entry_point: Cow<'static, str>,
    /// Device features the kernel needs.
    pub features: KernelFeatures,
    /// Largest difference in ULPs allowed between backends for float outputs; `None`
    /// when every output is an integer or an ordering, compared bit for bit.
    pub float_ulp_bound: Option<u32>,
}

#[cfg(test)]
mod tests {
    use super::{Executor, KernelId};

    #[test]
    fn device_types_map_to_executors() {
        // wgpu writes `Cpu`, ash (Vulkan's PhysicalDeviceType) `CPU`.
        assert_eq!(Executor::of_device("Cpu", false), Executor::CpuDriver);
        assert_eq!(Executor::of_device("CPU", false), Executor::CpuDriver);
        assert_eq!(Executor::of_device("DiscreteGpu", false), Executor::Gpu);
        assert_eq!(Executor::of_device("INTEGRATED_GPU", false), Executor::Gpu);
        assert_eq!(Executor::of_device("IntegratedGpu", false), Executor::Gpu);
        assert_eq!(Executor::of_device("VirtualGpu", false), Executor::Gpu);
        assert_eq!(Executor::of_device("Other", false), Executor::Gpu);
        assert_eq!(Executor::of_device("Cpu", true), Executor::Interpreter);
    }

    #[test]
    fn gpus_sort_with_the_network_and_cpu_drivers_rank() {
        for block_size in [4, 8, 16, 32] {
            assert_eq!(KernelId::fastest_histogram(block_size, true, Executor::Gpu), KernelId::BlockHistogramSubgroup);
            assert_eq!(KernelId::fastest_histogram(block_size, false, Executor::Gpu), KernelId::BlockHistogram);
            assert_eq!(KernelId::fastest_histogram(block_size, false, Executor::Interpreter), KernelId::BlockHistogram);
            for subgroups in [false, true] {
                assert_eq!(
                    KernelId::fastest_histogram(block_size, subgroups, Executor::CpuDriver),
                    KernelId::BlockHistogramRank
                );
            }
        }
    }
}
