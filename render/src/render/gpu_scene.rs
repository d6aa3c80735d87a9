//! A [`Scene`] flattened into the arrays the path-tracing kernels read
//! (`kernels/wgsl/render/scene.wgsl`): the BVH with its triangles in leaf order,
//! per-triangle attributes, materials, emissive triangles with their selection CDF,
//! texels and the environment's sampling CDFs.

use super::environment_cdf::{environment_cdf, luminance};
use crate::histogram_pass::PassError;
use crate::scene::{Albedo, Material, Scene};
use crate::trace_pass::build_obvhs;
use glam::Vec3;
use strata_kernels::render_types::{
    ALBEDO_CHECKERBOARD, ALBEDO_CONSTANT, ALBEDO_TEXTURE, EmissiveTriangle, GpuMaterial, MATERIAL_CONDUCTOR,
    MATERIAL_DIELECTRIC, MATERIAL_DIFFUSE, NO_LIGHT, RenderParams, TriangleInfo,
};
use strata_kernels::trace_types::{GpuBvhNode, GpuTriangle};

/// The scene's arrays, ready to upload, and the scene-wide part of [`RenderParams`].
pub struct GpuScene {
    /// BVH nodes (root at 0).
    pub nodes: Vec<GpuBvhNode>,
    /// Triangles in leaf order: leaf slot i holds `triangles[i]`.
    pub triangles: Vec<GpuTriangle>,
    /// Attributes of `triangles[i]`.
    pub triangle_info: Vec<TriangleInfo>,
    /// Materials.
    pub materials: Vec<GpuMaterial>,
    /// Emissive triangles (one placeholder entry when there are none; see `light_count`).
    pub lights: Vec<EmissiveTriangle>,
    /// Texels: every texture, then the environment map (one placeholder when empty).
    pub texels: Vec<[f32; 4]>,
    /// Environment CDFs (one placeholder entry without an environment).
    pub environment_cdf: Vec<f32>,
    /// Scene-wide parameters: light count, environment, ray epsilon. The camera, image
    /// size, sample index, seed, depths and flags are filled per render.
    pub params: RenderParams,
}

fn triangle_area(t: &[[f32; 3]; 3]) -> f32 {
    let [a, b, c] = t.map(Vec3::from);
    0.5 * (b - a).cross(c - a).length()
}

fn gpu_material(material: &Material, texture_offsets: &[(u32, u32, u32)]) -> GpuMaterial {
    let mut gpu = GpuMaterial { uv_scale: [1.0, 1.0], ..Default::default() };
    match material {
        Material::Diffuse { albedo, two_sided } => {
            gpu.kind = MATERIAL_DIFFUSE;
            gpu.two_sided = u32::from(*two_sided);
            match albedo {
                Albedo::Constant(c) => {
                    gpu.albedo_kind = ALBEDO_CONSTANT;
                    gpu.color0 = *c;
                }
                Albedo::Checkerboard { color0, color1, uv_scale } => {
                    gpu.albedo_kind = ALBEDO_CHECKERBOARD;
                    gpu.color0 = *color0;
                    gpu.color1 = *color1;
                    gpu.uv_scale = *uv_scale;
                }
                Albedo::Texture { texture, uv_scale } => {
                    let (offset, width, height) = texture_offsets[*texture];
                    gpu.albedo_kind = ALBEDO_TEXTURE;
                    gpu.texel_offset = offset;
                    gpu.texture_width = width;
                    gpu.texture_height = height;
                    gpu.uv_scale = *uv_scale;
                }
            }
        }
        Material::RoughConductor { alpha, eta, k, two_sided } => {
            gpu.kind = MATERIAL_CONDUCTOR;
            gpu.two_sided = u32::from(*two_sided);
            gpu.alpha = *alpha;
            gpu.color0 = *eta;
            gpu.color1 = *k;
        }
        Material::Dielectric { int_ior, ext_ior } => {
            gpu.kind = MATERIAL_DIELECTRIC;
            gpu.eta = int_ior / ext_ior;
        }
    }
    gpu
}

impl GpuScene {
    /// Flattens `scene`. Errors name what the kernels cannot take: no triangles, a
    /// material index out of range, NaN emission.
    pub fn build(scene: &Scene) -> Result<GpuScene, PassError> {
        let mut triangles = Vec::new();
        let mut info = Vec::new();
        let mut emission = Vec::new();
        for shape in &scene.shapes {
            if shape.material >= scene.materials.len() {
                return Err(PassError::Input(format!(
                    "shape `{}` names material {} of {}",
                    shape.name,
                    shape.material,
                    scene.materials.len()
                )));
            }
            if let Some(radiance) = shape.emission
                && radiance.iter().any(|c| !c.is_finite() || *c < 0.0)
            {
                return Err(PassError::Input(format!(
                    "shape `{}`: emitted radiance {radiance:?} must be finite and non-negative",
                    shape.name
                )));
            }
            for (index, triangle) in shape.triangles.iter().enumerate() {
                triangles.push(*triangle);
                let uv = shape.uvs.as_ref().map(|uvs| uvs[index]);
                info.push(TriangleInfo {
                    object_id: shape.object_id,
                    material: shape.material as u32,
                    light: NO_LIGHT,
                    has_uv: u32::from(uv.is_some()),
                    uv0: uv.map_or([0.0; 2], |uv| uv[0]),
                    uv1: uv.map_or([0.0; 2], |uv| uv[1]),
                    uv2: uv.map_or([0.0; 2], |uv| uv[2]),
                    _pad0: 0,
                    _pad1: 0,
                });
                emission.push(shape.emission.filter(|r| luminance(*r) > 0.0));
            }
        }
        if triangles.is_empty() {
            return Err(PassError::Input(format!("scene `{}` has no triangles", scene.name)));
        }
        if let Some(index) = triangles.iter().position(|t| t.iter().flatten().any(|c| !c.is_finite())) {
            return Err(PassError::Input(format!("triangle {index} has a NaN or infinite coordinate")));
        }
        let (tris, bvh) = build_obvhs(&triangles);
        let order = &bvh.primitive_indices;
        let leaf_triangles: Vec<GpuTriangle> =
            order.iter().map(|&i| bytemuck::cast(tris[i as usize])).collect::<Vec<GpuTriangle>>();
        let mut triangle_info: Vec<TriangleInfo> = order.iter().map(|&i| info[i as usize]).collect();

        // Emissive triangles, selected in proportion to luminance × area.
        let mut lights = Vec::new();
        for (slot, &original) in order.iter().enumerate() {
            let Some(radiance) = emission[original as usize] else { continue };
            let area = triangle_area(&triangles[original as usize]);
            if area <= 0.0 {
                continue;
            }
            triangle_info[slot].light = lights.len() as u32;
            lights.push(EmissiveTriangle {
                radiance,
                triangle: slot as u32,
                area,
                probability: luminance(radiance) * area,
                ..Default::default()
            });
        }
        let total: f64 = lights.iter().map(|l| f64::from(l.probability)).sum();
        let mut running = 0.0f64;
        for light in &mut lights {
            running += f64::from(light.probability);
            light.probability = (f64::from(light.probability) / total) as f32;
            light.cdf = (running / total) as f32;
        }
        if let Some(last) = lights.last_mut() {
            last.cdf = 1.0;
        }

        // Texels: textures first, then the environment.
        let mut texels: Vec<[f32; 4]> = Vec::new();
        let mut texture_offsets = Vec::new();
        for texture in &scene.textures {
            texture_offsets.push((texels.len() as u32, texture.width, texture.height));
            texels.extend(texture.texels.iter().map(|t| [t[0], t[1], t[2], 0.0]));
        }
        let materials: Vec<GpuMaterial> = scene.materials.iter().map(|m| gpu_material(m, &texture_offsets)).collect();

        let mut params = RenderParams { light_count: lights.len() as u32, ray_epsilon: 1e-4, ..Default::default() };
        let mut cdf = Vec::new();
        if let Some(environment) = &scene.environment {
            params.env_texel_offset = texels.len() as u32;
            params.env_width = environment.width;
            params.env_height = environment.height;
            params.env_scale = environment.scale;
            let r = environment.to_world;
            [params.env_to_world_0, params.env_to_world_1, params.env_to_world_2] = r;
            // R is a rotation (checked on load): its inverse is its transpose.
            params.env_from_world_0 = [r[0][0], r[1][0], r[2][0]];
            params.env_from_world_1 = [r[0][1], r[1][1], r[2][1]];
            params.env_from_world_2 = [r[0][2], r[1][2], r[2][2]];
            texels.extend(environment.texels.iter().map(|t| [t[0], t[1], t[2], 0.0]));
            if let Some(environment_cdf) = environment_cdf(environment).filter(|_| environment.scale > 0.0) {
                cdf = environment_cdf;
                params.environment_probability = if lights.is_empty() { 1.0 } else { 0.5 };
            }
        }
        if lights.is_empty() && params.environment_probability == 0.0 {
            return Err(PassError::Input(format!(
                "scene `{}` has no light: no shape emits and there is no environment with radiance, so every \
                 image would be black",
                scene.name
            )));
        }
        if lights.is_empty() {
            lights.push(EmissiveTriangle::default());
        }
        if texels.is_empty() {
            texels.push([0.0; 4]);
        }
        if cdf.is_empty() {
            cdf.push(0.0);
        }
        let mut gpu = GpuScene {
            nodes: bytemuck::cast_slice(&bvh.nodes).to_vec(),
            triangles: leaf_triangles,
            triangle_info,
            materials,
            lights,
            texels,
            environment_cdf: cdf,
            params,
        };
        let [nodes_row, triangles_row, triangle_info_row, materials_row, lights_row, texels_row, environment_cdf_row] =
            gpu.first_rows().map_err(|rows| {
                PassError::Input(format!(
                    "scene `{}` is too large: its arrays take {rows} rows of 16 bytes, more than a u32 counts",
                    scene.name
                ))
            })?;
        gpu.params = RenderParams {
            nodes_row,
            triangles_row,
            triangle_info_row,
            materials_row,
            lights_row,
            texels_row,
            environment_cdf_row,
            ..gpu.params
        };
        Ok(gpu)
    }

    /// The arrays as bytes, in the order they lie in the rows, with their names for errors.
    pub fn sections(&self) -> [(&'static str, &[u8]); 7] {
        [
            ("BVH nodes", bytemuck::cast_slice(&self.nodes)),
            ("triangles", bytemuck::cast_slice(&self.triangles)),
            ("triangle attributes", bytemuck::cast_slice(&self.triangle_info)),
            ("materials", bytemuck::cast_slice(&self.materials)),
            ("emissive triangles", bytemuck::cast_slice(&self.lights)),
            ("texels", bytemuck::cast_slice(&self.texels)),
            ("environment CDF", bytemuck::cast_slice(&self.environment_cdf)),
        ]
    }

    /// How many 16-byte rows each of [`Self::sections`] takes (its last one padded).
    fn section_rows(&self) -> [u64; 7] {
        self.sections().map(|(_, bytes)| (bytes.len() as u64).div_ceil(16))
    }

    /// The size in bytes of [`Self::rows`], without building it.
    pub fn rows_size(&self) -> u64 {
        self.section_rows().iter().sum::<u64>() * 16
    }

    /// Whether its rows fit their uniform copy (`SCENE_UNIFORM_ROWS`, `render/scene.wgsl`),
    /// from which the kernels then read them (on lavapipe much faster than from the
    /// storage buffer).
    pub fn fits_uniform_copy(&self) -> bool {
        self.rows_size() <= u64::from(strata_kernels::render_types::SCENE_UNIFORM_ROWS) * 16
    }

    /// The row at which each of [`Self::sections`] starts, or the total row count when it
    /// does not fit a `u32`.
    fn first_rows(&self) -> Result<[u32; 7], u64> {
        let mut first = [0u32; 7];
        let mut rows = 0u64;
        for (slot, count) in first.iter_mut().zip(self.section_rows()) {
            *slot = u32::try_from(rows).map_err(|_| rows)?;
            rows += count;
        }
        u32::try_from(rows).map_err(|_| rows)?;
        Ok(first)
    }

    /// The scene's rows (`scene_rows` of `render/scene.wgsl`, and its uniform copy
    /// `scene_rows_uniform` when they fit): every array of
    /// [`Self::sections`] in 16-byte rows from the row `params` gives it, each record laid
    /// out as in its own array (the CDF's last row padded with zeros).
    pub fn rows(&self) -> Vec<[u32; 4]> {
        let mut rows = Vec::new();
        for ((_, bytes), count) in self.sections().into_iter().zip(self.section_rows()) {
            let start = rows.len();
            rows.resize(start + count as usize, [0u32; 4]);
            bytemuck::cast_slice_mut::<[u32; 4], u8>(&mut rows[start..])[..bytes.len()].copy_from_slice(bytes);
        }
        rows
    }

    /// Number of emissive triangles.
    pub fn light_count(&self) -> u32 {
        self.params.light_count
    }
}
