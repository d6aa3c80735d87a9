//! Materials as the renderer uses them, resolved from any scene format: textures are
//! indices into [`super::Scene::textures`], already decoded to linear RGB.

/// A diffuse surface's reflectance (CONVENTIONS.md "Materials").
#[derive(Clone, Debug, PartialEq)]
pub enum Albedo {
    /// Constant linear RGB.
    Constant([f32; 3]),
    /// `color0` where frac(u') > ½ equals frac(v') > ½ with uv' = uv × `uv_scale`,
    /// otherwise `color1`.
    Checkerboard {
        /// First colour.
        color0: [f32; 3],
        /// Second colour.
        color1: [f32; 3],
        /// UV scale.
        uv_scale: [f32; 2],
    },
    /// A texture, bilinear with repeat wrap, looked up at uv × `uv_scale`.
    Texture {
        /// Index into the scene's textures.
        texture: usize,
        /// UV scale.
        uv_scale: [f32; 2],
    },
}

/// A BSDF with its parameters.
#[derive(Clone, Debug, PartialEq)]
pub enum Material {
    /// Lambertian, f = albedo / π.
    Diffuse {
        /// Reflectance.
        albedo: Albedo,
        /// Back-side hits see the front-side BSDF (Mitsuba `twosided`); otherwise black.
        two_sided: bool,
    },
    /// GGX microfacet conductor with exact complex-IOR Fresnel.
    RoughConductor {
        /// GGX alpha (no remapping).
        alpha: f32,
        /// Real part of the IOR per channel.
        eta: [f32; 3],
        /// Imaginary part of the IOR per channel.
        k: [f32; 3],
        /// Back-side hits see the front-side BSDF.
        two_sided: bool,
    },
    /// Smooth dielectric; the geometric normal points outside.
    Dielectric {
        /// Interior IOR.
        int_ior: f32,
        /// Exterior IOR.
        ext_ior: f32,
    },
}

impl Material {
    /// A black diffuse material (light fixtures).
    pub fn black(two_sided: bool) -> Material {
        Material::Diffuse { albedo: Albedo::Constant([0.0; 3]), two_sided }
    }

    /// A constant diffuse material.
    pub fn diffuse(reflectance: [f32; 3]) -> Material {
        Material::Diffuse { albedo: Albedo::Constant(reflectance), two_sided: true }
    }
}
