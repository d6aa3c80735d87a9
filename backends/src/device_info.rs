//! What a backend's device is and what it can do.

/// The device a backend runs on.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct DeviceInfo {
    /// Backend name: `wgpu-vulkan`, `wgpu-gl`, `ash`, `cpu`.
    pub backend: String,
    /// Adapter name reported by the driver, e.g. `llvmpipe (LLVM 15.0.6, 256 bits)`.
    pub adapter: String,
    /// Device type as the driver reports it (`Cpu`, `DiscreteGpu`, ...).
    pub device_type: String,
    /// Driver name and version.
    pub driver: String,
    /// Subgroup sizes (min, max) if compute shaders may use subgroup operations.
    pub subgroup_sizes: Option<(u32, u32)>,
    /// Whether passes can be timed with timestamp queries.
    pub timestamps: bool,
    /// Whether a sampler may filter `r32float` and `rgba32float` textures linearly:
    /// wgpu's `FLOAT32_FILTERABLE` feature (requested where the adapter has it), the
    /// formats' `SAMPLED_IMAGE_FILTER_LINEAR` feature on ash, always on the interpreter.
    /// Where false, a linear sampler on such a texture is refused before binding
    /// ([`crate::bindings_check::check_binds`]).
    pub float32_filterable: bool,
    /// Limits the kernels must fit in.
    pub limits: DeviceLimits,
}

impl DeviceInfo {
    /// Whether this is a Vulkan or GL driver running on the CPU (lavapipe, llvmpipe), not
    /// strata's interpreter.
    pub fn is_cpu_driver(&self) -> bool {
        self.device_type.eq_ignore_ascii_case("cpu") && !self.is_interpreter()
    }

    /// Whether this is strata's CPU interpreter of naga IR (the `cpu` backend).
    pub fn is_interpreter(&self) -> bool {
        self.backend == "cpu"
    }

    /// One line for people: backend, adapter, type.
    pub fn summary(&self) -> String {
        format!("{} on {} ({}, {})", self.backend, self.adapter, self.device_type, self.driver)
    }
}

/// The device limits that matter to compute kernels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DeviceLimits {
    /// Bytes of workgroup memory per workgroup.
    pub max_workgroup_storage: u64,
    /// Invocations per workgroup.
    pub max_invocations_per_workgroup: u32,
    /// Workgroup size per dimension.
    pub max_workgroup_size: [u32; 3],
    /// Workgroups per dispatch dimension.
    pub max_workgroups_per_dimension: u32,
    /// Bytes of one storage buffer binding.
    pub max_storage_binding: u64,
    /// Bytes of one uniform buffer binding.
    pub max_uniform_binding: u64,
    /// Bytes of one buffer.
    pub max_buffer_size: u64,
    /// Storage buffers per shader stage.
    pub max_storage_buffers_per_stage: u32,
    /// Width and height of a 1-D or 2-D texture.
    pub max_texture_2d: u32,
    /// Each axis of a 3-D texture.
    pub max_texture_3d: u32,
    /// Layers of a 2-D array texture.
    pub max_texture_layers: u32,
    /// Bind groups (descriptor sets) of one pipeline.
    pub max_bind_groups: u32,
}
