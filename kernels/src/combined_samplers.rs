//! Which sampler each sampled texture is combined with in naga's GLSL.
//!
//! GLSL for Vulkan has separate textures and samplers, but naga's GLSL writer targets
//! OpenGL: it declares every sampled texture as a combined image sampler (`sampler2D`)
//! at the texture's binding, sampling with the sampler the WGSL pairs it with, and drops
//! the sampler's own binding. A Vulkan runner of that GLSL (strata's `ash-glsl` path)
//! therefore binds one `COMBINED_IMAGE_SAMPLER` per sampled texture, holding the paired
//! sampler's state (any sampler for a texture that is only loaded), and nothing for the
//! samplers.

use crate::binding::BindingKind;
use crate::registry::Kernel;
use naga::{Expression, Handle};

/// A sampled texture's `(group, binding)` and its sampler's, if it is sampled.
pub type Pair = ((u32, u32), Option<(u32, u32)>);

/// Per sampled texture of `kernel` (its `(group, binding)`), the `(group, binding)` of
/// the sampler it is sampled with, `None` when it is only loaded; an error naming a texture sampled with two
/// samplers (two combined samplers at one binding) or through a function argument
/// (whose pairing naga resolves per call).
pub fn combined_samplers(kernel: &Kernel) -> Result<Vec<Pair>, String> {
    let module = &kernel.module;
    let binding_of = |function: &naga::Function, h: Handle<Expression>| match function.expressions[h] {
        Expression::GlobalVariable(g) => {
            Ok(module.global_variables[g].binding.as_ref().map_or((u32::MAX, u32::MAX), |b| (b.group, b.binding)))
        }
        _ => Err("a texture sampled through a function argument".to_string()),
    };
    let mut pairs: Vec<Pair> = kernel
        .bindings
        .iter()
        .filter(|b| matches!(b.kind, BindingKind::SampledTexture { .. }))
        .map(|b| ((b.group, b.binding), None))
        .collect();
    let functions = module.functions.iter().map(|(_, f)| f).chain(module.entry_points.iter().map(|e| &e.function));
    for function in functions {
        for (_, expression) in function.expressions.iter() {
            let Expression::ImageSample { image, sampler, .. } = *expression else { continue };
            let (texture, sampler) = (binding_of(function, image)?, binding_of(function, sampler)?);
            let Some(pair) = pairs.iter_mut().find(|(t, _)| *t == texture) else { continue };
            match pair.1 {
                Some(other) if other != sampler => {
                    return Err(format!(
                        "texture at binding {} sampled with the samplers at bindings {} and {}",
                        texture.1, other.1, sampler.1
                    ));
                }
                _ => pair.1 = Some(sampler),
            }
        }
    }
    Ok(pairs)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_sampled_texture_is_paired_with_its_sampler_and_two_samplers_are_refused() {
        let source = "@group(0) @binding(0) var a: texture_2d<f32>;
            @group(0) @binding(1) var b: texture_2d<f32>;
            @group(0) @binding(2) var s: sampler;
            @group(0) @binding(3) var t: sampler;
            @group(0) @binding(4) var<storage, read_write> o: array<vec4<f32>>;
            @compute @workgroup_size(1) fn main() {
                o[0] = textureSampleLevel(a, s, vec2(0.5), 0.0) + textureLoad(b, vec2(0), 0);
            }";
        let kernel = Kernel::from_wgsl("pairs.wgsl", source.into(), "main", false).unwrap();
        assert_eq!(combined_samplers(&kernel), Ok(vec![((0, 0), Some((0, 2))), ((0, 1), None)]));
        let twice = source.replace("textureLoad(b, vec2(0), 0)", "textureSampleLevel(a, t, vec2(0.5), 0.0)");
        let kernel = Kernel::from_wgsl("twice.wgsl", twice, "main", false).unwrap();
        assert!(combined_samplers(&kernel).unwrap_err().contains("bindings 2 and 3"));
    }
}
