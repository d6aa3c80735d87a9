//! The kernel registry: every kernel strata ships, with what the backends need to run
//! it, derived from naga's IR of the WGSL source.

use crate::binding::{BindingAccess, BindingInfo, BindingKind, element_layout};
use crate::error::KernelError;
use crate::fragment;
use crate::source::{ComposedSource, Fragment};
use naga::valid::{Capabilities, ModuleInfo, ShaderStages, SubgroupOperationSet, ValidationFlags};
use std::borrow::Cow;

/// Names a registry kernel.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum KernelId {
    /// Per-block histogram: candidates clustered by object id and sorted by key
    /// (paper §4.1, §4.3), without subgroup operations.
    BlockHistogram,
    /// The same pass exchanging elements between subgroup lanes (needs subgroups).
    BlockHistogramSubgroup,
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
    /// ReSTIR pass 5: shading of the reservoirs' samples with one shadow ray.
    RestirShade,
    /// Embedding: K payload indices per pixel from its cluster's run at the stratified
    /// positions of the chosen sampler variant (paper §4.2, Fig. 3, Table 2).
    StrataSelect,
    /// Embedding: inverse-CDF resampling of the engine's weights (paper §4.2).
    StrataResample,
    /// A kernel from outside the registry ([`Kernel::from_wgsl`]), keyed by a hash of its
    /// source and entry point so that backends can cache its pipeline.
    External(u64),
}

impl KernelId {
    /// Every registry kernel.
    pub const ALL: [KernelId; 13] = [
        KernelId::BlockHistogram,
        KernelId::BlockHistogramSubgroup,
        KernelId::Empty,
        KernelId::BvhClosestHit,
        KernelId::CameraRays,
        KernelId::PathTrace,
        KernelId::RestirCandidates,
        KernelId::RestirSelect,
        KernelId::RestirTemporalKeys,
        KernelId::RestirTemporal,
        KernelId::RestirShade,
        KernelId::StrataSelect,
        KernelId::StrataResample,
    ];

    /// What the registry knows of this kernel before parsing it.
    pub fn spec(self) -> Option<KernelSpec> {
        // The paper's histogram (§4.1) with object masking (§4.3).
        let histogram = || {
            [fragment!("strata/candidate.wgsl"), fragment!("strata/masking.wgsl"), fragment!("strata/histogram.wgsl")]
        };
        // The paper's selection (§4.2): positions from the blue-noise sampler, then the
        // inverse-CDF resampling.
        let selection = || {
            vec![
                fragment!("strata/blue_noise.wgsl"),
                fragment!("strata/selection.wgsl"),
                fragment!("strata/resampling.wgsl"),
            ]
        };
        // Every ReSTIR pass: the scene and the path tracer's functions, the candidate
        // records of the histogram, then its own entry point.
        // The path tracer's functions, shared by path_trace and the ReSTIR passes.
        let renderer = || {
            vec![
                fragment!("trace/bvh.wgsl"),
                fragment!("trace/traverse.wgsl"),
                fragment!("render/scene.wgsl"),
                fragment!("render/random.wgsl"),
                fragment!("render/environment.wgsl"),
                fragment!("render/albedo.wgsl"),
                fragment!("render/bsdf.wgsl"),
                fragment!("render/lights.wgsl"),
                fragment!("render/path.wgsl"),
            ]
        };
        // A ReSTIR pass: the renderer, the shared records, then `pass` (its entry point last).
        let restir = |name: &'static str, pass: &[Fragment]| KernelSpec {
            name: name.into(),
            fragments: [
                renderer(),
                vec![fragment!("strata/candidate.wgsl"), fragment!("restir/reservoir.wgsl")],
                pass.to_vec(),
            ]
            .concat(),
            entry_point: name.into(),
            features: KernelFeatures::empty(),
            // Paths and reconnections branch on float results, and environment lookups
            // use atan2/acos (4096 ULP in Vulkan): as for path_trace.
            float_ulp_bound: Some(4096),
        };
        Some(match self {
            KernelId::BlockHistogram => KernelSpec {
                name: "block_histogram".into(),
                fragments: [histogram().to_vec(), vec![fragment!("strata/entry_histogram.wgsl")]].concat(),
                entry_point: "block_histogram".into(),
                features: KernelFeatures::empty(),
                float_ulp_bound: None,
            },
            KernelId::BlockHistogramSubgroup => KernelSpec {
                name: "block_histogram_subgroup".into(),
                fragments: [histogram().to_vec(), vec![fragment!("strata/entry_histogram_subgroup.wgsl")]].concat(),
                entry_point: "block_histogram_subgroup".into(),
                features: KernelFeatures::SUBGROUP,
                float_ulp_bound: None,
            },
            KernelId::Empty => KernelSpec {
                name: "empty".into(),
                fragments: vec![fragment!("util/empty.wgsl")],
                entry_point: "empty".into(),
                features: KernelFeatures::empty(),
                float_ulp_bound: None,
            },
            KernelId::BvhClosestHit => KernelSpec {
                name: "bvh_closest_hit".into(),
                fragments: vec![
                    fragment!("trace/bvh.wgsl"),
                    fragment!("trace/traverse.wgsl"),
                    fragment!("trace/entry_closest_hit.wgsl"),
                ],
                entry_point: "bvh_closest_hit".into(),
                features: KernelFeatures::empty(),
                // Backends may contract products into fused multiply-adds; hits that change
                // triangle at near-ties are counted separately (see the check).
                float_ulp_bound: Some(8),
            },
            KernelId::CameraRays => KernelSpec {
                name: "camera_rays".into(),
                fragments: vec![fragment!("trace/bvh.wgsl"), fragment!("trace/camera_rays.wgsl")],
                entry_point: "camera_rays_main".into(),
                features: KernelFeatures::empty(),
                // normalize() and the divisions may round differently (inverse square
                // root, reciprocals, fused multiply-adds).
                float_ulp_bound: Some(16),
            },
            KernelId::PathTrace => KernelSpec {
                name: "path_trace".into(),
                fragments: [renderer(), vec![fragment!("render/entry_path_trace.wgsl")]].concat(),
                entry_point: "path_trace".into(),
                features: KernelFeatures::empty(),
                // Paths branch on float comparisons: a one-ULP difference can send a
                // path elsewhere, so pixels are compared with a bound and outliers. The
                // bound is Vulkan's precision for atan2 and acos (4096 ULP, used by every
                // environment lookup), which lavapipe's approximations do use: its
                // radiance differs from the interpreter's correctly rounded Rust
                // functions by ~2100 ULP in environment-lit pixels.
                float_ulp_bound: Some(4096),
            },
            KernelId::RestirCandidates => restir("restir_candidates", &[fragment!("restir/entry_candidates.wgsl")]),
            KernelId::RestirSelect => restir(
                "restir_select",
                &[selection(), vec![fragment!("restir/reuse_slot.wgsl"), fragment!("restir/entry_select.wgsl")]]
                    .concat(),
            ),
            KernelId::RestirTemporalKeys => {
                restir("restir_temporal_keys", &[fragment!("restir/entry_temporal_keys.wgsl")])
            }
            KernelId::RestirTemporal => restir(
                "restir_temporal",
                &[selection(), vec![fragment!("restir/reuse_slot.wgsl"), fragment!("restir/entry_temporal.wgsl")]]
                    .concat(),
            ),
            KernelId::RestirShade => restir("restir_shade", &[fragment!("restir/entry_shade.wgsl")]),
            KernelId::StrataSelect => KernelSpec {
                name: "strata_select".into(),
                fragments: [
                    vec![fragment!("strata/candidate.wgsl")],
                    selection(),
                    vec![fragment!("embed/contract.wgsl"), fragment!("embed/entry_select.wgsl")],
                ]
                .concat(),
                entry_point: "strata_select".into(),
                features: KernelFeatures::empty(),
                // Payload indices are integers; the resampling number is the one float
                // output (divisions and fract: a few ULP).
                float_ulp_bound: Some(4),
            },
            KernelId::StrataResample => KernelSpec {
                name: "strata_resample".into(),
                fragments: vec![
                    fragment!("strata/resampling.wgsl"),
                    fragment!("embed/contract.wgsl"),
                    fragment!("embed/entry_resample.wgsl"),
                ],
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

    fn capabilities(self) -> Capabilities {
        if self.subgroup { Capabilities::SUBGROUP | Capabilities::SUBGROUP_BARRIER } else { Capabilities::empty() }
    }
}

/// What the validator allows in external kernels ([`Kernel::from_wgsl`]) beyond the
/// kernel's [`KernelFeatures`].
const EXTERNAL_CAPABILITIES: Capabilities =
    Capabilities::SHADER_FLOAT16_IN_FLOAT32.union(Capabilities::SHADER_INT64).union(Capabilities::SHADER_FLOAT16);

/// A kernel as declared in the registry.
#[derive(Clone, Debug)]
pub struct KernelSpec {
    /// Registry name (also the name of translated files).
    pub name: Cow<'static, str>,
    /// WGSL fragments, concatenated in order.
    pub fragments: Vec<Fragment>,
    /// The compute entry point.
    pub entry_point: Cow<'static, str>,
    /// Device features the kernel needs.
    pub features: KernelFeatures,
    /// Largest difference in ULPs allowed between backends for float outputs; `None`
    /// when every output is an integer or an ordering, compared bit for bit.
    pub float_ulp_bound: Option<u32>,
}

/// A parsed, validated registry kernel.
#[derive(Debug)]
pub struct Kernel {
    /// Which kernel.
    pub id: KernelId,
    /// Its declaration.
    pub spec: KernelSpec,
    /// The composed WGSL.
    pub source: ComposedSource,
    /// naga's IR.
    pub module: naga::Module,
    /// naga's validation results.
    pub info: ModuleInfo,
    /// `@workgroup_size`.
    pub workgroup_size: [u32; 3],
    /// Bindings the entry point uses, sorted by (group, binding).
    pub bindings: Vec<BindingInfo>,
}

impl Kernel {
    /// Registry name.
    pub fn name(&self) -> &str {
        &self.spec.name
    }

    /// Entry point name in the WGSL source.
    pub fn entry_point(&self) -> &str {
        &self.spec.entry_point
    }

    /// Invocations per workgroup.
    pub fn invocations(&self) -> u32 {
        self.workgroup_size.iter().product()
    }

    /// Index of the entry point in `module.entry_points`.
    pub fn entry_index(&self) -> usize {
        self.module
            .entry_points
            .iter()
            .position(|ep| ep.name == self.spec.entry_point)
            .expect("checked when the kernel was loaded")
    }

    /// The binding `@group(group) @binding(binding)`, if the entry point uses it.
    pub fn binding(&self, group: u32, binding: u32) -> Option<&BindingInfo> {
        self.bindings.iter().find(|b| b.group == group && b.binding == binding)
    }

    /// The binding whose WGSL variable is `name`.
    pub fn binding_named(&self, name: &str) -> Option<&BindingInfo> {
        self.bindings.iter().find(|b| b.name == name)
    }

    /// Bytes of workgroup memory the entry point declares.
    pub fn workgroup_memory_bytes(&self) -> u64 {
        let mut layouter = naga::proc::Layouter::default();
        if layouter.update(self.module.to_ctx()).is_err() {
            return 0;
        }
        let ep_info = self.info.get_entry_point(self.entry_index());
        self.module
            .global_variables
            .iter()
            .filter(|(handle, var)| var.space == naga::AddressSpace::WorkGroup && !ep_info[*handle].is_empty())
            .map(|(_, var)| u64::from(layouter[var.ty].size))
            .sum()
    }

    /// Parses, validates and describes registry kernel `id`.
    pub fn load(id: KernelId) -> Result<Kernel, KernelError> {
        let spec = id.spec().ok_or_else(|| KernelError::MissingEntryPoint {
            kernel: format!("{id:?}"),
            entry: "(external kernels are made with Kernel::from_wgsl)".into(),
        })?;
        Self::from_spec(id, spec)
    }

    /// A kernel that is not in the registry: WGSL source from `path`, entry point
    /// `entry_point`, validated with subgroup operations allowed when `subgroup` is set.
    pub fn from_wgsl(path: &str, source: String, entry_point: &str, subgroup: bool) -> Result<Kernel, KernelError> {
        use std::hash::{Hash, Hasher};
        let mut hasher = std::collections::hash_map::DefaultHasher::new();
        (&source, entry_point, subgroup).hash(&mut hasher);
        let spec = KernelSpec {
            name: entry_point.to_string().into(),
            fragments: vec![Fragment { path: path.to_string().into(), text: source.into() }],
            entry_point: entry_point.to_string().into(),
            features: if subgroup { KernelFeatures::SUBGROUP } else { KernelFeatures::empty() },
            float_ulp_bound: None,
        };
        Self::from_spec(KernelId::External(hasher.finish()), spec)
    }

    fn from_spec(id: KernelId, spec: KernelSpec) -> Result<Kernel, KernelError> {
        let source = ComposedSource::compose(&spec.fragments);
        let module = naga::front::wgsl::parse_str(&source.text).map_err(|error| {
            let location = error
                .labels()
                .next()
                .map(|(span, _)| source.describe_offset(span.to_range().map_or(0, |r| r.start)))
                .unwrap_or_default();
            KernelError::Parse {
                kernel: spec.name.to_string(),
                message: format!("at {location}\n{}", error.emit_to_string(&source.text)),
            }
        })?;
        // External kernels may use what a backend supports beyond core WebGPU (the
        // interpreter and Vulkan devices with the features: 64-bit integers, f16, the
        // f16 packing builtins); a backend without them refuses the kernel itself.
        let mut capabilities = spec.features.capabilities();
        if matches!(id, KernelId::External(_)) {
            capabilities |= EXTERNAL_CAPABILITIES;
        }
        let info = naga::valid::Validator::new(ValidationFlags::all(), capabilities)
            .subgroup_stages(ShaderStages::COMPUTE)
            .subgroup_operations(SubgroupOperationSet::all())
            .validate(&module)
            .map_err(|error| KernelError::Validation {
                kernel: spec.name.to_string(),
                message: error.emit_to_string(&source.text),
            })?;
        let entry_index = module
            .entry_points
            .iter()
            .position(|ep| ep.name == spec.entry_point && ep.stage == naga::ShaderStage::Compute)
            .ok_or_else(|| KernelError::MissingEntryPoint {
                kernel: spec.name.to_string(),
                entry: spec.entry_point.to_string(),
            })?;
        let workgroup_size = module.entry_points[entry_index].workgroup_size;
        let bindings = describe_bindings(&spec.name, &module, &info, entry_index)?;
        Ok(Kernel { id, spec, source, module, info, workgroup_size, bindings })
    }
}

fn describe_bindings(
    kernel: &str,
    module: &naga::Module,
    info: &ModuleInfo,
    entry_index: usize,
) -> Result<Vec<BindingInfo>, KernelError> {
    let mut layouter = naga::proc::Layouter::default();
    layouter
        .update(module.to_ctx())
        .map_err(|e| KernelError::Validation { kernel: kernel.into(), message: e.to_string() })?;
    let ep_info = info.get_entry_point(entry_index);
    let mut bindings = Vec::new();
    for (handle, var) in module.global_variables.iter() {
        let Some(resource) = &var.binding else {
            continue;
        };
        if ep_info[handle].is_empty() {
            continue;
        }
        let name = var.name.clone().unwrap_or_default();
        let unsupported = |reason: &str| KernelError::UnsupportedBinding {
            kernel: kernel.into(),
            group: resource.group,
            binding: resource.binding,
            name: name.clone(),
            reason: reason.into(),
        };
        let kind = match var.space {
            naga::AddressSpace::Uniform => BindingKind::Uniform,
            naga::AddressSpace::Storage { access } => {
                if access.contains(naga::StorageAccess::STORE) {
                    BindingKind::Storage(BindingAccess::ReadWrite)
                } else {
                    BindingKind::Storage(BindingAccess::ReadOnly)
                }
            }
            _ => {
                return Err(unsupported("only uniform and storage buffers are supported"));
            }
        };
        if resource.group != 0 {
            return Err(unsupported("registry kernels use @group(0) only (GLSL has no descriptor sets)"));
        }
        bindings.push(BindingInfo {
            group: resource.group,
            binding: resource.binding,
            name,
            kind,
            element: element_layout(module, &layouter, var.ty),
        });
    }
    bindings.sort_by_key(|b| (b.group, b.binding));
    Ok(bindings)
}

/// Every registry kernel, loaded.
#[derive(Debug)]
pub struct Registry {
    kernels: Vec<Kernel>,
}

impl Registry {
    /// The registry of this process, loaded on first use.
    pub fn shared() -> Result<&'static Registry, KernelError> {
        static SHARED: std::sync::OnceLock<Result<Registry, KernelError>> = std::sync::OnceLock::new();
        SHARED.get_or_init(Registry::load).as_ref().map_err(Clone::clone)
    }

    /// Loads every kernel of [`KernelId::ALL`].
    pub fn load() -> Result<Registry, KernelError> {
        let kernels = KernelId::ALL.iter().map(|&id| Kernel::load(id)).collect::<Result<_, _>>()?;
        Ok(Registry { kernels })
    }

    /// The kernel `id`.
    pub fn get(&self, id: KernelId) -> &Kernel {
        self.kernels.iter().find(|k| k.id == id).expect("the registry loads every KernelId")
    }

    /// All kernels, in [`KernelId::ALL`] order.
    pub fn kernels(&self) -> &[Kernel] {
        &self.kernels
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::layout::check_struct;
    use crate::types::{BlockStats, Candidate, ClusterSpan, HistogramParams};

    #[test]
    fn every_kernel_loads_with_bindings_from_the_ir() {
        let registry = Registry::load().unwrap_or_else(|e| panic!("{e}"));
        let kernel = registry.get(KernelId::BlockHistogram);
        assert_eq!(kernel.workgroup_size, [64, 1, 1]);
        let names: Vec<_> = kernel.bindings.iter().map(|b| (b.binding, b.name.as_str())).collect();
        assert_eq!(names, [(0, "params"), (1, "candidates"), (2, "sorted_pixels"), (3, "spans"), (4, "block_stats")]);
        assert_eq!(kernel.bindings[0].kind, BindingKind::Uniform);
        assert_eq!(kernel.bindings[1].kind, BindingKind::Storage(BindingAccess::ReadOnly));
        assert_eq!(kernel.bindings[3].kind, BindingKind::Storage(BindingAccess::ReadWrite));
        assert_eq!(kernel.bindings[1].element.type_name, "Candidate");
        assert_eq!(kernel.bindings[1].element.stride, 8);
        assert_eq!(kernel.bindings[1].element.count, None);
        assert_eq!(kernel.bindings[3].element.stride, 12);
        assert_eq!(kernel.bindings[0].element.count, Some(1));
        assert_eq!(kernel.bindings[0].min_size(), 48);
        // 3 x 1024 u32 of keys plus 192 counters: within WebGPU's 16 KiB minimum.
        assert!(kernel.workgroup_memory_bytes() <= 16 * 1024, "{}", kernel.workgroup_memory_bytes());
        for kernel in registry.kernels() {
            assert!(kernel.bindings.iter().all(|b| b.group == 0), "{}", kernel.name());
        }
    }

    #[test]
    fn host_structs_match_their_wgsl_twins() {
        let registry = Registry::load().unwrap_or_else(|e| panic!("{e}"));
        for kernel in registry.kernels() {
            let module = &kernel.module;
            if kernel.id == KernelId::CameraRays {
                check_struct::<crate::trace_types::CameraParams>(module).unwrap_or_else(|e| panic!("{e}"));
                continue;
            }
            if kernel.id == KernelId::BvhClosestHit {
                use crate::trace_types::{GpuBvhNode, GpuTriangle, Hit, Ray, TraceParams};
                for result in [
                    check_struct::<GpuBvhNode>(module),
                    check_struct::<GpuTriangle>(module),
                    check_struct::<Ray>(module),
                    check_struct::<Hit>(module),
                    check_struct::<TraceParams>(module),
                ] {
                    result.unwrap_or_else(|e| panic!("{}: {e}", kernel.name()));
                }
                continue;
            }
            if kernel.id == KernelId::Empty {
                continue;
            }
            if matches!(
                kernel.id,
                KernelId::RestirCandidates
                    | KernelId::RestirSelect
                    | KernelId::RestirTemporalKeys
                    | KernelId::RestirTemporal
                    | KernelId::RestirShade
            ) {
                use crate::restir_types::{PathCandidate, Primary, Reservoir, RestirParams};
                for result in [
                    check_struct::<crate::render_types::RenderParams>(module),
                    check_struct::<RestirParams>(module),
                    check_struct::<Primary>(module),
                    check_struct::<PathCandidate>(module),
                    check_struct::<Reservoir>(module),
                    check_struct::<Candidate>(module),
                    check_struct::<ClusterSpan>(module),
                ] {
                    result.unwrap_or_else(|e| panic!("{}: {e}", kernel.name()));
                }
                continue;
            }
            if kernel.id == KernelId::PathTrace {
                use crate::render_types::{EmissiveTriangle, GpuMaterial, RenderParams, TriangleInfo};
                use crate::trace_types::{GpuBvhNode, GpuTriangle, Hit, Ray};
                for result in [
                    check_struct::<RenderParams>(module),
                    check_struct::<TriangleInfo>(module),
                    check_struct::<GpuMaterial>(module),
                    check_struct::<EmissiveTriangle>(module),
                    check_struct::<GpuBvhNode>(module),
                    check_struct::<GpuTriangle>(module),
                    check_struct::<Ray>(module),
                    check_struct::<Hit>(module),
                ] {
                    result.unwrap_or_else(|e| panic!("{}: {e}", kernel.name()));
                }
                continue;
            }
            if matches!(kernel.id, KernelId::StrataSelect | KernelId::StrataResample) {
                use crate::embed_types::{ResampleInput, ResampleOutput, SelectedCandidates, SelectionParams};
                let mut results = vec![
                    check_struct::<SelectionParams>(module),
                    check_struct::<SelectedCandidates>(module),
                    check_struct::<ResampleInput>(module),
                    check_struct::<ResampleOutput>(module),
                ];
                if kernel.id == KernelId::StrataSelect {
                    results.extend([check_struct::<Candidate>(module), check_struct::<ClusterSpan>(module)]);
                }
                for result in results {
                    result.unwrap_or_else(|e| panic!("{}: {e}", kernel.name()));
                }
                continue;
            }
            for result in [
                check_struct::<Candidate>(module),
                check_struct::<ClusterSpan>(module),
                check_struct::<BlockStats>(module),
                check_struct::<HistogramParams>(module),
            ] {
                result.unwrap_or_else(|e| panic!("{}: {e}", kernel.name()));
            }
        }
    }

    #[test]
    fn the_portable_kernel_is_validated_without_subgroups() {
        let mut spec = KernelId::BlockHistogram.spec().unwrap();
        *spec.fragments.last_mut().unwrap() = fragment!("strata/entry_histogram_subgroup.wgsl");
        let source = ComposedSource::compose(&spec.fragments);
        let module = naga::front::wgsl::parse_str(&source.text).unwrap();
        let result =
            naga::valid::Validator::new(ValidationFlags::all(), spec.features.capabilities()).validate(&module);
        assert!(result.is_err(), "subgroup operations must need the SUBGROUP capability");
    }
}
