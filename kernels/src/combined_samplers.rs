//! Which sampler each sampled texture is combined with in naga's GLSL.
//!
//! GLSL for Vulkan has separate textures and samplers, but naga's GLSL writer targets
//! OpenGL: it declares every sampled texture as a combined image sampler (`sampler2D`)
//! at the texture's binding, sampling with the sampler the WGSL pairs it with, and drops
//! the sampler's own binding. A Vulkan runner of that GLSL (strata's `ash-glsl` path)
//! therefore binds one `COMBINED_IMAGE_SAMPLER` per sampled texture, holding the paired
//! sampler's state (any sampler for a texture that is only loaded), and nothing for the
//! samplers.
//!
//! [`sampled_pairs`] is the fact every path needs: which textures each sampler samples,
//! followed through function arguments (wgpu's layouts and the shared bind check use it).

use crate::binding::BindingKind;
use crate::registry::Kernel;
use naga::{Block, Expression, Function, GlobalVariable, Handle, Statement};
use std::collections::BTreeSet;

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

/// One texture sampled with one sampler: their `(group, binding)`s.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct SamplePair {
    /// The sampled texture's `(group, binding)`.
    pub texture: (u32, u32),
    /// The sampler's `(group, binding)`.
    pub sampler: (u32, u32),
}

/// Every texture of `kernel` that some `textureSample*` or `textureGather*` samples with
/// some sampler, with that sampler; sorted, each pair once. A texture or sampler passed
/// to a function as an argument is followed through every call to the globals it may
/// be, so a pair found through a helper function is exact, not a guess.
pub fn sampled_pairs(kernel: &Kernel) -> Vec<SamplePair> {
    let module = &kernel.module;
    // Per function of `module.functions` and per argument, the globals it may be.
    let mut arguments: Vec<Vec<BTreeSet<Handle<GlobalVariable>>>> =
        module.functions.iter().map(|(_, f)| vec![BTreeSet::new(); f.arguments.len()]).collect();
    let origins = |arguments: &[Vec<BTreeSet<Handle<GlobalVariable>>>],
                   caller: Option<Handle<Function>>,
                   function: &Function,
                   h: Handle<Expression>| match function.expressions[h] {
        Expression::GlobalVariable(g) => BTreeSet::from([g]),
        Expression::FunctionArgument(i) => {
            caller.and_then(|c| arguments[c.index()].get(i as usize)).cloned().unwrap_or_default()
        }
        _ => BTreeSet::new(),
    };
    let functions: Vec<(Option<Handle<Function>>, &Function)> = module
        .functions
        .iter()
        .map(|(h, f)| (Some(h), f))
        .chain(module.entry_points.iter().map(|e| (None, &e.function)))
        .collect();
    // Calls go from callers to callees and WGSL has no recursion: repeat until nothing
    // grows (at most as many rounds as the call graph is deep).
    loop {
        let mut grew = false;
        for &(caller, function) in &functions {
            let mut calls = Vec::new();
            for_each_call(&function.body, &mut |callee, args| calls.push((callee, args.to_vec())));
            for (callee, args) in calls {
                for (i, &arg) in args.iter().enumerate() {
                    let found = origins(&arguments, caller, function, arg);
                    if let Some(set) = arguments[callee.index()].get_mut(i) {
                        let before = set.len();
                        set.extend(found);
                        grew |= set.len() != before;
                    }
                }
            }
        }
        if !grew {
            break;
        }
    }
    let binding = |g: Handle<GlobalVariable>| module.global_variables[g].binding.as_ref().map(|b| (b.group, b.binding));
    let mut pairs = BTreeSet::new();
    for &(caller, function) in &functions {
        for (_, expression) in function.expressions.iter() {
            let Expression::ImageSample { image, sampler, .. } = *expression else { continue };
            let samplers = origins(&arguments, caller, function, sampler);
            for texture in origins(&arguments, caller, function, image).into_iter().filter_map(binding) {
                for sampler in samplers.iter().copied().filter_map(binding) {
                    pairs.insert(SamplePair { texture, sampler });
                }
            }
        }
    }
    pairs.into_iter().collect()
}

/// Calls `f` with the callee and arguments of every call statement in `block`, nested
/// blocks included.
fn for_each_call(block: &Block, f: &mut impl FnMut(Handle<Function>, &[Handle<Expression>])) {
    for statement in block.iter() {
        match statement {
            Statement::Call { function, arguments, .. } => f(*function, arguments),
            Statement::Block(inner) => for_each_call(inner, f),
            Statement::If { accept, reject, .. } => {
                for_each_call(accept, f);
                for_each_call(reject, f);
            }
            Statement::Switch { cases, .. } => cases.iter().for_each(|case| for_each_call(&case.body, f)),
            Statement::Loop { body, continuing, .. } => {
                for_each_call(body, f);
                for_each_call(continuing, f);
            }
            _ => {}
        }
    }
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

    #[test]
    fn sampled_pairs_follow_textures_and_samplers_through_function_arguments() {
        let source = "@group(0) @binding(0) var a: texture_2d<u32>;
            @group(0) @binding(1) var b: texture_2d<u32>;
            @group(1) @binding(0) var s: sampler;
            @group(1) @binding(1) var t: sampler;
            @group(0) @binding(4) var<storage, read_write> o: array<vec4<u32>>;
            fn gather(x: texture_2d<u32>, y: sampler) -> vec4<u32> {
                return textureGather(0, x, y, vec2(0.5));
            }
            fn twice(x: texture_2d<u32>) -> vec4<u32> { return gather(x, t); }
            @compute @workgroup_size(1) fn main() {
                o[0] = twice(b) + textureLoad(a, vec2(0), 0) + textureGather(1, a, s, vec2(0.5));
            }";
        let kernel = Kernel::from_wgsl("through.wgsl", source.into(), "main", false).unwrap();
        let pairs = sampled_pairs(&kernel);
        let expected = [((0, 0), (1, 0)), ((0, 1), (1, 1))].map(|(texture, sampler)| SamplePair { texture, sampler });
        assert_eq!(pairs, expected);
    }
}
