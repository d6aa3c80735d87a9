//! Unsigned mip levels of `textureLoad` made signed in naga's IR, for naga's GLSL back
//! end.
//!
//! WGSL lets `textureLoad` take its level (and sample index) as `u32` or `i32`. With a
//! bounds-check policy (wgpu's GL back end uses one, and so does strata's GLSL
//! translation), naga 30's GLSL writer passes the level unchanged to `textureSize` and
//! compares it with `textureQueryLevels`, both `int` in GLSL, so Mesa rejects the
//! shader (`no matching function for call to textureSize(isampler2D, uint)`).
//!
//! [`sign_image_levels`] replaces each such load by a call of a small helper (one per
//! combination of operand types) that loads with `i32(level)`: what WGSL means for any
//! level a texture can have. The call keeps the load's handle (a `CallResult`), so
//! nothing that uses the texel changes; naga's IR forbids an expression to use a later
//! one, which rules out inserting the conversion beside the load.

use naga::valid::ModuleInfo;
use naga::{
    Expression, Function, FunctionArgument, FunctionResult, Handle, ScalarKind, Span, Statement, Type, TypeInner,
};

/// The operand types of one load to sign: image, coordinate, array index, level, result.
type Shape = (Handle<Type>, Handle<Type>, Option<Handle<Type>>, Handle<Type>, Handle<Type>);

/// One load to replace: its function (`None`: entry point `entry`), the load, its
/// operands (image, coordinate, array index, level) and its shape.
type Site = (Option<Handle<Function>>, usize, Handle<Expression>, [Option<Handle<Expression>>; 4], Shape);

/// The module with every `textureLoad` whose level is a `u32` turned into a call of a
/// helper that converts the level to `i32`, or `None` if it has none. The result must
/// be validated again.
pub fn sign_image_levels(module: &naga::Module, info: &ModuleInfo) -> Option<naga::Module> {
    let mut module_types = module.types.clone();
    let mut type_of = |finfo: &naga::valid::FunctionInfo, h: Handle<Expression>| match &finfo[h].ty {
        naga::proc::TypeResolution::Handle(handle) => *handle,
        naga::proc::TypeResolution::Value(inner) => {
            module_types.insert(Type { name: None, inner: inner.clone() }, Span::UNDEFINED)
        }
    };
    let mut sites: Vec<Site> = Vec::new();
    let mut find =
        |function: &Function, finfo: &naga::valid::FunctionInfo, owner: Option<Handle<Function>>, entry: usize| {
            for (handle, expression) in function.expressions.iter() {
                let Expression::ImageLoad { image, coordinate, array_index, sample: None, level: Some(level) } =
                    *expression
                else {
                    continue;
                };
                let unsigned = matches!(
                    finfo[level].ty.inner_with(&module.types),
                    TypeInner::Scalar(s) if s.kind == ScalarKind::Uint
                );
                if !unsigned {
                    continue;
                }
                let shape = (
                    type_of(finfo, image),
                    type_of(finfo, coordinate),
                    array_index.map(|a| type_of(finfo, a)),
                    type_of(finfo, level),
                    type_of(finfo, handle),
                );
                sites.push((owner, entry, handle, [Some(image), Some(coordinate), array_index, Some(level)], shape));
            }
        };
    crate::ir_edit::visit_functions(module, info, &mut find);
    if sites.is_empty() {
        return None;
    }
    let mut module = module.clone();
    module.types = module_types;
    let mut shapes: Vec<Shape> = Vec::new();
    for (.., shape) in &sites {
        if !shapes.contains(shape) {
            shapes.push(*shape);
        }
    }
    let helpers = shapes.iter().map(|shape| helper_function(*shape)).collect();
    let (helper_handles, moved) = crate::ir_edit::prepend_functions(&mut module, helpers);
    for (owner, entry, handle, operands, shape) in sites {
        let function = match owner {
            Some(old) => &mut module.functions[moved[old.index()]],
            None => &mut module.entry_points[entry].function,
        };
        let callee = helper_handles[shapes.iter().position(|s| *s == shape).expect("collected above")];
        function.expressions[handle] = Expression::CallResult(callee);
        let call = Statement::Call {
            function: callee,
            arguments: operands.into_iter().flatten().collect(),
            result: Some(handle),
        };
        crate::ir_edit::replace_emit(&mut function.body, handle, &[call], false);
    }
    Some(module)
}

/// `fn(image, coordinate[, array_index], level: u32) -> texel` returning
/// `textureLoad(image, coordinate[, array_index], i32(level))`.
fn helper_function((image, coordinate, array_index, level, result): Shape) -> Function {
    let argument = |name: &str, ty| FunctionArgument { name: Some(name.into()), ty, binding: None };
    let mut arguments = vec![argument("image", image), argument("coordinate", coordinate)];
    if let Some(ty) = array_index {
        arguments.push(argument("array_index", ty));
    }
    arguments.push(argument("level", level));
    let mut function = Function {
        name: Some("naga_load_signed_level".into()),
        arguments,
        result: Some(FunctionResult { ty: result, binding: None }),
        ..Function::default()
    };
    let e = &mut function.expressions;
    let arguments: Vec<Handle<Expression>> = (0..function.arguments.len() as u32)
        .map(|i| e.append(Expression::FunctionArgument(i), Span::UNDEFINED))
        .collect();
    let level = *arguments.last().expect("a level argument");
    let first = e.append(Expression::As { expr: level, kind: ScalarKind::Sint, convert: Some(4) }, Span::UNDEFINED);
    let load = e.append(
        Expression::ImageLoad {
            image: arguments[0],
            coordinate: arguments[1],
            array_index: array_index.map(|_| arguments[2]),
            sample: None,
            level: Some(first),
        },
        Span::UNDEFINED,
    );
    function.body.push(Statement::Emit(naga::Range::new_from_bounds(first, load)), Span::UNDEFINED);
    function.body.push(Statement::Return { value: Some(load) }, Span::UNDEFINED);
    function
}

/// The module as naga's GLSL writer needs it to be defined: WGSL's integer division
/// made explicit ([`crate::integer_division`]) and unsigned `textureLoad` levels made
/// signed; validated again. `None` when neither rewrite changed anything. An error here
/// is a bug of a rewrite.
pub fn defined_for_glsl(
    module: &naga::Module,
    info: &ModuleInfo,
) -> Result<Option<(naga::Module, ModuleInfo)>, String> {
    let divided = crate::integer_division::define_integer_division_validated(module, info)?;
    let (module, info) = match &divided {
        Some((module, info)) => (module, info),
        None => (module, info),
    };
    let Some(signed) = sign_image_levels(module, info) else {
        return Ok(divided);
    };
    let info = crate::ir_edit::revalidate(&signed, "signed texture levels")?;
    Ok(Some((signed, info)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_unsigned_level_is_loaded_through_a_signed_helper_and_the_module_validates() {
        let source = "@group(0) @binding(0) var t: texture_2d<u32>;
            @group(0) @binding(1) var<storage, read_write> o: array<vec4<u32>>;
            @compute @workgroup_size(1) fn main(@builtin(global_invocation_id) id: vec3<u32>) {
                o[0] = textureLoad(t, id.xy, id.z) + textureLoad(t, id.xy, 0);
            }";
        let module = naga::front::wgsl::parse_str(source).unwrap();
        let info = naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all())
            .validate(&module)
            .unwrap();
        let (signed, _) = defined_for_glsl(&module, &info).unwrap().expect("one unsigned level");
        // One helper, called once (the `i32` literal level is left alone); that the GLSL
        // of it compiles is tested on wgpu-gl by tests/tests/textures.rs.
        assert_eq!(signed.functions.len(), 1);
        let calls = signed.entry_points[0]
            .function
            .expressions
            .iter()
            .filter(|(_, e)| matches!(e, Expression::CallResult(_)))
            .count();
        assert_eq!(calls, 1);
    }
}
