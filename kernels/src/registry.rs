//! The kernel registry: every kernel strata ships, with what the backends need to run
//! it, derived from naga's IR of the WGSL source.

use crate::binding::{BindingAccess, BindingInfo, BindingKind, ElementLayout, element_layout, type_name};
pub use crate::catalogue::{KernelFeatures, KernelId, KernelSpec};
use crate::error::KernelError;
use crate::source::{ComposedSource, Fragment};
use crate::texture::{StorageTextureAccess, TexelFormat, TexelKind, TextureDimension};
use crate::word_kinds::WordKinds;
use naga::valid::{Capabilities, ModuleInfo, ShaderStages, SubgroupOperationSet, ValidationFlags};

/// What the validator allows in external kernels ([`Kernel::from_wgsl`]) beyond the
/// kernel's [`KernelFeatures`].
const EXTERNAL_CAPABILITIES: Capabilities =
    Capabilities::SHADER_FLOAT16_IN_FLOAT32.union(Capabilities::SHADER_INT64).union(Capabilities::SHADER_FLOAT16);

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
    /// Its memory per workgroup and per invocation, sized once when it is loaded (the
    /// backends check it before every dispatch).
    memory: MemoryBytes,
    /// The values its `override` constants were given ([`Kernel::overrides`]).
    overrides: Vec<(String, f64)>,
    /// The names of the `override` constants its entry point reaches
    /// ([`Kernel::uses_override`]).
    used_overrides: Vec<String>,
    /// The names of the globals its source declares ([`Kernel::declares`]): specialising
    /// compacts [`Kernel::module`] to what the entry point reaches.
    declared_globals: Vec<String>,
}

/// A kernel's workgroup memory per workgroup and private and function memory per
/// invocation, in bytes ([`Kernel::workgroup_memory_bytes`],
/// [`Kernel::private_memory_bytes`]).
#[derive(Clone, Copy, Debug, Default)]
struct MemoryBytes {
    workgroup: u64,
    private: u64,
}

impl MemoryBytes {
    /// Sizes the variables entry point `entry_index` of `module` uses with naga's layout
    /// (0 for a module naga cannot lay out, which validation has refused before).
    fn of(module: &naga::Module, info: &ModuleInfo, entry_index: usize) -> Self {
        let mut layouter = naga::proc::Layouter::default();
        if layouter.update(module.to_ctx()).is_err() {
            return Self::default();
        }
        let ep_info = info.get_entry_point(entry_index);
        let used = |space: naga::AddressSpace| -> u64 {
            module
                .global_variables
                .iter()
                .filter(|(handle, var)| var.space == space && !ep_info[*handle].is_empty())
                .map(|(_, var)| u64::from(layouter[var.ty].size))
                .sum()
        };
        let functions = module.functions.iter().map(|(_, f)| f);
        let locals: u64 = functions
            .chain([&module.entry_points[entry_index].function])
            .flat_map(|f| f.local_variables.iter())
            .map(|(_, local)| u64::from(layouter[local.ty].size))
            .sum();
        Self {
            workgroup: used(naga::AddressSpace::WorkGroup),
            private: used(naga::AddressSpace::Private).saturating_add(locals),
        }
    }
}

/// A kernel's pipeline as backends cache it ([`Kernel::pipeline_key`]): its id and a hash
/// of its overrides' values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PipelineKey(pub KernelId, pub u64);

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

    /// How many bind groups (descriptor sets) its pipeline layout has: one past the
    /// highest group it uses (groups it skips are empty), 1 without bindings.
    pub fn group_count(&self) -> u32 {
        self.bindings.iter().map(|b| b.group + 1).max().unwrap_or(1)
    }

    /// The binding number of `(group, binding)` in one flat set, for a translation that
    /// has no descriptor sets (naga's GLSL): the WGSL binding itself when the kernel uses
    /// group 0 alone, else its index in the kernel's `(group, binding)` order.
    pub fn flat_binding(&self, group: u32, binding: u32) -> u32 {
        if self.group_count() == 1 {
            return binding;
        }
        self.bindings.iter().position(|b| b.group == group && b.binding == binding).map_or(u32::MAX, |i| i as u32)
    }

    /// The binding whose WGSL variable is `name`.
    pub fn binding_named(&self, name: &str) -> Option<&BindingInfo> {
        self.bindings.iter().find(|b| b.name == name)
    }

    /// Whether the kernel's source declares a global named `name` (a binding its entry
    /// point may never reach, which naga then leaves out of [`Self::bindings`]).
    pub fn declares(&self, name: &str) -> bool {
        self.declared_globals.iter().any(|declared| declared == name)
    }

    /// Whether the kernel's entry point reaches an `override` constant named `name` (its
    /// module is specialised, so [`Self::module`] no longer holds any). One its source
    /// declares but the entry point never reaches does not count: naga's specialisation
    /// drops it, so every value would give the same module.
    pub fn uses_override(&self, name: &str) -> bool {
        self.used_overrides.iter().any(|used| used == name)
    }

    /// Bytes of workgroup memory the entry point declares.
    pub fn workgroup_memory_bytes(&self) -> u64 {
        self.memory.workgroup
    }

    /// Bytes of private and function memory an invocation may hold at once, bounded
    /// from above: the `var<private>` variables the entry point uses, and the local
    /// variables of its function and of every function of the module together (a chain
    /// of calls holds at most those). CPU drivers compile large per-invocation arrays
    /// slowly and into much memory (see `strata_backends::bindings_check`).
    pub fn private_memory_bytes(&self) -> u64 {
        self.memory.private
    }

    /// The values given for its `override` constants when it was loaded
    /// ([`Kernel::from_wgsl_with_overrides`]), keyed as naga's and WebGPU's pipeline
    /// constants are (an `@id` number as text, or the name): [`Kernel::module`] is
    /// already specialised with them, and a backend that compiles [`Kernel::source`]
    /// itself (WebGPU's) passes them as its pipeline's constants. Empty for the registry's
    /// own kernels ([`Registry::get`]); a registry kernel specialised for settings
    /// ([`Registry::specialised`]) has its values here.
    pub fn overrides(&self) -> &[(String, f64)] {
        &self.overrides
    }

    /// What a backend caches this kernel's pipeline under: its id and a hash of the values
    /// its overrides were given (0 for none). A registry kernel specialised with other
    /// values ([`Registry::specialised`]) keeps its id, so the id alone would
    /// hand it the general kernel's pipeline.
    pub fn pipeline_key(&self) -> PipelineKey {
        use std::hash::{Hash, Hasher};
        if self.overrides.is_empty() {
            return PipelineKey(self.id, 0);
        }
        let mut hasher = std::collections::hash_map::DefaultHasher::new();
        for (name, value) in &self.overrides {
            (name, value.to_bits()).hash(&mut hasher);
        }
        PipelineKey(self.id, hasher.finish())
    }

    /// Parses, validates and describes registry kernel `id`.
    pub fn load(id: KernelId) -> Result<Kernel, KernelError> {
        Self::load_with_overrides(id, &[])
    }

    /// Registry kernel `id` with its `override` constants given `overrides` (the others
    /// keep their defaults); see [`Kernel::from_wgsl_with_overrides`].
    pub fn load_with_overrides(id: KernelId, overrides: &[(String, f64)]) -> Result<Kernel, KernelError> {
        let spec = id.spec().ok_or_else(|| KernelError::MissingEntryPoint {
            kernel: format!("{id:?}"),
            entry: "(external kernels are made with Kernel::from_wgsl)".into(),
        })?;
        Self::from_spec(id, spec, overrides)
    }

    /// A kernel that is not in the registry: WGSL source from `path`, entry point
    /// `entry_point`, validated with subgroup operations allowed when `subgroup` is set.
    /// Pipeline-overridable constants (`override`) keep their WGSL defaults; see
    /// [`Kernel::from_wgsl_with_overrides`].
    pub fn from_wgsl(path: &str, source: String, entry_point: &str, subgroup: bool) -> Result<Kernel, KernelError> {
        Self::from_wgsl_with_overrides(path, source, entry_point, subgroup, &[])
    }

    /// [`Kernel::from_wgsl`] with values for the module's `override` constants, by name
    /// (or by `@id` number as text); the others keep their WGSL defaults.
    ///
    /// The overrides are resolved here, once, by naga's pipeline-constant processing
    /// (the same code wgpu runs at pipeline creation): the kernel's module, workgroup
    /// size and bindings are those of the specialised pipeline, so every backend (the
    /// interpreter, wgpu, ash on naga's SPIR-V and on glslang's GLSL and HLSL) runs the
    /// same specialised shader. Naming a constant the module lacks, a value that does not
    /// fit its type, or leaving one without a default unset is an error naming it.
    pub fn from_wgsl_with_overrides(
        path: &str,
        source: String,
        entry_point: &str,
        subgroup: bool,
        overrides: &[(String, f64)],
    ) -> Result<Kernel, KernelError> {
        use std::hash::{Hash, Hasher};
        let mut hasher = std::collections::hash_map::DefaultHasher::new();
        (&source, entry_point, subgroup).hash(&mut hasher);
        for (name, value) in overrides {
            (name, value.to_bits()).hash(&mut hasher);
        }
        let spec = KernelSpec {
            name: entry_point.to_string().into(),
            fragments: vec![Fragment { path: path.to_string().into(), text: source.into() }],
            entry_point: entry_point.to_string().into(),
            features: if subgroup { KernelFeatures::SUBGROUP } else { KernelFeatures::empty() },
            float_ulp_bound: None,
        };
        Self::from_spec(KernelId::External(hasher.finish()), spec, overrides)
    }

    fn from_spec(id: KernelId, spec: KernelSpec, overrides: &[(String, f64)]) -> Result<Kernel, KernelError> {
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
        let used_overrides = used_overrides(&module, &spec.entry_point);
        let declared_globals = module.global_variables.iter().filter_map(|(_, v)| v.name.clone()).collect();
        let (module, info) = specialise(&spec, module, info, overrides)?;
        let entry_index = module
            .entry_points
            .iter()
            .position(|ep| ep.name == spec.entry_point && ep.stage == naga::ShaderStage::Compute)
            .ok_or_else(|| KernelError::MissingEntryPoint {
                kernel: spec.name.to_string(),
                entry: spec.entry_point.to_string(),
            })?;
        let workgroup_size = module.entry_points[entry_index].workgroup_size;
        let registry = !matches!(id, KernelId::External(_));
        let bindings = describe_bindings(&spec.name, &module, &info, entry_index, registry)?;
        let memory = MemoryBytes::of(&module, &info, entry_index);
        let overrides = overrides.to_vec();
        Ok(Kernel {
            id,
            spec,
            source,
            module,
            info,
            workgroup_size,
            bindings,
            memory,
            overrides,
            used_overrides,
            declared_globals,
        })
    }
}

/// The names of the `override` constants entry point `entry` of `module` reaches: those
/// left after naga's compaction to that entry point (what `process_overrides` keeps).
fn used_overrides(module: &naga::Module, entry: &str) -> Vec<String> {
    if module.overrides.is_empty() {
        return Vec::new();
    }
    let mut reached = module.clone();
    reached.entry_points.retain(|ep| ep.name == entry && ep.stage == naga::ShaderStage::Compute);
    naga::compact::compact(&mut reached, naga::compact::KeepUnused::No);
    reached.overrides.iter().filter_map(|(_, o)| o.name.clone()).collect()
}

/// Replaces the module's `override` constants by `overrides` or their defaults (naga's
/// `process_overrides`, keeping only the kernel's entry point); a module without
/// overrides is returned as it is.
fn specialise(
    spec: &KernelSpec,
    module: naga::Module,
    info: ModuleInfo,
    overrides: &[(String, f64)],
) -> Result<(naga::Module, ModuleInfo), KernelError> {
    if module.overrides.is_empty() && overrides.is_empty() {
        return Ok((module, info));
    }
    let error = |message: String| KernelError::Override { kernel: spec.name.to_string(), message };
    let mut constants = naga::back::PipelineConstants::default();
    for (name, value) in overrides {
        if constants.insert(name.clone(), *value).is_some() {
            return Err(error(format!("`{name}` is given twice")));
        }
    }
    let declared: Vec<String> = module.overrides.iter().filter_map(|(_, o)| o.name.clone()).collect();
    let entry = (naga::ShaderStage::Compute, spec.entry_point.as_ref());
    let (module, info) = naga::back::pipeline_constants::process_overrides(&module, &info, Some(entry), &constants)
        .map_err(|e| {
            use naga::back::pipeline_constants::PipelineConstantError as E;
            let declared = if declared.is_empty() { "none".to_string() } else { declared.join(", ") };
            error(match e {
                E::NotFound(name) => format!("`{name}` is not an override of this shader (it declares: {declared})"),
                E::MissingValue(name) => format!("`{name}` has no default: give it a value"),
                E::SrcNeedsToBeFinite | E::DstRangeTooSmall => {
                    let given = overrides.iter().map(|(n, v)| format!("{n}={v}")).collect::<Vec<_>>().join(", ");
                    format!("a value does not fit its override's type ({given}): {e}")
                }
                other => other.to_string(),
            })
        })?;
    Ok((module.into_owned(), info.into_owned()))
}

/// The bindings the entry point uses. A registry kernel (`registry`) must keep to
/// `@group(0)`: strata-embed, the export's C header and the GLSL translations of the
/// package bind one descriptor set; an outside kernel may use any group.
fn describe_bindings(
    kernel: &str,
    module: &naga::Module,
    info: &ModuleInfo,
    entry_index: usize,
    registry: bool,
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
            naga::AddressSpace::Handle => handle_kind(module, var.ty).map_err(|reason| unsupported(&reason))?,
            _ => {
                return Err(unsupported("only buffers, textures and samplers can be bound"));
            }
        };
        if registry && resource.group != 0 {
            return Err(unsupported("registry kernels use @group(0) only (the package binds one descriptor set)"));
        }
        let (element, words) = match kind {
            BindingKind::Uniform | BindingKind::Storage(_) => {
                (element_layout(module, &layouter, var.ty), WordKinds::of_type(module, &layouter, var.ty))
            }
            // A texture or sampler has no bytes of its own a buffer would need; a storage
            // texture's words are its texels.
            _ => (
                ElementLayout { type_name: type_name(module, var.ty), stride: 0, align: 1, count: Some(1) },
                match kind {
                    BindingKind::StorageTexture { format, .. } => WordKinds::of_texels(format),
                    _ => WordKinds::default(),
                },
            ),
        };
        bindings.push(BindingInfo { group: resource.group, binding: resource.binding, name, kind, element, words });
    }
    bindings.sort_by_key(|b| (b.group, b.binding));
    Ok(bindings)
}

/// The kind of a texture or sampler variable of type `ty`, or why the project cannot bind
/// it.
fn handle_kind(module: &naga::Module, ty: naga::Handle<naga::Type>) -> Result<BindingKind, String> {
    match module.types[ty].inner {
        naga::TypeInner::Image { dim, arrayed, class } => {
            let dimension = TextureDimension::of(dim, arrayed).ok_or_else(|| {
                format!("{} textures are not supported (1d, 2d, 2d_array and 3d are)", type_name(module, ty))
            })?;
            match class {
                naga::ImageClass::Sampled { kind, multi: false } => {
                    let kind = match kind {
                        naga::ScalarKind::Float => TexelKind::Float,
                        naga::ScalarKind::Sint => TexelKind::Sint,
                        naga::ScalarKind::Uint => TexelKind::Uint,
                        _ => return Err(format!("{} has no texel kind", type_name(module, ty))),
                    };
                    Ok(BindingKind::SampledTexture { dimension, kind })
                }
                naga::ImageClass::Storage { format, access } => {
                    let format = TexelFormat::of(format).ok_or_else(|| {
                        let supported: Vec<&str> = TexelFormat::ALL.iter().map(|f| f.wgsl()).collect();
                        format!("storage format {format:?} is not supported (supported: {})", supported.join(", "))
                    })?;
                    Ok(BindingKind::StorageTexture { dimension, format, access: StorageTextureAccess::of(access) })
                }
                _ => Err(format!(
                    "{} is not supported (multisampled, depth and external textures)",
                    type_name(module, ty)
                )),
            }
        }
        naga::TypeInner::Sampler { comparison: false } => Ok(BindingKind::Sampler),
        _ => Err(format!(
            "{} cannot be bound (comparison samplers and binding arrays are not supported)",
            type_name(module, ty)
        )),
    }
}

/// Every registry kernel, loaded.
#[derive(Debug)]
pub struct Registry {
    kernels: Vec<Kernel>,
    /// Per [`Specialisation::index`] and per kernel (in `kernels`' order), the kernel
    /// specialised with the values it reaches that are not their defaults (`None`: it
    /// reaches none, and is itself), made on first use: a renderer that asks for one
    /// kernel does not load the others.
    variants: [Vec<VariantSlot>; Specialisation::COUNT],
}

/// One kernel's specialisation, made on first use ([`Registry::specialised`]): `None`
/// where the kernel is itself.
type VariantSlot = std::sync::OnceLock<Result<Option<Kernel>, KernelError>>;

/// The `override` of the ReSTIR kernels (`restir/reservoir.wgsl`) that keeps random
/// replay's path re-trace in the pipeline (the default, `true`).
pub const RANDOM_REPLAY: &str = "random_replay";

/// The `override` of every kernel that reads the scene (`render/scene.wgsl`) that reads
/// its rows from their uniform copy instead of the storage buffer (default `false`).
pub const SCENE_IN_UNIFORM: &str = "scene_in_uniform";

/// Values for the registry kernels' `override` constants ([`Registry::specialised`]):
/// what a renderer knows before its first dispatch. [`Default`] is every override's own
/// default, i.e. the kernels as written.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Specialisation {
    /// [`RANDOM_REPLAY`]: some pixel may resample by random replay (`RestirParams.replay`
    /// on). Without it the replayed path's re-trace is dropped as dead code (on lavapipe,
    /// which runs every branch under a mask, about 45 % of `restir_select`'s time).
    pub random_replay: bool,
    /// [`SCENE_IN_UNIFORM`]: the scene's rows fit its uniform copy
    /// (`SCENE_UNIFORM_ROWS`) and are read from there (on lavapipe the path tracer takes
    /// 27 % less time a sample).
    pub scene_in_uniform: bool,
}

impl Default for Specialisation {
    fn default() -> Self {
        Self { random_replay: true, scene_in_uniform: false }
    }
}

impl Specialisation {
    /// How many distinct specialisations there are.
    const COUNT: usize = 4;

    /// Every specialisation.
    pub const ALL: [Specialisation; Self::COUNT] = [
        Specialisation { random_replay: true, scene_in_uniform: false },
        Specialisation { random_replay: false, scene_in_uniform: false },
        Specialisation { random_replay: true, scene_in_uniform: true },
        Specialisation { random_replay: false, scene_in_uniform: true },
    ];

    /// The specialisation `kernel` was made with: its overrides' values, the defaults for
    /// those it was not given (a registry kernel from [`Registry::specialised`] or
    /// [`Registry::get`]; any other override is ignored).
    pub fn of(kernel: &Kernel) -> Specialisation {
        let mut specialisation = Specialisation::default();
        for (name, value) in kernel.overrides() {
            match name.as_str() {
                RANDOM_REPLAY => specialisation.random_replay = *value != 0.0,
                SCENE_IN_UNIFORM => specialisation.scene_in_uniform = *value != 0.0,
                _ => {}
            }
        }
        specialisation
    }

    /// Its slot among the [`Self::COUNT`].
    fn index(self) -> usize {
        usize::from(self.random_replay) | usize::from(self.scene_in_uniform) << 1
    }

    /// The overrides `kernel` reaches whose value here is not their default, as
    /// [`Kernel::load_with_overrides`] takes them (none: the kernel as it is).
    fn overrides_for(self, kernel: &Kernel) -> Vec<(String, f64)> {
        let defaults = Self::default();
        [
            (RANDOM_REPLAY, self.random_replay, defaults.random_replay),
            (SCENE_IN_UNIFORM, self.scene_in_uniform, defaults.scene_in_uniform),
        ]
        .into_iter()
        .filter(|&(name, value, default)| value != default && kernel.uses_override(name))
        .map(|(name, value, _)| (name.to_string(), f64::from(u8::from(value))))
        .collect()
    }
}

impl Registry {
    /// The registry of this process, loaded on first use.
    pub fn shared() -> Result<&'static Registry, KernelError> {
        static SHARED: std::sync::OnceLock<Result<Registry, KernelError>> = std::sync::OnceLock::new();
        SHARED.get_or_init(Registry::load).as_ref().map_err(Clone::clone)
    }

    /// Loads every kernel of [`KernelId::ALL`].
    pub fn load() -> Result<Registry, KernelError> {
        let kernels: Vec<Kernel> = KernelId::ALL.iter().map(|&id| Kernel::load(id)).collect::<Result<_, _>>()?;
        let variants = std::array::from_fn(|_| kernels.iter().map(|_| std::sync::OnceLock::new()).collect());
        Ok(Registry { kernels, variants })
    }

    /// Kernel `id` with its `override` constants given the values of `specialisation`:
    /// specialised where it reaches one whose value there is not its default (so that a
    /// driver drops the other side of each such branch as dead code), the kernel itself
    /// elsewhere. Its outputs are the general kernel's wherever the specialisation holds
    /// (no pixel replays; the scene fits its uniform copy).
    pub fn specialised(&self, id: KernelId, specialisation: Specialisation) -> Result<&Kernel, KernelError> {
        let index = self.kernels.iter().position(|k| k.id == id).expect("the registry loads every KernelId");
        let general = &self.kernels[index];
        let variant = self.variants[specialisation.index()][index]
            .get_or_init(|| {
                let overrides = specialisation.overrides_for(general);
                if overrides.is_empty() { Ok(None) } else { Kernel::load_with_overrides(id, &overrides).map(Some) }
            })
            .as_ref()
            .map_err(Clone::clone)?;
        Ok(variant.as_ref().unwrap_or(general))
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
    use crate::fragment;

    #[test]
    fn specialised_kernels_are_specialised_and_cached_apart() {
        let registry = Registry::load().unwrap_or_else(|e| panic!("{e}"));
        let without_replay = Specialisation { random_replay: false, ..Specialisation::default() };
        for id in [KernelId::RestirSelect, KernelId::RestirSpatial, KernelId::RestirTemporal, KernelId::RestirShade] {
            let general = registry.get(id);
            assert!(general.uses_override(RANDOM_REPLAY), "{id:?}");
            assert!(general.overrides().is_empty(), "{id:?}");
            let specialised = registry.specialised(id, without_replay).unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(specialised.overrides(), [(RANDOM_REPLAY.to_string(), 0.0)], "{id:?}");
            assert_ne!(specialised.pipeline_key(), general.pipeline_key(), "{id:?}");
            assert_eq!(specialised.bindings, general.bindings, "{id:?}");
        }
        // A kernel that declares the override (through restir/reservoir.wgsl) but never
        // reaches it, or does not declare it, is itself: a copy would be the same module
        // compiled twice. So is every kernel under the defaults.
        for id in
            [KernelId::RestirCandidates, KernelId::RestirReservoirKeys, KernelId::RestirGuide, KernelId::PathTrace]
        {
            let kernel = registry.get(id);
            assert!(!kernel.uses_override(RANDOM_REPLAY), "{id:?}");
            let same = registry.specialised(id, without_replay).unwrap_or_else(|e| panic!("{e}"));
            assert!(std::ptr::eq(same, kernel), "{id:?}");
        }
        for specialisation in Specialisation::ALL {
            for id in [KernelId::PathTrace, KernelId::RestirSelect] {
                let kernel = registry.specialised(id, specialisation).unwrap_or_else(|e| panic!("{e}"));
                let expected = Specialisation {
                    random_replay: specialisation.random_replay || !kernel.uses_override(RANDOM_REPLAY),
                    ..specialisation
                };
                assert_eq!(Specialisation::of(kernel), expected, "{id:?}");
            }
        }
        let slots: std::collections::HashSet<usize> = Specialisation::ALL.iter().map(|s| s.index()).collect();
        assert_eq!(slots.len(), Specialisation::COUNT, "two specialisations share a slot");
        for kernel in registry.kernels() {
            let same = registry.specialised(kernel.id, Specialisation::default()).unwrap_or_else(|e| panic!("{e}"));
            assert!(std::ptr::eq(same, kernel), "{:?}", kernel.id);
        }
        // The scene's uniform copy: every kernel that reads the scene reaches the override;
        // together with no replay, the kernels that reach both get both values. (naga keeps
        // the branch the constant decides, so both bindings stay in the reflection and are
        // bound; the driver drops the dead read when it builds the pipeline.)
        let in_uniform = Specialisation { scene_in_uniform: true, ..Specialisation::default() };
        let both = Specialisation { random_replay: false, scene_in_uniform: true };
        for id in [KernelId::PathTrace, KernelId::RestirCandidates, KernelId::RestirSelect, KernelId::RestirShade] {
            let general = registry.get(id);
            assert!(general.uses_override(SCENE_IN_UNIFORM), "{id:?}");
            assert!(
                general.binding_named("scene_rows").is_some() && general.binding_named("scene_rows_uniform").is_some()
            );
            let specialised = registry.specialised(id, in_uniform).unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(specialised.overrides(), [(SCENE_IN_UNIFORM.to_string(), 1.0)], "{id:?}");
            assert_eq!(specialised.bindings, general.bindings, "{id:?}");
            let both_kernel = registry.specialised(id, both).unwrap_or_else(|e| panic!("{e}"));
            let mut expected = vec![(SCENE_IN_UNIFORM.to_string(), 1.0)];
            if general.uses_override(RANDOM_REPLAY) {
                expected.insert(0, (RANDOM_REPLAY.to_string(), 0.0));
            }
            assert_eq!(both_kernel.overrides(), expected, "{id:?}");
            let distinct = both_kernel.pipeline_key() != specialised.pipeline_key();
            assert_eq!(distinct, general.uses_override(RANDOM_REPLAY), "{id:?}");
        }
        // Specialising compacts a module to what its entry point reaches; `declares` still
        // answers for the source, so that binding a scene buffer the kernel never reads is
        // not an error.
        let keys = registry.get(KernelId::RestirReservoirKeys);
        assert!(keys.declares("scene_rows"));
        assert!(keys.binding_named("scene_rows").is_none());
    }

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

    /// Every registry kernel holds far less private and function memory per invocation
    /// than CPU drivers are allowed (`strata_backends::bindings_check`), so the bound
    /// never refuses the project's own kernels.
    #[test]
    fn registry_kernels_hold_little_private_memory() {
        let registry = Registry::shared().unwrap();
        for id in KernelId::ALL {
            let kernel = registry.get(id);
            let bytes = kernel.private_memory_bytes();
            eprintln!("{}: {bytes} bytes of private and function memory", kernel.name());
            assert!(bytes <= 2048, "{}: {bytes} bytes of private and function memory", kernel.name());
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
