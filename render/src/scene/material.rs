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

/// The smallest GGX alpha the renderer samples: 10⁻³. Below it the kernels' GGX
/// terms leave single precision (alpha 10⁻³⁰ made every sample of such a surface NaN, and
/// the render failed naming no field), and the lobe, 0.06° wide, is already narrower than
/// a pixel at the usual fields of view: a smoother conductor is a mirror to the eye.
pub const MIN_ALPHA: f32 = 1e-3;

/// The one rule every loader (JSON `roughconductor` `alpha`, OBJ `Pr`/`Ns`, glTF
/// `roughnessFactor`) applies to a GGX alpha: one below [`MIN_ALPHA`] (a mirror, or a
/// near one) is rendered at [`MIN_ALPHA`]; the caller has refused one that is not finite
/// and positive.
pub fn ggx_alpha(alpha: f32) -> f32 {
    alpha.max(MIN_ALPHA)
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
        /// GGX alpha (no remapping), at least [`MIN_ALPHA`] as every loader makes it
        /// ([`ggx_alpha`]).
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
