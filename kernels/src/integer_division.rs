//! WGSL's integer `/` and `%` made explicit in naga's IR, for back ends that leave them
//! undefined.
//!
//! WGSL defines every integer division: `a % b` has the sign of `a` (truncated
//! division), `a / 0` is `a`, `a % 0` is 0, and `i32::MIN / -1` is `i32::MIN` with
//! remainder 0. GLSL leaves `%` undefined when an operand is negative and both
//! operators undefined for a zero divisor; naga's GLSL back end (30.0) writes WGSL's
//! operators as GLSL's (`back/glsl/writer.rs` carries a TODO), so Mesa's GL compiler
//! returned garbage for the signed remainder of a negative number on wgpu-gl (610 of
//! 3276 words of `tests/data/corpus/volume.wgsl`), while glslang (ash-glsl) happened to
//! choose WGSL's meaning.
//!
//! [`define_integer_division`] replaces each such expression by a call to a small
//! helper function (one per operator and type) that divides by a safe divisor:
//! `select(b, 1, b == 0 || (a == MIN && b == -1))`, and for `%` returns
//! `a - (a / safe) * safe`. Truncating division by a divisor that is neither zero nor
//! -1 under `MIN` is defined in GLSL, so the result is WGSL's on every driver.
//!
//! The call keeps the expression's handle (a `CallResult`, produced by a `Call`
//! statement placed where the expression was emitted), so nothing that uses the value
//! changes, and the helpers are placed before every other function, as naga requires
//! of callees.

use naga::valid::ModuleInfo;
use naga::{
    BinaryOperator, Expression, Function, FunctionArgument, FunctionResult, Handle, Literal, Scalar, ScalarKind, Span,
    Statement, Type, TypeInner, VectorSize,
};

/// One operator on one integer type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Helper {
    op: BinaryOperator,
    kind: ScalarKind,
    size: Option<VectorSize>,
}

/// An expression to replace: (function, expression, helper, left, right).
type Site = (Option<Handle<Function>>, usize, Handle<Expression>, Helper, Handle<Expression>, Handle<Expression>);

/// The module with every 32-bit integer `/` and `%` between operands of one type turned
/// into a call of a helper with WGSL's semantics, or `None` if it has none. The result
/// must be validated again (its `ModuleInfo` changes).
pub fn define_integer_division(module: &naga::Module, info: &ModuleInfo) -> Option<naga::Module> {
    let mut sites: Vec<Site> = Vec::new();
    let mut find =
        |function: &Function, finfo: &naga::valid::FunctionInfo, owner: Option<Handle<Function>>, entry: usize| {
            for (handle, expression) in function.expressions.iter() {
                let Expression::Binary { op: op @ (BinaryOperator::Divide | BinaryOperator::Modulo), left, right } =
                    *expression
                else {
                    continue;
                };
                let left_type = finfo[left].ty.inner_with(&module.types);
                let right_type = finfo[right].ty.inner_with(&module.types);
                if left_type != right_type {
                    continue;
                }
                let (scalar, size) = match *left_type {
                    TypeInner::Scalar(scalar) => (scalar, None),
                    TypeInner::Vector { size, scalar } => (scalar, Some(size)),
                    _ => continue,
                };
                if scalar.width != 4 || !matches!(scalar.kind, ScalarKind::Sint | ScalarKind::Uint) {
                    continue;
                }
                sites.push((owner, entry, handle, Helper { op, kind: scalar.kind, size }, left, right));
            }
        };
    crate::ir_edit::visit_functions(module, info, &mut find);
    if sites.is_empty() {
        return None;
    }

    let mut module = module.clone();
    let mut helpers: Vec<Helper> = Vec::new();
    for (_, _, _, helper, _, _) in &sites {
        if !helpers.contains(helper) {
            helpers.push(*helper);
        }
    }
    let functions = helpers.iter().map(|helper| helper_function(&mut module.types, *helper)).collect();
    let (helper_handles, remap) = crate::ir_edit::prepend_functions(&mut module, functions);
    let remap = |handle: Handle<Function>| remap[handle.index()];

    for (owner, entry, handle, helper, left, right) in sites {
        let function = match owner {
            Some(old_handle) => &mut module.functions[remap(old_handle)],
            None => &mut module.entry_points[entry].function,
        };
        let callee = helper_handles[helpers.iter().position(|h| *h == helper).expect("collected above")];
        function.expressions[handle] = Expression::CallResult(callee);
        let call = Statement::Call { function: callee, arguments: vec![left, right], result: Some(handle) };
        crate::ir_edit::replace_emit(&mut function.body, handle, &[call], false);
    }
    Some(module)
}

/// [`define_integer_division`] followed by validation: the module and its info to hand
/// to a GLSL writer, or `None` when nothing changed. An error here is a bug of this pass.
pub fn define_integer_division_validated(
    module: &naga::Module,
    info: &ModuleInfo,
) -> Result<Option<(naga::Module, ModuleInfo)>, String> {
    let Some(rewritten) = define_integer_division(module, info) else {
        return Ok(None);
    };
    let info = crate::ir_edit::revalidate(&rewritten, "WGSL integer division helpers")?;
    Ok(Some((rewritten, info)))
}

/// `fn(a: T, b: T) -> T` computing `a / b` or `a % b` as WGSL defines them.
fn helper_function(types: &mut naga::UniqueArena<Type>, helper: Helper) -> Function {
    let scalar = Scalar { kind: helper.kind, width: 4 };
    let inner = match helper.size {
        Some(size) => TypeInner::Vector { size, scalar },
        None => TypeInner::Scalar(scalar),
    };
    let ty = types.insert(Type { name: None, inner }, Span::UNDEFINED);
    let signed = helper.kind == ScalarKind::Sint;
    let literal = |value: i64| if signed { Literal::I32(value as i32) } else { Literal::U32(value as u32) };
    let mut function = Function {
        name: Some(format!(
            "wgsl_{}_{}{}",
            if helper.op == BinaryOperator::Divide { "div" } else { "rem" },
            if signed { "i32" } else { "u32" },
            helper.size.map_or(String::new(), |s| format!("x{}", s as u8))
        )),
        arguments: ["a", "b"]
            .iter()
            .map(|name| FunctionArgument { name: Some(name.to_string()), ty, binding: None })
            .collect(),
        result: Some(FunctionResult { ty, binding: None }),
        ..Function::default()
    };
    let e = &mut function.expressions;
    let a = e.append(Expression::FunctionArgument(0), Span::UNDEFINED);
    let b = e.append(Expression::FunctionArgument(1), Span::UNDEFINED);
    let literals: Vec<Handle<Expression>> = [0i64, 1, i64::from(i32::MIN), -1]
        .iter()
        .take(if signed { 4 } else { 2 })
        .map(|&v| e.append(Expression::Literal(literal(v)), Span::UNDEFINED))
        .collect();
    let first_emitted = e.len();
    // Literals are scalars: splat them for vectors.
    let value = |e: &mut naga::Arena<Expression>, literal: Handle<Expression>| match helper.size {
        Some(size) => e.append(Expression::Splat { size, value: literal }, Span::UNDEFINED),
        None => literal,
    };
    let zero = value(e, literals[0]);
    let one = value(e, literals[1]);
    let binary = |e: &mut naga::Arena<Expression>, op, left, right| {
        e.append(Expression::Binary { op, left, right }, Span::UNDEFINED)
    };
    let mut unsafe_divisor = binary(e, BinaryOperator::Equal, b, zero);
    if signed {
        let lowest = value(e, literals[2]);
        let minus_one = value(e, literals[3]);
        let a_lowest = binary(e, BinaryOperator::Equal, a, lowest);
        let b_minus_one = binary(e, BinaryOperator::Equal, b, minus_one);
        let overflow = binary(e, BinaryOperator::And, a_lowest, b_minus_one);
        unsafe_divisor = binary(e, BinaryOperator::InclusiveOr, unsafe_divisor, overflow);
    }
    let safe = e.append(Expression::Select { condition: unsafe_divisor, accept: one, reject: b }, Span::UNDEFINED);
    let quotient = binary(e, BinaryOperator::Divide, a, safe);
    let result = if helper.op == BinaryOperator::Divide {
        quotient
    } else {
        let product = binary(e, BinaryOperator::Multiply, quotient, safe);
        binary(e, BinaryOperator::Subtract, a, product)
    };
    let emitted: Vec<Handle<Expression>> = e.iter().map(|(h, _)| h).skip(first_emitted).collect();
    let range = naga::Range::new_from_bounds(emitted[0], *emitted.last().unwrap());
    function.body.push(Statement::Emit(range), Span::UNDEFINED);
    function.body.push(Statement::Return { value: Some(result) }, Span::UNDEFINED);
    function
}

#[cfg(test)]
mod tests {
    use super::*;

    fn validate(module: &naga::Module) -> ModuleInfo {
        naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::empty())
            .validate(module)
            .unwrap_or_else(|e| panic!("{e:?}"))
    }

    const SOURCE: &str = "
        fn half(x: i32) -> i32 { return x / 2; }
        @group(0) @binding(0) var<storage, read_write> out: array<i32>;
        @group(0) @binding(1) var<storage, read_write> outu: array<vec2<u32>>;
        @compute @workgroup_size(1)
        fn main() {
            let a = out[0];
            let b = out[1];
            out[2] = a % b + half(a);
            out[3] = (a + 1) / (b - 1) % 7;
            outu[0] = outu[1] / outu[2] + outu[3] % vec2<u32>(3u, 5u);
        }";

    #[test]
    fn every_integer_division_becomes_a_call_and_the_module_stays_valid() {
        let module = naga::front::wgsl::parse_str(SOURCE).unwrap();
        let info = validate(&module);
        let rewritten = define_integer_division(&module, &info).expect("the module divides integers");
        validate(&rewritten);
        // Helpers: rem i32, div i32, div u32x2, rem u32x2; then `half`.
        let names: Vec<_> = rewritten.functions.iter().map(|(_, f)| f.name.clone().unwrap()).collect();
        assert_eq!(names.last().map(String::as_str), Some("half"));
        assert_eq!(names.len(), 5, "{names:?}");
        let left = |f: &Function| {
            f.expressions
                .iter()
                .filter(|(_, e)| {
                    matches!(e, Expression::Binary { op: BinaryOperator::Divide | BinaryOperator::Modulo, .. })
                })
                .count()
        };
        assert_eq!(left(&rewritten.entry_points[0].function), 0);
        // GLSL can be written from it.
        let glsl_info = validate(&rewritten);
        let mut text = String::new();
        let options = naga::back::glsl::Options::default();
        let pipeline = naga::back::glsl::PipelineOptions {
            shader_stage: naga::ShaderStage::Compute,
            entry_point: "main".into(),
            multiview: None,
        };
        naga::back::glsl::Writer::new(&mut text, &rewritten, &glsl_info, &options, &pipeline, Default::default())
            .unwrap()
            .write()
            .unwrap();
        assert!(text.contains("wgsl_rem_i32"), "{text}");
    }

    #[test]
    fn a_module_without_integer_division_is_left_alone() {
        let module = naga::front::wgsl::parse_str(
            "@group(0) @binding(0) var<storage, read_write> out: array<f32>;
             @compute @workgroup_size(1) fn main() { out[0] = out[1] / out[2]; }",
        )
        .unwrap();
        assert!(define_integer_division(&module, &validate(&module)).is_none());
    }
}
