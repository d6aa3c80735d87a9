//! The JSON scene description of `scenes/*/scene.json` (the shared test scenes), as serde types.

use super::SceneError;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Pinhole camera (CONVENTIONS.md "Camera").
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Camera {
    /// Eye position.
    pub origin: [f32; 3],
    /// Point looked at.
    pub target: [f32; 3],
    /// Up vector.
    pub up: [f32; 3],
    /// Full opening angle along `fov_axis`, degrees.
    pub fov_deg: f32,
    /// `x` (horizontal) or `smaller` (the smaller image side).
    pub fov_axis: String,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Near clip distance.
    pub near_clip: f32,
    /// Far clip distance.
    pub far_clip: f32,
}

/// Integrator settings.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Integrator {
    /// Always `path`.
    #[serde(rename = "type")]
    pub kind: String,
    /// Maximum path segments including the camera ray.
    pub max_depth: u32,
    /// Russian roulette start depth.
    pub rr_depth: u32,
    /// Whether emitters are hidden from camera rays (false in every scene).
    pub hide_emitters: bool,
}

/// Diffuse reflectance: a constant, a checkerboard or an sRGB texture. Read by its shape
/// (an array, an object with `checkerboard`, an object with `texture`), each object form
/// refusing fields it does not know, as every other object of the file does.
#[derive(Clone, Debug, PartialEq)]
pub enum Reflectance {
    /// Constant linear RGB.
    Constant([f32; 3]),
    /// Checkerboard.
    Checkerboard {
        /// Its colours and scale.
        checkerboard: Checkerboard,
    },
    /// An 8-bit sRGB PNG, bilinear, repeat.
    Texture {
        /// File relative to the scene folder.
        texture: PathBuf,
        /// Whether the file is sRGB-encoded.
        srgb: bool,
        /// Filter (`bilinear`).
        filter: Option<String>,
        /// Wrap mode (`repeat`).
        wrap: Option<String>,
        /// UV scale.
        uv_scale: Option<[f32; 2]>,
    },
}

impl<'de> Deserialize<'de> for Reflectance {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_any(ReflectanceVisitor)
    }
}

/// Reads a [`Reflectance`] by its shape, field by field (so that an error names the
/// field, and a field given twice or unknown is refused).
struct ReflectanceVisitor;

/// The fields of the object forms.
const REFLECTANCE_FIELDS: &[&str] = &["checkerboard", "texture", "srgb", "filter", "wrap", "uv_scale"];

impl<'de> serde::de::Visitor<'de> for ReflectanceVisitor {
    type Value = Reflectance;

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("[r, g, b], {\"checkerboard\": {...}} or {\"texture\": \"file.png\", ...}")
    }

    fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> Result<Reflectance, A::Error> {
        use serde::de::Error;
        let mut rgb = [0.0f32; 3];
        for (i, c) in rgb.iter_mut().enumerate() {
            *c = seq.next_element()?.ok_or_else(|| A::Error::invalid_length(i, &"three numbers"))?;
        }
        if seq.next_element::<serde::de::IgnoredAny>()?.is_some() {
            return Err(A::Error::invalid_length(4, &"three numbers"));
        }
        Ok(Reflectance::Constant(rgb))
    }

    fn visit_map<A: serde::de::MapAccess<'de>>(self, mut map: A) -> Result<Reflectance, A::Error> {
        use serde::de::Error;
        let mut checkerboard: Option<Checkerboard> = None;
        let mut texture: Option<PathBuf> = None;
        let (mut srgb, mut filter, mut wrap, mut uv_scale) = (None, None, None, None);
        let mut seen: Vec<String> = Vec::new();
        while let Some(key) = map.next_key::<String>()? {
            if seen.contains(&key) {
                return Err(A::Error::custom(format!("duplicate field `{key}`")));
            }
            match key.as_str() {
                "checkerboard" => checkerboard = Some(map.next_value()?),
                "texture" => texture = Some(map.next_value()?),
                "srgb" => srgb = Some(map.next_value::<bool>()?),
                "filter" => filter = map.next_value::<Option<String>>()?,
                "wrap" => wrap = map.next_value::<Option<String>>()?,
                "uv_scale" => uv_scale = map.next_value::<Option<[f32; 2]>>()?,
                other => return Err(A::Error::unknown_field(other, REFLECTANCE_FIELDS)),
            }
            seen.push(key);
        }
        match (checkerboard, texture) {
            (Some(checkerboard), None) if seen.len() == 1 => Ok(Reflectance::Checkerboard { checkerboard }),
            (Some(_), _) => Err(A::Error::custom("a checkerboard takes no other field beside it")),
            (None, Some(texture)) => {
                Ok(Reflectance::Texture { texture, srgb: srgb.unwrap_or(false), filter, wrap, uv_scale })
            }
            (None, None) => Err(A::Error::custom("expected `checkerboard` or `texture`")),
        }
    }
}

/// Reads a map whose keys must be distinct (serde's maps keep the last of two equal
/// keys without a word): `materials`, where a name defined twice is an error.
fn distinct_keys<'de, D, V>(deserializer: D) -> Result<BTreeMap<String, V>, D::Error>
where
    D: serde::Deserializer<'de>,
    V: Deserialize<'de>,
{
    struct Visitor<V>(std::marker::PhantomData<V>);
    impl<'de, V: Deserialize<'de>> serde::de::Visitor<'de> for Visitor<V> {
        type Value = BTreeMap<String, V>;
        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            f.write_str("an object of materials by name")
        }
        fn visit_map<A: serde::de::MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
            let mut out = BTreeMap::new();
            while let Some(key) = map.next_key::<String>()? {
                if out.contains_key(&key) {
                    return Err(serde::de::Error::custom(format!("`{key}` is defined twice")));
                }
                let value = map.next_value()?;
                out.insert(key, value);
            }
            Ok(out)
        }
    }
    deserializer.deserialize_map(Visitor(std::marker::PhantomData))
}

/// Checkerboard parameters (CONVENTIONS.md).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Checkerboard {
    /// Colour where frac(u') > 0.5 equals frac(v') > 0.5.
    pub color0: [f32; 3],
    /// The other colour.
    pub color1: [f32; 3],
    /// uv' = uv * uv_scale.
    pub uv_scale: [f32; 2],
}

/// A material, by its `type`.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
pub enum MaterialDescription {
    /// Lambertian.
    Diffuse {
        /// Reflectance.
        reflectance: Reflectance,
        /// Two-sided.
        #[serde(default)]
        two_sided: bool,
    },
    /// Diffuse with reflectance 0 (light fixtures).
    Black {
        /// Two-sided.
        #[serde(default)]
        two_sided: bool,
    },
    /// GGX rough conductor with complex IOR.
    Roughconductor {
        /// Microfacet distribution (`ggx`).
        distribution: String,
        /// GGX alpha.
        alpha: f32,
        /// Real part of the IOR per channel.
        eta: [f32; 3],
        /// Imaginary part of the IOR per channel.
        k: [f32; 3],
        /// Two-sided.
        #[serde(default)]
        two_sided: bool,
    },
    /// Smooth dielectric.
    Dielectric {
        /// Interior IOR.
        int_ior: f32,
        /// Exterior IOR.
        ext_ior: f32,
        /// Two-sided (false for glass).
        #[serde(default)]
        two_sided: bool,
    },
}

/// A one-sided area emitter.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct EmitterDescription {
    /// Constant RGB radiance.
    pub radiance: [f32; 3],
}

/// A lat-long environment map.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct EnvironmentDescription {
    /// RGB float EXR (relative to the scene folder in the file; resolved on load).
    pub file: PathBuf,
    /// Radiance scale.
    pub scale: f32,
    /// Row-major 4 × 4 transform; its upper-left 3 × 3 rotates the map.
    #[serde(default)]
    pub to_world: Option<[[f32; 4]; 4]>,
}

/// One shape entry.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ShapeDescription {
    /// Shape id.
    pub id: String,
    /// PLY file relative to the scene folder.
    pub mesh: PathBuf,
    /// Material name.
    pub material: String,
    /// Normal mode (`face`: geometric normals).
    #[serde(default)]
    pub normals: Option<String>,
    /// Emission, if any.
    #[serde(default)]
    pub emitter: Option<EmitterDescription>,
}

/// A whole `scene.json`.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SceneDescription {
    /// Name.
    pub name: String,
    /// Free-text coordinate system note.
    #[serde(default)]
    pub coordinate_system: Option<String>,
    /// Camera.
    pub camera: Camera,
    /// Integrator.
    pub integrator: Integrator,
    /// Materials by name (each name once).
    #[serde(deserialize_with = "distinct_keys")]
    pub materials: BTreeMap<String, MaterialDescription>,
    /// Shapes.
    pub shapes: Vec<ShapeDescription>,
    /// Environment map, if any.
    #[serde(default)]
    pub environment: Option<EnvironmentDescription>,
}

/// Parses `text` (the contents of `path`), naming the field at fault on error. Nothing
/// but white space may follow the scene's object.
pub(super) fn parse(path: &Path, text: &str) -> Result<SceneDescription, SceneError> {
    let deserializer = &mut serde_json::Deserializer::from_str(text);
    let description = serde_path_to_error::deserialize(&mut *deserializer).map_err(|error| SceneError::Json {
        path: path.into(),
        field: error.path().to_string(),
        message: error.inner().to_string(),
    })?;
    deserializer.end().map_err(|error| SceneError::Json {
        path: path.into(),
        field: "(after the scene)".into(),
        message: format!("{error}: nothing may follow the scene's closing brace"),
    })?;
    Ok(description)
}
